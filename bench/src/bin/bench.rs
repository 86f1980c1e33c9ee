//! The benchmark firmware: every variant of `triad_bench` timed on an
//! emulated core, printed over semihosting, then a semihosting exit.
//!
//! Method (DESIGN.md, "The emulated board"): QEMU runs with `-icount
//! shift=0`, so each instruction advances virtual time by 1 ns; SysTick,
//! clocked by the core clock, counts f_core/1 GHz ticks per instruction
//! (0.168 on netduinoplus2's 168 MHz Cortex-M4F, 0.016 on microbit's 16 MHz
//! Cortex-M0). `cargo xtask bench` turns ticks into instructions per sample
//! and checks each digest against the host's computation of the same variant.
//!
//! Each line: `bench variant=NAME samples=N ticks=T overhead=O stack=S digest=D`
//! where O is the meter's own ticks per batch (already measured here, to be
//! subtracted BATCHES times) and S the kernel's stack high-water mark in bytes.
//! Then one `command name=…` line per command-handling row (see [`commands`]).
#![no_std]
#![no_main]

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprint, hprintln};
use triad_bench::command_handling::{
    run_commands, BenchCommand, CommandStats, COMMANDS, COUNT_KEYS,
};
use triad_bench::kernels::Meter;
use triad_bench::{Bench, Variant, BATCH, BATCHES};

/// Most bytes below the kernel caller's stack pointer painted before each
/// kernel (fewer when the stack has less room left: see [`paint_depth`]).
const STACK_PAINT: usize = 12 * 1024;
const PAINT: u32 = 0xC5AC_CE55;
/// SysTick's counter is 24 bits wide; one batch takes far fewer ticks.
const COUNTER_MASK: u32 = 0x00FF_FFFF;

/// SysTick timing and stack painting around each kernel call.
#[derive(Clone, Copy)]
struct SysTickMeter {
    t0: u32,
    ticks: u32,
    base: usize,
    /// Bytes painted by the last `start`.
    painted: usize,
    stack: usize,
    /// A kernel used every painted byte: `stack` is only a lower bound.
    stack_unknown: bool,
}

extern "C" {
    /// The end of the static data (cortex-m-rt's link.x): the stack may
    /// grow down to it.
    static __sheap: u32;
}

/// Bytes from the end of the static data up to `sp`, at most [`STACK_PAINT`].
fn paint_depth(sp: usize) -> usize {
    let end_of_statics = core::ptr::addr_of!(__sheap) as usize;
    sp.saturating_sub(end_of_statics).min(STACK_PAINT) & !3
}

impl SysTickMeter {
    /// A meter that has measured nothing (SysTick runs: [`start_systick`]).
    const fn new() -> Self {
        SysTickMeter {
            t0: 0,
            ticks: 0,
            base: 0,
            painted: 0,
            stack: 0,
            stack_unknown: false,
        }
    }
}

/// SysTick counting down from its 24-bit maximum on the core clock.
fn start_systick(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(COUNTER_MASK);
    syst.clear_current();
    syst.enable_counter();
}

impl Meter for SysTickMeter {
    #[inline(always)]
    fn start(&mut self) {
        self.base = cortex_m::register::msp::read() as usize;
        self.painted = paint_depth(self.base);
        let bottom = (self.base - self.painted) as *mut u32;
        for i in 0..self.painted / 4 {
            // SAFETY: the words below the stack pointer are unused (no
            // interrupt is enabled) and above the static data (paint_depth).
            unsafe { bottom.add(i).write_volatile(PAINT) };
        }
        self.t0 = SYST::get_current();
    }

    #[inline(always)]
    fn stop(&mut self) {
        let t1 = SYST::get_current();
        // SysTick counts down.
        self.ticks += self.t0.wrapping_sub(t1) & COUNTER_MASK;
        let bottom = (self.base - self.painted) as *const u32;
        let untouched = (0..self.painted / 4)
            // SAFETY: the same painted words as in `start`.
            .take_while(|&i| unsafe { bottom.add(i).read_volatile() } == PAINT)
            .count();
        self.stack_unknown |= untouched == 0;
        self.stack = self.stack.max(self.painted - 4 * untouched);
    }
}

#[entry]
fn main() -> ! {
    let core = cortex_m::Peripherals::take();
    let Some(mut core) = core else { finish(false) };
    start_systick(&mut core.SYST);

    // The meter's own cost per batch: a start/stop pair around nothing.
    let mut empty = SysTickMeter::new();
    for _ in 0..BATCHES {
        empty.start();
        empty.stop();
    }
    let overhead = empty.ticks / BATCHES as u32;

    variants(overhead);
    commands(overhead);
    finish(true)
}

/// The variants' rows. Out of line, so that the benchmark's calibration is
/// off the stack when the command rows run (the Cortex-M0's 16 KiB).
#[inline(never)]
fn variants(overhead: u32) {
    let bench = Bench::realistic();
    for variant in Variant::ALL {
        let mut meter = SysTickMeter::new();
        let Ok(digest) = bench.run(variant, &mut meter) else {
            hprintln!("bench error: the benchmark calibration is invalid");
            finish(false)
        };
        check_stack(variant.name(), &meter);
        hprintln!(
            "bench variant={} samples={} ticks={} overhead={} stack={} digest={:#018x}",
            variant.name(),
            BATCH * BATCHES,
            meter.ticks,
            overhead,
            meter.stack,
            digest.value()
        );
    }
}

/// The command-handling rows: `command name=NAME runs=N ticks=T overhead=O
/// stack=S digest=D wrong=W` and each of `COUNT_KEYS` (`erases=…` …), every
/// count summed over the N runs.
#[inline(never)]
fn commands(overhead: u32) {
    let mut meters = [SysTickMeter::new(); COMMANDS];
    let mut stats = [CommandStats::default(); COMMANDS];
    if let Err(e) = run_commands(&mut meters, &mut stats) {
        hprintln!("bench error: the command benchmark's device: {:?}", e);
        finish(false)
    }
    for ((row, meter), s) in BenchCommand::ALL.into_iter().zip(&meters).zip(&stats) {
        check_stack(row.name(), meter);
        hprint!(
            "command name={} runs={} ticks={} overhead={} stack={} digest={:#018x} wrong={}",
            row.name(),
            s.runs,
            meter.ticks,
            overhead,
            meter.stack,
            s.digest.value(),
            s.wrong_replies
        );
        for (key, count) in COUNT_KEYS.iter().zip(s.counts()) {
            hprint!(" {}={}", key, count);
        }
        hprintln!();
    }
}

/// Stops the run when a row's stack went past the painted bytes.
fn check_stack(name: &str, meter: &SysTickMeter) {
    if meter.stack_unknown {
        hprintln!(
            "bench error: {} used all {} painted stack bytes (raise STACK_PAINT, or RAM is short)",
            name,
            meter.stack
        );
        finish(false)
    }
}

fn finish(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    hprintln!("bench error: panic");
    finish(false)
}
