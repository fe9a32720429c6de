//! The curves against differences of themselves (the Frenet–Serret relations and their
//! generalization for the up-vector frame), against closed forms (helix, clothoid) and across
//! their special places (κ = 0, straight stretches, the ends, the seam of a closed spline).

use std::f64::consts::TAU;
use std::sync::Arc;

use num_dual::{Dual2_64, Dual64, HyperDual64};

use super::*;
use crate::math::tilde;

fn v(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

fn helix_points(per_turn: usize, turns: f64, r: f64, c: f64) -> Vec<Vec3> {
    let n = (per_turn as f64 * turns).round() as usize;
    (0..=n)
        .map(|k| {
            let phi = TAU * k as f64 / per_turn as f64;
            Vec3::new(r * phi.cos(), r * phi.sin(), c * phi)
        })
        .collect()
}

/// The helix r(φ) sampled with its exact derivatives (a function path).
fn helix_samples(per_turn: usize, turns: f64, r: f64, c: f64) -> Spline {
    let n = (per_turn as f64 * turns).round() as usize;
    let p: Vec<f64> = (0..=n).map(|k| TAU * k as f64 / per_turn as f64).collect();
    let pos = p.iter().map(|&f| Vec3::new(r * f.cos(), r * f.sin(), c * f)).collect::<Vec<_>>();
    let d1 = p.iter().map(|&f| Vec3::new(-r * f.sin(), r * f.cos(), c)).collect::<Vec<_>>();
    let d2 = p.iter().map(|&f| Vec3::new(-r * f.cos(), -r * f.sin(), 0.0)).collect::<Vec<_>>();
    Spline::hermite(&p, &pos, &d1, &d2, false, None).unwrap()
}

/// One curve of each kind, with arc lengths to probe (inside segments, away from the knots
/// where r‴ of a cubic jumps and central differences lose their order).
fn curves() -> Vec<(&'static str, PathCurve, Vec<f64>)> {
    let planar = Spline::through_points(
        &[[0.0, 0.0, 0.0], [1.0, 0.6, 0.0], [2.0, 0.0, 0.0], [3.0, -0.8, 0.0], [4.5, 0.2, 0.0]].map(v),
        false,
        None,
    )
    .unwrap();
    let space = Spline::through_points(
        &[[0.0, 0.0, 0.0], [1.0, 0.5, 0.1], [2.0, 0.0, 0.6], [2.5, -1.0, 0.2], [4.0, -0.5, 0.0], [4.4, 0.7, -0.3]]
            .map(v),
        false,
        None,
    )
    .unwrap();
    let closed = Spline::through_points(
        &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.3], [-1.0, 0.0, 0.0], [0.0, -1.0, -0.3]].map(v),
        true,
        None,
    )
    .unwrap();
    let mids = |sp: &Spline| sp.knots().windows(2).map(|w| 0.37 * w[0] + 0.63 * w[1]).collect::<Vec<_>>();
    let hermite = helix_samples(16, 1.2, 0.5, 0.1);
    let (m1, m2, m3, m4) = (mids(&planar), mids(&space), mids(&closed), mids(&hermite));
    vec![
        ("helix", PathCurve::Helix(Helix { radius: 0.3, lead: 0.05 }), vec![-1.0, 0.0, 0.7, 4.0]),
        ("clothoid", PathCurve::Clothoid(Clothoid { a: 1.2, kappa0: -0.5 }), vec![-3.0, 0.0, 0.72, 2.0, 9.0]),
        ("planar spline", PathCurve::Spline(Arc::new(planar)), m1),
        ("space spline", PathCurve::Spline(Arc::new(space)), m2),
        ("closed spline", PathCurve::Spline(Arc::new(closed)), m3),
        ("sampled helix", PathCurve::Spline(Arc::new(hermite)), m4),
    ]
}

#[test]
fn every_curve_obeys_its_frame_equations_by_differences() {
    let e = 1e-5;
    for (name, c, probes) in curves() {
        for &s in &probes {
            let p = c.point(s);
            let (pp, pm) = (c.point(s + e), c.point(s - e));
            let f = p.frame;
            assert!((f.transpose() * f - Mat3::identity()).norm() < 1e-13, "{name} at {s}");
            assert!((f.determinant() - 1.0).abs() < 1e-13, "{name} at {s}");
            let t = f.column(0).into_owned();
            // eq. 2.73: dr/ds = t, unit speed
            assert!(((pp.r - pm.r) / (2.0 * e) - t).norm() < 1e-9, "{name} at {s}: dr/ds");
            // dt/ds as reported
            assert!(
                ((pp.frame.column(0) - pm.frame.column(0)) / (2.0 * e) - p.tangent_rate).norm() < 1e-8,
                "{name} at {s}"
            );
            // d[t n b]/ds = [t n b] Ω̃ (eq. 2.75 for Ω = (τ, 0, κ))
            let d = (pp.frame - pm.frame) / (2.0 * e);
            assert!((d - f * tilde(&p.omega)).norm() < 1e-8, "{name} at {s}: {:?} vs {:?}", d, f * tilde(&p.omega));
            assert!(((pp.omega - pm.omega) / (2.0 * e) - p.omega_rate).norm() < 1e-7, "{name} at {s}: dΩ/ds");
            // the Frenet relations with the reported curvature and torsion: t' = κ n_F, and for
            // a space curve dn_F/ds = −κ t + τ b_F
            let k = p.curvature;
            assert!((p.tangent_rate.norm() - k.abs()).abs() < 1e-12, "{name} at {s}: |t'| = |κ|");
            if let Some(nrm) = c.plane() {
                assert!(p.torsion == 0.0 && (f.column(2) - nrm).norm() < 1e-12, "{name}: b is the plane's normal");
                assert!((p.tangent_rate - f.column(1) * k).norm() < 1e-12, "{name} at {s}: t' = κ n, signed");
            } else if k > 1e-3 {
                let frenet = |q: &PathPoint| {
                    let n = q.tangent_rate / q.tangent_rate.norm();
                    (n, q.frame.column(0).cross(&n))
                };
                let ((n, b), (np, _), (nm, _)) = (frenet(&p), frenet(&pp), frenet(&pm));
                assert!(((np - nm) / (2.0 * e) - (-t * k + b * p.torsion)).norm() < 1e-7, "{name} at {s}: dn/ds");
                let (bp, bm) = (frenet(&pp).1, frenet(&pm).1);
                assert!(((bp - bm) / (2.0 * e) + n * p.torsion).norm() < 1e-7, "{name} at {s}: db/ds");
            }
        }
    }
}

#[test]
fn dual_numbers_get_exact_first_and_second_derivatives() {
    for (name, c, probes) in curves() {
        for &s in &probes {
            let p = c.point(s);
            let w = tilde(&p.omega);
            // first order: d/ds r = t, d/ds F = F Ω̃, d/ds Ω = Ω′
            let l = c.local(Dual64::from(s).derivative());
            assert!((l.r.map(|x| x.re) - p.r).norm() < 1e-14, "{name}");
            assert!((l.r.map(|x| x.eps) - p.frame.column(0)).norm() < 1e-12, "{name} at {s}");
            assert!((l.frame.map(|x| x.eps) - p.frame * w).norm() < 1e-11, "{name} at {s}");
            assert!((l.omega.map(|x| x.eps) - p.omega_rate).norm() < 1e-10, "{name} at {s}");
            assert!((l.omega.map(|x| x.re) - p.omega).norm() < 1e-12, "{name} at {s}");
            // second order: d²r/ds² = t′, d²F/ds² = F (Ω̃² + Ω̃′)
            let l2 = c.local(Dual2_64::from(s).derivative());
            assert!((l2.r.map(|x| x.v2) - p.tangent_rate).norm() < 1e-11, "{name} at {s}");
            let f2 = p.frame * (w * w + tilde(&p.omega_rate));
            assert!((l2.frame.map(|x| x.v2) - f2).norm() < 1e-9, "{name} at {s}");
            // and a hyper-dual's mixed part is the same second derivative
            let h = c.local(HyperDual64::from(s).derivative1().derivative2());
            assert!((h.frame.map(|x| x.eps1eps2) - f2).norm() < 1e-9, "{name} at {s}");
        }
    }
}

#[test]
fn helix_closed_forms() {
    let h = Helix { radius: 0.3, lead: 0.05 };
    let p = PathCurve::Helix(h).point(0.7);
    assert!((p.curvature - 0.3 / (0.09 + 0.0025)).abs() < 1e-15 && (p.torsion - 0.05 / 0.0925).abs() < 1e-15);
    assert!((p.r.x.hypot(p.r.y) - 0.3).abs() < 1e-15);
    assert_eq!(p.omega, Vec3::new(p.torsion, 0.0, p.curvature));
}

#[test]
fn clothoid_curvature_is_linear_and_its_frame_passes_through_zero_curvature() {
    let (a, k0) = (1.2, -0.5);
    let c = PathCurve::Clothoid(Clothoid { a, kappa0: k0 });
    for s in [-2.0, 0.0, 0.3, 1.0, 5.0] {
        let p = c.point(s);
        assert!((p.curvature - (k0 + s / (a * a))).abs() < 1e-14);
        assert!((p.omega - Vec3::new(0.0, 0.0, p.curvature)).norm() < 1e-14);
        assert!((p.omega_rate - Vec3::new(0.0, 0.0, 1.0 / (a * a))).norm() < 1e-13);
    }
    // κ = 0 at s* = −κ₀ A²: n = z × t, continuous; κ changes sign there
    let s0 = -k0 * a * a;
    let (lo, mid, hi) = (c.point(s0 - 1e-7), c.point(s0), c.point(s0 + 1e-7));
    assert!(mid.curvature.abs() < 1e-15 && lo.curvature < 0.0 && hi.curvature > 0.0);
    let n = mid.frame.column(1).into_owned();
    assert!((n - Vec3::z().cross(&mid.frame.column(0))).norm() < 1e-15);
    assert!((lo.frame - hi.frame).norm() < 1e-6 && (lo.frame - mid.frame).norm() < 1e-6);
    // a clothoid starting at κ₀ = 0: the frame at s = 0 is the identity
    let c0 = PathCurve::Clothoid(Clothoid { a: 2.0, kappa0: 0.0 });
    let p = c0.point(0.0);
    assert!((p.frame - Mat3::identity()).norm() < 1e-15 && p.r.norm() == 0.0 && p.curvature == 0.0);
}

/// The largest jump of the frame and of Ω between neighbouring samples `ds` apart over [a, b].
fn largest_jumps(c: &PathCurve, a: f64, b: f64, n: usize) -> (f64, f64) {
    let (mut jf, mut jw) = (0.0f64, 0.0f64);
    let mut prev = c.point(a);
    for k in 1..=n {
        let p = c.point(a + (b - a) * k as f64 / n as f64);
        jf = jf.max((p.frame - prev.frame).norm());
        jw = jw.max((p.omega - prev.omega).norm());
        prev = p;
    }
    (jf, jw)
}

#[test]
fn a_straight_stretch_of_a_spline_keeps_a_continuous_frame() {
    // planar: four collinear points, then a bend; κ passes through 0, n = up × t throughout
    let pts =
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [4.0, 1.0, 0.0], [4.5, 2.5, 0.0]].map(v);
    let sp = Spline::through_points(&pts, false, None).unwrap();
    assert_eq!(sp.plane, Some(Vec3::z()));
    let total = sp.length();
    let c = PathCurve::Spline(Arc::new(sp));
    let n = 4000;
    let (jf, jw) = largest_jumps(&c, -0.5, total + 0.5, n);
    let ds = (total + 1.0) / n as f64;
    // frame steps of order Ω ds, Ω steps of order Ω′ ds: no flips anywhere
    assert!(jf < 5.0 * ds && jw < 50.0 * ds, "{jf} {jw} (ds = {ds})");
    for k in 0..=100 {
        let p = c.point(total * k as f64 / 100.0);
        assert!((p.frame.column(2) - Vec3::z()).norm() < 1e-14);
        assert!((p.tangent_rate - p.frame.column(1) * p.curvature).norm() < 1e-12);
    }
    // the curvature changes sign along the first stretch (the natural spline undulates slightly)
    // and is exactly 0 at the free ends
    assert!(c.point(0.0).curvature.abs() < 1e-12 && c.point(total).curvature.abs() < 1e-12);

    // a space curve with a nearly straight stretch: the up-vector frame stays continuous where
    // the Frenet normal swings around
    let pts =
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [4.0, 1.0, 0.5], [4.5, 2.5, 1.5]].map(v);
    let sp = Spline::through_points(&pts, false, None).unwrap();
    assert!(sp.plane.is_none());
    let total = sp.length();
    let c = PathCurve::Spline(Arc::new(sp));
    let (jf, jw) = largest_jumps(&c, 0.0, total, n);
    let ds = total / n as f64;
    assert!(jf < 5.0 * ds && jw < 50.0 * ds, "{jf} {jw}");
    // all collinear: a straight line, frame constant, κ = 0
    let line =
        Spline::through_points(&[[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [3.0, 3.0, 0.0]].map(v), false, None).unwrap();
    let c = PathCurve::Spline(Arc::new(line));
    let (p0, p1) = (c.point(0.3), c.point(3.0));
    assert!((p0.frame - p1.frame).norm() < 1e-14 && p0.curvature.abs() < 1e-14 && p0.omega.norm() < 1e-14);
    assert!((p1.r - Vec3::new(3.0, 3.0, 0.0) / 2f64.sqrt()).norm() < 1e-14);
}

#[test]
fn beyond_the_ends_an_open_spline_goes_straight_and_a_closed_one_repeats() {
    let pts = [[0.0, 0.0, 0.0], [1.0, 0.6, 0.0], [2.0, 0.0, 0.3], [3.0, -0.8, 0.0]].map(v);
    let sp = Arc::new(Spline::through_points(&pts, false, None).unwrap());
    let total = sp.length();
    let c = PathCurve::Spline(sp);
    let (start, end) = (c.point(0.0), c.point(total));
    for d in [1e-9, 0.5, 1e3] {
        let (p, q) = (c.point(-d), c.point(total + d));
        assert!((p.r - (start.r - start.frame.column(0) * d)).norm() < 1e-12 * (1.0 + d));
        assert!((q.r - (end.r + end.frame.column(0) * d)).norm() < 1e-12 * (1.0 + d));
        assert!((p.frame - start.frame).norm() < 1e-12 && (q.frame - end.frame).norm() < 1e-12);
        assert!(p.omega == Vec3::zeros() && p.curvature == 0.0 && q.omega_rate == Vec3::zeros());
    }
    // natural ends: the straight continuation joins with zero curvature
    assert!(start.curvature.abs() < 1e-12 && end.curvature.abs() < 1e-12);
    let p = c.point(f64::NAN);
    assert!(p.r.iter().all(|x| x.is_finite()));

    let closed = Spline::through_points(
        &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.3], [-1.0, 0.0, 0.0], [0.0, -1.0, -0.3]].map(v),
        true,
        None,
    )
    .unwrap();
    let total = closed.length();
    let c = PathCurve::Spline(Arc::new(closed));
    for s in [0.0, 0.3, 2.0] {
        for k in [-2.0, 1.0, 3.0] {
            let (p, q) = (c.point(s), c.point(s + k * total));
            assert!(
                (p.r - q.r).norm() < 1e-12 && (p.frame - q.frame).norm() < 1e-12 && (p.omega - q.omega).norm() < 1e-10
            );
        }
    }
    // across the seam: continuous frame and Ω
    let (lo, hi) = (c.point(total - 1e-7), c.point(total + 1e-7));
    assert!((lo.frame - hi.frame).norm() < 1e-6 && (lo.omega - hi.omega).norm() < 1e-5);
}

#[test]
fn a_helix_as_a_spline_or_as_samples_has_the_helix_curvature_and_torsion() {
    let (r, c) = (0.5, 0.1);
    let l2 = r * r + c * c;
    let (kappa, tau) = (r / l2, c / l2);
    let helix = PathCurve::Helix(Helix { radius: r, lead: c });
    let lh = TAU * l2.sqrt();
    let errors = |per_turn: usize| {
        let pts = helix_points(per_turn, 3.0, r, c);
        // the default reference direction: the axis, up to the spline's departures from the helix
        let sp = Spline::through_points(&pts, false, None).unwrap();
        assert!((sp.up - Vec3::z()).norm() < 1e-3, "{:?}", sp.up);
        let sp = Spline::through_points(&pts, false, Some(Vec3::z())).unwrap();
        let total = sp.length();
        assert!((total - 3.0 * lh).abs() < 1e-3 * total, "{total} vs {}", 3.0 * lh);
        let spc = PathCurve::Spline(Arc::new(sp));
        let (mut ek, mut et, mut er, mut ef) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for k in 0..=400 {
            let s = lh * (1.0 + k as f64 / 400.0);
            let (p, q) = (spc.point(s), helix.point(s));
            ek = ek.max((p.curvature - kappa).abs() / kappa);
            et = et.max((p.torsion - tau).abs() / tau);
            er = er.max((p.r - q.r).norm());
            ef = ef.max((p.frame - q.frame).norm());
        }
        (ek, et, er, ef)
    };
    // through 32 and 64 points per turn, over three turns; compared in the middle turn (the
    // natural ends bend the spline away from the helix near its ends)
    // (measured: 32 per turn κ 3.2e-3, τ 6.4e-3 relative, r 7.6e-5 m; 64 per turn a quarter of
    // that for κ and τ: second order in the spacing)
    let (e32, e64) = (errors(32), errors(64));
    assert!(e32.0 < 4e-3 && e32.1 < 8e-3 && e32.2 < 1e-4 && e32.3 < 4e-4, "{e32:?}");
    assert!(e32.0 / e64.0 > 3.5 && e32.1 / e64.1 > 3.5 && e32.2 / e64.2 > 7.0, "{e32:?} {e64:?}");
    // sampled with exact derivatives (a function path), 32 samples per turn: the quintic's orders
    // (measured: r 3.5e-9 m, κ 7.7e-7, τ 5.3e-6 relative; 16 per turn: 2.2e-7, 1.2e-5, 8.4e-5,
    // i.e. h⁶ in position and h⁴ in curvature)
    let sp = helix_samples(32, 2.0, r, c);
    let total = sp.length();
    assert!((total - 2.0 * lh).abs() < 1e-8, "{}", total - 2.0 * lh);
    let spc = PathCurve::Spline(Arc::new(sp));
    let (mut ek, mut et, mut er, mut ef) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for k in 0..=400 {
        let s = total * k as f64 / 400.0;
        let (p, q) = (spc.point(s), helix.point(s));
        ek = ek.max((p.curvature - kappa).abs() / kappa);
        et = et.max((p.torsion - tau).abs() / tau);
        er = er.max((p.r - q.r).norm());
        ef = ef.max((p.frame - q.frame).norm());
    }
    assert!(ek < 1e-6 && et < 1e-5 && er < 1e-8 && ef < 1e-7, "κ {ek:.1e}, τ {et:.1e}, r {er:.1e}, frame {ef:.1e}");
}

#[test]
fn bad_curves_are_errors_naming_the_joint_and_the_key() {
    use crate::model::{Model, ModelDescription};
    let build = |joint: &str| {
        let json = format!(
            r#"{{"name": "m", "bodies": [{{"name": "bead", "mass": 1.0, "inertia": [0, 0, 0]}}],
                 "joints": [{{"name": "wire", "type": "path", "parent": "ground", "child": "bead", {joint}}}]}}"#
        );
        Model::from_description(ModelDescription::from_json(&json).unwrap()).map(|_| ()).unwrap_err().to_string()
    };
    for (joint, want) in [
        (
            r#""curve": "spline", "points": [[0, 0, 0]]"#,
            "joints[0] 'wire'.points: an open spline needs at least 2 points, got 1",
        ),
        (
            r#""curve": "spline", "points": [[0, 0, 0], [1, 0, 0]], "closed": true"#,
            "joints[0] 'wire'.points: a closed spline needs at least 3",
        ),
        (
            r#""curve": "spline", "points": [[0, 0, 0], [1, 0, 0], [1, 0, 0]]"#,
            "joints[0] 'wire'.points[2]: repeats points[1]",
        ),
        (
            r#""curve": "spline", "points": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 0]], "closed": true"#,
            "joints[0] 'wire'.points[3]: repeats points[0]",
        ),
        (
            r#""curve": "spline", "points": [[0, 0, 0], [0, 0, 1]], "up": [0, 0, 1]"#,
            "joints[0] 'wire'.up: the path runs within 0.00°",
        ),
        (r#""curve": "clothoid", "A": -1.0"#, "joints[0] 'wire'.A: must be > 0, got -1"),
        (r#""curve": "clothoid""#, "joints[0] 'wire'.A: a clothoid needs its parameter A"),
        (
            r#""curve": "clothoid", "A": 1.0, "radius": 2.0"#,
            "joints[0] 'wire'.radius: a clothoid path has no radius (its keys: A, kappa0)",
        ),
        (r#""curve": "bezier""#, "joints[0] 'wire'.curve: unknown path curve 'bezier'"),
        (
            r#""curve": "hermite", "parameters": [0, 1], "points": [[0, 0, 0], [1, 0, 0]], "tangents": [[1, 0, 0]], "second_derivatives": [[0, 0, 0], [0, 0, 0]]"#,
            "joints[0] 'wire'.tangents: 1 rows for 2 parameter values",
        ),
        (
            r#""curve": "hermite", "parameters": [0, 0], "points": [[0, 0, 0], [1, 0, 0]], "tangents": [[1, 0, 0], [1, 0, 0]], "second_derivatives": [[0, 0, 0], [0, 0, 0]]"#,
            "joints[0] 'wire'.parameters[1]: must increase",
        ),
    ] {
        let e = build(joint);
        assert!(e.contains(want), "{joint}:\n{e}\nwanted: {want}");
    }
    // a straight spline along up is fine for a joint that does not turn with it
    let json = r#"{"name": "m", "bodies": [{"name": "bead", "mass": 1.0, "inertia": [0, 0, 0]}],
        "joints": [{"name": "wire", "type": "path", "parent": "ground", "child": "bead", "oriented": false,
                    "curve": "spline", "points": [[0, 0, 0], [0, 0, 1]], "up": [0, 0, 1]}]}"#;
    assert!(Model::from_description(ModelDescription::from_json(json).unwrap()).is_ok());
}
