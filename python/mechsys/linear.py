"""Linear vibration analysis (section 2.6.2): a model linearized at an equilibrium or a steady
operating point into M y'' + (D + G) y' + (K + N) y = g(t) (eq. 2.204), its modes, damping ratios
and stability, frequency responses H(jw) (eq. 2.205), Rayleigh damping (eq. 2.207) and the
one-degree-of-freedom closed forms (eqs. 2.208, 2.209).

>>> lin = ms.linear.linearize(model)              # at the model's q0, u0
>>> modes = lin.modes()                           # frequencies (Hz), damping ratios, shapes
>>> H = lin.frf(np.linspace(0.1, 50, 500), inputs=[0], outputs=[0])

The coordinates y are minimal: increments along a basis V of the velocity directions the
bilateral constraints allow (V = I without constraints, so y are the joint coordinates, with
rotation vectors for quaternion joints); ``lin.V`` maps y to the generalized velocities.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from . import _core
from .errors import ModelError, SettingsError
from .model import Model


@dataclass(frozen=True)
class Modes:
    """Eigen-solution of the state-space form, one entry per mode (complex pairs counted once,
    ordered by undamped natural frequency)."""

    #: eigenvalues lambda = -zeta w_n +- j w_d (1/s), the one with Im >= 0 of each pair
    eigenvalues: np.ndarray
    #: undamped natural frequencies |lambda| / 2 pi (Hz)
    natural_frequency: np.ndarray
    #: damped natural frequencies Im(lambda) / 2 pi (Hz; 0 for overdamped or static modes)
    damped_frequency: np.ndarray
    #: damping ratios -Re(lambda) / |lambda| (negative: the mode grows)
    damping_ratio: np.ndarray
    #: mode shapes in y (n x modes), each scaled to unit largest magnitude
    shapes: np.ndarray
    #: the same in the generalized velocities (nu x modes): V @ shapes
    shapes_u: np.ndarray

    @property
    def stable(self) -> bool:
        """No eigenvalue with a positive real part (beyond round-off)."""
        scale = 1.0 + float(np.abs(self.eigenvalues).max(initial=0.0))
        return bool(np.all(self.eigenvalues.real <= 1e-9 * scale))

    @property
    def unstable(self) -> np.ndarray:
        """Indices of the modes that grow (positive real part): divergence (Im = 0) or flutter."""
        scale = 1.0 + float(np.abs(self.eigenvalues).max(initial=0.0))
        return np.nonzero(self.eigenvalues.real > 1e-9 * scale)[0]

    def table(self) -> str:
        """A text table of the modes."""
        rows = [f"{'mode':>4}  {'f_n (Hz)':>12}  {'f_d (Hz)':>12}  {'zeta':>10}  {'Re(lambda) (1/s)':>16}"]
        for k, lam in enumerate(self.eigenvalues):
            flag = "  unstable" if k in set(self.unstable.tolist()) else ""
            rows.append(f"{k + 1:>4}  {self.natural_frequency[k]:12.6g}  {self.damped_frequency[k]:12.6g}  "
                        f"{self.damping_ratio[k]:10.4g}  {lam.real:16.6g}{flag}")
        return "\n".join(rows)


@dataclass(frozen=True)
class LinearModel:
    """M, D, G, K, N of eq. 2.204 (n x n numpy arrays), the basis ``V`` (nu x n) of the minimal
    coordinates, the point (``t``, ``q``, ``u``) and the ``residual`` V^T M u_dot there (zero at an
    equilibrium)."""

    M: np.ndarray
    D: np.ndarray
    G: np.ndarray
    K: np.ndarray
    N: np.ndarray
    V: np.ndarray
    residual: np.ndarray
    q: np.ndarray
    u: np.ndarray
    t: float = 0.0
    names: list = field(default_factory=list)
    method: str = "fd"

    @property
    def n(self) -> int:
        """Degrees of freedom."""
        return self.M.shape[0]

    def state_matrix(self) -> np.ndarray:
        """A of x' = A x with x = [y, y'] (2n x 2n)."""
        n = self.n
        minv = np.linalg.inv(self.M)
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -minv @ (self.K + self.N)
        a[n:, n:] = -minv @ (self.D + self.G)
        return a

    def modes(self) -> Modes:
        """Eigenvalues and mode shapes of the state-space form, natural and damped frequencies,
        damping ratios; stability from the real parts."""
        lam, vec = np.linalg.eig(self.state_matrix())
        n = self.n
        # one of each complex pair (Im >= 0); real eigenvalues all kept
        scale = 1.0 + np.abs(lam).max(initial=0.0)
        keep = lam.imag >= -1e-12 * scale
        lam, vec = lam[keep], vec[:, keep]
        wn = np.abs(lam)
        order = np.lexsort((lam.real, wn))
        lam, vec, wn = lam[order], vec[:, order], wn[order]
        shapes = vec[:n, :]
        big = np.abs(shapes).max(axis=0)
        big[big == 0] = 1.0
        # scale so that the largest entry is real and 1
        k = np.abs(shapes).argmax(axis=0)
        shapes = shapes / (shapes[k, np.arange(shapes.shape[1])] / np.abs(shapes[k, np.arange(shapes.shape[1])])) / big
        with np.errstate(invalid="ignore", divide="ignore"):
            zeta = np.where(wn > 0, -lam.real / np.where(wn > 0, wn, 1.0), 0.0)
        return Modes(lam, wn / (2 * np.pi), np.abs(lam.imag) / (2 * np.pi), zeta, shapes, self.V @ shapes)

    def frf(self, frequencies, inputs=None, outputs=None) -> np.ndarray:
        """H(j w) = [-w^2 M + j w (D + G) + (K + N)]^-1 (eq. 2.205) at ``frequencies`` (Hz, > 0),
        between generalized forces on the coordinates ``inputs`` and the coordinates ``outputs``
        (indices into y; all by default). Returns complex (n_freq, n_out, n_in), in m/N (or rad/(N m))."""
        f = np.atleast_1d(np.asarray(frequencies, dtype=float))
        if f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
            raise SettingsError("frf: frequencies must be finite and > 0 (Hz)")
        ins = list(range(self.n)) if inputs is None else [self._index(i, "inputs") for i in np.atleast_1d(inputs)]
        outs = list(range(self.n)) if outputs is None else [self._index(i, "outputs") for i in np.atleast_1d(outputs)]
        out = np.empty((f.size, len(outs), len(ins)), dtype=complex)
        b = np.zeros((self.n, len(ins)))
        b[ins, range(len(ins))] = 1.0
        c = self.D + self.G
        s = self.K + self.N
        for k, fk in enumerate(f):
            w = 2 * np.pi * fk
            z = -w * w * self.M + 1j * w * c + s
            out[k] = np.linalg.solve(z, b)[outs, :]
        return out

    def _index(self, i, what: str) -> int:
        if isinstance(i, (str, np.str_)):
            if i not in self.names:
                raise SettingsError(f"frf: {what}: no coordinate named '{i}' (have {', '.join(self.names)})")
            return self.names.index(i)
        k = int(i)
        if not 0 <= k < self.n:
            raise SettingsError(f"frf: {what}: coordinate index {k} out of range 0..{self.n - 1}")
        return k

    def with_damping(self, D) -> "LinearModel":
        """The same model with the damping matrix ``D`` (symmetric n x n) instead of its own."""
        D = np.asarray(D, dtype=float)
        if D.shape != self.M.shape:
            raise SettingsError(f"with_damping: D must be {self.n} x {self.n}, got {D.shape}")
        return replace(self, D=0.5 * (D + D.T))

    def rayleigh(self, zeta1: float, f1: float, zeta2: float, f2: float) -> "LinearModel":
        """The model with Rayleigh damping D = alpha M + beta K fitted to the damping ratios
        ``zeta1`` at ``f1`` and ``zeta2`` at ``f2`` (Hz) (see :func:`rayleigh_coefficients`)."""
        a, b = rayleigh_coefficients(zeta1, f1, zeta2, f2)
        return self.with_damping(a * self.M + b * self.K)

    def dissipation(self, ydot) -> float:
        """Rayleigh's dissipation function R = y'^T D y' / 2 (eq. 2.206: the power lost is 2R)."""
        v = np.asarray(ydot, dtype=float)
        return 0.5 * float(v @ self.D @ v)


def rayleigh_coefficients(zeta1: float, f1: float, zeta2: float, f2: float) -> tuple[float, float]:
    """alpha, beta of D = alpha M + beta K (eq. 2.207) so that the modes at ``f1`` and ``f2`` (Hz)
    have the damping ratios ``zeta1``, ``zeta2``: zeta(w) = alpha / (2 w) + beta w / 2."""
    for name, v in (("f1", f1), ("f2", f2)):
        if not (np.isfinite(v) and v > 0):
            raise SettingsError(f"rayleigh: {name} must be a frequency > 0 (Hz), got {v}")
    for name, v in (("zeta1", zeta1), ("zeta2", zeta2)):
        if not (np.isfinite(v) and v >= 0):
            raise SettingsError(f"rayleigh: {name} must be a damping ratio >= 0, got {v}")
    if f1 == f2:
        raise SettingsError("rayleigh: f1 and f2 must differ")
    w1, w2 = 2 * np.pi * f1, 2 * np.pi * f2
    a = np.array([[1 / (2 * w1), w1 / 2], [1 / (2 * w2), w2 / 2]])
    alpha, beta = np.linalg.solve(a, [zeta1, zeta2])
    return float(alpha), float(beta)


def sdof_frequencies(m: float, d: float, k: float) -> tuple[float, float]:
    """Undamped and damped natural frequencies (rad/s) of m y'' + d y' + k y = 0 (eq. 2.208):
    w0 = sqrt(k/m), wd = sqrt(k/m - (d/2m)^2) (0 when overdamped)."""
    if not (m > 0 and k >= 0 and d >= 0):
        raise SettingsError(f"sdof_frequencies: need m > 0, k >= 0, d >= 0; got m={m}, k={k}, d={d}")
    w0 = np.sqrt(k / m)
    delta = d / (2 * m)
    return float(w0), float(np.sqrt(max(w0 * w0 - delta * delta, 0.0)))


def sdof_response(a: float, omega0: float, delta: float, omega) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude R and phase psi of the forced part of y'' + 2 delta y' + omega0^2 y = a cos(omega t)
    (eq. 2.209): R = a / sqrt((omega0^2 - omega^2)^2 + 4 delta^2 omega^2), tan psi = 2 delta omega / (omega0^2 - omega^2)."""
    w = np.asarray(omega, dtype=float)
    r = a / np.sqrt((omega0**2 - w**2) ** 2 + 4 * delta**2 * w**2)
    psi = np.arctan2(2 * delta * w, omega0**2 - w**2)
    return r, psi


def _names(model: Model, n_u: int) -> list[str]:
    names = []
    for j in model.engine()[0].joints():
        for k in range(j["nu"]):
            names.append(f"{j['name']}" if j["nu"] == 1 else f"{j['name']}[{k}]")
    return names if len(names) == n_u else [f"u{k}" for k in range(n_u)]


def linearize(model: Model, q=None, u=None, t: float = 0.0, operating_point: bool = False,
              method: str = "auto") -> LinearModel:
    """Linearizes ``model`` at (``q``, ``u``, ``t``) (the model's q0, u0 by default).

    ``method`` chooses the derivatives: ``"auto"`` (exact where the model allows, else central
    differences), ``"exact"`` (dual numbers; an error on a model with a callback force) or
    ``"fd"`` (central differences); ``LinearModel.method`` says which were used (``"exact"``,
    ``"exact+fd-constraints"`` with bilateral constraints, or ``"fd"``).

    At a point that is not an equilibrium (``residual`` beyond round-off) a ``UserWarning``
    reports the residual, unless ``operating_point=True`` says the point is meant as it is (a
    steady motion, or a quasi-static state whose imbalance the user accepts)."""
    if not isinstance(model, Model):
        raise SettingsError(f"linearize: expected a mechsys.Model, got {type(model).__name__}")
    core, cbs = model.engine()
    q = model.q0() if q is None else np.ascontiguousarray(q, dtype=float)
    u = model.u0() if u is None else np.ascontiguousarray(u, dtype=float)
    raw = _core.linearize(core, q, u, float(t), cbs, method)
    n_u = raw["V"].shape[0]
    names = _names(model, n_u)
    if raw["V"].shape[1] != n_u or not np.allclose(raw["V"], np.eye(n_u)):
        names = [f"y{k}" for k in range(raw["V"].shape[1])]
    lin = LinearModel(raw["M"], raw["D"], raw["G"], raw["K"], raw["N"], raw["V"], raw["residual"], q, u, float(t), names,
                      raw["method"])
    scale = 1.0 + np.abs(lin.K).max(initial=0.0) + np.abs(lin.M).max(initial=0.0)
    res = float(np.abs(lin.residual).max(initial=0.0))
    if res > 1e-8 * scale and not operating_point:
        worst = int(np.abs(lin.residual).argmax())
        warnings.warn(f"model '{model.name}': linearized at a point that is not an equilibrium: residual "
                      f"{res:.3g} on coordinate '{lin.names[worst]}' (pass operating_point=True if that is meant)",
                      UserWarning, stacklevel=2)
    if not np.all(np.isfinite(lin.M)):
        raise ModelError(f"model '{model.name}': the linearized mass matrix is not finite")
    return lin


__all__ = ["linearize", "LinearModel", "Modes", "rayleigh_coefficients", "sdof_frequencies", "sdof_response"]
