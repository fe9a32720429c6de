"""Torsional vibration of a cam shaft with its follower (linearization with a closed contact,
section 2.6): a cam disc on a torsionally elastic shaft lifts a spring-loaded roller follower.
At rest at the base circle the follower presses on the cam; linearized with the contact held
closed (``contacts="hold"``: the contact becomes a bilateral constraint that slides without
friction), the one remaining degree of freedom is the cam's twist, and the follower adds its
preload through the cam's curvature: with the lift h(theta) = H (1 - cos theta) / 2,

    omega^2 = (k_t + (F0 + m g) h''(0)) / J = (k_t + (F0 + m g) H / 2) / J.

Then the model runs as it is (the contact unilateral, event-driven), started with a small twist:
the shaft oscillates at the linearized frequency while the follower stays on the cam.

    python examples/cam_shaft_modes.py
    mechsys run examples/cam_shaft_modes.py
    mechsys linear examples/cam_shaft_modes.py --contacts hold
"""

from pathlib import Path

import numpy as np

import mechsys as ms

BASE, ROLLER, LIFT = 0.03, 0.01, 0.008  # base circle, roller radius, total lift (m)
MASS, K, PRELOAD, G = 0.2, 2000.0, 20.0, 9.81  # follower mass (kg), spring (N/m), preload at base (N)
K_SHAFT = 3.0  # torsional stiffness of the cam shaft (N m / rad)
CAM_MASS = 1.0
J_CAM = 0.5 * CAM_MASS * BASE**2
ANCHOR = 0.1  # the spring pulls the follower towards a point this far below the cam centre (m)
TWIST0 = 0.02  # initial twist of the shaft (rad)
OMEGA = np.sqrt((K_SHAFT + (PRELOAD + MASS * G) * LIFT / 2) / J_CAM)


def lift(theta):
    return 0.5 * LIFT * (1 - np.cos(theta))


def build(twist: float = 0.0) -> ms.Model:
    m = ms.Model("cam-shaft", gravity=(0.0, -G, 0.0), planar=True)
    cam = m.add_body("cam", CAM_MASS, ms.inertia.cylinder(CAM_MASS, BASE, 0.01, axis="z"))
    follower = m.add_body("follower", MASS, ms.inertia.box(MASS, (0.01, 0.02, 0.01)))
    m.add_joint(ms.joints.Revolute("shaft", m.ground, cam, axis=(0, 0, 1), q0=twist,
                                   spring=ms.joints.JointSpring(K_SHAFT)))
    y0 = BASE + ROLLER + lift(twist)  # roller centre on the cam
    m.add_joint(ms.joints.Prismatic("guide", m.ground, follower, axis=(0, 1, 0), q0=y0))
    l_base = BASE + ROLLER + ANCHOR
    m.add_force(ms.forces.SpringDamper("spring", m.ground, follower, point1=(0, -ANCHOR, 0), k=K,
                                       l0=l_base - PRELOAD / K))
    profile = ms.contours.Cam(lift=lift, base_radius=BASE, follower="roller", roller_radius=ROLLER, samples=360)
    m.add_contact(ms.Contact("cam", follower.contour(ms.contours.Circle(radius=ROLLER)), cam.contour(profile),
                             impact=ms.laws.Newton(eps=0.0)))
    return m


model = build(TWIST0)
simulation = dict(t_end=4 * 2 * np.pi / OMEGA, integrator=ms.EventDriven(), output_dt=1e-4)


def period(res) -> float:
    """Mean period of the shaft's twist from its downward zero crossings."""
    return ms.analysis.period(res.t, res["joint/shaft/q"])


if __name__ == "__main__":
    lin = ms.linear.linearize(build(0.0), contacts="hold")
    f_lin = float(lin.modes().natural_frequency[0])
    print(f"linearized about rest, contact held: {lin.n} coordinate(s), f = {f_lin:.6f} Hz "
          f"(closed form {OMEGA / (2 * np.pi):.6f} Hz, without the follower {np.sqrt(K_SHAFT / J_CAM) / (2 * np.pi):.6f} Hz)")
    res = ms.simulate(model, **simulation)
    f_sim = 1.0 / period(res)
    print(f"simulated from a twist of {TWIST0} rad: f = {f_sim:.6f} Hz; the follower stays on the cam "
          f"(largest gap {res['contact/cam/g_n'].max():.2e} m, least force {res['contact/cam/lambda_n'].min():.3f} N)")
    out = Path("results")
    out.mkdir(exist_ok=True)
    res.save(out / "cam_shaft_modes.h5")
    ms.plot(res, signals=["joint/shaft/q", "contact/cam/lambda_n"], out=out / "cam_shaft_modes.png")
