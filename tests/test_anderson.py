"""Anderson-accelerated Gauss-Seidel (``NSGS(anderson=m)``, and ``Auto``'s sweeps on problems
above its Newton size): a pile of spheres poured into a box settles with converged contact
problems in fewer sweeps than plain Gauss-Seidel, to the same physical state; bad depths are
refused with the key named."""

import warnings

import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import SettingsError
from piles import M, R, box_pile


def pile(n=36, half=0.16):
    rng = np.random.default_rng(1)
    per = 3
    centres = []
    for i in range(n):
        ix, iy, iz = i % per, (i // per) % per, i // (per * per)
        centres.append((-half + 1.1 * R + 2.2 * R * ix + rng.uniform(-0.02, 0.02) * R,
                        -half + 1.1 * R + 2.2 * R * iy + rng.uniform(-0.02, 0.02) * R, R + 0.01 + 2.2 * R * iz))
    return box_pile(centres, half)


def run(solver, t_end=1.2):
    with warnings.catch_warnings():
        # (a step or two of the pour may miss the tolerance: counted below)
        warnings.filterwarnings("ignore", message=".*did not reach its tolerance")
        res = ms.simulate(pile(), t_end, ms.MoreauJean(1e-3, solver=solver), output_dt=1e-3, progress=False)
    return res


@pytest.fixture(scope="module")
def runs():
    tol = 1e-6
    return {aa: run(ms.Auto(tol=tol, newton_max_unknowns=0, nsgs_anderson=aa)) for aa in (0, 4)}


def test_accelerated_sweeps_converge_every_step_in_fewer_sweeps(runs):
    plain, fast = runs[0], runs[4]
    for res in (plain, fast):
        # (one step of the pour, a sphere knocked into the corner, ends at 6.6e-6 after the
        # 10 000 sweeps of both; the run warns about it)
        conv = res["solver/converged"][1:].astype(bool)
        assert conv.mean() >= 0.99 and res["solver/residual"][1:][conv].max() <= 1e-6
    it0, it4 = plain["solver/iterations"][1:], fast["solver/iterations"][1:]
    # the settled part of the pour, where plain sweeps crawl
    late = slice(len(it0) // 2, None)
    assert it0[late].mean() > 100, it0[late].mean()
    # (measured: 339 against 431 sweeps a step at tol 1e-6 on this narrow pile of columns; on the
    # wide pour of benches/contacts.py at tol 1e-4, 50 against 107)
    assert it4[late].sum() < 0.85 * it0[late].sum(), (it4[late].sum(), it0[late].sum())


def test_accelerated_pile_settles_to_the_same_state(runs):
    """Both runs settle the spheres into the same resting pile: none sunk into the floor, the
    same mean height (measured: equal to 1e-7 m; the pour is chaotic, so allow a hundredth of a
    radius), the same number of closed contacts to a few."""
    n = 36
    z = [res["q"][-1].reshape(n, 7)[:, 2] for res in runs.values()]
    for zi in z:
        assert zi.min() > R - 1e-3
    assert abs(z[0].mean() - z[1].mean()) < 0.01 * R, (z[0].mean(), z[1].mean())
    closed = [int(res["contact/pile/closed"][-1]) for res in runs.values()]
    assert abs(closed[0] - closed[1]) <= 3 and min(closed) >= n, closed
    # independent of the solver's own residual: at rest the floor and the walls carry the whole
    # weight and no net horizontal force (measured: 35.31575 N against 35.31600 N in both runs)
    weight = n * M * 9.81
    for res in runs.values():
        f = res["contact/pile/force_against"][-1]
        assert abs(f[2] - weight) < 1e-4 * weight and np.hypot(f[0], f[1]) < 1e-4 * weight, (f, weight)


def test_auto_finishes_the_pile_steps_its_newton_cannot():
    """With its default size limit ``Auto`` takes Newton on this pile (at most 255 unknowns),
    whose indeterminate contact sets (rank 208 of 255 in one step) made the regularized Newton
    stop at its cap of 200 iterations in 106 of 1200 steps, residuals up to 7e-3. Newton now
    gives up once its residual has not halved for 30 iterations, and Gauss-Seidel from its
    iterate finishes the step (measured over these 0.8 s: 39 steps past 60 iterations, 25 of
    them past 200, median 259; 3 steps of 800 still end above the tolerance after the whole
    sweep budget)."""
    tol = 1e-6
    res = run(ms.Auto(tol=tol), t_end=0.8)
    it = res["solver/iterations"][1:]
    conv = res["solver/converged"][1:].astype(bool)
    assert conv.mean() >= 0.99, (~conv).sum()
    assert res["solver/residual"][1:][conv].max() <= tol
    # the rescue ran: steps past Newton's cap and the first sweeps that converged all the same
    rescued = (it > 200) & conv
    assert rescued.sum() >= 10, rescued.sum()
    # and its forces are physical: nothing sinks into the floor
    z = res["q"][-1].reshape(36, 7)[:, 2]
    assert z.min() > R - 1e-3


@pytest.mark.parametrize("solver, key", [(ms.NSGS(anderson=9), "anderson"), (ms.Auto(nsgs_anderson=20), "nsgs_anderson")])
def test_a_depth_above_eight_is_refused_naming_the_key(solver, key):
    with pytest.raises(SettingsError, match=rf"{key} \(sweeps combined\) must be in 0\.\.=8, got"):
        ms.simulate(pile(4), 0.01, ms.MoreauJean(1e-3, solver=solver), progress=False)


@pytest.mark.parametrize("solver, key", [(ms.NSGS(anderson=2.5), "NSGS.anderson"), (ms.NSGS(max_iter=float("nan")), "NSGS.max_iter"),
                                         (ms.Auto(nsgs_anderson=None), "Auto.nsgs_anderson"), (ms.Lemke(facets="8"), "Lemke.facets"),
                                         (ms.NSGS(max_iter=-1), "NSGS.max_iter"), (ms.Auto(newton_max_unknowns=-3), "Auto.newton_max_unknowns")])
def test_a_count_that_is_not_a_whole_number_is_refused_naming_the_key(solver, key):
    """(int() alone turned 2.5 sweeps combined into 2 without a word; a negative count reached the
    engine, whose message did not name the setting.)"""
    with pytest.raises(SettingsError, match=rf"{key}: expected a whole number >= 0, got"):
        ms.simulate(pile(4), 0.01, ms.MoreauJean(1e-3, solver=solver), progress=False)


@pytest.mark.parametrize("integrator, key", [(ms.MoreauJean(1e-3, solver=ms.Auto(tol=float("nan"))), "Auto.tol"),
                                             (ms.MoreauJean(1e-3, solver=ms.NSGS(relaxation=float("inf"))), "NSGS.relaxation"),
                                             (ms.MoreauJean(1e-3, solver=ms.Newton(regularization="1e-4")), "Newton.regularization")])
def test_a_setting_that_is_not_a_finite_number_is_refused_naming_the_key(integrator, key):
    """(A NaN tolerance reached the engine's settings as a value it could not read: the error
    named the key but said only 'expected value'.)"""
    with pytest.raises(SettingsError, match=rf"{key}: expected a finite number, got"):
        ms.simulate(pile(4), 0.01, integrator, progress=False)
