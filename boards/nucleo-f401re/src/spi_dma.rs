//! SPI1 as an embedded-hal `SpiBus` whose bytes move by DMA: DMA2 stream 0,
//! channel 3 receives (SPI1_RX) and stream 3, channel 3 sends (SPI1_TX)
//! (RM0368 Table 28; the HAL's table must agree, or this does not compile),
//! set up and restarted through the HAL's [`Transfer`]s. The bytes of a
//! FIFO read (512 at W = 32) then go back to back at SPI1's clock, 0.38 µs
//! a byte at 21 MHz, where the HAL's blocking transfer waits for each byte
//! and spends its loop between them.
//!
//! Every transfer goes by DMA, the one-byte register address included: the
//! HAL's `Spi` cannot be kept beside its DMA (`Spi::use_dma` consumes it),
//! and a restart is a few register writes per stream
//! (`Transfer::next_transfer`), not a set-up of the stream.
//!
//! What the HAL lacks, and is here: a buffer that is not `'static` (each
//! transfer borrows the caller's bytes; [`DmaSpi::exchange`] waits until
//! both streams are done before it returns, so the borrow outlives the
//! DMA's use), a fill for the bytes a read sends and a sink for the bytes a
//! write receives (the HAL's `DmaConfig` fixes memory increment per
//! transfer, so both are buffers: [`ZEROS`] in flash and [`DISCARD`] in
//! SRAM, taken in chunks), and the wait: the data-ready task waits out the
//! transfer (its step is synchronous), bounded, so a stream that never ends
//! fails the read rather than hanging the task.

use core::sync::atomic::{compiler_fence, AtomicU8, Ordering};

use embedded_hal::spi::{ErrorKind, ErrorType, SpiBus};
use stm32f4xx_hal::dma::config::{DmaConfig, Priority};
use stm32f4xx_hal::dma::traits::DmaFlagExt as _;
use stm32f4xx_hal::dma::{MemoryToPeripheral, PeripheralToMemory, Stream0, Stream3, Transfer};
use stm32f4xx_hal::spi;
use stm32f4xx_hal::{ClearFlags as _, ReadFlags as _};

use crate::dma_region::Region;
use crate::pac;

/// What a read sends: zeros (the chips ignore SDI while they answer). In
/// flash: DMA2's memory port reads it there. One chunk holds a whole FIFO
/// read of the drivers (32 records of 16 bytes).
static ZEROS: [u8; CHUNK_LEN] = [0; CHUNK_LEN];

/// Where a write's received bytes go. Atomics: the DMA writes it behind
/// the compiler's back, and nothing reads it.
static DISCARD: [AtomicU8; DISCARD_LEN] = [const { AtomicU8::new(0) }; DISCARD_LEN];

/// The longest run a read sends from [`ZEROS`].
const CHUNK_LEN: usize = 512;
/// The longest run a write receives into [`DISCARD`]: the drivers write a
/// register address and at most one value.
const DISCARD_LEN: usize = 16;

/// Why an SPI transfer failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum SpiDmaError {
    /// A received byte was lost (SPI1's OVR: the receiving stream fell a
    /// byte behind); the bytes read are not to be trusted.
    Overrun,
    /// A stream stopped on a bus error (TEIF).
    TransferError,
    /// The transfer did not end in far more than its bytes' time at the
    /// slowest clock: the streams were stopped.
    Timeout,
}

impl embedded_hal::spi::Error for SpiDmaError {
    fn kind(&self) -> ErrorKind {
        match self {
            SpiDmaError::Overrun => ErrorKind::Overrun,
            SpiDmaError::TransferError | SpiDmaError::Timeout => ErrorKind::Other,
        }
    }
}

type RxTransfer = Transfer<Stream0<pac::DMA2>, 3, spi::Rx<pac::SPI1>, PeripheralToMemory, Region>;
type TxTransfer = Transfer<Stream3<pac::DMA2>, 3, spi::Tx<pac::SPI1>, MemoryToPeripheral, Region>;

/// SPI1 with its two DMA streams.
pub struct DmaSpi {
    rx: RxTransfer,
    tx: TxTransfer,
}

impl DmaSpi {
    /// Takes SPI1 (set up by the HAL: pins, mode, clock, enabled) and the
    /// two streams (from a DMA2 just reset by `StreamsTuple::new`). No
    /// interrupt: [`Self::exchange`] polls the receiving stream's flags.
    pub(crate) fn new(
        spi: stm32f4xx_hal::spi::Spi<pac::SPI1>,
        rx_stream: Stream0<pac::DMA2>,
        tx_stream: Stream3<pac::DMA2>,
    ) -> Self {
        let (tx, rx) = spi.use_dma().txrx();
        // The receiving stream first when both want DMA2 (RM0368, §20.3.9:
        // a late received byte is lost, a late sent one only delayed).
        let config = DmaConfig::default().memory_increment(true);
        let rx = Transfer::init_peripheral_to_memory(
            rx_stream,
            rx,
            Region::EMPTY,
            None,
            config.priority(Priority::VeryHigh),
        );
        let tx = Transfer::init_memory_to_peripheral(
            tx_stream,
            tx,
            Region::EMPTY,
            None,
            config.priority(Priority::High),
        );
        Self { rx, tx }
    }

    /// Sends `source` while receiving as many bytes into `sink` (both of
    /// the same length, at most 65535), and returns when the last byte is
    /// in: the clock has stopped, so the device may raise CS.
    fn exchange(&mut self, source: Region, sink: Region) -> Result<(), SpiDmaError> {
        debug_assert_eq!(source.len(), sink.len());
        if sink.len() == 0 {
            return Ok(());
        }
        // RM0368 (DMA_SxCR, EN): a stream's flags are cleared before it is
        // enabled.
        self.rx.clear_all_flags();
        self.tx.clear_all_flags();
        // The receiver is ready before the first byte goes (RM0368 §20.3.9).
        // Without double buffering `next_transfer` cannot fail: it stops the
        // stream if it ran, loads the region and enables the stream.
        if self.rx.next_transfer(sink).is_err() || self.tx.next_transfer(source).is_err() {
            return Err(self.stop(SpiDmaError::TransferError));
        }
        // At the slowest clock (PCLK2 / 256) a byte is 2048 core cycles;
        // each look takes more than 4.
        let mut looks = (sink.len() + 1) * 1024;
        loop {
            let (rx, tx) = (self.rx.flags(), self.tx.flags());
            if rx.is_transfer_error() || tx.is_transfer_error() {
                return Err(self.stop(SpiDmaError::TransferError));
            }
            if rx.is_transfer_complete() {
                break;
            }
            looks -= 1;
            if looks == 0 {
                return Err(self.stop(SpiDmaError::Timeout));
            }
        }
        // The DMA's writes to `sink` are read after its completion flag.
        compiler_fence(Ordering::Acquire);
        if overrun() {
            return Err(SpiDmaError::Overrun);
        }
        Ok(())
    }

    /// Stops both streams after a failure (the next exchange restarts
    /// them), and empties the receiver so that the next exchange's first
    /// byte is its own.
    fn stop(&mut self, error: SpiDmaError) -> SpiDmaError {
        self.tx.pause(|_| {});
        self.rx.pause(|_| {});
        let spi = spi1();
        // A byte already in DR or the shift register still goes out: at
        // most two bytes, 4096 core cycles at PCLK2 / 256.
        for _ in 0..4096 {
            if spi.sr().read().bsy().bit_is_clear() {
                break;
            }
        }
        clear_receiver(spi);
        error
    }
}

/// SPI1's registers, for what the HAL's DMA handles do not offer: the
/// status flags (the HAL checks OVR only in its own blocking transfers,
/// which the DMA replaces).
fn spi1() -> &'static pac::spi1::RegisterBlock {
    // SAFETY: used only to read SR and DR, which nothing else touches while
    // this bus owns SPI1 and both of its streams are stopped.
    unsafe { &*pac::SPI1::ptr() }
}

/// Empties DR and clears OVR (RM0368 §20.4.8: read DR, then SR).
fn clear_receiver(spi: &pac::spi1::RegisterBlock) {
    let _ = spi.dr().read();
    let _ = spi.sr().read();
}

/// Whether SPI1 lost a received byte (OVR) during the exchange just ended,
/// clearing the flag.
fn overrun() -> bool {
    let spi = spi1();
    if spi.sr().read().ovr().bit_is_clear() {
        return false;
    }
    clear_receiver(spi);
    true
}

impl ErrorType for DmaSpi {
    type Error = SpiDmaError;
}

impl SpiBus<u8> for DmaSpi {
    /// Sends zeros while reading, in runs of [`CHUNK_LEN`].
    fn read(&mut self, words: &mut [u8]) -> Result<(), SpiDmaError> {
        for chunk in words.chunks_mut(CHUNK_LEN) {
            self.exchange(Region::of(&ZEROS[..chunk.len()]), Region::of(chunk))?;
        }
        Ok(())
    }

    /// Discards what comes back, in runs of [`DISCARD_LEN`].
    fn write(&mut self, words: &[u8]) -> Result<(), SpiDmaError> {
        for chunk in words.chunks(DISCARD_LEN) {
            self.exchange(Region::of(chunk), Region::cells(&DISCARD, 0, chunk.len()))?;
        }
        Ok(())
    }

    /// Exchanges the common length, then reads or writes the rest.
    fn transfer(&mut self, read: &mut [u8], write: &[u8]) -> Result<(), SpiDmaError> {
        let common = read.len().min(write.len());
        let (read_both, read_rest) = read.split_at_mut(common);
        let (write_both, write_rest) = write.split_at(common);
        // A run is at most 65535 bytes (NDTR).
        for (r, w) in read_both
            .chunks_mut(usize::from(u16::MAX))
            .zip(write_both.chunks(usize::from(u16::MAX)))
        {
            self.exchange(Region::of(w), Region::of(r))?;
        }
        self.read(read_rest)?;
        self.write(write_rest)
    }

    /// Sends each byte and receives over it: the sending stream reads a
    /// byte before the receiving one writes it (a byte is received only
    /// after it was sent).
    fn transfer_in_place(&mut self, words: &mut [u8]) -> Result<(), SpiDmaError> {
        for chunk in words.chunks_mut(usize::from(u16::MAX)) {
            let region = Region::of(chunk);
            self.exchange(region, region)?;
        }
        Ok(())
    }

    /// Nothing: each transfer returns once its last byte is received.
    fn flush(&mut self) -> Result<(), SpiDmaError> {
        Ok(())
    }
}
