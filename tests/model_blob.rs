//! The binary calibration blob: round trip and every error.

mod model_support;

use model_support::*;
use triad::model::blob::{self, BLOB_LEN, MAGIC, V2_LEN, VERSION};
use triad::model::{BlobError, Calibration};
use triad::protocol::crc32c::crc32c;

fn bits(cal: &Calibration) -> Vec<u64> {
    let mut out = vec![u64::from(cal.id)];
    for t in [&cal.accel, &cal.gyro] {
        out.extend(
            t.scale_misalignment
                .iter()
                .flatten()
                .chain(t.bias.iter())
                .map(|x| x.to_bits()),
        );
        match &t.temperature {
            Some(tt) => {
                out.push(1);
                out.push(tt.reference_c.to_bits());
                out.extend(
                    tt.bias_coefficients
                        .iter()
                        .chain(tt.scale_misalignment_per_c.iter())
                        .flatten()
                        .map(|x| x.to_bits()),
                );
            }
            None => out.push(0),
        }
    }
    match &cal.g_sensitivity {
        Some(g) => {
            out.push(1);
            out.extend(g.iter().flatten().map(|x| x.to_bits()));
        }
        None => out.push(0),
    }
    out
}

/// The version-2 blob of `cal` (which has no G): the version-3 layout up to
/// byte 508, then its CRC-32C, as version 2 wrote it.
fn version_2(cal: &Calibration) -> Vec<u8> {
    assert!(cal.g_sensitivity.is_none());
    let mut v = blob::encode(cal)[..V2_LEN - 4].to_vec();
    v[4] = 2;
    let crc = crc32c(&v);
    v.extend_from_slice(&crc.to_le_bytes());
    v
}

/// Rewrites the CRC so that only the field under test is wrong.
fn reseal(b: &mut [u8; BLOB_LEN]) {
    let crc = crc32c(&b[..BLOB_LEN - 4]);
    b[BLOB_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
}

#[test]
fn a_version_1_blob_closed_with_the_ethernet_crc_is_refused_by_its_version() {
    // Version 1 used CRC-32/ISO-HDLC; its blobs must say "re-pack", not "corrupt".
    let mut b = blob::encode(&Calibration::identity(7));
    b[4] = 1;
    reseal(&mut b);
    assert_eq!(
        blob::decode(&b),
        Err(BlobError::UnsupportedVersion { version: 1 })
    );
}

#[test]
fn round_trip_is_bit_exact_with_and_without_temperature_terms_and_g_sensitivity() {
    let mut rng = rng(0xB10B);
    for n in 0..200 {
        let scale = random_scale(&mut rng);
        let mut cal = random_calibration(&mut rng, &scale);
        if n % 2 == 0 {
            cal.accel.temperature =
                Some(random_temperature_terms(&mut rng, scale.accel.full_scale));
        }
        if n % 3 == 0 {
            cal.gyro.temperature = Some(random_temperature_terms(&mut rng, scale.gyro.full_scale));
        }
        if n == 7 {
            cal.gyro.bias[1] = f64::NAN; // the blob carries what it is given; validation is separate
        }
        let b = blob::encode(&cal);
        assert_eq!(&b[..4], &MAGIC);
        assert_eq!(b[4], VERSION);
        assert_eq!(bits(&blob::decode(&b).unwrap()), bits(&cal));
        assert_eq!(blob::upgrade(&b), Some(b));
    }
}

#[test]
fn a_version_2_blob_still_loads_as_g_zero_and_upgrades_to_the_same_calibration() {
    let mut rng = rng(0xB102);
    for n in 0..50 {
        let scale = random_scale(&mut rng);
        let mut cal = random_calibration(&mut rng, &scale);
        cal.g_sensitivity = None;
        if n % 2 == 0 {
            cal.gyro.temperature = Some(random_temperature_terms(&mut rng, scale.gyro.full_scale));
        }
        let old = version_2(&cal);
        assert_eq!(old.len(), 512);
        assert_eq!(bits(&blob::decode(&old).unwrap()), bits(&cal));
        assert_eq!(blob::upgrade(&old), Some(blob::encode(&cal)));
        // The identity a file without `id` gets is the one version 2 gave it.
        assert_eq!(blob::parameter_id(&cal), crc32c(&old[12..508]));
    }
    // Version 2 knows no G: its flag bit 2 is reserved, and its length is its own.
    let mut old = version_2(&Calibration::identity(3));
    old[5] = 4;
    let crc = crc32c(&old[..508]);
    old[508..].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(
        blob::decode(&old),
        Err(BlobError::ReservedBits {
            offset: 5,
            value: 4
        })
    );
    let mut long = version_2(&Calibration::identity(3));
    long.resize(BLOB_LEN, 0);
    assert_eq!(
        blob::decode(&long),
        Err(BlobError::WrongLength {
            len: BLOB_LEN,
            expected: V2_LEN
        })
    );
}

#[test]
fn every_framing_error_is_reported() {
    let good = blob::encode(&Calibration::identity(42));
    for len in [0, 1, BLOB_LEN - 1, BLOB_LEN + 1] {
        let mut v = good.to_vec();
        v.resize(len, 0);
        assert_eq!(
            blob::decode(&v),
            Err(BlobError::WrongLength {
                len,
                expected: BLOB_LEN
            })
        );
    }
    let mut b = good;
    b[0] = b'X';
    assert_eq!(
        blob::decode(&b),
        Err(BlobError::BadMagic { found: *b"XRCL" })
    );

    b = good;
    b[4] = 4;
    assert_eq!(
        blob::decode(&b),
        Err(BlobError::UnsupportedVersion { version: 4 })
    );

    b = good;
    b[100] ^= 0x10;
    let stored = u32::from_le_bytes(good[580..].try_into().unwrap());
    let computed = crc32c(&b[..580]);
    assert_ne!(stored, computed);
    let err = blob::decode(&b).unwrap_err();
    assert_eq!(err, BlobError::CrcMismatch { stored, computed });
    assert!(
        err.to_string().contains(&format!("{stored:#010x}"))
            && err.to_string().contains(&format!("{computed:#010x}"))
    );

    b = good;
    b[5] = 0x80;
    reseal(&mut b);
    assert_eq!(
        blob::decode(&b),
        Err(BlobError::ReservedBits {
            offset: 5,
            value: 0x80
        })
    );
    b = good;
    b[7] = 1;
    reseal(&mut b);
    assert_eq!(
        blob::decode(&b),
        Err(BlobError::ReservedBits {
            offset: 7,
            value: 1
        })
    );
}

#[test]
fn every_single_bit_flip_is_detected() {
    let good = blob::encode(&Calibration::identity(42));
    for byte in 0..BLOB_LEN {
        for bit in 0..8 {
            let mut b = good;
            b[byte] ^= 1 << bit;
            assert!(blob::decode(&b).is_err(), "flip at {byte}.{bit} undetected");
        }
    }
}

#[test]
fn parameter_id_depends_on_parameters_only() {
    let mut a = Calibration::identity(1);
    let mut b = Calibration::identity(2);
    assert_eq!(blob::parameter_id(&a), blob::parameter_id(&b));
    b.gyro.bias[0] = 1e-3;
    assert_ne!(blob::parameter_id(&a), blob::parameter_id(&b));
    a.gyro.bias[0] = 1e-3;
    assert_eq!(blob::parameter_id(&a), blob::parameter_id(&b));
    assert_eq!(blob::parameter_id(&a), crc32c(&blob::encode(&a)[12..508]));
    // G is a parameter: with one, its bytes 508..580 are in the identity too.
    b.g_sensitivity = Some([[1e-4, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
    assert_ne!(blob::parameter_id(&a), blob::parameter_id(&b));
    assert_eq!(blob::parameter_id(&b), crc32c(&blob::encode(&b)[12..580]));
}
