//! Narrow phase: closed-form contact geometry per contour pair, a fixed number of candidate
//! contact points per pair (known when the model is built).
//!
//! For each candidate: the gap `g_N`, the unit normal `n` pointing from contour 2 towards
//! contour 1 (so `g_N` grows when body 1 moves along `n` relative to body 2), the points `P1` on
//! contour 1's surface and `P2` on contour 2's surface with `P1 - P2 = g_N n` exactly, and
//! tangents `t1`, `t2` with `(t1, t2, n)` right-handed orthonormal.
//!
//! | pair (either order) | candidates | rule |
//! | --- | --- | --- |
//! | point, sphere – plane | 1 | the centre projected on the plane |
//! | box – plane | 8 | the corners |
//! | capsule – plane | 2 | the two end spheres |
//! | cylinder – plane | 2 | the lowest point of each rim circle (below) |
//! | point, sphere – sphere | 1 | along the centre line |
//! | point, sphere, capsule – capsule | 1 | closest points of the axis segments |
//! | point, sphere – box | 1 | closest point of the box (deepest face when the centre is inside) |
//! | box – box | 8 | separating axes; the clipped incident face (each vertex a point against a face), or one edge–edge point ([`box_box`]) |
//! | point2, circle, polygon – line | 1, 1, vertices | as the spatial point/sphere – plane |
//! | point2, circle – circle | 1 | along the centre line in the x-y plane |
//! | point, sphere, box, capsule – mesh | 1, 1, 8, 2 | each centre (corner, end sphere) against the closest point of the mesh ([`mesh_pair`]) |
//! | ellipsoid – ellipsoid | 1 | the common normal maximizing the support gap ([`convex_pair`]) |
//! | revolution – plane | 1 | the profile's support point in the meridian opposite the normal ([`surface_pair`]) |
//! | point, sphere – revolution, patch | 1 | the centre's foot point ([`surface_pair`]) |
//! | ellipsoid – patch | 1 | Newton on the patch parameters with the ellipsoid's support point ([`surface_pair`]) |
//!
//! Planar pairs are evaluated in body 2's x-y plane: contours are extruded along body 2's z axis
//! `e_z`, `n ⟂ e_z`, and `t1 = e_z × n / |e_z × n|` (the one friction direction; `t2 = n × t1` is
//! the out-of-plane direction). In 3-D, `t1` is the projection onto the tangent plane of a fixed
//! reference axis `e` of body 2: the plane's first in-plane axis, a capsule's or cylinder's axis,
//! a box's first axis, else body 2's x axis; when `|e·n| > 0.9` a second fixed axis of body 2
//! perpendicular to `e` takes over (no field of tangents is continuous on the whole sphere of
//! normals; against a plane or along a capsule the switch never happens).
//!
//! Degenerate configurations give defined values, never NaN: coincident centres (sphere–sphere,
//! circle–circle) or intersecting capsule axes give the true (negative) gap with a normal fixed
//! in body 2 (`d1 × d2` for crossing capsule axes); a sphere centre inside a box uses the nearest
//! face; a cylinder standing exactly upright on the plane uses a fixed rim point; a centre exactly
//! on a mesh's edge or vertex takes that feature's pseudo-normal.
//!
//! Capsule–plane: the lowest points of the two end spheres. When the capsule is tilted, the
//! upper end's point lies inside the capsule (its gap exceeds the lower end's, so it never closes
//! first); lying flat, both are on the surface and both touch.
//!
//! Cylinder–plane: each rim circle touches a half-space first at its point farthest along `-n`;
//! these two points are exact for a cylinder on its edge or lying on its side. Standing on a flat
//! end, the whole rim touches but the pair has one point per rim: model a resting flat end with a
//! box or extra point contours.

use crate::ensure;
use crate::error::{Error, Result};
use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

use super::contour::{lift, Contour, ContourKind};
use crate::geometry::revolution::Revolution;
use crate::geometry::surface::Patch;
use box_box::BoxShape;
use curve_pair::{CurveGeometry, First};
use mesh_pair::MeshGeometry;
use warm::SearchHint;

pub mod box_box;
pub mod convex_pair;
pub mod curve_pair;
pub mod mesh_pair;
pub mod surface_pair;
pub mod warm;

/// One candidate contact: gap, frame and the two surface points, world components.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactPoint {
    /// Gap `g_N` (> 0 open, < 0 penetrating).
    pub g_n: f64,
    /// Unit normal from contour 2 towards contour 1.
    pub n: Vec3,
    /// Contact point on contour 1's surface.
    pub p1: Vec3,
    /// Contact point on contour 2's surface (`p1 - p2 = g_n n`).
    pub p2: Vec3,
    /// First tangent (for planar pairs `e_z × n`).
    pub t1: Vec3,
    /// Second tangent, `n × t1` (out of plane for planar pairs).
    pub t2: Vec3,
}

/// The closed-form geometry of a pair, parameters in the body frames of the canonical order
/// (the order of the table in the module docs; the caller's order may be the reverse).
#[derive(Debug, Clone, PartialEq)]
enum Geometry {
    /// Body-fixed centres on body 1, each with `radius`, against the half-space of body 2.
    PointsHalfSpace { centers: Vec<Vec3>, radius: f64, point: Vec3, normal: Vec3 },
    /// The two rim circles of a cylinder on body 1 against the half-space of body 2; `across` is a
    /// unit vector ⟂ axis for the upright case.
    CylinderHalfSpace {
        center: Vec3,
        axis: Vec3,
        across: Vec3,
        radius: f64,
        half_length: f64,
        point: Vec3,
        normal: Vec3,
        /// A torus: one rim (`half_length = 0`) inflated by this tube radius.
        tube: f64,
    },
    /// Swept segments `a + s d`, `s ∈ [0, 1]` (a point when `d = 0`) with radii; `across` ⟂ d2.
    Swept { a1: Vec3, d1: Vec3, r1: f64, a2: Vec3, d2: Vec3, r2: f64, across: Vec3 },
    /// A sphere (or point, radius 0) on body 1 against a box on body 2.
    SphereBox { center: Vec3, radius: f64, box_center: Vec3, box_rotation: Mat3, half: Vec3 },
    /// Two boxes (body 1's, body 2's), a manifold of up to [`box_box::POINTS`] points; `scale` is
    /// the largest half extent (tolerances of ties).
    BoxBox { a: BoxShape, b: BoxShape, scale: f64 },
    /// Planar: circles (or points, radius 0) extruded along body 2's z axis.
    CircleCircle { c1: Vec3, r1: f64, c2: Vec3, r2: f64 },
    /// Planar parametric contours ([`curve_pair`]).
    Curve(CurveGeometry),
    /// An ellipsoid on body 1 (`S = R diag(a², b², c²) Rᵀ` in its body frame) against the
    /// half-space of body 2.
    EllipsoidHalfSpace { center: Vec3, shape: Mat3, point: Vec3, normal: Vec3 },
    /// A sphere (or point, radius 0) on body 1 against an ellipsoid on body 2.
    SphereEllipsoid { center: Vec3, radius: f64, e_center: Vec3, e_rotation: Mat3, semi: Vec3 },
    /// Two ellipsoids, centres and shape matrices `S = R diag(a², b², c²) Rᵀ` in their body
    /// frames ([`convex_pair`]).
    EllipsoidEllipsoid { c1: Vec3, shape1: Mat3, c2: Vec3, shape2: Mat3 },
    /// A surface of revolution on body 1 against the half-space of body 2 ([`surface_pair`]).
    RevolutionHalfSpace { rev: Box<Revolution>, point: Vec3, normal: Vec3 },
    /// A sphere (or point, radius 0) on body 1 against a surface of revolution of body 2.
    SphereRevolution { center: Vec3, radius: f64, rev: Box<Revolution> },
    /// A sphere (or point, radius 0) on body 1 against a spline patch of body 2.
    SpherePatch { center: Vec3, radius: f64, patch: Box<Patch> },
    /// An ellipsoid on body 1 (centre, shape matrix in its body frame) against a spline patch.
    EllipsoidPatch { center: Vec3, shape: Mat3, patch: Box<Patch> },
    /// A sphere (or point, radius 0) on body 1 inside a spherical (`axis = 0`) or cylindrical
    /// cavity of body 2.
    Cavity { c1: Vec3, r1: f64, c2: Vec3, axis: Vec3, r2: f64, across: Vec3 },
    /// Centres of body 1 against a triangle mesh of body 2 ([`mesh_pair`]).
    Mesh(MeshGeometry),
}

/// A contour pair prepared for per-step evaluation.
///
/// # Example
/// ```
/// use mechsys_core::contact::{evaluate, ContactPair, ContactPoint, Contour};
/// use mechsys_core::math::Vec3;
/// use mechsys_core::spatial::Pose;
/// // a ball of radius 0.1 on body 1, the ground plane z ≤ 0 on body 2
/// let pair = ContactPair::new(
///     "ball",
///     Contour::Sphere { center: Vec3::zeros(), radius: 0.1 },
///     Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() },
/// )?;
/// let mut out = [ContactPoint::default(); 1];
/// let x1 = Pose::new(nalgebra::Matrix3::identity(), Vec3::new(0.0, 0.0, 0.5));
/// evaluate(&pair, &x1, &Pose::IDENTITY, &mut out)?;
/// assert!((out[0].g_n - 0.4).abs() < 1e-15);
/// assert_eq!(out[0].n, Vec3::z());
/// # Ok::<(), mechsys_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPair {
    kinds: (ContourKind, ContourKind),
    geometry: Geometry,
    swapped: bool,
    count: usize,
    planar: bool,
    /// Tangent reference axes, body 2 frame (the caller's body 2).
    tangent_ref: [Vec3; 2],
    /// Velocity of each contour's surface material over the contour, body frames, caller's
    /// order (zero unless a plane or line is a moving surface, a conveyor belt).
    surface: [Vec3; 2],
}

/// Raw candidate: geometry and, when asked, rates (zero otherwise).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Raw {
    pub g: f64,
    pub n: Vec3,
    pub p1: Vec3,
    pub p2: Vec3,
    /// `ṅ`
    pub nd: Vec3,
    /// `Ṗ1`, the rate of the contact point (material motion plus sliding over contour 1).
    pub p1d: Vec3,
    /// `Ṗ2`
    pub p2d: Vec3,
}

impl Raw {
    /// The candidate seen from the other body: normal flipped, points exchanged.
    #[inline]
    fn reversed(&self) -> Raw {
        Raw { g: self.g, n: -self.n, p1: self.p2, p2: self.p1, nd: -self.nd, p1d: self.p2d, p2d: self.p1d }
    }
}

/// Tangents and their rates.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Tangents {
    pub t1: Vec3,
    pub t2: Vec3,
    pub t1d: Vec3,
    pub t2d: Vec3,
}

/// Whether `(first, second)` is a canonical order of the dispatch table.
fn canonical(a: ContourKind, b: ContourKind) -> bool {
    use ContourKind as K;
    match b {
        K::Plane => matches!(
            a,
            K::Point | K::Sphere | K::Box | K::Capsule | K::Cylinder | K::Ellipsoid | K::Torus | K::Revolution
        ),
        K::Revolution => matches!(a, K::Point | K::Sphere),
        K::Patch => matches!(a, K::Point | K::Sphere | K::Ellipsoid),
        K::Line => matches!(a, K::Point2 | K::Circle | K::Polygon | K::Curve),
        K::Curve => matches!(a, K::Point2 | K::Circle | K::Polygon | K::Curve),
        K::Sphere => matches!(a, K::Point | K::Sphere),
        K::Capsule => matches!(a, K::Point | K::Sphere | K::Capsule),
        K::Box => matches!(a, K::Point | K::Sphere | K::Box),
        K::Circle => matches!(a, K::Point2 | K::Circle),
        K::Bowl | K::Bore => matches!(a, K::Point | K::Sphere),
        K::Ellipsoid => matches!(a, K::Point | K::Sphere | K::Ellipsoid),
        K::Mesh => matches!(a, K::Point | K::Sphere | K::Box | K::Capsule),
        _ => false,
    }
}

/// Whether the caller's order must be reversed; an error naming both kinds if unsupported.
fn orientation(a: ContourKind, b: ContourKind) -> Result<bool> {
    if canonical(a, b) {
        Ok(false)
    } else if canonical(b, a) {
        Ok(true)
    } else {
        Err(Error::Model(format!(
            "no contact geometry for the contour pair {a}–{b} (supported: point/sphere/box/capsule/cylinder/ellipsoid/torus–plane, \
             point2/circle/polygon–line, point/sphere–sphere, point/sphere/capsule–capsule, point/sphere/box–box, \
             point2/circle–circle, point2/circle/polygon/curve–curve, curve–line, point/sphere–bowl/bore/ellipsoid, ellipsoid–ellipsoid, revolution–plane, point/sphere–revolution/patch, ellipsoid–patch, point/sphere/box/capsule–mesh, in either order)"
        )))
    }
}

/// Number of candidate contact points of the pair (either order); an error naming both contour
/// kinds when the pair is not supported, or the contour when one is invalid.
pub fn candidates(c1: &Contour, c2: &Contour) -> Result<usize> {
    let swapped = orientation(c1.kind(), c2.kind())?;
    c1.validate(&format!("contour 1 ({})", c1.kind()))?;
    c2.validate(&format!("contour 2 ({})", c2.kind()))?;
    let first = if swapped { c2 } else { c1 };
    // end spheres and rim circles against a half-space, end spheres against a mesh
    let against_plane = [c1.kind(), c2.kind()].iter().any(|k| matches!(k, ContourKind::Plane | ContourKind::Mesh));
    Ok(match first {
        // the clipped incident face has at most 8 vertices (one point for an edge–edge contact)
        Contour::Box { .. } if matches!((c1.kind(), c2.kind()), (ContourKind::Box, ContourKind::Box)) => {
            box_box::POINTS
        }
        Contour::Box { .. } => 8,
        // end spheres and rim circles; a capsule against a capsule has one closest pair
        Contour::Capsule { .. } | Contour::Cylinder { .. } if against_plane => 2,
        Contour::Torus { .. } => 1,
        Contour::Polygon { vertices } => vertices.len(),
        _ => 1,
    })
}

/// A unit vector perpendicular to the unit vector `v`.
fn perpendicular(v: &Vec3) -> Vec3 {
    let k = v.iamin();
    let mut e = Vec3::zeros();
    e[k] = 1.0;
    (e - v * v.dot(&e)).normalize()
}

#[inline]
fn vel(t: &Motion, p: &Vec3) -> Vec3 {
    t.v + t.w.cross(p)
}

/// Lengths below this are treated as zero (coincident centres, crossing axes).
const TINY: f64 = 1e-12;

impl ContactPair {
    /// Validates both contours and prepares the pair; `name` appears in every message.
    pub fn new(name: &str, contour1: Contour, contour2: Contour) -> Result<Self> {
        let (k1, k2) = (contour1.kind(), contour2.kind());
        contour1.validate(&format!("contact '{name}': contour 1 ({k1})"))?;
        contour2.validate(&format!("contact '{name}': contour 2 ({k2})"))?;
        let swapped = orientation(k1, k2).map_err(|e| Error::Model(format!("contact '{name}': {e}")))?;
        let count = candidates(&contour1, &contour2)?;
        let (c1, c2) = (contour1.normalized(), contour2.normalized());
        let (f, s) = if swapped { (&c2, &c1) } else { (&c1, &c2) };
        let geometry = build_geometry(f, s);
        let planar = k1.is_planar();
        let tangent_ref = match &c2 {
            Contour::Plane { normal, .. } => {
                let t = perpendicular(normal);
                [t, normal.cross(&t)]
            }
            Contour::Capsule { a, b, .. } => {
                let d = (b - a).normalize();
                [d, perpendicular(&d)]
            }
            Contour::Cylinder { axis, .. } | Contour::Bore { axis, .. } | Contour::Torus { axis, .. } => {
                [*axis, perpendicular(axis)]
            }
            Contour::Revolution(r) => {
                let axis = r.rotation.column(2).into_owned();
                [axis, perpendicular(&axis)]
            }
            Contour::Box { rotation, .. } => [rotation.column(0).into_owned(), rotation.column(1).into_owned()],
            _ => [Vec3::x(), Vec3::y()],
        };
        Ok(ContactPair { kinds: (k1, k2), geometry, swapped, count, planar, tangent_ref, surface: [Vec3::zeros(); 2] })
    }

    /// The box–box feature pair chosen at these placements (tests).
    #[cfg(test)]
    pub(crate) fn box_feature(&self, x1: &Pose, x2: &Pose) -> Option<box_box::Feature> {
        match &self.geometry {
            Geometry::BoxBox { a, b, scale } => Some(box_box::feature(x1, x2, a, b, *scale).0),
            _ => None,
        }
    }

    /// The box–box feature pair and what each candidate is (tests; box–box pairs are never swapped).
    #[cfg(test)]
    pub(crate) fn box_kinds(
        &self,
        x1: &Pose,
        x2: &Pose,
    ) -> Option<(box_box::Feature, [box_box::Kind; box_box::POINTS])> {
        match &self.geometry {
            Geometry::BoxBox { a, b, scale } => Some(box_box::kinds(x1, x2, a, b, *scale)),
            _ => None,
        }
    }

    /// Asks a pair with a parametric contour (other than a polygon's vertices, which have one
    /// candidate each) for up to `points` contact points (1 to 8): the deepest local minima of
    /// the distance, ordered along the curve (gear pairs: one per flank side and tooth colour,
    /// an even number, see `curve_pair::GearSlots`). An error for other pairs or out of range.
    pub fn with_points(mut self, points: usize) -> Result<Self> {
        let name = format!("{}–{}", self.kinds.0, self.kinds.1);
        let Geometry::Curve(g) = &mut self.geometry else {
            return Err(Error::Model(format!(
                "contact pair {name}: only pairs with a parametric contour (curve) take a number of contact points"
            )));
        };
        ensure!(
            (1..=curve_pair::MAX_POINTS).contains(&points),
            Model,
            "contact pair {name}: points must be 1 to {}, got {points}",
            curve_pair::MAX_POINTS
        );
        ensure!(
            g.shared(),
            Model,
            "contact pair {name}: a polygon has one contact point per vertex; points does not apply"
        );
        g.check_points(points).map_err(|m| Error::Model(format!("contact pair {name}: {m}")))?;
        g.set_points(points);
        self.count = points;
        Ok(self)
    }

    /// Makes contour `which` (1 or 2), a plane or a line, a moving surface: its material moves
    /// over it at `velocity` (body frame, m/s, in its plane), as a conveyor belt does. The
    /// contact's tangential velocity is then measured against the moving material, so sticking
    /// means moving with the belt. An error for other contours, or a velocity with a normal part.
    pub fn with_surface_velocity(mut self, which: usize, velocity: Vec3) -> Result<Self> {
        let name = format!("{}–{}", self.kinds.0, self.kinds.1);
        ensure!(which == 1 || which == 2, Model, "contact pair {name}: the moving contour is 1 or 2, got {which}");
        ensure!(
            velocity.iter().all(|v| v.is_finite()),
            Model,
            "contact pair {name}: surface velocity must be finite, got {:?}",
            velocity.as_slice()
        );
        let normal = match (&self.geometry, which == 2, self.swapped) {
            // the canonical body 2 holds the plane or line
            (Geometry::PointsHalfSpace { normal, .. } | Geometry::CylinderHalfSpace { normal, .. }, is2, sw)
                if is2 != sw =>
            {
                *normal
            }
            (Geometry::Curve(CurveGeometry::OnLine { normal, .. }), is2, sw) if is2 != sw => lift(normal),
            _ => {
                return Err(Error::Model(format!(
                    "contact pair {name}: only a plane or a line can be a moving surface (contour {which} is a {})",
                    if which == 1 { self.kinds.0 } else { self.kinds.1 }
                )))
            }
        };
        let along = velocity.dot(&normal) / normal.norm();
        ensure!(
            along.abs() <= 1e-12 * (1.0 + velocity.norm()),
            Model,
            "contact pair {name}: a surface velocity must lie in the surface; it has {along} m/s along the normal"
        );
        self.surface[which - 1] = velocity;
        Ok(self)
    }

    /// Surface velocities of contours 1 and 2 (body frames).
    pub fn surface_velocity(&self) -> &[Vec3; 2] {
        &self.surface
    }

    /// Number of candidate points (the length `evaluate` fills).
    pub fn candidates(&self) -> usize {
        self.count
    }

    /// The contour kinds in the caller's order.
    pub fn kinds(&self) -> (ContourKind, ContourKind) {
        self.kinds
    }

    /// Friction directions per candidate: 1 for planar pairs, 2 in 3-D.
    pub fn tangent_dim(&self) -> usize {
        if self.planar {
            1
        } else {
            2
        }
    }

    /// Whether the pair is planar.
    pub fn is_planar(&self) -> bool {
        self.planar
    }

    /// Whether its candidates are a clipped face manifold (box–box): points that slide over
    /// both bodies' faces rather than material points of one of them.
    pub fn is_clipped_manifold(&self) -> bool {
        matches!(self.geometry, Geometry::BoxBox { .. })
    }

    pub(crate) fn check_len(&self, len: usize) -> Result<()> {
        ensure!(
            len >= self.count,
            Settings,
            "contact pair {}–{}: output has room for {len} candidates, needs {}",
            self.kinds.0,
            self.kinds.1,
            self.count
        );
        Ok(())
    }

    /// Candidate `k` in the caller's order; rates when `twists` are given.
    #[inline]
    pub(crate) fn candidate(&self, k: usize, x1: &Pose, x2: &Pose, twists: Option<(&Motion, &Motion)>) -> Raw {
        if !self.swapped {
            return self.raw(k, x1, x2, twists);
        }
        // canonical body 1 is the caller's body 2
        self.raw(k, x2, x1, twists.map(|(a, b)| (b, a))).reversed()
    }

    /// All candidates in the caller's order into `out[..self.candidates()]`, computing work the
    /// candidates share (the box–box manifold) once; the same values as [`Self::candidate`] for
    /// each `k`.
    pub(crate) fn candidates_into(&self, x1: &Pose, x2: &Pose, twists: Option<(&Motion, &Motion)>, out: &mut [Raw]) {
        debug_assert!(out.len() >= self.count, "candidates_into: room for {} of {}", out.len(), self.count);
        let out = &mut out[..self.count];
        // box–box is canonical in either order (never swapped)
        if let (Geometry::BoxBox { a, b, scale }, false) = (&self.geometry, self.swapped) {
            box_box::box_box_all(x1, x2, twists, a, b, *scale, out);
            return;
        }
        if let Geometry::Curve(g) = &self.geometry {
            if g.shared() {
                if self.swapped {
                    g.all(x2, x1, twists.map(|(a, b)| (b, a)), out, None);
                    for o in out.iter_mut() {
                        *o = o.reversed();
                    }
                } else {
                    g.all(x1, x2, twists, out, None);
                }
                return;
            }
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.candidate(k, x1, x2, twists);
        }
    }

    /// [`Self::each_candidate`] with the planar curve searches warm-started from `hints` (one per
    /// candidate, kept by the caller between evaluations of this pair; see [`warm`]); the other
    /// pairs have nothing to warm-start and ignore them.
    pub(crate) fn each_candidate_warm(
        &self,
        x1: &Pose,
        x2: &Pose,
        twists: Option<(&Motion, &Motion)>,
        hints: &mut [SearchHint],
        mut f: impl FnMut(usize, &Raw),
    ) {
        let Geometry::Curve(g) = &self.geometry else {
            return self.each_candidate(x1, x2, twists, f);
        };
        // the search and its hints are in canonical order
        let (x1, x2, tw) = if self.swapped { (x2, x1, twists.map(|(a, b)| (b, a))) } else { (x1, x2, twists) };
        let mut buf = [Raw::default(); curve_pair::MAX_POINTS];
        let (out, hints) = (&mut buf[..self.count], &mut hints[..self.count]);
        if g.shared() {
            g.all(x1, x2, tw, out, Some(hints));
        } else {
            for (k, (o, h)) in out.iter_mut().zip(hints.iter_mut()).enumerate() {
                *o = g.one(k, x1, x2, tw, Some(h));
            }
        }
        for (k, r) in out.iter().enumerate() {
            f(k, &if self.swapped { r.reversed() } else { *r });
        }
    }

    /// Calls `f(k, candidate k)` for every candidate in the caller's order, with one evaluation of
    /// the work the candidates share (the box–box manifold: one separating-axis test and one
    /// clipping per call); no allocation.
    #[inline]
    pub(crate) fn each_candidate(
        &self,
        x1: &Pose,
        x2: &Pose,
        twists: Option<(&Motion, &Motion)>,
        mut f: impl FnMut(usize, &Raw),
    ) {
        if let Geometry::Curve(g) = &self.geometry {
            if g.shared() {
                let mut buf = [Raw::default(); curve_pair::MAX_POINTS];
                self.candidates_into(x1, x2, twists, &mut buf);
                for (k, r) in buf[..self.count].iter().enumerate() {
                    f(k, r);
                }
                return;
            }
        }
        if let Geometry::PointsHalfSpace { centers, radius, point, normal } = &self.geometry {
            // the plane is placed once for all centres (a box's eight corners)
            let (xb, xp, tw) = if self.swapped { (x2, x1, twists.map(|(a, b)| (b, a))) } else { (x1, x2, twists) };
            let (m, p) = (xp.a * normal, xp.point_to_parent(point));
            for (k, c) in centers.iter().enumerate() {
                let c = xb.point_to_parent(c);
                let r = half_space_at(&c, tw.map(|(t1, _)| vel(t1, &c)), *radius, &m, &p, tw.map(|t| t.1));
                f(k, &if self.swapped { r.reversed() } else { r });
            }
            return;
        }
        if matches!(self.geometry, Geometry::BoxBox { .. }) {
            let mut buf = [Raw::default(); box_box::POINTS];
            self.candidates_into(x1, x2, twists, &mut buf);
            for (k, r) in buf[..self.count].iter().enumerate() {
                f(k, r);
            }
        } else {
            for k in 0..self.count {
                f(k, &self.candidate(k, x1, x2, twists));
            }
        }
    }

    /// Tangents at normal `n` for body 2 at `x2`; rates from body 2's `ω` and `ṅ` when given.
    #[inline]
    pub(crate) fn tangents(&self, x2: &Pose, n: &Vec3, rates: Option<(&Vec3, &Vec3)>) -> Tangents {
        // d/dt (u/|u|) = (u̇ - t (t·u̇)) / |u|
        let unit_rate = |ud: &Vec3, t: &Vec3, len: f64| (ud - t * t.dot(ud)) / len;
        if self.planar {
            // t1 = e_z × n / |e_z × n|
            let e = x2.a.column(2).into_owned();
            let u = e.cross(n);
            let len = u.norm();
            if len > 1e-6 {
                let t1 = u / len;
                let t2 = n.cross(&t1);
                let mut out = Tangents { t1, t2, ..Default::default() };
                if let Some((w2, nd)) = rates {
                    let ud = w2.cross(&e).cross(n) + e.cross(nd);
                    out.t1d = unit_rate(&ud, &t1, len);
                    out.t2d = nd.cross(&t1) + n.cross(&out.t1d);
                }
                return out;
            }
        }
        // t1 ∥ e - (e·n) n for a body-2 axis e
        let mut e = x2.a * self.tangent_ref[0];
        if e.dot(n).abs() > 0.9 {
            e = x2.a * self.tangent_ref[1];
        }
        let en = e.dot(n);
        let u = e - n * en;
        let len = u.norm();
        let t1 = u / len;
        let t2 = n.cross(&t1);
        let mut out = Tangents { t1, t2, ..Default::default() };
        if let Some((w2, nd)) = rates {
            let ed = w2.cross(&e);
            let ud = ed - n * (ed.dot(n) + e.dot(nd)) - nd * en;
            out.t1d = unit_rate(&ud, &t1, len);
            out.t2d = nd.cross(&t1) + n.cross(&out.t1d);
        }
        out
    }

    /// Candidate `k` in the canonical order.
    fn raw(&self, k: usize, x1: &Pose, x2: &Pose, tw: Option<(&Motion, &Motion)>) -> Raw {
        match &self.geometry {
            Geometry::PointsHalfSpace { centers, radius, point, normal } => {
                let c = x1.point_to_parent(&centers[k]);
                half_space(&c, tw.map(|(t1, _)| vel(t1, &c)), *radius, x2, point, normal, tw.map(|t| t.1))
            }
            Geometry::CylinderHalfSpace { center, axis, across, radius, half_length, point, normal, tube } => {
                let a = x1.a * axis;
                let m = x2.a * normal;
                let k_vec = m - a * m.dot(&a);
                let kn = k_vec.norm();
                // lowest rim direction u = -(m projected on the rim plane), normalized
                let (u, upright) = if kn > TINY { (-k_vec / kn, false) } else { (x1.a * across, true) };
                let side = if k == 0 { 1.0 } else { -1.0 };
                let c = x1.point_to_parent(&(center + axis * (side * half_length)));
                let q = c + u * *radius;
                let qd = tw.map(|(t1, t2)| {
                    let ud = if upright {
                        t1.w.cross(&u)
                    } else {
                        let ad = t1.w.cross(&a);
                        let md = t2.w.cross(&m);
                        let kd = md - ad * m.dot(&a) - a * (md.dot(&a) + m.dot(&ad));
                        -(kd - u * u.dot(&kd)) / kn
                    };
                    vel(t1, &c) + ud * *radius
                });
                half_space(&q, qd, *tube, x2, point, normal, tw.map(|t| t.1))
            }
            Geometry::Swept { a1, d1, r1, a2, d2, r2, across } => swept(x1, x2, tw, a1, d1, *r1, a2, d2, *r2, across),
            Geometry::SphereBox { center, radius, box_center, box_rotation, half } => {
                sphere_box(x1, x2, tw, center, *radius, box_center, box_rotation, half)
            }
            Geometry::CircleCircle { c1, r1, c2, r2 } => circle_circle(x1, x2, tw, c1, *r1, c2, *r2),
            Geometry::BoxBox { a, b, scale } => box_box::box_box(x1, x2, tw, a, b, *scale, k),
            Geometry::Curve(g) => g.one(k, x1, x2, tw, None),
            Geometry::Cavity { c1, r1, c2, axis, r2, across } => cavity(x1, x2, tw, c1, *r1, c2, axis, *r2, across),
            Geometry::EllipsoidHalfSpace { center, shape, point, normal } => {
                ellipsoid_half_space(x1, x2, tw, center, shape, point, normal)
            }
            Geometry::SphereEllipsoid { center, radius, e_center, e_rotation, semi } => {
                sphere_ellipsoid(x1, x2, tw, center, *radius, e_center, e_rotation, semi)
            }
            Geometry::Mesh(g) => g.one(k, x1, x2, tw),
            Geometry::EllipsoidEllipsoid { c1, shape1, c2, shape2 } => {
                convex_pair::ellipsoid_ellipsoid(x1, x2, tw, c1, shape1, c2, shape2)
            }
            Geometry::RevolutionHalfSpace { rev, point, normal } => {
                surface_pair::revolution_half_space(x1, x2, tw, rev, point, normal)
            }
            Geometry::SphereRevolution { center, radius, rev } => {
                surface_pair::sphere_revolution(x1, x2, tw, center, *radius, rev)
            }
            Geometry::SpherePatch { center, radius, patch } => {
                surface_pair::sphere_patch(x1, x2, tw, center, *radius, patch)
            }
            Geometry::EllipsoidPatch { center, shape, patch } => {
                surface_pair::ellipsoid_patch(x1, x2, tw, center, shape, patch)
            }
        }
    }
}

/// The eight corners of a box, in its body's frame.
fn box_corners(center: &Vec3, rotation: &Mat3, half: &Vec3) -> Vec<Vec3> {
    (0..8)
        .map(|i| {
            let sgn = |b: usize| if i & (1 << b) != 0 { 1.0 } else { -1.0 };
            center + rotation * Vec3::new(sgn(0) * half.x, sgn(1) * half.y, sgn(2) * half.z)
        })
        .collect()
}

fn build_geometry(f: &Contour, s: &Contour) -> Geometry {
    match (f, s) {
        (Contour::Curve(c), Contour::Line { point, normal }) => {
            return Geometry::Curve(CurveGeometry::OnLine {
                curve: (**c).clone(),
                point: *point,
                normal: *normal,
                count: 1,
                reach: 0.0,
            })
        }
        (_, Contour::Curve(second)) => {
            let first = match f {
                Contour::Point2 { p } => First::Points { centers: vec![lift(p)], radius: 0.0 },
                Contour::Circle { center, radius } => First::Points { centers: vec![lift(center)], radius: *radius },
                Contour::Polygon { vertices } => {
                    First::Points { centers: vertices.iter().map(lift).collect(), radius: 0.0 }
                }
                Contour::Curve(c) => First::Curve((**c).clone()),
                _ => unreachable!("excluded by the dispatch table"),
            };
            return Geometry::Curve(CurveGeometry::OnCurve { first, second: (**second).clone(), count: 1, reach: 0.0 });
        }
        _ => {}
    }
    if let Contour::Mesh(mesh) = s {
        let (centers, radius) = match f {
            Contour::Point { p } => (vec![*p], 0.0),
            Contour::Sphere { center, radius } => (vec![*center], *radius),
            Contour::Box { center, rotation, half_extents } => (box_corners(center, rotation, half_extents), 0.0),
            Contour::Capsule { a, b, radius } => (vec![*a, *b], *radius),
            _ => unreachable!("excluded by the dispatch table"),
        };
        return Geometry::Mesh(MeshGeometry { centers, radius, mesh: mesh.clone() });
    }
    // the second contour's half-space (plane or line), body 2 frame
    let half_space = |s: &Contour| match s {
        Contour::Plane { point, normal } => Some((*point, *normal)),
        Contour::Line { point, normal } => Some((lift(point), lift(normal))),
        _ => None,
    };
    if let Some((point, normal)) = half_space(s) {
        if let Contour::Revolution(rev) = f {
            return Geometry::RevolutionHalfSpace { rev: rev.clone(), point, normal };
        }
        if let Contour::Ellipsoid { center, rotation, semi_axes } = f {
            let d = Mat3::from_diagonal(&semi_axes.component_mul(semi_axes));
            return Geometry::EllipsoidHalfSpace {
                center: *center,
                shape: rotation * d * rotation.transpose(),
                point,
                normal,
            };
        }
        let (centers, radius) = match f {
            Contour::Point { p } => (vec![*p], 0.0),
            Contour::Sphere { center, radius } => (vec![*center], *radius),
            Contour::Box { center, rotation, half_extents } => (box_corners(center, rotation, half_extents), 0.0),
            Contour::Capsule { a, b, radius } => (vec![*a, *b], *radius),
            Contour::Cylinder { center, axis, radius, half_length } => {
                return Geometry::CylinderHalfSpace {
                    center: *center,
                    axis: *axis,
                    across: perpendicular(axis),
                    radius: *radius,
                    half_length: *half_length,
                    point,
                    normal,
                    tube: 0.0,
                };
            }
            // a torus is one rim circle inflated by its tube: the lowest rim point, then the tube
            Contour::Torus { center, axis, radius, tube } => {
                return Geometry::CylinderHalfSpace {
                    center: *center,
                    axis: *axis,
                    across: perpendicular(axis),
                    radius: *radius,
                    half_length: 0.0,
                    point,
                    normal,
                    tube: *tube,
                };
            }
            Contour::Point2 { p } => (vec![lift(p)], 0.0),
            Contour::Circle { center, radius } => (vec![lift(center)], *radius),
            Contour::Polygon { vertices } => (vertices.iter().map(lift).collect(), 0.0),
            Contour::Plane { .. }
            | Contour::Line { .. }
            | Contour::Curve(_)
            | Contour::Bowl { .. }
            | Contour::Bore { .. }
            | Contour::Ellipsoid { .. }
            | Contour::Mesh(_)
            | Contour::Revolution(_)
            | Contour::Patch(_) => {
                unreachable!("excluded by the dispatch table")
            }
        };
        return Geometry::PointsHalfSpace { centers, radius, point, normal };
    }
    if let (Contour::Ellipsoid { center, rotation, semi_axes }, Contour::Patch(patch)) = (f, s) {
        let shape = rotation * Mat3::from_diagonal(&semi_axes.component_mul(semi_axes)) * rotation.transpose();
        return Geometry::EllipsoidPatch { center: *center, shape, patch: patch.clone() };
    }
    if let Contour::Revolution(_) | Contour::Patch(_) = s {
        let (center, radius) = match f {
            Contour::Point { p } => (*p, 0.0),
            Contour::Sphere { center, radius } => (*center, *radius),
            _ => unreachable!("excluded by the dispatch table"),
        };
        return match s {
            Contour::Revolution(rev) => Geometry::SphereRevolution { center, radius, rev: rev.clone() },
            Contour::Patch(patch) => Geometry::SpherePatch { center, radius, patch: patch.clone() },
            _ => unreachable!(),
        };
    }
    let shape =
        |rotation: &Mat3, semi: &Vec3| rotation * Mat3::from_diagonal(&semi.component_mul(semi)) * rotation.transpose();
    if let (
        Contour::Ellipsoid { center: c1, rotation: r1, semi_axes: a1 },
        Contour::Ellipsoid { center: c2, rotation: r2, semi_axes: a2 },
    ) = (f, s)
    {
        return Geometry::EllipsoidEllipsoid { c1: *c1, shape1: shape(r1, a1), c2: *c2, shape2: shape(r2, a2) };
    }
    if let Contour::Ellipsoid { center: ec, rotation, semi_axes } = s {
        let (center, radius) = match f {
            Contour::Point { p } => (*p, 0.0),
            Contour::Sphere { center, radius } => (*center, *radius),
            _ => unreachable!("excluded by the dispatch table"),
        };
        return Geometry::SphereEllipsoid { center, radius, e_center: *ec, e_rotation: *rotation, semi: *semi_axes };
    }
    if let Contour::Bowl { center, radius } | Contour::Bore { center, radius, .. } = s {
        let (c1, r1) = match f {
            Contour::Point { p } => (*p, 0.0),
            Contour::Sphere { center, radius } => (*center, *radius),
            _ => unreachable!("excluded by the dispatch table"),
        };
        let axis = if let Contour::Bore { axis, .. } = s { *axis } else { Vec3::zeros() };
        let across = if axis.norm() > 0.0 { perpendicular(&axis) } else { Vec3::x() };
        return Geometry::Cavity { c1, r1, c2: *center, axis, r2: *radius, across };
    }
    let segment = |c: &Contour| match c {
        Contour::Point { p } => (*p, Vec3::zeros(), 0.0),
        Contour::Sphere { center, radius } => (*center, Vec3::zeros(), *radius),
        Contour::Capsule { a, b, radius } => (*a, b - a, *radius),
        _ => unreachable!("excluded by the dispatch table"),
    };
    match s {
        Contour::Sphere { .. } | Contour::Capsule { .. } => {
            let ((a1, d1, r1), (a2, d2, r2)) = (segment(f), segment(s));
            let across = if d2.norm() > 0.0 { perpendicular(&d2.normalize()) } else { Vec3::x() };
            Geometry::Swept { a1, d1, r1, a2, d2, r2, across }
        }
        Contour::Box { center: bc, rotation, half_extents } if matches!(f, Contour::Box { .. }) => {
            let Contour::Box { center: c1, rotation: r1, half_extents: h1 } = f else { unreachable!() };
            Geometry::BoxBox {
                a: BoxShape { center: *c1, rotation: *r1, half: *h1 },
                b: BoxShape { center: *bc, rotation: *rotation, half: *half_extents },
                scale: h1.max().max(half_extents.max()),
            }
        }
        Contour::Box { center: bc, rotation, half_extents } => {
            let (center, _, radius) = segment(f);
            Geometry::SphereBox { center, radius, box_center: *bc, box_rotation: *rotation, half: *half_extents }
        }
        Contour::Circle { center: c2, radius: r2 } => {
            let (c1, r1) = match f {
                Contour::Point2 { p } => (lift(p), 0.0),
                Contour::Circle { center, radius } => (lift(center), *radius),
                _ => unreachable!("excluded by the dispatch table"),
            };
            Geometry::CircleCircle { c1, r1, c2: lift(c2), r2: *r2 }
        }
        _ => unreachable!("excluded by the dispatch table"),
    }
}

/// A centre `c` (rate `cd`) inflated by `radius` against the half-space `(point, normal)` of
/// body 2: `n = m`, `P1 = c - R m`, `P2 = c - h m` with `h = m·(c - p)`, `g_N = h - R`.
#[inline]
fn half_space(
    c: &Vec3,
    cd: Option<Vec3>,
    radius: f64,
    x2: &Pose,
    point: &Vec3,
    normal: &Vec3,
    t2: Option<&Motion>,
) -> Raw {
    half_space_at(c, cd, radius, &(x2.a * normal), &x2.point_to_parent(point), t2)
}

/// [`half_space`] with the plane placed: world normal `m` through world point `p`.
#[inline]
fn half_space_at(c: &Vec3, cd: Option<Vec3>, radius: f64, m: &Vec3, p: &Vec3, t2: Option<&Motion>) -> Raw {
    let (m, p) = (*m, *p);
    let h = m.dot(&(c - p));
    let mut r = Raw { g: h - radius, n: m, p1: c - m * radius, p2: c - m * h, ..Default::default() };
    if let (Some(cd), Some(t2)) = (cd, t2) {
        // the normal turns with body 2; P2 is the foot of c on the moving plane
        let md = t2.w.cross(&m);
        let hd = md.dot(&(c - p)) + m.dot(&(cd - vel(t2, &p)));
        r.nd = md;
        r.p1d = cd - md * radius;
        r.p2d = cd - m * hd - md * h;
    }
    r
}

/// Closest points of two segments `a + s d` (either may be a point), with radii. Parameters on
/// the interior satisfy `d·(X1 - X2) = 0`; their rates follow from differentiating those
/// conditions (the general closest-point formula, cf. eqs. 2.102–2.109).
#[allow(clippy::too_many_arguments)]
fn swept(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    a1b: &Vec3,
    d1b: &Vec3,
    r1: f64,
    a2b: &Vec3,
    d2b: &Vec3,
    r2: f64,
    across: &Vec3,
) -> Raw {
    // a sphere's or point's segment has no direction to turn (spares two products per pair)
    let turn = |x: &Pose, d: &Vec3| if *d == Vec3::zeros() { Vec3::zeros() } else { x.a * d };
    let (a1, d1) = (x1.point_to_parent(a1b), turn(x1, d1b));
    let (a2, d2) = (x2.point_to_parent(a2b), turn(x2, d2b));
    let r = a1 - a2;
    let (aa, ee, bb, cc, ff) = (d1.dot(&d1), d2.dot(&d2), d1.dot(&d2), d1.dot(&r), d2.dot(&r));
    let clamp01 = |x: f64| x.clamp(0.0, 1.0);
    // minimize |r + s d1 - u d2|² over the unit square
    // the overlap-midpoint rule fixes s by fiat, so s has no stationarity condition there
    let mut midpoint = false;
    let (s, u) = if aa == 0.0 && ee == 0.0 {
        (0.0, 0.0)
    } else if aa == 0.0 {
        (0.0, clamp01(ff / ee))
    } else if ee == 0.0 {
        (clamp01(-cc / aa), 0.0)
    } else {
        let den = aa * ee - bb * bb;
        let s0 = if den > 1e-12 * aa * ee {
            clamp01((bb * ff - cc * ee) / den)
        } else {
            // parallel: the middle of the overlap of the two segments along segment 1
            midpoint = true;
            let (sa, sb) = (-cc / aa, (bb - cc) / aa);
            let (lo, hi) = (sa.min(sb).max(0.0), sa.max(sb).min(1.0));
            if lo <= hi {
                0.5 * (lo + hi)
            } else if sa.max(sb) < 0.0 {
                0.0
            } else {
                1.0
            }
        };
        let u0 = (bb * s0 + ff) / ee;
        if u0 < 0.0 {
            midpoint = false;
            (clamp01(-cc / aa), 0.0)
        } else if u0 > 1.0 {
            midpoint = false;
            (clamp01((bb - cc) / aa), 1.0)
        } else {
            (s0, u0)
        }
    };
    let x1p = a1 + d1 * s;
    let x2p = a2 + d2 * u;
    let dd = x1p - x2p;
    let len = dd.norm();
    let scale = 1.0 + r1 + r2;
    let degenerate = !(len > TINY * scale);
    let n = if !degenerate {
        dd / len
    } else {
        let c = d1.cross(&d2);
        let cn = c.norm();
        if cn > TINY * scale * scale {
            c / cn
        } else {
            x2.a * across
        }
    };
    let mut out = Raw { g: len - r1 - r2, n, p1: x1p - n * r1, p2: x2p + n * r2, ..Default::default() };
    if let Some((t1, t2)) = tw {
        // s free: d1·(X1 - X2) = 0; u free: d2·(X1 - X2) = 0; differentiated with
        // Ẋ1 = v1(X1) + ṡ d1, Ẋ2 = v2(X2) + u̇ d2, ḋ1 = ω1 × d1, ḋ2 = ω2 × d2
        let dv = vel(t1, &x1p) - vel(t2, &x2p);
        let (d1d, d2d) = (t1.w.cross(&d1), t2.w.cross(&d2));
        let s_free = aa > 0.0 && s > 0.0 && s < 1.0 && !midpoint;
        let u_free = ee > 0.0 && u > 0.0 && u < 1.0;
        let b1 = -(d1d.dot(&dd) + d1.dot(&dv));
        let b2 = -(d2d.dot(&dd) + d2.dot(&dv));
        let (sd, ud) = match (s_free, u_free) {
            // [A -B; B -E] [ṡ; u̇] = [b1; b2]
            (true, true) => {
                let det = bb * bb - aa * ee;
                ((-ee * b1 + bb * b2) / det, (-bb * b1 + aa * b2) / det)
            }
            (true, false) => (b1 / aa, 0.0),
            (false, true) => (0.0, -b2 / ee),
            (false, false) => (0.0, 0.0),
        };
        let x1d = vel(t1, &x1p) + d1 * sd;
        let x2d = vel(t2, &x2p) + d2 * ud;
        let ddd = x1d - x2d;
        out.nd = if degenerate { t2.w.cross(&n) } else { (ddd - n * n.dot(&ddd)) / len };
        out.p1d = x1d - out.nd * r1;
        out.p2d = x2d + out.nd * r2;
    }
    out
}

/// A sphere (centre on body 1) against a box of body 2. Outside: the closest box point (face,
/// edge or corner region); inside: the nearest face, as a plane.
#[allow(clippy::too_many_arguments)]
fn sphere_box(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    center: &Vec3,
    radius: f64,
    box_center: &Vec3,
    box_rotation: &Mat3,
    half: &Vec3,
) -> Raw {
    let c = x1.point_to_parent(center);
    let ab = x2.a * box_rotation;
    let ob = x2.point_to_parent(box_center);
    let cl = ab.transpose() * (c - ob);
    let q_out = Vec3::from_fn(|k, _| cl[k].clamp(-half[k], half[k]));
    let dl = cl - q_out;
    let len = dl.norm();
    let outside = len > TINY * (1.0 + half.max());
    let (n, q, g) = if outside {
        (ab * (dl / len), q_out, len - radius)
    } else {
        // deepest penetration is through the face nearest to the centre
        let depth = Vec3::from_fn(|k, _| half[k] - cl[k].abs());
        let k = depth.imin();
        let sgn = if cl[k] >= 0.0 { 1.0 } else { -1.0 };
        let mut q = cl;
        q[k] = sgn * half[k];
        (ab.column(k) * sgn, q, -depth[k] - radius)
    };
    let p2 = ob + ab * q;
    let mut out = Raw { g, n, p1: c - n * radius, p2, ..Default::default() };
    if let Some((t1, t2)) = tw {
        // rate of the centre in box coordinates: its velocity relative to body 2's point there
        let cld = ab.transpose() * (vel(t1, &c) - vel(t2, &c));
        let qd = if outside {
            Vec3::from_fn(|k, _| if cl[k].abs() < half[k] { cld[k] } else { 0.0 })
        } else {
            let k = Vec3::from_fn(|k, _| half[k] - cl[k].abs()).imin();
            let mut v = cld;
            v[k] = 0.0;
            v
        };
        out.nd = if outside {
            let dw = ab * dl;
            let ddw = t2.w.cross(&dw) + ab * (cld - qd);
            (ddw - n * n.dot(&ddw)) / len
        } else {
            t2.w.cross(&n)
        };
        out.p1d = vel(t1, &c) - out.nd * radius;
        out.p2d = vel(t2, &p2) + ab * qd;
    }
    out
}

/// Planar circles: the centre line projected on body 2's x-y plane; `P2` is taken at the height
/// of circle 1's centre on the extruded circle 2, so `P1 - P2 = g_N n`.
fn circle_circle(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    c1b: &Vec3,
    r1: f64,
    c2b: &Vec3,
    r2: f64,
) -> Raw {
    let c1 = x1.point_to_parent(c1b);
    let c2 = x2.point_to_parent(c2b);
    let e = x2.a.column(2).into_owned();
    let d = c1 - c2;
    let dp = d - e * d.dot(&e);
    let len = dp.norm();
    let degenerate = !(len > TINY * (1.0 + r1 + r2));
    let n = if degenerate { x2.a.column(0).into_owned() } else { dp / len };
    let mut out = Raw { g: len - r1 - r2, n, p1: c1 - n * r1, p2: c1 - n * (len - r2), ..Default::default() };
    if let Some((t1, t2)) = tw {
        let c1d = vel(t1, &c1);
        let dd = c1d - vel(t2, &c2);
        let ed = t2.w.cross(&e);
        let dpd = dd - e * (dd.dot(&e) + d.dot(&ed)) - ed * d.dot(&e);
        let lend = n.dot(&dpd);
        out.nd = if degenerate { t2.w.cross(&n) } else { (dpd - n * lend) / len };
        out.p1d = c1d - out.nd * r1;
        out.p2d = c1d - n * lend - out.nd * (len - r2);
    }
    out
}

/// An ellipsoid against a half-space (section 2.2.7.2 for a quadric and a plane): with the world
/// shape matrix `S = A1 S_b A1ᵀ` and the plane's normal `m`, the deepest point is the support
/// point `P1 = c - S m / √(mᵀ S m)` (where the ellipsoid's normal is `-m`), `g_N = m·(P1 - p)`.
/// Its rate follows from `Ṡ = ω1 × S - S ω1 ×` and `ṁ = ω2 × m`; the contact point slides over
/// the ellipsoid as it rolls.
fn ellipsoid_half_space(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    center: &Vec3,
    shape: &Mat3,
    point: &Vec3,
    normal: &Vec3,
) -> Raw {
    let c = x1.point_to_parent(center);
    let s = x1.a * shape * x1.a.transpose();
    let m = x2.a * normal;
    let p = x2.point_to_parent(point);
    let sm = s * m;
    let k = m.dot(&sm).sqrt();
    let p1 = c - sm / k;
    let g = m.dot(&(p1 - p));
    let mut out = Raw { g, n: m, p1, p2: p1 - m * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        let md = t2.w.cross(&m);
        // Ṡ m = ω1 × (S m) - S (ω1 × m)
        let sdm = t1.w.cross(&sm) - s * t1.w.cross(&m);
        let smd = sdm + s * md;
        let kd = (m.dot(&sdm) + 2.0 * sm.dot(&md)) / (2.0 * k);
        let p1d = vel(t1, &c) - smd / k + sm * (kd / (k * k));
        let gd = md.dot(&(p1 - p)) + m.dot(&(p1d - vel(t2, &p)));
        out.nd = md;
        out.p1d = p1d;
        out.p2d = p1d - m * gd - md * g;
    }
    out
}

/// The foot point of `y` (ellipsoid frame) on the ellipsoid with semi-axes `a`: `x = (I + t D⁻²)⁻¹ y`
/// with `D = diag(a)` and `t` the root of `Σ (a_i y_i / (a_i² + t))² = 1` above `-min a_i²`
/// (decreasing there: bisection safeguarding Newton). Returns `(x, t)`.
pub(crate) fn ellipsoid_foot(y: &Vec3, a: &Vec3) -> (Vec3, f64) {
    let a2 = a.component_mul(a);
    let f = |t: f64| -> (f64, f64) {
        let mut v = -1.0;
        let mut d = 0.0;
        for i in 0..3 {
            let q = a[i] * y[i] / (a2[i] + t);
            v += q * q;
            d -= 2.0 * q * q / (a2[i] + t);
        }
        (v, d)
    };
    let amin2 = a2.min();
    // bracket: F > 0 just above -amin² unless the point lies on the smallest axis' plane, F < 0 far out
    let mut lo = -amin2 * (1.0 - 1e-15);
    let mut hi = a.max() * y.norm() + a2.max();
    let mut t = if f(0.0).0 > 0.0 { 0.5 * hi } else { 0.5 * lo };
    for _ in 0..200 {
        let (v, d) = f(t);
        if v > 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let newton = t - v / d;
        let next = if d < 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if (next - t).abs() <= 1e-15 * (1.0 + t.abs()) || hi - lo <= 1e-15 * (1.0 + t.abs()) {
            t = next;
            break;
        }
        t = next;
    }
    let k = a2.imin();
    if f(t).0 < -1e-12 && (t - lo).abs() <= 1e-12 * (1.0 + amin2) {
        // no root above -a_k²: the point lies on the smallest axis' plane (y_k = 0) within the
        // medial region (the ellipsoid's centre included); the foot points are off that plane at
        // t = -a_k², x_k = ±a_k √(1 - Σ_{i≠k} (x_i / a_i)²), the + side taken (or y_k's sign)
        let mut x = Vec3::zeros();
        for i in (0..3).filter(|&i| i != k) {
            x[i] = if a2[i] > amin2 { a2[i] * y[i] / (a2[i] - amin2) } else { 0.0 };
        }
        let rest: f64 = (0..3).filter(|&i| i != k).map(|i| (x[i] / a[i]).powi(2)).sum();
        x[k] = if y[k] < 0.0 { -a[k] } else { a[k] } * (1.0 - rest).max(0.0).sqrt();
        return (x, -amin2);
    }
    (Vec3::from_fn(|i, _| a2[i] * y[i] / (a2[i] + t)), t)
}

/// A sphere (centre on body 1, radius `r1`) against an ellipsoid of body 2 (section 2.2.7.2 with
/// one surface a point): the foot point `x` of the centre `y` on the ellipsoid (its frame),
/// `ν = D⁻²x / |D⁻²x|`, `g_N = (y - x)·ν - r1`. The rates solve the differentiated foot
/// conditions `ẏ = (I + t D⁻²) ẋ + ṫ D⁻² x`, `xᵀ D⁻² ẋ = 0` (4 × 4).
#[allow(clippy::too_many_arguments)]
fn sphere_ellipsoid(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    center: &Vec3,
    r1: f64,
    e_center: &Vec3,
    e_rotation: &Mat3,
    semi: &Vec3,
) -> Raw {
    let c = x1.point_to_parent(center);
    let ae = x2.a * e_rotation;
    let ce = x2.point_to_parent(e_center);
    let y = ae.transpose() * (c - ce);
    let (xf, t) = ellipsoid_foot(&y, semi);
    let dinv = Vec3::from_fn(|i, _| 1.0 / (semi[i] * semi[i]));
    let grad = xf.component_mul(&dinv);
    let gl = grad.norm();
    let nu = grad / gl;
    let g = (y - xf).dot(&nu) - r1;
    let n = ae * nu;
    let p1 = c - n * r1;
    let mut out = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        let c1d = vel(t1, &c);
        let yd = ae.transpose() * (c1d - vel(t2, &c));
        let mut m = nalgebra::Matrix4::<f64>::zeros();
        for i in 0..3 {
            m[(i, i)] = 1.0 + t * dinv[i];
            m[(i, 3)] = grad[i];
            m[(3, i)] = grad[i];
        }
        let rhs = nalgebra::Vector4::new(yd.x, yd.y, yd.z, 0.0);
        let sol = m.lu().solve(&rhs).unwrap_or_else(nalgebra::Vector4::zeros);
        let xd = Vec3::new(sol[0], sol[1], sol[2]);
        let gd_l = xd.component_mul(&dinv);
        let nud = (gd_l - nu * nu.dot(&gd_l)) / gl;
        let gd = (yd - xd).dot(&nu) + (y - xf).dot(&nud);
        out.nd = t2.w.cross(&n) + ae * nud;
        out.p1d = c1d - out.nd * r1;
        out.p2d = out.p1d - n * gd - out.nd * g;
    }
    out
}

/// A sphere (centre on body 1, radius `r1`; a point when 0) inside a cavity of body 2: a
/// spherical one (`axis = 0`) or a cylindrical one along `axis`. With `d` the centre's offset from
/// the cavity's centre (or axis), `n = -d/|d|` points from the wall into the cavity,
/// `g_N = r2 - |d| - r1`, `P1 = c1 - r1 n`, `P2 = P1 - g_N n` on the wall. At the centre (axis) the
/// normal is a fixed direction of body 2 ⟂ the axis.
#[allow(clippy::too_many_arguments)]
fn cavity(
    x1: &Pose,
    x2: &Pose,
    tw: Option<(&Motion, &Motion)>,
    c1b: &Vec3,
    r1: f64,
    c2b: &Vec3,
    axis_b: &Vec3,
    r2: f64,
    across: &Vec3,
) -> Raw {
    let c1 = x1.point_to_parent(c1b);
    let c2 = x2.point_to_parent(c2b);
    let a = x2.a * axis_b;
    let e = c1 - c2;
    let d = e - a * a.dot(&e);
    let len = d.norm();
    let degenerate = !(len > TINY * (1.0 + r2));
    let n = if degenerate { x2.a * across } else { -d / len };
    let g = r2 - len - r1;
    let p1 = c1 - n * r1;
    let mut out = Raw { g, n, p1, p2: p1 - n * g, ..Default::default() };
    if let Some((t1, t2)) = tw {
        let c1d = vel(t1, &c1);
        let ed = c1d - vel(t2, &c2);
        let ad = t2.w.cross(&a);
        let dd = ed - ad * a.dot(&e) - a * (ad.dot(&e) + a.dot(&ed));
        let (gd, nd) = if degenerate {
            (0.0, t2.w.cross(&n))
        } else {
            let u = d / len;
            (-u.dot(&dd), -(dd - u * u.dot(&dd)) / len)
        };
        out.nd = nd;
        out.p1d = c1d - nd * r1;
        out.p2d = out.p1d - n * gd - nd * g;
    }
    out
}

/// Fills `out[..pair.candidates()]` with the candidates of `pair` for body 1 at `x1` and body 2
/// at `x2` (world placements). No allocation; an error only when `out` is too short.
pub fn evaluate(pair: &ContactPair, x1: &Pose, x2: &Pose, out: &mut [ContactPoint]) -> Result<()> {
    pair.check_len(out.len())?;
    pair.each_candidate(x1, x2, None, |k, r| {
        let t = pair.tangents(x2, &r.n, None);
        out[k] = ContactPoint { g_n: r.g, n: r.n, p1: r.p1, p2: r.p2, t1: t.t1, t2: t.t2 };
    });
    Ok(())
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod curve_tests;

#[cfg(test)]
mod mesh_tests;

#[cfg(test)]
mod surface_tests;

#[cfg(test)]
mod warm_tests;
