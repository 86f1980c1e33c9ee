//! The emulated board's sensor: what the simulator serves there (the demo
//! motion or an embedded scene) and each chip model with the configuration
//! the board's driver applies. Here, in the simulator, so that the emulated
//! board (boards/qemu) and the end-to-end test on the host build the very
//! same chip.

pub mod icm42688;
pub mod lsm6dsox;
pub mod source;
