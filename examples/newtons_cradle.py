"""Newton's cradle, rigid and compliant side by side: five steel balls on pendulum strings
(revolute joints), the first released from 30°. The rigid model (Newton's law e = 1, Moreau-Jean)
resolves the impact on the touching row at once: the closed contacts' complementarity keeps the
row together, so the energy is shared over it (for three balls (-1/3, 2/3, 2/3) v0; a sequence of
pairwise impacts would give (0, 0, v0)); the compliant one (Hertz between neighbours, DOPRI5)
sends the pulse down the row through the contacts' forces, and the last ball swings out nearly as
far as the first was released — the difference the two models of section 2.5.4 make for a row
of touching bodies.

    python examples/newtons_cradle.py
    mechsys run examples/newtons_cradle.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

STEEL = ms.Material(E=2.1e11, nu=0.3, density=7800.0)
N, R, L = 5, 0.01, 0.2
MASS = 7800.0 * 4 / 3 * np.pi * R**3


def build(compliant: bool) -> ms.Model:
    m = ms.Model("cradle-" + ("compliant" if compliant else "rigid"), gravity=(0, -9.81, 0))
    balls = []
    for k in range(N):
        b = m.add_body(f"ball{k}", mass=MASS, inertia=ms.inertia.sphere(MASS, R), com=(0, -L, 0))
        q0 = [np.radians(-30.0)] if k == 0 else [0.0]
        m.add_joint(ms.joints.Revolute(f"string{k}", m.ground, b, parent_frame=(2 * R * k, 0, 0), axis=(0, 0, 1), q0=q0))
        balls.append(b)
    for k in range(N - 1):
        law = dict(normal=ms.laws.Hertz()) if compliant else dict(impact=ms.laws.Newton(eps=1.0))
        m.add_contact(ms.Contact(f"c{k}", balls[k].contour(ms.contours.Sphere(radius=R, center=(0, -L, 0)), material=STEEL),
                                 balls[k + 1].contour(ms.contours.Sphere(radius=R, center=(0, -L, 0)), material=STEEL), **law))
    return m


model = build(compliant=True)
simulation = dict(t_end=0.5, output_dt=1e-4, integrator=ms.DOPRI5(rtol=1e-9, atol=1e-12))

if __name__ == "__main__":
    import matplotlib.pyplot as plt

    rigid = ms.simulate(build(False), t_end=0.5, output_dt=1e-4, integrator=ms.MoreauJean(dt=1e-5))
    soft = ms.simulate(model, **simulation)
    fig, ax = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for a, res, name in ((ax[0], rigid, "rigid (Newton e = 1, Moreau-Jean)"), (ax[1], soft, "compliant (Hertz, DOPRI5)")):
        for k in range(N):
            a.plot(res["t"], np.degrees(res[f"joint/string{k}/q"]), label=f"ball {k}")
        a.set(title=name, xlabel="t [s]")
    ax[0].set_ylabel("string angle [°]")
    ax[1].legend(fontsize=7)
    for res, name in ((rigid, "rigid"), (soft, "compliant")):
        print(f"{name:9s}: largest swing of the last ball {np.degrees(res[f'joint/string{N - 1}/q'].max()):.3f}°, "
              f"of the first after release {np.degrees(res['joint/string0/q'][len(res['t']) // 2:].max()):.3f}°")
    out = Path("results")
    out.mkdir(exist_ok=True)
    fig.tight_layout()
    fig.savefig(out / "newtons_cradle.png", dpi=120)
    print(f"plot: {out / 'newtons_cradle.png'}")
