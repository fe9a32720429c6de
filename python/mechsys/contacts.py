"""Contacts (section 2.5): a contour on each of two bodies, with the normal law (Signorini's
unilateral law, or ``laws.Bilateral`` to hold it closed), a friction law and an impact law from
:mod:`mechsys.laws`.

>>> c = Contact("tip", arm.contour(contours.Circle(radius=0.02, center=(0.4, 0, 0))),
...             m.ground.contour(contours.Line(point=(0.3, -0.5, 0), normal=(-1, 0, 0))),
...             friction=laws.Coulomb(mu=0.2, mu0=0.25), impact=laws.Poisson(eps=0.6))
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import laws
from ._pathsample import _Taylor2
from .contours import OnBody
from .errors import ModelError


@dataclass
class Contact:
    """A contact between two contours on bodies (``body.contour(...)``)."""

    name: str
    first: OnBody
    second: OnBody
    normal: Any = field(default_factory=laws.Signorini)
    friction: Any = None
    impact: Any = None
    #: contact points a pair with a parametric contour looks for (1 to 8), e.g. both flanks
    #: of a groove or several gear teeth; ``None``: one
    points: Any = None

    def describe(self, callbacks: list) -> dict:
        what = f"contact '{self.name}'"
        for k, side in (("first", self.first), ("second", self.second)):
            if not isinstance(side, OnBody):
                raise ModelError(f"{what}.{k}: expected a contour on a body (body.contour(ms.contours.X(...))), got {type(side).__name__}")
        d = {
            "name": self.name,
            "body1": self.first.body,
            "contour1": self.first.contour.describe(f"{what}.contour1"),
            "body2": self.second.body,
            "contour2": self.second.contour.describe(f"{what}.contour2"),
        }
        if isinstance(self.normal, laws.COMPLIANT):
            return _compliant(d, self, what, callbacks)
        normal = _normal_law(what, self.normal, self.friction, self.impact)
        if normal is not None:
            d["normal"] = normal
        if self.friction is not None:
            if isinstance(self.friction, laws.LuGre):
                raise ModelError(f"{what}.friction: the LuGre bristle law acts on compliant contacts (normal=laws.Hertz(), "
                                 "laws.KelvinVoigt(k), ...); a rigid contact takes Coulomb, Stribeck or FrictionTable")
            if not isinstance(self.friction, (laws.Coulomb, laws.Stribeck, laws.FrictionTable)):
                raise ModelError(f"{what}.friction: expected a mechsys.laws friction law, got {type(self.friction).__name__}")
            d["friction"] = self.friction.describe(f"{what}.friction")
        if self.impact is not None:
            if not isinstance(self.impact, (laws.Newton, laws.Poisson)):
                raise ModelError(f"{what}.impact: expected mechsys.laws.Newton or Poisson, got {type(self.impact).__name__}")
            d["impact"] = self.impact.describe(f"{what}.impact")
        if self.points is not None:
            if isinstance(self.points, bool) or not isinstance(self.points, int) or not 1 <= self.points <= 8:
                raise ModelError(f"{what}.points: expected a whole number from 1 to 8, got {self.points!r}")
            d["points"] = int(self.points)
        return d


def _compliant(d: dict, c: "Contact", what: str, callbacks: list) -> dict:
    """The description of a compliant contact: its law, materials and friction; its restitution
    comes from the law, so it takes no impact law."""
    if c.impact is not None:
        raise ModelError(f"{what}.impact: a compliant contact takes no impact law (its restitution comes from its normal "
                         "law: HuntCrossley(eps=...), LankaraniNikravesh, Flores, or KelvinVoigt's damping)")
    d["normal"] = c.normal.describe(f"{what}.normal", callbacks)
    for k, side in (("material1", c.first), ("material2", c.second)):
        mat = getattr(side, "material", None)
        if mat is not None:
            if not isinstance(mat, laws.Material):
                raise ModelError(f"{what}.{k}: expected mechsys.Material(E, nu, density), got {type(mat).__name__}")
            d[k] = mat.describe(f"{what}.{k}")
    if c.friction is not None:
        if not isinstance(c.friction, (laws.Coulomb, laws.Stribeck, laws.FrictionTable, laws.LuGre)):
            raise ModelError(f"{what}.friction: expected a mechsys.laws friction law, got {type(c.friction).__name__}")
        d["friction"] = c.friction.describe(f"{what}.friction")
    if c.points is not None:
        if isinstance(c.points, bool) or not isinstance(c.points, int) or not 1 <= c.points <= 8:
            raise ModelError(f"{what}.points: expected a whole number from 1 to 8, got {c.points!r}")
        d["points"] = int(c.points)
    return d


def _normal_law(what: str, normal, friction, impact) -> dict | None:
    """The description of a contact's normal law (None for Signorini's, the default); a bilateral
    contact takes no friction or impact law."""
    if not isinstance(normal, (laws.Signorini, laws.Bilateral)):
        raise ModelError(f"{what}.normal: expected mechsys.laws.Signorini(), Bilateral() or a compliant law (KelvinVoigt, Hertz, "
                         f"HuntCrossley, LankaraniNikravesh, Flores, UserLaw), got {type(normal).__name__}")
    if isinstance(normal, laws.Signorini):
        return normal.describe(f"{what}.normal")
    for key, law in (("friction", friction), ("impact", impact)):
        if law is not None:
            raise ModelError(f"{what}.{key}: a bilateral contact is held closed and takes no {key} law "
                             "(laws.Bilateral(rolling=True) holds it without slip)")
    return normal.describe(f"{what}.normal")


def _law_fields(what: str, friction, impact) -> dict:
    d = {}
    if friction is not None:
        if not isinstance(friction, (laws.Coulomb, laws.Stribeck, laws.FrictionTable)):
            raise ModelError(f"{what}.friction: expected a mechsys.laws friction law, got {type(friction).__name__}")
        d["friction"] = friction.describe(f"{what}.friction")
    if impact is not None:
        if not isinstance(impact, (laws.Newton, laws.Poisson)):
            raise ModelError(f"{what}.impact: expected mechsys.laws.Newton or Poisson, got {type(impact).__name__}")
        d["impact"] = impact.describe(f"{what}.impact")
    return d


@dataclass
class ContactGroup:
    """Contacts among many contours with one declaration: every pair of ``members`` on different
    bodies may touch, and every member may touch every contour of ``against`` (the walls and
    floor of a container, say), all with one friction and one impact law.

    At every step a broad phase (sweep and prune over bounding boxes grown by the motion within
    the step) picks the pairs that can touch, and only those go to the narrow phase, so a group
    of N members costs about O(N) per step instead of the N(N-1)/2 explicit
    :class:`Contact` s it stands for. Needs the time-stepping scheme :class:`mechsys.MoreauJean`.

    >>> pile = ContactGroup("pile", members=[b.contour(contours.Sphere(radius=0.05)) for b in balls],
    ...                     against=[m.ground.contour(contours.Plane(normal=(0, 0, 1)))],
    ...                     friction=laws.Coulomb(mu=0.3), impact=laws.Newton(eps=0.2))

    Signals (``res[...]``): ``contact/<name>/closed`` (points closed in the last step before
    each sample), ``max_penetration`` (m, largest penetration at the step midpoints since the
    previous sample), ``impulse_n`` (N s, the group's normal impulses summed since the previous
    sample), ``lambda_n`` (N, the same over the sample interval: the total normal force),
    ``pairs`` (pairs kept by the broad phase), ``impulse_against`` (N s, (n, 3): the impulse the
    ``against`` contours exert on the members, normal and friction, world axes, summed since the
    previous sample) and ``force_against`` (N, the same over the interval: with a container at
    rest, the weight of its contents); the energy they take goes into
    ``energy/dissipated_impact`` and ``energy/dissipated_friction``.

    With a compliant ``normal`` law (``laws.Hertz()``, ``laws.HuntCrossley(eps=0.3)``,
    ``laws.KelvinVoigt(k, d)``, ...) and a ``material`` (or materials on the contours), every
    pair the broad phase finds carries that law as a force, in every scheme (DOPRI5, Radau5, RK4,
    MoreauJean, EventDriven); friction is regularized (``v_reg`` of the normal law), LuGre is refused; onsets
    are stepped over under error control rather than located. Signals: ``contact/<name>/touching``
    (pairs in contact), ``max_overlap`` (m), ``max_overlap_rate`` (m/s), ``force_n`` (N, sum of
    the normal forces), ``energy_elastic`` and ``energy_dissipated`` (J), ``pairs`` (kept by the
    broad phase), ``touching_points``, and the first touching points (two per member at most) as
    ``points``, ``point_forces`` and ``point_states``, drawn by the viewer.
    """

    name: str
    members: list = field(default_factory=list)
    against: list = field(default_factory=list)
    friction: Any = None
    impact: Any = None
    #: ``None`` (Signorini's law: a rigid group, MoreauJean) or a compliant law
    #: (``laws.Hertz()``, ``laws.HuntCrossley(eps=...)``, ``laws.KelvinVoigt(k, d)``, ...): a
    #: compliant group runs in every scheme, see "Compliant contact groups" in docs/usage.md
    normal: Any = None
    #: the material of every contour that has none of its own (compliant groups)
    material: Any = None

    def describe(self, callbacks: list) -> dict:
        what = f"contact group '{self.name}'"
        compliant = isinstance(self.normal, laws.COMPLIANT)
        if self.normal is not None and not compliant and not isinstance(self.normal, laws.Signorini):
            raise ModelError(f"{what}.normal: expected None, mechsys.laws.Signorini() or a compliant law (KelvinVoigt, Hertz, "
                             f"HuntCrossley, LankaraniNikravesh, Flores, UserLaw), got {type(self.normal).__name__}")
        if self.material is not None and not compliant:
            raise ModelError(f"{what}.material: materials belong to compliant groups (normal=laws.Hertz(), ...); a rigid group takes none")
        if not isinstance(self.name, str) or not self.name.strip():
            raise ModelError(f"contact group: name must be a non-empty string, got {self.name!r}")
        out = {"name": self.name}
        for key in ("members", "against"):
            items = getattr(self, key)
            if isinstance(items, OnBody) or not isinstance(items, (list, tuple)):
                raise ModelError(f"{what}.{key}: expected a list of contours on bodies (body.contour(...)), got {type(items).__name__}")
            lst = []
            for k, side in enumerate(items):
                if not isinstance(side, OnBody):
                    raise ModelError(f"{what}.{key}[{k}]: expected a contour on a body (body.contour(ms.contours.X(...))), got {type(side).__name__}")
                item = {"body": side.body, "contour": side.contour.describe(f"{what}.{key}[{k}].contour")}
                mat = getattr(side, "material", None)
                if mat is not None and compliant:
                    if not isinstance(mat, laws.Material):
                        raise ModelError(f"{what}.{key}[{k}].material: expected mechsys.Material(E, nu, density), got {type(mat).__name__}")
                    item["material"] = mat.describe(f"{what}.{key}[{k}].material")
                lst.append(item)
            out[key] = lst
        if not out["members"]:
            raise ModelError(f"{what}.members: a group needs at least one member")
        if compliant:
            if self.impact is not None:
                raise ModelError(f"{what}.impact: a compliant group takes no impact law (its restitution comes from its normal "
                                 "law: HuntCrossley(eps=...), LankaraniNikravesh, Flores, or KelvinVoigt's damping)")
            if isinstance(self.friction, laws.LuGre):
                raise ModelError(f"{what}.friction: the LuGre bristle law needs a bristle state per contact point, which a group's "
                                 "pairs do not carry; give the group Coulomb, Stribeck or FrictionTable (regularized) or declare "
                                 "the contacts that need bristles explicitly")
            out["normal"] = self.normal.describe(f"{what}.normal", callbacks)
            if self.material is not None:
                if not isinstance(self.material, laws.Material):
                    raise ModelError(f"{what}.material: expected mechsys.Material(E, nu, density), got {type(self.material).__name__}")
                out["material"] = self.material.describe(f"{what}.material")
        elif isinstance(self.normal, laws.Signorini):
            signorini = self.normal.describe(f"{what}.normal")
            if signorini is not None:
                out["normal"] = signorini
        out.update(_law_fields(what, self.friction, self.impact))
        return out


@dataclass
class GapContact:
    """A unilateral contact given directly by its normal distance g_N(q, t) — open where it is
    positive — instead of by contours: a stop on a joint, a wall a linkage's point must not pass,
    a clearance written in the coordinates (section 2.2.7, the relative kinematics written by
    hand). Optional ``tangents`` (at most 2) are tangential coordinates g_T(q, t) whose rates are
    the sliding velocities the friction law acts against. Works in both contact schemes.

    Each function is either

    - an expression of the joint coordinates (a joint's name, or ``name[k]`` for coordinate k
      of a multi-coordinate joint) and the time ``t``, with ``+ - * / ^``, ``pi``, ``e`` and
      ``sin cos tan asin acos atan sinh cosh tanh exp ln sqrt abs atan2 hypot min max``:
      evaluated by the engine, with exact derivatives (dual numbers), at full speed; or
    - a Python callable ``g(q, t)`` of the whole coordinate vector, called back from the step
      loop (slow); its derivatives come from forward-mode Taylor arithmetic when it computes with
      operators and numpy functions (``np.sin``, not ``math.sin``), else from central
      differences.

    The coordinates a gap reads must have their velocities as rates (no free or spherical joint).
    With ``normal=laws.Bilateral()`` the gap is held at zero (a constraint g(q, t) = 0 written
    by hand; ``rolling=True`` holds the tangential coordinates' rates at zero too).

    Its contact frame is fixed (n = z, t1 = x, t2 = y at the origin), so the signals
    ``contact/<name>/g_n``, ``gd_n``, ``lambda_n`` (the generalized force along ∂g/∂q, N for a
    gap in m), ``lambda_t`` and the events mean what they mean for any contact, while ``normal``
    and ``point`` are those fixed values.

    >>> stop = GapContact("stop", gap="0.3 - L * sin(swing)".replace("L", "0.5"), impact=laws.Newton(eps=0.5))
    """

    name: str
    gap: Any
    tangents: Any = ()
    normal: Any = field(default_factory=laws.Signorini)
    friction: Any = None
    impact: Any = None

    def describe(self, callbacks: list) -> dict:
        what = f"gap contact '{self.name}'"
        if not isinstance(self.name, str) or not self.name.strip():
            raise ModelError(f"gap contact: name must be a non-empty string, got {self.name!r}")
        tangents = [self.tangents] if isinstance(self.tangents, str) or callable(self.tangents) else list(self.tangents)
        d = {"name": self.name, "gap": _gap_term(self.gap, f"{what}.gap", callbacks)}
        if tangents:
            d["tangents"] = [_gap_term(f, f"{what}.tangents[{k}]", callbacks) for k, f in enumerate(tangents)]
        normal = _normal_law(what, self.normal, self.friction, self.impact)
        if normal is not None:
            d["normal"] = normal
        d.update(_law_fields(what, self.friction, self.impact))
        return d


def _gap_term(f, what: str, callbacks: list):
    """An expression as it is, a callable as a callback id of its derivative wrapper."""
    if isinstance(f, str):
        return f
    if callable(f):
        callbacks.append(_GapCallback(f, what))
        return {"callback": len(callbacks) - 1}
    raise ModelError(f"{what}: expected an expression (a string) or a callable g(q, t), got {type(f).__name__}")


class _GapCallback:
    """The engine's side of a Python gap function g(q, t): called with (t, q, u), returns
    (g, g', w_bar, dg/dq) — g' the rate along q' = u (with dg/dt), w_bar the second derivative
    along (u, 1) at u' = 0 — by Taylor arithmetic, or central differences when g does not take
    Taylor numbers."""

    def __init__(self, f, what: str):
        self.f, self.what, self.taylor = f, what, True

    def _call(self, q, t):
        try:
            v = self.f(q, t)
        except Exception as e:  # the user's code: say which contact's function failed
            if self.taylor and isinstance(e, (TypeError, AttributeError)) and any(
                    isinstance(x, _Taylor2) for x in list(q) + [t]):
                raise _NoTaylor from None
            raise ModelError(f"{self.what}: the function raised {type(e).__name__}: {e}") from e
        if isinstance(v, np.ndarray) and v.size == 1:
            v = v.reshape(-1)[0]
        return v

    def __call__(self, t, q, u):
        q, u = np.asarray(q, dtype=float), np.asarray(u, dtype=float)
        if self.taylor:
            try:
                return self._by_taylor(t, q, u)
            except _NoTaylor:
                self.taylor = False
        return self._by_differences(t, q, u)

    def _scalar(self, v):
        if isinstance(v, _Taylor2):
            return v
        try:
            return float(v)
        except (TypeError, ValueError):
            raise ModelError(f"{self.what}: expected the function to return a number, got {v!r}") from None

    def _by_taylor(self, t, q, u):
        r = self._scalar(self._call(np.array([_Taylor2(x, v) for x, v in zip(q, u)], dtype=object), _Taylor2(t, 1.0)))
        r = _Taylor2.lift(r)
        grad = np.empty(q.size)
        for i in range(q.size):
            qi = np.array([_Taylor2(x, 1.0 if k == i else 0.0) for k, x in enumerate(q)], dtype=object)
            grad[i] = _Taylor2.lift(self._scalar(self._call(qi, t))).d
        return r.v, r.d, r.dd, grad

    def _by_differences(self, t, q, u):
        def g(qq, tt):
            return self._scalar(self._call(qq, tt))

        g0 = g(q, t)
        grad = np.empty(q.size)
        for i in range(q.size):
            h = 1e-6 * max(1.0, abs(q[i]))
            e = np.zeros(q.size)
            e[i] = h
            grad[i] = (g(q + e, t) - g(q - e, t)) / (2 * h)
        # along the motion (q + u s, t + s): first and second derivatives at s = 0
        s = 1e-4 / max(1.0, float(np.abs(u).max(initial=0.0)))
        gp, gm = g(q + u * s, t + s), g(q - u * s, t - s)
        return g0, (gp - gm) / (2 * s), (gp - 2 * g0 + gm) / (s * s), grad


class _NoTaylor(Exception):
    """The user's function does not compute with Taylor numbers."""


__all__ = ["Contact", "ContactGroup", "GapContact"]
