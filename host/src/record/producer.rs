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
pub struct Produced(Fed<Vec<Sample>>);

/// Runs `produce` on a thread; its error (after the samples it sent) ends
/// the record. `name` is the file, in messages.
pub fn spawn(
    name: &str,
    produce: impl FnOnce(&mut Sink) -> anyhow::Result<()> + Send + 'static,
) -> Produced {
    Produced(feed(name, IN_FLIGHT, move |tx| {
        let mut sink = Sink {
            tx: tx.clone(),
            chunk: Vec::with_capacity(CHUNK),
        };
        produce(&mut sink).and_then(|()| Ok(sink.flush()?))
    }))
}

/// Items made on a reading thread, as the consumer takes them.
pub struct Fed<T> {
    rx: Receiver<anyhow::Result<T>>,
    thread: Option<JoinHandle<()>>,
    /// False when the thread could not be started.
    started: bool,
    name: String,
}

/// Runs `produce` on a reading thread, its items sent on a channel of
/// `capacity`; its error (after the items it sent) is the last item.
/// `name` is the file, in messages.
pub fn feed<T: Send + 'static>(
    name: &str,
    capacity: usize,
    produce: impl FnOnce(&SyncSender<anyhow::Result<T>>) -> anyhow::Result<()> + Send + 'static,
) -> Fed<T> {
    let (tx, rx) = sync_channel(capacity);
    let thread = reading_thread(move || {
        if let Err(e) = produce(&tx) {
            let _ = tx.send(Err(e));
        }
    });
    Fed {
        rx,
        // Without a thread there is nothing read: the first take says so.
        started: thread.is_ok(),
        thread: thread.ok(),
        name: name.to_string(),
    }
}

impl<T> Fed<T> {
    /// The next item, None at the end; the thread's error, or a library's
    /// panic on it as the file's error.
    pub fn take(&mut self) -> anyhow::Result<Option<T>> {
        match self.rx.recv() {
            Ok(item) => item.map(Some),
            Err(_) => match self.thread.take().map(JoinHandle::join) {
                // A library that panicked on a corrupt file: an error, not a crash.
                Some(Err(_)) => Err(library_failed(&self.name)),
                Some(Ok(())) => Ok(None),
                None if self.started => Ok(None),
                None => {
                    self.started = true;
                    Err(anyhow!(
                        "{}: cannot start the thread that reads it",
                        self.name
                    ))
                }
            },
        }
    }
}

/// Runs `look` (a pass over the file a format's library makes before the
/// record is read: finding its channels, its messages) on a reading
/// thread and waits for it, so that a library that panics on a corrupt
/// file gives the file's error, as it does while the record is read.
pub fn guarded<T: Send>(
    name: &str,
    look: impl FnOnce() -> anyhow::Result<T> + Send,
) -> anyhow::Result<T> {
    quiet_panics_of_readers();
    std::thread::scope(|scope| {
        let thread = std::thread::Builder::new()
            .name(THREAD.into())
            .spawn_scoped(scope, look)
            .map_err(|e| anyhow!("{name}: cannot start the thread that reads it: {e}"))?;
        thread.join().unwrap_or_else(|_| Err(library_failed(name)))
    })
}

/// What a library's panic on a file is reported as, after the file's name
/// (the fuzz targets look for it: a panic is a crash there).
pub const LIBRARY_FAILED: &str = "the format's library stopped with an internal error on this file";

/// Starts `read` on a reading thread: a library's panic there is not
/// printed, and its join's error is the file's ([`library_failed`]).
fn reading_thread<T: Send + 'static>(
    read: impl FnOnce() -> T + Send + 'static,
) -> std::io::Result<JoinHandle<T>> {
    quiet_panics_of_readers();
    std::thread::Builder::new().name(THREAD.into()).spawn(read)
}

/// What a library's panic on a file is reported as.
fn library_failed(name: &str) -> anyhow::Error {
    anyhow!(
        "{name}: {LIBRARY_FAILED}, so it cannot be read (some part of it fails a check the library does not make; a damaged file does this)"
    )
}

/// The name of the reading threads.
const THREAD: &str = "triad-record-reader";

/// A library that panics on a corrupt file, on a reading thread, becomes
/// the error [`Produced::next_chunk`] returns: its panic message is not
/// printed (other threads' panics are, as before).
fn quiet_panics_of_readers() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if std::thread::current().name() != Some(THREAD) {
                default(info);
            }
        }));
    });
}

impl Reader for Produced {
    fn next_chunk(&mut self) -> anyhow::Result<Option<Vec<Sample>>> {
        self.0.take()
    }
}
