"""Compliant contact (issue 19): Hertz, Johnson, the dissipative Hertz laws, friction of compliant
contacts and the Hertz post-processing of rigid impacts, against closed forms and independent
SciPy integrations written here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk, gamma

import mechsys as ms

STEEL = ms.Material(E=2.1e11, nu=0.3, density=7800.0)
R = 0.01
MASS = 7800.0 * 4.0 / 3.0 * math.pi * R**3
E_STAR = 1.0 / (2.0 * (1 - 0.3**2) / 2.1e11)
# T v0 / delta_max of an undamped Hertz impact, 2 * int_0^1 dx / sqrt(1 - x^(5/2))
FACTOR = 0.8 * math.sqrt(math.pi) * gamma(0.4) / gamma(0.9)


def peak(t, x):
    """The maximum of sampled x by the parabola through the largest sample and its neighbours."""
    k = int(np.argmax(x))
    y0, y1, y2 = x[k - 1], x[k], x[k + 1]
    d = y0 - 2 * y1 + y2
    return y1 - 0.125 * (y2 - y0) ** 2 / d


def ball_on_plane(law, v0=1.0, gap=2e-4, gravity=0.0, material=STEEL, friction=None):
    m = ms.Model("ball", gravity=(0, 0, -gravity))
    b = m.add_body("ball", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=R + gap, u0=-v0))
    m.add_contact(ms.Contact("c", b.contour(ms.contours.Sphere(radius=R), material=material),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=material), normal=law,
                             friction=friction))
    return m


def hertz_closed_form(m_eff, v0, k):
    d = (1.25 * m_eff * v0**2 / k) ** 0.4
    return d, k * d**1.5, FACTOR * d / v0


def contact_times(res, name="c"):
    close = [e["t"] for e in res.events if e["contact"] == name and e["event"] == "close"]
    opened = [e["t"] for e in res.events if e["contact"] == name and e["event"] == "open"]
    return close, opened


@pytest.mark.parametrize("integrator", [ms.DOPRI5(rtol=1e-12, atol=1e-16), ms.Radau5(rtol=1e-11, atol=1e-16)])
def test_hertz_sphere_plane_impact_against_closed_form(integrator):
    """delta_max = (5 m v0^2 / 4K)^(2/5), F_max = K delta_max^1.5, T = 2.9432 delta_max / v0 with
    K = (4/3) E* sqrt(R); restitution exactly 1; energy conserved; onset and release events."""
    res = ms.simulate(ball_on_plane(ms.laws.Hertz()), t_end=4e-4, output_dt=1e-8, integrator=integrator)
    k = 4.0 / 3.0 * E_STAR * math.sqrt(R)
    d, f, T = hertz_closed_form(MASS, 1.0, k)
    assert peak(res["t"], res["contact/c/overlap"]) == pytest.approx(d, rel=1e-6)
    assert peak(res["t"], res["contact/c/force_n"]) == pytest.approx(f, rel=1e-6)
    close, opened = contact_times(res)
    assert len(close) == 1 and len(opened) == 1
    assert close[0] == pytest.approx(2e-4, rel=1e-9)
    assert opened[0] - close[0] == pytest.approx(T, rel=1e-6)
    assert res["joint/z/u"][-1] == pytest.approx(1.0, rel=1e-8)
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * e[0]
    # during the contact the energy sits in the overlap: E_el = (2/5) K delta^2.5
    i = int(np.argmax(res["contact/c/overlap"]))
    assert res["contact/c/energy_elastic"][i] == pytest.approx(0.4 * k * res["contact/c/overlap"][i] ** 2.5, rel=1e-12)
    assert abs(res["contact/c/energy_dissipated"][-1]) < 1e-10 * e[0]


def test_hertz_sphere_sphere_impact_against_closed_form():
    """Two free balls (radii 10 and 15 mm, different steels) along x: m = m1 m2/(m1 + m2),
    1/R = 1/R1 + 1/R2, E* from both materials; momentum conserved, velocities exchanged as for
    an elastic impact."""
    r2, soft = 0.015, ms.Material(E=7e10, nu=0.33, density=2700.0)
    m2 = 2700.0 * 4 / 3 * math.pi * r2**3
    m = ms.Model("two", gravity=(0, 0, 0))
    a = m.add_body("a", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
    b = m.add_body("b", mass=m2, inertia=ms.inertia.sphere(m2, r2))
    m.add_joint(ms.joints.Prismatic("xa", m.ground, a, axis=(1, 0, 0), q0=0.0, u0=2.0))
    m.add_joint(ms.joints.Prismatic("xb", m.ground, b, axis=(1, 0, 0), q0=R + r2 + 1e-4, u0=0.5))
    m.add_contact(ms.Contact("ab", a.contour(ms.contours.Sphere(radius=R), material=STEEL),
                             b.contour(ms.contours.Sphere(radius=r2), material=soft), normal=ms.laws.Hertz()))
    res = ms.simulate(m, t_end=3e-4, output_dt=1e-8, integrator=ms.DOPRI5(rtol=1e-12, atol=1e-16))
    es = 1 / ((1 - 0.09) / 2.1e11 + (1 - 0.33**2) / 7e10)
    k = 4 / 3 * es * math.sqrt(R * r2 / (R + r2))
    me, v = MASS * m2 / (MASS + m2), 1.5
    d, f, T = hertz_closed_form(me, v, k)
    assert peak(res["t"], res["contact/ab/overlap"]) == pytest.approx(d, rel=1e-6)
    assert peak(res["t"], res["contact/ab/force_n"]) == pytest.approx(f, rel=1e-6)
    close, opened = contact_times(res, "ab")
    assert opened[0] - close[0] == pytest.approx(T, rel=1e-6)
    ua, ub = res["joint/xa/u"][-1], res["joint/xb/u"][-1]
    p0 = MASS * 2.0 + m2 * 0.5
    assert MASS * ua + m2 * ub == pytest.approx(p0, rel=1e-12)
    # elastic: the relative velocity reverses
    assert ub - ua == pytest.approx(1.5, rel=1e-8)


def scipy_restitution(k, alpha_of_v, v0, m=MASS, kv=None):
    """Exit speed over v0 of m x'' = -F(x, x') from x = 0, x' = v0 (x the overlap), F = k x^1.5
    (1 + alpha x') cut at 0 (or Kelvin-Voigt kv = (k, d)), by an independent integration."""
    alpha = alpha_of_v(v0)

    def f(t, y):
        x, xd = y
        if kv is not None:
            F = max(0.0, kv[0] * x + kv[1] * xd)
        else:
            F = max(0.0, k * max(x, 0.0) ** 1.5 * (1 + alpha * xd))
        return [xd, -F / m]

    def out(t, y):
        return y[0]

    out.terminal, out.direction = True, -1
    s = solve_ivp(f, (0, 1.0), [0.0, v0], rtol=1e-12, atol=1e-18, events=out, method="DOP853",
                  first_step=1e-10)
    return -s.y_events[0][0][1] / v0


@pytest.mark.parametrize("law,alpha", [
    (ms.laws.HuntCrossley(eps=0.5), lambda v: 1.5 * 0.5 / v),
    (ms.laws.LankaraniNikravesh(eps=0.5), lambda v: 0.75 * (1 - 0.25) / v),
    (ms.laws.Flores(eps=0.5), lambda v: 1.6 * 0.5 / 0.5 / v),
    (ms.laws.HuntCrossley(alpha=0.4), lambda v: 0.4),
])
def test_dissipative_laws_restitution_against_scipy(law, alpha):
    """The restitution each damped Hertz law achieves (not exactly its eps: each mapping rests
    on its own approximation) against an independent high-accuracy integration; the dissipated
    energy signal closes the energy balance."""
    res = ms.simulate(ball_on_plane(law), t_end=4e-4, output_dt=1e-6, integrator=ms.DOPRI5(rtol=1e-12, atol=1e-16))
    k = 4 / 3 * E_STAR * math.sqrt(R)
    e_ref = scipy_restitution(k, alpha, 1.0)
    e = res["joint/z/u"][-1] / 1.0
    assert e == pytest.approx(e_ref, rel=1e-7)
    ke0 = 0.5 * MASS
    assert res["contact/c/energy_dissipated"][-1] == pytest.approx(ke0 * (1 - e * e), rel=1e-7)
    assert res["energy/dissipated"][-1] == pytest.approx(ke0 * (1 - e * e), rel=1e-7)
    if getattr(law, "eps", None) is not None:
        # the mappings are approximations: what each achieves at eps = 0.5 (as documented)
        documented = {"HuntCrossley": 0.663, "LankaraniNikravesh": 0.725, "Flores": 0.470}[type(law).__name__]
        assert e == pytest.approx(documented, abs=5e-4)


def test_kelvin_voigt_restitution_and_cutoff_against_scipy():
    """Kelvin-Voigt with the non-adhesive cut-off: the force reaches zero before the gap opens
    (a switch located by the scheme); restitution against SciPy."""
    kk, dd = 1e7, 20.0
    res = ms.simulate(ball_on_plane(ms.laws.KelvinVoigt(k=kk, d=dd)), t_end=2e-3, output_dt=1e-6,
                      integrator=ms.DOPRI5(rtol=1e-12, atol=1e-16))
    e_ref = scipy_restitution(0, lambda v: 0.0, 1.0, kv=(kk, dd))
    assert res["joint/z/u"][-1] == pytest.approx(e_ref, rel=1e-7)
    assert np.all(res["contact/c/force_n"] >= 0)


def test_ball_drop_keeps_its_apex_over_ten_bounces():
    """Undamped Hertz: the apex after each of 10 bounces equals the drop height to 1e-8 of it
    (the flight is a parabola: the apex from three samples around it is exact)."""
    h = 0.05
    m = ball_on_plane(ms.laws.Hertz(), v0=0.0, gap=h, gravity=9.81)
    T0 = 2 * math.sqrt(2 * h / 9.81)
    res = ms.simulate(m, t_end=10.5 * T0, output_dt=1e-4, integrator=ms.DOPRI5(rtol=1e-13, atol=1e-16))
    z = res["joint/z/q"] - R
    t = res["t"]
    apex = [peak(t[i - 2:i + 3], z[i - 2:i + 3]) for i in range(2, len(z) - 2)
            if z[i] >= z[i - 1] and z[i] > z[i + 1] and z[i] > 0.5 * h]
    assert len(apex) >= 10
    np.testing.assert_allclose(apex[:10], h, rtol=0, atol=1e-8 * h)
    close, _ = contact_times(res)
    assert len(close) >= 10


def test_bounce_period_tends_to_the_rigid_one_like_e_to_the_minus_two_fifths():
    """As E grows the period between onsets tends to the rigid 2 sqrt(2h/g); the error (about
    the contact duration, proportional to K^(-2/5)) falls like E^(-2/5) over three decades."""
    h = 0.01
    T0 = 2 * math.sqrt(2 * h / 9.81)
    errs = []
    moduli = [2.1e7, 2.1e8, 2.1e9, 2.1e10]
    for e_mod in moduli:
        mat = ms.Material(E=e_mod, nu=0.3, density=7800.0)
        m = ball_on_plane(ms.laws.Hertz(), v0=0.0, gap=h, gravity=9.81, material=mat)
        res = ms.simulate(m, t_end=2.2 * T0, output_dt=1e-3, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-15))
        close, _ = contact_times(res)
        errs.append(close[1] - close[0] - T0)
    slope = np.polyfit(np.log(moduli), np.log(errs), 1)[0]
    assert slope == pytest.approx(-0.4, abs=0.01)
    # the excess is the contact duration of the bounce (gravity during the contact aside)
    v0 = math.sqrt(2 * 9.81 * h)
    es = 1 / (2 * (1 - 0.09) / moduli[-1])
    d, _, T = hertz_closed_form(MASS, v0, 4 / 3 * es * math.sqrt(R))
    assert errs[-1] == pytest.approx(T, rel=1e-3)


def chain(law, v0=1.0, rigid=False):
    """Three equal steel balls on the x axis: b and c touching at rest, a arriving at v0."""
    m = ms.Model("chain", gravity=(0, 0, 0))
    balls = []
    for k, (x, u) in enumerate([(-2 * R - 1e-4, v0), (0.0, 0.0), (2 * R, 0.0)]):
        b = m.add_body(f"b{k}", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
        m.add_joint(ms.joints.Prismatic(f"x{k}", m.ground, b, axis=(1, 0, 0), q0=x, u0=u))
        balls.append(b)
    for k in range(2):
        kw = {"impact": ms.laws.Newton(eps=1.0)} if rigid else {"normal": law}
        m.add_contact(ms.Contact(f"c{k}", balls[k].contour(ms.contours.Sphere(radius=R), material=STEEL),
                                 balls[k + 1].contour(ms.contours.Sphere(radius=R), material=STEEL), **kw))
    return m


def test_three_ball_chain_conserves_and_matches_scipy():
    """Hertz chain: momentum and energy conserved to 1e-9 and the final velocities of an
    independent SciPy integration of the three-mass Hertz chain. The rigid model's answers next
    to it: Newton's law (e = 1) at the simultaneous impact, the touching pair kept together by
    the complementarity of its closed contact, gives (-1/3, 2/3, 2/3) v0 (event-driven and
    Moreau-Jean alike, energy conserved); a sequence of pairwise impacts (a on b, then b on c)
    gives (0, 0, 1) v0. The compliant chain lies in between, near the pairwise answer."""
    res = ms.simulate(chain(ms.laws.Hertz()), t_end=6e-4, output_dt=1e-6, integrator=ms.DOPRI5(rtol=1e-12, atol=1e-16))
    u = np.column_stack([res[f"joint/x{k}/u"] for k in range(3)])
    p = MASS * u.sum(axis=1)
    assert np.ptp(p) < 1e-9 * MASS
    e = res["energy/total"]
    assert np.ptp(e) < 1e-9 * e[0]
    k = 4 / 3 * E_STAR * math.sqrt(R / 2)

    def f(t, y):
        x, v = y[:3], y[3:]
        d01, d12 = max(x[0] - x[1], 0.0), max(x[1] - x[2], 0.0)
        f01, f12 = k * d01**1.5, k * d12**1.5
        return [*v, -f01 / MASS, (f01 - f12) / MASS, f12 / MASS]

    # x: each ball's position past its touching place (a starts 0.1 mm short)
    s = solve_ivp(f, (0, 6e-4), [-1e-4, 0, 0, 1, 0, 0], method="DOP853", rtol=1e-13, atol=1e-18)
    np.testing.assert_allclose(u[-1], s.y[3:, -1], atol=1e-8)
    assert 1 - u[-1, 2] > 1e-3 and u[-1, 0] < 0  # a part stays behind: not the rigid answer
    rigid = ms.simulate(chain(None, rigid=True), t_end=2e-4, output_dt=1e-5, integrator=ms.EventDriven())
    np.testing.assert_allclose([rigid[f"joint/x{k}/u"][-1] for k in range(3)], [-1 / 3, 2 / 3, 2 / 3], atol=1e-12)
    pairwise = np.array([1.0, 0.0, 0.0])
    for i in (0, 1):  # equal masses exchange their velocities
        pairwise[i], pairwise[i + 1] = pairwise[i + 1], pairwise[i]
    np.testing.assert_allclose(pairwise, [0, 0, 1])
    assert np.linalg.norm(u[-1] - pairwise) < np.linalg.norm(u[-1] - [-1 / 3, 2 / 3, 2 / 3])


def test_cylinder_line_contact_against_johnson():
    """A steel cylinder (R = 10 mm, L = 40 mm) resting on a plane under its weight (damped to
    rest): its overlap solves Johnson's delta = (F/(pi L E*)) (ln(4 pi L E* R / F) - 1)."""
    L, load = 0.04, 5000.0
    m = ms.Model("roller", gravity=(0, 0, -9.81))
    mass = load / 9.81
    b = m.add_body("roller", mass=mass, inertia=ms.inertia.sphere(mass, R))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=R))
    m.add_contact(ms.Contact("line", b.contour(ms.contours.Cylinder(axis=(1, 0, 0), radius=R, length=L), material=STEEL),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=STEEL),
                             normal=ms.laws.Hertz(alpha=300.0)))
    res = ms.simulate(m, t_end=0.1, output_dt=1e-3, integrator=ms.Radau5(rtol=1e-10, atol=1e-14))
    ref = brentq(lambda d: load / (math.pi * L * E_STAR) * (math.log(4 * math.pi * L * E_STAR * R / load) - 1) - d, 1e-9, 1e-3)
    delta = res["contact/line/overlap"][-1]
    np.testing.assert_allclose(delta, ref, rtol=1e-6)
    np.testing.assert_allclose(res["contact/line/force_n"][-1].sum(), load, rtol=1e-6)


def scipy_ellipse(A, B, e_star, force):
    """Hertz's contact ellipse by SciPy: B/A = (E/(1-m) - K)/(K - E), then a, b, delta."""
    def ratio(m):
        return (ellipe(m) / (1 - m) - ellipk(m)) / (ellipk(m) - ellipe(m)) - B / A

    m = brentq(ratio, 1e-12, 1 - 1e-14, xtol=1e-16, rtol=1e-15)
    K, E = ellipk(m), ellipe(m)
    # a^2 = delta (K - E)/(K m A), P = (2 pi/3) a E* delta / K
    c = (K - E) / (K * m * A)
    delta = (force * 3 * K / (2 * math.pi * e_star * math.sqrt(c))) ** (2 / 3)
    a = math.sqrt(delta * c)
    return a, a * math.sqrt(1 - m), delta


@pytest.mark.parametrize("ratio", [3.0, 40.0])
def test_ellipse_semi_axes_against_hertz_elliptic_solution(ratio):
    A = 20.0
    a, b, delta = scipy_ellipse(A, ratio * A, E_STAR, 100.0)
    c = ms.hertz.impact  # noqa: F841  (the module is public)
    from mechsys import _core

    got = _core.hertz_contact(A, ratio * A, E_STAR, 100.0)
    np.testing.assert_allclose([got["a"], got["b"], got["delta"]], [a, b, delta], rtol=1e-9)
    assert got["p0"] == pytest.approx(1.5 * 100.0 / (math.pi * a * b), rel=1e-9)


def test_ellipsoid_on_plane_static_overlap_from_the_elliptic_solution():
    """An ellipsoid (semi-axes 20, 10, 5 mm) resting on a plane on its small axis: curvatures
    c/a^2, c/b^2 at the pole; its overlap under the load is (F/K)^(2/3) with K from SciPy's
    elliptic solution."""
    ax = (0.02, 0.01, 0.005)
    load = 200.0
    m = ms.Model("egg", gravity=(0, 0, -9.81))
    mass = load / 9.81
    b = m.add_body("egg", mass=mass, inertia=ms.inertia.sphere(mass, 0.01))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=ax[2]))
    m.add_contact(ms.Contact("pole", b.contour(ms.contours.Ellipsoid(semi_axes=ax), material=STEEL),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=STEEL),
                             normal=ms.laws.Hertz(alpha=300.0)))
    res = ms.simulate(m, t_end=0.1, output_dt=1e-3, integrator=ms.Radau5(rtol=1e-10, atol=1e-14))
    A, B = 0.5 * ax[2] / ax[0] ** 2, 0.5 * ax[2] / ax[1] ** 2
    _, _, delta = scipy_ellipse(A, B, E_STAR, load)
    np.testing.assert_allclose(res["contact/pole/overlap"][-1], delta, rtol=1e-6)


def test_rigid_newton_impact_post_processed_equals_the_compliant_run():
    """Section 2.5.4: a rigid e = 1 impact resolved by Hertz afterwards gives the compliant run's
    delta_max, peak force and duration to 1e-6."""
    m = ms.Model("ball", gravity=(0, 0, 0))
    b = m.add_body("ball", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=R + 2e-4, u0=-1.0))
    m.add_contact(ms.Contact("c", b.contour(ms.contours.Sphere(radius=R), material=STEEL),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=STEEL),
                             impact=ms.laws.Newton(eps=1.0)))
    rigid = ms.simulate(m, t_end=4e-4, output_dt=1e-5, integrator=ms.EventDriven())
    rows = ms.hertz.impacts(rigid, m)
    assert len(rows) == 1
    comp = ms.simulate(ball_on_plane(ms.laws.Hertz()), t_end=4e-4, output_dt=1e-8, integrator=ms.DOPRI5(rtol=1e-12, atol=1e-16))
    close, opened = contact_times(comp)
    r = rows[0]
    assert r["delta_max"] == pytest.approx(peak(comp["t"], comp["contact/c/overlap"]), rel=1e-6)
    assert r["force_max"] == pytest.approx(peak(comp["t"], comp["contact/c/force_n"]), rel=1e-6)
    assert r["duration"] == pytest.approx(opened[0] - close[0], rel=1e-6)
    # a circle of radius sqrt(R delta) and p0 = 3F/(2 pi a^2)
    assert r["a"] == pytest.approx(math.sqrt(R * r["delta_max"]), rel=1e-12)
    assert r["p0"] == pytest.approx(1.5 * r["force_max"] / (math.pi * r["a"] ** 2), rel=1e-12)
    assert "delta_max" in ms.hertz.table(rows)


@pytest.mark.parametrize("mat,law,msg", [
    (ms.Material(E=0.0, nu=0.3, density=7800), ms.laws.Hertz(), "material1.E: Young's modulus must be > 0"),
    (ms.Material(E=2e11, nu=0.5, density=7800), ms.laws.Hertz(), "material1.nu: Poisson's ratio must lie in (-1, 0.5)"),
    (ms.Material(E=2e11, nu=-1.0, density=7800), ms.laws.Hertz(), "material1.nu"),
    (ms.Material(E=2e11, nu=0.3, density=0.0), ms.laws.Hertz(), "material1.density: must be > 0"),
    (None, ms.laws.Hertz(), "needs the materials of both contours"),
    (STEEL, ms.laws.HuntCrossley(alpha=-1.0), "alpha: the damping coefficient must be >= 0"),
    (STEEL, ms.laws.HuntCrossley(), "needs eps (restitution) or alpha"),
    (STEEL, ms.laws.Flores(eps=1.5), "eps: must be in (0, 1]"),
    (STEEL, ms.laws.KelvinVoigt(k=-1.0), "normal.k: must be > 0"),
])
def test_bad_input_names_the_contact(mat, law, msg):
    m = ms.Model("bad", gravity=(0, 0, 0))
    b = m.add_body("ball", mass=1.0, inertia=ms.inertia.sphere(1.0, R))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=0.02))
    m.add_contact(ms.Contact("hit", b.contour(ms.contours.Sphere(radius=R), material=mat),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=mat), normal=law))
    with pytest.raises(ms.ModelError, match="contact.*'hit'") as e:
        ms.simulate(m, t_end=1e-3, integrator=ms.DOPRI5())
    assert msg in str(e.value)


def test_hertz_on_flat_faces_and_impact_law_are_refused():
    m = ms.Model("flat", gravity=(0, 0, 0))
    b = m.add_body("box", mass=1.0, inertia=ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=0.06))
    m.add_contact(ms.Contact("face", b.contour(ms.contours.Box(half_extents=(0.05, 0.05, 0.05)), material=STEEL),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=STEEL), normal=ms.laws.Hertz()))
    with pytest.raises(ms.ModelError, match="'face'.*Hertz law needs curved contours.*KelvinVoigt"):
        ms.simulate(m, t_end=1e-3, integrator=ms.DOPRI5())
    m2 = ball_on_plane(ms.laws.Hertz())
    m2._contacts[0].impact = ms.laws.Newton(eps=0.5)
    with pytest.raises(ms.ModelError, match="'c'.impact: a compliant contact takes no impact law"):
        ms.simulate(m2, t_end=1e-3, integrator=ms.DOPRI5())


def test_schemes_rigid_and_compliant_side_by_side():
    """A rigid scheme with only compliant contacts works (Moreau-Jean, the force at the step
    midpoints); a rigid and a compliant contact mix in one Moreau-Jean run; a smooth scheme with
    a rigid contact keeps its message; RK4 splits its steps at the onsets."""
    k = 4 / 3 * E_STAR * math.sqrt(R)
    _, _, T = hertz_closed_form(MASS, 1.0, k)
    mj = ms.simulate(ball_on_plane(ms.laws.Hertz()), t_end=4e-4, output_dt=1e-6, integrator=ms.MoreauJean(dt=1e-8))
    assert mj["joint/z/u"][-1] == pytest.approx(1.0, rel=1e-3)
    close, opened = contact_times(mj)
    assert opened[0] - close[0] == pytest.approx(T, rel=2e-3)
    rk = ms.simulate(ball_on_plane(ms.laws.Hertz()), t_end=4e-4, output_dt=1e-6, integrator=ms.RK4(dt=1e-7))
    close, opened = contact_times(rk)
    assert close[0] == pytest.approx(2e-4, rel=1e-9)
    assert opened[0] - close[0] == pytest.approx(T, rel=1e-6)
    assert rk["joint/z/u"][-1] == pytest.approx(1.0, rel=1e-8)
    # mixed: the ball falls on a compliant pad, a second ball on a rigid floor
    m = ball_on_plane(ms.laws.HuntCrossley(eps=0.8))
    b2 = m.add_body("rigid_ball", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
    m.add_joint(ms.joints.Prismatic("z2", m.ground, b2, axis=(0, 0, 1), q0=R + 2e-4, u0=-1.0))
    m.add_contact(ms.Contact("floor", b2.contour(ms.contours.Sphere(radius=R)), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             impact=ms.laws.Newton(eps=0.8)))
    mix = ms.simulate(m, t_end=4e-4, output_dt=1e-6, integrator=ms.MoreauJean(dt=1e-8))
    assert mix["joint/z2/u"][-1] == pytest.approx(0.8, rel=1e-9)
    assert 0.75 < mix["joint/z/u"][-1] < 0.9
    with pytest.raises(ms.SettingsError, match="unilateral contacts \\('floor'\\)"):
        ms.simulate(m, t_end=1e-3, integrator=ms.DOPRI5())


def block(friction, push, normal=100.0):
    """A 1 kg block sliding along x (its height fixed) on a plane through a Kelvin-Voigt contact
    pressed to `normal` N, pushed along x by `push` N."""
    kv = 1e6
    m = ms.Model("block", gravity=(0, 0, 0))
    b = m.add_body("block", mass=1.0, inertia=ms.inertia.sphere(1.0, R))
    m.add_joint(ms.joints.Prismatic("x", m.ground, b, axis=(1, 0, 0)))
    m.add_contact(ms.Contact("foot", b.contour(ms.contours.Sphere(radius=R, center=(0, 0, -normal / kv))),
                             m.ground.contour(ms.contours.Plane(point=(0, 0, -R), normal=(0, 0, 1))),
                             normal=ms.laws.KelvinVoigt(k=kv, v_reg=1e-3), friction=friction))
    m.add_force(ms.forces.JointForce("push", "x", push))
    return m


def test_regularized_coulomb_creeps_at_the_stated_rate():
    """Under a push of half mu N the regularized contact creeps at v = v_reg atanh(1/2)."""
    res = ms.simulate(block(ms.laws.Coulomb(mu=0.4), push=20.0), t_end=0.5, output_dt=1e-2,
                      integrator=ms.Radau5(rtol=1e-10, atol=1e-14))
    assert res["joint/x/u"][-1] == pytest.approx(1e-3 * math.atanh(0.5), rel=1e-8)
    assert res["contact/foot/force_n"][-1] == pytest.approx(100.0, rel=1e-12)
    assert res["contact/foot/force_t"][-1, 0] * np.sign(res["contact/foot/slip_velocity"][-1, 0]) == pytest.approx(-20.0, rel=1e-8)
    # beyond mu N it slides
    slide = ms.simulate(block(ms.laws.Coulomb(mu=0.4), push=50.0), t_end=0.2, output_dt=1e-2, integrator=ms.Radau5(rtol=1e-9, atol=1e-12))
    assert slide["joint/x/u"][-1] == pytest.approx(0.2 * 10.0, rel=1e-3)


def test_lugre_bristles_hold_a_sticking_block_without_drift():
    """LuGre: under a push below mu0 N the block settles (its bristles carrying the push) and
    stays: no drift over the second half of 2 s, where the regularized law creeps by
    v_reg atanh(push/(mu N)) t."""
    law = ms.laws.LuGre(mu0=0.5, mu=0.4, v_s=1e-3, sigma0=1e4, sigma1=50.0)
    res = ms.simulate(block(law, push=30.0), t_end=2.0, output_dt=1e-2, integrator=ms.Radau5(rtol=1e-10, atol=1e-14))
    x = res["joint/x/q"]
    assert abs(x[-1] - x[len(x) // 2]) < 1e-10
    assert abs(x[-1]) < 1e-4
    assert res["contact/foot/force_t"][-1, 0] * np.sign(x[-1]) == pytest.approx(-30.0, rel=1e-8)
    assert res["contact/foot/energy_dissipated"][-1] > 0
    creep = ms.simulate(block(ms.laws.Coulomb(mu=0.4), push=30.0), t_end=2.0, output_dt=1e-2,
                        integrator=ms.Radau5(rtol=1e-10, atol=1e-14))["joint/x/q"]
    assert creep[-1] - creep[len(creep) // 2] == pytest.approx(1e-3 * math.atanh(0.75) * 1.0, rel=1e-6)


def test_user_law_matches_the_built_in_one():
    """A Python F(delta, delta') equal to Kelvin-Voigt's gives the same run (slow path)."""
    kv = ms.laws.KelvinVoigt(k=1e7, d=20.0)
    user = ms.laws.UserLaw(lambda d, dd: 1e7 * d + 20.0 * dd)
    a = ms.simulate(ball_on_plane(kv), t_end=1e-3, output_dt=1e-5, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-14))
    b = ms.simulate(ball_on_plane(user), t_end=1e-3, output_dt=1e-5, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-14))
    np.testing.assert_allclose(b["joint/z/u"], a["joint/z/u"], atol=1e-9)
    bad = ms.laws.UserLaw(lambda d, dd: float("nan"))
    with pytest.raises(ms.MechsysError, match="contact 'c'.normal"):
        ms.simulate(ball_on_plane(bad), t_end=1e-3, integrator=ms.DOPRI5())


def test_model_file_compliant_contact_from_the_command_line(tmp_path):
    """examples/hertz_drop.toml through `mechsys run`: the first bounce's apex is e^2 of the drop
    for the restitution the Hunt-Crossley law achieves (from the run's own velocities), and a
    file without materials is refused naming the contact."""
    import subprocess
    import sys
    from pathlib import Path

    ex = Path(__file__).resolve().parents[1] / "examples" / "hertz_drop.toml"
    out = tmp_path / "drop.h5"
    script = Path(sys.executable).parent / "mechsys"
    r = subprocess.run([str(script), "run", str(ex), "--t-end", "0.3", "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    res = ms.load(out)
    close, opened = contact_times(res, "floor")
    assert len(close) >= 2 and len(opened) >= 1
    # the first contact starts when the ball has fallen 50 mm: t = sqrt(2 h / g)
    assert close[0] == pytest.approx(math.sqrt(2 * 0.05 / 9.81), rel=1e-6)
    # its peak force lies below the undamped Hertz value for the impact speed (damping)
    v_in = math.sqrt(2 * 9.81 * 0.05)
    k = 4 / 3 * E_STAR * math.sqrt(R)
    _, f_max, _ = hertz_closed_form(MASS, v_in, k)
    assert 0.5 * f_max < res["contact/floor/force_n"].max() < f_max
    bad = tmp_path / "bad.toml"
    bad.write_text(ex.read_text().replace('material1 = { E = 2.1e11, nu = 0.3, density = 7800.0 }\n', ""))
    r = subprocess.run([str(script), "run", str(bad), "--t-end", "0.01", "--out", str(tmp_path / "b.h5")], capture_output=True, text=True)
    assert r.returncode != 0 and "'floor'" in r.stderr and "material" in r.stderr


def test_rk4_on_the_rotation_group_splits_its_steps_at_the_onsets_too():
    """The ball on a free joint (its quaternion stepped on the rotation group by RK4) meets the plane
    at the same time and leaves it after the same Hertz duration as the one on a slider."""
    k = 4 / 3 * E_STAR * math.sqrt(R)
    _, _, T = hertz_closed_form(MASS, 1.0, k)
    m = ms.Model("free_ball", gravity=(0, 0, 0))
    b = m.add_body("ball", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
    gap = 2e-4 + 3.3e-8  # the onset inside a step
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, R + gap, 1, 0, 0, 0], u0=[0, 0, -1.0, 0.3, 0, 0]))
    m.add_contact(ms.Contact("c", b.contour(ms.contours.Sphere(radius=R), material=STEEL),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=STEEL), normal=ms.laws.Hertz()))
    rk = ms.simulate(m, t_end=4e-4, output_dt=1e-6, integrator=ms.RK4(dt=1e-7))
    close, opened = contact_times(rk)
    assert close[0] == pytest.approx(gap, rel=1e-9)
    assert opened[0] - close[0] == pytest.approx(T, rel=1e-6)


@pytest.mark.parametrize("law", ["hertz", "kelvin_voigt"])
def test_linearized_at_rest_a_stiff_contact_has_its_tangent_stiffness(law):
    """A 1 cm steel ball at rest on a steel plane under gravity overlaps by delta = (m g / K)^(2/3)
    = 0.08 micrometre (Hertz, K = 4/3 E* sqrt(R)); linearized there, its bounce mode has the
    tangent stiffness 1.5 K sqrt(delta). On a Kelvin-Voigt contact of k = 1e9 N/m (overlap
    0.3 nm) it is k. The central differences' position step (1e-5 m) reached across the force
    law's kink at delta = 0 and gave about half of either: the step is now a quarter of the
    smallest overlap."""
    g = 9.81
    if law == "hertz":
        k_h = 4.0 / 3.0 * E_STAR * math.sqrt(R)
        delta = (MASS * g / k_h) ** (2.0 / 3.0)
        stiffness = 1.5 * k_h * math.sqrt(delta)
        normal = ms.laws.Hertz()
    else:
        stiffness = 1e9
        delta = MASS * g / stiffness
        normal = ms.laws.KelvinVoigt(k=stiffness)
    m = ball_on_plane(normal, v0=0.0, gap=-delta, gravity=g)
    m.build()
    lin = ms.linear.linearize(m)
    assert lin.method == "fd"
    np.testing.assert_allclose(lin.K[0, 0], stiffness, rtol=1e-6)
    np.testing.assert_allclose(lin.modes().natural_frequency[-1], math.sqrt(stiffness / MASS) / (2 * math.pi), rtol=1e-6)
