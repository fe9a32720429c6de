//! Derivatives of the constrained forward dynamics `u̇(q, u, t)` by central differences along the
//! columns of the minimal-coordinate basis V, in the tangent chart `q* ⊕ s V_j` of
//! `Model::integrate` (quaternions turned by rotation vectors).
//!
//! Step `1e-5` for positions and `1e-5 · max(1, |u|∞)` for velocities: truncation `h²/6 |u̇'''|`
//! and round-off `ε |u̇| / h` meet near 1e-10 relative for smooth force laws (exact for linear
//! ones). Used by `Derivatives::CentralDifferences` and wherever the exact path cannot go
//! (callback forces, compliant contacts). A compliant contact's force has a kink where its
//! overlap δ is zero; a stiff contact at rest overlaps by less than the step (a micrometre at
//! 1e7 N/m), and a difference across the kink halves its stiffness. The position step is
//! therefore shortened along each direction that moves a compliant contact's point: to a
//! thousandth of its overlap over its rate along the direction, and so that the overlap's
//! curvature along it changes the overlap by less than 1e-8 of itself.

use nalgebra::DMatrix;

use crate::data::Data;
use crate::dynamics::Workspace;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::model::Model;

/// Step of the central differences (positions absolute, velocities relative to `max(1, |u|∞)`).
pub(super) const STEP: f64 = 1e-5;

/// The position step along a direction from the compliant contacts' overlaps at the point
/// (`at`) and at ±`h` ([`crate::forces::compliant_overlaps`]): `h`, or less where an overlap
/// changes along it, so that the difference stays a thousandth of the overlap away from the force
/// law's kink at δ = 0 (about 1e-7 relative in a Hertz stiffness) and the overlap's own curvature
/// along the direction (a ball rocking in a bowl) moves it by less than 1e-8 of itself (a
/// millionth left the rolling ball's rocking frequency 2.5e-6 off; 1e-8 leaves 1e-8); not below
/// 1e-13 m. Also the static equilibrium's Newton stiffness (`mechsys.analysis`) steps by it.
pub fn difference_step(at: &[f64], plus: &[f64], minus: &[f64], h: f64) -> f64 {
    let mut step = h;
    for ((d0, dp), dm) in at.iter().zip(plus).zip(minus) {
        if !(d0.is_finite() && *d0 != 0.0) {
            continue;
        }
        let rate = (dp - dm).abs() / (2.0 * h);
        if rate > 0.0 {
            step = step.min(1e-3 * d0.abs() / rate);
        }
        let curvature = (dp + dm - 2.0 * d0).abs() / (h * h);
        if curvature > 0.0 {
            step = step.min((1e-8 * d0.abs() / curvature).sqrt());
        }
    }
    step.max(1e-13)
}

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
    // the compliant contacts' overlaps at the point, and at each difference's ends
    let overlaps = |data: &Data| -> Vec<f64> { crate::forces::compliant_overlaps(model, data) };
    accel(data, q, u)?;
    let at = overlaps(data);
    let mut ends: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
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
        let mut h = STEP;
        for pass in 0..2 {
            for (s, sign) in [1.0, -1.0].iter().enumerate() {
                model.integrate(q, &dir, sign * h, &mut qp);
                model.normalize(&mut qp);
                col[s] = accel(data, &qp, u)?;
                ends[s] = overlaps(data);
            }
            // a stiff contact at rest overlaps by less than STEP (a micrometre at 1e7 N/m): a
            // difference across its kink at δ = 0 halves its stiffness, so step again, shorter
            let shorter = difference_step(&at, &ends[0], &ends[1], h);
            if pass == 1 || shorter >= h {
                break;
            }
            h = shorter;
        }
        for i in 0..nu {
            dq[(i, j)] = (col[0][i] - col[1][i]) / (2.0 * h);
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
