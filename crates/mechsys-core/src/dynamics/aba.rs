//! Articulated-body algorithm: forward dynamics `u̇ = M⁻¹ (h + τ)` in O(n) without forming M.
//!
//! Pass 1 (outwards): twists and velocity products (kinematics). Pass 2 (inwards): articulated
//! inertias `I^A` and bias forces `p^A`; across each joint the joint's own motion is eliminated,
//! `I^a = I^A - U D⁻¹ Uᵀ` with `U = I^A S`, `D = Sᵀ U`. Pass 3 (outwards): accelerations.
//! All spatial quantities are in world components about the origin, so passing inertias and forces
//! to the parent is a plain sum.

use crate::data::Data;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::model::Model;
use crate::spatial::{Force, Motion, V6};

/// Inverts the symmetric positive definite leading `n × n` block of `d` in place (Gauss–Jordan
/// without pivoting, which is stable for SPD matrices). Returns false if it is not positive definite.
fn invert_spd(d: &mut [[f64; 6]; 6], n: usize) -> bool {
    for k in 0..n {
        let p = d[k][k];
        if !(p > 0.0) {
            return false;
        }
        let inv = 1.0 / p;
        d[k][k] = 1.0;
        for c in 0..n {
            d[k][c] *= inv;
        }
        for r in 0..n {
            if r != k {
                let f = d[r][k];
                d[r][k] = 0.0;
                for c in 0..n {
                    d[r][c] -= f * d[k][c];
                }
            }
        }
    }
    true
}

#[inline]
fn dot6(a: &V6, b: &V6) -> f64 {
    // a balanced sum: D = Sᵀ U lies on the inward pass's serial chain (see `M6::mul`)
    (a[0] * b[0] + a[1] * b[1]) + (a[2] * b[2] + a[3] * b[3]) + (a[4] * b[4] + a[5] * b[5])
}

/// ABA on prepared data (kinematics, inertias, `f_ext`, `tau_applied`); `tau` is an optional extra
/// actuation (length nu). Writes `data.udot` and the body accelerations `data.a` (without gravity).
pub fn aba_prepared(model: &Model, data: &mut Data, tau: Option<&[f64]>) {
    let nb = model.nbodies();
    for i in 1..nb {
        data.ia[i].set_rigid(&data.inertia[i]);
        let iv = data.inertia[i].mul_motion(&data.v[i]);
        data.pa[i] = data.v[i].cross_force(&iv) - data.f_ext[i];
    }
    for (ji, j) in model.joints.iter().enumerate().rev() {
        let i = ji + 1;
        let nu = j.nu();
        let parent = j.parent;
        let (lo, hi) = data.ia.split_at_mut(i);
        let ia = &mut hi[0];
        if nu == 1 {
            // the common case: U = I^A S and I^A c in one sweep of I^A, then I^a = I^A - U Uᵀ/D
            // added to the parent in a second sweep (I^a itself is never stored)
            let s = data.s[i][0].v6();
            let c = data.c[i].v6();
            let u_col = ia.mul(&s);
            let ic = ia.mul(&c);
            let d_inv = 1.0 / dot6(&s, &u_col);
            let t = data.tau_applied[j.iu] + tau.map_or(0.0, |t| t[j.iu]);
            let ub = t - data.s[i][0].dot(&data.pa[i]);
            data.u_mat[i][0] = u_col;
            data.d_inv[i][0][0] = d_inv;
            data.u_bias[i][0] = ub;
            if parent != 0 {
                // p^a = p^A + I^a c + U D⁻¹ u, with I^a c = I^A c - U D⁻¹ (Uᵀ c)
                let k = d_inv * (ub - dot6(&u_col, &c));
                let mut pa = data.pa[i].v6();
                for r in 0..6 {
                    pa[r] += ic[r] + u_col[r] * k;
                }
                lo[parent].add_minus_outer(ia, d_inv, &u_col);
                data.pa[parent] += Force::from_v6(&pa);
            }
            continue;
        }
        if nu == 0 {
            if parent != 0 {
                let ic = ia.mul_motion(&data.c[i]);
                let pa = data.pa[i] + Force::from_v6(&ic);
                lo[parent].add(ia);
                data.pa[parent] += pa;
            }
            continue;
        }
        let mut u_cols = [[0.0; 6]; 6];
        let mut ub = [0.0; 6];
        for k in 0..nu {
            let s = &data.s[i][k];
            u_cols[k] = ia.mul_motion(s);
            let t = data.tau_applied[j.iu + k] + tau.map_or(0.0, |t| t[j.iu + k]);
            ub[k] = t - s.dot(&data.pa[i]);
        }
        let mut d = [[0.0; 6]; 6];
        for r in 0..nu {
            for c in 0..nu {
                d[r][c] = data.s[i][r].dot6(&u_cols[c]);
            }
        }
        // D is positive definite for a physical body; NaN propagates otherwise and the integrator
        // reports the non-finite state with its time
        if !invert_spd(&mut d, nu) {
            d = [[f64::NAN; 6]; 6];
        }
        if parent != 0 {
            // I^a = I^A - U D⁻¹ Uᵀ, subtracted as Σ_r (U D⁻¹)_r U_rᵀ
            let mut w = [[0.0; 6]; 6]; // W = U D⁻¹
            for r in 0..nu {
                for c in 0..nu {
                    for e in 0..6 {
                        w[r][e] += u_cols[c][e] * d[c][r];
                    }
                }
            }
            for r in 0..nu {
                ia.sub_product(&w[r], &u_cols[r]);
            }
            let ic = ia.mul_motion(&data.c[i]);
            let mut pa = data.pa[i].v6();
            for r in 0..nu {
                let coef: f64 = (0..nu).map(|c| d[r][c] * ub[c]).sum();
                for e in 0..6 {
                    pa[e] += u_cols[r][e] * coef;
                }
            }
            for e in 0..6 {
                pa[e] += ic[e];
            }
            lo[parent].add(ia);
            data.pa[parent] += Force::from_v6(&pa);
        }
        data.u_mat[i] = u_cols;
        data.d_inv[i] = d;
        data.u_bias[i] = ub;
    }
    data.a[0] = Motion::new(crate::math::Vec3::zeros(), -model.gravity);
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let nu = j.nu();
        let mut a = data.a[j.parent] + data.c[i];
        if nu == 1 {
            let ud = data.d_inv[i][0][0] * (data.u_bias[i][0] - a.dot6(&data.u_mat[i][0]));
            data.udot[j.iu] = ud;
            a += data.s[i][0] * ud;
        } else if nu > 1 {
            let ap = a.v6();
            let mut rhs = [0.0; 6];
            for k in 0..nu {
                rhs[k] = data.u_bias[i][k] - dot6(&data.u_mat[i][k], &ap);
            }
            for r in 0..nu {
                let ud: f64 = (0..nu).map(|c| data.d_inv[i][r][c] * rhs[c]).sum();
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
#[allow(clippy::too_many_arguments)]
pub fn aba(
    model: &Model,
    data: &mut Data,
    ws: &mut super::Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    tau: Option<&[f64]>,
    cb: &dyn Callbacks,
) -> Result<()> {
    super::forward_dynamics(model, data, ws, t, q, u, tau, cb).map(|_| ())
}
