//! The example of docs/CHIP_MODELS.md: a driver written without triad (a
//! few register accesses over any embedded-hal `SpiDevice`, as a user's own
//! driver would be) run against triad-sim's emulated ICM-42688-P in a host
//! test, its readings compared with the truth the model was given, and the
//! model asked whether the driver touched anything it does not model.

use embedded_hal::spi::{Operation, SpiDevice};
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::source::{SampleSource, TrueSample};

/// The user's driver: identity, power-up, ±4 g / ±500 °/s, one burst read.
struct MyDriver<D> {
    spi: D,
}

impl<D: SpiDevice> MyDriver<D> {
    fn write(&mut self, address: u8, value: u8) -> Result<(), D::Error> {
        self.spi.write(&[address, value])
    }

    fn read<const N: usize>(&mut self, address: u8) -> Result<[u8; N], D::Error> {
        let mut out = [0u8; N];
        self.spi.transaction(&mut [
            Operation::Write(&[address | 0x80]),
            Operation::Read(&mut out),
        ])?;
        Ok(out)
    }

    fn start(&mut self) -> Result<bool, D::Error> {
        let [who_am_i] = self.read::<1>(0x75)?;
        self.write(0x50, (2 << 5) | 0x06)?; // ACCEL_CONFIG0: ±4 g, 1 kHz
        self.write(0x4F, (2 << 5) | 0x06)?; // GYRO_CONFIG0: ±500 °/s, 1 kHz
        self.write(0x4E, 0x0F)?; // PWR_MGMT0: both low-noise
        Ok(who_am_i == 0x47)
    }

    /// Specific force (g) and angular rate (°/s).
    fn read_motion(&mut self) -> Result<([f64; 3], [f64; 3]), D::Error> {
        let b = self.read::<12>(0x1F)?;
        let word = |i: usize| f64::from(i16::from_be_bytes([b[2 * i], b[2 * i + 1]]));
        let accel = [0, 1, 2].map(|i| word(i) / 8192.0);
        let gyro = [3, 4, 5].map(|i| word(i) / 65.5);
        Ok((accel, gyro))
    }
}

/// The truth: the chip lies still, z up, turning slowly about z.
struct Still;

impl SampleSource for Still {
    fn next_sample(&mut self) -> TrueSample {
        TrueSample {
            specific_force: [0.0, 0.0, 9.806_65],
            angular_rate: [0.0, 0.0, 10f64.to_radians()],
            temperature: 30.0,
        }
    }
}

#[test]
fn my_driver_reads_what_the_emulated_chip_was_given() {
    let mut driver = MyDriver {
        spi: Icm42688Model::new(Still),
    };
    assert!(driver.start().unwrap(), "WHO_AM_I");
    driver.spi.advance(2_000_000); // 2 ms: two samples at 1 kHz
    let (accel, gyro) = driver.read_motion().unwrap();
    // Within half an LSB of the truth (the model rounds to the nearest code).
    assert!((accel[2] - 1.0).abs() <= 0.5 / 8192.0, "{accel:?}");
    assert!((gyro[2] - 10.0).abs() <= 0.5 / 65.5, "{gyro:?}");
    assert!(accel[0].abs() + gyro[0].abs() == 0.0);
    // Nothing the driver touched is outside what the model models.
    assert!(driver.spi.unmodelled().is_empty());
}
