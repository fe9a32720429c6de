"""Double pendulum of two physical rods against hand-derived Lagrange equations solved by SciPy.

Planar model (all hinge axes along z, gravity -g e_y). Link i has mass m_i, centre of mass at
distance a_i along its body x axis and moment of inertia J_i about the z axis through its centre
of mass; joint 1 sits at the origin, joint 2 at distance l1 along link 1's x axis. With q1 the
angle of link 1 and q2 the angle of link 2 relative to link 1 (absolute angle q1 + q2):

    r_C1 = a1 (cos q1, sin q1),   r_C2 = l1 (cos q1, sin q1) + a2 (cos(q1+q2), sin(q1+q2)),
    T = 1/2 (m1 a1^2 + J1) q1'^2 + 1/2 m2 |r_C2'|^2 + 1/2 J2 (q1' + q2')^2          (eq. 2.183)
    V = m1 g a1 sin q1 + m2 g (l1 sin q1 + a2 sin(q1 + q2)).

Lagrange's equations d/dt dT/dq' - dT/dq + dV/dq = 0 give M(q) q'' + c(q, q') + dV/dq = 0 with
(b = m2 l1 a2):

    M11 = m1 a1^2 + J1 + m2 (l1^2 + a2^2) + J2 + 2 b cos q2,  M12 = m2 a2^2 + J2 + b cos q2,
    M22 = m2 a2^2 + J2,
    c1 = -b sin q2 (2 q1' q2' + q2'^2),  c2 = b sin q2 q1'^2,
    dV/dq1 = g (m1 a1 + m2 l1) cos q1 + m2 g a2 cos(q1 + q2),  dV/dq2 = m2 g a2 cos(q1 + q2).

For rotation about a fixed z axis only the zz moment about the centre of mass enters, so the
links are given full inertia tensors (with products of inertia) to show that the others do not
leak into the planar motion.

The comparison after 10 s needs a regular (non-chaotic) regime: both links start near the
hanging position (q1 = -pi/2 + 0.4, q2 = 0.3, at rest); at this energy the motion is a
quasi-periodic superposition of the two normal modes, errors grow only linearly, and two
independent 1e-12 solutions agree to ~1e-10.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mechsys as ms

G = 9.81
M1, L1, A1 = 1.2, 0.9, 0.42
M2, A2 = 0.7, 0.35
# inertia tensors about the centres of mass (body components): slender boxes whose principal axes
# are tilted against the body axes (products of inertia); J_i is the zz entry
def _tilted(inertia, ay, ax):
    ry = np.array([[np.cos(ay), 0, np.sin(ay)], [0, 1, 0], [-np.sin(ay), 0, np.cos(ay)]])
    rx = np.array([[1, 0, 0], [0, np.cos(ax), -np.sin(ax)], [0, np.sin(ax), np.cos(ax)]])
    return ms.inertia.rotate(inertia, ry @ rx)


INERTIA1 = _tilted(ms.inertia.box(M1, (0.9, 0.06, 0.04)), 0.2, 0.3)
INERTIA2 = _tilted(ms.inertia.box(M2, (0.7, 0.05, 0.05)), -0.15, 0.5)
J1, J2 = INERTIA1[2, 2], INERTIA2[2, 2]
TIGHT = ms.DOPRI5(rtol=1e-12, atol=1e-12)


def planar_double_pendulum():
    model = ms.Model("double-pendulum", gravity=(0.0, -G, 0.0))
    link1 = model.add_body("link1", mass=M1, inertia=INERTIA1, com=(A1, 0.0, 0.0))
    link2 = model.add_body("link2", mass=M2, inertia=INERTIA2, com=(A2, 0.0, 0.0))
    model.add_joint(ms.joints.Revolute("shoulder", parent=model.ground, child=link1, axis=(0, 0, 1)))
    model.add_joint(
        ms.joints.Revolute("elbow", parent=link1, child=link2, parent_frame=(L1, 0.0, 0.0), axis=(0, 0, 1))
    )
    return model


def lagrange_rhs(t, y):
    q1, q2, w1, w2 = y
    b = M2 * L1 * A2
    c2, s2 = np.cos(q2), np.sin(q2)
    m11 = M1 * A1**2 + J1 + M2 * (L1**2 + A2**2) + J2 + 2.0 * b * c2
    m12 = M2 * A2**2 + J2 + b * c2
    m22 = M2 * A2**2 + J2
    cor = np.array([-b * s2 * (2.0 * w1 * w2 + w2 * w2), b * s2 * w1 * w1])
    grav = np.array(
        [G * (M1 * A1 + M2 * L1) * np.cos(q1) + M2 * G * A2 * np.cos(q1 + q2), M2 * G * A2 * np.cos(q1 + q2)]
    )
    acc = np.linalg.solve(np.array([[m11, m12], [m12, m22]]), -cor - grav)
    return [w1, w2, acc[0], acc[1]]


def energy(q1, q2, w1, w2):
    v_c2 = np.array(
        [-L1 * np.sin(q1) * w1 - A2 * np.sin(q1 + q2) * (w1 + w2), L1 * np.cos(q1) * w1 + A2 * np.cos(q1 + q2) * (w1 + w2)]
    )
    kin = 0.5 * (M1 * A1**2 + J1) * w1**2 + 0.5 * M2 * (v_c2**2).sum(axis=0) + 0.5 * J2 * (w1 + w2) ** 2
    pot = M1 * G * A1 * np.sin(q1) + M2 * G * (L1 * np.sin(q1) + A2 * np.sin(q1 + q2))
    return kin, pot


Q0 = np.array([-0.5 * np.pi + 0.4, 0.3])


@pytest.fixture(scope="module")
def runs():
    t_end = 10.0
    res = ms.simulate(planar_double_pendulum(), t_end, TIGHT, output_dt=0.01, q0={"shoulder": Q0[0], "elbow": Q0[1]})
    ref = solve_ivp(lagrange_rhs, (0.0, t_end), [Q0[0], Q0[1], 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=res.t)
    assert ref.success
    return res, ref


def test_state_after_10s_matches_lagrange_equations(runs):
    res, ref = runs
    state = np.column_stack([res["joint/shoulder/q"], res["joint/elbow/q"], res["joint/shoulder/u"], res["joint/elbow/u"]])
    final_error = np.abs(state[-1] - ref.y[:, -1])
    print(f"double pendulum: |state(10 s) - Lagrange/DOP853| = {final_error}")
    assert res.t[-1] == pytest.approx(10.0)
    assert np.all(final_error < 1e-8)
    # and along the whole trajectory
    assert np.max(np.abs(state - ref.y.T)) < 1e-8


def test_accelerations_match_lagrange_equations(runs):
    res, _ = runs
    for k in range(0, len(res.t), 97):
        y = [res["joint/shoulder/q"][k], res["joint/elbow/q"][k], res["joint/shoulder/u"][k], res["joint/elbow/u"][k]]
        acc = lagrange_rhs(0.0, y)[2:]
        np.testing.assert_allclose([res["joint/shoulder/udot"][k], res["joint/elbow/udot"][k]], acc, rtol=1e-10, atol=1e-10)


def test_energies_match_hand_derived_expressions(runs):
    res, _ = runs
    kin, pot = energy(res["joint/shoulder/q"], res["joint/elbow/q"], res["joint/shoulder/u"], res["joint/elbow/u"])
    np.testing.assert_allclose(res["energy/kinetic"], kin, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res["energy/potential"], pot, rtol=1e-12, atol=1e-12)
    e0 = sum(energy(Q0[0], Q0[1], 0.0, 0.0))
    assert np.max(np.abs(res["energy/total"] - e0)) < 1e-10 * abs(e0)


def quat_to_matrix(quat):
    """A_IB of unit quaternions [w, x, y, z], (n, 4) -> (n, 3, 3)."""
    w, x, y, z = np.asarray(quat).T
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)


def spatial_double_pendulum():
    """Two links, hinge axes not parallel, joint frames rotated and offset out of plane."""
    model = ms.Model("spatial-double-pendulum", gravity=(0.0, 0.0, -G))
    link1 = model.add_body("link1", mass=1.1, inertia=[0.01, 0.07, 0.075], com=(0.3, 0.02, -0.01))
    link2 = model.add_body("link2", mass=0.6, inertia=_tilted(ms.inertia.box(0.6, (0.1, 0.5, 0.2)), 0.4, -0.3), com=(0.05, 0.25, 0.1))
    model.add_joint(ms.joints.Revolute("j1", parent=model.ground, child=link1, axis=(0.0, 1.0, 0.2)))
    model.add_joint(
        ms.joints.Revolute(
            "j2",
            parent=link1,
            child=link2,
            parent_frame=ms.Frame(position=(0.6, 0.0, 0.05), cardan=(0.3, -0.2, 0.5)),
            child_frame=ms.Frame(position=(0.0, -0.05, 0.0)),
            axis=(1.0, 1.0, 0.0),
        )
    )
    return model


def test_spatial_double_pendulum_conserves_energy():
    model = spatial_double_pendulum()
    res = ms.simulate(model, 5.0, TIGHT, output_dt=0.01, q0={"j1": 0.8, "j2": -1.1}, u0={"j1": 1.5, "j2": 2.0})
    e = res["energy/total"]
    scale = np.max(np.abs(res["energy/kinetic"])) + np.max(np.abs(res["energy/potential"]))
    # the energy really is exchanged between kinetic and potential, yet the sum stays constant
    assert np.ptp(res["energy/kinetic"]) > 0.1 * scale
    assert np.max(np.abs(e - e[0])) < 1e-9 * scale
    # potential energy from the recorded body positions: V = -sum m g.r_C with r_C = r + A_IB c
    pot = 0.0
    for name, m, com in (("link1", 1.1, (0.3, 0.02, -0.01)), ("link2", 0.6, (0.05, 0.25, 0.1))):
        r_c = res[f"body/{name}/position"] + quat_to_matrix(res[f"body/{name}/orientation"]) @ np.asarray(com)
        pot = pot + m * G * r_c[:, 2]
    np.testing.assert_allclose(res["energy/potential"], pot, rtol=1e-10, atol=1e-10 * scale)


def test_spatial_double_pendulum_rk4_energy_error_shrinks_with_fourth_order():
    model = spatial_double_pendulum()
    drift = []
    for dt in (0.01, 0.005):
        res = ms.simulate(model, 2.0, ms.RK4(dt=dt), output_dt=0.01, q0={"j1": 0.8, "j2": -1.1}, u0={"j1": 1.5, "j2": 2.0})
        drift.append(np.max(np.abs(res["energy/total"] - res["energy/total"][0])))
    # energy error of a 4th-order scheme: ~2^4 smaller per halving (allow 2^3.5)
    assert drift[0] / drift[1] > 2**3.5
