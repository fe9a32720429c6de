"""Force elements: point-to-point spring-dampers (linear, cubic, tabulated, progressive), forces and
torques on bodies, generalized forces on joints, Python force laws, and the damping elements of
section 2.6: six-component bushings, the squeeze-film slide way (eq. 2.211), the journal bearing
(eq. 2.212), the hydrodynamic journal bearing (short/long-bearing film forces) and Jenkins dry-friction elements with press-fit chains (eq. 2.215, Fig. 2.39).
Gravity is a property of the Model; joint springs and dampers are given with the joint
(``spring=``, ``damper=``).

Every element with a deflection records ``force/<name>/force`` (the force it carries along its
deflection, positive when it resists a positive deflection or deflection rate) and ``force/<name>/deflection``, so
``ms.linear.hysteresis`` can draw its loop.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from . import _core, functions
from .errors import ModelError, SettingsError
from .joints import JointDamper, JointSpring, RotaryDamper, RotarySpring, LinearDamper, LinearSpring  # noqa: F401
from .joints import Frame, _frame
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
    #: stop travel s (m) of a progressive elastomer law: k and d are divided by 1 - (delta/s)^2
    travel: float | None = None

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
        if self.travel is not None:
            d["travel"] = float(self.travel)
        return d


def _six(v, what: str) -> list[float]:
    """6 diagonal values or a 6x6 matrix, flattened row-major."""
    if v is None:
        return []
    a = np.asarray(v, dtype=float)
    if a.shape == (6, 6):
        return a.ravel().tolist()
    if a.shape == (6,):
        return a.tolist()
    if a.ndim == 0:
        raise ModelError(f"{what}: expected 6 values [x, y, z, alpha, beta, gamma] or a 6x6 matrix, got a number")
    raise ModelError(f"{what}: expected 6 values or a 6x6 matrix, got shape {a.shape}")


@dataclass
class Bushing:
    """Six-component bushing between ``frame1`` on ``body1`` and ``frame2`` on ``body2``.

    The deflection x = [dr; theta] (translation and rotation vector of frame 2 relative to frame 1,
    frame-1 components) and its rate v = [dr_dot; omega_rel] (the translation's rate and frame 2's
    angular velocity relative to frame 1, frame-1 components) give the wrench -K x - D v on frame 2
    (the rotational stiffness part through the rotation vector's Jacobian, so that it stays
    conservative) and its opposite on body1. The signal ``force/<name>/force`` records K x + D v.
    ``k``, ``d``: 6 diagonal values (N/m, N/m, N/m, N m/rad, ...) or symmetric 6x6 matrices.
    ``travel``: 6 stop travels (m, rad) making each component progressive, as an elastomer mount:
    k_i and d_i are divided by 1 - (x_i/s_i)^2 (diagonal k and d only).
    """

    name: str
    body1: Any
    body2: Any
    frame1: Any = None
    frame2: Any = None
    k: Any = None
    d: Any = None
    travel: Sequence[float] | None = None

    def describe(self, callbacks: list) -> dict:
        w = f"force '{self.name}'"
        d = {
            "type": "bushing",
            "name": self.name,
            "body1": _name(self.body1),
            "frame1": _frame(self.frame1 if self.frame1 is not None else Frame(), f"{w}.frame1"),
            "body2": _name(self.body2),
            "frame2": _frame(self.frame2 if self.frame2 is not None else Frame(), f"{w}.frame2"),
            "k": _six(self.k, f"{w}.k"),
            "d": _six(self.d, f"{w}.d"),
        }
        if self.travel is not None:
            t = np.asarray(self.travel, dtype=float)
            if t.shape != (6,):
                raise ModelError(f"{w}.travel: expected 6 stop travels, got shape {t.shape}")
            d["travel"] = t.tolist()
        return d


@dataclass
class SqueezeFilm:
    """Squeeze-film slide way (eq. 2.211): an oil film of gap h = gap + n . (p2 - p1) between the
    surface of ``body1`` through ``point1`` with normal ``normal`` (body1 frame) and ``point2`` on
    ``body2``; the film resists the gap rate with F = 12 eta A l^2 / h^3 * h_dot.

    ``eta`` dynamic viscosity (Pa s), ``length`` the half-length l of the way (m), ``area`` the gap
    cross-section A (m^2), ``gap`` h0 (m). Valid for a thin film: 0 < h <= length/10 (refused
    outside, at input and during a run).
    """

    name: str
    body1: Any
    body2: Any
    normal: Sequence[float]
    eta: float
    length: float
    area: float
    gap: float
    point1: Sequence[float] = (0.0, 0.0, 0.0)
    point2: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, callbacks: list) -> dict:
        w = f"force '{self.name}'"
        return {
            "type": "squeeze_film",
            "name": self.name,
            "body1": _name(self.body1),
            "point1": _vec(self.point1, f"{w}.point1"),
            "normal": _vec(self.normal, f"{w}.normal"),
            "body2": _name(self.body2),
            "point2": _vec(self.point2, f"{w}.point2"),
            "eta": float(self.eta),
            "length": float(self.length),
            "area": float(self.area),
            "gap": float(self.gap),
        }


@dataclass
class JournalBearing:
    """Journal-bearing friction torque (eq. 2.212, Reynolds-Sommerfeld) on a revolute ``joint``:
    M = 2(1 + 2 eps^2) / (sqrt(1 - eps^2)(1 + eps^2/2)) * pi r0^2 b eta / a * r0 Omega, opposing
    the shaft speed Omega. Petroff's law at eps = 0.

    ``radius`` r0, ``length`` b, ``clearance`` a (m; a <= r0/50), ``eta`` (Pa s),
    ``eccentricity`` eps in [0, 0.95].
    """

    name: str
    joint: Any
    radius: float
    length: float
    clearance: float
    eta: float
    eccentricity: float = 0.0

    def describe(self, callbacks: list) -> dict:
        return {
            "type": "journal_bearing",
            "name": self.name,
            "joint": _name(self.joint),
            "radius": float(self.radius),
            "length": float(self.length),
            "clearance": float(self.clearance),
            "eta": float(self.eta),
            "eccentricity": float(self.eccentricity),
        }

    def coefficient(self) -> float:
        """Torque per shaft speed c (N m s/rad) of eq. 2.212."""
        return journal_bearing_coefficient(self.radius, self.length, self.clearance, self.eta, self.eccentricity)


def journal_bearing_coefficient(radius: float, length: float, clearance: float, eta: float, eccentricity: float = 0.0) -> float:
    """c of eq. 2.212 with the wall speed u_w = r0 Omega, so that M = c Omega (N m s/rad): the
    engine's own law. Parameters outside the element's validity raise a SettingsError."""
    return _core.journal_bearing_coefficient(float(radius), float(length), float(clearance), float(eta),
                                             float(eccentricity))


def squeeze_film_coefficient(eta: float, length: float, area: float, gap: float) -> float:
    """12 eta A l^2 / h^3 of eq. 2.211: the film force per gap rate at gap h (N s/m), from the
    engine's law."""
    if not (np.isfinite(gap) and gap > 0):
        raise SettingsError(f"squeeze_film_coefficient: gap must be > 0, got {gap}")
    return _core.squeeze_film_coefficient(float(eta), float(length), float(area)) / float(gap) ** 3


@dataclass
class HydrodynamicBearing:
    """Hydrodynamic journal bearing: the oil film between a journal and its shell.

    ``journal_frame`` (on ``journal``) has its origin on the journal axis at mid-length;
    ``shell_frame`` (on ``shell``, which may be the ground) has its origin at the bearing centre and
    its z axis along the bearing axis (rotate it with a :class:`mechsys.Frame` for another axis).
    With e the journal centre's offset from the shell centre in the shell x-y plane, eps = |e|/c,
    its rate seen in the shell and the journal's spin relative to the shell about the shell z axis,
    the film pushes the journal with the short-bearing (``theory="short"``, Ocvirk, L/D <~ 1/2) or
    long-bearing (``"long"``, Sommerfeld, L/D >~ 2) force of a pi-film, including the squeeze
    and whirl terms, and brakes the spin with the friction torque of eq. 2.212. The shell carries
    the opposite force and torque. See :mod:`mechsys.bearings` for the steady operating point and
    the stiffness and damping coefficients.

    ``radius`` R, ``length`` L, ``clearance`` c (m; 0 < c < R, thin film: c << R), ``viscosity``
    eta (Pa s). A journal that reaches the shell (eps >= 1) stops a run with a SolverError naming
    the element and the time.

    Records ``force/<name>/force`` (film force on the journal, shell-frame x, y; N),
    ``force/<name>/torque`` (N m, about the shell axis), ``force/<name>/eccentricity`` (eps),
    ``force/<name>/position_angle`` (angle of e from the shell x axis, rad) and
    ``force/<name>/attitude_angle`` (from the film force's load line to the line of centres, along
    the rotation, rad).
    """

    name: str
    journal: Any
    shell: Any
    radius: float
    length: float
    clearance: float
    viscosity: float
    theory: str = "short"
    journal_frame: Any = None
    shell_frame: Any = None

    def describe(self, callbacks: list) -> dict:
        w = f"force '{self.name}'"
        if self.theory not in ("short", "long"):
            raise ModelError(f"{w}.theory: expected 'short' or 'long', got {self.theory!r}")
        d = {
            "type": "hydrodynamic_bearing",
            "name": self.name,
            "journal": _name(self.journal),
            "journal_frame": _frame(self.journal_frame, f"{w}.journal_frame"),
            "shell": _name(self.shell),
            "shell_frame": _frame(self.shell_frame, f"{w}.shell_frame"),
            "theory": self.theory,
        }
        for key in ("radius", "length", "clearance", "viscosity"):
            v = getattr(self, key)
            try:
                d[key] = float(v)
            except (TypeError, ValueError):
                raise ModelError(f"{w}.{key}: expected a number, got {v!r}") from None
            if not np.isfinite(d[key]):
                raise ModelError(f"{w}.{key}: must be a finite number, got {d[key]}")
        return d


@dataclass
class Jenkins:
    """Jenkins dry-friction elements (a spring ``k`` in series with a Coulomb slider, eq. 2.215) on
    velocity ``index`` of ``joint`` (the relative displacement of shaft and hub).

    ``slip``: one slip force (or torque) per element. Without ``shaft_stiffness`` the elements act
    in parallel (one element: the classic Jenkins element; several: a Masing/Iwan model). With
    it they form a press fit (Fig. 2.39): massless shaft segments of that stiffness, each held to
    the hub by one element, loaded at the first. The sliders are solved exactly as a linear
    complementarity problem (Lemke), not with a smoothed sign function. ``offset``: the joint
    coordinate where all springs are relaxed.
    """

    name: str
    joint: Any
    k: float
    slip: float | Sequence[float]
    shaft_stiffness: float | None = None
    index: int = 0
    offset: float = 0.0

    def describe(self, callbacks: list) -> dict:
        d = {
            "type": "jenkins",
            "name": self.name,
            "joint": _name(self.joint),
            "index": int(self.index),
            "k": float(self.k),
            "slip": [float(x) for x in np.atleast_1d(self.slip)],
            "offset": float(self.offset),
        }
        if self.shaft_stiffness is not None:
            d["shaft_stiffness"] = float(self.shaft_stiffness)
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
class Servo:
    """A servo actuator on a joint (velocity ``index`` of it): ``mode="position"`` drives the joint
    coordinate to ``reference`` r(t) with the motor torque ``kp n (r - q) + kd n (r' - q')``;
    ``mode="velocity"`` drives the joint velocity to r(t) with ``kd n (r - q')``. ``gear`` n is the
    ratio of motor to joint turns (the joint gets n times the motor torque); ``max_torque`` clamps
    the motor torque. ``reference``: a number, a mechsys.functions object or a callable f(t)
    (position servos use its derivative as the reference rate). Recorded as
    ``force/<name>/force`` (the torque or force on the joint) and ``force/<name>/deflection`` (the
    tracking error r - q, or r - q')."""

    name: str
    joint: Any
    reference: Any
    kp: float = 0.0
    kd: float = 0.0
    mode: str = "position"
    max_torque: float | None = None
    gear: float = 1.0
    index: int = 0

    def describe(self, callbacks: list) -> dict:
        w = f"force '{self.name}'"
        ref = functions.describe(self.reference, callbacks, f"{w}.reference")
        if ref is None:
            raise ModelError(f"{w}.reference: give the reference (a number, a mechsys.functions object or f(t))")
        d = {
            "type": "servo",
            "name": self.name,
            "joint": _name(self.joint),
            "index": int(self.index),
            "mode": str(self.mode),
            "kp": float(self.kp),
            "kd": float(self.kd),
            "reference": ref,
            "gear": float(self.gear),
        }
        if self.max_torque is not None:
            d["max_torque"] = float(self.max_torque)
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
    "Servo",
    "SpringDamper",
    "Bushing",
    "SqueezeFilm",
    "JournalBearing",
    "HydrodynamicBearing",
    "Jenkins",
    "journal_bearing_coefficient",
    "squeeze_film_coefficient",
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
