//! The ICM-42688-P self-test, as TDK InvenSense implements it in its eMD
//! driver for the ICM-426xx family (`Icm426xxSelfTest.c`; the same steps in
//! `Ixm42xxxSelfTest.c`, 2022). DS-000347 gives the registers
//! (SELF_TEST_CONFIG, and the factory self-test codes XG/YG/ZG_ST_DATA in
//! user bank 1, XA/YA/ZA_ST_DATA in user bank 2) but no limits; the pass
//! criteria are the driver's.
//!
//! Per triad, at 1 kHz with the UI filter third order at ODR/10 (gyroscope
//! ±250 °/s, accelerometer ±4 g): turn the triad on (low noise) and wait for
//! it to settle (gyroscope 60 ms, accelerometer 25 ms), average 200 samples,
//! turn it off; again with its self-test on (gyroscope: EN_G*_ST, 200 ms to
//! stabilise; accelerometer: EN_A*_ST and ACCEL_ST_POWER, 25 ms). The
//! response on − off is compared per axis with the factory response the
//! axis's code encodes (2620 LSB / 2^(3 − FS_SEL) × 1.01^(code − 1)): pass
//! when 0.5 < ratio < 1.5. An axis with code 0 (no factory value) is held to
//! absolute limits instead: gyroscope ≥ 60 °/s, accelerometer 50–1200 mg.
//! The gyroscope's output with self-test off must also be within ±20 °/s
//! (the chip at rest).

use embedded_hal::delay::DelayNs;

use super::config::{self, AccelRange, GyroRange, Odr};
use super::registers as reg;
use super::{Icm42688, Icm42688Chip};
use crate::model::Triad;
use crate::sensor::chip::DataRate;
use crate::sensor::error::Error;
use crate::sensor::interface::RegisterInterface;
use crate::sensor::self_test::{
    ChipSelfTest, Poll, Sampling, SelfTestLimits, SelfTestReport, TriadSelfTest,
};

/// PWR_MGMT0..=ACCEL_CONFIG1 (0x4E..=0x53): the configuration the procedure changes.
const SAVED_REGISTERS: usize = (reg::ACCEL_CONFIG1 - reg::PWR_MGMT0 + 1) as usize;
/// Samples averaged with self-test off, and again on.
const AVERAGED: u32 = 200;
/// The output data rate while testing.
const ODR: Odr = Odr::Hz1000;
/// After writing the configuration back: the gyroscope's output settles.
const RESTORE_SETTLE_MS: u32 = 200;

/// The response-to-factory ratio is checked against the factory value;
/// without one (code 0) the gyroscope needs at least this, °/s.
const GYRO_MIN_ABSOLUTE_DPS: f64 = 60.0;
/// The gyroscope's largest accepted output with self-test off, °/s.
const GYRO_MAX_OFFSET_DPS: f64 = 20.0;
/// Without a factory value the accelerometer's response must lie in this range, mg.
const ACCEL_ABSOLUTE_MG: (f64, f64) = (50.0, 1200.0);

/// What differs between the two triads' procedures.
struct Procedure {
    triad: Triad,
    /// PWR_MGMT0 mode bits that turn the triad on (low noise).
    mode: u8,
    /// Wait after turning the triad on, ms.
    power_on_settle_ms: u32,
    /// SELF_TEST_CONFIG with the triad's self-test on.
    self_test: u8,
    /// Wait after turning the self-test on, ms.
    self_test_settle_ms: u32,
    /// The triad's first output register.
    output: u8,
    /// The full-scale field (FS_SEL) used while testing.
    fs_sel: u8,
    /// LSB per data-sheet unit (g/1000 or °/s) at that full scale.
    lsb_per_unit: f64,
    /// The bank and first register of the three factory self-test codes.
    factory_codes: (u8, u8),
}

impl Procedure {
    fn gyro() -> Self {
        let range = GyroRange::Dps250;
        Self {
            triad: Triad::Gyro,
            mode: reg::GYRO_MODE_LOW_NOISE,
            power_on_settle_ms: 60,
            self_test: reg::EN_G_ST,
            self_test_settle_ms: 200,
            output: reg::GYRO_DATA_X1,
            fs_sel: range.code(),
            lsb_per_unit: range.lsb_per_dps(),
            factory_codes: (1, reg::XG_ST_DATA_BANK1),
        }
    }

    fn accel() -> Self {
        let range = AccelRange::G4;
        Self {
            triad: Triad::Accel,
            mode: reg::ACCEL_MODE_LOW_NOISE,
            power_on_settle_ms: 25,
            self_test: reg::EN_A_ST | reg::ACCEL_ST_POWER,
            self_test_settle_ms: 25,
            output: reg::ACCEL_DATA_X1,
            fs_sel: config::accel_fs_sel(range),
            lsb_per_unit: config::accel_lsb_per_g(range) / 1000.0,
            factory_codes: (2, reg::XA_ST_DATA_BANK2),
        }
    }

    /// The limits of one axis whose factory code is `code`.
    fn limits(&self, code: u8) -> SelfTestLimits {
        let factory = factory_response_lsb(code, self.fs_sel).map(|lsb| lsb / self.lsb_per_unit);
        match (self.triad, factory) {
            (Triad::Gyro, Some(factory)) => {
                SelfTestLimits::factory_ratio(factory).with_max_offset(GYRO_MAX_OFFSET_DPS)
            }
            // The maker's driver sets no upper limit here.
            (Triad::Gyro, None) => SelfTestLimits::fixed(GYRO_MIN_ABSOLUTE_DPS, f64::INFINITY)
                .with_max_offset(GYRO_MAX_OFFSET_DPS),
            (Triad::Accel, Some(factory)) => SelfTestLimits::factory_ratio(factory),
            (Triad::Accel, None) => SelfTestLimits::fixed(ACCEL_ABSOLUTE_MG.0, ACCEL_ABSOLUTE_MG.1),
        }
    }

    /// The waits of one triad's two passes, ms.
    fn settle_ms(&self) -> u32 {
        2 * self.power_on_settle_ms + self.self_test_settle_ms
    }
}

fn sampling() -> Sampling {
    Sampling::at_period(0, AVERAGED, u64::from(ODR.period_ns()))
}

/// The factory self-test response a code encodes, in LSB at full-scale field
/// `fs_sel` (TDK's equation: 2620 / 2^(3 − FS_SEL) × 1.01^(code − 1),
/// rounded to a whole LSB); `None` for code 0, "no factory value".
fn factory_response_lsb(code: u8, fs_sel: u8) -> Option<f64> {
    if code == 0 {
        return None;
    }
    let at_fs_sel_3 = 2620.0 * libm::pow(1.01, f64::from(code - 1));
    let scaled = libm::ldexp(at_fs_sel_3, i32::from(fs_sel) - 3);
    Some(libm::floor(scaled + 0.5))
}

/// PWR_MGMT0..=ACCEL_CONFIG1 and SELF_TEST_CONFIG, as the procedure found them.
pub struct Saved {
    configuration: [u8; SAVED_REGISTERS],
    self_test_config: u8,
}

/// TDK InvenSense's self-test procedure on the gyroscope, then the
/// accelerometer: each axis's response against the factory response stored
/// in the chip (0.5 < ratio < 1.5; see the module source for the limits
/// without one).
///
/// The chip must be still. It takes about 1.4 s: gyroscope 60 ms + 200
/// samples off, 60 ms + 200 ms + 200 samples on; accelerometer 25 ms +
/// 200 samples off, 25 + 25 ms + 200 samples on (samples at 1 kHz); and
/// 200 ms for the gyroscope to settle after the write-back.
///
/// PWR_MGMT0, GYRO_CONFIG0, ACCEL_CONFIG0, GYRO_CONFIG1,
/// GYRO_ACCEL_CONFIG0, ACCEL_CONFIG1 and SELF_TEST_CONFIG are read first
/// and written back at the end (bank 0 selected), and the FIFO is flushed.
impl ChipSelfTest for Icm42688Chip {
    type Saved = Saved;

    /// The procedure's waits plus every sampling pass's time budget.
    /// Nominally it takes about 1.4 s.
    fn self_test_max_duration_ms() -> u32 {
        let waits: u32 = [Procedure::gyro(), Procedure::accel()]
            .iter()
            .map(Procedure::settle_ms)
            .sum::<u32>()
            + RESTORE_SETTLE_MS;
        let budgets_ns = 4 * sampling().budget_ns;
        // About two seconds: fits.
        let budgets_ms = u32::try_from(budgets_ns.div_ceil(1_000_000)).unwrap_or(u32::MAX);
        waits.saturating_add(budgets_ms)
    }

    fn save<I: RegisterInterface>(driver: &mut Icm42688<I>) -> Result<Saved, Error<I::BusError>> {
        let mut configuration = [0u8; SAVED_REGISTERS];
        driver.read_registers(reg::PWR_MGMT0, &mut configuration)?;
        let self_test_config = driver.read_register(reg::SELF_TEST_CONFIG)?;
        Ok(Saved {
            configuration,
            self_test_config,
        })
    }

    fn run<I: RegisterInterface>(
        driver: &mut Icm42688<I>,
        delay: &mut impl DelayNs,
        saved: &Saved,
    ) -> Result<SelfTestReport, Error<I::BusError>> {
        driver.run_self_test(delay, &saved.configuration)
    }

    fn restore<I: RegisterInterface>(
        driver: &mut Icm42688<I>,
        delay: &mut impl DelayNs,
        saved: &Saved,
    ) -> Result<(), Error<I::BusError>> {
        driver.restore_after_self_test(delay, &saved.configuration, saved.self_test_config)
    }
}

impl<I: RegisterInterface> Icm42688<I> {
    fn run_self_test(
        &mut self,
        delay: &mut impl DelayNs,
        saved: &[u8; SAVED_REGISTERS],
    ) -> Result<SelfTestReport, Error<I::BusError>> {
        let [power, _, _, gyro_config1, filter_bandwidths, accel_config1] = *saved;
        let gyro = Procedure::gyro();
        self.write(
            reg::GYRO_CONFIG1,
            (gyro_config1 & !reg::GYRO_UI_FILT_ORD_MASK) | reg::GYRO_UI_FILT_ORD_3RD,
        )?;
        let gyro_bandwidth =
            (filter_bandwidths & !reg::GYRO_UI_FILT_BW_MASK) | reg::GYRO_UI_FILT_BW_ODR_10;
        self.write(reg::GYRO_ACCEL_CONFIG0, gyro_bandwidth)?;
        self.write(
            reg::GYRO_CONFIG0,
            (gyro.fs_sel << reg::FS_SEL_SHIFT) | ODR.code(),
        )?;
        let gyro = self.self_test_triad(delay, &gyro, power)?;

        let accel = Procedure::accel();
        self.write(
            reg::GYRO_ACCEL_CONFIG0,
            (gyro_bandwidth & !reg::ACCEL_UI_FILT_BW_MASK) | reg::ACCEL_UI_FILT_BW_ODR_10,
        )?;
        self.write(
            reg::ACCEL_CONFIG1,
            (accel_config1 & !reg::ACCEL_UI_FILT_ORD_MASK) | reg::ACCEL_UI_FILT_ORD_3RD,
        )?;
        self.write(
            reg::ACCEL_CONFIG0,
            (accel.fs_sel << reg::FS_SEL_SHIFT) | ODR.code(),
        )?;
        let accel = self.self_test_triad(delay, &accel, power)?;
        Ok(SelfTestReport { accel, gyro })
    }

    /// Both passes of one triad, its factory codes, and the verdict. `power`
    /// is PWR_MGMT0 as saved (its temperature and idle bits are kept).
    fn self_test_triad(
        &mut self,
        delay: &mut impl DelayNs,
        procedure: &Procedure,
        power: u8,
    ) -> Result<TriadSelfTest, Error<I::BusError>> {
        let off = self.mean_output(delay, procedure, power, 0)?;
        let on = self.mean_output(delay, procedure, power, procedure.self_test)?;
        let (bank, first) = procedure.factory_codes;
        let mut codes = [0u8; 3];
        self.write(reg::REG_BANK_SEL, bank)?;
        self.interface
            .read_registers(first, &mut codes)
            .map_err(Error::Bus)?;
        self.write(reg::REG_BANK_SEL, 0)?;
        let unit = |counts: [f64; 3]| counts.map(|c| c / procedure.lsb_per_unit);
        Ok(TriadSelfTest::judge(
            procedure.triad,
            unit(off),
            unit(on),
            codes.map(|code| procedure.limits(code)),
        ))
    }

    /// One pass: the triad on, its self-test set to `self_test`, the mean of
    /// 200 valid samples (counts; -32768 marks an invalid one, skipped), then
    /// both triads and the self-test off.
    fn mean_output(
        &mut self,
        delay: &mut impl DelayNs,
        procedure: &Procedure,
        power: u8,
        self_test: u8,
    ) -> Result<[f64; 3], Error<I::BusError>> {
        let sensors_off = power & !reg::SENSOR_MODES_MASK;
        self.write(reg::PWR_MGMT0, sensors_off | procedure.mode)?;
        delay.delay_ms(procedure.power_on_settle_ms);
        if self_test != 0 {
            self.write(reg::SELF_TEST_CONFIG, self_test)?;
            delay.delay_ms(procedure.self_test_settle_ms);
        }
        let mean = sampling().mean(delay, || {
            let status = self.read_register(reg::INT_STATUS)?;
            if status & reg::DATA_RDY_INT == 0 {
                return Ok(Poll::NotReady { status });
            }
            let mut b = [0u8; 6];
            self.interface
                .read_registers(procedure.output, &mut b)
                .map_err(Error::Bus)?;
            let w = |i: usize| i16::from_be_bytes([b[2 * i], b[2 * i + 1]]);
            let sample = [w(0), w(1), w(2)];
            if sample.contains(&reg::INVALID_SAMPLE) {
                return Ok(Poll::NotReady { status });
            }
            Ok(Poll::Sample(sample))
        })?;
        self.write(reg::PWR_MGMT0, sensors_off)?;
        if self_test != 0 {
            self.write(reg::SELF_TEST_CONFIG, 0)?;
        }
        Ok(mean)
    }

    /// Bank 0, SELF_TEST_CONFIG, the sensor configuration, then PWR_MGMT0
    /// (the sensors back on); waits for the gyroscope to settle and flushes
    /// the FIFO.
    fn restore_after_self_test(
        &mut self,
        delay: &mut impl DelayNs,
        saved: &[u8; SAVED_REGISTERS],
        self_test_config: u8,
    ) -> Result<(), Error<I::BusError>> {
        self.write(reg::REG_BANK_SEL, 0)?;
        self.write(reg::SELF_TEST_CONFIG, self_test_config)?;
        for (register, &value) in (reg::PWR_MGMT0..=reg::ACCEL_CONFIG1).zip(saved).skip(1) {
            self.write(register, value)?;
        }
        self.write(reg::PWR_MGMT0, saved[0])?;
        delay.delay_ms(RESTORE_SETTLE_MS);
        self.write(reg::SIGNAL_PATH_RESET, reg::FIFO_FLUSH)
    }
}
