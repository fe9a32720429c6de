"""Spatial parametric surfaces (section 2.2.7.2): an egg rocking on the floor and a ball rolling
in a terrain bowl, both rolling without slip (Coulomb friction, mu = 1).

- The egg is a surface of revolution: an elliptical profile (semi-axes A along the axis, B across)
  turned about its axis, lying on its side and tipped about a horizontal line across it. Its
  contact point slides along the meridian as it rocks; for small swings the rocking period is
  that of a body rolling on a curve of radius rho = A^2 / B at the contact with its centre of mass
  B above it:  T = 2 pi sqrt((I + m B^2) / (m g (rho - B))),  I = m (A^2 + B^2) / 5.
- The bowl is a bicubic spline patch sampled from z = (x^2 + y^2) / (2 R); a ball of radius r
  rolling across its bottom swings like a ball rolling in a sphere of radius R:
  T = 2 pi sqrt(7 (R - r) / (5 g)).

Printed: both periods against the closed forms and the energy drift. Plotted: the contact forces
and the positions.

    python examples/egg_and_bowl.py
    mechsys run examples/egg_and_bowl.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

G, MU = 9.81, 1.0
A, B, M_EGG, TIP = 0.03, 0.021, 0.06, 0.05  # egg: semi-axes (m), mass (kg), initial tip (rad)
R, RADIUS, M_BALL, X0 = 1.0, 0.05, 0.2, 0.04  # bowl radius at the bottom, ball, start offset (m)

model = ms.Model("egg-and-bowl", gravity=(0.0, 0.0, -G))

# the egg: its axis along the body's x (profile turned by cardan about y), lying on the floor
egg = model.add_body("egg", M_EGG, np.diag([2 * B * B, A * A + B * B, A * A + B * B]) * M_EGG / 5)
shell = ms.contours.Revolution(profile=ms.contours.Ellipse(a=B, b=A), cardan=(0.0, np.pi / 2, 0.0))
# tipped by TIP about the body's y axis, resting on the floor (height of the support point)
height = np.sqrt((A * np.sin(TIP)) ** 2 + (B * np.cos(TIP)) ** 2)
model.add_joint(ms.joints.Free("egg", model.ground, egg, q0=[0.0, 0.0, height, np.cos(TIP / 2), 0.0, np.sin(TIP / 2), 0.0]))
model.add_contact(ms.Contact("floor", egg.contour(shell), model.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(mu=MU)))

# the bowl: a spline patch through z = (x² + y²) / (2R), 1 m aside
bowl = ms.contours.Patch.from_function(lambda x, y: (x + 1.0, y, (x * x + y * y) / (2 * R)), (-0.4, 0.4), (-0.4, 0.4), 33, 33)
ball = model.add_body("ball", M_BALL, ms.inertia.sphere(M_BALL, RADIUS))
slope = X0 / R
z0 = X0 * X0 / (2 * R) + RADIUS / np.sqrt(1 + slope * slope)
model.add_joint(ms.joints.Free("ball", model.ground, ball,
                               q0=[1.0 + X0 - RADIUS * slope / np.sqrt(1 + slope * slope), 0.0, z0, 1.0, 0.0, 0.0, 0.0]))
model.add_contact(ms.Contact("bowl", ball.contour(ms.contours.Sphere(radius=RADIUS)), model.ground.contour(bowl),
                             friction=ms.laws.Coulomb(mu=MU)))

simulation = dict(t_end=3.0, integrator=ms.EventDriven(), output_dt=1e-3)


def period(t, x) -> float:
    """Mean period from the downward crossings of the middle of the range."""
    return ms.analysis.period(t, x, level=None)


def expected_periods() -> tuple[float, float]:
    rho, inertia = A * A / B, M_EGG * (A * A + B * B) / 5
    egg_t = 2 * np.pi * np.sqrt((inertia + M_EGG * B * B) / (M_EGG * G * (rho - B)))
    ball_t = 2 * np.pi * np.sqrt(7 * (R - RADIUS) / (5 * G))
    return float(egg_t), float(ball_t)


if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    egg_t, ball_t = expected_periods()
    tip = res["joint/egg/q"][:, 0]  # the egg's centre moves to and fro as it rocks
    print(f"egg rocking period {period(res.t, tip):.4f} s against {egg_t:.4f} s (small swings)")
    print(f"ball period {period(res.t, res['joint/ball/q'][:, 0]):.4f} s against {ball_t:.4f} s (small swings)")
    print(f"energy drift {np.ptp(res['energy/total']):.1e} J; contact states {sorted(set(res['contact/floor/state'].tolist()))}, "
          f"{sorted(set(res['contact/bowl/state'].tolist()))} (1 = stick)")
    Path("results").mkdir(exist_ok=True)
    res.save("results/egg_and_bowl.h5")
    ms.plot(res, ["contact/floor/lambda_n", "contact/bowl/lambda_n", "joint/egg/q", "joint/ball/q"], out="results/egg_and_bowl.png")
    print("wrote results/egg_and_bowl.h5, results/egg_and_bowl.png")
