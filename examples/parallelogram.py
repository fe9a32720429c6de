"""A chain of three parallelogram four-bars under gravity, turning through their flat positions.

At a flat position every loop's x-equation vanishes (the constraint equations lose rank): the
linkage could go on as a parallelogram or fold into its crossed form. mechsys goes through on the
parallelogram branch (the accelerations near the point come from the neighbouring states on the
constraint manifold) and reports each passage as a warning; the rockers keep turning with the crank,
and the energy of this conservative mechanism is kept to the integrator's tolerance. A servo on
the crank then drives it at a constant speed (a position servo tracking a ramp), its torque and
tracking error recorded.

    python examples/parallelogram.py
    mechsys run examples/parallelogram.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

A, B, R, M_LINK, M_COUPLER = 0.1, 0.3, 0.005, 0.2, 0.4


def build(n: int = 3, theta0: float = 0.3, omega0: float = 12.0, servo_speed: float | None = None,
          planar: bool = False) -> ms.Model:
    m = ms.Model("parallelograms", gravity=(0.0, -9.81, 0.0), planar=planar)
    link = ms.inertia.cylinder(M_LINK, R, A)
    prev = m.add_body("crank", M_LINK, link, com=(A / 2, 0, 0))
    m.add_joint(ms.joints.Revolute("crank", m.ground, prev, q0=theta0, u0=omega0))
    for k in range(n):
        coupler = m.add_body(f"coupler{k}", M_COUPLER, ms.inertia.cylinder(M_COUPLER, R, B), com=(B / 2, 0, 0))
        rocker = m.add_body(f"rocker{k}", M_LINK, link, com=(A / 2, 0, 0))
        m.add_joint(ms.joints.Revolute(f"a{k}", prev, coupler, parent_frame=(A, 0, 0), q0=-theta0, u0=-omega0))
        m.add_joint(ms.joints.Revolute(f"r{k}", m.ground, rocker, parent_frame=((k + 1) * B, 0, 0), q0=theta0, u0=omega0))
        m.add_constraint(ms.constraints.Point(f"loop{k}", body1=coupler, point1=(B, 0, 0), body2=rocker, point2=(A, 0, 0)))
        prev = rocker
    if servo_speed is not None:
        m.add_force(ms.forces.Servo("motor", "crank", lambda t: theta0 + servo_speed * t, kp=50.0, kd=2.0))
    return m


model = build()
simulation = dict(t_end=3.0, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=1e-3)

if __name__ == "__main__":
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = ms.simulate(model, **simulation)
    passages = [str(w.message) for w in caught if "singular configuration" in str(w.message)]
    crank = res["joint/crank/q"]
    flats = np.count_nonzero(np.diff(np.floor(crank / np.pi)))
    e = res["energy/total"]
    rockers = max(np.abs(res[f"joint/r{k}/q"] - crank).max() for k in range(3))
    print(f"free motion: the crank passes a flat position {flats} times in {res.t[-1]:g} s "
          f"({len(passages)} passage warnings); rockers off the crank by {rockers:.1e} rad at most; "
          f"energy drift {np.ptp(e):.1e} J of {np.abs(e).max():.3f} J")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the same passages, reported above
        driven = ms.simulate(build(servo_speed=15.0), 2.0, ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=1e-3)
    err = driven["force/motor/deflection"]
    print(f"servo at 15 rad/s: tracking error {np.abs(err[len(err) // 2:]).max():.2e} rad after 1 s, "
          f"torque {driven['force/motor/force'].min():.3f} .. {driven['force/motor/force'].max():.3f} N m")
    Path("results").mkdir(exist_ok=True)
    res.save("results/parallelogram.h5")
    ms.plot(res, ["joint/crank/q", "joint/r2/q", "energy/total"], out="results/parallelogram.png")
    print("wrote results/parallelogram.h5, results/parallelogram.png")
