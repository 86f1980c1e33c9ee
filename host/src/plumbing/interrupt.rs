//! Ctrl-C as a flag the long commands check, so they end cleanly (`decode`
//! with its summary, `sim` removing its unfinished output) instead of dying.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The flag Ctrl-C sets (the handler installed on the first call).
pub fn flag() -> Arc<AtomicBool> {
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        let set = Arc::clone(&flag);
        // If a handler cannot be installed, Ctrl-C still ends the program,
        // only less cleanly: not worth refusing to work.
        let _ = ctrlc::set_handler(move || set.store(true, Ordering::SeqCst));
        flag
    })
    .clone()
}

/// True once Ctrl-C was pressed (after [`flag`] installed the handler).
pub fn requested(flag: &AtomicBool) -> bool {
    flag.load(Ordering::SeqCst)
}
