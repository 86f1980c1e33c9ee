//! Which calibration the device starts with, and what the stream says about
//! it. The RTIC application and the end-to-end test both call
//! [`start_calibration`], so the host knows exactly what the device chose.
//!
//! Precedence: the calibration built into the firmware if it decodes and is
//! valid for the chip's ranges, else the identity with every frame flagged
//! UNCALIBRATED. (The link issue adds a stored calibration above the built-in one.)

use crate::model::{blob, BlobError, Calibration, CalibrationError, Corrector, Orientation};
use crate::sensor::ImuScale;

/// Where the active calibration came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CalibrationSource {
    /// Built into the firmware image.
    BuiltIn,
    /// None: the identity, and the stream flags every frame UNCALIBRATED.
    None,
}

/// Why a calibration offered at start-up was not applied.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Rejection {
    /// The blob is not a calibration (length, version, CRC).
    Blob(BlobError),
    /// The calibration is not valid for this chip's ranges.
    Invalid(CalibrationError),
}

/// What the device starts with.
#[derive(Clone, Debug)]
pub struct StartUp {
    /// The corrector to run: the chosen calibration folded for the chip.
    pub corrector: Corrector,
    /// Where its calibration came from.
    pub source: CalibrationSource,
    /// The built-in calibration's rejection, when it was rejected.
    pub rejected: Option<Rejection>,
}

impl StartUp {
    /// True when frames carry a calibration (not the UNCALIBRATED identity).
    pub fn calibrated(&self) -> bool {
        self.source != CalibrationSource::None
    }
}

/// The chip's scale cannot carry even the identity: the driver reported a
/// non-positive or non-finite sensitivity or range. Nothing can be streamed.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InvalidScale(pub CalibrationError);

/// Chooses the start-up calibration: `built_in` (a blob from `triad calib
/// pack`; empty for none) when it decodes and is valid for `scale`, else the
/// identity, flagged uncalibrated.
pub fn start_calibration(
    built_in: &[u8],
    scale: &ImuScale,
    orientation: Orientation,
) -> Result<StartUp, InvalidScale> {
    let rejected = if built_in.is_empty() {
        None
    } else {
        match blob::decode(built_in) {
            Err(error) => Some(Rejection::Blob(error)),
            Ok(cal) => match Corrector::new(&cal, scale, orientation) {
                Ok(corrector) => {
                    return Ok(StartUp {
                        corrector,
                        source: CalibrationSource::BuiltIn,
                        rejected: None,
                    })
                }
                Err(error) => Some(Rejection::Invalid(error)),
            },
        }
    };
    let corrector =
        Corrector::new(&Calibration::identity(0), scale, orientation).map_err(InvalidScale)?;
    Ok(StartUp {
        corrector,
        source: CalibrationSource::None,
        rejected,
    })
}
