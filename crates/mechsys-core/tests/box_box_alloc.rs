//! The box–box narrow phase (separating axes, clipping, rates) allocates nothing per evaluation
//! (a counting global allocator, per thread).

use mechsys_core::contact::{
    contact_kinematics, evaluate, BodyMotion, ContactKinematics, ContactPair, ContactPoint, Contour,
};
use mechsys_core::math::{Mat3, Vec3};
use mechsys_core::spatial::{Motion, Pose};

mod common;
use common::allocations;

#[global_allocator]
static A: common::Counting = common::Counting;

/// Face manifolds (4 and 8 points, clipped), the edge–edge point and the empty-clip fallback,
/// with and without rates: no allocation in 4000 evaluations.
#[test]
fn box_box_evaluation_does_not_allocate() {
    let cube = |h: f64, r: Mat3| Contour::Box { center: Vec3::zeros(), rotation: r, half_extents: Vec3::repeat(h) };
    let rot = |axis: Vec3, angle: f64| {
        nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).into_inner()
    };
    let q = std::f64::consts::FRAC_PI_4;
    let pairs = [
        ContactPair::new("a", cube(0.1, Mat3::identity()), cube(0.1, Mat3::identity())).unwrap(),
        ContactPair::new("b", cube(0.1, rot(Vec3::x(), q)), cube(0.15, rot(Vec3::y(), q))).unwrap(),
    ];
    let poses = [
        Pose::new(Mat3::identity(), Vec3::new(0.0, 0.0, 0.2)),
        Pose::new(rot(Vec3::z(), q), Vec3::new(0.01, 0.0, 0.2)),
        Pose::new(rot(Vec3::new(1.0, 0.3, 0.0), 0.2), Vec3::new(0.15, 0.05, 0.21)),
        Pose::new(rot(Vec3::z(), 0.2), Vec3::new(0.0, 0.0, 0.35)),
    ];
    let mut out = [ContactPoint::default(); 8];
    let mut kin = [ContactKinematics::default(); 8];
    let b2 = BodyMotion {
        pose: Pose::IDENTITY,
        twist: Motion::new(Vec3::new(0.1, 0.0, 0.2), Vec3::zeros()),
        acc: Motion::ZERO,
    };
    let mut sum = 0.0;
    let before = allocations();
    for k in 0..500 {
        for pair in &pairs {
            for x in &poses {
                let x = Pose::new(x.a, x.r + Vec3::new(1e-6 * k as f64, 0.0, 0.0));
                evaluate(pair, &x, &Pose::IDENTITY, &mut out).unwrap();
                let b1 = BodyMotion {
                    pose: x,
                    twist: Motion::new(Vec3::new(0.0, 0.3, 0.0), Vec3::new(0.0, 0.0, -1.0)),
                    acc: Motion::ZERO,
                };
                contact_kinematics(pair, &b1, &b2, &mut kin).unwrap();
                sum += out[0].g_n + kin[0].wbar_n;
            }
        }
    }
    assert_eq!(allocations() - before, 0);
    assert!(sum.is_finite());
}
