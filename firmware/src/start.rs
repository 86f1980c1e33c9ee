//! Start-up, before the tasks run: find and start the sensor, open the
//! calibration store, choose the calibration (the core's
//! `start_calibration`: stored, else built in, else none), and build the
//! sampler and the command handler on that choice. Every failure that
//! leaves nothing to stream stops the board with the reason in the log.

use crate::{B, CALIBRATION_BLOB, SETTINGS};
use triad::device::board::Board;
use triad::device::startup::load_stored;
use triad::device::{start_calibration, CalibrationStore, CommandHandler, DeviceFacts, Sampler};
use triad::protocol::StoredState;
use triad::sensor::{AnyChip, Imu};

/// The driver of the chip found on the board's bus.
pub type Sensor = AnyChip<<B as Board>::SensorInterface>;

/// What the tasks start with.
pub struct Started {
    /// The sensor, sampling.
    pub sensor: Sensor,
    /// The per-sample pipeline with the chosen calibration.
    pub sampler: Sampler,
    /// The command handler, over the store.
    pub handler: CommandHandler<<B as Board>::Flash>,
}

/// Brings the sensor, the store and the calibration up.
pub fn start(
    bus: <B as Board>::SensorBus,
    flash: Result<<B as Board>::Flash, <B as Board>::StorageUnavailable>,
) -> Started {
    let mut sensor = match B::find_sensor(bus) {
        Ok(sensor) => sensor,
        Err(error) => {
            defmt::error!("no known IMU on the bus: {}", defmt::Debug2Format(&error));
            B::exit(false)
        }
    };
    if let Err(error) = sensor.start_with(&mut <B as Board>::Delay::default(), &SETTINGS) {
        defmt::error!(
            "{} initialisation failed: {}",
            sensor.name(),
            defmt::Debug2Format(&error)
        );
        B::exit(false);
    }
    let rate_hz = sensor.sample_rate_hz();
    let description = B::DESCRIPTION;
    defmt::info!(
        "triad firmware: {} at {} Hz, {} per interrupt, decimation {}",
        sensor.name(),
        rate_hz as u32,
        SETTINGS.watermark,
        description.decimation
    );

    let (base, slot_len) = B::STORAGE_SLOTS;
    let mut store = match flash {
        Ok(flash) => match CalibrationStore::new(flash, base, slot_len) {
            Ok(store) => Some(store),
            Err(error) => {
                defmt::error!(
                    "calibration storage unusable: {}",
                    defmt::Debug2Format(&error)
                );
                None
            }
        },
        Err(why) => {
            defmt::info!("no calibration storage: {}", defmt::Debug2Format(&why));
            None
        }
    };
    let (stored, loaded) = match store.as_mut() {
        Some(store) => load_stored(store),
        None => (None, StoredState::NoStorage),
    };
    if loaded == StoredState::Rejected || loaded == StoredState::Failed {
        defmt::error!("stored calibration: {}; ignored", loaded.name());
    }

    let scale = sensor.scale();
    let startup = match start_calibration(
        stored.as_ref().map(|b| &b[..]),
        CALIBRATION_BLOB,
        &scale,
        description.orientation,
    ) {
        Ok(startup) => startup,
        Err(error) => {
            defmt::error!("the chip's scale is invalid: {}; stopping", error);
            B::exit(false)
        }
    };
    if let Some(rejection) = startup.stored_rejected {
        defmt::error!("stored calibration rejected: {}", rejection);
    }
    if let Some(rejection) = startup.rejected {
        defmt::error!("built-in calibration rejected: {}", rejection);
    }
    defmt::info!(
        "calibration {=u32:#010x} ({})",
        startup.corrector.calibration_id(),
        startup.source
    );
    let facts = DeviceFacts {
        firmware: env!("CARGO_PKG_VERSION"),
        board: description.name,
        chip: sensor.name(),
        bus: B::BUS,
        sample_rate_hz: rate_hz as f32,
        baud: description.baud,
        scale,
        orientation: description.orientation,
        cycles_hz: B::CYCLES_HZ,
    };
    let handler = CommandHandler::new(
        facts,
        startup.active(stored.as_ref(), CALIBRATION_BLOB),
        description.decimation,
        store,
        startup.stored_state(loaded),
    )
    .with_stored_reason(startup.stored_reason(loaded));
    let calibrated = startup.calibrated();
    let sampler = Sampler::at_rate(
        startup.corrector,
        calibrated,
        description.decimation,
        rate_hz,
    );
    Started {
        sensor,
        sampler,
        handler,
    }
}
