//! Which gravity directions a session has seen: the six body half-axes
//! (+x, −x, … −z), each seen when a pose's "up" lies within 60° of it
//! (cos ≥ 0.5). Every direction is within 54.7° of some half-axis, so each
//! pose sees at least one; an accelerometer fit whose poses see all six
//! has each axis measured near +g and −g, which separates its scale factor
//! from its bias.

/// The half-axes, as the user is told to point them up.
pub const SIDES: [&str; 6] = ["+x", "−x", "+y", "−y", "+z", "−z"];

/// A pose sees a side when up·side ≥ this (60°).
pub const SIDE_COS: f64 = 0.5;

/// The sides seen so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Coverage {
    seen: [u32; 6],
}

/// The unit vector of side `i` of [`SIDES`].
fn side(i: usize) -> [f64; 3] {
    let mut v = [0.0; 3];
    v[i / 2] = if i.is_multiple_of(2) { 1.0 } else { -1.0 };
    v
}

impl Coverage {
    /// Counts a pose with unit "up" `up`; returns the sides it saw first.
    pub fn add(&mut self, up: &[f64; 3]) -> Vec<&'static str> {
        let mut new = Vec::new();
        for (i, seen) in self.seen.iter_mut().enumerate() {
            let s = side(i);
            if up[0] * s[0] + up[1] * s[1] + up[2] * s[2] >= SIDE_COS {
                if *seen == 0 {
                    new.push(SIDES[i]);
                }
                *seen += 1;
            }
        }
        new
    }

    /// The sides not seen yet, in [`SIDES`] order.
    pub fn missing(&self) -> Vec<&'static str> {
        (0..6)
            .filter(|&i| self.seen[i] == 0)
            .map(|i| SIDES[i])
            .collect()
    }

    /// All six sides seen.
    pub fn complete(&self) -> bool {
        self.seen.iter().all(|&n| n > 0)
    }

    /// "+x 2, −x 1, … −z 0": poses per side.
    pub fn summary(&self) -> String {
        SIDES
            .iter()
            .zip(self.seen)
            .map(|(s, n)| format!("{s} {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_pose_sees_the_sides_within_60_degrees() {
        let mut c = Coverage::default();
        assert_eq!(c.missing(), SIDES.to_vec());
        assert_eq!(c.add(&[0.0, 0.0, 1.0]), vec!["+z"]);
        // Up halfway between +x and −y (45° from each): both seen.
        let h = 0.5f64.sqrt();
        assert_eq!(c.add(&[h, -h, 0.0]), vec!["+x", "−y"]);
        // A corner direction is 54.7° from three sides: all three seen, +z again.
        let k = 1.0 / 3f64.sqrt();
        assert_eq!(c.add(&[-k, k, k]), vec!["−x", "+y"]);
        assert_eq!(c.missing(), vec!["−z"]);
        assert!(!c.complete());
        // 61° from −z: not seen.
        let a = 61f64.to_radians();
        assert!(c.add(&[a.sin(), 0.0, -a.cos()]).is_empty());
        assert_eq!(c.add(&[0.0, 0.0, -1.0]), vec!["−z"]);
        assert!(c.complete() && c.missing().is_empty());
        assert_eq!(c.summary(), "+x 2, −x 1, +y 1, −y 1, +z 2, −z 1");
    }
}
