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


# ---- surfaces of revolution and spline patches ------------------------------------------------

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


def _on_ground(contour1, contour2, q0=(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0), name="c") -> ms.Model:
    m = ms.Model("s", gravity=(0.0, 0.0, -9.81))
    b = m.add_body("b", 1.0, ms.inertia.sphere(1.0, 0.1))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=list(q0)))
    m.add_contact(ms.Contact(name, b.contour(contour1), m.ground.contour(contour2)))
    return m


def test_revolution_of_an_ellipse_is_the_ellipsoid_of_revolution_on_a_plane():
    """An elliptical profile (a across, b along the axis) turned about the axis is a spheroid: on
    a plane, tipped by t, its centre is √(b² cos² t + a² sin² t) above the contact, the support
    point's curvatures are those of the spheroid there (closed forms of the ellipse)."""
    a, b = 0.1, 0.25
    egg = ms.contours.Revolution(profile=ms.contours.Ellipse(a=a, b=b))
    floor = ms.contours.Plane(normal=(0, 0, 1))
    for t in (0.0, 0.3, 1.0, math.pi / 2):
        q = [0.0, 0.0, 0.7, math.cos(t / 2), math.sin(t / 2), 0.0, 0.0]
        g = ms.dynamics.contact_geometry(_on_ground(egg, floor), q)
        h = math.sqrt((b * math.cos(t)) ** 2 + (a * math.sin(t)) ** 2)
        assert g["gap"][0] == pytest.approx(0.7 - h, abs=1e-12)
        if t == 0.0:
            # the pole: both curvatures b / a²
            assert g["curvature1"][0] == pytest.approx([b / a**2, b / a**2], rel=1e-9)
        if t == math.pi / 2:
            # the equator: meridian a / b², parallel 1 / a
            assert sorted(g["curvature1"][0]) == pytest.approx(sorted([a / b**2, 1 / a]), rel=1e-9)


def test_ball_on_a_patch_sampled_from_a_sphere_reproduces_gap_and_curvature():
    R = 0.8
    cap = ms.contours.Patch.from_function(lambda x, y: (x, y, math.sqrt(R * R - x * x - y * y)), (-0.4, 0.4), (-0.4, 0.4), 33, 33)
    ball = ms.contours.Sphere(radius=0.05)
    q = [0.03, -0.02, 1.2, 1.0, 0.0, 0.0, 0.0]
    g = ms.dynamics.contact_geometry(_on_ground(ball, cap), q)
    c = np.array(q[:3])
    assert g["gap"][0] == pytest.approx(np.linalg.norm(c) - R - 0.05, abs=1e-7)
    assert np.allclose(g["normal"][0], c / np.linalg.norm(c), atol=1e-6)
    assert g["curvature2"][0] == pytest.approx([1 / R, 1 / R], rel=1e-3)
    # the ball rests on the cap's top: lambda_N = m g once it has settled
    m = _on_ground(ball, cap, q0=(0.0, 0.0, R + 0.05 + 0.01, 1.0, 0.0, 0.0, 0.0))
    res = ms.simulate(m, t_end=0.3, integrator=ms.EventDriven(), output_dt=1e-2)
    assert res["contact/c/lambda_n"][-1] == pytest.approx(9.81, rel=1e-6)
    assert np.all(np.isfinite(res["contact/c/spin"])) and res["contact/c/rolling"].shape[1] == 2


def test_model_file_revolution_and_patch(tmp_path):
    text = """
name = "surfaces"
gravity = [0.0, 0.0, -9.81]

[[bodies]]
name = "egg"
mass = 1.0
inertia = [0.01, 0.01, 0.01]

[[bodies]]
name = "ball"
mass = 1.0
inertia = [0.01, 0.01, 0.01]

[[joints]]
name = "egg"
type = "free"
parent = "ground"
child = "egg"
q0 = [0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0]

[[joints]]
name = "ball"
type = "free"
parent = "ground"
child = "ball"
q0 = [0.2, 0.3, 0.5, 1.0, 0.0, 0.0, 0.0]

[[contacts]]
name = "floor"
body1 = "egg"
body2 = "ground"
contour1 = { type = "revolution", profile = { type = "ellipse", semi_axes = [0.1, 0.2] } }
contour2 = { type = "plane", normal = [0.0, 0.0, 1.0] }

[[contacts]]
name = "terrain"
body1 = "ball"
body2 = "ground"
contour1 = { type = "sphere", radius = 0.1 }
contour2 = { type = "patch", range1 = [-1.0, 1.0], range2 = [-1.0, 1.0], points = [
  [[-1.0, -1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, 1.0, 0.0]],
  [[0.0, -1.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
  [[1.0, -1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]] ] }
"""
    p = tmp_path / "m.toml"
    p.write_text(text)
    from mechsys.modelfile import load_model

    m, _ = load_model(p)
    g = ms.dynamics.contact_geometry(m, [0.0, 0.0, 0.5, 1, 0, 0, 0, 0.2, 0.3, 0.5, 1, 0, 0, 0])
    assert g["gap"] == pytest.approx([0.3, 0.4], abs=1e-12)


@pytest.mark.parametrize(
    "contour, message",
    [
        (ms.contours.Revolution(profile=ms.contours.Ellipse(a=0.1, b=0.2, center=(0.05, 0.0, 0.0))), "revolution profile crosses the axis"),
        (ms.contours.Revolution(profile=ms.contours.Ellipse(a=0.0, b=0.2)), "semi-axis a must be > 0"),
        (ms.contours.Revolution(profile=ms.contours.Circle(radius=0.1)), "expected a mechsys.contours Ellipse, Spline or Cam"),
        (ms.contours.Patch(points=[[(0, 0, 0), (0, 1, 0)], [(1, 0, 0), (1, 1, float("nan"))]]), r"points\[1\]\[1\]: must be finite"),
        (ms.contours.Patch(points=[[(0, 0, 0), (0, 1, 0)], [(1, 0, 0)]]), "rectangular: row 1 has 1 points"),
        (ms.contours.Patch(points=[[(0, 0, 0), (0, 1)], [(1, 0, 0), (1, 1, 0)]]), r"points\[0\]\[1\]: expected three numbers"),
        (ms.contours.Patch(points=[[(0, 0, 0), (0, 0, 0)], [(1, 0, 0), (1, 1, 0)]]), r"patch has no normal at \(s1, s2\) = \(0.0000"),
        (ms.contours.Patch(points=[[(0, 0, 0), (0, 1, 0)], [(1, 0, 0), (1, 1, 0)], [(2, 0, 0), (2, 1, 0)], [(3, 0, 0), (3, 1, 0)]],
                           periodic=(True, False)), "last row does not repeat the first"),
    ],
)
def test_bad_surfaces_name_the_contact_and_contour(contour, message):
    m = _on_ground(ms.contours.Sphere(radius=0.1), contour, name="terrain")
    with pytest.raises(ms.ModelError, match=rf"terrain.*contour2.*{message}|{message}"):
        m.build()
    # the message names the contact
    with pytest.raises(ms.ModelError, match="terrain"):
        m.build()


def test_patch_from_function_errors_name_the_function_and_point():
    with pytest.raises(ms.ModelError, match=r"surface function raised at \(s1, s2\) = \(0.0, 0.0\): ZeroDivisionError"):
        ms.contours.Patch.from_function(lambda x, y: (x, y, 1 / (x * x + y * y)), (0, 1), (0, 1), 3, 3)
    with pytest.raises(ms.ModelError, match="three finite numbers"):
        ms.contours.Patch.from_function(lambda x, y: (x, y, float("nan")), (0, 1), (0, 1), 3, 3)
    with pytest.raises(ms.ModelError, match="n1 must be a whole number"):
        ms.contours.Patch.from_function(lambda x, y: (x, y, 0.0), (0, 1), (0, 1), 1, 3)


def test_egg_and_bowl_example_rocks_and_rolls_at_the_closed_form_periods():
    ns = __import__("runpy").run_path(str(ROOT / "examples" / "egg_and_bowl.py"))
    res = ms.simulate(ns["model"], **ns["simulation"])
    egg_t, ball_t = ns["expected_periods"]()
    assert ns["period"](res.t, res["joint/egg/q"][:, 0]) == pytest.approx(egg_t, rel=5e-3)
    assert ns["period"](res.t, res["joint/ball/q"][:, 0]) == pytest.approx(ball_t, rel=1e-3)
    assert np.ptp(res["energy/total"]) < 1e-8
    assert set(res["contact/floor/state"].tolist()) == {1} and set(res["contact/bowl/state"].tolist()) == {1}


def test_patch_takes_a_numpy_grid_and_a_periodic_direction():
    """A cylinder of radius R about z as an (n1, n2, 3) array, periodic around it: a ball's gap is
    ρ − R − r to the spline's accuracy (16 cells around: about 5e-5)."""
    R, n = 0.5, 17
    t = np.linspace(0, 2 * np.pi, n)
    z = np.linspace(-1, 1, 9)
    grid = np.stack([R * np.cos(t)[:, None] + 0 * z, R * np.sin(t)[:, None] + 0 * z, 0 * t[:, None] + z], axis=-1)
    grid[-1] = grid[0]  # close the period exactly
    cyl = ms.contours.Patch(points=grid, range1=(0, 2 * np.pi), range2=(-1, 1), periodic=(True, False))
    q = [0.4, 0.6, 0.1, 1.0, 0.0, 0.0, 0.0]
    g = ms.dynamics.contact_geometry(_on_ground(ms.contours.Sphere(radius=0.05), cyl), q)
    assert g["gap"][0] == pytest.approx(math.hypot(0.4, 0.6) - R - 0.05, abs=2e-4)
    assert g["normal"][0] == pytest.approx([0.4 / math.hypot(0.4, 0.6), 0.6 / math.hypot(0.4, 0.6), 0.0], abs=1e-3)


def test_ellipsoid_on_a_saddle_patch_touches_where_the_normals_oppose():
    """An ellipsoid above a saddle z = (x² − y²) / 4: at the witness points the patch normal
    (from the analytic saddle) and the ellipsoid's normal (from its quadric) are opposite and
    along the connecting vector; the gap is the distance along it."""
    saddle = ms.contours.Patch.from_function(lambda x, y: (x, y, (x * x - y * y) / 4), (-1, 1), (-1, 1), 41, 41)
    egg = ms.contours.Ellipsoid(semi_axes=(0.2, 0.12, 0.1), cardan=(0.3, 0.2, 0.0))
    q = [0.1, -0.05, 0.3, math.cos(0.2), 0.0, math.sin(0.2), 0.0]
    g = ms.dynamics.contact_geometry(_on_ground(egg, saddle), q)
    p1, p2, n, gap = g["point1"][0], g["point2"][0], g["normal"][0], g["gap"][0]
    x, y = p2[0], p2[1]
    assert p2[2] == pytest.approx((x * x - y * y) / 4, abs=1e-7)
    ns = np.array([-x / 2, y / 2, 1.0]) / np.linalg.norm([-x / 2, y / 2, 1.0])
    assert np.allclose(n, ns, atol=1e-6)
    # the ellipsoid's outward normal at p1 is -n: the gradient of its quadric
    R = _rot(q[3:7]) @ Rotation.from_euler("XYZ", [0.3, 0.2, 0.0]).as_matrix()
    yb = R.T @ (p1 - np.array(q[:3]))
    assert np.sum((yb / [0.2, 0.12, 0.1]) ** 2) == pytest.approx(1.0, abs=1e-12)
    grad = R @ (yb / np.array([0.2, 0.12, 0.1]) ** 2)
    assert np.allclose(-grad / np.linalg.norm(grad), n, atol=1e-9)
    assert np.allclose(p1 - p2, gap * n, atol=1e-12)
