"""MJCF import: a MuJoCo model's body tree as a mechsys model.

The file is compiled by MuJoCo's own loader (the ``mujoco`` package), so defaults classes,
``<include>``, angle units, ``inertiafromgeom`` and the other compiler settings mean exactly what
they mean to MuJoCo. The compiled model's arrays are then walked here.

Frames. A MuJoCo body frame is the mechsys body frame: ``body_pos``/``body_quat`` place it in
its parent at the joint's reference position. The centre of mass is ``body_ipos`` and the
principal moments ``body_inertia`` are given in the frame ``body_iquat``, turned into body axes
as ``R diag(I) R^T``. A joint's motion happens in the body frame: a hinge turns about
``jnt_axis`` through ``jnt_pos``, a slide moves along ``jnt_axis``, both by ``q - ref``; the
mechsys joint gets the same coordinate as MuJoCo's ``qpos`` (the reference angle is folded into
the parent frame). A ball joint's quaternion and a free joint's position and quaternion are
MuJoCo's ``qpos`` too. Velocities: hinge, slide and ball are MuJoCo's ``qvel``; a free joint's
linear velocity is in the body frame here and in the world frame in MuJoCo (``v_B = R^T v_W``).

Bodies without a joint are welded to their parent: with mass, a body on a
:class:`~mechsys.joints.Fixed` joint; without mass, or welded to the world, a marker on the body they
hang from (their geometry goes there too). Two joints on one body become one mechsys joint when
one reproduces them with MuJoCo's coordinates: two hinges through one point a
:class:`~mechsys.joints.Universal` joint, a hinge and then a slide along its axis a
:class:`~mechsys.joints.Cylindrical` joint, named ``<joint1>_<joint2>``. Other
combinations have no mechsys counterpart (mechsys bodies need a mass, so there is no chain of
massless bodies) and are an error naming the body and its joints.

Geoms become contours (sphere, capsule, box, cylinder, ellipsoid, plane and mesh, with their
vertices from the compiled model) and visual records; height fields and SDFs are visual records
only. Sites become markers; ``opt.gravity`` the gravity. What the import leaves out (actuators,
tendons, equality constraints, armature, friction loss, fluid forces, ...) is named in a warning
(or an error with ``unsupported="error"``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import contours as _contours
from . import joints as _joints
from ._import import (JointLimit, ModelImport, Visual, add_limit_stops, add_visual, check_inertia, check_limit_mode,
                      primitive_contour)
from .errors import ModelError
from .kinematics import quat_to_matrix, rot_axis
from .model import Model

# mjtGeom and mjtJoint, by value: 0 plane, 1 hfield, 2 sphere, 3 capsule, 4 ellipsoid, 5 cylinder, 6 box, 7 mesh, 8 sdf
_GEOMS = {0: "plane", 1: "hfield", 2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh", 8: "sdf"}
_JOINTS = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}


@dataclass
class MJCFImport(ModelImport):
    """The result of :func:`load_mjcf` (see :class:`mechsys._import.ModelImport`): ``root`` is
    ``"world"``, ``contours`` and ``visuals`` are keyed by the MuJoCo body that holds the geom,
    ``markers`` maps massless welded bodies to the body they sit on, and ``ignored`` lists what
    the model holds that the import leaves out."""

    ignored: list[str] = field(default_factory=list)
    """What the model holds that the import leaves out, each item named."""
    compound: dict[str, list[str]] = field(default_factory=dict)
    """{mechsys joint: [MuJoCo joints]} for the bodies with two joints (see :func:`load_mjcf`)."""


def _mujoco():
    try:
        import mujoco
    except ImportError:
        raise ModelError("MJCF import needs the 'mujoco' package: pip install mujoco") from None
    return mujoco


def _names(m, mujoco, kind, count: int, prefix) -> list[str]:
    """Every object's name; unnamed ones get ``prefix(id)`` or ``<prefix><id>`` (made unique
    against the named ones)."""
    names = [mujoco.mj_id2name(m, kind, i) or "" for i in range(count)]
    taken = set(names)
    for i, n in enumerate(names):
        if not n:
            cand = prefix(i) if callable(prefix) else f"{prefix}{i}"
            while cand in taken:
                cand += "_"
            names[i] = cand
            taken.add(cand)
    return names


def _compile(source, mujoco):
    if isinstance(source, Path) or (isinstance(source, str) and "<" not in source):
        path = Path(source)
        label = str(path)
        if not path.is_file():
            raise ModelError(f"{label}: no such MJCF file")
        load, arg = mujoco.MjModel.from_xml_path, str(path)
    elif isinstance(source, (str, bytes)):
        label = "MJCF"
        load, arg = mujoco.MjModel.from_xml_string, source.decode() if isinstance(source, bytes) else source
    else:
        raise ModelError(f"load_mjcf: expected a file path or the MJCF text, got {type(source).__name__}")
    try:
        return load(arg), label
    except Exception as e:  # noqa: BLE001 - MuJoCo reports every compile error as one exception
        msg = " ".join(str(e).split())
        raise ModelError(f"{label}: MuJoCo cannot load the model ({msg})") from None


def load_mjcf(source, *, contours: str | None = "collision", limits: str = "data", unsupported: str = "warn",
              name: str | None = None) -> MJCFImport:
    """Imports a MuJoCo MJCF model (a file path or the XML text) as a mechsys model.

    The file is compiled by MuJoCo (``mujoco.MjModel``); hinge, slide, ball and free joints become
    :class:`~mechsys.joints.Revolute`, :class:`~mechsys.joints.Prismatic`,
    :class:`~mechsys.joints.Spherical` and :class:`~mechsys.joints.Free` joints with MuJoCo's
    coordinates, joint damping a damper and joint stiffness a spring about ``springref``.
    ``contours``: ``"collision"`` (geoms with a non-zero ``contype`` or ``conaffinity``),
    ``"all"`` or None. ``limits``: ``"data"`` keeps the ranges of limited joints as
    :attr:`MJCFImport.limits` only; ``"stops"`` also adds the gap contacts ``<joint>_lower`` and
    ``<joint>_upper`` (hinge and slide joints). ``unsupported``: what to do when the model holds
    something the import leaves out (actuators, tendons, equality constraints, armature, ...):
    ``"warn"`` (a warning naming the items), ``"error"`` or ``"ignore"``; the items are listed in
    :attr:`MJCFImport.ignored` either way.

    Returns an :class:`MJCFImport`. Errors are :class:`mechsys.ModelError` naming the file and
    the body, joint or geom.
    """
    mujoco = _mujoco()
    if unsupported not in ("warn", "error", "ignore"):
        raise ModelError(f"load_mjcf: unsupported must be 'warn', 'error' or 'ignore', got {unsupported!r}")
    if contours not in ("collision", "all", None):
        raise ModelError(f"load_mjcf: contours must be 'collision', 'all' or None, got {contours!r}")
    check_limit_mode(limits, "load_mjcf")
    m, label = _compile(source, mujoco)
    out = _Walker(m, mujoco, label).build(name, contours)
    if limits == "stops":
        in_compound = {j: c for c, js in out.compound.items() for j in js}
        for j, lim in out.limits.items():
            if lim.lower is None:
                raise ModelError(f"{label}: joint '{j}': a ball joint's cone limit cannot be a gap stop "
                                 "(load with limits='data')")
            if j in in_compound:
                raise ModelError(f"{label}: joint '{j}' is a coordinate of the mechsys joint '{in_compound[j]}': its "
                                 "limit cannot be a gap stop (load with limits='data')")
        add_limit_stops(out.model, out.limits, label)
    if out.ignored and unsupported != "ignore":
        text = f"{label}: not imported: " + "; ".join(out.ignored)
        if unsupported == "error":
            raise ModelError(text)
        warnings.warn(text, stacklevel=2)
    return out


class _Walker:
    def __init__(self, m, mujoco, label: str):
        self.m, self.mj, self.label = m, mujoco, label
        obj = mujoco.mjtObj
        self.bodies = _names(m, mujoco, obj.mjOBJ_BODY, m.nbody, "body")
        self.bodies[0] = "world"
        # an unnamed joint is called after its body and kind: <body>_free, <body>_hinge, ...
        self.joints = _names(m, mujoco, obj.mjOBJ_JOINT, m.njnt,
                             lambda j: f"{self.bodies[m.jnt_bodyid[j]]}_{_JOINTS[int(m.jnt_type[j])]}")
        self.geoms = _names(m, mujoco, obj.mjOBJ_GEOM, m.ngeom, "geom")

    def body_pose(self, b: int) -> tuple[np.ndarray, np.ndarray]:
        return quat_to_matrix(self.m.body_quat[b]), np.array(self.m.body_pos[b], dtype=float)

    def inertia(self, b: int) -> tuple[float, np.ndarray, np.ndarray]:
        m = self.m
        R = quat_to_matrix(m.body_iquat[b])
        I = R @ np.diag(m.body_inertia[b]) @ R.T
        return float(m.body_mass[b]), 0.5 * (I + I.T), np.array(m.body_ipos[b], dtype=float)

    def build(self, name: str | None, contour_mode: str | None) -> MJCFImport:
        m, label = self.m, self.label
        gravity = np.array(m.opt.gravity, dtype=float)
        if m.opt.disableflags & int(self.mj.mjtDisableBit.mjDSBL_GRAVITY):
            gravity = np.zeros(3)
        model_name = name or bytes(m.names[:200]).split(b"\0", 1)[0].decode(errors="replace")  # <mujoco model=...> comes first
        model = Model(model_name or "mjcf", gravity=tuple(gravity))
        out = MJCFImport(model=model, root="world")
        if "ground" in self.bodies:
            raise ModelError(f"{label}: body 'ground' clashes with mechsys's name for the inertial frame")
        # where each body's frame sits: (mechsys body, A, b) with v_body = A v_mujoco + b
        place: dict[int, tuple[str, np.ndarray, np.ndarray]] = {0: ("ground", np.eye(3), np.zeros(3))}
        for b in range(1, m.nbody):
            self.body(b, place, out)
        self.unsupported(out)
        self.geometry(out, place, contour_mode)
        self.sites(out, place)
        return out

    def body(self, b: int, place, out: MJCFImport) -> None:
        m, model = self.m, out.model
        bname = self.bodies[b]
        w = f"{self.label}: body '{bname}'"
        parent, A, t = place[int(m.body_parentid[b])]
        Rb, pb = self.body_pose(b)
        Rb, pb = A @ Rb, A @ pb + t  # the body frame at the reference position, in the parent mechsys body
        mass, inertia, com = self.inertia(b)
        first, count = int(m.body_jntadr[b]), int(m.body_jntnum[b])
        if count == 0:
            if mass == 0.0 or parent == "ground":
                # welded and massless, or welded to the world (its inertia never matters): a marker
                place[b] = (parent, Rb, pb)
                model.add_marker(parent, bname, tuple(pb), rotation=Rb.tolist())
                out.markers[bname] = parent
                return
            model.add_body(bname, mass, inertia, com=tuple(com))
            model.add_joint(_joints.Fixed(f"{bname}_weld", parent, bname,
                                          parent_frame=_joints.Frame(position=tuple(pb), rotation=Rb.tolist())))
            place[b] = (bname, np.eye(3), np.zeros(3))
            return
        check_inertia(w, mass, inertia)
        model.add_body(bname, mass, inertia, com=tuple(com))
        place[b] = (bname, np.eye(3), np.zeros(3))
        if count > 1:
            self.compound(b, parent, Rb, pb, out)
        else:
            self.joint(first, bname, parent, Rb, pb, out)
        for j in range(first, first + count):
            self.limit(j, out)

    def spring_damper(self, js: list[int]) -> dict:
        """Joint damping and stiffness (about ``springref``) of hinge and slide joints."""
        m, extra = self.m, {}
        d = [float(m.dof_damping[m.jnt_dofadr[j]]) for j in js]
        k = [float(m.jnt_stiffness[j]) for j in js]
        if any(d):
            extra["damper"] = _joints.JointDamper(d if len(d) > 1 else d[0])
        if any(k):
            q_free = [float(m.qpos_spring[m.jnt_qposadr[j]]) for j in js]
            extra["spring"] = _joints.JointSpring(k if len(k) > 1 else k[0], q_free if len(k) > 1 else q_free[0])
        return extra

    def joint(self, j: int, bname: str, parent: str, Rb: np.ndarray, pb: np.ndarray, out: MJCFImport) -> None:
        m, model = self.m, out.model
        jname, kind = self.joints[j], _JOINTS[int(m.jnt_type[j])]
        wj = f"{self.label}: joint '{jname}'"
        p = np.array(m.jnt_pos[j], dtype=float)
        axis = np.array(m.jnt_axis[j], dtype=float)
        qa = int(m.jnt_qposadr[j])
        extra = self.spring_damper([j]) if kind in ("hinge", "slide") else {}
        if kind == "hinge":
            ref = float(m.qpos0[qa])
            frame = _joints.Frame(position=tuple(Rb @ p + pb), rotation=(Rb @ rot_axis(axis, -ref)).tolist())
            model.add_joint(_joints.Revolute(jname, parent, bname, axis=tuple(axis), parent_frame=frame,
                                             child_frame=_joints.Frame(position=tuple(p)), q0=ref, **extra))
        elif kind == "slide":
            ref = float(m.qpos0[qa])
            frame = _joints.Frame(position=tuple(Rb @ (p - ref * axis) + pb), rotation=Rb.tolist())
            model.add_joint(_joints.Prismatic(jname, parent, bname, axis=tuple(axis), parent_frame=frame,
                                              child_frame=_joints.Frame(position=tuple(p)), q0=ref, **extra))
        elif kind == "ball":
            frame = _joints.Frame(position=tuple(Rb @ p + pb), rotation=Rb.tolist())
            model.add_joint(_joints.Spherical(jname, parent, bname, parent_frame=frame,
                                              child_frame=_joints.Frame(position=tuple(p))))
        else:  # free: MuJoCo's qpos is the body frame in the world, whatever the parent
            if parent != "ground":
                raise ModelError(f"{wj}: a free joint is placed in the world; mechsys's Free joint is relative to "
                                 f"its parent, so body '{bname}' must be a child of the world body")
            model.add_joint(_joints.Free(jname, "ground", bname, q0=[float(x) for x in m.qpos0[qa:qa + 7]]))

    def compound(self, b: int, parent: str, Rb: np.ndarray, pb: np.ndarray, out: MJCFImport) -> None:
        """Two joints on one body that one mechsys joint reproduces with MuJoCo's coordinates: two
        hinges through one point (Universal) or a hinge and then a slide along its axis
        (Cylindrical). Anything else is an error naming the body and its joints."""
        m, bname = self.m, self.bodies[b]
        first, count = int(m.body_jntadr[b]), int(m.body_jntnum[b])
        js = list(range(first, first + count))
        kinds = [_JOINTS[int(m.jnt_type[j])] for j in js]
        p = [np.array(m.jnt_pos[j], dtype=float) for j in js]
        a = [np.array(m.jnt_axis[j], dtype=float) for j in js]
        ref = [float(m.qpos0[m.jnt_qposadr[j]]) for j in js]
        name = "_".join(self.joints[j] for j in js)
        tol = 1e-12
        if kinds == ["hinge", "hinge"] and np.allclose(p[0], p[1], rtol=0, atol=tol) and np.linalg.norm(np.cross(a[0], a[1])) > 1e-9:
            # R(a1, q1 - r1) R(a2, q2 - r2) = R(a1, -r1) [R(a1, q1) R(a2, q2)] R(a2, -r2)
            frame = _joints.Frame(position=tuple(Rb @ p[0] + pb), rotation=(Rb @ rot_axis(a[0], -ref[0])).tolist())
            child = _joints.Frame(position=tuple(p[0]), rotation=rot_axis(a[1], ref[1]).tolist())
            joint = _joints.Universal(name, parent, bname, axis=tuple(a[0]), axis2=tuple(a[1]), parent_frame=frame,
                                      child_frame=child, q0=ref, **self.spring_damper(js))
        elif kinds == ["hinge", "slide"] and np.allclose(a[0], a[1], rtol=0, atol=tol):
            # rotation about and translation along one axis commute: both references go to the parent frame
            frame = _joints.Frame(position=tuple(Rb @ (p[0] - ref[1] * a[0]) + pb), rotation=(Rb @ rot_axis(a[0], -ref[0])).tolist())
            joint = _joints.Cylindrical(name, parent, bname, axis=tuple(a[0]), parent_frame=frame,
                                        child_frame=_joints.Frame(position=tuple(p[0])), q0=ref, **self.spring_damper(js))
        else:
            names = ", ".join(f"'{self.joints[j]}' ({k})" for j, k in zip(js, kinds))
            raise ModelError(f"{self.label}: body '{bname}': {count} joints ({names}): mechsys has one joint per body and no "
                             "massless bodies to chain them; two hinges through one point (universal) and a hinge then a "
                             "slide along its axis (cylindrical) are imported, other combinations are not")
        out.model.add_joint(joint)
        out.compound[name] = [self.joints[j] for j in js]

    def limit(self, j: int, out: MJCFImport) -> None:
        m = self.m
        if not m.jnt_limited[j]:
            return
        jname, kind = self.joints[j], _JOINTS[int(m.jnt_type[j])]
        lo, hi = (float(x) for x in m.jnt_range[j])
        if kind in ("hinge", "slide"):
            if lo > hi:
                raise ModelError(f"{self.label}: joint '{jname}': the lower limit {lo:g} is above the upper limit {hi:g}")
            out.limits[jname] = JointLimit(lo, hi)
        elif kind == "ball":
            out.limits[jname] = JointLimit(None, hi)  # a cone: the largest angle from the reference

    def unsupported(self, out: MJCFImport) -> None:
        m, notes = self.m, out.ignored
        for j in range(m.njnt):
            kind = _JOINTS[int(m.jnt_type[j])]
            da, nd = int(m.jnt_dofadr[j]), {"free": 6, "ball": 3}.get(kind, 1)
            dofs = slice(da, da + nd)
            for attr, what in (("dof_armature", "armature"), ("dof_frictionloss", "frictionloss")):
                if np.any(getattr(m, attr)[dofs] != 0.0):
                    notes.append(f"joint '{self.joints[j]}' {what}")
            if kind in ("ball", "free"):
                if np.any(m.dof_damping[dofs] != 0.0):
                    notes.append(f"joint '{self.joints[j]}' damping ({kind} joint)")
                if m.jnt_stiffness[j] != 0.0:
                    notes.append(f"joint '{self.joints[j]}' stiffness ({kind} joint)")
        obj = self.mj.mjtObj
        for count, kind, label in ((m.nu, obj.mjOBJ_ACTUATOR, "actuator"), (m.ntendon, obj.mjOBJ_TENDON, "tendon"),
                                   (m.neq, obj.mjOBJ_EQUALITY, "equality constraint"), (m.nsensor, obj.mjOBJ_SENSOR, "sensor")):
            for i in range(count):
                notes.append(f"{label} '{self.mj.mj_id2name(m, kind, i) or i}'")
        if m.npair or m.nexclude:
            notes.append(f"{m.npair} contact pair(s) and {m.nexclude} exclude(s) (pair contours with ms.Contact instead)")
        if getattr(m, "nflex", 0):
            notes.append(f"{m.nflex} flex object(s)")
        if m.opt.density != 0.0 or m.opt.viscosity != 0.0 or np.any(np.asarray(m.opt.wind) != 0.0):
            notes.append("fluid forces (option density, viscosity or wind)")
        for b in range(1, m.nbody):
            if m.body_mocapid[b] >= 0:
                notes.append(f"mocap body '{self.bodies[b]}' (imported as welded)")

    def geometry(self, out: MJCFImport, place, mode: str | None) -> None:
        m = self.m
        for g in range(m.ngeom):
            gname, kind = self.geoms[g], _GEOMS.get(int(m.geom_type[g]), f"type {int(m.geom_type[g])}")
            b = int(m.geom_bodyid[g])
            body, A, t = place[b]
            R, p = A @ quat_to_matrix(m.geom_quat[g]), A @ np.asarray(m.geom_pos[g], dtype=float) + t
            s = np.asarray(m.geom_size[g], dtype=float)
            size = {"sphere": s[0], "capsule": (s[0], 2.0 * s[1]), "cylinder": (s[0], 2.0 * s[1]), "box": s.copy(),
                    "ellipsoid": s.copy(), "plane": s[:2].copy()}.get(kind)
            file = None
            if kind == "mesh":
                file = self.mj.mj_id2name(m, self.mj.mjtObj.mjOBJ_MESH, int(m.geom_dataid[g]))
            T = np.eye(4)
            T[:3, :3], T[:3, 3] = R, p
            vis = Visual(kind, T, size, file)
            out.visuals.setdefault(self.bodies[b], []).append(vis)
            # drawn by the viewer: primitives as their contours, meshes from MuJoCo's compiled vertices
            rgba = np.asarray(m.geom_rgba[g], dtype=float)
            if kind == "mesh":
                mesh = self.mesh(int(m.geom_dataid[g]), R, p, f"{self.label}: geom '{gname}'")
                out.model.add_visual(body, (mesh.vertices, mesh.triangles), name=gname, color=tuple(rgba[:3]),
                                     opacity=float(rgba[3]) if 0.0 < rgba[3] < 1.0 else None)
            elif rgba[3] > 0.0:
                add_visual(out.model, body, vis, gname, rgba)
            collides = m.geom_contype[g] != 0 or m.geom_conaffinity[g] != 0
            if mode is None or (mode == "collision" and not collides):
                continue
            if kind == "mesh":
                c = self.mesh(int(m.geom_dataid[g]), R, p, f"{self.label}: geom '{gname}'")
            else:
                c = primitive_contour(kind, size, R, p)
            if c is None:
                out.ignored.append(f"geom '{gname}' ({kind}: no mechsys contour, kept as a visual)")
                continue
            out.contours.setdefault(self.bodies[b], []).append((body, c))

    def mesh(self, k: int, R: np.ndarray, p: np.ndarray, what: str):
        m = self.m
        va, vn, fa, fn = int(m.mesh_vertadr[k]), int(m.mesh_vertnum[k]), int(m.mesh_faceadr[k]), int(m.mesh_facenum[k])
        v = np.asarray(m.mesh_vert[va:va + vn], dtype=float) @ R.T + p
        f = np.asarray(m.mesh_face[fa:fa + fn], dtype=np.int64)
        return _contours.Mesh(v, f, source=what)

    def sites(self, out: MJCFImport, place) -> None:
        m = self.m
        for s in range(m.nsite):
            sname = self.mj.mj_id2name(m, self.mj.mjtObj.mjOBJ_SITE, s)
            if not sname:
                continue
            body, A, t = place[int(m.site_bodyid[s])]
            R = A @ quat_to_matrix(m.site_quat[s])
            out.model.add_marker(body, sname, tuple(A @ np.asarray(m.site_pos[s], dtype=float) + t), rotation=R.tolist())


__all__ = ["load_mjcf", "MJCFImport"]
