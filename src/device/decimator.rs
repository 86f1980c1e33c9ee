//! Averaging N corrected samples into one streamed sample, so the stream rate
//! can be the sample rate divided by N.

use crate::model::{ClipFlags, Sample};

/// Averages blocks of `factor` samples. A factor of 1 passes samples through
/// unchanged (bit for bit). Clip flags of the block are OR-ed: an average that
/// contains a clipped sample is itself suspect.
#[derive(Clone, Debug)]
pub struct Decimator {
    factor: u16,
    count: u16,
    accel: [f32; 3],
    gyro: [f32; 3],
    temperature: f32,
    clip: ClipFlags,
}

impl Decimator {
    /// A decimator by `factor`; 0 is taken as 1 (no averaging).
    pub const fn new(factor: u16) -> Self {
        Self {
            factor: if factor == 0 { 1 } else { factor },
            count: 0,
            accel: [0.0; 3],
            gyro: [0.0; 3],
            temperature: 0.0,
            clip: ClipFlags {
                accel: false,
                gyro: false,
            },
        }
    }

    /// The averaging factor N.
    pub fn factor(&self) -> u16 {
        self.factor
    }

    /// Adds one sample; returns the average when the block of N is complete.
    ///
    /// The sum is kept in f32: for N ≤ 2¹⁰ samples of similar magnitude the
    /// rounding of the running sum adds at most about N·2⁻²⁴ relative error,
    /// below a 16-bit sensor's resolution (2⁻¹⁵ of full scale).
    #[inline]
    pub fn push(&mut self, sample: &Sample) -> Option<Sample> {
        if self.factor == 1 {
            return Some(*sample);
        }
        for i in 0..3 {
            self.accel[i] += sample.accel[i];
            self.gyro[i] += sample.gyro[i];
        }
        self.temperature += sample.temperature;
        self.clip.accel |= sample.clip.accel;
        self.clip.gyro |= sample.clip.gyro;
        self.count += 1;
        if self.count < self.factor {
            return None;
        }
        let scale = 1.0 / f32::from(self.factor);
        let average = Sample {
            accel: self.accel.map(|x| x * scale),
            gyro: self.gyro.map(|x| x * scale),
            temperature: self.temperature * scale,
            clip: self.clip,
        };
        *self = Self::new(self.factor);
        Some(average)
    }
}
