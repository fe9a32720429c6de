"""Integration schemes: smooth dynamics (RK4, DOPRI5, Radau5) and, for models with unilateral
contacts, Moreau-Jean time-stepping (:class:`MoreauJean`) with a choice of contact solver
(:class:`NSGS`, :class:`Newton`, :class:`APGD`, :class:`Lemke`, :class:`Auto`) or event-driven integration
(:class:`EventDriven`).

- :class:`RK4` — classical Runge-Kutta, fixed step: cheap, predictable, 4th order.
- :class:`DOPRI5` — Dormand-Prince 5(4), adaptive with error control and dense output (the default).
- :class:`Radau5` — Radau IIA (3 stages, order 5, L-stable), implicit: for stiff spring-damper
  systems where explicit schemes need tiny steps; a fixed step ``dt`` or adaptive steps under
  ``rtol``/``atol`` with dense output. L-stability damps parasitic stiff modes instead of letting
  them ring, and as a collocation method on the first-order form it needs no special handling of
  quaternion kinematics (generalized-alpha would).
"""

from __future__ import annotations

import math
from dataclasses import KW_ONLY, asdict, dataclass


def _as_float(value) -> float:
    """``value`` as a float; NaN for what is not a number (strings and bools included: a "3" or
    True in a setting is a mistake, not a count)."""
    if isinstance(value, (bool, str, bytes)):
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _whole(owner: object, key: str, value) -> int:
    """``value`` as an int if it is a whole number from 0 (``3`` or ``3.0``; every integer setting
    is a count); otherwise a SettingsError naming the setting (``int()`` alone would turn 2.5 into
    2 without a word, and a negative count reached the engine as an unsigned value it refused
    without the setting's name)."""
    from .errors import SettingsError

    x = _as_float(value)
    if not math.isfinite(x) or x != int(x) or x < 0:
        raise SettingsError(f"{type(owner).__name__}.{key}: expected a whole number >= 0, got {value!r}")
    if x > MAX_COUNT:
        # (beyond, the engine's unsigned counts refused it as a float, naming only the integrator)
        raise SettingsError(f"{type(owner).__name__}.{key}: expected a whole number at most 2**53, got {value!r}")
    return int(x)


#: The largest count a setting takes (the largest whole number a float holds exactly; every
#: count, e.g. sweeps or a stall window, is far below it in practice).
MAX_COUNT = 2**53


def _number(owner: object, key: str, value) -> float:
    """``value`` as a float if it is a finite number; otherwise a SettingsError naming the setting
    (a NaN would reach the engine's settings file as a value it cannot read)."""
    from .errors import SettingsError

    x = _as_float(value)
    if not math.isfinite(x):
        raise SettingsError(f"{type(owner).__name__}.{key}: expected a finite number, got {value!r}")
    return x


@dataclass(frozen=True)
class RK4:
    """Fixed-step classical Runge-Kutta of order 4 with step ``dt`` (s)."""

    dt: float

    def describe(self) -> dict:
        return {"type": "rk4", "dt": _number(self, "dt", self.dt)}


@dataclass(frozen=True)
class DOPRI5:
    """Adaptive Dormand-Prince 5(4) with relative/absolute tolerances, optional step limits."""

    rtol: float = 1e-8
    atol: float = 1e-10
    max_step: float = 0.0
    first_step: float = 0.0

    def describe(self) -> dict:
        return {"type": "dopri5", **{k: float(v) for k, v in asdict(self).items()}}


@dataclass(frozen=True)
class Radau5:
    """Implicit Radau IIA (order 5, L-stable): a fixed step ``dt`` (s), or adaptive steps under
    the tolerances ``rtol``/``atol`` -- give exactly one of ``dt`` and ``rtol``.

    Fixed: every step is ``dt``; Newton stops at ``newton_tol`` (relative). Adaptive: error control
    by the embedded estimate of Hairer & Wanner (Solving ODEs II, IV.8), steps limited by
    ``max_step`` (0: none), starting at ``first_step`` (0: automatic), Newton's tolerance derived
    from ``rtol``; outputs between steps come from the collocation polynomial. For example
    ``Radau5(1e-3)`` (fixed) or ``Radau5(rtol=1e-6, atol=1e-9)`` (adaptive).
    """

    dt: float | None = None
    _: KW_ONLY
    rtol: float | None = None
    atol: float = 1e-10
    newton_tol: float = 1e-10
    max_step: float = 0.0
    first_step: float = 0.0

    def __post_init__(self):
        from .errors import SettingsError

        if self.dt is not None and self.rtol is not None:
            raise SettingsError("integrator: give radau5 a step dt (fixed) or a tolerance rtol (adaptive), not both")
        if self.dt is None and self.rtol is None:
            raise SettingsError("integrator: give radau5 a step dt (fixed) or a tolerance rtol (adaptive), one of them")

    @property
    def adaptive(self) -> bool:
        """Whether the steps are chosen by error control (an ``rtol`` was given)."""
        return self.rtol is not None

    def describe(self) -> dict:
        if not self.adaptive:
            return {"type": "radau5", "dt": _number(self, "dt", self.dt), "newton_tol": _number(self, "newton_tol", self.newton_tol)}
        return {"type": "radau5", "rtol": _number(self, "rtol", self.rtol), "atol": _number(self, "atol", self.atol),
                "newton_tol": _number(self, "newton_tol", self.newton_tol), "max_step": _number(self, "max_step", self.max_step),
                "first_step": _number(self, "first_step", self.first_step)}


@dataclass(frozen=True)
class NSGS:
    """Nonsmooth Gauss-Seidel with exact local cone solves (the default contact solver)."""

    tol: float = 1e-10
    max_iter: int = 10_000
    relaxation: float = 1.0
    #: Anderson acceleration: the number of past sweeps combined (0 = off, at most 8); with
    #: ``relaxation = 1``. Piles converge in several times fewer sweeps.
    anderson: int = 0
    #: Stall test: the first window of sweeps (0 = none). When the smallest change of a sweep stops
    #: halving from one window to the next (windows of ``stall``, ``stall``, ``2 stall``, ...), the
    #: sweeps are cycling, and from then on they are under-relaxed (``ω ← 0.9 ω`` per stall, down to
    #: 0.5). ``Auto`` uses 1024.
    stall: int = 0

    def describe(self) -> dict:
        return {"type": "nsgs", "tol": _number(self, "tol", self.tol), "max_iter": _whole(self, "max_iter", self.max_iter),
                "relaxation": _number(self, "relaxation", self.relaxation), "anderson": _whole(self, "anderson", self.anderson),
                "stall": _whole(self, "stall", self.stall)}


@dataclass(frozen=True)
class Newton:
    """Semismooth Newton on the Alart-Curnier function with a line search; the direction uses the
    Delassus matrix regularized by ``regularization`` times each contact's W_NN, so that
    statically indeterminate supports (a box on four corners, a stack) converge.

    A Moreau-Jean problem of more than ``body_space_above`` unknowns whose contacts are all on
    free bodies and the ground (a pile) takes its Newton direction in body space: one sparse
    factorization in the bodies' velocities (6 per body) instead of a dense one of the contact
    Jacobian (``3 n`` square for ``n`` contact points), the same iterates up to round-off."""

    tol: float = 1e-10
    max_iter: int = 200
    regularization: float = 1e-4
    body_space_above: int = 480

    def describe(self) -> dict:
        return {"type": "newton", "tol": _number(self, "tol", self.tol), "max_iter": _whole(self, "max_iter", self.max_iter),
                "regularization": _number(self, "regularization", self.regularization),
                "body_space_above": _whole(self, "body_space_above", self.body_space_above)}


@dataclass(frozen=True)
class Auto:
    """The contact solver by problem shape: :class:`Newton` (regularized, its factorization reused
    while the contact set rests) for problems of at most ``newton_max_unknowns`` unknowns (3 per
    contact point in space, 2 in the plane), :class:`NSGS` above (Anderson-accelerated:
    ``nsgs_anderson`` past sweeps combined, up to ``nsgs_max_iter`` sweeps). Before Newton a few
    sweeps (4, 10 from a cold start; until Newton has factored a problem, up to n²/1500 for n
    unknowns, about one factorization's cost); where Newton ends above the tolerance (its cap ``newton_max_iter``, or 30 iterations without halving its
    residual: indeterminate piles), those sweeps go on from its iterate; ``solver="auto"`` in
    :class:`MoreauJean`. A step whose every contact point has a compliant Signorini layer
    regularizing its normal diagonal by at least 1 % (``laws.Signorini(compliance=...)``: c/h²
    against W_NN) is swept at any size: well conditioned, its sweeps converge in tens."""

    tol: float = 1e-10
    newton_max_unknowns: int = 480
    newton_max_iter: int = 200
    nsgs_max_iter: int = 10_000
    nsgs_anderson: int = 4

    def describe(self) -> dict:
        return {"type": "auto", "tol": _number(self, "tol", self.tol),
                "newton_max_unknowns": _whole(self, "newton_max_unknowns", self.newton_max_unknowns),
                "newton_max_iter": _whole(self, "newton_max_iter", self.newton_max_iter),
                "nsgs_max_iter": _whole(self, "nsgs_max_iter", self.nsgs_max_iter),
                "nsgs_anderson": _whole(self, "nsgs_anderson", self.nsgs_anderson)}


@dataclass(frozen=True)
class APGD:
    """Accelerated projected gradient (Nesterov's method with adaptive restart) on the friction
    cones, with the De Saxce velocity so that its solutions are Coulomb's: one product with the
    Delassus matrix per iteration and no factorization, for large piles; stops at ``tol`` (the
    residual of ``solver/residual``) or after ``max_iter`` iterations."""

    tol: float = 1e-10
    max_iter: int = 10_000

    def describe(self) -> dict:
        return {"type": "apgd", "tol": _number(self, "tol", self.tol), "max_iter": _whole(self, "max_iter", self.max_iter)}


@dataclass(frozen=True)
class Lemke:
    """Lemke's pivoting on the LCP form (exact for planar friction; a pyramid of ``facets`` sides in 3-D)."""

    facets: int = 8
    pivot_tol: float = 1e-12

    def describe(self) -> dict:
        return {"type": "lemke", "facets": _whole(self, "facets", self.facets), "pivot_tol": _number(self, "pivot_tol", self.pivot_tol)}


@dataclass(frozen=True)
class MoreauJean:
    """Moreau-Jean time-stepping with step ``dt`` (s): impulses and velocities, so impacts,
    stick-slip and accumulations of impacts need no event detection; ``solver`` solves each
    step's friction-contact problem. A Painleve situation (a sliding contact pressed on with
    friction above its critical coefficient) is passed by the impulse the step's problem gives
    (an impact without collision), on record as a ``painleve`` event with a warning; with
    ``continue_on_painleve=False`` it raises :class:`mechsys.PainleveError` instead."""

    dt: float
    #: an object (NSGS, Newton, APGD, Lemke, Auto) or a name: "nsgs", "newton", "apgd", "lemke", "auto"
    solver: NSGS | Newton | APGD | Lemke | Auto | str = NSGS()
    continue_on_painleve: bool = True
    #: project the contacts that stay closed back onto their contours after each step: stops
    #: the O(dt) sinking of a contact rolling or sliding along a curved contour (a ball in a
    #: track); positions move without a force, so the energy balance carries that small work
    project: bool = False
    #: solve independent contact islands (groups of contacts that share no moving body) on
    #: several threads, and sweep the two halves of a large problem on free bodies on two, from
    #: 400 active contact points (below, a second thread costs more than it saves); the results
    #: are the same bit for bit either way
    parallel: bool = True

    def __post_init__(self):
        if isinstance(self.solver, str):
            from .modelfile import _solver

            object.__setattr__(self, "solver", _solver(self.solver, "MoreauJean.solver"))

    def describe(self) -> dict:
        return {"type": "moreau_jean", "dt": _number(self, "dt", self.dt), "solver": self.solver.describe(),
                "continue_on_painleve": bool(self.continue_on_painleve), "project": bool(self.project),
                "parallel": bool(self.parallel)}


@dataclass(frozen=True)
class EventDriven:
    """Event-driven integration of contact models: smooth phases by Dormand-Prince (``rtol``,
    ``atol``, ``max_step``), events (contact, detachment, stick, slip) located by root finding,
    impacts by Newton's or Poisson's law and the acceleration-level transition problem at each
    event. Points within ``gap_tol`` (m) touch; relative velocities within ``velocity_tol``
    (m/s) count as zero (an approach that slow closes without impact: the end of an
    accumulation of impacts). A Painleve situation (no solution at acceleration level) raises
    :class:`mechsys.PainleveError` naming the contact, mu and the critical mu, unless
    ``continue_on_painleve``: then the sliding is stopped by an impulse (an impact without
    collision). Non-unique states are taken with a warning and a ``painleve`` event. Accurate where Moreau-Jean is robust; for few contacts."""

    rtol: float = 1e-10
    atol: float = 1e-12
    max_step: float = 0.0
    gap_tol: float = 1e-10
    velocity_tol: float = 1e-8
    max_events: int = 100_000
    continue_on_painleve: bool = False

    def describe(self) -> dict:
        d = {k: float(v) for k, v in asdict(self).items() if k not in ("max_events", "continue_on_painleve")}
        return {"type": "event_driven", **d, "max_events": _whole(self, "max_events", self.max_events),
                "continue_on_painleve": bool(self.continue_on_painleve)}


def from_name(name: str, dt: float | None = None, rtol: float | None = None, atol: float | None = None):
    """An integrator from its name (command line): rk4, dopri5, radau5 (``dt``: fixed, ``rtol``: adaptive)."""
    from .errors import SettingsError

    n = name.lower()
    if n == "rk4":
        if dt is None:
            raise SettingsError("integrator rk4 needs a step: give --dt")
        return RK4(dt)
    if n == "dopri5":
        return DOPRI5(rtol=1e-8 if rtol is None else rtol, atol=1e-10 if atol is None else atol)
    if n == "radau5":
        if dt is None and rtol is None:
            raise SettingsError("integrator radau5 needs a step or a tolerance: give --dt (fixed) or --rtol (adaptive)")
        if rtol is not None:
            return Radau5(dt, rtol=rtol, atol=1e-10 if atol is None else atol)
        return Radau5(dt)
    if n in ("moreau_jean", "moreaujean", "mj"):
        if dt is None:
            raise SettingsError("integrator moreau_jean needs a step: give --dt")
        return MoreauJean(dt)
    if n in ("event_driven", "eventdriven", "ed"):
        return EventDriven(rtol=1e-10 if rtol is None else rtol, atol=1e-12 if atol is None else atol)
    raise SettingsError(f"integrator: unknown name '{name}' (expected rk4, dopri5, radau5, moreau_jean or event_driven)")


__all__ = ["RK4", "DOPRI5", "Radau5", "MoreauJean", "EventDriven", "NSGS", "Newton", "Lemke", "Auto", "APGD"]
