//! Triangle meshes as contact contours: a body-fixed surface of triangles, validated once, with
//! a static bounding-volume hierarchy for closest-point queries.
//!
//! **Solid side.** Each triangle `(a, b, c)` has the outward normal `(b - a) × (c - a)` (its
//! vertices counter-clockwise seen from outside, the STL/OBJ convention): the solid lies behind
//! the normals. A closed mesh (every edge shared by exactly two triangles) is a solid when wound
//! outward (positive volume) and a cavity (solid outside, a bowl seen from within) when wound
//! inward. An open mesh (a terrain, a track, a bowl's shell) is solid below its surface.
//!
//! **Signed distance.** The closest point `X` of the surface to a point `y` lies in the interior
//! of a face, on an edge or at a vertex. The distance is signed by the side of `y`: the face
//! normal for a face, else the angle-weighted pseudo-normal of the feature (Bærentzen and
//! Aanæs, 2005: the sum of the adjacent face normals for an edge, weighted by the faces' angles
//! at a vertex), which classifies inside and outside correctly for a closed mesh. Beyond the
//! boundary of an open mesh (the closest feature a boundary edge or vertex) there is no material:
//! the solid behind an open mesh is the region whose nearest point lies inside it, so a body
//! passing around the rim of an open bowl is outside. The contact normal is the unit direction
//! `±(y - X)`, which equals the face normal on a face and turns continuously across edges and
//! vertices.
//!
//! **Bounding-volume hierarchy.** A binary tree of axis-aligned boxes over the triangles, built
//! once by splitting at the median of the triangle centroids along the box's longest axis (up to
//! [`LEAF`] triangles per leaf, depth ≈ log₂(n / LEAF)); the nearest-triangle query walks it
//! depth first, nearer child first, and skips every box farther than the best distance so far,
//! on a fixed stack of [`STACK`] nodes (no allocation per query).

use std::collections::HashMap;

use crate::contact::Aabb;
use crate::ensure;
use crate::error::Result;
use crate::math::Vec3;

/// Most triangles in a leaf of the hierarchy.
pub const LEAF: usize = 4;
/// Depth bound of the query stack: a median split halves the triangles per level, so the depth
/// stays below log₂(n) + 2, far below this for any mesh that fits in memory.
pub const STACK: usize = 64;

/// Where on a triangle its closest point lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// The interior of the face.
    Face,
    /// The edge from local vertex `k` to `(k + 1) % 3`.
    Edge(u8),
    /// Local vertex `k`.
    Vertex(u8),
}

/// The result of a closest-point query, body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// Triangle index.
    pub triangle: u32,
    /// Feature of the triangle holding the point.
    pub feature: Feature,
    /// The closest point of the surface.
    pub point: Vec3,
    /// Squared (unsigned) distance from the query point.
    pub dist2: f64,
}

/// A node of the hierarchy: a box and either two children (`count == 0`: the left child follows
/// the node, the right one is at `index`) or a leaf of `count` triangles from `index` in
/// [`TriMesh::order`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    bounds: Aabb,
    index: u32,
    count: u32,
}

/// A validated triangle mesh with its hierarchy (body frame).
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Unit outward face normals.
    normals: Vec<Vec3>,
    /// Pseudo-normal of edge `k` of each triangle (unit).
    edge_normals: Vec<[Vec3; 3]>,
    /// Angle-weighted vertex pseudo-normals (unit; zero for a vertex of no triangle).
    vertex_normals: Vec<Vec3>,
    /// Bit k set: edge k of the triangle is a boundary edge (one triangle only).
    boundary_edges: Vec<u8>,
    /// Whether a vertex lies on a boundary edge.
    boundary_vertices: Vec<bool>,
    nodes: Vec<Node>,
    /// Triangle indices in leaf order.
    order: Vec<u32>,
    closed: bool,
    volume: f64,
}

impl TriMesh {
    /// Validates `vertices` and `triangles` (vertex indices) and builds the hierarchy; errors
    /// start with `what` (e.g. "contacts[0] 'marble'.contour2") and name the triangle, edge or
    /// vertex at fault: no triangles, non-finite vertices, indices out of range, degenerate
    /// (zero-area) triangles, edges of more than two triangles, and neighbours wound in
    /// opposite senses (both running along a shared edge in the same direction).
    ///
    /// # Example
    /// ```
    /// use mechsys_core::geometry::mesh::TriMesh;
    /// use mechsys_core::math::Vec3;
    /// // a unit square floor z = 0, normals up: solid below
    /// let v = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    /// let floor = TriMesh::new(&v, &[[0, 1, 2], [0, 2, 3]], "floor")?;
    /// assert!((floor.signed_distance(&Vec3::new(0.3, 0.6, 0.25)) - 0.25).abs() < 1e-15);
    /// let bad = TriMesh::new(&v, &[[0, 1, 2], [0, 3, 2]], "floor").unwrap_err();
    /// assert!(bad.to_string().contains("floor: triangles 0 and 1 are wound in opposite senses"));
    /// # Ok::<(), mechsys_core::Error>(())
    /// ```
    pub fn new(vertices: &[Vec3], triangles: &[[usize; 3]], what: &str) -> Result<TriMesh> {
        ensure!(!triangles.is_empty(), Model, "{what}: mesh has no triangles");
        ensure!(
            vertices.len() < u32::MAX as usize && triangles.len() < u32::MAX as usize,
            Model,
            "{what}: mesh too large ({} vertices, {} triangles; at most 2³² - 1 each)",
            vertices.len(),
            triangles.len()
        );
        for (i, v) in vertices.iter().enumerate() {
            ensure!(
                v.iter().all(|x| x.is_finite()),
                Model,
                "{what}: vertex {i} must be finite, got {:?}",
                v.as_slice()
            );
        }
        let nv = vertices.len();
        for (t, tri) in triangles.iter().enumerate() {
            for (j, &i) in tri.iter().enumerate() {
                ensure!(
                    i < nv,
                    Model,
                    "{what}: triangle {t} vertex {j} is index {i}, out of range (the mesh has {nv} vertices, 0 to {})",
                    nv.saturating_sub(1)
                );
            }
        }
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for tri in triangles {
            for &i in tri {
                lo = lo.inf(&vertices[i]);
                hi = hi.sup(&vertices[i]);
            }
        }
        let scale = (hi - lo).norm();
        let mut normals = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| vertices[i]);
            let cr = (b - a).cross(&(c - a));
            let area = 0.5 * cr.norm();
            // relative to the mesh's size: a sliver 1e-12 of its extent across has no normal to trust
            ensure!(
                area > 1e-12 * scale * scale && scale > 0.0,
                Model,
                "{what}: triangle {t} (vertices {}, {}, {}) is degenerate: area {area:.3e} m² (zero-area or repeated vertices)",
                tri[0],
                tri[1],
                tri[2]
            );
            normals.push(cr / cr.norm());
        }
        let tris: Vec<[u32; 3]> = triangles.iter().map(|t| t.map(|i| i as u32)).collect();
        // directed edges: a consistently wound 2-manifold runs along each shared edge once each way
        let mut edges: HashMap<(u32, u32), (u32, u8)> = HashMap::with_capacity(3 * tris.len());
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let (i, j) = (tri[k], tri[(k + 1) % 3]);
                if let Some(&(o, _)) = edges.get(&(i, j)) {
                    let shared = edges.contains_key(&(j, i));
                    return Err(crate::Error::Model(if shared {
                        format!(
                            "{what}: edge ({i}, {j}) is shared by more than two triangles ({o}, {t} and another); a mesh contour must be a 2-manifold surface"
                        )
                    } else {
                        format!(
                            "{what}: triangles {o} and {t} are wound in opposite senses (both run from vertex {i} to {j}); \
                             orient every triangle counter-clockwise seen from outside the solid"
                        )
                    }));
                }
                edges.insert((i, j), (t as u32, k as u8));
            }
        }
        let mut closed = true;
        let mut edge_normals = vec![[Vec3::zeros(); 3]; tris.len()];
        let mut boundary_edges = vec![0u8; tris.len()];
        let mut boundary_vertices = vec![false; nv];
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let (i, j) = (tri[k], tri[(k + 1) % 3]);
                let sum = match edges.get(&(j, i)) {
                    Some(&(o, _)) => normals[t] + normals[o as usize],
                    None => {
                        closed = false;
                        boundary_edges[t] |= 1 << k;
                        boundary_vertices[i as usize] = true;
                        boundary_vertices[j as usize] = true;
                        normals[t]
                    }
                };
                let len = sum.norm();
                // two faces folded flat onto each other (a zero-thickness sheet) have no side
                edge_normals[t][k] = if len > 1e-12 { sum / len } else { normals[t] };
            }
        }
        let mut vertex_normals = vec![Vec3::zeros(); nv];
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let p = vertices[tri[k] as usize];
                let (u, w) = (vertices[tri[(k + 1) % 3] as usize] - p, vertices[tri[(k + 2) % 3] as usize] - p);
                let angle = u.cross(&w).norm().atan2(u.dot(&w));
                vertex_normals[tri[k] as usize] += normals[t] * angle;
            }
        }
        for (i, n) in vertex_normals.iter_mut().enumerate() {
            let len = n.norm();
            if len > 1e-12 {
                *n /= len;
            } else if len > 0.0 {
                return Err(crate::Error::Model(format!(
                    "{what}: the triangles at vertex {i} cancel each other's normals (a fold); the solid side there is undefined"
                )));
            }
        }
        // signed volume by the divergence theorem (meaningful for a closed mesh)
        let volume = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i as usize]);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum();
        let mut mesh = TriMesh {
            vertices: vertices.to_vec(),
            triangles: tris,
            normals,
            edge_normals,
            vertex_normals,
            boundary_edges,
            boundary_vertices,
            nodes: Vec::new(),
            order: Vec::new(),
            closed,
            volume,
        };
        mesh.build_hierarchy();
        Ok(mesh)
    }

    /// Vertices (body frame).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// Triangles (vertex indices, counter-clockwise seen from outside the solid).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Unit outward normal of triangle `t`.
    pub fn normal(&self, t: usize) -> Vec3 {
        self.normals[t]
    }

    /// Whether every edge is shared by two triangles.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Signed enclosed volume (m³; > 0 for a closed solid, < 0 for a closed cavity; for an open
    /// mesh the signed volume of the cone from the origin).
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// Box of the triangles, body frame.
    pub fn bounds(&self) -> Aabb {
        self.nodes[0].bounds
    }

    /// Depth of the hierarchy (levels of nodes).
    pub fn depth(&self) -> usize {
        fn walk(nodes: &[Node], i: usize) -> usize {
            let n = &nodes[i];
            if n.count > 0 {
                1
            } else {
                1 + walk(nodes, i + 1).max(walk(nodes, n.index as usize))
            }
        }
        walk(&self.nodes, 0)
    }

    /// The three vertices of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|i| self.vertices[i as usize])
    }

    /// Pseudo-normal of a feature of triangle `t` (unit): the face normal, the edge's or the
    /// vertex's.
    #[inline]
    pub fn pseudo_normal(&self, t: usize, f: Feature) -> Vec3 {
        match f {
            Feature::Face => self.normals[t],
            Feature::Edge(k) => self.edge_normals[t][k as usize],
            Feature::Vertex(k) => self.vertex_normals[self.triangles[t][k as usize] as usize],
        }
    }

    /// Whether a feature of triangle `t` lies on the boundary of an open mesh (an edge of one
    /// triangle only, or a vertex of such an edge).
    #[inline]
    pub fn on_boundary(&self, t: usize, f: Feature) -> bool {
        match f {
            Feature::Face => false,
            Feature::Edge(k) => self.boundary_edges[t] & (1 << k) != 0,
            Feature::Vertex(k) => self.boundary_vertices[self.triangles[t][k as usize] as usize],
        }
    }

    /// Whether `y`, whose closest feature is `f` of triangle `t` at `x`, lies in the solid: behind
    /// the feature's pseudo-normal, except beyond the boundary of an open mesh, where there is no
    /// material (the solid behind an open mesh is the region whose nearest point lies inside it).
    #[inline]
    pub fn behind(&self, t: usize, f: Feature, y: &Vec3, x: &Vec3) -> bool {
        !self.on_boundary(t, f) && (y - x).dot(&self.pseudo_normal(t, f)) < 0.0
    }

    fn build_hierarchy(&mut self) {
        let n = self.triangles.len();
        let centroids: Vec<Vec3> = (0..n)
            .map(|t| {
                let [a, b, c] = self.corners(t);
                (a + b + c) / 3.0
            })
            .collect();
        let boxes: Vec<Aabb> = (0..n)
            .map(|t| {
                let [a, b, c] = self.corners(t);
                Aabb { min: a.inf(&b).inf(&c), max: a.sup(&b).sup(&c) }
            })
            .collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF + 1);
        build(&mut nodes, &mut order, 0, &centroids, &boxes);
        self.nodes = nodes;
        self.order = order;
    }

    /// The closest point of the surface to `y` (body frame). No allocation.
    pub fn closest(&self, y: &Vec3) -> Closest {
        let mut best = Closest { triangle: 0, feature: Feature::Face, point: Vec3::zeros(), dist2: f64::INFINITY };
        let mut stack = [0u32; STACK];
        let mut top = 0usize;
        let mut node = 0usize;
        loop {
            let nd = &self.nodes[node];
            if nd.count > 0 {
                for &t in &self.order[nd.index as usize..(nd.index + nd.count) as usize] {
                    let corners = self.corners(t as usize);
                    // the distance to the triangle's plane bounds it from below: a cheap rejection
                    let h = self.normals[t as usize].dot(&(y - corners[0]));
                    if h * h >= best.dist2 {
                        continue;
                    }
                    let (point, feature) = closest_on_triangle(y, &corners);
                    let d2 = (y - point).norm_squared();
                    if d2 < best.dist2 {
                        best = Closest { triangle: t, feature, point, dist2: d2 };
                    }
                }
            } else {
                let (l, r) = (node + 1, nd.index as usize);
                let (dl, dr) = (box_dist2(&self.nodes[l].bounds, y), box_dist2(&self.nodes[r].bounds, y));
                let (near, dn, far, df) = if dl <= dr { (l, dl, r, dr) } else { (r, dr, l, dl) };
                if df < best.dist2 {
                    debug_assert!(top < STACK, "mesh hierarchy deeper than its stack");
                    stack[top] = far as u32;
                    top += 1;
                }
                if dn < best.dist2 {
                    node = near;
                    continue;
                }
            }
            // pop the next box that can still hold a closer triangle
            loop {
                if top == 0 {
                    return best;
                }
                top -= 1;
                let cand = stack[top] as usize;
                if box_dist2(&self.nodes[cand].bounds, y) < best.dist2 {
                    node = cand;
                    break;
                }
            }
        }
    }

    /// Signed distance of `y` (body frame) to the surface: > 0 on the free side, < 0 in the solid.
    pub fn signed_distance(&self, y: &Vec3) -> f64 {
        let c = self.closest(y);
        let d = c.dist2.sqrt();
        if self.behind(c.triangle as usize, c.feature, y, &c.point) {
            -d
        } else {
            d
        }
    }
}

/// Builds the subtree over `order[first..]` (the slice given) and returns its node index.
fn build(nodes: &mut Vec<Node>, order: &mut [u32], first: usize, centroids: &[Vec3], boxes: &[Aabb]) -> usize {
    let bounds = order.iter().fold(Aabb::EMPTY, |b, &t| b.union(&boxes[t as usize]));
    let me = nodes.len();
    nodes.push(Node { bounds, index: first as u32, count: order.len() as u32 });
    if order.len() <= LEAF {
        return me;
    }
    let cb = order.iter().fold(Aabb::EMPTY, |b, &t| b.union(&Aabb::point(&centroids[t as usize])));
    let axis = (cb.max - cb.min).imax();
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |a, b| centroids[*a as usize][axis].total_cmp(&centroids[*b as usize][axis]));
    let (left, right) = order.split_at_mut(mid);
    build(nodes, left, first, centroids, boxes);
    let r = build(nodes, right, first + mid, centroids, boxes);
    nodes[me].index = r as u32;
    nodes[me].count = 0;
    me
}

/// Squared distance from `y` to the box (0 inside).
#[inline]
fn box_dist2(b: &Aabb, y: &Vec3) -> f64 {
    let d = (b.min - y).sup(&(y - b.max)).sup(&Vec3::zeros());
    d.norm_squared()
}

/// The closest point of the triangle `[a, b, c]` to `y` and its feature. Inside the prism over
/// the face (the barycentric coordinates of `y`'s projection, `n·((b - y) × (c - y)) / |n|²` and
/// its cyclic shifts, all ≥ 0) it is the projection; otherwise it lies on the boundary, the
/// nearest of the three clamped edge projections.
pub fn closest_on_triangle(y: &Vec3, v: &[Vec3; 3]) -> (Vec3, Feature) {
    let n = (v[1] - v[0]).cross(&(v[2] - v[0]));
    let nn = n.norm_squared();
    let bary = |k: usize| n.dot(&(v[(k + 1) % 3] - y).cross(&(v[(k + 2) % 3] - y)));
    let (l0, l1, l2) = (bary(0), bary(1), bary(2));
    if l0 >= 0.0 && l1 >= 0.0 && l2 >= 0.0 {
        return (y - n * (n.dot(&(y - v[0])) / nn), Feature::Face);
    }
    let mut best = (f64::INFINITY, v[0], Feature::Vertex(0));
    for k in 0..3 {
        let (p, d) = (v[k], v[(k + 1) % 3] - v[k]);
        let s = ((y - p).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        let x = p + d * s;
        let d2 = (y - x).norm_squared();
        if d2 < best.0 {
            let f = if s <= 0.0 {
                Feature::Vertex(k as u8)
            } else if s >= 1.0 {
                Feature::Vertex(((k + 1) % 3) as u8)
            } else {
                Feature::Edge(k as u8)
            };
            best = (d2, x, f);
        }
    }
    (best.1, best.2)
}

#[cfg(test)]
#[path = "mesh_tests.rs"]
mod tests;
