//! The gear outline against the geometry of the involute and of the tooth, computed from polar
//! coordinates of the contour's points (not from its pieces' formulas): the string unwound from the
//! base circle, the tooth thickness on the pitch circle, G1 joints, symmetry, and derivatives
//! against finite differences.

use super::*;
use crate::geometry::curve::{cross, Convexity, Curve};
use std::f64::consts::TAU;

/// Gears covering both flank roots (a segment below the involute, or the fillet on it), shifts,
/// backlash and a placement off the origin.
fn gears() -> Vec<GearSpec> {
    let mut out = vec![GearSpec::new(1.0, 17), GearSpec::new(1.0, 100)];
    out.push(GearSpec { shift: 0.4, backlash: 0.05, pressure_angle: 25f64.to_radians(), ..GearSpec::new(1.0, 9) });
    out.push(GearSpec {
        shift: -0.2,
        backlash: 0.02,
        center: Vec2::new(0.3, -0.7),
        phase: 0.4,
        ..GearSpec::new(1.0, 43)
    });
    out.push(GearSpec { tip_radius: Some(0.15), root_radius: Some(0.35), ..GearSpec::new(1.0, 31) });
    out
}

fn build(spec: &GearSpec) -> Curve {
    Curve::gear(spec, "contour 'g'").unwrap()
}

/// Tooth-local parameter ranges of the lower involute and of its mirror image.
fn involute_range(g: &Gear) -> (f64, f64) {
    let j = g.joints();
    let i = j.iter().position(|(_, k)| *k == "involute").unwrap();
    (j[i].0, j[i + 1].0)
}

/// Polar angle of a point about the gear centre.
fn polar(spec: &GearSpec, p: &Vec2) -> f64 {
    let d = p - spec.center;
    d.y.atan2(d.x)
}

fn angle_diff(a: f64, b: f64) -> f64 {
    (a - b + PI).rem_euclid(TAU) - PI
}

#[test]
fn flank_points_lie_on_the_involute_of_the_base_circle() {
    for spec in gears() {
        let c = build(&spec);
        let g = c.as_gear().unwrap();
        let (rb, l, z) = (g.base_radius(), g.tooth_length(), spec.teeth);
        let (a, b) = involute_range(g);
        let mut worst: f64 = 0.0;
        for k in [0, 1, z / 2, z - 1] {
            let centre = spec.phase + TAU * k as f64 / z as f64;
            for i in 0..=40 {
                let u = a + (b - a) * i as f64 / 40.0;
                // lower flank: unwound counter-clockwise from the base circle at centre - ψ_b;
                // upper flank: the mirror image, unwound clockwise from centre + ψ_b
                for (s, sign) in [(k as f64 * l + u, 1.0), (k as f64 * l + l - u, -1.0)] {
                    let p = c.eval(s)[0];
                    let rho = (p - spec.center).norm();
                    let start = centre - sign * g.base_half_angle();
                    // the string leaves the base circle where it is tangent to it: at the polar
                    // angle of p plus (lower) or minus (upper) acos(r_b / ρ)
                    let beta = polar(&spec, &p) + sign * (rb / rho).acos();
                    let t = spec.center + Vec2::new(beta.cos(), beta.sin()) * rb;
                    let rolled = rb * angle_diff(beta, start).abs();
                    assert!(((p - t).dot(&(t - spec.center))).abs() < 1e-12, "string not tangent");
                    worst = worst.max(((p - t).norm() - rolled).abs());
                }
            }
        }
        assert!(worst < 1e-13, "z = {z}: flank off the involute by {worst:e}");
        // the flank's curvature is that of the involute, 1 / (r_b φ), convex
        let u = 0.5 * (a + b);
        let p = c.eval(u)[0] - spec.center;
        let phi = (p.norm_squared() / (rb * rb) - 1.0).sqrt();
        assert!((c.curvature(u) - 1.0 / (rb * phi)).abs() < 1e-12 * c.curvature(u));
        assert_eq!(c.convexity(), Convexity::Mixed);
    }
}

#[test]
fn root_joins_the_involute_by_a_segment_only_when_the_fillet_cannot_reach_it() {
    let g17 = build(&GearSpec::new(1.0, 17));
    let g100 = build(&GearSpec::new(1.0, 100));
    // z = 17: the root circle lies inside the base circle
    let g = g17.as_gear().unwrap();
    assert!(g.root_radius() < g.base_radius() && g.has_segment());
    assert!((g.roll_range().0 - 0.05 / g.base_radius()).abs() < 1e-15);
    let g = g100.as_gear().unwrap();
    assert!(g.root_radius() > g.base_radius() && !g.has_segment());
    // the fillet touches the involute at r_b φ = √((r_f + ρ_f)² − r_b²) − ρ_f
    let (rb, rf) = (g.base_radius(), g.root_radius());
    assert!((g.roll_range().0 * rb - (((rf + 0.2).powi(2) - rb * rb).sqrt() - 0.2)).abs() < 1e-12);
    assert_eq!(g.roundings(), (0.05, 0.2));
}

#[test]
fn derivatives_match_finite_differences_inside_every_piece() {
    for spec in gears() {
        let c = build(&spec);
        let g = c.as_gear().unwrap();
        let l = g.tooth_length();
        let mut bounds: Vec<f64> = g.joints().iter().map(|j| j.0).collect();
        bounds.push(0.5 * l);
        let mut params = Vec::new();
        for w in bounds.windows(2) {
            for f in [0.13, 0.5, 0.87] {
                let u = w[0] + f * (w[1] - w[0]);
                params.push(u);
                params.push(l - u);
            }
        }
        let h = 1e-6;
        for k in [0, spec.teeth - 1] {
            for u in &params {
                let s = k as f64 * l + u;
                let (jm, j0, jp) = (c.eval(s - h), c.eval(s), c.eval(s + h));
                for d in 0..3 {
                    let fd = (jp[d] - jm[d]) / (2.0 * h);
                    let tol = 1e-6 * (1.0 + j0[d + 1].norm() + j0[d].norm() / 0.05);
                    assert!(
                        (fd - j0[d + 1]).norm() < tol,
                        "z = {}: derivative {} at u = {u}: {fd} vs {}",
                        spec.teeth,
                        d + 1,
                        j0[d + 1]
                    );
                }
                // arc-length parameter: unit tangent, normal acceleration
                assert!((j0[1].norm() - 1.0).abs() < 1e-14);
                assert!(j0[1].dot(&j0[2]).abs() < 1e-12 * (1.0 + j0[2].norm()));
            }
        }
    }
}

#[test]
fn the_outline_is_tangent_continuous_at_every_joint() {
    for spec in gears() {
        let c = build(&spec);
        let g = c.as_gear().unwrap();
        let (l, z) = (g.tooth_length(), spec.teeth);
        let joints = g.joints();
        let mut checks: Vec<(Jet2, Jet2, String)> = Vec::new();
        // between the pieces of the lower half (the upper half is their mirror image)
        for i in 1..joints.len() {
            let len = joints[i].0 - joints[i - 1].0;
            checks.push((
                g.piece_eval(i - 1, len),
                g.piece_eval(i, 0.0),
                format!("{} → {}", joints[i - 1].1, joints[i].1),
            ));
        }
        for k in 0..z {
            // tooth centre (tip) and tooth boundary (middle of the gap)
            checks.push((g.tooth_eval(k, 0.5 * l, false), g.tooth_eval(k, 0.5 * l, true), format!("tip of tooth {k}")));
            checks.push((
                g.tooth_eval(k, l, true),
                g.tooth_eval((k + 1) % z, 0.0, false),
                format!("gap after tooth {k}"),
            ));
        }
        for (a, b, what) in checks {
            assert!((a[0] - b[0]).norm() < 1e-12, "z = {z}, {what}: points {} vs {}", a[0], b[0]);
            let (ta, tb) = (a[1].normalize(), b[1].normalize());
            assert!(cross(&ta, &tb).abs() < 1e-12 && ta.dot(&tb) > 0.0, "z = {z}, {what}: tangents {ta} vs {tb}");
        }
        // and the sampled outline closes on itself without a kink (a period)
        let (p0, p1) = (c.eval(0.0), c.eval(g.period()));
        assert!((p0[0] - p1[0]).norm() < 1e-12 && (p0[1] - p1[1]).norm() < 1e-12);
    }
}

#[test]
fn tooth_thickness_on_the_pitch_circle_is_the_nominal_one() {
    for spec in gears() {
        let c = build(&spec);
        let g = c.as_gear().unwrap();
        let (l, r) = (g.tooth_length(), g.pitch_radius());
        let (a, b) = involute_range(g);
        // where the flank crosses the pitch circle (bisection on the contour)
        let cross_at = |mut lo: f64, mut hi: f64| {
            let f = |s: f64| (c.eval(s)[0] - spec.center).norm() - r;
            let flo = f(lo);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if (f(mid) > 0.0) == (flo > 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            polar(&spec, &c.eval(0.5 * (lo + hi))[0])
        };
        let m = spec.module;
        let nominal = m * (0.5 * PI + 2.0 * spec.shift * spec.pressure_angle.tan()) - spec.backlash;
        for k in [0, spec.teeth / 3, spec.teeth - 1] {
            let o = k as f64 * l;
            let (t1, t2) = (cross_at(o + a, o + b), cross_at(o + l - b, o + l - a));
            let thickness = r * angle_diff(t2, t1);
            assert!((thickness - nominal).abs() < 1e-12, "z = {}: thickness {thickness} vs {nominal}", spec.teeth);
            // the tooth is centred on its direction
            let mid = t1 + 0.5 * angle_diff(t2, t1);
            assert!(angle_diff(mid, spec.phase + TAU * k as f64 / spec.teeth as f64).abs() < 1e-13);
        }
    }
}

#[test]
fn teeth_are_symmetric_and_repeat_around_the_gear() {
    for spec in gears() {
        let c = build(&spec);
        let g = c.as_gear().unwrap();
        let (l, z) = (g.tooth_length(), spec.teeth);
        for k in [0, 1, z - 1] {
            let a = spec.phase + TAU * k as f64 / z as f64;
            let (sn, cs) = a.sin_cos();
            // into the frame of tooth k
            let local = |p: Vec2| {
                let d = p - spec.center;
                Vec2::new(cs * d.x + sn * d.y, -sn * d.x + cs * d.y)
            };
            for i in 0..=64 {
                let u = l * i as f64 / 64.0;
                let (p, q) = (local(c.eval(k as f64 * l + u)[0]), local(c.eval(k as f64 * l + l - u)[0]));
                assert!((p - Vec2::new(q.x, -q.y)).norm() < 1e-12, "z = {z}, tooth {k}, u = {u}: {p} vs {q}");
                // the next tooth is this one turned by 2π/z
                let (p2, p1) =
                    (c.eval((k + 1) as f64 * l + u)[0] - spec.center, c.eval(k as f64 * l + u)[0] - spec.center);
                let (s2, c2) = (TAU / z as f64).sin_cos();
                assert!((p2 - Vec2::new(c2 * p1.x - s2 * p1.y, s2 * p1.x + c2 * p1.y)).norm() < 1e-12);
            }
        }
        // tip and root radii are reached on the tooth centre line and in the middle of the gap
        assert!(((c.eval(0.5 * l)[0] - spec.center).norm() - g.tip_radius()).abs() < 1e-12);
        assert!(((c.eval(0.0)[0] - spec.center).norm() - g.root_radius()).abs() < 1e-12);
    }
}

#[test]
fn samples_per_tooth_and_the_largest_gears() {
    let c = build(&GearSpec::new(1.0, 100));
    assert_eq!(c.samples().len(), 4000);
    let c = build(&GearSpec::new(1.0, 17));
    assert_eq!(c.samples().len(), 17 * SAMPLES_PER_TOOTH);
    let c = build(&GearSpec::new(0.5, MAX_TEETH));
    assert!(c.samples().len() <= crate::geometry::curve::MAX_SAMPLES);
    assert!(c.samples().len() >= MAX_TEETH * MIN_SAMPLES_PER_TOOTH);
}

#[test]
fn bad_gears_are_refused_naming_the_contour() {
    let err = |spec: GearSpec| Curve::gear(&spec, "contour 'pinion'").unwrap_err().to_string();
    let e = err(GearSpec::new(1.0, 4));
    assert!(e.contains("contour 'pinion'") && e.contains("5 to"), "{e}");
    assert!(err(GearSpec::new(1.0, MAX_TEETH + 1)).contains("teeth"));
    assert!(err(GearSpec::new(0.0, 20)).contains("module must be > 0"));
    assert!(err(GearSpec::new(-1.0, 20)).contains("module must be > 0"));
    assert!(err(GearSpec::new(f64::NAN, 20)).contains("module must be > 0"));
    assert!(err(GearSpec { pressure_angle: 0.0, ..GearSpec::new(1.0, 20) }).contains("pressure angle"));
    assert!(err(GearSpec { backlash: 1.6, ..GearSpec::new(1.0, 20) }).contains("backlash"));
    assert!(err(GearSpec { backlash: -0.1, ..GearSpec::new(1.0, 20) }).contains("backlash must be ≥ 0"));
    let e = err(GearSpec { shift: 1.0, ..GearSpec::new(1.0, 8) });
    assert!(e.contains("pointed teeth"), "{e}");
    let e = err(GearSpec { tip_radius: Some(0.6), ..GearSpec::new(1.0, 20) });
    assert!(e.contains("tip rounding radius 0.6 does not fit") && e.contains("at most"), "{e}");
    let e = err(GearSpec { root_radius: Some(0.9), ..GearSpec::new(1.0, 20) });
    assert!(e.contains("root fillet radius 0.9 does not fit"), "{e}");
    assert!(err(GearSpec { tip_radius: Some(0.0), ..GearSpec::new(1.0, 20) }).contains("tip_radius must be > 0"));
    assert!(err(GearSpec { root_radius: Some(-1.0), ..GearSpec::new(1.0, 20) }).contains("root_radius must be > 0"));
    let e = err(GearSpec { dedendum: 11.0, ..GearSpec::new(1.0, 20) });
    assert!(e.contains("root circle"), "{e}");
    let e = err(GearSpec { addendum: 0.01, shift: -1.0, ..GearSpec::new(1.0, 20) });
    assert!(e.contains("inside its base circle"), "{e}");
    // the largest fitting radii are accepted
    let g = GearSpec::new(1.0, 20);
    let msg = err(GearSpec { tip_radius: Some(0.6), ..g });
    let max: f64 = msg.rsplit("at most ").next().unwrap().trim_end_matches(')').parse().unwrap();
    assert!(Curve::gear(&GearSpec { tip_radius: Some(0.999 * max), ..g }, "g").is_ok());
}

#[test]
fn curvature_range_is_exact() {
    for spec in gears() {
        let c = build(&spec);
        let g = c.as_gear().unwrap();
        let (lo, hi) = c.curvature_range();
        assert_eq!(lo, -1.0 / g.roundings().1);
        // densely sampled curvature stays within the range and reaches it
        let n = 200_000;
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..n {
            let k = c.curvature(g.tooth_length() * i as f64 / n as f64);
            a = a.min(k);
            b = b.max(k);
        }
        assert!(a >= lo * (1.0 + 1e-12) && b <= hi * (1.0 + 1e-12), "{a} {b} vs {lo} {hi}");
        assert!((a - lo).abs() < 1e-9 * lo.abs() && (b - hi).abs() < 1e-3 * hi, "{a} {b} vs {lo} {hi}");
    }
}
