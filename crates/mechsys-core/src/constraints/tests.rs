//! Constraint kinematics against finite differences, and the constrained dynamics against
//! closed-form mechanics.

use super::*;
use crate::data::Data;
use crate::forces::{Callbacks, NoCallbacks};
use crate::model::description::*;
use crate::model::Model;

pub(super) fn body(name: &str, m: f64, com: [f64; 3]) -> BodyDescription {
    BodyDescription {
        name: name.into(),
        mass: m,
        inertia: InertiaDescription::List(vec![0.01 * m, 0.02 * m, 0.025 * m]),
        com,
        markers: vec![],
        mass_rate: 0.0,
        ejection_velocity: [0.0; 3],
        ejection_point: None,
        mass_final: None,
        elastic: None,
    }
}

pub(super) fn joint(
    name: &str,
    kind: &str,
    parent: &str,
    child: &str,
    pos: [f64; 3],
    axis: Option<[f64; 3]>,
    q0: Option<Vec<f64>>,
) -> JointDescription {
    JointDescription {
        axis,
        parent_frame: FrameDescription { position: pos, rotation: None },
        q0,
        ..JointDescription::new(name, kind, parent, child)
    }
}

/// A spatial two-link arm with a free third body tied to its tip by a point and a distance
/// constraint, plus a coupler and a drive: every kind at once.
pub(super) fn model_with_all_kinds() -> Model {
    let desc = ModelDescription {
        name: "all".into(),
        gravity: [0.0, 0.0, -9.81],
        bodies: vec![
            body("a", 1.0, [0.2, 0.0, 0.0]),
            body("b", 0.5, [0.1, 0.0, 0.0]),
            body("c", 0.8, [0.0, 0.0, 0.0]),
            body("d", 0.3, [0.05, 0.0, 0.0]),
        ],
        joints: vec![
            joint("ja", "revolute", "ground", "a", [0.0; 3], Some([0.0, 0.0, 1.0]), Some(vec![0.3])),
            joint("jb", "revolute", "a", "b", [0.4, 0.0, 0.0], Some([0.0, 1.0, 0.0]), Some(vec![0.5])),
            joint("jc", "free", "ground", "c", [0.0; 3], None, Some(vec![0.5, 0.3, -0.1, 0.9, 0.1, 0.2, 0.3])),
            joint("jd", "revolute", "ground", "d", [1.0, 0.0, 0.0], Some([0.0, 0.0, 1.0]), Some(vec![0.1])),
        ],
        forces: vec![],
        ground_markers: vec![],
        contacts: vec![],
        contact_groups: vec![],
        gap_contacts: vec![],
        visuals: vec![],
        planar: false,
        constraints: vec![
            ConstraintDescription::Point {
                name: "pin".into(),
                body1: "b".into(),
                point1: [0.2, 0.0, 0.0],
                body2: "c".into(),
                point2: [0.1, 0.0, 0.0],
            },
            ConstraintDescription::Distance {
                name: "rod".into(),
                body1: "c".into(),
                point1: [-0.1, 0.05, 0.0],
                body2: "ground".into(),
                point2: [0.8, 0.2, 0.0],
                length: 0.35,
            },
            ConstraintDescription::Coupler {
                name: "gear".into(),
                joint1: "jd".into(),
                joint2: "ja".into(),
                ratio: -2.0,
                offset: 0.3,
            },
            ConstraintDescription::Prescribed {
                name: "drive".into(),
                joint: "jb".into(),
                index: 0,
                function: TimeFunctionDescription::Harmonic { amplitude: 0.4, omega: 3.0, phase: 0.2, offset: 0.5 },
            },
        ],
    };
    Model::from_description(desc).unwrap()
}

/// Per row: (finite-difference dΦ/dt along q ⊕ u s, G u - b) at (q, t).
pub(super) fn velocity_pairs(model: &Model, cb: &dyn Callbacks, q: &[f64], u: &[f64], t: f64) -> Vec<(f64, f64)> {
    let mut data = Data::new(model);
    crate::kinematics::positions(model, &mut data, q);
    positions(model, &mut data, t, q, cb).unwrap();
    let (g, b) = (data.g.clone(), data.b.clone());
    let h = 1e-6;
    let mut phi_at = |s: f64| {
        let mut qs = q.to_vec();
        model.integrate(q, u, s, &mut qs);
        crate::kinematics::positions(model, &mut data, &qs);
        positions(model, &mut data, t + s, &qs, cb).unwrap();
        data.phi.clone()
    };
    let (pp, pm) = (phi_at(h), phi_at(-h));
    (0..model.nc)
        .map(|r| ((pp[r] - pm[r]) / (2.0 * h), (0..model.nu).map(|i| g[(r, i)] * u[i]).sum::<f64>() - b[r]))
        .collect()
}

/// Per row: (finite-difference d(G u - b)/dt along q' = H*(q) u, u' = u̇, and G u̇ - γ) at (q, u, t).
pub(super) fn acceleration_pairs(
    model: &Model,
    cb: &dyn Callbacks,
    q: &[f64],
    u: &[f64],
    udot: &[f64],
    t: f64,
) -> Vec<(f64, f64)> {
    let mut data = Data::new(model);
    crate::kinematics::forward_kinematics(model, &mut data, q, u);
    positions(model, &mut data, t, q, cb).unwrap();
    data.a[0] = crate::spatial::Motion::ZERO;
    crate::kinematics::accelerations(model, &mut data, &vec![0.0; model.nu]);
    accelerations(model, &mut data, t, q, u, cb).unwrap();
    let (g, gamma) = (data.g.clone(), data.gamma.clone());
    let h = 1e-6;
    let mut residual_at = |s: f64| {
        let mut qs = q.to_vec();
        model.integrate(q, u, s, &mut qs);
        let us: Vec<f64> = u.iter().zip(udot).map(|(a, b)| a + b * s).collect();
        crate::kinematics::positions(model, &mut data, &qs);
        positions(model, &mut data, t + s, &qs, cb).unwrap();
        (0..model.nc)
            .map(|r| (0..model.nu).map(|i| data.g[(r, i)] * us[i]).sum::<f64>() - data.b[r])
            .collect::<Vec<f64>>()
    };
    let (rp, rm) = (residual_at(h), residual_at(-h));
    (0..model.nc)
        .map(|r| ((rp[r] - rm[r]) / (2.0 * h), (0..model.nu).map(|i| g[(r, i)] * udot[i]).sum::<f64>() - gamma[r]))
        .collect()
}

#[test]
fn velocity_rows_are_the_time_derivative_of_the_violation() {
    let model = model_with_all_kinds();
    assert_eq!(model.nc, 3 + 1 + 1 + 1);
    let u: Vec<f64> = (0..model.nu).map(|i| 0.3 - 0.07 * i as f64).collect();
    for (r, (fd, gu)) in velocity_pairs(&model, &NoCallbacks, &model.q0(), &u, 0.4).into_iter().enumerate() {
        assert!((fd - gu).abs() < 1e-7, "row {r}: dΦ/dt {fd} vs G u - b {gu}");
    }
}

#[test]
fn acceleration_rows_are_the_second_derivative_of_the_violation() {
    let model = model_with_all_kinds();
    let u: Vec<f64> = (0..model.nu).map(|i| 0.2 + 0.05 * i as f64).collect();
    let udot: Vec<f64> = (0..model.nu).map(|i| -0.4 + 0.1 * i as f64).collect();
    for (r, (fd, expected)) in
        acceleration_pairs(&model, &NoCallbacks, &model.q0(), &u, &udot, 0.3).into_iter().enumerate()
    {
        assert!((fd - expected).abs() < 1e-6, "row {r}: d(Gu - b)/dt {fd} vs G u̇ - γ {expected}");
    }
}

#[test]
fn constrained_accelerations_satisfy_the_constraints_and_dalembert() {
    let model = model_with_all_kinds();
    let (mut data, mut ws) = (Data::new(&model), crate::dynamics::Workspace::new(&model));
    let mut q = model.q0();
    let mut u: Vec<f64> = (0..model.nu).map(|i| 0.1 * (i as f64).sin()).collect();
    let t = 0.25;
    crate::dynamics::constrained::project(&model, &mut data, &mut ws, t, &mut q, &mut u, &NoCallbacks).unwrap();
    assert!(data.phi.iter().all(|v| v.abs() < 1e-12));
    crate::dynamics::forward_dynamics(&model, &mut data, &mut ws, t, &q, &u, None, &NoCallbacks).unwrap();
    let udot = data.udot.clone();
    let lambda = data.lambda.clone();
    // G u̇ = γ
    for r in 0..model.nc {
        let gu: f64 = (0..model.nu).map(|i| data.g[(r, i)] * udot[i]).sum();
        assert!((gu - data.gamma[r]).abs() < 1e-9, "row {r}: G u̇ {gu} vs γ {}", data.gamma[r]);
    }
    // M u̇ - h = Gᵀ λ (the multipliers are the generalized constraint forces)
    let g = data.g.clone();
    let mut tau = vec![0.0; model.nu];
    crate::dynamics::inverse_dynamics(&model, &mut data, &mut ws, t, &q, &u, &udot, &NoCallbacks, &mut tau).unwrap();
    for i in 0..model.nu {
        let gl: f64 = (0..model.nc).map(|r| g[(r, i)] * lambda[r]).sum();
        assert!((tau[i] - gl).abs() < 1e-9 * (1.0 + gl.abs()), "dof {i}: M u̇ - h = {} vs Gᵀλ = {gl}", tau[i]);
    }
}

/// A pendulum closed by a point constraint, run with each drift control: projection keeps the
/// violation at round-off, Baumgarte bounds it, none lets it grow.
#[test]
fn drift_control_choices() {
    use crate::integrator::IntegratorKind;
    use crate::simulate::{simulate, Settings, Stabilization};
    let desc = ModelDescription {
        name: "p".into(),
        gravity: [0.0, -9.81, 0.0],
        bodies: vec![body("b", 1.0, [0.0, 0.0, 0.0])],
        joints: vec![joint("f", "planar", "ground", "b", [0.0; 3], None, Some(vec![0.5, -0.5, 0.0]))],
        forces: vec![],
        ground_markers: vec![],
        contacts: vec![],
        contact_groups: vec![],
        gap_contacts: vec![],
        visuals: vec![],
        planar: false,
        constraints: vec![ConstraintDescription::Distance {
            name: "rod".into(),
            body1: "b".into(),
            point1: [0.0; 3],
            body2: "ground".into(),
            point2: [0.0; 3],
            length: 0.5f64.hypot(0.5),
        }],
    };
    let model = Model::from_description(desc).unwrap();
    let run = |s: Stabilization| {
        let settings = Settings {
            t0: 0.0,
            t_end: 5.0,
            output_dt: 0.01,
            integrator: IntegratorKind::Rk4 { dt: 0.01 },
            q0: None,
            u0: None,
            stabilization: s,
            on_singular: Default::default(),
            max_steps: None,
            max_wall: None,
            record: Default::default(),
            warm_search: true,
        };
        let rec = simulate(&model, &settings, &NoCallbacks, None).unwrap();
        rec.constraint_violation.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let (proj, baum, none) = (
        run(Stabilization::Projection),
        run(Stabilization::Baumgarte { alpha: 10.0, beta: 10.0 }),
        run(Stabilization::None),
    );
    assert!(proj < 1e-12, "projection {proj:e}");
    assert!(baum < none, "Baumgarte {baum:e} vs none {none:e}");
    assert!(none > 1e-9, "without control RK4 at dt = 0.01 drifts ({none:e})");
}
