//! What every command shares, none of it a command itself: [`input`] (a CSV
//! file or stdin), [`outfile`] (outputs written whole or not at all),
//! [`distinct`] (no output over an input), [`stdio`] (stdout and stderr
//! without panics), [`row_writer`] (lines counted as stored), [`progress`],
//! [`interrupt`] (Ctrl-C), [`serial`] (ports), [`heap`] (the allocator's
//! thresholds for blocks passed between threads), [`number`] (readable numbers
//! in messages), [`shipped`] (what the binary carries: scenes, the default
//! calibration) and [`version`] (what `triad --version` says).

pub mod distinct;
pub mod heap;
pub mod input;
pub mod interrupt;
pub mod number;
pub mod outfile;
pub mod progress;
pub mod row_writer;
pub mod serial;
pub mod shipped;
pub mod stdio;
pub mod version;
