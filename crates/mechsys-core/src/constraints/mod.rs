//! Bilateral constraints on the tree (sections 2.1.3, 2.2.5): loop closures and driving
//! constraints that the kinematic tree itself does not express.
//!
//! Each constraint contributes rows to `Φ(q, t) = 0`, to its velocity form `G u = b(t)` with
//! `G = Wᵀ` (eq. 2.70) and to its acceleration form `G u̇ = γ`, where `γ = -(Ġ u) + ḃ` is
//! computed from the velocity-product accelerations of the tree (the accelerations at `u̇ = 0`),
//! so no derivative of `G` is ever formed explicitly. The dynamics become
//! `M u̇ = h + τ + Gᵀ λ` (Lagrange multipliers λ), solved in `dynamics::constrained`.
//!
//! Kinds: coincidence of two body points (a spherical loop closure, 3 rows), a fixed distance
//! between two body points (1 row), a coupler `q_a = r q_b + c` between joint coordinates (1 row),
//! a prescribed joint coordinate `q = f(t)` (1 row, rheonomic), a prescribed body motion (a frame's
//! origin and optionally its Cardan angles as functions of time, 3 or 6 rows, rheonomic), a point
//! on a line (2 rows) or on a plane (1 row) of another body, loop-closing spherical / revolute /
//! fixed / prismatic / cylindrical / universal / planar joints between frames on two bodies
//! (3 / 5 / 6 / 5 / 4 / 4 / 3 rows, see [`LoopJoint`]), and the non-holonomic knife edge (1 velocity
//! row), rolling disc (1 holonomic + 2 velocity rows) and user rows `W(q, t)ᵀ u + w(q, t) = 0`
//! from callbacks (any number of velocity rows).
//!
//! Rheonomic rows carry their time dependence in `b` (`Φ̇ = G u - b`) and `γ`; a user velocity
//! constraint needs the state itself in the acceleration stage ([`accelerations`]).
//!
//! Non-holonomic rows (eq. 2.70 given directly at velocity level, not reducible to eq. 2.3) have
//! velocity and acceleration rows but no position row: their `Φ` is 0 and the position projection
//! skips them ([`ConstraintKind::holonomic_rows`]; the holonomic rows of a kind come first).
//!
//! Rows that act on bodies are written through one world wrench per body and row: with `W₁`, `W₂`
//! the wrenches (moment about the origin, force) of a row, its entry for a joint velocity with
//! world subspace `S` is `S·W₁` on the path of body1 minus `S·W₂` on the path of body2, and its
//! multiplier λ loads body1 with `λ W₁` and body2 with `-λ W₂` (so `Gᵀλ` and the applied loads
//! agree by construction).

use nalgebra::DMatrix;

use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::{Callbacks, VelocityArray};
use crate::kinematics::{frame_motion, point_acceleration, point_position, point_velocity, BodyMotion};
use crate::math::{Mat3, Vec3};
use crate::model::{Model, TimeFunction};
use crate::spatial::{Force, Motion, Pose};

pub use crate::model::constraint::{Constraint, ConstraintKind, LoopJoint, Reach};

/// [`add_point_rows`] of the relative motion of world point `p1` on body `b1` and `p2` on
/// `b2`: row `row` of `g` gains `dirᵀ (J_P1 − J_P2)` (three rows for `dir = None`), the rows of a
/// contact or of a point-to-point constraint.
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_relative_rows(
    model: &Model,
    s_all: &[[Motion; 6]],
    el: crate::kinematics::ElasticView<'_>,
    (b1, p1): (usize, &Vec3),
    (b2, p2): (usize, &Vec3),
    dir: Option<&Vec3>,
    g: &mut DMatrix<f64>,
    row: usize,
) {
    add_point_rows(model, s_all, el, b1, p1, 1.0, dir, g, row);
    add_point_rows(model, s_all, el, b2, p2, -1.0, dir, g, row);
}

/// Adds `sign · dirᵀ J_T(point)` (or all three rows of `sign · J_T` when `dir` is None) of the
/// world point `p` attached to `body` into the rows of `g` starting at `row`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_point_rows(
    model: &Model,
    s_all: &[[Motion; 6]],
    el: crate::kinematics::ElasticView<'_>,
    body: usize,
    p: &Vec3,
    sign: f64,
    dir: Option<&Vec3>,
    g: &mut DMatrix<f64>,
    row: usize,
) {
    let mut b = body;
    while b != 0 {
        let j = &model.joints[b - 1];
        for k in 0..j.nu() {
            let s = &s_all[b][k];
            crate::kinematics::add_column(g, row, j.iu + k, &((s.v + s.w.cross(p)) * sign), dir);
        }
        b = j.parent;
    }
    // at an elastic node: the columns of its deflection too
    crate::kinematics::add_elastic_point_rows(el, body, p, sign, dir, g, row);
}

/// At most this many rows per constraint kind.
const MAX_ROWS: usize = 6;

/// Position-level rows of a body constraint: violations and the per-body world wrenches (see the
/// module documentation). Lives on the stack: no allocation per evaluation.
struct BodyRows {
    body1: usize,
    body2: usize,
    n: usize,
    phi: [f64; MAX_ROWS],
    /// Velocity right-hand sides (non-zero for rheonomic rows).
    b: [f64; MAX_ROWS],
    w1: [Force; MAX_ROWS],
    w2: [Force; MAX_ROWS],
    /// The world points the rows' forces act at on body1 and body2, when every row is a force
    /// there (point kinds): an elastic node there adds its deflection's columns.
    points: Option<(Vec3, Vec3)>,
    /// The elastic nodes the rows' frames sit at on body1 and body2 (loop joints): their
    /// deflections and small rotations add columns.
    nodes: [Option<(usize, usize)>; 2],
}

impl BodyRows {
    fn new(body1: usize, body2: usize) -> Self {
        BodyRows {
            body1,
            body2,
            n: 0,
            phi: [0.0; MAX_ROWS],
            b: [0.0; MAX_ROWS],
            w1: [Force::ZERO; MAX_ROWS],
            w2: [Force::ZERO; MAX_ROWS],
            points: None,
            nodes: [None, None],
        }
    }
    /// A row with violation `phi`, wrench `w1` on body1 and `w2` on body2.
    fn push(&mut self, phi: f64, w1: Force, w2: Force) {
        self.phi[self.n] = phi;
        self.w1[self.n] = w1;
        self.w2[self.n] = w2;
        self.n += 1;
    }
}

/// The elastic columns of one row whose frames sit at elastic nodes (loop joints).
#[inline]
fn add_node_rows(data: &mut Data, rows: &BodyRows, w1: &Force, w2: &Force, row: usize) {
    for (node, body, w, sign) in [(rows.nodes[0], rows.body1, w1, 1.0), (rows.nodes[1], rows.body2, w2, -1.0)] {
        if let Some(node) = node {
            let view = (&data.x_abs[..], &data.elastic[..], &data.body_elastic[..]);
            crate::kinematics::add_node_wrench_row(view, node, body, w, sign, &mut data.g, row);
        }
    }
}

/// The wrench of a unit force along `d` acting at the world point `p`: `(p × d, d)`.
#[inline]
fn force_at(p: &Vec3, d: &Vec3) -> Force {
    Force::new(p.cross(d), *d)
}

/// A pure moment about `g`.
#[inline]
fn moment(g: &Vec3) -> Force {
    Force::new(*g, Vec3::zeros())
}

/// Adds `sign · S·w` for every joint velocity on the path of `body` into row `row` of `g`.
fn add_wrench_row(
    model: &Model,
    s_all: &[[Motion; 6]],
    body: usize,
    w: &Force,
    sign: f64,
    g: &mut DMatrix<f64>,
    row: usize,
) {
    let mut b = body;
    while b != 0 {
        let j = &model.joints[b - 1];
        for k in 0..j.nu() {
            let s = &s_all[b][k];
            g[(row, j.iu + k)] += sign * (s.w.dot(&w.n) + s.v.dot(&w.f));
        }
        b = j.parent;
    }
}

/// Acceleration (velocity-product part, `data.a` at u̇ = 0) of the material point of `body` at
/// the world point `p`.
#[inline]
fn acceleration_at(data: &Data, body: usize, p: &Vec3) -> Vec3 {
    let (v, a) = (&data.v[body], &data.a[body]);
    a.v + a.w.cross(p) + v.w.cross(&(v.v + v.w.cross(p)))
}

/// `vee` of the skew-symmetric part: `½ vee(M - Mᵀ)`.
#[inline]
fn skew_vee(m: &Mat3) -> Vec3 {
    Vec3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)]) * 0.5
}

/// `E(M) = ½ (tr(M) I - M)`: with `Ṁ = w̃ M`, `d/dt ½vee(M - Mᵀ) = E(M) w`.
#[inline]
fn vee_rate_matrix(m: &Mat3) -> Mat3 {
    (Mat3::identity() * m.trace() - m) * 0.5
}

/// World direction of axis `k` of a placed frame.
#[inline]
fn frame_axis(x: &Pose, k: usize) -> Vec3 {
    x.a.column(k).into_owned()
}

/// A row `Φ = a·b` with `a` fixed in body1 and `b` fixed in body2:
/// `Φ̇ = (ω₁ × a)·b + a·(ω₂ × b) = (ω₁ - ω₂)·(a × b)`, a moment about `a × b`.
#[inline]
fn push_perpendicular(r: &mut BodyRows, a: &Vec3, b: &Vec3) {
    let m = moment(&a.cross(b));
    r.push(a.dot(b), m, m);
}

/// Velocity-product part of `d²(a·b)/dt²` for `a` fixed in frame 1, `b` fixed in frame 2:
/// `ä·b + 2 ȧ·ḃ + a·b̈`.
#[inline]
fn perpendicular_rate(m1: &BodyMotion, a: &Vec3, m2: &BodyMotion, b: &Vec3) -> f64 {
    let (ad, add) = m1.vector_rates(a);
    let (bd, bdd) = m2.vector_rates(b);
    add.dot(b) + 2.0 * ad.dot(&bd) + a.dot(&bdd)
}

/// The frame-2 axes along which a loop joint holds the origin offset (None: all three world axes).
fn offset_axes(joint: LoopJoint) -> Option<&'static [usize]> {
    match joint {
        LoopJoint::Prismatic | LoopJoint::Cylindrical => Some(&[0, 1]),
        LoopJoint::Planar => Some(&[2]),
        _ => None,
    }
}

/// Geometry of a rolling disc: world axis `a`, unit in-plane vector `k̂` towards the ground side
/// reversed (the contact point is `C - R k̂`), `|k|` and the contact point.
fn disc_contact(
    data: &Data,
    c: &Constraint,
    t: f64,
    body: usize,
    center: &Vec3,
    axis: &Vec3,
    radius: f64,
) -> Result<(Vec3, Vec3, f64, Vec3)> {
    let a = data.x_abs[body].a * axis;
    let k = Vec3::z() - a * a.z;
    let kn = k.norm();
    if kn < 1e-9 {
        return Err(Error::Solver(format!(
            "constraint '{}': the disc lies flat on the ground at t = {t} s, the contact point is undefined",
            c.name
        )));
    }
    let kh = k / kn;
    let p = point_position(data, body, center) - kh * radius;
    Ok((a, kh, kn, p))
}

/// Position-level rows of the body kinds handled through wrenches (None for the others). A
/// point coincidence comes here only when a planar selection combines its rows (its own path is
/// faster); a prescribed body motion needs `t` and the callbacks.
fn body_rows(c: &Constraint, data: &Data, t: f64, cb: &dyn Callbacks) -> Result<Option<BodyRows>> {
    let (ex, ey, ez) = (Vec3::x(), Vec3::y(), Vec3::z());
    Ok(Some(match &c.kind {
        ConstraintKind::Point { body1, p1, body2, p2 } => {
            let mut r = BodyRows::new(*body1, *body2);
            let (w1, w2) = (point_position(data, *body1, p1), point_position(data, *body2, p2));
            for e in [ex, ey, ez] {
                r.push(e.dot(&(w1 - w2)), force_at(&w1, &e), force_at(&w2, &e));
            }
            r.points = Some((w1, w2));
            r
        }
        ConstraintKind::PrescribedBody { body, frame, position, orientation } => {
            let mut r = BodyRows::new(*body, 0);
            let x = data.x_abs[*body].compose(frame);
            // Φ = r_f - p(t): Φ̇ = v_f - ṗ, a force at the frame origin along each world axis
            let [p, pd, _] = prescribed_point(position, t, cb, c, "position")?;
            for (k, e) in [ex, ey, ez].iter().enumerate() {
                r.push(x.r[k] - p[k], force_at(&x.r, e), Force::ZERO);
                r.b[k] = pd[k];
            }
            if let Some(angles) = orientation {
                // Q = A_f A_pᵀ, Q̇ = (ω_f - Q ω_p)~ Q: Φ̇ = E(Q) ω_f - E(Q) Q ω_p; the row k
                // of E(Q) is a moment
                let (a_p, w_p, _) = prescribed_rotation(angles, t, cb, c)?;
                let qm = x.a * a_p.transpose();
                let phi = skew_vee(&qm);
                let e = vee_rate_matrix(&qm);
                let b = e * (qm * w_p);
                for k in 0..3 {
                    r.push(phi[k], moment(&e.row(k).transpose()), Force::ZERO);
                    r.b[3 + k] = b[k];
                }
            }
            r
        }
        ConstraintKind::PointOnLine { body1, p1, body2, p2, n } => {
            let mut r = BodyRows::new(*body1, *body2);
            let (w1, w2) = (point_position(data, *body1, p1), point_position(data, *body2, p2));
            let a2 = &data.x_abs[*body2].a;
            for nb in n {
                // body2's Jacobian at r₁ carries the ṅ·d term: n·(v₁ - v₂(r₁)) = n·ḋ + ṅ·d
                let nw = a2 * nb;
                let f = force_at(&w1, &nw);
                r.push(nw.dot(&(w1 - w2)), f, f);
            }
            r
        }
        ConstraintKind::PointOnPlane { body1, p1, body2, p2, n } => {
            let mut r = BodyRows::new(*body1, *body2);
            let (w1, w2) = (point_position(data, *body1, p1), point_position(data, *body2, p2));
            let nw = data.x_abs[*body2].a * n;
            let f = force_at(&w1, &nw);
            r.push(nw.dot(&(w1 - w2)), f, f);
            r
        }
        ConstraintKind::Loop { joint, body1, f1, body2, f2 } => {
            let mut r = BodyRows::new(*body1, *body2);
            let ((m1, n1), (m2, n2)) = (frame_motion(data, *body1, f1), frame_motion(data, *body2, f2));
            let (x1, x2) = (m1.pose, m2.pose);
            r.nodes = [n1, n2];
            let d = x1.r - x2.r;
            match offset_axes(*joint) {
                None => {
                    for e in [ex, ey, ez] {
                        r.push(e.dot(&d), force_at(&x1.r, &e), force_at(&x2.r, &e));
                    }
                }
                Some(axes) => {
                    // n fixed in body2: as for PointOnLine, body2's Jacobian at r₁ carries ṅ·d
                    for &k in axes {
                        let n = frame_axis(&x2, k);
                        let f = force_at(&x1.r, &n);
                        r.push(n.dot(&d), f, f);
                    }
                }
            }
            match joint {
                LoopJoint::Spherical => {}
                LoopJoint::Revolute | LoopJoint::Cylindrical | LoopJoint::Planar => {
                    // Φ = z₁·x₂, z₁·y₂
                    let z1 = frame_axis(&x1, 2);
                    push_perpendicular(&mut r, &z1, &frame_axis(&x2, 0));
                    push_perpendicular(&mut r, &z1, &frame_axis(&x2, 1));
                }
                LoopJoint::Universal => push_perpendicular(&mut r, &frame_axis(&x1, 0), &frame_axis(&x2, 1)),
                LoopJoint::Fixed | LoopJoint::Prismatic => {
                    // R = A₂ᵀA₁ (frame 1 in frame 2), Φ = ½ vee(R - Rᵀ) = sin θ · axis (frame 2),
                    // Φ̇ = E(R) A₂ᵀ (ω₁ - ω₂) exactly: row k is the moment column k of A₂ E(R)ᵀ
                    let rel = x2.a.transpose() * x1.a;
                    let phi = skew_vee(&rel);
                    let g = x2.a * vee_rate_matrix(&rel).transpose();
                    for k in 0..3 {
                        let m = moment(&g.column(k).into_owned());
                        r.push(phi[k], m, m);
                    }
                }
            }
            r
        }
        ConstraintKind::KnifeEdge { body, p, e } => {
            let mut r = BodyRows::new(*body, 0);
            let w = point_position(data, *body, p);
            let ew = data.x_abs[*body].a * e;
            r.push(0.0, force_at(&w, &ew), Force::ZERO);
            r
        }
        ConstraintKind::RollingDisc { body, center, axis, radius } => {
            let mut r = BodyRows::new(*body, 0);
            let (_, _, _, p) = disc_contact(data, c, t, *body, center, axis, *radius)?;
            r.push(p.z, force_at(&p, &ez), Force::ZERO);
            r.push(0.0, force_at(&p, &ex), Force::ZERO);
            r.push(0.0, force_at(&p, &ey), Force::ZERO);
            r
        }
        _ => return Ok(None),
    }))
}

/// Velocity-product part of the time derivative of the velocity rows of the body kinds, i.e.
/// `-γ` (`Ġ u`), into `out`; false for the other kinds.
fn body_rows_rate(c: &Constraint, data: &Data, t: f64, cb: &dyn Callbacks, out: &mut [f64; MAX_ROWS]) -> Result<bool> {
    match &c.kind {
        ConstraintKind::Point { body1, p1, body2, p2 } => {
            let a = point_acceleration(data, *body1, p1) - point_acceleration(data, *body2, p2);
            out[..3].copy_from_slice(a.as_slice());
        }
        ConstraintKind::PrescribedBody { body, frame, position, orientation } => {
            let x = data.x_abs[*body].compose(frame);
            // Φ̈ = a_f - p̈
            let [_, _, pdd] = prescribed_point(position, t, cb, c, "position")?;
            let acc = acceleration_at(data, *body, &x.r);
            for k in 0..3 {
                out[k] = acc[k] - pdd[k];
            }
            if let Some(angles) = orientation {
                // Φ̇ = E(Q) w, w = ω_f - Q ω_p, Q̇ = w̃ Q: Φ̈ = E(Q̇) w + E(Q) ẇ with
                // ẇ = ω̇_f - w × (Q ω_p) - Q ω̇_p
                let (a_p, w_p, wd_p) = prescribed_rotation(angles, t, cb, c)?;
                let qm = x.a * a_p.transpose();
                let qw = qm * w_p;
                let w = data.v[*body].w - qw;
                let qm_d = w.cross_matrix() * qm;
                let wd = data.a[*body].w - w.cross(&qw) - qm * wd_p;
                let phidd = vee_rate_matrix(&qm_d) * w + vee_rate_matrix(&qm) * wd;
                out[3..6].copy_from_slice(phidd.as_slice());
            }
        }
        ConstraintKind::PointOnLine { body1, p1, body2, p2, .. }
        | ConstraintKind::PointOnPlane { body1, p1, body2, p2, .. } => {
            // Φ = n·d with n fixed in body2: Φ̈ = n̈·d + 2 ṅ·ḋ + n·d̈
            let d = point_position(data, *body1, p1) - point_position(data, *body2, p2);
            let dd = point_velocity(data, *body1, p1) - point_velocity(data, *body2, p2);
            let ddd = point_acceleration(data, *body1, p1) - point_acceleration(data, *body2, p2);
            let a2 = data.x_abs[*body2].a;
            let mut one = |k: usize, nb: &Vec3| {
                let nw = a2 * nb;
                let (nd, ndd) = BodyMotion::from_data(data, *body2).vector_rates(&nw);
                out[k] = ndd.dot(&d) + 2.0 * nd.dot(&dd) + nw.dot(&ddd);
            };
            match &c.kind {
                ConstraintKind::PointOnLine { n, .. } => {
                    one(0, &n[0]);
                    one(1, &n[1]);
                }
                ConstraintKind::PointOnPlane { n, .. } => one(0, n),
                _ => unreachable!(),
            }
        }
        ConstraintKind::Loop { joint, body1, f1, body2, f2 } => {
            let ((m1, _), (m2, _)) = (frame_motion(data, *body1, f1), frame_motion(data, *body2, f2));
            let (x1, x2) = (m1.pose, m2.pose);
            let ddd = m1.point_acceleration(&x1.r) - m2.point_acceleration(&x2.r);
            let mut k = match offset_axes(*joint) {
                None => {
                    out[..3].copy_from_slice(ddd.as_slice());
                    3
                }
                Some(axes) => {
                    // Φ = n·d with n fixed in body2: Φ̈ = n̈·d + 2 ṅ·ḋ + n·d̈
                    let d = x1.r - x2.r;
                    let dd = m1.point_velocity(&x1.r) - m2.point_velocity(&x2.r);
                    for (i, &ax) in axes.iter().enumerate() {
                        let n = frame_axis(&x2, ax);
                        let (nd, ndd) = m2.vector_rates(&n);
                        out[i] = ndd.dot(&d) + 2.0 * nd.dot(&dd) + n.dot(&ddd);
                    }
                    axes.len()
                }
            };
            match joint {
                LoopJoint::Spherical => {}
                LoopJoint::Revolute | LoopJoint::Cylindrical | LoopJoint::Planar => {
                    let z1 = frame_axis(&x1, 2);
                    for ax in 0..2 {
                        out[k] = perpendicular_rate(&m1, &z1, &m2, &frame_axis(&x2, ax));
                        k += 1;
                    }
                }
                LoopJoint::Universal => {
                    out[k] = perpendicular_rate(&m1, &frame_axis(&x1, 0), &m2, &frame_axis(&x2, 1));
                }
                LoopJoint::Fixed | LoopJoint::Prismatic => {
                    // Φ̇ = E(R) w, w = A₂ᵀ ω_rel; Ṙ = w̃ R, ẇ = A₂ᵀ (ω̇_rel - ω₂ × ω_rel)
                    let rel = x2.a.transpose() * x1.a;
                    let (w1, w2) = (m1.twist.w, m2.twist.w);
                    let wrel = w1 - w2;
                    let arel = m1.acc.w - m2.acc.w;
                    let a2t = x2.a.transpose();
                    let w = a2t * wrel;
                    let wd = a2t * (arel - w2.cross(&wrel));
                    let rel_d = w.cross_matrix() * rel;
                    let phidd = vee_rate_matrix(&rel_d) * w + vee_rate_matrix(&rel) * wd;
                    out[k..k + 3].copy_from_slice(phidd.as_slice());
                }
            }
        }
        ConstraintKind::KnifeEdge { body, p, e } => {
            // d/dt (e·v_P) = ė·v_P + e·a_P
            let ew = data.x_abs[*body].a * e;
            let (ed, _) = BodyMotion::from_data(data, *body).vector_rates(&ew);
            out[0] = ed.dot(&point_velocity(data, *body, p)) + ew.dot(&point_acceleration(data, *body, p));
        }
        ConstraintKind::RollingDisc { body, center, axis, radius } => {
            // G u = e·(v_O + ω × P) with P the (moving) contact point:
            // d/dt = e·(a_O + ω̇ × P + ω × Ṗ), Ṗ = v_C - R dk̂/dt
            let (a, kh, kn, p) = disc_contact(data, c, t, *body, center, axis, *radius)?;
            let (v, acc) = (&data.v[*body], &data.a[*body]);
            let ad = v.w.cross(&a);
            let kd = -(a * ad.z + ad * a.z);
            let khd = (kd - kh * kh.dot(&kd)) / kn;
            let pd = point_velocity(data, *body, center) - khd * *radius;
            let r = acc.v + acc.w.cross(&p) + v.w.cross(&pd);
            out[0] = r.z;
            out[1] = r.x;
            out[2] = r.y;
        }
        _ => return Ok(false),
    }
    Ok(true)
}

/// Value and first two time derivatives of a time function (callbacks by central differences).
pub fn function_derivatives(f: &TimeFunction, t: f64, cb: &dyn Callbacks) -> Result<(f64, f64, f64)> {
    Ok(match f {
        TimeFunction::Constant(v) => (*v, 0.0, 0.0),
        TimeFunction::Ramp { slope, t0, .. } => {
            let v = f.eval(t, cb)?;
            let rising = t >= *t0 && (v - slope * (t - t0)).abs() < 1e-300f64.max(1e-12 * v.abs());
            (v, if rising { *slope } else { 0.0 }, 0.0)
        }
        TimeFunction::Harmonic { amplitude, omega, phase, offset } => {
            let (s, c) = (omega * t + phase).sin_cos();
            (offset + amplitude * s, amplitude * omega * c, -amplitude * omega * omega * s)
        }
        TimeFunction::Table { t: ts, values } => {
            let v = f.eval(t, cb)?;
            let n = ts.len();
            let slope = if n < 2 || t <= ts[0] || t >= ts[n - 1] {
                0.0
            } else {
                let k = ts.partition_point(|x| *x <= t).clamp(1, n - 1);
                (values[k] - values[k - 1]) / (ts[k] - ts[k - 1])
            };
            (v, slope, 0.0)
        }
        TimeFunction::Callback(_) => {
            let h = 1e-4 * t.abs().max(1.0);
            let (fm, f0, fp) = (f.eval(t - h, cb)?, f.eval(t, cb)?, f.eval(t + h, cb)?);
            (f0, (fp - fm) / (2.0 * h), (fp - 2.0 * f0 + fm) / (h * h))
        }
    })
}

/// Prefixes a callback's error with the constraint and key it belongs to.
fn in_constraint<'a>(c: &'a Constraint, key: &str) -> impl Fn(Error) -> Error + 'a {
    let key = if key.is_empty() { String::new() } else { format!(".{key}") };
    move |e| match e {
        Error::Callback(m) => Error::Callback(format!("constraint '{}'{key}: {m}", c.name)),
        other => other,
    }
}

/// `Wᵀ(t, q) u + w(t, q)` of a user velocity constraint into `out` (rows).
#[allow(clippy::too_many_arguments)]
fn velocity_residual(
    model: &Model,
    c: &Constraint,
    (w_matrix, w_offset): (usize, Option<usize>),
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    out: &mut [f64],
) -> Result<()> {
    let (rows, nu) = (out.len(), model.nu);
    let mut w = vec![0.0; rows * nu];
    cb.velocity_constraint(w_matrix, VelocityArray::W, t, q, &[], rows, &mut w).map_err(in_constraint(c, ""))?;
    match w_offset {
        Some(id) => {
            cb.velocity_constraint(id, VelocityArray::Offset, t, q, &[], rows, out).map_err(in_constraint(c, ""))?
        }
        None => out.fill(0.0),
    }
    for (k, o) in out.iter_mut().enumerate() {
        *o += w[k * nu..(k + 1) * nu].iter().zip(u).map(|(a, b)| a * b).sum::<f64>();
    }
    Ok(())
}

/// `γ = -(d(Wᵀ)/dt u + ẇ)` of a user velocity constraint without a rate callback: central
/// differences of `Wᵀ u + w` along the motion, `q(s) = q ⊕ u s` (Model::integrate), `t + s`, u held,
/// with the step `h = ε^(1/3) / max(1, |u|∞)` (balances the O(h²) truncation against round-off
/// for motions of unit time scale) rounded so that `t + h - t = h` exactly.
#[allow(clippy::too_many_arguments)]
fn velocity_rate_by_differences(
    model: &Model,
    c: &Constraint,
    ids: (usize, Option<usize>),
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    gamma: &mut [f64],
) -> Result<()> {
    let umax = u.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let h0 = f64::EPSILON.cbrt() / umax;
    let h = (t + h0) - t;
    let mut qs = vec![0.0; model.nq];
    let (mut plus, mut minus) = (vec![0.0; gamma.len()], vec![0.0; gamma.len()]);
    model.integrate(q, u, h, &mut qs);
    velocity_residual(model, c, ids, t + h, &qs, u, cb, &mut plus)?;
    model.integrate(q, u, -h, &mut qs);
    velocity_residual(model, c, ids, t - h, &qs, u, cb, &mut minus)?;
    for (g, (p, m)) in gamma.iter_mut().zip(plus.iter().zip(&minus)) {
        *g = -(p - m) / (2.0 * h);
    }
    Ok(())
}

/// Value, rate and second derivative of three time functions (a prescribed world point); a
/// callback's error names constraint `c` and the function `key[k]`.
fn prescribed_point(f: &[TimeFunction; 3], t: f64, cb: &dyn Callbacks, c: &Constraint, key: &str) -> Result<[Vec3; 3]> {
    let mut out = [Vec3::zeros(); 3];
    for (k, fk) in f.iter().enumerate() {
        let (v, vd, vdd) = function_derivatives(fk, t, cb).map_err(in_constraint(c, &format!("{key}[{k}]")))?;
        out[0][k] = v;
        out[1][k] = vd;
        out[2][k] = vdd;
    }
    Ok(out)
}

/// Orientation `A_p = Rx(α) Ry(β) Rz(γ)` of prescribed Cardan angles (eq. 2.19), its world angular
/// velocity `ω_p = α̇ eₓ + β̇ c₂ + γ̇ c₃` (eq. 2.32: `c₂ = Rx(α) e_y`, `c₃ = Rx(α) Ry(β) e_z`) and
/// angular acceleration `ω̇_p = α̈ eₓ + β̈ c₂ + γ̈ c₃ + β̇ ċ₂ + γ̇ ċ₃`, where `ċ₂ = α̇ eₓ × c₂`
/// and `ċ₃ = (α̇ eₓ + β̇ c₂) × c₃` (the angular velocities of the intermediate frames).
fn prescribed_rotation(
    f: &[TimeFunction; 3],
    t: f64,
    cb: &dyn Callbacks,
    c: &Constraint,
) -> Result<(Mat3, Vec3, Vec3)> {
    let [a, ad, add] = prescribed_point(f, t, cb, c, "orientation")?;
    let a_p = crate::math::rotation::cardan_xyz_to_matrix([a[0], a[1], a[2]]);
    let h = crate::math::rotation::cardan_h_inertial([a[0], a[1], a[2]]);
    let (ex, c2, c3) = (Vec3::x(), h.column(1).into_owned(), h.column(2).into_owned());
    let w1 = ex * ad[0];
    let c2d = w1.cross(&c2);
    let c3d = (w1 + c2 * ad[1]).cross(&c3);
    let w = h * ad;
    let wd = h * add + c2d * ad[1] + c3d * ad[2];
    Ok((a_p, w, wd))
}

/// `Q` from `φ = ½ vee(Q - Qᵀ) = sin θ · n` for θ ≤ π/2 (Rodrigues with `cos θ = √(1 - |φ|²)`):
/// `Q = cos θ I + φ̃ + φφᵀ / (1 + cos θ)`.
fn rotation_from_vee(phi: &Vec3) -> Mat3 {
    let c = (1.0 - phi.norm_squared()).max(0.0).sqrt();
    Mat3::identity() * c + phi.cross_matrix() + phi * phi.transpose() / (1.0 + c)
}

/// Geometry of a held-closed contact at the placements in `data`: its first candidate (gap,
/// normal, world points) and tangents; an error naming the constraint where the narrow phase
/// gives no finite answer.
fn held_contact(
    c: &Constraint,
    data: &Data,
    t: f64,
    body1: usize,
    body2: usize,
    pair: &crate::contact::ContactPair,
) -> Result<(crate::contact::narrow::Raw, [Vec3; 2])> {
    let (x1, x2) = (data.x_abs[body1], data.x_abs[body2]);
    let k = pair.candidate(0, &x1, &x2, None);
    if !(k.g.is_finite() && k.n.iter().all(|v| v.is_finite())) {
        return Err(Error::Solver(format!(
            "constraint '{}' (bilateral contact): the contact geometry is undefined at t = {t} s (gap {})",
            c.name, k.g
        )));
    }
    let tg = pair.tangents(&x2, &k.n, None);
    Ok((k, [tg.t1, tg.t2]))
}

/// Position stage of the constraints: `phi` (m) and `G` (m × nu) at the last
/// [`crate::kinematics::positions`]; `b` (m) receives the velocity right-hand side `G u = b`.
pub fn positions(model: &Model, data: &mut Data, t: f64, q: &[f64], cb: &dyn Callbacks) -> Result<()> {
    // rows write only on their planned pattern (`reach`), so clearing that is enough: O(nonzeros)
    // instead of O(nc · nu)
    for r in 0..model.nc {
        for p in data.g_row_ptr[r]..data.g_row_ptr[r + 1] {
            data.g[(r, data.g_row_idx[p])] = 0.0;
        }
    }
    for c in &model.constraints {
        let r = c.row;
        if let Some(sel) = &c.select {
            // planar: constant combinations of the kind's spatial rows
            let rows = body_rows(c, data, t, cb)?.expect("a selected constraint has body rows");
            for (k, s) in sel.s.iter().enumerate().take(sel.n) {
                let (mut phi, mut b, mut w1, mut w2) = (0.0, 0.0, Force::ZERO, Force::ZERO);
                for j in 0..rows.n {
                    phi += s[j] * rows.phi[j];
                    b += s[j] * rows.b[j];
                    w1 += rows.w1[j] * s[j];
                    w2 += rows.w2[j] * s[j];
                }
                data.phi[r + k] = phi;
                data.b[r + k] = b;
                add_wrench_row(model, &data.s, rows.body1, &w1, 1.0, &mut data.g, r + k);
                add_wrench_row(model, &data.s, rows.body2, &w2, -1.0, &mut data.g, r + k);
                if let Some((p1, p2)) = rows.points {
                    let view = (&data.x_abs[..], &data.elastic[..], &data.body_elastic[..]);
                    crate::kinematics::add_elastic_point_rows(
                        view,
                        rows.body1,
                        &p1,
                        1.0,
                        Some(&w1.f),
                        &mut data.g,
                        r + k,
                    );
                    crate::kinematics::add_elastic_point_rows(
                        view,
                        rows.body2,
                        &p2,
                        -1.0,
                        Some(&w2.f),
                        &mut data.g,
                        r + k,
                    );
                }
                add_node_rows(data, &rows, &w1, &w2, r + k);
            }
            continue;
        }
        match &c.kind {
            ConstraintKind::Point { body1, p1, body2, p2 } => {
                let (w1, w2) = (point_position(data, *body1, p1), point_position(data, *body2, p2));
                let d = w1 - w2;
                for k in 0..3 {
                    data.phi[r + k] = d[k];
                    data.b[r + k] = 0.0;
                }
                add_relative_rows(
                    model,
                    &data.s,
                    (&data.x_abs, &data.elastic, &data.body_elastic),
                    (*body1, &w1),
                    (*body2, &w2),
                    None,
                    &mut data.g,
                    r,
                );
            }
            ConstraintKind::Distance { body1, p1, body2, p2, length } => {
                let (w1, w2) = (point_position(data, *body1, p1), point_position(data, *body2, p2));
                let d = w1 - w2;
                let l = d.norm();
                if l < 1e-12 * length.max(1.0) {
                    return Err(Error::Solver(format!(
                        "constraint '{}': its two points coincide at t = {t} s, the distance direction is undefined",
                        c.name
                    )));
                }
                let e = d / l;
                data.phi[r] = l - length;
                data.b[r] = 0.0;
                add_relative_rows(
                    model,
                    &data.s,
                    (&data.x_abs, &data.elastic, &data.body_elastic),
                    (*body1, &w1),
                    (*body2, &w2),
                    Some(&e),
                    &mut data.g,
                    r,
                );
            }
            ConstraintKind::Contact { body1, body2, pair, normal, .. } => {
                // g_N = 0 (holonomic), then ġ_T = 0 along each friction direction (rolling);
                // without the normal row the tangents alone
                let (k, tg) = held_contact(c, data, t, *body1, *body2, pair)?;
                let rows = c.kind.rows();
                let skip = usize::from(!*normal);
                for (j, e) in std::iter::once(&k.n).chain(tg.iter()).skip(skip).take(rows).enumerate() {
                    data.phi[r + j] = if j == 0 && *normal { k.g } else { 0.0 };
                    data.b[r + j] = 0.0;
                    add_relative_rows(
                        model,
                        &data.s,
                        (&data.x_abs, &data.elastic, &data.body_elastic),
                        (*body1, &k.p1),
                        (*body2, &k.p2),
                        Some(e),
                        &mut data.g,
                        r + j,
                    );
                }
            }
            ConstraintKind::Gap { function, slot, .. } => {
                // the gap's rows at (q, t) (its rates need u: evaluated at u = 0 here, the rows
                // and ∂g/∂t do not depend on it)
                let nu = model.nu;
                let mut k = crate::contact::ContactKinematics::default();
                let zero = std::mem::take(&mut data.zero_u);
                let res = function.evaluate(t, q, &zero, cb, &mut data.gap, *slot, true, &mut k);
                data.zero_u = zero;
                res.map_err(in_constraint(c, ""))?;
                for j in 0..c.kind.rows() {
                    data.phi[r + j] = if j == 0 { k.point.g_n } else { 0.0 };
                    // G u = b: W_jᵀ u + w̃_j = 0
                    data.b[r + j] = -k.w_tilde[j];
                    for i in 0..nu {
                        data.g[(r + j, i)] += data.gap.rows[(3 * slot + j) * nu + i];
                    }
                }
            }
            ConstraintKind::Coupler { iq_a, iu_a, iq_b, iu_b, ratio, offset } => {
                data.phi[r] = q[*iq_a] - ratio * q[*iq_b] - offset;
                data.b[r] = 0.0;
                data.g[(r, *iu_a)] += 1.0;
                data.g[(r, *iu_b)] -= ratio;
            }
            ConstraintKind::Prescribed { iq, iu, function } => {
                let (f, fd, _) = function_derivatives(function, t, cb).map_err(in_constraint(c, "function"))?;
                data.phi[r] = q[*iq] - f;
                data.b[r] = fd;
                data.g[(r, *iu)] += 1.0;
            }
            ConstraintKind::Velocity { rows, w_matrix, w_offset, .. } => {
                let (rows, nu) = (*rows, model.nu);
                let mut w = vec![0.0; rows * nu];
                cb.velocity_constraint(*w_matrix, VelocityArray::W, t, q, &[], rows, &mut w)
                    .map_err(in_constraint(c, ""))?;
                for k in 0..rows {
                    data.phi[r + k] = 0.0;
                    for i in 0..nu {
                        data.g[(r + k, i)] += w[k * nu + i];
                    }
                }
                // G u = b with b = -w(q, t)
                let b = &mut data.b[r..r + rows];
                match w_offset {
                    Some(id) => {
                        cb.velocity_constraint(*id, VelocityArray::Offset, t, q, &[], rows, b)
                            .map_err(in_constraint(c, ""))?;
                        b.iter_mut().for_each(|v| *v = -*v);
                    }
                    None => b.fill(0.0),
                }
            }
            _ => {
                let rows = body_rows(c, data, t, cb)?.expect("a body constraint kind");
                for k in 0..rows.n {
                    data.phi[r + k] = rows.phi[k];
                    data.b[r + k] = rows.b[k];
                    add_wrench_row(model, &data.s, rows.body1, &rows.w1[k], 1.0, &mut data.g, r + k);
                    add_wrench_row(model, &data.s, rows.body2, &rows.w2[k], -1.0, &mut data.g, r + k);
                    add_node_rows(data, &rows, &rows.w1[k], &rows.w2[k], r + k);
                }
            }
        }
    }
    Ok(())
}

/// Acceleration right-hand side `γ` of `G u̇ = γ` (m) at the state (t, q, u) of the last
/// kinematics (a user velocity constraint evaluates its callbacks there). Requires the velocities
/// of the state and `data.a` holding the velocity-product accelerations (u̇ = 0, no gravity).
pub fn accelerations(model: &Model, data: &mut Data, t: f64, q: &[f64], u: &[f64], cb: &dyn Callbacks) -> Result<()> {
    for c in &model.constraints {
        let r = c.row;
        if let Some(sel) = &c.select {
            let mut rate = [0.0; MAX_ROWS];
            body_rows_rate(c, data, t, cb, &mut rate)?;
            for (k, s) in sel.s.iter().enumerate().take(sel.n) {
                data.gamma[r + k] = -s.iter().zip(&rate).map(|(a, b)| a * b).sum::<f64>();
            }
            continue;
        }
        match &c.kind {
            ConstraintKind::Velocity { rows, w_matrix, w_offset, w_rate } => {
                let gamma = &mut data.gamma[r..r + rows];
                match w_rate {
                    Some(id) => {
                        cb.velocity_constraint(*id, VelocityArray::Rate, t, q, u, *rows, gamma)
                            .map_err(in_constraint(c, ""))?;
                        gamma.iter_mut().for_each(|v| *v = -*v);
                    }
                    None => velocity_rate_by_differences(model, c, (*w_matrix, *w_offset), t, q, u, cb, gamma)?,
                }
            }
            ConstraintKind::Point { body1, p1, body2, p2 } => {
                let a = point_acceleration(data, *body1, p1) - point_acceleration(data, *body2, p2);
                for k in 0..3 {
                    data.gamma[r + k] = -a[k];
                }
            }
            ConstraintKind::Distance { body1, p1, body2, p2, .. } => {
                let d = point_position(data, *body1, p1) - point_position(data, *body2, p2);
                let l = d.norm();
                let e = d / l;
                let v = point_velocity(data, *body1, p1) - point_velocity(data, *body2, p2);
                let a = point_acceleration(data, *body1, p1) - point_acceleration(data, *body2, p2);
                // d²|d|/dt² = e·a + (|v|² - (e·v)²)/|d|
                data.gamma[r] = -(e.dot(&a) + (v.norm_squared() - e.dot(&v).powi(2)) / l);
            }
            ConstraintKind::Contact { body1, body2, pair, normal, .. } => {
                // the velocity-product parts w̄_N, w̄_T of the contact kinematics (eqs. 2.114,
                // 2.115): data.a holds the tree's accelerations at u̇ = 0 here
                use crate::contact::{contact_kinematics, BodyMotion, ContactKinematics};
                let (b1, b2) = (BodyMotion::from_data(data, *body1), BodyMotion::from_data(data, *body2));
                let mut k = [ContactKinematics::default(); 1];
                contact_kinematics(pair, &b1, &b2, &mut k)
                    .map_err(|e| Error::Solver(format!("constraint '{}' (bilateral contact): {e}", c.name)))?;
                let rows = c.kind.rows();
                let skip = usize::from(!*normal);
                for j in 0..rows {
                    let a = j + skip;
                    data.gamma[r + j] = if a == 0 { -k[0].wbar_n } else { -k[0].wbar_t[a - 1] };
                }
            }
            ConstraintKind::Gap { function, slot, .. } => {
                let mut k = crate::contact::ContactKinematics::default();
                function.evaluate(t, q, u, cb, &mut data.gap, *slot, false, &mut k).map_err(in_constraint(c, ""))?;
                data.gamma[r] = -k.wbar_n;
                for j in 1..c.kind.rows() {
                    data.gamma[r + j] = -k.wbar_t[j - 1];
                }
            }
            ConstraintKind::Coupler { .. } => data.gamma[r] = 0.0,
            ConstraintKind::Prescribed { function, .. } => {
                data.gamma[r] = function_derivatives(function, t, cb).map_err(in_constraint(c, "function"))?.2;
            }
            _ => {
                let mut rate = [0.0; MAX_ROWS];
                body_rows_rate(c, data, t, cb, &mut rate)?;
                for k in 0..c.kind.rows() {
                    data.gamma[r + k] = -rate[k];
                }
            }
        }
    }
    Ok(())
}

/// Adds the constraint forces `Gᵀ λ` of the last solve to the loads: point forces on the bodies
/// (`data.f_ext`) and generalized forces on joint coordinates (`data.tau_applied`), so that the
/// reaction forces at the joints include them.
pub fn apply_forces(model: &Model, data: &mut Data) {
    apply_forces_checked(model, data).expect("constraint geometry was valid in the last solve");
}

fn apply_forces_checked(model: &Model, data: &mut Data) -> Result<()> {
    for c in &model.constraints {
        let r = c.row;
        if let Some(sel) = &c.select {
            // the multipliers of the kind's spatial rows: λ_full = Sᵀ λ (likewise Φ)
            let (mut lam, mut phi) = ([0.0; MAX_ROWS], [0.0; MAX_ROWS]);
            for (k, s) in sel.s.iter().enumerate().take(sel.n) {
                for j in 0..MAX_ROWS {
                    lam[j] += s[j] * data.lambda[r + k];
                    phi[j] += s[j] * data.phi[r + k];
                }
            }
            if let ConstraintKind::PrescribedBody { body, frame, .. } = &c.kind {
                let x = data.x_abs[*body].compose(frame);
                let f = Vec3::new(lam[0], lam[1], lam[2]);
                let e = vee_rate_matrix(&rotation_from_vee(&Vec3::new(phi[3], phi[4], phi[5])));
                data.f_ext[*body] += Force::new(x.r.cross(&f) + e.transpose() * Vec3::new(lam[3], lam[4], lam[5]), f);
            } else {
                let rows = body_rows(c, data, f64::NAN, &crate::forces::NoCallbacks)?.expect("a body constraint kind");
                for (k, l) in lam.iter().enumerate().take(rows.n) {
                    if rows.body1 != 0 {
                        data.f_ext[rows.body1] += rows.w1[k] * *l;
                    }
                    if rows.body2 != 0 {
                        data.f_ext[rows.body2] += rows.w2[k] * (-*l);
                    }
                }
            }
            continue;
        }
        match &c.kind {
            ConstraintKind::Point { body1, p1, body2, p2 } => {
                let l = Vec3::new(data.lambda[r], data.lambda[r + 1], data.lambda[r + 2]);
                add_point_force(data, *body1, p1, &l);
                add_point_force(data, *body2, p2, &(-l));
            }
            ConstraintKind::Distance { body1, p1, body2, p2, .. } => {
                let d = point_position(data, *body1, p1) - point_position(data, *body2, p2);
                let f = d / d.norm() * data.lambda[r];
                add_point_force(data, *body1, p1, &f);
                add_point_force(data, *body2, p2, &(-f));
            }
            ConstraintKind::Contact { body1, body2, pair, normal, .. } => {
                let (k, tg) = held_contact(c, data, f64::NAN, *body1, *body2, pair)?;
                let skip = usize::from(!*normal);
                let mut f = Vec3::zeros();
                for j in 0..c.kind.rows() {
                    let a = j + skip;
                    f += if a == 0 { k.n } else { tg[a - 1] } * data.lambda[r + j];
                }
                if *body1 != 0 {
                    data.f_ext[*body1] += Force::new(k.p1.cross(&f), f);
                }
                if *body2 != 0 {
                    data.f_ext[*body2] += Force::new(k.p2.cross(&(-f)), -f);
                }
            }
            ConstraintKind::Coupler { iu_a, iu_b, ratio, .. } => {
                data.tau_applied[*iu_a] += data.lambda[r];
                data.tau_applied[*iu_b] -= ratio * data.lambda[r];
            }
            ConstraintKind::Prescribed { iu, .. } => data.tau_applied[*iu] += data.lambda[r],
            ConstraintKind::Gap { .. } | ConstraintKind::Velocity { .. } => {
                // W λ, with W from the last position stage
                for k in r..r + c.kind.rows() {
                    for i in 0..model.nu {
                        data.tau_applied[i] += data.g[(k, i)] * data.lambda[k];
                    }
                }
            }
            ConstraintKind::PrescribedBody { body, frame, orientation, .. } => {
                let x = data.x_abs[*body].compose(frame);
                let f = Vec3::new(data.lambda[r], data.lambda[r + 1], data.lambda[r + 2]);
                let mut w = Force::new(x.r.cross(&f), f);
                if orientation.is_some() {
                    // the moment rows are those of E(Q); t is not at hand here, but Q follows
                    // from the violation of the last position stage (exact while θ ≤ π/2)
                    let phi = Vec3::new(data.phi[r + 3], data.phi[r + 4], data.phi[r + 5]);
                    let e = vee_rate_matrix(&rotation_from_vee(&phi));
                    let l = Vec3::new(data.lambda[r + 3], data.lambda[r + 4], data.lambda[r + 5]);
                    w.n += e.transpose() * l;
                }
                data.f_ext[*body] += w;
            }
            _ => {
                let rows = body_rows(c, data, f64::NAN, &crate::forces::NoCallbacks)?.expect("a body constraint kind");
                for k in 0..rows.n {
                    let l = data.lambda[r + k];
                    if rows.body1 != 0 {
                        data.f_ext[rows.body1] += rows.w1[k] * l;
                    }
                    if rows.body2 != 0 {
                        data.f_ext[rows.body2] += rows.w2[k] * (-l);
                    }
                }
            }
        }
    }
    Ok(())
}

fn add_point_force(data: &mut Data, body: usize, p_b: &Vec3, f: &Vec3) {
    if body != 0 {
        let p = point_position(data, body, p_b);
        data.f_ext[body] += crate::spatial::Force::new(p.cross(f), *f);
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod tests_kinds;
