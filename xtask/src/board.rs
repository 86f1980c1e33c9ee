//! The boards xtask can build and run, and what it must know of each.

/// A board folder under boards/.
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

    /// Frames streamed per second: the sample rate over the decimation
    /// (keep equal to SAMPLE_RATE_HZ / DECIMATION in boards/<board>/board.rs).
    pub fn frame_rate(self) -> f64 {
        match self {
            Board::Qemu => 1000.0,
            Board::NucleoF401re => 1000.0,
        }
    }

    /// How many frames cover `seconds` of stream time.
    pub fn frames_in(self, seconds: f64) -> u64 {
        (seconds * self.frame_rate()).ceil() as u64
    }
}
