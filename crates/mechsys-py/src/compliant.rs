//! Bindings of the compliant contact laws' closed forms (`mechsys_core::model::compliant`), for
//! `mechsys.hertz`: the same functions the force elements evaluate.

use mechsys_core::model::compliant::{elliptic_ke, johnson_energy, johnson_x, HertzEllipse};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::settings;

fn positive(values: &[(&str, f64)], what: &str) -> PyResult<()> {
    match values.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
        Some((k, v)) => Err(settings(format!("{what}: {k} must be > 0, got {v}"))),
        None => Ok(()),
    }
}

/// Complete elliptic integrals (K(m), E(m)) for the parameter m = e² in [0, 1).
#[pyfunction]
fn complete_elliptic(m: f64) -> PyResult<(f64, f64)> {
    if !(m.is_finite() && (0.0..1.0).contains(&m)) {
        return Err(settings(format!("complete_elliptic: m must lie in [0, 1), got {m}")));
    }
    Ok(elliptic_ke(m))
}

/// Hertz's contact for relative principal curvatures A, B (1/m, either order), effective modulus
/// E* (Pa) and normal force (N): stiffness K (F = K δ^1.5), approach δ, semi-axes a ≥ b, peak
/// pressure p0, the ellipse's m = 1 − (b/a)².
#[pyfunction]
fn hertz_contact<'py>(
    py: Python<'py>,
    a_curv: f64,
    b_curv: f64,
    e_star: f64,
    force: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let what = "hertz_contact";
    positive(&[("A", a_curv), ("B", b_curv), ("E*", e_star)], what)?;
    if !(force.is_finite() && force >= 0.0) {
        return Err(settings(format!("{what}: force must be >= 0, got {force}")));
    }
    let (a0, b0) = (a_curv.min(b_curv), a_curv.max(b_curv));
    let el = HertzEllipse::new(a0, b0);
    let k = el.stiffness(a0, e_star);
    let delta = (force / k).powf(2.0 / 3.0);
    let (a, b, p0) = el.contact(a0, delta, force);
    let d = PyDict::new(py);
    d.set_item("stiffness", k)?;
    d.set_item("delta", delta)?;
    d.set_item("a", a)?;
    d.set_item("b", b)?;
    d.set_item("p0", p0)?;
    d.set_item("m", el.m)?;
    Ok(d)
}

/// Johnson's line contact at approach δ (m) for radius R (m), length L (m) and E* (Pa): the
/// force (N) and the stored energy (J).
#[pyfunction]
fn johnson_line(delta: f64, radius: f64, length: f64, e_star: f64) -> PyResult<(f64, f64)> {
    let what = "johnson_line";
    positive(&[("radius", radius), ("length", length), ("E*", e_star)], what)?;
    let x = johnson_x(delta, radius).ok_or_else(|| {
        settings(format!(
            "{what}: delta {delta} m is beyond the law's range (below 4R/e² = {} m)",
            4.0 * radius * (-2f64).exp()
        ))
    })?;
    Ok((std::f64::consts::PI * length * e_star * x, johnson_energy(x, radius, length, e_star)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(complete_elliptic, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_contact, m)?)?;
    m.add_function(wrap_pyfunction!(johnson_line, m)?)?;
    Ok(())
}
