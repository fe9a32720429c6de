"""The event log ``res.events`` of both contact schemes (issue 12) against closed forms: a ball
dropped on a floor (Newton's law, eps = 0.5), a block sliding to rest and a block pushed by a ramp
force until it breaks away.

Dropped from h0 (point contour: the gap is the height), impact k (k = 1, 2, ...) comes at
t_k = t0 (1 + 2 (eps + ... + eps^(k-1))), t0 = sqrt(2 h0 / g), with the speed
v_k = eps^(k-1) sqrt(2 g h0). Newton's law gives the normal impulse m (1 + eps) v_k, leaves with
eps v_k and takes 1/2 m v_k^2 (1 - eps^2). Over the whole accumulation the impacts take m g h0.
"""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms
from test_event_driven import point_ball
from test_transitions import KDOT, KDOT_OFF_GRID, MU0, ramp_block_2d, t_break

G = 9.81
EPS, H0, M = 0.5, 1.0, 1.0
T0, V0 = np.sqrt(2 * H0 / G), np.sqrt(2 * G * H0)


def impact_times(n):
    return T0 * (1 + 2 * np.concatenate([[0.0], np.cumsum(EPS ** np.arange(1, n))]))


def impact_speeds(n):
    return V0 * EPS ** np.arange(n)


def impacts(res):
    return [e for e in res.events if e["event"] == "impact"]


def test_event_driven_logs_each_impact_with_its_impulse_energy_and_velocities():
    res = ms.simulate(point_ball(EPS, H0), 2.0, ms.EventDriven(), output_dt=1e-2)
    imp = impacts(res)
    n = 12  # down to v = 2e-3 m/s, far above the velocity tolerance
    assert len(imp) >= n
    t_k, v_k = impact_times(n), impact_speeds(n)
    np.testing.assert_allclose([e["t"] for e in imp[:n]], t_k, rtol=1e-12)
    for e, v in zip(imp[:n], v_k):
        assert e["contact"] == "floor" and e["point"] == 0 and e["steps"] == 1
        assert e["impulse_n"] == pytest.approx(M * (1 + EPS) * v, rel=1e-9)
        assert e["impulse_t"] == [0.0, 0.0]
        assert e["energy"] == pytest.approx(0.5 * M * v**2 * (1 - EPS**2), rel=1e-9)
        # generalized velocities of the free joint (v, w): only the vertical one changes
        ub, ua = np.array(e["u_before"]), np.array(e["u_after"])
        assert ub.shape == ua.shape == (6,)
        assert ub[2] == pytest.approx(-v, rel=1e-9) and ua[2] == pytest.approx(EPS * v, rel=1e-9)
        np.testing.assert_array_equal(np.delete(ub, 2), 0.0)
        np.testing.assert_array_equal(np.delete(ua, 2), 0.0)
    # every joule the impacts took is on record: the log's sum is the recorded impact
    # dissipation, which is m g h0
    total = sum(e["energy"] for e in res.events)
    assert abs(total - res["energy/dissipated_impact"][-1]) < 1e-9
    assert abs(total - M * G * H0) < 1e-9


def test_moreau_jean_logs_the_impacts_within_steps_of_the_closed_form():
    """dt = 1e-4. An impact is found in the step that holds it and logged at the step's end, up
    to one step late; the rebound starts from there, so the lags add up: impact k within k steps
    (measured at dt = 1e-4: 0.76, 1.53, 1.91 steps; at 1e-5: 0.64, 1.27, 2.09). The step's
    impulse also carries gravity's m g dt and Newton's law acts on the velocity at the step's
    start (off by up to k g dt): impulse within 2 g dt / v_k relative, energy within twice that."""
    dt = 1e-4
    res = ms.simulate(point_ball(EPS, H0), 2.0, ms.MoreauJean(dt), output_dt=1e-2)
    imp = impacts(res)
    n = 3
    assert len(imp) >= n
    t_k, v_k = impact_times(n), impact_speeds(n)
    for k, (e, t, v) in enumerate(zip(imp[:n], t_k, v_k), start=1):
        assert e["contact"] == "floor" and e["steps"] >= 1
        assert t - 1e-12 <= e["t"] <= t + k * dt, (k, e["t"], t)
        assert abs(e["impulse_n"] / (M * (1 + EPS) * v) - 1) < 2 * G * dt / v, (k, e["impulse_n"])
        assert abs(e["energy"] / (0.5 * M * v**2 * (1 - EPS**2)) - 1) < 4 * G * dt / v, (k, e["energy"])
        ub, ua = np.array(e["u_before"]), np.array(e["u_after"])
        assert abs(ub[2] + v) < k * G * dt
        # Newton's law on the logged velocities, exactly
        assert ua[2] == pytest.approx(-EPS * ub[2], rel=1e-12)
        np.testing.assert_array_equal(np.delete(ua, 2), 0.0)
    # the log holds exactly what the scheme took (its own impulses), and that is m g h0 to O(dt)
    total = sum(e["energy"] for e in res.events)
    assert abs(total - res["energy/dissipated_impact"][-1]) < 1e-9
    assert abs(total - M * G * H0) < 10 * G * dt * V0


def slider(v0=2.0, mu=0.3):
    """A point block sliding on a rough floor: it stops at t = v0 / (mu g) and sticks."""
    m = ms.Model("slider", gravity=(0, -G, 0))
    b = m.add_body("block", 1.0, ms.inertia.sphere(1.0, 0.1))
    m.add_joint(ms.joints.Planar("pl", m.ground, b, u0=[v0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Point()), m.ground.contour(ms.contours.Line(normal=(0, 1, 0))),
                             friction=ms.laws.Coulomb(mu)))
    return m


def later(res, kind):
    return [e for e in res.events if e["event"] == kind and e["t"] > 0.0]


@pytest.mark.parametrize("scheme", ["event_driven", "moreau_jean"])
def test_stick_event_of_a_block_sliding_to_rest(scheme):
    """Event-driven to 1e-9 s; Moreau-Jean (dt = 1e-4) in the step that holds the stop: v falls by
    mu g dt per step, so the first step ending at rest ends within one step after v0 / (mu g)."""
    v0, mu, dt = 2.0, 0.3, 1e-4
    t_stop = v0 / (mu * G)
    integ = ms.EventDriven() if scheme == "event_driven" else ms.MoreauJean(dt)
    res = ms.simulate(slider(v0, mu), 1.0, integ, output_dt=1e-2)
    sticks = later(res, "stick")
    assert len(sticks) == 1 and sticks[0]["contact"] == "floor"
    assert not later(res, "slip") and not later(res, "open")
    if scheme == "event_driven":
        assert abs(sticks[0]["t"] - t_stop) < 1e-9
    else:
        assert t_stop - 1e-12 <= sticks[0]["t"] <= t_stop + dt + 1e-12, (sticks[0]["t"], t_stop)
        assert sticks[0]["steps"] >= 1


@pytest.mark.parametrize("scheme", ["event_driven", "moreau_jean"])
@pytest.mark.parametrize("kdot", [KDOT, KDOT_OFF_GRID], ids=["on_grid", "off_grid"])
def test_slip_event_of_a_ramp_pushed_block(scheme, kdot):
    """Pushed by kdot t, the block breaks away when the push reaches mu0 m g: t_s = mu0 m g / kdot
    (5.886 s on the 1e-4 grid, 6.1957 s between its steps). Event-driven to 1e-9 s. Moreau-Jean
    (dt = 1e-4) takes the step's forces at its midpoint: the first step whose midpoint is past t_s
    slides, and the slip is logged at its end, within (dt/2, 3 dt/2] after t_s (on the grid: one
    step; off it, 6.1959 s: 1.1 steps)."""
    dt = 1e-4
    t_s = t_break(kdot)
    assert t_s == pytest.approx(MU0 * 1.0 * G / kdot, rel=1e-15)
    integ = ms.EventDriven() if scheme == "event_driven" else ms.MoreauJean(dt)
    res = ms.simulate(ramp_block_2d(kdot), t_s + 0.05, integ, output_dt=1e-2)
    slips = later(res, "slip")
    assert len(slips) == 1 and slips[0]["contact"] == "floor"
    assert not later(res, "stick") and not later(res, "open")
    if scheme == "event_driven":
        assert abs(slips[0]["t"] - t_s) < 1e-9
    else:
        assert t_s + 0.5 * dt - 1e-9 <= slips[0]["t"] <= t_s + 1.5 * dt + 1e-9, (slips[0]["t"], t_s)
        assert slips[0]["steps"] >= 1
