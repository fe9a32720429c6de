"""Two spheres colliding, rigid and compliant side by side (section 2.5.4): a 10 mm steel ball
at 1 m/s hits a 15 mm aluminium ball at rest, once with Newton's impact law (e = 1, an impulse
at one instant, event-driven) and once with Hertz's compliant law from the two materials and
radii (a force over the contact's finite duration, DOPRI5 with the onset and release located).
Both conserve momentum and energy and leave with the same velocities; the compliant run adds the
contact force history, the overlap and the duration, which `mechsys.hertz` predicts from the
rigid run's impact alone (printed next to the compliant run's values).

    python examples/compliant_spheres.py
    mechsys run examples/compliant_spheres.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

STEEL = ms.Material(E=2.1e11, nu=0.3, density=7800.0)
ALU = ms.Material(E=7.0e10, nu=0.33, density=2700.0)
R1, R2, V0 = 0.010, 0.015, 1.0


def build(compliant: bool) -> ms.Model:
    m = ms.Model("spheres-" + ("compliant" if compliant else "rigid"), gravity=(0, 0, 0))
    m1, m2 = 7800.0 * 4 / 3 * np.pi * R1**3, 2700.0 * 4 / 3 * np.pi * R2**3
    a = m.add_body("steel", mass=m1, inertia=ms.inertia.sphere(m1, R1))
    b = m.add_body("alu", mass=m2, inertia=ms.inertia.sphere(m2, R2))
    m.add_joint(ms.joints.Prismatic("x_steel", m.ground, a, axis=(1, 0, 0), q0=0.0, u0=V0))
    m.add_joint(ms.joints.Prismatic("x_alu", m.ground, b, axis=(1, 0, 0), q0=R1 + R2 + 1e-4))
    law = dict(normal=ms.laws.Hertz()) if compliant else dict(impact=ms.laws.Newton(eps=1.0))
    m.add_contact(ms.Contact("hit", a.contour(ms.contours.Sphere(radius=R1), material=STEEL),
                             b.contour(ms.contours.Sphere(radius=R2), material=ALU), **law))
    return m


model = build(compliant=True)
simulation = dict(t_end=3e-4, output_dt=1e-7, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-14))

if __name__ == "__main__":
    import matplotlib.pyplot as plt

    rigid_model = build(compliant=False)
    rigid = ms.simulate(rigid_model, t_end=3e-4, output_dt=1e-7, integrator=ms.EventDriven())
    soft = ms.simulate(model, **simulation)
    est = ms.hertz.impacts(rigid, rigid_model)[0]
    f, d = soft["contact/hit/force_n"], soft["contact/hit/overlap"]
    ev = [e["t"] for e in soft.events]
    print(f"                 rigid + Hertz estimate   compliant run")
    print(f"delta_max (m)    {est['delta_max']:.6e}            {d.max():.6e}")
    print(f"F_max (N)        {est['force_max']:.6e}            {f.max():.6e}")
    print(f"duration (s)     {est['duration']:.6e}            {ev[1] - ev[0]:.6e}")
    print(f"contact radius {est['a'] * 1e3:.4f} mm, peak pressure {est['p0'] / 1e9:.3f} GPa")
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for res, name in ((rigid, "rigid (Newton e = 1)"), (soft, "compliant (Hertz)")):
        ax[0].plot(res["t"] * 1e6, res["joint/x_steel/u"], label=f"steel, {name}")
        ax[0].plot(res["t"] * 1e6, res["joint/x_alu/u"], "--", label=f"aluminium, {name}")
    ax[0].set(xlabel="t [µs]", ylabel="velocity [m/s]")
    ax[0].legend(fontsize=7)
    ax[1].plot(soft["t"] * 1e6, f, label="compliant: contact force")
    ax[1].axhline(est["force_max"], color="k", ls=":", label="rigid run's Hertz estimate of the peak")
    ax[1].set(xlabel="t [µs]", ylabel="force [N]")
    ax[1].legend(fontsize=7)
    out = Path("results")
    out.mkdir(exist_ok=True)
    fig.tight_layout()
    fig.savefig(out / "compliant_spheres.png", dpi=120)
    print(f"plot: {out / 'compliant_spheres.png'}")
