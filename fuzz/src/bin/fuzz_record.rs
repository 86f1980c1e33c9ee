//! AFL++ target: [`triad_fuzz::record`] (`cargo xtask bench --fuzz` runs it).

fn main() {
    afl::fuzz!(|data: &[u8]| {
        triad_fuzz::crash_on_broken(triad_fuzz::record(data));
    });
}
