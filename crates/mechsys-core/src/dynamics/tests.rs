//! Dynamics identities: CRBA, RNEA and ABA agree with each other and with the kinetic energy.

use nalgebra::{DMatrix, DVector};

use super::*;
use crate::data::Data;
use crate::forces::NoCallbacks;
use crate::model::description::*;
use crate::model::Model;

/// A branched tree with every joint type, gravity and a spring-damper.
fn mixed_tree() -> Model {
    let body = |name: &str, m: f64, com: [f64; 3]| BodyDescription {
        name: name.into(),
        mass: m,
        inertia: InertiaDescription::List(vec![0.02 * m, 0.03 * m, 0.04 * m, 0.001, -0.002, 0.0015]),
        com,
        markers: vec![],
        mass_rate: 0.0,
        ejection_velocity: [0.0; 3],
        ejection_point: None,
        mass_final: None,
        elastic: None,
    };
    let joint =
        |name: &str, kind: &str, parent: &str, child: &str, pos: [f64; 3], axis: Option<[f64; 3]>| JointDescription {
            axis,
            parent_frame: FrameDescription {
                position: pos,
                rotation: Some(RotationDescription::Angles(AnglesDescription {
                    cardan: Some([0.1, -0.2, 0.3]),
                    euler: None,
                    rotvec: None,
                })),
            },
            child_frame: FrameDescription { position: [-0.05, 0.02, 0.01], rotation: None },
            ..JointDescription::new(name, kind, parent, child)
        };
    let names = ["free", "rev", "pri", "uni", "sph", "pla", "cyl", "rev2"];
    let mut bodies = vec![];
    for (k, n) in names.iter().enumerate() {
        bodies.push(body(&format!("b_{n}"), 1.0 + 0.3 * k as f64, [0.1, 0.02 * k as f64, -0.03]));
    }
    let joints = vec![
        joint("free", "free", "ground", "b_free", [0.0, 0.0, 1.0], None),
        joint("rev", "revolute", "b_free", "b_rev", [0.3, 0.0, 0.0], Some([0.0, 0.6, 0.8])),
        joint("pri", "prismatic", "b_rev", "b_pri", [0.2, 0.1, 0.0], Some([1.0, 0.0, 0.0])),
        joint("uni", "universal", "b_free", "b_uni", [-0.3, 0.0, 0.0], None),
        joint("sph", "spherical", "b_uni", "b_sph", [0.0, 0.2, 0.0], None),
        joint("pla", "planar", "b_sph", "b_pla", [0.1, 0.1, 0.1], None),
        joint("cyl", "cylindrical", "b_rev", "b_cyl", [0.0, 0.0, 0.2], Some([0.0, 0.0, 1.0])),
        joint("rev2", "revolute", "b_cyl", "b_rev2", [0.1, 0.0, 0.0], Some([1.0, 0.0, 0.0])),
    ];
    let forces = vec![ForceDescription::SpringDamper {
        name: "sd".into(),
        body1: "b_pla".into(),
        point1: [0.1, 0.0, 0.0],
        body2: "b_rev2".into(),
        point2: [0.0, 0.1, 0.0],
        k: 30.0,
        k3: 5.0,
        d: 0.7,
        l0: 0.1,
        table_deflection: None,
        table_force: None,
        travel: None,
    }];
    Model::from_description(ModelDescription {
        name: "mixed".into(),
        gravity: [0.3, -9.81, 0.5],
        bodies,
        joints,
        forces,
        ground_markers: vec![],
        contacts: vec![],
        contact_groups: vec![],
        gap_contacts: vec![],
        visuals: vec![],
        planar: false,
        constraints: vec![],
    })
    .unwrap()
}

fn state(model: &Model, seed: f64) -> (Vec<f64>, Vec<f64>) {
    let mut q = model.neutral();
    let du: Vec<f64> = (0..model.nu).map(|i| ((i as f64 + 1.0) * 1.37 + seed).sin()).collect();
    let q0 = q.clone();
    model.integrate(&q0, &du, 0.8, &mut q);
    let u: Vec<f64> = (0..model.nu).map(|i| ((i as f64 + 2.0) * 0.71 - seed).cos()).collect();
    (q, u)
}

#[test]
fn aba_equals_mass_matrix_solve() {
    let model = mixed_tree();
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    for seed in [0.0, 1.0, 2.5] {
        let (q, u) = state(&model, seed);
        let tau: Vec<f64> = (0..model.nu).map(|i| 0.5 * (i as f64 * 0.3 + seed).sin()).collect();
        aba(&model, &mut data, &mut ws, 0.0, &q, &u, Some(&tau), &NoCallbacks).unwrap();
        let udot = DVector::from_column_slice(&data.udot);
        nonlinear_effects(&model, &mut data, &mut ws, 0.0, &q, &u, &NoCallbacks).unwrap();
        let h = data.h.clone();
        crba::mass_matrix(&model, &mut data, 0.0, &q);
        let m = data.mass_matrix.clone();
        assert!((&m - m.transpose()).norm() < 1e-12 * m.norm());
        assert!(m.clone().cholesky().is_some(), "M positive definite");
        let expected = m.lu().solve(&(h + DVector::from_column_slice(&tau))).unwrap();
        let rel = (&udot - &expected).norm() / expected.norm();
        assert!(rel < 1e-12, "seed {seed}: ABA vs M⁻¹(h+τ): {rel:e}");
    }
}

#[test]
fn inverse_of_forward_dynamics_gives_tau_back() {
    let model = mixed_tree();
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    let (q, u) = state(&model, 0.7);
    let tau: Vec<f64> = (0..model.nu).map(|i| (i as f64 - 3.0) * 0.4).collect();
    aba(&model, &mut data, &mut ws, 0.0, &q, &u, Some(&tau), &NoCallbacks).unwrap();
    let udot = data.udot.clone();
    let mut back = vec![0.0; model.nu];
    inverse_dynamics(&model, &mut data, &mut ws, 0.0, &q, &u, &udot, &NoCallbacks, &mut back).unwrap();
    for i in 0..model.nu {
        assert!((back[i] - tau[i]).abs() < 1e-10, "τ[{i}]: {} vs {}", back[i], tau[i]);
    }
}

#[test]
fn mass_matrix_is_hessian_of_kinetic_energy() {
    let model = mixed_tree();
    let mut data = Data::new(&model);
    let (q, u) = state(&model, 1.3);
    crba::mass_matrix(&model, &mut data, 0.0, &q);
    let m = data.mass_matrix.clone();
    let t_of = |data: &mut Data, u: &[f64]| {
        crate::kinematics::forward_kinematics(&model, data, &q, u);
        crate::kinematics::inertias(&model, data, 0.0);
        energy::kinetic_energy(&model, data)
    };
    // T is exactly quadratic in u: ½ uᵀ M u
    let uv = DVector::from_column_slice(&u);
    let t = t_of(&mut data, &u);
    assert!((t - 0.5 * uv.dot(&(&m * &uv))).abs() < 1e-12 * t.abs().max(1.0));
    // and its second differences in u are the entries of M
    let n = model.nu;
    let mut hess = DMatrix::zeros(n, n);
    let e = 0.5;
    for i in 0..n {
        for j in 0..n {
            let mut upp = vec![0.0; n];
            let mut upm = vec![0.0; n];
            let mut ump = vec![0.0; n];
            let mut umm = vec![0.0; n];
            upp[i] += e;
            upp[j] += e;
            upm[i] += e;
            upm[j] -= e;
            ump[i] -= e;
            ump[j] += e;
            umm[i] -= e;
            umm[j] -= e;
            hess[(i, j)] = (t_of(&mut data, &upp) - t_of(&mut data, &upm) - t_of(&mut data, &ump)
                + t_of(&mut data, &umm))
                / (4.0 * e * e);
        }
    }
    assert!((&hess - &m).norm() < 1e-10 * m.norm(), "{}", (&hess - &m).norm());
}

/// Energy is conserved along the free motion: dT/dt + dV/dt = -P_diss, checked by finite differences
/// of T + V along the ABA flow.
#[test]
fn power_balance_along_the_flow() {
    let model = mixed_tree();
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    let (q, u) = state(&model, 0.2);
    let p = forward_dynamics(&model, &mut data, &mut ws, 0.0, &q, &u, None, &NoCallbacks).unwrap();
    let udot = data.udot.clone();
    let energy_at = |data: &mut Data, s: f64| {
        let mut qs = q.clone();
        let mut qd = vec![0.0; model.nq];
        model.qdot(&q, &u, &mut qd);
        // second-order path: q(s) = q ⊕ (u s + ½ u̇ s²) on the manifold
        let du: Vec<f64> = u.iter().zip(&udot).map(|(a, b)| a * s + 0.5 * b * s * s).collect();
        model.integrate(&q, &du, 1.0, &mut qs);
        let us: Vec<f64> = u.iter().zip(&udot).map(|(a, b)| a + b * s).collect();
        crate::kinematics::forward_kinematics(&model, data, &qs, &us);
        crate::kinematics::inertias(&model, data, 0.0);
        energy::kinetic_energy(&model, data) + energy::potential_energy(&model, data, &qs)
    };
    let h = 1e-5;
    let de = (energy_at(&mut data, h) - energy_at(&mut data, -h)) / (2.0 * h);
    assert!((de + p.dissipated - p.external).abs() < 1e-6, "dE/dt {de} vs -P_diss {}", -p.dissipated);
    assert!(p.dissipated > 0.0);
}
