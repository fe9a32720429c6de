"""Bilateral constraints (issue 3, first part): Lagrange multipliers, projection, driving
constraints, checked against closed-form mechanics."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms

G = 9.81
TIGHT = ms.DOPRI5(rtol=1e-11, atol=1e-12)


def spherical_pendulum_as_free_body(mass=1.5, length=0.9, theta0=0.7):
    """A free body hanging on a massless rod: a distance constraint from a ground anchor to its
    centre of mass (so the rod exerts no moment and the body is a point-mass pendulum)."""
    m = ms.Model("rod-pendulum", gravity=(0.0, -G, 0.0))
    bob = m.add_body("bob", mass, ms.inertia.sphere(mass, 0.05))
    x0, y0 = length * np.sin(theta0), -length * np.cos(theta0)
    m.add_joint(ms.joints.Free("float", m.ground, bob, q0=[x0, y0, 0.0, 1.0, 0.0, 0.0, 0.0]))
    m.add_constraint(ms.constraints.Distance("rod", body1=bob, body2=m.ground, length=length))
    return m


def test_rod_force_of_a_pendulum_built_from_a_free_body_and_a_constraint():
    mass, length = 1.5, 0.9
    res = ms.simulate(spherical_pendulum_as_free_body(mass, length), 3.0, TIGHT, output_dt=0.01)
    r = res["body/bob/position"]
    v = res["body/bob/velocity"]
    theta = np.arctan2(r[:, 0], -r[:, 1])
    # tension m (g cos(theta) + l theta'^2), with l theta'^2 = |v|^2 / l; lambda acts along the
    # line from the anchor to the bob, so the pulling rod has lambda = -tension
    tension = mass * (G * np.cos(theta) + np.sum(v**2, axis=1) / length)
    np.testing.assert_allclose(-res["constraint/rod/lambda"], tension, rtol=0, atol=1e-8)
    assert np.abs(res["constraint/rod/violation"]).max() < 1e-10
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * np.abs(e).max()
    assert res.unit("constraint/rod/lambda") == "N"


def slider_crank(r=0.1, l=0.35, omega=20.0):
    m = ms.Model("slider-crank", gravity=(0.0, -G, 0.0))
    crank = m.add_body("crank", 0.5, ms.inertia.cylinder(0.5, 0.01, r), com=(r / 2, 0, 0))
    rod = m.add_body("rod", 0.8, ms.inertia.cylinder(0.8, 0.01, l), com=(l / 2, 0, 0))
    slider = m.add_body("slider", 1.2, ms.inertia.box(1.2, (0.05, 0.05, 0.05)))
    m.add_joint(ms.joints.Revolute("crank_pin", m.ground, crank, axis=(0, 0, 1)))
    m.add_joint(ms.joints.Revolute("crank_rod", crank, rod, axis=(0, 0, 1), parent_frame=ms.Frame(position=(r, 0, 0))))
    m.add_joint(ms.joints.Prismatic("guide", m.ground, slider, axis=(1, 0, 0), q0=r + l))
    m.add_constraint(ms.constraints.Point("wrist", body1=rod, point1=(l, 0, 0), body2=slider))
    m.add_constraint(ms.constraints.Prescribed("motor", "crank_pin", ms.functions.Ramp(slope=omega)))
    return m


def test_slider_crank_driven_at_constant_speed_follows_the_closed_form():
    r, l, omega = 0.1, 0.35, 20.0
    res = ms.simulate(slider_crank(r, l, omega), 0.5, ms.RK4(1e-4), output_dt=1e-3)
    th = omega * res.t
    np.testing.assert_allclose(res["joint/crank_pin/q"], th, atol=1e-12)
    root = np.sqrt(l**2 - (r * np.sin(th)) ** 2)
    x = r * np.cos(th) + root
    xd = -r * omega * np.sin(th) - (r**2 * omega * np.sin(th) * np.cos(th)) / root
    xdd = (
        -r * omega**2 * np.cos(th)
        - (r**2 * omega**2 * np.cos(2 * th)) / root
        - (r**4 * omega**2 * np.sin(th) ** 2 * np.cos(th) ** 2) / root**3
    )
    np.testing.assert_allclose(res["joint/guide/q"], x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res["joint/guide/u"], xd, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res["joint/guide/udot"], xdd, rtol=0, atol=1e-10)
    # the motor's work equals the change of mechanical energy
    balance = res["energy/total"] - res["energy/external_work"]
    assert np.ptp(balance) < 1e-6 * np.abs(res["energy/kinetic"]).max()


def test_four_bar_output_angle_satisfies_freudensteins_equation():
    a, b, c, d = 0.1, 0.3, 0.25, 0.28  # crank, coupler, rocker, ground link (Grashof crank-rocker)
    m = ms.Model("four-bar", gravity=(0.0, -G, 0.0))
    crank = m.add_body("crank", 0.2, ms.inertia.cylinder(0.2, 0.005, a), com=(a / 2, 0, 0))
    coupler = m.add_body("coupler", 0.4, ms.inertia.cylinder(0.4, 0.005, b), com=(b / 2, 0, 0))
    rocker = m.add_body("rocker", 0.3, ms.inertia.cylinder(0.3, 0.005, c), com=(c / 2, 0, 0))
    th2_0 = 0.3
    # a rough initial guess: the start projection assembles the loop
    m.add_joint(ms.joints.Revolute("o2", m.ground, crank, q0=th2_0))
    m.add_joint(ms.joints.Revolute("a", crank, coupler, parent_frame=(a, 0, 0), q0=0.9))
    m.add_joint(ms.joints.Revolute("o4", m.ground, rocker, parent_frame=(d, 0, 0), q0=1.9))
    m.add_constraint(ms.constraints.Point("b", body1=coupler, point1=(b, 0, 0), body2=rocker, point2=(c, 0, 0)))
    # the crank swings through a range of angles about its start
    m.add_constraint(ms.constraints.Prescribed("motor", "o2", ms.functions.Harmonic(0.8, 6.0, offset=th2_0)))
    res = ms.simulate(m, 1.0, ms.RK4(1e-3), output_dt=1e-2)
    th2, th4 = res["joint/o2/q"], res["joint/o4/q"]
    k1, k2, k3 = d / a, d / c, (a**2 - b**2 + c**2 + d**2) / (2 * a * c)
    freudenstein = k1 * np.cos(th4) - k2 * np.cos(th2) + k3 - np.cos(th2 - th4)
    np.testing.assert_allclose(freudenstein, 0.0, atol=1e-10)
    assert np.abs(res["constraint/b/violation"]).max() < 1e-10


def test_coupler_gear_keeps_its_ratio_and_conserves_energy():
    m = ms.Model("gears")
    w1 = m.add_body("w1", 1.0, ms.inertia.disc(1.0, 0.1))
    w2 = m.add_body("w2", 2.0, ms.inertia.disc(2.0, 0.2))
    m.add_joint(ms.joints.Revolute("j1", m.ground, w1, u0=2.0))
    m.add_joint(ms.joints.Revolute("j2", m.ground, w2, parent_frame=(0.3, 0, 0), u0=-1.0))
    m.add_constraint(ms.constraints.Coupler("mesh", "j1", "j2", ratio=-2.0))
    m.add_force(ms.forces.JointForce("drive", "j2", value=0.5, function=ms.functions.Harmonic(1.0, 3.0)))
    res = ms.simulate(m, 2.0, TIGHT, output_dt=0.01)
    np.testing.assert_allclose(res["joint/j1/q"], -2.0 * res["joint/j2/q"], atol=1e-10)
    np.testing.assert_allclose(res["joint/j1/u"], -2.0 * res["joint/j2/u"], atol=1e-10)
    # the gear force does no work: total energy changes only by the drive's work
    bal = res["energy/total"] - res["energy/external_work"]
    assert np.ptp(bal) < 1e-9
    # equal and opposite tooth force: M1 u1' = lambda, M2 u2' = tau - 2... checked through the rows
    i1, i2 = 0.5 * 1.0 * 0.1**2, 0.5 * 2.0 * 0.2**2
    tau = 0.5 * np.sin(3.0 * res.t)
    lam = res["constraint/mesh/lambda"]
    np.testing.assert_allclose(i1 * res["joint/j1/udot"], lam, atol=1e-9)
    np.testing.assert_allclose(i2 * res["joint/j2/udot"], tau + 2.0 * lam, atol=1e-9)


@pytest.mark.parametrize(
    "constraint, fragments",
    [
        (lambda m: ms.constraints.Point("p", "nobody", "ground"), ["p", "body1", "nobody"]),
        (lambda m: ms.constraints.Coupler("c", "j1", "nojoint", 2.0), ["c", "joint2", "nojoint"]),
        (lambda m: ms.constraints.Distance("d", "b", "ground", length=-1.0), ["d", "length"]),
        (lambda m: ms.constraints.Prescribed("pr", "j1", 1.0, index=3), ["pr", "index"]),
    ],
)
def test_bad_constraints_name_the_item(constraint, fragments):
    m = ms.Model("m")
    b = m.add_body("b", 1.0, [0.1, 0.1, 0.1])
    m.add_joint(ms.joints.Revolute("j1", m.ground, b))
    m.add_constraint(constraint(m))
    with pytest.raises(ms.ModelError) as e:
        m.build()
    for f in fragments:
        assert f in str(e.value)


def test_a_mechanism_that_cannot_close_is_reported_with_the_constraint():
    m = ms.Model("m")
    b = m.add_body("b", 1.0, [0.1, 0.1, 0.1], com=(0.5, 0, 0))
    m.add_joint(ms.joints.Revolute("j1", m.ground, b))
    # the tip of a 1 m arm can never reach a point 5 m away
    m.add_constraint(ms.constraints.Point("reach", b, m.ground, point1=(1.0, 0, 0), point2=(5.0, 0.0, 0.0)))
    with pytest.raises(ms.SolverError) as e:
        ms.simulate(m, 0.1, ms.RK4(1e-3))
    assert "reach" in str(e.value)


def test_drift_control_options_from_python():
    m = spherical_pendulum_as_free_body()
    worst = {}
    for name, stab in [("projection", None), ("baumgarte", ms.constraints.Baumgarte(20.0, 20.0)), ("none", "none")]:
        res = ms.simulate(m, 10.0, ms.RK4(1e-2), stabilization=stab)
        worst[name] = np.abs(res["constraint/rod/violation"]).max()
    assert worst["projection"] < 1e-12
    # RK4 drift grows without control; Baumgarte feedback keeps it about nine times lower (measured
    # 0.110 of it)
    assert worst["baumgarte"] < 0.13 * worst["none"]
    with pytest.raises(ms.SettingsError):
        ms.simulate(m, 0.1, ms.RK4(1e-3), stabilization="magic")
    with pytest.raises(ms.SettingsError) as e:
        ms.simulate(m, 0.1, ms.RK4(1e-3), stabilization=ms.constraints.Baumgarte(-1.0, 2.0))
    assert "Baumgarte" in str(e.value)


def test_two_drives_on_one_coordinate_are_rejected():
    m = slider_crank()
    m.add_constraint(ms.constraints.Prescribed("second_motor", "crank_pin", 0.3))
    with pytest.raises(ms.ModelError) as e:
        m.build()
    assert "second_motor" in str(e.value) and "motor" in str(e.value) and "crank_pin" in str(e.value)


def test_redundant_constraints_share_the_load_by_minimum_norm():
    # the same rod twice: the tension is split equally between the two copies
    single = ms.simulate(spherical_pendulum_as_free_body(), 1.0, TIGHT, output_dt=0.05)
    m = spherical_pendulum_as_free_body()
    m.add_constraint(ms.constraints.Distance("rod_copy", body1="bob", body2=m.ground, length=0.9))
    with pytest.warns(UserWarning, match="redundant"):
        double = ms.simulate(m, 1.0, TIGHT, output_dt=0.05)
    np.testing.assert_allclose(double["body/bob/position"], single["body/bob/position"], atol=1e-9)
    half = 0.5 * single["constraint/rod/lambda"]
    np.testing.assert_allclose(double["constraint/rod/lambda"], half, atol=1e-8)
    np.testing.assert_allclose(double["constraint/rod_copy/lambda"], half, atol=1e-8)


def test_singular_configuration_met_during_a_run_is_reported_with_time_and_constraint():
    """A driven slider-crank with rod length = crank radius: at crank angle pi/2 the rod lies on
    the crank and the wrist's y-equation vanishes (the Jacobian loses rank). Passing near it is
    smooth on this branch (the slider follows x = 2 r cos(theta)) but is reported as a warning
    naming the time and the constraint; landing exactly on it stops the run with a SolverError."""
    r, omega = 0.2, 2.0
    with pytest.warns(UserWarning, match="near-singular configuration at t = 0.78") as rec:
        res = ms.simulate(slider_crank(r=r, l=r, omega=omega), 1.5, ms.RK4(1e-3), output_dt=1e-2)
    msg = [str(w.message) for w in rec if "near-singular" in str(w.message)]
    assert len(msg) == 1 and "constraint 'wrist' (row 1)" in msg[0]
    t_warn = float(msg[0].split("t = ")[1].split(" s")[0])
    assert abs(t_warn - np.pi / 2 / omega) < 2e-3
    np.testing.assert_allclose(res["joint/guide/q"], 2 * r * np.cos(omega * res.t), atol=1e-12)
    # a step that lands on theta = pi/2 exactly (omega t = pi/2 at t = 0.5 s): by default the run
    # goes on (minimum-norm multipliers, a warning with the time), or stops when asked
    with pytest.warns(UserWarning, match=r"singular configuration at t = 0\.500000 s: constraint 'wrist'"):
        res = ms.simulate(slider_crank(r=r, l=r, omega=np.pi), 1.0, ms.RK4(1e-3), output_dt=1e-2)
    np.testing.assert_allclose(res["joint/guide/q"], 2 * r * np.cos(np.pi * res.t), atol=1e-9)
    with pytest.raises(ms.SolverError, match=r"singular configuration at t = 0\.500000 s: constraint 'wrist'"):
        ms.simulate(slider_crank(r=r, l=r, omega=np.pi), 1.0, ms.RK4(1e-3), output_dt=1e-2, on_singular="stop")
    with pytest.raises(ms.SettingsError, match="on_singular: must be 'continue' or 'stop'"):
        ms.simulate(slider_crank(r=r, l=r, omega=np.pi), 1.0, ms.RK4(1e-3), output_dt=1e-2, on_singular="warn")


def test_velocity_violation_signal_is_recorded_for_every_row():
    res = ms.simulate(slider_crank(), 0.2, ms.RK4(1e-3), output_dt=1e-2)
    vv = res["constraint/wrist/velocity_violation"]
    assert vv.shape == (21, 3) and res.unit("constraint/wrist/velocity_violation") == "m/s"
    assert np.abs(vv).max() < 1e-12
    assert np.abs(res["constraint/motor/velocity_violation"]).max() < 1e-12
    # without drift control the velocity residual drifts; for the rod it is e . v of the bob
    free = ms.simulate(spherical_pendulum_as_free_body(), 2.0, ms.RK4(2e-2), output_dt=2e-2, stabilization="none")
    r, v = free["body/bob/position"], free["body/bob/velocity"]
    ev = np.sum(r * v, axis=1) / np.linalg.norm(r, axis=1)
    vv = free["constraint/rod/velocity_violation"]
    assert np.abs(vv).max() > 1e-7
    np.testing.assert_allclose(vv, ev, rtol=0, atol=1e-15)
