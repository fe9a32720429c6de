"""Contours: closed-form contact geometry attached to a body (section 2.5; DESIGN.md).

Attach one to a body with ``body.contour(ms.contours.Sphere(radius=0.02))`` and pair two in a
:class:`mechsys.Contact`. All data are in the body frame (m).

In space: :class:`Point`, :class:`Sphere`, :class:`Plane` (half-space below its normal),
:class:`Box`, :class:`Capsule`, :class:`Cylinder`, :class:`Torus`, :class:`Ellipsoid`, the cavities
:class:`Bowl` and :class:`Bore`, the parametric surfaces of section 2.2.7.2 — :class:`Revolution`
(a planar profile turned about an axis) and :class:`Patch` (a bicubic spline through a grid of
points, or sampled from a function with :meth:`Patch.from_function`) — and triangle meshes
:class:`Mesh` (from arrays or from STL/OBJ files). In the plane (the body's x-y plane):
:class:`Point`, :class:`Circle`, :class:`Line` (half-plane behind its normal), :class:`Polygon`
(convex, vertices counter-clockwise), and the parametric contours of section 2.2.7.1 —
:class:`Ellipse`, :class:`Spline` (through points, or sampled from a function with
:meth:`Spline.from_function`), :class:`Cam` (a cam disc from a lift table or lift function) and
:class:`Gear` (an involute spur gear) — which pair with points, circles, polygons, lines and each
other through a Newton contact search on their parameters (see docs/contours.md). For gear pairs,
:func:`gear_center_distance` gives the tight-mesh centre distance of two (shifted, thinned) gears
and :func:`gear_mesh` the working pressure angle, backlash and contact ratio of a pair.
"""

from __future__ import annotations

import json
import math
import operator
from dataclasses import dataclass
from typing import Any, Sequence

from .errors import ModelError
from .joints import _vec3


def _radius(x, what: str) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected a number, got {x!r}") from None


class Contour:
    """Base of all contours: ``describe(what)`` gives the model-file table."""

    kind = ""

    def describe(self, what: str) -> dict:  # pragma: no cover - every contour overrides it
        raise NotImplementedError


@dataclass
class Point(Contour):
    """A single point (against a spatial or a planar contour)."""

    position: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "point", "position": _vec3(self.position, f"{what}.position")}


@dataclass
class Sphere(Contour):
    """A sphere of ``radius`` about ``center``."""

    radius: float = 0.0
    center: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "sphere", "center": _vec3(self.center, f"{what}.center"), "radius": _radius(self.radius, f"{what}.radius")}


@dataclass
class Plane(Contour):
    """The plane through ``point`` with outward ``normal``; the solid side is below it.
    ``surface_velocity`` (body frame, m/s, in the plane) makes it a moving surface, a conveyor
    belt: contacts then stick by moving with it."""

    normal: Sequence[float] = (0.0, 0.0, 1.0)
    point: Sequence[float] = (0.0, 0.0, 0.0)
    surface_velocity: Sequence[float] | None = None

    def describe(self, what: str) -> dict:
        d = {"type": "plane", "point": _vec3(self.point, f"{what}.point"), "normal": _vec3(self.normal, f"{what}.normal")}
        if self.surface_velocity is not None:
            d["surface_velocity"] = _vec3(self.surface_velocity, f"{what}.surface_velocity")
        return d


@dataclass
class Box(Contour):
    """A box of ``half_extents`` about ``center``; ``cardan`` angles (x-y-z) turn its axes in the body."""

    half_extents: Sequence[float] = (0.0, 0.0, 0.0)
    center: Sequence[float] = (0.0, 0.0, 0.0)
    cardan: Sequence[float] | None = None

    def describe(self, what: str) -> dict:
        d = {
            "type": "box",
            "center": _vec3(self.center, f"{what}.center"),
            "half_extents": _vec3(self.half_extents, f"{what}.half_extents"),
        }
        if self.cardan is not None:
            d["rotation"] = {"cardan": _vec3(self.cardan, f"{what}.cardan")}
        return d


@dataclass
class Capsule(Contour):
    """The points within ``radius`` of the segment ``a``–``b``."""

    a: Sequence[float] = (0.0, 0.0, 0.0)
    b: Sequence[float] = (0.0, 0.0, 0.0)
    radius: float = 0.0

    def describe(self, what: str) -> dict:
        return {"type": "capsule", "a": _vec3(self.a, f"{what}.a"), "b": _vec3(self.b, f"{what}.b"),
                "radius": _radius(self.radius, f"{what}.radius")}


@dataclass
class Cylinder(Contour):
    """A solid cylinder of ``radius`` and ``length`` along ``axis`` about ``center``."""

    radius: float = 0.0
    length: float = 0.0
    axis: Sequence[float] = (0.0, 0.0, 1.0)
    center: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "cylinder", "center": _vec3(self.center, f"{what}.center"), "axis": _vec3(self.axis, f"{what}.axis"),
                "radius": _radius(self.radius, f"{what}.radius"), "half_length": 0.5 * _radius(self.length, f"{what}.length")}


@dataclass
class Circle(Contour):
    """A circle in the body's x-y plane."""

    radius: float = 0.0
    center: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "circle", "center": _vec3(self.center, f"{what}.center"), "radius": _radius(self.radius, f"{what}.radius")}


@dataclass
class Line(Contour):
    """The line through ``point`` in the body's x-y plane; the solid side is behind ``normal``.
    ``surface_velocity`` (body frame, m/s, along the line) makes it a moving surface, a conveyor
    belt: contacts then stick by moving with it."""

    normal: Sequence[float] = (0.0, 1.0, 0.0)
    point: Sequence[float] = (0.0, 0.0, 0.0)
    surface_velocity: Sequence[float] | None = None

    def describe(self, what: str) -> dict:
        d = {"type": "line", "point": _vec3(self.point, f"{what}.point"), "normal": _vec3(self.normal, f"{what}.normal")}
        if self.surface_velocity is not None:
            d["surface_velocity"] = _vec3(self.surface_velocity, f"{what}.surface_velocity")
        return d


@dataclass
class Polygon(Contour):
    """A convex polygon in the body's x-y plane, ``vertices`` [(x, y), ...] counter-clockwise."""

    vertices: Sequence[Sequence[float]] = ()

    def describe(self, what: str) -> dict:
        out = []
        for k, v in enumerate(self.vertices):
            try:
                x, y = (float(c) for c in v)
            except (TypeError, ValueError):
                raise ModelError(f"{what}.vertices[{k}]: expected two numbers (x, y), got {v!r}") from None
            out.append([x, y])
        return {"type": "polygon", "vertices": out}


@dataclass
class Torus(Contour):
    """A torus: the points within ``tube`` of the circle of ``radius`` about ``axis`` through
    ``center`` — a wheel's rim (``tube=0``: a thin disc's edge). Pairs with a plane (the lowest
    rim point, closed form)."""

    radius: float = 0.0
    tube: float = 0.0
    axis: Sequence[float] = (0.0, 0.0, 1.0)
    center: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "torus", "center": _vec3(self.center, f"{what}.center"), "axis": _vec3(self.axis, f"{what}.axis"),
                "radius": _radius(self.radius, f"{what}.radius"), "tube": _radius(self.tube, f"{what}.tube")}


@dataclass
class Ellipsoid(Contour):
    """A solid ellipsoid with ``semi_axes`` (a, b, c) about ``center``; ``cardan`` angles (x-y-z)
    turn its axes in the body. Pairs with a plane (the support point, closed form), a point or a
    sphere (the foot point), another ellipsoid (the common normal, separated or overlapping) and a
:class:`Patch`."""

    semi_axes: Sequence[float] = (0.0, 0.0, 0.0)
    center: Sequence[float] = (0.0, 0.0, 0.0)
    cardan: Sequence[float] | None = None

    def describe(self, what: str) -> dict:
        d = {"type": "ellipsoid", "center": _vec3(self.center, f"{what}.center"),
             "semi_axes": _vec3(self.semi_axes, f"{what}.semi_axes")}
        if self.cardan is not None:
            d["rotation"] = {"cardan": _vec3(self.cardan, f"{what}.cardan")}
        return d


@dataclass
class Bowl(Contour):
    """A spherical cavity of ``radius`` about ``center``: the solid lies outside the sphere (a
    bowl, a ball race seen from within). Pairs with a point or a sphere inside it."""

    radius: float = 0.0
    center: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "bowl", "center": _vec3(self.center, f"{what}.center"), "radius": _radius(self.radius, f"{what}.radius")}


@dataclass
class Bore(Contour):
    """A cylindrical cavity of ``radius`` about the axis through ``center`` along ``axis``,
    infinitely long: the solid lies outside the cylinder (a bore, a bearing shell). Pairs with a
    point or a sphere inside it."""

    radius: float = 0.0
    axis: Sequence[float] = (0.0, 0.0, 1.0)
    center: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "bore", "center": _vec3(self.center, f"{what}.center"), "axis": _vec3(self.axis, f"{what}.axis"),
                "radius": _radius(self.radius, f"{what}.radius")}


class Mesh(Contour):
    """A triangle mesh (a bowl, a track, a container, uneven ground), rigid on its body.

    ``vertices``: (n, 3) points in the body frame (m); ``triangles``: (m, 3) vertex indices (from
    0), each counter-clockwise seen from outside the solid, so that its normal
    ``(b - a) × (c - a)`` points out of the material. The solid lies behind the triangles: below
    an open mesh (a terrain, a bowl's shell with its normals up and in), inside a closed mesh
    wound outward, outside a closed mesh wound inward (a cavity). ``flip=True`` reverses every
    triangle (turns a closed solid into a cavity). ``scale`` multiplies the vertices.

    Pairs with a point, a sphere, a box (its 8 corners) and a capsule (its 2 end spheres); see
    docs/contours.md for the cost and the limits. Beyond an open mesh's boundary there is no
    material: a body that gets around the rim of an open bowl is outside it.

    >>> bowl = ms.contours.Mesh.from_file("bowl.obj", scale=0.001)  # doctest: +SKIP
    """

    kind = "mesh"

    def __init__(self, vertices, triangles, *, scale: float = 1.0, flip: bool = False, source: str | None = None):
        what = f"Mesh({source!r})" if source else "Mesh"
        self.vertices, self.triangles = _mesh_arrays(vertices, triangles, scale, flip, what)
        self.source = source

    @classmethod
    def from_file(cls, path, scale: float = 1.0, flip: bool = False) -> "Mesh":
        """Reads an STL (ASCII or binary), OBJ, PLY, OFF, ... file through the ``trimesh``
        library (vertices with equal coordinates merged, so neighbouring triangles share their
        edges).
        ``scale`` converts the file's units to metres (0.001 for millimetres)."""
        v, t = _read_mesh_file(path, f"Mesh.from_file({str(path)!r})")
        return cls(v, t, scale=scale, flip=flip, source=str(path))

    def __repr__(self) -> str:
        src = f", source={self.source!r}" if self.source else ""
        return f"Mesh({len(self.vertices)} vertices, {len(self.triangles)} triangles{src})"

    def describe(self, what: str) -> dict:
        return {"type": "mesh", "vertices": self.vertices.tolist(), "triangles": self.triangles.tolist()}


def _mesh_arrays(vertices, triangles, scale, flip, what: str):
    """Checked (n, 3) float vertices (scaled) and (m, 3) int64 triangles (reversed if ``flip``);
    errors name ``what``. The engine checks the rest (degenerate triangles, orientation)."""
    import numpy as np

    try:
        v = np.asarray(vertices, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{what}.vertices: expected an (n, 3) array of numbers") from None
    if v.ndim != 2 or v.shape[1] != 3:
        raise ModelError(f"{what}.vertices: expected an (n, 3) array, got shape {v.shape}")
    try:
        t_raw = np.asarray(triangles)
        if t_raw.size and not np.issubdtype(t_raw.dtype, np.integer):
            if not np.issubdtype(t_raw.dtype, np.floating) or not np.all(t_raw == np.round(t_raw)):
                raise TypeError
        t = t_raw.astype(np.int64)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{what}.triangles: expected an (m, 3) array of whole vertex indices") from None
    if t.size == 0:
        raise ModelError(f"{what}: the mesh has no triangles")
    if t.ndim != 2 or t.shape[1] != 3:
        raise ModelError(f"{what}.triangles: expected an (m, 3) array, got shape {t.shape}")
    if not isinstance(flip, bool):
        raise ModelError(f"{what}.flip: expected true or false, got {flip!r}")
    scale = _radius(scale, f"{what}.scale")
    if not (math.isfinite(scale) and scale > 0):
        raise ModelError(f"{what}.scale: must be > 0 and finite, got {scale}")
    bad = np.argwhere(~np.isfinite(v))
    if len(bad):
        raise ModelError(f"{what}: vertex {int(bad[0][0])} must be finite, got {v[bad[0][0]].tolist()}")
    out = np.argwhere((t < 0) | (t >= len(v)))
    if len(out):
        i, j = (int(x) for x in out[0])
        raise ModelError(f"{what}: triangle {i} vertex {j} is index {int(t[i, j])}, out of range "
                         f"(the mesh has {len(v)} vertices)")
    return v * scale, (t[:, ::-1].copy() if flip else t)


def _read_mesh_file(path, what: str):
    """(vertices, triangles) of a mesh file, through trimesh; errors name ``what`` and the file."""
    from pathlib import Path

    try:
        import trimesh
    except ImportError:
        raise ModelError(f"{what}: reading mesh files needs the 'trimesh' package (pip install trimesh)") from None
    p = Path(path)
    if not p.is_file():
        raise ModelError(f"{what}: no such mesh file '{p}'")
    import numpy as np

    try:
        # unprocessed: the merge below is ours, the same for every format
        mesh = trimesh.load(str(p), force="mesh", process=False)
        faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
        vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=float)
    except Exception as e:  # noqa: BLE001 - any reader failure is the file's fault
        raise ModelError(f"{what}: cannot read mesh file '{p}': {e}") from None
    if faces.ndim != 2 or len(faces) == 0:
        raise ModelError(f"{what}: mesh file '{p}' contains no triangles")
    # STL repeats each vertex per triangle: merge equal coordinates, so neighbours share edges
    # (the engine's orientation check and the solid side at edges need that)
    merged, inverse = np.unique(vertices, axis=0, return_inverse=True)
    return merged, inverse.reshape(-1)[faces]


_SOLIDS = ("left", "right", "inside", "outside")


@dataclass
class Revolution(Contour):
    """A surface of revolution: the planar ``profile`` (an :class:`Ellipse`, :class:`Spline` or
    :class:`Cam`; its x is the distance from the axis, its y the height along it) turned about the
    z axis of a frame at ``center``, turned in the body by ``cardan`` angles (x-y-z). The solid is
    the profile's solid turned (inside a closed profile). The profile must keep x ≥ 0 or be its
    own mirror image across the axis (an ellipse centred on it: an egg). Pairs with a plane, a
    point and a sphere (searches in the meridian plane; docs/contours.md)."""

    profile: Contour | None = None
    center: Sequence[float] = (0.0, 0.0, 0.0)
    cardan: Sequence[float] | None = None

    def describe(self, what: str) -> dict:
        if not isinstance(self.profile, (Ellipse, Spline, Cam)):
            raise ModelError(f"{what}.profile: expected a mechsys.contours Ellipse, Spline or Cam, got {type(self.profile).__name__}")
        d = {"type": "revolution", "center": _vec3(self.center, f"{what}.center"),
             "profile": self.profile.describe(f"{what}.profile")}
        if self.cardan is not None:
            d["rotation"] = {"cardan": _vec3(self.cardan, f"{what}.cardan")}
        return d


@dataclass
class Patch(Contour):
    """A bicubic spline surface ``r(s1, s2)`` through a grid of body-frame ``points`` (shape
    n1 x n2 x 3) at uniform parameters over ``range1``, ``range2``; ``periodic`` per direction
    (the last grid line must then repeat the first), natural ends otherwise. The solid lies below
    the normal ``r_1 x r_2`` (for a terrain z(x, y) sampled with s1 = x, s2 = y: below the
    ground). Pairs with a point and a sphere (Newton on the two parameters from a sampled start)
and an ellipsoid (Newton from the foot point of its centre: a local search)."""

    points: Any = ()
    range1: Sequence[float] = (0.0, 1.0)
    range2: Sequence[float] = (0.0, 1.0)
    periodic: Sequence[bool] = (False, False)

    @classmethod
    def from_function(cls, f, s1_range, s2_range, n1: int = 33, n2: int = 33, periodic=(False, False)) -> "Patch":
        """Samples a surface ``f(s1, s2) -> (x, y, z)`` on an ``n1 x n2`` grid over the ranges
        (both ends included; a periodic direction's end repeats its start). The interpolation
        error falls with the fourth power of the spacing in the gap, the square in the curvature."""
        what = "Patch.from_function"
        ranges = []
        for name, r in (("s1_range", s1_range), ("s2_range", s2_range)):
            try:
                lo, hi = (float(v) for v in r)
            except (TypeError, ValueError):
                raise ModelError(f"{what}: {name} must be two numbers (start, end), got {r!r}") from None
            if not hi > lo:
                raise ModelError(f"{what}: {name} must increase, got ({lo}, {hi})")
            ranges.append((lo, hi))
        for name, n in (("n1", n1), ("n2", n2)):
            if isinstance(n, bool) or not isinstance(n, int) or n < 2:
                raise ModelError(f"{what}: {name} must be a whole number ≥ 2, got {n!r}")
        grid = []
        for i in range(n1):
            s1 = ranges[0][0] + (ranges[0][1] - ranges[0][0]) * i / (n1 - 1)
            row = []
            for j in range(n2):
                s2 = ranges[1][0] + (ranges[1][1] - ranges[1][0]) * j / (n2 - 1)
                try:
                    v = [float(c) for c in f(s1, s2)]
                except Exception as e:  # the user's function raised
                    raise ModelError(f"{what}: the surface function raised at (s1, s2) = ({s1}, {s2}): {type(e).__name__}: {e}") from None
                if len(v) != 3 or not all(math.isfinite(c) for c in v):
                    raise ModelError(f"{what}: the surface function must return three finite numbers, got {v} at (s1, s2) = ({s1}, {s2})")
                row.append(v)
            grid.append(row)
        if periodic[0]:
            grid[-1] = [list(p) for p in grid[0]]
        if periodic[1]:
            for row in grid:
                row[-1] = list(row[0])
        return cls(points=grid, range1=ranges[0], range2=ranges[1], periodic=tuple(bool(p) for p in periodic))

    def describe(self, what: str) -> dict:
        try:
            rows = [[[float(c) for c in p] for p in row] for row in self.points]
        except (TypeError, ValueError):
            raise ModelError(f"{what}.points: expected a grid of (x, y, z) points (shape n1 x n2 x 3)") from None
        for i, row in enumerate(rows):
            for j, p in enumerate(row):
                if len(p) != 3:
                    raise ModelError(f"{what}.points[{i}][{j}]: expected three numbers (x, y, z), got {len(p)}")
                if not all(math.isfinite(c) for c in p):
                    raise ModelError(f"{what}.points[{i}][{j}]: must be finite, got {p}")
        per = [bool(p) for p in self.periodic]
        if len(per) != 2:
            raise ModelError(f"{what}.periodic: expected two flags (s1, s2), got {self.periodic!r}")
        return {"type": "patch", "points": rows, "range1": _numbers(self.range1, f"{what}.range1"),
                "range2": _numbers(self.range2, f"{what}.range2"), "periodic": per}


def _solid(x, what: str, allowed=_SOLIDS):
    if x is None:
        return None
    if x not in allowed:
        raise ModelError(f"{what}: expected one of {', '.join(repr(a) for a in allowed)}, got {x!r}")
    return x


def _numbers(xs, what: str) -> list:
    try:
        out = [float(v) for v in xs]
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected a sequence of numbers, got {xs!r}") from None
    return out


def _points2(pts, what: str) -> list:
    out = []
    try:
        items = list(pts)
    except TypeError:
        raise ModelError(f"{what}: expected a sequence of (x, y) points, got {pts!r}") from None
    for k, v in enumerate(items):
        try:
            x, y = (float(c) for c in v)
        except (TypeError, ValueError):
            raise ModelError(f"{what}[{k}]: expected two numbers (x, y), got {v!r}") from None
        out.append([x, y])
    return out


@dataclass
class Ellipse(Contour):
    """An ellipse with semi-axes ``a`` (along its x axis, turned by ``angle`` from the body's) and
    ``b``; ``solid="outside"`` makes it an elliptical hole. Parameter: the ellipse angle
    ``s`` with ``r = c + R(angle) (a cos s, b sin s)``."""

    a: float = 0.0
    b: float = 0.0
    center: Sequence[float] = (0.0, 0.0, 0.0)
    angle: float = 0.0
    solid: str | None = None

    def describe(self, what: str) -> dict:
        d = {
            "type": "ellipse",
            "center": _vec3(self.center, f"{what}.center"),
            "semi_axes": [_radius(self.a, f"{what}.a"), _radius(self.b, f"{what}.b")],
            "angle": _radius(self.angle, f"{what}.angle"),
        }
        if self.solid is not None:
            d["solid"] = _solid(self.solid, f"{what}.solid", ("inside", "outside"))
        return d


@dataclass
class Spline(Contour):
    """A C² cubic spline through ``points`` [(x, y), ...] in the body's x-y plane, with the chord
    length as its parameter. ``closed=True`` makes it periodic (do not repeat the first point).
    ``solid``: ``"inside"`` (default when closed) or ``"outside"`` (a bore, a groove seen from
    within), or ``"left"`` (default when open) / ``"right"`` of the points' direction. An open
    spline continues straight along its end tangents."""

    points: Sequence[Sequence[float]] = ()
    closed: bool = False
    solid: str | None = None

    @classmethod
    def from_function(cls, f, s_range, samples: int = 400, closed: bool = False, solid: str | None = None) -> "Spline":
        """Samples a curve ``f(s) -> (x, y)`` at ``samples`` parameters over ``s_range`` (for a
        closed curve the end of the range is the start again and is not repeated). The spline's
        error against ``f`` falls with the fourth power of the spacing (about ``h⁴ κ³`` for
        spacing ``h`` and curvature ``κ``); check it by evaluating ``f`` between the samples."""
        what = "Spline.from_function"
        try:
            lo, hi = (float(v) for v in s_range)
        except (TypeError, ValueError):
            raise ModelError(f"{what}: s_range must be two numbers (start, end), got {s_range!r}") from None
        if not hi > lo:
            raise ModelError(f"{what}: s_range must increase, got ({lo}, {hi})")
        if isinstance(samples, bool) or not isinstance(samples, int) or samples < 3:
            raise ModelError(f"{what}: samples must be a whole number ≥ 3, got {samples!r}")
        n = samples
        ss = [lo + (hi - lo) * k / (n if closed else n - 1) for k in range(n)]
        pts = []
        for s in ss:
            try:
                v = f(s)
                x, y = float(v[0]), float(v[1])
            except Exception as e:  # the user's function raised
                raise ModelError(f"{what}: the curve function raised at s = {s}: {type(e).__name__}: {e}") from None
            if not (math.isfinite(x) and math.isfinite(y)):
                raise ModelError(f"{what}: the curve function returned a non-finite point ({x}, {y}) at s = {s}")
            pts.append((x, y))
        return cls(points=pts, closed=closed, solid=solid)

    def describe(self, what: str) -> dict:
        d = {"type": "spline", "points": _points2(self.points, f"{what}.points"), "closed": bool(self.closed)}
        if self.solid is not None:
            d["solid"] = _solid(self.solid, f"{what}.solid")
        return d


@dataclass
class Cam(Contour):
    """A cam disc whose follower translates along the +y axis of the frame the cam turns in (the
    cam body's frame at cam angle 0), lifted by ``lift``: a table ``(angles, lifts)`` over
    ``[0, 2π]`` (periodic: the lift at 2π equals the lift at 0) or a function of the cam angle
    sampled at ``samples`` angles. ``base_radius`` is the base circle of the cam profile.
    ``follower``: ``"roller"`` (radius ``roller_radius``, axis offset ``eccentricity`` from the
    cam centre), ``"knife"`` or ``"flat"`` (a flat face normal to the follower axis).
    ``direction=+1``: the cam turns counter-clockwise about its z axis as the angle grows.
    Pair it with the follower's :class:`Circle` (roller), :class:`Point` (knife) or
    :class:`Line` (flat face)."""

    lift: Any = None
    base_radius: float = 0.0
    follower: str = "roller"
    roller_radius: float = 0.0
    eccentricity: float = 0.0
    direction: int = 1
    samples: int = 720

    def table(self, what: str = "Cam") -> tuple[list, list]:
        """The lift table (angles, lifts) this cam is built from."""
        what = f"{what}.lift"
        if callable(self.lift):
            n = self.samples
            if isinstance(n, bool) or not isinstance(n, int) or n < 8:
                raise ModelError(f"Cam.samples: expected a whole number ≥ 8, got {n!r}")
            angles = [2.0 * math.pi * k / n for k in range(n + 1)]
            lifts = []
            for a in angles:
                try:
                    h = float(self.lift(a))
                except Exception as e:
                    raise ModelError(f"{what}: the lift function raised at angle {a}: {type(e).__name__}: {e}") from None
                if not math.isfinite(h):
                    raise ModelError(f"{what}: the lift function returned {h} at angle {a}")
                lifts.append(h)
            if abs(lifts[-1] - lifts[0]) > 1e-9 * max(1.0, max(abs(v) for v in lifts)):
                raise ModelError(f"{what}: the lift function is not periodic: {lifts[0]} at 0 but {lifts[-1]} at 2π")
            lifts[-1] = lifts[0]
            return angles, lifts
        try:
            angles, lifts = self.lift
        except (TypeError, ValueError):
            raise ModelError(f"{what}: expected a table (angles, lifts) or a function of the cam angle, got {self.lift!r}") from None
        return _numbers(angles, f"{what} angles"), _numbers(lifts, f"{what} lifts")

    def describe(self, what: str) -> dict:
        angles, lifts = self.table(what)
        if self.follower not in ("roller", "knife", "flat"):
            raise ModelError(f"{what}.follower: expected 'roller', 'knife' or 'flat', got {self.follower!r}")
        if self.direction not in (1, -1):
            raise ModelError(f"{what}.direction: expected +1 or -1, got {self.direction!r}")
        return {
            "type": "cam",
            "angles": angles,
            "lift": lifts,
            "base_radius": _radius(self.base_radius, f"{what}.base_radius"),
            "follower": self.follower,
            "roller_radius": _radius(self.roller_radius, f"{what}.roller_radius"),
            "eccentricity": _radius(self.eccentricity, f"{what}.eccentricity"),
            "direction": float(self.direction),
        }


def _teeth(z, what: str) -> int:
    if isinstance(z, bool):
        raise ModelError(f"{what}: expected a whole number of teeth, got {z!r}")
    try:
        return operator.index(z)
    except TypeError:
        if isinstance(z, float) and z.is_integer():
            return int(z)
        raise ModelError(f"{what}: expected a whole number of teeth, got {z!r}") from None


def _optional(x, what: str):
    return None if x is None else _radius(x, what)


#: The standard pressure angle, 20° (rad).
PRESSURE_ANGLE = math.radians(20.0)


@dataclass
class Gear(Contour):
    """An external involute spur gear in the body's x-y plane: ``module`` (or ``base_radius``,
    ``r_b = m z cos α / 2``), ``teeth`` z, ``pressure_angle`` α (rad, 20° by default), profile
    ``shift`` x, ``backlash`` (the teeth thinned by this arc length on the pitch circle),
    ``addendum`` (default one module) and ``dedendum`` (1.25 modules) about the shifted pitch
    circle, ``tip_radius`` and ``root_radius`` (the tip rounding and root fillet; by default 0.05
    and 0.2 modules, or less where that does not fit), ``center`` and ``phase`` (the direction of
    tooth 0's centre line). The flanks are exact involutes of the base circle, joined G1 to the
    roundings; the contour's parameter is the arc length along the outline, counter-clockwise
    from the middle of the gap before tooth 0 (see docs/contours.md). Pair two gears with
    ``ms.Contact(..., points=2)``: one candidate for the drive flanks and one for the coast flanks
    (the closest tooth pair on each side; 4, 6 or 8 points give every flank in mesh its own)."""

    module: float | None = None
    teeth: int = 0
    pressure_angle: float = PRESSURE_ANGLE
    shift: float = 0.0
    backlash: float = 0.0
    addendum: float | None = None
    dedendum: float | None = None
    tip_radius: float | None = None
    root_radius: float | None = None
    center: Sequence[float] = (0.0, 0.0, 0.0)
    phase: float = 0.0
    base_radius: float | None = None

    def describe(self, what: str) -> dict:
        d = {
            "type": "gear",
            "teeth": _teeth(self.teeth, f"{what}.teeth"),
            "pressure_angle": _radius(self.pressure_angle, f"{what}.pressure_angle"),
            "shift": _radius(self.shift, f"{what}.shift"),
            "backlash": _radius(self.backlash, f"{what}.backlash"),
            "center": _vec3(self.center, f"{what}.center"),
            "phase": _radius(self.phase, f"{what}.phase"),
        }
        for k in ("module", "base_radius", "addendum", "dedendum", "tip_radius", "root_radius"):
            v = _optional(getattr(self, k), f"{what}.{k}")
            if v is not None:
                d[k] = v
        return d

    def geometry(self, samples: int = 0, what: str = "Gear") -> "GearGeometry":
        """The gear as the engine builds it (radii, roll angles of the involute, roundings used);
        with ``samples`` > 0 also that many points of its outline (body frame, for plots)."""
        from . import _core

        if isinstance(samples, bool) or not isinstance(samples, int) or samples < 0:
            raise ModelError(f"{what}.geometry: samples must be a whole number ≥ 0, got {samples!r}")
        d = self.describe(what)
        d.pop("type")
        g = _core.gear_geometry(json.dumps(d), what, samples)
        return GearGeometry(**{k: (tuple(v) if k == "roll_range" else v) for k, v in g.items()})


@dataclass(frozen=True)
class GearGeometry:
    """A gear contour as the engine builds it (:meth:`Gear.geometry`); lengths in m, angles in
    rad. The flank is the exact involute between the roll angles ``roll_range``; ``segment``: a
    straight piece joins its start to the root fillet (the root circle lies inside the base
    circle or close to it)."""

    module: float
    teeth: int
    pressure_angle: float
    shift: float
    backlash: float
    pitch_radius: float
    base_radius: float
    tip_radius: float
    root_radius: float
    base_half_angle: float
    roll_range: tuple
    tip_rounding: float
    root_fillet: float
    segment: bool
    tooth_length: float
    perimeter: float
    outline: Any = None

    @property
    def base_pitch(self) -> float:
        """Distance between the flanks of neighbouring teeth along a line of action, 2π r_b / z."""
        return 2.0 * math.pi * self.base_radius / self.teeth

    @property
    def base_thickness(self) -> float:
        """Tooth thickness on the base circle (arc), 2 r_b ψ_b (the involutes extended down to it)."""
        return 2.0 * self.base_radius * self.base_half_angle


def involute(alpha: float) -> float:
    """The involute function inv α = tan α − α."""
    return math.tan(alpha) - alpha


def involute_inverse(value: float) -> float:
    """The angle α in [0, π/2) with inv α = ``value`` ≥ 0 (Newton on tan α − α)."""
    if not (math.isfinite(value) and value >= 0.0):
        raise ModelError(f"involute_inverse: expected a value ≥ 0, got {value!r}")
    # start from the series inv α ≈ α³/3 for small angles, capped below π/2
    a = min((3.0 * value) ** (1.0 / 3.0), 1.5)
    for _ in range(100):
        t = math.tan(a)
        step = (t - a - value) / (t * t)
        a = min(max(a - step, 0.5 * a), 0.5 * (a + math.pi / 2))
        if abs(step) < 1e-16 * max(a, 1e-300):
            break
    return a


def _thickness_angle(z: int, m: float, alpha: float, x: float, j: float) -> float:
    """Half angle of a tooth at the base circle, ψ_b = s / (2r) + inv α."""
    return (m * (math.pi / 2 + 2 * x * math.tan(alpha)) - j) / (m * z) + involute(alpha)


def gear_center_distance(z1: int, z2: int, module: float, pressure_angle: float = PRESSURE_ANGLE,
                         shift1: float = 0.0, shift2: float = 0.0, backlash1: float = 0.0,
                         backlash2: float = 0.0) -> float:
    """Centre distance at which two external gears mesh without backlash: from the tooth
    thicknesses on the base circles, ``inv α_w = (s_b1 + s_b2 − p_b) / (2 (r_b1 + r_b2))`` and
    ``a = (r_b1 + r_b2) / cos α_w`` (for unshifted, unthinned gears ``m (z1 + z2) / 2``;
    for shifted ones the classical ``inv α_w = inv α + 2 tan α (x1 + x2) / (z1 + z2)``). Any extra
    distance Δa opens a normal backlash of about ``2 Δa sin α_w``."""
    what = "gear_center_distance"
    z1, z2 = _teeth(z1, f"{what}: z1"), _teeth(z2, f"{what}: z2")
    m, alpha = _radius(module, f"{what}: module"), _radius(pressure_angle, f"{what}: pressure_angle")
    if not (m > 0 and math.isfinite(m)):
        raise ModelError(f"{what}: module must be > 0, got {m}")
    if not 0 < alpha < math.radians(60):
        raise ModelError(f"{what}: pressure_angle must lie between 0 and 60° (rad), got {alpha}")
    if z1 < 5 or z2 < 5:
        raise ModelError(f"{what}: gears need at least 5 teeth, got {z1} and {z2}")
    rb1, rb2 = 0.5 * m * z1 * math.cos(alpha), 0.5 * m * z2 * math.cos(alpha)
    sb1 = 2 * rb1 * _thickness_angle(z1, m, alpha, float(shift1), float(backlash1))
    sb2 = 2 * rb2 * _thickness_angle(z2, m, alpha, float(shift2), float(backlash2))
    pb = math.pi * m * math.cos(alpha)
    inv_w = (sb1 + sb2 - pb) / (2 * (rb1 + rb2))
    if inv_w <= 0:
        raise ModelError(f"{what}: the teeth are too thin to mesh tightly at any centre distance "
                         f"(base thicknesses {sb1:.6g} + {sb2:.6g} ≤ base pitch {pb:.6g})")
    return (rb1 + rb2) / math.cos(involute_inverse(inv_w))


@dataclass(frozen=True)
class GearMesh:
    """Two gears at a centre distance (:func:`gear_mesh`); lengths in m, angles in rad."""

    center_distance: float
    #: Working pressure angle: the lines of action make it with the common tangent of the
    #: working pitch circles, cos α_w = (r_b1 + r_b2) / a.
    working_pressure_angle: float
    #: Play along a line of action with the other flanks touching,
    #: p_b − s_b1 − s_b2 + 2 (r_b1 + r_b2) inv α_w.
    normal_backlash: float
    #: The same turned into an angle of gear 1 (rad): normal_backlash / r_b1.
    angular_backlash1: float
    #: Length of the path of contact over the base pitch (the exact involutes only: the tip
    #: roundings shorten it).
    contact_ratio: float
    #: Speed ratio ω2 / ω1 = −r_b1 / r_b2 = −z1 / z2.
    ratio: float
    #: Smallest gap between a tip circle and the other gear's root circle.
    tip_clearance: float
    #: Whether a tip reaches a flank below its involute (interference; the contact ratio then
    #: counts only the involute part).
    interference: bool


def gear_mesh(gear1: Gear, gear2: Gear, center_distance: float) -> GearMesh:
    """The mesh of two external gears (their own data; centres ``center_distance`` apart):
    working pressure angle, normal backlash, contact ratio and tip clearance."""
    what = "gear_mesh"
    a = _radius(center_distance, f"{what}: center_distance")
    g1, g2 = gear1.geometry(what=f"{what}: gear1"), gear2.geometry(what=f"{what}: gear2")
    if abs(g1.base_pitch - g2.base_pitch) > 1e-9 * g1.base_pitch:
        raise ModelError(f"{what}: the gears' base pitches differ ({g1.base_pitch:.9g} and {g2.base_pitch:.9g} m): "
                         "involute gears mesh only with equal base pitch (module × cos of the pressure angle)")
    rb1, rb2 = g1.base_radius, g2.base_radius
    if not a > rb1 + rb2:
        raise ModelError(f"{what}: the centre distance {a} must exceed the sum of the base radii {rb1 + rb2}")
    clearance = min(a - g1.tip_radius - g2.root_radius, a - g2.tip_radius - g1.root_radius)
    aw = math.acos((rb1 + rb2) / a)
    jn = g1.base_pitch - g1.base_thickness - g2.base_thickness + 2 * (rb1 + rb2) * involute(aw)
    length = a * math.sin(aw)  # between the tangent points T1, T2
    # each involute along the line of action, measured from T1: r_b1 φ1 and L − r_b2 φ2
    lo1, hi1 = (rb1 * p for p in g1.roll_range)
    lo2, hi2 = (length - rb2 * p for p in reversed(g2.roll_range))
    start, end = max(lo1, lo2), min(hi1, hi2)
    # an involute's end (where the tip rounding begins) beyond the other's involute start
    interference = lo2 < lo1 or hi1 > hi2
    return GearMesh(center_distance=a, working_pressure_angle=aw, normal_backlash=jn, angular_backlash1=jn / rb1,
                    contact_ratio=max(end - start, 0.0) / g1.base_pitch, ratio=-rb1 / rb2, tip_clearance=clearance,
                    interference=bool(interference))


@dataclass
class OnBody:
    """A contour attached to a body (what :meth:`mechsys.Body.contour` returns), with its
    material (:class:`mechsys.Material`) for compliant contact laws."""

    body: str
    contour: Contour
    material: Any = None


__all__ = [
    "Contour",
    "Point",
    "Sphere",
    "Plane",
    "Box",
    "Capsule",
    "Cylinder",
    "Circle",
    "Line",
    "Polygon",
    "Torus",
    "Ellipsoid",
    "Revolution",
    "Patch",
    "Bowl",
    "Bore",
    "Mesh",
    "Ellipse",
    "Spline",
    "Cam",
    "Gear",
    "GearGeometry",
    "GearMesh",
    "gear_center_distance",
    "gear_mesh",
    "involute",
    "involute_inverse",
    "OnBody",
]
