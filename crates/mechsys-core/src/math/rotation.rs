//! Rotation parametrizations and their angular-velocity matrices.
//!
//! The orientation of a frame `B` relative to a frame `I` is the rotation matrix `A_IB`, which maps
//! B-components to I-components, `r_i = A_IB r_b` (eq. 2.21); it is orthogonal, `A_BI = A_IB^T`
//! (eqs. 2.8, 2.22). This module converts between five descriptions of it:
//!
//! | parametrization | convention | equations |
//! | --- | --- | --- |
//! | rotation matrix | `A_IB` ([`Mat3`]) | 2.8–2.11 |
//! | Euler angles | `[ψ, ϑ, φ]`, `A_IB = Rz(ψ) Rx(ϑ) Rz(φ)`, ψ, φ ∈ (−π, π], ϑ ∈ [0, π] | 2.12–2.15 |
//! | Cardan angles | `[α, β, γ]`, `A_IB = Rx(α) Ry(β) Rz(γ)`, α, γ ∈ (−π, π], β ∈ [−π/2, π/2] | 2.16–2.19 |
//! | unit quaternion | [`Quat`] `= [w, x, y, z]`, scalar first, Hamilton product | — |
//! | rotation vector | `axis · angle`, angle ∈ [0, π] | — |
//!
//! The angular velocity follows from the angle rates through `ω = H ṗ` and back through
//! `ṗ = H* ω` (eq. 2.34), in inertial (eqs. 2.30, 2.32) or body components (eqs. 2.31, 2.33).
//! `H*` does not exist where the first and third elementary rotations turn about the same axis
//! (`sin ϑ = 0` for Euler, `cos β = 0` for Cardan angles); there the `*_inv` functions and the
//! `*_rates_from_omega_*` helpers return [`Error::Singular`]. The rotation matrix itself is still
//! representable at those angles, so the matrix-to-angle conversions pick one valid split of the
//! undetermined pair instead of failing.
//!
//! Quaternions follow `A(p ⊗ q) = A(p) A(q)` and rotate vectors as `q ⊗ (0, v) ⊗ q*`. Their
//! kinematics is `q̇ = ½ q ⊗ (0, ω_B) = ½ (0, ω_I) ⊗ q`; for constant `ω` the exact solution is
//! the exponential map used by [`quat_integrate`].
//!
//! The angle extraction goes through the quaternion: half-angle sums and differences of the
//! first and third angle are read off by `atan2` from pairs of quaternion components, which keeps
//! full precision up to the singular configurations (no `acos`/`asin` of a matrix entry).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::Matrix4x3;

use super::{tilde, Mat3, Vec3};
use crate::error::{Error, Result};

/// Unit quaternion `[w, x, y, z]`, scalar first: `w = cos(θ/2)`, `(x, y, z) = sin(θ/2) n` for a
/// rotation by the angle `θ` about the unit axis `n`. `q` and `−q` describe the same rotation.
pub type Quat = [f64; 4];

/// Threshold on `|sin ϑ|` (Euler) or `|cos β|` (Cardan) below which `H*` (eq. 2.34) is treated as
/// singular by the `*_inv` and `*_rates_from_omega_*` functions.
pub const SINGULAR_TOL: f64 = 1e-9;

/// Largest entry of `|A^T A − E|` accepted by the `matrix_to_*` conversions (see
/// [`check_rotation_matrix`]); loose enough for matrices that drift slightly during integration.
pub const ROTATION_MATRIX_TOL: f64 = 1e-6;

/// Relative size of a half-angle component pair below which the split of the first and third
/// angle is undetermined in floating point; the third angle is then set to zero.
const SPLIT_TOL: f64 = 1e-14;

/// The two three-angle parametrizations, for queries common to both.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleSet {
    /// Euler angles z-x-z `[ψ, ϑ, φ]` (eqs. 2.12–2.15); singular where `sin ϑ = 0`.
    EulerZxz,
    /// Cardan angles x-y-z `[α, β, γ]` (eqs. 2.16–2.19); singular where `cos β = 0`.
    CardanXyz,
}

// ---------------------------------------------------------------------------------------------
// Elementary rotations
// ---------------------------------------------------------------------------------------------

/// Elementary rotation about the x-axis by the angle `a` (the form of eqs. 2.13, 2.16).
#[inline]
pub fn rot_x(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Elementary rotation about the y-axis by the angle `a` (the form of eq. 2.17).
#[inline]
pub fn rot_y(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    Mat3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Elementary rotation about the z-axis by the angle `a` (the form of eqs. 2.12, 2.14, 2.18).
#[inline]
pub fn rot_z(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Rotation by `angle` about the unit vector `axis_unit` (Rodrigues' formula
/// `E + sin θ ñ + (1 − cos θ) ñ²`).
///
/// The axis must have unit length; a non-unit axis gives a matrix that is not a rotation.
///
/// # Example
/// ```
/// use mechsys_core::math::{rotation::{rot_axis, rot_x}, Vec3};
/// let a = rot_axis(&Vec3::x(), 0.3);
/// assert!((a - rot_x(0.3)).norm() < 1e-15);
/// ```
#[inline]
pub fn rot_axis(axis_unit: &Vec3, angle: f64) -> Mat3 {
    debug_assert!((axis_unit.norm() - 1.0).abs() < 1e-6, "rot_axis needs a unit axis");
    let n = tilde(axis_unit);
    let h = (0.5 * angle).sin();
    // 1 − cos θ = 2 sin²(θ/2) keeps small angles accurate
    Mat3::identity() + n * angle.sin() + n * n * (2.0 * h * h)
}

/// The angle `a` mapped to (−π, π].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    if a > -PI && a <= PI {
        return a;
    }
    let r = a.rem_euclid(TAU);
    if r > PI {
        r - TAU
    } else {
        r
    }
}

/// Checks that `a` is a proper rotation matrix: finite entries, `max |A^T A − E| ≤ tol` and
/// `det A > 0`.
///
/// # Errors
/// [`Error::Model`] saying which of the three properties fails.
pub fn check_rotation_matrix(a: &Mat3, tol: f64) -> Result<()> {
    crate::ensure!(a.iter().all(|v| v.is_finite()), Model, "rotation matrix has a non-finite entry");
    let err = (a.transpose() * a - Mat3::identity()).amax();
    // the entries are finite, so `err` is too
    if err > tol || tol.is_nan() {
        return Err(Error::Model(format!(
            "rotation matrix is not orthogonal: max |A^T A - E| = {err:.3e} exceeds {tol:.1e}"
        )));
    }
    let det = a.determinant();
    if det <= 0.0 {
        return Err(Error::Model(format!("matrix with det = {det:.6} is a reflection, not a rotation")));
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Euler angles z-x-z and Cardan angles x-y-z
// ---------------------------------------------------------------------------------------------

/// `A_IB` of the Euler angles `[ψ, ϑ, φ]`: `Rz(ψ) Rx(ϑ) Rz(φ)` (eq. 2.15).
pub fn euler_zxz_to_matrix(angles: [f64; 3]) -> Mat3 {
    let [psi, theta, phi] = angles;
    let (sp, cp) = psi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sf, cf) = phi.sin_cos();
    // eq. 2.15
    Mat3::new(
        cp * cf - sp * ct * sf,
        -cp * sf - sp * ct * cf,
        sp * st,
        sp * cf + cp * ct * sf,
        -sp * sf + cp * ct * cf,
        -cp * st,
        st * sf,
        st * cf,
        ct,
    )
}

/// Euler angles `[ψ, ϑ, φ]` of a rotation matrix `A_IB`, with ψ, φ ∈ (−π, π] and ϑ ∈ [0, π].
///
/// At ϑ = 0 (`A = Rz(ψ + φ)`) and ϑ = π (`A = Rz(ψ − φ) Rx(π)`) only the sum or the difference
/// of ψ and φ is determined; there (to within rounding) φ = 0 is returned and ψ carries the whole
/// turn. This is not an error: the returned angles reproduce the matrix. Close to these angles ψ
/// and φ are ill-conditioned one by one, but still reproduce the matrix to rounding accuracy.
///
/// # Errors
/// [`Error::Model`] if `a_ib` is not a rotation matrix within [`ROTATION_MATRIX_TOL`].
pub fn matrix_to_euler_zxz(a_ib: &Mat3) -> Result<[f64; 3]> {
    check_rotation_matrix(a_ib, ROTATION_MATRIX_TOL)?;
    Ok(quat_to_euler_zxz(shepperd(a_ib)))
}

/// `A_IB` of the Cardan angles `[α, β, γ]`: `Rx(α) Ry(β) Rz(γ)` (eq. 2.19).
pub fn cardan_xyz_to_matrix(angles: [f64; 3]) -> Mat3 {
    let [alpha, beta, gamma] = angles;
    let (sa, ca) = alpha.sin_cos();
    let (sb, cb) = beta.sin_cos();
    let (sg, cg) = gamma.sin_cos();
    // eq. 2.19
    Mat3::new(
        cb * cg,
        -cb * sg,
        sb,
        ca * sg + sa * sb * cg,
        ca * cg - sa * sb * sg,
        -sa * cb,
        sa * sg - ca * sb * cg,
        sa * cg + ca * sb * sg,
        ca * cb,
    )
}

/// Cardan angles `[α, β, γ]` of a rotation matrix `A_IB`, with α, γ ∈ (−π, π] and
/// β ∈ [−π/2, π/2].
///
/// At β = π/2 (`A = Rx(α + γ) Ry(π/2)`) and β = −π/2 (`A = Rx(α − γ) Ry(−π/2)`) only the sum or
/// the difference of α and γ is determined; there (to within rounding) γ = 0 is returned and α
/// carries the whole turn. This is not an error: the returned angles reproduce the matrix. Close to
/// these angles α and γ are ill-conditioned one by one, but still reproduce the matrix to rounding
/// accuracy.
///
/// # Errors
/// [`Error::Model`] if `a_ib` is not a rotation matrix within [`ROTATION_MATRIX_TOL`].
pub fn matrix_to_cardan_xyz(a_ib: &Mat3) -> Result<[f64; 3]> {
    check_rotation_matrix(a_ib, ROTATION_MATRIX_TOL)?;
    Ok(quat_to_cardan_xyz(shepperd(a_ib)))
}

/// Cardan angles of the rotation given by Euler angles (same `A_IB`).
pub fn euler_zxz_to_cardan_xyz(angles: [f64; 3]) -> [f64; 3] {
    quat_to_cardan_xyz(euler_zxz_to_quat(angles))
}

/// Euler angles of the rotation given by Cardan angles (same `A_IB`).
pub fn cardan_xyz_to_euler_zxz(angles: [f64; 3]) -> [f64; 3] {
    quat_to_euler_zxz(cardan_xyz_to_quat(angles))
}

// ---------------------------------------------------------------------------------------------
// Quaternions
// ---------------------------------------------------------------------------------------------

/// `A_IB` of a unit quaternion.
///
/// The quaternion must be normalized ([`quat_normalize`]); a non-unit one gives a matrix that is
/// not orthogonal.
pub fn quat_to_matrix(q: Quat) -> Mat3 {
    let [w, x, y, z] = q;
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz) = (x * y, x * z, y * z);
    let (wx, wy, wz) = (w * x, w * y, w * z);
    // A = (w² − v·v) E + 2 v vᵀ + 2 w ṽ with v = (x, y, z), simplified for |q| = 1
    Mat3::new(
        1.0 - 2.0 * (yy + zz),
        2.0 * (xy - wz),
        2.0 * (xz + wy),
        2.0 * (xy + wz),
        1.0 - 2.0 * (xx + zz),
        2.0 * (yz - wx),
        2.0 * (xz - wy),
        2.0 * (yz + wx),
        1.0 - 2.0 * (xx + yy),
    )
}

/// Unit quaternion of a rotation matrix `A_IB` by Shepperd's method, with `w ≥ 0`.
///
/// The component of largest magnitude is computed from the diagonal and the other three from
/// off-diagonal sums or differences divided by it, so the result is accurate for every rotation,
/// including half turns.
///
/// # Errors
/// [`Error::Model`] if `a_ib` is not a rotation matrix within [`ROTATION_MATRIX_TOL`].
pub fn matrix_to_quat(a_ib: &Mat3) -> Result<Quat> {
    check_rotation_matrix(a_ib, ROTATION_MATRIX_TOL)?;
    Ok(shepperd(a_ib))
}

/// Shepperd's method on a matrix already known to be (close to) a rotation.
fn shepperd(a: &Mat3) -> Quat {
    let (a00, a11, a22) = (a[(0, 0)], a[(1, 1)], a[(2, 2)]);
    let trace = a00 + a11 + a22;
    // 4w² = 1 + tr, 4x² = 1 + 2 a00 − tr, ...: the largest of (tr, a00, a11, a22) picks the
    // largest component, whose magnitude is at least 1/2.
    let q = if trace >= a00 && trace >= a11 && trace >= a22 {
        let w4 = 2.0 * (1.0 + trace).sqrt();
        [0.25 * w4, (a[(2, 1)] - a[(1, 2)]) / w4, (a[(0, 2)] - a[(2, 0)]) / w4, (a[(1, 0)] - a[(0, 1)]) / w4]
    } else if a00 >= a11 && a00 >= a22 {
        let x4 = 2.0 * (1.0 + a00 - a11 - a22).sqrt();
        [(a[(2, 1)] - a[(1, 2)]) / x4, 0.25 * x4, (a[(0, 1)] + a[(1, 0)]) / x4, (a[(0, 2)] + a[(2, 0)]) / x4]
    } else if a11 >= a22 {
        let y4 = 2.0 * (1.0 - a00 + a11 - a22).sqrt();
        [(a[(0, 2)] - a[(2, 0)]) / y4, (a[(0, 1)] + a[(1, 0)]) / y4, 0.25 * y4, (a[(1, 2)] + a[(2, 1)]) / y4]
    } else {
        let z4 = 2.0 * (1.0 - a00 - a11 + a22).sqrt();
        [(a[(1, 0)] - a[(0, 1)]) / z4, (a[(0, 2)] + a[(2, 0)]) / z4, (a[(1, 2)] + a[(2, 1)]) / z4, 0.25 * z4]
    };
    // removes the small non-orthogonality a checked matrix may carry; the norm is close to 1
    let n = quat_norm(q);
    let s = if q[0] < 0.0 { -1.0 / n } else { 1.0 / n };
    [s * q[0], s * q[1], s * q[2], s * q[3]]
}

#[inline]
fn quat_norm(q: Quat) -> f64 {
    (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt()
}

/// Hamilton product `p ⊗ q`; `A(p ⊗ q) = A(p) A(q)`.
#[inline]
pub fn quat_mul(p: Quat, q: Quat) -> Quat {
    [
        p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
        p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
        p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
        p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0],
    ]
}

/// Conjugate `q* = [w, −x, −y, −z]`, the inverse rotation of a unit quaternion.
#[inline]
pub fn quat_conj(q: Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

/// `q / |q|`.
///
/// # Errors
/// [`Error::Model`] if a component is not finite or `|q| ≤ 1e-12`, where no orientation can be
/// read from `q`.
pub fn quat_normalize(q: Quat) -> Result<Quat> {
    crate::ensure!(
        q.iter().all(|c| c.is_finite()),
        Model,
        "quaternion {q:?} has a non-finite component and cannot be normalized"
    );
    // scale by the largest component first so that huge finite entries do not overflow
    let m = q.iter().fold(0.0_f64, |acc, c| acc.max(c.abs()));
    let n = if m > 0.0 { m * quat_norm([q[0] / m, q[1] / m, q[2] / m, q[3] / m]) } else { 0.0 };
    if n <= 1e-12 {
        return Err(Error::Model(format!("quaternion {q:?} has norm {n:.3e} and cannot be normalized")));
    }
    Ok([q[0] / n, q[1] / n, q[2] / n, q[3] / n])
}

/// The vector `v` rotated by the unit quaternion `q`: `A(q) v`, i.e. `q ⊗ (0, v) ⊗ q*`.
#[inline]
pub fn quat_rotate(q: Quat, v: &Vec3) -> Vec3 {
    let u = Vec3::new(q[1], q[2], q[3]);
    let t = 2.0 * u.cross(v);
    v + q[0] * t + u.cross(&t)
}

/// Unit quaternion of a rotation by `angle` about the unit vector `axis_unit`
/// (same rotation as [`rot_axis`]).
#[inline]
pub fn quat_from_axis_angle(axis_unit: &Vec3, angle: f64) -> Quat {
    let (s, c) = (0.5 * angle).sin_cos();
    [c, s * axis_unit.x, s * axis_unit.y, s * axis_unit.z]
}

/// Time derivative of a unit quaternion from the body-frame angular velocity:
/// `q̇ = ½ q ⊗ (0, ω_B)`.
#[inline]
pub fn quat_derivative(q: Quat, omega_b: &Vec3) -> Quat {
    let d = quat_mul(q, [0.0, omega_b.x, omega_b.y, omega_b.z]);
    [0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3]]
}

/// The 4×3 matrix `G(q)` with `q̇ = G(q) ω_B` (matrix form of [`quat_derivative`]); for a unit
/// quaternion `4 G^T G = E`, so `ω_B = 4 G^T q̇`.
pub fn quat_derivative_matrix(q: Quat) -> Matrix4x3<f64> {
    let [w, x, y, z] = q;
    Matrix4x3::new(-x, -y, -z, w, -z, y, z, w, -x, -y, x, w) * 0.5
}

/// Time derivative of a unit quaternion from the inertial angular velocity:
/// `q̇ = ½ (0, ω_I) ⊗ q`.
#[inline]
pub fn quat_derivative_inertial(q: Quat, omega_i: &Vec3) -> Quat {
    let d = quat_mul([0.0, omega_i.x, omega_i.y, omega_i.z], q);
    [0.5 * d[0], 0.5 * d[1], 0.5 * d[2], 0.5 * d[3]]
}

/// Body-frame angular velocity from a unit quaternion and its rate: `ω_B = 2 vec(q* ⊗ q̇)`
/// (inverse of [`quat_derivative`]).
#[inline]
pub fn quat_omega_body(q: Quat, qdot: Quat) -> Vec3 {
    let d = quat_mul(quat_conj(q), qdot);
    Vec3::new(2.0 * d[1], 2.0 * d[2], 2.0 * d[3])
}

/// Inertial angular velocity from a unit quaternion and its rate: `ω_I = 2 vec(q̇ ⊗ q*)`
/// (inverse of [`quat_derivative_inertial`]).
#[inline]
pub fn quat_omega_inertial(q: Quat, qdot: Quat) -> Vec3 {
    let d = quat_mul(qdot, quat_conj(q));
    Vec3::new(2.0 * d[1], 2.0 * d[2], 2.0 * d[3])
}

/// Exact solution of `q̇ = ½ q ⊗ (0, ω_B)` over `dt` for a constant body angular velocity:
/// `q ⊗ exp(½ ω_B dt)`, i.e. `A_IB(t + dt) = A_IB(t) · rot_axis(ω̂_B, |ω_B| dt)`.
///
/// The result has the norm of `q` up to rounding; renormalize now and then over long runs.
#[inline]
pub fn quat_integrate(q: Quat, omega_b: &Vec3, dt: f64) -> Quat {
    quat_mul(q, rotvec_to_quat(&(omega_b * dt)))
}

/// Exact solution of `q̇ = ½ (0, ω_I) ⊗ q` over `dt` for a constant inertial angular velocity:
/// `exp(½ ω_I dt) ⊗ q`, i.e. `A_IB(t + dt) = rot_axis(ω̂_I, |ω_I| dt) · A_IB(t)`.
#[inline]
pub fn quat_integrate_inertial(q: Quat, omega_i: &Vec3, dt: f64) -> Quat {
    quat_mul(rotvec_to_quat(&(omega_i * dt)), q)
}

/// Rate of the rotation vector `θ` of `A = A₀ exp(θ̃)` for the body-frame angular velocity
/// `ω_B`: `θ̇ = J_r⁻¹(θ) ω_B` with the inverse right Jacobian of SO(3),
/// `J_r⁻¹ = E + ½ θ̃ + (1/θ² − (1 + cos θ)/(2 θ sin θ)) θ̃²` (θ = |θ| < 2π). It is the
/// `dexp⁻¹` that Lie-group Runge–Kutta schemes (Munthe-Kaas) apply to the stage derivatives.
pub fn rotvec_rate_body(rotvec: &Vec3, omega_b: &Vec3) -> Vec3 {
    let a2 = rotvec.norm_squared();
    // the θ̃² coefficient, by its series near θ = 0 where the closed form cancels
    let k = if a2 < 1e-4 {
        1.0 / 12.0 + a2 * (1.0 / 720.0 + a2 / 30240.0)
    } else {
        let a = a2.sqrt();
        (1.0 - 0.5 * a * (1.0 + a.cos()) / a.sin()) / a2
    };
    let tw = rotvec.cross(omega_b);
    omega_b + 0.5 * tw + k * rotvec.cross(&tw)
}

/// Unit quaternion of Euler angles `[ψ, ϑ, φ]`: `q_z(ψ) ⊗ q_x(ϑ) ⊗ q_z(φ)`.
///
/// The sign is continuous in the angles (no hemisphere flip), so the result can be
/// differentiated along a trajectory.
pub fn euler_zxz_to_quat(angles: [f64; 3]) -> Quat {
    let [psi, theta, phi] = angles;
    let (st, ct) = (0.5 * theta).sin_cos();
    let (ss, cs) = (0.5 * (psi + phi)).sin_cos();
    let (sd, cd) = (0.5 * (psi - phi)).sin_cos();
    // product of the three elementary quaternions, collected into half sums and differences
    [ct * cs, st * cd, st * sd, ct * ss]
}

/// Euler angles `[ψ, ϑ, φ]` of a quaternion (need not be normalized), with the ranges and the
/// choice φ = 0 at ϑ ∈ {0, π} of [`matrix_to_euler_zxz`].
pub fn quat_to_euler_zxz(q: Quat) -> [f64; 3] {
    let [w, x, y, z] = q;
    // q = [cos(ϑ/2) cos σ, sin(ϑ/2) cos δ, sin(ϑ/2) sin δ, cos(ϑ/2) sin σ],
    // σ = (ψ + φ)/2, δ = (ψ − φ)/2 (see euler_zxz_to_quat)
    let c = w.hypot(z);
    let s = x.hypot(y);
    let theta = 2.0 * s.atan2(c);
    let tol = SPLIT_TOL * c.hypot(s);
    let (psi, phi) = if s <= tol {
        // ϑ = 0: A = Rz(ψ + φ)
        (2.0 * z.atan2(w), 0.0)
    } else if c <= tol {
        // ϑ = π: A = Rz(ψ − φ) Rx(π)
        (2.0 * y.atan2(x), 0.0)
    } else {
        let sigma = z.atan2(w);
        let delta = y.atan2(x);
        (sigma + delta, sigma - delta)
    };
    [wrap_angle(psi), theta, wrap_angle(phi)]
}

/// Unit quaternion of Cardan angles `[α, β, γ]`: `q_x(α) ⊗ q_y(β) ⊗ q_z(γ)`.
///
/// The sign is continuous in the angles (no hemisphere flip).
pub fn cardan_xyz_to_quat(angles: [f64; 3]) -> Quat {
    let [alpha, beta, gamma] = angles;
    let (sa, ca) = (0.5 * alpha).sin_cos();
    let (sb, cb) = (0.5 * beta).sin_cos();
    let (sc, cc) = (0.5 * gamma).sin_cos();
    [ca * cb * cc - sa * sb * sc, sa * cb * cc + ca * sb * sc, ca * sb * cc - sa * cb * sc, ca * cb * sc + sa * sb * cc]
}

/// Cardan angles `[α, β, γ]` of a quaternion (need not be normalized), with the ranges and the
/// choice γ = 0 at β = ±π/2 of [`matrix_to_cardan_xyz`].
pub fn quat_to_cardan_xyz(q: Quat) -> [f64; 3] {
    let [w, x, y, z] = q;
    // With a = α/2, b = β/2, c = γ/2 (see cardan_xyz_to_quat):
    //   (w + y, x + z) = (cos b + sin b) (cos(a + c), sin(a + c)),
    //   (w − y, x − z) = (cos b − sin b) (cos(a − c), sin(a − c)),
    // and cos b ± sin b = √2 (sin, cos)(b + π/4) ≥ 0 for β ∈ [−π/2, π/2].
    let (pc, ps) = (w + y, x + z);
    let (mc, ms) = (w - y, x - z);
    let p = pc.hypot(ps);
    let m = mc.hypot(ms);
    let beta = 2.0 * p.atan2(m) - FRAC_PI_2;
    let tol = SPLIT_TOL * p.hypot(m);
    let (alpha, gamma) = if m <= tol {
        // β = π/2: A = Rx(α + γ) Ry(π/2)
        (2.0 * ps.atan2(pc), 0.0)
    } else if p <= tol {
        // β = −π/2: A = Rx(α − γ) Ry(−π/2)
        (2.0 * ms.atan2(mc), 0.0)
    } else {
        let sum = ps.atan2(pc);
        let diff = ms.atan2(mc);
        (sum + diff, sum - diff)
    };
    [wrap_angle(alpha), beta, wrap_angle(gamma)]
}

// ---------------------------------------------------------------------------------------------
// Rotation vector
// ---------------------------------------------------------------------------------------------

/// `sin x / x`, accurate near 0.
#[inline]
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        let x2 = x * x;
        1.0 - x2 / 6.0 * (1.0 - x2 / 20.0)
    } else {
        x.sin() / x
    }
}

/// `A_IB` of a rotation vector `axis · angle` (Rodrigues' formula, accurate for small angles).
pub fn rotvec_to_matrix(rotvec: &Vec3) -> Mat3 {
    let theta = rotvec.norm();
    let v = tilde(rotvec);
    let h = sinc(0.5 * theta);
    // sin θ / θ and (1 − cos θ)/θ² = ½ sinc²(θ/2)
    Mat3::identity() + v * sinc(theta) + v * v * (0.5 * h * h)
}

/// The coefficients `a = (1 − cos φ)/φ²`, `b = (φ − sin φ)/φ³` of the left Jacobian and their
/// derivatives divided by φ, `a'(φ)/φ` and `b'(φ)/φ` (series below φ = 0.1, where the closed
/// forms cancel).
fn so3_jacobian_coefficients(phi: f64) -> [f64; 4] {
    let p2 = phi * phi;
    if phi < 0.1 {
        let p4 = p2 * p2;
        [
            0.5 - p2 / 24.0 + p4 / 720.0 - p4 * p2 / 40320.0,
            1.0 / 6.0 - p2 / 120.0 + p4 / 5040.0 - p4 * p2 / 362880.0,
            -1.0 / 12.0 + p2 / 180.0 - p4 / 6720.0,
            -1.0 / 60.0 + p2 / 1260.0 - p4 / 60480.0,
        ]
    } else {
        let (s, c) = phi.sin_cos();
        let (p3, p4) = (p2 * phi, p2 * p2);
        [(1.0 - c) / p2, (phi - s) / p3, s / p3 - 2.0 * (1.0 - c) / p4, (1.0 - c) / p4 - 3.0 * (phi - s) / (p4 * phi)]
    }
}

/// The left Jacobian of SO(3): `exp(θ̃)` turns with angular velocity `J_l(θ) θ̇` (components on
/// the side it maps to), `J_l = I + a θ̃ + b θ̃²`.
pub fn so3_left_jacobian(theta: &Vec3) -> Mat3 {
    let [a, b, _, _] = so3_jacobian_coefficients(theta.norm());
    let t = tilde(theta);
    Mat3::identity() + t * a + t * t * b
}

/// `J̇_l θ̇`, the part of the angular acceleration of `exp(θ̃)` that is not `J_l θ̈`:
/// `ȧ θ × θ̇ + ḃ θ × (θ × θ̇) + b θ̇ × (θ × θ̇)`, with `ȧ = a'(φ) θ·θ̇/φ` (likewise ḃ).
pub fn so3_left_jacobian_rate(theta: &Vec3, theta_d: &Vec3) -> Vec3 {
    let [_, b, ca, cb] = so3_jacobian_coefficients(theta.norm());
    let tt = theta.dot(theta_d);
    let c = theta.cross(theta_d);
    c * (ca * tt) + theta.cross(&c) * (cb * tt) + theta_d.cross(&c) * b
}

/// Rotation vector `axis · angle`, angle ∈ [0, π], of a rotation matrix `A_IB`.
///
/// Goes through Shepperd's quaternion, so it is accurate near the identity and near half turns;
/// at exactly π either of the two opposite axes may be returned.
///
/// # Errors
/// [`Error::Model`] if `a_ib` is not a rotation matrix within [`ROTATION_MATRIX_TOL`].
pub fn matrix_to_rotvec(a_ib: &Mat3) -> Result<Vec3> {
    check_rotation_matrix(a_ib, ROTATION_MATRIX_TOL)?;
    Ok(quat_to_rotvec(shepperd(a_ib)))
}

/// Unit quaternion `[cos(θ/2), sin(θ/2) n]` of a rotation vector `θ n` (the exponential map).
#[inline]
pub fn rotvec_to_quat(rotvec: &Vec3) -> Quat {
    let half = 0.5 * rotvec.norm();
    // sin(θ/2) n = ½ sinc(θ/2) θ n
    let k = 0.5 * sinc(half);
    [half.cos(), k * rotvec.x, k * rotvec.y, k * rotvec.z]
}

/// Rotation vector `axis · angle`, angle ∈ [0, π], of a quaternion (the logarithmic map; `q`
/// need not be normalized, `q` and `−q` give the same result).
pub fn quat_to_rotvec(q: Quat) -> Vec3 {
    let (w, v) = if q[0] < 0.0 { (-q[0], Vec3::new(-q[1], -q[2], -q[3])) } else { (q[0], Vec3::new(q[1], q[2], q[3])) };
    let n = v.norm();
    if n < f64::MIN_POSITIVE {
        return Vec3::zeros();
    }
    // θ = 2 atan2(|v|, w) ∈ [0, π]; atan2 stays accurate for tiny |v|
    v * (2.0 * n.atan2(w) / n)
}

/// Rotation vector of Euler angles `[ψ, ϑ, φ]`.
pub fn euler_zxz_to_rotvec(angles: [f64; 3]) -> Vec3 {
    quat_to_rotvec(euler_zxz_to_quat(angles))
}

/// Euler angles `[ψ, ϑ, φ]` of a rotation vector (conventions of [`matrix_to_euler_zxz`]).
pub fn rotvec_to_euler_zxz(rotvec: &Vec3) -> [f64; 3] {
    quat_to_euler_zxz(rotvec_to_quat(rotvec))
}

/// Rotation vector of Cardan angles `[α, β, γ]`.
pub fn cardan_xyz_to_rotvec(angles: [f64; 3]) -> Vec3 {
    quat_to_rotvec(cardan_xyz_to_quat(angles))
}

/// Cardan angles `[α, β, γ]` of a rotation vector (conventions of [`matrix_to_cardan_xyz`]).
pub fn rotvec_to_cardan_xyz(rotvec: &Vec3) -> [f64; 3] {
    quat_to_cardan_xyz(rotvec_to_quat(rotvec))
}

// ---------------------------------------------------------------------------------------------
// Angular-velocity matrices H (ω = H ṗ) and their inverses H* (ṗ = H* ω), eqs. 2.30–2.34
// ---------------------------------------------------------------------------------------------

/// `H` with `ω_I = H [ψ̇, ϑ̇, φ̇]` for Euler angles (eq. 2.30).
pub fn euler_h_inertial(angles: [f64; 3]) -> Mat3 {
    let [psi, theta, _] = angles;
    let (sp, cp) = psi.sin_cos();
    let (st, ct) = theta.sin_cos();
    // eq. 2.30: columns are e_z, Rz(ψ) e_x and Rz(ψ) Rx(ϑ) e_z
    Mat3::new(0.0, cp, sp * st, 0.0, sp, -cp * st, 1.0, 0.0, ct)
}

/// `H` with `ω_B = H [ψ̇, ϑ̇, φ̇]` for Euler angles (eq. 2.31).
pub fn euler_h_body(angles: [f64; 3]) -> Mat3 {
    let [_, theta, phi] = angles;
    let (st, ct) = theta.sin_cos();
    let (sf, cf) = phi.sin_cos();
    // eq. 2.31
    Mat3::new(st * sf, cf, 0.0, st * cf, -sf, 0.0, ct, 0.0, 1.0)
}

/// `H` with `ω_I = H [α̇, β̇, γ̇]` for Cardan angles (eq. 2.32).
pub fn cardan_h_inertial(angles: [f64; 3]) -> Mat3 {
    let [alpha, beta, _] = angles;
    let (sa, ca) = alpha.sin_cos();
    let (sb, cb) = beta.sin_cos();
    // eq. 2.32: columns are e_x, Rx(α) e_y and Rx(α) Ry(β) e_z
    Mat3::new(1.0, 0.0, sb, 0.0, ca, -sa * cb, 0.0, sa, ca * cb)
}

/// `H` with `ω_B = H [α̇, β̇, γ̇]` for Cardan angles (eq. 2.33).
pub fn cardan_h_body(angles: [f64; 3]) -> Mat3 {
    let [_, beta, gamma] = angles;
    let (sb, cb) = beta.sin_cos();
    let (sg, cg) = gamma.sin_cos();
    // eq. 2.33
    Mat3::new(cb * cg, sg, 0.0, -cb * sg, cg, 0.0, sb, 0.0, 1.0)
}

/// `|sin ϑ|` for Euler or `|cos β|` for Cardan angles: the distance from the singularity of `H*`
/// (`NaN` for non-finite angles).
pub fn singularity_margin(set: AngleSet, angles: [f64; 3]) -> f64 {
    match set {
        AngleSet::EulerZxz => angles[1].sin().abs(),
        AngleSet::CardanXyz => angles[1].cos().abs(),
    }
}

/// Whether the angles are within `tol` of the singularity of `H*` ([`singularity_margin`]
/// `< tol`); non-finite angles count as singular.
pub fn is_near_singular(set: AngleSet, angles: [f64; 3], tol: f64) -> bool {
    let m = singularity_margin(set, angles);
    m.is_nan() || m < tol
}

/// `(sin ϑ, cos ϑ)` of Euler angles whose `H*` exists, or the error saying why it does not.
fn euler_regular(angles: [f64; 3]) -> Result<(f64, f64)> {
    crate::ensure!(angles.iter().all(|a| a.is_finite()), Solver, "Euler z-x-z angles {angles:?} are not finite");
    let (st, ct) = angles[1].sin_cos();
    if st.abs() < SINGULAR_TOL {
        return Err(Error::Singular(format!(
            "Euler z-x-z angles are singular at theta = {:.6e} rad (|sin theta| = {:.3e} < {SINGULAR_TOL:.0e}): \
             psi and phi turn about the same axis and their rates cannot be recovered from omega",
            angles[1],
            st.abs()
        )));
    }
    Ok((st, ct))
}

/// `(sin β, cos β)` of Cardan angles whose `H*` exists, or the error saying why it does not.
fn cardan_regular(angles: [f64; 3]) -> Result<(f64, f64)> {
    crate::ensure!(angles.iter().all(|a| a.is_finite()), Solver, "Cardan x-y-z angles {angles:?} are not finite");
    let (sb, cb) = angles[1].sin_cos();
    if cb.abs() < SINGULAR_TOL {
        return Err(Error::Singular(format!(
            "Cardan x-y-z angles are singular at beta = {:.6e} rad (|cos beta| = {:.3e} < {SINGULAR_TOL:.0e}): \
             alpha and gamma turn about the same axis and their rates cannot be recovered from omega",
            angles[1],
            cb.abs()
        )));
    }
    Ok((sb, cb))
}

/// `H*` with `[ψ̇, ϑ̇, φ̇] = H* ω_I` for Euler angles (inverse of eq. 2.30, eq. 2.34).
///
/// # Errors
/// [`Error::Singular`] if `|sin ϑ| <` [`SINGULAR_TOL`]; [`Error::Solver`] for non-finite angles.
pub fn euler_h_inertial_inv(angles: [f64; 3]) -> Result<Mat3> {
    let (st, ct) = euler_regular(angles)?;
    let (sp, cp) = angles[0].sin_cos();
    let (sp_st, cp_st) = (sp / st, cp / st);
    // eq. 2.34 with H of eq. 2.30
    Ok(Mat3::new(-sp_st * ct, cp_st * ct, 1.0, cp, sp, 0.0, sp_st, -cp_st, 0.0))
}

/// `H*` with `[ψ̇, ϑ̇, φ̇] = H* ω_B` for Euler angles (inverse of eq. 2.31, eq. 2.34).
///
/// # Errors
/// [`Error::Singular`] if `|sin ϑ| <` [`SINGULAR_TOL`]; [`Error::Solver`] for non-finite angles.
pub fn euler_h_body_inv(angles: [f64; 3]) -> Result<Mat3> {
    let (st, ct) = euler_regular(angles)?;
    let (sf, cf) = angles[2].sin_cos();
    let (sf_st, cf_st) = (sf / st, cf / st);
    // eq. 2.34 with H of eq. 2.31
    Ok(Mat3::new(sf_st, cf_st, 0.0, cf, -sf, 0.0, -sf_st * ct, -cf_st * ct, 1.0))
}

/// `H*` with `[α̇, β̇, γ̇] = H* ω_I` for Cardan angles (inverse of eq. 2.32, eq. 2.34).
///
/// # Errors
/// [`Error::Singular`] if `|cos β| <` [`SINGULAR_TOL`]; [`Error::Solver`] for non-finite angles.
pub fn cardan_h_inertial_inv(angles: [f64; 3]) -> Result<Mat3> {
    let (sb, cb) = cardan_regular(angles)?;
    let (sa, ca) = angles[0].sin_cos();
    let (sa_cb, ca_cb) = (sa / cb, ca / cb);
    // eq. 2.34 with H of eq. 2.32
    Ok(Mat3::new(1.0, sa_cb * sb, -ca_cb * sb, 0.0, ca, sa, 0.0, -sa_cb, ca_cb))
}

/// `H*` with `[α̇, β̇, γ̇] = H* ω_B` for Cardan angles (inverse of eq. 2.33, eq. 2.34).
///
/// # Errors
/// [`Error::Singular`] if `|cos β| <` [`SINGULAR_TOL`]; [`Error::Solver`] for non-finite angles.
pub fn cardan_h_body_inv(angles: [f64; 3]) -> Result<Mat3> {
    let (sb, cb) = cardan_regular(angles)?;
    let (sg, cg) = angles[2].sin_cos();
    let (sg_cb, cg_cb) = (sg / cb, cg / cb);
    // eq. 2.34 with H of eq. 2.33
    Ok(Mat3::new(cg_cb, -sg_cb, 0.0, sg, cg, 0.0, -sb * cg_cb, sb * sg_cb, 1.0))
}

#[inline]
fn to_array(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// Euler angle rates `[ψ̇, ϑ̇, φ̇]` from the inertial angular velocity (eq. 2.34 with eq. 2.30).
///
/// # Errors
/// As [`euler_h_inertial_inv`].
pub fn euler_rates_from_omega_inertial(angles: [f64; 3], omega_i: &Vec3) -> Result<[f64; 3]> {
    Ok(to_array(&(euler_h_inertial_inv(angles)? * omega_i)))
}

/// Euler angle rates `[ψ̇, ϑ̇, φ̇]` from the body angular velocity (eq. 2.34 with eq. 2.31).
///
/// # Errors
/// As [`euler_h_body_inv`].
pub fn euler_rates_from_omega_body(angles: [f64; 3], omega_b: &Vec3) -> Result<[f64; 3]> {
    Ok(to_array(&(euler_h_body_inv(angles)? * omega_b)))
}

/// Cardan angle rates `[α̇, β̇, γ̇]` from the inertial angular velocity (eq. 2.34 with eq. 2.32).
///
/// # Errors
/// As [`cardan_h_inertial_inv`].
pub fn cardan_rates_from_omega_inertial(angles: [f64; 3], omega_i: &Vec3) -> Result<[f64; 3]> {
    Ok(to_array(&(cardan_h_inertial_inv(angles)? * omega_i)))
}

/// Cardan angle rates `[α̇, β̇, γ̇]` from the body angular velocity (eq. 2.34 with eq. 2.33).
///
/// # Errors
/// As [`cardan_h_body_inv`].
pub fn cardan_rates_from_omega_body(angles: [f64; 3], omega_b: &Vec3) -> Result<[f64; 3]> {
    Ok(to_array(&(cardan_h_body_inv(angles)? * omega_b)))
}

#[cfg(test)]
pub(crate) mod tests {

    /// `J_l(θ) θ̇` is the angular velocity of `exp(θ̃)` and `J̇_l θ̇` the rest of its rate: both
    /// against central differences of the rotation matrix, small and large angles.
    #[test]
    fn so3_left_jacobian_and_rate_match_differences() {
        for (theta0, thetad, thetadd) in [
            (Vec3::new(0.3, -0.7, 1.1), Vec3::new(0.9, 0.4, -0.5), Vec3::new(-0.2, 0.6, 0.3)),
            (Vec3::new(2e-3, -1e-3, 4e-3), Vec3::new(0.9, 0.4, -0.5), Vec3::new(0.5, -0.1, 0.8)),
            (Vec3::new(0.05, 0.02, -0.06), Vec3::new(-0.3, 0.8, 0.1), Vec3::new(0.0, 0.0, 0.0)),
        ] {
            let at = |t: f64| theta0 + thetad * t + thetadd * (0.5 * t * t);
            let omega = |t: f64| {
                let h = 1e-6;
                let rd = (rotvec_to_matrix(&at(t + h)) - rotvec_to_matrix(&at(t - h))) / (2.0 * h);
                let w = rd * rotvec_to_matrix(&at(t)).transpose();
                Vec3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]) * 0.5
            };
            let w = so3_left_jacobian(&theta0) * thetad;
            assert!((w - omega(0.0)).norm() < 1e-8, "{w} vs {}", omega(0.0));
            let h = 1e-4;
            let wd_fd = (omega(h) - omega(-h)) / (2.0 * h);
            let wd = so3_left_jacobian(&theta0) * thetadd + so3_left_jacobian_rate(&theta0, &thetad);
            assert!((wd - wd_fd).norm() < 1e-5, "{wd} vs {wd_fd}");
        }
        // across the series/closed-form switch the coefficients agree
        let (lo, hi) = (so3_jacobian_coefficients(0.1 - 1e-12), so3_jacobian_coefficients(0.1 + 1e-12));
        for k in 0..4 {
            assert!((lo[k] - hi[k]).abs() < 1e-11, "coefficient {k}: {} vs {}", lo[k], hi[k]);
        }
    }

    use super::*;
    use crate::math::untilde;
    use nalgebra::{SMatrix, Vector4};

    /// Deterministic pseudo-random numbers (xorshift64*), so tests need no extra crate.
    pub(crate) struct Rng(u64);

    impl Rng {
        pub(crate) fn new(seed: u64) -> Self {
            Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
        }

        pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let u = (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64;
            lo + (hi - lo) * u
        }

        pub(crate) fn vec3(&mut self, r: f64) -> Vec3 {
            Vec3::new(self.uniform(-r, r), self.uniform(-r, r), self.uniform(-r, r))
        }
    }

    /// First derivative by the fourth-order central difference.
    pub(crate) fn d1<const R: usize, const C: usize>(
        f: impl Fn(f64) -> SMatrix<f64, R, C>,
        t: f64,
        h: f64,
    ) -> SMatrix<f64, R, C> {
        (f(t - 2.0 * h) - f(t - h) * 8.0 + f(t + h) * 8.0 - f(t + 2.0 * h)) / (12.0 * h)
    }

    /// Second derivative by the fourth-order central difference.
    pub(crate) fn d2<const R: usize, const C: usize>(
        f: impl Fn(f64) -> SMatrix<f64, R, C>,
        t: f64,
        h: f64,
    ) -> SMatrix<f64, R, C> {
        (-f(t - 2.0 * h) + f(t - h) * 16.0 - f(t) * 30.0 + f(t + h) * 16.0 - f(t + 2.0 * h)) / (12.0 * h * h)
    }

    fn q4(q: Quat) -> Vector4<f64> {
        Vector4::from(q)
    }

    /// Distance between two quaternions up to the sign ambiguity.
    fn quat_dist(p: Quat, q: Quat) -> f64 {
        (q4(p) - q4(q)).norm().min((q4(p) + q4(q)).norm())
    }

    fn angle_dist(a: f64, b: f64) -> f64 {
        wrap_angle(a - b).abs()
    }

    fn assert_rotation(a: &Mat3, tol: f64) {
        assert!((a.transpose() * a - Mat3::identity()).amax() < tol, "not orthogonal: {a}");
        assert!((a.determinant() - 1.0).abs() < tol, "det != 1: {a}");
    }

    /// Angles spread over the whole range, plus the singular and near-singular middle angles.
    fn euler_samples() -> Vec<[f64; 3]> {
        let mut rng = Rng::new(1);
        let mut v: Vec<[f64; 3]> =
            (0..300).map(|_| [rng.uniform(-PI, PI), rng.uniform(0.0, PI), rng.uniform(-PI, PI)]).collect();
        for theta in [0.0, 1e-15, 1e-13, 1e-9, 1e-6, 1e-3, PI - 1e-3, PI - 1e-9, PI - 1e-13, PI] {
            for _ in 0..10 {
                v.push([rng.uniform(-PI, PI), theta, rng.uniform(-PI, PI)]);
            }
        }
        v
    }

    fn cardan_samples() -> Vec<[f64; 3]> {
        let mut rng = Rng::new(2);
        let mut v: Vec<[f64; 3]> = (0..300)
            .map(|_| [rng.uniform(-PI, PI), rng.uniform(-FRAC_PI_2, FRAC_PI_2), rng.uniform(-PI, PI)])
            .collect();
        let h = FRAC_PI_2;
        for beta in [h, h - 1e-15, h - 1e-13, h - 1e-9, h - 1e-6, -h, -h + 1e-13, -h + 1e-9, -h + 1e-6, 0.0] {
            for _ in 0..10 {
                v.push([rng.uniform(-PI, PI), beta, rng.uniform(-PI, PI)]);
            }
        }
        v
    }

    #[test]
    fn elementary_rotations_map_axes() {
        let h = FRAC_PI_2;
        // a positive quarter turn about each axis maps the next axis to the one after it
        assert!((rot_x(h) * Vec3::y() - Vec3::z()).norm() < 1e-15);
        assert!((rot_y(h) * Vec3::z() - Vec3::x()).norm() < 1e-15);
        assert!((rot_z(h) * Vec3::x() - Vec3::y()).norm() < 1e-15);
        assert!((rot_x(h) * Vec3::z() + Vec3::y()).norm() < 1e-15);
        for a in [0.0, 0.4, -2.3, 3.0] {
            assert!((rot_axis(&Vec3::x(), a) - rot_x(a)).norm() < 1e-15);
            assert!((rot_axis(&Vec3::y(), a) - rot_y(a)).norm() < 1e-15);
            assert!((rot_axis(&Vec3::z(), a) - rot_z(a)).norm() < 1e-15);
        }
    }

    #[test]
    fn rodrigues_general_axis() {
        let mut rng = Rng::new(3);
        for _ in 0..50 {
            let n = rng.vec3(1.0).normalize();
            let th = rng.uniform(-PI, PI);
            let a = rot_axis(&n, th);
            assert_rotation(&a, 1e-14);
            assert!((a * n - n).norm() < 1e-14, "axis is fixed");
            // a vector perpendicular to n turns by θ towards n × u
            let u = n.cross(&rng.vec3(1.0)).normalize();
            let expect = u * th.cos() + n.cross(&u) * th.sin();
            assert!((a * u - expect).norm() < 1e-14);
            // agrees with the rotation vector and quaternion forms
            assert!((rotvec_to_matrix(&(n * th)) - a).amax() < 1e-14);
            assert!((quat_to_matrix(quat_from_axis_angle(&n, th)) - a).amax() < 1e-14);
        }
    }

    #[test]
    fn euler_matrix_is_product_of_elementary_rotations() {
        for e in euler_samples() {
            let a = euler_zxz_to_matrix(e);
            // eqs. 2.12–2.15
            let p = rot_z(e[0]) * rot_x(e[1]) * rot_z(e[2]);
            assert!((a - p).amax() < 1e-15);
            assert_rotation(&a, 1e-14);
        }
    }

    #[test]
    fn cardan_matrix_is_product_of_elementary_rotations() {
        for c in cardan_samples() {
            let a = cardan_xyz_to_matrix(c);
            // eqs. 2.16–2.19
            let p = rot_x(c[0]) * rot_y(c[1]) * rot_z(c[2]);
            assert!((a - p).amax() < 1e-15);
            assert_rotation(&a, 1e-14);
        }
    }

    #[test]
    fn known_values() {
        let h = FRAC_PI_2;
        // Cardan α = π/2 turns about x: y → z
        let a = cardan_xyz_to_matrix([h, 0.0, 0.0]);
        assert!((a * Vec3::y() - Vec3::z()).norm() < 1e-15);
        // Cardan β = π/2: z → x; γ = π/2: x → y
        assert!((cardan_xyz_to_matrix([0.0, h, 0.0]) * Vec3::z() - Vec3::x()).norm() < 1e-15);
        assert!((cardan_xyz_to_matrix([0.0, 0.0, h]) * Vec3::x() - Vec3::y()).norm() < 1e-15);
        // Euler ψ = π/2: x → y; ϑ = π/2: y → z; then the body z-axis after (0, π/2, 0) is −y
        assert!((euler_zxz_to_matrix([h, 0.0, 0.0]) * Vec3::x() - Vec3::y()).norm() < 1e-15);
        assert!((euler_zxz_to_matrix([0.0, h, 0.0]) * Vec3::y() - Vec3::z()).norm() < 1e-15);
        assert!((euler_zxz_to_matrix([0.0, h, 0.0]) * Vec3::z() + Vec3::y()).norm() < 1e-15);
        // Euler (π/2, π/2, 0): the nodal line is y, the body z-axis is the third column (sinψ sinϑ, −cosψ sinϑ, cosϑ)
        let a = euler_zxz_to_matrix([h, h, 0.0]);
        assert!((a * Vec3::x() - Vec3::y()).norm() < 1e-15);
        assert!((a * Vec3::z() - Vec3::x()).norm() < 1e-15);
        // quaternion of a quarter turn about z: [cos π/4, 0, 0, sin π/4]
        let q = matrix_to_quat(&rot_z(h)).unwrap();
        let s = 0.5_f64.sqrt();
        assert!(quat_dist(q, [s, 0.0, 0.0, s]) < 1e-15 && q[3] > 0.0);
        assert!((quat_rotate(q, &Vec3::x()) - Vec3::y()).norm() < 1e-15);
        // rotation vector of the same
        let rv = matrix_to_rotvec(&rot_z(h)).unwrap();
        assert!((rv - Vec3::new(0.0, 0.0, h)).norm() < 1e-15);
        // the Euler angles of Rx(0.7) are (0, 0.7, 0); its Cardan angles (0.7, 0, 0)
        let e = matrix_to_euler_zxz(&rot_x(0.7)).unwrap();
        assert!((e[0]).abs() < 1e-15 && (e[1] - 0.7).abs() < 1e-15 && e[2].abs() < 1e-15);
        let c = matrix_to_cardan_xyz(&rot_x(0.7)).unwrap();
        assert!((c[0] - 0.7).abs() < 1e-15 && c[1].abs() < 1e-15 && c[2].abs() < 1e-15);
        // Rx(−0.7) is Euler (π, 0.7, π) because ϑ must be ≥ 0
        let e = matrix_to_euler_zxz(&rot_x(-0.7)).unwrap();
        assert!(angle_dist(e[0], PI) < 1e-15 && (e[1] - 0.7).abs() < 1e-15 && angle_dist(e[2], PI) < 1e-15);
    }

    #[test]
    fn euler_angles_round_trip_through_matrix() {
        for e in euler_samples() {
            let a = euler_zxz_to_matrix(e);
            let back = matrix_to_euler_zxz(&a).unwrap();
            assert!(back[1] >= 0.0 && back[1] <= PI);
            assert!(back[0] > -PI && back[0] <= PI && back[2] > -PI && back[2] <= PI);
            // the matrix is always reproduced, also at and near the singularity
            assert!((euler_zxz_to_matrix(back) - a).amax() < 1e-13, "{e:?} -> {back:?}");
            // away from it the angles themselves come back
            if e[1].sin() > 1e-3 {
                for k in 0..3 {
                    assert!(angle_dist(back[k], e[k]) < 1e-12, "{e:?} -> {back:?}");
                }
            }
        }
    }

    #[test]
    fn cardan_angles_round_trip_through_matrix() {
        for c in cardan_samples() {
            let a = cardan_xyz_to_matrix(c);
            let back = matrix_to_cardan_xyz(&a).unwrap();
            assert!(back[1].abs() <= FRAC_PI_2);
            assert!((cardan_xyz_to_matrix(back) - a).amax() < 1e-13, "{c:?} -> {back:?}");
            if c[1].cos() > 1e-3 {
                for k in 0..3 {
                    assert!(angle_dist(back[k], c[k]) < 1e-12, "{c:?} -> {back:?}");
                }
            }
        }
    }

    #[test]
    fn degenerate_angles_pick_zero_third_angle() {
        // ϑ = 0: only ψ + φ matters
        let e = matrix_to_euler_zxz(&euler_zxz_to_matrix([0.5, 0.0, 0.9])).unwrap();
        assert!((e[0] - 1.4).abs() < 1e-14 && e[1].abs() < 1e-15 && e[2] == 0.0, "{e:?}");
        // ϑ = π: only ψ − φ matters
        let e = matrix_to_euler_zxz(&euler_zxz_to_matrix([0.5, PI, 0.9])).unwrap();
        assert!((e[0] + 0.4).abs() < 1e-14 && (e[1] - PI).abs() < 1e-15 && e[2] == 0.0, "{e:?}");
        // β = π/2: only α + γ; β = −π/2: only α − γ
        let c = matrix_to_cardan_xyz(&cardan_xyz_to_matrix([0.5, FRAC_PI_2, 0.9])).unwrap();
        assert!((c[0] - 1.4).abs() < 1e-14 && (c[1] - FRAC_PI_2).abs() < 1e-15 && c[2] == 0.0, "{c:?}");
        let c = matrix_to_cardan_xyz(&cardan_xyz_to_matrix([0.5, -FRAC_PI_2, 0.9])).unwrap();
        assert!((c[0] + 0.4).abs() < 1e-14 && (c[1] + FRAC_PI_2).abs() < 1e-15 && c[2] == 0.0, "{c:?}");
        // the identity
        assert_eq!(matrix_to_euler_zxz(&Mat3::identity()).unwrap(), [0.0, 0.0, 0.0]);
        assert_eq!(matrix_to_cardan_xyz(&Mat3::identity()).unwrap(), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn quaternion_round_trips() {
        let mut rng = Rng::new(4);
        for e in euler_samples() {
            let a = euler_zxz_to_matrix(e);
            let q = matrix_to_quat(&a).unwrap();
            assert!((quat_norm(q) - 1.0).abs() < 1e-15 && q[0] >= 0.0);
            assert!((quat_to_matrix(q) - a).amax() < 1e-14);
            // direct and matrix-based conversions agree
            assert!(quat_dist(euler_zxz_to_quat(e), q) < 1e-14);
            let e2 = quat_to_euler_zxz(q);
            assert!((euler_zxz_to_matrix(e2) - a).amax() < 1e-13);
            let v = rng.vec3(2.0);
            assert!((quat_rotate(q, &v) - a * v).norm() < 1e-14);
        }
        for c in cardan_samples() {
            let a = cardan_xyz_to_matrix(c);
            let q = cardan_xyz_to_quat(c);
            assert!(quat_dist(matrix_to_quat(&a).unwrap(), q) < 1e-14);
            assert!((quat_to_matrix(q) - a).amax() < 1e-14);
            assert!((cardan_xyz_to_matrix(quat_to_cardan_xyz(q)) - a).amax() < 1e-13);
            // a non-unit quaternion gives the same rotation (and, away from the singularity, the
            // same angles)
            let scaled = [3.0 * q[0], 3.0 * q[1], 3.0 * q[2], 3.0 * q[3]];
            let (c1, c2) = (quat_to_cardan_xyz(q), quat_to_cardan_xyz(scaled));
            assert!((cardan_xyz_to_matrix(c2) - a).amax() < 1e-13);
            if c[1].cos() > 1e-3 {
                assert!((0..3).all(|k| angle_dist(c1[k], c2[k]) < 1e-13), "{c1:?} {c2:?}");
            }
        }
    }

    #[test]
    fn shepperd_covers_all_branches() {
        // half turns about x, y, z and about a diagonal, where w = 0 and the other branches are taken
        let diag = Vec3::new(1.0, -2.0, 0.5).normalize();
        for (n, th) in [
            (Vec3::x(), PI),
            (Vec3::y(), PI),
            (Vec3::z(), PI),
            (diag, PI),
            (diag, PI - 1e-9),
            (Vec3::x(), 2.5),
            (Vec3::y(), -2.9),
            (Vec3::z(), 3.1),
            (diag, 1e-12),
        ] {
            let a = rot_axis(&n, th);
            let q = matrix_to_quat(&a).unwrap();
            assert!(quat_dist(q, quat_from_axis_angle(&n, th)) < 1e-14, "{n} {th}");
            assert!((quat_to_matrix(q) - a).amax() < 1e-14);
        }
    }

    #[test]
    fn quaternion_algebra() {
        let mut rng = Rng::new(5);
        for _ in 0..100 {
            let p = euler_zxz_to_quat([rng.uniform(-PI, PI), rng.uniform(0.0, PI), rng.uniform(-PI, PI)]);
            let q = cardan_xyz_to_quat([rng.uniform(-PI, PI), rng.uniform(-1.5, 1.5), rng.uniform(-PI, PI)]);
            // composition: A(p ⊗ q) = A(p) A(q)
            let pq = quat_mul(p, q);
            assert!((quat_to_matrix(pq) - quat_to_matrix(p) * quat_to_matrix(q)).amax() < 1e-14);
            // conjugate is the inverse
            let one = quat_mul(p, quat_conj(p));
            assert!(quat_dist(one, [1.0, 0.0, 0.0, 0.0]) < 1e-15);
            assert!((quat_to_matrix(quat_conj(p)) - quat_to_matrix(p).transpose()).amax() < 1e-15);
        }
        // the product is not commutative: i ⊗ j = k, j ⊗ i = −k
        assert_eq!(quat_mul([0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(quat_mul([0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0]), [0.0, 0.0, 0.0, -1.0]);
    }

    /// θ̇ = J_r⁻¹(θ) ω: moving θ by θ̇ dt turns A₀ exp(θ̃) by ω dt in its own frame.
    #[test]
    fn rotvec_rate_matches_body_rotation() {
        let w = Vec3::new(0.3, -1.1, 0.7);
        for th in [Vec3::new(1e-9, 2e-9, -1e-9), Vec3::new(3e-3, -2e-3, 1e-3), Vec3::new(0.4, -1.2, 2.1)] {
            let rate = rotvec_rate_body(&th, &w);
            let h = 1e-6;
            let ap = rotvec_to_matrix(&(th + rate * h));
            let am = rotvec_to_matrix(&(th - rate * h));
            let a = rotvec_to_matrix(&th);
            let wt = a.transpose() * (ap - am) / (2.0 * h);
            assert!((crate::math::untilde(&wt) - w).norm() < 1e-8, "{th}: {}", crate::math::untilde(&wt));
        }
    }

    #[test]
    fn quaternion_normalize() {
        let q = quat_normalize([2.0, 0.0, 0.0, -2.0]).unwrap();
        let s = 0.5_f64.sqrt();
        assert!(quat_dist(q, [s, 0.0, 0.0, -s]) < 1e-15 && q[3] < 0.0);
        let big = quat_normalize([1e300, 1e300, 0.0, 0.0]).unwrap();
        assert!((big[0] - s).abs() < 1e-15 && (big[1] - s).abs() < 1e-15);
        for bad in [[0.0; 4], [1e-13, 0.0, 0.0, 0.0], [f64::NAN, 1.0, 0.0, 0.0], [f64::INFINITY, 0.0, 0.0, 0.0]] {
            assert!(matches!(quat_normalize(bad), Err(Error::Model(_))), "{bad:?}");
        }
    }

    #[test]
    fn rotation_vector_round_trips() {
        let mut rng = Rng::new(6);
        let mut cases: Vec<Vec3> = (0..200).map(|_| rng.vec3(1.0).normalize() * rng.uniform(0.0, PI)).collect();
        for th in [0.0, 1e-300, 1e-12, 1e-8, 1e-4, PI - 1e-6, PI - 1e-9, PI - 1e-12, PI] {
            for _ in 0..5 {
                cases.push(rng.vec3(1.0).normalize() * th);
            }
        }
        for rv in cases {
            let th = rv.norm();
            let a = rotvec_to_matrix(&rv);
            assert_rotation(&a, 1e-14);
            if th > 0.0 {
                assert!((a - rot_axis(&(rv / th), th)).amax() < 1e-14);
            }
            let back = matrix_to_rotvec(&a).unwrap();
            assert!(back.norm() <= PI * (1.0 + 1e-15));
            assert!((rotvec_to_matrix(&back) - a).amax() < 1e-14);
            if th < PI - 1e-6 {
                // relative accuracy also for tiny angles
                assert!((back - rv).norm() <= 1e-12 * th.max(1e-300), "{rv} -> {back}");
            } else {
                // near π the axis may flip
                assert!((back - rv).norm().min((back + rv).norm()) < 1e-8, "{rv} -> {back}");
            }
            let q = rotvec_to_quat(&rv);
            assert!((quat_norm(q) - 1.0).abs() < 1e-15);
            assert!((quat_to_matrix(q) - a).amax() < 1e-14);
            assert!((rotvec_to_matrix(&quat_to_rotvec(q)) - a).amax() < 1e-14);
            // −q is the same rotation
            let nq = [-q[0], -q[1], -q[2], -q[3]];
            assert!((quat_to_rotvec(nq) - quat_to_rotvec(q)).norm() < 1e-12 || th > PI - 1e-6);
        }
        // a turn by more than π comes back as the shorter opposite turn
        let rv = matrix_to_rotvec(&rot_z(1.5 * PI)).unwrap();
        assert!((rv - Vec3::new(0.0, 0.0, -0.5 * PI)).norm() < 1e-14);
    }

    #[test]
    fn pairwise_conversions_agree_with_matrices() {
        let mut rng = Rng::new(7);
        for e in euler_samples() {
            let a = euler_zxz_to_matrix(e);
            let c = euler_zxz_to_cardan_xyz(e);
            assert!((cardan_xyz_to_matrix(c) - a).amax() < 1e-13);
            assert!((euler_zxz_to_matrix(cardan_xyz_to_euler_zxz(c)) - a).amax() < 1e-13);
            let rv = euler_zxz_to_rotvec(e);
            assert!((rotvec_to_matrix(&rv) - a).amax() < 1e-13);
            assert!((euler_zxz_to_matrix(rotvec_to_euler_zxz(&rv)) - a).amax() < 1e-13);
        }
        for c in cardan_samples() {
            let a = cardan_xyz_to_matrix(c);
            let rv = cardan_xyz_to_rotvec(c);
            assert!((rotvec_to_matrix(&rv) - a).amax() < 1e-13);
            assert!((cardan_xyz_to_matrix(rotvec_to_cardan_xyz(&rv)) - a).amax() < 1e-13);
            let e = cardan_xyz_to_euler_zxz(c);
            assert!((euler_zxz_to_matrix(e) - a).amax() < 1e-13);
        }
        // angle round trips away from the singularities of both sets
        for _ in 0..100 {
            let e = [rng.uniform(-PI, PI), rng.uniform(0.2, PI - 0.2), rng.uniform(-PI, PI)];
            if cardan_xyz_to_matrix(euler_zxz_to_cardan_xyz(e))[(0, 2)].abs() > 0.99 {
                continue;
            }
            let back = cardan_xyz_to_euler_zxz(euler_zxz_to_cardan_xyz(e));
            assert!((0..3).all(|k| angle_dist(back[k], e[k]) < 1e-12), "{e:?} {back:?}");
            let back = rotvec_to_euler_zxz(&euler_zxz_to_rotvec(e));
            assert!((0..3).all(|k| angle_dist(back[k], e[k]) < 1e-12), "{e:?} {back:?}");
            let c = [rng.uniform(-PI, PI), rng.uniform(-1.4, 1.4), rng.uniform(-PI, PI)];
            let back = rotvec_to_cardan_xyz(&cardan_xyz_to_rotvec(c));
            assert!((0..3).all(|k| angle_dist(back[k], c[k]) < 1e-12), "{c:?} {back:?}");
            let q = cardan_xyz_to_quat(c);
            let back = quat_to_cardan_xyz(q);
            assert!((0..3).all(|k| angle_dist(back[k], c[k]) < 1e-12), "{c:?} {back:?}");
        }
    }

    #[test]
    fn invalid_matrices_are_rejected() {
        let mut bad = rot_x(0.3);
        bad[(0, 1)] += 1e-3;
        let reflection = Mat3::from_diagonal(&Vec3::new(1.0, 1.0, -1.0));
        let mut nan = Mat3::identity();
        nan[(2, 2)] = f64::NAN;
        for m in [bad, reflection, nan, Mat3::zeros()] {
            assert!(matches!(matrix_to_quat(&m), Err(Error::Model(_))));
            assert!(matches!(matrix_to_euler_zxz(&m), Err(Error::Model(_))));
            assert!(matches!(matrix_to_cardan_xyz(&m), Err(Error::Model(_))));
            assert!(matches!(matrix_to_rotvec(&m), Err(Error::Model(_))));
        }
        // a slightly drifted rotation is accepted and its quaternion is the nearby rotation
        let mut drift = rot_x(0.3);
        drift[(1, 1)] *= 1.0 + 1e-8;
        let q = matrix_to_quat(&drift).unwrap();
        assert!((quat_norm(q) - 1.0).abs() < 1e-15);
        assert!(quat_dist(q, quat_from_axis_angle(&Vec3::x(), 0.3)) < 1e-8);
    }

    fn h_samples(set: AngleSet) -> Vec<[f64; 3]> {
        let mut rng = Rng::new(8);
        (0..200)
            .map(|_| match set {
                AngleSet::EulerZxz => [rng.uniform(-PI, PI), rng.uniform(0.05, PI - 0.05), rng.uniform(-PI, PI)],
                AngleSet::CardanXyz => [rng.uniform(-PI, PI), rng.uniform(-1.5, 1.5), rng.uniform(-PI, PI)],
            })
            .collect()
    }

    #[test]
    fn h_times_h_star_is_identity() {
        type HPair = (fn([f64; 3]) -> Mat3, fn([f64; 3]) -> Result<Mat3>, AngleSet);
        let pairs: [HPair; 4] = [
            (euler_h_inertial, euler_h_inertial_inv, AngleSet::EulerZxz),
            (euler_h_body, euler_h_body_inv, AngleSet::EulerZxz),
            (cardan_h_inertial, cardan_h_inertial_inv, AngleSet::CardanXyz),
            (cardan_h_body, cardan_h_body_inv, AngleSet::CardanXyz),
        ];
        for (h, h_inv, set) in pairs {
            for p in h_samples(set) {
                let hs = h_inv(p).unwrap();
                assert!((h(p) * hs - Mat3::identity()).amax() < 1e-12);
                assert!((hs * h(p) - Mat3::identity()).amax() < 1e-12);
            }
        }
    }

    #[test]
    fn body_and_inertial_h_are_related_by_a_ib() {
        for p in h_samples(AngleSet::EulerZxz) {
            let a = euler_zxz_to_matrix(p);
            assert!((euler_h_inertial(p) - a * euler_h_body(p)).amax() < 1e-14);
        }
        for p in h_samples(AngleSet::CardanXyz) {
            let a = cardan_xyz_to_matrix(p);
            assert!((cardan_h_inertial(p) - a * cardan_h_body(p)).amax() < 1e-14);
        }
    }

    /// ω̃_I = Ȧ_IB A_BI and ω̃_B = A_BI Ȧ_IB (eq. 2.35) by finite differences along p + ṗ t.
    #[test]
    fn h_matrices_agree_with_matrix_derivative() {
        let mut rng = Rng::new(9);
        type Case = (fn([f64; 3]) -> Mat3, fn([f64; 3]) -> Mat3, fn([f64; 3]) -> Mat3, AngleSet);
        let cases: [Case; 2] = [
            (euler_zxz_to_matrix, euler_h_inertial, euler_h_body, AngleSet::EulerZxz),
            (cardan_xyz_to_matrix, cardan_h_inertial, cardan_h_body, AngleSet::CardanXyz),
        ];
        for (to_matrix, h_i, h_b, set) in cases {
            for p in h_samples(set) {
                let pd = rng.vec3(2.0);
                let path = |t: f64| to_matrix([p[0] + pd.x * t, p[1] + pd.y * t, p[2] + pd.z * t]);
                let a = path(0.0);
                let a_dot = d1(path, 0.0, 1e-3);
                let w_i_tilde = a_dot * a.transpose();
                let w_b_tilde = a.transpose() * a_dot;
                // both products are skew-symmetric (eq. 2.29)
                assert!((w_i_tilde + w_i_tilde.transpose()).amax() < 1e-9);
                let w_i = h_i(p) * pd;
                let w_b = h_b(p) * pd;
                assert!((untilde(&w_i_tilde) - w_i).norm() < 1e-7, "{set:?} {p:?}");
                assert!((untilde(&w_b_tilde) - w_b).norm() < 1e-7, "{set:?} {p:?}");
                assert!((tilde(&w_i) - a * tilde(&w_b) * a.transpose()).amax() < 1e-13);
            }
        }
    }

    #[test]
    fn rates_from_omega_invert_h() {
        let mut rng = Rng::new(10);
        for p in h_samples(AngleSet::EulerZxz) {
            let pd = rng.vec3(3.0);
            let r = euler_rates_from_omega_inertial(p, &(euler_h_inertial(p) * pd)).unwrap();
            assert!((Vec3::from(r) - pd).norm() < 1e-11);
            let r = euler_rates_from_omega_body(p, &(euler_h_body(p) * pd)).unwrap();
            assert!((Vec3::from(r) - pd).norm() < 1e-11);
        }
        for p in h_samples(AngleSet::CardanXyz) {
            let pd = rng.vec3(3.0);
            let r = cardan_rates_from_omega_inertial(p, &(cardan_h_inertial(p) * pd)).unwrap();
            assert!((Vec3::from(r) - pd).norm() < 1e-11);
            let r = cardan_rates_from_omega_body(p, &(cardan_h_body(p) * pd)).unwrap();
            assert!((Vec3::from(r) - pd).norm() < 1e-11);
        }
        // a pure spin about the body z-axis at ϑ = π/2 is φ̇ alone
        let r = euler_rates_from_omega_body([0.3, FRAC_PI_2, -0.2], &Vec3::new(0.0, 0.0, 2.0)).unwrap();
        assert!((Vec3::from(r) - Vec3::new(0.0, 0.0, 2.0)).norm() < 1e-15);
    }

    #[test]
    fn singularities_are_reported() {
        let w = Vec3::new(0.1, 0.2, 0.3);
        for theta in [0.0, 1e-10, -1e-10, PI, PI - 1e-10] {
            let p = [0.3, theta, -0.4];
            assert!(is_near_singular(AngleSet::EulerZxz, p, SINGULAR_TOL));
            for r in [euler_h_inertial_inv(p), euler_h_body_inv(p)] {
                match r {
                    Err(Error::Singular(msg)) => {
                        assert!(msg.contains("singular") && msg.contains("Euler"), "{msg}")
                    }
                    other => panic!("expected a singularity error, got {other:?}"),
                }
            }
            assert!(euler_rates_from_omega_inertial(p, &w).is_err());
            assert!(euler_rates_from_omega_body(p, &w).is_err());
        }
        for beta in [FRAC_PI_2, -FRAC_PI_2, FRAC_PI_2 - 1e-10, -FRAC_PI_2 + 1e-10] {
            let p = [0.3, beta, -0.4];
            assert!(is_near_singular(AngleSet::CardanXyz, p, SINGULAR_TOL));
            for r in [cardan_h_inertial_inv(p), cardan_h_body_inv(p)] {
                match r {
                    Err(Error::Singular(msg)) => {
                        assert!(msg.contains("singular") && msg.contains("Cardan"), "{msg}")
                    }
                    other => panic!("expected a singularity error, got {other:?}"),
                }
            }
            assert!(cardan_rates_from_omega_inertial(p, &w).is_err());
            assert!(cardan_rates_from_omega_body(p, &w).is_err());
        }
        // just outside the tolerance H* is finite
        let p = [0.3, 1e-8, -0.4];
        assert!(!is_near_singular(AngleSet::EulerZxz, p, SINGULAR_TOL));
        assert!(euler_h_body_inv(p).unwrap().iter().all(|v| v.is_finite()));
        assert!(is_near_singular(AngleSet::EulerZxz, p, 1e-6));
        assert!(!is_near_singular(AngleSet::CardanXyz, [0.0, 0.0, 0.0], 1e-6));
        assert!((singularity_margin(AngleSet::CardanXyz, [0.0, 1.0, 0.0]) - 1.0_f64.cos()).abs() < 1e-16);
        // non-finite angles are errors too, never NaN matrices
        let p = [f64::NAN, 1.0, 0.0];
        assert!(is_near_singular(AngleSet::EulerZxz, [0.0, f64::NAN, 0.0], 1e-9));
        assert!(matches!(euler_h_inertial_inv(p), Err(Error::Solver(_))));
        assert!(matches!(cardan_h_body_inv([0.0, f64::INFINITY, 0.0]), Err(Error::Solver(_))));
    }

    /// Cardan angles that are polynomials in t, with their rates.
    fn cardan_path(t: f64) -> [f64; 3] {
        [0.3 + 1.1 * t - 0.7 * t * t, -0.4 + 0.8 * t + 0.5 * t * t * t, 1.2 - 2.0 * t + 0.9 * t * t]
    }

    fn cardan_path_rate(t: f64) -> Vec3 {
        Vec3::new(1.1 - 1.4 * t, 0.8 + 1.5 * t * t, -2.0 + 1.8 * t)
    }

    #[test]
    fn quaternion_derivative_matches_finite_differences() {
        for t in [0.0, 0.3, 0.8] {
            let q = cardan_xyz_to_quat(cardan_path(t));
            let w_b = cardan_h_body(cardan_path(t)) * cardan_path_rate(t);
            let w_i = cardan_h_inertial(cardan_path(t)) * cardan_path_rate(t);
            let qd_fd = d1(|s| q4(cardan_xyz_to_quat(cardan_path(s))), t, 1e-3);
            let qd = q4(quat_derivative(q, &w_b));
            assert!((qd - qd_fd).norm() < 1e-9, "{qd} {qd_fd}");
            assert!((quat_derivative_matrix(q) * w_b - qd_fd).norm() < 1e-9);
            assert!((q4(quat_derivative_inertial(q, &w_i)) - qd_fd).norm() < 1e-9);
            // and back
            let qd_arr = [qd_fd[0], qd_fd[1], qd_fd[2], qd_fd[3]];
            assert!((quat_omega_body(q, qd_arr) - w_b).norm() < 1e-9);
            assert!((quat_omega_inertial(q, qd_arr) - w_i).norm() < 1e-9);
            let g = quat_derivative_matrix(q);
            assert!((g.transpose() * g * 4.0 - Mat3::identity()).amax() < 1e-15);
        }
    }

    #[test]
    fn quat_integrate_is_exact_for_constant_omega() {
        let q0 = euler_zxz_to_quat([0.4, 1.1, -2.0]);
        let a0 = quat_to_matrix(q0);
        for (w, dt) in [
            (Vec3::new(0.3, -1.2, 2.0), 0.7),
            (Vec3::new(0.0, 0.0, 5.0), 0.1),
            (Vec3::new(1e-13, 0.0, -2e-13), 0.5),
            (Vec3::zeros(), 1.0),
            (Vec3::new(-4.0, 3.0, 0.0), 2.0),
        ] {
            let th = w.norm() * dt;
            let turn = if w.norm() > 0.0 { rot_axis(&w.normalize(), th) } else { Mat3::identity() };
            // body ω: the turn is applied on the right; inertial ω: on the left
            assert!((quat_to_matrix(quat_integrate(q0, &w, dt)) - a0 * turn).amax() < 1e-14);
            assert!((quat_to_matrix(quat_integrate_inertial(q0, &w, dt)) - turn * a0).amax() < 1e-14);
        }
        // consistent with the derivative: RK4 on q̇ = ½ q ⊗ (0, ω) reaches the same point
        let w = Vec3::new(0.3, -1.2, 2.0);
        let (n, t_end) = (1000, 1.3);
        let h = t_end / n as f64;
        let mut q = q4(q0);
        let f = |q: Vector4<f64>| q4(quat_derivative([q[0], q[1], q[2], q[3]], &w));
        for _ in 0..n {
            let k1 = f(q);
            let k2 = f(q + k1 * (0.5 * h));
            let k3 = f(q + k2 * (0.5 * h));
            let k4 = f(q + k3 * h);
            q += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        }
        assert!((q - q4(quat_integrate(q0, &w, t_end))).norm() < 1e-12);
    }

    #[test]
    fn wrap_angle_range() {
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap_angle(-7.0) - (-7.0 + TAU)).abs() < 1e-15);
        assert_eq!(wrap_angle(0.25), 0.25);
    }
}
