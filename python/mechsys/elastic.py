"""Shape functions and reduced data of elastic bodies (sections 2.2.8 and 2.4.2 of the reference).

A floating-frame elastic body moves with a body frame B (the reference of eq. 2.133); a point at
r (body frame, undeformed) is displaced by u(r, t) = Φ_u(r) q(t) and its material rotates by the
small angle φ(r, t) = Φ_φ(r) q(t) (eqs. 2.134, 2.145) — the Ritz separation of section 2.4.2 into
space-dependent shapes Φ, evaluated once here, and time-dependent elastic coordinates q.
:class:`ReducedBody` holds what the equations of motion need:

* ``nodes`` (n, 3) — node positions in the body frame (m);
* ``modes`` (n, 6, q) — per node the translation (ux, uy, uz) and small rotation (rx, ry, rz)
  of each elastic coordinate (m and rad per unit q);
* ``M``, ``K`` (q, q) — mass and stiffness matrices of the elastic coordinates;
* the inertia invariants (see :class:`ReducedBody`) that appear when the absolute velocity
  eq. 2.191 is put into the kinetic energy eq. 2.192.

Sources:

* analytic Euler–Bernoulli modes (:func:`euler_bernoulli_roots`, :func:`euler_bernoulli_mode`,
  as a body: :func:`analytic_beam_body`) and Timoshenko frequencies (:func:`timoshenko_frequencies`),
* a built-in Euler–Bernoulli (Hermite) finite-element beam, planar or spatial
  (:func:`beam_model`), reduced by modal truncation (:func:`modal_reduction`) or Craig–Bampton
  (:func:`craig_bampton`),
* full matrices of an external FE code (:func:`fe_model`) and reduced bodies written by one
  (:func:`load_reduced`, layout in :func:`save_reduced`).

:func:`rotating_cantilever_frequencies` and :func:`southwell_coefficients` give the centrifugal
stiffening of a rotating beam (stress stiffening from the axial force distribution).
All inputs and outputs are SI. Errors are :class:`~mechsys.errors.ModelError` naming the body and
the item.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import linalg, optimize

from .continuum import skew
from .errors import ModelError

__all__ = [
    "DOF_NAMES",
    "ReducedBody",
    "BeamSection",
    "FEModel",
    "euler_bernoulli_roots",
    "euler_bernoulli_frequencies",
    "euler_bernoulli_mode",
    "timoshenko_frequencies",
    "timoshenko_pinned_pinned",
    "analytic_beam_body",
    "beam_model",
    "fe_model",
    "modal_reduction",
    "craig_bampton",
    "geometric_stiffness",
    "rotating_cantilever_frequencies",
    "southwell_coefficients",
    "save_reduced",
    "load_reduced",
    "FREQUENCY_WARNING_HZ",
]

DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")
"""The six nodal degrees of freedom, in the order of `modes` and of the FE matrices."""
FREQUENCY_WARNING_HZ = 1e7
"""An elastic frequency above this (Hz) gives a warning: usually mm taken for m or g for kg."""

_BC = ("clamped-free", "pinned-pinned", "free-free", "clamped-clamped", "clamped-pinned")


# ============================================================================================
# Analytic Euler-Bernoulli beams
# ============================================================================================


def _num(v, what: str) -> float:
    """float(v), or a ModelError naming the item."""
    try:
        if isinstance(v, (str, bytes)):
            raise TypeError
        return float(v)
    except (TypeError, ValueError):
        raise ModelError(f"{what} must be a number, got {v!r}") from None


def _char(bc: str, x: float) -> float:
    """Characteristic equation of bc, scaled by 1/cosh x so that it stays O(1)."""
    if bc == "clamped-free":  # cos x cosh x + 1 = 0
        return np.cos(x) + 1.0 / np.cosh(x)
    if bc in ("free-free", "clamped-clamped"):  # cos x cosh x - 1 = 0
        return np.cos(x) - 1.0 / np.cosh(x)
    if bc == "clamped-pinned":  # tan x = tanh x
        return np.sin(x) - np.cos(x) * np.tanh(x)
    raise ModelError(f"beam boundary conditions must be one of {_BC}, got {bc!r}")


def euler_bernoulli_roots(bc: str, n: int) -> np.ndarray:
    """The first n roots β_k L of the characteristic equation of an Euler–Bernoulli beam.

    clamped-free: cos βL cosh βL = −1 (1.8751, 4.6941, 7.8548, ...); pinned-pinned: sin βL = 0
    (kπ); free-free and clamped-clamped: cos βL cosh βL = 1 (4.7300, 7.8532, ..., the elastic
    roots; free-free also has two rigid-body modes at 0); clamped-pinned: tan βL = tanh βL
    (3.9266, ...). Solved by Brent's method to machine precision.
    """
    if int(n) != n or n < 1:
        raise ModelError(f"euler_bernoulli_roots: n must be a positive integer, got {n}")
    if bc == "pinned-pinned":
        return np.pi * np.arange(1, n + 1, dtype=float)
    _char(bc, 1.0)  # validates bc
    roots = []
    for k in range(1, int(n) + 1):
        if bc == "clamped-free":
            a, b = (k - 1) * np.pi, k * np.pi
        elif bc == "clamped-pinned":
            a, b = k * np.pi, k * np.pi + np.pi / 2
        else:
            a, b = k * np.pi, (k + 1) * np.pi
        roots.append(optimize.brentq(lambda x: _char(bc, x), a + 1e-12, b, xtol=1e-15, rtol=1e-15, maxiter=200))
    return np.array(roots)


def euler_bernoulli_frequencies(bc: str, n: int, E: float, I: float, rho: float, A: float, L: float) -> np.ndarray:
    """ω_k = (β_k L)² √(E I / (ρ A L⁴)) in rad/s for the first n elastic modes."""
    for k, v in (("E", E), ("I", I), ("rho", rho), ("A", A), ("L", L)):
        v = _num(v, f"euler_bernoulli_frequencies: {k}")
        if not (np.isfinite(v) and v > 0):
            raise ModelError(f"euler_bernoulli_frequencies: {k} must be > 0, got {v}")
    return euler_bernoulli_roots(bc, n) ** 2 * np.sqrt(E * I / (rho * A * L**4))


def euler_bernoulli_mode(bc: str, k: int, x, L: float, derivative: int = 0) -> np.ndarray:
    """The k-th (1-based) mode shape φ_k(x) of an Euler–Bernoulli beam, or its derivative (0–3).

    clamped-free: φ = cosh βx − cos βx − σ (sinh βx − sin βx), σ = (cosh βL + cos βL)/(sinh βL + sin βL);
    free-free: φ = cosh βx + cos βx − σ (sinh βx + sin βx), σ = (cosh βL − cos βL)/(sinh βL − sin βL);
    clamped-clamped: φ = cosh βx − cos βx − σ (sinh βx − sin βx) with the free-free σ;
    clamped-pinned: as clamped-clamped with φ(L) = 0; pinned-pinned: φ = sin βx. Unscaled (the
    cantilever has φ(L) = ±2). cosh βx − σ sinh βx is evaluated as ½ e^{βx}(1 − σ) +
    ½ e^{−βx}(1 + σ) with 1 − σ in closed form, so that high modes keep their accuracy.
    """
    if derivative not in (0, 1, 2, 3):
        raise ModelError(f"euler_bernoulli_mode: derivative must be 0..3, got {derivative}")
    if not (np.isfinite(L) and L > 0):
        raise ModelError(f"euler_bernoulli_mode: L must be > 0, got {L}")
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ModelError("euler_bernoulli_mode: x has non-finite entries")
    beta = euler_bernoulli_roots(bc, k)[-1] / L
    bx, bL = beta * x, beta * L
    d = derivative
    trig_c = [np.cos, lambda t: -np.sin(t), lambda t: -np.cos(t), np.sin][d]
    trig_s = [np.sin, np.cos, lambda t: -np.sin(t), lambda t: -np.cos(t)][d]
    if bc == "pinned-pinned":
        return beta**d * trig_s(bx)
    # phi = cosh - s_c cos - sig (sinh - s_s sin);  clamped-free: s_c = s_s = +1
    # free-free: cosh + cos - sig (sinh + sin); clamped-clamped: cosh - cos - sig (sinh - sin)
    # clamped-pinned: same as clamped-clamped with its own sigma = (cosh - cos)/(sinh - sin)
    if bc == "clamped-free":
        sc, ss = 1.0, 1.0
        num_c, num_s = 1.0, 1.0  # sigma = (cosh + cos)/(sinh + sin)
    elif bc == "free-free":
        sc, ss = -1.0, -1.0
        num_c, num_s = -1.0, -1.0  # sigma = (cosh - cos)/(sinh - sin)
    else:  # clamped-clamped, clamped-pinned
        sc, ss = 1.0, 1.0
        num_c, num_s = -1.0, -1.0
    # sigma = (cosh bL + num_c cos bL) / (sinh bL + num_s sin bL); 1 - sigma in stable form
    eL = np.exp(-bL)
    den = 1.0 - eL * eL + 2.0 * num_s * np.sin(bL) * eL  # = 2 e^{-bL} (sinh bL + num_s sin bL)
    one_minus_sigma = 2.0 * eL * (-eL + num_s * np.sin(bL) - num_c * np.cos(bL)) / den
    sigma = 1.0 - one_minus_sigma
    # cosh - sigma sinh = ½ e^{bx}(1 - sigma) + ½ e^{-bx}(1 + sigma); d-th derivative: beta^d,
    # and the e^{-bx} term alternates in sign
    hyp = 0.5 * np.exp(bx) * one_minus_sigma + 0.5 * (-1.0) ** d * np.exp(-bx) * (1.0 + sigma)
    return beta**d * (hyp - sc * trig_c(bx) - sigma * (-ss) * trig_s(bx))


# ============================================================================================
# Timoshenko beams
# ============================================================================================


def timoshenko_pinned_pinned(k: int, E: float, G: float, kappa: float, rho: float, A: float, I: float, L: float) -> float:
    """Closed form ω (rad/s) of the k-th bending mode of a pinned–pinned Timoshenko beam.

    With w = W sin(k π x / L), ψ = Ψ cos(k π x / L) the two equations give
    (ρAω² − κGA a²)(ρIω² − EI a² − κGA) − (κGA a)² = 0, a = kπ/L; the lower root in ω².
    """
    for name, v in (("E", E), ("G", G), ("kappa", kappa), ("rho", rho), ("A", A), ("I", I), ("L", L)):
        v = _num(v, f"timoshenko_pinned_pinned: {name}")
        if not (np.isfinite(v) and v > 0):
            raise ModelError(f"timoshenko_pinned_pinned: {name} must be > 0, got {v}")
    if int(k) != k or k < 1:
        raise ModelError(f"timoshenko_pinned_pinned: k must be a positive integer, got {k}")
    a = k * np.pi / L
    s = kappa * G * A
    c2 = rho * A * rho * I
    c1 = -(rho * A * (E * I * a * a + s) + rho * I * s * a * a)
    c0 = s * a * a * (E * I * a * a + s) - (s * a) ** 2
    disc = c1 * c1 - 4 * c2 * c0
    w2 = 2 * c0 / (-c1 + np.sqrt(disc))  # the smaller root, written without cancellation
    return float(np.sqrt(w2))


def _timoshenko_det(omega, bc, EI, kGA, rhoA, rhoI, L):
    """2x2 boundary determinant of the Timoshenko beam at frequency omega (transfer matrix)."""
    # state y = (w, psi, M, Q): w' = psi + Q/kGA, psi' = M/EI, M' = -Q - rhoI w^2 psi, Q' = -rhoA w^2 w
    Amat = np.array(
        [
            [0.0, 1.0, 0.0, 1.0 / kGA if np.isfinite(kGA) else 0.0],
            [0.0, 0.0, 1.0 / EI, 0.0],
            [0.0, -rhoI * omega**2, 0.0, -1.0],
            [-rhoA * omega**2, 0.0, 0.0, 0.0],
        ]
    )
    # scale the state so that the matrix exponential is well conditioned: w ~ L, psi ~ 1,
    # M ~ EI/L, Q ~ EI/L^2
    S = np.diag([L, 1.0, EI / L, EI / L**2])
    P = linalg.expm(np.linalg.solve(S, Amat @ S) * L)
    idx = {"clamped": (0, 1), "pinned": (0, 2), "free": (2, 3)}
    left, right = bc.split("-")
    free_left = [i for i in range(4) if i not in idx[left]]
    return np.linalg.det(P[np.ix_(idx[right], free_left)])


def timoshenko_frequencies(bc: str, n: int, E: float, G: float, kappa: float, rho: float, A: float, I: float, L: float) -> np.ndarray:
    """The first n bending frequencies ω (rad/s) of a uniform Timoshenko beam (shear flexibility
    1/(κGA) and rotary inertia ρI), bc as in :func:`euler_bernoulli_roots`.

    The transfer matrix exp(A L) of the state (w, ψ, M, Q) is put into the two boundary
    conditions at each end; the zeros of the 2x2 determinant, bracketed below the
    Euler–Bernoulli frequencies (which bound them from above), are found by Brent's method.
    """
    for k, v in (("E", E), ("G", G), ("kappa", kappa), ("rho", rho), ("A", A), ("I", I), ("L", L)):
        v = _num(v, f"timoshenko_frequencies: {k}")
        if not (np.isfinite(v) and v > 0):
            raise ModelError(f"timoshenko_frequencies: {k} must be > 0, got {v}")
    if bc not in _BC:
        raise ModelError(f"timoshenko_frequencies: bc must be one of {_BC}, got {bc!r}")
    EI, kGA, rhoA, rhoI = E * I, kappa * G * A, rho * A, rho * I
    w_eb = euler_bernoulli_frequencies(bc, n, E, I, rho, A, L)
    f = lambda w: _timoshenko_det(w, bc, EI, kGA, rhoA, rhoI, L)  # noqa: E731
    grid = np.linspace(1e-4 * w_eb[0], w_eb[-1] * 1.0001, 400 * n + 1)
    vals = np.array([f(w) for w in grid])
    roots = []
    for i in range(len(grid) - 1):
        if vals[i] == 0.0:
            roots.append(grid[i])
        elif vals[i] * vals[i + 1] < 0:
            roots.append(optimize.brentq(f, grid[i], grid[i + 1], xtol=1e-14 * w_eb[-1], rtol=1e-15))
        if len(roots) == n:
            break
    if len(roots) < n:
        raise ModelError(f"timoshenko_frequencies: found only {len(roots)} of {n} roots below the Euler-Bernoulli bound ({bc})")
    return np.array(roots)


# ============================================================================================
# Finite-element beam (Euler-Bernoulli, Hermite cubic bending, linear axial and torsion)
# ============================================================================================


@dataclass(frozen=True)
class BeamSection:
    """A uniform beam cross-section and material (SI).

    E, G moduli (Pa); rho density (kg/m³); A area (m²); Iy, Iz second moments about the local
    y and z axes (m⁴; Iz governs bending in the x–y plane); J torsion constant (m⁴); Ip polar
    moment for torsional inertia (m⁴, default Iy + Iz); kappa shear coefficient (Timoshenko).
    """

    E: float
    G: float
    rho: float
    A: float
    Iy: float
    Iz: float
    J: float
    Ip: float | None = None
    kappa: float = 5.0 / 6.0

    def __post_init__(self):
        for k in ("E", "G", "rho", "A", "Iy", "Iz", "J", "kappa"):
            v = _num(getattr(self, k), f"BeamSection: {k}")
            object.__setattr__(self, k, v)
            if not (np.isfinite(v) and v > 0):
                raise ModelError(f"BeamSection: {k} must be > 0, got {v}")
        if self.Ip is None:
            object.__setattr__(self, "Ip", self.Iy + self.Iz)
        elif not (np.isfinite(_num(self.Ip, "BeamSection: Ip")) and self.Ip > 0):
            raise ModelError(f"BeamSection: Ip must be > 0, got {self.Ip}")

    @classmethod
    def rectangle(cls, b: float, h: float, *, E: float, nu: float, rho: float) -> "BeamSection":
        """Solid b (along y) x h (along z) rectangle; J from the Saint-Venant series
        approximation J = a b³ [1/3 − 0.21 (b/a)(1 − (b/a)⁴/12)] (a ≥ b the sides);
        kappa = 10 (1 + ν) / (12 + 11 ν) (Cowper)."""
        from .continuum import isotropic

        mat = isotropic(E=E, nu=nu)
        if not (b > 0 and h > 0):
            raise ModelError(f"BeamSection.rectangle: b and h must be > 0, got b = {b}, h = {h}")
        a, c = max(b, h), min(b, h)
        J = a * c**3 * (1.0 / 3.0 - 0.21 * (c / a) * (1.0 - (c / a) ** 4 / 12.0))
        return cls(E=E, G=mat.G, rho=rho, A=b * h, Iy=b * h**3 / 12, Iz=h * b**3 / 12, J=J, kappa=10 * (1 + nu) / (12 + 11 * nu))

    @classmethod
    def circle(cls, r: float, *, E: float, nu: float, rho: float) -> "BeamSection":
        """Solid circle of radius r: I = π r⁴/4, J = Ip = π r⁴/2, kappa = 6 (1 + ν)/(7 + 6 ν)."""
        from .continuum import isotropic

        mat = isotropic(E=E, nu=nu)
        if not r > 0:
            raise ModelError(f"BeamSection.circle: r must be > 0, got {r}")
        I = np.pi * r**4 / 4
        return cls(E=E, G=mat.G, rho=rho, A=np.pi * r * r, Iy=I, Iz=I, J=2 * I, Ip=2 * I, kappa=6 * (1 + nu) / (7 + 6 * nu))


@dataclass
class FEModel:
    """Full finite-element matrices with 6 DOFs per node (ux, uy, uz, rx, ry, rz).

    ``mass_points`` = (positions (p, 3), masses (p,), interpolation (p, 3, 6n)) discretizes the
    mass for the second-order inertia invariants: the translation of point j is
    ``interpolation[j] @ d`` for the nodal DOF vector d. ``always_fixed`` are DOFs fixed by the
    model itself (the out-of-plane DOFs of a planar beam).
    """

    nodes: np.ndarray
    M: np.ndarray
    K: np.ndarray
    mass_points: tuple
    always_fixed: tuple = ()
    elements: np.ndarray | None = None
    section: BeamSection | None = None
    rotations: np.ndarray | None = None  # per element 3x3, rows = local axes in the body frame
    #: rigid masses fixed to nodes (:func:`add_rigid_mass`): (node, second-moment tensor about it)
    rigid_masses: tuple = ()

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)


def _hermite(xi, L):
    """Cubic Hermite shape functions on [0, L] (dofs v1, v1', v2, v2') and first derivatives."""
    H = np.array([1 - 3 * xi**2 + 2 * xi**3, L * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3, L * (-(xi**2) + xi**3)])
    dH = np.array([(-6 * xi + 6 * xi**2) / L, 1 - 4 * xi + 3 * xi**2, (6 * xi - 6 * xi**2) / L, -2 * xi + 3 * xi**2])
    return H, dH


def _element_local(sec: BeamSection, L: float, rotary: bool):
    """12x12 local stiffness and consistent mass of a 3-D Euler-Bernoulli beam element."""
    K = np.zeros((12, 12))
    M = np.zeros((12, 12))
    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    bar_m = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
    ax, tor = [0, 6], [3, 9]
    K[np.ix_(ax, ax)] = sec.E * sec.A / L * bar
    M[np.ix_(ax, ax)] = sec.rho * sec.A * L * bar_m
    K[np.ix_(tor, tor)] = sec.G * sec.J / L * bar
    M[np.ix_(tor, tor)] = sec.rho * sec.Ip * L * bar_m
    kb = np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L * L, -6 * L, 2 * L * L], [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L * L, -6 * L, 4 * L * L]]) / L**3
    mb = np.array([[156, 22 * L, 54, -13 * L], [22 * L, 4 * L * L, 13 * L, -3 * L * L], [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L * L, -22 * L, 4 * L * L]]) * L / 420
    mr = np.array([[36, 3 * L, -36, 3 * L], [3 * L, 4 * L * L, -3 * L, -L * L], [-36, -3 * L, 36, -3 * L], [3 * L, -L * L, -3 * L, 4 * L * L]]) / (30 * L)
    S = np.diag([1.0, -1.0, 1.0, -1.0])  # x-z plane: dofs (w, ry) with ry = -w'
    xy, xz = [1, 5, 7, 11], [2, 4, 8, 10]
    K[np.ix_(xy, xy)] = sec.E * sec.Iz * kb
    K[np.ix_(xz, xz)] = sec.E * sec.Iy * S @ kb @ S
    M[np.ix_(xy, xy)] = sec.rho * sec.A * mb + (sec.rho * sec.Iz * mr if rotary else 0.0)
    M[np.ix_(xz, xz)] = sec.rho * sec.A * S @ mb @ S + (sec.rho * sec.Iy * S @ mr @ S if rotary else 0.0)
    return K, M


def _local_interp(xi, L):
    """3x12 local interpolation of the translation (u, v, w) at xi in [0, 1]."""
    H, _ = _hermite(xi, L)
    N = np.zeros((3, 12))
    N[0, 0], N[0, 6] = 1 - xi, xi
    N[1, [1, 5, 7, 11]] = H
    N[2, [2, 4, 8, 10]] = H * np.array([1.0, -1.0, 1.0, -1.0])
    return N


def _frame(direction, up):
    e1 = np.asarray(direction, float)
    if e1.shape != (3,) or not np.all(np.isfinite(e1)) or np.linalg.norm(e1) == 0:
        raise ModelError(f"beam_model: direction must be a non-zero 3-vector, got {direction!r}")
    e1 = e1 / np.linalg.norm(e1)
    u = np.asarray(up, float)
    e2 = np.cross(u, e1)
    if np.linalg.norm(e2) < 1e-9:
        raise ModelError(f"beam_model: up {up!r} is parallel to the beam direction {direction!r}")
    e2 /= np.linalg.norm(e2)
    return np.array([e1, e2, np.cross(e1, e2)])


def beam_model(section: BeamSection, length: float, n_elements: int, *, start=(0.0, 0.0, 0.0), direction=(1.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), planar: bool = False, rotary_inertia: bool = False, gauss: int = 4) -> FEModel:
    """Straight uniform Euler–Bernoulli beam of ``n_elements`` equal elements from ``start``.

    Each element has linear axial and torsional and cubic Hermite bending interpolation in both
    planes (12 DOFs, consistent mass; ``rotary_inertia`` adds ρI of the section). The local y
    axis is up × direction (the default beam along x has local y = body y, local z = body z).
    ``planar`` keeps the motion in the local x–y plane (uz, rx, ry fixed at every node).
    Second-order invariants use ``gauss`` points per element as mass points (ρA w L each).
    """
    length = _num(length, "beam_model: length")
    if not (np.isfinite(length) and length > 0):
        raise ModelError(f"beam_model: length must be > 0, got {length}")
    if not isinstance(n_elements, (int, np.integer)) or n_elements < 1:
        raise ModelError(f"beam_model: n_elements must be a positive integer, got {n_elements}")
    n_el = int(n_elements)
    Lam = _frame(direction, up)
    start = np.asarray(start, float)
    nodes = start + np.outer(np.linspace(0.0, length, n_el + 1), Lam[0])
    ndof = 6 * (n_el + 1)
    K = np.zeros((ndof, ndof))
    M = np.zeros((ndof, ndof))
    Le = length / n_el
    Ke, Me = _element_local(section, Le, rotary_inertia)
    T = np.kron(np.eye(4), Lam)
    Kg, Mg = T.T @ Ke @ T, T.T @ Me @ T
    xg, wg = np.polynomial.legendre.leggauss(gauss)
    xg, wg = 0.5 * (xg + 1), 0.5 * wg
    pos, mass, interp = [], [], []
    for e in range(n_el):
        sl = slice(6 * e, 6 * e + 12)
        K[sl, sl] += Kg
        M[sl, sl] += Mg
        for x, w in zip(xg, wg):
            pos.append(nodes[e] + x * Le * Lam[0])
            mass.append(section.rho * section.A * Le * w)
            N = np.zeros((3, ndof))
            N[:, sl] = Lam.T @ _local_interp(x, Le) @ T
            interp.append(N)
    fixed = ()
    if planar:
        # out-of-plane translation along local z and rotations about local x, y: fixed where the
        # beam lies along a body axis (the usual case); otherwise they are not plain DOFs
        if not np.allclose(np.abs(Lam), np.round(np.abs(Lam))):
            raise ModelError("beam_model: planar beams must lie along a body axis with up along another")
        iz = int(np.argmax(np.abs(Lam[2])))
        ix, iy = int(np.argmax(np.abs(Lam[0]))), int(np.argmax(np.abs(Lam[1])))
        fixed = tuple(6 * i + d for i in range(n_el + 1) for d in (iz, 3 + ix, 3 + iy))
    elements = np.array([[e, e + 1] for e in range(n_el)])
    return FEModel(nodes=nodes, M=M, K=K, mass_points=(np.array(pos), np.array(mass), np.array(interp)), always_fixed=fixed, elements=elements, section=section, rotations=np.repeat(Lam[None], n_el, axis=0))


def add_rigid_mass(model: FEModel, node: int, mass: float, inertia=(0.0, 0.0, 0.0)) -> FEModel:
    """The model with a rigid body (a disc, a hub, a tool) of ``mass`` and principal ``inertia``
    (Jxx, Jyy, Jzz along the body axes, about the node) fixed to ``node``: added to M at the node's
    translations and rotations, and as six mass points on the axes around the node (moving with
    the node's translation and rotation) that carry exactly that mass and inertia into the
    second-order invariants, so a spinning disc's gyroscopic coupling is in the reduced body."""
    n = _node_index(node, model.n_nodes, "add_rigid_mass: node")
    m = _num(mass, "add_rigid_mass: mass")
    j = np.asarray(inertia, dtype=float)
    if not (np.isfinite(m) and m > 0):
        raise ModelError(f"add_rigid_mass: mass must be > 0, got {mass}")
    if j.shape != (3,) or not np.all(np.isfinite(j)) or np.any(j < 0):
        raise ModelError(f"add_rigid_mass: inertia must be three principal moments >= 0, got {inertia!r}")
    # second moments S_a = ∫ a² dm from J: S_x = (J_yy + J_zz - J_xx)/2, ... (triangle inequality)
    sec = 0.5 * np.array([j[1] + j[2] - j[0], j[0] + j[2] - j[1], j[0] + j[1] - j[2]])
    if np.any(sec < -1e-12 * max(j.max(), 1e-300)):
        raise ModelError(f"add_rigid_mass: inertia {tuple(j)} violates the triangle inequality (J_xx <= J_yy + J_zz, ...)")
    sec = np.maximum(sec, 0.0)
    ndof = 6 * model.n_nodes
    M = model.M.copy()
    dofs = np.arange(6 * n, 6 * n + 6)
    M[dofs[:3], dofs[:3]] += m
    M[dofs[3:], dofs[3:]] += j
    pos, mp, interp = (np.asarray(a) for a in model.mass_points)
    if sec.sum() > 0:
        # six points at ±d on the axes: pair a has mass 2 m_a with 2 m_a d² = S_a, Σ 2 m_a = m
        d = np.sqrt(sec.sum() / m)
        extra_pos, extra_m, extra_n = [], [], []
        for a in range(3):
            for sgn in (1.0, -1.0):
                off = np.zeros(3)
                off[a] = sgn * d
                N = np.zeros((3, ndof))
                N[:, dofs[:3]] = np.eye(3)
                N[:, dofs[3:]] = -skew(off)  # u = u_node + θ × off
                extra_pos.append(model.nodes[n] + off)
                extra_m.append(sec[a] / (2 * d * d))
                extra_n.append(N)
        pos = np.concatenate([pos.reshape(-1, 3), np.array(extra_pos)])
        mp = np.concatenate([mp.reshape(-1), np.array(extra_m)])
        interp = np.concatenate([interp.reshape(-1, 3, ndof), np.array(extra_n)])
    else:
        N = np.zeros((1, 3, ndof))
        N[0][:, dofs[:3]] = np.eye(3)
        pos = np.concatenate([pos.reshape(-1, 3), model.nodes[n][None]])
        mp = np.concatenate([mp.reshape(-1), [m]])
        interp = np.concatenate([interp.reshape(-1, 3, ndof), N])
    return FEModel(nodes=model.nodes, M=M, K=model.K, mass_points=(pos, mp, interp), always_fixed=model.always_fixed,
                   elements=model.elements, section=model.section, rotations=model.rotations,
                   rigid_masses=tuple(model.rigid_masses) + ((n, np.diag(sec)),))


def fe_model(nodes, M, K, *, node_masses=None, name: str = "fe_model") -> FEModel:
    """Full matrices of an external FE code, 6 DOFs per node in the order (ux, uy, uz, rx, ry, rz)
    of node 0, node 1, ... (fix the rotation DOFs of solid-element nodes: they carry no mass).

    The second-order invariants use the nodes as mass points with ``node_masses`` (default: the
    row sums of the translational part of M, the mass a rigid translation puts on each node).
    """
    nodes = np.asarray(nodes, float)
    if nodes.ndim != 2 or nodes.shape[1] != 3 or not np.all(np.isfinite(nodes)):
        raise ModelError(f"{name}: nodes must be a finite (n, 3) array, got shape {nodes.shape}")
    n = len(nodes)
    M = _square(M, 6 * n, f"{name}: M")
    K = _square(K, 6 * n, f"{name}: K")
    _check_symmetric(M, f"{name}: M")
    _check_symmetric(K, f"{name}: K")
    if node_masses is None:
        node_masses = np.array([np.mean([M[6 * i + d, d::6].sum() for d in range(3)]) for i in range(n)])
    node_masses = np.asarray(node_masses, float)
    if node_masses.shape != (n,) or not np.all(np.isfinite(node_masses)) or np.any(node_masses < 0):
        raise ModelError(f"{name}: node_masses must be {n} finite values >= 0, got {node_masses!r}")
    interp = np.zeros((n, 3, 6 * n))
    for i in range(n):
        interp[i, :, 6 * i : 6 * i + 3] = np.eye(3)
    return FEModel(nodes=nodes, M=M, K=K, mass_points=(nodes.copy(), node_masses, interp))


def _square(A, n, what):
    A = np.asarray(A, float)
    if A.shape != (n, n):
        raise ModelError(f"{what} must be {n}x{n} (6 DOFs per node), got shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise ModelError(f"{what} has non-finite entries")
    return A


def _check_symmetric(A, what, rtol=1e-9):
    d = np.abs(A - A.T)
    if d.size and d.max() > rtol * max(np.abs(A).max(), 1e-300):
        i, j = np.unravel_index(np.argmax(d), d.shape)
        raise ModelError(f"{what} is not symmetric: entry ({i}, {j}) = {A[i, j]:.6g} but ({j}, {i}) = {A[j, i]:.6g}")


# --------------------------------------------------------------------------------------------
# Boundary conditions and reduction
# --------------------------------------------------------------------------------------------


def _node_index(node, n, what):
    if isinstance(node, (bool, np.bool_)) or not isinstance(node, (int, np.integer)):
        raise ModelError(f"{what}: node {node!r} is not an integer index")
    i = int(node)
    if not -n <= i < n:
        raise ModelError(f"{what}: node {node} does not exist (the model has {n} nodes, 0..{n - 1})")
    return i % n


def _fixed_dofs(model: FEModel, fixed, what: str) -> list[int]:
    dofs = set(model.always_fixed)
    for node, spec in (fixed or {}).items():
        i = _node_index(node, model.n_nodes, what)
        if spec == "clamped":
            names = DOF_NAMES
        elif spec == "pinned":
            names = DOF_NAMES[:3]
        elif isinstance(spec, str):
            names = [spec]
        elif isinstance(spec, (list, tuple, set)):
            names = list(spec)
        else:
            raise ModelError(f"{what}: node {node}: give 'clamped', 'pinned' or a list of DOF names from {DOF_NAMES}, got {spec!r}")
        for nm in names:
            if nm not in DOF_NAMES:
                raise ModelError(f"{what}: unknown DOF {nm!r} at node {node} (use 'clamped', 'pinned' or names from {DOF_NAMES})")
            dofs.add(6 * i + DOF_NAMES.index(nm))
    return sorted(dofs)


def _rigid_modes(nodes) -> np.ndarray:
    """Γ (6n, 6): nodal translations and rotations of a rigid motion (v, ω) of the body frame:
    node i moves by v − r̃_i ω and rotates by ω."""
    n = len(nodes)
    G = np.zeros((6 * n, 6))
    for i, r in enumerate(nodes):
        G[6 * i : 6 * i + 3, :3] = np.eye(3)
        G[6 * i : 6 * i + 3, 3:] = -skew(r)
        G[6 * i + 3 : 6 * i + 6, 3:] = np.eye(3)
    return G


def _n_admissible_rigid(model: FEModel, fixed: list[int]) -> int:
    """Dimension of the rigid motions the fixed DOFs allow (they stay in the unreduced model)."""
    G = _rigid_modes(model.nodes)
    if not fixed:
        return 6
    s = np.linalg.svd(G[fixed], compute_uv=False)
    scale = max(1.0, np.abs(model.nodes).max())
    return 6 - int(np.sum(s > 1e-9 * scale))


def _sign_fix(V):
    for k in range(V.shape[1]):
        i = np.argmax(np.abs(V[:, k]))
        if V[i, k] < 0:
            V[:, k] *= -1.0
    return V


def modal_reduction(model: FEModel, n_modes: int, *, fixed=None, held=None, name: str = "elastic_body") -> "ReducedBody":
    """Modal truncation: the n_modes lowest elastic modes of (K, M) with ``fixed`` DOFs held,
    mass-normalized (M = I, K = diag ω²). Rigid-body motions the supports allow (e.g. all six
    for a free–free body) are recognized from the geometry and left out of the elastic basis.

    ``fixed`` maps node index (negative counts from the end) to 'clamped', 'pinned' (the three
    translations) or a list of DOF names from :data:`DOF_NAMES`.

    ``held`` (same form) names where the model's joints hold the body, for the stress state of the
    geometric stiffness (:func:`geometric_fields`): the body forces' reactions flow there. By
    default the fixed DOFs; where they leave rigid motions free (a free–free basis), inertia relief
    (right for a free-flying body; a free–free basis on a joint at its centre wants ``held``).
    """
    dofs = _fixed_dofs(model, fixed, f"elastic body {name!r}")
    free = np.setdiff1d(np.arange(6 * model.n_nodes), dofs)
    n_rigid = _n_admissible_rigid(model, dofs)
    n_avail = len(free) - n_rigid
    if int(n_modes) != n_modes or not 1 <= n_modes <= n_avail:
        raise ModelError(f"elastic body {name!r}: n_modes must be 1..{n_avail}, got {n_modes}")
    Mf, Kf = model.M[np.ix_(free, free)], model.K[np.ix_(free, free)]
    try:
        w2, V = linalg.eigh(Kf, Mf, subset_by_index=[0, n_rigid + int(n_modes) - 1])
    except linalg.LinAlgError as exc:
        raise ModelError(f"elastic body {name!r}: M restricted to the free DOFs is not positive definite ({exc})") from None
    V = _sign_fix(V[:, n_rigid:])
    T = np.zeros((6 * model.n_nodes, V.shape[1]))
    T[free] = V
    labels = [f"mode{k + 1}" for k in range(V.shape[1])]
    stress = dofs if held is None else sorted(set(dofs) | set(_fixed_dofs(model, held, f"elastic body {name!r} held")))
    return _build(name, model, T, labels, interface=(), fixed_dofs=stress)


def craig_bampton(model: FEModel, n_modes: int, interface, *, fixed=None, held=None, name: str = "elastic_body") -> "ReducedBody":
    """Craig–Bampton reduction: the free DOFs of the ``interface`` nodes are kept as coordinates
    (static constraint modes Ψ = −K_ii⁻¹ K_ib: unit displacement of one interface DOF, the others
    held, interior relaxed) plus ``n_modes`` fixed-interface normal modes of (K_ii, M_ii).
    q = (η_1..η_n, interface DOFs); u = [[Φ_i, Ψ], [0, I]] q.

    For a floating-frame body the frame's reference conditions go into ``fixed``; interface
    DOFs that leave a rigid-body motion free make K singular and are refused by
    :class:`ReducedBody`. ``held``: as for :func:`modal_reduction` (the geometric stiffness).
    """
    what = f"elastic body {name!r}"
    dofs = _fixed_dofs(model, fixed, what)
    if isinstance(interface, (str, bytes)) or not hasattr(interface, "__iter__"):
        raise ModelError(f"{what}: interface must be a list of node indices, got {interface!r}")
    inodes = sorted({_node_index(i, model.n_nodes, what + " interface") for i in interface})
    if not inodes:
        raise ModelError(f"{what}: craig_bampton needs at least one interface node")
    b = [6 * i + d for i in inodes for d in range(6) if 6 * i + d not in dofs]
    free = np.setdiff1d(np.arange(6 * model.n_nodes), dofs)
    ii = np.setdiff1d(free, b)
    if int(n_modes) != n_modes or not 0 <= n_modes <= len(ii):
        raise ModelError(f"{what}: n_modes must be 0..{len(ii)} (interior DOFs), got {n_modes}")
    Kii, Kib = model.K[np.ix_(ii, ii)], model.K[np.ix_(ii, b)]
    Mii = model.M[np.ix_(ii, ii)]
    try:
        cf = linalg.cho_factor(Kii)
    except linalg.LinAlgError:
        raise ModelError(f"{what}: the interior (interface nodes {inodes} and fixed DOFs held) is not restrained: K_ii is singular; fix the reference conditions") from None
    Psi = -linalg.cho_solve(cf, Kib)
    T = np.zeros((6 * model.n_nodes, int(n_modes) + len(b)))
    if n_modes:
        _, Phi = linalg.eigh(Kii, Mii, subset_by_index=[0, int(n_modes) - 1])
        T[ii, : int(n_modes)] = _sign_fix(Phi)
    T[ii, int(n_modes) :] = Psi
    T[b, int(n_modes) :] = np.eye(len(b))
    labels = [f"mode{k + 1}" for k in range(int(n_modes))] + [f"n{d // 6}.{DOF_NAMES[d % 6]}" for d in b]
    stress = dofs if held is None else sorted(set(dofs) | set(_fixed_dofs(model, held, what + " held")))
    return _build(name, model, T, labels, interface=tuple(inodes), fixed_dofs=stress)


def geometric_fields(model: FEModel, T: np.ndarray, fixed_dofs) -> np.ndarray:
    """The geometric (stress) stiffness of the basis T for the 12 unit body-force fields per unit
    mass the engine combines (``e_x, e_y, e_z``, then ``e_a s_b``), (12, q, q): each field's
    static response of the supported beam model gives the elements' axial forces and so K_G
    (with inertia relief where the supports leave rigid motions free: a free-flying or a pinned
    body is stressed by the part of each field its rigid acceleration does not take up)
    (:func:`geometric_stiffness`); a rigid mass fixed to a node adds the work of the field on its
    points' second-order motion under the node's rotation, ``-(sym(L S) - tr(L S) E)`` on the
    rotations (S its second-moment tensor): a spinning disc's tilt stiffening (J_p - J_d) Ω²."""
    if model.elements is None or model.section is None:
        raise ModelError("geometric_fields: needs a beam model from beam_model")
    ndof = 6 * model.n_nodes
    fixed = sorted(int(d) for d in fixed_dofs)
    # inertia relief: where the supports leave rigid motions free (a free-free body), each field
    # accelerates the body rigidly and only its self-equilibrated rest, f - M Γ a, stresses it;
    # that rest is then carried on a statically determinate set of extra supports, whose
    # reactions are zero, so the stress does not depend on which DOFs they are
    G = _rigid_modes(model.nodes)
    scale = max(1.0, np.abs(model.nodes).max())
    if fixed:
        _, sv, vt = np.linalg.svd(G[fixed])
        rank = int(np.sum(sv > 1e-9 * scale))
        Ga = G @ vt[rank:].T
    else:
        Ga = G
    relief = None
    if Ga.shape[1]:
        mg = Ga.T @ model.M @ Ga
        relief = model.M @ Ga @ np.linalg.solve(mg, Ga.T)
        order = [6 * i + d for i in (0, model.n_nodes - 1, *range(1, model.n_nodes - 1)) for d in range(6)]
        held = list(fixed)
        for d in order:
            if d in held:
                continue
            if _n_admissible_rigid(model, held + [d]) < _n_admissible_rigid(model, held):
                held.append(d)
            if _n_admissible_rigid(model, held) == 0:
                break
        fixed = sorted(held)
    free = np.setdiff1d(np.arange(ndof), np.asarray(fixed, dtype=int))
    kff = model.K[np.ix_(free, free)]
    try:
        cf = linalg.cho_factor(kff)
    except linalg.LinAlgError:
        raise ModelError("geometric_fields: the beam model is not held even with inertia-relief supports (K singular): "
                         "is it in one piece?") from None
    pos, mp, interp = (np.asarray(a) for a in model.mass_points)
    s0 = np.cumsum([0.0] + [np.linalg.norm(model.nodes[j] - model.nodes[i]) for i, j in model.elements])
    ea = model.section.E * model.section.A
    out = np.zeros((12, T.shape[1], T.shape[1]))
    for f in range(12):
        if f < 3:
            b = np.zeros((len(pos), 3))
            b[:, f] = 1.0
            lmat = np.zeros((3, 3))
        else:
            a, c = divmod(f - 3, 3)
            b = np.zeros((len(pos), 3))
            b[:, a] = pos[:, c]
            lmat = np.zeros((3, 3))
            lmat[a, c] = 1.0
        load = np.einsum("p,pad,pa->d", mp, interp, b)
        if relief is not None:
            load = load - relief @ load
        u = np.zeros(ndof)
        u[free] = linalg.cho_solve(cf, load[free])
        forces = []
        for e, (i, j) in enumerate(model.elements):
            t = model.rotations[e][0]
            le = np.linalg.norm(model.nodes[j] - model.nodes[i])
            forces.append(ea * (u[6 * j : 6 * j + 3] - u[6 * i : 6 * i + 3]) @ t / le)

        def axial(sv, forces=forces):
            k = min(int(np.searchsorted(s0, sv, side="right")) - 1, len(forces) - 1)
            return forces[max(k, 0)]

        kg = geometric_stiffness(model, axial)
        for node, second in model.rigid_masses:
            ls = lmat @ second
            rot = slice(6 * node + 3, 6 * node + 6)
            kg[rot, rot] -= 0.5 * (ls + ls.T) - np.trace(ls) * np.eye(3)
        out[f] = T.T @ kg @ T
    return 0.5 * (out + out.transpose(0, 2, 1))


def _build(name, model: FEModel, T, labels, interface, fixed_dofs=None) -> "ReducedBody":
    """Reduced matrices and inertia invariants of the basis T (6n x q) of the full model."""
    M, K = T.T @ model.M @ T, T.T @ model.K @ T
    inv = _invariants(model.nodes, model.M, model.mass_points, T)
    modes = T.reshape(model.n_nodes, 6, T.shape[1])
    geometric = None
    if fixed_dofs is not None and model.elements is not None and model.section is not None:
        geometric = geometric_fields(model, T, fixed_dofs)
    return ReducedBody(name=name, nodes=model.nodes.copy(), M=0.5 * (M + M.T), K=0.5 * (K + K.T), modes=modes, interface_nodes=tuple(interface), labels=tuple(labels), geometric=geometric, **inv)


def _vee(A):
    return np.array([A[2, 1], A[0, 2], A[1, 0]])


def _skews(V):
    """Skew matrices of the 3-vectors along axis -2 of V (..., 3, k) -> (..., k, 3, 3)."""
    x, y, z = V[..., 0, :], V[..., 1, :], V[..., 2, :]
    o = np.zeros_like(x)
    return np.stack([np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2)


def _second_order(pos, mp, Phi) -> dict:
    """I1, I2, G_k of mass points at pos (p, 3) with masses mp (p,) and translations Phi (p, 3, q)."""
    rt = np.array([skew(r) for r in pos])  # (p, 3, 3)
    Pt = _skews(Phi)  # (p, q, 3, 3)
    I1 = -(np.einsum("p,pij,pkjl->kil", mp, rt, Pt) + np.einsum("p,pkij,pjl->kil", mp, Pt, rt))
    I2 = -np.einsum("p,pkij,pljm->klim", mp, Pt, Pt)
    Gk = np.einsum("p,pkij,pjl->kil", mp, Pt, Phi)
    # the engine's form of the same integrals: P1_k = ∫ r Φ_kᵀ dm, P2_kl = ∫ Φ_k Φ_lᵀ dm
    P1 = np.einsum("p,pa,pbk->kab", mp, pos, Phi)
    P2 = np.einsum("p,pak,pbl->klab", mp, Phi, Phi)
    return dict(I1=I1, I2=0.5 * (I2 + I2.transpose(1, 0, 2, 3)), Gk=Gk, P1=P1, P2=P2)


def _invariants(nodes, M_full, mass_points, T) -> dict:
    G = _rigid_modes(nodes)
    rig = G.T @ M_full @ G
    C = G.T @ M_full @ T
    pos, mp, interp = mass_points
    Phi = np.einsum("pad,dk->pak", interp, T)  # (p, 3, q) translation of each mass point
    return dict(mass=float(rig[0, 0]), first_moment=_vee(rig[3:, :3]), inertia=0.5 * (rig[3:, 3:] + rig[3:, 3:].T), Ct=C[:3], Cr=C[3:], **_second_order(pos, mp, Phi))


def analytic_beam_body(section: BeamSection, length: float, bc: str, n_modes: int, *, n_nodes: int = 11, plane: str = "xy", name: str = "elastic_body", cells: int = 40, order: int = 10) -> "ReducedBody":
    """A reduced body from analytic Euler–Bernoulli modes of a uniform beam along body x from the
    origin (bc as in :func:`euler_bernoulli_roots`; free–free: the elastic modes only).

    ``plane`` "xy": deflection along y (bending stiffness E Iz, rotation rz = φ'); "xz": along z
    (E Iy, ry = −φ'). Each shape is scaled to unit modal mass ∫ ρA φ² dx = 1. M = ∫ ρA φ_k φ_l dx
    and K = ∫ E I φ_k'' φ_l'' dx, and every invariant, are integrated with ``cells`` x ``order``
    Gauss–Legendre points; ``modes`` samples φ and φ' at ``n_nodes`` equidistant nodes.
    The inertia about the beam axis includes the section's polar inertia ρ Ip L.
    """
    if plane not in ("xy", "xz"):
        raise ModelError(f"analytic_beam_body: plane must be 'xy' or 'xz', got {plane!r}")
    length = _num(length, "analytic_beam_body: length")
    if not (np.isfinite(length) and length > 0):
        raise ModelError(f"analytic_beam_body: length must be > 0, got {length}")
    if not isinstance(n_nodes, (int, np.integer)) or n_nodes < 2:
        raise ModelError(f"analytic_beam_body: n_nodes must be an integer >= 2, got {n_nodes!r}")
    if not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
        raise ModelError(f"analytic_beam_body: n_modes must be a positive integer, got {n_modes!r}")
    I = section.Iz if plane == "xy" else section.Iy
    d, rot, sgn = (1, 5, 1.0) if plane == "xy" else (2, 4, -1.0)
    rA = section.rho * section.A
    edges = np.linspace(0.0, length, cells + 1)
    xg, wg = np.polynomial.legendre.leggauss(order)
    x = np.concatenate([0.5 * (b - a) * xg + 0.5 * (a + b) for a, b in zip(edges[:-1], edges[1:])])
    w = np.concatenate([0.5 * (b - a) * wg for a, b in zip(edges[:-1], edges[1:])])
    phi = np.array([euler_bernoulli_mode(bc, k, x, length) for k in range(1, n_modes + 1)])  # (q, p)
    scale = 1.0 / np.sqrt(rA * (phi**2) @ w)
    phi *= scale[:, None]
    ddphi = np.array([euler_bernoulli_mode(bc, k, x, length, 2) for k in range(1, n_modes + 1)]) * scale[:, None]
    M = rA * (phi * w) @ phi.T
    K = section.E * I * (ddphi * w) @ ddphi.T
    pos = np.zeros((len(x), 3))
    pos[:, 0] = x
    mp = rA * w
    Phi = np.zeros((len(x), 3, n_modes))
    Phi[:, d, :] = phi.T
    nodes = np.zeros((n_nodes, 3))
    nodes[:, 0] = np.linspace(0.0, length, n_nodes)
    modes = np.zeros((n_nodes, 6, n_modes))
    for k in range(n_modes):
        modes[:, d, k] = scale[k] * euler_bernoulli_mode(bc, k + 1, nodes[:, 0], length)
        modes[:, rot, k] = sgn * scale[k] * euler_bernoulli_mode(bc, k + 1, nodes[:, 0], length, 1)
    rt = np.array([skew(r) for r in pos])
    inertia = -np.einsum("p,pij,pjk->ik", mp, rt, rt)
    inertia[0, 0] += section.rho * section.Ip * length
    geometric = None
    if bc in ("clamped-free", "cantilever"):
        # stress stiffening of the 12 unit body-force fields (per unit mass) the engine combines:
        # along the beam only the axial field components load it, N(x) = ρA ∫_x^L b_x dξ (the
        # tip is free); uniform e_x gives ρA (L - x), the linear field e_x s_x gives ρA (L² - x²)/2
        dphi = np.array([euler_bernoulli_mode(bc, k, x, length, 1) for k in range(1, n_modes + 1)]) * scale[:, None]
        kg = lambda n: (dphi * (n * w)) @ dphi.T  # noqa: E731
        geometric = np.zeros((12, n_modes, n_modes))
        geometric[0] = kg(rA * (length - x))
        geometric[3] = kg(rA * 0.5 * (length**2 - x**2))
    return ReducedBody(
        name=name, nodes=nodes, M=0.5 * (M + M.T), K=0.5 * (K + K.T), modes=modes, mass=float(mp.sum()), first_moment=mp @ pos, inertia=inertia,
        Ct=np.einsum("p,pak->ak", mp, Phi), Cr=np.einsum("p,pab,pbk->ak", mp, rt, Phi), labels=tuple(f"mode{k + 1}" for k in range(n_modes)),
        geometric=geometric, **_second_order(pos, mp, Phi),
    )


# ============================================================================================
# The reduced body
# ============================================================================================


@dataclass
class ReducedBody:
    """Data of a floating-frame elastic body: shapes, matrices and inertia invariants (SI).

    With u(r, t) = Φ(r) q(t) the elastic translation (Φ the translational rows of ``modes``) and
    the absolute velocity of eq. 2.191, v_P = v + ω̃ (r + u) + u̇, the kinetic energy eq. 2.192 is

        T = ½ m vᵀv + vᵀ ω̃ (c + C_t q) + vᵀ C_t q̇ + ½ ωᵀ I(q) ω
            + ωᵀ (C_r + Σ_k q_k G_k) q̇ + ½ q̇ᵀ M q̇,

    where (∫ over the body mass dm = ρ dV, r̃ the skew matrix of r, Φ̃_k that of mode k's
    translation):

    * ``mass``          m   = ∫ dm
    * ``first_moment``  c   = ∫ r dm = m r_S (eq. 2.184)
    * ``inertia``       I₀  = −∫ r̃ r̃ dm about the body origin (eq. 2.184)
    * ``Ct``  (3, q)    C_t = ∫ Φ dm
    * ``Cr``  (3, q)    C_r = ∫ r̃ Φ dm
    * ``M``   (q, q)    M   = ∫ Φᵀ Φ dm (plus the rotary terms of the section)
    * ``I1``  (q, 3, 3) I1_k = −∫ (r̃ Φ̃_k + Φ̃_k r̃) dm
    * ``I2``  (q, q, 3, 3) I2_kl = −∫ Φ̃_k Φ̃_l dm (symmetric in k, l), so that
      I(q) = I₀ + Σ_k q_k I1_k + Σ_kl q_k q_l I2_kl = −∫ (r̃ + ũ)(r̃ + ũ) dm
    * ``Gk``  (q, 3, q) G_k = ∫ Φ̃_k Φ dm, so that ∫ ũ Φ dm = Σ_k q_k G_k.

    The rotation of the mass elements themselves (the ω̃_BiBei u term of eq. 2.191, second order
    in the elastic quantities) and, in I1/I2/G_k, the section's rotary inertia are left out.

    The zeroth- and first-order invariants (m, c, I₀, C_t, C_r, M) are taken with the full FE
    mass matrix M_FE and the nodal rigid-body motions Γ (node i: translation v − r̃_i ω,
    rotation ω): Γᵀ M_FE Γ = [[m I, −c̃], [c̃, I₀]], Γᵀ M_FE T = [C_t; C_r], so section rotary
    and torsional inertia are included. The second-order ones (I1, I2, G_k) integrate the
    translation field over mass points (Gauss points along beam elements, or lumped node masses).

    ``modes`` (n, 6, q): per node (ux, uy, uz, rx, ry, rz) per coordinate; ``interface_nodes``
    the nodes kept as Craig–Bampton coordinates; ``labels`` the coordinate names.

    Checked on construction (errors name the body and the item): shapes, finite values,
    M symmetric positive definite, K symmetric positive semi-definite and no rigid-body
    (zero-frequency) mode in the basis, interface nodes that exist; frequencies above
    :data:`FREQUENCY_WARNING_HZ` give a warning (unit confusion).
    """

    name: str
    nodes: np.ndarray
    M: np.ndarray
    K: np.ndarray
    modes: np.ndarray
    mass: float
    first_moment: np.ndarray
    inertia: np.ndarray
    Ct: np.ndarray
    Cr: np.ndarray
    I1: np.ndarray | None = None
    I2: np.ndarray | None = None
    Gk: np.ndarray | None = None
    P1: np.ndarray | None = None
    P2: np.ndarray | None = None
    geometric: np.ndarray | None = None
    interface_nodes: tuple = ()
    labels: tuple = ()
    omega: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        _validate(self)

    @property
    def n_coordinates(self) -> int:
        return self.M.shape[0]

    @property
    def center_of_mass(self) -> np.ndarray:
        return self.first_moment / self.mass

    def frequencies(self) -> np.ndarray:
        """Natural frequencies of the elastic coordinates with the body frame held (Hz)."""
        return self.omega / (2 * np.pi)

    def save(self, path) -> Path:
        """Write the body in the layout of :func:`save_reduced`."""
        return save_reduced(self, path)

    def _q(self, q, what):
        q = np.zeros(self.n_coordinates) if q is None else np.asarray(q, dtype=float)
        if q.shape != (self.n_coordinates,) or not np.all(np.isfinite(q)):
            raise ModelError(f"elastic body {self.name!r}: {what} must be {self.n_coordinates} finite values, got {q!r}")
        return q

    def mass_matrix(self, q=None) -> np.ndarray:
        """Floating-frame mass matrix M(q), (6 + n) x (6 + n), for the velocities (v, ω, q̇) in the
        body frame, such that T = ½ xᵀ M(q) x is the kinetic energy of the class docstring:

            [[ m I,         −(c + C_t q)~,     C_t              ],
             [ (c + C_t q)~, I(q),             C_r + Σ q_k G_k  ],
             [ C_tᵀ,         (C_r + Σ q_k G_k)ᵀ, M              ]]

        Needs the second-order invariants (I2, Gk; I1) when q ≠ 0.
        """
        q = self._q(q, "q")
        n = self.n_coordinates
        cq = self.first_moment + self.Ct @ q
        Iq = self.inertia.copy()
        Crq = self.Cr.copy()
        if np.any(q != 0):
            if self.I1 is None or self.I2 is None or self.Gk is None:
                raise ModelError(f"elastic body {self.name!r}: mass_matrix(q != 0) needs the second-order invariants I1, I2, Gk")
            Iq += np.einsum("k,kij->ij", q, self.I1) + np.einsum("k,l,klij->ij", q, q, self.I2)
            Crq += np.einsum("k,kij->ij", q, self.Gk)
        out = np.zeros((6 + n, 6 + n))
        out[:3, :3] = self.mass * np.eye(3)
        out[:3, 3:6] = -skew(cq)
        out[3:6, :3] = skew(cq)
        out[:3, 6:] = self.Ct
        out[6:, :3] = self.Ct.T
        out[3:6, 3:6] = 0.5 * (Iq + Iq.T)
        out[3:6, 6:] = Crq
        out[6:, 3:6] = Crq.T
        out[6:, 6:] = self.M
        return out

    def to_engine(self) -> dict:
        """The engine's table of this body (``Model.add_body(..., elastic=...)``, ``[bodies.elastic]``
        in a model file): the invariants S_t, P1, P2, the stiffness, the geometric stiffness
        when known, and the nodes with their translations and small rotations per coordinate."""
        if self.P1 is None or self.P2 is None:
            raise ModelError(f"elastic body {self.name!r}: the engine needs the mass-point invariants P1 and P2 "
                             "(bodies from analytic modes, the beam model and files that carry them have them)")
        q = self.n_coordinates
        out = {
            "modes": q,
            "s_t": np.asarray(self.Ct).T.tolist(),
            "p1": [np.asarray(self.P1[k]).reshape(-1).tolist() for k in range(q)],
            "p2": [np.asarray(self.P2[k, l]).reshape(-1).tolist() for k in range(q) for l in range(q)],
            "stiffness": np.asarray(self.K).tolist(),
            "nodes": [{"name": f"n{i}", "position": np.asarray(self.nodes[i]).tolist(),
                       "translation": np.asarray(self.modes[i, :3, :]).T.tolist(),
                       "rotation": np.asarray(self.modes[i, 3:, :]).T.tolist()} for i in range(len(self.nodes))],
        }
        if self.geometric is not None:
            out["geometric"] = np.asarray(self.geometric).tolist()
        rotary = self._rotary_inertia()
        if rotary is not None:
            out["s_r"], out["m_rr"] = rotary[0].T.tolist(), rotary[1].tolist()
        return out

    def _rotary_inertia(self):
        """(S_r (3, q), M_rr (q, q)): what M and C_r hold beyond the mass points' translations — the
        rotary inertia of the sections (a shaft's torsion), None when there is none. M_rr = M − tr P2,
        S_r = C_r − ∫ r × Φ dm over the mass points."""
        tr = np.einsum("klaa->kl", np.asarray(self.P2))
        m_rr = 0.5 * ((self.M - tr) + (self.M - tr).T)
        p1 = np.asarray(self.P1)
        s_r = np.asarray(self.Cr) - np.stack([p1[:, 1, 2] - p1[:, 2, 1], p1[:, 2, 0] - p1[:, 0, 2], p1[:, 0, 1] - p1[:, 1, 0]])
        scale = np.abs(self.M).max()
        if np.abs(m_rr).max() <= 1e-10 * scale and np.abs(s_r).max() <= 1e-10 * np.abs(self.Cr).max(initial=scale):
            return None
        ev = np.linalg.eigvalsh(m_rr)
        if ev[0] < -1e-8 * scale:
            # the mass points and M disagree beyond rotary inertia (lumped points, consistent M)
            warnings.warn(f"elastic body {self.name!r}: M differs from the mass points' translational mass by an indefinite "
                          f"part (eigenvalue {ev[0]:.3g}); the engine uses the mass points' M only", stacklevel=3)
            return None
        return s_r, m_rr

    def inertia_about_center(self) -> np.ndarray:
        """The undeformed inertia tensor about the centre of mass (body axes)."""
        c = self.center_of_mass
        return np.asarray(self.inertia) - self.mass * (c @ c * np.eye(3) - np.outer(c, c))

    def damping(self, *, rayleigh=None, modal=None) -> np.ndarray:
        """A damping matrix: ``rayleigh=(alpha, beta)`` gives αM + βK (eq. 2.207); ``modal=zeta``
        (a number or one per mode) gives each undamped mode the damping ratio ζ."""
        if (rayleigh is None) == (modal is None):
            raise ModelError(f"elastic body {self.name!r}: damping needs rayleigh=(alpha, beta) or modal=zeta")
        if rayleigh is not None:
            a, b = (float(x) for x in rayleigh)
            if not (np.isfinite(a) and np.isfinite(b) and a >= 0 and b >= 0):
                raise ModelError(f"elastic body {self.name!r}: Rayleigh coefficients must be >= 0, got {rayleigh!r}")
            return a * self.M + b * self.K
        w2, V = linalg.eigh(self.K, self.M)
        z = np.broadcast_to(np.asarray(modal, dtype=float), w2.shape)
        if not np.all(np.isfinite(z)) or np.any(z < 0):
            raise ModelError(f"elastic body {self.name!r}: modal damping ratios must be >= 0, got {modal!r}")
        mv = self.M @ V
        return mv @ np.diag(2.0 * z * np.sqrt(np.maximum(w2, 0.0))) @ mv.T

    def plot_modes(self, modes=(0, 1, 2), out=None, scale: float | None = None):
        """Draws mode shapes over the undeformed nodes (matplotlib, a view of the two body axes the
        nodes and deflections spread over most): each mode scaled so its largest node deflection is
        ``scale`` (default a tenth of the body's size), labelled with its frequency. Writes ``out``
        (.png, .svg, .pdf) when given; returns the figure."""
        import matplotlib

        if out is not None:
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        idx = [int(k) for k in np.atleast_1d(modes)]
        bad = [k for k in idx if not 0 <= k < self.n_coordinates]
        if bad:
            raise ModelError(f"elastic body {self.name!r}: no mode {bad[0]} (the body has {self.n_coordinates}, 0..{self.n_coordinates - 1})")
        w2, v = linalg.eigh(self.K, self.M)
        size = float(np.ptp(self.nodes, axis=0).max()) or 1.0
        s = 0.1 * size if scale is None else float(scale)
        shapes = [np.einsum("nck,k->nc", self.modes[:, :3, :], v[:, k]) for k in idx]
        spread = np.ptp(self.nodes, axis=0) + sum(np.abs(d).max(axis=0) for d in shapes)
        a, b = (int(i) for i in np.sort(np.argsort(-spread)[:2]))
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(self.nodes[:, a], self.nodes[:, b], "k.-", lw=0.8, label="undeformed")
        for k, d in zip(idx, shapes):
            big = np.abs(d).max() or 1.0
            p = self.nodes + d * (s / big)
            ax.plot(p[:, a], p[:, b], "o-", ms=3, label=f"mode {k + 1}: {np.sqrt(max(w2[k], 0.0)) / (2 * np.pi):.4g} Hz")
        ax.set_xlabel(f"{'xyz'[a]} (m)")
        ax.set_ylabel(f"{'xyz'[b]} (m)")
        ax.set_title(f"{self.name}: mode shapes (largest deflection {s:.3g} m)")
        ax.legend(fontsize=8)
        fig.tight_layout()
        if out is not None:
            fig.savefig(out, dpi=120)
        return fig

    def kinetic_energy(self, v, omega, q=None, qdot=None) -> float:
        """T = ½ xᵀ M(q) x with x = (v, ω, q̇) (eq. 2.192 with the Ritz separation); v, ω of the
        body frame in body coordinates."""
        v = np.asarray(v, dtype=float)
        omega = np.asarray(omega, dtype=float)
        if v.shape != (3,) or omega.shape != (3,) or not (np.all(np.isfinite(v)) and np.all(np.isfinite(omega))):
            raise ModelError(f"elastic body {self.name!r}: v and omega must be finite 3-vectors, got {v!r}, {omega!r}")
        x = np.concatenate([v, omega, self._q(qdot, "qdot")])
        return float(0.5 * x @ self.mass_matrix(q) @ x)


def _validate(b: ReducedBody) -> None:
    if not isinstance(b.name, str) or not b.name:
        raise ModelError(f"elastic body: name must be a non-empty string, got {b.name!r}")
    w = f"elastic body {b.name!r}"

    def arr(key, shape=None, ndim=None):
        a = np.asarray(getattr(b, key), dtype=float)
        if shape is not None and a.shape != shape:
            raise ModelError(f"{w}: {key} must have shape {shape}, got {a.shape}")
        if ndim is not None and a.ndim != ndim:
            raise ModelError(f"{w}: {key} must be {ndim}-dimensional, got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ModelError(f"{w}: {key} has non-finite entries")
        setattr(b, key, a)
        return a

    nodes = arr("nodes", ndim=2)
    if nodes.shape[1] != 3 or len(nodes) == 0:
        raise ModelError(f"{w}: nodes must be an (n, 3) array, got shape {nodes.shape}")
    n = len(nodes)
    M = arr("M", ndim=2)
    q = M.shape[0]
    if q == 0 or M.shape != (q, q):
        raise ModelError(f"{w}: M must be a non-empty square matrix, got shape {M.shape}")
    K = arr("K", shape=(q, q))
    modes = np.asarray(b.modes, dtype=float)
    if modes.shape != (n, 6, q):
        raise ModelError(f"{w}: modes must have shape (n_nodes, 6, n_coordinates) = ({n}, 6, {q}), got {modes.shape}")
    arr("modes")
    _check_symmetric(M, f"{w}: M")
    _check_symmetric(K, f"{w}: K")
    ev_m = np.linalg.eigvalsh(M)
    if ev_m[0] <= 1e-12 * ev_m[-1] or ev_m[-1] <= 0:
        raise ModelError(f"{w}: M is not positive definite (smallest eigenvalue {ev_m[0]:.6g}, largest {ev_m[-1]:.6g})")
    ev_k = np.linalg.eigvalsh(K)
    if ev_k[0] < -1e-9 * max(abs(ev_k[-1]), 1e-300):
        raise ModelError(f"{w}: K is indefinite (eigenvalue {ev_k[0]:.6g} < 0; largest {ev_k[-1]:.6g})")
    w2 = linalg.eigh(K, M, eigvals_only=True)
    if w2[0] <= 1e-10 * max(w2[-1], 1e-300):
        raise ModelError(
            f"{w}: the elastic basis contains a rigid-body (zero-frequency) mode (omega^2 = {w2[0]:.3g} vs largest {w2[-1]:.3g}); "
            "fix the body frame's reference conditions or drop the mode"
        )
    b.omega = np.sqrt(w2)
    try:
        m = float(np.asarray(b.mass, dtype=float).reshape(()))
    except (TypeError, ValueError):
        raise ModelError(f"{w}: mass must be a number, got {b.mass!r}") from None
    if not (np.isfinite(m) and m > 0):
        raise ModelError(f"{w}: mass must be > 0, got {b.mass}")
    b.mass = m
    arr("first_moment", shape=(3,))
    I0 = arr("inertia", shape=(3, 3))
    _check_symmetric(I0, f"{w}: inertia")
    if np.linalg.eigvalsh(I0)[0] < -1e-9 * np.abs(I0).max():
        raise ModelError(f"{w}: inertia is not positive semi-definite: {I0.tolist()}")
    arr("Ct", shape=(3, q))
    arr("Cr", shape=(3, q))
    for key, shape in (("I1", (q, 3, 3)), ("I2", (q, q, 3, 3)), ("Gk", (q, 3, q)), ("P1", (q, 3, 3)), ("P2", (q, q, 3, 3)),
                       ("geometric", (12, q, q))):
        if getattr(b, key) is not None:
            arr(key, shape=shape)
    b.interface_nodes = tuple(_node_index(i, n, f"{w}: interface") for i in b.interface_nodes)
    if not b.labels:
        b.labels = tuple(f"q{k + 1}" for k in range(q))
    if len(b.labels) != q:
        raise ModelError(f"{w}: labels has {len(b.labels)} names for {q} coordinates")
    fmax = b.omega[-1] / (2 * np.pi)
    if fmax > FREQUENCY_WARNING_HZ:
        warnings.warn(
            f"{w}: highest elastic frequency {fmax:.3g} Hz exceeds {FREQUENCY_WARNING_HZ:.0e} Hz - check the units (SI: m, kg, N/m; mm or g taken for m or kg?)",
            stacklevel=3,
        )


# ============================================================================================
# Rotating beams: centrifugal (stress) stiffening
# ============================================================================================


def geometric_stiffness(model: FEModel, axial_force) -> np.ndarray:
    """Stress-stiffening matrix K_G = Σ_e ∫ N(s) (N'_vᵀ N'_v + N'_wᵀ N'_w) ds of a beam model for
    an axial force distribution ``axial_force(s)`` (N, tension > 0; s the distance from the
    beam's first node), in body coordinates (4-point Gauss per element: exact for N quadratic)."""
    if model.elements is None:
        raise ModelError("geometric_stiffness: needs a beam model from beam_model")
    ndof = 6 * model.n_nodes
    KG = np.zeros((ndof, ndof))
    xg, wg = np.polynomial.legendre.leggauss(4)
    xg, wg = 0.5 * (xg + 1), 0.5 * wg
    s0 = np.cumsum([0.0] + [np.linalg.norm(model.nodes[j] - model.nodes[i]) for i, j in model.elements])
    for e, (i, j) in enumerate(model.elements):
        Le = np.linalg.norm(model.nodes[j] - model.nodes[i])
        T = np.kron(np.eye(4), model.rotations[e])
        kg = np.zeros((12, 12))
        for x, w in zip(xg, wg):
            _, dH = _hermite(x, Le)
            Nf = float(axial_force(s0[e] + x * Le))
            if not np.isfinite(Nf):
                raise ModelError(f"geometric_stiffness: axial_force({s0[e] + x * Le}) is not finite")
            bv = np.zeros(12)
            bv[[1, 5, 7, 11]] = dH
            bw = np.zeros(12)
            bw[[2, 4, 8, 10]] = dH * np.array([1.0, -1.0, 1.0, -1.0])
            kg += w * Le * Nf * (np.outer(bv, bv) + np.outer(bw, bw))
        dofs = np.r_[6 * i : 6 * i + 6, 6 * j : 6 * j + 6]
        KG[np.ix_(dofs, dofs)] += T.T @ kg @ T
    return KG


def _rotating_setup(section, length, n_elements, hub_radius, plane, n_modes):
    if int(n_modes) != n_modes or not 1 <= n_modes <= 2 * n_elements:
        raise ModelError(f"rotating cantilever: n_modes must be 1..{2 * n_elements} (2 per element), got {n_modes}")
    if plane not in ("flap", "lag"):
        raise ModelError(f"rotating cantilever: plane must be 'flap' or 'lag', got {plane!r}")
    if not (np.isfinite(hub_radius) and hub_radius >= 0):
        raise ModelError(f"rotating cantilever: hub_radius must be >= 0, got {hub_radius}")
    # beam along body x from the hub at x = hub_radius, rotating about body z
    model = beam_model(section, length, n_elements, start=(hub_radius, 0.0, 0.0))
    keep = [2, 4] if plane == "flap" else [1, 5]  # (uz, ry) out of the plane, (uy, rz) in it
    dofs = [6 * i + d for i in range(1, model.n_nodes) for d in keep]
    rA = section.rho * section.A
    KG1 = geometric_stiffness(model, lambda s: rA * (hub_radius * (length - s) + 0.5 * (length**2 - s**2)))
    sub = np.ix_(dofs, dofs)
    Msub, Ksub, Gsub = model.M[sub], model.K[sub], KG1[sub]
    if plane == "lag":  # spin softening: the centrifugal field pushes in-plane deflection outward
        Gsub = Gsub - _translational_mass(model, dofs)
    return Msub, Ksub, Gsub


def _translational_mass(model, dofs):
    """Mass matrix of the in-plane (y) translation field alone, ∫ ρA N_vᵀ N_v ds, on ``dofs``."""
    pos, mp, interp = model.mass_points
    Ny = interp[:, 1, :][:, dofs]
    return np.einsum("p,pi,pj->ij", mp, Ny, Ny)


def rotating_cantilever_frequencies(section: BeamSection, length: float, Omega: float, *, n_elements: int = 20, n_modes: int = 3, hub_radius: float = 0.0, plane: str = "flap") -> np.ndarray:
    """Bending frequencies ω (rad/s) of a uniform cantilever spinning at Omega (rad/s) about an
    axis perpendicular to it (body z), clamped at hub_radius from the axis.

    The centrifugal axial force N(s) = ρAΩ² [R (L − s) + (L² − s²)/2] stiffens bending through
    K_G (:func:`geometric_stiffness`): (K + K_G − δ Ω² M_v) φ = ω² M φ, with the spin-softening
    term δ = 1 only for in-plane ("lag") bending. Out-of-plane ("flap") bending follows
    Southwell's ω² ≈ ω₀² + κ Ω² (κ₁ ≈ 1.193 at R = 0), lag bending ω² ≈ ω₀² + (κ − 1) Ω².
    """
    if not np.isfinite(Omega):
        raise ModelError(f"rotating_cantilever_frequencies: Omega must be finite, got {Omega}")
    M, K, G1 = _rotating_setup(section, length, n_elements, hub_radius, plane, n_modes)
    w2 = linalg.eigh(K + Omega**2 * G1, M, eigvals_only=True, subset_by_index=[0, n_modes - 1])
    if w2[0] <= 0:
        raise ModelError(f"rotating_cantilever_frequencies: Omega = {Omega} rad/s makes the {plane} mode unstable (omega^2 = {w2[0]:.4g})")
    return np.sqrt(w2)


def southwell_coefficients(section: BeamSection, length: float, *, n_elements: int = 20, n_modes: int = 3, hub_radius: float = 0.0, plane: str = "flap") -> np.ndarray:
    """κ_k = dω_k²/dΩ² at Ω = 0 (Southwell: ω² ≈ ω₀² + κ Ω²), from first-order perturbation of
    the FE eigenproblem: κ_k = φ_kᵀ K_G1 φ_k / φ_kᵀ M φ_k with K_G1 the stress stiffening per
    unit Ω² (minus the spin softening for "lag")."""
    M, K, G1 = _rotating_setup(section, length, n_elements, hub_radius, plane, n_modes)
    _, V = linalg.eigh(K, M, subset_by_index=[0, n_modes - 1])
    return np.array([V[:, k] @ G1 @ V[:, k] / (V[:, k] @ M @ V[:, k]) for k in range(n_modes)])


# ============================================================================================
# Files: reduced bodies from external FE codes
# ============================================================================================

_INVARIANT_KEYS = ("mass", "first_moment", "inertia", "Ct", "Cr")
_SECOND_ORDER_KEYS = ("I1", "I2", "Gk", "P1", "P2", "geometric")
_FORMAT = "mechsys-reduced-1"


def save_reduced(body: ReducedBody, path) -> Path:
    """Write a reduced body to NPZ (``.npz``) or HDF5 (``.h5``/``.hdf5``), SI units.

    Layout (one array per key; the same names as HDF5 datasets):

    ==================  =============  ========================================================
    key                 shape          meaning
    ==================  =============  ========================================================
    format              scalar str     "mechsys-reduced-1"
    units               scalar str     "SI" (m, kg, s, N, rad)
    name                scalar str     body name (optional on reading)
    nodes               (n, 3)         node positions in the body frame (m)
    M, K                (q, q)         mass and stiffness of the elastic coordinates
    modes               (n, 6, q)      per node ux, uy, uz (m), rx, ry, rz (rad) per unit q
    interface           (k,) int       optional: interface node indices (0-based)
    labels              (q,) str       optional: coordinate names
    node_masses         (n,)           optional: lumped node masses (kg) for the invariants
    mass, first_moment, inertia, Ct, Cr, I1, I2, Gk   optional: the invariants of ReducedBody
    ==================  =============  ========================================================

    On reading, either the invariants mass … Cr or node_masses must be present; with only
    node_masses every invariant is computed with the nodes as point masses.
    """
    path = Path(path)
    data = {"format": np.array(_FORMAT), "units": np.array("SI"), "name": np.array(body.name), "nodes": body.nodes, "M": body.M, "K": body.K, "modes": body.modes,
            "interface": np.array(body.interface_nodes, dtype=np.int64), "labels": np.array(body.labels, dtype=str)}
    for k in _INVARIANT_KEYS + _SECOND_ORDER_KEYS:
        v = getattr(body, k)
        if v is not None:
            data[k] = np.asarray(v)
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix in (".h5", ".hdf5"):
        import h5py

        with h5py.File(path, "w") as f:
            for k, v in data.items():
                if v.dtype.kind != "U":
                    f[k] = v
                elif v.ndim == 0:
                    f[k] = str(v)
                elif v.size:
                    f[k] = np.array([x.encode() for x in v])
    else:
        np.savez(path, **data)
    return path


def load_reduced(path, name: str | None = None) -> ReducedBody:
    """Read a reduced body written by :func:`save_reduced` or an external FE code (layout there)."""
    path = Path(path)
    what = f"reduced body file {str(path)!r}"
    if not path.exists():
        raise ModelError(f"{what} does not exist")
    data = {}
    try:
        if path.suffix in (".h5", ".hdf5"):
            import h5py

            with h5py.File(path, "r") as f:
                for k in f.keys():
                    v = f[k][()]
                    if isinstance(v, bytes):
                        v = v.decode()
                    elif isinstance(v, np.ndarray) and v.dtype.kind in ("O", "S"):
                        v = np.array([x.decode() if isinstance(x, bytes) else str(x) for x in v.ravel()])
                    data[k] = np.asarray(v)
        else:
            with np.load(path, allow_pickle=False) as f:
                data = {k: f[k] for k in f.files}
    except (OSError, ValueError) as exc:
        raise ModelError(f"{what} cannot be read: {exc}") from None
    for k in ("nodes", "M", "K", "modes"):
        if k not in data:
            raise ModelError(f"{what}: missing key {k!r} (needs nodes, M, K, modes)")
    if "units" in data and str(data["units"]) != "SI":
        raise ModelError(f"{what}: units must be 'SI', got {str(data['units'])!r}")
    if "format" in data and str(data["format"]) != _FORMAT:
        raise ModelError(f"{what}: format {str(data['format'])!r} is not {_FORMAT!r}")
    body_name = name or (str(data["name"]) if "name" in data else path.stem)
    w = f"elastic body {body_name!r} ({path.name})"
    nodes = np.asarray(data["nodes"], float)
    modes = np.asarray(data["modes"], float)
    if nodes.ndim != 2 or nodes.shape[1] != 3:
        raise ModelError(f"{w}: nodes must be an (n, 3) array, got shape {nodes.shape}")
    M = np.asarray(data["M"], float)
    if M.ndim != 2:
        raise ModelError(f"{w}: M must be a square matrix, got shape {M.shape}")
    if modes.ndim != 3 or modes.shape[0] != len(nodes) or modes.shape[1] != 6 or modes.shape[2] != M.shape[0]:
        raise ModelError(f"{w}: modes must have shape (n_nodes, 6, n_coordinates) = ({len(nodes)}, 6, {M.shape[0]}), got {modes.shape}")
    interface = tuple(int(i) for i in np.asarray(data.get("interface", np.zeros(0, int))).ravel())
    for i in interface:
        if not 0 <= i < len(nodes):
            raise ModelError(f"{w}: interface node {i} does not exist (the body has {len(nodes)} nodes, 0..{len(nodes) - 1})")
    labels = tuple(str(s) for s in np.asarray(data.get("labels", np.zeros(0, str))).ravel())
    if all(k in data for k in _INVARIANT_KEYS):
        inv = {k: np.asarray(data[k], float) for k in _INVARIANT_KEYS}
        inv["mass"] = float(inv["mass"])
        for k in _SECOND_ORDER_KEYS:
            inv[k] = np.asarray(data[k], float) if k in data else None
    elif "node_masses" in data:
        nm = np.asarray(data["node_masses"], float)
        if nm.shape != (len(nodes),) or not np.all(np.isfinite(nm)) or np.any(nm < 0):
            raise ModelError(f"{w}: node_masses must be {len(nodes)} finite values >= 0, got shape {nm.shape}")
        Mlump = np.zeros((6 * len(nodes), 6 * len(nodes)))
        for i, mi in enumerate(nm):
            Mlump[6 * i : 6 * i + 3, 6 * i : 6 * i + 3] = mi * np.eye(3)
        interp = np.zeros((len(nodes), 3, 6 * len(nodes)))
        for i in range(len(nodes)):
            interp[i, :, 6 * i : 6 * i + 3] = np.eye(3)
        inv = _invariants(nodes, Mlump, (nodes, nm, interp), modes.reshape(6 * len(nodes), -1))
    else:
        raise ModelError(f"{w}: needs the inertia invariants ({', '.join(_INVARIANT_KEYS)}) or node_masses")
    return ReducedBody(name=body_name, nodes=nodes, M=M, K=np.asarray(data["K"], float), modes=modes, interface_nodes=interface, labels=labels, **inv)
