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
    let nu_all = model.nu;
    // every per-body array cut to nb and every per-velocity array to nu: all index checks by a
    // body then compare with one bound, which the loops already imply (they were a tenth of the
    // instructions of a chain's pass, each with its own length reloaded from the stack)
    let Data { ia, pa, s, c, v, inertia, f_ext, tau_applied, u_mat, d_inv, u_bias, a, udot, .. } = data;
    let (ia, pa, u_mat, d_inv, u_bias, acc) =
        (&mut ia[..nb], &mut pa[..nb], &mut u_mat[..nb], &mut d_inv[..nb], &mut u_bias[..nb], &mut a[..nb]);
    let (s, c, v, inertia, f_ext) = (&s[..nb], &c[..nb], &v[..nb], &inertia[..nb], &f_ext[..nb]);
    let (tau_applied, udot) = (&tau_applied[..nu_all], &mut udot[..nu_all]);
    let tau = tau.map(|t| &t[..nu_all]);
    for i in 1..nb {
        ia[i].set_rigid(&inertia[i]);
        let iv = inertia[i].mul_motion(&v[i]);
        pa[i] = v[i].cross_force(&iv) - f_ext[i];
    }
    for (ji, j) in model.joints.iter().enumerate().rev() {
        let i = ji + 1;
        let nu = j.nu();
        let parent = j.parent;
        let (lo, hi) = ia.split_at_mut(i);
        let ia_i = &mut hi[0];
        if nu == 1 {
            // the common case: U = I^A S and I^A c in one sweep of I^A, then I^a = I^A - U Uᵀ/D
            // added to the parent in a second sweep (I^a itself is never stored)
            let s0 = s[i][0].v6();
            let ci = c[i].v6();
            let u_col = ia_i.mul(&s0);
            let ic = ia_i.mul(&ci);
            let d_i = 1.0 / dot6(&s0, &u_col);
            let t = tau_applied[j.iu] + tau.map_or(0.0, |t| t[j.iu]);
            let ub = t - s[i][0].dot(&pa[i]);
            u_mat[i][0] = u_col;
            d_inv[i][0][0] = d_i;
            u_bias[i][0] = ub;
            if parent != 0 {
                // p^a = p^A + I^a c + U D⁻¹ u, with I^a c = I^A c - U D⁻¹ (Uᵀ c)
                let k = d_i * (ub - dot6(&u_col, &ci));
                let mut p = pa[i].v6();
                for r in 0..6 {
                    p[r] += ic[r] + u_col[r] * k;
                }
                lo[parent].add_minus_outer(ia_i, d_i, &u_col);
                pa[parent] += Force::from_v6(&p);
            }
            continue;
        }
        if nu == 0 {
            if parent != 0 {
                let ic = ia_i.mul_motion(&c[i]);
                let p = pa[i] + Force::from_v6(&ic);
                lo[parent].add(ia_i);
                pa[parent] += p;
            }
            continue;
        }
        let mut u_cols = [[0.0; 6]; 6];
        let mut ub = [0.0; 6];
        for k in 0..nu {
            let sk = &s[i][k];
            u_cols[k] = ia_i.mul_motion(sk);
            let t = tau_applied[j.iu + k] + tau.map_or(0.0, |t| t[j.iu + k]);
            ub[k] = t - sk.dot(&pa[i]);
        }
        let mut d = [[0.0; 6]; 6];
        for r in 0..nu {
            for col in 0..nu {
                d[r][col] = s[i][r].dot6(&u_cols[col]);
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
                for col in 0..nu {
                    for e in 0..6 {
                        w[r][e] += u_cols[col][e] * d[col][r];
                    }
                }
            }
            for r in 0..nu {
                ia_i.sub_product(&w[r], &u_cols[r]);
            }
            let ic = ia_i.mul_motion(&c[i]);
            let mut p = pa[i].v6();
            for r in 0..nu {
                let coef: f64 = (0..nu).map(|col| d[r][col] * ub[col]).sum();
                for e in 0..6 {
                    p[e] += u_cols[r][e] * coef;
                }
            }
            for e in 0..6 {
                p[e] += ic[e];
            }
            lo[parent].add(ia_i);
            pa[parent] += Force::from_v6(&p);
        }
        u_mat[i] = u_cols;
        d_inv[i] = d;
        u_bias[i] = ub;
    }
    acc[0] = Motion::new(crate::math::Vec3::zeros(), -model.gravity);
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let nu = j.nu();
        let mut ai = acc[j.parent] + c[i];
        if nu == 1 {
            let ud = d_inv[i][0][0] * (u_bias[i][0] - ai.dot6(&u_mat[i][0]));
            udot[j.iu] = ud;
            ai += s[i][0] * ud;
        } else if nu > 1 {
            let ap = ai.v6();
            let mut rhs = [0.0; 6];
            for k in 0..nu {
                rhs[k] = u_bias[i][k] - dot6(&u_mat[i][k], &ap);
            }
            for r in 0..nu {
                let ud: f64 = (0..nu).map(|col| d_inv[i][r][col] * rhs[col]).sum();
                udot[j.iu + r] = ud;
                ai += s[i][r] * ud;
            }
        }
        acc[i] = ai;
    }
    // report accelerations without the gravity offset: the ground's a = -g was added to all
    acc[0] = Motion::ZERO;
    for ai in acc[1..].iter_mut() {
        ai.v += model.gravity;
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
