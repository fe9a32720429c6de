//! Relative contact kinematics against finite differences along prescribed smooth motions of
//! both bodies, and the W-part split against the point Jacobians of a multibody chain.

use nalgebra::{DMatrix, DVector};

use super::*;
use crate::contact::narrow::{evaluate, ContactPair};
use crate::contact::test_util::{close, random_poses, sample, Rng, Trajectory, PAIRS};
use crate::contact::Contour;
use crate::math::Mat3;

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
    let (gp1, gm1) = (g(h1), g(-h1));
    let (m1, m2) = (tr1.at(0.0), tr2.at(0.0));
    for (k, c) in k0.iter().enumerate() {
        let tag = format!("{tag} candidate {k}");
        assert_eq!(c.point.g_n, g0[k].g_n, "{tag}: evaluate and kinematics agree");
        let gd_fd = (gp1[k].g_n - gm1[k].g_n) / (2.0 * h1);
        assert!(close(c.gd_n, gd_fd, 1e-6), "{tag}: ġ_N {} vs difference {gd_fd}", c.gd_n);
        let gdd_fd2 = (gp[k].g_n - 2.0 * g0[k].g_n + gm[k].g_n) / (h2 * h2);
        assert!(close(c.wbar_n, gdd_fd2, 1e-6), "{tag}: g̈_N {} vs second difference {gdd_fd2}", c.wbar_n);
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

/// Box on box (vertex–face candidates): a tilted box resting over the top face of another, both
/// moving; the 16 candidates' rates against finite differences, and the reversed pair gives the
/// same contacts with candidates 0–7 and 8–15 exchanged.
#[test]
fn box_on_box_rates_and_reversal() {
    let mut rng = Rng::new(31);
    let upper = sample("box_b");
    let lower =
        Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(0.6, 0.5, 0.2) };
    let pair = ContactPair::new("bb", upper.clone(), lower.clone()).unwrap();
    assert_eq!(pair.candidates(), 16);
    let rev = ContactPair::new("bb", lower, upper).unwrap();
    for it in 0..6 {
        let tilt = nalgebra::Rotation3::from_euler_angles(0.1 * it as f64, -0.05, 0.3).into_inner();
        let x1 = Pose::new(tilt, Vec3::new(0.05, -0.03, 0.32 + 0.01 * it as f64));
        let x2 = Pose::new(nalgebra::Rotation3::from_euler_angles(0.0, 0.0, 0.2).into_inner(), Vec3::zeros());
        let tr1 = Trajectory::random(&mut rng, &x1, 0.3, 0.2);
        let tr2 = Trajectory::random(&mut rng, &x2, 0.3, 0.2);
        check(&pair, &tr1, &tr2, &format!("box–box #{it}"));
        let (mut f, mut r) =
            ([crate::contact::ContactPoint::default(); 16], [crate::contact::ContactPoint::default(); 16]);
        evaluate(&pair, &x1, &x2, &mut f).unwrap();
        evaluate(&rev, &x2, &x1, &mut r).unwrap();
        for k in 0..16 {
            let (a, b) = (&f[k], &r[(k + 8) % 16]);
            assert!(
                (a.g_n - b.g_n).abs() < 1e-14 && (a.n + b.n).norm() < 1e-14 && (a.p1 - b.p2).norm() < 1e-14,
                "candidate {k}"
            );
        }
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
