"""Path coordinates (issue 14, part 4, first piece): a point moving along a helix with its arc
length as the coordinate. Checked against closed forms: on a helix about the vertical the weight's
tangential part is constant, so s'' = -m g (c/L) / m_eff (m_eff = m, or m + w.I.w for a body turning
with the trihedral, w = (tau, 0, kappa)); the path's force is m (s'' t + kappa s'^2 n) - m g (the
Frenet-frame equations); a bead on a vertical circle is a pendulum of length R."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

ROOT = Path(__file__).resolve().parents[1]
R, PITCH, M, G, V0 = 0.3, 0.2, 0.5, 9.81, 2.0
C = PITCH / (2 * np.pi)
L = np.hypot(R, C)
INERTIA = np.diag([0.02, 0.035, 0.05])


def bead(oriented: bool) -> tuple[ms.Model, ms.joints.Path]:
    m = ms.Model("bead", gravity=(0, 0, -G))
    b = m.add_body("bead", M, INERTIA)
    j = ms.joints.Path("wire", m.ground, b, radius=R, pitch=PITCH, oriented=oriented, u0=V0)
    m.add_joint(j)
    return m, j


def frenet(s):
    phi = s / L
    t = np.c_[-R * np.sin(phi), R * np.cos(phi), np.full_like(phi, C)] / L
    n = np.c_[-np.cos(phi), -np.sin(phi), np.zeros_like(phi)]
    b = np.c_[C * np.sin(phi), -C * np.cos(phi), np.full_like(phi, R)] / L
    return t, n, b


@pytest.mark.parametrize("oriented", [False, True])
def test_motion_on_a_helix_under_gravity_is_the_closed_form(oriented):
    m, j = bead(oriented)
    assert np.isclose(j.curvature(), R / L**2) and np.isclose(j.torsion(), C / L**2)
    res = ms.simulate(m, 2.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01)
    w = np.array([j.torsion(), 0.0, j.curvature()])
    m_eff = M + (w @ INERTIA @ w if oriented else 0.0)
    a = -M * G * (C / L) / m_eff
    t = res.t
    s = V0 * t + 0.5 * a * t**2
    assert np.abs(res["joint/wire/q"] - s).max() < 1e-12
    assert np.ptp(res["energy/total"]) < 1e-12
    tt, n, bb = frenet(res["joint/wire/q"])
    phi = res["joint/wire/q"] / L
    assert np.abs(res["body/bead/position"] - np.c_[R * np.cos(phi), R * np.sin(phi), C * phi]).max() < 1e-12
    sd = res["joint/wire/u"]
    om = res["body/bead/angular_velocity"]
    if oriented:
        # the body turns with the trihedral: omega = (tau t + kappa b) s'
        assert np.abs(om - (j.torsion() * tt + j.curvature() * bb) * sd[:, None]).max() < 1e-12
    else:
        assert np.abs(om).max() == 0.0
        # the wire's force on the bead: m (s'' t + kappa s'^2 n) - m g (world axes: the joint
        # frames are the world's)
        f = M * (a * tt + j.curvature() * sd[:, None] ** 2 * n) - M * np.array([0.0, 0.0, -G])
        assert np.abs(res["joint/wire/reaction_force"] - f).max() < 1e-9
        # no force along the path: it is frictionless
        assert np.abs(np.einsum("ij,ij->i", res["joint/wire/reaction_force"], tt)).max() < 1e-9


def test_a_bead_on_a_vertical_circle_is_a_pendulum_of_its_radius():
    m = ms.Model("ring", gravity=(0, -G, 0))
    b = m.add_body("bead", M, np.zeros((3, 3)))
    m.add_joint(ms.joints.Path("ring", m.ground, b, radius=R, oriented=False, q0=-np.pi / 2 * R))
    lin = ms.linear.linearize(m)
    f = lin.modes().natural_frequency
    assert f.shape == (1,) and abs(f[0] - np.sqrt(G / R) / (2 * np.pi)) < 1e-9 * f[0]
    # and the exact linearization equals the finite-difference one
    fd = ms.linear.linearize(m, method="fd").modes().natural_frequency
    assert abs(fd[0] - f[0]) < 1e-6 * f[0]


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(radius=0.0), "radius: must be > 0"),
    (dict(radius=-1.0), "radius: must be > 0"),
    (dict(radius=0.2, pitch=float("nan")), r"pitch: must be a finite number"),
    (dict(radius="big"), "radius: expected a number"),
    (dict(radius=0.2, oriented="yes"), "oriented: expected true or false"),
])
def test_bad_path_joints_are_named(kwargs, fragment):
    m = ms.Model("bad")
    b = m.add_body("b", 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Path("wire", m.ground, b, **kwargs))
    with pytest.raises(ms.ModelError, match=rf"(wire|joints\[0\]).*{fragment}"):
        m.build()


def test_path_keys_on_another_joint_and_a_toml_path_joint(tmp_path):
    f = tmp_path / "bead.toml"
    f.write_text(f"""
name = "bead"
gravity = [0.0, 0.0, -9.81]
[[bodies]]
name = "bead"
mass = {M}
inertia = [0.02, 0.035, 0.05]
[[joints]]
type = "path"
name = "wire"
parent = "ground"
child = "bead"
radius = {R}
pitch = {PITCH}
oriented = false
u0 = {V0}
[simulation]
t_end = 1.0
integrator = {{ type = "dopri5", rtol = 1e-11, atol = 1e-12 }}
output_dt = 0.01
""")
    out = tmp_path / "r.h5"
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(f), "--out", str(out), "-q"], capture_output=True, text=True,
                       cwd=ROOT)
    assert p.returncode == 0, p.stderr
    res = ms.Results.load(out)
    a = -G * C / L
    assert abs(res["joint/wire/q"][-1] - (V0 + 0.5 * a)) < 1e-10
    assert res.columns("q") == ["wire.s"] and res.unit("joint/wire/q") == "m"
    f.write_text(f.read_text().replace('type = "path"', 'type = "revolute"'))
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(f), "--out", str(out)], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode != 0 and "radius: only a path joint has a radius" in p.stderr


def test_tangential_and_normal_accelerations_are_signals():
    m, j = bead(False)
    res = ms.simulate(m, 1.0, ms.RK4(dt=1e-3), output_dt=1e-2)
    a = -G * C / L
    assert np.abs(res["joint/wire/tangential_acceleration"] - a).max() < 1e-12
    sd = V0 + a * res.t
    assert np.abs(res["joint/wire/normal_acceleration"] - j.curvature() * sd**2).max() < 1e-9
    assert res.unit("joint/wire/normal_acceleration") == "m/s^2"
    # they are the body's acceleration split along t and n
    tt, n, _ = frenet(res["joint/wire/q"])
    acc = res["body/bead/acceleration"]
    assert np.abs(np.einsum("ij,ij->i", acc, n) - res["joint/wire/normal_acceleration"]).max() < 1e-9


def test_a_trajectory_prescribed_along_the_path_and_its_forces():
    """s(t) = v t on a horizontal circle without gravity: no drive force along the path, the
    path's force m v^2 / R towards the centre."""
    v = 1.5
    m = ms.Model("carousel")
    b = m.add_body("car", M, np.zeros((3, 3)))
    m.add_joint(ms.joints.Path("track", m.ground, b, radius=R, oriented=False))
    m.add_constraint(ms.constraints.Prescribed("drive", "track", ms.functions.Ramp(slope=v)))
    res = ms.simulate(m, 1.0, ms.RK4(dt=1e-3), output_dt=1e-2)
    assert np.abs(res["joint/track/q"] - v * res.t).max() < 1e-12
    assert np.abs(res["constraint/drive/lambda"]).max() < 1e-9
    f = res["joint/track/reaction_force"]
    assert np.abs(np.linalg.norm(f, axis=1) - M * v**2 / R).max() < 1e-9
    pos = res["body/car/position"]
    assert np.abs(np.einsum("ij,ij->i", f, pos) / R + M * v**2 / R).max() < 1e-9  # towards the centre
    assert np.abs(res["joint/track/normal_acceleration"] - v**2 / R).max() < 1e-9


# ---- curves beyond the helix (issue 14, part 4) ----------------------------------------------------

SQPI = np.sqrt(np.pi)


def clothoid_reference(s, a, kappa0):
    """x + i y of the clothoid from scipy's Fresnel integrals, completing the square:
    theta = (pi/2) w^2 - theta0, w = (s + kappa0 A^2) / (A sqrt(pi))."""
    from scipy.special import fresnel

    w0, w1 = kappa0 * a / SQPI, (s + kappa0 * a * a) / (a * SQPI)
    s0, c0 = fresnel(w0)
    s1, c1 = fresnel(w1)
    th0 = 0.5 * kappa0**2 * a * a
    z = a * SQPI * np.exp(-1j * th0) * ((c1 - c0) + 1j * (s1 - s0))
    return np.c_[z.real, z.imag]


def test_clothoid_curvature_is_linear_in_s_and_its_position_the_scaled_fresnel_integrals():
    a = 1.5
    s = np.linspace(-6.0, 12.0, 181)
    j = ms.joints.Path.clothoid("track", "ground", "car", A=a)
    g = j.geometry(s)
    assert np.abs(g["curvature"] - s / a**2).max() < 1e-14
    assert np.abs(g["torsion"]).max() == 0.0 and np.abs(g["position"][:, 2]).max() == 0.0
    # kappa0 = 0: x = A sqrt(pi) C(s / (A sqrt(pi))), y = A sqrt(pi) S(...)
    ref = clothoid_reference(s, a, 0.0)
    assert np.abs(g["position"][:, :2] - ref).max() < 1e-12 * a
    # with an initial curvature (scipy's values differ by a subtraction, accurate where the
    # arc turns enough: away from s = 0)
    j = ms.joints.Path.clothoid("track", "ground", "car", A=a, kappa0=0.4)
    s = np.linspace(0.5, 10.0, 96)
    g = j.geometry(s)
    assert np.abs(g["curvature"] - (0.4 + s / a**2)).max() < 1e-14
    ref = clothoid_reference(s, a, 0.4)
    assert (np.linalg.norm(g["position"][:, :2] - ref, axis=1) / np.linalg.norm(ref, axis=1)).max() < 1e-12
    # the tangent angle is theta = kappa0 s + s^2 / (2 A^2), the frame [t, z x t, z]
    th = 0.4 * s + s**2 / (2 * a * a)
    t = np.c_[np.cos(th), np.sin(th), 0 * s]
    assert np.abs(g["frame"][:, :, 0] - t).max() < 1e-13
    assert np.abs(g["frame"][:, :, 1] - np.cross([0, 0, 1], t)).max() < 1e-13
    assert np.abs(g["frame"][:, :, 2] - [0, 0, 1]).max() == 0.0


def test_at_zero_curvature_the_clothoid_frame_is_the_left_normal_and_the_curvature_changes_sign():
    # kappa0 = -1: kappa = 0 at s = A^2; the Frenet normal would flip there, n = z x t does not
    a = 1.2
    j = ms.joints.Path.clothoid("track", "ground", "car", A=a, kappa0=-1.0)
    s0 = a * a
    s = s0 + np.array([-1e-3, -1e-8, 0.0, 1e-8, 1e-3])
    g = j.geometry(s)
    assert np.all(np.diff(np.sign(g["curvature"])) >= 0) and g["curvature"][0] < 0 < g["curvature"][-1]
    assert abs(g["curvature"][2]) < 1e-15
    n = g["frame"][:, :, 1]
    assert np.abs(n - np.cross([0, 0, 1], g["frame"][:, :, 0])).max() < 1e-15
    assert np.abs(np.diff(n, axis=0)).max() < 2e-3  # continuous through kappa = 0
    # and t' = kappa n on either side (the signed curvature)
    assert np.abs(g["tangent_rate"] - g["curvature"][:, None] * n).max() < 1e-14
    # a body turning with the frame spins about z at kappa s', through the sign change
    m = ms.Model("spin", gravity=(0, 0, 0))
    b = m.add_body("car", M, INERTIA)
    m.add_joint(ms.joints.Path.clothoid("track", m.ground, b, A=a, kappa0=-1.0, u0=1.0))
    res = ms.simulate(m, 3.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.05)
    q, qd = res["joint/track/q"], res["joint/track/u"]
    assert q[0] < s0 < q[-1]
    om = res["body/car/angular_velocity"]
    assert np.abs(om - np.c_[0 * q, 0 * q, (-1.0 + q / a**2) * qd]).max() < 1e-10
    assert np.ptp(res["energy/total"]) < 1e-10


def helix_points(per_turn, turns, r, c):
    phi = 2 * np.pi * np.arange(int(round(per_turn * turns)) + 1) / per_turn
    return np.c_[r * np.cos(phi), r * np.sin(phi), c * phi]


def test_a_helix_as_a_spline_has_the_helix_curvature_and_torsion():
    # kappa = R / (R^2 + c^2), tau = c / (R^2 + c^2); the cubic through 32 points per turn
    # approximates both to 4e-3 and 8e-3 (second order in the spacing), over the middle turn
    # of three (the natural ends bend the spline away from the helix near its ends)
    r, c = 0.5, 0.1
    l2 = r * r + c * c
    j = ms.joints.Path.spline("wire", "ground", "bead", helix_points(32, 3.0, r, c), up=(0, 0, 1))
    lh = 2 * np.pi * np.sqrt(l2)
    s = lh * (1 + np.linspace(0, 1, 301))
    g = j.geometry(s)
    assert np.abs(g["curvature"] / (r / l2) - 1).max() < 4e-3
    assert np.abs(g["torsion"] / (c / l2) - 1).max() < 8e-3
    # the same with the built-in helix: position, and the frame (Frenet's, since up is the axis)
    h = ms.joints.Path("wire", "ground", "bead", radius=r, pitch=2 * np.pi * c).geometry(s)
    assert np.abs(g["position"] - h["position"]).max() < 1e-4
    assert np.abs(g["frame"] - h["frame"]).max() < 4e-4


def helix_function(r, c):
    return lambda p: (r * np.cos(p), r * np.sin(p), c * p)


@pytest.mark.parametrize("how", ["taylor", "user", "complex step", "differences"])
def test_a_helix_given_as_a_function_is_the_builtin_helix(how):
    """The function path r(phi) of a helix (phi is not the arc length), sampled at 64 points
    per turn: positions and curvature to 1e-7 of the built-in helix, whichever way its
    derivatives come."""
    import math

    r, c = 0.5, 0.1
    l2 = r * r + c * c
    kw = {}
    f = helix_function(r, c)
    if how == "user":
        kw = dict(df=lambda p: (-r * np.sin(p), r * np.cos(p), c), d2f=lambda p: (-r * np.cos(p), -r * np.sin(p), 0.0))
    elif how == "complex step":
        f = lambda p: np.array([r * np.cos(p), r * np.sin(p), c * p], dtype=complex if isinstance(p, complex) else float)  # noqa: E731
    elif how == "differences":
        f = lambda p: (r * math.cos(p), r * math.sin(p), c * p)  # noqa: E731
    j = ms.joints.Path.function("wire", "ground", "bead", f, (0.0, 4 * np.pi), samples=129, **kw)
    assert j.derivatives_by == how
    # the sampling error measured at the interval midpoints, under the bound h^6 R / 46080
    h = 4 * np.pi / 128
    assert 0 < j.sampling_error < h**6 * r / 46080 * 1.01
    s = np.linspace(0, 2 * 2 * np.pi * np.sqrt(l2) - 1e-6, 401)
    g = j.geometry(s)
    ref = ms.joints.Path("wire", "ground", "bead", radius=r, pitch=2 * np.pi * c).geometry(s)
    assert np.abs(g["position"] - ref["position"]).max() < 1e-7
    assert np.abs(g["curvature"] - r / l2).max() < 1e-7 * (r / l2)
    assert np.abs(g["torsion"] - c / l2).max() < 1e-5 * (c / l2)


def bead_on(joint_factory, gravity=(0, -G, 0), oriented=False, inertia=None):
    m = ms.Model("bead", gravity=gravity)
    b = m.add_body("bead", M, np.zeros((3, 3)) if inertia is None else inertia)
    j = m.add_joint(joint_factory(m, b, oriented))
    return m, j


def wire_force_against_frenet(res, j, gravity):
    """The wire's force on the bead against m (s'' t + kappa s'^2 n) - m g, with t and kappa n
    from the engine's geometry; returns the largest error and the force itself."""
    s, sd, sdd = res["joint/wire/q"], res["joint/wire/u"], res["joint/wire/udot"]
    g = j.geometry(s)
    t, kn = g["frame"][:, :, 0], g["tangent_rate"]
    f = M * (sdd[:, None] * t + sd[:, None] ** 2 * kn) - M * np.asarray(gravity)
    return np.abs(res["joint/wire/reaction_force"] - f).max(), f, t


def test_a_bead_on_a_clothoid_under_gravity_keeps_its_energy_and_the_wire_force_is_the_frenet_one():
    # the clothoid in a vertical plane (gravity -y), the bead sliding down from its curled end
    a, k0 = 1.0, 0.0
    gravity = (0.0, -G, 0.0)
    m, j = bead_on(lambda m, b, o: ms.joints.Path.clothoid("wire", m.ground, b, A=a, kappa0=k0, oriented=o, q0=2.0),
                   gravity)
    res = ms.simulate(m, 2.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01)
    # it swings through the origin deep into the other curl (s to -7.5, kappa -7.5 1/m); the
    # energy drifts by the integrator's error only: ten times less for a ten times tighter rtol
    drift = np.ptp(res["energy/total"])
    assert drift < 1e-9 * res["energy/kinetic"].max()
    loose = ms.simulate(m, 2.0, ms.DOPRI5(rtol=1e-10, atol=1e-11), output_dt=0.01)
    assert np.ptp(loose["energy/total"]) > 5 * drift
    err, f, t = wire_force_against_frenet(res, j, gravity)
    assert err < 1e-8
    # independently of the engine's geometry: theta = s^2 / (2 A^2), t = (cos, sin), kappa = s / A^2,
    # n = (-sin, cos); tangential: s'' = g . t; normal: f . n = m kappa s'^2 - m g . n
    s, sd, sdd = res["joint/wire/q"], res["joint/wire/u"], res["joint/wire/udot"]
    th = s**2 / (2 * a * a)
    tt, nn = np.c_[np.cos(th), np.sin(th), 0 * s], np.c_[-np.sin(th), np.cos(th), 0 * s]
    assert np.abs(sdd - tt @ np.array(gravity)).max() < 1e-9
    fr = res["joint/wire/reaction_force"]
    for k in (0, 50, 120, 200):
        assert abs(fr[k] @ nn[k] - (M * s[k] / a**2 * sd[k] ** 2 - M * nn[k] @ np.array(gravity))) < 1e-9
        assert abs(fr[k] @ tt[k]) < 1e-9  # frictionless


def loop_points():
    """A closed 3-D track: a tilted, wobbling loop."""
    phi = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    return np.c_[1.5 * np.cos(phi), 0.8 * np.sin(phi) + 0.3 * np.sin(2 * phi), 0.6 * np.sin(phi) + 0.2 * np.cos(3 * phi)]


@pytest.mark.parametrize("oriented", [False, True])
def test_a_bead_on_a_closed_space_spline_keeps_its_energy(oriented):
    gravity = (0.0, 0.0, -G)
    m, j = bead_on(lambda m, b, o: ms.joints.Path.spline("wire", m.ground, b, loop_points(), closed=True, oriented=o, u0=4.0),
                   gravity, oriented, INERTIA if oriented else None)
    info = m.joint_info()[0]
    assert info["curve"] == "spline" and info["closed"] and info["length"] > 6
    res = ms.simulate(m, 3.0, ms.DOPRI5(rtol=1e-12, atol=1e-13), output_dt=0.01)
    assert res["joint/wire/q"][-1] > info["length"]  # round the loop and on
    # the energy drifts by the integrator's error (measured 1.7e-10 and 1.1e-9 of the largest
    # kinetic energy; ten times more at rtol = 1e-11: the third derivative of the cubic jumps at
    # the knots)
    assert np.ptp(res["energy/total"]) < 2e-9 * res["energy/kinetic"].max()
    g = j.geometry(res["joint/wire/q"])
    assert np.abs(res["body/bead/position"] - g["position"]).max() < 1e-12
    if oriented:
        # the body turns with the frame: omega = F Omega s'
        om = np.einsum("kij,kj->ki", g["frame"], g["omega"]) * res["joint/wire/u"][:, None]
        assert np.abs(res["body/bead/angular_velocity"] - om).max() < 1e-10
    else:
        err, _, t = wire_force_against_frenet(res, j, gravity)
        assert err < 1e-8
        assert np.abs(np.einsum("ij,ij->i", res["joint/wire/reaction_force"], t)).max() < 1e-8
        # the normal acceleration signal is kappa s'^2 with the curvature at each sample
        assert np.abs(res["joint/wire/normal_acceleration"] - g["curvature"] * res["joint/wire/u"] ** 2).max() < 1e-12


def test_beyond_the_end_of_an_open_spline_the_path_goes_straight_on():
    # a short descending ramp: the bead leaves its end and carries on along the end tangent
    pts = [(0, 1.0, 0), (1.0, 0.4, 0), (2.0, 0.0, 0), (3.0, -0.1, 0)]
    m, j = bead_on(lambda m, b, o: ms.joints.Path.spline("wire", m.ground, b, pts, oriented=o, u0=1.0))
    res = ms.simulate(m, 3.0, ms.DOPRI5(rtol=1e-12, atol=1e-13), output_dt=0.01)
    length = m.joint_info()[0]["length"]
    s = res["joint/wire/q"]
    assert s[-1] > length + 1.0 and np.all(np.isfinite(res["body/bead/position"]))
    end = j.geometry([length])
    r_end, t_end = end["position"][0], end["frame"][0, :, 0]
    beyond = s > length
    assert np.abs(res["body/bead/position"][beyond] - (r_end + (s[beyond] - length)[:, None] * t_end)).max() < 1e-12
    assert np.ptp(res["energy/total"]) < 1e-9 * res["energy/kinetic"].max()
    # and before the start
    g = j.geometry([-0.5])
    start = j.geometry([0.0])
    assert np.abs(g["position"][0] - (start["position"][0] - 0.5 * start["frame"][0, :, 0])).max() < 1e-14


def test_small_oscillations_at_the_bottom_of_a_clothoid_and_of_a_spline_loop():
    # at the bottom of a curve (tangent horizontal) a bead oscillates at omega^2 = g kappa
    k0 = 2.0
    m, _ = bead_on(lambda m, b, o: ms.joints.Path.clothoid("wire", m.ground, b, A=0.8, kappa0=k0, oriented=o))
    f = ms.linear.linearize(m, method="exact").modes().natural_frequency
    assert abs(f[0] - np.sqrt(G * k0) / (2 * np.pi)) < 1e-9 * f[0]
    fd = ms.linear.linearize(m, method="fd").modes().natural_frequency
    assert abs(fd[0] - f[0]) < 1e-6 * f[0]
    # a vertical circle of radius R as a closed spline through 128 points from its bottom:
    # omega^2 = g / R up to the spline's curvature error at its knots, O(h^2)
    R_ = 0.4
    phi = -np.pi / 2 + 2 * np.pi * np.arange(128) / 128
    pts = np.c_[R_ * np.cos(phi), R_ * np.sin(phi), 0 * phi]
    m, _ = bead_on(lambda m, b, o: ms.joints.Path.spline("wire", m.ground, b, pts, closed=True, oriented=o))
    f = ms.linear.linearize(m, method="exact").modes().natural_frequency
    # (measured 1.0e-4; with 64 points 4.0e-4)
    assert abs(f[0] / (np.sqrt(G / R_) / (2 * np.pi)) - 1) < 1.5e-4
    fd = ms.linear.linearize(m, method="fd").modes().natural_frequency
    assert abs(fd[0] - f[0]) < 1e-6 * f[0]


def test_the_exact_linearization_of_a_moving_oriented_body_on_a_spline_matches_differences():
    # a body turning with the up-vector frame of a space curve, moving: the bias Omega' s'^2
    # and the frame's derivatives by dual numbers against central differences
    m, _ = bead_on(lambda m, b, o: ms.joints.Path.spline("wire", m.ground, b, loop_points(), closed=True, oriented=o,
                                                       q0=1.3, u0=2.0), (0, 0, -G), True, INERTIA)
    ex = ms.linear.linearize(m, method="exact", operating_point=True)
    fd = ms.linear.linearize(m, method="fd", operating_point=True)
    assert ex.method == "exact" and fd.method == "fd"
    assert np.abs(ex.A - fd.A).max() < 1e-6 * np.abs(ex.A).max()


@pytest.mark.parametrize("factory, fragment", [
    (lambda m, b: ms.joints.Path.spline("wire", m.ground, b, [(0, 0, 0)]), r"points: an open spline needs at least 2 points, got 1"),
    (lambda m, b: ms.joints.Path.spline("wire", m.ground, b, [(0, 0, 0), (1, 0, 0)], closed=True),
     r"points: a closed spline needs at least 3 points, got 2"),
    (lambda m, b: ms.joints.Path.spline("wire", m.ground, b, [(0, 0, 0), (1, 0, 0), (1, 0, 0), (2, 1, 0)]),
     r"points\[2\]: repeats points\[1\] \(a zero-length segment\)"),
    (lambda m, b: ms.joints.Path.spline("wire", m.ground, b, [(0, 0, 0), (1, float("nan"), 0)]), r"points\[1\]: must be finite"),
    (lambda m, b: ms.joints.Path.spline("wire", m.ground, b, [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 0, 0)], closed=True),
     r"points\[3\]: repeats points\[0\]; a closed spline joins its last point to its first by itself"),
    (lambda m, b: ms.joints.Path.spline("wire", m.ground, b, [(0, 0, 0), (0, 0, 1), (0, 0, 2)], up=(0, 0, 1)),
     r"up: the path runs within 0.00° of the frame's reference direction"),
    (lambda m, b: ms.joints.Path.spline("wire", m.ground, b, [[0, 0], [1]]), r"points: expected a list of \(x, y, z\) points"),
    (lambda m, b: ms.joints.Path.clothoid("wire", m.ground, b, A=0.0), r"A: must be > 0, got 0"),
    (lambda m, b: ms.joints.Path.clothoid("wire", m.ground, b, A=1.0, kappa0=float("inf")), r"kappa0: must be a finite number, got inf"),
    (lambda m, b: ms.joints.Path("wire", m.ground, b, curve="bezier"), r"curve: unknown path curve 'bezier'"),
    (lambda m, b: ms.joints.Path.function("wire", m.ground, b, lambda p: (p, 0, 0), (1.0, 0.0)),
     r"p_range: expected finite p_start < p_end"),
    (lambda m, b: ms.joints.Path.function("wire", m.ground, b, lambda p: (p, 0), (0.0, 1.0), samples=1),
     r"samples: expected an integer >= 2"),
    (lambda m, b: ms.joints.Path.function("wire", m.ground, b, lambda p: (p**2, p**3, 0), (-1.0, 1.0), samples=20),
     r"the curve's parameterization is singular between parameters"),
])
def test_bad_curves_are_named(factory, fragment):
    m = ms.Model("bad")
    b = m.add_body("b", 1.0, [1, 1, 1])
    m.add_joint(factory(m, b))
    with pytest.raises(ms.ModelError, match=rf"(joint 'wire'|joints\[0\] 'wire').*{fragment}"):
        m.build()


def test_path_curves_in_a_toml_model_file(tmp_path):
    from mechsys.modelfile import load_model

    head = f"""
name = "track"
gravity = [0.0, -9.81, 0.0]
[[bodies]]
name = "car"
mass = {M}
inertia = [0.0, 0.0, 0.0]
[[joints]]
type = "path"
name = "wire"
parent = "ground"
child = "car"
oriented = false
"""
    f = tmp_path / "track.toml"
    f.write_text(head + 'curve = "clothoid"\nA = 1.5\nkappa0 = 0.2\n')
    model, _ = load_model(f)
    info = model.joint_info()[0]
    assert info["curve"] == "clothoid" and abs(info["curvature"] - 0.2) < 1e-15
    f.write_text(head + 'curve = "spline"\npoints = [[0, 0, 0], [1, 0.5, 0], [2, 0, 0], [3, 1, 0]]\nq0 = 0.5\n')
    model, _ = load_model(f)
    info = model.joint_info()[0]
    assert info["curve"] == "spline" and not info["closed"] and info["length"] > 3
    res = ms.simulate(model, 0.5, ms.DOPRI5(rtol=1e-12, atol=1e-13), output_dt=0.05)
    assert np.ptp(res["energy/total"]) < 1e-9 * res["energy/kinetic"].max()
    # a key of another curve is named
    f.write_text(head + 'curve = "spline"\npoints = [[0, 0, 0], [1, 0, 0]]\nradius = 2.0\n')
    with pytest.raises(ms.ModelError, match=r"wire'\.radius: a spline path has no radius \(its keys: points, closed, up\)"):
        load_model(f)[0].build()
    f.write_text(head + 'curve = "clothoid"\n')
    with pytest.raises(ms.ModelError, match=r"wire'\.A: a clothoid needs its parameter A"):
        load_model(f)[0].build()


def tilde(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


@pytest.mark.parametrize("kind", ["helix", "clothoid", "spline", "closed space spline", "function"])
def test_frenet_serret_by_differences_for_every_curve(kind):
    """dr/ds = t, d[t n b]/ds = [t n b] Omega~ (Omega = (tau, 0, kappa) for Frenet's trihedral),
    and with the reported curvature and torsion dt/ds = kappa n_F, dn_F/ds = -kappa t + tau b_F,
    db_F/ds = -tau n_F (eq. 2.75), by central differences of the engine's geometry."""
    j = {
        "helix": lambda: ms.joints.Path("w", "ground", "b", radius=R, pitch=PITCH),
        "clothoid": lambda: ms.joints.Path.clothoid("w", "ground", "b", A=1.3, kappa0=-0.6),
        "spline": lambda: ms.joints.Path.spline("w", "ground", "b", [(0, 0, 0), (1, 0.6, 0), (2, 0, 0), (3, -0.8, 0)]),
        "closed space spline": lambda: ms.joints.Path.spline("w", "ground", "b", loop_points(), closed=True),
        "function": lambda: ms.joints.Path.function("w", "ground", "b", lambda p: (np.cos(p), np.sin(2 * p), 0.3 * p**2),
                                                    (0.0, 3.0), samples=101),
    }[kind]()
    s = np.array([0.23, 0.71, 1.37, 2.06])
    e = 1e-5
    g, gp, gm = j.geometry(s), j.geometry(s + e), j.geometry(s - e)
    f = g["frame"]
    assert np.abs(np.einsum("kji,kjl->kil", f, f) - np.eye(3)).max() < 1e-13
    assert np.abs((gp["position"] - gm["position"]) / (2 * e) - f[:, :, 0]).max() < 1e-9
    df = (gp["frame"] - gm["frame"]) / (2 * e)
    assert np.abs(df - np.array([fk @ tilde(w) for fk, w in zip(f, g["omega"])])).max() < 1e-7
    k, tau = g["curvature"], g["torsion"]
    assert np.abs(df[:, :, 0] - g["tangent_rate"]).max() < 1e-7
    assert np.abs(np.linalg.norm(g["tangent_rate"], axis=1) - np.abs(k)).max() < 1e-12

    def frenet(q):
        n = q["tangent_rate"] / np.linalg.norm(q["tangent_rate"], axis=1)[:, None]
        return n, np.cross(q["frame"][:, :, 0], n)

    (n, b), (n_p, b_p), (n_m, b_m) = frenet(g), frenet(gp), frenet(gm)
    t = f[:, :, 0]
    assert np.abs((n_p - n_m) / (2 * e) - (-np.abs(k)[:, None] * t + tau[:, None] * b)).max() < 1e-6
    assert np.abs((b_p - b_m) / (2 * e) + tau[:, None] * n).max() < 1e-6
