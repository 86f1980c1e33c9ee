//! The poses of a board turned by hand: random orientations drawn from a
//! seed, each new pose's gravity direction kept apart from the earlier ones'
//! (a person turning a board for a calibration looks for directions not yet
//! shown), so that every record of the script sees gravity from all sides.

use super::rotation::{self, Mat3, IDENTITY};
use crate::effects::rng::{mix64, Rng};
use crate::motion::MAX_POSITIONS;

/// The fewest poses of a hand motion: a rig-free fit wants at least twelve
/// gravity directions (issue 12).
pub const MIN_HAND_POSES: u8 = 12;

/// The angle, radians, the body's gravity direction is kept from every
/// earlier pose's (20°): 24 caps of that radius cover about 70 % of the
/// sphere, so a new direction is found within a few dozen draws.
pub const MIN_SEPARATION: f64 = 20.0 * core::f64::consts::PI / 180.0;

/// Draws per pose; when none is [`MIN_SEPARATION`] away, the farthest is kept.
const TRIES: usize = 64;

/// Keeps the hand poses' stream apart from every effect stream of the same seed.
const HAND_KEY: u64 = u32::from_be_bytes(*b"hand") as u64;

/// A uniformly distributed rotation: the unit quaternion of four normal
/// deviates (Shoemake, "Uniform random rotations", Graphics Gems III).
fn random_rotation(rng: &mut Rng) -> Mat3 {
    let mut q = [0.0; 4];
    let mut n2 = 0.0;
    while n2 < 1e-12 {
        q = [
            rng.gaussian(),
            rng.gaussian(),
            rng.gaussian(),
            rng.gaussian(),
        ];
        n2 = q.iter().map(|x| x * x).sum::<f64>();
    }
    let n = libm::sqrt(n2);
    rotation::from_quaternion(&q.map(|c| c / n))
}

/// The level "up" seen in the body frame: Rᵀ·e_z, the third row of R.
fn body_up(r: &Mat3) -> [f64; 3] {
    r[2]
}

/// The smallest angle between `up` and the first `n` poses' up directions
/// (π when there are none).
fn nearest(up: &[f64; 3], poses: &[Mat3]) -> f64 {
    poses
        .iter()
        .map(|p| {
            let u = body_up(p);
            let c = up[0] * u[0] + up[1] * u[1] + up[2] * u[2];
            libm::acos(c.clamp(-1.0, 1.0))
        })
        .fold(core::f64::consts::PI, f64::min)
}

/// The first `n` (at most [`MAX_POSITIONS`]) poses of seed `seed`,
/// body-to-level rotations; the rest of the array is the identity.
pub fn hand_poses(seed: u64, n: usize) -> [Mat3; MAX_POSITIONS] {
    let n = n.min(MAX_POSITIONS);
    let mut rng = Rng::from_seed(mix64(seed ^ mix64(HAND_KEY)));
    let mut poses = [IDENTITY; MAX_POSITIONS];
    for i in 0..n {
        let mut best = (IDENTITY, -1.0);
        for _ in 0..TRIES {
            let r = random_rotation(&mut rng);
            let apart = nearest(&body_up(&r), &poses[..i]);
            if apart > best.1 {
                best = (r, apart);
            }
            if apart >= MIN_SEPARATION {
                break;
            }
        }
        poses[i] = best.0;
    }
    poses
}
