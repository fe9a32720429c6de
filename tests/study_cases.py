"""Module-level functions for tests/test_study.py: worker processes (a process pool, Dask
workers) import them by name."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mechsys as ms

QUARTER_CAR = str(Path(__file__).resolve().parents[1] / "examples" / "quarter_car.toml")


def quarter_car(d: float = 1500.0, mass: float = 300.0) -> ms.Model:
    """The example quarter car with suspension damping ``d`` and body mass ``mass``; a damping of
    exactly 999 raises (the one failing case of a test)."""
    from mechsys.modelfile import load_model

    if d == 999.0:
        raise ValueError("damping 999 is refused on purpose")
    model, _ = load_model(QUARTER_CAR)
    return model.with_values({"force.suspension.d": float(d), "body.body.mass": float(mass)})


def rk4_run(model: ms.Model) -> ms.Results:
    return ms.simulate(model, t_end=0.5, integrator=ms.RK4(dt=1e-4), output_dt=1e-2, progress=False)


def settle(res: ms.Results) -> dict:
    """Peak upward body acceleration and the final body coordinate."""
    return {"peak": float(np.max(res["body/body/acceleration"][:, 1])), "final": float(res["joint/body_y/q"][-1])}


def push(t, q, u):
    """A constant generalized force of 1 N on every coordinate."""
    return np.ones(len(u))
