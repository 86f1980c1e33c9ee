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
    type Model: embedded_hal::spi::SpiDevice;
    /// A powered-up chip model serving `source`.
    fn model(source: Source) -> Self::Model;
    /// The register writes, (address, value) in order, of the chip's own
    /// reset: the register page or bank that holds it selected, then its
    /// soft-reset bit, which sets every register to its reset value.
    const POWER_ON_RESET: [(u8, u8); 2];
    /// Puts the model back at its power-on registers (sensors off, FIFO
    /// empty), as after its supply came back: [`Self::POWER_ON_RESET`]
    /// written over the model's own SPI port.
    fn power_on_reset(model: &mut Self::Model) {
        use embedded_hal::spi::{Operation, SpiDevice};
        for (address, value) in Self::POWER_ON_RESET {
            // The model's own SPI port: nothing fails once faults are cleared.
            let _ = model.transaction(&mut [Operation::Write(&[address, value])]);
        }
    }
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

#[cfg(test)]
mod tests {
    use super::{source, Emulated};
    use embedded_hal::spi::{Operation, SpiDevice};
    use triad::sensor::icm42688::Icm42688Chip;
    use triad::sensor::lsm6dsox::Lsm6dsoxChip;

    fn write(model: &mut impl SpiDevice, address: u8, value: u8) {
        model
            .transaction(&mut [Operation::Write(&[address, value])])
            .unwrap();
    }

    #[test]
    fn power_on_reset_leaves_each_chip_at_its_reset_registers_from_another_bank_or_page() {
        use crate::chips::icm42688_registers as icm;
        let mut model = Icm42688Chip::model(source::demo(1000.0));
        write(&mut model, icm::PWR_MGMT0, 0x0F);
        write(&mut model, icm::REG_BANK_SEL, 1);
        Icm42688Chip::power_on_reset(&mut model);
        assert_eq!(model.peek(icm::PWR_MGMT0), 0, "sensors off");
        assert_eq!(model.peek(icm::REG_BANK_SEL), 0, "bank 0 selected");

        use crate::chips::lsm6dsox_registers as lsm;
        let mut model = Lsm6dsoxChip::model(source::demo(833.0));
        write(&mut model, lsm::CTRL1_XL, 0x74);
        write(&mut model, lsm::FUNC_CFG_ACCESS, lsm::EMBEDDED_PAGE);
        Lsm6dsoxChip::power_on_reset(&mut model);
        assert_eq!(model.peek(lsm::CTRL1_XL), 0, "accelerometer off");
        assert_eq!(model.peek(lsm::FUNC_CFG_ACCESS), 0, "main page selected");
    }
}
