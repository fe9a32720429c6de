//! Recursive Newton–Euler algorithm: inverse dynamics in O(n).
//!
//! Outward pass: body accelerations from the joint accelerations (eqs. 2.56–2.58); per body the
//! Newton–Euler equations (momentum and moment of momentum, section 2.3), here in world components
//! about the origin, `f_i = I_i a_i + v_i ×* I_i v_i - f_ext,i`; inward pass: cut forces summed
//! towards the root (cut principle, section 2.1.2) and projected on the joint axes, `τ_i = S_iᵀ f_i`.

use crate::data::Data;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::model::Model;
use crate::spatial::Motion;

/// Core of the RNEA on prepared data (kinematics, inertias and `f_ext`, `tau_applied` filled):
/// writes `out = M udot - h` (the extra generalized forces needed to produce `udot`).
pub fn rnea_prepared(model: &Model, data: &mut Data, udot: &[f64], out: &mut [f64]) {
    data.a[0] = Motion::ZERO;
    crate::kinematics::accelerations(model, data, udot);
    rnea_inward(model, data, out);
}

/// The Newton–Euler equations and the inward pass on the accelerations in `data.a` (without
/// gravity, which enters as the d'Alembert term `-I g`): `out = Sᵀ f - τ_applied`.
pub fn rnea_inward(model: &Model, data: &mut Data, out: &mut [f64]) {
    let g = Motion::new(crate::math::Vec3::zeros(), model.gravity);
    for i in 1..model.nbodies() {
        let iv = data.inertia[i].mul_motion(&data.v[i]);
        data.f[i] = data.inertia[i].mul_motion(&(data.a[i] - g)) + data.v[i].cross_force(&iv) - data.f_ext[i];
    }
    if !model.elastic.is_empty() {
        crate::elastic::rnea_terms(model, data, out);
    }
    for (ji, j) in model.joints.iter().enumerate().rev() {
        let i = ji + 1;
        for k in 0..j.nu() {
            out[j.iu + k] = data.s[i][k].dot(&data.f[i]) - data.tau_applied[j.iu + k];
        }
        if j.parent != 0 {
            let fi = data.f[i];
            data.f[j.parent] += fi;
        }
    }
}

/// Inverse dynamics: the generalized forces τ, beyond those of the model's force elements, that
/// produce the accelerations `udot` in state (t, q, u): `τ = M u̇ - h`.
#[allow(clippy::too_many_arguments)]
pub fn inverse_dynamics(
    model: &Model,
    data: &mut Data,
    ws: &mut super::Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    udot: &[f64],
    cb: &dyn Callbacks,
    tau: &mut [f64],
) -> Result<()> {
    super::prepare(model, data, ws, t, q, u, cb)?;
    rnea_prepared(model, data, udot, tau);
    Ok(())
}

/// Alias of [`inverse_dynamics`] under the algorithm's name.
pub use inverse_dynamics as rnea;

/// `h(q, u, t)`, all forces of the model in generalized components (`-rnea` at zero acceleration);
/// stores it in `data.h`.
pub fn nonlinear_effects(
    model: &Model,
    data: &mut Data,
    ws: &mut super::Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
) -> Result<()> {
    super::prepare(model, data, ws, t, q, u, cb)?;
    let mut tmp = std::mem::take(&mut data.scratch_u);
    let zero = std::mem::take(&mut data.zero_u);
    rnea_prepared(model, data, &zero, &mut tmp);
    for (h, x) in data.h.iter_mut().zip(&tmp) {
        *h = -x;
    }
    data.scratch_u = tmp;
    data.zero_u = zero;
    Ok(())
}
