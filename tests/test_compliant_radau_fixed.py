"""Fixed-step Radau5 with compliant contacts (issue 19, item 3): a step across an onset, release
or force cut-off is split there (located on the collocation polynomial), so no step straddles the
kink; checked on the Hertz sphere-plane impact against its closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mechsys as ms
from test_compliant import E_STAR, FACTOR, MASS, R, ball_on_plane, contact_times, hertz_closed_form, peak

GAP = 2.03e-4  # the onset at t = 203 us falls inside a step of the grid


def test_fixed_step_radau5_hertz_impact_against_closed_form():
    """delta_max = (5 m v^2 / 4K)^(2/5), duration 2.9432 delta_max / v, restitution 1, with the
    onset located exactly and the outputs on the dt grid; the errors fall like dt^5."""
    k = 4.0 / 3.0 * E_STAR * math.sqrt(R)
    d, f, T = hertz_closed_form(MASS, 1.0, k)
    errors = []
    for dt in (5e-7, 2e-7):
        res = ms.simulate(ball_on_plane(ms.laws.Hertz(), gap=GAP), t_end=4e-4, output_dt=dt,
                          integrator=ms.Radau5(dt=dt, newton_tol=1e-13), progress=False)
        close, opened = contact_times(res)
        assert len(close) == 1 and len(opened) == 1
        # located, not rounded to the grid: no step straddles the onset
        assert close[0] == pytest.approx(GAP, rel=1e-10)
        assert np.allclose(res["t"], np.arange(len(res["t"])) * dt, rtol=0, atol=1e-15)
        assert res.stats["steps"] >= 2 + round(4e-4 / dt)
        errors.append((abs((opened[0] - close[0]) / T - 1), abs(res["joint/z/u"][-1] - 1)))
    assert errors[1][0] < 1e-9 and errors[1][1] < 1e-8
    assert peak(res["t"], res["contact/c/overlap"]) == pytest.approx(d, rel=1e-6)
    assert peak(res["t"], res["contact/c/force_n"]) == pytest.approx(f, rel=1e-6)
    assert (opened[0] - close[0]) * 1.0 / FACTOR == pytest.approx(d, rel=1e-9)
    # fifth order: 2.5x smaller steps, about 100x smaller errors
    assert errors[1][1] < errors[0][1] / 30


def test_fixed_step_radau5_lands_on_the_adaptive_run_with_a_damped_law():
    """Hunt-Crossley (onset speed committed at the located onset) at a fixed step of 1e-6 s against
    the adaptive Radau5 at rtol 1e-11: the rebound speed agrees to 1e-6."""
    law = ms.laws.HuntCrossley(eps=0.5)
    fixed = ms.simulate(ball_on_plane(law, gap=GAP), t_end=4e-4, output_dt=1e-6,
                        integrator=ms.Radau5(dt=1e-6, newton_tol=1e-13), progress=False)
    ref = ms.simulate(ball_on_plane(law, gap=GAP), t_end=4e-4, output_dt=1e-6,
                      integrator=ms.Radau5(rtol=1e-11, atol=1e-16), progress=False)
    assert fixed["joint/z/u"][-1] == pytest.approx(ref["joint/z/u"][-1], rel=1e-6)
    assert 0.5 < fixed["joint/z/u"][-1] < 0.8
