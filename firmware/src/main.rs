//! The triad firmware: an RTIC 2 application that is wiring only. Every
//! decision lives in the core (`triad::device`: which calibration starts, the
//! data-ready step, the command handler), where host tests call it; the board
//! crate (chosen by a cargo feature) owns the peripherals, the sensor's bus
//! (SPI, or I²C with the `bus-i2c` feature) and the calibration flash. The
//! chip is found on that bus by its identity (`triad::sensor::AnyChip`), so
//! nothing here names a chip and one build serves every chip triad drives.
//!
//! Tasks, highest priority first:
//! - `link_rx` (USART2's interrupt, priority 3): moves received bytes into
//!   a queue; never waits.
//! - `data_ready` (EXTI0, priority 2): applies the command handler's pending
//!   changes, then reads, corrects, averages and frames one sample; queues
//!   the frame (dropping and counting it when the queue is full). Built with
//!   a FIFO watermark W > 1 (`TRIAD_FIFO_WATERMARK`), the chip's interrupt
//!   signals W samples waiting, and the task drains the FIFO into batch
//!   frames (or per-sample frames in raw mode or when averaging).
//! - `link` (EXTI1, priority 1): decodes received commands and answers each
//!   through the core's `CommandHandler`, and sends queued frames. It runs
//!   below `data_ready`, which preempts it: the sampling task never waits on
//!   a command, a save or the transmitter.
#![no_std]
#![no_main]

#[cfg(feature = "board-nucleo-f401re")]
use triad_board_nucleo_f401re as board;
#[cfg(feature = "board-qemu")]
use triad_board_qemu as board;

use triad::device::SharedCounters;

// The sampling settings chosen at build time (`TRIAD_SAMPLE_RATE_HZ`,
// `TRIAD_FIFO_WATERMARK`, see build.rs): `SETTINGS`.
include!(concat!(env!("OUT_DIR"), "/settings.rs"));

/// The calibration chosen at build time (`TRIAD_CALIBRATION`, see build.rs).
static CALIBRATION_BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/calibration.bin"));

/// The link's baud rate, exported for `cargo xtask run`, which reads it from
/// this ELF to open the host's port at the board's rate.
#[used]
#[no_mangle]
static TRIAD_LINK_BAUD: u32 = board::DESCRIPTION.baud;

/// Frames waiting for the link; when full, new frames are dropped and counted.
const QUEUE_LEN: usize = 32;
/// Received bytes waiting for the command decoder: two longest packets.
const RX_QUEUE_LEN: usize = 512;

/// The sensor bus's name, as `identify` reports it.
#[cfg(feature = "bus-i2c")]
const BUS: &str = "i2c";
/// The sensor bus's name, as `identify` reports it.
#[cfg(not(feature = "bus-i2c"))]
const BUS: &str = "spi";

/// The device's counters, written by the tasks that count and read by the
/// command handler.
static COUNTERS: SharedCounters = SharedCounters::new();

mod run_time;
mod start;

#[rtic::app(device = crate::board::pac, dispatchers = [EXTI3])]
mod app {
    use crate::{board, COUNTERS, QUEUE_LEN, RX_QUEUE_LEN, SETTINGS};
    use heapless::spsc::{Consumer, Producer, Queue};
    use triad::device::board::{LinkRx, LinkTx};
    use triad::device::{
        on_data_ready, on_fifo_ready, CommandHandler, Control, Handled, LoadWindow, Outgoing,
        Sampler, Stepped, Task,
    };
    use triad::link::MAX_WIRE_LEN;
    use triad::sensor::{SelfTestError, SelfTestReport};
    use triad::stream::Decoder;

    /// A self-test's outcome, with the sequence number of its command.
    type SelfTestDone = (
        u16,
        Result<SelfTestReport, SelfTestError<board::SensorBusError>>,
    );

    /// The load goes to the log every this many seconds.
    const LOG_LOAD_EVERY: u32 = 10;

    /// The interrupt that runs the `link` task.
    /// (The board names it too: the task below binds EXTI1 by name.)
    const LINK_TASK: board::pac::Interrupt = board::LINK_TASK;

    #[shared]
    struct Shared {}

    #[local]
    struct Local {
        sample_line: board::SampleLine,
        clock: board::MicrosecondClock,
        serial: board::Serial,
        serial_rx: board::SerialRx,
        sensor: board::Sensor,
        sampler: Sampler,
        frames_in: Producer<'static, Outgoing>,
        frames_out: Consumer<'static, Outgoing>,
        rx_in: Producer<'static, u8>,
        rx_out: Consumer<'static, u8>,
        controls_in: Producer<'static, Control>,
        controls_out: Consumer<'static, Control>,
        handler: CommandHandler<board::Flash>,
        decoder: Decoder,
        self_test_delay: board::SelfTestDelay,
        self_tests_in: Producer<'static, u16>,
        self_tests_out: Consumer<'static, u16>,
        self_tests_done_in: Producer<'static, SelfTestDone>,
        self_tests_done_out: Consumer<'static, SelfTestDone>,
    }

    #[init(local = [
        frames: Queue<Outgoing, QUEUE_LEN> = Queue::new(),
        rx: Queue<u8, RX_QUEUE_LEN> = Queue::new(),
        controls: Queue<Control, 2> = Queue::new(),
        self_tests: Queue<u16, 2> = Queue::new(),
        self_tests_done: Queue<SelfTestDone, 2> = Queue::new(),
    ])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let b = board::init(cx.device, &SETTINGS);
        let started = crate::start::start(b.sensor_bus, b.flash);
        let (frames_in, frames_out) = cx.local.frames.split();
        let (rx_in, rx_out) = cx.local.rx.split();
        let (controls_in, controls_out) = cx.local.controls.split();
        let (self_tests_in, self_tests_out) = cx.local.self_tests.split();
        let (self_tests_done_in, self_tests_done_out) = cx.local.self_tests_done.split();
        (
            Shared {},
            Local {
                sample_line: b.sample_line,
                clock: b.clock,
                serial: b.serial,
                serial_rx: b.serial_rx,
                sensor: started.sensor,
                sampler: started.sampler,
                frames_in,
                frames_out,
                rx_in,
                rx_out,
                controls_in,
                controls_out,
                handler: started.handler,
                decoder: Decoder::new(),
                self_test_delay: b.self_test_delay,
                self_tests_in,
                self_tests_out,
                self_tests_done_in,
                self_tests_done_out,
            },
        )
    }

    /// Sleeps until the next interrupt: the time here is the load report's
    /// idle share.
    #[idle]
    fn idle(_: idle::Context) -> ! {
        loop {
            cortex_m::asm::wfi();
        }
    }

    /// The data-ready step: the IMU's data-ready line is EXTI0 on every board
    /// (on the emulated board a timer pends it).
    #[task(binds = EXTI0, priority = 2, local = [sample_line, clock, sensor, sampler, frames_in, controls_out, self_test_delay, self_tests_out, self_tests_done_in, load_window: LoadWindow = LoadWindow::new(), windows: u32 = 0])]
    fn data_ready(cx: data_ready::Context) {
        let run = crate::run_time::begin();
        let model = board::model_cycles();
        let l = cx.local;
        // The window closes here; its log waits until the sample is read,
        // so that writing it does not delay the step's timestamp.
        let closed = l
            .load_window
            .tick(run.start(), board::CYCLES_HZ, &COUNTERS.load);
        if closed.is_some() {
            *l.windows += 1;
        }
        // The second window first (the first full second of steady
        // sampling: `cargo xtask bench` reads it), then every tenth.
        let log = closed.filter(|_| *l.windows % LOG_LOAD_EVERY == 2);
        step(l);
        if let Some(shares) = log {
            let load = COUNTERS.load.load(board::CYCLES_HZ);
            defmt::info!(
                "load ‰: data-ready {}, link {}, receive {}, chip model {}",
                shares[0],
                shares[1],
                shares[2],
                shares[3]
            );
            defmt::info!(
                "load cycles in {=u32} at {=u32} Hz: data-ready {=u32}, link {=u32}, receive {=u32}, chip model {=u32}",
                load.window_cycles,
                load.cycles_hz,
                load.busy_cycles[0],
                load.busy_cycles[1],
                load.busy_cycles[2],
                load.busy_cycles[3]
            );
        }
        let model = board::model_cycles().wrapping_sub(model);
        crate::run_time::end_with_model(run, Task::DataReady, model);
    }

    /// The data-ready task's work.
    // heapless's `enqueue` gives a frame back when the queue is full (the
    // sampler counts it dropped from it): the large `Err` is that frame.
    #[allow(clippy::result_large_err)]
    fn step(l: data_ready::LocalResources<'_>) {
        // The handler's changes take effect here, between two samples.
        while let Some(control) = l.controls_out.dequeue() {
            l.sampler.apply(control);
        }
        // A self-test runs here, in place of sampling: the steps it takes
        // are counted lost (OVERRUN) in the next frame.
        if let Some(sequence) = l.self_tests_out.dequeue() {
            let result = l.sensor.self_test(l.self_test_delay);
            if let Err(SelfTestError {
                chip: triad::sensor::ChipLeft::NeedsInit,
                ..
            }) = result
            {
                if l.sensor.start_with(&mut board::Delay, &SETTINGS).is_err() {
                    defmt::error!("the chip did not restart after its self-test");
                }
            }
            // The link task takes one self-test at a time: there is room.
            let _ = l.self_tests_done_in.enqueue((sequence, result));
            cortex_m::peripheral::NVIC::pend(LINK_TASK);
            return;
        }
        let frames_in = l.frames_in;
        let queued = if SETTINGS.watermark > 1 {
            let stepped = on_fifo_ready(
                l.sample_line,
                l.clock,
                l.sensor,
                l.sampler,
                |sensor| board::data_ready(sensor, SETTINGS.watermark),
                |frame| frames_in.enqueue(frame).is_ok(),
            );
            if let Some(error) = stepped.read_failed {
                defmt::warn!("FIFO read failed: {}", defmt::Debug2Format(&error));
            }
            stepped.queued > 0
        } else {
            let stepped = on_data_ready(
                l.sample_line,
                l.clock,
                l.sensor,
                l.sampler,
                |sensor| board::data_ready(sensor, 1),
                |frame| frames_in.enqueue(frame),
            );
            if let Stepped::ReadFailed(error) = &stepped {
                defmt::warn!("sensor read failed: {}", defmt::Debug2Format(error));
            }
            stepped == Stepped::Queued
        };
        COUNTERS.publish(l.sampler.totals(), l.sampler.uptime_ms());
        if queued {
            cortex_m::peripheral::NVIC::pend(LINK_TASK);
        }
    }

    /// The link's USART interrupt: USART2 on both boards (the NUCLEO's
    /// ST-LINK virtual COM port; QEMU's second serial port). It receives,
    /// and on the emulated board it also transmits what the link task
    /// queued.
    #[task(binds = USART2, priority = 3, local = [serial_rx, rx_in])]
    fn link_rx(cx: link_rx::Context) {
        let run = crate::run_time::begin();
        let (serial_rx, rx_in) = (cx.local.serial_rx, cx.local.rx_in);
        let mut received = false;
        while let Some(byte) = serial_rx.read() {
            received = true;
            match byte {
                Ok(byte) if rx_in.enqueue(byte).is_ok() => {}
                _ => COUNTERS.rx_overflowed(),
            }
        }
        // The transmit queue ran empty: the link task may queue more.
        if serial_rx.transmit() || received {
            cortex_m::peripheral::NVIC::pend(LINK_TASK);
        }
        crate::run_time::end(run, Task::Receive);
    }

    /// Answers commands and sends frames, below the sampling task. Each
    /// pass handles every byte received, then sends one frame, so neither
    /// starves the other.
    #[task(binds = EXTI1, priority = 1, local = [serial, frames_out, rx_out, handler, decoder, controls_in, self_tests_in, self_tests_done_out, self_test_running: bool = false, buffer: [u8; MAX_WIRE_LEN] = [0; MAX_WIRE_LEN]])]
    fn link(cx: link::Context) {
        let run = crate::run_time::begin();
        serve_link(cx.local);
        crate::run_time::end(run, Task::Link);
    }

    /// The link task's work.
    fn serve_link(l: link::LocalResources<'_>) {
        loop {
            if let Some((sequence, result)) = l.self_tests_done_out.dequeue() {
                *l.self_test_running = false;
                let reply = l.handler.self_test_reply(sequence, &result);
                send_reply(&reply, l.serial, l.buffer);
            }
            // While a self-test runs, commands wait in the queue: the host
            // waits for its reply anyway.
            while !*l.self_test_running {
                let Some(byte) = l.rx_out.dequeue() else {
                    break;
                };
                let Some(decoded) = l.decoder.push(byte) else {
                    continue;
                };
                let controls_in = &mut *l.controls_in;
                let handled = l.handler.on_packet(
                    &decoded,
                    l.decoder.last_packet_bytes(),
                    &COUNTERS,
                    &mut |control| controls_in.enqueue(control).is_ok(),
                );
                match handled {
                    Handled::Reply(reply) => send_reply(&reply, l.serial, l.buffer),
                    Handled::SelfTest { sequence } => {
                        *l.self_test_running = l.self_tests_in.enqueue(sequence).is_ok();
                    }
                    Handled::Nothing => {}
                }
            }
            // A frame goes when the transmit queue has room for it; else it
            // waits in the frame queue (which the data-ready task drops and
            // counts from when it is full) until the queue drains and the
            // USART's interrupt runs this task again.
            let Some(frame) = l.frames_out.peek() else {
                break;
            };
            let n = frame.to_wire(l.buffer);
            if !l.serial.queue(&l.buffer[..n]) {
                break;
            }
            let _ = l.frames_out.dequeue();
        }
    }

    /// Queues a reply whole: replies are never dropped, so this waits for
    /// room (the USART's interrupt, above this task, drains the queue; a
    /// reply is at most 242 bytes, the queue far longer).
    fn send_reply(
        reply: &triad::link::Reply,
        serial: &mut board::Serial,
        buffer: &mut [u8; MAX_WIRE_LEN],
    ) {
        let Ok(packet) = reply.to_packet() else {
            return;
        };
        let n = packet.to_wire(buffer);
        while !serial.queue(&buffer[..n]) {
            cortex_m::asm::nop();
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    // Nothing in the firmware is meant to panic; if it does, stop loudly.
    board::exit(false)
}
