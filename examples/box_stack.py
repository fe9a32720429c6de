"""Boxes on boxes: a twisted tower at rest, and a box dropped corner first onto another.

1. The tower (the module's `model`): ten equal boxes (0.2 x 0.2 x 0.1 m, 1 kg) face on face on
   the floor, each turned by 10 degrees about the vertical against the one below, released at
   rest. Every interface is two squares turned against each other: the separating-axis manifold
   clips one face against the other into an octagon, 8 contact points. The tower stays where it
   is (to ~1e-13 m) and each interface carries the weight above it.
2. The drop: the same box, tilted by 0.3 rad about (1, 0.4, 0), released with its lowest corner
   5 cm above a fixed equal box. It lands on a corner (1 point), rocks onto an edge (2 points) and
   back, and settles on its face, all from the same box-box pair. Each landing sinks in by up to
   the landing speed times the step, which time-stepping does not undo: hence dt = 1e-4 here, and
   a residual tilt of the order of that penetration over the box's width.

Moreau-Jean time-stepping with the automatic solver choice at a tight tolerance (`solver="auto"`:
the regularized semismooth Newton method on these singular, statically indeterminate contact
problems; its residual, iterations and convergence are the signals solver/*). Prints the checks, writes
results/box_stack.h5 (the tower) and results/box_stack.png (both scenes).
"""

import math
from pathlib import Path

import numpy as np

import mechsys as ms

G, N, MASS, MU = 9.81, 10, 1.0, 0.5
HALF = (0.1, 0.1, 0.05)
TWIST = math.radians(10.0)
SOLVER = ms.Auto(tol=1e-12)


def quat(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return [math.cos(angle / 2), *(math.sin(angle / 2) * a)]


def add_box(m, name, position, q):
    b = m.add_body(name, MASS, ms.inertia.box(MASS, tuple(2 * h for h in HALF)))
    m.add_joint(ms.joints.Free(f"free_{name}", m.ground, b, q0=[*position, *q]))
    return b


model = ms.Model("box_stack", gravity=(0.0, 0.0, -G))
boxes = [add_box(model, f"box{k}", (0.0, 0.0, HALF[2] * (2 * k + 1)), quat((0, 0, 1), k * TWIST)) for k in range(N)]
shape = ms.contours.Box(half_extents=HALF)
model.add_contact(ms.Contact("floor", boxes[0].contour(shape), model.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(MU)))
for k in range(1, N):
    model.add_contact(ms.Contact(f"on{k}", boxes[k].contour(shape), boxes[k - 1].contour(shape),
                                 friction=ms.laws.Coulomb(MU)))
simulation = {"t_end": 1.0, "integrator": ms.MoreauJean(1e-3, solver=SOLVER), "output_dt": 1e-2}


def drop_model(height=0.05, tilt=0.3):
    """A box tilted about (1, 0.4, 0) with its lowest corner `height` above a fixed equal box."""
    m = ms.Model("box_drop", gravity=(0.0, 0.0, -G))
    q = quat((1, 0.4, 0), tilt)
    # the lowest corner of the tilted box, below its centre by the largest corner height
    w, x, y, z = q
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    low = max(-(r @ (sx * HALF[0], sy * HALF[1], sz * HALF[2]))[2] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1))
    box = add_box(m, "box", (0.0, 0.0, 2 * HALF[2] + height + low), q)
    base = m.ground.contour(ms.contours.Box(half_extents=HALF, center=(0, 0, HALF[2])))
    m.add_contact(ms.Contact("on", box.contour(shape), base, friction=ms.laws.Coulomb(MU)))
    return m


if __name__ == "__main__":
    import time

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t0 = time.perf_counter()
    res = ms.simulate(model, **simulation)
    wall = time.perf_counter() - t0
    print(f"tower: simulated {res.t[-1]:.2f} s in {wall:.2f} s wall ({res.stats['steps']} steps of {simulation['integrator'].dt:g} s)")
    moved = max(np.abs(res[f"body/box{k}/position"] - res[f"body/box{k}/position"][0]).max() for k in range(N))
    names = ["floor"] + [f"on{k}" for k in range(1, N)]
    pen = max(0.0, -min(res[f"contact/{c}/g_n"].min() for c in names))
    print(f"  no box moved more than {moved:.1e} m; largest penetration {pen:.1e} m")
    print(f"  contact solver: worst residual {res['solver/residual'].max():.1e}, every step converged: "
          f"{bool(res['solver/converged'][1:].all())}, at most {res['solver/iterations'].max():.0f} iterations in a step")
    loads = []
    for k, c in enumerate(names):
        load = res[f"contact/{c}/lambda_n"][-1].sum() / (MASS * G)
        loads.append(load)
        points = int((np.abs(res[f"contact/{c}/g_n"][-1]) < 1e-9).sum())
        print(f"  {c:5s} carries {load:.10f} m g (the {N - k} boxes above: {N - k}) on {points} points")

    t0 = time.perf_counter()
    drop = ms.simulate(drop_model(), 1.0, ms.MoreauJean(1e-4, solver=SOLVER), output_dt=1e-3)
    wall = time.perf_counter() - t0
    closed = (drop["contact/on/g_n"] < 1e-9).sum(axis=1)
    phases = [(drop.t[0], closed[0])] + [(drop.t[i], closed[i]) for i in range(1, len(closed)) if closed[i] != closed[i - 1]]
    print(f"drop: 1 s in {wall:.2f} s wall (dt = 1e-4); closed points " + ", ".join(f"{n} from {t:.3f} s" for t, n in phases[:10])
          + (" ..." if len(phases) > 10 else ""))
    q = drop["body/box/orientation"][-1]
    tilt = 2 * math.degrees(math.atan2(math.hypot(q[1], q[2]), math.hypot(q[0], q[3])))
    z = drop["body/box/position"][-1, 2]
    pen = max(0.0, -drop["contact/on/g_n"].min())
    print(f"  at rest on its face: tilt {tilt:.1e} degrees, height {z:.7f} m (flat: {3 * HALF[2]:.7f}), "
          f"carrying {drop['contact/on/lambda_n'][-1].sum() / (MASS * G):.9f} m g on {closed[-1]} closed points; "
          f"largest penetration {pen:.1e} m (landing speed {math.sqrt(2 * G * 0.05):.2f} m/s times dt: "
          f"{math.sqrt(2 * G * 0.05) * 1e-4:.1e} m)")

    Path("results").mkdir(exist_ok=True)
    res.save("results/box_stack.h5")
    fig, ax = plt.subplots(2, 2, figsize=(10, 6.5))
    ax[0, 0].bar(range(N), loads, color="tab:blue", label="sum of λ_N / (m g)")
    ax[0, 0].plot(range(N), [N - k for k in range(N)], "k_", markersize=18, label="boxes above")
    ax[0, 0].set(xticks=range(N), xticklabels=names, ylabel="load / (m g)", title="tower: load per interface at 1 s")
    ax[0, 0].legend()
    top = res[f"body/box{N - 1}/position"]
    ax[0, 1].plot(res.t, np.linalg.norm(top - top[0], axis=1))
    ax[0, 1].set(xlabel="t (s)", ylabel="m", title="tower: displacement of the top box")
    ax[1, 0].plot(drop.t, drop["body/box/position"][:, 2], label="centre height")
    ax[1, 0].set(xlabel="t (s)", ylabel="m", title="drop: height and closed points")
    ax2 = ax[1, 0].twinx()
    ax2.step(drop.t, closed, "tab:red", where="post")
    ax2.set_ylabel("closed points", color="tab:red")
    ax[1, 1].plot(drop.t, drop["contact/on/lambda_n"])
    ax[1, 1].set(xlabel="t (s)", ylabel="N", title="drop: λ_N of the 8 candidates", ylim=(-1, 4 * MASS * G))
    fig.tight_layout()
    fig.savefig("results/box_stack.png", dpi=120)
    print("wrote results/box_stack.h5, results/box_stack.png")
