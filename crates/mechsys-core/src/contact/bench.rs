//! Micro-benchmark of the narrow phase per pair (ignored; run with
//! `cargo test -p mechsys-core --release --lib contact::bench -- --ignored --nocapture`): the
//! full kinematics and the velocity level, interleaved, on the pairs of a box stack, a box on a
//! plane and a sphere pile, near rest as in a settled run.

use std::hint::black_box;
use std::time::Instant;

use super::kinematics::{contact_kinematics, contact_velocities_warm, BodyMotion, ContactKinematics};
use super::narrow::ContactPair;
use super::test_util::{rot, Rng};
use super::Contour;
use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

/// A body at `r`, turned by `tilt` rad about a random axis, with a small random twist.
fn body(rng: &mut Rng, r: Vec3, tilt: f64) -> BodyMotion {
    let a = if tilt > 0.0 { rot(&rng.unit(), tilt) } else { Mat3::identity() };
    BodyMotion {
        pose: Pose::new(a, r),
        twist: Motion::new(rng.vec3(1e-3), rng.vec3(1e-3)),
        acc: Motion::new(rng.vec3(1.0), rng.vec3(1.0)),
    }
}

/// ns per evaluation of `f`, min over repeats of `calls` calls.
fn time(calls: usize, mut f: impl FnMut()) -> f64 {
    let t0 = Instant::now();
    for _ in 0..calls {
        f();
    }
    t0.elapsed().as_nanos() as f64 / calls as f64
}

#[test]
#[ignore]
fn narrow_phase_per_pair() {
    let mut rng = Rng::new(17);
    let half = Vec3::new(0.1, 0.1, 0.05);
    let cbox = Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: half };
    let plane = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() };
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.05 };
    let ground = BodyMotion::GROUND;
    let scenes: Vec<(&str, ContactPair, BodyMotion, BodyMotion)> = vec![
        (
            "box on box",
            ContactPair::new("bb", cbox.clone(), cbox.clone()).unwrap(),
            body(&mut rng, Vec3::new(1e-4, 0.0, 0.1 - 1e-7), 1e-5),
            body(&mut rng, Vec3::zeros(), 1e-5),
        ),
        (
            "box on box, straddling",
            ContactPair::new("bb", cbox.clone(), cbox.clone()).unwrap(),
            body(&mut rng, Vec3::new(0.105, 0.0, 0.1 - 1e-7), 1e-5),
            body(&mut rng, Vec3::zeros(), 1e-5),
        ),
        (
            "box on plane",
            ContactPair::new("bp", cbox.clone(), plane.clone()).unwrap(),
            body(&mut rng, Vec3::new(0.0, 0.0, 0.05 - 1e-7), 1e-5),
            ground,
        ),
        (
            "sphere on sphere",
            ContactPair::new("ss", ball.clone(), ball.clone()).unwrap(),
            body(&mut rng, Vec3::new(0.01, 0.0, 0.1 - 1e-7), 0.3),
            body(&mut rng, Vec3::zeros(), 0.3),
        ),
        (
            "sphere on plane",
            ContactPair::new("sp", ball.clone(), plane.clone()).unwrap(),
            body(&mut rng, Vec3::new(0.0, 0.0, 0.05 - 1e-7), 0.3),
            ground,
        ),
    ];
    let (calls, repeats) = (20_000, 15);
    for (name, pair, b1, b2) in &scenes {
        let mut out = vec![ContactKinematics::default(); pair.candidates()];
        let (mut full, mut vel) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..repeats {
            full = full.min(time(calls, || {
                contact_kinematics(black_box(pair), black_box(b1), black_box(b2), black_box(&mut out)).unwrap()
            }));
            vel = vel.min(time(calls, || {
                contact_velocities_warm(black_box(pair), black_box(b1), black_box(b2), black_box(&mut out), None)
                    .unwrap()
            }));
        }
        println!("{name:24} full {full:7.1} ns  velocity level {vel:7.1} ns  ratio {:.2}", full / vel);
    }
}
