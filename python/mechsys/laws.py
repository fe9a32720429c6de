"""Contact laws (section 2.5.3): the normal law, friction laws and impact laws of a
:class:`mechsys.Contact`.

- :class:`Signorini`: the normal corner law g_N >= 0, lambda_N >= 0, g_N lambda_N = 0 (rigid and
  unilateral: the default).
- :class:`Bilateral`: the contact is held closed, g_N = 0, by a bilateral constraint whose force
  may pull (MBSim's bilateral constraint law); ``rolling=True`` also holds the tangential relative
  velocity at zero (rolling without slip). The contact is then a constraint: its force is the
  signal ``constraint/<name>/lambda`` (columns normal, t1, t2).
- :class:`Coulomb`: the double-corner law (2.200) with sliding coefficient ``mu`` and static
  coefficient ``mu0`` (equal to mu if omitted; below mu it is accepted with a warning and the
  contact sticks up to mu).
- :class:`Stribeck`: mu(v) = mu + (mu0 - mu) exp(-(|v| / v_s)^exponent) (2.201).
- :class:`FrictionTable`: mu(|v|) tabulated, linear in between.
- :class:`Newton`: g_N' after = -eps g_N' before (2.202), normal direction only.
- :class:`Poisson`: expansion impulse = eps times the compression impulse (2.203), normal and,
  with ``eps_t``, tangential; event-driven scheme only (Moreau-Jean refuses it: a time step's
  impulse mixes the impact with the step's smooth forces).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

from .errors import ModelError


def _num(x, what: str) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected a number, got {x!r}") from None


@dataclass
class Signorini:
    """Signorini's law for the normal direction (Fig. 2.33)."""

    def describe(self, what: str) -> None:
        return None


@dataclass
class Bilateral:
    """The contact stays closed (g_N = 0, the normal force may be negative: pulling); with
    ``rolling``, it also rolls without slipping. No friction or impact law goes with it."""

    rolling: bool = False

    def describe(self, what: str) -> dict:
        if not isinstance(self.rolling, (bool,)):
            raise ModelError(f"{what}.rolling: expected True or False, got {self.rolling!r}")
        return {"type": "bilateral", "rolling": bool(self.rolling)}


@dataclass
class Coulomb:
    """Coulomb friction: sliding ``mu``, static ``mu0`` (= mu if None)."""

    mu: float
    mu0: float | None = None

    def describe(self, what: str) -> dict:
        d = {"type": "coulomb", "mu": _num(self.mu, f"{what}.mu")}
        if self.mu0 is not None:
            d["mu0"] = _num(self.mu0, f"{what}.mu0")
        return d


@dataclass
class Stribeck:
    """A Stribeck curve from ``mu0`` at rest to ``mu`` at high speed, with velocity ``v_s``."""

    mu0: float
    mu: float
    v_s: float
    exponent: float = 2.0

    def describe(self, what: str) -> dict:
        return {"type": "stribeck", "mu0": _num(self.mu0, f"{what}.mu0"), "mu": _num(self.mu, f"{what}.mu"),
                "v_s": _num(self.v_s, f"{what}.v_s"), "exponent": _num(self.exponent, f"{what}.exponent")}


@dataclass
class FrictionTable:
    """mu at sliding speeds ``speed`` (ascending from 0); the first value is the static coefficient."""

    speed: Sequence[float]
    mu: Sequence[float]

    def describe(self, what: str) -> dict:
        return {"type": "table", "speed": [_num(v, f"{what}.speed") for v in self.speed],
                "mu": [_num(v, f"{what}.mu") for v in self.mu]}


@dataclass
class Newton:
    """Newton's impact law with coefficient of restitution ``eps`` in [0, 1]."""

    eps: float = 0.0

    def describe(self, what: str) -> dict:
        return {"type": "newton", "eps": _num(self.eps, f"{what}.eps")}


@dataclass
class Poisson:
    """Poisson's impact law: normal coefficient ``eps``, tangential ``eps_t``, both in [0, 1]."""

    eps: float = 0.0
    eps_t: float = 0.0

    def describe(self, what: str) -> dict:
        return {"type": "poisson", "eps": _num(self.eps, f"{what}.eps"), "eps_t": _num(self.eps_t, f"{what}.eps_t")}


__all__ = ["Signorini", "Bilateral", "Coulomb", "Stribeck", "FrictionTable", "Newton", "Poisson"]
