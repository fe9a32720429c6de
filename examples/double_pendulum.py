"""Double pendulum of two physical rods, released from the horizontal: a chaotic motion in which
the lower link keeps flipping over. Energy is the check: without dampers T + V stays constant.

Run it:            .venv/bin/python examples/double_pendulum.py
or as a model:     mechsys run examples/double_pendulum.py
"""

from __future__ import annotations

import numpy as np

import mechsys as ms

G = 9.81
M1, L1 = 1.0, 1.0  # upper rod: mass (kg), length (m)
M2, L2 = 0.6, 0.7  # lower rod

model = ms.Model("double-pendulum", gravity=(0.0, -G, 0.0))
upper = model.add_body("upper", mass=M1, inertia=ms.inertia.cylinder(M1, 0.02, L1), com=(0.5 * L1, 0.0, 0.0))
lower = model.add_body("lower", mass=M2, inertia=ms.inertia.cylinder(M2, 0.02, L2), com=(0.5 * L2, 0.0, 0.0))
model.add_joint(ms.joints.Revolute("shoulder", parent=model.ground, child=upper, axis=(0.0, 0.0, 1.0)))
model.add_joint(ms.joints.Revolute("elbow", parent=upper, child=lower, parent_frame=(L1, 0.0, 0.0), axis=(0.0, 0.0, 1.0)))

# q = 0 is horizontal (rods along +x), q = -pi/2 hanging; both released from rest, horizontal
simulation = dict(
    t_end=20.0,
    integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12),
    output_dt=0.005,
    q0={"shoulder": 0.0, "elbow": 0.0},
    u0={"shoulder": 0.0, "elbow": 0.0},
)

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    e = res["energy/total"]
    elbow = res["joint/elbow/q"]
    flips = int(np.count_nonzero(np.diff(np.floor((elbow + np.pi) / (2 * np.pi)))))
    print(f"{len(res.t)} samples over {res.t[-1]:.0f} s, {res.stats['steps']} steps ({res.stats['rejected']} rejected)")
    scale = np.max(res["energy/kinetic"])
    print(f"energy: {e[0]:.6f} J at the start, largest deviation {np.max(np.abs(e - e[0])):.2e} J "
          f"({np.max(np.abs(e - e[0])) / scale:.1e} of the largest kinetic energy)")
    print(f"the lower link turned over {flips} times; elbow angle range {np.degrees(elbow.min()):.0f}..{np.degrees(elbow.max()):.0f} deg")
    print(f"largest speed of the elbow joint: {np.max(np.abs(res['joint/elbow/u'])):.2f} rad/s")
    res.save("results/double_pendulum.h5")
    ms.plot(res, ["joint/shoulder/q", "joint/elbow/q", "energy/kinetic", "energy/total"], out="results/double_pendulum.png")
    print("wrote results/double_pendulum.h5 and results/double_pendulum.png")
