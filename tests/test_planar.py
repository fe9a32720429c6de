"""Planar models (issue 13): every body in the world x-y plane, loop closures with their in-plane
equations only. Each mechanism is built twice, planar and spatial: the planar one has no
redundant equations, the spatial one does, and both must move identically (same integrator,
same steps). Conservation laws and closed forms check what the two could share."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import ModelError

ROOT = Path(__file__).resolve().parents[1]
R, L = 0.1, 0.35


def run(model, t_end=0.5, integrator=None, output_dt=1e-2):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ms.simulate(model, t_end, integrator or ms.RK4(dt=1e-4), output_dt=output_dt)


def slider_crank(planar: bool) -> ms.Model:
    m = ms.Model("slider-crank", gravity=(0.0, -9.81, 0.0), planar=planar)
    crank = m.add_body("crank", 0.5, ms.inertia.cylinder(0.5, 0.01, R), com=(R / 2, 0, 0))
    rod = m.add_body("rod", 0.8, ms.inertia.cylinder(0.8, 0.01, L), com=(L / 2, 0, 0))
    slider = m.add_body("slider", 1.2, ms.inertia.box(1.2, (0.05, 0.05, 0.05)))
    m.add_joint(ms.joints.Revolute("crank_pin", m.ground, crank, axis=(0, 0, 1), u0=6.0))
    m.add_joint(ms.joints.Revolute("crank_rod", crank, rod, axis=(0, 0, 1), parent_frame=ms.Frame(position=(R, 0, 0))))
    m.add_joint(ms.joints.Prismatic("guide", m.ground, slider, axis=(1, 0, 0), q0=R + L))
    m.add_constraint(ms.constraints.Point("wrist", body1=rod, point1=(L, 0, 0), body2=slider))
    return m


def four_bar(planar: bool) -> ms.Model:
    """Crank a = 0.1, coupler b = 0.3, rocker c = 0.2 from ground pivots 0.25 apart, closed by a
    revolute loop joint between coupler and rocker tips (frames with z along the hinge)."""
    a, b, c, d = 0.1, 0.3, 0.2, 0.25
    th = 1.0
    # the coupler and rocker angles that close the loop at crank angle th
    px, py = a * np.cos(th), a * np.sin(th)
    dx, dy = d - px, -py
    e = np.hypot(dx, dy)
    gam = np.arccos((b * b + e * e - c * c) / (2 * b * e))
    phi_b = np.arctan2(dy, dx) + gam
    qx, qy = px + b * np.cos(phi_b), py + b * np.sin(phi_b)
    phi_c = np.arctan2(qy, qx - d)
    m = ms.Model("four-bar", gravity=(0.0, -9.81, 0.0), planar=planar)
    crank = m.add_body("crank", 0.3, ms.inertia.rod(0.3, a), com=(a / 2, 0, 0))
    coupler = m.add_body("coupler", 0.6, ms.inertia.rod(0.6, b), com=(b / 2, 0, 0))
    rocker = m.add_body("rocker", 0.4, ms.inertia.rod(0.4, c), com=(c / 2, 0, 0))
    m.add_joint(ms.joints.Revolute("crank", m.ground, crank, q0=th, u0=8.0))
    m.add_joint(ms.joints.Revolute("a", crank, coupler, parent_frame=(a, 0, 0), q0=phi_b - th))
    m.add_joint(ms.joints.Revolute("rocker", m.ground, rocker, parent_frame=(d, 0, 0), q0=phi_c))
    m.add_constraint(ms.constraints.LoopRevolute("pin", body1=coupler, frame1=(b, 0, 0), body2=rocker, frame2=(c, 0, 0)))
    return m


def rod_and_slider(planar: bool) -> ms.Model:
    """A free rod turning about a ground pivot and a slider (a planar joint: x, y, angle) kept on
    the rod by a prismatic loop joint whose sliding axis (frame-2 z) is the rod's x-axis: no
    gravity, so the angular momentum about the pivot and the energy are conserved."""
    m = ms.Model("rod-slider", planar=planar)
    rod = m.add_body("rod", 1.0, ms.inertia.rod(1.0, 1.0), com=(0.5, 0, 0))
    slider = m.add_body("slider", 0.5, ms.inertia.box(0.5, (0.05, 0.05, 0.05)))
    m.add_joint(ms.joints.Revolute("pivot", m.ground, rod, u0=2.0))
    m.add_joint(ms.joints.Planar("free", m.ground, slider, q0=[0.3, 0.0, 0.0], u0=[0.2, 0.6, 2.0]))
    along_rod = ms.Frame(cardan=(0.0, np.pi / 2, 0.0))  # frame z = rod x
    m.add_constraint(ms.constraints.LoopPrismatic("sleeve", body1=slider, frame1=ms.Frame(cardan=(0.0, np.pi / 2, 0.0)),
                                                  body2=rod, frame2=along_rod))
    return m


def angular_momentum_z(res, model) -> np.ndarray:
    return res["momentum/angular"][:, 2]


def test_planar_slider_crank_matches_its_spatial_model_without_redundant_rows():
    mob3, mob2 = ms.mechanisms.mobility(slider_crank(False)), ms.mechanisms.mobility(slider_crank(True))
    assert mob3["redundant"] == [("wrist", 2)] and mob3["nc"] == 3
    assert mob2["redundant"] == [] and mob2["nc"] == 2 and mob2["dof"] == 1
    r3, r2 = run(slider_crank(False)), run(slider_crank(True))
    for name in ("joint/crank_pin/q", "joint/guide/q", "joint/crank_rod/u"):
        assert np.abs(r2[name] - r3[name]).max() < 1e-10, name
    lam2, lam3 = r2["constraint/wrist/lambda"], r3["constraint/wrist/lambda"]
    assert lam2.shape[1] == 2 and r2.columns("constraint/wrist/lambda") == ["x", "y"]
    assert np.abs(lam2 - lam3[:, :2]).max() < 1e-7 * np.abs(lam3).max()
    assert np.abs(lam3[:, 2]).max() < 1e-9  # the spatial out-of-plane reaction, minimum norm: zero
    # the slider on its guide follows the crank by the closed-form loop closure
    th, phi = r2["joint/crank_pin/q"], r2["joint/crank_rod/q"]
    assert np.abs(r2["joint/guide/q"] - (R * np.cos(th) + L * np.cos(th + phi))).max() < 1e-10


def test_planar_four_bar_revolute_loop_keeps_two_rows_and_the_energy():
    m3, m2 = four_bar(False), four_bar(True)
    mob3, mob2 = ms.mechanisms.mobility(m3), ms.mechanisms.mobility(m2)
    assert mob3["nc"] == 5 and len(mob3["redundant"]) == 3
    assert mob2["nc"] == 2 and mob2["redundant"] == [] and mob2["dof"] == 1
    r3, r2 = run(m3), run(m2)
    for j in ("crank", "a", "rocker"):
        assert np.abs(r2[f"joint/{j}/q"] - r3[f"joint/{j}/q"]).max() < 1e-9, j
    fine = run(m2, t_end=0.5, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-12))
    e = fine["energy/total"]
    assert np.ptp(e) < 1e-8 * np.abs(e).max()
    assert np.abs(fine["constraint/pin/violation"]).max() < 1e-9


def test_planar_prismatic_loop_on_a_turning_rod_conserves_momentum_and_energy():
    m3, m2 = rod_and_slider(False), rod_and_slider(True)
    mob3, mob2 = ms.mechanisms.mobility(m3), ms.mechanisms.mobility(m2)
    assert mob3["nc"] == 5 and len(mob3["redundant"]) == 3
    # in the plane: the slider stays on the rod's line (1) and turns with it (1)
    assert mob2["nc"] == 2 and mob2["redundant"] == [] and mob2["dof"] == 2
    r3 = run(m3)
    integ = ms.DOPRI5(rtol=1e-11, atol=1e-12)
    r2 = run(m2, integrator=integ)
    r2_rk = run(m2)
    for j in ("pivot", "free"):
        assert np.abs(r2_rk[f"joint/{j}/q"] - r3[f"joint/{j}/q"]).max() < 1e-9, j
    hz, e = r2["momentum/angular"][:, 2], r2["energy/total"]
    assert np.ptp(hz) < 1e-8 * np.abs(hz).max()
    assert np.ptp(e) < 1e-8 * np.abs(e).max()
    # the slider really slides: its distance from the pivot changes, its angle follows the rod
    x, y, ang = (r2["joint/free/q"][:, k] for k in range(3))
    assert np.ptp(np.hypot(x, y)) > 0.05
    assert np.abs(ang - r2["joint/pivot/q"]).max() < 1e-9
    assert np.abs(np.arctan2(y, x) - r2["joint/pivot/q"]).max() < 1e-9
    assert r2.columns("constraint/sleeve/lambda") == ["normal", "rz"]
    assert r2.column_units("constraint/sleeve/lambda") == ["N", "N m"]


def test_planar_fixed_loop_makes_one_rigid_body_in_free_fall():
    """Two planar bodies welded by a fixed loop fall as one body: the centre of mass accelerates at
    g, the common spin stays constant, the weld's three in-plane rows carry the loads."""
    for planar in (True, False):
        m = ms.Model("weld", gravity=(0.0, -9.81, 0.0), planar=planar)
        a = m.add_body("a", 1.0, ms.inertia.box(1.0, (0.4, 0.1, 0.1)), com=(0.2, 0, 0))
        b = m.add_body("b", 2.0, ms.inertia.box(2.0, (0.3, 0.1, 0.1)), com=(0.15, 0, 0))
        m.add_joint(ms.joints.Planar("pa", m.ground, a, q0=[0, 0, 0.3], u0=[1.0, 2.0, 3.0]))
        # b starts welded at a's tip, turned by 0.5 rad relative to a
        rot = np.array([[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]])
        tip = rot @ [0.4, 0.0]
        v_tip = np.array([1.0, 2.0]) + 3.0 * np.array([-tip[1], tip[0]])
        m.add_joint(ms.joints.Planar("pb", m.ground, b, q0=[tip[0], tip[1], 0.8], u0=[v_tip[0], v_tip[1], 3.0]))
        m.add_constraint(ms.constraints.LoopFixed("weld", body1=b, body2=a, frame2=ms.Frame(position=(0.4, 0, 0), cardan=(0, 0, 0.5))))
        mob = ms.mechanisms.mobility(m)
        assert (mob["nc"], len(mob["redundant"])) == ((3, 0) if planar else (6, 3))
        res = run(m, t_end=0.4, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-12))
        t = res.t
        com = res["com/position"]
        v0 = res["com/velocity"][0]
        expect = com[0] + np.outer(t, v0) + 0.5 * np.outer(t**2, [0.0, -9.81, 0.0])
        assert np.abs(com - expect).max() < 1e-8
        assert np.abs(res["joint/pa/u"][:, 2] - 3.0).max() < 1e-8
        assert np.abs(res["joint/pb/q"][:, 2] - res["joint/pa/q"][:, 2] - 0.5).max() < 1e-9
        if planar:
            assert res.columns("constraint/weld/lambda") == ["x", "y", "rz"]


def test_planar_prescribed_body_drives_a_circle_with_the_centripetal_force():
    r, w, mass = 0.3, 4.0, 2.0
    m = ms.Model("circle", planar=True)
    b = m.add_body("puck", mass, ms.inertia.box(mass, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Planar("p", m.ground, b, q0=[r, 0.0, 0.0], u0=[0.0, r * w, w]))
    m.add_constraint(ms.constraints.PrescribedBody(
        "drive", b, position=(ms.functions.Harmonic(amplitude=r, omega=w, phase=np.pi / 2), ms.functions.Harmonic(amplitude=r, omega=w), 0.0),
        orientation=(0.0, 0.0, ms.functions.Ramp(slope=w))))
    assert ms.mechanisms.mobility(m)["nc"] == 3
    res = run(m, t_end=1.0, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-12))
    t = res.t
    q = res["joint/p/q"]
    assert np.abs(q[:, 0] - r * np.cos(w * t)).max() < 1e-8
    assert np.abs(q[:, 1] - r * np.sin(w * t)).max() < 1e-8
    assert np.abs(q[:, 2] - w * t).max() < 1e-8
    lam = res["constraint/drive/lambda"]
    # the drive pulls the puck towards the centre with m r w^2 and needs no moment
    assert np.abs(np.hypot(lam[:, 0], lam[:, 1]) - mass * r * w**2).max() < 1e-6
    assert np.abs(lam[:, 2]).max() < 1e-6
    assert res.columns("constraint/drive/lambda") == ["x", "y", "rz"]


@pytest.mark.parametrize("change, fragment", [
    (lambda m, g, b, c: m.add_joint(ms.joints.Spherical("ball", g, b)), "joint 'ball' (spherical) moves out of the plane"),
    (lambda m, g, b, c: m.add_joint(ms.joints.Revolute("tilted", g, b, axis=(1, 0, 0))), "joint 'tilted' (revolute) turns about the world axis"),
    (lambda m, g, b, c: m.add_joint(ms.joints.Prismatic("lift", g, b, axis=(0, 0, 1))), "joint 'lift' (prismatic) moves along the world z-axis"),
    (lambda m, g, b, c: m.add_joint(ms.joints.Free("float", g, b)), "joint 'float' (free) moves out of the plane"),
])
def test_planar_model_refuses_spatial_joints_naming_them(change, fragment):
    m = ms.Model("bad", planar=True)
    b = m.add_body("b", 1.0, [1, 1, 1])
    change(m, m.ground, b, None)
    with pytest.raises(ModelError, match="planar model: " + fragment.replace("(", r"\(").replace(")", r"\)")):
        m.build()


def test_planar_model_refuses_spatial_constraints_and_gravity_out_of_plane():
    m = ms.Model("g", gravity=(0, 0, -9.81), planar=True)
    b = m.add_body("b", 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Revolute("r", m.ground, b))
    with pytest.raises(ModelError, match="gravity has a z-component"):
        m.build()

    def two(kind):
        m = ms.Model("c", planar=True)
        a = m.add_body("a", 1.0, [1, 1, 1])
        b = m.add_body("b", 1.0, [1, 1, 1])
        m.add_joint(ms.joints.Revolute("ra", m.ground, a))
        m.add_joint(ms.joints.Revolute("rb", m.ground, b, parent_frame=(1, 0, 0)))
        m.add_constraint(kind(a, b))
        return m

    cases = [
        (lambda a, b: ms.constraints.LoopUniversal("u", body1=a, body2=b), "constraint 'u' (loop universal) is spatial"),
        (lambda a, b: ms.constraints.LoopRevolute("h", body1=a, body2=b, frame1=ms.Frame(cardan=(0, np.pi / 2, 0))),
         "constraint 'h' (loop revolute): its axis (frame z)"),
        (lambda a, b: ms.constraints.PointOnPlane("pp", body1=a, body2=b, normal=(0, 0, 1)), "constraint 'pp' (point on plane): the plane's normal is the world z-axis"),
        (lambda a, b: ms.constraints.LoopPlanar("lp", body1=a, body2=b), "constraint 'lp' (loop planar) holds nothing"),
    ]
    for kind, fragment in cases:
        with pytest.raises(ModelError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
            two(kind).build()
    m = ms.Model("disc", planar=True)
    d = m.add_body("d", 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Planar("p", m.ground, d))
    m.add_constraint(ms.constraints.RollingDisc("roll", d, radius=0.1, axis=(0, 0, 1)))
    with pytest.raises(ModelError, match=r"constraint 'roll' \(rolling disc\)"):
        m.build()
    with pytest.raises(ModelError, match="planar: expected true or false"):
        ms.Model("x", planar="yes")


def test_planar_key_in_a_toml_model_file(tmp_path):
    f = tmp_path / "crank.toml"
    f.write_text("""
name = "slider-crank"
planar = true
gravity = [0.0, -9.81, 0.0]

[[bodies]]
name = "crank"
mass = 0.5
inertia = [1e-4, 1e-3, 1e-3]
com = [0.05, 0.0, 0.0]

[[bodies]]
name = "rod"
mass = 0.8
inertia = [1e-4, 8e-3, 8e-3]
com = [0.175, 0.0, 0.0]

[[bodies]]
name = "slider"
mass = 1.2
inertia = [5e-4, 5e-4, 5e-4]

[[joints]]
type = "revolute"
name = "crank_pin"
parent = "ground"
child = "crank"
u0 = 6.0

[[joints]]
type = "revolute"
name = "crank_rod"
parent = "crank"
child = "rod"
parent_frame = { position = [0.1, 0.0, 0.0] }

[[joints]]
type = "prismatic"
name = "guide"
parent = "ground"
child = "slider"
axis = [1.0, 0.0, 0.0]
q0 = 0.45

[[constraints]]
type = "point"
name = "wrist"
body1 = "rod"
point1 = [0.35, 0.0, 0.0]
body2 = "slider"

[simulation]
t_end = 0.1
output_dt = 0.01
integrator = { type = "rk4", dt = 1e-4 }
""")
    out = tmp_path / "r.h5"
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(f), "--out", str(out)], capture_output=True, text=True,
                       cwd=ROOT)
    assert p.returncode == 0, p.stderr
    assert "redundant" not in p.stderr + p.stdout
    res = ms.Results.load(out)
    assert res["constraint/wrist/lambda"].shape[1] == 2
    f.write_text(f.read_text().replace("planar = true", 'planar = "yes"'))
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(f), "--out", str(out)], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode != 0 and "planar" in p.stderr and "Traceback" not in p.stderr
