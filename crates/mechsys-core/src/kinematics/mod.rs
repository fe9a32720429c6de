//! Recursive kinematics of the tree (eqs. 2.45–2.62): placements, twists and velocity-product
//! accelerations of every body from the root outwards, and the Jacobians of body points and body
//! twists with respect to the generalized velocities (J and j of eqs. 2.63–2.69).
//!
//! Spatial quantities are kept in inertial components about the inertial origin ("world"
//! convention): a twist `(ω_I, v_O)` holds the angular velocity and the velocity of the body-fixed
//! point that momentarily coincides with the origin. Then the recurrences need no frame changes at
//! all — eq. 2.45 becomes `v_i = v_p(i) + S_i u_i` literally — and the dynamics passes add inertias
//! and forces of children to parents directly.

use nalgebra::DMatrix;

use crate::data::Data;
use crate::math::{Mat3, Vec3};
use crate::model::Model;
use crate::spatial::{Motion, Pose};

/// A twist or acceleration given in the components of frame `x` about its origin, expressed in
/// inertial components about the inertial origin (`x` placed in I).
#[inline]
pub fn motion_to_world(x: &Pose, m: &Motion) -> Motion {
    let w = x.a * m.w;
    Motion::new(w, x.a * m.v + x.r.cross(&w))
}

/// Position stage for the joint moving body `i`: its placement, joint frame and world subspace.
#[inline(always)]
fn position_step(j: &crate::model::Joint, data: &mut Data, i: usize, q: &[f64]) {
    let qj = &q[j.iq..j.iq + j.nq()];
    // pose of the child joint frame in I, then of the child body frame (joint frames are
    // mostly pure offsets: skip the rotation products then)
    let xp = &data.x_abs[j.parent];
    let x_pj = if j.frames_plain.0 { xp.translate(&j.parent_frame.r) } else { xp.compose(&j.parent_frame) };
    let mut axis = Vec3::zeros();
    let x_cj = match j.coordinate_axis {
        Some(k) => {
            // rotation about coordinate axis k: only the two other columns turn (eq. 2.12-2.18)
            // (the columns are picked with constant indices per axis: writing them at a runtime
            // index into a matrix on the stack made the loads after it wait on store forwarding)
            let (s, c) = data.sin_cos[i];
            let a = &x_pj.a;
            let col = |i: usize| Vec3::new(a[(0, i)], a[(1, i)], a[(2, i)]);
            let turn = |c1: Vec3, c2: Vec3| (c1 * c + c2 * s, c2 * c - c1 * s);
            let a = match k {
                0 => {
                    let (n1, n2) = turn(col(1), col(2));
                    axis = col(0);
                    Mat3::from_columns(&[axis, n1, n2])
                }
                1 => {
                    let (n1, n2) = turn(col(2), col(0));
                    axis = col(1);
                    Mat3::from_columns(&[n2, axis, n1])
                }
                _ => {
                    let (n1, n2) = turn(col(0), col(1));
                    axis = col(2);
                    Mat3::from_columns(&[n1, n2, axis])
                }
            };
            Pose::new(a, x_pj.r)
        }
        None => x_pj.compose(&j.kind.placement(qj)),
    };
    data.x_abs[i] = match (j.frames_plain.1, j.child_frame_inv.r == Vec3::zeros()) {
        (true, true) => x_cj,
        (true, false) => x_cj.translate(&j.child_frame_inv.r),
        _ => x_cj.compose(&j.child_frame_inv),
    };
    data.x_joint[i] = x_cj;
    if j.coordinate_axis.is_some() {
        // the axis in I is a column of A (kept above); the twist about it through r is (ω, r × ω)
        data.s[i][0] = Motion::new(axis, x_cj.r.cross(&axis));
        return;
    }
    let mut s = [Motion::ZERO; 6];
    j.kind.subspace(qj, &mut s);
    for k in 0..j.nu() {
        data.s[i][k] = motion_to_world(&x_cj, &s[k]);
    }
}

/// Velocity stage for the joint moving body `i`: twist and velocity-product acceleration.
#[inline(always)]
fn velocity_step(j: &crate::model::Joint, data: &mut Data, i: usize, q: &[f64], u: &[f64]) {
    let uj = &u[j.iu..j.iu + j.nu()];
    let mut vj = Motion::ZERO;
    for (k, uk) in uj.iter().enumerate() {
        vj += data.s[i][k] * *uk;
    }
    let vi = data.v[j.parent] + vj;
    data.v[i] = vi;
    // d/dt of world-frame S: the frame carrying S moves with v_i, plus the joint's own Ṡ u
    let mut c = vi.cross_motion(&vj);
    if j.kind.has_bias() {
        let cj = j.kind.bias(&q[j.iq..j.iq + j.nq()], uj);
        c += motion_to_world(&data.x_joint[i], &cj);
    }
    data.c[i] = c;
}

/// Inertia of body `i` at time t in world components about the origin (variable mass scaled).
#[inline(always)]
fn inertia_step(b: &crate::model::Body, data: &mut Data, i: usize, t: f64) {
    let x = &data.x_abs[i];
    let c = x.r + x.a * b.com;
    let (m, i_c) = if b.mass_rate == 0.0 {
        (b.mass, b.inertia)
    } else {
        let m = b.mass_at(t);
        (m, b.inertia * (m / b.mass))
    };
    let i_c_w = if b.principal_axes {
        // A diag(d) Aᵀ = Σ d_k a_k a_kᵀ over the columns a_k of A, symmetric: 6 entries
        let a = &x.a;
        let (d0, d1, d2) = (i_c[(0, 0)], i_c[(1, 1)], i_c[(2, 2)]);
        let e =
            |r: usize, c: usize| d0 * a[(r, 0)] * a[(c, 0)] + d1 * a[(r, 1)] * a[(c, 1)] + d2 * a[(r, 2)] * a[(c, 2)];
        let (xx, xy, xz, yy, yz, zz) = (e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2));
        Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
    } else {
        x.a * i_c * x.a.transpose()
    };
    data.inertia[i] = crate::spatial::RigidInertia::from_com(m, &c, &i_c_w);
}

/// The stored elastic coordinates (and, with `u`, their rates) of every elastic body.
fn store_elastic(model: &Model, data: &mut Data, q: &[f64], u: Option<&[f64]>) {
    for (e, w) in model.elastic.iter().zip(data.elastic.iter_mut()) {
        w.q.copy_from_slice(&q[e.iq..e.iq + e.ne]);
        if let Some(u) = u {
            w.qd.copy_from_slice(&u[e.iu..e.iu + e.ne]);
        }
    }
}

/// The elastic bodies' deformed inertias and couplings, after their rigid inertias.
fn deform_elastic(model: &Model, data: &mut Data) {
    for (k, e) in model.elastic.iter().enumerate() {
        let b = &model.bodies[e.body];
        crate::elastic::deform(e, data, k, b.mass, &b.com);
    }
}

/// `(sin q, cos q)` of every revolute joint about a coordinate axis, ahead of the placements:
/// the angles do not depend on each other, so these polynomial chains overlap in the pipeline
/// instead of each one stalling the serial parent-to-child recursion.
#[inline(always)]
fn joint_sin_cos(model: &Model, data: &mut Data, q: &[f64]) {
    for (j, sc) in model.joints.iter().zip(data.sin_cos[1..].iter_mut()) {
        if j.coordinate_axis.is_some() {
            *sc = crate::math::trig::sin_cos(q[j.iq]);
        }
    }
}

/// Position stage: placements `x_abs`, `x_joint` and motion subspaces `s` (world) of all bodies.
///
/// eq. 2.46: A_IBi = A_IBi-1 · A_Bi-1Bi; eq. 2.51: r_IBi = r_IBi-1 + A_IBi-1 r_Bi-1Bi.
pub fn positions(model: &Model, data: &mut Data, q: &[f64]) {
    joint_sin_cos(model, data, q);
    for (ji, j) in model.joints.iter().enumerate() {
        position_step(j, data, ji + 1, q);
    }
    store_elastic(model, data, q, None);
}

/// Velocity stage: body twists `v` (eqs. 2.49, 2.52, 2.54, 2.55) and velocity-product terms `c`
/// (the ω̃ ω_rel and Coriolis terms of eqs. 2.56, 2.57). Requires [`positions`].
pub fn velocities(model: &Model, data: &mut Data, q: &[f64], u: &[f64]) {
    for (ji, j) in model.joints.iter().enumerate() {
        velocity_step(j, data, ji + 1, q, u);
    }
    store_elastic(model, data, q, Some(u));
}

/// Body inertias at time t in world components about the origin (variable masses scaled).
/// Requires [`positions`].
pub fn inertias(model: &Model, data: &mut Data, t: f64) {
    for (i, b) in model.bodies.iter().enumerate().skip(1) {
        inertia_step(b, data, i, t);
    }
    deform_elastic(model, data);
}

/// Positions, velocities and inertias in one sweep over the tree (the stages of one evaluation
/// before the forces; fused so each body's placement is used while it is still in registers).
pub fn forward_pass(model: &Model, data: &mut Data, t: f64, q: &[f64], u: &[f64]) {
    joint_sin_cos(model, data, q);
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        position_step(j, data, i, q);
        velocity_step(j, data, i, q, u);
        inertia_step(&model.bodies[i], data, i, t);
    }
    if !model.elastic.is_empty() {
        store_elastic(model, data, q, Some(u));
        deform_elastic(model, data);
    }
}

/// Both kinematic stages.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64], u: &[f64]) {
    positions(model, data, q);
    velocities(model, data, q, u);
}

/// Acceleration stage for given `udot`: spatial accelerations `a` (eqs. 2.56–2.58), starting from
/// `data.a[0]` (zero, or the gravity offset). Requires [`forward_kinematics`].
pub fn accelerations(model: &Model, data: &mut Data, udot: &[f64]) {
    for (ji, j) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let mut a = data.a[j.parent] + data.c[i];
        for k in 0..j.nu() {
            a += data.s[i][k] * udot[j.iu + k];
        }
        data.a[i] = a;
    }
    for (e, w) in model.elastic.iter().zip(data.elastic.iter_mut()) {
        w.qdd.copy_from_slice(&udot[e.iu..e.iu + e.ne]);
    }
}

/// The elastic node at the body-frame point `p_b` of `body`, if the body is elastic and the point
/// is at a node: (elastic index, node index). A point at a node moves with the node's translation
/// (eq. 2.133); any other point of an elastic body moves with its reference frame.
#[inline]
pub fn elastic_node(data: &Data, body: usize, p_b: &Vec3) -> Option<(usize, usize)> {
    let k = data.body_elastic.get(body).copied().flatten()?;
    data.elastic[k].node_at(p_b).map(|n| (k, n))
}

/// Absolute position (I components) of a point `p_b` fixed on body `body` (at an elastic node:
/// deflected with it).
#[inline]
pub fn point_position(data: &Data, body: usize, p_b: &Vec3) -> Vec3 {
    point_position_at(data, body, p_b, elastic_node(data, body, p_b))
}

/// [`point_position`] with the point's elastic node already looked up.
#[inline]
fn point_position_at(data: &Data, body: usize, p_b: &Vec3, node: Option<(usize, usize)>) -> Vec3 {
    match node {
        Some((k, n)) => {
            let w = &data.elastic[k];
            data.x_abs[body].point_to_parent(&(p_b + w.node_field(n, &w.q)))
        }
        None => data.x_abs[body].point_to_parent(p_b),
    }
}

/// Absolute velocity (I components) of a body-fixed point (eq. 2.28 with ṙ = 0; at an elastic
/// node plus its deflection rate, eq. 2.191).
#[inline]
pub fn point_velocity(data: &Data, body: usize, p_b: &Vec3) -> Vec3 {
    point_velocity_at(data, body, p_b, elastic_node(data, body, p_b))
}

/// [`point_velocity`] with the point's elastic node already looked up.
#[inline]
fn point_velocity_at(data: &Data, body: usize, p_b: &Vec3, node: Option<(usize, usize)>) -> Vec3 {
    let v = &data.v[body];
    let rigid = v.v + v.w.cross(&point_position_at(data, body, p_b, node));
    match node {
        Some((k, n)) => rigid + data.x_abs[body].a * data.elastic[k].node_field(n, &data.elastic[k].qd),
        None => rigid,
    }
}

/// Absolute (classical) acceleration, I components, of a body-fixed point (eq. 2.41 with
/// ṙ = r̈ = 0; at an elastic node with its relative acceleration and Coriolis term).
/// Requires [`accelerations`] without the gravity offset.
#[inline]
pub fn point_acceleration(data: &Data, body: usize, p_b: &Vec3) -> Vec3 {
    point_acceleration_at(data, body, p_b, elastic_node(data, body, p_b))
}

/// [`point_acceleration`] with the point's elastic node already looked up.
#[inline]
fn point_acceleration_at(data: &Data, body: usize, p_b: &Vec3, node: Option<(usize, usize)>) -> Vec3 {
    let (v, a) = (&data.v[body], &data.a[body]);
    let p = point_position_at(data, body, p_b, node);
    let vp = v.v + v.w.cross(&p);
    // spatial → classical: a_P = a_O + ω̇ × p + ω × v_P
    let rigid = a.v + a.w.cross(&p) + v.w.cross(&vp);
    match node {
        Some((k, n)) => {
            let (w, am) = (&data.elastic[k], &data.x_abs[body].a);
            let rel_v = am * w.node_field(n, &w.qd);
            // ω × (A d) in v_P already; d/dt adds ω × A ḋ, and A d̈ + ω × A ḋ from the relative motion
            rigid + am * w.node_field(n, &w.qdd) + v.w.cross(&rel_v) * 2.0
        }
        None => rigid,
    }
}

/// Placement, twist and spatial acceleration of a body, world convention (about the origin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMotion {
    /// Placement `A_IB`, `r`.
    pub pose: Pose,
    /// Twist `(ω, v)`: the material point at world `x` moves with `v + ω × x`.
    pub twist: Motion,
    /// Spatial acceleration `(α, a)`: full, or the velocity-product part for `w̄`.
    pub acc: Motion,
}

impl BodyMotion {
    /// The ground: identity placement, at rest.
    pub const GROUND: BodyMotion = BodyMotion { pose: Pose::IDENTITY, twist: Motion::ZERO, acc: Motion::ZERO };

    /// Body `body` from the workspace: `x_abs`, `v`, and `a` as the last
    /// [`crate::kinematics::accelerations`] left it (with `u̇ = 0` and `a[0] = 0` that is the
    /// velocity-product part).
    pub fn from_data(data: &Data, body: usize) -> BodyMotion {
        BodyMotion { pose: data.x_abs[body], twist: data.v[body], acc: data.a[body] }
    }

    /// Velocity of the material point at world `p`.
    #[inline]
    pub fn point_velocity(&self, p: &Vec3) -> Vec3 {
        self.twist.v + self.twist.w.cross(p)
    }

    /// Acceleration of the material point at world `p` (eq. 2.41 with ṙ = r̈ = 0).
    #[inline]
    pub fn point_acceleration(&self, p: &Vec3) -> Vec3 {
        self.acc.v + self.acc.w.cross(p) + self.twist.w.cross(&self.point_velocity(p))
    }

    /// First and second time derivatives of a world vector `n` fixed in the body.
    #[inline]
    pub fn vector_rates(&self, n: &Vec3) -> (Vec3, Vec3) {
        let nd = self.twist.w.cross(n);
        (nd, self.acc.w.cross(n) + self.twist.w.cross(&nd))
    }
}

/// The motion of frame `f` (body frame) of `body`, at the stage `data` holds (its accelerations
/// from [`accelerations`]), and the elastic node it sits at, (elastic index, node index). On a
/// rigid body, or away from an elastic body's nodes, the body's motion with the frame's placement;
/// at a node the frame also moves with the node's deflection and turns by its small rotation
/// `θ = Σ q_k ψ_k` (eq. 2.134), placed as `exp(θ̃)` so that its angular velocity `A J_l(θ) θ̇` is
/// the exact rate of its orientation (J_l the left Jacobian of SO(3)).
pub fn frame_motion(data: &Data, body: usize, f: &Pose) -> (BodyMotion, Option<(usize, usize)>) {
    let xb = &data.x_abs[body];
    let Some((k, n)) = elastic_node(data, body, &f.r) else {
        return (BodyMotion { pose: xb.compose(f), twist: data.v[body], acc: data.a[body] }, None);
    };
    use crate::math::rotation::{rotvec_to_matrix, so3_left_jacobian, so3_left_jacobian_rate};
    let w = &data.elastic[k];
    let (th, thd, thdd) = (w.node_rotation(n, &w.q), w.node_rotation(n, &w.qd), w.node_rotation(n, &w.qdd));
    let jl = so3_left_jacobian(&th);
    let (vb, ab) = (&data.v[body], &data.a[body]);
    // the node is known: the point functions need not search for it again
    let node = Some((k, n));
    let p = point_position_at(data, body, &f.r, node);
    let vp = point_velocity_at(data, body, &f.r, node);
    let ap = point_acceleration_at(data, body, &f.r, node);
    let w_rel = xb.a * (jl * thd);
    let om = vb.w + w_rel;
    let al = ab.w + vb.w.cross(&w_rel) + xb.a * (jl * thdd + so3_left_jacobian_rate(&th, &thd));
    let m = BodyMotion {
        pose: Pose { a: xb.a * rotvec_to_matrix(&th) * f.a, r: p },
        twist: Motion { w: om, v: vp - om.cross(&p) },
        acc: Motion { w: al, v: ap - al.cross(&p) - om.cross(&vp) },
    };
    (m, node)
}

/// Adds `sign · S_k·W` for every elastic coordinate k of the node a frame sits at into row `row`
/// of `g`, with `S_k` the node's twist per unit rate (world, about the origin) and `W` a world
/// wrench about the origin acting on the frame.
pub fn add_node_wrench_row(
    view: ElasticView<'_>,
    node: (usize, usize),
    body: usize,
    w: &crate::spatial::Force,
    sign: f64,
    g: &mut DMatrix<f64>,
    row: usize,
) {
    let (k, n) = node;
    let (el, xb) = (&view.1[k], &view.0[body]);
    let ne = el.q.len();
    let p = xb.point_to_parent(&(el.nodes[n] + el.node_field(n, &el.q)));
    let rot = xb.a * crate::math::rotation::so3_left_jacobian(&el.node_rotation(n, &el.q));
    // the moment about the node
    let m = w.n - p.cross(&w.f);
    for kk in 0..ne {
        let (om, vp) = (rot * el.psi[n * ne + kk], xb.a * el.phi[n * ne + kk]);
        g[(row, el.iu + kk)] += sign * (om.dot(&m) + vp.dot(&w.f));
    }
}

/// The elastic node of `body` whose deflected world place is the world point `p`: (elastic index,
/// node index), None when `body` is rigid or `p` is no node.
pub fn elastic_point_at(el: ElasticView<'_>, body: usize, p: &Vec3) -> Option<(usize, usize)> {
    let (x_abs, elastic, body_elastic) = el;
    let k = body_elastic.get(body).copied().flatten()?;
    let (w, x) = (&elastic[k], &x_abs[body]);
    let tol = 1e-12 * (1.0 + p.norm());
    let n =
        (0..w.nodes.len()).find(|&n| (x.point_to_parent(&(w.nodes[n] + w.node_field(n, &w.q))) - p).amax() <= tol)?;
    Some((k, n))
}

/// Adds the velocity column `v` (3 rows) of velocity `col` to `g`: projected on `dir` into row
/// `row`, or as the three rows from `row` when `dir` is None.
#[inline]
pub(crate) fn add_column(g: &mut DMatrix<f64>, row: usize, col: usize, v: &Vec3, dir: Option<&Vec3>) {
    match dir {
        Some(d) => g[(row, col)] += d.dot(v),
        None => {
            for r in 0..3 {
                g[(row + r, col)] += v[r];
            }
        }
    }
}

/// What the elastic point rows read from the [`Data`]: placements, elastic works, body → elastic.
pub type ElasticView<'a> = (&'a [crate::spatial::Pose], &'a [crate::elastic::ElasticWork], &'a [Option<usize>]);

/// Adds `sign · dirᵀ` (or all three rows with `dir` None) of the elastic columns `A φ_nk` of the
/// world point `p` on `body` into row `row` of `g`, when `p` is an elastic node of the body.
pub fn add_elastic_point_rows(
    el: ElasticView<'_>,
    body: usize,
    p: &Vec3,
    sign: f64,
    dir: Option<&Vec3>,
    g: &mut DMatrix<f64>,
    row: usize,
) {
    let Some((k, n)) = elastic_point_at(el, body, p) else { return };
    let (w, x) = (&el.1[k], &el.0[body]);
    let ne = w.q.len();
    for kk in 0..ne {
        add_column(g, row, w.iu + kk, &(x.a * w.phi[n * ne + kk] * sign), dir);
    }
}

/// Jacobians of a body-fixed point (translational `jt`, 3 × nu) and of the body's angular velocity
/// (`jr`, 3 × nu), both I components, so that `v_P = jt u` and `ω_I = jr u` (eq. 2.69 with j = 0).
/// Requires [`positions`].
pub fn point_jacobian(
    model: &Model,
    data: &Data,
    body: usize,
    p_b: &Vec3,
    jt: &mut DMatrix<f64>,
    jr: &mut DMatrix<f64>,
) {
    jt.fill(0.0);
    jr.fill(0.0);
    let p = point_position(data, body, p_b);
    let mut b = body;
    while b != 0 {
        let j = &model.joints[b - 1];
        for k in 0..j.nu() {
            let s = &data.s[b][k];
            let v = s.v + s.w.cross(&p);
            for r in 0..3 {
                jt[(r, j.iu + k)] = v[r];
                jr[(r, j.iu + k)] = s.w[r];
            }
        }
        b = j.parent;
    }
    add_elastic_point_rows((&data.x_abs, &data.elastic, &data.body_elastic), body, &p, 1.0, None, jt, 0);
}

pub mod path;

#[cfg(test)]
mod tests;
