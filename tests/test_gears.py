"""Involute gear contours (section 2.2.7.1) against the geometry of involute gearing: a driven pair
turns at the base-radius ratio through the tooth changes with its contact normal on the line of
action and its contact point on the path of contact; the gear-mesh helpers against the textbook
formulas for shifted gears; the rattle example hammering within the backlash; model files; and
bad input naming the contact."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys.contours import Gear, gear_center_distance, gear_mesh, involute, involute_inverse

ROOT = Path(__file__).resolve().parents[1]
M, Z1, Z2 = 0.002, 17, 31
ALPHA = math.radians(20.0)
THIN = 0.05 * M


def _drive_angle(g1: ms.contours.GearGeometry, g2: ms.contours.GearGeometry, a: float, alpha_w: float, gap: float = 0.0):
    """The wheel's angle (centre at (a, 0)) with the drive flanks (the upper flanks of both) `gap`
    apart along the line of action when the pinion is at angle 0: tooth 0 of each on the line of
    action, where the flanks' distances r_b phi from the tangent points add up to a sin(alpha_w)."""
    phi1 = g1.base_half_angle + alpha_w
    phi2 = (a * math.sin(alpha_w) - gap - g1.base_radius * phi1) / g2.base_radius
    return math.pi - alpha_w + phi2 - g2.base_half_angle


def _pair(omega: float, torque: float, points: int = 2):
    pinion, wheel = Gear(M, Z1, backlash=THIN), Gear(M, Z2, backlash=THIN)
    a = gear_center_distance(Z1, Z2, M)
    g1, g2 = pinion.geometry(), wheel.geometry()
    m = ms.Model("gears", gravity=(0.0, 0.0, 0.0), planar=True)
    p = m.add_body("pinion", 0.07, ms.inertia.cylinder(0.07, 0.017, 0.01, axis="z"))
    w = m.add_body("wheel", 0.24, ms.inertia.cylinder(0.24, 0.031, 0.01, axis="z"))
    m.add_joint(ms.joints.Revolute("shaft1", m.ground, p, axis=(0, 0, 1)))
    m.add_joint(ms.joints.Revolute("shaft2", m.ground, w, parent_frame=(a, 0, 0), axis=(0, 0, 1),
                                   q0=[_drive_angle(g1, g2, a, ALPHA)], u0=[-omega * Z1 / Z2]))
    m.add_constraint(ms.constraints.Prescribed("motor", "shaft1", ms.functions.Ramp(slope=omega)))
    m.add_force(ms.forces.JointForce("load", "shaft2", value=torque))
    m.add_contact(ms.Contact("mesh", p.contour(pinion), w.contour(wheel), points=points, impact=ms.laws.Newton(eps=0.0)))
    return m, (pinion, wheel, a, g1, g2)


def test_a_loaded_gear_pair_turns_at_the_base_radius_ratio_through_the_tooth_changes():
    omega, torque = 10.0, 0.5
    model, (pinion, wheel, a, g1, g2) = _pair(omega, torque)
    t_end = 0.3  # 3 rad of the pinion: 8 tooth changes
    res = ms.simulate(model, t_end=t_end, integrator=ms.EventDriven(), output_dt=5e-4)
    mesh = gear_mesh(pinion, wheel, a)
    assert mesh.contact_ratio > 1.5 and not mesh.interference
    w1, w2 = res["joint/shaft1/u"], res["joint/shaft2/u"]
    # candidate 1: the pinion's upper (driving) flanks; candidate 0: the coast flanks
    gap, lam = res["contact/mesh/g_n"], res["contact/mesh/lambda_n"]
    assert np.all(res["contact/mesh/state"][:, 1] != 0) and np.abs(gap[:, 1]).max() < 1e-12
    # the coast flanks stay the normal backlash apart
    assert np.abs(gap[:, 0] - mesh.normal_backlash).max() < 1e-12
    # speed ratio -z1/z2 = -r_b1/r_b2 (conjugate action, also across the tooth changes)
    assert np.abs(w2 / w1 + Z1 / Z2).max() < 1e-10
    assert mesh.ratio == pytest.approx(-Z1 / Z2, rel=1e-14)
    # at constant speeds the wheel's balance is r_b2 lambda = T
    assert np.abs(lam[:, 1] * g2.base_radius - torque).max() < 1e-9
    # rigid conjugate tooth changes: no impact, nothing but the initial closing
    assert [e["event"] for e in res.events] == ["close"]
    # the normal lies along the line of action: at alpha to the common tangent of the pitch
    # circles (the y axis), pointing from the wheel's flank towards the pinion's
    n = res["contact/mesh/normal"][:, 1]
    assert np.abs(n - [-math.sin(ALPHA), -math.cos(ALPHA), 0.0]).max() < 1e-10
    # the contact point runs along the line of action from T1 = r_b1 (cos a, -sin a) and stays on
    # the path of contact
    p = res["contact/mesh/point"][:, 1]
    t1 = np.array([g1.base_radius * math.cos(ALPHA), -g1.base_radius * math.sin(ALPHA), 0.0])
    e = np.array([math.sin(ALPHA), math.cos(ALPHA), 0.0])
    d = p - t1
    assert np.abs(d[:, 0] * e[1] - d[:, 1] * e[0]).max() < 1e-10
    s = d @ e
    start = max(g1.base_radius * g1.roll_range[0], a * math.sin(ALPHA) - g2.base_radius * g2.roll_range[1])
    end = min(g1.base_radius * g1.roll_range[1], a * math.sin(ALPHA) - g2.base_radius * g2.roll_range[0])
    assert (end - start) / g1.base_pitch == pytest.approx(mesh.contact_ratio, rel=1e-12)
    assert s.min() >= start - 1e-10 and s.max() <= end + 1e-10
    # with two pairs in mesh for part of each tooth pitch (contact ratio 1.55) the candidate is
    # either (equally deep): its point runs over the whole path of contact, and over the pinion's
    # teeth one after the other
    step = omega * g1.base_radius * 5e-4
    assert s.min() < start + step and s.max() > end - step
    theta = res["joint/shaft1/q"]
    local = np.arctan2(-np.sin(theta) * p[:, 0] + np.cos(theta) * p[:, 1], np.cos(theta) * p[:, 0] + np.sin(theta) * p[:, 1])
    tooth = np.round(local / (2 * math.pi / Z1)).astype(int) % Z1
    teeth = omega * t_end * Z1 / (2 * math.pi)
    assert len(set(tooth)) == pytest.approx(teeth + 1, abs=1.0)
    assert set(tooth) == {(tooth[-1] + k) % Z1 for k in range(len(set(tooth)))}


def test_gear_rattle_example_hammers_on_both_flanks_within_the_backlash():
    spec = importlib.util.spec_from_file_location("gear_rattle", ROOT / "examples" / "gear_rattle.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    res = ms.simulate(ex.model, t_end=0.2, integrator=ms.EventDriven(velocity_tol=1e-6), output_dt=1e-4)
    n = ex.impacts(res)
    period = 2 * math.pi / ex.NU
    # the wheel crosses the backlash twice per period of the speed fluctuation (ahead onto the
    # coast flanks as the pinion slows down, back onto the drive flanks as it speeds up)
    assert n["coast"] >= 4 and n["drive"] >= 4
    assert n["strokes"] == pytest.approx(2 * 0.2 / period, abs=2)
    # the transmission error stays within the backlash band, reaching both ends
    dte = ex.transmission_error(res)
    jn = ex.MESH.normal_backlash
    assert dte.min() > -1e-9 and dte.max() < jn + 1e-9
    assert dte.min() < 0.01 * jn and dte.max() > 0.95 * jn
    assert res["contact/mesh/g_n"].min() > -1e-9
    # while the drive flanks are closed the wheel follows the pinion at the ratio
    closed = res["contact/mesh/state"][:, 1] != 0
    w1 = res["joint/motor_shaft/u"] + res["joint/pinion_shaft/u"]
    assert closed.sum() > 10
    assert np.abs(res["joint/wheel_shaft/u"][closed] / w1[closed] + Z1 / Z2).max() < 1e-8


def test_center_distance_and_mesh_against_the_textbook_formulas():
    # unshifted: m (z1 + z2) / 2
    assert gear_center_distance(17, 31, M) == pytest.approx(0.048, rel=1e-14)
    # shifted: inv alpha_w = inv alpha + 2 tan alpha (x1 + x2) / (z1 + z2), a = a0 cos alpha / cos alpha_w
    x1, x2 = 0.4, 0.15
    aw = involute_inverse(involute(ALPHA) + 2 * math.tan(ALPHA) * (x1 + x2) / (Z1 + Z2))
    a = 0.5 * M * (Z1 + Z2) * math.cos(ALPHA) / math.cos(aw)
    assert gear_center_distance(Z1, Z2, M, ALPHA, x1, x2) == pytest.approx(a, rel=1e-13)
    assert involute(involute_inverse(0.0149)) == pytest.approx(0.0149, rel=1e-14)
    # at that distance the shifted pair meshes without backlash, at the working pressure angle
    g1, g2 = Gear(M, Z1, shift=x1), Gear(M, Z2, shift=x2)
    mesh = gear_mesh(g1, g2, a)
    assert mesh.working_pressure_angle == pytest.approx(aw, rel=1e-12)
    assert abs(mesh.normal_backlash) < 1e-15
    # moved apart by da, the flanks open by 2 (r_b1 + r_b2)(inv alpha_w' - inv alpha_w) along the line of action
    da = 1e-4
    wider = gear_mesh(g1, g2, a + da)
    rb = 0.5 * M * (Z1 + Z2) * math.cos(ALPHA)
    expected = 2 * rb * (involute(math.acos(rb / (a + da))) - involute(aw))
    assert wider.normal_backlash == pytest.approx(expected, rel=1e-10)
    assert wider.normal_backlash == pytest.approx(2 * da * math.sin(aw), rel=1e-2)
    # thinned teeth: the normal backlash is the thinning on the base circles, 2 j cos alpha
    thin = gear_mesh(Gear(M, Z1, backlash=THIN), Gear(M, Z2, backlash=THIN), 0.048)
    assert thin.normal_backlash == pytest.approx(2 * THIN * math.cos(ALPHA), rel=1e-12)
    # contact ratio: (sqrt(r_a1² - r_b1²) + sqrt(r_a2² - r_b2²) - a sin alpha_w) / p_b without tip
    # rounding; the rounding (kept tiny here) shortens the involutes
    sharp = gear_mesh(Gear(M, Z1, tip_radius=1e-9), Gear(M, Z2, tip_radius=1e-9), 0.048)
    ra1, ra2, rb1, rb2 = 0.5 * M * Z1 + M, 0.5 * M * Z2 + M, 0.5 * M * Z1 * math.cos(ALPHA), 0.5 * M * Z2 * math.cos(ALPHA)
    eps = (math.sqrt(ra1**2 - rb1**2) + math.sqrt(ra2**2 - rb2**2) - 0.048 * math.sin(ALPHA)) / (math.pi * M * math.cos(ALPHA))
    assert sharp.contact_ratio == pytest.approx(eps, rel=1e-6)
    assert gear_mesh(Gear(M, Z1), Gear(M, Z2), 0.048).contact_ratio < sharp.contact_ratio
    # geometry as the engine builds it
    geo = Gear(M, Z1).geometry(samples=8 * Z1)
    assert geo.base_radius == pytest.approx(0.5 * M * Z1 * math.cos(ALPHA), rel=1e-15)
    assert (geo.tip_rounding, geo.root_fillet) == pytest.approx((0.05 * M, 0.2 * M), rel=1e-15)
    assert geo.segment  # the root circle of 17 teeth lies inside the base circle
    r = np.linalg.norm(geo.outline, axis=1)
    assert r.max() <= geo.tip_radius * (1 + 1e-12) and r.min() >= geo.root_radius * (1 - 1e-12)
    # the base radius instead of the module
    same = Gear(base_radius=geo.base_radius, teeth=Z1).geometry()
    assert same.module == pytest.approx(M, rel=1e-14)


def test_gears_from_a_model_file(tmp_path):
    a = 0.048
    q0 = _drive_angle(Gear(M, Z1, backlash=THIN).geometry(), Gear(M, Z2, backlash=THIN).geometry(), a, ALPHA)
    text = f"""
name = "gears"
gravity = [0.0, 0.0, 0.0]
planar = true

[[bodies]]
name = "pinion"
mass = 0.07
inertia = [1e-5, 1e-5, 1e-5]

[[bodies]]
name = "wheel"
mass = 0.24
inertia = [1.2e-4, 1.2e-4, 1.2e-4]

[[joints]]
name = "shaft1"
type = "revolute"
parent = "ground"
child = "pinion"
axis = [0.0, 0.0, 1.0]

[[joints]]
name = "shaft2"
type = "revolute"
parent = "ground"
child = "wheel"
axis = [0.0, 0.0, 1.0]
parent_frame = {{ position = [{a}, 0.0, 0.0] }}
q0 = [{q0!r}]
u0 = [{-10.0 * Z1 / Z2!r}]

[[constraints]]
name = "motor"
type = "prescribed"
joint = "shaft1"
function = {{ type = "ramp", slope = 10.0 }}

[[forces]]
name = "load"
type = "joint_force"
joint = "shaft2"
value = [0.5]

[[contacts]]
name = "mesh"
body1 = "pinion"
body2 = "wheel"
points = 2
contour1 = {{ type = "gear", module = {M}, teeth = {Z1}, backlash = {THIN} }}
contour2 = {{ type = "gear", base_radius = {0.5 * M * Z2 * math.cos(ALPHA)!r}, teeth = {Z2}, backlash = {THIN}, pressure_angle = {ALPHA!r} }}
"""
    p = tmp_path / "gears.toml"
    p.write_text(text)
    from mechsys.modelfile import load_model

    model, _ = load_model(p)
    res = ms.simulate(model, t_end=0.05, integrator=ms.EventDriven(), output_dt=1e-3)
    assert np.abs(res["joint/shaft2/u"] / res["joint/shaft1/u"] + Z1 / Z2).max() < 1e-10
    assert np.abs(res["contact/mesh/g_n"][:, 1]).max() < 1e-12
    # an unknown key is named
    bad = p.with_name("bad.toml")
    bad.write_text(text.replace("teeth = 17,", "teeth = 17, modul = 2,"))
    with pytest.raises(ms.ModelError, match="modul"):
        load_model(bad)


def _contact(c1, c2, points=2):
    m = ms.Model("g", gravity=(0.0, 0.0, 0.0), planar=True)
    p = m.add_body("p", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    w = m.add_body("w", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Revolute("s1", m.ground, p, axis=(0, 0, 1)))
    m.add_joint(ms.joints.Revolute("s2", m.ground, w, parent_frame=(0.048, 0, 0), axis=(0, 0, 1)))
    m.add_contact(ms.Contact("mesh", p.contour(c1), w.contour(c2), points=points))
    return m


@pytest.mark.parametrize(
    "c1, points, message",
    [
        (Gear(M, 3), 2, r"'mesh'\.contour1: a gear needs 5 to \d+ teeth, got 3"),
        (Gear(-M, 17), 2, r"'mesh'\.contour1: gear module must be > 0"),
        (Gear(M, 17.5), 2, r"contour1\.teeth: expected a whole number of teeth"),
        (Gear(M, 17, base_radius=0.01), 2, r"'mesh'\.contour1: give the gear's module or its base_radius, not both"),
        (Gear(teeth=17), 2, r"'mesh'\.contour1: a gear needs its module"),
        (Gear(M, 17, tip_radius=0.7 * M), 2, r"'mesh'\.contour1: the gear's tip rounding radius .* does not fit"),
        (Gear(M, 17, root_radius=M), 2, r"'mesh'\.contour1: the gear's root fillet radius .* does not fit"),
        (Gear(M, 8, shift=1.0), 2, r"'mesh'\.contour1: pointed teeth"),
        (Gear(M, 17, backlash=2 * M), 2, r"'mesh'\.contour1: the gear's tooth thickness on the pitch circle"),
        (Gear(M, 17, pressure_angle=1.2), 2, r"'mesh'\.contour1\.pressure_angle: must lie between 0 and 60"),
        (Gear(M, 17), 4, r"'mesh'\.points: .*17 and 31.*use 6 points"),
        (Gear(M, 17), 3, r"'mesh'\.points: .*even number of points"),
    ],
)
def test_bad_gears_are_refused_naming_the_contact(c1, points, message):
    with pytest.raises(ms.ModelError, match=message):
        _contact(c1, Gear(M, 31), points).build()


def test_bad_gear_helpers_are_refused():
    with pytest.raises(ms.ModelError, match="base pitches differ"):
        gear_mesh(Gear(M, 17), Gear(1.5 * M, 31), 0.05)
    with pytest.raises(ms.ModelError, match="must exceed the sum of the base radii"):
        gear_mesh(Gear(M, 17), Gear(M, 31), 0.04)
    with pytest.raises(ms.ModelError, match="at least 5 teeth"):
        gear_center_distance(3, 31, M)
    with pytest.raises(ms.ModelError, match="module must be > 0"):
        gear_center_distance(17, 31, 0.0)
