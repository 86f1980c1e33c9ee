//! The LSM6DSOX self-test, as ST publishes it (application note AN5272,
//! "Self-test", the accelerometer and gyroscope procedures; the same steps
//! as ST's reference example `lsm6dsox_self_test.c`), with the limits of
//! DS12814 Table 2 (LA_ST, G_ST).
//!
//! Per triad: write the ten control registers CTRL1_XL..=CTRL10_C (the
//! triad under test on, the other off, BDU on), wait 100 ms, read and
//! discard one sample, average five; turn the positive self-test on
//! (CTRL5_C), wait 100 ms, discard one, average five; turn the self-test
//! and the triad off. Pass when min ≤ |mean(on) − mean(off)| ≤ max on every axis.

use embedded_hal::delay::DelayNs;

use super::config::{self, AccelRange, GyroRange, Odr};
use super::registers as reg;
use super::{Lsm6dsox, Lsm6dsoxChip};
use crate::model::Triad;
use crate::sensor::chip::DataRate;
use crate::sensor::error::Error;
use crate::sensor::interface::RegisterInterface;
use crate::sensor::self_test::{
    ChipSelfTest, Poll, Sampling, SelfTestLimits, SelfTestReport, TriadSelfTest,
};

/// CTRL1_XL..=CTRL10_C: the registers the procedure writes.
const CONTROL_REGISTERS: usize = (reg::CTRL10_C - reg::CTRL1_XL + 1) as usize;
/// AN5272: wait after a configuration or self-test change, for a stable output.
const SETTLE_MS: u32 = 100;
/// AN5272: samples read and discarded after each wait.
const DISCARDED: u32 = 1;
/// AN5272: samples averaged with self-test off, and again on.
const AVERAGED: u32 = 5;

/// DS12814 Table 2 LA_ST: accelerometer self-test output change, mg
/// (full-scale independent).
const ACCEL_LIMITS_MG: (f64, f64) = (50.0, 1700.0);
/// DS12814 Table 2 G_ST: gyroscope self-test output change at ±2000 °/s, °/s.
const GYRO_LIMITS_DPS: (f64, f64) = (150.0, 700.0);

/// What differs between the two triads' procedures.
struct Procedure {
    triad: Triad,
    /// CTRL1_XL..=CTRL10_C while testing (AN5272's values, in its order).
    setup: [u8; CONTROL_REGISTERS],
    /// The triad's output data rate while testing.
    odr: Odr,
    /// CTRL5_C with the positive self-test on.
    self_test: u8,
    /// STATUS_REG: the triad's new-data bit.
    ready: u8,
    /// The triad's first output register.
    output: u8,
    /// Data-sheet units (mg or °/s) per LSB at the test's full scale.
    unit_per_lsb: f64,
    /// DS12814 Table 2 limits, data-sheet units.
    limits: (f64, f64),
    /// The control register holding the triad's ODR (off at the end).
    odr_register: u8,
}

impl Procedure {
    /// Accelerometer: CTRL1_XL = 38h (52 Hz, ±4 g), CTRL2_G = 00h, CTRL3_C =
    /// 44h (BDU, IF_INC), CTRL4_C..CTRL10_C = 00h; CTRL5_C = 01h (ST_XL positive).
    fn accel() -> Self {
        let odr = Odr::Hz52;
        let range = AccelRange::G4;
        Self {
            triad: Triad::Accel,
            setup: control_setup(
                (odr.code() << reg::ODR_SHIFT) | (config::accel_fs_xl(range) << reg::FS_SHIFT),
                0,
            ),
            odr,
            self_test: reg::ST_XL_POSITIVE,
            ready: reg::XLDA,
            output: reg::OUTX_L_A,
            unit_per_lsb: config::accel_mg_per_lsb(range),
            limits: ACCEL_LIMITS_MG,
            odr_register: reg::CTRL1_XL,
        }
    }

    /// Gyroscope: CTRL1_XL = 00h, CTRL2_G = 5Ch (208 Hz, ±2000 °/s), CTRL3_C =
    /// 44h, CTRL4_C..CTRL10_C = 00h; CTRL5_C = 04h (ST_G positive).
    fn gyro() -> Self {
        let odr = Odr::Hz208;
        let range = GyroRange::Dps2000;
        Self {
            triad: Triad::Gyro,
            setup: control_setup(0, (odr.code() << reg::ODR_SHIFT) | range.bits()),
            odr,
            self_test: reg::ST_G_POSITIVE,
            ready: reg::GDA,
            output: reg::OUTX_L_G,
            unit_per_lsb: range.mdps_per_lsb() * 1e-3,
            limits: GYRO_LIMITS_DPS,
            odr_register: reg::CTRL2_G,
        }
    }

    fn sampling(&self) -> Sampling {
        let period_ns = 1_000_000_000_000 / u64::from(self.odr.millihertz());
        Sampling::at_period(DISCARDED, AVERAGED, period_ns)
    }
}

/// CTRL1_XL..=CTRL10_C: the two ODR/FS registers, CTRL3_C = BDU | IF_INC,
/// every other control register (self-test, filters, modes) 00h.
fn control_setup(ctrl1_xl: u8, ctrl2_g: u8) -> [u8; CONTROL_REGISTERS] {
    let mut setup = [0; CONTROL_REGISTERS];
    setup[0] = ctrl1_xl;
    setup[1] = ctrl2_g;
    setup[usize::from(reg::CTRL3_C - reg::CTRL1_XL)] = reg::BDU | reg::IF_INC;
    setup
}

/// CTRL1_XL..=CTRL10_C and FIFO_CTRL4, as the procedure found them.
pub struct Saved {
    control: [u8; CONTROL_REGISTERS],
    fifo_ctrl4: u8,
}

/// The data sheet's self-test (AN5272) on the accelerometer, then the
/// gyroscope: each axis's response against DS12814's limits (accelerometer
/// 50–1700 mg, gyroscope 150–700 °/s).
///
/// The chip must be still. It takes about 0.64 s (accelerometer: 2 ×
/// (100 ms wait + 6 samples at 52 Hz); gyroscope: 2 × (100 ms + 6 samples
/// at 208 Hz)); the caller stops sampling meanwhile, as the outputs carry
/// the self-test configuration.
///
/// CTRL1_XL..=CTRL10_C are read first and written back at the end, and the
/// FIFO (which batched self-test samples) is emptied by a pass through
/// bypass mode back to FIFO_CTRL4's value.
impl ChipSelfTest for Lsm6dsoxChip {
    type Saved = Saved;

    /// The procedure's waits plus every sampling pass's time budget.
    /// Nominally it takes about 0.64 s.
    fn self_test_max_duration_ms() -> u32 {
        let ns: u64 = [Procedure::accel(), Procedure::gyro()]
            .iter()
            .map(|p| 2 * (u64::from(SETTLE_MS) * 1_000_000 + p.sampling().budget_ns))
            .sum();
        // Under a second: fits.
        u32::try_from(ns.div_ceil(1_000_000)).unwrap_or(u32::MAX)
    }

    fn save<I: RegisterInterface>(driver: &mut Lsm6dsox<I>) -> Result<Saved, Error<I::BusError>> {
        let mut control = [0u8; CONTROL_REGISTERS];
        driver.read_registers(reg::CTRL1_XL, &mut control)?;
        let fifo_ctrl4 = driver.read_register(reg::FIFO_CTRL4)?;
        Ok(Saved {
            control,
            fifo_ctrl4,
        })
    }

    fn run<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
        delay: &mut impl DelayNs,
        _saved: &Saved,
    ) -> Result<SelfTestReport, Error<I::BusError>> {
        driver.run_self_test(delay)
    }

    fn restore<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
        _delay: &mut impl DelayNs,
        saved: &Saved,
    ) -> Result<(), Error<I::BusError>> {
        driver.restore_after_self_test(&saved.control, saved.fifo_ctrl4)
    }
}

impl<I: RegisterInterface> Lsm6dsox<I> {
    fn run_self_test(
        &mut self,
        delay: &mut impl DelayNs,
    ) -> Result<SelfTestReport, Error<I::BusError>> {
        let accel = self.self_test_triad(delay, &Procedure::accel())?;
        let gyro = self.self_test_triad(delay, &Procedure::gyro())?;
        Ok(SelfTestReport { accel, gyro })
    }

    fn self_test_triad(
        &mut self,
        delay: &mut impl DelayNs,
        procedure: &Procedure,
    ) -> Result<TriadSelfTest, Error<I::BusError>> {
        for (register, value) in (reg::CTRL1_XL..=reg::CTRL10_C).zip(procedure.setup) {
            self.write(register, value)?;
        }
        delay.delay_ms(SETTLE_MS);
        let off = self.mean_output(delay, procedure)?;
        self.write(reg::CTRL5_C, procedure.self_test)?;
        delay.delay_ms(SETTLE_MS);
        let on = self.mean_output(delay, procedure)?;
        self.write(reg::CTRL5_C, 0)?;
        self.write(procedure.odr_register, 0)?;
        let limits = SelfTestLimits::fixed(procedure.limits.0, procedure.limits.1);
        let unit = |counts: [f64; 3]| counts.map(|c| c * procedure.unit_per_lsb);
        Ok(TriadSelfTest::judge(
            procedure.triad,
            unit(off),
            unit(on),
            [limits; 3],
        ))
    }

    /// The mean of the triad's output (counts) after the discarded sample,
    /// each sample read when STATUS_REG flags it new.
    fn mean_output(
        &mut self,
        delay: &mut impl DelayNs,
        procedure: &Procedure,
    ) -> Result<[f64; 3], Error<I::BusError>> {
        procedure.sampling().mean(delay, || {
            let status = self.read_register(reg::STATUS_REG)?;
            if status & procedure.ready == 0 {
                return Ok(Poll::NotReady { status });
            }
            let mut b = [0u8; 6];
            self.interface
                .read_registers(procedure.output, &mut b)
                .map_err(Error::Bus)?;
            Ok(Poll::Sample(super::words_le(&b)))
        })
    }

    /// Writes back the control registers (self-test off first, the output
    /// data rates last, BOOT and SW_RESET never: they are commands), then
    /// empties the FIFO and restores its mode.
    fn restore_after_self_test(
        &mut self,
        saved: &[u8; CONTROL_REGISTERS],
        fifo_ctrl4: u8,
    ) -> Result<(), Error<I::BusError>> {
        let index = |register: u8| usize::from(register - reg::CTRL1_XL);
        self.write(reg::CTRL5_C, saved[index(reg::CTRL5_C)])?;
        for register in reg::CTRL3_C..=reg::CTRL10_C {
            let mut value = saved[index(register)];
            if register == reg::CTRL3_C {
                value &= !(reg::BOOT | reg::SW_RESET);
            }
            if register != reg::CTRL5_C {
                self.write(register, value)?;
            }
        }
        self.write(reg::CTRL1_XL, saved[index(reg::CTRL1_XL)])?;
        self.write(reg::CTRL2_G, saved[index(reg::CTRL2_G)])?;
        self.write(reg::FIFO_CTRL4, reg::FIFO_MODE_BYPASS)?;
        self.write(reg::FIFO_CTRL4, fifo_ctrl4)
    }
}
