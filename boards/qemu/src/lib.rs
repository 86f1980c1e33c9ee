//! The emulated board: QEMU's `netduinoplus2` (STM32F405, Cortex-M4F).
#![no_std]
//!
//! QEMU models the USARTs, the timers, SysTick and the FPU; RCC and GPIO are
//! stubs, so nothing here waits on a clock-ready bit. QEMU's STM32 timers
//! count at 1 GHz of virtual time (not at the APB clock), so prescalers and
//! reloads are computed for that. The sensor is a register-level chip model
//! of the chip `TRIAD_EMULATED_CHIP` names at build (default the
//! ICM-42688-P; see build.rs), on the model's embedded-hal `SpiDevice` (or
//! its `I2c` with `bus-i2c`), where the firmware finds it by its identity as
//! on a real board; a timer stands in for its data-ready line and advances
//! the model's clock.

use defmt_semihosting as _;
pub use stm32f4::stm32f405 as pac;

/// What QEMU's STM32 timers count at (virtual time), Hz.
const TIMER_CLOCK_HZ: u32 = 1_000_000_000;
/// The APB1 clock that the baud-rate divider assumes (168 MHz core / 4).
const APB1_HZ: u32 = 42_000_000;

#[cfg(all(feature = "bus-spi", feature = "bus-i2c"))]
compile_error!("one bus per build: features bus-spi and bus-i2c are on together");

/// The emulated board, as the firmware sees it ([`triad::device::board::Board`]).
pub struct Board;

// The firmware's interrupts as this board's vectors (memory.x maps them too).
triad::board_vectors!(
    pac = stm32f4::stm32f405,
    data_ready = EXTI0,
    link = USART2,
    board_own = TIM2,
    dispatch = EXTI1,
);

impl triad::device::board::Board for Board {
    type Peripherals = pac::Peripherals;
    type SampleLine = SampleLine;
    type Clock = MicrosecondClock;
    type Serial = Serial;
    type SerialRx = SerialRx;
    type SensorBus = SensorBus;
    type SensorInterface = SensorInterface;
    type SensorBusError = SensorBusError;
    type Flash = Flash;
    type StorageUnavailable = StorageUnavailable;
    type SelfTestDelay = SelfTestDelay;
    type Delay = Delay;

    const DESCRIPTION: BoardDescription = DESCRIPTION;
    const BUS: &'static str = if cfg!(feature = "bus-i2c") {
        "i2c"
    } else {
        "spi"
    };
    /// From 0, one 16 KiB erase unit each.
    const STORAGE_SLOTS: (u32, u32) = (0, 16 * 1024);
    const CYCLES_HZ: u32 = TIMER_CLOCK_HZ;

    /// No clock tree set-up: QEMU's RCC is a stub. The chip model runs at
    /// the settings' rate, and the timer edges once per `watermark` samples.
    fn init(dp: pac::Peripherals, settings: &Settings) -> Parts<Self> {
        dp.RCC.apb1enr().modify(|_, w| {
            w.tim2en().set_bit();
            w.tim4en().set_bit();
            w.tim5en().set_bit()
        });
        dp.RCC.apb1enr().modify(|_, w| w.usart2en().set_bit());
        let (chip, rate_hz) = emulated_chip(settings.rate_hz, settings.watermark);
        let sensor_bus = SensorBus(SharedBus(chip));
        let (serial, tx_drain) = Serial::new(dp.USART2, USART_DIV_X16);
        // SAFETY: the interrupt side reads SR/DR, writes DR and sets or clears
        // CR1's RE, RXNEIE and TXEIE; the transmitter's side sets TXEIE (a
        // read-modify-write the interrupt may preempt: both leave the other
        // bits as they were).
        let serial_rx = SerialRx::new(unsafe { pac::USART2::steal() }, tx_drain);
        Parts {
            sample_line: SampleLine::new(dp.TIM2, rate_hz / f64::from(settings.watermark.max(1))),
            clock: MicrosecondClock::new(dp.TIM5, TIMER_CLOCK_HZ),
            serial,
            serial_rx,
            sensor_bus,
            flash: Flash::open(),
            self_test_delay: SelfTestDelay(ModelDelay::new(chip)),
        }
    }

    fn find_sensor(bus: SensorBus) -> Result<Sensor, Undetected<SensorBus, SensorBusError>> {
        find_sensor(bus)
    }

    /// The timer stands in for the data-ready line: the chip model's clock
    /// advances by `samples` samples.
    fn data_ready(sensor: &mut Sensor, samples: u16) {
        in_model(|| {
            let bus = sensor.bus_mut();
            {
                let mut chip = bus.chip();
                for _ in 0..samples {
                    chip.advance_one_sample();
                }
            }
            bus.publish();
        });
    }

    /// TIM2: the emulated data-ready edge (the chip's time, not the firmware's).
    fn own_interrupt() -> OwnInterrupt {
        sample_timer_edge();
        OwnInterrupt {
            transmit_room: false,
            chip_model: true,
            data_ready_period: true,
        }
    }

    fn cycles() -> u32 {
        cycles()
    }

    fn model_cycles() -> u32 {
        MODEL_CYCLES.load(Ordering::Relaxed)
    }

    fn exit(success: bool) -> ! {
        exit(success)
    }
}

/// The data-ready line: TIM2's update interrupt pends EXTI0 (the line's
/// interrupt on real boards) once per sample, or once per FIFO watermark's
/// worth of samples (the chip's INT1 then signals the watermark), so the
/// application's data-ready task is the same on every board.
///
/// QEMU 7.2's STM32 timer model (hw/timer/stm32f2xx_timer.c) does not count
/// from the enable: every update period is (ARR + offset) ticks, where the
/// offset is the tick count since reset at the last write of CNT (or PSC,
/// or EGR.UG) minus the value written. The board makes that offset exactly
/// zero by writing CNT with the current tick count, which it reads from
/// TIM4: a timer never written counts virtual nanoseconds since reset.
pub struct SampleLine {
    tim: pac::TIM2,
    period_us: u32,
}

impl SampleLine {
    /// TIM2 pending EXTI0 at `rate_hz` (the sample rate over the watermark),
    /// to the microsecond, once [`DataReadyLine::start`] starts it.
    fn new(tim: pac::TIM2, rate_hz: f64) -> Self {
        tim.psc()
            .write(|w| w.psc().set((TIMER_CLOCK_HZ / 1_000_000 - 1) as u16));
        Self {
            tim,
            period_us: triad::device::sample_period_us(rate_hz),
        }
    }
}

impl DataReadyLine for SampleLine {
    /// The timer starts at the end of the firmware's start-up, so that its
    /// first edge comes one period later whatever start-up took (as a chip
    /// configured last raises its first data-ready a period after).
    fn start(&mut self) {
        let tim = &self.tim;
        let ticks_now = || cycles() / (TIMER_CLOCK_HZ / 1_000_000);
        // The offset is zero when the write lands in the microsecond read
        // before it; under -icount that is decided by instruction counts, so
        // a retry (at most once per microsecond boundary) settles it.
        loop {
            let before = ticks_now();
            tim.cnt().write(|w| w.cnt().set(before));
            if ticks_now() == before {
                break;
            }
        }
        tim.sr().write(|w| w.uif().clear_bit());
        // The firmware binds TIM2 to a task ([`sample_timer_edge`]); RTIC
        // sets its priority and unmasks it.
        tim.dier().write(|w| w.uie().set_bit());
        tim.cr1().modify(|_, w| w.cen().set_bit());
        // The model schedules the first update one period after this write.
        tim.arr().write(|w| w.arr().set(self.period_us));
    }

    /// Nothing to acknowledge: a pended interrupt clears itself on entry.
    fn acknowledge(&mut self) {}

    fn next_step_pending(&self) -> bool {
        cortex_m::peripheral::NVIC::is_pending(pac::Interrupt::EXTI0)
    }
}

/// The emulated data-ready edge: the body of the firmware's task bound to
/// TIM2 (the board's one interrupt of its own). The edge reaches EXTI0 only
/// while the chip raises data-ready and no scheduled fault holds the line
/// ([`scheduled_faults`]). One call per data-ready period, whatever the chip
/// does: the firmware's stall watch ticks on it.
fn sample_timer_edge() {
    // SAFETY: only this function writes TIM2's status register after
    // start-up, from the one task bound to TIM2.
    let tim = unsafe { &*pac::TIM2::ptr() };
    tim.sr().write(|w| w.uif().clear_bit());
    if scheduled_faults::tick() {
        cortex_m::peripheral::NVIC::pend(pac::Interrupt::EXTI0);
    }
}

mod scheduled_faults;

mod microsecond_clock;
pub use microsecond_clock::MicrosecondClock;

mod semihosting_flash;
mod serial_rx;
mod serial_tx;

/// The stream's link: USART2's transmitter, 8N1. USART2, as on the
/// NUCLEO (its ST-LINK virtual COM port), so that both boards' firmware
/// binds the same receive interrupt; QEMU connects its second `-serial`
/// to it.
pub type Serial = serial_tx::SerialTx<pac::USART2>;
/// The commands' link: USART2's receiver (interrupt USART2).
pub type SerialRx = serial_rx::SerialRx<pac::USART2>;
/// The calibration flash.
pub type Flash = semihosting_flash::SemihostingFlash;
/// Why the board has no calibration flash.
pub use semihosting_flash::Unavailable as StorageUnavailable;

// RM0090 §30.3.4: USARTDIV = f_APB1 / (16 · baud), mantissa.fraction in BRR.
// 42 MHz / 921600 rounds to 46 (0x2E): −0.9 %; fits BRR's 16 bits. (QEMU
// sends at once whatever BRR says.)
const USART_DIV_X16: u16 = ((APB1_HZ + DESCRIPTION.baud / 2) / DESCRIPTION.baud) as u16;

/// The load measurement's clock: TIM4, never written, counts QEMU's virtual
/// nanoseconds since reset, which under `-icount shift=0` are instructions
/// (and, served in real time, host nanoseconds).
fn cycles() -> u32 {
    // SAFETY: a read of a counter nothing writes after reset.
    unsafe { &*pac::TIM4::ptr() }.cnt().read().bits()
}

/// Ends the emulation with a status QEMU returns to its caller.
fn exit(success: bool) -> ! {
    use cortex_m_semihosting::debug;
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

/// The chip model's name (build.rs checks it against the core's list).
const EMULATED_CHIP: &str = env!("TRIAD_EMULATED_CHIP");

/// What the chip model measures: the demo motion or an embedded scene.
use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};
use triad_sim::chips::emulated_board::{source, EmulatedChip, FaultedChip};
use triad_sim::chips::model_clock::{ModelDelay, SharedBus};

use triad_sim::chips::emulated_board::DESCRIPTION;

/// The bus the chip model answers on: SPI (or I²C with `bus-i2c`), the
/// model shared with the [`SelfTestDelay`].
pub struct SensorBus(SharedBus<'static, FaultedChip>);

// SAFETY: the chip model's cell is reached only through the sensor's bus and
// the self-test delay. The firmware's data-ready task holds the sensor, and
// hands it to the idle task, which holds the delay, for a self-test; it
// takes nothing from the model while the sensor is away, and the idle task
// uses neither once it has handed the sensor back: the cell is never used
// from two contexts at once.
unsafe impl Send for SensorBus {}
// SAFETY: as for `SensorBus`.
unsafe impl Send for SelfTestDelay {}

impl SensorBus {
    /// The chip model.
    fn chip(&self) -> core::cell::RefMut<'_, FaultedChip> {
        self.0 .0.borrow_mut()
    }

    /// Tells the sample timer whether the chip raises data-ready now.
    fn publish(&self) {
        scheduled_faults::chip_raises(self.chip().gives_data_ready());
    }
}

impl spi::ErrorType for SensorBus {
    type Error = <EmulatedChip as spi::ErrorType>::Error;
}

impl spi::SpiDevice for SensorBus {
    fn transaction(
        &mut self,
        operations: &mut [spi::Operation<'_, u8>],
    ) -> Result<(), Self::Error> {
        let out = in_model(|| self.0.transaction(operations));
        self.publish();
        out
    }
}

impl i2c::ErrorType for SensorBus {
    type Error = <EmulatedChip as i2c::ErrorType>::Error;
}

impl i2c::I2c for SensorBus {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
        let out = in_model(|| self.0.transaction(address, operations));
        self.publish();
        out
    }
}

/// Cycles spent in the chip model (its bus transactions and its clock),
/// wrapping: the load report counts them apart from the firmware's own.
static MODEL_CYCLES: AtomicU32 = AtomicU32::new(0);

/// Runs `f`, counting its cycles as the chip model's (the data-ready task
/// is the only caller: one writer).
fn in_model<T>(f: impl FnOnce() -> T) -> T {
    let start = cycles();
    let out = f();
    let spent = cycles().wrapping_sub(start);
    MODEL_CYCLES.store(
        MODEL_CYCLES.load(Ordering::Relaxed).wrapping_add(spent),
        Ordering::Relaxed,
    );
    out
}

/// The register interface the chip's driver reads through.
#[cfg(not(feature = "bus-i2c"))]
pub type SensorInterface = SpiInterface<SensorBus>;
/// The register interface the chip's driver reads through.
#[cfg(feature = "bus-i2c")]
pub type SensorInterface = I2cInterface<SensorBus>;
/// The sensor: the driver of the chip found on the bus.
pub type Sensor = AnyChip<SensorInterface>;

/// The sensor bus's error, as the drivers report it.
#[cfg(not(feature = "bus-i2c"))]
pub type SensorBusError = spi::ErrorKind;
/// The sensor bus's error, as the drivers report it.
#[cfg(feature = "bus-i2c")]
pub type SensorBusError = i2c::ErrorKind;

/// Finds the chip on the SPI bus by its identity.
#[cfg(not(feature = "bus-i2c"))]
fn find_sensor(bus: SensorBus) -> Result<Sensor, Undetected<SensorBus, spi::ErrorKind>> {
    AnyChip::detect(SpiInterface::new(bus)).map_err(|undetected| Undetected {
        reason: undetected.reason,
        bus: undetected.bus.release(),
    })
}

/// Finds the chip on the I²C bus by its identity at each chip's addresses.
#[cfg(feature = "bus-i2c")]
fn find_sensor(bus: SensorBus) -> Result<Sensor, Undetected<SensorBus, i2c::ErrorKind>> {
    AnyChip::detect_i2c(bus)
}

/// The chip model serving `model_source()` at `rate_hz` (the driver's
/// default when `None`) behind the command line's fault schedule (its data
/// ready every `watermark` samples), in a static cell the driver's bus and
/// the self-test's delay share, and its rate in Hz. build.rs admitted only
/// listed names; a rate the chip does not have stops the board, saying so.
fn emulated_chip(rate_hz: Option<u32>, watermark: u16) -> (&'static RefCell<FaultedChip>, f64) {
    let Some(rate) = EmulatedChip::rate_hz(EMULATED_CHIP, rate_hz) else {
        defmt::error!(
            "the {} model has no output data rate of {} Hz",
            EMULATED_CHIP,
            rate_hz
        );
        exit(false)
    };
    let chip =
        EmulatedChip::named_at(EMULATED_CHIP, rate_hz, model_source).unwrap_or_else(|| exit(false));
    let tick_us = triad::device::sample_period_us(rate / f64::from(watermark.max(1)));
    let schedule = scheduled_faults::read(tick_us);
    let chip = FaultedChip::new(chip, schedule, scheduled_faults::now_us);
    let cell = cortex_m::singleton!(: RefCell<FaultedChip> = RefCell::new(chip))
        .unwrap_or_else(|| exit(false));
    (cell, rate)
}

/// The scene embedded at build (TRIAD_SCENE, see build.rs), simulated at the
/// chip's rate; a blob or scene that cannot run stops the board with the
/// reason in the log.
#[cfg(feature = "sim-scene")]
fn model_source(rate_hz: f64) -> source::Source {
    static SCENE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/scene.bin"));
    match source::scene(rate_hz, SCENE) {
        Ok(source) => source,
        Err(error) => {
            defmt::error!("embedded scene rejected: {}", defmt::Debug2Format(&error));
            exit(false)
        }
    }
}

/// The documented demo motion at the chip's rate.
#[cfg(not(feature = "sim-scene"))]
fn model_source(rate_hz: f64) -> source::Source {
    source::demo(rate_hz)
}

/// The self-test's delay: each wait lets the chip model's time pass by as
/// long, and busy-waits as long too, so the board's own time (the stream's
/// timestamps, the steps lost while sampling paused) is what hardware shows.
pub struct SelfTestDelay(ModelDelay<'static, FaultedChip>);

impl embedded_hal::delay::DelayNs for SelfTestDelay {
    fn delay_ns(&mut self, ns: u32) {
        self.0.delay_ns(ns);
        Delay.delay_ns(ns);
    }
}

/// A busy-wait delay for the driver's start-up waits (the core runs at 168
/// MHz; under `-icount shift=0` one loop cycle is one instruction).
#[derive(Default)]
pub struct Delay;

impl embedded_hal::delay::DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        cortex_m::asm::delay(ns / 6 + 1);
    }
}

use embedded_hal::{i2c, spi};
use triad::device::board::{BoardDescription, DataReadyLine, OwnInterrupt, Parts};
#[cfg(feature = "bus-i2c")]
use triad::sensor::interface::I2cInterface;
#[cfg(not(feature = "bus-i2c"))]
use triad::sensor::interface::{RegisterInterface as _, SpiInterface};
use triad::sensor::{AnyChip, Settings, Undetected};
