//! The SVG plot of `triad allan`: log-log σ(τ) with confidence bars, one
//! colour per column, each fitted term as a dashed slope line labelled with
//! its value in data-sheet units, and the whole model as a thin solid line.
//! Hand-written SVG (no plotting dependency); axes on whole decades.

use std::fmt::Write as _;
use std::path::Path;

use triad_lab::allan::noise_terms::Term;

use crate::allan::{datasheet, ColumnResult};

const WIDTH: f64 = 1120.0;
const HEIGHT: f64 = 640.0;
const LEFT: f64 = 90.0;
const RIGHT: f64 = 400.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;
const COLOURS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
];

/// Log-log axes mapping.
struct Axes {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Axes {
    fn x(&self, tau: f64) -> f64 {
        LEFT + (tau.log10() - self.x0) / (self.x1 - self.x0) * (WIDTH - LEFT - RIGHT)
    }
    fn y(&self, dev: f64) -> f64 {
        HEIGHT - BOTTOM - (dev.log10() - self.y0) / (self.y1 - self.y0) * (HEIGHT - TOP - BOTTOM)
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Writes the plot of `columns` to `path`.
pub fn write_svg(path: &Path, columns: &[ColumnResult]) -> anyhow::Result<()> {
    std::fs::write(path, render(columns))?;
    Ok(())
}

/// The SVG text.
pub fn render(columns: &[ColumnResult]) -> String {
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for c in columns {
        for p in &c.points {
            xs.push(p.tau);
            for v in [p.avar.sqrt(), p.ci.0, p.ci.1] {
                if v > 0.0 && v.is_finite() {
                    ys.push(v);
                }
            }
        }
    }
    let range = |v: &[f64]| -> (f64, f64) {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0f64, f64::max);
        if !(lo.is_finite() && hi > 0.0) {
            return (0.0, 1.0);
        }
        let (a, b) = (lo.log10().floor(), hi.log10().ceil());
        (a, if b > a { b } else { a + 1.0 })
    };
    let (x0, x1) = range(&xs);
    let (y0, y1) = range(&ys);
    let ax = Axes { x0, x1, y0, y1 };
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(
        s,
        r#"<rect x="0" y="0" width="{WIDTH}" height="{HEIGHT}" fill="white"/>"#
    );
    let (pl, pr, pt, pb) = (LEFT, WIDTH - RIGHT, TOP, HEIGHT - BOTTOM);
    let _ = writeln!(
        s,
        r#"<defs><clipPath id="plot"><rect x="{pl}" y="{pt}" width="{}" height="{}"/></clipPath></defs>"#,
        pr - pl,
        pb - pt
    );
    // Decade grid and labels.
    for d in (x0 as i32)..=(x1 as i32) {
        let x = ax.x(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{pt}" x2="{x:.1}" y2="{pb}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">1e{d}</text>"##,
            pb + 18.0
        );
    }
    for d in (y0 as i32)..=(y1 as i32) {
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
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">averaging time τ (s)</text>"#,
        0.5 * (pl + pr),
        HEIGHT - 15.0
    );
    let units: Vec<&str> = {
        let mut u: Vec<&str> = columns.iter().map(|c| c.kind.si_unit()).collect();
        u.dedup();
        u
    };
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
    let mut legend_y = pt + 10.0;
    for (ci, col) in columns.iter().enumerate() {
        let colour = COLOURS[ci % COLOURS.len()];
        let _ = writeln!(s, r#"<g clip-path="url(#plot)">"#);
        for p in &col.points {
            let dev = p.avar.sqrt();
            if dev.is_nan() || dev <= 0.0 {
                continue;
            }
            let x = ax.x(p.tau);
            let lo = if p.ci.0 > 0.0 { ax.y(p.ci.0) } else { pb };
            let hi = ax.y(p.ci.1);
            let _ = writeln!(
                s,
                r#"<line x1="{x:.1}" y1="{lo:.1}" x2="{x:.1}" y2="{hi:.1}" stroke="{colour}"/><circle cx="{x:.1}" cy="{:.1}" r="2.5" fill="{colour}"/>"#,
                ax.y(dev)
            );
        }
        if let Some(fit) = &col.fit {
            let samples = 60;
            let tau_at = |i: usize| 10f64.powf(x0 + (x1 - x0) * i as f64 / samples as f64);
            let path = |f: &dyn Fn(f64) -> f64| -> String {
                let mut d = String::new();
                for i in 0..=samples {
                    let tau = tau_at(i);
                    let v = f(tau).sqrt().max(10f64.powf(y0 - 3.0));
                    let _ = write!(
                        d,
                        "{}{:.1},{:.1} ",
                        if i == 0 { "M" } else { "L" },
                        ax.x(tau),
                        ax.y(v)
                    );
                }
                d
            };
            let total = path(&|tau| fit.avar(tau));
            let _ = writeln!(
                s,
                r#"<path d="{total}" fill="none" stroke="{colour}" stroke-width="1" opacity="0.6"/>"#
            );
            for t in Term::ALL {
                let e = fit.term(t);
                if !(e.in_support && e.squared > 0.0) {
                    continue;
                }
                let d = path(&|tau| e.squared * t.basis(tau));
                let _ = writeln!(
                    s,
                    r#"<path d="{d}" fill="none" stroke="{colour}" stroke-dasharray="6 4" stroke-width="1.2"/>"#
                );
                // The label sits where the term makes the largest share of the model.
                let (mut best, mut share) = (tau_at(0), 0.0);
                for i in 0..=samples {
                    let tau = tau_at(i);
                    let f = e.squared * t.basis(tau) / fit.avar(tau);
                    if f > share {
                        (best, share) = (tau, f);
                    }
                }
                let y = ax.y((e.squared * t.basis(best)).sqrt()) - 6.0;
                let x = ax.x(best).clamp(pl + 4.0, pr - 40.0);
                let _ = writeln!(
                    s,
                    r#"<text x="{x:.1}" y="{:.1}" fill="{colour}" font-weight="bold">{} {}</text>"#,
                    y.clamp(pt + 12.0, pb - 4.0),
                    escape(&col.name),
                    t.symbol()
                );
            }
        }
        let _ = writeln!(s, "</g>");
        // Legend: the column and its fitted terms.
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{colour}"/><text x="{:.1}" y="{:.1}" font-weight="bold">{} ({})</text>"#,
            pr + 20.0,
            legend_y - 4.0,
            pr + 30.0,
            legend_y,
            escape(&col.name),
            escape(col.kind.si_unit())
        );
        legend_y += 16.0;
        if let Some(fit) = &col.fit {
            for t in Term::ALL {
                let e = fit.term(t);
                if !e.in_support || e.squared <= 0.0 {
                    continue;
                }
                let (f, unit) = datasheet(col.kind, t);
                let _ = writeln!(
                    s,
                    r#"<text x="{:.1}" y="{:.1}" fill="{colour}">{} = {:.3e} ± {:.1e} {} (slope {})</text>"#,
                    pr + 30.0,
                    legend_y,
                    t.symbol(),
                    e.value * f,
                    e.sigma * f,
                    escape(unit),
                    t.slope()
                );
                legend_y += 15.0;
            }
        }
        legend_y += 8.0;
    }
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" fill="#555">dashed: fitted terms; thin: their sum</text>"##,
        pr + 20.0,
        pb
    );
    s.push_str("</svg>\n");
    s
}
