"""Force elements: point-to-point spring-dampers (linear, cubic, tabulated), forces and torques on
bodies, generalized forces on joints, and Python force laws. Gravity is a property of the Model;
joint springs and dampers are given with the joint (``spring=``, ``damper=``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from . import functions
from .errors import ModelError
from .joints import JointDamper, JointSpring, RotaryDamper, RotarySpring, LinearDamper, LinearSpring  # noqa: F401
from .joints import _vec3 as _vec


def _name(x) -> str:
    return x if isinstance(x, str) else getattr(x, "name", str(x))


@dataclass
class SpringDamper:
    """Point-to-point spring-damper between ``point1`` on ``body1`` and ``point2`` on ``body2``.

    Tension F = k (l - l0) + k3 (l - l0)^3 + table(l - l0) + d dl/dt pulls the points together.
    ``table`` is an optional force-deflection curve ``(deflections, forces)`` (piecewise linear).
    """

    name: str
    body1: Any
    body2: Any
    point1: Sequence[float] = (0.0, 0.0, 0.0)
    point2: Sequence[float] = (0.0, 0.0, 0.0)
    k: float = 0.0
    d: float = 0.0
    l0: float = 0.0
    k3: float = 0.0
    table: tuple[Sequence[float], Sequence[float]] | None = None

    def describe(self, callbacks: list) -> dict:
        w = f"force '{self.name}'"
        d = {
            "type": "spring_damper",
            "name": self.name,
            "body1": _name(self.body1),
            "point1": _vec(self.point1, f"{w}.point1"),
            "body2": _name(self.body2),
            "point2": _vec(self.point2, f"{w}.point2"),
            "k": float(self.k),
            "k3": float(self.k3),
            "d": float(self.d),
            "l0": float(self.l0),
        }
        if self.table is not None:
            x, y = self.table
            d["table_deflection"] = [float(v) for v in x]
            d["table_force"] = [float(v) for v in y]
        return d


@dataclass
class BodyForce:
    """Force (at ``point``, body frame) and torque on a body, in ``frame`` 'inertial' or 'body'
    components, multiplied by ``function`` of time (a number, a mechsys.functions object or a
    callable f(t))."""

    name: str
    body: Any
    force: Sequence[float] = (0.0, 0.0, 0.0)
    torque: Sequence[float] = (0.0, 0.0, 0.0)
    point: Sequence[float] = (0.0, 0.0, 0.0)
    frame: str = "inertial"
    function: Any = None

    def describe(self, callbacks: list) -> dict:
        w = f"force '{self.name}'"
        d = {
            "type": "body_force",
            "name": self.name,
            "body": _name(self.body),
            "point": _vec(self.point, f"{w}.point"),
            "force": _vec(self.force, f"{w}.force"),
            "torque": _vec(self.torque, f"{w}.torque"),
            "frame": self.frame,
        }
        f = functions.describe(self.function, callbacks, f"{w}.function")
        if f is not None:
            d["function"] = f
        return d


@dataclass
class JointForce:
    """Generalized force on a joint's velocities (N or N m), times ``function`` of time."""

    name: str
    joint: Any
    value: float | Sequence[float] = 1.0
    function: Any = None

    def describe(self, callbacks: list) -> dict:
        d = {
            "type": "joint_force",
            "name": self.name,
            "joint": _name(self.joint),
            "value": [float(x) for x in np.atleast_1d(self.value)],
        }
        f = functions.describe(self.function, callbacks, f"force '{self.name}'.function")
        if f is not None:
            d["function"] = f
        return d


@dataclass
class PythonForce:
    """A force law written in Python: ``func(t, q, u) -> array of nu generalized forces``.

    Slow: the step loop calls back into the interpreter at every evaluation (microseconds each).
    Use it to prototype a law, then move it into a built-in element.
    """

    name: str
    func: Callable[[float, np.ndarray, np.ndarray], Sequence[float]]

    def describe(self, callbacks: list) -> dict:
        if not callable(self.func):
            raise ModelError(f"force '{self.name}': func must be callable f(t, q, u)")
        callbacks.append(self.func)
        return {"type": "callback", "name": self.name, "id": len(callbacks) - 1}


__all__ = [
    "SpringDamper",
    "BodyForce",
    "JointForce",
    "PythonForce",
    "JointSpring",
    "JointDamper",
    "RotarySpring",
    "RotaryDamper",
    "LinearSpring",
    "LinearDamper",
]
