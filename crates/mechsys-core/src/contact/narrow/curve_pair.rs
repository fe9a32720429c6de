//! Planar parametric contours in contact (section 2.2.7.1): the contact search on the contour
//! parameters and the exact rates of the contact frame.
//!
//! Everything is computed in body 2's x-y plane: body 1's contour is mapped there by the relative
//! placement (`ρ1(s1) = [A2ᵀ (r1 - r2 + A1 r1(s1))]_xy`; in plane motion this is a rigid motion of
//! the curve, in general 3-D motion a projection, equally well defined). With `d = ρ1 - r2`:
//!
//! | pair (canonical) | unknowns | conditions | valid root |
//! | --- | --- | --- | --- |
//! | point, circle – curve | `s2` | `d·r2' = 0` (foot point) | distance minimum: `|r2'|² - d·r2'' > 0` |
//! | curve – line (normal `m`) | `s1` | `m·ρ1' = 0` (support point) | `m·ρ1'' > 0` (deepest point) |
//! | curve – curve | `s1, s2` | `d·r2' = 0`, `ρ1' × r2' = 0` (eqs. 2.102, 2.103) | normals opposed, `κ1 + κ2 + g κ1 κ2 > 0` |
//!
//! The gap is `g_N = d·ν2 - o1 - o2` (eq. 2.105 with the outward normal `ν2` of contour 2 and
//! the contours' offsets), `n = A2 ν2`, `P1 = P1,base - o1 n`, `P2 = P1 - g_N n`. The parameter
//! rates `ṡ` solve the conditions differentiated in time (the general form of eq. 2.109),
//! `J ṡ = -∂F/∂t`; from them `ṅ = ω2 × n + A2 ν2'(s2) ṡ2` (eq. 2.92) and the rates of the points,
//! which the relative kinematics turn into the `κ ṡ` terms of eqs. 2.100, 2.101 and 2.115.
//!
//! **Global start.** Each contour carries samples and a bounding circle per chunk of samples.
//! Chunks (pairs of chunks for curve–curve) that cannot hold a point closer than the closest
//! chunk bound (plus a reach when several points are wanted) are skipped; on the rest, the
//! local minima of the sampled distance (point–curve), height (curve–line) or sampled signed
//! distance of contour 1's samples to contour 2 (curve–curve) seed a damped Newton iteration. A
//! non-convex contour therefore has a seed near every local minimum, and Newton only refines
//! it; roots that are not minima (the far side of a concave flank) are refused. When no seed
//! converges, the best sample pair is used as it is (finite, approximate).
//!
//! **Several points.** With `count > 1` the `count` deepest roots are kept, ordered by their
//! parameter on the curve (so a candidate keeps its index while its root persists); slots
//! without a root are *unused* candidates whose gap exceeds any real one.

use crate::geometry::curve::{cross, Curve, Jet2, Vec2, CHUNK, MAX_SAMPLES};
use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

use super::{vel, Raw};

/// Most candidates per curve pair (a stack buffer holds them).
pub const MAX_POINTS: usize = 8;
/// Roots kept during one search.
const MAX_ROOTS: usize = 16;
/// Most seeds refined by Newton in a curve–curve search (the deepest local minima).
const MAX_SEEDS: usize = 10;
use crate::geometry::curve::{CONVERGED, NEWTON_ITERATIONS};

/// What body 1 (canonical order) brings against a curve.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum First {
    /// Body-fixed centres inflated by `radius` (a point, a circle, a polygon's vertices).
    Points { centers: Vec<Vec3>, radius: f64 },
    /// A parametric contour.
    Curve(Curve),
}

/// A curve pair's geometry in canonical order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum CurveGeometry {
    /// Points or a curve on body 1 against a curve on body 2; `count` candidates (for points:
    /// per centre when there are several centres, else the `count` best foot points).
    OnCurve { first: First, second: Curve, count: usize, reach: f64 },
    /// A curve on body 1 against the half-plane `(point, normal)` of body 2 (2-D, body 2 frame).
    OnLine { curve: Curve, point: Vec2, normal: Vec2, count: usize, reach: f64 },
}

/// A root of the contact conditions.
#[derive(Debug, Clone, Copy, Default)]
struct Root {
    s1: f64,
    s2: f64,
    /// Ranking key: smaller is deeper.
    key: f64,
}

/// The best roots found so far (sorted by key), without allocation.
struct Roots {
    list: [Root; MAX_ROOTS],
    len: usize,
    keep: usize,
}

impl Roots {
    fn new(keep: usize) -> Self {
        Roots { list: [Root::default(); MAX_ROOTS], len: 0, keep: keep.clamp(1, MAX_ROOTS) }
    }
    /// Adds a root unless one with the same parameters (`same`) is there.
    fn push(&mut self, r: Root, same: impl Fn(&Root, &Root) -> bool) {
        if self.list[..self.len].iter().any(|o| same(o, &r)) {
            return;
        }
        let mut i = self.len;
        while i > 0 && self.list[i - 1].key > r.key {
            i -= 1;
        }
        if i >= self.keep {
            return;
        }
        let end = self.len.min(self.keep - 1);
        let mut j = end;
        while j > i {
            self.list[j] = self.list[j - 1];
            j -= 1;
        }
        self.list[i] = r;
        self.len = (self.len + 1).min(self.keep);
    }
}

/// Relative placement of body 1 in body 2's frame and the world data of both.
struct Relative<'a> {
    x1: &'a Pose,
    x2: &'a Pose,
    /// `A2ᵀ A1`
    b: Mat3,
    /// `A2ᵀ (r1 - r2)`
    c: Vec3,
}

impl<'a> Relative<'a> {
    fn new(x1: &'a Pose, x2: &'a Pose) -> Self {
        let a2t = x2.a.transpose();
        Relative { x1, x2, b: a2t * x1.a, c: a2t * (x1.r - x2.r) }
    }
    /// A point of body 1 (body frame) in body 2's plane.
    #[inline]
    fn point(&self, p: &Vec2) -> Vec2 {
        let y = self.b * lift(p) + self.c;
        Vec2::new(y.x, y.y)
    }
    #[inline]
    fn point3(&self, p: &Vec3) -> Vec2 {
        let y = self.b * p + self.c;
        Vec2::new(y.x, y.y)
    }
    /// A direction of body 1 (body frame) in body 2's plane.
    #[inline]
    fn dir(&self, v: &Vec2) -> Vec2 {
        let y = self.b * lift(v);
        Vec2::new(y.x, y.y)
    }
    /// Orientation of body 1's plane seen in body 2's (`+1` unless turned over).
    fn handed(&self) -> f64 {
        if self.b[(0, 0)] * self.b[(1, 1)] - self.b[(0, 1)] * self.b[(1, 0)] >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }
    /// Rate, in body 2's plane, of body 1's material point at world `x`.
    #[inline]
    fn point_rate(&self, tw: (&Motion, &Motion), x: &Vec3) -> Vec2 {
        let y = self.x2.a.transpose() * (vel(tw.0, x) - vel(tw.1, x));
        Vec2::new(y.x, y.y)
    }
    /// Rate, in body 2's plane, of body 1's direction `v` (body frame).
    #[inline]
    fn dir_rate(&self, tw: (&Motion, &Motion), v: &Vec2) -> Vec2 {
        let y = self.x2.a.transpose() * (tw.0.w - tw.1.w).cross(&(self.x1.a * lift(v)));
        Vec2::new(y.x, y.y)
    }
    /// A 2-D vector of body 2's plane in the world.
    #[inline]
    fn world2(&self, v: &Vec2) -> Vec3 {
        self.x2.a * lift(v)
    }
}

#[inline]
fn lift(v: &Vec2) -> Vec3 {
    Vec3::new(v.x, v.y, 0.0)
}

/// Whether two parameters are the same point of `curve` (periodic-aware).
fn same_param(curve: &Curve, a: f64, b: f64) -> bool {
    let tol = 1e-7 * curve.step();
    if curve.is_closed() {
        let (lo, hi) = curve.range();
        let p = hi - lo;
        let d = (a - b).rem_euclid(p);
        d.min(p - d) <= tol
    } else {
        (a - b).abs() <= tol
    }
}

/// Derivative of the outward normal with respect to the parameter.
#[inline]
fn normal_rate(curve_sigma_normal: &Vec2, j: &Jet2) -> Vec2 {
    // ν = σ (r'_y, -r'_x) / |r'|: ν' = σ (r''_y, -r''_x) / |r'| - ν (r'·r'') / |r'|²
    let l2 = j[1].norm_squared();
    let sigma_perp = |v: &Vec2| Vec2::new(v.y, -v.x);
    // σ/|r'| recovered from ν and r': ν = (σ/|r'|) perp(r')
    let scale = curve_sigma_normal.dot(&sigma_perp(&j[1])) / l2;
    sigma_perp(&j[2]) * scale - curve_sigma_normal * (j[1].dot(&j[2]) / l2)
}

impl CurveGeometry {
    /// Sets the number of candidates (shared searches only) and the reach of the search: a
    /// tenth of the smaller bounding radius when several points are wanted.
    pub(crate) fn set_points(&mut self, points: usize) {
        match self {
            CurveGeometry::OnCurve { first, second, count, reach } => {
                *count = points;
                let r1 = match first {
                    First::Curve(c) => c.bound().1,
                    First::Points { .. } => f64::INFINITY,
                };
                *reach = if points > 1 { 0.1 * r1.min(second.bound().1) } else { 0.0 };
            }
            CurveGeometry::OnLine { curve, count, reach, .. } => {
                *count = points;
                *reach = if points > 1 { 0.1 * curve.bound().1 } else { 0.0 };
            }
        }
    }

    /// Whether one search serves all candidates (else each candidate searches alone).
    pub(crate) fn shared(&self) -> bool {
        !matches!(self, CurveGeometry::OnCurve { first: First::Points { centers, .. }, .. } if centers.len() > 1)
    }

    /// Candidate `k` alone (one search per candidate: a polygon's vertices).
    pub(crate) fn one(&self, k: usize, x1: &Pose, x2: &Pose, tw: Option<(&Motion, &Motion)>) -> Raw {
        let mut out = [Raw::default(); 1];
        match self {
            CurveGeometry::OnCurve { first: First::Points { centers, radius }, second, .. } => {
                point_curve(&centers[k], *radius, second, 1, 0.0, x1, x2, tw, &mut out);
            }
            _ => {
                let mut all = [Raw::default(); MAX_POINTS];
                self.all(x1, x2, tw, &mut all);
                return all[k];
            }
        }
        out[0]
    }

    /// All candidates into `out[..count]` (shared search).
    pub(crate) fn all(&self, x1: &Pose, x2: &Pose, tw: Option<(&Motion, &Motion)>, out: &mut [Raw]) {
        match self {
            CurveGeometry::OnCurve { first: First::Points { centers, radius }, second, count, reach } => {
                if centers.len() == 1 {
                    point_curve(&centers[0], *radius, second, *count, *reach, x1, x2, tw, out);
                } else {
                    for (k, o) in out.iter_mut().enumerate().take(centers.len()) {
                        *o = self.one(k, x1, x2, tw);
                    }
                }
            }
            CurveGeometry::OnCurve { first: First::Curve(c1), second, count, reach } => {
                curve_curve(c1, second, *count, *reach, x1, x2, tw, out)
            }
            CurveGeometry::OnLine { curve, point, normal, count, reach } => {
                curve_line(curve, point, normal, *count, *reach, x1, x2, tw, out)
            }
        }
    }
}

/// The unused candidate: the bounding centres' direction `u` in body 2's plane, a gap larger
/// than any real one; `P1` is body 1's material point at its bounding centre, `P2 = P1 - g n`,
/// so that `n·(v1(P1) - v2(P2))` is the rate of the gap as for every candidate.
fn unused(rel: &Relative, c1: &Vec2, r1: f64, c2: &Vec2, r2: f64, tw: Option<(&Motion, &Motion)>) -> Raw {
    let e = rel.point(c1) - c2;
    let len = e.norm();
    let (u, degenerate) = if len > 1e-12 * (1.0 + r1 + r2) { (e / len, false) } else { (Vec2::x(), true) };
    let g = len + 2.0 * (r1 + r2) + 1.0;
    let n = rel.world2(&u);
    let p1 = rel.x1.point_to_parent(&lift(c1));
    let mut out = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
    if let Some(tw) = tw {
        let ed = rel.point_rate(tw, &p1);
        let (gd, ud) = if degenerate { (0.0, Vec2::zeros()) } else { (u.dot(&ed), (ed - u * u.dot(&ed)) / len) };
        out.nd = tw.1.w.cross(&n) + rel.world2(&ud);
        out.p1d = vel(tw.0, &p1);
        out.p2d = out.p1d - n * gd - out.nd * g;
    }
    out
}

/// Fills `out` from sorted roots (by parameter), unused candidates after them.
fn fill(roots: &mut Roots, count: usize, param: impl Fn(&Root) -> f64, mut make: impl FnMut(usize, Option<&Root>)) {
    let n = roots.len.min(count);
    roots.list[..n].sort_by(|a, b| param(a).total_cmp(&param(b)));
    for k in 0..count {
        make(k, if k < n { Some(&roots.list[k]) } else { None });
    }
}

/// A centre of body 1 (body frame, inflated by `radius`) against `curve` on body 2.
#[allow(clippy::too_many_arguments)]
fn point_curve(
    center: &Vec3,
    radius: f64,
    curve: &Curve,
    count: usize,
    reach: f64,
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    out: &mut [Raw],
) {
    let rel = Relative::new(x1, x2);
    let y = rel.point3(center);
    let mut roots = Roots::new(count.max(1));
    foot_points(curve, &y, reach, &mut roots);
    let o2 = curve.offset();
    let c2d = Vec2::new(center.x, center.y);
    fill(&mut roots, count, |r| r.s2, |k, root| {
        out[k] = match root {
            None => unused(&rel, &c2d, radius, &curve.bound().0, curve.bound().1, tw),
            Some(root) => {
                let j = curve.eval(root.s2);
                let d = y - j[0];
                let nu = curve.outward(&j[1]);
                let g = d.dot(&nu) - radius - o2;
                let n = rel.world2(&nu);
                let cw = x1.point_to_parent(center);
                let p1 = cw - n * radius;
                let mut r = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
                if let Some(tw) = tw {
                    let yd = rel.point_rate(tw, &cw);
                    let fs = -j[1].norm_squared() + d.dot(&j[2]);
                    let sd = if fs.abs() > 0.0 { -yd.dot(&j[1]) / fs } else { 0.0 };
                    let nud = normal_rate(&nu, &j) * sd;
                    let gd = (yd - j[1] * sd).dot(&nu) + d.dot(&nud);
                    r.nd = tw.1.w.cross(&n) + rel.world2(&nud);
                    r.p1d = vel(tw.0, &cw) - r.nd * radius;
                    r.p2d = r.p1d - n * gd - r.nd * g;
                }
                r
            }
        };
    });
}

/// Local minima of the distance from `y` to the curve's samples, refined to foot points.
fn foot_points(curve: &Curve, y: &Vec2, reach: f64, roots: &mut Roots) {
    let (samples, chunks) = (curve.samples(), curve.chunks());
    let n = samples.len();
    let ub = chunks.iter().map(|c| (y - c.center).norm() + c.radius).fold(f64::INFINITY, f64::min);
    let dist = |i: usize| (y - samples[i].r).norm();
    let mut best = (f64::INFINITY, 0usize);
    for ch in chunks {
        if (y - ch.center).norm() - ch.radius > ub + reach {
            continue;
        }
        for i in ch.first..ch.first + ch.count {
            let di = dist(i);
            if di < best.0 {
                best = (di, i);
            }
            let prev = if i > 0 { dist(i - 1) } else if curve.is_closed() { dist(n - 1) } else { f64::INFINITY };
            let next = if i + 1 < n { dist(i + 1) } else if curve.is_closed() { dist(0) } else { f64::INFINITY };
            if di <= prev && di <= next {
                if let Some(s) = curve.foot(y, samples[i].s) {
                    let j = curve.eval(s);
                    let key = (y - j[0]).dot(&curve.outward(&j[1])).abs();
                    roots.push(Root { s1: 0.0, s2: curve.wrap(s), key }, |a, b| same_param(curve, a.s2, b.s2));
                }
            }
        }
    }
    if roots.len == 0 && best.0.is_finite() {
        roots.push(Root { s1: 0.0, s2: samples[best.1].s, key: best.0 }, |_, _| false);
    }
}

/// A curve on body 1 against the half-plane of body 2 (2-D `point`, unit `normal`).
#[allow(clippy::too_many_arguments)]
fn curve_line(
    curve: &Curve,
    point: &Vec2,
    m: &Vec2,
    count: usize,
    reach: f64,
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    out: &mut [Raw],
) {
    let rel = Relative::new(x1, x2);
    let (samples, chunks) = (curve.samples(), curve.chunks());
    let ns = samples.len();
    let height = |i: usize| m.dot(&rel.point(&samples[i].r));
    let ub = chunks.iter().map(|c| m.dot(&rel.point(&c.center)) + c.radius).fold(f64::INFINITY, f64::min);
    let mut roots = Roots::new(count.max(1));
    let mut best = (f64::INFINITY, 0usize);
    let jet = |s: f64| {
        let j = curve.eval(s);
        (rel.point(&j[0]), rel.dir(&j[1]), rel.dir(&j[2]), j)
    };
    for ch in chunks {
        if m.dot(&rel.point(&ch.center)) - ch.radius > ub + reach {
            continue;
        }
        for i in ch.first..ch.first + ch.count {
            let hi = height(i);
            if hi < best.0 {
                best = (hi, i);
            }
            let prev = if i > 0 { height(i - 1) } else if curve.is_closed() { height(ns - 1) } else { f64::INFINITY };
            let next = if i + 1 < ns { height(i + 1) } else if curve.is_closed() { height(0) } else { f64::INFINITY };
            if hi <= prev && hi <= next {
                // Newton on m·ρ1'(s) = 0 towards the minimum of the height
                let cap = 2.0 * curve.step();
                let mut s = samples[i].s;
                let mut ok = false;
                for _ in 0..NEWTON_ITERATIONS {
                    let (_, r1, r2, _) = jet(s);
                    let (f, fs) = (m.dot(&r1), m.dot(&r2));
                    let ds = if fs > 0.0 { (-f / fs).clamp(-cap, cap) } else { -f.signum() * cap };
                    s += ds;
                    if ds.abs() <= CONVERGED * curve.step() {
                        ok = m.dot(&jet(s).2) > 0.0;
                        break;
                    }
                }
                if ok {
                    let key = m.dot(&(jet(s).0 - point));
                    roots.push(Root { s1: curve.wrap(s), s2: 0.0, key }, |a, b| same_param(curve, a.s1, b.s1));
                }
            }
        }
    }
    if roots.len == 0 && best.0.is_finite() {
        roots.push(Root { s1: samples[best.1].s, s2: 0.0, key: best.0 }, |_, _| false);
    }
    let o1 = curve.offset();
    fill(&mut roots, count, |r| r.s1, |k, root| {
        out[k] = match root {
            None => unused(&rel, &curve.bound().0, curve.bound().1, point, 0.0, tw),
            Some(root) => {
                let (rho, rho1, rho2, j) = jet(root.s1);
                let g = m.dot(&(rho - point)) - o1;
                let n = rel.world2(m);
                let pb = x1.point_to_parent(&lift(&j[0]));
                let p1 = pb - n * o1;
                let mut r = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
                if let Some(tw) = tw {
                    let rhod = rel.point_rate(tw, &pb);
                    let rho1d = rel.dir_rate(tw, &j[1]);
                    let fs = m.dot(&rho2);
                    let sd = if fs.abs() > 0.0 { -m.dot(&rho1d) / fs } else { 0.0 };
                    let gd = m.dot(&(rhod + rho1 * sd));
                    r.nd = tw.1.w.cross(&n);
                    r.p1d = vel(tw.0, &pb) + x1.a * lift(&j[1]) * sd - r.nd * o1;
                    r.p2d = r.p1d - n * gd - r.nd * g;
                }
                r
            }
        };
    });
}

/// Two curves: seeds from the sampled signed distance of curve 1's samples to curve 2.
#[allow(clippy::too_many_arguments)]
fn curve_curve(
    c1: &Curve,
    c2: &Curve,
    count: usize,
    reach: f64,
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    out: &mut [Raw],
) {
    let rel = Relative::new(x1, x2);
    let (s1, ch1) = (c1.samples(), c1.chunks());
    let (s2, ch2) = (c2.samples(), c2.chunks());
    let n1 = s1.len();
    // chunk pruning: keep chunks that may hold a point within the best upper bound (+ reach)
    let mut keep1 = [false; MAX_SAMPLES / CHUNK + 1];
    let mut keep2 = [false; MAX_SAMPLES / CHUNK + 1];
    let mut centers1 = [Vec2::zeros(); MAX_SAMPLES / CHUNK + 1];
    for (a, ca) in ch1.iter().enumerate() {
        centers1[a] = rel.point(&ca.center);
    }
    // an upper bound of the distance between the curves: the closest sample pair of the chunk
    // pair with the smallest lower bound (much tighter than the chunks' own bounds)
    let mut lowest = (f64::INFINITY, 0usize, 0usize);
    for (a, ca) in ch1.iter().enumerate() {
        for (b, cb) in ch2.iter().enumerate() {
            let lb = (centers1[a] - cb.center).norm() - ca.radius - cb.radius;
            if lb < lowest.0 {
                lowest = (lb, a, b);
            }
        }
    }
    let mut ub = f64::INFINITY;
    if lowest.0.is_finite() {
        let (ca, cb) = (&ch1[lowest.1], &ch2[lowest.2]);
        for i in ca.first..ca.first + ca.count {
            let p = rel.point(&s1[i].r);
            for smp in &s2[cb.first..cb.first + cb.count] {
                ub = ub.min((p - smp.r).norm());
            }
        }
    }
    for (a, ca) in ch1.iter().enumerate() {
        for (b, cb) in ch2.iter().enumerate() {
            if (centers1[a] - cb.center).norm() - ca.radius - cb.radius <= ub + reach {
                keep1[a] = true;
                keep2[b] = true;
            }
        }
    }
    // signed distance of a kept sample of curve 1 to the kept samples of curve 2 (recomputed for
    // the neighbours instead of stored: no buffers of sample length on the stack)
    let phi = |i: usize| -> (f64, usize) {
        if !keep1[i / CHUNK] {
            return (f64::INFINITY, 0);
        }
        let p = rel.point(&s1[i].r);
        let mut best = (f64::INFINITY, 0usize);
        for (b, cb) in ch2.iter().enumerate() {
            if !keep2[b] || (p - cb.center).norm() - cb.radius > best.0 {
                continue;
            }
            for jdx in cb.first..cb.first + cb.count {
                let dd = (p - s2[jdx].r).norm();
                if dd < best.0 {
                    best = (dd, jdx);
                }
            }
        }
        let sign = if (p - s2[best.1].r).dot(&s2[best.1].nu) < 0.0 { -1.0 } else { 1.0 };
        (sign * best.0, best.1)
    };
    let handed = rel.handed();
    let jets = |a: f64, b: f64| {
        let j1 = c1.eval(a);
        let j2 = c2.eval(b);
        ([rel.point(&j1[0]), rel.dir(&j1[1]), rel.dir(&j1[2]), rel.dir(&j1[3])], j1, j2)
    };
    let mut roots = Roots::new(count.max(1));
    let mut best = (f64::INFINITY, 0usize, 0usize);
    let cap1 = 2.0 * c1.step();
    // seeds: the local minima of φ along curve 1 within the kept chunks, the deepest few only
    let max_seeds = (count + 2).min(MAX_SEEDS);
    let mut seeds = [(f64::INFINITY, 0usize, 0usize); MAX_SEEDS];
    let mut nseeds = 0;
    let neighbour = |i: isize| -> Option<usize> {
        if i >= 0 && (i as usize) < n1 {
            Some(i as usize)
        } else if c1.is_closed() {
            Some(i.rem_euclid(n1 as isize) as usize)
        } else {
            None
        }
    };
    for (a, ca) in ch1.iter().enumerate() {
        if !keep1[a] {
            continue;
        }
        // φ of the chunk's samples and of one neighbour on each side
        let mut vals = [(f64::INFINITY, 0usize); CHUNK + 2];
        for (k, v) in vals.iter_mut().enumerate().take(ca.count + 2) {
            if let Some(i) = neighbour(ca.first as isize + k as isize - 1) {
                *v = phi(i);
            }
        }
        for k in 1..=ca.count {
            let (pi, partner) = vals[k];
            let i = ca.first + k - 1;
            if pi < best.0 {
                best = (pi, i, partner);
            }
            if pi.is_finite() && pi <= vals[k - 1].0 && pi <= vals[k + 1].0 {
                // insert sorted by φ, keeping the deepest max_seeds
                let mut j = nseeds.min(max_seeds - 1);
                if nseeds == max_seeds && pi >= seeds[j].0 {
                    continue;
                }
                while j > 0 && seeds[j - 1].0 > pi {
                    seeds[j] = seeds[j - 1];
                    j -= 1;
                }
                seeds[j] = (pi, i, partner);
                nseeds = (nseeds + 1).min(max_seeds);
            }
        }
    }
    for &(_, i, partner) in &seeds[..nseeds] {
        // minimize the signed distance φ(s1) of curve 1's point to curve 2 (the foot point s2
        // follows s1): φ' = ν2·ρ1' (envelope theorem), φ'' = ν2·ρ1'' + ν2'·ρ1' ds2/ds1
        let (mut a, mut b) = (s1[i].s, s2[partner].s);
        let mut ok = false;
        for _ in 0..NEWTON_ITERATIONS {
            let r1 = jets(a, b).0;
            let Some(foot) = c2.foot(&r1[0], b) else { break };
            b = foot;
            let j2 = c2.eval(b);
            let d = r1[0] - j2[0];
            let nu2 = c2.outward(&j2[1]);
            let fp = nu2.dot(&r1[1]);
            let foot_s = -j2[1].norm_squared() + d.dot(&j2[2]);
            let db_da = -r1[1].dot(&j2[1]) / foot_s;
            let fpp = nu2.dot(&r1[2]) + normal_rate(&nu2, &j2).dot(&r1[1]) * db_da;
            let da = if fpp > 0.0 { (-fp / fpp).clamp(-cap1, cap1) } else { -fp.signum() * cap1 };
            a += da;
            b += db_da * da;
            if da.abs() <= CONVERGED * c1.step() {
                ok = c2.foot(&jets(a, b).0[0], b).map(|f| b = f).is_some() && fpp > 0.0;
                break;
            }
        }
        if !ok {
            continue;
        }
        let (r1, _, j2) = jets(a, b);
        // the mapped curve's outward normal and curvature (a projection when body 1 is tilted;
        // turned over it runs the other way round)
        let nu1p = c1.outward(&r1[1]) * handed;
        let nu2 = c2.outward(&j2[1]);
        let g = (r1[0] - j2[0]).dot(&nu2);
        let k1 = c1.curvature_of(&[r1[0], r1[1], r1[2], r1[3]]) * handed;
        let k2 = c2.curvature_of(&j2);
        if nu1p.dot(&nu2) < 0.0 && k1 + k2 + g * k1 * k2 > 0.0 {
            roots.push(Root { s1: c1.wrap(a), s2: c2.wrap(b), key: g }, |p, q| {
                same_param(c1, p.s1, q.s1) && same_param(c2, p.s2, q.s2)
            });
        }
    }
    if roots.len == 0 && best.0.is_finite() {
        roots.push(Root { s1: s1[best.1].s, s2: s2[best.2].s, key: best.0 }, |_, _| false);
    }
    let (o1, o2) = (c1.offset(), c2.offset());
    fill(&mut roots, count, |r| r.s1, |k, root| {
        out[k] = match root {
            None => unused(&rel, &c1.bound().0, c1.bound().1, &c2.bound().0, c2.bound().1, tw),
            Some(root) => {
                let (r1, j1, j2) = jets(root.s1, root.s2);
                let d = r1[0] - j2[0];
                let nu = c2.outward(&j2[1]);
                let g = d.dot(&nu) - o1 - o2;
                let n = rel.world2(&nu);
                let pb = x1.point_to_parent(&lift(&j1[0]));
                let p1 = pb - n * o1;
                let mut r = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
                if let Some(tw) = tw {
                    let rhod = rel.point_rate(tw, &pb);
                    let rho1d = rel.dir_rate(tw, &j1[1]);
                    let jm = [
                        [r1[1].dot(&j2[1]), -j2[1].norm_squared() + d.dot(&j2[2])],
                        [cross(&r1[2], &j2[1]), cross(&r1[1], &j2[2])],
                    ];
                    let ft = [rhod.dot(&j2[1]), cross(&rho1d, &j2[1])];
                    let det = jm[0][0] * jm[1][1] - jm[0][1] * jm[1][0];
                    let (sd1, sd2) = if det.abs() > 0.0 && det.is_finite() {
                        (-(jm[1][1] * ft[0] - jm[0][1] * ft[1]) / det, -(-jm[1][0] * ft[0] + jm[0][0] * ft[1]) / det)
                    } else {
                        (0.0, 0.0)
                    };
                    let nud = normal_rate(&nu, &j2) * sd2;
                    let gd = (rhod + r1[1] * sd1 - j2[1] * sd2).dot(&nu) + d.dot(&nud);
                    r.nd = tw.1.w.cross(&n) + rel.world2(&nud);
                    r.p1d = vel(tw.0, &pb) + x1.a * lift(&j1[1]) * sd1 - r.nd * o1;
                    r.p2d = r.p1d - n * gd - r.nd * g;
                }
                r
            }
        };
    });
}


