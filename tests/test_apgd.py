"""The accelerated projected-gradient contact solver (ms.APGD, solver="apgd") under Moreau-Jean:
a stack's interfaces carry the weight above them, a resting stack's warm start needs no iteration,
a block slides down an incline at the closed-form acceleration, and the solver is reachable by
name, model-file table and command line, with bad settings named."""

import math

import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import SettingsError
from test_box_stack import stack_model

G = 9.81


def test_apgd_stack_carries_the_weights_and_rests_without_iterations():
    """Four boxes of 1 kg: the interface under box k carries (4 - k) m g to 1e-8 N at every sample
    (the split among the four corners is indeterminate, the sum is not), every step converges
    to 1e-12, the top box does not move (1e-9 m), and once at rest the previous step's impulses
    (kept per contact point) solve the next step's problem: at most one iteration in 95 % of the
    steps (round-off moves the resting boxes by 1e-13 m, so now and then a step takes a few)."""
    n = 4
    res = ms.simulate(stack_model(n), 0.5, ms.MoreauJean(1e-3, solver=ms.APGD(tol=1e-12, max_iter=100_000)), output_dt=1e-3)
    assert res["solver/converged"][1:].min() == 1
    assert res["solver/residual"].max() <= 1e-12
    for k in range(n):
        name = "floor" if k == 0 else f"on{k}"
        carried = res[f"contact/{name}/lambda_n"][1:].sum(axis=1)
        np.testing.assert_allclose(carried, (n - k) * G, rtol=0, atol=1e-8, err_msg=name)
    top = res[f"body/box{n - 1}/position"]
    assert np.abs(top - top[0]).max() < 1e-9
    rest = res["solver/iterations"][100:]
    assert np.mean(rest <= 1) >= 0.95 and rest.max() <= 10, np.bincount(rest.astype(int))
    # a cold start of the same problem takes many more
    assert res["solver/iterations"][1] > 50


def test_apgd_block_slides_down_an_incline_at_the_closed_form_acceleration():
    """A box on a plane under gravity tilted by alpha, mu < tan(alpha): it slides with
    x = g (sin alpha - mu cos alpha) t^2 / 2 (the De Saxce velocity makes the slip Coulomb's, the
    convex relaxation would lift the box). Moreau-Jean's midpoint rule is exact for the constant
    acceleration up to the first step, so 1e-3 relative."""
    alpha, mu, half = 0.3, 0.2, (0.1, 0.05, 0.05)
    m = ms.Model("incline", gravity=(G * math.sin(alpha), 0, -G * math.cos(alpha)))
    b = m.add_body("block", 2.0, ms.inertia.box(2.0, tuple(2 * h for h in half)))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, half[2], 1, 0, 0, 0]))
    m.add_contact(ms.Contact("base", b.contour(ms.contours.Box(half_extents=half)),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))), friction=ms.laws.Coulomb(mu)))
    res = ms.simulate(m, 0.5, ms.MoreauJean(1e-3, solver="apgd"), output_dt=1e-2)
    a = G * (math.sin(alpha) - mu * math.cos(alpha))
    x = res["body/block/position"][:, 0]
    np.testing.assert_allclose(x[-1] - x[0], 0.5 * a * 0.5**2, rtol=1e-3)
    # it slides on the plane, it is not lifted
    assert np.abs(res["body/block/position"][:, 2] - half[2]).max() < 1e-9
    assert res["solver/converged"][1:].min() == 1
    # the same run with Newton: the same motion
    ref = ms.simulate(m, 0.5, ms.MoreauJean(1e-3, solver="newton"), output_dt=1e-2)
    np.testing.assert_allclose(res["body/block/position"], ref["body/block/position"], rtol=0, atol=1e-9)


def test_apgd_by_name_table_and_bad_settings():
    assert ms.MoreauJean(1e-3, solver="apgd").solver == ms.APGD()
    assert ms.APGD(tol=1e-6, max_iter=50).describe() == {"type": "apgd", "tol": 1e-6, "max_iter": 50}
    from mechsys.modelfile import _solver

    assert _solver({"type": "apgd", "tol": 1e-8}) == ms.APGD(tol=1e-8)
    with pytest.raises(SettingsError, match=r"integrator\.solver\.max_iter: expected an integer >= 1"):
        _solver({"type": "apgd", "max_iter": 0})
    with pytest.raises(SettingsError, match=r"integrator\.solver\.relaxation: unknown key for apgd"):
        _solver({"type": "apgd", "relaxation": 1.2})
    with pytest.raises(Exception, match="APGD: tol must be a finite number > 0"):
        ms.simulate(stack_model(1), 0.01, ms.MoreauJean(1e-3, solver=ms.APGD(tol=-1.0)))


def test_apgd_from_the_command_line(tmp_path):
    """`mechsys run examples/box_stack.py --solver apgd`: the run records the solver and its
    signals, and the tower's steps converge (the file's own solver is Auto)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "box_stack.py"
    out = tmp_path / "stack.h5"
    cmd = [sys.executable, "-m", "mechsys", "run", str(example), "--t-end", "0.05", "--solver", "apgd", "--out", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path, timeout=300,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert proc.returncode == 0, proc.stderr
    res = ms.load(out)
    assert res.settings["integrator"]["solver"] == {"type": "apgd", "tol": 1e-10, "max_iter": 10_000}
    assert res["solver/converged"][1:].min() == 1 and res["solver/residual"].max() <= 1e-10
