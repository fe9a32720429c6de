"""The model builder: bodies, joints, force elements and gravity, validated by the engine.

A :class:`Model` collects the description; :meth:`Model.build` (called by ``simulate`` and the
analysis functions) hands it to the Rust engine, which validates everything and names the
offending item in any error. The description is plain data, the same as a TOML model file.
"""

from __future__ import annotations

import copy
import json
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from . import _core
from .errors import ModelError
from .joints import Frame, Joint


@dataclass
class Body:
    """Handle of a body in a model (returned by :meth:`Model.add_body`; ``model.ground`` too)."""

    name: str
    model: "Model" = field(repr=False)

    def add_marker(self, name: str, position: Sequence[float] = (0.0, 0.0, 0.0), **rotation) -> "Body":
        """Adds a named body-fixed frame (``rotation=``, ``cardan=``, ``euler=`` or ``rotvec=``)."""
        self.model.add_marker(self.name, name, position, **rotation)
        return self

    def node(self, node) -> tuple:
        """The undeformed position (body frame) of node ``node`` (index or name ``"n<k>"``) of this
        elastic body: a point given there (a constraint's or force element's) moves with the node."""
        desc = next((b for b in self.model._bodies if isinstance(b, dict) and b.get("name") == self.name), None)
        nodes = ((desc or {}).get("elastic") or {}).get("nodes") or []
        if not nodes:
            raise ModelError(f"body '{self.name}': not an elastic body with nodes")
        if isinstance(node, str):
            k = next((i for i, n in enumerate(nodes) if n["name"] == node), None)
        elif isinstance(node, (int, np.integer)) and not isinstance(node, bool) and -len(nodes) <= node < len(nodes):
            k = int(node) % len(nodes)
        else:
            k = None
        if k is None:
            raise ModelError(f"body '{self.name}'.node: no node {node!r} (the body has {len(nodes)} nodes, "
                             f"0..{len(nodes) - 1} or 'n0'..'n{len(nodes) - 1}')")
        return tuple(float(x) for x in nodes[k]["position"])

    def contour(self, contour, material=None) -> "Any":
        """This body carrying a contour (see :mod:`mechsys.contours`), for a :class:`mechsys.Contact`;
        ``material``: a :class:`mechsys.Material` for compliant laws (Hertz, Johnson)."""
        from .contours import Contour, OnBody
        from .laws import Material

        if not isinstance(contour, Contour):
            raise ModelError(f"body '{self.name}'.contour: expected a mechsys.contours contour, got {type(contour).__name__}")
        if material is not None and not isinstance(material, Material):
            raise ModelError(f"body '{self.name}'.contour: material: expected mechsys.Material(E, nu, density), got {type(material).__name__}")
        return OnBody(self.name, contour, material)


from .joints import _vec3  # noqa: E402  (one vector check for the whole builder)


class Model:
    """A multibody model under construction.

    >>> m = Model("pendulum", gravity=(0, -9.81, 0))
    >>> rod = m.add_body("rod", mass=1.0, inertia=[1e-4, 0.0833, 0.0833], com=(0.5, 0, 0))

    ``planar=True`` makes a planar model: every body moves in the world x-y plane (revolute joints
    about z, prismatic joints in the plane, :class:`mechsys.joints.Planar` for free bodies, fixed
    joints), gravity lies in the plane, and loop closures hold only their in-plane equations (a
    point coincidence 2, a revolute loop 2, a fixed loop 3), so a planar loop is never redundant.
    """

    def __init__(self, name: str = "model", gravity: Sequence[float] = (0.0, 0.0, 0.0), *, planar: bool = False):
        self.name = name
        self.gravity = _vec3(gravity, "gravity")
        self._planar = False
        self._built = None
        self._engine = None
        self.planar = planar
        self._bodies: list[dict] = []
        self._joints: list[Joint | dict] = []
        self._forces: list[Any] = []
        self._constraints: list[Any] = []
        self._contacts: list[Any] = []
        self._contact_groups: list[Any] = []
        self._visuals: list[dict] = []
        self._ground_markers: list[dict] = []
        self._built: tuple[str, Any, list, dict] | None = None
        self._engine: tuple | None = None
        self._extra_callbacks: list = []
        self.ground = Body("ground", self)

    @property
    def planar(self) -> bool:
        """Whether this is a planar model (see the class docstring); changing it rebuilds."""
        return self._planar

    @planar.setter
    def planar(self, value: bool) -> None:
        if not isinstance(value, (bool, np.bool_)):
            raise ModelError(f"model '{self.name}'.planar: expected true or false, got {value!r}")
        self._planar = bool(value)
        self._invalidate()

    # ---- building ------------------------------------------------------------------------------
    def add_body(
        self,
        name: str,
        mass: float,
        inertia,
        com: Sequence[float] = (0.0, 0.0, 0.0),
        *,
        mass_rate: float = 0.0,
        ejection_velocity: Sequence[float] = (0.0, 0.0, 0.0),
        ejection_point: Sequence[float] | None = None,
        mass_final: float | None = None,
        elastic: dict | None = None,
    ) -> Body:
        """Adds a rigid body. ``inertia`` about the centre of mass in body components: a 3x3
        matrix, its diagonal, or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]. A variable-mass body (section
        2.1.1) has ``mass_rate`` (kg/s, negative when ejecting), the ``ejection_velocity`` of the
        ejected mass relative to the body (body frame), and the ``mass_final`` at which the flow stops."""
        try:
            mass_f = float(mass)
        except (TypeError, ValueError):
            raise ModelError(f"body '{name}'.mass: expected a number, got {mass!r}") from None
        try:
            inert = np.asarray(inertia, dtype=float)
        except (TypeError, ValueError):
            raise ModelError(f"body '{name}'.inertia: expected a 3x3 matrix or a list of numbers, got {inertia!r}") from None
        body = {
            "name": name,
            "mass": mass_f,
            "inertia": inert.tolist(),
            "com": _vec3(com, f"body '{name}'.com"),
            "markers": [],
        }
        if mass_rate:
            body["mass_rate"] = float(mass_rate)
            body["ejection_velocity"] = _vec3(ejection_velocity, f"body '{name}'.ejection_velocity")
            if ejection_point is not None:
                body["ejection_point"] = _vec3(ejection_point, f"body '{name}'.ejection_point")
            if mass_final is not None:
                body["mass_final"] = float(mass_final)
        if elastic is not None:
            # the Ritz invariants of an elastic body (mechsys.elastic builds them); the engine checks them
            if not isinstance(elastic, dict):
                to_engine = getattr(elastic, "to_engine", None)
                if to_engine is None:
                    raise ModelError(f"body '{name}'.elastic: expected the invariants of an elastic body (a dict or "
                                     f"an object with to_engine()), got {type(elastic).__name__}")
                elastic = to_engine()
            body["elastic"] = copy.deepcopy(elastic)
        self._bodies.append(body)
        self._invalidate()
        return Body(name, self)

    def add_marker(self, body: str | Body, name: str, position: Sequence[float] = (0.0, 0.0, 0.0), **rotation) -> None:
        """Adds a named frame to a body (or to the ground)."""
        bname = body if isinstance(body, str) else body.name
        f = Frame(position=position, **rotation).describe()
        marker = {"name": name, **f}
        if bname == "ground":
            self._ground_markers.append(marker)
        else:
            for b in self._bodies:
                if b["name"] == bname:
                    b["markers"].append(marker)
                    break
            else:
                raise ModelError(f"add_marker: unknown body '{bname}'")
        self._invalidate()

    def _own_bodies(self, element, what: str) -> None:
        """ModelError when an element refers to a body handle of another model (joined by name it
        would silently take this model's body of the same name)."""
        items = vars(element).items() if hasattr(element, "__dict__") else ()
        for key, value in items:
            for v in (value if isinstance(value, (list, tuple)) else [value]):
                body = v if isinstance(v, Body) else getattr(v, "body", None) if hasattr(v, "contour") else None
                owner = getattr(body, "model", self) if isinstance(body, Body) else self
                if owner is not self:
                    name = getattr(element, "name", "?")
                    raise ModelError(f"{what} '{name}'.{key}: the body handle '{body.name}' belongs to model "
                                     f"'{owner.name}', not to '{self.name}' (use this model's add_body handle, or its name)")

    def add_joint(self, joint: Joint | dict) -> Joint | dict:
        """Adds a joint (see :mod:`mechsys.joints`)."""
        if not isinstance(joint, (Joint, dict)):
            raise ModelError(f"add_joint: expected a mechsys.joints joint, got {type(joint).__name__}")
        self._own_bodies(joint, "joint")
        self._joints.append(joint)
        self._invalidate()
        return joint

    def add_force(self, force) -> Any:
        """Adds a force element (see :mod:`mechsys.forces`)."""
        if not (hasattr(force, "describe") or isinstance(force, dict)):
            raise ModelError(f"add_force: expected a mechsys.forces element, got {type(force).__name__}")
        self._own_bodies(force, "force")
        self._forces.append(force)
        self._invalidate()
        return force

    def add_constraint(self, constraint) -> Any:
        """Adds a bilateral constraint (see :mod:`mechsys.constraints`)."""
        if not (hasattr(constraint, "describe") or isinstance(constraint, dict)):
            raise ModelError(f"add_constraint: expected a mechsys.constraints element, got {type(constraint).__name__}")
        self._own_bodies(constraint, "constraint")
        self._constraints.append(constraint)
        self._invalidate()
        return constraint

    def add_contact(self, contact) -> Any:
        """Adds a unilateral contact (see :class:`mechsys.Contact`), a contact given by a gap
        function (:class:`mechsys.GapContact`) or a contact group (:class:`mechsys.ContactGroup`)."""
        from .contacts import ContactGroup

        if isinstance(contact, ContactGroup):
            return self.add_contact_group(contact)
        if not (hasattr(contact, "describe") or isinstance(contact, dict)):
            raise ModelError(f"add_contact: expected a mechsys.Contact, got {type(contact).__name__}")
        self._contacts.append(contact)
        self._invalidate()
        return contact

    def add_contact_group(self, group) -> Any:
        """Adds a contact group (see :class:`mechsys.ContactGroup`)."""
        from .contacts import ContactGroup

        if not isinstance(group, (ContactGroup, dict)):
            raise ModelError(f"add_contact_group: expected a mechsys.ContactGroup, got {type(group).__name__}")
        self._contact_groups.append(group)
        self._invalidate()
        return group

    def add_elastic_body(self, name: str, reduced, *, damping=None, rayleigh=None, modal=None, stiffening: bool = True,
                         q0=None, u0=None) -> Body:
        """Adds an elastic body (floating frame of reference) from a :class:`mechsys.elastic.ReducedBody`
        (analytic beam modes, the beam FE model reduced, or a file of an external FE code): its
        mass properties are the undeformed body's, its elastic coordinates follow every joint's.
        Damping: a matrix, ``rayleigh=(alpha, beta)`` or ``modal=zeta``. ``stiffening=False``
        leaves out the geometric stiffness (a spinning beam's model then misses its centrifugal
        stiffening). Joints attach to the body frame; the nodes are in ``reduced.nodes``."""
        from .elastic import ReducedBody

        if not isinstance(reduced, ReducedBody):
            raise ModelError(f"body '{name}': expected a mechsys.elastic.ReducedBody, got {type(reduced).__name__}")
        table = reduced.to_engine()
        if not stiffening:
            table.pop("geometric", None)
        given = [x is not None for x in (damping, rayleigh, modal)]
        if sum(given) > 1:
            raise ModelError(f"body '{name}': give one of damping, rayleigh and modal")
        if damping is not None:
            table["damping"] = np.asarray(damping, dtype=float).tolist()
        elif rayleigh is not None or modal is not None:
            table["damping"] = reduced.damping(rayleigh=rayleigh, modal=modal).tolist()
        if q0 is not None:
            table["q0"] = np.asarray(q0, dtype=float).reshape(-1).tolist()
        if u0 is not None:
            table["u0"] = np.asarray(u0, dtype=float).reshape(-1).tolist()
        return self.add_body(name, reduced.mass, reduced.inertia_about_center(), com=tuple(reduced.center_of_mass),
                             elastic=table)

    def add_visual(self, body: "str | Body", shape, *, name: str = "", color: Sequence[float] | None = None,
                   opacity: float | None = None, scale: float = 1.0, position: Sequence[float] = (0.0, 0.0, 0.0),
                   cardan: Sequence[float] | None = None) -> dict:
        """Adds a shape the viewer draws on ``body`` (no contact): a contour of
        :mod:`mechsys.contours` (placed by its own centre and angles), or a mesh — a file (STL,
        OBJ, PLY, glTF, ... read through trimesh), a ``trimesh.Trimesh`` or ``(vertices,
        triangles)`` — scaled by ``scale`` and placed at ``position`` turned by ``cardan``
        angles (x-y-z) in the body frame. ``color`` is RGB in [0, 1], ``opacity`` in (0, 1]."""
        from pathlib import Path

        from .contours import Contour, Mesh, _mesh_arrays, _read_mesh_file

        body_name = body.name if isinstance(body, Body) else body
        what = f"visual '{name}'" if name else f"visual on body '{body_name}'"
        if not isinstance(body_name, str):
            raise ModelError(f"{what}.body: expected a body or its name, got {type(body).__name__}")
        if isinstance(shape, Contour) and not isinstance(shape, Mesh):
            desc = shape.describe(f"{what}.shape")
        else:
            if isinstance(shape, Mesh):
                v, t = shape.vertices, shape.triangles
            elif isinstance(shape, (str, Path)):
                v, t = _read_mesh_file(shape, f"{what}.shape")
            elif hasattr(shape, "vertices") and hasattr(shape, "faces"):
                v, t = np.asarray(shape.vertices, dtype=float), np.asarray(shape.faces)
            elif isinstance(shape, (tuple, list)) and len(shape) == 2:
                v, t = shape
            else:
                raise ModelError(f"{what}.shape: expected a mechsys.contours contour, a mesh file, a trimesh mesh "
                                 f"or (vertices, triangles), got {type(shape).__name__}")
            v, t = _mesh_arrays(v, t, scale, False, f"{what}.shape")
            from .kinematics import cardan_xyz_to_matrix

            rot = np.eye(3) if cardan is None else np.asarray(cardan_xyz_to_matrix(_vec3(cardan, f"{what}.cardan")))
            v = v @ rot.T + np.asarray(_vec3(position, f"{what}.position"))
            desc = {"type": "mesh", "vertices": v.tolist(), "triangles": t.tolist()}
        visual: dict[str, Any] = {"name": str(name), "body": body_name, "shape": desc}
        if color is not None:
            visual["color"] = _vec3(color, f"{what}.color")
        if opacity is not None:
            try:
                visual["opacity"] = float(opacity)
            except (TypeError, ValueError):
                raise ModelError(f"{what}.opacity: expected a number in (0, 1], got {opacity!r}") from None
        self._visuals.append(visual)
        self._invalidate()
        return visual

    # ---- description and engine model -----------------------------------------------------------
    def describe(self) -> tuple[dict, list]:
        """The plain-data description (as in a model file) and the Python callbacks it refers to."""
        callbacks: list = list(self._extra_callbacks)

        def described(element, what):
            if isinstance(element, dict):
                return element
            try:
                return element.describe(callbacks)
            except (TypeError, ValueError) as e:
                if isinstance(e, ModelError):
                    raise
                raise ModelError(f"{what} '{getattr(element, 'name', '?')}': a value is not what it should be ({e}); "
                                 "numbers must be numbers (not strings)") from None

        forces = [described(f, "force") for f in self._forces]
        constraints = [described(c, "constraint") for c in self._constraints]
        desc = {
            "name": self.name,
            "gravity": list(self.gravity),
            "bodies": copy.deepcopy(self._bodies),
            "joints": [j if isinstance(j, dict) else j.describe() for j in self._joints],
            "forces": forces,
            "ground_markers": copy.deepcopy(self._ground_markers),
        }
        if self.planar:
            desc["planar"] = True
        if constraints:
            desc["constraints"] = constraints
        described_contacts = [c if isinstance(c, dict) else c.describe(callbacks) for c in self._contacts]
        # a gap contact (a user gap function, mechsys.GapContact) has a "gap" instead of contours
        contacts = [c for c in described_contacts if not (isinstance(c, dict) and "gap" in c)]
        gaps = [c for c in described_contacts if isinstance(c, dict) and "gap" in c]
        if contacts:
            desc["contacts"] = contacts
        if gaps:
            desc["gap_contacts"] = gaps
        groups = [g if isinstance(g, dict) else g.describe(callbacks) for g in self._contact_groups]
        if groups:
            desc["contact_groups"] = groups
        if self._visuals:
            desc["visuals"] = copy.deepcopy(self._visuals)
        return desc, callbacks

    def to_dict(self) -> dict:
        """The description as plain data (Python callables appear as callback ids)."""
        return self.describe()[0]

    def build(self) -> "_core.Model":
        """Validates the model in the engine (cached until the model changes)."""
        if self._built is None:
            desc, callbacks = self.describe()
            text = json.dumps(desc, allow_nan=True)
            # the last slot caches what every run's results carry (see `run_metadata`)
            self._built = (text, _core.Model(text), callbacks, {})
            _warn_static_below_sliding(desc)
        return self._built[1]

    def run_metadata(self) -> tuple[str, list[dict]]:
        """The engine's description as JSON and its joint table, as every run's results carry
        them; made once per build (for a small model they were a tenth of a millisecond of each
        run). The joint dicts are shared between runs: read them, do not change them."""
        self.build()
        cache = self._built[3]  # type: ignore[index]
        if "meta" not in cache:
            core = self._built[1]  # type: ignore[index]
            cache["meta"] = (core.description_json(), core.joints())
        return cache["meta"]

    def _invalidate(self) -> None:
        self._built = None
        self._engine = None

    def engine(self) -> tuple:
        """(engine model, callbacks or None): the fast path for repeated single evaluations."""
        if self._engine is None:
            self.build()
            built = self._built
            self._engine = (built[1], built[2] or None)  # type: ignore[index]
        return self._engine

    @property
    def callbacks(self) -> list:
        """Python callables referred to by the description."""
        self.build()
        return self._built[2]  # type: ignore[index]

    @classmethod
    def from_dict(cls, desc: dict, callbacks: list | None = None) -> "Model":
        """A model from a plain-data description (e.g. a parsed TOML model file)."""
        if not isinstance(desc, dict):
            raise ModelError(f"model: expected a table/dict, got {type(desc).__name__}")
        planar = desc.get("planar", False)
        if not isinstance(planar, bool):
            raise ModelError(f"model.planar: expected true or false, got {planar!r}")
        m = cls(desc.get("name", "model"), desc.get("gravity", (0.0, 0.0, 0.0)), planar=planar)
        # non-list values are passed on unchanged so the engine reports "expected a sequence"
        def seq(key):
            v = desc.get(key, [])
            return copy.deepcopy(list(v) if isinstance(v, (list, tuple)) else v)

        m._bodies = seq("bodies")
        m._joints = seq("joints")
        m._forces = seq("forces")
        m._ground_markers = seq("ground_markers")
        m._constraints = seq("constraints")
        m._contacts = seq("contacts")
        gaps = seq("gap_contacts")
        if isinstance(gaps, list) and isinstance(m._contacts, list):
            m._contacts += gaps
        elif gaps:
            raise ModelError(f"model.gap_contacts: expected a list of tables, got {type(gaps).__name__}")
        m._contact_groups = seq("contact_groups")
        m._visuals = seq("visuals")
        known = {"name", "gravity", "planar", "bodies", "joints", "forces", "ground_markers", "constraints", "contacts",
                 "gap_contacts", "contact_groups", "visuals"}
        extra = set(desc) - known
        if extra:
            # let the engine produce the canonical message for a misspelt top-level key
            _core.Model(json.dumps(desc))
        m._extra_callbacks = list(callbacks or [])
        return m

    # ---- information ----------------------------------------------------------------------------
    @property
    def nq(self) -> int:
        """Number of generalized coordinates."""
        return self.build().nq

    @property
    def nu(self) -> int:
        """Number of generalized velocities (degrees of freedom of the tree)."""
        return self.build().nu

    def joint_info(self) -> list[dict]:
        """Per joint: name, type, parent, child, index ranges in q (iq, nq) and u (iu, nu)."""
        return self.build().joints()

    def body_info(self) -> list[dict]:
        """Per body: name, mass, com, inertia, parent joint, markers."""
        return self.build().bodies()

    def q0(self) -> np.ndarray:
        """Initial coordinates from the joints' q0 (neutral where none was given)."""
        return self.build().q0()

    def u0(self) -> np.ndarray:
        """Initial velocities from the joints' u0 (zero where none was given)."""
        return self.build().u0()

    def state_vector(self, values, which: str) -> np.ndarray:
        """A full q (``which='q'``) or u vector from an array or a {joint name: value} dict,
        starting from the model's own initial values."""
        core = self.build()
        base = core.q0() if which == "q" else core.u0()
        n = core.nq if which == "q" else core.nu
        if values is None:
            return base
        if isinstance(values, dict):
            info = {j["name"]: j for j in core.joints()}
            out = np.array(base, dtype=float)
            for name, v in values.items():
                if name not in info:
                    raise ModelError(f"{which}0: unknown joint '{name}' (joints: {', '.join(info)})")
                j = info[name]
                start, cnt = (j["iq"], j["nq"]) if which == "q" else (j["iu"], j["nu"])
                arr = np.atleast_1d(np.asarray(v, dtype=float))
                if arr.size != cnt:
                    raise ModelError(
                        f"{which}0['{name}']: a {j['type']} joint has {cnt} {'coordinates' if which == 'q' else 'velocities'}, got {arr.size}"
                    )
                out[start : start + cnt] = arr
            return out
        arr = np.asarray(values, dtype=float).reshape(-1)
        if arr.size != n:
            raise ModelError(f"{which}0: the model has {n} {'coordinates' if which == 'q' else 'velocities'}, got {arr.size}")
        return arr

    # ---- pickling and changed copies -----------------------------------------------------------
    def __getstate__(self) -> dict:
        """The plain description and element objects without the engine caches (rebuilt on first
        use), so a model goes to a process pool or a Dask worker. A Python function in the model
        must pickle itself (a module-level function); a lambda or a nested function is a
        ModelError naming the element that holds it."""
        _check_picklable_callables(self)
        state = dict(self.__dict__)
        state["_built"] = None
        state["_engine"] = None
        state.pop("_warned", None)
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    def __copy__(self) -> "Model":
        new = Model.__new__(type(self))
        new.__dict__.update({k: v for k, v in self.__dict__.items() if k != "_warned"})
        new._built = new._engine = None
        return new

    def __deepcopy__(self, memo: dict) -> "Model":
        # (not through pickling: a copy in this process may keep a lambda)
        new = Model.__new__(type(self))
        memo[id(self)] = new
        for k, v in self.__dict__.items():
            if k not in ("_built", "_engine", "_warned"):
                setattr(new, k, copy.deepcopy(v, memo))
        new._built = new._engine = None
        return new

    def with_values(self, values: dict) -> "Model":
        """A new model with values changed by dotted paths into the description, e.g.
        ``{"body.arm.mass": 2.0, "force.damper.d": 1500, "joint.pin.q0": [0.1],
        "contact.beak.friction.mu": 0.2, "gravity": [0, 0, -9.81]}`` (see :func:`set_path`). This
        model is left as it is; the new one is validated by the engine."""
        if not isinstance(values, dict):
            raise ModelError(f"with_values: expected a dict of dotted path -> value, got {type(values).__name__}")
        desc, callbacks = self.describe()
        desc = copy.deepcopy(desc)  # element dicts of the description are this model's own
        added = []
        for path, value in values.items():
            if set_path(desc, path, value):
                added.append(path)
        try:
            m = Model.from_dict(desc, callbacks)
            m.build()
        except ModelError as e:
            if added and "unknown field" in str(e):
                raise ModelError(f"{', '.join(added)}: not a key of the model description ({e})") from None
            raise
        return m

    def __repr__(self) -> str:
        return f"Model('{self.name}', bodies={len(self._bodies)}, joints={len(self._joints)}, forces={len(self._forces)})"


__all__ = ["Model", "Body", "set_path"]


def _warn_static_below_sliding(desc: dict) -> None:
    """mu0 < mu is accepted (a measured Stribeck curve may rise from rest), with a warning: the
    contact then sticks up to mu, since a slide against more friction than held it cannot start."""
    import warnings

    for kind in ("contacts", "contact_groups"):
        for c in desc.get(kind, []):
            f = c.get("friction") or {}
            mu, mu0 = f.get("mu"), f.get("mu0")
            if isinstance(mu, (int, float)) and isinstance(mu0, (int, float)) and mu0 < mu:
                what = "contact" if kind == "contacts" else "contact group"
                warnings.warn(f"{what} '{c.get('name')}': the static coefficient mu0 = {mu0} is below the sliding "
                              f"one mu = {mu}; it sticks up to mu", UserWarning, stacklevel=3)


#: Dotted-path prefixes and the description lists they name (``body.arm`` is bodies[name=arm]).
PATH_KINDS = {
    "body": "bodies", "joint": "joints", "force": "forces", "constraint": "constraints", "contact": "contacts",
    "gap_contact": "gap_contacts", "contact_group": "contact_groups", "ground_marker": "ground_markers",
}


def _names_at(node) -> list[str]:
    if isinstance(node, dict):
        return [str(k) for k in node]
    if isinstance(node, list):
        named = [x.get("name") for x in node if isinstance(x, dict) and isinstance(x.get("name"), str)]
        return named if len(named) == len(node) else [str(i) for i in range(len(node))]
    return []


def set_path(desc: dict, path: str, value: Any) -> bool:
    """Sets ``value`` at a dotted ``path`` in a model description dict (in place): the first part is
    a top-level key (``gravity``, ``name``) or an element kind (``body``, ``joint``, ``force``,
    ``constraint``, ``contact``, ``contact_group``, ``ground_marker``) followed by the element's
    name; then keys of nested tables, names of named list entries (``markers``) or list indices.
    An unknown part is a ModelError naming the path and listing what exists at that level. The
    last key may be new to the element (a joint's ``q0`` not given before; the engine then checks
    it): returns whether it was."""
    if not isinstance(path, str) or not path or any(not p for p in path.split(".")):
        raise ModelError(f"parameter {path!r}: expected a dotted path such as 'body.arm.mass'")
    parts = path.split(".")
    head = parts[0]
    if head in PATH_KINDS or head in PATH_KINDS.values():
        kind = PATH_KINDS.get(head, head)
        if len(parts) < 3:
            raise ModelError(f"parameter '{path}': give the element's name and a key, e.g. '{head}.NAME.KEY'")
        if kind == "contacts":
            pool = list(desc.get("contacts", [])) + list(desc.get("gap_contacts", []))
        else:
            pool = list(desc.get(kind, []))
        node = next((e for e in pool if isinstance(e, dict) and e.get("name") == parts[1]), None)
        if node is None:
            names = ", ".join(str(e.get("name")) for e in pool if isinstance(e, dict)) or "(none)"
            raise ModelError(f"parameter '{path}': no {head} named '{parts[1]}'; the model's are: {names}")
        rest, where = parts[2:], f"{head}.{parts[1]}"
    else:
        node, rest, where = desc, parts, ""
        if head not in desc:
            kinds = ", ".join([k for k in desc if k not in PATH_KINDS.values()] + [k + ".NAME" for k in PATH_KINDS])
            raise ModelError(f"parameter '{path}': unknown top-level key '{head}'; expected one of {kinds}")
    for k, key in enumerate(rest):
        last = k == len(rest) - 1
        if isinstance(node, list):
            idx = None
            if key.isdigit():
                idx = int(key)
            else:
                idx = next((i for i, x in enumerate(node) if isinstance(x, dict) and x.get("name") == key), None)
            if idx is None or idx >= len(node):
                raise ModelError(f"parameter '{path}': '{key}' is not an entry of {where or 'the model'}; "
                                 f"entries: {', '.join(_names_at(node)) or '(none)'}")
            if last:
                node[idx] = value
                return False
            node, where = node[idx], f"{where}.{key}" if where else key
            continue
        if not isinstance(node, dict):
            raise ModelError(f"parameter '{path}': {where} is a value ({node!r}), it has no '{key}'")
        if key not in node:
            if last and where:
                node[key] = value
                return True
            raise ModelError(f"parameter '{path}': unknown key '{key}' at {where or 'the top level'}; "
                             f"keys there: {', '.join(_names_at(node)) or '(none)'}")
        if last:
            node[key] = value
            return False
        node, where = node[key], f"{where}.{key}" if where else key
    return False


def _check_picklable_callables(model: "Model") -> None:
    """ModelError naming the element (and attribute) whose Python function cannot be pickled."""
    import pickle
    import types

    def walk(obj, where: str, depth: int):
        if depth > 6 or isinstance(obj, (str, bytes, int, float, bool, type(None), np.ndarray, Body, Model)):
            return
        if isinstance(obj, (types.FunctionType, types.MethodType, types.BuiltinFunctionType)) or (
                callable(obj) and not isinstance(obj, type) and not hasattr(obj, "__dataclass_fields__")
                and not hasattr(obj, "__dict__")):
            try:
                pickle.dumps(obj)
            except Exception as e:  # noqa: BLE001 - any failure to pickle is reported the same way
                name = getattr(obj, "__qualname__", type(obj).__name__)
                raise ModelError(f"{where}: the Python function '{name}' cannot be pickled ({type(e).__name__}: {e}); "
                                 "define it at module level (not a lambda or a nested function) to send the model "
                                 "to another process") from None
            return
        if isinstance(obj, dict):
            items = obj.items()
        elif isinstance(obj, (list, tuple)):
            items = enumerate(obj)
        elif hasattr(obj, "__dict__") and type(obj).__module__.startswith("mechsys"):
            items = vars(obj).items()  # (other libraries' objects pickle as they define)
        else:
            return
        for key, v in items:
            walk(v, f"{where}.{key}" if not isinstance(key, int) else f"{where}[{key}]", depth + 1)

    groups = (("joint", model._joints), ("force", model._forces), ("constraint", model._constraints),
              ("contact", model._contacts), ("contact group", model._contact_groups))
    for what, elements in groups:
        for k, e in enumerate(elements if isinstance(elements, list) else []):
            name = e.get("name") if isinstance(e, dict) else getattr(e, "name", None)
            walk(e, f"{what} '{name}'" if name is not None else f"{what}[{k}]", 0)
    for k, f in enumerate(model._extra_callbacks):
        walk(f, f"model '{model.name}' callback {k}", 0)
