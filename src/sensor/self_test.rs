//! The chips' built-in self-test: what it measured on each axis, the limits
//! the chip maker publishes, and the verdict.
//!
//! A self-test moves each proof mass with a built-in electrostatic force and
//! reads the change of the output: the response is mean(output, self-test on)
//! − mean(output, self-test off), so the sensor must be still while it runs.
//! Each chip module runs its maker's procedure ([`ChipSelfTest`]: `self_test`
//! on the driver and on [`AnyChip`](super::AnyChip)); this module holds the
//! save–run–write-back frame every procedure runs in, what they report, the
//! acceptance rule, and the sampling loop they share.

use embedded_hal::delay::DelayNs;

use super::chip::Chip;
use super::driver::Driver;
use super::error::Error;
use super::interface::RegisterInterface;
use crate::model::Triad;
use crate::units::{deg_to_rad, STANDARD_GRAVITY};

/// A sensor axis (the chip's own axes, before any mounting rotation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

impl Axis {
    /// x, y, z.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// 0, 1, 2: the index into a triad's arrays.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        match self {
            Axis::X => "x",
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }
}

/// The unit data sheets give a triad's self-test figures in: `mg` for the
/// accelerometer, `dps` (°/s) for the gyroscope.
pub fn data_sheet_unit(triad: Triad) -> &'static str {
    match triad {
        Triad::Accel => "mg",
        Triad::Gyro => "dps",
    }
}

/// SI units (m/s² or rad/s) per data-sheet unit (mg or °/s).
pub fn si_per_data_sheet_unit(triad: Triad) -> f64 {
    match triad {
        Triad::Accel => 1e-3 * STANDARD_GRAVITY,
        Triad::Gyro => deg_to_rad(1.0),
    }
}

/// What one axis's self-test response must satisfy, in the data sheet's unit
/// (mg or °/s).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SelfTestLimits {
    /// The smallest accepted |response|.
    pub min: f64,
    /// The largest accepted |response|.
    pub max: f64,
    /// The response the factory measured and stored in the chip, when the
    /// chip stores one (ICM-42688-P): `min` and `max` are then 0.5 and 1.5
    /// times it, and both bounds are excluded (the maker's driver fails a
    /// ratio ≤ 0.5 or ≥ 1.5). `None`: fixed limits, both bounds included.
    pub factory: Option<f64>,
    /// The largest accepted |output| with self-test off, when the procedure
    /// bounds it (ICM-42688-P gyroscope: 20 °/s, the chip must be at rest).
    pub max_offset: Option<f64>,
}

impl SelfTestLimits {
    /// Fixed limits, both included: min ≤ |response| ≤ max.
    pub fn fixed(min: f64, max: f64) -> Self {
        Self {
            min,
            max,
            factory: None,
            max_offset: None,
        }
    }

    /// Limits relative to a stored factory response: 0.5 < |response| / factory < 1.5.
    pub fn factory_ratio(factory: f64) -> Self {
        Self {
            min: FACTORY_RATIO_MIN * factory,
            max: FACTORY_RATIO_MAX * factory,
            factory: Some(factory),
            max_offset: None,
        }
    }

    /// The same limits with the self-test-off output bounded by `max_offset`.
    pub fn with_max_offset(self, max_offset: f64) -> Self {
        Self {
            max_offset: Some(max_offset),
            ..self
        }
    }

    /// Whether a response of `magnitude` (data-sheet unit, ≥ 0) is accepted.
    pub fn accepts_response(&self, magnitude: f64) -> bool {
        match self.factory {
            Some(factory) => {
                let ratio = magnitude / factory;
                ratio > FACTORY_RATIO_MIN && ratio < FACTORY_RATIO_MAX
            }
            None => magnitude >= self.min && magnitude <= self.max,
        }
    }

    /// Whether an output of `off` (data-sheet unit) with self-test off is accepted.
    pub fn accepts_offset(&self, off: f64) -> bool {
        self.max_offset.is_none_or(|max| off.abs() <= max)
    }
}

/// The ratio window to a factory-stored response (TDK InvenSense's
/// self-test drivers for the ICM-426xx family: pass when 0.5 < ratio < 1.5).
const FACTORY_RATIO_MIN: f64 = 0.5;
/// See [`FACTORY_RATIO_MIN`].
const FACTORY_RATIO_MAX: f64 = 1.5;

/// One axis's self-test.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisSelfTest {
    /// The response, mean(on) − mean(off), in SI units (m/s² or rad/s).
    pub response: f64,
    /// The response in the data sheet's unit (mg or °/s).
    pub response_data_sheet: f64,
    /// The mean output with self-test off, in SI units: what the axis read
    /// at rest (gravity, bias), for the record.
    pub off: f64,
    /// The limits applied.
    pub limits: SelfTestLimits,
    /// |response| within the limits.
    pub response_ok: bool,
    /// The self-test-off output within `limits.max_offset` (true when unbounded).
    pub offset_ok: bool,
}

impl AxisSelfTest {
    /// Judges one axis of `triad` from its mean outputs with self-test off
    /// and on, in the data sheet's unit.
    pub fn judge(triad: Triad, off: f64, on: f64, limits: SelfTestLimits) -> Self {
        let si = si_per_data_sheet_unit(triad);
        let response = on - off;
        Self {
            response: response * si,
            response_data_sheet: response,
            off: off * si,
            limits,
            response_ok: limits.accepts_response(response.abs()),
            offset_ok: limits.accepts_offset(off),
        }
    }

    /// Whether the axis passed.
    pub fn passed(&self) -> bool {
        self.response_ok && self.offset_ok
    }
}

/// One triad's self-test: its three axes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TriadSelfTest {
    /// Which triad.
    pub triad: Triad,
    /// x, y, z.
    pub axes: [AxisSelfTest; 3],
}

impl TriadSelfTest {
    /// Judges each axis from the mean outputs off and on (data-sheet unit)
    /// against its limits.
    pub fn judge(triad: Triad, off: [f64; 3], on: [f64; 3], limits: [SelfTestLimits; 3]) -> Self {
        let axis = |i: usize| AxisSelfTest::judge(triad, off[i], on[i], limits[i]);
        Self {
            triad,
            axes: [axis(0), axis(1), axis(2)],
        }
    }

    /// Whether every axis passed.
    pub fn passed(&self) -> bool {
        self.axes.iter().all(AxisSelfTest::passed)
    }

    /// The axes that failed.
    pub fn failed_axes(&self) -> impl Iterator<Item = Axis> + '_ {
        Axis::ALL
            .into_iter()
            .filter(|axis| !self.axes[axis.index()].passed())
    }
}

/// A chip's self-test: both triads.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SelfTestReport {
    /// The accelerometer.
    pub accel: TriadSelfTest,
    /// The gyroscope.
    pub gyro: TriadSelfTest,
}

impl SelfTestReport {
    /// Whether every axis of both triads passed.
    pub fn passed(&self) -> bool {
        self.accel.passed() && self.gyro.passed()
    }

    /// Each failed axis, named by triad and axis (accelerometer first).
    pub fn failures(&self) -> impl Iterator<Item = (Triad, Axis)> + '_ {
        let accel = self.accel.failed_axes().map(|axis| (Triad::Accel, axis));
        let gyro = self.gyro.failed_axes().map(|axis| (Triad::Gyro, axis));
        accel.chain(gyro)
    }
}

/// The state a self-test that did not finish left the chip in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChipLeft {
    /// Configured as before the self-test (nothing was changed, or every
    /// changed register was written back): sampling can resume.
    AsConfigured,
    /// The configuration could not be written back (the bus failed again):
    /// the chip may still be in the self-test configuration, with its
    /// excitation on. Run the driver's `init` before sampling.
    NeedsInit,
}

/// A self-test that did not finish: why, and the state it left the chip in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SelfTestError<E> {
    /// The first error (a bus error, or no new sample in time).
    pub error: Error<E>,
    /// What the chip was left in.
    pub chip: ChipLeft,
}

/// A chip's data-sheet self-test, as its maker publishes it (each chip
/// module's `self_test.rs`): the configuration it changes is saved first
/// and written back at the end, whatever happened in between.
pub trait ChipSelfTest: Chip {
    /// What the procedure saves before it changes anything.
    type Saved;

    /// The longest the procedure can take, ms (bus time excluded): what a
    /// caller's watchdog or link timeout should allow.
    fn self_test_max_duration_ms() -> u32;

    /// Reads the configuration the procedure changes.
    fn save<I: RegisterInterface>(
        driver: &mut Driver<Self, I>,
    ) -> Result<Self::Saved, Error<I::BusError>>;

    /// The procedure on both triads, and the verdicts.
    fn run<I: RegisterInterface>(
        driver: &mut Driver<Self, I>,
        delay: &mut impl DelayNs,
        saved: &Self::Saved,
    ) -> Result<SelfTestReport, Error<I::BusError>>;

    /// Writes `saved` back and empties the FIFO (which took self-test
    /// samples), so sampling resumes in the configuration it had.
    fn restore<I: RegisterInterface>(
        driver: &mut Driver<Self, I>,
        delay: &mut impl DelayNs,
        saved: &Self::Saved,
    ) -> Result<(), Error<I::BusError>>;
}

impl<C: ChipSelfTest, I: RegisterInterface> Driver<C, I> {
    /// Runs the chip's data-sheet self-test on both triads and reports each
    /// axis's response, limits and verdict (each chip module documents its
    /// procedure). The chip must be still and sampling paused; it takes at
    /// most [`ChipSelfTest::self_test_max_duration_ms`]. The configuration
    /// is written back at the end. A verdict of fail is `Ok` with the
    /// failing axes in the report; `Err` means the procedure did not finish
    /// (bus error, or no new sample within twice the expected time), and
    /// says whether the write-back restored the chip.
    pub fn self_test(
        &mut self,
        delay: &mut impl DelayNs,
    ) -> Result<SelfTestReport, SelfTestError<I::BusError>> {
        let saved = C::save(self).map_err(untouched)?;
        let run = C::run(self, delay, &saved);
        let restore = C::restore(self, delay, &saved);
        conclude(run, restore)
    }
}

/// The outcome of a procedure run between saving and writing back the
/// configuration: the report if both succeeded; otherwise the first error,
/// and whether the write-back (always attempted) restored the chip.
fn conclude<E>(
    run: Result<SelfTestReport, Error<E>>,
    restore: Result<(), Error<E>>,
) -> Result<SelfTestReport, SelfTestError<E>> {
    match (run, restore) {
        (Ok(report), Ok(())) => Ok(report),
        (Err(error), Ok(())) => Err(SelfTestError {
            error,
            chip: ChipLeft::AsConfigured,
        }),
        (Ok(_), Err(error)) | (Err(error), Err(_)) => Err(SelfTestError {
            error,
            chip: ChipLeft::NeedsInit,
        }),
    }
}

/// An error before anything was written: the chip is as it was.
fn untouched<E>(error: Error<E>) -> SelfTestError<E> {
    SelfTestError {
        error,
        chip: ChipLeft::AsConfigured,
    }
}

/// What one poll of the chip found.
pub(crate) enum Poll {
    /// A new sample of the triad under test, in counts.
    Sample([i16; 3]),
    /// No new (valid) sample yet; the status register read.
    NotReady {
        /// The status register read, reported if the wait times out.
        status: u8,
    },
}

/// How one averaging pass samples: discard the first `discard` new samples,
/// average the next `average`, polling every `poll_ns`, and give up after
/// `budget_ns` of waiting in all.
pub(crate) struct Sampling {
    /// New samples read and thrown away first (settling).
    pub discard: u32,
    /// Samples averaged.
    pub average: u32,
    /// Wait between polls, ns.
    pub poll_ns: u32,
    /// The longest the pass may wait in all, ns.
    pub budget_ns: u64,
}

impl Sampling {
    /// `discard` then `average` samples at `period_ns`, polled 8 times per
    /// period, within twice the time they take at the nominal rate (room for
    /// a chip clock a few percent slow, and for the first sample's phase).
    pub fn at_period(discard: u32, average: u32, period_ns: u64) -> Self {
        let samples = u64::from(discard + average);
        Self {
            discard,
            average,
            // A period is at most 80 ms here: an eighth fits in u32.
            poll_ns: u32::try_from(period_ns / 8).unwrap_or(u32::MAX),
            budget_ns: 2 * samples * period_ns,
        }
    }

    /// The mean of `average` samples after `discard`, in counts, from `poll`;
    /// [`Error::NoNewData`] with the last status read if the budget runs out.
    pub fn mean<E>(
        &self,
        delay: &mut impl DelayNs,
        mut poll: impl FnMut() -> Result<Poll, Error<E>>,
    ) -> Result<[f64; 3], Error<E>> {
        let mut sum = [0i64; 3];
        let mut taken = 0;
        let mut waited: u64 = 0;
        while taken < self.discard + self.average {
            match poll()? {
                Poll::Sample(sample) => {
                    if taken >= self.discard {
                        for (s, v) in sum.iter_mut().zip(sample) {
                            *s += i64::from(v);
                        }
                    }
                    taken += 1;
                }
                Poll::NotReady { status } => {
                    if waited >= self.budget_ns {
                        return Err(Error::NoNewData { status });
                    }
                    delay.delay_ns(self.poll_ns);
                    waited += u64::from(self.poll_ns);
                }
            }
        }
        // Sums of at most a few hundred i16: exact in f64.
        let n = f64::from(self.average.max(1));
        Ok(sum.map(|s| s as f64 / n))
    }
}
