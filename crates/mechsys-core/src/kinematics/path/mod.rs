//! Path coordinates (section 2.2.6): a body's point moving along a space curve r(s), parameterized
//! by its arc length s, with a frame moving along it.
//!
//! With the path velocity ṡ, `v = r′ ṡ` (eq. 2.72), `t = r′` (eq. 2.73) and
//! `a = r″ ṡ² + r′ s̈` (eq. 2.74): the centripetal part `r″ = t′ = κ n` and the tangential part.
//! The Frenet trihedral [t n b] turns by the Darboux vector `Ω = τ t + κ b` per unit arc length:
//! `t′ = κ n`, `n′ = −κ t + τ b`, `b′ = −τ n` (eq. 2.75; the text's last one has a misprint).
//!
//! # The curves
//!
//! - [`Helix`] about the z-axis of the joint frame (a circle when its lead is zero), closed forms.
//! - [`Clothoid`] in the x-y plane: κ(s) = κ₀ + s/A², from the origin along x; its position by
//!   Fresnel integrals (`math::fresnel`) or Gauss–Legendre, to about 1e-14 relative.
//! - [`Spline`]: the C² cubic through points (open: natural ends; or closed), or the quintic
//!   Hermite through samples of a function with its derivatives, re-parameterized by arc length.
//!
//! # The frame
//!
//! A joint whose child frame turns with the path needs a frame [t n b] defined and smooth all
//! along it. The Frenet trihedral is not: where κ = 0 (the clothoid's start, the inflections and
//! straight stretches of a spline, the ends of a natural spline) n is undefined, and across an
//! inflection of a space curve it flips. So:
//!
//! - **helix**: the Frenet trihedral (n towards the axis; κ, τ > 0 constant; Ω = (τ, 0, κ)).
//! - **clothoid**: `b = z`, `n = z × t` (the in-plane left normal). This is the Frenet trihedral
//!   of a plane curve with signed curvature (`t′ = κ n`, κ < 0 where the curve turns right),
//!   continuous through κ = 0; Ω = (0, 0, κ).
//! - **spline** (and sampled functions): b is the part of a reference direction `up` across the
//!   tangent, normalized, and `n = b × t`. For a plane curve `up` defaults to the plane's normal,
//!   which gives exactly the signed Frenet trihedral of the clothoid. For a space curve `up`
//!   defaults to the direction the tangent runs along least (the eigenvector of the smallest
//!   eigenvalue of `∫ t tᵀ ds`; for a helix its axis, and then the frame is the helix's Frenet
//!   trihedral), and the frame is an "up-vector" frame, not Frenet's: it turns by
//!   `Ω = (Ω_t, Ω_n, Ω_b)` in its own axes with `t′ = Ω_b n − Ω_n b`, `n′ = −Ω_b t + Ω_t b`,
//!   `b′ = Ω_n t − Ω_t n` (eq. 2.75 with Ω = (τ, 0, κ) is the special case). It depends on t and
//!   t′ = r″ only, so it is continuous with a continuous angular velocity wherever the curve is
//!   C² (the Frenet frame of a cubic spline is not: its torsion jumps at the knots, where r‴
//!   does) and needs only that the tangent never runs along `up` (an oriented joint refuses a
//!   path coming within 5° of it).
//!
//! Curvature and torsion as reported: for a plane curve (clothoid, circle, a spline whose points
//! lie in a plane) the signed curvature about the plane normal (the one along `up`) and τ = 0;
//! for a space curve Frenet's κ = |t′| ≥ 0 and `τ = (t × t′)·t″/κ²` (0 where κ < 1e-14 1/m).
//!
//! # Scalars
//!
//! [`PathCurve::point`] evaluates in `f64` for the time step; [`PathCurve::local`] for any
//! `num_dual::DualNum` scalar (the exact linearization, `linear::ad`): the helix by its generic
//! closed forms, the other curves as Taylor series in δ = s − re(s) at the real part (`jet`),
//! evaluated at δ — exact values and first and second derivatives of position, frame, tangent
//! rate, Ω and Ω′ (so `Dual`, `Dual2` and `HyperDual` numbers all come out right).

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};
use num_dual::DualNum;

use crate::math::{Mat3, Vec3};

mod clothoid;
mod helix;
pub mod jet;
mod spline;

pub use clothoid::Clothoid;
pub use helix::Helix;
pub use spline::Spline;

use jet::JVec;

/// The curve of a path joint, in the parent joint frame.
#[derive(Debug, Clone, PartialEq)]
pub enum PathCurve {
    /// A circular helix about z (or a circle).
    Helix(Helix),
    /// An Euler spiral in the x-y plane.
    Clothoid(Clothoid),
    /// A spline re-parameterized by arc length (shared: a model's copies point to one table).
    Spline(Arc<Spline>),
}

/// Everything about the path at one s (real), parent joint frame components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Position r(s) (m).
    pub r: Vec3,
    /// The frame [t n b] as columns (see the module docs for n and b per curve).
    pub frame: Mat3,
    /// dt/ds = κ n (Frenet's; 1/m).
    pub tangent_rate: Vec3,
    /// The frame's Darboux vector Ω, in its own axes [t n b] (1/m): d[t n b]/ds = [t n b] Ω̃.
    pub omega: Vec3,
    /// dΩ/ds (1/m²).
    pub omega_rate: Vec3,
    /// Curvature (1/m; signed for a plane curve, see the module docs).
    pub curvature: f64,
    /// Torsion (1/m).
    pub torsion: f64,
}

/// As [`PathPoint`] for any scalar (no curvature and torsion: the joint does not need them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathLocal<T: nalgebra::Scalar> {
    /// Position r(s).
    pub r: Vector3<T>,
    /// The frame [t n b].
    pub frame: Matrix3<T>,
    /// dt/ds.
    pub tangent_rate: Vector3<T>,
    /// The Darboux vector in the frame's axes.
    pub omega: Vector3<T>,
    /// dΩ/ds.
    pub omega_rate: Vector3<T>,
}

impl PathCurve {
    /// The curve's name in model files: helix, clothoid, spline, hermite.
    pub fn kind_name(&self) -> &'static str {
        match self {
            PathCurve::Helix(_) => "helix",
            PathCurve::Clothoid(_) => "clothoid",
            PathCurve::Spline(sp) => sp.kind_name(),
        }
    }
    /// Whether Ω is constant along the curve (then an oriented joint's subspace is constant).
    #[inline]
    pub fn constant_darboux(&self) -> bool {
        matches!(self, PathCurve::Helix(_))
    }
    /// The direction the frame's b leans towards (the helix: its axis).
    pub fn up(&self) -> Vec3 {
        match self {
            PathCurve::Helix(_) | PathCurve::Clothoid(_) => Vec3::z(),
            PathCurve::Spline(sp) => sp.up,
        }
    }
    /// The normal of the plane holding the curve, if it is a plane curve.
    pub fn plane(&self) -> Option<Vec3> {
        match self {
            PathCurve::Helix(h) => (h.lead == 0.0).then(Vec3::z),
            PathCurve::Clothoid(_) => Some(Vec3::z()),
            PathCurve::Spline(sp) => sp.plane,
        }
    }

    /// Position, frame, Ω and their rates, curvature and torsion at arc length s.
    pub fn point(&self, s: f64) -> PathPoint {
        match self {
            PathCurve::Helix(h) => h.point(s),
            PathCurve::Clothoid(c) => point_from_series(&c.r_jet::<4>(s), &Vec3::z(), Some(Vec3::z())),
            PathCurve::Spline(sp) => point_from_series(&sp.r_jet::<4>(s), &sp.up, sp.plane),
        }
    }

    /// Position, frame, tangent rate, Ω and Ω′ at s for any dual-number scalar (exact through
    /// second derivatives).
    pub fn local<T: DualNum<f64> + Copy + nalgebra::Scalar>(&self, s: T) -> PathLocal<T> {
        let s0 = s.re();
        let d = s - s0;
        match self {
            PathCurve::Helix(h) => h.local(s),
            PathCurve::Clothoid(c) => local_from_series(&c.r_jet::<6>(s0), &Vec3::z(), d),
            PathCurve::Spline(sp) => local_from_series(&sp.r_jet::<6>(s0), &sp.up, d),
        }
    }
}

/// The frame [t n b] as series from the tangent's: b the unit part of `up` across t, n = b × t.
fn frame_series<const N: usize>(t: &JVec<N>, up: &Vec3) -> [JVec<N>; 3] {
    let mut across = JVec::constant(up).sub(&t.scale(&t.dot_const(up)));
    if across.value().norm() < 1e-9 {
        // t along up: only reachable for joints that do not turn with the path (whose frame is
        // reported, not used); any direction across t will do
        let tv = t.value();
        let k = tv.iamin();
        let mut e = Vec3::zeros();
        e[k] = 1.0;
        across = JVec::constant(&e).sub(&t.scale(&t.dot_const(&e)));
    }
    let b = across.scale(&across.dot(&across).sqrt().recip());
    let n = b.cross(t);
    [*t, n, b]
}

/// Ω in the frame's axes from the frame's series: Ω_t = n′·b, Ω_n = b′·t, Ω_b = t′·n.
fn darboux_series<const N: usize>(f: &[JVec<N>; 3]) -> JVec<N> {
    JVec([f[1].diff().dot(&f[2]), f[2].diff().dot(&f[0]), f[0].diff().dot(&f[1])])
}

fn point_from_series(r: &JVec<4>, up: &Vec3, plane: Option<Vec3>) -> PathPoint {
    let t = r.diff();
    let f = frame_series(&t, up);
    let w = darboux_series(&f);
    let (t0, t1, t2) = (t.value(), t.derivative(1), t.derivative(2));
    let (curvature, torsion) = match plane {
        Some(nrm) => (t0.cross(&t1).dot(&nrm), 0.0),
        None => {
            let k = t1.norm();
            (k, if k > 1e-14 { t0.cross(&t1).dot(&t2) / (k * k) } else { 0.0 })
        }
    };
    PathPoint {
        r: r.value(),
        frame: Mat3::from_columns(&[f[0].value(), f[1].value(), f[2].value()]),
        tangent_rate: t1,
        omega: w.value(),
        omega_rate: w.derivative(1),
        curvature,
        torsion,
    }
}

fn local_from_series<T: DualNum<f64> + Copy + nalgebra::Scalar>(r: &JVec<6>, up: &Vec3, d: T) -> PathLocal<T> {
    let t = r.diff();
    let f = frame_series(&t, up);
    let w = darboux_series(&f);
    PathLocal {
        r: r.eval(d),
        frame: Matrix3::from_columns(&[f[0].eval(d), f[1].eval(d), f[2].eval(d)]),
        tangent_rate: t.diff().eval(d),
        omega: w.eval(d),
        omega_rate: w.diff().eval(d),
    }
}

#[cfg(test)]
mod tests;
