"""URDF import: a robot description's links and joints as a mechsys model.

The file is parsed by the ``yourdfpy`` library; everything after the parse (the tree checks, the
frames, the inertias, the contours) is ours, so every error can name the link, joint or file.

Frames. A URDF link frame is the mechsys body frame. A joint's ``<origin>`` places the joint frame
in the parent link, which is exactly a mechsys ``parent_frame`` (rotation ``A`` with
``v_parent = A v_joint``); the child link frame is the joint frame at q = 0, so ``child_frame``
is the identity (except for a planar joint, whose plane normal to the axis becomes the
mechsys joint frame's x-y plane). The ``<inertial>``
frame may be offset and turned in the link: its origin is the body's centre of mass and its
tensor, given in the inertial frame's axes, is turned into link axes as ``R I R^T``.

The root link. With ``root="ground"`` the root link *is* the ground (its inertia is dropped, as a
fixed-base robot's base never moves); with ``root="free"`` it becomes a body on a
:class:`mechsys.joints.Free` joint.

A link without mass that hangs on a fixed joint and carries nothing that moves (a tool frame,
a sensor mount) would be a body the engine cannot move; it becomes a marker on the body it is
fixed to instead, and its contours move to that body too.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from . import constraints as _constraints
from . import contours as _contours
from . import joints as _joints
from ._import import (JointLimit, ModelImport, Visual, add_limit_stops, add_visual, check_inertia, check_limit_mode,
                      primitive_contour)
from .errors import ModelError
from .model import Model

_KINDS = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


class URDFImport(ModelImport):
    """The result of :func:`load_urdf` (see :class:`mechsys._import.ModelImport`): ``contours``
    come from the collision (or visual) geometry of each link, ``mimics`` from ``<mimic>``,
    ``markers`` are the massless fixed links, ``root`` is the root link's name."""


def _yourdfpy():
    try:
        import yourdfpy
    except ImportError:
        raise ModelError("URDF import needs the 'yourdfpy' package: pip install yourdfpy") from None
    return yourdfpy


def _parse(source, label: str, yourdfpy) -> Any:
    """The yourdfpy robot description, parsed without loading meshes (we resolve and check them)."""
    import xml.etree.ElementTree as ET

    # yourdfpy quietly recovers from broken XML; a truncated file must be an error instead
    try:
        text = source.getvalue() if isinstance(source, io.BytesIO) else Path(source).read_bytes()
        top = ET.fromstring(text)
    except ET.ParseError as e:
        raise ModelError(f"{label}: cannot read the URDF (not well-formed XML: {e})") from None
    if top.tag != "robot":
        raise ModelError(f"{label}: cannot read the URDF (the top element is <{top.tag}>, expected <robot>)")
    try:
        urdf = yourdfpy.URDF.load(source, build_scene_graph=False, load_meshes=False, load_collision_meshes=False)
    except Exception as e:  # noqa: BLE001 - a malformed file raises anything from lxml or yourdfpy
        raise ModelError(f"{label}: cannot read the URDF ({type(e).__name__}: {e})") from None
    return urdf.robot


def _origin(T, what: str) -> tuple[np.ndarray, np.ndarray]:
    """Rotation and position of a 4x4 URDF origin (identity when absent)."""
    if T is None:
        return np.eye(3), np.zeros(3)
    T = np.asarray(T, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise ModelError(f"{what}: the origin is not a finite transform")
    return T[:3, :3].copy(), T[:3, 3].copy()


def _planar_alignment(axis: np.ndarray) -> np.ndarray:
    """A rotation whose z column is ``axis``: a URDF planar joint moves in the plane normal to its
    axis, a mechsys Planar joint in its frame's x-y plane."""
    z = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


class _Loader:
    def __init__(self, robot, label: str, base_dir: Path | None, package_dirs, root: str, contours, limits: str):
        self.robot = robot
        self.label = label
        self.base_dir = base_dir
        self.package_dirs = [Path(p) for p in ([package_dirs] if isinstance(package_dirs, (str, Path)) else (package_dirs or []))]
        self.root_mode = root
        self.contour_source = contours
        self.limit_mode = limits
        self.links = {}
        for link in robot.links:
            if link.name in self.links:
                raise ModelError(f"{label}: link '{link.name}' is defined twice")
            self.links[link.name] = link
        self.joints = list(robot.joints)

    # ---- the tree ------------------------------------------------------------------------------
    def tree(self) -> tuple[str, list]:
        """The root link and the joints in parent-before-child order; every other shape of graph
        is an error naming the links or joints concerned."""
        parent_of: dict[str, Any] = {}
        names = set()
        for j in self.joints:
            w = f"{self.label}: joint '{j.name}'"
            if j.name in names:
                raise ModelError(f"{w} is defined twice")
            names.add(j.name)
            if j.type not in _KINDS:
                raise ModelError(f"{w}: unknown joint type {j.type!r} (expected one of {', '.join(_KINDS)})")
            for role, link in (("parent", j.parent), ("child", j.child)):
                if link not in self.links:
                    raise ModelError(f"{w}: {role} link '{link}' is not defined")
            if j.child in parent_of:
                raise ModelError(f"{w}: link '{j.child}' already has the parent joint '{parent_of[j.child].name}' "
                                 "(a link has one parent; a closed loop needs a mechsys constraint)")
            parent_of[j.child] = j
        roots = [n for n in self.links if n not in parent_of]
        if not roots:
            raise ModelError(f"{self.label}: no root link: the joints form a cycle through every link")
        if len(roots) > 1:
            raise ModelError(f"{self.label}: the links are not one tree: {len(roots)} links have no parent joint "
                             f"({', '.join(repr(r) for r in roots)})")
        order, seen, frontier = [], {roots[0]}, [roots[0]]
        children: dict[str, list] = {}
        for j in self.joints:
            children.setdefault(j.parent, []).append(j)
        while frontier:
            nxt = []
            for link in frontier:
                for j in children.get(link, []):
                    order.append(j)
                    seen.add(j.child)
                    nxt.append(j.child)
            frontier = nxt
        lost = [n for n in self.links if n not in seen]
        if lost:
            raise ModelError(f"{self.label}: link(s) {', '.join(repr(n) for n in lost)} are not reachable from the root "
                             f"'{roots[0]}': their joints form a cycle")
        return roots[0], order

    # ---- bodies ----------------------------------------------------------------------------------
    def inertia(self, name: str) -> tuple[float, np.ndarray, np.ndarray] | None:
        """(mass, inertia about the centre of mass in link axes, centre of mass), None without <inertial>."""
        inertial = self.links[name].inertial
        w = f"{self.label}: link '{name}'"
        if inertial is None or inertial.mass is None:
            return None
        mass = float(inertial.mass)
        R, p = _origin(inertial.origin, f"{w}.inertial")
        I_f = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia, dtype=float)
        if not np.all(np.isfinite(I_f)) or not np.isfinite(mass):
            raise ModelError(f"{w}: the mass and inertia must be finite numbers")
        # the tensor is given in the inertial frame's axes; the body wants link axes
        I_b = R @ I_f @ R.T
        return mass, 0.5 * (I_b + I_b.T), p  # symmetric to the last bit, as the engine checks it

    def check_inertia(self, name: str, data) -> None:
        check_inertia(f"{self.label}: link '{name}'", None if data is None else data[0], None if data is None else data[1],
                      noun="link", missing="no <inertial>")

    # ---- geometry --------------------------------------------------------------------------------
    def mesh_path(self, filename: str, what: str) -> Path:
        if filename.startswith("package://"):
            rest = filename[len("package://"):]
            package, _, inner = rest.partition("/")
            tried = []
            for d in self.package_dirs:
                for cand in (d / package / inner, d / inner if d.name == package else None):
                    if cand is not None:
                        tried.append(cand)
                        if cand.is_file():
                            return cand
            if not self.package_dirs:
                raise ModelError(f"{what}: mesh file '{filename}' needs package_dirs= to find package '{package}'")
            raise ModelError(f"{what}: mesh file '{filename}' not found (looked in {', '.join(str(t) for t in tried)})")
        path = Path(filename[len("file://"):]) if filename.startswith("file://") else Path(filename)
        if not path.is_absolute() and self.base_dir is not None:
            path = self.base_dir / path
        if not path.is_file():
            raise ModelError(f"{what}: mesh file '{filename}' not found ({path})")
        return path

    def geometry(self, element, what: str, A: np.ndarray, b: np.ndarray, as_contour: bool):
        """(kind, size, file, contour) of a visual/collision element placed on its body by (A, b),
        the link frame in the body frame."""
        R0, p0 = _origin(element.origin, what)
        R, p = A @ R0, A @ p0 + b
        g = element.geometry
        if g is None:
            raise ModelError(f"{what}: no <geometry>")
        for kind, size in (("box", None if g.box is None else 0.5 * np.asarray(g.box.size, dtype=float)),
                           ("sphere", None if g.sphere is None else float(g.sphere.radius)),
                           ("cylinder", None if g.cylinder is None else (float(g.cylinder.radius), float(g.cylinder.length)))):
            if size is not None:
                return kind, size, None, (primitive_contour(kind, size, R, p) if as_contour else None), (R, p)
        if g.mesh is not None:
            path = self.mesh_path(g.mesh.filename, what)
            scale = np.ones(3) if g.mesh.scale is None else np.broadcast_to(np.asarray(g.mesh.scale, dtype=float), (3,))
            c = None
            if as_contour:
                v, t = _contours._read_mesh_file(path, f"{what}: mesh file '{g.mesh.filename}'")
                v = (np.asarray(v, dtype=float) * scale) @ R.T + p
                c = _contours.Mesh(v, t, source=str(path))
            return "mesh", scale, str(path), c, (R, p)
        raise ModelError(f"{what}: unsupported geometry (expected box, sphere, cylinder or mesh)")

    # ---- the model -------------------------------------------------------------------------------
    def build(self, name: str | None, gravity) -> URDFImport:
        root, order = self.tree()
        model = Model(name or self.robot.name or "urdf", gravity=gravity)
        out = URDFImport(model=model, root=root)
        # where each link's frame sits: (body name, A, b) with v_body = A v_link + b
        place: dict[str, tuple[str, np.ndarray, np.ndarray]] = {}
        if "ground" in self.links and not (self.root_mode == "ground" and root == "ground"):
            raise ModelError(f"{self.label}: link 'ground' clashes with mechsys's name for the inertial frame")
        if self.root_mode == "ground":
            place[root] = ("ground", np.eye(3), np.zeros(3))
        elif self.root_mode == "free":
            data = self.inertia(root)
            self.check_inertia(root, data)
            model.add_body(root, data[0], data[1], com=tuple(data[2]))
            model.add_joint(_joints.Free(f"{root}_free", model.ground, root))
            place[root] = (root, np.eye(3), np.zeros(3))
        else:
            raise ModelError(f"load_urdf: root must be 'ground' or 'free', got {self.root_mode!r}")

        moving_below = self._moving_descendants(order)
        for j in order:
            w = f"{self.label}: joint '{j.name}'"
            parent_body, A, b = place[j.parent]
            R, p = _origin(j.origin, w)
            # the joint frame in the parent body: the link placement composed with the origin
            R_pj, p_pj = A @ R, A @ p + b
            data = self.inertia(j.child)
            if j.type == "fixed" and (data is None or data[0] == 0.0) and not moving_below[j.child]:
                # a massless fixed link: a marker on the body it hangs from (see the module doc)
                place[j.child] = (parent_body, R_pj, p_pj)
                model.add_marker(parent_body, j.child, tuple(p_pj), rotation=R_pj.tolist())
                out.markers[j.child] = parent_body
                continue
            self.check_inertia(j.child, data)
            model.add_body(j.child, data[0], data[1], com=tuple(data[2]))
            place[j.child] = (j.child, np.eye(3), np.zeros(3))
            axis = np.asarray(j.axis if j.axis is not None else (1.0, 0.0, 0.0), dtype=float)
            if j.type != "fixed" and j.type != "floating" and (not np.all(np.isfinite(axis)) or np.linalg.norm(axis) == 0.0):
                raise ModelError(f"{w}: the axis must be a non-zero vector, got {axis.tolist()}")
            common = dict(parent_frame=_joints.Frame(position=tuple(p_pj), rotation=R_pj.tolist()))
            damping = getattr(j.dynamics, "damping", None) if j.dynamics is not None else None
            if damping and j.type in ("revolute", "continuous", "prismatic"):
                common["damper"] = _joints.JointDamper(float(damping))
            if j.type in ("revolute", "continuous"):
                joint = _joints.Revolute(j.name, parent_body, j.child, axis=tuple(axis), **common)
            elif j.type == "prismatic":
                joint = _joints.Prismatic(j.name, parent_body, j.child, axis=tuple(axis), **common)
            elif j.type == "fixed":
                joint = _joints.Fixed(j.name, parent_body, j.child, **common)
            elif j.type == "floating":
                joint = _joints.Free(j.name, parent_body, j.child, **common)
            else:  # planar: the plane normal to the axis becomes the joint frame's x-y plane
                Q = _planar_alignment(axis)
                joint = _joints.Planar(j.name, parent_body, j.child,
                                       parent_frame=_joints.Frame(position=tuple(p_pj), rotation=(R_pj @ Q).tolist()),
                                       child_frame=_joints.Frame(rotation=Q.tolist()))
            model.add_joint(joint)
            if j.limit is not None and j.type in ("revolute", "prismatic", "continuous"):
                lim = j.limit
                lower, upper = lim.lower, lim.upper
                if j.type == "continuous":
                    lower = upper = None
                out.limits[j.name] = JointLimit(lower, upper, lim.effort, lim.velocity)
                if lower is not None and upper is not None and lower > upper:
                    raise ModelError(f"{w}: the lower limit {lower:g} is above the upper limit {upper:g}")
        self._mimics(out, order)
        self._stops(out)
        self._geometry(out, place)
        return out

    def _moving_descendants(self, order) -> dict[str, bool]:
        """Per link: whether something below it (or itself) needs to be a body."""
        below = {n: False for n in self.links}
        for j in reversed(order):
            data = self.inertia(j.child)
            needs = j.type != "fixed" or (data is not None and data[0] != 0.0) or below[j.child]
            below[j.parent] = below[j.parent] or needs
        return below

    def _mimics(self, out: URDFImport, order) -> None:
        kinds = {j.name: j.type for j in order}
        for j in order:
            if j.mimic is None:
                continue
            w = f"{self.label}: joint '{j.name}'.mimic"
            other = j.mimic.joint
            if other not in kinds:
                raise ModelError(f"{w}: mimicked joint '{other}' is not defined")
            chain, follow = [j.name], other
            while follow is not None and follow not in chain:
                chain.append(follow)
                nxt = next((k for k in order if k.name == follow), None)
                follow = nxt.mimic.joint if nxt is not None and nxt.mimic is not None else None
            if follow is not None:
                raise ModelError(f"{w}: the mimic joints form a cycle ({' -> '.join(chain + [follow])}): "
                                 "no joint in it moves on its own")
            single = ("revolute", "continuous", "prismatic")
            if kinds[other] not in single or j.type not in single:
                raise ModelError(f"{w}: only revolute, continuous and prismatic joints can mimic each other "
                                 f"('{j.name}' is {j.type}, '{other}' is {kinds[other]})")
            mult = 1.0 if j.mimic.multiplier is None else float(j.mimic.multiplier)
            off = 0.0 if j.mimic.offset is None else float(j.mimic.offset)
            out.mimics[j.name] = (other, mult, off)
            # URDF: q_joint = multiplier * q_other + offset, the Coupler's q1 = ratio q2 + offset
            out.model.add_constraint(_constraints.Coupler(f"{j.name}_mimic", j.name, other, mult, off))

    def _stops(self, out: URDFImport) -> None:
        check_limit_mode(self.limit_mode, "load_urdf")
        if self.limit_mode == "stops":
            add_limit_stops(out.model, out.limits, self.label)

    def _geometry(self, out: URDFImport, place) -> None:
        if self.contour_source not in ("collision", "visual", None):
            raise ModelError(f"load_urdf: contours must be 'collision', 'visual' or None, got {self.contour_source!r}")
        for name, link in self.links.items():
            body, A, b = place[name]
            for k, v in enumerate(link.visuals or []):
                what = f"{self.label}: link '{name}'.visual[{k}]"
                kind, size, file, c, (R, p) = self.geometry(v, what, A, b, self.contour_source == "visual")
                T = np.eye(4)
                T[:3, :3], T[:3, 3] = R, p
                vis = Visual(kind, T, size, file)
                out.visuals.setdefault(name, []).append(vis)
                rgba = getattr(getattr(getattr(v, "material", None), "color", None), "rgba", None)
                add_visual(out.model, body, vis, f"{name}.visual[{k}]", rgba)
                if c is not None:
                    out.contours.setdefault(name, []).append((body, c))
            for k, col in enumerate(link.collisions or []):
                what = f"{self.label}: link '{name}'.collision[{k}]"
                *_, c, _ = self.geometry(col, what, A, b, self.contour_source == "collision")
                if c is not None:
                    out.contours.setdefault(name, []).append((body, c))


def load_urdf(source, *, root: str = "ground", package_dirs: Sequence[str | Path] | str | Path | None = None,
              contours: str | None = "collision", limits: str = "data", gravity: Sequence[float] = (0.0, 0.0, -9.81),
              name: str | None = None) -> URDFImport:
    """Imports a URDF robot description (a file path or the XML text) as a mechsys model.

    ``root``: ``"ground"`` (fixed base: the root link is the ground) or ``"free"`` (a floating
    base on a ``Free`` joint). ``package_dirs``: directories searched for ``package://`` meshes
    (each either the package folder itself or a folder holding it); relative mesh paths are
    relative to the URDF file. ``contours``: which geometry becomes contours, ``"collision"``,
    ``"visual"`` or None (meshes are still checked to exist). ``limits``: ``"data"`` keeps the
    joint limits as :attr:`URDFImport.limits` only; ``"stops"`` also adds two gap contacts per
    bounded joint, ``<joint>_lower`` and ``<joint>_upper`` (simulate with a contact integrator).
    ``gravity`` defaults to URDF's z-up convention. ``<mimic>`` joints become
    :class:`mechsys.constraints.Coupler` constraints; joint ``<dynamics damping>`` a damper.

    Returns a :class:`URDFImport` (``.model``, ``.limits``, ``.contours``, ``.visuals``, ...).
    Errors are :class:`mechsys.ModelError` naming the file, link or joint.
    """
    yourdfpy = _yourdfpy()
    base_dir = None
    if isinstance(source, Path) or (isinstance(source, str) and "<" not in source):
        path = Path(source)
        label = str(path)
        if not path.is_file():
            raise ModelError(f"{label}: no such URDF file")
        base_dir = path.parent
        robot = _parse(str(path), label, yourdfpy)
    elif isinstance(source, (str, bytes)):
        label = "URDF"
        text = source.encode() if isinstance(source, str) else source
        robot = _parse(io.BytesIO(text), label, yourdfpy)
    else:
        raise ModelError(f"load_urdf: expected a file path or the URDF text, got {type(source).__name__}")
    loader = _Loader(robot, label, base_dir, package_dirs, root, contours, limits)
    return loader.build(name, gravity)


__all__ = ["load_urdf", "URDFImport", "JointLimit", "Visual"]
