//! Composite-rigid-body algorithm: the mass matrix `M(q)` (the Hessian of the kinetic energy in
//! u, eq. 2.183), O(n d) for a tree of depth d.
//!
//! Composite inertias are accumulated from the leaves (`I^c_p(i) += I^c_i`, world components, so
//! no frame change); column block i is `F = I^c_i S_i`, and `M_ji = S_jᵀ F` for i and its ancestors j.

use crate::data::Data;
use crate::model::Model;

/// Fills `data.mass_matrix` from the placements and inertias of the last
/// [`crate::kinematics::positions`] and [`crate::kinematics::inertias`] calls.
pub fn crba(model: &Model, data: &mut Data) {
    let nb = model.nbodies();
    data.ic[..nb].copy_from_slice(&data.inertia[..nb]);
    data.mass_matrix.fill(0.0);
    for (ji, j) in model.joints.iter().enumerate().rev() {
        let i = ji + 1;
        if j.parent != 0 {
            let c = data.ic[i];
            let p = &mut data.ic[j.parent];
            p.m += c.m;
            p.h += c.h;
            p.i_o += c.i_o;
        }
        for k in 0..j.nu() {
            let f = data.ic[i].mul_motion(&data.s[i][k]);
            let col = j.iu + k;
            for kk in 0..j.nu() {
                data.mass_matrix[(j.iu + kk, col)] = data.s[i][kk].dot(&f);
            }
            // M_(ancestor, col) = S_ancᵀ F: the composite body's reaction seen by each ancestor joint
            let mut b = j.parent;
            while b != 0 {
                let jb = &model.joints[b - 1];
                for kk in 0..jb.nu() {
                    let v = data.s[b][kk].dot(&f);
                    data.mass_matrix[(jb.iu + kk, col)] = v;
                    data.mass_matrix[(col, jb.iu + kk)] = v;
                }
                b = jb.parent;
            }
        }
    }
}

/// Positions, inertias at time t, then [`crba`]: `data.mass_matrix = M(q, t)`.
pub fn mass_matrix(model: &Model, data: &mut Data, t: f64, q: &[f64]) {
    crate::kinematics::positions(model, data, q);
    crate::kinematics::inertias(model, data, t);
    crba(model, data);
}
