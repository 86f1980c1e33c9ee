//! The board's mounting orientation: the 24 right-angle rotations, named and
//! numbered as PX4's `enum Rotation` (src/lib/conversion/rotation.h), which
//! maps the sensor's axes onto the board's: v_board = R·v_sensor with
//! R = Rz(yaw)·Ry(pitch)·Rx(roll).
//!
//! PX4's non-right-angle entries (the 45° yaws, PITCH_315, ...) are not
//! accepted, nor are its later duplicates of right-angle rotations
//! (26 PITCH_180_YAW_90 = 14, 27 PITCH_180_YAW_270 = 10, 41 = 31, 42 = 36,
//! 43 = 29): one rotation, one id. R has only 0 and ±1 entries, so applying it
//! is an exact permutation with signs; it is folded into K after (I+Σ)⁻¹, so
//! validation always sees the sensor's own near-identity (I+Σ).

use core::fmt;

macro_rules! orientations {
    ($( $variant:ident = $id:literal, $name:literal, $m:expr; )*) => {
        /// A right-angle mounting rotation; the discriminant is PX4's `Rotation` id.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[repr(u8)]
        #[allow(non_camel_case_types)]
        pub enum Orientation {
            /// The sensor's axes are the board's axes.
            #[default]
            RotationNone = 0,
            $(
                #[doc = concat!("PX4 `", $name, "` (id ", stringify!($id), ").")]
                $variant = $id,
            )*
        }

        impl Orientation {
            /// All 24 orientations, in id order.
            pub const ALL: [Orientation; 24] = [Orientation::RotationNone, $(Orientation::$variant,)*];

            /// PX4's numeric id.
            pub fn id(self) -> u8 {
                self as u8
            }

            /// PX4's name, e.g. `ROTATION_ROLL_180_YAW_90`.
            pub fn name(self) -> &'static str {
                match self {
                    Orientation::RotationNone => "ROTATION_NONE",
                    $(Orientation::$variant => $name,)*
                }
            }

            /// R with v_board = R·v_sensor.
            pub fn matrix(self) -> [[i8; 3]; 3] {
                match self {
                    Orientation::RotationNone => [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                    $(Orientation::$variant => $m,)*
                }
            }
        }
    };
}

orientations! {
    Yaw90 = 2, "ROTATION_YAW_90", [[0, -1, 0], [1, 0, 0], [0, 0, 1]];
    Yaw180 = 4, "ROTATION_YAW_180", [[-1, 0, 0], [0, -1, 0], [0, 0, 1]];
    Yaw270 = 6, "ROTATION_YAW_270", [[0, 1, 0], [-1, 0, 0], [0, 0, 1]];
    Roll180 = 8, "ROTATION_ROLL_180", [[1, 0, 0], [0, -1, 0], [0, 0, -1]];
    Roll180Yaw90 = 10, "ROTATION_ROLL_180_YAW_90", [[0, 1, 0], [1, 0, 0], [0, 0, -1]];
    Pitch180 = 12, "ROTATION_PITCH_180", [[-1, 0, 0], [0, 1, 0], [0, 0, -1]];
    Roll180Yaw270 = 14, "ROTATION_ROLL_180_YAW_270", [[0, -1, 0], [-1, 0, 0], [0, 0, -1]];
    Roll90 = 16, "ROTATION_ROLL_90", [[1, 0, 0], [0, 0, -1], [0, 1, 0]];
    Roll90Yaw90 = 18, "ROTATION_ROLL_90_YAW_90", [[0, 0, 1], [1, 0, 0], [0, 1, 0]];
    Roll270 = 20, "ROTATION_ROLL_270", [[1, 0, 0], [0, 0, 1], [0, -1, 0]];
    Roll270Yaw90 = 22, "ROTATION_ROLL_270_YAW_90", [[0, 0, -1], [1, 0, 0], [0, -1, 0]];
    Pitch90 = 24, "ROTATION_PITCH_90", [[0, 0, 1], [0, 1, 0], [-1, 0, 0]];
    Pitch270 = 25, "ROTATION_PITCH_270", [[0, 0, -1], [0, 1, 0], [1, 0, 0]];
    Roll90Pitch90 = 28, "ROTATION_ROLL_90_PITCH_90", [[0, 1, 0], [0, 0, -1], [-1, 0, 0]];
    Roll180Pitch90 = 29, "ROTATION_ROLL_180_PITCH_90", [[0, 0, -1], [0, -1, 0], [-1, 0, 0]];
    Roll270Pitch90 = 30, "ROTATION_ROLL_270_PITCH_90", [[0, -1, 0], [0, 0, 1], [-1, 0, 0]];
    Roll90Pitch180 = 31, "ROTATION_ROLL_90_PITCH_180", [[-1, 0, 0], [0, 0, -1], [0, -1, 0]];
    Roll270Pitch180 = 32, "ROTATION_ROLL_270_PITCH_180", [[-1, 0, 0], [0, 0, 1], [0, 1, 0]];
    Roll90Pitch270 = 33, "ROTATION_ROLL_90_PITCH_270", [[0, -1, 0], [0, 0, -1], [1, 0, 0]];
    Roll180Pitch270 = 34, "ROTATION_ROLL_180_PITCH_270", [[0, 0, 1], [0, -1, 0], [1, 0, 0]];
    Roll270Pitch270 = 35, "ROTATION_ROLL_270_PITCH_270", [[0, 1, 0], [0, 0, 1], [1, 0, 0]];
    Roll90Pitch180Yaw90 = 36, "ROTATION_ROLL_90_PITCH_180_YAW_90", [[0, 0, 1], [-1, 0, 0], [0, -1, 0]];
    Roll90Yaw270 = 37, "ROTATION_ROLL_90_YAW_270", [[0, 0, -1], [-1, 0, 0], [0, 1, 0]];
}

/// A rotation id or name that is not one of the 24 right-angle orientations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UnsupportedOrientation(pub u8);

impl fmt::Display for UnsupportedOrientation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "rotation id {} is not one of the 24 right-angle orientations \
             (PX4 Rotation ids 0, 2, 4, ..., 22, 24, 25, 28 to 37)",
            self.0
        )
    }
}

impl Orientation {
    /// The orientation with PX4 id `id`.
    pub fn from_id(id: u8) -> Result<Orientation, UnsupportedOrientation> {
        Orientation::ALL
            .iter()
            .copied()
            .find(|o| o.id() == id)
            .ok_or(UnsupportedOrientation(id))
    }

    /// The orientation with PX4 name `name` (e.g. `ROTATION_YAW_90`; the
    /// `ROTATION_` prefix may be left out; ASCII case is ignored).
    pub fn from_name(name: &str) -> Option<Orientation> {
        let short = |s: &'static str| s.strip_prefix("ROTATION_").unwrap_or(s);
        let wanted = name.trim();
        let wanted = match (wanted.get(..9), wanted.get(9..)) {
            (Some(prefix), Some(rest)) if prefix.eq_ignore_ascii_case("ROTATION_") => rest,
            _ => wanted,
        };
        Orientation::ALL
            .iter()
            .copied()
            .find(|o| short(o.name()).eq_ignore_ascii_case(wanted))
    }

    /// R·v, exact (a permutation with signs).
    pub fn rotate(self, v: [f64; 3]) -> [f64; 3] {
        let r = self.matrix();
        let mut out = [0.0; 3];
        for (o, row) in out.iter_mut().zip(r.iter()) {
            for (&rij, &vj) in row.iter().zip(v.iter()) {
                // Exactly one non-zero per row: adding zeros and ±v is exact.
                if rij != 0 {
                    *o = f64::from(rij) * vj;
                }
            }
        }
        out
    }
}

impl fmt::Display for Orientation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.name(), self.id())
    }
}
