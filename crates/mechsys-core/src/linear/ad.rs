//! Exact first derivatives of the inverse dynamics by forward-mode automatic differentiation, for
//! the linearization of eq. 2.204.
//!
//! The inverse dynamics of the tree, `ID(q, u, u̇) = M(q) u̇ − h(q, u, t)` (the generalized forces
//! beyond the model's own that produce `u̇`; section 2.3 projected as in eq. 2.70, all force
//! elements inside `h`), is written here once more over a generic scalar `T`: the joint
//! placements, motion subspaces and biases of every joint type (as in `model::joint`), the
//! recursive kinematics in world components (eqs. 2.45–2.58, as in `kinematics`), the body
//! inertias, the force elements (as in `forces`) and the recursive Newton–Euler passes (as in
//! `dynamics::rnea`). Evaluated on dual numbers `x + ε ẋ` (`ε² = 0`), one pass gives the value
//! and the exact directional derivative along the seeded tangent; with `T = f64` it is the plain
//! inverse dynamics, which the tests hold against the engine's own RNEA.
//!
//! Directions. The minimal coordinates y live in the tangent chart `q = q* ⊕ V y` of
//! `Model::integrate` (quaternions turned by rotation vectors in the child frame,
//! `q ⊗ exp(½ ω)`; the free joint's position moved by `A(q) v`). The derivative of that chart
//! along column `V_j` at y = 0 is exactly `H*(q) V_j` (eq. 2.34, `Model::qdot`):
//! `d/ds [q ⊗ (cos ½s|ω|, sin ½s|ω| ω/|ω|)]₀ = ½ q ⊗ (0, ω)`. So seeding `q + ε H*(q) V_j` gives
//! `∂ID/∂q V_j` in the same chart as the central differences use, and seeding `u + ε V_j` gives
//! `∂ID/∂u V_j`, both with `u̇ = u̇*` held fixed. The 2n seeds go eight at a time through one
//! pass of vector duals (`x + Σ ε_l ẋ_l`): 2n/8 passes of O(bodies) each, O(n²) in all, the real
//! part computed once per pass, and values none of a pass's seeds reach (the bodies before the
//! seeded joints, constants) carrying no derivative part at all.
//!
//! Why `num-dual`: its `DualSVec64<N>` is a `nalgebra::Scalar` (`Copy`, all arithmetic and
//! assign operators, `From<f64>`), so `Vector3` and `Matrix3` of it work with nalgebra's own
//! products and cross products, it stores an all-zero derivative as `None` (the sparsity above for
//! free), and its `DualNum<f64>` trait is also implemented for `f64`, which lets one generic body
//! serve both the derivative passes and the value check against the engine's RNEA. A hand-written
//! dual type would have needed the same operator impls and the nalgebra trait plumbing.
//!
//! Elements not covered: `ForceElement::Callback` (a Python function of (t, q, u) whose
//! derivative nothing here can see) and any element kind added after this module; [`unsupported`]
//! names the first such element so the caller can fall back to central differences.

use nalgebra::{Const, DMatrix, Matrix3, SVector, Vector3, U1};
use num_dual::{Derivative, DualNum, DualSVec64};

use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::math::{Mat3, Vec3};
use crate::model::{ForceElement, ForceFrame, JointKind, Model};
use crate::spatial::Pose;

/// A scalar the generic inverse dynamics runs on: `f64` or a dual number.
pub(super) trait Real: DualNum<f64> + Copy + nalgebra::Scalar {}
impl<T: DualNum<f64> + Copy + nalgebra::Scalar> Real for T {}

type V3<T> = Vector3<T>;
type M3<T> = Matrix3<T>;

#[inline]
fn cst<T: Real>(x: f64) -> T {
    T::from(x)
}

#[inline]
fn lift<T: Real>(v: &Vec3) -> V3<T> {
    v.map(T::from)
}

#[inline]
fn lift_m<T: Real>(m: &Mat3) -> M3<T> {
    m.map(T::from)
}

/// A twist or spatial acceleration `(ω, v)`, world components about the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Twist<T: Real> {
    w: V3<T>,
    v: V3<T>,
}

/// A wrench `(n, f)`, world components about the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Wrench<T: Real> {
    n: V3<T>,
    f: V3<T>,
}

/// A placement `(A, r)` of a frame in its parent frame.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Frame<T: Real> {
    a: M3<T>,
    r: V3<T>,
}

/// A rigid-body inertia about the world origin: mass, first moment `m c`, inertia about the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Inertia<T: Real> {
    m: T,
    h: V3<T>,
    i_o: M3<T>,
}

impl<T: Real> Twist<T> {
    fn zero() -> Self {
        Twist { w: V3::zeros(), v: V3::zeros() }
    }
    fn add(&self, o: &Self) -> Self {
        Twist { w: self.w + o.w, v: self.v + o.v }
    }
    fn scale(&self, s: T) -> Self {
        Twist { w: self.w * s, v: self.v * s }
    }
    /// `self ×m m` (derivative of a motion vector in a moving frame).
    fn cross_motion(&self, m: &Self) -> Self {
        Twist { w: self.w.cross(&m.w), v: self.w.cross(&m.v) + self.v.cross(&m.w) }
    }
    /// `self ×f f` (the gyroscopic term of the Newton–Euler equations).
    fn cross_force(&self, f: &Wrench<T>) -> Wrench<T> {
        Wrench { n: self.w.cross(&f.n) + self.v.cross(&f.f), f: self.w.cross(&f.f) }
    }
    /// Power pairing with a wrench.
    fn dot(&self, f: &Wrench<T>) -> T {
        self.w.dot(&f.n) + self.v.dot(&f.f)
    }
}

impl<T: Real> Wrench<T> {
    fn zero() -> Self {
        Wrench { n: V3::zeros(), f: V3::zeros() }
    }
    fn add(&self, o: &Self) -> Self {
        Wrench { n: self.n + o.n, f: self.f + o.f }
    }
    fn sub(&self, o: &Self) -> Self {
        Wrench { n: self.n - o.n, f: self.f - o.f }
    }
    /// The wrench of a force `f` acting at the world point `p`.
    fn at(p: &V3<T>, f: V3<T>) -> Self {
        Wrench { n: p.cross(&f), f }
    }
}

impl<T: Real> Frame<T> {
    fn identity() -> Self {
        Frame { a: M3::identity(), r: V3::zeros() }
    }
    fn lift(p: &Pose) -> Self {
        Frame { a: lift_m(&p.a), r: lift(&p.r) }
    }
    /// `self` = P→B composed with `o` = B→C gives P→C (eqs. 2.46, 2.51).
    fn compose(&self, o: &Self) -> Self {
        Frame { a: self.a * o.a, r: self.r + self.a * o.r }
    }
    /// A point given in B components, in P components.
    fn point(&self, p: &Vec3) -> V3<T> {
        self.r + self.a * lift(p)
    }
    /// A twist in the components of this frame about its origin, in world components about the
    /// world origin (this frame placed in the world).
    fn motion_to_world(&self, m: &Twist<T>) -> Twist<T> {
        let w = self.a * m.w;
        Twist { w, v: self.a * m.v + self.r.cross(&w) }
    }
}

impl<T: Real> Inertia<T> {
    /// From mass, centre of mass and inertia about it, all world components (Steiner shift).
    fn from_com(m: f64, c: &V3<T>, i_c: &M3<T>) -> Self {
        let (x, y, z) = (c.x, c.y, c.z);
        let (xx, yy, zz) = (x * x * m, y * y * m, z * z * m);
        let (xy, xz, yz) = (x * y * m, x * z * m, y * z * m);
        let shift = M3::new(yy + zz, -xy, -xz, -xy, xx + zz, -yz, -xz, -yz, xx + yy);
        Inertia { m: cst(m), h: c * cst::<T>(m), i_o: i_c + shift }
    }
    /// Momentum of the body moving with `v`.
    fn mul_motion(&self, v: &Twist<T>) -> Wrench<T> {
        Wrench { n: self.i_o * v.w + self.h.cross(&v.v), f: v.v * self.m - self.h.cross(&v.w) }
    }
}

/// Rotation by `angle` about the unit `axis` (Rodrigues, eq. 2.12 ff.), as `joint::axis_rotation`.
fn axis_rotation<T: Real>(axis: &Vec3, angle: T) -> M3<T> {
    let (s, c) = angle.sin_cos();
    let (x, y, z) = (axis.x, axis.y, axis.z);
    let k = cst::<T>(1.0) - c;
    M3::new(
        c + k * (x * x),
        k * (x * y) - s * z,
        k * (x * z) + s * y,
        k * (x * y) + s * z,
        c + k * (y * y),
        k * (y * z) - s * x,
        k * (x * z) - s * y,
        k * (y * z) + s * x,
        c + k * (z * z),
    )
}

/// Rotation matrix of the quaternion `q = [w, x, y, z]` after normalization, as
/// `joint::unit_quat_matrix` (the normalization has zero derivative along the chart's tangents,
/// but it is kept so that the value agrees off the unit sphere too).
fn unit_quat_matrix<T: Real>(q: &[T]) -> M3<T> {
    let n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    let s = if n2.re() > 0.0 { n2.sqrt().recip() } else { cst(1.0) };
    let (w, x, y, z) = (q[0] * s, q[1] * s, q[2] * s, q[3] * s);
    let one = cst::<T>(1.0);
    M3::new(
        one - (y * y + z * z) * 2.0,
        (x * y - w * z) * 2.0,
        (x * z + w * y) * 2.0,
        (x * y + w * z) * 2.0,
        one - (x * x + z * z) * 2.0,
        (y * z - w * x) * 2.0,
        (x * z - w * y) * 2.0,
        (y * z + w * x) * 2.0,
        one - (x * x + y * y) * 2.0,
    )
}

/// Placement of the child joint frame in the parent joint frame (`JointKind::placement`).
fn placement<T: Real>(kind: &JointKind, q: &[T]) -> Frame<T> {
    let z = V3::zeros();
    match kind {
        JointKind::Fixed => Frame::identity(),
        JointKind::Revolute { axis } => Frame { a: axis_rotation(axis, q[0]), r: z },
        JointKind::Prismatic { axis } => Frame { a: M3::identity(), r: lift::<T>(axis) * q[0] },
        JointKind::Cylindrical { axis } => Frame { a: axis_rotation(axis, q[0]), r: lift::<T>(axis) * q[1] },
        JointKind::Universal { axis1, axis2 } => {
            Frame { a: axis_rotation(axis1, q[0]) * axis_rotation(axis2, q[1]), r: z }
        }
        JointKind::Spherical => Frame { a: unit_quat_matrix(&q[0..4]), r: z },
        JointKind::Planar => Frame { a: axis_rotation(&Vec3::z(), q[2]), r: V3::new(q[0], q[1], cst(0.0)) },
        JointKind::Free => Frame { a: unit_quat_matrix(&q[3..7]), r: V3::new(q[0], q[1], q[2]) },
        JointKind::Path { curve, oriented } => {
            let p = curve.local(q[0]);
            Frame { a: if *oriented { p.frame } else { M3::identity() }, r: p.r }
        }
    }
}

fn unit<T: Real>(k: usize) -> V3<T> {
    let mut e = V3::zeros();
    e[k] = cst(1.0);
    e
}

/// Motion subspace columns, child joint frame components (`JointKind::subspace`).
fn subspace<T: Real>(kind: &JointKind, q: &[T], s: &mut [Twist<T>; 6]) {
    let z = V3::zeros();
    match kind {
        JointKind::Fixed => {}
        JointKind::Revolute { axis } => s[0] = Twist { w: lift(axis), v: z },
        JointKind::Prismatic { axis } => s[0] = Twist { w: z, v: lift(axis) },
        JointKind::Cylindrical { axis } => {
            s[0] = Twist { w: lift(axis), v: z };
            s[1] = Twist { w: z, v: lift(axis) };
        }
        JointKind::Universal { axis1, axis2 } => {
            s[0] = Twist { w: axis_rotation(axis2, q[1]).transpose() * lift(axis1), v: z };
            s[1] = Twist { w: lift(axis2), v: z };
        }
        JointKind::Spherical => {
            for (k, col) in s.iter_mut().take(3).enumerate() {
                *col = Twist { w: unit(k), v: z };
            }
        }
        JointKind::Planar => {
            let (sn, c) = q[2].sin_cos();
            s[0] = Twist { w: z, v: V3::new(c, -sn, cst(0.0)) };
            s[1] = Twist { w: z, v: V3::new(sn, c, cst(0.0)) };
            s[2] = Twist { w: unit(2), v: z };
        }
        JointKind::Free => {
            for k in 0..3 {
                s[k] = Twist { w: z, v: unit(k) };
                s[k + 3] = Twist { w: unit(k), v: z };
            }
        }
        JointKind::Path { curve, oriented: true } => {
            s[0] = Twist { w: curve.local(q[0]).omega, v: unit(0) };
        }
        JointKind::Path { curve, oriented: false } => {
            s[0] = Twist { w: z, v: curve.local(q[0]).frame.column(0).into_owned() };
        }
    }
}

/// The bias `c_J = Ṡ(q) u`, child joint frame components (`JointKind::bias`).
fn bias<T: Real>(kind: &JointKind, q: &[T], u: &[T]) -> Twist<T> {
    match kind {
        JointKind::Universal { axis1, axis2 } => {
            let s1 = axis_rotation(axis2, q[1]).transpose() * lift(axis1);
            Twist { w: -(lift::<T>(axis2) * u[1]).cross(&(s1 * u[0])), v: V3::zeros() }
        }
        JointKind::Planar => {
            let (sn, c) = q[2].sin_cos();
            let v = V3::new(c * u[0] + sn * u[1], -sn * u[0] + c * u[1], cst(0.0));
            Twist { w: V3::zeros(), v: -(unit::<T>(2) * u[2]).cross(&v) }
        }
        JointKind::Path { curve, oriented: false } => {
            Twist { w: V3::zeros(), v: curve.local(q[0]).tangent_rate * (u[0] * u[0]) }
        }
        JointKind::Path { curve, oriented: true } => {
            Twist { w: curve.local(q[0]).omega_rate * (u[0] * u[0]), v: V3::zeros() }
        }
        _ => Twist::zero(),
    }
}

/// Piecewise-linear interpolation as `forces::interp`: the segment is chosen by the value, the
/// interpolation carries the derivative (zero outside the table, where the force is constant).
fn interp<T: Real>(x: &[f64], y: &[f64], xi: T) -> T {
    let n = x.len();
    let r = xi.re();
    if r <= x[0] {
        return cst(y[0]);
    }
    if r >= x[n - 1] {
        return cst(y[n - 1]);
    }
    let k = x.partition_point(|v| *v <= r).clamp(1, n - 1);
    let s = (xi - x[k - 1]) / (x[k] - x[k - 1]);
    s * (y[k] - y[k - 1]) + y[k - 1]
}

/// Elastic force of a spring–damper at deflection `delta` (tension positive), as in `forces`.
fn spring_force<T: Real>(k: f64, k3: f64, table: &(Vec<f64>, Vec<f64>), delta: T) -> T {
    let mut f = delta * k + delta * delta * delta * k3;
    if !table.0.is_empty() {
        f += interp(&table.0, &table.1, delta);
    }
    f
}

/// The name of the first force element the exact derivatives do not cover, if any.
pub(super) fn unsupported(model: &Model) -> Option<&str> {
    // elastic bodies are not in the generic tree: differences
    if let Some(e) = model.elastic.first() {
        return Some(&model.bodies[e.body].name);
    }
    model.forces.iter().find(|fe| !covered(fe)).map(|fe| fe.name())
}

/// Whether [`Tree::inverse_dynamics`] has the element's law; a kind added to the model later is
/// not covered (and so falls back to differences) until it is written here too.
fn covered(fe: &ForceElement) -> bool {
    match fe {
        ForceElement::SpringDamper { .. }
        | ForceElement::SqueezeFilm { .. }
        | ForceElement::BodyForce { .. }
        | ForceElement::JointForce { .. }
        | ForceElement::JournalBearing { .. }
        | ForceElement::HydrodynamicBearing(_) => true,
        _ => false,
    }
}

/// Workspace of the generic inverse dynamics, one entry per body (index 0 = ground).
pub(super) struct Tree<T: Real> {
    x_abs: Vec<Frame<T>>,
    s: Vec<[Twist<T>; 6]>,
    v: Vec<Twist<T>>,
    c: Vec<Twist<T>>,
    a: Vec<Twist<T>>,
    inertia: Vec<Inertia<T>>,
    f_ext: Vec<Wrench<T>>,
    f: Vec<Wrench<T>>,
    tau: Vec<T>,
}

impl<T: Real> Tree<T> {
    /// Sized for `model`.
    pub(super) fn new(model: &Model) -> Self {
        let nb = model.nbodies();
        let zi = Inertia { m: cst(0.0), h: V3::zeros(), i_o: M3::zeros() };
        Tree {
            x_abs: vec![Frame::identity(); nb],
            s: vec![[Twist::zero(); 6]; nb],
            v: vec![Twist::zero(); nb],
            c: vec![Twist::zero(); nb],
            a: vec![Twist::zero(); nb],
            inertia: vec![zi; nb],
            f_ext: vec![Wrench::zero(); nb],
            f: vec![Wrench::zero(); nb],
            tau: vec![cst(0.0); model.nu],
        }
    }

    /// Kinematics of (q, u) and the body inertias at t (`kinematics::forward_pass`).
    fn kinematics(&mut self, model: &Model, t: f64, q: &[T], u: &[T]) {
        for (ji, j) in model.joints.iter().enumerate() {
            let i = ji + 1;
            let (qj, uj) = (&q[j.iq..j.iq + j.nq()], &u[j.iu..j.iu + j.nu()]);
            let x_pj = self.x_abs[j.parent].compose(&Frame::lift(&j.parent_frame));
            let x_cj = x_pj.compose(&placement(&j.kind, qj));
            self.x_abs[i] = x_cj.compose(&Frame::lift(&j.child_frame_inv));
            let mut s = [Twist::zero(); 6];
            subspace(&j.kind, qj, &mut s);
            let mut vj = Twist::zero();
            for k in 0..j.nu() {
                self.s[i][k] = x_cj.motion_to_world(&s[k]);
                vj = vj.add(&self.s[i][k].scale(uj[k]));
            }
            let vi = self.v[j.parent].add(&vj);
            self.v[i] = vi;
            let mut c = vi.cross_motion(&vj);
            if j.kind.has_bias() {
                c = c.add(&x_cj.motion_to_world(&bias(&j.kind, qj, uj)));
            }
            self.c[i] = c;
            // inertia in world components (variable mass scaled at the fixed t)
            let b = &model.bodies[i];
            let x = &self.x_abs[i];
            let com = x.point(&b.com);
            let (m, i_c) = if b.mass_rate == 0.0 {
                (b.mass, b.inertia)
            } else {
                let m = b.mass_at(t);
                (m, b.inertia * (m / b.mass))
            };
            let i_c_w = x.a * lift_m(&i_c) * x.a.transpose();
            self.inertia[i] = Inertia::from_com(m, &com, &i_c_w);
        }
    }

    fn point_velocity(&self, body: usize, p: &V3<T>) -> V3<T> {
        let v = &self.v[body];
        v.v + v.w.cross(p)
    }

    fn add_point_force(&mut self, body: usize, p_b: &Vec3, f: V3<T>) {
        if body == 0 {
            return;
        }
        let p = self.x_abs[body].point(p_b);
        self.f_ext[body] = self.f_ext[body].add(&Wrench::at(&p, f));
    }

    /// The force elements (`forces::evaluate`, without the power balance): `f_ext`, `tau`.
    fn forces(&mut self, model: &Model, t: f64, q: &[T], u: &[T], cb: &dyn Callbacks) -> Result<()> {
        self.f_ext.iter_mut().for_each(|f| *f = Wrench::zero());
        self.tau.iter_mut().for_each(|x| *x = cst(0.0));
        for j in &model.joints {
            if let Some(s) = &j.spring {
                for k in 0..j.nu() {
                    self.tau[j.iu + k] -= (q[j.iq + k] - s.q_free[k]) * s.k[k];
                }
            }
            for (k, d) in j.damper.iter().enumerate() {
                self.tau[j.iu + k] -= u[j.iu + k] * *d;
            }
        }
        if model.variable_mass {
            // thrust ṁ w_rel at the ejection point (section 2.1.1)
            for (i, b) in model.bodies.iter().enumerate().skip(1) {
                let mdot = b.mass_rate_at(t);
                if mdot != 0.0 {
                    let x = self.x_abs[i];
                    let f = x.a * lift::<T>(&(b.ejection_velocity * mdot));
                    self.f_ext[i] = self.f_ext[i].add(&Wrench::at(&x.point(&b.ejection_point), f));
                }
            }
        }
        for fe in &model.forces {
            match fe {
                ForceElement::SpringDamper { name, body1, point1, body2, point2, k, k3, d, l0, table, travel } => {
                    let p1 = self.x_abs[*body1].point(point1);
                    let p2 = self.x_abs[*body2].point(point2);
                    let dr = p2 - p1;
                    let l = dr.dot(&dr).sqrt();
                    if l.re() < 1e-12 {
                        if *l0 > 0.0 || !table.0.is_empty() {
                            return Err(Error::Solver(format!(
                                "spring-damper '{name}': its two points coincide at t = {t} s, the force direction is undefined"
                            )));
                        }
                        continue;
                    }
                    let e = dr / l;
                    let ldot = e.dot(&(self.point_velocity(*body2, &p2) - self.point_velocity(*body1, &p1)));
                    let delta = l - *l0;
                    // the progressive (elastomer) law divides the linear terms by 1 − (δ/s)², as in forces.rs
                    let g = if *travel > 0.0 {
                        let r = delta / *travel;
                        (cst::<T>(1.0) - r * r).recip()
                    } else {
                        cst(1.0)
                    };
                    let f = spring_force(0.0, *k3, table, delta) + delta * g * *k + ldot * g * *d;
                    let fv = e * f;
                    self.add_point_force(*body1, point1, fv);
                    self.add_point_force(*body2, point2, -fv);
                }
                ForceElement::BodyForce { body, point, force, torque, frame, function, .. } => {
                    // at fixed t the time function is a constant
                    let s = function.eval(t, cb)?;
                    let x = self.x_abs[*body];
                    let (f, n) = match frame {
                        ForceFrame::Inertial => (lift::<T>(&(force * s)), lift::<T>(&(torque * s))),
                        ForceFrame::Body => (x.a * lift::<T>(&(force * s)), x.a * lift::<T>(&(torque * s))),
                    };
                    let w = Wrench { n: n + x.point(point).cross(&f), f };
                    self.f_ext[*body] = self.f_ext[*body].add(&w);
                }
                ForceElement::SqueezeFilm { body1, point1, normal, body2, point2, coeff, gap, .. } => {
                    // eq. 2.211, as in forces.rs: F = coeff / h³ · ḣ along the body1 normal
                    let n = self.x_abs[*body1].a * lift::<T>(normal);
                    let p1 = self.x_abs[*body1].point(point1);
                    let p2 = self.x_abs[*body2].point(point2);
                    let h = n.dot(&(p2 - p1)) + *gap;
                    let hdot = n.dot(&(self.point_velocity(*body2, &p2) - self.point_velocity(*body1, &p2)));
                    let fv = n * (hdot * *coeff / (h * h * h));
                    if *body2 != 0 {
                        self.f_ext[*body2] = self.f_ext[*body2].add(&Wrench::at(&p2, -fv));
                    }
                    if *body1 != 0 {
                        self.f_ext[*body1] = self.f_ext[*body1].add(&Wrench::at(&p2, fv));
                    }
                }
                ForceElement::JournalBearing { joint, c, .. } => {
                    // eq. 2.212: a torque linear in the shaft speed
                    let iu = model.joints[*joint].iu;
                    self.tau[iu] -= u[iu] * *c;
                }
                ForceElement::HydrodynamicBearing(b) => {
                    // forces::bearing, as in forces.rs: the film's wrench at the journal centre
                    let (jb, sb) = (b.journal, b.shell);
                    let a_s = self.x_abs[sb].a * lift_m::<T>(&b.shell_frame.a);
                    let z_s: V3<T> = a_s.column(2).into_owned();
                    let p_j = self.x_abs[jb].point(&b.journal_frame.r);
                    let p_s = self.x_abs[sb].point(&b.shell_frame.r);
                    let e = a_s.transpose() * (p_j - p_s);
                    let e_dot = a_s.transpose() * (self.point_velocity(jb, &p_j) - self.point_velocity(sb, &p_j));
                    let omega_rel = z_s.dot(&(self.v[jb].w - self.v[sb].w));
                    let load = b
                        .law
                        .shell_load([e.x, e.y], [e_dot.x, e_dot.y], omega_rel)
                        .map_err(|eps| crate::forces::bearing::touch_error(&b.name, eps, t))?;
                    let f = a_s * V3::new(load.force[0], load.force[1], cst(0.0));
                    let n = z_s * load.torque;
                    let w = Wrench { n: n + p_j.cross(&f), f };
                    if jb != 0 {
                        self.f_ext[jb] = self.f_ext[jb].add(&w);
                    }
                    if sb != 0 {
                        self.f_ext[sb] = self.f_ext[sb].sub(&w);
                    }
                }
                ForceElement::JointForce { joint, value, function, .. } => {
                    let s = function.eval(t, cb)?;
                    let j = &model.joints[*joint];
                    for (k, v) in value.iter().enumerate() {
                        self.tau[j.iu + k] += cst::<T>(v * s);
                    }
                }
                other => {
                    return Err(Error::Settings(format!(
                        "linearize: exact derivatives do not cover force element '{}'",
                        other.name()
                    )))
                }
            }
        }
        Ok(())
    }

    /// `out = M(q) u̇ − h(q, u, t)`: kinematics, force elements, then the Newton–Euler equations
    /// per body and the inward pass (`dynamics::rnea`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn inverse_dynamics(
        &mut self,
        model: &Model,
        t: f64,
        q: &[T],
        u: &[T],
        udot: &[f64],
        cb: &dyn Callbacks,
        out: &mut [T],
    ) -> Result<()> {
        self.kinematics(model, t, q, u);
        self.forces(model, t, q, u, cb)?;
        // outward: accelerations without gravity; gravity enters as the d'Alembert term −I g
        let g = Twist { w: V3::zeros(), v: lift(&model.gravity) };
        for (ji, j) in model.joints.iter().enumerate() {
            let i = ji + 1;
            let mut a = self.a[j.parent].add(&self.c[i]);
            for k in 0..j.nu() {
                a = a.add(&self.s[i][k].scale(cst(udot[j.iu + k])));
            }
            self.a[i] = a;
            let ag = Twist { w: a.w - g.w, v: a.v - g.v };
            let iv = self.inertia[i].mul_motion(&self.v[i]);
            self.f[i] = self.inertia[i].mul_motion(&ag).add(&self.v[i].cross_force(&iv)).sub(&self.f_ext[i]);
        }
        for (ji, j) in model.joints.iter().enumerate().rev() {
            let i = ji + 1;
            for k in 0..j.nu() {
                out[j.iu + k] = self.s[i][k].dot(&self.f[i]) - self.tau[j.iu + k];
            }
            if j.parent != 0 {
                let fi = self.f[i];
                self.f[j.parent] = self.f[j.parent].add(&fi);
            }
        }
        Ok(())
    }
}

/// Directions carried by one dual pass.
const LANES: usize = 8;

/// A dual number with [`LANES`] derivative directions; a value whose directions are all zero
/// carries none (`None`), so the parts of the tree a pass's seeds do not reach cost no more than
/// plain f64 arithmetic.
type Lanes = DualSVec64<LANES>;

/// `∂ID/∂q V` and `∂ID/∂u V` (each nu × n) at (t, q, u) with `u̇ = udot` held, exact. The 2n
/// seeds `q + ε H*(q) V_j` and `u + ε V_j` go [`LANES`] at a time through one vector-dual pass,
/// the q and u seeds of a column side by side (they reach the same part of the tree).
pub(super) fn inverse_dynamics_derivatives(
    model: &Model,
    t: f64,
    q: &[f64],
    u: &[f64],
    udot: &[f64],
    v: &DMatrix<f64>,
    cb: &dyn Callbacks,
) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let (nq, nu, n) = (model.nq, model.nu, v.ncols());
    // the chart's tangents H*(q) V_j, one column per direction
    let mut tangents = DMatrix::zeros(nq, n);
    let (mut dir, mut tangent) = (vec![0.0; nu], vec![0.0; nq]);
    for j in 0..n {
        for i in 0..nu {
            dir[i] = v[(i, j)];
        }
        model.qdot(q, &dir, &mut tangent);
        for i in 0..nq {
            tangents[(i, j)] = tangent[i];
        }
    }
    let seeds: Vec<(usize, bool)> = (0..n).flat_map(|j| [(j, false), (j, true)]).collect();
    let mut tree = Tree::<Lanes>::new(model);
    let lift_seeded = |x: f64, e: SVector<f64, LANES>| {
        Lanes::new(x, Derivative::new(if e.iter().all(|v| *v == 0.0) { None } else { Some(e) }))
    };
    let (mut qd, mut ud) = (Vec::with_capacity(nq), Vec::with_capacity(nu));
    let mut out = vec![Lanes::from_re(0.0); nu];
    let (mut dq, mut du) = (DMatrix::zeros(nu, n), DMatrix::zeros(nu, n));
    for chunk in seeds.chunks(LANES) {
        let mut eq = vec![SVector::<f64, LANES>::zeros(); nq];
        let mut eu = vec![SVector::<f64, LANES>::zeros(); nu];
        for (l, &(j, velocity)) in chunk.iter().enumerate() {
            if velocity {
                for i in 0..nu {
                    eu[i][l] = v[(i, j)];
                }
            } else {
                for i in 0..nq {
                    eq[i][l] = tangents[(i, j)];
                }
            }
        }
        qd.clear();
        qd.extend(q.iter().zip(eq).map(|(x, e)| lift_seeded(*x, e)));
        ud.clear();
        ud.extend(u.iter().zip(eu).map(|(x, e)| lift_seeded(*x, e)));
        tree.inverse_dynamics(model, t, &qd, &ud, udot, cb, &mut out)?;
        for i in 0..nu {
            let d = out[i].eps.unwrap_generic(Const::<LANES>, U1);
            for (l, &(j, velocity)) in chunk.iter().enumerate() {
                if velocity {
                    du[(i, j)] = d[l];
                } else {
                    dq[(i, j)] = d[l];
                }
            }
        }
    }
    Ok((dq, du))
}
