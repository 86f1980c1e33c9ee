//! ICM-42688-P configuration as typed values: full-scale ranges (the
//! accelerometer's the shared [`AccelRange`], with this chip's codes and
//! sensitivities), output data rates, interrupt pin, FIFO. Codes and
//! sensitivities from DS-000347 §3.1 (Tables 1 and 2, sensitivity scale
//! factors) and §14 (GYRO_CONFIG0, ACCEL_CONFIG0).

pub use crate::sensor::accel_range::AccelRange;
use crate::sensor::chip::{DataRate, FullScale};
pub use crate::sensor::fifo::{FifoConfig, FifoMode};
pub use crate::sensor::interrupt::InterruptPin;
use crate::sensor::{CodeRange, ImuScale, TriadScale};
use crate::units::{deg_to_rad, STANDARD_GRAVITY};

/// The ACCEL_FS_SEL field value of `range` (bits 7:5 of ACCEL_CONFIG0;
/// ±16 g, the reset value, is 0 and each step halves the range).
pub fn accel_fs_sel(range: AccelRange) -> u8 {
    match range {
        AccelRange::G16 => 0,
        AccelRange::G8 => 1,
        AccelRange::G4 => 2,
        AccelRange::G2 => 3,
    }
}

/// §3.2 Table 2: sensitivity in LSB/g (±2 g: 16384, ±4 g: 8192, ±8 g:
/// 4096, ±16 g: 2048).
pub fn accel_lsb_per_g(range: AccelRange) -> f64 {
    match range {
        AccelRange::G2 => 16384.0,
        AccelRange::G4 => 8192.0,
        AccelRange::G8 => 4096.0,
        AccelRange::G16 => 2048.0,
    }
}

/// Gyroscope full-scale range (GYRO_CONFIG0 GYRO_FS_SEL).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GyroRange {
    /// ±15.625 °/s, 2097.2 LSB/(°/s).
    Dps15_625,
    /// ±31.25 °/s, 1048.6 LSB/(°/s).
    Dps31_25,
    /// ±62.5 °/s, 524.3 LSB/(°/s).
    Dps62_5,
    /// ±125 °/s, 262 LSB/(°/s).
    Dps125,
    /// ±250 °/s, 131 LSB/(°/s).
    Dps250,
    /// ±500 °/s, 65.5 LSB/(°/s).
    Dps500,
    /// ±1000 °/s, 32.8 LSB/(°/s).
    Dps1000,
    /// ±2000 °/s, 16.4 LSB/(°/s) (reset value).
    Dps2000,
}

impl GyroRange {
    /// All ranges, narrowest first.
    pub const ALL: [GyroRange; 8] = [
        Self::Dps15_625,
        Self::Dps31_25,
        Self::Dps62_5,
        Self::Dps125,
        Self::Dps250,
        Self::Dps500,
        Self::Dps1000,
        Self::Dps2000,
    ];

    /// The GYRO_FS_SEL field value: 0 = ±2000 °/s, each step halves the range.
    pub fn code(self) -> u8 {
        match self {
            Self::Dps2000 => 0,
            Self::Dps1000 => 1,
            Self::Dps500 => 2,
            Self::Dps250 => 3,
            Self::Dps125 => 4,
            Self::Dps62_5 => 5,
            Self::Dps31_25 => 6,
            Self::Dps15_625 => 7,
        }
    }

    /// The range for a GYRO_FS_SEL field value (bits 7:5 of GYRO_CONFIG0).
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|r| r.code() == code)
    }

    /// The full scale in °/s.
    pub fn dps(self) -> f64 {
        match self {
            Self::Dps15_625 => 15.625,
            Self::Dps31_25 => 31.25,
            Self::Dps62_5 => 62.5,
            Self::Dps125 => 125.0,
            Self::Dps250 => 250.0,
            Self::Dps500 => 500.0,
            Self::Dps1000 => 1000.0,
            Self::Dps2000 => 2000.0,
        }
    }

    /// §3.1 Table 1: sensitivity in LSB/(°/s), as the datasheet states it
    /// (rounded: 16.4 rather than 32768/2000 = 16.384).
    pub fn lsb_per_dps(self) -> f64 {
        match self {
            Self::Dps15_625 => 2097.2,
            Self::Dps31_25 => 1048.6,
            Self::Dps62_5 => 524.3,
            Self::Dps125 => 262.0,
            Self::Dps250 => 131.0,
            Self::Dps500 => 65.5,
            Self::Dps1000 => 32.8,
            Self::Dps2000 => 16.4,
        }
    }
}

impl FullScale for GyroRange {
    /// Counts → rad/s and the range in rad/s.
    fn scale(self) -> TriadScale {
        TriadScale {
            si_per_lsb: deg_to_rad(1.0 / self.lsb_per_dps()),
            full_scale: deg_to_rad(self.dps()),
            codes: CodeRange::I16,
        }
    }
}

/// Output data rate of both sensors in low-noise mode (GYRO_ODR / ACCEL_ODR).
/// The accel-only low-power rates (6.25 Hz and below) are left out: the driver
/// runs both sensors in low-noise mode at one rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Odr {
    /// 32 kHz.
    Hz32000,
    /// 16 kHz.
    Hz16000,
    /// 8 kHz.
    Hz8000,
    /// 4 kHz.
    Hz4000,
    /// 2 kHz.
    Hz2000,
    /// 1 kHz (reset value).
    Hz1000,
    /// 500 Hz.
    Hz500,
    /// 200 Hz.
    Hz200,
    /// 100 Hz.
    Hz100,
    /// 50 Hz.
    Hz50,
    /// 25 Hz.
    Hz25,
    /// 12.5 Hz.
    Hz12_5,
}

impl Odr {
    /// All rates, fastest first.
    pub const ALL: [Odr; 12] = [
        Self::Hz32000,
        Self::Hz16000,
        Self::Hz8000,
        Self::Hz4000,
        Self::Hz2000,
        Self::Hz1000,
        Self::Hz500,
        Self::Hz200,
        Self::Hz100,
        Self::Hz50,
        Self::Hz25,
        Self::Hz12_5,
    ];

    /// The sample period in nanoseconds (exact for every rate).
    pub fn period_ns(self) -> u32 {
        match self {
            Self::Hz32000 => 31_250,
            Self::Hz16000 => 62_500,
            Self::Hz8000 => 125_000,
            Self::Hz4000 => 250_000,
            Self::Hz2000 => 500_000,
            Self::Hz1000 => 1_000_000,
            Self::Hz500 => 2_000_000,
            Self::Hz200 => 5_000_000,
            Self::Hz100 => 10_000_000,
            Self::Hz50 => 20_000_000,
            Self::Hz25 => 40_000_000,
            Self::Hz12_5 => 80_000_000,
        }
    }
}

impl DataRate for Odr {
    const ALL: &'static [Odr] = &Odr::ALL;

    /// The 4-bit ODR field value (note 500 Hz is 0b1111, out of sequence).
    fn code(self) -> u8 {
        match self {
            Self::Hz32000 => 0x1,
            Self::Hz16000 => 0x2,
            Self::Hz8000 => 0x3,
            Self::Hz4000 => 0x4,
            Self::Hz2000 => 0x5,
            Self::Hz1000 => 0x6,
            Self::Hz200 => 0x7,
            Self::Hz100 => 0x8,
            Self::Hz50 => 0x9,
            Self::Hz25 => 0xA,
            Self::Hz12_5 => 0xB,
            Self::Hz500 => 0xF,
        }
    }

    /// The rate in Hz.
    fn hz(self) -> f64 {
        1e9 / f64::from(self.period_ns())
    }
}

/// The samples of the high-resolution FIFO (§6.1 packet 4: 20-bit values,
/// 18 meaningful bits of accelerometer at ±16 g and 19 of gyroscope at
/// ±2000 °/s whatever the configured ranges), on the temperature register's
/// scale: what the driver delivers with [`FifoConfig::high_resolution`].
pub fn high_resolution_scale() -> ImuScale {
    use super::registers as reg;
    let codes = |limit: i32| CodeRange {
        low: -limit,
        high: limit,
        magnitude: reg::HIRES_MAGNITUDE,
    };
    ImuScale {
        accel: TriadScale {
            si_per_lsb: STANDARD_GRAVITY / reg::HIRES_ACCEL_LSB_PER_G,
            full_scale: AccelRange::G16.g() * STANDARD_GRAVITY,
            codes: codes(reg::HIRES_ACCEL_LIMIT),
        },
        gyro: TriadScale {
            si_per_lsb: deg_to_rad(1.0 / reg::HIRES_GYRO_LSB_PER_DPS),
            full_scale: deg_to_rad(GyroRange::Dps2000.dps()),
            codes: codes(reg::HIRES_GYRO_LIMIT),
        },
        temperature_per_lsb: 1.0 / reg::TEMP_LSB_PER_C,
        temperature_offset: reg::TEMP_OFFSET_C,
    }
}

/// The INT_CONFIG value for INT1 (§14 INT_CONFIG).
pub fn int_config(pin: InterruptPin) -> u8 {
    use super::registers::{INT1_DRIVE_PUSH_PULL, INT1_MODE_LATCHED, INT1_POLARITY_HIGH};
    let mut v = 0;
    if pin.active_high {
        v |= INT1_POLARITY_HIGH;
    }
    if pin.push_pull {
        v |= INT1_DRIVE_PUSH_PULL;
    }
    if pin.latched {
        v |= INT1_MODE_LATCHED;
    }
    v
}

/// A complete driver configuration of this chip (the shared
/// [`crate::sensor::config::Config`]; default: [`super::Icm42688Chip`]'s
/// `DEFAULT_CONFIG`).
pub type Config = crate::sensor::config::Config<super::Icm42688Chip>;
