//! The FIFO watermark step (`Sampler::step_fifo`) against a scripted FIFO:
//! every sample framed once, in batches of at most 16, one chip period
//! apart and ending at the interrupt's time; an overflow flagged and its
//! lost samples counted as overruns; a full link queue counted dropped with
//! the counters carried to the next frame; raw mode and averaging through
//! the per-sample frames; a failed read counted; a restarted chip's gap
//! counted lost once.

mod model_support;

use std::collections::VecDeque;

use model_support::*;
use triad::device::{Outgoing, Sampler, SlotQueue};
use triad::model::{BatchKernel, Corrector, Orientation};
use triad::protocol::{Flags, Frame};
use triad::protocol::{Mode, MAX_BATCH};
use triad::sensor::{FifoImu, FifoRead, Imu, ImuScale, RawSample};

/// A FIFO that holds what the test puts in it, and may report an overflow
/// or fail its next read.
struct ScriptedFifo {
    waiting: VecDeque<RawSample>,
    scale: ImuScale,
    overflow_lost: Option<u32>,
    fail_next: bool,
}

impl Imu for ScriptedFifo {
    type Error = &'static str;
    fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
        Err("the FIFO step never reads the data registers")
    }
    fn scale(&self) -> ImuScale {
        self.scale
    }
}

impl FifoImu for ScriptedFifo {
    fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<FifoRead, Self::Error> {
        if std::mem::take(&mut self.fail_next) {
            return Err("bus error");
        }
        if let Some(lost) = self.overflow_lost.take() {
            // As the ICM-42688-P driver: the FIFO reset, its content counted lost.
            let lost = lost + self.waiting.len() as u32;
            self.waiting.clear();
            return Ok(FifoRead {
                samples: 0,
                remaining: 0,
                overflowed: true,
                lost,
                lost_is_lower_bound: false,
            });
        }
        let n = out.len().min(self.waiting.len());
        for slot in &mut out[..n] {
            *slot = self.waiting.pop_front().unwrap();
        }
        Ok(FifoRead {
            samples: n,
            remaining: self.waiting.len() as u16,
            overflowed: false,
            lost: 0,
            lost_is_lower_bound: false,
        })
    }
    fn reset_fifo(&mut self) -> Result<(), Self::Error> {
        self.waiting.clear();
        Ok(())
    }
}

/// 8 kHz: 125 µs between samples.
const RATE_HZ: f64 = 8000.0;
const PERIOD_NS: u32 = 125_000;

fn setup(seed: u64) -> (ScriptedFifo, Sampler, Corrector) {
    let mut rng = rng(seed);
    let scale = random_scale(&mut rng);
    let cal = random_calibration(&mut rng, &scale);
    let corrector = Corrector::new(&cal, &scale, Orientation::default()).unwrap();
    let sampler = Sampler::at_rate(corrector.clone(), true, 1, RATE_HZ);
    let fifo = ScriptedFifo {
        waiting: VecDeque::new(),
        scale,
        overflow_lost: None,
        fail_next: false,
    };
    (fifo, sampler, corrector)
}

fn fill(fifo: &mut ScriptedFifo, seed: u64, n: usize) -> Vec<RawSample> {
    let mut rng = rng(seed);
    let samples: Vec<RawSample> = (0..n).map(|_| random_raw(&mut rng)).collect();
    fifo.waiting.extend(&samples);
    samples
}

#[test]
fn every_sample_is_framed_once_in_batches_one_period_apart() {
    let (mut fifo, mut sampler, corrector) = setup(1);
    let kernel = BatchKernel::new(&corrector);
    // 70 samples waiting: more than one read of 32, and a batch of 6 last.
    let raws = fill(&mut fifo, 2, 70);
    let mut frames = Vec::new();
    let now_us = 1_000_000;
    let stepped = sampler.step_fifo(&mut fifo, now_us, |f| {
        frames.push(f);
        true
    });
    assert_eq!(stepped.samples, 70);
    assert_eq!(stepped.queued as usize, frames.len());
    let batches: Vec<_> = frames
        .iter()
        .map(|f| match f {
            Outgoing::Batch(b) => *b,
            other => panic!("calibrated, no averaging: batches only, got {other:?}"),
        })
        .collect();
    assert!(batches.iter().all(|b| usize::from(b.count) <= MAX_BATCH));
    let mut expected = vec![[0i16; 6]; 70];
    kernel.correct(&raws, &mut expected);
    let got: Vec<[i16; 6]> = batches.iter().flat_map(|b| b.samples().to_vec()).collect();
    assert_eq!(
        got, expected,
        "each sample once, in order, as the kernel corrects it"
    );
    // Times: one period apart, the newest at the interrupt's time (to the µs).
    let times: Vec<u64> = batches
        .iter()
        .flat_map(|b| {
            (0..u64::from(b.count))
                .map(|i| u64::from(b.timestamp_us) * 1000 + i * u64::from(PERIOD_NS))
        })
        .collect();
    for pair in times.windows(2) {
        assert_eq!(pair[1] - pair[0], u64::from(PERIOD_NS));
    }
    let newest = *times.last().unwrap();
    assert!(
        newest.abs_diff(u64::from(now_us) * 1000) < 1000,
        "{newest} ns"
    );
    // Sequence numbers count packets.
    for (n, b) in batches.iter().enumerate() {
        assert_eq!(b.sequence, n as u32);
    }
}

#[test]
fn an_overflow_is_flagged_and_its_samples_counted_lost_in_the_next_batch() {
    let (mut fifo, mut sampler, _) = setup(3);
    fill(&mut fifo, 4, 20);
    fifo.overflow_lost = Some(100);
    let mut frames = Vec::new();
    sampler.step_fifo(&mut fifo, 0, |f| {
        frames.push(f);
        true
    });
    assert!(
        frames.is_empty(),
        "the overflowed FIFO was reset: nothing to frame"
    );
    fill(&mut fifo, 5, 8);
    sampler.step_fifo(&mut fifo, 1000, |f| {
        frames.push(f);
        true
    });
    let Outgoing::Batch(b) = frames[0] else {
        panic!("{:?}", frames[0]);
    };
    assert!(b.flags.contains(Flags::FIFO_OVERFLOW));
    assert_eq!(
        b.overruns, 120,
        "the 100 dropped while full and the 20 reset"
    );
    assert_eq!(sampler.totals().overruns, 120);
    // Cleared once sent.
    fill(&mut fifo, 6, 8);
    let mut next = Vec::new();
    sampler.step_fifo(&mut fifo, 2000, |f| {
        next.push(f);
        true
    });
    let Outgoing::Batch(b) = next[0] else {
        panic!("{:?}", next[0]);
    };
    assert!(!b.flags.contains(Flags::FIFO_OVERFLOW));
    assert_eq!(b.overruns, 0);
}

#[test]
fn a_full_link_queue_drops_and_counts_and_the_next_frame_carries_it() {
    let (mut fifo, mut sampler, _) = setup(7);
    fill(&mut fifo, 8, 32);
    let mut offered = 0;
    let stepped = sampler.step_fifo(&mut fifo, 0, |_| {
        offered += 1;
        false
    });
    assert_eq!((stepped.queued, stepped.dropped), (0, 2));
    assert_eq!(sampler.totals().frames_dropped, 2);
    fill(&mut fifo, 9, 8);
    let mut frames = Vec::new();
    sampler.step_fifo(&mut fifo, 4000, |f| {
        frames.push(f);
        true
    });
    let Outgoing::Batch(b) = frames[0] else {
        panic!("{:?}", frames[0]);
    };
    assert_eq!(b.dropped, 2);
    assert!(b.flags.contains(Flags::DROPPED));
    assert_eq!(b.sequence, 0, "a dropped frame gives its number back");
}

#[test]
fn frames_written_in_the_link_queues_slots_are_the_frames_given_by_value() {
    // The firmware's queue (frames built in its slots, none built when it is
    // full) against the by-value form (built, then refused): the same
    // frames, the same counts, the same bytes on the wire.
    let (mut fifo_a, mut by_value, _) = setup(21);
    let (mut fifo_b, mut in_place, _) = setup(21);
    // Slots that start as data frames (the firmware's zeroed queue): the
    // first batch into each is built apart and copied in, the later ones
    // are written in place.
    let mut queue = SlotQueue::<Outgoing, 2>::new(Outgoing::Data(Default::default()));
    let (mut slots, mut link) = queue.split();
    let mut wire_a = [0u8; triad::protocol::MAX_WIRE_LEN];
    let mut wire_b = [0u8; triad::protocol::MAX_WIRE_LEN];
    // 70 samples: five batches, the last of 6 (slots reused hold 16).
    for (step, n) in [(0u32, 70usize), (1, 70), (2, 40), (3, 3)] {
        fill(&mut fifo_a, 22 + u64::from(step), n);
        fill(&mut fifo_b, 22 + u64::from(step), n);
        let now_us = 10_000 * (step + 1);
        let mut room = 2;
        let mut given = Vec::new();
        let a = by_value.step_fifo(&mut fifo_a, now_us, |f| {
            let queued = room > 0;
            if queued {
                room -= 1;
                given.push(f);
            }
            queued
        });
        let b = in_place.step_fifo_into(&mut fifo_b, now_us, &mut slots);
        assert_eq!(a, b, "step {step}");
        assert_eq!(by_value.totals(), in_place.totals(), "step {step}");
        let mut taken = Vec::new();
        while let Some(frame) = link.peek() {
            taken.push(*frame);
            link.release();
        }
        assert_eq!(given, taken, "step {step}");
        for (a, b) in given.iter().zip(&taken) {
            let (na, nb) = (a.to_wire(&mut wire_a), b.to_wire(&mut wire_b));
            assert_eq!(wire_a[..na], wire_b[..nb], "step {step}");
        }
    }
}

#[test]
fn raw_mode_and_averaging_frame_each_sample_through_the_per_sample_path() {
    let (mut fifo, mut sampler, _) = setup(11);
    sampler.apply(triad::device::Control::SetMode(Mode::Raw));
    let raws = fill(&mut fifo, 12, 10);
    let mut frames = Vec::new();
    sampler.step_fifo(&mut fifo, 10_000, |f| {
        frames.push(f);
        true
    });
    assert_eq!(frames.len(), 10);
    for (f, raw) in frames.iter().zip(&raws) {
        let Outgoing::Raw(r) = f else {
            panic!("{f:?}");
        };
        assert_eq!(r.accel, raw.accel.map(|x| x as f32));
    }
    sampler.apply(triad::device::Control::SetMode(Mode::Calibrated));
    sampler.apply(triad::device::Control::SetDecimation(4));
    fill(&mut fifo, 13, 10);
    let mut averaged = Vec::new();
    sampler.step_fifo(&mut fifo, 20_000, |f| {
        averaged.push(f);
        true
    });
    assert_eq!(averaged.len(), 2, "10 samples, averages of 4: two frames");
    assert!(averaged.iter().all(|f| matches!(f, Outgoing::Data(_))));
}

#[test]
fn a_failed_read_is_counted_and_reported() {
    let (mut fifo, mut sampler, _) = setup(15);
    fill(&mut fifo, 16, 8);
    fifo.fail_next = true;
    let stepped = sampler.step_fifo(&mut fifo, 0, |_| true);
    assert_eq!(stepped.read_failed, Some("bus error"));
    assert_eq!(sampler.totals().read_failures, 1);
    // The samples waited in the FIFO: the next interrupt takes them.
    let stepped = sampler.step_fifo(&mut fifo, 1000, |_| true);
    assert_eq!(stepped.samples, 8);
}

#[test]
fn the_samples_a_self_test_took_are_counted_in_the_next_batch_which_says_self_test() {
    let (mut fifo, mut sampler, _) = setup(7);
    fill(&mut fifo, 8, 8);
    let mut frames = Vec::new();
    sampler.step_fifo(&mut fifo, 1_000, |f| {
        frames.push(f);
        true
    });
    // The chip goes to its self-test after this step: 0.64 s later it is
    // back, with 8 new samples (one watermark) waiting.
    sampler.self_test_began();
    assert!(sampler.in_self_test());
    let back = 1_000 + 640_000;
    fill(&mut fifo, 9, 8);
    sampler.step_fifo(&mut fifo, back, |f| {
        frames.push(f);
        true
    });
    assert!(!sampler.in_self_test());
    let Outgoing::Batch(before) = frames[0] else {
        panic!("{:?}", frames[0]);
    };
    let Outgoing::Batch(after) = frames[1] else {
        panic!("{:?}", frames[1]);
    };
    assert!(!before.flags.contains(Flags::SELF_TEST));
    assert!(after.flags.contains(Flags::SELF_TEST | Flags::OVERRUN));
    // 640 ms at 8 kHz is 5120 periods; the 8 read at the end were measured
    // (the first of them 7 periods before the interrupt).
    assert_eq!(after.overruns, 5120 - 8);
    assert_eq!(sampler.totals().overruns, 5120 - 8);
    // Said once.
    fill(&mut fifo, 10, 8);
    let mut next = Vec::new();
    sampler.step_fifo(&mut fifo, back + 1_000, |f| {
        next.push(f);
        true
    });
    let Outgoing::Batch(b) = next[0] else {
        panic!("{:?}", next[0]);
    };
    assert!(!b.flags.contains(Flags::SELF_TEST));
    assert_eq!(b.overruns, 0);
    assert_eq!(sampler.totals().overruns, 5120 - 8);
}

/// A chip read one sample at a time.
struct OneSample(ImuScale);

impl Imu for OneSample {
    type Error = &'static str;
    fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
        Ok(RawSample::default())
    }
    fn scale(&self) -> ImuScale {
        self.0
    }
}

/// Per sample: a frame at 0, `away` done to the sampler, then frames 100
/// and 101 periods later; the two frames after and the total overruns.
fn per_sample_around(seed: u64, away: fn(&mut Sampler)) -> (Frame, Frame, u32) {
    let (fifo, mut sampler, _) = setup(seed);
    let mut chip = OneSample(fifo.scale);
    let period_us = PERIOD_NS / 1000;
    let mut frame_at = |sampler: &mut Sampler, t: u32| match sampler.step(&mut chip, t) {
        triad::device::StepOutcome::Frame(Outgoing::Data(f)) => f,
        other => panic!("{other:?}"),
    };
    frame_at(&mut sampler, 0);
    away(&mut sampler);
    let back = 100 * period_us;
    let first = frame_at(&mut sampler, back);
    let next = frame_at(&mut sampler, back + period_us);
    (first, next, sampler.totals().overruns)
}

#[test]
fn per_sample_the_self_test_gap_is_counted_once_not_again_by_the_step_monitor() {
    // Back 100 periods later: the 99 between were not measured.
    let (f, next, total) = per_sample_around(11, Sampler::self_test_began);
    assert!(f.flags.contains(Flags::SELF_TEST | Flags::OVERRUN));
    assert_eq!(f.overruns, 99);
    assert_eq!(next.overruns, 0);
    assert!(!next.flags.contains(Flags::SELF_TEST));
    assert_eq!(total, 99);
}

#[test]
fn a_flash_stall_is_said_by_the_next_frame_sent_even_past_a_dropped_one() {
    let (fifo, mut sampler, _) = setup(13);
    let mut chip = OneSample(fifo.scale);
    let period_us = PERIOD_NS / 1000;
    sampler.flash_stalled();
    // The first frame after the stall finds the link's queue full.
    let Outgoing::Data(dropped) = (match sampler.step(&mut chip, 0) {
        triad::device::StepOutcome::Frame(frame) => frame,
        other => panic!("{other:?}"),
    }) else {
        panic!("not a data frame");
    };
    assert!(dropped.flags.contains(Flags::FLASH_STALL));
    sampler.frame_dropped(&Outgoing::Data(dropped));
    let sent = match sampler.step(&mut chip, period_us) {
        triad::device::StepOutcome::Frame(Outgoing::Data(f)) => f,
        other => panic!("{other:?}"),
    };
    assert!(sent.flags.contains(Flags::FLASH_STALL | Flags::DROPPED));
    let next = match sampler.step(&mut chip, 2 * period_us) {
        triad::device::StepOutcome::Frame(Outgoing::Data(f)) => f,
        other => panic!("{other:?}"),
    };
    assert!(!next.flags.contains(Flags::FLASH_STALL));
}

#[test]
fn the_fifo_flushed_by_a_self_test_is_not_counted_again_as_an_overflow() {
    let (mut fifo, mut sampler, _) = setup(17);
    fill(&mut fifo, 18, 8);
    sampler.step_fifo(&mut fifo, 1_000, |_| true);
    sampler.self_test_began();
    // The procedure's end flushed the FIFO: the chip says 7 were lost.
    fifo.overflow_lost = Some(7);
    let back = 1_000 + 100_000;
    let mut frames = Vec::new();
    sampler.step_fifo(&mut fifo, back, |f| {
        frames.push(f);
        true
    });
    // The overflowed read had nothing (the self-test's end is dated by the
    // first sample read); the next holds the watermark.
    fill(&mut fifo, 19, 8);
    sampler.step_fifo(&mut fifo, back + 1_000, |f| {
        frames.push(f);
        true
    });
    let Outgoing::Batch(b) = frames[0] else {
        panic!("{:?}", frames[0]);
    };
    assert!(b.flags.contains(Flags::SELF_TEST));
    assert!(!b.flags.contains(Flags::FIFO_OVERFLOW));
    // From the sample at 1 ms to the first after, at 102 ms less 7
    // periods: 801 periods at 8 kHz, less one; nothing more for the flush.
    assert_eq!(b.overruns, 800);
}

#[test]
fn a_restarted_chips_gap_is_counted_lost_once_in_the_first_batch_after() {
    let (mut fifo, mut sampler, _) = setup(23);
    fill(&mut fifo, 24, 8);
    sampler.step_fifo(&mut fifo, 1_000, |_| true);
    // The chip goes silent: a failed read, the stall watch's restart (and
    // a second attempt), then 0.5 s later it streams again after its
    // restart flushed the FIFO, which reports an overflow at first.
    fifo.fail_next = true;
    sampler.step_fifo(&mut fifo, 2_000, |_| true);
    sampler.chip_restarted();
    sampler.chip_restarted();
    fifo.overflow_lost = Some(40);
    let back = 1_000 + 500_000;
    let mut frames = Vec::new();
    sampler.step_fifo(&mut fifo, back, |f| {
        frames.push(f);
        true
    });
    assert!(frames.is_empty(), "the overflowed read had no sample");
    fill(&mut fifo, 25, 8);
    sampler.step_fifo(&mut fifo, back + 1_000, |f| {
        frames.push(f);
        true
    });
    let Outgoing::Batch(b) = frames[0] else {
        panic!("{:?}", frames[0]);
    };
    assert!(b.flags.contains(Flags::OVERRUN));
    assert!(!b.flags.contains(Flags::FIFO_OVERFLOW | Flags::SELF_TEST));
    // From the newest sample before (1 ms) to the first after (502 ms less
    // 7 periods, 501.125 ms): 4001 periods at 8 kHz, the 4000 between
    // lost; the flush's 40 are among them, not counted again.
    assert_eq!(b.overruns, 4000);
    assert_eq!(sampler.totals().overruns, 4000);
    fill(&mut fifo, 26, 8);
    let mut next = Vec::new();
    sampler.step_fifo(&mut fifo, back + 2_000, |f| {
        next.push(f);
        true
    });
    let Outgoing::Batch(b) = next[0] else {
        panic!("{:?}", next[0]);
    };
    assert_eq!(b.overruns, 0, "counted once");
    assert_eq!(sampler.totals().overruns, 4000);
}

#[test]
fn per_sample_a_restarts_gap_is_the_step_monitors_alone() {
    let (f, next, total) = per_sample_around(27, Sampler::chip_restarted);
    assert_eq!(f.overruns, 99);
    assert_eq!(next.overruns, 0);
    assert_eq!(total, 99);
}
