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

from . import laws
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
        if not isinstance(self.normal, (laws.Signorini, laws.Bilateral)):
            raise ModelError(f"{what}.normal: expected mechsys.laws.Signorini() or Bilateral(), got {type(self.normal).__name__}")
        if isinstance(self.normal, laws.Bilateral):
            for key in ("friction", "impact"):
                if getattr(self, key) is not None:
                    raise ModelError(f"{what}.{key}: a bilateral contact is held closed and takes no {key} law "
                                     "(laws.Bilateral(rolling=True) holds it without slip)")
        d = {
            "name": self.name,
            "body1": self.first.body,
            "contour1": self.first.contour.describe(f"{what}.contour1"),
            "body2": self.second.body,
            "contour2": self.second.contour.describe(f"{what}.contour2"),
        }
        if isinstance(self.normal, laws.Bilateral):
            d["normal"] = self.normal.describe(f"{what}.normal")
        if self.friction is not None:
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
    """

    name: str
    members: list = field(default_factory=list)
    against: list = field(default_factory=list)
    friction: Any = None
    impact: Any = None

    def describe(self, callbacks: list) -> dict:
        what = f"contact group '{self.name}'"
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
                lst.append({"body": side.body, "contour": side.contour.describe(f"{what}.{key}[{k}].contour")})
            out[key] = lst
        if not out["members"]:
            raise ModelError(f"{what}.members: a group needs at least one member")
        out.update(_law_fields(what, self.friction, self.impact))
        return out


__all__ = ["Contact", "ContactGroup"]
