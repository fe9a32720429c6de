"""Adaptive Radau IIA (``ms.Radau5(rtol=...)``) on a stiff mechanical model against its exact
solution: two bodies on prismatic joints coupled by a stiff spring-damper (k = 1e8 N/m,
d = 1e3 N s/m), the first tied to ground by a soft spring (k = 100 N/m). The model is linear, so
its exact motion is expm(A t) z0; the stiff mode (1.4e4 rad/s, decaying at 1000 1/s) limits an
explicit scheme to steps of ~2e-4 s while the motion that matters is the slow 7.07 rad/s one.
Also: the fixed-step mode, the command line, the settings' parsing and their error messages."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

import mechsys as ms
from mechsys.cli import _describe_integrator
from mechsys.modelfile import load_model, simulation_kwargs

M1, M2 = 1.0, 1.0  # kg
K, D = 1e8, 1e3  # the stiff coupling, N/m and N s/m
KS = 100.0  # the soft spring to ground, N/m
L = 0.5  # rest distance of the coupling, m
X0 = 0.1  # both bodies start displaced by X0, at rest
T_END = 2.0

# the model as a model file, so that the command-line test runs the very same model
MODEL_PY = f"""
import mechsys as ms

model = ms.Model("stiff_pair", gravity=(0, 0, 0))
a = model.add_body("a", mass={M1}, inertia=[1e-3] * 3)
b = model.add_body("b", mass={M2}, inertia=[1e-3] * 3)
model.add_joint(ms.joints.Prismatic("xa", model.ground, a, axis=(1, 0, 0), q0={X0},
                                    spring=ms.joints.JointSpring(k={KS})))
model.add_joint(ms.joints.Prismatic("xb", model.ground, b, axis=(1, 0, 0), parent_frame=({L}, 0, 0), q0={X0}))
model.add_force(ms.forces.SpringDamper("coupling", a, b, k={K}, d={D}, l0={L}))
simulation = {{"t_end": {T_END}, "output_dt": 0.01}}
"""


def stiff_pair() -> ms.Model:
    ns: dict = {}
    exec(MODEL_PY, ns)
    return ns["model"]


def exact(t: np.ndarray) -> np.ndarray:
    """(xa, xb) at the times t from the linear equations of motion, z = (xa, xb, va, vb):
    m1 xa'' = -KS xa + K (xb - xa) + D (vb - va),  m2 xb'' = -K (xb - xa) - D (vb - va)."""
    a = np.array([
        [0, 0, 1, 0],
        [0, 0, 0, 1],
        [-(KS + K) / M1, K / M1, -D / M1, D / M1],
        [K / M2, -K / M2, D / M2, -D / M2],
    ])
    # velocities scaled by sqrt(K/m1): the same exponential, better balanced for expm
    # (unscaled its error at t = 2 s is 1.4e-10 m against a 50-digit mpmath expm, scaled 8e-11)
    s = np.diag([1.0, 1.0, np.sqrt(K / M1), np.sqrt(K / M1)])
    a_s = np.linalg.solve(s, a @ s)
    z0 = np.linalg.solve(s, np.array([X0, X0, 0.0, 0.0]))
    return np.array([(s @ scipy.linalg.expm(a_s * ti) @ z0)[:2] for ti in t])


@pytest.fixture(scope="module")
def model():
    return stiff_pair()


@pytest.fixture(scope="module")
def reference():
    t = np.linspace(0.0, T_END, 201)
    return t, exact(t)


def max_error(res, ref) -> float:
    t, z = ref
    np.testing.assert_allclose(res.t, t, atol=1e-12)
    return float(max(np.max(np.abs(res["joint/xa/q"] - z[:, 0])), np.max(np.abs(res["joint/xb/q"] - z[:, 1]))))


def test_the_error_falls_with_rtol_and_stays_below_it(model, reference):
    # measured (max over 201 samples, m): 2.2e-6, 1.3e-8, 2.6e-10 with 105, 328, 891 steps
    errors, steps = [], []
    for rtol in (1e-4, 1e-6, 1e-8):
        res = ms.simulate(model, T_END, ms.Radau5(rtol=rtol), output_dt=0.01)
        errors.append(max_error(res, reference))
        steps.append(res.stats["steps"])
        assert errors[-1] < rtol * X0, (rtol, errors)  # below the tolerance relative to the amplitude
    assert errors[1] < errors[0] / 10 and errors[2] < errors[1] / 10, errors
    assert steps[0] < steps[1] < steps[2] < 2000, steps


def test_far_fewer_steps_than_dopri5_at_the_same_rtol(model, reference):
    # measured at rtol 1e-6: Radau5 328 steps (2422 evaluations), DOPRI5 11339 steps (75842)
    radau = ms.simulate(model, T_END, ms.Radau5(rtol=1e-6), output_dt=0.01)
    dopri = ms.simulate(model, T_END, ms.DOPRI5(rtol=1e-6), output_dt=0.01)
    assert radau.stats["steps"] * 10 < dopri.stats["steps"], (radau.stats, dopri.stats)
    assert radau.stats["evaluations"] * 10 < dopri.stats["evaluations"]
    # the Jacobian is kept over most steps (Newton converges fast)
    assert radau.stats["jacobians"] < radau.stats["steps"] / 4, radau.stats
    assert max_error(dopri, reference) < 1e-7 and max_error(radau, reference) < 1e-7


def test_outputs_between_steps_meet_the_tolerance(model):
    # samples every 1 ms, ~15 per step on the slow motion: the collocation polynomial
    res = ms.simulate(model, T_END, ms.Radau5(rtol=1e-6), output_dt=1e-3)
    coarse = ms.simulate(model, T_END, ms.Radau5(rtol=1e-6), output_dt=0.5)
    assert res.stats["steps"] == coarse.stats["steps"]  # the samples do not shorten the steps
    assert len(res.t) == 2001 < 10 * res.stats["steps"]
    z = exact(res.t)
    err = max(np.max(np.abs(res["joint/xa/q"] - z[:, 0])), np.max(np.abs(res["joint/xb/q"] - z[:, 1])))
    assert err < 1e-6 * X0, err


def test_fixed_step_radau5_still_works(model, reference):
    res = ms.simulate(model, T_END, ms.Radau5(dt=1e-2))
    assert res.stats["steps"] == 200 and res.stats["rejected"] == 0
    assert max_error(res, reference) < 1e-8  # measured 4.0e-10
    assert res.settings["integrator"]["type"] == "radau5" and res.settings["integrator"]["dt"] == 0.01


def test_settings_parse_from_tables_and_overrides():
    kw = simulation_kwargs({"t_end": 1.0, "integrator": {"type": "radau5", "rtol": 1e-6, "atol": 1e-9}})
    assert kw["integrator"] == ms.Radau5(rtol=1e-6, atol=1e-9)
    # a file's fixed step gives way to a tolerance from the command line, and back
    fixed = {"t_end": 1.0, "integrator": {"type": "radau5", "dt": 1e-3}}
    assert simulation_kwargs(fixed, rtol=1e-8)["integrator"] == ms.Radau5(rtol=1e-8)
    adaptive = {"t_end": 1.0, "integrator": {"type": "radau5", "rtol": 1e-6}}
    assert simulation_kwargs(adaptive, dt=1e-3)["integrator"] == ms.Radau5(1e-3)
    assert simulation_kwargs({"t_end": 1.0, "integrator": {"type": "rk4", "dt": 1e-3}}, integrator="radau5",
                             rtol=1e-7)["integrator"] == ms.Radau5(rtol=1e-7)
    assert ms.Radau5(rtol=1e-6).describe() == {"type": "radau5", "rtol": 1e-6, "atol": 1e-10, "newton_tol": 1e-10,
                                               "max_step": 0.0, "first_step": 0.0}
    assert _describe_integrator({"integrator": ms.Radau5(rtol=1e-8).describe()}) == "radau5 (adaptive, rtol=1e-08, atol=1e-10)"
    assert _describe_integrator({"integrator": ms.Radau5(dt=1e-3).describe()}) == "radau5 (fixed step, dt=0.001, newton_tol=1e-10)"


def test_max_step_and_first_step_are_honoured(model):
    res = ms.simulate(model, 0.5, ms.Radau5(rtol=1e-4, max_step=0.005, first_step=1e-6), output_dt=0.01)
    assert res.stats["steps"] >= 100  # 0.5 s in steps of at most 5 ms


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: ms.Radau5(1e-3, rtol=1e-6), ["dt", "rtol", "not both"]),
        (lambda: ms.Radau5(), ["dt", "rtol", "one of"]),
        (lambda: ms.simulate(stiff_pair(), 0.1, ms.Radau5(rtol=0.0)), ["integrator.rtol", "[1e-14, 1)"]),
        (lambda: ms.simulate(stiff_pair(), 0.1, ms.Radau5(rtol=1e-30)), ["integrator.rtol", "[1e-14, 1)", "1e-30"]),
        (lambda: ms.simulate(stiff_pair(), 0.1, ms.Radau5(rtol=1e-6, atol=-1.0)), ["integrator.atol", "> 0", "-1"]),
        (lambda: ms.simulate(stiff_pair(), 0.1, ms.Radau5(rtol=1e-6, max_step=-1.0)), ["integrator.max_step"]),
        (lambda: ms.simulate(stiff_pair(), 0.1, ms.Radau5(dt=-1e-3)), ["integrator.dt", "> 0"]),
        (lambda: simulation_kwargs({"t_end": 1.0, "integrator": {"type": "radau5"}}), ["radau5", "--dt", "--rtol"]),
        (lambda: simulation_kwargs({"t_end": 1.0}, integrator="radau5", dt=1e-3, rtol=1e-6), ["not both"]),
        (lambda: simulation_kwargs({"t_end": 1.0}, integrator="radau5", dt=1e-3, atol=1e-6), ["--atol", "fixed step"]),
    ],
    ids=["both", "neither", "rtol-0", "rtol-1e-30", "atol-negative", "max_step-negative", "dt-negative",
         "table-without-either", "overrides-both", "atol-with-fixed-step"],
)
def test_bad_settings_name_the_setting(make, words):
    with pytest.raises(ms.SettingsError) as e:
        make()
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_a_model_file_with_both_is_refused_at_load(tmp_path):
    p = tmp_path / "both.py"
    p.write_text(MODEL_PY + "simulation['integrator'] = {'type': 'radau5', 'dt': 1e-3, 'rtol': 1e-6}\n")
    with pytest.raises(ms.ModelError, match=r"simulation\.integrator: give radau5 a step dt .* not both"):
        load_model(p)
    p.write_text(MODEL_PY + "simulation['integrator'] = ms.Radau5(rtol=1e-6)\n")
    _, sim = load_model(p)
    assert sim["integrator"] == ms.Radau5(rtol=1e-6)


def _cli(args: list[str]) -> subprocess.CompletedProcess:
    script = Path(sys.executable).parent / "mechsys"
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "mechsys"]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run(cmd + args, capture_output=True, text=True, env=env, timeout=120)


def test_command_line_runs_adaptive_and_fixed_radau5(tmp_path, reference):
    model_file = tmp_path / "stiff_pair.py"
    model_file.write_text(MODEL_PY)
    out = tmp_path / "adaptive.h5"
    proc = _cli(["run", str(model_file), "--integrator", "radau5", "--rtol", "1e-8", "--out", str(out)])
    assert proc.returncode == 0, proc.stderr
    assert "radau5 (adaptive, rtol=1e-08, atol=1e-10)" in proc.stdout, proc.stdout
    res = ms.load(out)
    assert res.settings["integrator"]["rtol"] == 1e-8
    assert max_error(res, reference) < 1e-9
    assert res.stats["steps"] < 2000

    out = tmp_path / "fixed.h5"
    proc = _cli(["run", str(model_file), "--integrator", "radau5", "--dt", "0.01", "--out", str(out)])
    assert proc.returncode == 0, proc.stderr
    assert "radau5 (fixed step, dt=0.01" in proc.stdout, proc.stdout
    assert ms.load(out).stats["steps"] == 200

    proc = _cli(["run", str(model_file), "--integrator", "radau5", "--rtol", "1e-30", "--out", str(out)])
    assert proc.returncode != 0 and "integrator.rtol" in proc.stderr, proc.stderr
