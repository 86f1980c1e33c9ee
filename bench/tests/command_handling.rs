//! The command-handling rows on the host: the same commands the benchmark
//! firmware times (`cargo xtask bench` checks the firmware's reply digests
//! and flash counts against these), each answered as the protocol says, and
//! the flash touched only by save and erase.

use triad::device::storage::RECORD_LEN;
use triad_bench::command_handling::{
    run_commands, save_wear, BenchCommand, CommandStats, COMMANDS, REPETITIONS, UPLOAD_CHUNKS,
};
use triad_bench::kernels::NoMeter;
use triad_bench::ram_flash::FlashOps;

fn host_run() -> [CommandStats; COMMANDS] {
    let mut stats = [CommandStats::default(); COMMANDS];
    run_commands(&mut [(); COMMANDS].map(|_| NoMeter), &mut stats).unwrap();
    stats
}

fn stats_of(stats: &[CommandStats; COMMANDS], row: BenchCommand) -> &CommandStats {
    let at = BenchCommand::ALL.iter().position(|&c| c == row).unwrap();
    &stats[at]
}

#[test]
fn every_command_is_answered_with_its_expected_status_every_run() {
    let stats = host_run();
    for row in BenchCommand::ALL {
        let s = stats_of(&stats, row);
        assert_eq!(s.wrong_replies, 0, "{row:?}");
        assert_eq!(s.runs as usize, REPETITIONS * row.packets(), "{row:?}");
        assert!(s.reply_bytes > 0, "{row:?} got a reply");
    }
    assert_eq!(
        stats_of(&stats, BenchCommand::UploadChunk).runs as usize,
        REPETITIONS * 5,
        "a 584-byte blob (version 3) is four 128-byte chunks and one of 72"
    );
    assert_eq!(UPLOAD_CHUNKS, 5);
}

#[test]
fn the_runs_are_deterministic_and_each_row_s_replies_are_its_own() {
    let (a, b) = (host_run(), host_run());
    assert_eq!(a, b);
    for (i, x) in a.iter().enumerate() {
        for y in &a[i + 1..] {
            assert_ne!(x.digest, y.digest, "two rows got the same replies");
        }
    }
}

#[test]
fn only_save_and_erase_use_the_flash_and_a_save_erases_one_slot_and_writes_one_record() {
    let stats = host_run();
    let runs = REPETITIONS as u32;
    for row in BenchCommand::ALL {
        let f = stats_of(&stats, row).flash;
        match row {
            BenchCommand::Save => {
                // Both slots read and checked (header, then blob), the older
                // erased, the blob then the header written.
                assert_eq!(f.erases, runs);
                assert_eq!(f.writes, 2 * runs);
                assert_eq!(f.bytes_written as usize, runs as usize * RECORD_LEN);
                assert_eq!(f.reads, 4 * runs);
            }
            BenchCommand::Erase => {
                assert_eq!(f.erases, 2 * runs);
                assert_eq!(f.writes, 0);
            }
            _ => assert_eq!(f, FlashOps::default(), "{row:?}"),
        }
    }
}

#[test]
fn saves_alternate_between_the_two_sectors() {
    assert_eq!(save_wear(10).unwrap(), [5, 5]);
    assert_eq!(save_wear(3).unwrap(), [2, 1]);
}
