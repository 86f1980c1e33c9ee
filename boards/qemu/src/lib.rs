//! The emulated board: QEMU's `netduinoplus2` (STM32F405, Cortex-M4F).
#![no_std]
//!
//! QEMU models USART1, the timers, SysTick and the FPU; RCC and GPIO are
//! stubs, so nothing here waits on a clock-ready bit. QEMU's STM32 timers
//! count at 1 GHz of virtual time (not at the APB clock), so prescalers and
//! reloads are computed for that. The sensor is a register-level chip model
//! (the ICM-42688-P, or the LSM6DSOX with the `sensor-lsm6dsox` feature), read
//! by the real driver through the model's embedded-hal `SpiDevice` (or its
//! `I2c` with `bus-i2c`); a timer stands in for its data-ready line and
//! advances the model's clock.

use defmt_semihosting as _;
use pac::interrupt;
pub use stm32f4::stm32f405 as pac;

/// What QEMU's STM32 timers count at (virtual time), Hz.
const TIMER_CLOCK_HZ: u32 = 1_000_000_000;
/// The APB2 clock that the baud-rate divider assumes (168 MHz core / 2).
const APB2_HZ: u32 = 84_000_000;

/// The peripherals the application uses.
pub struct Board {
    /// The data-ready stand-in: one TIM3 interrupt per sample.
    pub sample_line: SampleLine,
    /// Microsecond timestamps for the stream.
    pub clock: MicrosecondClock,
    /// The stream's transmitter.
    pub serial: Serial,
    /// The IMU driver on its (software) SPI or I²C bus.
    pub sensor: Sensor,
}

/// Brings up the peripherals; call first thing in `init` (see [`SampleTimer`]).
/// No clock tree set-up: QEMU's RCC is a stub.
pub fn init(dp: pac::Peripherals) -> Board {
    dp.RCC
        .apb1enr()
        .modify(|_, w| w.tim3en().set_bit().tim5en().set_bit());
    dp.RCC.apb2enr().modify(|_, w| w.usart1en().set_bit());
    let clock = MicrosecondClock::new(dp.TIM5, TIMER_CLOCK_HZ);
    Board {
        sample_line: SampleLine::new(dp.TIM3, &clock, sensor_config().sample_rate_hz()),
        clock,
        serial: Serial::new(dp.USART1, USART_DIV_X16),
        sensor: sensor(),
    }
}

/// The data-ready line: TIM3's update interrupt pends EXTI0 (the line's
/// interrupt on real boards) once per sample, so the application's
/// data-ready task is the same on every board.
///
/// QEMU 7.2's STM32 timer model lengthens every update period by the virtual
/// time at which the counter was enabled (measured with `-icount shift=0`:
/// enabled at 448 µs, a 1000 µs reload gave 1448 µs periods; enabled at
/// about 1 µs, 1001 µs). So the board starts its timers first thing and shortens
/// the reload by the enable time read from the microsecond clock.
pub struct SampleLine(pac::TIM3);

impl SampleLine {
    /// TIM3 pending EXTI0 every sample period of `rate_hz`, to the microsecond.
    fn new(tim: pac::TIM3, clock: &MicrosecondClock, rate_hz: f64) -> Self {
        let period_us = triad::device::sample_period_us(rate_hz);
        tim.psc()
            .write(|w| w.psc().set((TIMER_CLOCK_HZ / 1_000_000 - 1) as u16));
        tim.egr().write(|w| w.ug().set_bit());
        tim.sr().write(|w| w.uif().clear_bit());
        tim.dier().write(|w| w.uie().set_bit());
        // SAFETY: TIM3's handler below only touches TIM3's status register and
        // the NVIC pending bit; priority 0 is the highest, above RTIC's tasks.
        unsafe {
            let mut core = cortex_m::Peripherals::steal();
            core.NVIC.set_priority(pac::Interrupt::TIM3, 0);
            cortex_m::peripheral::NVIC::unmask(pac::Interrupt::TIM3);
        }
        // Rounded up: the enable lands within the microsecond after the read.
        let enabled_at = (clock.now_us() + 1).min(period_us / 2);
        tim.arr()
            .write(|w| w.arr().set((period_us - 1 - enabled_at) as u16));
        tim.cr1().modify(|_, w| w.cen().set_bit());
        Self(tim)
    }
}

impl DataReadyLine for SampleLine {
    /// Nothing to acknowledge: a pended interrupt clears itself on entry.
    fn acknowledge(&mut self) {}

    fn next_step_pending(&self) -> bool {
        cortex_m::peripheral::NVIC::is_pending(pac::Interrupt::EXTI0)
    }
}

/// The emulated data-ready edge.
#[interrupt]
fn TIM3() {
    // SAFETY: only this handler writes TIM3's status register after start-up.
    let tim = unsafe { &*pac::TIM3::ptr() };
    tim.sr().write(|w| w.uif().clear_bit());
    cortex_m::peripheral::NVIC::pend(pac::Interrupt::EXTI0);
}

mod microsecond_clock;
pub use microsecond_clock::MicrosecondClock;

mod serial_tx;

/// The stream's link: USART1, transmit only, 8N1.
pub type Serial = serial_tx::SerialTx<pac::USART1>;

// RM0090 §30.3.4: USARTDIV = f_APB2 / (16 · baud), mantissa.fraction in BRR.
// 84 MHz / 921600 rounds to 91 (0x5B): 0.0 % error; fits BRR's 16 bits.
const USART_DIV_X16: u16 = ((APB2_HZ + DESCRIPTION.baud / 2) / DESCRIPTION.baud) as u16;

/// Ends the emulation with a status QEMU returns to its caller.
pub fn exit(success: bool) -> ! {
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

/// The chip on this build: the ICM-42688-P model unless the `sensor-lsm6dsox`
/// feature selects the LSM6DSOX model (each says its rate and address).
#[cfg(not(feature = "sensor-lsm6dsox"))]
use triad_sim::emulated_board::icm42688 as chip;
#[cfg(feature = "sensor-lsm6dsox")]
use triad_sim::emulated_board::lsm6dsox as chip;

/// What the chip model measures: the demo motion or an embedded scene.
use triad_sim::emulated_board::source;

pub use chip::sensor_config;
pub use triad_sim::emulated_board::DESCRIPTION;

/// The sensor: the real driver of the chosen chip over SPI (or I²C with the
/// `bus-i2c` feature), talking to the chip model serving `model_source()`.
#[cfg(not(feature = "bus-i2c"))]
pub type Sensor = chip::Driver<SpiInterface<chip::Model>>;
/// The sensor: the real driver of the chosen chip over I²C, talking to the
/// chip model (at its default address) serving `model_source()`.
#[cfg(feature = "bus-i2c")]
pub type Sensor = chip::Driver<I2cInterface<chip::Model>>;

/// The driver on the chip model, over SPI.
#[cfg(not(feature = "bus-i2c"))]
fn sensor() -> Sensor {
    chip::Driver::new_spi(chip::model(model_source()))
}

/// The driver on the chip model, over I²C at the model's address.
#[cfg(feature = "bus-i2c")]
fn sensor() -> Sensor {
    chip::Driver::new_i2c(chip::model(model_source()), chip::I2C_ADDRESS)
}

/// The scene embedded at build (TRIAD_SCENE, see build.rs), simulated at the
/// chip's rate; a blob or scene that cannot run stops the board with the
/// reason in the log.
#[cfg(feature = "sim-scene")]
fn model_source() -> source::Source {
    static SCENE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/scene.bin"));
    match source::scene(sensor_config().sample_rate_hz(), SCENE) {
        Ok(source) => source,
        Err(error) => {
            defmt::error!("embedded scene rejected: {}", defmt::Debug2Format(&error));
            exit(false)
        }
    }
}

/// The documented demo motion at the chip's rate.
#[cfg(not(feature = "sim-scene"))]
fn model_source() -> source::Source {
    source::demo(sensor_config().sample_rate_hz())
}

/// The data-ready line: on this board the timer interrupt stands in for it,
/// and the chip model's clock advances to its next sample.
pub fn data_ready(sensor: &mut Sensor) {
    let model = sensor.bus_mut();
    model.advance(chip::next_sample_ns(model));
}

/// A busy-wait delay for the driver's start-up waits (the core runs at 168
/// MHz; under `-icount shift=0` one loop cycle is one instruction).
pub struct Delay;

impl embedded_hal::delay::DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        cortex_m::asm::delay(ns / 6 + 1);
    }
}

use triad::device::board::{DataReadyLine, MicrosecondClock as _};
#[cfg(feature = "bus-i2c")]
use triad::sensor::interface::I2cInterface;
#[cfg(not(feature = "bus-i2c"))]
use triad::sensor::interface::SpiInterface;
