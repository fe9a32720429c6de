//! Bindings of the dynamics algorithms for single evaluations: CRBA, RNEA, ABA, h, energies.

use mechsys_core::dynamics::{self, energy};
use mechsys_core::forces::Callbacks;
use mechsys_core::kinematics;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{settings, PyMechsysError};
use crate::model::{check_len, fast_slice, q_checked, q_slice, PyModel};
use crate::simulate::PyCallbacks;

fn callbacks(model: &PyModel, cbs: Option<Vec<PyObject>>) -> PyResult<PyCallbacks> {
    PyCallbacks::for_model(model, cbs)
}

/// Mass matrix M(q) by the composite-rigid-body algorithm.
#[pyfunction]
#[pyo3(signature = (model, q, t = 0.0))]
fn crba<'py>(py: Python<'py>, model: &PyModel, q: &Bound<'py, PyAny>, t: f64) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = q_slice(model, q)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    dynamics::crba::mass_matrix(&model.model, &mut data, t, q);
    let n = model.model.nu;
    // M is symmetric, so its column-major storage reads as row-major
    PyArray1::from_slice(py, data.mass_matrix.as_slice()).reshape([n, n])
}

/// Forward dynamics u̇ = M⁻¹(h + τ) by the articulated-body algorithm.
#[pyfunction]
#[pyo3(signature = (model, q, u, tau = None, t = 0.0, callbacks = None, out = None))]
#[allow(clippy::too_many_arguments)]
fn aba<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    u: &Bound<'py, PyAny>,
    tau: Option<&Bound<'py, PyAny>>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
    out: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m = &model.model;
    let q = q_slice(model, q)?;
    let u = fast_slice(u, m.nu, "u")?;
    let tau = match tau {
        Some(a) if !a.is_none() => Some(fast_slice(a, m.nu, "tau")?),
        _ => None,
    };
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let mut ws = model.ws.lock().map_err(|_| settings("model workspace is poisoned"))?;
    if m.n_callbacks == 0 && callbacks.is_none() {
        dynamics::aba(m, &mut data, &mut ws, t, q, u, tau, &mechsys_core::forces::NoCallbacks)
            .map_err(PyMechsysError::from)?;
    } else {
        let cb = self::callbacks(model, callbacks)?;
        dynamics::aba(m, &mut data, &mut ws, t, q, u, tau, &cb).map_err(PyMechsysError::from)?;
    }
    match out {
        // write into the caller's array: no allocation per call
        Some(o) if !o.is_none() => {
            let arr =
                o.downcast_into::<PyArray1<f64>>().map_err(|_| settings("out: must be a 1-D float64 numpy array"))?;
            {
                // SAFETY: the GIL is held and no other Rust reference to the array exists.
                let s = unsafe { arr.as_slice_mut() }.map_err(|_| settings("out: must be contiguous and writeable"))?;
                if s.len() != m.nu {
                    return Err(settings(format!("out: expected length {}, got {}", m.nu, s.len())));
                }
                s.copy_from_slice(&data.udot);
            }
            Ok(arr)
        }
        _ => Ok(PyArray1::from_slice(py, &data.udot)),
    }
}

/// Inverse dynamics τ = M u̇ - h by the recursive Newton–Euler algorithm.
#[pyfunction]
#[pyo3(signature = (model, q, u, udot, t = 0.0, callbacks = None))]
fn rnea<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    udot: PyReadonlyArray1<'py, f64>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let u = check_len(&u, m.nu, "u")?;
    let ud = check_len(&udot, m.nu, "udot")?;
    let cb = self::callbacks(model, callbacks)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let mut ws = model.ws.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let mut tau = vec![0.0; m.nu];
    dynamics::inverse_dynamics(m, &mut data, &mut ws, t, q, u, ud, &cb as &dyn Callbacks, &mut tau)
        .map_err(PyMechsysError::from)?;
    Ok(PyArray1::from_vec(py, tau))
}

/// h(q, u, t): all model forces in generalized components, so that M u̇ = h + τ.
#[pyfunction]
#[pyo3(signature = (model, q, u, t = 0.0, callbacks = None))]
fn nonlinear_effects<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let u = check_len(&u, m.nu, "u")?;
    let cb = self::callbacks(model, callbacks)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let mut ws = model.ws.lock().map_err(|_| settings("model workspace is poisoned"))?;
    dynamics::nonlinear_effects(m, &mut data, &mut ws, t, q, u, &cb).map_err(PyMechsysError::from)?;
    Ok(PyArray1::from_slice(py, data.h.as_slice()))
}

/// The overlaps δ = −g_N (m; negative where open) of the model's explicit compliant contacts'
/// points at (q, u = 0, t), contact by contact and point by point (where their force laws kink).
#[pyfunction]
#[pyo3(signature = (model, q, t = 0.0, callbacks = None))]
fn compliant_overlaps(
    model: &PyModel,
    q: PyReadonlyArray1<'_, f64>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
) -> PyResult<Vec<f64>> {
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let cb = self::callbacks(model, callbacks)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let mut ws = model.ws.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let zero = vec![0.0; m.nu];
    dynamics::nonlinear_effects(m, &mut data, &mut ws, t, q, &zero, &cb).map_err(PyMechsysError::from)?;
    Ok(mechsys_core::forces::compliant_overlaps(m, &data))
}

/// The central difference's position step along a direction, from the compliant overlaps at the
/// point and at ±h (`mechsys_core::linear::difference_step`).
#[pyfunction]
fn difference_step(at: Vec<f64>, plus: Vec<f64>, minus: Vec<f64>, h: f64) -> PyResult<f64> {
    if plus.len() != at.len() || minus.len() != at.len() {
        return Err(settings("difference_step: the three overlap lists must have one length"));
    }
    Ok(mechsys_core::linear::difference_step(&at, &plus, &minus, h))
}

/// Linearization at (q, u, t) into M, D, G, K, N (eq. 2.204) in minimal coordinates: a dict of
/// row-major numpy matrices, the basis `v` (nu × n), the `residual` Vᵀ M u̇ and the `method` the
/// derivatives were taken by (`method`: "auto" exact where the model allows, "exact", or "fd"
/// central differences; see `mechsys_core::linear`).
#[pyfunction]
#[pyo3(signature = (model, q, u, t = 0.0, callbacks = None, method = "auto"))]
#[allow(clippy::too_many_arguments)]
fn linearize<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
    method: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let how = derivatives(method)?;
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let u = check_len(&u, m.nu, "u")?;
    let cb = self::callbacks(model, callbacks)?;
    let lin = mechsys_core::linear::linearize_with(m, t, q, u, &cb, how).map_err(PyMechsysError::from)?;
    let d = PyDict::new(py);
    let n = lin.n;
    for (key, v) in [("M", &lin.m), ("D", &lin.d), ("G", &lin.g), ("K", &lin.k), ("N", &lin.n_mat)] {
        d.set_item(key, PyArray1::from_slice(py, v).reshape([n, n])?)?;
    }
    d.set_item("V", PyArray1::from_slice(py, &lin.v).reshape([m.nu, n])?)?;
    d.set_item("method", lin.method.as_str())?;
    d.set_item("residual", PyArray1::from_slice(py, &lin.residual))?;
    Ok(d)
}

/// The derivatives `linearize` and `state_space` take, from their `method` name.
fn derivatives(method: &str) -> PyResult<mechsys_core::linear::Derivatives> {
    use mechsys_core::linear::Derivatives;
    Derivatives::from_name(method).ok_or_else(|| {
        let allowed = Derivatives::NAMES.map(|n| format!("'{n}'")).join(", ");
        settings(format!("linearize: method must be one of {allowed}, got '{method}'"))
    })
}

/// The state form `x' = A x + B tau` about a (moving) state (see `mechsys_core::linear::motion`):
/// `A`, `B`, the bases `Vh`, `P`, `V` and left inverses `Lh`, `Lu`, the reference's rates, the
/// invariance defect and the velocity-constraint violation. `prefer`: None for orthonormal bases,
/// else a partition into joint coordinates keeping these velocity indices independent.
#[pyfunction]
#[pyo3(signature = (model, q, u, t = 0.0, callbacks = None, method = "auto", prefer = None))]
#[allow(clippy::too_many_arguments)]
fn state_space<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
    method: &str,
    prefer: Option<Vec<usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    use mechsys_core::linear::Basis;
    let how = derivatives(method)?;
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let u = check_len(&u, m.nu, "u")?;
    if let Some(k) = prefer.as_ref().and_then(|p| p.iter().find(|&&k| k >= m.nu)) {
        return Err(settings(format!("linearize: coordinate index {k} out of range 0..{}", m.nu)));
    }
    let basis = prefer.map_or(Basis::Orthonormal, Basis::Partition);
    let cb = self::callbacks(model, callbacks)?;
    let s = mechsys_core::linear::state_space(m, t, q, u, &cb, how, &basis).map_err(PyMechsysError::from)?;
    let d = PyDict::new(py);
    let (n1, n2, nu) = (s.nq, s.nu, m.nu);
    let nx = n1 + n2;
    for (key, v, r, c) in [
        ("A", &s.a, nx, nx),
        ("B", &s.b, nx, nu),
        ("Vh", &s.vh, nu, n1),
        ("P", &s.p, nu, n1),
        ("V", &s.v, nu, n2),
        ("Lh", &s.lh, n1, nu),
        ("Lu", &s.lu, n2, nu),
    ] {
        d.set_item(key, PyArray1::from_slice(py, v).reshape([r, c])?)?;
    }
    d.set_item("rate", PyArray1::from_slice(py, &s.rate))?;
    d.set_item("mass", PyArray1::from_slice(py, &s.mass).reshape([nu, nu])?)?;
    d.set_item("independent_q", s.independent_q.clone())?;
    d.set_item("independent_u", s.independent_u.clone())?;
    d.set_item("defect", s.defect)?;
    d.set_item("phi", PyArray1::from_slice(py, &s.phi))?;
    d.set_item("velocity_residual", PyArray1::from_slice(py, &s.velocity_residual))?;
    d.set_item("method", s.method.as_str())?;
    Ok(d)
}

/// Energies and momenta at (q, u, t): kinetic and potential energy (total and per body), linear
/// momentum and moment of momentum about `point` (total and per body).
#[pyfunction]
#[pyo3(signature = (model, q, u, t = 0.0, point = [0.0, 0.0, 0.0]))]
fn energies<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    t: f64,
    point: [f64; 3],
) -> PyResult<Bound<'py, PyDict>> {
    if point.iter().any(|x| !x.is_finite()) {
        return Err(settings(format!("point: must be finite, got {point:?}")));
    }
    let m = &model.model;
    let q = q_checked(model, &q)?;
    let u = check_len(&u, m.nu, "u")?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    kinematics::forward_kinematics(m, &mut data, q, u);
    kinematics::inertias(m, &mut data, t);
    let d = PyDict::new(py);
    d.set_item("kinetic", energy::kinetic_energy(m, &data))?;
    d.set_item("potential", energy::potential_energy(m, &data, q))?;
    let per_body: Vec<f64> = (1..m.nbodies()).map(|i| energy::body_kinetic_energy(m, &data, i)).collect();
    d.set_item("kinetic_per_body", PyArray1::from_vec(py, per_body))?;
    let gravity: Vec<f64> = (1..m.nbodies()).map(|i| energy::body_gravity_energy(m, &data, i)).collect();
    d.set_item("gravity_per_body", PyArray1::from_vec(py, gravity))?;
    // moment of momentum about a fixed point P: L_P = L_O - r_P × p (section 2.3.3)
    let rp = mechsys_core::math::Vec3::from(point);
    let (p, l) = energy::momentum(m, &data);
    d.set_item("momentum_linear", PyArray1::from_slice(py, p.as_slice()))?;
    d.set_item("momentum_angular", PyArray1::from_slice(py, (l - rp.cross(&p)).as_slice()))?;
    let mut pl = Vec::with_capacity(m.nbodies() - 1);
    let mut pa = Vec::with_capacity(m.nbodies() - 1);
    for i in 1..m.nbodies() {
        let h = data.inertia[i].mul_motion(&data.v[i]);
        pl.push(h.f.as_slice().to_vec());
        pa.push((h.n - rp.cross(&h.f)).as_slice().to_vec());
    }
    if m.nbodies() > 1 {
        d.set_item("momentum_linear_per_body", PyArray2::from_vec2(py, &pl).map_err(|e| settings(e.to_string()))?)?;
        d.set_item("momentum_angular_per_body", PyArray2::from_vec2(py, &pa).map_err(|e| settings(e.to_string()))?)?;
    }
    Ok(d)
}

/// Checks that each named value is finite and > 0, naming the first that is not.
fn positive(values: &[(&str, f64)], what: &str) -> PyResult<()> {
    match values.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
        Some((k, v)) => Err(settings(format!("{what}: {k} must be > 0, got {v}"))),
        None => Ok(()),
    }
}

/// Torque per shaft speed of eq. 2.212 (the engine's law), checked like the element's input.
#[pyfunction]
#[pyo3(signature = (radius, length, clearance, eta, eccentricity=0.0))]
fn journal_bearing_coefficient(radius: f64, length: f64, clearance: f64, eta: f64, eccentricity: f64) -> PyResult<f64> {
    use mechsys_core::forces::damping::{journal_bearing_coefficient as c, MAX_ECCENTRICITY};
    let what = "journal_bearing_coefficient";
    positive(&[("radius", radius), ("length", length), ("clearance", clearance), ("eta", eta)], what)?;
    if !(eccentricity.is_finite() && (0.0..=MAX_ECCENTRICITY).contains(&eccentricity)) {
        return Err(settings(format!("{what}: eccentricity must lie in [0, {MAX_ECCENTRICITY}], got {eccentricity}")));
    }
    Ok(c(radius, length, clearance, eta, eccentricity))
}

/// `12 η A l²` of eq. 2.211 (the engine's law): the film force per gap rate times h³.
#[pyfunction]
fn squeeze_film_coefficient(eta: f64, length: f64, area: f64) -> PyResult<f64> {
    positive(&[("eta", eta), ("length", length), ("area", area)], "squeeze_film_coefficient")?;
    Ok(mechsys_core::forces::damping::squeeze_film_coefficient(eta, length, area))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(journal_bearing_coefficient, m)?)?;
    m.add_function(wrap_pyfunction!(squeeze_film_coefficient, m)?)?;
    m.add_function(wrap_pyfunction!(crba, m)?)?;
    m.add_function(wrap_pyfunction!(aba, m)?)?;
    m.add_function(wrap_pyfunction!(rnea, m)?)?;
    m.add_function(wrap_pyfunction!(nonlinear_effects, m)?)?;
    m.add_function(wrap_pyfunction!(compliant_overlaps, m)?)?;
    m.add_function(wrap_pyfunction!(difference_step, m)?)?;
    m.add_function(wrap_pyfunction!(energies, m)?)?;
    m.add_function(wrap_pyfunction!(linearize, m)?)?;
    m.add_function(wrap_pyfunction!(state_space, m)?)?;
    register_reactions(m)?;
    register_constraints(m)?;
    register_constraint_gamma(m)?;
    register_contact_matrices(m)
}

/// Joint reaction wrenches for a whole recorded run: for each sample (t, q, u, udot) the wrench
/// the parent exerts on the child through every joint, at the joint origin, in child-joint-frame
/// components. Returns (force, torque), each (n_samples × n_joints × 3).
#[pyfunction]
#[pyo3(signature = (model, t, q, u, udot, callbacks = None))]
fn joint_reactions<'py>(
    py: Python<'py>,
    model: &PyModel,
    t: PyReadonlyArray1<'py, f64>,
    q: numpy::PyReadonlyArray2<'py, f64>,
    u: numpy::PyReadonlyArray2<'py, f64>,
    udot: numpy::PyReadonlyArray2<'py, f64>,
    callbacks: Option<Vec<PyObject>>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let m = &model.model;
    let t = t.as_slice().map_err(|_| settings("t: must be a contiguous float64 array"))?;
    let n = t.len();
    let shape_ok = |a: &numpy::PyReadonlyArray2<'py, f64>, cols: usize| a.shape() == [n, cols];
    if !shape_ok(&q, m.nq) || !shape_ok(&u, m.nu) || !shape_ok(&udot, m.nu) {
        return Err(settings(format!("q, u, udot: expected shapes ({n}, {}), ({n}, {}), ({n}, {})", m.nq, m.nu, m.nu)));
    }
    let (q, u, udot) = (
        q.as_slice().map_err(|_| settings("q: must be C-contiguous"))?,
        u.as_slice().map_err(|_| settings("u: must be C-contiguous"))?,
        udot.as_slice().map_err(|_| settings("udot: must be C-contiguous"))?,
    );
    let cb = self::callbacks(model, callbacks)?;
    let nj = m.joints.len();
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let mut ws = model.ws.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let mut fo = vec![mechsys_core::math::Vec3::zeros(); nj];
    let mut to = vec![mechsys_core::math::Vec3::zeros(); nj];
    let mut force = Vec::with_capacity(n * nj * 3);
    let mut torque = Vec::with_capacity(n * nj * 3);
    for k in 0..n {
        let (qk, uk, ak) =
            (&q[k * m.nq..(k + 1) * m.nq], &u[k * m.nu..(k + 1) * m.nu], &udot[k * m.nu..(k + 1) * m.nu]);
        m.check_q(qk, "q").map_err(PyMechsysError::from)?;
        dynamics::joint_reactions(m, &mut data, &mut ws, t[k], qk, uk, ak, &cb, &mut fo, &mut to)
            .map_err(PyMechsysError::from)?;
        for j in 0..nj {
            force.extend_from_slice(fo[j].as_slice());
            torque.extend_from_slice(to[j].as_slice());
        }
    }
    Ok((PyArray1::from_vec(py, force), PyArray1::from_vec(py, torque)))
}

pub fn register_reactions(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(joint_reactions, m)?)
}

/// Constraint violation Φ (nc) and its Jacobian G = Wᵀ (nc × nu, so that Φ̇ = G u - b) at (q, t),
/// plus the velocity right-hand side b (nc) — eq. 2.70.
#[pyfunction]
#[pyo3(signature = (model, q, t = 0.0, callbacks = None))]
fn constraint_jacobian<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
    let m = &model.model;
    let q = q_slice(model, q)?;
    let cb = self::callbacks(model, callbacks)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    kinematics::positions(m, &mut data, q);
    mechsys_core::constraints::positions(m, &mut data, t, q, &cb).map_err(PyMechsysError::from)?;
    let rows: Vec<Vec<f64>> = (0..m.nc).map(|r| (0..m.nu).map(|c| data.g[(r, c)]).collect()).collect();
    let g = if m.nc == 0 {
        PyArray2::zeros(py, [0, m.nu], false)
    } else {
        PyArray2::from_vec2(py, &rows).map_err(|e| settings(e.to_string()))?
    };
    Ok((PyArray1::from_slice(py, &data.phi), g, PyArray1::from_slice(py, &data.b)))
}

pub fn register_constraints(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(constraint_jacobian, m)?)
}

/// Acceleration right-hand side γ of the constraints, G u̇ = γ, at (q, u, t) (nc).
#[pyfunction]
#[pyo3(signature = (model, q, u, t = 0.0, callbacks = None))]
fn constraint_gamma<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    u: &Bound<'py, PyAny>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m = &model.model;
    let q = q_slice(model, q)?;
    let u = fast_slice(u, m.nu, "u")?;
    let cb = self::callbacks(model, callbacks)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    kinematics::forward_kinematics(m, &mut data, q, u);
    mechsys_core::constraints::positions(m, &mut data, t, q, &cb).map_err(PyMechsysError::from)?;
    data.a[0] = mechsys_core::spatial::Motion::ZERO;
    let zero = vec![0.0; m.nu];
    kinematics::accelerations(m, &mut data, &zero);
    mechsys_core::constraints::accelerations(m, &mut data, t, q, u, &cb).map_err(PyMechsysError::from)?;
    Ok(PyArray1::from_slice(py, &data.gamma))
}

pub fn register_constraint_gamma(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(constraint_gamma, m)?)
}

/// The contact matrices at (q, u, t) for every contact point: gaps, relative velocities, the rows
/// W (points × 3 × nu: normal, t1, t2), the Delassus matrix Wᵀ M̃⁻¹ W (3 points square, with the
/// bilateral constraints' reactions), w̄ and the free relative accelerations (points × 3).
#[pyfunction]
#[pyo3(signature = (model, q, u, t = 0.0, callbacks = None))]
fn contact_matrices<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    u: &Bound<'py, PyAny>,
    t: f64,
    callbacks: Option<Vec<PyObject>>,
) -> PyResult<Bound<'py, PyDict>> {
    use mechsys_core::integrator::event_driven::{Options, Phase};
    let m = &model.model;
    let q = q_slice(model, q)?;
    let u = fast_slice(u, m.nu, "u")?;
    // (q is checked by q_slice; a non-finite u or t would come back as NaN matrices)
    if let Some(k) = u.iter().position(|v| !v.is_finite()) {
        return Err(settings(format!("u[{k}]: must be finite, got {}", u[k])));
    }
    if !t.is_finite() {
        return Err(settings(format!("t: must be finite, got {t}")));
    }
    let cb = self::callbacks(model, callbacks)?;
    let mut phase = Phase::new(m, &cb, Options::default()).map_err(PyMechsysError::from)?;
    let c = phase.contact_matrices(t, q, u).map_err(PyMechsysError::from)?;
    let np = c.points;
    let d = PyDict::new(py);
    let shaped = |v: Vec<f64>, shape: &[usize]| -> PyResult<Bound<'py, PyAny>> {
        Ok(PyArray1::from_vec(py, v).reshape(shape.to_vec())?.into_any())
    };
    let names: Vec<String> = (0..np).map(|pt| m.contact_of_point(pt).name.clone()).collect();
    d.set_item("contact", names)?;
    d.set_item("gap", shaped(c.gap, &[np])?)?;
    d.set_item("velocity", shaped(c.velocity, &[np, 3])?)?;
    d.set_item("w", shaped(c.w, &[np, 3, m.nu])?)?;
    d.set_item("delassus", shaped(c.delassus, &[3 * np, 3 * np])?)?;
    d.set_item("wbar", shaped(c.wbar, &[np, 3])?)?;
    d.set_item("free_acceleration", shaped(c.free_acceleration, &[np, 3])?)?;
    Ok(d)
}

pub fn register_contact_matrices(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(contact_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(contact_geometry, m)?)
}

/// The contact geometry at q for every candidate point of the explicit contour contacts: gap, the
/// witness points on each contour, the normal and tangents, and each contour's principal
/// curvatures at its witness point (planar contours: [κ, 0]; ∞ at points, vertices, edges).
#[pyfunction]
fn contact_geometry<'py>(py: Python<'py>, model: &PyModel, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    use mechsys_core::contact::{evaluate, ContactPoint};
    let m = &model.model;
    let q = q_slice(model, q)?;
    let mut data = model.data.lock().map_err(|_| settings("model workspace is poisoned"))?;
    let zero = vec![0.0; m.nu];
    kinematics::forward_kinematics(m, &mut data, q, &zero);
    let (mut names, mut gap) = (Vec::new(), Vec::new());
    let (mut p1, mut p2, mut n, mut t1, mut t2, mut k1, mut k2) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut krel = Vec::new();
    for con in &m.contacts {
        // gap contacts have no contours (their gap and rows: contact_matrices)
        let (Some(pair), Some(contours)) = (con.pair(), con.contours()) else { continue };
        let mut pts = vec![ContactPoint::default(); pair.candidates()];
        let (x1, x2) = (data.x_abs[con.body1], data.x_abs[con.body2]);
        evaluate(pair, &x1, &x2, &mut pts).map_err(PyMechsysError::from)?;
        for c in &pts {
            names.push(con.name.clone());
            gap.push(c.g_n);
            p1.extend_from_slice(c.p1.as_slice());
            p2.extend_from_slice(c.p2.as_slice());
            n.extend_from_slice(c.n.as_slice());
            t1.extend_from_slice(c.t1.as_slice());
            t2.extend_from_slice(c.t2.as_slice());
            k1.extend_from_slice(&contours[0].curvatures_at(&x1, &c.p1));
            k2.extend_from_slice(&contours[1].curvatures_at(&x2, &c.p2));
            // the principal values of the two surfaces' curvature tensors summed in the common
            // tangent plane: what a Hertz contact feels whatever angle the principal directions
            // make (∞ where a contour has no curvature)
            let tensor =
                |k: usize, x: &mechsys_core::spatial::Pose, p| contours[k].curvature_tensor_at(x, p, &c.t1, &c.t2);
            match (tensor(0, &x1, &c.p1), tensor(1, &x2, &c.p2)) {
                (Some(a), Some(b)) => {
                    let (s11, s12, s22) = (a[0] + b[0], a[1] + b[1], a[2] + b[2]);
                    let (m, d) = (0.5 * (s11 + s22), (0.25 * (s11 - s22).powi(2) + s12 * s12).sqrt());
                    krel.extend_from_slice(&[m - d, m + d]);
                }
                _ => krel.extend_from_slice(&[f64::INFINITY; 2]),
            }
        }
    }
    let np = gap.len();
    let d = PyDict::new(py);
    let shaped = |v: Vec<f64>, shape: &[usize]| -> PyResult<Bound<'py, PyAny>> {
        Ok(PyArray1::from_vec(py, v).reshape(shape.to_vec())?.into_any())
    };
    d.set_item("contact", names)?;
    d.set_item("gap", shaped(gap, &[np])?)?;
    d.set_item("point1", shaped(p1, &[np, 3])?)?;
    d.set_item("point2", shaped(p2, &[np, 3])?)?;
    d.set_item("normal", shaped(n, &[np, 3])?)?;
    d.set_item("tangent1", shaped(t1, &[np, 3])?)?;
    d.set_item("tangent2", shaped(t2, &[np, 3])?)?;
    d.set_item("curvature1", shaped(k1, &[np, 2])?)?;
    d.set_item("curvature2", shaped(k2, &[np, 2])?)?;
    d.set_item("relative_curvature", shaped(krel, &[np, 2])?)?;
    Ok(d)
}
