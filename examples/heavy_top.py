"""Heavy symmetric top: a spinning disc on a stem, its tip held in a ball joint, released tilted
without precession. It does not fall: it precesses about the vertical and nods (nutation) between
its starting tilt and a lower one, tracing cusps.

Run it:            .venv/bin/python examples/heavy_top.py
or as a model:     mechsys run examples/heavy_top.py

Body frame: origin at the tip (the fixed point), symmetry axis = body z, disc centre at height l.
With A = A_C + m l^2 (about the tip) and C (about the axis), released from tilt theta0 at rest in
precession, cos(theta) swings between cos(theta0) and the root u1 of
alpha (1 - u^2) = beta (cos(theta0) - u), alpha = 2 m g l / A, beta = (C omega3 / A)^2
(energy and the vertical moment of momentum are conserved), and for a fast top the mean precession
rate is close to m g l / (C omega3).
"""

from __future__ import annotations

import numpy as np

import mechsys as ms

G = 9.81
MASS, RADIUS, HEIGHT = 0.3, 0.04, 0.04  # kg, m (disc), m (disc centre above the tip)
SPIN = 100.0  # rad/s about the symmetry axis (about 950 rpm)
TILT = np.radians(30.0)

model = ms.Model("heavy-top", gravity=(0.0, 0.0, -G))
top = model.add_body("top", mass=MASS, inertia=ms.inertia.disc(MASS, RADIUS, axis="z"), com=(0.0, 0.0, HEIGHT))
model.add_joint(ms.joints.Spherical("pivot", parent=model.ground, child=top))

# tilted about the inertial x axis by TILT, spinning about its own axis, no precession yet
simulation = dict(
    t_end=3.0,
    integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12),
    output_dt=1e-3,
    q0={"pivot": [np.cos(0.5 * TILT), np.sin(0.5 * TILT), 0.0, 0.0]},
    u0={"pivot": [0.0, 0.0, SPIN]},
)


def nutation_and_precession(res: ms.Results) -> tuple[np.ndarray, np.ndarray]:
    """Tilt theta and unwrapped precession angle psi of the symmetry axis (Euler z-x-z, eq. 2.15):
    A_IB e3 = (sin th sin psi, -sin th cos psi, cos th)."""
    w, x, y, z = res["joint/pivot/q"].T
    axis = np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], axis=1)
    theta = np.arctan2(np.hypot(axis[:, 0], axis[:, 1]), axis[:, 2])
    psi = np.unwrap(np.arctan2(axis[:, 0], -axis[:, 1]))
    return theta, psi


if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    theta, psi = nutation_and_precession(res)

    c_axial = 0.5 * MASS * RADIUS**2
    a_tip = 0.25 * MASS * RADIUS**2 + MASS * HEIGHT**2
    mgl = MASS * G * HEIGHT
    alpha, beta, c0 = 2 * mgl / a_tip, (c_axial * SPIN / a_tip) ** 2, np.cos(TILT)
    u1 = (beta - np.sqrt(beta**2 - 4 * alpha * (beta * c0 - alpha))) / (2 * alpha)
    print(f"nutation: tilt between {np.degrees(theta.min()):.4f} and {np.degrees(theta.max()):.4f} deg "
          f"(theory {np.degrees(TILT):.4f} and {np.degrees(np.arccos(u1)):.4f} deg)")
    rate = np.polyfit(res.t, psi, 1)[0]
    print(f"mean precession rate {rate:.4f} rad/s (fast-top estimate m g l / (C omega3) = {mgl / (c_axial * SPIN):.4f} rad/s)")
    e = res["energy/total"]
    print(f"energy drift over {res.t[-1]:.1f} s: {np.ptp(e) / abs(e[0]):.2e} (relative); "
          f"vertical moment of momentum drift: {np.ptp(res['momentum/angular'][:, 2]):.2e} N m s")

    # the derived angles become signals of their own, saved and plotted with the rest
    signals = {name: res[name] for name in res.names()}
    units = {name: res.unit(name) for name in res.names()}
    signals["top/nutation"], units["top/nutation"] = np.degrees(theta), "deg"
    signals["top/precession"], units["top/precession"] = np.degrees(psi), "deg"
    out = ms.Results(signals, units, res.attrs)
    out.save("results/heavy_top.h5")
    ms.plot(out, ["top/nutation", "top/precession", "joint/pivot/u", "energy/total"], out="results/heavy_top.png")

    # the classic picture: the path of the axis' end seen from above over one precession turn,
    # with a cusp wherever the top stops at its starting tilt
    from matplotlib.figure import Figure

    turn = psi <= 2 * np.pi
    fig = Figure(figsize=(5, 5))
    ax = fig.add_subplot()
    ax.plot(np.sin(theta[turn]) * np.sin(psi[turn]), -np.sin(theta[turn]) * np.cos(psi[turn]), lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x of the symmetry axis (unit length)")
    ax.set_ylabel("y")
    ax.set_title("heavy top: locus of the symmetry axis from above")
    fig.savefig("results/heavy_top_locus.png", dpi=150)
    print("wrote results/heavy_top.h5, results/heavy_top.png, results/heavy_top_locus.png")
