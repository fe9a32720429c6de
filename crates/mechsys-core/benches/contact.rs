//! Timings of the contact geometry: narrow phase and broad phase over the "spheres in a box"
//! fixture.
//!
//! Groups:
//! - `narrow/sphere_plane_evaluate/1000`: [`evaluate`] for 1000 sphere–ground pairs (gap,
//!   normal, points, tangents);
//! - `narrow/sphere_plane_kinematics/1000`: [`contact_kinematics`] for the same pairs, moving
//!   (adds `ġ_N`, `ġ_T`, `w̄_N`, `w̄_T`);
//! - `narrow/box_box_evaluate/100`, `narrow/box_box_kinematics/100`: the same two for 100 box–box
//!   pairs (the upper box turned and tilted by up to 0.2 rad over the lower one, overlapping by up
//!   to 1 mm: clipped face manifolds of 4 to 8 points, a few edge–edge points), both boxes moving;
//!   half of the pairs in the reversed order (box of body 2 first);
//! - `broad/sap/N`, N = 1000, 10000: one step of the broad phase for N spheres in a unit box (volume
//!   fraction 0.3) plus its six walls: world boxes from the poses ([`Contour::aabb`]) and
//!   [`SweepAndPrune::update`], alternating between two configurations one small step apart, as
//!   in a simulation (the insertion-sort path);
//! - `broad/sap_cold/N`: the same from an empty broad phase (full sort);
//! - `broad/brute_force/1000`: the O(n²) test of every pair, for comparison.
//!
//! - `narrow_curve/<pair>_evaluate/100`, `narrow_curve/<pair>_kinematics/100`: planar
//!   parametric pairs (roller–cam, circle–ellipse, ellipse–line, ellipse–ellipse) at random
//!   placements near contact, both bodies turning, beside the closed-form circle–circle pair;
//! - `narrow_curve/gears_<z1>_<z2>_<points>_evaluate/100`, `..._kinematics/100`: two involute
//!   gears in mesh (m = 2 mm, backlash 0.05 m each, standard centre distance; 2 points: the drive
//!   and the coast side, 4: each tooth flank), gear 1 at random angles and gear 2 at the
//!   conjugate angle with the drive flanks 10 µm apart, both turning;
//! - `narrow_curve/<pair>_sequence_{cold,warm}/100`: [`contact_kinematics`] along 100
//!   consecutive small relative motions (a cam turning by 2 mrad per evaluation, an ellipse
//!   pair's bodies turning and orbiting near contact by 1-2 mrad, gears turning by 1 mrad), cold
//!   (every evaluation searches) and warm ([`contact_kinematics_warm`] carrying the search state
//!   through the sequence; the jump back to its start searches cold once per 100).
//!
//! - `narrow_surface/<pair>_evaluate/100`, `..._kinematics/100`: spatial parametric pairs
//!   (ellipsoid–ellipsoid apart and overlapping, revolution–plane with an egg-shaped spline profile, sphere–revolution,
//!   sphere–patch and ellipsoid–patch on a 33 × 33 terrain patch) at random placements near contact, both bodies
//!   turning, beside the closed-form sphere–sphere and ellipsoid–plane pairs; every call searches
//!   from scratch (no warm start for the spatial pairs);
//!
//! - `mesh/<pair>_evaluate/100`, `mesh/<pair>_kinematics/100`: sphere–mesh and box–mesh (8
//!   corner queries) on wavy terrains of 98, 10 082 and 100 352 triangles, beside sphere–plane
//!   (`-- mesh` runs them alone);
//!
//! Run with `cargo bench -p mechsys-core --bench contact` (about a minute; `-- --quick` for a
//! rough figure).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

use mechsys_core::contact::{
    contact_kinematics, contact_kinematics_warm, evaluate, Aabb, BodyMotion, ContactKinematics, ContactPair,
    ContactPoint, Contour, SweepAndPrune,
};
use mechsys_core::math::{Mat3, Vec3};
use mechsys_core::spatial::{Motion, Pose};

/// A small deterministic generator (xorshift64*).
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        a + (b - a) * ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// N spheres in the unit box at volume fraction 0.3: centres, radius, and the six walls.
fn spheres_in_a_box(n: usize, rng: &mut Rng) -> (Vec<Vec3>, f64, Vec<Contour>) {
    let r = (0.3 * 3.0 / (4.0 * std::f64::consts::PI * n as f64)).cbrt();
    let c =
        (0..n).map(|_| Vec3::new(rng.uniform(r, 1.0 - r), rng.uniform(r, 1.0 - r), rng.uniform(r, 1.0 - r))).collect();
    let mut walls = Vec::new();
    for k in 0..3 {
        let mut e = Vec3::zeros();
        e[k] = 1.0;
        // solid outside the unit box
        walls.push(Contour::Plane { point: Vec3::zeros(), normal: e });
        walls.push(Contour::Plane { point: e, normal: -e });
    }
    (c, r, walls)
}

fn bench_narrow(c: &mut Criterion) {
    let n = 1000;
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let ground = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() };
    let pairs: Vec<ContactPair> = (0..n)
        .map(|i| {
            let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.05 + 1e-5 * i as f64 };
            ContactPair::new("ball", ball, ground.clone()).expect("valid pair")
        })
        .collect();
    let bodies: Vec<BodyMotion> = (0..n)
        .map(|_| {
            let a = nalgebra::Rotation3::from_euler_angles(
                rng.uniform(-3.0, 3.0),
                rng.uniform(-1.5, 1.5),
                rng.uniform(-3.0, 3.0),
            )
            .into_inner();
            let r = Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(0.0, 0.1));
            let w = Vec3::new(rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0));
            let v = Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)) - w.cross(&r);
            BodyMotion {
                pose: Pose::new(a, r),
                twist: Motion::new(w, v),
                acc: Motion::new(Vec3::zeros(), Vec3::new(0.0, 0.0, -9.81)),
            }
        })
        .collect();
    let mut g = c.benchmark_group("narrow");
    g.throughput(Throughput::Elements(n as u64));
    let mut points = vec![ContactPoint::default(); n];
    g.bench_with_input(BenchmarkId::new("sphere_plane_evaluate", n), &n, |b, _| {
        b.iter(|| {
            for ((p, body), out) in pairs.iter().zip(&bodies).zip(points.iter_mut()) {
                evaluate(p, &body.pose, &Pose::IDENTITY, std::slice::from_mut(out)).expect("room for 1");
            }
            black_box(&points);
        })
    });
    let mut kin = vec![ContactKinematics::default(); n];
    g.bench_with_input(BenchmarkId::new("sphere_plane_kinematics", n), &n, |b, _| {
        b.iter(|| {
            for ((p, body), out) in pairs.iter().zip(&bodies).zip(kin.iter_mut()) {
                contact_kinematics(p, body, &BodyMotion::GROUND, std::slice::from_mut(out)).expect("room for 1");
            }
            black_box(&kin);
        })
    });
    g.finish();
    bench_box_box(c);
    bench_curves(c);
    bench_sequences(c);
    bench_gears(c);
    bench_mesh(c);
    bench_surfaces(c);
}

/// A wavy terrain over [-1, 1]² (z = 0.05 sin 3x cos 2y), `k × k` cells of two triangles each.
fn terrain(k: usize) -> Contour {
    use mechsys_core::geometry::mesh::TriMesh;
    let h = |x: f64, y: f64| 0.05 * (3.0 * x).sin() * (2.0 * y).cos();
    let s = |i: usize| -1.0 + 2.0 * i as f64 / k as f64;
    let mut v = Vec::with_capacity((k + 1) * (k + 1));
    for j in 0..=k {
        for i in 0..=k {
            v.push(Vec3::new(s(i), s(j), h(s(i), s(j))));
        }
    }
    let id = |i: usize, j: usize| j * (k + 1) + i;
    let mut t = Vec::with_capacity(2 * k * k);
    for j in 0..k {
        for i in 0..k {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Contour::Mesh(std::sync::Arc::new(TriMesh::new(&v, &t, "terrain").expect("valid mesh")))
}

/// Spheres (radius 0.05) and boxes (0.1 × 0.08 × 0.06) on terrains of about 100, 10 000 and
/// 100 000 triangles: [`evaluate`] and [`contact_kinematics`] for 100 pairs at random places
/// over the terrain, 0 to 2 cm above its surface, turned at random and moving (the box's 8
/// corners are 8 closest-point queries); sphere–plane beside them.
fn bench_mesh(c: &mut Criterion) {
    let n = 100;
    let mut rng = Rng(0x6d65_7368_0000_0001);
    let mut g = c.benchmark_group("mesh");
    g.throughput(Throughput::Elements(n as u64));
    let bodies: Vec<BodyMotion> = (0..n)
        .map(|_| {
            let a = nalgebra::Rotation3::from_euler_angles(
                rng.uniform(-3.0, 3.0),
                rng.uniform(-1.5, 1.5),
                rng.uniform(-3.0, 3.0),
            )
            .into_inner();
            let (x, y) = (rng.uniform(-0.9, 0.9), rng.uniform(-0.9, 0.9));
            let r = Vec3::new(x, y, 0.05 * (3.0 * x).sin() * (2.0 * y).cos() + 0.05 + rng.uniform(0.0, 0.02));
            let w = Vec3::new(rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0));
            let v = Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)) - w.cross(&r);
            BodyMotion {
                pose: Pose::new(a, r),
                twist: Motion::new(w, v),
                acc: Motion::new(Vec3::zeros(), Vec3::new(0.0, 0.0, -9.81)),
            }
        })
        .collect();
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.05 };
    let cube =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(0.05, 0.04, 0.03) };
    let plane = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() };
    let mut cases = vec![("sphere_plane".to_string(), ball.clone(), plane)];
    for k in [7usize, 71, 224] {
        let t = terrain(k);
        cases.push((format!("sphere_mesh_{}", 2 * k * k), ball.clone(), t.clone()));
        cases.push((format!("box_mesh_{}", 2 * k * k), cube.clone(), t));
    }
    for (name, first, second) in cases {
        let pair = ContactPair::new("p", first, second).expect("valid pair");
        let m = pair.candidates();
        let mut points = vec![ContactPoint::default(); m];
        g.bench_with_input(BenchmarkId::new(format!("{name}_evaluate"), n), &n, |b, _| {
            b.iter(|| {
                for body in &bodies {
                    evaluate(&pair, &body.pose, &Pose::IDENTITY, &mut points).expect("room");
                    black_box(&points);
                }
            })
        });
        let mut kin = vec![ContactKinematics::default(); m];
        g.bench_with_input(BenchmarkId::new(format!("{name}_kinematics"), n), &n, |b, _| {
            b.iter(|| {
                for body in &bodies {
                    contact_kinematics(&pair, body, &BodyMotion::GROUND, &mut kin).expect("room");
                    black_box(&kin);
                }
            })
        });
    }
    g.finish();
}

/// Gear pairs in mesh: [`evaluate`] and [`contact_kinematics`] with 4 candidates per pair.
fn bench_gears(c: &mut Criterion) {
    use mechsys_core::geometry::curve::Curve;
    use mechsys_core::geometry::gear::GearSpec;
    use std::f64::consts::TAU;
    let n = 100;
    let mut rng = Rng(0x9ea2_5eed_0000_0017);
    let mut g = c.benchmark_group("narrow_curve");
    g.throughput(Throughput::Elements(n as u64));
    for (z1, z2, points) in [(17usize, 31usize, 2usize), (18, 31, 4), (40, 97, 2)] {
        let m = 0.002;
        let gear = |z| {
            let spec = GearSpec { backlash: 0.05 * m, ..GearSpec::new(m, z) };
            Curve::gear(&spec, "gear").expect("valid")
        };
        let (g1, g2) = (gear(z1), gear(z2));
        let (q1, q2) = (g1.as_gear().expect("gear").clone(), g2.as_gear().expect("gear").clone());
        let alpha = 20f64.to_radians();
        let a = 0.5 * m * (z1 + z2) as f64;
        // drive flanks (upper flanks of both) on the line of action, 10 µm apart
        let phi1 = q1.base_half_angle() + alpha;
        let phi2 = (a * alpha.sin() - 1e-5 - q1.base_radius() * phi1) / q2.base_radius();
        let c0 = std::f64::consts::PI - alpha + phi2 - q2.base_half_angle();
        let pair = ContactPair::new("mesh", Contour::Curve(Box::new(g1)), Contour::Curve(Box::new(g2)))
            .expect("valid pair")
            .with_points(points)
            .expect("points");
        let rz = |t: f64| nalgebra::Rotation3::from_axis_angle(&Vec3::z_axis(), t).into_inner();
        let bodies: Vec<(BodyMotion, BodyMotion)> = (0..n)
            .map(|_| {
                let t1 = rng.uniform(0.0, TAU);
                let t2 = c0 - (z1 as f64 / z2 as f64) * t1;
                let w = rng.uniform(10.0, 100.0);
                let b1 = BodyMotion {
                    pose: Pose::new(rz(t1), Vec3::zeros()),
                    twist: Motion::new(Vec3::new(0.0, 0.0, w), Vec3::zeros()),
                    acc: Motion::ZERO,
                };
                let r2 = Vec3::new(a, 0.0, 0.0);
                let w2 = Vec3::new(0.0, 0.0, -w * z1 as f64 / z2 as f64);
                let b2 = BodyMotion {
                    pose: Pose::new(rz(t2), r2),
                    twist: Motion::new(w2, -w2.cross(&r2)),
                    acc: Motion::ZERO,
                };
                (b1, b2)
            })
            .collect();
        let mut out = vec![ContactPoint::default(); points * n];
        g.bench_with_input(BenchmarkId::new(format!("gears_{z1}_{z2}_{points}_evaluate"), n), &n, |b, _| {
            b.iter(|| {
                for ((b1, b2), o) in bodies.iter().zip(out.chunks_mut(points)) {
                    evaluate(&pair, &b1.pose, &b2.pose, o).expect("room for the points");
                }
                black_box(&out);
            })
        });
        let mut kin = vec![ContactKinematics::default(); points * n];
        g.bench_with_input(BenchmarkId::new(format!("gears_{z1}_{z2}_{points}_kinematics"), n), &n, |b, _| {
            b.iter(|| {
                for ((b1, b2), o) in bodies.iter().zip(kin.chunks_mut(points)) {
                    contact_kinematics(&pair, b1, b2, o).expect("room for the points");
                }
                black_box(&kin);
            })
        });
    }
    g.finish();
}

/// [`evaluate`] and [`contact_kinematics`] of a one-candidate `pair` at each of the placement
/// pairs `bodies` (`<name>_evaluate/n`, `<name>_kinematics/n`).
fn bench_single(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    pair: &ContactPair,
    bodies: &[(BodyMotion, BodyMotion)],
) {
    let n = bodies.len();
    let mut points = vec![ContactPoint::default(); n];
    g.bench_with_input(BenchmarkId::new(format!("{name}_evaluate"), n), &n, |b, _| {
        b.iter(|| {
            for ((b1, b2), out) in bodies.iter().zip(points.iter_mut()) {
                evaluate(pair, &b1.pose, &b2.pose, std::slice::from_mut(out)).expect("room for 1");
            }
            black_box(&points);
        })
    });
    let mut kin = vec![ContactKinematics::default(); n];
    g.bench_with_input(BenchmarkId::new(format!("{name}_kinematics"), n), &n, |b, _| {
        b.iter(|| {
            for ((b1, b2), out) in bodies.iter().zip(kin.iter_mut()) {
                contact_kinematics(pair, b1, b2, std::slice::from_mut(out)).expect("room for 1");
            }
            black_box(&kin);
        })
    });
}

/// Planar parametric pairs near contact, in plane motion: [`evaluate`] and
/// [`contact_kinematics`] per pair (the global start over the sampled chunks and Newton on the
/// parameters each call; there is no warm start), next to the closed-form circle–circle pair.
fn bench_curves(c: &mut Criterion) {
    use mechsys_core::geometry::curve::{Curve, Follower, Vec2};
    use std::f64::consts::TAU;
    let n = 100;
    let mut rng = Rng(0x5eed_c0de_0000_0001);
    let ellipse = |a, b| Contour::Curve(Box::new(Curve::ellipse(Vec2::zeros(), a, b, 0.0, "e").expect("valid")));
    let ang: Vec<f64> = (0..=360).map(|i| TAU * i as f64 / 360.0).collect();
    let lift: Vec<f64> = ang.iter().map(|t| 0.004 * (1.0 - t.cos())).collect();
    let cam = Contour::Curve(Box::new(
        Curve::cam(&ang, &lift, 0.03, Follower::Roller { radius: 0.01, eccentricity: 0.0 }, 1.0, "cam").expect("valid"),
    ));
    let roller = Contour::Circle { center: Vec2::zeros(), radius: 0.01 };
    let line = Contour::Line { point: Vec2::zeros(), normal: Vec2::y() };
    // (name, contour 1, contour 2, distance between the body origins)
    let cases = [
        ("circle_circle", roller.clone(), Contour::Circle { center: Vec2::zeros(), radius: 0.3 }, 0.31),
        ("circle_ellipse", roller.clone(), ellipse(0.3, 0.2), 0.25),
        ("roller_cam", roller, cam.clone(), 0.045),
        ("ellipse_line", ellipse(0.3, 0.2), line, 0.25),
        ("ellipse_ellipse", ellipse(0.3, 0.2), ellipse(0.25, 0.15), 0.45),
    ];
    let mut g = c.benchmark_group("narrow_curve");
    g.throughput(Throughput::Elements(n as u64));
    for (name, c1, c2, dist) in cases {
        let pair = ContactPair::new(name, c1, c2).expect("valid pair");
        let bodies: Vec<(BodyMotion, BodyMotion)> = (0..n)
            .map(|_| {
                let dir = rng.uniform(0.0, TAU);
                let rz = |t: f64| nalgebra::Rotation3::from_axis_angle(&Vec3::z_axis(), t).into_inner();
                let r = Vec3::new(dir.cos(), dir.sin(), 0.0) * dist;
                let w = Vec3::new(0.0, 0.0, rng.uniform(-5.0, 5.0));
                let b1 = BodyMotion {
                    pose: Pose::new(rz(rng.uniform(-3.0, 3.0)), r),
                    twist: Motion::new(w, Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), 0.0) - w.cross(&r)),
                    acc: Motion::ZERO,
                };
                let b2 = BodyMotion {
                    pose: Pose::new(rz(rng.uniform(-3.0, 3.0)), Vec3::zeros()),
                    twist: Motion::new(Vec3::new(0.0, 0.0, rng.uniform(-5.0, 5.0)), Vec3::zeros()),
                    acc: Motion::ZERO,
                };
                (b1, b2)
            })
            .collect();
        bench_single(&mut g, name, &pair, &bodies);
    }
    g.finish();
}

/// Curve pairs along sequences of small relative motions: every evaluation searching cold vs
/// the search warm-started from the previous evaluation (see the module docs).
fn bench_sequences(c: &mut Criterion) {
    use mechsys_core::contact::SearchHint;
    use mechsys_core::geometry::curve::{Curve, Follower, Vec2};
    use mechsys_core::geometry::gear::GearSpec;
    let n = 100;
    let rz = |t: f64| nalgebra::Rotation3::from_axis_angle(&Vec3::z_axis(), t).into_inner();
    let at = |pose: Pose, w: f64| BodyMotion {
        pose,
        twist: Motion::new(Vec3::new(0.0, 0.0, w), Vec3::zeros()),
        acc: Motion::ZERO,
    };
    let ellipse = |a, b| Contour::Curve(Box::new(Curve::ellipse(Vec2::zeros(), a, b, 0.0, "e").expect("valid")));
    let ang: Vec<f64> = (0..=360).map(|i| std::f64::consts::TAU * i as f64 / 360.0).collect();
    let lift: Vec<f64> = ang.iter().map(|t| 0.004 * (1.0 - t.cos())).collect();
    let cam = Contour::Curve(Box::new(
        Curve::cam(&ang, &lift, 0.03, Follower::Roller { radius: 0.01, eccentricity: 0.0 }, 1.0, "cam").expect("valid"),
    ));
    let roller = Contour::Circle { center: Vec2::zeros(), radius: 0.01 };
    // body 1 near contact with body 2 along direction ψ (its centre distance put at a gap of
    // 0.1 mm by a few cold evaluations), body 1 turned by θ1, body 2 by θ2
    let near = |pair: &ContactPair, psi: f64, t1: f64, t2: f64| {
        let x1 = |d: f64| Pose::new(rz(t1), Vec3::new(d * psi.cos(), d * psi.sin(), 0.0));
        let mut d = 0.5;
        let mut k = vec![ContactKinematics::default(); pair.candidates()];
        for _ in 0..8 {
            contact_kinematics(pair, &at(x1(d), 0.0), &at(Pose::new(rz(t2), Vec3::zeros()), 0.0), &mut k)
                .expect("room");
            d -= k[0].point.g_n - 1e-4;
        }
        (at(x1(d), 1.0), at(Pose::new(rz(t2), Vec3::zeros()), -2.0))
    };
    let mut cases: Vec<(String, ContactPair, Vec<(BodyMotion, BodyMotion)>)> = Vec::new();
    for (name, c1, c2) in [
        ("circle_ellipse", roller.clone(), ellipse(0.3, 0.2)),
        ("roller_cam", roller, cam),
        ("ellipse_ellipse", ellipse(0.3, 0.2), ellipse(0.25, 0.15)),
    ] {
        let pair = ContactPair::new(name, c1, c2).expect("valid pair");
        let seq = (0..n)
            .map(|i| {
                let k = i as f64;
                if name == "roller_cam" {
                    // the follower on its axis, the cam turning by 2 mrad per evaluation
                    near(&pair, std::f64::consts::FRAC_PI_2, 0.0, 0.3 + 2e-3 * k)
                } else {
                    near(&pair, 0.7 + 1e-3 * k, 0.2 + 2e-3 * k, -0.1 - 1e-3 * k)
                }
            })
            .collect();
        cases.push((name.to_string(), pair, seq));
    }
    for (z1, z2) in [(17usize, 31usize), (40, 97)] {
        let m = 0.002;
        let gear = |z| Curve::gear(&GearSpec { backlash: 0.05 * m, ..GearSpec::new(m, z) }, "gear").expect("valid");
        let (g1, g2) = (gear(z1), gear(z2));
        let (q1, q2) = (g1.as_gear().expect("gear").clone(), g2.as_gear().expect("gear").clone());
        let alpha = 20f64.to_radians();
        let a = 0.5 * m * (z1 + z2) as f64;
        let phi1 = q1.base_half_angle() + alpha;
        let phi2 = (a * alpha.sin() - 1e-5 - q1.base_radius() * phi1) / q2.base_radius();
        let c0 = std::f64::consts::PI - alpha + phi2 - q2.base_half_angle();
        let pair = ContactPair::new("mesh", Contour::Curve(Box::new(g1)), Contour::Curve(Box::new(g2)))
            .expect("valid pair")
            .with_points(2)
            .expect("points");
        let seq = (0..n)
            .map(|i| {
                let t1 = 0.1 + 1e-3 * i as f64;
                let t2 = c0 - (z1 as f64 / z2 as f64) * t1;
                (at(Pose::new(rz(t1), Vec3::zeros()), 10.0), at(Pose::new(rz(t2), Vec3::new(a, 0.0, 0.0)), -5.0))
            })
            .collect();
        cases.push((format!("gears_{z1}_{z2}_2"), pair, seq));
    }
    let mut g = c.benchmark_group("narrow_curve");
    g.throughput(Throughput::Elements(n as u64));
    for (name, pair, seq) in &cases {
        let m = pair.candidates();
        let mut kin = vec![ContactKinematics::default(); m];
        g.bench_with_input(BenchmarkId::new(format!("{name}_sequence_cold"), n), &n, |b, _| {
            b.iter(|| {
                for (b1, b2) in seq {
                    contact_kinematics(pair, b1, b2, &mut kin).expect("room");
                }
                black_box(&kin);
            })
        });
        let mut hints = vec![SearchHint::default(); m];
        let mut warm = 0;
        g.bench_with_input(BenchmarkId::new(format!("{name}_sequence_warm"), n), &n, |b, _| {
            b.iter(|| {
                warm = 0;
                for (b1, b2) in seq {
                    contact_kinematics_warm(pair, b1, b2, &mut kin, Some(&mut hints)).expect("room");
                    warm += hints[0].was_warm() as usize;
                }
                black_box(&kin);
            })
        });
        eprintln!("{name}: {warm} of {n} evaluations warm");
    }
    g.finish();
}

/// Spatial parametric pairs near contact, in general 3-D motion: [`evaluate`] and
/// [`contact_kinematics`] per pair (a global start and Newton each call), next to closed forms.
fn bench_surfaces(c: &mut Criterion) {
    use mechsys_core::geometry::curve::{Curve, Solid, Vec2};
    use mechsys_core::geometry::revolution::Revolution;
    use mechsys_core::geometry::surface::Patch;
    use std::f64::consts::TAU;
    let n = 100;
    let mut rng = Rng(0x5eed_5eed_0000_0002);
    let ellipsoid = |a: Vec3| Contour::Ellipsoid { center: Vec3::zeros(), rotation: Mat3::identity(), semi_axes: a };
    let egg_profile: Vec<Vec2> = (0..64)
        .map(|i| TAU * i as f64 / 64.0)
        .map(|t| Vec2::new(0.2 * t.cos(), 0.3 * t.sin() * (1.0 + 0.1 * t.sin())))
        .collect();
    let egg = Contour::Revolution(Box::new(
        Revolution::new(
            Vec3::zeros(),
            Mat3::identity(),
            Curve::spline(&egg_profile, true, Solid::Inside, "egg").expect("valid"),
            "egg",
        )
        .expect("valid"),
    ));
    let grid: Vec<Vec<Vec3>> = (0..33)
        .map(|i| {
            (0..33)
                .map(|j| {
                    let (x, y) = (-1.0 + 2.0 * i as f64 / 32.0, -1.0 + 2.0 * j as f64 / 32.0);
                    Vec3::new(x, y, 0.05 * (3.0 * x).sin() * (2.0 * y).cos())
                })
                .collect()
        })
        .collect();
    let terrain =
        Contour::Patch(Box::new(Patch::new(&grid, (0.0, 1.0), (0.0, 1.0), [false, false], "terrain").expect("valid")));
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.1 };
    let plane = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() };
    // (name, contour 1, contour 2, distance of body 1's origin from body 2's)
    let cases = [
        ("sphere_sphere", ball.clone(), Contour::Sphere { center: Vec3::zeros(), radius: 0.3 }, 0.4),
        ("ellipsoid_plane", ellipsoid(Vec3::new(0.3, 0.2, 0.15)), plane.clone(), 0.25),
        // always apart (extents at most 0.3 + 0.25) and always overlapping (at least 0.15 + 0.15)
        ("ellipsoid_ellipsoid_apart", ellipsoid(Vec3::new(0.3, 0.2, 0.15)), ellipsoid(Vec3::new(0.25, 0.15, 0.2)), 0.6),
        (
            "ellipsoid_ellipsoid_overlap",
            ellipsoid(Vec3::new(0.3, 0.2, 0.15)),
            ellipsoid(Vec3::new(0.25, 0.15, 0.2)),
            0.25,
        ),
        ("revolution_plane", egg.clone(), plane, 0.3),
        ("sphere_revolution", ball.clone(), egg, 0.4),
        ("sphere_patch", ball, terrain.clone(), 0.1),
        ("ellipsoid_patch", ellipsoid(Vec3::new(0.15, 0.1, 0.08)), terrain, 0.15),
    ];
    let mut g = c.benchmark_group("narrow_surface");
    g.throughput(Throughput::Elements(n as u64));
    for (name, c1, c2, dist) in cases {
        let pair = ContactPair::new(name, c1, c2).expect("valid pair");
        let turn = |rng: &mut Rng| {
            let axis = Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
            nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), rng.uniform(-3.0, 3.0))
                .into_inner()
        };
        let ground = name.ends_with("plane") || name.ends_with("patch");
        let bodies: Vec<(BodyMotion, BodyMotion)> = (0..n)
            .map(|_| {
                // above a ground contour, anywhere around a body
                let dir = if ground {
                    Vec3::new(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 1.0).normalize()
                } else {
                    Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)).normalize()
                };
                let r = dir * dist;
                let w = Vec3::new(rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0));
                let b1 = BodyMotion {
                    pose: Pose::new(turn(&mut rng), r),
                    twist: Motion::new(w, Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), 0.0) - w.cross(&r)),
                    acc: Motion::ZERO,
                };
                let b2 = if ground {
                    BodyMotion::GROUND
                } else {
                    BodyMotion {
                        pose: Pose::new(turn(&mut rng), Vec3::zeros()),
                        twist: Motion::new(Vec3::new(rng.uniform(-5.0, 5.0), 0.0, 0.0), Vec3::zeros()),
                        acc: Motion::ZERO,
                    }
                };
                (b1, b2)
            })
            .collect();
        bench_single(&mut g, name, &pair, &bodies);
    }
    g.finish();
}

/// 100 box–box pairs near contact, moving: [`evaluate`] and [`contact_kinematics`] per pair.
fn bench_box_box(c: &mut Criterion) {
    let n = 100;
    let mut rng = Rng(0x0bad_5eed_1234_5678);
    let rot = |axis: Vec3, angle: f64| {
        nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).into_inner()
    };
    let upper =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(0.2, 0.15, 0.1) };
    let lower =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(0.25, 0.2, 0.1) };
    let mut cases = Vec::with_capacity(n);
    for i in 0..n {
        let tilt = Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), 0.0);
        let a = rot(Vec3::z(), rng.uniform(-0.8, 0.8)) * rot(tilt, rng.uniform(0.0, 0.2));
        // the upper box's lowest point 1 mm below the lower box's top face at most
        let low = (0..8)
            .map(|k| {
                let s = |b: usize| if k & (1 << b) != 0 { 1.0 } else { -1.0 };
                (a * Vec3::new(s(0) * 0.2, s(1) * 0.15, s(2) * 0.1)).z
            })
            .fold(f64::INFINITY, f64::min);
        let r = Vec3::new(rng.uniform(-0.15, 0.15), rng.uniform(-0.1, 0.1), 0.1 - low - rng.uniform(0.0, 1e-3));
        let motion = |rng: &mut Rng, pose: Pose| BodyMotion {
            pose,
            twist: Motion::new(
                Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)),
                Vec3::new(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5)),
            ),
            acc: Motion::new(Vec3::zeros(), Vec3::new(0.0, 0.0, -9.81)),
        };
        let (b_up, b_low) = (motion(&mut rng, Pose::new(a, r)), motion(&mut rng, Pose::IDENTITY));
        if i % 2 == 0 {
            cases.push((ContactPair::new("bb", upper.clone(), lower.clone()).expect("valid pair"), b_up, b_low));
        } else {
            cases.push((ContactPair::new("bb", lower.clone(), upper.clone()).expect("valid pair"), b_low, b_up));
        }
    }
    let mut points = [ContactPoint::default(); 8];
    let (mut used, mut touching) = (0, 0);
    for (p, b1, b2) in &cases {
        evaluate(p, &b1.pose, &b2.pose, &mut points).expect("room for 8");
        used += points.iter().filter(|c| c.g_n < 0.1).count();
        touching += usize::from(points.iter().any(|c| c.g_n <= 0.0));
    }
    eprintln!("narrow/box_box: {used} candidates in use over {n} pairs, {touching} pairs overlapping");
    let mut g = c.benchmark_group("narrow");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_with_input(BenchmarkId::new("box_box_evaluate", n), &n, |b, _| {
        b.iter(|| {
            let mut s = 0.0;
            for (p, b1, b2) in &cases {
                evaluate(p, &b1.pose, &b2.pose, &mut points).expect("room for 8");
                s += points[0].g_n;
            }
            black_box(s)
        })
    });
    let mut kin = [ContactKinematics::default(); 8];
    g.bench_with_input(BenchmarkId::new("box_box_kinematics", n), &n, |b, _| {
        b.iter(|| {
            let mut s = 0.0;
            for (p, b1, b2) in &cases {
                contact_kinematics(p, b1, b2, &mut kin).expect("room for 8");
                s += kin[0].wbar_n;
            }
            black_box(s)
        })
    });
    g.finish();
}

fn boxes_into(centres: &[Vec3], ball: &Contour, walls: &[Contour], out: &mut [Aabb]) {
    for (o, c) in out.iter_mut().zip(centres) {
        *o = ball.aabb(&Pose::new(Mat3::identity(), *c));
    }
    for (o, w) in out[centres.len()..].iter_mut().zip(walls) {
        *o = w.aabb(&Pose::IDENTITY);
    }
}

fn bench_broad(c: &mut Criterion) {
    let mut g = c.benchmark_group("broad");
    for n in [1000usize, 10000] {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ n as u64);
        let (centres, r, walls) = spheres_in_a_box(n, &mut rng);
        // one step later: every sphere moved by up to 0.1 r per axis
        let moved: Vec<Vec3> = centres
            .iter()
            .map(|c| c + Vec3::new(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1)) * r)
            .collect();
        let ball = Contour::Sphere { center: Vec3::zeros(), radius: r };
        let mut boxes = vec![Aabb::EMPTY; n + walls.len()];
        let mut sap = SweepAndPrune::with_capacity(boxes.len());
        let mut pairs = Vec::with_capacity(8 * n);
        boxes_into(&centres, &ball, &walls, &mut boxes);
        sap.update(&boxes, &mut pairs);
        g.throughput(Throughput::Elements(n as u64));
        let mut flip = false;
        g.bench_with_input(BenchmarkId::new("sap", n), &n, |b, _| {
            b.iter(|| {
                flip = !flip;
                boxes_into(if flip { &moved } else { &centres }, &ball, &walls, &mut boxes);
                sap.update(&boxes, &mut pairs);
                black_box(pairs.len())
            })
        });
        g.bench_with_input(BenchmarkId::new("sap_cold", n), &n, |b, _| {
            b.iter(|| {
                let mut cold = SweepAndPrune::with_capacity(boxes.len());
                boxes_into(&centres, &ball, &walls, &mut boxes);
                cold.update(&boxes, &mut pairs);
                black_box(pairs.len())
            })
        });
        if n == 1000 {
            g.bench_with_input(BenchmarkId::new("brute_force", n), &n, |b, _| {
                b.iter(|| {
                    boxes_into(&centres, &ball, &walls, &mut boxes);
                    pairs.clear();
                    for i in 0..boxes.len() {
                        for j in i + 1..boxes.len() {
                            if boxes[i].overlaps(&boxes[j]) {
                                pairs.push((i, j));
                            }
                        }
                    }
                    black_box(pairs.len())
                })
            });
        }
        eprintln!("broad/{n}: {} candidate pairs (spheres of radius {r:.4})", pairs.len());
    }
    g.finish();
}

fn config() -> Criterion {
    // small samples: shared 2-core machine
    Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .noise_threshold(0.05)
}

criterion_group! {
    name = benches;
    config = config();
    targets = bench_narrow, bench_broad
}
criterion_main!(benches);
