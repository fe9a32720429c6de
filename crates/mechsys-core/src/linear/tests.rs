//! Linearization against closed forms: a spring–mass chain, pendulums upright and hanging, the
//! same pendulum held by a constraint, a damper, and finite-difference consistency; the exact
//! (dual-number) derivatives against central differences and closed forms.

use super::{linearize, linearize_with, DerivativeMethod, Derivatives, Linearization};
use crate::forces::{Callbacks, NoCallbacks};
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
    let forces =
        [spring("ground", 0.0, "m0"), spring("m0", 0.0, "m1"), spring("m1", 0.0, "m2"), spring("m2", 0.0, "ground")];
    // the last spring runs from m2 to the wall at x = 4: swap its ends' roles through point1
    let forces = [
        forces[0].clone(),
        forces[1].clone(),
        forces[2].clone(),
        forces[3].replace(r#""body2": "ground""#, r#""body2": "ground", "point2": [4, 0, 0]"#),
    ];
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

// ---------------------------------------------------------------------------------------------
// Exact derivatives (module `ad`) against central differences and closed forms
// ---------------------------------------------------------------------------------------------

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Relative differences of M, D, G, K, N and the residual between two linearizations. D and G
/// are measured against the size of C = D + G, K and N against that of S = K + N (an entry that
/// should be zero is judged on the scale of its matrix), the residual against |M|·1 m/s² at least.
fn differences(a: &Linearization, b: &Linearization) -> [f64; 6] {
    assert_eq!(a.n, b.n);
    let floor = 1e-9 * (max_abs(&b.m) + max_abs(&b.k));
    let sc = max_abs(&b.d).max(max_abs(&b.g)).max(floor);
    let ss = max_abs(&b.k).max(max_abs(&b.n_mat)).max(floor);
    let sr = max_abs(&b.residual).max(max_abs(&b.m));
    [
        max_diff(&a.m, &b.m) / max_abs(&b.m),
        max_diff(&a.d, &b.d) / sc,
        max_diff(&a.g, &b.g) / sc,
        max_diff(&a.k, &b.k) / ss,
        max_diff(&a.n_mat, &b.n_mat) / ss,
        max_diff(&a.residual, &b.residual) / sr,
    ]
}

/// Exact and central-difference linearizations at one point; asserts that they agree to `tol`
/// (relative, see [`differences`]) and that the exact one says so.
fn exact_vs_fd(
    what: &str,
    model: &Model,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    tol: f64,
) -> (Linearization, Linearization) {
    let ex = linearize_with(model, t, q, u, cb, Derivatives::Exact).unwrap();
    let fd = linearize_with(model, t, q, u, cb, Derivatives::CentralDifferences).unwrap();
    let want = if model.nc > 0 { DerivativeMethod::ExactWithDifferencedConstraints } else { DerivativeMethod::Exact };
    assert_eq!(ex.method, want);
    assert_eq!(fd.method, DerivativeMethod::CentralDifferences);
    let e = differences(&ex, &fd);
    eprintln!(
        "{what}: exact vs fd relative differences M {:.1e} D {:.1e} G {:.1e} K {:.1e} N {:.1e} residual {:.1e}",
        e[0], e[1], e[2], e[3], e[4], e[5]
    );
    for (name, x) in ["M", "D", "G", "K", "N", "residual"].iter().zip(e) {
        assert!(x < tol, "{what}: {name} differs by {x:.3e} (relative) between exact and central differences");
    }
    (ex, fd)
}

#[test]
fn exact_spring_chain_matches_differences_and_the_closed_form() {
    // linear springs on prismatic joints: both methods are exact, off the rest position and moving
    let (m, k, d) = (2.0, 300.0, 3.0);
    let model = chain(m, k, d);
    let q: Vec<f64> = model.q0().iter().enumerate().map(|(i, x)| x + 0.05 * (i as f64 - 1.0)).collect();
    let u = [0.3, -0.2, 0.5];
    let (ex, _) = exact_vs_fd("spring chain", &model, 0.0, &q, &u, &NoCallbacks, 1e-9);
    // K = k tridiag(-1, 2, -1), D = (d / k) K
    for r in 0..3 {
        for c in 0..3 {
            let kk = match (r as i32 - c as i32).abs() {
                0 => 2.0 * k,
                1 => -k,
                _ => 0.0,
            };
            assert!((ex.k[r * 3 + c] - kk).abs() < 1e-12 * k, "K[{r}{c}] = {}", ex.k[r * 3 + c]);
            assert!((ex.d[r * 3 + c] - kk * d / k).abs() < 1e-12 * k, "D[{r}{c}] = {}", ex.d[r * 3 + c]);
        }
    }
    assert!(max_abs(&ex.g) == 0.0 && max_abs(&ex.n_mat) < 1e-12 * k);
}

/// A spatial double pendulum: a spherical joint at the ground, a revolute joint (with spring and
/// damper) between the links, off-principal inertias and offsets.
fn spatial_double_pendulum() -> Model {
    model(
        r#"{"name": "dp", "gravity": [0, 0, -9.81],
        "bodies": [
            {"name": "a", "mass": 1.2, "com": [0.25, 0.02, -0.01], "inertia": [[0.02, 0.001, -0.002], [0.001, 0.05, 0.003], [-0.002, 0.003, 0.06]]},
            {"name": "b", "mass": 0.7, "com": [0.2, -0.03, 0.01], "inertia": [0.01, 0.03, 0.035]}],
        "joints": [
            {"name": "ball", "type": "spherical", "parent": "ground", "child": "a",
             "parent_frame": {"position": [0.1, 0, 0.5], "rotation": {"cardan": [0.2, -0.1, 0.3]}},
             "q0": [0.9, 0.2, -0.3, 0.25]},
            {"name": "hinge", "type": "revolute", "parent": "a", "child": "b", "axis": [0, 0.6, 0.8],
             "parent_frame": {"position": [0.5, 0, 0]}, "child_frame": {"position": [-0.05, 0.01, 0]},
             "q0": [0.7], "spring": {"k": [4.0], "q_free": [0.2]}, "damper": {"d": [0.3]}}]}"#,
    )
}

#[test]
fn exact_spatial_double_pendulum_with_a_quaternion_joint_matches_differences() {
    let model = spatial_double_pendulum();
    let mut q = model.q0();
    model.normalize(&mut q);
    let u = [0.8, -1.1, 0.6, 1.7];
    let (ex, _) = exact_vs_fd("spatial double pendulum", &model, 0.0, &q, &u, &NoCallbacks, 1e-7);
    // off equilibrium and moving: every matrix is populated
    for (name, m) in [("D", &ex.d), ("G", &ex.g), ("K", &ex.k), ("N", &ex.n_mat), ("residual", &ex.residual)] {
        assert!(max_abs(m) > 1e-3, "{name} is zero");
    }
}

#[test]
fn exact_sleeping_top_has_the_closed_form_gyroscopic_and_stiffness_matrices() {
    // a symmetric top on a ball joint, spinning upright at Ω: I_pivot = diag(a + m l², same, c);
    // Euler's equations about the pivot linearize to G = Ω (c − a') [[0, 1, 0], [−1, 0, 0], 0],
    // K = −m g l diag(1, 1, 0) (upright: unstable without the spin), D = N = 0
    let (m, l, a, c, g, om) = (2.0, 0.3, 0.04, 0.07, 9.81, 25.0);
    let model = model(&format!(
        r#"{{"name": "top", "gravity": [0, 0, -{g}],
        "bodies": [{{"name": "top", "mass": {m}, "com": [0, 0, {l}], "inertia": [{a}, {a}, {c}]}}],
        "joints": [{{"name": "ball", "type": "spherical", "parent": "ground", "child": "top"}}]}}"#
    ));
    let q = model.q0();
    let u = [0.0, 0.0, om];
    let (ex, _) = exact_vs_fd("sleeping top", &model, 0.0, &q, &u, &NoCallbacks, 1e-8);
    let a1 = a + m * l * l;
    let g01 = om * (c - a1);
    assert!((ex.g[1] - g01).abs() < 1e-13 * g01.abs(), "G01 = {} vs {g01}", ex.g[1]);
    assert!((ex.g[3] + g01).abs() < 1e-13 * g01.abs());
    for (i, kk) in [(0, -m * g * l), (4, -m * g * l), (8, 0.0)] {
        assert!((ex.k[i] - kk).abs() < 1e-13 * m * g * l, "K[{i}] = {} vs {kk}", ex.k[i]);
    }
    assert!(max_abs(&ex.d) < 1e-13 * g01.abs() && max_abs(&ex.n_mat) < 1e-13 * m * g * l);
    assert!(max_abs(&ex.residual) < 1e-13);
}

/// A planar body tied to the ground by a spring–damper with linear, cubic and tabulated terms,
/// loaded by a body-frame force and a joint force.
fn nonlinear_spring_model() -> Model {
    model(
        r#"{"name": "sd", "gravity": [0, -9.81, 0],
        "bodies": [{"name": "box", "mass": 1.3, "com": [0.02, 0.01, 0], "inertia": [0.01, 0.02, 0.025]}],
        "joints": [{"name": "plane", "type": "planar", "parent": "ground", "child": "box",
                    "q0": [0.35, -0.6, 0.4]}],
        "forces": [
            {"type": "spring_damper", "name": "mount", "body1": "ground", "point1": [0.1, 0.2, 0],
             "body2": "box", "point2": [0.05, 0.08, 0], "k": 150.0, "k3": 900.0, "d": 2.5, "l0": 0.6,
             "table_deflection": [-0.5, -0.1, 0.0, 0.1, 0.3, 0.8], "table_force": [-40, -9, 0, 12, 55, 70]},
            {"type": "body_force", "name": "push", "body": "box", "point": [0.1, -0.05, 0],
             "force": [3.0, 1.0, 0], "torque": [0, 0, 0.4], "frame": "body",
             "function": {"type": "harmonic", "amplitude": 2.0, "omega": 3.0, "phase": 0.2, "offset": 1.0}},
            {"type": "joint_force", "name": "drive", "joint": "plane", "value": [0.5, -0.2, 0.1]}]}"#,
    )
}

#[test]
fn exact_spring_damper_with_cubic_and_table_terms_matches_differences() {
    let model = nonlinear_spring_model();
    let q = model.q0();
    let u = [0.4, -0.3, 1.2];
    // the deflection lies inside a table segment, where the table force is smooth
    let l = ((0.35f64 + 0.05 * 0.4f64.cos() - 0.08 * 0.4f64.sin() - 0.1).powi(2)
        + (-0.6f64 + 0.05 * 0.4f64.sin() + 0.08 * 0.4f64.cos() - 0.2).powi(2))
    .sqrt();
    let delta = l - 0.6;
    assert!([-0.5, -0.1, 0.0, 0.1, 0.3, 0.8].iter().all(|x: &f64| (x - delta).abs() > 1e-3), "δ = {delta}");
    let (ex, _) = exact_vs_fd("spring-damper with cubic and table terms", &model, 0.7, &q, &u, &NoCallbacks, 1e-7);
    assert!(max_abs(&ex.d) > 1.0 && max_abs(&ex.k) > 100.0);
}

#[test]
fn exact_four_bar_with_a_loop_constraint_matches_differences() {
    // crank (0.3) – coupler (0.8) – rocker (0.6) between ground pivots 1 m apart, the rocker's tip
    // pinned to the ground by a point constraint; gravity −y, off equilibrium and moving
    let th1 = 1.1f64;
    let a = (0.3 * th1.cos(), 0.3 * th1.sin());
    let dpt = (1.0, 0.0);
    // B on the circles |B − A| = 0.8, |B − D| = 0.6 (the upper intersection)
    let (dx, dy) = (dpt.0 - a.0, dpt.1 - a.1);
    let dist = (dx * dx + dy * dy).sqrt();
    let along = (0.8 * 0.8 - 0.6 * 0.6 + dist * dist) / (2.0 * dist);
    let h = (0.8 * 0.8 - along * along).sqrt();
    let b = (a.0 + along * dx / dist - h * dy / dist, a.1 + along * dy / dist + h * dx / dist);
    let phi2 = (b.1 - a.1).atan2(b.0 - a.0);
    let phi3 = (dpt.1 - b.1).atan2(dpt.0 - b.0);
    let body = |n: &str, l: f64| {
        format!(
            r#"{{"name": "{n}", "mass": {}, "com": [{}, 0, 0], "inertia": [1e-3, {}, {}]}}"#,
            2.0 * l,
            0.5 * l,
            l * l / 6.0,
            l * l / 6.0
        )
    };
    let json = format!(
        r#"{{"name": "fourbar", "gravity": [0, -9.81, 0],
        "bodies": [{}, {}, {}],
        "joints": [
            {{"name": "j1", "type": "revolute", "parent": "ground", "child": "crank", "q0": [{th1}]}},
            {{"name": "j2", "type": "revolute", "parent": "crank", "child": "coupler", "parent_frame": {{"position": [0.3, 0, 0]}}, "q0": [{}]}},
            {{"name": "j3", "type": "revolute", "parent": "coupler", "child": "rocker", "parent_frame": {{"position": [0.8, 0, 0]}}, "q0": [{}]}}],
        "constraints": [{{"type": "point", "name": "closure", "body1": "rocker", "point1": [0.6, 0, 0], "body2": "ground", "point2": [1, 0, 0]}}]}}"#,
        body("crank", 0.3),
        body("coupler", 0.8),
        body("rocker", 0.6),
        phi2 - th1,
        phi3 - phi2
    );
    let model = model(&json);
    let q = model.q0();
    let at_rest = linearize_with(&model, 0.0, &q, &model.u0(), &NoCallbacks, Derivatives::CentralDifferences).unwrap();
    assert_eq!(at_rest.n, 1, "a four-bar has one degree of freedom");
    let u: Vec<f64> = (0..3).map(|i| 1.5 * at_rest.v[i]).collect();
    let (ex, fd) = exact_vs_fd("four-bar (point loop constraint)", &model, 0.0, &q, &u, &NoCallbacks, 1e-6);
    assert!(max_abs(&ex.k) > 0.1 && max_abs(&ex.d) > 0.01, "K {:?} D {:?}", ex.k, ex.d);
    // Auto takes the exact path here too
    let auto = linearize(&model, 0.0, &q, &u, &NoCallbacks).unwrap();
    assert_eq!(auto.method, DerivativeMethod::ExactWithDifferencedConstraints);
    assert_eq!(auto.k, ex.k);
    let _ = fd;
}

#[test]
fn exact_pendulum_stiffness_is_exact_where_differences_are_not() {
    // K = m g l cos θ off equilibrium: exact to round-off, while the central differences carry
    // their truncation error h²/6 ≈ 1.7e-11 (sin θ differenced with h = 1e-5)
    let th = 0.3f64;
    let (m, q) = pendulum(th, false);
    let exact_k = 1.5 * 9.81 * 0.8 * th.cos();
    let ex = linearize_with(&m, 0.0, &q, &[0.7], &NoCallbacks, Derivatives::Exact).unwrap();
    let fd = linearize_with(&m, 0.0, &q, &[0.7], &NoCallbacks, Derivatives::CentralDifferences).unwrap();
    let (e_ex, e_fd) = ((ex.k[0] - exact_k).abs() / exact_k, (fd.k[0] - exact_k).abs() / exact_k);
    eprintln!("pendulum K = m g l cos θ: exact {e_ex:.1e}, central differences {e_fd:.1e} (relative)");
    assert!(e_ex < 1e-14, "exact: {e_ex:.3e}");
    assert!(e_fd > 1e-12, "the differences were expected to show their truncation error: {e_fd:.3e}");
    assert_eq!((ex.d[0], ex.g[0]), (0.0, 0.0));
}

/// Every joint type in one chain, with a variable-mass body and every covered force element.
fn zoo() -> Model {
    model(
        r#"{"name": "zoo", "gravity": [0.3, -9.81, 0.5],
        "bodies": [
            {"name": "b1", "mass": 1.0, "com": [0.1, 0.0, 0.05], "inertia": [0.01, 0.02, 0.03]},
            {"name": "b2", "mass": 0.8, "com": [0.0, 0.1, 0.0], "inertia": [0.02, 0.02, 0.01]},
            {"name": "b3", "mass": 0.6, "com": [0.05, 0.05, 0.0], "inertia": [[0.01, 0.001, 0], [0.001, 0.02, 0], [0, 0, 0.02]]},
            {"name": "b4", "mass": 0.9, "com": [0.1, -0.02, 0.03], "inertia": [0.015, 0.01, 0.02],
             "mass_rate": -0.2, "ejection_velocity": [-50, 3, 0], "ejection_point": [-0.1, 0, 0], "mass_final": 0.3},
            {"name": "b5", "mass": 0.5, "com": [0.1, 0.0, 0.0], "inertia": [0.005, 0.01, 0.012]},
            {"name": "b6", "mass": 0.4, "com": [0.0, 0.0, 0.02], "inertia": [0.004, 0.006, 0.008]},
            {"name": "b7", "mass": 0.7, "com": [0.02, 0.01, -0.01], "inertia": [0.01, 0.012, 0.009]},
            {"name": "b8", "mass": 0.3, "com": [0.05, 0.0, 0.0], "inertia": [0.002, 0.003, 0.003]}],
        "joints": [
            {"name": "rev", "type": "revolute", "parent": "ground", "child": "b1", "axis": [0, 0.6, 0.8], "q0": [0.4],
             "spring": {"k": [3.0]}, "damper": {"d": [0.2]}},
            {"name": "pri", "type": "prismatic", "parent": "b1", "child": "b2", "axis": [0.8, 0, 0.6],
             "parent_frame": {"position": [0.2, 0, 0], "rotation": {"cardan": [0.1, 0.2, -0.3]}}, "q0": [0.15],
             "spring": {"k": [40.0], "q_free": [0.1]}},
            {"name": "cyl", "type": "cylindrical", "parent": "b2", "child": "b3", "axis": [0, 0, 1],
             "parent_frame": {"position": [0, 0.2, 0]}, "child_frame": {"position": [0.01, 0, 0.02], "rotation": {"rotvec": [0.2, 0, 0.1]}},
             "q0": [0.3, -0.05], "damper": {"d": [0.1, 0.5]}},
            {"name": "uni", "type": "universal", "parent": "b3", "child": "b4", "axis": [1, 0, 0], "axis2": [0, 0.6, 0.8],
             "parent_frame": {"position": [0.1, 0.1, 0]}, "q0": [0.5, -0.4]},
            {"name": "sph", "type": "spherical", "parent": "b4", "child": "b5",
             "parent_frame": {"position": [0.2, 0, 0]}, "q0": [0.8, 0.3, -0.4, 0.3]},
            {"name": "pla", "type": "planar", "parent": "b5", "child": "b6",
             "parent_frame": {"position": [0.2, 0, 0], "rotation": {"cardan": [0.4, 0, 0]}}, "q0": [0.05, -0.03, 0.6],
             "spring": {"k": [10.0, 12.0, 2.0]}},
            {"name": "fre", "type": "free", "parent": "ground", "child": "b7", "q0": [0.3, 0.2, -0.1, 0.7, -0.2, 0.5, 0.4]},
            {"name": "fix", "type": "fixed", "parent": "b7", "child": "b8", "parent_frame": {"position": [0.1, 0.05, 0], "rotation": {"cardan": [0.3, 0.2, 0.1]}}}],
        "forces": [
            {"type": "spring_damper", "name": "s1", "body1": "b2", "point1": [0.05, 0, 0], "body2": "b6", "point2": [0, 0.02, 0],
             "k": 80.0, "k3": 500.0, "d": 1.5, "l0": 0.1, "table_deflection": [-1, 0, 0.5, 2], "table_force": [-10, 0, 20, 30]},
            {"type": "spring_damper", "name": "s2", "body1": "ground", "point1": [0.5, 0.5, 0], "body2": "b8", "point2": [0.05, 0, 0.01],
             "k": 20.0, "d": 0.5, "l0": 0.3},
            {"type": "body_force", "name": "f1", "body": "b5", "point": [0.1, 0.02, 0], "force": [1, 2, 3], "torque": [0.1, 0, -0.2], "frame": "body"},
            {"type": "body_force", "name": "f2", "body": "b7", "point": [0.0, 0.1, 0], "force": [0, 0, 4], "torque": [0.3, 0, 0],
             "function": {"type": "ramp", "slope": 2.0}},
            {"type": "joint_force", "name": "f3", "joint": "uni", "value": [0.3, -0.1]}]}"#,
    )
}

fn zoo_state(model: &Model) -> (Vec<f64>, Vec<f64>) {
    let mut q = model.q0();
    model.normalize(&mut q);
    let u: Vec<f64> = (0..model.nu).map(|i| 0.6 * ((i as f64) * 1.3 + 0.4).sin()).collect();
    (q, u)
}

#[test]
fn generic_inverse_dynamics_equals_the_engine_rnea_for_every_joint_and_element() {
    // the element laws and joint kinematics written over a generic scalar reproduce forces.rs,
    // kinematics and the RNEA: the value part at f64, on every joint type and covered element
    let model = zoo();
    let (q, u) = zoo_state(&model);
    let udot: Vec<f64> = (0..model.nu).map(|i| 0.9 * ((i as f64) * 0.7 - 0.2).cos()).collect();
    let t = 0.8;
    let mut data = crate::data::Data::new(&model);
    let mut ws = crate::dynamics::Workspace::new(&model);
    let mut want = vec![0.0; model.nu];
    crate::dynamics::inverse_dynamics(&model, &mut data, &mut ws, t, &q, &u, &udot, &NoCallbacks, &mut want).unwrap();
    let mut tree = super::ad::Tree::<f64>::new(&model);
    let mut got = vec![0.0; model.nu];
    tree.inverse_dynamics(&model, t, &q, &u, &udot, &NoCallbacks, &mut got).unwrap();
    let err = max_diff(&got, &want) / max_abs(&want);
    eprintln!("generic ID vs engine RNEA on all joint types: {err:.1e} relative");
    assert!(err < 1e-13, "{err:.3e}: {got:?} vs {want:?}");
}

#[test]
fn exact_on_every_joint_type_matches_differences() {
    let model = zoo();
    let (q, u) = zoo_state(&model);
    exact_vs_fd("all joint types and elements", &model, 0.8, &q, &u, &NoCallbacks, 1e-6);
}

/// A callback force: a torsion spring −k q on the pendulum's pin.
struct Torsion(f64);

impl Callbacks for Torsion {
    fn time_function(&self, id: usize, _t: f64) -> crate::error::Result<f64> {
        Err(crate::error::Error::Callback(format!("no time function {id}")))
    }
    fn generalized_force(
        &self,
        _id: usize,
        _t: f64,
        q: &[f64],
        _u: &[f64],
        out: &mut [f64],
    ) -> crate::error::Result<()> {
        out[0] -= self.0 * q[0];
        Ok(())
    }
}

#[test]
fn callback_forces_make_auto_fall_back_and_exact_name_the_element() {
    let m = model(
        r#"{"name": "p", "gravity": [0, -9.81, 0],
        "bodies": [{"name": "bob", "mass": 1.5, "inertia": [1e-9, 1e-9, 1e-9]}],
        "joints": [{"name": "pin", "type": "revolute", "parent": "ground", "child": "bob", "axis": [0, 0, 1],
                     "child_frame": {"position": [0, 0.8, 0]}}],
        "forces": [{"type": "callback", "name": "torsion spring", "id": 0}]}"#,
    );
    let cb = Torsion(5.0);
    let e = linearize_with(&m, 0.0, &m.q0(), &m.u0(), &cb, Derivatives::Exact).unwrap_err();
    assert!(matches!(e, crate::error::Error::Settings(_)), "{e:?}");
    assert!(e.to_string().contains("'torsion spring'"), "{e}");
    let auto = linearize(&m, 0.0, &m.q0(), &m.u0(), &cb).unwrap();
    assert_eq!(auto.method, DerivativeMethod::CentralDifferences);
    let k = 1.5 * 9.81 * 0.8 + 5.0;
    assert!((auto.k[0] - k).abs() < 1e-8 * k, "{}", auto.k[0]);
    // without the callback the same pendulum goes the exact way
    let (p, q) = pendulum(0.0, false);
    assert_eq!(linearize(&p, 0.0, &q, &p.u0(), &NoCallbacks).unwrap().method, DerivativeMethod::Exact);
    assert_eq!(Derivatives::from_name("fd"), Some(Derivatives::CentralDifferences));
    assert_eq!(Derivatives::from_name("exact"), Some(Derivatives::Exact));
    assert_eq!(Derivatives::from_name("Exact"), None);
}

// ---- the state form about a motion (module `motion`) -------------------------------------------

use super::{state_space, Basis, StateSpace};

fn eigenvalues(s: &StateSpace) -> Vec<nalgebra::Complex<f64>> {
    let n = s.nq + s.nu;
    DMatrix::from_row_slice(n, n, &s.a).complex_eigenvalues().iter().copied().collect()
}

/// A sledge on a planar joint with a knife edge at distance `a` ahead of its centre of mass,
/// sliding straight at speed `v`: the yaw rate obeys (I + m a²) ω̇ = m a v ω (the Chaplygin
/// sleigh), one eigenvalue m a v / (I + m a²), the others zero.
fn sleigh(a: f64, v: f64) -> Model {
    model(&format!(
        r#"{{"name": "sleigh", "gravity": [0, 0, 0],
             "bodies": [{{"name": "sled", "mass": 2.0, "inertia": [0.2, 0.2, 0.3]}}],
             "joints": [{{"name": "p", "type": "planar", "parent": "ground", "child": "sled", "u0": [{v}, 0, 0]}}],
             "constraints": [{{"type": "knife_edge", "name": "blade", "body": "sled", "point": [{a}, 0, 0], "direction": [0, 1, 0]}}]}}"#
    ))
}

#[test]
fn chaplygin_sleigh_eigenvalue_and_its_sign() {
    for (a, v) in [(0.3, 1.5), (-0.3, 1.5), (0.2, -2.0)] {
        let m = sleigh(a, v);
        let (q, u) = (m.q0(), m.u0());
        let want = 2.0 * a * v / (0.3 + 2.0 * a * a);
        for (how, tol) in [(Derivatives::Exact, 1e-10), (Derivatives::CentralDifferences, 1e-7)] {
            for basis in [Basis::Orthonormal, Basis::Partition(vec![])] {
                let s = state_space(&m, 0.0, &q, &u, &NoCallbacks, how, &basis).unwrap();
                assert_eq!((s.nq, s.nu), (3, 2), "three configuration, two velocity states");
                let lam = eigenvalues(&s);
                let big = lam.iter().max_by(|x, y| x.norm().total_cmp(&y.norm())).unwrap();
                assert!(
                    (big.re - want).abs() < tol * want.abs() && big.im.abs() < tol,
                    "{how:?} {basis:?}: {big} vs {want}"
                );
                assert!(s.defect < 1e-9, "steady: defect {}", s.defect);
            }
        }
    }
}

#[test]
fn partition_basis_selects_joint_coordinates() {
    let m = sleigh(0.3, 1.0);
    let s =
        state_space(&m, 0.0, &m.q0(), &m.u0(), &NoCallbacks, Derivatives::Exact, &Basis::Partition(vec![2])).unwrap();
    // all three coordinates are configuration states; the yaw rate (preferred) stays independent
    assert_eq!(s.independent_q, vec![0, 1, 2]);
    assert!(s.independent_u.contains(&2) && s.independent_u.len() == 2, "{:?}", s.independent_u);
    // L_u V = I and G (P ξ + V η) = −J ξ: the lateral velocity follows the heading at speed v
    let v = DMatrix::from_row_slice(3, 2, &s.v);
    let lu = DMatrix::from_row_slice(2, 3, &s.lu);
    assert!((&lu * &v - DMatrix::<f64>::identity(2, 2)).amax() < 1e-15);
    let p = DMatrix::from_row_slice(3, 3, &s.p);
    // turning the sled by δθ at speed 1 along x: the blade's lateral direction turns, so the
    // admissible velocity gains v δθ sideways (world y), taken by the dependent velocity
    // (G = [−sin θ, cos θ, a] on (ẋ, ẏ, θ̇) in the ground's axes, J = ∂(G u*)/∂θ = −v at θ = 0)
    assert_eq!(s.independent_u, vec![0, 2]);
    assert!((p[(1, 2)] - 1.0).abs() < 1e-10, "P = {p}");
    assert!((0..3).all(|r| (0..3).all(|c| (r, c) == (1, 2) || p[(r, c)].abs() < 1e-12)), "P = {p}");
}

/// The chart's rate: along a motion with constant body velocities, the rotation-vector and
/// position chart of a free joint about the reference obeys δ̇ = Ω(u*) δ + δu, by central
/// differences of `Model::integrate` and the chart's inverse.
#[test]
fn chart_rate_of_the_free_joint_by_differences() {
    use crate::math::{Mat3, Vec3};
    let m = model(
        r#"{"name": "f", "gravity": [0, 0, 0], "bodies": [{"name": "b", "mass": 1, "inertia": [1, 2, 3]}],
            "joints": [{"name": "j", "type": "free", "parent": "ground", "child": "b"}]}"#,
    );
    let q0 = vec![0.3, -0.2, 0.5, 0.9, 0.1, -0.3, 0.2];
    let mut qs = q0.clone();
    m.normalize(&mut qs);
    let us = vec![0.7, -0.4, 0.2, 1.1, -0.6, 0.8];
    let d = [1e-5, -2e-5, 1.5e-5, 2e-5, 1e-5, -1e-5];
    let du = [3e-5, 1e-5, -2e-5, -1e-5, 2e-5, 1e-5];
    let quat = |q: &[f64]| nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[4], q[5], q[6]));
    // the chart's inverse about the reference at time h: (Aᵀ (p − p*), log(q*⁻¹ q))
    let chart = |h: f64| -> Vec<f64> {
        let (mut qr, mut qp, mut q1) = (vec![0.0; 7], vec![0.0; 7], vec![0.0; 7]);
        m.integrate(&qs, &us, h, &mut qr);
        m.integrate(&qs, &d, 1.0, &mut q1);
        let up: Vec<f64> = us.iter().zip(&du).map(|(a, b)| a + b).collect();
        m.integrate(&q1, &up, h, &mut qp);
        let a: Mat3 = quat(&qr).to_rotation_matrix().into_inner();
        let dp = a.transpose() * (Vec3::new(qp[0], qp[1], qp[2]) - Vec3::new(qr[0], qr[1], qr[2]));
        let rot = (quat(&qr).inverse() * quat(&qp)).scaled_axis();
        vec![dp[0], dp[1], dp[2], rot[0], rot[1], rot[2]]
    };
    let h = 1e-4;
    let (cp, cm) = (chart(h), chart(-h));
    let rate: Vec<f64> = (0..6).map(|i| (cp[i] - cm[i]) / (2.0 * h)).collect();
    let om = super::motion::chart_rate(&m, &us);
    for i in 0..6 {
        let want: f64 = (0..6).map(|k| om[(i, k)] * d[k]).sum::<f64>() + du[i];
        // second order in δ (1e-10) and the differences (h² |δ| ~ 1e-13)
        assert!((rate[i] - want).abs() < 2e-9, "component {i}: {} vs {want}", rate[i]);
    }
    // and the rotation term is there: without Ω the rate is off by |ω × δ| ~ 3e-5
    assert!((0..3).any(|i| (rate[3 + i] - du[3 + i]).abs() > 1e-5));
}

/// A free joint held by a point constraint (a conical pendulum) and the same on a spherical
/// joint linearize alike, exact and by differences; the exact and differenced state matrices agree.
#[test]
fn constrained_free_joint_matches_the_spherical_joint() {
    let (alpha, l, g) = (0.5f64, 0.8f64, 9.81f64);
    let omega = (g / (l * alpha.cos())).sqrt();
    let (c, s) = ((alpha / 2.0).cos(), (alpha / 2.0).sin());
    // body rotated by alpha about x; body-frame angular velocity Rᵀ Ω e_z
    let w = [0.0, omega * alpha.sin(), omega * alpha.cos()];
    let body = r#"{"name": "bob", "mass": 1.0, "inertia": [0.02, 0.02, 0.01], "com": [0, 0, -0.8]}"#;
    let sph = model(&format!(
        r#"{{"name": "s", "gravity": [0, 0, -9.81], "bodies": [{body}],
             "joints": [{{"name": "j", "type": "spherical", "parent": "ground", "child": "bob", "q0": [{c}, {s}, 0, 0], "u0": [{}, {}, {}]}}]}}"#,
        w[0], w[1], w[2]
    ));
    let free = model(&format!(
        r#"{{"name": "f", "gravity": [0, 0, -9.81], "bodies": [{body}],
             "joints": [{{"name": "j", "type": "free", "parent": "ground", "child": "bob", "q0": [0, 0, 0, {c}, {s}, 0, 0], "u0": [0, 0, 0, {}, {}, {}]}}],
             "constraints": [{{"type": "point", "name": "pin", "body1": "bob", "body2": "ground"}}]}}"#,
        w[0], w[1], w[2]
    ));
    let spectrum = |m: &Model, how| {
        let s = state_space(m, 0.0, &m.q0(), &m.u0(), &NoCallbacks, how, &Basis::Orthonormal).unwrap();
        let mut im: Vec<f64> = eigenvalues(&s).iter().map(|z| z.im.abs()).collect();
        im.sort_by(|a, b| b.total_cmp(a));
        (im[0], s)
    };
    let (ref_freq, ref_s) = spectrum(&sph, Derivatives::Exact);
    assert!(ref_freq > 1.0);
    for (m, how, tol) in [
        (&sph, Derivatives::CentralDifferences, 1e-8),
        (&free, Derivatives::Exact, 1e-9),
        (&free, Derivatives::CentralDifferences, 1e-7),
    ] {
        let (f, s) = spectrum(m, how);
        assert!((f - ref_freq).abs() < tol * ref_freq, "{how:?}: {f} vs {ref_freq}");
        assert_eq!((s.nq, s.nu), (ref_s.nq, ref_s.nu));
    }
    let (_, ex) = spectrum(&free, Derivatives::Exact);
    let (_, fd) = spectrum(&free, Derivatives::CentralDifferences);
    let diff = ex.a.iter().zip(&fd.a).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let big = ex.a.iter().map(|a| a.abs()).fold(0.0, f64::max);
    assert!(diff < 1e-7 * big, "exact vs fd state matrices: {diff:e} of {big:e}");
}

// ---- hydrodynamic bearings through the exact path ----------------------------------------------

/// A journal on a free joint in a shell on a turning housing, both frames tilted: the bearing's
/// offset, its rate seen in the moving shell and the relative spin all take part. The clearance is
/// large (4 cm) so that the differences' step (1e-5) stays small against it, the oil thick so that
/// the film forces dominate the linearization.
fn bearing_in_a_turning_housing(theory: &str) -> (Model, Vec<f64>, Vec<f64>) {
    let m = model(&format!(
        r#"{{"name": "brg", "gravity": [0, -9.81, 0],
        "bodies": [
            {{"name": "housing", "mass": 3.0, "com": [0.05, 0, 0], "inertia": [0.02, 0.03, 0.03]}},
            {{"name": "rotor", "mass": 2.0, "com": [0, 0.02, 0.01], "inertia": [0.01, 0.012, 0.02]}}],
        "joints": [
            {{"name": "tilt", "type": "revolute", "parent": "ground", "child": "housing", "axis": [1, 0, 0], "q0": 0.3}},
            {{"name": "float", "type": "free", "parent": "ground", "child": "rotor"}}],
        "forces": [
            {{"type": "hydrodynamic_bearing", "name": "brg", "journal": "rotor", "journal_frame": {{"position": [0, 0, 0.05]}},
              "shell": "housing", "shell_frame": {{"position": [0.1, 0, 0], "rotation": {{"cardan": [0, 0, 0.2]}}}},
              "radius": 0.05, "length": 0.1, "clearance": 0.04, "viscosity": 50.0, "theory": "{theory}"}}]}}"#
    ));
    // the rotor turned as the housing, its journal centre 3 and -4 mm off the shell centre (shell x, y)
    let a = crate::model::joint::axis_rotation(&crate::math::Vec3::x(), 0.3);
    let a_s = a * crate::model::joint::axis_rotation(&crate::math::Vec3::z(), 0.2);
    let p_j = crate::math::Vec3::new(0.1, 0.0, 0.0) + a_s * crate::math::Vec3::new(12e-3, -16e-3, 0.0);
    let r = p_j - a * crate::math::Vec3::new(0.0, 0.0, 0.05);
    let mut q = m.q0();
    q[1..4].copy_from_slice(&[r.x, r.y, r.z]);
    q[4..8].copy_from_slice(&[0.15f64.cos(), 0.15f64.sin(), 0.0, 0.0]);
    // housing turning, the rotor spinning about its axis and drifting in the gap
    let u = vec![2.0, 0.01, -0.02, 0.005, 2.1, 0.3, 120.0];
    (m, q, u)
}

#[test]
fn hydrodynamic_bearing_generic_law_equals_the_engine_and_its_exact_derivatives_the_differences() {
    for theory in ["short", "long"] {
        let (model, q, u) = bearing_in_a_turning_housing(theory);
        let udot: Vec<f64> = (0..model.nu).map(|i| 0.5 * ((i as f64) * 0.9 + 0.1).sin()).collect();
        let mut data = crate::data::Data::new(&model);
        let mut ws = crate::dynamics::Workspace::new(&model);
        let mut want = vec![0.0; model.nu];
        crate::dynamics::inverse_dynamics(&model, &mut data, &mut ws, 0.0, &q, &u, &udot, &NoCallbacks, &mut want)
            .unwrap();
        // the bearing is loaded: its film force is well above the dynamics' rounding
        assert!(data.element_deflection[0] > 0.4 && data.element_force[0].hypot(data.element_force[1]) > 50.0);
        let mut tree = super::ad::Tree::<f64>::new(&model);
        let mut got = vec![0.0; model.nu];
        tree.inverse_dynamics(&model, 0.0, &q, &u, &udot, &NoCallbacks, &mut got).unwrap();
        let err = max_diff(&got, &want) / max_abs(&want);
        assert!(err < 1e-13, "{theory}: {err:.3e}: {got:?} vs {want:?}");
        exact_vs_fd(&format!("{theory} bearing in a turning housing"), &model, 0.0, &q, &u, &NoCallbacks, 1e-6);
    }
}

#[test]
fn hydrodynamic_bearing_touching_its_shell_is_a_named_solver_error() {
    let (model, mut q, u) = bearing_in_a_turning_housing("short");
    q[2] -= 0.06;
    let e = linearize(&model, 0.5, &q, &u, &NoCallbacks).unwrap_err();
    assert!(matches!(e, crate::error::Error::Solver(_)), "{e:?}");
    assert!(e.to_string().contains("'brg'") && e.to_string().contains("touches the shell"), "{e}");
}
