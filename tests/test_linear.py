"""Linearization into M, D, G, K, N (issue 5, first part) against closed forms: a spring-mass
chain, the pendulum upright and hanging, Rayleigh damping, the one-degree-of-freedom response."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import mechsys as ms

G = 9.81


def chain(m=2.0, k=300.0, d=0.0):
    mod = ms.Model("chain", gravity=(0.0, 0.0, 0.0))
    bodies = []
    for i in range(3):
        b = mod.add_body(f"m{i}", m, [1e-3] * 3)
        mod.add_joint(ms.joints.Prismatic(f"x{i}", mod.ground, b, axis=(1, 0, 0), parent_frame=(i + 1.0, 0, 0)))
        bodies.append(b)
    ends = [(mod.ground, (0, 0, 0), bodies[0], (0, 0, 0)), (bodies[0], (0, 0, 0), bodies[1], (0, 0, 0)),
            (bodies[1], (0, 0, 0), bodies[2], (0, 0, 0)), (bodies[2], (0, 0, 0), mod.ground, (4, 0, 0))]
    for k_, (b1, p1, b2, p2) in enumerate(ends):
        mod.add_force(ms.forces.SpringDamper(f"s{k_}", b1, b2, point1=p1, point2=p2, k=k, d=d, l0=1.0))
    return mod


def pendulum(theta=0.0):
    mod = ms.Model("pendulum", gravity=(0.0, -G, 0.0))
    b = mod.add_body("bob", 1.5, [1e-9] * 3)
    mod.add_joint(ms.joints.Revolute("pin", mod.ground, b, axis=(0, 0, 1), child_frame=(0, 0.8, 0), q0=theta))
    return mod


def test_chain_frequencies_to_1e10():
    m, k = 2.0, 300.0
    lin = ms.linear.linearize(chain(m, k))
    modes = lin.modes()
    exact = np.sqrt(k / m * (2 - 2 * np.cos(np.pi * np.arange(1, 4) / 4))) / (2 * np.pi)
    np.testing.assert_allclose(modes.natural_frequency, exact, rtol=1e-10)
    assert modes.stable and lin.names == ["x0", "x1", "x2"]
    # the middle mode moves the outer masses against each other, the middle one not at all
    s = modes.shapes[:, 1].real
    assert abs(s[1]) < 1e-9 and abs(s[0] + s[2]) < 1e-9


def test_pendulum_and_the_inverted_one():
    lin = ms.linear.linearize(pendulum())
    np.testing.assert_allclose(lin.modes().natural_frequency, np.sqrt(G / 0.8) / (2 * np.pi), rtol=1e-9)
    up = ms.linear.linearize(pendulum(np.pi)).modes()
    assert not up.stable and len(up.unstable) == 1
    np.testing.assert_allclose(up.eigenvalues[up.unstable[0]].real, np.sqrt(G / 0.8), rtol=1e-7)
    with pytest.warns(UserWarning, match="not an equilibrium"):
        lin = ms.linear.linearize(pendulum(0.3))
    np.testing.assert_allclose(abs(lin.residual[0]), 1.5 * G * 0.8 * np.sin(0.3), rtol=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ms.linear.linearize(pendulum(0.3), operating_point=True)


def test_rayleigh_fit_reproduces_its_two_damping_ratios():
    lin = ms.linear.linearize(chain())
    f = lin.modes().natural_frequency
    damped = lin.rayleigh(0.02, f[0], 0.05, f[2]).modes()
    np.testing.assert_allclose(damped.damping_ratio[[0, 2]], [0.02, 0.05], rtol=1e-10)
    for bad in (dict(zeta1=0.02, f1=0.0, zeta2=0.05, f2=1.0), dict(zeta1=0.02, f1=1.0, zeta2=0.05, f2=-2.0)):
        with pytest.raises(ms.SettingsError, match="f1|f2"):
            ms.linear.rayleigh_coefficients(**bad)


def test_damper_and_the_one_degree_of_freedom_response():
    """One mass between two spring-dampers (the others locked by stiff springs is not needed:
    the chain's D = (d/k) K); the FRF of a one-dof oscillator equals eq. 2.209."""
    k, d = 300.0, 3.0
    lin = ms.linear.linearize(chain(2.0, k, d))
    np.testing.assert_allclose(lin.D, lin.K * d / k, atol=1e-8)
    m1 = ms.Model("sdof", gravity=(0.0, 0.0, 0.0))
    b = m1.add_body("m", 2.0, [1e-3] * 3)
    m1.add_joint(ms.joints.Prismatic("x", m1.ground, b, axis=(1, 0, 0), spring=ms.joints.JointSpring(k=k),
                                     damper=ms.joints.JointDamper(d=d)))
    lin1 = ms.linear.linearize(m1)
    f = np.linspace(0.5, 4.0, 8)
    h = lin1.frf(f)[:, 0, 0]
    w0, _ = ms.linear.sdof_frequencies(2.0, d, k)
    r, psi = ms.linear.sdof_response(1.0 / 2.0, w0, d / 4.0, 2 * np.pi * f)
    np.testing.assert_allclose(np.abs(h), r, rtol=1e-9)
    np.testing.assert_allclose(-np.angle(h), psi, atol=1e-9)
    assert abs(lin1.dissipation([2.0]) - 0.5 * d * 4.0) < 1e-9
    with pytest.raises(ms.SettingsError, match="frequencies"):
        lin1.frf([0.0, 1.0])
