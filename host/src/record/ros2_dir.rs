//! A ROS 2 bag directory: metadata.yaml beside its storage files (`*.mcap`
//! or `*.db3`, split bags in several). The storage files are read in their
//! names' order (rosbag2 numbers them `_0`, `_1`, …); metadata.yaml itself
//! is not parsed: the files say their format by their content.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

use super::Format;
use super::{mcap_bag, sqlite_bag, Opened, Options, Reader, Sample, Source};
use crate::plumbing::input;

/// Opens the bag directory at `path`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let name = input::name(path);
    let files = storage_files(path).with_context(|| format!("{name}: cannot list"))?;
    let mut parts = Vec::new();
    for f in &files {
        parts.push(match super::detect::detect(f)? {
            Format::Mcap => mcap_bag::open(f, options)?,
            Format::Ros2Sqlite => sqlite_bag::open(f, options)?,
            other => bail!("{}: a {} file in a ROS 2 bag", f.display(), other.name()),
        });
    }
    if parts.is_empty() {
        bail!("{name}: a ROS 2 bag directory without .mcap or .db3 files");
    }
    let first = &parts[0].source;
    let source = Source {
        name: name.clone(),
        format: Format::Ros2Dir,
        ..first.clone()
    };
    Ok(Opened {
        source,
        reader: Box::new(Chain {
            parts: parts.into_iter().map(|o| o.reader).collect(),
            index: 0,
        }),
    })
}

/// The `.mcap` and `.db3` files of `dir`, by name.
fn storage_files(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mcap" || x == "db3"))
        .collect();
    files.sort();
    Ok(files)
}

/// The readers of the parts, one after the other.
struct Chain {
    parts: Vec<Box<dyn Reader>>,
    index: usize,
}

impl Reader for Chain {
    fn next_chunk(&mut self) -> anyhow::Result<Option<Vec<Sample>>> {
        while let Some(part) = self.parts.get_mut(self.index) {
            if let Some(chunk) = part.next_chunk()? {
                return Ok(Some(chunk));
            }
            self.index += 1;
        }
        Ok(None)
    }
}
