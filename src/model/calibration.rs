//! What a lab measures: per triad the matrix (I+Σ) and the bias b, in SI
//! units, optionally with temperature terms and the gyroscope's
//! g-sensitivity G, plus the calibration identity.
//!
//! The measurement model (DESIGN.md): m̂ = (I+Σ)·m + b, so the correction is
//! m = (I+Σ)⁻¹·(m̂ − b). With G the gyroscope's is m̂_g = (I+Σ_g)·ω + b_g +
//! G·f, f the specific force (the corrected accelerometer sample), so
//! ω = (I+Σ_g)⁻¹·(m̂_g − b_g − G·f). Everything here is in the sensor's own
//! axes (the accelerometer's and the gyroscope's are the chip's one frame);
//! the board's mounting [`Orientation`](super::Orientation) is applied after.

/// Which triad: the accelerometer or the gyroscope. The one such enum of the
/// project (parameters, scenes, reports). The discriminants are part of every
/// simulation's random-stream keys (triad-sim's `Rng::for_stream`): never
/// renumber.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Triad {
    /// The accelerometer (m/s²).
    Accel = 0,
    /// The gyroscope (rad/s).
    Gyro = 1,
}

impl Triad {
    /// The name used in calibration files and messages: `accel` or `gyro`.
    pub fn name(self) -> &'static str {
        match self {
            Triad::Accel => "accel",
            Triad::Gyro => "gyro",
        }
    }
}

/// Temperature dependence of one triad's parameters around `reference_c`.
///
/// With ΔT = T − T_ref: bias_i(ΔT) = b_i + c1·ΔT + c2·ΔT² + c3·ΔT³ where
/// `[c1, c2, c3] = bias_coefficients[i]`, and (I+Σ)(ΔT) = (I+Σ) + ΔT·D where
/// `D = scale_misalignment_per_c`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemperatureTerms {
    /// T_ref in °C: the temperature at which `scale_misalignment` and `bias` hold.
    pub reference_c: f64,
    /// Per axis `[c1, c2, c3]`, in SI/°C, SI/°C², SI/°C³.
    pub bias_coefficients: [[f64; 3]; 3],
    /// d(I+Σ)/dT in 1/°C.
    pub scale_misalignment_per_c: [[f64; 3]; 3],
}

impl TemperatureTerms {
    /// The bias change at ΔT = `delta_c` (Horner form of the cubic, no constant term).
    pub fn bias_delta(&self, delta_c: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (o, c) in out.iter_mut().zip(self.bias_coefficients.iter()) {
            *o = delta_c * (c[0] + delta_c * (c[1] + delta_c * c[2]));
        }
        out
    }
}

/// One triad's calibration: m = (I+Σ)⁻¹·(m̂ − b).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriadCalibration {
    /// I + Σ: scale factors on the diagonal, misalignments / cross-axis terms off it.
    pub scale_misalignment: [[f64; 3]; 3],
    /// b in SI units (m/s² or rad/s), in the sensor's axes.
    pub bias: [f64; 3],
    /// Optional temperature terms.
    pub temperature: Option<TemperatureTerms>,
}

/// The 3×3 identity.
pub const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

impl TriadCalibration {
    /// I + Σ = I, b = 0, no temperature terms: the correction does nothing.
    pub const IDENTITY: TriadCalibration = TriadCalibration {
        scale_misalignment: IDENTITY,
        bias: [0.0; 3],
        temperature: None,
    };

    /// (I+Σ) and b evaluated at `temperature_c` (the plain values without temperature terms).
    pub fn at_temperature(&self, temperature_c: f64) -> ([[f64; 3]; 3], [f64; 3]) {
        let mut matrix = self.scale_misalignment;
        let mut bias = self.bias;
        if let Some(terms) = &self.temperature {
            let delta = temperature_c - terms.reference_c;
            for (row, d_row) in matrix.iter_mut().zip(terms.scale_misalignment_per_c.iter()) {
                for (m, d) in row.iter_mut().zip(d_row.iter()) {
                    *m += delta * d;
                }
            }
            for (b, db) in bias.iter_mut().zip(terms.bias_delta(delta)) {
                *b += db;
            }
        }
        (matrix, bias)
    }
}

/// A complete calibration: both triads and the identity the stream carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// The calibration identity, carried in every stream frame.
    pub id: u32,
    /// The accelerometer triad.
    pub accel: TriadCalibration,
    /// The gyroscope triad.
    pub gyro: TriadCalibration,
    /// The gyroscope's g-sensitivity G in (rad/s)/(m/s²), sensor axes: row i
    /// is the gyro axis, column j the specific-force axis. `None` is G = 0
    /// (and costs nothing per sample).
    pub g_sensitivity: Option<[[f64; 3]; 3]>,
}

impl Calibration {
    /// The identity calibration (I, zero bias, no temperature terms) with identity `id`.
    pub fn identity(id: u32) -> Calibration {
        Calibration {
            id,
            accel: TriadCalibration::IDENTITY,
            gyro: TriadCalibration::IDENTITY,
            g_sensitivity: None,
        }
    }

    /// The triad `which`.
    pub fn triad(&self, which: Triad) -> &TriadCalibration {
        match which {
            Triad::Accel => &self.accel,
            Triad::Gyro => &self.gyro,
        }
    }
}
