"""Reaction forces at the cuts (section 2.1.2): the wrench the parent exerts on the child through a
joint, at the joint origin, in child-joint-frame components, checked against Newton-Euler by hand."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms

G = 9.81


def physical_pendulum(mass=2.0, length=0.8, q0=-0.3, u0=2.0, spring=None):
    m = ms.Model("pendulum", gravity=(0.0, -G, 0.0))
    rod = m.add_body("rod", mass, ms.inertia.cylinder(mass, 0.01, length), com=(length / 2, 0.0, 0.0))
    m.add_joint(ms.joints.Revolute("hinge", m.ground, rod, axis=(0, 0, 1), q0=q0, u0=u0, spring=spring))
    return m


def test_pendulum_pivot_force_is_mass_times_centripetal_and_tangential_acceleration_minus_weight():
    mass, length = 2.0, 0.8
    res = ms.simulate(physical_pendulum(mass, length), 2.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01)
    th, w, al = res["joint/hinge/q"], res["joint/hinge/u"], res["joint/hinge/udot"]
    f = res["joint/hinge/reaction_force"]
    a = length / 2
    # joint frame turns with the rod: x radial (outwards), y tangential; F = m a_c - m g
    radial = mass * (-a * w**2) + mass * G * np.sin(th)
    tangential = mass * (a * al) + mass * G * np.cos(th)
    np.testing.assert_allclose(f[:, 0], radial, rtol=0, atol=1e-10)
    np.testing.assert_allclose(f[:, 1], tangential, rtol=0, atol=1e-10)
    np.testing.assert_allclose(f[:, 2], 0.0, atol=1e-12)
    # a frictionless hinge transmits no moment about its axis; the others vanish in the plane
    np.testing.assert_allclose(res["joint/hinge/reaction_torque"], 0.0, atol=1e-10)
    assert res.unit("joint/hinge/reaction_force") == "N"
    assert res.unit("joint/hinge/reaction_torque") == "N m"


def test_joint_spring_torque_appears_as_axial_reaction_moment():
    k, q_free = 15.0, 0.2
    res = ms.simulate(physical_pendulum(spring=ms.joints.JointSpring(k=k, q_free=q_free)), 1.0,
                      ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.05)
    # the spring's moment on the child is -k (q - q_free) about the axis
    np.testing.assert_allclose(res["joint/hinge/reaction_torque"][:, 2], -k * (res["joint/hinge/q"] - q_free),
                               rtol=0, atol=1e-9)


def test_fixed_body_hanging_on_a_chain_carries_its_weight():
    # ground -> revolute (held still by a stiff spring at its free angle) -> fixed tip mass
    m = ms.Model("hanger", gravity=(0.0, 0.0, -G))
    arm = m.add_body("arm", 1.5, [0.01, 0.02, 0.02], com=(0.25, 0.0, 0.0))
    tip = m.add_body("tip", 0.7, [0.001, 0.001, 0.001])
    m.add_joint(ms.joints.Prismatic("lift", m.ground, arm, axis=(0, 0, 1),
                                    spring=ms.joints.JointSpring(k=1e3, q_free=0.0)))
    m.add_joint(ms.joints.Fixed("weld", arm, tip, parent_frame=ms.Frame(position=(0.5, 0.0, 0.0))))
    # static equilibrium of the spring: q = -(m_total g)/k, start there at rest
    q_eq = -(1.5 + 0.7) * G / 1e3
    res = ms.simulate(m, 0.1, ms.RK4(1e-3), q0={"lift": q_eq})
    np.testing.assert_allclose(res["joint/lift/q"], q_eq, atol=1e-12)
    # the weld holds the tip's weight (+z force on the tip) ...
    np.testing.assert_allclose(res["joint/weld/reaction_force"], np.tile([0.0, 0.0, 0.7 * G], (len(res.t), 1)),
                               atol=1e-10)
    # ... and the slider holds both, through its spring along z and its bearings for the moment
    f = res["joint/lift/reaction_force"]
    np.testing.assert_allclose(f[:, 2], (1.5 + 0.7) * G, atol=1e-9)
    # weights (0, 0, -m g) at x = 0.25 and 0.5: (x, 0, 0) x (0, 0, -m g) = (0, +x m g, 0); the
    # bearing's moment cancels it
    moment_of_weights_y = 1.5 * G * 0.25 + 0.7 * G * 0.5
    np.testing.assert_allclose(res["joint/lift/reaction_torque"][:, 1], -moment_of_weights_y, atol=1e-9)


def test_free_body_in_free_space_has_no_reaction():
    m = ms.Model("free")
    b = m.add_body("b", 2.0, [1.0, 2.0, 3.0])
    m.add_joint(ms.joints.Free("f", m.ground, b, u0=[1.0, 0.0, 0.0, 0.3, 2.0, 0.1]))
    res = ms.simulate(m, 1.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.1)
    np.testing.assert_allclose(res["joint/f/reaction_force"], 0.0, atol=1e-10)
    np.testing.assert_allclose(res["joint/f/reaction_torque"], 0.0, atol=1e-10)


def test_reactions_are_listed_saved_and_loaded(tmp_path):
    res = ms.simulate(physical_pendulum(), 0.2, ms.RK4(1e-3), output_dt=0.01)
    assert "joint/hinge/reaction_force" in res.names()
    assert "joint/hinge/reaction_force" in res
    path = res.save(tmp_path / "r.h5")
    back = ms.load(path)
    np.testing.assert_array_equal(back["joint/hinge/reaction_force"], res["joint/hinge/reaction_force"])
    assert back.unit("joint/hinge/reaction_torque") == "N m"


def test_forward_dynamics_can_write_into_a_given_array():
    m = physical_pendulum()
    q, u = m.q0(), m.u0()
    out = np.empty(m.nu)
    res = ms.dynamics.forward_dynamics(m, q, u, out=out)
    assert res is out
    np.testing.assert_array_equal(out, ms.dynamics.forward_dynamics(m, q, u))
    with pytest.raises(ms.SettingsError):
        ms.dynamics.forward_dynamics(m, q, u, out=np.empty(3))
