//! Wire budget of the stream: bytes per streamed sample and the highest frame
//! rate a UART sustains, from the encoder itself; plus the host decoder's
//! throughput (indicative: this machine, not the device).
//!
//! `cargo run -p triad-host --release --example wire_budget`

use std::hint::black_box;
use std::time::Instant;

use triad::protocol::{encode, max_frame_rate, Decoder, Flags, Frame, MAX_ENCODED_LEN};

/// 8N1: start bit, 8 data bits, stop bit.
const BITS_PER_BYTE: u32 = 10;

fn main() {
    wire_budget();
    decoder_throughput();
}

/// Bytes per frame and the frame rates the UART sustains.
fn wire_budget() {
    // Every frame encodes to the same length; measure it over frames with
    // many zero bytes (most stuffing work) and with none.
    let mut shortest = usize::MAX;
    let mut longest = 0;
    let mut out = [0u8; MAX_ENCODED_LEN];
    for i in 0..10_000u32 {
        let frame = if i % 2 == 0 {
            Frame {
                sequence: i,
                ..Frame::default()
            }
        } else {
            Frame {
                sequence: i | 0x0101_0101,
                timestamp_us: 0x0101_0101,
                flags: Flags::from_bits_retain(0x0101),
                overruns: 0x0101,
                dropped: 0x0101,
                calibration_id: 0x0101_0101,
                accel: [f32::from_bits(0x0101_0101); 3],
                gyro: [f32::from_bits(0x0101_0101); 3],
                temperature: f32::from_bits(0x0101_0101),
            }
        };
        let n = encode(&frame, &mut out);
        shortest = shortest.min(n);
        longest = longest.max(n);
    }
    println!("bytes on the wire per streamed sample: {longest} (shortest seen {shortest}; 51-byte frame + 1 COBS byte + 1 delimiter)");
    println!(
        "bit times per frame at 8N1: {}",
        longest as u32 * BITS_PER_BYTE
    );
    println!("{:>10}  {:>10}  {:>16}", "baud", "bytes/s", "max frames/s");
    for baud in [115_200u32, 921_600, 2_000_000] {
        let bytes_per_s = f64::from(baud) / f64::from(BITS_PER_BYTE);
        let exact = bytes_per_s / longest as f64;
        println!(
            "{baud:>10}  {bytes_per_s:>10.0}  {exact:>10.1} (floor {})",
            max_frame_rate(baud)
        );
    }
}

/// Host decoder throughput over a long clean stream.
fn decoder_throughput() {
    let mut out = [0u8; MAX_ENCODED_LEN];
    let frames = 200_000u32;
    let mut stream = Vec::with_capacity(frames as usize * MAX_ENCODED_LEN);
    for i in 0..frames {
        let frame = Frame {
            sequence: i,
            timestamp_us: i * 1000,
            accel: [0.1, -0.2, 9.8],
            gyro: [0.01, 0.0, -0.02],
            temperature: 25.0,
            ..Frame::default()
        };
        let n = encode(&frame, &mut out);
        stream.extend_from_slice(&out[..n]);
    }
    let start = Instant::now();
    let mut decoder = Decoder::new();
    let decoded = decoder
        .feed(black_box(&stream))
        .filter(|r| r.is_ok())
        .count();
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!(decoded as u32, frames);
    println!(
        "host decoder: {decoded} frames in {:.3} s = {:.0} ns/frame, {:.1} MB/s",
        seconds,
        seconds * 1e9 / f64::from(frames),
        stream.len() as f64 / seconds / 1e6
    );
}
