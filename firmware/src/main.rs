//! The triad firmware: an RTIC 2 application that is wiring only. Every
//! decision lives in the core (`triad::device`: which calibration starts, the
//! data-ready step, the command handler), where host tests call it; the board
//! crate (chosen by a cargo feature, seen only through the core's contract
//! `triad::device::board::Board`) owns the peripherals, the sensor's bus
//! (SPI, or I²C with its `bus-i2c` feature) and the calibration flash. The
//! chip is found on that bus by its identity (`triad::sensor::AnyChip`), so
//! nothing here names a chip and one build serves every chip triad drives.
//!
//! Tasks, highest priority first (RTIC 2: every interrupt the firmware
//! uses is bound here, so RTIC's analysis covers them all; state moves
//! between tasks through rtic-sync channels). Each binds one of the fixed
//! names the board's `vectors` module numbers and its memory.x maps to its
//! own vectors (named below as on both boards):
//! - `board_own` (BOARD_OWN), priority 4: the emulated board's sample
//!   timer (TIM2, the chip's data-ready edge), or the NUCLEO's transmit DMA
//!   (DMA1_STREAM6, which ends and starts runs of the transmit ring). Short,
//!   and no shared state: it only wakes the transmitter when room was freed.
//! - `data_ready` (DATA_READY: EXTI0, priority 3): applies the command handler's pending
//!   changes, then reads, corrects, averages and frames one sample; queues
//!   the frame for the transmitter without waiting (dropping and counting
//!   it when the queue is full) and wakes it. Built with a FIFO watermark W > 1
//!   (`TRIAD_FIFO_WATERMARK`), the chip's interrupt signals W samples
//!   waiting, and the task drains the FIFO into batch frames (or per-sample
//!   frames in raw mode or when averaging).
//! - `link_rx` (LINK: USART2's interrupt, priority 2): sends received bytes to the
//!   command task; never waits. On the emulated board it also drains the
//!   transmit ring (QEMU's USART has no DMA).
//! - `commands` (async, priority 1, run from DISPATCH: EXTI1): decodes received commands and answers
//!   each through the core's `CommandHandler`, which writes the reply where
//!   it keeps it; the task encodes it from there to wire bytes in the reply
//!   slot, awaiting the slot while the previous reply is sent (a reply is
//!   never dropped, nor copied between tasks).
//! - `transmit` (async, priority 1): puts replies and frames on the line,
//!   awaiting room in the transmit ring when it is full. Neither async task
//!   spins: each awaits a channel, a queue's waker or the ring's room.
//! - `idle`: sleeps, timing each sleep for the load report; and runs the
//!   chip's self-test when the data-ready task hands it the chip (between
//!   two steps), below every task, so sampling's time, the link and the
//!   commands go on meanwhile. The data-ready task takes the chip back at
//!   the first step after, and the next frame counts the samples the chip
//!   did not measure meanwhile (`overruns`, flag SELF_TEST).
//!
//! Frames go from `data_ready` to `transmit` through a lock-free
//! single-producer queue of slots (`triad::device::SlotQueue`) and a
//! waker, not an rtic-sync channel: a frame is up to 232 bytes, and the
//! channel's send and receive (each a critical section, each a copy of the
//! item, and the executor's wake-up per frame) cost about 90 instructions
//! per sample more at 8 kHz (measured, see docs/BENCHMARKS.md). The sampler
//! writes each batch where it lies in its slot and the transmitter encodes
//! it from there straight into the board's transmit ring where the board
//! lends its free bytes (`LinkTx::queue_encoded`; the emulated board does):
//! no frame is built apart and copied (about 95 instructions per sample at
//! 8 kHz with W = 32, and the copy into the ring about 26). Replies likewise: the command task
//! encodes the reply the handler wrote in place straight into the one
//! reply slot the transmitter reads.
#![no_std]
#![no_main]

// `use triad_board_<name> as board;` for the board the features name (build.rs).
include!(concat!(env!("OUT_DIR"), "/board.rs"));

use triad::device::board::Board as _;
use triad::device::SharedCounters;

/// The board, through its contract (`triad::device::board::Board`).
type B = board::Board;

// The sampling settings chosen at build time (`TRIAD_SAMPLE_RATE_HZ`,
// `TRIAD_FIFO_WATERMARK`, see build.rs): `SETTINGS`.
include!(concat!(env!("OUT_DIR"), "/settings.rs"));

/// The calibration chosen at build time (`TRIAD_CALIBRATION`, see build.rs).
static CALIBRATION_BLOB: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/calibration.bin"));

/// The link's baud rate, exported for `cargo xtask run`, which reads it from
/// this ELF to open the host's port at the board's rate.
#[used]
#[no_mangle]
static TRIAD_LINK_BAUD: u32 = B::DESCRIPTION.baud;

/// Frames waiting for the line; when full, new frames are dropped and counted.
const QUEUE_LEN: usize = 32;
/// Received bytes waiting for the command decoder: two longest packets.
const RX_QUEUE_LEN: usize = 512;

/// The device's counters, written by the tasks that count and read by the
/// command handler.
static COUNTERS: SharedCounters = SharedCounters::new();

mod queue_marks;
mod received;
mod run_time;
mod stall;
mod start;
mod wire;

// The board names its own vectors: RTIC binds the fixed names of its
// `vectors` module, and its memory.x maps its vectors to them.
#[rtic::app(device = crate::board::vectors, dispatchers = [DISPATCH])]
mod app {
    use crate::received::{self, RX_WAKER};
    use crate::wire::{self, ReplyIn, ReplyOut, ReplyWire, OUTGOING, REPLY_ROOM, TX_ROOM};
    use crate::{COUNTERS, QUEUE_LEN, RX_QUEUE_LEN, SETTINGS};
    use heapless::spsc::{Consumer, Producer, Queue};
    use rtic_sync::channel::{Receiver, Sender};
    use rtic_sync::make_channel;
    use triad::device::board::{Board, DataReadyLine, LinkRx, LinkTx};
    use triad::device::{
        on_data_ready, on_fifo_ready, Answer, CommandHandler, Control, LoadWindow, Outgoing,
        Sampler, SensorHealth, StallWatch, Stepped, Task,
    };
    use triad::device::{SlotConsumer, SlotProducer, SlotQueue};
    use triad::protocol::Decoder;
    use triad::protocol::MAX_WIRE_LEN;
    use triad::sensor::{SelfTestError, SelfTestReport};

    /// The board, through its contract.
    type B = crate::B;
    /// The chip's driver.
    type Sensor = crate::start::Sensor;
    /// data_ready → commands: the chip answered late (once).
    type ChipFacts = crate::start::ChipFacts;

    /// A self-test's outcome, with the sequence number of its command.
    type SelfTestDone = (
        u16,
        Result<SelfTestReport, SelfTestError<<B as Board>::SensorBusError>>,
    );

    /// The load goes to the log every this many seconds.
    const LOG_LOAD_EVERY: u32 = 10;

    #[shared]
    struct Shared {}

    #[local]
    struct Local {
        /// The stall watch, made at start-up.
        watch: Option<(u32, StallWatch)>,
        sample_line: <B as Board>::SampleLine,
        clock: <B as Board>::Clock,
        /// The chip: the data-ready task's, but the idle task's while it
        /// runs the chip's self-test (and none until one answers).
        sensor: Option<Sensor>,
        /// The pipeline, from when the chip answered.
        sampler: Option<Sampler>,
        /// No chip has answered yet: the bus to look on, the store as it was.
        waiting: Option<crate::start::Waiting>,
        /// data_ready → commands: the chip answered.
        found_in: Sender<'static, ChipFacts, 1>,
        /// Stalls and restarts of the sensor (the data-ready task's).
        health: SensorHealth,
        /// data_ready → transmit: frames, written in their slots (woken by [`OUTGOING`]).
        frames_in: SlotProducer<'static, Outgoing, QUEUE_LEN>,
        /// commands → data_ready: changes, applied between two samples.
        controls_out: Receiver<'static, Control, 2>,
        /// commands → data_ready: a self-test to run (its sequence number).
        self_tests_out: Receiver<'static, u16, 1>,
        /// data_ready → idle: the chip, for a self-test (its sequence number).
        to_self_test: Sender<'static, (u16, Sensor), 1>,
        /// idle → data_ready: the chip, back from its self-test.
        sensor_back: Receiver<'static, Sensor, 1>,
        // The idle task's: the self-test.
        self_test_delay: <B as Board>::SelfTestDelay,
        self_tests_to_run: Receiver<'static, (u16, Sensor), 1>,
        sensor_back_in: Sender<'static, Sensor, 1>,
        /// idle → commands: a self-test's outcome.
        self_tests_done_in: Sender<'static, SelfTestDone, 1>,
        serial_rx: <B as Board>::SerialRx,
        /// link_rx → commands: received bytes (a byte stream: a lock-free
        /// queue and a waker, where a channel would cost a critical section
        /// per byte).
        rx_in: Producer<'static, u8>,
        // The command task's.
        handler: CommandHandler<<B as Board>::Flash>,
        found_out: Receiver<'static, ChipFacts, 1>,
        decoder: Decoder,
        rx_out: Consumer<'static, u8>,
        /// commands → transmit: the reply slot (woken by [`wire::OUTGOING`]).
        replies: ReplyOut,
        controls_in: Sender<'static, Control, 2>,
        self_tests_in: Sender<'static, u16, 1>,
        self_tests_done_out: Receiver<'static, SelfTestDone, 1>,
        // The transmitter's.
        serial: <B as Board>::Serial,
        frames_out: SlotConsumer<'static, Outgoing, QUEUE_LEN>,
        replies_out: ReplyIn,
    }

    #[init(local = [
        rx: Queue<u8, RX_QUEUE_LEN> = Queue::new(),
        frames: SlotQueue<Outgoing, QUEUE_LEN> = SlotQueue::new(crate::wire::NO_FRAME),
        reply_slot: SlotQueue<ReplyWire, 1> = SlotQueue::new(ReplyWire::EMPTY),
    ])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let b = B::init(cx.device, &SETTINGS);
        let started = crate::start::start(b.sensor_bus, b.flash);
        // One data-ready step per period of the chip's rate over the
        // watermark: what the stall watch and the health count in.
        let (sensor, sampler, waiting) = match started.sensor {
            Ok((sensor, sampler)) => (Some(sensor), Some(sampler), None),
            Err(waiting) => (None, None, Some(waiting)),
        };
        let step_us = crate::start::step_us(
            sensor
                .as_ref()
                .map_or_else(crate::start::look_rate_hz, |s| s.sample_rate_hz()),
        );
        crate::stall::set_tick_us(step_us);
        let (found_in, found_out) = make_channel!(ChipFacts, 1);
        let (frames_in, frames_out) = cx.local.frames.split();
        let (replies, replies_out) = cx.local.reply_slot.split();
        let (rx_in, rx_out) = cx.local.rx.split();
        let (controls_in, controls_out) = make_channel!(Control, 2);
        let (self_tests_in, self_tests_out) = make_channel!(u16, 1);
        let (self_tests_done_in, self_tests_done_out) = make_channel!(SelfTestDone, 1);
        let (to_self_test, self_tests_to_run) = make_channel!((u16, Sensor), 1);
        let (sensor_back_in, sensor_back) = make_channel!(Sensor, 1);
        // Spawning at start-up cannot fail: neither task is running yet.
        let _ = commands::spawn();
        let _ = transmit::spawn();
        // Last: the first data-ready edge a board paces itself comes one
        // period from here, not from part-way through start-up.
        let mut sample_line = b.sample_line;
        sample_line.start();
        (
            Shared {},
            Local {
                watch: Some((step_us, StallWatch::new(step_us))),
                sample_line,
                clock: b.clock,
                sensor,
                sampler,
                waiting,
                found_in,
                health: SensorHealth::new(step_us),
                frames_in,
                controls_out,
                self_tests_out,
                to_self_test,
                sensor_back,
                self_test_delay: b.self_test_delay,
                self_tests_to_run,
                sensor_back_in,
                self_tests_done_in,
                serial_rx: b.serial_rx,
                rx_in,
                handler: started.handler,
                found_out,
                decoder: Decoder::new(),
                rx_out,
                replies,
                controls_in,
                self_tests_in,
                self_tests_done_out,
                serial: b.serial,
                frames_out,
                replies_out,
            },
        )
    }

    /// Sleeps until the next interrupt, timing each sleep: with interrupts
    /// masked, WFI still wakes on a pending one, and the clock is read
    /// before its handler runs, so what is counted is sleep alone. The
    /// window's cycles less the tasks' and this are what no measured task
    /// took: RTIC's dispatch, the async executor, interrupt entry and exit.
    ///
    /// The chip's self-test runs here, below every task, when the
    /// data-ready task hands the chip over: it takes up to 1.4 s of waits
    /// (the data sheets' procedures), during which every task still runs
    /// (the data-ready task keeps the stream's time and counts the samples
    /// not measured, the link answers). Its time is counted as the link's
    /// (the command's work).
    #[idle(local = [self_test_delay, self_tests_to_run, sensor_back_in, self_tests_done_in])]
    fn idle(cx: idle::Context) -> ! {
        let l = cx.local;
        loop {
            if let Ok((sequence, mut sensor)) = l.self_tests_to_run.try_recv() {
                let run = crate::run_time::begin();
                let result = self_test(&mut sensor, l.self_test_delay);
                // Each channel has room: one self-test at a time. The
                // outcome first: the command task (above this one) queues
                // the reply at once, so it goes out before the frame that
                // counts what the self-test missed.
                let _ = l.self_tests_done_in.try_send((sequence, result));
                let _ = l.sensor_back_in.try_send(sensor);
                crate::run_time::end(run, Task::Link);
                continue;
            }
            cortex_m::interrupt::free(|_| {
                // A chip handed over since the look above: no sleep.
                if !l.self_tests_to_run.is_empty() {
                    return;
                }
                let before = B::cycles();
                cortex_m::asm::wfi();
                crate::run_time::slept(B::cycles().wrapping_sub(before));
            });
        }
    }

    /// The chip's self-test; a chip it left needing a restart is restarted.
    fn self_test(
        sensor: &mut Sensor,
        delay: &mut <B as Board>::SelfTestDelay,
    ) -> Result<SelfTestReport, SelfTestError<<B as Board>::SensorBusError>> {
        let result = sensor.self_test(delay);
        if let Err(SelfTestError {
            chip: triad::sensor::ChipLeft::NeedsInit,
            ..
        }) = result
        {
            let mut delay = <B as Board>::Delay::default();
            if sensor.start_with(&mut delay, &SETTINGS).is_err() {
                defmt::error!("the chip did not restart after its self-test");
            }
        }
        result
    }

    /// The board's own interrupt: the emulated board's sample timer (which
    /// pends the data-ready line, as the chip's INT1 does on a real board),
    /// or the NUCLEO's transmit DMA (a run of the transmit ring ended: the
    /// transmitter may have room again). A board whose interrupt ticks once
    /// per data-ready period whatever the chip does (the sample timer) also
    /// keeps the stall watch: a sensor silent for 50 ms gets the data-ready
    /// task pended to check it (the NUCLEO's independent watchdog resets a
    /// board whose data-ready task read no sample for 10 s instead).
    #[task(binds = BOARD_OWN, priority = 4, local = [watch])]
    fn board_own(cx: board_own::Context) {
        let run = crate::run_time::begin();
        let done = B::own_interrupt();
        if done.transmit_room {
            TX_ROOM.wake();
        }
        if done.data_ready_period && crate::stall::tick(cx.local.watch) {
            rtic::pend(crate::board::vectors::Interrupt::DATA_READY);
        }
        // The chip's own edge is the model's time, not the firmware's.
        let task = if done.chip_model {
            Task::ChipModel
        } else {
            Task::Link
        };
        crate::run_time::end(run, task);
    }

    /// The data-ready step, on the IMU's data-ready line (on the emulated
    /// board its sample timer pends it).
    #[task(binds = DATA_READY, priority = 3, local = [sample_line, clock, sensor, sampler, waiting, found_in, health, frames_in, controls_out, self_tests_out, to_self_test, sensor_back, flash_stalls: u32 = 0, load_window: LoadWindow = LoadWindow::new(), windows: u32 = 0, slept_then: u32 = 0])]
    fn data_ready(cx: data_ready::Context) {
        let _step = crate::stall::Step::begin();
        let run = crate::run_time::begin();
        let model = B::model_cycles();
        let mut l = cx.local;
        step(&mut l);
        // The window closes at this step's start (`run.start()`), but its
        // bookkeeping and its log wait until the sample is read, so that
        // they never delay the step's timestamp.
        let closed = l
            .load_window
            .tick(run.start(), B::CYCLES_HZ, &COUNTERS.load);
        let mut slept = 0;
        if closed.is_some() {
            *l.windows += 1;
            let now = crate::run_time::slept_total();
            slept = now.wrapping_sub(*l.slept_then);
            *l.slept_then = now;
        }
        // The second window first (the first full second of steady
        // sampling: `cargo xtask bench` reads it), then every tenth.
        let log = closed.filter(|_| *l.windows % LOG_LOAD_EVERY == 2);
        if let Some(shares) = log {
            let load = COUNTERS.load.load(B::CYCLES_HZ);
            defmt::info!(
                "load ‰: data-ready {}, link {}, receive {}, chip model {}",
                shares[0],
                shares[1],
                shares[2],
                shares[3]
            );
            defmt::info!(
                "load cycles in {=u32} at {=u32} Hz: data-ready {=u32}, link {=u32}, receive {=u32}, chip model {=u32}, asleep {=u32}",
                load.window_cycles,
                load.cycles_hz,
                load.busy_cycles[0],
                load.busy_cycles[1],
                load.busy_cycles[2],
                load.busy_cycles[3],
                slept
            );
            let (frames, received) = crate::queue_marks::marks();
            defmt::info!(
                "queue high-water: frames {=u32} of {=usize}, received bytes {=u32} of {=usize}",
                frames,
                QUEUE_LEN,
                received,
                RX_QUEUE_LEN
            );
        }
        let model = B::model_cycles().wrapping_sub(model);
        crate::run_time::end_with_model(run, Task::DataReady, model);
    }

    /// The data-ready task's work.
    // A frame the channel has no room for comes back (the sampler counts it
    // dropped and carries its events on): the large `Err` is that frame.
    #[allow(clippy::result_large_err)]
    fn step(l: &mut data_ready::LocalResources<'_>) {
        if l.waiting.is_some() {
            look_for_sensor(l);
            return;
        }
        // Never absent once the chip answered (built together).
        let Some(sampler) = l.sampler.as_mut() else {
            return;
        };
        // The handler's changes take effect here, between two samples.
        while let Ok(control) = l.controls_out.try_recv() {
            sampler.apply(control);
        }
        // The flash stalled the CPU since the last step (a save or an erase
        // on a single-bank board): this step's frame carries what was missed.
        let stalls = B::flash_stalls();
        if stalls != *l.flash_stalls {
            *l.flash_stalls = stalls;
            sampler.flash_stalled();
            COUNTERS.publish_flash_stalls(stalls);
        }
        // The chip is away in its self-test (the idle task's): nothing to
        // read until it is back; the sampler counts the samples it missed
        // when it is (SELF_TEST in the next frame).
        let sensor = match l.sensor {
            Some(sensor) => sensor,
            None => match l.sensor_back.try_recv() {
                // The sampler counts what was missed at this step.
                Ok(sensor) => l.sensor.insert(sensor),
                Err(_) => {
                    l.sample_line.acknowledge();
                    return;
                }
            },
        };
        // The stall watch's check: data ready has been silent for 50 ms.
        // Nothing to read; find the chip and configure it again. The steps
        // lost are counted when data ready comes back.
        if crate::stall::take_check() {
            if l.health.stalled() {
                sampler.chip_restarted();
                restart(sensor, l.health);
            }
            COUNTERS.publish_health(l.health.totals());
            return;
        }
        let frames_in = &mut *l.frames_in;
        let (queued, read) = if SETTINGS.watermark > 1 {
            let stepped = on_fifo_ready(
                l.sample_line,
                l.clock,
                sensor,
                sampler,
                |sensor| B::data_ready(sensor, SETTINGS.watermark),
                frames_in,
            );
            if let Some(error) = &stepped.read_failed {
                defmt::warn!("FIFO read failed: {}", defmt::Debug2Format(error));
            }
            (stepped.queued > 0, stepped.read_failed.is_none())
        } else {
            let stepped = on_data_ready(
                l.sample_line,
                l.clock,
                sensor,
                sampler,
                |sensor| B::data_ready(sensor, 1),
                |frame| frames_in.enqueue(frame),
            );
            if let Stepped::ReadFailed(error) = &stepped {
                defmt::warn!("sensor read failed: {}", defmt::Debug2Format(error));
            }
            (
                stepped == Stepped::Queued,
                !matches!(stepped, Stepped::ReadFailed(_)),
            )
        };
        if read {
            B::feed_watchdog();
        }
        if l.health.read(read) {
            sampler.chip_restarted();
            restart(sensor, l.health);
        }
        // The health's totals change only at a stall or a restart, where
        // they are published; the sampler's at every step.
        COUNTERS.publish(sampler.totals(), sampler.uptime_ms());
        crate::queue_marks::frames(frames_in.len());
        if queued {
            OUTGOING.wake();
        }
        // A self-test asked for: the chip goes to the idle task after this
        // step's samples were read, and comes back at a later step.
        if let Ok(sequence) = l.self_tests_out.try_recv() {
            if let Some(sensor) = l.sensor.take() {
                sampler.self_test_began();
                // Empty: the chip is here, so no self-test is under way.
                let _ = l.to_self_test.try_send((sequence, sensor));
            }
        }
    }

    /// No chip has answered yet: at each of the stall watch's checks (about
    /// every 50 ms) look for one on the bus. When one answers it is
    /// started, counted as a restart (found by its identity and
    /// configured), the calibration chosen for it and the sampler built;
    /// the command task learns its facts; its data-ready line then starts
    /// the stream.
    fn look_for_sensor(l: &mut data_ready::LocalResources<'_>) {
        l.sample_line.acknowledge();
        if !crate::stall::take_check() {
            return;
        }
        let Some(waiting) = l.waiting.take() else {
            return;
        };
        let looks = waiting.looks.saturating_add(1);
        match crate::start::find(waiting.bus, looks) {
            Err(bus) => {
                *l.waiting = Some(crate::start::Waiting {
                    bus,
                    store: waiting.store,
                    looks,
                })
            }
            Ok(sensor) => {
                let (sampler, chip) = crate::start::for_sensor(&sensor, &waiting.store);
                let step_us = crate::start::step_us(sensor.sample_rate_hz());
                crate::stall::set_tick_us(step_us);
                *l.health = SensorHealth::new(step_us);
                l.health.restarted(true);
                COUNTERS.publish_health(l.health.totals());
                *l.sampler = Some(sampler);
                *l.sensor = Some(sensor);
                // Sent once: the channel has room.
                let _ = l.found_in.try_send(chip);
                defmt::warn!("sensor found after start-up: streaming");
            }
        }
    }

    /// Finds the chip again by its identity and configures it (what a chip
    /// back from a brown-out needs), counting the restart when it worked.
    fn restart(sensor: &mut Sensor, health: &mut SensorHealth) {
        let mut delay = <B as Board>::Delay::default();
        let restarted = sensor.start_with(&mut delay, &SETTINGS);
        health.restarted(restarted.is_ok());
        COUNTERS.publish_health(health.totals());
        if restarted.is_ok() {
            defmt::warn!("sensor restarted ({} so far)", health.totals().restarts);
        }
    }

    /// The link's interrupt (USART2 on both boards: the NUCLEO's ST-LINK
    /// virtual COM port; QEMU's second serial port). It receives, and on
    /// the emulated board it also transmits what the transmitter queued.
    #[task(binds = LINK, priority = 2, local = [serial_rx, rx_in])]
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
        if received {
            crate::queue_marks::received(rx_in.len());
            RX_WAKER.wake();
        }
        // The transmit ring ran empty: the transmitter may queue more.
        if serial_rx.transmit() {
            TX_ROOM.wake();
        }
        crate::run_time::end(run, Task::Receive);
    }

    /// Answers commands, below the sampling task: awaits each received
    /// byte, and each decoded command's reply goes to the transmitter
    /// (awaiting room: a reply is never dropped). While a self-test runs,
    /// the next commands wait in the channel: the host waits for its reply
    /// anyway.
    #[task(priority = 1, local = [handler, found_out, decoder, rx_out, replies, controls_in, self_tests_in, self_tests_done_out])]
    async fn commands(cx: commands::Context) {
        let l = cx.local;
        loop {
            let byte = received::next_byte(l.rx_out).await;
            let run = crate::run_time::begin();
            // A chip that answered after start-up: its facts and calibration
            // before the next command is handled.
            if let Ok(chip) = l.found_out.try_recv() {
                l.handler
                    .sensor_found(chip.facts, chip.active, chip.stored, chip.stored_reason);
            }
            let Some(completed) = l.decoder.push_command(byte) else {
                crate::run_time::end(run, Task::Link);
                continue;
            };
            let controls_in = &mut *l.controls_in;
            let answer = l
                .handler
                .answer_received(&completed, &COUNTERS, &mut |control| {
                    controls_in.try_send(control).is_ok()
                });
            match answer {
                Answer::Reply(reply) => {
                    crate::run_time::end(run, Task::Link);
                    // Its encoding is timed as the link's in the send.
                    wire::send_reply(l.replies, reply).await;
                }
                Answer::SelfTest { sequence } => {
                    crate::run_time::end(run, Task::Link);
                    if l.self_tests_in.try_send(sequence).is_err() {
                        continue;
                    }
                    let Ok((sequence, result)) = l.self_tests_done_out.recv().await else {
                        return;
                    };
                    let reply = l.handler.self_test_reply(sequence, &result);
                    wire::send_reply(l.replies, &reply).await;
                }
                Answer::Nothing => crate::run_time::end(run, Task::Link),
            }
        }
    }

    /// Puts replies and frames on the line: awaits something to send, then
    /// sends every reply and frame waiting, each encoded where it lies; when
    /// the transmit ring has no room for one, awaits the board's transmit
    /// interrupt freeing some (a frame stays queued meanwhile, so a full
    /// queue makes the data-ready task drop and count new ones).
    #[task(priority = 1, local = [serial, frames_out, replies_out])]
    async fn transmit(cx: transmit::Context) {
        let l = cx.local;
        loop {
            wire::something_to_send(l.frames_out, l.replies_out).await;
            let run = crate::run_time::begin();
            let mut blocked = None;
            if let Some(reply) = l.replies_out.peek() {
                if l.serial.queue(reply.as_bytes()) {
                    l.replies_out.release();
                    REPLY_ROOM.wake();
                } else {
                    blocked = Some(Blocked::Reply);
                }
            }
            while blocked.is_none() {
                let Some(frame) = l.frames_out.peek() else {
                    break;
                };
                // Encoded where the transmitter sends it from: no copy.
                if !l.serial.queue_encoded(|out| frame.to_wire(out)) {
                    blocked = Some(Blocked::Frame);
                    break;
                }
                l.frames_out.release();
            }
            crate::run_time::end(run, Task::Link);
            match blocked {
                Some(Blocked::Reply) => {
                    if let Some(reply) = l.replies_out.peek() {
                        wire::queue(l.serial, reply.as_bytes()).await;
                    }
                    l.replies_out.release();
                    REPLY_ROOM.wake();
                }
                // The frame stays queued: encoded at the next round.
                Some(Blocked::Frame) => wire::room(l.serial, MAX_WIRE_LEN).await,
                None => {}
            }
        }
    }

    /// What the transmit ring had no room for: the reply in its slot, or
    /// the frame at the queue's head (the room of a longest packet).
    enum Blocked {
        Reply,
        Frame,
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    // Nothing in the firmware is meant to panic; if it does, stop loudly.
    B::exit(false)
}
