//! The host's stream decoder ([`triad::protocol::Decoder`], what `triad
//! decode` and `triad device` read a board's bytes with): the input is
//! bytes off the line, fed in two pieces (a read boundary anywhere).
//! Invariants: the byte accounting balances, every good packet and every
//! damaged one is counted once.

use triad::protocol::Decoder;

use crate::invariants::{
    byte_accounting_balances, errors_counted_once, good_packets_counted_once, Broken,
};

/// Decodes `bytes`; the good packets.
pub fn stream_decoder(bytes: &[u8]) -> Result<u64, Broken> {
    let mut decoder = Decoder::new();
    // Split where the first byte says: a packet cut by a read boundary is
    // the decoder's everyday case.
    let cut = bytes
        .first()
        .map_or(0, |&b| usize::from(b) % (bytes.len() + 1));
    let (mut good, mut damaged) = (0u64, 0u64);
    for piece in [&bytes[..cut], &bytes[cut..]] {
        for item in decoder.feed_packets(piece) {
            match item {
                Ok(_) => good += 1,
                Err(_) => damaged += 1,
            }
        }
    }
    let stats = decoder.stats();
    byte_accounting_balances(stats, bytes.len() as u64, decoder.pending_bytes())?;
    good_packets_counted_once(stats, good)?;
    errors_counted_once(stats, damaged)?;
    Ok(good)
}
