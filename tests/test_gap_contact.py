"""Contacts given by user gap functions (mechsys.GapContact): expressions and Python callables,
in both contact schemes, against closed forms of impacts, lift-off and friction."""

import subprocess
import sys

import numpy as np
import pytest
from scipy.special import ellipkinc, ellipk

import mechsys as ms
from mechsys.errors import CallbackError, ModelError

G, L, D, A0 = 9.81, 1.0, 0.3, 0.5  # gravity, pendulum length, wall distance, release angle


def pendulum(gap, eps: float = 0.5, friction=None, tangents=()) -> ms.Model:
    """A point-mass pendulum (length L, angle 'swing' from hanging, counter-clockwise) released
    from rest at -A0 towards a wall at x = D given by ``gap``."""
    m = ms.Model("pendulum", gravity=(0.0, -G, 0.0), planar=True)
    bob = m.add_body("bob", 1.0, np.zeros((3, 3)), com=(0.0, -L, 0.0))
    m.add_joint(ms.joints.Revolute("swing", m.ground, bob, axis=(0, 0, 1), q0=-A0))
    m.add_contact(ms.GapContact("wall", gap=gap, tangents=tangents, friction=friction, impact=ms.laws.Newton(eps=eps)))
    return m


def impact_time_and_rate() -> tuple[float, float]:
    """First impact of the pendulum on the wall: time from release (complete and incomplete
    elliptic integrals of the first kind) and angular rate just before it (energy)."""
    k = np.sin(A0 / 2)
    theta = np.arcsin(D / L)
    phi = np.arcsin(np.sin(theta / 2) / k)
    m = k * k  # scipy's parameter m = k^2
    t = (ellipkinc(phi, m) + ellipk(m)) / np.sqrt(G / L)
    return float(t), float(np.sqrt(2 * G / L * (np.cos(theta) - np.cos(A0))))


def first_impact(res) -> dict:
    ev = [e for e in res.events if e["event"] == "impact" and e["contact"] == "wall"]
    assert ev, "no impact on the wall"
    return ev[0]


@pytest.mark.parametrize("gap", ["0.3 - 1.0 * sin(swing)", lambda q, t: 0.3 - np.sin(q[0]),
                                  lambda q, t: 0.3 - __import__("math").sin(q[0])],
                         ids=["expression", "callable-taylor", "callable-differences"])
def test_a_pendulum_hits_a_wall_given_by_its_gap_at_the_closed_form_time_and_rebounds_by_newton(gap):
    t_star, rate = impact_time_and_rate()
    res = ms.simulate(pendulum(gap), t_end=t_star + 0.3, integrator=ms.EventDriven(rtol=1e-10, atol=1e-12),
                      output_dt=1e-3)
    ev = first_impact(res)
    assert abs(ev["t"] - t_star) < 1e-7
    np.testing.assert_allclose(ev["u_before"], [rate], rtol=1e-6)
    np.testing.assert_allclose(ev["u_after"], [-0.5 * rate], rtol=1e-6)
    # the impulse is the generalized one along dg/dq = -L cos(theta): m L^2 (1 + e) theta' / (L cos(theta))
    theta = np.arcsin(D / L)
    np.testing.assert_allclose(ev["impulse_n"], L * L * 1.5 * rate / (L * np.cos(theta)), rtol=1e-6)
    assert res["contact/wall/g_n"].min() > -1e-9


def test_the_moreau_jean_scheme_keeps_the_pendulum_out_of_the_wall_and_rebounds_by_newton():
    t_star, rate = impact_time_and_rate()
    res = ms.simulate(pendulum("0.3 - sin(swing)", eps=0.5), t_end=t_star + 0.2, integrator=ms.MoreauJean(dt=1e-4),
                      output_dt=1e-4)
    q, u = res["joint/swing/q"], res["joint/swing/u"]
    assert q.max() < np.arcsin(D / L) + 1e-3
    k = int(np.argmax(u < 0))  # first sample moving back
    assert abs(res.t[k] - t_star) < 2e-4
    np.testing.assert_allclose(u[k], -0.5 * rate, rtol=2e-3)


def test_rows_and_velocity_product_terms_of_a_time_dependent_gap_match_finite_differences():
    # a planar body (x, y, angle) and a gap with every kind of term: coordinates, products, time
    m = ms.Model("rows", gravity=(0.0, -G, 0.0), planar=True)
    b = m.add_body("b", 1.0, np.eye(3) * 0.01)
    m.add_joint(ms.joints.Planar("p", m.ground, b, q0=[0.1, 0.2, 0.3]))
    expr = "p[1] - 0.1 * sin(3 * t) * cos(p[2]) + 0.05 * p[0]^2 * exp(-t)"
    tan = "p[0] + 0.2 * p[2] * t"
    m.add_contact(ms.GapContact("g", gap=expr, tangents=[tan], friction=ms.laws.Coulomb(mu=0.3)))

    def g(q, t):
        return q[1] - 0.1 * np.sin(3 * t) * np.cos(q[2]) + 0.05 * q[0] ** 2 * np.exp(-t)

    def s(q, t):
        return q[0] + 0.2 * q[2] * t

    q, u, t = np.array([0.1, 0.2, 0.3]), np.array([0.7, -0.4, 1.1]), 0.37
    cm = ms.dynamics.contact_matrices(m, q, u, t)
    h = 1e-6
    for k, f in enumerate([g, s]):
        row = 0 if k == 0 else 1
        grad = np.array([(f(q + h * e, t) - f(q - h * e, t)) / (2 * h) for e in np.eye(3)])
        np.testing.assert_allclose(cm["w"][0, row], grad, atol=1e-8)
        # along the motion (q + u s, t + s): g' and its velocity-product part g'' (u' = 0)
        hs = 1e-4
        fp, f0, fm = f(q + u * hs, t + hs), f(q, t), f(q - u * hs, t - hs)
        np.testing.assert_allclose(cm["velocity"][0, row], (fp - fm) / (2 * hs), atol=1e-8)
        np.testing.assert_allclose(cm["wbar"][0, row], (fp - 2 * f0 + fm) / hs**2, atol=1e-5)
    assert cm["gap"][0] == pytest.approx(g(q, t), abs=1e-15)
    assert cm["contact"] == ["g"]


def shaker(amplitude: float, omega: float) -> ms.Model:
    """A block resting on a table that moves up and down as A sin(omega t): gap = y - A sin(omega t)."""
    m = ms.Model("shaker", gravity=(0.0, -G, 0.0), planar=True)
    b = m.add_body("block", 2.0, np.eye(3) * 0.01)
    m.add_joint(ms.joints.Prismatic("lift", m.ground, b, axis=(0, 1, 0), q0=0.0, u0=amplitude * omega))
    m.add_contact(ms.GapContact("table", gap=f"lift - {amplitude} * sin({omega} * t)"))
    return m


def test_a_block_on_a_shaker_table_lifts_off_where_the_table_falls_faster_than_gravity():
    amplitude, omega = 0.01, 40.0  # A omega^2 = 16 m/s^2 > g
    t_off = np.arcsin(G / (amplitude * omega**2)) / omega
    res = ms.simulate(shaker(amplitude, omega), t_end=t_off + 0.01, integrator=ms.EventDriven(rtol=1e-10, atol=1e-12),
                      output_dt=1e-4)
    ev = [e for e in res.events if e["contact"] == "table" and e["event"] == "open"]
    assert ev, [e["event"] for e in res.events]
    assert abs(ev[0]["t"] - t_off) < 1e-7
    before = res.t < t_off - 1e-3
    # riding on the table: y = A sin(omega t), and the table carries m (g + y'')
    np.testing.assert_allclose(res["joint/lift/q"][before], amplitude * np.sin(omega * res.t[before]), atol=1e-9)
    lam = 2.0 * (G - amplitude * omega**2 * np.sin(omega * res.t[before]))
    np.testing.assert_allclose(res["contact/table/lambda_n"][before][1:], lam[1:], rtol=1e-6)
    # the table's motion does work on the block through the contact force: the energy balance holds
    e = res["energy/total"] - res["energy/external_work"]
    assert np.abs(e - e[0]).max() < 1e-6


def test_a_block_sliding_on_a_gap_floor_stops_where_coulomb_friction_says():
    mu, v0 = 0.4, 2.0
    for integrator, tol in ((ms.EventDriven(rtol=1e-10, atol=1e-12), 1e-7), (ms.MoreauJean(dt=1e-4), 2e-3)):
        m = ms.Model("slide", gravity=(0.0, -G, 0.0), planar=True)
        b = m.add_body("block", 1.5, np.eye(3) * 0.01)
        m.add_joint(ms.joints.Planar("p", m.ground, b, q0=[0.0, 0.0, 0.0], u0=[v0, 0.0, 0.0]))
        m.add_contact(ms.GapContact("floor", gap="p[1]", tangents=["p[0]"], friction=ms.laws.Coulomb(mu=mu)))
        res = ms.simulate(m, t_end=1.0, integrator=integrator, output_dt=1e-3)
        x = res["joint/p/q"][:, 0]
        np.testing.assert_allclose(x[-1], v0**2 / (2 * mu * G), rtol=tol * 10)
        t_stop = v0 / (mu * G)
        sliding = res.t < t_stop - 0.01
        np.testing.assert_allclose(res["contact/floor/lambda_t"][sliding][2:], -mu * 1.5 * G, rtol=tol * 10)
        np.testing.assert_allclose(res["contact/floor/lambda_n"][2:], 1.5 * G, rtol=tol * 10)


def test_bad_gap_functions_are_refused_naming_the_contact():
    with pytest.raises(ModelError, match=r"gap_contacts\[0\] 'wall'.gap: unknown name 'swang' \(joint coordinates: swing; and t\)"):
        pendulum("0.3 - sin(swang)").build()
    with pytest.raises(ModelError, match=r"'wall'.gap: expected a number, a name or '\(', found the end"):
        pendulum("0.3 - ").build()
    with pytest.raises(ModelError, match="'wall'.friction: a friction law needs a tangential coordinate"):
        pendulum("0.3 - sin(swing)", friction=ms.laws.Coulomb(mu=0.3)).build()
    with pytest.raises(ModelError, match=r"'wall'.gap: \"0.3 - 0.1 \* t\" reads no joint coordinate"):
        pendulum("0.3 - 0.1 * t").build()
    with pytest.raises(ModelError, match="'wall'.tangents: at most 2 tangential coordinates"):
        pendulum("0.3 - sin(swing)", tangents=["swing"] * 3).build()
    m = ms.Model("free", gravity=(0, 0, -G))
    b = m.add_body("ball", 1.0, np.eye(3) * 0.1)
    m.add_joint(ms.joints.Free("fly", m.ground, b))
    m.add_contact(ms.GapContact("floor", gap="fly[2]"))
    with pytest.raises(ModelError, match="joint 'fly' turns by a quaternion"):
        m.build()
    with pytest.raises(ModelError, match="expected an expression .* or a callable"):
        pendulum(3.0).build()
    # a function that raises or returns NaN stops the run with the contact named
    bad = pendulum(lambda q, t: 0.3 - np.sin(q[0]) + (1 / 0 if t > 0.1 else 0.0))
    with pytest.raises(CallbackError, match="gap contact 'wall'.gap: the function raised ZeroDivisionError"):
        ms.simulate(bad, t_end=0.5, integrator=ms.EventDriven())
    nan = pendulum(lambda q, t: 0.3 - np.sin(q[0]) + (np.nan if t > 0.1 else 0.0))
    with pytest.raises(CallbackError, match="gap contact 'wall': gap is not finite"):
        ms.simulate(nan, t_end=0.5, integrator=ms.MoreauJean(dt=1e-3))


def test_a_gap_contact_in_a_model_file_runs_from_the_command_line(tmp_path):
    path = tmp_path / "stop.toml"
    path.write_text(f"""
name = "stop"
gravity = [0.0, -9.81, 0.0]
planar = true
[[bodies]]
name = "bob"
mass = 1.0
inertia = [0.0, 0.0, 0.0]
com = [0.0, -1.0, 0.0]
[[joints]]
name = "swing"
type = "revolute"
parent = "ground"
child = "bob"
axis = [0.0, 0.0, 1.0]
q0 = [-{A0}]
[[gap_contacts]]
name = "wall"
gap = "{D} - sin(swing)"
impact = {{ type = "newton", eps = 0.5 }}
[simulation]
t_end = 1.0
integrator = "event_driven"
""")
    out = tmp_path / "stop.h5"
    run = subprocess.run([sys.executable, "-m", "mechsys", "run", str(path), "--out", str(out), "--quiet"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    res = ms.load(out)
    assert abs(first_impact(res)["t"] - impact_time_and_rate()[0]) < 1e-6


def test_a_gap_held_closed_is_a_constraint_written_by_hand():
    # a bead on a circle of radius R: hypot(x, y) - R = 0 held, released from the side at rest
    R, x0 = 0.8, 0.3
    m = ms.Model("bead", gravity=(0.0, -G, 0.0), planar=True)
    b = m.add_body("bead", 0.5, np.eye(3) * 1e-3)
    y0 = -np.sqrt(R * R - x0 * x0)
    m.add_joint(ms.joints.Planar("p", m.ground, b, q0=[x0, y0, 0.0]))
    m.add_contact(ms.GapContact("hoop", gap=f"{R} - hypot(p[0], p[1])", normal=ms.laws.Bilateral()))
    res = ms.simulate(m, t_end=2.0, output_dt=1e-3, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12))
    q = res["joint/p/q"]
    np.testing.assert_allclose(np.hypot(q[:, 0], q[:, 1]), R, atol=1e-9)
    # the hoop's force: m (g cos(phi) + v^2 / R) towards the centre, phi from the bottom
    phi0 = np.arcsin(x0 / R)
    phi = np.arctan2(q[:, 0], -q[:, 1])
    v2 = 2 * G * R * (np.cos(phi) - np.cos(phi0))
    lam = res["constraint/hoop/lambda"]
    # g = R - |r| grows inwards: its force pushes inwards, the tension of a pendulum string
    np.testing.assert_allclose(lam, 0.5 * (G * np.cos(phi) + v2 / R), rtol=1e-6)
    e = res["energy/total"]
    assert np.abs(e - e[0]).max() < 1e-8


def test_a_held_gap_rolling_on_its_tangent_coordinate_rolls_a_cylinder_down_an_incline():
    alpha, r, mass = 0.3, 0.1, 2.0
    m = ms.Model("roll", gravity=(G * np.sin(alpha), -G * np.cos(alpha), 0.0), planar=True)
    b = m.add_body("cyl", mass, ms.inertia.cylinder(mass, r, 0.05, axis="z"))
    m.add_joint(ms.joints.Planar("p", m.ground, b, q0=[0.0, r, 0.0]))
    # contact point slides by x + r phi: rolling holds its rate at zero
    m.add_contact(ms.GapContact("floor", gap=f"p[1] - {r}", tangents=[f"p[0] + {r} * p[2]"],
                                normal=ms.laws.Bilateral(rolling=True)))
    res = ms.simulate(m, t_end=1.0, output_dt=0.01)
    np.testing.assert_allclose(res["joint/p/q"][:, 0], 0.5 * (2.0 / 3.0) * G * np.sin(alpha) * res.t**2, atol=1e-9)
    lam = res["constraint/floor/lambda"]
    np.testing.assert_allclose(lam[:, 0], mass * G * np.cos(alpha), rtol=1e-8)
    # the tangent's force holds back a third of the slope force (along -x: the tangent grows with x)
    np.testing.assert_allclose(lam[:, 1], -mass * G * np.sin(alpha) / 3.0, rtol=1e-8)


def test_linearizing_with_a_closed_gap_contact_held():
    k, mass = 200.0, 2.0
    m = ms.Model("spring-block", gravity=(0.0, -G, 0.0), planar=True)
    b = m.add_body("block", mass, np.eye(3) * 0.01)
    m.add_joint(ms.joints.Planar("p", m.ground, b, q0=[0.0, 0.0, 0.0]))
    m.add_force(ms.forces.SpringDamper("spring", m.ground, b, point1=(-1.0, 0.0, 0.0), k=k, l0=1.0))
    m.add_contact(ms.GapContact("floor", gap="p[1]", tangents=["p[0]"], friction=ms.laws.Coulomb(mu=0.5)))
    with pytest.raises(ms.errors.SettingsError, match="contact 'floor' is closed"):
        ms.linear.linearize(m)
    f = np.sort(ms.linear.linearize(m, contacts="hold").modes().natural_frequency)
    np.testing.assert_allclose(f[-1], np.sqrt(k / mass) / (2 * np.pi), rtol=1e-9)
    # sticking holds x as well: the block's free turning is all that is left, without stiffness
    lin = ms.linear.linearize(m, contacts="roll")
    assert lin.n == 1 and abs(lin.K[0, 0]) < 1e-12 and lin.M[0, 0] == pytest.approx(0.01)


def test_the_hopping_part_of_the_shaker_example_balances_its_energy_in_both_schemes():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "shaker_table.py"
    spec = importlib.util.spec_from_file_location("shaker_table", path)
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    ends = []
    for integrator, tol in ((ex.simulation["integrator"], 1e-9), (ms.MoreauJean(dt=1e-5), 1e-12)):
        res = ms.simulate(ex.model, t_end=0.3, integrator=integrator, output_dt=1e-4)
        # the table works on the part through the contact forces and the landing impulses (-Lambda w~)
        work = res["energy/external_work"]
        assert work[-1] > 5e-3 and res["energy/dissipated"][-1] > 5e-3
        balance = res["energy/total"] + res["energy/dissipated"] - work
        assert np.abs(balance - balance[0]).max() < tol
        ends.append(res["joint/lift/q"][-1])
    # the two schemes land the part at the same place after some 60 hops
    assert abs(ends[0] - ends[1]) < 1e-5


def _arm(kind: str) -> ms.Model:
    """An arm falling about a horizontal hinge onto a stop at 0.2 rad (gravity presses it on)."""
    m = ms.Model("arm", gravity=(0.0, 0.0, -G))
    arm = m.add_body("arm", 1.0, np.eye(3) * 0.01, com=(0.5, 0.0, 0.0))
    m.add_joint(ms.joints.Revolute("hinge", m.ground, arm, axis=(0, 1, 0), q0=-0.3))
    if kind == "gap":
        m.add_contact(ms.GapContact("stop", gap="sin(0.2 - hinge)", impact=ms.laws.Newton(eps=0.5)))
    else:  # the same stop as a point on the arm against a plane through the hinge: n . tip = sin(0.2 - q)
        m.add_contact(ms.Contact("stop", arm.contour(ms.contours.Point(position=(1.0, 0.0, 0.0))),
                                 m.ground.contour(ms.contours.Plane(normal=(np.sin(0.2), 0.0, np.cos(0.2)))),
                                 impact=ms.laws.Newton(eps=0.5)))
    return m


def test_an_accumulation_of_impacts_on_a_gap_stop_ends_closed_as_on_the_same_contour_stop():
    runs = {}
    for kind in ("gap", "contour"):
        res = ms.simulate(_arm(kind), t_end=1.5, integrator=ms.EventDriven(), output_dt=1e-3)
        impacts = [e["t"] for e in res.events if e["event"] == "impact"]
        close = [e["t"] for e in res.events if e["event"] == "close"]
        runs[kind] = (impacts, close, res["joint/hinge/q"], res["contact/stop/state"][-1], res["contact/stop/lambda_n"][-1])
    gap, contour = runs["gap"], runs["contour"]
    assert len(gap[0]) == len(contour[0]) > 10
    np.testing.assert_allclose(gap[0], contour[0], atol=1e-9)
    assert len(gap[1]) == 1 and abs(gap[1][0] - contour[1][0]) < 1e-9
    assert gap[3] == 1 and gap[2].max() <= 0.2 + 1e-12
    # resting on the stop: the gap's force along d(sin(0.2 - q))/dq = -1 holds the gravity moment m g x_c cos(0.2)
    np.testing.assert_allclose(gap[4], 1.0 * G * 0.5 * np.cos(0.2), rtol=1e-9)
