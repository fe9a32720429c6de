//! Composite-rigid-body algorithm: the mass matrix `M(q)` (the Hessian of the kinetic energy in
//! u, eq. 2.183), O(n d) for a tree of depth d.
//!
//! Composite inertias are accumulated from the leaves (`I^c_λ += X_iᵀ I^c_i X_i`); column block i
//! is `F = I^c_i S_i` carried towards the root, `M_ij = S_jᵀ F`.

use crate::data::Data;
use crate::model::Model;
use crate::spatial::Force;

/// Fills `data.mass_matrix` for the configuration of the last [`crate::kinematics::positions`] call
/// (and the inertias of the last [`crate::forces::update_inertias`]).
pub fn crba(model: &Model, data: &mut Data) {
    let nb = model.nbodies();
    data.ic[..nb].copy_from_slice(&data.inertia[..nb]);
    data.mass_matrix.fill(0.0);
    for (ji, j) in model.joints.iter().enumerate().rev() {
        let i = ji + 1;
        if j.parent != 0 {
            let shifted = data.ic[i].to_parent(&data.x_rel[i]);
            let p = &mut data.ic[j.parent];
            p.m += shifted.m;
            p.h += shifted.h;
            p.i_o += shifted.i_o;
        }
        for k in 0..j.nu() {
            let mut f: Force = data.ic[i].mul_motion(&data.s[i][k]);
            let col = j.iu + k;
            for kk in 0..j.nu() {
                data.mass_matrix[(j.iu + kk, col)] = data.s[i][kk].dot(&f);
            }
            // carry the column up the tree: M_(ancestor, col) = S_ancᵀ F
            let mut b = i;
            while model.joints[b - 1].parent != 0 {
                f = data.x_rel[b].force_to_parent(&f);
                b = model.joints[b - 1].parent;
                let jb = &model.joints[b - 1];
                for kk in 0..jb.nu() {
                    let v = data.s[b][kk].dot(&f);
                    data.mass_matrix[(jb.iu + kk, col)] = v;
                    data.mass_matrix[(col, jb.iu + kk)] = v;
                }
            }
        }
    }
}

/// Positions, inertias at time t, then [`crba`]: `data.mass_matrix = M(q, t)`.
pub fn mass_matrix(model: &Model, data: &mut Data, t: f64, q: &[f64]) {
    crate::kinematics::positions(model, data, q);
    crate::forces::update_inertias(model, data, t);
    crba(model, data);
}
