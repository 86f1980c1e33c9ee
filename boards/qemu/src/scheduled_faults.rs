//! The faults the emulated board is told to show (`fault=SPEC` words on
//! QEMU's semihosting command line, before `storage=`; see
//! `triad_sim::chips::fault_schedule`), and the board's time they are
//! scheduled in: the sample timer's ticks, one per data-ready period.
//!
//! On the command line rather than built in (as a scene is): one firmware
//! build then serves every schedule, so the end-to-end tests of each fault
//! and the soak cost no build of their own.
//!
//! What a fault does to the chip and its bus is the simulator's
//! (`FaultedChip`); what it does to the data-ready line is here: the sample
//! timer's edge reaches EXTI0 only while no fault silences data-ready (by
//! the schedule's time, from the tick the fault starts) and the chip raises
//! it (as the chip model said after its latest bus transaction or clock
//! step: a chip back from a brown-out raises none until configured).

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use triad_sim::chips::fault_schedule::{FaultSchedule, MAX_FAULTS};

use crate::semihosting_flash::{command_line, COMMAND_LINE_MAX};

/// Sample-timer ticks since start (its one writer: the timer's task).
static TICKS: AtomicU32 = AtomicU32::new(0);
/// The tick's length, µs.
static TICK_US: AtomicU32 = AtomicU32::new(1);
/// Whether the chip raises data-ready (written where the model is used).
static CHIP_RAISES: AtomicBool = AtomicBool::new(false);
/// The windows of the faults that silence data-ready, in ticks: start
/// (`u32::MAX`: no fault), length (`u32::MAX`: to the end), period (0: once).
static SILENCED: [[AtomicU32; 3]; MAX_FAULTS] = [const {
    [
        AtomicU32::new(u32::MAX),
        AtomicU32::new(u32::MAX),
        AtomicU32::new(0),
    ]
}; MAX_FAULTS];

/// The schedule the command line gives (empty without `fault=` words), for
/// a sample timer ticking every `tick_us`. A word that is not a schedule
/// entry stops the board, saying which and why.
pub fn read(tick_us: u32) -> FaultSchedule {
    TICK_US.store(tick_us.max(1), Ordering::Relaxed);
    let mut buf = [0u8; COMMAND_LINE_MAX];
    let mut schedule = FaultSchedule::new();
    let Some(line) = command_line(&mut buf) else {
        return schedule;
    };
    // The storage path runs to the end of the line and may hold spaces:
    // fault words come before it.
    let head = line.split_once("storage=").map_or(line, |(head, _)| head);
    for spec in head
        .split_ascii_whitespace()
        .filter_map(|w| w.strip_prefix("fault="))
    {
        if let Err(error) = schedule.add(spec) {
            defmt::error!("{}", defmt::Display2Format(&error));
            crate::exit(false);
        }
        defmt::info!("fault scheduled: {}", spec);
    }
    let tick = |us: u64| u32::try_from(us / u64::from(tick_us.max(1))).unwrap_or(u32::MAX);
    let silencing = schedule.entries().filter(|e| e.fault.silences_data_ready());
    for (slot, entry) in SILENCED.iter().zip(silencing) {
        let length = entry.end_us.map(|end| end - entry.start_us);
        slot[0].store(tick(entry.start_us), Ordering::Relaxed);
        slot[1].store(length.map_or(u32::MAX, tick), Ordering::Relaxed);
        slot[2].store(entry.every_us.map_or(0, tick), Ordering::Relaxed);
    }
    schedule
}

/// µs since start by the sample timer's ticks: the schedule's clock.
pub fn now_us() -> u64 {
    u64::from(TICKS.load(Ordering::Relaxed)) * u64::from(TICK_US.load(Ordering::Relaxed))
}

/// The chip model says whether it raises data-ready now.
pub fn chip_raises(raises: bool) {
    CHIP_RAISES.store(raises, Ordering::Relaxed);
}

/// One tick of the sample timer (its task only): true when the data-ready
/// line rises on it.
pub fn tick() -> bool {
    let now = TICKS.load(Ordering::Relaxed).wrapping_add(1);
    TICKS.store(now, Ordering::Relaxed);
    let blocked = SILENCED.iter().any(|w| {
        let [start, length, every] = [0, 1, 2].map(|i| w[i].load(Ordering::Relaxed));
        let Some(since) = now.checked_sub(start) else {
            return false;
        };
        let since = if every > 0 { since % every } else { since };
        start != u32::MAX && since < length
    });
    !blocked && CHIP_RAISES.load(Ordering::Relaxed)
}
