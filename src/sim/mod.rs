//! Simulation: what a sensor triad measures in a scene, and the software chips
//! that serve it over a bus.

pub mod source;
