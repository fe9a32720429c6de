"""What the model importers (:mod:`mechsys.urdf`, :mod:`mechsys.mjcf`) share: the result record,
joint limits and their gap-contact stops, visual records, the inertia check and the mapping of
primitive shapes to contours. Every error names the file and the item through ``what``."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from pathlib import Path

import numpy as np

from . import contours as _contours
from .contacts import GapContact
from .errors import ModelError
from .kinematics import matrix_to_cardan_xyz
from .model import Model

IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass
class JointLimit:
    """A joint's limits: position bounds (rad or m; None where the file gives none, as for a
    continuous joint), the effort (N m or N) and the velocity (rad/s or m/s) limits."""

    lower: float | None
    upper: float | None
    effort: float | None = None
    velocity: float | None = None


@dataclass
class Visual:
    """A geometry element kept for a viewer: the ``kind`` (box, sphere, cylinder, capsule,
    ellipsoid, plane, mesh, ...), its ``size`` data (half extents, radius, (radius, length), semi
    axes or the mesh scale), the mesh ``file`` or name, and the placement ``origin`` (4x4, in the
    frame of the body that carries it)."""

    kind: str
    origin: np.ndarray
    size: Any = None
    file: str | None = None


@dataclass
class ModelImport:
    """An imported model.

    ``model``: the :class:`mechsys.Model`; ``root``: the root link or body; ``limits``: {joint:
    :class:`JointLimit`}; ``contours``: {link or body: [(body, contour)]}, each placed in the frame
    of the body that carries it, ready for ``model.add_contact(ms.Contact(..., body.contour(c)))``
    or a contact group; ``visuals``: {link or body: [:class:`Visual`]}; ``mimics``: {joint:
    (mimicked joint, multiplier, offset)}; ``markers``: {frame: body} for the massless fixed frames
    turned into markers."""

    model: Model
    """The imported model."""
    root: str
    """The root link (URDF) or ``"world"`` (MJCF)."""
    limits: dict[str, JointLimit] = field(default_factory=dict)
    """{joint: :class:`JointLimit`}."""
    contours: dict[str, list] = field(default_factory=dict)
    """{link or body: [(mechsys body, contour)]}."""
    visuals: dict[str, list[Visual]] = field(default_factory=dict)
    """{link or body: [:class:`Visual`]}."""
    mimics: dict[str, tuple[str, float, float]] = field(default_factory=dict)
    """{joint: (mimicked joint, multiplier, offset)} (URDF ``<mimic>``)."""
    markers: dict[str, str] = field(default_factory=dict)
    """{massless fixed link or body: the mechsys body that carries it as a marker}."""

    def contour_list(self) -> list:
        """Every contour as ``OnBody`` (the body and its contour), for a contact group's members."""
        return [_contours.OnBody(body, c) for items in self.contours.values() for body, c in items]


def check_inertia(what: str, mass: float | None, inertia: np.ndarray | None, noun: str = "body",
                  missing: str = "no inertial data") -> None:
    """A moving body needs a mass > 0 and a positive definite inertia about its centre of mass."""
    if mass is None or not mass > 0.0:
        got = missing if mass is None else f"mass {mass:g}"
        raise ModelError(f"{what}: a moving {noun} needs a mass > 0, got {got}")
    eig = np.linalg.eigvalsh(0.5 * (inertia + inertia.T))
    if eig[0] <= 0.0:
        raise ModelError(f"{what}: the inertia is not positive definite (principal moments "
                         f"{', '.join(f'{e:.6g}' for e in eig)} kg m^2)")


def primitive_contour(kind: str, size, R: np.ndarray, p: np.ndarray):
    """The contour of a primitive shape whose own frame sits at (R, p) in the body: a box (half
    extents), sphere (radius), cylinder or capsule ((radius, length) along the shape's z),
    ellipsoid (semi axes) or plane (the shape's x-y plane, normal z). None for other kinds."""
    p = tuple(float(x) for x in p)
    if kind == "box":
        return _contours.Box(half_extents=tuple(float(x) for x in size), center=p, cardan=tuple(matrix_to_cardan_xyz(R)))
    if kind == "sphere":
        return _contours.Sphere(radius=float(size), center=p)
    if kind == "cylinder":
        return _contours.Cylinder(radius=float(size[0]), length=float(size[1]), axis=tuple(R[:, 2]), center=p)
    if kind == "capsule":
        half = 0.5 * float(size[1]) * R[:, 2]
        return _contours.Capsule(a=tuple(np.asarray(p) - half), b=tuple(np.asarray(p) + half), radius=float(size[0]))
    if kind == "ellipsoid":
        return _contours.Ellipsoid(semi_axes=tuple(float(x) for x in size), center=p, cardan=tuple(matrix_to_cardan_xyz(R)))
    if kind == "plane":
        return _contours.Plane(normal=tuple(R[:, 2]), point=p)
    return None


def add_visual(model: Model, body: str, vis: Visual, name: str, color=None) -> None:
    """Draws an imported geometry element on ``body`` (``Model.add_visual``): primitives as their
    contours, mesh files read through trimesh with their scale and placement; planes and kinds
    without a drawable form are left out."""
    R, p = vis.origin[:3, :3], vis.origin[:3, 3]
    rgb = None
    if color is not None:
        rgb = tuple(float(min(max(c, 0.0), 1.0)) for c in list(color)[:3])
    opacity = float(color[3]) if color is not None and len(color) > 3 and 0.0 < float(color[3]) < 1.0 else None
    if vis.kind == "mesh":
        if vis.file is None or not Path(vis.file).is_file():
            return
        v, t = _contours._read_mesh_file(vis.file, f"{name}: mesh file '{vis.file}'")
        scale = np.broadcast_to(np.asarray(1.0 if vis.size is None else vis.size, dtype=float), (3,))
        model.add_visual(body, ((np.asarray(v, dtype=float) * scale) @ R.T + p, t), name=name, color=rgb, opacity=opacity)
        return
    if vis.kind == "plane":
        return
    c = primitive_contour(vis.kind, vis.size, R, p)
    if c is not None:
        model.add_visual(body, c, name=name, color=rgb, opacity=opacity)


def check_limit_mode(mode: str, caller: str) -> None:
    if mode not in ("data", "stops"):
        raise ModelError(f"{caller}: limits must be 'data' or 'stops', got {mode!r}")


def add_limit_stops(model: Model, limits: dict[str, JointLimit], label: str) -> None:
    """Two gap contacts per joint bounded on both sides, ``<joint>_lower`` and ``<joint>_upper``."""
    for name, lim in limits.items():
        if lim.lower is None or lim.upper is None:
            continue
        if not IDENTIFIER.match(name):
            raise ModelError(f"{label}: joint '{name}': a limit stop's gap expression needs a joint name made of "
                             "letters, digits and '_' (rename the joint, or load with limits='data')")
        # open while positive: above the lower bound and below the upper one
        model.add_contact(GapContact(f"{name}_lower", gap=f"{name} - ({lim.lower!r})"))
        model.add_contact(GapContact(f"{name}_upper", gap=f"({lim.upper!r}) - {name}"))


def limits_header(imp: ModelImport) -> str:
    """The joint limits as one comment line for an imported model file ('' without limits)."""
    if not imp.limits:
        return ""
    return "\nJoint limits [lower, upper]: " + ", ".join(f"{n} [{lim.lower}, {lim.upper}]" for n, lim in imp.limits.items())
