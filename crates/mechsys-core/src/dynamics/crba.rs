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
    data.mass_matrix.as_mut_slice().fill(0.0);
    let Data { ic, inertia, s, mass_matrix, elastic, .. } = data;
    composite_inertias(model, inertia, s, ic, elastic, |r, c, v| {
        mass_matrix[(r, c)] = v;
        mass_matrix[(c, r)] = v;
    });
}

/// The composite-rigid-body recursion: hands every structurally nonzero entry `M(r, c)` (r a
/// velocity of the same joint as c or of one of its ancestors) to `put`, once per pair and
/// triangle, so dense and sparse storages share one algorithm.
pub(crate) fn composite_inertias(
    model: &Model,
    inertia: &[crate::spatial::RigidInertia],
    s: &[[crate::spatial::Motion; 6]],
    ic: &mut [crate::spatial::RigidInertia],
    elastic: &[crate::elastic::ElasticWork],
    mut put: impl FnMut(usize, usize, f64),
) {
    let nb = model.nbodies();
    ic[..nb].copy_from_slice(&inertia[..nb]);
    for (ji, j) in model.joints.iter().enumerate().rev() {
        let i = ji + 1;
        if j.parent != 0 {
            let c = ic[i];
            let p = &mut ic[j.parent];
            p.m += c.m;
            p.h += c.h;
            p.i_o += c.i_o;
        }
        for k in 0..j.nu() {
            let f = ic[i].mul_motion(&s[i][k]);
            let col = j.iu + k;
            for kk in 0..=k {
                put(j.iu + kk, col, s[i][kk].dot(&f));
            }
            // M_(ancestor, col) = S_ancᵀ F: the composite body's reaction seen by each ancestor joint
            let mut b = j.parent;
            while b != 0 {
                let jb = &model.joints[b - 1];
                for kk in 0..jb.nu() {
                    put(jb.iu + kk, col, s[b][kk].dot(&f));
                }
                b = jb.parent;
            }
        }
    }
    // elastic coordinates: M_ee among themselves, S_jᵀ C_k with the joints carrying the body
    for (e, w) in model.elastic.iter().zip(elastic) {
        for k in 0..e.ne {
            let col = e.iu + k;
            for kk in 0..=k {
                put(e.iu + kk, col, e.m_ee[(kk, k)]);
            }
            let f = &w.c[k];
            let mut b = e.body;
            while b != 0 {
                let jb = &model.joints[b - 1];
                for kk in 0..jb.nu() {
                    put(jb.iu + kk, col, s[b][kk].dot(f));
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
