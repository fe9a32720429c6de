"""A crank-rocker four-bar linkage falling under gravity from a rough initial guess: the start
projection assembles the loop, the rocker angle obeys Freudenstein's equation throughout, and the
energy of the conservative mechanism is conserved. It is a planar model (``planar=True``): the loop
closure holds its two in-plane equations only, where the same linkage built in 3-D has a third,
redundant one (see benches/planar.py for what that costs)."""

from pathlib import Path

import numpy as np

import mechsys as ms

A, B, C, D = 0.1, 0.3, 0.25, 0.28  # crank, coupler, rocker, ground link

model = ms.Model("four-bar", gravity=(0.0, -9.81, 0.0), planar=True)
crank = model.add_body("crank", 0.2, ms.inertia.cylinder(0.2, 0.005, A), com=(A / 2, 0, 0))
coupler = model.add_body("coupler", 0.4, ms.inertia.cylinder(0.4, 0.005, B), com=(B / 2, 0, 0))
rocker = model.add_body("rocker", 0.3, ms.inertia.cylinder(0.3, 0.005, C), com=(C / 2, 0, 0))
model.add_joint(ms.joints.Revolute("o2", model.ground, crank, q0=0.3, u0=8.0))
model.add_joint(ms.joints.Revolute("a", crank, coupler, parent_frame=(A, 0, 0), q0=0.9))
model.add_joint(ms.joints.Revolute("o4", model.ground, rocker, parent_frame=(D, 0, 0), q0=1.9))
model.add_constraint(ms.constraints.Point("b", body1=coupler, point1=(B, 0, 0), body2=rocker, point2=(C, 0, 0)))

simulation = dict(t_end=2.0, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=1e-3)

if __name__ == "__main__":
    print(f"Grashof: {ms.mechanisms.grashof(A, B, C, D)}")
    mob = ms.mechanisms.mobility(model)
    print(f"degrees of freedom {mob['dof']}; {mob['nc']} loop equations, redundant: {mob['redundant'] or 'none'}")
    res = ms.simulate(model, **simulation)
    th2, th4 = res["joint/o2/q"], res["joint/o4/q"]
    k1, k2, k3 = D / A, D / C, (A**2 - B**2 + C**2 + D**2) / (2 * A * C)
    fr = k1 * np.cos(th4) - k2 * np.cos(th2) + k3 - np.cos(th2 - th4)
    e = res["energy/total"]
    print(f"Freudenstein residual max {np.abs(fr).max():.2e}; closure error max "
          f"{np.abs(res['constraint/b/violation']).max():.2e} m; energy drift {np.ptp(e) / np.abs(e).max():.2e} (relative)")
    Path("results").mkdir(exist_ok=True)
    res.save("results/four_bar.h5")
    ms.plot(res, ["joint/o2/q", "joint/o4/q", "constraint/b/lambda", "energy/total"], out="results/four_bar.png")
    print("wrote results/four_bar.h5, results/four_bar.png")
