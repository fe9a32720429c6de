"""Compliant contacts in the event-driven scheme (issue 19, item 2): a model mixing a compliant
contact (forces in the smooth phases, onset and release located like in the smooth schemes) with
a rigid one (impacts and transitions), against an independent SciPy integration and the closed
form of the bouncing ball."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mechsys as ms

R, M, G = 0.05, 0.2, 9.81
MAT = ms.Material(E=1e7, nu=0.3, density=1000.0)
E_STAR = 1 / (2 * (1 - 0.3**2) / 1e7)
K = 4 / 3 * E_STAR * math.sqrt(R)
ALPHA, KS = 0.4, 40.0
EPS, H0 = 0.5, 0.25


def mixed() -> ms.Model:
    """A soft ball held by a spring towards z = 0 bounces on the floor through a damped Hertz
    contact, lower and lower; beside it a hard ball falls 0.25 m onto the floor with Newton's law."""
    m = ms.Model("mixed", gravity=(0, 0, -G))
    a = m.add_body("soft", M, ms.inertia.sphere(M, R))
    m.add_joint(ms.joints.Prismatic("za", m.ground, a, axis=(0, 0, 1), q0=0.15, spring=ms.joints.JointSpring(k=KS)))
    b = m.add_body("hard", M, ms.inertia.sphere(M, R))
    m.add_joint(ms.joints.Prismatic("zb", m.ground, b, axis=(0, 0, 1), q0=R + H0))
    m.add_contact(ms.Contact("soft_floor", a.contour(ms.contours.Sphere(radius=R), material=MAT),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=MAT),
                             normal=ms.laws.Hertz(alpha=ALPHA)))
    m.add_contact(ms.Contact("hard_floor", b.contour(ms.contours.Sphere(radius=R)),
                             m.ground.contour(ms.contours.Plane(point=(1, 0, 0), normal=(0, 0, 1))),
                             impact=ms.laws.Newton(eps=EPS)))
    return m


def scipy_soft(t_out: np.ndarray) -> tuple[np.ndarray, list[float]]:
    """The soft ball alone: m z'' = max(0, K d^1.5 (1 + alpha d')) - k_s z - m g with d = R - z,
    integrated piecewise between the onsets and releases (located by SciPy's events)."""
    def f(t, y):
        z, v = y
        d = R - z
        force = max(0.0, K * d**1.5 * (1 - ALPHA * v)) if d > 0 else 0.0
        return [v, (force - KS * z) / M - G]

    def touch(t, y):
        return y[0] - R
    touch.terminal = True
    t, y, pieces, switches = 0.0, np.array([0.15, 0.0]), [], []
    while t < t_out[-1]:
        s = solve_ivp(f, (t, t_out[-1]), y, method="DOP853", rtol=1e-12, atol=1e-15, events=touch, dense_output=True)
        inside = (t_out >= t) & (t_out <= s.t[-1])
        pieces.append((t_out[inside], s.sol(t_out[inside])[0]))
        t, y = s.t[-1], s.y[:, -1]
        if s.status == 1:
            switches.append(t)
            # on across the switch by a sliver, so the event does not fire again at once
            s = solve_ivp(f, (t, t + 1e-9), y, method="DOP853", rtol=1e-13, atol=1e-16)
            t, y = s.t[-1], s.y[:, -1]
    ts = np.concatenate([p[0] for p in pieces])
    zs = np.concatenate([p[1] for p in pieces])
    _, first = np.unique(ts, return_index=True)
    return np.interp(t_out, ts[first], zs[first]), switches


@pytest.fixture(scope="module")
def run():
    return ms.simulate(mixed(), t_end=1.0, output_dt=0.005, integrator=ms.EventDriven(rtol=1e-11, atol=1e-13),
                       progress=False)


def test_compliant_ball_matches_scipy_beside_rigid_impacts(run):
    ref, switches = scipy_soft(run["t"])
    assert np.abs(run["joint/za/q"] - ref).max() < 1e-8
    # the located onsets and releases are the SciPy ones
    soft = [e["t"] for e in run.events if e["contact"] == "soft_floor"]
    assert len(soft) == len(switches) >= 6
    assert np.abs(np.array(soft) - np.array(switches)).max() < 5e-9
    assert {e["event"] for e in run.events if e["contact"] == "soft_floor"} == {"close", "open"}
    # the bounces shrink (the damped law's restitution grows towards 1 as the approach slows, so
    # the ball goes on bouncing lower and lower)
    top = [run["joint/za/q"][(run["t"] > a) & (run["t"] < b)].max() for a, b in zip(soft[1:-2:2], soft[2::2])]
    assert all(np.diff(top) < 0) and top[-1] < R + 1e-3


def test_rigid_ball_keeps_its_closed_form_impacts(run):
    """Impact k of the hard ball at t1 (1 + 2 e + ... + 2 e^(k-1)), t1 = sqrt(2 h / g), and it rests
    from the accumulation time t1 (1 + e) / (1 - e) on."""
    t1 = math.sqrt(2 * H0 / G)
    hits = [e["t"] for e in run.events if e["contact"] == "hard_floor" and e["event"] == "impact"]
    expected = [t1 * (1 + sum(2 * EPS**j for j in range(1, k + 1))) for k in range(5)]
    assert np.allclose(hits[:5], expected, rtol=1e-9, atol=0)
    rest = t1 * (1 + EPS) / (1 - EPS)
    zb = run["joint/zb/q"][run["t"] > rest + 0.01]
    assert np.abs(zb - R).max() < 1e-9


def test_mixed_energy_balance_closes(run):
    e = run["energy/total"] + run["energy/dissipated"]
    assert np.abs(e - e[0]).max() < 1e-8 * abs(e[0])
    # both kinds took their share: the damped Hertz contact and the impacts
    assert run["contact/soft_floor/energy_dissipated"][-1] > 0.01
    assert run["energy/dissipated_impact"][-1] > 0.1


def test_mixed_model_under_moreau_jean_lands_on_the_event_driven_run(run):
    """The same model under Moreau-Jean at a small step (compliant forces as smooth forces, the
    impacts by the time-stepping scheme): first order in dt."""
    mj = ms.simulate(mixed(), t_end=1.0, output_dt=0.005, integrator=ms.MoreauJean(dt=1e-5), progress=False)
    assert np.abs(mj["joint/za/q"] - run["joint/za/q"]).max() < 1e-4
    assert np.abs(mj["joint/zb/q"] - run["joint/zb/q"]).max() < 2e-3


def test_event_driven_compliant_from_the_command_line(tmp_path):
    """examples/hertz_drop.toml with --integrator event_driven: the first onset falls after the
    free fall of 50 mm."""
    from pathlib import Path
    ex = Path(__file__).resolve().parents[1] / "examples" / "hertz_drop.toml"
    out = tmp_path / "d.h5"
    script = Path(sys.executable).parent / "mechsys"
    text = ex.read_text().replace('integrator = { type = "dopri5", rtol = 1e-9, atol = 1e-13 }',
                                  'integrator = { type = "event_driven", rtol = 1e-9, atol = 1e-13 }')
    f = tmp_path / "drop.toml"
    f.write_text(text)
    r = subprocess.run([str(script), "run", str(f), "--t-end", "0.12", "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    res = ms.load(out)
    close = [e["t"] for e in res.events if e["event"] == "close"]
    assert close[0] == pytest.approx(math.sqrt(2 * 0.05 / 9.81), rel=1e-6)
