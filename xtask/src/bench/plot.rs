//! docs/benchmarks.svg: maximum error against instructions per sample, one
//! panel per core, log-log, each variant a labelled point, the Pareto front
//! (no other variant both faster and more accurate) joined by a line.
//! Written as SVG text directly: a scatter of a dozen points needs no
//! plotting library, and text in SVG needs no font files at render time.

use super::{Core, Row};
use std::fmt::Write;

const PANEL_W: f64 = 520.0;
const PANEL_H: f64 = 380.0;
const MARGIN: f64 = 60.0;
/// Errors below this (the f64 row: 0) are drawn at it.
const ERROR_FLOOR: f64 = 1e-4;

/// The SVG document.
pub fn svg(rows: &[Row]) -> String {
    let width = MARGIN + Core::ALL.len() as f64 * (PANEL_W + MARGIN);
    let height = PANEL_H + 2.0 * MARGIN;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (n, core) in Core::ALL.into_iter().enumerate() {
        let x0 = MARGIN + n as f64 * (PANEL_W + MARGIN);
        panel(&mut s, rows, core, x0, MARGIN);
    }
    s.push_str("</svg>\n");
    s
}

/// The points of a core: (instructions, max error LSB, name).
fn points(rows: &[Row], core: Core) -> Vec<(f64, f64, &'static str)> {
    rows.iter()
        .filter(|r| r.core == core)
        .filter_map(|r| {
            let e = r.realistic?.max_lsb.max(ERROR_FLOOR);
            Some((r.instructions_per_sample, e, r.variant.name()))
        })
        .collect()
}

/// The Pareto front, by increasing instructions.
fn front(points: &[(f64, f64, &'static str)]) -> Vec<(f64, f64)> {
    let mut sorted: Vec<(f64, f64)> = points.iter().map(|p| (p.0, p.1)).collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut out: Vec<(f64, f64)> = Vec::new();
    for p in sorted {
        if out.last().is_none_or(|last| p.1 < last.1) {
            out.push(p);
        }
    }
    out
}

fn decades(lo: f64, hi: f64) -> (i32, i32) {
    (lo.log10().floor() as i32, hi.log10().ceil() as i32)
}

fn panel(s: &mut String, rows: &[Row], core: Core, x0: f64, y0: f64) {
    let pts = points(rows, core);
    if pts.is_empty() {
        return;
    }
    let (xl, xh) = decades(
        pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min),
        pts.iter().map(|p| p.0).fold(0.0, f64::max),
    );
    let (yl, yh) = decades(ERROR_FLOOR, pts.iter().map(|p| p.1).fold(1.0, f64::max));
    let px = |x: f64| x0 + (x.log10() - f64::from(xl)) / f64::from(xh - xl) * PANEL_W;
    let py = |y: f64| y0 + PANEL_H - (y.log10() - f64::from(yl)) / f64::from(yh - yl) * PANEL_H;
    let _ = writeln!(
        s,
        r##"<rect x="{x0}" y="{y0}" width="{PANEL_W}" height="{PANEL_H}" fill="none" stroke="#444"/>"##
    );
    for d in xl..=xh {
        let x = px(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{x}" y1="{y0}" x2="{x}" y2="{}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">1e{d}</text>"##,
            y0 + PANEL_H,
            y0 + PANEL_H + 15.0
        );
    }
    for d in yl..=yh {
        let y = py(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{x0}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">1e{d}</text>"##,
            x0 + PANEL_W,
            x0 - 5.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle" font-size="13">{}: max error (LSB, realistic calibration) vs instructions per 6-axis sample</text>"#,
        x0 + PANEL_W / 2.0,
        y0 - 12.0,
        core.name()
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">instructions per sample (log)</text>"#,
        x0 + PANEL_W / 2.0,
        y0 + PANEL_H + 32.0
    );
    let line: Vec<String> = front(&pts)
        .iter()
        .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
        .collect();
    let _ = writeln!(
        s,
        r##"<polyline points="{}" fill="none" stroke="#c33" stroke-width="2"/>"##,
        line.join(" ")
    );
    for (x, y, name) in &pts {
        let _ = writeln!(
            s,
            r##"<circle cx="{:.1}" cy="{:.1}" r="4" fill="#236"/><text x="{:.1}" y="{:.1}">{name}</text>"##,
            px(*x),
            py(*y),
            px(*x) + 6.0,
            py(*y) - 6.0
        );
    }
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{}" fill="#c33">Pareto front</text>"##,
        x0 + PANEL_W - 80.0,
        y0 + 15.0
    );
}
