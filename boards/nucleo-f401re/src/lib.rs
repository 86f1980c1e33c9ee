//! ST NUCLEO-F401RE (STM32F401RE, Cortex-M4F) with an ICM-42688-P or an
//! LSM6DSOX on SPI1 or I²C1, chosen by cargo features (`sensor-lsm6dsox`,
//! `bus-i2c`; the default is the ICM-42688-P on SPI1).
//!
//! Clocks: HSI 16 MHz → PLL → 84 MHz SYSCLK, APB1 42 MHz, APB2 84 MHz
//! (RM0368 §6). Pins (Arduino headers; wiring in this folder's README.md):
//! SPI1 SCK PA5 (D13), MISO PA6 (D12), MOSI PA7 (D11), chip select PB6 (D10);
//! or I²C1 SCL PB8 (D15), SDA PB9 (D14), with PB6 holding the chip's CS high;
//! IMU INT1 → PB0 (A3) on EXTI0 for both chips; stream on USART2 TX PA2 (the
//! ST-LINK virtual COM port). Registers are written through the PAC; each raw
//! value names its reference-manual section.

#![no_std]

use defmt_rtt as _;
pub use stm32f4::stm32f401 as pac;

use triad::model::Orientation;
#[cfg(feature = "bus-i2c")]
use triad::sensor::interface::I2cInterface;
#[cfg(not(feature = "bus-i2c"))]
use triad::sensor::interface::SpiInterface;

/// The chip on this build: the ICM-42688-P unless the `sensor-lsm6dsox`
/// feature selects the LSM6DSOX (each file says its rate, address and SPI clock).
#[cfg(not(feature = "sensor-lsm6dsox"))]
mod icm42688;
#[cfg(not(feature = "sensor-lsm6dsox"))]
use icm42688 as chip;
#[cfg(feature = "sensor-lsm6dsox")]
mod lsm6dsox;
#[cfg(feature = "sensor-lsm6dsox")]
use lsm6dsox as chip;
#[cfg(feature = "bus-i2c")]
mod i2c1;
#[cfg(not(feature = "bus-i2c"))]
mod spi1;

pub use chip::{sensor_config, SAMPLE_RATE_HZ};

/// Averaging factor: streamed frames per second = SAMPLE_RATE_HZ / DECIMATION.
pub const DECIMATION: u16 = 1;
/// How the sensor is mounted on the board.
pub const ORIENTATION: Orientation = Orientation::RotationNone;
/// USART2 baud rate (the ST-LINK/V2-1 virtual COM port carries up to 2 Mbaud).
pub const BAUD: u32 = 921_600;

const SYSCLK_HZ: u32 = 84_000_000;
const APB1_HZ: u32 = 42_000_000;
/// APB1 timers run at twice APB1 when its prescaler is not 1 (RM0368 §6.2).
const APB1_TIMER_HZ: u32 = 2 * APB1_HZ;

/// The peripherals the application uses.
pub struct Board {
    /// The IMU's data-ready line (EXTI0).
    pub sample_timer: SampleTimer,
    /// Microsecond timestamps for the stream.
    pub clock: MicrosecondClock,
    /// The stream's transmitter.
    pub serial: Serial,
    /// The IMU driver on SPI1 or I²C1.
    pub sensor: Sensor,
}

/// The sensor: the chosen chip's driver over SPI1.
#[cfg(not(feature = "bus-i2c"))]
pub type Sensor = chip::Driver<SpiInterface<spi1::Spi1Device>>;
/// The sensor: the chosen chip's driver over I²C1.
#[cfg(feature = "bus-i2c")]
pub type Sensor = chip::Driver<I2cInterface<i2c1::I2c1>>;

/// Nothing to do on hardware: the chip raises INT1 by itself.
pub fn data_ready(_sensor: &mut Sensor) {}

/// Brings up clocks and peripherals.
pub fn init(dp: pac::Peripherals) -> Board {
    init_clocks(&dp);
    let rcc = &dp.RCC;
    // RM0368 §6.3.9-12: GPIOA, GPIOB; USART2, TIM5 (and I2C1); SYSCFG (and SPI1).
    rcc.ahb1enr()
        .modify(|_, w| w.gpioaen().set_bit().gpioben().set_bit());
    rcc.apb1enr()
        .modify(|_, w| w.usart2en().set_bit().tim5en().set_bit());
    rcc.apb2enr().modify(|_, w| w.syscfgen().set_bit());
    #[cfg(not(feature = "bus-i2c"))]
    rcc.apb2enr().modify(|_, w| w.spi1en().set_bit());
    #[cfg(feature = "bus-i2c")]
    rcc.apb1enr().modify(|_, w| w.i2c1en().set_bit());
    init_pins(&dp);
    Board {
        sample_timer: SampleTimer::new(&dp),
        clock: MicrosecondClock::new(dp.TIM5, APB1_TIMER_HZ),
        serial: Serial::new(dp.USART2, USART_DIV_X16),
        sensor: sensor(dp.SPI1, dp.GPIOB, dp.I2C1),
    }
}

/// The driver on SPI1, with the chip's clock divider.
#[cfg(not(feature = "bus-i2c"))]
fn sensor(spi: pac::SPI1, cs: pac::GPIOB, _: pac::I2C1) -> Sensor {
    chip::Driver::new_spi(spi1::Spi1Device::new(spi, cs, chip::SPI_BR))
}

/// The driver on I²C1 at the chip's address (PB6 stays high: CS selects I²C).
#[cfg(feature = "bus-i2c")]
fn sensor(_: pac::SPI1, _: pac::GPIOB, i2c: pac::I2C1) -> Sensor {
    chip::Driver::new_i2c(i2c1::I2c1::new(i2c), chip::I2C_ADDRESS)
}

/// HSI 16 MHz / M 16 × N 336 / P 4 = 84 MHz; flash 2 wait states (RM0368 §3.4.1).
fn init_clocks(dp: &pac::Peripherals) {
    let rcc = &dp.RCC;
    dp.FLASH
        .acr()
        .modify(|_, w| unsafe { w.latency().bits(2) }.prften().set_bit());
    // SAFETY (all raw field writes below): values within the fields' ranges per RM0368 §6.3.2.
    rcc.pllcfgr().write(|w| unsafe {
        w.pllsrc()
            .clear_bit()
            .pllm()
            .bits(16)
            .plln()
            .bits(336)
            .pllp()
            .bits(0b01)
            .pllq()
            .bits(7)
    });
    rcc.cr().modify(|_, w| w.pllon().set_bit());
    while rcc.cr().read().pllrdy().bit_is_clear() {}
    // AHB /1, APB1 /2 (≤ 42 MHz), APB2 /1; then switch SYSCLK to the PLL.
    rcc.cfgr()
        .modify(|_, w| unsafe { w.hpre().bits(0).ppre1().bits(0b100).ppre2().bits(0) });
    rcc.cfgr().modify(|_, w| unsafe { w.sw().bits(0b10) });
    while rcc.cfgr().read().sws().bits() != 0b10 {}
}

/// Pins (RM0368 §8.4; alternate functions from datasheet DS9716 table 9):
/// PA2 USART2_TX AF7; PB6 push-pull output held high (the chip's CS: idle for
/// SPI, I²C mode for I²C); PB0 input for INT1 (its reset mode); and the bus:
/// PA5/6/7 SPI1 AF5, or PB8/9 I²C1 AF4 open drain.
fn init_pins(dp: &pac::Peripherals) {
    let (a, b) = (&dp.GPIOA, &dp.GPIOB);
    // SAFETY (every raw MODER/OTYPER/OSPEEDR/PUPDR/AFR write here): two bits
    // per pin in MODER, OSPEEDR and PUPDR, one in OTYPER, four in AFRL/AFRH
    // (§8.4.1-4, §8.4.9-10); each write masks its own pins, others keep their values.
    a.afrl()
        .modify(|r, w| unsafe { w.bits((r.bits() & !(0xF << 8)) | (7 << 8)) });
    a.moder()
        .modify(|r, w| unsafe { w.bits((r.bits() & !(0b11 << 4)) | (0b10 << 4)) });
    b.bsrr().write(|w| w.bs6().set_bit());
    b.moder()
        .modify(|r, w| unsafe { w.bits((r.bits() & !((0b11 << 12) | 0b11)) | (0b01 << 12)) });
    #[cfg(not(feature = "bus-i2c"))]
    spi1_pins(a);
    #[cfg(feature = "bus-i2c")]
    i2c1_pins(b);
}

/// PA5 SCK, PA6 MISO, PA7 MOSI: AF5, very high speed.
#[cfg(not(feature = "bus-i2c"))]
fn spi1_pins(a: &pac::GPIOA) {
    // SAFETY: as in `init_pins`; pins 5..=7 only.
    a.afrl().modify(|r, w| unsafe {
        w.bits((r.bits() & !0xFFF0_0000) | (5 << 20) | (5 << 24) | (5 << 28))
    });
    a.ospeedr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (0b11 << 10) | (0b11 << 12) | (0b11 << 14)) });
    a.moder().modify(|r, w| unsafe {
        w.bits(
            (r.bits() & !((0b11 << 10) | (0b11 << 12) | (0b11 << 14)))
                | (0b10 << 10)
                | (0b10 << 12)
                | (0b10 << 14),
        )
    });
}

/// PB8 SCL, PB9 SDA: AF4, open drain (§8.4.2: OTYPER 1), fast speed, and the
/// internal pull-ups (about 40 kΩ: too weak alone at 400 kHz, so the
/// breakout's 2.2-4.7 kΩ pull-ups to 3V3 must be fitted; README.md). The
/// alternate function and output type are set before MODER hands the pins
/// to I²C1, so no push-pull glitch reaches the bus.
#[cfg(feature = "bus-i2c")]
fn i2c1_pins(b: &pac::GPIOB) {
    // SAFETY: as in `init_pins`; pins 8 and 9 only.
    b.afrh()
        .modify(|r, w| unsafe { w.bits((r.bits() & !0xFF) | 4 | (4 << 4)) });
    b.otyper()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 8) | (1 << 9)) });
    b.ospeedr().modify(|r, w| unsafe {
        w.bits((r.bits() & !((0b11 << 16) | (0b11 << 18))) | (0b10 << 16) | (0b10 << 18))
    });
    b.pupdr().modify(|r, w| unsafe {
        w.bits((r.bits() & !((0b11 << 16) | (0b11 << 18))) | (0b01 << 16) | (0b01 << 18))
    });
    b.moder().modify(|r, w| unsafe {
        w.bits((r.bits() & !((0b11 << 16) | (0b11 << 18))) | (0b10 << 16) | (0b10 << 18))
    });
}

/// The IMU's INT1 on PB0 → EXTI0, rising edge (RM0368 §10.2, §7.2.3).
pub struct SampleTimer;

impl SampleTimer {
    fn new(dp: &pac::Peripherals) -> Self {
        // SAFETY: EXTICR1 EXTI0 = 0b0001 selects port B.
        dp.SYSCFG
            .exticr1()
            .modify(|r, w| unsafe { w.bits((r.bits() & !0xF) | 0b0001) });
        dp.EXTI.rtsr().modify(|_, w| w.tr0().set_bit());
        dp.EXTI.imr().modify(|_, w| w.mr0().set_bit());
        SampleTimer
    }

    /// Clears EXTI0's pending flag (write 1 to clear).
    pub fn acknowledge(&mut self) {
        // SAFETY: PR is write-1-to-clear; bit 0 is this line only.
        unsafe { (*pac::EXTI::ptr()).pr().write(|w| w.bits(1)) };
    }

    /// True when the next data-ready edge already arrived: this step overran.
    pub fn next_step_pending(&self) -> bool {
        // SAFETY: read-only access to EXTI PR.
        unsafe { (*pac::EXTI::ptr()).pr().read().bits() & 1 != 0 }
    }
}

mod microsecond_clock;
pub use microsecond_clock::MicrosecondClock;

mod serial_tx;

/// The stream's link: USART2, transmit only, 8N1, to the ST-LINK virtual COM port.
pub type Serial = serial_tx::SerialTx<pac::USART2>;

// RM0368 §19.3.4: USARTDIV = f_APB1 / (16 · baud) in 12.4 fixed point;
// 42 MHz / 921600 rounds to 46 = 2 + 14/16: 913 kbaud, −0.9 %.
const USART_DIV_X16: u16 = ((APB1_HZ + BAUD / 2) / BAUD) as u16;

/// A busy-wait delay for the driver's start-up waits (84 MHz core).
pub struct Delay;

impl embedded_hal::delay::DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        cortex_m::asm::delay(ns / (1_000_000_000 / SYSCLK_HZ) + 1);
    }
}

/// Stops the firmware; under `probe-rs run` the breakpoint ends the session.
pub fn exit(_success: bool) -> ! {
    cortex_m::asm::bkpt();
    loop {
        cortex_m::asm::wfi();
    }
}
