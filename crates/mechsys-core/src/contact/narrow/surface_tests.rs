//! Surfaces of revolution and spline patches against closed forms: circle profiles are spheres
//! and tori, a parabola profile a paraboloid; patches sampled from a sphere and a cylinder
//! reproduce their gaps and curvatures to the spline's accuracy, falling at its order.

use crate::contact::narrow::{evaluate, ContactPair, ContactPoint};
use crate::contact::test_util::{rot, Rng};
use crate::contact::Contour;
use crate::geometry::curve::{Curve, Solid, Vec2};
use crate::geometry::revolution::Revolution;
use crate::geometry::surface::Patch;
use crate::math::{Mat3, Vec3};
use crate::spatial::Pose;

fn one(c1: &Contour, x1: &Pose, c2: &Contour, x2: &Pose) -> ContactPoint {
    let mut out = [ContactPoint::default()];
    evaluate(&ContactPair::new("s", c1.clone(), c2.clone()).unwrap(), x1, x2, &mut out).unwrap();
    out[0]
}

fn revolution(profile: Curve, center: Vec3, rotation: Mat3) -> Contour {
    Contour::Revolution(Box::new(Revolution::new(center, rotation, profile, "rev").unwrap()))
}

/// A circle centred on the axis turns into a sphere, one off the axis into a torus: the gaps
/// of a sphere and of a plane, the normals and the principal curvatures of both closed forms.
#[test]
fn circle_profiles_are_spheres_and_tori() {
    let mut rng = Rng::new(17);
    let turn = rot(&Vec3::new(0.2, 1.0, 0.4), 0.9);
    let (big, r0, a) = (0.4, 0.5, 0.15);
    let ball =
        revolution(Curve::ellipse(Vec2::zeros(), big, big, 0.3, "ball").unwrap(), Vec3::new(0.1, 0.0, 0.0), turn);
    let ring = revolution(Curve::ellipse(Vec2::new(r0, 0.0), a, a, 0.0, "ring").unwrap(), Vec3::zeros(), turn);
    let probe = Contour::Sphere { center: Vec3::zeros(), radius: 0.05 };
    let plane = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() };
    for _ in 0..40 {
        let x2 = Pose::new(rng.rotation(), rng.vec3(0.3));
        let x1 = Pose::new(Mat3::identity(), x2.r + rng.unit() * rng.uniform(0.2, 1.0));
        // sphere: |c - centre| - R - r
        let cb = x2.point_to_parent(&Vec3::new(0.1, 0.0, 0.0));
        let c = one(&probe, &x1, &ball, &x2);
        assert!((c.g_n - ((x1.r - cb).norm() - big - 0.05)).abs() < 1e-12, "sphere gap {}", c.g_n);
        assert!((c.n - (x1.r - cb).normalize()).norm() < 1e-9);
        let k = ball.curvatures_at(&x2, &c.p2);
        assert!((k[0] - 1.0 / big).abs() < 1e-9 && (k[1] - 1.0 / big).abs() < 1e-9, "{k:?}");
        // torus: √((ρ - R)² + z²) - a - r
        let y = turn.transpose() * (x2.a.transpose() * (x1.r - x2.r));
        let (rho, z) = (y.x.hypot(y.y), y.z);
        let c = one(&probe, &x1, &ring, &x2);
        assert!((c.g_n - ((rho - r0).hypot(z) - a - 0.05)).abs() < 1e-12, "torus gap {}", c.g_n);
        let cphi = (rho - r0) / (rho - r0).hypot(z);
        let k = ring.curvatures_at(&x2, &c.p2);
        assert!((k[0] - 1.0 / a).abs() < 1e-9 && (k[1] - cphi / (r0 + a * cphi)).abs() < 1e-9, "{k:?}");
        // on a plane: the ball's height over it minus R; the ring as the existing closed-form torus
        let xb = Pose::new(rng.rotation(), Vec3::new(0.0, 0.0, rng.uniform(-0.2, 1.0)));
        let c = one(&ball, &xb, &plane, &Pose::IDENTITY);
        assert!((c.g_n - (xb.point_to_parent(&Vec3::new(0.1, 0.0, 0.0)).z - big)).abs() < 1e-12);
        let torus = Contour::Torus { center: Vec3::zeros(), axis: turn.column(2).into_owned(), radius: r0, tube: a };
        let (ct, cr) = (one(&torus, &xb, &plane, &Pose::IDENTITY), one(&ring, &xb, &plane, &Pose::IDENTITY));
        assert!((ct.g_n - cr.g_n).abs() < 1e-12 && (ct.p1 - cr.p1).norm() < 1e-9, "{} vs {}", ct.g_n, cr.g_n);
    }
}

/// A paraboloid `z = ρ² / (2c)` (an open parabola profile, solid above) on a plane tilted by θ
/// touches where its slope is tan θ: `ρ* = c tan θ`, `z* = c tan² θ / 2` (hand-derived), to the
/// spline's accuracy: the gap error falls 14- and 29-fold per halving of the point spacing
/// (order 4).
#[test]
fn paraboloid_on_a_tilted_plane_touches_where_the_slope_matches() {
    let c = 0.5;
    let (theta, height) = (0.35f64, 0.3);
    let m = Vec3::new(theta.sin(), 0.0, theta.cos());
    let plane = Contour::Plane { point: Vec3::zeros(), normal: m };
    let x1 = Pose::new(Mat3::identity(), Vec3::new(0.0, 0.0, height));
    let expected = Vec3::new(-c * theta.tan(), 0.0, height + c * theta.tan().powi(2) / 2.0);
    let mut errors = Vec::new();
    for n in [21, 41, 81] {
        let pts: Vec<Vec2> =
            (0..n).map(|i| -1.0 + 2.0 * i as f64 / (n - 1) as f64).map(|x| Vec2::new(x, x * x / (2.0 * c))).collect();
        let profile = Curve::spline(&pts, false, Solid::Left, "cup").unwrap();
        let cup = revolution(profile, Vec3::zeros(), Mat3::identity());
        let k = one(&cup, &x1, &plane, &Pose::IDENTITY);
        assert!((k.n - m).norm() < 1e-15);
        // the gap converges at the spline's order; the contact point, where the surface is
        // flat along the plane, only as its normal does (an order less)
        assert!((k.p1 - expected).norm() < 2e-4, "n {n}: contact point {} vs {expected}", k.p1);
        errors.push((k.g_n - m.dot(&expected)).abs());
    }
    // measured: 2.7e-6, 2.0e-7, 6.8e-9
    assert!(errors[2] < 1e-7, "{errors:?}");
    assert!(errors[0] / errors[1] > 10.0 && errors[1] / errors[2] > 10.0, "order: {errors:?}");
}

/// A profile may not cross the axis unless it is its own mirror image.
#[test]
fn a_profile_crossing_the_axis_is_refused() {
    let off = Curve::ellipse(Vec2::new(0.1, 0.0), 0.3, 0.2, 0.0, "p").unwrap();
    let e = Revolution::new(Vec3::zeros(), Mat3::identity(), off, "contact 'egg': contour 2 (revolution)").unwrap_err();
    assert!(
        e.to_string().contains("contact 'egg': contour 2 (revolution): revolution profile crosses the axis"),
        "{e}"
    );
    let centred = Curve::ellipse(Vec2::zeros(), 0.3, 0.2, 0.0, "p").unwrap();
    Revolution::new(Vec3::zeros(), Mat3::identity(), centred, "egg").unwrap();
}

fn grid(n: usize, lo: (f64, f64), hi: (f64, f64), f: impl Fn(f64, f64) -> Vec3) -> Vec<Vec<Vec3>> {
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let u = lo.0 + (hi.0 - lo.0) * i as f64 / (n - 1) as f64;
                    let v = lo.1 + (hi.1 - lo.1) * j as f64 / (n - 1) as f64;
                    f(u, v)
                })
                .collect()
        })
        .collect()
}

/// A patch sampled from a spherical cap (natural ends) and one from a cylinder (periodic around
/// it): a ball's gap and the curvatures near the middle match the closed forms; the gap error
/// falls at about the spline's order 4 and the curvature error at order 2 or better.
#[test]
fn patches_sampled_from_a_sphere_and_a_cylinder_converge_to_the_closed_forms() {
    let r = 1.0;
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.1 };
    let centre = Vec3::new(0.05, -0.08, 0.0);
    let x1 = Pose::new(Mat3::identity(), Vec3::new(0.13, -0.02, 1.4));
    let (mut eg, mut ek) = (Vec::new(), Vec::new());
    for n in [9, 17, 33] {
        let cap = grid(n, (-0.6, -0.6), (0.6, 0.6), |x, y| centre + Vec3::new(x, y, (r * r - x * x - y * y).sqrt()));
        let patch =
            Contour::Patch(Box::new(Patch::new(&cap, (-0.6, 0.6), (-0.6, 0.6), [false, false], "cap").unwrap()));
        let c = one(&ball, &x1, &patch, &Pose::IDENTITY);
        eg.push((c.g_n - ((x1.r - centre).norm() - r - 0.1)).abs());
        let k = patch.curvatures_at(&Pose::IDENTITY, &c.p2);
        ek.push((k[0] - 1.0 / r).abs().max((k[1] - 1.0 / r).abs()));
    }
    assert!(eg[2] < 1e-6 && ek[2] < 1e-3, "gap errors {eg:?}, curvature errors {ek:?}");
    assert!(eg[0] / eg[1] > 10.0 && eg[1] / eg[2] > 10.0, "gap order: {eg:?}");
    assert!(ek[0] / ek[1] > 3.5 && ek[1] / ek[2] > 3.5, "curvature order: {ek:?}");

    // a solid cylinder of radius R about z, periodic in the angle: r_θ × r_z points outward
    let mut eg = Vec::new();
    let tau = std::f64::consts::TAU;
    let x1 = Pose::new(Mat3::identity(), Vec3::new(0.9, 0.7, 0.1));
    for n in [9, 17, 33] {
        let cyl = grid(n, (0.0, -1.0), (tau, 1.0), |t, z| Vec3::new(r * t.cos(), r * t.sin(), z));
        let patch = Contour::Patch(Box::new(Patch::new(&cyl, (0.0, tau), (-1.0, 1.0), [true, false], "cyl").unwrap()));
        let c = one(&ball, &x1, &patch, &Pose::IDENTITY);
        eg.push((c.g_n - (x1.r.x.hypot(x1.r.y) - r - 0.1)).abs());
        if n == 33 {
            let k = patch.curvatures_at(&Pose::IDENTITY, &c.p2);
            assert!((k[0] - 1.0 / r).abs() < 5e-3 && k[1].abs() < 1e-9, "{k:?}");
        }
    }
    // measured: 3.2e-4, 4.8e-5, 3.4e-6 (coarse grids of 8 and 16 cells around)
    assert!(eg[2] < 1e-5 && eg[0] / eg[1] > 5.0 && eg[1] / eg[2] > 10.0, "cylinder gap errors {eg:?}");
}

/// Bad grids name the contour and what is wrong.
#[test]
fn bad_patch_grids_are_refused() {
    let what = "contact 'ground': contour 2 (patch)";
    let ok = grid(5, (0.0, 0.0), (1.0, 1.0), |x, y| Vec3::new(x, y, 0.0));
    let mut nan = ok.clone();
    nan[2][3].z = f64::NAN;
    let e = Patch::new(&nan, (0.0, 1.0), (0.0, 1.0), [false, false], what).unwrap_err().to_string();
    assert!(e.contains(what) && e.contains("patch point [2][3] must be finite"), "{e}");
    let mut ragged = ok.clone();
    ragged[1].pop();
    let e = Patch::new(&ragged, (0.0, 1.0), (0.0, 1.0), [false, false], what).unwrap_err().to_string();
    assert!(e.contains("rectangular: row 1 has 4 points"), "{e}");
    let e = Patch::new(&ok, (0.0, 1.0), (0.0, 1.0), [true, false], what).unwrap_err().to_string();
    assert!(e.contains("periodic in s1 but its last row does not repeat the first"), "{e}");
    let e = Patch::new(&ok[..1], (0.0, 1.0), (0.0, 1.0), [false, false], what).unwrap_err().to_string();
    assert!(e.contains("at least 2 points along s1"), "{e}");
    // a pole: the first row collapsed to one point
    let pole = grid(5, (0.0, 0.0), (1.0, 1.0), |x, y| Vec3::new(x * y, x * (1.0 - y), x));
    let e = Patch::new(&pole, (0.0, 1.0), (0.0, 1.0), [false, false], what).unwrap_err().to_string();
    assert!(e.contains("patch has no normal at (s1, s2) = (0.0000"), "{e}");
    let e = Patch::new(&ok, (1.0, 0.0), (0.0, 1.0), [false, false], what).unwrap_err().to_string();
    assert!(e.contains("range s1 must be finite and increasing"), "{e}");
}

/// Beyond a natural patch's edge the foot point is the nearest edge point and the edge's tangent
/// plane continues the surface: finite values, `P1 - P2 = g n`, the gap the height over that
/// plane (a flat patch: the plane itself); finite rates.
#[test]
fn beyond_a_patch_edge_the_tangent_plane_continues_it() {
    use crate::contact::kinematics::{contact_kinematics, BodyMotion, ContactKinematics};
    use crate::spatial::Motion;
    let flat = grid(5, (0.0, 0.0), (1.0, 1.0), |x, y| Vec3::new(x, y, 0.1 * x));
    let patch = Contour::Patch(Box::new(Patch::new(&flat, (0.0, 1.0), (0.0, 1.0), [false, false], "flat").unwrap()));
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.05 };
    for c in [Vec3::new(1.5, 0.5, 0.4), Vec3::new(-0.3, 1.2, 0.2), Vec3::new(0.5, -0.5, -0.1)] {
        let x1 = Pose::new(Mat3::identity(), c);
        let k = one(&ball, &x1, &patch, &Pose::IDENTITY);
        let m = Vec3::new(-0.1, 0.0, 1.0).normalize();
        assert!((k.n - m).norm() < 1e-9, "{}", k.n);
        assert!((k.g_n - (m.dot(&c) - 0.05)).abs() < 1e-9, "{} vs {}", k.g_n, m.dot(&c) - 0.05);
        assert!((k.p1 - k.p2 - k.n * k.g_n).norm() < 1e-12);
        let pair = ContactPair::new("s", ball.clone(), patch.clone()).unwrap();
        let b1 = BodyMotion {
            pose: x1,
            twist: Motion::new(Vec3::new(0.3, -1.0, 0.2), Vec3::new(0.5, 0.1, -0.2)),
            acc: Motion::ZERO,
        };
        let mut out = [ContactKinematics::default()];
        contact_kinematics(&pair, &b1, &BodyMotion::GROUND, &mut out).unwrap();
        assert!(out[0].gd_n.is_finite() && out[0].wbar_n.is_finite() && out[0].gd_t.iter().all(|v| v.is_finite()));
    }
}

/// An ellipsoid on a patch sampled from a tilted plane (which the spline reproduces exactly) has
/// the closed-form ellipsoid–plane contact: gap, normal and contact point.
#[test]
fn ellipsoid_on_a_planar_patch_is_the_ellipsoid_plane_contact() {
    let mut rng = Rng::new(23);
    let m = Vec3::new(0.2, -0.1, 1.0).normalize();
    // points of the plane m·x = 0 over a square
    let flat = grid(9, (-2.0, -2.0), (2.0, 2.0), |x, y| Vec3::new(x, y, -(m.x * x + m.y * y) / m.z));
    let patch = Contour::Patch(Box::new(Patch::new(&flat, (0.0, 1.0), (0.0, 1.0), [false, false], "flat").unwrap()));
    let plane = Contour::Plane { point: Vec3::zeros(), normal: m };
    let egg = Contour::Ellipsoid {
        center: Vec3::new(0.02, 0.0, -0.03),
        rotation: rot(&Vec3::new(1.0, 0.3, 0.2), 0.4),
        semi_axes: Vec3::new(0.3, 0.2, 0.12),
    };
    for _ in 0..30 {
        let x1 = Pose::new(
            rng.rotation(),
            Vec3::new(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-0.1, 0.6)),
        );
        let (a, b) = (one(&egg, &x1, &patch, &Pose::IDENTITY), one(&egg, &x1, &plane, &Pose::IDENTITY));
        assert!((a.g_n - b.g_n).abs() < 1e-12, "{} vs {}", a.g_n, b.g_n);
        assert!((a.n - b.n).norm() < 1e-9 && (a.p1 - b.p1).norm() < 1e-9);
    }
}
