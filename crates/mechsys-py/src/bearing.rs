//! Bindings of the hydrodynamic journal bearing's law and its steady analysis
//! (`mechsys_core::forces::bearing`), for `mechsys.bearings`: the same law the element uses.

use mechsys_core::model::{BearingLaw, BearingTheory};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{settings, PyMechsysError};

/// The law from its parameters, checked as the model element's are.
fn law(theory: &str, radius: f64, length: f64, clearance: f64, viscosity: f64, what: &str) -> PyResult<BearingLaw> {
    let theory = BearingTheory::from_name(theory)
        .ok_or_else(|| settings(format!("{what}: theory must be one of {:?}, got '{theory}'", BearingTheory::NAMES)))?;
    for (k, v, unit) in [
        ("radius", radius, "m"),
        ("length", length, "m"),
        ("clearance", clearance, "m"),
        ("viscosity", viscosity, "Pa s"),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(settings(format!("{what}: {k} must be > 0 ({unit}), got {v}")));
        }
    }
    if clearance >= radius {
        return Err(settings(format!(
            "{what}: clearance must be smaller than the radius {radius} m, got {clearance} m"
        )));
    }
    Ok(BearingLaw { theory, radius, length, clearance, viscosity })
}

fn finite(values: &[(&str, f64)], what: &str) -> PyResult<()> {
    match values.iter().find(|(_, v)| !v.is_finite()) {
        Some((k, v)) => Err(settings(format!("{what}: {k} must be finite, got {v}"))),
        None => Ok(()),
    }
}

/// Film forces (F_r, F_t) and friction torque on the journal at eccentricity ε ∈ [0, 1), its rate
/// ε̇, the effective speed ω* = ω_rel − 2φ̇ and the relative spin ω_rel.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn bearing_film(
    theory: &str,
    radius: f64,
    length: f64,
    clearance: f64,
    viscosity: f64,
    eps: f64,
    eps_dot: f64,
    omega_star: f64,
    omega_rel: f64,
) -> PyResult<(f64, f64, f64)> {
    let what = "bearing film";
    let b = law(theory, radius, length, clearance, viscosity, what)?;
    finite(&[("eps_dot", eps_dot), ("omega_star", omega_star), ("omega_rel", omega_rel)], what)?;
    if !(eps.is_finite() && (0.0..1.0).contains(&eps)) {
        return Err(settings(format!("{what}: eccentricity ratio must lie in [0, 1), got {eps}")));
    }
    let f = b.film(eps, eps_dot, omega_star, omega_rel);
    Ok((f.f_r, f.f_t, f.torque))
}

/// The film's force (shell x, y) and torque on the journal from its offset and offset rate (shell
/// x, y) and the relative spin; a SolverError once the journal touches the shell.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn bearing_load(
    theory: &str,
    radius: f64,
    length: f64,
    clearance: f64,
    viscosity: f64,
    offset: [f64; 2],
    offset_rate: [f64; 2],
    spin: f64,
) -> PyResult<(f64, f64, f64)> {
    let what = "bearing load";
    let b = law(theory, radius, length, clearance, viscosity, what)?;
    finite(&[("offset x", offset[0]), ("offset y", offset[1]), ("offset_rate x", offset_rate[0])], what)?;
    finite(&[("offset_rate y", offset_rate[1]), ("spin", spin)], what)?;
    let l = b.shell_load(offset, offset_rate, spin).map_err(|eps| {
        PyMechsysError(mechsys_core::Error::Solver(format!(
            "{what}: the journal touches the shell (eccentricity ratio {eps:.6} >= 1)"
        )))
    })?;
    Ok((l.force[0], l.force[1], l.torque))
}

/// The steady operating point under `load` (N, along −y) at `speed` (rad/s): a dict of eps,
/// attitude, position_angle, offset, sommerfeld, h_min, torque, K and C (2×2 nested lists).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn bearing_operating_point<'py>(
    py: Python<'py>,
    theory: &str,
    radius: f64,
    length: f64,
    clearance: f64,
    viscosity: f64,
    speed: f64,
    load: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let b = law(theory, radius, length, clearance, viscosity, "bearing operating point")?;
    let op = b.operating_point(speed, load).map_err(PyMechsysError)?;
    let d = PyDict::new(py);
    d.set_item("eps", op.eps)?;
    d.set_item("attitude", op.attitude)?;
    d.set_item("position_angle", op.position_angle)?;
    d.set_item("offset", op.offset.to_vec())?;
    d.set_item("sommerfeld", op.sommerfeld)?;
    d.set_item("h_min", op.h_min)?;
    d.set_item("torque", op.torque)?;
    d.set_item("K", op.stiffness.iter().map(|r| r.to_vec()).collect::<Vec<_>>())?;
    d.set_item("C", op.damping.iter().map(|r| r.to_vec()).collect::<Vec<_>>())?;
    Ok(d)
}

/// Load capacity W(ε) (N) of a steady journal at ε ∈ [0, 1) spinning at `speed`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn bearing_load_capacity(
    theory: &str,
    radius: f64,
    length: f64,
    clearance: f64,
    viscosity: f64,
    eps: f64,
    speed: f64,
) -> PyResult<(f64, f64)> {
    let what = "bearing load capacity";
    let b = law(theory, radius, length, clearance, viscosity, what)?;
    finite(&[("speed", speed)], what)?;
    if !(eps.is_finite() && (0.0..1.0).contains(&eps)) {
        return Err(settings(format!("{what}: eccentricity ratio must lie in [0, 1), got {eps}")));
    }
    Ok((b.load_capacity(eps, speed), b.attitude_angle(eps)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(bearing_film, m)?)?;
    m.add_function(wrap_pyfunction!(bearing_load, m)?)?;
    m.add_function(wrap_pyfunction!(bearing_operating_point, m)?)?;
    m.add_function(wrap_pyfunction!(bearing_load_capacity, m)?)?;
    Ok(())
}
