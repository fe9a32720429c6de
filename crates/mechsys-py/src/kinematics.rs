//! Bindings of the recursive kinematics: body placements, twists and point Jacobians.

use mechsys_core::kinematics;
use mechsys_core::math::Vec3;
use nalgebra::DMatrix;
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{settings, PyMechsysError};
use crate::model::{check_len, q_checked, PyModel};

fn body_index(model: &PyModel, body: &str) -> PyResult<usize> {
    model.model.body_id(body).ok_or_else(|| settings(format!("body: unknown body '{body}'")))
}

/// Positions (nbody × 3), rotation matrices A_IB (nbody × 3 × 3), velocities and angular velocities
/// (I components) of all bodies including the ground (row 0).
#[pyfunction]
#[pyo3(signature = (model, q, u = None))]
fn body_states<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    u: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let zero = vec![0.0; m.nu];
    let u = match &u {
        Some(a) => check_len(a, m.nu, "u")?,
        None => &zero,
    };
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    kinematics::forward_kinematics(m, &mut data, q, u);
    let nb = m.nbodies();
    let mut pos = Vec::with_capacity(nb);
    let mut rot = Vec::with_capacity(nb);
    let mut vel = Vec::with_capacity(nb);
    let mut omg = Vec::with_capacity(nb);
    for i in 0..nb {
        let x = &data.x_abs[i];
        pos.push(x.r.as_slice().to_vec());
        rot.push((0..3).map(|r| (0..3).map(|c| x.a[(r, c)]).collect::<Vec<f64>>()).collect::<Vec<_>>());
        // world-convention twists: the origin's velocity is that of the body point at r_IB
        vel.push(kinematics::point_velocity(&data, i, &Vec3::zeros()).as_slice().to_vec());
        omg.push(data.v[i].w.as_slice().to_vec());
    }
    let d = PyDict::new(py);
    let e = |e: numpy::FromVecError| settings(e.to_string());
    d.set_item("position", PyArray2::from_vec2(py, &pos).map_err(e)?)?;
    d.set_item("rotation", PyArray3::from_vec3(py, &rot).map_err(|e| settings(e.to_string()))?)?;
    d.set_item("velocity", PyArray2::from_vec2(py, &vel).map_err(|e| settings(e.to_string()))?)?;
    d.set_item("angular_velocity", PyArray2::from_vec2(py, &omg).map_err(|e| settings(e.to_string()))?)?;
    Ok(d)
}

/// Jacobians of a body-fixed point: translational (3 × nu) and rotational (3 × nu), I components.
#[pyfunction]
#[pyo3(signature = (model, q, body, point = [0.0, 0.0, 0.0]))]
fn point_jacobian<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    body: &str,
    point: [f64; 3],
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let b = body_index(model, body)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    kinematics::positions(m, &mut data, q);
    let mut jt = DMatrix::zeros(3, m.nu);
    let mut jr = DMatrix::zeros(3, m.nu);
    kinematics::point_jacobian(m, &data, b, &Vec3::from(point), &mut jt, &mut jr);
    let to_rows =
        |j: &DMatrix<f64>| -> Vec<Vec<f64>> { (0..3).map(|r| (0..m.nu).map(|c| j[(r, c)]).collect()).collect() };
    let a = PyArray2::from_vec2(py, &to_rows(&jt)).map_err(|e| settings(e.to_string()))?;
    let b = PyArray2::from_vec2(py, &to_rows(&jr)).map_err(|e| settings(e.to_string()))?;
    Ok((a, b))
}

/// Position of a body-fixed point, I components.
#[pyfunction]
#[pyo3(signature = (model, q, body, point = [0.0, 0.0, 0.0]))]
fn point_position<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    body: &str,
    point: [f64; 3],
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let b = body_index(model, body)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    kinematics::positions(m, &mut data, q);
    let p = kinematics::point_position(&data, b, &Vec3::from(point));
    Ok(PyArray1::from_slice(py, p.as_slice()))
}

/// The geometry of a path curve at the arc lengths `s`, as arrays: position (n × 3), frame
/// (n × 3 × 3, columns t n b), tangent_rate (n × 3, dt/ds), omega and omega_rate (n × 3, the
/// frame's Darboux vector in its own axes and its rate), curvature, torsion (n), in the parent
/// joint frame.
fn geometry<'py>(
    py: Python<'py>,
    curve: &mechsys_core::kinematics::path::PathCurve,
    s: &[f64],
) -> PyResult<Bound<'py, PyDict>> {
    let n = s.len();
    let (mut pos, mut frame, mut dt, mut w, mut dw) = (vec![], vec![], vec![], vec![], vec![]);
    let (mut k, mut tau) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for &si in s {
        let p = curve.point(si);
        pos.extend_from_slice(p.r.as_slice());
        // row-major 3 × 3
        frame.extend((0..9).map(|i| p.frame[(i / 3, i % 3)]));
        dt.extend_from_slice(p.tangent_rate.as_slice());
        w.extend_from_slice(p.omega.as_slice());
        dw.extend_from_slice(p.omega_rate.as_slice());
        k.push(p.curvature);
        tau.push(p.torsion);
    }
    let d = PyDict::new(py);
    d.set_item("position", PyArray1::from_vec(py, pos).reshape([n, 3])?)?;
    d.set_item("frame", PyArray1::from_vec(py, frame).reshape([n, 3, 3])?)?;
    d.set_item("tangent_rate", PyArray1::from_vec(py, dt).reshape([n, 3])?)?;
    d.set_item("omega", PyArray1::from_vec(py, w).reshape([n, 3])?)?;
    d.set_item("omega_rate", PyArray1::from_vec(py, dw).reshape([n, 3])?)?;
    d.set_item("curvature", PyArray1::from_vec(py, k))?;
    d.set_item("torsion", PyArray1::from_vec(py, tau))?;
    Ok(d)
}

/// Geometry of the path joint `joint` of a model at arc lengths `s` (see the module's
/// `geometry`): what the engine computes in a step.
#[pyfunction]
fn path_geometry<'py>(
    py: Python<'py>,
    model: &PyModel,
    joint: &str,
    s: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let j = model
        .model
        .joints
        .iter()
        .find(|j| j.name == joint)
        .ok_or_else(|| settings(format!("joint: unknown joint '{joint}'")))?;
    let mechsys_core::model::JointKind::Path { curve, .. } = &j.kind else {
        return Err(settings(format!("joint '{joint}' is a {} joint, not a path", j.kind.type_name())));
    };
    let s = s.as_slice().map_err(|_| settings("s: must be a contiguous float64 array"))?;
    geometry(py, curve, s)
}

/// Geometry of a path joint described alone (the JSON of one joint entry), before any model.
#[pyfunction]
fn path_curve_geometry<'py>(
    py: Python<'py>,
    joint_json: &str,
    s: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let curve = mechsys_core::model::validate::path_curve_from_json(joint_json).map_err(PyMechsysError::from)?;
    let s = s.as_slice().map_err(|_| settings("s: must be a contiguous float64 array"))?;
    geometry(py, &curve, s)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(path_geometry, m)?)?;
    m.add_function(wrap_pyfunction!(path_curve_geometry, m)?)?;
    m.add_function(wrap_pyfunction!(body_states, m)?)?;
    m.add_function(wrap_pyfunction!(point_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(point_position, m)?)?;
    Ok(())
}
