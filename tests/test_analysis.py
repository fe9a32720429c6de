"""Assembly, kinematic analysis and static equilibrium of constrained mechanisms."""

from __future__ import annotations

import runpy
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
A, B, C, D = 0.1, 0.3, 0.25, 0.28


def four_bar():
    return runpy.run_path(str(EXAMPLES / "four_bar.py"))["model"]


def slider_crank():
    return runpy.run_path(str(EXAMPLES / "slider_crank.py"))


def test_assembly_keeps_the_named_joints_and_closes_the_loop():
    m = four_bar()
    q, u = ms.analysis.assemble(m, q={"o2": 0.7}, u={"o2": 3.0}, keep=["o2"])
    info = {j["name"]: j for j in m.joint_info()}
    assert q[info["o2"]["iq"]] == 0.7 and u[info["o2"]["iu"]] == 3.0
    phi, g, b = ms._core.constraint_jacobian(m.build(), q, 0.0)
    assert np.abs(phi).max() < 1e-12
    assert np.abs(g @ u - b).max() < 1e-12
    # the closed loop satisfies Freudenstein's equation at the kept crank angle
    th2, th4 = 0.7, q[info["o4"]["iq"]]
    k1, k2, k3 = D / A, D / C, (A**2 - B**2 + C**2 + D**2) / (2 * A * C)
    assert abs(k1 * np.cos(th4) - k2 * np.cos(th2) + k3 - np.cos(th2 - th4)) < 1e-12
    # simulate(..., keep=...) starts from exactly that state
    res = ms.simulate(m, 0.05, ms.RK4(1e-3), q0={"o2": 0.7}, u0={"o2": 3.0}, keep=["o2"])
    assert res["joint/o2/q"][0] == 0.7 and abs(res["joint/o2/u"][0] - 3.0) < 1e-12


def test_assembly_reports_the_constraint_that_cannot_close():
    m = four_bar()
    # with the ground link much longer than the others the loop cannot close
    m._joints[2].parent_frame = (2.0, 0.0, 0.0)
    m._invalidate()
    with pytest.raises(ms.SolverError) as e:
        ms.analysis.assemble(m)
    assert "'b'" in str(e.value)


def test_kinematic_analysis_of_the_slider_crank_matches_the_closed_form():
    ex = slider_crank()
    r, l, w = ex["R"], ex["L"], ex["OMEGA"]
    t = np.linspace(0.0, 0.3, 31)
    out = ms.analysis.kinematic_analysis(ex["model"], t)
    th = w * t
    root = np.sqrt(l**2 - (r * np.sin(th)) ** 2)
    x = r * np.cos(th) + root
    xd = -r * w * np.sin(th) - r**2 * w * np.sin(th) * np.cos(th) / root
    xdd = -r * w**2 * np.cos(th) - r**2 * w**2 * np.cos(2 * th) / root - r**4 * w**2 * np.sin(th) ** 2 * np.cos(th) ** 2 / root**3
    np.testing.assert_allclose(out["q"][:, 2], x, atol=1e-10)
    np.testing.assert_allclose(out["u"][:, 2], xd, atol=1e-10)
    np.testing.assert_allclose(out["udot"][:, 2], xdd, atol=1e-8)


def test_kinematic_analysis_needs_a_driven_mechanism():
    with pytest.raises(ms.ModelError) as e:
        ms.analysis.kinematic_analysis(four_bar(), [0.0])
    assert "degree" in str(e.value)


def loaded_four_bar(th2, drive):
    m = ms.Model("loaded four-bar")  # no gravity: the load alone
    crank = m.add_body("crank", 0.2, ms.inertia.cylinder(0.2, 0.005, A), com=(A / 2, 0, 0))
    coupler = m.add_body("coupler", 0.4, ms.inertia.cylinder(0.4, 0.005, B), com=(B / 2, 0, 0))
    rocker = m.add_body("rocker", 0.3, ms.inertia.cylinder(0.3, 0.005, C), com=(C / 2, 0, 0))
    m.add_joint(ms.joints.Revolute("o2", m.ground, crank, q0=th2))
    m.add_joint(ms.joints.Revolute("a", crank, coupler, parent_frame=(A, 0, 0), q0=0.5))
    m.add_joint(ms.joints.Revolute("o4", m.ground, rocker, parent_frame=(D, 0, 0), q0=1.6))
    m.add_constraint(ms.constraints.Point("b", body1=coupler, point1=(B, 0, 0), body2=rocker, point2=(C, 0, 0)))
    if drive:
        m.add_constraint(ms.constraints.Prescribed("motor", "o2", ms.functions.Constant(th2)))
        m.add_force(ms.forces.BodyForce("load", rocker, force=(3.0, -2.0, 0.0), point=(C, 0, 0)))
    return m


def test_static_equilibrium_drive_torque_equals_virtual_work():
    th2 = 0.9
    eq = ms.analysis.static_equilibrium(loaded_four_bar(th2, drive=True))
    tau = eq["lambda"]["motor"][0]
    assert eq["residual"] < 1e-9
    # virtual work: tau dtheta2 + F . dr_tip = 0, with dr_tip/dtheta2 from the loop geometry alone
    # (central differences of assembled configurations of the undriven linkage)
    free = loaded_four_bar(th2, drive=False)

    def tip(theta):
        q, _ = ms.analysis.assemble(free, q={"o2": theta, "a": eq["q"][1], "o4": eq["q"][2]}, keep=["o2"])
        return ms.kinematics.point_position(free, q, "rocker", (C, 0, 0))

    h = 1e-6
    drdth = (tip(th2 + h) - tip(th2 - h)) / (2 * h)
    np.testing.assert_allclose(tau, -np.array([3.0, -2.0, 0.0]) @ drdth, rtol=1e-6)


def test_coordinate_partitioning_gives_a_velocity_map_in_the_null_space_of_g():
    m = four_bar()
    q, _ = ms.analysis.assemble(m)
    part = ms.analysis.coordinate_partitioning(m, q)
    assert len(part["independent"]) == 1 and len(part["dependent"]) == 2
    v = part["velocity_map"]
    _, g, _ = ms._core.constraint_jacobian(m.build(), q, 0.0)
    assert np.abs(g @ v).max() < 1e-12
    # any independent velocity gives a consistent motion: the loop closure rate vanishes
    u = v @ np.array([2.5])
    assert np.abs(g @ u).max() < 1e-12


def test_pseudo_inverse_relation_recovers_generalized_velocities():
    m = four_bar()
    q, _ = ms.analysis.assemble(m)
    u = np.array([1.3, -0.4, 0.7])
    j = ms.analysis.system_jacobian(m, q)
    assert j.shape == (6 * 3, 3)
    # z-dot from the recursive kinematics, then u back by eq. 2.68
    st = ms.kinematics.body_states(m, q, u)
    zdot = np.concatenate([np.concatenate([st["velocity"][k], st["angular_velocity"][k]]) for k in (1, 2, 3)])
    np.testing.assert_allclose(j @ u, zdot, atol=1e-12)
    np.testing.assert_allclose(ms.analysis.velocities_from_system(m, q, zdot), u, atol=1e-12)


def test_period_of_a_sampled_sine_from_its_interpolated_crossings():
    t = np.linspace(0.0, 10.0, 2001)
    np.testing.assert_allclose(ms.analysis.period(t, np.sin(2 * np.pi * t / 1.3)), 1.3, rtol=1e-5)
    # about the middle of its range (an offset sine), or about a given level
    np.testing.assert_allclose(ms.analysis.period(t, 3.0 + np.cos(2 * np.pi * t / 0.7), level=None), 0.7, rtol=1e-5)
    np.testing.assert_allclose(ms.analysis.period(t, 3.0 + np.cos(2 * np.pi * t / 0.7), level=3.0), 0.7, rtol=1e-5)
    with pytest.raises(ms.errors.SettingsError, match="need at least 2"):
        ms.analysis.period(t, np.exp(-t))


def test_static_equilibrium_leaves_a_level_pendulum_downhill_to_the_hanging_one():
    # held level the pendulum's stiffness vanishes: Newton alone has no step there
    from mechsys.modelfile import load_model

    root = Path(__file__).resolve().parents[1]
    for name in ("pendulum.toml", "double_pendulum.toml"):
        model, _ = load_model(root / "examples" / name)
        eq = ms.analysis.static_equilibrium(model)
        # hanging: every rod along -y, the first at -pi/2 (mod 2 pi), the second straight on
        np.testing.assert_allclose(np.mod(eq["q"][0] + np.pi / 2, 2 * np.pi), 0.0, atol=1e-9)
        np.testing.assert_allclose(eq["q"][1:], 0.0, atol=1e-9)
        lin = ms.linear.linearize(model, q=eq["q"])
        assert lin.modes().stable and np.all(lin.modes().natural_frequency > 0)
