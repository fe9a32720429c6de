//! Geometric stiffness of the bilateral constraints for the exact linearization: the derivative
//! `∂(Gᵀ λ*)/∂q V` of the constraint forces at the multipliers λ* of the point, held fixed.
//!
//! With `M u̇ − h = Gᵀ λ` holding at every q (eq. 2.70 solved by `dynamics::constrained`), its
//! derivative along `V_j` premultiplied by `Vᵀ` (`Vᵀ Gᵀ = 0` removes `∂λ/∂q`) gives
//! `Vᵀ ∂ID/∂q V_j − Vᵀ ∂(Gᵀ)/∂q[V_j] λ* = −Vᵀ M ∂u̇/∂q V_j`: the turning of the constraint
//! directions under a load λ* acts as a stiffness (the pendulum held by a rod gets its `m g / l`
//! from it). `G` is assembled per constraint kind by `constraints::positions`, in f64 only, so
//! this term is differenced rather than carried by dual numbers: five-point central differences
//! along `q* ⊕ s V_j` (`Model::integrate`), `f' ≈ (8 (f(h) − f(−h)) − (f(2h) − f(−2h))) / 12h`,
//! step `h = 1e-3`. Truncation `h⁴/30 |f⁽⁵⁾|` is ~3e-14 and round-off `1.5 ε |f| / h` ~3e-13 of
//! the load for geometry of metre scale: about 1e-12 relative, against ~1e-10 for the three-point
//! differences of the whole dynamics. `G` does not depend on u (holonomic rows, and velocity rows
//! `W(q, t)ᵀ u`), so no velocity term arises.

use nalgebra::{DMatrix, DVector};

use crate::data::Data;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::model::Model;

/// Step of the five-point differences along the chart (rad or m).
const STEP: f64 = 1e-3;

/// `∂(Gᵀ λ)/∂q V` (nu × n) at (t, q) for fixed `lambda` (nc).
pub(super) fn constraint_load_derivative(
    model: &Model,
    t: f64,
    q: &[f64],
    lambda: &[f64],
    v: &DMatrix<f64>,
    cb: &dyn Callbacks,
) -> Result<DMatrix<f64>> {
    let (nq, nu, n) = (model.nq, model.nu, v.ncols());
    let mut data = Data::new(model);
    let lambda = DVector::from_column_slice(lambda);
    let (mut qp, mut dir) = (vec![0.0; nq], vec![0.0; nu]);
    let mut out = DMatrix::zeros(nu, n);
    for j in 0..n {
        for i in 0..nu {
            dir[i] = v[(i, j)];
        }
        let mut acc = DVector::zeros(nu);
        for (s, w) in [(2.0, -1.0), (1.0, 8.0), (-1.0, -8.0), (-2.0, 1.0)] {
            model.integrate(q, &dir, s * STEP, &mut qp);
            model.normalize(&mut qp);
            crate::kinematics::positions(model, &mut data, &qp);
            crate::constraints::positions(model, &mut data, t, &qp, cb)?;
            acc.gemv_tr(w, &data.g, &lambda, 1.0);
        }
        out.set_column(j, &(acc / (12.0 * STEP)));
    }
    Ok(out)
}
