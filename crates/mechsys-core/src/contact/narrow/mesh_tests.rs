//! Mesh pairs against the analytic primitives they tessellate: a plane (exact), a spherical
//! cavity (gap error of the order of the sagitta h²/(8R), falling fourfold per halving of h),
//! and a box resting on a mesh floor on its four lower corners.

use super::*;
use crate::contact::test_util::{icosphere, mesh_contour, rot, Rng};

fn eval(pair: &ContactPair, x1: &Pose, x2: &Pose) -> Vec<ContactPoint> {
    let mut out = vec![ContactPoint::default(); pair.candidates()];
    evaluate(pair, x1, x2, &mut out).unwrap();
    out
}

/// A square grid of `n × n` cells of side `2 half / n` in the plane z = `height`, split into
/// triangles along alternating diagonals, normals up.
fn grid(n: usize, half: f64, height: f64) -> Contour {
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let s = |k: usize| -half + 2.0 * half * k as f64 / n as f64;
            v.push(Vec3::new(s(i), s(j), height));
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                t.extend([[a, b, c], [a, c, d]]);
            } else {
                t.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    mesh_contour(&v, &t)
}

/// Over a tessellated plane, spheres and points get the plane's gap, normal and points exactly,
/// at any placement of both bodies (the floor on a turned, moving body 2 too).
#[test]
fn sphere_and_point_on_a_tessellated_plane_match_the_plane() {
    let mut rng = Rng::new(21);
    let floor = grid(8, 1.0, 0.1);
    let plane = Contour::Plane { point: Vec3::new(0.0, 0.0, 0.1), normal: Vec3::z() };
    for first in
        [Contour::Sphere { center: Vec3::new(0.02, 0.0, 0.01), radius: 0.15 }, Contour::Point { p: Vec3::zeros() }]
    {
        let mesh_pair = ContactPair::new("m", first.clone(), floor.clone()).unwrap();
        let plane_pair = ContactPair::new("p", first.clone(), plane.clone()).unwrap();
        for it in 0..200 {
            let x2 = Pose::new(rng.rotation(), rng.vec3(0.5));
            // above (or slightly into) the floor, within its extent
            let local = Vec3::new(rng.uniform(-0.9, 0.9), rng.uniform(-0.9, 0.9), 0.1 + rng.uniform(-0.1, 0.5));
            let x1 = Pose::new(rng.rotation(), x2.point_to_parent(&local));
            let (m, p) = (eval(&mesh_pair, &x1, &x2)[0], eval(&plane_pair, &x1, &x2)[0]);
            assert!((m.g_n - p.g_n).abs() < 1e-12, "#{it}: {} vs {}", m.g_n, p.g_n);
            assert!(
                (m.n - p.n).norm() < 1e-12 && (m.p1 - p.p1).norm() < 1e-12 && (m.p2 - p.p2).norm() < 1e-12,
                "#{it}"
            );
        }
    }
}

/// A ball in an icosphere cavity of radius R (vertices on the sphere, wound inward) against the
/// analytic bowl: the faces lie inside the sphere, so the mesh's gap is smaller by at most the
/// largest sagitta ≈ ρ²/(2R) (ρ a face's circumradius), never larger; the worst error over random
/// positions falls about fourfold per subdivision (the edges halve): O(h²).
#[test]
fn ball_in_a_tessellated_cavity_converges_to_the_bowl_at_second_order() {
    let big_r = 0.5;
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.05 };
    let bowl = ContactPair::new("b", ball.clone(), Contour::Bowl { center: Vec3::zeros(), radius: big_r }).unwrap();
    let mut worst = Vec::new();
    for level in 2..=5 {
        let (v, mut t) = icosphere(level, big_r);
        for tri in t.iter_mut() {
            tri.swap(1, 2);
        }
        // the polyhedron holds the ball of radius √(R² - ρ²) (ρ the largest circumradius of a
        // face, whose vertices lie on the sphere): the gap is short by at most R - √(R² - ρ²)
        let rho = t
            .iter()
            .map(|tri| {
                let [a, b, c] = tri.map(|i| v[i]);
                (b - a).norm() * (c - b).norm() * (a - c).norm() / (2.0 * (b - a).cross(&(c - a)).norm())
            })
            .fold(0.0, f64::max);
        let sagitta = big_r - (big_r * big_r - rho * rho).sqrt();
        let pair = ContactPair::new("m", ball.clone(), mesh_contour(&v, &t)).unwrap();
        let mut rng = Rng::new(4);
        let mut err: f64 = 0.0;
        for it in 0..2000 {
            // centres from the middle out to touching and slightly beyond
            let c = rng.unit() * rng.uniform(0.0, big_r - 0.04);
            let x1 = Pose::new(Mat3::identity(), c);
            let (m, b) = (eval(&pair, &x1, &Pose::IDENTITY)[0], eval(&bowl, &x1, &Pose::IDENTITY)[0]);
            let e = b.g_n - m.g_n;
            assert!(e >= -1e-12, "level {level} #{it}: the mesh's gap {} exceeds the bowl's {}", m.g_n, b.g_n);
            assert!(e <= sagitta + 1e-12, "level {level} #{it}: error {e} above the sagitta {sagitta}");
            // the normal points into the cavity, towards the ball
            assert!(m.n.dot(&-c) >= 0.0 || c.norm() < 0.05, "level {level} #{it}: normal {:?}", m.n);
            err = err.max(e);
        }
        worst.push(err);
    }
    for k in 1..worst.len() {
        let ratio = worst[k - 1] / worst[k];
        assert!(ratio > 3.5 && ratio < 4.5, "error ratio per subdivision {ratio} ({worst:?})");
    }
}

/// A box resting flat on a mesh floor (its bottom 0.2 × 0.3, turned about z, corners inside
/// triangles or on their edges): the four lower corners touch with the floor's normal, the upper
/// four are open by the box's height.
#[test]
fn box_on_a_mesh_floor_touches_at_four_corners() {
    let floor = grid(6, 1.0, 0.0);
    let cube =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(0.1, 0.15, 0.05) };
    let pair = ContactPair::new("box", cube.clone(), floor).unwrap();
    assert_eq!(pair.candidates(), 8);
    for (k, angle) in [0.0, 0.3, 1.1].iter().enumerate() {
        let x1 = Pose::new(rot(&Vec3::z(), *angle), Vec3::new(0.1 * k as f64, -0.05, 0.05));
        let cs = eval(&pair, &x1, &Pose::IDENTITY);
        let touching: Vec<_> = cs.iter().filter(|c| c.g_n.abs() < 1e-14).collect();
        assert_eq!(touching.len(), 4, "{cs:?}");
        assert!(touching.iter().all(|c| (c.n - Vec3::z()).norm() < 1e-14 && c.p2.z.abs() < 1e-14));
        assert!(cs.iter().filter(|c| (c.g_n - 0.1).abs() < 1e-14).count() == 4);
    }
    // reversed: the same contacts seen from the floor
    let rev = ContactPair::new("r", grid(6, 1.0, 0.0), cube).unwrap();
    let x1 = Pose::new(Mat3::identity(), Vec3::new(0.0, 0.0, 0.04));
    let cs = eval(&rev, &Pose::IDENTITY, &x1);
    assert!(cs.iter().filter(|c| (c.g_n + 0.01).abs() < 1e-14 && (c.n + Vec3::z()).norm() < 1e-14).count() == 4);
}

/// Over an edge and a vertex of a convex mesh (a cube of triangles) the normal turns from one
/// face's to the other's through the feature direction, continuously, and the gap is the
/// distance to the nearest feature.
#[test]
fn normal_is_continuous_across_edges_and_vertices() {
    let v: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { -0.5 } else { 0.5 },
                if i & 2 == 0 { -0.5 } else { 0.5 },
                if i & 4 == 0 { -0.5 } else { 0.5 },
            )
        })
        .collect();
    // two triangles per face, counter-clockwise seen from outside
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let t: Vec<[usize; 3]> = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    let cube = mesh_contour(&v, &t);
    let Contour::Mesh(m) = &cube else { unreachable!() };
    assert!(m.is_closed() && (m.volume() - 1.0).abs() < 1e-14);
    let pair = ContactPair::new("p", Contour::Point { p: Vec3::zeros() }, cube).unwrap();
    // around the edge x = z = 0.5 on a circle of radius 0.2 and across the corner (0.5, 0.5, 0.5)
    let mut last: Option<Vec3> = None;
    for i in 0..=400 {
        let phi = -0.3 + (std::f64::consts::FRAC_PI_2 + 0.6) * i as f64 / 400.0;
        let p = Vec3::new(0.5 + 0.2 * phi.sin(), 0.1, 0.5 + 0.2 * phi.cos());
        let c = eval(&pair, &Pose::new(Mat3::identity(), p), &Pose::IDENTITY)[0];
        // the distance to the box [-0.5, 0.5]³, independently
        let q = p.abs() - Vec3::repeat(0.5);
        let d = q.sup(&Vec3::zeros()).norm() + q.max().min(0.0);
        assert!((c.g_n - d).abs() < 1e-14, "{i}: {} vs {d}", c.g_n);
        if let Some(l) = last {
            assert!((c.n - l).norm() < 0.01, "{i}: normal jumps from {l:?} to {:?}", c.n);
        }
        last = Some(c.n);
    }
    let c = eval(&pair, &Pose::new(Mat3::identity(), Vec3::repeat(0.6)), &Pose::IDENTITY)[0];
    assert!((c.n - Vec3::repeat(1.0).normalize()).norm() < 1e-14 && (c.g_n - 0.1 * 3f64.sqrt()).abs() < 1e-14);
}

/// Beyond an open mesh's boundary there is no material: a ball beside a floor's edge, below its
/// plane, is open by its distance to the edge; under the floor it penetrates.
#[test]
fn beyond_an_open_mesh_boundary_is_free() {
    let floor = grid(4, 1.0, 0.0);
    let pair = ContactPair::new("f", Contour::Sphere { center: Vec3::zeros(), radius: 0.1 }, floor).unwrap();
    let c = eval(&pair, &Pose::new(Mat3::identity(), Vec3::new(1.3, 0.2, -0.4)), &Pose::IDENTITY)[0];
    assert!((c.g_n - (0.5 - 0.1)).abs() < 1e-14 && (c.n - Vec3::new(0.6, 0.0, -0.8)).norm() < 1e-14, "{c:?}");
    assert!((c.p2 - Vec3::new(1.0, 0.2, 0.0)).norm() < 1e-14);
    let c = eval(&pair, &Pose::new(Mat3::identity(), Vec3::new(0.9, 0.2, -0.05)), &Pose::IDENTITY)[0];
    assert!((c.g_n + 0.15).abs() < 1e-14 && c.n == Vec3::z(), "{c:?}");
}
