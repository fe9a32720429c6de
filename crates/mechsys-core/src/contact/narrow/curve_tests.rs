//! Parametric contour pairs against references computed without the contact search: closed
//! forms (ellipse against a line, a disc in an elliptical hole), and dense sampling refined by
//! golden-section search (`test_util::curve_sdf`) for the distance to a curve.

use super::*;
use crate::contact::test_util::{curve_sample, curve_sdf, rot, Rng};
use crate::geometry::curve::{Curve, Follower, Vec2};
use std::f64::consts::{PI, TAU};

fn curve(c: &Contour) -> &Curve {
    match c {
        Contour::Curve(c) => c,
        _ => unreachable!(),
    }
}

fn planar_pose(angle: f64, x: f64, y: f64) -> Pose {
    Pose::new(rot(&Vec3::z(), angle), Vec3::new(x, y, 0.0))
}

fn eval(pair: &ContactPair, x1: &Pose, x2: &Pose) -> Vec<ContactPoint> {
    let mut out = vec![ContactPoint::default(); pair.candidates()];
    evaluate(pair, x1, x2, &mut out).unwrap();
    out
}

/// Body-frame point of a world point on a planar body.
fn local(x: &Pose, p: &Vec3) -> Vec2 {
    let l = x.a.transpose() * (p - x.r);
    Vec2::new(l.x, l.y)
}

#[test]
fn circle_against_ellipse_gap_equals_the_sampled_distance() {
    let ell = curve_sample("ellipse");
    let mut rng = Rng::new(11);
    for it in 0..40 {
        let r = 0.05;
        let pair = ContactPair::new("c", Contour::Circle { center: Vec2::zeros(), radius: r }, ell.clone()).unwrap();
        let x2 = planar_pose(rng.uniform(-3.0, 3.0), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2));
        // centres from well inside to outside the ellipse
        let dir = rng.uniform(0.0, TAU);
        let dist = rng.uniform(0.1, 0.7);
        let x1 = planar_pose(0.0, x2.r.x + dist * dir.cos(), x2.r.y + dist * dir.sin());
        let c = eval(&pair, &x1, &x2)[0];
        let (d, _) = curve_sdf(curve(&ell), &local(&x2, &x1.r));
        assert!((c.g_n - (d - r)).abs() < 1e-10, "#{it}: gap {} vs sampled {}", c.g_n, d - r);
        // the points lie on their contours and the normal is the ellipse's outward normal
        assert!(((c.p1 - x1.r).norm() - r).abs() < 1e-12);
        assert!(curve_sdf(curve(&ell), &local(&x2, &c.p2)).0.abs() < 1e-10);
        assert!((c.p1 - c.p2 - c.n * c.g_n).norm() < 1e-14);
    }
}

#[test]
fn ellipse_pairs_against_independent_references() {
    let (e1, e2) = (curve_sample("ellipse_b"), curve_sample("ellipse"));
    let (c1, c2) = (curve(&e1), curve(&e2));
    let mut rng = Rng::new(12);
    for it in 0..6 {
        let x1 = planar_pose(rng.uniform(-3.0, 3.0), rng.uniform(0.5, 0.8), rng.uniform(-0.3, 0.3));
        let x2 = planar_pose(rng.uniform(-3.0, 3.0), 0.0, 0.0);
        let pair = ContactPair::new("ee", e1.clone(), e2.clone()).unwrap();
        let c = eval(&pair, &x1, &x2)[0];
        // reference: the smallest signed distance of ellipse 1's points to ellipse 2, over a
        // dense grid of ellipse 1's parameter refined by golden-section search
        let phi = |s: f64| {
            let p = x1.point_to_parent(&Vec3::new(c1.eval(s)[0].x, c1.eval(s)[0].y, 0.0));
            curve_sdf(c2, &local(&x2, &p)).0
        };
        let n = 400;
        let (mut best, mut sb) = (f64::INFINITY, 0.0);
        for i in 0..n {
            let s = TAU * i as f64 / n as f64;
            let v = phi(s);
            if v < best {
                best = v;
                sb = s;
            }
        }
        let (mut a, mut b) = (sb - TAU / n as f64, sb + TAU / n as f64);
        let gr = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..60 {
            let (m1, m2) = (b - gr * (b - a), a + gr * (b - a));
            if phi(m1) < phi(m2) {
                b = m2;
            } else {
                a = m1;
            }
        }
        let reference = phi(0.5 * (a + b));
        assert!((c.g_n - reference).abs() < 1e-10, "#{it}: ellipse–ellipse gap {} vs {reference}", c.g_n);
        // ellipse against a line: the support function in closed form, h = m·c - √(a²(m·u)² + b²(m·v)²)
        let m = Vec2::new(0.3, 1.0).normalize();
        let pl = ContactPair::new("el", e2.clone(), Contour::Line { point: Vec2::new(0.0, -0.5), normal: m }).unwrap();
        let xg = planar_pose(0.2, 0.0, 0.0);
        let c = eval(&pl, &x1, &xg)[0];
        let (ax, bx, ang, ctr) = (0.35, 0.2, 0.3, Vec2::new(0.05, -0.02));
        let mw = rot(&Vec3::z(), 0.2) * Vec3::new(m.x, m.y, 0.0);
        let pw = xg.point_to_parent(&Vec3::new(0.0, -0.5, 0.0));
        let a1 = x1.a * rot(&Vec3::z(), ang);
        let (u, v) = (a1.column(0).into_owned(), a1.column(1).into_owned());
        let cw = x1.point_to_parent(&Vec3::new(ctr.x, ctr.y, 0.0));
        let h = mw.dot(&(cw - pw)) - (ax * ax * mw.dot(&u).powi(2) + bx * bx * mw.dot(&v).powi(2)).sqrt();
        assert!((c.g_n - h).abs() < 1e-13, "#{it}: ellipse–line gap {} vs closed form {h}", c.g_n);
        assert!((c.n - mw).norm() < 1e-14);
    }
}

#[test]
fn roller_on_a_cam_with_a_hollow_flank_finds_the_global_minimum_over_a_revolution() {
    // a lift with a sharp rise: the pitch curve has concave flanks
    let n = 180;
    let ang: Vec<f64> = (0..=n).map(|i| TAU * i as f64 / n as f64).collect();
    let lift: Vec<f64> = ang.iter().map(|t| 0.012 * (-((t - 2.0) / 0.35).powi(2)).exp() + 0.006 * (1.0 - t.cos())).collect();
    let cam = Curve::cam(&ang, &lift, 0.03, Follower::Roller { radius: 0.008, eccentricity: 0.004 }, 1.0, "cam").unwrap();
    assert_eq!(cam.convexity(), crate::geometry::curve::Convexity::Mixed);
    let contour = Contour::Curve(Box::new(cam.clone()));
    let pair = ContactPair::new("cf", Contour::Circle { center: Vec2::zeros(), radius: 0.008 }, contour).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..720 {
        let theta = TAU * k as f64 / 720.0;
        let x2 = planar_pose(theta, 0.0, 0.0);
        // the roller centre at the prescribed lift along the follower axis (+y), plus a clearance
        let base = ((0.03f64 + 0.008).powi(2) - 0.004f64.powi(2)).sqrt();
        let hl = 0.012 * (-((theta - 2.0) / 0.35).powi(2)).exp() + 0.006 * (1.0 - theta.cos());
        let x1 = planar_pose(0.0, 0.004, base + hl + 0.001);
        let c = eval(&pair, &x1, &x2)[0];
        let (d, _) = curve_sdf(&cam, &local(&x2, &x1.r));
        worst = worst.max((c.g_n - (d - 0.008)).abs());
        assert!((c.g_n - (d - 0.008)).abs() < 1e-9, "cam angle {theta}: gap {} vs sampled {}", c.g_n, d - 0.008);
    }
    assert!(worst < 1e-9);
}

#[test]
fn disc_in_an_elliptical_hole_touches_at_two_points() {
    let (a, b, r) = (0.5, 0.3, 0.28);
    let hole = Contour::Curve(Box::new(Curve::ellipse(Vec2::zeros(), a, b, 0.0, "hole").unwrap().flipped()));
    let disc = Contour::Circle { center: Vec2::zeros(), radius: r };
    let pair = ContactPair::new("h", disc.clone(), hole.clone()).unwrap().with_points(2).unwrap();
    let x2 = planar_pose(0.4, 0.1, -0.2);
    let x1 = Pose::new(Mat3::identity(), x2.r);
    let c = eval(&pair, &x1, &x2);
    for p in &c {
        assert!((p.g_n - (b - r)).abs() < 1e-12, "gap {} vs b - r = {}", p.g_n, b - r);
        // the normal points from the hole's wall towards the disc centre
        assert!((p.n + (p.p1 - x1.r).normalize()).norm() < 1e-12);
    }
    assert!((c[0].n + c[1].n).norm() < 1e-12, "the two contacts face each other");
    // one point: the deeper of the two; moved up, the upper wall closes
    let one = ContactPair::new("h", disc, hole).unwrap();
    let x1 = Pose::new(Mat3::identity(), x2.r + x2.a * Vec3::new(0.0, 0.01, 0.0));
    let c1 = eval(&one, &x1, &x2)[0];
    assert!((c1.g_n - (b - r - 0.01)).abs() < 1e-12, "{}", c1.g_n);
    assert!(((x2.a.transpose() * c1.n).y + 1.0).abs() < 1e-12);
    // the pair with two points keeps them ordered along the hole, the far one unchanged in gap
    let c2 = eval(&pair, &x1, &x2);
    let mut gaps: Vec<f64> = c2.iter().map(|p| p.g_n).collect();
    gaps.sort_by(f64::total_cmp);
    assert!((gaps[0] - (b - r - 0.01)).abs() < 1e-12 && (gaps[1] - (b - r + 0.01)).abs() < 1e-12, "{gaps:?}");
    // asking a primitive pair for points is an error naming it
    let e = ContactPair::new("s", Contour::Circle { center: Vec2::zeros(), radius: 1.0 }, Contour::Line {
        point: Vec2::zeros(),
        normal: Vec2::y(),
    })
    .unwrap()
    .with_points(2)
    .unwrap_err();
    assert!(e.to_string().contains("circle–line"), "{e}");
}

#[test]
fn curve_pairs_give_finite_values_in_degenerate_placements() {
    // coincident centres, a point at an ellipse's centre of curvature, NaN-free everywhere
    let ell = curve_sample("ellipse");
    for (c1, x1) in [
        (Contour::Point2 { p: Vec2::new(0.05, -0.02) }, Pose::IDENTITY),
        (curve_sample("ellipse_b"), Pose::IDENTITY),
        (curve_sample("cam"), Pose::IDENTITY),
    ] {
        let pair = ContactPair::new("d", c1, ell.clone()).unwrap();
        let mut out = vec![ContactPoint::default(); pair.candidates()];
        evaluate(&pair, &x1, &Pose::IDENTITY, &mut out).unwrap();
        for p in &out {
            assert!(p.g_n.is_finite() && p.n.iter().all(|v| v.is_finite()) && (p.n.norm() - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn ellipsoid_on_a_plane_against_sampled_support_and_curvatures_at_the_axes() {
    let mut rng = Rng::new(21);
    let (a, b, c) = (0.4, 0.25, 0.15);
    let shape = Contour::Ellipsoid { center: Vec3::new(0.05, 0.0, -0.02), rotation: rot(&Vec3::new(1.0, 2.0, 0.5), 0.7), semi_axes: Vec3::new(a, b, c) };
    let ground = Contour::Plane { point: Vec3::zeros(), normal: Vec3::new(0.1, -0.2, 1.0) };
    let pair = ContactPair::new("egg", shape.clone(), ground.clone()).unwrap();
    let Contour::Ellipsoid { center, rotation, .. } = &shape else { unreachable!() };
    for it in 0..10 {
        let x1 = Pose::new(rng.rotation(), rng.vec3(0.5));
        let c0 = eval(&pair, &x1, &Pose::IDENTITY)[0];
        // reference: the lowest surface point along the normal by dense sampling of the angles,
        // refined on a finer grid around the best
        let m = Vec3::new(0.1, -0.2, 1.0).normalize();
        let height = |u: f64, v: f64| {
            let y = Vec3::new(a * u.cos() * v.cos(), b * u.sin() * v.cos(), c * v.sin());
            m.dot(&x1.point_to_parent(&(center + rotation * y)))
        };
        let (mut best, mut bu, mut bv) = (f64::INFINITY, 0.0, 0.0);
        for i in 0..720 {
            for j in 0..=360 {
                let (u, v) = (TAU * i as f64 / 720.0, -1.5707963 + std::f64::consts::PI * j as f64 / 360.0);
                let h = height(u, v);
                if h < best {
                    (best, bu, bv) = (h, u, v);
                }
            }
        }
        let mut step = TAU / 720.0;
        for _ in 0..60 {
            let mut moved = false;
            for (du, dv) in [(step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)] {
                let h = height(bu + du, bv + dv);
                if h < best {
                    (best, bu, bv, moved) = (h, bu + du, bv + dv, true);
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
        assert!((c0.g_n - best).abs() < 1e-10, "#{it}: gap {} vs sampled {best}", c0.g_n);
        assert!((c0.n - m).norm() < 1e-15);
    }
    // principal curvatures at the end of the a axis: a/b², a/c²
    let e = Contour::Ellipsoid { center: Vec3::zeros(), rotation: Mat3::identity(), semi_axes: Vec3::new(a, b, c) };
    let k = e.curvatures_at(&Pose::IDENTITY, &Vec3::new(a, 0.0, 0.0));
    assert!((k[0] - a / (c * c)).abs() < 1e-12 && (k[1] - a / (b * b)).abs() < 1e-12, "{k:?}");
}

/// Two involute gears in mesh, z1 = 17 and z2 = 31, m = 2 mm, backlash on both, at the standard
/// centre distance; gear 2 follows gear 1 at the speed ratio -z1/z2 with the drive flanks a gap
/// `delta` apart. Reference (the involutes' own geometry, not the search): a flank pair meets the
/// line of action (the common tangent of the base circles, tangent points T1, T2) at distances
/// `r_b φ` (roll angles) from T1 and T2, so its gap along it is `a sin α - r_b1 φ1 - r_b2 φ2`, the
/// same for every pair in mesh; drive and coast gaps add up to the normal backlash
/// `p_b - s_b1 - s_b2 + 2 (r_b1 + r_b2) inv α`.
#[test]
fn gear_pair_gaps_and_normals_follow_the_lines_of_action() {
    use crate::geometry::gear::{involute_function, GearSpec};
    let (m, z1, z2) = (0.002, 17usize, 31usize);
    let alpha = 20f64.to_radians();
    let j = 0.05 * m;
    let g1 = Curve::gear(&GearSpec { backlash: j, ..GearSpec::new(m, z1) }, "pinion").unwrap();
    let g2 = Curve::gear(&GearSpec { backlash: j, ..GearSpec::new(m, z2) }, "wheel").unwrap();
    let (q1, q2) = (g1.as_gear().unwrap().clone(), g2.as_gear().unwrap().clone());
    let (rb1, rb2) = (q1.base_radius(), q2.base_radius());
    let a = 0.5 * m * (z1 + z2) as f64;
    let (psi1, psi2) = (q1.base_half_angle(), q2.base_half_angle());
    let pb = TAU * rb1 / z1 as f64;
    let jn = pb - 2.0 * rb1 * psi1 - 2.0 * rb2 * psi2 + 2.0 * (rb1 + rb2) * involute_function(alpha);
    assert!((jn - 2.0 * j * alpha.cos()).abs() < 1e-15, "normal backlash {jn}");
    let delta = 0.3 * jn;
    let pair = ContactPair::new("mesh", Contour::Curve(Box::new(g1)), Contour::Curve(Box::new(g2)))
        .unwrap()
        .with_points(4)
        .unwrap();
    let wrap = |x: f64| x.rem_euclid(TAU);
    let (lo1, hi1) = q1.roll_range();
    let (lo2, hi2) = q2.roll_range();
    // gear 2's angle for gear 1 at 0: tooth 0 of both on the drive line of action at gap delta
    let phi1 = psi1 + alpha;
    let phi2 = (a * alpha.sin() - delta - rb1 * phi1) / rb2;
    let c = PI - alpha + phi2 - psi2;
    // drive: gear 1's upper flanks (unwound clockwise from θ1 + 2πk/z1 + ψ_b1) against gear 2's
    // upper flanks, line of action T1 = r_b1 (cos α, -sin α) → T2, direction e = (sin α, cos α);
    // coast: the lower flanks, mirrored about the centre line
    let pairs_in_mesh = |t1: f64, t2: f64, coast: bool| {
        let mut gaps = Vec::new();
        let sgn = if coast { -1.0 } else { 1.0 };
        for k in 0..z1 {
            let b1 = t1 + TAU * k as f64 / z1 as f64 + sgn * psi1;
            let f1 = wrap(sgn * b1 + alpha);
            for jj in 0..z2 {
                let b2 = t2 + TAU * jj as f64 / z2 as f64 + sgn * psi2;
                let f2 = wrap(sgn * (b2 - PI) + alpha);
                let margin = 1e-6;
                let g = a * alpha.sin() - rb1 * f1 - rb2 * f2;
                // facing flanks (the others are a base pitch or more apart along the line)
                let inside = f1 > lo1 + margin && f1 < hi1 - margin && f2 > lo2 + margin && f2 < hi2 - margin;
                if inside && g.abs() < 0.5 * pb {
                    gaps.push(g);
                }
            }
        }
        gaps
    };
    let x2 = |t2: f64| planar_pose(t2, a, 0.0);
    let n = 60;
    let (mut two, mut worst) = (0, 0.0f64);
    for i in 0..n {
        let t1 = 2.0 * TAU / z1 as f64 * i as f64 / n as f64 + 1e-3;
        let t2 = c - (z1 as f64 / z2 as f64) * t1;
        let (drive, coast) = (pairs_in_mesh(t1, t2, false), pairs_in_mesh(t1, t2, true));
        assert!(!drive.is_empty() && !coast.is_empty(), "contact ratio > 1: always a pair in mesh");
        for g in drive.iter() {
            assert!((g - delta).abs() < 1e-15, "conjugate: every drive pair at delta, {g}");
        }
        for g in coast.iter() {
            assert!((g - (jn - delta)).abs() < 1e-15);
        }
        two += (drive.len() == 2) as usize;
        let pts = eval(&pair, &planar_pose(t1, 0.0, 0.0), &x2(t2));
        let e_drive = Vec3::new(alpha.sin(), alpha.cos(), 0.0);
        let e_coast = Vec3::new(alpha.sin(), -alpha.cos(), 0.0);
        let near = |p: &ContactPoint, g: f64| (p.g_n - g).abs() < 1e-12;
        let (mut nd, mut nc) = (0, 0);
        for p in &pts {
            if near(p, delta) {
                nd += 1;
                // n points from body 2's contour towards body 1: against the drive direction
                assert!((p.n + e_drive).norm() < 1e-10, "t1 = {t1}: drive normal {:?}", p.n);
            } else if near(p, jn - delta) {
                nc += 1;
                assert!((p.n + e_coast).norm() < 1e-10, "t1 = {t1}: coast normal {:?}", p.n);
            }
            let err = (p.g_n - delta).abs().min((p.g_n - jn + delta).abs());
            if err < 1e-9 {
                worst = worst.max(err);
            }
        }
        let least = pts.iter().map(|p| p.g_n).fold(f64::INFINITY, f64::min);
        assert!((least - delta).abs() < 1e-12, "t1 = {t1}: least gap {least} vs {delta}");
        assert_eq!(nd, drive.len(), "t1 = {t1}: drive pairs found {nd}, in mesh {}", drive.len());
        assert!(nc >= 1 && nc <= coast.len(), "t1 = {t1}: coast pairs found {nc}, in mesh {}", coast.len());
    }
    assert!(two > n / 4 && two < n, "two pairs in mesh part of the time: {two} of {n}");
    eprintln!("gear pair: worst gap error {worst:e}");
}
