"""Guards of a run (issue 13, part 2): an explicit fixed step above its stability limit stops with
a message naming the stiff element and the stable step (instead of returning growing garbage),
step and wall-time budgets, and settings that cannot give a meaningful run are refused."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms


def spring(k: float, m: float = 1.0) -> ms.Model:
    mod = ms.Model("stiff", gravity=(0, 0, 0))
    b = mod.add_body("b", m, [1e-3] * 3)
    mod.add_joint(ms.joints.Prismatic("x", mod.ground, b, axis=(1, 0, 0), q0=0.01))
    mod.add_force(ms.forces.SpringDamper("s", mod.ground, b, k=k, l0=0.0))
    return mod


def test_unstable_rk4_stops_naming_the_stiff_spring_and_the_stable_step():
    # k = 1e9 on 1 kg: omega = 3.16e4 rad/s, RK4 stable for dt < 2.8 / omega = 8.85e-5 s
    with pytest.raises(ms.SolverError, match=r"diverged at t = 0\.01.*force element 's'.*3\.1623e4 rad/s.*dt < 2\.8 / omega = 8\.854e-5 s"):
        ms.simulate(spring(1e9), 0.1, ms.RK4(dt=1e-2))


def test_stable_rk4_is_not_flagged():
    # omega dt = 1.6: stable (RK4's own damping takes energy out), so not flagged
    res = ms.simulate(spring(1e9), 0.01, ms.RK4(dt=5e-5), output_dt=1e-4)
    assert res["energy/total"][-1] < res["energy/total"][0]
    # omega dt = 0.03: the closed form x = x0 cos(w t)
    res = ms.simulate(spring(1e9), 0.002, ms.RK4(dt=1e-6), output_dt=1e-5)
    np.testing.assert_allclose(res["joint/x/q"], 0.01 * np.cos(np.sqrt(1e9) * res.t), atol=1e-8)


def test_a_driven_run_whose_energy_comes_from_outside_is_not_flagged():
    # a joint force doing work on the spring: the balance counts it (T + V - W + D constant)
    m = spring(1e4)
    m.add_force(ms.forces.JointForce("push", "x", 50.0))
    res = ms.simulate(m, 2.0, ms.RK4(dt=1e-4), output_dt=1e-2)
    balance = res["energy/total"] - res["energy/external_work"] + res["energy/dissipated"]
    assert np.abs(res["energy/external_work"]).max() > 0.1 and np.ptp(balance) < 1e-6


def test_step_and_wall_budgets():
    with pytest.raises(ms.SolverError, match=r"step budget of 100 accepted steps spent at t = 0\.0101"):
        ms.simulate(spring(1e4), 1.0, ms.RK4(dt=1e-4), max_steps=100)
    with pytest.raises(ms.SolverError, match="wall-time budget of 0.01 s spent"):
        ms.simulate(spring(1e4), 1e4, ms.DOPRI5(rtol=1e-12, atol=1e-14), max_wall=0.01)
    res = ms.simulate(spring(1e4), 0.1, ms.RK4(dt=1e-4), max_steps=2000, max_wall=60)
    assert res.t[-1] == pytest.approx(0.1)
    for bad, msg in ((dict(max_steps=0), "max_steps"), (dict(max_steps=1.5), "max_steps"), (dict(max_wall=-1), "max_wall"),
                     (dict(max_wall="x"), "max_wall")):
        with pytest.raises(ms.SettingsError, match=msg):
            ms.simulate(spring(1e4), 0.1, ms.RK4(dt=1e-4), **bad)


@pytest.mark.parametrize("kwargs,message", [
    (dict(integrator=ms.RK4(dt=1.0)), r"integrator\.dt: the step \(1 s\) is longer than the run \(0\.5 s"),
    (dict(output_dt=2.0), r"output_dt: 2 s is longer than the run"),
    (dict(integrator=ms.DOPRI5(rtol=1e-30)), r"integrator\.rtol: must be in \[1e-14, 1\)"),
    (dict(integrator=ms.DOPRI5(rtol=1e6)), r"integrator\.rtol: must be in \[1e-14, 1\)"),
    (dict(integrator=ms.DOPRI5(atol=-1.0)), r"integrator\.atol: must be >= 0"),
])
def test_settings_that_cannot_give_a_meaningful_run_are_refused(kwargs, message):
    with pytest.raises(ms.SettingsError, match=message):
        ms.simulate(spring(1.0), 0.5, **kwargs)


# ---- point masses (issue 13, part 4) ---------------------------------------------------------------


def test_point_mass_pendulum_period_is_the_elliptic_integral():
    from scipy.special import ellipk

    g, l, th0 = 9.81, 0.8, 2.0  # large amplitude: far from the small-angle period
    m = ms.Model("point-pendulum", gravity=(0, 0, -g))
    bob = m.add_body("bob", 0.5, [0, 0, 0], com=(0, 0, -l))  # a point mass: zero inertia
    m.add_joint(ms.joints.Revolute("hinge", m.ground, bob, axis=(1, 0, 0), q0=th0))
    period = 4 * np.sqrt(l / g) * ellipk(np.sin(th0 / 2) ** 2)
    res = ms.simulate(m, period, ms.DOPRI5(rtol=1e-12, atol=1e-14), output_dt=period / 400)
    q = res["joint/hinge/q"]
    assert q[-1] == pytest.approx(th0, abs=1e-8) and q[200] == pytest.approx(-th0, abs=1e-8)
    assert np.ptp(res["energy/total"]) < 1e-10


def test_a_point_mass_turning_about_its_own_centre_is_named():
    m = ms.Model("pm")
    b = m.add_body("bob", 1.0, [0, 0, 0])
    m.add_joint(ms.joints.Spherical("ball", m.ground, b))
    with pytest.raises(ms.ModelError, match=r"'ball' \(velocity 0\).*move no inertia"):
        ms.simulate(m, 1.0)
    with pytest.raises(ms.ModelError, match="negative principal moment"):
        ms.Model("neg").add_body("b", 1.0, [-1, 1, 1]).model.build() if False else _negative()


def _negative():
    m = ms.Model("neg")
    b = m.add_body("b", 1.0, [-1.0, 1.0, 1.0])
    m.add_joint(ms.joints.Revolute("r", m.ground, b))
    m.build()


def test_a_long_run_is_not_stopped_by_a_step_floor_relative_to_its_span():
    """The adaptive schemes' smallest step was 1e-14 of the span: a 10-link chain run to
    t_end = 1000 s stopped with 'step size underflow' at t = 1.9157 s (where its steps are ~1e-11
    s), while the same run to 3 s went through. Now only the round-off of t bounds the step."""
    m = ms.Model("chain", gravity=(0, -9.81, 0))
    parent = m.ground
    for i in range(10):
        b = m.add_body(f"b{i}", 1.0, ms.inertia.rod(1.0, 0.1), com=(0.05, 0, 0))
        m.add_joint(ms.joints.Revolute(f"j{i}", parent, b, parent_frame=(0.1, 0, 0) if i else None))
        parent = b
    for integ in (ms.DOPRI5(), ms.Radau5(rtol=1e-6)):
        with pytest.raises(ms.SolverError) as e:
            ms.simulate(m, 1000.0, integ, output_dt=0.01, max_steps=3000)
        msg = str(e.value)
        assert "step budget of 3000 accepted steps spent at t = " in msg, msg
        assert float(msg.split("spent at t = ")[1].split(" s")[0]) > 2.0, msg
