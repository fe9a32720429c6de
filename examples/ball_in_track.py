"""A ball rolling in a curved track (parametric contours, section 2.2.7.1): the track is a C²
spline through points of the valley y = x^2 / (2 R0) (radius of curvature R0 at the bottom), the
ball a disc of radius r that rolls without slipping (Coulomb friction, mu = 0.8). Rolling does no
work, so the energy stays constant while the ball rolls to and fro; small oscillations about the
bottom have the period of a disc rolling in a circle of radius R0,

    T = 2 pi sqrt(3 (R0 - r) / (2 g)).

Printed: the energy drift, the period against the closed form and the largest friction demand
|lambda_T| / lambda_N (below mu: it never slips). Plotted: the contact force and the position.

    python examples/ball_in_track.py
    mechsys run examples/ball_in_track.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

R0, RADIUS, MASS, G, MU = 2.0, 0.1, 1.0, 9.81, 0.8
X0 = 0.15  # start, at rest, this far from the bottom (m)

xs = np.linspace(-1.0, 1.0, 81)
track = ms.contours.Spline(points=[(x, x * x / (2 * R0)) for x in xs], solid="right")  # ground below the points

model = ms.Model("ball-in-track", gravity=(0.0, -G, 0.0), planar=True)
ball = model.add_body("ball", MASS, ms.inertia.cylinder(MASS, RADIUS, 0.02, axis="z"))


def start() -> tuple[float, float]:
    """Centre of the ball resting on the track at x-position X0 of the contact point."""
    slope = X0 / R0
    n = np.array([-slope, 1.0]) / np.hypot(slope, 1.0)
    c = np.array([X0, X0 * X0 / (2 * R0)]) + RADIUS * n
    return float(c[0]), float(c[1])


cx, cy = start()
model.add_joint(ms.joints.Planar("free", model.ground, ball, q0=(cx, cy, 0.0)))
model.add_contact(ms.Contact("track", ball.contour(ms.contours.Circle(radius=RADIUS)), model.ground.contour(track),
                             friction=ms.laws.Coulomb(mu=MU)))

simulation = dict(t_end=6.0, integrator=ms.EventDriven(), output_dt=1e-3)


def period(res) -> float:
    return ms.analysis.period(res.t, res["joint/free/q"][:, 0])


if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    expected = 2 * np.pi * np.sqrt(3 * (R0 - RADIUS) / (2 * G))
    e = res["energy/total"]
    demand = np.abs(res["contact/track/lambda_t"]) / res["contact/track/lambda_n"]
    print(f"period {period(res):.5f} s against {expected:.5f} s for small oscillations (amplitude {X0 / R0:.3f} rad)")
    print(f"energy drift {np.ptp(e):.1e} J; contact state: {sorted(set(res['contact/track/state'].tolist()))} "
          f"(1 = stick); friction demand at most {demand.max():.3f} (mu = {MU})")
    Path("results").mkdir(exist_ok=True)
    res.save("results/ball_in_track.h5")
    ms.plot(res, ["joint/free/q", "contact/track/lambda_n", "contact/track/lambda_t", "energy/total"],
            out="results/ball_in_track.png")
    print("wrote results/ball_in_track.h5, results/ball_in_track.png")
