"""Slider-crank driven at constant crank speed: a closed loop (the wrist pin) and a driving
constraint. The slider follows x = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)); the motor torque
needed is the drive's Lagrange multiplier."""

from pathlib import Path

import numpy as np

import mechsys as ms

R, L, OMEGA = 0.1, 0.35, 20.0

model = ms.Model("slider-crank", gravity=(0.0, -9.81, 0.0))
crank = model.add_body("crank", 0.5, ms.inertia.cylinder(0.5, 0.01, R), com=(R / 2, 0, 0))
rod = model.add_body("rod", 0.8, ms.inertia.cylinder(0.8, 0.01, L), com=(L / 2, 0, 0))
slider = model.add_body("slider", 1.2, ms.inertia.box(1.2, (0.05, 0.05, 0.05)))
model.add_joint(ms.joints.Revolute("crank_pin", model.ground, crank, axis=(0, 0, 1)))
model.add_joint(ms.joints.Revolute("crank_rod", crank, rod, axis=(0, 0, 1), parent_frame=ms.Frame(position=(R, 0, 0))))
model.add_joint(ms.joints.Prismatic("guide", model.ground, slider, axis=(1, 0, 0), q0=R + L))
model.add_constraint(ms.constraints.Point("wrist", body1=rod, point1=(L, 0, 0), body2=slider))
model.add_constraint(ms.constraints.Prescribed("motor", "crank_pin", ms.functions.Ramp(slope=OMEGA)))

simulation = dict(t_end=2 * np.pi / OMEGA, integrator=ms.RK4(dt=1e-4), output_dt=1e-3)

if __name__ == "__main__":
    mob = ms.mechanisms.mobility(model)
    print(f"degrees of freedom {mob['dof']} (redundant equations: {mob['redundant']})")
    res = ms.simulate(model, **simulation)
    th = OMEGA * res.t
    x = R * np.cos(th) + np.sqrt(L**2 - (R * np.sin(th)) ** 2)
    print(f"slider position vs closed form: max error {np.abs(res['joint/guide/q'] - x).max():.2e} m")
    print(f"max loop closure error {np.abs(res['constraint/wrist/violation']).max():.2e} m")
    work = res["energy/external_work"][-1]
    print(f"motor work over one turn {work:.4e} J; change of mechanical energy "
          f"{res['energy/total'][-1] - res['energy/total'][0]:.4e} J")
    Path("results").mkdir(exist_ok=True)
    res.save("results/slider_crank.h5")
    ms.plot(res, ["joint/guide/q", "joint/guide/udot", "constraint/motor/lambda", "joint/crank_rod/reaction_force"],
            out="results/slider_crank.png")
    print("wrote results/slider_crank.h5, results/slider_crank.png")
