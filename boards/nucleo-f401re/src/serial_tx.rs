//! USART2's transmitter (PA2, to the ST-LINK's virtual COM port) by DMA:
//! the firmware's transmitter copies bytes into [`BUFFER`], a ring ([`triad::device::tx_ring`]),
//! and DMA1 stream 6, channel 4 (RM0368 Table 28: USART2_TX) sends them to
//! DR, one run of consecutive bytes at a time, paced by the USART's TXE
//! requests (CR3's DMAT).
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
use stm32f4xx_hal::dma::config::Priority;
use stm32f4xx_hal::dma::traits::{DMASet, DmaFlagExt as _, PeriAddress as _, Stream as _};
use stm32f4xx_hal::dma::Stream6;
use stm32f4xx_hal::dma::{DmaChannel, DmaDataSize, DmaDirection, DmaEvent, MemoryToPeripheral};
use stm32f4xx_hal::serial;
use stm32f4xx_hal::{ClearFlags as _, Listen as _, ReadFlags as _};
use triad::device::board::LinkTx;

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

/// The stream and channel RM0368 Table 28 gives USART2_TX; the HAL's table
/// must agree, or this does not compile.
fn usart2_tx_maps_to<S, const CHANNEL: u8>()
where
    serial::Tx<pac::USART2>: DMASet<S, CHANNEL, MemoryToPeripheral>,
{
}

/// The link task's side of USART2's transmitter.
pub struct Serial {
    /// Owns PA2 and USART2's transmit side; the DMA writes its DR.
    _usart: serial::Tx<pac::USART2>,
}

impl Serial {
    /// Sets up the stream (memory to DR, a byte at a time, interrupts on
    /// transfer complete and error); the firmware binds its interrupt,
    /// DMA1_STREAM6, to a task that calls [`transmit_dma_interrupt`] (RTIC
    /// sets its priority and unmasks it). `usart` must have DMAT set (the HAL's `serial::Config::dma`);
    /// `stream` comes from a DMA1 just reset by `StreamsTuple::new`, so it is
    /// off, its flags clear and in direct mode (no FIFO).
    pub(crate) fn new(usart: serial::Tx<pac::USART2>, mut stream: Stream6<pac::DMA1>) -> Self {
        usart2_tx_maps_to::<Stream6<pac::DMA1>, 4>();
        stream.set_channel(DmaChannel::Channel4);
        stream.set_direction(DmaDirection::MemoryToPeripheral);
        stream.set_peripheral_address(usart.address());
        stream.set_peripheral_increment(false);
        stream.set_memory_increment(true);
        stream.set_circular_mode(false);
        // The receiver's stream is High: a late received byte is lost, a
        // late transmitted one only delayed.
        stream.set_priority(Priority::Medium);
        stream.listen(DmaEvent::TransferComplete | DmaEvent::TransferError);
        stream.clear_all_flags();
        // SAFETY: bytes on both sides: DR is written a byte at a time (8N1),
        // the buffer is bytes. The stream is not enabled here; the handler
        // enables it only over a run inside BUFFER (`TxRing::next_run`).
        unsafe {
            stream.set_peripheral_size(DmaDataSize::Byte);
            stream.set_memory_size(DmaDataSize::Byte);
        }
        cortex_m::interrupt::free(|cs| {
            SENDER
                .borrow(cs)
                .replace(Some(Sender { stream, sending: 0 }));
        });
        Self { _usart: usart }
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
    stream: Stream6<pac::DMA1>,
    sending: usize,
}

impl Sender {
    /// Ends the run if the stream finished it, then starts the next if the
    /// stream is idle and bytes are pending.
    fn serve(&mut self) -> bool {
        let mut freed = false;
        if self.sending > 0 {
            let flags = self.stream.flags();
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
            // (RM0368, DMA_SxCR); the registers can be written once it reads 0.
            while self.stream.is_enabled() {}
            let released = RELEASED.load(Ordering::Relaxed);
            RELEASED.store(released.wrapping_add(self.sending), Ordering::Release);
            self.sending = 0;
            // Frames may be waiting in the firmware's queue for this room.
            freed = true;
        }
        // RM0368 (DMA_SxCR, EN): the stream's flags are cleared before it is
        // enabled; this also ends the interrupt's request.
        self.stream.clear_all_flags();
        let written = WRITTEN.load(Ordering::Acquire);
        let Some(run) = Ring::next_run(written, RELEASED.load(Ordering::Relaxed)) else {
            return freed;
        };
        // The buffer's address fits the 32-bit bus; a run is at most
        // TX_BUFFER_LEN ≤ 65535 bytes (checked above).
        let start = BUFFER[run.start].as_ptr() as u32;
        self.stream.set_memory_address(start);
        self.stream.set_number_of_transfers(run.len as u16);
        // The link task's stores to BUFFER complete before the DMA can read.
        cortex_m::asm::dsb();
        // SAFETY: the stream reads `run.len` bytes from `start`, all inside
        // BUFFER ('static) and pending: the link task writes only free bytes
        // until RELEASED passes them, after this run ends.
        unsafe { self.stream.enable() };
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
