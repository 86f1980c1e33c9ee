//! Sensor faults on the emulated board, end to end: the firmware on QEMU
//! behind `xtask serve --deterministic --fault SPEC`, its stream read with
//! the host's transport. Each fault is shown twice in one run: for 0.4 s
//! from 0.3 s of device time (the firmware must notice, count what was lost
//! and bring the chip back), then from 1.2 s to the end (while it lasts,
//! `identify` must answer, its counters saying what happened).
//!
//! What every case checks on the stream: no frame lost on the wire
//! (consecutive sequence numbers), and every data-ready period accounted
//! for: the gap between two frames, in periods, is the later frame's
//! `overruns` + 1, with OVERRUN set when it is not 0. Then the counters the
//! fault must leave: stalls, restarts, read failures, and the steps lost
//! across the fault's window.
//!
//! Run by `cargo xtask test` (it sets TRIAD_SERVE_XTASK and
//! TRIAD_SERVE_ELF); ignored in a plain `cargo test`.

// Shared with the other tests on the served board: this one uses a part.
#[allow(dead_code)]
mod served_board;

use std::time::{Duration, Instant};

use served_board::{test_dir, Clock, ServedBoard};
use triad::protocol::{BatchFrame, CalibrationSource, Command, Counters, Packet, Status};
use triad::protocol::{Flags, Frame};
use triad_host::device::identify;
use triad_host::device::link::{Link, LinkError};

/// The first window: from 0.3 s for 0.4 s of device time.
const WINDOW_START_S: f64 = 0.3;
const WINDOW_S: f64 = 0.4;
/// The fault again from here to the end of the run.
const FOREVER_FROM_S: f64 = 1.2;
/// The firmware checks a silent sensor every 50 ms
/// (`triad::device::sensor_health::STALL_US`).
const CHECK_S: f64 = 0.05;
/// How long the stream may be silent (wall time) before the run is taken
/// to have stopped: far more than a frame takes on a loaded machine.
const SILENCE: Duration = Duration::from_secs(20);
/// The longest a whole run may take.
const RUN_TIMEOUT: Duration = Duration::from_secs(90);

/// What a run showed: every frame read, and the counters `identify` gave.
struct Run {
    frames: Vec<Frame>,
    counters: Counters,
    period_us: f64,
    log: String,
}

/// Serves the firmware with `faults` and reads frames until one at
/// `until_s` of device time; then asks `identify` until its counters are
/// `ready` (the fault under way has shown), within [`RUN_TIMEOUT`].
fn serve_and_read(
    name: &str,
    faults: &[String],
    until_s: f64,
    ready: impl Fn(&Counters) -> bool,
) -> Run {
    let d = test_dir(name);
    let board =
        ServedBoard::start_with_faults(&d.join("storage.bin"), Clock::Deterministic, faults);
    let mut link = board.link();
    let started = Instant::now();
    let mut frames: Vec<Frame> = Vec::new();
    while frames
        .last()
        .is_none_or(|f| f64::from(f.timestamp_us) * 1e-6 < until_s)
    {
        match link
            .next_packet(Instant::now() + SILENCE)
            .expect("reading the port")
        {
            Some(Ok(Packet::Data(frame))) => frames.push(frame),
            Some(Ok(_)) => {}
            Some(Err(e)) => assert!(frames.is_empty(), "{name}: a damaged packet: {e:?}"),
            None => panic!(
                "{name}: the stream stopped at {:?} s, before {until_s} s; serve's log:\n{}",
                frames.last().map(|f| f64::from(f.timestamp_us) * 1e-6),
                board.log()
            ),
        }
    }
    loop {
        let info = identify(&mut link).unwrap_or_else(|e| {
            panic!(
                "{name}: identify during the fault: {e}; serve's log:\n{}",
                board.log()
            )
        });
        if ready(&info.counters) {
            return Run {
                frames,
                counters: info.counters,
                period_us: 1e6 / f64::from(info.sample_rate_hz),
                log: board.log(),
            };
        }
        assert!(
            started.elapsed() < RUN_TIMEOUT,
            "{name}: counters {:?} after {RUN_TIMEOUT:?}; serve's log:\n{}",
            info.counters,
            board.log()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// `KIND@0.3+0.4` and `KIND@1.2`.
fn twice(kind: &str) -> Vec<String> {
    vec![
        format!("{kind}@{WINDOW_START_S}+{WINDOW_S}"),
        format!("{kind}@{FOREVER_FROM_S}"),
    ]
}

/// Serves the FIFO firmware (8 kHz, a batch per 32 samples) with `faults`
/// and reads batches until one at `until_s` of device time; the board and
/// its link stay open for `identify`.
fn serve_fifo_batches(
    name: &str,
    faults: &[String],
    until_s: f64,
) -> (
    ServedBoard,
    Link<Box<dyn serialport::SerialPort>>,
    Vec<BatchFrame>,
) {
    let elf = served_board::env_path("TRIAD_FAULTS_FIFO_ELF");
    let d = test_dir(name);
    let board = ServedBoard::start_elf_with_faults(
        &elf,
        &d.join("storage.bin"),
        Clock::Deterministic,
        faults,
    );
    let mut link = board.link();
    let mut batches: Vec<BatchFrame> = Vec::new();
    while batches
        .last()
        .is_none_or(|f| f64::from(f.timestamp_us) * 1e-6 < until_s)
    {
        match link
            .next_packet(Instant::now() + SILENCE)
            .expect("reading the port")
        {
            Some(Ok(Packet::Batch(frame))) => batches.push(frame),
            Some(Ok(_)) => {}
            Some(Err(e)) => assert!(batches.is_empty(), "{name}: a damaged packet: {e:?}"),
            None => panic!("{name}: the stream stopped; serve's log:\n{}", board.log()),
        }
    }
    (board, link, batches)
}

impl Run {
    /// Checks that every period between two frames is a frame or a counted
    /// lost step, and no frame was lost on the wire; returns the steps lost
    /// the frames report in all.
    fn accounted(&self, name: &str) -> u64 {
        assert!(
            self.frames.len() > 200,
            "{name}: {} frames",
            self.frames.len()
        );
        let mut lost = 0;
        for pair in self.frames.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            assert_eq!(
                b.sequence,
                a.sequence + 1,
                "{name}: a frame lost on the wire"
            );
            let gap_us = f64::from(b.timestamp_us.wrapping_sub(a.timestamp_us));
            let periods = (gap_us / self.period_us).round() as u64;
            assert_eq!(
                periods,
                u64::from(b.overruns) + 1,
                "{name}: {gap_us} µs between frames {} and {} but {} steps counted lost",
                a.sequence,
                b.sequence,
                b.overruns
            );
            assert_eq!(
                b.flags.contains(Flags::OVERRUN),
                b.overruns > 0,
                "{name}: frame {} flags {:?} with {} lost",
                b.sequence,
                b.flags,
                b.overruns
            );
            lost += u64::from(b.overruns);
        }
        lost
    }

    /// The steps the frame after the first window reports lost.
    fn lost_across_window(&self, name: &str) -> u64 {
        let start_us = (WINDOW_START_S * 1e6) as u32;
        let after = self
            .frames
            .iter()
            .find(|f| f.timestamp_us >= start_us)
            .unwrap_or_else(|| panic!("{name}: no frame after {WINDOW_START_S} s"));
        u64::from(after.overruns)
    }

    /// Periods in `seconds`.
    fn periods(&self, seconds: f64) -> u64 {
        (seconds * 1e6 / self.period_us).round() as u64
    }
}

/// A fault that silences data-ready: the window's steps are lost (at least
/// the window, at most a check more for a chip the firmware must bring
/// back), counted in frames and counters alike; two stalls.
fn silenced(name: &str, kind: &str, needs_restart: bool) -> Run {
    // Frames run to the endless fault; identify answers once it has stalled.
    let until = FOREVER_FROM_S - 0.05;
    let run = serve_and_read(name, &twice(kind), until, |c| c.sensor_stalls >= 2);
    let lost = run.accounted(name);
    let across = run.lost_across_window(name);
    let window = run.periods(WINDOW_S);
    let most = window
        + if needs_restart {
            run.periods(CHECK_S) + 2
        } else {
            1
        };
    assert!(
        (window - 1..=most).contains(&across),
        "{name}: {across} steps lost across the {WINDOW_S} s window ({window} periods; at most {most})"
    );
    let c = run.counters;
    println!(
        "{name}: {} frames; {across} steps lost across the window, {lost} in all; counters {c:?}",
        run.frames.len()
    );
    assert_eq!(c.overruns as u64, lost, "{name}: {c:?}");
    assert_eq!(
        c.sensor_stalls, 2,
        "{name}: the window's and the endless one: {c:?}"
    );
    assert_eq!(c.read_failures, 0, "{name}: {c:?}");
    assert_eq!(c.frames_dropped, 0, "{name}: {c:?}");
    run
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_chip_that_vanishes_is_found_again_when_it_comes_back() {
    let run = silenced("vanish", "vanish", true);
    // Its checks during the window fail (it reads 0xFF); the first after
    // brings it back; in the endless fault none can.
    assert_eq!(run.counters.sensor_restarts, 1, "{:?}", run.counters);
    assert!(run.log.contains("sensor restarted"), "{}", run.log);
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_chip_back_from_a_brown_out_is_configured_again() {
    // Back at its power-on registers the chip samples nothing: frames after
    // the window prove the firmware configured it again.
    let run = silenced("brownout", "brownout", true);
    assert_eq!(run.counters.sensor_restarts, 1, "{:?}", run.counters);
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_chip_whose_output_stops_is_restarted_until_it_samples_again() {
    // It answers on the bus, so every check (every 50 ms) restarts it.
    let run = silenced("stop", "stop", true);
    let checks = (WINDOW_S / CHECK_S) as u32;
    assert!(
        run.counters.sensor_restarts >= checks,
        "{checks} checks in the window: {:?}",
        run.counters
    );
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_data_ready_line_held_high_is_a_stall_detected_and_reported() {
    // EXTI is edge-triggered: a line held high brings no edge. The chip is
    // fine, so data-ready comes back with the line, at the window's end.
    let run = silenced("drdy-high", "drdy-high", false);
    assert!(run.counters.sensor_restarts >= (WINDOW_S / CHECK_S) as u32);
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_silent_data_ready_line_is_a_stall_detected_and_reported() {
    let run = silenced("drdy-silent", "drdy-silent", false);
    assert!(run.counters.sensor_restarts >= (WINDOW_S / CHECK_S) as u32);
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_nack_storm_costs_one_step_and_one_read_failure_per_failed_transaction() {
    // 30 failed reads (one transaction each): no stall, no restart (that
    // takes 50 ms of failures), and each a step lost in the next frame.
    let storm = 30;
    let faults = vec![format!("nack@{WINDOW_START_S}*{storm}")];
    let run = serve_and_read("nack", &faults, WINDOW_START_S + 0.2, |_| true);
    let lost = run.accounted("nack");
    assert_eq!(run.lost_across_window("nack"), storm);
    let c = run.counters;
    println!("nack: {} frames; counters {c:?}", run.frames.len());
    assert_eq!(c.read_failures as u64, storm, "{c:?}");
    assert_eq!(c.overruns as u64, lost, "{c:?}");
    assert_eq!(
        (
            c.sensor_stalls,
            c.sensor_restarts,
            c.sensor_restart_failures
        ),
        (0, 0, 0),
        "{c:?}"
    );

    // A storm without end: reads fail every step, the firmware restarts
    // the chip after each 50 ms of them (each attempt failing too), and
    // the link answers all the while.
    let faults = vec![format!("nack@{FOREVER_FROM_S}*4000000000")];
    let until = FOREVER_FROM_S - 0.05;
    // Answered while 50 ms of failed reads went by: a restart was tried.
    let failures = (CHECK_S * 1000.0) as u32;
    let run = serve_and_read("nack-endless", &faults, until, |c| {
        c.read_failures > failures
    });
    let c = run.counters;
    println!("nack-endless: counters {c:?}");
    assert_eq!((c.sensor_stalls, c.sensor_restarts), (0, 0), "{c:?}");
    assert!(c.sensor_restart_failures >= 1, "{c:?}");
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_nack_storm_in_fifo_mode_fails_reads_then_the_restarts_it_outlasts() {
    // The chip's FIFO at 8 kHz, a read every 32 samples (4 ms): 50 ms of
    // failed reads is 13 in a row, after which the firmware tries a restart.
    // A storm of 30 failed transactions: 13 reads, a restart (failing at its
    // first transaction), 13 reads, a restart, 2 reads; then the FIFO is read
    // again. Each restart tried counts the gap since the newest sample read
    // as lost, so the batches account for every period.
    let storm = 30;
    let faults = [format!("nack@{WINDOW_START_S}*{storm}")];
    let (_board, mut link, batches) =
        serve_fifo_batches("nack-fifo", &faults, WINDOW_START_S + 0.4);
    let info = identify(&mut link).expect("identify after the storm");
    let period_us = 1e6 / f64::from(info.sample_rate_hz);
    // Every period between two batches' first samples is a sample the
    // earlier carried or a step the later reported lost.
    for pair in batches.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        assert_eq!(b.sequence, a.sequence + 1, "a batch lost on the wire");
        let periods = (f64::from(b.timestamp_us.wrapping_sub(a.timestamp_us)) / period_us).round();
        assert_eq!(
            periods as u64,
            u64::from(a.count) + u64::from(b.overruns),
            "unexplained gap between batches {} and {}",
            a.sequence,
            b.sequence
        );
    }
    let lost: u64 = batches.iter().map(|f| u64::from(f.overruns)).sum();
    let c = info.counters;
    println!(
        "nack-fifo: {} batches, {lost} samples lost; counters {c:?}",
        batches.len()
    );
    assert_eq!(
        (c.read_failures, c.sensor_restart_failures),
        (28, 2),
        "{c:?}"
    );
    assert_eq!((c.sensor_stalls, c.sensor_restarts), (0, 0), "{c:?}");
    assert_eq!(u64::from(c.overruns), lost, "{c:?}");
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn an_impossible_fifo_count_flushes_the_fifo_and_counts_its_watermark_lost() {
    // The chip's FIFO at 8 kHz, an interrupt per 32 samples (every 4 ms):
    // for 0.1 s the count reads 4095 records where the FIFO holds 128. Each
    // such interrupt, the driver reads no data, flushes the FIFO and reports
    // at least the watermark lost: the next batch is flagged FIFO_OVERFLOW
    // and counts it. Then the count is impossible to the end: no sample
    // comes, the link answers, the losses mount.
    let faults = [
        format!("fifo-count@{WINDOW_START_S}+0.1"),
        format!("fifo-count@{FOREVER_FROM_S}"),
    ];
    let (_board, mut link, batches) =
        serve_fifo_batches("fifo-count", &faults, FOREVER_FROM_S - 0.05);
    let watermark = 32;
    let window = |f: &&BatchFrame| {
        let t = f64::from(f.timestamp_us) * 1e-6;
        (WINDOW_START_S..WINDOW_START_S + 0.2).contains(&t)
    };
    let flagged: Vec<&BatchFrame> = batches
        .iter()
        .filter(|f| f.flags.contains(Flags::FIFO_OVERFLOW))
        .collect();
    let lost: u64 = batches.iter().map(|f| u64::from(f.overruns)).sum();
    // 0.1 s of 4 ms interrupts: 25, one either way for where they fall.
    let interrupts = lost / watermark;
    println!(
        "fifo-count: {} batches, {} flagged FIFO_OVERFLOW, {lost} samples counted lost",
        batches.len(),
        flagged.len()
    );
    assert_eq!(lost % watermark, 0, "a watermark per flush: {lost}");
    assert!((24..=26).contains(&interrupts), "{interrupts} flushes");
    assert!(
        !flagged.is_empty() && flagged.iter().all(window),
        "flagged outside the window"
    );
    for pair in batches.windows(2) {
        assert_eq!(
            pair[1].sequence,
            pair[0].sequence + 1,
            "a batch lost on the wire"
        );
    }
    let ready = |c: &Counters| u64::from(c.overruns) > lost + 50 * watermark;
    let started = Instant::now();
    let c = loop {
        let c = identify(&mut link)
            .expect("identify during the fault")
            .counters;
        if ready(&c) {
            break c;
        }
        assert!(started.elapsed() < RUN_TIMEOUT, "{c:?}");
        std::thread::sleep(Duration::from_millis(50));
    };
    println!("fifo-count: counters {c:?}");
    assert_eq!(
        (c.read_failures, c.sensor_stalls, c.sensor_restarts),
        (0, 0, 0),
        "{c:?}"
    );
    assert_eq!(u64::from(c.overruns) % watermark, 0, "{c:?}");
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_chip_absent_at_start_leaves_the_board_answering_and_looking() {
    // No chip ever: the board comes up all the same, says chip "none" in
    // identify, refuses what needs the chip saying so, streams nothing and
    // keeps looking (its log counts the looks: 1, 2, 4, ... logged), with
    // what the bus answered (SPI: 0xFF, nothing drives MISO).
    let d = test_dir("absent");
    let faults = ["vanish@0".to_string()];
    let board =
        ServedBoard::start_with_faults(&d.join("storage.bin"), Clock::Deterministic, &faults);
    let mut link = board.link();
    let info = identify(&mut link)
        .unwrap_or_else(|e| panic!("identify without a chip: {e}; log:\n{}", board.log()));
    assert_eq!(info.chip.as_str(), "none", "{info:?}");
    assert_eq!(info.sample_rate_hz, 0.0, "{info:?}");
    assert_eq!(info.calibration_source, CalibrationSource::None, "{info:?}");
    match link.command(&Command::SetDecimation(2)) {
        Err(LinkError::Refused { status, reason, .. }) => {
            assert_eq!(status, Status::SensorError);
            assert!(reason.contains("no sensor"), "{reason}");
        }
        other => panic!("decimation without a chip: {other:?}"),
    }
    let started = Instant::now();
    let c = loop {
        let c = identify(&mut link)
            .expect("identify without a chip")
            .counters;
        if board.log().contains("(look 8)") {
            break c;
        }
        assert!(
            started.elapsed() < RUN_TIMEOUT,
            "{c:?}; log:\n{}",
            board.log()
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    println!("absent: counters {c:?}");
    assert_eq!(c.frames_sent, 0, "{c:?}");
    assert_eq!(
        (
            c.sensor_stalls,
            c.sensor_restarts,
            c.read_failures,
            c.overruns
        ),
        (0, 0, 0, 0),
        "{c:?}"
    );
    // identify, decimation (refused), and the identifies since.
    assert_eq!(c.command_errors, 1, "{c:?}");
    let log = board.log();
    assert!(
        log.contains("no known IMU on the bus (look 1)") && log.contains("Some(255)"),
        "{log}"
    );
}

#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn a_chip_that_comes_after_start_up_is_found_and_streams() {
    // The chip is off the bus for the first 0.5 s of device time: the
    // firmware finds it at its next look (within 50 ms), starts it, and the
    // stream begins then, from sequence 0, every period a frame.
    let absent_s = 0.5;
    let faults = [format!("vanish@0+{absent_s}")];
    let until = absent_s + 0.4;
    let run = serve_and_read("late", &faults, until, |_| true);
    let first = &run.frames[0];
    let first_s = f64::from(first.timestamp_us) * 1e-6;
    assert_eq!(first.sequence, 0, "{first:?}");
    assert!(
        (absent_s..absent_s + CHECK_S + 0.01).contains(&first_s),
        "the first frame at {first_s} s; log:\n{}",
        run.log
    );
    let lost = run.accounted("late");
    let c = run.counters;
    println!(
        "late: {} frames from {first_s} s; counters {c:?}",
        run.frames.len()
    );
    assert_eq!(lost, 0, "{c:?}");
    // Found by its identity and configured once; it never stalled.
    assert_eq!(
        (
            c.sensor_restarts,
            c.sensor_stalls,
            c.read_failures,
            c.overruns
        ),
        (1, 0, 0, 0),
        "{c:?}"
    );
    assert!(
        run.log.contains("sensor found after start-up"),
        "{}",
        run.log
    );
}
