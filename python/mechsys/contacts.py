"""Unilateral contacts (section 2.5): a contour on each of two bodies, with the normal law
(Signorini), a friction law and an impact law from :mod:`mechsys.laws`.

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

    def describe(self, callbacks: list) -> dict:
        what = f"contact '{self.name}'"
        for k, side in (("first", self.first), ("second", self.second)):
            if not isinstance(side, OnBody):
                raise ModelError(f"{what}.{k}: expected a contour on a body (body.contour(ms.contours.X(...))), got {type(side).__name__}")
        if not isinstance(self.normal, laws.Signorini):
            raise ModelError(f"{what}.normal: expected mechsys.laws.Signorini(), got {type(self.normal).__name__}")
        d = {
            "name": self.name,
            "body1": self.first.body,
            "contour1": self.first.contour.describe(f"{what}.contour1"),
            "body2": self.second.body,
            "contour2": self.second.contour.describe(f"{what}.contour2"),
        }
        if self.friction is not None:
            if not isinstance(self.friction, (laws.Coulomb, laws.Stribeck, laws.FrictionTable)):
                raise ModelError(f"{what}.friction: expected a mechsys.laws friction law, got {type(self.friction).__name__}")
            d["friction"] = self.friction.describe(f"{what}.friction")
        if self.impact is not None:
            if not isinstance(self.impact, (laws.Newton, laws.Poisson)):
                raise ModelError(f"{what}.impact: expected mechsys.laws.Newton or Poisson, got {type(self.impact).__name__}")
            d["impact"] = self.impact.describe(f"{what}.impact")
        return d


__all__ = ["Contact"]
