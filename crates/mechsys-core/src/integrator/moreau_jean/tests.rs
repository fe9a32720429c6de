//! The sparse contact assembly against the dense one, and contact groups against explicit pairs.

use super::{Assembly, MoreauJean};
use crate::data::Data;
use crate::dynamics::Workspace;
use crate::forces::NoCallbacks;
use crate::model::{Model, ModelDescription};
use crate::solver::{Method, NsgsOptions};

fn nsgs_tight() -> Method {
    Method::Nsgs(NsgsOptions { tol: 1e-14, max_iter: 100_000, relaxation: 1.0, anderson: 0, stall: 0 })
}

/// A two-link arm (revolute, then spherical: trees with multi-velocity joints and child-frame
/// velocities) falling under gravity, whose tip sphere strikes a stack of two free spheres on the
/// floor and then the floor, and a slider (prismatic on a revolute) whose sphere lands on the
/// floor: contacts that couple through shared bodies and trees.
fn tree_model() -> Model {
    let sphere = |r: f64| format!(r#"{{"type": "sphere", "radius": {r}}}"#);
    let plane = r#"{"type": "plane", "normal": [0, 0, 1]}"#;
    let contact = |name: &str, b1: &str, c1: &str, b2: &str, c2: &str| {
        format!(
            r#"{{"name": "{name}", "body1": "{b1}", "contour1": {c1}, "body2": "{b2}", "contour2": {c2},
                "friction": {{"type": "coulomb", "mu": 0.3, "mu0": 0.4}}, "impact": {{"type": "newton", "eps": 0.5}}}}"#
        )
    };
    let tip = r#"{"type": "sphere", "center": [0.4, 0, 0], "radius": 0.05}"#;
    let contacts = [
        contact("tip_floor", "arm2", tip, "ground", plane),
        contact("s1_floor", "s1", &sphere(0.05), "ground", plane),
        contact("s1_s2", "s2", &sphere(0.05), "s1", &sphere(0.05)),
        contact("s2_tip", "s2", &sphere(0.05), "arm2", tip),
        contact(
            "slide_floor",
            "slider",
            r#"{"type": "sphere", "center": [0, 0, -0.1], "radius": 0.04}"#,
            "ground",
            plane,
        ),
    ]
    .join(",");
    let json = format!(
        r#"{{
        "name": "trees", "gravity": [0, 0, -9.81],
        "bodies": [
            {{"name": "arm1", "mass": 1.0, "inertia": [0.001, 0.02, 0.02], "com": [0.2, 0, 0]}},
            {{"name": "arm2", "mass": 0.7, "inertia": [0.004, 0.015, 0.012], "com": [0.2, 0, 0]}},
            {{"name": "s1", "mass": 0.2, "inertia": [2e-4, 2e-4, 2e-4]}},
            {{"name": "s2", "mass": 0.3, "inertia": [3e-4, 3e-4, 3e-4]}},
            {{"name": "rail", "mass": 0.5, "inertia": [0.01, 0.01, 0.01], "com": [0.1, 0, 0]}},
            {{"name": "slider", "mass": 0.4, "inertia": [0.002, 0.002, 0.002]}}
        ],
        "joints": [
            {{"name": "j1", "type": "revolute", "parent": "ground", "child": "arm1", "axis": [0, 1, 0],
              "parent_frame": {{"position": [0, 0, 0.3]}}}},
            {{"name": "j2", "type": "spherical", "parent": "arm1", "child": "arm2",
              "parent_frame": {{"position": [0.4, 0, 0]}}, "u0": [0.3, 0.0, 0.0]}},
            {{"name": "f1", "type": "free", "parent": "ground", "child": "s1", "q0": [0.74, 0.07, 0.0505, 1, 0, 0, 0]}},
            {{"name": "f2", "type": "free", "parent": "ground", "child": "s2", "q0": [0.745, 0.07, 0.152, 1, 0, 0, 0]}},
            {{"name": "turn", "type": "revolute", "parent": "ground", "child": "rail", "axis": [1, 0, 0],
              "parent_frame": {{"position": [0.72, -0.1, 0.15]}}, "u0": [0.5]}},
            {{"name": "slide", "type": "prismatic", "parent": "rail", "child": "slider", "axis": [0, 0, 1],
              "u0": [-0.3]}}
        ],
        "contacts": [{contacts}]
    }}"#
    );
    Model::from_description(ModelDescription::from_json(&json).unwrap()).unwrap()
}

fn run(model: &Model, assembly: Assembly, steps: usize, h: f64) -> (Vec<Vec<f64>>, Vec<Vec<[f64; 3]>>, MoreauJean) {
    let mut st = MoreauJean::with_assembly(model, h, nsgs_tight(), assembly).unwrap();
    let (mut data, mut ws) = (Data::new(model), Workspace::new(model));
    let (mut q, mut u) = (model.q0(), model.u0());
    let (mut us, mut imps) = (Vec::new(), Vec::new());
    for k in 0..steps {
        st.step(model, &mut data, &mut ws, k as f64 * h, &mut q, &mut u, &NoCallbacks).unwrap();
        let mut y = q.clone();
        y.extend_from_slice(&u);
        us.push(y);
        imps.push(st.results.iter().map(|r| [r.impulse_n, r.impulse_t[0], r.impulse_t[1]]).collect());
    }
    (us, imps, st)
}

/// The same impulses and velocities from the sparse (tree factor, Delassus blocks) and the dense
/// (M⁻¹ column by column) assembly, over 400 steps with impacts, sticking and sliding.
#[test]
fn sparse_and_dense_assembly_agree_on_trees() {
    let model = tree_model();
    let h = 1e-3;
    let (ys, is_, st_s) = run(&model, Assembly::Sparse, 400, h);
    let (yd, id, st_d) = run(&model, Assembly::Dense, 400, h);
    assert!(st_s.is_sparse() && !st_d.is_sparse());
    assert_eq!(st_s.unconverged.0, 0);
    let scale_y = ys.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    let scale_i = is_.iter().flatten().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut worst = (0.0f64, 0.0f64);
    for k in 0..ys.len() {
        for (a, b) in ys[k].iter().zip(&yd[k]) {
            worst.0 = worst.0.max((a - b).abs());
        }
        for (a, b) in is_[k].iter().flatten().zip(id[k].iter().flatten()) {
            worst.1 = worst.1.max((a - b).abs());
        }
    }
    assert!(worst.0 <= 1e-11 * scale_y, "states differ by {:.1e} (scale {scale_y:.1e})", worst.0);
    assert!(worst.1 <= 1e-11 * scale_i, "impulses differ by {:.1e} (scale {scale_i:.1e})", worst.1);
    // the run exercised what it should: every contact closed at some step, and steps where
    // contacts on one tree (the arm: tip on the floor and a ball on the tip) act together
    let names: Vec<&str> = model.contacts.iter().map(|c| c.name.as_str()).collect();
    let closed: Vec<usize> = (0..names.len()).map(|c| is_.iter().filter(|r| r[c][0] > 0.0).count()).collect();
    for (c, name) in names.iter().enumerate() {
        assert!(closed[c] > 0, "contact '{name}' never closed");
    }
    let together = |a: usize, b: usize| is_.iter().filter(|r| r[a][0] > 0.0 && r[b][0] > 0.0).count();
    assert!(together(1, 2) > 100, "the balls never rested on each other");
    assert!(together(2, 3) > 0, "the arm never hit the stacked balls");
}

/// The sparse assembly's Delassus matrix is WᵀM⁻¹W: compared with the dense product at one
/// state, block by block.
#[test]
fn block_delassus_is_w_minv_wt() {
    let model = tree_model();
    let h = 1e-3;
    let (mut ss, mut sd) = (
        MoreauJean::with_assembly(&model, h, nsgs_tight(), Assembly::Sparse).unwrap(),
        MoreauJean::with_assembly(&model, h, nsgs_tight(), Assembly::Dense).unwrap(),
    );
    let (mut data_s, mut data_d) = (Data::new(&model), Data::new(&model));
    let (mut ws_s, mut ws_d) = (Workspace::new(&model), Workspace::new(&model));
    let (mut q, mut u) = (model.q0(), model.u0());
    let (mut q2, mut u2) = (q.clone(), u.clone());
    let mut checked = 0;
    for k in 0..300 {
        let t = k as f64 * h;
        ss.step(&model, &mut data_s, &mut ws_s, t, &mut q, &mut u, &NoCallbacks).unwrap();
        sd.step(&model, &mut data_d, &mut ws_d, t, &mut q2, &mut u2, &NoCallbacks).unwrap();
        let m = ss.problem.contacts();
        if m >= 3 {
            let crate::solver::Delassus::Blocks(bw) = &ss.problem.w else { panic!("blocks expected") };
            let crate::solver::Delassus::Dense(wd) = &sd.problem.w else { panic!("dense expected") };
            let ws = bw.to_dense();
            assert_eq!(ws.len(), wd.len());
            let scale = wd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (a, b) in ws.iter().zip(wd) {
                assert!((a - b).abs() <= 1e-12 * scale, "step {k}: {a} vs {b}");
            }
            checked += 1;
        }
    }
    assert!(checked > 20, "only {checked} steps with three or more contacts");
}

/// A roller pressed by gravity on a spinning elliptical cam: the curve contact's search
/// warm-starts between steps (most steps), and the trajectory is the one of cold searches.
#[test]
fn curve_contacts_warm_start_between_steps_and_match_cold_searches() {
    let model = crate::fixtures::ellipse_cam(5.0, 0.0605);
    let h = 1e-4;
    let run = |warm: bool| {
        let mut st = MoreauJean::new(&model, h, nsgs_tight()).unwrap();
        st.warm_search = warm;
        let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
        let (mut q, mut u) = (model.q0(), model.u0());
        let (mut warm_steps, mut closed) = (0, 0);
        for k in 0..3000 {
            st.step(&model, &mut data, &mut ws, k as f64 * h, &mut q, &mut u, &NoCallbacks).unwrap();
            warm_steps += st.search[0].was_warm() as usize;
            closed += (st.results[0].impulse_n > 0.0) as usize;
        }
        (q, u, warm_steps, closed)
    };
    let (qw, uw, warm_steps, closed) = run(true);
    let (qc, uc, cold_warm, _) = run(false);
    assert_eq!(cold_warm, 0);
    assert!(closed > 1000, "the roller rides on the cam: {closed} of 3000 steps closed");
    assert!(warm_steps > 1500, "warm searches in {warm_steps} of 3000 steps");
    for (a, b) in qw.iter().zip(&qc).chain(uw.iter().zip(&uc)) {
        assert!((a - b).abs() < 1e-10, "warm {a} vs cold {b}");
    }
}
