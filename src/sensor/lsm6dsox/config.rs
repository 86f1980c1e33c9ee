//! LSM6DSOX configuration as typed values (the accelerometer's range the
//! shared [`AccelRange`], with this chip's codes and sensitivities). Codes
//! from DS12814 §9 (CTRL1_XL, CTRL2_G); sensitivities from §4.1 Table 2
//! (mechanical characteristics).

pub use crate::sensor::accel_range::AccelRange;
use crate::sensor::chip::{DataRate, FullScale};
pub use crate::sensor::fifo::{FifoConfig, FifoMode};
pub use crate::sensor::interrupt::InterruptPin;
use crate::sensor::{CodeRange, TriadScale};
use crate::units::deg_to_rad;

/// The FS_XL field value of `range` (CTRL1_XL bits 3:2, with XL_FS_MODE =
/// 0; note ±16 g is 01, out of order; ±2 g, 00, is the reset value).
pub fn accel_fs_xl(range: AccelRange) -> u8 {
    match range {
        AccelRange::G2 => 0b00,
        AccelRange::G16 => 0b01,
        AccelRange::G4 => 0b10,
        AccelRange::G8 => 0b11,
    }
}

/// §4.1 Table 2: sensitivity in mg/LSB (±2 g: 0.061, ±4 g: 0.122, ±8 g:
/// 0.244, ±16 g: 0.488).
pub fn accel_mg_per_lsb(range: AccelRange) -> f64 {
    match range {
        AccelRange::G2 => 0.061,
        AccelRange::G4 => 0.122,
        AccelRange::G8 => 0.244,
        AccelRange::G16 => 0.488,
    }
}

/// Gyroscope full-scale range (CTRL2_G FS_G and FS_125).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GyroRange {
    /// ±125 °/s, 4.375 mdps/LSB.
    Dps125,
    /// ±250 °/s, 8.75 mdps/LSB (reset value).
    Dps250,
    /// ±500 °/s, 17.50 mdps/LSB.
    Dps500,
    /// ±1000 °/s, 35 mdps/LSB.
    Dps1000,
    /// ±2000 °/s, 70 mdps/LSB.
    Dps2000,
}

impl GyroRange {
    /// All ranges, narrowest first.
    pub const ALL: [GyroRange; 5] = [
        Self::Dps125,
        Self::Dps250,
        Self::Dps500,
        Self::Dps1000,
        Self::Dps2000,
    ];

    /// CTRL2_G bits 3:1 (FS_G and FS_125) for this range.
    pub fn bits(self) -> u8 {
        match self {
            Self::Dps125 => super::registers::FS_125,
            Self::Dps250 => 0b00 << 2,
            Self::Dps500 => 0b01 << 2,
            Self::Dps1000 => 0b10 << 2,
            Self::Dps2000 => 0b11 << 2,
        }
    }

    /// The range for CTRL2_G bits 3:1 (FS_125 set overrides FS_G).
    pub fn from_bits(ctrl2_g: u8) -> Self {
        if ctrl2_g & super::registers::FS_125 != 0 {
            return Self::Dps125;
        }
        match (ctrl2_g >> 2) & 0b11 {
            0b00 => Self::Dps250,
            0b01 => Self::Dps500,
            0b10 => Self::Dps1000,
            _ => Self::Dps2000,
        }
    }

    /// The full scale in °/s.
    pub fn dps(self) -> f64 {
        match self {
            Self::Dps125 => 125.0,
            Self::Dps250 => 250.0,
            Self::Dps500 => 500.0,
            Self::Dps1000 => 1000.0,
            Self::Dps2000 => 2000.0,
        }
    }

    /// §4.1 Table 2: sensitivity in mdps/LSB.
    pub fn mdps_per_lsb(self) -> f64 {
        match self {
            Self::Dps125 => 4.375,
            Self::Dps250 => 8.75,
            Self::Dps500 => 17.50,
            Self::Dps1000 => 35.0,
            Self::Dps2000 => 70.0,
        }
    }
}

impl FullScale for GyroRange {
    /// Counts → rad/s and the range in rad/s.
    fn scale(self) -> TriadScale {
        TriadScale {
            si_per_lsb: deg_to_rad(self.mdps_per_lsb() * 1e-3),
            full_scale: deg_to_rad(self.dps()),
            codes: CodeRange::I16,
        }
    }
}

/// Output data rate of both sensors in high-performance mode (ODR_XL, ODR_G;
/// the same codes set the FIFO batch rates BDR_XL, BDR_GY).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Odr {
    /// 12.5 Hz.
    Hz12_5,
    /// 26 Hz.
    Hz26,
    /// 52 Hz.
    Hz52,
    /// 104 Hz.
    Hz104,
    /// 208 Hz.
    Hz208,
    /// 416 Hz.
    Hz416,
    /// 833 Hz.
    Hz833,
    /// 1.66 kHz.
    Hz1666,
    /// 3.33 kHz.
    Hz3333,
    /// 6.66 kHz.
    Hz6667,
}

impl Odr {
    /// All rates, slowest first.
    pub const ALL: [Odr; 10] = [
        Self::Hz12_5,
        Self::Hz26,
        Self::Hz52,
        Self::Hz104,
        Self::Hz208,
        Self::Hz416,
        Self::Hz833,
        Self::Hz1666,
        Self::Hz3333,
        Self::Hz6667,
    ];

    /// The nominal rate in mHz, as the datasheet names it (12.5 Hz × 2ⁿ rounded:
    /// 26, 52, 104, ... 6667 Hz).
    pub fn millihertz(self) -> u32 {
        match self {
            Self::Hz12_5 => 12_500,
            Self::Hz26 => 26_000,
            Self::Hz52 => 52_000,
            Self::Hz104 => 104_000,
            Self::Hz208 => 208_000,
            Self::Hz416 => 416_000,
            Self::Hz833 => 833_000,
            Self::Hz1666 => 1_666_000,
            Self::Hz3333 => 3_333_000,
            Self::Hz6667 => 6_667_000,
        }
    }
}

impl DataRate for Odr {
    const ALL: &'static [Odr] = &Odr::ALL;

    /// The 4-bit ODR field value (0 is power-down).
    fn code(self) -> u8 {
        match self {
            Self::Hz12_5 => 0x1,
            Self::Hz26 => 0x2,
            Self::Hz52 => 0x3,
            Self::Hz104 => 0x4,
            Self::Hz208 => 0x5,
            Self::Hz416 => 0x6,
            Self::Hz833 => 0x7,
            Self::Hz1666 => 0x8,
            Self::Hz3333 => 0x9,
            Self::Hz6667 => 0xA,
        }
    }

    /// The nominal rate in Hz.
    fn hz(self) -> f64 {
        f64::from(self.millihertz()) / 1000.0
    }
}

/// The CTRL3_C value for `pin`: BDU and IF_INC on, pin polarity and drive.
pub fn ctrl3_c(pin: InterruptPin) -> u8 {
    use super::registers::{BDU, H_LACTIVE, IF_INC, PP_OD};
    let mut v = BDU | IF_INC;
    if !pin.active_high {
        v |= H_LACTIVE;
    }
    if !pin.push_pull {
        v |= PP_OD;
    }
    v
}

/// A complete driver configuration of this chip (the shared
/// [`crate::sensor::config::Config`]; default: [`super::Lsm6dsoxChip`]'s
/// `DEFAULT_CONFIG`).
pub type Config = crate::sensor::config::Config<super::Lsm6dsoxChip>;
