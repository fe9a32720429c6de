"""The external loads' work under Moreau-Jean where contact impulses act in the same step.

The scheme moves positions by h (u_k + u_{k+1})/2, so a load's work over a step is
h Q_ext^T (u_k + u_{k+1})/2: for a constant force F on a translating body exactly F times the
body's displacement, and nothing on a body at rest. The force stage's own power, taken at the
velocities before the impulses ((u_k + u_free)/2), had counted work on a body pressed at rest:
0.577 J in 1 s for a 2 kg ball pressed down by twice its weight (F u_free h / 2 every step).
"""

import numpy as np
import pytest

import mechsys as ms

G = 9.81


def balance(res):
    e = (res["energy/kinetic"] + res["energy/potential"] + res["energy/contact_elastic"] + res["energy/dissipated"]
         - res["energy/external_work"])
    return e - e[0]


def pressed_ball(compliance=0.0, mass=2.0, radius=0.1, load=None):
    m = ms.Model("pressed", gravity=(0, 0, -G))
    b = m.add_body("ball", mass, ms.inertia.sphere(mass, radius))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=[0, 0, radius - compliance * 3 * mass * G, 1, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=radius)), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             normal=ms.laws.Signorini(compliance=compliance), friction=ms.laws.Coulomb(0.5)))
    m.add_force(load(b) if load else ms.forces.BodyForce("press", b, force=(0.0, 0.0, -2 * mass * G)))
    m.build()
    return m


@pytest.mark.parametrize("compliance", [0.0, 1e-5], ids=["rigid", "layer"])
def test_a_load_on_a_body_pressed_at_rest_does_no_work(compliance):
    res = ms.simulate(pressed_ball(compliance), 1.0, ms.MoreauJean(1e-3), output_dt=1e-3)
    z = res["body/ball/position"][:, 2]
    assert np.abs(z - z[0]).max() < 1e-12
    assert np.abs(res["energy/external_work"]).max() < 1e-12
    assert np.abs(balance(res)).max() < 1e-12


def test_a_generalized_load_from_python_pressing_at_rest_does_no_work():
    """The callback's generalized forces (here -2 m g on the free joint's vertical velocity)."""
    def load(b):
        def push(t, q, u):
            f = np.zeros(6)
            f[2] = -2 * 2.0 * G
            return f

        return ms.forces.PythonForce("push", push)

    res = ms.simulate(pressed_ball(load=load), 0.2, ms.MoreauJean(1e-3), output_dt=1e-3)
    assert np.abs(res["energy/external_work"]).max() < 1e-12
    assert np.abs(balance(res)).max() < 1e-12


def test_a_block_pushed_along_a_rough_floor_takes_force_times_displacement():
    """A box pushed at its centre by F = 2 mu m g along x slides with a = F/m - mu g: the load's
    work is F (x - x0) and the contact's impulses take mu m g (x - x0), each to round-off (their
    split between friction, -Lambda_T u_T+ per step, and the rest is the scheme's), and
    x - x0 = a t^2/2 at the scheme's first order in h."""
    mass, mu, h = 1.0, 0.4, 1e-3
    m = ms.Model("pushed", gravity=(0, 0, -G))
    b = m.add_body("box", mass, ms.inertia.box(mass, (0.2, 0.2, 0.1)))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=[0, 0, 0.05, 1, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Box(half_extents=(0.1, 0.1, 0.05))),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))), friction=ms.laws.Coulomb(mu)))
    force = 2 * mu * mass * G
    m.add_force(ms.forces.BodyForce("push", b, force=(force, 0.0, 0.0)))
    m.build()
    res = ms.simulate(m, 0.5, ms.MoreauJean(h), output_dt=h)
    dx = res["body/box/position"][:, 0] - res["body/box/position"][0, 0]
    np.testing.assert_allclose(res["energy/external_work"], force * dx, rtol=1e-10, atol=1e-13)
    taken = res["energy/dissipated_friction"] + res["energy/dissipated_impact"]
    np.testing.assert_allclose(taken, mu * mass * G * dx, rtol=1e-9, atol=1e-13)
    a = force / mass - mu * G
    np.testing.assert_allclose(dx[-1], 0.5 * a * 0.5**2, rtol=5e-3)
    assert np.abs(balance(res)).max() < 1e-11


def test_a_joint_force_holding_a_slider_on_its_stop_and_then_pulling_it_off():
    """A slider (prismatic joint along x) held against a wall by a joint force of -5 N does no
    work while it rests there; reversed at t = 0.1 s, the force pulls it off and its work is
    5 N times the slider's travel."""
    mass, radius = 1.0, 0.05
    m = ms.Model("slider", gravity=(0, 0, -G))
    b = m.add_body("slider", mass, ms.inertia.sphere(mass, radius))
    j = m.add_joint(ms.joints.Prismatic("x", m.ground, b, axis=(1, 0, 0)))
    m.add_contact(ms.Contact("stop", b.contour(ms.contours.Sphere(radius=radius)),
                             m.ground.contour(ms.contours.Plane(point=(-radius, 0, 0), normal=(1, 0, 0)))))
    m.add_force(ms.forces.JointForce("drive", j, value=5.0, function=lambda t: -1.0 if t < 0.1 else 1.0))
    m.build()
    res = ms.simulate(m, 0.3, ms.MoreauJean(1e-3), output_dt=1e-3)
    x = res["joint/x/q"]
    rest = res.t <= 0.1
    assert np.abs(x[rest]).max() < 1e-12
    assert np.abs(res["energy/external_work"][rest]).max() < 1e-12
    assert x[-1] > 0.05
    np.testing.assert_allclose(res["energy/external_work"][-1], 5.0 * x[-1], rtol=1e-9)
    assert np.abs(balance(res)).max() < 1e-11
