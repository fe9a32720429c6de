"""Mechanism analysis: mobility (degrees of freedom left by the constraints, redundant equations)
and Grashof's classification of four-bar linkages."""

from __future__ import annotations

import numpy as np
from scipy.linalg import qr

from . import _core
from .model import Model


def mobility(model: Model, q=None, t: float = 0.0, tol: float = 1e-10) -> dict:
    """Degrees of freedom of a constrained model at configuration ``q`` (default: the model's q0):
    ``dof = nu - rank(G)`` with G = W^T the constraint Jacobian (eq. 2.70). Dependent (redundant)
    constraint equations are found by a rank-revealing QR factorization of G^T and named as
    ``(constraint, component)``; the engine gives them zero multipliers.

    Returns ``{"nu", "nc", "rank", "dof", "redundant": [(name, component), ...], "violation"}``.
    """
    core, callbacks = model.engine()
    qv = np.ascontiguousarray(model.q0() if q is None else q, dtype=float)
    phi, g, _ = _core.constraint_jacobian(core, qv, float(t), callbacks)
    nu, nc = core.nu, core.nc
    rank, redundant = 0, []
    if nc:
        _, r, piv = qr(g.T, mode="economic", pivoting=True)
        d = np.abs(np.diag(r))
        rank = int(np.sum(d > tol * max(d.max(), 1e-300))) if d.size else 0
        rows = {}
        for c in core.constraints():
            for k in range(c["rows"]):
                rows[c["row"] + k] = (c["name"], k)
        redundant = [rows[int(i)] for i in sorted(piv[rank:])]
    return {
        "nu": nu,
        "nc": nc,
        "rank": rank,
        "dof": nu - rank,
        "redundant": redundant,
        "violation": float(np.abs(phi).max()) if nc else 0.0,
    }


def grashof(crank: float, coupler: float, rocker: float, ground: float) -> str:
    """Grashof's classification of a four-bar linkage from its link lengths.

    With s the shortest and l the longest link and p, q the others: s + l < p + q makes at least
    one link fully rotatable (Grashof): a crank-rocker when the shortest link is the crank (next to
    the ground link), a double crank (drag link) when it is the ground link, a double rocker when it
    is the coupler. s + l > p + q gives a triple rocker (non-Grashof); equality a change-point
    mechanism."""
    lengths = {"crank": crank, "coupler": coupler, "rocker": rocker, "ground": ground}
    if any(not np.isfinite(v) or v <= 0 for v in lengths.values()):
        raise ValueError(f"grashof: link lengths must be > 0, got {lengths}")
    vals = sorted(lengths.values())
    s, p, q, l = vals
    lhs, rhs = s + l, p + q
    if np.isclose(lhs, rhs, rtol=1e-12, atol=0.0):
        return "change point"
    if lhs > rhs:
        return "triple rocker (non-Grashof)"
    shortest = min(lengths, key=lengths.get)
    return {
        "crank": "crank-rocker",
        "rocker": "crank-rocker",  # the rotatable link is next to the ground: drive it as the crank
        "ground": "double crank (drag link)",
        "coupler": "double rocker (Grashof)",
    }[shortest]


__all__ = ["mobility", "grashof"]
