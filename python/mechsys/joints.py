"""Joints of the kinematic tree.

Each joint connects a parent body (``model.ground`` for the inertial frame) to a child body; the
joint frame sits at ``parent_frame`` on the parent and at ``child_frame`` on the child (both
:class:`mechsys.Frame` or a position tuple). Coordinates and velocities per type:

============  ==  ==  =====================================================  ==========================
type          nq  nu  q                                                      u
============  ==  ==  =====================================================  ==========================
Fixed         0   0   -                                                      -
Revolute      1   1   angle about ``axis`` (rad)                             rate
Prismatic     1   1   displacement along ``axis`` (m)                        rate
Cylindrical   2   2   angle, displacement about/along ``axis``               rates
Universal     2   2   angle about ``axis`` (parent), then ``axis2`` (child)  rates
Spherical     4   3   unit quaternion [w, x, y, z]                           angular velocity, child frame
Planar        3   3   x, y in the joint frame's x-y plane, angle about z     rates
Free          7   6   position (parent frame), quaternion                    velocity, angular velocity, child frame
============  ==  ==  =====================================================  ==========================
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from .errors import ModelError


@dataclass
class Frame:
    """A frame on a body: origin ``position`` and orientation, all relative to the body frame.

    Give at most one of ``rotation`` (3x3 matrix A_BF or quaternion [w, x, y, z]),
    ``cardan`` (x-y-z angles), ``euler`` (z-x-z angles) or ``rotvec`` (axis times angle).
    """

    position: Sequence[float] = (0.0, 0.0, 0.0)
    rotation: Any = None
    cardan: Sequence[float] | None = None
    euler: Sequence[float] | None = None
    rotvec: Sequence[float] | None = None

    def describe(self, what: str = "Frame") -> dict:
        d: dict = {"position": _vec3(self.position, f"{what}.position")}
        given = [k for k in ("rotation", "cardan", "euler", "rotvec") if getattr(self, k) is not None]
        if len(given) > 1:
            raise ModelError(f"Frame: give only one of rotation, cardan, euler, rotvec (got {given})")
        if self.rotation is not None:
            try:
                r = np.asarray(self.rotation, dtype=float)
            except (TypeError, ValueError):
                raise ModelError(f"{what}.rotation: expected a 3x3 matrix or a quaternion, got {self.rotation!r}") from None
            d["rotation"] = r.tolist()
        elif given:
            k = given[0]
            d["rotation"] = {k: _vec3(getattr(self, k), f"{what}.{k}")}
        return d


def _vec3(v, what: str) -> list[float]:
    """Three floats, or a ModelError naming the item and key."""
    try:
        a = np.asarray(v, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected 3 numbers, got {v!r}") from None
    return [float(x) for x in a]


def _floats(v, what: str) -> list[float]:
    """One or more floats, or a ModelError naming the item and key."""
    try:
        a = np.atleast_1d(np.asarray(v, dtype=float)).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected a number or a list of numbers, got {v!r}") from None
    return [float(x) for x in a]


def _frame(f, what: str) -> dict:
    if f is None:
        return Frame().describe()
    if isinstance(f, Frame):
        return f.describe(what)
    if isinstance(f, dict):
        return f
    try:
        return Frame(position=tuple(float(x) for x in f)).describe()
    except Exception:  # noqa: BLE001 - any malformed value gets the same clear message
        raise ModelError(f"{what}: expected a mechsys.Frame or a position (x, y, z), got {f!r}") from None


def _name(x) -> str:
    return x if isinstance(x, str) else getattr(x, "name", str(x))


@dataclass
class JointSpring:
    """Linear spring on each joint coordinate: tau = -k (q - q_free)."""

    k: float | Sequence[float]
    q_free: float | Sequence[float] | None = None

    def describe(self) -> dict:
        d = {"k": _floats(self.k, "spring.k")}
        if self.q_free is not None:
            d["q_free"] = _floats(self.q_free, "spring.q_free")
        return d


@dataclass
class JointDamper:
    """Linear viscous damper on each joint velocity: tau = -d u."""

    d: float | Sequence[float]

    def describe(self) -> dict:
        return {"d": _floats(self.d, "damper.d")}


@dataclass
class Joint:
    """Base of all joint types; use the subclasses."""

    name: str
    parent: Any
    child: Any
    parent_frame: Any = None
    child_frame: Any = None
    q0: Any = None
    u0: Any = None
    spring: JointSpring | None = None
    damper: JointDamper | None = None
    type: str = field(default="", init=False)

    def _extra(self) -> dict:
        return {}

    def describe(self) -> dict:
        d = {
            "name": self.name,
            "type": self.type,
            "parent": _name(self.parent),
            "child": _name(self.child),
            "parent_frame": _frame(self.parent_frame, f"joint '{self.name}'.parent_frame"),
            "child_frame": _frame(self.child_frame, f"joint '{self.name}'.child_frame"),
        }
        w = f"joint '{self.name}'"
        try:
            d.update(self._extra())
        except ModelError as e:
            raise ModelError(f"{w}.{e}") from None
        if self.q0 is not None:
            d["q0"] = _floats(self.q0, f"{w}.q0")
        if self.u0 is not None:
            d["u0"] = _floats(self.u0, f"{w}.u0")
        try:
            if self.spring is not None:
                d["spring"] = self.spring.describe()
            if self.damper is not None:
                d["damper"] = self.damper.describe()
        except ModelError as e:
            raise ModelError(f"{w}.{e}") from None
        return d


def _axis(a, key: str = "axis") -> list[float]:
    return _vec3(a, key)


@dataclass
class Fixed(Joint):
    """Rigid connection (0 DOF)."""

    def __post_init__(self):
        self.type = "fixed"


@dataclass
class Revolute(Joint):
    """Rotation about ``axis`` (joint frame), 1 DOF."""

    axis: Sequence[float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        self.type = "revolute"

    def _extra(self):
        return {"axis": _axis(self.axis)}


@dataclass
class Prismatic(Joint):
    """Translation along ``axis`` (joint frame), 1 DOF."""

    axis: Sequence[float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        self.type = "prismatic"

    def _extra(self):
        return {"axis": _axis(self.axis)}


@dataclass
class Cylindrical(Joint):
    """Rotation about and translation along ``axis``, 2 DOF (q = [angle, displacement])."""

    axis: Sequence[float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        self.type = "cylindrical"

    def _extra(self):
        return {"axis": _axis(self.axis)}


@dataclass
class Universal(Joint):
    """Cardan joint: rotation about ``axis`` (parent), then about ``axis2`` (child), 2 DOF."""

    axis: Sequence[float] = (1.0, 0.0, 0.0)
    axis2: Sequence[float] = (0.0, 1.0, 0.0)

    def __post_init__(self):
        self.type = "universal"

    def _extra(self):
        return {"axis": _axis(self.axis), "axis2": _axis(self.axis2, "axis2")}


@dataclass
class Spherical(Joint):
    """Ball joint, 3 DOF; q is a unit quaternion [w, x, y, z], u the child's angular velocity."""

    def __post_init__(self):
        self.type = "spherical"


@dataclass
class Path(Joint):
    """Path coordinate (section 2.2.6), 1 DOF: the child frame's origin moves along a helix about
    the joint frame's z-axis, ``q`` = its arc length s (m), ``u`` = ds/dt (m/s). ``radius`` (m,
    > 0), ``pitch``: rise per turn (m; 0, the default, is a circle; negative: left-handed).
    ``oriented``: the child frame turns with the curve's trihedral (x along the tangent t, y the
    principal normal n towards the axis, z the binormal b), else it keeps the parent's axes (a
    bead). At s = 0 the point is at (radius, 0, 0). Curvature radius / L^2, torsion c / L^2 with
    c = pitch / 2 pi, L^2 = radius^2 + c^2."""

    radius: float = 1.0
    pitch: float = 0.0
    oriented: bool = True

    def __post_init__(self):
        self.type = "path"

    def _extra(self):
        for key in ("radius", "pitch"):
            v = getattr(self, key)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
                raise ModelError(f"joint '{self.name}'.{key}: expected a number, got {v!r}")
        if not isinstance(self.oriented, (bool, np.bool_)):
            raise ModelError(f"joint '{self.name}'.oriented: expected true or false, got {self.oriented!r}")
        return {"radius": float(self.radius), "pitch": float(self.pitch), "oriented": bool(self.oriented)}

    def curvature(self) -> float:
        """kappa = R / (R^2 + c^2) (1/m)."""
        c = self.pitch / (2 * np.pi)
        return self.radius / (self.radius**2 + c**2)

    def torsion(self) -> float:
        """tau = c / (R^2 + c^2) (1/m)."""
        c = self.pitch / (2 * np.pi)
        return c / (self.radius**2 + c**2)


@dataclass
class Planar(Joint):
    """Planar joint in the joint frame's x-y plane, 3 DOF (q = [x, y, angle])."""

    def __post_init__(self):
        self.type = "planar"


@dataclass
class Free(Joint):
    """Six degrees of freedom; q = [x, y, z, qw, qx, qy, qz], u = [v_B, omega_B] (child frame)."""

    def __post_init__(self):
        self.type = "free"


# Aliases engineers coming from other tools look for.
RotaryDamper = JointDamper
RotarySpring = JointSpring
LinearDamper = JointDamper
LinearSpring = JointSpring

__all__ = [
    "Frame",
    "Joint",
    "JointSpring",
    "JointDamper",
    "Fixed",
    "Revolute",
    "Prismatic",
    "Cylindrical",
    "Universal",
    "Spherical",
    "Planar",
    "Path",
    "Free",
    "RotaryDamper",
    "RotarySpring",
    "LinearDamper",
    "LinearSpring",
]
