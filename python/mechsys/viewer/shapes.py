"""Triangles and polylines of contours, for the viewer (body frame, float32).

Every contour of :mod:`mechsys.contours` becomes a list of drawable parts: ``{"kind": "mesh",
"v": (n, 3), "f": (m, 3)}`` or ``{"kind": "line", "v": (n, 3), "closed": bool}``. Unbounded
contours (planes, lines, bores) are cut to ``extent``, the size of the scene; a point contour is
drawn as a small sphere of radius ``marker``. The planar curves (ellipse, spline, cam, gear) are
sampled by the engine (``_core.curve_outline``), so the drawing is the contour the contact sees.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from .. import _core
from ..errors import ModelError

Part = dict[str, Any]
_SEG = 32  # segments around a circle


def _basis(axis) -> np.ndarray:
    """A right-handed frame (3x3, columns e1, e2, axis) with the unit ``axis`` as its third column."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(helper, a)
    e1 /= np.linalg.norm(e1)
    return np.column_stack([e1, np.cross(a, e1), a])


def _rotation(d: dict) -> np.ndarray:
    r = d.get("rotation")
    if not r:
        return np.eye(3)
    if "cardan" in r:
        from ..kinematics import cardan_xyz_to_matrix

        return np.asarray(cardan_xyz_to_matrix(r["cardan"]))
    if "matrix" in r:
        return np.asarray(r["matrix"], dtype=float)
    if "rotvec" in r or "euler" in r or "quaternion" in r:
        from .. import kinematics as kin

        if "rotvec" in r:
            return np.asarray(kin.rotvec_to_matrix(r["rotvec"]))
        if "euler" in r:
            return np.asarray(kin.euler_zxz_to_matrix(r["euler"]))
        return np.asarray(kin.quat_to_matrix(r["quaternion"]))
    return np.eye(3)


def _mesh(v, f) -> Part:
    return {"kind": "mesh", "v": np.asarray(v, dtype=np.float32), "f": np.asarray(f, dtype=np.uint32)}


def _line(v, closed: bool) -> Part:
    return {"kind": "line", "v": np.asarray(v, dtype=np.float32), "closed": bool(closed)}


def _grid(points: np.ndarray, wrap_u: bool, wrap_v: bool) -> Part:
    """Triangles of a (nu, nv, 3) grid of points, rows joined across the seam where wrapped."""
    nu, nv = points.shape[:2]
    idx = np.arange(nu * nv).reshape(nu, nv)
    iu = np.arange(nu if wrap_u else nu - 1)
    iv = np.arange(nv if wrap_v else nv - 1)
    a = idx[iu[:, None], iv[None, :]]
    b = idx[(iu[:, None] + 1) % nu, iv[None, :]]
    c = idx[(iu[:, None] + 1) % nu, (iv[None, :] + 1) % nv]
    d = idx[iu[:, None], (iv[None, :] + 1) % nv]
    # wound so that (profile direction) x (around direction) points out: a lathe's outside
    faces = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return _mesh(points.reshape(-1, 3), faces)


def _lathe(profile: np.ndarray, frame: np.ndarray, center, closed_profile: bool = False) -> Part:
    """The surface of a profile (r, h) turned about the third column of ``frame`` at ``center``."""
    phi = np.linspace(0.0, 2 * np.pi, _SEG, endpoint=False)
    r, h = profile[:, 0], profile[:, 1]
    local = np.stack([r[:, None] * np.cos(phi)[None, :], r[:, None] * np.sin(phi)[None, :],
                      np.broadcast_to(h[:, None], (len(r), len(phi)))], -1)
    pts = local @ frame.T + np.asarray(center, dtype=float)
    return _grid(pts, closed_profile, True)


def _sphere_points(n_lat: int = 16) -> np.ndarray:
    th = np.linspace(0.0, np.pi, n_lat + 1)
    return np.column_stack([np.sin(th), -np.cos(th)])


def _disc(outline2: np.ndarray, z: float = 0.0) -> list[Part]:
    """A planar closed outline filled from its centroid (the planar contours are star-shaped about
    it: circles, ellipses, cams, gears, convex polygons) and its edge as a line."""
    c = outline2.mean(axis=0)
    n = len(outline2)
    v = np.vstack([[c[0], c[1], z], np.column_stack([outline2, np.full(n, z)])])
    f = np.column_stack([np.zeros(n, dtype=np.uint32), 1 + np.arange(n), 1 + (np.arange(n) + 1) % n])
    return [_mesh(v, f), _line(v[1:], True)]


def _planar_band(p0, p1, normal2, width: float, z: float = 0.0) -> list[Part]:
    """A strip of ``width`` behind the segment p0-p1 (the solid side of a line contour)."""
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    back = -np.asarray(normal2, dtype=float) * width
    v = np.array([[*p0, z], [*p1, z], [*(p1 + back), z], [*(p0 + back), z]])
    return [_mesh(v, [[0, 1, 2], [0, 2, 3]]), _line(v[:2], False)]


def contour_parts(d: dict, extent: float, marker: float, what: str = "contour", bounds=None) -> list[Part]:
    """Drawable parts of a contour description ``d`` (a contour table, body frame); ``bounds``
    (low and high corners, body frame) limits a plane to the part under the motion."""
    kind = d.get("type")
    center = np.asarray(d.get("center", (0.0, 0.0, 0.0)), dtype=float)
    if kind == "point":
        return [dict(_lathe(_sphere_points(8) * marker, np.eye(3), d["position"]), marker=True)]
    if kind == "sphere":
        return [_lathe(_sphere_points() * d["radius"], np.eye(3), center)]
    if kind == "bowl":
        # the cavity: its lower half as a shell, seen from inside
        prof = _sphere_points()[: 9] * d["radius"]
        return [dict(_lathe(prof, np.eye(3), center), side="double", opacity=0.35)]
    if kind == "ellipsoid":
        part = _lathe(_sphere_points(), np.eye(3), (0.0, 0.0, 0.0))
        part["v"] = (part["v"] * np.asarray(d["semi_axes"])) @ _rotation(d).T + center
        part["v"] = part["v"].astype(np.float32)
        return [part]
    if kind == "box":
        h = np.asarray(d["half_extents"], dtype=float)
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float) * h
        v = corners @ _rotation(d).T + center
        f = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
             [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
        return [_mesh(v, f)]
    if kind == "capsule":
        a, b = np.asarray(d["a"], dtype=float), np.asarray(d["b"], dtype=float)
        r, length = d["radius"], float(np.linalg.norm(b - a))
        axis = (b - a) / length if length > 0 else np.array([0.0, 0.0, 1.0])
        s = _sphere_points()
        prof = np.vstack([s[: 9] * r, s[8:] * r + [0.0, length]])
        return [_lathe(prof, _basis(axis), a)]
    if kind == "cylinder":
        r, hl = d["radius"], d["half_length"]
        prof = np.array([[0.0, -hl], [r, -hl], [r, -hl], [r, hl], [r, hl], [0.0, hl]])
        return [_lathe(prof, _basis(d["axis"]), center)]
    if kind == "bore":
        r = d["radius"]
        prof = np.array([[r, -extent / 2], [r, extent / 2]])
        return [dict(_lathe(prof, _basis(d["axis"]), center), side="double", opacity=0.35)]
    if kind == "torus":
        th = np.linspace(0.0, 2 * np.pi, 17)
        tube = max(d["tube"], 1e-3 * d["radius"])
        prof = np.column_stack([d["radius"] + tube * np.cos(th), tube * np.sin(th)])
        return [_lathe(prof, _basis(d["axis"]), center, closed_profile=False)]
    if kind == "plane":
        n = np.asarray(d["normal"], dtype=float)
        n = n / np.linalg.norm(n)
        frame = _basis(n)
        p = np.asarray(d["point"], dtype=float)
        if bounds is not None:
            # the part of the plane under the motion: the bounds' corners projected on it, with a margin
            lo, hi = np.asarray(bounds[0], dtype=float), np.asarray(bounds[1], dtype=float)
            corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
            c1, c2 = (corners - p) @ frame[:, 0], (corners - p) @ frame[:, 1]
            pad = 0.25 * extent / 3
            a1, b1, a2, b2 = c1.min() - pad, c1.max() + pad, c2.min() - pad, c2.max() + pad
        else:
            a1 = a2 = -extent / 2
            b1 = b2 = extent / 2
        e1, e2 = frame[:, 0], frame[:, 1]
        v = np.array([p + a1 * e1 + a2 * e2, p + b1 * e1 + a2 * e2, p + b1 * e1 + b2 * e2, p + a1 * e1 + b2 * e2])
        return [dict(_mesh(v, [[0, 1, 2], [0, 2, 3]]), side="double", ground=True, normal=n.tolist())]
    if kind == "line":
        n = np.asarray(d["normal"][:2], dtype=float)
        n /= np.linalg.norm(n)
        t = np.array([-n[1], n[0]])
        p = np.asarray(d["point"][:2], dtype=float)
        return _planar_band(p - t * extent / 2, p + t * extent / 2, n, 0.5 * marker, float(d["point"][2]))
    if kind == "circle":
        phi = np.linspace(0.0, 2 * np.pi, 2 * _SEG, endpoint=False)
        out = np.column_stack([np.cos(phi), np.sin(phi)]) * d["radius"] + center[:2]
        return _disc(out, float(center[2]))
    if kind == "polygon":
        return _disc(np.asarray(d["vertices"], dtype=float))
    if kind in ("ellipse", "spline", "cam", "gear"):
        samples = 2000 if kind == "gear" else 400
        out = np.asarray(_core.curve_outline(json.dumps(d), what, samples))
        closed = kind != "spline" or bool(d.get("closed"))
        if closed and d.get("solid") != "outside":
            return _disc(out)
        return [_line(np.column_stack([out, np.zeros(len(out))]), closed)]
    if kind == "revolution":
        prof_d = d["profile"]
        out = np.asarray(_core.curve_outline(json.dumps(prof_d), f"{what}.profile", 200))
        closed = prof_d["type"] != "spline" or bool(prof_d.get("closed"))
        if closed:
            out = out[out[:, 0] >= 0] if (out[:, 0] < 0).any() else out
            order = np.argsort(out[:, 1])
            out = out[order]
        return [_lathe(out, _rotation(d), center)]
    if kind == "patch":
        pts = np.asarray(d["points"], dtype=float)
        return [dict(_grid(pts, False, False), side="double")]
    if kind == "mesh":
        return [dict(_mesh(d["vertices"], d["triangles"]), side="double")]
    raise ModelError(f"{what}: the viewer cannot draw a contour of type {kind!r}")


def extent_of(d: dict) -> float:
    """A length typical of a bounded contour (0 for the unbounded ones), for the scene's scale."""
    kind = d.get("type")
    if kind in ("sphere", "bowl", "circle", "cylinder", "bore", "torus"):
        return 2.0 * float(d.get("radius", 0.0)) + float(d.get("tube", 0.0))
    if kind in ("box",):
        return 2.0 * float(max(d["half_extents"]))
    if kind in ("ellipsoid", "ellipse"):
        return 2.0 * float(max(d["semi_axes"]))
    if kind == "capsule":
        return float(np.linalg.norm(np.subtract(d["b"], d["a"]))) + 2.0 * d["radius"]
    if kind in ("polygon", "spline"):
        p = np.asarray(d.get("vertices", d.get("points")), dtype=float)
        return float(np.ptp(p, axis=0).max()) if len(p) else 0.0
    if kind == "mesh" or kind == "patch":
        p = np.asarray(d.get("vertices", d.get("points")), dtype=float).reshape(-1, 3)
        return float(np.ptp(p, axis=0).max()) if len(p) else 0.0
    if kind == "cam":
        return 2.0 * (float(d["base_radius"]) + max(d["lift"]) + float(d.get("roller_radius", 0.0)))
    if kind == "gear":
        m = d.get("module") or 2.0 * d.get("base_radius", 0.0) / d["teeth"] / math.cos(d["pressure_angle"])
        return float(m) * (d["teeth"] + 2)
    return 0.0
