"""A variable-mass body (section 2.1.1): a sounding rocket launched vertically burns 60 % of its
mass in 60 s, then coasts to its apogee. Tsiolkovsky with gravity loss gives the burn-out speed
v_b = w ln(m0 / m_b) - g t_b; after burn-out the flight is ballistic, apogee h_b + v_b^2 / (2 g).

Run it:            .venv/bin/python examples/rocket.py
or as a model:     mechsys run examples/rocket.py
"""

from __future__ import annotations

import numpy as np

import mechsys as ms

G = 9.81
M0, M_BURNOUT = 1000.0, 400.0  # kg
MASS_RATE = -10.0  # kg/s: a burn of 60 s
EXHAUST = 2000.0  # m/s relative to the rocket: thrust 20 kN, twice the weight at lift-off

model = ms.Model("rocket", gravity=(0.0, 0.0, -G))
rocket = model.add_body(
    "rocket",
    mass=M0,
    inertia=ms.inertia.cylinder(M0, 0.3, 6.0, axis="z"),
    mass_rate=MASS_RATE,
    ejection_velocity=(0.0, 0.0, -EXHAUST),  # body frame: the jet leaves downwards along the axis
    mass_final=M_BURNOUT,
)
model.add_joint(ms.joints.Free("flight", parent=model.ground, child=rocket))

simulation = dict(
    t_end=200.0,
    integrator=ms.DOPRI5(rtol=1e-10, atol=1e-10),
    output_dt=0.1,
    q0={"flight": [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]},
    u0={"flight": [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]},
)

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    t_b = (M_BURNOUT - M0) / MASS_RATE
    v_b = EXHAUST * np.log(M0 / M_BURNOUT) - G * t_b
    h_b = EXHAUST * (t_b * np.log(M0) - ((M_BURNOUT * np.log(M_BURNOUT) - M_BURNOUT) - (M0 * np.log(M0) - M0)) / MASS_RATE) - 0.5 * G * t_b**2
    k = int(round(t_b / simulation["output_dt"]))
    v, z = res["body/rocket/velocity"][:, 2], res["body/rocket/position"][:, 2]
    print(f"burn-out at t = {res.t[k]:.1f} s: mass {res['body/rocket/mass'][k]:.1f} kg, speed {v[k]:.4f} m/s "
          f"(Tsiolkovsky - g t_b: {v_b:.4f}), height {z[k]:.2f} m (closed form {h_b:.2f})")
    top = np.argmax(z)
    print(f"apogee {z[top]:.1f} m at t = {res.t[top]:.1f} s (ballistic estimate {h_b + v_b**2 / (2 * G):.1f} m at "
          f"{t_b + v_b / G:.1f} s)")
    res.save("results/rocket.h5")
    ms.plot(res, ["body/rocket/mass", "body/rocket/velocity", "body/rocket/position", "energy/external_work"], out="results/rocket.png")
    print("wrote results/rocket.h5 and results/rocket.png")
