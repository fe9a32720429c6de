//! Evaluating the dynamics of a model with an elastic body (deformed inertia, couplings in the
//! tree-sparse mass matrix, elastic forces, geometric stiffness) allocates nothing after the first
//! evaluation (a counting global allocator, per thread).

use mechsys_core::data::Data;
use mechsys_core::dynamics::{forward_dynamics, Workspace};
use mechsys_core::forces::NoCallbacks;
use mechsys_core::model::{Model, ModelDescription};

mod common;
use common::allocations;

#[global_allocator]
static A: common::Counting = common::Counting;

/// A flexible pendulum: a 1 m rod of 2 kg on a hinge, two bending shapes (x/L)² and (x/L)³ along
/// y, its invariants summed over 50 mass points, with damping and a geometric stiffness.
fn flexible_pendulum() -> Model {
    let (n, l, m) = (50usize, 1.0f64, 2.0f64);
    let xs: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) / n as f64 * l).collect();
    let mp = m / n as f64;
    let shapes = |k: usize, x: f64| (x / l).powi(k as i32 + 2);
    let mut s_t = vec![[0.0; 3]; 2];
    let mut p1 = vec![[0.0; 9]; 2];
    let mut p2 = vec![[0.0; 9]; 4];
    for &x in &xs {
        for k in 0..2 {
            s_t[k][1] += mp * shapes(k, x);
            // ∫ r0 Φ_kᵀ: r0 = (x, 0, 0), Φ_k = (0, φ, 0): entry (0, 1)
            p1[k][1] += mp * x * shapes(k, x);
            for j in 0..2 {
                // ∫ Φ_k Φ_jᵀ: entry (1, 1)
                p2[k * 2 + j][4] += mp * shapes(k, x) * shapes(j, x);
            }
        }
    }
    let json = format!(
        r#"{{
        "name": "flexible-pendulum",
        "gravity": [0.0, -9.81, 0.0],
        "bodies": [{{"name": "rod", "mass": {m}, "inertia": [0.0, {i}, {i}], "com": [0.5, 0.0, 0.0],
                    "elastic": {{"modes": 2, "s_t": {s_t:?}, "p1": {p1:?}, "p2": {p2:?},
                                 "stiffness": [[40.0, 5.0], [5.0, 90.0]], "damping": [[0.1, 0.0], [0.0, 0.2]],
                                 "geometric": [[[0.2, 0.0], [0.0, 0.3]], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]],
                                               [[0.1, 0.0], [0.0, 0.1]], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]],
                                               [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]],
                                               [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]],
                                 "q0": [0.01, -0.002]}}}}],
        "joints": [{{"name": "hinge", "type": "revolute", "parent": "ground", "child": "rod", "axis": [0.0, 0.0, 1.0],
                     "q0": [0.4], "u0": [1.0]}}]
    }}"#,
        i = m * l * l / 12.0
    );
    Model::from_description(ModelDescription::from_json(&json).unwrap()).unwrap()
}

#[test]
fn elastic_dynamics_does_not_allocate() {
    let model = flexible_pendulum();
    assert_eq!((model.nq, model.nu), (3, 3));
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    let (mut q, u) = (model.q0(), model.u0());
    forward_dynamics(&model, &mut data, &mut ws, 0.0, &q, &u, None, &NoCallbacks).unwrap();
    let before = allocations();
    for k in 0..200 {
        q[0] = 0.4 + 1e-3 * k as f64;
        q[1] = 0.01 * (k as f64 * 0.1).sin();
        forward_dynamics(&model, &mut data, &mut ws, 0.0, &q, &u, None, &NoCallbacks).unwrap();
    }
    let n = allocations() - before;
    assert_eq!(n, 0, "{n} allocations in 200 evaluations");
    assert!(data.udot.iter().all(|a| a.is_finite()) && data.udot[1].abs() > 0.0);
}
