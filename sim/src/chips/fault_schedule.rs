//! Faults the emulated board shows on a schedule in device time, as a
//! deployment throws them at a board: the chip vanishes from the bus, a
//! storm of failed transactions, the data-ready line held high or silent,
//! the output stops, a brown-out after which the chip is back at its
//! power-on registers.
//!
//! A schedule is written `KIND@START[+DURATION][/EVERY]` (seconds of
//! device time), `nack@START*COUNT[/EVERY]` for a storm of COUNT failed
//! transactions; a fault without a duration lasts to the end of the run, one
//! with `/EVERY` comes back every EVERY seconds (the soak's hourly faults). The board reads one
//! entry per `fault=` word of its semihosting command line (`cargo xtask
//! serve --fault SPEC`), so one firmware build serves every schedule;
//! xtask checks each entry with this same parser before QEMU starts.

use core::fmt;

/// What the board shows while a scheduled fault is active.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoardFault {
    /// `vanish`: the chip is gone from the bus (a loose cable, the chip
    /// still powered): SPI reads 0xFF (MISO pulled up), I²C is not
    /// acknowledged, and its data-ready line gives no edge. It keeps its
    /// registers, and its configuration when it comes back.
    Vanish,
    /// `nack`: the next `transactions` bus transactions fail (SPI error,
    /// I²C NACK); the chip and its data-ready line carry on.
    NackStorm {
        /// Transactions that fail.
        transactions: u32,
    },
    /// `fifo-count`: the FIFO's count registers read a count beyond the
    /// FIFO's size (a corrupted read, a chip confused by a glitch); the
    /// FIFO itself and the data-ready line carry on.
    ImpossibleFifoCount,
    /// `drdy-high`: the data-ready line is held high. The MCU's interrupt is
    /// edge-triggered (EXTI), so no edge arrives: the chip samples on, and
    /// the firmware sees no data-ready.
    DataReadyHeldHigh,
    /// `drdy-silent`: the data-ready line stays low (a broken track); the
    /// chip samples on, and the firmware sees no data-ready.
    DataReadySilent,
    /// `stop`: the chip's output stops (data registers frozen, no
    /// data-ready, no FIFO) while it still answers on the bus; a reset does
    /// not cure it, the end of the fault does.
    OutputStops,
    /// `brownout`: the chip's supply sags: gone from the bus as for
    /// [`BoardFault::Vanish`] while it lasts, then back at its power-on
    /// registers (sensors off), so the firmware must configure it again.
    BrownOut,
}

impl BoardFault {
    /// The fault's name in a schedule.
    pub fn name(&self) -> &'static str {
        match self {
            BoardFault::Vanish => "vanish",
            BoardFault::NackStorm { .. } => "nack",
            BoardFault::ImpossibleFifoCount => "fifo-count",
            BoardFault::DataReadyHeldHigh => "drdy-high",
            BoardFault::DataReadySilent => "drdy-silent",
            BoardFault::OutputStops => "stop",
            BoardFault::BrownOut => "brownout",
        }
    }

    /// Whether no data-ready edge reaches the MCU while the fault lasts:
    /// the line's own faults, and a chip that raises none (gone from the
    /// bus, browned out, its output stopped). From the fault's start on,
    /// whatever the chip model last said; after it ends, the chip model
    /// says (a chip back from a brown-out raises none until configured).
    pub fn silences_data_ready(&self) -> bool {
        !matches!(
            self,
            BoardFault::NackStorm { .. } | BoardFault::ImpossibleFifoCount
        )
    }
}

/// One fault with its time, µs of device time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScheduledFault {
    /// What happens.
    pub fault: BoardFault,
    /// When it starts, µs since the board started.
    pub start_us: u64,
    /// When it ends, µs since the board started (`None`: never). A
    /// storm has no end: its transactions fail whenever they come.
    pub end_us: Option<u64>,
    /// It comes back this often, µs (`None`: once).
    pub every_us: Option<u64>,
}

impl ScheduledFault {
    /// Whether the fault is on at `now_us`.
    pub fn active_at(&self, now_us: u64) -> bool {
        let Some(since) = now_us.checked_sub(self.start_us) else {
            return false;
        };
        let since = self.every_us.map_or(since, |every| since % every);
        self.end_us.is_none_or(|end| since < end - self.start_us)
    }

    /// When its `n`-th occurrence (from 0) starts, µs; `None` past the
    /// first for a fault that comes once.
    pub fn start_of(&self, n: u64) -> Option<u64> {
        match (n, self.every_us) {
            (0, _) => Some(self.start_us),
            (_, Some(every)) => self.start_us.checked_add(n.checked_mul(every)?),
            (_, None) => None,
        }
    }

    /// When its `n`-th occurrence ends, µs (`None`: never, or no such one).
    pub fn end_of(&self, n: u64) -> Option<u64> {
        let length = self.end_us? - self.start_us;
        self.start_of(n)?.checked_add(length)
    }
}

/// Most entries a schedule holds.
pub const MAX_FAULTS: usize = 8;

/// Why an entry of a schedule is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScheduleError<'a> {
    /// The entry is not `KIND@START[+DURATION][/EVERY]` (or
    /// `nack@START*COUNT[/EVERY]`).
    Form(&'a str),
    /// A fault that comes back lasts as long as its period, or has no end.
    Every(&'a str),
    /// The kind is not one of [`KINDS`].
    Kind(&'a str),
    /// A time is not a finite number of seconds ≥ 0 (the text given).
    Time(&'a str),
    /// A storm's count is not a whole number ≥ 1, or is missing.
    Count(&'a str),
    /// More than [`MAX_FAULTS`] entries.
    Full,
}

/// The kinds a schedule names.
pub const KINDS: &str = "vanish, nack, fifo-count, drdy-high, drdy-silent, stop, brownout";

impl fmt::Display for ScheduleError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ScheduleError::Form(entry) => write!(
                f,
                "fault {entry:?}: not KIND@START[+DURATION][/EVERY] (seconds), \
                 or nack@START*COUNT[/EVERY]"
            ),
            ScheduleError::Every(every) => write!(
                f,
                "fault period {every:?}: a fault that comes back must end before it does"
            ),
            ScheduleError::Kind(kind) => write!(f, "fault kind {kind:?}: not one of {KINDS}"),
            ScheduleError::Time(time) => write!(
                f,
                "fault time {time:?}: not a finite number of seconds, 0 or more"
            ),
            ScheduleError::Count(count) => write!(
                f,
                "nack count {count:?}: not a whole number of transactions, 1 or more"
            ),
            ScheduleError::Full => write!(f, "more than {MAX_FAULTS} faults scheduled"),
        }
    }
}

/// The faults of a run, in the order given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultSchedule {
    entries: [Option<ScheduledFault>; MAX_FAULTS],
}

impl FaultSchedule {
    /// No fault.
    pub const fn new() -> Self {
        Self {
            entries: [None; MAX_FAULTS],
        }
    }

    /// Adds the entry `spec` (`KIND@START[+DURATION]`, `nack@START*COUNT`).
    pub fn add<'a>(&mut self, spec: &'a str) -> Result<(), ScheduleError<'a>> {
        let entry = parse_entry(spec)?;
        let slot = self
            .entries
            .iter_mut()
            .find(|e| e.is_none())
            .ok_or(ScheduleError::Full)?;
        *slot = Some(entry);
        Ok(())
    }

    /// The entries, in the order given.
    pub fn entries(&self) -> impl Iterator<Item = &ScheduledFault> {
        self.entries.iter().flatten()
    }

    /// Whether a fault that silences data-ready is on at `now_us`.
    pub fn silenced_at(&self, now_us: u64) -> bool {
        self.entries()
            .any(|e| e.fault.silences_data_ready() && e.active_at(now_us))
    }

    /// Whether the schedule is empty.
    pub fn is_empty(&self) -> bool {
        self.entries().next().is_none()
    }
}

fn parse_entry(spec: &str) -> Result<ScheduledFault, ScheduleError<'_>> {
    let (kind, when) = spec.split_once('@').ok_or(ScheduleError::Form(spec))?;
    let (when, every) = match when.split_once('/') {
        Some((when, every)) => (when, Some(every)),
        None => (when, None),
    };
    let every_us = match every {
        Some(text) => match seconds_us(text)? {
            0 => return Err(ScheduleError::Every(text)),
            us => Some(us),
        },
        None => None,
    };
    if kind == "nack" {
        let (start, count) = when.split_once('*').ok_or(ScheduleError::Count(""))?;
        let transactions = match count.parse::<u32>() {
            Ok(n) if n >= 1 => n,
            _ => return Err(ScheduleError::Count(count)),
        };
        return Ok(ScheduledFault {
            fault: BoardFault::NackStorm { transactions },
            start_us: seconds_us(start)?,
            end_us: None,
            every_us,
        });
    }
    let fault = match kind {
        "vanish" => BoardFault::Vanish,
        "fifo-count" => BoardFault::ImpossibleFifoCount,
        "drdy-high" => BoardFault::DataReadyHeldHigh,
        "drdy-silent" => BoardFault::DataReadySilent,
        "stop" => BoardFault::OutputStops,
        "brownout" => BoardFault::BrownOut,
        _ => return Err(ScheduleError::Kind(kind)),
    };
    let (start, duration) = match when.split_once('+') {
        Some((start, duration)) => (start, Some(duration)),
        None => (when, None),
    };
    let start_us = seconds_us(start)?;
    let length_us = match duration {
        Some(d) => Some(seconds_us(d)?),
        None => None,
    };
    if let Some(every) = every {
        // A fault that comes back ends before its next occurrence.
        if length_us.is_none_or(|length| Some(length) >= every_us) {
            return Err(ScheduleError::Every(every));
        }
    }
    Ok(ScheduledFault {
        fault,
        start_us,
        end_us: length_us.map(|length| start_us.saturating_add(length)),
        every_us,
    })
}

/// `text` seconds as whole µs (rounded).
fn seconds_us(text: &str) -> Result<u64, ScheduleError<'_>> {
    match text.parse::<f64>() {
        // Below 2⁶⁴ µs by far: 10⁶ years.
        Ok(s) if s.is_finite() && (0.0..=3.0e13).contains(&s) => Ok(libm::round(s * 1e6) as u64),
        _ => Err(ScheduleError::Time(text)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_read_their_kind_start_and_end_in_microseconds() {
        let mut s = FaultSchedule::new();
        s.add("vanish@2.0+0.5").unwrap();
        s.add("nack@1.25*40").unwrap();
        s.add("stop@3").unwrap();
        let e: [ScheduledFault; 3] = core::array::from_fn(|i| *s.entries().nth(i).unwrap());
        assert_eq!(
            e[0],
            ScheduledFault {
                fault: BoardFault::Vanish,
                start_us: 2_000_000,
                end_us: Some(2_500_000),
                every_us: None,
            }
        );
        assert_eq!(e[1].fault, BoardFault::NackStorm { transactions: 40 });
        assert_eq!(e[1].start_us, 1_250_000);
        assert_eq!(e[2].end_us, None);
        assert!(e[0].active_at(2_000_000) && e[0].active_at(2_499_999));
        assert!(!e[0].active_at(1_999_999) && !e[0].active_at(2_500_000));
    }

    #[test]
    fn every_fault_but_a_storm_silences_data_ready_and_only_while_on() {
        let mut s = FaultSchedule::new();
        s.add("drdy-high@1+1").unwrap();
        s.add("nack@0*1000").unwrap();
        s.add("vanish@5+0.001").unwrap();
        assert!(!s.silenced_at(999_999));
        assert!(s.silenced_at(1_000_000));
        assert!(!s.silenced_at(2_000_000));
        assert!(s.silenced_at(5_000_000));
        assert!(!s.silenced_at(5_001_000));
    }

    #[test]
    fn a_fault_that_comes_back_is_on_in_each_period_for_its_length() {
        let mut s = FaultSchedule::new();
        s.add("brownout@1800+0.5/3600").unwrap();
        s.add("nack@10*5/20").unwrap();
        let e = *s.entries().next().unwrap();
        let h = 3_600_000_000;
        assert!(!e.active_at(1_799_999_999));
        assert!(e.active_at(1_800_000_000) && e.active_at(1_800_499_999));
        assert!(!e.active_at(1_800_500_000));
        assert!(e.active_at(23 * h + 1_800_000_000));
        assert!(!e.active_at(23 * h + 1_800_500_000));
        assert_eq!(e.start_of(2), Some(2 * h + 1_800_000_000));
        assert_eq!(e.end_of(2), Some(2 * h + 1_800_500_000));
        let storm = *s.entries().nth(1).unwrap();
        assert_eq!(storm.fault, BoardFault::NackStorm { transactions: 5 });
        assert_eq!(
            (storm.start_of(1), storm.end_of(1)),
            (Some(30_000_000), None)
        );
    }

    #[test]
    fn a_bad_entry_is_refused_naming_the_part_that_is_wrong() {
        let mut s = FaultSchedule::new();
        assert_eq!(s.add("vanish"), Err(ScheduleError::Form("vanish")));
        assert_eq!(s.add("melt@1"), Err(ScheduleError::Kind("melt")));
        assert_eq!(s.add("stop@-1"), Err(ScheduleError::Time("-1")));
        assert_eq!(s.add("stop@1+nan"), Err(ScheduleError::Time("nan")));
        assert_eq!(s.add("nack@1"), Err(ScheduleError::Count("")));
        assert_eq!(s.add("nack@1*0"), Err(ScheduleError::Count("0")));
        assert_eq!(s.add("stop@1/10"), Err(ScheduleError::Every("10")));
        assert_eq!(s.add("stop@1+10/10"), Err(ScheduleError::Every("10")));
        assert_eq!(s.add("stop@1+1/0"), Err(ScheduleError::Every("0")));
        for _ in 0..MAX_FAULTS {
            s.add("stop@1").unwrap();
        }
        assert_eq!(s.add("stop@1"), Err(ScheduleError::Full));
    }
}
