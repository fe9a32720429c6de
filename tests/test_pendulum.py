"""Simple and physical pendulum on a revolute joint against closed-form periods.

A rigid body of mass m hangs on a hinge; its centre of mass is at distance a from the hinge axis
and its moment of inertia about that axis is I_O = I_C + m a^2 (Steiner). With the deflection
theta from the hanging position, T + V = E0 (eq. 2.181) gives

    I_O theta'' = -m g a sin(theta),    omega0^2 = m g a / I_O,

whose period for an amplitude theta0 is the complete elliptic integral of the first kind

    T(theta0) = 4 K(k^2) / omega0,  k = sin(theta0 / 2)    (scipy.special.ellipk takes m = k^2),

which tends to 2 pi / omega0 = 2 pi sqrt(I_O / (m g a)) for small amplitudes (2 pi sqrt(l / g) for
a point mass). The period is measured two ways: the state after exactly one closed-form period
must be the initial state again, and successive upward zero crossings of theta (found from the
recorded samples with cubic Hermite interpolation, which uses q and u = q') must be one period
apart.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipk

import mechsys as ms

G = 9.81
TIGHT = ms.DOPRI5(rtol=1e-12, atol=1e-12)

# Two placements of the same physical pendulum: the body's com direction is perpendicular to the
# hinge axis and to gravity, so that in both the coordinate is q = theta - pi/2 (q = 0 horizontal).
GEOMETRIES = {
    # hinge about z, gravity along -y, com on the body x axis
    "z-hinge": dict(axis=(0.0, 0.0, 1.0), gravity=(0.0, -G, 0.0), direction=np.array([1.0, 0.0, 0.0])),
    # hinge about x, gravity along -z, com on the body y axis
    "x-hinge": dict(axis=(1.0, 0.0, 0.0), gravity=(0.0, 0.0, -G), direction=np.array([0.0, 1.0, 0.0])),
}


def rod_pendulum(geometry: str = "z-hinge", m: float = 1.3, length: float = 0.8):
    """A homogeneous slender rod hinged at one end; returns (model, I_O, m g a)."""
    geo = GEOMETRIES[geometry]
    a = 0.5 * length
    model = ms.Model("rod-pendulum", gravity=geo["gravity"])
    axis_name = "x" if geo["direction"][0] else "y"
    rod = model.add_body("rod", mass=m, inertia=ms.inertia.rod(m, length, axis=axis_name), com=a * geo["direction"])
    model.add_joint(ms.joints.Revolute("hinge", parent=model.ground, child=rod, axis=geo["axis"]))
    i_o = m * length**2 / 12.0 + m * a * a  # Steiner about the hinge; the rod's axial moment plays no role
    return model, i_o, m * G * a


def point_pendulum(m: float = 0.5, length: float = 1.2, radius: float = 1e-3):
    """A tiny sphere on a massless arm: the mathematical pendulum (I_C / (m l^2) ~ 3e-7)."""
    model = ms.Model("point-pendulum", gravity=(0.0, -G, 0.0))
    bob = model.add_body("bob", mass=m, inertia=ms.inertia.sphere(m, radius), com=(length, 0.0, 0.0))
    model.add_joint(ms.joints.Revolute("hinge", parent=model.ground, child=bob, axis=(0.0, 0.0, 1.0)))
    return model


def exact_period(theta0: float, i_o: float, mga: float) -> float:
    return 4.0 * ellipk(np.sin(0.5 * theta0) ** 2) / np.sqrt(mga / i_o)


def upward_zero_crossings(t: np.ndarray, x: np.ndarray, xdot: np.ndarray) -> np.ndarray:
    """Times where x crosses zero upwards, from the cubic Hermite interpolant of (x, x')."""
    roots = []
    for i in np.nonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))[0]:
        h = t[i + 1] - t[i]

        def p(s, i=i, h=h):
            s2, s3 = s * s, s * s * s
            return (
                (2 * s3 - 3 * s2 + 1) * x[i]
                + (s3 - 2 * s2 + s) * h * xdot[i]
                + (-2 * s3 + 3 * s2) * x[i + 1]
                + (s3 - s2) * h * xdot[i + 1]
            )

        roots.append(t[i] + h * brentq(p, 0.0, 1.0, xtol=1e-15, rtol=1e-15))
    return np.array(roots)


@pytest.mark.parametrize("geometry", list(GEOMETRIES))
def test_small_amplitude_period_of_physical_pendulum(geometry):
    model, i_o, mga = rod_pendulum(geometry)
    t_lin = 2.0 * np.pi * np.sqrt(i_o / mga)
    theta0 = 0.01  # finite-amplitude correction theta0^2/16 ~ 6e-6, far below the 1e-4 asked
    res = ms.simulate(model, 3.2 * t_lin, TIGHT, output_dt=t_lin / 400, q0={"hinge": -0.5 * np.pi + theta0})
    theta = res["joint/hinge/q"] + 0.5 * np.pi
    crossings = upward_zero_crossings(res.t, theta, res["joint/hinge/u"])
    assert len(crossings) >= 3
    periods = np.diff(crossings)
    assert np.max(np.abs(periods / t_lin - 1.0)) < 1e-4


def test_small_amplitude_period_of_point_pendulum():
    length = 1.2
    model = point_pendulum(length=length)
    t_lin = 2.0 * np.pi * np.sqrt(length / G)
    res = ms.simulate(model, 2.5 * t_lin, TIGHT, output_dt=t_lin / 400, q0={"hinge": -0.5 * np.pi + 0.01})
    crossings = upward_zero_crossings(res.t, res["joint/hinge/q"] + 0.5 * np.pi, res["joint/hinge/u"])
    assert len(crossings) >= 2
    assert abs((crossings[1] - crossings[0]) / t_lin - 1.0) < 1e-4


@pytest.mark.parametrize("theta0", [0.5, 1.5, 2.5, 3.0])
def test_large_amplitude_state_after_one_elliptic_period(theta0):
    """After exactly T(theta0) the pendulum is back at rest at its start; the velocity left over
    measures the period error: u(T) = -u'(T) dT with u'(T) = -omega0^2 sin(theta0)."""
    model, i_o, mga = rod_pendulum()
    period = exact_period(theta0, i_o, mga)
    q0 = -0.5 * np.pi + theta0
    res = ms.simulate(model, period, TIGHT, output_dt=period / 4, q0={"hinge": q0})
    assert res.t[-1] == pytest.approx(period, rel=1e-15)
    q_end, u_end = res["joint/hinge/q"][-1], res["joint/hinge/u"][-1]
    udot_end = -(mga / i_o) * np.sin(theta0)
    period_error = u_end / udot_end  # time by which the true turning point differs from T
    assert abs(period_error) / period < 1e-8
    # the turning point is flat, so q(T) - q0 is second order in the period error
    assert abs(q_end - q0) < 1e-8


@pytest.mark.parametrize("theta0", [1.0, 2.8])
def test_large_amplitude_period_from_zero_crossings(theta0):
    model, i_o, mga = rod_pendulum("x-hinge")
    period = exact_period(theta0, i_o, mga)
    res = ms.simulate(model, 3.3 * period, TIGHT, output_dt=period / 2000, q0={"hinge": -0.5 * np.pi + theta0})
    theta = res["joint/hinge/q"] + 0.5 * np.pi
    crossings = upward_zero_crossings(res.t, theta, res["joint/hinge/u"])
    assert len(crossings) == 3
    # crossings of a pendulum released at rest from +theta0 come at (k + 3/4) T
    np.testing.assert_allclose(crossings, (np.arange(3) + 0.75) * period, rtol=1e-8, atol=0)
    np.testing.assert_allclose(np.diff(crossings), period, rtol=1e-8)


@pytest.mark.parametrize("theta0", [0.3, 2.5])
def test_energy_is_conserved(theta0):
    model, i_o, mga = rod_pendulum()
    period = exact_period(theta0, i_o, mga)
    res = ms.simulate(model, 4 * period, TIGHT, output_dt=period / 50, q0={"hinge": -0.5 * np.pi + theta0})
    e0 = -mga * np.cos(theta0)  # V = m g y_c with y_c = -a cos(theta); at rest T = 0
    assert res["energy/total"][0] == pytest.approx(e0, rel=1e-14, abs=1e-14 * mga)
    assert np.max(np.abs(res["energy/total"] - e0)) < 1e-10 * mga
    # the two parts exchange energy: kinetic from the angle alone, 1/2 I_O u^2
    theta = res["joint/hinge/q"] + 0.5 * np.pi
    np.testing.assert_allclose(res["energy/kinetic"], mga * (np.cos(theta) - np.cos(theta0)), atol=1e-10 * mga)
    np.testing.assert_allclose(res["energy/kinetic"], 0.5 * i_o * res["joint/hinge/u"] ** 2, rtol=1e-12, atol=1e-14)


def test_rk4_converges_with_fourth_order():
    """The error of RK4 after one exact period falls by 2^4 per halving of the step.

    At the turning point the angle is flat in time, so the phase error of the scheme shows in
    the velocity u(T) (order 4) while q(T) - q0 is of higher order; u(T) is the measure."""
    theta0 = 0.5
    model, i_o, mga = rod_pendulum()
    period = exact_period(theta0, i_o, mga)
    q0 = -0.5 * np.pi + theta0
    errors = []
    for n_steps in (40, 80, 160, 320):
        dt = period / n_steps
        res = ms.simulate(model, period, ms.RK4(dt=dt), output_dt=period, q0={"hinge": q0})
        assert len(res.t) == 2 and res.t[-1] == pytest.approx(period, rel=1e-12)
        errors.append(abs(res["joint/hinge/u"][-1]))
        assert abs(res["joint/hinge/q"][-1] - q0) < errors[-1]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 4.0) < 0.1), (errors, orders)
    # and the step of 1/320 of a period is accurate to ~1e-8 relative to the peak speed
    u_peak = np.sqrt(2.0 * mga * (1.0 - np.cos(theta0)) / i_o)
    assert errors[-1] < 1e-7 * u_peak
