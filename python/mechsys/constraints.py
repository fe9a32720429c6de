"""Bilateral constraints beyond the kinematic tree (loop closures, couplers, driven coordinates).

The engine adds Lagrange multipliers: ``M u' = h + tau + G^T lambda`` with ``G u' = gamma``
(eq. 2.70), and after every step projects q and u back onto the constraints. Results carry
``constraint/<name>/lambda`` (the multipliers: force in N for point and distance constraints,
the driving force or torque for prescribed motion) and ``constraint/<name>/violation``.

- :class:`Point`: a point of one body coincides with a point of another (spherical loop closure).
- :class:`Distance`: fixed distance between two body points (massless rod with ball ends);
  ``lambda`` is the force along the line from point 2 to point 1 acting on body 1.
- :class:`Coupler`: ``q(joint1) = ratio * q(joint2) + offset`` (gears, belts).
- :class:`Prescribed`: ``q(joint)[index] = f(t)`` (a driven joint; ``lambda`` is the drive).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

from . import functions
from .joints import _vec3


def _name(x) -> str:
    return x if isinstance(x, str) else getattr(x, "name", str(x))


@dataclass
class Point:
    """``point1`` on ``body1`` coincides with ``point2`` on ``body2`` (3 equations)."""

    name: str
    body1: Any
    body2: Any
    point1: Sequence[float] = (0.0, 0.0, 0.0)
    point2: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        return {
            "type": "point",
            "name": self.name,
            "body1": _name(self.body1),
            "point1": _vec3(self.point1, f"{w}.point1"),
            "body2": _name(self.body2),
            "point2": _vec3(self.point2, f"{w}.point2"),
        }


@dataclass
class Distance:
    """``|r(point1) - r(point2)| = length`` (1 equation)."""

    name: str
    body1: Any
    body2: Any
    length: float
    point1: Sequence[float] = (0.0, 0.0, 0.0)
    point2: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        return {
            "type": "distance",
            "name": self.name,
            "body1": _name(self.body1),
            "point1": _vec3(self.point1, f"{w}.point1"),
            "body2": _name(self.body2),
            "point2": _vec3(self.point2, f"{w}.point2"),
            "length": float(self.length),
        }


@dataclass
class Coupler:
    """``q(joint1) = ratio * q(joint2) + offset`` between single-coordinate joints (1 equation)."""

    name: str
    joint1: Any
    joint2: Any
    ratio: float
    offset: float = 0.0

    def describe(self, callbacks: list) -> dict:
        return {
            "type": "coupler",
            "name": self.name,
            "joint1": _name(self.joint1),
            "joint2": _name(self.joint2),
            "ratio": float(self.ratio),
            "offset": float(self.offset),
        }


@dataclass
class Prescribed:
    """``q(joint)[index] = function(t)``: a mechanism driven in time (1 equation). ``function`` is
    a :mod:`mechsys.functions` object (exact derivatives) or a callable ``f(t)`` (derivatives by
    central differences, slow)."""

    name: str
    joint: Any
    function: Any
    index: int = 0

    def describe(self, callbacks: list) -> dict:
        f = functions.describe(self.function, callbacks, f"constraint '{self.name}'.function")
        return {"type": "prescribed", "name": self.name, "joint": _name(self.joint), "index": int(self.index), "function": f}


__all__ = ["Point", "Distance", "Coupler", "Prescribed"]
