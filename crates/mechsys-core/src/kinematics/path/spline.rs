//! Piecewise polynomial space curves re-parameterized by arc length: the C² cubic spline through
//! points, and the quintic Hermite spline through samples of a function with its first and
//! second derivatives.
//!
//! **Cubic through points.** Knots at the cumulative chord lengths `h_k = |P_{k+1} − P_k|`; the
//! second derivatives `M_k` solve the tridiagonal system
//! `h_{k−1} M_{k−1} + 2 (h_{k−1} + h_k) M_k + h_k M_{k+1} = 6 ((P_{k+1} − P_k)/h_k − (P_k − P_{k−1})/h_{k−1})`
//! with natural ends (`M = 0`: the curvature vanishes at both ends) for an open spline, or
//! periodically (a cyclic system, by Sherman–Morrison) for a closed one. Segment k is then
//! `P(x) = P_k + b x + M_k x²/2 + (M_{k+1} − M_k) x³/(6 h_k)`, `x ∈ [0, h_k]`.
//!
//! **Quintic Hermite through samples** `p_j, r_j, r'_j, r''_j` (r' = dr/dp): on each interval the
//! quintic matching value, first and second derivative at both ends (C² across samples). Its
//! error is at most `h⁶ max|r⁽⁶⁾| / 46080` in position (h the sample spacing of p; the interpolation
//! remainder `r⁽⁶⁾(ξ) (p − p_j)³ (p − p_{j+1})³ / 6!`), `O(h⁵)` in the tangent, `O(h⁴)` in the
//! curvature.
//!
//! Both are stored as polynomials `P_k(τ) = Σ c_j τʲ` in a local `τ ∈ [0, 1]`.
//!
//! **Arc length.** The parameter is not the arc length. The length of each segment,
//! `∫₀¹ |P_k'(τ)| dτ`, is tabulated by 8-point Gauss–Legendre on `m_k` equal sub-intervals,
//! `m_k` doubled until two successive totals agree to 1e-13 (the rule's error then is far below
//! rounding). At run time `s` is located by bisection in the tables and `τ(s)` found by Newton's
//! method on `∫_{τ_j}^τ |P'| = s − s_j` (the partial integral by the same rule), converged to
//! rounding. The derivatives of `τ(s)` follow from `dτ/ds = 1/|P'(τ)|` as a Taylor series
//! (`path::jet`), and so do those of `r(s) = P(τ(s))`: the chain rule of the re-parameterization
//! done exactly, to any order, with `|dr/ds| = 1` to rounding.
//!
//! **Beyond the ends** of an open spline the path continues straight along the end tangent
//! (`r = r(0) + t(0) s` for s < 0, `r = r(L) + t(L) (s − L)` for s > L), with the end's frame and
//! no curvature: position and tangent stay continuous; for the cubic through points, whose
//! natural ends have zero curvature, the curvature too. A closed spline repeats with period L.

use nalgebra::{Matrix3, SymmetricEigen};

use super::jet::{JVec, Jet};
use crate::math::quadrature::{gl8, integrate};
use crate::math::Vec3;

/// A spline re-parameterized by arc length.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline {
    /// Segment polynomials `P_k(τ) = Σ_j coef[k][j] τʲ`, τ ∈ [0, 1] (cubics have zero c₄, c₅).
    coef: Vec<[Vec3; 6]>,
    /// Polynomial degree (3 or 5).
    degree: usize,
    /// Arc length at the sub-interval boundaries, segment k's in `table[start[k]..start[k + 1]]`.
    table: Vec<f64>,
    /// Offsets of the segments in `table` (one more than segments).
    start: Vec<usize>,
    /// Arc length at each segment's start, and the total last.
    s_seg: Vec<f64>,
    /// Whether the curve closes on itself (then s wraps with period L).
    closed: bool,
    /// The child frame's reference direction (b leans towards it; see `path`).
    pub up: Vec3,
    /// The unit normal of the plane holding the curve (its sign along `up`), if it is planar.
    pub plane: Option<Vec3>,
    /// The smallest sine of the angle between the tangent and `up` along the curve, and the arc
    /// length where it occurs (the frame needs it away from 0).
    pub up_clearance: (f64, f64),
}

/// Relative tolerance of "the same point" and of planarity, against the curve's extent.
const GEOM_TOL: f64 = 1e-10;

impl Spline {
    /// The C² cubic spline through `points` (chord-length knots), natural ends or closed.
    /// Errors name the key (`points[3]: ...`); the caller prefixes the joint.
    pub fn through_points(points: &[Vec3], closed: bool, up: Option<Vec3>) -> Result<Self, String> {
        let n = points.len();
        let need = if closed { 3 } else { 2 };
        if n < need {
            return Err(format!(
                "points: {} spline needs at least {need} points, got {n}",
                if closed { "a closed" } else { "an open" }
            ));
        }
        for (k, p) in points.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(format!("points[{k}]: must be finite, got [{}, {}, {}]", p.x, p.y, p.z));
            }
        }
        let ext = extent(points);
        if ext == 0.0 {
            return Err("points: all points are the same".into());
        }
        for k in 1..n {
            if (points[k] - points[k - 1]).norm() <= GEOM_TOL * ext {
                return Err(format!("points[{k}]: repeats points[{}] (a zero-length segment); remove one", k - 1));
            }
        }
        if closed && (points[n - 1] - points[0]).norm() <= GEOM_TOL * ext {
            return Err(format!(
                "points[{}]: repeats points[0]; a closed spline joins its last point to its first by itself, give each point once",
                n - 1
            ));
        }
        let nseg = if closed { n } else { n - 1 };
        let pt = |k: usize| points[k % n];
        let h: Vec<f64> = (0..nseg).map(|k| (pt(k + 1) - pt(k)).norm()).collect();
        // second derivatives at the knots (per unit chord length)
        let m = if closed { periodic_moments(points, &h) } else { natural_moments(points, &h) };
        let coef = (0..nseg)
            .map(|k| {
                let (p0, p1, m0, m1, hk) = (pt(k), pt(k + 1), m[k % n], m[(k + 1) % n], h[k]);
                let h2 = hk * hk;
                [
                    p0,
                    (p1 - p0) - (m0 * 2.0 + m1) * (h2 / 6.0),
                    m0 * (h2 / 2.0),
                    (m1 - m0) * (h2 / 6.0),
                    Vec3::zeros(),
                    Vec3::zeros(),
                ]
            })
            .collect();
        let plane = plane_of(points, &[]);
        Spline::finish(coef, 3, closed, up, plane, |k| format!("between points[{k}] and points[{}]", (k + 1) % n))
    }

    /// The quintic Hermite spline through samples of a curve r(p): parameter values `p`
    /// (increasing), positions `r`, first and second derivatives `d1 = dr/dp`, `d2 = d²r/dp²`.
    /// `closed`: the last sample repeats the first (a periodic function over one period).
    pub fn hermite(
        p: &[f64],
        r: &[Vec3],
        d1: &[Vec3],
        d2: &[Vec3],
        closed: bool,
        up: Option<Vec3>,
    ) -> Result<Self, String> {
        let n = p.len();
        if n < 2 {
            return Err(format!("parameters: a sampled path needs at least 2 samples, got {n}"));
        }
        for (key, len) in [("points", r.len()), ("tangents", d1.len()), ("second_derivatives", d2.len())] {
            if len != n {
                return Err(format!("{key}: {len} rows for {n} parameter values"));
            }
        }
        for k in 0..n {
            if !p[k].is_finite() {
                return Err(format!("parameters[{k}]: must be finite, got {}", p[k]));
            }
            if k > 0 && !(p[k] > p[k - 1]) {
                return Err(format!("parameters[{k}]: must increase, got {} after {}", p[k], p[k - 1]));
            }
            for (key, v) in [("points", r[k]), ("tangents", d1[k]), ("second_derivatives", d2[k])] {
                if !v.iter().all(|x| x.is_finite()) {
                    return Err(format!("{key}[{k}]: must be finite, got [{}, {}, {}]", v.x, v.y, v.z));
                }
            }
        }
        let ext = extent(r);
        if ext == 0.0 {
            return Err("points: the curve does not move (all samples at one point)".into());
        }
        if closed {
            let (gap, dt) = ((r[n - 1] - r[0]).norm(), (d1[n - 1] - d1[0]).norm());
            if gap > 1e-9 * ext || dt > 1e-6 * d1[0].norm().max(1e-300) {
                return Err(format!(
                    "closed: the curve must end where it starts with the same derivative (a periodic function over one period); \
                     the end is {gap:.3e} m from the start, its derivative differs by {dt:.3e}"
                ));
            }
        }
        let coef = (0..n - 1)
            .map(|k| {
                let hk = p[k + 1] - p[k];
                let (c0, c1, c2) = (r[k], d1[k] * hk, d2[k] * (hk * hk / 2.0));
                let a = r[k + 1] - (c0 + c1 + c2);
                let b = d1[k + 1] * hk - (c1 + c2 * 2.0);
                let c = d2[k + 1] * (hk * hk) - c2 * 2.0;
                [c0, c1, c2, a * 10.0 - b * 4.0 + c * 0.5, a * -15.0 + b * 7.0 - c, a * 6.0 - b * 3.0 + c * 0.5]
            })
            .collect();
        let plane = plane_of(r, &[d1, d2]);
        Spline::finish(coef, 5, closed, up, plane, |k| format!("between parameters {} and {}", p[k], p[k + 1]))
    }

    /// Arc-length tables, the checks on the parameterization, the frame's reference direction.
    fn finish(
        coef: Vec<[Vec3; 6]>,
        degree: usize,
        closed: bool,
        up: Option<Vec3>,
        plane: Option<Vec3>,
        where_: impl Fn(usize) -> String,
    ) -> Result<Self, String> {
        let mut sp = Spline {
            coef,
            degree,
            table: vec![],
            start: vec![],
            s_seg: vec![],
            closed,
            up: Vec3::z(),
            plane: None,
            up_clearance: (1.0, 0.0),
        };
        let rule = gl8();
        let mut s = 0.0;
        for k in 0..sp.coef.len() {
            let total = |m: usize| -> f64 {
                (0..m)
                    .map(|j| integrate(rule, j as f64 / m as f64, (j + 1) as f64 / m as f64, |x| sp.speed(k, x)))
                    .sum()
            };
            let mut m = 1;
            let (mut l_m, mut l_2m) = (total(1), total(2));
            while (l_2m - l_m).abs() > 1e-13 * l_2m && m < 1024 {
                m *= 2;
                l_m = l_2m;
                l_2m = total(2 * m);
            }
            let m = 2 * m;
            // no cusp: the speed must stay well away from zero (the re-parameterization divides by it)
            let mut slowest = f64::INFINITY;
            for j in 0..=8 * m {
                slowest = slowest.min(sp.speed(k, j as f64 / (8 * m) as f64));
            }
            if !(slowest > 1e-6 * l_2m) {
                return Err(format!(
                    "the curve's parameterization is singular {} (its speed nearly vanishes: a cusp); {}",
                    where_(k),
                    if degree == 3 {
                        "space the points more evenly"
                    } else {
                        "give a regular function (r'(p) never zero)"
                    }
                ));
            }
            sp.start.push(sp.table.len());
            sp.s_seg.push(s);
            sp.table.push(s);
            for j in 0..m {
                s += integrate(rule, j as f64 / m as f64, (j + 1) as f64 / m as f64, |x| sp.speed(k, x));
                sp.table.push(s);
            }
        }
        sp.start.push(sp.table.len());
        sp.s_seg.push(s);

        // the frame's reference direction: given; else the plane's normal; else the direction the
        // tangent runs along least (smallest eigenvalue of ∫ t tᵀ ds); a straight line: the
        // world axis most across it
        let mut scatter = Matrix3::zeros();
        sp.each_sample(|_, t, w| scatter += t * t.transpose() * w);
        let eig = SymmetricEigen::new(scatter);
        let mut order = [0, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let total = sp.length();
        let straight = eig.eigenvalues[order[1]] <= 1e-12 * total;
        let up = match up {
            Some(u) => {
                if !(u.iter().all(|x| x.is_finite()) && u.norm() > 0.0) {
                    return Err(format!("up: must be a nonzero direction, got [{}, {}, {}]", u.x, u.y, u.z));
                }
                u.normalize()
            }
            None => {
                let d = if straight {
                    across(&sp.point_and_tangent(0.0).1, None)
                } else if let Some(nrm) = plane {
                    nrm
                } else {
                    eig.eigenvectors.column(order[0]).into_owned()
                };
                positive(d)
            }
        };
        sp.up = up;
        sp.plane = if straight {
            // a line lies in every plane through it: the one across `up`
            Some(across(&sp.point_and_tangent(0.0).1, Some(&up)))
        } else {
            plane.map(|nrm| if nrm.dot(&up) < 0.0 { -nrm } else { nrm })
        };
        let mut clear = (f64::INFINITY, 0.0);
        sp.each_sample(|s, t, _| {
            let c = t.cross(&up).norm();
            if c < clear.0 {
                clear = (c, s);
            }
        });
        sp.up_clearance = clear;
        Ok(sp)
    }

    /// Total arc length L (m).
    pub fn length(&self) -> f64 {
        *self.s_seg.last().unwrap_or(&0.0)
    }
    /// Whether the curve is closed.
    pub fn closed(&self) -> bool {
        self.closed
    }
    /// Number of polynomial segments.
    pub fn segments(&self) -> usize {
        self.coef.len()
    }
    /// Arc length at the segment ends (the knots: the points, or the samples), from 0 to L.
    pub fn knots(&self) -> &[f64] {
        &self.s_seg
    }
    /// "spline" (cubic through points) or "hermite" (quintic through samples).
    pub fn kind_name(&self) -> &'static str {
        if self.degree == 3 {
            "spline"
        } else {
            "hermite"
        }
    }

    /// |P_k'(τ)|.
    #[inline]
    fn speed(&self, k: usize, tau: f64) -> f64 {
        self.deriv(k, tau).norm()
    }
    /// P_k(τ).
    #[inline]
    fn value(&self, k: usize, tau: f64) -> Vec3 {
        let c = &self.coef[k];
        let mut acc = c[self.degree];
        for j in (0..self.degree).rev() {
            acc = acc * tau + c[j];
        }
        acc
    }
    /// P_k'(τ).
    #[inline]
    fn deriv(&self, k: usize, tau: f64) -> Vec3 {
        let c = &self.coef[k];
        let mut acc = c[self.degree] * self.degree as f64;
        for j in (1..self.degree).rev() {
            acc = acc * tau + c[j] * j as f64;
        }
        acc
    }
    /// P_k (or P_k' with `derivative`) on a series τ(δ), by Horner's rule.
    #[inline]
    fn poly_jet<const N: usize>(&self, k: usize, tau: &Jet<N>, derivative: bool) -> JVec<N> {
        let c = &self.coef[k];
        let coef = |j: usize| if derivative { c[j] * j as f64 } else { c[j] };
        let mut acc = JVec::constant(&coef(self.degree));
        for j in (usize::from(derivative)..self.degree).rev() {
            acc = acc.scale(tau).add(&JVec::constant(&coef(j)));
        }
        acc
    }

    /// Calls `f(s, t, weight)` at Gauss points along the curve (weights: arc length).
    fn each_sample(&self, mut f: impl FnMut(f64, Vec3, f64)) {
        let rule = gl8();
        for k in 0..self.coef.len() {
            let tab = &self.table[self.start[k]..self.start[k + 1]];
            let m = tab.len() - 1;
            for j in 0..m {
                let (a, b) = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
                for i in 0..8 {
                    let tau = 0.5 * (a + b) + 0.5 * (b - a) * rule.0[i];
                    let d = self.deriv(k, tau);
                    let sp = d.norm();
                    // arc length at the node, to first order (for messages only)
                    let s = tab[j] + (tab[j + 1] - tab[j]) * (tau - a) / (b - a);
                    f(s, d / sp, rule.1[i] * 0.5 * (b - a) * sp);
                }
            }
        }
    }

    /// Segment and local parameter of arc length `s` in [0, L].
    fn locate(&self, s: f64) -> (usize, f64) {
        let nseg = self.coef.len();
        let k = self.s_seg[..nseg].partition_point(|&x| x <= s).saturating_sub(1).min(nseg - 1);
        let tab = &self.table[self.start[k]..self.start[k + 1]];
        let m = tab.len() - 1;
        let j = tab.partition_point(|&x| x <= s).saturating_sub(1).min(m - 1);
        let (t0, t1) = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
        let (target, len) = (s - tab[j], tab[j + 1] - tab[j]);
        let mut tau = t0 + (t1 - t0) * (target / len).clamp(0.0, 1.0);
        let rule = gl8();
        for _ in 0..20 {
            let l = integrate(rule, t0, tau, |x| self.speed(k, x));
            let step = (l - target) / self.speed(k, tau);
            let next = (tau - step).clamp(t0, t1);
            let done = (next - tau).abs() <= 1e-15;
            tau = next;
            if done {
                break;
            }
        }
        (k, tau)
    }

    /// Position and unit tangent at arc length s in [0, L] (no extrapolation).
    fn point_and_tangent(&self, s: f64) -> (Vec3, Vec3) {
        let (k, tau) = self.locate(s.clamp(0.0, self.length()));
        (self.value(k, tau), self.deriv(k, tau).normalize())
    }

    /// Position as a series in δ = s − s₀ (extrapolated straight beyond an open spline's ends,
    /// wrapped for a closed one).
    pub(super) fn r_jet<const N: usize>(&self, s0: f64) -> JVec<N> {
        let total = self.length();
        let s = if self.closed {
            let w = s0.rem_euclid(total);
            if w >= total {
                0.0
            } else {
                w
            }
        } else {
            s0
        };
        if !self.closed && !(0.0..=total).contains(&s) {
            // straight on along the end tangent (s NaN: the start, so nothing downstream is NaN
            // but the caller's own NaN state)
            let (end, ds) = if s > total { (total, s - total) } else { (0.0, if s.is_nan() { 0.0 } else { s }) };
            let (r, t) = self.point_and_tangent(end);
            let mut out = JVec::constant(&(r + t * ds));
            if N > 1 {
                for c in 0..3 {
                    out.0[c].0[1] = t[c];
                }
            }
            return out;
        }
        let (k, tau0) = self.locate(s);
        // dτ/ds = 1/|P'(τ)|: each pass makes the series of τ right to one more order
        let mut tau = Jet::<N>::constant(tau0);
        for _ in 1..N {
            let d = self.poly_jet(k, &tau, true);
            tau = d.dot(&d).sqrt().recip().integral(tau0);
        }
        self.poly_jet(k, &tau, false)
    }
}

/// Diagonal of the bounding box.
fn extent(points: &[Vec3]) -> f64 {
    let (mut lo, mut hi) = (points[0], points[0]);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (hi - lo).norm()
}

/// A unit vector across the unit `line`: the part of `up` across it, or (no `up`, or one along
/// the line) the world axis most across it, made perpendicular.
fn across(line: &Vec3, up: Option<&Vec3>) -> Vec3 {
    if let Some(u) = up {
        let p = u - line * line.dot(u);
        if p.norm() > 1e-6 {
            return p.normalize();
        }
    }
    let k = line.iamin();
    let mut e = Vec3::zeros();
    e[k] = 1.0;
    positive((e - line * line[k]).normalize())
}

/// The sign making a direction's largest component positive.
fn positive(d: Vec3) -> Vec3 {
    if d[d.iamax()] < 0.0 {
        -d
    } else {
        d
    }
}

/// The unit normal of the plane through `points` (best fit) if all points lie in it and all
/// `directions` along it, to 1e-10 of the extent; None for a space curve (or a straight line,
/// whose plane is not unique).
fn plane_of(points: &[Vec3], directions: &[&[Vec3]]) -> Option<Vec3> {
    let n = points.len() as f64;
    let c = points.iter().fold(Vec3::zeros(), |a, p| a + p) / n;
    let cov = points.iter().fold(Matrix3::zeros(), |a, p| a + (p - c) * (p - c).transpose());
    let eig = SymmetricEigen::new(cov);
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let ext = extent(points);
    let nrm = eig.eigenvectors.column(order[0]).into_owned();
    if eig.eigenvalues[order[1]].max(0.0).sqrt() <= GEOM_TOL * ext {
        return None; // collinear: handled as a straight line
    }
    let flat = points.iter().all(|p| (p - c).dot(&nrm).abs() <= GEOM_TOL * ext)
        && directions.iter().all(|ds| ds.iter().all(|d| d.dot(&nrm).abs() <= GEOM_TOL * d.norm()));
    flat.then(|| positive(nrm))
}

/// Second derivatives of the natural cubic spline (zero at both ends), per knot.
fn natural_moments(p: &[Vec3], h: &[f64]) -> Vec<Vec3> {
    let n = p.len();
    let mut m = vec![Vec3::zeros(); n];
    if n < 3 {
        return m;
    }
    // Thomas algorithm on the interior knots 1..n-1
    let k_in = n - 2;
    let mut diag = vec![0.0; k_in];
    let mut rhs = vec![Vec3::zeros(); k_in];
    for i in 0..k_in {
        let k = i + 1;
        diag[i] = 2.0 * (h[k - 1] + h[k]);
        rhs[i] = ((p[k + 1] - p[k]) / h[k] - (p[k] - p[k - 1]) / h[k - 1]) * 6.0;
    }
    for i in 1..k_in {
        let w = h[i] / diag[i - 1]; // sub-diagonal h[k-1] with k = i + 1
        diag[i] -= w * h[i];
        let r = rhs[i - 1];
        rhs[i] -= r * w;
    }
    for i in (0..k_in).rev() {
        let next = if i + 1 < k_in { m[i + 2] * h[i + 1] } else { Vec3::zeros() };
        m[i + 1] = (rhs[i] - next) / diag[i];
    }
    m
}

/// Second derivatives of the periodic cubic spline (n knots, n segments, knot n = knot 0).
fn periodic_moments(p: &[Vec3], h: &[f64]) -> Vec<Vec3> {
    let n = p.len();
    let pt = |k: usize| p[k % n];
    // row k: h[k-1] M[k-1] + 2 (h[k-1] + h[k]) M[k] + h[k] M[k+1] = rhs[k], indices mod n
    let hm = |k: usize| h[(k + n - 1) % n];
    let rhs: Vec<Vec3> = (0..n).map(|k| ((pt(k + 1) - pt(k)) / h[k] - (pt(k) - pt(k + n - 1)) / hm(k)) * 6.0).collect();
    let sub: Vec<f64> = (0..n).map(hm).collect(); // coefficient of M[k-1]
    let sup: Vec<f64> = (0..n).map(|k| h[k]).collect(); // coefficient of M[k+1]
    let mut diag: Vec<f64> = (0..n).map(|k| 2.0 * (hm(k) + h[k])).collect();
    // Sherman–Morrison: A = T + u vᵀ with the corners A[0][n-1] = sub[0] = β, A[n-1][0] = sup[n-1] = α
    let (alpha, beta) = (sup[n - 1], sub[0]);
    let gamma = -diag[0];
    diag[0] -= gamma;
    diag[n - 1] -= alpha * beta / gamma;
    let solve = |rhs: &[Vec3]| -> Vec<Vec3> {
        // tridiagonal T (sub[1..], diag, sup[..n-1])
        let mut d = diag.clone();
        let mut r = rhs.to_vec();
        for i in 1..n {
            let w = sub[i] / d[i - 1];
            d[i] -= w * sup[i - 1];
            let prev = r[i - 1];
            r[i] -= prev * w;
        }
        let mut x = vec![Vec3::zeros(); n];
        x[n - 1] = r[n - 1] / d[n - 1];
        for i in (0..n - 1).rev() {
            x[i] = (r[i] - x[i + 1] * sup[i]) / d[i];
        }
        x
    };
    let x = solve(&rhs);
    let mut u = vec![Vec3::zeros(); n];
    u[0] = Vec3::repeat(gamma);
    u[n - 1] = Vec3::repeat(alpha);
    let z = solve(&u); // the same scalar system in every component
    let (v0, vn) = (1.0, beta / gamma);
    (0..n)
        .map(|k| {
            let f = (x[0] * v0 + x[n - 1] * vn).component_div(&(Vec3::repeat(1.0) + z[0] * v0 + z[n - 1] * vn));
            x[k] - z[k].component_mul(&f)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn helix_points(n_per_turn: usize, turns: f64, r: f64, c: f64) -> Vec<Vec3> {
        let n = (n_per_turn as f64 * turns).round() as usize;
        (0..=n)
            .map(|k| {
                let phi = std::f64::consts::TAU * k as f64 / n_per_turn as f64;
                Vec3::new(r * phi.cos(), r * phi.sin(), c * phi)
            })
            .collect()
    }

    #[test]
    fn the_spline_interpolates_its_points_with_continuous_second_derivatives() {
        let pts = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.5, 0.0),
            Vec3::new(2.0, 0.0, 0.3),
            Vec3::new(2.5, -1.0, 0.2),
            Vec3::new(4.0, -0.5, 0.0),
        ];
        for closed in [false, true] {
            let sp = Spline::through_points(&pts, closed, None).unwrap();
            let nseg = sp.segments();
            assert_eq!(nseg, if closed { 5 } else { 4 });
            for k in 0..nseg {
                assert!((sp.value(k, 0.0) - pts[k]).norm() < 1e-15);
                assert!((sp.value(k, 1.0) - pts[(k + 1) % 5]).norm() < 1e-14);
                if k + 1 < nseg || closed {
                    let k1 = (k + 1) % nseg;
                    // C¹ and C² in the chord-length parameter x = h τ
                    let (h0, h1) = ((pts[(k + 1) % 5] - pts[k]).norm(), (pts[(k + 2) % 5] - pts[(k + 1) % 5]).norm());
                    assert!((sp.deriv(k, 1.0) / h0 - sp.deriv(k1, 0.0) / h1).norm() < 1e-13);
                    let dd = |k: usize, t: f64| {
                        let c = &sp.coef[k];
                        c[2] * 2.0 + c[3] * (6.0 * t)
                    };
                    assert!((dd(k, 1.0) / (h0 * h0) - dd(k1, 0.0) / (h1 * h1)).norm() < 1e-12);
                }
            }
            if !closed {
                // natural ends
                assert!(sp.coef[0][2].norm() < 1e-15);
                let c = &sp.coef[3];
                assert!((c[2] * 2.0 + c[3] * 6.0).norm() < 1e-13);
            }
        }
    }

    #[test]
    fn arc_length_is_the_parameter() {
        let sp = Spline::through_points(&helix_points(12, 1.5, 0.4, 0.05), false, None).unwrap();
        let total = sp.length();
        // |dr/ds| = 1 and the length of the chord of a short arc
        for s in [0.0, 0.1, 0.77, total * 0.5, total - 1e-9, total] {
            let r = sp.r_jet::<4>(s);
            assert!((r.derivative(1).norm() - 1.0).abs() < 1e-13, "s = {s}");
        }
        // the arc length of a segment by an independent fine quadrature (Simpson on 20000 pieces)
        let k = 5;
        let n = 20000;
        let simpson: f64 = (0..n)
            .map(|i| {
                let (a, b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                (b - a) / 6.0 * (sp.speed(k, a) + 4.0 * sp.speed(k, 0.5 * (a + b)) + sp.speed(k, b))
            })
            .sum();
        assert!((sp.s_seg[k + 1] - sp.s_seg[k] - simpson).abs() < 1e-13);
        // locating s inverts the table
        for s in [0.003, 0.4, 1.1, total * 0.9] {
            let (k, tau) = sp.locate(s);
            let l = integrate(gl8(), 0.0, tau, |x| sp.speed(k, x));
            let l2 = integrate(gl8(), 0.0, 0.5 * tau, |x| sp.speed(k, x))
                + integrate(gl8(), 0.5 * tau, tau, |x| sp.speed(k, x));
            assert!((sp.s_seg[k] + l - s).abs() < 1e-14 && (l - l2).abs() < 1e-14, "s = {s}");
        }
    }

    #[test]
    fn bad_points_are_refused_with_the_key() {
        let p = |v: &[[f64; 3]]| v.iter().map(|a| Vec3::new(a[0], a[1], a[2])).collect::<Vec<_>>();
        let e = Spline::through_points(&p(&[[0.0, 0.0, 0.0]]), false, None).unwrap_err();
        assert!(e.contains("at least 2 points, got 1"), "{e}");
        let e = Spline::through_points(&p(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), true, None).unwrap_err();
        assert!(e.contains("closed spline needs at least 3 points"), "{e}");
        let e =
            Spline::through_points(&p(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), false, None).unwrap_err();
        assert!(e.starts_with("points[2]: repeats points[1]"), "{e}");
        let e = Spline::through_points(&p(&[[0.0, 0.0, 0.0], [1.0, f64::NAN, 0.0]]), false, None).unwrap_err();
        assert!(e.starts_with("points[1]: must be finite"), "{e}");
        let e = Spline::through_points(
            &p(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]]),
            true,
            None,
        )
        .unwrap_err();
        assert!(e.starts_with("points[3]: repeats points[0]; a closed spline"), "{e}");
        let e =
            Spline::through_points(&p(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), false, Some(Vec3::zeros())).unwrap_err();
        assert!(e.starts_with("up: must be a nonzero direction"), "{e}");
    }
}
