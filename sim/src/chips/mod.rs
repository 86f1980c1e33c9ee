//! Register-level chip models and what they share: the bus port, the
//! FIFO, the sample clock, faults, self-test, the unmodelled-access log; the
//! emulated board's sensor.

mod chip_model;
#[cfg(feature = "scene-blob")]
pub mod emulated_board;
pub mod fault;
pub mod fault_schedule;
pub mod icm42688_factory_trim;
pub mod icm42688_model;
pub mod icm42688_registers;
pub mod lsm6dsox_model;
pub mod lsm6dsox_registers;
pub mod model_clock;
pub mod packet_fifo;
pub mod register_bus;
pub mod self_test_response;
pub mod sensor_clock;
pub mod source;
pub mod spi_wire;
pub mod unmodelled;
