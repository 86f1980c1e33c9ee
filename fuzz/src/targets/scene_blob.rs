//! The scene blob ([`triad_sim::scenes::scene_blob`]: what the emulated
//! board's firmware reads its scene from). The input is a blob. Invariants:
//! a refusal says why; what decodes re-encodes, with its seed, to bytes
//! that decode and encode to the same.

use triad_sim::scenes::scene_blob::{decode, encode, MAX_BLOB_LEN};

use crate::invariants::{error_has_message, reencodes_to_itself, Broken};

/// Decodes `bytes` as a scene blob; 1 when it decoded.
pub fn scene_blob(bytes: &[u8]) -> Result<u64, Broken> {
    let (scene, seed) = match decode(bytes) {
        Ok(decoded) => decoded,
        Err(e) => return error_has_message(&e.to_string()).map(|()| 0),
    };
    // Compared as bytes: a NaN parameter (refused later, by the simulator)
    // is not equal to itself.
    let (mut first, mut second) = ([0u8; MAX_BLOB_LEN], [0u8; MAX_BLOB_LEN]);
    let n = encode(&scene, seed, &mut first)
        .map_err(|e| Broken(format!("a decoded scene does not encode: {e}")))?;
    let (again, again_seed) = decode(&first[..n])
        .map_err(|e| Broken(format!("a decoded scene re-encodes to a blob refused: {e}")))?;
    let m = encode(&again, again_seed, &mut second)
        .map_err(|e| Broken(format!("a decoded scene does not encode twice: {e}")))?;
    if again_seed != seed {
        return Err(Broken(format!("seed {seed} re-encodes as {again_seed}")));
    }
    reencodes_to_itself("scene blob", &first[..n], &second[..m])?;
    Ok(1)
}
