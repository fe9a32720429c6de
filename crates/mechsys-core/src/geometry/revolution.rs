//! Surfaces of revolution (section 2.2.7.2 for a surface with a symmetry): a planar profile
//! [`Curve`] in the meridian half-plane, turned about the revolution axis.
//!
//! In the revolution frame (axis `e_z`, placed in the body by a centre and a rotation) the
//! profile point `q(s) = (x(s), y(s))` gives the radius `x` from the axis and the height `y`
//! along it; the surface is `X(s, φ) = x(s) e_ρ(φ) + y(s) e_z`. A point `p` of the frame lies in
//! the meridian half-plane through `e_ρ = (p_x, p_y, 0) / ρ`, at `w = (ρ, p_z)`; by symmetry its
//! foot point on the surface lies in that half-plane too, so every search is the profile's
//! planar one (the point's foot on the curve, a half-space's support point with the 2-D
//! direction `μ`) and the azimuth needs no iteration.
//!
//! The solid is the profile's solid turned about the axis (inside a closed profile; the side
//! chosen for an open one, whose ends continue straight). A profile must stay on one side of the
//! axis (`x ≥ 0`) or be its own mirror image across it (a closed profile centred on the axis: an
//! egg, a sphere); either way the half `x ≥ 0` is the one that counts.
//!
//! Principal curvatures (eqs. 2.117–2.119 for `X(s, φ)`): along the meridian the profile's
//! curvature `κ`, along the parallel `ν_x / x` (`ν` the profile's outward normal: `sin φ / ρ`
//! of the text's meridian angle), the limit `κ` on the axis.

use crate::ensure;
use crate::error::Result;
use crate::geometry::curve::{Curve, Jet2, Vec2, CONVERGED, NEWTON_ITERATIONS};
use crate::math::{Mat3, Vec3};

/// A surface of revolution in a body frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Revolution {
    /// Centre: the origin of the profile's plane, on the axis (body frame).
    pub center: Vec3,
    /// Rotation revolution frame → body frame; its third column is the axis.
    pub rotation: Mat3,
    /// The profile: `x` the radius, `y` the height along the axis.
    pub profile: Curve,
}

impl Revolution {
    /// Checks the placement and that the profile does not cross the axis (unless it is its own
    /// mirror image across it); `what` names the contact and contour in errors.
    pub fn new(center: Vec3, rotation: Mat3, profile: Curve, what: &str) -> Result<Self> {
        ensure!(center.iter().all(|v| v.is_finite()), Model, "{what}: revolution center must be finite");
        ensure!(rotation.iter().all(|v| v.is_finite()), Model, "{what}: revolution rotation must be finite");
        let e = (rotation.transpose() * rotation - Mat3::identity()).norm();
        ensure!(
            e < 1e-6 && rotation.determinant() > 0.0,
            Model,
            "{what}: revolution rotation must be orthonormal with determinant +1 (|AᵀA - E| = {e:.2e})"
        );
        let (c, r) = profile.bound();
        let scale = c.norm() + r;
        let tol = 1e-9 * scale;
        let samples = profile.samples();
        if let Some(bad) = samples.iter().find(|p| p.r.x < -tol) {
            // allowed only for a mirror-symmetric profile: every sample's mirror lies on it
            let symmetric = samples.iter().all(|p| {
                let m = Vec2::new(-p.r.x, p.r.y);
                let s = profile.closest_parameter(&m);
                (profile.eval(s)[0] - m).norm() <= 1e-6 * scale
            });
            ensure!(
                symmetric,
                Model,
                "{what}: revolution profile crosses the axis (x = {:.4} < 0 at ({:.4}, {:.4})); a profile must keep x ≥ 0 \
                 or be symmetric about the axis",
                bad.r.x,
                bad.r.x,
                bad.r.y
            );
        }
        Ok(Revolution { center, rotation: orthonormalized(&rotation), profile })
    }

    /// Revolution-frame coordinates of a body-frame point.
    #[inline]
    pub fn local(&self, p: &Vec3) -> Vec3 {
        self.rotation.transpose() * (p - self.center)
    }

    /// The meridian of a revolution-frame point `y`: `w = (ρ, y_z)` and the unit radial direction
    /// `e_ρ` (the frame's x axis on the axis itself, where every meridian is one).
    #[inline]
    pub fn meridian(y: &Vec3) -> (Vec2, Vec3) {
        let rho = y.x.hypot(y.y);
        let e = if rho > 1e-300 { Vec3::new(y.x / rho, y.y / rho, 0.0) } else { Vec3::x() };
        (Vec2::new(rho, y.z), e)
    }

    /// The foot point of `w` (meridian plane) on the base profile: the nearest sample, skipping
    /// chunks whose bounding circle is farther than the best sample so far, refined by Newton.
    pub fn foot(&self, w: &Vec2) -> (f64, Jet2) {
        let c = &self.profile;
        let samples = c.samples();
        let (mut best, mut sb) = (f64::INFINITY, c.range().0);
        for ch in c.chunks() {
            let lb = (w - ch.center).norm() - ch.radius;
            if lb > 0.0 && lb * lb > best {
                continue;
            }
            for smp in &samples[ch.first..ch.first + ch.count] {
                let d = (w - smp.r).norm_squared();
                if d < best {
                    (best, sb) = (d, smp.s);
                }
            }
        }
        c.foot(w, sb).unwrap_or_else(|| (sb, c.eval(sb)))
    }

    /// The point of the base profile deepest along the 2-D direction `-μ` (minimum of `μ·q`): the
    /// lowest sample, refined by Newton on `μ·q'(s) = 0` with `μ·q'' > 0`.
    pub fn support(&self, mu: &Vec2) -> (f64, Jet2) {
        let c = &self.profile;
        let (mut best, mut s) = (f64::INFINITY, c.range().0);
        for smp in c.samples() {
            let v = mu.dot(&smp.r);
            if v < best {
                (best, s) = (v, smp.s);
            }
        }
        let cap = 2.0 * c.step();
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for _ in 0..NEWTON_ITERATIONS {
            let j = c.eval(s);
            let (f, fs) = (mu.dot(&j[1]), mu.dot(&j[2]));
            // f increases through the minimum: keep its sign change
            if f < 0.0 {
                lo = lo.max(s);
            } else if f > 0.0 {
                hi = hi.min(s);
            }
            let ds = if fs > 0.0 { (-f / fs).clamp(-cap, cap) } else { -f.signum() * cap };
            let mut next = s + ds;
            if lo.is_finite() && hi.is_finite() && !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            let done = (next - s).abs() <= CONVERGED * c.step();
            s = next;
            if done {
                break;
            }
        }
        (s, c.eval(s))
    }

    /// Principal curvatures `[κ_meridian, κ_parallel]` (convex > 0) at the profile parameter `s`.
    pub fn curvatures(&self, s: f64) -> [f64; 2] {
        let f = self.profile.frame(s);
        let x = f.point.x;
        let par = if x.abs() > 1e-9 * (1.0 + f.point.norm()) { f.normal.x / x } else { f.curvature };
        [f.curvature, par]
    }

    /// A ball about the centre holding the surface (`None` for an open profile, which continues
    /// without bound).
    pub fn bound(&self) -> Option<f64> {
        let (c, r) = self.profile.bound();
        self.profile.is_closed().then_some(c.norm() + r)
    }
}

/// Gram–Schmidt on the columns, the third their cross product (det = +1).
fn orthonormalized(r: &Mat3) -> Mat3 {
    let x = r.column(0).normalize();
    let y = (r.column(1) - x * x.dot(&r.column(1))).normalize();
    Mat3::from_columns(&[x, y, x.cross(&y)])
}
