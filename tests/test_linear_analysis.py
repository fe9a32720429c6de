"""Linear vibration analysis (issue 5): linearization points, Campbell diagrams with forward and
backward whirl of a gyroscopic rotor, frequency responses and the power equation against time
simulation, hysteresis loops (eq. 2.213, Fig. 2.37), and bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import simpson

import mechsys as ms

G = 9.81
IP, ID, KT = 0.04, 0.025, 400.0  # disc polar and diametral inertia (kg m^2), tilt springs (N m/rad)


def rotor(ip=IP, id_=ID, kt=KT, spin=0.0):
    """Ground -> tilt alpha about x -> tilt beta about y -> spin about z with a disc; the gimbal
    bodies' inertia (1e-12 kg m^2) is negligible against the disc's."""
    m = ms.Model("rotor", gravity=(0.0, 0.0, 0.0))
    g1 = m.add_body("gimbal1", 1e-3, [1e-12] * 3)
    g2 = m.add_body("gimbal2", 1e-3, [1e-12] * 3)
    disc = m.add_body("disc", 2.0, [id_, id_, ip])
    m.add_joint(ms.joints.Revolute("alpha", m.ground, g1, axis=(1, 0, 0), spring=ms.joints.JointSpring(kt)))
    m.add_joint(ms.joints.Revolute("beta", g1, g2, axis=(0, 1, 0), spring=ms.joints.JointSpring(kt)))
    m.add_joint(ms.joints.Revolute("spin", g2, disc, axis=(0, 0, 1), u0=spin))
    return m


def whirl_frequencies(speed, ip=IP, id_=ID, kt=KT):
    """Forward and backward tilt frequencies (Hz): I_d w^2 -+ I_p W w - k_t = 0 for the complex
    tilt alpha + j beta (Cardan tilts at zero tilt: I_d a'' + I_p W b' + k a = 0, I_d b'' - I_p W a' + k b = 0)."""
    root = np.sqrt((speed * ip) ** 2 + 4 * id_ * kt)
    return (abs(speed) * ip + root) / (2 * id_) / (2 * np.pi), (-abs(speed) * ip + root) / (2 * id_) / (2 * np.pi)


def chain2(m=(1.0, 1.5), k=(100.0, 150.0), d=(8.0, 3.0), force=None):
    """ground -k0,d0- m0 -k1,d1- m1 on prismatic joints along x, an optional harmonic load on x0."""
    mod = ms.Model("chain2", gravity=(0.0, 0.0, 0.0))
    b = [mod.add_body(f"m{i}", m[i], [1e-3] * 3) for i in range(2)]
    for i in range(2):
        mod.add_joint(ms.joints.Prismatic(f"x{i}", mod.ground, b[i], axis=(1, 0, 0), parent_frame=(i + 1.0, 0, 0)))
    mod.add_force(ms.forces.SpringDamper("s0", mod.ground, b[0], k=k[0], d=d[0], l0=1.0))
    mod.add_force(ms.forces.SpringDamper("s1", b[0], b[1], k=k[1], d=d[1], l0=1.0))
    if force is not None:
        amp, omega = force
        mod.add_force(ms.forces.JointForce("load", "x0", amp, function=ms.functions.Harmonic(1.0, omega)))
    return mod


def fit_phasor(t, y, omega):
    """Complex amplitude X of y ~ c + Re(X e^(j omega t)) by least squares."""
    a = np.column_stack([np.ones_like(t), np.cos(omega * t), np.sin(omega * t)])
    _, c, s = np.linalg.lstsq(a, y, rcond=None)[0]
    return complex(c, -s)


# ---- linearization points ------------------------------------------------------------------------


def hanging(k=500.0, m=2.0):
    mod = ms.Model("hanging", gravity=(0.0, -G, 0.0))
    b = mod.add_body("mass", m, [1e-3] * 3)
    mod.add_joint(ms.joints.Prismatic("y", mod.ground, b, axis=(0, 1, 0), spring=ms.joints.JointSpring(k)))
    return mod


def test_at_equilibrium_q0_and_dicts():
    mod = hanging()
    with pytest.warns(UserWarning, match="not an equilibrium"):
        ms.linear.linearize(mod)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lin = ms.linear.linearize(mod, at="equilibrium")
    np.testing.assert_allclose(lin.q, [-2.0 * G / 500.0], rtol=1e-10)
    assert lin.model is mod and lin.K[0, 0] == pytest.approx(500.0, rel=1e-9)
    assert "model" not in repr(lin).split("names=")[-1]
    # the same point given three ways
    y_eq = float(lin.q[0])
    for at in ({"q": {"y": y_eq}}, {"y": y_eq}, {"q": [y_eq], "u": [0.0]}):
        other = ms.linear.linearize(mod, at=at)
        np.testing.assert_allclose(other.q, lin.q, rtol=1e-14)
        np.testing.assert_allclose(other.residual, 0.0, atol=1e-9)
    np.testing.assert_allclose(ms.linear.linearize(mod, q={"y": y_eq}).q, lin.q, rtol=1e-14)
    # at=None and "q0" are the model's q0
    with pytest.warns(UserWarning):
        assert ms.linear.linearize(mod, at="q0").q[0] == 0.0


def test_singular_mass_matrix_names_the_coordinate():
    mod = ms.Model("light", gravity=(0.0, 0.0, 0.0))
    c = mod.add_body("cart", 1.0, [1.0] * 3)
    mod.add_joint(ms.joints.Prismatic("p", mod.ground, c, axis=(1, 0, 0), spring=ms.joints.JointSpring(10.0)))
    b = mod.add_body("flywheel", 1.0, [1e-20] * 3)
    mod.add_joint(ms.joints.Revolute("wheel", c, b, axis=(0, 0, 1), spring=ms.joints.JointSpring(10.0)))
    with pytest.raises(ms.ModelError, match="singular.*'wheel'"):
        ms.linear.linearize(mod)


@pytest.mark.parametrize(
    "at, fragment",
    [("equlibrium", "at='equlibrium'"), (3.5, "at: expected"), ({"q": {"nojoint": 1.0}}, "nojoint"),
     ({"q": [0.0, 1.0]}, "at['q']"), ({"q": "abc"}, "at['q']")],
)
def test_bad_at_names_the_item(at, fragment):
    with pytest.raises((ms.SettingsError, ms.ModelError)) as e:
        ms.linear.linearize(hanging(), at=at)
    assert fragment in str(e.value)


# ---- Campbell diagram of the gyroscopic rotor ------------------------------------------------------


def test_rotor_gyroscopic_matrix_is_skew_and_matches_the_disc():
    spin = 150.0
    lin = ms.linear.linearize(rotor(spin=spin))
    g = lin.G
    assert np.abs(g).max() > 0
    assert np.abs(g + g.T).max() <= 1e-12 * np.abs(g).max()
    np.testing.assert_allclose(g[0, 1], IP * spin, rtol=1e-9)
    np.testing.assert_allclose(lin.M[:2, :2], ID * np.eye(2), rtol=1e-9)


def test_campbell_matches_the_closed_form_with_whirl_labels():
    w0 = np.sqrt(KT / ID)
    speeds = np.linspace(0.0, 3 * w0, 16)
    lin = ms.linear.linearize(rotor())
    c = lin.campbell(speeds, joint="spin", whirl=("alpha", "beta"))
    assert c.frequencies.shape == (16, 2)  # the spin's rigid-body mode is left out
    worst = 0.0
    for k, s in enumerate(speeds):
        ff, fb = whirl_frequencies(s)
        got = np.sort(c.frequencies[k])
        worst = max(worst, abs(got[0] / fb - 1), abs(got[1] / ff - 1))
        if k == 0:
            assert list(c.whirl[k]) == ["", ""]
        else:
            by = dict(zip(c.whirl[k], c.frequencies[k]))
            assert set(by) == {"forward", "backward"}
            np.testing.assert_allclose([by["forward"], by["backward"]], [ff, fb], rtol=1e-6)
    assert worst <= 1e-6, worst
    # each column is one whirl direction throughout (tracking keeps the branches apart)
    assert {tuple(set(c.whirl[1:, j])) for j in range(2)} == {("forward",), ("backward",)}
    # the backward branch crosses the 1x line where I_d W^2 + I_p W^2 = k_t
    (cs,) = c.critical_speeds()
    assert cs["whirl"] == "backward"
    np.testing.assert_allclose(cs["speed"], np.sqrt(KT / (ID + IP)), rtol=2e-2)  # linear interpolation


def test_campbell_negative_speed_order_tracking_and_indices():
    lin = ms.linear.linearize(rotor())
    c = lin.campbell([-200.0, 200.0], joint="spin", whirl="0,1", track="order")
    ff, fb = whirl_frequencies(200.0)
    for k in range(2):
        np.testing.assert_allclose(c.frequencies[k], [fb, ff], rtol=1e-9)
        assert list(c.whirl[k]) == ["backward", "forward"]


def test_campbell_plot_and_table(tmp_path):
    lin = ms.linear.linearize(rotor())
    c = lin.campbell(np.linspace(0, 300, 7), joint="spin", whirl=("alpha", "beta"))
    out = tmp_path / "c.png"
    c.plot(out=out, orders=(1, 2))
    assert out.read_bytes()[:4] == b"\x89PNG"
    assert c.table().count("\n") == 7 and " f" in c.table() and " b" in c.table()


def test_campbell_bad_input():
    lin = ms.linear.linearize(rotor())
    with pytest.raises(ms.SettingsError, match="unknown joint 'spinn'"):
        lin.campbell([0.0, 10.0], joint="spinn")
    m = ms.Model("ball", gravity=(0.0, 0.0, 0.0))
    b = m.add_body("b", 1.0, [1.0, 1.0, 2.0])
    m.add_joint(ms.joints.Spherical("ball", m.ground, b))
    with pytest.raises(ms.SettingsError, match="joint 'ball' \\(spherical\\) has 3 velocities"):
        ms.linear.linearize(m).campbell([1.0], joint="ball")
    with pytest.raises(ms.SettingsError, match="whirl: no coordinate named 'gamma'"):
        lin.campbell([1.0], joint="spin", whirl=("alpha", "gamma"))
    with pytest.raises(ms.SettingsError, match="values"):
        lin.campbell([np.nan], joint="spin")


# ---- frequency response against time simulation ----------------------------------------------------


def test_frf_equals_the_simulated_steady_state():
    """|H(j w)| F and the phase against DOPRI5 after the transient (30 s; the slowest mode decays
    as exp(-1.04 t)): fitted over the whole periods of the last 5 s, at four frequencies
    including both resonances (zeta = 0.18 and 0.31)."""
    lin = ms.linear.linearize(chain2())
    fn = lin.modes().natural_frequency
    worst = 0.0
    for f in (0.6 * fn[0], fn[0], 0.5 * (fn[0] + fn[1]), fn[1]):
        omega, amp = 2 * np.pi * f, 2.0
        res = ms.simulate(chain2(force=(amp, omega)), 30.0, ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=2e-3)
        period = 2 * np.pi / omega
        tail = res.t >= res.t[-1] - max(np.floor(5.0 / period), 1) * period - 1e-9
        h = lin.frf(f, inputs=["x0"])[0, :, 0]
        for j, name in enumerate(("x0", "x1")):
            y = res[f"joint/{name}/q"][tail]
            x_sim = fit_phasor(res.t[tail], y, omega)
            x_lin = h[j] * (-1j * amp)  # the load amp sin(w t) has the phasor -j amp
            worst = max(worst, abs(x_sim - x_lin) / abs(x_lin))
    assert worst < 1e-6, worst


def test_frf_modal_equals_direct_and_falls_back_with_rigid_modes():
    lin = ms.linear.linearize(chain2())
    f = np.linspace(0.1, 5.0, 50)
    np.testing.assert_allclose(lin.frf(f, method="modal"), lin.frf(f, method="direct"), rtol=1e-10, atol=1e-14)
    spun = ms.linear.linearize(rotor(spin=100.0))
    np.testing.assert_allclose(spun.frf(f, inputs=[0], outputs=[1]), spun.frf(f, inputs=[0], outputs=[1], method="direct"),
                               rtol=1e-12)
    with pytest.raises(ms.SettingsError, match="method='modal'"):
        spun.frf(f, method="modal")
    # proportional damping (D = K / 100) and a free spin at standstill: the real modes of K, M
    for other in (ms.linear.linearize(chain2(d=(1.0, 1.5))), ms.linear.linearize(rotor())):
        assert other._frf_real_modes(2 * np.pi * f, [0], [0]) is not None
        np.testing.assert_allclose(other.frf(f, method="modal"), other.frf(f, method="direct"), rtol=1e-10, atol=1e-14)
    with pytest.raises(ms.SettingsError, match="frequencies"):
        lin.frf([-1.0], method="modal")
    with pytest.raises(ms.SettingsError, match="method must be"):
        lin.frf([1.0], method="fast")


# ---- the power equation (eq. 2.206) ----------------------------------------------------------------


def test_energy_lost_equals_the_dissipation_integral():
    mod = chain2()
    lin = ms.linear.linearize(mod)
    assert np.abs(lin.D - lin.D.T).max() == 0 and lin.D[0, 1] == pytest.approx(-3.0)
    res = ms.simulate(mod, 3.0, ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=1e-3, q0={"x0": 0.02, "x1": -0.03})
    y, yd = lin.deviation(res["q"], res["u"])
    ek, ep = lin.energy(y, yd)
    e = ek + ep
    lost = e[0] - e[-1]
    integral = simpson(np.einsum("ki,ij,kj->k", yd, lin.D, yd), x=res.t)
    assert abs(lost / integral - 1) < 1e-6, lost / integral - 1
    assert abs(res["energy/dissipated"][-1] / integral - 1) < 1e-6
    pb = lin.power_balance(res.t, y, yd)
    # by hand: the dampers d0 = 8 on x0' and d1 = 3 on x1' - x0' (review: not vT D v restated)
    np.testing.assert_allclose(pb["dissipation"], -(8.0 * yd[:, 0] ** 2 + 3.0 * (yd[:, 1] - yd[:, 0]) ** 2), rtol=1e-12)
    # dE/dt = y'^T M y'' + y'^T K y = -2R along the free motion (to the integrator's tolerance), and
    # to second-order differences of E (at dt = 1 ms, about (w dt)^2) without the accelerations
    exact = lin.power_balance(res.t, y, yd, res["udot"])
    assert np.abs(exact["external"]).max() < 1e-8 * np.abs(pb["dissipation"]).max()
    assert np.abs(pb["external"]).max() < 1e-3 * np.abs(pb["dissipation"]).max()


# ---- hysteresis ------------------------------------------------------------------------------------


def test_hysteresis_of_a_viscous_damper_and_a_spring():
    d, k, xa, omega = 3.0, 200.0, 0.02, 7.0
    t = np.linspace(0.0, 3 * 2 * np.pi / omega, 6001)
    x = 0.1 + xa * np.sin(omega * t + 0.3)
    v = xa * omega * np.cos(omega * t + 0.3)
    h = ms.linear.hysteresis(t, x, d * v + k * (x - 0.1) + 5.0, cycles=2)
    w_exact = np.pi * d * omega * xa**2
    assert abs(h.work / w_exact - 1) < 1e-4
    assert abs(h.d_eq / d - 1) < 1e-4 and abs(h.k_eq / k - 1) < 1e-9
    assert abs(h.amplitude / xa - 1) < 1e-9 and abs(h.omega / omega - 1) < 1e-9
    assert h.force_mean == pytest.approx(5.0, rel=1e-9) and h.loss_factor == pytest.approx(d * omega / k, rel=1e-4)
    spring = ms.linear.hysteresis(t, x, k * x, period=2 * np.pi / omega)
    assert abs(spring.work) < 1e-9 * k * xa**2 and abs(spring.d_eq) < 1e-8
    flipped = ms.linear.hysteresis(t, x, -d * v, period=2 * np.pi / omega, sign=-1)
    assert abs(flipped.work / w_exact - 1) < 1e-4
    # the equal-area ellipse encloses W_D
    ex, ef = h.ellipse(20001)
    assert abs(np.sum(0.5 * (ef[1:] + ef[:-1]) * np.diff(ex)) / h.work - 1) < 1e-6


def test_hysteresis_of_a_simulated_spring_damper(tmp_path):
    """A mass on a spring-damper under a harmonic force: the element's force/deflection loop
    at steady state gives W_D = pi d w x_a^2 = the work the load puts in per cycle, d_eq = d."""
    k, d, omega = 300.0, 4.0, 10.0
    mod = ms.Model("sdof", gravity=(0.0, 0.0, 0.0))
    b = mod.add_body("m", 2.0, [1e-3] * 3)
    mod.add_joint(ms.joints.Prismatic("x", mod.ground, b, axis=(1, 0, 0), parent_frame=(1.0, 0, 0)))
    mod.add_force(ms.forces.SpringDamper("mount", mod.ground, b, k=k, d=d, l0=1.0))
    mod.add_force(ms.forces.JointForce("load", "x", 3.0, function=ms.functions.Harmonic(1.0, omega)))
    res = ms.simulate(mod, 12.0, ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=5e-4)
    h = ms.linear.hysteresis(res.t, res["force/mount/deflection"], res["force/mount/force"], cycles=3)
    assert abs(h.omega / omega - 1) < 1e-5  # period found from the mean crossings of the signal
    assert abs(h.work / (np.pi * d * omega * h.amplitude**2) - 1) < 1e-4
    assert abs(h.d_eq / d - 1) < 1e-4 and abs(h.k_eq / k - 1) < 1e-4
    period = 2 * np.pi / omega
    ext = res["energy/external_work"]
    per_cycle = (ext[-1] - np.interp(res.t[-1] - 3 * period, res.t, ext)) / 3
    assert abs(h.work / per_cycle - 1) < 1e-4
    out = tmp_path / "loop.png"
    h.plot(out=out)
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_hysteresis_bad_input():
    t = np.linspace(0, 1, 100)
    with pytest.raises(ms.SettingsError, match="less than 3 period"):
        ms.linear.hysteresis(t, np.sin(20 * t), np.cos(20 * t), period=0.5, cycles=3)
    with pytest.raises(ms.SettingsError, match="sign"):
        ms.linear.hysteresis(t, np.sin(20 * t), np.cos(20 * t), sign=2)
    with pytest.raises(ms.SettingsError, match="displacement: expected a 1-D"):
        ms.linear.hysteresis(t, np.zeros((100, 2)), t)
    with pytest.raises(ms.SettingsError, match="period"):
        ms.linear.hysteresis(t, t, t)


def test_modal_damping_gives_each_mode_its_ratio():
    from test_linear import chain

    lin = ms.linear.linearize(chain(2.0, 300.0))
    zeta = [0.01, 0.05, 0.2]
    modes = lin.modal_damping(zeta).modes()
    np.testing.assert_allclose(modes.damping_ratio, zeta, rtol=1e-10)
    # the undamped frequencies stay
    np.testing.assert_allclose(modes.natural_frequency, lin.modes().natural_frequency, rtol=1e-10)
    with pytest.raises(ms.SettingsError, match="damping ratios"):
        lin.modal_damping([0.1, -0.1, 0.1])
    with pytest.raises(ms.SettingsError, match="one damping ratio or 3"):
        lin.modal_damping([0.1, 0.2])


def test_mode_shapes_mapped_back_to_the_bodies():
    # pendulum: the bob's centre moves along the tangent, l times the joint's angle; it turns about z
    mod = ms.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    b = mod.add_body("bob", 1.5, [1e-3] * 3, com=(0.0, -0.8, 0.0))
    mod.add_joint(ms.joints.Revolute("pin", mod.ground, b, axis=(0, 0, 1)))
    lin = ms.linear.linearize(mod)
    modes = lin.modes()
    shape = lin.body_shapes(modes)["bob"][0]
    theta = modes.shapes[0, 0]
    np.testing.assert_allclose(shape, np.array([0.8, 0, 0, 0, 0, 1.0]) * theta, atol=1e-12)


def test_campbell_of_a_model_with_constraints():
    # a constrained model linearizes as "exact+fd-constraints"; the Campbell sweep must re-linearize
    # it the same way (a held slider beside the rotor leaves the whirl frequencies as they were)
    m = rotor()
    s = m.add_body("slider", 1.0, [1e-3] * 3)
    m.add_joint(ms.joints.Prismatic("rail", m.ground, s, axis=(1, 0, 0)))
    m.add_constraint(ms.constraints.Prescribed("hold", "rail", ms.functions.Constant(0.0)))
    lin = ms.linear.linearize(m)
    assert lin.method == "exact+fd-constraints"
    w0 = np.sqrt(KT / ID)
    # (minimal coordinates of a constrained model are a null-space basis y0, y1, ...: no whirl pair here)
    c = lin.campbell([0.5 * w0, 2 * w0], joint="spin")
    for k, sp in enumerate([0.5 * w0, 2 * w0]):
        ff, fb = whirl_frequencies(sp)
        np.testing.assert_allclose(np.sort(c.frequencies[k]), [fb, ff], rtol=1e-6)
