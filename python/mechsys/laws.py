"""Contact laws (section 2.5.3): the normal law, friction laws and impact laws of a
:class:`mechsys.Contact`.

- :class:`Signorini`: the normal corner law g_N >= 0, lambda_N >= 0, g_N lambda_N = 0 (rigid and
  unilateral: the default); with ``compliance`` c a compliant layer in series, g_N + c lambda_N >= 0
  (time-stepping).
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

Compliant normal laws (section 2.5.4: a contact zone that deforms, with forces over a finite
duration; the contact then is a force element on the same contour geometry and runs in every
scheme, the smooth ones included). With the overlap delta = -g_N and its rate, each force has the
non-adhesive cut-off F = max(0, .):

- :class:`KelvinVoigt`: F = k delta + d delta'.
- :class:`Hertz`: F = K delta^(3/2), K from the contours' materials (:class:`Material`, E* =
  1/((1-nu1^2)/E1 + (1-nu2^2)/E2)) and curvatures: (4/3) E* sqrt(R) for spheres and planes,
  Hertz's elliptic-integral solution for an ellipsoid or torus against a sphere or plane; a
  cylinder on a plane, or two discs in a planar model, by Johnson's line-contact formula
  delta = (F/(pi L E*)) (ln(4 pi L E* R / F) - 1). Undamped: restitution 1.
- :class:`HuntCrossley`, :class:`LankaraniNikravesh`, :class:`Flores`: F = F_el (1 + alpha delta')
  with alpha (s/m) given, or from the restitution ``eps`` and the approach speed v at the onset:
  alpha = 3(1-eps)/(2v), 3(1-eps^2)/(4v) and 8(1-eps)/(5 eps v). Each mapping rests on its own
  approximation, so the restitution a law achieves is not ``eps``: for a Hertz point contact,
  eps = 0.2, 0.5, 0.8 give 0.547, 0.663, 0.833 (Hunt-Crossley), 0.672, 0.725, 0.847
  (Lankarani-Nikravesh, derived for small dissipation) and 0.156, 0.470, 0.789 (Flores, the
  closest); the test suite checks them against SciPy integrations.
- :class:`UserLaw`: F(delta, delta') from a Python callable (called from the step loop: slow).

Their friction (``friction=`` of the contact): Coulomb, Stribeck or a table regularized with the
velocity ``v_reg`` (default 1e-4 m/s) as F_T = -mu(|v|) F_N tanh(|v|/v_reg) v/|v| (so a contact
under a tangential load below mu F_N creeps at v = v_reg atanh(F_T/(mu F_N)); mu0 of Coulomb's law
plays no part), or :class:`LuGre` bristles, which hold a sticking contact without creep.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

from .errors import ModelError


def _num(x, what: str) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected a number, got {x!r}") from None


@dataclass
class Signorini:
    """Signorini's law for the normal direction (Fig. 2.33): rigid by default.

    ``compliance`` c > 0 (m/N, the inverse of a contact stiffness k = 1/c) puts a linear compliant
    layer in series with the rigid contact: ``g_N + c lambda_N >= 0``, ``lambda_N >= 0``, their
    product zero. At rest a pressed contact then overlaps by ``c lambda_N`` instead of drifting,
    and in :class:`mechsys.MoreauJean` the contact problem is regularized by ``c/h^2`` on its
    normal diagonal: its solution is unique, so the sweeps of a dense pile converge in tens
    instead of thousands (see "Compliant Signorini contacts" in docs/usage.md). ``damping`` d
    (N s/m) damps the layer, ``lambda_N = k delta + d delta'``; undamped, a stiff layer is damped
    only by the scheme (an implicit Euler step of the layer: little where ``sqrt(k/m) h`` is well
    below 1, so a ball then bounces off it). Time-stepping only: the event-driven scheme refuses
    it."""

    compliance: float = 0.0
    damping: float = 0.0

    def describe(self, what: str) -> dict | None:
        c, d = self.compliance, self.damping
        for key, v, unit in (("compliance", c, "m/N; 0 for a rigid contact"), ("damping", d, "N s/m")):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ModelError(f"{what}.{key}: expected a finite number >= 0 ({unit}), got {v!r}")
        if d > 0 and c == 0:
            raise ModelError(f"{what}.damping: damps a compliant layer; give a compliance > 0 too (a rigid contact's "
                             "impacts take an impact law)")
        if c == 0:
            return None
        out = {"type": "signorini", "compliance": float(c)}
        if d > 0:
            out["damping"] = float(d)
        return out


@dataclass
class Bilateral:
    """The contact stays closed (g_N = 0, the normal force may be negative: pulling); with
    ``rolling``, it also rolls without slipping. No friction or impact law goes with it. With
    ``hold_normal=False`` (and ``rolling``) only the tangents are held: the contact rolls without
    slip while another contact of the same pair carries its normal force (a compliant one: a
    wheel on an elastic layer, as ``linearize(contacts="roll")`` holds a compliant Signorini
    layer)."""

    rolling: bool = False
    hold_normal: bool = True

    def describe(self, what: str) -> dict:
        for key in ("rolling", "hold_normal"):
            if not isinstance(getattr(self, key), (bool,)):
                raise ModelError(f"{what}.{key}: expected True or False, got {getattr(self, key)!r}")
        if not self.hold_normal and not self.rolling:
            raise ModelError(f"{what}.hold_normal: False holds only the tangents, so it needs rolling=True")
        d = {"type": "bilateral", "rolling": bool(self.rolling)}
        if not self.hold_normal:
            d["hold_normal"] = False
        return d


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


def _opt(d: dict, key: str, v, what: str) -> None:
    if v is not None:
        d[key] = _num(v, f"{what}.{key}")


@dataclass
class Material:
    """An elastic material of a contour: Young's modulus ``E`` (Pa), Poisson's ratio ``nu`` in
    (-1, 0.5) and ``density`` (kg/m^3). ``body.contour(shape, material=steel)``."""

    E: float
    nu: float
    density: float

    def describe(self, what: str) -> dict:
        return {"E": _num(self.E, f"{what}.E"), "nu": _num(self.nu, f"{what}.nu"),
                "density": _num(self.density, f"{what}.density")}


@dataclass
class KelvinVoigt:
    """A compliant spring-damper: F = max(0, k delta + d delta'), ``k`` (N/m), ``d`` (N s/m);
    ``v_reg``: the friction law's regularization velocity (m/s)."""

    k: float
    d: float = 0.0
    v_reg: float | None = None

    def describe(self, what: str, callbacks: list | None = None) -> dict:
        d = {"type": "kelvin_voigt", "k": _num(self.k, f"{what}.k"), "d": _num(self.d, f"{what}.d")}
        _opt(d, "v_reg", self.v_reg, what)
        return d


@dataclass
class Hertz:
    """Hertz's compliant law F = K delta^1.5 (or Johnson's line law), undamped. ``stiffness``
    gives K (N/m^1.5) instead of the materials; ``length`` the contact length of a planar line
    contact (m); ``alpha`` (s/m) adds the damping factor (1 + alpha delta')."""

    stiffness: float | None = None
    length: float | None = None
    alpha: float | None = None
    v_reg: float | None = None
    _type = "hertz"

    def describe(self, what: str, callbacks: list | None = None) -> dict:
        d = {"type": self._type}
        for k in ("stiffness", "length", "alpha", "v_reg", "eps"):
            _opt(d, k, getattr(self, k, None), what)
        return d


@dataclass
class HuntCrossley(Hertz):
    """Hertz with Hunt-Crossley damping: alpha = 3(1 - eps)/(2 v) from the restitution ``eps``
    and the approach speed v at the onset, or ``alpha`` (s/m) given."""

    eps: float | None = None
    _type = "hunt_crossley"


@dataclass
class LankaraniNikravesh(Hertz):
    """Hertz with Lankarani-Nikravesh damping: alpha = 3(1 - eps^2)/(4 v)."""

    eps: float | None = None
    _type = "lankarani_nikravesh"


@dataclass
class Flores(Hertz):
    """Hertz with Flores' damping: alpha = 8(1 - eps)/(5 eps v)."""

    eps: float | None = None
    _type = "flores"


@dataclass
class UserLaw:
    """A compliant law F(delta, delta_dot) -> N given as a Python callable (its value before the
    cut-off max(0, F)); slow: called from the step loop. No stored energy is known for it, so
    its whole work counts as dissipated."""

    force: Any
    v_reg: float | None = None

    def describe(self, what: str, callbacks: list | None = None) -> dict:
        if not callable(self.force):
            raise ModelError(f"{what}.force: expected a callable F(delta, delta_dot), got {type(self.force).__name__}")
        if callbacks is None:
            raise ModelError(f"{what}: a Python contact law cannot be written to a model file")
        f = self.force

        def call(delta, rate, _f=f, _what=what):
            try:
                return float(_f(delta, rate))
            except Exception as e:  # the user's code: say which contact's law failed
                raise ModelError(f"{_what}: the law raised {type(e).__name__}: {e}") from e

        callbacks.append(call)
        d = {"type": "user", "callback": len(callbacks) - 1}
        _opt(d, "v_reg", self.v_reg, what)
        return d


@dataclass
class LuGre:
    """The LuGre bristle friction law of a compliant contact: dz/dt = v - sigma0 |v| z / g(v),
    F_T = -F_N (sigma0 z + sigma1 dz/dt + sigma2 v), g(v) = mu + (mu0 - mu) exp(-(v/v_s)^2);
    ``sigma0`` (1/m), ``sigma1``, ``sigma2`` (s/m) per unit normal force."""

    mu0: float
    mu: float
    v_s: float
    sigma0: float
    sigma1: float = 0.0
    sigma2: float = 0.0

    def describe(self, what: str) -> dict:
        return {"type": "lu_gre", **{k: _num(getattr(self, k), f"{what}.{k}")
                                     for k in ("mu0", "mu", "v_s", "sigma0", "sigma1", "sigma2")}}


#: the compliant normal laws
COMPLIANT = (KelvinVoigt, Hertz, UserLaw)

__all__ = ["Signorini", "Bilateral", "Coulomb", "Stribeck", "FrictionTable", "Newton", "Poisson", "Material",
           "KelvinVoigt", "Hertz", "HuntCrossley", "LankaraniNikravesh", "Flores", "UserLaw", "LuGre"]
