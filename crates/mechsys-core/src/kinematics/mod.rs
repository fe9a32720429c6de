//! Recursive kinematics of the tree (eqs. 2.45–2.62): placements, twists and velocity-product
//! accelerations of every body from the root outwards, and the Jacobians of body points and body
//! twists with respect to the generalized velocities (J and j of eqs. 2.63–2.69).

use nalgebra::DMatrix;

use crate::data::Data;
use crate::math::Vec3;
use crate::model::Model;
use crate::spatial::Motion;

/// Position stage: placements `x_rel`, `x_abs` and motion subspaces `s` of all bodies.
///
/// eq. 2.46: A_IBi = A_IBi-1 · A_Bi-1Bi; eq. 2.51: r_IBi = r_IBi-1 + A_IBi-1 r_Bi-1Bi.
pub fn positions(model: &Model, data: &mut Data, q: &[f64]) {
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let qj = &q[j.iq..j.iq + j.nq()];
        let xj = j.kind.placement(qj);
        data.x_rel[i] = j.parent_frame.compose(&xj).compose(&j.child_frame_inv);
        data.x_abs[i] = data.x_abs[j.parent].compose(&data.x_rel[i]);
        let mut s = [Motion::ZERO; 6];
        j.kind.subspace(qj, &mut s);
        for k in 0..j.nu() {
            // joint-frame twist → body-frame twist (constant placement of the joint frame)
            data.s[i][k] = j.child_frame.motion_to_parent(&s[k]);
        }
    }
}

/// Velocity stage: body twists `v` (eqs. 2.49, 2.52) and velocity-product terms `c`.
/// Requires [`positions`].
pub fn velocities(model: &Model, data: &mut Data, q: &[f64], u: &[f64]) {
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let uj = &u[j.iu..j.iu + j.nu()];
        let mut vj = Motion::ZERO;
        for (k, uk) in uj.iter().enumerate() {
            vj += data.s[i][k] * *uk;
        }
        let vi = data.x_rel[i].motion_to_child(&data.v[j.parent]) + vj;
        data.v[i] = vi;
        let cj = j.kind.bias(&q[j.iq..j.iq + j.nq()], uj);
        // eq. 2.57 / 2.56: ω̃ ω_rel and the centripetal/Coriolis terms of the chain
        data.c[i] = j.child_frame.motion_to_parent(&cj) + vi.cross_motion(&vj);
    }
}

/// Both stages.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64], u: &[f64]) {
    positions(model, data, q);
    velocities(model, data, q, u);
}

/// Acceleration stage for given `udot`: spatial accelerations `a` (eqs. 2.56–2.58), without gravity.
/// Requires [`forward_kinematics`].
pub fn accelerations(model: &Model, data: &mut Data, udot: &[f64]) {
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let mut a = data.x_rel[i].motion_to_child(&data.a[j.parent]) + data.c[i];
        for k in 0..j.nu() {
            a += data.s[i][k] * udot[j.iu + k];
        }
        data.a[i] = a;
    }
}

/// Absolute position (I components) of a point `p_b` fixed on body `body`.
pub fn point_position(data: &Data, body: usize, p_b: &Vec3) -> Vec3 {
    data.x_abs[body].point_to_parent(p_b)
}

/// Absolute velocity (I components) of a body-fixed point (eq. 2.28 with ṙ = 0).
pub fn point_velocity(data: &Data, body: usize, p_b: &Vec3) -> Vec3 {
    let v = &data.v[body];
    data.x_abs[body].a * (v.v + v.w.cross(p_b))
}

/// Absolute (classical) acceleration, I components, of a body-fixed point (eq. 2.41 with ṙ = r̈ = 0).
/// Requires [`accelerations`].
pub fn point_acceleration(data: &Data, body: usize, p_b: &Vec3) -> Vec3 {
    let (v, a) = (&data.v[body], &data.a[body]);
    let vp = v.v + v.w.cross(p_b);
    // spatial → classical: a_P = v̇ + ω̇ × p + ω × (v + ω × p)
    data.x_abs[body].a * (a.v + a.w.cross(p_b) + v.w.cross(&vp))
}

/// Jacobians of a body-fixed point (translational `jt`, 3 × nu) and of the body's angular velocity
/// (`jr`, 3 × nu), both I components, so that `v_P = jt u` and `ω_I = jr u` (eq. 2.69 with j = 0).
/// Requires [`positions`].
pub fn point_jacobian(model: &Model, data: &Data, body: usize, p_b: &Vec3, jt: &mut DMatrix<f64>, jr: &mut DMatrix<f64>) {
    jt.fill(0.0);
    jr.fill(0.0);
    let p_i = point_position(data, body, p_b);
    let mut b = body;
    while b != 0 {
        let j = &model.joints[b - 1];
        let x = &data.x_abs[b];
        for k in 0..j.nu() {
            let s = &data.s[b][k];
            let w_i = x.a * s.w;
            // velocity of the body-b origin due to this column, then carried to the point
            let v_i = x.a * s.v + w_i.cross(&(p_i - x.r));
            for r in 0..3 {
                jt[(r, j.iu + k)] = v_i[r];
                jr[(r, j.iu + k)] = w_i[r];
            }
        }
        b = j.parent;
    }
}

#[cfg(test)]
mod tests;
