"""The benchmark bicycle of Meijaard, Papadopoulos, Ruina and Schwab (Proc. R. Soc. A 463, 2007):
the closed-form reference (tests/bicycle_reference.py) against the published numbers, and the
mechsys model (examples/bicycle.py) against the reference: steady upright running, the motion
after a small push in lean (weave unstable at 3 m/s, self-stable at 5 m/s), and the linearization
at rest.

Sign conventions: the model's lean (rotation of the rear frame about the forward axis, from its
orientation) and steer (the ``steer`` joint, axis pointing down the steer axis) are the paper's,
both positive to the right, so no sign is changed anywhere; the perturbation tests would fail
with the wrong sign of either.
"""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import bicycle_reference as ref  # noqa: E402

BIKE = runpy.run_path(str(HERE.parent / "examples" / "bicycle.py"))
build, lean, steer = BIKE["build"], BIKE["lean"], BIKE["steer"]
SMOOTH = dict(integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=0.01)


# ---- the reference ---------------------------------------------------------------------------


def test_reference_matrices_reproduce_the_published_values():
    m = ref.matrices()
    for key, published in (("M", ref.M_PUBLISHED), ("C1", ref.C1_PUBLISHED), ("K0", ref.K0_PUBLISHED),
                           ("K2", ref.K2_PUBLISHED)):
        np.testing.assert_allclose(m[key], published, rtol=0, atol=1e-10, err_msg=key)
    # a few of the intermediate values quoted in the paper
    assert m["mT"] == pytest.approx(94.0, abs=1e-12)
    assert m["mT"] * m["zT"] == pytest.approx(-80.95, abs=1e-12)
    assert m["mu"] == pytest.approx(0.08 / 1.02 * np.cos(np.pi / 10), abs=1e-15)


def test_reference_weave_and_capsize_speeds():
    vw, vc = ref.weave_speed(), ref.capsize_speed()
    assert vw == pytest.approx(4.29238, abs=1e-5)
    assert vc == pytest.approx(6.02426, abs=1e-5)
    assert vw == pytest.approx(ref.WEAVE_SPEED_PUBLISHED, abs=1e-10)
    assert vc == pytest.approx(ref.CAPSIZE_SPEED_PUBLISHED, abs=1e-10)
    # stable in between, unstable just outside
    assert ref.eigenvalues(0.5 * (vw + vc)).real.max() < 0
    assert ref.eigenvalues(vw - 1e-3).real.max() > 0
    assert ref.eigenvalues(vc + 1e-3).real.max() > 0
    # at rest: the two static (inverted pendulum) instabilities, as tabulated (the last quoted
    # digits differ by 4e-12 for the second one)
    np.testing.assert_allclose(np.sort(np.abs(ref.eigenvalues(0.0).real))[::2], ref.EIGENVALUES_V0_PUBLISHED,
                               rtol=0, atol=1e-10)
    assert np.abs(ref.eigenvalues(0.0).imag).max() == 0.0


# ---- the model -------------------------------------------------------------------------------


def test_upright_configuration_has_zero_pitch_and_both_wheels_down():
    q, pitch = BIKE["configuration"](0.0, 0.0)
    assert pitch == 0.0
    np.testing.assert_array_equal(q[:7], [0, 0, 0, 1, 0, 0, 0])
    # a perturbed start: positions and velocities already consistent (assembly leaves them)
    m = build(v=4.0, lean=0.05, steer=0.1, lean_rate=0.2, steer_rate=-0.3)
    q0, u0 = m.q0(), m.u0()
    q1, u1 = ms.analysis.assemble(m, q0, u0)
    np.testing.assert_allclose(q1, q0, rtol=0, atol=1e-14)
    np.testing.assert_allclose(u1, u0, rtol=0, atol=1e-12)
    assert abs(BIKE["configuration"](0.05, 0.1)[1]) > 1e-4  # the pitch that keeps the front wheel down


def test_steady_upright_straight_running_at_5_m_per_s():
    res = ms.simulate(build(v=5.0), t_end=3.0, **SMOOTH)
    u = res["u"]
    np.testing.assert_allclose(u, np.broadcast_to(u[0], u.shape), rtol=0, atol=1e-8)
    np.testing.assert_allclose(u[0], [5, 0, 0, 0, 0, 0, -5 / 0.3, 0, -5 / 0.35], rtol=0, atol=1e-14)
    assert np.abs(lean(res)).max() < 1e-10
    assert np.abs(steer(res)).max() < 1e-10
    x = res["body/rear_frame/position"]
    np.testing.assert_allclose(x[:, 0], 5.0 * res.t, rtol=0, atol=1e-8)
    np.testing.assert_allclose(x[:, 1:], 0.0, rtol=0, atol=1e-8)
    for c in ("rear_contact", "front_contact"):
        assert np.abs(res[f"constraint/{c}/violation"]).max() < 1e-12


@pytest.mark.parametrize("v, grows", [(3.0, True), (5.0, False)], ids=["3 m/s weave unstable", "5 m/s stable"])
def test_small_lean_push_follows_the_linearized_benchmark(v, grows):
    """Lean rate 1e-5 rad/s at t = 0 on upright straight running; the difference of lean and steer
    from the unperturbed run against the reference's exp(A t) x0 over 3 s."""
    eps, t_end = 1e-5, 3.0
    base = ms.simulate(build(v=v), t_end=t_end, **SMOOTH)
    push = ms.simulate(build(v=v, lean_rate=eps), t_end=t_end, **SMOOTH)
    np.testing.assert_allclose(push.t, base.t)
    d_lean, d_steer = lean(push) - lean(base), steer(push) - steer(base)
    linear = ref.lean_steer_response(v, push.t, phidot0=eps)
    for name, sim, pred in (("lean", d_lean, linear[:, 0]), ("steer", d_steer, linear[:, 1])):
        amp = np.abs(pred).max()
        err = np.abs(sim - pred).max()
        assert err < 1e-3 * amp, f"{name} at {v} m/s: error {err:.3g} of amplitude {amp:.3g}"
    # the lean rate starts as given, in the paper's sign (positive: leaning to the right)
    assert push["u"][0, 3] == pytest.approx(eps, abs=1e-18)
    early, late = np.abs(linear[push.t <= 1.0, 0]).max(), np.abs(linear[push.t >= t_end - 1.0, 0]).max()
    assert (late > 10 * early) if grows else (late < early)
    assert (np.abs(d_lean[push.t >= t_end - 1.0]).max() > 10 * np.abs(d_lean[push.t <= 1.0]).max()) if grows \
        else (np.abs(d_lean[push.t >= t_end - 1.0]).max() < np.abs(d_lean[push.t <= 1.0]).max())


@pytest.mark.parametrize("v, start", [(5.0, dict(lean=1e-5)), (5.0, dict(steer=1e-5)), (3.0, dict(steer=1e-5)),
                                      (5.0, dict(steer_rate=1e-5))], ids=["lean", "steer", "steer 3 m/s", "steer rate"])
def test_other_small_starts_follow_the_linearized_benchmark(v, start):
    """Starts at a lean or steer angle (the rear frame pitched to keep the front wheel down, the yaw
    rate v delta cos(lambda) / w of rolling) or a steer rate: the same agreement."""
    base = ms.simulate(build(v=v), t_end=3.0, **SMOOTH)
    push = ms.simulate(build(v=v, **start), t_end=3.0, **SMOOTH)
    linear = ref.lean_steer_response(v, push.t, phi0=start.get("lean", 0.0), delta0=start.get("steer", 0.0),
                                     deltadot0=start.get("steer_rate", 0.0))
    for sim, pred in ((lean(push) - lean(base), linear[:, 0]), (steer(push) - steer(base), linear[:, 1])):
        assert np.abs(sim - pred).max() < 1e-3 * np.abs(pred).max()


def test_linearization_at_rest_matches_the_benchmark():
    lin = ms.linear.linearize(build(v=0.0))
    assert lin.n == 3  # lean, steer, forward motion (rolling leaves 3 velocity freedoms)
    lam = np.linalg.eigvals(lin.state_matrix())
    order = np.argsort(np.abs(lam))
    zero, moving = lam[order[:2]], lam[order[2:]]
    assert np.abs(zero).max() < 1e-4  # the forward motion: no stiffness, a (numerically tiny) double zero
    moving = moving[np.lexsort((moving.imag, moving.real))]
    np.testing.assert_allclose(moving, ref.eigenvalues(0.0), rtol=0, atol=1e-8)
