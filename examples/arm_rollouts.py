"""Monte Carlo rollouts of the 7-DOF arm (examples/arm7.py) on all cores: 200 starts scattered
about the bent pose, and the same start under 8 damping settings, each batch one call of
`ms.simulate_batch` that runs the cases in the engine on every core.

Run it:            .venv/bin/python examples/arm_rollouts.py
or one case:       mechsys run examples/arm_rollouts.py
many cases:        mechsys batch examples/arm_rollouts.py --states states.npy --t-end 2

It prints how far the flange's end position spreads after 2 s for the scattered starts, and how
the energy dissipated in 2 s depends on the dampers' strength (most at a middle setting:
weak dampers take little per swing, strong ones hold the arm back from swinging).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from arm7 import LENGTHS, model  # noqa: E402  (the arm itself)

import mechsys as ms  # noqa: E402

Q_BENT = np.array([0.0, 0.8, 0.3, -1.2, 0.5, 0.9, 0.0])

simulation = dict(
    t_end=2.0,
    integrator=ms.RK4(1e-3),
    output_dt=0.01,
    q0=dict(zip([f"j{i}" for i in range(1, 8)], Q_BENT)),
)

if __name__ == "__main__":
    rng = np.random.default_rng(0)
    n = 200
    starts = np.hstack([Q_BENT + rng.normal(0.0, 0.05, (n, 7)), np.zeros((n, 7))])
    threads = os.cpu_count() or 1
    batch = ms.simulate_batch(model, simulation["t_end"], simulation["integrator"], output_dt=0.01,
                              initial_states=starts, threads=threads)
    flange = np.array([ms.kinematics.point_position(model, q[-1], "link7", (0.0, 0.0, LENGTHS[-1])) for q in batch.q])
    print(f"{n} rollouts of {simulation['t_end']} s on {threads} threads: flange at the end "
          f"{flange.mean(axis=0).round(3)} m, spread (std) {flange.std(axis=0).round(4)} m")

    # one start, the dampers scaled: parameter sets through Model.with_values
    scales = np.linspace(0.5, 4.0, 8)
    values = [{f"joint.j{i}.damper.d": [float(s * d)] for i, d in enumerate([3.0, 3.0, 2.0, 2.0, 1.0, 0.5, 0.05], 1)}
              for s in scales]
    damped = ms.simulate_batch(model, simulation["t_end"], simulation["integrator"], output_dt=0.01,
                               q0=[Q_BENT] * len(scales), values=values, threads=threads)
    for s, e in zip(scales, damped["energy/dissipated"][:, -1]):
        print(f"  dampers x{s:.1f}: {e:.3f} J dissipated in {simulation['t_end']} s")

    out = Path("results")
    out.mkdir(exist_ok=True)
    np.savez(out / "arm_rollouts.npz", t=batch.t, q=batch.q, u=batch.u, flange=flange)
    print("wrote results/arm_rollouts.npz")
