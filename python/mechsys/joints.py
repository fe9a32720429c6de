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
Path          1   1   arc length s along a helix, clothoid or spline (m)     ds/dt
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
    """Path coordinate (section 2.2.6), 1 DOF: the child frame's origin moves along a curve in the
    parent joint frame, ``q`` = its arc length s (m), ``u`` = ds/dt (m/s). ``oriented``: the child
    frame turns with the curve's frame [t n b] (x along the tangent t), else it keeps the parent's
    axes (a bead). The curve (``curve``):

    - ``"helix"`` (the default; ``Path(...)`` or :meth:`helix`): about the joint frame's z-axis,
      ``radius`` (m, > 0), ``pitch``: rise per turn (m; 0, the default, is a circle; negative:
      left-handed); at s = 0 at (radius, 0, 0). n points to the axis. Curvature radius / L^2,
      torsion c / L^2 with c = pitch / 2 pi, L^2 = radius^2 + c^2.
    - ``"clothoid"`` (:meth:`clothoid`): the Euler spiral in the x-y plane, curvature
      kappa0 + s / A^2, from the origin along x; b = z and n = z x t (the left normal, so the
      curvature is signed and the frame passes smoothly through kappa = 0).
    - ``"spline"`` (:meth:`spline`): the C2 cubic through ``points``, ``closed`` or with natural
      ends (straight on along the end tangents beyond them).
    - ``"hermite"`` (:meth:`function`): a user's function r(p) sampled with its derivatives.

    For the splines b is the part of a reference direction ``up`` across the tangent and
    n = b x t: for a plane curve (default ``up``: the plane's normal) the Frenet trihedral with
    signed curvature, for a space curve a frame without the Frenet frame's flips where the
    curvature vanishes (see docs/usage.md, "Path coordinates")."""

    radius: float = 1.0
    pitch: float = 0.0
    oriented: bool = True
    curve: str = "helix"
    A: float | None = None
    kappa0: float = 0.0
    points: Any = None
    closed: bool = False
    up: Sequence[float] | None = None
    f: Any = None
    p_range: Sequence[float] | None = None
    samples: int = 200
    df: Any = None
    d2f: Any = None
    _sampled: Any = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        self.type = "path"

    # ---- the curves ------------------------------------------------------------------------------
    @classmethod
    def helix(cls, name: str, parent, child, radius: float, pitch: float = 0.0, oriented: bool = True, **joint) -> "Path":
        """A helix about the joint frame's z-axis (a circle for ``pitch = 0``); ``joint``: the
        other joint arguments (``parent_frame``, ``q0``, ``u0``, ``spring``, ...)."""
        return cls(name, parent, child, radius=radius, pitch=pitch, oriented=oriented, **joint)

    @classmethod
    def clothoid(cls, name: str, parent, child, A: float, kappa0: float = 0.0, oriented: bool = True, **joint) -> "Path":
        """The clothoid kappa(s) = kappa0 + s / A^2 in the joint frame's x-y plane, from the origin
        along x (A in m, > 0; kappa0 in 1/m)."""
        return cls(name, parent, child, curve="clothoid", A=A, kappa0=kappa0, oriented=oriented, **joint)

    @classmethod
    def spline(cls, name: str, parent, child, points, closed: bool = False, up=None, oriented: bool = True,
               **joint) -> "Path":
        """The C2 cubic spline through ``points`` ((n, 3), joint frame; chord-length knots), open
        with natural ends (at least 2 points) or ``closed`` (at least 3, each given once). ``up``:
        the frame's reference direction (default: the points' plane normal, or the direction the
        path runs along least)."""
        return cls(name, parent, child, curve="spline", points=points, closed=closed, up=up, oriented=oriented, **joint)

    @classmethod
    def function(cls, name: str, parent, child, f, p_range, samples: int = 200, df=None, d2f=None, closed: bool = False,
                 up=None, oriented: bool = True, **joint) -> "Path":
        """A curve given as a function ``f(p) -> (x, y, z)`` over ``p_range = (p0, p1)``: sampled
        at ``samples`` equally spaced p when the model is built, with its first and second
        derivatives (``df``, ``d2f`` if given; else exactly by Taylor arithmetic, or the complex
        step, or differences), into a quintic Hermite spline that the engine re-parameterizes by
        arc length. p need not be the arc length: the joint's s runs from 0 at f(p0).
        ``closed``: f is periodic over p_range. The interpolation error is at most
        h^6 max|r^(6)| / 46080 (h the sample spacing in p) and :attr:`sampling_error` gives the
        one measured at the interval midpoints."""
        return cls(name, parent, child, curve="hermite", f=f, p_range=p_range, samples=samples, df=df, d2f=d2f,
                   closed=closed, up=up, oriented=oriented, **joint)

    # ---- description -----------------------------------------------------------------------------
    def _number(self, key: str, value) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
            raise ModelError(f"{key}: expected a number, got {value!r}")
        if not np.isfinite(value):
            raise ModelError(f"{key}: must be a finite number, got {value}")
        return float(value)

    def _flag(self, key: str, value) -> bool:
        if not isinstance(value, (bool, np.bool_)):
            raise ModelError(f"{key}: expected true or false, got {value!r}")
        return bool(value)

    def _samples(self) -> dict:
        """The sampled function (once per function and settings)."""
        from ._pathsample import sample

        key = (id(self.f), tuple(self.p_range) if self.p_range is not None else None, self.samples, id(self.df), id(self.d2f))
        if self._sampled is None or self._sampled[0] != key:
            if self.f is None or self.p_range is None:
                raise ModelError("f: a function path needs f and p_range")
            self._sampled = (key, sample(self.f, self.p_range, self.samples, self.df, self.d2f))
        return self._sampled[1]

    def _extra(self):
        curve = self.curve.lower() if isinstance(self.curve, str) else self.curve
        d: dict = {"oriented": self._flag("oriented", self.oriented)}
        if curve in ("helix", "circle"):
            d.update(radius=self._number("radius", self.radius), pitch=self._number("pitch", self.pitch))
            return d
        d["curve"] = curve
        if curve == "clothoid":
            if self.A is None:
                raise ModelError("A: a clothoid needs its parameter A (m)")
            d.update(A=self._number("A", self.A), kappa0=self._number("kappa0", self.kappa0))
        elif curve == "spline":
            try:
                pts = np.asarray(self.points, dtype=float)
            except (TypeError, ValueError):
                raise ModelError(f"points: expected a list of (x, y, z) points, got {self.points!r}") from None
            if pts.ndim != 2 or pts.shape[1] not in (2, 3):
                raise ModelError(f"points: expected a list of (x, y, z) points, got shape {pts.shape}")
            if pts.shape[1] == 2:
                pts = np.c_[pts, np.zeros(len(pts))]
            bad = np.flatnonzero(~np.all(np.isfinite(pts), axis=1))
            if bad.size:
                raise ModelError(f"points[{bad[0]}]: must be finite, got {pts[bad[0]].tolist()}")
            d.update(points=pts.tolist(), closed=self._flag("closed", self.closed))
        elif curve == "hermite":
            smp = self._samples()
            d.update({k: np.asarray(smp[k]).tolist() for k in ("parameters", "points", "tangents", "second_derivatives")})
            d["closed"] = self._flag("closed", self.closed)
        else:
            raise ModelError(f"curve: unknown path curve {self.curve!r} (helix, clothoid, spline or hermite)")
        if self.up is not None:
            d["up"] = _vec3(self.up, "up")
        return d

    @property
    def sampling_error(self) -> float | None:
        """For a function path: the largest distance (m) between the spline and f at the middles
        of the sample intervals; None otherwise."""
        return self._sample_info("error")

    @property
    def derivatives_by(self) -> str | None:
        """For a function path: how the derivatives were found (user, taylor, complex step,
        differences); None otherwise."""
        return self._sample_info("method")

    def _sample_info(self, key: str):
        if self.curve != "hermite":
            return None
        try:
            return self._samples()[key]
        except ModelError as e:
            raise ModelError(f"joint '{self.name}'.{e}") from None

    # ---- geometry --------------------------------------------------------------------------------
    def geometry(self, s) -> dict:
        """The curve at arc lengths ``s`` as the engine has it: position (n, 3), frame (n, 3, 3;
        columns t, n, b), tangent_rate (dt/ds), omega (the frame's Darboux vector in its own axes)
        and omega_rate, curvature and torsion (n), in the parent joint frame."""
        import json

        from . import _core

        d = self.describe()
        return _core.path_curve_geometry(json.dumps(d), np.ascontiguousarray(np.atleast_1d(s), dtype=float))

    def curvature(self, s=None):
        """Curvature (1/m) at arc length(s) ``s`` (signed for a plane curve, about b); for a helix
        the constant R / (R^2 + c^2) (s may be omitted)."""
        if s is None and self.curve in ("helix", "circle"):
            c = self.pitch / (2 * np.pi)
            return self.radius / (self.radius**2 + c**2)
        return self._at(s, "curvature")

    def torsion(self, s=None):
        """Torsion (1/m) at ``s``; for a helix the constant c / (R^2 + c^2)."""
        if s is None and self.curve in ("helix", "circle"):
            c = self.pitch / (2 * np.pi)
            return c / (self.radius**2 + c**2)
        return self._at(s, "torsion")

    def _at(self, s, key: str):
        if s is None:
            raise ModelError(f"joint '{self.name}': the {key} of a {self.curve} path depends on s; give s")
        v = self.geometry(s)[key]
        return float(v[0]) if np.ndim(s) == 0 else v


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
