//! The triad firmware: an RTIC 2 application that is wiring only. Every
//! decision lives in the core (`triad::device`: which calibration starts, the
//! data-ready step), where host tests call it; the board crate (chosen by a
//! cargo feature) owns the peripherals and the sensor's bus (SPI, or I²C with
//! the `bus-i2c` feature). The chip is found on that bus by its identity
//! (`triad::sensor::AnyChip`), so nothing here names a chip and one build
//! serves every chip triad drives.
#![no_std]
#![no_main]

#[cfg(feature = "board-nucleo-f401re")]
use triad_board_nucleo_f401re as board;
#[cfg(feature = "board-qemu")]
use triad_board_qemu as board;

/// The calibration chosen at build time (`TRIAD_CALIBRATION`, see build.rs).
static CALIBRATION_BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/calibration.bin"));

/// The link's baud rate, exported for `cargo xtask run`, which reads it from
/// this ELF to open the host's port at the board's rate.
#[used]
#[no_mangle]
static TRIAD_LINK_BAUD: u32 = board::DESCRIPTION.baud;

/// Frames waiting for the link; when full, new frames are dropped and counted.
const QUEUE_LEN: usize = 32;

#[rtic::app(device = crate::board::pac, dispatchers = [EXTI3, EXTI4])]
mod app {
    use crate::{board, CALIBRATION_BLOB, QUEUE_LEN};
    use heapless::spsc::{Consumer, Producer, Queue};
    use triad::device::board::LinkTx;
    use triad::device::{on_data_ready, start_calibration, Outgoing, Sampler, Stepped};
    use triad::link::MAX_WIRE_LEN;
    use triad::sensor::Imu;

    #[shared]
    struct Shared {}

    #[local]
    struct Local {
        sample_line: board::SampleLine,
        clock: board::MicrosecondClock,
        serial: board::Serial,
        sensor: board::Sensor,
        sampler: Sampler,
        frames_in: Producer<'static, Outgoing>,
        frames_out: Consumer<'static, Outgoing>,
    }

    #[init(local = [queue: Queue<Outgoing, QUEUE_LEN> = Queue::new()])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let b = board::init(cx.device);
        let mut sensor = match board::find_sensor(b.sensor_bus) {
            Ok(sensor) => sensor,
            Err(error) => {
                defmt::error!("no known IMU on the bus: {}", defmt::Debug2Format(&error));
                board::exit(false)
            }
        };
        if let Err(error) = sensor.start(&mut board::Delay) {
            defmt::error!(
                "{} initialisation failed: {}",
                sensor.name(),
                defmt::Debug2Format(&error)
            );
            board::exit(false);
        }
        let rate_hz = sensor.sample_rate_hz();
        let description = board::DESCRIPTION;
        defmt::info!(
            "triad firmware: {} at {} Hz, decimation {}",
            sensor.name(),
            rate_hz as u32,
            description.decimation
        );
        let startup = match start_calibration(
            None,
            CALIBRATION_BLOB,
            &sensor.scale(),
            description.orientation,
        ) {
            Ok(startup) => startup,
            Err(error) => {
                defmt::error!("the chip's scale is invalid: {}; stopping", error);
                board::exit(false)
            }
        };
        if let Some(rejection) = startup.rejected {
            defmt::error!("built-in calibration rejected: {}", rejection);
        }
        defmt::info!(
            "calibration {=u32:#010x} ({})",
            startup.corrector.calibration_id(),
            startup.source
        );
        let calibrated = startup.calibrated();
        let sampler = Sampler::at_rate(
            startup.corrector,
            calibrated,
            description.decimation,
            rate_hz,
        );
        let (frames_in, frames_out) = cx.local.queue.split();
        (
            Shared {},
            Local {
                sample_line: b.sample_line,
                clock: b.clock,
                serial: b.serial,
                sensor,
                sampler,
                frames_in,
                frames_out,
            },
        )
    }

    #[idle]
    fn idle(_: idle::Context) -> ! {
        loop {
            cortex_m::asm::nop();
        }
    }

    /// The data-ready step: the IMU's data-ready line is EXTI0 on every board
    /// (on the emulated board a timer pends it).
    #[task(binds = EXTI0, priority = 2, local = [sample_line, clock, sensor, sampler, frames_in])]
    fn data_ready(cx: data_ready::Context) {
        let l = cx.local;
        let frames_in = l.frames_in;
        let stepped = on_data_ready(
            l.sample_line,
            l.clock,
            l.sensor,
            l.sampler,
            board::data_ready,
            |frame| frames_in.enqueue(frame),
        );
        match stepped {
            // Already running: it drains the queue, including this frame.
            Stepped::Queued => {
                let _ = send::spawn();
            }
            Stepped::Dropped | Stepped::Averaging => {}
            Stepped::ReadFailed(error) => {
                defmt::warn!("sensor read failed: {}", defmt::Debug2Format(&error))
            }
        }
    }

    /// Sends queued frames; runs below the sampling task, which preempts it.
    #[task(priority = 1, local = [serial, frames_out, buffer: [u8; MAX_WIRE_LEN] = [0; MAX_WIRE_LEN]])]
    async fn send(cx: send::Context) {
        while let Some(frame) = cx.local.frames_out.dequeue() {
            let len = frame.to_wire(cx.local.buffer);
            cx.local.serial.write_all(&cx.local.buffer[..len]);
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    // Nothing in the firmware is meant to panic; if it does, stop loudly.
    board::exit(false)
}
