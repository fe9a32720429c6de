//! The mesh contour against independent references: the projection onto a triangle checked by
//! its variational inequality, the hierarchy's nearest triangle against all triangles, signed
//! distances against the winding number, and validation messages.

use super::*;
use crate::contact::test_util::{icosphere, mesh_sdf, Rng};

/// A unit square floor `z = 0` (two triangles, normals up).
fn floor() -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let v =
        vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    (v, vec![[0, 1, 2], [0, 2, 3]])
}

fn err(v: &[Vec3], t: &[[usize; 3]]) -> String {
    TriMesh::new(v, t, "contour 'm'").unwrap_err().to_string()
}

#[test]
fn validation_names_the_contour_and_the_fault() {
    let (v, t) = floor();
    TriMesh::new(&v, &t, "m").unwrap();
    assert_eq!(err(&v, &[]), "contour 'm': mesh has no triangles");
    let mut bad = v.clone();
    bad[2].y = f64::NAN;
    assert!(err(&bad, &t).starts_with("contour 'm': vertex 2 must be finite"));
    assert!(err(&v, &[[0, 1, 4]])
        .contains("contour 'm': triangle 0 vertex 2 is index 4, out of range (the mesh has 4 vertices"));
    assert!(err(&v, &[[0, 1, 2], [0, 2, 2]]).contains("contour 'm': triangle 1 (vertices 0, 2, 2) is degenerate"));
    // collinear vertices: zero area
    let line = [v[0], v[1], Vec3::new(2.0, 0.0, 0.0), v[3]];
    assert!(err(&line, &[[0, 1, 2], [0, 1, 3]]).contains("triangle 0 (vertices 0, 1, 2) is degenerate"));
    assert!(err(&v, &[[0, 1, 2], [0, 3, 2]])
        .contains("triangles 0 and 1 are wound in opposite senses (both run from vertex 2 to 0)"));
    // a closed mesh with one triangle flipped
    let (s, mut st) = icosphere(1, 1.0);
    st[7].swap(1, 2);
    assert!(err(&s, &st).contains("are wound in opposite senses"));
    // three triangles on one edge
    let fan = [v[0], v[1], Vec3::new(0.5, 1.0, 0.0), Vec3::new(0.5, -1.0, 0.3), Vec3::new(0.5, 0.0, 1.0)];
    assert!(err(&fan, &[[0, 1, 2], [1, 0, 3], [1, 0, 4]]).contains("shared by more than two triangles"));
}

/// The projection `X` of `y` onto a convex set is characterized by `X` in the set and
/// `(y - X)·(z - X) ≤ 0` for every point `z` of it (the vertices suffice for a triangle); the
/// feature reported must hold `X` (interior of the face, of the edge, or the vertex).
#[test]
fn closest_point_on_a_triangle_is_the_projection() {
    let mut rng = Rng::new(11);
    let mut seen = [0usize; 3];
    for it in 0..20000 {
        let tri = [rng.vec3(1.0), rng.vec3(1.0), rng.vec3(1.0)];
        let y = rng.vec3(2.0);
        let (x, f) = closest_on_triangle(&y, &tri);
        let n = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
        if n.norm() < 1e-3 {
            continue;
        }
        // barycentric coordinates of X (it lies in the plane)
        let lam: Vec<f64> =
            (0..3).map(|k| n.dot(&(tri[(k + 1) % 3] - x).cross(&(tri[(k + 2) % 3] - x))) / n.norm_squared()).collect();
        assert!(lam.iter().all(|&l| l > -1e-12) && (lam.iter().sum::<f64>() - 1.0).abs() < 1e-12, "#{it}: {lam:?}");
        for z in &tri {
            assert!((y - x).dot(&(z - x)) <= 1e-12, "#{it}: not the projection");
        }
        match f {
            Feature::Face => {
                seen[0] += 1;
                assert!(lam.iter().all(|&l| l > -1e-12), "#{it}");
            }
            Feature::Edge(k) => {
                seen[1] += 1;
                let k = k as usize;
                // on edge k: the opposite vertex's coordinate vanishes
                assert!(lam[(k + 2) % 3].abs() < 1e-12 && lam[k] > 0.0 && lam[(k + 1) % 3] > 0.0, "#{it}: {lam:?}");
            }
            Feature::Vertex(k) => {
                seen[2] += 1;
                assert!((x - tri[k as usize]).norm() < 1e-15, "#{it}");
            }
        }
    }
    assert!(seen.iter().all(|&n| n > 500), "{seen:?}");
}

/// The hierarchy's nearest triangle against all triangles, for random points near and far from
/// an irregular closed mesh; the signed distance against the winding-number sign.
#[test]
fn hierarchy_finds_the_nearest_triangle_and_the_side() {
    let (mut v, t) = icosphere(3, 1.0);
    let mut rng = Rng::new(3);
    for p in v.iter_mut() {
        *p = p.component_mul(&Vec3::new(1.0, 0.7, 0.5)) * rng.uniform(0.9, 1.1);
    }
    let m = TriMesh::new(&v, &t, "m").unwrap();
    assert!(m.is_closed() && m.volume() > 0.0);
    // median splits: about log2(n / LEAF) + 1 levels
    let bound = ((t.len() as f64 / LEAF as f64).log2().ceil() as usize) + 2;
    assert!(m.depth() <= bound, "depth {} > {bound}", m.depth());
    let (mut inside, mut features) = (0, [0usize; 3]);
    for it in 0..3000 {
        let y = rng.vec3(1.1);
        let c = m.closest(&y);
        let brute = (0..t.len())
            .map(|k| (y - closest_on_triangle(&y, &m.corners(k)).0).norm_squared())
            .fold(f64::INFINITY, f64::min);
        assert!((c.dist2 - brute).abs() <= 1e-12 * brute.max(1e-12), "#{it}: {} vs {brute}", c.dist2);
        let d = m.signed_distance(&y);
        let reference = mesh_sdf(&m, &y);
        assert!((d - reference).abs() < 1e-12, "#{it}: signed distance {d} vs {reference}");
        inside += (d < 0.0) as usize;
        features[match c.feature {
            Feature::Face => 0,
            Feature::Edge(_) => 1,
            Feature::Vertex(_) => 2,
        }] += 1;
    }
    assert!(inside > 200 && inside < 2000, "{inside}");
    assert!(features.iter().all(|&n| n > 20), "{features:?}");
}

/// An inward-wound closed mesh is a cavity: negative volume, positive distance inside.
#[test]
fn inward_winding_makes_a_cavity() {
    let (v, mut t) = icosphere(2, 1.0);
    for tri in t.iter_mut() {
        tri.swap(1, 2);
    }
    let m = TriMesh::new(&v, &t, "bowl").unwrap();
    assert!(m.is_closed() && m.volume() < 0.0);
    assert!(m.signed_distance(&Vec3::new(0.1, 0.2, -0.3)) > 0.5);
    assert!(m.signed_distance(&Vec3::new(1.5, 0.0, 0.0)) < -0.4);
    let (f, ft) = floor();
    let open = TriMesh::new(&f, &ft, "floor").unwrap();
    assert!(!open.is_closed());
    assert!((open.signed_distance(&Vec3::new(0.5, 0.2, -0.1)) + 0.1).abs() < 1e-15);
    // beyond the edge x = 1 the floor's edge gives the distance; there is no material there, above
    // or below the floor's plane
    let d = open.signed_distance(&Vec3::new(1.3, 0.5, 0.4));
    assert!((d - 0.5).abs() < 1e-15, "{d}");
    let d = open.signed_distance(&Vec3::new(1.3, 0.5, -0.4));
    assert!((d - 0.5).abs() < 1e-15, "{d}");
    // beyond the corner (1, 1): the corner vertex, also free
    let d = open.signed_distance(&Vec3::new(1.3, 1.4, -0.6));
    assert!((d - 0.61f64.sqrt()).abs() < 1e-15, "{d}");
    // under the floor, within it: inside
    assert!((open.signed_distance(&Vec3::new(0.9, 0.5, -0.4)) + 0.4).abs() < 1e-15);
}
