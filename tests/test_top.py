"""Heavy symmetric top on a spherical joint at its fixed point, against the classical solutions.

Body frame: origin at the fixed point, symmetry axis e3 = body z, centre of mass at (0, 0, l);
moments about the centre of mass A_C (transverse) and C (axial), so A = A_C + m l^2 about the
fixed point. Gravity -g e_z. With Euler angles z-x-z (psi precession, theta tilt, phi spin;
eq. 2.15) the body angular velocity is

    omega_B = psi' (sin th sin phi, sin th cos phi, cos th) + th' (cos phi, -sin phi, 0) + phi' e3,

the spin omega3 = psi' cos th + phi' and the momentum about the vertical
L_z = A psi' sin^2 th + C omega3 cos th are conserved, and the Lagrange equation for theta is

    A th'' = A psi'^2 sin th cos th - C omega3 psi' sin th + m g l sin th.

Steady precession (th'' = th' = 0, psi' = Omega) therefore needs

    m g l = Omega (C omega3 - A Omega cos th)
    =>  Omega = (C omega3 -+ sqrt(C^2 omega3^2 - 4 A m g l cos th)) / (2 A cos th)   (slow / fast).

Released at rest in precession (psi' = th' = 0) from tilt th0, u = cos th oscillates between
u0 = cos th0 and the root u1 of  alpha (1 - u^2) = beta (u0 - u)  (alpha = 2 m g l / A,
beta = (C omega3 / A)^2), from energy and L_z conservation; u' ^2 = alpha (u0 - u)(u - u1)(u2 - u),
so the nutation period is  T_n = 4 K(k^2) / sqrt(alpha (u2 - u1)),  k^2 = (u0 - u1)/(u2 - u1).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.special import ellipk

import mechsys as ms

G = 9.81
M, L_COM, A_C, C_AX = 1.0, 0.1, 0.002, 0.003
A_FIX = A_C + M * L_COM**2  # transverse moment about the fixed point (Steiner)
MGL = M * G * L_COM
TIGHT = ms.DOPRI5(rtol=1e-12, atol=1e-12)


def top_model():
    model = ms.Model("heavy-top", gravity=(0.0, 0.0, -G))
    top = model.add_body("top", mass=M, inertia=[A_C, A_C, C_AX], com=(0.0, 0.0, L_COM))
    model.add_joint(ms.joints.Spherical("pivot", parent=model.ground, child=top))
    return model


def rotation_matrices(quat: np.ndarray) -> np.ndarray:
    """A_IB of unit quaternions [w, x, y, z] (n, 4) -> (n, 3, 3)."""
    w, x, y, z = np.asarray(quat).T
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)


def tilt_and_precession(quat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """theta and (unwrapped) psi from the symmetry axis A_IB e3 = (sin th sin psi, -sin th cos psi, cos th)."""
    axis = rotation_matrices(quat)[:, :, 2]
    theta = np.arctan2(np.hypot(axis[:, 0], axis[:, 1]), axis[:, 2])
    psi = np.unwrap(np.arctan2(axis[:, 0], -axis[:, 1]))
    return theta, psi


def initial_state(theta0: float, psi_dot: float, omega3: float):
    """psi = phi = 0, theta = theta0, theta' = 0: A_IB = rotation about x by theta0 and
    omega_B = (0, psi' sin th0, omega3)."""
    q0 = [np.cos(0.5 * theta0), np.sin(0.5 * theta0), 0.0, 0.0]
    u0 = [0.0, psi_dot * np.sin(theta0), omega3]
    return q0, u0


def steady_precession_rate(theta0: float, omega3: float, branch: str) -> float:
    c = np.cos(theta0)
    root = np.sqrt((C_AX * omega3) ** 2 - 4.0 * A_FIX * MGL * c)
    sign = -1.0 if branch == "slow" else 1.0
    return (C_AX * omega3 + sign * root) / (2.0 * A_FIX * c)


@pytest.mark.parametrize(
    "theta0, branch",
    [(0.5, "slow"), (0.5, "fast"), (2.0, "slow"), (2.0, "fast")],
    ids=["above-slow", "above-fast", "hanging-slow", "hanging-fast"],
)
def test_steady_precession(theta0, branch):
    omega3 = 100.0
    rate = steady_precession_rate(theta0, omega3, branch)
    # the quadratic's root satisfies the steady-precession condition exactly
    assert rate * (C_AX * omega3 - A_FIX * rate * np.cos(theta0)) == pytest.approx(MGL, rel=1e-12)
    q0, u0 = initial_state(theta0, rate, omega3)
    t_end = 2.5 * 2.0 * np.pi / abs(rate)
    res = ms.simulate(top_model(), t_end, TIGHT, output_dt=t_end / 500, q0={"pivot": q0}, u0={"pivot": u0})
    theta, psi = tilt_and_precession(res["joint/pivot/q"])
    assert psi[0] == pytest.approx(0.0, abs=1e-15)
    assert np.max(np.abs(theta - theta0)) < 1e-8
    # psi(t) = Omega t over 2.5 precession periods
    assert np.max(np.abs(psi - rate * res.t)) < 1e-8 * abs(rate) * t_end
    fitted_rate = np.polyfit(res.t, psi, 1)[0]
    assert fitted_rate == pytest.approx(rate, rel=1e-8)
    # body-frame angular velocity: constant spin and constant transverse magnitude Omega sin(theta)
    w_b = res["joint/pivot/u"]
    assert np.max(np.abs(w_b[:, 2] - omega3)) < 1e-8 * omega3
    np.testing.assert_allclose(np.hypot(w_b[:, 0], w_b[:, 1]), abs(rate) * np.sin(theta0), rtol=1e-8)


def test_nutation_of_a_top_released_without_precession():
    theta0, omega3 = 0.5, 100.0
    q0, u0 = initial_state(theta0, 0.0, omega3)
    res = ms.simulate(top_model(), 1.0, TIGHT, output_dt=1e-4, q0={"pivot": q0}, u0={"pivot": u0})

    c0 = np.cos(theta0)
    alpha, beta = 2.0 * MGL / A_FIX, (C_AX * omega3 / A_FIX) ** 2
    disc = np.sqrt(beta * beta - 4.0 * alpha * (beta * c0 - alpha))
    u1, u2 = (beta - disc) / (2.0 * alpha), (beta + disc) / (2.0 * alpha)
    assert u1 < c0 < 1.0 < u2
    t_nut = 4.0 * ellipk((c0 - u1) / (u2 - u1)) / np.sqrt(alpha * (u2 - u1))

    a_ib = rotation_matrices(res["joint/pivot/q"])
    cos_theta = a_ib[:, 2, 2]
    # the top never rises above its start and dips to u1 (sampling 1e-4 s resolves the minimum to ~1e-8)
    assert np.max(cos_theta) < c0 + 1e-10
    assert np.min(cos_theta) == pytest.approx(u1, abs=1e-8)

    # times of lowest tilt: zeros of d(cos th)/dt = ((A_IB omega_B) x e3_I)_z with positive slope
    axis = a_ib[:, :, 2]
    omega_i = np.einsum("nij,nj->ni", a_ib, res["joint/pivot/u"])
    rate = np.cross(omega_i, axis)[:, 2]
    spline = CubicSpline(res.t, rate)
    roots = spline.roots(extrapolate=False)
    lowest = roots[spline(roots, 1) > 0]
    assert len(lowest) >= 2
    # released at a cusp (u = u0 at t = 0), the lowest points come at (k + 1/2) T_n
    np.testing.assert_allclose(lowest, (np.arange(len(lowest)) + 0.5) * t_nut, rtol=1e-8)

    # conserved: spin, L_z about the fixed point (= inertial origin) and energy
    assert np.max(np.abs(res["joint/pivot/u"][:, 2] - omega3)) < 1e-9 * omega3
    lz0 = C_AX * omega3 * c0
    assert np.max(np.abs(res["momentum/angular"][:, 2] - lz0)) < 1e-10 * lz0
    e0 = MGL * c0 + 0.5 * C_AX * omega3**2
    assert np.max(np.abs(res["energy/total"] - e0)) < 1e-10 * e0
