//! ST NUCLEO-F401RE (STM32F401RE, Cortex-M4F) with an ICM-42688-P on SPI1.
//!
//! Clocks: HSI 16 MHz → PLL → 84 MHz SYSCLK, APB1 42 MHz, APB2 84 MHz
//! (RM0368 §6). Pins (Arduino headers; wiring in this folder's README.md):
//! SPI1 SCK PA5 (D13), MISO PA6 (D12), MOSI PA7 (D11), chip select PB6 (D10),
//! IMU INT1 → PB0 (A3) on EXTI0, stream on USART2 TX PA2 (the ST-LINK virtual
//! COM port). Registers are written through the PAC; each raw value names its
//! reference-manual section.

pub use stm32f4::stm32f401 as pac;

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use triad::model::Orientation;
use triad::sensor::icm42688::{config::Config, Icm42688};
use triad::sensor::interface::SpiInterface;

/// The data-ready (sample) rate, Hz: the chip's ODR in [`sensor_config`].
pub const SAMPLE_RATE_HZ: u32 = 1_000;
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
    /// The IMU driver on SPI1.
    pub sensor: Sensor,
}

/// The sensor: the ICM-42688-P driver over SPI1.
pub type Sensor = Icm42688<SpiInterface<Spi1Device>>;

/// The chip's configuration: ±16 g, ±2000 °/s, 1 kHz, data-ready on INT1.
pub fn sensor_config() -> Config {
    Config::default()
}

/// Nothing to do on hardware: the chip raises INT1 by itself.
pub fn data_ready(_sensor: &mut Sensor) {}

/// Brings up clocks and peripherals.
pub fn init(dp: pac::Peripherals) -> Board {
    init_clocks(&dp);
    let rcc = &dp.RCC;
    // RM0368 §6.3.9-12: GPIOA, GPIOB; USART2, TIM5; SPI1, SYSCFG.
    rcc.ahb1enr()
        .modify(|_, w| w.gpioaen().set_bit().gpioben().set_bit());
    rcc.apb1enr()
        .modify(|_, w| w.usart2en().set_bit().tim5en().set_bit());
    rcc.apb2enr()
        .modify(|_, w| w.spi1en().set_bit().syscfgen().set_bit());
    init_pins(&dp);
    Board {
        sample_timer: SampleTimer::new(&dp),
        clock: MicrosecondClock::new(dp.TIM5),
        serial: Serial::new(dp.USART2),
        sensor: Icm42688::new_spi(Spi1Device::new(dp.SPI1, dp.GPIOB)),
    }
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

/// Alternate functions (RM0368 §8.4; datasheet DS9716 table 9): PA2 USART2_TX
/// AF7, PA5/6/7 SPI1 AF5; PB6 push-pull output (chip select, idle high);
/// PB0 input for INT1.
fn init_pins(dp: &pac::Peripherals) {
    let (a, b) = (&dp.GPIOA, &dp.GPIOB);
    // SAFETY (raw MODER/AFR/OSPEEDR writes): two bits per pin in MODER and
    // OSPEEDR, four per pin in AFRL; other pins keep their values.
    a.afrl().modify(|r, w| unsafe {
        w.bits((r.bits() & !0xFFF0_0F00) | (7 << 8) | (5 << 20) | (5 << 24) | (5 << 28))
    });
    a.ospeedr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (0b11 << 10) | (0b11 << 12) | (0b11 << 14)) });
    a.moder().modify(|r, w| unsafe {
        w.bits(
            (r.bits() & !((0b11 << 4) | (0b11 << 10) | (0b11 << 12) | (0b11 << 14)))
                | (0b10 << 4)
                | (0b10 << 10)
                | (0b10 << 12)
                | (0b10 << 14),
        )
    });
    b.bsrr().write(|w| w.bs6().set_bit());
    b.moder()
        .modify(|r, w| unsafe { w.bits((r.bits() & !((0b11 << 12) | 0b11)) | (0b01 << 12)) });
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

/// TIM5 (32 bit) free-running at 1 MHz: the stream's timestamps.
pub struct MicrosecondClock(pac::TIM5);

impl MicrosecondClock {
    fn new(tim: pac::TIM5) -> Self {
        tim.psc()
            .write(|w| w.psc().set((APB1_TIMER_HZ / 1_000_000 - 1) as u16));
        tim.arr().write(|w| w.arr().set(u32::MAX));
        tim.egr().write(|w| w.ug().set_bit());
        tim.cr1().modify(|_, w| w.cen().set_bit());
        Self(tim)
    }

    /// Microseconds since start, wrapping at 2³².
    pub fn now_us(&self) -> u32 {
        self.0.cnt().read().bits()
    }
}

/// USART2, transmit only, 8N1, to the ST-LINK virtual COM port.
pub struct Serial(pac::USART2);

impl Serial {
    fn new(usart: pac::USART2) -> Self {
        // RM0368 §19.3.4: USARTDIV = f_APB1 / (16 · baud) in 12.4 fixed point;
        // 42 MHz / 921600 rounds to 46 = 2 + 14/16: 913 kbaud, −0.9 %.
        const DIV_X16: u16 = ((APB1_HZ + BAUD / 2) / BAUD) as u16;
        // SAFETY: BRR takes any 16-bit divider; DIV_X16 is a compile-time constant.
        usart.brr().write(|w| unsafe { w.bits(DIV_X16) });
        usart.cr1().write(|w| w.ue().set_bit().te().set_bit());
        Self(usart)
    }

    /// Sends the bytes, waiting for the transmit register to empty before each.
    pub fn write_all(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            while self.0.sr().read().txe().bit_is_clear() {}
            self.0.dr().write(|w| w.dr().set(u16::from(byte)));
        }
    }
}

/// SPI1 as an embedded-hal `SpiDevice`: mode 3, 10.5 MHz (84 MHz / 8; the
/// ICM-42688-P allows 24 MHz), chip select on PB6 around each transaction.
pub struct Spi1Device {
    spi: pac::SPI1,
    cs: pac::GPIOB,
}

impl Spi1Device {
    fn new(spi: pac::SPI1, cs: pac::GPIOB) -> Self {
        // RM0368 §20.5.1: master, BR = /8, CPOL = CPHA = 1, software NSS held high.
        spi.cr1().write(|w| {
            unsafe {
                w.mstr()
                    .set_bit()
                    .br()
                    .bits(0b010)
                    .cpol()
                    .set_bit()
                    .cpha()
                    .set_bit()
            }
            .ssm()
            .set_bit()
            .ssi()
            .set_bit()
            .spe()
            .set_bit()
        });
        Self { spi, cs }
    }

    fn transfer_byte(&mut self, out: u8) -> Result<u8, ErrorKind> {
        while self.spi.sr().read().txe().bit_is_clear() {}
        self.spi.dr().write(|w| w.dr().set(u16::from(out)));
        loop {
            let sr = self.spi.sr().read();
            if sr.ovr().bit_is_set() {
                return Err(ErrorKind::Overrun);
            }
            if sr.modf().bit_is_set() {
                return Err(ErrorKind::ModeFault);
            }
            if sr.rxne().bit_is_set() {
                return Ok(self.spi.dr().read().dr().bits() as u8);
            }
        }
    }

    fn operation(&mut self, op: &mut Operation<'_, u8>) -> Result<(), ErrorKind> {
        match op {
            Operation::Read(buf) => buf
                .iter_mut()
                .try_for_each(|b| Ok(*b = self.transfer_byte(0)?)),
            Operation::Write(buf) => buf
                .iter()
                .try_for_each(|&b| self.transfer_byte(b).map(drop)),
            Operation::Transfer(read, write) => {
                for i in 0..read.len().max(write.len()) {
                    let got = self.transfer_byte(write.get(i).copied().unwrap_or(0))?;
                    if let Some(slot) = read.get_mut(i) {
                        *slot = got;
                    }
                }
                Ok(())
            }
            Operation::TransferInPlace(buf) => buf
                .iter_mut()
                .try_for_each(|b| Ok(*b = self.transfer_byte(*b)?)),
            Operation::DelayNs(ns) => {
                cortex_m::asm::delay(*ns / (1_000_000_000 / SYSCLK_HZ) + 1);
                Ok(())
            }
        }
    }
}

impl ErrorType for Spi1Device {
    type Error = ErrorKind;
}

impl SpiDevice for Spi1Device {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        self.cs.bsrr().write(|w| w.br6().set_bit());
        let result = operations.iter_mut().try_for_each(|op| self.operation(op));
        while self.spi.sr().read().bsy().bit_is_set() {}
        self.cs.bsrr().write(|w| w.bs6().set_bit());
        result
    }
}

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
