"""Inertia tensors of homogeneous bodies about their centre of mass, Steiner's theorem and rotation.

All functions return a 3x3 numpy array in kg m^2. Symmetry axes follow the body frame:
rods and cylinders lie along ``axis`` (default x), discs have their normal along ``axis``.
"""

from __future__ import annotations

import numpy as np

from .errors import ModelError

_AXES = {"x": 0, "y": 1, "z": 2}


def _positive(name: str, **values: float) -> None:
    for k, v in values.items():
        if not np.isfinite(v) or v <= 0:
            raise ModelError(f"inertia.{name}: {k} must be > 0, got {v}")


def _axial(axial: float, transverse: float, axis: str) -> np.ndarray:
    if axis not in _AXES:
        raise ModelError(f"inertia: axis must be 'x', 'y' or 'z', got {axis!r}")
    d = np.full(3, transverse, dtype=float)
    d[_AXES[axis]] = axial
    return np.diag(d)


def rod(mass: float, length: float, axis: str = "x") -> np.ndarray:
    """Slender rod of negligible thickness: m l^2 / 12 about the transverse axes, 0 along it.

    The zero axial moment is replaced by a tiny positive value (1e-9 of the transverse one) so
    that the tensor stays positive definite; use :func:`cylinder` for a rod of finite radius.
    """
    _positive("rod", mass=mass, length=length)
    it = mass * length**2 / 12.0
    return _axial(1e-9 * it, it, axis)


def cylinder(mass: float, radius: float, length: float, axis: str = "x") -> np.ndarray:
    """Solid circular cylinder: m r^2/2 about its axis, m(3 r^2 + l^2)/12 about the others."""
    _positive("cylinder", mass=mass, radius=radius, length=length)
    return _axial(0.5 * mass * radius**2, mass * (3 * radius**2 + length**2) / 12.0, axis)


def disc(mass: float, radius: float, axis: str = "z") -> np.ndarray:
    """Thin disc: m r^2/2 about its normal, m r^2/4 about diameters."""
    _positive("disc", mass=mass, radius=radius)
    return _axial(0.5 * mass * radius**2, 0.25 * mass * radius**2, axis)


def box(mass: float, size: tuple[float, float, float]) -> np.ndarray:
    """Solid cuboid with edge lengths (a, b, c) along x, y, z."""
    a, b, c = (float(s) for s in size)
    _positive("box", mass=mass, a=a, b=b, c=c)
    return np.diag([mass * (b * b + c * c), mass * (a * a + c * c), mass * (a * a + b * b)]) / 12.0


def sphere(mass: float, radius: float, hollow: bool = False) -> np.ndarray:
    """Solid (2/5 m r^2) or thin hollow (2/3 m r^2) sphere."""
    _positive("sphere", mass=mass, radius=radius)
    k = 2.0 / 3.0 if hollow else 0.4
    return np.eye(3) * k * mass * radius**2


def ellipsoid(mass: float, semi_axes: tuple[float, float, float]) -> np.ndarray:
    """Solid ellipsoid with semi-axes (a, b, c) along x, y, z: m(b^2 + c^2)/5, ..."""
    a, b, c = (float(s) for s in semi_axes)
    _positive("ellipsoid", mass=mass, a=a, b=b, c=c)
    return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * mass / 5.0


def steiner(inertia_c, mass: float, offset) -> np.ndarray:
    """Inertia about a point displaced by ``offset`` from the centre of mass (parallel axes):
    I_P = I_C + m (|d|^2 E - d d^T)."""
    d = np.asarray(offset, dtype=float).reshape(3)
    return np.asarray(inertia_c, dtype=float) + mass * (d @ d * np.eye(3) - np.outer(d, d))


def rotate(inertia, a_ib) -> np.ndarray:
    """Components of an inertia tensor in another frame: I_I = A_IB I_B A_IB^T."""
    a = np.asarray(a_ib, dtype=float)
    return a @ np.asarray(inertia, dtype=float) @ a.T


def principal(inertia) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (ascending) and axes (columns) of an inertia tensor."""
    w, v = np.linalg.eigh(np.asarray(inertia, dtype=float))
    return w, v


__all__ = ["rod", "cylinder", "disc", "box", "sphere", "ellipsoid", "steiner", "rotate", "principal"]
