"""Steady motions (relative equilibria): the mechsys models of ``steady_models`` against the
independent references of ``steady_refs``, without any linearization code.

1. Each model, started in its steady motion, stays in it: the joint velocities u and the
   non-cyclic coordinates stay constant under the nonlinear simulation.
2. Each reference reproduces the classical closed forms (critical speed of the rolling disc,
   Chaplygin's sleigh, the heavy top's nutation, the spherical pendulum's w^2 = Omega^2 (1 + 3
   cos^2 alpha), ...).
3. A run with one velocity perturbed by 1e-6 (relative to the largest joint velocity) is
   compared with the unperturbed run: the difference of the joint velocities is fitted by
   least-squares linear prediction, and its modes agree with the reference's eigenvalues to 1e-4.
"""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms

import steady_models as sm
import steady_refs as refs

G = 9.81
TIGHT = ms.DOPRI5(rtol=1e-11, atol=1e-12)
P = sm.PARAMS

# name -> (builder kwargs, perturbed joint, index in its u, differences taken before the fit)
# n_diff removes the polynomial part of the difference signal: constants (neighbouring steady
# motions) need 1, terms linear in t (a slow spin of the body frame, Spherical/Free joints) 2.
CASES = {
    "upright_disc_chain": (lambda: sm.upright_disc_model(**P["upright_disc"]), "lean", 0, 1),
    "upright_disc_free": (lambda: sm.upright_disc_model(**P["upright_disc"], carrier="free"), "float", 3, 2),
    "circular_disc_chain": (lambda: sm.circular_disc_model(**P["circular_disc"]), "lean", 0, 1),
    "circular_disc_free": (lambda: sm.circular_disc_model(**P["circular_disc"], carrier="free"), "float", 3, 2),
    "sleigh_planar": (lambda: sm.sleigh_model(**P["chaplygin_sleigh"]), "plane", 2, 1),
    "sleigh_free": (lambda: sm.sleigh_model(**P["chaplygin_sleigh"], joint="free"), "float", 5, 1),
    "sleigh_unstable": (lambda: sm.sleigh_model(**P["chaplygin_sleigh_unstable"]), "plane", 2, 1),
    "heavy_top": (lambda: sm.heavy_top_model(**P["heavy_top"]), "nutation", 0, 1),
    "conical_spherical": (lambda: sm.conical_pendulum_model(**P["conical_pendulum"]), "pivot", 0, 2),
    "conical_free": (lambda: sm.conical_pendulum_model(**P["conical_pendulum"], joint="free"), "float", 3, 2),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request):
    build, joint, index, n_diff = CASES[request.param]
    return request.param, build(), joint, index, n_diff


def _expected_modes(model) -> np.ndarray:
    """Reference eigenvalues visible in the joint velocities of the model: the non-trivial ones,
    plus the group pair +-i Omega where the model measures positions in the heading frame."""
    ref = model.steady_info["reference"]
    ev = list(ref.eigenvalues)
    joints = {j["name"] for j in model.joint_info()}
    if "xi" in joints:  # heading-frame chain of the turning disc
        ev += list(ref.group_eigenvalues)
    return np.array(ev, complex)


def _rotation(quat: np.ndarray) -> np.ndarray:
    w, x, y, z = np.asarray(quat).T
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]).transpose(2, 0, 1)


def _time_scales(model):
    ev = _expected_modes(model)
    fast = np.abs(ev).max()
    slow = np.abs(ev).min()
    return fast, slow


# ---- 1. the models are in steady motion --------------------------------------------------------

def test_model_stays_in_steady_motion(case):
    name, model, *_ = case
    fast, slow = _time_scales(model)
    t_end = 2.0 if name.startswith("sleigh") else 3 * 2 * np.pi / slow
    res = ms.simulate(model, t_end=t_end, integrator=TIGHT, output_dt=t_end / 300)
    u = res["u"]
    scale = np.abs(u[0]).max()
    np.testing.assert_allclose(u[0], model.u0(), rtol=0, atol=1e-12 * scale)  # started as given
    assert np.abs(u - u[0]).max() < 1e-7 * scale, f"{name}: joint velocities drift"
    info = {j["name"]: j for j in model.joint_info()}
    q = res["q"]
    for joint, k in model.steady_info["constant"]:
        col = q[:, info[joint]["iq"] + k]
        assert np.ptp(col) < 1e-9 * max(1.0, np.abs(col).max()), f"{name}: {joint}[{k}] not constant"
    # cyclic coordinates really move (and nothing else does)
    moving = [(j, k) for j, k in model.steady_info["cyclic"] if np.ptp(q[:, info[j]["iq"] + k]) > 1e-6]
    assert moving, f"{name}: no cyclic coordinate moves"
    # quaternion joints: the body-frame vertical (tilt) is constant
    for j in info.values():
        if j["type"] in ("spherical", "free"):
            iq = j["iq"] + (3 if j["type"] == "free" else 0)
            gamma = _rotation(q[:, iq:iq + 4])[:, 2, :]  # third row of A_IB: e_z in body axes
            assert np.abs(gamma - gamma[0]).max() < 1e-9, f"{name}: tilt of '{j['name']}' not constant"


# ---- 2. references against closed forms --------------------------------------------------------

def test_upright_disc_critical_speed_is_sqrt_gR_over_3():
    for R in (0.1, 0.3, 1.0):
        assert refs.upright_disc_critical_speed(R, G) == pytest.approx(np.sqrt(G * R / 3), rel=1e-12)
    # a hoop (I_a = m R^2, I_d = m R^2/2): v^2 = g R I_d / (I_a (I_a + m R^2) / (m R^2)) = g R / 4
    assert refs.upright_disc_critical_speed(0.5, G, m=2.0, I_a=2.0 * 0.25, I_d=0.25) == pytest.approx(
        np.sqrt(G * 0.5 / 4), rel=1e-12)


@pytest.mark.parametrize("carrier", [0.0, 2e-3])
def test_upright_disc_eigenvalues_closed_form(carrier):
    m, R = 1.5, 0.3
    I_a, I_d = m * R * R / 2, m * R * R / 4 + carrier
    vc = np.sqrt(G * R / 3)
    for v in (0.3 * vc, 0.99 * vc, 1.01 * vc, 3.0, 10.0):
        c = (m * G * R - (I_a + m * R * R) * I_a * (v / R) ** 2 / I_d) / (I_d + m * R * R)
        ref = refs.upright_disc(m, R, v, G, carrier_inertia=carrier)
        expected = np.sort_complex(np.array([np.sqrt(complex(c)), -np.sqrt(complex(c))]))
        np.testing.assert_allclose(np.sort_complex(ref.eigenvalues), expected, rtol=1e-10, atol=1e-12)
        assert ref.n_zero == 6 and len(ref.all_eigenvalues) == 8
        if carrier == 0.0:
            assert (np.abs(ref.eigenvalues.real).max() < 1e-9) == (v > vc)


def test_circular_disc_steady_spin_formula():
    R = 0.2
    for theta, Omega in ((0.3, 2.0), (-0.2, 5.0), (0.8, -1.5), (0.05, 20.0)):
        n = refs.disc_steady_spin(theta, Omega, R, G) + Omega * np.sin(theta)
        assert Omega * np.cos(theta) * (6 * n - Omega * np.sin(theta)) + 4 * G * np.sin(theta) / R == pytest.approx(
            0.0, abs=1e-10 * (1 + Omega**2 + abs(n * Omega)))
        # closed form of examples/rolling_disc.py
        assert n == pytest.approx((Omega * np.sin(theta) - 4 * G * np.tan(theta) / (R * Omega)) / 6, rel=1e-12)


def test_circular_disc_tends_to_upright_for_large_circles():
    """Lean theta -> 0 at fixed speed v: Omega = -2 g theta / (3 v) (from the steady condition,
    n -> v/R), and the eigenvalues tend to those of straight rolling."""
    m, R, v = 1.5, 0.3, 3.0
    up = refs.upright_disc(m, R, v, G).eigenvalues
    for theta in (1e-3, 1e-4):
        Omega = -2 * G * theta / (3 * v)
        ref = refs.circular_disc(m, R, theta, Omega, G)
        assert ref.steady["speed"] == pytest.approx(v, rel=1e-5)
        np.testing.assert_allclose(np.sort_complex(ref.eigenvalues), np.sort_complex(up), rtol=50 * theta)
        assert ref.n_zero == 4 and len(ref.all_eigenvalues) == 8


def test_chaplygin_sleigh_closed_form_and_stability():
    m, I = 2.0, 0.05
    for a, v in ((0.2, 1.0), (-0.2, 1.0), (0.3, -2.0), (-0.1, -0.5)):
        ref = refs.chaplygin_sleigh(m, I, a, v)
        lam = m * a * v / (I + m * a * a)
        np.testing.assert_allclose(ref.eigenvalues, [lam], rtol=1e-12)
        assert (ref.eigenvalues[0].real < 0) == (a * v < 0)  # stable: blade trailing the CM


def test_heavy_top_nutation_closed_form():
    m, l, I1, I3 = P["heavy_top"]["m"], P["heavy_top"]["l"], P["heavy_top"]["I1"], P["heavy_top"]["I3"]
    for theta, Om in ((0.5, 2.0), (1.2, -0.7), (2.0, 1.0), (0.3, 15.0)):
        spin, w3 = refs.heavy_top_spin(m, l, I1, I3, theta, Om, G)
        assert m * G * l == pytest.approx(Om * (I3 * w3 - I1 * Om * np.cos(theta)), rel=1e-12)
        a = I3 * w3 / I1
        w2 = a * a - 4 * a * Om * np.cos(theta) + Om**2 * (1 + 3 * np.cos(theta) ** 2)
        ref = refs.heavy_top(m, l, I1, I3, theta, Om, G)
        expected = np.sort_complex(np.array([1, -1]) * np.sqrt(complex(-w2)))
        np.testing.assert_allclose(np.sort_complex(ref.eigenvalues), expected, rtol=1e-10)
        assert ref.steady["spin_rate"] == pytest.approx(spin) and ref.n_zero == 4


def test_heavy_top_fast_top_limit():
    """Slow precession of a fast top: Omega ~ m g l / (I3 omega3), nutation w -> I3 omega3 / I1."""
    m, l, I1, I3 = 0.5, 0.05, 1.65e-3, 6e-4
    theta = 0.5
    for Om in (1e-2, 1e-3):
        spin, w3 = refs.heavy_top_spin(m, l, I1, I3, theta, Om, G)
        assert Om == pytest.approx(m * G * l / (I3 * w3), rel=3 * I1 * Om**2 / (m * G * l))
        w = refs.heavy_top(m, l, I1, I3, theta, Om, G).eigenvalues.imag.max()
        assert w == pytest.approx(I3 * w3 / I1, rel=5 * Om * I1 / (I3 * w3) + 1e-12)


def test_conical_pendulum_point_mass():
    """Point mass on a massless rod (I_t = 0, I_a -> 0): Omega^2 = g / (l cos alpha) and the
    classical nutation w^2 = Omega^2 (1 + 3 cos^2 alpha)."""
    m, l = 0.7, 0.8
    for alpha in (0.1, 0.6, 1.2):
        ref = refs.conical_pendulum(m, l, 0.0, 1e-14, alpha, G)
        Om = ref.steady["Omega"]
        assert Om**2 == pytest.approx(G / (l * np.cos(alpha)), rel=1e-12)
        assert ref.eigenvalues.imag.max() == pytest.approx(Om * np.sqrt(1 + 3 * np.cos(alpha) ** 2), rel=1e-10)
        assert np.abs(ref.eigenvalues.real).max() < 1e-9 * abs(Om)


def test_conical_pendulum_rigid_body_against_heavy_top():
    """Independent derivations (Euler-Poisson vs Lagrange in Euler angles): the conical pendulum is
    the heavy top with I1 = I_t + m l^2, I3 = I_a, theta = pi - alpha, precession Omega, spin 0."""
    c = P["conical_pendulum"]
    m, l, It, Ia = c["m"], c["l"], c["I_t"], c["I_a"]
    for alpha, direction in ((0.6, 1.0), (1.1, -1.0), (0.2, 1.0)):
        ref = refs.conical_pendulum(m, l, It, Ia, alpha, G, direction=direction)
        Om = ref.steady["Omega"]
        top = refs.heavy_top(m, l, It + m * l * l, Ia, np.pi - alpha, Om, G)
        assert abs(top.steady["spin_rate"]) < 1e-10 * abs(Om)
        np.testing.assert_allclose(np.sort_complex(ref.eigenvalues), np.sort_complex(top.eigenvalues), rtol=1e-10)
        w2 = Om**2 * (np.cos(alpha) ** 2 * (2 - Ia / (It + m * l * l)) ** 2 + np.sin(alpha) ** 2)
        assert ref.eigenvalues.imag.max() == pytest.approx(np.sqrt(w2), rel=1e-12)


def test_references_are_cached_and_fast():
    import time

    refs.circular_disc(**P["circular_disc"])  # warm
    t0 = time.perf_counter()
    for _ in range(200):
        refs.upright_disc(**P["upright_disc"])
        refs.circular_disc(**P["circular_disc"])
        refs.heavy_top(**P["heavy_top"])
        refs.conical_pendulum(**P["conical_pendulum"])
        refs.chaplygin_sleigh(**P["chaplygin_sleigh"])
    assert time.perf_counter() - t0 < 2.0


# ---- 3. the nonlinear mechsys motion oscillates / grows at the reference eigenvalues -------------

def fit_modes(t: np.ndarray, signals: np.ndarray, n_modes: int, n_diff: int = 1, extra: int = 2) -> np.ndarray:
    """Continuous-time eigenvalues in sampled signals (n_samples, n_channels) by least-squares
    linear prediction shared by all channels: x[k] = sum_j c_j x[k - j], order n_modes + extra,
    after n_diff differences (removing constants / linear trends: the zero eigenvalues). The
    roots z of the prediction polynomial give lambda = log(z) / dt. The ``extra`` roots absorb
    the sample-to-sample jitter of the integrator's dense output (they sit near the Nyquist
    frequency) and are dropped with everything faster than 1.2 rad per sample."""
    dt = t[1] - t[0]
    Y = np.asarray(signals, float).reshape(len(t), -1)
    amp = np.abs(Y).max(axis=0)
    Y = Y[:, amp > 1e-3 * amp.max()] / amp[amp > 1e-3 * amp.max()]
    for _ in range(n_diff):
        Y = np.diff(Y, axis=0)
    order = n_modes + extra
    n = Y.shape[0]
    A = np.concatenate([np.column_stack([Y[order - j - 1:n - j - 1, c] for j in range(order)]) for c in range(Y.shape[1])])
    b = np.concatenate([Y[order:, c] for c in range(Y.shape[1])])
    coef = np.linalg.lstsq(A, b, rcond=None)[0]
    lam = np.log(np.roots(np.concatenate([[1.0], -coef])).astype(complex)) / dt
    return lam[np.abs(lam.imag) * dt < 1.2]


def test_perturbation_follows_reference_eigenvalues(case):
    name, model, joint, index, n_diff = case
    expected = _expected_modes(model)
    fast, slow = _time_scales(model)
    if name.startswith("sleigh"):
        t_end, dt = 2.0, 0.01  # e^(3 * 2) growth of the unstable one stays in the linear range
    else:
        t_end, dt = 8 * 2 * np.pi / slow, 2 * np.pi / fast / 16
    info = {j["name"]: j for j in model.joint_info()}
    u0 = model.u0()
    du = 1e-6 * np.abs(u0).max()
    u1 = u0.copy()
    u1[info[joint]["iu"] + index] += du
    base = ms.simulate(model, t_end=t_end, integrator=TIGHT, output_dt=dt)
    pert = ms.simulate(model, t_end=t_end, integrator=TIGHT, output_dt=dt, u0=u1)
    diff = (pert["u"] - base["u"]) / du
    assert np.abs(diff).max() < 1e3  # stayed small: the linear range
    lam = fit_modes(base.t, diff, len(expected), n_diff)
    worst = 0.0
    for ev in expected:
        err = np.abs(lam - ev).min() / abs(ev)
        worst = max(worst, err)
    print(f"{name}: reference {np.round(expected, 6)}, fitted {np.round(lam, 6)}, worst relative error {worst:.1e}")
    assert worst < 1e-4, f"{name}: fitted {lam}, reference {expected}"
