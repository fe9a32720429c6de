"""Hertz contact between two doubly curved contours (issue 19, item 4): the relative curvature
tensor at the contact point, summed from both contours' curvatures in the common tangent plane,
gives Hertz's A and B whatever the angle between their principal directions. Checked on two
crossed capsules (cylinders with spherical ends): at 90° they are a sphere of radius R on a plane,
and at other angles the impact follows Hertz's elliptic-integral solution computed here with
SciPy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

import mechsys as ms

STEEL = ms.Material(E=2.1e11, nu=0.3, density=7800.0)
E_STAR = 1.0 / (2.0 * (1 - 0.3**2) / 2.1e11)
MASS, V0, GAP = 0.05, 1.0, 2e-4


def crossed(angle: float, r1: float, r2: float, rigid: bool = False) -> ms.Model:
    """A capsule of radius r2 whose axis makes `angle` with that of a fixed capsule of radius r1
    (along x), falling onto it at V0 (no gravity); Hertz's law, or with ``rigid`` Signorini's
    with a Newton impact e = 1."""
    m = ms.Model("crossed", gravity=(0, 0, 0))
    b = m.add_body("rod", MASS, ms.inertia.sphere(MASS, r2))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=r1 + r2 + GAP, u0=-V0))
    d = np.array([math.cos(angle), math.sin(angle), 0.0]) * 0.1
    m.add_contact(ms.Contact("cross", b.contour(ms.contours.Capsule(a=tuple(-d), b=tuple(d), radius=r2), material=STEEL),
                             m.ground.contour(ms.contours.Capsule(a=(-0.1, 0, 0), b=(0.1, 0, 0), radius=r1), material=STEEL),
                             **({"impact": ms.laws.Newton(eps=1.0)} if rigid else {"normal": ms.laws.Hertz()})))
    return m


def hertz_k(a_curv: float, b_curv: float) -> float:
    """K in F = K delta^1.5 for relative curvatures A <= B: the eccentricity from
    B/A = (E(e)/(1 - e^2) - K(e)) / (K(e) - E(e)), then delta = 3 F K(e) / (2 pi a E*) with
    a^3 = 3 F (K(e) - E(e)) / (2 pi E* A e^2)."""
    if b_curv / a_curv < 1 + 1e-12:
        return 4 / 3 * E_STAR * math.sqrt(1 / (a_curv + b_curv))
    ratio = lambda m: (ellipe(m) / (1 - m) - ellipk(m)) / (ellipk(m) - ellipe(m)) - b_curv / a_curv
    m = brentq(ratio, 1e-12, 1 - 1e-15, xtol=1e-16, rtol=1e-15)
    k, e = ellipk(m), ellipe(m)
    # delta = c F^(2/3)
    c = 3 * k / (2 * math.pi * E_STAR) * (2 * math.pi * E_STAR * a_curv * m / (3 * (k - e))) ** (1 / 3)
    return c ** -1.5


def delta_max(model: ms.Model) -> tuple[float, float]:
    res = ms.simulate(model, t_end=GAP / V0 + 3e-4, output_dt=5e-9, integrator=ms.DOPRI5(rtol=1e-12, atol=1e-16),
                      progress=False)
    d = res["contact/cross/overlap"]
    j = int(np.argmax(d))
    y0, y1, y2 = d[j - 1], d[j], d[j + 1]
    return y1 - 0.125 * (y2 - y0) ** 2 / (y0 - 2 * y1 + y2), res["joint/z/u"][-1]


def test_crossed_capsules_at_right_angles_are_a_sphere_on_a_plane():
    """Equal radii R at 90°: A = B = 1/(2R), the sphere of radius R on a plane."""
    r = 0.01
    k = 4 / 3 * E_STAR * math.sqrt(r)
    d, u = delta_max(crossed(math.pi / 2, r, r))
    assert d == pytest.approx((1.25 * MASS * V0**2 / k) ** 0.4, rel=1e-6)
    assert u == pytest.approx(V0, rel=1e-8)


@pytest.mark.parametrize("angle, r1, r2", [(math.radians(30), 0.01, 0.01), (math.radians(60), 0.01, 0.02),
                                           (math.pi / 2, 0.01, 0.03)])
def test_crossed_capsules_at_an_angle_follow_the_elliptic_solution(angle, r1, r2):
    """A + B = (1/R1 + 1/R2)/2, B - A = (1/2) sqrt(1/R1^2 + 1/R2^2 + 2 cos(2 angle)/(R1 R2))."""
    s = 0.5 * (1 / r1 + 1 / r2)
    dif = 0.5 * math.sqrt(1 / r1**2 + 1 / r2**2 + 2 * math.cos(2 * angle) / (r1 * r2))
    a_curv, b_curv = 0.5 * (s - dif), 0.5 * (s + dif)
    k = hertz_k(a_curv, b_curv)
    d, u = delta_max(crossed(angle, r1, r2))
    assert d == pytest.approx((1.25 * MASS * V0**2 / k) ** 0.4, rel=1e-6)
    assert u == pytest.approx(V0, rel=1e-8)
    # the crossing angle matters: at 30° the contact is stiffer along the rods than at 90°
    if angle < math.pi / 4:
        d90, _ = delta_max(crossed(math.pi / 2, r1, r2))
        assert d < d90


def test_parallel_capsules_are_refused_at_the_contact_not_silently():
    """Parallel axes touch along a line (A = 0): no Hertz point contact, a clear error naming it."""
    with pytest.raises(ms.SolverError, match="cross.*conforming or flat"):
        ms.simulate(crossed(0.0, 0.01, 0.01), t_end=GAP / V0 + 1e-4, integrator=ms.DOPRI5(rtol=1e-8), progress=False)


def test_hertz_impact_post_processing_takes_the_crossing_angle():
    """ms.hertz.impact with each rod's curvatures (1/R, 0) and the crossing angle gives the
    compliant run's delta_max (and, at angle 0, the old aligned result)."""
    r1, r2, angle = 0.01, 0.02, math.radians(60)
    d, _ = delta_max(crossed(angle, r1, r2))
    row = ms.hertz.impact(MASS, V0, E_STAR, (1 / r1, 0.0), (1 / r2, 0.0), angle=angle)
    assert row["delta_max"] == pytest.approx(d, rel=1e-6)
    # aligned directions (the default): A, B are the half sums of the matching curvatures
    aligned = ms.hertz.impact(MASS, V0, E_STAR, (100.0, 20.0), (50.0, 5.0))
    assert aligned["stiffness"] == pytest.approx(hertz_k(12.5, 75.0), rel=1e-9)
    # parallel rods touch along a line: refused
    with pytest.raises(ms.ModelError, match="flat or conforming"):
        ms.hertz.impact(MASS, V0, E_STAR, (1 / r1, 0.0), (1 / r2, 0.0))
    with pytest.raises(ms.ModelError, match="angle"):
        ms.hertz.impact(MASS, V0, E_STAR, (1 / r1, 0.0), (1 / r2, 0.0), angle=float("nan"))


def test_rigid_impact_of_crossed_rods_post_processed_at_their_angle():
    """ms.hertz.impacts on a rigid e = 1 run of rods crossed at 60 degrees takes the angle from the
    contact geometry (the summed curvature tensor, dynamics.contact_geometry's
    relative_curvature) and gives the compliant run's delta_max."""
    r1, r2, angle = 0.01, 0.02, math.radians(60)
    m = crossed(angle, r1, r2, rigid=True)
    rigid = ms.simulate(m, t_end=GAP / V0 + 1e-4, output_dt=1e-5, integrator=ms.EventDriven(), progress=False)
    rows = ms.hertz.impacts(rigid, m)
    assert len(rows) == 1
    d, _ = delta_max(crossed(angle, r1, r2))
    assert rows[0]["delta_max"] == pytest.approx(d, rel=1e-6)
    # the angle matters: the same rods crossed at right angles approach by a different amount
    right = ms.hertz.impact(MASS, V0, E_STAR, (1 / r1, 0.0), (1 / r2, 0.0), angle=math.pi / 2)
    assert abs(right["delta_max"] / d - 1) > 1e-2
    geo = ms.dynamics.contact_geometry(m, [r1 + r2])
    s = 1 / r1 + 1 / r2
    dif = math.sqrt(1 / r1**2 + 1 / r2**2 + 2 * math.cos(2 * angle) / (r1 * r2))
    np.testing.assert_allclose(geo["relative_curvature"][0], [0.5 * (s - dif), 0.5 * (s + dif)], rtol=1e-12)
