"""Hysteresis of a press fit (section 2.6.3, Figs. 2.39 and 2.40): a gear hub on a shaft modelled
as five massless shaft segments, each held to the hub by a Jenkins element (spring in series
with a Coulomb slider). The hub is twisted harmonically at three amplitudes; the loops widen and
their secant stiffness falls as slip spreads from the loaded end. For each amplitude: the work
dissipated per cycle (eq. 2.213) and the equivalent viscous damping of equal loop area (Fig. 2.37).

    .venv/bin/python examples/press_fit.py     # writes results/press_fit_loops.png

As a model file (`mechsys run examples/press_fit.py`), the module-level `model` is the fit
twisted at the middle amplitude (0.5 mrad) over two cycles, sampled at every step.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mechsys as ms

K, K_SHAFT, SLIP = 2.0e4, 5.0e4, [3.0] * 5  # N m/rad, N m/rad, N m
OMEGA = 2 * np.pi * 5.0  # rad/s
STEPS = 2000  # per cycle
PERIOD = 2 * np.pi / OMEGA
DT = PERIOD / STEPS
AMPLITUDES = (3e-4, 5e-4, 8e-4)  # rad


def press_fit(amplitude: float) -> ms.Model:
    m = ms.Model("press-fit")
    hub = m.add_body("hub", mass=20.0, inertia=[0.2, 0.2, 0.4])
    m.add_joint(ms.joints.Revolute("fit", m.ground, hub, axis=(0, 0, 1)))
    m.add_constraint(ms.constraints.Prescribed("twist", "fit", ms.functions.Harmonic(amplitude=amplitude, omega=OMEGA)))
    m.add_force(ms.forces.Jenkins("press", "fit", k=K, slip=SLIP, shaft_stiffness=K_SHAFT))
    return m


def one_cycle(amplitude: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Twist and torque over the second cycle, and the sliders' dissipation over it."""
    res = ms.simulate(press_fit(amplitude), **simulation)
    last = slice(STEPS, 2 * STEPS + 1)
    diss = res["energy/dissipated"]
    return res["force/press/deflection"][last], res["force/press/force"][last], float(diss[2 * STEPS] - diss[STEPS])


# the model file's model and simulation (`mechsys run examples/press_fit.py`): the middle amplitude
model = press_fit(AMPLITUDES[1])
simulation = dict(t_end=2 * PERIOD, output_dt=DT, integrator=ms.RK4(dt=DT))


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path("results")
    out.mkdir(exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    print(f"{'amplitude (mrad)':>17} {'W_D (mJ)':>10} {'secant (N m/rad)':>17} {'d_eq (N m s/rad)':>17}")
    for amp in AMPLITUDES:
        x, f, w_slider = one_cycle(amp)
        w_loop = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))  # eq. 2.213: the loop's area
        secant = (f.max() - f.min()) / (x.max() - x.min())
        d_eq = w_loop / (np.pi * OMEGA * amp**2)  # an ellipse of the same area (Fig. 2.37)
        print(f"{amp * 1e3:17.2f} {w_loop * 1e3:10.4f} {secant:17.1f} {d_eq:17.4g}   (sliders: {w_slider * 1e3:.4f} mJ)")
        ax.plot(x * 1e3, f, label=f"{amp * 1e3:.1f} mrad: W_D = {w_loop * 1e3:.2f} mJ")
    ax.set_xlabel("twist of the hub against the shaft (mrad)")
    ax.set_ylabel("torque carried by the fit (N m)")
    ax.set_title("Press fit: five Jenkins elements on an elastic shaft")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "press_fit_loops.png", dpi=120)
    print(f"wrote {out / 'press_fit_loops.png'}")


if __name__ == "__main__":
    main()
