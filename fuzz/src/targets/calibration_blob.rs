//! The calibration blob ([`triad::model::blob`]: what an upload carries and
//! the flash keeps). The input is a blob. Invariants: a refusal says why;
//! what decodes re-encodes to bytes that decode and encode to the same.

use triad::model::blob;

use crate::invariants::{error_has_message, reencodes_to_itself, Broken};

/// Decodes `bytes` as a calibration blob; 1 when it decoded.
pub fn calibration_blob(bytes: &[u8]) -> Result<u64, Broken> {
    match blob::decode(bytes) {
        Ok(cal) => {
            let first = blob::encode(&cal);
            let again = blob::decode(&first)
                .map_err(|e| Broken(format!("a decoded blob re-encodes to one refused: {e}")))?;
            reencodes_to_itself("calibration blob", &first, &blob::encode(&again))?;
            Ok(1)
        }
        Err(e) => error_has_message(&e.to_string()).map(|()| 0),
    }
}
