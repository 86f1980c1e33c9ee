//! A device for the tests: a thread running the core's real command handler
//! and sampler over the emulated board's chip model, as the firmware wires
//! them (receive decoder → `CommandHandler::on_packet` → reply; controls
//! applied between two samples; one `Sampler::step` per sample), streaming
//! onto any byte port that does not block its reads. It logs every frame
//! with the raw sample it was made from, and every control applied.

use std::cell::RefCell;
use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::thread::{self, JoinHandle};
use std::time::Duration;

use triad::device::{
    sample_period_us, start_calibration, ActiveCalibration, CommandHandler, Control, DeviceFacts,
    Handled, Outgoing, Sampler, SharedCounters, StepOutcome,
};
use triad::model::Orientation;
use triad::protocol::Decoder;
use triad::protocol::{CalibrationSource, Mode, Reply, StoredState, MAX_WIRE_LEN};
use triad::sensor::interface::SpiInterface;
use triad::sensor::{AnyChip, Imu, ImuScale, RawSample};
use triad_sim::chips::emulated_board::{source, EmulatedChip};
use triad_sim::chips::model_clock::{ModelDelay, SharedBus};

use super::ram_flash::RamFlash;

/// The byte port the device talks on (reads return `WouldBlock` when empty).
pub trait Port: Read + Write + Send + 'static {}
impl<T: Read + Write + Send + 'static> Port for T {}

/// What the device is built with.
pub struct Options {
    /// The built-in calibration's blob (empty: none).
    pub built_in: Vec<u8>,
    /// Flash for the calibration store (`None`: a board without storage).
    pub flash: Option<RamFlash>,
    /// Replies to drop (0 is the first reply sent), as a lost reply on the line.
    pub drop_replies: Vec<usize>,
    /// Wall time between two samples.
    pub sample_every: Duration,
}

/// A change the sampler took.
#[derive(Clone, Debug, PartialEq)]
pub enum Applied {
    /// A new calibration, by id.
    Calibrate(u32),
    /// A mode.
    Mode(Mode),
    /// A decimation.
    Decimation(u16),
}

/// What the device did.
#[derive(Default)]
pub struct Log {
    /// Each frame sent, with the raw sample of its (last) step.
    pub frames: Vec<(Outgoing, RawSample)>,
    /// The changes applied, in order.
    pub applied: Vec<Applied>,
    /// Replies sent (dropped ones included).
    pub replies: usize,
}

/// A running fake device; stopped when dropped.
pub struct FakeDevice {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    /// What it did so far.
    pub log: Arc<Mutex<Log>>,
    /// The chip's configured scale.
    pub scale: ImuScale,
    /// The chip's sample rate.
    pub rate_hz: f64,
}

/// The chip model the fake carries: the emulated board's first chip, on SPI.
const CHIP: &str = "icm42688";

struct NoDelay;
impl embedded_hal::delay::DelayNs for NoDelay {
    fn delay_ns(&mut self, _: u32) {}
}

/// The chip model, shared by the driver and the self-test's delay (which
/// lets the model's time pass), as the emulated board shares it.
type Model<'m> = &'m RefCell<EmulatedChip>;
type Sensor<'m> = AnyChip<SpiInterface<SharedBus<'m, EmulatedChip>>>;

fn sensor(model: Model<'_>) -> Sensor<'_> {
    let mut sensor = AnyChip::detect(SpiInterface::new(SharedBus(model))).expect("found on SPI");
    sensor.start(&mut NoDelay).expect("the chip model starts");
    sensor
}

impl FakeDevice {
    /// Starts the device on `port`.
    pub fn spawn(port: impl Port, options: Options) -> FakeDevice {
        let stop = Arc::new(AtomicBool::new(false));
        let log = Arc::new(Mutex::new(Log::default()));
        let (flag, device_log) = (Arc::clone(&stop), Arc::clone(&log));
        let (facts, chip) = mpsc::channel();
        // The model lives on the device's thread, which the driver borrows.
        let thread = thread::spawn(move || {
            let model = EmulatedChip::named(CHIP, source::demo).expect("an emulated chip");
            let model = RefCell::new(model);
            let sensor = sensor(&model);
            let _ = facts.send((sensor.scale(), sensor.sample_rate_hz()));
            Device::new(sensor, &model, options, device_log).run(port, &flag)
        });
        let (scale, rate_hz) = chip.recv().expect("the fake device starts");
        FakeDevice {
            stop,
            thread: Some(thread),
            log,
            scale,
            rate_hz,
        }
    }

    /// The changes applied so far, once a change whose reply was just
    /// received has been applied (changes are applied before the next
    /// sample, so after the next frame they are in).
    pub fn applied(&self) -> Vec<Applied> {
        self.wait_frames(1);
        self.log.lock().unwrap().applied.clone()
    }

    /// Waits until the device has sent `n` frames more than now.
    pub fn wait_frames(&self, n: usize) {
        let target = self.log.lock().unwrap().frames.len() + n;
        while self.log.lock().unwrap().frames.len() < target {
            thread::sleep(Duration::from_millis(1));
        }
    }
}

impl Drop for FakeDevice {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The device's state, on its thread.
struct Device<'m> {
    sensor: Sensor<'m>,
    model: Model<'m>,
    sampler: Sampler,
    handler: CommandHandler<RamFlash>,
    counters: SharedCounters,
    decoder: Decoder,
    controls: Vec<Control>,
    drop_replies: Vec<usize>,
    sample_every: Duration,
    log: Arc<Mutex<Log>>,
}

impl<'m> Device<'m> {
    fn new(sensor: Sensor<'m>, model: Model<'m>, options: Options, log: Arc<Mutex<Log>>) -> Self {
        let scale = sensor.scale();
        let rate = sensor.sample_rate_hz();
        let orientation = Orientation::RotationNone;
        let (store, stored_blob, stored) = match &options.flash {
            None => (None, None, StoredState::NoStorage),
            Some(flash) => match flash.stored_blob() {
                Some(blob) => (Some(flash.store()), Some(blob), StoredState::Valid),
                None => (Some(flash.store()), None, StoredState::Empty),
            },
        };
        let startup = start_calibration(
            stored_blob.as_ref().map(|b| &b[..]),
            &options.built_in,
            &scale,
            orientation,
        )
        .expect("the chip's scale is valid");
        let blob = match startup.source {
            CalibrationSource::Stored => stored_blob,
            CalibrationSource::BuiltIn => triad::model::blob::upgrade(&options.built_in),
            _ => None,
        };
        let active = ActiveCalibration {
            blob,
            id: startup.corrector.calibration_id(),
            source: startup.source,
        };
        let calibrated = startup.calibrated();
        let facts = DeviceFacts {
            firmware: "fake-0.0.0",
            board: "fake-board",
            chip: CHIP,
            bus: "spi",
            sample_rate_hz: rate as f32,
            baud: 921_600,
            scale,
            orientation,
            cycles_hz: 1_000_000_000,
        };
        let handler = CommandHandler::new(facts, active, 1, store, stored);
        Self {
            sampler: Sampler::at_rate(startup.corrector, calibrated, 1, rate),
            sensor,
            model,
            handler,
            counters: SharedCounters::new(),
            decoder: Decoder::new(),
            controls: Vec::new(),
            drop_replies: options.drop_replies,
            sample_every: options.sample_every,
            log,
        }
    }

    fn run(mut self, mut port: impl Port, stop: &AtomicBool) {
        let period_us = sample_period_us(self.sensor.sample_rate_hz());
        let mut step: u32 = 0;
        let mut buf = [0u8; 512];
        while !stop.load(Ordering::SeqCst) {
            loop {
                match port.read(&mut buf) {
                    Ok(0) => break,
                    Ok(n) => {
                        for &byte in &buf[..n] {
                            self.received(byte, &mut port, stop);
                        }
                    }
                    Err(e) if e.kind() == ErrorKind::Interrupted => {}
                    Err(_) => break,
                }
            }
            for control in self.controls.drain(..) {
                let applied = match &control {
                    Control::Calibrate(c) => Applied::Calibrate(c.calibration_id()),
                    Control::SetMode(m) => Applied::Mode(*m),
                    Control::SetDecimation(n) => Applied::Decimation(*n),
                };
                self.log.lock().unwrap().applied.push(applied);
                self.sampler.apply(control);
            }
            self.sample(step.wrapping_mul(period_us), &mut port, stop);
            step = step.wrapping_add(1);
            thread::sleep(self.sample_every);
        }
    }

    /// One received byte; a completed command is answered.
    fn received(&mut self, byte: u8, port: &mut impl Port, stop: &AtomicBool) {
        let Some(decoded) = self.decoder.push(byte) else {
            return;
        };
        let bytes = self.decoder.last_packet_bytes().to_vec();
        let controls = &mut self.controls;
        // This queue is never full.
        let mut submit = |c: Control| {
            controls.push(c);
            true
        };
        let handled = self
            .handler
            .on_packet(&decoded, &bytes, &self.counters, &mut submit);
        let reply = match handled {
            Handled::Reply(reply) => reply,
            // The driver's procedure on the chip model, sampling paused.
            Handled::SelfTest { sequence } => {
                let result = self.sensor.self_test(&mut ModelDelay::new(self.model));
                self.handler.self_test_reply(sequence, &result)
            }
            Handled::Nothing => return,
        };
        let n = {
            let mut log = self.log.lock().unwrap();
            log.replies += 1;
            log.replies - 1
        };
        if !self.drop_replies.contains(&n) {
            send_reply(&reply, port, stop);
        }
    }

    /// One sample step: a frame when the decimation completes one.
    fn sample(&mut self, now_us: u32, port: &mut impl Port, stop: &AtomicBool) {
        self.model.borrow_mut().advance_one_sample();
        // The step reads the same registers again: the model only changes
        // when it advances.
        let raw = self.sensor.read_sample().expect("the model reads");
        let outcome = self.sampler.step(&mut self.sensor, now_us);
        if let StepOutcome::Frame(frame) = outcome {
            let mut wire = [0u8; MAX_WIRE_LEN];
            let n = frame.to_wire(&mut wire);
            // Logged before it goes out, so a test that read the frame
            // finds it in the log.
            self.log.lock().unwrap().frames.push((frame, raw));
            if !write_frame(&wire[..n], port, stop) {
                self.log.lock().unwrap().frames.pop();
                self.sampler.frame_dropped(&frame);
            }
        }
        self.counters
            .publish(self.sampler.totals(), self.sampler.uptime_ms());
    }
}

/// Writes all of `bytes`, waiting while the port is full (a reply is never
/// dropped); gives up only when the device stops.
fn write_all(bytes: &[u8], port: &mut impl Port, stop: &AtomicBool) {
    let mut done = 0;
    while done < bytes.len() && !stop.load(Ordering::SeqCst) {
        match port.write(&bytes[done..]) {
            Ok(n) => done += n,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) => {
                thread::sleep(Duration::from_micros(200));
            }
            Err(_) => return,
        }
    }
}

fn send_reply(reply: &Reply, port: &mut impl Port, stop: &AtomicBool) {
    let packet = reply.to_packet().expect("a reply fits in a packet");
    let mut wire = [0u8; MAX_WIRE_LEN];
    let n = packet.to_wire(&mut wire);
    write_all(&wire[..n], port, stop);
}

/// Sends a frame unless the port is full when it starts (the firmware drops
/// a frame its queue cannot take); a frame started is finished.
fn write_frame(bytes: &[u8], port: &mut impl Port, stop: &AtomicBool) -> bool {
    match port.write(bytes) {
        Ok(n) => {
            write_all(&bytes[n..], port, stop);
            true
        }
        Err(_) => false,
    }
}
