"""Runs through singular configurations: a chain of parallelogram four-bars under gravity turning
through its flat (change-point) positions, where each loop's x-equation vanishes and the loop could
flip to its crossed form. Checked against the exact one-degree-of-freedom reduction written here
(all cranks and rockers turn by the same angle, the couplers translate), with every smooth
integrator; and the stop-instead option."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mechsys as ms

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import parallelogram  # noqa: E402

A, B, R = 0.1, 0.3, 0.005  # crank / rocker length, coupler length, link radius (as the example's)
M_LINK, M_COUPLER, G = 0.2, 0.4, 9.81
assert (parallelogram.A, parallelogram.B, parallelogram.R, parallelogram.M_LINK, parallelogram.M_COUPLER) == \
    (A, B, R, M_LINK, M_COUPLER)


def parallelograms(n: int, theta0: float = 0.3, omega0: float = 12.0) -> ms.Model:
    """n parallelogram loops in a row (examples/parallelogram.py): a crank and n rockers (length A,
    pivots B apart), n couplers (length B), each coupler hinged to the previous rocker's tip (the
    crank's for the first) and closed on the next rocker's tip by a Point constraint (3 rows, one
    redundant in the plane)."""
    return parallelogram.build(n, theta0, omega0)


def reduction(n: int, t, theta0: float = 0.3, omega0: float = 12.0):
    """theta(t), theta'(t) of J theta'' = -dV/dtheta: cranks and rockers (n + 1 links, each
    m (A^2 / 4) + m (3 r^2 + A^2) / 12 about its pivot) turn together; couplers translate on
    circles of radius A; V = g sin(theta) ((n + 1) m A / 2 + n m_c A)."""
    j_link = M_LINK * (3 * R**2 + A**2) / 12 + M_LINK * A**2 / 4
    j = (n + 1) * j_link + n * M_COUPLER * A**2
    c = G * ((n + 1) * M_LINK * A / 2 + n * M_COUPLER * A)
    sol = solve_ivp(lambda _, y: [y[1], -c * np.cos(y[0]) / j], (t[0], t[-1]), [theta0, omega0], t_eval=t,
                    method="DOP853", rtol=1e-13, atol=1e-14)
    energy = 0.5 * j * sol.y[1] ** 2 + c * np.sin(sol.y[0])
    return sol.y[0], sol.y[1], energy


def run(model, integrator, t_end=3.0, output_dt=1e-3):
    with pytest.warns(UserWarning) as rec:
        res = ms.simulate(model, t_end, integrator, output_dt=output_dt)
    return res, [str(w.message) for w in rec]


@pytest.mark.parametrize("n", [1, 3])
def test_dopri5_through_the_flat_positions_error_falls_with_the_tolerance(n):
    m = parallelograms(n)
    errs, drifts = [], []
    for rtol in (1e-8, 1e-10, 1e-12):
        res, msgs = run(m, ms.DOPRI5(rtol=rtol, atol=rtol * 1e-2))
        theta, omega, _ = reduction(n, res.t)
        # the crank passes the flat positions (theta = k pi) several times in 3 s
        passes = np.count_nonzero(np.diff(np.floor(res["joint/crank/q"] / np.pi)))
        assert passes >= 5
        # every loop stays a parallelogram: each rocker turns with the crank
        for k in range(n):
            np.testing.assert_allclose(res[f"joint/r{k}/q"], res["joint/crank/q"], atol=1e-6)
        errs.append(np.abs(res["joint/crank/q"] - theta).max())
        e = res["energy/total"]
        drifts.append(np.ptp(e))
    assert errs[-1] < 1e-7 and drifts[-1] < 1e-8, (errs, drifts)
    assert errs[0] > 10 * errs[-1] and drifts[0] > 10 * drifts[-1], (errs, drifts)


@pytest.mark.parametrize("integrator", [ms.RK4(dt=1e-3), ms.RK4(dt=1e-4), ms.Radau5(dt=1e-3)], ids=str)
def test_fixed_step_schemes_pass_the_flat_positions(integrator):
    m = parallelograms(3)
    res, msgs = run(m, integrator)
    theta, _, _ = reduction(3, res.t)
    assert np.abs(res["joint/crank/q"] - theta).max() < 1e-6
    assert np.ptp(res["energy/total"]) < 2e-8
    # the passages are reported, with their time and constraint
    near = [s for s in msgs if "singular configuration" in s]
    assert near and all("constraint 'loop" in s for s in near)


@pytest.mark.parametrize("n", [1, 3])
def test_rk4_through_the_flat_positions_converges_at_its_order(n):
    """Halving RK4's step divides the error by about 16 (order 4) through every passage, until
    near 1e-9 rad the interpolation of the accelerations across the window around each flat
    position takes over (measured: n = 1: 3.4e-7, 1.7e-8, 1.2e-9; n = 3: 2.9e-7, 2.1e-8, 3.6e-9
    rad at dt = 2e-3, 1e-3, 5e-4; energy drift 4.2e-9, 1.9e-10, 9e-12 and 7.0e-9, 9.1e-10,
    3.6e-10 J)."""
    m = parallelograms(n)
    errs, drifts = [], []
    for dt in (2e-3, 1e-3, 5e-4):
        res, _ = run(m, ms.RK4(dt=dt), output_dt=1e-2)
        theta, _, _ = reduction(n, res.t)
        errs.append(np.abs(res["joint/crank/q"] - theta).max())
        drifts.append(np.ptp(res["energy/total"]))
    assert errs[0] / errs[1] > 8 and errs[1] / errs[2] > 4, errs
    assert drifts[0] / drifts[1] > 3 and drifts[1] / drifts[2] > 2, drifts
    assert errs[2] < 5e-9 and drifts[2] < 5e-10, (errs, drifts)


def test_the_exact_reduction_is_what_the_test_thinks():
    # its energy is conserved and it passes the flat positions at speed
    t = np.linspace(0, 3, 30001)
    theta, omega, energy = reduction(3, t)
    assert np.ptp(energy) < 1e-10 * np.abs(energy).max()
    crossing = np.nonzero(np.diff(np.floor(theta / np.pi)))[0]
    assert crossing.size >= 5 and np.abs(omega[crossing]).min() > 5.0


def test_stop_at_a_singular_configuration_from_the_command_line(tmp_path):
    # the slider-crank of rod length = crank radius lands on its singular position at t = 0.5 s
    import subprocess
    import sys

    model = tmp_path / "sc.py"
    model.write_text(
        "import mechsys as ms\n"
        "r = 0.2\n"
        "model = ms.Model('sc', gravity=(0, 0, 0))\n"
        "crank = model.add_body('crank', 1.0, [0.01, 0.01, 0.01], com=(r / 2, 0, 0))\n"
        "rod = model.add_body('rod', 1.0, [0.01, 0.01, 0.01], com=(r / 2, 0, 0))\n"
        "slider = model.add_body('slider', 1.0, [0.01, 0.01, 0.01])\n"
        "model.add_joint(ms.joints.Revolute('crank', model.ground, crank))\n"
        "model.add_joint(ms.joints.Revolute('elbow', crank, rod, parent_frame=(r, 0, 0), q0=-0.0))\n"
        "model.add_joint(ms.joints.Prismatic('guide', model.ground, slider, axis=(1, 0, 0), q0=2 * r))\n"
        "model.add_constraint(ms.constraints.Point('wrist', body1=rod, point1=(r, 0, 0), body2=slider))\n"
        "model.add_constraint(ms.constraints.Prescribed('motor', 'crank', ms.functions.Ramp(slope=3.141592653589793)))\n"
        "simulation = dict(t_end=1.0, integrator=ms.RK4(dt=1e-3), output_dt=1e-2)\n"
    )
    cmd = [sys.executable, "-m", "mechsys", "run", str(model), "--out", str(tmp_path / "r.h5"), "-q"]
    ok = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0, ok.stderr
    stop = subprocess.run(cmd + ["--on-singular", "stop"], capture_output=True, text=True, timeout=120)
    assert stop.returncode != 0 and "singular configuration at t = 0.5" in stop.stderr and "'wrist'" in stop.stderr


def test_adaptive_radau5_through_the_flat_positions_error_falls_with_the_tolerance():
    """Measured: rtol 1e-6, 1e-8, 1e-10 -> crank error 7.6e-6, 5.5e-8, 9.4e-9 rad, energy drift
    3.6e-6, 2.4e-8, 1.4e-9 J."""
    m = parallelograms(3)
    errs, drifts = [], []
    for rtol in (1e-6, 1e-8, 1e-10):
        res, msgs = run(m, ms.Radau5(rtol=rtol, atol=rtol * 1e-2))
        theta, _, _ = reduction(3, res.t)
        errs.append(np.abs(res["joint/crank/q"] - theta).max())
        drifts.append(np.ptp(res["energy/total"]))
        assert any("singular configuration" in s for s in msgs)
    assert errs[0] > 30 * errs[1] > 30 * 3 * errs[2], errs
    assert drifts[0] > 30 * drifts[1] > 30 * 10 * drifts[2], drifts
    assert errs[2] < 3e-8 and drifts[2] < 5e-9, (errs, drifts)
