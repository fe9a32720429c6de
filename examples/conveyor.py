"""A block put down on a conveyor belt (a moving surface): the belt runs at V under a block at
rest; Coulomb friction accelerates the block at mu g until it moves with the belt, at
t* = V / (mu g), having slid V^2 / (2 mu g) over it; from then on it sticks, which on a belt
means moving with the belt. Friction turns exactly half of the belt's work, m V^2 / 2, into heat
(the other half is the block's kinetic energy).

Both contact schemes run: event-driven (the stick event located where the sliding velocity
relative to the belt vanishes) and Moreau-Jean.

    python examples/conveyor.py
    mechsys run examples/conveyor.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

V, MU, G, MASS = 1.0, 0.3, 9.81, 2.0
T_STICK = V / (MU * G)
SLIDE = V**2 / (2 * MU * G)

model = ms.Model("conveyor", gravity=(0.0, -G, 0.0), planar=True)
block = model.add_body("block", MASS, ms.inertia.box(MASS, (0.2, 0.1, 0.1)))
model.add_joint(ms.joints.Planar("free", model.ground, block, q0=(0.0, 0.05, 0.0)))
corners = [(-0.1, -0.05), (0.1, -0.05), (0.1, 0.05), (-0.1, 0.05)]
model.add_contact(ms.Contact("belt", block.contour(ms.contours.Polygon(vertices=corners)),
                             model.ground.contour(ms.contours.Line(normal=(0, 1, 0), surface_velocity=(V, 0, 0))),
                             friction=ms.laws.Coulomb(mu=MU)))

simulation = dict(t_end=0.6, integrator=ms.EventDriven(), output_dt=1e-3)


def stick_time(res) -> float:
    """The first moment both bottom corners move with the belt (event log, else the signals)."""
    sticks = [e["t"] for e in res.events if e["event"] == "stick"]
    if sticks:
        return float(sticks[0])
    v = res["joint/free/u"][:, 0]
    return float(res.t[np.argmax(v >= V * (1 - 1e-9))])


if __name__ == "__main__":
    print(f"closed form: sticks at t* = {T_STICK:.6f} s after sliding {SLIDE:.6f} m over the belt")
    Path("results").mkdir(exist_ok=True)
    for label, integ in (("event-driven", ms.EventDriven()), ("Moreau-Jean, dt = 1e-4", ms.MoreauJean(dt=1e-4))):
        res = ms.simulate(model, t_end=0.6, integrator=integ, output_dt=1e-4)
        ts = stick_time(res)
        x_stick = float(np.interp(T_STICK, res.t, res["joint/free/q"][:, 0]))
        slid = V * T_STICK - x_stick
        v_end = res["joint/free/u"][-1, 0]
        print(f"{label}: sticks at {ts:.6f} s (error {ts - T_STICK:+.1e} s), slid {slid:.6f} m over the belt "
              f"(error {slid - SLIDE:+.1e} m), final speed {v_end:.9f} m/s")
        if integ == simulation["integrator"]:
            res.save("results/conveyor.h5")
            ms.plot(res, ["joint/free/u", "contact/belt/gd_t", "contact/belt/lambda_t", "contact/belt/state"],
                    out="results/conveyor.png")
    print("wrote results/conveyor.h5, results/conveyor.png")
