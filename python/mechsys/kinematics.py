"""Rotations and relative kinematics: the engine's ``math::rotation`` and ``math::frames``.

Conventions (section 2 of the reference):

* ``A_IB`` maps body (B) components to inertial (I) components, ``r_I = A_IB r_B`` (eq. 2.21); it
  is orthogonal, ``A_BI = A_IB^T`` (eqs. 2.8, 2.22).
* Euler angles z-x-z ``[psi, theta, phi]``: ``A_IB = Rz(psi) Rx(theta) Rz(phi)`` (eqs. 2.12-2.15),
  psi, phi in (-pi, pi], theta in [0, pi]; singular where sin(theta) = 0.
* Cardan angles x-y-z ``[alpha, beta, gamma]``: ``A_IB = Rx(alpha) Ry(beta) Rz(gamma)``
  (eqs. 2.16-2.19), alpha, gamma in (-pi, pi], beta in [-pi/2, pi/2]; singular where cos(beta) = 0.
* Quaternions ``[w, x, y, z]``, scalar first, Hamilton product, ``A(p ⊗ q) = A(p) A(q)``.
* Rotation vectors ``axis * angle`` with angle in [0, pi].
* ``omega = H p_dot`` and ``p_dot = H* omega`` (eqs. 2.30-2.34), in inertial or body components.

Every function takes numbers, lists or numpy arrays (3-vectors, 3x3 matrices, length-4
quaternions) and returns numpy arrays. Bad input raises :class:`mechsys.SettingsError` (a
``ValueError``) naming the argument; a matrix that is not a rotation raises
:class:`mechsys.ModelError`; ``H*`` at its singularity raises :class:`mechsys.SingularityError`.
Quaternions that the formulas assume to be unit length (and rotation axes) must be so within
:data:`UNIT_TOL`.

>>> import numpy as np
>>> from mechsys import kinematics as kin
>>> a = kin.cardan_xyz_to_matrix([np.pi / 2, 0.0, 0.0])
>>> np.round(a @ [0.0, 1.0, 0.0], 12) + 0.0
array([0., 0., 1.])
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from . import _core
from .errors import SettingsError

SINGULAR_TOL: float = _core.SINGULAR_TOL
"""Threshold on |sin theta| (Euler) or |cos beta| (Cardan) below which ``H*`` is singular."""
ROTATION_MATRIX_TOL: float = _core.ROTATION_MATRIX_TOL
"""Largest entry of |A^T A - E| accepted for an argument that must be a rotation matrix."""
UNIT_TOL: float = _core.UNIT_TOL
"""Largest | |q| - 1 | accepted for arguments that must be unit quaternions or unit axes."""

# ---------------------------------------------------------------------------------------------
# Elementary rotations, tilde
# ---------------------------------------------------------------------------------------------


def rot_x(angle: float) -> np.ndarray:
    """Elementary rotation about the x axis, ``[[1, 0, 0], [0, c, -s], [0, s, c]]`` (the form of
    eqs. 2.13, 2.16)."""
    return _core.rot_x(angle)


def rot_y(angle: float) -> np.ndarray:
    """Elementary rotation about the y axis, ``[[c, 0, s], [0, 1, 0], [-s, 0, c]]`` (eq. 2.17)."""
    return _core.rot_y(angle)


def rot_z(angle: float) -> np.ndarray:
    """Elementary rotation about the z axis, ``[[c, -s, 0], [s, c, 0], [0, 0, 1]]`` (the form of
    eqs. 2.12, 2.14, 2.18)."""
    return _core.rot_z(angle)


def rot_axis(axis, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about the unit vector ``axis``: ``E + sin(angle) ñ + (1 - cos(angle)) ñ²``
    (Rodrigues' formula, with ñ of eq. 2.36)."""
    return _core.rot_axis(axis, angle)


def wrap_angle(angle: float) -> float:
    """The angle mapped to (-pi, pi]."""
    return _core.wrap_angle(angle)


def check_rotation_matrix(a_ib, tol: float | None = None) -> None:
    """Raises :class:`mechsys.ModelError` unless ``a_ib`` is a proper rotation: finite,
    ``max |A^T A - E| <= tol`` (eq. 2.8, default :data:`ROTATION_MATRIX_TOL`) and ``det A > 0``."""
    _core.check_rotation_matrix(a_ib, tol)


def tilde(a) -> np.ndarray:
    """The skew-symmetric matrix ``ã`` with ``ã b = a × b`` (eq. 2.36); ``ã^T = -ã`` (eq. 2.37)."""
    return _core.tilde(a)


def untilde(m) -> np.ndarray:
    """The vector ``a`` of a skew-symmetric matrix ``ã`` (inverse of :func:`tilde`, eq. 2.36); the
    symmetric part of ``m`` is ignored."""
    return _core.untilde(m)


# ---------------------------------------------------------------------------------------------
# Euler angles z-x-z and Cardan angles x-y-z
# ---------------------------------------------------------------------------------------------


def euler_zxz_to_matrix(angles) -> np.ndarray:
    """``A_IB = Rz(psi) Rx(theta) Rz(phi)`` of Euler angles ``[psi, theta, phi]`` (eqs. 2.12-2.15)."""
    return _core.euler_zxz_to_matrix(angles)


def matrix_to_euler_zxz(a_ib) -> np.ndarray:
    """Euler angles ``[psi, theta, phi]`` of ``A_IB`` (inverse of eq. 2.15), psi, phi in (-pi, pi],
    theta in [0, pi]. At theta = 0 or pi only psi ± phi is determined; phi = 0 is returned."""
    return _core.matrix_to_euler_zxz(a_ib)


def cardan_xyz_to_matrix(angles) -> np.ndarray:
    """``A_IB = Rx(alpha) Ry(beta) Rz(gamma)`` of Cardan angles ``[alpha, beta, gamma]``
    (eqs. 2.16-2.19)."""
    return _core.cardan_xyz_to_matrix(angles)


def matrix_to_cardan_xyz(a_ib) -> np.ndarray:
    """Cardan angles ``[alpha, beta, gamma]`` of ``A_IB`` (inverse of eq. 2.19), alpha, gamma in
    (-pi, pi], beta in [-pi/2, pi/2]. At beta = ±pi/2 only alpha ± gamma is determined; gamma = 0
    is returned."""
    return _core.matrix_to_cardan_xyz(a_ib)


def euler_zxz_to_cardan_xyz(angles) -> np.ndarray:
    """Cardan angles (eq. 2.19) of the rotation given by Euler angles (eq. 2.15)."""
    return _core.euler_zxz_to_cardan_xyz(angles)


def cardan_xyz_to_euler_zxz(angles) -> np.ndarray:
    """Euler angles (eq. 2.15) of the rotation given by Cardan angles (eq. 2.19)."""
    return _core.cardan_xyz_to_euler_zxz(angles)


# ---------------------------------------------------------------------------------------------
# Quaternions
# ---------------------------------------------------------------------------------------------


def quat_to_matrix(q) -> np.ndarray:
    """``A_IB`` of a unit quaternion ``[w, x, y, z]``: ``(w² - v·v) E + 2 v v^T + 2 w ṽ``."""
    return _core.quat_to_matrix(q)


def matrix_to_quat(a_ib) -> np.ndarray:
    """Unit quaternion (w >= 0) of ``A_IB`` by Shepperd's method, accurate for all rotations."""
    return _core.matrix_to_quat(a_ib)


def quat_mul(p, q) -> np.ndarray:
    """Hamilton product ``p ⊗ q``, with ``A(p ⊗ q) = A(p) A(q)`` (as the chain of eq. 2.11)."""
    return _core.quat_mul(p, q)


def quat_conj(q) -> np.ndarray:
    """Conjugate ``[w, -x, -y, -z]``: the inverse rotation of a unit quaternion (``A_BI``, eq. 2.22)."""
    return _core.quat_conj(q)


def quat_normalize(q) -> np.ndarray:
    """``q / |q|``; raises :class:`mechsys.ModelError` for a (near-)zero quaternion."""
    return _core.quat_normalize(q)


def quat_rotate(q, v) -> np.ndarray:
    """``A(q) v`` = ``q ⊗ (0, v) ⊗ q*`` for a unit quaternion (eq. 2.21 with ``A_IB = A(q)``)."""
    return _core.quat_rotate(q, v)


def quat_from_axis_angle(axis, angle: float) -> np.ndarray:
    """``[cos(angle/2), sin(angle/2) axis]`` for a unit ``axis`` (same rotation as :func:`rot_axis`)."""
    return _core.quat_from_axis_angle(axis, angle)


def quat_derivative(q, omega_b) -> np.ndarray:
    """``q_dot = ½ q ⊗ (0, omega_B)`` from the body angular velocity (the quaternion counterpart of
    eq. 2.31)."""
    return _core.quat_derivative(q, omega_b)


def quat_derivative_matrix(q) -> np.ndarray:
    """The 4x3 matrix ``G(q)`` with ``q_dot = G(q) omega_B``; ``4 G^T G = E``, so ``omega_B = 4 G^T q_dot``."""
    return _core.quat_derivative_matrix(q)


def quat_derivative_inertial(q, omega_i) -> np.ndarray:
    """``q_dot = ½ (0, omega_I) ⊗ q`` from the inertial angular velocity (counterpart of eq. 2.30)."""
    return _core.quat_derivative_inertial(q, omega_i)


def quat_omega_body(q, qdot) -> np.ndarray:
    """``omega_B = 2 vec(q* ⊗ q_dot)`` (inverse of :func:`quat_derivative`)."""
    return _core.quat_omega_body(q, qdot)


def quat_omega_inertial(q, qdot) -> np.ndarray:
    """``omega_I = 2 vec(q_dot ⊗ q*)`` (inverse of :func:`quat_derivative_inertial`)."""
    return _core.quat_omega_inertial(q, qdot)


def quat_integrate(q, omega_b, dt: float) -> np.ndarray:
    """``q ⊗ exp(½ omega_B dt)``: exact solution of ``q_dot = ½ q ⊗ (0, omega_B)`` for constant
    ``omega_B``, i.e. ``A_IB(t + dt) = A_IB(t) rot_axis(omega_B/|omega_B|, |omega_B| dt)``."""
    return _core.quat_integrate(q, omega_b, dt)


def quat_integrate_inertial(q, omega_i, dt: float) -> np.ndarray:
    """``exp(½ omega_I dt) ⊗ q``: exact for constant ``omega_I``, i.e.
    ``A_IB(t + dt) = rot_axis(omega_I/|omega_I|, |omega_I| dt) A_IB(t)``."""
    return _core.quat_integrate_inertial(q, omega_i, dt)


def euler_zxz_to_quat(angles) -> np.ndarray:
    """Unit quaternion ``q_z(psi) ⊗ q_x(theta) ⊗ q_z(phi)`` of Euler angles (eq. 2.15), continuous
    in the angles."""
    return _core.euler_zxz_to_quat(angles)


def quat_to_euler_zxz(q) -> np.ndarray:
    """Euler angles of a nonzero quaternion (need not be normalized); ranges as
    :func:`matrix_to_euler_zxz`."""
    return _core.quat_to_euler_zxz(q)


def cardan_xyz_to_quat(angles) -> np.ndarray:
    """Unit quaternion ``q_x(alpha) ⊗ q_y(beta) ⊗ q_z(gamma)`` of Cardan angles (eq. 2.19),
    continuous in the angles."""
    return _core.cardan_xyz_to_quat(angles)


def quat_to_cardan_xyz(q) -> np.ndarray:
    """Cardan angles of a nonzero quaternion (need not be normalized); ranges as
    :func:`matrix_to_cardan_xyz`."""
    return _core.quat_to_cardan_xyz(q)


# ---------------------------------------------------------------------------------------------
# Rotation vector
# ---------------------------------------------------------------------------------------------


def rotvec_to_matrix(rotvec) -> np.ndarray:
    """``A_IB`` of a rotation vector ``angle * axis`` (Rodrigues' formula, accurate for small angles)."""
    return _core.rotvec_to_matrix(rotvec)


def matrix_to_rotvec(a_ib) -> np.ndarray:
    """Rotation vector (angle in [0, pi]) of ``A_IB``; at exactly pi either axis may be returned."""
    return _core.matrix_to_rotvec(a_ib)


def rotvec_to_quat(rotvec) -> np.ndarray:
    """Unit quaternion ``[cos(θ/2), sin(θ/2) n]`` of ``θ n`` (the exponential map)."""
    return _core.rotvec_to_quat(rotvec)


def quat_to_rotvec(q) -> np.ndarray:
    """Rotation vector (angle in [0, pi]) of a nonzero quaternion (the logarithmic map); ``q`` and
    ``-q`` give the same result."""
    return _core.quat_to_rotvec(q)


def euler_zxz_to_rotvec(angles) -> np.ndarray:
    """Rotation vector of Euler angles (eq. 2.15)."""
    return _core.euler_zxz_to_rotvec(angles)


def rotvec_to_euler_zxz(rotvec) -> np.ndarray:
    """Euler angles (eq. 2.15) of a rotation vector; ranges as :func:`matrix_to_euler_zxz`."""
    return _core.rotvec_to_euler_zxz(rotvec)


def cardan_xyz_to_rotvec(angles) -> np.ndarray:
    """Rotation vector of Cardan angles (eq. 2.19)."""
    return _core.cardan_xyz_to_rotvec(angles)


def rotvec_to_cardan_xyz(rotvec) -> np.ndarray:
    """Cardan angles (eq. 2.19) of a rotation vector; ranges as :func:`matrix_to_cardan_xyz`."""
    return _core.rotvec_to_cardan_xyz(rotvec)


# ---------------------------------------------------------------------------------------------
# Angular-velocity matrices H (omega = H p_dot) and H* (p_dot = H* omega), eqs. 2.30-2.34
# ---------------------------------------------------------------------------------------------


def euler_h_inertial(angles) -> np.ndarray:
    """``H`` with ``omega_I = H [psi_dot, theta_dot, phi_dot]`` (eq. 2.30)."""
    return _core.euler_h_inertial(angles)


def euler_h_body(angles) -> np.ndarray:
    """``H`` with ``omega_B = H [psi_dot, theta_dot, phi_dot]`` (eq. 2.31)."""
    return _core.euler_h_body(angles)


def cardan_h_inertial(angles) -> np.ndarray:
    """``H`` with ``omega_I = H [alpha_dot, beta_dot, gamma_dot]`` (eq. 2.32)."""
    return _core.cardan_h_inertial(angles)


def cardan_h_body(angles) -> np.ndarray:
    """``H`` with ``omega_B = H [alpha_dot, beta_dot, gamma_dot]`` (eq. 2.33)."""
    return _core.cardan_h_body(angles)


def euler_h_inertial_inv(angles) -> np.ndarray:
    """``H* = H^-1`` of eq. 2.30 (eq. 2.34); :class:`mechsys.SingularityError` where
    |sin theta| < :data:`SINGULAR_TOL`."""
    return _core.euler_h_inertial_inv(angles)


def euler_h_body_inv(angles) -> np.ndarray:
    """``H* = H^-1`` of eq. 2.31 (eq. 2.34); :class:`mechsys.SingularityError` where
    |sin theta| < :data:`SINGULAR_TOL`."""
    return _core.euler_h_body_inv(angles)


def cardan_h_inertial_inv(angles) -> np.ndarray:
    """``H* = H^-1`` of eq. 2.32 (eq. 2.34); :class:`mechsys.SingularityError` where
    |cos beta| < :data:`SINGULAR_TOL`."""
    return _core.cardan_h_inertial_inv(angles)


def cardan_h_body_inv(angles) -> np.ndarray:
    """``H* = H^-1`` of eq. 2.33 (eq. 2.34); :class:`mechsys.SingularityError` where
    |cos beta| < :data:`SINGULAR_TOL`."""
    return _core.cardan_h_body_inv(angles)


def singularity_margin(angle_set: str, angles) -> float:
    """Distance from the singularity of ``H*`` (eq. 2.34): |sin theta| for
    ``angle_set='euler_zxz'``, |cos beta| for ``'cardan_xyz'``."""
    return _core.singularity_margin(angle_set, angles)


def is_near_singular(angle_set: str, angles, tol: float | None = None) -> bool:
    """Whether :func:`singularity_margin` is below ``tol`` (default :data:`SINGULAR_TOL`)."""
    return _core.is_near_singular(angle_set, angles, tol)


def euler_rates_from_omega_inertial(angles, omega_i) -> np.ndarray:
    """``[psi_dot, theta_dot, phi_dot] = H* omega_I`` (eq. 2.34 with eq. 2.30)."""
    return _core.euler_rates_from_omega_inertial(angles, omega_i)


def euler_rates_from_omega_body(angles, omega_b) -> np.ndarray:
    """``[psi_dot, theta_dot, phi_dot] = H* omega_B`` (eq. 2.34 with eq. 2.31)."""
    return _core.euler_rates_from_omega_body(angles, omega_b)


def cardan_rates_from_omega_inertial(angles, omega_i) -> np.ndarray:
    """``[alpha_dot, beta_dot, gamma_dot] = H* omega_I`` (eq. 2.34 with eq. 2.32)."""
    return _core.cardan_rates_from_omega_inertial(angles, omega_i)


def cardan_rates_from_omega_body(angles, omega_b) -> np.ndarray:
    """``[alpha_dot, beta_dot, gamma_dot] = H* omega_B`` (eq. 2.34 with eq. 2.33)."""
    return _core.cardan_rates_from_omega_body(angles, omega_b)


# ---------------------------------------------------------------------------------------------
# Moving frames
# ---------------------------------------------------------------------------------------------


def chain(transforms) -> np.ndarray:
    """``A_1n = A_12 A_23 ... A_(n-1)n`` of a sequence of 3x3 matrices (eqs. 2.10, 2.11); the
    identity for an empty sequence. Order matters: ``A_IB = chain([A_IR, A_RB])``."""
    return _core.chain(transforms)


def point_velocity_inertial(v_q_i, a_ib, omega_i, r_b, rdot_b) -> np.ndarray:
    """Absolute velocity of a point P, I components (eq. 2.28 with ``A_IB_dot = ω̃_I A_IB``, eq. 2.35):
    ``v_P = v_Q + omega_I × (A_IB r_B) + A_IB r_B_dot``.

    ``v_q_i``: velocity of the frame origin Q (I); ``a_ib``: orientation of the moving frame B;
    ``omega_i``: its angular velocity (I); ``r_b``: position of P relative to Q (B);
    ``rdot_b``: time derivative of ``r_b`` (B)."""
    return _core.point_velocity_inertial(v_q_i, a_ib, omega_i, r_b, rdot_b)


def point_velocity_body(v_q_b, omega_b, r_b, rdot_b) -> np.ndarray:
    """Absolute velocity of P, B components (eq. 2.38): ``v_P = v_Q + omega_B × r + r_dot``, with
    ``v_q_b = A_BI v_Q``."""
    return _core.point_velocity_body(v_q_b, omega_b, r_b, rdot_b)


def point_acceleration_inertial(a_q_i, a_ib, omega_b, omegadot_b, r_b, rdot_b, rddot_b) -> np.ndarray:
    """Absolute acceleration of P, I components (eq. 2.41):
    ``a_P = a_Q + A_IB (omegadot × r + omega × (omega × r) + 2 omega × r_dot + r_ddot)``, all of
    ``omega_b``, ``omegadot_b`` (the rate of ``omega_b``), ``r_b`` and its rates in B components;
    ``a_q_i`` is the acceleration of the frame origin Q (I). The terms are the angular (Euler),
    centripetal, Coriolis and relative accelerations."""
    return _core.point_acceleration_inertial(a_q_i, a_ib, omega_b, omegadot_b, r_b, rdot_b, rddot_b)


def point_acceleration_body(a_q_b, omega_b, omegadot_b, r_b, rdot_b, rddot_b) -> np.ndarray:
    """Absolute acceleration of P, B components (eq. 2.42):
    ``a_P = a_Q + omegadot × r + omega × (omega × r) + 2 omega × r_dot + r_ddot``, with
    ``a_q_b = A_BI a_Q``."""
    return _core.point_acceleration_body(a_q_b, omega_b, omegadot_b, r_b, rdot_b, rddot_b)


def cylindrical_position(r: float, phi: float, z: float) -> np.ndarray:
    """``(r cos phi, r sin phi, z)``, I components."""
    return _core.cylindrical_position(r, phi, z)


def cylindrical_velocity(r: float, phi: float, rdot: float, phidot: float, zdot: float) -> np.ndarray:
    """Velocity of a point in cylindrical coordinates, I components (eq. 2.43):
    ``(rdot cos phi - r phidot sin phi, rdot sin phi + r phidot cos phi, zdot)``."""
    return _core.cylindrical_velocity(r, phi, rdot, phidot, zdot)


def cylindrical_acceleration(
    r: float,
    phi: float,
    z: float,
    rdot: float,
    phidot: float,
    zdot: float,
    rddot: float,
    phiddot: float,
    zddot: float,
) -> np.ndarray:
    """Acceleration of a point in cylindrical coordinates, I components (eq. 2.43); ``z`` and
    ``zdot`` complete the state but do not enter."""
    return _core.cylindrical_acceleration(r, phi, z, rdot, phidot, zdot, rddot, phiddot, zddot)


def cylindrical_a_ib(phi: float) -> np.ndarray:
    """``A_IB = Rz(phi)`` of the cylindrical trihedral (radial, circumferential, axial unit vectors
    as columns); its transpose is the ``A_BI`` of eq. 2.44."""
    return _core.cylindrical_a_ib(phi)


def cylindrical_velocity_trihedral(r: float, rdot: float, phidot: float, zdot: float) -> np.ndarray:
    """Velocity in trihedral components, ``(rdot, r phidot, zdot)`` (``A_BI`` times eq. 2.43)."""
    return _core.cylindrical_velocity_trihedral(r, rdot, phidot, zdot)


def cylindrical_acceleration_trihedral(
    r: float, rdot: float, phidot: float, rddot: float, phiddot: float, zddot: float
) -> np.ndarray:
    """Acceleration in trihedral components,
    ``(rddot - r phidot², 2 rdot phidot + r phiddot, zddot)`` (eq. 2.44)."""
    return _core.cylindrical_acceleration_trihedral(r, rdot, phidot, rddot, phiddot, zddot)


# ---------------------------------------------------------------------------------------------
# Model-level kinematics (recursive forward kinematics of a built model)
# ---------------------------------------------------------------------------------------------


def _vector(x, what: str) -> np.ndarray:
    try:
        return np.ascontiguousarray(x, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise SettingsError(f"{what}: expected a sequence of numbers, got {x!r}") from None


def _point(point) -> list[float]:
    p = _vector(point, "point")
    if p.shape != (3,):
        raise SettingsError(f"point: expected a 3-vector, got {p.size} numbers")
    if not np.all(np.isfinite(p)):
        raise SettingsError(f"point: must be finite, got {p.tolist()}")
    return p.tolist()


def _body_name(body) -> str:
    return body if isinstance(body, str) else getattr(body, "name", str(body))


def body_states(model, q, u=None) -> dict:
    """Placements and velocities of all bodies at ``(q, u)`` (``u`` defaults to zero).

    Returns a dict of arrays, row ``i`` for body ``body_names[i]`` (the ground is row 0):
    ``position`` (nbody x 3, origin of the body frame, I components), ``rotation``
    (nbody x 3 x 3, ``A_IB``), ``velocity`` (nbody x 3, of the body-frame origin, I components,
    eq. 2.28), ``angular_velocity`` (nbody x 3, ``omega_I``), and ``body_names``.
    """
    core = model.build()
    u_arr = None if u is None else _vector(u, "u")
    out = dict(_core.body_states(core, _vector(q, "q"), u_arr))
    out["body_names"] = list(core.body_names)
    return out


def point_position(model, q, body, point: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Position ``r_OP = r_OQ + A_IB r_QP`` (eq. 2.27), I components, of the point at ``point``
    (body components, relative to the body-frame origin Q) of ``body`` (name or handle)."""
    return _core.point_position(model.build(), _vector(q, "q"), _body_name(body), _point(point))


def point_jacobian(model, q, body, point: Sequence[float] = (0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians ``(Jt, Jr)`` (each 3 x nu, I components) of a body-fixed point: its velocity is
    ``v_P = Jt u`` and the body's angular velocity ``omega_I = Jr u`` (eq. 2.28 for a point fixed
    in the body, summed over the joints of the tree)."""
    jt, jr = _core.point_jacobian(model.build(), _vector(q, "q"), _body_name(body), _point(point))
    return jt, jr


__all__ = [
    "SINGULAR_TOL",
    "ROTATION_MATRIX_TOL",
    "UNIT_TOL",
    # elementary rotations, tilde
    "rot_x",
    "rot_y",
    "rot_z",
    "rot_axis",
    "wrap_angle",
    "check_rotation_matrix",
    "tilde",
    "untilde",
    # Euler and Cardan angles
    "euler_zxz_to_matrix",
    "matrix_to_euler_zxz",
    "cardan_xyz_to_matrix",
    "matrix_to_cardan_xyz",
    "euler_zxz_to_cardan_xyz",
    "cardan_xyz_to_euler_zxz",
    # quaternions
    "quat_to_matrix",
    "matrix_to_quat",
    "quat_mul",
    "quat_conj",
    "quat_normalize",
    "quat_rotate",
    "quat_from_axis_angle",
    "quat_derivative",
    "quat_derivative_matrix",
    "quat_derivative_inertial",
    "quat_omega_body",
    "quat_omega_inertial",
    "quat_integrate",
    "quat_integrate_inertial",
    "euler_zxz_to_quat",
    "quat_to_euler_zxz",
    "cardan_xyz_to_quat",
    "quat_to_cardan_xyz",
    # rotation vector
    "rotvec_to_matrix",
    "matrix_to_rotvec",
    "rotvec_to_quat",
    "quat_to_rotvec",
    "euler_zxz_to_rotvec",
    "rotvec_to_euler_zxz",
    "cardan_xyz_to_rotvec",
    "rotvec_to_cardan_xyz",
    # H, H*
    "euler_h_inertial",
    "euler_h_body",
    "cardan_h_inertial",
    "cardan_h_body",
    "euler_h_inertial_inv",
    "euler_h_body_inv",
    "cardan_h_inertial_inv",
    "cardan_h_body_inv",
    "singularity_margin",
    "is_near_singular",
    "euler_rates_from_omega_inertial",
    "euler_rates_from_omega_body",
    "cardan_rates_from_omega_inertial",
    "cardan_rates_from_omega_body",
    # moving frames
    "chain",
    "point_velocity_inertial",
    "point_velocity_body",
    "point_acceleration_inertial",
    "point_acceleration_body",
    "cylindrical_position",
    "cylindrical_velocity",
    "cylindrical_acceleration",
    "cylindrical_a_ib",
    "cylindrical_velocity_trihedral",
    "cylindrical_acceleration_trihedral",
    # model level
    "body_states",
    "point_position",
    "point_jacobian",
]
