//! `triad correct` on a recording (a bag, MCAP, ULog, EuRoC, imu_tk): the
//! reader's samples go to the corrector as they are read, with no CSV text
//! in between, so every value is the record's own (an f64, rounded once to
//! f32 for the firmware's kernel) and every message names the sample by its
//! message or line and its time. Output: `t` and the triads the record has
//! (`t,ax,ay,az,gx,gy,gz[,temp]`), the time and temperature as read, the
//! corrected values in the shortest form that reads back to the same f32
//! (or f64).

use std::io::Write;

use anyhow::{anyhow, bail};
use triad::model::Corrector;

use super::{six, How, Outside};
use crate::plumbing::stdio;
use crate::record::{to_csv, Opened, Sample, Source};

/// Corrects every sample of `opened` into CSV rows on `out`.
pub(super) fn correct_record(
    opened: Opened,
    out: &mut impl Write,
    corrector: &mut Corrector,
    how: How,
) -> anyhow::Result<Outside> {
    let Opened { source, mut reader } = opened;
    let channels = source.channels;
    if !channels.gyro && !channels.accel {
        bail!(
            "{}: the record carries neither an accelerometer nor a gyroscope",
            source.name
        );
    }
    // The gyroscope's g-sensitivity term is applied with the accelerometer's
    // sample: without one, the gyro cannot be corrected as calibrated.
    if channels.gyro && !channels.accel && how.g_sensitivity {
        bail!(
            "{}: the record carries the gyroscope only, and the calibration's g-sensitivity (G) \
             needs the accelerometer's sample at each gyro sample: give a record with both triads",
            source.name
        );
    }
    writeln!(out, "{}", to_csv::header(channels)).map_err(stdio::stdout_error)?;
    let mut count = Outside::default();
    let mut folded_at: Option<f64> = None;
    while let Some(chunk) = reader.next_chunk()? {
        for s in &chunk {
            let temperature = temperature_of(&source, s, how)?;
            if let (Some(t), true) = (temperature, how.has_terms) {
                if folded_at != Some(t) {
                    corrector
                        .refold(t)
                        .map_err(|e| anyhow!("{}: {e}", source.where_is(s)))?;
                    folded_at = Some(t);
                }
            }
            let corrected = correct_sample(&source, corrector, s, temperature, how.exact)?;
            write_row(out, &source, s, &corrected).map_err(stdio::stdout_error)?;
            count.add(temperature, how.fitted_range);
        }
    }
    Ok(count)
}

/// The sample's temperature where the record has one: a missing (NaN) one is
/// an error only where temperature terms need it.
fn temperature_of(source: &Source, s: &Sample, how: How) -> anyhow::Result<Option<f64>> {
    if !source.channels.temp {
        return Ok(None);
    }
    if s.temp.is_finite() {
        return Ok(Some(s.temp));
    }
    if how.has_terms {
        bail!(
            "{}: the temperature is {}, and the calibration's temperature terms need it",
            source.where_is(s),
            s.temp
        );
    }
    Ok(None)
}

/// The six corrected values, as text (the f32 kernel's or the f64 reference's).
fn correct_sample(
    source: &Source,
    corrector: &Corrector,
    s: &Sample,
    temperature: Option<f64>,
    exact: bool,
) -> anyhow::Result<[String; 6]> {
    let values = six(s.accel, s.gyro);
    for (k, v) in values.iter().enumerate() {
        if present(source, k) && !v.is_finite() {
            bail!(
                "{}: {} = {v} is not a finite number",
                source.where_is(s),
                NAMES[k]
            );
        }
    }
    if exact {
        let m = corrector.reference_si(s.accel, s.gyro, temperature.unwrap_or(0.0));
        return Ok(six(m.accel, m.gyro).map(|v| v.to_string()));
    }
    let mut narrow = [0f32; 6];
    for (k, v) in values.iter().enumerate() {
        narrow[k] = *v as f32;
        if present(source, k) && !narrow[k].is_finite() {
            bail!(
                "{}: {} = {v} is beyond the f32 range",
                source.where_is(s),
                NAMES[k]
            );
        }
    }
    let [ax, ay, az, gx, gy, gz] = narrow;
    let m = corrector.correct_si(
        [ax, ay, az],
        [gx, gy, gz],
        temperature.unwrap_or(0.0) as f32,
    );
    Ok(six(m.accel, m.gyro).map(|v| v.to_string()))
}

/// The names of the six values, for messages.
const NAMES: [&str; 6] = ["ax", "ay", "az", "gx", "gy", "gz"];

/// Whether value `k` (0 = ax … 5 = gz) is in the record.
fn present(source: &Source, k: usize) -> bool {
    if k < 3 {
        source.channels.accel
    } else {
        source.channels.gyro
    }
}

/// One output row: `t`, the corrected triads the record has, its temperature.
fn write_row(
    out: &mut impl Write,
    source: &Source,
    s: &Sample,
    corrected: &[String; 6],
) -> std::io::Result<()> {
    write!(out, "{}", s.t)?;
    for (k, v) in corrected.iter().enumerate() {
        if present(source, k) {
            write!(out, ",{v}")?;
        }
    }
    if source.channels.temp {
        write!(out, ",{}", s.temp)?;
    }
    out.write_all(b"\n")
}
