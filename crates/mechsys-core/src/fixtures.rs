//! Model fixtures shared by tests and benchmarks: spatial chains of uniform rods, and a roller
//! on a spinning elliptical cam.

use crate::model::description::*;
use crate::model::Model;

/// A spatial chain of `n` uniform rods (mass 1 kg, length 0.5 m, radius 0.02 m) along x, hanging
/// in gravity -z; joint `joint_type` ("revolute": axes alternating z, y, x; "spherical"; "universal").
pub fn chain_description(n: usize, joint_type: &str) -> ModelDescription {
    let (m, l, r) = (1.0, 0.5, 0.02);
    let ia = 0.5 * m * r * r;
    let it = m * (3.0 * r * r + l * l) / 12.0;
    let axes = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
    let mut bodies = Vec::with_capacity(n);
    let mut joints = Vec::with_capacity(n);
    for i in 0..n {
        bodies.push(BodyDescription {
            name: format!("link{}", i + 1),
            mass: m,
            inertia: InertiaDescription::List(vec![ia, it, it]),
            com: [0.5 * l, 0.0, 0.0],
            markers: vec![],
            mass_rate: 0.0,
            ejection_velocity: [0.0; 3],
            ejection_point: None,
            mass_final: None,
            elastic: None,
        });
        let nq = match joint_type {
            "spherical" => 4,
            "universal" => 2,
            _ => 1,
        };
        let q0 = match joint_type {
            "spherical" => vec![(0.5f64).cos(), 0.0, (0.5f64).sin() * 0.6, (0.5f64).sin() * 0.8],
            _ => (0..nq).map(|k| 0.1 + 0.05 * (i + k) as f64).collect(),
        };
        let (name, parent, child) = (
            format!("j{}", i + 1),
            if i == 0 { "ground".to_string() } else { format!("link{i}") },
            format!("link{}", i + 1),
        );
        joints.push(JointDescription {
            axis: if joint_type == "revolute" { Some(axes[i % 3]) } else { None },
            parent_frame: FrameDescription { position: [if i == 0 { 0.0 } else { l }, 0.0, 0.0], rotation: None },
            q0: Some(q0),
            ..JointDescription::new(&name, joint_type, &parent, &child)
        });
    }
    ModelDescription {
        name: format!("chain-{n}-{joint_type}"),
        gravity: [0.0, 0.0, -9.81],
        bodies,
        joints,
        forces: vec![],
        ground_markers: vec![],
        contacts: vec![],
        contact_groups: vec![],
        gap_contacts: vec![],
        visuals: vec![],
        planar: false,
        constraints: vec![],
    }
}

/// The validated chain model.
pub fn chain(n: usize, joint_type: &str) -> Model {
    Model::from_description(chain_description(n, joint_type)).expect("fixture chain is valid")
}

/// A roller (radius 0.01 m, 0.1 kg) on a prismatic guide pressed by gravity on an elliptical cam
/// (semi-axes 0.05, 0.035 m) spinning freely at `speed` rad/s, the roller's centre at `y0`: a
/// planar curve contact whose search warm-starts between steps.
pub fn ellipse_cam(speed: f64, y0: f64) -> Model {
    let json = format!(
        r#"{{
        "name": "ellipse-cam", "gravity": [0, -9.81, 0], "planar": true,
        "bodies": [
            {{"name": "cam", "mass": 1.0, "inertia": [0.001, 0.001, 0.001]}},
            {{"name": "roller", "mass": 0.1, "inertia": [1e-5, 1e-5, 1e-5]}}
        ],
        "joints": [
            {{"name": "shaft", "type": "revolute", "parent": "ground", "child": "cam", "axis": [0, 0, 1], "u0": [{speed}]}},
            {{"name": "guide", "type": "prismatic", "parent": "ground", "child": "roller", "axis": [0, 1, 0], "q0": [{y0}]}}
        ],
        "contacts": [{{"name": "cam", "body1": "roller", "contour1": {{"type": "circle", "radius": 0.01}},
                      "body2": "cam", "contour2": {{"type": "ellipse", "semi_axes": [0.05, 0.035]}},
                      "friction": {{"type": "coulomb", "mu": 0.1}}, "impact": {{"type": "newton", "eps": 0.0}}}}]
    }}"#
    );
    Model::from_description(ModelDescription::from_json(&json).expect("valid JSON")).expect("valid model")
}
