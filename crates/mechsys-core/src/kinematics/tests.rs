//! Kinematics against finite differences.

use nalgebra::DMatrix;

use super::*;
use crate::data::Data;
use crate::fixtures;
use crate::math::{Mat3, Vec3};

/// The point Jacobian times u equals the recursive point velocity, and both equal the finite
/// difference of the point position along q ⊕ u dt (eq. 2.69).
#[test]
fn point_jacobian_matches_velocity_and_finite_difference() {
    for kind in ["revolute", "spherical", "universal"] {
        let model = fixtures::chain(4, kind);
        let mut data = Data::new(&model);
        let q = model.q0();
        let u: Vec<f64> = (0..model.nu).map(|i| 0.3 - 0.11 * i as f64).collect();
        forward_kinematics(&model, &mut data, &q, &u);
        let p_b = Vec3::new(0.4, 0.05, -0.02);
        let body = model.nbodies() - 1;
        let mut jt = DMatrix::zeros(3, model.nu);
        let mut jr = DMatrix::zeros(3, model.nu);
        point_jacobian(&model, &data, body, &p_b, &mut jt, &mut jr);
        let uv = nalgebra::DVector::from_column_slice(&u);
        let v_rec = point_velocity(&data, body, &p_b);
        assert!((&jt * &uv - v_rec).norm() < 1e-12, "{kind}: J u vs recursion");
        let w_rec = data.v[body].w;
        assert!((&jr * &uv - w_rec).norm() < 1e-12, "{kind}: J_R u vs recursion");
        let h = 1e-6;
        let (mut qp, mut qm) = (q.clone(), q.clone());
        model.integrate(&q, &u, h, &mut qp);
        model.integrate(&q, &u, -h, &mut qm);
        let mut d2 = Data::new(&model);
        positions(&model, &mut d2, &qp);
        let pp = point_position(&d2, body, &p_b);
        positions(&model, &mut d2, &qm);
        let pm = point_position(&d2, body, &p_b);
        assert!(((pp - pm) / (2.0 * h) - v_rec).norm() < 1e-8, "{kind}: finite difference");
    }
}

/// The recursive acceleration of a point equals the finite difference of its velocity.
#[test]
fn point_acceleration_matches_finite_difference() {
    let model = fixtures::chain(3, "universal");
    let q = model.q0();
    let u: Vec<f64> = (0..model.nu).map(|i| 0.5 - 0.2 * i as f64).collect();
    let udot: Vec<f64> = (0..model.nu).map(|i| -0.3 + 0.4 * i as f64).collect();
    let mut data = Data::new(&model);
    forward_kinematics(&model, &mut data, &q, &u);
    data.a[0] = crate::spatial::Motion::ZERO;
    accelerations(&model, &mut data, &udot);
    let p_b = Vec3::new(0.3, -0.1, 0.05);
    let body = 3;
    let a_rec = point_acceleration(&data, body, &p_b);
    let h = 1e-5;
    let vel = |s: f64| {
        let mut qs = q.clone();
        model.integrate(&q, &u, s, &mut qs);
        // second-order accurate: q(t+s) ≈ q ⊕ (u s + ½ u̇ s²)
        let du: Vec<f64> = udot.iter().map(|a| 0.5 * a * s * s).collect();
        let q2 = qs.clone();
        let mut q3 = qs.clone();
        model.integrate(&q2, &du, 1.0, &mut q3);
        let us: Vec<f64> = u.iter().zip(&udot).map(|(a, b)| a + b * s).collect();
        let mut d = Data::new(&model);
        forward_kinematics(&model, &mut d, &q3, &us);
        point_velocity(&d, body, &p_b)
    };
    let fd = (vel(h) - vel(-h)) / (2.0 * h);
    assert!((fd - a_rec).norm() < 1e-6, "fd {fd} vs {a_rec}");
}

/// The world-frame inertias (principal-axes fast path included) equal the textbook rotation
/// A I_C Aᵀ and Steiner shift m(|c|²E - c cᵀ) (section 2.3.4).
#[test]
fn world_inertias_match_rotation_and_steiner() {
    let model = fixtures::chain(3, "spherical");
    assert!(model.bodies[1].principal_axes);
    let mut data = Data::new(&model);
    let q = model.q0();
    positions(&model, &mut data, &q);
    inertias(&model, &mut data, 0.0);
    for i in 1..model.nbodies() {
        let b = &model.bodies[i];
        let x = &data.x_abs[i];
        let c = x.r + x.a * b.com;
        let expected =
            x.a * b.inertia * x.a.transpose() + (Mat3::identity() * c.norm_squared() - c * c.transpose()) * b.mass;
        assert!((data.inertia[i].i_o - expected).norm() < 1e-13, "body {i}");
        assert!((data.inertia[i].h - c * b.mass).norm() < 1e-14);
    }
}

/// The coordinate-axis path of revolute joints (the angles' sin/cos ahead of the recursion, two
/// columns turned) gives the placements and world subspaces of the general path (the joint's
/// own placement composed with the parent's, its subspace moved to the world), about x, y and z,
/// at angles in every quadrant and beyond ±2π, and the fused forward pass equals the stages.
#[test]
fn coordinate_axis_revolutes_match_the_general_placement() {
    let model = fixtures::chain(6, "revolute"); // axes z, y, x, z, y, x
    let axes: Vec<_> = model.joints.iter().map(|j| j.coordinate_axis).collect();
    assert_eq!(axes, [Some(2), Some(1), Some(0), Some(2), Some(1), Some(0)]);
    let (mut data, mut fused) = (Data::new(&model), Data::new(&model));
    for seed in [0.0, 1.3, -2.9] {
        let q: Vec<f64> = (0..model.nq).map(|k| seed + 2.1 * k as f64 - 4.0 * (k % 2) as f64).collect();
        let u: Vec<f64> = (0..model.nu).map(|k| 0.4 - 0.3 * k as f64).collect();
        positions(&model, &mut data, &q);
        velocities(&model, &mut data, &q, &u);
        forward_pass(&model, &mut fused, 0.0, &q, &u);
        let mut x_prev = Pose::IDENTITY;
        for (ji, j) in model.joints.iter().enumerate() {
            let i = ji + 1;
            let x_joint = x_prev.compose(&j.parent_frame).compose(&j.kind.placement(&q[j.iq..j.iq + 1]));
            let x = x_joint.compose(&j.child_frame_inv);
            let mut s = [Motion::ZERO; 6];
            j.kind.subspace(&q[j.iq..j.iq + 1], &mut s);
            let s_world = motion_to_world(&x_joint, &s[0]);
            assert!((data.x_abs[i].a - x.a).amax() < 1e-14, "seed {seed}, body {i}: rotation");
            assert!((data.x_abs[i].r - x.r).amax() < 1e-14, "seed {seed}, body {i}: position");
            assert!((data.s[i][0].w - s_world.w).amax() < 1e-14 && (data.s[i][0].v - s_world.v).amax() < 1e-14);
            assert_eq!(
                (fused.x_abs[i], fused.s[i][0], fused.v[i], fused.c[i]),
                (data.x_abs[i], data.s[i][0], data.v[i], data.c[i])
            );
            x_prev = x;
        }
    }
}
