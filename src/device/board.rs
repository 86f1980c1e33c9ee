//! What the firmware needs from a board: the [`Board`] contract every board
//! crate implements (boards/qemu on the PAC, boards/nucleo-f401re on
//! stm32f4xx-hal) and the traits of its parts, so the data-ready step in
//! [`super::data_ready`] is the same code on every board and in host tests,
//! and the RTIC application is written once.

use crate::model::Orientation;
use crate::protocol::MAX_WIRE_LEN;
use crate::sensor::interface::RegisterInterface;
use crate::sensor::{AnyChip, Settings, Undetected};
use embedded_hal::delay::DelayNs;
use embedded_storage::nor_flash::NorFlash;

/// The IMU's data-ready line as the sampling task sees it.
pub trait DataReadyLine {
    /// Sampling begins: called once, at the end of the firmware's start-up.
    /// A line that the board itself paces (the emulated board's timer)
    /// starts here; a chip's line needs nothing (the default).
    fn start(&mut self) {}
    /// Clears what started this step (an EXTI pending bit), if anything must.
    fn acknowledge(&mut self);
    /// True when the next data-ready is already pending: this step overran.
    fn next_step_pending(&self) -> bool;
}

/// Microsecond timestamps for the stream.
pub trait MicrosecondClock {
    /// Microseconds since start, wrapping at 2³².
    fn now_us(&self) -> u32;
}

/// The link's transmitter as the firmware's transmitter feeds it: bytes are queued, and
/// the board sends them (from the USART's interrupt, or by DMA) while the
/// task goes on. Nothing waits on the line.
pub trait LinkTx {
    /// Bytes that can be queued now.
    fn room(&self) -> usize;
    /// Queues `bytes` (at most [`LinkTx::room`]; beyond it nothing is
    /// queued and it returns false) and starts the transmitter if it is idle.
    fn queue(&mut self, bytes: &[u8]) -> bool;

    /// Queues the packet `encode` writes into the buffer it is given (wire
    /// bytes from the start; it returns how many) and starts the
    /// transmitter, when at least [`MAX_WIRE_LEN`] bytes are free; else
    /// queues nothing and returns false. A board whose ring can lend its
    /// free bytes has `encode` write straight into them (the emulated
    /// board: no copy per byte); this default encodes into a buffer on the
    /// stack and queues its bytes.
    fn queue_encoded(&mut self, encode: impl FnOnce(&mut [u8; MAX_WIRE_LEN]) -> usize) -> bool
    where
        Self: Sized,
    {
        if self.room() < MAX_WIRE_LEN {
            return false;
        }
        let mut buffer = [0; MAX_WIRE_LEN];
        let n = encode(&mut buffer).min(MAX_WIRE_LEN);
        self.queue(&buffer[..n])
    }
}

/// Why a received byte was lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RxError {
    /// A byte arrived before the previous one was read.
    Overrun,
    /// Framing error or noise on the line.
    Line,
}

/// The link's receiver, read from its interrupt.
pub trait LinkRx {
    /// The next received byte, a reception error, or `None` when nothing
    /// is waiting.
    fn read(&mut self) -> Option<Result<u8, RxError>>;

    /// On a board that transmits from the USART's interrupt: moves queued
    /// bytes to the USART while it takes them, and returns true when the
    /// queue ran empty (the transmitter may queue more). A board that
    /// transmits by DMA does nothing here.
    fn transmit(&mut self) -> bool {
        false
    }
}

/// The facts about a board that the stream depends on, in one place:
/// [`Board::DESCRIPTION`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardDescription {
    /// The board's name as `identify` reports it (e.g. "qemu-netduinoplus2").
    pub name: &'static str,
    /// How the sensor is mounted on the board.
    pub orientation: Orientation,
    /// Samples averaged into one streamed frame.
    pub decimation: u16,
    /// The link's baud rate.
    pub baud: u32,
}

/// What a board's own interrupt did (the one interrupt of its own a board
/// may bind besides the data-ready line and the link: the emulated board's
/// sample timer, the NUCLEO's transmit DMA).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OwnInterrupt {
    /// The transmit ring has room again: wake the transmitter.
    pub transmit_room: bool,
    /// The interrupt was the emulated chip's, not the firmware's: the load
    /// report counts its time as the chip model's.
    pub chip_model: bool,
    /// One data-ready period of the board's own time passed, whatever the
    /// chip did (the emulated board's sample timer): the firmware's stall
    /// watch ticks on it.
    pub data_ready_period: bool,
}

/// The peripherals a board hands the firmware at start-up, each behind the
/// core's trait for it.
pub struct Parts<B: Board> {
    /// The IMU's data-ready line (or what stands in for it).
    pub sample_line: B::SampleLine,
    /// Microsecond timestamps for the stream.
    pub clock: B::Clock,
    /// The link's transmitter (replies and frames).
    pub serial: B::Serial,
    /// The link's receiver (commands), read from the link's interrupt.
    pub serial_rx: B::SerialRx,
    /// The IMU's bus, for [`Board::find_sensor`].
    pub sensor_bus: B::SensorBus,
    /// The calibration flash, or why the board has none.
    pub flash: Result<B::Flash, B::StorageUnavailable>,
    /// The delay the chip's self-test waits with.
    pub self_test_delay: B::SelfTestDelay,
}

/// A board: what the firmware needs of it, so that the RTIC application is
/// written once for every board. A board crate implements this on one type
/// and also provides, as a module `vectors` (RTIC's `device`; one line of
/// [`board_vectors!`](crate::board_vectors) makes it), the PAC's
/// `Peripherals` and `NVIC_PRIO_BITS` and an `interrupt` enumeration with
/// the four fixed names the firmware binds (`DATA_READY`, `LINK`,
/// `BOARD_OWN`, `DISPATCH`), numbered as its own vectors; its memory.x
/// maps the vectors' symbols to those names (e.g. `PROVIDE(EXTI0 = DATA_READY);`).
/// RTIC's `binds` takes a literal name, so the names are fixed and each
/// board says which of its vectors each one is.
pub trait Board: Sized + 'static {
    /// The PAC's peripherals, which RTIC's `init` hands over.
    type Peripherals;
    /// The IMU's data-ready line.
    type SampleLine: DataReadyLine + Send;
    /// The stream's clock.
    type Clock: MicrosecondClock + Send;
    /// The link's transmitter.
    type Serial: LinkTx + Send;
    /// The link's receiver.
    type SerialRx: LinkRx + Send;
    /// The IMU's bus as the board brings it up.
    type SensorBus;
    /// The register interface the chip's driver reads through (SPI or I²C
    /// over [`Board::SensorBus`]).
    type SensorInterface: RegisterInterface<BusError = Self::SensorBusError> + Send;
    /// The bus's error, as the drivers report it.
    type SensorBusError: core::fmt::Debug + Send;
    /// The calibration flash.
    type Flash: NorFlash + Send;
    /// Why there is no calibration flash.
    type StorageUnavailable: core::fmt::Debug;
    /// The delay the chip's self-test waits with.
    type SelfTestDelay: DelayNs + Send;
    /// A busy-wait delay for the driver's start-up waits.
    type Delay: DelayNs + Default;

    /// The facts the stream depends on (name, mounting, decimation, baud).
    const DESCRIPTION: BoardDescription;
    /// The sensor bus's name, as `identify` reports it ("spi", "i2c").
    const BUS: &'static str;
    /// Where the two calibration slots are in [`Board::Flash`]: base and
    /// length of each.
    const STORAGE_SLOTS: (u32, u32);
    /// The rate of [`Board::cycles`], Hz.
    const CYCLES_HZ: u32;

    /// Brings up clocks and peripherals for the firmware's sampling `settings`.
    fn init(peripherals: Self::Peripherals, settings: &Settings) -> Parts<Self>;

    /// Finds the chip on the bus by its identity; when none answers, why,
    /// and the bus given back (the firmware keeps looking: a chip absent
    /// at start, its cable loose, may come later).
    #[allow(clippy::type_complexity)]
    fn find_sensor(
        bus: Self::SensorBus,
    ) -> Result<AnyChip<Self::SensorInterface>, Undetected<Self::SensorBus, Self::SensorBusError>>;

    /// Called at each data-ready step before the sample is read, with the
    /// samples the step reads (the FIFO watermark, or 1): the emulated board
    /// advances its chip model; hardware does nothing.
    fn data_ready(_sensor: &mut AnyChip<Self::SensorInterface>, _samples: u16) {}

    /// The body of the board's own interrupt (`BOARD_OWN`).
    fn own_interrupt() -> OwnInterrupt;

    /// A data-ready step read the sensor: proof of progress for a board
    /// with a hardware watchdog (the NUCLEO's independent watchdog), which
    /// resets a board whose sampling stopped. Nothing by default.
    fn feed_watchdog() {}

    /// The load measurement's clock, wrapping.
    fn cycles() -> u32;

    /// How many flash operations (erases, programs) have stalled the CPU
    /// since start, wrapping: on a board whose one flash bank holds both
    /// the program and the calibration, every fetch waits while it erases
    /// or programs. Counted as each begins, with interrupts masked until it
    /// ends, so the first task to run after a stall sees the count changed.
    /// 0 on a board whose flash does not stall the CPU.
    fn flash_stalls() -> u32 {
        0
    }

    /// Cycles spent in an emulated chip model so far, wrapping (none on hardware).
    fn model_cycles() -> u32 {
        0
    }

    /// Stops the firmware with its outcome.
    fn exit(success: bool) -> !;
}

/// A board crate's `vectors` module ([`Board`]'s doc): RTIC's `device` for
/// the firmware, whose `interrupt` enumeration numbers the four names the
/// firmware binds as the board's own vectors, taken from its PAC. Invoked
/// at the board crate's root (it expands to `pub mod vectors`, which uses
/// the crate's `cortex-m`):
///
/// ```ignore
/// triad::board_vectors!(pac = stm32f4::stm32f405, data_ready = EXTI0,
///     link = USART2, board_own = TIM2, dispatch = EXTI1);
/// ```
///
/// The board's memory.x maps the same vectors to the names
/// (`EXTI0 = DATA_READY;` ...): the firmware's handlers are named for the
/// names, and the PAC's vector table for the vectors.
#[macro_export]
macro_rules! board_vectors {
    (pac = $($pac:ident)::+, data_ready = $data_ready:ident, link = $link:ident,
     board_own = $own:ident, dispatch = $dispatch:ident $(,)?) => {
        /// The interrupts the firmware binds, by the names it binds them
        /// (RTIC's `device`): memory.x maps this board's vectors to them.
        pub mod vectors {
            pub use $($pac)::+::{Peripherals, NVIC_PRIO_BITS};

            /// The firmware's interrupts, numbered as this board's vectors.
            #[allow(non_camel_case_types)]
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            #[repr(u16)]
            pub enum interrupt {
                #[doc = concat!("The data-ready line: ", stringify!($data_ready), ".")]
                DATA_READY = $($pac)::+::Interrupt::$data_ready as u16,
                #[doc = concat!("The link: ", stringify!($link), ".")]
                LINK = $($pac)::+::Interrupt::$link as u16,
                #[doc = concat!("The board's own interrupt: ", stringify!($own), ".")]
                BOARD_OWN = $($pac)::+::Interrupt::$own as u16,
                #[doc = concat!("A spare vector RTIC runs the async tasks from: ", stringify!($dispatch), ".")]
                DISPATCH = $($pac)::+::Interrupt::$dispatch as u16,
            }
            pub use interrupt as Interrupt;

            // SAFETY: each number is the PAC's for that vector.
            unsafe impl ::cortex_m::interrupt::InterruptNumber for interrupt {
                fn number(self) -> u16 {
                    self as u16
                }
            }
        }
    };
}
