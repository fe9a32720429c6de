//! Jenkins elements as model elements: a linear spring in series with a Coulomb slider (eq. 2.215)
//! on one joint coordinate, alone, several in parallel, or holding the segments of a press-fitted
//! shaft. Validated parameters and the constant matrices of the incremental slider problem; the
//! force stage ([`crate::forces::jenkins`], whose documentation has the mechanics) evaluates them.

use crate::error::{Error, Result};

/// A set of Jenkins elements on one joint velocity (validated; the mechanics are in
/// [`crate::forces::jenkins`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Jenkins {
    /// Name.
    pub name: String,
    /// Joint index.
    pub joint: usize,
    /// Index of the coordinate in q.
    pub iq: usize,
    /// Index of the velocity in u.
    pub iu: usize,
    /// Stiffness of each Jenkins spring.
    pub k: f64,
    /// Slip force of each slider (n).
    pub slip: Vec<f64>,
    /// Shaft segment stiffness (none: elements in parallel).
    pub shaft: Option<f64>,
    /// Joint coordinate at which everything is relaxed.
    pub offset: f64,
    /// First slider of this element in `Data::slider`.
    pub slot: usize,
    /// Chain only: `A⁻¹ b` (n).
    pub(crate) ainv_b: Vec<f64>,
    /// Chain only: `k A⁻¹` (n × n, row-major).
    pub(crate) k_ainv: Vec<f64>,
    /// Chain only: `W = k (E − k A⁻¹)` (n × n, row-major).
    pub(crate) w: Vec<f64>,
}

impl Jenkins {
    /// Builds the element and, for a chain, its constant matrices. Inputs are checked by the caller.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: String,
        joint: usize,
        iq: usize,
        iu: usize,
        k: f64,
        slip: Vec<f64>,
        shaft: Option<f64>,
        offset: f64,
        slot: usize,
    ) -> Result<Self> {
        let n = slip.len();
        let (mut ainv_b, mut k_ainv, mut w) = (vec![], vec![], vec![]);
        if let Some(ks) = shaft {
            // A = K_shaft + k E: the load point joins node 0, node i joins node i + 1 (tridiagonal)
            let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
            for i in 0..n {
                a[(i, i)] = k + ks + if i + 1 < n { ks } else { 0.0 };
                if i + 1 < n {
                    a[(i, i + 1)] = -ks;
                    a[(i + 1, i)] = -ks;
                }
            }
            // A is symmetric positive definite when k, ks > 0 (strictly diagonally dominant)
            let ainv = a.cholesky().map(|c| c.inverse()).ok_or_else(|| {
                Error::Model(format!("Jenkins element '{name}': k and shaft_stiffness must be > 0 (got {k}, {ks})"))
            })?;
            ainv_b = (0..n).map(|i| ainv[(i, 0)] * ks).collect();
            k_ainv = (0..n * n).map(|m| k * ainv[(m / n, m % n)]).collect();
            w = (0..n * n).map(|m| k * (if m / n == m % n { 1.0 } else { 0.0 } - k * ainv[(m / n, m % n)])).collect();
        }
        Ok(Jenkins { name, joint, iq, iu, k, slip, shaft, offset, slot, ainv_b, k_ainv, w })
    }

    /// Number of sliders.
    pub fn len(&self) -> usize {
        self.slip.len()
    }

    /// Whether the element has no slider (never, once validated).
    pub fn is_empty(&self) -> bool {
        self.slip.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn element(slip: Vec<f64>, shaft: Option<f64>) -> Jenkins {
        Jenkins::new("press".into(), 0, 0, 0, 100.0, slip, shaft, 0.0, 0).unwrap()
    }

    #[test]
    fn w_is_symmetric_positive_definite_and_matches_series_springs() {
        // one node: the shaft spring and the Jenkins spring in series, W = k ks / (k + ks)
        let j = element(vec![1.0], Some(300.0));
        assert!((j.w[0] - 100.0 * 300.0 / 400.0).abs() < 1e-12);
        let j = element(vec![1.0; 5], Some(50.0));
        let w = nalgebra::DMatrix::from_row_slice(5, 5, &j.w);
        assert!((&w - w.transpose()).norm() < 1e-12);
        assert!(w.symmetric_eigen().eigenvalues.min() > 0.0);
        // a non-positive stiffness is an error naming the element, not a made-up matrix
        let e = Jenkins::new("press".into(), 0, 0, 0, -100.0, vec![1.0; 3], Some(50.0), 0.0, 0).unwrap_err();
        assert!(e.to_string().contains("'press'"), "{e}");
    }
}
