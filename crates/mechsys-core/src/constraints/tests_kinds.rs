//! The point-on-line/plane, loop-joint, knife-edge and rolling-disc kinds against finite
//! differences: `G u - b = dΦ/dt` on the holonomic rows, `d(G u - b)/dt = G u̇ - γ` along the
//! motion on all rows, and the applied loads of `apply_forces` equal to `Gᵀλ`.

use super::*;
use crate::data::Data;
use crate::forces::NoCallbacks;
use crate::model::description::*;
use crate::model::Model;

use super::tests::body;

fn joint(
    name: &str,
    kind: &str,
    parent: &str,
    child: &str,
    pos: [f64; 3],
    axis: Option<[f64; 3]>,
    q0: Vec<f64>,
) -> JointDescription {
    super::tests::joint(name, kind, parent, child, pos, axis, Some(q0))
}

fn frame(position: [f64; 3], cardan: [f64; 3]) -> FrameDescription {
    FrameDescription {
        position,
        rotation: Some(RotationDescription::Angles(AnglesDescription {
            cardan: Some(cardan),
            euler: None,
            rotvec: None,
        })),
    }
}

/// A tree of revolute and free bodies with every new kind attached at generic (not assembled)
/// configurations: the kinematic identities hold everywhere, on the manifold or not.
fn model_with_new_kinds() -> Model {
    let s = |name: &str| name.to_string();
    let desc = ModelDescription {
        name: "kinds".into(),
        gravity: [0.0, 0.0, -9.81],
        bodies: vec![
            body("a", 1.0, [0.2, 0.0, 0.0]),
            body("b", 0.5, [0.1, 0.0, 0.0]),
            body("c", 0.8, [0.0, 0.0, 0.0]),
            body("d", 0.3, [0.05, 0.0, 0.0]),
            body("disc", 1.2, [0.0, 0.0, 0.0]),
        ],
        joints: vec![
            joint("ja", "revolute", "ground", "a", [0.0; 3], Some([0.0, 0.0, 1.0]), vec![0.3]),
            joint("jb", "revolute", "a", "b", [0.4, 0.0, 0.0], Some([0.0, 1.0, 0.0]), vec![0.5]),
            joint("jc", "free", "ground", "c", [0.0; 3], None, vec![0.5, 0.3, -0.1, 0.9, 0.1, 0.2, 0.3]),
            joint("jd", "free", "b", "d", [0.1, 0.0, 0.0], None, vec![0.2, -0.1, 0.3, 0.7, -0.3, 0.4, 0.1]),
            joint("jdisc", "free", "ground", "disc", [0.0; 3], None, vec![0.3, 0.2, 0.25, 0.8, 0.4, -0.2, 0.3]),
        ],
        forces: vec![],
        ground_markers: vec![],
        constraints: vec![
            ConstraintDescription::PointOnLine {
                name: s("line"),
                body1: s("c"),
                point1: [0.1, 0.05, 0.0],
                body2: s("b"),
                point2: [0.2, 0.0, 0.1],
                direction: [1.0, 2.0, 0.5],
            },
            ConstraintDescription::PointOnPlane {
                name: s("plane"),
                body1: s("d"),
                point1: [0.0, 0.1, -0.05],
                body2: s("c"),
                point2: [0.1, 0.0, 0.2],
                normal: [0.3, -1.0, 2.0],
            },
            ConstraintDescription::LoopSpherical {
                name: s("ball"),
                body1: s("b"),
                frame1: frame([0.1, 0.0, 0.05], [0.2, -0.3, 0.4]),
                body2: s("c"),
                frame2: frame([0.0, 0.1, 0.0], [0.0; 3]),
            },
            ConstraintDescription::LoopRevolute {
                name: s("hinge"),
                body1: s("c"),
                frame1: frame([0.05, 0.0, 0.1], [0.3, 0.1, -0.2]),
                body2: s("d"),
                frame2: frame([0.0, -0.1, 0.0], [-0.4, 0.2, 0.7]),
            },
            ConstraintDescription::LoopFixed {
                name: s("weld"),
                body1: s("d"),
                frame1: frame([0.1, 0.1, 0.0], [0.5, -0.2, 0.1]),
                body2: s("a"),
                frame2: frame([0.3, 0.0, 0.0], [0.1, 0.6, -0.3]),
            },
            ConstraintDescription::LoopFixed {
                name: s("weld_ground"),
                body1: s("c"),
                frame1: frame([0.0, 0.0, 0.1], [1.0, 0.3, 0.2]),
                body2: s("ground"),
                frame2: frame([0.4, 0.1, 0.0], [0.2, 0.1, 2.0]),
            },
            ConstraintDescription::KnifeEdge {
                name: s("blade"),
                body: s("d"),
                point: [0.1, 0.2, 0.0],
                direction: [0.2, 1.0, 0.3],
            },
            ConstraintDescription::RollingDisc {
                name: s("wheel"),
                body: s("disc"),
                center: [0.02, 0.0, 0.01],
                axis: [0.1, 0.2, 1.0],
                radius: 0.3,
            },
        ],
    };
    Model::from_description(desc).unwrap()
}

fn holonomic(model: &Model, r: usize) -> bool {
    model.constraints.iter().any(|c| r >= c.row && r < c.row + c.kind.holonomic_rows())
}

#[test]
fn new_kinds_have_their_row_counts() {
    let model = model_with_new_kinds();
    assert_eq!(model.nc, 2 + 1 + 3 + 5 + 6 + 6 + 1 + 3);
    let h: usize = model.constraints.iter().map(|c| c.kind.holonomic_rows()).sum();
    assert_eq!(h, model.nc - 1 - 2);
}

#[test]
fn new_kinds_velocity_rows_are_the_time_derivative_of_the_violation() {
    let model = model_with_new_kinds();
    let u: Vec<f64> = (0..model.nu).map(|i| 0.6 * ((i as f64) * 1.3).sin() + 0.1).collect();
    for (r, (fd, gu)) in super::tests::velocity_pairs(&model, &model.q0(), &u, 0.4).into_iter().enumerate() {
        if !holonomic(&model, r) {
            assert_eq!(fd, 0.0, "row {r}: a non-holonomic row has no position violation");
            continue;
        }
        assert!((fd - gu).abs() < 1e-8, "row {r}: dΦ/dt {fd} vs G u - b {gu}");
    }
}

#[test]
fn new_kinds_acceleration_rows_are_the_derivative_of_the_velocity_rows() {
    let model = model_with_new_kinds();
    let u: Vec<f64> = (0..model.nu).map(|i| 0.5 * ((i as f64) * 0.7).cos() - 0.1).collect();
    let udot: Vec<f64> = (0..model.nu).map(|i| -0.4 + 0.1 * i as f64).collect();
    for (r, (fd, expected)) in super::tests::acceleration_pairs(&model, &model.q0(), &u, &udot, 0.3).into_iter().enumerate() {
        assert!((fd - expected).abs() < 1e-7, "row {r}: d(Gu - b)/dt {fd} vs G u̇ - γ {expected}");
    }
}

#[test]
fn new_kinds_apply_forces_equal_g_transpose_lambda() {
    let model = model_with_new_kinds();
    let mut data = Data::new(&model);
    let q = model.q0();
    crate::kinematics::positions(&model, &mut data, &q);
    positions(&model, &mut data, 0.0, &q, &NoCallbacks).unwrap();
    for r in 0..model.nc {
        data.lambda[r] = 0.3 + 0.17 * r as f64 - 0.01 * (r * r) as f64;
    }
    for f in data.f_ext.iter_mut() {
        *f = crate::spatial::Force::ZERO;
    }
    data.tau_applied.fill(0.0);
    apply_forces(&model, &mut data);
    // generalized force of the body loads: Σ over the bodies below each joint of S·f
    for (ji, j) in model.joints.iter().enumerate() {
        for k in 0..j.nu() {
            let col = j.iu + k;
            let mut tau = data.tau_applied[col];
            for bi in 1..model.bodies.len() {
                let mut b = bi;
                while b != 0 && b != ji + 1 {
                    b = model.joints[b - 1].parent;
                }
                if b == ji + 1 {
                    let s = &data.s[ji + 1][k];
                    tau += s.w.dot(&data.f_ext[bi].n) + s.v.dot(&data.f_ext[bi].f);
                }
            }
            let gl: f64 = (0..model.nc).map(|r| data.g[(r, col)] * data.lambda[r]).sum();
            assert!((tau - gl).abs() < 1e-12 * (1.0 + gl.abs()), "dof {col}: loads {tau} vs Gᵀλ {gl}");
        }
    }
}

/// A loop-fixed row pair at an assembled configuration: Φ = 0 and the rotation rows are the
/// relative angular velocity in frame-2 axes exactly (E(I) = I).
#[test]
fn loop_fixed_rows_at_zero_violation_are_the_relative_angular_velocity() {
    let model = model_with_new_kinds();
    let c = model.constraints.iter().find(|c| c.name == "weld_ground").unwrap();
    let ConstraintKind::Loop { f2, .. } = &c.kind else { panic!() };
    // place body c so that its frame1 coincides with the ground frame2
    let mut data = Data::new(&model);
    let mut q = model.q0();
    let ConstraintKind::Loop { f1, .. } = &c.kind else { panic!() };
    let x_c = f2.compose(&f1.inverse());
    let quat = crate::simulate::matrix_to_quaternion(&x_c.a);
    let jc = &model.joints[2];
    q[jc.iq..jc.iq + 3].copy_from_slice(x_c.r.as_slice());
    q[jc.iq + 3..jc.iq + 7].copy_from_slice(&quat);
    crate::kinematics::positions(&model, &mut data, &q);
    positions(&model, &mut data, 0.0, &q, &NoCallbacks).unwrap();
    for k in 0..6 {
        assert!(data.phi[c.row + k].abs() < 1e-14, "row {k}: Φ = {}", data.phi[c.row + k]);
    }
    // free joint: u = (v_B, ω_B) in body axes, so the rows map ω_B into frame-2 axes: A₂ᵀ A_c
    let a = f2.a.transpose() * x_c.a;
    for r in 0..3 {
        for k in 0..3 {
            let gk = data.g[(c.row + 3 + r, jc.iu + 3 + k)];
            assert!((gk - a[(r, k)]).abs() < 1e-14, "G[{r}, ω{k}] = {gk} vs {}", a[(r, k)]);
        }
    }
}
