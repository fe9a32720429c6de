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
    let lift: Vec<f64> =
        ang.iter().map(|t| 0.012 * (-((t - 2.0) / 0.35).powi(2)).exp() + 0.006 * (1.0 - t.cos())).collect();
    let cam =
        Curve::cam(&ang, &lift, 0.03, Follower::Roller { radius: 0.008, eccentricity: 0.004 }, 1.0, "cam").unwrap();
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
    let e = ContactPair::new(
        "s",
        Contour::Circle { center: Vec2::zeros(), radius: 1.0 },
        Contour::Line { point: Vec2::zeros(), normal: Vec2::y() },
    )
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
    let shape = Contour::Ellipsoid {
        center: Vec3::new(0.05, 0.0, -0.02),
        rotation: rot(&Vec3::new(1.0, 2.0, 0.5), 0.7),
        semi_axes: Vec3::new(a, b, c),
    };
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
                let (u, v) =
                    (TAU * i as f64 / 720.0, -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * j as f64 / 360.0);
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

/// Two involute gears in mesh at the standard centre distance, m = 2 mm, backlash on both; gear 2
/// follows gear 1 at the speed ratio -z1/z2 with the drive flanks a gap `delta` apart.
/// Reference (the involutes' own geometry, not the search): a flank pair meets the line of action
/// (the common tangent of the base circles, tangent points T1, T2) at distances `r_b φ` (roll
/// angles) from T1 and T2, so its gap along it is `a sin α - r_b1 φ1 - r_b2 φ2`, the same for every
/// pair in mesh; drive and coast gaps add up to the normal backlash
/// `p_b - s_b1 - s_b2 + 2 (r_b1 + r_b2) inv α`.
struct Mesh {
    z: (usize, usize),
    pair2: ContactPair,
    pair4: Option<ContactPair>,
    alpha: f64,
    a: f64,
    rb: (f64, f64),
    psi: (f64, f64),
    roll: ((f64, f64), (f64, f64)),
    pb: f64,
    jn: f64,
    delta: f64,
    /// gear 2's angle for gear 1 at 0
    c: f64,
}

impl Mesh {
    fn new(z1: usize, z2: usize) -> Mesh {
        use crate::geometry::gear::{involute_function, GearSpec};
        let (m, alpha) = (0.002, 20f64.to_radians());
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
        let pair = ContactPair::new("mesh", Contour::Curve(Box::new(g1)), Contour::Curve(Box::new(g2))).unwrap();
        let pair4 = pair.clone().with_points(4).ok();
        // tooth 0 of both on the drive line of action at gap delta
        let phi1 = psi1 + alpha;
        let phi2 = (a * alpha.sin() - delta - rb1 * phi1) / rb2;
        Mesh {
            z: (z1, z2),
            pair2: pair.with_points(2).unwrap(),
            pair4,
            alpha,
            a,
            rb: (rb1, rb2),
            psi: (psi1, psi2),
            roll: (q1.roll_range(), q2.roll_range()),
            pb,
            jn,
            delta,
            c: PI - alpha + phi2 - psi2,
        }
    }

    /// Gaps of the flank pairs in involute action: drive (gear 1's upper flanks, unwound
    /// clockwise from θ1 + 2πk/z1 + ψ_b1, against gear 2's upper flanks; line of action from
    /// T1 = r_b1 (cos α, -sin α) along e = (sin α, cos α)) or coast (the lower flanks, mirrored).
    fn in_mesh(&self, t1: f64, coast: bool) -> Vec<f64> {
        let (z1, z2) = self.z;
        let t2 = self.t2(t1);
        let wrap = |x: f64| x.rem_euclid(TAU);
        let sgn = if coast { -1.0 } else { 1.0 };
        let ((lo1, hi1), (lo2, hi2)) = self.roll;
        let mut gaps = Vec::new();
        for k in 0..z1 {
            let f1 = wrap(sgn * (t1 + TAU * k as f64 / z1 as f64 + sgn * self.psi.0) + self.alpha);
            for j in 0..z2 {
                let f2 = wrap(sgn * (t2 + TAU * j as f64 / z2 as f64 + sgn * self.psi.1 - PI) + self.alpha);
                let g = self.a * self.alpha.sin() - self.rb.0 * f1 - self.rb.1 * f2;
                let margin = 1e-6;
                let inside = f1 > lo1 + margin && f1 < hi1 - margin && f2 > lo2 + margin && f2 < hi2 - margin;
                // facing flanks (the others are a base pitch or more apart along the line)
                if inside && g.abs() < 0.5 * self.pb {
                    gaps.push(g);
                }
            }
        }
        gaps
    }

    fn t2(&self, t1: f64) -> f64 {
        self.c - (self.z.0 as f64 / self.z.1 as f64) * t1
    }

    fn eval(&self, pair: &ContactPair, t1: f64) -> Vec<ContactPoint> {
        eval(pair, &planar_pose(t1, 0.0, 0.0), &planar_pose(self.t2(t1), self.a, 0.0))
    }
}

#[test]
fn gear_pair_gaps_and_normals_follow_the_lines_of_action() {
    let mesh = Mesh::new(17, 31);
    let (delta, jn) = (mesh.delta, mesh.jn);
    let e_drive = Vec3::new(mesh.alpha.sin(), mesh.alpha.cos(), 0.0);
    let e_coast = Vec3::new(mesh.alpha.sin(), -mesh.alpha.cos(), 0.0);
    let n = 150;
    let mut two = 0;
    // three tooth pitches of gear 1: through tooth changes and past gear 1's parameter origin
    for i in 0..n {
        let t1 = 3.0 * TAU / 17.0 * i as f64 / n as f64 + 1e-3;
        let (drive, coast) = (mesh.in_mesh(t1, false), mesh.in_mesh(t1, true));
        assert!(!drive.is_empty() && !coast.is_empty(), "contact ratio > 1: always a pair in mesh");
        for g in &drive {
            assert!((g - delta).abs() < 1e-15, "conjugate: every drive pair at delta, {g}");
        }
        for g in &coast {
            assert!((g - (jn - delta)).abs() < 1e-15);
        }
        two += (drive.len() == 2) as usize;
        // two points: the drive side (slot 1: gear 1's upper flanks) and the coast side
        let pts = mesh.eval(&mesh.pair2, t1);
        assert!((pts[1].g_n - delta).abs() < 1e-12, "t1 = {t1}: drive gap {} vs {delta}", pts[1].g_n);
        assert!((pts[0].g_n - (jn - delta)).abs() < 1e-12, "t1 = {t1}: coast gap {} vs {}", pts[0].g_n, jn - delta);
        // n points from body 2's contour towards body 1: against the drive direction
        assert!((pts[1].n + e_drive).norm() < 1e-10, "t1 = {t1}: drive normal {:?}", pts[1].n);
        assert!((pts[0].n + e_coast).norm() < 1e-10, "t1 = {t1}: coast normal {:?}", pts[0].n);
    }
    assert!(two > n / 4 && two < n, "two pairs in mesh part of the time: {two} of {n}");
}

#[test]
fn gear_pair_flanks_keep_their_candidates_through_the_tooth_changes() {
    // z1 = 18: gear 1's teeth alternate in two colours; 4 points = 2 flank sides × 2 colours
    let mesh = Mesh::new(18, 31);
    let pair = mesh.pair4.as_ref().unwrap();
    let n = 400;
    let step = 3.0 * TAU / 18.0 / n as f64;
    let mut prev: Option<Vec<ContactPoint>> = None;
    let (mut seen, mut handovers) = ([0usize; 4], 0);
    for i in 0..n {
        let t1 = step * i as f64 + 1e-3;
        let pts = mesh.eval(pair, t1);
        let (drive, coast) = (mesh.in_mesh(t1, false), mesh.in_mesh(t1, true));
        let at = |g: f64| pts.iter().filter(|p| (p.g_n - g).abs() < 1e-12).count();
        // every flank pair in involute action is a candidate of its own
        assert_eq!(at(mesh.delta), drive.len(), "t1 = {t1}: drive candidates");
        assert_eq!(at(mesh.jn - mesh.delta), coast.len(), "t1 = {t1}: coast candidates");
        // a candidate in action now and before is the same flank: its point on gear 1 moved by
        // no more than the step (the flank rolls along the line of action)
        if let Some(prev) = &prev {
            let x1 = |t: f64, p: &Vec3| local(&planar_pose(t, 0.0, 0.0), p);
            for k in 0..4 {
                let now = [mesh.delta, mesh.jn - mesh.delta].iter().any(|g| (pts[k].g_n - g).abs() < 1e-12);
                let before = [mesh.delta, mesh.jn - mesh.delta].iter().any(|g| (prev[k].g_n - g).abs() < 1e-12);
                if now && before {
                    let moved = (x1(t1, &pts[k].p1) - x1(t1 - step, &prev[k].p1)).norm();
                    assert!(moved < 0.05 * mesh.pb, "t1 = {t1}: candidate {k} jumped by {moved}");
                    seen[k] += 1;
                } else if now != before {
                    handovers += 1;
                }
            }
        }
        prev = Some(pts);
    }
    assert!(seen.iter().all(|&c| c > n / 10), "every slot carries a flank in action: {seen:?}");
    assert!(handovers >= 10, "flank pairs enter and leave action: {handovers}");
}

#[test]
fn gear_pairs_refuse_points_that_cannot_keep_their_flanks_apart() {
    let mesh = Mesh::new(17, 31);
    assert!(mesh.pair4.is_none());
    let pair = || mesh.pair2.clone();
    let e = pair().with_points(4).unwrap_err().to_string();
    assert!(e.contains("17 and 31") && e.contains("use 6 points"), "{e}");
    let e = pair().with_points(3).unwrap_err().to_string();
    assert!(e.contains("even number of points"), "{e}");
    assert!(pair().with_points(6).is_ok() && pair().with_points(1).is_ok());
    // 4 points colour the second gear's teeth when only the first leaves 1 over
    assert!(Mesh::new(17, 30).pair4.is_some());
}

#[test]
fn sphere_at_an_ellipsoids_centre_or_on_its_minor_plane_gets_the_nearest_wall() {
    use crate::contact::test_util::ellipsoid_sdf;
    let semi = Vec3::new(0.4, 0.3, 0.2);
    let e = Contour::Ellipsoid { center: Vec3::zeros(), rotation: Mat3::identity(), semi_axes: semi };
    let pair = ContactPair::new("core", Contour::Point { p: Vec3::zeros() }, e).unwrap();
    // the centre and points on the smallest axis' plane inside (no root of the foot equation
    // above -c²): the gap against an independent sampled distance, the normal finite and unit
    for y in [Vec3::zeros(), Vec3::new(0.05, -0.03, 0.0), Vec3::new(0.1, 0.0, 0.0)] {
        let c = eval(&pair, &Pose::new(Mat3::identity(), y), &Pose::IDENTITY)[0];
        assert!(c.g_n.is_finite() && (c.n.norm() - 1.0).abs() < 1e-12, "{y}: {c:?}");
        let reference = ellipsoid_sdf(&y, &semi);
        assert!((c.g_n - reference).abs() < 1e-9, "{y}: gap {} vs sampled {reference}", c.g_n);
    }
}
