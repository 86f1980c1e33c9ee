//! Start-up, before the tasks run: find and start the sensor, open the
//! calibration store, choose the calibration (the core's
//! `start_calibration`: stored, else built in, else none), and build the
//! sampler and the command handler on that choice. A chip that does not
//! answer on the bus is not fatal: the board comes up without it (the
//! handler says chip "none" and refuses what needs one), and the
//! data-ready task keeps looking ([`find`], [`for_sensor`] when it
//! answers) at the stall watch's checks, on a board whose own interrupt
//! ticks it (the emulated board's sample timer); on the NUCLEO nothing
//! does, and its watchdog resets the board within 10 s, whose start-up
//! looks again. Every other failure that leaves nothing to stream stops the
//! board with the reason in the log.

use crate::{B, CALIBRATION_BLOB, SETTINGS};
use triad::device::board::Board;
use triad::device::startup::load_stored;
use triad::device::{
    sample_period_us, start_calibration, ActiveCalibration, CalibrationStore, CommandHandler,
    DeviceFacts, Sampler, NO_SENSOR,
};
use triad::model::blob::BLOB_LEN;
use triad::protocol::{CalibrationSource, StoredReason, StoredState};
use triad::sensor::{AnyChip, Imu, ImuScale};

/// The driver of the chip found on the board's bus.
pub type Sensor = AnyChip<<B as Board>::SensorInterface>;
/// The board's sensor bus, while no chip has answered on it.
pub type SensorBus = <B as Board>::SensorBus;

/// What the store held at start-up: the calibration is chosen from it when
/// the chip answers (nothing that changes the store runs before).
pub struct StoreAtStart {
    stored: Option<[u8; BLOB_LEN]>,
    loaded: StoredState,
}

/// No chip yet: the bus to look on, and the store as it was.
pub struct Waiting {
    /// The bus, given back by the last look.
    pub bus: SensorBus,
    /// The store at start-up.
    pub store: StoreAtStart,
    /// Looks so far.
    pub looks: u32,
}

/// What the command handler learns of a chip that answered.
pub struct ChipFacts {
    /// The device's facts.
    pub facts: DeviceFacts,
    /// The calibration in force.
    pub active: ActiveCalibration,
    /// What the store's record is for this chip.
    pub stored: StoredState,
    /// Why it was rejected, if it was.
    pub stored_reason: StoredReason,
}

/// What the tasks start with.
pub struct Started {
    /// The sensor, sampling, and its pipeline; or the bus to keep looking on.
    pub sensor: Result<(Sensor, Sampler), Waiting>,
    /// The command handler, over the store.
    pub handler: CommandHandler<<B as Board>::Flash>,
}

/// Looks for the chip on `bus` (the `look`-th time, from 1) and starts it;
/// the bus back when no chip answers. A chip found that does not take its
/// configuration stops the board.
pub fn find(bus: SensorBus, look: u32) -> Result<Sensor, SensorBus> {
    let mut sensor = match B::find_sensor(bus) {
        Ok(sensor) => sensor,
        Err(undetected) => {
            // Logged at looks 1, 2, 4, 8, ...: a chip absent for hours
            // does not flood the log.
            if look.is_power_of_two() {
                defmt::warn!(
                    "no known IMU on the bus (look {}): {}; looking again at each stall-watch check (about every 50 ms where the board ticks it without a chip, else after the watchdog's reset)",
                    look,
                    defmt::Debug2Format(&undetected.reason)
                );
            }
            return Err(undetected.bus);
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
    defmt::info!(
        "triad firmware: {} at {} Hz, {} per interrupt, decimation {}",
        sensor.name(),
        sensor.sample_rate_hz() as u32,
        SETTINGS.watermark,
        B::DESCRIPTION.decimation
    );
    Ok(sensor)
}

/// The device's facts for a chip named `chip` of `scale` sampling at `rate_hz`.
fn facts(chip: &'static str, scale: ImuScale, rate_hz: f64) -> DeviceFacts {
    let description = B::DESCRIPTION;
    DeviceFacts {
        firmware: env!("CARGO_PKG_VERSION"),
        board: description.name,
        chip,
        bus: B::BUS,
        sample_rate_hz: rate_hz as f32,
        baud: description.baud,
        scale,
        orientation: description.orientation,
        cycles_hz: B::CYCLES_HZ,
    }
}

/// Chooses the calibration for `sensor` from the store as it was and the
/// built-in one: the sampler built on it, and what the handler learns.
pub fn for_sensor(sensor: &Sensor, store: &StoreAtStart) -> (Sampler, ChipFacts) {
    let scale = sensor.scale();
    let description = B::DESCRIPTION;
    let stored = store.stored.as_ref();
    let startup = match start_calibration(
        stored.map(|b| &b[..]),
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
    let rate_hz = sensor.sample_rate_hz();
    let chip = ChipFacts {
        facts: facts(sensor.name(), scale, rate_hz),
        active: startup.active(stored, CALIBRATION_BLOB),
        stored: startup.stored_state(store.loaded),
        stored_reason: startup.stored_reason(store.loaded),
    };
    let calibrated = startup.calibrated();
    let sampler = Sampler::at_rate(
        startup.corrector,
        calibrated,
        description.decimation,
        rate_hz,
    );
    (sampler, chip)
}

/// One data-ready step of a chip sampling at `rate_hz`, µs (the watermark's
/// samples per step): what the stall watch and the health count in.
pub fn step_us(rate_hz: f64) -> u32 {
    sample_period_us(rate_hz / f64::from(SETTINGS.watermark.max(1)))
}

/// The rate the stall watch counts in while no chip has answered, Hz: the
/// settings' rate, or 1 kHz where the chip's default is to decide (not
/// known before it answers); the firmware looks for the chip at each of
/// the watch's checks, about every 50 ms.
pub fn look_rate_hz() -> f64 {
    SETTINGS.rate_hz.map_or(1000.0, f64::from)
}

/// Opens the calibration store and reads what it holds.
fn open_store(
    flash: Result<<B as Board>::Flash, <B as Board>::StorageUnavailable>,
) -> (Option<CalibrationStore<<B as Board>::Flash>>, StoreAtStart) {
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
    (store, StoreAtStart { stored, loaded })
}

/// Brings the sensor (when one answers), the store and the calibration up.
pub fn start(
    bus: SensorBus,
    flash: Result<<B as Board>::Flash, <B as Board>::StorageUnavailable>,
) -> Started {
    let found = find(bus, 1);
    let (store, at_start) = open_store(flash);
    let decimation = B::DESCRIPTION.decimation;
    match found {
        Ok(sensor) => {
            let (sampler, chip) = for_sensor(&sensor, &at_start);
            let handler =
                CommandHandler::new(chip.facts, chip.active, decimation, store, chip.stored)
                    .with_stored_reason(chip.stored_reason);
            Started {
                sensor: Ok((sensor, sampler)),
                handler,
            }
        }
        Err(bus) => {
            // Nothing is applied until a chip answers: no calibration, no
            // rate, no scale (identify says chip "none").
            let none = triad::sensor::TriadScale {
                si_per_lsb: 0.0,
                full_scale: 0.0,
                codes: triad::sensor::CodeRange::I16,
            };
            let scale = ImuScale {
                accel: none,
                gyro: none,
                temperature_per_lsb: 0.0,
                temperature_offset: 0.0,
            };
            let active = ActiveCalibration {
                blob: None,
                id: 0,
                source: CalibrationSource::None,
            };
            let reason = match at_start.loaded {
                StoredState::Rejected => StoredReason::RecordDamaged,
                _ => StoredReason::None,
            };
            let handler = CommandHandler::new(
                facts(NO_SENSOR, scale, 0.0),
                active,
                decimation,
                store,
                at_start.loaded,
            )
            .with_stored_reason(reason)
            .awaiting_sensor();
            Started {
                sensor: Err(Waiting {
                    bus,
                    store: at_start,
                    looks: 1,
                }),
                handler,
            }
        }
    }
}
