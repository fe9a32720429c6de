"""Intermediate-axis instability (the Dzhanibekov effect): a wing nut spinning about the axis of
its intermediate principal moment turns over again and again in free space, while the same spin
about the smallest or largest moment is stable. Energy and moment of momentum stay constant.

Run it:            .venv/bin/python examples/free_body.py
or as a model:     mechsys run examples/free_body.py

Principal moments I1 < I2 < I3 (a box 0.10 x 0.05 x 0.02 m). Linearizing Euler's equations about
omega = (0, Omega, 0) gives perturbations growing like exp(lambda t) with
lambda = Omega sqrt((I2 - I1)(I3 - I2) / (I1 I3)).
"""

from __future__ import annotations

import numpy as np

import mechsys as ms

MASS = 0.05
SIZE = (0.10, 0.05, 0.02)  # m, along the body x, y, z axes
SPIN = 20.0  # rad/s about the intermediate (body y) axis
KICK = 1e-3  # rad/s about x and z: what sets the flipping off

moments = np.diag(ms.inertia.box(MASS, SIZE))
assert moments[0] < moments[1] < moments[2]  # body y carries the intermediate moment

model = ms.Model("free-body")  # no gravity: free space
nut = model.add_body("nut", mass=MASS, inertia=ms.inertia.box(MASS, SIZE))
model.add_joint(ms.joints.Free("free", parent=model.ground, child=nut))

simulation = dict(
    t_end=10.0,
    integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12),
    output_dt=0.002,
    q0={"free": [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]},
    # u = [v_B, omega_B]: a slow drift and the spin about body y with a small kick
    u0={"free": [0.01, 0.0, 0.0, KICK, SPIN, KICK]},
)

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    omega_b = res["joint/free/u"][:, 3:]
    flips = res.t[1:][np.diff(np.sign(omega_b[:, 1])) != 0]
    i1, i2, i3 = sorted(moments)
    lam = SPIN * np.sqrt((i2 - i1) * (i3 - i2) / (i1 * i3))
    print(f"principal moments {i1:.3e}, {i2:.3e}, {i3:.3e} kg m^2; growth rate lambda = {lam:.2f} 1/s")
    print(f"the spin about the intermediate axis reversed {len(flips)} times, first at t = {flips[0]:.3f} s "
          f"(order of magnitude ln(SPIN/KICK)/lambda = {np.log(SPIN / KICK) / lam:.3f} s)")
    e, h = res["energy/kinetic"], res["momentum/angular"]
    print(f"relative drift: kinetic energy {np.ptp(e) / e[0]:.1e}, moment of momentum "
          f"{np.max(np.linalg.norm(h - h[0], axis=1)) / np.linalg.norm(h[0]):.1e}")

    signals = {name: res[name] for name in res.names()}
    units = {name: res.unit(name) for name in res.names()}
    signals["nut/omega_body"], units["nut/omega_body"] = omega_b, "rad/s"
    out = ms.Results(signals, units, res.attrs)
    out.save("results/free_body.h5")
    ms.plot(out, ["nut/omega_body", "body/nut/angular_velocity", "momentum/angular", "energy/kinetic"], out="results/free_body.png")
    print("wrote results/free_body.h5 and results/free_body.png")
