"""Hertz post-processing of rigid impacts (section 2.5.4: simulate non-smooth, then resolve the
selected impacts into forces, durations and pressures whose impulses match the rigid run).

An impact of a rigid run changes the approach speed v of a contact point by an impulse; seen
through the contact's effective mass m = 1 / (w_N^T M~^-1 w_N) (the Delassus entry of that
point) and a Hertz law F = K delta^(3/2) of the two contours' materials and curvatures there, the
same impact resolved elastically reaches

- the maximum approach delta_max = (5 m v^2 / (4 K))^(2/5),
- the peak force F_max = K delta_max^(3/2),
- the duration T = c delta_max / v with c = (4/5) sqrt(pi) Gamma(2/5) / Gamma(9/10) = 2.94325...,
- the contact ellipse (semi-axes a >= b; a circle of radius a for spheres) and the peak pressure
  p0 = 3 F_max / (2 pi a b) at that force (Hertz's elliptic-integral solution).

These are exact for an undamped Hertz contact of a single point (no other force acting during the
impact, which the rigid model assumes anyway); :func:`impact` gives them for one impact,
:func:`impacts` for every impact recorded in ``res.events``, as a table.

>>> row = impact(mass=0.5, speed=1.0, e_star=1.1e11, curvature1=(50.0, 50.0), curvature2=(0.0, 0.0))
>>> round(row["duration"] / row["delta_max"] * row["speed"], 5)
2.94325
"""

from __future__ import annotations

import math

import numpy as np

from . import _core
from .errors import ModelError

#: T v / delta_max of an undamped Hertz impact: 2 * integral of dx / sqrt(1 - x^(5/2)) over [0, 1]
DURATION_FACTOR = 0.8 * math.sqrt(math.pi) * math.gamma(0.4) / math.gamma(0.9)


def effective_modulus(material1, material2) -> float:
    """E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2) of two :class:`mechsys.Material` s (Pa)."""
    return 1.0 / ((1 - material1.nu ** 2) / material1.E + (1 - material2.nu ** 2) / material2.E)


def _curvatures(c1, c2, what: str, angle: float = 0.0) -> tuple[float, float]:
    """The relative principal curvatures A <= B from each contour's (kappa_1, kappa_2), the
    directions of the two kappa_1 crossing at ``angle`` (rad; 0: aligned, exact whatever the angle
    when one side is a sphere or a plane): A + B = (sum of the four)/2 and
    B - A = (1/2) sqrt(g1^2 + g2^2 + 2 g1 g2 cos 2 angle) with g_i = kappa_i1 - kappa_i2."""
    k1, k2 = np.asarray(c1, dtype=float), np.asarray(c2, dtype=float)
    if k1.shape != (2,) or k2.shape != (2,) or not (np.all(np.isfinite(k1)) and np.all(np.isfinite(k2))):
        raise ModelError(f"{what}: Hertz's contact needs finite principal curvatures on both contours (a vertex, edge or "
                         f"point has none), got {k1.tolist()} and {k2.tolist()}")
    if not (isinstance(angle, (int, float, np.floating)) and math.isfinite(angle)):
        raise ModelError(f"{what}: angle must be a finite number (rad), got {angle!r}")
    g1, g2 = k1[0] - k1[1], k2[0] - k2[1]
    half_sum = 0.25 * (k1.sum() + k2.sum())
    half_dif = 0.25 * math.sqrt(max(0.0, g1 * g1 + g2 * g2 + 2 * g1 * g2 * math.cos(2 * angle)))
    s = np.array([half_sum - half_dif, half_sum + half_dif])
    if not s[0] > 0:
        raise ModelError(f"{what}: no Hertz contact: the relative curvature is {s[0]:.4g} 1/m (flat or conforming faces)")
    return float(s[0]), float(s[1])


def impact(mass: float, speed: float, e_star: float, curvature1=(0.0, 0.0), curvature2=(0.0, 0.0),
           angle: float = 0.0) -> dict:
    """The Hertz resolution of one impact: effective ``mass`` (kg), approach ``speed`` (m/s, > 0),
    ``e_star`` (Pa) and each contour's principal curvatures at the contact (1/m; a sphere of radius
    R is (1/R, 1/R), a plane (0, 0), a cylinder (1/R, 0)); ``angle`` (rad) between the directions of
    the two first curvatures (crossed cylinders at 90°: ``angle=pi/2``). Returns ``delta_max`` (m), ``force_max`` (N), ``duration``
    (s), ``a``, ``b`` (m, contact semi-axes at the peak), ``p0`` (Pa), ``stiffness`` (K, N/m^1.5),
    with ``mass`` and ``speed``."""
    for k, v in (("mass", mass), ("speed", speed), ("e_star", e_star)):
        if not (isinstance(v, (int, float, np.floating)) and math.isfinite(v) and v > 0):
            raise ModelError(f"hertz.impact: {k} must be > 0, got {v!r}")
    a_curv, b_curv = _curvatures(curvature1, curvature2, "hertz.impact", angle)
    k = _core.hertz_contact(a_curv, b_curv, float(e_star), 1.0)["stiffness"]
    delta = (1.25 * mass * speed ** 2 / k) ** 0.4
    force = k * delta ** 1.5
    c = _core.hertz_contact(a_curv, b_curv, float(e_star), force)
    return {"mass": float(mass), "speed": float(speed), "stiffness": k, "delta_max": delta, "force_max": force,
            "duration": DURATION_FACTOR * delta / speed, "a": c["a"], "b": c["b"], "p0": c["p0"]}


def _materials(model, name: str, materials):
    if materials is not None and name in materials:
        return materials[name]
    for c in getattr(model, "_contacts", []):
        if getattr(c, "name", None) == name:
            m1, m2 = getattr(c.first, "material", None), getattr(c.second, "material", None)
            if m1 is not None and m2 is not None:
                return m1, m2
        elif isinstance(c, dict) and c.get("name") == name and "material1" in c and "material2" in c:
            from .laws import Material

            return Material(**c["material1"]), Material(**c["material2"])
    raise ModelError(f"contact '{name}': no materials to resolve its impacts (body.contour(..., material=ms.Material(...)) "
                     "on both contours, or materials={'" + name + "': (m1, m2)})")


def impacts(res, model, materials: dict | None = None) -> list[dict]:
    """The Hertz resolution of every impact in ``res.events`` (a rigid run of ``model``): one
    row per impact with ``t``, ``contact``, ``point`` and the values of :func:`impact`. The
    effective mass and approach speed come from the contact matrices at the impact (the state
    interpolated from the samples, the velocities before the impact from the event), the
    curvatures from the contact geometry there; ``materials`` maps a contact's name to its two
    :class:`mechsys.Material` s where the contours carry none."""
    from . import dynamics

    rows = []
    t = np.asarray(res["t"])
    qs = np.asarray(res["q"])
    for ev in res.events:
        if ev.get("event") != "impact" or "u_before" not in ev:
            continue
        name, pt = ev["contact"], int(ev["point"])
        q = np.array([np.interp(ev["t"], t, qs[:, i]) for i in range(qs.shape[1])])
        mats = dynamics.contact_matrices(model, q, np.asarray(ev["u_before"], dtype=float), ev["t"])
        idx = [i for i, c in enumerate(mats["contact"]) if c == name]
        i = idx[pt]
        w_nn = mats["delassus"][3 * i, 3 * i]
        speed = -mats["velocity"][i, 0]
        geo = dynamics.contact_geometry(model, q)
        j = [k for k, c in enumerate(geo["contact"]) if c == name][pt]
        m1, m2 = _materials(model, name, materials)
        # the summed curvature tensor's principal values: exact for principal directions at any
        # angle (crossed rods), where the two contours' own principal values are not enough
        krel = tuple(float(k) for k in geo["relative_curvature"][j])
        c1, c2 = (krel, (0.0, 0.0)) if all(math.isfinite(k) for k in krel) else (geo["curvature1"][j], geo["curvature2"][j])
        row = impact(1.0 / w_nn, speed, effective_modulus(m1, m2), c1, c2)
        rows.append({"t": ev["t"], "contact": name, "point": pt, **row})
    return rows


def table(rows: list[dict]) -> str:
    """The rows of :func:`impacts` as a text table (SI units)."""
    head = ["t [s]", "contact", "v [m/s]", "m [kg]", "delta_max [m]", "F_max [N]", "T [s]", "a [m]", "b [m]", "p0 [Pa]"]
    keys = ["t", "contact", "speed", "mass", "delta_max", "force_max", "duration", "a", "b", "p0"]
    lines = [" | ".join(head)]
    for r in rows:
        lines.append(" | ".join(r[k] if isinstance(r[k], str) else f"{r[k]:.6g}" for k in keys))
    return "\n".join(lines)


__all__ = ["DURATION_FACTOR", "effective_modulus", "impact", "impacts", "table"]
