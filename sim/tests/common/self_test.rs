//! Scaffolding for the self-test tests: a chip at rest with white noise, a
//! delay that acts on the model at a chosen time, an SPI bus that records
//! every register write, and what the tests read of either chip model.

use std::cell::RefCell;

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{self, Operation, SpiDevice};
use triad::model::Triad;
use triad::sensor::self_test::si_per_data_sheet_unit;
use triad::sensor::{Axis, ImuScale, RawSample, SelfTestReport};
use triad::units::STANDARD_GRAVITY;
use triad_sim::chips::fault::Fault;
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::chips::model_clock::{Clocked, ModelDelay, SharedBus};
use triad_sim::chips::self_test_response::SelfTestResponse;
use triad_sim::chips::source::{SampleSource, TrueSample};
use triad_sim::effects::rng::Rng;

/// A chip lying still, z up: specific force (0, 0, g) and no rotation, each
/// axis with Gaussian white noise of `accel_sigma` m/s² and `gyro_sigma`
/// rad/s per sample, plus a constant `rate` rad/s (0 for a chip at rest).
#[derive(Clone, Debug)]
pub struct NoisyRest {
    rng: Rng,
    /// Per-sample noise, m/s².
    pub accel_sigma: f64,
    /// Per-sample noise, rad/s.
    pub gyro_sigma: f64,
    /// A constant angular rate, rad/s.
    pub rate: [f64; 3],
}

impl NoisyRest {
    /// A chip at rest with the given noise, seeded with `seed`.
    pub fn new(seed: u64, accel_sigma: f64, gyro_sigma: f64) -> Self {
        Self {
            rng: Rng::from_seed(seed),
            accel_sigma,
            gyro_sigma,
            rate: [0.0; 3],
        }
    }

    /// The same with the noise in the data sheets' units: mg and °/s.
    pub fn with_data_sheet_noise(seed: u64, accel_mg: f64, gyro_dps: f64) -> Self {
        Self::new(
            seed,
            accel_mg * si_per_data_sheet_unit(Triad::Accel),
            gyro_dps * si_per_data_sheet_unit(Triad::Gyro),
        )
    }
}

impl SampleSource for NoisyRest {
    fn next_sample(&mut self) -> TrueSample {
        let mut s = TrueSample {
            specific_force: [0.0, 0.0, STANDARD_GRAVITY],
            angular_rate: self.rate,
            temperature: 25.0,
        };
        for axis in 0..3 {
            s.specific_force[axis] += self.accel_sigma * self.rng.gaussian();
            s.angular_rate[axis] += self.gyro_sigma * self.rng.gaussian();
        }
        s
    }
}

/// A [`ModelDelay`] that runs `action` on the model once, as soon as
/// `at_ns` of waiting has passed (e.g. to inject a fault mid-procedure).
pub struct ActAt<'a, M, F: FnMut(&mut M)> {
    /// The delay advancing the model.
    pub delay: ModelDelay<'a, M>,
    at_ns: u64,
    action: Option<F>,
}

impl<'a, M, F: FnMut(&mut M)> ActAt<'a, M, F> {
    /// `action` on `model` after `at_ns`.
    pub fn new(model: &'a RefCell<M>, at_ns: u64, action: F) -> Self {
        Self {
            delay: ModelDelay::new(model),
            at_ns,
            action: Some(action),
        }
    }
}

impl<M: Clocked, F: FnMut(&mut M)> DelayNs for ActAt<'_, M, F> {
    fn delay_ns(&mut self, ns: u32) {
        self.delay.delay_ns(ns);
        if self.delay.elapsed_ns() >= self.at_ns {
            if let Some(mut action) = self.action.take() {
                action(&mut self.delay.model().borrow_mut());
            }
        }
    }
}

/// An SPI device over a shared model that records each single-register
/// write (a transaction writing an address with bit 7 clear and one value).
pub struct WriteLog<'a, M> {
    bus: SharedBus<'a, M>,
    /// (register, value), in order.
    pub writes: Vec<(u8, u8)>,
}

impl<'a, M> WriteLog<'a, M> {
    /// A recording bus over `model`.
    pub fn new(model: &'a RefCell<M>) -> Self {
        Self {
            bus: SharedBus(model),
            writes: Vec::new(),
        }
    }
}

impl<M: spi::ErrorType> spi::ErrorType for WriteLog<'_, M> {
    type Error = M::Error;
}

impl<M: SpiDevice> SpiDevice for WriteLog<'_, M> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        let write = match operations {
            [Operation::Write([register, value])] if register & 0x80 == 0 => {
                Some((*register, *value))
            }
            _ => None,
        };
        self.bus.transaction(operations)?;
        self.writes.extend(write);
        Ok(())
    }
}

/// Reads one register of a model on SPI, outside any driver.
pub fn spi_read<M: SpiDevice>(model: &RefCell<M>, register: u8) -> u8 {
    let mut value = [0u8];
    model
        .borrow_mut()
        .transaction(&mut [
            Operation::Write(&[register | 0x80]),
            Operation::Read(&mut value),
        ])
        .expect("the model answers");
    value[0]
}

/// How far a reported self-test response may lie from the emulated one, SI:
/// 5 σ of the response's noise (σ·√(2/n) after averaging `n` samples on and
/// `n` off, with noise `sigma` per sample) plus one `lsb` of quantisation;
/// `sigma` and `lsb` in the data sheet's unit (mg or °/s).
pub fn response_tolerance(triad: Triad, sigma: f64, n: f64, lsb: f64) -> f64 {
    (5.0 * sigma * (2.0 / n).sqrt() + lsb) * si_per_data_sheet_unit(triad)
}

/// What the self-test tests need of a chip model besides its buses and clock.
pub trait ModelUnderTest:
    SpiDevice
    + spi::ErrorType<Error = spi::ErrorKind>
    + embedded_hal::i2c::I2c
    + embedded_hal::i2c::ErrorType<Error = embedded_hal::i2c::ErrorKind>
    + Clocked
{
    /// Injects a fault.
    fn inject_fault(&mut self, fault: Fault);
    /// Clears every persistent fault.
    fn clear(&mut self);
    /// A (bank-0) register's stored value.
    fn stored(&self, address: u8) -> u8;
    /// Whether sampling changes `address` (data, status, FIFO registers).
    fn volatile(address: u8) -> bool;
    /// What the positive self-test adds, SI.
    fn response(&self) -> SelfTestResponse;
}

/// Both models answer to the same inherent methods.
macro_rules! model_under_test {
    ($model:ident, $volatile:pat) => {
        impl<S: SampleSource> ModelUnderTest for $model<S> {
            fn inject_fault(&mut self, fault: Fault) {
                self.inject(fault);
            }
            fn clear(&mut self) {
                self.clear_faults();
            }
            fn stored(&self, address: u8) -> u8 {
                self.peek(address)
            }
            fn volatile(address: u8) -> bool {
                matches!(address, $volatile)
            }
            fn response(&self) -> SelfTestResponse {
                self.self_test_response()
            }
        }
    };
}

// TEMP_DATA1..=FIFO_DATA, FIFO_LOST_PKT0/1.
model_under_test!(Icm42688Model, 0x1D..=0x30 | 0x6C..=0x6D);
// STATUS_REG..=OUTZ_H_A, FIFO_STATUS1/2, FIFO_DATA_OUT_TAG..=FIFO_DATA_OUT_Z_H.
model_under_test!(Lsm6dsoxModel, 0x1E..=0x2D | 0x3A..=0x3B | 0x78..=0x7E);

/// Every register the model stores except those sampling changes: the
/// chip's configuration.
pub fn configuration<M: ModelUnderTest>(model: &RefCell<M>) -> Vec<(u8, u8)> {
    (0..0x80u8)
        .filter(|&a| !M::volatile(a))
        .map(|a| (a, model.borrow().stored(a)))
        .collect()
}

/// Asserts that `report` passed and that each axis's response is the
/// emulated one within `tolerance(triad)` (SI), in the data sheet's unit
/// alike; and that with self-test off the accelerometer read the still chip
/// z up, (0, 0, g), within `tolerance(Accel)`.
pub fn assert_reports_emulated(
    report: &SelfTestReport,
    emulated: &SelfTestResponse,
    tolerance: impl Fn(Triad) -> f64,
) {
    assert!(report.passed(), "{report:?}");
    for (triad, result) in [(Triad::Accel, report.accel), (Triad::Gyro, report.gyro)] {
        assert_eq!(result.triad, triad);
        for axis in Axis::ALL {
            let got = result.axes[axis.index()];
            let want = emulated.get(triad, axis);
            assert!(
                (got.response - want).abs() <= tolerance(triad),
                "{triad:?} {axis:?}: reported {} SI, emulated {want}",
                got.response
            );
            let in_data_sheet_units = got.response / si_per_data_sheet_unit(triad);
            assert!((got.response_data_sheet - in_data_sheet_units).abs() < 1e-9);
        }
    }
    let off = report.accel.axes.map(|a| a.off);
    for (got, want) in off.iter().zip([0.0, 0.0, STANDARD_GRAVITY]) {
        assert!((got - want).abs() <= tolerance(Triad::Accel), "off {off:?}");
    }
}

/// Asserts that `sample` is the still chip z up: z within `accel_tolerance`
/// m/s² of g, gyroscope x within `gyro_tolerance` rad/s of 0 (no self-test in it).
pub fn assert_still(
    sample: &RawSample,
    scale: &ImuScale,
    accel_tolerance: f64,
    gyro_tolerance: f64,
) {
    let z = f64::from(sample.accel[2]) * scale.accel.si_per_lsb;
    let gyro_x = f64::from(sample.gyro[0]) * scale.gyro.si_per_lsb;
    assert!((z - STANDARD_GRAVITY).abs() < accel_tolerance, "z {z}");
    assert!(gyro_x.abs() < gyro_tolerance, "gyro x {gyro_x}");
}

/// Runs a driver's self-test (`self_test`, given a delay that drives
/// `model`'s clock) and asserts that it passed and left the chip's
/// configuration as it found it.
pub fn assert_passes_and_keeps_configuration<M: ModelUnderTest, E: core::fmt::Debug>(
    model: &RefCell<M>,
    self_test: impl FnOnce(&mut ModelDelay<'_, M>) -> Result<SelfTestReport, E>,
) {
    let before = configuration(model);
    let report = self_test(&mut ModelDelay::new(model)).expect("finishes");
    assert!(report.passed(), "{report:?}");
    assert_eq!(configuration(model), before);
}

/// Runs a driver's self-test and asserts that it took at least `least_ms`
/// and at most `bound_ms` of the model's time; prints the time.
pub fn assert_duration<M: ModelUnderTest, E: core::fmt::Debug>(
    model: &RefCell<M>,
    least_ms: f64,
    bound_ms: u32,
    self_test: impl FnOnce(&mut ModelDelay<'_, M>) -> Result<SelfTestReport, E>,
) {
    let mut delay = ModelDelay::new(model);
    self_test(&mut delay).expect("finishes");
    let elapsed_ms = delay.elapsed_ns() as f64 * 1e-6;
    assert!(elapsed_ms >= least_ms, "{elapsed_ms} ms < {least_ms} ms");
    assert!(
        elapsed_ms <= f64::from(bound_ms),
        "{elapsed_ms} ms > {bound_ms} ms"
    );
    println!("self-test: {elapsed_ms:.1} ms of the model's time (at least {least_ms:.1}, bound {bound_ms} ms)");
}
