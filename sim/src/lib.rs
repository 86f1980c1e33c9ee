//! triad-sim: what a sensor triad measures in a scene, and the software chips
//! that serve it over a bus. no_std, so it also runs inside the emulated
//! board; the host simulates in f64 with the same code.
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod averaged_gauss_markov;
pub mod bias;
pub mod bias_instability;
pub mod demo_motion;
#[cfg(feature = "scene-blob")]
pub mod emulated_board;
pub mod fault;
pub mod fibre_optic;
pub mod g_sensitivity;
pub mod gauss_markov;
pub mod grade;
pub mod hand_poses;
pub mod icm42688_factory_trim;
pub mod icm42688_model;
pub mod icm42688_registers;
pub mod increment_quantisation;
pub mod linear_truth;
pub mod lsm6dsox_model;
pub mod lsm6dsox_registers;
pub mod model_clock;
pub mod motion;
pub mod output_lsb;
pub mod packet_fifo;
pub mod random_walk;
pub mod register_bus;
pub mod ring_laser;
pub mod rng;
pub mod rotation;
pub mod saturation;
pub mod scale_misalignment;
pub mod scene;
#[cfg(feature = "scene-blob")]
pub mod scene_blob;
pub mod self_test_response;
pub mod sensor_clock;
pub mod simulator;
pub mod source;
pub mod spi_wire;
pub mod temperature_dependence;
pub mod temperature_profile;
pub mod turn_on;
pub mod unmodelled;
pub mod white_noise;
pub mod ziggurat;
