//! The boards and buses xtask can build and run, and what it must know of
//! each. A firmware build is one board with one bus, chosen by cargo features
//! (`board-*`, `bus-*`; see firmware/Cargo.toml); the firmware finds its
//! chip on the bus. The emulated board's chip model is one of the core's
//! chips (`triad::sensor::CHIP_NAMES`), named at build by TRIAD_EMULATED_CHIP.

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

/// One firmware build: a board with a bus, and for the emulated board the
/// chip model it serves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Firmware {
    /// The board.
    pub board: Board,
    /// The bus.
    pub bus: Bus,
    /// The emulated board's chip model (one of `triad::sensor::CHIP_NAMES`);
    /// `None` on hardware, where the firmware finds whichever chip is fitted.
    pub emulated_chip: Option<&'static str>,
    /// The sample rate and FIFO watermark the firmware asks of the chip.
    pub sampling: Sampling,
}

/// The firmware's sampling settings at build (firmware/build.rs):
/// `TRIAD_SAMPLE_RATE_HZ`, `TRIAD_ACCEL_RATE_HZ` or `TRIAD_GYRO_RATE_HZ`,
/// and `TRIAD_FIFO_WATERMARK`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sampling {
    /// The chip's output data rate, Hz (the faster sensor's when `slower`
    /// is set); `None`: the driver's default.
    pub rate_hz: Option<u32>,
    /// One sensor at a lower rate, Hz; `None`: both at `rate_hz`.
    pub slower: Option<(Triad, u32)>,
    /// Samples per interrupt; `None` (or 1): one, FIFO off.
    pub watermark: Option<u16>,
}

impl Firmware {
    /// Every build: each bus of each board, the emulated board with each chip model.
    pub fn all() -> impl Iterator<Item = Firmware> {
        Board::ALL.into_iter().flat_map(|board| {
            let chips: Vec<Option<&'static str>> = match board {
                Board::Qemu => CHIP_NAMES.iter().copied().map(Some).collect(),
                Board::NucleoF401re => vec![None],
            };
            chips.into_iter().flat_map(move |emulated_chip| {
                Bus::ALL.into_iter().map(move |bus| Firmware {
                    board,
                    bus,
                    emulated_chip,
                    sampling: Sampling::default(),
                })
            })
        })
    }

    /// The emulated board with the first listed chip on SPI.
    pub fn default_emulated() -> Firmware {
        Firmware {
            board: Board::Qemu,
            bus: Bus::Spi,
            emulated_chip: Some(CHIP_NAMES[0]),
            sampling: Sampling::default(),
        }
    }

    /// The cargo features that select this build.
    pub fn features(self) -> String {
        format!("board-{},bus-{}", self.board.name(), self.bus.name())
    }

    /// The environment the build reads besides its features.
    pub fn build_env(self) -> Vec<(&'static str, String)> {
        let mut env = Vec::new();
        if let Some(chip) = self.emulated_chip {
            env.push(("TRIAD_EMULATED_CHIP", chip.to_string()));
        }
        if let Some(hz) = self.sampling.rate_hz {
            env.push(("TRIAD_SAMPLE_RATE_HZ", hz.to_string()));
        }
        match self.sampling.slower {
            Some((Triad::Accel, hz)) => env.push(("TRIAD_ACCEL_RATE_HZ", hz.to_string())),
            Some((Triad::Gyro, hz)) => env.push(("TRIAD_GYRO_RATE_HZ", hz.to_string())),
            None => {}
        }
        if let Some(w) = self.sampling.watermark {
            env.push(("TRIAD_FIFO_WATERMARK", w.to_string()));
        }
        env
    }

    /// A short name: `qemu/lsm6dsox/i2c`, `nucleo-f401re/spi`, and the
    /// sampling settings when set: `qemu/icm42688/spi at 8000 Hz, W = 32`.
    pub fn label(self) -> String {
        let mut label = match self.emulated_chip {
            Some(chip) => format!("{}/{chip}/{}", self.board.name(), self.bus.name()),
            None => format!("{}/{}", self.board.name(), self.bus.name()),
        };
        if let Some(hz) = self.sampling.rate_hz {
            label += &format!(" at {hz} Hz");
        }
        if let Some((triad, hz)) = self.sampling.slower {
            label += &format!(" ({} at {hz} Hz)", slower_name(triad));
        }
        if let Some(w) = self.sampling.watermark {
            label += &format!(", W = {w}");
        }
        label
    }

    /// A file-name stem for this build's artefacts: `lsm6dsox-i2c`, `spi`,
    /// `icm42688-spi-8000hz-w32` with sampling settings.
    pub fn stem(self) -> String {
        let mut stem = match self.emulated_chip {
            Some(chip) => format!("{chip}-{}", self.bus.name()),
            None => self.bus.name().to_owned(),
        };
        if let Some(hz) = self.sampling.rate_hz {
            stem += &format!("-{hz}hz");
        }
        if let Some((triad, hz)) = self.sampling.slower {
            stem += &format!("-{}{hz}hz", slower_name(triad));
        }
        if let Some(w) = self.sampling.watermark {
            stem += &format!("-w{w}");
        }
        stem
    }
}

/// The name of a triad in labels and file names.
fn slower_name(triad: Triad) -> &'static str {
    match triad {
        Triad::Accel => "accel",
        Triad::Gyro => "gyro",
    }
}

use triad::model::Triad;
use triad::sensor::CHIP_NAMES;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_build_once_each_chip_model_on_the_emulated_board() {
        let all: Vec<Firmware> = Firmware::all().collect();
        assert_eq!(
            all.len(),
            CHIP_NAMES.len() * Bus::ALL.len() + Bus::ALL.len()
        );
        assert!(all.contains(&Firmware {
            board: Board::Qemu,
            bus: Bus::I2c,
            emulated_chip: Some("lsm6dsox"),
            sampling: Sampling::default(),
        }));
        assert_eq!(
            all[0],
            Firmware::default_emulated(),
            "the default comes first"
        );
        assert_eq!(all[0].features(), "board-qemu,bus-spi");
        assert_eq!(
            all[0].build_env(),
            [("TRIAD_EMULATED_CHIP", "icm42688".to_string())]
        );
        let hardware = all.iter().find(|f| f.board == Board::NucleoF401re).unwrap();
        assert!(
            hardware.build_env().is_empty(),
            "hardware has no chip model"
        );
    }
}
