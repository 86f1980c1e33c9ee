//! The header of the CSV and the columns analysed: which ones (`--columns`
//! or every `g…`/`a…` column), which triad each belongs to, and where each
//! row's cells go (the selected columns, then `t` when the sample rate comes
//! from it).

use anyhow::{anyhow, bail};
use triad::model::Triad;

/// A selected column: its header name, its index in a row, its triad.
#[derive(Clone, Debug, PartialEq)]
pub struct Selected {
    /// The header name.
    pub name: String,
    /// Its index among the row's cells.
    pub index: usize,
    /// Gyro (`g…`) or accelerometer (`a…`).
    pub triad: Triad,
}

/// The triad a column's name says: `g…` a gyro, `a…` an accelerometer.
pub fn triad_of(name: &str) -> Option<Triad> {
    match name.as_bytes().first() {
        Some(b'g') => Some(Triad::Gyro),
        Some(b'a') => Some(Triad::Accel),
        _ => None,
    }
}

/// The columns `wanted` (all `g…`/`a…` columns when None) of `header`.
pub fn select(header: &[&str], wanted: Option<&[String]>) -> anyhow::Result<Vec<Selected>> {
    match wanted {
        Some(names) => select_named(header, names),
        None => select_all(header),
    }
}

/// The columns of `--columns`, in its order; each named once.
fn select_named(header: &[&str], names: &[String]) -> anyhow::Result<Vec<Selected>> {
    let list = header.join(",");
    let mut out: Vec<Selected> = Vec::new();
    for name in names {
        let name = name.trim();
        let index = header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| anyhow!("unknown column \"{name}\" (the header has {list})"))?;
        let triad = triad_of(name).ok_or_else(|| {
            anyhow!("column \"{name}\": neither a gyro (g…) nor an accelerometer (a…) column")
        })?;
        if out.iter().any(|s| s.index == index) {
            bail!("column \"{name}\" is named twice in --columns");
        }
        out.push(Selected {
            name: name.to_string(),
            index,
            triad,
        });
    }
    Ok(out)
}

/// Every gyro and accelerometer column, in the header's order.
fn select_all(header: &[&str]) -> anyhow::Result<Vec<Selected>> {
    let out: Vec<Selected> = header
        .iter()
        .enumerate()
        .filter_map(|(index, h)| {
            triad_of(h).map(|triad| Selected {
                name: h.to_string(),
                index,
                triad,
            })
        })
        .collect();
    if out.is_empty() {
        bail!(
            "no gyro (g…) or accelerometer (a…) column in the header {}",
            header.join(",")
        );
    }
    Ok(out)
}

/// Where each row's cells go: slot k of a parsed row is selected column k,
/// and the last slot is `t` when the sample rate comes from it.
#[derive(Debug, PartialEq)]
pub struct Layout {
    /// The columns analysed.
    pub selected: Vec<Selected>,
    /// (cell index, slot), sorted by cell index.
    pub cells: Vec<(usize, usize)>,
    /// The name of each slot (for messages).
    pub names: Vec<String>,
    /// The slot of `t`, when the rate comes from it.
    pub t_slot: Option<usize>,
}

impl Layout {
    /// The layout of `header_line` for `--columns` (`wanted`); `t` is read
    /// when `rate_from_t`.
    pub fn new(
        header_line: &str,
        wanted: Option<&[String]>,
        rate_from_t: bool,
    ) -> anyhow::Result<Layout> {
        let header: Vec<&str> = header_line.split(',').map(str::trim).collect();
        let selected = select(&header, wanted)?;
        let t_index = header.iter().position(|h| *h == "t");
        if rate_from_t && t_index.is_none() {
            bail!("no t column to take the sample rate from; give --rate HZ");
        }
        let mut cells: Vec<(usize, usize)> = selected
            .iter()
            .enumerate()
            .map(|(slot, s)| (s.index, slot))
            .collect();
        let mut names: Vec<String> = selected.iter().map(|s| s.name.clone()).collect();
        let t_slot = rate_from_t.then_some(selected.len());
        if let (Some(slot), Some(index)) = (t_slot, t_index) {
            cells.push((index, slot));
            names.push("t".to_string());
        }
        cells.sort_unstable();
        Ok(Layout {
            selected,
            cells,
            names,
            t_slot,
        })
    }

    /// Values per parsed row.
    pub fn width(&self) -> usize {
        self.names.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: [&str; 8] = ["t", "ax", "ay", "az", "gx", "gy", "gz", "temp"];

    #[test]
    fn the_first_letter_names_the_triad() {
        assert_eq!(triad_of("gx"), Some(Triad::Gyro));
        assert_eq!(triad_of("a_z"), Some(Triad::Accel));
        assert_eq!(triad_of("temp"), None);
        assert_eq!(triad_of(""), None);
    }

    #[test]
    fn by_default_every_gyro_and_accel_column_is_selected() {
        let s = select(&HEADER, None).unwrap();
        let names: Vec<&str> = s.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["ax", "ay", "az", "gx", "gy", "gz"]);
        assert_eq!(s[3].index, 4);
        assert_eq!(s[3].triad, Triad::Gyro);
        let err = select(&["t", "temp"], None).unwrap_err().to_string();
        assert!(err.contains("no gyro (g…) or accelerometer"), "{err}");
    }

    #[test]
    fn named_columns_keep_their_order_and_are_checked() {
        let wanted = ["gz".to_string(), " ax ".to_string()];
        let s = select(&HEADER, Some(&wanted)).unwrap();
        assert_eq!((s[0].index, s[1].index), (6, 1));
        assert_eq!(s[1].name, "ax");
        let err = |w: &[&str]| {
            let w: Vec<String> = w.iter().map(|s| s.to_string()).collect();
            select(&HEADER, Some(&w)).unwrap_err().to_string()
        };
        assert!(err(&["gq"]).contains("unknown column \"gq\""));
        assert!(err(&["temp"]).contains("neither a gyro"));
        assert!(err(&["gx", "gx"]).contains("named twice"));
    }

    #[test]
    fn the_layout_puts_t_last_and_sorts_the_cells() {
        let wanted = ["gz".to_string(), "ax".to_string()];
        let l = Layout::new("t, ax,ay,az,gx,gy,gz", Some(&wanted), true).unwrap();
        assert_eq!(l.cells, [(0, 2), (1, 1), (6, 0)]);
        assert_eq!(l.names, ["gz", "ax", "t"]);
        assert_eq!((l.t_slot, l.width()), (Some(2), 3));
        let without_t = Layout::new("t,ax", None, false).unwrap();
        assert_eq!((without_t.t_slot, without_t.width()), (None, 1));
        let err = Layout::new("ax,gx", None, true).unwrap_err().to_string();
        assert!(err.contains("no t column"), "{err}");
    }
}
