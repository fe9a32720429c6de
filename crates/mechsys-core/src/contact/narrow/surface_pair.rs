//! Spatial parametric surfaces in contact (section 2.2.7.2): a surface of revolution against a
//! half-space, a point or sphere against a surface of revolution or a spline patch. The search
//! lives with the surface ([`Revolution::foot`], [`Revolution::support`], [`Patch::foot`]); here
//! are the contact frame and its exact rates from the differentiated contact conditions.
//!
//! | pair (canonical) | unknowns | conditions | rates |
//! | --- | --- | --- | --- |
//! | revolution – plane (normal `m`) | profile `s`, azimuth | `e_ρ ∥ -m_h`, `μ·q'(s) = 0`, `μ = (-|m_h|, m_z)` | `ṡ = -μ̇·q' / μ·q''` |
//! | point, sphere – revolution | profile `s`, azimuth | `e_ρ ∥ y_h`, `(w - q)·q' = 0` | `ṡ = ẇ·q' / (|q'|² - (w - q)·q'')` |
//! | point, sphere – patch | `s1, s2` | `(y - r)·r_i = 0` (eq. 2.120 with a point) | `(I - h II) ṡ = (ẏ·r_1, ẏ·r_2)` |
//!
//! `m_h` is the half-space normal's part across the axis (revolution frame), `y` the sphere's
//! centre in the surface's frame, `w` its meridian coordinates, `h = g_N + r1` its height over
//! the foot point, `I`, `II` the fundamental forms (eqs. 2.117, 2.119). The normal's rate is
//! `ṅ = ω2 × n + A2 ν̇` with `ν̇` from the parameter rates (eq. 2.125) and, for a revolution,
//! the turning meridian `ė_ρ`.
//!
//! Degenerate: a half-space normal along the axis (the support is a whole parallel circle) or a
//! centre on the axis use a fixed meridian; a patch foot point on a natural edge holds that
//! parameter (the edge's tangent plane continues the surface there); their rates are then those
//! of the fixed choice.

use crate::geometry::curve::{cross, Vec2};
use crate::geometry::revolution::Revolution;
use crate::geometry::surface::Patch;
use crate::math::Vec3;
use crate::spatial::{Motion, Pose};

use super::{vel, Raw};

/// Derivative of the profile's outward normal `ν(s) = σ (q'_y, -q'_x) / |q'|` along `s`.
#[inline]
fn normal_rate(nu: &Vec2, q1: &Vec2, q2: &Vec2) -> Vec2 {
    // ν' ⟂ ν, of size |κ| |q'|: the rotation of the tangent, (q' × q'') / |q'|²
    let turn = cross(q1, q2) / q1.norm_squared();
    Vec2::new(-nu.y, nu.x) * turn
}

/// `e_ρ`'s rate for the meridian of `y` moving at `ẏ` (revolution frame).
#[inline]
fn meridian_rate(w: &Vec2, e: &Vec3, yd: &Vec3) -> Vec3 {
    if w.x > 1e-12 {
        let h = Vec3::new(yd.x, yd.y, 0.0);
        (h - e * e.dot(&h)) / w.x
    } else {
        Vec3::zeros()
    }
}

/// A surface of revolution (body 1) against the half-space `(point, normal)` of body 2: the
/// deepest point along `-m` lies in the meridian opposite to `m`'s part across the axis.
pub(crate) fn revolution_half_space(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    rev: &Revolution,
    point: &Vec3,
    normal: &Vec3,
) -> Raw {
    let m = x2.a * normal;
    let p = x2.point_to_parent(point);
    let a1r = x1.a * rev.rotation;
    let mr = a1r.transpose() * m;
    let a = mr.x.hypot(mr.y);
    let upright = !(a > 1e-12);
    let e = if upright { Vec3::x() } else { -Vec3::new(mr.x, mr.y, 0.0) / a };
    let mu = Vec2::new(-a, mr.z);
    let (s, j) = rev.support(&mu);
    let c = &rev.profile;
    let nu = c.outward(&j[1]);
    let q = j[0] + nu * c.offset();
    let xr = e * q.x + Vec3::z() * q.y;
    let p1 = x1.point_to_parent(&(rev.center + rev.rotation * xr));
    let g = m.dot(&(p1 - p));
    let mut out = Raw { g, n: m, p1, p2: p1 - m * g, ..Default::default() };
    let _ = s;
    if let Some((t1, t2)) = tw {
        let md = t2.w.cross(&m);
        // m in the revolution frame turns with the relative rotation
        let mrd = a1r.transpose() * (t2.w - t1.w).cross(&m);
        let (ed, mud) = if upright {
            (Vec3::zeros(), Vec2::new(0.0, mrd.z))
        } else {
            let u = -e;
            let hd = Vec3::new(mrd.x, mrd.y, 0.0);
            let ad = u.dot(&hd);
            (-(hd - u * ad) / a, Vec2::new(-ad, mrd.z))
        };
        let fs = mu.dot(&j[2]);
        let sd = if fs.abs() > 0.0 { -mud.dot(&j[1]) / fs } else { 0.0 };
        let dq = j[1] + normal_rate(&nu, &j[1], &j[2]) * c.offset();
        let xrd = e * (dq.x * sd) + ed * q.x + Vec3::z() * (dq.y * sd);
        let p1d = vel(t1, &p1) + a1r * xrd;
        let gd = md.dot(&(p1 - p)) + m.dot(&(p1d - vel(t2, &p)));
        out.nd = md;
        out.p1d = p1d;
        out.p2d = p1d - m * gd - md * g;
    }
    out
}

/// A sphere (centre on body 1, radius `r1`; a point when 0) against a surface of revolution of
/// body 2: the foot point in the centre's meridian.
pub(crate) fn sphere_revolution(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    center: &Vec3,
    r1: f64,
    rev: &Revolution,
) -> Raw {
    let c = x1.point_to_parent(center);
    let a2r = x2.a * rev.rotation;
    let y = rev.local(&(x2.a.transpose() * (c - x2.r)));
    let (w, e) = Revolution::meridian(&y);
    let (_, j) = rev.foot(&w);
    let prof = &rev.profile;
    let nu = prof.outward(&j[1]);
    let g = (w - j[0]).dot(&nu) - prof.offset() - r1;
    let nu3 = e * nu.x + Vec3::z() * nu.y;
    let n = a2r * nu3;
    let p1 = c - n * r1;
    let mut out = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        let c1d = vel(t1, &c);
        let yd = a2r.transpose() * (c1d - vel(t2, &c));
        let ed = meridian_rate(&w, &e, &yd);
        let wd = Vec2::new(e.dot(&yd), yd.z);
        // foot condition (w - q)·q' = 0 differentiated
        let den = j[1].norm_squared() - (w - j[0]).dot(&j[2]);
        let sd = if den.abs() > 0.0 { wd.dot(&j[1]) / den } else { 0.0 };
        let nud = normal_rate(&nu, &j[1], &j[2]) * sd;
        let nu3d = e * nud.x + ed * nu.x + Vec3::z() * nud.y;
        let gd = wd.dot(&nu);
        out.nd = t2.w.cross(&n) + a2r * nu3d;
        out.p1d = c1d - out.nd * r1;
        out.p2d = out.p1d - n * gd - out.nd * g;
    }
    out
}

/// A sphere (centre on body 1, radius `r1`; a point when 0) against a spline patch of body 2.
pub(crate) fn sphere_patch(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    center: &Vec3,
    r1: f64,
    patch: &Patch,
) -> Raw {
    let c = x1.point_to_parent(center);
    let y = x2.a.transpose() * (c - x2.r);
    let s = patch.foot(&y);
    let j = patch.eval(s);
    let nu = Patch::normal(&j);
    let h = (y - j[0]).dot(&nu);
    let g = h - r1;
    let n = x2.a * nu;
    let p1 = c - n * r1;
    let mut out = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        let c1d = vel(t1, &c);
        let yd = x2.a.transpose() * (c1d - vel(t2, &c));
        let free = patch.on_edge(s).map(|e| !e);
        // (I - h II) ṡ = (ẏ·r_1, ẏ·r_2), eqs. 2.117, 2.119 (d = h ν inside; on an edge d keeps a
        // part along the edge's normal); a parameter held on an edge has ṡ = 0
        let d = y - j[0];
        let m = |a: usize, b: usize| j[1 + a].dot(&j[1 + b]) - d.dot(&j[3 + a + b]);
        let r = [yd.dot(&j[1]), yd.dot(&j[2])];
        let sd = match free {
            [true, true] => {
                let mat = nalgebra::Matrix2::new(m(0, 0), m(0, 1), m(1, 0), m(1, 1));
                let v = mat.lu().solve(&nalgebra::Vector2::new(r[0], r[1])).unwrap_or_else(nalgebra::Vector2::zeros);
                [v.x, v.y]
            }
            [true, false] => [r[0] / m(0, 0), 0.0],
            [false, true] => [0.0, r[1] / m(1, 1)],
            [false, false] => [0.0, 0.0],
        };
        // ∂ν/∂s_i = (I - ν νᵀ)(r_1i × r_2 + r_1 × r_2i) / |r_1 × r_2| (eq. 2.125)
        let len = j[1].cross(&j[2]).norm();
        let dn = |a: usize| {
            let (r1a, r2a) = (j[3 + a], j[4 + a]);
            let v = r1a.cross(&j[2]) + j[1].cross(&r2a);
            (v - nu * nu.dot(&v)) / len
        };
        let nud = dn(0) * sd[0] + dn(1) * sd[1];
        let gd = yd.dot(&nu) + (y - j[0]).dot(&nud) - (j[1] * sd[0] + j[2] * sd[1]).dot(&nu);
        out.nd = t2.w.cross(&n) + x2.a * nud;
        out.p1d = c1d - out.nd * r1;
        out.p2d = out.p1d - n * gd - out.nd * g;
    }
    out
}

/// An ellipsoid (body 1; centre and shape matrix `S = R diag(a², b², c²) Rᵀ` in its body frame)
/// against a spline patch of body 2. The unknowns are the patch parameters `s`: the ellipsoid's
/// point facing the patch is its support point along `-ν(s)`,
/// `q1 = c - S̃ ν / √(νᵀ S̃ ν)` (`S̃` the shape matrix in body 2's frame), so the normals are
/// opposed by construction and the conditions 2.120 reduce to `(q1 - r)·r_i = 0`. Newton on `s`
/// (Jacobian `-(K ν_,j)·r_i - E_ij + (q1 - r)·r_ij`, `K` the support function's Hessian) from the
/// foot point of the ellipsoid's centre, steps limited to a cell and damped on `|F|`. Rates: the
/// same Jacobian times `ṡ` balances `q̇1·r_i` at fixed `ν`, where a turning body turns its
/// support point (`ṗ1 = v1(p1) - K1 (ṅ - ω1 × n)`, see [`super::convex_pair`]).
pub(crate) fn ellipsoid_patch(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    center: &Vec3,
    shape: &crate::math::Mat3,
    patch: &Patch,
) -> Raw {
    use crate::math::Mat3;
    let rel = x2.a.transpose() * x1.a;
    let st = rel * shape * rel.transpose();
    let yc = x2.a.transpose() * (x1.point_to_parent(center) - x2.r);
    // support point along -ν, its Hessian K and the normal's derivatives at s
    let at = |s: [f64; 2]| {
        let j = patch.eval(s);
        let nu = Patch::normal(&j);
        let sn = st * nu;
        let k = nu.dot(&sn).sqrt();
        let q1 = yc - sn / k;
        let kk: Mat3 = st / k - sn * sn.transpose() / (k * k * k);
        let len = j[1].cross(&j[2]).norm();
        let dn = |a: usize| {
            let v = j[3 + a].cross(&j[2]) + j[1].cross(&j[4 + a]);
            (v - nu * nu.dot(&v)) / len
        };
        let dnu = [dn(0), dn(1)];
        (j, nu, q1, kk, dnu)
    };
    let residual = |j: &crate::geometry::surface::Jet, q1: &Vec3| {
        let d = q1 - j[0];
        nalgebra::Vector2::new(d.dot(&j[1]), d.dot(&j[2]))
    };
    let jacobian = |j: &crate::geometry::surface::Jet, q1: &Vec3, kk: &Mat3, dnu: &[Vec3; 2]| {
        let d = q1 - j[0];
        let m = |i: usize, c: usize| -(kk * dnu[c]).dot(&j[1 + i]) - j[1 + c].dot(&j[1 + i]) + d.dot(&j[3 + i + c]);
        nalgebra::Matrix2::new(m(0, 0), m(0, 1), m(1, 0), m(1, 1))
    };
    let mut s = patch.foot(&yc);
    let mut cur = at(s);
    let mut fr = residual(&cur.0, &cur.2);
    let [(a0, a1), (b0, b1)] = patch.range();
    let cell = [(a1 - a0) / 8.0, (b1 - b0) / 8.0];
    for _ in 0..60 {
        let jm = jacobian(&cur.0, &cur.2, &cur.3, &cur.4);
        let Some(ji) = jm.try_inverse() else { break };
        let mut step = -(ji * fr);
        let cap = (step.x.abs() / cell[0]).max(step.y.abs() / cell[1]);
        if cap > 1.0 {
            step /= cap;
        }
        let mut moved = false;
        for _ in 0..30 {
            let t = patch.clamp([s[0] + step.x, s[1] + step.y]);
            let next = at(t);
            let fn_ = residual(&next.0, &next.2);
            if fn_.norm() <= fr.norm() * (1.0 + 1e-12) {
                moved = (t[0] - s[0]).abs() > 1e-15 * cell[0] || (t[1] - s[1]).abs() > 1e-15 * cell[1];
                (s, cur, fr) = (t, next, fn_);
                break;
            }
            step *= 0.5;
        }
        if !moved {
            break;
        }
    }
    let (j, nu, q1, kk, dnu) = cur;
    let g = (q1 - j[0]).dot(&nu);
    let n = x2.a * nu;
    let p1 = x2.point_to_parent(&q1);
    let mut out = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        // q̇1 at fixed ν (body 2 frame): the support point turned by the relative rotation
        let kw = x2.a * kk * x2.a.transpose();
        let p1_fixed = vel(t1, &p1) - kw * (t2.w - t1.w).cross(&n);
        let q1d = x2.a.transpose() * (p1_fixed - vel(t2, &p1));
        let free = patch.on_edge(s).map(|e| !e);
        let jm = jacobian(&j, &q1, &kk, &dnu);
        let r = -nalgebra::Vector2::new(q1d.dot(&j[1]), q1d.dot(&j[2]));
        let sd = match free {
            [true, true] => {
                let v = jm.lu().solve(&r).unwrap_or_else(nalgebra::Vector2::zeros);
                [v.x, v.y]
            }
            [true, false] => [r[0] / jm[(0, 0)], 0.0],
            [false, true] => [0.0, r[1] / jm[(1, 1)]],
            [false, false] => [0.0, 0.0],
        };
        let nud = dnu[0] * sd[0] + dnu[1] * sd[1];
        let nd = t2.w.cross(&n) + x2.a * nud;
        let p1d = vel(t1, &p1) - kw * (nd - t1.w.cross(&n));
        let gd = n.dot(&(p1d - vel(t2, &p1))) + (x2.a * (q1 - j[0])).dot(&nd)
            - (x2.a * (j[1] * sd[0] + j[2] * sd[1])).dot(&n);
        out.nd = nd;
        out.p1d = p1d;
        out.p2d = p1d - n * gd - nd * g;
    }
    out
}
