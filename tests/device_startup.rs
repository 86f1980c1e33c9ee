//! Which calibration the device starts with: a valid stored one, else a
//! valid built-in one, else the identity flagged UNCALIBRATED; a calibration
//! that fails (its blob or its values) is reported and never applied.

mod model_support;

use model_support::*;
use triad::device::startup::Rejection;
use triad::device::{start_calibration, CalibrationSource};
use triad::model::{blob, BlobError, Calibration, Orientation};

/// A valid calibration's blob, with its id.
fn valid(seed: u64, id: u32) -> [u8; blob::BLOB_LEN] {
    let mut rng = rng(seed);
    let mut cal = random_calibration(&mut rng, &widest_scale());
    cal.id = id;
    blob::encode(&cal)
}

/// A blob that decodes but whose accelerometer matrix is singular.
fn singular(id: u32) -> [u8; blob::BLOB_LEN] {
    let mut cal = Calibration::identity(id);
    cal.accel.scale_misalignment = [[0.0; 3]; 3];
    blob::encode(&cal)
}

/// A blob whose CRC fails.
fn corrupt(id: u32) -> [u8; blob::BLOB_LEN] {
    let mut bytes = valid(1, id);
    bytes[100] ^= 1;
    bytes
}

fn start(stored: Option<&[u8]>, built_in: &[u8]) -> triad::device::StartUp {
    start_calibration(stored, built_in, &widest_scale(), Orientation::RotationNone)
        .expect("the scale is valid")
}

#[test]
fn a_valid_stored_calibration_wins_over_the_built_in_one() {
    let s = start(Some(&valid(1, 0x5100)), &valid(2, 0xB100));
    assert_eq!(s.source, CalibrationSource::Stored);
    assert_eq!(s.corrector.calibration_id(), 0x5100);
    assert!(s.calibrated());
    assert_eq!((s.stored_rejected, s.rejected), (None, None));
}

#[test]
fn a_rejected_stored_calibration_is_reported_and_the_built_in_one_runs() {
    for (stored, reason) in [(corrupt(0x5100), "blob"), (singular(0x5100), "values")] {
        let s = start(Some(&stored), &valid(2, 0xB100));
        assert_eq!(s.source, CalibrationSource::BuiltIn, "{reason}");
        assert_eq!(s.corrector.calibration_id(), 0xB100, "{reason}");
        match (reason, s.stored_rejected) {
            ("blob", Some(Rejection::Blob(BlobError::CrcMismatch { .. }))) => {}
            ("values", Some(Rejection::Invalid(_))) => {}
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn with_nothing_valid_the_identity_runs_uncalibrated_with_both_reasons() {
    let s = start(Some(&singular(0x5100)), &corrupt(0xB100));
    assert_eq!(s.source, CalibrationSource::None);
    assert!(!s.calibrated());
    assert!(matches!(s.stored_rejected, Some(Rejection::Invalid(_))));
    assert!(matches!(s.rejected, Some(Rejection::Blob(_))));
    let none = start(None, &[]);
    assert_eq!(none.source, CalibrationSource::None);
    assert_eq!((none.stored_rejected, none.rejected), (None, None));
}
