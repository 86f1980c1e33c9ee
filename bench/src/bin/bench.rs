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
#![no_std]
#![no_main]

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use triad_bench::kernels::Meter;
use triad_bench::{Bench, Variant, BATCH, BATCHES};

/// Bytes below the kernel caller's stack pointer painted before each kernel.
const STACK_PAINT: usize = 3072;
const PAINT: u32 = 0xC5AC_CE55;
/// SysTick's counter is 24 bits wide; one batch takes far fewer ticks.
const COUNTER_MASK: u32 = 0x00FF_FFFF;

/// SysTick timing and stack painting around each kernel call.
struct SysTickMeter {
    t0: u32,
    ticks: u32,
    base: usize,
    stack: usize,
}

impl SysTickMeter {
    fn new(syst: &mut SYST) -> Self {
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(COUNTER_MASK);
        syst.clear_current();
        syst.enable_counter();
        SysTickMeter {
            t0: 0,
            ticks: 0,
            base: 0,
            stack: 0,
        }
    }
}

impl Meter for SysTickMeter {
    #[inline(always)]
    fn start(&mut self) {
        self.base = cortex_m::register::msp::read() as usize;
        let bottom = (self.base - STACK_PAINT) as *mut u32;
        for i in 0..STACK_PAINT / 4 {
            // SAFETY: the words below the stack pointer are unused (no
            // interrupt is enabled) and within RAM: the stack has more than
            // STACK_PAINT bytes left (the run's RAM use is ~12 KiB of 16 KiB
            // on the smallest core).
            unsafe { bottom.add(i).write_volatile(PAINT) };
        }
        self.t0 = SYST::get_current();
    }

    #[inline(always)]
    fn stop(&mut self) {
        let t1 = SYST::get_current();
        // SysTick counts down.
        self.ticks += self.t0.wrapping_sub(t1) & COUNTER_MASK;
        let bottom = (self.base - STACK_PAINT) as *const u32;
        let untouched = (0..STACK_PAINT / 4)
            // SAFETY: the same painted words as in `start`.
            .take_while(|&i| unsafe { bottom.add(i).read_volatile() } == PAINT)
            .count();
        self.stack = self.stack.max(STACK_PAINT - 4 * untouched);
    }
}

#[entry]
fn main() -> ! {
    let core = cortex_m::Peripherals::take();
    let Some(mut core) = core else { finish(false) };
    let bench = Bench::realistic();

    // The meter's own cost per batch: a start/stop pair around nothing.
    let mut empty = SysTickMeter::new(&mut core.SYST);
    for _ in 0..BATCHES {
        empty.start();
        empty.stop();
    }
    let overhead = empty.ticks / BATCHES as u32;

    for variant in Variant::ALL {
        let mut meter = SysTickMeter::new(&mut core.SYST);
        let Ok(digest) = bench.run(variant, &mut meter) else {
            hprintln!("bench error: the benchmark calibration is invalid");
            finish(false)
        };
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
    finish(true)
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
