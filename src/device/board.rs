//! What the firmware needs from a board, as traits every board crate
//! implements (boards/qemu on the PAC, boards/nucleo-f401re on
//! stm32f4xx-hal), so the data-ready step in [`super::data_ready`] is the same
//! code on every board and in host tests.

use crate::model::Orientation;

/// The IMU's data-ready line as the sampling task sees it.
pub trait DataReadyLine {
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

/// The facts about a board that the stream depends on, in one place: the
/// board crate's `DESCRIPTION` constant.
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
