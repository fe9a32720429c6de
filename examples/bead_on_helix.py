"""A bead sliding down a helical wire (path coordinates, section 2.2.6): the arc length s along
the helix is the generalized coordinate. On a helix about the vertical the weight's component
along the wire is constant, so the bead speeds up uniformly, s'' = -g c / L (c = pitch / 2 pi,
L = sqrt(R^2 + c^2)), while the wire pushes it towards the axis with m kappa s'^2 (the
Frenet-frame equations); both are printed against the run.

    python examples/bead_on_helix.py
    mechsys run examples/bead_on_helix.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

R, PITCH, MASS, G = 0.2, 0.1, 0.05, 9.81

model = ms.Model("bead-on-helix", gravity=(0.0, 0.0, -G))
bead = model.add_body("bead", MASS, np.zeros((3, 3)))  # a point mass
wire = model.add_joint(ms.joints.Path("wire", model.ground, bead, radius=R, pitch=PITCH, oriented=False, u0=0.5))

simulation = dict(t_end=1.5, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=1e-3)

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    c = PITCH / (2 * np.pi)
    L = np.hypot(R, c)
    s_exact = 0.5 * res.t - 0.5 * G * c / L * res.t**2
    print(f"curvature {wire.curvature():.4f} 1/m, torsion {wire.torsion():.4f} 1/m")
    print(f"arc length vs closed form: max error {np.abs(res['joint/wire/q'] - s_exact).max():.2e} m")
    # the wire's force from the Frenet-frame equations: m (s'' t + kappa s'^2 n) - m g
    s, sd = res["joint/wire/q"], res["joint/wire/u"]
    phi = s / L
    t_hat = np.c_[-R * np.sin(phi), R * np.cos(phi), np.full_like(phi, c)] / L
    n_hat = np.c_[-np.cos(phi), -np.sin(phi), np.zeros_like(phi)]
    f_exact = MASS * (-G * c / L * t_hat + wire.curvature() * sd[:, None] ** 2 * n_hat) + MASS * np.array([0, 0, G])
    f = res["joint/wire/reaction_force"]
    print(f"wire force at the end {np.linalg.norm(f[-1]):.4f} N; against the Frenet-frame equations: max error "
          f"{np.abs(f - f_exact).max():.2e} N")
    print(f"energy drift {np.ptp(res['energy/total']):.1e} J")
    Path("results").mkdir(exist_ok=True)
    res.save("results/bead_on_helix.h5")
    ms.plot(res, ["joint/wire/q", "joint/wire/u", "joint/wire/reaction_force", "energy/total"], out="results/bead_on_helix.png")
    print("wrote results/bead_on_helix.h5, results/bead_on_helix.png")
