//! The stream step: a few seconds of calibrated samples, checked for loss
//! four ways — the decoder's counters (CRC errors, malformed frames,
//! sequence gaps), the device's own counters before and after (overruns,
//! frames dropped, failed reads), and the samples themselves: as many rows
//! as their time span holds at the sample rate, so a sample lost before it
//! was framed shows too. That last count is judged on the emulated board
//! only, where the chip model and the timestamps run on one clock; on
//! hardware the chip's own oscillator sets its rate and the timestamps come
//! from the microcontroller's, which differ by the oscillators' tolerance,
//! so there it is reported, not judged.

use super::report::Step;
use super::triad_device::{Info, StreamSummary, TriadDevice};
use crate::board::Firmware;
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::time::Duration;

/// The device's counters that count a loss.
const DEVICE_LOSSES: [&str; 3] = ["overruns", "frames dropped", "read failures"];
/// The decoder's counters that count a loss.
const DECODER_LOSSES: [&str; 3] = ["crc errors", "malformed", "sequence gaps"];

/// Streams `seconds` from `device` and checks that nothing was lost.
pub fn run(device: &TriadDevice, firmware: Firmware, seconds: f64, dir: &Path) -> Step {
    let one_clock = firmware.board.is_emulated();
    let name = format!("stream {seconds} s ({}): nothing lost", firmware.label());
    match check(
        device,
        seconds,
        one_clock,
        &dir.join(format!("stream-{}.csv", firmware.stem())),
    ) {
        Ok((passed, detail, commands)) => Step {
            name,
            passed,
            detail,
            commands,
        },
        Err(e) => Step {
            name,
            passed: false,
            detail: vec![format!("{e:#}")],
            commands: vec![],
        },
    }
}

type Checked = (bool, Vec<String>, Vec<String>);

fn check(device: &TriadDevice, seconds: f64, one_clock: bool, csv: &Path) -> Result<Checked> {
    let (first, before) = device.info()?;
    let rate = before
        .number("sample rate")
        .filter(|&hz| hz > 0)
        .with_context(|| {
            format!(
                "identify gave no sample rate: `{}`",
                before.get("sample rate")
            )
        })?;
    if before.number("decimation") != Some(1) {
        bail!(
            "the device averages ({}): the check needs decimation 1",
            before.get("decimation")
        );
    }
    // The stream's own time bounds it; the limit only catches a silent device.
    let limit = Duration::from_secs_f64(seconds * 4.0 + 30.0);
    let s = seconds.to_string();
    let ran = device.run(&["stream", "--seconds", &s], Some(csv), limit)?;
    let (last, after) = device.info()?;
    let mut passed = ran.status.success();
    let mut detail = vec![];
    if !passed {
        detail.push(format!(
            "the stream exited {}: {}",
            ran.status,
            ran.stderr.trim()
        ));
    }
    let summary = StreamSummary::parse(&ran.stderr);
    for counter in DECODER_LOSSES {
        let n = summary.get(counter);
        passed &= n == Some(0);
        detail.push(format!("decoder {counter}: {}", shown(n)));
    }
    for counter in DEVICE_LOSSES {
        let n = difference(&before, &after, counter);
        passed &= n == Some(0);
        detail.push(format!("device {counter} during the stream: {}", shown(n)));
    }
    let text =
        std::fs::read_to_string(csv).with_context(|| format!("reading {}", csv.display()))?;
    let span = Span::of(&text).with_context(|| format!("the samples in {}", csv.display()))?;
    let expected = span.seconds * rate as f64 + 1.0;
    // Rows carry times rounded to the printed precision: half a sample of slack.
    let whole = (span.rows as f64 - expected).abs() <= 0.5;
    passed &= span.seconds >= seconds * 0.99;
    if one_clock {
        passed &= whole;
    }
    detail.push(format!(
        "{} samples over {:.6} s at {rate} Hz: {} expected{}",
        span.rows,
        span.seconds,
        expected.round(),
        match (whole, one_clock) {
            (true, _) => "",
            (false, true) => " — samples are missing",
            (false, false) => " (reported, not judged: the chip's clock is not the timestamps')",
        }
    ));
    detail.push(format!(
        "largest step between samples: {:.3} sample periods",
        span.largest_step * rate as f64
    ));
    detail.push(format!("load: {}", after.get("load")));
    detail.push(format!("longest run: {}", after.get("longest run")));
    Ok((passed, detail, vec![first.line, ran.line, last.line]))
}

fn difference(before: &Info, after: &Info, counter: &str) -> Option<u64> {
    after.number(counter)?.checked_sub(before.number(counter)?)
}

fn shown(n: Option<u64>) -> String {
    n.map(|n| n.to_string())
        .unwrap_or_else(|| "not reported".into())
}

/// The rows of a stream's CSV and the time they span.
struct Span {
    rows: usize,
    seconds: f64,
    largest_step: f64,
}

impl Span {
    /// Reads the `t` column of a CSV with a header.
    fn of(text: &str) -> Result<Span> {
        let mut lines = text.lines();
        let header = lines
            .next()
            .context("no header: the stream printed nothing")?;
        let column = header
            .split(',')
            .position(|c| c == "t")
            .with_context(|| format!("no `t` column in the header `{header}`"))?;
        let mut times = Vec::new();
        for (i, line) in lines.enumerate() {
            let cell = line.split(',').nth(column).unwrap_or("");
            let t: f64 = cell
                .parse()
                .with_context(|| format!("line {}: t = `{cell}` is not a number", i + 2))?;
            times.push(t);
        }
        let (Some(first), Some(last)) = (times.first(), times.last()) else {
            bail!("no samples");
        };
        let largest_step = times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        Ok(Span {
            rows: times.len(),
            seconds: last - first,
            largest_step,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_span_counts_rows_and_the_largest_step() {
        let span = Span::of("seq,t,ax\n0,0.000,1\n1,0.001,1\n2,0.003,1\n").unwrap();
        assert_eq!(span.rows, 3);
        assert!((span.seconds - 0.003).abs() < 1e-12);
        assert!((span.largest_step - 0.002).abs() < 1e-12);
    }

    #[test]
    fn a_stream_without_samples_or_times_is_an_error() {
        assert!(Span::of("").is_err());
        assert!(Span::of("seq,t\n").is_err());
        assert!(Span::of("seq,ax\n0,1\n").is_err());
        let bad = Span::of("seq,t\n0,zero\n").err().unwrap().to_string();
        assert!(bad.contains("line 2"), "{bad}");
    }
}
