//! The ICM-42688-P's factory self-test trim: per axis a code (user bank 1
//! XG/YG/ZG_ST_DATA, bank 2 XA/YA/ZA_ST_DATA) that encodes the self-test
//! response measured at the factory, and the response it encodes (the
//! model's own copy of TDK InvenSense's equation, so a wrong copy in the
//! driver is caught: 2620 LSB × 1.01^(code − 1) at FS_SEL 3, i.e. ±250 °/s at
//! 32768/250 LSB per °/s and ±2 g at 16384 LSB/g).

use crate::chips::self_test_response::SelfTestResponse;

/// The factory codes of one unit; 0 means "no factory value".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FactoryTrim {
    /// Accelerometer x, y, z (bank 2, 0x3B..=0x3D).
    pub accel: [u8; 3],
    /// Gyroscope x, y, z (bank 1, 0x5F..=0x61).
    pub gyro: [u8; 3],
}

impl FactoryTrim {
    /// A plausible unit: accelerometer about 0.50–0.53 g, gyroscope about
    /// 88–94 °/s (codes 116..=122 and 150..=156).
    pub const TYPICAL: FactoryTrim = FactoryTrim {
        accel: [116, 119, 122],
        gyro: [150, 153, 156],
    };

    /// The response the codes encode, SI; an axis with code 0 gets 0.
    pub fn response(&self) -> SelfTestResponse {
        let g = |code: u8| at_fs_sel_3(code) / 16384.0 * 1000.0;
        let dps = |code: u8| at_fs_sel_3(code) / (32768.0 / 250.0);
        SelfTestResponse::from_data_sheet_units(self.accel.map(g), self.gyro.map(dps))
    }
}

/// The factory response of `code` in LSB at FS_SEL 3, unrounded; 0 for code 0.
fn at_fs_sel_3(code: u8) -> f64 {
    if code == 0 {
        return 0.0;
    }
    2620.0 * libm::pow(1.01, f64::from(code) - 1.0)
}
