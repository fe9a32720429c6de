"""Anderson acceleration that pauses at a stall instead of stopping for the rest of the solve.

The state in ``data/pile1000_settling.npz`` is the 1000-sphere pour of ``benches/contacts.py``
(start seed 0, ``Auto(tol=1e-4)``) at t = 0.8 s, when the pile settles and a step's problem
(about 2000 contact points) takes thousands of sweeps. Anderson's guard turns the acceleration
off when the smallest sweep change has not fallen for 128 sweeps. Off for the rest of the step,
the three steps from this state took 3738, 3650 and 4034 sweeps; paused for 32 plain sweeps
(``solver::anderson::RETRY``) and then started again with a fresh history, 1401, 2015 and 1104."""

import pathlib
import warnings

import numpy as np
import pytest

import mechsys as ms
from piles import R, box_pile

HALF = 0.55
STATE = pathlib.Path(__file__).parent / "data" / "pile1000_settling.npz"
TOL = 1e-4


@pytest.fixture(scope="module")
def model():
    # the benchmark's pile of 1000 (its initial positions are replaced by the saved state)
    return box_pile([(0.0, 0.0, R + 2.2 * R * i) for i in range(1000)], HALF, name="pile-1000")


def steps(model, solver, n=3):
    d = np.load(STATE)
    t0 = float(d["t"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an unconverged step warns; the report is checked
        res = ms.simulate(model, t0 + n * 1e-3, ms.MoreauJean(1e-3, solver=solver), q0=d["q"], u0=d["u"], t0=t0,
                          output_dt=1e-3, progress=False, sensors=["solver/*"])
    assert res.t[-1] == pytest.approx(t0 + n * 1e-3)
    return res


def test_the_state_holds_a_settling_pile(model):
    d = np.load(STATE)
    z = d["q"].reshape(1000, 7)[:, 2]
    assert z.min() == pytest.approx(R, abs=2e-3)  # spheres on the floor
    assert 0.3 < z.mean() < 0.5
    # still moving (velocities in m/s and rad/s): the slowest settling phase of the pour, not a
    # pile at rest
    assert 0.05 < np.abs(d["u"]).max() < 20.0


@pytest.mark.parametrize("solver", [ms.Auto(tol=TOL), ms.NSGS(tol=TOL, max_iter=10_000, anderson=4)],
                         ids=["auto", "nsgs-anderson"])
def test_accelerated_sweeps_converge_on_the_settling_pile(model, solver):
    res = steps(model, solver)
    it = res["solver/iterations"][1:]
    assert res["solver/converged"][1:].all(), it
    assert (res["solver/residual"][1:] <= TOL).all()
    assert (res["solver/contacts"][1:] > 1500).all()  # the whole pile's problem, every step
    # paused and resumed: 4520 sweeps for the three steps (stopped for the rest of each step
    # instead: 11 422)
    assert it.sum() < 7000, it
