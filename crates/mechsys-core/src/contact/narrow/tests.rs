//! Narrow phase against independent geometry: signed distances of the contours, brute-force
//! minima, concrete configurations with known answers, and the swapped order.

use super::*;
use crate::contact::contour::Vec2;
use crate::contact::test_util::{close, random_poses, rot, sample, sdf, Rng, PAIRS};

fn eval(pair: &ContactPair, x1: &Pose, x2: &Pose) -> Vec<ContactPoint> {
    let mut out = vec![ContactPoint::default(); pair.candidates()];
    evaluate(pair, x1, x2, &mut out).unwrap();
    out
}

fn pose(r: Vec3) -> Pose {
    Pose::new(Mat3::identity(), r)
}

/// Numerical gradient of the signed distance (central differences).
fn grad(c: &Contour, x: &Pose, p: &Vec3) -> Vec3 {
    let h = 1e-7;
    Vec3::from_fn(|k, _| {
        let mut e = Vec3::zeros();
        e[k] = h;
        (sdf(c, x, &(p + e)) - sdf(c, x, &(p - e))) / (2.0 * h)
    })
}

/// Contours whose surface is smooth at every contact point they produce.
fn smooth(c: &Contour) -> bool {
    matches!(
        c,
        Contour::Sphere { .. }
            | Contour::Capsule { .. }
            | Contour::Circle { .. }
            | Contour::Plane { .. }
            | Contour::Line { .. }
    )
}

/// Minimum of a function convex on [0, 1] (golden-section search).
fn argmin01(f: impl Fn(f64) -> f64) -> f64 {
    argmin01_n(f, 200)
}

/// The same with `iters` golden-section steps (0.618^iters of the interval).
fn argmin01_n(f: impl Fn(f64) -> f64, iters: usize) -> f64 {
    let (mut a, mut b) = (0.0, 1.0);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..iters {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if f(c) < f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    f(0.5 * (a + b))
}

#[test]
fn candidate_counts_and_unsupported_pairs() {
    let expect =
        [1, 1, 8, 2, 2, 1, 1, 5, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 8, 2];
    for ((a, b), n) in PAIRS.iter().zip(expect) {
        let (c1, c2) = (sample(a), sample(b));
        assert_eq!(candidates(&c1, &c2).unwrap(), n, "{a}–{b}");
        assert_eq!(candidates(&c2, &c1).unwrap(), n, "{b}–{a}");
    }
    // box–box: the clipped incident face has at most eight vertices
    assert_eq!(candidates(&sample("box"), &sample("box_b")).unwrap(), 8);
    for (a, b) in [
        ("cylinder", "box"),
        ("plane", "plane"),
        ("circle", "plane"),
        ("sphere", "line"),
        ("polygon", "circle"),
        ("point", "point"),
    ] {
        let e = candidates(&sample(a), &sample(b)).unwrap_err().to_string();
        assert!(e.contains(&format!("{}–{}", sample(a).kind(), sample(b).kind())), "{e}");
    }
    let e = ContactPair::new("c", sample("box"), sample("cylinder")).unwrap_err().to_string();
    assert!(e.starts_with("contact 'c': no contact geometry for the contour pair box–cylinder"), "{e}");
    let e = ContactPair::new("tip", Contour::Circle { center: Vec2::zeros(), radius: 0.0 }, sample("line"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("contact 'tip': contour 1 (circle): circle radius must be > 0"), "{e}");
    let pair = ContactPair::new("c", sample("box"), sample("plane")).unwrap();
    let mut short = [ContactPoint::default(); 7];
    let e = evaluate(&pair, &Pose::IDENTITY, &Pose::IDENTITY, &mut short).unwrap_err().to_string();
    assert!(e.contains("room for 7 candidates, needs 8"), "{e}");
}

/// Known answers with signs: each would flip under a sign error in n, g or the points.
#[test]
fn concrete_configurations() {
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.5 };
    let ground = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() };
    let pair = ContactPair::new("b", ball.clone(), ground.clone()).unwrap();
    let c = eval(&pair, &pose(Vec3::new(1.0, 2.0, 3.0)), &Pose::IDENTITY)[0];
    assert_eq!((c.g_n, c.n, c.p1, c.p2), (2.5, Vec3::z(), Vec3::new(1.0, 2.0, 2.5), Vec3::new(1.0, 2.0, 0.0)));
    // the plane on body 1: n points from the ball (contour 2) to the plane (contour 1)
    let flipped = ContactPair::new("b", ground, ball.clone()).unwrap();
    let c = eval(&flipped, &Pose::IDENTITY, &pose(Vec3::new(1.0, 2.0, 3.0)))[0];
    assert_eq!((c.g_n, c.n, c.p1, c.p2), (2.5, -Vec3::z(), Vec3::new(1.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 2.5)));
    // two balls on the x axis, overlapping by 0.25
    let b2 = Contour::Sphere { center: Vec3::zeros(), radius: 0.25 };
    let pair = ContactPair::new("bb", ball.clone(), b2).unwrap();
    let c = eval(&pair, &pose(Vec3::new(0.5, 0.0, 0.0)), &Pose::IDENTITY)[0];
    assert!((c.g_n + 0.25).abs() < 1e-15 && c.n == Vec3::x());
    assert_eq!((c.p1, c.p2), (Vec3::zeros(), Vec3::new(0.25, 0.0, 0.0)));
    // a unit cube resting 0.1 above the ground, turned about z: four corners at 0.1, four at 1.1
    let cube = Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::repeat(0.5) };
    let pair =
        ContactPair::new("cube", cube.clone(), Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() }).unwrap();
    let mut g: Vec<f64> = eval(&pair, &Pose::new(rot(&Vec3::z(), 0.3), Vec3::new(0.0, 0.0, 0.6)), &Pose::IDENTITY)
        .iter()
        .map(|c| c.g_n)
        .collect();
    g.sort_by(f64::total_cmp);
    for (k, gk) in g.iter().enumerate() {
        assert!((gk - if k < 4 { 0.1 } else { 1.1 }).abs() < 1e-14);
    }
    // a ball beside a box face, at an edge and at a corner
    let pair = ContactPair::new("sb", ball.clone(), cube).unwrap();
    let c = eval(&pair, &pose(Vec3::new(2.0, 0.1, 0.2)), &Pose::IDENTITY)[0];
    assert!((c.g_n - 1.0).abs() < 1e-15 && c.n == Vec3::x() && c.p2 == Vec3::new(0.5, 0.1, 0.2));
    let c = eval(&pair, &pose(Vec3::new(1.5, 1.5, 0.0)), &Pose::IDENTITY)[0];
    assert!((c.g_n - (2f64.sqrt() - 0.5)).abs() < 1e-15 && c.p2 == Vec3::new(0.5, 0.5, 0.0));
    // centre inside, nearest face -y: n = -y, depth 0.2 + radius
    let c = eval(&pair, &pose(Vec3::new(0.1, -0.3, 0.0)), &Pose::IDENTITY)[0];
    assert!((c.g_n + 0.7).abs() < 1e-15 && c.n == -Vec3::y() && c.p2 == Vec3::new(0.1, -0.5, 0.0));
    // crossing capsules, one above the other by 1: g = 1 - 0.2 - 0.3
    let cx = Contour::Capsule { a: Vec3::new(-1.0, 0.0, 0.0), b: Vec3::new(1.0, 0.0, 0.0), radius: 0.2 };
    let cy = Contour::Capsule { a: Vec3::new(0.0, -1.0, 0.0), b: Vec3::new(0.0, 1.0, 0.0), radius: 0.3 };
    let pair = ContactPair::new("cc", cx, cy).unwrap();
    let c = eval(&pair, &pose(Vec3::new(0.2, 0.3, 1.0)), &Pose::IDENTITY)[0];
    assert!((c.g_n - 0.5).abs() < 1e-15 && (c.n - Vec3::z()).norm() < 1e-15, "{c:?}");
    assert!((c.p1 - Vec3::new(0.0, 0.3, 0.8)).norm() < 1e-15 && (c.p2 - Vec3::new(0.0, 0.3, 0.3)).norm() < 1e-15);
    // a cylinder lying on its side (axis x) 0.1 above the ground: both rims touch at 0.1
    let cyl = Contour::Cylinder { center: Vec3::zeros(), axis: Vec3::x(), radius: 0.3, half_length: 0.5 };
    let pair =
        ContactPair::new("cyl", cyl.clone(), Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() }).unwrap();
    let cs = eval(&pair, &pose(Vec3::new(0.0, 0.0, 0.4)), &Pose::IDENTITY);
    assert!(cs.iter().all(|c| (c.g_n - 0.1).abs() < 1e-15));
    assert!(
        (cs[0].p1 - Vec3::new(0.5, 0.0, 0.1)).norm() < 1e-15 && (cs[1].p1 - Vec3::new(-0.5, 0.0, 0.1)).norm() < 1e-15
    );
    // tilted by 0.2 about y: each rim's lowest point, 1 + (±h) a_z - R √(1 - a_z²)
    let tilt = rot(&Vec3::y(), 0.2);
    let cs = eval(&pair, &Pose::new(tilt, Vec3::new(0.0, 0.0, 1.0)), &Pose::IDENTITY);
    let a = tilt * Vec3::x();
    let low = |s: f64| 1.0 + s * 0.5 * a.z - 0.3 * (1.0 - a.z * a.z).sqrt();
    assert!((cs[0].g_n - low(1.0)).abs() < 1e-15 && (cs[1].g_n - low(-1.0)).abs() < 1e-15);
    // planar: a disc of radius 0.5 at (2, 1) against the wall x ≤ 0.3 (normal +x): n = +x,
    // t1 = e_z × n = +y
    let disc = Contour::Circle { center: Vec2::zeros(), radius: 0.5 };
    let wall = Contour::Line { point: Vec2::new(0.3, 0.0), normal: Vec2::new(1.0, 0.0) };
    let pair = ContactPair::new("tip", disc, wall).unwrap();
    assert_eq!(pair.tangent_dim(), 1);
    let c = eval(&pair, &pose(Vec3::new(2.0, 1.0, 0.0)), &Pose::IDENTITY)[0];
    assert!((c.g_n - 1.2).abs() < 1e-15 && c.n == Vec3::x() && c.t1 == Vec3::y() && c.t2 == Vec3::z());
    assert!((c.p1 - Vec3::new(1.5, 1.0, 0.0)).norm() < 1e-15 && (c.p2 - Vec3::new(0.3, 1.0, 0.0)).norm() < 1e-15);
}

/// At random configurations of every pair: P1 on contour 1, P2 on contour 2, P1 - P2 = g n,
/// n the surface normal, an orthonormal right-handed frame, g the true (signed) distance.
#[test]
fn geometry_matches_signed_distances() {
    let mut rng = Rng::new(42);
    let mut box_regions = [0usize; 4];
    for (a, b) in PAIRS {
        let (c1, c2) = (sample(a), sample(b));
        let planar = c1.kind().is_planar();
        let pair = ContactPair::new("p", c1.clone(), c2.clone()).unwrap();
        for it in 0..30 {
            let (x1, x2) = random_poses(&mut rng, planar);
            let cs = eval(&pair, &x1, &x2);
            for (k, c) in cs.iter().enumerate() {
                let tag = format!("{a}–{b} #{it} candidate {k}");
                assert!((c.n.norm() - 1.0).abs() < 1e-12, "{tag}");
                assert!((c.p1 - c.p2 - c.n * c.g_n).norm() < 1e-12, "{tag}: P1 - P2 = g n");
                let gmin = cs.iter().map(|c| c.g_n).fold(f64::INFINITY, f64::min);
                let d1 = sdf(&c1, &x1, &c.p1);
                // the upper end sphere's lowest point may lie inside the capsule; against a
                // non-convex mesh either end's may
                if matches!(c1, Contour::Capsule { .. })
                    && (matches!(c2, Contour::Mesh(_)) || matches!(c2, Contour::Plane { .. }) && c.g_n > gmin)
                {
                    // the upper end sphere's lowest point may lie inside the capsule
                    assert!(d1 < 1e-12, "{tag}: P1 outside contour 1 by {d1}");
                } else {
                    assert!(d1.abs() < 1e-12, "{tag}: P1 off contour 1 by {d1}");
                }
                assert!(sdf(&c2, &x2, &c.p2).abs() < 1e-12, "{tag}: P2 off contour 2 by {}", sdf(&c2, &x2, &c.p2));
                let frame = Mat3::from_columns(&[c.t1, c.t2, c.n]);
                assert!((frame.transpose() * frame - Mat3::identity()).norm() < 1e-12, "{tag}: frame");
                assert!((frame.determinant() - 1.0).abs() < 1e-12, "{tag}: right-handed");
                if smooth(&c2) {
                    let g2 = grad(&c2, &x2, &(c.p2 + c.n * 1e-3));
                    assert!((g2 - c.n).norm() < 1e-6, "{tag}: n is contour 2's normal");
                }
                if smooth(&c1) && d1.abs() < 1e-12 {
                    let g1 = grad(&c1, &x1, &(c.p1 - c.n * 1e-3));
                    assert!((g1 + c.n).norm() < 1e-6, "{tag}: -n is contour 1's normal");
                }
                if planar {
                    let ez = x2.a.column(2).into_owned();
                    assert!(c.n.dot(&ez).abs() < 1e-12, "{tag}: planar n ⟂ e_z");
                    assert!((c.t1 - ez.cross(&c.n).normalize()).norm() < 1e-12, "{tag}: t1 = e_z × n");
                }
            }
            // g as the distance between the contours from independent formulas
            let g = cs[0].g_n;
            let centre = match &c1 {
                Contour::Sphere { center, radius } => Some((x1.point_to_parent(center), *radius)),
                Contour::Circle { center, radius } => Some((x1.point_to_parent(&lift(center)), *radius)),
                Contour::Point { p } => Some((x1.point_to_parent(p), 0.0)),
                Contour::Point2 { p } => Some((x1.point_to_parent(&lift(p)), 0.0)),
                _ => None,
            };
            if let Some((c, r)) = centre {
                assert!((g - (sdf(&c2, &x2, &c) - r)).abs() < 1e-12, "{a}–{b}: g vs sdf");
            }
            match (&c1, &c2) {
                (Contour::Capsule { a: a1, b: b1, radius: r1 }, Contour::Capsule { a: a2, b: b2, radius: r2 }) => {
                    let (p1, q1) = (x1.point_to_parent(a1), x1.point_to_parent(b1));
                    let (p2, q2) = (x2.point_to_parent(a2), x2.point_to_parent(b2));
                    let dist = |s: f64| argmin01(|u| (p1 + (q1 - p1) * s - p2 - (q2 - p2) * u).norm());
                    let d = argmin01(dist);
                    assert!((g - (d - r1 - r2)).abs() < 1e-9, "{a}–{b}: g {g} vs brute force {}", d - r1 - r2);
                }
                (Contour::Cylinder { center, axis, radius, half_length }, _) => {
                    // the lowest rim point of each end by sampling the rim
                    for (k, s) in [1.0, -1.0].iter().enumerate() {
                        let ax = axis.normalize();
                        let u = if ax.x.abs() < 0.9 {
                            ax.cross(&Vec3::x()).normalize()
                        } else {
                            ax.cross(&Vec3::y()).normalize()
                        };
                        let w = ax.cross(&u);
                        let min = (0..20000)
                            .map(|i| {
                                let phi = std::f64::consts::TAU * i as f64 / 20000.0;
                                let p = center + ax * (s * half_length) + (u * phi.cos() + w * phi.sin()) * *radius;
                                sdf(&c2, &x2, &x1.point_to_parent(&p))
                            })
                            .fold(f64::INFINITY, f64::min);
                        assert!(cs[k].g_n <= min + 1e-12 && min - cs[k].g_n < 1e-6, "{a}–{b}: rim {k}");
                    }
                }
                _ => {}
            }
            if let (
                Contour::Sphere { center, .. } | Contour::Point { p: center },
                Contour::Box { center: bc, rotation, half_extents },
            ) = (&c1, &c2)
            {
                let cl = rotation.transpose() * (x2.a.transpose() * (x1.point_to_parent(center) - x2.r) - bc);
                let out = (0..3).filter(|&k| cl[k].abs() > half_extents[k]).count();
                box_regions[out] += 1;
            }
        }
    }
    // the sphere–box cases met the inside, face, edge and corner regions
    assert!(box_regions.iter().all(|&n| n > 0), "{box_regions:?}");
}

/// Reversing the contours gives the same gap, the opposite normal and exchanged points.
#[test]
fn reversed_order_flips_the_normal() {
    let mut rng = Rng::new(5);
    for (a, b) in PAIRS {
        let (c1, c2) = (sample(a), sample(b));
        let fwd = ContactPair::new("f", c1.clone(), c2.clone()).unwrap();
        let rev = ContactPair::new("r", c2, c1).unwrap();
        for _ in 0..5 {
            let (x1, x2) = random_poses(&mut rng, fwd.is_planar());
            let (f, r) = (eval(&fwd, &x1, &x2), eval(&rev, &x2, &x1));
            for (f, r) in f.iter().zip(&r) {
                assert!((f.g_n - r.g_n).abs() < 1e-14, "{a}–{b}");
                assert!((f.n + r.n).norm() < 1e-14 && (f.p1 - r.p2).norm() < 1e-14 && (f.p2 - r.p1).norm() < 1e-14);
            }
        }
    }
}

/// Degenerate configurations give finite values and the documented normal and gap.
#[test]
fn degenerate_configurations_are_defined() {
    let finite = |c: &ContactPoint| {
        [c.g_n]
            .iter()
            .chain(c.n.iter())
            .chain(c.p1.iter())
            .chain(c.p2.iter())
            .chain(c.t1.iter())
            .chain(c.t2.iter())
            .all(|v| v.is_finite())
    };
    let s = |r| Contour::Sphere { center: Vec3::zeros(), radius: r };
    let x = Pose::new(rot(&Vec3::new(1.0, 2.0, 3.0), 0.7), Vec3::new(0.3, 0.2, 0.1));
    // coincident centres: g = -(R1 + R2), n = body 2's x axis
    let c = eval(&ContactPair::new("d", s(0.5), s(0.25)).unwrap(), &x, &x)[0];
    assert!(finite(&c) && (c.g_n + 0.75).abs() < 1e-15 && (c.n - x.a.column(0)).norm() < 1e-15);
    // crossing capsule axes: n along d1 × d2
    let cx = Contour::Capsule { a: Vec3::new(-1.0, 0.0, 0.0), b: Vec3::new(1.0, 0.0, 0.0), radius: 0.2 };
    let cy = Contour::Capsule { a: Vec3::new(0.0, -1.0, 0.0), b: Vec3::new(0.0, 1.0, 0.0), radius: 0.3 };
    let c = eval(&ContactPair::new("d", cx.clone(), cy).unwrap(), &Pose::IDENTITY, &Pose::IDENTITY)[0];
    assert!(finite(&c) && (c.g_n + 0.5).abs() < 1e-15 && c.n == Vec3::z());
    // coaxial capsules: any normal ⟂ the axis
    let c = eval(&ContactPair::new("d", cx.clone(), cx).unwrap(), &Pose::IDENTITY, &Pose::IDENTITY)[0];
    assert!(finite(&c) && c.n.x.abs() < 1e-15 && (c.g_n + 0.4).abs() < 1e-15);
    // sphere centre at the box centre (all faces... the thinnest one), upright cylinder, circles
    let cube =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(1.0, 0.5, 2.0) };
    let c = eval(&ContactPair::new("d", s(0.1), cube).unwrap(), &Pose::IDENTITY, &Pose::IDENTITY)[0];
    assert!(finite(&c) && (c.g_n + 0.6).abs() < 1e-15 && c.n == Vec3::y());
    let cyl = Contour::Cylinder { center: Vec3::zeros(), axis: Vec3::z(), radius: 0.3, half_length: 0.5 };
    let ground = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() };
    let cs = eval(&ContactPair::new("d", cyl, ground).unwrap(), &pose(Vec3::new(0.0, 0.0, 0.5)), &Pose::IDENTITY);
    assert!(cs.iter().all(finite) && cs[1].g_n.abs() < 1e-15 && (cs[0].g_n - 1.0).abs() < 1e-15);
    let ci = Contour::Circle { center: Vec2::zeros(), radius: 0.5 };
    let c = eval(&ContactPair::new("d", ci.clone(), ci).unwrap(), &Pose::IDENTITY, &Pose::IDENTITY)[0];
    assert!(finite(&c) && c.g_n == -1.0 && c.n == Vec3::x() && c.t1 == Vec3::y());
    // NaN poses do not panic, and give no finite gap: every candidate is NaN (never active)
    let nan = Pose::new(Mat3::repeat(f64::NAN), Vec3::repeat(f64::NAN));
    let half_nan = Pose::new(Mat3::identity(), Vec3::new(0.0, f64::NAN, 0.0));
    for (a, b) in PAIRS.iter().chain(&[("box", "box_b")]) {
        let pair = ContactPair::new("n", sample(a), sample(b)).unwrap();
        for (x1, x2) in
            [(nan, Pose::IDENTITY), (Pose::IDENTITY, nan), (half_nan, Pose::IDENTITY), (Pose::IDENTITY, half_nan)]
        {
            for (k, c) in eval(&pair, &x1, &x2).iter().enumerate() {
                assert!(!c.g_n.is_finite(), "{a}–{b} candidate {k}: a finite gap from a NaN pose {c:?}");
            }
        }
    }
}

// ---- box–box ---------------------------------------------------------------------------------------

fn cuboid(h: Vec3) -> Contour {
    Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: h }
}

/// The candidates in use (unused ones carry a gap larger than the pair's whole extent).
fn used(pair: &ContactPair, x1: &Pose, x2: &Pose) -> Vec<ContactPoint> {
    let cs = eval(pair, x1, x2);
    let far = (x1.r - x2.r).norm() + 0.5;
    let (u, rest): (Vec<_>, Vec<_>) = cs.into_iter().partition(|c| c.g_n < far * 0.5);
    for c in &rest {
        assert!(c.g_n > 0.1 && c.g_n.is_finite(), "an unused candidate must stay inactive: {c:?}");
    }
    u
}

/// Equal boxes stacked face on face: four candidates at the corners of the contact square with
/// the exact gap, the lower box's face as the reference (n = +z), and the same under rounding-
/// sized perturbations (no flip of the normal, no near-duplicate points).
#[test]
fn box_box_aligned_equal_boxes_give_four_corners() {
    let h = Vec3::new(0.2, 0.15, 0.1);
    let pair = ContactPair::new("bb", cuboid(h), cuboid(h)).unwrap();
    assert_eq!(pair.candidates(), 8);
    for (dz, dx, eps) in
        [(0.0, 0.0, 0.0), (-1e-6, 0.0, 0.0), (3e-4, 0.0, 0.0), (0.0, 1e-13, 1e-15), (-2e-7, -3e-14, -2e-16)]
    {
        let x1 = Pose::new(rot(&Vec3::new(0.3, -0.2, 1.0), eps), Vec3::new(dx, 0.0, 0.2 + dz));
        let cs = used(&pair, &x1, &Pose::IDENTITY);
        assert_eq!(cs.len(), 4, "dz {dz} dx {dx}: {cs:?}");
        for c in &cs {
            assert!((c.n - Vec3::z()).norm() < 1e-14, "{c:?}");
            assert!((c.g_n - dz).abs() < 1e-14 + 1e-15 * 0.2, "gap {} vs {dz}", c.g_n);
            assert!((c.p2.z - 0.1).abs() < 1e-15, "P2 on the lower box's top face");
            assert!((c.p1.x.abs() - 0.2).abs() < 1e-12 && (c.p1.y.abs() - 0.15).abs() < 1e-12, "a corner: {:?}", c.p1);
        }
        // the four distinct corners
        let mut q: Vec<(i32, i32)> = cs.iter().map(|c| (c.p1.x.signum() as i32, c.p1.y.signum() as i32)).collect();
        q.sort();
        assert_eq!(q, vec![(-1, -1), (-1, 1), (1, -1), (1, 1)]);
    }
}

/// A cube turned by 45° about the vertical on an equal cube: the contact region is the regular
/// octagon, vertices at (±h, ±(√2 - 1) h) and (±(√2 - 1) h, ±h), all at the same gap.
#[test]
fn box_box_cube_turned_45_degrees_gives_the_octagon() {
    let h = 0.1;
    let pair = ContactPair::new("bb", cuboid(Vec3::repeat(h)), cuboid(Vec3::repeat(h))).unwrap();
    let gap = -2e-5;
    let x1 = Pose::new(rot(&Vec3::z(), std::f64::consts::FRAC_PI_4), Vec3::new(0.0, 0.0, 2.0 * h + gap));
    let x2 = Pose::new(Mat3::identity(), Vec3::zeros());
    let cs = used(&pair, &x1, &x2);
    assert_eq!(cs.len(), 8, "{cs:?}");
    let w = (2f64.sqrt() - 1.0) * h;
    let mut expect: Vec<Vec3> = [(h, w), (h, -w), (-h, w), (-h, -w), (w, h), (-w, h), (w, -h), (-w, -h)]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, h))
        .collect();
    for c in &cs {
        assert!((c.g_n - gap).abs() < 1e-15 && (c.n - Vec3::z()).norm() < 1e-15, "{c:?}");
        let k =
            expect.iter().position(|e| (e - c.p2).norm() < 1e-14).unwrap_or_else(|| panic!("{:?} not a vertex", c.p2));
        expect.remove(k);
        // P1 on the upper cube's bottom face
        assert!(sdf(&cuboid(Vec3::repeat(h)), &x1, &c.p1).abs() < 1e-15);
    }
    // the same octagon when both are turned together about the vertical and moved
    let turn = rot(&Vec3::z(), 0.7);
    let shift = Vec3::new(0.3, -0.2, 0.5);
    let cs2 = used(&pair, &Pose::new(turn * x1.a, turn * x1.r + shift), &Pose::new(turn, shift));
    assert_eq!(cs2.len(), 8);
    for (a, b) in cs.iter().zip(&cs2) {
        assert!((turn * a.p2 + shift - b.p2).norm() < 1e-14 && (b.g_n - gap).abs() < 1e-15);
    }
}

/// Two cubes with crossing edges (upper turned 45° about x, lower 45° about y): one candidate at
/// the crossing, gap z_1 - z_2 - √2 (h_1 + h_2), normal +z; then the reversed pair.
#[test]
fn box_box_crossing_edges_give_the_closed_form_gap() {
    let (h1, h2) = (0.1, 0.15);
    let pair = ContactPair::new("ee", cuboid(Vec3::repeat(h1)), cuboid(Vec3::repeat(h2))).unwrap();
    let rev = ContactPair::new("ee", cuboid(Vec3::repeat(h2)), cuboid(Vec3::repeat(h1))).unwrap();
    let q = std::f64::consts::FRAC_PI_4;
    for (gap, off) in [(0.01, Vec3::zeros()), (0.0, Vec3::new(0.02, -0.03, 0.0)), (-1e-3, Vec3::new(-0.01, 0.05, 0.0))]
    {
        let z1 = 2f64.sqrt() * (h1 + h2) + gap;
        let x1 = Pose::new(rot(&Vec3::x(), q), Vec3::new(off.x, off.y, z1));
        let x2 = Pose::new(rot(&Vec3::y(), q), Vec3::new(-off.y, off.x, 0.0));
        let cs = used(&pair, &x1, &x2);
        assert_eq!(cs.len(), 1, "{cs:?}");
        let c = cs[0];
        assert!((c.g_n - gap).abs() < 1e-15, "gap {} vs {gap}", c.g_n);
        assert!((c.n - Vec3::z()).norm() < 1e-15);
        // on the upper cube's lowest edge (along x) above the lower cube's top edge (along y)
        let p2 = Vec3::new(-off.y, off.y, 2f64.sqrt() * h2);
        assert!((c.p2 - p2).norm() < 1e-14 && (c.p1 - p2 - Vec3::z() * gap).norm() < 1e-14, "{c:?}");
        let r = used(&rev, &x2, &x1);
        assert!(r.len() == 1 && (r[0].g_n - gap).abs() < 1e-15 && (r[0].n + Vec3::z()).norm() < 1e-15);
        assert!((r[0].p1 - c.p2).norm() < 1e-14 && (r[0].p2 - c.p1).norm() < 1e-14);
    }
}

/// A box tilted over an edge of the lower one's top face: the upper box's face is the reference
/// once the tilt is larger than the tie tolerance; its normal then turns with the tilt (no flip).
/// Over a sweep of small rotations of the upper box the normal stays within the tilt of +z.
#[test]
fn box_box_normal_is_continuous_under_small_rotations() {
    let h = Vec3::new(0.2, 0.15, 0.1);
    let pair = ContactPair::new("bb", cuboid(h), cuboid(h)).unwrap();
    let mut rng = Rng::new(17);
    for _ in 0..200 {
        let axis = rng.unit();
        let angle = rng.uniform(-1e-3, 1e-3) * 10f64.powi(-(rng.uniform(0.0, 9.0) as i32));
        let x1 = Pose::new(rot(&axis, angle), Vec3::new(rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), 0.2));
        let cs = used(&pair, &x1, &Pose::IDENTITY);
        assert!(cs.len() >= 4, "{cs:?}");
        for c in &cs {
            assert!(c.n.z > 0.0 && (c.n - Vec3::z()).norm() <= angle.abs() * 1.000001 + 1e-15, "angle {angle}: {c:?}");
            assert!(c.g_n.abs() < 0.3 * angle.abs() + 1e-15, "{c:?}");
        }
    }
    // overhanging by 0.25 and tipped about the lower box's edge x = 0.2: the upper face is the
    // reference, n = its bottom normal reversed, and the edge's two ends touch at g = 0
    for tilt in [1e-6, 0.05, 0.3] {
        let a = rot(&Vec3::y(), tilt);
        // the upper bottom face passes through the lower's top edge (0.2, y, 0.1)
        let c_local = Vec3::new(0.05, 0.0, 0.1); // lower edge point in the upper frame: (x, ·, -0.1) → centre offset
        let r = Vec3::new(0.2, 0.0, 0.1) + a * Vec3::new(c_local.x, 0.0, c_local.z);
        let x1 = Pose::new(a, r);
        let cs = used(&pair, &x1, &Pose::IDENTITY);
        let n = a * Vec3::z();
        let touching: Vec<_> = cs.iter().filter(|c| c.g_n.abs() < 1e-13).collect();
        assert_eq!(touching.len(), 2, "tilt {tilt}: {cs:?}");
        for c in &cs {
            assert!((c.n - n).norm() < 1e-13, "tilt {tilt}: n {:?} vs {n:?}", c.n);
            assert!(c.g_n > -1e-13);
        }
        for c in touching {
            assert!(
                (c.p2.x - 0.2).abs() < 1e-13 && (c.p2.z - 0.1).abs() < 1e-13 && (c.p2.y.abs() - 0.15).abs() < 1e-13
            );
        }
    }
}

/// At random placements of two boxes near each other: unit normals, P1 - P2 = g n, orthonormal
/// frames, both points on their boxes' surfaces for face manifolds, the same manifold in the
/// reversed order (away from ties), and the least gap equal to the distance of the boxes from
/// brute force where a face or edge pair is closest (separated boxes).
#[test]
fn box_box_random_configurations() {
    let (ca, cb) = (sample("box"), sample("box_b"));
    let pair = ContactPair::new("bb", ca.clone(), cb.clone()).unwrap();
    let rev = ContactPair::new("bb", cb.clone(), ca.clone()).unwrap();
    let mut rng = Rng::new(123);
    let (mut faces, mut edges, mut exact, mut fallback, mut corners) = (0, 0, 0, 0, 0);
    let corners_of = |c: &Contour, x: &Pose| -> Vec<Vec3> {
        let Contour::Box { center, rotation, half_extents: h } = c else { unreachable!() };
        (0..8)
            .map(|i| {
                let s = |b: usize| if i & (1 << b) != 0 { 1.0 } else { -1.0 };
                x.point_to_parent(&(center + rotation * Vec3::new(s(0) * h.x, s(1) * h.y, s(2) * h.z)))
            })
            .collect()
    };
    for it in 0..400 {
        let (x1, mut x2) = random_poses(&mut rng, false);
        x2.r = x1.r + (x2.r - x1.r).normalize() * rng.uniform(0.15, 0.6);
        let cs = eval(&pair, &x1, &x2);
        let rs = eval(&rev, &x2, &x1);
        let Geometry::BoxBox { a, b, scale } = &pair.geometry else { unreachable!() };
        let (feature, s) = box_box::feature(&x1, &x2, a, b, *scale);
        let (_, kinds) = pair.box_kinds(&x1, &x2).unwrap();
        // the reference face's normal (the normal of every candidate but the reference corners)
        let m = match feature {
            box_box::Feature::Face { ref_a: true, axis } => (x1.a * a.rotation).column(axis).into_owned(),
            box_box::Feature::Face { ref_a: false, axis } => (x2.a * b.rotation).column(axis).into_owned(),
            _ => Vec3::zeros(),
        };
        let is_face = matches!(feature, box_box::Feature::Face { .. });
        if is_face {
            faces += 1
        } else {
            edges += 1
        }
        let far = 0.5 * ((x1.r - x2.r).norm() + 0.5);
        let mut gmin = f64::INFINITY;
        for (k, c) in cs.iter().enumerate() {
            let tag = format!("#{it} candidate {k} ({feature:?})");
            assert!((c.n.norm() - 1.0).abs() < 1e-12, "{tag}");
            assert!((c.p1 - c.p2 - c.n * c.g_n).norm() < 1e-12, "{tag}: P1 - P2 = g n");
            let frame = Mat3::from_columns(&[c.t1, c.t2, c.n]);
            assert!(
                (frame.transpose() * frame - Mat3::identity()).norm() < 1e-12 && frame.determinant() > 0.0,
                "{tag}"
            );
            if c.g_n > far {
                continue;
            }
            gmin = gmin.min(c.g_n);
            // a reference corner's gap is measured along the incident face's normal, at cos τ of
            // the gap along m (τ the tilt between the faces)
            let corner = kinds[k] == box_box::Kind::ReferenceCorner;
            let (cos, sin) = (c.n.dot(&m).abs(), c.n.cross(&m).norm());
            let bound = if corner { s.min(s * cos) } else { s };
            assert!(c.g_n >= bound - 1e-12, "{tag}: a candidate's gap {} below the separation {s}", c.g_n);
            if is_face && !corner {
                assert!((c.n.dot(&m).abs() - 1.0).abs() < 1e-12, "{tag}: normal ∥ the reference face's");
            }
            if let box_box::Feature::Face { ref_a, .. } = feature {
                // the incident point on its box (a reference corner's foot on the incident face's
                // plane, within |g| sin τ of the face); the reference point on the reference face,
                // or (the fallback when the clipped face is empty: one candidate) on its plane
                let (d1, d2) = (sdf(&ca, &x1, &c.p1), sdf(&cb, &x2, &c.p2));
                let (d_inc, d_ref) = if ref_a { (d2, d1) } else { (d1, d2) };
                if corner {
                    corners += 1;
                    let slack = c.g_n.abs() * sin * (1.0 + 1e-9);
                    assert!(d_inc > -5e-10 && d_inc < slack + 5e-10, "{tag}: foot off its face by {d_inc}");
                } else {
                    assert!(d_inc.abs() < 5e-10, "{tag}: incident point off its box by {d_inc}");
                }
                let in_use = cs.iter().filter(|c| c.g_n < far).count();
                if d_ref.abs() > 5e-10 {
                    assert!(in_use == 1 && d_ref > 0.0, "{tag}: reference point off its face by {d_ref}");
                    fallback += 1;
                }
            }
            // the reversed pair: the same points with the normal reversed (away from ties)
            let r = &rs[k];
            assert!((c.g_n - r.g_n).abs() < 1e-13 && (c.n + r.n).norm() < 1e-13, "{tag}: reversed");
            assert!((c.p1 - r.p2).norm() < 1e-13 && (c.p2 - r.p1).norm() < 1e-13, "{tag}: reversed");
        }
        // separated: the distance by brute force (corners against the other box, edges against edges)
        if gmin.is_finite() && s > 1e-6 {
            let (k1, k2) = (corners_of(&ca, &x1), corners_of(&cb, &x2));
            let mut dist = k1
                .iter()
                .map(|p| sdf(&cb, &x2, p))
                .chain(k2.iter().map(|p| sdf(&ca, &x1, p)))
                .fold(f64::INFINITY, f64::min);
            let edges_of = |k: &[Vec3]| -> Vec<(Vec3, Vec3)> {
                let mut e = vec![];
                for i in 0..8 {
                    for b in 0..3 {
                        if i & (1 << b) == 0 {
                            e.push((k[i], k[i | (1 << b)]));
                        }
                    }
                }
                e
            };
            for (p, q) in edges_of(&k1) {
                for (u, v) in edges_of(&k2) {
                    let f = |t: f64| argmin01_n(|w| (p + (q - p) * t - u - (v - u) * w).norm(), 70);
                    dist = dist.min(argmin01_n(f, 70));
                }
            }
            // the separation of the chosen axis is a lower bound; the least candidate gap is the
            // distance when the closest points are a vertex over a face or two crossing edges
            assert!(s <= dist + 1e-9, "#{it}: separation {s} above the distance {dist}");
            if (gmin - dist).abs() < 1e-8 {
                exact += 1;
            }
        }
    }
    assert!(faces > 50 && edges > 10, "faces {faces}, edges {edges}");
    assert!(exact > 30, "exact distances {exact}");
    assert!((1..10).contains(&fallback), "empty clipped faces {fallback}");
    assert!(corners > 20, "reference corners {corners}");
}

/// The one-pass evaluation of all candidates equals the candidate-by-candidate one (values and
/// rates), in both orders.
#[test]
fn box_box_one_pass_equals_each_candidate() {
    let mut rng = Rng::new(8);
    for (c1, c2) in [(sample("box"), sample("box_b")), (sample("box_b"), sample("box"))] {
        let pair = ContactPair::new("bb", c1, c2).unwrap();
        for _ in 0..50 {
            let (x1, mut x2) = random_poses(&mut rng, false);
            x2.r = x1.r + (x2.r - x1.r).normalize() * rng.uniform(0.15, 0.5);
            let (w1, w2) = (Motion::new(rng.vec3(1.0), rng.vec3(1.0)), Motion::new(rng.vec3(1.0), rng.vec3(1.0)));
            let mut all = [Raw::default(); 8];
            pair.candidates_into(&x1, &x2, Some((&w1, &w2)), &mut all);
            for (k, a) in all.iter().enumerate() {
                let b = pair.candidate(k, &x1, &x2, Some((&w1, &w2)));
                assert!(
                    a.g == b.g
                        && a.n == b.n
                        && a.p1 == b.p1
                        && a.p2 == b.p2
                        && a.nd == b.nd
                        && a.p1d == b.p1d
                        && a.p2d == b.p2d
                );
            }
        }
    }
}

/// Degenerate box–box input: NaN placements do not panic; an incident face that misses the
/// reference face's slab still gives one candidate (its deepest corner), with the exact gap.
#[test]
fn box_box_degenerate_inputs() {
    let h = Vec3::new(0.2, 0.15, 0.1);
    let pair = ContactPair::new("bb", cuboid(h), cuboid(Vec3::new(0.05, 0.05, 0.3))).unwrap();
    let nan = Pose::new(Mat3::repeat(f64::NAN), Vec3::repeat(f64::NAN));
    for (x1, x2) in [(nan, Pose::IDENTITY), (Pose::IDENTITY, nan)] {
        assert!(eval(&pair, &x1, &x2).iter().all(|c| !c.g_n.is_finite()), "NaN pose: a finite gap");
    }
    let mut out = [Raw::default(); 8];
    let tw = Motion::new(Vec3::repeat(f64::NAN), Vec3::zeros());
    pair.candidates_into(&Pose::IDENTITY, &nan, Some((&tw, &tw)), &mut out);
    assert!(out.iter().all(|r| !r.g.is_finite()), "NaN pose: a finite gap {out:?}");
    // finite, overlapping placements with a NaN angular velocity: the candidates in use (gap ≤ 0)
    // have NaN rates, the others stay inactive (a finite gap larger than the boxes)
    {
        use crate::contact::kinematics::{contact_kinematics, BodyMotion, ContactKinematics};
        let x1 = Pose::new(rot(&Vec3::new(1.0, 0.5, 0.0), 0.1), Vec3::new(0.02, 0.01, 0.39));
        let b1 = BodyMotion { pose: x1, twist: tw, acc: Motion::ZERO };
        let b2 = BodyMotion { pose: Pose::IDENTITY, twist: Motion::ZERO, acc: Motion::ZERO };
        let mut kin = [ContactKinematics::default(); 8];
        contact_kinematics(&pair, &b1, &b2, &mut kin).unwrap();
        assert!(kin.iter().any(|c| c.point.g_n <= 0.0), "{kin:?}");
        for c in &kin {
            let rates = [c.gd_n, c.gd_t[0], c.gd_t[1], c.wbar_n, c.wbar_t[0], c.wbar_t[1]];
            assert!(c.point.g_n.is_finite(), "{c:?}");
            assert!(c.point.g_n > 0.5 || rates.iter().all(|v| !v.is_finite()), "NaN twist: finite rates {c:?}");
        }
    }
    // a thin post (body 2, half 0.05 x 0.05 x 0.3) pushed into the middle of a plate's long side
    // (body 1), overlapping by 0.01 along x: the least overlap is along x, the post's face x is the
    // reference (it is smaller, but the plate's faces overlap more), and the plate's side face
    // clipped against the post's side planes gives the post's cross-section, 4 points
    let x1 = Pose::new(Mat3::identity(), Vec3::new(0.24, 0.0, 0.0));
    let cs = used(&pair, &x1, &Pose::IDENTITY);
    assert_eq!(cs.len(), 4, "{cs:?}");
    let gmin = cs.iter().map(|c| c.g_n).fold(f64::INFINITY, f64::min);
    assert!((gmin + 0.01).abs() < 1e-14, "{cs:?}");
    for c in &cs {
        assert!((c.n - Vec3::x()).norm() < 1e-14);
    }
}

/// The pose `x` advanced by `t` with the constant world twist `tw`: the screw motion in which
/// every material point moves with `v + ω × x`, `x(t) = R(t) x0 + S(t) v`,
/// `R = exp(ω̃ t)`, `S = ∫_0^t R`.
fn advance(x: &Pose, tw: &Motion, t: f64) -> Pose {
    let wn = tw.w.norm();
    let (r, s) = if wn == 0.0 {
        (Mat3::identity(), Mat3::identity() * t)
    } else {
        let k = crate::math::tilde(&(tw.w / wn));
        let th = wn * t;
        let k2 = k * k;
        (
            Mat3::identity() + k * th.sin() + k2 * (1.0 - th.cos()),
            Mat3::identity() * t + k * ((1.0 - th.cos()) / wn) + k2 * (t - th.sin() / wn),
        )
    };
    Pose::new(r * x.a, r * x.r + s * tw.v)
}

/// A tilted box (turned 0.2 rad about x and 0.1 rad about y, and about the vertical) resting on
/// another, penetrating it by 1 mm, over its middle and overhanging its edges and corners, larger
/// and smaller than the lower box, both boxes moving with generic twists, in both orders of the
/// pair. For every candidate, against central differences (δ = 1e-5) along the screw motions:
///
/// - `ġ_N` is the rate of the gap of the candidate's material point: the corner for a corner of
///   either face, the incident box's point for a crossing (module docs of `box_box`). Its gap at
///   `t ± δ` is measured against the plane of the matched candidate there (same kind, nearest
///   point: the same corner, or the crossing on the same edge): the other point `P'` and normal
///   `n'`. For corners that gap is the matched candidate's `g_N` itself (to 1e-13), so there
///   `ġ_N = d g_N/dt` of the candidate; for the edge–edge point `ġ_N = d g_N/dt` too;
/// - for a crossing, the rate of its own gap is `ġ_N + n·σ`, `σ` the crossing's velocity
///   relative to the incident box (differenced), and `n·σ ≠ 0` on the tilted face (the documented
///   part no face normal removes);
/// - `ġ_T = t·Δv` of the same material points at `P1`, `P2`;
/// - `w̄_N`, `w̄_T` (full accelerations: zero spatial accelerations for constant twists) against
///   the differences of `ġ_N`, `ġ_T` of the matched candidates, and `w̄_N` against the second
///   difference of `g_N` where the candidate is a material point.
///
/// All to 1e-7 relative (1e-6 for second differences).
#[test]
fn box_box_rates_on_a_tilted_face_match_finite_differences() {
    use crate::contact::kinematics::{contact_kinematics, BodyMotion, ContactKinematics};
    use box_box::{Feature, Kind};
    let mut rng = Rng::new(2718);
    let lower = Contour::Box {
        center: Vec3::new(0.01, -0.02, 0.0),
        rotation: rot(&Vec3::z(), 0.1),
        half_extents: Vec3::new(0.3, 0.2, 0.1),
    };
    let (delta, delta2) = (1e-5, 1e-4);
    let kin = |pair: &ContactPair, b1: &BodyMotion, b2: &BodyMotion| {
        let mut out = [ContactKinematics::default(); 8];
        contact_kinematics(pair, b1, b2, &mut out).unwrap();
        out
    };
    let body = |x: Pose, tw: Motion| BodyMotion { pose: x, twist: tw, acc: Motion::ZERO };
    let mut met = [0usize; 4];
    let (mut configs, mut switched, mut defect_max) = (0, 0, 0.0f64);
    for half in [Vec3::new(0.2, 0.15, 0.08), Vec3::new(0.42, 0.3, 0.06), Vec3::new(0.5, 0.4, 0.04)] {
        let upper =
            Contour::Box { center: Vec3::new(-0.01, 0.02, 0.01), rotation: Mat3::identity(), half_extents: half };
        for yaw in [0.0, 0.5] {
            let a = rot(&Vec3::z(), yaw) * rot(&Vec3::x(), 0.2) * rot(&Vec3::y(), 0.1);
            for off in [(0.0, 0.0), (0.33, 0.02), (0.28, 0.21), (-0.3, 0.12), (0.05, -0.27), (-0.4, -0.27)] {
                for order in 0..2 {
                    let pair = if order == 0 {
                        ContactPair::new("bb", upper.clone(), lower.clone()).unwrap()
                    } else {
                        ContactPair::new("bb", lower.clone(), upper.clone()).unwrap()
                    };
                    // the upper box at xu, lowered until the least gap is -1 mm
                    let mut xu = Pose::new(a, Vec3::new(off.0, off.1, 0.3));
                    let xl = Pose::new(rot(&Vec3::new(0.2, -0.1, 1.0), 0.05), Vec3::new(0.0, 0.0, 0.0));
                    let poses = |xu: &Pose| if order == 0 { (*xu, xl) } else { (xl, *xu) };
                    for _ in 0..8 {
                        let (x1, x2) = poses(&xu);
                        let gmin = eval(&pair, &x1, &x2).iter().map(|c| c.g_n).fold(f64::INFINITY, f64::min);
                        xu.r.z -= gmin + 1e-3;
                    }
                    let (x1, x2) = poses(&xu);
                    let gmin = eval(&pair, &x1, &x2).iter().map(|c| c.g_n).fold(f64::INFINITY, f64::min);
                    assert!((gmin + 1e-3).abs() < 1e-4, "half {half:?} yaw {yaw} offset {off:?}: penetration {gmin}");
                    let twist = |rng: &mut Rng, x: &Pose| {
                        let w = rng.vec3(1.0);
                        // the centre moves at up to 0.5 m/s
                        Motion::new(w, rng.vec3(0.5) - w.cross(&x.r))
                    };
                    let (t1, t2) = (twist(&mut rng, &x1), twist(&mut rng, &x2));
                    let at = |t: f64| (advance(&x1, &t1, t), advance(&x2, &t2, t));
                    let state = |t: f64| {
                        let (y1, y2) = at(t);
                        let (feature, kinds) = pair.box_kinds(&y1, &y2).unwrap();
                        (y1, y2, feature, kinds, kin(&pair, &body(y1, t1), &body(y2, t2)))
                    };
                    let s0 = state(0.0);
                    let (sp, sm, sp2, sm2) = (state(delta), state(-delta), state(delta2), state(-delta2));
                    let kinds0 = s0.3;
                    if [&sp, &sm, &sp2, &sm2].iter().any(|s| s.2 != s0.2 || s.3 != kinds0) {
                        switched += 1; // a vertex appears or leaves within δ: no derivative
                        continue;
                    }
                    configs += 1;
                    // whether body 1 carries the reference face (box–box pairs keep the caller's order)
                    let ref_is_1 = matches!(s0.2, Feature::Face { ref_a: true, .. });
                    for (k, c) in s0.4.iter().enumerate() {
                        let kind = kinds0[k];
                        let tag =
                            format!("half {half:?} yaw {yaw} offset {off:?} order {order} candidate {k} ({kind:?})");
                        // the body whose material point the candidate is (1 or 2), none for edge–edge
                        let material = match kind {
                            Kind::Unused => continue,
                            Kind::EdgeEdge => 0,
                            Kind::ReferenceCorner => {
                                if ref_is_1 {
                                    1
                                } else {
                                    2
                                }
                            }
                            Kind::IncidentCorner | Kind::Crossing => {
                                if ref_is_1 {
                                    2
                                } else {
                                    1
                                }
                            }
                        };
                        met[match kind {
                            Kind::IncidentCorner => 0,
                            Kind::ReferenceCorner => 1,
                            Kind::Crossing => 2,
                            _ => 3,
                        }] += 1;
                        let p = |c: &ContactKinematics, b: usize| if b == 2 { c.point.p2 } else { c.point.p1 };
                        // the same material point(s) at t: X_i(t) = x_i(t) x_i(0)⁻¹ P_i
                        let (p1b, p2b) =
                            (x1.inverse().point_to_parent(&c.point.p1), x2.inverse().point_to_parent(&c.point.p2));
                        let mat = |s: &(Pose, Pose, Feature, [Kind; 8], [ContactKinematics; 8]), b: usize| {
                            if b == 2 {
                                s.1.point_to_parent(&p2b)
                            } else {
                                s.0.point_to_parent(&p1b)
                            }
                        };
                        // the matched candidate at t: same kind, point on the material body (P1 for
                        // edge–edge) nearest the material point
                        let matched = |s: &(Pose, Pose, Feature, [Kind; 8], [ContactKinematics; 8])| {
                            let b = material.max(1);
                            let x = mat(s, b);
                            let mut d: Vec<(f64, usize)> =
                                (0..8).filter(|&j| s.3[j] == kind).map(|j| ((p(&s.4[j], b) - x).norm(), j)).collect();
                            d.sort_by(|a, b| a.0.total_cmp(&b.0));
                            assert!(
                                d[0].0 < 1e-3 && d.get(1).map_or(true, |e| e.0 > 1e-2),
                                "{tag}: no unique match {d:?}"
                            );
                            s.4[d[0].1]
                        };
                        let (cp, cm, cp2, cm2) = (matched(&sp), matched(&sm), matched(&sp2), matched(&sm2));
                        // the gap of the material point against the matched candidate's plane
                        let gap_of = |s: &(Pose, Pose, Feature, [Kind; 8], [ContactKinematics; 8]),
                                      m: &ContactKinematics| {
                            match material {
                                1 => m.point.n.dot(&(mat(s, 1) - m.point.p2)),
                                2 => m.point.n.dot(&(m.point.p1 - mat(s, 2))),
                                _ => m.point.g_n,
                            }
                        };
                        let (gp, gm) = (gap_of(&sp, &cp), gap_of(&sm, &cm));
                        let gd = (gp - gm) / (2.0 * delta);
                        assert!(close(c.gd_n, gd, 1e-7), "{tag}: ġ_N {} vs the material point's {gd}", c.gd_n);
                        let own = (cp.point.g_n - cm.point.g_n) / (2.0 * delta);
                        if kind == Kind::Crossing {
                            // the crossing's own gap: ġ_N + n·σ
                            let bi = if ref_is_1 { 2 } else { 1 };
                            let (pi0, pip, pim) = (p(c, bi), p(&cp, bi), p(&cm, bi));
                            let vi = if bi == 1 { t1.v + t1.w.cross(&pi0) } else { t2.v + t2.w.cross(&pi0) };
                            let sigma = (pip - pim) / (2.0 * delta) - vi;
                            let defect = c.point.n.dot(&sigma) * if bi == 1 { 1.0 } else { -1.0 };
                            assert!(
                                close(own, c.gd_n + defect, 1e-7),
                                "{tag}: d g/dt {own} vs ġ_N {} + n·σ {defect}",
                                c.gd_n
                            );
                            defect_max = defect_max.max(defect.abs());
                        } else {
                            // a material point: the candidate's own gap is that point's gap
                            assert!((gp - cp.point.g_n).abs() < 1e-13 && (gm - cm.point.g_n).abs() < 1e-13, "{tag}");
                            assert!(close(c.gd_n, own, 1e-7), "{tag}: ġ_N {} vs d g_N/dt {own}", c.gd_n);
                            let gdd = (cp2.point.g_n - 2.0 * c.point.g_n + cm2.point.g_n) / (delta2 * delta2);
                            assert!(close(c.wbar_n, gdd, 1e-6), "{tag}: g̈_N {} vs second difference {gdd}", c.wbar_n);
                        }
                        // ġ_T of the material points at P1, P2; w̄ against differences of ġ
                        let dv = (mat(&sp, 1) - mat(&sm, 1) - mat(&sp, 2) + mat(&sm, 2)) / (2.0 * delta);
                        for (j, t) in [c.point.t1, c.point.t2].iter().enumerate() {
                            assert!(
                                close(c.gd_t[j], t.dot(&dv), 1e-7),
                                "{tag}: ġ_T[{j}] {} vs {}",
                                c.gd_t[j],
                                t.dot(&dv)
                            );
                            let d = (cp.gd_t[j] - cm.gd_t[j]) / (2.0 * delta);
                            assert!(close(c.wbar_t[j], d, 1e-7), "{tag}: w̄_T[{j}] {} vs difference {d}", c.wbar_t[j]);
                        }
                        let d = (cp.gd_n - cm.gd_n) / (2.0 * delta);
                        assert!(close(c.wbar_n, d, 1e-7), "{tag}: w̄_N {} vs difference of ġ_N {d}", c.wbar_n);
                    }
                }
            }
        }
    }
    assert!(configs >= 60 && switched <= 4, "configurations {configs}, skipped {switched}");
    assert!(met[0] >= 40 && met[1] >= 12 && met[2] >= 40, "incident corners, reference corners, crossings: {met:?}");
    assert!(defect_max > 1e-2, "crossings on the tilted face slide off the normal: largest n·σ {defect_max}");
}

/// The box–box manifold against a brute-force construction of the clipped incident face at
/// random placements (face features): the incident face's corners inside the reference face's
/// side planes, the reference face's corners whose line along `m` meets the incident face inside
/// it, and the crossings of the incident face's edges with the side planes inside the other two;
/// each with its kind, gap, normal and points (module docs of `box_box`), to 1e-12. Placements
/// where a point lies within 1e-7 of a side plane are left out (the clipping merges such points
/// by its tie rule).
#[test]
fn box_box_manifold_matches_brute_force_clipping() {
    use box_box::{Feature, Kind};
    let (ca, cb) = (sample("box"), sample("box_b"));
    let pair = ContactPair::new("bb", ca.clone(), cb.clone()).unwrap();
    let placed = |c: &Contour, x: &Pose| {
        let Contour::Box { center, rotation, half_extents } = c else { unreachable!() };
        (x.point_to_parent(center), x.a * rotation, *half_extents)
    };
    let mut rng = Rng::new(99);
    let (mut compared, mut skipped, mut kinds_met) = (0, 0, [0usize; 3]);
    for _ in 0..600 {
        let (x1, mut x2) = random_poses(&mut rng, false);
        x2.r = x1.r + (x2.r - x1.r).normalize() * rng.uniform(0.15, 0.6);
        let (feature, kinds) = pair.box_kinds(&x1, &x2).unwrap();
        let Feature::Face { ref_a, axis } = feature else { continue };
        let ((c_a, r_a, h_a), (c_b, r_b, h_b)) = (placed(&ca, &x1), placed(&cb, &x2));
        let ((cr, rr, hr), (ci, ri, hi)) =
            if ref_a { ((c_a, r_a, h_a), (c_b, r_b, h_b)) } else { ((c_b, r_b, h_b), (c_a, r_a, h_a)) };
        let ax = |r: &Mat3, k: usize| r.column(k).into_owned();
        let m = ax(&rr, axis) * if (ci - cr).dot(&ax(&rr, axis)) >= 0.0 { 1.0 } else { -1.0 };
        let p_ref = cr + m * hr[axis];
        let j = (0..3).max_by(|&p, &q| ax(&ri, p).dot(&m).abs().total_cmp(&ax(&ri, q).dot(&m).abs())).unwrap();
        let f = ax(&ri, j) * if ax(&ri, j).dot(&m) > 0.0 { -1.0 } else { 1.0 };
        let fc = ci + f * hi[j];
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        let (k1, k2) = ((axis + 1) % 3, (axis + 2) % 3);
        // signed distances beyond the side planes (≤ 0 inside)
        let out_ref = |x: &Vec3, k: usize| (x - cr).dot(&ax(&rr, k)).abs() - hr[k];
        let out_inc = |x: &Vec3, k: usize| (x - fc).dot(&ax(&ri, k)).abs() - hi[k];
        let mut margin = f64::INFINITY;
        // (kind, point on the reference box, point on the incident box, normal from the reference box)
        let mut expect: Vec<(Kind, Vec3, Vec3, Vec3, f64)> = vec![];
        let on_ref_plane = |v: Vec3| {
            let g = m.dot(&(v - p_ref));
            (v - m * g, v, m, g)
        };
        let corners: Vec<Vec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(s1, s2)| fc + ax(&ri, j1) * (s1 * hi[j1]) + ax(&ri, j2) * (s2 * hi[j2]))
            .collect();
        for v in &corners {
            let d = out_ref(v, k1).max(out_ref(v, k2));
            margin = margin.min(d.abs());
            if d < 0.0 {
                let (pr, pi, n, g) = on_ref_plane(*v);
                expect.push((Kind::IncidentCorner, pr, pi, n, g));
            }
        }
        for (s1, s2) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let q = p_ref + ax(&rr, k1) * (s1 * hr[k1]) + ax(&rr, k2) * (s2 * hr[k2]);
            let v = q + m * (f.dot(&(fc - q)) / f.dot(&m));
            let d = out_inc(&v, j1).max(out_inc(&v, j2));
            margin = margin.min(d.abs());
            if d < 0.0 {
                let g = f.dot(&(q - fc));
                expect.push((Kind::ReferenceCorner, q, q - f * g, -f, g));
            }
        }
        for e in 0..4 {
            let (p, q) = (corners[e], corners[(e + 1) % 4]);
            for (k, other) in [(k1, k2), (k2, k1)] {
                for sgn in [1.0, -1.0] {
                    let dist = |x: &Vec3| sgn * (x - cr).dot(&ax(&rr, k)) - hr[k];
                    let (dp, dq) = (dist(&p), dist(&q));
                    if dp * dq < 0.0 {
                        let v = p + (q - p) * (dp / (dp - dq));
                        let d = out_ref(&v, other);
                        margin = margin.min(d.abs());
                        if d < 0.0 {
                            let (pr, pi, n, g) = on_ref_plane(v);
                            expect.push((Kind::Crossing, pr, pi, n, g));
                        }
                    }
                }
            }
        }
        if expect.is_empty() {
            // the incident face misses the reference face's side planes: its deepest corner
            let v = *corners.iter().min_by(|p, q| p.dot(&m).total_cmp(&q.dot(&m))).unwrap();
            let (pr, pi, n, g) = on_ref_plane(v);
            expect.push((Kind::IncidentCorner, pr, pi, n, g));
        }
        if margin < 1e-7 {
            skipped += 1;
            continue;
        }
        compared += 1;
        let cs = eval(&pair, &x1, &x2);
        let used = kinds.iter().filter(|&&k| k != Kind::Unused).count();
        assert_eq!(
            used,
            expect.len(),
            "{feature:?}: {kinds:?} vs {:?}",
            expect.iter().map(|e| e.0).collect::<Vec<_>>()
        );
        for (kind, pr, pi, nr, g) in expect {
            let (n, p1, p2) = if ref_a { (-nr, pr, pi) } else { (nr, pi, pr) };
            let k = (0..8)
                .find(|&k| kinds[k] == kind && (cs[k].p1 - p1).norm() < 1e-12 && (cs[k].p2 - p2).norm() < 1e-12)
                .unwrap_or_else(|| panic!("{feature:?}: no {kind:?} at {p1:?}, {p2:?} in {cs:?}"));
            assert!(
                (cs[k].g_n - g).abs() < 1e-12 && (cs[k].n - n).norm() < 1e-12,
                "{kind:?}: {:?} vs {g}, {n:?}",
                cs[k]
            );
            kinds_met[kind as usize] += 1;
        }
    }
    assert!(compared > 400 && skipped < 10, "compared {compared}, skipped {skipped}");
    assert!(kinds_met.iter().all(|&n| n > 50), "incident corners, reference corners, crossings {kinds_met:?}");
}

/// One evaluation of a box–box pair builds its manifold once ([`evaluate`] and
/// [`crate::contact::contact_kinematics`] alike, face and edge features), and fills the same
/// candidates as asking for each one separately (the path that built the manifold once per
/// candidate): geometry, `ġ_N` and `ġ_T` of the material points, bit for bit.
#[test]
fn box_box_pair_is_clipped_once_per_evaluation() {
    use crate::contact::kinematics::{contact_kinematics, BodyMotion, ContactKinematics};
    let builds = || box_box::BUILDS.with(|b| b.get());
    let mut rng = Rng::new(4);
    let mut features = [0usize; 2];
    for (c1, c2) in [(sample("box"), sample("box_b")), (sample("box_b"), sample("box"))] {
        let pair = ContactPair::new("bb", c1, c2).unwrap();
        for _ in 0..40 {
            let (x1, mut x2) = random_poses(&mut rng, false);
            x2.r = x1.r + (x2.r - x1.r).normalize() * rng.uniform(0.15, 0.5);
            let body = |rng: &mut Rng, x: Pose| BodyMotion {
                pose: x,
                twist: Motion::new(rng.vec3(1.0), rng.vec3(1.0)),
                acc: Motion::new(rng.vec3(1.0), rng.vec3(1.0)),
            };
            let (b1, b2) = (body(&mut rng, x1), body(&mut rng, x2));
            let mut points = [ContactPoint::default(); 8];
            let mut kin = [ContactKinematics::default(); 8];
            let n0 = builds();
            evaluate(&pair, &x1, &x2, &mut points).unwrap();
            assert_eq!(builds() - n0, 1, "evaluate builds the manifold once");
            contact_kinematics(&pair, &b1, &b2, &mut kin).unwrap();
            assert_eq!(builds() - n0, 2, "contact_kinematics builds the manifold once");
            features[usize::from(matches!(pair.box_feature(&x1, &x2), Some(box_box::Feature::Edge { .. })))] += 1;
            for k in 0..8 {
                let r = pair.candidate(k, &x1, &x2, None);
                let rt = pair.candidate(k, &x1, &x2, Some((&b1.twist, &b2.twist)));
                let (c, kk) = (&points[k], &kin[k]);
                assert!(c.g_n == r.g && c.n == r.n && c.p1 == r.p1 && c.p2 == r.p2, "candidate {k}");
                assert!(kk.point == *c, "candidate {k}");
                let dv = b1.point_velocity(&rt.p1) - b2.point_velocity(&rt.p2);
                assert!(kk.gd_n == rt.n.dot(&dv) && kk.gd_t == [c.t1.dot(&dv), c.t2.dot(&dv)], "candidate {k}");
            }
        }
    }
    assert!(features[0] > 20 && features[1] > 5, "face, edge features {features:?}");
}

/// The separating-axis test from `R = AᵀB` picks the feature of the test computed axis by axis in
/// world components, with the same separation (to rounding): on random placements, on stacked
/// boxes turned by tiny angles (near ties between face and edge axes, edge axes next to face
/// normals, nearly parallel edges) and on cubes turned by 45°.
#[test]
fn box_box_axis_test_from_the_relative_rotation_equals_the_direct_one() {
    let mut rng = Rng::new(99);
    let cube = cuboid(Vec3::repeat(0.1));
    for (c1, c2) in [
        (sample("box"), sample("box_b")),
        (cuboid(Vec3::new(0.2, 0.15, 0.1)), cuboid(Vec3::new(0.2, 0.15, 0.1))),
        (cube.clone(), cube),
    ] {
        let pair = ContactPair::new("bb", c1, c2).unwrap();
        let Geometry::BoxBox { a, b, scale } = &pair.geometry else { unreachable!() };
        for it in 0..3000 {
            let (x1, x2) = match it % 3 {
                0 => {
                    let (x1, mut x2) = random_poses(&mut rng, false);
                    x2.r = x1.r + (x2.r - x1.r).normalize() * rng.uniform(0.1, 0.6);
                    (x1, x2)
                }
                1 => {
                    // stacked, turned by 1e-12 .. 1e-2 rad about random axes, shifted sideways
                    let tilt = |rng: &mut Rng| rot(&rng.unit(), 10f64.powf(rng.uniform(-12.0, -2.0)));
                    let r = Vec3::new(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), 0.2 + rng.uniform(-1e-3, 1e-3));
                    (Pose::new(tilt(&mut rng), r), Pose::new(tilt(&mut rng), Vec3::zeros()))
                }
                _ => {
                    let q = std::f64::consts::FRAC_PI_4 * (rng.next_u64() % 3) as f64;
                    let r = Vec3::new(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(0.15, 0.35));
                    (Pose::new(rot(&Vec3::new(rng.uniform(-1.0, 1.0), 0.0, 1.0), q), r), Pose::IDENTITY)
                }
            };
            let (f, s) = box_box::feature(&x1, &x2, a, b, *scale);
            let (fd, sd) = box_box::feature_direct(&x1, &x2, a, b, *scale);
            assert_eq!(f, fd, "#{it}: {x1:?} {x2:?}");
            assert!((s - sd).abs() <= 1e-14, "#{it}: separation {s} vs {sd}");
        }
    }
}

/// The one-pass evaluation of every pair (shared work, as the kinematics uses it) equals its
/// candidate-by-candidate evaluation bit for bit, with and without rates, in both orders.
#[test]
fn each_candidate_equals_candidate_by_candidate_for_every_pair() {
    let mut rng = Rng::new(31);
    let boxes = [("box", "box_b")];
    for (a, b) in PAIRS.iter().chain(boxes.iter()) {
        let (c1, c2) = (sample(a), sample(b));
        for (ca, cb) in [(c1.clone(), c2.clone()), (c2, c1)] {
            let pair = ContactPair::new("p", ca, cb).unwrap();
            for it in 0..10 {
                let (x1, x2) = random_poses(&mut rng, pair.is_planar() && it % 2 == 0);
                let (w1, w2) = (Motion::new(rng.vec3(1.0), rng.vec3(1.0)), Motion::new(rng.vec3(1.0), rng.vec3(1.0)));
                for tw in [None, Some((&w1, &w2))] {
                    let mut seen = 0;
                    pair.each_candidate(&x1, &x2, tw, |k, r| {
                        let c = pair.candidate(k, &x1, &x2, tw);
                        let same = [(r.g, c.g)].iter().all(|(x, y)| x.to_bits() == y.to_bits())
                            && [(r.n, c.n), (r.p1, c.p1), (r.p2, c.p2), (r.nd, c.nd), (r.p1d, c.p1d), (r.p2d, c.p2d)]
                                .iter()
                                .all(|(x, y)| x.iter().zip(y.iter()).all(|(u, v)| u.to_bits() == v.to_bits()));
                        assert!(same, "{a}–{b} #{it} candidate {k}: {r:?} vs {c:?}");
                        seen += 1;
                    });
                    assert_eq!(seen, pair.candidates());
                }
            }
        }
    }
}

/// Clipping passes that cut nothing, done in place, give the plain clipping's manifold bit for
/// bit: equal and unequal boxes stacked with offsets from zero to past the edge, turned by tiny
/// angles, exactly aligned (corners on the side planes) and at random.
#[test]
fn box_box_in_place_clipping_passes_equal_the_plain_ones() {
    let mut rng = Rng::new(5);
    let h = Vec3::new(0.2, 0.15, 0.1);
    let (mut uncut, mut cut) = (0, 0);
    for (c1, c2) in [(cuboid(h), cuboid(h)), (cuboid(h * 0.5), cuboid(h)), (sample("box"), sample("box_b"))] {
        let pair = ContactPair::new("bb", c1, c2).unwrap();
        let Geometry::BoxBox { a, b, scale } = &pair.geometry else { unreachable!() };
        for it in 0..2000 {
            let (x1, x2) = if it % 4 == 3 {
                random_poses(&mut rng, false)
            } else {
                let angle = if it % 4 == 0 { 0.0 } else { 10f64.powf(rng.uniform(-14.0, -3.0)) };
                let off = if it % 2 == 0 {
                    Vec3::zeros()
                } else {
                    Vec3::new(rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0.0)
                };
                (
                    Pose::new(rot(&rng.unit(), angle), Vec3::new(off.x, off.y, 0.2 + rng.uniform(-1e-4, 1e-4))),
                    Pose::IDENTITY,
                )
            };
            if let Some((same, t)) = box_box::shortcut_agrees(&x1, &x2, a, b, *scale) {
                assert!(same, "#{it}: {x1:?}");
                if t {
                    uncut += 1
                } else {
                    cut += 1
                }
            }
        }
    }
    assert!(uncut > 500 && cut > 500, "uncut {uncut}, cut {cut}");
}
