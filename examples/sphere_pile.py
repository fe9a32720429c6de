"""Spheres poured into a box: one contact group instead of N(N-1)/2 contacts.

N spheres (radius 5 cm, 0.1 kg, friction 0.5, no restitution) start on a jittered lattice
filling a square box layer by layer and fall in under gravity. A single `ms.ContactGroup` says
that every pair of spheres may touch and that each may touch the floor and the four walls; at
every step a sweep-and-prune broad phase over bounding boxes (grown by the motion within the step)
picks the pairs close enough to matter, and only those go to the narrow phase and the contact
problem (Moreau-Jean time-stepping, nonsmooth Gauss-Seidel on per-contact Delassus blocks).

Printed at the end: the vertical force the box exerts on the spheres (`contact/pile/force_against`,
the weight N m g once nothing moves vertically; spheres on a flat floor keep rolling, since
nothing resists rolling), the largest penetration, and the energy balance (impacts and friction
take what the spheres lose).

``python examples/sphere_pile.py [N] [SOLVER]`` (default 100 spheres, 1.5 s simulated; a few seconds).
SOLVER names the contact solver instead of the budgeted Gauss-Seidel: ``nsgs``, ``newton`` (its
direction solved in body space, a sparse factorization in the spheres' velocities), ``apgd``
(accelerated projected gradient), ``auto``, each at tol 1e-4. From the command line the same is
``mechsys run examples/sphere_pile.py --solver apgd``.
"""

import sys
import time
from pathlib import Path

import numpy as np

import mechsys as ms

R, MASS, MU, G = 0.05, 0.1, 0.5, 9.81


def build(n: int = 100, seed: int = 0, compliance: float = 0.0) -> ms.Model:
    """The pile of `n` spheres in a box just wide enough for 5 (n ≤ 100) or 10 spheres a row; its
    contacts rigid, or on compliant Signorini layers of `compliance` m/N
    (`examples/compliant_layer_pile.py`)."""
    half = 0.275 if n <= 100 else 0.55
    per = int(round(2 * half / (2.2 * R)))
    rng = np.random.default_rng(seed)
    m = ms.Model(f"sphere-pile-{n}", gravity=(0, 0, -G))
    members = []
    for i in range(n):
        ix, iy, iz = i % per, (i // per) % per, i // (per * per)
        x = -half + 1.1 * R + 2.2 * R * ix + rng.uniform(-0.01, 0.01) * R
        y = -half + 1.1 * R + 2.2 * R * iy + rng.uniform(-0.01, 0.01) * R
        z = R + 0.01 + 2.2 * R * iz
        b = m.add_body(f"s{i}", MASS, ms.inertia.sphere(MASS, R))
        m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=[x, y, z, 1, 0, 0, 0]))
        members.append(b.contour(ms.contours.Sphere(radius=R)))
    floor = m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))
    walls = [m.ground.contour(ms.contours.Plane(point=(-s * half * (ax == 0), -s * half * (ax == 1), 0),
                                                normal=(s * (ax == 0), s * (ax == 1), 0)))
             for ax in (0, 1) for s in (1, -1)]
    m.add_contact(ms.ContactGroup("pile", members=members, against=[floor, *walls],
                                  friction=ms.laws.Coulomb(mu=MU), impact=ms.laws.Newton(eps=0.0),
                                  normal=ms.laws.Signorini(compliance=compliance)))
    return m


N = int(sys.argv[1]) if len(sys.argv) > 1 and __name__ == "__main__" else 100
SOLVERS = {"nsgs": ms.NSGS(tol=1e-4), "newton": ms.Newton(tol=1e-4), "apgd": ms.APGD(tol=1e-4), "auto": ms.Auto(tol=1e-4)}
solver = SOLVERS[sys.argv[2]] if len(sys.argv) > 2 and __name__ == "__main__" else ms.NSGS(tol=1e-6, max_iter=100)
model = build(N)
simulation = dict(t_end=1.5, integrator=ms.MoreauJean(dt=1e-3, solver=solver), output_dt=1e-2)


if __name__ == "__main__":
    import warnings

    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as notes:
        warnings.simplefilter("always")
        res = ms.simulate(model, **simulation)
    wall = time.perf_counter() - t0
    for w in notes:
        print(f"note: {w.message}")
    weight = N * MASS * G
    f = res["contact/pile/force_against"]
    e = res["energy/total"] + res["energy/dissipated"]
    print(f"contact solver {solver}: worst residual {res['solver/residual'].max():.1e}, at most "
          f"{res['solver/iterations'].max():.0f} iterations in a step")
    print(f"{N} spheres, {res.t[-1]:.2f} s simulated in {wall:.2f} s wall ({res.stats['steps']} steps of "
          f"{simulation['integrator'].dt:g} s; {wall / res.t[-1]:.2f} s per simulated s)")
    print(f"at the end: {int(res['contact/pile/closed'][-1])} closed contact points among "
          f"{int(res['contact/pile/pairs'][-1])} pairs from the broad phase (of {N * (N - 1) // 2 + 5 * N} possible)")
    v = np.array([res[f"body/s{i}/velocity"][-1] for i in range(N)])
    print(f"vertical force of the box on the spheres over the last 10 ms {f[-1, 2]:.4f} N (N m g = {weight:.4f} N); "
          f"largest speed {np.linalg.norm(v, axis=1).max():.1e} m/s, vertical {np.abs(v[:, 2]).max():.1e} m/s")
    print(f"largest penetration {1e3 * res['contact/pile/max_penetration'].max():.3f} mm; energy taken by impacts "
          f"{res['energy/dissipated_impact'][-1]:.3f} J, by friction {res['energy/dissipated_friction'][-1]:.3f} J, "
          f"balance drift {np.ptp(e):.1e} J")
    Path("results").mkdir(exist_ok=True)
    res.save("results/sphere_pile.h5")
    ms.plot(res, ["contact/pile/closed", "contact/pile/force_against", "contact/pile/max_penetration",
                  "energy/kinetic", "energy/dissipated"], out="results/sphere_pile.png")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pos = res["q"][-1].reshape(N, 7)[:, :3]
    fig, ax = plt.subplots(figsize=(5, 5))
    for x, _, z in pos:
        ax.add_patch(plt.Circle((x, z), R, fill=False))
    ax.set_xlim(pos[:, 0].min() - 2 * R, pos[:, 0].max() + 2 * R)
    ax.set_ylim(0, pos[:, 2].max() + 2 * R)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"{N} spheres at t = {res.t[-1]:.2f} s (side view)")
    fig.tight_layout()
    fig.savefig("results/sphere_pile_side.png", dpi=120)
    print("wrote results/sphere_pile.h5, results/sphere_pile.png, results/sphere_pile_side.png")
