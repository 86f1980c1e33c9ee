//! model placeholder
