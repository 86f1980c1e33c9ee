//! One module per parser that takes outside bytes; each target reads the
//! input as that parser's input and checks [`crate::invariants`] after it.

pub mod calibration_blob;
pub mod calibration_toml;
pub mod cobs;
pub mod command_path;
pub mod record_files;
pub mod scene_blob;
pub mod stream_decoder;

pub use calibration_blob::calibration_blob;
pub use calibration_toml::calibration_toml;
pub use cobs::cobs;
pub use command_path::command_path;
pub use scene_blob::scene_blob;
pub use stream_decoder::stream_decoder;
