//! What reading the sensor costs: the ICM-42688-P driver's 14-byte burst
//! read per sample, and its FIFO drain of W packets at a time (W = 1, 8,
//! 32), through a bus that only hands back canned bytes ([`CannedFifoSpi`]),
//! so that no chip model's instructions are counted. The bus counts the
//! bytes it carries (address and data) for the report's bytes per sample.

use core::convert::Infallible;

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};

use super::pipeline::sample_block;
use super::BATCH;
use triad::sensor::icm42688::Icm42688;
use triad::sensor::interface::SpiInterface;
use triad::sensor::{FifoImu, Imu, RawSample};
use triad_sim::chips::icm42688_registers as reg;

/// An SPI device serving one batch: burst reads of the sample block
/// (TEMP_DATA1…) and FIFO drains (INT_STATUS + FIFO_COUNT, then FIFO_DATA
/// packets), from the samples loaded with [`CannedFifoSpi::load`].
#[derive(Debug)]
pub struct CannedFifoSpi {
    packets: [[u8; reg::FIFO_PACKET_LEN]; BATCH],
    blocks: [[u8; 14]; BATCH],
    /// The next sample to serve.
    next: usize,
    /// Packets the FIFO reports at each drain (the watermark).
    watermark: usize,
    /// Bytes carried so far, address bytes included.
    pub bytes: usize,
}

impl CannedFifoSpi {
    /// A bus whose FIFO reports `watermark` packets per drain.
    pub fn new(watermark: usize) -> Self {
        CannedFifoSpi {
            packets: [[0; reg::FIFO_PACKET_LEN]; BATCH],
            blocks: [[0; 14]; BATCH],
            next: 0,
            watermark,
            bytes: 0,
        }
    }

    /// Loads a batch: each sample as a burst block and as a FIFO packet 3
    /// (header 0x68: accel and gyro, big-endian, 8-bit temperature, timestamp).
    pub fn load(&mut self, input: &[RawSample; BATCH]) {
        for ((raw, block), packet) in input.iter().zip(&mut self.blocks).zip(&mut self.packets) {
            *block = sample_block(raw);
            // The packet holds the six axes in the block's order, after the
            // header and without the temperature, which follows as 8 bits.
            packet[0] = reg::HEADER_ACCEL | reg::HEADER_GYRO | reg::HEADER_TIMESTAMP_ODR;
            packet[1..13].copy_from_slice(&block[2..14]);
            packet[13] = (raw.temperature / 64) as u8;
        }
        self.next = 0;
    }

    fn serve(&mut self, register: u8, buffer: &mut [u8]) {
        let left = BATCH - self.next;
        match register & !0x80 {
            reg::INT_STATUS => {
                let count = self.watermark.min(left) as u16;
                let head = [0, (count >> 8) as u8, count as u8];
                let n = buffer.len().min(3);
                buffer[..n].copy_from_slice(&head[..n]);
            }
            reg::FIFO_DATA => {
                for chunk in buffer.chunks_exact_mut(reg::FIFO_PACKET_LEN) {
                    if let Some(p) = self.packets.get(self.next) {
                        chunk.copy_from_slice(p);
                        self.next += 1;
                    }
                }
            }
            _ => {
                if let Some(b) = self.blocks.get(self.next) {
                    let n = buffer.len().min(14);
                    buffer[..n].copy_from_slice(&b[..n]);
                    self.next += 1;
                }
            }
        }
    }
}

impl ErrorType for CannedFifoSpi {
    type Error = Infallible;
}

impl SpiDevice for CannedFifoSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Infallible> {
        let mut register = 0;
        for op in operations {
            match op {
                Operation::Write(bytes) => {
                    register = bytes.first().copied().unwrap_or(0);
                    self.bytes += bytes.len();
                }
                Operation::Read(buffer) => {
                    self.bytes += buffer.len();
                    self.serve(register, buffer);
                }
                _ => {}
            }
        }
        Ok(())
    }
}

/// The driver on the canned bus.
pub type CannedImu = Icm42688<SpiInterface<CannedFifoSpi>>;

/// A driver reading through a canned bus with FIFO watermark `watermark`
/// (its default configuration; the canned bus ignores writes).
pub fn canned_imu(watermark: usize) -> CannedImu {
    Icm42688::new_spi(CannedFifoSpi::new(watermark))
}

/// One burst read per sample.
#[inline(never)]
pub fn read_burst(imu: &mut CannedImu, out: &mut [RawSample; BATCH]) {
    for o in out.iter_mut() {
        if let Ok(raw) = imu.read_sample() {
            *o = raw;
        }
    }
}

/// FIFO drains of up to the watermark's packets until the batch is read.
#[inline(never)]
pub fn read_fifo(imu: &mut CannedImu, out: &mut [RawSample; BATCH]) {
    let mut done = 0;
    while done < BATCH {
        match imu.read_fifo(&mut out[done..]) {
            Ok(read) if read.samples > 0 => done += read.samples,
            _ => break,
        }
    }
}
