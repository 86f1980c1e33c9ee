//! The allocator kept from giving row blocks back and taking them again:
//! `triad allan` (the one caller) passes blocks of rows (under a MiB each)
//! from the threads that read to the threads that sum, which free them. glibc maps
//! a block that size on its own (above its mmap threshold, which it raises
//! only to the size of the last such block freed) or trims the heap it
//! came from, so the next block's pages were new and each faulted in and
//! cleared: ~25 000 page faults and ~50 ms of CPU on an 8-hour bag in
//! `triad allan`. With the threshold fixed above such blocks (and the trim
//! bound above a few of them), freed blocks are reused. The buffers of
//! several MiB (the Allan histories) are still mapped alone and given back
//! when freed: kept in the heap instead, the process's exit had ~200 MB
//! more to unmap (18 ms more on that bag). Advice only: elsewhere (another
//! C library, another system) nothing changes.

/// Blocks below this are taken from the heap, not mapped alone.
const MAP_ABOVE: i32 = 2 << 20;

/// Free memory the heap keeps at its top before giving it back.
const TRIM_ABOVE: i32 = 16 << 20;

/// Sets the allocator's thresholds (call before the threads start).
pub fn keep_freed_blocks() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets the allocator's parameters; it returns 0
    // when one is refused, which leaves the default (nothing to undo).
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MAP_ABOVE);
        libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_ABOVE);
    }
}
