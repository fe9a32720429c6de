"""Signorini's law with a compliant layer (``laws.Signorini(compliance=c, damping=d)``) under
Moreau-Jean time-stepping: ``g_N + c lambda_N >= 0`` (with damping ``lambda_N = k delta + d
delta'``), solved as the rigid contact problem regularized by ``c/(h (h + c d))`` on each normal
diagonal with the gap term ``g_N/(h + c d)``.

Checked against closed forms: the overlap of a resting body is ``c`` times its weight on every
assembly path (sparse rows, dense rows of a gap contact) and every solver; a layer's free vibration
about that rest is ``g_s + A cos(omega t)`` with ``omega = sqrt(k/m)``, the error falling at first
order in the step (the layer's implicit Euler step), with the energy balance closing to round-off;
equal layers share a box's weight equally among its four corners (the rigid problem's forces are
not unique there); the sweeps of a settling pile converge in tens instead of thousands."""

import pathlib
import warnings

import numpy as np
import pytest

import mechsys as ms
from piles import R as PILE_R, box_pile

G = 9.81


def ball_on_floor(compliance, mass=2.0, radius=0.1, z0=None, damping=0.0, friction=True, u0=None):
    m = ms.Model("layer", gravity=(0, 0, -G))
    b = m.add_body("ball", mass, ms.inertia.sphere(mass, radius))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=[0, 0, radius if z0 is None else z0, 1, 0, 0, 0], u0=u0))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=radius)),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             normal=ms.laws.Signorini(compliance=compliance, damping=damping),
                             friction=ms.laws.Coulomb(0.5) if friction else None))
    m.build()
    return m


def energy_balance(res):
    e = (res["energy/kinetic"] + res["energy/potential"] + res["energy/contact_elastic"] + res["energy/dissipated"]
         - res["energy/external_work"])
    return e - e[0]


@pytest.mark.parametrize("solver", [ms.NSGS(tol=1e-12), ms.Newton(tol=1e-12), ms.Auto(tol=1e-12), ms.APGD(tol=1e-12)],
                         ids=["nsgs", "newton", "auto", "apgd"])
def test_a_resting_ball_overlaps_by_its_weight_times_the_compliance(solver):
    c, mass = 1e-6, 2.0
    res = ms.simulate(ball_on_floor(c, mass), 0.3, ms.MoreauJean(1e-3, solver=solver), output_dt=1e-3)
    w = mass * G
    np.testing.assert_allclose(res["contact/floor/g_n"][-1], -c * w, rtol=1e-9)
    np.testing.assert_allclose(res["contact/floor/lambda_n"][-1], w, rtol=1e-9)
    np.testing.assert_allclose(res["energy/contact_elastic"][-1], 0.5 * c * w * w, rtol=1e-9)
    # a rigid floor (the same model, compliance 0) holds the ball without overlap and stores nothing
    rigid = ms.simulate(ball_on_floor(0.0, mass), 0.3, ms.MoreauJean(1e-3, solver=solver), output_dt=1e-3)
    assert abs(rigid["contact/floor/g_n"][-1]) < 1e-12
    assert np.all(rigid["energy/contact_elastic"] == 0.0)


def test_the_overlap_does_not_depend_on_the_step_or_the_damping():
    """(The layer's vibration from the first touch decays by the implicit Euler factor
    (1 + (omega h)^2)^(-1/2) per step: at h = 2e-4, omega h = 0.12, to 1e-14 of it in 1 s.)"""
    c, mass = 2e-6, 1.5
    for h, d in ((1e-3, 0.0), (2e-4, 0.0), (1e-3, 5e3)):
        res = ms.simulate(ball_on_floor(c, mass, damping=d), 1.0, ms.MoreauJean(h, solver=ms.NSGS(tol=1e-13)),
                          output_dt=1e-2)
        np.testing.assert_allclose(res["contact/floor/g_n"][-1], -c * mass * G, rtol=1e-9, err_msg=f"h={h}, d={d}")


def test_a_gap_contact_on_the_dense_rows_overlaps_the_same():
    """A slider on a vertical prismatic joint whose gap function is its coordinate: the dense
    assembly path (user gap functions), regularized on W's diagonal."""
    c, mass = 5e-6, 3.0
    m = ms.Model("slider", gravity=(0, 0, -G))
    b = m.add_body("slider", mass, ms.inertia.box(mass, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=0.0))
    m.add_contact(ms.GapContact("stop", gap="z", normal=ms.laws.Signorini(compliance=c)))
    m.build()
    # (omega h = 0.26: the vibration from the first touch decays to 1e-14 of itself in 1 s)
    res = ms.simulate(m, 1.0, ms.MoreauJean(1e-3, solver=ms.Lemke()), output_dt=1e-3)
    np.testing.assert_allclose(res["joint/z/q"][-1], -c * mass * G, rtol=1e-9)
    np.testing.assert_allclose(res["energy/contact_elastic"][-1], 0.5 * c * (mass * G) ** 2, rtol=1e-9)


def test_free_vibration_on_the_layer_converges_at_first_order_with_an_exact_energy_balance():
    """m z'' = -m g + k (-g_N) about the rest overlap g_s = -m g / k: g(t) = g_s + A cos(omega t).
    Released from 1.5 g_s at rest it stays closed (A = g_s / 2). The scheme integrates the layer by
    an implicit Euler step (numerical damping of relative (omega h)^2 / 2 per step), so halving h
    halves the error; the energy balance with the layer's energy closes to round-off."""
    k, mass, radius = 1e4, 1.0, 0.1
    omega, gs = np.sqrt(k / mass), -mass * G / k
    amp = 0.5 * gs
    errors = []
    for h in (2e-4, 1e-4, 5e-5):
        m = ball_on_floor(1.0 / k, mass, radius, z0=radius + gs + amp, friction=False)
        res = ms.simulate(m, 0.05, ms.MoreauJean(h, solver=ms.Newton(tol=1e-14)), output_dt=h)
        z = res["body/ball/position"][:, 2] - radius
        exact = gs + amp * np.cos(omega * res.t)
        errors.append(np.abs(z - exact).max())
        assert np.abs(energy_balance(res)).max() < 1e-12
        assert res["contact/floor/lambda_n"][1:].min() > 0.0  # never opens
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(ratios, 2.0, rtol=0.03)
    # the size of the error: the amplitude's decay A (1 - exp(-omega^2 h T / 2)) is 2.4e-5 at h = 2e-4
    # and T = 0.05 s (1.5e-5 measured, the largest difference over the run)
    assert 5e-6 < errors[0] < 2.4e-5


def test_a_damped_layer_takes_the_bounce_out_of_a_drop_and_the_balance_closes():
    """Dropped from 0.2 m onto an undamped stiff layer (omega h = 0.22) the ball bounces back to
    about half its height: the layer gives back what it stored (less the scheme's numerical
    damping), whatever the plastic impact law. Damped critically (d = 2 sqrt(k m)) or at four
    times that, the ball hops by under a millimetre (a Kelvin-Voigt layer lets go while the ball
    still moves up: 0.08 and 0.2 mm measured). All come to rest at the static overlap, and the
    energy balance (kinetic, potential, the layer's, dissipated) closes to round-off."""
    c, mass = 1e-5, 2.0
    crit = 2.0 * np.sqrt(mass / c)
    hops = []
    for d in (0.0, crit, 4 * crit):
        res = ms.simulate(ball_on_floor(c, mass, z0=0.3, damping=d, friction=False), 1.0, ms.MoreauJean(1e-3),
                          output_dt=1e-3)
        touch = np.flatnonzero(res["contact/floor/lambda_n"] > 0)[0]
        hops.append(res["contact/floor/g_n"][touch:].max())
        assert np.abs(energy_balance(res)).max() < 1e-12
        if d > 0:
            np.testing.assert_allclose(res["contact/floor/g_n"][-1], -c * mass * G, rtol=1e-6)
    assert 0.05 < hops[0] < 0.2
    assert hops[1] < 1e-3 and hops[2] < 1e-3


@pytest.mark.parametrize("zeta", [0.3, 1.0])
def test_a_ball_leaves_a_damped_layer_at_the_kelvin_voigt_separation_speed(zeta):
    """A ball dropped on a Kelvin-Voigt layer (m x'' = m g - k x - d x' for the overlap x from the
    touch) leaves it where the layer's force k x + d x' falls to zero, while the layer is still
    deflected; it then flies, and its highest point above the touch is -x_s + v_s^2 / (2 g). The
    scheme's hop converges to that at first order: the error falls tenfold from h = 1e-4 to 1e-5
    (measured 2.33 -> 0.24 mm at zeta = 0.3 of a 37.2 mm hop, 0.12 -> 0.012 mm at zeta = 1)."""
    from scipy.integrate import solve_ivp

    c, mass, radius, z0 = 1e-5, 2.0, 0.1, 0.3
    k, d = 1.0 / c, zeta * 2.0 * np.sqrt(mass / c)
    leaves = lambda t, y: k * y[0] + d * y[1]  # noqa: E731 - the event function
    leaves.terminal, leaves.direction = True, -1
    sol = solve_ivp(lambda t, y: [y[1], G - (k * y[0] + d * y[1]) / mass], (0.0, 1.0), [0.0, np.sqrt(2 * G * (z0 - radius))],
                    events=leaves, rtol=1e-12, atol=1e-15, max_step=1e-5)
    x_s, v_s = sol.y_events[0][0]
    hop = -x_s + v_s**2 / (2 * G)
    errors = []
    for h in (1e-4, 1e-5):
        res = ms.simulate(ball_on_floor(c, mass, radius, z0=z0, damping=d, friction=False), 0.45, ms.MoreauJean(h), output_dt=h)
        touch = np.flatnonzero(res["contact/floor/lambda_n"] > 0)[0]
        errors.append(abs(res["contact/floor/g_n"][touch:].max() - hop))
    assert 6.0 < errors[0] / errors[1] < 15.0, errors
    assert errors[1] < 0.02 * hop, (errors, hop)


@pytest.mark.parametrize("zeta", [0.0, 0.3, 1.0, 4.0])
@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_every_step_of_a_drop_on_a_layer_dissipates(zeta, h):
    """The layer carries its deflection from step to step, so what it takes in from the deflection
    it starts from is its spring's and its damper's: a step's impact dissipation is never
    negative beyond the scheme's split of the step's impulse from gravity's, -1/2 Lambda (g h -
    Lambda/m) >= -m g^2 h^2 / 8 for a ball (2.4e-5 J at h = 1e-3; the layer's deflection taken at
    c lambda_N while it crept back out gave -1.5e-4 J). No point joins its layer overlapped, so
    nothing is booked as the geometry's (dissipated_drift stays 0)."""
    c, mass = 1e-5, 2.0
    d = zeta * 2.0 * np.sqrt(mass / c)
    res = ms.simulate(ball_on_floor(c, mass, z0=0.3, damping=d, friction=False), 1.0, ms.MoreauJean(h), output_dt=h)
    step = np.diff(res["energy/dissipated_impact"])
    assert step.min() >= -mass * G**2 * h**2 / 8 * (1 + 1e-9) - 1e-15, step.min()
    assert np.abs(res["energy/dissipated_drift"]).max() == 0.0
    assert np.abs(energy_balance(res)).max() < 1e-12
    if zeta > 0:  # the damped layers take the drop's energy (undamped, the ball keeps bouncing)
        assert step.sum() > 0.5 * mass * G * 0.2, step.sum()


def test_a_layer_let_go_relaxes_on_its_own_and_its_damper_takes_what_it_held():
    """A ball resting on a strongly damped layer (tau = c d = 20 ms) is pulled up at t = 0.05 s by
    three times its weight. The layer cannot follow: it lets go while still deflected, and without
    force it relaxes by the implicit Euler factor tau/(h + tau) per step, so the energy it holds
    falls by that factor squared per step, to round-off, all of it into the damper (a layer
    without a state of its own was pressed again at the ball's overlap every step instead). The
    state given as overlapped at t = 0 brings its layer's energy 1/2 k g_N^2 as the geometry's."""
    c, mass, radius, h, tau = 1e-5, 2.0, 0.1, 1e-4, 0.02
    g0 = -c * mass * G
    m = ms.Model("layer-pull", gravity=(0, 0, -G))
    b = m.add_body("ball", mass, ms.inertia.sphere(mass, radius))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=[0, 0, radius + g0, 1, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=radius)), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             normal=ms.laws.Signorini(compliance=c, damping=tau / c)))
    m.add_force(ms.forces.BodyForce("pull", b, force=(0.0, 0.0, 3 * mass * G), function=lambda t: 1.0 if t >= 0.05 else 0.0))
    m.build()
    res = ms.simulate(m, 0.06, ms.MoreauJean(h), output_dt=h)
    held, lam, g = res["energy/contact_elastic"], res["contact/floor/lambda_n"], res["contact/floor/g_n"]
    np.testing.assert_allclose(res["energy/dissipated_drift"][-1], -0.5 * g0**2 / c, rtol=1e-9)
    np.testing.assert_allclose(held[int(0.04 / h)], 0.5 * g0**2 / c, rtol=1e-9)  # at rest: the weight's deflection
    free = np.flatnonzero((lam[1:] == 0.0) & (lam[:-1] == 0.0) & (g[1:] < 0.0) & (res.t[1:] > 0.05)) + 1
    assert len(free) > 10, free
    w = tau / (h + tau)
    np.testing.assert_allclose(held[free] / held[free - 1], w * w, rtol=1e-9)
    lost = held[free - 1] - held[free]
    np.testing.assert_allclose(np.diff(res["energy/dissipated_impact"])[free - 1], lost, rtol=1e-6, atol=1e-15)
    assert np.abs(energy_balance(res)).max() < 1e-12


def stack(n, compliance, mass=1.0, half=(0.1, 0.1, 0.05)):
    m = ms.Model("stack", gravity=(0.0, 0.0, -G))
    shape = ms.contours.Box(half_extents=half)
    law = ms.laws.Signorini(compliance=compliance)
    boxes = []
    for k in range(n):
        b = m.add_body(f"box{k}", mass, ms.inertia.box(mass, tuple(2 * h for h in half)))
        m.add_joint(ms.joints.Free(f"f{k}", m.ground, b, q0=[0, 0, half[2] * (2 * k + 1), 1, 0, 0, 0]))
        boxes.append(b)
    m.add_contact(ms.Contact("floor", boxes[0].contour(shape), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(0.5), normal=law))
    for k in range(1, n):
        m.add_contact(ms.Contact(f"on{k}", boxes[k].contour(shape), boxes[k - 1].contour(shape), friction=ms.laws.Coulomb(0.5),
                                 normal=law))
    m.build()
    return m


@pytest.mark.parametrize("solver", [ms.NSGS(tol=1e-12, max_iter=100_000), ms.Newton(tol=1e-12), ms.Auto(tol=1e-12)],
                         ids=["nsgs", "newton", "auto"])
def test_equal_layers_share_each_boxs_load_equally_among_its_corners(solver):
    """A stack of four boxes on compliant layers: each interface's four corners carry a quarter of
    the weight above it and overlap by c times that quarter, to 1e-8 N (with rigid contacts only
    the corners' sum is determined)."""
    n, mass, c = 4, 1.0, 1e-6
    res = ms.simulate(stack(n, c, mass), 0.5, ms.MoreauJean(1e-3, solver=solver), output_dt=1e-2)
    for k, name in enumerate(["floor"] + [f"on{i}" for i in range(1, n)]):
        lam, g = res[f"contact/{name}/lambda_n"][-1], res[f"contact/{name}/g_n"][-1]
        closed = np.flatnonzero(lam > 0)
        assert len(closed) == 4, name
        quarter = (n - k) * mass * G / 4
        np.testing.assert_allclose(lam[closed], quarter, atol=1e-8, err_msg=name)
        np.testing.assert_allclose(g[closed], -c * quarter, rtol=1e-6, err_msg=name)


def test_auto_sweeps_a_well_regularized_problem_and_takes_newton_on_a_stiff_one():
    """`auto` on a stack whose layers regularize every normal diagonal by more than 1 % (c/h^2 =
    1 against W_NN of a few 1/kg) is its Gauss-Seidel setting, bit for bit; with layers 1e4 times
    stiffer it keeps Newton (fewer iterations than the sweeps need)."""
    auto, tol = ms.Auto(tol=1e-10), 1e-10
    sweeps = ms.NSGS(tol=tol, max_iter=auto.nsgs_max_iter, anderson=auto.nsgs_anderson, stall=1024)
    soft = [ms.simulate(stack(3, 1e-6), 0.2, ms.MoreauJean(1e-3, solver=s), output_dt=1e-3) for s in (auto, sweeps)]
    for name in ("q", "u", "solver/iterations", "solver/residual"):
        assert np.array_equal(soft[0][name], soft[1][name]), name
    stiff = [ms.simulate(stack(3, 1e-10), 0.2, ms.MoreauJean(1e-3, solver=s), output_dt=1e-3) for s in (auto, sweeps)]
    assert stiff[0]["solver/converged"][1:].all()
    assert stiff[0]["solver/iterations"][1:].sum() < stiff[1]["solver/iterations"][1:].sum()


@pytest.fixture(scope="module")
def pile1000():
    return box_pile([(0.0, 0.0, PILE_R + 2.2 * PILE_R * i) for i in range(1000)], 0.55, name="pile-1000")


def pile_steps(model, n=5):
    """`n` steps of the 1000-sphere pour on layers of k = 1e6 N/m from its own state at t = 0.8 s
    (``data/pile1000_layer_settling.npz``: ``benches/contacts.py``'s pile, seed 0, ``Auto(tol=1e-4)``,
    dt 1e-3, saved from the compliant pour, so its overlaps are the layers' own and nothing pops)."""
    d = np.load(pathlib.Path(__file__).parent / "data" / "pile1000_layer_settling.npz")
    t0 = float(d["t"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an unconverged step warns; the report is checked
        return ms.simulate(model, t0 + n * 1e-3, ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-4, max_iter=10_000, anderson=4)),
                           q0=d["q"], u0=d["u"], t0=t0, output_dt=1e-3, progress=False,
                           sensors=["solver/*", "energy/kinetic"])


def compliant_pile(c):
    return box_pile([(0.0, 0.0, PILE_R + 2.2 * PILE_R * i) for i in range(1000)], 0.55, name="pile-1000", compliance=c)


def test_a_settling_pile_on_compliant_layers_converges_in_tens_of_sweeps(pile1000):
    """The same settling state of the 1000-sphere pour (about 2040 contact points, two-domain
    sweeps) stepped on rigid contacts and on its layers of k = 1e6 N/m: rigid, five steps take
    thousands of sweeps (1155, 610, 685, 1640, 1416 measured); on the layers tens (66, 41, 41, 41,
    45). The pile stays as it was on both (its contacts within 3 %, its kinetic energy within
    20 %): a state whose overlaps the layers did not make would be pushed apart instead, and its
    few remaining contacts would converge fast for the wrong reason."""
    rigid = pile_steps(pile1000)
    soft = pile_steps(compliant_pile(1e-6))
    for res in (rigid, soft):
        assert res["solver/converged"][1:].all()
        contacts = res["solver/contacts"][1:]
        assert contacts.min() > 1900 and contacts.min() > 0.97 * contacts.max(), contacts
        ke = res["energy/kinetic"]
        assert ke.max() < 1.2 * ke[0] and ke.min() > 0.8 * ke[0], ke
    it_rigid, it_soft = rigid["solver/iterations"][1:].sum(), soft["solver/iterations"][1:].sum()
    assert it_rigid > 2500, it_rigid
    assert it_soft < 600, it_soft


def test_a_layer_takes_no_restitution_on_top_of_its_own():
    with pytest.raises(ms.ModelError, match=r"'floor'\.impact: a compliant Signorini layer rebounds"):
        m = ms.Model("bad", gravity=(0, 0, -G))
        b = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, 0.1))
        m.add_joint(ms.joints.Free("f", m.ground, b))
        m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=0.1)),
                                 m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))), normal=ms.laws.Signorini(compliance=1e-6),
                                 impact=ms.laws.Newton(eps=0.5)))
        m.build()
    # a plastic Newton law goes with it (the pile's groups)
    assert box_pile([(0.0, 0.0, PILE_R)], 0.3, compliance=1e-6) is not None


@pytest.mark.parametrize("kwargs, key", [({"compliance": -1.0}, "compliance"), ({"compliance": float("nan")}, "compliance"),
                                         ({"compliance": "soft"}, "compliance"), ({"compliance": True}, "compliance"),
                                         ({"compliance": 1e-6, "damping": -2.0}, "damping"),
                                         ({"damping": 10.0}, "damping")])
def test_bad_layers_are_refused_naming_the_contact_and_the_key(kwargs, key):
    with pytest.raises(ms.ModelError, match=rf"contact 'floor'\.normal\.{key}"):
        m = ms.Model("bad", gravity=(0, 0, -G))
        b = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, 0.1))
        m.add_joint(ms.joints.Free("f", m.ground, b))
        m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=0.1)),
                                 m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))), normal=ms.laws.Signorini(**kwargs)))
        m.build()


def test_a_group_with_a_bad_layer_is_refused_by_name():
    with pytest.raises(ms.ModelError, match=r"contact group 'pile'\.normal\.compliance"):
        box_pile([(0.0, 0.0, PILE_R)], 0.3, compliance=-1e-6)


def test_the_event_driven_scheme_refuses_a_compliant_layer_by_contact_name():
    with pytest.raises(ms.SettingsError, match=r"contact 'floor' has a compliant Signorini law.*MoreauJean"):
        ms.simulate(ball_on_floor(1e-6), 0.1, ms.EventDriven())


def test_a_model_file_carries_the_layer(tmp_path):
    """Written by the TOML writer and read back (normal = { type = "signorini", compliance, damping })."""
    from mechsys.modelfile import load_model
    from mechsys.tomlwrite import dumps

    path = tmp_path / "layer.toml"
    path.write_text(dumps(ball_on_floor(1e-6, damping=30.0).describe()[0]))
    text = path.read_text()
    assert 'type = "signorini"' in text and "compliance = 1e-06" in text and "damping = 30.0" in text
    back, _ = load_model(path)
    res = ms.simulate(back, 0.3, ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-12)), output_dt=1e-2)
    np.testing.assert_allclose(res["contact/floor/g_n"][-1], -1e-6 * 2.0 * G, rtol=1e-9)
    # `mechsys info` names the layer and the one scheme that takes it
    from click.testing import CliRunner
    from mechsys.cli import cli

    shown = CliRunner().invoke(cli, ["info", str(path)])
    assert shown.exit_code == 0, shown.output
    assert "compliant layer k = 1e+06 N/m, d = 30 N s/m" in shown.output
    assert "moreau_jean (compliant layers: time-stepping only)" in shown.output
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("compliance = 1e-06", "compliance = -1e-06"))
    with pytest.raises(ms.ModelError, match=r"bad\.toml.*normal\.compliance"):
        load_model(bad)


def test_linearized_with_the_contact_held_a_layer_is_its_spring_and_damper():
    """At rest on its layer (overlap c m g), `linearize(contacts="hold")` holds the contact as the
    layer: the bounce mode's natural frequency is sqrt(k/m) and its damping ratio d/(2 sqrt(k m))
    (the four other rigid-body directions free, frequency 0)."""
    c, mass = 1e-5, 2.0
    k = 1.0 / c
    for d in (0.0, 150.0):
        m = ball_on_floor(c, mass, damping=d)
        res = ms.simulate(m, 1.0, ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-13)), output_dt=1e-2)
        lin = ms.linear.linearize(m, q=res["q"][-1], u=np.zeros(6), contacts="hold")
        modes = lin.modes()
        bounce = int(np.argmax(modes.natural_frequency))
        np.testing.assert_allclose(modes.natural_frequency[bounce], np.sqrt(k / mass) / (2 * np.pi), rtol=1e-9)
        np.testing.assert_allclose(modes.damping_ratio[bounce], d / (2 * np.sqrt(k * mass)), rtol=1e-9, atol=1e-12)
        assert np.sort(modes.natural_frequency)[-2] < 1e-3
    # a layer touched without load has a kink: refused by name
    with pytest.raises(ms.SettingsError, match=r"contact 'floor' touches without pressing its compliant layer"):
        ms.linear.linearize(ball_on_floor(c, mass), contacts="hold")


def ball_in_bowl(c, mass=1.0, r=0.05, radius=0.5, friction=True):
    m = ms.Model("bowl", gravity=(0, 0, -G))
    b = m.add_body("ball", mass, ms.inertia.sphere(mass, r))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=[0, 0, -(radius - r), 1, 0, 0, 0]))
    m.add_contact(ms.Contact("bowl", b.contour(ms.contours.Sphere(radius=r)), m.ground.contour(ms.contours.Bowl(radius=radius)),
                             normal=ms.laws.Signorini(compliance=c), friction=ms.laws.Coulomb(0.8) if friction else None))
    m.build()
    return m


def test_a_ball_rolling_in_a_bowl_on_its_layer_rocks_at_the_rolling_frequency():
    """A ball (radius r) at rest at the bottom of a spherical bowl (radius R) on a layer of
    k = 1e9 N/m, linearized with the contact held: sliding ("hold") it rocks at
    sqrt(g/(R - r)), rolling without slip ("roll": the layer carries the normal force, a
    tangents-only bilateral contact the friction) at sqrt(5 g / (7 (R - r))), the classical
    rolling ball in a bowl; in both its bounce on the layer is sqrt(k/m), and the spin about the
    normal is free. (Before, "roll" on a layer was refused.)"""
    c, mass, r, radius = 1e-9, 1.0, 0.05, 0.5
    m = ball_in_bowl(c, mass, r, radius)
    q = np.array([0.0, 0.0, -(radius - r) - c * mass * G, 1.0, 0.0, 0.0, 0.0])
    bounce = np.sqrt(1.0 / (c * mass)) / (2 * np.pi)
    # (central differences, the layer's force being no exact-derivative law: 8e-9 and 1.4e-8
    # measured, where the overlap c m g shifts the closed forms by about 1e-8; a curvature bound
    # of a millionth of the overlap on the differences' step had left 2.5e-6 on the rolling one)
    for mode, rock, tol in (("hold", np.sqrt(G / (radius - r)), 1e-7), ("roll", np.sqrt(5 * G / (7 * (radius - r))), 1e-7)):
        lin = ms.linear.linearize(m, q=q, u=np.zeros(6), contacts=mode)
        f = np.sort(lin.modes().natural_frequency)
        np.testing.assert_allclose(f[-1], bounce, rtol=1e-6, err_msg=mode)
        np.testing.assert_allclose(f[-3:-1], rock / (2 * np.pi), rtol=tol, err_msg=mode)
        assert np.abs(f[:-3]).max() < 1e-6 * rock, (mode, f)
    held = ms.linear.linearize(m, q=q, u=np.zeros(6), contacts="roll").model
    assert {c["name"] for c in held.engine()[0].constraints()} == {"bowl_rolling"}
    # a frictionless layer cannot roll; a gap contact's layer rolls in no tangent plane of its own
    with pytest.raises(ms.SettingsError, match=r"contact 'bowl' has a frictionless compliant Signorini layer.*contacts='hold'"):
        ms.linear.linearize(ball_in_bowl(c, mass, r, radius, friction=False), q=q, u=np.zeros(6), contacts="roll")


def test_rolling_on_a_layer_that_would_slip_is_refused_by_name():
    """The same ball held by its layer on a bowl's flank under a sideways pull larger than
    mu0 times the layer's normal force would have to slip: refused naming the contact."""
    c, mass, r, radius = 1e-9, 1.0, 0.05, 0.5
    m2 = ms.Model("bowl-pulled", gravity=(0, 0, -G))
    b = m2.add_body("ball", mass, ms.inertia.sphere(mass, r))
    m2.add_joint(ms.joints.Free("f", m2.ground, b, q0=[0, 0, -(radius - r), 1, 0, 0, 0]))
    m2.add_contact(ms.Contact("bowl", b.contour(ms.contours.Sphere(radius=r)), m2.ground.contour(ms.contours.Bowl(radius=radius)),
                              normal=ms.laws.Signorini(compliance=c), friction=ms.laws.Coulomb(0.1)))
    m2.add_force(ms.forces.BodyForce("pull", b, force=(0.5 * mass * G, 0.0, 0.0), point=(0.0, 0.0, r)))
    m2.build()
    q = np.array([0.0, 0.0, -(radius - r) - c * mass * G, 1.0, 0.0, 0.0, 0.0])
    with pytest.raises(ms.SettingsError, match=r"contact 'bowl' cannot roll on its compliant layer at the point"):
        ms.linear.linearize(m2, q=q, u=np.zeros(6), contacts="roll", operating_point=True)


def test_a_tangents_only_bilateral_contact_and_the_static_equilibrium_on_a_layer():
    """laws.Bilateral(rolling=True, hold_normal=False) holds only the tangents (the constraint's
    columns are t1, t2); without rolling it holds nothing and is refused by name. The static
    equilibrium of the ball in the bowl with its layer held rolling sinks it by c m g and leaves
    no friction force."""
    with pytest.raises(ms.ModelError, match=r"hold_normal: False holds only the tangents, so it needs rolling=True"):
        ms.laws.Bilateral(hold_normal=False).describe("contact 'x'.normal")
    c, mass, r, radius = 1e-6, 1.0, 0.05, 0.5
    m = ball_in_bowl(c, mass, r, radius)
    eq = ms.analysis.static_equilibrium(m, q=[0.0, 0.0, -(radius - r), 1.0, 0.0, 0.0, 0.0], contacts="roll")
    np.testing.assert_allclose(eq["q"][2], -(radius - r) - c * mass * G, rtol=0, atol=1e-12)
    assert set(eq["lambda"]) == {"bowl_rolling"} and np.abs(eq["lambda"]["bowl_rolling"]).max() < 1e-9
    held = ms.linear.linearize(m, q=eq["q"], u=np.zeros(6), contacts="roll").model
    (info,) = held.engine()[0].constraints()
    assert info["columns"] == ["t1", "t2"] and info["holonomic_rows"] == 0
    # the model file carries the key, and a gap contact refuses it by name
    desc, _ = held.describe()
    roller = next(d for d in desc["contacts"] if d["name"] == "bowl_rolling")
    assert roller["normal"] == {"type": "bilateral", "rolling": True, "hold_normal": False}
    g = ms.Model("gap", gravity=(0, 0, -G))
    b = g.add_body("slider", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    g.add_joint(ms.joints.Prismatic("z", g.ground, b, axis=(0, 0, 1)))
    g.add_contact(ms.GapContact("stop", gap="z", tangents=["z"], normal=ms.laws.Bilateral(rolling=True, hold_normal=False)))
    with pytest.raises(ms.ModelError, match=r"gap_contacts\[0\] 'stop'\.normal: hold_normal = false .* is for contour contacts"):
        g.build()


def test_released_aside_the_ball_rolls_in_the_bowl_at_the_linearized_rolling_frequency():
    """The nonsmooth run (Moreau-Jean, the unilateral contact on its layer with Coulomb friction)
    from 2 cm aside: the ball rolls without slipping (slip speed below 1e-9 m/s) and rocks at the
    rolling frequency sqrt(5 g / (7 (R - r))) of the linearization, to 1e-3 (measured 0.6280 Hz;
    sliding would be 0.7431 Hz)."""
    c, mass, r, radius, side = 1e-7, 1.0, 0.05, 0.5, 0.02
    m = ball_in_bowl(c, mass, r, radius)
    rho = radius - r + c * mass * G
    start = [rho * np.sin(side / rho), 0.0, -rho * np.cos(side / rho), 1.0, 0.0, 0.0, 0.0]
    rolling = np.sqrt(5 * G / (7 * (radius - r))) / (2 * np.pi)
    res = ms.simulate(m, 2.2 / rolling, ms.MoreauJean(1e-3), output_dt=1e-3, q0={"f": start})
    f = 1.0 / ms.analysis.period(res.t, res["body/ball/position"][:, 0])
    np.testing.assert_allclose(f, rolling, rtol=1e-3)
    assert np.abs(res["contact/bowl/gd_t"]).max() < 1e-9


@pytest.mark.parametrize("c", [1e-6, 1e-8, 1e-10])
@pytest.mark.parametrize("mode", ["hold", "roll"])
def test_the_static_equilibrium_on_a_stiff_layer_from_the_touching_point(c, mode):
    """From the ball just touching the bowl, the equilibrium with the layer held sinks it by
    c m g (to 1e-12 m) at any stiffness. The Newton iteration's stiffness by central differences
    (step 1e-7) had reached across the layer's kink at zero overlap from 1e7 N/m on, and its
    tolerance, relative to the forces at the iterate (nothing at an equilibrium), sat below the
    round-off of a stiff contact: it failed from 1e7 N/m on."""
    m = ball_in_bowl(c, 1.0, 0.05, 0.5)
    eq = ms.analysis.static_equilibrium(m, q=[0.0, 0.0, -0.45, 1.0, 0.0, 0.0, 0.0], contacts=mode)
    np.testing.assert_allclose(eq["q"][2], -0.45 - c * 1.0 * G, rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq["q"][:2], 0.0, atol=1e-12)
