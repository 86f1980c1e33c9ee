//! USART2's transmitter (PA2, to the ST-LINK's virtual COM port) by DMA:
//! the firmware's transmitter copies bytes into [`BUFFER`], a ring ([`triad::device::tx_ring`]),
//! and DMA1 stream 6, channel 4 (RM0368 Table 28: USART2_TX; the HAL's
//! table must agree, or this does not compile) sends them to DR, one run of
//! consecutive bytes at a time, paced by the USART's TXE requests (CR3's
//! DMAT). The stream is the HAL's `Transfer`, each run started by its
//! `next_transfer`.
//!
//! Why not the HAL's serial DMA (`Serial::use_dma`, `write_dma`): it sends
//! one caller's slice at a time and ends in a callback, a plain `fn` with
//! no state, from the stream's interrupt; it takes the slice as `'static`
//! by transmuting it; and it turns on USART2's error interrupt, which the
//! firmware binds for the receiver's IDLE line. The ring needs runs of its
//! own buffer chained from the stream's interrupt, which `Transfer` gives.
//!
//! Who does what, so that no one waits:
//! - [`Serial::queue`] (the transmitter) copies the bytes in, advances
//!   [`WRITTEN`] and pends `DMA1_STREAM6`.
//! - [`transmit_dma_interrupt`], the body of the firmware's RTIC task bound
//!   to `DMA1_STREAM6`, is the only code that programs the stream. It runs
//!   on that pend and on the stream's transfer-complete (or transfer-error)
//!   interrupt: when a run has ended it advances [`RELEASED`] and returns
//!   true, and the firmware wakes its transmitter, which may be waiting for
//!   that room; when the stream is idle it starts the next run.
//!
//! Why its own interrupt rather than polling from the transmitter or the
//! USART's interrupt: a run ends without any task running (the last frames
//! before the stream stops, or a reply queued behind a run), and the next
//! run must then still start.

use core::cell::RefCell;
use core::sync::atomic::{AtomicU8, AtomicUsize, Ordering};

use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::NVIC;
use stm32f4xx_hal::dma::config::{DmaConfig, Priority};
use stm32f4xx_hal::dma::traits::DmaFlagExt as _;
use stm32f4xx_hal::dma::{MemoryToPeripheral, Stream6, Transfer};
use stm32f4xx_hal::serial;
use stm32f4xx_hal::{ClearFlags as _, ReadFlags as _};
use triad::device::board::LinkTx;

use crate::dma_region::Region;
use crate::pac;
use triad::device::tx_ring::TxRing;

/// The ring's length: four longest packets (a reply is at most
/// [`triad::protocol::MAX_WIRE_LEN`] = 242 bytes), about 19 stream frames of 53
/// bytes, 11 ms of the line at 913 kbaud. NDTR takes up to 65535.
pub const TX_BUFFER_LEN: usize = 1024;
const _: () = assert!(triad::protocol::MAX_WIRE_LEN <= TX_BUFFER_LEN);
const _: () = assert!(TX_BUFFER_LEN <= u16::MAX as usize);

type Ring = TxRing<TX_BUFFER_LEN>;

/// The bytes queued for the line. Atomics so that the link task's stores
/// and the DMA's reads need no `unsafe`: the link task stores only into
/// free bytes, the DMA reads only pending ones.
static BUFFER: [AtomicU8; TX_BUFFER_LEN] = [const { AtomicU8::new(0) }; TX_BUFFER_LEN];

/// Bytes ever queued, wrapping: stored only by [`Serial::queue`] (there is one
/// `Serial`, made from the one DMA1 stream 6), read by the handler.
static WRITTEN: AtomicUsize = AtomicUsize::new(0);

/// Bytes ever sent, wrapping: stored only by the handler, read by
/// [`Serial::room`].
static RELEASED: AtomicUsize = AtomicUsize::new(0);

/// The stream and its run, owned by the handler once [`Serial::new`] has put
/// them here (before the interrupt is unmasked): the critical section only
/// lends them to the handler, which nothing else borrows from.
static SENDER: Mutex<RefCell<Option<Sender>>> = Mutex::new(RefCell::new(None));

/// USART2_TX's stream and channel (RM0368 Table 28), sending runs of
/// [`BUFFER`].
type TxTransfer =
    Transfer<Stream6<pac::DMA1>, 4, serial::Tx<pac::USART2>, MemoryToPeripheral, Region>;

/// The link task's side of USART2's transmitter (the transmit side itself,
/// PA2 and DR, is the handler's transfer's).
pub struct Serial {
    _made_by_new: (),
}

impl Serial {
    /// Sets up the stream (memory to DR, a byte at a time, interrupts on
    /// transfer complete and error); the firmware binds its interrupt,
    /// DMA1_STREAM6, to a task that calls [`transmit_dma_interrupt`] (RTIC
    /// sets its priority and unmasks it). `usart` must have DMAT set (the
    /// HAL's `serial::Config::dma`); `stream` comes from a DMA1 just reset
    /// by `StreamsTuple::new`, so it is off; the HAL's set-up clears its
    /// flags and puts it in direct mode (no FIFO).
    pub(crate) fn new(usart: serial::Tx<pac::USART2>, stream: Stream6<pac::DMA1>) -> Self {
        // Bytes to DR (the HAL's USART2 DMA word), memory incrementing, not
        // started: the handler starts each run. The receiver's stream is
        // High: a late received byte is lost, a late sent one only delayed.
        let config = DmaConfig::default()
            .memory_increment(true)
            .priority(Priority::Medium)
            .transfer_complete_interrupt(true)
            .transfer_error_interrupt(true);
        let transfer =
            Transfer::init_memory_to_peripheral(stream, usart, Region::EMPTY, None, config);
        cortex_m::interrupt::free(|cs| {
            SENDER.borrow(cs).replace(Some(Sender {
                transfer,
                sending: 0,
            }));
        });
        Self { _made_by_new: () }
    }
}

impl LinkTx for Serial {
    /// The bytes neither pending nor in the run being sent: a run's bytes
    /// are freed when it ends.
    fn room(&self) -> usize {
        Ring::free(
            WRITTEN.load(Ordering::Relaxed),
            RELEASED.load(Ordering::Acquire),
        )
    }

    fn queue(&mut self, bytes: &[u8]) -> bool {
        if bytes.len() > self.room() {
            return false;
        }
        if bytes.is_empty() {
            return true;
        }
        let written = WRITTEN.load(Ordering::Relaxed);
        for (n, &byte) in bytes.iter().enumerate() {
            BUFFER[Ring::index(written.wrapping_add(n))].store(byte, Ordering::Relaxed);
        }
        WRITTEN.store(written.wrapping_add(bytes.len()), Ordering::Release);
        // The handler starts a run if the stream is idle; if a run is going,
        // it finds nothing ended and returns, and the bytes go after the run.
        NVIC::pend(pac::Interrupt::DMA1_STREAM6);
        true
    }
}

/// The stream, and the length of the run it is sending (0: idle).
struct Sender {
    transfer: TxTransfer,
    sending: usize,
}

impl Sender {
    /// Ends the run if the stream finished it, then starts the next if the
    /// stream is idle and bytes are pending.
    fn serve(&mut self) -> bool {
        let mut freed = false;
        if self.sending > 0 {
            let flags = self.transfer.flags();
            if !flags.is_transfer_complete() && !flags.is_transfer_error() {
                // Pended by `queue` while the run goes on.
                return false;
            }
            if flags.is_transfer_error() {
                // Only a bad address raises it; the run's bytes are lost,
                // the ones after still go.
                defmt::error!("USART2 TX DMA: transfer error, {} bytes lost", self.sending);
            }
            // The hardware clears EN at the end of a transfer or on an error
            // (RM0368, DMA_SxCR); `next_transfer` waits for it before
            // writing the stream's registers.
            let released = RELEASED.load(Ordering::Relaxed);
            RELEASED.store(released.wrapping_add(self.sending), Ordering::Release);
            self.sending = 0;
            // Frames may be waiting in the firmware's queue for this room.
            freed = true;
        }
        // RM0368 (DMA_SxCR, EN): the stream's flags are cleared before it is
        // enabled; this also ends the interrupt's request.
        self.transfer.clear_all_flags();
        let written = WRITTEN.load(Ordering::Acquire);
        let Some(run) = Ring::next_run(written, RELEASED.load(Ordering::Relaxed)) else {
            return freed;
        };
        // The run's bytes are pending: the link task writes only free bytes
        // until RELEASED passes them, after this run ends. A run is at most
        // TX_BUFFER_LEN ≤ 65535 bytes (checked above).
        let region = Region::cells(&BUFFER, run.start, run.len);
        // The link task's stores to BUFFER complete before the DMA can read.
        cortex_m::asm::dsb();
        // Without double buffering `next_transfer` cannot fail: it loads the
        // run and enables the stream.
        if self.transfer.next_transfer(region).is_err() {
            return freed;
        }
        self.sending = run.len;
        freed
    }
}

/// Ends and starts runs (see the module's comment): the body of the
/// firmware's task bound to DMA1_STREAM6. True when a run ended, freeing
/// room (the firmware then wakes its transmitter).
pub fn transmit_dma_interrupt() -> bool {
    cortex_m::interrupt::free(|cs| {
        // Nothing else borrows it after `Serial::new`: the borrow always
        // succeeds (`try_` only spares the handler a panic path).
        match SENDER.borrow(cs).try_borrow_mut() {
            Ok(mut sender) => sender.as_mut().is_some_and(Sender::serve),
            Err(_) => false,
        }
    })
}
