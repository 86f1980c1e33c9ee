//! The emulated board's facts and sensor: its description (orientation,
//! decimation, baud), what the simulator serves there (the demo motion or an
//! embedded scene) and the model of each listed chip, one of which the build
//! names ([`EmulatedChip`]); the firmware finds it on the bus as it would a
//! real chip. Here, in the simulator, so that the emulated board
//! (boards/qemu) and the end-to-end test on the host build the very same
//! chip and pipeline from one source.

mod emulated_chip;
pub mod icm42688;
pub mod lsm6dsox;
pub mod source;

pub use emulated_chip::EmulatedChip;

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
