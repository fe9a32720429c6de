"""The browser viewer: one self-contained HTML page per result, no server, no network.

``to_html(res, "page.html")`` (or ``res.to_html(...)``, ``mechsys view results.h5``) writes a
page with the 3D scene (three.js), a timeline, contact arrows and plots of chosen signals, all
data inside the file as base64 typed arrays. ``view(res)`` shows it inline in Jupyter or opens a
browser. ``mode_results(lin, k)`` turns a mode of :mod:`mechsys.linear` into an animation the
same page plays.

What the page shows:

* bodies from their contact contours and visuals (``Model.add_visual``: contours or meshes); a
  body with neither is drawn as rods from its centre of mass to its joints and attachment points;
* joint frames and markers as axis triads (toggle "frames"), the path of chosen points as
  trails, a camera that orbits, pans, zooms and follows a body;
* contacts (rigid and compliant): a dot at the contact point, the normal force and the friction force as arrows scaled
  by magnitude, coloured by state (open grey, stick blue, slip orange), impacts flashed at their
  events; a contact group's closed points with their whole contact force as one arrow;
* plots of signals with a cursor following the timeline; a click on a plot moves the timeline.

Frames are decimated to at most ``max_frames`` (uniform in time, plus every event's sample), so
a long record opens fast; plots keep each bucket's extremes so peaks survive the decimation.
"""

from __future__ import annotations

import base64
import html
import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np

from ..errors import ResultsError, SettingsError
from .shapes import contour_parts, extent_of

__all__ = ["page_data", "to_html", "view", "mode_results", "bundle_path"]

_BUNDLE = Path(__file__).parent / "_bundle"
_MAX_GROUP_SLOTS = 400  # contact points drawn per group and frame


def bundle_path() -> Path:
    """The built JavaScript bundle (three.js, uPlot and the viewer), or a clear error."""
    js = _BUNDLE / "viewer.js"
    if not js.is_file():
        raise ResultsError(
            f"the viewer's JavaScript bundle is missing ({js}); it is built from the pinned npm packages "
            "by `make viewer` (needs Node.js and npm), which `make build` runs when npm is found")
    return js


def _b64(a: np.ndarray, dtype: str) -> dict:
    arr = np.ascontiguousarray(np.asarray(a, dtype=dtype))
    if arr.dtype.byteorder == ">":
        arr = arr.byteswap().view(arr.dtype.newbyteorder("<"))
    return {"b64": base64.b64encode(arr.tobytes()).decode("ascii"), "dtype": np.dtype(dtype).name,
            "shape": list(arr.shape)}


def _finite(a: np.ndarray) -> np.ndarray:
    """NaN-free for drawing: NaN (a not-yet-closed contact's point) becomes 0 and is masked by state."""
    return np.nan_to_num(np.asarray(a, dtype=float), nan=0.0, posinf=0.0, neginf=0.0)


@dataclass
class _Motion:
    """What the page plays: times, body poses, the model description, optional contacts/signals."""

    t: np.ndarray
    model: dict
    bodies: list[str]
    position: np.ndarray          # (F, B, 3)
    orientation: np.ndarray       # (F, B, 4) w x y z
    results: Any = None
    title: str = ""
    events: list = field(default_factory=list)
    #: elastic coordinates per elastic body name, (F, n_e)
    elastic: dict = field(default_factory=dict)


def _motion(res) -> _Motion:
    model = res.model
    bodies = [b["name"] for b in model.get("bodies", [])]
    t = np.asarray(res.t, dtype=float)
    have = all(f"body/{b}/position" in res and f"body/{b}/orientation" in res for b in bodies)
    if have:
        pos = np.stack([np.asarray(res[f"body/{b}/position"]) for b in bodies], 1) if bodies else np.zeros((len(t), 0, 3))
        rot = np.stack([np.asarray(res[f"body/{b}/orientation"]) for b in bodies], 1) if bodies else np.zeros((len(t), 0, 4))
    elif (q := _coordinates(res, model)) is not None:
        pos, rot = _poses_from_q(model, q)
    else:
        raise ResultsError("the results hold neither the bodies' poses (body/*/position, body/*/orientation) nor the "
                           "coordinates (q or every joint/*/q); record them (sensors='body/*') to view this run")
    elastic = {b["name"]: np.asarray(res[f"body/{b['name']}/elastic_q"]) for b in model.get("bodies", [])
               if b.get("elastic") and f"body/{b['name']}/elastic_q" in res}
    return _Motion(t, model, bodies, pos, rot, results=res, title=model.get("name", ""), events=list(res.events),
                   elastic=elastic)


def _coordinates(res, model_dict: dict):
    """q of every sample: the recorded ``q``, or assembled from each joint's ``joint/<j>/q``."""
    if "q" in res:
        return np.asarray(res["q"])
    from ..model import Model

    joints = Model.from_dict(model_dict).build().joints()
    n = len(res.t)
    q = np.zeros((n, sum(j["nq"] for j in joints)))
    for j in joints:
        if j["nq"] == 0:
            continue
        name = f"joint/{j['name']}/q"
        if name not in res:
            return None
        q[:, j["iq"]: j["iq"] + j["nq"]] = np.asarray(res[name]).reshape(n, j["nq"])
    return q


def _poses_from_q(model_dict: dict, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    from ..kinematics import body_states, matrix_to_quat
    from ..model import Model

    m = Model.from_dict(model_dict)
    n = len(model_dict.get("bodies", []))
    pos = np.zeros((len(q), n, 3))
    rot = np.zeros((len(q), n, 4))
    for k, qk in enumerate(q):
        st = body_states(m, qk)
        # body_states lists the ground first
        p, a = np.asarray(st["position"])[-n:], np.asarray(st["rotation"])[-n:]
        pos[k] = p
        rot[k] = [matrix_to_quat(ai) for ai in a]
    return pos, rot


def mode_results(lin, mode: int = 0, *, amplitude: float | None = None, cycles: float = 2.0,
                 frames_per_cycle: int = 48) -> _Motion:
    """An animation of mode ``mode`` (from 0, in the order of ``lin.modes()``) of a linearization
    ``lin`` (:func:`mechsys.linear.linearize`): the coordinates q0 + a Re(φ e^{iωt}) over
    ``cycles`` periods of the damped (or undamped) frequency, the largest coordinate swinging by
    ``amplitude`` (default: a tenth of the scene size in metres or 0.2 rad). Pass it to
    :func:`to_html` or :func:`view` like a result."""
    from ..linear import LinearModel

    if not isinstance(lin, LinearModel) or lin.model is None:
        raise SettingsError("mode_results: expected a linearization from mechsys.linear.linearize(model, ...)")
    modes = lin.modes()
    if not (isinstance(mode, (int, np.integer)) and 0 <= mode < len(modes.eigenvalues)):
        raise SettingsError(f"mode_results: mode must be a whole number in [0, {len(modes.eigenvalues) - 1}], got {mode!r}")
    model = lin.model
    if model.build().nq != model.build().nu:
        raise SettingsError("mode_results: animating modes of models with free or spherical joints (quaternion "
                            "coordinates) is not supported yet")
    shape = np.asarray(modes.shapes_u[:, mode])
    f = float(modes.damped_frequency[mode]) or float(modes.natural_frequency[mode])
    desc = model.to_dict()
    a = 0.2 if amplitude is None else float(amplitude)
    if not np.isfinite(a) or a <= 0:
        raise SettingsError(f"mode_results: amplitude must be a positive number, got {amplitude!r}")
    n = max(2, int(round(cycles * frames_per_cycle)))
    if f > 0:
        t = np.linspace(0.0, cycles / f, n + 1)
        phase = np.exp(1j * 2 * np.pi * f * t)
    else:
        # a static (zero-frequency) mode: a slow back-and-forth of its shape
        t = np.linspace(0.0, float(cycles), n + 1)
        phase = np.sin(2 * np.pi * t / cycles) + 0j
    q = np.asarray(lin.q)[None, :] + a * np.real(shape[None, :] * phase[:, None])
    pos, rot = _poses_from_q(desc, q)
    title = (f"{desc.get('name', 'model')}: mode {mode + 1}, f = {modes.natural_frequency[mode]:.4g} Hz, "
             f"zeta = {modes.damping_ratio[mode]:.3g}")
    m = _Motion(t, desc, [b["name"] for b in desc.get("bodies", [])], pos, rot, title=title,
                elastic={e["body"]: q[:, e["iq"]: e["iq"] + e["ne"]] for e in model.build().elastic()})
    m.results = _ModeSignals(t, q, [str(x) for x in lin.names] if lin.names else [f"q{i}" for i in range(q.shape[1])])
    return m


class _ModeSignals:
    """The coordinates of a mode animation as a signal the plots can show."""

    def __init__(self, t, q, names):
        self.t, self._q, self._names = t, q, names
        self.events: list = []

    def __contains__(self, name):
        return name == "q"

    def __getitem__(self, name):
        return self._q

    def names(self):
        return ["q"]

    def unit(self, name):
        return "mixed"

    def columns(self, name):
        return self._names


def _frame_indices(t: np.ndarray, events: list, max_frames: int) -> np.ndarray:
    n = len(t)
    if n <= max_frames:
        return np.arange(n)
    grid = np.linspace(t[0], t[-1], max_frames)
    idx = np.clip(np.searchsorted(t, grid), 0, n - 1)
    ev = np.array([e.get("t", np.nan) for e in events[:2000]], dtype=float)
    ev = ev[np.isfinite(ev)]
    if len(ev):
        idx = np.concatenate([idx, np.clip(np.searchsorted(t, ev), 0, n - 1)])
    return np.unique(idx)


def _decimate_minmax(t: np.ndarray, y: np.ndarray, points: int) -> tuple[np.ndarray, np.ndarray]:
    """At most about ``points`` samples keeping each bucket's first, smallest and largest values
    (per column), so a short peak stays visible."""
    n = len(t)
    if n <= points:
        return t, y
    buckets = max(1, points // 3)
    edges = np.linspace(0, n, buckets + 1).astype(int)
    keep = set()
    y2 = y.reshape(n, -1)
    for a, b in zip(edges[:-1], edges[1:]):
        if b <= a:
            continue
        keep.add(a)
        seg = y2[a:b]
        with np.errstate(invalid="ignore"):
            finite = np.where(np.isfinite(seg), seg, np.nan)
        if np.isfinite(finite).any():
            keep.update((a + np.nanargmin(np.where(np.isfinite(finite), finite, np.inf), axis=0)).tolist())
            keep.update((a + np.nanargmax(np.where(np.isfinite(finite), finite, -np.inf), axis=0)).tolist())
    keep.add(n - 1)
    idx = np.array(sorted(keep))
    return t[idx], y[idx]


def _default_signals(res) -> list[str]:
    names = []
    contacts = [c["name"] for c in (res.model.get("contacts", []) if hasattr(res, "model") else [])]
    for c in contacts[:2]:
        if f"contact/{c}/lambda_n" in res:
            names.append(f"contact/{c}/lambda_n")
        elif f"contact/{c}/force_n" in res:
            names.append(f"contact/{c}/force_n")
    if "energy/total" in res and not names:
        names.append("energy/total")
    if "q" in res and np.asarray(res["q"]).reshape(len(res.t), -1).shape[1] <= 6:
        names.insert(0, "q")
    return names[:3]


def _body_shapes(model: dict, extent: float, marker: float, bounds=None, up=None) -> dict[str, list[dict]]:
    """Drawable parts per body ("ground" included) from contacts, groups and visuals, each contour
    once even when several contacts use it."""
    seen: dict[str, set] = {}
    out: dict[str, list[dict]] = {}

    def add(body: str, contour: dict, what: str, color=None, opacity=None, name: str = "") -> None:
        key = json.dumps(contour, sort_keys=True)
        if key in seen.setdefault(body, set()):
            return
        seen[body].add(key)
        for part in contour_parts(contour, extent, marker, what, bounds if body == "ground" else None):
            if part.get("ground") and up is not None and abs(float(np.dot(part["normal"], up))) < 0.7:
                # a wall: seen through, so it hides nothing
                part["opacity"] = 0.25
            if color is not None:
                part["color"] = list(color)
            if opacity is not None:
                part["opacity"] = float(opacity)
            part["name"] = name or contour.get("type", "")
            out.setdefault(body, []).append(part)

    for c in model.get("contacts", []):
        for k in ("1", "2"):
            add(c[f"body{k}"], c[f"contour{k}"], f"contact '{c['name']}'.contour{k}", name=f"{c['name']}.contour{k}")
    for g in model.get("contact_groups", []):
        for key in ("members", "against"):
            for k, m in enumerate(g.get(key, [])):
                add(m["body"], m["contour"], f"contact group '{g['name']}'.{key}[{k}]", name=g["name"])
    for i, v in enumerate(model.get("visuals", [])):
        add(v["body"], v["shape"], f"visuals[{i}]", v.get("color"), v.get("opacity"), v.get("name") or f"visual {i}")
    return out


def _rods(model: dict, body: str, com, rod: float) -> list[dict]:
    """Rods from a body's centre of mass to its joints' and constraints' attachment points."""
    from .shapes import _basis, _lathe

    pts = []
    for j in model.get("joints", []):
        if j.get("child") == body:
            pts.append((j.get("child_frame") or {}).get("position", [0, 0, 0]))
        if j.get("parent") == body:
            pts.append((j.get("parent_frame") or {}).get("position", [0, 0, 0]))
    for c in model.get("constraints", []):
        for k in ("1", "2"):
            if c.get(f"body{k}") == body and f"point{k}" in c:
                pts.append(c[f"point{k}"])
    for f in model.get("forces", []):
        for k in ("1", "2"):
            if f.get(f"body{k}") == body and f"point{k}" in f:
                pts.append(f[f"point{k}"])
    com = np.asarray(com, dtype=float)
    if len(pts) == 1:
        # one attachment (a pendulum's rod): drawn through the centre of mass to its mirror point,
        # the length of a uniform rod
        pts.append((2.0 * com - np.asarray(pts[0], dtype=float)).tolist())
    parts = []
    for p in pts:
        p = np.asarray(p, dtype=float)
        d = p - com
        length = float(np.linalg.norm(d))
        if length < 1e-12:
            continue
        prof = np.array([[0.0, 0.0], [rod, 0.0], [rod, length], [0.0, length]])
        parts.append(dict(_lathe(prof, _basis(d / length), com), name="rod"))
    return parts


def _triads(model: dict) -> dict[str, list]:
    """Frames to draw as axis triads per body: joint frames on both sides and markers."""
    from ..kinematics import cardan_xyz_to_quat, euler_zxz_to_quat, matrix_to_quat, rotvec_to_quat

    def quat(rot) -> list:
        if not rot:
            return [1.0, 0.0, 0.0, 0.0]
        try:
            if "cardan" in rot:
                return list(map(float, cardan_xyz_to_quat(rot["cardan"])))
            if "euler" in rot:
                return list(map(float, euler_zxz_to_quat(rot["euler"])))
            if "rotvec" in rot:
                return list(map(float, rotvec_to_quat(rot["rotvec"])))
            if "matrix" in rot:
                return list(map(float, matrix_to_quat(rot["matrix"])))
            if "quaternion" in rot:
                return list(map(float, rot["quaternion"]))
        except Exception:  # noqa: BLE001 - a frame the engine accepted but we cannot draw: identity
            pass
        return [1.0, 0.0, 0.0, 0.0]

    out: dict[str, list] = {}
    for j in model.get("joints", []):
        for side, frame in (("parent", "parent_frame"), ("child", "child_frame")):
            fr = j.get(frame) or {}
            out.setdefault(j[side], []).append({"name": f"joint {j['name']}", "p": list(fr.get("position", [0, 0, 0])),
                                               "q": quat(fr.get("rotation"))})
    for b in model.get("bodies", []):
        for mk in b.get("markers", []):
            out.setdefault(b["name"], []).append({"name": f"marker {mk['name']}", "p": list(mk.get("position", [0, 0, 0])),
                                                 "q": quat(mk.get("rotation"))})
    for mk in model.get("ground_markers", []):
        out.setdefault("ground", []).append({"name": f"marker {mk['name']}", "p": list(mk.get("position", [0, 0, 0])),
                                            "q": quat(mk.get("rotation"))})
    return out


def _parse_trail(spec, bodies: list[str]) -> tuple[str, np.ndarray]:
    if isinstance(spec, str):
        name, _, point = spec.partition(":")
        p = [float(x) for x in point.split(",")] if point else [0.0, 0.0, 0.0]
    else:
        name, p = spec[0], list(spec[1]) if len(spec) > 1 else [0.0, 0.0, 0.0]
    if name not in bodies:
        raise SettingsError(f"trail: no body '{name}' in the model (bodies: {', '.join(bodies) or 'none'})")
    if len(p) != 3 or not all(np.isfinite(p)):
        raise SettingsError(f"trail '{name}': the point must be three finite numbers (body frame), got {p}")
    return name, np.asarray(p, dtype=float)


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotates body-frame vector v by unit quaternions q (F, 4) (w x y z)."""
    w, x = q[:, :1], q[:, 1:]
    t = 2.0 * np.cross(x, v)
    return v + w * t + np.cross(x, t)


def page_data(source, *, signals: Sequence[str] | None = None, max_frames: int = 1500, trails: Iterable = (),
              follow: str | None = None, plot_points: int = 2000, title: str | None = None) -> dict:
    """The page's data (plain JSON with base64 arrays) for a :class:`mechsys.Results` or a mode
    animation (:func:`mode_results`). ``signals``: names to plot (default: coordinates and the
    first contacts' normal forces); ``trails``: body names or ``"body:x,y,z"`` / ``(body, point)``
    whose path is drawn; ``follow``: the body the camera follows at start."""
    m = source if isinstance(source, _Motion) else _motion(source)
    if isinstance(max_frames, bool) or not isinstance(max_frames, (int, np.integer)) or max_frames < 2:
        raise SettingsError(f"max_frames: expected a whole number ≥ 2, got {max_frames!r}")
    if len(m.t) == 0:
        raise ResultsError("the results hold no samples")
    idx = _frame_indices(m.t, m.events, int(max_frames))
    t = m.t[idx]
    pos, rot = _finite(m.position[idx]), _finite(m.orientation[idx])
    model = m.model

    # scene size: the bodies' travel and their bounded contours
    sizes = [extent_of(c[f"contour{k}"]) for c in model.get("contacts", []) for k in ("1", "2")]
    sizes += [extent_of(mm["contour"]) for g in model.get("contact_groups", []) for key in ("members", "against")
              for mm in g.get(key, [])]
    sizes += [extent_of(v["shape"]) for v in model.get("visuals", [])]
    for j in model.get("joints", []):
        for fr in ("parent_frame", "child_frame"):
            sizes.append(2.0 * float(np.linalg.norm((j.get(fr) or {}).get("position", [0, 0, 0]))))
    travel = float(np.ptp(pos.reshape(-1, 3), axis=0).max()) if pos.size else 0.0
    scene = max([travel, *sizes, 1e-3])
    marker = 0.015 * scene
    lo = pos.reshape(-1, 3).min(axis=0) if pos.size else np.zeros(3)
    hi = pos.reshape(-1, 3).max(axis=0) if pos.size else np.zeros(3)
    g = np.asarray(model.get("gravity", [0, 0, 0]), dtype=float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else None
    shapes = _body_shapes(model, 3.0 * scene, marker, (lo, hi), up)
    triads = _triads(model)

    body_entries = []
    for k, b in enumerate(m.bodies):
        bd = next(x for x in model["bodies"] if x["name"] == b)
        parts = list(shapes.get(b, []))
        # a body drawn only by point contours (markers) gets its rods too; an elastic body with
        # nodes is drawn by its deforming node line instead
        drawn_by_contours = any(not p.get("marker") for p in parts) or bool((bd.get("elastic") or {}).get("nodes"))
        if not drawn_by_contours:
            parts += _rods(model, b, bd.get("com", [0, 0, 0]), 0.3 * marker)
            from .shapes import _lathe, _sphere_points

            parts.append(dict(_lathe(_sphere_points(10) * 1.5 * marker, np.eye(3), bd.get("com", [0, 0, 0])), name="com"))
        body_entries.append({"name": b, "parts": [_encode_part(p) for p in parts], "triads": triads.get(b, []),
                             "stick": not drawn_by_contours})
    ground = {"name": "ground", "parts": [_encode_part(p) for p in shapes.get("ground", [])], "triads": triads.get("ground", [])}

    out: dict[str, Any] = {
        "title": title or m.title or "mechsys",
        "bounds": [lo.tolist(), hi.tolist()],
        "planar": bool(model.get("planar", False)) or _is_planar(model, pos),
        "gravity": list(model.get("gravity", [0, 0, 0])),
        "scene": scene,
        "t": _b64(t, "float64"),
        "frames": int(len(t)),
        "recorded": int(len(m.t)),
        "bodies": body_entries,
        "ground": ground,
        "pose": _b64(np.concatenate([pos, rot], axis=2), "float32"),
        "follow": follow if follow in m.bodies else None,
    }
    if follow is not None and follow not in m.bodies:
        raise SettingsError(f"follow: no body '{follow}' in the model (bodies: {', '.join(m.bodies) or 'none'})")

    out["elastic"] = _elastic_lines(model, m, idx, scene)
    res = m.results
    out["contacts"] = _contacts(res, model, idx, scene) if res is not None and hasattr(res, "model") else []
    names = [c["name"] for c in out["contacts"]]
    kinds = sorted({e.get("event", "?") for e in m.events})
    ev_t = np.array([e.get("t", np.nan) for e in m.events], dtype=float)
    ev_c = np.array([names.index(e["contact"]) if e.get("contact") in names else -1 for e in m.events], dtype=np.int32)
    ev_k = np.array([kinds.index(e.get("event", "?")) for e in m.events], dtype=np.int32)
    out["events"] = {"kinds": kinds, "t": _b64(ev_t, "float64"), "contact": _b64(ev_c, "int32"), "kind": _b64(ev_k, "int32")}

    trail_out = []
    for spec in trails:
        name, p = _parse_trail(spec, m.bodies)
        b = m.bodies.index(name)
        path = pos[:, b, :] + _rotate(rot[:, b, :], p)
        trail_out.append({"body": name, "point": p.tolist(), "path": _b64(path, "float32")})
    out["trails"] = trail_out

    plots = []
    if res is not None:
        chosen = list(signals) if signals is not None else _default_signals(res)
        for name in chosen:
            if name not in res:
                avail = [n for n in res.names() if n != "t"]
                raise SettingsError(f"signal '{name}' is not in the results (some of those there: {', '.join(avail[:12])}"
                                    f"{', ...' if len(avail) > 12 else ''})")
            y = np.asarray(res[name], dtype=float)
            tt = np.asarray(res.t, dtype=float)
            y2 = y.reshape(len(tt), -1)
            if y2.shape[1] > 12:
                y2 = y2[:, :12]
            td, yd = _decimate_minmax(tt, y2, int(plot_points))
            try:
                cols = list(res.columns(name))[: y2.shape[1]]
            except Exception:  # noqa: BLE001 - a signal without column names: number them
                cols = [str(i) for i in range(y2.shape[1])]
            if len(cols) != y2.shape[1]:
                cols = [str(i) for i in range(y2.shape[1])]
            plots.append({"name": name, "unit": res.unit(name), "columns": cols, "t": _b64(td, "float64"),
                          "y": [_b64(np.nan_to_num(yd[:, k], nan=np.nan), "float32") for k in range(yd.shape[1])]})
    out["plots"] = plots
    return out


def _elastic_lines(model: dict, m: _Motion, idx: np.ndarray, scene: float) -> list[dict]:
    """Per elastic body with nodes: the undeformed node line (body frame) and the node
    displacements of every kept frame, with a magnification that makes the largest deflection
    about 5 % of the scene (a power of ten; 1 when the deflection is already that large)."""
    out = []
    for b in model.get("bodies", []):
        el = b.get("elastic") or {}
        nodes = el.get("nodes") or []
        if not nodes or b["name"] not in m.elastic or b["name"] not in m.bodies:
            continue
        pos0 = np.array([n["position"] for n in nodes], dtype=float)
        trans = np.array([n["translation"] for n in nodes], dtype=float)  # (n, n_e, 3)
        qe = np.asarray(m.elastic[b["name"]], dtype=float)[idx]
        disp = np.einsum("fk,nkc->fnc", qe, trans)
        big = float(np.abs(disp).max(initial=0.0))
        scale = 1.0
        if 0.0 < big < 0.05 * scene:
            scale = float(10.0 ** np.floor(np.log10(0.05 * scene / big)))
        out.append({"body": m.bodies.index(b["name"]), "nodes": _b64(pos0, "float32"),
                    "disp": _b64(_finite(disp), "float32"), "scale": scale, "largest": big})
    return out


def _is_planar(model: dict, pos: np.ndarray) -> bool:
    """Everything moves in the x-y plane and the ground's contours are planar ones."""
    if pos.size and np.ptp(pos[..., 2]) > 1e-12:
        return False
    planar_kinds = {"point", "circle", "line", "polygon", "ellipse", "spline", "cam", "gear"}
    kinds = {c[f"contour{k}"].get("type") for c in model.get("contacts", []) for k in ("1", "2")}
    return bool(kinds) and kinds <= planar_kinds


def _encode_part(p: dict) -> dict:
    out = {k: v for k, v in p.items() if k not in ("v", "f")}
    out["v"] = _b64(p["v"], "float32")
    if "f" in p:
        out["f"] = _b64(p["f"], "uint32")
    return out


def _contacts(res, model: dict, idx: np.ndarray, scene: float) -> list[dict]:
    out = []
    fmax = 0.0
    raw = []
    for c in model.get("contacts", []):
        name = c["name"]
        if f"contact/{name}/point" not in res:
            continue
        p = np.asarray(res[f"contact/{name}/point"])[idx]
        n = np.asarray(res[f"contact/{name}/normal"])[idx]
        ft = np.asarray(res[f"contact/{name}/friction_force"])[idx] if f"contact/{name}/friction_force" in res \
            else np.zeros(p.shape)
        if f"contact/{name}/lambda_n" in res:
            ln = np.asarray(res[f"contact/{name}/lambda_n"])[idx]
            st = np.asarray(res[f"contact/{name}/state"])[idx]
        else:
            # a compliant contact: its force where it overlaps; drawn as slipping where it slides
            # (faster than 1 µm/s), as sticking otherwise, hidden while open
            ln = np.asarray(res[f"contact/{name}/force_n"])[idx]
            over = np.asarray(res[f"contact/{name}/overlap"])[idx] > 0
            slip = np.asarray(res[f"contact/{name}/slip_velocity"])[idx]
            speed = np.abs(slip) if slip.ndim == over.ndim else np.linalg.norm(slip, axis=-1)
            st = np.where(over, np.where(speed > 1e-6, 2, 1), 0)
        if p.ndim == 2:
            p, n, ft, ln, st = p[:, None], n[:, None], ft[:, None], ln[:, None], st[:, None]
        for k in range(p.shape[1]):
            label = name if p.shape[1] == 1 else f"{name}[{k}]"
            raw.append((label, name, p[:, k], n[:, k], ln[:, k], ft[:, k], st[:, k]))
            fmax = max(fmax, float(np.nanmax(np.abs(_finite(ln[:, k])), initial=0.0)),
                       float(np.nanmax(np.linalg.norm(_finite(ft[:, k]), axis=-1), initial=0.0)))
    # contact groups: the points closed in the last step before each sample (padded slots)
    for g in model.get("contact_groups", []):
        name = g["name"]
        if f"contact/{name}/points" not in res:
            continue
        p = np.asarray(res[f"contact/{name}/points"])[idx][:, :_MAX_GROUP_SLOTS]
        f = np.asarray(res[f"contact/{name}/point_forces"])[idx][:, :_MAX_GROUP_SLOTS]
        st = np.asarray(res[f"contact/{name}/point_states"])[idx][:, :_MAX_GROUP_SLOTS]
        for k in range(p.shape[1]):
            fk = _finite(f[:, k])
            # the force split along and across the normal is not recorded: the whole force is
            # drawn as the "normal" arrow, no friction arrow
            ln = np.linalg.norm(fk, axis=1)
            unit = np.divide(fk, ln[:, None], out=np.zeros_like(fk), where=ln[:, None] > 0)
            raw.append((f"{name}[{k}]", name, p[:, k], unit, ln, np.zeros_like(fk), st[:, k]))
            fmax = max(fmax, float(ln.max(initial=0.0)))
    scale = 0.2 * scene / fmax if fmax > 0 else 0.0
    for label, name, p, n, ln, ft, st in raw:
        out.append({"name": label, "contact": name, "point": _b64(_finite(p), "float32"),
                    "normal": _b64(_finite(n) * _finite(ln)[:, None] * scale, "float32"),
                    "friction": _b64(_finite(ft) * scale, "float32"), "state": _b64(_finite(st), "int8"),
                    "lambda_n": _b64(_finite(ln), "float32")})
    return out


def _template() -> str:
    return (Path(__file__).parent / "page.html").read_text(encoding="utf-8")


def to_html(source, path: str | Path | None = None, **options) -> Path | str:
    """Writes the viewer page of ``source`` (a :class:`mechsys.Results` or :func:`mode_results`) to
    ``path`` and returns the path; with ``path=None`` returns the page as a string. Options as
    :func:`page_data`."""
    data = page_data(source, **options)
    js = bundle_path().read_text(encoding="utf-8")
    css_file = _BUNDLE / "uPlot.min.css"
    css = css_file.read_text(encoding="utf-8") if css_file.is_file() else ""
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    page = (_template().replace("/*@CSS@*/", css).replace("@TITLE@", html.escape(data["title"]))
            .replace("/*@DATA@*/", payload).replace("/*@JS@*/", js.replace("</script", "<\\/script")))
    if path is None:
        return page
    target = Path(path)
    if target.suffix.lower() not in (".html", ".htm"):
        raise SettingsError(f"viewer page '{target}': the file name must end in .html")
    target.parent.mkdir(parents=True, exist_ok=True)
    # written whole or not at all: a page half written by an interrupted run would not load
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(page)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target


class Inline:
    """A page shown inline by Jupyter (its ``_repr_html_``): the page in an iframe."""

    def __init__(self, html_text: str):
        self.data = html_text

    def _repr_html_(self) -> str:
        return self.data


def _in_notebook() -> bool:
    try:
        from IPython import get_ipython  # type: ignore[import-not-found]
    except ImportError:
        return False
    ip = get_ipython()
    return ip is not None and "IPKernelApp" in getattr(ip, "config", {})


def view(source, path: str | Path | None = None, *, open_browser: bool = True, height: int = 600, **options):
    """Shows the viewer page of ``source``: inline in a Jupyter notebook (an iframe), else written
    to ``path`` (default: a temporary file) and opened in the web browser. Returns the notebook
    display object or the page's path."""
    if _in_notebook() and path is None:
        page = to_html(source, None, **options)
        return Inline(f'<iframe srcdoc="{html.escape(str(page), quote=True)}" style="width:100%;height:{int(height)}px;'
                      'border:0"></iframe>')
    if path is None:
        fd, name = tempfile.mkstemp(prefix="mechsys-view-", suffix=".html")
        os.close(fd)
        path = name
    target = to_html(source, path, **options)
    if open_browser:
        import webbrowser

        webbrowser.open(Path(target).resolve().as_uri())
    return target
