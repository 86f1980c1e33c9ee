//! What a chip model's built-in self-test adds to its output: per axis, the
//! change of specific force or angular rate while the excitation is on, and
//! which axes a [`Fault::DeadSelfTest`](crate::chips::fault::Fault::DeadSelfTest) broke.

use triad::model::Triad;
use triad::sensor::self_test::si_per_data_sheet_unit;
use triad::sensor::Axis;

/// The self-test excitation of one unit, in SI units (m/s², rad/s), for the
/// positive self-test; the negative one is its opposite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelfTestResponse {
    /// Accelerometer x, y, z, m/s².
    pub accel: [f64; 3],
    /// Gyroscope x, y, z, rad/s.
    pub gyro: [f64; 3],
}

impl SelfTestResponse {
    /// A response given in the data sheets' units: mg and °/s.
    pub fn from_data_sheet_units(accel_mg: [f64; 3], gyro_dps: [f64; 3]) -> Self {
        Self {
            accel: accel_mg.map(|v| v * si_per_data_sheet_unit(Triad::Accel)),
            gyro: gyro_dps.map(|v| v * si_per_data_sheet_unit(Triad::Gyro)),
        }
    }

    /// One axis's response, SI.
    pub fn get(&self, triad: Triad, axis: Axis) -> f64 {
        match triad {
            Triad::Accel => self.accel[axis.index()],
            Triad::Gyro => self.gyro[axis.index()],
        }
    }

    /// Every axis's response times `factor`.
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            accel: self.accel.map(|v| v * factor),
            gyro: self.gyro.map(|v| v * factor),
        }
    }
}

/// Which axes' self-test excitation is broken ([`crate::chips::fault::Fault::DeadSelfTest`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeadAxes {
    accel: [bool; 3],
    gyro: [bool; 3],
}

impl DeadAxes {
    /// Breaks `triad`'s `axis`.
    pub fn kill(&mut self, triad: Triad, axis: Axis) {
        match triad {
            Triad::Accel => self.accel[axis.index()] = true,
            Triad::Gyro => self.gyro[axis.index()] = true,
        }
    }

    /// What the excitation adds to the truth: each axis's response times
    /// its sign (+1 positive self-test, −1 negative, 0 off), 0 on a dead axis.
    pub fn excitation(
        &self,
        response: &SelfTestResponse,
        accel_sign: [i8; 3],
        gyro_sign: [i8; 3],
    ) -> SelfTestResponse {
        let axis = |dead: bool, sign: i8, value: f64| {
            if dead {
                0.0
            } else {
                f64::from(sign) * value
            }
        };
        SelfTestResponse {
            accel: [0, 1, 2].map(|i| axis(self.accel[i], accel_sign[i], response.accel[i])),
            gyro: [0, 1, 2].map(|i| axis(self.gyro[i], gyro_sign[i], response.gyro[i])),
        }
    }
}
