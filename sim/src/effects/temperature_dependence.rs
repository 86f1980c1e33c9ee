//! Temperature dependence of bias and scale factor, linear about a reference
//! temperature (the first-order terms of data sheets: "zero-g offset
//! temperature coefficient", "sensitivity temperature coefficient").

/// Linear temperature coefficients of one triad.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct TemperatureDependence {
    /// Temperature at which both terms vanish, °C.
    pub reference: f64,
    /// Bias change per °C (SI units of the triad per °C), per axis.
    pub bias_per_degree: [f64; 3],
    /// Relative scale-factor change per °C (1/°C), per axis.
    pub scale_per_degree: [f64; 3],
}

impl TemperatureDependence {
    /// The bias at temperature `t`.
    pub fn bias(&self, t: f64) -> [f64; 3] {
        let dt = t - self.reference;
        [
            self.bias_per_degree[0] * dt,
            self.bias_per_degree[1] * dt,
            self.bias_per_degree[2] * dt,
        ]
    }

    /// The relative scale-factor error at temperature `t`.
    pub fn scale(&self, t: f64) -> [f64; 3] {
        let dt = t - self.reference;
        [
            self.scale_per_degree[0] * dt,
            self.scale_per_degree[1] * dt,
            self.scale_per_degree[2] * dt,
        ]
    }
}
