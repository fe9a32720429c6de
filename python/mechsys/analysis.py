"""Analyses of constrained mechanisms without time integration: assembly (consistent initial
states), kinematic analysis of fully driven mechanisms, and static equilibrium.

All three work on the constraint equations Phi(q, t) = 0, G u = b, G u' = gamma (eq. 2.70) and
use minimum-norm corrections (the pseudo-inverse of eq. 2.68) so that redundant equations are
harmless.
"""

from __future__ import annotations

from typing import Iterable, Sequence

import numpy as np

from . import _core
from .errors import ModelError, SettingsError, SolverError
from .model import Model


def _free_mask(model: Model, keep: Iterable[str]) -> np.ndarray:
    info = {j["name"]: j for j in model.joint_info()}
    mask = np.ones(model.nu, dtype=bool)
    for name in keep:
        if name not in info:
            raise ModelError(f"keep: unknown joint '{name}' (joints: {', '.join(info)})")
        j = info[name]
        mask[j["iu"] : j["iu"] + j["nu"]] = False
    return mask


def _worst(core, phi: np.ndarray) -> str:
    k = int(np.argmax(np.abs(phi)))
    for c in core.constraints():
        if c["row"] <= k < c["row"] + c["rows"]:
            return c["name"]
    return "?"


def assemble(
    model: Model, q=None, u=None, t: float = 0.0, keep: Sequence[str] = (), tol: float = 1e-12, max_iter: int = 50
) -> tuple[np.ndarray, np.ndarray]:
    """A consistent state near (q, u): Newton on Phi(q, t) = 0 with minimum-norm steps over the
    coordinates of all joints not named in ``keep``, then the velocities projected onto
    G u = b the same way. Raises SolverError naming the constraint that cannot be closed."""
    core, callbacks = model.engine()
    q = model.state_vector(q, "q").astype(float)
    u = model.state_vector(u, "u").astype(float)
    free = _free_mask(model, keep)
    if core.nc == 0:
        return q, u
    for _ in range(max_iter):
        phi, g, b = _core.constraint_jacobian(core, q, t, callbacks)
        if np.abs(phi).max() <= tol:
            break
        du = np.zeros(core.nu)
        du[free] = -np.linalg.lstsq(g[:, free], phi, rcond=1e-12)[0]
        q = core.integrate(q, du, 1.0)
    else:
        raise SolverError(
            f"assembly: constraint '{_worst(core, phi)}' cannot be closed (violation {np.abs(phi).max():.3e})"
            + (f" with joints {list(keep)} kept" if keep else "")
        )
    phi, g, b = _core.constraint_jacobian(core, q, t, callbacks)
    r = g @ u - b
    u = u.copy()
    u[free] -= np.linalg.lstsq(g[:, free], r, rcond=1e-12)[0]
    res = np.abs(g @ u - b).max()
    if res > 1e-9 * max(1.0, np.abs(u).max()):
        raise SolverError(f"assembly: velocities of the kept joints {list(keep)} violate constraint '{_worst(core, g @ u - b)}'")
    return q, u


def kinematic_analysis(model: Model, t: Sequence[float], q=None) -> dict[str, np.ndarray]:
    """Positions, velocities and accelerations of a fully driven mechanism (no degree of freedom
    left) at the times ``t``, from the constraints alone: Phi = 0 by Newton (continuing from the
    previous time), G u = b, G u' = gamma. Returns ``{"t", "q", "u", "udot"}`` (rows per time)."""
    from .mechanisms import mobility

    core, callbacks = model.engine()
    ts = np.asarray(t, dtype=float).reshape(-1)
    qk = model.state_vector(q, "q").astype(float)
    mob = mobility(model, qk, float(ts[0]) if ts.size else 0.0)
    if mob["dof"] != 0:
        raise ModelError(
            f"kinematic analysis needs a fully driven mechanism; {mob['dof']} degree(s) of freedom are left (add drives)"
        )
    out_q, out_u, out_a = [], [], []
    for tk in ts:
        qk, _ = assemble(model, qk, np.zeros(core.nu), float(tk))
        _, g, b = _core.constraint_jacobian(core, qk, float(tk), callbacks)
        uk = np.linalg.lstsq(g, b, rcond=1e-12)[0]
        gamma = _core.constraint_gamma(core, qk, uk, float(tk), callbacks)
        ak = np.linalg.lstsq(g, gamma, rcond=1e-12)[0]
        out_q.append(qk)
        out_u.append(uk)
        out_a.append(ak)
    return {"t": ts, "q": np.array(out_q), "u": np.array(out_u), "udot": np.array(out_a)}


def static_equilibrium(model: Model, q=None, t: float = 0.0, tol: float = 1e-10, max_iter: int = 50,
                       contacts: str = "ignore") -> dict:
    """Static equilibrium of a constrained model at time t: h(q, 0, t) + G(q)^T lambda = 0 with
    Phi(q, t) = 0, by Newton with a finite-difference stiffness in the velocity coordinates.
    Returns ``{"q", "lambda": {constraint: multipliers}, "residual"}``; the multiplier of a
    driving constraint is the force or torque the drive must supply (virtual work).

    ``contacts``: ``"ignore"`` (unilateral contacts exert nothing), or ``"hold"``/``"roll"``: the
    contacts closed at the start q are held closed (sliding freely, or rolling without slip) and
    their forces come back in ``lambda`` under their names (normal, then tangential); a held
    contact that would have to pull in the equilibrium found (it opens there) or, rolling, slip
    is a SolverError naming it."""
    held = {}
    if contacts != "ignore":
        if contacts not in ("hold", "roll"):
            raise SettingsError(f"static equilibrium: contacts: expected 'ignore', 'hold' or 'roll', got {contacts!r}")
        from .linear import _held_model

        q_start, _ = assemble(model, q, None, t)
        model, held = _held_model(model, q_start, np.zeros(model.nu), t, contacts)
    core, callbacks = model.engine()
    qk, _ = assemble(model, q, None, t)
    nu, nc = core.nu, core.nc
    zero = np.zeros(nu)
    lam = np.zeros(nc)

    def h_of(qv):
        return _core.nonlinear_effects(core, qv, zero, t, callbacks)

    def overlaps(qv):
        return _core.compliant_overlaps(core, qv, t, callbacks)

    # the residual's scale: the forces at the start (at an equilibrium h is only the imbalance,
    # and a stiff contact's round-off alone is k eps |q|)
    scale, floor = 1.0, 0.0
    for _ in range(max_iter):
        h = h_of(qk)
        scale = max(scale, float(np.abs(h).max(initial=0.0)))
        phi, g, _ = _core.constraint_jacobian(core, qk, t, callbacks)
        f = np.concatenate([h + g.T @ lam, phi])
        # (floor: what round-off in q alone leaves of the residual through the stiffness K of the
        # last iterate, e.g. 4e-7 N on a 1e9 N/m contact at |q| = 0.45 m)
        if np.abs(f).max() <= max(tol * scale, floor):
            break
        # d/d(du) of h + G^T lambda by central differences on the configuration manifold; along a
        # direction that moves a compliant contact's point the step is shortened (as in the
        # linearization's differences) so that it does not reach across the contact law's kink
        # at zero overlap: a stiff contact overlaps by less than 1e-7 m
        kmat = np.zeros((nu, nu))
        at = overlaps(qk)
        for i in range(nu):
            eps = 1e-7
            for _pass in range(2):
                e = np.zeros(nu)
                e[i] = eps
                qp, qm = core.integrate(qk, e, 1.0), core.integrate(qk, -e, 1.0)
                shorter = _core.difference_step(at, overlaps(qp), overlaps(qm), eps) if at else eps
                if shorter >= eps:
                    break
                eps = shorter
            _, gp, _ = _core.constraint_jacobian(core, qp, t, callbacks)
            _, gm, _ = _core.constraint_jacobian(core, qm, t, callbacks)
            kmat[:, i] = ((h_of(qp) + gp.T @ lam) - (h_of(qm) + gm.T @ lam)) / (2 * eps)
        floor = 64 * np.finfo(float).eps * float(np.abs(kmat).max(initial=0.0)) * max(1.0, float(np.abs(qk).max()))
        jac = np.block([[kmat, g.T], [g, np.zeros((nc, nc))]])
        step = np.linalg.lstsq(jac, -f, rcond=1e-12)[0]
        norm_f = np.linalg.norm(f)
        q_new, lam_new = qk, lam
        # Newton with halving while the residual does not fall
        for _half in range(6):
            q_try, lam_try = core.integrate(qk, step[:nu], 1.0), lam + step[nu:]
            phi_t, g_t, _ = _core.constraint_jacobian(core, q_try, t, callbacks)
            if np.linalg.norm(np.concatenate([h_of(q_try) + g_t.T @ lam_try, phi_t])) < norm_f:
                q_new, lam_new = q_try, lam_try
                break
            step = step / 2
        else:
            # no descent: a stationary point of the residual that is no equilibrium (a pendulum
            # held level: its stiffness vanishes there). Step downhill along the applied forces
            # -h, within the constraints' tangent space, by at most 0.2 (rad or m).
            down = -(h + g.T @ lam)
            if nc:
                basis = np.linalg.svd(g)[2][np.linalg.matrix_rank(g):].T if g.size else np.eye(nu)
                down = basis @ (basis.T @ down)
            q_new = core.integrate(qk, down * (0.2 / max(np.abs(down).max(), 1e-300)), 1.0)
        qk, lam = q_new, lam_new
    else:
        raise SolverError(f"static equilibrium: Newton did not converge (residual {np.abs(f).max():.3e})")
    names = {c["name"]: lam[c["row"] : c["row"] + c["rows"]].copy() for c in core.constraints()}
    for name, mu in held.items():
        lam_c = names[name]
        if isinstance(mu, tuple):
            # rolling on a compliant layer: the layer carries the normal force, the rows are the
            # tangential forces
            from .linear import _layer_force

            lam_n = _layer_force(mu, qk, zero, t)
            if np.linalg.norm(lam_c) > mu[0] * lam_n * (1 + 1e-12):
                raise SolverError(f"static equilibrium: contact '{mu[2]}' would need a friction force "
                                  f"{np.linalg.norm(lam_c):.4g} N, more than mu0 x its layer's normal force "
                                  f"({mu[0]:.3g} x {lam_n:.4g} N): it slips")
            continue
        if lam_c[0] <= 0.0:
            raise SolverError(f"static equilibrium: contact '{name}' would have to pull (normal force {lam_c[0]:.4g} N) "
                              "in the equilibrium found: it opens there")
        if contacts == "roll" and np.linalg.norm(lam_c[1:]) > mu * lam_c[0] * (1 + 1e-12):
            raise SolverError(f"static equilibrium: contact '{name}' would need a friction force "
                              f"{np.linalg.norm(lam_c[1:]):.4g} N, more than mu0 x normal force ({mu:.3g} x {lam_c[0]:.4g} N): "
                              "it slips")
    return {"q": qk, "lambda": names, "residual": float(np.abs(f).max())}




def system_jacobian(model: Model, q) -> np.ndarray:
    """The Jacobian J = dz/dq-dot of the system coordinates z (each body's origin velocity and
    angular velocity, inertial components, stacked per body: 6 n rows) with respect to the
    generalized velocities u, so that z-dot = J u (eqs. 2.63, 2.64, 2.69)."""
    core, _ = model.engine()
    qv = np.ascontiguousarray(q, dtype=float)
    blocks = []
    for name in core.body_names[1:]:
        jt, jr = _core.point_jacobian(core, qv, name, [0.0, 0.0, 0.0])
        blocks += [np.asarray(jt), np.asarray(jr)]
    return np.vstack(blocks) if blocks else np.zeros((0, core.nu))


def velocities_from_system(model: Model, q, zdot) -> np.ndarray:
    """Generalized velocities from system velocities by the pseudo-inverse relation
    u = (J^T J)^-1 J^T z-dot (eq. 2.68), the least-squares fit when z-dot is not exactly compatible."""
    j = system_jacobian(model, q)
    return np.linalg.lstsq(j, np.asarray(zdot, dtype=float).reshape(-1), rcond=1e-12)[0]


def coordinate_partitioning(model: Model, q=None, t: float = 0.0, tol: float = 1e-10) -> dict:
    """Splits the velocities into dependent and independent ones by pivoting on the constraint
    Jacobian G (QR with column pivoting): the dependent velocities are the pivot columns, the
    others can be chosen freely. Returns ``{"independent", "dependent"}`` as lists of
    ``(joint, component)`` and ``velocity_map`` V (nu x dof) with u = V u_independent, G V = 0."""
    from scipy.linalg import qr

    core, callbacks = model.engine()
    qv = np.ascontiguousarray(model.q0() if q is None else q, dtype=float)
    _, g, _ = _core.constraint_jacobian(core, qv, float(t), callbacks)
    nu = core.nu
    names = []
    for j in core.joints():
        names += [(j["name"], k) for k in range(j["nu"])]
    if core.nc == 0:
        return {"independent": names, "dependent": [], "velocity_map": np.eye(nu)}
    _, r, piv = qr(g, mode="economic", pivoting=True)
    d = np.abs(np.diag(r))
    rank = int(np.sum(d > tol * max(d.max(), 1e-300))) if d.size else 0
    dep, ind = np.sort(piv[:rank]), np.sort(piv[rank:])
    # G_d u_d + G_i u_i = 0 -> u_d = -G_d^+ G_i u_i
    vmap = np.zeros((nu, ind.size))
    vmap[ind, np.arange(ind.size)] = 1.0
    vmap[dep, :] = -np.linalg.lstsq(g[:, dep], g[:, ind], rcond=1e-12)[0]
    return {"independent": [names[i] for i in ind], "dependent": [names[i] for i in dep], "velocity_map": vmap}


def period(t, x, level: float | None = 0.0) -> float:
    """The mean period of an oscillating signal ``x(t)`` from its downward crossings of ``level``
    (0 by default; ``None``: the middle of its range), each located by linear interpolation
    between samples. A SettingsError when there are fewer than two crossings."""
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    if t.shape != x.shape or t.ndim != 1:
        raise SettingsError(f"period: t and x must be 1-D arrays of one length, got shapes {t.shape} and {x.shape}")
    y = x - (0.5 * (x.max() + x.min()) if level is None else float(level))
    k = np.where((y[:-1] > 0) & (y[1:] <= 0))[0]
    if k.size < 2:
        raise SettingsError(f"period: {k.size} downward crossing(s) of the level in the signal; need at least 2")
    tc = t[k] + (t[k + 1] - t[k]) * y[k] / (y[k] - y[k + 1])
    return float(np.diff(tc).mean())


__all__ = ["assemble", "kinematic_analysis", "static_equilibrium", "system_jacobian", "velocities_from_system",
           "coordinate_partitioning", "period"]
