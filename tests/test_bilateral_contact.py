"""Contacts held closed (laws.Bilateral) and the linearization with closed contacts: against
closed forms of rolling, of a cam follower's force and of small oscillations on curved contours."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import ModelError, SettingsError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
G = 9.81


def _example(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _incline(alpha: float, rolling: bool, r: float = 0.1, mass: float = 2.0, friction=None) -> ms.Model:
    """A solid cylinder (a circle) on a line, gravity tilted by alpha (the line an incline)."""
    m = ms.Model("incline", gravity=(G * np.sin(alpha), -G * np.cos(alpha), 0.0), planar=True)
    b = m.add_body("cyl", mass, ms.inertia.cylinder(mass, r, 0.05, axis="z"))
    m.add_joint(ms.joints.Planar("p", m.ground, b, q0=[0.0, r, 0.0]))
    normal = ms.laws.Bilateral(rolling=rolling) if friction is None else ms.laws.Signorini()
    m.add_contact(ms.Contact("roll", b.contour(ms.contours.Circle(radius=r)),
                             m.ground.contour(ms.contours.Line(point=(0, 0, 0), normal=(0, 1, 0))),
                             normal=normal, friction=friction))
    return m


@pytest.mark.parametrize("integrator", [None, "moreau_jean"])
def test_a_cylinder_held_rolling_on_an_incline_accelerates_at_two_thirds_g_sin_alpha(integrator):
    alpha, r, mass = 0.3, 0.1, 2.0
    m = _incline(alpha, True, r, mass)
    kw = dict(integrator=ms.MoreauJean(dt=1e-3)) if integrator else {}
    res = ms.simulate(m, t_end=1.0, output_dt=0.01, **kw)
    q = res["joint/p/q"]
    a = 2.0 / 3.0 * G * np.sin(alpha)  # m g sin a / (m + I / r^2), I = m r^2 / 2
    tol = 1e-9 if integrator is None else 2e-3
    np.testing.assert_allclose(q[:, 0], 0.5 * a * res.t**2, atol=tol)
    np.testing.assert_allclose(q[:, 2], -q[:, 0] / r, atol=tol / r)  # rolls: x = -r phi
    np.testing.assert_allclose(q[:, 1], r, atol=1e-9)
    lam = res["constraint/roll/lambda"]
    assert res.columns("constraint/roll/lambda") == ["normal", "t1"]
    # the normal force carries the weight's normal part; friction (along t1 = e_z x n = -x) holds a third of its slope part
    np.testing.assert_allclose(lam[2:, 0], mass * G * np.cos(alpha), rtol=1e-6)
    np.testing.assert_allclose(lam[2:, 1], mass * G * np.sin(alpha) / 3.0, rtol=1e-6 if integrator is None else 1e-3)


def test_a_cylinder_held_without_rolling_slides_at_g_sin_alpha_without_turning():
    alpha = 0.3
    res = ms.simulate(_incline(alpha, False), t_end=1.0, output_dt=0.01)
    q = res["joint/p/q"]
    np.testing.assert_allclose(q[:, 0], 0.5 * G * np.sin(alpha) * res.t**2, atol=1e-9)
    np.testing.assert_allclose(q[:, 2], 0.0, atol=1e-12)


def test_a_held_cam_follower_follows_the_lift_and_its_force_pulls_above_the_critical_speed():
    cf = _example("cam_follower")
    omega = 1.5 * cf.OMEGA_C
    m = cf.build(omega)
    m._contacts[0].normal = ms.laws.Bilateral()
    m._contacts[0].impact = None
    res = ms.simulate(m, t_end=2 * np.pi / omega, output_dt=1e-4)
    theta = res["joint/shaft/q"]
    y = res["joint/guide/q"] - (cf.BASE + cf.ROLLER)
    assert np.abs(y - cf.lift(theta)).max() < 1e-10
    # vertical balance of the follower: lambda cos(pressure angle) = m omega^2 h'' + k h + F0 + m g, with
    # tan(pressure angle) = h' / (r_pitch + h) for an in-line roller follower
    pitch = cf.BASE + cf.ROLLER
    phi = np.arctan2(0.5 * cf.LIFT * np.sin(theta), pitch + cf.lift(theta))
    expected = cf.MASS * 0.5 * cf.LIFT * np.cos(theta) * omega**2 + cf.K * cf.lift(theta) + cf.PRELOAD + cf.MASS * cf.G
    lam = res["constraint/cam/lambda"]
    np.testing.assert_allclose(lam * np.cos(phi), expected, atol=1e-6)
    assert expected.min() < -40.0 and lam.min() < -40.0  # it pulls where a unilateral contact lifts off
    # power through the frictionless contact: motor torque x omega = lambda cos(phi) y'
    np.testing.assert_allclose(res["constraint/motor/lambda"], lam * np.cos(phi) * res["joint/guide/u"] / omega,
                               atol=1e-7)
    # the contact force reaches the cam (body 2) with its moment: the shaft's reactions balance it
    np.testing.assert_allclose(res["joint/shaft/reaction_torque"][:, 2], res["constraint/motor/lambda"], atol=1e-9)
    cam_mass = 1.0
    np.testing.assert_allclose(np.linalg.norm(res["joint/shaft/reaction_force"], axis=1),
                               np.sqrt(lam**2 + 2 * lam * np.cos(phi) * cam_mass * G + (cam_mass * G) ** 2), atol=1e-8)


def _cam_at_rest():
    return _example("cam_shaft_modes")


def test_linearizing_a_cam_shaft_with_its_contact_held_gives_the_closed_form_frequency():
    ex = _cam_at_rest()
    model = ex.build(0.0)
    with pytest.raises(SettingsError, match="contact 'cam' is closed"):
        ms.linear.linearize(model)
    lin = ms.linear.linearize(model, contacts="hold")
    assert lin.n == 1
    f = lin.modes().natural_frequency
    # the preload through the cam's curvature h''(0) = H/2 stiffens the shaft by (F0 + m g) H / 2
    np.testing.assert_allclose(f, [ex.OMEGA / (2 * np.pi)], rtol=1e-7)
    assert abs(f[0] - np.sqrt(ex.K_SHAFT / ex.J_CAM) / (2 * np.pi)) > 0.1  # the follower's share is visible
    with pytest.raises(SettingsError, match="contact 'cam' is frictionless, so it cannot roll"):
        ms.linear.linearize(model, contacts="roll")
    # with friction it may roll, but the roller is fixed to its follower: nothing would move
    model._contacts[0].friction = ms.laws.Coulomb(mu=0.5)
    with pytest.raises(ModelError, match="the constraints leave no degree of freedom"):
        ms.linear.linearize(model, contacts="roll")


def test_the_nonlinear_cam_shaft_oscillates_at_the_linearized_frequency():
    ex = _cam_at_rest()
    res = ms.simulate(ex.model, t_end=4 * 2 * np.pi / ex.OMEGA, integrator=ms.EventDriven(), output_dt=1e-4)
    assert res["contact/cam/lambda_n"].min() > 15.0  # stays closed
    # amplitude 0.02 rad: the frequency's amplitude dependence is second order (~1e-5 here)
    np.testing.assert_allclose(1.0 / ex.period(res), ex.OMEGA / (2 * np.pi), rtol=1e-4)


def _touching(a: float, b: float, r: float, s: float) -> np.ndarray:
    """The centre of a disc of radius r touching the inside of the ellipse (a, b) at angle s."""
    p = np.array([a * np.cos(s), b * np.sin(s)])
    n = -np.array([np.cos(s) / a, np.sin(s) / b])
    return p + r * n / np.linalg.norm(n)


def _disc_in_hole(a: float, b: float, r: float, friction=True, x0: float = 0.0, gravity=-G) -> ms.Model:
    """A disc resting at the bottom of an elliptical hole with semi-axes a (x), b (y)."""
    m = ms.Model("disc", gravity=(0.0, gravity, 0.0), planar=True)
    d = m.add_body("disc", 1.0, ms.inertia.cylinder(1.0, r, 0.02, axis="z"))
    m.add_joint(ms.joints.Planar("free", m.ground, d, q0=(x0, -b + r, 0.0)))
    m.add_contact(ms.Contact("hole", d.contour(ms.contours.Circle(radius=r)),
                             m.ground.contour(ms.contours.Ellipse(a=a, b=b, solid="outside")),
                             friction=ms.laws.Coulomb(mu=0.8) if friction else None))
    return m


def test_a_disc_in_an_elliptical_hole_rolls_and_slides_at_the_closed_form_frequencies():
    a, b, r = 1.2, 1.0, 0.1
    rho = a * a / b  # radius of curvature at the bottom of the ellipse
    m = _disc_in_hole(a, b, r)
    roll = ms.linear.linearize(m, contacts="roll").modes().natural_frequency
    np.testing.assert_allclose(roll, [np.sqrt(2 * G / (3 * (rho - r))) / (2 * np.pi)], rtol=1e-8)
    hold = ms.linear.linearize(m, contacts="hold").modes().natural_frequency
    # sliding frictionlessly: the disc's spin is free (a zero frequency), its centre swings on rho - r
    np.testing.assert_allclose(np.sort(hold)[-1], np.sqrt(G / (rho - r)) / (2 * np.pi), rtol=1e-8)
    assert np.sort(hold)[0] < 1e-6


def test_the_held_linearization_finds_the_equilibrium_from_a_point_on_the_contour():
    a, b, r = 1.2, 1.0, 0.1
    # a start beside the bottom, touching: the centre on the offset curve at ellipse angle -pi/2 + 0.1
    c = _touching(a, b, r, -np.pi / 2 + 0.1)
    m = _disc_in_hole(a, b, r)
    lin = ms.linear.linearize(m, q=(c[0], c[1], 0.0), at="equilibrium", contacts="roll")
    np.testing.assert_allclose(lin.q[:2], [0.0, -b + r], atol=1e-9)
    np.testing.assert_allclose(lin.modes().natural_frequency, [np.sqrt(2 * G / (3 * (a * a / b - r))) / (2 * np.pi)],
                               rtol=1e-7)


def test_held_contacts_that_pull_or_slip_are_refused_by_name():
    # gravity upwards: the disc at the bottom would have to be pulled onto the contour
    with pytest.raises(SettingsError, match=r"contact 'hole' does not press at the point \(normal force -9.81"):
        ms.linear.linearize(_disc_in_hole(1.2, 1.0, 0.1, gravity=G), contacts="hold")
    with pytest.raises(SettingsError, match="'hole' is frictionless, so it cannot roll"):
        ms.linear.linearize(_disc_in_hole(1.2, 1.0, 0.1, friction=False), contacts="roll")
    # on an incline with mu = 0.05, rolling needs tan(alpha)/3 = 0.10 of the normal force
    steep = _incline(0.3, False, friction=ms.laws.Coulomb(mu=0.05))
    with pytest.raises(SettingsError, match="contact 'roll' cannot roll at the point: it needs a friction force 1.93"):
        ms.linear.linearize(steep, contacts="roll", operating_point=True)
    with pytest.raises(SettingsError, match="contacts: expected 'refuse', 'hold' or 'roll'"):
        ms.linear.linearize(steep, contacts="stick")


def test_bad_bilateral_contacts_are_refused_naming_the_contact():
    m = _incline(0.3, True)
    m._contacts[0].friction = ms.laws.Coulomb(mu=0.3)
    with pytest.raises(ModelError, match="contact 'roll'.friction: a bilateral contact is held closed"):
        m.build()
    desc = _incline(0.3, True).to_dict()
    desc["contacts"][0]["points"] = 2
    desc["contacts"][0]["contour2"] = {"type": "spline", "points": [[x, 0.1 * x * x] for x in np.linspace(-1, 1, 21)]}
    with pytest.raises(ModelError, match=r"contacts\[0\] 'roll'.points: a bilateral contact holds one contact point"):
        ms.Model.from_dict(desc).build()
    desc = _incline(0.3, True).to_dict()
    desc["contacts"][0]["friction"] = {"type": "coulomb", "mu": 0.3}
    with pytest.raises(ModelError, match=r"contacts\[0\] 'roll'.friction: a bilateral contact takes no friction law"):
        ms.Model.from_dict(desc).build()
    with pytest.raises(ModelError, match="rolling: expected True or False"):
        ms.Contact("c", m.ground.contour(ms.contours.Circle(radius=1.0)), m.ground.contour(ms.contours.Circle(radius=1.0)),
                   normal=ms.laws.Bilateral(rolling="yes")).describe([])


def test_a_bilateral_contact_in_a_model_file_and_the_linear_command(tmp_path):
    path = tmp_path / "roll.toml"
    path.write_text("""
name = "roll"
gravity = [2.899, -9.372, 0.0]
planar = true
[[bodies]]
name = "cyl"
mass = 2.0
inertia = [0.005416667, 0.005416667, 0.01]
[[joints]]
name = "p"
type = "planar"
parent = "ground"
child = "cyl"
q0 = [0.0, 0.1, 0.0]
[[contacts]]
name = "roll"
body1 = "cyl"
contour1 = { type = "circle", radius = 0.1 }
body2 = "ground"
contour2 = { type = "line", normal = [0.0, 1.0, 0.0] }
normal = { type = "bilateral", rolling = true }
[simulation]
t_end = 0.5
""")
    out = tmp_path / "roll.h5"
    run = subprocess.run([sys.executable, "-m", "mechsys", "run", str(path), "--out", str(out), "--quiet"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    res = ms.load(out)
    np.testing.assert_allclose(res["joint/p/q"][-1, 0], 0.5 * (2.0 / 3.0) * 2.899 * 0.25, rtol=1e-8)
    lin = subprocess.run([sys.executable, "-m", "mechsys", "linear", str(EXAMPLES / "cam_shaft_modes.py"), "--contacts",
                          "hold", "--at", "equilibrium", "--out-dir", str(tmp_path)], capture_output=True, text=True)
    assert lin.returncode == 0, lin.stderr
    ex = _example("cam_shaft_modes")
    assert f"{ex.OMEGA / (2 * np.pi):.6g}" in lin.stdout  # the closed form, as the modes table prints it


def test_static_equilibrium_with_contacts_held_gives_the_contact_forces():
    # the disc in the elliptical hole, started beside the bottom: it rolls down to the bottom,
    # where the hole carries its weight (normal force m g, no friction needed)
    a, b, r = 1.2, 1.0, 0.1
    c = _touching(a, b, r, -np.pi / 2 + 0.2)
    m = _disc_in_hole(a, b, r)
    eq = ms.analysis.static_equilibrium(m, q=(c[0], c[1], 0.3), contacts="roll")
    np.testing.assert_allclose(eq["q"][:2], [0.0, -b + r], atol=1e-9)
    np.testing.assert_allclose(eq["lambda"]["hole"], [G, 0.0], atol=1e-9)
    # without the contacts held the disc has no equilibrium at all (it would fall)
    with pytest.raises(ms.errors.SolverError):
        ms.analysis.static_equilibrium(m, q=(c[0], c[1], 0.3))
    # gravity pointing up: the disc would have to be pulled onto the hole
    up = _disc_in_hole(a, b, r, gravity=G)
    with pytest.raises(ms.errors.SolverError, match="contact 'hole' would have to pull"):
        ms.analysis.static_equilibrium(up, q=(0.0, -b + r, 0.0), contacts="hold")
