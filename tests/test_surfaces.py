"""Spatial parametric surfaces (issue 14, part 3): ellipsoid–ellipsoid gaps against independent
high-precision solutions, surfaces of revolution and spline patches against closed forms."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

import mechsys as ms


def _two_ellipsoids(a1, a2, cardan1=(0, 0, 0), cardan2=(0, 0, 0)) -> ms.Model:
    m = ms.Model("ee")
    b1 = m.add_body("b1", 1.0, ms.inertia.sphere(1.0, 0.1))
    b2 = m.add_body("b2", 1.0, ms.inertia.sphere(1.0, 0.1))
    m.add_joint(ms.joints.Free("f1", m.ground, b1))
    m.add_joint(ms.joints.Free("f2", m.ground, b2))
    m.add_contact(ms.Contact("ee", b1.contour(ms.contours.Ellipsoid(semi_axes=a1, cardan=cardan1)),
                             b2.contour(ms.contours.Ellipsoid(semi_axes=a2, cardan=cardan2))))
    return m


def _rot(quat_wxyz):
    w, x, y, z = quat_wxyz
    return Rotation.from_quat([x, y, z, w]).as_matrix()


def _surface(a, R, c, u, v):
    """A point of the ellipsoid with semi-axes a, world rotation R and centre c at angles u, v."""
    return c + R @ np.array([a[0] * math.cos(u) * math.cos(v), a[1] * math.sin(u) * math.cos(v), a[2] * math.sin(v)])


def _case(rng, separated: bool):
    a1, a2 = rng.uniform(0.1, 0.4, 3), rng.uniform(0.1, 0.4, 3)
    q1, q2 = Rotation.random(random_state=rng).as_quat(), Rotation.random(random_state=rng).as_quat()
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    dist = rng.uniform(0.7, 1.0) if separated else rng.uniform(0.05, 0.25)
    c1, c2 = d * dist, np.zeros(3)
    wxyz = lambda q: [q[3], q[0], q[1], q[2]]  # noqa: E731
    q = np.concatenate([c1, wxyz(q1), c2, wxyz(q2)])
    return a1, a2, q


def test_separated_ellipsoid_gaps_match_a_multistart_minimization_of_the_distance():
    rng = np.random.default_rng(7)
    m = None
    done = 0
    while done < 12:
        a1, a2, q = _case(rng, True)
        m = _two_ellipsoids(a1, a2)
        g = ms.dynamics.contact_geometry(m, q)
        R1, R2 = _rot(q[3:7]), _rot(q[10:14])
        c1, c2 = q[:3], q[7:10]
        if g["gap"][0] < 0.01:
            continue
        f = lambda p: np.sum((_surface(a1, R1, c1, p[0], p[1]) - _surface(a2, R2, c2, p[2], p[3])) ** 2)  # noqa: E731
        best = math.inf
        for u1 in np.linspace(0, 2 * np.pi, 6, endpoint=False):
            for u2 in np.linspace(0, 2 * np.pi, 6, endpoint=False):
                for v in (-0.8, 0.0, 0.8):
                    r = minimize(f, [u1, v, u2, -v], method="BFGS", options={"gtol": 1e-14})
                    best = min(best, r.fun)
        assert g["gap"][0] == pytest.approx(math.sqrt(best), abs=1e-9)
        # the witness points lie on the surfaces and along the normal
        assert np.allclose(g["point1"][0] - g["point2"][0], g["gap"][0] * g["normal"][0], atol=1e-12)
        done += 1


def test_overlapping_ellipsoids_satisfy_the_contact_conditions_at_30_digits_and_give_the_minimum_translation():
    """Overlap: the engine's witness angles seed an mpmath root solve of eqs. 2.120 at 30 digits
    (the common normal), and the gap is the largest separating-axis gap over all directions
    (the minimum translation that separates the solids), from a multistart maximization."""
    mp.mp.dps = 30
    rng = np.random.default_rng(11)
    for _ in range(8):
        a1, a2, q = _case(rng, False)
        g = ms.dynamics.contact_geometry(_two_ellipsoids(a1, a2), q)
        gap = g["gap"][0]
        assert gap < 0
        R1, R2 = _rot(q[3:7]), _rot(q[10:14])
        c1, c2 = q[:3], q[7:10]
        # angles of the witness points
        def angles(p, a, R, c):
            y = R.T @ (p - c) / a
            return math.atan2(y[1], y[0]), math.asin(max(-1.0, min(1.0, y[2])))
        u1, v1 = angles(g["point1"][0], a1, R1, c1)
        u2, v2 = angles(g["point2"][0], a2, R2, c2)
        A1, A2 = mp.matrix(R1.tolist()), mp.matrix(R2.tolist())
        C1, C2 = mp.matrix(c1.tolist()), mp.matrix(c2.tolist())

        def geo(a, A, C, u, v):
            x = C + A * mp.matrix([a[0] * mp.cos(u) * mp.cos(v), a[1] * mp.sin(u) * mp.cos(v), a[2] * mp.sin(v)])
            s = A * mp.matrix([-a[0] * mp.sin(u) * mp.cos(v), a[1] * mp.cos(u) * mp.cos(v), 0])
            t = A * mp.matrix([-a[0] * mp.cos(u) * mp.sin(v), -a[1] * mp.sin(u) * mp.sin(v), a[2] * mp.cos(v)])
            return x, s, t

        def cross(p, q):
            return mp.matrix([p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]])

        def dot(p, q):
            return sum(p[i] * q[i] for i in range(3))

        def conditions(U1, V1, U2, V2):
            x1, s1, t1 = geo(a1, A1, C1, U1, V1)
            x2, s2, t2 = geo(a2, A2, C2, U2, V2)
            n1 = cross(s1, t1)
            rd = x1 - x2
            # eq. 2.120: n1 ⟂ s2, t2 and r_D ⟂ s2, t2
            return [dot(n1, s2), dot(n1, t2), dot(rd, s2), dot(rd, t2)]

        root = mp.findroot(conditions, (u1, v1, u2, v2), tol=mp.mpf(10) ** -28)
        x1, s1, t1 = geo(a1, A1, C1, *root[:2])
        x2, _, _ = geo(a2, A2, C2, *root[2:])
        n1 = cross(s1, t1)
        n1 = n1 / mp.sqrt(dot(n1, n1))
        g_ref = float(dot(n1, x2 - x1))  # n1 outward on body 1 points towards body 2
        assert gap == pytest.approx(g_ref, abs=1e-9)
        assert np.allclose(np.array([float(v) for v in x1]), g["point1"][0], atol=1e-8)

        # the largest separating-axis gap f(n) = n·(c1 - c2) - h1 - h2 over directions n
        S1 = R1 @ np.diag(np.asarray(a1) ** 2) @ R1.T
        S2 = R2 @ np.diag(np.asarray(a2) ** 2) @ R2.T

        def f(p):
            n = np.array([math.cos(p[0]) * math.cos(p[1]), math.sin(p[0]) * math.cos(p[1]), math.sin(p[1])])
            return -(n @ (c1 - c2) - math.sqrt(n @ S1 @ n) - math.sqrt(n @ S2 @ n))

        best = min(minimize(f, [u, v], method="Nelder-Mead", options={"xatol": 1e-13, "fatol": 1e-15, "maxiter": 4000}).fun
                   for u in np.linspace(-np.pi, np.pi, 8, endpoint=False) for v in (-1.0, 0.0, 1.0))
        assert gap == pytest.approx(-best, abs=1e-9)
