//! ST NUCLEO-F401RE (STM32F401RE, Cortex-M4F) with any IMU triad drives
//! (found by its identity: `triad::sensor::AnyChip`) on SPI1 or I²C1, chosen
//! by the cargo feature `bus-i2c` (default SPI1), on stm32f4xx-hal 0.23.
//!
//! Clocks: the ST-LINK's 8 MHz (MCO into OSC_IN, HSE bypass) when it is
//! there, else HSI 16 MHz; either → PLL → SYSCLK 84 MHz, APB1 42 MHz (its
//! timers 84 MHz), APB2 84 MHz. Pins (Arduino headers; wiring in this
//! folder's README.md): SPI1 SCK PA5 (D13), MISO PA6 (D12), MOSI PA7 (D11),
//! chip select PB6 (D10); or I²C1 SCL PB8 (D15), SDA PB9 (D14), with PB6
//! holding the chip's CS high; the IMU's INT1 → PB0 (A3) on EXTI0, rising
//! edge; the link on USART2, the ST-LINK's virtual COM port: the stream
//! and the replies out on TX PA2 by DMA (DMA1 stream 6 from a ring), the
//! commands in on RX PA3 by DMA (DMA1 stream 5 into a ring, woken by the
//! IDLE-line interrupt); timestamps from TIM5 (32-bit) at 1 MHz; the
//! calibration in flash sectors 6 and 7.
//!
//! Nothing here has run on silicon yet (see README.md).

#![no_std]

use defmt_rtt as _;
pub use stm32f4xx_hal::pac;

mod dma_region;
mod flash;
mod serial_rx;
mod serial_tx;
#[cfg(not(feature = "bus-i2c"))]
mod spi_dma;
pub use flash::{Flash, FlashError, StorageUnavailable, STORAGE_SLOTS};
pub use serial_rx::SerialRx;
use serial_tx::transmit_dma_interrupt;
pub use serial_tx::{Serial, TX_BUFFER_LEN};
#[cfg(not(feature = "bus-i2c"))]
pub use spi_dma::{DmaSpi, SpiDmaError};

use stm32f4xx_hal::dma::StreamsTuple;
use stm32f4xx_hal::gpio::{self, Edge, ExtiPin as _, GpioExt as _, Input, PinState};
use stm32f4xx_hal::prelude::_fugit_ExtU32 as _;
use stm32f4xx_hal::rcc::{self, Rcc, RccExt as _};
use stm32f4xx_hal::serial::{self, SerialExt as _};
use stm32f4xx_hal::syscfg::{SysCfg, SysCfgExt as _};
use stm32f4xx_hal::time::{Bps, Hertz};
use stm32f4xx_hal::timer::FTimerUs;
use stm32f4xx_hal::watchdog::IndependentWatchdog;
use triad::device::board::{BoardDescription, DataReadyLine, OwnInterrupt, Parts};
use triad::model::Orientation;
#[cfg(feature = "bus-i2c")]
use triad::sensor::interface::I2cInterface;
#[cfg(not(feature = "bus-i2c"))]
use triad::sensor::interface::{RegisterInterface as _, SpiInterface};
use triad::sensor::{AnyChip, Undetected};

/// This board's facts that the stream depends on. The link's baud rate is
/// 921600 unless the build sets `TRIAD_LINK_BAUD` (e.g. 2000000, the
/// ST-LINK virtual COM port's top rate, which 8 kHz batches need).
const DESCRIPTION: BoardDescription = BoardDescription {
    name: "nucleo-f401re",
    orientation: Orientation::RotationNone,
    decimation: 1,
    baud: link_baud(option_env!("TRIAD_LINK_BAUD")),
};

/// `TRIAD_LINK_BAUD` read at build: 921600 when unset; anything but a whole
/// number from 9600 to 5250000 (PCLK1 / 8, the USART's top rate) stops the
/// build.
const fn link_baud(text: Option<&str>) -> u32 {
    let Some(text) = text else {
        return 921_600;
    };
    let bytes = text.as_bytes();
    let mut value: u64 = 0;
    let mut i = 0;
    if bytes.is_empty() {
        panic!("TRIAD_LINK_BAUD is empty: give a baud rate, e.g. 2000000");
    }
    while i < bytes.len() {
        let digit = bytes[i];
        if !digit.is_ascii_digit() || value > u32::MAX as u64 {
            panic!("TRIAD_LINK_BAUD is not a whole number of baud, e.g. 2000000");
        }
        value = value * 10 + (digit - b'0') as u64;
        i += 1;
    }
    if value < 9_600 || value > (PCLK1_HZ / 8) as u64 {
        panic!("TRIAD_LINK_BAUD is outside 9600..=5250000 (PCLK1 / 8)");
    }
    value as u32
}

/// The core clock: the most the STM32F401 allows.
const SYSCLK_HZ: u32 = 84_000_000;
/// APB1 (USART2, I²C1, TIM5): at most 42 MHz; its timers run at twice it.
const PCLK1_HZ: u32 = 42_000_000;
/// APB2 (SPI1, SYSCFG).
const PCLK2_HZ: u32 = 84_000_000;
/// What the ST-LINK/V2-1 feeds OSC_IN from its MCO (UM1724, "OSC clock").
const ST_LINK_MCO_HZ: u32 = 8_000_000;
/// How long to wait for the ST-LINK's clock before running on HSI (ST's
/// HSE_STARTUP_TIMEOUT), in steps of at least 1 ms at HSI's 16 MHz.
const HSE_TIMEOUT_MS: u32 = 100;

#[cfg(all(feature = "bus-spi", feature = "bus-i2c"))]
compile_error!("one bus per build: features bus-spi and bus-i2c are on together");

/// The NUCLEO-F401RE, as the firmware sees it ([`triad::device::board::Board`]).
pub struct Board;

// The firmware's interrupts as this board's vectors (memory.x maps them too).
triad::board_vectors!(
    pac = stm32f4xx_hal::pac,
    data_ready = EXTI0,
    link = USART2,
    board_own = DMA1_STREAM6,
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
    type SelfTestDelay = Delay;
    type Delay = Delay;

    const DESCRIPTION: BoardDescription = DESCRIPTION;
    const BUS: &'static str = if cfg!(feature = "bus-i2c") {
        "i2c"
    } else {
        "spi"
    };
    const STORAGE_SLOTS: (u32, u32) = STORAGE_SLOTS;
    /// The DWT cycle counter: the core clock.
    const CYCLES_HZ: u32 = SYSCLK_HZ;

    /// Brings up clocks and peripherals. The sampling settings are the
    /// chip's own business here (its INT1 pin, on EXTI0, signals data ready
    /// or the FIFO watermark alike).
    fn init(dp: pac::Peripherals, _settings: &triad::sensor::Settings) -> Parts<Self> {
        init(dp)
    }

    fn find_sensor(bus: SensorBus) -> Result<Sensor, FindError> {
        find_sensor(bus)
    }

    /// DMA1_STREAM6: ends and starts runs of the transmit ring.
    fn own_interrupt() -> OwnInterrupt {
        OwnInterrupt {
            transmit_room: transmit_dma_interrupt(),
            chip_model: false,
            data_ready_period: false,
        }
    }

    /// The data-ready task made progress (a sample read): the watchdog waits
    /// its period again.
    fn feed_watchdog() {
        // SAFETY: only IWDG's key register is written (the reload key), and
        // from the data-ready task alone.
        IndependentWatchdog::new(unsafe { pac::IWDG::steal() }).feed();
    }

    /// Each erase and write of the calibration's sectors: the flash has one
    /// bank, so the CPU stalls on every fetch while it works.
    fn flash_stalls() -> u32 {
        flash::stalls()
    }

    /// The DWT cycle counter ([`init`] starts it).
    fn cycles() -> u32 {
        cortex_m::peripheral::DWT::cycle_count()
    }

    fn exit(success: bool) -> ! {
        exit(success)
    }
}

/// Brings up clocks and peripherals.
fn init(dp: pac::Peripherals) -> Parts<Board> {
    // SAFETY: init runs once, before any task; only the trace enable and
    // the cycle counter's enable bit (RTIC uses neither) are written.
    let mut core = unsafe { cortex_m::Peripherals::steal() };
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();
    let mut rcc = clocks(dp.RCC);
    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpiob = dp.GPIOB.split(&mut rcc);
    // The chip's CS, high from here on: SPI idle, or the chip's I²C mode.
    let cs = gpiob.pb6.into_push_pull_output_in_state(PinState::High);
    let mut syscfg = dp.SYSCFG.constrain(&mut rcc);
    let mut exti = dp.EXTI;
    #[cfg(not(feature = "bus-i2c"))]
    let sensor_bus = {
        let dma2 = StreamsTuple::new(dp.DMA2, &mut rcc);
        let spi = spi1(dp.SPI1, (gpioa.pa5, gpioa.pa6, gpioa.pa7), &mut rcc);
        let Ok(device) = embedded_hal_bus::spi::ExclusiveDevice::new_no_delay(
            DmaSpi::new(spi, dma2.0, dma2.3),
            cs,
        );
        device
    };
    #[cfg(feature = "bus-i2c")]
    let sensor_bus = {
        // Only its level matters: the pin keeps driving high once dropped.
        let _cs = cs;
        i2c_bus(dp.I2C1, (gpiob.pb8, gpiob.pb9), &mut rcc)
    };
    let (tx, rx) = usart2(dp.USART2, gpioa.pa2, gpioa.pa3, &mut rcc);
    let dma1 = StreamsTuple::new(dp.DMA1, &mut rcc);
    IndependentWatchdog::new(dp.IWDG).start(WATCHDOG_MS.millis());
    Parts {
        sample_line: SampleLine::new(gpiob.pb0, &mut syscfg, &mut exti),
        clock: MicrosecondClock::new(dp.TIM5, &mut rcc),
        serial: Serial::new(tx, dma1.6),
        serial_rx: SerialRx::new(rx, dma1.5),
        sensor_bus,
        flash: Ok(Flash::new(dp.FLASH)),
        self_test_delay: Delay,
    }
}

/// The independent watchdog's period, ms: a data-ready path that made no
/// progress this long (a chip gone, its data-ready line stuck, a bus
/// transaction that never ends) resets the board, whose start-up finds the
/// chip again. This board's absence handling is that watchdog (issue 26
/// accepts it on the NUCLEO): it has no sample timer, so nothing ticks the
/// firmware's stall watch, which on the emulated board checks a silent chip
/// and looks for an absent one every 50 ms. With no chip at start-up the
/// link answers (`identify`: chip `none`) until the reset, about 10 s later,
/// and each start-up looks again; a chip lost mid-stream is a reset too,
/// not a `sensor_stalls` (docs/PROTOCOL.md §17). Longer
/// than the longest self-test, during which no sample is read (about 1.4 s
/// on an ICM-42688-P), and than `erase`, which erases both calibration
/// sectors with the core stalled (DS10086 t_ERASE128KB: 2 s at most each, so
/// 4 s), with margin for the LSI clock the watchdog counts, which may run
/// up to 47 kHz where 32 kHz is assumed (DS10086 §6.3.8): 10 s nominal is
/// 6.8 s at the fastest.
const WATCHDOG_MS: u32 = 10_000;

/// SYSCLK 84 MHz from the ST-LINK's 8 MHz if it reaches OSC_IN, else from
/// HSI; the HAL picks the PLL factors and the flash wait states.
fn clocks(rcc: pac::RCC) -> Rcc {
    let source = if st_link_clock_present(&rcc) {
        defmt::info!("clock: ST-LINK 8 MHz on OSC_IN (HSE bypass)");
        rcc::Config::hse(Hertz::from_raw(ST_LINK_MCO_HZ)).bypass_hse_oscillator()
    } else {
        defmt::warn!("clock: no ST-LINK clock on OSC_IN; HSI 16 MHz (±1 % at 25 °C)");
        rcc::Config::hsi()
    };
    let rcc = rcc.freeze(
        source
            .sysclk(Hertz::from_raw(SYSCLK_HZ))
            .pclk1(Hertz::from_raw(PCLK1_HZ))
            .pclk2(Hertz::from_raw(PCLK2_HZ)),
    );
    // The SPI divider, the delay and the baud rate assume these exactly.
    defmt::assert_eq!(rcc.clocks.sysclk().raw(), SYSCLK_HZ);
    defmt::assert_eq!(rcc.clocks.pclk1().raw(), PCLK1_HZ);
    defmt::assert_eq!(rcc.clocks.pclk2().raw(), PCLK2_HZ);
    rcc
}

/// Whether the ST-LINK's MCO clock reaches OSC_IN. It does on the boards ST
/// ships from revision MB1136 C-02 on (solder bridges SB16 and SB50 fitted);
/// without it the HAL would wait for HSE forever, so this waits a bounded
/// time and, if the clock never came, leaves HSE off for the HSI set-up.
fn st_link_clock_present(rcc: &pac::RCC) -> bool {
    // RM0368 §6.3.1: HSEBYP is written while HSE is off, then HSEON.
    rcc.cr().modify(|_, w| w.hsebyp().set_bit());
    rcc.cr().modify(|_, w| w.hseon().set_bit());
    for _ in 0..HSE_TIMEOUT_MS {
        if rcc.cr().read().hserdy().bit_is_set() {
            return true;
        }
        cortex_m::asm::delay(16_000); // ≥ 1 ms at HSI's 16 MHz
    }
    rcc.cr().modify(|_, w| w.hseon().clear_bit());
    rcc.cr().modify(|_, w| w.hsebyp().clear_bit());
    false
}

/// The IMU's bus: SPI1, its bytes moved by DMA, as an embedded-hal
/// `SpiDevice` with PB6 as its CS.
#[cfg(not(feature = "bus-i2c"))]
pub type SensorBus = embedded_hal_bus::spi::ExclusiveDevice<
    DmaSpi,
    gpio::PB6<gpio::Output>,
    embedded_hal_bus::spi::NoDelay,
>;

/// The IMU's bus: I²C1.
#[cfg(feature = "bus-i2c")]
pub type SensorBus = stm32f4xx_hal::i2c::I2c<pac::I2C1>;

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
pub type SensorBusError = <SensorBus as embedded_hal::spi::ErrorType>::Error;
/// The sensor bus's error, as the drivers report it.
#[cfg(feature = "bus-i2c")]
pub type SensorBusError = <SensorBus as embedded_hal::i2c::ErrorType>::Error;

/// Why no chip was found, and the bus given back.
pub type FindError = Undetected<SensorBus, SensorBusError>;

/// Finds the chip on SPI1 by its identity (at [`SPI_HZ`], which every
/// listed chip takes), then runs SPI1 at the fastest clock the chip found
/// takes.
#[cfg(not(feature = "bus-i2c"))]
fn find_sensor(bus: SensorBus) -> Result<Sensor, FindError> {
    let sensor = AnyChip::detect(SpiInterface::new(bus)).map_err(|undetected| Undetected {
        reason: undetected.reason,
        bus: undetected.bus.release(),
    })?;
    let divider = spi_divider(sensor.spi_max_hz());
    set_spi_divider(divider);
    defmt::info!(
        "SPI1 at {} Hz for the {} (it takes {} Hz)",
        PCLK2_HZ / divider,
        sensor.name(),
        sensor.spi_max_hz()
    );
    Ok(sensor)
}

/// SPI1's clock divider of PCLK2 for a chip taking at most `max_hz`: the
/// smallest power of two, 2 to 256, that keeps the clock within it.
#[cfg(not(feature = "bus-i2c"))]
const fn spi_divider(max_hz: u32) -> u32 {
    let mut divider = 2;
    while PCLK2_HZ / divider > max_hz && divider < 256 {
        divider *= 2;
    }
    divider
}

/// Sets SPI1's clock to PCLK2 / `divider` (a power of two, 2 to 256). The
/// HAL sets the clock only when it builds the bus (`Spi::new` takes a
/// frequency; nothing changes it later, and rebuilding needs the RCC, which
/// `init` has given up), so CR1's BR field is written here, through the PAC.
#[cfg(not(feature = "bus-i2c"))]
fn set_spi_divider(divider: u32) {
    // BR = log2(divider) − 1 (RM0368, SPI_CR1: 000 is PCLK2 / 2).
    let br = (divider.trailing_zeros().clamp(1, 8) - 1) as u8;
    // SAFETY: SPI1 is idle (detection has ended; the sensor's next
    // transaction starts after this returns, from the same context), and
    // only BR changes, with the peripheral disabled meanwhile as RM0368
    // asks ("BR[2:0] should not be changed when communication is ongoing").
    let spi = unsafe { &*pac::SPI1::ptr() };
    let enabled = spi.cr1().read().spe().bit_is_set();
    spi.cr1().modify(|_, w| w.spe().clear_bit());
    spi.cr1().modify(|_, w| w.br().set(br));
    spi.cr1().modify(|_, w| w.spe().bit(enabled));
}

#[cfg(not(feature = "bus-i2c"))]
const _: () = {
    // 84 MHz / 4 = 21 MHz for the ICM-42688-P's 24; / 16 = 5.25 MHz for
    // the LSM6DSOX's 10 (/ 8 would be 10.5).
    assert!(spi_divider(24_000_000) == 4);
    assert!(spi_divider(10_000_000) == 16);
};

/// Finds the chip on I²C1 by its identity at each chip's addresses (both
/// address-pin levels: the breakout's strap does not matter).
#[cfg(feature = "bus-i2c")]
fn find_sensor(bus: SensorBus) -> Result<Sensor, FindError> {
    AnyChip::detect_i2c(bus)
}

/// SPI1's clock divider of PCLK2 while the chip is looked for: within every
/// listed chip's limit (the chip is not known until it is found on the
/// bus): 84 MHz / 16 = 5.25 MHz for the LSM6DSOX's 10 MHz. [`find_sensor`]
/// then sets the found chip's own.
#[cfg(not(feature = "bus-i2c"))]
const SPI_DIVIDER: u32 = spi_divider(triad::sensor::detect::SPI_MAX_HZ);

/// SPI1's clock. The HAL takes a frequency and rounds PCLK2 / f to the
/// nearest power-of-two divider, which can be faster than asked (10 MHz
/// would give 84 MHz / 8 = 10.5 MHz); asked for PCLK2 / 2ⁿ it sets exactly
/// that.
#[cfg(not(feature = "bus-i2c"))]
const SPI_HZ: u32 = PCLK2_HZ / SPI_DIVIDER;
#[cfg(not(feature = "bus-i2c"))]
const _: () = assert!(SPI_DIVIDER <= 256, "SPI1 divides PCLK2 by 2, 4, ... 256");

/// SPI1 (PA5 SCK, PA6 MISO, PA7 MOSI, AF5), mode 3 (both chips take 0 or 3)
/// at [`SPI_HZ`], set up and enabled by the HAL.
#[cfg(not(feature = "bus-i2c"))]
fn spi1(
    spi: pac::SPI1,
    (sck, miso, mosi): (gpio::PA5, gpio::PA6, gpio::PA7),
    rcc: &mut Rcc,
) -> stm32f4xx_hal::spi::Spi<pac::SPI1> {
    use stm32f4xx_hal::spi::SpiExt as _;
    // Fast edges for MHz clocks (the HAL leaves new pins at low speed).
    let pins = (
        Some(sck.into_alternate::<5>().speed(gpio::Speed::VeryHigh)),
        Some(miso.into_alternate::<5>()),
        Some(mosi.into_alternate::<5>().speed(gpio::Speed::VeryHigh)),
    );
    spi.spi(
        pins,
        embedded_hal::spi::MODE_3,
        Hertz::from_raw(SPI_HZ),
        rcc,
    )
}

/// I²C1 (PB8 SCL, PB9 SDA, AF4 open drain) at 400 kHz (both chips' fast
/// mode). The pins' internal pull-ups (about 40 kΩ) are on but too weak
/// alone for 400 kHz: the breakout's 2.2-4.7 kΩ must be fitted.
#[cfg(feature = "bus-i2c")]
fn i2c_bus(i2c: pac::I2C1, (scl, sda): (gpio::PB8, gpio::PB9), rcc: &mut Rcc) -> SensorBus {
    use stm32f4xx_hal::i2c::I2cExt as _;
    let pins = (
        scl.into_alternate_open_drain::<4>().internal_pull_up(true),
        sda.into_alternate_open_drain::<4>().internal_pull_up(true),
    );
    // Above 100 kHz the HAL picks fast mode, duty 2:1: CCR = 42 MHz / (3 ×
    // 400 kHz) = 35, TRISE = 13 (RM0368 §18.6.8-9).
    i2c.i2c(pins, Hertz::kHz(400), rcc)
}

/// The IMU's INT1 on PB0 → EXTI0, rising edge. PB0 is pulled down so that
/// a missing or not yet configured chip leaves the line low, not floating.
pub struct SampleLine(gpio::PB0<Input>);

impl SampleLine {
    fn new(pin: gpio::PB0, syscfg: &mut SysCfg, exti: &mut pac::EXTI) -> Self {
        let mut pin = pin.into_pull_down_input();
        pin.make_interrupt_source(syscfg);
        pin.trigger_on_edge(exti, Edge::Rising);
        pin.enable_interrupt(exti);
        Self(pin)
    }
}

impl DataReadyLine for SampleLine {
    /// Clears EXTI0's pending bit (RTIC clears only the NVIC's).
    fn acknowledge(&mut self) {
        self.0.clear_interrupt_pending_bit();
    }

    /// EXTI0's pending bit is set again: the next edge came during this step.
    fn next_step_pending(&self) -> bool {
        self.0.check_interrupt()
    }
}

/// Microseconds since start: TIM5, 32 bits, counting at 1 MHz.
pub struct MicrosecondClock(pac::TIM5);

impl MicrosecondClock {
    /// The HAL enables and resets TIM5 and sets its prescaler from the
    /// frozen clocks (84 MHz / 84). Its `Counter` is not used: `start(d)`
    /// loads ARR = d − 1 ticks, so its longest period is 2³² − 1 µs, and
    /// the count must wrap at 2³². So ARR = 2³² − 1 is written here, then
    /// an update event loads the prescaler and the counter starts.
    fn new(tim: pac::TIM5, rcc: &mut Rcc) -> Self {
        let tim = FTimerUs::new(tim, rcc).release();
        tim.arr().write(|w| w.arr().set(u32::MAX));
        tim.egr().write(|w| w.ug().set_bit());
        tim.cr1().modify(|_, w| w.cen().set_bit());
        Self(tim)
    }
}

impl triad::device::board::MicrosecondClock for MicrosecondClock {
    fn now_us(&self) -> u32 {
        self.0.cnt().read().bits()
    }
}

/// USART2 8N1 at `DESCRIPTION.baud`, TX on PA2 and RX on PA3 (AF7), both to
/// the ST-LINK's virtual COM port, both sides' requests going to the DMA
/// (CR3's DMAT and DMAR). 921600 baud from 42 MHz: the HAL writes BRR = 46 (16×
/// oversampling, 2 + 14/16), 913 kbaud, −0.9 %.
fn usart2(
    usart: pac::USART2,
    tx: gpio::PA2,
    rx: gpio::PA3,
    rcc: &mut Rcc,
) -> (serial::Tx<pac::USART2>, serial::Rx<pac::USART2>) {
    let config = serial::Config::default()
        .baudrate(Bps(DESCRIPTION.baud))
        .dma(serial::config::DmaConfig::TxRx);
    match usart.serial((tx, rx), config, rcc) {
        Ok(serial) => serial.split(),
        // Only a baud rate above PCLK1 / 8 is refused.
        Err(serial::config::InvalidConfig) => {
            defmt::error!("USART2 cannot run at {} baud", DESCRIPTION.baud);
            exit(false)
        }
    }
}

/// A busy-wait delay for the driver's start-up waits, counted in cycles of
/// the 84 MHz core (valid once [`init`] has set the clocks). `asm::delay`
/// waits at least the cycles asked for. SysTick is left to RTIC.
#[derive(Default)]
pub struct Delay;

impl embedded_hal::delay::DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        // At most 2³² ns × 0.084 cycles/ns ≈ 3.6 × 10⁸ cycles: fits a u32.
        let cycles = (u64::from(ns) * u64::from(SYSCLK_HZ)).div_ceil(1_000_000_000);
        cortex_m::asm::delay(u32::try_from(cycles).unwrap_or(u32::MAX));
    }
}

/// Stops the firmware, logging the outcome. Success halts on a breakpoint
/// (`bkpt`, in a loop), which ends a `probe-rs run` session; failure raises
/// a HardFault (`udf`), which probe-rs reports with a backtrace and a
/// non-zero exit. Without a debugger, both end in the HardFault handler's
/// loop (a `bkpt` with no debugger attached escalates to a HardFault).
fn exit(success: bool) -> ! {
    if success {
        defmt::info!("exit: success");
        loop {
            cortex_m::asm::bkpt();
        }
    } else {
        defmt::error!("exit: failure");
        cortex_m::asm::udf()
    }
}
