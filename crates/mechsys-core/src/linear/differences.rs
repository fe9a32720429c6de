//! Derivatives of the constrained forward dynamics `u̇(q, u, t)` by central differences along the
//! columns of the minimal-coordinate basis V, in the tangent chart `q* ⊕ s V_j` of
//! `Model::integrate` (quaternions turned by rotation vectors).
//!
//! Step `1e-5` for positions and `1e-5 · max(1, |u|∞)` for velocities: truncation `h²/6 |u̇'''|`
//! and round-off `ε |u̇| / h` meet near 1e-10 relative for smooth force laws (exact for linear
//! ones). Used by `Derivatives::CentralDifferences` and wherever the exact path cannot go
//! (callback forces).

use nalgebra::DMatrix;

use crate::data::Data;
use crate::dynamics::Workspace;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::model::Model;

/// Step of the central differences (positions absolute, velocities relative to `max(1, |u|∞)`).
pub(super) const STEP: f64 = 1e-5;

/// `(∂u̇/∂q V, ∂u̇/∂u V)`, each nu × n, by central differences of `dynamics::forward_dynamics`.
#[allow(clippy::too_many_arguments)]
pub(super) fn acceleration_derivatives(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    v: &DMatrix<f64>,
    cb: &dyn Callbacks,
) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let (nq, nu, n) = (model.nq, model.nu, v.ncols());
    let mut accel = |data: &mut Data, q: &[f64], u: &[f64]| -> Result<Vec<f64>> {
        crate::dynamics::forward_dynamics(model, data, ws, t, q, u, None, cb)?;
        Ok(data.udot.clone())
    };
    let (mut qp, mut up, mut dir) = (vec![0.0; nq], u.to_vec(), vec![0.0; nu]);
    let mut dq = DMatrix::zeros(nu, n);
    let mut du = DMatrix::zeros(nu, n);
    // the velocity step scales with the state so that fast operating points keep their digits
    let hu = STEP * u.iter().fold(1.0f64, |a, x| a.max(x.abs()));
    for j in 0..n {
        for i in 0..nu {
            dir[i] = v[(i, j)];
        }
        // positions: q* ⊕ ±h V_j
        let mut col = [vec![0.0; nu], vec![0.0; nu]];
        for (s, sign) in [1.0, -1.0].iter().enumerate() {
            model.integrate(q, &dir, sign * STEP, &mut qp);
            model.normalize(&mut qp);
            col[s] = accel(data, &qp, u)?;
        }
        for i in 0..nu {
            dq[(i, j)] = (col[0][i] - col[1][i]) / (2.0 * STEP);
        }
        for (s, sign) in [1.0, -1.0].iter().enumerate() {
            for i in 0..nu {
                up[i] = u[i] + sign * hu * dir[i];
            }
            col[s] = accel(data, q, &up)?;
        }
        for i in 0..nu {
            du[(i, j)] = (col[0][i] - col[1][i]) / (2.0 * hu);
        }
    }
    Ok((dq, du))
}
