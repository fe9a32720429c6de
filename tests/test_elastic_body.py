"""Elastic bodies in the floating frame of reference (issue 16): the engine's mass matrix and
forces of an elastic body against a reference that never uses the Ritz invariants — the kinetic
energy summed over the body's mass points, Lagrange's equations by differences — and energy
conservation in a simulation.

The body is a lumped beam: mass points along x, shape functions polynomials in x (bending in y
and z, stretching along x), invariants summed over the points (the engine's input)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import linalg as sp_linalg

import mechsys as ms

G = np.array([0.0, -9.81, 0.3])
K = np.diag([50.0, 80.0, 3000.0, 60.0])
MODES = ("y2", "y3", "x1", "z2")


def lumped_beam(length=1.0, mass=2.0, n=120, modes=MODES):
    x = (np.arange(n) + 0.5) / n * length
    r0 = np.column_stack([x, np.zeros(n), np.zeros(n)])
    phi = []
    for md in modes:
        f = np.zeros((n, 3))
        f[:, "xyz".index(md[0])] = (x / length) ** int(md[1])
        phi.append(f)
    return r0, np.full(n, mass / n), np.stack(phi, 2)


def invariants(r0, mp, phi, k, d=None):
    """Mass, centre of mass, inertia about it and the engine's elastic table, summed over points."""
    ne = phi.shape[2]
    m = mp.sum()
    com = (mp[:, None] * r0).sum(0) / m
    rho = r0 - com
    i_c = sum(mi * (p @ p * np.eye(3) - np.outer(p, p)) for mi, p in zip(mp, rho))
    el = {
        "modes": ne,
        "s_t": [(mp[:, None] * phi[:, :, k]).sum(0).tolist() for k in range(ne)],
        "p1": [np.einsum("p,pa,pb->ab", mp, r0, phi[:, :, k]).reshape(-1).tolist() for k in range(ne)],
        "p2": [np.einsum("p,pa,pb->ab", mp, phi[:, :, k], phi[:, :, l]).reshape(-1).tolist()
               for k in range(ne) for l in range(ne)],
        "stiffness": np.asarray(k).tolist(),
    }
    if d is not None:
        el["damping"] = np.asarray(d).tolist()
    return m, com, i_c, el


R0, MP, PHI = lumped_beam()


def flexible_arm(arm_mass=1e-9, damping=None):
    """A light arm on a vertical hinge carrying the elastic rod on a skew hinge: 3-D motion."""
    m_, com, i_c, el = invariants(R0, MP, PHI, K, damping)
    m = ms.Model("flex3d", gravity=tuple(G))
    a = m.add_body("arm", arm_mass, ms.inertia.box(arm_mass, (0.4, 0.1, 0.1)), com=(0.2, 0, 0))
    b = m.add_body("rod", m_, i_c, com=tuple(com), elastic=el)
    m.add_joint(ms.joints.Revolute("j1", m.ground, a, axis=(0, 0, 1)))
    m.add_joint(ms.joints.Revolute("j2", a, b, axis=(0.3, 1.0, 0.2), parent_frame=ms.Frame(position=(0.4, 0.05, 0.0))))
    return m


def rod_points(m, q):
    """World positions of the rod's mass points, x = r + A (r0 + Φ q_e)."""
    st = ms.kinematics.body_states(m, q)
    a, r = np.asarray(st["rotation"])[-1], np.asarray(st["position"])[-1]
    return r + (R0 + PHI @ q[2:]) @ a.T


def kinetic(m, q, u, eps=1e-6):
    # the points' velocities by a central difference along q + u t (q̇ = u: hinges and elastic coordinates)
    v = (rod_points(m, q + eps * u) - rod_points(m, q - eps * u)) / (2 * eps)
    return 0.5 * np.sum(MP[:, None] * v * v)


def mass_matrix_ref(m, q):
    n = len(q)
    e = np.eye(n)
    t = [kinetic(m, q, e[i]) for i in range(n)]
    return np.array([[kinetic(m, q, e[i] + e[j]) - t[i] - t[j] for j in range(n)] for i in range(n)])


def potential_ref(m, q):
    return -np.sum(MP * (rod_points(m, q) @ G)) + 0.5 * q[2:] @ K @ q[2:]


@pytest.fixture(scope="module")
def state():
    rng = np.random.default_rng(3)
    q = rng.normal(size=6) * np.array([1, 1, 0.05, 0.05, 0.02, 0.05])
    return q, rng.normal(size=6)


def test_mass_matrix_is_the_hessian_of_the_summed_kinetic_energy(state):
    q, _ = state
    m = flexible_arm()
    m_engine = np.asarray(ms.dynamics.mass_matrix(m, q))
    m_ref = mass_matrix_ref(m, q)
    np.testing.assert_allclose(m_engine, m_ref, atol=1e-8 * np.abs(m_ref).max())
    # the couplings are there: the elastic coordinates pull on both hinges
    assert np.abs(m_ref[:2, 2:]).max() > 0.05


def test_forces_are_lagranges_equations_of_the_summed_energies(state):
    """h = -(Ṁ u - ∂T/∂q + ∂V/∂q): Coriolis, centrifugal, gravity and stiffness of the elastic
    coordinates at a deformed, moving state."""
    q, u = state
    m = flexible_arm()
    eps, n = 1e-5, 6
    e = np.eye(n)
    mdot = sum((mass_matrix_ref(m, q + eps * e[j]) - mass_matrix_ref(m, q - eps * e[j])) / (2 * eps) * u[j] for j in range(n))
    dtdq = np.array([(u @ mass_matrix_ref(m, q + eps * e[j]) @ u - u @ mass_matrix_ref(m, q - eps * e[j]) @ u) / (4 * eps)
                     for j in range(n)])
    dvdq = np.array([(potential_ref(m, q + eps * e[j]) - potential_ref(m, q - eps * e[j])) / (2 * eps) for j in range(n)])
    h_ref = -(mdot @ u - dtdq + dvdq)
    h = np.asarray(ms.dynamics.nonlinear_effects(m, q, u))
    np.testing.assert_allclose(h, h_ref, atol=1e-6 * np.abs(h_ref).max())


def test_a_flexible_pendulum_keeps_its_energy_and_damping_takes_what_it_dissipates():
    m = flexible_arm(arm_mass=0.5)
    res = ms.simulate(m, t_end=2.0, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01,
                      q0={"j2": 0.8}, u0={"j1": 1.5})
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * np.abs(res["energy/kinetic"]).max()
    assert res["body/rod/strain_energy"].max() > 1e-4  # it does bend
    np.testing.assert_allclose(res["body/rod/strain_energy"],
                               0.5 * np.einsum("ti,ij,tj->t", res["body/rod/elastic_q"], K, res["body/rod/elastic_q"]),
                               rtol=1e-12)
    # material damping: the balance T + V + E_dissipated stays, and energy is taken
    d = 0.02 * K
    md = flexible_arm(arm_mass=0.5, damping=d)
    rd = ms.simulate(md, t_end=2.0, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01,
                     q0={"j2": 0.8}, u0={"j1": 1.5})
    bal = rd["energy/total"] + rd["energy/dissipated"]
    assert rd["energy/dissipated"][-1] > 1e-4
    assert np.ptp(bal) < 1e-7 * np.abs(rd["energy/kinetic"]).max()
    assert res.columns("q") == ["j1.angle", "j2.angle", "rod.e0", "rod.e1", "rod.e2", "rod.e3"]


def test_bad_elastic_data_names_the_body_and_the_item():
    m_, com, i_c, el = invariants(R0, MP, PHI, K)

    def build(**change):
        e = dict(el, **change)
        m = ms.Model("bad")
        b = m.add_body("rod", m_, i_c, com=tuple(com), elastic=e)
        m.add_joint(ms.joints.Revolute("j", m.ground, b))
        return m.build()

    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.stiffness: not symmetric"):
        build(stiffness=(K + np.triu(np.ones((4, 4)), 1)).tolist())
    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.stiffness: a mode without stiffness"):
        k = K.copy()
        k[3, 3] = 0.0
        build(stiffness=k.tolist())
    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.p2: expected 16"):
        build(p2=el["p2"][:-1])
    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.stiffness: expected 4 rows"):
        build(stiffness=K[:3].tolist())
    bad = [list(r) for r in el["p2"]]
    bad[1] = [2 * x for x in bad[1]]
    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.p2: the entries of modes \(0, 1\) and \(1, 0\)"):
        build(p2=bad)
    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.damping: must be positive semi-definite"):
        build(damping=(-K).tolist())
    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.q0: expected 4 numbers"):
        build(q0=[0.0])
    with pytest.raises(ms.ModelError, match=r"'rod'.elastic.modes: an elastic body needs at least one"):
        build(modes=0)


# ---- geometric stiffening: a spinning cantilever ---------------------------------------------
def spinning_beam(reduced, spin, stiffening=True, angle=None, hub_radius=0.0):
    """The beam clamped to a hub turning about z, ``hub_radius`` out from the axis: at a constant
    ``spin`` or along ``angle(t)``."""
    m = ms.Model("spinning-beam")
    hub = m.add_body("hub", 1.0, [0.01, 0.01, 0.01])
    b = m.add_elastic_body("beam", reduced, stiffening=stiffening)
    m.add_joint(ms.joints.Revolute("hub", m.ground, hub, axis=(0, 0, 1), u0=[spin]))
    m.add_joint(ms.joints.Fixed("root", hub, b, parent_frame=ms.Frame(position=(hub_radius, 0.0, 0.0))))
    m.add_constraint(ms.constraints.Prescribed("spin", "hub", angle if angle is not None else ms.functions.Ramp(spin)))
    return m


def test_a_spinning_cantilevers_flap_frequencies_rise_as_southwell_says():
    """Linearized about the steady spin, the flapwise bending frequencies of the engine's
    floating-frame beam (4 analytic modes) against the beam FE model's rotating eigenproblem
    (K + Ω² K_G) φ = ω² M φ (20 elements, a separate code path); without the geometric stiffness
    they would not rise at all."""
    import warnings

    from mechsys import elastic as el

    sec = el.BeamSection.rectangle(0.02, 0.005, E=70e9, nu=0.3, rho=2700.0)
    body = el.analytic_beam_body(sec, 1.0, "clamped-free", 4, plane="xz")
    for spin in (20.0, 50.0):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the spin is prescribed: the point is a steady motion
            f = np.sort(ms.linear.linearize(spinning_beam(body, spin)).modes().natural_frequency)[:3]
            f_plain = np.sort(ms.linear.linearize(spinning_beam(body, spin, False)).modes().natural_frequency)[:3]
        ref = el.rotating_cantilever_frequencies(sec, 1.0, spin, plane="flap", n_modes=3) / (2 * np.pi)
        np.testing.assert_allclose(f, ref, rtol=5e-4)
        np.testing.assert_allclose(f_plain, body.frequencies()[:3], rtol=1e-9)
        assert f[0] > 1.3 * f_plain[0]
    # off the axis the root is pulled outward too (the uniform part of the centrifugal field):
    # the frequencies rise further, as the FE model with the hub radius says (8 modes: the Ritz
    # error falls from 7e-4 with 4 modes to 4e-5)
    body8 = el.analytic_beam_body(sec, 1.0, "clamped-free", 8, plane="xz")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = np.sort(ms.linear.linearize(spinning_beam(body8, 50.0, hub_radius=0.5)).modes().natural_frequency)[:3]
    ref = el.rotating_cantilever_frequencies(sec, 1.0, 50.0, plane="flap", n_modes=3, hub_radius=0.5,
                                             n_elements=60) / (2 * np.pi)
    np.testing.assert_allclose(f, ref, rtol=1e-4)
    assert f[0] > 1.05 * np.sort(ms.linear.linearize(spinning_beam(body8, 50.0)).modes().natural_frequency)[0]


def test_spin_up_follows_the_reference_and_diverges_without_stiffening():
    """The spin-up manoeuvre of examples/spinning_beam.py (a 10 m beam, ρA = 1.2 kg/m,
    EI = 14000 N m², to 6 rad/s in 15 s along a smooth ramp, above the first bending frequency
    3.80 rad/s): the in-plane tip deflection of the engine's model against the example's
    reference, the rotating-frame FE equations M q̈ + (K + Ω²(K_G - M_v)) q = -α f of the beam
    model integrated by SciPy; the same model without geometric stiffness runs away (spin
    softening beats the bending stiffness)."""
    import runpy
    import warnings
    from pathlib import Path

    ex = runpy.run_path(str(Path(__file__).resolve().parents[1] / "examples" / "spinning_beam.py"), run_name="test")
    body = ex["BEAM"]
    np.testing.assert_allclose(body.frequencies()[0] * 2 * np.pi, 1.875104068711961**2 * np.sqrt(14000.0 / (1.2 * 10.0**4)),
                               rtol=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = ms.simulate(ex["model"], **dict(ex["simulation"], output_dt=0.1))
    d = res["body/beam/elastic_q"] @ ex["TIP"]
    ref = ex["reference"](res.t)
    assert np.abs(ref).max() > 0.5  # the beam lags by half a metre at the tip
    np.testing.assert_allclose(d, ref, atol=1e-3 * np.abs(ref).max())
    # without geometric stiffness the deflection runs away before the end of the spin-up
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            loose = ms.simulate(ex["build"](False), **dict(ex["simulation"], output_dt=0.1))
            grown = np.abs(loose["body/beam/elastic_q"] @ ex["TIP"]).max()
        except ms.SolverError as e:
            assert "'beam' have run away" in str(e)
            grown = np.inf
    assert grown > 20 * np.abs(ref).max()


def test_an_elastic_rod_in_a_slider_crank_sags_as_a_pinned_beam_under_its_own_weight():
    """The crank held level, the rod (pinned-pinned sine modes between its two joints) sags at
    midspan by 5 ρA g L⁴ / (384 E I) (the six-mode series is short of the closed form by the
    first left-out term, 7⁻⁵ of the first)."""
    import runpy
    from pathlib import Path

    ns = runpy.run_path(str(Path(__file__).resolve().parents[1] / "examples" / "flexible_slider_crank.py"), run_name="x")
    w, w_ref = ns["static_sag"]()
    np.testing.assert_allclose(w, w_ref, rtol=1e-4)
    assert w > 0


def test_an_elastic_overhung_rotor_whirls_as_the_analytic_disc_on_a_massless_shaft():
    """A disc (5 kg, J_p = m R²/2, J_d = m R²/4) at the end of a light cantilevered shaft spinning
    about its axis: the beam FE model with the disc as a rigid mass (its gyroscopic coupling and
    tilt stiffening in the invariants), reduced to 6 modes, linearized about the steady spin.
    Reference: the 4-DOF disc on a massless shaft, M ẍ + Ω G ẋ + K x = 0 with the cantilever's tip
    stiffness, in the inertial frame; the elastic coordinates turn with the shaft, so an
    axisymmetric rotor's forward whirl appears at |ω - Ω| and its backward whirl at ω + Ω."""
    import warnings

    from mechsys import elastic as el

    length, r_shaft, m_d, r_d, e_mod = 0.4, 0.01, 5.0, 0.1, 210e9
    jp, jd = 0.5 * m_d * r_d**2, 0.25 * m_d * r_d**2
    sec = el.BeamSection.circle(r_shaft, E=e_mod, nu=0.3, rho=0.785)  # a shaft of 1e-5 kg
    fe = el.add_rigid_mass(el.beam_model(sec, length, 8), -1, m_d, (jp, jd, jd))
    body = el.modal_reduction(fe, 6, fixed={0: "clamped"}, name="rotor")
    ei = e_mod * sec.Iz
    k_tip = ei / length**3 * np.array([[12, -6 * length], [-6 * length, 4 * length**2]])
    stiff = np.zeros((4, 4))
    stiff[:2, :2] = k_tip
    stiff[2:, 2:] = k_tip * np.array([[1, -1], [-1, 1]])  # (w, θ_y): θ_y = -w'
    mass = np.diag([m_d, jd, m_d, jd])
    torsion = np.sqrt(sec.G * sec.Ip / length / jp) / (2 * np.pi)
    for spin in (0.0, 200.0, 600.0):
        gyro = np.zeros((4, 4))
        gyro[1, 3], gyro[3, 1] = jp * spin, -jp * spin
        a = np.block([[np.zeros((4, 4)), np.eye(4)], [-np.linalg.solve(mass, stiff), -np.linalg.solve(mass, gyro)]])
        lam = np.linalg.eigvals(a)
        w = np.sort(lam.imag[lam.imag > 0])  # backward (lower) and forward of each pair
        f_rot = np.sort(np.abs(np.array([w[0] + spin, w[1] - spin, w[2] + spin, w[3] - spin]))) / (2 * np.pi)
        m = ms.Model("rotor")
        b = m.add_elastic_body("rotor", body)
        m.add_joint(ms.joints.Revolute("spin", m.ground, b, axis=(1, 0, 0), u0=[spin]))
        m.add_constraint(ms.constraints.Prescribed("drive", "spin", ms.functions.Ramp(spin)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f = np.sort(ms.linear.linearize(m).modes().natural_frequency)
        bending = f[np.abs(f - torsion) > 1e-3 * torsion][:4]
        np.testing.assert_allclose(bending, f_rot, rtol=2e-5)
        assert np.min(np.abs(f - torsion)) < 1e-4 * torsion  # the shaft's torsion with the disc


def test_mechsys_info_lists_the_elastic_bodies_with_their_frequencies():
    import runpy
    import subprocess
    import sys
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "spinning_beam.py"
    out = subprocess.run([sys.executable, "-m", "mechsys", "info", str(path)], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "elastic bodies (1):" in out.stdout
    line = next(ln for ln in out.stdout.splitlines() if ln.strip().startswith("beam ") and " .. " in ln)
    parts = line.split()
    k = parts.index("..")
    f_low, f_high = float(parts[k - 1]), float(parts[k + 1])
    f = runpy.run_path(str(path), run_name="x")["BEAM"].frequencies()
    np.testing.assert_allclose([f_low, f_high], [f[0], f[-1]], rtol=1e-3)


# ---- loads and constraints at nodes ----------------------------------------------------------
def planar_cantilever():
    """A steel strip (1 m, 20 x 10 mm) as beam elements in the x-y plane, clamped at its root; the
    tip node kept as Craig-Bampton coordinates, so static loads there come out exact."""
    from mechsys import elastic as el

    sec = el.BeamSection.rectangle(0.02, 0.01, E=210e9, nu=0.3, rho=7850.0)
    fe = el.beam_model(sec, 1.0, 10, planar=True)
    return sec, el.craig_bampton(fe, 4, interface=[-1], fixed={0: "clamped"}, name="beam")


def test_a_load_at_the_tip_node_bends_the_cantilever_by_p_l3_over_3_e_i():
    sec, body = planar_cantilever()
    m = ms.Model("cantilever", planar=True)
    b = m.add_elastic_body("beam", body)
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    m.add_force(ms.forces.BodyForce("load", b, force=(0, -50.0, 0), point=b.node(-1)))
    q = ms.analysis.static_equilibrium(m)["q"]
    np.testing.assert_allclose(body.modes[-1, 1, :] @ q, -50.0 / (3 * sec.E * sec.Iz), rtol=1e-9)
    # a point that is not a node moves with the reference frame: the same load there does nothing elastic
    m2 = ms.Model("cantilever2", planar=True)
    b2 = m2.add_elastic_body("beam", body)
    m2.add_joint(ms.joints.Fixed("clamp", m2.ground, b2))
    m2.add_force(ms.forces.BodyForce("load", b2, force=(0, -50.0, 0), point=(0.95, 0.0, 0.0)))
    np.testing.assert_allclose(ms.analysis.static_equilibrium(m2)["q"], 0.0, atol=1e-15)
    with pytest.raises(ms.ModelError, match="no node 99"):
        b.node(99)


def test_a_propped_cantilever_carries_three_eighths_of_its_weight_on_the_prop():
    """The tip node held on the ground by a point constraint (its rows carry the node's elastic
    columns): the prop's reaction is 3 w L / 8 under the weight w per length, the tip stays put,
    and a run keeps the constraint to round-off."""
    sec, body = planar_cantilever()
    g = 9.81
    m = ms.Model("propped", gravity=(0, -g, 0), planar=True)
    b = m.add_elastic_body("beam", body)
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    m.add_constraint(ms.constraints.Point("prop", b, m.ground, point1=b.node(-1), point2=(1.0, 0, 0)))
    eq = ms.analysis.static_equilibrium(m)
    np.testing.assert_allclose(eq["lambda"]["prop"][1], 3 * sec.rho * sec.A * g / 8, rtol=1e-9)
    assert abs(body.modes[-1, 1, :] @ eq["q"]) < 1e-15
    res = ms.simulate(m, t_end=0.05, integrator=ms.DOPRI5(rtol=1e-9, atol=1e-12), output_dt=1e-3)
    assert np.abs(res["constraint/prop/violation"]).max() < 1e-12
    assert np.abs(res["body/beam/elastic_q"]).max() > 1e-6  # it does vibrate under its weight
    # started at rest in the equilibrium: the clamp carries the other 5/8 of the weight (its
    # reaction from the Newton-Euler pass with the elastic body's terms)
    rest = ms.simulate(m, t_end=1e-3, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-14), output_dt=1e-3, q0=eq["q"])
    np.testing.assert_allclose(np.abs(rest["joint/clamp/reaction_force"][0, 1]), 5 * sec.rho * sec.A * g / 8, rtol=1e-6)
    assert np.abs(rest["body/beam/elastic_u"]).max() < 1e-9


def test_a_spring_at_the_tip_node_keeps_the_energy():
    """A spring from the tip node to the ground, the beam released bent: the spring works on the
    elastic coordinates, and kinetic + strain + spring energy stays constant."""
    sec, body = planar_cantilever()
    m = ms.Model("sprung", planar=True)
    b = m.add_elastic_body("beam", body, q0=np.r_[np.zeros(4), [0.0, 5e-3, 0.0]][: body.n_coordinates])
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    m.add_force(ms.forces.SpringDamper("tip-spring", b, m.ground, k=2000.0, point1=b.node(-1), point2=(1.0, -0.2, 0.0),
                                       l0=0.2))
    res = ms.simulate(m, t_end=0.2, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=1e-3)
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * e[0]
    assert np.ptp(res["force/tip-spring/force"]) > 1.0  # the spring does work


@pytest.mark.parametrize("integrator, tol", [(ms.RK4(dt=1e-4), 1e-9), (ms.Radau5(rtol=1e-8, atol=1e-10), 1e-8),
                                             (ms.MoreauJean(dt=1e-4), 2e-5), (ms.EventDriven(), 1e-9)],
                         ids=["rk4", "radau5", "moreau_jean", "event_driven"])
def test_every_integrator_runs_the_flexible_arm_to_the_same_state(integrator, tol):
    m = flexible_arm(arm_mass=0.5)
    kw = dict(t_end=0.5, output_dt=0.01, q0={"j2": 0.8}, u0={"j1": 1.5})
    ref = ms.simulate(m, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-12), **kw)
    res = ms.simulate(m, integrator=integrator, **kw)
    np.testing.assert_allclose(res["q"][-1], ref["q"][-1], atol=tol)
    assert np.abs(res["body/rod/elastic_q"]).max() > 1e-3


def test_node_deflections_are_signals_and_a_toml_file_takes_a_reduced_body_file(tmp_path):
    """A cantilever under its own weight from a model file naming a reduced-body file: the run
    from the command line records each node's deflection (m, body frame); the tip settles at the
    static sag w L⁴ / (8 E I) (3 analytic modes, damped)."""
    import subprocess
    import sys

    from mechsys import elastic as el

    sec = el.BeamSection.rectangle(0.02, 0.01, E=210e9, nu=0.3, rho=7850.0)
    el.analytic_beam_body(sec, 1.0, "clamped-free", 3, plane="xy", name="blade").save(tmp_path / "blade.npz")
    (tmp_path / "m.toml").write_text('''
name = "blade"
gravity = [0, -9.81, 0]
[[bodies]]
name = "blade"
elastic = { file = "blade.npz", modal = 0.3 }
[[joints]]
name = "root"
type = "fixed"
parent = "ground"
child = "blade"
[simulation]
t_end = 2.0
output_dt = 0.01
integrator = { type = "dopri5", rtol = 1e-10, atol = 1e-13 }
''')
    out = tmp_path / "r.h5"
    r = subprocess.run([sys.executable, "-m", "mechsys", "run", str(tmp_path / "m.toml"), "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    res = ms.load(out)
    d = res["body/blade/node_deflection"]
    assert res.unit("body/blade/node_deflection") == "m" and d.shape == (len(res.t), 11, 3)
    w = sec.rho * sec.A * 9.81
    np.testing.assert_allclose(d[-1, -1, 1], -w / (8 * sec.E * sec.Iz), rtol=2e-3)
    np.testing.assert_allclose(d[:, 0, :], 0.0, atol=1e-15)  # the clamped root does not move
    (tmp_path / "bad.toml").write_text((tmp_path / "m.toml").read_text().replace("blade.npz", "nothere.npz"))
    r = subprocess.run([sys.executable, "-m", "mechsys", "run", str(tmp_path / "bad.toml")], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and "bodies[0] 'blade'.elastic.file" in r.stderr and "nothere.npz" in r.stderr


def test_a_moment_at_the_tip_node_turns_it_by_m_l_over_e_i():
    """A torque at the tip node loads the elastic coordinates through the node's small rotation
    (eq. 2.134): the tip turns by M L / (E I) and deflects by M L² / (2 E I)."""
    sec, body = planar_cantilever()
    m = ms.Model("moment", planar=True)
    b = m.add_elastic_body("beam", body)
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    m.add_force(ms.forces.BodyForce("moment", b, torque=(0, 0, 20.0), point=b.node(-1)))
    q = ms.analysis.static_equilibrium(m)["q"]
    ei = sec.E * sec.Iz
    np.testing.assert_allclose(body.modes[-1, 5, :] @ q, 20.0 / ei, rtol=1e-9)
    np.testing.assert_allclose(body.modes[-1, 1, :] @ q, 20.0 / (2 * ei), rtol=1e-9)
    # the node signals at that state: the tip's rotation about z and its deflection along y
    res = ms.simulate(m, t_end=1e-4, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-14), output_dt=1e-4, q0=q)
    assert res.unit("body/beam/node_rotation") == "rad"
    np.testing.assert_allclose(res["body/beam/node_rotation"][0, -1], [0, 0, 20.0 / ei], atol=1e-12)
    np.testing.assert_allclose(res["body/beam/node_deflection"][0, -1], [0, 20.0 / (2 * ei), 0], atol=1e-12)


def test_mode_shapes_are_drawn_at_their_frequencies(tmp_path):
    from mechsys import elastic as el

    sec = el.BeamSection.rectangle(0.02, 0.01, E=210e9, nu=0.3, rho=7850.0)
    body = el.analytic_beam_body(sec, 1.0, "clamped-free", 3, plane="xy", name="blade")
    fig = body.plot_modes((0, 1), out=tmp_path / "modes.png")
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    f = body.frequencies()
    assert labels[1] == f"mode 1: {f[0]:.4g} Hz" and labels[2] == f"mode 2: {f[1]:.4g} Hz"
    line = fig.axes[0].get_lines()[1]
    assert abs(np.abs(line.get_ydata()).max() - 0.1) < 1e-12  # scaled to a tenth of the 1 m blade
    assert (tmp_path / "modes.png").stat().st_size > 10_000
    with pytest.raises(ms.ModelError, match="no mode 7"):
        body.plot_modes(7)


def test_an_elastic_tip_resting_on_a_stop_carries_three_eighths_of_the_weight():
    """A point contour at the tip node touches a rigid stop level with the clamp: once the beam
    has settled on it the contact force is the propped cantilever's 3 w L / 8, in both contact
    schemes (event-driven to the transition tolerance, Moreau-Jean to its step)."""
    sec, body = planar_cantilever()
    g = 9.81
    m = ms.Model("stop", gravity=(0, -g, 0), planar=True)
    b = m.add_elastic_body("beam", body, modal=0.2)
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    m.add_contact(ms.Contact("stop", b.contour(ms.contours.Point(b.node(-1))),
                             m.ground.contour(ms.contours.Line(point=(1.0, 0, 0), normal=(0, 1, 0)))))
    w = sec.rho * sec.A * g
    ed = ms.simulate(m, t_end=1.5, integrator=ms.EventDriven(), output_dt=1e-3)
    np.testing.assert_allclose(ed["contact/stop/lambda_n"][-1], 3 * w / 8, rtol=1e-8)
    assert abs(ed["contact/stop/g_n"][-1]) < 1e-12
    assert any(e["event"] == "close" or e["event"] == "impact" for e in ed.events)
    mj = ms.simulate(m, t_end=1.5, integrator=ms.MoreauJean(dt=1e-4), output_dt=1e-3)
    np.testing.assert_allclose(mj["contact/stop/lambda_n"][-1], 3 * w / 8, rtol=1e-2)


# ---- loop joints at nodes ---------------------------------------------------------------------
def bracket_at_the_tip(joint, P, e, L=1.0):
    """The planar cantilever with a rigid bracket (a planar joint of its own) joined to its tip
    node by ``joint`` (a loop-joint class), loaded by P downward a distance ``e`` beyond the tip."""
    sec, body = planar_cantilever()
    m = ms.Model("bracket", planar=True, gravity=(0, 0, 0))
    b = m.add_elastic_body("beam", body)
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    arm = m.add_body("bracket", 0.5, [1e-3, 1e-3, 1e-3], com=(0.15, 0, 0))
    m.add_joint(ms.joints.Planar("float", m.ground, arm, q0=[L, 0.0, 0.0]))
    m.add_constraint(joint("joint", b, arm, frame1=b.node(-1)))
    m.add_force(ms.forces.BodyForce("load", arm, force=(0, -P, 0), point=(e, 0, 0)))
    return sec, body, m, arm


def test_a_bracket_welded_to_the_tip_node_bends_and_turns_it_as_force_and_moment_would():
    """A rigid bracket welded (LoopFixed) to the cantilever's tip node, loaded at its far end a
    distance e beyond the tip: the weld passes the force P and the moment P e into the beam, whose
    tip deflects by P L³/(3EI) + P e L²/(2EI) and turns by P L²/(2EI) + P e L/(EI) (the weld's
    rows carry the node's deflection and rotation columns). P is small enough (tip rotation 2e-4)
    that the bracket's turn, which shortens the lever by θ²/2, stays below the tolerance."""
    P, e, L = 0.4, 0.3, 1.0
    sec, body, m, _ = bracket_at_the_tip(ms.constraints.LoopFixed, P, e, L)
    eq = ms.analysis.static_equilibrium(m)
    qe = eq["q"][-body.n_coordinates:]
    ei = sec.E * sec.Iz
    np.testing.assert_allclose(body.modes[-1, 1, :] @ qe, -(P * L**3 / (3 * ei) + P * e * L**2 / (2 * ei)), rtol=1e-7)
    np.testing.assert_allclose(body.modes[-1, 5, :] @ qe, -(P * L**2 / (2 * ei) + P * e * L / ei), rtol=1e-7)
    # the bracket went with the node: its angle is the tip's rotation, its origin the tip's place
    q_float = eq["q"][:3]
    np.testing.assert_allclose(q_float[2], body.modes[-1, 5, :] @ qe, rtol=1e-8)
    np.testing.assert_allclose(q_float[1], body.modes[-1, 1, :] @ qe, rtol=1e-8)


def test_a_hinge_at_the_tip_node_passes_the_force_but_no_moment():
    """The same bracket on a hinge (LoopRevolute) at the tip node, held level by a vertical prop at its
    far end and loaded at its middle: the tip carries P/2 and no moment, P L³/(6EI) of deflection."""
    P, e, L = 0.4, 0.3, 1.0
    sec, body, m, arm = bracket_at_the_tip(ms.constraints.LoopRevolute, P, e / 2, L)
    m.add_constraint(ms.constraints.PointOnLine("prop", arm, m.ground, point1=(e, 0, 0), point2=(L + e, 0, 0),
                                                direction=(1, 0, 0)))
    qe = ms.analysis.static_equilibrium(m)["q"][-body.n_coordinates:]
    ei = sec.E * sec.Iz
    np.testing.assert_allclose(body.modes[-1, 1, :] @ qe, -(P / 2) * L**3 / (3 * ei), rtol=1e-7)


def test_a_tree_joint_at_a_deflecting_node_is_refused_with_the_loop_joint_named():
    sec, body = planar_cantilever()
    m = ms.Model("tree_at_node", planar=True)
    b = m.add_elastic_body("beam", body)
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    tip = m.add_body("tip", 1.0, [1e-3] * 3)
    m.add_joint(ms.joints.Revolute("hinge", b, tip, axis=(0, 0, 1), parent_frame=ms.Frame(position=b.node(-1))))
    with pytest.raises(ms.ModelError, match=r"joint 'hinge'.*node 'n10' of elastic body 'beam'.*loop joint"):
        m.build()


def test_a_flexible_pendulum_with_a_bob_welded_off_axis_keeps_its_energy():
    """A 3-D flexible pendulum: a cantilevered strip on a hinge, a rigid bob welded to its tip node
    with its centre of mass off the beam's axis, gravity slanted: the strip bends both ways and
    twists (the twist's mass is the sections' rotary inertia).
    The bob floats on a free joint and follows the node only through the weld's rows, so any slip
    between those rows' Jacobian (the node's J_l ψ columns) and their velocity-product terms would
    pump energy in or out: kinetic + potential + strain energy stays constant, the weld closed."""
    from mechsys import elastic as el

    sec = el.BeamSection.rectangle(0.02, 0.012, E=70e9, nu=0.33, rho=2700.0)
    body = el.craig_bampton(el.beam_model(sec, 1.0, 8), 4, interface=[-1], fixed={0: "clamped"}, name="strip")
    m = ms.Model("welded_bob", gravity=(0, -9.81, 3.0))
    # without the geometric stiffness: its stress state follows the swing and is no potential
    b = m.add_elastic_body("strip", body, stiffening=False)
    m.add_joint(ms.joints.Revolute("hinge", m.ground, b, axis=(0, 0, 1)))
    bob = m.add_body("bob", 0.8, [2e-3, 3e-3, 4e-3], com=(0.05, 0.02, 0.08))
    m.add_joint(ms.joints.Free("float", m.ground, bob, q0=[1.0, 0, 0, 1, 0, 0, 0]))
    m.add_constraint(ms.constraints.LoopFixed("weld", b, bob, frame1=b.node(-1)))
    res = ms.simulate(m, t_end=0.15, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=1e-3)
    e = res["energy/total"]
    swing = np.ptp(res["energy/kinetic"])
    assert swing > 1.0  # it falls
    assert np.ptp(e) < 1e-7 * swing, np.ptp(e) / swing
    assert np.abs(res["constraint/weld/violation"]).max() < 1e-9
    rot = res["body/strip/node_rotation"][:, -1]
    assert (np.abs(rot).max(axis=0) > 1e-4).all()  # twisted and bent both ways


# ---- rotary inertia: a shaft's torsion --------------------------------------------------------
def torsion_shaft(n_el=12, n_modes=None):
    """A steel shaft (1 m, r = 20 mm) along x, only its twist free (every other DOF held), the root
    clamped: its modes move no mass point (they lie on the axis), only the sections' polar
    inertia ρ Ip, which the body hands the engine as its rotary mass."""
    from mechsys import elastic as el

    sec = el.BeamSection.circle(0.02, E=210e9, nu=0.3, rho=7850.0)
    fe = el.beam_model(sec, 1.0, n_el)
    fixed = {0: "clamped", **{i: ["ux", "uy", "uz", "ry", "rz"] for i in range(1, n_el + 1)}}
    return sec, fe, el.modal_reduction(fe, n_modes or n_el, fixed=fixed, name="shaft")


def test_a_shaft_twists_at_its_torsional_frequencies_held_and_free_to_turn():
    """Clamped at the root its twist rings at the FE model's own frequencies, close to the closed
    form (2n - 1) π c / (2L), c = √(G J / ρ Ip). On a bearing about its axis (the reference
    frame free to turn) the coupling ∫ J ψ_k with the reference rotation makes it a free-free
    shaft: the linearized frequencies are the full FE model's free-free twist, n π c / L."""
    sec, fe, body = torsion_shaft()
    c = np.sqrt(sec.G * sec.J / (sec.rho * sec.Ip))
    m = ms.Model("held_shaft", gravity=(0, 0, 0))
    b = m.add_elastic_body("shaft", body)
    m.add_joint(ms.joints.Fixed("root", m.ground, b))
    f_held = np.sort(ms.linear.linearize(m).modes().natural_frequency)[:3]
    np.testing.assert_allclose(f_held, body.frequencies()[:3], rtol=1e-9)
    np.testing.assert_allclose(f_held[0], np.pi * c / 2 / (2 * np.pi), rtol=1e-3)  # 12 linear elements
    m2 = ms.Model("free_shaft", gravity=(0, 0, 0))
    b2 = m2.add_elastic_body("shaft", body)
    m2.add_joint(ms.joints.Revolute("bearing", m2.ground, b2, axis=(1, 0, 0)))
    f = np.sort(ms.linear.linearize(m2).modes().natural_frequency)
    f = f[f > 1.0][:3]
    rx = np.arange(3, fe.M.shape[0], 6)  # the full model's twist DOFs, free-free
    w2 = sp_linalg.eigh(fe.K[np.ix_(rx, rx)], fe.M[np.ix_(rx, rx)], eigvals_only=True)
    np.testing.assert_allclose(f, np.sqrt(w2[1:4]) / (2 * np.pi), rtol=1e-8)
    np.testing.assert_allclose(f[0], c / 2, rtol=3e-3)


def test_a_twisted_shaft_released_on_its_bearing_keeps_energy_and_angular_momentum():
    """Released twisted, the shaft's twist swings the free reference frame back and forth: the
    axial angular momentum (ρ Ip L ω + ∫ J ψ q̇) stays zero and the energy constant."""
    sec, fe, body = torsion_shaft(n_el=8, n_modes=3)
    m = ms.Model("released_shaft", gravity=(0, 0, 0))
    b = m.add_elastic_body("shaft", body, q0=[2e-3, 0.0, 0.0])
    m.add_joint(ms.joints.Revolute("bearing", m.ground, b, axis=(1, 0, 0)))
    res = ms.simulate(m, t_end=5e-3, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-14), output_dt=1e-5)
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * e.max()
    assert np.abs(res["joint/bearing/u"]).max() > 1.0  # the frame does turn
    assert np.abs(res["momentum/angular"][:, 0]).max() < 1e-10 * sec.rho * sec.Ip * np.abs(res["joint/bearing/u"]).max()


def free_flap_frequencies(fe, axial, n=2):
    """The lowest flap (z) bending frequencies (Hz) of a beam model along x under the axial force
    ``axial(s)``: its flap DOFs (uz, ry), the two rigid flap motions projected out M-orthogonally
    (the motions of a free-free basis), K + K_G(axial) against M."""
    from mechsys import elastic as el

    dofs = [6 * i + d for i in range(fe.n_nodes) for d in (2, 4)]
    rigid = np.zeros((len(dofs), 2))
    rigid[0::2, 0] = 1.0  # uz
    rigid[0::2, 1], rigid[1::2, 1] = -fe.nodes[:, 0], 1.0  # a turn about y: uz = -x θ, ry = θ
    Mf, Kf = fe.M[np.ix_(dofs, dofs)], fe.K[np.ix_(dofs, dofs)]
    Gf = el.geometric_stiffness(fe, axial)[np.ix_(dofs, dofs)]
    N = sp_linalg.null_space(rigid.T @ Mf)
    return np.sqrt(sp_linalg.eigh(N.T @ (Kf + Gf) @ N, N.T @ Mf @ N, eigvals_only=True)[:n]) / (2 * np.pi)


def test_a_free_free_rod_spun_about_its_centre_stiffens_by_inertia_relief():
    """A free-free strip (12 free-free modes, no support: its geometric stiffness comes from the
    inertia-relieved fields) spun about z through its centre: the flap frequencies against the
    full FE model's rotating eigenproblem on the motions M-orthogonal to the rigid ones, with the
    closed-form centrifugal force N(x) = ρAΩ²(L²/4 - x²)/2 (a separate path: geometric_stiffness
    of that N, no field or relief)."""
    import warnings

    from mechsys import elastic as el

    sec = el.BeamSection.rectangle(0.02, 0.005, E=70e9, nu=0.3, rho=2700.0)
    L, spin = 1.0, 80.0
    fe = el.beam_model(sec, L, 24, start=(-L / 2, 0, 0))
    body = el.modal_reduction(fe, 12, name="rod")
    assert body.geometric is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = np.sort(ms.linear.linearize(spinning_beam(body, spin)).modes().natural_frequency)[:2]
        f0 = np.sort(ms.linear.linearize(spinning_beam(body, spin, False)).modes().natural_frequency)[:2]
    rA = sec.rho * sec.A
    ref = free_flap_frequencies(fe, lambda s: 0.5 * rA * spin**2 * (L**2 / 4 - (s - L / 2) ** 2))
    np.testing.assert_allclose(f, ref, rtol=1e-3)
    assert f[0] > 1.2 * f0[0]
    # a free body: the uniform fields (gravity) only accelerate it, they stress nothing
    assert np.abs(body.geometric[:3]).max() < 1e-9 * np.abs(body.geometric).max()


def test_a_free_free_basis_held_at_its_centre_off_the_axis_carries_the_hubs_pull():
    """The same free-free strip fixed to a hub at its centre 0.3 m off the spin axis, reduced with
    ``held`` at the centre node: the uniform part of the centrifugal field pulls the strip out and
    the hub holds it: the outer half is pulled harder, the inner half pushed toward the hub,
    N(x) = ρAΩ²[R(L/2 - x) + (L²/4 - x²)/2] outside, ρAΩ²[(L²/4 - x²)/2 - R(x + L/2)] inside;
    inertia relief (no ``held``) would miss the hub's pull."""
    import warnings

    from mechsys import elastic as el

    sec = el.BeamSection.rectangle(0.02, 0.005, E=70e9, nu=0.3, rho=2700.0)
    L, spin, R = 1.0, 80.0, 0.3
    fe = el.beam_model(sec, L, 24, start=(-L / 2, 0, 0))
    body = el.modal_reduction(fe, 12, held={12: "clamped"}, name="rod")
    relieved = el.modal_reduction(fe, 12, name="rod")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = np.sort(ms.linear.linearize(spinning_beam(body, spin, hub_radius=R)).modes().natural_frequency)[:2]
        f_rel = np.sort(ms.linear.linearize(spinning_beam(relieved, spin, hub_radius=R)).modes().natural_frequency)[:2]
    rA = sec.rho * sec.A

    def axial(s):
        x = s - L / 2
        if x >= 0:
            return rA * spin**2 * (R * (L / 2 - x) + 0.5 * (L**2 / 4 - x**2))
        return rA * spin**2 * (-R * (x + L / 2) + 0.5 * (L**2 / 4 - x**2))

    ref = free_flap_frequencies(fe, axial)
    np.testing.assert_allclose(f, ref, rtol=1e-3)
    assert abs(f_rel[1] - ref[1]) > 3e-3 * ref[1]  # relief alone is not this body's stress state
