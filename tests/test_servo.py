"""Servo actuators (issue 13, part 4) against textbook results: the steady-state error of a
position servo tracking a ramp on a viscously damped load (a type-1 loop: e_ss = c v / K), the
same with a gear (K = n^2 kp), a velocity servo's first-order lag, and a torque limit."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms

M, C = 2.0, 5.0  # load mass (kg) and viscous damping (N s/m)


def slide(servo: ms.forces.Servo) -> ms.Model:
    m = ms.Model("servo", gravity=(0, 0, 0))
    b = m.add_body("load", M, [1, 1, 1])
    m.add_joint(ms.joints.Prismatic("x", m.ground, b, axis=(1, 0, 0), damper=ms.joints.JointDamper(C)))
    m.add_force(servo)
    return m


@pytest.mark.parametrize("gear", [1.0, 3.0])
def test_position_servo_tracks_a_ramp_with_the_textbook_error(gear):
    v, kp = 0.4, 200.0
    # (the transient decays at C / 2M = 1.25 1/s: gone to 1e-8 after 16 s)
    res = ms.simulate(slide(ms.forces.Servo("drive", "x", ms.functions.Ramp(slope=v), kp=kp, gear=gear)), 16.0,
                      ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=0.01)
    err = res["force/drive/deflection"]
    # M x'' + C x' = n^2 kp (v t - x): steady state x' = v, e = C v / (n^2 kp)
    assert err[-1] == pytest.approx(C * v / (gear**2 * kp), rel=1e-6)
    np.testing.assert_allclose(err, v * res.t - res["joint/x/q"], atol=1e-12)
    # the force on the joint is what the law says
    np.testing.assert_allclose(res["force/drive/force"], gear**2 * kp * err, rtol=1e-12)
    assert res.unit("force/drive/force") == "N" and res.unit("force/drive/deflection") == "m"


def test_derivative_action_damps_but_leaves_the_ramp_error():
    v = 0.4
    res = ms.simulate(slide(ms.forces.Servo("drive", "x", ms.functions.Ramp(slope=v), kp=200.0, kd=20.0)), 16.0,
                      ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=0.01)
    # kd acts on e' -> 0: the steady ramp error stays C v / kp; the transient decays at
    # (C + kd) / 2M instead of C / 2M
    e = res["force/drive/deflection"]
    assert e[-1] == pytest.approx(C * v / 200.0, rel=1e-9)
    assert abs(e[200] - e[-1]) < 1e-6  # settled by t = 2 s (1e-5 of the error without kd)


def test_velocity_servo_is_a_first_order_lag():
    w, kd = 1.5, 20.0
    res = ms.simulate(slide(ms.forces.Servo("spin", "x", w, kd=kd, mode="velocity")), 1.0,
                      ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=0.01)
    # M v' = kd (w - v) - C v: v = w kd / (kd + C) (1 - exp(-(kd + C) t / M))
    lam = (kd + C) / M
    np.testing.assert_allclose(res["joint/x/u"], w * kd / (kd + C) * (1 - np.exp(-lam * res.t)), atol=1e-9)


def test_the_torque_limit_clamps_the_motor():
    res = ms.simulate(slide(ms.forces.Servo("drive", "x", 1.0, kp=1e4, max_torque=3.0, gear=2.0)), 0.2,
                      ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=0.01)
    f = res["force/drive/force"]
    assert np.abs(f).max() == pytest.approx(6.0, rel=1e-12)  # gear x limit
    # saturated from rest: M x'' = 6 - C x'
    t = res.t
    np.testing.assert_allclose(res["joint/x/u"], 6.0 / C * (1 - np.exp(-C / M * t)), atol=1e-9)


@pytest.mark.parametrize("kwargs,message", [
    (dict(kp=-1.0), "kp: must be a finite gain >= 0"),
    (dict(kp=0.0, kd=0.0), "give kp or kd"),
    (dict(kp=1.0, mode="torque"), 'mode: must be "position" or "velocity"'),
    (dict(kp=1.0, gear=0.0), "gear: must be a finite, nonzero ratio"),
    (dict(kp=1.0, max_torque=-2.0), "max_torque: must be > 0"),
    (dict(kp=1.0, index=1), "index"),
])
def test_bad_servo_settings_name_the_element(kwargs, message):
    with pytest.raises(ms.ModelError, match=rf"'drive'.*{message}|{message}"):
        slide(ms.forces.Servo("drive", "x", 1.0, **kwargs)).build()
    with pytest.raises(ms.ModelError, match="unknown joint 'y'"):
        m = slide(ms.forces.Servo("drive", "y", 1.0, kp=1.0))
        m.build()
