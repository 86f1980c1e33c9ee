//! COBS ([`triad::protocol::cobs`]), both ways. The input is stuffed bytes
//! off the line (each 0x00 ends a frame, as on the wire), unstuffed byte by
//! byte as the decoders do: a frame that unstuffs whole is data, which must
//! stuff and unstuff back to itself. The input is also data to stuff:
//! every stuffer that takes it (the general one, the block one, the
//! in-place one the encoders use) gives the same bytes, with no 0x00, that
//! unstuff to the data.

use triad::protocol::cobs::{self, Unstuffer};

use crate::invariants::{stuffers_agree, stuffing_undoes, Broken};

/// Unstuffs `stuffed` (one frame, no delimiter); `None` when it is cut.
fn unstuff(stuffed: &[u8]) -> Option<Vec<u8>> {
    let mut unstuffer = Unstuffer::new();
    let data: Vec<u8> = stuffed.iter().filter_map(|&b| unstuffer.push(b)).collect();
    unstuffer.finish().ok().map(|()| data)
}

/// Stuffs `data` every way that takes it; checks them.
fn stuff_checked(data: &[u8]) -> Result<(), Broken> {
    let max = cobs::max_stuffed_len(data.len());
    let mut general = vec![0u8; max];
    let n = cobs::stuff(data, &mut general).map_err(|e| Broken(format!("stuff: {e:?}")))?;
    general.truncate(n);
    stuffing_undoes(data, &general, max, unstuff(&general).as_deref())?;
    if data.len() <= cobs::MAX_BLOCK {
        let mut block = vec![0u8; data.len() + 1];
        let m = cobs::stuff_block(data, &mut block)
            .map_err(|e| Broken(format!("stuff_block: {e:?}")))?;
        let mut in_place = Vec::with_capacity(data.len() + 2);
        in_place.push(0);
        in_place.extend_from_slice(data);
        in_place.push(0);
        let k = cobs::stuff_in_place(&mut in_place)
            .map_err(|e| Broken(format!("stuff_in_place: {e:?}")))?;
        // In place ends with the delimiter: the stuffed bytes are before it.
        stuffers_agree(data, &[&general, &block[..m], &in_place[..k - 1]])?;
    }
    Ok(())
}

/// The frames of `bytes` that unstuff whole.
pub fn cobs(bytes: &[u8]) -> Result<u64, Broken> {
    stuff_checked(bytes)?;
    let mut whole = 0;
    for frame in bytes.split(|&b| b == 0) {
        if let Some(data) = unstuff(frame) {
            whole += 1;
            stuff_checked(&data)?;
        }
    }
    Ok(whole)
}
