//! Bindings of the small-matrix kinematics library: rotation parametrizations and their
//! angular-velocity matrices (`math::rotation`, eqs. 2.8–2.19, 2.30–2.34), the tilde operator
//! (eqs. 2.36, 2.37) and the relative kinematics of moving frames (`math::frames`, eqs. 2.10,
//! 2.11, 2.28, 2.38, 2.41–2.44).
//!
//! Every function keeps the engine's name and argument names. Arguments are read from anything
//! `numpy.asarray(x, dtype=float)` accepts and checked here before they reach the engine: shape,
//! finiteness, and unit length where the engine assumes it (quaternions fed to `quat_to_matrix`,
//! `quat_rotate`, the quaternion rates; rotation axes). A failed check raises `SettingsError` (a
//! `ValueError`) naming the argument, e.g. `"a_ib: expected a 3x3 matrix, got an array of shape
//! (3,)"`. Engine errors keep their class (`SingularityError` for `H*` at its singularity,
//! `ModelError` for a matrix that is not a rotation), with the argument name prefixed to the
//! engine's message where an argument is at fault.

use mechsys_core::math::rotation::{self as rot, AngleSet, Quat};
use mechsys_core::math::{self as mmath, frames, Mat3, Vec3};
use mechsys_core::Error;
use nalgebra::{Dim, Matrix, RawStorage};
use numpy::ndarray::Array2;
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLikeDyn};
use pyo3::prelude::*;

use crate::errors::{settings, PyMechsysError};

/// Largest `| |x| − 1 |` accepted for arguments that must be unit quaternions or unit axes.
const UNIT_TOL: f64 = 1e-6;

type PyVec<'py> = Bound<'py, PyArray1<f64>>;
type PyMat<'py> = Bound<'py, PyArray2<f64>>;

// ---------------------------------------------------------------------------------------------
// Argument reading and checking
// ---------------------------------------------------------------------------------------------

/// `repr(obj)`, shortened for error messages.
fn short_repr(obj: &Bound<'_, PyAny>) -> String {
    let r = obj.repr().map(|r| r.to_string()).unwrap_or_else(|_| "<unprintable>".into());
    if r.chars().count() > 60 {
        format!("{}...", r.chars().take(57).collect::<String>())
    } else {
        r
    }
}

/// A numpy shape as Python prints it: `(3,)`, `(3, 3)`.
fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

fn as_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    expected: &str,
) -> PyResult<PyArrayLikeDyn<'py, f64, AllowTypeChange>> {
    obj.extract::<PyArrayLikeDyn<'py, f64, AllowTypeChange>>()
        .map_err(|_| settings(format!("{name}: expected {expected}, got {}", short_repr(obj))))
}

/// `N` finite numbers (shape `(N,)`).
fn fixed<const N: usize>(obj: &Bound<'_, PyAny>, name: &str, expected: &str) -> PyResult<[f64; N]> {
    let a = as_array(obj, name, expected)?;
    let view = a.as_array();
    if view.shape() != [N] {
        return Err(settings(format!(
            "{name}: expected {expected}, got an array of shape {}",
            shape_str(view.shape())
        )));
    }
    let mut out = [0.0; N];
    for (i, (o, v)) in out.iter_mut().zip(view.iter()).enumerate() {
        if !v.is_finite() {
            return Err(settings(format!("{name}[{i}]: must be finite, got {v}")));
        }
        *o = *v;
    }
    Ok(out)
}

/// A finite 3-vector (shape `(3,)`).
fn vec3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec3> {
    fixed::<3>(obj, name, "a 3-vector").map(Vec3::from)
}

/// Three finite angles (shape `(3,)`).
fn angles3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 3]> {
    fixed::<3>(obj, name, "3 angles")
}

/// A finite quaternion `[w, x, y, z]` of any nonzero norm.
fn quat(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Quat> {
    fixed::<4>(obj, name, "a quaternion [w, x, y, z]")
}

/// A finite quaternion with `| |q| − 1 | ≤ UNIT_TOL`.
fn unit_quat(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Quat> {
    let q = quat(obj, name)?;
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if (n - 1.0).abs() > UNIT_TOL {
        return Err(settings(format!(
            "{name}: must be a unit quaternion, got norm {n} (normalize it with quat_normalize)"
        )));
    }
    Ok(q)
}

/// A finite quaternion that is not (numerically) zero, for conversions that normalize implicitly.
fn nonzero_quat(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Quat> {
    let q = quat(obj, name)?;
    let m = q.iter().fold(0.0_f64, |acc, c| acc.max(c.abs()));
    if m <= 1e-12 {
        return Err(settings(format!("{name}: the zero quaternion describes no rotation")));
    }
    Ok(q)
}

/// A finite 3-vector of unit length (within `UNIT_TOL`).
fn unit_axis(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec3> {
    let a = vec3(obj, name)?;
    let n = a.norm();
    if (n - 1.0).abs() > UNIT_TOL {
        return Err(settings(format!("{name}: must be a unit vector, got norm {n}")));
    }
    Ok(a)
}

/// A 3×3 matrix; finite entries unless `allow_nonfinite`.
fn mat3_with(obj: &Bound<'_, PyAny>, name: &str, allow_nonfinite: bool) -> PyResult<Mat3> {
    let a = as_array(obj, name, "a 3x3 matrix")?;
    let view = a.as_array();
    if view.shape() != [3, 3] {
        return Err(settings(format!(
            "{name}: expected a 3x3 matrix, got an array of shape {}",
            shape_str(view.shape())
        )));
    }
    let mut out = Mat3::zeros();
    for ((r, c), v) in view.indexed_iter().map(|(ix, v)| ((ix[0], ix[1]), *v)) {
        if !allow_nonfinite && !v.is_finite() {
            return Err(settings(format!("{name}[{r}, {c}]: must be finite, got {v}")));
        }
        out[(r, c)] = v;
    }
    Ok(out)
}

/// A finite 3×3 matrix.
fn mat3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Mat3> {
    mat3_with(obj, name, false)
}

/// A finite 3×3 proper rotation matrix (`check_rotation_matrix` with `ROTATION_MATRIX_TOL`).
fn rotation(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Mat3> {
    let a = mat3(obj, name)?;
    rot::check_rotation_matrix(&a, rot::ROTATION_MATRIX_TOL).map_err(named(name))?;
    Ok(a)
}

/// A finite number.
fn scalar(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<f64> {
    let v: f64 = obj.extract().map_err(|_| settings(format!("{name}: expected a number, got {}", short_repr(obj))))?;
    if !v.is_finite() {
        return Err(settings(format!("{name}: must be finite, got {v}")));
    }
    Ok(v)
}

fn angle_set(s: &str) -> PyResult<AngleSet> {
    match s {
        "euler_zxz" => Ok(AngleSet::EulerZxz),
        "cardan_xyz" => Ok(AngleSet::CardanXyz),
        _ => Err(settings(format!("angle_set: expected 'euler_zxz' or 'cardan_xyz', got '{s}'"))),
    }
}

/// Engine error → Python exception, with the argument at fault named in front of the engine's
/// message for errors about the argument's value (`Error::Model`).
fn named(name: &str) -> impl Fn(Error) -> PyErr + '_ {
    move |e| {
        let e = match e {
            Error::Model(msg) => Error::Model(format!("{name}: {msg}")),
            other => other,
        };
        PyMechsysError(e).into()
    }
}

fn engine(e: Error) -> PyErr {
    PyMechsysError(e).into()
}

// ---------------------------------------------------------------------------------------------
// Results
// ---------------------------------------------------------------------------------------------

fn vec_out<'py>(py: Python<'py>, v: &[f64]) -> PyVec<'py> {
    PyArray1::from_slice(py, v)
}

fn mat_out<'py, R: Dim, C: Dim, S: RawStorage<f64, R, C>>(py: Python<'py>, m: &Matrix<f64, R, C, S>) -> PyMat<'py> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(r, c)| m[(r, c)]).into_pyarray(py)
}

// ---------------------------------------------------------------------------------------------
// Elementary rotations, tilde
// ---------------------------------------------------------------------------------------------

/// Elementary rotation about the x-axis (the form of eqs. 2.13, 2.16).
#[pyfunction]
fn rot_x<'py>(py: Python<'py>, angle: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::rot_x(scalar(angle, "angle")?)))
}

/// Elementary rotation about the y-axis (the form of eq. 2.17).
#[pyfunction]
fn rot_y<'py>(py: Python<'py>, angle: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::rot_y(scalar(angle, "angle")?)))
}

/// Elementary rotation about the z-axis (the form of eqs. 2.12, 2.14, 2.18).
#[pyfunction]
fn rot_z<'py>(py: Python<'py>, angle: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::rot_z(scalar(angle, "angle")?)))
}

/// Rotation by `angle` about the unit vector `axis` (Rodrigues' formula).
#[pyfunction]
fn rot_axis<'py>(py: Python<'py>, axis: &Bound<'py, PyAny>, angle: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    let axis = unit_axis(axis, "axis")?;
    Ok(mat_out(py, &rot::rot_axis(&axis, scalar(angle, "angle")?)))
}

/// The angle mapped to (−π, π].
#[pyfunction]
fn wrap_angle(angle: &Bound<'_, PyAny>) -> PyResult<f64> {
    Ok(rot::wrap_angle(scalar(angle, "angle")?))
}

/// Raises ModelError unless `a_ib` is a proper rotation matrix within `tol`.
#[pyfunction]
#[pyo3(signature = (a_ib, tol = None))]
fn check_rotation_matrix(a_ib: &Bound<'_, PyAny>, tol: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
    // non-finite entries are one of the properties checked, reported by the engine
    let a = mat3_with(a_ib, "a_ib", true)?;
    let tol = tol.map(|t| scalar(t, "tol")).transpose()?.unwrap_or(rot::ROTATION_MATRIX_TOL);
    if tol < 0.0 {
        return Err(settings(format!("tol: must be >= 0, got {tol}")));
    }
    rot::check_rotation_matrix(&a, tol).map_err(named("a_ib"))
}

/// The skew-symmetric matrix ã with ã b = a × b (eq. 2.36).
#[pyfunction]
fn tilde<'py>(py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &mmath::tilde(&vec3(a, "a")?)))
}

/// The vector of a skew-symmetric matrix (inverse of tilde; the symmetric part is ignored).
#[pyfunction]
fn untilde<'py>(py: Python<'py>, m: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, mmath::untilde(&mat3(m, "m")?).as_slice()))
}

// ---------------------------------------------------------------------------------------------
// Euler and Cardan angles
// ---------------------------------------------------------------------------------------------

/// A_IB of Euler angles [ψ, ϑ, φ] = Rz(ψ) Rx(ϑ) Rz(φ) (eq. 2.15).
#[pyfunction]
fn euler_zxz_to_matrix<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::euler_zxz_to_matrix(angles3(angles, "angles")?)))
}

/// Euler angles [ψ, ϑ, φ] of a rotation matrix A_IB.
#[pyfunction]
fn matrix_to_euler_zxz<'py>(py: Python<'py>, a_ib: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    let e = rot::matrix_to_euler_zxz(&mat3(a_ib, "a_ib")?).map_err(named("a_ib"))?;
    Ok(vec_out(py, &e))
}

/// A_IB of Cardan angles [α, β, γ] = Rx(α) Ry(β) Rz(γ) (eq. 2.19).
#[pyfunction]
fn cardan_xyz_to_matrix<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::cardan_xyz_to_matrix(angles3(angles, "angles")?)))
}

/// Cardan angles [α, β, γ] of a rotation matrix A_IB.
#[pyfunction]
fn matrix_to_cardan_xyz<'py>(py: Python<'py>, a_ib: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    let c = rot::matrix_to_cardan_xyz(&mat3(a_ib, "a_ib")?).map_err(named("a_ib"))?;
    Ok(vec_out(py, &c))
}

/// Cardan angles of the rotation given by Euler angles.
#[pyfunction]
fn euler_zxz_to_cardan_xyz<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::euler_zxz_to_cardan_xyz(angles3(angles, "angles")?)))
}

/// Euler angles of the rotation given by Cardan angles.
#[pyfunction]
fn cardan_xyz_to_euler_zxz<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::cardan_xyz_to_euler_zxz(angles3(angles, "angles")?)))
}

// ---------------------------------------------------------------------------------------------
// Quaternions
// ---------------------------------------------------------------------------------------------

/// A_IB of a unit quaternion [w, x, y, z].
#[pyfunction]
fn quat_to_matrix<'py>(py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::quat_to_matrix(unit_quat(q, "q")?)))
}

/// Unit quaternion (w ≥ 0) of a rotation matrix A_IB (Shepperd's method).
#[pyfunction]
fn matrix_to_quat<'py>(py: Python<'py>, a_ib: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    let q = rot::matrix_to_quat(&mat3(a_ib, "a_ib")?).map_err(named("a_ib"))?;
    Ok(vec_out(py, &q))
}

/// Hamilton product p ⊗ q.
#[pyfunction]
fn quat_mul<'py>(py: Python<'py>, p: &Bound<'py, PyAny>, q: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_mul(quat(p, "p")?, quat(q, "q")?)))
}

/// Conjugate [w, −x, −y, −z].
#[pyfunction]
fn quat_conj<'py>(py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_conj(quat(q, "q")?)))
}

/// q / |q|.
#[pyfunction]
fn quat_normalize<'py>(py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_normalize(quat(q, "q")?).map_err(named("q"))?))
}

/// A(q) v.
#[pyfunction]
fn quat_rotate<'py>(py: Python<'py>, q: &Bound<'py, PyAny>, v: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, rot::quat_rotate(unit_quat(q, "q")?, &vec3(v, "v")?).as_slice()))
}

/// Unit quaternion of a rotation by `angle` about the unit vector `axis`.
#[pyfunction]
fn quat_from_axis_angle<'py>(
    py: Python<'py>,
    axis: &Bound<'py, PyAny>,
    angle: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_from_axis_angle(&unit_axis(axis, "axis")?, scalar(angle, "angle")?)))
}

/// q̇ = ½ q ⊗ (0, ω_B).
#[pyfunction]
fn quat_derivative<'py>(py: Python<'py>, q: &Bound<'py, PyAny>, omega_b: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_derivative(unit_quat(q, "q")?, &vec3(omega_b, "omega_b")?)))
}

/// The 4×3 matrix G(q) with q̇ = G(q) ω_B.
#[pyfunction]
fn quat_derivative_matrix<'py>(py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::quat_derivative_matrix(unit_quat(q, "q")?)))
}

/// q̇ = ½ (0, ω_I) ⊗ q.
#[pyfunction]
fn quat_derivative_inertial<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    omega_i: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_derivative_inertial(unit_quat(q, "q")?, &vec3(omega_i, "omega_i")?)))
}

/// ω_B = 2 vec(q* ⊗ q̇).
#[pyfunction]
fn quat_omega_body<'py>(py: Python<'py>, q: &Bound<'py, PyAny>, qdot: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, rot::quat_omega_body(unit_quat(q, "q")?, quat(qdot, "qdot")?).as_slice()))
}

/// ω_I = 2 vec(q̇ ⊗ q*).
#[pyfunction]
fn quat_omega_inertial<'py>(py: Python<'py>, q: &Bound<'py, PyAny>, qdot: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, rot::quat_omega_inertial(unit_quat(q, "q")?, quat(qdot, "qdot")?).as_slice()))
}

/// q ⊗ exp(½ ω_B dt): exact for a constant body angular velocity.
#[pyfunction]
fn quat_integrate<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    omega_b: &Bound<'py, PyAny>,
    dt: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_integrate(unit_quat(q, "q")?, &vec3(omega_b, "omega_b")?, scalar(dt, "dt")?)))
}

/// exp(½ ω_I dt) ⊗ q: exact for a constant inertial angular velocity.
#[pyfunction]
fn quat_integrate_inertial<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    omega_i: &Bound<'py, PyAny>,
    dt: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let q = rot::quat_integrate_inertial(unit_quat(q, "q")?, &vec3(omega_i, "omega_i")?, scalar(dt, "dt")?);
    Ok(vec_out(py, &q))
}

/// Unit quaternion of Euler angles.
#[pyfunction]
fn euler_zxz_to_quat<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::euler_zxz_to_quat(angles3(angles, "angles")?)))
}

/// Euler angles of a (not necessarily normalized) quaternion.
#[pyfunction]
fn quat_to_euler_zxz<'py>(py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_to_euler_zxz(nonzero_quat(q, "q")?)))
}

/// Unit quaternion of Cardan angles.
#[pyfunction]
fn cardan_xyz_to_quat<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::cardan_xyz_to_quat(angles3(angles, "angles")?)))
}

/// Cardan angles of a (not necessarily normalized) quaternion.
#[pyfunction]
fn quat_to_cardan_xyz<'py>(py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::quat_to_cardan_xyz(nonzero_quat(q, "q")?)))
}

// ---------------------------------------------------------------------------------------------
// Rotation vector
// ---------------------------------------------------------------------------------------------

/// A_IB of a rotation vector axis · angle.
#[pyfunction]
fn rotvec_to_matrix<'py>(py: Python<'py>, rotvec: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::rotvec_to_matrix(&vec3(rotvec, "rotvec")?)))
}

/// Rotation vector (angle ∈ [0, π]) of a rotation matrix A_IB.
#[pyfunction]
fn matrix_to_rotvec<'py>(py: Python<'py>, a_ib: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    let rv = rot::matrix_to_rotvec(&mat3(a_ib, "a_ib")?).map_err(named("a_ib"))?;
    Ok(vec_out(py, rv.as_slice()))
}

/// Unit quaternion of a rotation vector (exponential map).
#[pyfunction]
fn rotvec_to_quat<'py>(py: Python<'py>, rotvec: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::rotvec_to_quat(&vec3(rotvec, "rotvec")?)))
}

/// Rotation vector of a quaternion (logarithmic map).
#[pyfunction]
fn quat_to_rotvec<'py>(py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, rot::quat_to_rotvec(nonzero_quat(q, "q")?).as_slice()))
}

/// Rotation vector of Euler angles.
#[pyfunction]
fn euler_zxz_to_rotvec<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, rot::euler_zxz_to_rotvec(angles3(angles, "angles")?).as_slice()))
}

/// Euler angles of a rotation vector.
#[pyfunction]
fn rotvec_to_euler_zxz<'py>(py: Python<'py>, rotvec: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::rotvec_to_euler_zxz(&vec3(rotvec, "rotvec")?)))
}

/// Rotation vector of Cardan angles.
#[pyfunction]
fn cardan_xyz_to_rotvec<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, rot::cardan_xyz_to_rotvec(angles3(angles, "angles")?).as_slice()))
}

/// Cardan angles of a rotation vector.
#[pyfunction]
fn rotvec_to_cardan_xyz<'py>(py: Python<'py>, rotvec: &Bound<'py, PyAny>) -> PyResult<PyVec<'py>> {
    Ok(vec_out(py, &rot::rotvec_to_cardan_xyz(&vec3(rotvec, "rotvec")?)))
}

// ---------------------------------------------------------------------------------------------
// Angular-velocity matrices H and H* (eqs. 2.30–2.34)
// ---------------------------------------------------------------------------------------------

/// H with ω_I = H [ψ̇, ϑ̇, φ̇] (eq. 2.30).
#[pyfunction]
fn euler_h_inertial<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::euler_h_inertial(angles3(angles, "angles")?)))
}

/// H with ω_B = H [ψ̇, ϑ̇, φ̇] (eq. 2.31).
#[pyfunction]
fn euler_h_body<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::euler_h_body(angles3(angles, "angles")?)))
}

/// H with ω_I = H [α̇, β̇, γ̇] (eq. 2.32).
#[pyfunction]
fn cardan_h_inertial<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::cardan_h_inertial(angles3(angles, "angles")?)))
}

/// H with ω_B = H [α̇, β̇, γ̇] (eq. 2.33).
#[pyfunction]
fn cardan_h_body<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::cardan_h_body(angles3(angles, "angles")?)))
}

/// H* = inverse of eq. 2.30 (eq. 2.34); SingularityError where sin ϑ = 0.
#[pyfunction]
fn euler_h_inertial_inv<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::euler_h_inertial_inv(angles3(angles, "angles")?).map_err(engine)?))
}

/// H* = inverse of eq. 2.31 (eq. 2.34); SingularityError where sin ϑ = 0.
#[pyfunction]
fn euler_h_body_inv<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::euler_h_body_inv(angles3(angles, "angles")?).map_err(engine)?))
}

/// H* = inverse of eq. 2.32 (eq. 2.34); SingularityError where cos β = 0.
#[pyfunction]
fn cardan_h_inertial_inv<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::cardan_h_inertial_inv(angles3(angles, "angles")?).map_err(engine)?))
}

/// H* = inverse of eq. 2.33 (eq. 2.34); SingularityError where cos β = 0.
#[pyfunction]
fn cardan_h_body_inv<'py>(py: Python<'py>, angles: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &rot::cardan_h_body_inv(angles3(angles, "angles")?).map_err(engine)?))
}

/// |sin ϑ| (angle_set = 'euler_zxz') or |cos β| ('cardan_xyz'): the distance from the singularity.
#[pyfunction]
fn singularity_margin(angle_set: &str, angles: &Bound<'_, PyAny>) -> PyResult<f64> {
    Ok(rot::singularity_margin(self::angle_set(angle_set)?, angles3(angles, "angles")?))
}

/// Whether the angles are within `tol` of the singularity of H*.
#[pyfunction]
#[pyo3(signature = (angle_set, angles, tol = None))]
fn is_near_singular(angle_set: &str, angles: &Bound<'_, PyAny>, tol: Option<&Bound<'_, PyAny>>) -> PyResult<bool> {
    let set = self::angle_set(angle_set)?;
    let tol = tol.map(|t| scalar(t, "tol")).transpose()?.unwrap_or(rot::SINGULAR_TOL);
    if tol < 0.0 {
        return Err(settings(format!("tol: must be >= 0, got {tol}")));
    }
    Ok(rot::is_near_singular(set, angles3(angles, "angles")?, tol))
}

/// [ψ̇, ϑ̇, φ̇] = H* ω_I (eq. 2.34 with eq. 2.30).
#[pyfunction]
fn euler_rates_from_omega_inertial<'py>(
    py: Python<'py>,
    angles: &Bound<'py, PyAny>,
    omega_i: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let r = rot::euler_rates_from_omega_inertial(angles3(angles, "angles")?, &vec3(omega_i, "omega_i")?);
    Ok(vec_out(py, &r.map_err(engine)?))
}

/// [ψ̇, ϑ̇, φ̇] = H* ω_B (eq. 2.34 with eq. 2.31).
#[pyfunction]
fn euler_rates_from_omega_body<'py>(
    py: Python<'py>,
    angles: &Bound<'py, PyAny>,
    omega_b: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let r = rot::euler_rates_from_omega_body(angles3(angles, "angles")?, &vec3(omega_b, "omega_b")?);
    Ok(vec_out(py, &r.map_err(engine)?))
}

/// [α̇, β̇, γ̇] = H* ω_I (eq. 2.34 with eq. 2.32).
#[pyfunction]
fn cardan_rates_from_omega_inertial<'py>(
    py: Python<'py>,
    angles: &Bound<'py, PyAny>,
    omega_i: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let r = rot::cardan_rates_from_omega_inertial(angles3(angles, "angles")?, &vec3(omega_i, "omega_i")?);
    Ok(vec_out(py, &r.map_err(engine)?))
}

/// [α̇, β̇, γ̇] = H* ω_B (eq. 2.34 with eq. 2.33).
#[pyfunction]
fn cardan_rates_from_omega_body<'py>(
    py: Python<'py>,
    angles: &Bound<'py, PyAny>,
    omega_b: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let r = rot::cardan_rates_from_omega_body(angles3(angles, "angles")?, &vec3(omega_b, "omega_b")?);
    Ok(vec_out(py, &r.map_err(engine)?))
}

// ---------------------------------------------------------------------------------------------
// Moving frames (math::frames)
// ---------------------------------------------------------------------------------------------

/// A_12 A_23 ⋯ A_(n−1)n of a sequence of 3×3 matrices (eqs. 2.10, 2.11); the identity if empty.
#[pyfunction]
fn chain<'py>(py: Python<'py>, transforms: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    let expected = "a sequence of 3x3 matrices";
    let a = as_array(transforms, "transforms", expected)?;
    let view = a.as_array();
    let mats: Vec<Mat3> = if view.is_empty() && view.ndim() <= 1 {
        vec![]
    } else {
        let sh = view.shape();
        if sh.len() != 3 || sh[1] != 3 || sh[2] != 3 {
            return Err(settings(format!("transforms: expected {expected}, got an array of shape {}", shape_str(sh))));
        }
        let mut out = vec![Mat3::zeros(); sh[0]];
        for (ix, v) in view.indexed_iter() {
            let (k, r, c) = (ix[0], ix[1], ix[2]);
            if !v.is_finite() {
                return Err(settings(format!("transforms[{k}][{r}, {c}]: must be finite, got {v}")));
            }
            out[k][(r, c)] = *v;
        }
        out
    };
    Ok(mat_out(py, &frames::chain(&mats)))
}

/// v_P in I components (eq. 2.28).
#[pyfunction]
fn point_velocity_inertial<'py>(
    py: Python<'py>,
    v_q_i: &Bound<'py, PyAny>,
    a_ib: &Bound<'py, PyAny>,
    omega_i: &Bound<'py, PyAny>,
    r_b: &Bound<'py, PyAny>,
    rdot_b: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let v = frames::point_velocity_inertial(
        &vec3(v_q_i, "v_q_i")?,
        &rotation(a_ib, "a_ib")?,
        &vec3(omega_i, "omega_i")?,
        &vec3(r_b, "r_b")?,
        &vec3(rdot_b, "rdot_b")?,
    );
    Ok(vec_out(py, v.as_slice()))
}

/// v_P in B components (eq. 2.38).
#[pyfunction]
fn point_velocity_body<'py>(
    py: Python<'py>,
    v_q_b: &Bound<'py, PyAny>,
    omega_b: &Bound<'py, PyAny>,
    r_b: &Bound<'py, PyAny>,
    rdot_b: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let v = frames::point_velocity_body(
        &vec3(v_q_b, "v_q_b")?,
        &vec3(omega_b, "omega_b")?,
        &vec3(r_b, "r_b")?,
        &vec3(rdot_b, "rdot_b")?,
    );
    Ok(vec_out(py, v.as_slice()))
}

/// a_P in I components (eq. 2.41).
#[pyfunction]
#[allow(clippy::too_many_arguments)] // the arguments of eq. 2.41, one per term
fn point_acceleration_inertial<'py>(
    py: Python<'py>,
    a_q_i: &Bound<'py, PyAny>,
    a_ib: &Bound<'py, PyAny>,
    omega_b: &Bound<'py, PyAny>,
    omegadot_b: &Bound<'py, PyAny>,
    r_b: &Bound<'py, PyAny>,
    rdot_b: &Bound<'py, PyAny>,
    rddot_b: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let a = frames::point_acceleration_inertial(
        &vec3(a_q_i, "a_q_i")?,
        &rotation(a_ib, "a_ib")?,
        &vec3(omega_b, "omega_b")?,
        &vec3(omegadot_b, "omegadot_b")?,
        &vec3(r_b, "r_b")?,
        &vec3(rdot_b, "rdot_b")?,
        &vec3(rddot_b, "rddot_b")?,
    );
    Ok(vec_out(py, a.as_slice()))
}

/// a_P in B components (eq. 2.42).
#[pyfunction]
fn point_acceleration_body<'py>(
    py: Python<'py>,
    a_q_b: &Bound<'py, PyAny>,
    omega_b: &Bound<'py, PyAny>,
    omegadot_b: &Bound<'py, PyAny>,
    r_b: &Bound<'py, PyAny>,
    rdot_b: &Bound<'py, PyAny>,
    rddot_b: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let a = frames::point_acceleration_body(
        &vec3(a_q_b, "a_q_b")?,
        &vec3(omega_b, "omega_b")?,
        &vec3(omegadot_b, "omegadot_b")?,
        &vec3(r_b, "r_b")?,
        &vec3(rdot_b, "rdot_b")?,
        &vec3(rddot_b, "rddot_b")?,
    );
    Ok(vec_out(py, a.as_slice()))
}

/// (r cos φ, r sin φ, z).
#[pyfunction]
fn cylindrical_position<'py>(
    py: Python<'py>,
    r: &Bound<'py, PyAny>,
    phi: &Bound<'py, PyAny>,
    z: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let p = frames::cylindrical_position(scalar(r, "r")?, scalar(phi, "phi")?, scalar(z, "z")?);
    Ok(vec_out(py, p.as_slice()))
}

/// Velocity in cylindrical coordinates, I components (eq. 2.43).
#[pyfunction]
fn cylindrical_velocity<'py>(
    py: Python<'py>,
    r: &Bound<'py, PyAny>,
    phi: &Bound<'py, PyAny>,
    rdot: &Bound<'py, PyAny>,
    phidot: &Bound<'py, PyAny>,
    zdot: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let v = frames::cylindrical_velocity(
        scalar(r, "r")?,
        scalar(phi, "phi")?,
        scalar(rdot, "rdot")?,
        scalar(phidot, "phidot")?,
        scalar(zdot, "zdot")?,
    );
    Ok(vec_out(py, v.as_slice()))
}

/// Acceleration in cylindrical coordinates, I components (eq. 2.43).
#[pyfunction]
#[allow(clippy::too_many_arguments)] // the nine scalars of (q, q̇, q̈)
fn cylindrical_acceleration<'py>(
    py: Python<'py>,
    r: &Bound<'py, PyAny>,
    phi: &Bound<'py, PyAny>,
    z: &Bound<'py, PyAny>,
    rdot: &Bound<'py, PyAny>,
    phidot: &Bound<'py, PyAny>,
    zdot: &Bound<'py, PyAny>,
    rddot: &Bound<'py, PyAny>,
    phiddot: &Bound<'py, PyAny>,
    zddot: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let a = frames::cylindrical_acceleration(
        scalar(r, "r")?,
        scalar(phi, "phi")?,
        scalar(z, "z")?,
        scalar(rdot, "rdot")?,
        scalar(phidot, "phidot")?,
        scalar(zdot, "zdot")?,
        scalar(rddot, "rddot")?,
        scalar(phiddot, "phiddot")?,
        scalar(zddot, "zddot")?,
    );
    Ok(vec_out(py, a.as_slice()))
}

/// A_IB = Rz(φ) of the cylindrical trihedral (its transpose is the A_BI of eq. 2.44).
#[pyfunction]
fn cylindrical_a_ib<'py>(py: Python<'py>, phi: &Bound<'py, PyAny>) -> PyResult<PyMat<'py>> {
    Ok(mat_out(py, &frames::cylindrical_a_ib(scalar(phi, "phi")?)))
}

/// (ṙ, r φ̇, ż): velocity in trihedral components.
#[pyfunction]
fn cylindrical_velocity_trihedral<'py>(
    py: Python<'py>,
    r: &Bound<'py, PyAny>,
    rdot: &Bound<'py, PyAny>,
    phidot: &Bound<'py, PyAny>,
    zdot: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let v = frames::cylindrical_velocity_trihedral(
        scalar(r, "r")?,
        scalar(rdot, "rdot")?,
        scalar(phidot, "phidot")?,
        scalar(zdot, "zdot")?,
    );
    Ok(vec_out(py, v.as_slice()))
}

/// (r̈ − r φ̇², 2 ṙ φ̇ + r φ̈, z̈): acceleration in trihedral components (eq. 2.44).
#[pyfunction]
fn cylindrical_acceleration_trihedral<'py>(
    py: Python<'py>,
    r: &Bound<'py, PyAny>,
    rdot: &Bound<'py, PyAny>,
    phidot: &Bound<'py, PyAny>,
    rddot: &Bound<'py, PyAny>,
    phiddot: &Bound<'py, PyAny>,
    zddot: &Bound<'py, PyAny>,
) -> PyResult<PyVec<'py>> {
    let a = frames::cylindrical_acceleration_trihedral(
        scalar(r, "r")?,
        scalar(rdot, "rdot")?,
        scalar(phidot, "phidot")?,
        scalar(rddot, "rddot")?,
        scalar(phiddot, "phiddot")?,
        scalar(zddot, "zddot")?,
    );
    Ok(vec_out(py, a.as_slice()))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SINGULAR_TOL", rot::SINGULAR_TOL)?;
    m.add("ROTATION_MATRIX_TOL", rot::ROTATION_MATRIX_TOL)?;
    m.add("UNIT_TOL", UNIT_TOL)?;
    // elementary rotations, tilde
    m.add_function(wrap_pyfunction!(rot_x, m)?)?;
    m.add_function(wrap_pyfunction!(rot_y, m)?)?;
    m.add_function(wrap_pyfunction!(rot_z, m)?)?;
    m.add_function(wrap_pyfunction!(rot_axis, m)?)?;
    m.add_function(wrap_pyfunction!(wrap_angle, m)?)?;
    m.add_function(wrap_pyfunction!(check_rotation_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(tilde, m)?)?;
    m.add_function(wrap_pyfunction!(untilde, m)?)?;
    // Euler and Cardan angles
    m.add_function(wrap_pyfunction!(euler_zxz_to_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(matrix_to_euler_zxz, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_xyz_to_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(matrix_to_cardan_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(euler_zxz_to_cardan_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_xyz_to_euler_zxz, m)?)?;
    // quaternions
    m.add_function(wrap_pyfunction!(quat_to_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(matrix_to_quat, m)?)?;
    m.add_function(wrap_pyfunction!(quat_mul, m)?)?;
    m.add_function(wrap_pyfunction!(quat_conj, m)?)?;
    m.add_function(wrap_pyfunction!(quat_normalize, m)?)?;
    m.add_function(wrap_pyfunction!(quat_rotate, m)?)?;
    m.add_function(wrap_pyfunction!(quat_from_axis_angle, m)?)?;
    m.add_function(wrap_pyfunction!(quat_derivative, m)?)?;
    m.add_function(wrap_pyfunction!(quat_derivative_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(quat_derivative_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(quat_omega_body, m)?)?;
    m.add_function(wrap_pyfunction!(quat_omega_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(quat_integrate, m)?)?;
    m.add_function(wrap_pyfunction!(quat_integrate_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(euler_zxz_to_quat, m)?)?;
    m.add_function(wrap_pyfunction!(quat_to_euler_zxz, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_xyz_to_quat, m)?)?;
    m.add_function(wrap_pyfunction!(quat_to_cardan_xyz, m)?)?;
    // rotation vector
    m.add_function(wrap_pyfunction!(rotvec_to_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(matrix_to_rotvec, m)?)?;
    m.add_function(wrap_pyfunction!(rotvec_to_quat, m)?)?;
    m.add_function(wrap_pyfunction!(quat_to_rotvec, m)?)?;
    m.add_function(wrap_pyfunction!(euler_zxz_to_rotvec, m)?)?;
    m.add_function(wrap_pyfunction!(rotvec_to_euler_zxz, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_xyz_to_rotvec, m)?)?;
    m.add_function(wrap_pyfunction!(rotvec_to_cardan_xyz, m)?)?;
    // H and H*
    m.add_function(wrap_pyfunction!(euler_h_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(euler_h_body, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_h_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_h_body, m)?)?;
    m.add_function(wrap_pyfunction!(euler_h_inertial_inv, m)?)?;
    m.add_function(wrap_pyfunction!(euler_h_body_inv, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_h_inertial_inv, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_h_body_inv, m)?)?;
    m.add_function(wrap_pyfunction!(singularity_margin, m)?)?;
    m.add_function(wrap_pyfunction!(is_near_singular, m)?)?;
    m.add_function(wrap_pyfunction!(euler_rates_from_omega_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(euler_rates_from_omega_body, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_rates_from_omega_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(cardan_rates_from_omega_body, m)?)?;
    // moving frames
    m.add_function(wrap_pyfunction!(chain, m)?)?;
    m.add_function(wrap_pyfunction!(point_velocity_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(point_velocity_body, m)?)?;
    m.add_function(wrap_pyfunction!(point_acceleration_inertial, m)?)?;
    m.add_function(wrap_pyfunction!(point_acceleration_body, m)?)?;
    m.add_function(wrap_pyfunction!(cylindrical_position, m)?)?;
    m.add_function(wrap_pyfunction!(cylindrical_velocity, m)?)?;
    m.add_function(wrap_pyfunction!(cylindrical_acceleration, m)?)?;
    m.add_function(wrap_pyfunction!(cylindrical_a_ib, m)?)?;
    m.add_function(wrap_pyfunction!(cylindrical_velocity_trihedral, m)?)?;
    m.add_function(wrap_pyfunction!(cylindrical_acceleration_trihedral, m)?)?;
    Ok(())
}
