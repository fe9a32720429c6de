//! Bindings of the contact geometry (`mechsys_core::geometry`) for `mechsys.contours`: the
//! geometry of an involute gear contour as the engine builds it.

use mechsys_core::geometry::curve::Curve;
use mechsys_core::model::contact::{gear_spec, planar_curve};
use mechsys_core::model::contact_description::{ContourDescription, GearDescription};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::PyMechsysError;

/// A contour table from its JSON; errors name `what` and the key path.
fn parse<T: serde::de::DeserializeOwned>(description: &str, what: &str) -> PyResult<T> {
    let de = &mut serde_json::Deserializer::from_str(description);
    serde_path_to_error::deserialize(de).map_err(|e| {
        let m = e.inner().to_string();
        let m = m.split(" at line ").next().unwrap_or(&m).to_string();
        PyMechsysError(mechsys_core::Error::Model(format!("{what}.{}: {m}", e.path()))).into()
    })
}

/// Radii, roll angles, roundings and parameter lengths of the gear described by `description`
/// (the JSON of a `type = "gear"` contour table without its `type`), and `samples` points of its
/// outline (body frame, `samples × 2`, at equal steps of the arc-length parameter from 0).
#[pyfunction]
#[pyo3(signature = (description, what, samples = 0))]
fn gear_geometry<'py>(py: Python<'py>, description: &str, what: &str, samples: usize) -> PyResult<Bound<'py, PyDict>> {
    let d: GearDescription = parse(description, what)?;
    let spec = gear_spec(&d, what).map_err(PyMechsysError::from)?;
    let curve = Curve::gear(&spec, what).map_err(PyMechsysError::from)?;
    let g = curve.as_gear().expect("a gear contour");
    let out = PyDict::new(py);
    let s = g.spec();
    out.set_item("module", s.module)?;
    out.set_item("teeth", s.teeth)?;
    out.set_item("pressure_angle", s.pressure_angle)?;
    out.set_item("shift", s.shift)?;
    out.set_item("backlash", s.backlash)?;
    out.set_item("pitch_radius", g.pitch_radius())?;
    out.set_item("base_radius", g.base_radius())?;
    out.set_item("tip_radius", g.tip_radius())?;
    out.set_item("root_radius", g.root_radius())?;
    out.set_item("base_half_angle", g.base_half_angle())?;
    out.set_item("roll_range", g.roll_range())?;
    out.set_item("tip_rounding", g.roundings().0)?;
    out.set_item("root_fillet", g.roundings().1)?;
    out.set_item("segment", g.has_segment())?;
    out.set_item("tooth_length", g.tooth_length())?;
    out.set_item("perimeter", g.period())?;
    if samples > 0 {
        let pts: Vec<Vec<f64>> = (0..samples)
            .map(|i| {
                let p = g.eval(g.period() * i as f64 / samples as f64)[0];
                vec![p.x, p.y]
            })
            .collect();
        out.set_item("outline", PyArray2::from_vec2(py, &pts)?)?;
    }
    Ok(out)
}

/// `samples` points (body frame, `samples × 2`) of the planar curve contour `description` (the
/// JSON of a contour table: ellipse, spline, cam or gear) at equal parameter steps, with the
/// roller offset of a cam included; an open spline is sampled between its first and last points.
/// For drawing (the viewer).
#[pyfunction]
#[pyo3(signature = (description, what, samples = 400))]
fn curve_outline<'py>(
    py: Python<'py>,
    description: &str,
    what: &str,
    samples: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let d: ContourDescription = parse(description, what)?;
    if !(2..=1_000_000).contains(&samples) {
        return Err(PyMechsysError(mechsys_core::Error::Model(format!(
            "{what}: samples must be 2 to 1e6, got {samples}"
        )))
        .into());
    }
    let curve = planar_curve(&d, what).map_err(PyMechsysError::from)?;
    let (lo, hi) = curve.range();
    // a closed curve's end is its start: not repeated
    let n = if curve.is_closed() { samples } else { samples - 1 };
    let pts: Vec<Vec<f64>> = (0..samples)
        .map(|i| {
            let p = curve.frame(lo + (hi - lo) * i as f64 / n as f64).point;
            vec![p.x, p.y]
        })
        .collect();
    Ok(PyArray2::from_vec2(py, &pts)?)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(gear_geometry, m)?)?;
    m.add_function(wrap_pyfunction!(curve_outline, m)?)
}
