"""A rigid rotor in a hydrodynamic journal bearing: the static operating point, the oil-whirl
stability threshold, and a run-up through it (short-bearing theory, section 2.6 and docs/theory.md).

The rotor (50 kg: the cylindrical whirl of a symmetric rotor on two bearings, carried here by one)
moves in the bearing's plane on a planar joint, gravity along -y; the bearing (D = 100 mm,
L = 30 mm so L/D = 0.3, radial clearance 0.1 mm, oil of 0.02 Pa s) sits on the ground. A velocity
servo on the spin runs it up from 400 rad/s to 1.2 times the whirl threshold in 2 s.

Below the threshold the journal follows the static operating point (eccentricity falling with the
speed, `ms.bearings.static`); above it the orbit around that point grows at the rate the
linearization predicts (half-frequency whirl) into oil whip: a limit cycle at half the spin speed
with the journal at eps ~ 0.98-0.99, where the squeeze film is so stiff that the explicit
integrator's steps shrink to a fraction of a microsecond (millions of steps per simulated second on
the limit cycle; docs/benchmarks.md).
The threshold from the bearing's eight coefficients by Lund's formula (`ms.bearings.threshold`)
is checked against the eigenvalues of the linearized multibody model.

Runs on its own (prints the operating points, the threshold both ways and the run-up's tracking,
writes results/rotor_bearing.h5 and results/rotor_bearing.png) and as a model file:

    mechsys run examples/rotor_bearing.py     # the run-up, into oil whip
    mechsys view results/rotor_bearing.h5     # the rotor in the browser (a page beside the file)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mechsys as ms

R, L, C, ETA = 0.05, 0.03, 1e-4, 0.02  # journal radius, bearing length, clearance (m), viscosity (Pa s)
MASS, G = 50.0, 9.81  # rotor mass (kg), gravity (m/s^2)
W0, T_RUN = 400.0, 2.0  # speed at the start (rad/s), duration of the run-up (s)
BEARING = ("short", R, L, C, ETA)

THRESHOLD = ms.bearings.threshold(*BEARING, mass=MASS)
W1 = 1.2 * THRESHOLD.speed  # speed at the end of the run-up


def build(speed: float | None = None) -> ms.Model:
    """The rotor at its static point. ``speed`` None: run up by a velocity servo; a number: the
    spin held at that speed by a prescribed motion (for the linearization)."""
    w = W0 if speed is None else speed
    op = ms.bearings.static(*BEARING, w, MASS * G)
    m = ms.Model("rotor_bearing", gravity=(0.0, -G, 0.0))
    rotor = m.add_body("rotor", MASS, [0.4, 0.4, 0.5])
    m.add_joint(ms.joints.Planar("float", m.ground, rotor, q0=[op.offset[0], op.offset[1], 0.0], u0=[0.0, 0.0, w]))
    m.add_force(ms.forces.HydrodynamicBearing("brg", rotor, m.ground, radius=R, length=L, clearance=C,
                                              viscosity=ETA, theory="short"))
    # for the viewer (mechsys view): the journal, a disc with a stripe that shows the spin, and
    # the bearing's housing on the ground
    m.add_visual(rotor, ms.contours.Cylinder(radius=R, length=0.3, axis=(0, 0, 1)), name="journal", color=(0.55, 0.57, 0.6))
    m.add_visual(rotor, ms.contours.Cylinder(radius=0.16, length=0.04, axis=(0, 0, 1), center=(0, 0, 0.1)), name="disc")
    m.add_visual(rotor, ms.contours.Box(half_extents=(0.07, 0.01, 0.022), center=(0.09, 0, 0.1)), name="stripe", color=(0.9, 0.3, 0.1))
    m.add_visual(m.ground, ms.contours.Torus(radius=R + 0.012, tube=0.012, axis=(0, 0, 1)), name="housing", opacity=0.6)
    if speed is None:
        m.add_force(ms.forces.Servo("motor", "float", index=2, mode="velocity", kd=200.0,
                                    reference=ms.functions.Table([0.0, T_RUN], [W0, W1])))
    else:
        m.add_constraint(ms.constraints.Prescribed("spin", "float", ms.functions.Ramp(speed), index=2))
    return m


def whirl_rate(speed: float) -> tuple[float, float]:
    """Real and imaginary part of the least damped whirl eigenvalue of the linearized rotor."""
    lin = ms.linear.linearize(build(speed), operating_point=True)
    minv = np.linalg.inv(lin.M)
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-minv @ (lin.K + lin.N), -minv @ (lin.D + lin.G)]])
    ev = np.linalg.eigvals(a)
    top = ev[np.argmax(ev.real)]
    return float(top.real), float(abs(top.imag))


model = build()
# `mechsys run examples/rotor_bearing.py`: the run-up and the whirl growing into oil whip
simulation = dict(t_end=2.5, integrator=ms.DOPRI5(rtol=1e-9, atol=1e-13), output_dt=1e-3)

if __name__ == "__main__":
    print(f"rigid rotor {MASS} kg on a short bearing, D = {2 * R * 1e3:.0f} mm, L/D = {L / (2 * R):.2f}, "
          f"c = {C * 1e6:.0f} um, eta = {ETA} Pa s")
    print("\nstatic operating points (load along -y, spin counter-clockwise):")
    print("  speed rad/s    eps   psi deg  Sommerfeld  h_min um  torque N m   Kxx  Kxy  Kyx  Kyy (K c/W)")
    for w in (300.0, 500.0, 800.0, 1200.0):
        op = ms.bearings.static(*BEARING, w, MASS * G)
        k = op.K_bar
        print(f"  {w:11.0f} {op.eps:6.3f} {np.degrees(op.attitude):8.2f} {op.sommerfeld:11.3f} "
              f"{op.h_min * 1e6:9.2f} {op.torque:11.4f}  {k[0, 0]:5.2f} {k[0, 1]:5.2f} {k[1, 0]:5.2f} {k[1, 1]:5.2f}")

    th = THRESHOLD
    print(f"\nwhirl threshold by Lund's formula: {th.speed:.2f} rad/s ({th.speed * 30 / np.pi:.0f} rpm), "
          f"eps = {th.point.eps:.4f}, whirl ratio {th.whirl_ratio:.4f}")
    lo, hi = 0.9 * th.speed, 1.1 * th.speed
    for w in (lo, hi):
        s, f = whirl_rate(w)
        print(f"  linearized rotor at {w:7.1f} rad/s: whirl eigenvalue {s:+8.3f} +- {f:7.2f}i 1/s "
              f"({'decays' if s < 0 else 'grows'}, {f / w:.3f} x speed)")
    while hi - lo > 1e-10 * th.speed:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if whirl_rate(mid)[0] < 0 else (lo, mid)
    print(f"  eigenvalue crossing: {0.5 * (lo + hi):.6f} rad/s, "
          f"relative difference to Lund's {0.5 * (lo + hi) / th.speed - 1:.1e}")

    res = ms.simulate(model, **simulation)
    t, w = res.t, res["joint/float/u"][:, 2]
    eps = res["force/brg/eccentricity"]
    static = np.array([ms.bearings.static(*BEARING, x, MASS * G).eps for x in w])
    print(f"\nrun-up {W0:.0f} -> {W1:.0f} rad/s in {T_RUN:.1f} s "
          f"({res.stats['steps']} steps, {res.stats['rejected']} rejected):")
    for tk in (0.5, 1.0, 1.5, 2.0, 2.1, 2.2, 2.3, 2.4, 2.5):
        k = min(np.searchsorted(t, tk), len(t) - 1)
        print(f"  t = {t[k]:4.2f} s  speed {w[k]:7.1f} rad/s  eps {eps[k]:.5f}  static {static[k]:.5f}")
    crossed = t[np.argmax(w > th.speed)]
    away = np.abs(eps - static) > 0.01
    onset = t[np.argmax(away)] if away.any() else None
    print(f"  the speed crossed the threshold at t = {crossed:.3f} s; "
          + (f"the orbit left the static point (|eps - eps_static| > 0.01) at t = {onset:.3f} s" if onset is not None
             else "the orbit is still at the static point"))
    late = t > t[-1] - 0.1
    if away.any() and late.any():
        x = res["joint/float/q"][late, 0]
        up = np.flatnonzero(np.diff(np.sign(x - x.mean())) > 0)
        if len(up) > 2:
            whirl = 2 * np.pi / np.mean(np.diff(t[late][up]))
            print(f"  oil whip over the last 0.1 s: eps {eps[late].min():.4f} .. {eps[late].max():.4f}, "
                  f"whirl {whirl:.1f} rad/s = {whirl / w[-1]:.3f} x speed")

    Path("results").mkdir(exist_ok=True)
    res.save("results/rotor_bearing.h5")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.5))
    a1.plot(t, eps, label="simulation")
    a1.plot(t, static, "--", label="static operating point")
    a1.axvline(crossed, color="k", lw=0.8, ls=":", label="whirl threshold (Lund)")
    a1.set_xlabel("t (s)")
    a1.set_ylabel("eccentricity ratio")
    a1.legend(fontsize="small")
    a1.set_title("run-up through the whirl threshold")
    x, y = res["joint/float/q"][:, 0] / C, res["joint/float/q"][:, 1] / C
    a2.plot(np.cos(np.linspace(0, 2 * np.pi, 200)), np.sin(np.linspace(0, 2 * np.pi, 200)), "k", lw=0.8)
    a2.plot(x, y, lw=0.8)
    a2.set_aspect("equal")
    a2.set_xlabel("x / c")
    a2.set_ylabel("y / c")
    a2.set_title("journal centre in the clearance circle")
    fig.tight_layout()
    fig.savefig("results/rotor_bearing.png", dpi=120)
    print("wrote results/rotor_bearing.h5, results/rotor_bearing.png")
