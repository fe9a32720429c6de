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
from pathlib import Path

import numpy as np

from . import _core
from .errors import MechsysError, ModelError, SettingsError
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

    def shapes_table(self, names, modes: int = 8, cut: float = 1e-3) -> str:
        """Mode shapes as text: per mode (the first ``modes``), each coordinate whose share is
        above ``cut`` of the largest, with its magnitude and phase (degrees)."""
        rows = []
        for k in range(min(modes, self.shapes.shape[1])):
            s = self.shapes[:, k]
            parts = [f"{names[i]} {abs(s[i]):.3g}" + (f" at {np.degrees(np.angle(s[i])):+.0f} deg" if abs(s[i].imag) > 1e-9 else "")
                     for i in np.argsort(-np.abs(s)) if abs(s[i]) > cut]
            rows.append(f"{k + 1:>4}  " + (", ".join(parts) or "-"))
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
    #: which derivatives built it: "exact", "exact+fd-constraints" or "fd"
    method: str = "fd"
    #: the model it came from (for re-linearizing, e.g. by :meth:`campbell`); None when built by hand
    model: Model | None = field(default=None, repr=False, compare=False)
    #: the first-order form about the point (:class:`StateForm`; None when built by hand)
    state: "StateForm | None" = field(default=None, repr=False, compare=False)
    #: whether the point is an equilibrium or a steady motion (see :attr:`StateForm.steady`)
    steady: bool = True

    @property
    def n(self) -> int:
        """Degrees of freedom of the second-order form (configuration states of the first-order
        form when there is none)."""
        return self.M.shape[0] if self.M is not None else self.state.n_config

    @property
    def A(self) -> np.ndarray:
        """State matrix of the first-order form ``x' = A x + B tau`` with the cyclic coordinates
        removed (``states`` names its entries): configuration perturbations, then velocity
        perturbations. About an equilibrium of a holonomic model its eigenvalues are those of
        :meth:`state_matrix`."""
        return self._state().reduced()[0]

    @property
    def B(self) -> np.ndarray:
        """Input matrix of the first-order form: column k is x' for a unit generalized force on
        the joint velocity ``self.state.coordinates[k]`` (N or N m)."""
        return self._state().reduced()[1]

    @property
    def states(self) -> list[str]:
        """Names of the entries of the first-order state x (rates end in a prime)."""
        return self._state().reduced()[2]

    @property
    def cyclic(self) -> list[str]:
        """Cyclic coordinates: joint coordinates the linearized motion does not depend on
        (positions on the plane, heading, wheel and spin angles); built with the first-order form."""
        return list(self._state().cyclic)

    def _state(self) -> "StateForm":
        if self.state is None:
            if self.model is None:
                raise SettingsError("this LinearModel has no first-order form (built by hand); use ms.linear.linearize")
            # at rest it is built on demand, with the same kind of derivatives
            prefer = [] if _nonholonomic(self.model) else None
            sf, _ = _state_form(self.model, self.q, self.u, self.t, "fd" if self.method == "fd" else "exact", prefer)
            object.__setattr__(self, "state", sf)
        return self.state

    def state_space(self, inputs=None, outputs=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C)`` of ``x' = A x + B tau``, ``z = C x``: ``inputs`` are joint velocities
        (names as in ``state.coordinates``, or indices) that receive a generalized force (all by
        default), ``outputs`` joint coordinates or their rates (``"steer"``, ``"steer'"``; the
        states by default). A cyclic coordinate cannot be an output."""
        return self._state().state_space(inputs, outputs)

    def state_matrix(self) -> np.ndarray:
        """A of x' = A x with x = [y, y'] (2n x 2n); the first-order form's A where the model
        has no second-order form."""
        if self.M is None:
            return self.A
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
        if self.M is None:
            return _modes(lam, vec, n, self.state.shape_map())
        return _modes(lam, vec, n, self.V)

    def _second_order(self, what: str) -> None:
        if self.M is None:
            raise SettingsError(f"{what}: this linearization has no second-order form M, D, G, K, N "
                                f"({self.state.why_first_order}); use lin.A, lin.state_space() or lin.modes()")

    def frf(self, frequencies, inputs=None, outputs=None, method: str = "auto") -> np.ndarray:
        """H(j w) = [-w^2 M + j w (D + G) + (K + N)]^-1 (eq. 2.205) at ``frequencies`` (Hz, > 0),
        between generalized forces on the coordinates ``inputs`` and the coordinates ``outputs``
        (indices into y; all by default). Returns complex (n_freq, n_out, n_in), in m/N (or rad/(N m)).

        ``method``: ``"direct"`` solves the n x n system at every frequency; ``"modal"``
        diagonalizes once: with G = N = 0 and proportional damping by the real modes of K, M
        (H = Phi diag(1 / (w_i^2 - w^2 + j w d_i)) Phi^T), else by the state-space form,
        H = C Phi (j w - Lambda)^-1 Phi^-1 B (refused when its eigenvectors are nearly dependent,
        as with rigid-body modes); both are fast for a few inputs and outputs. ``"auto"``
        (default) takes the modal form when there are no more input-output pairs than
        coordinates and it is well conditioned, else the direct one."""
        self._second_order("frf")
        f = np.atleast_1d(np.asarray(frequencies, dtype=float))
        if f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
            raise SettingsError("frf: frequencies must be finite and > 0 (Hz)")
        if method not in ("auto", "direct", "modal"):
            raise SettingsError(f"frf: method must be 'auto', 'direct' or 'modal', got {method!r}")
        ins = list(range(self.n)) if inputs is None else [self._index(i, "inputs") for i in np.atleast_1d(inputs)]
        outs = list(range(self.n)) if outputs is None else [self._index(i, "outputs") for i in np.atleast_1d(outputs)]
        w = 2 * np.pi * f
        if method == "modal" or (method == "auto" and len(ins) * len(outs) <= self.n):
            h = self._frf_modal(w, ins, outs, strict=method == "modal")
            if h is not None:
                return h
        return self._frf_direct(w, ins, outs)

    def _frf_direct(self, w: np.ndarray, ins: list, outs: list) -> np.ndarray:
        out = np.empty((w.size, len(outs), len(ins)), dtype=complex)
        b = np.zeros((self.n, len(ins)))
        b[ins, range(len(ins))] = 1.0
        c = self.D + self.G
        s = self.K + self.N
        z = np.empty((self.n, self.n), dtype=complex)
        for k, wk in enumerate(w):
            z.real = s - wk * wk * self.M
            z.imag = wk * c
            out[k] = np.linalg.solve(z, b)[outs, :]
        return out

    def _frf_modal(self, w: np.ndarray, ins: list, outs: list, strict: bool):
        real = self._frf_real_modes(w, ins, outs)
        if real is not None:
            return real
        n = self.n
        lam, phi = np.linalg.eig(self.state_matrix())
        if np.linalg.cond(phi) > 1e6:
            if strict:
                raise SettingsError("frf: method='modal': the eigenvectors are nearly dependent (rigid-body or defective "
                                    "modes); use method='direct'")
            return None
        b = np.zeros((2 * n, len(ins)))
        unit = np.zeros((n, len(ins)))
        unit[ins, range(len(ins))] = 1.0
        b[n:, :] = np.linalg.solve(self.M, unit)
        r = np.linalg.solve(phi, b)
        d = 1.0 / (1j * w[:, None] - lam[None, :])
        return np.einsum("ok,fk,ki->foi", phi[outs, :], d, r, optimize=True)

    def _frf_real_modes(self, w: np.ndarray, ins: list, outs: list):
        """H = Phi diag(1 / (w_i^2 - w^2 + j w d_i)) Phi^T from K Phi = M Phi W^2 (Phi^T M Phi = I)
        when G = N = 0 and the damping is proportional (Phi^T D Phi diagonal); else None."""
        # G, N and the modal damping's off-diagonal part below the linearization's round-off (~1e-10)
        tiny = 1e-9 * (np.abs(self.K).max(initial=0.0) + np.abs(self.D).max(initial=0.0) + 1e-300)
        if np.abs(self.G).max(initial=0.0) > tiny or np.abs(self.N).max(initial=0.0) > tiny:
            return None
        from scipy.linalg import eigh

        w2, phi = eigh(0.5 * (self.K + self.K.T), 0.5 * (self.M + self.M.T))
        dm = phi.T @ self.D @ phi
        diag = np.diag(dm).copy()
        if np.abs(dm - np.diag(diag)).max(initial=0.0) > 1e-8 * max(np.abs(diag).max(initial=0.0), 1e-300):
            return None
        d = 1.0 / (w2[None, :] - (w * w)[:, None] + 1j * w[:, None] * diag[None, :])
        return np.einsum("ok,fk,ik->foi", phi[outs, :], d, phi[ins, :], optimize=True)

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
        self._second_order("with_damping")
        D = np.asarray(D, dtype=float)
        if D.shape != self.M.shape:
            raise SettingsError(f"with_damping: D must be {self.n} x {self.n}, got {D.shape}")
        return replace(self, D=0.5 * (D + D.T))

    def rayleigh(self, zeta1: float, f1: float, zeta2: float, f2: float) -> "LinearModel":
        """The model with Rayleigh damping D = alpha M + beta K fitted to the damping ratios
        ``zeta1`` at ``f1`` and ``zeta2`` at ``f2`` (Hz) (see :func:`rayleigh_coefficients`)."""
        a, b = rayleigh_coefficients(zeta1, f1, zeta2, f2)
        return self.with_damping(a * self.M + b * self.K)

    def body_shapes(self, modes: "Modes | None" = None) -> dict[str, np.ndarray]:
        """Mode shapes mapped back to the bodies: for each body, a complex (modes x 6) array of
        the displacement of its centre of mass (3) and its rotation (3), inertial components,
        for the mode shapes of ``modes`` (``self.modes()`` by default) as scaled there."""
        if self.model is None:
            raise SettingsError("body_shapes: this LinearModel has no model (built by hand); use ms.linear.linearize")
        from .kinematics import point_jacobian

        modes = self.modes() if modes is None else modes
        out = {}
        for b in self.model.body_info():
            jt, jr = point_jacobian(self.model, self.q, b["name"], b["com"])
            out[b["name"]] = np.hstack([(jt @ modes.shapes_u).T, (jr @ modes.shapes_u).T])
        return out

    def modal_damping(self, zeta) -> "LinearModel":
        """The model with modal damping: each undamped mode i of (M, K) gets the damping ratio
        ``zeta[i]`` (one number: all modes), D = M Phi diag(2 zeta_i w_i) Phi^T M with the modes
        Phi mass-normalized (Phi^T M Phi = E). Modes in order of rising frequency; needs K
        positive definite (no rigid-body or unstable modes)."""
        self._second_order("modal_damping")
        lam, phi = _undamped_modes(self.M, self.K)
        if lam.size and lam.min() <= 1e-12 * max(lam.max(), 1.0):
            raise SettingsError("modal_damping: K must be positive definite (a rigid-body or unstable mode has no "
                                f"damping ratio; smallest eigenvalue {lam.min():.3g})")
        z = np.broadcast_to(np.asarray(zeta, dtype=float), lam.shape) if np.ndim(zeta) == 0 else np.asarray(zeta, float)
        if z.shape != lam.shape:
            raise SettingsError(f"modal_damping: give one damping ratio or {lam.size}, got {z.size}")
        if not np.all(np.isfinite(z)) or np.any(z < 0):
            raise SettingsError(f"modal_damping: damping ratios must be finite and >= 0, got {z.tolist()}")
        mp = self.M @ phi
        return self.with_damping(mp @ np.diag(2 * z * np.sqrt(lam)) @ mp.T)

    def dissipation(self, ydot) -> float:
        """Rayleigh's dissipation function R = y'^T D y' / 2 (eq. 2.206: the power lost is 2R)."""
        self._second_order("dissipation")
        v = np.asarray(ydot, dtype=float)
        return 0.5 * float(v @ self.D @ v)

    def energy(self, y, ydot) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic and potential energy of the linear model, E_k = y'^T M y' / 2 and
        E_p = y^T K y / 2, for one state or for samples (rows of ``y`` and ``ydot``)."""
        self._second_order("energy")
        y, v = self._samples(y, "y"), self._samples(ydot, "ydot")
        ek = 0.5 * np.einsum("ki,ij,kj->k", v, self.M, v)
        ep = 0.5 * np.einsum("ki,ij,kj->k", y, self.K, y)
        return ek, ep

    def power_balance(self, t, y, ydot, yddot=None) -> dict:
        """The power equation (eq. 2.206) along sampled motion (rows of ``y``, ``ydot`` at times
        ``t``): ``energy`` E_k + E_p, ``dE_dt`` its time derivative (y'^T M y'' + y'^T K y with
        the accelerations ``yddot`` if given, e.g. ``res["udot"]`` when V = I, else second-order
        differences),
        ``dissipation`` -y'^T D y' = -2R, ``circulatory`` -y'^T N y (the non-conservative
        forces' power) and ``external`` dE_dt minus both (the power of the loads g(t) and the
        linearization error; zero for free motion of a linear model)."""
        tt = np.asarray(t, dtype=float).reshape(-1)
        y, v = self._samples(y, "y"), self._samples(ydot, "ydot")
        if not (tt.size == y.shape[0] == v.shape[0]) or tt.size < 3:
            raise SettingsError(f"power_balance: t, y, ydot need the same number (>= 3) of samples, got {tt.size}, {y.shape[0]}, {v.shape[0]}")
        ek, ep = self.energy(y, v)
        e = ek + ep
        if yddot is None:
            de = np.gradient(e, tt, edge_order=2)
        else:
            a = self._samples(yddot, "yddot")
            de = np.einsum("ki,ij,kj->k", v, self.M, a) + np.einsum("ki,ij,kj->k", v, self.K, y)
        diss = -np.einsum("ki,ij,kj->k", v, self.D, v)
        circ = -np.einsum("ki,ij,kj->k", v, self.N, y)
        return {"energy": e, "dE_dt": de, "dissipation": diss, "circulatory": circ, "external": de - diss - circ}

    def _samples(self, a, what: str) -> np.ndarray:
        arr = np.atleast_2d(np.asarray(a, dtype=float))
        if arr.shape[-1] != self.n:
            raise SettingsError(f"{what}: expected rows of {self.n} coordinates, got shape {np.shape(a)}")
        return arr

    def deviation(self, q, u) -> tuple[np.ndarray, np.ndarray]:
        """y and y' of sampled states (rows of ``q``, ``u``, e.g. ``res["q"]``, ``res["u"]``)
        relative to the linearization point: y = V^+ (q - q_lin), y' = V^+ u. Only for models
        whose coordinates are their velocities' integrals (no quaternion joints)."""
        qa, ua = np.atleast_2d(np.asarray(q, dtype=float)), np.atleast_2d(np.asarray(u, dtype=float))
        if qa.shape[-1] != self.q.size or ua.shape[-1] != self.u.size or self.q.size != self.u.size:
            raise SettingsError("deviation: needs a model with as many coordinates as velocities (no quaternion "
                                f"joints) and rows of q ({self.q.size}) and u ({self.u.size})")
        vp = np.linalg.pinv(self.V)
        return (qa - self.q) @ vp.T, (ua - self.u) @ vp.T

    def campbell(self, values, joint: str, whirl=None, component: int | None = None, track: str = "mac",
                 rigid_tol: float = 1e-6) -> "Campbell":
        """Campbell diagram: the stored model re-linearized (as an operating point) with the
        velocity of the spin joint ``joint`` set to each of ``values`` (rad/s), the other
        coordinates and velocities as at this point. Modes with |lambda| below ``rigid_tol`` times
        the largest (rigid-body ones, e.g. the spin itself) are left out; the others are followed
        from speed to speed by the modal assurance criterion of their complex shapes
        (``track="mac"``) or by frequency order (``"order"``).

        ``whirl``: the two lateral coordinates of the whirl plane (names or indices into y),
        x then y with x, y and the spin axis right-handed (displacements along x and y, or tilts
        about x and y). A mode whirls ``forward`` when its orbit y(t) = Re(s e^(lambda t)) in
        that plane turns with the spin (sign of Im(s_x conj(s_y)) equal to the speed's sign),
        ``backward`` against it; ``""`` at zero speed, without ``whirl`` or for a straight-line
        orbit."""
        if self.model is None:
            raise SettingsError("campbell: this LinearModel has no model to re-linearize (use ms.linear.linearize)")
        speeds = np.atleast_1d(np.asarray(values, dtype=float)).reshape(-1)
        if speeds.size == 0 or not np.all(np.isfinite(speeds)):
            raise SettingsError("campbell: values must be finite spin speeds (rad/s)")
        if track not in ("mac", "order"):
            raise SettingsError(f"campbell: track must be 'mac' or 'order', got {track!r}")
        iu = _spin_index(self.model, joint, component)
        pair = None if whirl is None else self._whirl_pair(whirl)
        per_speed, worst = [], 0.0
        for w in speeds:
            u = self.u.copy()
            u[iu] = w
            lin = _relinearize(self, u)
            worst = max(worst, float(np.abs(lin.residual).max(initial=0.0)))
            per_speed.append(_elastic_modes(lin.modes(), rigid_tol))
        return _campbell(speeds, per_speed, pair, track, f"{joint}" if component is None else f"{joint}[{component}]", worst)

    def _whirl_pair(self, whirl) -> tuple[int, int]:
        """Indices of the whirl plane's coordinates from ``(x, y)`` or ``"x,y"`` (names or indices)."""
        parts = [p.strip() for p in whirl.split(",")] if isinstance(whirl, str) else \
            list(whirl) if isinstance(whirl, (tuple, list, np.ndarray)) else []
        if len(parts) != 2:
            raise SettingsError(f"campbell: whirl must be two coordinates (x, y) as names or indices, got {whirl!r}")
        idx = []
        for p in parts:
            p = int(p) if isinstance(p, str) and p.isdigit() else p
            try:
                idx.append(self._index(p, "whirl"))
            except (SettingsError, TypeError, ValueError) as e:
                raise SettingsError(f"campbell: whirl: {e}".replace("frf: whirl: ", "")) from None
        if idx[0] == idx[1]:
            raise SettingsError(f"campbell: whirl needs two different coordinates, got {whirl!r}")
        return idx[0], idx[1]


def _modes(lam: np.ndarray, vec: np.ndarray, n: int, to_u: np.ndarray) -> Modes:
    """Modes from the eigen-solution of a state matrix whose first n states are configurations:
    one of each complex pair (Im >= 0), ordered by |lambda|, shapes scaled to a real unit peak."""
    scale = 1.0 + np.abs(lam).max(initial=0.0)
    keep = lam.imag >= -1e-12 * scale
    lam, vec = lam[keep], vec[:, keep]
    wn = np.abs(lam)
    order = np.lexsort((lam.real, wn))
    lam, vec, wn = lam[order], vec[:, order], wn[order]
    shapes = vec[:n, :]
    if n == 0:
        # every configuration state cyclic (a sledge): the modes live in the velocities only
        with np.errstate(invalid="ignore", divide="ignore"):
            zeta = np.where(wn > 0, -lam.real / np.where(wn > 0, wn, 1.0), 0.0)
        return Modes(lam, wn / (2 * np.pi), np.abs(lam.imag) / (2 * np.pi), zeta, shapes, to_u @ shapes)
    big = np.abs(shapes).max(axis=0)
    big[big == 0] = 1.0
    k = np.abs(shapes).argmax(axis=0)
    cols = np.arange(shapes.shape[1])
    peak = shapes[k, cols]
    peak = np.where(np.abs(peak) > 0, peak / np.where(np.abs(peak) > 0, np.abs(peak), 1.0), 1.0)
    shapes = shapes / peak / big
    with np.errstate(invalid="ignore", divide="ignore"):
        zeta = np.where(wn > 0, -lam.real / np.where(wn > 0, wn, 1.0), 0.0)
    return Modes(lam, wn / (2 * np.pi), np.abs(lam.imag) / (2 * np.pi), zeta, shapes, to_u @ shapes)


def _undamped_modes(m: np.ndarray, k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues w^2 (rising) and mass-normalized modes of K phi = w^2 M phi."""
    from scipy.linalg import eigh

    lam, phi = eigh(0.5 * (k + k.T), 0.5 * (m + m.T))
    return lam, phi


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


def linearize(model: Model, q=None, u=None, t: float = 0.0, operating_point: bool = False, at=None,
              method: str = "auto", coordinates=None, contacts: str = "refuse") -> LinearModel:
    """Linearizes ``model`` at (``q``, ``u``, ``t``) (the model's q0, u0 by default): about an
    equilibrium or about a steady motion (a relative equilibrium: straight or circular rolling, a
    precessing top, a spinning rotor), also with non-holonomic constraints.

    The result always carries the first-order form ``x' = A x + B tau`` (``lin.A``, ``lin.B``,
    ``lin.states``, ``lin.state_space()``) with the cyclic coordinates (``lin.cyclic``: positions
    on the plane, heading, wheel and spin angles) detected and removed, and, where the motion admits
    it, the second-order form M y'' + (D + G) y' + (K + N) y = g (eq. 2.204):

    - at rest (u = 0): in minimal coordinates y along the admissible velocities, as always;
    - moving, holonomic: in the same coordinates, with the chart's rotation and the constraints'
      turning with q included;
    - non-holonomic and moving: in the coordinates you name (``coordinates=["lean", "steer"]``,
      joint coordinate names as in ``lin.state.coordinates``), or, by default, in all non-cyclic
      configuration coordinates, provided the remaining states (cyclic rates, a forward speed)
      do not feed back into them; otherwise ``M`` etc. are None and ``lin.modes()`` uses A.

    ``method`` chooses the derivatives: ``"auto"`` (exact where the model allows, else central
    differences), ``"exact"`` (dual numbers; an error on a model with a callback force) or
    ``"fd"`` (central differences); ``LinearModel.method`` says which were used (``"exact"``,
    ``"exact+fd-constraints"`` with bilateral constraints, or ``"fd"``).

    At a point that is neither an equilibrium nor a steady motion (``lin.steady`` False: the
    non-cyclic states change along the reference) a ``UserWarning`` says so, unless
    ``operating_point=True`` says the point is meant as it is. A point that violates a
    constraint is a ModelError naming it; a friction element sticking there is refused (its law
    is not smooth there).

    ``contacts`` says what a unilateral contact closed at the point becomes: ``"refuse"`` (the
    default: a SettingsError naming it, since it may open or slip under any perturbation),
    ``"hold"`` (held closed, g_N = 0, as a bilateral constraint that slides frictionlessly: a cam
    follower that stays on its cam, a wheel on its rail) or ``"roll"`` (held closed and rolling
    without slip: ġ_T = 0 too). A held contact must press at the point (normal force > 0, from
    the constrained dynamics there), and a rolling one must stay inside its static friction cone;
    otherwise a SettingsError names it and its force. Open contacts exert nothing and are left
    out. ``lin.model`` is then the model with the held contacts (``laws.Bilateral``). A contact on
    a compliant Signorini layer (``laws.Signorini(compliance=c, damping=d)``) pressed at the point
    is held as its layer instead, a spring 1/c and damper d along the normal (``laws.KelvinVoigt``
    in ``lin.model``), sliding frictionlessly with ``"hold"``; with ``"roll"`` a second contact
    of the pair, ``<name>_rolling`` (``laws.Bilateral(rolling=True, hold_normal=False)``), holds
    its tangents, and must stay inside mu0 times the layer's force.

    ``at`` chooses the point instead of ``q``/``u``: ``None`` or ``"q0"`` (the model's q0, u0),
    ``"equilibrium"`` (:func:`mechsys.analysis.static_equilibrium` from ``q``, at rest unless
    ``u`` is given), a :class:`SteadyMotion` from :func:`steady_motion`, or a dict
    ``{"q": ..., "u": ...}`` whose entries are full vectors or ``{joint: value}`` dicts, or
    directly a ``{joint: q value}`` dict as ``simulate``'s q0. ``q``, ``u`` also accept
    ``{joint: value}`` dicts. A mass matrix that is singular (a coordinate without inertia)
    raises a ModelError naming the coordinate."""
    if not isinstance(model, Model):
        raise SettingsError(f"linearize: expected a mechsys.Model, got {type(model).__name__}")
    if isinstance(at, SteadyMotion):
        t = at.t
    if contacts != "refuse":
        # which contacts are closed is read where the search starts (q, or q0); an equilibrium is
        # then found with them held
        start = at if not (isinstance(at, str) and at == "equilibrium") else None
        q0_, u0_ = _point(model, q, u, float(t), start)
        model, held = _held_model(model, q0_, u0_, float(t), contacts)
        q, u = (q0_, u0_) if start is at else _point(model, q, u, float(t), at)
        _check_held(model, held, q, u, float(t), contacts)
    else:
        q, u = _point(model, q, u, float(t), at)
    _refuse_nonsmooth(model, q, u, float(t))
    coords = _names(model, model.nu)
    nonholonomic = _nonholonomic(model) if model.engine()[0].constraints() else False
    if coordinates is not None:
        wanted = [coordinates] if isinstance(coordinates, (str, int, np.integer)) else list(coordinates)
        if not wanted:
            raise SettingsError("linearize: coordinates: name at least one joint coordinate")
        idx = [_coordinate(coords, c, "linearize: coordinates") for c in wanted]
        if len(set(idx)) < len(idx):
            raise SettingsError(f"linearize: coordinates: a coordinate is named twice in {wanted!r}")
        prefer = idx
    else:
        prefer = [] if nonholonomic else None
    moving = bool(np.any(u != 0.0))
    _check_constraints(model, q, u, float(t))
    old = None
    if coordinates is None and not moving:
        # at rest: the second-order form in minimal coordinates (as always); the first-order form
        # is built when asked for (lin.A, lin.cyclic, ...)
        core, cbs = model.engine()
        old = _core.linearize(core, q, u, float(t), cbs, method)
        n_u = old["V"].shape[0]
        names = _names(model, n_u)
        if old["V"].shape[1] != n_u or not np.allclose(old["V"], np.eye(n_u)):
            names = [f"y{k}" for k in range(old["V"].shape[1])]
        c, s_ = old["D"] + old["G"], old["K"] + old["N"]
        mats = (old["M"], old["D"], old["G"], old["K"], old["N"])
        v_basis, residual, sf = old["V"], old["residual"], None
        res = float(np.abs(residual).max(initial=0.0))
        steady = res <= 1e-8 * (1.0 + np.abs(old["K"]).max(initial=0.0) + np.abs(old["M"]).max(initial=0.0))
        why = "" if steady else f"residual {res:.3g} on coordinate '{names[int(np.abs(residual).argmax())]}'"
        method_used = old["method"]
    else:
        sf, raw = _state_form(model, q, u, float(t), method, prefer)
        steady, why = _steadiness(sf, u)
        method_used = raw["method"]
        if coordinates is not None:
            sel = []
            for k in idx:
                name = coords[k]
                if name in sf.cyclic:
                    raise SettingsError(f"linearize: coordinates: '{name}' is cyclic (the linearized motion does not depend "
                                        f"on it; cyclic: {', '.join(sf.cyclic)}); name non-cyclic coordinates")
                if name not in sf.keep_names:
                    raise SettingsError(f"linearize: coordinates: '{name}' is not an independent coordinate here (the "
                                        f"constraints determine it from the others); independent: {', '.join(sf.keep_names)}")
                sel.append(sf.keep_names.index(name))
            form = _second_order_form(sf.reduced()[0], sf.n_config, sf.keep_names, sf.V, raw["mass"], sel)
            if isinstance(form, str):
                raise SettingsError(f"linearize: coordinates {', '.join(coords[k] for k in idx)}: {form}")
            names = [coords[k] for k in idx]
            v_basis = (sf.Vh @ sf.keep)[:, sel]
        elif not nonholonomic:
            # moving, holonomic: y = all configuration states (cyclic ones kept: a Campbell diagram
            # follows the same coordinates at every speed)
            form = _second_order_form(sf.A, sf.nq, sf.names[: sf.nq], sf.V, raw["mass"], None)
            names, v_basis = sf.names[: sf.nq], sf.Vh
        else:
            form = _second_order_form(sf.reduced()[0], sf.n_config, sf.keep_names, sf.V, raw["mass"], None)
            names, v_basis = list(sf.keep_names), sf.Vh @ sf.keep
        if isinstance(form, str):
            sf = replace(sf, why_first_order=form)
            mats = (None,) * 5
        else:
            mm, c, s_ = form
            mats = (mm, 0.5 * (c + c.T), 0.5 * (c - c.T), 0.5 * (s_ + s_.T), 0.5 * (s_ - s_.T))
        residual = np.concatenate([sf.keep.T @ sf.rate[: sf.nq], sf.rate[sf.nq:]])
    lin = LinearModel(*mats, v_basis, np.asarray(residual, dtype=float), q, u, float(t), names, method_used,
                      model, sf, steady)
    if lin.M is not None:
        _check_mass(lin, model.name)
    if not steady and not operating_point:
        warnings.warn(f"model '{model.name}': linearized at a point that is not an equilibrium or a steady motion: {why} "
                      "(the linear model holds at this instant only; pass operating_point=True if that is meant)",
                      UserWarning, stacklevel=2)
    return lin


def _steadiness(sf: StateForm, u: np.ndarray) -> tuple[bool, str]:
    """Whether the reference is steady: its non-cyclic configuration states do not move, its
    velocity states do not change, and the admissible subspace is invariant."""
    scale_a = 1.0 + float(np.abs(sf.A).max(initial=0.0)) * (1.0 + float(np.abs(u).max(initial=0.0)))
    moves = sf.keep.T @ sf.rate[: sf.nq]
    acc = sf.rate[sf.nq:]
    if moves.size and np.abs(moves).max() > 1e-8 * (1.0 + float(np.abs(u).max(initial=0.0))):
        k = int(np.abs(moves).argmax())
        return False, f"the non-cyclic coordinate '{sf.keep_names[k]}' moves at {moves[k]:.3g} per second"
    if acc.size and np.abs(acc).max() > 1e-8 * scale_a:
        k = int(np.abs(acc).argmax())
        return False, f"the velocity '{sf.names[sf.nq + k]}' changes at {acc[k]:.3g} per second (residual)"
    if sf.defect > 1e-4:
        return False, f"the admissible motions are not invariant (defect {sf.defect:.2g})"
    return True, ""


def _check_constraints(model: Model, q: np.ndarray, u: np.ndarray, t: float) -> None:
    """A ModelError naming the first constraint the point violates (position or velocity)."""
    cons = model.engine()[0].constraints()
    if not cons:
        return
    core, cbs = model.engine()
    phi, g, b = _core.constraint_jacobian(core, q, t, cbs)
    vel_res = g @ u - b
    tol_q = 1e-6 * (1.0 + float(np.abs(q).max(initial=0.0)))
    tol_u = 1e-6 * (1.0 + float(np.abs(u).max(initial=0.0)))
    for c in cons:
        r0, n, nh = c["row"], c["rows"], c["holonomic_rows"]
        ph = np.abs(phi[r0:r0 + nh])
        if ph.size and ph.max() > tol_q:
            raise ModelError(f"linearize: the point violates constraint '{c['name']}' (position residual "
                             f"{ph.max():.3g} {c.get('violation_unit', '')}); give a consistent q (e.g. from the "
                             "start of a simulation or ms.analysis.assemble)")
        vel = np.abs(vel_res[r0:r0 + n])
        if vel.size and vel.max() > tol_u:
            raise ModelError(f"linearize: the point violates constraint '{c['name']}' (velocity residual "
                             f"{vel.max():.3g}); give velocities the constraint admits")


def _static_mu(friction) -> float | None:
    """The static friction coefficient of a described friction law (None: frictionless)."""
    if not isinstance(friction, dict):
        return None
    kind = friction.get("type")
    if kind == "coulomb":
        mu = float(friction["mu"])
        return max(mu, float(friction.get("mu0") if friction.get("mu0") is not None else mu))
    if kind == "stribeck":
        return float(friction["mu0"])
    if kind == "table":
        return float(friction["mu"][0])
    return None


def _held_model(model: Model, q: np.ndarray, u: np.ndarray, t: float, mode: str) -> tuple[Model, dict]:
    """``model`` with its contacts closed at (q, u, t) held by the bilateral law (rolling for
    ``mode == "roll"``), and the held contacts' static friction coefficients by name."""
    from .dynamics import contact_matrices

    if mode not in ("hold", "roll"):
        raise SettingsError(f"linearize: contacts: expected 'refuse', 'hold' or 'roll', got {mode!r}")
    if not model._contacts:
        return model, {}
    cm = contact_matrices(model, q, u, t)
    scale = 1e-9 * (1.0 + float(np.abs(q).max(initial=0.0)))
    closed: dict[str, int] = {}
    closed_gap: dict[str, float] = {}
    for name, g in zip(cm["contact"], cm["gap"]):
        if g <= scale:
            closed[name] = closed.get(name, 0) + 1
            closed_gap[name] = min(closed_gap.get(name, np.inf), float(g))
    if not closed:
        return model, {}
    desc, callbacks = model.describe()
    held = {}
    rollers = []
    for c in desc.get("contacts", []) + desc.get("gap_contacts", []):
        if c["name"] not in closed:
            continue
        what = f"linearize: contact '{c['name']}'"
        if "gap" in c and mode == "roll" and not c.get("tangents"):
            raise SettingsError(f"{what} has no tangential coordinate, so it cannot roll; use contacts='hold'")
        if c.get("points", 1) != 1:
            raise SettingsError(f"{what} looks for {c['points']} contact points; only a single-point contact "
                                "(points=1) can be held closed")
        layer = c.get("normal") or {}
        if layer.get("type") == "signorini" and layer.get("compliance", 0.0) > 0.0:
            # a compliant Signorini layer held closed is its spring (and damper) along the normal,
            # sliding frictionlessly: a Kelvin-Voigt force, smooth where the layer is pressed;
            # rolling, a second contact of the pair holds its tangents (laws.Bilateral with
            # hold_normal=False) while the layer carries the normal force
            if mode == "roll":
                if "gap" in c:
                    raise SettingsError(f"{what} is a gap contact on a compliant Signorini layer: rolling on a layer is "
                                        "held for contour contacts only; use contacts='hold'")
                mu = _static_mu(c.get("friction"))
                if mu is None:
                    raise SettingsError(f"{what} has a frictionless compliant Signorini layer, so it cannot roll without "
                                        "slip; use contacts='hold'")
                roller = {k: v for k, v in c.items() if k not in ("friction", "impact", "normal")}
                roller["name"] = f"{c['name']}_rolling"
                roller["normal"] = {"type": "bilateral", "rolling": True, "hold_normal": False}
                rollers.append(roller)
                held[roller["name"]] = (mu, model, c["name"], 1.0 / float(layer["compliance"]))
            if closed_gap[c["name"]] >= 0.0:
                raise SettingsError(f"{what} touches without pressing its compliant layer at the point (gap "
                                    f"{closed_gap[c['name']]:.3g} m): the layer's force has a kink there; linearize where "
                                    "it is pressed (at rest under load) or open")
            c["normal"] = {"type": "kelvin_voigt", "k": 1.0 / float(layer["compliance"]),
                           "d": float(layer.get("damping", 0.0))}
            c.pop("friction", None)
            c.pop("impact", None)
            continue
        mu = _static_mu(c.get("friction"))
        if mode == "roll" and mu is None:
            raise SettingsError(f"{what} is frictionless, so it cannot roll without slip; use contacts='hold'")
        held[c["name"]] = mu
        c["normal"] = {"type": "bilateral", "rolling": mode == "roll"}
        c.pop("friction", None)
        c.pop("impact", None)
    desc.setdefault("contacts", []).extend(rollers)
    return Model.from_dict(desc, callbacks), held


def _layer_force(entry: tuple, q: np.ndarray, u: np.ndarray, t: float) -> float:
    """The normal force k max(0, -g_N) of a contact held rolling on its compliant layer (a
    ``held`` entry (mu, model, contact, k)), from its gap in the model it was derived from."""
    from .dynamics import contact_matrices

    _, original, name, k = entry
    cm = contact_matrices(original, q, u, t)
    gaps = [float(g) for c, g in zip(cm["contact"], cm["gap"]) if c == name]
    return k * max(0.0, -min(gaps)) if gaps else 0.0


def _check_held(derived: Model, held: dict, q: np.ndarray, u: np.ndarray, t: float, mode: str) -> None:
    """A SettingsError naming a held contact that pulls at the point (or, rolling, would slip)."""
    from .dynamics import mass_matrix, nonlinear_effects

    if not held:
        return
    # the multipliers at the point: M u' = h + G^T lambda, G u' = gamma
    core, cbs = derived.engine()
    _, g_mat, _ = _core.constraint_jacobian(core, q, t, cbs)
    gamma = _core.constraint_gamma(core, q, u, t, cbs)
    m_inv_h = np.linalg.solve(mass_matrix(derived, q, t), np.column_stack([nonlinear_effects(derived, q, u, t), g_mat.T]))
    lam = np.linalg.lstsq(g_mat @ m_inv_h[:, 1:], gamma - g_mat @ m_inv_h[:, 0], rcond=None)[0]
    for info in derived.engine()[0].constraints():
        if info["name"] not in held:
            continue
        if isinstance(held[info["name"]], tuple):
            # rolling on a compliant layer: the layer's spring carries the normal force, the
            # constraint's rows are the tangential (friction) forces
            entry = held[info["name"]]
            lam_n = _layer_force(entry, q, u, t)
            lam_t = float(np.linalg.norm(lam[info["row"]:info["row"] + info["rows"]]))
            if lam_t > entry[0] * lam_n * (1.0 + 1e-12):
                raise SettingsError(f"linearize: contact '{entry[2]}' cannot roll on its compliant layer at the point: it "
                                    f"needs a friction force {lam_t:.4g} N, more than mu0 times the layer's normal force "
                                    f"({entry[0]:.3g} x {lam_n:.4g} N); it slips (use contacts='hold' for frictionless sliding)")
            continue
        r0, lam_n = info["row"], float(lam[info["row"]])
        if lam_n <= 0.0:
            raise SettingsError(f"linearize: contact '{info['name']}' does not press at the point (normal force "
                                f"{lam_n:.4g} N): held closed it would have to pull, so it opens there")
        mu = held[info["name"]]
        if mode == "roll":
            lam_t = float(np.linalg.norm(lam[r0 + 1:r0 + info["rows"]]))
            if lam_t > mu * lam_n * (1.0 + 1e-12):
                raise SettingsError(f"linearize: contact '{info['name']}' cannot roll at the point: it needs a friction "
                                    f"force {lam_t:.4g} N, more than mu0 times its normal force ({mu:.3g} x {lam_n:.4g} N); "
                                    "it slips (use contacts='hold' for frictionless sliding)")


def _refuse_nonsmooth(model: Model, q: np.ndarray, u: np.ndarray, t: float) -> None:
    """SettingsError where a force law is not smooth at the point, so no linear form exists:
    a unilateral contact touching there (its force may jump on or off with any perturbation),
    or a Jenkins slider at its slip limit (stick on one side, slip on the other). Open contacts
    exert nothing and are left out; a Jenkins element well inside stick is its spring."""
    from .forces import Jenkins

    if model._contacts:
        from .dynamics import contact_matrices

        cm = contact_matrices(model, q, u, t)
        scale = 1e-9 * (1.0 + float(np.abs(q).max(initial=0.0)))
        for k, g in enumerate(cm["gap"]):
            if g <= scale:
                raise SettingsError(
                    f"linearize: contact '{cm['contact'][k]}' is closed at the point (gap {g:.3g} m): a unilateral "
                    "contact switches between touching and open (and stick and slip) under any perturbation, so the "
                    "linear form does not apply there; linearize where it is open, hold it closed (contacts='hold' "
                    "or 'roll'), or simulate")
    joints = {j["name"]: j for j in model.joint_info()}
    for f in model._forces:
        if isinstance(f, Jenkins):
            j = joints.get(f.joint if isinstance(f.joint, str) else getattr(f.joint, "name", ""))
            if j is None:
                continue
            x = float(q[j["iq"] + int(f.index)]) - float(f.offset)
            slip = float(np.min(np.atleast_1d(f.slip)))
            if abs(f.k * x) >= slip * (1.0 - 1e-9):
                raise SettingsError(
                    f"linearize: force element '{f.name}' (Jenkins) is at its slip limit at the point (spring force "
                    f"{abs(f.k * x):.4g} >= slip force {slip:.4g}): its law sticks one way and slips the other, so the "
                    "linear form does not apply; linearize inside stick, or use ms.linear.hysteresis for an "
                    "equivalent linear element")


# ---- the first-order form about a motion ---------------------------------------------------------


@dataclass(frozen=True)
class StateForm:
    """The linearization about a state (q, u, t) in first-order form, ``x' = A x + B tau``, with
    x = (xi, eta): configuration perturbations delta = Vh xi along the directions the holonomic
    constraints allow (quaternion joints in rotation vectors of the child frame) and velocity
    perturbations delta_u = P xi + V eta along those all constraints allow; P keeps a perturbed
    configuration's velocity admissible. Right for non-holonomic constraints and moving states,
    where configuration and velocity perturbations differ in number and the reference moves.

    ``A``, ``B`` here include the cyclic coordinates; :meth:`reduced` (and ``LinearModel.A``)
    removes them."""

    A: np.ndarray
    B: np.ndarray
    #: names of the entries of x (configuration coordinates, then rates with a prime)
    names: list
    #: configuration and velocity states (n_q,min, n_u,min)
    nq: int
    nu: int
    Vh: np.ndarray
    P: np.ndarray
    V: np.ndarray
    Lh: np.ndarray
    Lu: np.ndarray
    #: the joint velocities (chart coordinates) by name, model order
    coordinates: list
    #: the reference's own rates in x: a steady motion moves only along cyclic directions
    rate: np.ndarray
    #: how far the admissible subspace is from invariant under the linearized motion (round-off
    #: about a steady motion)
    defect: float
    #: cyclic coordinates (names) and the xi-directions the motion does not depend on (nq x k)
    cyclic: list
    cyclic_basis: np.ndarray
    #: xi-directions kept by :meth:`reduced` (nq x (nq - k)) and their names
    keep: np.ndarray
    keep_names: list
    method: str = "exact"
    #: why there is no second-order form ("" when there is one)
    why_first_order: str = ""

    @property
    def n_config(self) -> int:
        """Configuration states after removing the cyclic ones."""
        return self.keep.shape[1]

    def _t(self) -> np.ndarray:
        t = np.zeros((self.nq + self.nu, self.n_config + self.nu))
        t[: self.nq, : self.n_config] = self.keep
        t[self.nq:, self.n_config:] = np.eye(self.nu)
        return t

    def reduced(self) -> tuple[np.ndarray, np.ndarray, list]:
        """``(A, B, names)`` with the cyclic coordinates removed (the motion does not depend on
        them, so the rest is closed)."""
        t = self._t()
        return t.T @ self.A @ t, t.T @ self.B, list(self.keep_names) + [n for n in self.names[self.nq:]]

    def shape_map(self) -> np.ndarray:
        """Reduced configuration states -> joint velocities (chart directions), for mode shapes."""
        return self.Vh @ self.keep

    def state_space(self, inputs=None, outputs=None):
        a, b, names = self.reduced()
        t = self._t()
        if inputs is not None:
            b = b[:, [_coordinate(self.coordinates, i, "inputs") for i in np.atleast_1d(inputs)]]
        if outputs is None:
            return a, b, np.eye(a.shape[0])
        rows = []
        for o in np.atleast_1d(outputs):
            name = str(o)
            rate = name.endswith("'")
            k = _coordinate(self.coordinates, name[:-1] if rate else o, "outputs")
            if self.coordinates[k] in self.cyclic and not rate:
                raise SettingsError(f"state_space: outputs: coordinate '{self.coordinates[k]}' is cyclic (the linearized "
                                    "motion does not depend on it and it drifts freely); name a non-cyclic coordinate or "
                                    "its rate")
            full = np.zeros(self.nq + self.nu)
            if rate:
                full[: self.nq] = self.P[k]
                full[self.nq:] = self.V[k]
            else:
                full[: self.nq] = self.Vh[k]
            rows.append(full @ t)
        return a, b, np.array(rows)


def _coordinate(names: list, i, what: str) -> int:
    if isinstance(i, (str, np.str_)):
        if str(i) not in names:
            raise SettingsError(f"{what}: no joint coordinate named '{i}' (have {', '.join(names)})")
        return names.index(str(i))
    k = int(i)
    if not 0 <= k < len(names):
        raise SettingsError(f"{what}: coordinate index {k} out of range 0..{len(names) - 1}")
    return k


def _nonholonomic(model: Model) -> bool:
    return any(c["holonomic_rows"] < c["rows"] for c in model.engine()[0].constraints())


def _state_form(model: Model, q, u, t: float, method: str, prefer) -> tuple[StateForm, dict]:
    """The first-order form from the core, its cyclic coordinates and their complement."""
    core, cbs = model.engine()
    raw = _core.state_space(core, q, u, t, cbs, method, prefer)
    coords = _names(model, model.nu)
    a, nq, nu = raw["A"], raw["Vh"].shape[1], raw["V"].shape[1]
    partition = prefer is not None
    if partition:
        names = [coords[i] for i in raw["independent_q"]] + [coords[i] + "'" for i in raw["independent_u"]]
    elif raw["Vh"].shape == (model.nu, model.nu) and np.allclose(raw["Vh"], np.eye(model.nu)) and \
            raw["V"].shape == (model.nu, model.nu) and np.allclose(raw["V"], np.eye(model.nu)):
        names = coords + [c + "'" for c in coords]
    else:
        names = [f"y{k}" for k in range(nq)] + [f"y{k}'" for k in range(nu)]
    # cyclic: xi-directions whose columns of A vanish (the motion does not depend on them)
    scale = max(float(np.abs(a).max(initial=0.0)), 1e-300)
    tol = (1e-7 if raw["method"] == "fd" else 1e-9) * scale
    axi = a[:, :nq]
    # coordinates nothing else depends on (heading on the plane feeds only the position, itself
    # cyclic): the largest set C of configuration states with A[rows outside C, C] = 0
    inside = np.ones(nq, dtype=bool)
    while nq:
        outside = np.concatenate([~inside, np.ones(nu, dtype=bool)])
        bad = inside & (np.abs(a[outside, :nq]).max(axis=0, initial=0.0) > tol)
        if not bad.any():
            break
        inside &= ~bad
    unit = [int(i) for i in np.nonzero(inside)[0]]
    cyclic = []
    null = np.zeros((nq, 0))
    if not unit and nq:
        # no single coordinate: look for combinations the columns of A do not see
        _, sv, vt = np.linalg.svd(axi)
        sv = np.concatenate([sv, np.zeros(nq - sv.size)])
        null = vt[sv <= tol].T
    k = null.shape[1]
    if unit:
        cyclic = [names[i] for i in unit]
        rest = [i for i in range(nq) if i not in unit]
        keep = np.eye(nq)[:, rest]
        keep_names = [names[i] for i in rest]
    elif k:
        # combinations only (a rotation about the vertical in a rotation-vector chart): name the
        # joint coordinates lying in them, keep the orthogonal complement
        for c in range(model.nu):
            e = np.zeros(model.nu)
            e[c] = 1.0
            xi = raw["Lh"] @ e
            if np.linalg.norm(raw["Vh"] @ xi - e) <= 1e-9 and \
                    np.linalg.norm(xi - null @ (null.T @ xi)) <= 1e-6 * np.linalg.norm(xi):
                cyclic.append(coords[c])
        if not cyclic:
            cyclic = [_describe_direction(model, raw["Vh"] @ null[:, i]) for i in range(k)]
        keep = np.linalg.svd(null.T)[2][k:].T
        keep_names = [f"z{i}" for i in range(keep.shape[1])]
    else:
        keep, keep_names = np.eye(nq), names[:nq]
    return StateForm(a, raw["B"], names, nq, nu, raw["Vh"], raw["P"], raw["V"], raw["Lh"], raw["Lu"], coords,
                     raw["rate"], float(raw["defect"]), cyclic, null, keep, keep_names, raw["method"]), raw


def _describe_direction(model: Model, d: np.ndarray) -> str:
    """A chart direction in words: a joint's turn about an axis of its child frame, or its
    components."""
    big = float(np.abs(d).max(initial=0.0))
    parts = []
    for j in model.joint_info():
        seg = d[j["iu"]:j["iu"] + j["nu"]]
        if np.abs(seg).max(initial=0.0) > 1e-6 * big:
            parts.append((j, seg))
    if len(parts) == 1:
        j, seg = parts[0]
        rot = {"spherical": slice(0, 3), "free": slice(3, 6)}.get(j["type"])
        if rot is not None and np.abs(np.delete(seg, np.arange(seg.size)[rot])).max(initial=0.0) <= 1e-6 * big:
            ax = seg[rot] / np.linalg.norm(seg[rot])
            return f"turn of '{j['name']}' about ({ax[0]:.4g}, {ax[1]:.4g}, {ax[2]:.4g}) of its child frame"
    return "combination " + " + ".join(f"{c:.3g} {n}" for n, c in zip(_names(model, model.nu), d / big) if abs(c) > 1e-6)


def _second_order_form(a: np.ndarray, n_cfg: int, cfg_names: list, v: np.ndarray, mass: np.ndarray, select):
    """M, D+G, K+N of the second-order form in the configuration states ``select`` (indices into
    the first ``n_cfg`` states of ``a``; all by default) where the motion admits it: the states
    outside y = xi[select], y' must form an invariant subspace (cyclic and decoupled conserved
    directions). Returns (M, C, S) or a str saying why not."""
    nu = a.shape[0] - n_cfg
    sel = list(range(n_cfg)) if select is None else list(select)
    m = len(sel)
    if m == 0:
        return "no non-cyclic configuration coordinate is left"
    y = np.zeros((2 * m, n_cfg + nu))
    y[np.arange(m), sel] = 1.0
    y[m:] = a[sel]
    if y.shape[0] == y.shape[1]:
        # every state named (holonomic, cyclic ones kept): a change of coordinates
        try:
            az = np.linalg.solve(y.T, (y @ a).T).T
        except np.linalg.LinAlgError:
            return "the coordinates' rates are not independent velocities"
    else:
        if np.linalg.matrix_rank(y, tol=1e-9 * max(float(np.abs(y).max()), 1.0)) < 2 * m:
            return "the coordinates' rates are not independent velocities"
        az = y @ a @ np.linalg.pinv(y)
    scale = max(float(np.abs(a).max(initial=0.0)), 1e-300)
    if y.shape[0] < y.shape[1] and \
            np.abs(y @ a - az @ y).max(initial=0.0) > 1e-7 * scale * max(1.0, float(np.abs(y).max())):
        names = [cfg_names[i] for i in sel]
        return (f"the other states feed back into {', '.join(names)} (velocities without a configuration partner, "
                "as a rolling wheel's heading rate): no second-order form in these coordinates")
    # the mass matrix: the kinetic metric of the velocity perturbations with y' given and xi = 0,
    # the least kinetic energy among them
    e = a[sel, n_cfg:]
    m_eta = v.T @ mass @ v
    metric = e @ np.linalg.solve(m_eta, e.T)
    # dependent rates (a rolling disc's x, y and heading rates tied by its constraints) make this
    # metric singular: exactly so with some rounding, and with other rounding a matrix whose
    # inverse is noise; both are the same answer, no second-order form in these coordinates
    sv = np.linalg.svd(metric, compute_uv=False)
    if not np.all(np.isfinite(sv)) or sv[-1] <= 1e-9 * sv[0]:
        return "the coordinates' rates are not independent velocities (their kinetic metric is singular)"
    my = np.linalg.inv(metric)
    my = 0.5 * (my + my.T)
    return my, -my @ az[m:, m:], -my @ az[m:, :m]


# ---- steady motions ------------------------------------------------------------------------------


@dataclass(frozen=True)
class SteadyMotion:
    """A steady motion (relative equilibrium) found by :func:`steady_motion`: every joint velocity
    constant (child-frame components for quaternion joints), the constraints satisfied; pass it
    as ``linearize(model, at=steady)``."""

    q: np.ndarray
    u: np.ndarray
    t: float
    #: the largest residual left (accelerations, constraint rows)
    residual: float
    iterations: int
    #: the unknowns that were solved for (names; rates end in a prime)
    solved: list = field(default_factory=list)

    def __getitem__(self, key: str) -> np.ndarray:
        return {"q": self.q, "u": self.u}[key]


def steady_motion(model: Model, q=None, u=None, t: float = 0.0, free=(), fixed=None, tol: float = 1e-10,
                  max_iter: int = 50) -> SteadyMotion:
    """A steady motion of ``model`` near the guess (``q``, ``u``; the model's q0, u0 by default):
    the joint velocities constant (u' = 0; child-frame components for quaternion joints) and the
    constraints satisfied, by Gauss-Newton on

        Phi(q) = 0 (holonomic rows),  G(q) u = b,  u'(q, u) = 0.

    ``free`` names what may change, as joint coordinates (``"lean"``, ``"free[3]"``: the chart
    direction of that velocity, a rotation-vector turn for quaternion joints) or speeds with a
    prime (``"spin'"``); ``fixed`` sets values first (``{"rear_hub'": -16.7, "lean": 0.1}``;
    coordinates of quaternion joints cannot be set this way). Coordinates and speeds the
    constraints determine (a wheel's height, a rolling wheel's forward speed) follow
    automatically; everything else stays at the guess. Straight running at speed v, steady
    circular rolling at a lean, a top's steady precession and a rotor at speed are all of this
    kind.

    Raises a SolverError naming the equation with the largest residual when it does not converge
    within ``max_iter`` iterations (a guess too far away, or too few ``free`` unknowns)."""
    from .errors import SolverError

    if not isinstance(model, Model):
        raise SettingsError(f"steady_motion: expected a mechsys.Model, got {type(model).__name__}")
    core, cbs = model.engine()
    q0 = _vector(model, q, "q", "q")
    u0 = _vector(model, u, "u", "u")
    coords = _names(model, model.nu)
    joints = {j["name"]: j for j in model.joint_info()}
    for name, value in (fixed or {}).items():
        rate = str(name).endswith("'")
        k = _coordinate(coords, str(name)[:-1] if rate else name, "steady_motion: fixed")
        if not np.isfinite(value):
            raise SettingsError(f"steady_motion: fixed['{name}'] must be finite, got {value!r}")
        if rate:
            u0[k] = float(value)
        else:
            j = next(j for j in joints.values() if j["iu"] <= k < j["iu"] + j["nu"])
            if j["nq"] != j["nu"]:
                raise SettingsError(f"steady_motion: fixed['{name}']: joint '{j['name']}' has quaternion coordinates; "
                                    "give its value in the guess q instead")
            q0[j["iq"] + k - j["iu"]] = float(value)
    fixed_names = {str(n) for n in (fixed or {})}
    free_q, free_u = [], []
    for name in ([free] if isinstance(free, str) else list(free)):
        rate = str(name).endswith("'")
        k = _coordinate(coords, str(name)[:-1] if rate else name, "steady_motion: free")
        (free_u if rate else free_q).append(k)
    nc = int(sum(c["rows"] for c in core.constraints()))
    cons = core.constraints()
    hol = np.zeros(nc, dtype=bool)
    for c in cons:
        hol[c["row"]:c["row"] + c["holonomic_rows"]] = True
    phi, g, b = _core.constraint_jacobian(core, q0, t, cbs)
    # the coordinates and speeds the constraints determine, among those neither free nor fixed
    pinned_q = set(free_q) | {_coordinate(coords, n, "") for n in fixed_names if not n.endswith("'")}
    pinned_u = set(free_u) | {_coordinate(coords, n[:-1], "") for n in fixed_names if n.endswith("'")}
    dep_q = _dependent(g[hol], [k for k in range(model.nu) if k not in pinned_q])
    dep_u = _dependent(g, [k for k in range(model.nu) if k not in pinned_u])
    unk_q = sorted(set(free_q) | set(dep_q))
    unk_u = sorted(set(free_u) | set(dep_u))
    nq_x = len(unk_q)

    def state(x):
        d = np.zeros(model.nu)
        d[unk_q] = x[:nq_x]
        qq = np.asarray(core.integrate(q0, d, 1.0))
        uu = u0.copy()
        uu[unk_u] = x[nq_x:]
        return qq, uu

    def residual(x):
        qq, uu = state(x)
        ph, gg, bb = _core.constraint_jacobian(core, qq, t, cbs)
        ud = _core.aba(core, qq, uu, None, t, cbs, None)
        return np.concatenate([ph[hol], gg @ uu - bb, ud])

    labels = ([f"constraint '{c['name']}' (position)" for c in cons for _ in range(c["holonomic_rows"])] +
              [f"constraint '{c['name']}' (velocity)" for c in cons for _ in range(c["rows"])] +
              [f"acceleration of '{n}'" for n in coords])
    x = np.concatenate([np.zeros(nq_x), u0[unk_u]])
    r = residual(x)
    scale = 1.0 + float(np.abs(u0).max(initial=0.0))
    it = 0
    while np.abs(r).max(initial=0.0) > tol * scale and it < max_iter:
        it += 1
        jac = np.empty((r.size, x.size))
        for k in range(x.size):
            h = 1e-7 * max(1.0, abs(x[k]))
            xp, xm = x.copy(), x.copy()
            xp[k] += h
            xm[k] -= h
            jac[:, k] = (residual(xp) - residual(xm)) / (2 * h)
        step = np.linalg.lstsq(jac, -r, rcond=1e-12)[0]
        lam, base = 1.0, np.abs(r).max()
        while lam > 1e-4:
            trial = residual(x + lam * step)
            if np.all(np.isfinite(trial)) and np.abs(trial).max() < base:
                break
            lam *= 0.5
        x = x + lam * step
        r = residual(x)
    if not np.all(np.isfinite(r)):
        bad = int(np.nonzero(~np.isfinite(r))[0][0])
        raise SolverError(f"steady_motion: model '{model.name}': the residual is not finite on {labels[bad]} after {it} "
                          "iterations (the guess or a step left the model's valid range)")
    worst = float(np.abs(r).max(initial=0.0))
    if not worst <= tol * scale:
        k = int(np.nanargmax(np.abs(r)))
        raise SolverError(f"steady_motion: model '{model.name}': no steady motion found near the guess in {it} "
                          f"iterations: residual {worst:.3g} on {labels[k]}; free: "
                          f"{', '.join([coords[i] for i in free_q] + [coords[i] + chr(39) for i in free_u]) or 'nothing'} "
                          "(free more speeds or coordinates, or start closer)")
    qq, uu = state(x)
    return SteadyMotion(qq, uu, float(t), worst, it, [coords[i] for i in unk_q] + [coords[i] + "'" for i in unk_u])


def _dependent(g: np.ndarray, allowed: list[int]) -> list[int]:
    """Columns of ``g`` among ``allowed`` that the rows determine (pivoted QR)."""
    if g.shape[0] == 0 or not allowed:
        return []
    from scipy.linalg import qr

    sub = g[:, allowed]
    _, r, piv = qr(sub, pivoting=True, mode="economic")
    d = np.abs(np.diag(r))
    rank = int(np.sum(d > 1e-10 * max(d.max(initial=0.0), 1e-300)))
    return [allowed[i] for i in piv[:rank]]


# ---- the self-check ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Check:
    """Eigenvalues of a linearization set beside growth rates and frequencies fitted to
    small-perturbation runs of the nonlinear model (:func:`check`)."""

    #: the eigenvalues checked (1/s)
    eigenvalues: np.ndarray
    #: fitted from the nonlinear runs (1/s)
    fitted: np.ndarray
    #: |fitted - eigenvalue| / |eigenvalue|
    error: np.ndarray
    #: duration of each run (s)
    duration: np.ndarray

    @property
    def worst(self) -> float:
        return float(self.error.max(initial=0.0))

    def table(self) -> str:
        rows = [f"{'mode':>4}  {'eigenvalue (1/s)':>28}  {'fitted from simulate (1/s)':>28}  {'rel. error':>10}"]
        for k, (a, b, e) in enumerate(zip(self.eigenvalues, self.fitted, self.error)):
            rows.append(f"{k + 1:>4}  {a.real:13.7g} {a.imag:+13.7g}j  {b.real:13.7g} {b.imag:+13.7g}j  {e:10.2e}")
        return "\n".join(rows)


def check(lin: LinearModel, modes=None, amplitude: float = 1e-6, cycles: float = 2.0, samples: int = 400,
          rtol: float = 1e-12) -> Check:
    """Checks a linearization against its nonlinear model: for each non-trivial eigenvalue (one
    of each complex pair; ``modes`` picks indices into that list), a run of ``simulate`` from
    the point perturbed along the eigenvector (largest coordinate or speed change ``amplitude``,
    relative to the state's scale) beside an unperturbed run; the difference of the joint
    velocities is fitted by linear prediction (order 2 for an oscillation, 1 for a real
    eigenvalue) over ``cycles`` periods (a quarter as many e-folding times for a real
    eigenvalue), and the fitted growth rate and
    frequency are set beside the eigenvalue. Agreement to about ``amplitude`` (the nonlinear
    terms) says the linear model is the nonlinear model's."""
    from .integrators import DOPRI5
    from .simulate import simulate

    sf = lin._state()
    model = lin.model
    if model is None:
        raise SettingsError("check: this LinearModel has no model (built by hand)")
    # (a zero or non-finite amplitude would fit a zero signal: log(0), a silent NaN)
    for name, v in (("amplitude", amplitude), ("cycles", cycles), ("rtol", rtol)):
        if not (isinstance(v, (int, float, np.floating)) and np.isfinite(v) and v > 0):
            raise SettingsError(f"check: {name} must be a finite number > 0, got {v!r}")
    if not (isinstance(samples, (int, np.integer)) and samples >= 8):
        raise SettingsError(f"check: samples must be a whole number >= 8, got {samples!r}")
    a, _, _ = sf.reduced()
    lam, vec = np.linalg.eig(a)
    big = float(np.abs(lam).max(initial=0.0))
    nontrivial = [i for i in range(lam.size) if abs(lam[i]) > 1e-6 * max(big, 1e-300) and lam[i].imag >= -1e-12 * big]
    nontrivial.sort(key=lambda i: (abs(lam[i]), lam[i].real))
    if modes is not None:
        try:
            nontrivial = [nontrivial[int(k)] for k in np.atleast_1d(modes)]
        except IndexError:
            raise SettingsError(f"check: modes {modes!r} out of range 0..{len(nontrivial) - 1}") from None
    t_ = sf._t()
    core = model.engine()[0]
    q0, u0 = np.asarray(lin.q, float), np.asarray(lin.u, float)
    uscale = 1.0 + float(np.abs(u0).max(initial=0.0))
    out = []
    for i in nontrivial:
        x = t_ @ (vec[:, i] if lam[i].imag > 0 else vec[:, i].real)
        x = x.real if lam[i].imag == 0 else x
        x = np.real(x) if np.iscomplexobj(x) else x
        d = sf.Vh @ x[: sf.nq]
        du = sf.P @ x[: sf.nq] + sf.V @ x[sf.nq:]
        size = max(float(np.abs(d).max(initial=0.0)), float(np.abs(du).max(initial=0.0)) / uscale, 1e-300)
        d, du = d * amplitude / size, du * amplitude / size
        qp = np.asarray(core.integrate(q0, d, 1.0))
        up = u0 + du
        li = lam[i]
        # oscillations over `cycles` periods; a real eigenvalue over a quarter of that many
        # e-folding times (long runs of slow modes collect the nonlinear drift of the cyclic states)
        span = cycles * (2 * np.pi / abs(li.imag) if abs(li.imag) > 1e-9 * abs(li) else 0.25 / abs(li.real))
        kw = dict(t_end=lin.t + span, t0=lin.t, output_dt=span / samples,
                  integrator=DOPRI5(rtol=rtol, atol=rtol * 1e-2))
        ref = simulate(model, q0=q0, u0=u0, **kw)
        run = simulate(model, q0=qp, u0=up, **kw)
        # all joint velocities (a mode may live in dependent ones, as a rolling disc's shifted
        # circle); a cyclic heading's offset is a constant per channel in the fit
        s = np.asarray(run["u"]) - np.asarray(ref["u"])
        dt = float(np.diff(np.asarray(run["t"])).mean())
        out.append((li, _fit_rate(s, dt, li.imag != 0), span))
    ev = np.array([o[0] for o in out], dtype=complex)
    fit = np.array([o[1] for o in out], dtype=complex)
    err = np.abs(fit - ev) / np.maximum(np.abs(ev), 1e-300)
    return Check(ev, fit, err, np.array([o[2] for o in out]))


def _fit_rate(s: np.ndarray, dt: float, oscillating: bool) -> complex:
    """Growth rate (and frequency) of a sampled multi-channel signal s (samples x channels) of
    one real exponential or one damped oscillation over constant offsets (a zero mode touched by
    the perturbation), by least-squares linear prediction with one constant per channel."""
    n, c = s.shape
    order = 2 if oscillating else 1
    rows = n - order
    lhs = s[order:].T.reshape(-1)
    cols = [s[order - 1 - i:n - 1 - i].T.reshape(-1) for i in range(order)]
    offsets = np.kron(np.eye(c), np.ones((rows, 1)))
    coef = np.linalg.lstsq(np.column_stack(cols + [offsets]), lhs, rcond=None)[0]
    if oscillating:
        z = np.roots([1.0, -coef[0], -coef[1]]).astype(complex)
        z = z[np.argmax(z.imag)]
    else:
        z = complex(coef[0])
    return complex(np.log(z) / dt)


# ---- the linearization point ---------------------------------------------------------------------


def _vector(model: Model, values, which: str, what: str) -> np.ndarray:
    """A full q (``which="q"``) or u vector from None (the model's own), an array or a
    ``{joint: value}`` dict; errors name ``what``."""
    try:
        v = np.array(model.state_vector(values, which), dtype=float)
    except MechsysError as e:
        raise type(e)(f"linearize: {what}: " + str(e).split(": ", 1)[-1]) from None
    except (TypeError, ValueError):
        raise SettingsError(f"linearize: {what}: expected a vector or a {{joint: value}} dict, got {values!r}") from None
    if not np.all(np.isfinite(v)):
        raise SettingsError(f"linearize: {what}: values must be finite, got {values!r}")
    return v


def _point(model: Model, q, u, t: float, at) -> tuple[np.ndarray, np.ndarray]:
    """(q, u) of the linearization point from linearize's ``q``, ``u`` and ``at``."""
    if isinstance(at, SteadyMotion):
        if q is not None or u is not None:
            raise SettingsError("linearize: give the point by at= or by q=/u=, not both")
        return _vector(model, at.q, "q", "at.q"), _vector(model, at.u, "u", "at.u")
    if at is None or (isinstance(at, str) and at == "q0"):
        return _vector(model, q, "q", "q"), _vector(model, u, "u", "u")
    if isinstance(at, str):
        if at != "equilibrium":
            raise SettingsError(f"linearize: at={at!r}: expected None, 'q0', 'equilibrium' or a dict {{'q': ..., 'u': ...}}")
        from .analysis import static_equilibrium

        eq = static_equilibrium(model, _vector(model, q, "q", "q"), t)
        return np.array(eq["q"], dtype=float), np.zeros(model.nu) if u is None else _vector(model, u, "u", "u")
    if isinstance(at, dict):
        if q is not None or u is not None:
            raise SettingsError("linearize: give the point by at= or by q=/u=, not both")
        if at and set(at) <= {"q", "u"}:
            return _vector(model, at.get("q"), "q", "at['q']"), _vector(model, at.get("u"), "u", "at['u']")
        return _vector(model, at, "q", "at"), _vector(model, None, "u", "u")
    raise SettingsError(f"linearize: at: expected None, 'q0', 'equilibrium' or a dict {{'q': ..., 'u': ...}}, "
                        f"got {type(at).__name__} {at!r}")


def _check_mass(lin: LinearModel, model_name: str) -> None:
    """ModelError naming the coordinate(s) without inertia when M is singular (to round-off)."""
    m = lin.M
    if not np.all(np.isfinite(m)):
        raise ModelError(f"model '{model_name}': the linearized mass matrix is not finite")
    if lin.n == 0:
        return
    d = np.diag(m)
    big = float(np.abs(d).max())
    light = np.nonzero(d <= 1e-13 * big)[0] if big > 0 else np.arange(lin.n)
    if light.size == 0:
        s = m / np.sqrt(np.outer(d, d))
        w, v = np.linalg.eigh(0.5 * (s + s.T))
        if w[0] > 1e-12 * w[-1]:
            return
        light = np.nonzero(np.abs(v[:, 0]) > 0.1 * np.abs(v[:, 0]).max())[0]
    names = ", ".join(f"'{lin.names[k]}'" for k in light)
    raise ModelError(f"model '{model_name}': the mass matrix is singular: coordinate{'s' if light.size > 1 else ''} "
                     f"{names} {'have' if light.size > 1 else 'has'} no inertia (give the body on that joint mass "
                     "or inertia, or remove the coordinate)")


# ---- Campbell diagrams ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Campbell:
    """Modes of a spinning model against the spin speed, each column one mode followed across
    the speeds (NaN where it is missing)."""

    #: spin speeds (rad/s)
    speeds: np.ndarray
    #: damped (whirl) frequencies Im(lambda) / 2 pi (Hz), n_speeds x n_modes
    frequencies: np.ndarray
    #: undamped natural frequencies |lambda| / 2 pi (Hz)
    natural_frequency: np.ndarray
    #: damping ratios -Re(lambda) / |lambda| (negative: unstable)
    damping_ratio: np.ndarray
    #: 'forward', 'backward' or '' per speed and mode
    whirl: np.ndarray
    #: the spin joint (and component)
    joint: str = ""
    #: the largest equilibrium residual over the speeds (nonzero: not a steady motion)
    residual: float = 0.0

    def critical_speeds(self, order: float = 1.0) -> list[dict]:
        """Speeds (rad/s) where a mode's frequency crosses the excitation line f = order * speed / 2 pi
        (linear interpolation): dicts with mode (column), speed, frequency (Hz), whirl."""
        out = []
        for c in range(self.frequencies.shape[1]):
            g = self.frequencies[:, c] - order * self.speeds / (2 * np.pi)
            for k in range(len(g) - 1):
                if np.isfinite(g[k]) and np.isfinite(g[k + 1]) and g[k] * g[k + 1] <= 0 and g[k] != g[k + 1]:
                    a = g[k] / (g[k] - g[k + 1])
                    w = self.speeds[k] + a * (self.speeds[k + 1] - self.speeds[k])
                    out.append({"mode": c, "speed": float(w), "frequency": float(order * w / (2 * np.pi)),
                                "whirl": self.whirl[k + (a > 0.5), c]})
        return sorted(out, key=lambda d: abs(d["speed"]))

    def table(self) -> str:
        """A text table: one row per speed, the frequency (Hz) of each mode with f/b for the whirl."""
        n = self.frequencies.shape[1]
        rows = [f"{'speed (rad/s)':>13}" + "".join(f"  {'mode ' + str(c + 1) + ' (Hz)':>15}" for c in range(n))]
        mark = {"forward": " f", "backward": " b", "": "  "}
        for k, w in enumerate(self.speeds):
            rows.append(f"{w:13.6g}" + "".join(f"  {self.frequencies[k, c]:13.6g}{mark[self.whirl[k, c]]}" for c in range(n)))
        return "\n".join(rows)

    def plot(self, out=None, orders=(1.0,), title: str | None = None, rpm: bool = False):
        """Frequency (Hz) against speed (rad/s, or rpm with ``rpm=True``): forward whirl solid,
        backward dashed, undetermined dotted; the excitation lines f = order * speed (``orders``,
        e.g. (1, 2)) and their crossings (critical speeds). Saved to ``out`` if given."""
        fig = _figure(out, (7.5, 5.0))
        ax = fig.subplots()
        scale = 60 / (2 * np.pi) if rpm else 1.0
        x = self.speeds * scale
        styles = {"forward": "-", "backward": "--", "": ":"}
        colors = [f"C{c % 10}" for c in range(self.frequencies.shape[1])]
        for c in range(self.frequencies.shape[1]):
            f, lab = self.frequencies[:, c], self.whirl[:, c]
            start = 0
            for k in range(1, len(f) + 1):
                if k == len(f) or lab[k] != lab[start]:
                    seg = slice(max(start - 1, 0), k)
                    ax.plot(x[seg], f[seg], styles[lab[start]], color=colors[c], lw=1.6)
                    start = k
        top = np.nanmax(self.frequencies) * 1.1 if np.isfinite(self.frequencies).any() else 1.0
        for o in orders:
            ax.plot(x, o * np.abs(self.speeds) / (2 * np.pi), color="0.4", lw=1.0)
            # the label near where the line leaves the axes
            end = min(float(np.abs(self.speeds).max()), top * 2 * np.pi / o) * 0.93
            ax.annotate(f"{o:g}×", (end * scale * (1 if x.max() > 0 else -1), o * end / (2 * np.pi)), xytext=(5, -2),
                        textcoords="offset points", fontsize="medium", color="0.3", ha="left", va="top")
            for cs in self.critical_speeds(o):
                ax.plot(cs["speed"] * scale, abs(cs["frequency"]), "o", mfc="none", color="k", ms=7)
        from matplotlib.lines import Line2D

        handles = [Line2D([], [], color=colors[c], lw=1.6, label=f"mode {c + 1}") for c in range(len(colors))]
        handles += [Line2D([], [], color="k", ls="-", label="forward whirl"), Line2D([], [], color="k", ls="--", label="backward whirl"),
                    Line2D([], [], color="0.4", lw=1.0, label="excitation (order × speed)"),
                    Line2D([], [], marker="o", mfc="none", color="k", ls="", label="critical speed")]
        ax.legend(handles=handles, fontsize="small", loc="upper left", framealpha=0.8)
        ax.set_xlim(x.min(), x.max() if x.max() > x.min() else x.min() + 1)
        ax.set_ylim(0, top)
        ax.set_xlabel(f"spin speed of '{self.joint}' [{'rpm' if rpm else 'rad/s'}]")
        ax.set_ylabel("whirl frequency [Hz]")
        ax.grid(True, alpha=0.3)
        ax.set_title(title or "Campbell diagram")
        return _save(fig, out)


def _spin_index(model: Model, joint: str, component: int | None) -> int:
    """Index into u of the spin joint's velocity (component ``component`` of a multi-velocity joint)."""
    info = {j["name"]: j for j in model.joint_info()}
    if joint not in info:
        raise SettingsError(f"campbell: unknown joint '{joint}' (joints: {', '.join(info)})")
    j = info[joint]
    if component is None:
        if j["nu"] != 1:
            raise SettingsError(f"campbell: joint '{joint}' ({j['type']}) has {j['nu']} velocities; a spin joint has one "
                                f"(or pass component=0..{j['nu'] - 1})")
        return j["iu"]
    if not (isinstance(component, (int, np.integer)) and 0 <= component < j["nu"]):
        raise SettingsError(f"campbell: component {component!r} of joint '{joint}' out of range 0..{j['nu'] - 1}")
    return j["iu"] + int(component)


def _relinearize(lin: LinearModel, u: np.ndarray) -> LinearModel:
    """``lin``'s model linearized again at its q, t with the velocities ``u``, by the same kind of
    derivatives (``lin.method`` names what was used, e.g. "exact+fd-constraints"; the request
    that gives it again is "fd" or "exact")."""
    return linearize(lin.model, q=lin.q, u=u, t=lin.t, operating_point=True,
                     method="fd" if lin.method == "fd" else "exact")


def _elastic_modes(modes: Modes, rigid_tol: float) -> dict:
    """Eigenvalues and shapes of the modes with |lambda| above ``rigid_tol`` times the largest."""
    mag = np.abs(modes.eigenvalues)
    keep = mag > rigid_tol * mag.max(initial=0.0)
    return {"lam": modes.eigenvalues[keep], "shapes": modes.shapes[:, keep]}


def _mac(a: np.ndarray, b: np.ndarray) -> float:
    """Modal assurance criterion |a^H b|^2 / (|a|^2 |b|^2) of two complex shapes."""
    den = float(np.vdot(a, a).real * np.vdot(b, b).real)
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


def _whirl(shape: np.ndarray, pair, speed: float, lam: complex) -> str:
    """'forward' / 'backward' from the orbit's sense in the whirl plane against the spin's sign."""
    if pair is None or speed == 0 or lam.imag <= 0:
        return ""
    sx, sy = shape[pair[0]], shape[pair[1]]
    size = abs(sx) ** 2 + abs(sy) ** 2
    sense = (sx * np.conj(sy)).imag
    if size <= 1e-12 * float(np.vdot(shape, shape).real) or abs(sense) <= 1e-6 * size:
        return ""
    return "forward" if np.sign(sense) == np.sign(speed) else "backward"


def _campbell(speeds, per_speed: list[dict], pair, track: str, joint: str, residual: float) -> Campbell:
    """Assembles a :class:`Campbell`, assigning each speed's modes to columns (by MAC and
    frequency from the previous speed, or by frequency order)."""
    from scipy.optimize import linear_sum_assignment

    ns, nc = len(speeds), max((len(m["lam"]) for m in per_speed), default=0)
    lam = np.full((ns, nc), np.nan + 0j)
    whirl = np.full((ns, nc), "", dtype=object)
    last: list = [None] * nc
    for k, m in enumerate(per_speed):
        cur = m["lam"]
        if track == "order" or k == 0:
            cols = np.arange(len(cur))
        else:
            fscale = max(float(np.nanmax(np.abs(lam[:k]))), 1e-300) if k else 1.0
            cost = np.full((len(cur), nc), 3.0)
            for i in range(len(cur)):
                for c in range(nc):
                    if last[c] is not None:
                        cost[i, c] = 1.0 - _mac(m["shapes"][:, i], last[c][0]) + 0.1 * abs(abs(cur[i]) - abs(last[c][1])) / fscale
            rows, cols_ = linear_sum_assignment(cost)
            cols = np.empty(len(cur), dtype=int)
            cols[rows] = cols_
        for i, c in enumerate(cols):
            lam[k, c] = cur[i]
            last[c] = (m["shapes"][:, i], cur[i])
            whirl[k, c] = _whirl(m["shapes"][:, i], pair, float(speeds[k]), complex(cur[i]))
    with np.errstate(invalid="ignore", divide="ignore"):
        wn = np.abs(lam)
        zeta = np.where(wn > 0, -lam.real / wn, np.nan)
    return Campbell(np.asarray(speeds, dtype=float), np.abs(lam.imag) / (2 * np.pi), wn / (2 * np.pi), zeta,
                    whirl.astype(str), joint, residual)


# ---- eigenvalues over a parameter ----------------------------------------------------------------


@dataclass(frozen=True)
class Sweep:
    """Eigenvalues of a model linearized at each value of a parameter (a speed, a load), each
    column one eigenvalue followed across the values (both of each complex pair, so a pair that
    splits into two real ones stays two continuous columns)."""

    values: np.ndarray
    #: eigenvalues (n_values x n_modes), 1/s
    eigenvalues: np.ndarray
    #: the parameter's name (for plots)
    parameter: str = "parameter"

    @property
    def stable(self) -> np.ndarray:
        """Whether every eigenvalue has Re <= 0 (to round-off) at each value."""
        lam = self.eigenvalues
        scale = 1.0 + np.nanmax(np.abs(lam), axis=1)
        return np.all(np.nan_to_num(lam.real, nan=-1.0) <= 1e-9 * scale[:, None], axis=1)

    def stable_ranges(self) -> list[tuple[float, float]]:
        """The intervals of values with a stable linearization, their ends interpolated where a
        real part crosses zero."""
        out, start = [], None
        st = self.stable
        for k, s in enumerate(st):
            if s and start is None:
                start = self.values[0] if k == 0 else self._crossing(k - 1)
            if not s and start is not None:
                out.append((float(start), float(self._crossing(k - 1))))
                start = None
        if start is not None:
            out.append((float(start), float(self.values[-1])))
        return out

    def _crossing(self, k: int) -> float:
        """Where the largest real part crosses zero between values k and k + 1."""
        a = np.nanmax(self.eigenvalues[k].real)
        b = np.nanmax(self.eigenvalues[k + 1].real)
        if a == b or a * b > 0:
            return float(0.5 * (self.values[k] + self.values[k + 1]))
        return float(self.values[k] + a / (a - b) * (self.values[k + 1] - self.values[k]))

    def plot(self, out=None, title: str | None = None, imaginary: bool = True):
        """Real parts (solid) and, with ``imaginary``, imaginary parts (dashed, the oscillation's
        angular frequency) against the parameter, the stable ranges shaded. Saved to ``out`` if
        given; returns the Figure."""
        fig = _figure(out, (7.5, 5.0))
        ax = fig.subplots()
        for a, b in self.stable_ranges():
            ax.axvspan(a, b, color="C2", alpha=0.12, lw=0)
        for c in range(self.eigenvalues.shape[1]):
            lam = self.eigenvalues[:, c]
            ax.plot(self.values, lam.real, "-", color=f"C{c % 10}", lw=1.6)
            if imaginary and np.nanmax(lam.imag, initial=0.0) > 0:
                ax.plot(self.values, np.where(lam.imag > 0, lam.imag, np.nan), "--", color=f"C{c % 10}", lw=1.0)
        ax.axhline(0.0, color="k", lw=0.8)
        from matplotlib.lines import Line2D
        from matplotlib.patches import Patch

        handles = [Line2D([], [], color="k", ls="-", label="Re(lambda)"), Patch(color="C2", alpha=0.25, label="stable")]
        if imaginary:
            handles.insert(1, Line2D([], [], color="k", ls="--", label="Im(lambda) > 0"))
        ax.legend(handles=handles, fontsize="small", loc="best", framealpha=0.8)
        ax.set_xlabel(self.parameter)
        ax.set_ylabel("eigenvalue [1/s]")
        ax.grid(True, alpha=0.3)
        ax.set_title(title or f"eigenvalues against {self.parameter}")
        return _save(fig, out)


def sweep(model, values, speed: str | None = None, free=(), coordinates=None, method: str = "auto",
          parameter: str | None = None, rigid_tol: float = 1e-9) -> Sweep:
    """Eigenvalues of the linearization at each of ``values``, followed from value to value.

    ``model`` is a :class:`mechsys.Model` whose speed ``speed`` (a joint velocity name with a
    prime, ``"rear_hub'"``, or a coordinate name) is set to each value, the steady motion then
    found by :func:`steady_motion` (``free`` as there; the speeds the constraints determine
    follow), or a function ``value -> Model`` built at its point. Eigenvalues with |lambda| below
    ``rigid_tol`` times the largest at every value (cyclic and conserved directions) are left out.
    ``Sweep.plot()`` draws them with the stable ranges shaded."""
    vals = np.atleast_1d(np.asarray(values, dtype=float)).reshape(-1)
    if vals.size == 0 or not np.all(np.isfinite(vals)):
        raise SettingsError("sweep: values must be finite numbers")
    per = []
    for v in vals:
        if callable(model) and not isinstance(model, Model):
            m = model(float(v))
            if not isinstance(m, Model):
                raise SettingsError(f"sweep: the builder returned {type(m).__name__} for {v:g}, expected a mechsys.Model")
            lin = linearize(m, operating_point=True, method=method, coordinates=coordinates)
        elif isinstance(model, Model):
            if speed is None:
                raise SettingsError("sweep: name the swept speed or coordinate (speed=\"joint'\"), or pass a builder")
            st = steady_motion(model, free=free, fixed={speed: float(v)})
            lin = linearize(model, at=st, operating_point=True, method=method, coordinates=coordinates)
        else:
            raise SettingsError(f"sweep: expected a mechsys.Model or a function value -> Model, got {type(model).__name__}")
        per.append(np.linalg.eigvals(lin.state_matrix()))
    big = max((float(np.abs(p).max(initial=0.0)) for p in per), default=0.0)
    per = [p[np.abs(p) > rigid_tol * big] for p in per]
    n = max((p.size for p in per), default=0)
    lam = np.full((vals.size, n), np.nan + 0j)
    from scipy.optimize import linear_sum_assignment

    for k, p in enumerate(per):
        if k == 0 or not np.any(np.isfinite(lam[k - 1])):
            lam[k, : p.size] = p
            continue
        prev = lam[k - 1]
        cost = np.abs(p[:, None] - np.where(np.isfinite(prev), prev, 1e300)[None, :])
        rows, cols = linear_sum_assignment(np.minimum(cost, 1e300))
        lam[k, cols] = p[rows]
    return Sweep(vals, lam, parameter or (speed or "parameter"))


# ---- hysteresis (section 2.6.3) ------------------------------------------------------------------


@dataclass(frozen=True)
class Hysteresis:
    """The force-displacement loop of the last whole cycle(s) of a periodic steady state, its
    dissipated work per cycle W_D (eq. 2.213) and the equivalent linear element of equal loop
    area (Fig. 2.37): F ~ F_m + k_eq (x - x_m) + d_eq x'."""

    #: time, displacement and force samples of the analysed cycles (the loop)
    t: np.ndarray
    x: np.ndarray
    force: np.ndarray
    #: work dissipated per cycle W_D = sign * closed integral F dx / cycles (J, or N m per rad ...)
    work: float
    #: amplitude of the displacement's fundamental harmonic x_a
    amplitude: float
    #: half the displacement's peak-to-peak range
    peak: float
    #: angular frequency 2 pi / period (rad/s) and the period (s)
    omega: float
    period: float
    #: equivalent viscous damping by equal loop area d_eq = W_D / (pi omega x_a^2)
    d_eq: float
    #: equivalent stiffness: in-phase part of the force's fundamental over x_a
    k_eq: float
    #: mean displacement and force over the cycles
    x_mean: float
    force_mean: float
    cycles: int = 1

    @property
    def loss_factor(self) -> float:
        """W_D / (pi k_eq x_a^2) = d_eq omega / k_eq (NaN without stiffness)."""
        return float(self.d_eq * self.omega / self.k_eq) if self.k_eq != 0 else float("nan")

    def ellipse(self, n: int = 361) -> tuple[np.ndarray, np.ndarray]:
        """The loop of the equivalent linear element under x = x_m + x_a sin(theta): the ellipse
        enclosing the same area W_D (Fig. 2.37, left)."""
        th = np.linspace(0.0, 2 * np.pi, n)
        x = self.x_mean + self.amplitude * np.sin(th)
        f = self.force_mean + self.k_eq * self.amplitude * np.sin(th) + self.d_eq * self.omega * self.amplitude * np.cos(th)
        return x, f

    def plot(self, out=None, title: str | None = None, xlabel: str = "displacement", ylabel: str = "force"):
        """The loop and its equivalent ellipse (equal area); saved to ``out`` if given."""
        fig = _figure(out, (6.0, 5.0))
        ax = fig.subplots()
        ax.plot(self.x, self.force, lw=1.6, label=f"loop, W_D = {self.work:.4g} per cycle")
        ex, ef = self.ellipse()
        ax.plot(ex, ef, "--", lw=1.2, color="C3", label=f"equal area: k_eq = {self.k_eq:.4g}, d_eq = {self.d_eq:.4g}")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small", loc="upper left", framealpha=0.8)
        ax.set_title(title or f"hysteresis, omega = {self.omega:.4g} rad/s, x_a = {self.amplitude:.4g}")
        return _save(fig, out)


def hysteresis(t, displacement, force, period: float | None = None, cycles: int = 1, sign: float = 1.0) -> Hysteresis:
    """Hysteresis analysis of a periodic steady state: the last ``cycles`` whole periods of the
    signals ``displacement`` x(t) and ``force`` F(t) (e.g. ``res["force/<e>/deflection"]`` and
    ``res["force/<e>/force"]``).

    Sign convention: ``force`` is the force the element exerts *against* its displacement (the
    force it carries along its deflection, as the ``force/<e>/force`` signals), so that
    W_D = closed integral F dx > 0 for a dissipating element; pass ``sign=-1`` for the force the
    element exerts on the moving side. ``period``: known period (s); by default it is found from
    the spacing of the last upward mean crossings of x (give it for noisy or multi-harmonic x).

    W_D uses the trapezoidal rule on F dx (error about (2 pi / samples per cycle)^2 / 6 relative);
    the amplitude x_a and k_eq are the fundamental harmonics' least-squares fit; d_eq = W_D /
    (pi omega x_a^2) is the viscous damper with the same loop area (Fig. 2.37)."""
    tt, x, f = _signals(t, displacement, force)
    if sign not in (1, -1, 1.0, -1.0):
        raise SettingsError(f"hysteresis: sign must be +1 or -1, got {sign!r}")
    if not (isinstance(cycles, (int, np.integer)) and cycles >= 1):
        raise SettingsError(f"hysteresis: cycles must be an integer >= 1, got {cycles!r}")
    T = _period(tt, x) if period is None else float(period)
    if not (np.isfinite(T) and T > 0):
        raise SettingsError(f"hysteresis: period must be > 0 (s), got {period!r}")
    ta = tt[-1] - cycles * T
    if ta < tt[0] - 1e-12 * T:
        raise SettingsError(f"hysteresis: the signals span {tt[-1] - tt[0]:.6g} s, less than {cycles} period(s) of {T:.6g} s")
    inside = tt > ta
    wt = np.concatenate([[ta], tt[inside]])
    wx = np.concatenate([[np.interp(ta, tt, x)], x[inside]])
    wf = np.concatenate([[np.interp(ta, tt, f)], f[inside]])
    work = float(sign * np.sum(0.5 * (wf[1:] + wf[:-1]) * np.diff(wx)) / cycles)
    omega = 2 * np.pi / T
    xm, xc, xs = _fundamental(wt, wx, omega)
    fm, fc, fs = _fundamental(wt, wf, omega)
    # phasors X = xc - j xs, F = fc - j fs of x = Re(X e^(j omega t)); k* = F / X
    amp = float(np.hypot(xc, xs))
    kstar = sign * complex(fc, -fs) / complex(xc, -xs) if amp > 0 else complex("nan")
    d_eq = work / (np.pi * omega * amp * amp) if amp > 0 else float("nan")
    return Hysteresis(wt, wx, wf, work, amp, float(0.5 * np.ptp(wx)), float(omega), float(T), float(d_eq),
                      float(kstar.real), float(xm), float(fm), int(cycles))


def _signals(t, x, f) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    arrs = []
    for name, a in (("t", t), ("displacement", x), ("force", f)):
        try:
            v = np.asarray(a, dtype=float)
        except (TypeError, ValueError):
            raise SettingsError(f"hysteresis: {name}: expected an array of numbers") from None
        if v.ndim != 1:
            raise SettingsError(f"hysteresis: {name}: expected a 1-D signal, got shape {v.shape} (pick one component)")
        if not np.all(np.isfinite(v)):
            raise SettingsError(f"hysteresis: {name}: contains NaN or infinite values")
        arrs.append(v)
    tt, xx, ff = arrs
    if not (tt.size == xx.size == ff.size) or tt.size < 8:
        raise SettingsError(f"hysteresis: t, displacement, force need the same length (>= 8), got {tt.size}, {xx.size}, {ff.size}")
    if np.any(np.diff(tt) <= 0):
        raise SettingsError("hysteresis: t must be increasing")
    return tt, xx, ff


def _period(t: np.ndarray, x: np.ndarray) -> float:
    """Period from the last upward crossings of x through its mean over the second half."""
    xm = x - x[t >= 0.5 * (t[0] + t[-1])].mean()
    k = np.nonzero((xm[:-1] < 0) & (xm[1:] >= 0))[0]
    if k.size < 3:
        raise SettingsError("hysteresis: cannot find the period (fewer than 3 crossings of the mean); pass period=")
    tc = t[k] - xm[k] * (t[k + 1] - t[k]) / (xm[k + 1] - xm[k])
    tc = tc[-6:]
    return float((tc[-1] - tc[0]) / (tc.size - 1))


def _fundamental(t: np.ndarray, y: np.ndarray, omega: float) -> tuple[float, float, float]:
    """Least-squares mean, cosine and sine amplitudes of y ~ m + c cos(omega t) + s sin(omega t)."""
    a = np.column_stack([np.ones_like(t), np.cos(omega * t), np.sin(omega * t)])
    m, c, s = np.linalg.lstsq(a, y, rcond=None)[0]
    return float(m), float(c), float(s)


# ---- plots ---------------------------------------------------------------------------------------


def _figure(out, size):
    """A matplotlib Figure: Agg canvas when saving or headless (as mechsys.plotting)."""
    from .plotting import FORMATS, _headless

    if out is not None and Path(out).suffix.lower() not in FORMATS:
        raise SettingsError(f"plot: cannot write {out} ('{Path(out).suffix}'); use one of {', '.join(FORMATS)}")
    if out is not None or _headless():
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=size, layout="constrained")
        FigureCanvasAgg(fig)
        return fig
    import matplotlib.pyplot as plt

    return plt.figure(figsize=size, layout="constrained")


def _save(fig, out):
    if out is not None:
        from .files import write_atomically

        path = Path(out)
        write_atomically(path, lambda tmp: fig.savefig(tmp, dpi=150, format=path.suffix.lower()[1:]))
    return fig


def bode(lin: LinearModel, frequencies, input=0, output=0, out=None, title: str | None = None):
    """Bode plot of H(j w) (eq. 2.205) from generalized force ``input`` to coordinate ``output``
    (names or indices): magnitude (log-log) and phase (degrees) against frequency (Hz), the
    natural frequencies marked. Saved to ``out`` if given; returns the Figure."""
    f = np.atleast_1d(np.asarray(frequencies, dtype=float))
    h = lin.frf(f, inputs=[input], outputs=[output])[:, 0, 0]
    i, o = lin.names[lin._index(input, "inputs")], lin.names[lin._index(output, "outputs")]
    fig = _figure(out, (7.5, 5.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.loglog(f, np.abs(h), lw=1.5)
    ax2.semilogx(f, np.degrees(np.unwrap(np.angle(h))), lw=1.5)
    for fn in lin.modes().natural_frequency:
        if f.min() <= fn <= f.max():
            for ax in (ax1, ax2):
                ax.axvline(fn, color="0.6", ls=":", lw=1.0)
    ax1.set_ylabel(f"|H| [{o} per unit force on {i}]")
    ax2.set_ylabel("phase [deg]")
    ax2.set_xlabel("frequency [Hz]")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
    ax1.set_title(title or f"frequency response {i} -> {o}")
    return _save(fig, out)


__all__ = ["linearize", "LinearModel", "StateForm", "SteadyMotion", "steady_motion", "Check", "check", "Sweep", "sweep", "Modes", "Campbell", "Hysteresis", "hysteresis", "bode",
           "rayleigh_coefficients", "sdof_frequencies", "sdof_response"]
