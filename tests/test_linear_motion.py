"""Linearization about motions (steady motions, non-holonomic constraints) against results derived
outside mechsys: the benchmark bicycle's published matrices and eigenvalues (tests/bicycle_reference.py,
from the paper's closed-form expressions), the conical pendulum's closed form, and the self-check
against small-perturbation runs of the nonlinear model. Bad input: points off the constraint
manifold, cyclic or dependent coordinates named, steady-motion guesses that do not converge,
contacts and friction elements at their switching points."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))
sys.path.insert(0, str(ROOT / "tests"))

import bicycle  # noqa: E402
import bicycle_reference as bref  # noqa: E402

LEAN, STEER = "free[3]", "steer"


# ---- the benchmark bicycle (non-holonomic, moving) ----------------------------------------------


@pytest.mark.parametrize("v", [1.0, 3.0, 4.9, 5.0, 8.0, 10.0])
def test_bicycle_eigenvalues_match_the_benchmark_at_every_speed(v):
    lin = ms.linear.linearize(bicycle.build(v=v))
    assert lin.steady and lin.names == [LEAN, STEER]
    got = np.sort_complex(lin.modes().eigenvalues)
    want = np.sort_complex(bref.eigenvalues(v))
    want = want[want.imag >= -1e-12]
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-9)


def test_bicycle_second_order_form_is_the_benchmarks_matrices():
    ref = bref.matrices()
    for v in (2.0, 5.0):
        lin = ms.linear.linearize(bicycle.build(v=v), coordinates=[LEAN, STEER])
        np.testing.assert_allclose(lin.M, ref["M"], rtol=1e-9)
        np.testing.assert_allclose(lin.D + lin.G, v * ref["C1"], rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(lin.K + lin.N, 9.81 * ref["K0"] + v * v * ref["K2"], rtol=1e-8, atol=1e-8)
        # the wheel angles, the position on the plane and the heading are cyclic and left out
        assert set(lin.cyclic) == {"free[0]", "free[1]", "free[5]", "rear_hub", "front_hub"}
        assert lin.A.shape == (5, 5) and lin.states == [LEAN, STEER, "free[3]'", "rear_hub'", "steer'"]


def test_bicycle_stable_speed_range_is_the_benchmarks():
    sw = ms.linear.sweep(lambda v: bicycle.build(v=v), np.linspace(4.0, 6.5, 26), parameter="v")
    (lo, hi), = sw.stable_ranges()
    assert lo == pytest.approx(bref.weave_speed(), abs=2e-3)
    assert hi == pytest.approx(bref.capsize_speed(), abs=2e-3)


def test_bicycle_self_check_agrees_with_the_eigenvalues():
    lin = ms.linear.linearize(bicycle.build(v=5.0))
    c = ms.linear.check(lin)
    assert c.eigenvalues.size == 3 and c.worst < 1e-4
    np.testing.assert_allclose(np.sort_complex(c.fitted), np.sort_complex(lin.modes().eigenvalues), rtol=1e-4)


def test_bicycle_at_rest_keeps_the_equilibrium_linearization():
    lin = ms.linear.linearize(bicycle.build(v=0.0))
    lam = lin.modes().eigenvalues
    nonzero = np.sort(lam[np.abs(lam) > 1e-4].real)
    np.testing.assert_allclose(nonzero, np.sort(bref.eigenvalues(0.0).real), rtol=1e-8)


def test_steady_motion_from_a_named_speed():
    m = bicycle.build(v=5.0)
    st = ms.linear.steady_motion(m, fixed={"rear_hub'": -6.0 / 0.3})
    assert st.residual < 1e-10
    assert st.u[0] == pytest.approx(6.0, rel=1e-12)  # the rear frame's forward speed follows
    lin = ms.linear.linearize(m, at=st)
    np.testing.assert_allclose(np.sort_complex(lin.modes().eigenvalues),
                               np.sort_complex(bref.eigenvalues(6.0)[bref.eigenvalues(6.0).imag >= -1e-12]), rtol=1e-7)


def test_the_old_linearization_of_a_moving_nonholonomic_state_is_gone():
    # the finding: the velocity-coordinate form gave lean-mode eigenvalues off by ~1.6 1/s
    # at 1 m/s; the first-order form must agree with the benchmark wherever the old one did not
    lin = ms.linear.linearize(bicycle.build(v=1.0))
    assert np.abs(np.sort_complex(lin.modes().eigenvalues) -
                  np.sort_complex(bref.eigenvalues(1.0)[bref.eigenvalues(1.0).imag >= -1e-12])).max() < 1e-6


# ---- quaternion joints about a motion ------------------------------------------------------------


def conical(free: bool, g=9.81, l=0.8, alpha=0.5, inertia=1e-6):
    """A bob (centre of mass l below the pivot, tiny inertia) turning steadily about the vertical
    at cone angle alpha: Omega^2 = g / (l cos alpha); small nutations at
    w^2 = Omega^2 (1 + 3 cos^2 alpha) (the spherical pendulum's closed form)."""
    m = ms.Model("cone", gravity=(0.0, 0.0, -g))
    b = m.add_body("bob", 1.0, [inertia] * 3, com=(0.0, 0.0, -l))
    rot = ms.kinematics.rot_x(alpha)
    omega = np.sqrt(g / (l * np.cos(alpha)))
    w = rot.T @ np.array([0.0, 0.0, omega])
    quat = ms.kinematics.matrix_to_quat(rot)
    if free:
        m.add_joint(ms.joints.Free("j", m.ground, b, q0=[0, 0, 0, *quat], u0=[0, 0, 0, *w]))
        m.add_constraint(ms.constraints.Point("pin", b, m.ground))
    else:
        m.add_joint(ms.joints.Spherical("j", m.ground, b, q0=list(quat), u0=list(w)))
    return m, omega * np.sqrt(1 + 3 * np.cos(alpha) ** 2)


@pytest.mark.parametrize("free", [False, True])
@pytest.mark.parametrize("method", ["exact", "fd"])
def test_conical_pendulum_nutation_on_quaternion_joints(free, method):
    # was 4.747 and 1.813 rad/s (the chart's rotation -omega x delta left out); closed form 6.083
    m, w = conical(free)
    lin = ms.linear.linearize(m, method=method)
    assert lin.steady
    lam = lin.modes().eigenvalues
    nut = lam[np.argmax(np.abs(lam))]
    assert abs(nut.real) < 1e-6 * w
    assert nut.imag == pytest.approx(w, rel=1e-5)  # the bob's 1e-6 inertia


def test_conical_pendulum_self_check():
    m, w = conical(False)
    c = ms.linear.check(ms.linear.linearize(m), modes=[-1])
    assert c.worst < 1e-4 and c.fitted[0].imag == pytest.approx(w, rel=1e-4)


def test_holonomic_rotor_campbell_is_unchanged_by_the_motion_path():
    # revolute joints only: the first-order form and the old second-order one coincide at speed
    sys.path.insert(0, str(ROOT / "examples"))
    import rotor_campbell as rc

    lin = ms.linear.linearize(rc.build(spin=300.0), operating_point=True)
    fw, bw = rc.whirl_frequencies(300.0)
    f = np.sort(lin.modes().damped_frequency)
    assert f[-1] == pytest.approx(fw, rel=1e-3) and f[-2] == pytest.approx(bw, rel=1e-3)
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(lin.A)[np.abs(np.linalg.eigvals(lin.A)) > 1e-6]),
                               np.sort_complex(np.linalg.eigvals(lin.state_matrix())[
                                   np.abs(np.linalg.eigvals(lin.state_matrix())) > 1e-6]), rtol=1e-9)


def test_equilibrium_first_order_form_has_the_second_order_eigenvalues():
    m = ms.Model("pendulum2", gravity=(0.0, 0.0, -9.81))
    a = m.add_body("a", 1.0, [0.01] * 3, com=(0, 0, -0.5))
    b = m.add_body("b", 2.0, [0.02] * 3, com=(0, 0, -0.4))
    m.add_joint(ms.joints.Revolute("j1", m.ground, a, axis=(1, 0, 0)))
    m.add_joint(ms.joints.Revolute("j2", a, b, axis=(1, 0, 0), parent_frame=ms.joints.Frame(position=(0, 0, -1.0))))
    lin = ms.linear.linearize(m)
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(lin.A)), np.sort_complex(np.linalg.eigvals(lin.state_matrix())),
                               rtol=1e-10)
    assert lin.A.shape == (4, 4) and np.all(np.abs(np.linalg.eigvals(lin.A).real) < 1e-9)
    assert lin.cyclic == [] and lin.steady


# ---- bad input -----------------------------------------------------------------------------------


def test_a_point_off_the_constraint_manifold_names_the_constraint():
    m = bicycle.build(v=5.0)
    q = m.q0().copy()
    q[2] += 1e-3  # lift the rear frame: the rear wheel leaves the ground
    with pytest.raises(ms.ModelError, match="rear_contact"):
        ms.linear.linearize(m, q=q)
    u = m.state_vector(None, "u").copy()
    u[1] += 0.1  # side slip
    with pytest.raises(ms.ModelError, match="contact.*velocity residual"):
        ms.linear.linearize(m, u=u)


def test_cyclic_or_dependent_coordinates_cannot_be_named():
    m = bicycle.build(v=5.0)
    with pytest.raises(ms.SettingsError, match="'free\\[0\\]' is cyclic"):
        ms.linear.linearize(m, coordinates=["free[0]", STEER])
    with pytest.raises(ms.SettingsError, match="no joint coordinate named 'lean'"):
        ms.linear.linearize(m, coordinates=["lean"])
    lin = ms.linear.linearize(m)
    with pytest.raises(ms.SettingsError, match="'rear_hub' is cyclic"):
        lin.state_space(outputs=["rear_hub"])
    a, b, c = lin.state_space(inputs=[STEER], outputs=[LEAN, "steer'"])
    assert a.shape == (5, 5) and b.shape == (5, 1) and c.shape == (2, 5)


def test_a_steady_motion_guess_that_does_not_converge_is_an_error():
    m = bicycle.build(v=5.0, lean_rate=0.5)  # a lean rate that no steady motion keeps
    with pytest.raises(ms.SolverError, match="no steady motion.*acceleration of"):
        ms.linear.steady_motion(m, max_iter=3)


def test_a_moving_point_that_is_not_steady_warns():
    m = bicycle.build(v=5.0, lean=0.05)
    with pytest.warns(UserWarning, match="not an equilibrium or a steady motion"):
        lin = ms.linear.linearize(m)
    assert not lin.steady


def test_no_second_order_form_in_coordinates_that_do_not_close():
    # lean alone: the steer feeds back into it
    with pytest.raises(ms.SettingsError, match="feed back"):
        ms.linear.linearize(bicycle.build(v=5.0), coordinates=[LEAN])


def test_a_closed_contact_at_the_point_is_refused():
    m = ms.Model("ball")
    b = m.add_body("ball", 1.0, [4e-3] * 3)
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=0.1))
    m.add_contact(ms.contacts.Contact("floor", m.ground.contour(ms.contours.Plane()), b.contour(ms.contours.Sphere(radius=0.1))))
    with pytest.raises(ms.SettingsError, match="contact 'floor' is closed"):
        ms.linear.linearize(m, operating_point=True)
    lin = ms.linear.linearize(m, q=[0.5], operating_point=True)  # open: it exerts nothing
    assert lin.K[0, 0] == pytest.approx(0.0, abs=1e-12)


def test_a_jenkins_slider_at_its_slip_limit_is_refused():
    m = ms.Model("fit")
    b = m.add_body("shaft", mass=2.0, inertia=[1, 1, 1])
    m.add_joint(ms.joints.Prismatic("fit", m.ground, b, axis=(1, 0, 0)))
    m.add_force(ms.forces.Jenkins("press", "fit", k=1e4, slip=5.0))
    assert ms.linear.linearize(m).K[0, 0] == pytest.approx(1e4, rel=1e-8)  # inside stick: the spring
    with pytest.raises(ms.SettingsError, match="'press' \\(Jenkins\\) is at its slip limit"):
        ms.linear.linearize(m, q=[5.0 / 1e4], operating_point=True)


def test_exact_derivatives_refused_for_callbacks():
    m = ms.Model("cb")
    b = m.add_body("b", 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Prismatic("x", m.ground, b, axis=(1, 0, 0), u0=1.0))
    m.add_force(ms.forces.PythonForce("push", lambda t, q, u: np.array([-q[0]])))
    with pytest.raises(ms.SettingsError, match="exact derivatives do not cover 'push'"):
        ms.linear.linearize(m, method="exact", operating_point=True)


# ---- steady motions against independent derivations (tests/steady_refs.py, SymPy) ---------------

import steady_models as sm  # noqa: E402

CASES = [
    ("upright_disc", dict(carrier="chain")),
    ("upright_disc", dict(carrier="free")),
    ("circular_disc", dict(carrier="chain")),
    ("circular_disc", dict(carrier="free")),
    ("chaplygin_sleigh", dict(joint="planar")),
    ("chaplygin_sleigh", dict(joint="free")),
    ("chaplygin_sleigh_unstable", dict(joint="planar")),
    ("heavy_top", {}),
    ("conical_pendulum", dict(joint="spherical")),
    ("conical_pendulum", dict(joint="free")),
]


def steady_case(key, kw):
    m = sm.BUILDERS[key.replace("_unstable", "")](**sm.PARAMS[key], **kw)
    return m, m.steady_info["reference"]


def nontrivial(lam):
    lam = np.asarray(lam, dtype=complex)
    lam = lam[np.abs(lam) > 1e-6 * max(np.abs(lam).max(initial=0.0), 1e-300)]
    scale = max(np.abs(lam).max(initial=0.0), 1e-300)
    return lam[np.lexsort((lam.imag, np.round(lam.real / scale, 6)))]


@pytest.mark.parametrize("key,kw", CASES, ids=[f"{k}-{'-'.join(map(str, v.values()))}" for k, v in CASES])
def test_steady_motion_eigenvalues_match_the_independent_derivation(key, kw):
    m, ref = steady_case(key, kw)
    lin = ms.linear.linearize(m)
    assert lin.steady
    got = nontrivial(np.linalg.eigvals(lin.A))
    # the turning disc in a chain keeps its heading-frame position: the shifted circle at +-i Omega;
    # where the cyclic world positions are dropped (free carrier) that pair is not a state
    want = nontrivial(ref.all_eigenvalues if key == "circular_disc" and kw["carrier"] == "chain" else ref.eigenvalues)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-9 * np.abs(want).max())
    # the self-check of each non-trivial eigenvalue against simulate
    c = ms.linear.check(lin)
    assert c.eigenvalues.size == (want.imag >= 0).sum() and c.worst < 1e-4, c.table()


def test_chaplygin_sleigh_is_stable_with_the_blade_behind():
    for key, sign in (("chaplygin_sleigh", -1), ("chaplygin_sleigh_unstable", 1)):
        m, _ = steady_case(key, dict(joint="planar"))
        p = sm.PARAMS[key]
        lin = ms.linear.linearize(m)
        lam = nontrivial(np.linalg.eigvals(lin.A))
        assert lam.size == 1 and lam[0].real == pytest.approx(p["m"] * p["a"] * p["v"] / (p["I"] + p["m"] * p["a"] ** 2), rel=1e-9)
        assert lin.modes().stable == (sign < 0)


def test_cyclic_coordinates_of_the_steady_motions():
    m, _ = steady_case("heavy_top", {})
    assert ms.linear.linearize(m).cyclic == ["precession", "spin"]
    m, _ = steady_case("upright_disc", dict(carrier="chain"))
    lin = ms.linear.linearize(m)
    assert lin.cyclic == ["x", "y", "heading", "spin"] and lin.M is None  # the heading rate feeds the lean
    m, _ = steady_case("conical_pendulum", dict(joint="spherical"))
    (text,) = ms.linear.linearize(m).cyclic
    assert text.startswith("turn of 'pivot' about")  # the vertical, seen from the body


def test_heavy_top_second_order_form_and_gyroscopic_matrix():
    m, ref = steady_case("heavy_top", {})
    lin = ms.linear.linearize(m)
    # holonomic: all Euler angles kept; the precession-spin coupling is gyroscopic (skew G)
    assert lin.M.shape == (3, 3) and np.abs(lin.G).max() > 1e-3 and np.allclose(lin.G, -lin.G.T)
    w = nontrivial(lin.modes().eigenvalues)
    assert w[-1].imag == pytest.approx(np.abs(ref.eigenvalues).max(), rel=1e-8)


def test_steady_motion_solver_finds_the_top_precession():
    # start from the right nutation angle and precession rate but a wrong spin: the spin is solved
    p = sm.PARAMS["heavy_top"]
    m, ref = steady_case("heavy_top", {})
    u = m.state_vector(None, "u").copy()
    names = [j["name"] for j in m.joint_info()]
    k = names.index("spin")
    exact = u[k]
    u[k] *= 1.3
    st = ms.linear.steady_motion(m, u=u, free=["spin'"])
    assert st.u[k] == pytest.approx(exact, rel=1e-9) and st.residual < 1e-9
    lin = ms.linear.linearize(m, at=st)
    assert nontrivial(lin.modes().eigenvalues)[-1].imag == pytest.approx(np.abs(ref.eigenvalues).max(), rel=1e-7)
    # only the spin was free: the nutation angle stays the given one
    assert st.q[names.index("nutation")] == pytest.approx(p["theta"], rel=1e-12)


def test_upright_disc_critical_speed_and_lean_frequency():
    import steady_refs as sr

    p = sm.PARAMS["upright_disc"]
    vc = sr.upright_disc_critical_speed(p["R"], m=p["m"])
    assert vc == pytest.approx(np.sqrt(9.81 * p["R"] / 3), rel=1e-12)
    sw = ms.linear.sweep(lambda v: sm.upright_disc_model(p["m"], p["R"], v), np.linspace(0.5 * vc, 1.5 * vc, 21), parameter="v")
    (lo, hi), = sw.stable_ranges()
    assert vc <= lo <= vc + 0.05 * vc and hi == pytest.approx(1.5 * vc)  # the first stable value of the grid
    # on either side: a capsizing real pair below, a lean oscillation at the reference's frequency above
    for v in (0.9 * vc, 1.2 * vc, 3.0):
        lam = nontrivial(np.linalg.eigvals(ms.linear.linearize(sm.upright_disc_model(p["m"], p["R"], v)).A))
        want = nontrivial(sr.upright_disc(p["m"], p["R"], v).eigenvalues)
        np.testing.assert_allclose(lam, want, rtol=1e-7, atol=1e-9)
        assert (np.abs(lam.imag).max() > 0) == (v > vc)


def test_steady_motion_bad_names_and_values():
    m = bicycle.build(v=5.0)
    with pytest.raises(ms.SettingsError, match="no joint coordinate named 'rear'"):
        ms.linear.steady_motion(m, free=["rear'"])
    with pytest.raises(ms.SettingsError, match="fixed\\['steer'\\] must be finite"):
        ms.linear.steady_motion(m, fixed={"steer": float("nan")})
    with pytest.raises(ms.SettingsError, match="quaternion coordinates"):
        ms.linear.steady_motion(m, fixed={"free[3]": 0.1})
    with pytest.raises(ms.SettingsError, match="expected a mechsys.Model"):
        ms.linear.steady_motion("bicycle")
    with pytest.raises(ms.SettingsError, match="values must be finite"):
        ms.linear.sweep(lambda v: bicycle.build(v=v), [1.0, float("inf")])
    with pytest.raises(ms.SettingsError, match="returned str"):
        ms.linear.sweep(lambda v: "no model", [1.0])
    with pytest.raises(ms.SettingsError, match="modes .* out of range"):
        ms.linear.check(ms.linear.linearize(m), modes=[7])


def test_check_refuses_settings_that_would_fit_nothing():
    lin = ms.linear.linearize(bicycle.build(v=5.0))
    for kw, name in ((dict(amplitude=0.0), "amplitude"), (dict(amplitude=float("nan")), "amplitude"),
                     (dict(cycles=-1.0), "cycles"), (dict(samples=3), "samples")):
        with pytest.raises(ms.SettingsError, match=f"check: {name}"):
            ms.linear.check(lin, **kw)


def test_a_rolling_disc_in_a_chain_has_no_second_order_form_and_says_why():
    """The disc on a circle, carried by a chain of joints: its coordinates' rates are tied by the
    rolling constraints, so their kinetic metric e M_eta^-1 e^T is singular (rank 2 of 3). The
    linearization keeps the first-order form and says why, on every rounding: the metric came out
    exactly singular on one machine (numpy's inverse raised) and as noise on another (an M built
    from its inverse); both are refused by its singular values."""
    m, ref = steady_case("circular_disc", dict(carrier="chain"))
    lin = ms.linear.linearize(m)
    assert lin.M is None and "not independent velocities" in lin.state.why_first_order
    with pytest.raises(ms.SettingsError, match="no second-order form"):
        lin.frf([1.0])
    # the first-order form is the reference's, as in the parametrized test above
    np.testing.assert_allclose(nontrivial(np.linalg.eigvals(lin.A)), nontrivial(ref.all_eigenvalues), rtol=1e-6,
                               atol=1e-9 * np.abs(ref.all_eigenvalues).max())
