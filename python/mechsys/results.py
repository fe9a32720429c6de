"""Simulation results: named signals with units, as numpy arrays, saved to and loaded from HDF5.

Signal names (``res.names()`` lists those present):

==============================  ===========  =============================================
name                            unit         shape
==============================  ===========  =============================================
t                               s            (n,)
q, u, udot                      mixed        (n, nq), (n, nu), (n, nu)
joint/<j>/q, /u, /udot          rad, m, ...  (n,) for 1-DOF joints, else (n, k)
body/<b>/position               m            (n, 3)  body-frame origin, inertial components
body/<b>/orientation            1            (n, 4)  quaternion [w, x, y, z] of A_IB
body/<b>/velocity               m/s          (n, 3)
body/<b>/angular_velocity       rad/s        (n, 3)  inertial components
body/<b>/acceleration           m/s^2        (n, 3)
body/<b>/mass                   kg           (n,)
body/<b>/kinetic_energy         J            (n,)
energy/kinetic, potential,      J            (n,)
  total, dissipated,
  external_work
momentum/linear                 N s          (n, 3)
momentum/angular                N m s        (n, 3)  about the inertial origin
force/<e>/force, /deflection    N, m, ...    (n,) or (n, k)  a force element's force (resisting its
                                                     deflection) and deflection; the loads record
                                                     what they apply: a joint force its value, a
                                                     Python force its generalized forces (columns
                                                     named by joint coordinate), a body force its
                                                     force and force/<e>/torque (about its point)
constraint/<c>/lambda           N, N m, ...  (n,) or (n, 3)  Lagrange multipliers
constraint/<c>/violation        m, rad, ...  (n,) or (n, 3)  Phi(q, t)
body/<b>/angular_acceleration   rad/s^2      (n, 3)  inertial components
body/<b>/com_position, ...      m, m/s, ...  (n, 3)  centre of mass: _position, _velocity, _acceleration
com/position, velocity,         m, m/s, ...  (n, 3)  the system's centre of mass
  acceleration
marker/<b>/<m>/position, ...    m, m/s, ...  (n, 3)  a marker's origin: position, velocity, acceleration
marker/<b>/<m>/orientation      1            (n, 4)  its frame as a quaternion [w, x, y, z] of A_IM
joint/<j>/reaction_force        N            (n, 3)  wrench of the parent on the child through
joint/<j>/reaction_torque       N m          (n, 3)  the joint, at the joint origin, child
                                                     joint frame components (computed on first
                                                     access from the recorded state)
==============================  ===========  =============================================

Models with contacts (Moreau-Jean) add, per contact (shape (n,) for one candidate point, (n, k)
for k points; tangential ones (n, [k,] 2) in 3-D): ``contact/<c>/g_n`` (m), ``gd_n``, ``gd_t``
(m/s), ``lambda_n``, ``lambda_t`` (N, the step's impulse over the step), ``impulse_n``,
``impulse_t`` (N s), ``point`` (m, where the contact is on the first contour's surface, inertial
components, (n, [k,] 3)), ``normal`` (from the second contour towards the first), ``state`` (int8 levels open 0, stick 1, slip 2: ``res.levels(name)``; an
HDF5 enum in files), ``friction_reserve`` (mu0 lambda_N -
|lambda_T|, N), and ``energy/dissipated_impact``, ``energy/dissipated_friction`` (J), and
``energy/contact_elastic`` (J, the energy held by compliant Signorini layers, ``½ k δ²`` summed
over their deflections δ, ``½ c lambda_N²`` undamped; zero for rigid contacts: kinetic + potential
+ contact_elastic + dissipated - external work stays at its start), and
``energy/dissipated_drift`` (J, part of ``energy/dissipated``: what the steps' geometry took from
the layers between steps, overlaps that changed without work, negative where it gave; zero for
rigid contacts).

``constraint/<c>/velocity_violation`` (the violation's unit per second, same shape as
``violation``) is ``G u - b`` for every row, the velocity-only (non-holonomic) rows included.

Vector signals name their columns and give each its unit: ``res.columns("q")`` ->
``["hinge.angle", "float.x", ..., "float.qw", ...]``, ``res.column_units("q")`` -> ``["rad",
"m", ..., "1", ...]``. Arrays are read-only views (``np.array(res[name])`` for a copy to change).
``res.to_pandas()`` and ``res.to_xarray()`` give labelled tables (with pandas / xarray installed).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable, Iterable

import numpy as np

from .errors import ResultsError

# per joint type: (q columns, q units, u columns, u units); udot has u's columns and units per s
_JOINT_COLUMNS = {
    "revolute": (["angle"], ["rad"], ["rate"], ["rad/s"]),
    "prismatic": (["position"], ["m"], ["rate"], ["m/s"]),
    "path": (["s"], ["m"], ["s_rate"], ["m/s"]),
    "cylindrical": (["angle", "position"], ["rad", "m"], ["angle rate", "rate"], ["rad/s", "m/s"]),
    "universal": (["angle1", "angle2"], ["rad", "rad"], ["rate1", "rate2"], ["rad/s", "rad/s"]),
    "spherical": (["qw", "qx", "qy", "qz"], ["1"] * 4, ["wx", "wy", "wz"], ["rad/s"] * 3),
    "planar": (["x", "y", "angle"], ["m", "m", "rad"], ["vx", "vy", "rate"], ["m/s", "m/s", "rad/s"]),
    "free": (["x", "y", "z", "qw", "qx", "qy", "qz"], ["m"] * 3 + ["1"] * 4, ["vx", "vy", "vz", "wx", "wy", "wz"],
             ["m/s"] * 3 + ["rad/s"] * 3),
    "fixed": ([], [], [], []),
}

#: the levels of the contact state signals (an HDF5 enum in files)
CONTACT_STATES = {"open": 0, "stick": 1, "slip": 2}

_JOINT_UNITS = {
    "revolute": ("rad", "rad/s", "rad/s^2"),
    "prismatic": ("m", "m/s", "m/s^2"),
    "path": ("m", "m/s", "m/s^2"),
    "cylindrical": ("rad, m", "rad/s, m/s", "rad/s^2, m/s^2"),
    "universal": ("rad", "rad/s", "rad/s^2"),
    "spherical": ("1 (quaternion)", "rad/s", "rad/s^2"),
    "planar": ("m, m, rad", "m/s, m/s, rad/s", "m/s^2, m/s^2, rad/s^2"),
    "free": ("m, 1 (quaternion)", "m/s, rad/s", "m/s^2, rad/s^2"),
    "fixed": ("", "", ""),
}


class Results:
    """Named signals of one simulation. ``res["joint/hinge/q"]`` is a numpy array (a view into the
    recorded block, no copy); ``res.unit(name)`` its unit; ``res.model`` the model description."""

    def __init__(
        self,
        signals: dict[str, np.ndarray],
        units: dict[str, str],
        attrs: dict | None = None,
        lazy: dict[str, tuple[str, Callable[[], dict[str, np.ndarray]]]] | None = None,
    ):
        self._signals = signals
        self._units = units
        self.attrs = dict(attrs or {})
        # signals derived from the recorded state on first access: name -> (unit, group computer)
        self._lazy = dict(lazy or {})
        # per-column names and units of vector signals: name -> (columns, units)
        self._columns: dict[str, tuple[list, list]] = {}

    # ---- construction from a simulation --------------------------------------------------------
    @classmethod
    def from_raw(
        cls, raw: dict, joints: list[dict], body_names: list[str], attrs: dict, engine=None, callbacks=None,
        keep: Iterable[str] | None = None,
    ) -> "Results":
        """The results of a run from the engine's recording ``raw``. The named signals (views into
        the recorded blocks), their units and columns are laid out on first use: a run whose
        results are read by a few names, or not at all (a parameter study keeping one number),
        does not pay for naming the others (a few tenths of a millisecond for a chain of 16
        bodies). ``keep``: the names of a selective recording (``simulate(sensors=...)``)."""
        out = cls.__new__(cls)
        out.attrs = dict(attrs or {})
        out._pending = (raw, joints, body_names, engine, callbacks, None if keep is None else list(keep))
        return out

    def __getattr__(self, name: str):
        # only reached for attributes not set yet: the signal tables of results still to be laid out
        if name in ("_signals", "_units", "_columns", "_lazy") and "_pending" in self.__dict__:
            raw, joints, body_names, engine, callbacks, keep = self.__dict__["_pending"]
            try:
                s, u, cols, lazy = Results._lay_out(raw, joints, body_names, engine, callbacks)
            except AttributeError as e:  # not to be mistaken for a missing attribute by the caller
                raise ResultsError(f"laying out the recorded signals failed: {e}") from e
            # (the recording is let go only once laid out: a failed layout fails the same way again
            # instead of leaving results without tables)
            del self.__dict__["_pending"]
            self._signals, self._units, self._lazy, self._columns = s, u, lazy, cols
            if keep is not None:
                self._keep_only(keep)
            return self.__dict__[name]
        raise AttributeError(f"'{type(self).__name__}' object has no attribute '{name}'")

    @staticmethod
    def _lay_out(raw: dict, joints: list[dict], body_names: list[str], engine, callbacks):
        """Names, units and columns of every recorded signal, and the derived groups computed on
        first access: ``(signals, units, columns, lazy)``."""
        s: dict[str, np.ndarray] = {}
        u: dict[str, str] = {}
        cols: dict[str, tuple[list, list]] = {}
        xyz = ["x", "y", "z"]

        def put(name, arr, unit, columns=None, column_units=None):
            s[name] = arr
            u[name] = unit
            if columns is not None:
                cols[name] = (list(columns), list(column_units) if column_units is not None else [unit] * len(columns))

        qc, qu, uc, uu_ = [], [], [], []
        for j in joints:
            a, b, c, d = _JOINT_COLUMNS.get(j["type"], ([f"q{i}" for i in range(j["nq"])], [""] * j["nq"],
                                                         [f"u{i}" for i in range(j["nu"])], [""] * j["nu"]))
            qc += [f"{j['name']}.{x}" for x in a]
            qu += b
            uc += [f"{j['name']}.{x}" for x in c]
            uu_ += d
        elastic = engine.elastic() if engine is not None and hasattr(engine, "elastic") else []
        for e in elastic:
            qc += [f"{e['body']}.e{k}" for k in range(e["ne"])]
            qu += ["1"] * e["ne"]
            uc += [f"{e['body']}.e{k}" for k in range(e["ne"])]
            uu_ += ["1/s"] * e["ne"]
        # a selective recording (simulate(sensors=...)) holds some bodies only, maybe no
        # accelerations, constraint or force values
        if "body_index" in raw:
            all_bodies = body_names
            body_names = [all_bodies[i - 1] for i in raw["body_index"]]
            complete = len(body_names) == len(all_bodies)
        else:
            complete = True
        acc = "udot" in raw
        put("t", raw["t"], "s")
        put("q", raw["q"], "mixed", qc, qu)
        put("u", raw["u"], "mixed", uc, uu_)
        if acc:
            put("udot", raw["udot"], "mixed", uc, [_rate_unit(x) for x in uu_])
        for e in elastic:
            # elastic coordinates (their unit is that of the shape functions' normalization)
            sl, ecols = slice(e["iq"], e["iq"] + e["ne"]), [f"e{k}" for k in range(e["ne"])]
            put(f"body/{e['body']}/elastic_q", raw["q"][:, sl], "1", ecols)
            su = slice(e["iu"], e["iu"] + e["ne"])
            put(f"body/{e['body']}/elastic_u", raw["u"][:, su], "1/s", ecols)
            if acc:
                put(f"body/{e['body']}/elastic_udot", raw["udot"][:, su], "1/s^2", ecols)
            qe = np.asarray(raw["q"][:, sl])
            put(f"body/{e['body']}/strain_energy", 0.5 * np.einsum("ti,ij,tj->t", qe, np.asarray(e["stiffness"]), qe), "J")
            if e.get("nodes"):
                # each node's deflection from its undeformed place, body frame (n, nodes, 3)
                put(f"body/{e['body']}/node_deflection",
                    np.einsum("tk,nkc->tnc", qe, np.asarray(e["node_translation"], dtype=float)), "m")
                put(f"body/{e['body']}/node_rotation",
                    np.einsum("tk,nkc->tnc", qe, np.asarray(e["node_rotation"], dtype=float)), "rad")
        for j in joints:
            uq, uu, ua = _JOINT_UNITS.get(j["type"], ("", "", ""))
            if j["nq"] == 0:
                continue
            sq = slice(j["iq"], j["iq"] + j["nq"])
            su = slice(j["iu"], j["iu"] + j["nu"])
            one = j["nq"] == 1
            a, b, c, d = _JOINT_COLUMNS.get(j["type"], (None, None, None, None))
            put(f"joint/{j['name']}/q", raw["q"][:, j["iq"]] if one else raw["q"][:, sq], uq, None if one else a, b)
            put(f"joint/{j['name']}/u", raw["u"][:, j["iu"]] if one else raw["u"][:, su], uu, None if one else c, d)
            if acc:
                put(f"joint/{j['name']}/udot", raw["udot"][:, j["iu"]] if one else raw["udot"][:, su], ua, None if one else c,
                    None if one or d is None else [_rate_unit(x) for x in d])
            if j["type"] == "path" and acc and "curvature" in j:
                # along the path: the tangential acceleration s'' and the normal (centripetal)
                # one kappa s'^2 towards the centre of curvature (signed for a plane curve: along
                # n = b x t); kappa at each sample's s unless the curve has a constant one
                kappa = j["curvature"]
                if not j.get("constant_curvature", True) and engine is not None:
                    from . import _core

                    s_q = np.ascontiguousarray(raw["q"][:, j["iq"]])
                    kappa = _core.path_geometry(engine, j["name"], s_q)["curvature"]
                put(f"joint/{j['name']}/tangential_acceleration", raw["udot"][:, j["iu"]], "m/s^2")
                put(f"joint/{j['name']}/normal_acceleration", kappa * raw["u"][:, j["iu"]] ** 2, "m/s^2")
        for k, b in enumerate(body_names):
            put(f"body/{b}/position", raw["body_position"][:, k, :], "m", xyz)
            put(f"body/{b}/orientation", raw["body_orientation"][:, k, :], "1", ["w", "x", "y", "z"])
            put(f"body/{b}/velocity", raw["body_velocity"][:, k, :], "m/s", xyz)
            put(f"body/{b}/angular_velocity", raw["body_angular_velocity"][:, k, :], "rad/s", xyz)
            if acc:
                put(f"body/{b}/acceleration", raw["body_acceleration"][:, k, :], "m/s^2", xyz)
            if "body_angular_acceleration" in raw:
                put(f"body/{b}/angular_acceleration", raw["body_angular_acceleration"][:, k, :], "rad/s^2", xyz)
            put(f"body/{b}/mass", raw["body_mass"][:, k], "kg")
            put(f"body/{b}/kinetic_energy", raw["body_kinetic"][:, k], "J")
        put("energy/kinetic", raw["kinetic"], "J")
        put("energy/potential", raw["potential"], "J")
        put("energy/total", raw["kinetic"] + raw["potential"], "J")
        # with contacts, what the impulses dissipate counts too (its parts are signals of their own)
        contact_loss = raw["dissipated_impact"] + raw["dissipated_friction"] if "dissipated_impact" in raw else 0.0
        if "contact_drift" in raw:
            contact_loss = contact_loss + raw["contact_drift"]
        put("energy/dissipated", raw["dissipated"] + contact_loss, "J")
        put("energy/external_work", raw["external_work"], "J")
        put("momentum/linear", raw["momentum_linear"], "N s", xyz)
        put("momentum/angular", raw["momentum_angular"], "N m s", xyz)
        if engine is not None and "constraint_lambda" in raw:
            for c in engine.constraints():
                sl = slice(c["row"], c["row"] + c["rows"])
                unit = c["unit"]
                # a planar model's constraints name their in-plane rows (x, y, rz, normal)
                ccols = c.get("columns") if c["rows"] > 1 else None
                cu, cv = c.get("column_units"), c.get("column_violation_units")
                if ccols is not None:
                    unit, vunit = ", ".join(dict.fromkeys(cu)), ", ".join(dict.fromkeys(cv))
                else:
                    vunit = c["violation_unit"]
                put(f"constraint/{c['name']}/lambda", raw["constraint_lambda"][:, sl] if c["rows"] > 1 else raw["constraint_lambda"][:, c["row"]], unit,
                    ccols, cu)
                put(f"constraint/{c['name']}/violation", raw["constraint_violation"][:, sl] if c["rows"] > 1 else raw["constraint_violation"][:, c["row"]], vunit,
                    ccols, cv)
                if "constraint_velocity_violation" in raw:
                    vv = raw["constraint_velocity_violation"]
                    put(f"constraint/{c['name']}/velocity_violation", vv[:, sl] if c["rows"] > 1 else vv[:, c["row"]],
                        _rate_unit(vunit), ccols, [_rate_unit(u) for u in cv] if ccols is not None else None)
        if engine is not None and "force_value" in raw:
            # each force element's force along its deflection (resisting it) and the deflection
            joint_of = {}
            for j in joints:
                a, b, c, d = _JOINT_COLUMNS.get(j["type"], (None, None, [f"u{i}" for i in range(j["nu"])], [""] * j["nu"]))
                for i in range(j["nu"]):
                    joint_of[j["iu"] + i] = (f"{j['name']}.{c[i]}", _force_unit(d[i]))
            for f in engine.force_outputs():
                k, w = f["first"], f["width"]
                sl = slice(k, k + w) if w > 1 else k
                name, kind = f["name"], f["type"]
                if kind == "body_force":
                    # the applied force and its torque about the point, inertial components
                    put(f"force/{name}/force", raw["force_value"][:, k:k + 3], "N", xyz)
                    put(f"force/{name}/torque", raw["force_value"][:, k + 3:k + 6], "N m", xyz)
                elif kind == "joint_force":
                    put(f"force/{name}/force", raw["force_value"][:, sl], f["force_unit"])
                elif kind == "hydrodynamic_bearing":
                    # the film's force on the journal (shell-frame x, y) and its friction torque; the
                    # eccentricity ratio, where the journal centre sits (position angle of the offset
                    # from the shell x axis) and the attitude angle of the film force's load line
                    put(f"force/{name}/force", raw["force_value"][:, k:k + 2], "N", ["x", "y"])
                    put(f"force/{name}/torque", raw["force_value"][:, k + 2], "N m")
                    put(f"force/{name}/eccentricity", raw["force_deflection"][:, k], "1")
                    put(f"force/{name}/position_angle", raw["force_deflection"][:, k + 1], "rad")
                    put(f"force/{name}/attitude_angle", raw["force_deflection"][:, k + 2], "rad")
                elif kind == "compliant_contact":
                    # per point: F_N, F_T1, F_T2, stored and dissipated energy, point, friction force (world);
                    # delta, delta', slip velocity (t1, t2), alpha, normal (world), unused
                    npt, nt = f["points"], f["tangents"]
                    fv = raw["force_value"][:, k:k + w].reshape(-1, npt, 11)
                    dv = raw["force_deflection"][:, k:k + w].reshape(-1, npt, 11)
                    one = npt == 1
                    pick = (lambda a, i: a[:, 0, i]) if one else (lambda a, i: a[:, :, i])
                    pre = f"contact/{name}"
                    put(f"{pre}/overlap", pick(dv, 0), "m")
                    put(f"{pre}/overlap_rate", pick(dv, 1), "m/s")
                    put(f"{pre}/force_n", pick(fv, 0), "N")
                    if nt > 1:
                        put(f"{pre}/force_t", fv[:, 0, 1:3] if one else fv[:, :, 1:3], "N", ["t1", "t2"] if one else None)
                        put(f"{pre}/slip_velocity", dv[:, 0, 2:4] if one else dv[:, :, 2:4], "m/s", ["t1", "t2"] if one else None)
                    else:
                        put(f"{pre}/force_t", pick(fv, 1), "N")
                        put(f"{pre}/slip_velocity", pick(dv, 2), "m/s")
                    put(f"{pre}/damping_alpha", pick(dv, 4), "s/m")
                    put(f"{pre}/energy_elastic", fv[:, :, 3].sum(axis=1), "J")
                    put(f"{pre}/energy_dissipated", fv[:, :, 4].sum(axis=1), "J")
                    # where it acts (the viewer's dot and arrows), world axes: the point on the first
                    # contour, the normal (towards the first contour) and the friction force on it
                    put(f"{pre}/point", fv[:, 0, 5:8] if one else fv[:, :, 5:8], "m", xyz if one else None)
                    put(f"{pre}/normal", dv[:, 0, 5:8] if one else dv[:, :, 5:8], "1", xyz if one else None)
                    put(f"{pre}/friction_force", fv[:, 0, 8:11] if one else fv[:, :, 8:11], "N", xyz if one else None)
                elif kind == "compliant_group":
                    # force: sum of F_N, stored and dissipated energy, touching pairs, drawn points; deflection: max delta,
                    # max delta', pairs kept, touching points
                    fv, dv = raw["force_value"][:, k:k + 4], raw["force_deflection"][:, k:k + 4]
                    pre = f"contact/{name}"
                    put(f"{pre}/touching_points", dv[:, 3], "1")
                    put(f"{pre}/force_n", fv[:, 0], "N")
                    put(f"{pre}/energy_elastic", fv[:, 1], "J")
                    put(f"{pre}/energy_dissipated", fv[:, 2], "J")
                    put(f"{pre}/touching", fv[:, 3], "1")
                    put(f"{pre}/max_overlap", dv[:, 0], "m")
                    put(f"{pre}/max_overlap_rate", dv[:, 1], "m/s")
                    put(f"{pre}/pairs", dv[:, 2], "1")
                    # the first touching points (two per member at most), as a rigid group's, for
                    # the viewer: position, force on the first contour, 1 where a point is drawn
                    nd = (w - 4) // 6
                    if nd > 0:
                        pts = raw["force_value"][:, k + 4:k + w].reshape(-1, nd, 6)
                        used = np.arange(nd)[None, :] < np.minimum(dv[:, 3], nd)[:, None]
                        put(f"{pre}/points", pts[:, :, :3], "m")
                        put(f"{pre}/point_forces", pts[:, :, 3:], "N")
                        put(f"{pre}/point_states", used.astype(float), "1")
                elif kind == "python_force":
                    labels = [joint_of.get(i, (f"u{i}", ""))[0] for i in range(w)]
                    put(f"force/{name}/force", raw["force_value"][:, sl], "mixed", labels,
                        [joint_of.get(i, ("", ""))[1] for i in range(w)])
                else:
                    put(f"force/{name}/force", raw["force_value"][:, sl], f["force_unit"])
                    put(f"force/{name}/deflection", raw["force_deflection"][:, sl], f["deflection_unit"])
        if engine is not None and "dissipated_impact" in raw:
            put("energy/dissipated_impact", raw["dissipated_impact"], "J")
            put("energy/dissipated_friction", raw["dissipated_friction"], "J")
            if "contact_elastic" in raw:
                put("energy/contact_elastic", raw["contact_elastic"], "J")
            if "contact_drift" in raw:
                put("energy/dissipated_drift", raw["contact_drift"], "J")
            if "solver" in raw:
                # the contact solver over the steps since the previous sample
                sv = raw["solver"]
                put("solver/residual", sv[:, 0], "1")
                put("solver/iterations", sv[:, 1], "1")
                put("solver/converged", sv[:, 2].astype(np.int8), "1")
                put("solver/contacts", sv[:, 3], "1")
                put("solver/islands", sv[:, 4], "1")
            # (the points' signals are left out of a recording that chose none of them)
            for c in engine.contacts() if "contact_gap" in raw else ():
                k, n, nt = c["first"], c["points"], c["tangents"]
                sl = slice(k, k + n) if n > 1 else k
                pre = f"contact/{c['name']}"
                put(f"{pre}/g_n", raw["contact_gap"][:, sl], "m")
                if "contact_point" in raw:
                    # where the contact is (on the first contour's surface) and its normal (from the
                    # second contour towards the first), inertial components
                    put(f"{pre}/point", raw["contact_point"][:, sl, :], "m", xyz if n == 1 else None)
                    put(f"{pre}/normal", raw["contact_normal"][:, sl, :], "1", xyz if n == 1 else None)
                if "contact_friction" in raw:
                    # the friction force on the first contour's body, inertial components
                    put(f"{pre}/friction_force", raw["contact_friction"][:, sl, :], "N", xyz if n == 1 else None)
                put(f"{pre}/gd_n", raw["contact_gd_n"][:, sl], "m/s")
                put(f"{pre}/gd_t", raw["contact_gd_t"][:, sl, :nt] if nt > 1 else raw["contact_gd_t"][:, sl, 0], "m/s")
                if "contact_omega" in raw:
                    # relative angular velocity in the contact frame: spin (drilling) about the normal,
                    # rolling about the tangents (in the plane: about the out-of-plane tangent only)
                    om = raw["contact_omega"]
                    put(f"{pre}/spin", om[:, sl, 0], "rad/s")
                    put(f"{pre}/rolling", om[:, sl, 1:3] if nt > 1 else om[:, sl, 2], "rad/s")
                put(f"{pre}/lambda_n", raw["contact_lambda_n"][:, sl], "N")
                put(f"{pre}/lambda_t", raw["contact_lambda_t"][:, sl, :nt] if nt > 1 else raw["contact_lambda_t"][:, sl, 0], "N")
                put(f"{pre}/impulse_n", raw["contact_impulse_n"][:, sl], "N s")
                put(f"{pre}/impulse_t", raw["contact_impulse_t"][:, sl, :nt] if nt > 1 else raw["contact_impulse_t"][:, sl, 0], "N s")
                put(f"{pre}/state", np.asarray(raw["contact_state"][:, sl]).astype(np.int8), "1")
                put(f"{pre}/friction_reserve", raw["contact_reserve"][:, sl], "N")
        if engine is not None and "group_closed" in raw:
            # contact groups (mechsys.ContactGroup): one column per group
            span = np.diff(raw["t"], prepend=np.nan)
            span[0] = span[1] if len(span) > 1 else 1.0
            for k, g in enumerate(engine.contact_groups()):
                pre = f"contact/{g['name']}"
                put(f"{pre}/closed", raw["group_closed"][:, k], "1")
                put(f"{pre}/max_penetration", raw["group_max_penetration"][:, k], "m")
                put(f"{pre}/impulse_n", raw["group_impulse_n"][:, k], "N s")
                put(f"{pre}/lambda_n", raw["group_impulse_n"][:, k] / span, "N")
                put(f"{pre}/pairs", raw["group_pairs"][:, k], "1")
                put(f"{pre}/impulse_against", raw["group_impulse_against"][:, k, :], "N s")
                put(f"{pre}/force_against", raw["group_impulse_against"][:, k, :] / span[:, None], "N")
            if "group_points" in raw:
                # the points closed in the last step before each sample, padded to the most any
                # sample has (zeros, state 0: no point)
                counts = np.asarray(raw["group_point_count"], dtype=np.int64)
                flat = np.asarray(raw["group_points"])
                starts = np.concatenate([[0], np.cumsum(counts.reshape(-1))])[:-1].reshape(counts.shape)
                for k, g in enumerate(engine.contact_groups()):
                    pre = f"contact/{g['name']}"
                    width = int(counts[:, k].max(initial=0))
                    pts = np.zeros((len(counts), width, 3))
                    frc = np.zeros((len(counts), width, 3))
                    st = np.zeros((len(counts), width), dtype=np.int8)
                    for i in range(len(counts)):
                        c, a = counts[i, k], starts[i, k]
                        pts[i, :c], frc[i, :c], st[i, :c] = flat[a:a + c, :3], flat[a:a + c, 3:6], flat[a:a + c, 6]
                    put(f"{pre}/points", pts, "m")
                    put(f"{pre}/point_forces", frc, "N")
                    put(f"{pre}/point_states", st, "1")
        for a in s.values():
            a.setflags(write=False)
        lazy = {}
        if engine is not None and "body_orientation" in raw and "body_mass" in raw:
            group, sensors = _sensor_group(engine, body_names, raw, complete)
            for name, unit in sensors.items():
                lazy[name] = (unit, group)
        if engine is not None and joints and acc:
            group = _reaction_group(engine, callbacks, joints, raw)
            for j in joints:
                lazy[f"joint/{j['name']}/reaction_force"] = ("N", group)
                lazy[f"joint/{j['name']}/reaction_torque"] = ("N m", group)
        return s, u, cols, lazy

    def _keep_only(self, names) -> None:
        """Drops every signal but ``t`` and ``names`` (a selective recording; names the run
        cannot give, e.g. contact signals of another scheme, are left out)."""
        keep = set(names) | {"t"}
        self._signals = {n: a for n, a in self._signals.items() if n in keep}
        self._units = {n: u for n, u in self._units.items() if n in keep or n in self._lazy}
        self._lazy = {n: v for n, v in self._lazy.items() if n in keep}
        self._columns = {n: c for n, c in self._columns.items() if n in keep}

    # ---- pickling ------------------------------------------------------------------------------
    def __getstate__(self) -> dict:
        """Signals, units and attributes; the derived signal groups still waiting to be computed
        (they close over the engine model, which does not pickle) are computed first, as for
        :meth:`save`, so the copy answers the same without an engine."""
        for name in list(self._lazy):
            if name in self._lazy:
                self._materialize(name)
        state = dict(self.__dict__)
        state["_lazy"] = {}
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        for arr in self._signals.values():
            if isinstance(arr, np.ndarray) and arr.flags.owndata:
                arr.setflags(write=False)

    # ---- access --------------------------------------------------------------------------------
    def __getitem__(self, name: str) -> np.ndarray:
        if not isinstance(name, str):
            raise ResultsError(f"a signal is named by a string such as 'joint/j1/q', got {name!r} "
                               f"({type(name).__name__}); res.names() lists them")
        try:
            return self._signals[name]
        except KeyError:
            if name in self._lazy:
                self._materialize(name)
                return self._signals[name]
            import difflib

            close = difflib.get_close_matches(name, list(self._signals), n=6, cutoff=0.6)
            hint = f"; similar: {', '.join(close)}" if close else ""
            raise ResultsError(f"unknown signal '{name}'{hint} (res.names() lists all)") from None

    def _materialize(self, name: str) -> None:
        unit, compute = self._lazy[name]
        for n, arr in compute().items():
            if n not in self._lazy:
                continue  # left out by a selective recording (or already there)
            arr.setflags(write=False)
            self._signals[n] = arr
            self._units[n] = self._lazy.pop(n, (unit, None))[0]
            if arr.ndim == 2 and arr.shape[1] == 3:
                self._columns[n] = (["x", "y", "z"], [self._units[n]] * 3)
            elif arr.ndim == 2 and arr.shape[1] == 4 and n.endswith("/orientation"):
                self._columns[n] = (["w", "x", "y", "z"], ["1"] * 4)

    def columns(self, name: str) -> list[str]:
        """Names of a signal's columns (joint coordinates as ``joint.x``, ``joint.qw``, ...;
        components ``x``, ``y``, ``z``; ``[k]`` where nothing better is known); one name for a
        scalar signal."""
        a = self[name]
        if name in self._columns:
            return list(self._columns[name][0])
        if a.ndim == 1:
            return [name.rsplit("/", 1)[-1]]
        return [f"[{k}]" for k in range(int(np.prod(a.shape[1:])))]

    def column_units(self, name: str) -> list[str]:
        """The unit of each column (``q``: m for positions, 1 for quaternion entries, rad for
        angles, ...)."""
        if name in self._columns:
            self[name]
            return list(self._columns[name][1])
        return [self.unit(name)] * len(self.columns(name))

    def levels(self, name: str) -> dict[str, int] | None:
        """The named levels of an integer signal (a contact's ``state``: open 0, stick 1, slip 2),
        else None."""
        self[name]
        return dict(CONTACT_STATES) if name.startswith("contact/") and name.endswith("/state") else None

    def to_pandas(self, signals: Iterable[str] | None = None):
        """A pandas DataFrame indexed by time (s): one column per scalar signal, ``name.column``
        for each column of a vector signal (all signals with one row per sample by default);
        ``df.attrs["units"]`` maps every column to its unit. Needs pandas."""
        try:
            import pandas as pd
        except ImportError:
            raise ResultsError("to_pandas needs pandas (pip install pandas)") from None
        data, units = {}, {}
        for n, a2, cols, cu in self._tables(signals):
            for k, (c, un) in enumerate(zip(cols, cu)):
                key = n if a2.shape[1] == 1 else f"{n}.{c}"
                data[key] = a2[:, k]
                units[key] = un
        df = pd.DataFrame(data, index=pd.Index(np.asarray(self.t), name="t"))
        df.attrs["units"] = units
        return df

    def to_xarray(self, signals: Iterable[str] | None = None):
        """An xarray Dataset over the time coordinate ``t`` (s): one variable per signal, vector
        signals with a second dimension ``<name>/column`` labelled by the column names; each
        variable's ``units`` attribute (and ``column_units`` for vectors). Needs xarray."""
        try:
            import xarray as xr
        except ImportError:
            raise ResultsError("to_xarray needs xarray (pip install xarray)") from None
        data = {}
        for n, a2, cols, cu in self._tables(signals):
            if a2.shape[1] == 1:
                data[n] = xr.DataArray(a2[:, 0], dims=("t",), attrs={"units": cu[0]})
            else:
                dim = f"{n}/column"
                data[n] = xr.DataArray(a2, dims=("t", dim), coords={dim: cols},
                                       attrs={"units": self.unit(n), "column_units": list(cu)})
        return xr.Dataset(data, coords={"t": ("t", np.asarray(self.t), {"units": "s"})})

    def _tables(self, signals):
        names = list(signals) if signals is not None else [n for n in self.names() if n != "t"]
        out = []
        for n in names:
            a = np.asarray(self[n])
            if a.shape[0] != len(self.t) or a.ndim > 2:
                if signals is not None:
                    raise ResultsError(f"signal '{n}' is not a table of one row per sample (shape {a.shape})")
                continue
            a2 = a.reshape(len(self.t), -1)
            out.append((n, a2, self.columns(n), self.column_units(n)))
        return out

    def __contains__(self, name: str) -> bool:
        return name in self._signals or name in self._lazy

    def names(self) -> list[str]:
        """All signal names (including those computed on first access)."""
        return list(self._signals) + list(self._lazy)

    def unit(self, name: str) -> str:
        """The unit of a signal."""
        if name in self._lazy:
            return self._lazy[name][0]
        self[name]
        return self._units.get(name, "")

    def angular_momentum_about(self, point) -> np.ndarray:
        """Moment of momentum about a fixed point P: L_P = L_O - r_P x p (n, 3), N m s."""
        try:
            rp = np.asarray(point, dtype=float).reshape(3)
        except (TypeError, ValueError):
            raise ResultsError(f"angular_momentum_about: point must be 3 numbers, got {point!r}") from None
        if not np.all(np.isfinite(rp)):
            raise ResultsError(f"angular_momentum_about: point must be finite, got {point!r}")
        return self["momentum/angular"] - np.cross(rp, self["momentum/linear"])

    @property
    def t(self) -> np.ndarray:
        """Sample times (s)."""
        return self._signals["t"]

    @property
    def model(self) -> dict:
        """The model description the results came from."""
        return _json_attr(self.attrs, "model", "{}")

    @property
    def settings(self) -> dict:
        """The simulation settings."""
        return _json_attr(self.attrs, "settings", "{}")

    @property
    def stats(self) -> dict:
        """Integrator statistics (steps, rejected, evaluations, jacobians)."""
        return _json_attr(self.attrs, "stats", "{}")

    @property
    def events(self) -> list[dict]:
        """Contact events of a contact run (event-driven or Moreau-Jean), in time order: dicts with
        ``t`` (s), ``contact``, ``point`` (candidate index within the contact), ``event``
        (``impact``, ``close``, ``open``, ``stick``, ``slip``, ``painleve``), the event's impulses
        ``impulse_n`` and ``impulse_t`` (N s, t1 and t2), the kinetic ``energy`` its impulses
        took (J) and ``steps`` (Moreau-Jean steps merged into it; 1 for the event-driven scheme).
        Impacts add the generalized velocities ``u_before`` and ``u_after``; Painleve situations
        add ``mu``, ``mu_critical``, ``situation`` (``inconsistent`` or ``non-unique``),
        ``solutions`` (the points closed in each solution of a non-unique state, as
        ``"contact[k]"``) and ``resolved_by_impulse``. Empty for the smooth integrators."""
        return _json_attr(self.attrs, "events", "[]")

    def __repr__(self) -> str:
        n = len(self.t)
        span = f"{self.t[0]:g}..{self.t[-1]:g} s" if n else "empty"
        return f"Results({len(self._signals)} signals, {n} samples, t = {span})"

    # ---- files ---------------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Writes all signals to HDF5 (one dataset per signal with a ``unit`` attribute; the model
        description, settings and statistics as file attributes)."""
        import h5py

        for name in list(self._lazy):
            if name in self._lazy:
                self._materialize(name)
        from .files import atomic_path

        path = Path(path)
        # to a temporary file renamed over the target: a failed or interrupted save leaves the
        # previous results as they were
        with atomic_path(path) as tmp, h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["format"] = "mechsys-results"
            f.attrs["format_version"] = FORMAT_VERSION
            for k, v in self.attrs.items():
                if k != "signal_order":
                    f.attrs[k] = v
            f.attrs["signal_order"] = json.dumps(list(self._signals))
            for name, arr in self._signals.items():
                data = np.ascontiguousarray(arr)
                if self.levels(name) is not None:
                    data = data.astype(np.int8)
                    ds = f.create_dataset(name, data=data, dtype=h5py.enum_dtype(CONTACT_STATES, basetype="i1"))
                else:
                    ds = f.create_dataset(name, data=data)
                ds.attrs["unit"] = self._units.get(name, "")
                ds.attrs["crc32"] = _crc32(data)
                if name in self._columns:
                    ds.attrs["columns"] = json.dumps(self._columns[name][0])
                    ds.attrs["column_units"] = json.dumps(self._columns[name][1])
            # written last: a file without it was not finished
            f.attrs["signal_count"] = len(self._signals)
            f.attrs["complete"] = True
        return path

    @classmethod
    def load(cls, path: str | Path) -> "Results":
        """Reads a results file written by :meth:`save`, as untrusted input: the file must be
        complete (its marker written last) with every signal's checksum matching; links, external
        storage, virtual or compressed datasets and shapes larger than the file are refused. Every
        problem is a :class:`mechsys.ResultsError` naming the file and the signal."""
        import h5py

        path = Path(path)
        if not path.exists():
            raise ResultsError(f"results file '{path}' does not exist")
        try:
            f = h5py.File(path, "r")
        except OSError as e:
            raise ResultsError(f"'{path}' is not an HDF5 results file ({e})") from None
        size = path.stat().st_size
        try:
            with f:
                if f.attrs.get("format") != "mechsys-results":
                    raise ResultsError(f"'{path}' is an HDF5 file but not mechsys results (no 'format' attribute)")
                version = int(f.attrs.get("format_version", 0))
                if version > FORMAT_VERSION or version < 1:
                    raise ResultsError(f"'{path}': results format version {version} is not one this mechsys reads "
                                       f"(1 to {FORMAT_VERSION})")
                if version >= 2 and not bool(f.attrs.get("complete", False)):
                    raise ResultsError(f"'{path}': incomplete results file (no completeness marker: its writing stopped "
                                       "part-way); run the simulation again")
                signals, units, columns = _read_signals(f, path, size, checksums=version >= 2)
                _check_schema(signals, path)
                if version >= 2 and int(f.attrs.get("signal_count", -1)) != len(signals):
                    raise ResultsError(f"'{path}': {len(signals)} signals, the file says {int(f.attrs.get('signal_count', -1))}")
                attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
        except ResultsError:
            raise
        except (OSError, KeyError, ValueError, TypeError, RuntimeError) as e:
            raise ResultsError(f"'{path}': unreadable results file ({type(e).__name__}: {e})") from None
        if version < 2:
            import warnings

            warnings.warn(f"'{path}' was written before results files carried checksums (format 1): not verified",
                          UserWarning, stacklevel=2)
        try:
            order = json.loads(attrs.pop("signal_order", "[]"))
            if not isinstance(order, list):
                raise ValueError("not a list")
        except (ValueError, TypeError):
            raise ResultsError(f"'{path}': unreadable attribute 'signal_order'") from None
        order = [n for n in order if n in signals] + [n for n in signals if n not in order]
        out = cls({n: signals[n] for n in order}, units, attrs)
        out._columns = columns
        return out

    def to_html(self, path: str | Path, **options) -> Path:
        """Writes the browser viewer page of this run (see :mod:`mechsys.viewer`; options as
        :func:`mechsys.viewer.page_data`: ``signals``, ``trails``, ``follow``, ``max_frames``)."""
        from .viewer import to_html

        return to_html(self, path, **options)

    def to_csv(self, path: str | Path, signals: Iterable[str] | None = None) -> Path:
        """Writes chosen signals (all scalar and vector ones if None) as CSV with a header row
        ``t [s], name[i] [unit], ...``."""
        names = list(signals) if signals is not None else [n for n in self.names() if n not in ("t", "q", "u", "udot")]
        cols = [self.t.reshape(-1, 1)]
        header = ["t [s]"]
        for n in names:
            a = np.asarray(self[n])
            if a.shape[0] != len(self.t):
                raise ResultsError(f"signal '{n}' does not have one row per sample")
            a2 = a.reshape(len(self.t), -1)
            cols.append(a2)
            unit = self.unit(n)
            if a2.shape[1] == 1:
                header.append(f"{n} [{unit}]")
            else:
                header.extend(f"{n}[{i}] [{cu}]" for i, cu in enumerate(self.column_units(n)))
        from .files import write_atomically

        table = np.hstack(cols)
        return write_atomically(path, lambda tmp: np.savetxt(tmp, table, delimiter=",", header=",".join(header), comments=""))


def _sensor_group(engine, body_names: list[str], raw: dict, complete: bool = True):
    """Marker and centre-of-mass signals from the recorded body states (computed on first access):
    a point r fixed in a body (A_IB from the orientation) moves as p + A r, v + w x (A r),
    a + al x (A r) + w x (w x (A r)); a marker's orientation is q_body * q_marker. Without
    recorded accelerations there are no acceleration signals; the model's centre of mass needs
    every body recorded (``complete``)."""
    from .kinematics import matrix_to_quat

    acc = "body_angular_acceleration" in raw
    info = {b["name"]: b for b in engine.bodies()}
    names: dict[str, str] = {}
    for b in body_names:
        for mk in info[b].get("marker_frames", []):
            pre = f"marker/{b}/{mk[0]}"
            names.update({f"{pre}/position": "m", f"{pre}/velocity": "m/s", f"{pre}/orientation": "1"})
            if acc:
                names[f"{pre}/acceleration"] = "m/s^2"
        names.update({f"body/{b}/com_position": "m", f"body/{b}/com_velocity": "m/s"})
        if acc:
            names[f"body/{b}/com_acceleration"] = "m/s^2"
    whole = bool(body_names) and complete
    if whole:
        names.update({"com/position": "m", "com/velocity": "m/s"})
        if acc:
            names["com/acceleration"] = "m/s^2"

    def compute() -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        qb = raw["body_orientation"]  # (n, nb, 4) [w, x, y, z]
        m_tot = 0.0
        sums = [0.0, 0.0, 0.0]
        for k, b in enumerate(body_names):
            a_ib = _quat_matrices(qb[:, k, :])
            p, v, w = raw["body_position"][:, k, :], raw["body_velocity"][:, k, :], raw["body_angular_velocity"][:, k, :]
            a = raw["body_acceleration"][:, k, :] if acc else None
            al = raw["body_angular_acceleration"][:, k, :] if acc else None

            def point(r):
                rr = a_ib @ np.asarray(r, dtype=float)  # (n, 3)
                if not acc:
                    return p + rr, v + np.cross(w, rr), None
                return p + rr, v + np.cross(w, rr), a + np.cross(al, rr) + np.cross(w, np.cross(w, rr))

            for name, pos, rot in info[b].get("marker_frames", []):
                pre = f"marker/{b}/{name}"
                x, xd, xdd = point(pos)
                qm = matrix_to_quat(np.asarray(rot, dtype=float).reshape(3, 3))
                out[f"{pre}/position"], out[f"{pre}/velocity"] = x, xd
                if acc:
                    out[f"{pre}/acceleration"] = xdd
                out[f"{pre}/orientation"] = _quat_products(qb[:, k, :], qm)
            c, cd, cdd = point(info[b]["com"])
            out[f"body/{b}/com_position"], out[f"body/{b}/com_velocity"] = c, cd
            if acc:
                out[f"body/{b}/com_acceleration"] = cdd
            mass = raw["body_mass"][:, k][:, None]
            m_tot = m_tot + mass
            sums = [s_ + mass * x if x is not None else s_ for s_, x in zip(sums, (c, cd, cdd))]
        if whole:
            out["com/position"], out["com/velocity"] = sums[0] / m_tot, sums[1] / m_tot
            if acc:
                out["com/acceleration"] = sums[2] / m_tot
        return out

    return compute, names


def _quat_matrices(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) [w, x, y, z]."""
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def _quat_products(q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """q * r for quaternions q (n, 4) and one r (4,), [w, x, y, z]."""
    w1, x1, y1, z1 = q.T
    w2, x2, y2, z2 = r
    return np.stack([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2], -1)


def _reaction_group(engine, callbacks, joints: list[dict], raw: dict):
    """A computer of every joint's reaction wrench from the recorded t, q, u, u_dot (cut principle;
    see mechsys_core::dynamics::reactions), run once on first access."""

    def compute() -> dict[str, np.ndarray]:
        from . import _core

        force, torque = _core.joint_reactions(engine, raw["t"], raw["q"], raw["u"], raw["udot"], callbacks)
        n, nj = len(raw["t"]), len(joints)
        force = force.reshape(n, nj, 3)
        torque = torque.reshape(n, nj, 3)
        out = {}
        for k, j in enumerate(joints):
            out[f"joint/{j['name']}/reaction_force"] = force[:, k, :]
            out[f"joint/{j['name']}/reaction_torque"] = torque[:, k, :]
        return out

    return compute


def load(path: str | Path) -> Results:
    """Reads a results file (see :meth:`Results.load`)."""
    return Results.load(path)


__all__ = ["Results", "load"]


def _rate_unit(unit: str) -> str:
    """The unit of the time rate of a quantity in ``unit`` ("m" -> "m/s", "N, N m" style lists per part)."""
    if not unit:
        return "1/s"
    return ", ".join(_per_second(part.strip()) for part in unit.split(","))


def _force_unit(rate_unit: str) -> str:
    """The generalized force that goes with a velocity: m/s -> N, rad/s -> N m."""
    return {"m/s": "N", "rad/s": "N m"}.get(rate_unit, "")


def _per_second(unit: str) -> str:
    """"m/s" -> "m/s^2", "m" -> "m/s"."""
    return unit[:-2] + "/s^2" if unit.endswith("/s") else f"{unit}/s"


# ---- selective recording (simulate(sensors=...)) ---------------------------------------------------
_ACCELERATION_SUFFIXES = ("udot", "/acceleration", "/angular_acceleration", "/com_acceleration", "/reaction_force",
                          "/reaction_torque", "/tangential_acceleration", "/normal_acceleration")
_CONTACT_SUFFIXES = ("g_n", "point", "normal", "friction_force", "gd_n", "gd_t", "spin", "rolling", "lambda_n", "lambda_t", "impulse_n", "impulse_t", "state",
                     "friction_reserve")
_GROUP_SUFFIXES = ("closed", "max_penetration", "impulse_n", "lambda_n", "pairs", "impulse_against", "force_against",
                   "points", "point_forces", "point_states")


def signal_universe(engine) -> list[str]:
    """Every signal name a run of the engine model can give (some only with contacts or the
    matching scheme): what ``sensors=`` patterns are checked against."""
    names = ["t", "q", "u", "udot"]
    elastic_bodies = {e["body"] for e in engine.elastic()} if hasattr(engine, "elastic") else set()
    for j in engine.joints():
        if j["nq"]:
            names += [f"joint/{j['name']}/{x}" for x in ("q", "u", "udot")]
        names += [f"joint/{j['name']}/reaction_force", f"joint/{j['name']}/reaction_torque"]
        if j["type"] == "path":
            names += [f"joint/{j['name']}/tangential_acceleration", f"joint/{j['name']}/normal_acceleration"]
    for b in engine.bodies():
        n = b["name"]
        if n in elastic_bodies:
            names += [f"body/{n}/{x}" for x in ("elastic_q", "elastic_u", "elastic_udot", "strain_energy", "node_deflection",
                                                 "node_rotation")]
        names += [f"body/{n}/{x}" for x in ("position", "orientation", "velocity", "angular_velocity", "acceleration",
                                             "angular_acceleration", "mass", "kinetic_energy", "com_position",
                                             "com_velocity", "com_acceleration")]
        for mk in b.get("marker_frames", []):
            names += [f"marker/{n}/{mk[0]}/{x}" for x in ("position", "velocity", "acceleration", "orientation")]
    names += ["com/position", "com/velocity", "com/acceleration"]
    names += [f"energy/{x}" for x in ("kinetic", "potential", "total", "dissipated", "external_work", "dissipated_impact",
                                      "dissipated_friction", "dissipated_drift", "contact_elastic")]
    names += ["momentum/linear", "momentum/angular"]
    names += [f"solver/{x}" for x in ("residual", "iterations", "converged", "contacts", "islands")]
    for c in engine.constraints():
        names += [f"constraint/{c['name']}/{x}" for x in ("lambda", "violation", "velocity_violation")]
    for name, _ in engine.forces():
        names += [f"force/{name}/{x}" for x in ("force", "torque", "deflection")]
    for c in engine.contacts():
        names += [f"contact/{c['name']}/{x}" for x in _CONTACT_SUFFIXES]
    for g in engine.contact_groups():
        names += [f"contact/{g['name']}/{x}" for x in _GROUP_SUFFIXES]
    return names


def record_selection(engine, patterns) -> tuple[dict, list[str]]:
    """The engine's recording selection for signal-name patterns (``fnmatch``: ``*``, ``?``,
    ``[..]``) and the names they match; a pattern matching nothing is a SettingsError naming it."""
    import difflib
    import fnmatch

    from .errors import SettingsError

    if isinstance(patterns, str):
        patterns = [patterns]
    try:
        patterns = list(patterns)
    except TypeError:
        raise SettingsError(f"sensors: expected a list of signal names or patterns, got {patterns!r}") from None
    if not patterns:
        raise SettingsError("sensors: empty list (None records everything)")
    universe = signal_universe(engine)
    chosen: list[str] = []
    for p in patterns:
        if not isinstance(p, str) or not p:
            raise SettingsError(f"sensors: expected signal names or patterns (strings), got {p!r}")
        hits = fnmatch.filter(universe, p)
        if not hits:
            close = difflib.get_close_matches(p, universe, n=5, cutoff=0.6)
            hint = f"; similar: {', '.join(close)}" if close else ""
            raise SettingsError(f"sensors: '{p}' matches no signal of model '{engine.name}'{hint}")
        chosen += [h for h in hits if h not in chosen]
    body_names = [b["name"] for b in engine.bodies()]
    if any(n.startswith("com/") for n in chosen):
        bodies = body_names
    else:
        wanted = {n.split("/")[1] for n in chosen if n.startswith(("body/", "marker/"))}
        bodies = [b for b in body_names if b in wanted]
    selection = {
        "bodies": bodies,
        "accelerations": any(n.endswith(_ACCELERATION_SUFFIXES) for n in chosen),
        "constraints": any(n.startswith("constraint/") for n in chosen),
        "forces": any(n.startswith("force/") for n in chosen),
        "contacts": any(n.startswith("contact/") for n in chosen),
    }
    return selection, chosen


#: Results file format: 2 adds the completeness marker and a CRC-32 per signal.
FORMAT_VERSION = 2
#: Largest results file signal the reader accepts, bytes (a guard against crafted shapes).
MAX_SIGNAL_BYTES = 8 << 30


def _crc32(arr) -> int:
    import zlib

    return zlib.crc32(np.ascontiguousarray(arr).tobytes()) & 0xFFFFFFFF


def _read_signals(f, path: Path, size: int, checksums: bool):
    """Every dataset of an open results file, checked as untrusted input (see Results.load)."""
    import h5py

    signals: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    columns: dict[str, tuple[list, list]] = {}

    def walk(group, prefix: str) -> None:
        for key in group:
            name = f"{prefix}{key}"
            link = group.get(key, getlink=True)
            if isinstance(link, (h5py.SoftLink, h5py.ExternalLink)):
                raise ResultsError(f"'{path}': signal '{name}' is a {'soft' if isinstance(link, h5py.SoftLink) else 'external'} "
                                   "link; results files hold their data themselves (refused)")
            obj = group[key]
            if isinstance(obj, h5py.Group):
                walk(obj, name + "/")
                continue
            if not isinstance(obj, h5py.Dataset):
                raise ResultsError(f"'{path}': '{name}' is neither a signal nor a group")
            if obj.is_virtual or obj.external:
                raise ResultsError(f"'{path}': signal '{name}' keeps its data in other files (external or virtual "
                                   "dataset); refused")
            if obj.compression is not None or obj.chunks is not None and obj.id.get_create_plist().get_nfilters():
                raise ResultsError(f"'{path}': signal '{name}' is compressed or filtered; mechsys writes plain data (refused)")
            if obj.dtype.kind not in "fiub" or obj.dtype.itemsize > 8 or obj.ndim > 4:
                raise ResultsError(f"'{path}': signal '{name}' has type {obj.dtype} and {obj.ndim} dimensions; "
                                   "expected numbers in at most 4 dimensions")
            nbytes = int(np.prod(obj.shape, dtype=np.int64)) * obj.dtype.itemsize
            if nbytes > size or nbytes > MAX_SIGNAL_BYTES:
                raise ResultsError(f"'{path}': signal '{name}' declares {nbytes} bytes, more than the file holds "
                                   f"({size} bytes); refused")
            try:
                arr = np.asarray(obj[()])
            except (OSError, ValueError, TypeError) as e:
                raise ResultsError(f"'{path}': signal '{name}' cannot be read ({e})") from None
            if checksums:
                stored = obj.attrs.get("crc32")
                if stored is None:
                    raise ResultsError(f"'{path}': signal '{name}' has no checksum")
                if int(stored) != _crc32(arr):
                    raise ResultsError(f"'{path}': signal '{name}' is corrupt (checksum mismatch)")
            arr.setflags(write=False)
            signals[name] = arr
            units[name] = str(obj.attrs.get("unit", ""))
            if "columns" in obj.attrs:
                try:
                    columns[name] = (json.loads(obj.attrs["columns"]), json.loads(obj.attrs["column_units"]))
                except (KeyError, ValueError, TypeError):
                    raise ResultsError(f"'{path}': signal '{name}': unreadable column names") from None

    walk(f, "")
    return signals, units, columns


def _json_attr(attrs: dict, key: str, default: str):
    """A JSON attribute of a results file; ResultsError (not a traceback) when it is malformed."""
    try:
        return json.loads(attrs.get(key, default))
    except (ValueError, TypeError):
        raise ResultsError(f"results attribute '{key}' is not readable JSON (the file is damaged)") from None


def _check_schema(signals: dict, path: Path) -> None:
    """The shape every results file has: a 1-D, finite, non-decreasing float time ``t`` and every
    other signal one row per sample."""
    t = signals.get("t")
    if t is None:
        raise ResultsError(f"'{path}': no sample times (signal 't' missing)")
    if t.ndim != 1 or t.dtype.kind != "f" or not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
        raise ResultsError(f"'{path}': signal 't' must be 1-D, finite, non-decreasing sample times (s)")
    for name, a in signals.items():
        if a.ndim == 0 or a.shape[0] != len(t):
            raise ResultsError(f"'{path}': signal '{name}' has shape {a.shape}, not one row per sample ({len(t)})")
