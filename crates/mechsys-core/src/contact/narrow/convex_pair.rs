//! Two ellipsoids (section 2.2.7.2): the common normal of two smooth strictly convex solids,
//! found on the unit sphere of normal directions instead of on the four surface parameters.
//!
//! An ellipsoid with centre `c` and world shape matrix `S = A R diag(a², b², c²) Rᵀ Aᵀ` has the
//! support function `h(ν) = c·ν + √(νᵀ S ν)`; its gradient `∇h(ν) = c + S ν / √(νᵀ S ν)` is the
//! surface point whose outward normal is `ν`, and its Hessian
//! `K(ν) = S / k - (S ν)(S ν)ᵀ / k³` (`k = √(νᵀ S ν)`) is the inverse of the shape operator in the
//! tangent plane (the principal radii of curvature), with `K ν = 0`.
//!
//! For a normal `n` (from body 2 towards body 1) put `P1 = ∇h1(-n)`, `P2 = ∇h2(n)`: each point's
//! outward normal is along the line of contact, so the conditions 2.120 reduce to
//! `(I - n nᵀ)(P1 - P2) = 0` — two equations in the two degrees of freedom of `n` — and
//! `g_N = n·(P1 - P2)` (eq. 2.121). They are the stationarity conditions of
//! `f(n) = n·(c1 - c2) - k1 - k2` on the sphere, and the maximum of `f` is the signed distance:
//! the distance when the solids are apart (the separating-axis theorem), minus the minimum
//! translation that separates them when they overlap. Maximizing `f` therefore never returns a
//! non-minimum of the distance, and penetration needs no separate case.
//!
//! **Search.** Newton from the centre line; when that ends at `f > 0` it is the global maximum
//! (`f` extends to a concave, positively homogeneous function on ℝ³, so a local maximum with
//! `f > 0` is the maximum over the unit ball). Otherwise `f` at a fixed set of directions spread
//! over the sphere (cheap: two quadratic forms) gives a second start, and the larger root is
//! kept. Newton on the sphere uses the Riemannian Hessian `-(K1 + K2) - g I` restricted to the
//! tangent plane, safeguarded by an ascent test (a gradient step where that Hessian is not
//! negative definite).
//!
//! **Rates** (the differentiated conditions, the spatial form of eq. 2.109). A rotating body turns
//! its support point: `Ṗ1 = v1(P1) - K1 (ṅ - ω1 × n)`, `Ṗ2 = v2(P2) + K2 (ṅ - ω2 × n)`.
//! Differentiating `P1 - P2 = g_N n` and projecting on the tangent plane gives
//! `(K1 + K2 + g_N I) ṅ = Δv + K1 (ω1 × n) + K2 (ω2 × n)` (tangential part), a 2 × 2 system.

use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

use super::{perpendicular, vel, Raw};

/// Directions sampled for the start (a Fibonacci lattice; the spacing is ≈ 0.25 rad).
const SAMPLES: usize = 200;
/// Newton iterations at most.
const ITERATIONS: usize = 60;

/// An ellipsoid's world centre and shape matrix `S`.
struct Quadric {
    c: Vec3,
    s: Mat3,
}

impl Quadric {
    fn new(x: &Pose, center: &Vec3, shape: &Mat3) -> Self {
        Quadric { c: x.point_to_parent(center), s: x.a * shape * x.a.transpose() }
    }
    /// `k = √(νᵀ S ν)` and `S ν`.
    #[inline]
    fn k(&self, nu: &Vec3) -> (f64, Vec3) {
        let sn = self.s * nu;
        (nu.dot(&sn).sqrt(), sn)
    }
    /// `K(ν)` from `k` and `S ν`.
    #[inline]
    fn hessian(&self, k: f64, sn: &Vec3) -> Mat3 {
        self.s / k - sn * sn.transpose() / (k * k * k)
    }
}

/// `f(n) = n·(c1 - c2) - k1(n) - k2(n)`.
#[inline]
fn support_gap(e1: &Quadric, e2: &Quadric, n: &Vec3) -> f64 {
    n.dot(&(e1.c - e2.c)) - e1.k(n).0 - e2.k(n).0
}

/// The unit direction `i` of a Fibonacci lattice of `SAMPLES` points.
#[inline]
fn lattice(i: usize) -> Vec3 {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = 1.0 - (2.0 * i as f64 + 1.0) / SAMPLES as f64;
    let r = (1.0 - z * z).sqrt();
    let (s, c) = (golden * i as f64).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// The normal maximizing `f`. Newton from the centre line first: `F(v) = v·(c1 - c2) - h1(-v) -
/// h2(v)` is concave and positively homogeneous on ℝ³, so a local maximum on the sphere with
/// `f > 0` is one on the unit ball too, hence the global one (the solids are apart and this is
/// their distance). Otherwise (overlap) the best lattice direction is refined as well and the
/// larger root kept.
fn common_normal(e1: &Quadric, e2: &Quadric) -> Vec3 {
    let d = e1.c - e2.c;
    let start = if d.norm() > 0.0 { d.normalize() } else { Vec3::z() };
    let (n, f) = refine(e1, e2, start);
    if f > 0.0 {
        return n;
    }
    let (mut best, mut fb) = (start, support_gap(e1, e2, &start));
    for i in 0..SAMPLES {
        let u = lattice(i);
        let fu = support_gap(e1, e2, &u);
        if fu > fb {
            (best, fb) = (u, fu);
        }
    }
    let (m, fm) = refine(e1, e2, best);
    if fm > f {
        m
    } else {
        n
    }
}

/// Newton on the sphere from `n` (ascent-safeguarded); the root and `f` there.
fn refine(e1: &Quadric, e2: &Quadric, mut n: Vec3) -> (Vec3, f64) {
    let d = e1.c - e2.c;
    let mut f = support_gap(e1, e2, &n);
    let scale = e1.s.trace().sqrt() + e2.s.trace().sqrt() + d.norm();
    for _ in 0..ITERATIONS {
        let (k1, s1) = e1.k(&n);
        let (k2, s2) = e2.k(&n);
        let dp = d - s1 / k1 - s2 / k2;
        let t1 = perpendicular(&n);
        let t2 = n.cross(&t1);
        let b = nalgebra::Vector2::new(t1.dot(&dp), t2.dot(&dp));
        if b.norm() <= 1e-15 * scale {
            break;
        }
        // Riemannian Hessian of f on the sphere, in the tangent basis
        let kk = e1.hessian(k1, &s1) + e2.hessian(k2, &s2);
        let g = n.dot(&dp);
        let a = nalgebra::Matrix2::new(
            -t1.dot(&(kk * t1)) - g,
            -t1.dot(&(kk * t2)),
            -t2.dot(&(kk * t1)),
            -t2.dot(&(kk * t2)) - g,
        );
        let negdef = a[(0, 0)] < 0.0 && a.determinant() > 0.0;
        let mut step = match (negdef, a.try_inverse()) {
            (true, Some(ai)) => -(ai * b),
            // ascent along the gradient, scaled by the curvature radii
            _ => b / (kk.trace() + g.abs() + 1e-300),
        };
        // a step longer than 0.5 rad leaves the region where the quadratic model holds
        let len = step.norm();
        if len > 0.5 {
            step *= 0.5 / len;
        }
        let mut accepted = false;
        for _ in 0..30 {
            let m = (n + t1 * step.x + t2 * step.y).normalize();
            let fm = support_gap(e1, e2, &m);
            if fm >= f - 1e-15 * scale {
                (n, f) = (m, fm);
                accepted = true;
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    (n, f)
}

/// Ellipsoid (body 1, centre and shape matrix in its body frame) against ellipsoid (body 2).
pub(crate) fn ellipsoid_ellipsoid(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    c1: &Vec3,
    shape1: &Mat3,
    c2: &Vec3,
    shape2: &Mat3,
) -> Raw {
    let (e1, e2) = (Quadric::new(x1, c1, shape1), Quadric::new(x2, c2, shape2));
    let n = common_normal(&e1, &e2);
    let (k1, s1) = e1.k(&n);
    let (k2, s2) = e2.k(&n);
    // support points: P1 = ∇h1(-n), P2 = ∇h2(n)
    let p1 = e1.c - s1 / k1;
    let p2 = e2.c + s2 / k2;
    let g = n.dot(&(p1 - p2));
    // P1 - P2 = g n holds to the iteration's tolerance; P2 is the exact image of P1
    let mut out = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        let (h1, h2) = (e1.hessian(k1, &s1), e2.hessian(k2, &s2));
        let (w1n, w2n) = (t1.w.cross(&n), t2.w.cross(&n));
        let dv = vel(t1, &p1) - vel(t2, &p2);
        let rhs = dv + h1 * w1n + h2 * w2n;
        let a = perpendicular(&n);
        let b = n.cross(&a);
        let kk = h1 + h2;
        let m = nalgebra::Matrix2::new(a.dot(&(kk * a)) + g, a.dot(&(kk * b)), b.dot(&(kk * a)), b.dot(&(kk * b)) + g);
        let r = nalgebra::Vector2::new(a.dot(&rhs), b.dot(&rhs));
        let sol = m.lu().solve(&r).unwrap_or_else(nalgebra::Vector2::zeros);
        let nd = a * sol.x + b * sol.y;
        let p1d = vel(t1, &p1) - h1 * (nd - w1n);
        let p2d_true = vel(t2, &p2) + h2 * (nd - w2n);
        let gd = n.dot(&(p1d - p2d_true));
        out.nd = nd;
        out.p1d = p1d;
        // the rate of P2 = P1 - g n (the same as Ṗ2 on the exact root)
        out.p2d = p1d - n * gd - nd * g;
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::contact::narrow::{evaluate, ContactPair, ContactPoint};
    use crate::contact::test_util::{rot, Rng};
    use crate::contact::Contour;
    use crate::math::{Mat3, Vec3};
    use crate::spatial::Pose;

    fn gap(c1: &Contour, x1: &Pose, c2: &Contour, x2: &Pose) -> ContactPoint {
        let mut out = [ContactPoint::default()];
        evaluate(&ContactPair::new("e", c1.clone(), c2.clone()).unwrap(), x1, x2, &mut out).unwrap();
        out[0]
    }

    fn ellipsoid(semi: Vec3) -> Contour {
        Contour::Ellipsoid { center: Vec3::zeros(), rotation: Mat3::identity(), semi_axes: semi }
    }

    /// Round ellipsoids are spheres: `g = |c1 - c2| - r1 - r2`, apart and overlapping.
    #[test]
    fn round_ellipsoids_give_the_sphere_gap() {
        let mut rng = Rng::new(9);
        for _ in 0..50 {
            let (r1, r2) = (rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5));
            let x1 = Pose::new(rng.rotation(), rng.vec3(0.5));
            let x2 = Pose::new(rng.rotation(), rng.vec3(0.5));
            let c = gap(&ellipsoid(Vec3::repeat(r1)), &x1, &ellipsoid(Vec3::repeat(r2)), &x2);
            let d = x1.r - x2.r;
            assert!((c.g_n - (d.norm() - r1 - r2)).abs() < 1e-12, "{} vs {}", c.g_n, d.norm() - r1 - r2);
            assert!((c.n - d.normalize()).norm() < 1e-9);
        }
    }

    /// Flat ellipsoids side by side along their common short axis: `g = d - a1 - a2` along it,
    /// also when they overlap a little (the minimum translation is along the short axis).
    #[test]
    fn aligned_ellipsoids_along_a_common_axis() {
        let (e1, e2) = (ellipsoid(Vec3::new(0.1, 0.4, 0.3)), ellipsoid(Vec3::new(0.15, 0.3, 0.5)));
        let turn = rot(&Vec3::new(0.3, -0.5, 1.0), 0.9);
        for d in [0.6, 0.3, 0.26, 0.24, 0.2] {
            let x1 = Pose::new(turn, turn * Vec3::new(d, 0.0, 0.0));
            let c = gap(&e1, &x1, &e2, &Pose::new(turn, Vec3::zeros()));
            assert!((c.g_n - (d - 0.25)).abs() < 1e-12, "d {d}: {}", c.g_n);
            assert!((c.n - turn * Vec3::x()).norm() < 1e-9);
            assert!((c.p1 - turn * Vec3::new(d - 0.1, 0.0, 0.0)).norm() < 1e-9);
        }
    }

    /// Separated ellipsoids in random poses: the gap equals the minimum of `|X1 - X2|` over both
    /// surfaces' angles, found by dense sampling and a shrinking pattern search (no support
    /// functions, no Newton).
    #[test]
    fn separated_gap_is_the_brute_force_minimum_distance() {
        let mut rng = Rng::new(31);
        let surf =
            |a: &Vec3, u: f64, v: f64| Vec3::new(a.x * u.cos() * v.cos(), a.y * u.sin() * v.cos(), a.z * v.sin());
        let mut checked = 0;
        while checked < 6 {
            let (a1, a2) = (
                Vec3::new(rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5)),
                Vec3::new(rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5)),
            );
            let x1 = Pose::new(rng.rotation(), rng.unit() * rng.uniform(0.5, 1.2));
            let x2 = Pose::new(rng.rotation(), Vec3::zeros());
            let c = gap(&ellipsoid(a1), &x1, &ellipsoid(a2), &x2);
            if c.g_n < 0.02 {
                continue;
            }
            checked += 1;
            let d = |p: &[f64; 4]| {
                (x1.point_to_parent(&surf(&a1, p[0], p[1])) - x2.point_to_parent(&surf(&a2, p[2], p[3]))).norm()
            };
            let (n, m) = (48, 24);
            let (mut best, mut bp) = (f64::INFINITY, [0.0; 4]);
            let ang =
                |i: usize, j: usize| (std::f64::consts::TAU * i as f64 / n as f64, -1.5 + 3.0 * j as f64 / m as f64);
            for i in 0..n {
                for j in 0..=m {
                    for k in 0..n {
                        for l in 0..=m {
                            let ((u1, v1), (u2, v2)) = (ang(i, j), ang(k, l));
                            let p = [u1, v1, u2, v2];
                            let v = d(&p);
                            if v < best {
                                (best, bp) = (v, p);
                            }
                        }
                    }
                }
            }
            let mut step = 0.1;
            while step > 1e-12 {
                let mut moved = false;
                for k in 0..4 {
                    for s in [step, -step] {
                        let mut p = bp;
                        p[k] += s;
                        let v = d(&p);
                        if v < best {
                            (best, bp, moved) = (v, p, true);
                        }
                    }
                }
                if !moved {
                    step *= 0.5;
                }
            }
            assert!((c.g_n - best).abs() < 1e-9, "gap {} vs brute force {best}", c.g_n);
        }
    }
}
