//! docs/benchmarks.svg: maximum error against instructions per sample, one
//! panel per core, log-log, each variant a labelled point, the Pareto front
//! (no other variant both faster and more accurate) joined by a line.
//! Rendered by plotters' SVG backend (text stays text: no fonts needed).

use super::{Core, Row};
use plotters::prelude::*;

/// Errors below this (the f64 row: 0) are drawn at it.
const ERROR_FLOOR: f64 = 1e-4;
const PANEL: (u32, u32) = (640, 460);

/// The SVG document.
pub fn svg(rows: &[Row]) -> Result<String, Box<dyn std::error::Error>> {
    let mut out = String::new();
    {
        let size = (PANEL.0 * Core::ALL.len() as u32, PANEL.1);
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        root.fill(&WHITE)?;
        let panels = root.split_evenly((1, Core::ALL.len()));
        for (area, core) in panels.iter().zip(Core::ALL) {
            panel(area, rows, core)?;
        }
        root.present()?;
    }
    Ok(out)
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
pub fn front(points: &[(f64, f64, &'static str)]) -> Vec<(f64, f64)> {
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

fn decade_below(x: f64) -> f64 {
    10f64.powf(x.log10().floor())
}

fn decade_above(x: f64) -> f64 {
    10f64.powf(x.log10().ceil())
}

fn panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    rows: &[Row],
    core: Core,
) -> Result<(), Box<dyn std::error::Error>> {
    let pts = points(rows, core);
    if pts.is_empty() {
        return Ok(());
    }
    let x_lo = decade_below(pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min));
    let x_hi = decade_above(pts.iter().map(|p| p.0).fold(0.0, f64::max)) * 3.0;
    let y_hi = decade_above(pts.iter().map(|p| p.1).fold(1.0, f64::max));
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{}: max error vs cost", core.name()),
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x_lo..x_hi).log_scale(), (ERROR_FLOOR..y_hi).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("instructions per 6-axis sample")
        .y_desc("max error, LSB (realistic calibration)")
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .draw()?;
    chart
        .draw_series(LineSeries::new(front(&pts), RED.stroke_width(2)))?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
    chart.draw_series(pts.iter().map(|&(x, y, name)| {
        EmptyElement::at((x, y))
            + Circle::new((0, 0), 4, BLUE.filled())
            + Text::new(name, (6, -14), ("sans-serif", 12))
    }))?;
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::front;

    #[test]
    fn the_front_keeps_only_points_no_other_beats_in_both() {
        let pts = [
            (37.0, 130.0, "bias"),
            (37.0, 80.0, "diag"),
            (60.0, 0.008, "fusion"),
            (90.0, 0.005, "f32"),
            (340.0, 0.12, "stale"),
            (3900.0, 1e-4, "f64"),
        ];
        assert_eq!(
            front(&pts),
            vec![(37.0, 80.0), (60.0, 0.008), (90.0, 0.005), (3900.0, 1e-4)]
        );
    }
}
