//! The mesh narrow phase (hierarchy walk on its fixed stack, closest features, rates) allocates
//! nothing per evaluation (a counting global allocator, per thread).

use std::sync::Arc;

use mechsys_core::contact::{
    contact_kinematics, evaluate, BodyMotion, ContactKinematics, ContactPair, ContactPoint, Contour,
};
use mechsys_core::geometry::mesh::TriMesh;
use mechsys_core::math::{Mat3, Vec3};
use mechsys_core::spatial::{Motion, Pose};

mod common;
use common::allocations;

#[global_allocator]
static A: common::Counting = common::Counting;

/// A bumpy 40 × 40 terrain (3200 triangles) under a sphere, a box and a capsule at places over
/// faces, edges and vertices, with and without rates: no allocation in 3000 evaluations.
#[test]
fn mesh_evaluation_does_not_allocate() {
    let k = 40;
    let s = |i: usize| -1.0 + 2.0 * i as f64 / k as f64;
    let mut v = Vec::new();
    for j in 0..=k {
        for i in 0..=k {
            v.push(Vec3::new(s(i), s(j), 0.05 * (3.0 * s(i)).sin() * (2.0 * s(j)).cos()));
        }
    }
    let mut t = Vec::new();
    for j in 0..k {
        for i in 0..k {
            let id = |i: usize, j: usize| j * (k + 1) + i;
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let terrain = Contour::Mesh(Arc::new(TriMesh::new(&v, &t, "terrain").unwrap()));
    let pairs = [
        ContactPair::new("s", Contour::Sphere { center: Vec3::zeros(), radius: 0.05 }, terrain.clone()).unwrap(),
        ContactPair::new(
            "b",
            Contour::Box {
                center: Vec3::zeros(),
                rotation: Mat3::identity(),
                half_extents: Vec3::new(0.1, 0.05, 0.03),
            },
            terrain.clone(),
        )
        .unwrap(),
        ContactPair::new("c", terrain, Contour::Capsule { a: -Vec3::x() * 0.1, b: Vec3::x() * 0.1, radius: 0.02 })
            .unwrap(),
    ];
    let mut out = [ContactPoint::default(); 8];
    let mut kin = [ContactKinematics::default(); 8];
    let ground = BodyMotion::GROUND;
    let mut sum = 0.0;
    let before = allocations();
    for it in 0..1000 {
        let x = -0.9 + 1.8 * (it as f64 / 1000.0);
        let r = Vec3::new(x, 0.37 * x, 0.04 + 0.02 * (7.0 * x).sin());
        let a = nalgebra::Rotation3::from_euler_angles(x, 0.5 * x, 2.0 * x).into_inner();
        let body = BodyMotion {
            pose: Pose::new(a, r),
            twist: Motion::new(Vec3::new(0.3, -0.2, 1.0), Vec3::new(0.1, 0.0, -0.5)),
            acc: Motion::ZERO,
        };
        for (p, pair) in pairs.iter().enumerate() {
            // the capsule pair has the mesh first: body 1 is the ground
            let (b1, b2) = if p == 2 { (&ground, &body) } else { (&body, &ground) };
            evaluate(pair, &b1.pose, &b2.pose, &mut out).unwrap();
            contact_kinematics(pair, b1, b2, &mut kin).unwrap();
            sum += out[0].g_n + kin[0].wbar_n;
        }
    }
    let n = allocations() - before;
    assert!(sum.is_finite());
    assert_eq!(n, 0, "{n} allocations in 3000 mesh evaluations");
}
