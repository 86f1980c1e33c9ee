//! USART2's receiver (PA3, from the ST-LINK's virtual COM port) by DMA: DMA1
//! stream 5, channel 4 (RM0368 Table 28: USART2_RX) copies every received
//! byte into [`RING`] in circles, with no interrupt of its own; USART2's
//! IDLE-line interrupt (IDLEIE) wakes the firmware at the end of each burst,
//! and its handler calls [`LinkRx::read`] until it returns `None`.
//!
//! The stream is the HAL's `Transfer` (channel, addresses, sizes, priority;
//! the HAL's table must map USART2_RX to it, or this does not compile),
//! with one bit the HAL cannot be told: CIRC. Its `DmaConfig` has no
//! circular mode, only double buffering, whose flags mark the end of each
//! of two buffers rather than the half and the end of one ring, which is
//! what the core's [`triad::device::dma_ring`] counts exactly. So CIRC is
//! set on the stream before the HAL takes it (its set-up leaves CIRC as
//! it finds it), and the transfer is started once and never restarted.
//! The HAL's serial DMA (`read_dma`) fits less: it fills one caller's
//! buffer once, then ends in a callback.
//!
//! Why a command cannot be lost to the ring: [`triad::device::dma_ring`] counts
//! exactly any run of up to `RING_LEN / 2` = 256 bytes between two drains,
//! and a command packet is at most [`triad::protocol::MAX_WIRE_LEN`] = 242 bytes
//! on the wire (checked below at compile time). The host sends one command
//! and waits for its reply, which the device sends only after a drain has
//! taken the command, so one command at most arrives between two drains.
//! A flash erase stalls the CPU (and this interrupt) for up to 2 s per sector
//! while the DMA keeps filling the ring: a host that retries during it (a
//! reply timeout shorter than the erase) adds its retries to that run. From
//! 512 bytes on, the loss is always reported ([`RxError::Overrun`]).

use core::sync::atomic::{compiler_fence, AtomicU8, Ordering};

use stm32f4xx_hal::dma::config::{DmaConfig, Priority};
use stm32f4xx_hal::dma::traits::{Stream as _, StreamISR as _};
use stm32f4xx_hal::dma::{PeripheralToMemory, Stream5, Transfer};
use stm32f4xx_hal::serial::{self, RxListen as _};
use triad::device::board::{LinkRx, RxError};

use crate::dma_region::Region;
use crate::pac;
use triad::device::dma_ring::{Boundaries, RingReader};

/// The ring's length: its half, which is counted exactly, holds the longest
/// command packet (see the module's comment). NDTR takes up to 65535.
const RING_LEN: usize = 512;
const _: () = assert!(triad::protocol::MAX_WIRE_LEN <= RING_LEN / 2);

/// What the DMA writes into. Atomics because the DMA writes behind the
/// compiler's back: each load reads memory. Only the one [`SerialRx`] (made
/// once, in `init`, from the one DMA1 stream 5) points the DMA here.
static RING: [AtomicU8; RING_LEN] = [const { AtomicU8::new(0) }; RING_LEN];

/// USART2_RX's stream and channel (RM0368 Table 28), filling [`RING`].
type RxTransfer =
    Transfer<Stream5<pac::DMA1>, 4, serial::Rx<pac::USART2>, PeripheralToMemory, Region>;

/// USART2's receive side with its DMA ring.
pub struct SerialRx {
    /// The stream, and USART2's receive side and PA3 (its registers are
    /// read through `registers`).
    transfer: RxTransfer,
    ring: RingReader<RING_LEN>,
}

impl SerialRx {
    /// Starts the stream filling the ring and enables the IDLE interrupt.
    /// `usart` must have DMAR set (the HAL's `serial::Config::dma`); `stream`
    /// comes from a DMA1 just reset by `StreamsTuple::new`, so it is off. The
    /// HAL's set-up leaves it with no interrupt, its flags clear and in
    /// direct mode (no FIFO): each byte is written to memory as it is read
    /// from DR.
    pub(crate) fn new(mut usart: serial::Rx<pac::USART2>, mut stream: Stream5<pac::DMA1>) -> Self {
        // What the HAL's `DmaConfig` cannot say (see the module's comment).
        stream.set_circular_mode(true);
        // The whole ring (RING_LEN bytes from its start, NDTR = RING_LEN),
        // memory incrementing, round and round; the CPU only reads RING,
        // and only bytes the stream has written (`RingReader`).
        let ring = Region::cells(&RING, 0, RING_LEN);
        let config = DmaConfig::default()
            .memory_increment(true)
            .priority(Priority::High);
        usart.listen_idle();
        let mut transfer = Transfer::init_peripheral_to_memory(stream, usart, ring, None, config);
        transfer.start(|_| {});
        Self {
            transfer,
            ring: RingReader::new(),
        }
    }

    /// USART2's status and data registers, which the receiver reads to see
    /// and clear its flags (the HAL's `Rx` does not expose the error flags).
    fn registers(&self) -> &pac::usart1::RegisterBlock {
        // SAFETY: a shared reference to memory-mapped registers; only SR and
        // DR are read through it, which changes nothing but the receive flags
        // that this receiver owns (the transmitter's DMA writes DR).
        unsafe { &*pac::USART2::ptr() }
    }

    /// Reads SR, then DR unless RXNE is set. Reading SR then DR clears IDLE,
    /// ORE, NF and FE (RM0368, USART_SR); with RXNE set, the DMA's own read of
    /// DR, due within a few bus cycles, is the DR read that clears them, and
    /// reading DR here would take that byte from the DMA. What this cannot
    /// rule out: a byte completing between the two reads, a window of a few
    /// bus cycles; it is then lost, as a line error would, and the packet's
    /// CRC rejects the packet it belonged to.
    fn read_flags_and_clear(&self) -> pac::usart1::sr::R {
        let usart = self.registers();
        let sr = usart.sr().read();
        if sr.rxne().bit_is_clear() {
            let _ = usart.dr().read();
        }
        sr
    }

    /// A line error since the last look (reported once, then cleared): one of
    /// the bytes around now, in the ring or still to come, is damaged.
    fn line_error(&self) -> Option<RxError> {
        let error = error_in(&self.registers().sr().read())?;
        self.read_flags_and_clear();
        Some(error)
    }

    /// The stream's position in the ring: NDTR counts down from RING_LEN
    /// and reloads on wrapping, so RING_LEN − NDTR bytes of this lap are in.
    fn stream_at(&self) -> usize {
        (RING_LEN - usize::from(self.transfer.number_of_transfers())) % RING_LEN
    }

    /// The boundaries whose flags are set, clearing those (and only those:
    /// one that rises after this read stays set for the next look).
    fn take_boundaries(&mut self) -> Boundaries {
        let reached = Boundaries {
            half: self.transfer.is_half_transfer(),
            end: self.transfer.is_transfer_complete(),
        };
        if reached.half {
            self.transfer.clear_half_transfer();
        }
        if reached.end {
            self.transfer.clear_transfer_complete();
        }
        reached
    }

    /// The stream's position and the boundaries reached since the last
    /// look. The flags are read between two reads of the position; if a
    /// boundary lies between those two, it may have been reached just before
    /// or just after the flags were read, so the look is taken again (keeping
    /// the flags already cleared). That window is a few bus cycles and a
    /// boundary comes every 256 bytes (2.8 ms at 921600 baud), so the loop
    /// ends at the second pass at most.
    fn look(&mut self) -> (usize, Boundaries) {
        let mut reached = Boundaries::default();
        loop {
            let before = self.stream_at();
            reached = reached.union(self.take_boundaries());
            let after = self.stream_at();
            let window = (after + RING_LEN - before) % RING_LEN;
            if Boundaries::on_arc(RING_LEN, before, window) == Boundaries::default() {
                return (after, reached);
            }
        }
    }

    /// The next byte, a reception error, or `None` when nothing is waiting.
    fn next(&mut self) -> Option<Result<u8, RxError>> {
        if let Some(error) = self.line_error() {
            return Some(Err(error));
        }
        let (at, reached) = self.look();
        if self.ring.sync(at, reached).is_err() {
            return Some(Err(RxError::Overrun));
        }
        let index = self.ring.take()?;
        // The bytes before `at` are in memory: read them after NDTR.
        compiler_fence(Ordering::Acquire);
        Some(Ok(RING[index].load(Ordering::Relaxed)))
    }
}

impl LinkRx for SerialRx {
    /// The next byte of the ring not yet read. With nothing more, clears
    /// IDLE (so the interrupt ends), reporting a line error that clearing
    /// took with it, then looks once more: a byte that came in between is
    /// returned now rather than left to the next burst's interrupt.
    fn read(&mut self) -> Option<Result<u8, RxError>> {
        if let Some(next) = self.next() {
            return Some(next);
        }
        if let Some(error) = error_in(&self.read_flags_and_clear()) {
            return Some(Err(error));
        }
        self.next()
    }
}

/// The line error a status register reading shows, if any.
fn error_in(sr: &pac::usart1::sr::R) -> Option<RxError> {
    if sr.ore().bit_is_set() {
        // The DMA did not take a byte before the next one came.
        Some(RxError::Overrun)
    } else if sr.fe().bit_is_set() || sr.nf().bit_is_set() {
        Some(RxError::Line)
    } else {
        None
    }
}
