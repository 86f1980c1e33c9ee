//! The error effects a simulated triad adds to the truth, and the random
//! streams that drive them.

pub mod averaged_gauss_markov;
pub mod bias;
pub mod bias_instability;
pub mod g_sensitivity;
pub mod gauss_markov;
pub mod increment_quantisation;
pub mod linear_truth;
pub mod output_lsb;
pub mod random_walk;
pub mod rng;
pub mod saturation;
pub mod scale_misalignment;
pub mod temperature_dependence;
pub mod turn_on;
pub mod white_noise;
pub mod ziggurat;
