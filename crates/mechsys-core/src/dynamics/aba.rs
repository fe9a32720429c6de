//! Articulated-body algorithm: forward dynamics `u̇ = M⁻¹ (h + τ)` in O(n) without forming M.
//!
//! Pass 1 (outwards): twists and velocity products (kinematics). Pass 2 (inwards): articulated
//! inertias `I^A` and bias forces `p^A`; across each joint the joint's own motion is eliminated,
//! `I^a = I^A - U D⁻¹ Uᵀ` with `U = I^A S`, `D = Sᵀ U`. Pass 3 (outwards): accelerations.
//! All spatial quantities are in world components about the origin, so passing inertias and forces
//! to the parent is a plain sum.

use nalgebra::{Matrix6, Vector6};

use crate::data::Data;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::model::Model;
use crate::spatial::{Force, Motion};

/// ABA on prepared data (kinematics, inertias, `f_ext`, `tau_applied`); `tau` is an optional extra
/// actuation (length nu). Writes `data.udot` and the body accelerations `data.a` (without gravity).
pub fn aba_prepared(model: &Model, data: &mut Data, tau: Option<&[f64]>) {
    let nb = model.nbodies();
    for i in 1..nb {
        data.ia[i] = data.inertia[i].to_matrix();
        let iv = data.inertia[i].mul_motion(&data.v[i]);
        data.pa[i] = data.v[i].cross_force(&iv) - data.f_ext[i];
    }
    for (ji, j) in model.joints.iter().enumerate().rev() {
        let i = ji + 1;
        let nu = j.nu();
        let parent = j.parent;
        if nu == 1 {
            // the common case, without small-matrix bookkeeping
            let s = data.s[i][0].to_vec6();
            let u_col = data.ia[i] * s;
            let d_inv = 1.0 / s.dot(&u_col);
            let t = data.tau_applied[j.iu] + tau.map_or(0.0, |t| t[j.iu]);
            let ub = t - s.dot(&data.pa[i].to_vec6());
            data.u_mat[i][0] = u_col;
            data.d_inv[i][(0, 0)] = d_inv;
            data.u_bias[i][0] = ub;
            if parent != 0 {
                let mut i_art = data.ia[i];
                i_art.ger(-d_inv, &u_col, &u_col, 1.0);
                let pa = data.pa[i].to_vec6() + i_art * data.c[i].to_vec6() + u_col * (d_inv * ub);
                data.ia[parent] += i_art;
                data.pa[parent] += Force::from_vec6(&pa);
            }
            continue;
        }
        let ia = data.ia[i];
        let pa_a = data.pa[i];
        if nu == 0 {
            if parent != 0 {
                let pa = pa_a.to_vec6() + ia * data.c[i].to_vec6();
                data.ia[parent] += ia;
                data.pa[parent] += Force::from_vec6(&pa);
            }
            continue;
        }
        let mut u_cols = [Vector6::zeros(); 6];
        let mut ub = [0.0; 6];
        for k in 0..nu {
            let s = data.s[i][k];
            u_cols[k] = ia * s.to_vec6();
            let t = data.tau_applied[j.iu + k] + tau.map_or(0.0, |t| t[j.iu + k]);
            ub[k] = t - s.dot(&pa_a);
        }
        let mut d = Matrix6::identity();
        for r in 0..nu {
            for c in 0..nu {
                d[(r, c)] = data.s[i][r].to_vec6().dot(&u_cols[c]);
            }
        }
        // D is symmetric positive definite for a physical body; NaN propagates otherwise and the
        // integrator reports the non-finite state with its time
        let d_inv = d.cholesky().map(|c| c.inverse()).unwrap_or_else(|| Matrix6::from_element(f64::NAN));
        if parent != 0 {
            let mut i_art = ia;
            let mut corr = Vector6::zeros();
            for r in 0..nu {
                let mut du = Vector6::zeros();
                let mut coef = 0.0;
                for c in 0..nu {
                    du += u_cols[c] * d_inv[(c, r)];
                    coef += d_inv[(r, c)] * ub[c];
                }
                i_art -= du * u_cols[r].transpose();
                corr += u_cols[r] * coef;
            }
            let pa = pa_a.to_vec6() + i_art * data.c[i].to_vec6() + corr;
            data.ia[parent] += i_art;
            data.pa[parent] += Force::from_vec6(&pa);
        }
        data.u_mat[i] = u_cols;
        data.d_inv[i] = d_inv;
        data.u_bias[i] = ub;
    }
    data.a[0] = Motion::new(crate::math::Vec3::zeros(), -model.gravity);
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let nu = j.nu();
        let mut a = data.a[j.parent] + data.c[i];
        if nu == 1 {
            let ud = data.d_inv[i][(0, 0)] * (data.u_bias[i][0] - data.u_mat[i][0].dot(&a.to_vec6()));
            data.udot[j.iu] = ud;
            a += data.s[i][0] * ud;
        } else if nu > 1 {
            let ap = a.to_vec6();
            let mut rhs = [0.0; 6];
            for k in 0..nu {
                rhs[k] = data.u_bias[i][k] - data.u_mat[i][k].dot(&ap);
            }
            for r in 0..nu {
                let mut ud = 0.0;
                for c in 0..nu {
                    ud += data.d_inv[i][(r, c)] * rhs[c];
                }
                data.udot[j.iu + r] = ud;
                a += data.s[i][r] * ud;
            }
        }
        data.a[i] = a;
    }
    // report accelerations without the gravity offset: the ground's a = -g was added to all
    data.a[0] = Motion::ZERO;
    for i in 1..nb {
        data.a[i].v += model.gravity;
    }
}

/// Forward dynamics for state (t, q, u) and extra actuation `tau`: fills `data.udot`.
pub fn aba(
    model: &Model,
    data: &mut Data,
    t: f64,
    q: &[f64],
    u: &[f64],
    tau: Option<&[f64]>,
    cb: &dyn Callbacks,
) -> Result<()> {
    super::forward_dynamics(model, data, t, q, u, tau, cb).map(|_| ())
}
