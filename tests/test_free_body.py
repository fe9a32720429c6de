"""Free rigid body (free joint, no gravity) against the conservation laws and Euler's equations.

Without active forces (eqs. 2.146-2.148) the momentum p = m v_C and the moment of momentum about
the inertial origin L = r_C x m v_C + A_IB I_C omega_B are constant, the centre of mass moves on a
straight line with constant speed (eq. 2.149), and the kinetic energy
T = 1/2 m v_C^2 + 1/2 omega_B^T I_C omega_B (eq. 2.183) is constant. The angular velocity obeys
Euler's equations I_C omega_B' + omega_B x I_C omega_B = 0, integrated here independently by SciPy.

Free-joint conventions (python/mechsys/joints.py): q = [r, quaternion of A_IB], u = [v_B, omega_B]
with v_B the velocity of the body-frame origin in body components, so v_C = v_B + omega_B x c.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mechsys as ms

MASS = 2.0
COM = np.array([0.1, -0.2, 0.05])
R0 = np.array([0.5, -1.0, 2.0])
QUAT0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
V_B0 = np.array([0.3, -0.1, 0.2])
W_B0 = np.array([0.8, -1.1, 0.6])
TIGHT = ms.DOPRI5(rtol=1e-12, atol=1e-12)


def rot_x(a):
    return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])


def rot_z(a):
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


# distinct principal moments 1, 2, 3 kg m^2 on principal axes turned away from the body axes
PRINCIPAL_AXES = rot_z(0.3) @ rot_x(0.7)
INERTIA = PRINCIPAL_AXES @ np.diag([1.0, 2.0, 3.0]) @ PRINCIPAL_AXES.T


def quat_to_matrix(q):
    w, x, y, z = np.asarray(q, dtype=float).T
    a = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    return a if a.ndim == 2 else a.transpose(2, 0, 1)


def free_body(inertia=INERTIA, com=COM, mass=MASS):
    model = ms.Model("free-body")  # no gravity
    body = model.add_body("body", mass=mass, inertia=inertia, com=com)
    model.add_joint(ms.joints.Free("free", parent=model.ground, child=body))
    return model


def run(integrator, t_end=20.0, output_dt=0.05):
    return ms.simulate(
        free_body(), t_end, integrator, output_dt=output_dt, q0={"free": np.r_[R0, QUAT0]}, u0={"free": np.r_[V_B0, W_B0]}
    )


def initial_invariants():
    """T, p and L of the initial state, from the definitions."""
    a0 = quat_to_matrix(QUAT0)
    v_c = V_B0 + np.cross(W_B0, COM)
    r_c = R0 + a0 @ COM
    kinetic = 0.5 * MASS * v_c @ v_c + 0.5 * W_B0 @ INERTIA @ W_B0
    p = MASS * a0 @ v_c
    ang = np.cross(r_c, p) + a0 @ INERTIA @ W_B0
    return kinetic, p, ang, r_c, a0 @ v_c


@pytest.fixture(scope="module")
def tight():
    return run(TIGHT)


def test_initial_energy_and_momenta_match_definitions(tight):
    kinetic, p, ang, _, _ = initial_invariants()
    assert tight["energy/kinetic"][0] == pytest.approx(kinetic, rel=1e-14)
    np.testing.assert_allclose(tight["momentum/linear"][0], p, rtol=0, atol=1e-14 * np.linalg.norm(p))
    np.testing.assert_allclose(tight["momentum/angular"][0], ang, rtol=0, atol=1e-14 * np.linalg.norm(ang))
    assert np.all(tight["energy/potential"] == 0.0)


def test_energy_and_angular_momentum_conserved_over_20s(tight):
    kinetic, p, ang, _, _ = initial_invariants()
    assert tight.t[-1] == pytest.approx(20.0)
    assert np.max(np.abs(tight["energy/kinetic"] / kinetic - 1.0)) < 1e-9
    assert np.max(np.linalg.norm(tight["momentum/angular"] - ang, axis=1)) < 1e-9 * np.linalg.norm(ang)
    assert np.max(np.linalg.norm(tight["momentum/linear"] - p, axis=1)) < 1e-9 * np.linalg.norm(p)


def test_centre_of_mass_moves_uniformly(tight):
    _, _, _, r_c0, v_c0 = initial_invariants()
    a_ib = quat_to_matrix(tight["body/body/orientation"])
    r_c = tight["body/body/position"] + a_ib @ COM
    expected = r_c0 + np.outer(tight.t, v_c0)
    assert np.max(np.linalg.norm(r_c - expected, axis=1)) < 1e-9 * np.linalg.norm(v_c0) * 20.0
    # the recorded body-origin position is the free joint's own coordinate (parent = ground)
    np.testing.assert_array_equal(tight["body/body/position"], tight["joint/free/q"][:, :3])


def test_angular_velocity_follows_euler_equations(tight):
    sol = solve_ivp(
        lambda t, w: np.linalg.solve(INERTIA, -np.cross(w, INERTIA @ w)),
        (0.0, 20.0),
        W_B0,
        method="DOP853",
        rtol=1e-13,
        atol=1e-13,
        t_eval=tight.t,
    )
    assert sol.success
    w_b = tight["joint/free/u"][:, 3:]
    assert np.max(np.abs(w_b - sol.y.T)) < 1e-8 * np.linalg.norm(W_B0)
    # the recorded inertial angular velocity is A_IB omega_B
    a_ib = quat_to_matrix(tight["body/body/orientation"])
    np.testing.assert_allclose(tight["body/body/angular_velocity"], np.einsum("nij,nj->ni", a_ib, w_b), atol=1e-12)


def test_rk4_drifts_more_than_dopri5_but_stays_bounded(tight):
    kinetic, _, ang, _, _ = initial_invariants()

    def drifts(res):
        e = np.max(np.abs(res["energy/kinetic"] / kinetic - 1.0))
        h = np.max(np.linalg.norm(res["momentum/angular"] - ang, axis=1)) / np.linalg.norm(ang)
        return e, h

    rk4 = run(ms.RK4(dt=0.025))
    e_rk4, h_rk4 = drifts(rk4)
    e_dp, h_dp = drifts(tight)
    print(f"relative drift over 20 s: energy RK4(dt=0.025) {e_rk4:.2e} vs DOPRI5(1e-12) {e_dp:.2e}; "
          f"angular momentum {h_rk4:.2e} vs {h_dp:.2e}")
    assert e_rk4 > e_dp and h_rk4 > h_dp
    assert e_rk4 < 1e-6 and h_rk4 < 1e-5


@pytest.mark.parametrize("axis", [0, 1, 2], ids=["min-axis", "intermediate-axis", "max-axis"])
def test_intermediate_axis_instability(axis):
    """Spin 5 rad/s about one principal axis of diag(1, 2, 3), the others perturbed by 1e-3 rad/s.

    About the intermediate axis the perturbation grows like exp(lambda t) with
    lambda = omega sqrt((I2 - I1)(I3 - I2) / (I1 I3)) = 2.9 /s, and the spin reverses (the body
    flips) after about ln(5 / 1e-3) / lambda = 3 s; about the other two it stays bounded."""
    moments = np.array([1.0, 2.0, 3.0])
    omega0, eps = 5.0, 1e-3
    w0 = np.full(3, eps)
    w0[axis] = omega0
    model = free_body(inertia=moments, com=(0.0, 0.0, 0.0), mass=1.0)
    res = ms.simulate(model, 10.0, ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=0.01, u0={"free": np.r_[0.0, 0.0, 0.0, w0]})
    spin = res["joint/free/u"][:, 3 + axis]
    sign_changes = np.count_nonzero(np.diff(np.sign(spin)))
    if axis == 1:
        assert sign_changes >= 1
        flip = res.t[np.argmax(spin < 0)]
        lam = omega0 * np.sqrt((moments[1] - moments[0]) * (moments[2] - moments[1]) / (moments[0] * moments[2]))
        assert 0.5 * np.log(omega0 / eps) / lam < flip < 2.0 * np.log(omega0 / eps) / lam
        assert np.min(spin) < -0.9 * omega0
    else:
        assert sign_changes == 0
        assert np.max(np.abs(spin - omega0)) < 1e-5 * omega0
    # the flip or its absence is what Euler's equations predict
    ref = solve_ivp(
        lambda t, w: -np.cross(w, moments * w) / moments, (0.0, 10.0), w0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=res.t
    )
    assert np.max(np.abs(res["joint/free/u"][:, 3:] - ref.y.T)) < 1e-5 * omega0
