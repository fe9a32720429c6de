"""Continuum utilities for small and finite deformations (section 2.2.8, 2.4.3 of the reference).

Notation follows the reference: X is a point of the reference configuration, x = X + u(X) the
deformed one, F = dx/dX = I + H with H = du/dX the displacement gradient (eq. 2.136).

* :func:`deformation_gradient` — F from a displacement field u(X) (4th-order central differences)
  or from its exact gradient; :func:`tet4_deformation_gradient` and
  :func:`hex8_deformation_gradient` from nodal displacements of linear elements.
* :func:`polar_decomposition` — F = R U = V R (eq. 2.137), R proper orthogonal, U and V
  symmetric positive definite; det F > 0 is checked.
* :func:`green_lagrange` — G = ½ (FᵀF − I) (eq. 2.138, written out as eqs. 2.139–2.141);
  :func:`euler_almansi` — e = ½ (I − F⁻ᵀF⁻¹), the spatial counterpart.
* :func:`small_strain` — ε = ½ (H + Hᵀ) and ω = ½ (H − Hᵀ) = φ̃ (eqs. 2.142–2.144);
  :func:`rotation_vector` — φ = ½ curl u = (α, β, γ) (eq. 2.145), the small rotation of eq. 2.134.
* :class:`IsotropicMaterial` / :func:`isotropic` — Hooke's law (eqs. 2.195–2.197) from any two of
  E, ν, G (= Lamé µ), λ, checked; stress, compliance, strain-energy density
  W = ½ σ:ε (eq. 2.194) = [(1+ν) σ_ij σ_ij − ν σ_nn²] / (2E) (eq. 2.199).
* :func:`strain_energy_box`, :func:`strain_energy_beam` — V = ∫ W dV (eqs. 2.194/2.199) by
  Gauss–Legendre quadrature over a box or a prismatic bar with a rectangular or circular section.

The reference writes Poisson's ratio as µ; here it is ``nu`` and µ is Lamé's second constant
(µ = G). All quantities are SI. Errors are :class:`~mechsys.errors.ModelError` naming the item.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .errors import ModelError

__all__ = [
    "deformation_gradient",
    "tet4_deformation_gradient",
    "hex8_deformation_gradient",
    "polar_decomposition",
    "green_lagrange",
    "euler_almansi",
    "small_strain",
    "rotation_vector",
    "skew",
    "IsotropicMaterial",
    "isotropic",
    "strain_energy_box",
    "strain_energy_beam",
    "gauss_legendre",
]


def _matrix3(A, what: str) -> np.ndarray:
    A = np.asarray(A, dtype=float)
    if A.shape != (3, 3):
        raise ModelError(f"{what}: expected a 3x3 matrix, got shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise ModelError(f"{what}: contains non-finite entries {A.tolist()}")
    return A


def skew(v) -> np.ndarray:
    """ṽ, the skew-symmetric matrix with ṽ a = v × a (the tilde of eq. 2.134)."""
    x, y, z = np.asarray(v, dtype=float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


# --------------------------------------------------------------------------------------------
# Deformation gradient
# --------------------------------------------------------------------------------------------


def deformation_gradient(u: Callable, X, *, grad: Callable | None = None, h: float | None = None) -> np.ndarray:
    """F = I + ∂u/∂X at the reference point X (eq. 2.136).

    ``u`` maps a reference point (3,) to its displacement (3,). With ``grad`` (a callable giving
    the 3x3 matrix H_ij = ∂u_i/∂X_j) the gradient is exact; otherwise it is taken by 4th-order
    central differences with step ``h`` (default 1e-3 times max(1, |X|), error O(h⁴)).
    """
    X = np.asarray(X, dtype=float)
    if X.shape != (3,) or not np.all(np.isfinite(X)):
        raise ModelError(f"deformation_gradient: X must be a finite 3-vector, got {X!r}")
    if grad is not None:
        H = _matrix3(grad(X), "deformation_gradient: grad(X)")
        return np.eye(3) + H
    if h is None:
        h = 1e-3 * max(1.0, float(np.linalg.norm(X)))
    if not (np.isfinite(h) and h > 0):
        raise ModelError(f"deformation_gradient: step h must be > 0, got {h}")
    H = np.empty((3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        vals = []
        for k in (-2, -1, 1, 2):
            val = np.asarray(u(X + k * e), dtype=float)
            if val.shape != (3,) or not np.all(np.isfinite(val)):
                raise ModelError(f"deformation_gradient: u({(X + k * e).tolist()}) must be a finite 3-vector, got {val!r}")
            vals.append(val)
        H[:, j] = (vals[0] - 8.0 * vals[1] + 8.0 * vals[2] - vals[3]) / (12.0 * h)
    return np.eye(3) + H


def tet4_deformation_gradient(X_nodes, u_nodes) -> np.ndarray:
    """F of a linear (4-node) tetrahedron, constant over the element.

    With edge matrices D_X = [X1−X0, X2−X0, X3−X0] and D_u likewise, H = D_u D_X⁻¹.
    """
    Xn = np.asarray(X_nodes, dtype=float)
    un = np.asarray(u_nodes, dtype=float)
    for name, a in (("X_nodes", Xn), ("u_nodes", un)):
        if a.shape != (4, 3) or not np.all(np.isfinite(a)):
            raise ModelError(f"tet4_deformation_gradient: {name} must be a finite 4x3 array, got shape {a.shape}")
    DX = (Xn[1:] - Xn[0]).T
    vol6 = np.linalg.det(DX)
    scale = max(np.linalg.norm(DX, axis=0).prod(), 1e-300)
    if abs(vol6) <= 1e-12 * scale:
        raise ModelError(f"tet4_deformation_gradient: X_nodes form a degenerate tetrahedron (6 V = {vol6:.3e})")
    Du = (un[1:] - un[0]).T
    return np.eye(3) + Du @ np.linalg.inv(DX)


# Trilinear hexahedron: node k at natural coordinates _HEX[k] (the usual 1..8 numbering,
# bottom face counter-clockwise, then the top face).
_HEX = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)


def hex8_deformation_gradient(X_nodes, u_nodes, xi=(0.0, 0.0, 0.0)) -> np.ndarray:
    """F of a trilinear (8-node) hexahedron at natural coordinates ``xi`` in [−1, 1]³.

    Nodes are numbered bottom face (ζ = −1) counter-clockwise from (−1, −1), then the top face.
    H = (∂u/∂ξ)(∂X/∂ξ)⁻¹ with N_k = ⅛ (1 + ξ ξ_k)(1 + η η_k)(1 + ζ ζ_k).
    """
    Xn = np.asarray(X_nodes, dtype=float)
    un = np.asarray(u_nodes, dtype=float)
    for name, a in (("X_nodes", Xn), ("u_nodes", un)):
        if a.shape != (8, 3) or not np.all(np.isfinite(a)):
            raise ModelError(f"hex8_deformation_gradient: {name} must be a finite 8x3 array, got shape {a.shape}")
    xi = np.asarray(xi, dtype=float)
    if xi.shape != (3,) or np.any(np.abs(xi) > 1.0):
        raise ModelError(f"hex8_deformation_gradient: xi must lie in [-1, 1]^3, got {xi.tolist()}")
    dN = np.empty((8, 3))
    f = 1.0 + _HEX * xi  # (8, 3)
    for j in range(3):
        others = [k for k in range(3) if k != j]
        dN[:, j] = 0.125 * _HEX[:, j] * f[:, others[0]] * f[:, others[1]]
    J = Xn.T @ dN
    detJ = np.linalg.det(J)
    if detJ <= 0:
        raise ModelError(f"hex8_deformation_gradient: X_nodes give det(dX/dxi) = {detJ:.3e} <= 0 at xi = {xi.tolist()} (inverted or mis-numbered element)")
    return np.eye(3) + (un.T @ dN) @ np.linalg.inv(J)


# --------------------------------------------------------------------------------------------
# Polar decomposition and strain measures
# --------------------------------------------------------------------------------------------


def _checked_F(F, what: str) -> np.ndarray:
    F = _matrix3(F, what)
    d = np.linalg.det(F)
    if not d > 1e-14 * max(1.0, np.abs(F).max() ** 3):
        raise ModelError(f"{what}: det F = {d:.6g} must be > 0 (a deformation cannot invert or collapse material), F = {F.tolist()}")
    return F


def polar_decomposition(F):
    """F = R U = V R (eq. 2.137): returns (R, U, V).

    From the singular value decomposition F = W Σ Zᵀ: R = W Zᵀ (det R = +1 since det F > 0),
    U = Z Σ Zᵀ (right stretch, reference configuration), V = W Σ Wᵀ (left stretch, current
    configuration); U and V share the principal stretches Σ.
    """
    F = _checked_F(F, "polar_decomposition")
    W, s, Zt = np.linalg.svd(F)
    R = W @ Zt  # det R = sign(det F) = +1, the singular values being >= 0
    U = Zt.T @ np.diag(s) @ Zt
    V = W @ np.diag(s) @ W.T
    return R, 0.5 * (U + U.T), 0.5 * (V + V.T)


def green_lagrange(F) -> np.ndarray:
    """Green–Lagrange (Cauchy–Lagrange) strain G = ½ (FᵀF − I), eq. 2.138 (2.139 with F = I + H)."""
    F = _checked_F(F, "green_lagrange")
    return 0.5 * (F.T @ F - np.eye(3))


def euler_almansi(F) -> np.ndarray:
    """Euler–Almansi strain e = ½ (I − F⁻ᵀ F⁻¹) in the current configuration (e = F⁻ᵀ G F⁻¹)."""
    F = _checked_F(F, "euler_almansi")
    Fi = np.linalg.inv(F)
    return 0.5 * (np.eye(3) - Fi.T @ Fi)


def small_strain(H):
    """Split the displacement gradient H = ∂u/∂X into (ε, ω) with ε = ½ (H + Hᵀ) the linear strain
    (eqs. 2.139–2.141 without the quadratic terms) and ω = ½ (H − Hᵀ) = F_skew = φ̃ (eqs. 2.143,
    2.144). Pass H = F − I when you hold F."""
    H = _matrix3(H, "small_strain: H")
    return 0.5 * (H + H.T), 0.5 * (H - H.T)


def rotation_vector(H) -> np.ndarray:
    """φ = (α, β, γ) = ½ curl u (eq. 2.145): the small elastic rotation of eq. 2.134,
    α = ½ (∂w/∂η − ∂v/∂ζ), β = ½ (∂u/∂ζ − ∂w/∂ξ), γ = ½ (∂v/∂ξ − ∂u/∂η)."""
    H = _matrix3(H, "rotation_vector: H")
    return 0.5 * np.array([H[2, 1] - H[1, 2], H[0, 2] - H[2, 0], H[1, 0] - H[0, 1]])


# --------------------------------------------------------------------------------------------
# Isotropic linear elasticity
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class IsotropicMaterial:
    """Isotropic linear-elastic material; build it with :func:`isotropic`.

    E Young's modulus, nu Poisson's ratio (µ in the reference), G shear modulus = Lamé µ,
    lam Lamé λ, K bulk modulus (Pa); density (kg/m³) is optional (0 when not given).
    """

    E: float
    nu: float
    G: float
    lam: float
    K: float
    density: float = 0.0

    @property
    def mu(self) -> float:
        """Lamé's second constant µ (= G)."""
        return self.G

    def stress(self, eps) -> np.ndarray:
        """σ = λ tr(ε) I + 2 µ ε, the inverse of eq. 2.197."""
        eps = _symmetric(eps, "IsotropicMaterial.stress: strain")
        return self.lam * np.trace(eps) * np.eye(3) + 2.0 * self.G * eps

    def strain(self, sigma) -> np.ndarray:
        """ε_ij = [(1 + ν) σ_ij − ν δ_ij σ_nn] / E, eq. 2.197 (eqs. 2.195, 2.196 written out)."""
        sigma = _symmetric(sigma, "IsotropicMaterial.strain: stress")
        return ((1.0 + self.nu) * sigma - self.nu * np.trace(sigma) * np.eye(3)) / self.E

    def energy_density(self, eps) -> np.ndarray:
        """W = ½ σ:ε = ½ (σxx εxx + σyy εyy + σzz εzz + σxy γxy + σyz γyz + σzx γzx), the
        integrand of eq. 2.194 (J/m³)."""
        eps = _symmetric(eps, "IsotropicMaterial.energy_density: strain")
        return 0.5 * float(np.sum(self.stress(eps) * eps))

    def energy_density_from_stress(self, sigma) -> float:
        """W = [(1 + ν) σ_ij σ_ij − ν σ_nn²] / (2E), the integrand of eq. 2.199 (= eq. 2.198)."""
        sigma = _symmetric(sigma, "IsotropicMaterial.energy_density_from_stress: stress")
        return float(((1.0 + self.nu) * np.sum(sigma * sigma) - self.nu * np.trace(sigma) ** 2) / (2.0 * self.E))


def _symmetric(A, what: str) -> np.ndarray:
    A = _matrix3(A, what)
    if np.abs(A - A.T).max() > 1e-12 * max(1.0, np.abs(A).max()):
        raise ModelError(f"{what} must be symmetric, got {A.tolist()}")
    return 0.5 * (A + A.T)


def isotropic(*, E=None, nu=None, G=None, lam=None, mu=None, density: float = 0.0, rtol: float = 1e-6) -> IsotropicMaterial:
    """An isotropic material from any two of E, nu, G (or mu, the same as G), lam.

    Checked: E > 0, G > 0, −1 < ν < 0.5 (so that the bulk modulus K = λ + 2µ/3 > 0), finite
    values; when more than two are given the others must agree to ``rtol``.
    Relations: G = E / (2 (1 + ν)) (reference after eq. 2.197), λ = E ν / ((1 + ν)(1 − 2ν)).
    """
    for k, v in (("G", G), ("mu", mu)):
        if v is not None and not isinstance(v, (int, float, np.integer, np.floating)):
            raise ModelError(f"isotropic: {k} must be a number, got {v!r}")
    if G is not None and mu is not None and not np.isclose(G, mu, rtol=rtol, atol=0):
        raise ModelError(f"isotropic: G = {G} and mu = {mu} are the same constant and differ")
    if G is None:
        G = mu
    given = {k: v for k, v in (("E", E), ("nu", nu), ("G", G), ("lam", lam)) if v is not None}
    for k, v in given.items():
        try:
            if isinstance(v, (str, bytes)):
                raise TypeError
            v = given[k] = float(v)
        except (TypeError, ValueError):
            raise ModelError(f"isotropic: {k} must be a number, got {v!r}") from None
        if not np.isfinite(v):
            raise ModelError(f"isotropic: {k} must be finite, got {v}")
    if not np.isfinite(density) or density < 0:
        raise ModelError(f"isotropic: density must be >= 0, got {density}")
    if len(given) < 2:
        raise ModelError(f"isotropic: give two of E, nu, G (mu), lam; got only {sorted(given) or 'none'}")
    for k in ("E", "G"):
        if k in given and given[k] <= 0:
            raise ModelError(f"isotropic: {k} must be > 0, got {given[k]}")
    if "nu" in given and not (-1.0 < given["nu"] < 0.5):
        raise ModelError(f"isotropic: nu must lie in (-1, 0.5), got {given['nu']}")
    keys = [k for k in ("E", "nu", "G", "lam") if k in given]
    a, b = keys[0], keys[1]
    x, y = given[a], given[b]
    if (a, b) == ("E", "nu"):
        E_, nu_ = x, y
    elif (a, b) == ("E", "G"):
        E_, nu_ = x, x / (2.0 * y) - 1.0
    elif (a, b) == ("E", "lam"):
        r = np.sqrt(x * x + 9.0 * y * y + 2.0 * x * y)
        E_, nu_ = x, 2.0 * y / (x + y + r)
    elif (a, b) == ("nu", "G"):
        E_, nu_ = 2.0 * y * (1.0 + x), x
    elif (a, b) == ("nu", "lam"):
        if x == 0.0:
            raise ModelError("isotropic: nu = 0 and lam fix nothing (lam is then 0); give E or G")
        E_, nu_ = y * (1.0 + x) * (1.0 - 2.0 * x) / x, x
    else:  # G, lam
        if y + x <= 0:
            raise ModelError(f"isotropic: G = {x} and lam = {y} need lam + G > 0 (else nu is outside (-1, 0.5))")
        E_, nu_ = x * (3.0 * y + 2.0 * x) / (y + x), y / (2.0 * (y + x))
    if not (np.isfinite(E_) and E_ > 0):
        raise ModelError(f"isotropic: {a} = {x} and {b} = {y} give E = {E_:.6g}, which must be > 0")
    if not (np.isfinite(nu_) and -1.0 < nu_ < 0.5):
        raise ModelError(f"isotropic: {a} = {x} and {b} = {y} give nu = {nu_:.6g}, which must lie in (-1, 0.5)")
    G_ = E_ / (2.0 * (1.0 + nu_))
    lam_ = E_ * nu_ / ((1.0 + nu_) * (1.0 - 2.0 * nu_))
    derived = {"E": E_, "nu": nu_, "G": G_, "lam": lam_}
    for k in keys[2:]:
        v, w = given[k], derived[k]
        if not np.isclose(v, w, rtol=rtol, atol=rtol * (E_ if k != "nu" else 1.0)):
            raise ModelError(f"isotropic: {k} = {v} is inconsistent with {a} = {x}, {b} = {y} (which give {k} = {w:.9g})")
    return IsotropicMaterial(E=E_, nu=nu_, G=G_, lam=lam_, K=lam_ + 2.0 * G_ / 3.0, density=float(density))


# --------------------------------------------------------------------------------------------
# Strain energy by Gauss quadrature
# --------------------------------------------------------------------------------------------


def gauss_legendre(n: int, a: float, b: float):
    """n-point Gauss–Legendre points and weights on [a, b] (exact for degree 2n − 1)."""
    if int(n) != n or n < 1:
        raise ModelError(f"gauss_legendre: order must be a positive integer, got {n}")
    x, w = np.polynomial.legendre.leggauss(int(n))
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


def _strain_at(strain: Callable, X, what: str) -> np.ndarray:
    eps = np.asarray(strain(X), dtype=float)
    if eps.shape != (3, 3) or not np.all(np.isfinite(eps)):
        raise ModelError(f"{what}: strain({np.asarray(X).tolist()}) must be a finite 3x3 matrix, got {eps!r}")
    return eps


def strain_energy_box(strain: Callable, material: IsotropicMaterial, bounds, order: int = 4) -> float:
    """V = ∫ ½ σ:ε dV over the box bounds = ((x0, x1), (y0, y1), (z0, z1)) (eq. 2.194 / 2.199)
    with an ``order``³-point Gauss–Legendre rule; ``strain(X)`` gives ε (3x3) at X. Exact when
    ε is polynomial of degree ≤ order − 1 in each coordinate."""
    b = np.asarray(bounds, dtype=float)
    if b.shape != (3, 2) or not np.all(np.isfinite(b)) or np.any(b[:, 1] <= b[:, 0]):
        raise ModelError(f"strain_energy_box: bounds must be ((x0, x1), (y0, y1), (z0, z1)) with x0 < x1, got {np.asarray(bounds).tolist()}")
    rules = [gauss_legendre(order, lo, hi) for lo, hi in b]
    total = 0.0
    for x, wx in zip(*rules[0]):
        for y, wy in zip(*rules[1]):
            for z, wz in zip(*rules[2]):
                X = np.array([x, y, z])
                total += wx * wy * wz * material.energy_density(_strain_at(strain, X, "strain_energy_box"))
    return float(total)


def strain_energy_beam(strain: Callable, material: IsotropicMaterial, length: float, section, order: int = 4) -> float:
    """V = ∫₀ᴸ ∫_A ½ σ:ε dA dx for a prismatic bar along x (eq. 2.194 / 2.199).

    ``section`` is ("rect", b, h) — y in [−b/2, b/2], z in [−h/2, h/2] — or ("circle", r), a
    full disc integrated with Gauss–Legendre in radius and angle. ``strain(X)`` gives ε at X.
    """
    if not (np.isfinite(length) and length > 0):
        raise ModelError(f"strain_energy_beam: length must be > 0, got {length}")
    kind = section[0] if isinstance(section, (tuple, list)) and section else None
    if kind == "rect" and len(section) == 3 and all(np.isfinite(s) and s > 0 for s in section[1:]):
        b, h = section[1], section[2]
        return strain_energy_box(strain, material, ((0.0, length), (-b / 2, b / 2), (-h / 2, h / 2)), order)
    if kind == "circle" and len(section) == 2 and np.isfinite(section[1]) and section[1] > 0:
        r0 = section[1]
        xs, wxs = gauss_legendre(order, 0.0, length)
        rs, wrs = gauss_legendre(order, 0.0, r0)
        nt = 2 * order + 2  # uniform rule in angle: exact for trigonometric degree < nt
        ts, wts = 2 * np.pi * np.arange(nt) / nt, np.full(nt, 2 * np.pi / nt)
        total = 0.0
        for x, wx in zip(xs, wxs):
            for r, wr in zip(rs, wrs):
                for t, wt in zip(ts, wts):
                    X = np.array([x, r * np.cos(t), r * np.sin(t)])
                    total += wx * wr * wt * r * material.energy_density(_strain_at(strain, X, "strain_energy_beam"))
        return float(total)
    raise ModelError(f"strain_energy_beam: section must be ('rect', b, h) or ('circle', r) with positive sizes, got {section!r}")
