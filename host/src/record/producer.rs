//! A reader fed by a thread: the container readers (whose libraries borrow
//! a mapped file, a database statement or a parser with callbacks) run on a
//! thread of their own and hand chunks over a bounded channel, so the
//! consumer holds at most a few chunks whatever the record's length.

use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::thread::JoinHandle;

use anyhow::anyhow;

use super::{Reader, Sample, CHUNK};

/// Chunks in flight between the thread and the consumer.
const IN_FLIGHT: usize = 4;

/// Where a producing thread puts its samples.
pub struct Sink {
    tx: SyncSender<anyhow::Result<Vec<Sample>>>,
    chunk: Vec<Sample>,
}

/// The consumer has gone (it stopped reading): the producer should stop.
#[derive(Debug)]
pub struct Gone;

impl std::fmt::Display for Gone {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the consumer stopped reading")
    }
}

impl std::error::Error for Gone {}

impl Sink {
    /// Adds a sample, sending a chunk when full.
    pub fn push(&mut self, s: Sample) -> Result<(), Gone> {
        self.chunk.push(s);
        if self.chunk.len() >= CHUNK {
            self.flush()?;
        }
        Ok(())
    }

    /// Sends what is pending.
    pub fn flush(&mut self) -> Result<(), Gone> {
        if self.chunk.is_empty() {
            return Ok(());
        }
        let chunk = std::mem::replace(&mut self.chunk, Vec::with_capacity(CHUNK));
        self.tx.send(Ok(chunk)).map_err(|_| Gone)
    }
}

/// The consuming end.
pub struct Produced {
    rx: Receiver<anyhow::Result<Vec<Sample>>>,
    thread: Option<JoinHandle<()>>,
    name: String,
}

/// Runs `produce` on a thread; its error (after the samples it sent) ends
/// the record. `name` is the file, in messages.
pub fn spawn(
    name: &str,
    produce: impl FnOnce(&mut Sink) -> anyhow::Result<()> + Send + 'static,
) -> Produced {
    let (tx, rx) = sync_channel(IN_FLIGHT);
    let thread = std::thread::spawn(move || {
        let mut sink = Sink {
            tx: tx.clone(),
            chunk: Vec::with_capacity(CHUNK),
        };
        let result = produce(&mut sink).and_then(|()| Ok(sink.flush()?));
        if let Err(e) = result {
            let _ = tx.send(Err(e));
        }
    });
    Produced {
        rx,
        thread: Some(thread),
        name: name.to_string(),
    }
}

impl Reader for Produced {
    fn next_chunk(&mut self) -> anyhow::Result<Option<Vec<Sample>>> {
        match self.rx.recv() {
            Ok(chunk) => chunk.map(Some),
            Err(_) => {
                // The thread has ended: a panic in a library is an error, not ours.
                if let Some(t) = self.thread.take() {
                    if t.join().is_err() {
                        return Err(anyhow!(
                            "{}: the reader failed (a library panicked)",
                            self.name
                        ));
                    }
                }
                Ok(None)
            }
        }
    }
}
