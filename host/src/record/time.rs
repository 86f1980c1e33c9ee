//! The one check of a record's time base: every reader's samples pass
//! through [`check`], which refuses a time that is not finite or does not
//! increase, naming the file, the line or message and the time. (The repair
//! of duplicate or quantised stamps and the report of gaps belong here too:
//! `triad_lab::time_base` when it lands.)

use anyhow::bail;

use super::{Opened, Reader, Sample, Source};

/// Checks `s` against the previous sample's time `last` (None: the first).
pub fn check(source: &Source, last: Option<f64>, s: &Sample) -> anyhow::Result<()> {
    if !s.t.is_finite() {
        bail!("{}: the time is not a finite number", source.where_is(s));
    }
    if let Some(last) = last {
        if s.t <= last {
            bail!(
                "{}: the time does not increase (previous sample at {last} s); the record must be in time order",
                source.where_is(s)
            );
        }
    }
    Ok(())
}

/// A reader whose samples have passed [`check`].
struct Checked {
    source: Source,
    inner: Box<dyn Reader>,
    last: Option<f64>,
}

impl Reader for Checked {
    fn next_chunk(&mut self) -> anyhow::Result<Option<Vec<Sample>>> {
        let Some(chunk) = self.inner.next_chunk()? else {
            return Ok(None);
        };
        for s in &chunk {
            check(&self.source, self.last, s)?;
            self.last = Some(s.t);
        }
        Ok(Some(chunk))
    }
}

/// `opened` with its time checked.
pub fn checked(opened: Opened) -> Opened {
    let source = opened.source.clone();
    Opened {
        reader: Box::new(Checked {
            source: source.clone(),
            inner: opened.reader,
            last: None,
        }),
        source,
    }
}
