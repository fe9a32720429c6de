"""Bilateral constraints beyond the kinematic tree (loop closures, couplers, drives, non-holonomic
rows).

The engine adds Lagrange multipliers: ``M u' = h + tau + G^T lambda`` with ``G u' = gamma``
(eq. 2.70), and after every step projects q and u back onto the constraints. Results carry
``constraint/<name>/lambda`` (the multipliers, meaning below) and ``constraint/<name>/violation``
(``Phi``; 0 on velocity-only rows). "Force on body 1" is the load the constraint puts on
``body1`` (``body2`` gets the opposite).

- :class:`Point`: a point of one body coincides with a point of another (spherical loop closure);
  ``lambda``: force on body 1, world axes (N).
- :class:`Distance`: fixed distance between two body points (massless rod with ball ends);
  ``lambda`` is the force on body 1 along the unit vector from point 2 to point 1 (N; a rod in
  tension has ``lambda < 0``).
- :class:`Coupler`: ``q(joint1) = ratio * q(joint2) + offset`` (gears, belts); ``lambda``: the
  generalized force on joint 1 (N or N m).
- :class:`Prescribed`: ``q(joint)[index] = f(t)``; ``lambda`` is the driving force or torque.
- :class:`PrescribedBody`: a frame on a body follows ``position(t)`` and optionally Cardan angles
  ``orientation(t)`` (3 or 6 equations); ``lambda``: driving force (N) then moment (N m), world axes.
- :class:`PointOnLine`, :class:`PointOnPlane`: a point of one body slides on a line / in a plane
  fixed to another body (2 / 1 equations; ``lambda``: force on body 1 along the normals, N).
- Loop-closing joints between a frame on each of two bodies, the joint axis being the frames'
  z-axis; ``lambda`` lists forces on body 1 (N) first, then moments (N m):

  ========================  ====  ==================================================================
  class                     rows  lambda
  ========================  ====  ==================================================================
  :class:`LoopSpherical`    3     force, world axes
  :class:`LoopRevolute`     5     force, world axes; moments about ``z1 x x2``, ``z1 x y2``
  :class:`LoopFixed`        6     force, world axes; moment (frame-2 axes when assembled)
  :class:`LoopPrismatic`    5     force along ``x2``, ``y2``; moment as LoopFixed
  :class:`LoopCylindrical`  4     force along ``x2``, ``y2``; moments about ``z1 x x2``, ``z1 x y2``
  :class:`LoopUniversal`    4     force, world axes; moment about ``x1 x y2`` (the cross's pins)
  :class:`LoopPlanar`       3     force along ``z2``; moments about ``z1 x x2``, ``z1 x y2``
  ========================  ====  ==================================================================

- :class:`KnifeEdge`, :class:`RollingDisc`, :class:`Velocity`: non-holonomic constraints, eq. (2.70)
  given at velocity level (no position equation; their ``violation`` rows read 0). ``lambda``: the
  lateral blade force (N); the contact force (N); for a user :class:`Velocity` constraint the
  multipliers whose generalized force is ``W lambda``.

Redundant equations (a planar loop closed by a 3-D joint) are allowed: the solver gives dependent
rows zero multipliers.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Any, Callable, Sequence

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


def _three_functions(fs, callbacks: list, what: str, meaning: str) -> list:
    """Three time functions (numbers, mechsys.functions objects or callables f(t)); a wrong count
    is left to the engine, which names the constraint and the key."""
    if isinstance(fs, (str, bytes, dict)) or not hasattr(fs, "__len__"):
        raise ModelError(f"{what}: expected a sequence of 3 time functions ({meaning}), got {fs!r}")
    return [functions.describe(f, callbacks, f"{what}[{k}]") for k, f in enumerate(fs)]


@dataclass
class PrescribedBody:
    """Prescribed motion of a frame on a body (a rheonomic driving constraint): its origin follows
    ``position = (f_x, f_y, f_z)`` (world axes, m) and, if ``orientation = (f_a, f_b, f_c)`` is given,
    its orientation follows those Cardan angles x-y-z (``A = Rx(a) Ry(b) Rz(c)``, rad). Each ``f``
    is a number, a :mod:`mechsys.functions` object or a callable ``f(t)`` (derivatives by central
    differences, slow). ``frame``: a :class:`mechsys.Frame` or a position on the body (default:
    the body frame). 3 or 6 equations: ``lambda[0:3]`` is the driving force on the body at the frame
    origin (N, world axes), ``lambda[3:6]`` the driving moment (N m, world axes)."""

    name: str
    body: Any
    position: Sequence[Any]
    orientation: Sequence[Any] | None = None
    frame: Any = None

    def describe(self, callbacks: list) -> dict:
        w = f"constraint '{self.name}'"
        d = {
            "type": "prescribed_body",
            "name": self.name,
            "body": _name(self.body),
            "frame": _frame(self.frame, f"{w}.frame"),
            "position": _three_functions(self.position, callbacks, f"{w}.position", "x, y, z"),
        }
        if self.orientation is not None:
            d["orientation"] = _three_functions(self.orientation, callbacks, f"{w}.orientation", "Cardan angles x-y-z")
        return d


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
class LoopPrismatic(_Loop):
    """Loop-closing slider along the z-axis of ``frame2``: the origin of ``frame1`` stays on that
    axis and the orientations coincide. 5 equations: ``lambda[0:2]`` the force on body 1 along the
    x- and y-axes of frame 2 (N), ``lambda[2:5]`` the moment rows of :class:`LoopFixed` (N m)."""

    _type = "loop_prismatic"


@dataclass
class LoopCylindrical(_Loop):
    """Loop-closing cylindrical joint: the origin of ``frame1`` stays on the z-axis of ``frame2``
    and the z-axes stay parallel (sliding along and turning about it are free). 4 equations:
    ``lambda[0:2]`` the force on body 1 along x2 and y2 (N), ``lambda[2:4]`` the moments (N m)
    about ``z1 x x2`` and ``z1 x y2``."""

    _type = "loop_cylindrical"


@dataclass
class LoopUniversal(_Loop):
    """Loop-closing universal (Hooke) joint: the origins coincide and the cross's pins, the x-axis
    of ``frame1`` (fixed in body 1) and the y-axis of ``frame2`` (fixed in body 2), stay
    perpendicular; the shafts are the z-axes (aligned when the frames coincide). 4 equations:
    ``lambda[0:3]`` the force on body 1 (N, world axes), ``lambda[3]`` the moment (N m) about
    ``x1 x y2``."""

    _type = "loop_universal"


@dataclass
class LoopPlanar(_Loop):
    """Loop-closing planar joint: the z-axes stay parallel and the origin of ``frame1`` stays in
    the x-y plane of ``frame2``. 3 equations: ``lambda[0]`` the force on body 1 along z2 (N),
    ``lambda[1:3]`` the moments (N m) about ``z1 x x2`` and ``z1 x y2``."""

    _type = "loop_planar"


@dataclass
class Velocity:
    """A non-holonomic constraint written by the user, ``W(q, t)^T u + w(q, t) = 0`` (eq. 2.70),
    ``rows`` velocity equations without a position form. The callables:

    - ``W(t, q)`` returns ``W^T``, shape ``(rows, nu)`` (or ``(nu,)`` when ``rows == 1``): row k
      holds the coefficients of the generalized velocities u in equation k;
    - ``w(t, q)`` returns shape ``(rows,)`` (optional, zero if absent);
    - ``Wdot(t, q, u)`` returns ``d(W^T)/dt u + dw/dt``, shape ``(rows,)`` (optional). Without it
      the engine differentiates ``W(q, t)^T u + w(q, t)`` along the motion by central differences
      (q moved by ``q' = H(q) u``, t with it, u held; step ``eps^(1/3) / max(1, |u|_inf)``), which
      costs four extra calls per evaluation and is accurate to about 1e-9.

    ``lambda`` (one per row) are the multipliers: the generalized constraint force is ``W lambda``
    (in N or N m per unit of the row's coefficients: a row of direction cosines times velocities,
    as for a knife edge, gives a force in N). Each call is checked: a wrong shape, NaN or inf
    raises :class:`mechsys.CallbackError` naming the constraint. Slow (Python in the step loop)."""

    name: str
    rows: int
    W: Callable
    w: Callable | None = None
    Wdot: Callable | None = None

    def describe(self, callbacks: list) -> dict:
        where = f"constraint '{self.name}'"
        if isinstance(self.rows, bool) or not isinstance(self.rows, numbers.Integral):
            raise ModelError(f"{where}.rows: expected an integer, got {self.rows!r}")
        if self.rows < 1:
            raise ModelError(f"{where}.rows: must be >= 1, got {self.rows}")
        d: dict = {"type": "velocity", "name": self.name, "rows": int(self.rows)}
        for key, f, signature, required in (
            ("W", self.W, "W(t, q)", True),
            ("w", self.w, "w(t, q)", False),
            ("Wdot", self.Wdot, "Wdot(t, q, u)", False),
        ):
            if f is None and not required:
                continue
            if not callable(f):
                raise ModelError(f"{where}.{key}: expected a callable {signature}, got {type(f).__name__}")
            callbacks.append(f)
            d[key] = len(callbacks) - 1
        return d


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
    "PrescribedBody",
    "PointOnLine",
    "PointOnPlane",
    "LoopSpherical",
    "LoopRevolute",
    "LoopFixed",
    "LoopPrismatic",
    "LoopCylindrical",
    "LoopUniversal",
    "LoopPlanar",
    "Velocity",
    "KnifeEdge",
    "RollingDisc", "Baumgarte", "stabilization"]
