//! Warm-started curve searches against the cold search at every step of smooth random relative
//! motions (the reference: the same pair evaluated with an empty hint, i.e. searched from
//! scratch), through cam flank changes and gear tooth handovers; stale hints and jumps.

use super::warm::SearchHint;
use super::*;
use crate::contact::kinematics::{contact_kinematics, contact_kinematics_warm, BodyMotion, ContactKinematics};
use crate::contact::test_util::{rot, Rng};
use crate::geometry::curve::{Curve, Follower, Vec2};
use crate::geometry::gear::GearSpec;
use std::f64::consts::{PI, TAU};

fn planar_pose(angle: f64, x: f64, y: f64) -> Pose {
    Pose::new(rot(&Vec3::z(), angle), Vec3::new(x, y, 0.0))
}

/// A body in plane motion at `pose` with a fixed twist (the rates are compared too).
fn moving(pose: Pose, w: f64, v: (f64, f64)) -> BodyMotion {
    BodyMotion { pose, twist: Motion::new(Vec3::new(0.0, 0.0, w), Vec3::new(v.0, v.1, 0.0)), acc: Motion::ZERO }
}

/// A smooth random signal: three sinusoids of random frequencies (cycles over the run) and
/// phases, amplitude `amp`.
struct Smooth([(f64, f64, f64); 3]);

impl Smooth {
    fn new(rng: &mut Rng, amp: f64, cycles: f64) -> Smooth {
        Smooth(
            [0, 1, 2].map(|k| {
                (amp / (1 + k) as f64, rng.uniform(0.3, 1.0) * cycles * (1 + k) as f64, rng.uniform(0.0, TAU))
            }),
        )
    }
    fn at(&self, t: f64) -> f64 {
        self.0.iter().map(|(a, f, p)| a * (TAU * f * t + p).sin()).sum()
    }
}

/// Parameter difference on a closed contour of period `p`.
fn dparam(a: f64, b: f64, p: f64) -> f64 {
    let d = (a - b).rem_euclid(p);
    d.min(p - d)
}

/// Evaluates `pair` along `path(i)` for `i < n`, warm (one hint array carried through) and cold
/// (an empty hint each time, and no hint at all); asserts the same roots (parameters within
/// `tol_s`), gaps, points, normals and rates at every step; returns the warm evaluations.
fn follow(
    pair: &ContactPair,
    periods: (f64, f64),
    n: usize,
    tol_s: f64,
    path: impl Fn(usize) -> (BodyMotion, BodyMotion),
) -> usize {
    let m = pair.candidates();
    let mut hints = vec![SearchHint::default(); m];
    let (mut kw, mut kc, mut kn) = (
        vec![ContactKinematics::default(); m],
        vec![ContactKinematics::default(); m],
        vec![ContactKinematics::default(); m],
    );
    let mut warm = 0;
    for i in 0..n {
        let (b1, b2) = path(i);
        contact_kinematics_warm(pair, &b1, &b2, &mut kw, Some(&mut hints)).unwrap();
        let mut fresh = vec![SearchHint::default(); m];
        contact_kinematics_warm(pair, &b1, &b2, &mut kc, Some(&mut fresh)).unwrap();
        contact_kinematics(pair, &b1, &b2, &mut kn).unwrap();
        assert!(!fresh[0].was_warm());
        assert_eq!(kc, kn, "step {i}: a cold search with an empty hint is the plain search");
        warm += hints[0].was_warm() as usize;

        for k in 0..m {
            let (w, c) = (&kw[k], &kc[k]);
            let at = format!("step {i} ({}), candidate {k}", if hints[0].was_warm() { "warm" } else { "cold" });
            if std::env::var("WARM_DEBUG").is_ok() && (w.point.g_n - c.point.g_n).abs() > 1e-10 {
                for j in 0..m {
                    eprintln!(
                        "{at}: cand {j} warm g {} s {:?} cold g {} s {:?} margin {:?} cold margin {:?} key {}",
                        kw[j].point.g_n,
                        hints[j].s,
                        kc[j].point.g_n,
                        fresh[j].s,
                        hints[0].margin(),
                        fresh[0].margin(),
                        hints[j].key
                    );
                }
            }
            assert_eq!(hints[k].root, fresh[k].root, "{at}: a root in one, none in the other");
            if fresh[k].root {
                let (d1, d2) =
                    (dparam(hints[k].s[0], fresh[k].s[0], periods.0), dparam(hints[k].s[1], fresh[k].s[1], periods.1));
                assert!(d1 < tol_s && d2 < tol_s, "{at}: parameters {:?} vs cold {:?}", hints[k].s, fresh[k].s);
            }
            assert!((w.point.g_n - c.point.g_n).abs() < 1e-10, "{at}: gap {} vs cold {}", w.point.g_n, c.point.g_n);
            for (a, b) in [(w.point.p1, c.point.p1), (w.point.p2, c.point.p2), (w.point.n, c.point.n)] {
                assert!((a - b).norm() < 1e-9, "{at}: {a:?} vs cold {b:?}");
            }
            assert!((w.gd_n - c.gd_n).abs() < 1e-8 * (1.0 + c.gd_n.abs()), "{at}: ġN {} vs {}", w.gd_n, c.gd_n);
            assert!(
                (w.wbar_n - c.wbar_n).abs() < 1e-6 * (1.0 + c.wbar_n.abs()),
                "{at}: w̄N {} vs {}",
                w.wbar_n,
                c.wbar_n
            );
        }
    }
    warm
}

/// The cam of `curve_tests` with a sharp rise (concave pitch flanks) and its roller.
fn hollow_cam() -> (ContactPair, Curve, impl Fn(f64) -> f64) {
    let n = 180;
    let ang: Vec<f64> = (0..=n).map(|i| TAU * i as f64 / n as f64).collect();
    let lift = |t: f64| 0.012 * (-((t - 2.0) / 0.35).powi(2)).exp() + 0.006 * (1.0 - t.cos());
    let lifts: Vec<f64> = ang.iter().map(|&t| lift(t)).collect();
    let cam =
        Curve::cam(&ang, &lifts, 0.03, Follower::Roller { radius: 0.008, eccentricity: 0.004 }, 1.0, "cam").unwrap();
    assert_eq!(cam.convexity(), crate::geometry::curve::Convexity::Mixed);
    let pair = ContactPair::new(
        "cf",
        Contour::Circle { center: Vec2::zeros(), radius: 0.008 },
        Contour::Curve(Box::new(cam.clone())),
    )
    .unwrap();
    (pair, cam, lift)
}

#[test]
fn roller_on_a_non_convex_cam_warm_equals_cold_over_revolutions() {
    let (pair, cam, lift) = hollow_cam();
    let p = cam.range().1 - cam.range().0;
    let mut rng = Rng::new(14);
    let (wob_x, wob_y) = (Smooth::new(&mut rng, 4e-4, 7.0), Smooth::new(&mut rng, 6e-4, 11.0));
    let n = 3000;
    let base = ((0.03f64 + 0.008).powi(2) - 0.004f64.powi(2)).sqrt();
    // two revolutions of the cam, the roller on its follower axis with a smooth wobble (in and
    // out of contact, over the hollow flank)
    let warm = follow(&pair, (TAU, p), n, 1e-9, |i| {
        let t = i as f64 / n as f64;
        let theta = 2.0 * TAU * t;
        let x1 = planar_pose(0.0, 0.004 + wob_x.at(t), base + lift(theta.rem_euclid(TAU)) + 2e-4 + wob_y.at(t));
        (moving(x1, 0.0, (0.1, -0.2)), moving(planar_pose(theta, 0.0, 0.0), 12.0, (0.0, 0.0)))
    });
    eprintln!("roller–cam: warm starts in {warm} of {n} evaluations");
    assert!(warm > n / 2, "warm starts in {warm} of {n} evaluations");
}

#[test]
fn ellipse_pairs_warm_equal_cold_along_random_motions() {
    let e1 = Curve::ellipse(Vec2::zeros(), 0.3, 0.2, 0.0, "e1").unwrap();
    let e2 = Curve::ellipse(Vec2::zeros(), 0.25, 0.15, 0.0, "e2").unwrap();
    let cases = [
        ContactPair::new("ee", Contour::Curve(Box::new(e1.clone())), Contour::Curve(Box::new(e2.clone()))).unwrap(),
        // circle–ellipse (the point search) and the swapped order
        ContactPair::new(
            "ce",
            Contour::Circle { center: Vec2::new(0.01, 0.0), radius: 0.05 },
            Contour::Curve(Box::new(e2)),
        )
        .unwrap(),
        ContactPair::new("ec", Contour::Curve(Box::new(e1)), Contour::Circle { center: Vec2::zeros(), radius: 0.05 })
            .unwrap(),
    ];
    for (c, pair) in cases.iter().enumerate() {
        let mut rng = Rng::new(100 + c as u64);
        let (dir, spin, gap) =
            (Smooth::new(&mut rng, 1.0, 1.0), Smooth::new(&mut rng, 1.0, 1.0), Smooth::new(&mut rng, 2e-3, 5.0));
        let n = 3000;
        // the bodies near contact: the centre distance along the direction corrected by the
        // (cold) gap to a target between 2 mm of penetration and 2 mm of clearance
        let place = |t: f64| {
            let (psi, theta) = (dir.at(t) + TAU * t, spin.at(t) + PI * t);
            let x1 = |d: f64| planar_pose(theta, d * psi.cos(), d * psi.sin());
            let x2 = planar_pose(0.3, 0.0, 0.0);
            let mut d = 0.6;
            for _ in 0..6 {
                let mut k = vec![ContactKinematics::default(); pair.candidates()];
                contact_kinematics(pair, &moving(x1(d), 0.0, (0.0, 0.0)), &moving(x2, 0.0, (0.0, 0.0)), &mut k)
                    .unwrap();
                d -= k[0].point.g_n - gap.at(t);
            }
            (x1(d), x2)
        };
        let path: Vec<(Pose, Pose)> = (0..n).map(|i| place(i as f64 / n as f64)).collect();
        let warm = follow(pair, (TAU, TAU), n, 1e-9, |i| {
            (moving(path[i].0, 3.0, (0.2, 0.1)), moving(path[i].1, -1.0, (0.0, 0.05)))
        });
        eprintln!("case {c}: warm starts in {warm} of {n} evaluations");
        assert!(warm > n / 4, "case {c}: warm starts in {warm} of {n} evaluations");
    }
}

#[test]
fn gear_pairs_warm_equal_cold_through_tooth_handovers() {
    for (z1, z2) in [(17usize, 31usize), (18, 31)] {
        let m = 0.002;
        let gear = |z| Curve::gear(&GearSpec { backlash: 0.05 * m, ..GearSpec::new(m, z) }, "gear").unwrap();
        let (g1, g2) = (gear(z1), gear(z2));
        let (p1, p2) = (g1.range().1 - g1.range().0, g2.range().1 - g2.range().0);
        let (q1, q2) = (g1.as_gear().unwrap().clone(), g2.as_gear().unwrap().clone());
        let points = if z1 == 18 { 4 } else { 2 };
        let pair = ContactPair::new("mesh", Contour::Curve(Box::new(g1)), Contour::Curve(Box::new(g2)))
            .unwrap()
            .with_points(points)
            .unwrap();
        let alpha = 20f64.to_radians();
        let a = 0.5 * m * (z1 + z2) as f64;
        let phi1 = q1.base_half_angle() + alpha;
        let phi2 = (a * alpha.sin() - 1e-5 - q1.base_radius() * phi1) / q2.base_radius();
        let c0 = PI - alpha + phi2 - q2.base_half_angle();
        let mut rng = Rng::new(z1 as u64);
        // the wheel wobbles within the backlash, the centre distance by a few µm
        let (play, centre) = (Smooth::new(&mut rng, 0.02 / z2 as f64 * 0.05, 9.0), Smooth::new(&mut rng, 3e-6, 4.0));
        let n = 1500;
        // four tooth pitches of the pinion
        let warm = follow(&pair, (p1, p2), n, 1e-9, |i| {
            let t = i as f64 / n as f64;
            let t1 = 4.0 * TAU / z1 as f64 * t + 0.1;
            let t2 = c0 - (z1 as f64 / z2 as f64) * t1 + play.at(t);
            (
                moving(planar_pose(t1, 0.0, 0.0), 30.0, (0.0, 0.0)),
                moving(planar_pose(t2, a + centre.at(t), 0.0), -16.0, (0.0, 0.3)),
            )
        });
        // gear pairs always search cold (see `curve_curve`): this guards that choice
        assert_eq!(warm, 0, "gears {z1}/{z2}: warm starts in {warm} of {n} evaluations");
    }
}

#[test]
fn stale_hints_and_jumps_fall_back_to_the_cold_search() {
    let (pair, _, lift) = hollow_cam();
    let base = ((0.03f64 + 0.008).powi(2) - 0.004f64.powi(2)).sqrt();
    let at = |theta: f64, dy: f64| {
        let x1 = planar_pose(0.0, 0.004, base + lift(theta.rem_euclid(TAU)) + dy);
        (moving(x1, 0.0, (0.0, 0.0)), moving(planar_pose(theta, 0.0, 0.0), 1.0, (0.0, 0.0)))
    };
    let cold = |b: &(BodyMotion, BodyMotion)| {
        let mut k = [ContactKinematics::default(); 1];
        contact_kinematics(&pair, &b.0, &b.1, &mut k).unwrap();
        k[0]
    };
    let mut h = [SearchHint::default(); 1];
    let mut k = [ContactKinematics::default(); 1];
    let b = at(1.0, 1e-4);
    contact_kinematics_warm(&pair, &b.0, &b.1, &mut k, Some(&mut h)).unwrap();
    assert!(h[0].margin().is_some_and(|m| m > 0.0), "the cold search leaves a margin");
    // a small move is warm
    let b = at(1.0 + 1e-4, 1e-4);
    contact_kinematics_warm(&pair, &b.0, &b.1, &mut k, Some(&mut h)).unwrap();
    assert!(h[0].was_warm());
    assert_eq!(k[0], cold(&b));
    // a jump over the hollow flank: cold, and right
    let b = at(2.5, 1e-4);
    contact_kinematics_warm(&pair, &b.0, &b.1, &mut k, Some(&mut h)).unwrap();
    assert!(!h[0].was_warm(), "a jump searches cold");
    assert_eq!(k[0], cold(&b));
    // garbage parameters in a valid hint: Newton from anywhere on the cam either fails, leaves
    // the window or finds a root above the bound, and the search runs cold; a parameter in the
    // window is refined to the same root
    let mut rng = Rng::new(3);
    let mut fell_back = 0;
    for _ in 0..200 {
        let mut g = h;
        g[0].s[1] = rng.uniform(-10.0, 10.0);
        let b = at(2.5 + 1e-5, 1e-4);
        contact_kinematics_warm(&pair, &b.0, &b.1, &mut k, Some(&mut g)).unwrap();
        fell_back += !g[0].was_warm() as usize;
        let c = cold(&b);
        assert!((k[0].point.g_n - c.point.g_n).abs() < 1e-12 && (k[0].point.p2 - c.point.p2).norm() < 1e-12);
    }
    assert!(fell_back > 100, "most random parameters are refused: {fell_back} of 200");
    // the hint of another pair's search (a circle–ellipse) read by this one: cold or right
    let e = Curve::ellipse(Vec2::zeros(), 0.3, 0.2, 0.0, "e").unwrap();
    let other =
        ContactPair::new("ce", Contour::Circle { center: Vec2::zeros(), radius: 0.008 }, Contour::Curve(Box::new(e)))
            .unwrap();
    let mut g = [SearchHint::default(); 1];
    contact_kinematics_warm(&other, &b.0, &b.1, &mut k, Some(&mut g)).unwrap();
    contact_kinematics_warm(&pair, &b.0, &b.1, &mut k, Some(&mut g)).unwrap();
    assert!((k[0].point.g_n - cold(&b).point.g_n).abs() < 1e-12);
}

#[test]
fn ellipse_on_a_line_and_a_disc_rattling_in_an_elliptical_hole_warm_equal_cold() {
    // the support-point search (ellipse on its flat floor, rocking and turning) and a search for
    // two points (a disc wandering in an elliptical hole, both walls near)
    let e = Curve::ellipse(Vec2::zeros(), 0.3, 0.2, 0.0, "e").unwrap();
    let line =
        ContactPair::new("el", Contour::Curve(Box::new(e)), Contour::Line { point: Vec2::zeros(), normal: Vec2::y() })
            .unwrap();
    let mut rng = Rng::new(21);
    let (spin, drift, lift) =
        (Smooth::new(&mut rng, 1.0, 1.0), Smooth::new(&mut rng, 0.1, 2.0), Smooth::new(&mut rng, 1e-3, 6.0));
    let n = 3000;
    let warm = follow(&line, (TAU, TAU), n, 1e-9, |i| {
        let t = i as f64 / n as f64;
        let theta = spin.at(t) + PI * t;
        // the lowest point's height over the floor: the support function along -y
        let h = ((0.3 * theta.sin()).powi(2) + (0.2 * theta.cos()).powi(2)).sqrt();
        (
            moving(planar_pose(theta, drift.at(t), h + lift.at(t)), 2.0, (0.1, 0.0)),
            moving(Pose::IDENTITY, 0.0, (0.0, 0.0)),
        )
    });
    eprintln!("ellipse–line: warm starts in {warm} of {n} evaluations");
    assert!(warm > n / 2, "ellipse–line: warm starts in {warm} of {n} evaluations");

    let (a, b, r) = (0.5, 0.3, 0.28);
    let hole = Contour::Curve(Box::new(Curve::ellipse(Vec2::zeros(), a, b, 0.0, "hole").unwrap().flipped()));
    let pair = ContactPair::new("h", Contour::Circle { center: Vec2::zeros(), radius: r }, hole)
        .unwrap()
        .with_points(2)
        .unwrap();
    let (x, y) = (Smooth::new(&mut rng, 0.1, 2.0), Smooth::new(&mut rng, 0.015, 3.0));
    let warm = follow(&pair, (TAU, TAU), n, 1e-9, |i| {
        let t = i as f64 / n as f64;
        (
            moving(planar_pose(0.0, x.at(t), y.at(t)), 0.0, (0.3, 0.1)),
            moving(planar_pose(0.0, 0.0, 0.0), 0.5, (0.0, 0.0)),
        )
    });
    eprintln!("disc in a hole, 2 points: warm starts in {warm} of {n} evaluations");
    assert!(warm > n / 2, "disc in a hole: warm starts in {warm} of {n} evaluations");
}
