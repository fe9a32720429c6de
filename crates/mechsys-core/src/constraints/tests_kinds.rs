//! The point-on-line/plane, loop-joint, knife-edge and rolling-disc kinds against finite
//! differences: `G u - b = dΦ/dt` on the holonomic rows, `d(G u - b)/dt = G u̇ - γ` along the
//! motion on all rows, and the applied loads of `apply_forces` equal to `Gᵀλ`.

use super::*;
use crate::data::Data;
use crate::forces::{Callbacks, NoCallbacks};
use crate::kinematics::point_velocity;
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
        contacts: vec![],
        contact_groups: vec![],
        gap_contacts: vec![],
        visuals: vec![],
        planar: false,
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
            ConstraintDescription::LoopSpherical(LoopFrames {
                name: s("ball"),
                body1: s("b"),
                frame1: frame([0.1, 0.0, 0.05], [0.2, -0.3, 0.4]),
                body2: s("c"),
                frame2: frame([0.0, 0.1, 0.0], [0.0; 3]),
            }),
            ConstraintDescription::LoopRevolute(LoopFrames {
                name: s("hinge"),
                body1: s("c"),
                frame1: frame([0.05, 0.0, 0.1], [0.3, 0.1, -0.2]),
                body2: s("d"),
                frame2: frame([0.0, -0.1, 0.0], [-0.4, 0.2, 0.7]),
            }),
            ConstraintDescription::LoopFixed(LoopFrames {
                name: s("weld"),
                body1: s("d"),
                frame1: frame([0.1, 0.1, 0.0], [0.5, -0.2, 0.1]),
                body2: s("a"),
                frame2: frame([0.3, 0.0, 0.0], [0.1, 0.6, -0.3]),
            }),
            ConstraintDescription::LoopFixed(LoopFrames {
                name: s("weld_ground"),
                body1: s("c"),
                frame1: frame([0.0, 0.0, 0.1], [1.0, 0.3, 0.2]),
                body2: s("ground"),
                frame2: frame([0.4, 0.1, 0.0], [0.2, 0.1, 2.0]),
            }),
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

/// `G u - b = dΦ/dt` on the holonomic rows (non-holonomic rows have Φ = 0) at time `t`.
pub(super) fn check_velocity_rows(model: &Model, cb: &dyn Callbacks, t: f64, tol: f64) {
    let u: Vec<f64> = (0..model.nu).map(|i| 0.6 * ((i as f64) * 1.3).sin() + 0.1).collect();
    for (r, (fd, gu)) in super::tests::velocity_pairs(model, cb, &model.q0(), &u, t).into_iter().enumerate() {
        if !holonomic(model, r) {
            assert_eq!(fd, 0.0, "row {r}: a non-holonomic row has no position violation");
            continue;
        }
        assert!((fd - gu).abs() < tol, "row {r}: dΦ/dt {fd} vs G u - b {gu}");
    }
}

/// `d(G u - b)/dt = G u̇ - γ` along the motion on all rows at time `t`.
pub(super) fn check_acceleration_rows(model: &Model, cb: &dyn Callbacks, t: f64, tol: f64) {
    let u: Vec<f64> = (0..model.nu).map(|i| 0.5 * ((i as f64) * 0.7).cos() - 0.1).collect();
    let udot: Vec<f64> = (0..model.nu).map(|i| -0.4 + 0.1 * i as f64).collect();
    for (r, (fd, expected)) in
        super::tests::acceleration_pairs(model, cb, &model.q0(), &u, &udot, t).into_iter().enumerate()
    {
        assert!((fd - expected).abs() < tol, "row {r}: d(Gu - b)/dt {fd} vs G u̇ - γ {expected}");
    }
}

/// The first nonzero of `data.g` outside the planned pattern of G (row, velocity), if any: a
/// constraint kind whose [`crate::constraints::ConstraintKind::reach`] is too small.
fn outside_pattern(data: &Data) -> Option<(usize, usize)> {
    let (nc, nu) = data.g.shape();
    for r in 0..nc {
        let pat = &data.g_row_idx[data.g_row_ptr[r]..data.g_row_ptr[r + 1]];
        for i in 0..nu {
            if data.g[(r, i)] != 0.0 && pat.binary_search(&i).is_err() {
                return Some((r, i));
            }
        }
    }
    None
}

/// The loads of `apply_forces` (body wrenches and generalized forces) equal `Gᵀλ` for arbitrary λ.
pub(super) fn check_apply_forces(model: &Model, cb: &dyn Callbacks, t: f64) {
    let mut data = Data::new(model);
    let q = model.q0();
    crate::kinematics::positions(model, &mut data, &q);
    positions(model, &mut data, t, &q, cb).unwrap();
    // the sparse solve sees only the planned pattern: every nonzero of G must lie on it
    assert_eq!(outside_pattern(&data), None, "a constraint writes outside its reach");
    for r in 0..model.nc {
        data.lambda[r] = 0.3 + 0.17 * r as f64 - 0.01 * (r * r) as f64;
    }
    for f in data.f_ext.iter_mut() {
        *f = crate::spatial::Force::ZERO;
    }
    data.tau_applied.fill(0.0);
    apply_forces(model, &mut data);
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

#[test]
fn new_kinds_velocity_rows_are_the_time_derivative_of_the_violation() {
    check_velocity_rows(&model_with_new_kinds(), &NoCallbacks, 0.4, 1e-8);
}

#[test]
fn new_kinds_acceleration_rows_are_the_derivative_of_the_velocity_rows() {
    check_acceleration_rows(&model_with_new_kinds(), &NoCallbacks, 0.3, 1e-7);
}

#[test]
fn new_kinds_apply_forces_equal_g_transpose_lambda() {
    check_apply_forces(&model_with_new_kinds(), &NoCallbacks, 0.0);
}

/// The tree of [`model_with_new_kinds`] closed by the prismatic, cylindrical, universal and
/// planar loop joints, each between two moving bodies and once to the ground, at generic frames.
fn model_with_loop_joints() -> Model {
    let s = |name: &str| name.to_string();
    let mut desc = model_with_new_kinds().description.clone();
    let f = frame;
    desc.constraints = vec![
        ConstraintDescription::LoopPrismatic(LoopFrames {
            name: s("slider"),
            body1: s("c"),
            frame1: f([0.05, 0.02, 0.1], [0.3, 0.1, -0.2]),
            body2: s("b"),
            frame2: f([0.1, -0.1, 0.0], [-0.4, 0.2, 0.7]),
        }),
        ConstraintDescription::LoopPrismatic(LoopFrames {
            name: s("slider_ground"),
            body1: s("disc"),
            frame1: f([0.0, 0.1, 0.0], [0.2, 0.0, 0.5]),
            body2: s("ground"),
            frame2: f([0.4, 0.1, 0.2], [0.1, -0.3, 0.2]),
        }),
        ConstraintDescription::LoopCylindrical(LoopFrames {
            name: s("sleeve"),
            body1: s("d"),
            frame1: f([0.1, 0.0, 0.05], [0.5, -0.2, 0.1]),
            body2: s("c"),
            frame2: f([0.0, 0.2, -0.1], [0.1, 0.6, -0.3]),
        }),
        ConstraintDescription::LoopCylindrical(LoopFrames {
            name: s("sleeve_ground"),
            body1: s("ground"),
            frame1: f([0.1, 0.2, 0.0], [0.0, 0.4, 0.0]),
            body2: s("d"),
            frame2: f([0.05, 0.0, 0.0], [0.3, 0.0, 0.2]),
        }),
        ConstraintDescription::LoopUniversal(LoopFrames {
            name: s("hooke"),
            body1: s("b"),
            frame1: f([0.2, 0.0, 0.1], [0.2, -0.3, 0.4]),
            body2: s("disc"),
            frame2: f([0.0, 0.1, 0.0], [0.7, 0.1, 0.0]),
        }),
        ConstraintDescription::LoopUniversal(LoopFrames {
            name: s("hooke_ground"),
            body1: s("c"),
            frame1: f([0.0, 0.0, 0.2], [0.0; 3]),
            body2: s("ground"),
            frame2: f([0.3, 0.3, 0.3], [0.4, 0.2, 0.1]),
        }),
        ConstraintDescription::LoopPlanar(LoopFrames {
            name: s("table"),
            body1: s("disc"),
            frame1: f([0.1, 0.0, 0.0], [0.3, 0.2, 0.1]),
            body2: s("a"),
            frame2: f([0.2, 0.1, 0.0], [-0.2, 0.4, 0.3]),
        }),
        ConstraintDescription::LoopPlanar(LoopFrames {
            name: s("floor"),
            body1: s("d"),
            frame1: f([0.0, 0.05, 0.1], [0.1, 0.1, 0.1]),
            body2: s("ground"),
            frame2: f([0.0, 0.0, -0.2], [0.2, -0.1, 0.0]),
        }),
    ];
    Model::from_description(desc).unwrap()
}

#[test]
fn loop_joints_have_their_row_counts() {
    let model = model_with_loop_joints();
    let rows: Vec<usize> = model.constraints.iter().map(|c| c.kind.rows()).collect();
    assert_eq!(rows, [5, 5, 4, 4, 4, 4, 3, 3]);
    assert!(model.constraints.iter().all(|c| c.kind.holonomic_rows() == c.kind.rows()));
    assert!(model.constraints.iter().all(|c| matches!(c.kind.reach(), Reach::Bodies(..))));
}

#[test]
fn loop_joints_velocity_rows_are_the_time_derivative_of_the_violation() {
    check_velocity_rows(&model_with_loop_joints(), &NoCallbacks, 0.4, 1e-8);
}

#[test]
fn loop_joints_acceleration_rows_are_the_derivative_of_the_velocity_rows() {
    check_acceleration_rows(&model_with_loop_joints(), &NoCallbacks, 0.3, 1e-7);
}

#[test]
fn loop_joints_apply_forces_equal_g_transpose_lambda() {
    check_apply_forces(&model_with_loop_joints(), &NoCallbacks, 0.0);
}

/// The rows at an assembled configuration say what each λ is: the prismatic joint's translation
/// rows are the offset velocity along x₂, y₂ and its rotation rows the relative angular velocity
/// in frame-2 axes; the universal joint's row is the relative angular velocity about x₁ × y₂;
/// the planar joint's first row is the offset velocity along z₂ (a sign error in any row fails).
#[test]
fn loop_joint_rows_at_zero_violation_mean_what_the_docs_say() {
    use crate::spatial::Pose;
    // body "c" on a free joint against the ground: place it so that its frame1 meets frame2
    let mut desc = model_with_new_kinds().description.clone();
    let fr = |p: [f64; 3], c: [f64; 3]| frame(p, c);
    let (f1, f2) = (fr([0.05, 0.02, 0.1], [0.3, 0.1, -0.2]), fr([0.4, 0.1, 0.2], [0.1, -0.3, 0.2]));
    let mk = |name: &str, f1: FrameDescription, f2: FrameDescription| {
        let frames =
            LoopFrames { name: name.into(), body1: "c".into(), frame1: f1, body2: "ground".into(), frame2: f2 };
        match name {
            "p" => ConstraintDescription::LoopPrismatic(frames),
            "u" => ConstraintDescription::LoopUniversal(frames),
            _ => ConstraintDescription::LoopPlanar(frames),
        }
    };
    desc.constraints =
        vec![mk("p", f1.clone(), f2.clone()), mk("u", f1, f2.clone()), mk("l", fr([0.0; 3], [0.0; 3]), f2)];
    let model = Model::from_description(desc).unwrap();
    let ConstraintKind::Loop { f1: p1, f2: p2, .. } = &model.constraints[0].kind else { panic!() };
    let x_c: Pose = p2.compose(&p1.inverse());
    let mut q = model.q0();
    let jc = &model.joints[2];
    q[jc.iq..jc.iq + 3].copy_from_slice(x_c.r.as_slice());
    q[jc.iq + 3..jc.iq + 7].copy_from_slice(&crate::simulate::matrix_to_quaternion(&x_c.a));
    // a free-joint velocity: u = (v_B, ω_B), body axes
    let mut u = vec![0.0; model.nu];
    let (v_b, w_b) = (Vec3::new(0.3, -0.2, 0.5), Vec3::new(-0.4, 0.7, 0.2));
    u[jc.iu..jc.iu + 3].copy_from_slice(v_b.as_slice());
    u[jc.iu + 3..jc.iu + 6].copy_from_slice(w_b.as_slice());
    let mut data = Data::new(&model);
    crate::kinematics::forward_kinematics(&model, &mut data, &q, &u);
    positions(&model, &mut data, 0.0, &q, &NoCallbacks).unwrap();
    for r in [0, 1, 2, 3, 4, 5, 6, 7, 8] {
        assert!(data.phi[r].abs() < 1e-14, "row {r}: Φ = {}", data.phi[r]);
    }
    let gu = |r: usize| (0..model.nu).map(|i| data.g[(r, i)] * u[i]).sum::<f64>();
    let (v1, w) = (point_velocity(&data, 3, &p1.r), data.v[3].w);
    let a2 = p2.a;
    // prismatic: rows 0, 1 = x₂·v₁, y₂·v₁; rows 2..5 = A₂ᵀ ω
    for k in 0..2 {
        assert!((gu(k) - a2.column(k).dot(&v1)).abs() < 1e-14, "prismatic row {k}");
    }
    let w2 = a2.transpose() * w;
    for k in 0..3 {
        assert!((gu(2 + k) - w2[k]).abs() < 1e-14, "prismatic rotation row {k}");
    }
    // universal: rows 5..8 the origin velocity, row 8 = ω·(x₁ × y₂)
    for k in 0..3 {
        assert!((gu(5 + k) - v1[k]).abs() < 1e-14, "universal row {k}");
    }
    let axis = a2.column(0).cross(&a2.column(1));
    assert!((gu(8) - w.dot(&axis)).abs() < 1e-14, "universal pin row");
    // planar with frame1 at the body origin (z₂ fixed in the ground): row 0 = z₂·v(origin)
    let r0 = model.constraints[2].row;
    let o = data.x_abs[3].r;
    let vo = data.v[3].v + w.cross(&o);
    assert!((gu(r0) - a2.column(2).dot(&vo)).abs() < 1e-14, "planar normal row");
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

fn harmonic(amplitude: f64, omega: f64, phase: f64, offset: f64) -> TimeFunctionDescription {
    TimeFunctionDescription::Harmonic { amplitude, omega, phase, offset }
}

/// Prescribed body motions on the tree of [`model_with_new_kinds`]: a driven frame on the free
/// body "c" (position and orientation, near but not on its course, so that the rows are generic),
/// and the origin of the free body "d" (child of a moving body) driven alone.
fn model_with_prescribed_bodies() -> Model {
    let base = model_with_new_kinds();
    let mut desc = base.description.clone();
    let f_c = frame([0.05, -0.1, 0.2], [0.4, -0.2, 0.3]);
    // Cardan angles of that frame at q0, so that the orientation error stays well below 90°
    let mut data = Data::new(&base);
    crate::kinematics::positions(&base, &mut data, &base.q0());
    let c = base.body_id("c").unwrap();
    let pose = data.x_abs[c].compose(&crate::spatial::Pose::new(
        crate::math::rotation::cardan_xyz_to_matrix([0.4, -0.2, 0.3]),
        Vec3::new(0.05, -0.1, 0.2),
    ));
    let ang = crate::math::rotation::matrix_to_cardan_xyz(&pose.a).unwrap();
    desc.constraints = vec![
        ConstraintDescription::PrescribedBody {
            name: "drive_c".into(),
            body: "c".into(),
            frame: f_c,
            position: vec![
                harmonic(0.3, 1.1, 0.2, 0.5),
                harmonic(-0.2, 2.0, 0.0, 0.1),
                TimeFunctionDescription::Ramp { slope: 0.7, t0: 0.1, final_value: None },
            ],
            orientation: Some(vec![
                harmonic(0.2, 1.7, 0.3, ang[0] + 0.05),
                harmonic(-0.15, 2.3, -0.4, ang[1] - 0.1),
                harmonic(0.25, 0.9, 1.0, ang[2]),
            ]),
        },
        ConstraintDescription::PrescribedBody {
            name: "drive_d".into(),
            body: "d".into(),
            frame: frame([0.1, 0.0, 0.05], [0.0; 3]),
            position: vec![
                TimeFunctionDescription::Constant { value: 0.2 },
                harmonic(0.1, 3.0, 0.5, 0.0),
                harmonic(0.4, 0.5, 0.0, -0.3),
            ],
            orientation: None,
        },
    ];
    Model::from_description(desc).unwrap()
}

#[test]
fn prescribed_body_rows_and_reach() {
    let model = model_with_prescribed_bodies();
    let rows: Vec<usize> = model.constraints.iter().map(|c| c.kind.rows()).collect();
    assert_eq!(rows, [6, 3]);
    assert_eq!(model.constraints[0].kind.reach(), Reach::Bodies(model.body_id("c").unwrap(), 0));
    assert_eq!(model.constraints[1].kind.holonomic_rows(), 3);
}

#[test]
fn prescribed_body_velocity_rows_are_the_time_derivative_of_the_violation() {
    // t-dependence included: dΦ(q(t), t)/dt = G u - b
    let model = model_with_prescribed_bodies();
    for t in [0.0, 0.4, 1.3] {
        check_velocity_rows(&model, &NoCallbacks, t, 1e-8);
    }
}

#[test]
fn prescribed_body_acceleration_rows_are_the_derivative_of_the_velocity_rows() {
    let model = model_with_prescribed_bodies();
    for t in [0.3, 1.1] {
        check_acceleration_rows(&model, &NoCallbacks, t, 1e-7);
    }
}

#[test]
fn prescribed_body_apply_forces_equal_g_transpose_lambda() {
    let model = model_with_prescribed_bodies();
    for t in [0.0, 0.5] {
        check_apply_forces(&model, &NoCallbacks, t);
    }
}

/// On its prescribed course the rows are the world velocity error of the frame origin and the
/// world angular velocity error: λ is the world driving force and moment.
#[test]
fn prescribed_body_rows_on_course_are_world_velocity_errors() {
    use crate::spatial::Pose;
    let model = model_with_prescribed_bodies();
    let ConstraintKind::PrescribedBody { body, frame: f, position, orientation: Some(angles) } =
        &model.constraints[0].kind
    else {
        panic!()
    };
    let (c, t) = (&model.constraints[0], 0.7);
    let [p, pd, _] = prescribed_point(position, t, &NoCallbacks, c, "position").unwrap();
    let (a_p, w_p, _) = prescribed_rotation(angles, t, &NoCallbacks, c).unwrap();
    // ω_p against a finite difference of A_p: Ȧ_p A_pᵀ = ω̃_p
    let h = 1e-6;
    let (a_plus, _, _) = prescribed_rotation(angles, t + h, &NoCallbacks, c).unwrap();
    let (a_minus, _, _) = prescribed_rotation(angles, t - h, &NoCallbacks, c).unwrap();
    let w_fd = crate::math::untilde(&(((a_plus - a_minus) / (2.0 * h)) * a_p.transpose()));
    assert!((w_fd - w_p).norm() < 1e-8, "ω_p {w_p:?} vs finite difference {w_fd:?}");
    let x_b = Pose::new(a_p, p).compose(&f.inverse());
    let mut q = model.q0();
    let j = &model.joints[*body - 1];
    q[j.iq..j.iq + 3].copy_from_slice(x_b.r.as_slice());
    q[j.iq + 3..j.iq + 7].copy_from_slice(&crate::simulate::matrix_to_quaternion(&x_b.a));
    let mut u = vec![0.0; model.nu];
    for (k, v) in [0.3, -0.5, 0.2, 0.8, -0.1, 0.6].iter().enumerate() {
        u[j.iu + k] = *v;
    }
    let mut data = Data::new(&model);
    crate::kinematics::forward_kinematics(&model, &mut data, &q, &u);
    positions(&model, &mut data, t, &q, &NoCallbacks).unwrap();
    for k in 0..6 {
        assert!(data.phi[k].abs() < 1e-13, "row {k}: Φ = {}", data.phi[k]);
    }
    let err = |r: usize| (0..model.nu).map(|i| data.g[(r, i)] * u[i]).sum::<f64>() - data.b[r];
    let origin = data.x_abs[*body].point_to_parent(&f.r);
    let v = point_velocity(&data, *body, &f.r) - pd;
    let w = data.v[*body].w - w_p;
    assert!((origin - p).norm() < 1e-13);
    for k in 0..3 {
        assert!((err(k) - v[k]).abs() < 1e-13, "position row {k}: {} vs {}", err(k), v[k]);
        assert!((err(3 + k) - w[k]).abs() < 1e-13, "orientation row {k}: {} vs {}", err(3 + k), w[k]);
    }
}

/// User velocity constraints for the tests: `skate` is a knife edge written by hand on the planar
/// joint (x, y, θ at q[1..4]) of a sledge with its blade point at (a, 0, 0), blocked direction the
/// body y-axis: `W = [-sin θ, cos θ, a]`, plus (if `offset`) the rheonomic `w = 0.3 sin 2t + 0.1 x`;
/// `generic` has 2 rows whose W depends on every coordinate (quaternion included) and on t.
struct UserRows {
    a: f64,
    offset: bool,
}

impl UserRows {
    fn generic_w(q: &[f64], t: f64, nu: usize, out: &mut [f64]) {
        for k in 0..2 {
            for i in 0..nu {
                out[k * nu + i] = (0.3 * k as f64 + 0.2 * i as f64 + 0.7 * q[(i + 3 * k) % q.len()] + 0.1 * t).sin();
            }
        }
    }
}

impl Callbacks for UserRows {
    fn time_function(&self, id: usize, _t: f64) -> crate::error::Result<f64> {
        Err(crate::error::Error::Callback(format!("no time function {id}")))
    }
    fn generalized_force(&self, id: usize, _: f64, _: &[f64], _: &[f64], _: &mut [f64]) -> crate::error::Result<()> {
        Err(crate::error::Error::Callback(format!("no force {id}")))
    }
    fn velocity_constraint(
        &self,
        id: usize,
        which: crate::forces::VelocityArray,
        t: f64,
        q: &[f64],
        u: &[f64],
        rows: usize,
        out: &mut [f64],
    ) -> crate::error::Result<()> {
        use crate::forces::VelocityArray as A;
        let nu = out.len() / rows;
        let (sn, c) = q[3].sin_cos();
        match (id, which) {
            (0, A::W) => {
                out.fill(0.0);
                out[1..4].copy_from_slice(&[-sn, c, self.a]);
            }
            (1, A::Offset) => out[0] = if self.offset { 0.3 * (2.0 * t).sin() + 0.1 * q[1] } else { 0.0 },
            (2, A::Rate) => {
                // d(Wᵀ)/dt u + ẇ
                out[0] = -c * u[3] * u[1] - sn * u[3] * u[2];
                if self.offset {
                    out[0] += 0.6 * (2.0 * t).cos() + 0.1 * u[1];
                }
            }
            (3, A::W) => Self::generic_w(q, t, nu, out),
            (4, A::Offset) => {
                out[0] = t.cos() * q[4];
                out[1] = 0.5 * q[5] * q[8];
            }
            _ => panic!("unexpected callback {id} {which:?}"),
        }
        Ok(())
    }
}

/// An arm (revolute), the sledge (planar) and a free body, with the two user constraints; the
/// skate's rate from its callback (`rate`) or by central differences.
fn model_with_user_rows(rate: bool, offset: bool) -> Model {
    let s = |name: &str| name.to_string();
    let desc = ModelDescription {
        name: "user".into(),
        gravity: [0.0, 0.0, -9.81],
        bodies: vec![
            body("arm", 1.0, [0.2, 0.0, 0.0]),
            body("sledge", 2.0, [0.05, 0.0, 0.0]),
            body("c", 0.8, [0.0; 3]),
        ],
        joints: vec![
            joint("ja", "revolute", "ground", "arm", [0.0; 3], Some([0.0, 1.0, 0.0]), vec![0.3]),
            joint("jp", "planar", "ground", "sledge", [0.0; 3], None, vec![0.4, -0.2, 0.7]),
            joint("jc", "free", "ground", "c", [0.0; 3], None, vec![0.5, 0.3, -0.1, 0.9, 0.1, 0.2, 0.3]),
        ],
        forces: vec![],
        ground_markers: vec![],
        contacts: vec![],
        contact_groups: vec![],
        gap_contacts: vec![],
        visuals: vec![],
        planar: false,
        constraints: vec![
            ConstraintDescription::Velocity {
                name: s("skate"),
                rows: 1,
                w_matrix: 0,
                w_offset: offset.then_some(1),
                w_rate: rate.then_some(2),
            },
            ConstraintDescription::Velocity {
                name: s("generic"),
                rows: 2,
                w_matrix: 3,
                w_offset: Some(4),
                w_rate: None,
            },
        ],
    };
    Model::from_description(desc).unwrap()
}

#[test]
fn user_velocity_rows_kinds_and_reach() {
    let model = model_with_user_rows(true, true);
    assert_eq!((model.nc, model.n_callbacks), (3, 5));
    for c in &model.constraints {
        assert_eq!(c.kind.holonomic_rows(), 0);
        assert_eq!(c.kind.reach(), Reach::All);
    }
}

#[test]
fn user_velocity_rows_are_w_transpose_and_minus_w() {
    let model = model_with_user_rows(true, true);
    let cb = UserRows { a: 0.15, offset: true };
    let (q, t) = (model.q0(), 0.6);
    let mut data = Data::new(&model);
    crate::kinematics::positions(&model, &mut data, &q);
    positions(&model, &mut data, t, &q, &cb).unwrap();
    let (sn, c) = q[3].sin_cos();
    let expected = [0.0, -sn, c, 0.15, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    for i in 0..model.nu {
        assert_eq!(data.g[(0, i)], expected[i], "column {i}");
    }
    assert!((data.b[0] + 0.3 * 1.2f64.sin() + 0.1 * q[1]).abs() < 1e-15, "b = -w");
    let mut w = vec![0.0; 2 * model.nu];
    UserRows::generic_w(&q, t, model.nu, &mut w);
    for k in 0..2 {
        for i in 0..model.nu {
            assert_eq!(data.g[(1 + k, i)], w[k * model.nu + i]);
        }
    }
    assert!(data.phi.iter().all(|v| *v == 0.0), "no position rows");
}

#[test]
fn user_velocity_acceleration_rows_with_rate_callback_and_by_differences() {
    let cb = UserRows { a: 0.15, offset: true };
    for rate in [true, false] {
        let model = model_with_user_rows(rate, true);
        for t in [0.0, 0.35, 250.0] {
            check_acceleration_rows(&model, &cb, t, 1e-7);
        }
    }
}

#[test]
fn user_velocity_apply_forces_equal_g_transpose_lambda() {
    check_apply_forces(&model_with_user_rows(false, true), &UserRows { a: 0.15, offset: true }, 0.2);
}

/// The hand-written knife edge equals the built-in one: same G row and γ (the rate callback to
/// round-off, central differences to their truncation error).
#[test]
fn user_knife_edge_equals_the_built_in_knife_edge() {
    let a = 0.15;
    let built_in = {
        let mut d = model_with_user_rows(true, false).description.clone();
        d.constraints = vec![ConstraintDescription::KnifeEdge {
            name: "blade".into(),
            body: "sledge".into(),
            point: [a, 0.0, 0.0],
            direction: [0.0, 1.0, 0.0],
        }];
        Model::from_description(d).unwrap()
    };
    let q = built_in.q0();
    let u: Vec<f64> = (0..built_in.nu).map(|i| 0.7 * (i as f64 * 0.9).cos() - 0.2).collect();
    let eval = |model: &Model, cb: &dyn Callbacks| {
        let mut data = Data::new(model);
        crate::kinematics::forward_kinematics(model, &mut data, &q, &u);
        positions(model, &mut data, 0.3, &q, cb).unwrap();
        data.a[0] = crate::spatial::Motion::ZERO;
        crate::kinematics::accelerations(model, &mut data, &vec![0.0; model.nu]);
        accelerations(model, &mut data, 0.3, &q, &u, cb).unwrap();
        ((0..model.nu).map(|i| data.g[(0, i)]).collect::<Vec<_>>(), data.b[0], data.gamma[0])
    };
    let (g0, b0, gamma0) = eval(&built_in, &NoCallbacks);
    let cb = UserRows { a, offset: false };
    for (rate, tol) in [(true, 1e-14), (false, 1e-9)] {
        let mut d = model_with_user_rows(rate, false).description.clone();
        d.constraints.truncate(1);
        let (g, b, gamma) = eval(&Model::from_description(d).unwrap(), &cb);
        for i in 0..g.len() {
            assert!((g[i] - g0[i]).abs() < 1e-15, "G[{i}] {} vs {}", g[i], g0[i]);
        }
        assert_eq!((b, b0), (0.0, 0.0));
        assert!((gamma - gamma0).abs() < tol, "rate callback {rate}: γ {gamma} vs built-in {gamma0}");
    }
}

#[test]
fn user_velocity_errors_name_the_constraint() {
    let model = model_with_user_rows(false, true);
    let mut data = Data::new(&model);
    let q = model.q0();
    crate::kinematics::positions(&model, &mut data, &q);
    // no callbacks given
    let e = positions(&model, &mut data, 0.0, &q, &NoCallbacks).unwrap_err().to_string();
    assert!(e.contains("constraint 'skate'") && e.contains("W callback 0"), "{e}");
    // nor can the acceleration stage
    let u = vec![0.0; model.nu];
    let e = accelerations(&model, &mut data, 0.0, &q, &u, &NoCallbacks).unwrap_err().to_string();
    assert!(e.contains("constraint 'skate'"), "{e}");
    // rows < 1 fails the build
    let mut d = model.description.clone();
    d.constraints = vec![ConstraintDescription::Velocity {
        name: "none".into(),
        rows: 0,
        w_matrix: 0,
        w_offset: None,
        w_rate: None,
    }];
    let e = Model::from_description(d).unwrap_err().to_string();
    assert!(e.contains("'none'.rows") && e.contains(">= 1"), "{e}");
}

#[test]
fn first_kinds_apply_forces_equal_g_transpose_lambda_on_the_planned_pattern() {
    check_apply_forces(&super::tests::model_with_all_kinds(), &NoCallbacks, 0.0);
}

/// The tree of [`model_with_new_kinds`] with its constraints replaced by contacts held closed
/// (the bilateral normal law), rolling or not, between moving bodies and against the ground, on
/// primitive and curved contours, at generic (not assembled) configurations.
fn model_with_held_contacts() -> Model {
    use crate::model::contact_description::{
        ContactDescription, ContourDescription, FrictionDescription, ImpactDescription, NormalDescription,
    };
    let base = model_with_new_kinds();
    let mut desc = base.description.clone();
    desc.constraints.clear();
    let held_as =
        |name: &str, b1: &str, c1: ContourDescription, b2: &str, c2: ContourDescription, rolling, hold_normal| {
            ContactDescription {
                name: name.into(),
                body1: b1.into(),
                contour1: c1,
                body2: b2.into(),
                contour2: c2,
                normal: NormalDescription::Bilateral { rolling, hold_normal },
                friction: FrictionDescription::None,
                impact: ImpactDescription::default(),
                points: None,
                material1: None,
                material2: None,
            }
        };
    let held = |name: &str, b1: &str, c1: ContourDescription, b2: &str, c2: ContourDescription, rolling| {
        held_as(name, b1, c1, b2, c2, rolling, true)
    };
    let sphere = |c: [f64; 3], r| ContourDescription::Sphere { center: c, radius: r };
    desc.contacts = vec![
        held(
            "ball_on_plate",
            "c",
            sphere([0.05, -0.02, 0.1], 0.2),
            "b",
            ContourDescription::Plane { point: [0.1, 0.0, -0.3], normal: [0.2, 0.1, 1.0], surface_velocity: None },
            true,
        ),
        held(
            "egg_on_ground",
            "disc",
            ContourDescription::Ellipsoid { center: [0.01, 0.02, 0.0], rotation: None, semi_axes: [0.3, 0.2, 0.15] },
            "ground",
            ContourDescription::Plane { point: [0.0; 3], normal: [0.0, 0.0, 1.0], surface_velocity: None },
            true,
        ),
        held("balls", "d", sphere([0.0, 0.1, 0.0], 0.1), "c", sphere([0.1, 0.0, 0.05], 0.15), false),
        // the tangents alone (another law of the pair carrying the normal)
        held_as("rolling_only", "d", sphere([0.02, -0.1, 0.03], 0.12), "b", sphere([0.0, 0.05, 0.1], 0.2), true, false),
    ];
    Model::from_description(desc).unwrap()
}

#[test]
fn held_contacts_have_their_row_counts() {
    let model = model_with_held_contacts();
    assert!(model.contacts.is_empty(), "held contacts are constraints");
    let rows: Vec<(usize, usize)> =
        model.constraints.iter().map(|c| (c.kind.rows(), c.kind.holonomic_rows())).collect();
    assert_eq!(rows, [(3, 1), (3, 1), (1, 1), (2, 0)]);
}

#[test]
fn held_contacts_velocity_rows_are_the_time_derivative_of_the_gap() {
    check_velocity_rows(&model_with_held_contacts(), &NoCallbacks, 0.2, 1e-8);
}

#[test]
fn held_contacts_acceleration_rows_are_the_derivative_of_the_velocity_rows() {
    check_acceleration_rows(&model_with_held_contacts(), &NoCallbacks, 0.3, 1e-7);
}

#[test]
fn held_contacts_apply_forces_equal_g_transpose_lambda() {
    check_apply_forces(&model_with_held_contacts(), &NoCallbacks, 0.0);
}
