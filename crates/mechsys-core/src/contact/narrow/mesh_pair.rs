//! Points, spheres, boxes and capsules against a triangle mesh ([`crate::geometry::mesh`]).
//!
//! Body 1 brings body-fixed centres inflated by a radius: a point or a sphere (one centre), a
//! box's eight corners, a capsule's two end spheres; each centre is one candidate. Its contact
//! is the closest point `X` of the mesh to the centre `c` (found through the mesh's hierarchy):
//!
//! - on a face with outward normal `m`: the half-space of that face, `n = m`,
//!   `g_N = m·(c - a) - r` (signed: negative when `c` lies behind the face);
//! - on an edge or at a vertex: `n = σ (c - X)/|c - X|` with `σ = ±1` the side of the feature's
//!   pseudo-normal (`+1` on an open mesh's boundary), `g_N = σ |c - X| - r`. The normal is continuous across the face/edge/vertex
//!   regions (on their borders `c - X` is along the face normal).
//!
//! `P1 = c - r n`, `P2 = X`, so `P1 - P2 = g_N n`. Rates for a fixed feature: the face normal
//! turns with body 2 (`ṅ = ω2 × n`, the half-space rule); on an edge `a + s d`,
//! `s = (c - a)·d / |d|²` and, with `ḋ = ω2 × d` (so `d·ḋ = 0`),
//! `ṡ = ((ċ - ȧ)·d + (c - a)·ḋ) / |d|²`, `Ẋ = ȧ + ṡ d + s ḋ`; at a vertex `Ẋ = ȧ`; then with
//! `e = c - X`, `ṅ = (ė - n (n·ė)) / |e|` (the rate of a unit vector), `Ṗ1 = ċ - r ṅ`,
//! `Ṗ2 = Ẋ`.
//!
//! A box against a mesh touches at its corners only (a box face resting on a mesh vertex or
//! ridge is not seen), a capsule at its end spheres: meshes are meant as the ground, containers
//! and tracks, with the smaller bodies' features landing on them.

use std::sync::Arc;

use crate::geometry::mesh::{Feature, TriMesh};
use crate::math::Vec3;
use crate::spatial::{Motion, Pose};

use super::{half_space, vel, Raw};

/// Centres of body 1 (body frame) inflated by `radius`, against the mesh of body 2.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MeshGeometry {
    pub centers: Vec<Vec3>,
    pub radius: f64,
    pub mesh: Arc<TriMesh>,
}

impl MeshGeometry {
    /// Candidate `k`: centre `k` against the mesh.
    pub(crate) fn one(&self, k: usize, x1: &Pose, x2: &Pose, tw: Option<(&Motion, &Motion)>) -> Raw {
        let c = x1.point_to_parent(&self.centers[k]);
        let y = x2.a.transpose() * (c - x2.r);
        let hit = self.mesh.closest(&y);
        let t = hit.triangle as usize;
        let corners = self.mesh.corners(t);
        let r = self.radius;
        let (a_b, d_b) = match hit.feature {
            Feature::Face => {
                let m = self.mesh.normal(t);
                return half_space(&c, tw.map(|(t1, _)| vel(t1, &c)), r, x2, &corners[0], &m, tw.map(|t| t.1));
            }
            Feature::Edge(j) => {
                let j = j as usize;
                (corners[j], corners[(j + 1) % 3] - corners[j])
            }
            Feature::Vertex(j) => (corners[j as usize], Vec3::zeros()),
        };
        let a = x2.point_to_parent(&a_b);
        let d = x2.a * d_b;
        let dd = d.norm_squared();
        let s = if dd > 0.0 { (c - a).dot(&d) / dd } else { 0.0 };
        let x = a + d * s;
        let e = c - x;
        let len = e.norm();
        let pn = x2.a * self.mesh.pseudo_normal(t, hit.feature);
        // beyond an open mesh's boundary there is no material (see `TriMesh::behind`)
        let sigma = if e.dot(&pn) < 0.0 && !self.mesh.on_boundary(t, hit.feature) { -1.0 } else { 1.0 };
        // on the feature itself (a centre exactly on an edge or vertex): its pseudo-normal
        let degenerate = !(len > 1e-12 * (1.0 + r));
        let n = if degenerate { pn } else { e * (sigma / len) };
        let g = if degenerate { -r } else { sigma * len - r };
        let mut out = Raw { g, n, p1: c - n * r, p2: x, ..Default::default() };
        if let Some((t1, t2)) = tw {
            let cd = vel(t1, &c);
            let ad = vel(t2, &a);
            let ddot = t2.w.cross(&d);
            let sd = if dd > 0.0 { ((cd - ad).dot(&d) + (c - a).dot(&ddot)) / dd } else { 0.0 };
            let xd = ad + d * sd + ddot * s;
            let ed = cd - xd;
            out.nd = if degenerate { t2.w.cross(&n) } else { (ed - n * n.dot(&ed)) * (sigma / len) };
            out.p1d = cd - out.nd * r;
            out.p2d = xd;
        }
        out
    }
}
