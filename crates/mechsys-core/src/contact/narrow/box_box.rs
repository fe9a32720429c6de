//! Box against box: the separating-axis test and a contact manifold of clipped face vertices.
//!
//! Box A is the canonical body 1's, box B body 2's; `d = c_A - c_B` joins their centres. Along a
//! unit axis `u` the two boxes' projections are separated by
//! `s(u) = |d·u| - Σ_k hA_k |a_k·u| - Σ_l hB_l |b_l·u|` (negative: they overlap by `-s`). The 15
//! axes are the six face normals `a_i`, `b_j` and the nine edge directions `a_i × b_j`. For
//! separated boxes the largest `s` is the distance whenever a face or a pair of edges is closest;
//! for overlapping boxes it is the least overlap, the classic choice of the contact normal.
//!
//! **Choice of the axis.** A near tie between two axes must not flip the manifold with rounding
//! errors (two equal boxes stacked face on face tie exactly between `a_z`, `b_z` and the edge axes
//! `a_x × b_y`, `a_y × b_x`). Faces of B win over faces of A unless A's separation exceeds B's by
//! [`TIE`]` · scale` (within it the box with the larger face area is the reference, B when the
//! areas are equal), and an edge axis wins only if it beats the chosen face axis by that
//! tolerance plus 10 % of the face's overlap. Edge axes are skipped when the edges are nearly
//! parallel (`|a_i × b_j| < 1e-6`, no reliable direction) or when the axis lies within ≈ 0.01 rad
//! of a face normal of either box: both edges then lie nearly in that face's plane, which the face
//! manifold covers (two equal boxes turned slightly against each other and pressed together would
//! otherwise pick such an axis by a rounding-sized margin and lose three of their four points).
//!
//! **Face manifold.** On the reference face (outward unit normal `m`, pointing towards the other
//! box, fixed in the reference body) the other box's incident face is the one whose outward
//! normal `f` is most opposed to `m`. Its four corners are clipped against the reference face's
//! four side planes (Sutherland–Hodgman): at most 8 vertices `v`, each on the incident face and
//! labelled with the two planes besides the incident face that define it. Each vertex becomes one
//! candidate (see "Contact points"). Should the incident face miss the reference face's side
//! planes altogether, its corner deepest along `-m` is the one candidate (so overlapping boxes are
//! never left without one). A vertex within [`TIE`]` · scale` of a side plane counts as lying on
//! it (no near-duplicate vertex is made), so equal boxes stacked exactly keep four corner
//! candidates.
//!
//! **Contact points.** The engine's normal rate is `ġ_N = n·(v_1(P1) - v_2(P2))` (eq. 2.110,
//! `w_Nᵀ u`): the rate of the gap between the material points of the two boxes at `P1` and `P2`,
//! held in their bodies. It is the rate of the candidate's own gap exactly when each contact point
//! moves over its contour perpendicular to `n` — the contact conditions of eqs. 2.102–2.103: the
//! normal is the normal of the surface over which the other body's point slides, the same rule as
//! for point contours (a box corner against a plane takes the plane's normal). Each vertex is
//! therefore a point of one box against a face of the other:
//!
//! | vertex (its two defining planes) | point | against | normal, reference box → incident box | `g_N` |
//! | --- | --- | --- | --- | --- |
//! | corner of the incident face (two incident side planes) | that corner | reference face | `m` | `m·(v - p_ref)` |
//! | corner of the reference face (two reference side planes) | that corner `q` | incident face | `-f` | `f·(q - c_f)` |
//! | crossing: an incident edge and a reference side plane | incident box's point at `v` | reference face | `m` | `m·(v - p_ref)` |
//!
//! (`p_ref` the reference face's centre, `c_f` the incident face's.) The other contact point is
//! the point's foot on the face's plane, `g_N` away along the normal; the pair's normal (from B
//! towards A) is the table's when B carries the reference face, reversed when A does. For the two
//! kinds of corners the point is a material point and its foot slides in the face's plane,
//! perpendicular to the normal: `ġ_N = d g_N/dt` exactly, and `w̄_N`, `w̄_T` are the time
//! derivatives of `ġ_N`, `ġ_T` along the motion (eqs. 2.114–2.115). Faces parallel (`f = -m`):
//! all three rows give the same gap and normal. Tilted by `τ` against each other, a reference
//! corner's normal is the incident face's (the direction of the force on a corner pressed on a
//! face) and its gap is `cos τ` times the gap along `m`; its foot lies on the incident face's
//! plane, within `|g_N| sin τ` of the face itself.
//!
//! A crossing is no material point of either box: it moves along the incident edge (direction
//! `e`, rate `ṡ` relative to the incident box) and along the reference face's edge. It is taken
//! as the incident box's material point there, against the reference face: `ġ_N` is exactly the
//! rate of that point's gap (and `w̄_N`, `w̄_T` the exact derivatives of `ġ_N`, `ġ_T` as the engine
//! evaluates them, following the crossing), while the crossing's own gap changes at
//! `d g_N/dt = ġ_N + (m·e) ṡ`. The extra term vanishes when the incident edge lies in the
//! reference face's plane (an edge resting on a face, or faces parallel) and is otherwise of the
//! order of the tilt times the sliding speed along the edge. No face normal removes it: the only
//! direction perpendicular to both sliding directions is the edges' common normal `e × e_ref`,
//! which turns over as the edges become parallel; the edge–edge candidate below uses it when the
//! separating-axis test picks that axis.
//!
//! **Edge–edge.** For the axis `u ∝ a_i × b_j` oriented from B to A, the edge of A parallel to
//! `a_i` farthest along `-u` and the edge of B parallel to `b_j` farthest along `+u`; one
//! candidate between the closest points of their lines (`P1 - P2 = g u`, `g = s(u)`). Both points
//! slide along their edges, perpendicular to `u`: `ġ_N = d g_N/dt` exactly.
//!
//! **Unused candidates.** A pair has [`POINTS`] candidates; those the manifold does not use get the
//! gap `|d| + |hA| + |hB|` (more than the distance between any two points of the boxes, never
//! active) with `P2` at B's centre, `P1 = P2 + g n`; their rates are not meaningful.
//!
//! **Rates.** `Ṗ1`, `Ṗ2`, `ṅ` are the time derivatives of the candidate's points and normal. A
//! corner of the reference face moves with the reference box, the incident face's plane (its
//! normal, the foot) with the incident box. The other vertices are intersections of the incident
//! face's plane with two more planes, each a side plane of the incident face (fixed in the
//! incident box) or of the reference face (fixed in the reference box); a point kept on a plane
//! fixed in box X moves, normal to that plane, with X's material velocity there:
//! `m_k·v̇ = m_k·v_X(v)` for the three planes, solved for `v̇` (for a corner of the incident face,
//! its material velocity); `m` turns with the reference box.
//!
//! **One evaluation per pair.** One separating-axis test and one clipping fill all candidates of
//! a pair: [`super::evaluate`] and [`crate::contact::contact_kinematics`] build the manifold once
//! per call, on the stack (no allocation).

use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

use super::{vel, Raw};

/// Candidate points of a box–box pair (the clipped face polygon has at most 8 vertices).
pub const POINTS: usize = 8;

/// Relative tolerance (times the largest half extent of the pair) of ties between axes and of a
/// vertex lying on a side plane.
pub const TIE: f64 = 1e-9;

/// Edge axes with `|a_i × b_j|` below this are skipped.
const PARALLEL: f64 = 1e-6;

/// Edge axes closer than ≈ 0.01 rad to a face normal are skipped (`cos` of that angle).
const NEAR_FACE: f64 = 1.0 - 5e-5;

/// An edge axis must beat the face axis by this share of the face's overlap, besides the tie.
const EDGE_BIAS: f64 = 0.1;

/// A box in its body's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct BoxShape {
    pub center: Vec3,
    pub rotation: Mat3,
    pub half: Vec3,
}

/// A box placed in the world: centre, axes (columns), half extents.
#[derive(Clone, Copy)]
struct Placed {
    c: Vec3,
    r: Mat3,
    h: Vec3,
}

impl Placed {
    fn new(b: &BoxShape, x: &Pose) -> Self {
        Placed { c: x.point_to_parent(&b.center), r: x.a * b.rotation, h: b.half }
    }
    #[inline]
    fn axis(&self, k: usize) -> Vec3 {
        self.r.column(k).into_owned()
    }
}

/// The feature pair the separating-axis test chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Feature {
    /// A face of B (`ref_a == false`) or of A is the reference; `axis` its normal's index.
    Face { ref_a: bool, axis: usize },
    /// Edges parallel to `a_i` and `b_j`.
    Edge { i: usize, j: usize },
}

/// The separating-axis test: the chosen feature and its separation `s`. Every projection of the
/// 15 axes is a combination of `R_kl = a_k·b_l` and of `d`'s components in either box's axes
/// (the classic form of the test), so the nine edge axes cost a few products each: with `k', k''`
/// the indices after `k` (mod 3), `a_i × b_j` has the components `(−R_i''j, R_i'j)` on
/// `(a_i', a_i'')` and `(R_ij'', −R_ij')` on `(b_j', b_j'')`, and `|a_i × b_j|² = R_i'j² + R_i''j²`.
fn choose(a: &Placed, b: &Placed, scale: f64) -> (Feature, f64) {
    let d = a.c - b.c;
    let tol = TIE * scale;
    let (ax, bx) = ([a.axis(0), a.axis(1), a.axis(2)], [b.axis(0), b.axis(1), b.axis(2)]);
    let r: [[f64; 3]; 3] = std::array::from_fn(|k| std::array::from_fn(|l| ax[k].dot(&bx[l])));
    let (da, db): ([f64; 3], [f64; 3]) =
        (std::array::from_fn(|k| ax[k].dot(&d)), std::array::from_fn(|l| bx[l].dot(&d)));
    // face axes: |d·u| - h - (the other box's radius along u)
    let (mut sa, mut ia) = (f64::NEG_INFINITY, 0);
    for k in 0..3 {
        let s = da[k].abs() - a.h[k] - (b.h[0] * r[k][0].abs() + b.h[1] * r[k][1].abs() + b.h[2] * r[k][2].abs());
        if s > sa {
            (sa, ia) = (s, k);
        }
    }
    let (mut sb, mut jb) = (f64::NEG_INFINITY, 0);
    for l in 0..3 {
        let s = db[l].abs() - b.h[l] - (a.h[0] * r[0][l].abs() + a.h[1] * r[1][l].abs() + a.h[2] * r[2][l].abs());
        if s > sb {
            (sb, jb) = (s, l);
        }
    }
    let ref_a = if (sa - sb).abs() <= tol {
        // a tie: the larger reference face, B's when equal
        let area = |p: &Placed, k: usize| p.h[(k + 1) % 3] * p.h[(k + 2) % 3];
        area(a, ia) > area(b, jb) * (1.0 + 1e-12)
    } else {
        sa > sb
    };
    let (mut feature, s_face) =
        if ref_a { (Feature::Face { ref_a, axis: ia }, sa) } else { (Feature::Face { ref_a, axis: jb }, sb) };
    let mut best_edge = (f64::NEG_INFINITY, 0, 0);
    for i in 0..3 {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        for j in 0..3 {
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            // |a_i × b_j| times the axis' components on a_i', a_i'', b_j', b_j''
            let (ca1, ca2, cb1, cb2) = (r[i2][j].abs(), r[i1][j].abs(), r[i][j2].abs(), r[i][j1].abs());
            let cn = (r[i1][j] * r[i1][j] + r[i2][j] * r[i2][j]).sqrt();
            if cn < PARALLEL {
                continue;
            }
            // an edge axis next to a face normal is that face's contact (the edges lie nearly in it)
            if ca1.max(ca2).max(cb1).max(cb2) > NEAR_FACE * cn {
                continue;
            }
            let dc = da[i2] * r[i1][j] - da[i1] * r[i2][j];
            let s = (dc.abs() - (a.h[i1] * ca1 + a.h[i2] * ca2) - (b.h[j1] * cb1 + b.h[j2] * cb2)) / cn;
            if s > best_edge.0 {
                best_edge = (s, i, j);
            }
        }
    }
    let mut s = s_face;
    if best_edge.0 > s_face + tol + EDGE_BIAS * (-s_face).max(0.0) {
        feature = Feature::Edge { i: best_edge.1, j: best_edge.2 };
        s = best_edge.0;
    }
    (feature, s)
}

/// The separating-axis test axis by axis in world components (the reference for [`choose`]).
#[cfg(test)]
fn choose_direct(a: &Placed, b: &Placed, scale: f64) -> (Feature, f64) {
    let radius = |p: &Placed, u: &Vec3| (0..3).map(|k| p.h[k] * p.axis(k).dot(u).abs()).sum::<f64>();
    let d = a.c - b.c;
    let tol = TIE * scale;
    let face = |p: &Placed, q: &Placed| {
        let mut best = (f64::NEG_INFINITY, 0);
        for k in 0..3 {
            let u = p.axis(k);
            let s = d.dot(&u).abs() - p.h[k] - radius(q, &u);
            if s > best.0 {
                best = (s, k);
            }
        }
        best
    };
    let (sa, ia) = face(a, b);
    let (sb, jb) = face(b, a);
    let ref_a = if (sa - sb).abs() <= tol {
        let area = |p: &Placed, k: usize| p.h[(k + 1) % 3] * p.h[(k + 2) % 3];
        area(a, ia) > area(b, jb) * (1.0 + 1e-12)
    } else {
        sa > sb
    };
    let (mut feature, s_face) =
        if ref_a { (Feature::Face { ref_a, axis: ia }, sa) } else { (Feature::Face { ref_a, axis: jb }, sb) };
    let mut best_edge = (f64::NEG_INFINITY, 0, 0);
    for i in 0..3 {
        for j in 0..3 {
            let c = a.axis(i).cross(&b.axis(j));
            let cn = c.norm();
            if cn < PARALLEL {
                continue;
            }
            let u = c / cn;
            if (0..3).any(|k| a.axis(k).dot(&u).abs() > NEAR_FACE || b.axis(k).dot(&u).abs() > NEAR_FACE) {
                continue;
            }
            let s = d.dot(&u).abs() - radius(a, &u) - radius(b, &u);
            if s > best_edge.0 {
                best_edge = (s, i, j);
            }
        }
    }
    let mut s = s_face;
    if best_edge.0 > s_face + tol + EDGE_BIAS * (-s_face).max(0.0) {
        feature = Feature::Edge { i: best_edge.1, j: best_edge.2 };
        s = best_edge.0;
    }
    (feature, s)
}

/// A plane through a polygon vertex: which body carries it (`true`: the reference box) and its
/// outward normal's axis and sign in that box.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Label {
    on_ref: bool,
    axis: u8,
    positive: bool,
}

/// A vertex of the clipped incident face with the planes it lies on (besides the incident face
/// itself; the first two define it).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Vertex {
    p: Vec3,
    labels: [Label; 4],
    count: u8,
}

impl Vertex {
    fn has(&self, l: &Label) -> bool {
        self.labels[..self.count as usize].contains(l)
    }
    fn add(&mut self, l: Label) {
        if !self.has(&l) && (self.count as usize) < self.labels.len() {
            self.labels[self.count as usize] = l;
            self.count += 1;
        }
    }
}

/// What a candidate of a box–box pair is: which features meet there (module docs, "Contact
/// points").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) enum Kind {
    /// A corner of the incident face against the reference face.
    IncidentCorner,
    /// A corner of the reference face against the incident face.
    ReferenceCorner,
    /// An edge of the incident face crossing a side plane of the reference face.
    Crossing,
    /// The edge–edge point.
    EdgeEdge,
    /// Not used by the manifold.
    Unused,
}

impl Vertex {
    /// The features of a clipped vertex, from the two planes that define it.
    fn kind(&self) -> Kind {
        match (self.labels[0].on_ref, self.labels[1].on_ref) {
            (false, false) => Kind::IncidentCorner,
            (true, true) => Kind::ReferenceCorner,
            _ => Kind::Crossing,
        }
    }
}

/// The clipped incident face of a face contact: vertices, the reference normal `m` (outward of
/// the reference face, fixed in the reference body) and the centre `p_ref` of the reference face;
/// `f` the incident face's outward normal and `fc` its centre.
struct Manifold {
    v: [Vertex; POINTS],
    count: usize,
    m: Vec3,
    p_ref: Vec3,
    f: Vec3,
    fc: Vec3,
}

/// Clips the incident box's face most opposed to the reference face `axis` of `rf`.
fn clip(rf: &Placed, inc: &Placed, axis: usize, scale: f64) -> Manifold {
    clip_with(rf, inc, axis, scale, true)
}

/// [`clip`]; `shortcut`: a pass that cuts nothing leaves the polygon in place (off in tests:
/// every pass copies it, the plain Sutherland–Hodgman, to compare with).
fn clip_with(rf: &Placed, inc: &Placed, axis: usize, scale: f64, shortcut: bool) -> Manifold {
    let tol = TIE * scale;
    let ra = rf.axis(axis);
    let sgn = if (inc.c - rf.c).dot(&ra) >= 0.0 { 1.0 } else { -1.0 };
    let m = ra * sgn;
    let p_ref = rf.c + m * rf.h[axis];
    // the incident face: outward normal most opposed to m
    let dots = Vec3::from_fn(|k, _| inc.axis(k).dot(&m));
    let j = dots.iamax();
    let fs = if dots[j] > 0.0 { -1.0 } else { 1.0 };
    let f = inc.axis(j) * fs;
    let fc = inc.c + f * inc.h[j];
    let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
    let (u1, u2) = (inc.axis(j1), inc.axis(j2));
    let mut buf = [[Vertex::default(); POINTS]; 2];
    for (n, v) in buf[0].iter_mut().take(4).enumerate() {
        *v = corner(&fc, &u1, &u2, inc.h[j1], inc.h[j2], n, j1, j2);
    }
    // the side planes ±e·(x - c) = h in clipping order; the signed distance of x to the
    // negative one is exactly the negated projection minus h, so one projection serves both
    let sides = [(axis + 1) % 3, (axis + 2) % 3];
    let dist = |t: f64, k: usize, positive: bool| if positive { t - rf.h[k] } else { -t - rf.h[k] };
    let mut proj = [[0.0; 2]; 4];
    for (n, pr) in proj.iter_mut().enumerate() {
        let rel = buf[0][n].p - rf.c;
        *pr = [rf.axis(sides[0]).dot(&rel), rf.axis(sides[1]).dot(&rel)];
    }
    let mut count = 4;
    let mut cur = 0;
    // the polygon is still the incident face's corners (their projections are at hand)
    let mut corners = true;
    for (s, &k) in sides.iter().enumerate() {
        let e = rf.axis(k);
        for positive in [true, false] {
            let label = Label { on_ref: true, axis: k as u8, positive };
            // each vertex's distance once
            let mut d = [0.0; POINTS];
            for (q, dq) in d.iter_mut().enumerate().take(count) {
                let t = if corners { proj[q][s] } else { e.dot(&(buf[cur][q].p - rf.c)) };
                *dq = dist(t, k, positive);
            }
            if shortcut && d[..count].iter().all(|&x| x <= tol) {
                // nothing is cut (a stack's faces; three of the four planes of a box straddling
                // two others): the pass would copy every vertex, adding this plane to those on it
                for (v, dq) in buf[cur][..count].iter_mut().zip(&d) {
                    if dq.abs() <= tol {
                        v.add(label);
                    }
                }
                continue;
            }
            corners = false;
            let (src, dst) = if cur == 0 {
                let (a, b) = buf.split_at_mut(1);
                (&a[0], &mut b[0])
            } else {
                let (a, b) = buf.split_at_mut(1);
                (&b[0], &mut a[0])
            };
            let mut out = 0;
            // the edge from the previous vertex (cyclic; no integer division in this loop)
            let mut qp = count - 1;
            for q in 0..count {
                let (p, qv) = (&src[qp], &src[q]);
                let (dp, dq) = (d[qp], d[q]);
                let crossing = |out: &mut usize, dst: &mut [Vertex; POINTS]| {
                    // the edge p → q lies on their common plane; the new vertex on it and on this one
                    let t = dp / (dp - dq);
                    let mut x = Vertex { p: p.p + (qv.p - p.p) * t, ..Default::default() };
                    let common = p.labels[..p.count as usize].iter().find(|l| qv.has(l)).copied();
                    x.add(common.unwrap_or(p.labels[0]));
                    x.add(label);
                    if *out < POINTS {
                        dst[*out] = x;
                        *out += 1;
                    }
                };
                if dq <= tol {
                    if dp > tol && dq < -tol {
                        crossing(&mut out, dst);
                    }
                    let mut kept = *qv;
                    if dq.abs() <= tol {
                        kept.add(label);
                    }
                    if out < POINTS {
                        dst[out] = kept;
                        out += 1;
                    }
                } else if dp < -tol {
                    crossing(&mut out, dst);
                }
                qp = q;
            }
            count = out;
            cur = 1 - cur;
            if count == 0 {
                break;
            }
        }
        if count == 0 {
            break;
        }
    }
    if count == 0 {
        // the incident face misses the reference face's slab (overlapping boxes at odd angles,
        // or separated ones): keep its corner deepest along -m, a material point
        let at = |n: usize| corner(&fc, &u1, &u2, inc.h[j1], inc.h[j2], n, j1, j2);
        let deepest = (0..4).min_by(|&p, &q| at(p).p.dot(&m).total_cmp(&at(q).p.dot(&m))).unwrap_or(0);
        return Manifold { v: [at(deepest); POINTS], count: 1, m, p_ref, f, fc };
    }
    Manifold { v: buf[cur], count, m, p_ref, f, fc }
}

/// Corner `n` of the incident face (cyclic order (-,-), (+,-), (+,+), (-,+) along `u1`, `u2`),
/// labelled with the incident box's two side planes through it.
#[allow(clippy::too_many_arguments)]
fn corner(fc: &Vec3, u1: &Vec3, u2: &Vec3, e1: f64, e2: f64, n: usize, j1: usize, j2: usize) -> Vertex {
    let (s1, s2) = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)][n];
    let mut v = Vertex { p: fc + u1 * (s1 * e1) + u2 * (s2 * e2), ..Default::default() };
    v.add(Label { on_ref: false, axis: j1 as u8, positive: s1 > 0.0 });
    v.add(Label { on_ref: false, axis: j2 as u8, positive: s2 > 0.0 });
    v
}

/// Candidate `k` of two boxes, canonical order (A on body 1, B on body 2): the whole manifold is
/// built for it, so this is for single look-ups and tests; evaluations of a pair fill all
/// candidates at once with [`box_box_all`].
pub(super) fn box_box(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    sa: &BoxShape,
    sb: &BoxShape,
    scale: f64,
    k: usize,
) -> Raw {
    let mut out = [Raw::default(); POINTS];
    box_box_all(x1, x2, tw, sa, sb, scale, &mut out);
    out[k]
}

#[cfg(test)]
thread_local! {
    /// Manifolds built on this thread (tests count them per evaluation).
    pub(crate) static BUILDS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// All [`POINTS`] candidates of two boxes into `out`, canonical order: one separating-axis test
/// and one clipping for all of them.
pub(super) fn box_box_all(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    sa: &BoxShape,
    sb: &BoxShape,
    scale: f64,
    out: &mut [Raw],
) {
    #[cfg(test)]
    BUILDS.with(|b| b.set(b.get() + 1));
    let (a, b) = (Placed::new(sa, x1), Placed::new(sb, x2));
    let (feature, _) = choose(&a, &b, scale);
    match feature {
        Feature::Face { ref_a, axis } => {
            let (rf, inc) = if ref_a { (&a, &b) } else { (&b, &a) };
            let mf = clip(rf, inc, axis, scale);
            // the pair's normal, from B towards A
            let n = if ref_a { -mf.m } else { mf.m };
            let out = &mut out[..POINTS];
            for (o, v) in out.iter_mut().zip(&mf.v[..mf.count]) {
                *o = face_point(&mf, v, ref_a, rf, inc, tw);
            }
            if mf.count < POINTS {
                out[mf.count..].fill(unused(&a, &b, n, tw, ref_a));
            }
        }
        Feature::Edge { i, j } => {
            let e = edge_point(&a, &b, i, j, tw);
            out[0] = e;
            out[1..POINTS].fill(unused(&a, &b, e.n, tw, false));
        }
    }
}

/// One vertex of a face manifold as a candidate, with rates: a corner of the reference face
/// against the incident face, or the incident box's point at the vertex against the reference
/// face (module docs, "Contact points").
fn face_point(
    mf: &Manifold,
    vx: &Vertex,
    ref_a: bool,
    rf: &Placed,
    inc: &Placed,
    tw: Option<(&Motion, &Motion)>,
) -> Raw {
    let twists = tw.map(|(t1, t2)| if ref_a { (t1, t2) } else { (t2, t1) });
    // the point on the reference box, the point on the incident box, the normal from the
    // reference box towards the incident one, the gap; then their rates
    let (p_ref, p_inc, nr, g, rates) = if vx.kind() == Kind::ReferenceCorner {
        // the corner q of the reference face, a material point of the reference box, against the
        // incident face's plane (normal f, fixed in the incident box): g = f·(q - c_f), n = -f
        let mut q = mf.p_ref;
        for l in &vx.labels[..2] {
            let s = if l.positive { 1.0 } else { -1.0 };
            q += rf.axis(l.axis as usize) * (s * rf.h[l.axis as usize]);
        }
        let g = mf.f.dot(&(q - mf.fc));
        let foot = q - mf.f * g;
        let rates = twists.map(|(t_ref, t_inc)| {
            let qd = vel(t_ref, &q);
            let fd = t_inc.w.cross(&mf.f);
            let gd = fd.dot(&(q - mf.fc)) + mf.f.dot(&(qd - vel(t_inc, &mf.fc)));
            (qd, qd - mf.f * gd - fd * g, -fd)
        });
        (q, foot, -mf.f, g, rates)
    } else {
        // the incident box's point v at the vertex against the reference face's plane (normal m,
        // fixed in the reference box): g = m·(v - p_ref), n = m
        let g = mf.m.dot(&(vx.p - mf.p_ref));
        let foot = vx.p - mf.m * g;
        let rates = twists.map(|(t_ref, t_inc)| {
            // the vertex stays on the incident face and on its two defining planes, each fixed in
            // its box: m_k·v̇ = m_k·v_X(v), solved for v̇ (for a corner of the incident face its
            // material velocity; a crossing also moves along the incident edge)
            let planes = [(mf.f, false), plane(&vx.labels[0], rf, inc), plane(&vx.labels[1], rf, inc)];
            let rhs = planes.map(|(nk, on_ref)| nk.dot(&vel(if on_ref { t_ref } else { t_inc }, &vx.p)));
            let (c0, c1, c2) =
                (planes[1].0.cross(&planes[2].0), planes[2].0.cross(&planes[0].0), planes[0].0.cross(&planes[1].0));
            let det = planes[0].0.dot(&c0);
            let vd = if vx.count >= 2 && det.abs() > 1e-12 {
                (c0 * rhs[0] + c1 * rhs[1] + c2 * rhs[2]) / det
            } else {
                vel(t_inc, &vx.p)
            };
            let md = t_ref.w.cross(&mf.m);
            let gd = md.dot(&(vx.p - mf.p_ref)) + mf.m.dot(&(vd - vel(t_ref, &mf.p_ref)));
            (vd - mf.m * gd - md * g, vd, md)
        });
        (foot, vx.p, mf.m, g, rates)
    };
    // the pair's normal points from B towards A
    let (n, p1, p2) = if ref_a { (-nr, p_ref, p_inc) } else { (nr, p_inc, p_ref) };
    let mut out = Raw { g, n, p1, p2, ..Default::default() };
    if let Some((p_ref_d, p_inc_d, nr_d)) = rates {
        (out.nd, out.p1d, out.p2d) = if ref_a { (-nr_d, p_ref_d, p_inc_d) } else { (nr_d, p_inc_d, p_ref_d) };
    }
    out
}

/// The edge–edge candidate of the edges parallel to `a_i` and `b_j`, with rates.
fn edge_point(a: &Placed, b: &Placed, i: usize, j: usize, tw: Option<(&Motion, &Motion)>) -> Raw {
    let (ai, bj) = (a.axis(i), b.axis(j));
    let c = ai.cross(&bj);
    let cn = c.norm();
    let d = a.c - b.c;
    let sigma = if d.dot(&c) >= 0.0 { 1.0 } else { -1.0 };
    let n = c * (sigma / cn);
    // the extreme edges: A's towards B (along -n), B's towards A (along +n)
    let side = |x: f64| if x >= 0.0 { 1.0 } else { -1.0 };
    let mut ea = a.c;
    let mut eb = b.c;
    for l in 0..3 {
        if l != i {
            ea -= a.axis(l) * (side(a.axis(l).dot(&n)) * a.h[l]);
        }
        if l != j {
            eb += b.axis(l) * (side(b.axis(l).dot(&n)) * b.h[l]);
        }
    }
    // closest points of the lines ea + s a_i, eb + t b_j (unit directions, cos = a_i·b_j)
    let r = ea - eb;
    let cab = ai.dot(&bj);
    let den = 1.0 - cab * cab;
    let s = (cab * bj.dot(&r) - ai.dot(&r)) / den;
    let t = cab * s + bj.dot(&r);
    let x1p = ea + ai * s;
    let x2p = eb + bj * t;
    let g = n.dot(&(x1p - x2p));
    let mut out = Raw { g, n, p1: x1p, p2: x1p - n * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        let (ad, bd) = (t1.w.cross(&ai), t2.w.cross(&bj));
        let cd = ad.cross(&bj) + ai.cross(&bd);
        let u = c / cn;
        let nd = (cd - u * u.dot(&cd)) * (sigma / cn);
        // d/dt a_i·(X1 - X2) = 0 and d/dt b_j·(X1 - X2) = 0 with X1 = material point + ṡ a_i
        let dd = x1p - x2p;
        let dv = vel(t1, &x1p) - vel(t2, &x2p);
        let (b1, b2) = (-ad.dot(&dd) - ai.dot(&dv), -bd.dot(&dd) - bj.dot(&dv));
        let sd = (b1 - cab * b2) / den;
        let td = cab * sd - b2;
        let x1d = vel(t1, &x1p) + ai * sd;
        let x2d = vel(t2, &x2p) + bj * td;
        let gd = nd.dot(&dd) + n.dot(&(x1d - x2d));
        out.nd = nd;
        out.p1d = x1d;
        out.p2d = x1d - n * gd - nd * g;
    }
    out
}

/// World normal of a labelled plane and whether the reference box carries it.
#[inline]
fn plane(l: &Label, rf: &Placed, inc: &Placed) -> (Vec3, bool) {
    let axis = if l.on_ref { rf.axis(l.axis as usize) } else { inc.axis(l.axis as usize) };
    (if l.positive { axis } else { -axis }, l.on_ref)
}

/// An unused candidate: never active, finite (see the module docs).
fn unused(a: &Placed, b: &Placed, n: Vec3, tw: Option<(&Motion, &Motion)>, ref_a: bool) -> Raw {
    let g = (a.c - b.c).norm() + a.h.norm() + b.h.norm();
    let p2 = b.c;
    let p1 = p2 + n * g;
    let mut out = Raw { g, n, p1, p2, ..Default::default() };
    if let Some((t1, t2)) = tw {
        // the normal turns with the reference body; the points move with their bodies
        out.nd = if ref_a { t1.w.cross(&n) } else { t2.w.cross(&n) };
        out.p1d = vel(t1, &p1);
        out.p2d = vel(t2, &p2);
    }
    out
}

/// The chosen feature at body placements `x1`, `x2` (for tests and diagnostics).
#[cfg(test)]
pub(super) fn feature(x1: &Pose, x2: &Pose, sa: &BoxShape, sb: &BoxShape, scale: f64) -> (Feature, f64) {
    choose(&Placed::new(sa, x1), &Placed::new(sb, x2), scale)
}

/// Whether the face manifold at these placements (if the feature is a face) is the same with
/// and without the in-place passes, bit for bit; `None` for edge features, `Some((same, the
/// incident face uncut))` otherwise (tests).
#[cfg(test)]
pub(super) fn shortcut_agrees(x1: &Pose, x2: &Pose, sa: &BoxShape, sb: &BoxShape, scale: f64) -> Option<(bool, bool)> {
    let (a, b) = (Placed::new(sa, x1), Placed::new(sb, x2));
    let Feature::Face { ref_a, axis } = choose(&a, &b, scale).0 else { return None };
    let (rf, inc) = if ref_a { (&a, &b) } else { (&b, &a) };
    let (fast, slow) = (clip_with(rf, inc, axis, scale, true), clip_with(rf, inc, axis, scale, false));
    let same = fast.count == slow.count && fast.v[..fast.count] == slow.v[..slow.count];
    let taken = fast.count == 4 && fast.v[..4].iter().all(|v| v.kind() == Kind::IncidentCorner);
    Some((same, taken))
}

/// The feature the axis-by-axis test picks (tests: the reference for [`choose`]).
#[cfg(test)]
pub(super) fn feature_direct(x1: &Pose, x2: &Pose, sa: &BoxShape, sb: &BoxShape, scale: f64) -> (Feature, f64) {
    choose_direct(&Placed::new(sa, x1), &Placed::new(sb, x2), scale)
}

/// The chosen feature and what each candidate is, at body placements `x1`, `x2` (tests).
#[cfg(test)]
pub(super) fn kinds(x1: &Pose, x2: &Pose, sa: &BoxShape, sb: &BoxShape, scale: f64) -> (Feature, [Kind; POINTS]) {
    let (a, b) = (Placed::new(sa, x1), Placed::new(sb, x2));
    let (feature, _) = choose(&a, &b, scale);
    let mut out = [Kind::Unused; POINTS];
    match feature {
        Feature::Face { ref_a, axis } => {
            let (rf, inc) = if ref_a { (&a, &b) } else { (&b, &a) };
            let mf = clip(rf, inc, axis, scale);
            for (o, v) in out.iter_mut().zip(&mf.v[..mf.count]) {
                *o = v.kind();
            }
        }
        Feature::Edge { .. } => out[0] = Kind::EdgeEdge,
    }
    (feature, out)
}
