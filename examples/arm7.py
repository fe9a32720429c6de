"""A spatial 7-link arm (joint axes alternating z, y, z, y, ... like common 7-axis robots) hanging
limp under gravity from a bent pose, with viscous joint dampers and a harmonic torque on the
shoulder. The energy balance T + V + E_dissipated - W_external = const checks the run.

Run it:            .venv/bin/python examples/arm7.py
or as a model:     mechsys run examples/arm7.py
"""

from __future__ import annotations

import numpy as np

import mechsys as ms

LENGTHS = [0.30, 0.20, 0.20, 0.20, 0.20, 0.15, 0.08]  # m, each link along its body z axis
MASSES = [4.0, 3.5, 3.0, 2.5, 1.8, 1.2, 0.4]  # kg
RADIUS = 0.05  # m, links as solid cylinders
DAMPINGS = [3.0, 3.0, 2.0, 2.0, 1.0, 0.5, 0.05]  # N m s/rad, lighter towards the wrist
AXES = [(0, 0, 1), (0, 1, 0)] * 3 + [(0, 0, 1)]

model = ms.Model("arm7", gravity=(0.0, 0.0, -9.81))
parent, offset = model.ground, 0.0
for i, (length, mass, axis, damping) in enumerate(zip(LENGTHS, MASSES, AXES, DAMPINGS), start=1):
    link = model.add_body(f"link{i}", mass=mass, inertia=ms.inertia.cylinder(mass, RADIUS, length, axis="z"), com=(0.0, 0.0, 0.5 * length))
    model.add_joint(ms.joints.Revolute(f"j{i}", parent=parent, child=link, parent_frame=(0.0, 0.0, offset), axis=axis,
                                       damper=ms.forces.RotaryDamper(d=damping)))
    parent, offset = link, length
model.add_marker("link7", "flange", (0.0, 0.0, LENGTHS[-1]))
# the shoulder is driven by 20 N m at 0.5 Hz
model.add_force(ms.forces.JointForce("shoulder_drive", joint="j2", value=20.0, function=ms.functions.Harmonic(amplitude=1.0, omega=np.pi)))

simulation = dict(
    t_end=8.0,
    integrator=ms.DOPRI5(rtol=1e-9, atol=1e-11),
    output_dt=0.01,
    q0={"j1": 0.0, "j2": 0.8, "j3": 0.3, "j4": -1.2, "j5": 0.5, "j6": 0.9, "j7": 0.0},
    u0={"j1": 1.0},
)

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    balance = res["energy/total"] + res["energy/dissipated"] - res["energy/external_work"]
    scale = max(np.ptp(res["energy/total"]), res["energy/dissipated"][-1])
    print(f"{len(res.t)} samples, {res.stats['steps']} steps, {res.stats['evaluations']} evaluations of the 7-DOF dynamics")
    print(f"energy: dissipated {res['energy/dissipated'][-1]:.3f} J, work of the drive {res['energy/external_work'][-1]:.3f} J, "
          f"balance constant to {np.ptp(balance):.2e} J ({np.ptp(balance) / scale:.1e} relative)")
    q_end = res["q"][-1]
    flange = ms.kinematics.point_position(model, q_end, "link7", (0.0, 0.0, LENGTHS[-1]))
    print("joint angles at the end [deg]: " + ", ".join(f"{np.degrees(x):.1f}" for x in q_end))
    print(f"flange at the end: ({flange[0]:.3f}, {flange[1]:.3f}, {flange[2]:.3f}) m, "
          f"lowest point reached by the last link origin: z = {res['body/link7/position'][:, 2].min():.3f} m")

    signals = {name: res[name] for name in res.names()}
    units = {name: res.unit(name) for name in res.names()}
    signals["energy/balance"], units["energy/balance"] = balance - balance[0], "J"
    out = ms.Results(signals, units, res.attrs)
    out.save("results/arm7.h5")
    ms.plot(out, ["joint/j2/q", "joint/j4/q", "body/link7/position", "energy/dissipated", "energy/balance"], out="results/arm7.png")
    print("wrote results/arm7.h5 and results/arm7.png")
