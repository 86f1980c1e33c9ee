//! `triad device info`: the identify reply, every field a line a person
//! reads (`name: value`, so a script can pick one with `grep`).

use std::time::Duration;

use triad::protocol::{DeviceInfo, Reply, StoredReason};

use super::link::LinkError;
use crate::plumbing::number::readable;
use crate::plumbing::stdio::outln;

/// The device description an identify reply carries.
pub fn parse(reply: &Reply) -> Result<DeviceInfo, LinkError> {
    let payload = reply.payload.as_slice();
    DeviceInfo::parse(payload).ok_or_else(|| LinkError::BadResult {
        command: "identify",
        reason: format!(
            "its {} bytes are not a protocol-2 device description (docs/PROTOCOL.md)",
            payload.len()
        ),
    })
}

/// `info` as lines, the link's `place` first.
pub fn render(info: &DeviceInfo, place: &str) -> String {
    let mut out = String::new();
    outln!(out, "link: {place}, protocol {}", info.protocol);
    outln!(out, "firmware: {}", info.firmware);
    outln!(out, "board: {}", info.board);
    outln!(out, "chip: {}", info.chip);
    outln!(out, "bus: {}", info.bus);
    let rate = f64::from(info.sample_rate_hz);
    outln!(out, "sample rate: {} Hz", readable(rate));
    outln!(
        out,
        "decimation: {} ({} frames/s)",
        info.decimation,
        readable(rate / f64::from(info.decimation.max(1)))
    );
    outln!(out, "mode: {}", info.mode);
    outln!(out, "baud: {}", info.baud);
    outln!(
        out,
        "calibration: {:#010x} ({})",
        info.calibration_id,
        info.calibration_source
    );
    match info.stored_reason {
        StoredReason::None => outln!(out, "stored: {}", info.stored),
        reason => outln!(out, "stored: {} ({reason})", info.stored),
    }
    outln!(out, "uptime: {}", uptime(info.uptime_ms));
    let c = &info.counters;
    outln!(out, "frames sent: {}", c.frames_sent);
    outln!(out, "frames dropped: {}", c.frames_dropped);
    outln!(out, "overruns: {}", c.overruns);
    outln!(out, "read failures: {}", c.read_failures);
    outln!(out, "commands: {}", c.commands);
    outln!(out, "command errors: {}", c.command_errors);
    outln!(out, "rx overflows: {}", c.rx_overflows);
    outln!(out, "sensor stalls: {}", c.sensor_stalls);
    outln!(out, "sensor restarts: {}", c.sensor_restarts);
    outln!(
        out,
        "sensor restart failures: {}",
        c.sensor_restart_failures
    );
    outln!(out, "flash stalls: {}", c.flash_stalls);
    let l = &info.load;
    // Each task's share, and its cycles per streamed frame (what a task
    // costs per sample with decimation 1).
    let frames_per_window = rate / f64::from(info.decimation.max(1)) * f64::from(l.window_cycles)
        / f64::from(l.cycles_hz.max(1));
    let share = |i: usize| {
        format!(
            "{:.3} % ({:.0} cycles/frame)",
            100.0 * l.share(i),
            f64::from(l.busy_cycles[i]) / frames_per_window.max(1.0)
        )
    };
    outln!(
        out,
        "load: data-ready {}, link {}, receive {}, chip model {}, idle {:.3} % (the last {:.2} s; cycles at {} Hz; the chip model is the emulated board's)",
        share(0),
        share(1),
        share(2),
        share(3),
        100.0 * l.idle_share(),
        f64::from(l.window_cycles) / f64::from(l.cycles_hz.max(1)),
        l.cycles_hz
    );
    outln!(
        out,
        "longest run: data-ready {} µs, link {} µs, receive {} µs, chip model {} µs (since start)",
        l.max_run_us[0],
        l.max_run_us[1],
        l.max_run_us[2],
        l.max_run_us[3]
    );
    let s = &info.scale;
    let r = |x: f32| readable(f64::from(x));
    outln!(
        out,
        "scale: accel {} m/s² per LSB, gyro {} rad/s per LSB, temperature {} °C per LSB + {} °C",
        r(s.accel_si_per_lsb),
        r(s.gyro_si_per_lsb),
        r(s.temperature_per_lsb),
        r(s.temperature_offset)
    );
    out
}

/// Milliseconds as `1 d 02:03:04.005` (days only when there are some).
fn uptime(ms: u32) -> String {
    let total = Duration::from_millis(u64::from(ms));
    let s = total.as_secs();
    let (days, h, m, sec) = (s / 86_400, s / 3600 % 24, s / 60 % 60, s % 60);
    let clock = format!("{h:02}:{m:02}:{sec:02}.{:03}", total.subsec_millis());
    if days > 0 {
        format!("{days} d {clock}")
    } else {
        clock
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uptime_reads_as_a_clock() {
        assert_eq!(uptime(0), "00:00:00.000");
        assert_eq!(uptime(3_723_004), "01:02:03.004");
        // The counter wraps at 2³² ms: 49 days 17:02:47.295.
        assert_eq!(uptime(u32::MAX), "49 d 17:02:47.295");
    }
}
