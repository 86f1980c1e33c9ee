//! The whole per-sample step for the benchmark: the ICM-42688-P driver's
//! burst read through a bus that only hands back bytes ([`CannedSpi`]: no
//! chip model, so its instructions are a 14-byte copy, not a register
//! machine), then [`Sampler::step`] (correction, averaging, framing) and
//! [`encode`] (CRC-32C and COBS), as the firmware's data-ready task runs them.

use core::convert::Infallible;

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};

use triad::device::{Outgoing, Sampler, StepOutcome};
use triad::model::Corrector;
use triad::protocol::{encode, MAX_ENCODED_LEN};
use triad::sensor::icm42688::Icm42688;
use triad::sensor::interface::SpiInterface;
use triad::sensor::RawSample;

/// An encoded frame's bytes (unused tail bytes zero).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncodedFrame(pub [u8; MAX_ENCODED_LEN]);

impl Default for EncodedFrame {
    fn default() -> Self {
        EncodedFrame([0; MAX_ENCODED_LEN])
    }
}

/// A sample as the ICM-42688-P's 14-byte data block: TEMP_DATA1 …
/// GYRO_DATA_Z0, each register pair big-endian (DS-000347 §14.1 order).
/// The counts are a 16-bit chip's: each is taken as its i16 code.
pub fn sample_block(raw: &RawSample) -> [u8; 14] {
    let words = [
        raw.temperature,
        raw.accel[0] as i16,
        raw.accel[1] as i16,
        raw.accel[2] as i16,
        raw.gyro[0] as i16,
        raw.gyro[1] as i16,
        raw.gyro[2] as i16,
    ];
    let mut block = [0u8; 14];
    for (pair, w) in block.chunks_exact_mut(2).zip(words) {
        pair.copy_from_slice(&w.to_be_bytes());
    }
    block
}

/// An SPI device that answers every read with the 14 bytes of one sample
/// block (TEMP_DATA1 … GYRO_DATA_Z0, big-endian, ICM-42688-P §14.1 order).
#[derive(Clone, Debug, Default)]
pub struct CannedSpi {
    block: [u8; 14],
}

impl CannedSpi {
    /// Loads the sample the next burst read returns.
    pub fn load(&mut self, raw: &RawSample) {
        self.block = sample_block(raw);
    }
}

impl ErrorType for CannedSpi {
    type Error = Infallible;
}

impl SpiDevice for CannedSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Infallible> {
        for op in operations {
            if let Operation::Read(buffer) = op {
                let n = buffer.len().min(self.block.len());
                buffer[..n].copy_from_slice(&self.block[..n]);
            }
        }
        Ok(())
    }
}

/// The sampler and driver of the pipeline row.
#[derive(Debug)]
pub struct PipelineBench {
    sampler: Sampler,
    sensor: Icm42688<SpiInterface<CannedSpi>>,
    now_us: u32,
}

/// Steps 1 ms apart, decimation 1, no refold (the calibration has no
/// temperature terms): the emulated board's settings.
const PERIOD_US: u32 = 1_000;

impl PipelineBench {
    /// A pipeline correcting with `corrector`.
    pub fn new(corrector: Corrector) -> Self {
        PipelineBench {
            sampler: Sampler::new(corrector, true, 1, PERIOD_US, 0),
            sensor: Icm42688::new_spi(CannedSpi::default()),
            now_us: 0,
        }
    }

    /// One data-ready step on `raw`; the encoded frame goes to `out`.
    #[inline(always)]
    pub fn step(&mut self, raw: &RawSample, out: &mut EncodedFrame) {
        self.sensor.bus_mut().load(raw);
        self.now_us = self.now_us.wrapping_add(PERIOD_US);
        // The pipeline streams in calibrated mode: every frame is a data frame.
        if let StepOutcome::Frame(Outgoing::Data(frame)) =
            self.sampler.step(&mut self.sensor, self.now_us)
        {
            encode(&frame, &mut out.0);
        }
    }
}
