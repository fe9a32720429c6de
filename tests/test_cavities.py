"""Concave contours (issue 14, part 5): a ball rolling in a spherical bowl and a sphere in a
cylindrical bore, against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mechsys as ms

G = 9.81


def _ball_in_bowl(R: float, r: float, phi0: float, mu: float | None = 1.0) -> ms.Model:
    m = ms.Model("bowl", gravity=(0.0, 0.0, -G))
    ball = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, r))
    x0, z0 = (R - r) * math.sin(phi0), -(R - r) * math.cos(phi0)
    m.add_joint(ms.joints.Free("free", m.ground, ball, q0=[x0, 0.0, z0, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("bowl", ball.contour(ms.contours.Sphere(radius=r)), m.ground.contour(ms.contours.Bowl(radius=R)),
                             friction=None if mu is None else ms.laws.Coulomb(mu=mu)))
    return m


def test_a_ball_rolling_in_a_spherical_bowl_has_the_closed_form_period():
    # a solid ball rolling without slip: T = 2 pi sqrt(7 (R - r) / (5 g)) for small swings
    R, r, phi0 = 0.5, 0.05, 0.02
    res = ms.simulate(_ball_in_bowl(R, r, phi0), t_end=3.0, integrator=ms.EventDriven(), output_dt=1e-3)
    x = res["joint/free/q"][:, 0]
    k = np.where((x[:-1] > 0) & (x[1:] <= 0))[0]
    tc = res.t[k] + (res.t[k + 1] - res.t[k]) * x[k] / (x[k] - x[k + 1])
    period = np.diff(tc).mean() if len(tc) > 1 else 2 * (tc[0] - 0.0)
    expected = 2 * math.pi * math.sqrt(7 * (R - r) / (5 * G))
    assert period == pytest.approx(expected, rel=2e-4)
    # it rolls: sticking throughout, energy kept, on the bowl (gap zero)
    assert set(res["contact/bowl/state"].tolist()) == {1}
    assert np.ptp(res["energy/total"]) < 1e-8
    assert np.abs(res["contact/bowl/g_n"]).max() < 1e-9
    # spin and rolling: the ball's angular velocity (the bowl is at rest) in the contact frame
    w = res["body/ball/angular_velocity"]
    n = res["contact/bowl/normal"]
    assert np.allclose(res["contact/bowl/spin"], np.einsum("ij,ij->i", w, n), atol=1e-12)
    roll = res["contact/bowl/rolling"]
    assert roll.shape == (len(res.t), 2)
    assert np.allclose(np.linalg.norm(roll, axis=1) ** 2 + res["contact/bowl/spin"] ** 2, np.einsum("ij,ij->i", w, w), atol=1e-10)
    # frictionless it slides instead: the period of a point mass, 2 pi sqrt((R - r) / g)
    m = _ball_in_bowl(R, r, phi0, mu=None)
    res = ms.simulate(m, t_end=3.0, integrator=ms.EventDriven(), output_dt=1e-3)
    x = res["joint/free/q"][:, 0]
    k = np.where((x[:-1] > 0) & (x[1:] <= 0))[0]
    tc = res.t[k] + (res.t[k + 1] - res.t[k]) * x[k] / (x[k] - x[k + 1])
    assert np.diff(tc).mean() == pytest.approx(2 * math.pi * math.sqrt((R - r) / G), rel=2e-4)


def test_a_sphere_resting_in_a_bore_sits_on_its_bottom_line():
    R, r = 0.3, 0.1
    m = ms.Model("bore", gravity=(0.0, 0.0, -G))
    ball = m.add_body("ball", 2.0, ms.inertia.sphere(2.0, r))
    m.add_joint(ms.joints.Free("free", m.ground, ball, q0=[0.0, 0.3, 0.0, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("bore", ball.contour(ms.contours.Sphere(radius=r)),
                             m.ground.contour(ms.contours.Bore(radius=R, axis=(0, 1, 0))), friction=ms.laws.Coulomb(mu=0.5)))
    res = ms.simulate(m, t_end=1.0, integrator=ms.EventDriven(), output_dt=1e-2)
    q = res["joint/free/q"][-1]
    # fallen from the axis onto the bottom line of the bore: centre at z = -(R - r), y unchanged
    assert q[2] == pytest.approx(-(R - r), abs=1e-9)
    assert q[1] == pytest.approx(0.3, abs=1e-9)
    assert res["contact/bore/lambda_n"][-1] == pytest.approx(2.0 * G, rel=1e-6)
    g = ms.dynamics.contact_geometry(m, res["joint/free/q"][-1])
    assert g["curvature2"][0] == pytest.approx([-1 / R, 0.0])
    assert g["curvature1"][0] == pytest.approx([1 / r, 1 / r])


def test_cavity_errors_name_the_contact():
    m = ms.Model("bad")
    b = m.add_body("b", 1.0, ms.inertia.sphere(1.0, 0.1))
    m.add_joint(ms.joints.Free("free", m.ground, b))
    m.add_contact(ms.Contact("shell", b.contour(ms.contours.Sphere(radius=0.1)), m.ground.contour(ms.contours.Bore(radius=0.3, axis=(0, 0, 0)))))
    with pytest.raises(ms.ModelError, match=r"shell.*bore axis must not be the zero vector"):
        m.build()
    m2 = ms.Model("bad2")
    b2 = m2.add_body("b", 1.0, ms.inertia.sphere(1.0, 0.1))
    m2.add_joint(ms.joints.Free("free", m2.ground, b2))
    m2.add_contact(ms.Contact("cup", b2.contour(ms.contours.Box(half_extents=(0.1, 0.1, 0.1))), m2.ground.contour(ms.contours.Bowl(radius=1.0))))
    with pytest.raises(ms.ModelError, match=r"cup.*box–bowl"):
        m2.build()


def test_an_ellipsoid_rocking_on_a_floor_without_slipping_has_the_closed_form_frequency():
    # resting on the end of its c axis, rocking about y: the contact rolls over a radius of
    # curvature rho = a² / c below a centre at h = c, so omega² = m g (rho - h) / (I_y + m h²)
    a, b, c, mass = 0.3, 0.2, 0.1, 2.0
    m = ms.Model("egg", gravity=(0.0, 0.0, -G))
    inertia = ms.inertia.ellipsoid(mass, (a, b, c))
    egg = m.add_body("egg", mass, inertia)
    tilt = 0.01
    q0 = [0.0, 0.0, c, math.cos(tilt / 2), 0.0, math.sin(tilt / 2), 0.0]
    # start on the floor at the tilted support height
    q0[2] = math.sqrt((a * math.sin(tilt)) ** 2 + (c * math.cos(tilt)) ** 2)
    m.add_joint(ms.joints.Free("free", m.ground, egg, q0=q0))
    m.add_contact(ms.Contact("floor", egg.contour(ms.contours.Ellipsoid(semi_axes=(a, b, c))), m.ground.contour(ms.contours.Plane()),
                             friction=ms.laws.Coulomb(mu=1.0)))
    res = ms.simulate(m, t_end=2.0, integrator=ms.EventDriven(), output_dt=1e-3)
    quat = res["joint/free/q"][:, 3:7]
    theta = 2 * np.arctan2(quat[:, 2], quat[:, 0])  # rotation about y
    k = np.where((theta[:-1] > 0) & (theta[1:] <= 0))[0]
    tc = res.t[k] + (res.t[k + 1] - res.t[k]) * theta[k] / (theta[k] - theta[k + 1])
    i_y = mass * (a * a + c * c) / 5
    omega = math.sqrt(mass * G * (a * a / c - c) / (i_y + mass * c * c))
    assert np.diff(tc).mean() == pytest.approx(2 * math.pi / omega, rel=1e-3)
    assert set(res["contact/floor/state"].tolist()) == {1}
    assert np.ptp(res["energy/total"]) < 1e-8


def test_a_ball_dropped_on_an_ellipsoidal_dome_bounces_off_its_surface_normal():
    # a fixed ellipsoid (semi-axes a, b, c) and a ball dropped off-centre: the impact happens where
    # the ball's centre reaches the surface offset by r, the normal is the ellipsoid's there
    a, b, c, r = 0.4, 0.3, 0.2, 0.05
    m = ms.Model("dome", gravity=(0.0, 0.0, -G))
    ball = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, r))
    x0, y0 = 0.1, 0.05
    m.add_joint(ms.joints.Free("free", m.ground, ball, q0=[x0, y0, 0.5, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("dome", ball.contour(ms.contours.Sphere(radius=r)),
                             m.ground.contour(ms.contours.Ellipsoid(semi_axes=(a, b, c))), impact=ms.laws.Newton(eps=1.0)))
    res = ms.simulate(m, t_end=0.4, integrator=ms.EventDriven(), output_dt=1e-3)
    impacts = [e for e in res.events if e["event"] == "impact"]
    assert impacts
    t_hit = impacts[0]["t"]
    # reference, independent of the engine's search: the height where the ball's centre is r from
    # the ellipsoid, the distance by a dense grid of the surface's angles refined by scipy
    from scipy.optimize import brentq, minimize

    def distance(z):
        p = np.array([x0, y0, z])
        pt = lambda w: np.array([a * np.cos(w[0]) * np.cos(w[1]), b * np.sin(w[0]) * np.cos(w[1]), c * np.sin(w[1])])
        uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 181), np.linspace(-np.pi / 2, np.pi / 2, 91))
        d = (x0 - a * np.cos(uu) * np.cos(vv)) ** 2 + (y0 - b * np.sin(uu) * np.cos(vv)) ** 2 + (z - c * np.sin(vv)) ** 2
        k = np.unravel_index(np.argmin(d), d.shape)
        res = minimize(lambda w: np.sum((p - pt(w)) ** 2), [uu[k], vv[k]], method="Nelder-Mead",
                       options={"xatol": 1e-14, "fatol": 1e-30, "maxiter": 4000})
        return math.sqrt(res.fun)

    z_hit = brentq(lambda z: distance(z) - r, c + 1e-6, 0.5, xtol=1e-13)
    g = ms.dynamics.contact_geometry
    assert 0.5 - 0.5 * G * t_hit**2 == pytest.approx(z_hit, abs=1e-9)
    # the geometry at the hit: normal along the ellipsoid's gradient at the foot point
    geo = g(m, [x0, y0, z_hit, 1.0, 0.0, 0.0, 0.0])
    p2 = geo["point2"][0]
    grad = np.array([p2[0] / a**2, p2[1] / b**2, p2[2] / c**2])
    assert np.allclose(geo["normal"][0], grad / np.linalg.norm(grad), atol=1e-12)
    assert (p2[0] / a) ** 2 + (p2[1] / b) ** 2 + (p2[2] / c) ** 2 == pytest.approx(1.0, abs=1e-12)
    # elastic: energy kept through the impact
    assert np.ptp(res["energy/total"]) < 1e-8


def test_event_driven_steps_do_not_tunnel_through_a_closed_contour():
    # free fall is a polynomial: the error estimate is zero and the step would grow past the
    # whole passage through a fixed ball (whose gap is positive again below it); the step cap
    # from the predicted gap makes the crossing a sign change the event search finds
    m = ms.Model("drop", gravity=(0.0, 0.0, -G))
    ball = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, 0.05))
    m.add_joint(ms.joints.Free("free", m.ground, ball, q0=[0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("hit", ball.contour(ms.contours.Sphere(radius=0.05)), m.ground.contour(ms.contours.Sphere(radius=0.2)),
                             impact=ms.laws.Newton(eps=1.0)))
    res = ms.simulate(m, t_end=0.6, integrator=ms.EventDriven(), output_dt=1e-2)
    hits = [e["t"] for e in res.events if e["event"] == "impact"]
    assert hits and hits[0] == pytest.approx(math.sqrt(2 * (0.5 - 0.25) / G), rel=1e-9)
    assert res["contact/hit/g_n"].min() > -1e-9


def test_a_wheel_rolls_down_an_incline_with_the_closed_form_acceleration():
    # a torus rim (R = 0.3, tube 0.01) rolling without slip down a 10° slope: a = g sin α / (1 + I / (m r²))
    # with the rolling radius r = R + tube; I = m r² / 2 (a uniform disc of that radius)
    R, tube, mass, alpha = 0.3, 0.01, 2.0, math.radians(10.0)
    r = R + tube
    m = ms.Model("wheel", gravity=(G * math.sin(alpha), 0.0, -G * math.cos(alpha)))  # the slope is the x-y plane
    wheel = m.add_body("wheel", mass, ms.inertia.cylinder(mass, r, 0.02, axis="y"))
    m.add_joint(ms.joints.Free("free", m.ground, wheel, q0=[0.0, 0.0, r, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("road", wheel.contour(ms.contours.Torus(radius=R, tube=tube, axis=(0, 1, 0))),
                             m.ground.contour(ms.contours.Plane()), friction=ms.laws.Coulomb(mu=0.8)))
    res = ms.simulate(m, t_end=1.0, integrator=ms.EventDriven(), output_dt=1e-2)
    a = G * math.sin(alpha) / 1.5
    x = res["joint/free/q"][:, 0]
    assert np.abs(x - 0.5 * a * res.t**2).max() < 1e-8
    assert set(res["contact/road/state"].tolist()) == {1}
    # rolling: the wheel turns at v / r about its axle (the contact frame's rolling velocity)
    v = res["body/wheel/velocity"][:, 0]  # world components (u of a free joint is in the body frame)
    assert np.allclose(np.linalg.norm(res["contact/road/rolling"], axis=1), np.abs(v) / r, atol=1e-8)
    assert np.abs(res["contact/road/spin"]).max() < 1e-10
    assert res["contact/road/lambda_n"][-1] == pytest.approx(mass * G * math.cos(alpha), rel=1e-9)
