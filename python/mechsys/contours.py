"""Contours: closed-form contact geometry attached to a body (section 2.5; DESIGN.md).

Attach one to a body with ``body.contour(ms.contours.Sphere(radius=0.02))`` and pair two in a
:class:`mechsys.Contact`. All data are in the body frame (m).

In space: :class:`Point`, :class:`Sphere`, :class:`Plane` (half-space below its normal),
:class:`Box`, :class:`Capsule`, :class:`Cylinder`. In the plane (the body's x-y plane):
:class:`Point`, :class:`Circle`, :class:`Line` (half-plane behind its normal), :class:`Polygon`
(convex, vertices counter-clockwise).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

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
    """The plane through ``point`` with outward ``normal``; the solid side is below it."""

    normal: Sequence[float] = (0.0, 0.0, 1.0)
    point: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "plane", "point": _vec3(self.point, f"{what}.point"), "normal": _vec3(self.normal, f"{what}.normal")}


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
    """The line through ``point`` in the body's x-y plane; the solid side is behind ``normal``."""

    normal: Sequence[float] = (0.0, 1.0, 0.0)
    point: Sequence[float] = (0.0, 0.0, 0.0)

    def describe(self, what: str) -> dict:
        return {"type": "line", "point": _vec3(self.point, f"{what}.point"), "normal": _vec3(self.normal, f"{what}.normal")}


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
class OnBody:
    """A contour attached to a body (what :meth:`mechsys.Body.contour` returns)."""

    body: str
    contour: Contour


__all__ = ["Contour", "Point", "Sphere", "Plane", "Box", "Capsule", "Cylinder", "Circle", "Line", "Polygon", "OnBody"]
