//! `--plot`: log-log σ(τ) with confidence bars, one colour per column, each
//! fitted term as a dashed slope line labelled with its value in data-sheet
//! units, and the whole model as a thin solid line. Hand-written SVG (no
//! plotting dependency); axes on whole decades.

use std::fmt::Write as _;
use std::path::Path;

use triad_lab::allan::noise_terms::{NoiseFit, Term, TermEstimate};

use super::compute::ColumnResult;
use super::fit::{datasheet, si_unit};
use crate::plumbing::outfile::OutFile;

const WIDTH: f64 = 1120.0;
const HEIGHT: f64 = 640.0;
const LEFT: f64 = 90.0;
const RIGHT: f64 = 400.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;
/// The plot area's right edge (the legend is to its right).
const PLOT_RIGHT: f64 = WIDTH - RIGHT;
/// The plot area's bottom edge.
const PLOT_BOTTOM: f64 = HEIGHT - BOTTOM;
const COLOURS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
];
/// Points along a model line.
const LINE_POINTS: usize = 60;

/// Log-log axes mapping: the decades shown, x0..x1 (τ) and y0..y1 (σ).
struct Axes {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Axes {
    /// Whole decades around every τ and every positive finite σ and bound.
    fn around(columns: &[ColumnResult]) -> Axes {
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        for p in columns.iter().flat_map(|c| &c.points) {
            xs.push(p.tau);
            ys.extend(
                [p.avar.sqrt(), p.ci.0, p.ci.1]
                    .into_iter()
                    .filter(|v| *v > 0.0 && v.is_finite()),
            );
        }
        let (x0, x1) = decades(&xs);
        let (y0, y1) = decades(&ys);
        Axes { x0, x1, y0, y1 }
    }

    fn x(&self, tau: f64) -> f64 {
        LEFT + (tau.log10() - self.x0) / (self.x1 - self.x0) * (WIDTH - LEFT - RIGHT)
    }

    fn y(&self, dev: f64) -> f64 {
        HEIGHT - BOTTOM - (dev.log10() - self.y0) / (self.y1 - self.y0) * (HEIGHT - TOP - BOTTOM)
    }

    /// The i-th of the τ a model line is drawn through.
    fn tau_at(&self, i: usize) -> f64 {
        10f64.powf(self.x0 + (self.x1 - self.x0) * i as f64 / LINE_POINTS as f64)
    }
}

/// The whole decades (log10) around the values; 0..1 when there are none.
fn decades(v: &[f64]) -> (f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(0.0f64, f64::max);
    if !(lo.is_finite() && hi > 0.0) {
        return (0.0, 1.0);
    }
    let (a, b) = (lo.log10().floor(), hi.log10().ceil());
    (a, if b > a { b } else { a + 1.0 })
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Writes the plot of `columns` to `path`.
pub fn write_svg(path: &Path, columns: &[ColumnResult]) -> anyhow::Result<OutFile> {
    use std::io::Write as _;
    let mut out = OutFile::create(path)?;
    out.write_all(render(columns).as_bytes())
        .map_err(|e| out.error(e))?;
    Ok(out)
}

/// The SVG text.
pub fn render(columns: &[ColumnResult]) -> String {
    let ax = Axes::around(columns);
    let mut s = String::new();
    frame(&mut s, &ax);
    labels(&mut s, columns);
    let mut legend_y = TOP + 10.0;
    for (ci, col) in columns.iter().enumerate() {
        let colour = COLOURS[ci % COLOURS.len()];
        let _ = writeln!(s, r#"<g clip-path="url(#plot)">"#);
        points(&mut s, &ax, col, colour);
        if let Ok(fit) = &col.fit {
            model_lines(&mut s, &ax, col, fit, colour);
        }
        let _ = writeln!(s, "</g>");
        legend_y = legend(&mut s, col, colour, legend_y);
    }
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" fill="#555">dashed: fitted terms; thin: their sum</text>"##,
        PLOT_RIGHT + 20.0,
        PLOT_BOTTOM
    );
    s.push_str("</svg>\n");
    s
}

/// The document, the clip path, the decade grid and the plot's box.
fn frame(s: &mut String, ax: &Axes) {
    let (pl, pr, pt, pb) = (LEFT, PLOT_RIGHT, TOP, PLOT_BOTTOM);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(
        s,
        r#"<rect x="0" y="0" width="{WIDTH}" height="{HEIGHT}" fill="white"/>"#
    );
    let _ = writeln!(
        s,
        r#"<defs><clipPath id="plot"><rect x="{pl}" y="{pt}" width="{}" height="{}"/></clipPath></defs>"#,
        pr - pl,
        pb - pt
    );
    for d in (ax.x0 as i32)..=(ax.x1 as i32) {
        let x = ax.x(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{pt}" x2="{x:.1}" y2="{pb}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">1e{d}</text>"##,
            pb + 18.0
        );
    }
    for d in (ax.y0 as i32)..=(ax.y1 as i32) {
        let y = ax.y(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{pl}" y1="{y:.1}" x2="{pr}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">1e{d}</text>"##,
            pl - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<rect x="{pl}" y="{pt}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        pr - pl,
        pb - pt
    );
}

/// The axis labels (σ in the columns' units) and the title.
fn labels(s: &mut String, columns: &[ColumnResult]) {
    let (pl, pr, pt, pb) = (LEFT, PLOT_RIGHT, TOP, PLOT_BOTTOM);
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">averaging time τ (s)</text>"#,
        0.5 * (pl + pr),
        HEIGHT - 15.0
    );
    let mut units: Vec<&str> = columns.iter().map(|c| si_unit(c.triad)).collect();
    units.dedup();
    let _ = writeln!(
        s,
        r#"<text x="20" y="{:.1}" text-anchor="middle" transform="rotate(-90 20 {:.1})">Allan deviation σ(τ) ({})</text>"#,
        0.5 * (pt + pb),
        0.5 * (pt + pb),
        escape(&units.join(", "))
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="24" text-anchor="middle" font-size="14">Overlapping Allan deviation with confidence intervals and fitted noise terms</text>"#,
        0.5 * (pl + pr)
    );
}

/// Each point of a column with its confidence bar.
fn points(s: &mut String, ax: &Axes, col: &ColumnResult, colour: &str) {
    for p in &col.points {
        let dev = p.avar.sqrt();
        if dev.is_nan() || dev <= 0.0 {
            continue;
        }
        let x = ax.x(p.tau);
        let lo = if p.ci.0 > 0.0 {
            ax.y(p.ci.0)
        } else {
            PLOT_BOTTOM
        };
        let hi = ax.y(p.ci.1);
        let _ = writeln!(
            s,
            r#"<line x1="{x:.1}" y1="{lo:.1}" x2="{x:.1}" y2="{hi:.1}" stroke="{colour}"/><circle cx="{x:.1}" cy="{:.1}" r="2.5" fill="{colour}"/>"#,
            ax.y(dev)
        );
    }
}

/// The path of σ(τ) = √avar(τ) across the plot (floored three decades below it).
fn model_path(ax: &Axes, avar: &dyn Fn(f64) -> f64) -> String {
    let mut d = String::new();
    for i in 0..=LINE_POINTS {
        let tau = ax.tau_at(i);
        let v = avar(tau).sqrt().max(10f64.powf(ax.y0 - 3.0));
        let _ = write!(
            d,
            "{}{:.1},{:.1} ",
            if i == 0 { "M" } else { "L" },
            ax.x(tau),
            ax.y(v)
        );
    }
    d
}

/// The fitted model (thin) and each reported (significant) term (dashed, labelled).
fn model_lines(s: &mut String, ax: &Axes, col: &ColumnResult, fit: &NoiseFit, colour: &str) {
    let total = model_path(ax, &|tau| fit.avar(tau));
    let _ = writeln!(
        s,
        r#"<path d="{total}" fill="none" stroke="{colour}" stroke-width="1" opacity="0.6"/>"#
    );
    for t in Term::ALL {
        let e = fit.term(t);
        if !(e.significant && e.squared > 0.0) {
            continue;
        }
        let d = model_path(ax, &|tau| e.squared * t.basis(tau));
        let _ = writeln!(
            s,
            r#"<path d="{d}" fill="none" stroke="{colour}" stroke-dasharray="6 4" stroke-width="1.2"/>"#
        );
        let best = label_tau(ax, fit, t, e);
        let y = ax.y((e.squared * t.basis(best)).sqrt()) - 6.0;
        let x = ax.x(best).clamp(LEFT + 4.0, PLOT_RIGHT - 40.0);
        let _ = writeln!(
            s,
            r#"<text x="{x:.1}" y="{:.1}" fill="{colour}" font-weight="bold">{} {}</text>"#,
            y.clamp(TOP + 12.0, PLOT_BOTTOM - 4.0),
            escape(&col.name),
            t.symbol()
        );
    }
}

/// Where a term's label sits: the τ where it makes the largest share of the model.
fn label_tau(ax: &Axes, fit: &NoiseFit, t: Term, e: &TermEstimate) -> f64 {
    let (mut best, mut share) = (ax.tau_at(0), 0.0);
    for i in 0..=LINE_POINTS {
        let tau = ax.tau_at(i);
        let f = e.squared * t.basis(tau) / fit.avar(tau);
        if f > share {
            (best, share) = (tau, f);
        }
    }
    best
}

/// The legend of a column (its name, unit and fitted terms) from `y` down;
/// returns where the next column's starts.
fn legend(s: &mut String, col: &ColumnResult, colour: &str, mut y: f64) -> f64 {
    let _ = writeln!(
        s,
        r#"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{colour}"/><text x="{:.1}" y="{:.1}" font-weight="bold">{} ({})</text>"#,
        PLOT_RIGHT + 20.0,
        y - 4.0,
        PLOT_RIGHT + 30.0,
        y,
        escape(&col.name),
        escape(si_unit(col.triad))
    );
    y += 16.0;
    let fitted = Term::ALL
        .into_iter()
        .filter_map(|t| Some((t, col.fit.as_ref().ok()?.term(t))))
        // As drawn before: a NaN estimate is listed (it shows as NaN).
        .filter(|(_, e)| e.significant && (e.squared > 0.0 || e.squared.is_nan()));
    for (t, e) in fitted {
        let (f, unit) = datasheet(col.triad, t);
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" fill="{colour}">{} = {:.3e} ± {:.1e} {} (slope {})</text>"#,
            PLOT_RIGHT + 30.0,
            y,
            t.symbol(),
            e.value * f,
            e.sigma * f,
            escape(unit),
            t.slope()
        );
        y += 15.0;
    }
    y + 8.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::table::tests::column;
    use triad::model::Triad;

    #[test]
    fn decades_enclose_the_values() {
        assert_eq!(decades(&[0.02, 30.0]), (-2.0, 2.0));
        assert_eq!(decades(&[10.0]), (1.0, 2.0));
        assert_eq!(decades(&[]), (0.0, 1.0));
    }

    #[test]
    fn the_axes_map_decades_onto_the_plot_area() {
        let ax = Axes {
            x0: -1.0,
            x1: 1.0,
            y0: 0.0,
            y1: 2.0,
        };
        assert_eq!(ax.x(0.1), LEFT);
        assert_eq!(ax.x(10.0), PLOT_RIGHT);
        assert_eq!(ax.y(1.0), PLOT_BOTTOM);
        assert!((ax.y(100.0) - TOP).abs() < 1e-9);
        assert!((ax.tau_at(LINE_POINTS) - 10.0).abs() < 1e-12);
    }

    #[test]
    fn the_svg_has_every_column_escaped_and_closes() {
        let svg = render(&[column("g<x>", Triad::Gyro), column("az", Triad::Accel)]);
        assert!(svg.starts_with("<svg xmlns="));
        assert!(svg.ends_with("</svg>\n"));
        assert!(svg.contains("g&lt;x&gt; (rad/s)"));
        assert!(svg.contains("az (m/s^2)"));
        assert!(
            svg.contains("(rad/s, m/s^2)"),
            "the σ axis names both units"
        );
        // Two points per column, each a bar and a dot.
        assert_eq!(svg.matches("<circle cx=").count(), 4 + 2);
        assert_eq!(svg.matches("<g clip-path").count(), 2);
    }
}
