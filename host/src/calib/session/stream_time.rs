//! The stream's own time: the frames' µs time stamps (u32, wrapping every
//! 71.6 min) unwrapped into seconds since the first frame, and the breaks
//! a gyro integration cannot cross (a frame lost on the way, dropped by
//! the firmware, or a sample step overrun). A session times everything by
//! this clock, so an emulated board slower than real time is judged as a
//! real one is.

/// Why the stream is not continuous at a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Break {
    /// Frame numbers skip: frames lost on the way.
    Lost {
        /// The frame number expected.
        expected: u32,
        /// The one that came.
        got: u32,
    },
    /// The firmware dropped frames (its link was full).
    Dropped(u16),
    /// Sample steps overran (samples not taken).
    Overrun(u16),
}

impl std::fmt::Display for Break {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Break::Lost { expected, got } => write!(
                f,
                "frame {got} came after frame {}: {} frame(s) lost on the way",
                expected.wrapping_sub(1),
                got.wrapping_sub(expected)
            ),
            Break::Dropped(n) => write!(f, "the device dropped {n} frame(s) (its link was full)"),
            Break::Overrun(n) => write!(f, "the device missed {n} sample step(s) (overruns)"),
        }
    }
}

/// Unwraps the time stamps of consecutive frames and finds breaks.
#[derive(Clone, Copy, Debug, Default)]
pub struct StreamTime {
    last: Option<(u32, u32)>,
    seconds: f64,
}

impl StreamTime {
    /// The time (s since the first frame) of a frame numbered `sequence`
    /// stamped `timestamp_us`, with the break before it if any (the time
    /// still advances by the stamps' difference).
    pub fn frame(
        &mut self,
        sequence: u32,
        timestamp_us: u32,
        dropped: u16,
        overruns: u16,
    ) -> (f64, Option<Break>) {
        let mut gap = None;
        if let Some((last_sequence, last_us)) = self.last {
            self.seconds += f64::from(timestamp_us.wrapping_sub(last_us)) * 1e-6;
            let expected = last_sequence.wrapping_add(1);
            gap = if sequence != expected {
                Some(Break::Lost {
                    expected,
                    got: sequence,
                })
            } else if dropped > 0 {
                Some(Break::Dropped(dropped))
            } else if overruns > 0 {
                Some(Break::Overrun(overruns))
            } else {
                None
            };
        }
        self.last = Some((sequence, timestamp_us));
        (self.seconds, gap)
    }

    /// The time of a sample stamped `timestamp_us` inside the frame last
    /// given (a batch's later samples): no frame number of its own.
    pub fn within(&mut self, timestamp_us: u32) -> f64 {
        if let Some((sequence, last_us)) = self.last {
            self.seconds += f64::from(timestamp_us.wrapping_sub(last_us)) * 1e-6;
            self.last = Some((sequence, timestamp_us));
        }
        self.seconds
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_unwraps_across_the_u32_wrap_and_gaps_are_named() {
        let mut s = StreamTime::default();
        assert_eq!(s.frame(7, u32::MAX - 499, 0, 0), (0.0, None));
        // 1000 µs later, across the wrap.
        let (t, gap) = s.frame(8, 500, 0, 0);
        assert!((t - 1e-3).abs() < 1e-12 && gap.is_none(), "{t}");
        let (t, gap) = s.frame(10, 2500, 0, 0);
        assert!((t - 3e-3).abs() < 1e-12);
        assert_eq!(
            gap,
            Some(Break::Lost {
                expected: 9,
                got: 10
            })
        );
        assert_eq!(
            gap.unwrap().to_string(),
            "frame 10 came after frame 8: 1 frame(s) lost on the way"
        );
        assert_eq!(s.frame(11, 3500, 2, 0).1, Some(Break::Dropped(2)));
        assert_eq!(s.frame(12, 4500, 0, 1).1, Some(Break::Overrun(1)));
        assert_eq!(s.frame(13, 5500, 0, 0).1, None);
    }
}
