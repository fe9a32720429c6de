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
