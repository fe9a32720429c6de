"""Equations of motion of a model at one state: M(q), h(q, u, t), forward and inverse dynamics,
energies and momenta. Each call runs the Rust algorithms once (CRBA, RNEA, ABA)."""

from __future__ import annotations

import numpy as np

from . import _core
from .errors import SettingsError
from .model import Model


def _arr(x) -> np.ndarray:
    # the engine takes contiguous float64 arrays; convert only when needed (the common case is free)
    if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous:
        return x
    return np.ascontiguousarray(x, dtype=float)


def mass_matrix(model: Model, q, t: float = 0.0) -> np.ndarray:
    """M(q) by the composite-rigid-body algorithm (nu x nu)."""
    core = (model._engine or model.engine())[0]
    try:
        return _core.crba(core, q, t)
    except SettingsError:
        return _core.crba(core, _arr(q), t)


def forward_dynamics(model: Model, q, u, tau=None, t: float = 0.0, out: np.ndarray | None = None) -> np.ndarray:
    """u_dot = M^-1 (h + tau) by the articulated-body algorithm (O(n)).

    The fast path takes float64 numpy arrays as they are; anything else is converted once.
    ``out``: a float64 array of length nu to write the result into (no allocation per call)."""
    core, cbs = model._engine or model.engine()
    try:
        return _core.aba(core, q, u, tau, t, cbs, out)
    except SettingsError:
        # lists, other dtypes, non-contiguous views: convert and try again (real errors re-raise)
        return _core.aba(core, _arr(q), _arr(u), None if tau is None else _arr(tau), t, cbs, out)


def inverse_dynamics(model: Model, q, u, udot, t: float = 0.0) -> np.ndarray:
    """tau = M u_dot - h by the recursive Newton-Euler algorithm: the generalized forces needed,
    beyond the model's own force elements, to produce ``udot``."""
    core, cbs = model.engine()
    return _core.rnea(core, _arr(q), _arr(u), _arr(udot), t, cbs)


def nonlinear_effects(model: Model, q, u, t: float = 0.0) -> np.ndarray:
    """h(q, u, t): gravity, gyroscopic/Coriolis terms and all force elements, with M u_dot = h + tau."""
    core, cbs = model.engine()
    return _core.nonlinear_effects(core, _arr(q), _arr(u), t, cbs)


def energies(model: Model, q, u, t: float = 0.0, point=(0.0, 0.0, 0.0)) -> dict:
    """Energies and momenta (sections 2.3, 2.4): ``kinetic``, ``potential`` (gravity and springs),
    ``kinetic_per_body``, ``gravity_per_body``, ``momentum_linear`` and ``momentum_angular``
    (about the fixed ``point``, inertial components), and their ``*_per_body`` arrays."""
    return _core.energies(model.engine()[0], _arr(q), _arr(u), t, [float(x) for x in point])


def contact_matrices(model: Model, q, u=None, t: float = 0.0) -> dict:
    """The contact quantities of every contact point at one state (sections 2.2.7, 2.5): ``gap``
    (points, m), ``velocity`` (points x 3: g_N', g_T1', g_T2'), the rows ``w`` (points x 3 x nu:
    normal, t1, t2; g' = w u), the Delassus matrix ``delassus`` (3 points square, W^T M~^-1 W with
    the bilateral constraints' reactions: relative acceleration per unit contact force, the matrix
    of the transition and impact problems), ``wbar`` (points x 3, the velocity-product terms) and
    ``free_acceleration`` (points x 3, the relative accelerations without contact forces), and
    ``contact`` (the contact's name per point). Points are ordered as the contacts and their
    candidates; ``u`` defaults to zero."""
    core, callbacks = model.engine()
    u = np.zeros(model.nu) if u is None else u
    return _core.contact_matrices(core, _arr(q), _arr(u), t, callbacks)


aba = forward_dynamics
crba = mass_matrix
rnea = inverse_dynamics

def contact_geometry(model: Model, q) -> dict:
    """The contact geometry of every candidate point of the explicit contacts at ``q``, outside a
    simulation (sections 2.2.7.1, 2.5): ``gap`` (points, m), the witness points ``point1``,
    ``point2`` on the two contours (points x 3, world, m; point1 - point2 = gap * normal), the
    unit ``normal`` from contour 2 towards contour 1 and the tangents ``tangent1``, ``tangent2``,
    and each contour's principal curvatures at its witness point, ``curvature1``, ``curvature2``
    (points x 2, 1/m: convex > 0, hollow < 0; planar contours [kappa, 0]; inf at a point, vertex
    or edge), ``relative_curvature`` (points x 2, 1/m: the principal values of the two curvature
    tensors summed in the tangent plane, Hertz's 2A <= 2B whatever angle the contours' principal
    directions make; inf where either has none), with ``contact`` naming the contact of each point. Unused candidates of a pair
    asked for several points have a gap larger than any real one."""
    core, _ = model.engine()
    return _core.contact_geometry(core, _arr(q))


__all__ = ["contact_geometry", "mass_matrix", "forward_dynamics", "inverse_dynamics", "nonlinear_effects", "energies", "contact_matrices", "aba",
           "crba", "rnea"]
