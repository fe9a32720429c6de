"""Bending modes of a steel cantilever: analytic, finite elements, Craig-Bampton, spin stiffening.

A 1 m steel strip (20 mm x 10 mm) clamped at x = 0. Its bending frequencies in the stiff plane
are omega_n = (beta_n L)^2 sqrt(E I / (rho A L^4)) with beta_n L = 1.8751, 4.6941, 7.8548
(cos beta L cosh beta L = -1). The script prints them next to

* the Euler-Bernoulli finite-element beam (Hermite elements) for 2 .. 32 elements — the error
  falls as h^4 (a factor 16 per halving),
* a Craig-Bampton model (interface: the tip and the middle node, 6 fixed-interface modes),
* the Timoshenko frequencies (shear and rotary inertia; a slender strip: almost equal),
* the Southwell coefficient of the spinning cantilever, omega^2 ~ omega_0^2 + kappa Omega^2
  (kappa_1 = 1.193 for out-of-plane bending at zero hub radius),

and writes results/beam_modes.png with the first three mode shapes (analytic and FE).

As a model file (`mechsys run examples/beam_modes.py`) it is the tip deflection in the first mode
as a one-degree-of-freedom oscillator: modal mass m/4 (the mode normalized to a unit tip
deflection) on a spring (beta_1 L)^4 E I / (4 L^3), released from 1 mm.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mechsys as ms
from mechsys import elastic as el

E, NU, RHO = 210e9, 0.3, 7850.0
B, H, L = 0.02, 0.01, 1.0
SECTION = el.BeamSection.rectangle(B, H, E=E, nu=NU, rho=RHO)
MASS = RHO * SECTION.A * L
W1 = el.euler_bernoulli_frequencies("clamped-free", 1, E, SECTION.Iz, RHO, SECTION.A, L)[0]


def build() -> ms.Model:
    m = ms.Model("cantilever_mode1", gravity=(0.0, 0.0, 0.0))
    tip = m.add_body("tip", MASS / 4, [1e-6, 1e-6, 1e-6])
    m.add_joint(ms.joints.Prismatic("deflection", m.ground, tip, axis=(0, 1, 0), spring=ms.joints.JointSpring(k=W1**2 * MASS / 4)))
    return m


model = build()
simulation = dict(t_end=0.2, integrator=ms.DOPRI5(rtol=1e-9, atol=1e-12), output_dt=1e-4, q0={"deflection": 1e-3})


def main() -> None:
    hz = 1 / (2 * np.pi)
    w_an = el.euler_bernoulli_frequencies("clamped-free", 3, E, SECTION.Iz, RHO, SECTION.A, L)
    print("cantilever, bending in the x-y plane (I = %.4g m^4), frequencies in Hz" % SECTION.Iz)
    print(f"{'':>22s}" + "".join(f"{'mode %d' % (k + 1):>14s}" for k in range(3)))
    print(f"{'analytic':>22s}" + "".join(f"{w * hz:14.6f}" for w in w_an))
    for n in (2, 4, 8, 16, 32):
        body = el.modal_reduction(el.beam_model(SECTION, L, n, planar=True), 3, fixed={0: "clamped"}, name="fe")
        err = body.omega / w_an - 1
        print(f"{'FE, %2d elements' % n:>22s}" + "".join(f"{w * hz:14.6f}" for w in body.omega) + "   rel. error " + " ".join(f"{e:.2e}" for e in err))
    fe = el.beam_model(SECTION, L, 20, planar=True)
    full = el.modal_reduction(fe, 3, fixed={0: "clamped"}, name="full")
    cb = el.craig_bampton(fe, 6, interface=[10, -1], fixed={0: "clamped"}, name="cb")
    print(f"{'Craig-Bampton (%d q)' % cb.n_coordinates:>22s}" + "".join(f"{w * hz:14.6f}" for w in cb.omega[:3]) + "   vs 20-element FE " + " ".join(f"{e:.2e}" for e in cb.omega[:3] / full.omega - 1))
    w_t = el.timoshenko_frequencies("clamped-free", 3, E, SECTION.G, SECTION.kappa, RHO, SECTION.A, SECTION.Iz, L)
    print(f"{'Timoshenko':>22s}" + "".join(f"{w * hz:14.6f}" for w in w_t))
    kappa = el.southwell_coefficients(SECTION, L, n_elements=20, n_modes=3)
    print("Southwell coefficients (flap, zero hub radius): " + ", ".join(f"{k:.4f}" for k in kappa) + "  (published: 1.193, 6.479)")
    w0 = el.rotating_cantilever_frequencies(SECTION, L, 0.0, n_modes=1)[0]
    for ratio in (0.5, 1.0, 2.0):
        w = el.rotating_cantilever_frequencies(SECTION, L, ratio * w0, n_modes=1)[0]
        print(f"  flap, Omega = {ratio:.1f} omega_0: omega_1 = {w * hz:9.4f} Hz, Southwell {np.sqrt(w0**2 + kappa[0] * (ratio * w0) ** 2) * hz:9.4f} Hz")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    body = el.modal_reduction(el.beam_model(SECTION, L, 8, planar=True), 3, fixed={0: "clamped"}, name="fe8")
    x = np.linspace(0, L, 200)
    fig, ax = plt.subplots(figsize=(7, 4))
    for k in range(3):
        phi = el.euler_bernoulli_mode("clamped-free", k + 1, x, L)
        fe_tip = body.modes[-1, 1, k]
        (line,) = ax.plot(x, phi / phi[-1], label=f"mode {k + 1}: {w_an[k] * hz:.2f} Hz")
        ax.plot(body.nodes[:, 0], body.modes[:, 1, k] / fe_tip, "o", color=line.get_color(), ms=4)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("deflection / tip deflection")
    ax.set_title("Cantilever modes: analytic (lines), 8 Hermite elements (dots)")
    ax.legend(loc="lower left")
    ax.grid(alpha=0.3)
    out = Path("results") / "beam_modes.png"
    out.parent.mkdir(exist_ok=True)
    fig.savefig(out, dpi=120, bbox_inches="tight")
    print(f"mode shapes: {out}")


if __name__ == "__main__":
    main()
