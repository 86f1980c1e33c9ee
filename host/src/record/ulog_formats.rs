//! What px4-ulog 0.6.1's flattening of a ULog's formats will cost, worked
//! out from the format messages ('F') before the parser sees the data
//! section: it expands every format into one field per leaf, recursively
//! (file_reader.rs `flatten_format`), with no bound but a message's 65 535
//! bytes, which a format of no bytes escapes. A few dozen bytes of formats
//! (`e:`, `b:e[32767] x;`, `a:b[32767] y;`) make it loop 10⁹ times, a
//! chain of nested formats with long field names makes it allocate tens of
//! GiB, a chain thousands deep overflows its stack: a hang, or the end of
//! the process. The parsing here follows the crate's (`parse_format`); a
//! format it would refuse is left to it to refuse.

use std::collections::HashMap;

/// The most formats nested in one another that triad reads (PX4 nests 2
/// or 3; the crate recurses once per level, on the reading thread's stack).
pub const MAX_DEPTH: u32 = 64;

/// The most work flattening may take: leaves made plus their names'
/// bytes, summed over every format (as the crate flattens each) and every
/// subscription ('A', which copies its format's fields). The PX4 log of
/// the fixtures (host/tests/fixtures/recordings/px4_sample_log_small.ulg)
/// needs 58 227, about 1/144 of this; a file of formats needing 12.7 M
/// took the crate 0.2 s and 90 MB (`triad allan`, debug build).
pub const MAX_WORK: u64 = 8 << 20;

/// A field of a format: its type's name, how many (1 when not an array),
/// its name.
struct Field {
    kind: String,
    count: u64,
    name: String,
}

/// What flattening a format makes.
#[derive(Clone, Copy, Default)]
struct Cost {
    /// Fields made (one per leaf).
    leaves: u64,
    /// Bytes of their names, without a prefix.
    name_bytes: u64,
    /// Nested formats entered.
    steps: u64,
    /// Formats nested below it.
    depth: u32,
}

impl Cost {
    fn work(&self) -> u64 {
        self.leaves
            .saturating_add(self.name_bytes)
            .saturating_add(self.steps)
    }
}

/// The formats seen so far and the work their flattening takes.
#[derive(Default)]
pub struct Formats {
    fields: HashMap<String, Vec<Field>>,
    costs: HashMap<String, Cost>,
    /// The work counted so far: every format (once the data section
    /// starts) and every subscription.
    work: u64,
    flattened: bool,
}

/// Why the formats are refused.
pub type TooCostly = String;

impl Formats {
    /// A format message's body.
    pub fn format(&mut self, body: &[u8]) {
        let Some((name, fields)) = parse(body) else {
            return;
        };
        self.fields.entry(name).or_insert(fields);
    }

    /// The data section starts (the crate flattens every format here):
    /// refused when that would be too much work.
    pub fn flatten(&mut self) -> Result<(), TooCostly> {
        if self.flattened {
            return Ok(());
        }
        self.flattened = true;
        let names: Vec<String> = self.fields.keys().cloned().collect();
        for name in names {
            let cost = self.cost(&name, 0)?;
            self.add(cost.work(), &name)?;
        }
        Ok(())
    }

    /// A subscription message's body: its format is copied.
    pub fn subscription(&mut self, body: &[u8]) -> Result<(), TooCostly> {
        self.flatten()?;
        let Some(name) = body.get(3..).and_then(|n| std::str::from_utf8(n).ok()) else {
            return Ok(());
        };
        let work = self.costs.get(name).map_or(0, Cost::work);
        let name = name.to_string();
        self.add(work, &name)
    }

    /// The work counted so far.
    pub fn work(&self) -> u64 {
        self.work
    }

    fn add(&mut self, work: u64, name: &str) -> Result<(), TooCostly> {
        self.work = self.work.saturating_add(work);
        if self.work > MAX_WORK {
            return Err(format!(
                "flattening its formats comes to more than {MAX_WORK} fields and name bytes (the limit passed at format {name:?}), more than triad reads"
            ));
        }
        Ok(())
    }

    /// What flattening format `name`, nested `depth` deep, makes.
    fn cost(&mut self, name: &str, depth: u32) -> Result<Cost, TooCostly> {
        let deep = || {
            format!("its format {name:?} is nested more than {MAX_DEPTH} formats deep, more than triad reads")
        };
        if depth > MAX_DEPTH {
            return Err(deep());
        }
        let cost = match self.costs.get(name) {
            Some(c) => *c,
            None => self.cost_anew(name, depth)?,
        };
        if depth + cost.depth > MAX_DEPTH {
            return Err(deep());
        }
        Ok(cost)
    }

    /// [`Self::cost`] of a format not costed before.
    fn cost_anew(&mut self, name: &str, depth: u32) -> Result<Cost, TooCostly> {
        // Out of the map while it is costed: a format that contains itself
        // costs nothing more here (the crate refuses it).
        let Some(fields) = self.fields.remove(name) else {
            return Ok(Cost::default());
        };
        let mut total = Ok(Cost::default());
        for f in &fields {
            let inner = if primitive(&f.kind) {
                Cost {
                    leaves: 1,
                    ..Cost::default()
                }
            } else {
                match self.cost(&f.kind, depth + 1) {
                    Ok(c) => Cost {
                        steps: c.steps.saturating_add(1),
                        depth: c.depth + 1,
                        ..c
                    },
                    Err(e) => {
                        total = Err(e);
                        break;
                    }
                }
            };
            if let Ok(t) = &mut total {
                t.add(&inner, f);
            }
        }
        self.fields.insert(name.to_string(), fields);
        let total = total?;
        self.costs.insert(name.to_string(), total);
        Ok(total)
    }
}

impl Cost {
    /// Adds `f.count` copies of a field whose type costs `inner`.
    fn add(&mut self, inner: &Cost, f: &Field) {
        // Each copy's leaves are named "NAME[i]." + the inner names (8
        // bytes for "[i]." at most).
        let prefix = f.name.len() as u64 + if f.count > 1 { 8 } else { 1 };
        let names = inner
            .leaves
            .saturating_mul(prefix)
            .saturating_add(inner.name_bytes);
        self.leaves = self
            .leaves
            .saturating_add(inner.leaves.saturating_mul(f.count));
        self.name_bytes = self
            .name_bytes
            .saturating_add(names.saturating_mul(f.count));
        self.steps = self
            .steps
            .saturating_add(inner.steps.saturating_mul(f.count));
        self.depth = self.depth.max(inner.depth);
    }
}

/// The crate's primitive types (anything else names a format).
fn primitive(kind: &str) -> bool {
    matches!(
        kind,
        "int8_t"
            | "uint8_t"
            | "int16_t"
            | "uint16_t"
            | "int32_t"
            | "uint32_t"
            | "int64_t"
            | "uint64_t"
            | "float"
            | "double"
            | "bool"
            | "char"
    )
}

/// A format message's name and fields, read as the crate reads them
/// (`NAME:TYPE NAME;TYPE[N] NAME;…`); `None` where the crate refuses it.
fn parse(body: &[u8]) -> Option<(String, Vec<Field>)> {
    let text = std::str::from_utf8(body).ok()?;
    let (name, list) = text.split_once(':')?;
    if name.is_empty() || list.contains(':') {
        return None;
    }
    let mut fields = Vec::new();
    for entry in list.split(';').filter(|s| !s.is_empty()) {
        let (kind, field) = entry.split_once(' ')?;
        if kind.is_empty() || field.is_empty() || field.contains(' ') {
            return None;
        }
        let (kind, count) = match kind.split_once('[') {
            None => (kind, 1),
            Some((k, n)) => {
                let n: i16 = n.strip_suffix(']')?.parse().ok()?;
                (k, u64::try_from(n).unwrap_or(0))
            }
        };
        fields.push(Field {
            kind: kind.to_string(),
            count,
            name: field.to_string(),
        });
    }
    Some((name.to_string(), fields))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn formats(list: &[&str]) -> Formats {
        let mut f = Formats::default();
        for body in list {
            f.format(body.as_bytes());
        }
        f
    }

    #[test]
    fn nested_arrays_of_an_empty_format_are_refused_before_flattening() {
        let mut f = formats(&["e:", "b:e[32767] x;", "a:b[32767] y;"]);
        let e = f.flatten().unwrap_err();
        assert!(e.contains("more than 8388608 fields and name bytes"), "{e}");
    }

    #[test]
    fn a_chain_deeper_than_the_limit_is_refused() {
        let mut list = vec!["m0:uint8_t v;".to_string()];
        list.extend((1..=MAX_DEPTH + 2).map(|i| format!("m{i}:m{} x;", i - 1)));
        let mut f = formats(&list.iter().map(String::as_str).collect::<Vec<_>>());
        let e = f.flatten().unwrap_err();
        assert!(e.contains("nested more than 64 formats deep"), "{e}");
        // One level less deep is read.
        list.truncate(MAX_DEPTH as usize + 1);
        let mut f = formats(&list.iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(f.flatten(), Ok(()));
    }

    #[test]
    fn a_format_that_contains_itself_is_left_to_the_crate() {
        let mut f = formats(&["a:b x;", "b:a y;uint8_t z;"]);
        assert_eq!(f.flatten(), Ok(()));
    }

    #[test]
    fn the_work_counts_leaves_their_full_names_and_each_subscription() {
        // "v[0]" … "v[2]": 3 leaves; names counted with 8 bytes for "[i]".
        let mut f = formats(&["m:uint8_t[3] v;"]);
        f.flatten().unwrap();
        let one = f.work;
        assert_eq!(one, 3 + 3 * (1 + 8));
        f.subscription(b"\x00\x00\x00m").unwrap();
        assert_eq!(f.work, 2 * one);
    }
}
