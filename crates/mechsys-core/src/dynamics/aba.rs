//! Articulated-body algorithm: forward dynamics `u̇ = M⁻¹ (h + τ)` in O(n) without forming M.
//!
//! Pass 1 (outwards): twists and velocity products (kinematics). Pass 2 (inwards): articulated
//! inertias `I^A` and bias forces `p^A`; across each joint the joint's own motion is eliminated,
//! `I^a = I^A - U D⁻¹ Uᵀ`, `U = I^A S`, `D = Sᵀ U`. Pass 3 (outwards): accelerations.

use nalgebra::{Matrix6, Vector6};

use crate::data::Data;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::model::Model;
use crate::spatial::{inertia6_to_parent, Force, Motion};

/// ABA on prepared data (kinematics, inertias, `f_ext`, `tau_applied`); `tau` is an optional extra
/// actuation (length nu). Writes `data.udot` and the body accelerations `data.a` (gravity removed).
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
        let ia = data.ia[i];
        let mut pa_a = data.pa[i];
        if nu > 0 {
            let s = &data.s[i];
            let mut u_cols = [Vector6::zeros(); 6];
            let mut ub = [0.0; 6];
            for k in 0..nu {
                u_cols[k] = ia * s[k].to_vec6();
                let t = data.tau_applied[j.iu + k] + tau.map_or(0.0, |t| t[j.iu + k]);
                ub[k] = t - s[k].dot(&pa_a);
            }
            let mut d_inv = Matrix6::zeros();
            if nu == 1 {
                let d = s[0].dot(&Force::from_vec6(&u_cols[0]));
                d_inv[(0, 0)] = 1.0 / d;
            } else {
                let mut d = Matrix6::identity();
                for r in 0..nu {
                    for c in 0..nu {
                        d[(r, c)] = s[r].dot(&Force::from_vec6(&u_cols[c]));
                    }
                }
                d_inv = d.try_inverse().unwrap_or_else(|| Matrix6::from_element(f64::NAN));
            }
            if j.parent != 0 {
                // I^a = I^A - U D⁻¹ Uᵀ ; p^a = p^A + I^a c + U D⁻¹ u
                let mut i_art = ia;
                let mut corr = Vector6::zeros();
                for r in 0..nu {
                    let mut du = Vector6::zeros();
                    for c in 0..nu {
                        du += u_cols[c] * d_inv[(c, r)];
                    }
                    i_art -= du * u_cols[r].transpose();
                }
                for r in 0..nu {
                    let mut coef = 0.0;
                    for c in 0..nu {
                        coef += d_inv[(r, c)] * ub[c];
                    }
                    corr += u_cols[r] * coef;
                }
                let ic = i_art * data.c[i].to_vec6();
                pa_a = Force::from_vec6(&(pa_a.to_vec6() + ic + corr));
                let ip = inertia6_to_parent(&data.x_rel[i], &i_art);
                data.ia[j.parent] += ip;
                let pp = data.x_rel[i].force_to_parent(&pa_a);
                data.pa[j.parent] += pp;
            }
            data.u_mat[i] = u_cols;
            data.d_inv[i] = d_inv;
            data.u_bias[i] = ub;
        } else if j.parent != 0 {
            let ic = ia * data.c[i].to_vec6();
            pa_a = Force::from_vec6(&(pa_a.to_vec6() + ic));
            data.ia[j.parent] += inertia6_to_parent(&data.x_rel[i], &ia);
            let pp = data.x_rel[i].force_to_parent(&pa_a);
            data.pa[j.parent] += pp;
        }
    }
    data.a[0] = Motion::new(crate::math::Vec3::zeros(), -model.gravity);
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let a_par = data.x_rel[i].motion_to_child(&data.a[j.parent]) + data.c[i];
        let nu = j.nu();
        let mut a = a_par;
        if nu > 0 {
            let ap = a_par.to_vec6();
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
    data.a[0] = Motion::ZERO;
    for i in 1..nb {
        let g_b = data.x_abs[i].a.transpose() * model.gravity;
        data.a[i].v += g_b;
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
