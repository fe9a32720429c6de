//! Relative contact kinematics against finite differences along prescribed smooth motions of
//! both bodies, and the W-part split against the point Jacobians of a multibody chain.

use nalgebra::{DMatrix, DVector};

use super::*;
use crate::contact::narrow::{evaluate, ContactPair};
use crate::contact::test_util::{close, curve_joints, random_poses, rot, sample, Rng, Trajectory, CURVE_PAIRS, PAIRS};
use crate::contact::{Contour, ContourKind};
use crate::geometry::curve::Vec2;
use crate::math::Mat3;
use crate::spatial::{Motion, Pose};

fn kin(pair: &ContactPair, b1: &BodyMotion, b2: &BodyMotion) -> Vec<ContactKinematics> {
    let mut out = vec![ContactKinematics::default(); pair.candidates()];
    contact_kinematics(pair, b1, b2, &mut out).unwrap();
    out
}

/// For one pair and one pair of trajectories at t = 0, compares with relative tolerance 1e-6:
/// - `ġ_N` with the central difference of `g_N` and with `n·Δv` of the frozen material points;
/// - `g̈_N` (full accelerations) with the second difference of `g_N` and the difference of `ġ_N`;
/// - `ġ_T` with `t·Δv` of the material points at P1, P2 frozen in their bodies, differenced;
/// - `d ġ_T/dt` with the central difference of `ġ_T`.
fn check(pair: &ContactPair, tr1: &Trajectory, tr2: &Trajectory, tag: &str) {
    check_smooth(pair, tr1, tr2, (&[], &[]), tag)
}

/// [`check`], skipping a candidate whose contact point passes a joint of its contour during the
/// differences (`joints`: where the curvature of a G1 contour jumps, body frames; there `g̈_N`
/// jumps too, and the differences straddle it).
fn check_smooth(pair: &ContactPair, tr1: &Trajectory, tr2: &Trajectory, joints: (&[Vec2], &[Vec2]), tag: &str) {
    let (h1, h2) = (1e-5, 1e-4);
    let at = |t: f64| kin(pair, &tr1.at(t), &tr2.at(t));
    let g = |t: f64| {
        let mut out = vec![crate::contact::ContactPoint::default(); pair.candidates()];
        evaluate(pair, &tr1.at(t).pose, &tr2.at(t).pose, &mut out).unwrap();
        out
    };
    let k0 = at(0.0);
    let (kp, km) = (at(h1), at(-h1));
    let (gp, gm, g0) = (g(h2), g(-h2), g(0.0));
    let (gph, gmh) = (g(0.5 * h2), g(-0.5 * h2));
    let mesh = matches!(pair.kinds(), (_, ContourKind::Mesh) | (ContourKind::Mesh, _));
    let (gp1, gm1) = (g(h1), g(-h1));
    let (m1, m2) = (tr1.at(0.0), tr2.at(0.0));
    let body = |tr: &Trajectory, t: f64, p: &Vec3| {
        let l = tr.at(t).pose.inverse().point_to_parent(p);
        Vec2::new(l.x, l.y)
    };
    let passes_joint = |k: usize| {
        let near = |js: &[Vec2], tr: &Trajectory, p: &dyn Fn(&crate::contact::ContactPoint) -> Vec3| {
            let at = body(tr, 0.0, &p(&g0[k]));
            let moved = [&gp[k], &gm[k]].iter().map(|q| (body(tr, 0.0, &p(q)) - at).norm()).fold(0.0, f64::max);
            let moved = moved.max((body(tr, h2, &p(&gp[k])) - at).norm()).max((body(tr, -h2, &p(&gm[k])) - at).norm());
            js.iter().any(|j| (j - at).norm() <= 2.0 * moved + 1e-12)
        };
        near(joints.0, tr1, &|q| q.p1) || near(joints.1, tr2, &|q| q.p2)
    };
    for (k, c) in k0.iter().enumerate() {
        let tag = format!("{tag} candidate {k}");
        assert_eq!(c.point.g_n, g0[k].g_n, "{tag}: evaluate and kinematics agree");
        if passes_joint(k) {
            continue;
        }
        let gd_fd = (gp1[k].g_n - gm1[k].g_n) / (2.0 * h1);
        assert!(close(c.gd_n, gd_fd, 1e-6), "{tag}: ġ_N {} vs difference {gd_fd}", c.gd_n);
        let d2 = |p: f64, m: f64, h: f64| (p - 2.0 * g0[k].g_n + m) / (h * h);
        let gdd_fd2 = if mesh {
            // Richardson-extrapolated (error O(h⁴)): a centre near a mesh edge or vertex has a
            // contact curvature of 1/distance, large enough for the plain difference's O(h²)
            // error to show; the mesh's closed forms have no solver noise for it to amplify
            (4.0 * d2(gph[k].g_n, gmh[k].g_n, 0.5 * h2) - d2(gp[k].g_n, gm[k].g_n, h2)) / 3.0
        } else {
            d2(gp[k].g_n, gm[k].g_n, h2)
        };
        assert!(
            close(c.wbar_n, gdd_fd2, 1e-6),
            "{tag}: g̈_N {} vs second difference {gdd_fd2} (g_N {})",
            c.wbar_n,
            c.point.g_n
        );
        let gdd_fd = (kp[k].gd_n - km[k].gd_n) / (2.0 * h1);
        assert!(close(c.wbar_n, gdd_fd, 1e-6), "{tag}: g̈_N {} vs difference of ġ_N {gdd_fd}", c.wbar_n);
        // material points at P1 and P2 frozen in their bodies
        let (p1b, p2b) =
            (m1.pose.inverse().point_to_parent(&c.point.p1), m2.pose.inverse().point_to_parent(&c.point.p2));
        let pos = |tr: &Trajectory, pb: &Vec3, t: f64| tr.at(t).pose.point_to_parent(pb);
        let dv = (pos(tr1, &p1b, h1) - pos(tr1, &p1b, -h1) - pos(tr2, &p2b, h1) + pos(tr2, &p2b, -h1)) / (2.0 * h1);
        assert!(close(c.gd_n, c.point.n.dot(&dv), 1e-6), "{tag}: ġ_N vs material points");
        for (j, t) in [c.point.t1, c.point.t2].iter().enumerate() {
            assert!(close(c.gd_t[j], t.dot(&dv), 1e-6), "{tag}: ġ_T[{j}] {} vs {}", c.gd_t[j], t.dot(&dv));
            let fd = (kp[k].gd_t[j] - km[k].gd_t[j]) / (2.0 * h1);
            assert!(close(c.wbar_t[j], fd, 1e-6), "{tag}: d ġ_T[{j}]/dt {} vs difference {fd}", c.wbar_t[j]);
        }
    }
}

/// Every pair, both orders, at random configurations and motions (plane pairs also along
/// general 3-D motions, for which their closed forms are equally defined).
#[test]
fn rates_match_finite_differences_for_every_pair() {
    let mut rng = Rng::new(2024);
    for (a, b) in PAIRS {
        let (c1, c2) = (sample(a), sample(b));
        for (order, (ca, cb)) in [(c1.clone(), c2.clone()), (c2, c1)].into_iter().enumerate() {
            let pair = ContactPair::new("p", ca, cb).unwrap();
            for it in 0..8 {
                let planar = pair.is_planar() && it % 2 == 0;
                let (x1, x2) = random_poses(&mut rng, planar);
                let (tr1, tr2) = if planar {
                    (
                        Trajectory::random_planar(&mut rng, &x1, 1.0, 0.5),
                        Trajectory::random_planar(&mut rng, &x2, 1.0, 0.5),
                    )
                } else if it == 7 {
                    // body 2 is the ground
                    (Trajectory::random(&mut rng, &x1, 1.0, 0.5), Trajectory::fixed(&x2))
                } else {
                    (Trajectory::random(&mut rng, &x1, 1.0, 0.5), Trajectory::random(&mut rng, &x2, 1.0, 0.5))
                };
                check(&pair, &tr1, &tr2, &format!("{a}–{b} order {order} #{it}"));
            }
        }
    }
}

/// Parametric contours (section 2.2.7.1): the rates from the differentiated contact conditions
/// (ṡ of eq. 2.109, ṅ of eq. 2.92) against differences of the searched contact, in plane motion
/// and in general 3-D motion (where the curves are compared in body 2's plane), both orders.
/// (With several points per pair a candidate may switch roots between the differenced states;
/// those pairs are checked in `narrow::curve_tests`.)
#[test]
fn curve_pair_rates_match_finite_differences() {
    let mut rng = Rng::new(77);
    for (a, b) in CURVE_PAIRS {
        let (c1, c2) = (sample(a), sample(b));
        for (order, (ca, cb)) in [(c1.clone(), c2.clone()), (c2, c1)].into_iter().enumerate() {
            {
                let pair = ContactPair::new("p", ca.clone(), cb.clone()).unwrap();
                for it in 0..8 {
                    let planar = it % 3 != 2;
                    let (mut x1, x2) = random_poses(&mut rng, true);
                    // near touching rather than deeply overlapping (the samples are ~0.3 in size)
                    let sep = x1.r - x2.r;
                    x1.r = x2.r + sep * (rng.uniform(0.6, 0.95) / sep.norm());
                    // slower motions than for the primitives: deep penetrations of curved
                    // contours have large higher derivatives, which the differences truncate
                    let (tr1, tr2) = if planar {
                        (
                            Trajectory::random_planar(&mut rng, &x1, 0.5, 0.25),
                            Trajectory::random_planar(&mut rng, &x2, 0.5, 0.25),
                        )
                    } else {
                        // a small tilt: the curves are compared in body 2's plane
                        let tilt = |x: &Pose, rng: &mut Rng| Pose::new(rot(&rng.unit(), 0.2) * x.a, x.r);
                        let (y1, y2) = (tilt(&x1, &mut rng), tilt(&x2, &mut rng));
                        (Trajectory::random(&mut rng, &y1, 0.5, 0.25), Trajectory::random(&mut rng, &y2, 0.5, 0.25))
                    };
                    let joints = (curve_joints(&ca), curve_joints(&cb));
                    check_smooth(&pair, &tr1, &tr2, (&joints.0, &joints.1), &format!("{a}–{b} order {order} #{it}"));
                }
            }
        }
    }
}

/// Box–box candidates (the clipped face manifold and the edge–edge point) along prescribed motions
/// of both boxes: `ṅ`, `Ṗ1`, `Ṗ2` against central differences of the candidate's `n`, `P1`, `P2`;
/// `ġ_N`, `ġ_T` against the frozen material points; `g̈_N` and `d ġ_T/dt` against differences of
/// `ġ_N`, `ġ_T`; and the rate of the gap `d g_N/dt = ġ_N + n·(σ1 - σ2)` with `σ_i = Ṗ_i - v_i(P_i)`
/// the motion of the point over its box. Returns how many used candidates have `n·(σ1 - σ2) = 0`
/// identically (corners of either face, edge–edge points: there also `g̈_N` against the second
/// difference of `g_N`) and how many are crossings, which slide along an edge of the incident face.
fn check_box(pair: &ContactPair, tr1: &Trajectory, tr2: &Trajectory, edge: bool, tag: &str) -> (usize, usize) {
    use crate::contact::narrow::box_box::{Feature, Kind};
    let (h1, h2) = (1e-5, 1e-4);
    let at = |t: f64| kin(pair, &tr1.at(t), &tr2.at(t));
    let raw = |t: f64, k: usize| {
        let (m1, m2) = (tr1.at(t), tr2.at(t));
        pair.candidate(k, &m1.pose, &m2.pose, Some((&m1.twist, &m2.twist)))
    };
    let (k0, kp, km) = (at(0.0), at(h1), at(-h1));
    let (k2p, k2m) = (at(h2), at(-h2));
    let (m1, m2) = (tr1.at(0.0), tr2.at(0.0));
    let far = 0.5 * ((m1.pose.r - m2.pose.r).norm() + 0.3);
    let (mut exact, mut sliding) = (0, 0);
    for (k, c) in k0.iter().enumerate() {
        if c.point.g_n > far {
            continue; // unused
        }
        let tag = format!("{tag} candidate {k}");
        let r = raw(0.0, k);
        let (rp, rm) = (raw(h1, k), raw(-h1, k));
        let fd = |a: Vec3, b: Vec3| (a - b) / (2.0 * h1);
        let tol = |v: &Vec3| 1e-6 * v.norm().max(1.0);
        for (name, rate, d) in
            [("n", r.nd, fd(rp.n, rm.n)), ("P1", r.p1d, fd(rp.p1, rm.p1)), ("P2", r.p2d, fd(rp.p2, rm.p2))]
        {
            assert!((rate - d).norm() < tol(&d), "{tag}: rate of {name} {rate:?} vs difference {d:?}");
        }
        // ġ_N and ġ_T from the material points at P1, P2, frozen in their bodies
        let (p1b, p2b) =
            (m1.pose.inverse().point_to_parent(&c.point.p1), m2.pose.inverse().point_to_parent(&c.point.p2));
        let pos = |tr: &Trajectory, pb: &Vec3, t: f64| tr.at(t).pose.point_to_parent(pb);
        let dv = (pos(tr1, &p1b, h1) - pos(tr1, &p1b, -h1) - pos(tr2, &p2b, h1) + pos(tr2, &p2b, -h1)) / (2.0 * h1);
        assert!(close(c.gd_n, c.point.n.dot(&dv), 1e-6), "{tag}: ġ_N vs material points");
        for (j, t) in [c.point.t1, c.point.t2].iter().enumerate() {
            assert!(close(c.gd_t[j], t.dot(&dv), 1e-6), "{tag}: ġ_T[{j}]");
            let d = (kp[k].gd_t[j] - km[k].gd_t[j]) / (2.0 * h1);
            assert!(close(c.wbar_t[j], d, 1e-6), "{tag}: d ġ_T[{j}]/dt {} vs difference {d}", c.wbar_t[j]);
        }
        let d = (kp[k].gd_n - km[k].gd_n) / (2.0 * h1);
        assert!(close(c.wbar_n, d, 1e-6), "{tag}: g̈_N {} vs difference of ġ_N {d}", c.wbar_n);
        // the rate of the gap
        let (s1, s2) = (r.p1d - m1.point_velocity(&r.p1), r.p2d - m2.point_velocity(&r.p2));
        let defect = r.n.dot(&(s1 - s2));
        let gd_fd = (kp[k].point.g_n - km[k].point.g_n) / (2.0 * h1);
        assert!(close(c.gd_n + defect, gd_fd, 1e-6), "{tag}: d g/dt {gd_fd} vs ġ_N {} + n·σ {defect}", c.gd_n);
        // identically ⟂ n: an edge–edge point, or a corner of either face (one point is a material
        // point, the other moves in the face it lies on, ⟂ n)
        let (feature, kinds) = pair.box_kinds(&m1.pose, &m2.pose).unwrap();
        let corner = matches!(kinds[k], Kind::IncidentCorner | Kind::ReferenceCorner);
        if corner {
            assert!(s1.norm() < 1e-12 || s2.norm() < 1e-12, "{tag}: a corner is a material point");
        }
        assert_eq!(edge, matches!(feature, Feature::Edge { .. }), "{tag}");
        if corner || edge {
            assert!(defect.abs() < 1e-12, "{tag}: n·σ = {defect}, σ1 {s1:?} σ2 {s2:?} {r:?}");
            exact += 1;
            let gdd = (k2p[k].point.g_n - 2.0 * c.point.g_n + k2m[k].point.g_n) / (h2 * h2);
            assert!(close(c.wbar_n, gdd, 1e-6), "{tag}: g̈_N {} vs second difference {gdd}", c.wbar_n);
        } else {
            sliding += 1;
        }
    }
    (exact, sliding)
}

/// Box on box, both moving: a tilted box over another's top face, turned so that its bottom face
/// crosses the other's edges (corners, clipped edge points and reference corners in one
/// manifold), the upper face as the reference when the upper box tips over the lower one's edge,
/// and crossing edges; the reversed pair gives the same contacts with the normal reversed.
#[test]
fn box_on_box_rates_and_reversal() {
    let mut rng = Rng::new(31);
    let cuboid = |h: Vec3, r: Mat3| Contour::Box { center: Vec3::new(0.01, -0.02, 0.0), rotation: r, half_extents: h };
    let (wide, square) = (Vec3::new(0.3, 0.1, 0.1), Vec3::new(0.2, 0.2, 0.1));
    let q = std::f64::consts::FRAC_PI_4;
    let cases = [
        // (upper, lower, upper pose, lower pose, used candidates at least, corners expected)
        (
            cuboid(wide, Mat3::identity()),
            cuboid(square, Mat3::identity()),
            Pose::new(rot(&Vec3::z(), 0.5) * rot(&Vec3::new(1.0, 0.3, 0.0), 0.006), Vec3::new(0.02, -0.01, 0.2012)),
            Pose::new(rot(&Vec3::z(), 0.1) * rot(&Vec3::new(1.0, -1.0, 0.0), 0.003), Vec3::zeros()),
            5,
            true,
        ),
        // tipped over the lower box's edge x = 0.2 (the upper face is the reference; its two
        // corners over the lower box's top face are reference corners)
        (
            cuboid(Vec3::new(0.2, 0.15, 0.1), Mat3::identity()),
            cuboid(square, Mat3::identity()),
            Pose::new(rot(&Vec3::y(), 0.2), Vec3::new(0.35, 0.0, 0.24)),
            Pose::IDENTITY,
            3,
            true,
        ),
        // crossing edges
        (
            cuboid(Vec3::repeat(0.1), rot(&Vec3::x(), q)),
            cuboid(Vec3::repeat(0.15), rot(&Vec3::y(), q)),
            Pose::new(rot(&Vec3::z(), 0.2), Vec3::new(0.0, 0.0, 0.35)),
            Pose::IDENTITY,
            1,
            true,
        ),
    ];
    for (ci, (upper, lower, x1, x2, n_used, corners)) in cases.into_iter().enumerate() {
        let pair = ContactPair::new("bb", upper.clone(), lower.clone()).unwrap();
        let rev = ContactPair::new("bb", lower, upper).unwrap();
        assert_eq!(pair.candidates(), 8);
        let (mut ex, mut sl) = (0, 0);
        for it in 0..4 {
            let tr1 = Trajectory::random(&mut rng, &x1, 0.3, 0.2);
            let tr2 = if it == 3 { Trajectory::fixed(&x2) } else { Trajectory::random(&mut rng, &x2, 0.3, 0.2) };
            let (e, s) = check_box(&pair, &tr1, &tr2, ci == 2, &format!("case {ci} #{it}"));
            assert!(e + s >= n_used, "case {ci}: {e} + {s} candidates in use");
            ex += e;
            sl += s;
            // reversed: the same candidates, normal reversed, points exchanged, same rates
            let (a, b) = (kin(&pair, &tr1.at(0.0), &tr2.at(0.0)), kin(&rev, &tr2.at(0.0), &tr1.at(0.0)));
            let far = 0.5 * ((x1.r - x2.r).norm() + 0.3);
            for (k, (f, r)) in a.iter().zip(&b).enumerate().filter(|(_, (f, _))| f.point.g_n < far) {
                assert!(
                    (f.point.g_n - r.point.g_n).abs() < 1e-13 && (f.point.n + r.point.n).norm() < 1e-13,
                    "case {ci} candidate {k}"
                );
                assert!(
                    (f.point.p1 - r.point.p2).norm() < 1e-13 && (f.point.p2 - r.point.p1).norm() < 1e-13,
                    "case {ci} candidate {k}"
                );
                assert!(
                    (f.gd_n - r.gd_n).abs() < 1e-12 && (f.wbar_n - r.wbar_n).abs() < 1e-10,
                    "case {ci} candidate {k}: rates"
                );
            }
        }
        assert_eq!(ex > 0, corners, "case {ci}: corner or edge–edge candidates {ex}");
        // every face manifold here has crossings; the edge–edge point does not slide off n
        assert_eq!(sl > 0, ci != 2, "case {ci}: crossings {sl}");
    }
}

/// Sphere–box in each region and capsule–capsule with each clamping pattern, explicitly.
#[test]
fn rates_in_every_region() {
    let mut rng = Rng::new(77);
    let cube =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(0.5, 0.4, 0.3) };
    let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.2 };
    let pair = ContactPair::new("sb", ball, cube).unwrap();
    // inside, face, edge, corner
    for r in
        [Vec3::new(0.1, 0.05, -0.1), Vec3::new(0.9, 0.1, -0.1), Vec3::new(0.9, 0.7, 0.1), Vec3::new(0.8, -0.7, 0.6)]
    {
        let x1 = Pose::new(rng.rotation(), r);
        let tr1 = Trajectory::random(&mut rng, &x1, 1.0, 0.5);
        let tr2 = Trajectory::random(&mut rng, &Pose::IDENTITY, 1.0, 0.5);
        check(&pair, &tr1, &tr2, &format!("sphere–box at {r:?}"));
    }
    let cap = |a: Vec3, b: Vec3| Contour::Capsule { a, b, radius: 0.1 };
    let seg2 = cap(Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0));
    for (a, b) in [
        (Vec3::new(0.0, -1.0, 0.5), Vec3::new(0.2, 1.0, 0.6)), // both interior
        (Vec3::new(0.3, 0.2, 0.5), Vec3::new(0.4, 1.0, 0.9)),  // s clamped at a
        (Vec3::new(1.5, -1.0, 0.5), Vec3::new(1.6, 1.0, 0.4)), // u clamped at the end
        (Vec3::new(1.5, 0.2, 0.5), Vec3::new(2.0, 1.0, 0.4)),  // both clamped
    ] {
        let pair = ContactPair::new("cc", cap(a, b), seg2.clone()).unwrap();
        let tr1 = Trajectory::random(&mut rng, &Pose::IDENTITY, 0.3, 0.1);
        let tr2 = Trajectory::random(&mut rng, &Pose::IDENTITY, 0.3, 0.1);
        check(&pair, &tr1, &tr2, &format!("capsule–capsule {a:?}"));
    }
}

/// On a multibody chain: `g̈ = wᵀ u̇ + w̄` with `w_N = J_P1ᵀ n - J_P2ᵀ n` from the point
/// Jacobians and `w̄` from the velocity-product accelerations; also `ġ = wᵀ u`.
#[test]
fn w_part_is_the_point_jacobian_projection() {
    use crate::data::Data;
    use crate::kinematics::{accelerations, forward_kinematics, point_jacobian};
    let model = crate::fixtures::chain(3, "revolute");
    let mut data = Data::new(&model);
    let q = model.q0();
    let u: Vec<f64> = (0..model.nu).map(|i| 0.7 - 0.4 * i as f64).collect();
    let udot: Vec<f64> = (0..model.nu).map(|i| -0.5 + 0.9 * i as f64).collect();
    let cases = [
        (3, sample("sphere"), 1, sample("capsule")),
        (2, sample("box"), 0, Contour::Plane { point: Vec3::new(0.0, 0.0, -0.3), normal: Vec3::z() }),
        (1, sample("capsule_b"), 3, sample("capsule")),
    ];
    for (b1, c1, b2, c2) in cases {
        let pair = ContactPair::new("w", c1, c2).unwrap();
        forward_kinematics(&model, &mut data, &q, &u);
        data.a[0] = Motion::ZERO;
        accelerations(&model, &mut data, &vec![0.0; model.nu]);
        let vp = kin(&pair, &BodyMotion::from_data(&data, b1), &BodyMotion::from_data(&data, b2));
        accelerations(&model, &mut data, &udot);
        let full = kin(&pair, &BodyMotion::from_data(&data, b1), &BodyMotion::from_data(&data, b2));
        let (ud, uv) = (DVector::from_column_slice(&udot), DVector::from_column_slice(&u));
        for (k, (c, f)) in vp.iter().zip(&full).enumerate() {
            let jac = |body: usize, p: &Vec3| {
                let (mut jt, mut jr) = (DMatrix::zeros(3, model.nu), DMatrix::zeros(3, model.nu));
                let pb = data.x_abs[body].inverse().point_to_parent(p);
                point_jacobian(&model, &data, body, &pb, &mut jt, &mut jr);
                jt
            };
            let dj = jac(b1, &c.point.p1) - jac(b2, &c.point.p2);
            for (dir, gd, wbar, gdd) in [
                (c.point.n, c.gd_n, c.wbar_n, f.wbar_n),
                (c.point.t1, c.gd_t[0], c.wbar_t[0], f.wbar_t[0]),
                (c.point.t2, c.gd_t[1], c.wbar_t[1], f.wbar_t[1]),
            ] {
                let w = dj.transpose() * dir;
                assert!((w.dot(&uv) - gd).abs() < 1e-12, "candidate {k}: ġ = wᵀu");
                assert!((w.dot(&ud) + wbar - gdd).abs() < 1e-12, "candidate {k}: g̈ = wᵀu̇ + w̄");
            }
        }
    }
}

/// At the degenerate configurations of the narrow phase, moving bodies give finite rates.
#[test]
fn degenerate_configurations_give_finite_rates() {
    use crate::contact::contour::Vec2;
    let mut rng = Rng::new(9);
    let s = |r| Contour::Sphere { center: Vec3::zeros(), radius: r };
    let cx = Contour::Capsule { a: Vec3::new(-1.0, 0.0, 0.0), b: Vec3::new(1.0, 0.0, 0.0), radius: 0.2 };
    let cy = Contour::Capsule { a: Vec3::new(0.0, -1.0, 0.0), b: Vec3::new(0.0, 1.0, 0.0), radius: 0.3 };
    let cube =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(1.0, 0.5, 2.0) };
    let cyl = Contour::Cylinder { center: Vec3::zeros(), axis: Vec3::z(), radius: 0.3, half_length: 0.5 };
    let ground = Contour::Plane { point: Vec3::new(0.0, 0.0, -0.5), normal: Vec3::z() };
    let ci = Contour::Circle { center: Vec2::zeros(), radius: 0.5 };
    let cases =
        [(s(0.5), s(0.25)), (cx.clone(), cy), (cx.clone(), cx), (s(0.1), cube), (cyl, ground), (ci.clone(), ci)];
    for (c1, c2) in cases {
        let tag = format!("{}–{}", c1.kind(), c2.kind());
        let pair = ContactPair::new("d", c1, c2).unwrap();
        let body = |rng: &mut Rng| BodyMotion {
            pose: Pose::IDENTITY,
            twist: Motion::new(rng.vec3(1.0), rng.vec3(1.0)),
            acc: Motion::new(rng.vec3(1.0), rng.vec3(1.0)),
        };
        let (b1, b2) = (body(&mut rng), body(&mut rng));
        for c in kin(&pair, &b1, &b2) {
            let all = [c.gd_n, c.gd_t[0], c.gd_t[1], c.wbar_n, c.wbar_t[0], c.wbar_t[1], c.point.g_n];
            assert!(all.iter().all(|v| v.is_finite()), "{tag}: {c:?}");
        }
    }
}

/// A moving surface (conveyor belt) on a turning, moving body 2: `ġ_T` is the sliding velocity
/// against the belt's material (the material points' relative velocity plus the belt's speed
/// `w̃_T`), `ġ_N` is unchanged, and `d ġ_T/dt` matches differences of `ġ_T`.
#[test]
fn moving_surface_adds_its_speed_to_the_tangential_velocity() {
    let mut rng = Rng::new(99);
    for (c1, c2, belt) in [
        (sample("sphere"), sample("plane"), Vec3::new(0.0, 0.0, 0.0)),
        (sample("circle"), sample("line"), Vec3::new(0.0, 0.0, 0.0)),
        (crate::contact::test_util::curve_sample("ellipse"), sample("line"), Vec3::new(0.0, 0.0, 0.0)),
    ] {
        // a belt speed along the surface: the plane's or line's own tangent, 0.7 m/s
        let normal = match &c2 {
            Contour::Plane { normal, .. } => normal.normalize(),
            Contour::Line { normal, .. } => Vec3::new(normal.x, normal.y, 0.0).normalize(),
            _ => unreachable!(),
        };
        let along = (Vec3::z().cross(&normal) + belt).normalize() * 0.7;
        let plain = ContactPair::new("b", c1.clone(), c2.clone()).unwrap();
        let moving = ContactPair::new("b", c1, c2).unwrap().with_surface_velocity(2, along).unwrap();
        let planar = plain.is_planar();
        let (x1, x2) = random_poses(&mut rng, planar);
        let (tr1, tr2) = if planar {
            (Trajectory::random_planar(&mut rng, &x1, 0.5, 0.25), Trajectory::random_planar(&mut rng, &x2, 0.5, 0.25))
        } else {
            (Trajectory::random(&mut rng, &x1, 0.5, 0.25), Trajectory::random(&mut rng, &x2, 0.5, 0.25))
        };
        let (a, b) = (kin(&plain, &tr1.at(0.0), &tr2.at(0.0)), kin(&moving, &tr1.at(0.0), &tr2.at(0.0)));
        let w = tr2.at(0.0).pose.a * along;
        for (p, m) in a.iter().zip(&b) {
            assert_eq!(p.gd_n, m.gd_n);
            assert_eq!(p.wbar_n, m.wbar_n);
            // the belt material moves at v2(P2) + A2 u: sliding against it is the difference
            for k in 0..2 {
                let t = [m.point.t1, m.point.t2][k];
                assert!((m.gd_t[k] - (p.gd_t[k] - t.dot(&w))).abs() < 1e-14, "ġ_T[{k}]");
                assert!((m.w_tilde[k + 1] + t.dot(&w)).abs() < 1e-14);
                let h = 1e-5;
                let fd = (kin(&moving, &tr1.at(h), &tr2.at(h))[0].gd_t[k]
                    - kin(&moving, &tr1.at(-h), &tr2.at(-h))[0].gd_t[k])
                    / (2.0 * h);
                assert!(close(m.wbar_t[k], fd, 1e-6), "d ġ_T[{k}]/dt {} vs difference {fd}", m.wbar_t[k]);
            }
        }
    }
}

#[test]
fn moving_surface_is_refused_off_planes_and_lines_and_out_of_the_surface() {
    let pair = ContactPair::new("b", sample("sphere"), sample("plane")).unwrap();
    let e = pair.clone().with_surface_velocity(1, Vec3::x()).unwrap_err().to_string();
    assert!(e.contains("only a plane or a line can be a moving surface") && e.contains("sphere"), "{e}");
    let e = pair.clone().with_surface_velocity(2, Vec3::new(0.1, 0.2, 1.0)).unwrap_err().to_string();
    assert!(e.contains("must lie in the surface"), "{e}");
    let e = pair.with_surface_velocity(2, Vec3::new(f64::NAN, 0.0, 0.0)).unwrap_err().to_string();
    assert!(e.contains("must be finite"), "{e}");
}

/// The velocity level equals the full kinematics' shared fields bit for bit, for every pair in
/// both orders at random placements and motions, the planar searches warm-started along a short
/// motion (each level with its own hints, which must stay equal too); its `w̄` are zero.
#[test]
fn velocity_level_equals_the_full_kinematics_bit_for_bit() {
    let mut rng = Rng::new(4711);
    let boxes = [("box", "box_b"), ("box_b", "box")];
    for (a, b) in PAIRS.iter().chain(CURVE_PAIRS.iter()).chain(boxes.iter()) {
        let (c1, c2) = (sample(a), sample(b));
        for (order, (ca, cb)) in [(c1.clone(), c2.clone()), (c2, c1)].into_iter().enumerate() {
            let pair = ContactPair::new("p", ca, cb).unwrap();
            let n = pair.candidates();
            for it in 0..6 {
                let planar = pair.is_planar() && it % 2 == 0;
                let (x1, x2) = random_poses(&mut rng, planar);
                let traj = |rng: &mut Rng, x: &Pose| {
                    if planar {
                        Trajectory::random_planar(rng, x, 1.0, 0.5)
                    } else {
                        Trajectory::random(rng, x, 1.0, 0.5)
                    }
                };
                let (tr1, tr2) = (traj(&mut rng, &x1), traj(&mut rng, &x2));
                let (mut h_full, mut h_vel) = (vec![SearchHint::default(); n], vec![SearchHint::default(); n]);
                for step in 0..4 {
                    let t = 1e-3 * step as f64;
                    let (b1, b2) = (tr1.at(t), tr2.at(t));
                    let (mut full, mut vel) =
                        (vec![ContactKinematics::default(); n], vec![ContactKinematics::default(); n]);
                    contact_kinematics_warm(&pair, &b1, &b2, &mut full, Some(&mut h_full)).unwrap();
                    contact_velocities_warm(&pair, &b1, &b2, &mut vel, Some(&mut h_vel)).unwrap();
                    let tag = format!("{a}–{b} order {order} #{it} step {step}");
                    for (k, (f, v)) in full.iter().zip(&vel).enumerate() {
                        let same = f.point == v.point
                            && f.gd_n.to_bits() == v.gd_n.to_bits()
                            && f.gd_t.map(f64::to_bits) == v.gd_t.map(f64::to_bits)
                            && f.omega_rel.map(f64::to_bits) == v.omega_rel.map(f64::to_bits)
                            && f.w_tilde.map(f64::to_bits) == v.w_tilde.map(f64::to_bits);
                        assert!(same, "{tag} candidate {k}: {f:?} vs {v:?}");
                        assert_eq!((v.wbar_n, v.wbar_t), (0.0, [0.0; 2]), "{tag}");
                    }
                    assert_eq!(h_full, h_vel, "{tag}: search hints");
                }
            }
        }
    }
}

/// A moving surface (conveyor) at velocity level: the belt's speed in `ġ_T` and `w̃` as in the
/// full kinematics.
#[test]
fn velocity_level_keeps_the_surface_velocity() {
    // in the sample plane (normal (0.1, 0.2, 1))
    let belt = Vec3::new(0.0, 0.3, -0.06);
    let pair =
        ContactPair::new("belt", sample("box"), sample("plane")).unwrap().with_surface_velocity(2, belt).unwrap();
    let mut rng = Rng::new(5);
    let (x1, x2) = random_poses(&mut rng, false);
    let (b1, b2) =
        (Trajectory::random(&mut rng, &x1, 1.0, 0.5).at(0.0), Trajectory::random(&mut rng, &x2, 1.0, 0.5).at(0.0));
    let n = pair.candidates();
    let (mut full, mut vel) = (vec![ContactKinematics::default(); n], vec![ContactKinematics::default(); n]);
    contact_kinematics(&pair, &b1, &b2, &mut full).unwrap();
    contact_velocities_warm(&pair, &b1, &b2, &mut vel, None).unwrap();
    for (f, v) in full.iter().zip(&vel) {
        assert_eq!(
            (f.point, f.gd_n, f.gd_t, f.w_tilde, f.omega_rel),
            (v.point, v.gd_n, v.gd_t, v.w_tilde, v.omega_rel)
        );
        assert!(v.w_tilde[1].abs() + v.w_tilde[2].abs() > 0.0);
    }
}
