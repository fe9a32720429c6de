"""Event-driven integration of contact models (issue 4) against closed forms: the accumulation of
impacts, stick and slip on an incline, the slip-to-roll transition, Newton's cradle under
Newton's and Poisson's laws, a stick-slip oscillator (also against Moreau-Jean as dt -> 0), a
Painleve situation, the event log, the energy balance and bad settings."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import mechsys as ms
from test_contact import G, ball, block, cradle

ED = ms.EventDriven()


def point_ball(eps, h0, law=ms.laws.Newton):
    """A ball whose contact point is its centre (a point contour): its gap is the height itself,
    resolved in floating point down to the last rebounds."""
    m = ms.Model("ball", gravity=(0.0, 0.0, -G))
    b = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, 0.1))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, h0, 1, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Point()),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))), impact=law(eps)))
    return m


@pytest.mark.parametrize("eps", [0.5, 0.8])
def test_accumulation_of_impacts_to_1e8_relative(eps):
    """Impact k at t0 + 2 t0 (eps + ... + eps^(k-1)), t0 = sqrt(2 h0 / g); they accumulate at
    t_inf = t0 (1 + eps) / (1 - eps); from then on the ball rests with lambda_N = m g."""
    h0 = 1.0
    res = ms.simulate(point_ball(eps, h0), 5.0, ms.EventDriven(velocity_tol=1e-10), output_dt=1e-2)
    t0 = np.sqrt(2 * h0 / G)
    t_inf = t0 * (1 + eps) / (1 - eps)
    impacts = [e["t"] for e in res.events if e["event"] == "impact"]
    expected = t0 + 2 * t0 * np.cumsum(eps ** np.arange(len(impacts)))[:len(impacts)] - 2 * t0
    np.testing.assert_allclose(impacts[:20], expected[:20], rtol=1e-12)
    closes = [e["t"] for e in res.events if e["event"] == "close"]
    assert len(closes) == 1 and abs(closes[0] - t_inf) < 1e-8 * t_inf
    after = res.t > t_inf
    z = res["body/ball/position"][:, 2]
    assert np.abs(z[after]).max() < 1e-20 and np.abs(res["body/ball/velocity"][after]).max() < 1e-12
    np.testing.assert_allclose(res["contact/floor/lambda_n"][after], G, rtol=1e-12)
    assert np.all(res["contact/floor/state"][after] == 1) and np.all(res["contact/floor/state"][res.t < t0] == 0)
    # apexes h0 eps^(2k): the largest height between impacts k and k + 1
    for k in range(1, 4):
        window = (res.t > impacts[k - 1]) & (res.t < impacts[k])
        assert abs(z[window].max() - h0 * eps ** (2 * k)) < 0.5 * G * 0.01**2  # within the sampling
    e = res["energy/total"] + res["energy/dissipated"] - res["energy/external_work"]
    assert np.ptp(e) < 1e-12
    assert abs(res["energy/dissipated_impact"][-1] - G * h0) < 1e-12


def test_sphere_on_a_plane_comes_to_rest_near_the_accumulation_time():
    """With a sphere the gap is a difference of coordinates near 0.1 m, so rebounds below about
    1e-7 m/s cannot be resolved; they end as plastic impacts: t_inf to 1e-7 relative."""
    eps, h0 = 0.8, 1.0
    res = ms.simulate(ball(eps, h0), 5.0, ED, output_dt=1e-2)
    t_inf = np.sqrt(2 * h0 / G) * (1 + eps) / (1 - eps)
    closes = [e["t"] for e in res.events if e["event"] == "close"]
    assert len(closes) == 1 and abs(closes[0] - t_inf) < 1e-7 * t_inf
    assert abs(res["body/ball/position"][-1, 2] - 0.1) < 1e-15
    assert res.stats["events"] < 200


def test_block_on_an_incline_sticks_exactly_and_slides_with_the_kinetic_coefficient():
    res = ms.simulate(block(0.3, 0.3, 0.4), 2.0, ED, output_dt=1e-2)
    x = res["body/block/position"]
    assert np.abs(x - x[0]).max() < 1e-12
    st = res["contact/base/state"]
    assert np.all(st[:, :4] == 1) and np.all(st[:, 4:] == 0)
    # redundant supports share the load (minimum-norm forces): left and right alike, and the
    # downhill pair more by the moment of friction about the centre, m g sin(a) h = dN a
    lam_n = res["contact/base/lambda_n"][-1, :4]
    assert abs(lam_n.sum() - 2.0 * G * np.cos(0.3)) < 1e-9
    np.testing.assert_allclose(np.sort(lam_n)[[0, 2]], np.sort(lam_n)[[1, 3]], rtol=1e-12)
    np.testing.assert_allclose(np.ptp(lam_n) * 2 * 0.1, 2.0 * G * np.sin(0.3) * 0.05, rtol=1e-9)
    np.testing.assert_allclose(res["contact/base/lambda_t"][-1, :4, 0].sum(), -2.0 * G * np.sin(0.3), rtol=1e-9)
    assert np.all(res["contact/base/friction_reserve"][:, :4] > 0.0)
    assert res.events == [] or all(e["event"] in ("close", "stick") and e["t"] == 0.0 for e in res.events)

    alpha, mu = 0.3, 0.2
    a = G * (np.sin(alpha) - mu * np.cos(alpha))
    res = ms.simulate(block(alpha, mu, 0.25), 1.0, ED, output_dt=1e-2)
    np.testing.assert_allclose(res["body/block/position"][:, 0], 0.5 * a * res.t**2, rtol=0, atol=1e-12)
    assert np.all(res["contact/base/state"][:, :4] == 2)
    # friction dissipates mu N |v| exactly: the energy balance closes
    e = res["energy/total"] + res["energy/dissipated"]
    assert np.ptp(e) < 1e-10
    np.testing.assert_allclose(res["energy/dissipated_friction"], mu * 2.0 * G * np.cos(alpha) * 0.5 * a * res.t**2, atol=1e-10)


def test_ball_with_backspin_rolls_from_the_closed_form_time_on():
    r, v0, w0, mu = 0.1, 2.0, -5.0, 0.3
    # (the ball's velocities are components in its spinning frame: the phases are not polynomial
    # in time, and the event times carry the integration error)
    res = ms.simulate(ball(0.0, 0.0, r, v0=(v0, 0, 0), w0=(0, w0, 0), friction=ms.laws.Coulomb(mu)), 1.0,
                      ms.EventDriven(rtol=1e-12), output_dt=1e-3)
    s0 = v0 - r * w0
    t_r, v_f = 2 * s0 / (7 * mu * G), (5 * v0 + 2 * r * w0) / 7
    sticks = [e["t"] for e in res.events if e["event"] == "stick"]
    assert len(sticks) == 1 and abs(sticks[0] - t_r) < 1e-9
    v = res["body/ball/velocity"][:, 0]
    slipping = res.t < t_r
    np.testing.assert_allclose(v[slipping], v0 - mu * G * res.t[slipping], atol=1e-9)
    np.testing.assert_allclose(v[res.t > t_r], v_f, atol=1e-8)
    np.testing.assert_allclose(res["body/ball/angular_velocity"][res.t > t_r, 1], v_f / r, atol=1e-7)
    assert np.abs(res["contact/floor/lambda_t"][res.t > t_r]).max() < 1e-8
    e = res["energy/total"] + res["energy/dissipated"]
    assert np.ptp(e) < 1e-8
    # the energy friction took is the kinetic energy lost
    t_lost = 0.5 * (v0**2 - v_f**2) + 0.5 * 0.4 * r**2 * (w0**2 - (v_f / r) ** 2)
    assert abs(res["energy/dissipated_friction"][-1] - t_lost) < 1e-8


def test_newtons_cradle_under_newtons_and_poissons_laws():
    """Simultaneous impact of ball 1 on the touching balls 2 and 3 (unit masses, v = 1).
    Newton, eps = 1: (-1/3, 2/3, 2/3). Poisson, eps = 1: compression to the common 1/3 with
    impulses (2/3, 1/3), expansion returns them: the same velocities. Poisson, eps = 0.5:
    impulses 1.5 (2/3, 1/3) give (0, 1/2, 1/2), and the expansion impulse of contact 2 must
    grow (its gap would close) to 0.5 at both: (0, 0.5, 0.5) stays consistent. Plastic: 1/3."""
    res = ms.simulate(cradle(), 0.3, ED, output_dt=1e-3)
    np.testing.assert_allclose(res["u"][-1], [-1 / 3, 2 / 3, 2 / 3], atol=1e-12)
    res = ms.simulate(cradle(1.0, ms.laws.Poisson), 0.3, ED, output_dt=1e-3)
    np.testing.assert_allclose(res["u"][-1], [-1 / 3, 2 / 3, 2 / 3], atol=1e-12)
    np.testing.assert_allclose(res["u"].sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(res["energy/dissipated_impact"][-1], 0.0, atol=1e-12)
    res = ms.simulate(cradle(0.5, ms.laws.Poisson), 0.3, ED, output_dt=1e-3)
    u = res["u"][-1]
    np.testing.assert_allclose(u.sum(), 1.0, atol=1e-12)
    np.testing.assert_allclose(u, [0.0, 0.5, 0.5], atol=1e-12)
    np.testing.assert_allclose(res["energy/dissipated_impact"][-1], 0.5 - 0.5 * (u**2).sum(), atol=1e-12)
    res = ms.simulate(cradle(0.0), 0.3, ED, output_dt=1e-3)
    np.testing.assert_allclose(res["u"][-1], [1 / 3] * 3, atol=1e-12)


def oscillator(mu=0.3, mu0=0.4, k=100.0, x0=0.2):
    """A 1 kg block on a rough floor (point contact), tied by a spring k to a wall."""
    m = ms.Model("stick_slip", gravity=(0.0, -G, 0.0))
    b = m.add_body("block", 1.0, ms.inertia.sphere(1.0, 0.05))
    m.add_joint(ms.joints.Planar("plane", m.ground, b, q0=[x0, 0.0, 0.0]))
    m.add_force(ms.forces.SpringDamper("spring", m.ground, b, point1=(-1.0, 0, 0), k=k, l0=1.0))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Point()),
                             m.ground.contour(ms.contours.Line(normal=(0, 1, 0))), friction=ms.laws.Coulomb(mu, mu0)))
    return m


def test_stick_slip_oscillator_against_the_closed_form_and_time_stepping():
    """Each sliding half-cycle is harmonic about +-mu g / w^2 (w = 10 rad/s) and ends at rest
    2 mu g / w^2 closer to the middle; the block sticks at the first rest within mu0 g / w^2:
    x = -(x0 - 6 mu g / w^2) at t = 3 pi / w. Moreau-Jean converges to it as dt -> 0."""
    mu, x0, w = 0.3, 0.2, 10.0
    c = mu * G / w**2
    res = ms.simulate(oscillator(), 1.5, ED, output_dt=1e-3)
    x = res["joint/plane/q"][:, 0]
    x_stop = -(x0 - 6 * c)
    assert abs(x[-1] - x_stop) < 1e-9
    log = [(e["t"], e["event"]) for e in res.events]
    assert [k for _, k in log] == ["close", "slip", "slip", "stick"]
    # the slip reverses at pi / w and 2 pi / w, and stops for good at 3 pi / w
    np.testing.assert_allclose([t for t, _ in log[1:]], [np.pi / w, 2 * np.pi / w, 3 * np.pi / w], atol=1e-9)
    half = (res.t < np.pi / w)
    np.testing.assert_allclose(x[half], c + (x0 - c) * np.cos(w * res.t[half]), atol=1e-9)
    e = res["energy/total"] + res["energy/dissipated"]
    assert np.ptp(e) < 1e-8
    errors = []
    for dt in (1e-3, 1e-4):
        mj = ms.simulate(oscillator(), 1.5, ms.MoreauJean(dt), output_dt=1e-3)
        errors.append(abs(mj["joint/plane/q"][-1, 0] - x[-1]))
    assert errors[1] < errors[0] / 10 and errors[1] < 1e-6


def rod(theta=np.radians(30), mu=3.0, v=-1.0):
    """A rod (length 1 m) leaning on a rough floor by its lower end, sliding."""
    m = ms.Model("painleve", gravity=(0.0, -G, 0.0))
    b = m.add_body("rod", 1.0, ms.inertia.box(1.0, (1.0, 0.01, 0.01)))
    m.add_joint(ms.joints.Planar("plane", m.ground, b, q0=[0.5 * np.cos(theta), 0.5 * np.sin(theta), theta],
                                 u0=[v, 0, 0]))
    m.add_contact(ms.Contact("tip", b.contour(ms.contours.Point(position=(-0.5, 0, 0))),
                             m.ground.contour(ms.contours.Line(normal=(0, 1, 0))), friction=ms.laws.Coulomb(mu)))
    return m


def test_painleve_situation_raises_naming_the_contact_unless_asked_to_go_on():
    """With the tip sliding, the normal acceleration per unit normal force is
    1/m (1 + 3 cos(theta) (cos(theta) -+ mu sin(theta))) for the slender rod: negative for mu = 3
    at 30 degrees in one sliding direction, so the problem at acceleration level has no solution."""
    with pytest.raises(ms.SolverError, match=r"Painlev.*tip"):
        ms.simulate(rod(), 0.5, ED, output_dt=1e-3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = ms.simulate(rod(), 0.5, ms.EventDriven(continue_on_painleve=True), output_dt=1e-3)
    assert any("Painlev" in str(w.message) for w in caught)
    # the impulsive stop: the tip sticks at once
    assert res["contact/tip/state"][0] == 1 and abs(res["contact/tip/gd_t"][0]) < 1e-12
    # with a small coefficient both directions are regular
    for v in (1.0, -1.0):
        ms.simulate(rod(mu=0.5, v=v), 0.2, ED, output_dt=1e-3)


def test_event_driven_from_a_model_file_and_the_command_line(tmp_path):
    from click.testing import CliRunner

    from mechsys.cli import cli

    text = """
name = "drop"
gravity = [0.0, 0.0, -9.81]
[[bodies]]
name = "ball"
mass = 1.0
inertia = [0.004, 0.004, 0.004]
[[joints]]
name = "free"
type = "free"
parent = "ground"
child = "ball"
q0 = [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0]
[[contacts]]
name = "floor"
body1 = "ball"
contour1 = { type = "point" }
body2 = "ground"
contour2 = { type = "plane", normal = [0.0, 0.0, 1.0] }
impact = { type = "newton", eps = 0.5 }
[simulation]
t_end = 2.0
output_dt = 0.01
integrator = { type = "event_driven", velocity_tol = 1e-10 }
"""
    path = tmp_path / "drop.toml"
    path.write_text(text)
    out = tmp_path / "drop.h5"
    r = CliRunner().invoke(cli, ["run", str(path), "--out", str(out)])
    assert r.exit_code == 0, r.output
    res = ms.Results.load(out)
    t_inf = np.sqrt(2 / G) * 3
    closes = [e["t"] for e in res.events if e["event"] == "close"]
    assert len(closes) == 1 and abs(closes[0] - t_inf) < 1e-8 * t_inf
    r = CliRunner().invoke(cli, ["run", str(path), "--integrator", "event_driven", "--rtol", "1e-9", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert json.loads(ms.Results.load(out).attrs["stats"])["events"] > 20


@pytest.mark.parametrize(
    "change, fragment",
    [
        ({"velocity_tol": 0.0}, "velocity_tol"),
        ({"gap_tol": -1.0}, "gap_tol"),
        ({"rtol": float("nan")}, "rtol"),
        ({"max_events": 0}, "max_events"),
    ],
)
def test_bad_event_driven_settings_name_the_key(change, fragment):
    with pytest.raises(ms.SettingsError, match=fragment):
        ms.simulate(point_ball(0.5, 1.0), 0.1, ms.EventDriven(**change))


def test_too_many_events_is_an_error_naming_the_contact():
    with pytest.raises(ms.SolverError, match=r"events by t = .*floor"):
        ms.simulate(point_ball(0.8, 1.0), 5.0, ms.EventDriven(max_events=10))


def test_woodpecker_event_driven_keeps_the_energy_balance_and_pecks():
    """The showcase toy, event-driven: hundreds of impacts, stick and slip; the energy balance
    closes to the integration tolerance, no contour penetrates, and the bird pecks about every
    0.16 s (the published toy: 0.15-0.17 s)."""
    import importlib.util
    import pathlib

    path = pathlib.Path(__file__).parent.parent / "examples" / "woodpecker.py"
    spec = importlib.util.spec_from_file_location("woodpecker_ed", path)
    wp = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(wp)
    res = ms.simulate(wp.model, **wp.event_driven)
    e = res["energy/total"] + res["energy/dissipated"] - res["energy/external_work"]
    assert np.ptp(e) < 1e-9
    for c in ("upper_right", "lower_left", "lower_right", "upper_left", "beak"):
        assert res[f"contact/{c}/g_n"].min() > -1e-9, c
    period = np.diff(wp.pecks(res))
    assert len(period) >= 4 and 0.14 < period.mean() < 0.18
    assert res.stats["events"] > 100 and res["joint/sleeve/q"][-1, 1] < -0.15


def test_poisson_returns_the_stored_tangential_impulse():
    """A ball (no spin) hits a very rough floor obliquely. Compression stops the contact point
    (the tangential impulse (2/7) m g_T- stays inside the cone), expansion returns eps Lambda_NC
    and eps_t Lambda_TC: it leaves with g_N+ = -eps g_N- and g_T+ = -eps_t g_T-, the superball's
    reversal; Newton's law cannot give it (its tangential outcome is a stop or a slide)."""
    r, vx, eps, eps_t = 0.1, 1.0, 0.5, 0.4
    m = ms.Model("superball", gravity=(0.0, 0.0, -G))
    b = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, r))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, 0.5 + r, 1, 0, 0, 0], u0=[vx, 0, 0, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=r)),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(2.0), impact=ms.laws.Poisson(eps, eps_t)))
    res = ms.simulate(m, 0.6, ED, output_dt=1e-3)
    t_hit = np.sqrt(2 * 0.5 / G)
    impacts = [e["t"] for e in res.events if e["event"] == "impact"]
    assert abs(impacts[0] - t_hit) < 1e-12
    before, after = res.t < t_hit, (res.t > t_hit) & (res.t < 0.55)
    gd_t = res["contact/floor/gd_t"][:, 0]
    gt_before = gd_t[before][-1]
    np.testing.assert_allclose(gd_t[after], -eps_t * gt_before, rtol=1e-9)
    vz = res["body/ball/velocity"][:, 2]
    v_in = G * t_hit
    np.testing.assert_allclose(vz[after][0], eps * v_in - G * (res.t[after][0] - t_hit), rtol=1e-9)
    e = res["energy/total"] + res["energy/dissipated"]
    assert np.ptp(e) < 1e-9  # the spinning ball's body-frame velocities: integration error
    # the impulses: normal (1 + eps) m v_in, tangential (1 + eps_t) (2/7) m |g_T-|
    np.testing.assert_allclose(res["contact/floor/impulse_n"].sum(), (1 + eps) * v_in, rtol=1e-9)
    np.testing.assert_allclose(np.abs(res["contact/floor/impulse_t"][:, 0].sum()), (1 + eps_t) * 2 / 7 * abs(gt_before), rtol=1e-9)


def test_bilateral_constraints_with_contacts_agree_with_the_joint_model():
    """A pendulum bob striking a wall (Newton, eps = 0.7, friction 0.3), once hung on a revolute
    joint, once a planar body held by a distance constraint (the constrained inverse mass in the
    impact and transition problems): the same impact times and motion."""

    def pendulum(constrained):
        m = ms.Model("pendulum", gravity=(0.0, -G, 0.0))
        b = m.add_body("bob", 1.0, [1e-12, 1e-12, 1e-12])
        if constrained:
            m.add_joint(ms.joints.Planar("plane", m.ground, b, q0=[np.sin(1.0), -np.cos(1.0), 0.0]))
            m.add_constraint(ms.constraints.Distance("rod", m.ground, b, length=1.0))
        else:
            m.add_joint(ms.joints.Revolute("pin", m.ground, b, axis=(0, 0, 1), child_frame=(0, 1.0, 0), q0=1.0))
        m.add_contact(ms.Contact("wall", b.contour(ms.contours.Point()),
                                 m.ground.contour(ms.contours.Line(point=(-0.35, 0, 0), normal=(1, 0, 0))),
                                 friction=ms.laws.Coulomb(0.3), impact=ms.laws.Newton(0.7)))
        return m

    a = ms.simulate(pendulum(False), 3.0, ED, output_dt=1e-2)
    b = ms.simulate(pendulum(True), 3.0, ED, output_dt=1e-2)
    ta = [e["t"] for e in a.events if e["event"] == "impact"]
    tb = [e["t"] for e in b.events if e["event"] == "impact"]
    assert len(ta) == len(tb) >= 2
    np.testing.assert_allclose(ta, tb, atol=1e-9)
    np.testing.assert_allclose(a["body/bob/position"], b["body/bob/position"], atol=1e-8)
    # the swing before the first impact keeps its energy; the impacts take (1 - eps^2) of the
    # normal kinetic energy, which the balance accounts for
    for r in (a, b):
        e = r["energy/total"] + r["energy/dissipated"]
        assert np.ptp(e) < 1e-9 * abs(e[0]) and r["energy/dissipated_impact"][-1] > 0.1
    assert np.abs(b["constraint/rod/violation"]).max() < 1e-10


def test_block_slows_along_the_stribeck_curve_and_stops_at_the_closed_form_time():
    """v' = -mu(v) g with mu(v) = mu + (mu0 - mu) exp(-(v / v_s)^2), against SciPy's solution of
    the same ODE to 1e-8 (time-stepping reaches 2e-3), the stop located to 1e-8 s."""
    from scipy.integrate import solve_ivp

    mu0, mu, v_s, v0 = 0.5, 0.2, 0.3, 2.0
    m = ms.Model("stribeck", gravity=(0.0, 0.0, -G))
    half = (0.1, 0.05, 0.05)
    b = m.add_body("block", 1.0, ms.inertia.box(1.0, (0.2, 0.1, 0.1)))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, half[2], 1, 0, 0, 0], u0=[v0, 0, 0, 0, 0, 0]))
    m.add_contact(ms.Contact("base", b.contour(ms.contours.Box(half_extents=half)),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Stribeck(mu0=mu0, mu=mu, v_s=v_s)))
    res = ms.simulate(m, 1.5, ED, output_dt=1e-2)
    law = lambda v: mu + (mu0 - mu) * np.exp(-((v / v_s) ** 2))  # noqa: E731
    stop = lambda t, y: y[0]  # noqa: E731
    stop.terminal = True
    ref = solve_ivp(lambda t, y: [-law(y[0]) * G], (0, 1.5), [v0], rtol=1e-12, atol=1e-14, dense_output=True, events=stop)
    t_stop = ref.t_events[0][0]
    sticks = [e["t"] for e in res.events if e["event"] == "stick"]
    assert abs(sticks[0] - t_stop) < 1e-8
    v = res["body/block/velocity"][:, 0]
    moving = res.t < t_stop
    np.testing.assert_allclose(v[moving], ref.sol(res.t[moving])[0], atol=1e-8)
    assert np.abs(v[res.t > t_stop]).max() < 1e-12
