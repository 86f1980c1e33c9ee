//! Which calibration the device starts with, and what the stream says about
//! it. The RTIC application and the end-to-end test both call
//! [`start_calibration`], so the host knows exactly what the device chose.
//!
//! Precedence: the calibration stored on the device ([`super::storage`]) if
//! it decodes and is valid for the chip's ranges, else the one built into the
//! firmware under the same test, else the identity with every frame flagged
//! UNCALIBRATED. A calibration that fails is reported, never applied.

use embedded_storage::nor_flash::NorFlash;

use super::commands::ActiveCalibration;
use super::storage::{CalibrationStore, Loaded};
use crate::model::blob::BLOB_LEN;
use crate::model::{blob, BlobError, Calibration, CalibrationError, Corrector, Orientation};
pub use crate::protocol::CalibrationSource;
use crate::protocol::{StoredReason, StoredState};
use crate::sensor::ImuScale;

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
    /// The stored calibration's rejection, when one was stored and rejected.
    pub stored_rejected: Option<Rejection>,
    /// The built-in calibration's rejection, when it was tried and rejected.
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

/// A blob's calibration folded for the chip, or why not.
fn corrector_of(
    bytes: &[u8],
    scale: &ImuScale,
    orientation: Orientation,
) -> Result<Corrector, Rejection> {
    let cal = blob::decode(bytes).map_err(Rejection::Blob)?;
    Corrector::new(&cal, scale, orientation).map_err(Rejection::Invalid)
}

/// Chooses the start-up calibration: `stored` (the blob the device keeps,
/// if any) when it decodes and is valid for `scale`, else `built_in` (a blob
/// from `triad calib pack`; empty for none) under the same test, else the
/// identity, flagged uncalibrated.
pub fn start_calibration(
    stored: Option<&[u8]>,
    built_in: &[u8],
    scale: &ImuScale,
    orientation: Orientation,
) -> Result<StartUp, InvalidScale> {
    let stored_rejected = match stored.map(|b| corrector_of(b, scale, orientation)) {
        Some(Ok(corrector)) => {
            return Ok(StartUp {
                corrector,
                source: CalibrationSource::Stored,
                stored_rejected: None,
                rejected: None,
            })
        }
        Some(Err(rejection)) => Some(rejection),
        None => None,
    };
    let rejected = if built_in.is_empty() {
        None
    } else {
        match corrector_of(built_in, scale, orientation) {
            Ok(corrector) => {
                return Ok(StartUp {
                    corrector,
                    source: CalibrationSource::BuiltIn,
                    stored_rejected,
                    rejected: None,
                })
            }
            Err(rejection) => Some(rejection),
        }
    };
    let corrector =
        Corrector::new(&Calibration::identity(0), scale, orientation).map_err(InvalidScale)?;
    Ok(StartUp {
        corrector,
        source: CalibrationSource::None,
        stored_rejected,
        rejected,
    })
}

/// What the device's store holds at start-up: the newest valid record's
/// blob (not yet validated for the chip: [`start_calibration`] does that),
/// and its state for `identify`. Slots that hold a cut save or foreign data
/// are ignored; when no valid record remains, the state is
/// [`StoredState::Rejected`].
pub fn load_stored<F: NorFlash>(
    store: &mut CalibrationStore<F>,
) -> (Option<[u8; BLOB_LEN]>, StoredState) {
    let mut blob = [0u8; BLOB_LEN];
    match store.load(&mut blob) {
        Ok(Loaded {
            record: Some(_), ..
        }) => (Some(blob), StoredState::Valid),
        Ok(Loaded {
            record: None,
            damaged_slots: 0,
        }) => (None, StoredState::Empty),
        Ok(Loaded { record: None, .. }) => (None, StoredState::Rejected),
        Err(_) => (None, StoredState::Failed),
    }
}

impl StartUp {
    /// The calibration in force, for the command handler: the blob chosen
    /// (`stored` or `built_in`, as [`StartUp::source`] says) and its id.
    pub fn active(&self, stored: Option<&[u8; BLOB_LEN]>, built_in: &[u8]) -> ActiveCalibration {
        let blob = match self.source {
            CalibrationSource::Stored => stored.copied(),
            CalibrationSource::BuiltIn => blob::upgrade(built_in),
            CalibrationSource::None | CalibrationSource::Uploaded => None,
        };
        ActiveCalibration {
            blob,
            id: self.corrector.calibration_id(),
            source: self.source,
        }
    }

    /// Why the flash's record was not applied, for `identify`: the store's
    /// state `loaded` ([`load_stored`]) and what this start-up made of it.
    pub fn stored_reason(&self, loaded: StoredState) -> StoredReason {
        match (loaded, self.stored_rejected) {
            (StoredState::Rejected, _) => StoredReason::RecordDamaged,
            (_, Some(Rejection::Blob(BlobError::UnsupportedVersion { .. }))) => {
                StoredReason::BlobVersion
            }
            (_, Some(Rejection::Blob(_))) => StoredReason::NotABlob,
            (_, Some(Rejection::Invalid(_))) => StoredReason::Invalid,
            (_, None) => StoredReason::None,
        }
    }

    /// What the store's state is once the stored blob has been tried:
    /// `loaded`, or [`StoredState::Rejected`] when it failed validation.
    pub fn stored_state(&self, loaded: StoredState) -> StoredState {
        match self.stored_rejected {
            Some(_) => StoredState::Rejected,
            None => loaded,
        }
    }
}
