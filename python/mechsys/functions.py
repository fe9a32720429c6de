"""Scalar functions of time that scale loads: constant, ramp, harmonic, table, or any Python callable.

A Python callable runs in Rust's step loop through a callback into the interpreter, which costs
microseconds per call; prefer the built-in forms for long simulations.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from .errors import ModelError


@dataclass(frozen=True)
class Constant:
    """f(t) = value."""

    value: float

    def describe(self, callbacks: list) -> dict:
        return {"type": "constant", "value": float(self.value)}


@dataclass(frozen=True)
class Ramp:
    """f(t) = 0 before t0, slope (t - t0) after, held at final_value once reached (if given)."""

    slope: float
    t0: float = 0.0
    final_value: float | None = None

    def describe(self, callbacks: list) -> dict:
        d = {"type": "ramp", "slope": float(self.slope), "t0": float(self.t0)}
        if self.final_value is not None:
            d["final_value"] = float(self.final_value)
        return d


@dataclass(frozen=True)
class Harmonic:
    """f(t) = offset + amplitude sin(omega t + phase), omega in rad/s."""

    amplitude: float
    omega: float
    phase: float = 0.0
    offset: float = 0.0

    def describe(self, callbacks: list) -> dict:
        return {
            "type": "harmonic",
            "amplitude": float(self.amplitude),
            "omega": float(self.omega),
            "phase": float(self.phase),
            "offset": float(self.offset),
        }


@dataclass(frozen=True)
class Table:
    """Piecewise-linear interpolation of (t, values), held constant outside the table."""

    t: Sequence[float]
    values: Sequence[float]

    def describe(self, callbacks: list) -> dict:
        return {"type": "table", "t": [float(x) for x in self.t], "values": [float(x) for x in self.values]}


def describe(f, callbacks: list, what: str) -> dict | None:
    """The description of a time function; registers Python callables in ``callbacks``."""
    if f is None:
        return None
    if isinstance(f, (int, float, np.floating)):
        return Constant(float(f)).describe(callbacks)
    if isinstance(f, dict):
        return f
    if hasattr(f, "describe"):
        return f.describe(callbacks)
    if callable(f):
        callbacks.append(f)
        return {"type": "callback", "id": len(callbacks) - 1}
    raise ModelError(f"{what}: expected a number, a mechsys.functions object or a callable f(t), got {type(f).__name__}")


Callable_ = Callable[[float], float]

__all__ = ["Constant", "Ramp", "Harmonic", "Table"]
