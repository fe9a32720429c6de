//! The simulation binding: runs the loop in Rust with the GIL released, hands the recorded arrays
//! to numpy without copying, and calls Python callables back (slowly) where a model asks for it.

use std::sync::atomic::Ordering;
use std::sync::Arc;

use mechsys_core::error::Error;
use mechsys_core::forces::{Callbacks, VelocityArray};
use mechsys_core::simulate::{Progress, Settings};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{settings, PyMechsysError};
use crate::model::PyModel;

/// Python callables: time functions `f(t) -> float`, force laws `f(t, q, u) -> array(nu)` and
/// the arrays of user velocity constraints (`W(t, q)`, `w(t, q)`, `Wdot(t, q, u)`).
pub struct PyCallbacks {
    pub funcs: Vec<PyObject>,
    pub nu: usize,
}

impl PyCallbacks {
    /// The callables a model refers to; fails if fewer were given than the model uses.
    pub fn for_model(model: &PyModel, cbs: Option<Vec<PyObject>>) -> PyResult<Self> {
        let cb = PyCallbacks { funcs: cbs.unwrap_or_default(), nu: model.model.nu };
        if cb.funcs.len() < model.model.n_callbacks {
            return Err(settings(format!(
                "callbacks: the model refers to {} callbacks, {} given",
                model.model.n_callbacks,
                cb.funcs.len()
            )));
        }
        Ok(cb)
    }

    fn get(&self, id: usize) -> Result<&PyObject, Error> {
        self.funcs.get(id).ok_or_else(|| Error::Callback(format!("callback {id} was not provided")))
    }
}

/// A shape as Python prints it: `(2, 5)`, `(6,)`, `()`.
fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

/// Marks a callback error that is a KeyboardInterrupt (Ctrl-C inside a Python force law), so that
/// it reaches the script as KeyboardInterrupt again instead of as a CallbackError.
pub const INTERRUPTED: &str = "\u{1}KeyboardInterrupt in a callback";

fn py_err(e: PyErr) -> Error {
    Python::with_gil(|py| {
        if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
            return Error::Callback(INTERRUPTED.into());
        }
        let tb = e.traceback(py).and_then(|t| t.format().ok()).unwrap_or_default();
        Error::Callback(format!("{e}{}", if tb.is_empty() { String::new() } else { format!("\n{tb}") }))
    })
}

impl Callbacks for PyCallbacks {
    fn time_function(&self, id: usize, t: f64) -> Result<f64, Error> {
        let f = self.get(id)?;
        Python::with_gil(|py| {
            let v: f64 = f.call1(py, (t,)).and_then(|r| r.extract(py)).map_err(py_err)?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(Error::Callback(format!("time function callback {id} returned {v} at t = {t}")))
            }
        })
    }
    fn generalized_force(&self, id: usize, t: f64, q: &[f64], u: &[f64], out: &mut [f64]) -> Result<(), Error> {
        let f = self.get(id)?;
        Python::with_gil(|py| {
            let qa = PyArray1::from_slice(py, q);
            let ua = PyArray1::from_slice(py, u);
            let r = f.call1(py, (t, qa, ua)).map_err(py_err)?;
            let v: Vec<f64> = r.extract(py).map_err(py_err)?;
            if v.len() != self.nu {
                return Err(Error::Callback(format!(
                    "force callback returned {} values, expected nu = {}",
                    v.len(),
                    self.nu
                )));
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::Callback(format!("force callback returned {} at index {i}, t = {t}", v[i])));
            }
            out.iter_mut().zip(&v).for_each(|(o, x)| *o += x);
            Ok(())
        })
    }
    fn gap_function(&self, id: usize, t: f64, q: &[f64], u: &[f64], grad: &mut [f64]) -> Result<[f64; 3], Error> {
        // the Python side (mechsys.contacts) returns (g, ġ, w̄, ∂g/∂q) from the user's g(q, t)
        let f = self.get(id)?;
        Python::with_gil(|py| {
            let qa = PyArray1::from_slice(py, q);
            let ua = PyArray1::from_slice(py, u);
            let r = f.call1(py, (t, qa, ua)).map_err(py_err)?;
            let (g, gd, wbar, jac): (f64, f64, f64, Vec<f64>) = r.extract(py).map_err(py_err)?;
            if jac.len() != grad.len() {
                return Err(Error::Callback(format!(
                    "gap function callback {id} gave {} derivatives, expected nq = {}",
                    jac.len(),
                    grad.len()
                )));
            }
            grad.copy_from_slice(&jac);
            Ok([g, gd, wbar])
        })
    }
    fn contact_force(&self, id: usize, delta: f64, rate: f64) -> Result<f64, Error> {
        // a compliant contact's user law F(δ, δ̇)
        let f = self.get(id)?;
        Python::with_gil(|py| {
            let r = f.call1(py, (delta, rate)).map_err(py_err)?;
            let v: f64 = r.extract(py).map_err(|_| {
                Error::Callback(format!("contact law callback {id}: expected a number (the normal force in N)"))
            })?;
            if !v.is_finite() {
                return Err(Error::Callback(format!(
                    "contact law callback {id} returned {v} at overlap {delta:e} m, rate {rate:e} m/s"
                )));
            }
            Ok(v)
        })
    }
    fn velocity_constraint(
        &self,
        id: usize,
        which: VelocityArray,
        t: f64,
        q: &[f64],
        u: &[f64],
        rows: usize,
        out: &mut [f64],
    ) -> Result<(), Error> {
        let f = self.get(id)?;
        let label = which.label();
        let nu = self.nu;
        // W is (rows, nu), or (nu,) for one row; w and Wdot (rows,), or a number for one row
        let is_w = which == VelocityArray::W;
        let expected = match (is_w, rows) {
            (true, 1) => format!("(1, {nu}) or ({nu},)"),
            (true, _) => shape_str(&[rows, nu]),
            (false, 1) => "(1,) or a number".to_string(),
            (false, _) => shape_str(&[rows]),
        };
        let accepts = |s: &[usize]| {
            if is_w {
                s == [rows, nu] || (rows == 1 && s == [nu])
            } else {
                s == [rows] || (rows == 1 && s.is_empty())
            }
        };
        Python::with_gil(|py| {
            let qa = PyArray1::from_slice(py, q);
            let called = match which {
                VelocityArray::Rate => f.call1(py, (t, qa, PyArray1::from_slice(py, u))),
                _ => f.call1(py, (t, qa)),
            };
            let r = called.map_err(|e| Error::Callback(format!("{label} raised {}", py_err(e))))?;
            let r = r.bind(py);
            if r.is_none() {
                return Err(Error::Callback(format!("{label} returned None, expected an array of shape {expected}")));
            }
            let not_numbers = || {
                let tn = r.get_type().name().map(|n| n.to_string()).unwrap_or_default();
                Error::Callback(format!(
                    "{label} returned a {tn} that is not an array of numbers, expected shape {expected}"
                ))
            };
            let arr = py
                .import("numpy")
                .and_then(|np| np.call_method1("asarray", (r, "float64")))
                .map_err(|_| not_numbers())?;
            let arr = arr.downcast_into::<PyArrayDyn<f64>>().map_err(|_| not_numbers())?;
            let shape = arr.shape().to_vec();
            if !accepts(&shape) {
                return Err(Error::Callback(format!(
                    "{label} returned shape {}, expected {expected}",
                    shape_str(&shape)
                )));
            }
            let ro = arr.readonly();
            for (k, (o, v)) in out.iter_mut().zip(ro.as_array().iter()).enumerate() {
                if !v.is_finite() {
                    let at =
                        if which == VelocityArray::W { format!("[{}, {}]", k / nu, k % nu) } else { format!("[{k}]") };
                    return Err(Error::Callback(format!("{label} returned {v} at {at}, t = {t}")));
                }
                *o = *v;
            }
            Ok(())
        })
    }
}

/// Progress of a running simulation, readable from another Python thread.
#[pyclass(name = "Progress", module = "mechsys._core", frozen)]
pub struct PyProgress {
    inner: Arc<Progress>,
}

#[pymethods]
impl PyProgress {
    #[new]
    fn new() -> Self {
        PyProgress { inner: Arc::new(Progress::default()) }
    }
    /// Samples recorded so far.
    #[getter]
    fn samples(&self) -> u64 {
        self.inner.samples.load(Ordering::Relaxed)
    }
    /// Ask the running simulation to stop (it raises SolverError).
    fn cancel(&self) {
        self.inner.cancel.store(true, Ordering::Relaxed);
    }
}

/// Runs a simulation; `settings_json` holds t0, t_end, output_dt, integrator, q0, u0.
/// Returns a dict of numpy arrays and the integrator statistics.
#[pyfunction]
#[pyo3(signature = (model, settings_json, callbacks = None, progress = None))]
fn simulate<'py>(
    py: Python<'py>,
    model: &PyModel,
    settings_json: &str,
    callbacks: Option<Vec<PyObject>>,
    progress: Option<&PyProgress>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = parse_settings(settings_json)?;
    let cb = PyCallbacks::for_model(model, callbacks)?;
    let prog = progress.map(|p| p.inner.clone());
    let m = &model.model;
    let rec = py
        .allow_threads(|| mechsys_core::simulate::simulate(m, &s, &cb, prog.as_deref()))
        .map_err(PyMechsysError::from)?;
    recording_dict(py, m, rec)
}

/// Reads the settings of a run from JSON, naming the offending key.
fn parse_settings(settings_json: &str) -> PyResult<Settings> {
    let de = &mut serde_json::Deserializer::from_str(settings_json);
    serde_path_to_error::deserialize(de).map_err(|e| {
        let m = e.inner().to_string();
        let m = m.split(" at line ").next().unwrap_or(&m).to_string();
        settings(format!("settings.{}: {m}", e.path()))
    })
}

/// Runs many simulations on `threads` threads (0: all cores) with the interpreter released:
/// case i is `models[i]` (or the one model) with `settings_json[i]`. The models must need no
/// callbacks. Returns one `(dict, None)` per case that ran (the dict as from `simulate`) or
/// `(None, exception)` for a case that failed (its message starts with `case i:`).
/// `progress`: cancelling it stops every case at its next sample (each then has `cancelled`).
#[pyfunction]
#[pyo3(signature = (models, settings_json, threads = 0, progress = None))]
fn simulate_batch<'py>(
    py: Python<'py>,
    models: Vec<PyRef<'py, PyModel>>,
    settings_json: Vec<String>,
    threads: usize,
    progress: Option<&PyProgress>,
) -> PyResult<Bound<'py, pyo3::types::PyList>> {
    if models.len() != 1 && models.len() != settings_json.len() {
        return Err(settings(format!(
            "simulate_batch: give one model or one per case ({} cases), got {} models",
            settings_json.len(),
            models.len()
        )));
    }
    let mut cases = Vec::with_capacity(settings_json.len());
    for (i, text) in settings_json.iter().enumerate() {
        let s = parse_settings(text).map_err(|e| settings(format!("case {i}: {}", e.value(py))))?;
        let m: &mechsys_core::model::Model = &models[if models.len() == 1 { 0 } else { i }].model;
        cases.push((m, s));
    }
    let prog = progress.map(|p| p.inner.clone());
    let out = py
        .allow_threads(|| mechsys_core::batch::simulate_batch(&cases, threads, prog.as_deref()))
        .map_err(PyMechsysError::from)?;
    let list = pyo3::types::PyList::empty(py);
    for (i, r) in out.into_iter().enumerate() {
        match r {
            Ok(rec) => list.append((recording_dict(py, cases[i].0, rec)?, py.None()))?,
            Err(e) => list.append((py.None(), PyErr::from(PyMechsysError::from(e)).into_value(py)))?,
        }
    }
    Ok(list)
}

/// The recorded signals of a run as a dict of numpy arrays, its events and statistics.
fn recording_dict<'py>(
    py: Python<'py>,
    m: &mechsys_core::model::Model,
    rec: mechsys_core::simulate::Recording,
) -> PyResult<Bound<'py, PyDict>> {
    let n = rec.n_out;
    let nb = rec.n_bodies;
    let d = PyDict::new(py);
    let put = |name: &str, v: Vec<f64>, shape: &[usize]| -> PyResult<()> {
        let a = PyArray1::from_vec(py, v);
        let a = a.reshape(shape.to_vec())?;
        d.set_item(name, a)
    };
    put("t", rec.t, &[n])?;
    put("q", rec.q, &[n, m.nq])?;
    put("u", rec.u, &[n, m.nu])?;
    let sel = rec.selection.clone();
    if sel.accelerations {
        put("udot", rec.udot, &[n, m.nu])?;
    }
    d.set_item("body_index", rec.body_index.clone())?;
    put("body_position", rec.body_position, &[n, nb, 3])?;
    put("body_orientation", rec.body_orientation, &[n, nb, 4])?;
    put("body_velocity", rec.body_velocity, &[n, nb, 3])?;
    put("body_angular_velocity", rec.body_angular_velocity, &[n, nb, 3])?;
    if sel.accelerations {
        put("body_acceleration", rec.body_acceleration, &[n, nb, 3])?;
        put("body_angular_acceleration", rec.body_angular_acceleration, &[n, nb, 3])?;
    }
    put("body_mass", rec.body_mass, &[n, nb])?;
    put("kinetic", rec.kinetic, &[n])?;
    put("body_kinetic", rec.body_kinetic, &[n, nb])?;
    put("potential", rec.potential, &[n])?;
    put("dissipated", rec.dissipated, &[n])?;
    put("external_work", rec.external_work, &[n])?;
    put("momentum_linear", rec.momentum_linear, &[n, 3])?;
    put("momentum_angular", rec.momentum_angular, &[n, 3])?;
    if sel.constraints {
        put("constraint_lambda", rec.constraint_lambda, &[n, m.nc])?;
        put("constraint_violation", rec.constraint_violation, &[n, m.nc])?;
        put("constraint_velocity_violation", rec.constraint_velocity_violation, &[n, m.nc])?;
    }
    if m.n_force_outputs > 0 && sel.forces {
        put("force_value", rec.force_value, &[n, m.n_force_outputs])?;
        put("force_deflection", rec.force_deflection, &[n, m.n_force_outputs])?;
    }
    d.set_item("warnings", rec.warnings)?;
    if let Some(msg) = &rec.cancelled {
        d.set_item("cancelled", msg)?;
    }
    d.set_item("events_json", mechsys_core::simulate::events_json(&rec.events))?;
    let np = m.n_contact_points;
    // (the points' signals only where recorded: a selection without contact signals skips them)
    let points = rec.selection.contacts;
    if (!m.contacts.is_empty() || !m.contact_groups.is_empty()) && points {
        put("contact_gap", rec.contact_gap, &[n, np])?;
        put("contact_point", rec.contact_point, &[n, np, 3])?;
        put("contact_normal", rec.contact_normal, &[n, np, 3])?;
        put("contact_friction", rec.contact_friction, &[n, np, 3])?;
        put("contact_gd_n", rec.contact_gd_n, &[n, np])?;
        put("contact_gd_t", rec.contact_gd_t, &[n, np, 2])?;
        put("contact_omega", rec.contact_omega, &[n, np, 3])?;
        put("contact_lambda_n", rec.contact_lambda_n, &[n, np])?;
        put("contact_lambda_t", rec.contact_lambda_t, &[n, np, 2])?;
        put("contact_impulse_n", rec.contact_impulse_n, &[n, np])?;
        put("contact_impulse_t", rec.contact_impulse_t, &[n, np, 2])?;
        put("contact_state", rec.contact_state, &[n, np])?;
        put("contact_reserve", rec.contact_reserve, &[n, np])?;
    }
    if !m.contacts.is_empty() || !m.contact_groups.is_empty() {
        put("dissipated_impact", rec.dissipated_impact, &[n])?;
        put("dissipated_friction", rec.dissipated_friction, &[n])?;
        put("contact_elastic", rec.contact_elastic, &[n])?;
        put("contact_drift", rec.contact_drift, &[n])?;
        if !rec.solver.is_empty() {
            put("solver", rec.solver, &[n, 5])?;
        }
    }
    let ng = m.contact_groups.len();
    if ng > 0 {
        put("group_closed", rec.group_closed, &[n, ng])?;
        put("group_max_penetration", rec.group_max_penetration, &[n, ng])?;
        put("group_impulse_n", rec.group_impulse_n, &[n, ng])?;
        put("group_pairs", rec.group_pairs, &[n, ng])?;
        put("group_impulse_against", rec.group_impulse_against, &[n, ng, 3])?;
        let total = rec.group_points.len();
        put("group_point_count", rec.group_point_count.iter().map(|&c| c as f64).collect(), &[n, ng])?;
        put("group_points", rec.group_points.iter().flatten().copied().collect(), &[total, 7])?;
    }
    let st = PyDict::new(py);
    st.set_item("steps", rec.stats.steps)?;
    st.set_item("rejected", rec.stats.rejected)?;
    st.set_item("evaluations", rec.stats.evaluations)?;
    st.set_item("jacobians", rec.stats.jacobians)?;
    st.set_item("events", rec.stats.events)?;
    st.set_item("transitions", rec.stats.transitions)?;
    st.set_item("transition_seconds", rec.stats.transition_seconds)?;
    d.set_item("stats", st)?;
    Ok(d)
}

/// Coordinate rates q̇ = H*(q) u (eq. 2.34).
#[pyfunction]
fn qdot<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let q = crate::model::check_len(&q, model.model.nq, "q")?;
    let u = crate::model::check_len(&u, model.model.nu, "u")?;
    let mut out = vec![0.0; model.model.nq];
    model.model.qdot(q, u, &mut out);
    Ok(PyArray1::from_vec(py, out))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyProgress>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_batch, m)?)?;
    m.add_function(wrap_pyfunction!(qdot, m)?)?;
    Ok(())
}
