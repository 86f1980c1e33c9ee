//! The triad firmware: an RTIC 2 application that is wiring only. Every
//! decision lives in the core (`triad::device`, `triad::model`,
//! `triad::stream`), where host tests call it; the board module
//! (a crate under boards/, chosen by a cargo feature) owns the peripherals
//! and the sensor: its chip and bus are cargo features too (`sensor-*`,
//! `bus-*`), which the board turns into `board::Sensor` and
//! `board::sensor_config()`, so nothing here names a chip.
#![no_std]
#![no_main]

#[cfg(feature = "board-nucleo-f401re")]
use triad_board_nucleo_f401re as board;
#[cfg(feature = "board-qemu")]
use triad_board_qemu as board;

/// The calibration chosen at build time (`TRIAD_CALIBRATION`, see build.rs).
static CALIBRATION_BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/calibration.bin"));

/// Frames waiting for the link; when full, new frames are dropped and counted.
const QUEUE_LEN: usize = 32;

/// Re-fold temperature terms ten times a second.
const REFOLD_EVERY: u32 = board::SAMPLE_RATE_HZ / 10;

#[rtic::app(device = crate::board::pac, dispatchers = [EXTI3, EXTI4])]
mod app {
    use crate::{board, CALIBRATION_BLOB, QUEUE_LEN, REFOLD_EVERY};
    use heapless::spsc::{Consumer, Producer, Queue};
    use triad::device::{Sampler, StepOutcome};
    use triad::model::{blob, Calibration, Corrector};
    use triad::sensor::Imu;
    use triad::stream::{encode, Frame, MAX_ENCODED_LEN};

    #[shared]
    struct Shared {}

    #[local]
    struct Local {
        sample_timer: board::SampleTimer,
        clock: board::MicrosecondClock,
        serial: board::Serial,
        sensor: board::Sensor,
        sampler: Sampler,
        frames_in: Producer<'static, Frame>,
        frames_out: Consumer<'static, Frame>,
    }

    #[init(local = [queue: Queue<Frame, QUEUE_LEN> = Queue::new()])]
    fn init(cx: init::Context) -> (Shared, Local) {
        defmt::info!(
            "triad firmware: {} Hz, decimation {}",
            board::SAMPLE_RATE_HZ,
            board::DECIMATION
        );
        let b = board::init(cx.device);
        let mut sensor = b.sensor;
        // Every chip driver's `init(delay, config)`: the board's `Sensor` and
        // `sensor_config()` are of the chosen chip.
        if let Err(error) = sensor.init(&mut board::Delay, &board::sensor_config()) {
            defmt::error!(
                "sensor initialisation failed: {}",
                defmt::Debug2Format(&error)
            );
            board::exit(false);
        }
        let (corrector, calibrated) = load_calibration(&sensor.scale());
        let period_us = 1_000_000 / board::SAMPLE_RATE_HZ;
        let sampler = Sampler::new(
            corrector,
            calibrated,
            board::DECIMATION,
            period_us,
            REFOLD_EVERY,
        );
        let (frames_in, frames_out) = cx.local.queue.split();
        (
            Shared {},
            Local {
                sample_timer: b.sample_timer,
                clock: b.clock,
                serial: b.serial,
                sensor,
                sampler,
                frames_in,
                frames_out,
            },
        )
    }

    /// The embedded calibration, checked; on any error the identity with the
    /// UNCALIBRATED flag, so the stream says what it carries.
    fn load_calibration(scale: &triad::sensor::ImuScale) -> (Corrector, bool) {
        let checked = blob::decode(CALIBRATION_BLOB)
            .map_err(|e| defmt::error!("embedded calibration rejected: {}", e))
            .ok()
            .and_then(|cal| {
                Corrector::new(&cal, scale, board::ORIENTATION)
                    .map_err(|e| defmt::error!("embedded calibration invalid: {}", e))
                    .ok()
            });
        match checked {
            Some(corrector) => {
                defmt::info!(
                    "calibration {=u32:#010x} loaded",
                    corrector.calibration_id()
                );
                (corrector, true)
            }
            None => {
                let identity = Corrector::new(&Calibration::identity(0), scale, board::ORIENTATION);
                match identity {
                    Ok(corrector) => (corrector, false),
                    Err(_) => {
                        defmt::error!("the chip's scale is invalid: stopping");
                        board::exit(false)
                    }
                }
            }
        }
    }

    #[idle]
    fn idle(_: idle::Context) -> ! {
        loop {
            cortex_m::asm::nop();
        }
    }

    /// The data-ready step: the IMU's data-ready line is EXTI0 on every board
    /// (on the emulated board a timer pends it; see boards/qemu/board.rs).
    #[task(binds = EXTI0, priority = 2, local = [sample_timer, clock, sensor, sampler, frames_in])]
    fn data_ready(cx: data_ready::Context) {
        let l = cx.local;
        sample_step(l.sample_timer, l.clock, l.sensor, l.sampler, l.frames_in);
    }

    /// One step: read, correct, average, frame, queue; count what overran.
    fn sample_step(
        sample_timer: &mut board::SampleTimer,
        clock: &board::MicrosecondClock,
        sensor: &mut board::Sensor,
        sampler: &mut Sampler,
        frames_in: &mut Producer<'static, Frame>,
    ) {
        sample_timer.acknowledge();
        let now_us = clock.now_us();
        board::data_ready(sensor);
        match sampler.step(sensor, now_us) {
            StepOutcome::Frame(frame) => {
                if frames_in.enqueue(frame).is_err() {
                    sampler.frame_dropped(&frame);
                }
                // Already running: it drains the queue, including this frame.
                let _ = send::spawn();
            }
            StepOutcome::Averaging => {}
            StepOutcome::ReadFailed(error) => {
                defmt::warn!("sensor read failed: {}", defmt::Debug2Format(&error))
            }
        }
        if sample_timer.next_step_pending() {
            sampler.overran();
        }
    }

    /// Sends queued frames; runs below the sampling task, which preempts it.
    #[task(priority = 1, local = [serial, frames_out, buffer: [u8; MAX_ENCODED_LEN] = [0; MAX_ENCODED_LEN]])]
    async fn send(cx: send::Context) {
        while let Some(frame) = cx.local.frames_out.dequeue() {
            let len = encode(&frame, cx.local.buffer);
            cx.local.serial.write_all(&cx.local.buffer[..len]);
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    // Nothing in the firmware is meant to panic; if it does, stop loudly.
    board::exit(false)
}
