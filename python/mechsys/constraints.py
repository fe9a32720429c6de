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
- :class:`PointOnLine`, :class:`PointOnPlane`: a point of one body slides on a line / in a plane
  fixed to another body (2 / 1 equations; ``lambda`` is the force on body 1, N).
- :class:`LoopSpherical`, :class:`LoopRevolute`, :class:`LoopFixed`: loop-closing joints between
  a frame on each of two bodies (3 / 5 / 6 equations; ``lambda`` rows 0-2 are the force on body 1
  in world axes, N, the remaining rows moments, N m).
- :class:`KnifeEdge`, :class:`RollingDisc`: non-holonomic constraints, eq. (2.70) given at velocity
  level (no position equation; their ``violation`` rows read 0).

Redundant equations (a planar loop closed by a 3-D joint) are allowed: the solver gives dependent
rows zero multipliers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

from . import functions
from .errors import ModelError
from .joints import _frame, _vec3


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


def _bodies(c, w: str) -> dict:
    return {
        "name": c.name,
        "body1": _name(c.body1),
        "point1": _vec3(c.point1, f"{w}.point1"),
        "body2": _name(c.body2),
        "point2": _vec3(c.point2, f"{w}.point2"),
    }


@dataclass
class PointOnLine:
    """``point1`` on ``body1`` stays on the line through ``point2`` of ``body2`` along ``direction``
    (body2 frame; the line moves with body2). 2 equations: the offset components along two unit
    normals of the line fixed in body2; ``lambda`` is the force on body 1 along them (N)."""

    name: str
    body1: Any
    body2: Any
    direction: Sequence[float]
    point1: Sequence[float] = (0.0, 0.0, 0.0)
    point2: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        return {"type": "point_on_line", **_bodies(self, w), "direction": _vec3(self.direction, f"{w}.direction")}


@dataclass
class PointOnPlane:
    """``point1`` on ``body1`` stays in the plane through ``point2`` of ``body2`` with ``normal``
    (body2 frame). 1 equation ``n . (r1 - r2) = 0``; ``lambda`` is the normal force on body 1 (N)."""

    name: str
    body1: Any
    body2: Any
    normal: Sequence[float]
    point1: Sequence[float] = (0.0, 0.0, 0.0)
    point2: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        return {"type": "point_on_plane", **_bodies(self, w), "normal": _vec3(self.normal, f"{w}.normal")}


@dataclass
class _Loop:
    name: str
    body1: Any
    body2: Any
    frame1: Any = None
    frame2: Any = None
    _type = ""

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        return {
            "type": self._type,
            "name": self.name,
            "body1": _name(self.body1),
            "frame1": _frame(self.frame1, f"{w}.frame1"),
            "body2": _name(self.body2),
            "frame2": _frame(self.frame2, f"{w}.frame2"),
        }


@dataclass
class LoopSpherical(_Loop):
    """Loop-closing ball joint: the origins of ``frame1`` (a :class:`mechsys.Frame` or a position on
    ``body1``) and ``frame2`` (on ``body2``) coincide. 3 equations; ``lambda`` is the force on
    body 1 (N, world axes)."""

    _type = "loop_spherical"


@dataclass
class LoopRevolute(_Loop):
    """Loop-closing hinge about the z-axes of ``frame1`` and ``frame2``: the origins coincide and
    the z-axis of frame 1 stays perpendicular to the x- and y-axes of frame 2. 5 equations:
    ``lambda[0:3]`` the force on body 1 (N, world axes), ``lambda[3:5]`` the moments (N m) about
    ``z1 x x2`` and ``z1 x y2``."""

    _type = "loop_revolute"


@dataclass
class LoopFixed(_Loop):
    """Loop-closing weld: ``frame1`` and ``frame2`` coincide. 6 equations: origins, and the relative
    rotation ``R = A2^T A1`` through ``1/2 vee(R - R^T)`` (= sin(angle) * axis, the rotation vector
    to first order). ``lambda[0:3]`` is the force on body 1 (N), ``lambda[3:6]`` the moment (N m,
    frame-2 axes when assembled)."""

    _type = "loop_fixed"


@dataclass
class KnifeEdge:
    """Knife edge, sledge or skate: the velocity of ``point`` on ``body`` along the body-fixed
    ``direction`` is zero (1 non-holonomic equation); ``lambda`` is the lateral force on the blade
    (N). The body may still translate along the blade and turn."""

    name: str
    body: Any
    direction: Sequence[float]
    point: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        return {
            "type": "knife_edge",
            "name": self.name,
            "body": _name(self.body),
            "point": _vec3(self.point, f"{w}.point"),
            "direction": _vec3(self.direction, f"{w}.direction"),
        }


@dataclass
class RollingDisc:
    """A disc of ``radius`` about the body-fixed ``axis`` through ``center`` rolls without slipping
    on the ground plane z = 0 (world z up). 3 equations, world order (z, x, y): the contact height
    is zero (holonomic) and the disc's material point at the contact has no horizontal velocity
    (non-holonomic). ``lambda`` is the contact force on the disc (N): normal, then tangential."""

    name: str
    body: Any
    radius: float
    axis: Sequence[float] = (0.0, 0.0, 1.0)
    center: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        try:
            radius = float(self.radius)
        except (TypeError, ValueError):
            raise ModelError(f"{w}.radius: expected a number, got {self.radius!r}") from None
        return {
            "type": "rolling_disc",
            "name": self.name,
            "body": _name(self.body),
            "center": _vec3(self.center, f"{w}.center"),
            "axis": _vec3(self.axis, f"{w}.axis"),
            "radius": radius,
        }





@dataclass(frozen=True)
class Baumgarte:
    """Baumgarte drift control for ``simulate(..., stabilization=Baumgarte(alpha, beta))``: the
    constraints are enforced as ``Phi'' + 2 alpha Phi' + beta^2 Phi = 0``. Cruder than the default
    projection (the violation decays but never vanishes, and large gains stiffen the equations);
    offered for comparison with codes that use it."""

    alpha: float = 10.0
    beta: float = 10.0

    def describe(self) -> dict:
        return {"type": "baumgarte", "alpha": float(self.alpha), "beta": float(self.beta)}


def stabilization(value) -> dict:
    """The settings entry for a drift control: ``"projection"`` (default), ``"none"`` or a
    :class:`Baumgarte`."""
    from .errors import SettingsError

    if value is None or value == "projection":
        return {"type": "projection"}
    if value == "none":
        return {"type": "none"}
    if isinstance(value, Baumgarte):
        return value.describe()
    raise SettingsError(f"stabilization: expected 'projection', 'none' or mechsys.constraints.Baumgarte, got {value!r}")


__all__ = [
    "Point",
    "Distance",
    "Coupler",
    "Prescribed",
    "PointOnLine",
    "PointOnPlane",
    "LoopSpherical",
    "LoopRevolute",
    "LoopFixed",
    "KnifeEdge",
    "RollingDisc", "Baumgarte", "stabilization"]
