//! Allan variance of rate data (IEEE Std 952-1997 Annex C; NIST SP 1065).
//!
//! Rate samples y_i (rad/s or m/s², sampled every τ₀) are integrated into the
//! cumulative sums S_k = Σ_{i<k} y_i (S₀ = 0; the "phase" of SP 1065 is τ₀·S).
//! At τ = m·τ₀ the overlapping Allan variance is
//!
//!   σ²(τ) = Σ_{j=0}^{N−2m} (S_{j+2m} − 2S_{j+m} + S_j)² / (2 m² (N − 2m + 1)),
//!
//! and the non-overlapping one keeps only the terms with j a multiple of m.
//!
//! - [`accumulate`]: streaming, at octave m = 1, 2, 4, …, memory bounded by
//!   the largest m (a caller-provided ring), one pass;
//! - [`strided`]: the octaves beyond the ring (m > M), their terms every
//!   m/M samples, in a ring of 2M sums whatever m;
//! - [`direct`]: any m on a record held in memory (every-τ mode, reference sets);
//! - [`chi2`]: the χ² distribution and its quantile;
//! - [`edf`]: equivalent degrees of freedom and confidence intervals;
//! - [`covariance`]: the covariance of the octave estimates under the model;
//! - [`noise_terms`]: the model of Q, N, B, K, R and its types;
//! - [`gls`]: its fit, by generalised least squares with that covariance;
//! - [`grade`]: the sensor grade by the grade tables of THEORY.md.

pub mod accumulate;
pub mod chi2;
mod cholesky;
pub mod covariance;
pub mod direct;
pub mod edf;
pub mod gls;
pub mod grade;
mod nnls;
pub mod noise_terms;
pub mod strided;
mod sum;

pub use sum::{CompensatedLanes, CompensatedSum};
