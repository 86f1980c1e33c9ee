//! The columns shared among the cores: each block of rows the parsing
//! thread sends is handed (shared, not copied) to one thread per group of
//! columns, this one included, each integrating its own columns. The
//! columns are independent, so the results are those of one thread, bit
//! for bit; the threads are as many as the cores (no more than the columns).

use std::sync::mpsc::sync_channel;
use std::sync::Arc;

use super::compute::{push_columns, ColumnState, BLOCK_ROWS};

/// Blocks queued per worker before the sender waits.
const QUEUED_BLOCKS: usize = 4;

/// Threads to share `columns` among: the cores, at most one per column.
pub(super) fn threads(columns: usize) -> usize {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, columns.max(1))
}

/// Pushes each block `next` gives (None: the end) into `states` (slot c
/// of a row of `width` values is column c), reporting the rows consumed
/// every 16 full blocks' worth; returns the reading's error, if any (the
/// blocks before it pushed).
pub(super) fn accumulate(
    mut next: impl FnMut() -> Option<anyhow::Result<Vec<f64>>>,
    states: &mut [ColumnState],
    width: usize,
    report: impl Fn(u64),
) -> Option<anyhow::Error> {
    let per_thread = states.len().div_ceil(threads(states.len())).max(1);
    let mut groups = states.chunks_mut(per_thread);
    let mine = groups.next().unwrap_or_default();
    std::thread::scope(|scope| {
        let mut workers = Vec::new();
        for (g, group) in groups.enumerate() {
            let (tx, blocks) = sync_channel::<Arc<Vec<f64>>>(QUEUED_BLOCKS);
            let first = (g + 1) * per_thread;
            scope.spawn(move || {
                for block in blocks {
                    push_columns(group, &block, width, first);
                }
            });
            workers.push(tx);
        }
        let (mut consumed, mut reported) = (0u64, 0u64);
        while let Some(msg) = next() {
            let block = match msg {
                Ok(block) => Arc::new(block),
                // The workers stop when their senders drop, at this return.
                Err(e) => return Some(e),
            };
            for tx in &workers {
                // A worker gone has panicked: the scope's join reports it.
                let _ = tx.send(Arc::clone(&block));
            }
            push_columns(mine, &block, width, 0);
            consumed += (block.len() / width) as u64;
            if consumed - reported >= 16 * BLOCK_ROWS as u64 {
                report(consumed);
                reported = consumed;
            }
        }
        None
    })
}
