//! The self-test through `AnyChip`, the same checks on every listed chip's
//! model, found on the bus as the firmware finds it: a dead axis fails alone
//! and is named; a bus failure mid-test is an error that says the chip was
//! restored, or, when the bus stays down, that it needs `init` (and `start`
//! brings it back); a chip whose output stopped makes it time out, restored;
//! the procedure runs on I²C as on SPI, within the bound the chip states.

mod common;

use std::cell::RefCell;

use common::self_test::{configuration, ActAt, ModelUnderTest, NoisyRest};
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::model::Triad;
use triad::sensor::icm42688::Icm42688Chip;
use triad::sensor::interface::SpiInterface;
use triad::sensor::lsm6dsox::Lsm6dsoxChip;
use triad::sensor::{
    AnyChip, Axis, Chip as _, ChipLeft, ChipSelfTest as _, Error, SelfTestError, SelfTestReport,
};
use triad_sim::chips::fault::Fault;
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::chips::model_clock::{ModelDelay, SharedBus};

/// A chip at rest with 1 mg and 0.1 °/s of noise per sample.
fn rest() -> NoisyRest {
    NoisyRest::new(11, 0.01, 0.002)
}

type Chip<'m, M> = AnyChip<SpiInterface<SharedBus<'m, M>>>;

/// The chip on SPI, found and started with its default configuration.
fn started<M: ModelUnderTest>(model: &RefCell<M>) -> Chip<'_, M> {
    let mut chip = AnyChip::detect(SpiInterface::new(SharedBus(model))).expect("found");
    chip.start(&mut NoopDelay::new()).expect("started");
    chip
}

fn run<M: ModelUnderTest>(model: &RefCell<M>) -> SelfTestReport {
    started(model)
        .self_test(&mut ModelDelay::new(model))
        .expect("finishes")
}

/// Each axis in turn dead: it alone fails, named, and shows (almost) no response.
fn each_dead_axis_fails_alone_and_is_named<M: ModelUnderTest>(new: impl Fn() -> M) {
    for triad in [Triad::Accel, Triad::Gyro] {
        for axis in Axis::ALL {
            let model = RefCell::new(new());
            let emulated = model.borrow().response().get(triad, axis);
            model
                .borrow_mut()
                .inject_fault(Fault::DeadSelfTest { triad, axis });
            let report = run(&model);
            assert_eq!(report.failures().collect::<Vec<_>>(), [(triad, axis)]);
            let result = if triad == Triad::Accel {
                report.accel
            } else {
                report.gyro
            };
            let dead = result.axes[axis.index()];
            assert!(!dead.response_ok && dead.offset_ok, "{dead:?}");
            // Noise only: a few percent of a live axis's response at most.
            assert!(dead.response.abs() < 0.05 * emulated, "{dead:?}");
        }
    }
}

#[test]
fn a_dead_axis_fails_alone_and_is_named_on_every_chip() {
    each_dead_axis_fails_alone_and_is_named(|| Icm42688Model::new(rest()));
    each_dead_axis_fails_alone_and_is_named(|| Lsm6dsoxModel::new(rest()));
}

/// The self-test with `transactions` failing bus transactions from 150 ms
/// in (inside the first triad's passes on both chips).
fn self_test_with_bus_down<M: ModelUnderTest>(
    chip: &mut Chip<'_, M>,
    model: &RefCell<M>,
    transactions: u32,
) -> SelfTestError<embedded_hal::spi::ErrorKind> {
    let mut delay = ActAt::new(model, 150_000_000, |m: &mut M| {
        m.inject_fault(Fault::BusError { transactions })
    });
    chip.self_test(&mut delay).expect_err("the bus failed")
}

fn a_bus_error_mid_test_leaves_the_chip_configured<M: ModelUnderTest>(model: M) {
    let model = RefCell::new(model);
    let mut chip = started(&model);
    let before = configuration(&model);
    let error = self_test_with_bus_down(&mut chip, &model, 1);
    assert!(matches!(error.error, Error::Bus(_)), "{error:?}");
    assert_eq!(error.chip, ChipLeft::AsConfigured, "{}", chip.name());
    assert_eq!(configuration(&model), before, "{}", chip.name());
}

#[test]
fn a_bus_error_mid_test_is_an_error_and_the_chip_is_restored() {
    a_bus_error_mid_test_leaves_the_chip_configured(Icm42688Model::new(rest()));
    a_bus_error_mid_test_leaves_the_chip_configured(Lsm6dsoxModel::new(rest()));
}

fn a_bus_down_leaves_the_chip_needing_init<M: ModelUnderTest>(model: M) {
    let model = RefCell::new(model);
    let mut chip = started(&model);
    let before = configuration(&model);
    let error = self_test_with_bus_down(&mut chip, &model, 1000);
    assert_eq!(error.chip, ChipLeft::NeedsInit, "{}", chip.name());
    model.borrow_mut().clear();
    // As the error says: the chip is still in a self-test configuration...
    assert_ne!(configuration(&model), before, "{}", chip.name());
    // ...and starting it again brings it back.
    chip.start(&mut NoopDelay::new()).expect("started");
    assert_eq!(configuration(&model), before, "{}", chip.name());
}

#[test]
fn a_bus_that_stays_down_leaves_the_chip_needing_init() {
    a_bus_down_leaves_the_chip_needing_init(Icm42688Model::new(rest()));
    a_bus_down_leaves_the_chip_needing_init(Lsm6dsoxModel::new(rest()));
}

fn a_stopped_chip_times_out_and_is_restored<M: ModelUnderTest>(model: M) {
    let model = RefCell::new(model);
    let mut chip = started(&model);
    let before = configuration(&model);
    model.borrow_mut().inject_fault(Fault::StuckOutput);
    let mut delay = ModelDelay::new(&model);
    let error = chip.self_test(&mut delay).expect_err("no new samples");
    assert!(matches!(error.error, Error::NoNewData { .. }), "{error:?}");
    assert_eq!(error.chip, ChipLeft::AsConfigured, "{}", chip.name());
    assert_eq!(configuration(&model), before, "{}", chip.name());
    // It gave up within its stated bound.
    let bound_ns = u64::from(chip.self_test_max_duration_ms()) * 1_000_000;
    assert!(delay.elapsed_ns() <= bound_ns, "{}", chip.name());
}

#[test]
fn a_chip_whose_output_stopped_times_out_and_is_restored() {
    a_stopped_chip_times_out_and_is_restored(Icm42688Model::new(rest()));
    a_stopped_chip_times_out_and_is_restored(Lsm6dsoxModel::new(rest()));
}

/// Found on I²C, started, self-tested: it passes, within the chip's bound.
fn passes_on_i2c<M: ModelUnderTest>(model: M) -> (&'static str, u32) {
    let model = RefCell::new(model);
    let mut chip = AnyChip::detect_i2c(SharedBus(&model)).expect("found");
    chip.start(&mut NoopDelay::new()).expect("started");
    let mut delay = ModelDelay::new(&model);
    let report = chip.self_test(&mut delay).expect("finishes");
    assert!(report.passed(), "{}: {report:?}", chip.name());
    let bound = chip.self_test_max_duration_ms();
    assert!(delay.elapsed_ns() <= u64::from(bound) * 1_000_000);
    (chip.name(), bound)
}

#[test]
fn every_chip_self_tests_on_i2c_within_its_stated_bound() {
    let runs = [
        passes_on_i2c(Icm42688Model::new(rest())),
        passes_on_i2c(Lsm6dsoxModel::new(rest()).with_sa0(true)),
    ];
    let modules = [
        (
            Icm42688Chip::NAME,
            Icm42688Chip::self_test_max_duration_ms(),
        ),
        (
            Lsm6dsoxChip::NAME,
            Lsm6dsoxChip::self_test_max_duration_ms(),
        ),
    ];
    assert_eq!(runs, modules);
}
