//! The reply to `self-test`: each axis's measured response and its limits.
//!
//! Payload (little-endian): `passed u8` (1 when every axis passed), then
//! for the accelerometer x, y, z and the gyroscope x, y, z, 21 bytes each:
//! `response f32` (self-test on − off, SI: m/s² or rad/s) `| off f32` (the
//! output with self-test off, SI) `| min f32 | max f32` (the accepted
//! |response|, data-sheet unit: mg or °/s) `| factory f32` (the response
//! the chip stores from its factory test, mg or °/s; NaN when it stores
//! none) `| verdict u8` (bit 0: response accepted, bit 1: self-test-off
//! output accepted). 127 bytes.

use super::bytes::{Reader, Writer};
use super::payload::Payload;
use crate::model::Triad;
use crate::sensor::self_test::{AxisSelfTest, SelfTestReport};

/// Bytes of one axis's entry.
const AXIS_LEN: usize = 21;
/// Bytes of the whole payload.
pub const SELF_TEST_LEN: usize = 1 + 6 * AXIS_LEN;

/// One axis as the reply carries it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisResult {
    /// Self-test on − off, SI.
    pub response: f32,
    /// Output with self-test off, SI.
    pub off: f32,
    /// Smallest accepted |response|, data-sheet unit.
    pub min: f32,
    /// Largest accepted |response|, data-sheet unit.
    pub max: f32,
    /// The factory's stored response, data-sheet unit (NaN: none).
    pub factory: f32,
    /// The response is within the limits.
    pub response_ok: bool,
    /// The self-test-off output is within its bound (if any).
    pub offset_ok: bool,
}

/// The self-test reply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelfTestResult {
    /// Every axis passed.
    pub passed: bool,
    /// Accelerometer x, y, z.
    pub accel: [AxisResult; 3],
    /// Gyroscope x, y, z.
    pub gyro: [AxisResult; 3],
}

impl SelfTestResult {
    /// The wire form of a driver's report.
    pub fn of(report: &SelfTestReport) -> SelfTestResult {
        let axis = |a: &AxisSelfTest| AxisResult {
            response: a.response as f32,
            off: a.off as f32,
            min: a.limits.min as f32,
            max: a.limits.max as f32,
            factory: a.limits.factory.map_or(f32::NAN, |f| f as f32),
            response_ok: a.response_ok,
            offset_ok: a.offset_ok,
        };
        SelfTestResult {
            passed: report.passed(),
            accel: report.accel.axes.each_ref().map(axis),
            gyro: report.gyro.axes.each_ref().map(axis),
        }
    }

    /// The axes of one triad.
    pub fn triad(&self, triad: Triad) -> &[AxisResult; 3] {
        match triad {
            Triad::Accel => &self.accel,
            Triad::Gyro => &self.gyro,
        }
    }

    /// The reply payload.
    pub fn to_payload(&self) -> Payload {
        let mut p = Payload::EMPTY;
        let mut w = Writer::new(p.buffer());
        w.u8(u8::from(self.passed));
        for a in self.accel.iter().chain(&self.gyro) {
            w.f32(a.response)
                .f32(a.off)
                .f32(a.min)
                .f32(a.max)
                .f32(a.factory)
                .u8(u8::from(a.response_ok) | (u8::from(a.offset_ok) << 1));
        }
        let n = w.len();
        p.set_len(n);
        p
    }

    /// Reads a self-test payload; `None` when its length is wrong.
    pub fn parse(payload: &[u8]) -> Option<SelfTestResult> {
        if payload.len() != SELF_TEST_LEN {
            return None;
        }
        let mut r = Reader::new(payload);
        let passed = r.u8() != 0;
        let mut axis = || {
            let (response, off, min, max, factory) = (r.f32(), r.f32(), r.f32(), r.f32(), r.f32());
            let verdict = r.u8();
            AxisResult {
                response,
                off,
                min,
                max,
                factory,
                response_ok: verdict & 1 != 0,
                offset_ok: verdict & 2 != 0,
            }
        };
        let accel = [axis(), axis(), axis()];
        let gyro = [axis(), axis(), axis()];
        Some(SelfTestResult {
            passed,
            accel,
            gyro,
        })
    }
}
