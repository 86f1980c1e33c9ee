//! The 24 mounting orientations: proper rotations, distinct, a group, PX4's
//! ids and names, and an exact remap when folded into the correction.

mod model_support;

use model_support::*;
use triad::model::{Corrector, Orientation, Triad};

type M = [[i32; 3]; 3];

fn m(o: Orientation) -> M {
    o.matrix().map(|r| r.map(i32::from))
}

fn mul(a: &M, b: &M) -> M {
    let mut out = [[0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

fn det(a: &M) -> i32 {
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

#[test]
fn all_24_are_distinct_proper_rotations_forming_a_group() {
    let all = Orientation::ALL;
    for o in all {
        let r = m(o);
        let rt = [0, 1, 2].map(|i| [0, 1, 2].map(|j| r[j][i]));
        assert_eq!(
            mul(&r, &rt),
            [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
            "{o} not orthonormal"
        );
        assert_eq!(det(&r), 1, "{o} is a reflection");
    }
    for (i, a) in all.iter().enumerate() {
        for b in &all[i + 1..] {
            assert_ne!(m(*a), m(*b), "{a} = {b}");
        }
    }
    // Closed under composition: the 24 are the whole rotation group of the cube.
    for a in all {
        for b in all {
            let ab = mul(&m(a), &m(b));
            assert!(all.iter().any(|c| m(*c) == ab), "{a}·{b} not in the set");
        }
    }
}

#[test]
fn ids_and_names_follow_px4() {
    let ids: Vec<u8> = Orientation::ALL.iter().map(|o| o.id()).collect();
    assert_eq!(
        ids,
        [
            0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 25, 28, 29, 30, 31, 32, 33, 34, 35, 36,
            37
        ]
    );
    for o in Orientation::ALL {
        assert_eq!(Orientation::from_id(o.id()), Ok(o));
        assert_eq!(Orientation::from_name(o.name()), Some(o));
        assert_eq!(
            Orientation::from_name(&o.name()[9..].to_ascii_lowercase()),
            Some(o)
        );
    }
    for id in (0..=255u8).filter(|id| !ids.contains(id)) {
        let err = Orientation::from_id(id).unwrap_err();
        assert_eq!(err.0, id);
        assert!(err.to_string().contains(&format!("rotation id {id} ")));
    }
    assert_eq!(Orientation::from_name("ROTATION_YAW_45"), None);
    assert_eq!(Orientation::from_name("ROTATIÖN_"), None);
    // PX4: R = Rz(yaw)·Ry(pitch)·Rx(roll), v_board = R·v_sensor.
    assert_eq!(Orientation::Yaw90.rotate([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    assert_eq!(Orientation::Roll90.rotate([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
    assert_eq!(
        Orientation::Pitch90.rotate([0.0, 0.0, 1.0]),
        [1.0, 0.0, 0.0]
    );
    assert_eq!(
        Orientation::Roll180.rotate([1.0, 2.0, 3.0]),
        [1.0, -2.0, -3.0]
    );
}

#[test]
fn orientation_is_an_exact_remap_of_the_corrected_sample() {
    let mut rng = rng(24);
    for _ in 0..50 {
        let scale = random_scale(&mut rng);
        let cal = random_calibration(&mut rng, &scale);
        let plain = Corrector::new(&cal, &scale, Orientation::RotationNone).unwrap();
        for o in Orientation::ALL {
            let c = Corrector::new(&cal, &scale, o).unwrap();
            // Validation saw the same unrotated (I+Σ).
            assert_eq!(
                c.condition_number(Triad::Accel),
                plain.condition_number(Triad::Accel)
            );
            let r = o.matrix();
            // Row i of R has one ±1, at column j: out_i = ±v_j.
            let remap = |v: [f32; 3]| {
                r.map(|row| {
                    let j = row.iter().position(|&x| x != 0).unwrap();
                    if row[j] > 0 {
                        v[j]
                    } else {
                        -v[j]
                    }
                })
            };
            for _ in 0..20 {
                let raw = random_raw(&mut rng);
                let (a, b) = (plain.correct(&raw), c.correct(&raw));
                // Rows of K and k are permuted and negated exactly, and
                // round-to-nearest is symmetric: the f32 results are bit-exact.
                assert_eq!(b.accel, remap(a.accel), "{o}");
                assert_eq!(b.gyro, remap(a.gyro), "{o}");
                assert_eq!(
                    c.reference(&raw).accel,
                    o.rotate(plain.reference(&raw).accel)
                );
            }
        }
    }
}
