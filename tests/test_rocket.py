"""Variable-mass body (section 2.1.1) on a free joint: the rocket equation.

The body loses mass at the constant rate mdot < 0 until it reaches mass_final; the ejected mass
leaves with the velocity w_rel relative to the body, so the thrust is F = mdot w_rel and, with the
thrust acting at the centre of mass, m(t) v_C' = F (eq. 2.152 with the reactive force of the
ejected mass). For w_rel = (-w, 0, 0) and m(t) = m0 + mdot t this integrates to Tsiolkovsky's

    v(t) = v0 + w ln(m0 / m(t)) e_x        (and, under gravity, - g t),
    x(t) = x0 + w [ t ln m0 - ((m ln m - m) - (m0 ln m0 - m0)) / mdot ]   during the burn,

after the burn-out time t_b = (mass_final - m0) / mdot the velocity stays constant. The thrust is
constant, so its work is F times the distance travelled during the burn.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mechsys as ms

M0, MDOT, M_FINAL, W_REL = 100.0, -2.0, 40.0, 300.0
T_BURN = (M_FINAL - M0) / MDOT  # 30 s
TIGHT = ms.DOPRI5(rtol=1e-12, atol=1e-12)


def rocket_model(gravity=(0.0, 0.0, 0.0), w_rel=W_REL):
    model = ms.Model("rocket", gravity=gravity)
    body = model.add_body(
        "rocket",
        mass=M0,
        inertia=ms.inertia.cylinder(M0, 0.3, 4.0, axis="x"),
        mass_rate=MDOT,
        ejection_velocity=(-w_rel, 0.0, 0.0),
        mass_final=M_FINAL,
    )
    model.add_joint(ms.joints.Free("flight", parent=model.ground, child=body))
    return model


def mass(t):
    return np.maximum(M0 + MDOT * t, M_FINAL)


def delta_v(t, w=W_REL):
    return w * np.log(M0 / mass(t))


def distance(t, w=W_REL):
    """Distance gained over a coast at the initial velocity, burn and coast phases."""
    tb = np.minimum(t, T_BURN)
    m = M0 + MDOT * tb
    burn = w * (tb * np.log(M0) - ((m * np.log(m) - m) - (M0 * np.log(M0) - M0)) / MDOT)
    return burn + delta_v(T_BURN, w) * np.maximum(t - T_BURN, 0.0)


def test_tsiolkovsky_velocity_and_burn_out():
    res = ms.simulate(rocket_model(), 40.0, TIGHT, output_dt=0.25)
    t = res.t
    v = res["body/rocket/velocity"]
    dv = delta_v(t)
    assert np.max(np.abs(v[:, 0] - dv)) < 1e-8 * dv[-1]
    assert np.max(np.abs(v[:, 1:])) < 1e-12 * dv[-1]
    # after burn-out the speed stays at w ln(m0 / m_final)
    coast = t > T_BURN
    assert coast.sum() > 10
    np.testing.assert_allclose(v[coast, 0], W_REL * np.log(M0 / M_FINAL), rtol=1e-8)
    assert np.ptp(v[coast, 0]) < 1e-10 * dv[-1]
    # position from integrating the rocket equation once more
    x = distance(t)
    assert np.max(np.abs(res["body/rocket/position"][:, 0] - x)) < 1e-8 * x[-1]


def test_mass_signal_follows_mass_rate():
    res = ms.simulate(rocket_model(), 40.0, TIGHT, output_dt=0.25)
    assert res.unit("body/rocket/mass") == "kg"
    np.testing.assert_allclose(res["body/rocket/mass"], mass(res.t), rtol=1e-14)
    burning = res.t < T_BURN
    np.testing.assert_allclose(res["body/rocket/mass"][burning], M0 + MDOT * res.t[burning], rtol=1e-14)
    assert np.all(res["body/rocket/mass"][res.t >= T_BURN] == M_FINAL)


def test_momentum_and_thrust_work():
    res = ms.simulate(rocket_model(), 40.0, TIGHT, output_dt=0.25)
    t = res.t
    # p = m(t) v(t); thrust work = F x during the burn, then constant
    np.testing.assert_allclose(res["momentum/linear"][:, 0], mass(t) * delta_v(t), rtol=1e-8, atol=1e-8 * M0 * W_REL)
    thrust = -MDOT * W_REL
    np.testing.assert_allclose(res["energy/external_work"], thrust * distance(np.minimum(t, T_BURN)), rtol=1e-8, atol=1e-6)
    np.testing.assert_allclose(res["energy/kinetic"], 0.5 * mass(t) * delta_v(t) ** 2, rtol=1e-8, atol=1e-6)


def test_thrust_follows_body_orientation_and_adds_to_initial_velocity():
    """Turned so that the body x axis points along d: v(t) = v0 + d w ln(m0/m)."""
    rot = Rotation.from_rotvec([0.3, -0.8, 0.5])
    quat = rot.as_quat(scalar_first=True)
    d = rot.as_matrix()[:, 0]
    v0_inertial = np.array([10.0, -4.0, 7.0])
    v0_body = rot.as_matrix().T @ v0_inertial  # the free joint's u holds v_B in body components
    r0 = np.array([1.0, 2.0, -3.0])
    res = ms.simulate(
        rocket_model(), 35.0, TIGHT, output_dt=0.5, q0={"flight": np.r_[r0, quat]}, u0={"flight": np.r_[v0_body, 0.0, 0.0, 0.0]}
    )
    t = res.t
    expected_v = v0_inertial + np.outer(delta_v(t), d)
    assert np.max(np.abs(res["body/rocket/velocity"] - expected_v)) < 1e-8 * W_REL
    expected_r = r0 + np.outer(t, v0_inertial) + np.outer(distance(t), d)
    assert np.max(np.abs(res["body/rocket/position"] - expected_r)) < 1e-8 * distance(t[-1])
    # no rotation is induced, the thrust acts at the centre of mass (what shows is integration
    # noise: absolute tolerance 1e-12 on states of size 1e3)
    assert np.max(np.abs(res["body/rocket/angular_velocity"])) < 1e-9
    np.testing.assert_allclose(res["body/rocket/orientation"][-1], quat, atol=1e-9)


@pytest.mark.parametrize("w_rel", [800.0, 300.0], ids=["lift-off", "too-weak"])
def test_vertical_flight_under_gravity(w_rel):
    """Body x pointing up, gravity -g e_z: v_z = w ln(m0/m) - g t (thrust-to-weight 1.6 or 0.6)."""
    g = 9.81
    quat = Rotation.from_rotvec([0.0, -0.5 * np.pi, 0.0]).as_quat(scalar_first=True)  # body x -> inertial z
    res = ms.simulate(rocket_model(gravity=(0.0, 0.0, -g), w_rel=w_rel), 20.0, TIGHT, output_dt=0.25,
                      q0={"flight": np.r_[0.0, 0.0, 0.0, quat]})
    t = res.t
    v_z = delta_v(t, w_rel) - g * t
    assert np.max(np.abs(res["body/rocket/velocity"][:, 2] - v_z)) < 1e-8 * w_rel
    z = distance(t, w_rel) - 0.5 * g * t**2
    assert np.max(np.abs(res["body/rocket/position"][:, 2] - z)) < 1e-8 * np.abs(z).max()
    assert (v_z[4] > 0) == (-MDOT * w_rel > M0 * g)
