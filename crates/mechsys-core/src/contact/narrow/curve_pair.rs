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
//! **Warm start.** Given the state of the last evaluation ([`SearchHint`]), each search first
//! tries Newton from the previous roots when the relative motion since the last full search is
//! provably too small to change them (see [`super::warm`]); it records its basins and margin
//! when it searches in full.
//!
//! **Several points.** With `count > 1` the `count` deepest roots are kept, ordered by their
//! parameter on the curve (so a candidate keeps its index while its root persists); slots
//! without a root are *unused* candidates whose gap exceeds any real one. Gear pairs, whose
//! roots come and go with every tooth change, give each root the slot of its flank side and
//! tooth colour instead (`GearSlots`).

use crate::geometry::curve::{
    cross, Bracket, Chunk, Curve, Jet2, Vec2, CHUNK, CONVERGED, MAX_SAMPLES, NEWTON_ITERATIONS,
};
use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

use super::warm::{in_window, Basins, SearchHint};
use super::{vel, Raw};

/// Most candidates per curve pair (a stack buffer holds them).
pub const MAX_POINTS: usize = 8;
/// Roots kept during one search.
const MAX_ROOTS: usize = 16;

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
    /// Warm starts: the window of the searched parameter and the key at the cold search.
    window: [f64; 2],
    cold_key: f64,
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

/// How a gear pair's roots are given candidate slots: `2 × colours` slots, the root's flank side
/// (the lower or upper flank of a tooth of the colouring gear) and the colour of that tooth,
/// `k mod colours`. A root keeps its slot while it persists, so each tooth flank in mesh stays
/// the same candidate through the tooth changes (a slot holds its deepest root; roots that
/// share a slot are teeth `colours` apart, never in contact together while the contact ratio is
/// below `colours`). With one colour the slots are the drive and the coast side: every pair in
/// involute action on one side has the same gap and line of action, so the closest pair of each
/// side is the contact that side needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GearSlots {
    colours: usize,
    /// Colour the teeth of the pair's second gear (the first has `z mod colours = 1`).
    second: bool,
}

impl GearSlots {
    fn slot(&self, c1: &Curve, c2: &Curve, r: &Root) -> usize {
        let (gear, s) = if self.second { (c2.as_gear(), r.s2) } else { (c1.as_gear(), r.s1) };
        let (k, upper) = gear.expect("a gear pair").tooth_at(s);
        2 * (k % self.colours) + upper as usize
    }
}

/// The slots of a gear–gear pair with `count` candidates (`None`: not a gear pair, or one
/// candidate); an error for an odd count or when neither gear's teeth can be coloured with
/// `count / 2` colours so that neighbouring teeth differ (`z mod colours = 1` for both).
pub(crate) fn gear_slots(c1: &Curve, c2: &Curve, count: usize) -> Option<Result<GearSlots, String>> {
    let (g1, g2) = (c1.as_gear()?, c2.as_gear()?);
    if count < 2 {
        return None;
    }
    if count % 2 == 1 {
        return Some(Err(format!(
            "a gear pair takes an even number of points (one per flank side and tooth colour: 2, 4, 6 or 8), got {count}"
        )));
    }
    let colours = count / 2;
    let proper = |z: usize| colours == 1 || z % colours != 1;
    Some(if proper(g1.teeth()) {
        Ok(GearSlots { colours, second: false })
    } else if proper(g2.teeth()) {
        Ok(GearSlots { colours, second: true })
    } else {
        Err(format!(
            "with {count} points the gear pair's teeth ({} and {}) cannot be told apart around the gear (both leave 1 over when divided by {colours}); use {} points, or 2 (drive and coast side)",
            g1.teeth(),
            g2.teeth(),
            2 * (colours + 1)
        ))
    })
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
    /// The placement a warm start compares: `[A2ᵀ A1]_xy` (row-major), `[A2ᵀ (r1 - r2)]_xy`.
    fn placement(&self) -> ([f64; 4], [f64; 2]) {
        let b = &self.b;
        ([b[(0, 0)], b[(0, 1)], b[(1, 0)], b[(1, 1)]], [self.c.x, self.c.y])
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
    /// Sets the number of candidates (shared searches only) and the reach of the search when
    /// several points are wanted: a tenth of the smaller bounding radius, or less where a
    /// contour knows the scale of its features (a gear: its module, see [`Curve::reach`]).
    pub(crate) fn set_points(&mut self, points: usize) {
        let scale = |c: &Curve| c.reach().unwrap_or(0.1 * c.bound().1);
        match self {
            CurveGeometry::OnCurve { first, second, count, reach } => {
                *count = points;
                let r1 = match first {
                    First::Curve(c) => scale(c),
                    First::Points { .. } => f64::INFINITY,
                };
                *reach = if points > 1 { r1.min(scale(second)) } else { 0.0 };
            }
            CurveGeometry::OnLine { curve, count, reach, .. } => {
                *count = points;
                *reach = if points > 1 { scale(curve) } else { 0.0 };
            }
        }
    }

    /// A number of points this pair cannot take, with the reason (gear pairs, see [`GearSlots`]).
    pub(crate) fn check_points(&self, points: usize) -> Result<(), String> {
        match self {
            CurveGeometry::OnCurve { first: First::Curve(c1), second, .. } => {
                gear_slots(c1, second, points).unwrap_or(Ok(GearSlots { colours: 1, second: false })).map(|_| ())
            }
            _ => Ok(()),
        }
    }

    /// Whether one search serves all candidates (else each candidate searches alone).
    pub(crate) fn shared(&self) -> bool {
        !matches!(self, CurveGeometry::OnCurve { first: First::Points { centers, .. }, .. } if centers.len() > 1)
    }

    /// Candidate `k` alone (one search per candidate: a polygon's vertices), warm-started from
    /// `hint` (that candidate's) when given.
    pub(crate) fn one(
        &self,
        k: usize,
        x1: &Pose,
        x2: &Pose,
        tw: Option<(&Motion, &Motion)>,
        hint: Option<&mut SearchHint>,
    ) -> Raw {
        let mut out = [Raw::default(); 1];
        match self {
            CurveGeometry::OnCurve { first: First::Points { centers, radius }, second, .. } => {
                let hint = hint.map(std::slice::from_mut);
                point_curve(&centers[k], *radius, second, 1, 0.0, x1, x2, tw, &mut out, hint);
            }
            _ => {
                let mut all = [Raw::default(); MAX_POINTS];
                self.all(x1, x2, tw, &mut all, None);
                return all[k];
            }
        }
        out[0]
    }

    /// All candidates into `out[..count]` (shared search), warm-started from `hints` (one per
    /// candidate, see [`super::warm`]) when given.
    pub(crate) fn all(
        &self,
        x1: &Pose,
        x2: &Pose,
        tw: Option<(&Motion, &Motion)>,
        out: &mut [Raw],
        mut hints: Option<&mut [SearchHint]>,
    ) {
        match self {
            CurveGeometry::OnCurve { first: First::Points { centers, radius }, second, count, reach } => {
                if centers.len() == 1 {
                    point_curve(&centers[0], *radius, second, *count, *reach, x1, x2, tw, out, hints);
                } else {
                    for (k, o) in out.iter_mut().enumerate().take(centers.len()) {
                        *o = self.one(k, x1, x2, tw, hints.as_deref_mut().map(|h| &mut h[k]));
                    }
                }
            }
            CurveGeometry::OnCurve { first: First::Curve(c1), second, count, reach } => {
                curve_curve(c1, second, *count, *reach, x1, x2, tw, out, hints)
            }
            CurveGeometry::OnLine { curve, point, normal, count, reach } => {
                curve_line(curve, point, normal, *count, *reach, x1, x2, tw, out, hints)
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

/// The period of a closed contour's parameter.
fn period(curve: &Curve) -> Option<f64> {
    curve.is_closed().then(|| curve.range().1 - curve.range().0)
}

/// The chunk holding parameter `s` (its sample and the piece of curve up to the next one).
fn chunk_of(curve: &Curve, s: f64) -> &Chunk {
    let s = curve.wrap(s);
    let i = curve.samples().partition_point(|x| x.s <= s).saturating_sub(1);
    let chunks = curve.chunks();
    &chunks[chunks.partition_point(|c| c.first <= i).saturating_sub(1)]
}

/// Newton tolerance on a warm root's key against the bound `cold key + δ` (round-off).
fn key_tolerance(curve: &Curve) -> f64 {
    1e-12 * (1.0 + curve.bound().1)
}

/// Leaves the search's state in `hints` for the next evaluation (see [`super::warm`]): each
/// candidate's root; after a cold search also the margin, the placement and the windows.
/// `bound(g_best, g_worst)` is the lowest key the regions the search pruned (and, with several
/// points, its reach) allow; `param` and `same` name the searched parameter.
#[allow(clippy::too_many_arguments)]
fn leave(
    hints: &mut [SearchHint],
    sel: &[Option<Root>],
    warm: bool,
    basins: Option<&Basins<Root>>,
    searched: &Curve,
    param: impl Fn(&Root) -> f64,
    same: impl Fn(&Root, &Root) -> bool,
    bound: impl Fn(f64, f64) -> f64,
    placement: ([f64; 4], [f64; 2]),
) {
    let mut windows = [[0.0; 2]; MAX_POINTS];
    if warm {
        hints[0].set_warm();
    } else {
        let other = basins.and_then(|b| b.margin(sel, &param, |r| r.key, same, period(searched), &mut windows));
        let keys = sel.iter().flatten().map(|r| r.key);
        let (best, worst) = keys.fold((f64::INFINITY, f64::NEG_INFINITY), |(b, w), k| (b.min(k), w.max(k)));
        let margin = other.map_or(-1.0, |o| o.min(bound(best, worst)) - worst);
        hints[0].set_cold(margin, &placement.0, &placement.1);
    }
    for (k, (h, r)) in hints.iter_mut().zip(sel).enumerate() {
        h.root = r.is_some();
        if let Some(r) = r {
            h.s = [r.s1, r.s2];
            (h.window, h.key) = if warm { (r.window, r.cold_key) } else { (windows[k], r.key) };
        }
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
    hints: Option<&mut [SearchHint]>,
) {
    let rel = Relative::new(x1, x2);
    let y = rel.point3(center);
    let placement = ([0.0; 4], [y.x, y.y]);
    let mut roots = Roots::new(count.max(1));
    // warm: the point moved by δ = |y - y0|; Newton from each previous foot point
    let warm = hints.as_deref().is_some_and(|h| {
        let delta = h[0].moved(&placement.0, &placement.1, &Vec2::zeros(), 0.0);
        h[0].allows(delta)
            && h[..count].iter().all(|h| {
                let Some((s, j)) = h.root.then(|| curve.foot(&y, h.s[1])).flatten() else { return false };
                let key = (y - j[0]).dot(&curve.outward(&j[1])).abs();
                let ok = in_window(s, &h.window, period(curve)) && key <= h.key + delta + key_tolerance(curve);
                let r = Root { s1: 0.0, s2: curve.wrap(s), key, window: h.window, cold_key: h.key };
                roots.push(r, |a, b| same_param(curve, a.s2, b.s2));
                ok
            })
            && roots.len == count
            // with several points the cold search would keep each root's chunk: within its reach
            // of the closest point (the best root, every other region being farther)
            && roots.list[..roots.len].iter().all(|r| {
                let ch = chunk_of(curve, r.s2);
                (y - ch.center).norm() - ch.radius <= roots.list[0].key + reach
            })
    });
    // (recorded for a later warm start only: a few kB to clear)
    let mut basins = (hints.is_some() && !warm).then(Basins::new);
    let mut ub = 0.0;
    if !warm {
        roots = Roots::new(count.max(1));
        // a band of a tenth of the curve's size beyond the pruning: the margin's reach
        ub = foot_points(curve, &y, reach, &mut roots, basins.as_mut(), 0.1 * curve.bound().1);
    }
    let o2 = curve.offset();
    let c2d = Vec2::new(center.x, center.y);
    let mut sel = [None; MAX_POINTS];
    fill(
        &mut roots,
        count,
        |r| r.s2,
        |k, root| {
            sel[k] = root.copied();
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
        },
    );
    if let Some(h) = hints {
        // the chunks not looked at are farther than that
        let bound = |_, _| ub;
        let same = |a: &Root, b: &Root| same_param(curve, a.s2, b.s2);
        leave(h, &sel[..count], warm, basins.as_ref(), curve, |r| r.s2, same, bound, placement);
    }
}

/// Calls `at_min(i)` for every local minimum of the sampled `value(i)` over the samples of the
/// chunks that `keep` admits (a closed curve wraps; beyond an open curve's ends counts as higher);
/// returns the smallest sampled value and its sample (`∞` if no chunk is kept).
fn sampled_minima(
    curve: &Curve,
    keep: impl Fn(&Chunk) -> bool,
    value: impl Fn(usize) -> f64,
    mut at_min: impl FnMut(usize),
) -> (f64, usize) {
    let n = curve.samples().len();
    let closed = curve.is_closed();
    let mut best = (f64::INFINITY, 0usize);
    for ch in curve.chunks().iter().filter(|c| keep(c)) {
        for i in ch.first..ch.first + ch.count {
            let vi = value(i);
            if vi < best.0 {
                best = (vi, i);
            }
            let prev = if i > 0 {
                value(i - 1)
            } else if closed {
                value(n - 1)
            } else {
                f64::INFINITY
            };
            let next = if i + 1 < n {
                value(i + 1)
            } else if closed {
                value(0)
            } else {
                f64::INFINITY
            };
            if vi <= prev && vi <= next {
                at_min(i);
            }
        }
    }
    best
}

/// Local minima of the distance from `y` to the curve's samples, refined to foot points; returns
/// the bound of the regions the search did not look at. Recording for a warm start (`basins`),
/// it also looks `band` further, at competitors only (their minima go to `basins`, never to
/// `roots`: the roots are those of the plain search), so that the margin is not limited by the
/// pruning's upper bound.
fn foot_points(
    curve: &Curve,
    y: &Vec2,
    reach: f64,
    roots: &mut Roots,
    mut basins: Option<&mut Basins<Root>>,
    band: f64,
) -> f64 {
    let (samples, chunks) = (curve.samples(), curve.chunks());
    let ub = chunks.iter().map(|c| (y - c.center).norm() + c.radius).fold(f64::INFINITY, f64::min);
    let band = if basins.is_some() { band } else { 0.0 };
    let below = |ch: &Chunk| (y - ch.center).norm() - ch.radius;
    let best = sampled_minima(
        curve,
        |ch| below(ch) <= ub + reach + band,
        |i| (y - samples[i].r).norm(),
        |i| {
            let searched = chunks.get(i / CHUNK).is_some_and(|ch| below(ch) <= ub + reach);
            let root = curve.foot(y, samples[i].s).map(|(s, j)| {
                let key = (y - j[0]).dot(&curve.outward(&j[1])).abs();
                Root { s2: curve.wrap(s), key, ..Default::default() }
            });
            if let (Some(r), true) = (root, searched) {
                roots.push(r, |a, b| same_param(curve, a.s2, b.s2));
            }
            if let Some(b) = basins.as_deref_mut() {
                b.push(samples[i].s, root);
            }
        },
    );
    if roots.len == 0 && best.0.is_finite() {
        roots.push(Root { s2: samples[best.1].s, key: best.0, ..Default::default() }, |_, _| false);
    }
    ub + reach + band
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
    hints: Option<&mut [SearchHint]>,
) {
    let rel = Relative::new(x1, x2);
    let (samples, chunks) = (curve.samples(), curve.chunks());
    let height = |i: usize| m.dot(&rel.point(&samples[i].r));
    let mut roots = Roots::new(count.max(1));
    let jet = |s: f64| {
        let j = curve.eval(s);
        (rel.point(&j[0]), rel.dir(&j[1]), rel.dir(&j[2]), j)
    };
    // Newton on m·ρ1'(s) = 0 towards the minimum of the height from `s`: the root (unwrapped)
    // and its key, if it converges to a minimum
    let newton = |mut s: f64| -> Option<(f64, f64)> {
        let cap = 2.0 * curve.step();
        for _ in 0..NEWTON_ITERATIONS {
            let (_, r1, r2, _) = jet(s);
            let (f, fs) = (m.dot(&r1), m.dot(&r2));
            let ds = if fs > 0.0 { (-f / fs).clamp(-cap, cap) } else { -f.signum() * cap };
            s += ds;
            if ds.abs() <= CONVERGED * curve.step() {
                let (rho, _, rho2, _) = jet(s);
                return (m.dot(&rho2) > 0.0).then(|| (s, m.dot(&(rho - point))));
            }
        }
        None
    };
    let same = |a: &Root, b: &Root| same_param(curve, a.s1, b.s1);
    let placement = rel.placement();
    // warm: every point of the curve moved by at most δ (its bounding circle)
    let warm = hints.as_deref().is_some_and(|h| {
        let (c, r) = curve.bound();
        let delta = h[0].moved(&placement.0, &placement.1, &c, r);
        h[0].allows(delta)
            && h[..count].iter().all(|h| {
                let Some((s, key)) = h.root.then(|| newton(h.s[0])).flatten() else { return false };
                let ok = in_window(s, &h.window, period(curve)) && key <= h.key + delta + key_tolerance(curve);
                roots.push(Root { s1: curve.wrap(s), key, window: h.window, cold_key: h.key, ..Default::default() }, same);
                ok
            })
            && roots.len == count
            // with several points: each root's chunk within the reach of the lowest point
            && roots.list[..roots.len].iter().all(|r| {
                let ch = chunk_of(curve, r.s1);
                m.dot(&(rel.point(&ch.center) - point)) - ch.radius <= roots.list[0].key + reach
            })
    });
    let mut basins = (hints.is_some() && !warm).then(Basins::new);
    let mut ub = 0.0;
    if !warm {
        roots = Roots::new(count.max(1));
        ub = chunks.iter().map(|c| m.dot(&rel.point(&c.center)) + c.radius).fold(f64::INFINITY, f64::min);
        let best = sampled_minima(
            curve,
            |ch| m.dot(&rel.point(&ch.center)) - ch.radius <= ub + reach,
            height,
            |i| {
                let root = newton(samples[i].s).map(|(s, key)| Root { s1: curve.wrap(s), key, ..Default::default() });
                if let Some(r) = root {
                    roots.push(r, same);
                }
                if let Some(b) = basins.as_mut() {
                    b.push(samples[i].s, root);
                }
            },
        );
        if roots.len == 0 && best.0.is_finite() {
            roots.push(Root { s1: samples[best.1].s, key: best.0, ..Default::default() }, |_, _| false);
        }
    }
    let o1 = curve.offset();
    let mut sel = [None; MAX_POINTS];
    fill(
        &mut roots,
        count,
        |r| r.s1,
        |k, root| {
            sel[k] = root.copied();
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
        },
    );
    if let Some(h) = hints {
        // pruned chunks are higher than ub + reach (keys: heights over the line's point)
        let bound = |_, _| ub + reach - m.dot(point);
        leave(h, &sel[..count], warm, basins.as_ref(), curve, |r| r.s1, same, bound, placement);
    }
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
    hints: Option<&mut [SearchHint]>,
) {
    let rel = Relative::new(x1, x2);
    let handed = rel.handed();
    let map1 = |j1: &Jet2| [rel.point(&j1[0]), rel.dir(&j1[1]), rel.dir(&j1[2]), rel.dir(&j1[3])];
    let jet1 = |a: f64| map1(&c1.eval(a));
    let jets = |a: f64, b: f64| {
        let j1 = c1.eval(a);
        (map1(&j1), j1, c2.eval(b))
    };
    // gear pairs: one candidate per flank side and tooth colour (see `gear_slots`)
    let slots = gear_slots(c1, c2, count).and_then(|r| r.ok());
    let mut roots = Roots::new(if slots.is_some() { MAX_ROOTS } else { count.max(1) });
    let cap1 = 2.0 * c1.step();
    // minimize the signed distance φ(s1) of curve 1's point to curve 2 from (a, b) (the foot
    // point s2 follows s1): φ' = ν2·ρ1' (envelope theorem), φ'' = ν2·ρ1'' + ν2'·ρ1' ds2/ds1;
    // the minimum (unwrapped parameters) if Newton converges to one
    let newton = |mut a: f64, mut b: f64| -> Option<(f64, f64)> {
        let mut bracket = Bracket::new();
        for _ in 0..NEWTON_ITERATIONS {
            let r1 = jet1(a);
            let (foot, j2) = c2.foot(&r1[0], b)?;
            b = foot;
            let d = r1[0] - j2[0];
            let nu2 = c2.outward(&j2[1]);
            let fp = nu2.dot(&r1[1]);
            let foot_s = -j2[1].norm_squared() + d.dot(&j2[2]);
            let db_da = -r1[1].dot(&j2[1]) / foot_s;
            let fpp = nu2.dot(&r1[2]) + normal_rate(&nu2, &j2).dot(&r1[1]) * db_da;
            bracket.update(a, fp);
            let da = if fpp > 0.0 { (-fp / fpp).clamp(-cap1, cap1) } else { -fp.signum() * cap1 };
            let da = bracket.step(a, da, CONVERGED * c1.step()) - a;
            a += da;
            b += db_da * da;
            if da.abs() <= CONVERGED * c1.step() {
                let ok = c2.foot(&jet1(a)[0], b).map(|f| b = f.0).is_some() && fpp > 0.0;
                return ok.then_some((a, b));
            }
        }
        None
    };
    // the root at a minimum (a, b) and whether it is a contact: the mapped curve's outward normal
    // and curvature (a projection when body 1 is tilted; turned over it runs the other way round)
    let assess = |a: f64, b: f64| -> (Root, bool) {
        let (r1, _, j2) = jets(a, b);
        let nu1p = c1.outward(&r1[1]) * handed;
        let nu2 = c2.outward(&j2[1]);
        let g = (r1[0] - j2[0]).dot(&nu2);
        let k1 = c1.curvature_of(&[r1[0], r1[1], r1[2], r1[3]]) * handed;
        let k2 = c2.curvature_of(&j2);
        let root = Root { s1: c1.wrap(a), s2: c2.wrap(b), key: g, ..Default::default() };
        (root, nu1p.dot(&nu2) < 0.0 && k1 + k2 + g * k1 * k2 > 0.0)
    };
    let same = |p: &Root, q: &Root| same_param(c1, p.s1, q.s1) && same_param(c2, p.s2, q.s2);
    let placement = rel.placement();
    // warm: every point of curve 1 moved by at most δ (its bounding circle)
    let warm = hints.as_deref().is_some_and(|h| {
        let (c, r) = c1.bound();
        let delta = h[0].moved(&placement.0, &placement.1, &c, r);
        h[0].allows(delta)
            && h[..count].iter().all(|h| {
                let Some((a, b)) = h.root.then(|| newton(h.s[0], h.s[1])).flatten() else { return false };
                let (root, valid) = assess(a, b);
                let ok = valid && in_window(a, &h.window, period(c1)) && root.key <= h.key + delta + key_tolerance(c1);
                roots.push(Root { window: h.window, cold_key: h.key, ..root }, same);
                ok
            })
            && roots.len == h[..count].len()
            // the cold search keeps every chunk pair within ub + reach, ub at least the closest
            // distance (the best root's when it is positive, every other region being farther;
            // else 0): a root whose chunks' bounding circles are that close is kept
            && {
                let best = roots.list[..roots.len].iter().map(|r| r.key).fold(f64::INFINITY, f64::min).max(0.0);
                roots.list[..roots.len].iter().all(|r| {
                    let (a, b) = (chunk_of(c1, r.s1), chunk_of(c2, r.s2));
                    (rel.point(&a.center) - b.center).norm() - a.radius - b.radius <= best + reach
                })
            }
    });
    let mut basins = (hints.is_some() && !warm).then(Basins::new);
    let mut ub_out = 0.0;
    if !warm {
        roots = Roots::new(if slots.is_some() { MAX_ROOTS } else { count.max(1) });
        let (s1, ch1) = (c1.samples(), c1.chunks());
        let (s2, ch2) = (c2.samples(), c2.chunks());
        let n1 = s1.len();
        // chunk pruning: keep the chunks that may hold a point within the best upper bound (+ reach).
        // Only chunks reaching into the other curve's bounding circle give the upper bound, and only
        // chunks that may come that close to the other's bounding circle are paired (a gear pair
        // meshes over a few of its hundreds of chunks).
        const N: usize = MAX_SAMPLES / CHUNK + 1;
        let mut keep1 = [false; N];
        let mut keep2 = [false; N];
        let mut centers1 = [Vec2::zeros(); N];
        for (a, ca) in ch1.iter().enumerate() {
            centers1[a] = rel.point(&ca.center);
        }
        let (b1c, b1r) = (rel.point(&c1.bound().0), c1.bound().1);
        let (b2c, b2r) = c2.bound();
        let mut list1 = [0u16; N];
        let mut list2 = [0u16; N];
        let near =
            |list: &mut [u16; N], centers: &dyn Fn(usize) -> (Vec2, f64), n: usize, c: &Vec2, r: f64, by: f64| {
                let mut len = 0;
                for a in 0..n {
                    let (ca, ra) = centers(a);
                    if (ca - c).norm_squared() <= (ra + r + by).powi(2) {
                        list[len] = a as u16;
                        len += 1;
                    }
                }
                len
            };
        let chunk1 = |a: usize| (centers1[a], ch1[a].radius);
        let chunk2 = |b: usize| (ch2[b].center, ch2[b].radius);
        let mut n1n = near(&mut list1, &chunk1, ch1.len(), &b2c, b2r, 0.0);
        let mut n2n = near(&mut list2, &chunk2, ch2.len(), &b1c, b1r, 0.0);
        if n1n == 0 || n2n == 0 {
            // the bounding circles are apart: every chunk may give the bound
            (n1n, n2n) = (ch1.len(), ch2.len());
            for (a, l) in list1.iter_mut().enumerate().take(n1n) {
                *l = a as u16;
            }
            for (b, l) in list2.iter_mut().enumerate().take(n2n) {
                *l = b as u16;
            }
        }
        // the chunk pair with the closest bounding circles, and the closest of its samples: every
        // sample lies on its curve, so that distance bounds the curves' distance from above
        let mut closest = (f64::INFINITY, 0usize, 0usize);
        for &a in &list1[..n1n] {
            let (ca, ra) = chunk1(a as usize);
            for &b in &list2[..n2n] {
                let (cb, rb) = chunk2(b as usize);
                let d = (ca - cb).norm() - ra - rb;
                if d < closest.0 {
                    closest = (d, a as usize, b as usize);
                }
            }
        }
        let mut ub = f64::INFINITY;
        let (ka, kb) = (&ch1[closest.1], &ch2[closest.2]);
        for i in ka.first..ka.first + ka.count {
            let p = rel.point(&s1[i].r);
            for jdx in kb.first..kb.first + kb.count {
                ub = ub.min((p - s2[jdx].r).norm_squared());
            }
        }
        let ub_cold = ub.sqrt();
        let ub = ub_cold;
        let n1k = near(&mut list1, &chunk1, ch1.len(), &b2c, b2r, ub + reach);
        let n2k = near(&mut list2, &chunk2, ch2.len(), &b1c, b1r, ub + reach);
        for &a in &list1[..n1k] {
            let (ca, ra) = chunk1(a as usize);
            for &b in &list2[..n2k] {
                let (cb, rb) = chunk2(b as usize);
                if (ca - cb).norm_squared() <= (ub + reach + ra + rb).powi(2) {
                    keep1[a as usize] = true;
                    keep2[b as usize] = true;
                }
            }
        }
        let mut kept2 = [0u16; N];
        let mut n2kept = 0;
        for (b, k) in keep2.iter().enumerate().take(ch2.len()) {
            if *k {
                kept2[n2kept] = b as u16;
                n2kept += 1;
            }
        }
        // signed distance of a kept sample of curve 1 to the kept samples of curve 2 (recomputed for
        // the neighbours instead of stored: no buffers of sample length on the stack; a small cache
        // serves a sample's value to its neighbours)
        // (squared distances; the chunk that held the previous sample's partner is tried first)
        let last = std::cell::Cell::new(0usize);
        let phi_of = |i: usize| -> (f64, usize) {
            if !keep1[i / CHUNK] {
                return (f64::INFINITY, 0);
            }
            let p = rel.point(&s1[i].r);
            let mut best = (f64::INFINITY, 0usize);
            let first = last.get().min(n2kept.saturating_sub(1));
            for k in std::iter::once(first).chain((0..n2kept).filter(|&k| k != first)) {
                let cb = &ch2[kept2[k] as usize];
                let reach = best.0.sqrt() + cb.radius;
                if best.0.is_finite() && (p - cb.center).norm_squared() > reach * reach {
                    continue;
                }
                for jdx in cb.first..cb.first + cb.count {
                    let dd = (p - s2[jdx].r).norm_squared();
                    if dd < best.0 {
                        best = (dd, jdx);
                        last.set(k);
                    }
                }
            }
            let sign = if (p - s2[best.1].r).dot(&s2[best.1].nu) < 0.0 { -1.0 } else { 1.0 };
            (sign * best.0.sqrt(), best.1)
        };
        let cache = std::cell::RefCell::new(([usize::MAX; 4], [(0.0, 0usize); 4], 0usize));
        let phi = |i: usize| -> (f64, usize) {
            let mut c = cache.borrow_mut();
            if let Some(k) = c.0.iter().position(|&j| j == i) {
                return c.1[k];
            }
            let v = phi_of(i);
            let slot = c.2;
            c.0[slot] = i;
            c.1[slot] = v;
            c.2 = (slot + 1) % 4;
            v
        };
        let mut best = (f64::INFINITY, 0usize, 0usize);
        let samples1 = (0..ch1.len()).filter(|&a| keep1[a]).flat_map(|a| ch1[a].first..ch1[a].first + ch1[a].count);
        for i in samples1 {
            let (pi, partner) = phi(i);
            if pi < best.0 {
                best = (pi, i, partner);
            }
            let prev = if i > 0 {
                phi(i - 1).0
            } else if c1.is_closed() {
                phi(n1 - 1).0
            } else {
                f64::INFINITY
            };
            let next = if i + 1 < n1 {
                phi(i + 1).0
            } else if c1.is_closed() {
                phi(0).0
            } else {
                f64::INFINITY
            };
            if !(pi <= prev && pi <= next) {
                continue;
            }
            let root = newton(s1[i].s, s2[partner].s).map(|(a, b)| assess(a, b));
            if let Some((r, true)) = root {
                roots.push(r, same);
            }
            if let Some(b) = basins.as_mut() {
                b.push(s1[i].s, root.map(|r| r.0));
            }
        }
        if roots.len == 0 && best.0.is_finite() {
            roots.push(Root { s1: s1[best.1].s, s2: s2[best.2].s, key: best.0, ..Default::default() }, |_, _| false);
        }
        ub_out = ub_cold;
    }
    let (o1, o2) = (c1.offset(), c2.offset());
    let mut sel = [None; MAX_POINTS];
    let make = |root: Option<&Root>| match root {
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
    match slots {
        Some(slots) => {
            // the deepest root of each slot, in slot order
            let mut best: [Option<Root>; MAX_POINTS] = [None; MAX_POINTS];
            for r in &roots.list[..roots.len] {
                let k = slots.slot(c1, c2, r);
                if k < count && best[k].is_none_or(|b| r.key < b.key) {
                    best[k] = Some(*r);
                }
            }
            for (k, o) in out.iter_mut().enumerate().take(count) {
                *o = make(best[k].as_ref());
            }
            sel = best;
        }
        None => fill(
            &mut roots,
            count,
            |r| r.s1,
            |k, root| {
                sel[k] = root.copied();
                out[k] = make(root)
            },
        ),
    }
    if let Some(h) = hints {
        // pruned chunk pairs are farther apart than ub + reach, and outside each other unless the
        // curves overlap deeper than that (a chunk of curve 1 inside curve 2 is joined to the
        // crossing by points at every smaller depth, kept and above the deepest root)
        let prune = ub_out + reach;
        // gear pairs: whether the cold search finds a root at a flank's end (the tip rounding)
        // depends on its sampling, so its roots through a tooth handover are not a continuous
        // family a warm start could follow; they always search cold
        let gears = c1.as_gear().is_some() || c2.as_gear().is_some();
        let bound = |best: f64, _| if -best < prune && !gears { prune } else { f64::NEG_INFINITY };
        leave(h, &sel[..count], warm, basins.as_ref(), c1, |r| r.s1, same, bound, placement);
    }
}
