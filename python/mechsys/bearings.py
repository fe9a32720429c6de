"""Hydrodynamic journal bearings: the film law of :class:`mechsys.forces.HydrodynamicBearing`, its
steady operating point under a load, the eight linear stiffness and damping coefficients there, and
the oil-whirl stability threshold of a rigid rotor.

Everything here evaluates the engine's own law (short-bearing theory of Ocvirk or long-bearing
theory of Sommerfeld over a pi-film, see docs/theory.md), so an analysis and a simulation of the
same bearing agree.

Conventions: shell-frame axes x (horizontal) and y (up), the static load W on the journal along
-y, the journal spinning at ``speed`` about +z (counter-clockwise seen from +z; a negative speed is
the mirror image). The journal then sits below the centre and ahead in the rotation sense by the
attitude angle psi. K_ij = -dF_i/dx_j and C_ij = -dF_i/dx'_j with F the film force on the journal;
the dimensionless coefficients are K c/W and C c |speed|/W (as in Lund's tables).

    >>> import mechsys as ms
    >>> op = ms.bearings.static("short", radius=0.05, length=0.03, clearance=1e-4,
    ...                         viscosity=0.1, speed=157.08, load=525.0)
    >>> round(op.eps, 3), round(float(op.K[0, 0]) / 1e6, 2)   # Friswell et al., example 5.5.1
    (0.266, 12.81)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _core
from .errors import SettingsError

__all__ = [
    "OperatingPoint",
    "Threshold",
    "film_forces",
    "film_load",
    "load_capacity",
    "attitude_angle",
    "static",
    "threshold",
]


def _theory(theory) -> str:
    if theory not in ("short", "long"):
        raise SettingsError(f"bearings: theory must be 'short' or 'long', got {theory!r}")
    return theory


def _number(x, what: str) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise SettingsError(f"{what}: expected a number, got {x!r}") from None
    if not math.isfinite(v):
        raise SettingsError(f"{what}: must be finite, got {v}")
    return v


def _geometry(theory, radius, length, clearance, viscosity, what: str) -> tuple:
    return (_theory(theory), _number(radius, f"{what}: radius"), _number(length, f"{what}: length"),
            _number(clearance, f"{what}: clearance"), _number(viscosity, f"{what}: viscosity"))


def _eps(eps, what: str) -> float:
    e = _number(eps, what)
    if not 0.0 <= e < 1.0:
        raise SettingsError(f"{what}: the eccentricity ratio must lie in [0, 1), got {e}")
    return e


def film_forces(theory, radius, length, clearance, viscosity, eps, eps_dot, omega_star, omega_rel=None):
    """The film forces (F_r along the offset, F_t along the rotation; N) and the friction torque
    (N m) on the journal at eccentricity ratio ``eps``, its rate ``eps_dot`` (1/s), the effective
    speed ``omega_star`` = spin - 2 x whirl rate and the relative spin ``omega_rel`` (rad/s;
    ``omega_star`` if not given): the element's law."""
    g = _geometry(theory, radius, length, clearance, viscosity, "film_forces")
    w = _number(omega_star, "film_forces: omega_star")
    return _core.bearing_film(*g, _eps(eps, "film_forces: eps"), _number(eps_dot, "film_forces: eps_dot"), w,
                              w if omega_rel is None else _number(omega_rel, "film_forces: omega_rel"))


def film_load(theory, radius, length, clearance, viscosity, offset, offset_rate=(0.0, 0.0), spin=0.0):
    """The film's force on the journal (shell x, y; N) and its friction torque (N m) for the journal
    centre's ``offset`` (m) and ``offset_rate`` (m/s) in the shell frame and the relative ``spin``
    (rad/s). A SolverError once the journal touches the shell."""
    g = _geometry(theory, radius, length, clearance, viscosity, "film_load")
    e = np.asarray(offset, dtype=float)
    ed = np.asarray(offset_rate, dtype=float)
    if e.shape != (2,) or ed.shape != (2,):
        raise SettingsError(f"film_load: offset and offset_rate are (x, y) pairs, got shapes {e.shape}, {ed.shape}")
    fx, fy, m = _core.bearing_load(*g, [float(e[0]), float(e[1])], [float(ed[0]), float(ed[1])],
                                   _number(spin, "film_load: spin"))
    return np.array([fx, fy]), m


def load_capacity(eps, theory, radius, length, clearance, viscosity, speed):
    """Load capacity W (N) of a steady journal at eccentricity ratio ``eps`` in [0, 1) (a number or
    an array) spinning at ``speed`` (rad/s): the magnitude of the film force. Short bearing:
    W = eta |w| R L^3/(4 c^2) eps sqrt(16 eps^2 + pi^2 (1 - eps^2))/(1 - eps^2)^2."""
    g = _geometry(theory, radius, length, clearance, viscosity, "load_capacity")
    w = _number(speed, "load_capacity: speed")
    e = np.asarray(eps, dtype=float)
    out = np.array([_core.bearing_load_capacity(*g, _eps(x, "load_capacity: eps"), w)[0] for x in e.ravel()])
    return float(out[0]) if e.ndim == 0 else out.reshape(e.shape)


def attitude_angle(eps, theory="short"):
    """Attitude angle psi (rad) of a steady journal at eccentricity ratio ``eps`` (a number or an
    array): the angle from the load line to the line of centres, ahead in the rotation sense.
    Short bearing: tan psi = pi sqrt(1 - eps^2)/(4 eps); long bearing: pi sqrt(1 - eps^2)/(2 eps)."""
    _theory(theory)
    e = np.asarray(eps, dtype=float)
    # the angle does not depend on the size of the bearing: any valid geometry will do
    out = np.array([_core.bearing_load_capacity(theory, 1.0, 1.0, 0.5, 1.0, _eps(x, "attitude_angle: eps"), 1.0)[1]
                    for x in e.ravel()])
    return float(out[0]) if e.ndim == 0 else out.reshape(e.shape)


@dataclass(frozen=True)
class OperatingPoint:
    """A bearing's steady operating point (see :func:`static`)."""

    theory: str
    speed: float  #: spin of the journal relative to the shell (rad/s)
    load: float  #: static load W on the journal, along -y (N)
    eps: float  #: eccentricity ratio e/c
    attitude: float  #: attitude angle psi (rad), from the load line to the line of centres
    position_angle: float  #: angle of the journal centre from the shell x axis (rad)
    offset: np.ndarray  #: the journal centre's offset, shell x and y (m)
    sommerfeld: float  #: Sommerfeld number eta N L D / W (R/c)^2, N in rev/s
    h_min: float  #: minimum film thickness c (1 - eps) (m)
    torque: float  #: friction torque on the journal (N m, opposing the spin)
    K: np.ndarray  #: stiffness coefficients K_ij = -dF_i/dx_j (2x2, N/m; x, y)
    C: np.ndarray  #: damping coefficients C_ij = -dF_i/dx'_j (2x2, N s/m)
    clearance: float  #: radial clearance c (m)

    @property
    def K_bar(self) -> np.ndarray:
        """Dimensionless stiffness K c / W."""
        return self.K * self.clearance / self.load

    @property
    def C_bar(self) -> np.ndarray:
        """Dimensionless damping C c |speed| / W."""
        return self.C * self.clearance * abs(self.speed) / self.load


def static(theory, radius, length, clearance, viscosity, speed, load) -> OperatingPoint:
    """The steady operating point of a bearing carrying ``load`` (N, > 0, on the journal along -y)
    at ``speed`` (rad/s, nonzero): the eccentricity ratio solving W(eps) = load, the attitude angle,
    the Sommerfeld number, the minimum film thickness, the friction torque (eq. 2.212) and the
    eight stiffness and damping coefficients (exact derivatives of the element's law)."""
    g = _geometry(theory, radius, length, clearance, viscosity, "static")
    w = _number(speed, "static: speed")
    W = _number(load, "static: load")
    if W <= 0.0:
        raise SettingsError(f"static: load must be > 0 (N), got {W}")
    if w == 0.0:
        raise SettingsError("static: speed must be nonzero (a journal at rest carries no steady load)")
    d = _core.bearing_operating_point(*g, w, W)
    return OperatingPoint(theory=g[0], speed=w, load=W, eps=d["eps"], attitude=d["attitude"],
                          position_angle=d["position_angle"], offset=np.array(d["offset"]),
                          sommerfeld=d["sommerfeld"], h_min=d["h_min"], torque=d["torque"],
                          K=np.array(d["K"]), C=np.array(d["C"]), clearance=g[3])


@dataclass(frozen=True)
class Threshold:
    """The oil-whirl stability threshold of a rigid rotor (see :func:`threshold`)."""

    speed: float  #: threshold speed (rad/s); inf if the rotor is stable at every speed examined
    whirl_ratio: float | None  #: whirl frequency / speed at the threshold (None without one)
    k_eq: float | None  #: Lund's equivalent stiffness K_eq (N/m) at the threshold
    point: OperatingPoint | None  #: the bearing's operating point at the threshold


def _lund(op: OperatingPoint) -> tuple[float, float]:
    """K_eq and the squared whirl frequency nu^2 of Lund's stability criterion."""
    K, C = op.K, op.C
    k_eq = (K[0, 0] * C[1, 1] + K[1, 1] * C[0, 0] - K[0, 1] * C[1, 0] - K[1, 0] * C[0, 1]) / (C[0, 0] + C[1, 1])
    nu2 = ((K[0, 0] - k_eq) * (K[1, 1] - k_eq) - K[0, 1] * K[1, 0]) / (C[0, 0] * C[1, 1] - C[0, 1] * C[1, 0])
    return k_eq, nu2


def threshold(theory, radius, length, clearance, viscosity, mass, load=None, gravity=9.81) -> Threshold:
    """The speed above which a rigid rotor of ``mass`` (kg, the mass the bearing carries) whirls
    unstably on the bearing, by Lund's criterion on the eight coefficients: at the threshold the
    whirl frequency nu solves m nu^2 = K_eq with K_eq = (Kxx Cyy + Kyy Cxx - Kxy Cyx - Kyx Cxy)/(Cxx
    + Cyy) and nu^2 = ((Kxx - K_eq)(Kyy - K_eq) - Kxy Kyx)/(Cxx Cyy - Cxy Cyx). ``load`` (N) is the
    static load, ``mass * gravity`` by default. The eccentricity ratio is searched in [0.005, 0.995]
    (the rotor is stable at large eps, whirls at small eps); a rotor stable throughout gives
    ``speed = inf``."""
    g = _geometry(theory, radius, length, clearance, viscosity, "threshold")
    m = _number(mass, "threshold: mass")
    if m <= 0.0:
        raise SettingsError(f"threshold: mass must be > 0 (kg), got {m}")
    W = m * _number(gravity, "threshold: gravity") if load is None else _number(load, "threshold: load")
    if W <= 0.0:
        raise SettingsError(f"threshold: the load must be > 0 (N), got {W}")
    # the load grows linearly with the speed at fixed eps: the speed that puts the journal at eps
    unit = _core.bearing_load_capacity

    def speed_at(eps: float) -> float:
        return W / unit(*g, eps, 1.0)[0]

    def margin(eps: float) -> float:
        # critical mass minus the rotor's, relative: > 0 stable (no real whirl frequency: stable)
        k_eq, nu2 = _lund(static(*g, speed_at(eps), W))
        return (k_eq / nu2 - m) / m if nu2 > 0.0 else math.inf

    grid = np.linspace(0.995, 0.005, 100)
    values = [margin(float(e)) for e in grid]
    for k in range(len(grid) - 1):
        a, b = values[k], values[k + 1]
        if math.isfinite(a) and math.isfinite(b) and a > 0.0 >= b:
            lo, hi = float(grid[k + 1]), float(grid[k])
            for _ in range(100):
                mid = 0.5 * (lo + hi)
                if margin(mid) > 0.0:
                    hi = mid
                else:
                    lo = mid
                if hi - lo < 1e-14:
                    break
            eps = 0.5 * (lo + hi)
            op = static(*g, speed_at(eps), W)
            k_eq, nu2 = _lund(op)
            return Threshold(speed=op.speed, whirl_ratio=math.sqrt(nu2) / op.speed, k_eq=float(k_eq), point=op)
    return Threshold(speed=math.inf, whirl_ratio=None, k_eq=None, point=None)
