//! Linear least squares by QR, one row at a time (Givens rotations), in
//! fixed-size arrays: no allocation, any number of rows.
//!
//! Each row [a | y] of the system A·x ≈ y is rotated into the upper
//! triangular R (N×N) and Qᵀy; what is left of y after the rotations is that
//! row's share of the residual, so ‖A·x̂ − y‖² accumulates as rows arrive.
//! This is the orthogonal factorisation A = Q·R without storing Q or A, so it
//! keeps the accuracy of QR (errors ∝ κ(A), where the normal equations AᵀA
//! would square it). References: Golub & Van Loan, Matrix Computations,
//! 4th ed., §5.1.8–5.1.9 (Givens rotations) and §5.3 (the LS problem).
#![allow(clippy::needless_range_loop)] // index form reads as the textbook algorithm

/// Why a least-squares problem has no unique solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LsError {
    /// Fewer rows than unknowns.
    TooFewRows {
        /// Rows given.
        rows: usize,
        /// Unknowns.
        unknowns: usize,
    },
    /// A column of A is zero or a combination of the others: R has a zero
    /// (or, relative to its column, negligible) diagonal entry.
    RankDeficient {
        /// The first unknown (0-based) that the data do not determine.
        unknown: usize,
    },
}

impl core::fmt::Display for LsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            LsError::TooFewRows { rows, unknowns } => {
                write!(f, "{rows} equations for {unknowns} unknowns")
            }
            LsError::RankDeficient { unknown } => {
                write!(
                    f,
                    "parameter {unknown} is not determined by the data (rank deficient)"
                )
            }
        }
    }
}

/// Incremental QR least squares with N unknowns.
#[derive(Clone, Copy, Debug)]
pub struct GivensLs<const N: usize> {
    r: [[f64; N]; N],
    qty: [f64; N],
    rss: f64,
    rows: usize,
}

impl<const N: usize> Default for GivensLs<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> GivensLs<N> {
    /// An empty problem.
    pub const fn new() -> Self {
        Self {
            r: [[0.0; N]; N],
            qty: [0.0; N],
            rss: 0.0,
            rows: 0,
        }
    }

    /// Adds the equation a·x ≈ y.
    pub fn add_row(&mut self, mut a: [f64; N], mut y: f64) {
        for k in 0..N {
            if a[k] == 0.0 {
                continue;
            }
            let rkk = self.r[k][k];
            let h = libm::hypot(rkk, a[k]);
            let (c, s) = (rkk / h, a[k] / h);
            self.r[k][k] = h;
            a[k] = 0.0;
            for j in k + 1..N {
                let rkj = self.r[k][j];
                self.r[k][j] = c * rkj + s * a[j];
                a[j] = c * a[j] - s * rkj;
            }
            let q = self.qty[k];
            self.qty[k] = c * q + s * y;
            y = c * y - s * q;
        }
        self.rss += y * y;
        self.rows += 1;
    }

    /// Rows added so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// ‖A·x̂ − y‖² at the least-squares solution x̂.
    pub fn residual_sum_of_squares(&self) -> f64 {
        self.rss
    }

    /// The triangular factor R (AᵀA = RᵀR).
    pub fn r(&self) -> &[[f64; N]; N] {
        &self.r
    }

    /// Checks that R is of full rank: every diagonal entry must exceed
    /// `N·ε` times the norm of its column (below that it is rounding noise).
    fn check_rank(&self) -> Result<(), LsError> {
        if self.rows < N {
            return Err(LsError::TooFewRows {
                rows: self.rows,
                unknowns: N,
            });
        }
        for k in 0..N {
            let norm = column_norm(&self.r, k);
            if norm == 0.0 || self.r[k][k].abs() <= N as f64 * f64::EPSILON * norm {
                return Err(LsError::RankDeficient { unknown: k });
            }
        }
        Ok(())
    }

    /// The least-squares solution x̂ (back substitution R·x = Qᵀy).
    pub fn solve(&self) -> Result<[f64; N], LsError> {
        self.check_rank()?;
        let mut x = [0.0; N];
        for i in (0..N).rev() {
            let mut sum = self.qty[i];
            for j in i + 1..N {
                sum -= self.r[i][j] * x[j];
            }
            x[i] = sum / self.r[i][i];
        }
        Ok(x)
    }

    /// (AᵀA)⁻¹ = R⁻¹·R⁻ᵀ: times σ² it is the covariance of x̂.
    pub fn inverse_normal_matrix(&self) -> Result<[[f64; N]; N], LsError> {
        self.check_rank()?;
        let ri = upper_inverse(&self.r);
        let mut out = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..N {
                // R⁻¹ is upper triangular: (R⁻¹R⁻ᵀ)_ij = Σ_{k ≥ max(i,j)} R⁻¹_ik R⁻¹_jk.
                let mut s = 0.0;
                for k in i.max(j)..N {
                    s += ri[i][k] * ri[j][k];
                }
                out[i][j] = s;
            }
        }
        Ok(out)
    }

    /// The condition number of A after scaling each column to unit norm,
    /// κ_F = ‖R̃‖_F·‖R̃⁻¹‖_F with R̃ = R·D⁻¹, D = diag(column norms). It is
    /// within a factor √N of the 2-norm condition number κ₂(Ã) (κ₂ ≤ κ_F ≤
    /// N·κ₂), and the column scaling removes the parameters' units, so it
    /// measures how well the data determine the parameters, not their
    /// magnitudes. κ(AᵀA) is its square. `f64::INFINITY` when R is singular.
    pub fn scaled_condition(&self) -> f64 {
        if self.check_rank().is_err() {
            return f64::INFINITY;
        }
        let mut scaled = self.r;
        for j in 0..N {
            let norm = column_norm(&self.r, j);
            for row in scaled.iter_mut() {
                row[j] /= norm;
            }
        }
        let inv = upper_inverse(&scaled);
        let frob = |m: &[[f64; N]; N]| libm::sqrt(m.iter().flatten().map(|x| x * x).sum::<f64>());
        let kappa = frob(&scaled) * frob(&inv);
        if kappa.is_finite() {
            kappa
        } else {
            f64::INFINITY
        }
    }
}

fn column_norm<const N: usize>(r: &[[f64; N]; N], j: usize) -> f64 {
    libm::sqrt((0..=j).map(|i| r[i][j] * r[i][j]).sum::<f64>())
}

/// The inverse of an upper triangular matrix with non-zero diagonal.
fn upper_inverse<const N: usize>(r: &[[f64; N]; N]) -> [[f64; N]; N] {
    let mut inv = [[0.0; N]; N];
    for j in 0..N {
        // Column j of R⁻¹ solves R·x = e_j.
        for i in (0..=j).rev() {
            let mut sum = if i == j { 1.0 } else { 0.0 };
            for k in i + 1..=j {
                sum -= r[i][k] * inv[k][j];
            }
            inv[i][j] = sum / r[i][i];
        }
    }
    inv
}
