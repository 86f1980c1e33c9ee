//! The emulated board's facts and sensor: its description (orientation,
//! decimation, baud), what the simulator serves there (the demo motion or an
//! embedded scene) and the model of each listed chip, one of which the build
//! names ([`EmulatedChip`]); the firmware finds it on the bus as it would a
//! real chip. Here, in the simulator, so that the emulated board
//! (boards/qemu) and the end-to-end test on the host build the very same
//! chip and pipeline from one source.

mod emulated_chip;
mod faulted_chip;
pub mod icm42688;
pub mod lsm6dsox;
pub mod source;

pub use emulated_chip::EmulatedChip;
pub use faulted_chip::FaultedChip;

use self::source::Source;

use triad::device::board::BoardDescription;
use triad::model::Orientation;

/// A chip the emulated board can carry: its register-level model serving
/// the board's source. Each listed chip (`triad::for_each_chip!`) has one.
pub trait Emulated: triad::sensor::Chip {
    /// The chip model behind the bus.
    type Model;
    /// A powered-up chip model serving `source`.
    fn model(source: Source) -> Self::Model;
    /// Puts the model back at its power-on registers (sensors off, FIFO
    /// empty), as after its supply came back, through its own reset.
    fn power_on_reset(model: &mut Self::Model);
    /// `byte` as read at `address` when the FIFO's count is impossible: the
    /// count registers give a count beyond the FIFO's size, any other
    /// register its own byte.
    fn impossible_fifo_count(address: u8, byte: u8) -> u8;
}

/// The emulated board (QEMU's netduinoplus2): chip mounted in the board's
/// axes, every sample streamed, USART1 at 921600 baud (QEMU ignores the
/// rate; the divider is what silicon would get).
pub const DESCRIPTION: BoardDescription = BoardDescription {
    name: "qemu-netduinoplus2",
    orientation: Orientation::RotationNone,
    decimation: 1,
    baud: 921_600,
};
