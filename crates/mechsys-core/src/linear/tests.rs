//! Linearization against closed forms: a spring–mass chain, pendulums upright and hanging, the
//! same pendulum held by a constraint, a damper, and finite-difference consistency.

use super::linearize;
use crate::forces::NoCallbacks;
use crate::model::{Model, ModelDescription};
use nalgebra::DMatrix;

fn model(json: &str) -> Model {
    Model::from_description(ModelDescription::from_json(json).unwrap()).unwrap()
}

fn mat(v: &[f64], n: usize) -> DMatrix<f64> {
    DMatrix::from_row_slice(n, n, v)
}

/// Squared undamped natural frequencies: eigenvalues of M⁻¹ K (M, K symmetric, M > 0).
fn omega2(m: &DMatrix<f64>, k: &DMatrix<f64>) -> Vec<f64> {
    let l = m.clone().cholesky().unwrap().l();
    let li = l.try_inverse().unwrap();
    let a = &li * k * li.transpose();
    let mut w: Vec<f64> = a.symmetric_eigen().eigenvalues.iter().copied().collect();
    w.sort_by(|a, b| a.partial_cmp(b).unwrap());
    w
}

/// Three masses on a line between two walls, four equal springs.
fn chain(m: f64, k: f64, d: f64) -> Model {
    let body = |i: usize| format!(r#"{{"name": "m{i}", "mass": {m}, "inertia": [1e-3, 1e-3, 1e-3]}}"#);
    let joint = |i: usize| {
        format!(
            r#"{{"name": "x{i}", "type": "prismatic", "parent": "ground", "child": "m{i}", "axis": [1, 0, 0],
                 "parent_frame": {{"position": [{}, 0, 0]}}}}"#,
            i + 1
        )
    };
    let spring = |a: &str, pa: f64, b: &str| {
        format!(
            r#"{{"type": "spring_damper", "name": "{a}_{b}", "body1": "{a}", "point1": [{pa}, 0, 0], "body2": "{b}", "k": {k}, "d": {d}, "l0": 1.0}}"#
        )
    };
    let forces = [spring("ground", 0.0, "m0"), spring("m0", 0.0, "m1"), spring("m1", 0.0, "m2"), spring("m2", 0.0, "ground")];
    // the last spring runs from m2 to the wall at x = 4: swap its ends' roles through point1
    let forces = [forces[0].clone(), forces[1].clone(), forces[2].clone(), forces[3].replace(r#""body2": "ground""#, r#""body2": "ground", "point2": [4, 0, 0]"#)];
    model(&format!(
        r#"{{"name": "chain", "gravity": [0, 0, 0], "bodies": [{}], "joints": [{}], "forces": [{}]}}"#,
        (0..3).map(body).collect::<Vec<_>>().join(","),
        (0..3).map(joint).collect::<Vec<_>>().join(","),
        forces.join(",")
    ))
}

#[test]
fn spring_mass_chain_frequencies_match_the_closed_form() {
    // ω_j² = (k/m)(2 − 2 cos(jπ/4)), j = 1, 2, 3
    let (m, k) = (2.0, 300.0);
    let model = chain(m, k, 0.0);
    let lin = linearize(&model, 0.0, &model.q0(), &model.u0(), &NoCallbacks).unwrap();
    assert_eq!(lin.n, 3);
    let w2 = omega2(&mat(&lin.m, 3), &mat(&lin.k, 3));
    for (j, w) in w2.iter().enumerate() {
        let exact = k / m * (2.0 - 2.0 * (std::f64::consts::PI * (j + 1) as f64 / 4.0).cos());
        assert!((w - exact).abs() < 1e-10 * exact, "mode {j}: {w} vs {exact}");
    }
    assert!(lin.residual.iter().all(|r| r.abs() < 1e-12), "{:?}", lin.residual);
    assert!(lin.g.iter().chain(&lin.n_mat).chain(&lin.d).all(|x| x.abs() < 1e-9));
}

#[test]
fn dampers_give_the_damping_matrix() {
    // the same chain with dampers d: D has the same pattern as K, scaled by d / k
    let (k, d) = (300.0, 3.0);
    let model = chain(2.0, k, d);
    let lin = linearize(&model, 0.0, &model.q0(), &model.u0(), &NoCallbacks).unwrap();
    for (a, b) in lin.d.iter().zip(&lin.k) {
        assert!((a - b * d / k).abs() < 1e-8, "{a} vs {}", b * d / k);
    }
}

fn pendulum(theta: f64, constrained: bool) -> (Model, Vec<f64>) {
    // a point-like bob of 1.5 kg on a 0.8 m massless rod, gravity −y
    let json = if constrained {
        format!(
            r#"{{"name": "p", "gravity": [0, -9.81, 0],
            "bodies": [{{"name": "bob", "mass": 1.5, "inertia": [1e-9, 1e-9, 1e-9]}}],
            "joints": [{{"name": "xy", "type": "planar", "parent": "ground", "child": "bob",
                         "q0": [{}, {}, 0]}}],
            "constraints": [{{"name": "rod", "type": "distance", "body1": "ground", "body2": "bob", "length": 0.8}}]}}"#,
            0.8 * theta.sin(),
            -0.8 * theta.cos()
        )
    } else {
        format!(
            r#"{{"name": "p", "gravity": [0, -9.81, 0],
            "bodies": [{{"name": "bob", "mass": 1.5, "inertia": [1e-9, 1e-9, 1e-9]}}],
            "joints": [{{"name": "pin", "type": "revolute", "parent": "ground", "child": "bob", "axis": [0, 0, 1],
                         "child_frame": {{"position": [0, 0.8, 0]}}, "q0": [{theta}]}}]}}"#
        )
    };
    let m = model(&json);
    let q = m.q0();
    (m, q)
}

#[test]
fn pendulum_frequency_and_the_inverted_one_unstable() {
    let (m, q) = pendulum(0.0, false);
    let lin = linearize(&m, 0.0, &q, &m.u0(), &NoCallbacks).unwrap();
    let w2 = lin.k[0] / lin.m[0];
    assert!((w2 - 9.81 / 0.8).abs() < 1e-8 * 9.81 / 0.8, "{w2}");
    let (m, q) = pendulum(std::f64::consts::PI, false);
    let lin = linearize(&m, 0.0, &q, &m.u0(), &NoCallbacks).unwrap();
    assert!((lin.k[0] / lin.m[0] + 9.81 / 0.8).abs() < 1e-7, "{}", lin.k[0] / lin.m[0]);
    // off equilibrium: the residual is the gravity moment m g l sin θ
    let (m, q) = pendulum(0.3, false);
    let lin = linearize(&m, 0.0, &q, &m.u0(), &NoCallbacks).unwrap();
    assert!((lin.residual[0].abs() - 1.5 * 9.81 * 0.8 * 0.3f64.sin()).abs() < 1e-9);
}

#[test]
fn constrained_pendulum_has_one_degree_of_freedom_and_the_same_frequency() {
    // planar body (3 velocities) held by a distance constraint: V spans the swing and the free
    // spin of the bob; the swing has ω² = g / l (the reaction's geometric stiffness included)
    let (m, q) = pendulum(0.0, true);
    let lin = linearize(&m, 0.0, &q, &m.u0(), &NoCallbacks).unwrap();
    assert_eq!(lin.n, 2);
    let w2 = omega2(&mat(&lin.m, 2), &mat(&lin.k, 2));
    let swing = w2.iter().copied().fold(0.0f64, f64::max);
    assert!((swing - 9.81 / 0.8).abs() < 1e-7 * 9.81 / 0.8, "{w2:?}");
    assert!(w2[0].abs() < 1e-6, "the spin has no stiffness: {w2:?}");
}

#[test]
fn bad_points_name_the_item() {
    let (m, q) = pendulum(0.0, false);
    let e = linearize(&m, 0.0, &q[..0], &m.u0(), &NoCallbacks).unwrap_err().to_string();
    assert!(e.contains("q has 0 entries"), "{e}");
    let e = linearize(&m, 0.0, &q, &[f64::NAN], &NoCallbacks).unwrap_err().to_string();
    assert!(e.contains("u[0]"), "{e}");
}
