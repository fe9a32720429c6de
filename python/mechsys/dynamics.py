"""Equations of motion of a model at one state: M(q), h(q, u, t), forward and inverse dynamics,
energies and momenta. Each call runs the Rust algorithms once (CRBA, RNEA, ABA)."""

from __future__ import annotations

import numpy as np

from . import _core
from .model import Model


def _q(model: Model, q) -> np.ndarray:
    return np.ascontiguousarray(q, dtype=float)


def mass_matrix(model: Model, q, t: float = 0.0) -> np.ndarray:
    """M(q) by the composite-rigid-body algorithm (nu x nu)."""
    return _core.crba(model.build(), _q(model, q), t)


def forward_dynamics(model: Model, q, u, tau=None, t: float = 0.0) -> np.ndarray:
    """u_dot = M^-1 (h + tau) by the articulated-body algorithm (O(n))."""
    core = model.build()
    tau_a = None if tau is None else np.ascontiguousarray(tau, dtype=float)
    return _core.aba(core, _q(model, q), np.ascontiguousarray(u, dtype=float), tau_a, t, model.callbacks or None)


def inverse_dynamics(model: Model, q, u, udot, t: float = 0.0) -> np.ndarray:
    """tau = M u_dot - h by the recursive Newton-Euler algorithm: the generalized forces needed,
    beyond the model's own force elements, to produce ``udot``."""
    core = model.build()
    return _core.rnea(
        core,
        _q(model, q),
        np.ascontiguousarray(u, dtype=float),
        np.ascontiguousarray(udot, dtype=float),
        t,
        model.callbacks or None,
    )


def nonlinear_effects(model: Model, q, u, t: float = 0.0) -> np.ndarray:
    """h(q, u, t): gravity, gyroscopic/Coriolis terms and all force elements, with M u_dot = h + tau."""
    core = model.build()
    return _core.nonlinear_effects(core, _q(model, q), np.ascontiguousarray(u, dtype=float), t, model.callbacks or None)


def energies(model: Model, q, u, t: float = 0.0) -> dict:
    """Kinetic and potential energy, per-body kinetic energy, linear momentum and moment of
    momentum about the inertial origin."""
    return _core.energies(model.build(), _q(model, q), np.ascontiguousarray(u, dtype=float), t)


aba = forward_dynamics
crba = mass_matrix
rnea = inverse_dynamics

__all__ = ["mass_matrix", "forward_dynamics", "inverse_dynamics", "nonlinear_effects", "energies", "aba", "crba", "rnea"]
