//! The scene blob the emulated board embeds: round trips, and every way a
//! blob can be wrong is refused with what was found.

use triad_sim::motion::{Axis, Motion};
use triad_sim::scenes::scene::{GaussMarkovParams, Scene, TriadEffects};
use triad_sim::scenes::scene_blob::{decode, encode, SceneBlobError, MAX_BLOB_LEN, VERSION};
use triad_sim::scenes::simulator::Simulator;
use triad_sim::scenes::temperature_profile::TemperatureProfile;

fn busy_scene() -> Scene {
    let mut scene = Scene::new(
        1000.0,
        Motion::RateTable {
            axis: Axis::PlusZ,
            rate: 0.5,
        },
    );
    scene.temperature = TemperatureProfile::Ramp {
        from: -10.0,
        to: 60.0,
        start: 1.0,
        duration: 100.0,
    };
    scene.accel = TriadEffects {
        white_noise: Some([1e-3, 2e-3, 3e-3]),
        constant_bias: Some([0.1, -0.2, 0.3]),
        scale_misalignment: Some([[1e-3, 2e-4, 0.0], [0.0, -2e-3, 1e-4], [3e-4, 0.0, 5e-4]]),
        output_lsb: Some([4.8e-3; 3]),
        saturation: Some([156.9; 3]),
        ..TriadEffects::NONE
    };
    scene.gyro = TriadEffects {
        gauss_markov: Some(GaussMarkovParams {
            sigma: [1e-4; 3],
            correlation_time: [100.0, 200.0, 300.0],
        }),
        random_walk: Some([1e-6; 3]),
        increment_quantisation: Some([1e-5; 3]),
        ..TriadEffects::NONE
    };
    scene
}

fn blob(scene: &Scene, seed: u64) -> Vec<u8> {
    let mut out = [0u8; MAX_BLOB_LEN];
    let n = encode(scene, seed, &mut out).unwrap();
    out[..n].to_vec()
}

#[test]
fn a_scene_and_its_seed_round_trip_and_simulate_identically() {
    let scene = busy_scene();
    let bytes = blob(&scene, 0xDEAD_BEEF_1234);
    let (back, seed) = decode(&bytes).unwrap();
    assert_eq!(back, scene);
    assert_eq!(seed, 0xDEAD_BEEF_1234);
    let mut a = Simulator::new(&scene, seed).unwrap();
    let mut b = Simulator::new(&back, seed).unwrap();
    for _ in 0..1000 {
        assert_eq!(a.step().measured, b.step().measured);
    }
}

#[test]
fn damaged_foreign_and_truncated_blobs_are_refused_with_what_was_found() {
    let good = blob(&busy_scene(), 7);
    assert_eq!(
        decode(&good[..10]),
        Err(SceneBlobError::TooShort { len: 10 })
    );

    let mut foreign = good.clone();
    foreign[..4].copy_from_slice(b"TCAL");
    assert_eq!(
        decode(&foreign),
        Err(SceneBlobError::Magic { found: *b"TCAL" })
    );

    let mut newer = good.clone();
    newer[4] = VERSION + 1;
    assert_eq!(
        decode(&newer),
        Err(SceneBlobError::Version { found: VERSION + 1 })
    );

    let cut = &good[..good.len() - 5];
    assert!(
        matches!(decode(cut), Err(SceneBlobError::Length { available, .. }) if available == cut.len())
    );

    // Every single-bit flip in the payload or seed is caught by the CRC.
    for byte in 5..good.len() - 4 {
        let mut damaged = good.clone();
        damaged[byte] ^= 0x10;
        match decode(&damaged) {
            Err(SceneBlobError::Crc { .. }) | Err(SceneBlobError::Length { .. }) => {}
            other => panic!("flip in byte {byte}: {other:?}"),
        }
    }
}

#[test]
fn a_payload_that_is_not_a_scene_is_refused_even_with_a_good_crc() {
    // A well-formed blob around 3 bytes of garbage.
    let mut bytes = b"TSCN".to_vec();
    bytes.push(VERSION);
    bytes.extend(1u64.to_le_bytes());
    bytes.extend(3u16.to_le_bytes());
    bytes.extend([0xFF, 0xFF, 0xFF]);
    let crc = triad::protocol::crc32c(&bytes);
    bytes.extend(crc.to_le_bytes());
    assert_eq!(decode(&bytes), Err(SceneBlobError::Payload));
}

#[test]
fn a_buffer_too_small_is_an_error_not_a_panic() {
    let mut out = [0u8; 30];
    assert_eq!(
        encode(&busy_scene(), 1, &mut out),
        Err(SceneBlobError::BufferTooSmall { available: 30 })
    );
}
