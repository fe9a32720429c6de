"""Parametric contours (section 2.2.7.1) from the Python API and model files: a cam-follower
lift-off against its closed form, an ellipse settling on its flat side, a disc rolling in a
circular groove, and the errors that name the contour for bad data."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

ROOT = Path(__file__).resolve().parents[1]


def _example(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def cam():
    return _example("cam_follower")


def test_cam_follower_below_the_critical_speed_follows_the_lift_table(cam):
    omega = 0.9 * cam.OMEGA_C
    res = ms.simulate(cam.build(omega), t_end=2 * math.pi / omega, integrator=ms.EventDriven(), output_dt=2e-5)
    r = cam.report(res, omega)
    assert "lift_off_angle" not in r
    # the roller centre rides on the pitch curve: the follower's travel is the lift (the quintic
    # lift spline through 360 samples of the cosine reproduces it to ~1e-12 m)
    assert r["follow_error"] < 1e-10
    # contact force against m omega^2 h'' + k h + F0 + m g (vertical balance of the follower)
    assert r["force_error"] < 1e-6
    # the least sampled force, near full lift (sampled every 0.2° of cam angle)
    assert r["min_force"] == pytest.approx(cam.contact_force_closed_form_min(omega), abs=1e-4)
    assert r["max_gap"] < 1e-9


def test_cam_follower_above_the_critical_speed_lifts_off_where_the_force_vanishes(cam):
    omega = 1.15 * cam.OMEGA_C
    res = ms.simulate(cam.build(omega), t_end=2 * math.pi / omega, integrator=ms.EventDriven(), output_dt=1e-4)
    r = cam.report(res, omega)
    theta = cam.lift_off_angle(omega)
    assert 1.5 < theta < 2.9  # after full lift's start, before full lift
    assert r["lift_off_angle"] == pytest.approx(theta, abs=1e-8)
    assert r["max_gap"] > 1e-4
    # just below the critical speed the roller would not leave: the two runs bracket omega_c
    assert math.isnan(cam.lift_off_angle(0.99 * cam.OMEGA_C))


def test_cam_contact_point_signals_lie_on_the_profile(cam):
    omega = 0.5 * cam.OMEGA_C
    res = ms.simulate(cam.build(omega), t_end=0.5 * math.pi / omega, integrator=ms.EventDriven(), output_dt=1e-4)
    p = res["contact/cam/point"]
    assert p.shape == (len(res.t), 3)
    # the contact point is one roller radius from the roller centre, along the contact normal
    y = res["joint/guide/q"]
    centre = np.c_[np.zeros_like(y), y, np.zeros_like(y)]
    d = np.linalg.norm(p - centre, axis=1)
    assert np.abs(d - cam.ROLLER).max() < 1e-9
    assert res.unit("contact/cam/point") == "m"


def _ellipse_drop(integrator) -> ms.Results:
    a, b = 0.2, 0.1
    m = ms.Model("egg", gravity=(0.0, -9.81, 0.0), planar=True)
    egg = m.add_body("egg", 1.0, ms.inertia.box(1.0, (2 * a, 2 * b, 0.05)))
    m.add_joint(ms.joints.Planar("free", m.ground, egg, q0=(0.0, 0.4, 0.3)))
    m.add_contact(ms.Contact("floor", egg.contour(ms.contours.Ellipse(a=a, b=b)),
                             m.ground.contour(ms.contours.Line(normal=(0, 1, 0))),
                             friction=ms.laws.Coulomb(mu=0.5), impact=ms.laws.Newton(eps=0.0)))
    return ms.simulate(m, t_end=3.0, integrator=integrator, output_dt=1e-2)


def test_an_ellipse_dropped_on_a_floor_rocks_on_it_at_its_support_height():
    # event-driven: the rolling contact is kept at acceleration level (Moreau-Jean's velocity-level
    # steps let a rolling curved contact sink by O(dt) per unit time; it has no position projection)
    res = _ellipse_drop(ms.EventDriven())
    q = res["joint/free/q"]
    after = res.t > 1.0
    # touching the floor, the centre is at the ellipse's support distance along the floor's
    # normal: y = sqrt(a² sin²θ + b² cos²θ) (closed form), whatever the rocking angle
    support = np.sqrt((0.2 * np.sin(q[:, 2])) ** 2 + (0.1 * np.cos(q[:, 2])) ** 2)
    assert np.abs(q[after, 1] - support[after]).max() < 1e-9
    assert np.abs(res["contact/floor/g_n"][after]).max() < 1e-9
    # it rocks about its flat side (the stable equilibrium) without tipping over, carried by the
    # floor on average
    assert np.cos(q[after, 2]).min() > 0.5
    assert res["contact/floor/lambda_n"][after].mean() == pytest.approx(9.81, rel=0.05)


def test_a_disc_rolling_in_a_circular_groove_oscillates_with_the_closed_form_period():
    # a disc of radius r rolling without slip inside a groove of radius R (a bore, the solid
    # outside): small oscillations have the period 2 pi sqrt(3 (R - r) / (2 g)) (uniform disc)
    R, r, g = 0.5, 0.1, 9.81
    m = ms.Model("groove", gravity=(0.0, -g, 0.0), planar=True)
    disc = m.add_body("disc", 1.0, ms.inertia.cylinder(1.0, r, 0.02, axis="z"))
    phi0 = 0.05
    x0, y0 = (R - r) * math.sin(phi0), -(R - r) * math.cos(phi0)
    m.add_joint(ms.joints.Planar("free", m.ground, disc, q0=(x0, y0, 0.0)))
    pts = [(R * math.cos(t), R * math.sin(t)) for t in np.linspace(0, 2 * math.pi, 96, endpoint=False)]
    m.add_contact(ms.Contact("groove", disc.contour(ms.contours.Circle(radius=r)),
                             m.ground.contour(ms.contours.Spline(points=pts, closed=True, solid="outside")),
                             friction=ms.laws.Coulomb(mu=1.0), impact=ms.laws.Newton(eps=0.0)))
    res = ms.simulate(m, t_end=4.0, integrator=ms.EventDriven(), output_dt=1e-3)
    x = res["joint/free/q"][:, 0]
    crossings = np.where((x[:-1] > 0) & (x[1:] <= 0))[0]
    t_cross = res.t[crossings] + (res.t[crossings + 1] - res.t[crossings]) * x[crossings] / (x[crossings] - x[crossings + 1])
    period = np.diff(t_cross).mean()
    expected = 2 * math.pi * math.sqrt(3 * (R - r) / (2 * g))
    # a spline through 96 points and a finite amplitude (0.05 rad)
    assert period == pytest.approx(expected, rel=3e-3)
    # rolling: the contact sticks throughout
    assert np.all(res["contact/groove/state"][10:] == 1)


def test_model_file_round_trip_of_curved_contours(tmp_path):
    text = """
name = "curves"
gravity = [0.0, -9.81, 0.0]
planar = true

[[bodies]]
name = "egg"
mass = 1.0
inertia = [0.01, 0.01, 0.01]

[[joints]]
name = "free"
type = "planar"
parent = "ground"
child = "egg"
q0 = [0.0, 0.3, 0.0]

[[contacts]]
name = "floor"
body1 = "egg"
body2 = "ground"
contour1 = { type = "ellipse", semi_axes = [0.2, 0.1] }
contour2 = { type = "line", normal = [0.0, 1.0, 0.0] }
"""
    p = tmp_path / "m.toml"
    p.write_text(text)
    from mechsys.modelfile import load_model

    m, _ = load_model(p)
    res = ms.simulate(m, t_end=0.5, integrator=ms.EventDriven(), output_dt=1e-2)
    # dropped flat from 0.3: lands (at t = sqrt(2 (0.3 - 0.1) / g)) and stays on its minor axis end
    assert res["joint/free/q"][-1][1] == pytest.approx(0.1, abs=1e-9)
    landing = [e["t"] for e in res.events if e["event"] == "impact"][0]
    assert landing == pytest.approx(math.sqrt(2 * 0.2 / 9.81), rel=1e-8)
    assert res["contact/floor/g_n"][0] == pytest.approx(0.2, abs=1e-12)


@pytest.mark.parametrize(
    "contour, message",
    [
        (ms.contours.Ellipse(a=0.0, b=0.1), "semi-axis a must be > 0"),
        (ms.contours.Ellipse(a=0.1, b=0.1, solid="left"), "expected one of 'inside', 'outside'"),
        (ms.contours.Spline(points=[(0, 0), (1, 0), (1, 0), (2, 1)]), "points 1 and 2 coincide"),
        (ms.contours.Spline(points=[(0, 0), (1, 0), (0, 0.1)]), "turns by"),
        # a figure eight: smooth, but crossing itself at the origin
        (ms.contours.Spline(points=[(math.sin(t), 0.5 * math.sin(2 * t)) for t in np.linspace(0, 2 * math.pi, 32, endpoint=False)],
                            closed=True), "intersects itself"),
        (ms.contours.Spline(points=[(0, 0), (1, 0)], solid="inside"), "open curve has no inside"),
        (ms.contours.Cam(lift=([0.0, 2.0, 4.0, 2 * math.pi], [0.0, 0.01, 0.0, 0.002]), base_radius=0.03), "not periodic"),
        (ms.contours.Cam(lift=lambda t: 0.01 * t, base_radius=0.03), "not periodic"),
        (ms.contours.Cam(lift=lambda t: float("nan"), base_radius=0.03), "returned nan"),
        (ms.contours.Cam(lift=lambda t: 1 / 0, base_radius=0.03), "raised at angle 0.0: ZeroDivisionError"),
        (ms.contours.Cam(lift=lambda t: 0.02 * (1 - math.cos(3 * t)), base_radius=0.01, follower="flat"), "R_b + h + h''"),
        (ms.contours.Cam(lift=lambda t: 0.02 * (1 - math.cos(3 * t)), base_radius=0.01, roller_radius=0.05), "undercuts"),
        (ms.contours.Cam(lift=lambda t: 0.0, base_radius=0.03, follower="mushroom"), "expected 'roller', 'knife' or 'flat'"),
    ],
)
def test_bad_curved_contour_data_names_the_contact(contour, message):
    m = ms.Model("bad", planar=True)
    b = m.add_body("b", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Planar("free", m.ground, b))
    m.add_contact(ms.Contact("touch", b.contour(ms.contours.Circle(radius=0.01)), m.ground.contour(contour)))
    with pytest.raises(ms.ModelError) as e:
        m.build()
    assert "touch" in str(e.value) and message in str(e.value), str(e.value)


def test_spline_from_a_function_that_raises_names_the_parameter():
    with pytest.raises(ms.ModelError, match=r"raised at s = 0.0: ValueError"):
        ms.contours.Spline.from_function(lambda s: (_ for _ in ()).throw(ValueError("no")), (0.0, 1.0))
    with pytest.raises(ms.ModelError, match="non-finite point"):
        ms.contours.Spline.from_function(lambda s: (s, float("inf")), (0.0, 1.0))


def test_points_is_checked_and_only_for_parametric_pairs():
    m = ms.Model("p", planar=True)
    b = m.add_body("b", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Planar("free", m.ground, b))
    m.add_contact(ms.Contact("c", b.contour(ms.contours.Circle(radius=0.1)), m.ground.contour(ms.contours.Line(normal=(0, 1, 0))), points=2))
    with pytest.raises(ms.ModelError, match=r"contacts\[0\] 'c'.points: .*only pairs with a parametric contour"):
        m.build()
    with pytest.raises(ms.ModelError, match="expected a whole number from 1 to 8"):
        ms.Contact("c", b.contour(ms.contours.Circle(radius=0.1)), m.ground.contour(ms.contours.Ellipse(a=1, b=1)), points=9).describe([])


def test_ball_rolling_in_a_spline_track_conserves_energy_and_oscillates_with_the_bottom_radius():
    ex = _example("ball_in_track")
    res = ms.simulate(ex.model, **ex.simulation)
    # rolling does no work: the energy stays (event-driven, rtol 1e-10)
    assert np.ptp(res["energy/total"]) < 1e-6
    assert set(res["contact/track/state"].tolist()) == {1}
    # the period of a disc rolling in a circle of the bottom's radius, longer by the finite
    # amplitude (the parabola flattens away from the bottom): within 0.3 %
    expected = 2 * math.pi * math.sqrt(3 * (ex.R0 - ex.RADIUS) / (2 * ex.G))
    assert ex.period(res) == pytest.approx(expected, rel=3e-3)
    assert ex.period(res) > expected
    # the rolling velocity: the disc's angular velocity about the out-of-plane tangent (the
    # track does not turn); no spin in the plane
    assert np.allclose(res["contact/track/rolling"], res["joint/free/u"][:, 2], atol=1e-12)
    assert np.abs(res["contact/track/spin"]).max() < 1e-12
    assert res.unit("contact/track/rolling") == "rad/s"


def test_contact_geometry_query_gives_gap_witness_points_normal_and_curvatures():
    # the cam of benches/cam.py: the exact lift of an eccentric circle of radius R, so the
    # profile is that circle; roller and cam curvatures 1/r and 1/R at the contact
    import sys

    sys.path.insert(0, str(ROOT / "benches"))
    import cam as bench_cam

    m = bench_cam.build(True)
    for angle in (0.3, 1.7, 4.0):
        q = np.array(m.engine()[0].q0())
        # shaft angle, then the follower where the roller touches the circle: y = e cos + sqrt(...)
        e, R, r = bench_cam.E, bench_cam.R, bench_cam.ROLLER
        y = e * math.cos(angle) + math.sqrt((R + r) ** 2 - (e * math.sin(angle)) ** 2) + 1e-3
        q[0], q[1] = angle, y
        g = ms.dynamics.contact_geometry(m, q)
        assert g["contact"] == ["cam"]
        centre = np.array([-e * math.sin(angle), e * math.cos(angle), 0.0])
        roller = np.array([0.0, y, 0.0])
        assert g["gap"][0] == pytest.approx(np.linalg.norm(roller - centre) - R - r, abs=1e-10)
        assert np.allclose(g["point1"][0] - g["point2"][0], g["gap"][0] * g["normal"][0], atol=1e-15)
        # the normal points from the cam's circle centre towards the roller centre
        assert np.allclose(g["normal"][0], (roller - centre) / np.linalg.norm(roller - centre), atol=1e-9)
        assert g["curvature1"][0] == pytest.approx([1 / r, 0.0])
        assert g["curvature2"][0][0] == pytest.approx(1 / R, rel=1e-6)


def test_parametric_contours_in_a_contact_group_land_on_the_floor():
    m = ms.Model("eggs", gravity=(0, -9.81, 0), planar=True)
    members = []
    for k in range(3):
        b = m.add_body(f"e{k}", 1.0, ms.inertia.box(1.0, (0.2, 0.1, 0.05)))
        m.add_joint(ms.joints.Planar(f"j{k}", m.ground, b, q0=(0.05 * k, 0.15 + 0.25 * k, 0.3 * k)))
        members.append(b.contour(ms.contours.Ellipse(a=0.1, b=0.05)))
    m.add_contact_group(ms.ContactGroup("pile", members=members, against=[m.ground.contour(ms.contours.Line(normal=(0, 1, 0)))],
                                        friction=ms.laws.Coulomb(mu=0.3)))
    res = ms.simulate(m, t_end=2.0, integrator=ms.MoreauJean(dt=1e-3), output_dt=1e-2)
    for k in range(3):
        y = res[f"joint/j{k}/q"][-1][1]
        # resting or rolling on the floor: the centre between the semi-axes' heights
        assert 0.05 - 5e-3 < y < 0.1 + 1e-6, (k, y)
    assert res["contact/pile/max_penetration"].max() < 5e-3
