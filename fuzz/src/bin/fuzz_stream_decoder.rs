//! AFL++ target: [`triad_fuzz::stream_decoder`] (`cargo xtask bench --fuzz` runs it).

fn main() {
    afl::fuzz!(|data: &[u8]| {
        triad_fuzz::crash_on_broken(triad_fuzz::stream_decoder(data));
    });
}
