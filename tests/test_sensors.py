"""Sensors (issue 13, part 3): marker position, velocity, acceleration and orientation, body and
system centre of mass, body angular acceleration, against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms


def spinning(omega=3.0, g=0.0, com=(0.0, 0.0, 0.0)):
    m = ms.Model("spin", gravity=(0, 0, -g))
    b = m.add_body("plate", 2.0, [0.1, 0.1, 0.2], com=com)
    b.add_marker("edge", (0.3, 0.1, 0.0), cardan=(0.0, 0.0, 0.4))
    m.add_joint(ms.joints.Free("float", m.ground, b, q0=[0, 0, 1, 1, 0, 0, 0], u0=[0, 0, 0, 0, 0, omega]))
    return m


def test_marker_on_a_spinning_body_follows_the_circle():
    # body turning at omega about z (constant: a principal axis, no torque): a marker at r moves on
    # a circle with velocity omega x r and the centripetal acceleration -omega^2 r_perp
    om = 3.0
    res = ms.simulate(spinning(om), 2.0, ms.DOPRI5(rtol=1e-12, atol=1e-14), output_dt=0.01)
    t = res.t
    r = np.hypot(0.3, 0.1)
    phase = np.arctan2(0.1, 0.3) + om * t
    x = res["marker/plate/edge/position"]
    np.testing.assert_allclose(x, np.column_stack([r * np.cos(phase), r * np.sin(phase), np.ones_like(t)]), atol=1e-10)
    np.testing.assert_allclose(res["marker/plate/edge/velocity"],
                               np.column_stack([-om * r * np.sin(phase), om * r * np.cos(phase), 0 * t]), atol=1e-9)
    np.testing.assert_allclose(res["marker/plate/edge/acceleration"],
                               np.column_stack([-om**2 * r * np.cos(phase), -om**2 * r * np.sin(phase), 0 * t]), atol=1e-8)
    # its orientation: the body's turned by the marker's own 0.4 rad about z
    ang = 2 * np.arctan2(res["marker/plate/edge/orientation"][:, 3], res["marker/plate/edge/orientation"][:, 0])
    np.testing.assert_allclose(np.unwrap(ang), 0.4 + om * t, atol=1e-10)
    assert res.columns("marker/plate/edge/orientation") == ["w", "x", "y", "z"]
    assert res.unit("marker/plate/edge/acceleration") == "m/s^2" and res.columns("marker/plate/edge/velocity") == ["x", "y", "z"]


def test_centre_of_mass_in_free_fall_and_angular_acceleration():
    res = ms.simulate(spinning(3.0, g=9.81, com=(0.05, 0.0, 0.0)), 0.5, ms.DOPRI5(rtol=1e-12, atol=1e-14), output_dt=0.01)
    # the system's centre of mass falls at g whatever the spin
    np.testing.assert_allclose(res["com/acceleration"], np.tile([0, 0, -9.81], (len(res.t), 1)), atol=1e-8)
    np.testing.assert_allclose(res["com/position"][:, 2], 1.0 - 0.5 * 9.81 * res.t**2, atol=1e-10)
    # the body spins about its centre of mass (0.05 m off the frame origin, which starts at rest):
    # the centre of mass drifts at w x r_com = 0.15 m/s along y while the origin circles it
    np.testing.assert_allclose(res["body/plate/com_position"][:, :2],
                               np.column_stack([0.05 + 0 * res.t, 0.15 * res.t]), atol=1e-9)
    origin = res["body/plate/position"][:, :2] - res["body/plate/com_position"][:, :2]
    np.testing.assert_allclose(np.hypot(origin[:, 0], origin[:, 1]), 0.05, atol=1e-10)
    # torque-free spin about a principal axis: no angular acceleration
    assert np.abs(res["body/plate/angular_acceleration"]).max() < 1e-9


def test_angular_acceleration_of_a_pendulum():
    g, l = 9.81, 0.5
    m = ms.Model("pend", gravity=(0, 0, -g))
    b = m.add_body("bob", 1.0, [0, 0, 0], com=(0, 0, -l))
    b.add_marker("tip", (0, 0, -l))
    m.add_joint(ms.joints.Revolute("hinge", m.ground, b, axis=(1, 0, 0), q0=1.0))
    res = ms.simulate(m, 1.0, ms.DOPRI5(rtol=1e-12, atol=1e-14), output_dt=0.01)
    th = res["joint/hinge/q"]
    # theta'' = -(g / l) sin(theta) about x
    np.testing.assert_allclose(res["body/bob/angular_acceleration"][:, 0], -(g / l) * np.sin(th), atol=1e-9)
    # the tip (the bob itself): its acceleration is gravity plus the rod's pull, along the rod
    acc = res["marker/bob/tip/acceleration"]
    rod = res["marker/bob/tip/position"] / l
    tangential = acc - np.sum(acc * rod, axis=1)[:, None] * rod
    np.testing.assert_allclose(tangential, np.array([0, 0, -g]) - np.sum(np.array([0, 0, -g]) * rod, axis=1)[:, None] * rod,
                               atol=1e-8)


def test_sensor_signals_are_saved(tmp_path):
    res = ms.simulate(spinning(), 0.1, ms.RK4(dt=1e-3), output_dt=0.01)
    back = ms.Results.load(res.save(tmp_path / "s.h5"))
    np.testing.assert_array_equal(back["marker/plate/edge/position"], res["marker/plate/edge/position"])
    assert back.columns("com/velocity") == ["x", "y", "z"]


def test_loads_are_recorded_as_they_are_applied():
    # a motor torque (JointForce), a controller (PythonForce) and a body force, each as a signal
    m = ms.Model("loads", gravity=(0, 0, 0))
    wheel = m.add_body("wheel", 2.0, [0.1, 0.1, 0.2])
    cart = m.add_body("cart", 3.0, [1, 1, 1])
    m.add_joint(ms.joints.Revolute("spin", m.ground, wheel, axis=(0, 0, 1)))
    m.add_joint(ms.joints.Prismatic("slide", m.ground, cart, axis=(1, 0, 0)))
    m.add_force(ms.forces.JointForce("motor", "spin", 0.5, function=ms.functions.Ramp(slope=2.0)))
    m.add_force(ms.forces.PythonForce("pd", lambda t, q, u: np.array([0.0, -4.0 * q[1] - 1.0 * u[1]])))
    m.add_force(ms.forces.BodyForce("push", "cart", force=(1.5, 0.0, 0.0), torque=(0.0, 0.0, 0.2)))
    res = ms.simulate(m, 1.0, ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=0.01)
    np.testing.assert_allclose(res["force/motor/force"], 0.5 * 2.0 * res.t, atol=1e-12)
    assert res.unit("force/motor/force") == "N m"
    pd = res["force/pd/force"]
    assert res.columns("force/pd/force") == ["spin.rate", "slide.rate"]
    assert res.column_units("force/pd/force") == ["N m", "N"]
    x, v = res["joint/slide/q"], res["joint/slide/u"]
    np.testing.assert_allclose(pd[:, 1], -4.0 * x - v, atol=1e-10)
    np.testing.assert_allclose(pd[:, 0], 0.0, atol=0)
    np.testing.assert_allclose(res["force/push/force"], np.tile([1.5, 0, 0], (len(res.t), 1)), atol=0)
    np.testing.assert_allclose(res["force/push/torque"], np.tile([0, 0, 0.2], (len(res.t), 1)), atol=0)
    # and they are what moves the bodies: m x'' = 1.5 + pd (the cart), I w' = t (the wheel, 0.5 * 2 t)
    np.testing.assert_allclose(3.0 * res["joint/slide/udot"], 1.5 + pd[:, 1], atol=1e-8)
    np.testing.assert_allclose(0.2 * res["joint/spin/udot"], res["force/motor/force"], atol=1e-9)


@pytest.mark.parametrize("integrator", [ms.MoreauJean(dt=1e-3), ms.EventDriven()], ids=["moreau_jean", "event_driven"])
def test_contact_point_and_normal(integrator):
    # a ball dropped on a tilted plane (normal (0, sin a, cos a), friction holding it): the contact
    # point lies one radius from the centre, on the plane, and the normal is the plane's
    a, r = 0.3, 0.1
    m = ms.Model("ball", gravity=(0, 0, -9.81))
    ball = m.add_body("ball", 1.0, [4e-3] * 3)
    n = np.array([0.0, np.sin(a), np.cos(a)])
    m.add_joint(ms.joints.Free("float", m.ground, ball, q0=[*(n * (r + 0.02)), 1, 0, 0, 0]))
    plane = ms.contours.Plane(normal=tuple(n))
    m.add_contact(ms.contacts.Contact("floor", m.ground.contour(plane), ball.contour(ms.contours.Sphere(radius=r)),
                                      friction=ms.laws.Coulomb(mu=0.8)))
    res = ms.simulate(m, 0.5, integrator, output_dt=0.01)
    centre = res["body/ball/position"]
    normal = res["contact/floor/normal"]
    # from the ball (the second contour) towards the plane (the first): against the plane's normal
    np.testing.assert_allclose(normal, np.tile(-n, (len(res.t), 1)), atol=1e-12)
    after = res.t > 0.2
    point = res["contact/floor/point"]
    # on the plane's surface, one radius plus the gap (a velocity-level scheme's small drift) from
    # the centre
    gap = res["contact/floor/g_n"][after]
    np.testing.assert_allclose(np.linalg.norm(point[after] - centre[after], axis=1), r + gap, atol=1e-12)
    np.testing.assert_allclose(point[after] @ n, 0.0, atol=1e-12)
    assert np.abs(gap).max() < 2e-4
    assert res.unit("contact/floor/point") == "m" and res.columns("contact/floor/point") == ["x", "y", "z"]
