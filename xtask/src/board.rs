//! The boards, sensor chips and buses xtask can build and run, and what it
//! must know of each. A firmware build is one board with one chip on one bus,
//! chosen by cargo features (`board-*`, `sensor-*`, `bus-*`; see Cargo.toml).

/// A board crate under boards/.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Board {
    /// QEMU's netduinoplus2 (STM32F405): the emulated board.
    Qemu,
    /// ST NUCLEO-F401RE with an IMU on SPI1 or I²C1.
    #[value(name = "nucleo-f401re")]
    NucleoF401re,
}

impl Board {
    /// Every board, for builds that must cover them all.
    pub const ALL: [Board; 2] = [Board::Qemu, Board::NucleoF401re];

    /// The folder name under boards/ and the cargo feature suffix.
    pub fn name(self) -> &'static str {
        match self {
            Board::Qemu => "qemu",
            Board::NucleoF401re => "nucleo-f401re",
        }
    }

    /// The Rust target of the board's core.
    pub fn target(self) -> &'static str {
        "thumbv7em-none-eabihf"
    }
}

/// The IMU chip the firmware reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Sensor {
    /// TDK InvenSense ICM-42688-P (the default).
    Icm42688,
    /// ST LSM6DSOX.
    Lsm6dsox,
}

impl Sensor {
    /// Every chip.
    pub const ALL: [Sensor; 2] = [Sensor::Icm42688, Sensor::Lsm6dsox];

    /// The cargo feature suffix, and the name `TRIAD_E2E_SENSOR` carries.
    pub fn name(self) -> &'static str {
        match self {
            Sensor::Icm42688 => "icm42688",
            Sensor::Lsm6dsox => "lsm6dsox",
        }
    }
}

/// The bus between the microcontroller and the chip.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Bus {
    /// SPI (the default).
    Spi,
    /// I²C.
    I2c,
}

impl Bus {
    /// Every bus.
    pub const ALL: [Bus; 2] = [Bus::Spi, Bus::I2c];

    /// The cargo feature suffix, and the name `TRIAD_E2E_BUS` carries.
    pub fn name(self) -> &'static str {
        match self {
            Bus::Spi => "spi",
            Bus::I2c => "i2c",
        }
    }
}

/// One firmware build: a board with a chip on a bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Firmware {
    /// The board.
    pub board: Board,
    /// The chip.
    pub sensor: Sensor,
    /// The bus.
    pub bus: Bus,
}

impl Firmware {
    /// Every valid board × chip × bus (all of them: both boards wire both chips on both buses).
    pub fn all() -> impl Iterator<Item = Firmware> {
        Board::ALL.into_iter().flat_map(|board| {
            Sensor::ALL.into_iter().flat_map(move |sensor| {
                Bus::ALL
                    .into_iter()
                    .map(move |bus| Firmware { board, sensor, bus })
            })
        })
    }

    /// The emulated board with the default chip and bus (ICM-42688-P on SPI).
    pub fn default_emulated() -> Firmware {
        Firmware {
            board: Board::Qemu,
            sensor: Sensor::Icm42688,
            bus: Bus::Spi,
        }
    }

    /// The cargo features that select this build.
    pub fn features(self) -> String {
        format!(
            "board-{},sensor-{},bus-{}",
            self.board.name(),
            self.sensor.name(),
            self.bus.name()
        )
    }

    /// A short name: `qemu/lsm6dsox/i2c`.
    pub fn label(self) -> String {
        format!(
            "{}/{}/{}",
            self.board.name(),
            self.sensor.name(),
            self.bus.name()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_combination_is_built_once_with_its_features() {
        let all: Vec<Firmware> = Firmware::all().collect();
        assert_eq!(all.len(), 8);
        assert!(all.contains(&Firmware {
            board: Board::Qemu,
            sensor: Sensor::Lsm6dsox,
            bus: Bus::I2c
        }));
        assert_eq!(
            all[0].features(),
            "board-qemu,sensor-icm42688,bus-spi",
            "the default chip and bus come first"
        );
    }
}
