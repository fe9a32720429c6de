"""Model files: a model and its simulation defaults in TOML or Python.

A **TOML** model file holds the model description at the top level, with exactly the keys of the
engine's schema (``name``, ``gravity``, ``[[bodies]]``, ``[[joints]]``, ``[[forces]]``,
``[[ground_markers]]``), plus an optional ``[simulation]`` table::

    name = "pendulum"
    gravity = [0.0, -9.81, 0.0]

    [[bodies]]
    name = "rod"
    mass = 1.0
    inertia = [1e-4, 0.0833, 0.0833]
    com = [0.5, 0.0, 0.0]

    [[joints]]
    name = "hinge"
    type = "revolute"
    parent = "ground"
    child = "rod"
    axis = [0.0, 0.0, 1.0]

    [simulation]
    t_end = 2.0
    integrator = { type = "rk4", dt = 1e-3 }
    q0 = { hinge = 0.5 }

A **Python** model file is executed and must define a module-level ``model`` (a
:class:`mechsys.Model`); an optional ``simulation`` dict has the same keys as the TOML table, and
its ``integrator`` may also be an integrator object: ``ms.RK4(dt=1e-3)``, ``ms.DOPRI5(...)``,
``ms.Radau5(...)``, ``ms.MoreauJean(dt=1e-4, solver=ms.NSGS(...))`` or ``ms.EventDriven(...)``,
checked like a table (``simulation.integrator.dt: must be > 0, ...``). In a table, moreau_jean's
``solver`` is a name or a table (``solver = { type = "nsgs", tol = 1e-8 }``). The file runs with
``__name__ == "__mechsys_model__"``, so an ``if __name__ == "__main__":`` block is skipped, and
with its folder on ``sys.path``, so it can import modules next to it.

:func:`load_model` validates everything when the file is read, so a bad file fails at load time
with the file name and the key path in the message; :func:`simulation_kwargs` turns the defaults
and any command-line overrides into keyword arguments for :func:`mechsys.simulate`.
"""

from __future__ import annotations

import math
import numbers
import runpy
import sys
import tomllib
from dataclasses import fields
from pathlib import Path
from typing import Any

from .errors import MechsysError, ModelError, SettingsError
from .integrators import APGD, DOPRI5, MAX_COUNT, NSGS, RK4, Auto, EventDriven, Lemke, MoreauJean, Newton, Radau5
from .model import Model

#: Keys of the ``[simulation]`` table.
SIMULATION_KEYS: tuple[str, ...] = ("t_end", "t0", "output_dt", "integrator", "q0", "u0", "sensors", "on_singular",
                                     "max_steps", "max_wall")

#: Keys allowed in an integrator table, per integrator type (besides ``type``).
INTEGRATOR_KEYS: dict[str, tuple[str, ...]] = {
    "rk4": ("dt",),
    "dopri5": ("rtol", "atol", "max_step", "first_step"),
    "radau5": ("dt", "rtol", "atol", "newton_tol", "max_step", "first_step"),
    "moreau_jean": ("dt", "solver", "continue_on_painleve", "project", "parallel"),
    "event_driven": ("rtol", "atol", "max_step", "gap_tol", "velocity_tol", "max_events", "continue_on_painleve"),
}

_INTEGRATOR_CLASSES = {"rk4": RK4, "dopri5": DOPRI5, "radau5": Radau5, "moreau_jean": MoreauJean, "event_driven": EventDriven}
_SOLVER_CLASSES = {"nsgs": NSGS, "newton": Newton, "lemke": Lemke, "auto": Auto, "apgd": APGD}
#: What an integrator object in a Python model file may be.
_INTEGRATOR_OBJECTS = "mechsys.RK4, DOPRI5, Radau5, MoreauJean or EventDriven"
#: Parameters of integrators and solvers: integers (with their least value), booleans, and numbers
#: that must be > 0; all other parameters are numbers >= 0.
_INTEGER_KEYS = {"max_events": 1, "max_iter": 1, "facets": 3, "newton_max_unknowns": 0, "newton_max_iter": 1,
                 "nsgs_max_iter": 1, "anderson": 0, "nsgs_anderson": 0, "body_space_above": 0, "stall": 0}
_BOOLEAN_KEYS = ("continue_on_painleve", "project", "parallel")
_POSITIVE_KEYS = ("dt", "rtol", "newton_tol", "tol", "pivot_tol", "relaxation")
#: Keys of a solver table, per solver type (besides ``type``).
SOLVER_KEYS: dict[str, tuple[str, ...]] = {"nsgs": ("tol", "max_iter", "relaxation", "anderson", "stall"),
                                           "newton": ("tol", "max_iter", "regularization", "body_space_above"),
                                           "lemke": ("facets", "pivot_tol"),
                                           "apgd": ("tol", "max_iter"),
                                           "auto": ("tol", "newton_max_unknowns", "newton_max_iter", "nsgs_max_iter",
                                                    "nsgs_anderson")}


def _solver(spec: Any, where: str = "integrator.solver", error: type[MechsysError] = SettingsError):
    """A contact solver from a solver object, a name or a table (``{type = "nsgs", tol = 1e-10}``);
    ``None`` stays ``None``. Bad input raises ``error`` with ``where`` in front of the message."""
    if spec is None:
        return None
    if isinstance(spec, tuple(_SOLVER_CLASSES.values())):
        table = _fields(spec, _SOLVER_CLASSES)  # the fields as given (describe() would convert them first)
    elif isinstance(spec, str):
        table = {"type": spec}
    elif isinstance(spec, dict):
        table = dict(spec)
    else:
        raise error(f"{where}: expected mechsys.NSGS, Newton, APGD, Lemke or Auto, a name (nsgs, newton, apgd, lemke, auto) or a table with type, "
                    f"got {_tname(spec)}")
    kind = table.pop("type", None)
    if not isinstance(kind, str) or kind.lower() not in _SOLVER_CLASSES:
        shown = "missing" if kind is None else repr(kind)
        raise error(f"{where}.type: expected nsgs, newton, apgd, lemke or auto, got {shown}")
    kind = kind.lower()
    args = {key: _parameter(value, key, SOLVER_KEYS[kind], kind, f"{where}.{key}", error) for key, value in table.items()}
    return _SOLVER_CLASSES[kind](**args)


def _parameter(value: Any, key: str, allowed: tuple[str, ...], kind: str, where: str, error: type[MechsysError]) -> Any:
    """One parameter of an integrator or solver table, checked and converted."""
    if key not in allowed:
        raise error(f"{where}: unknown key for {kind}; expected one of type, {', '.join(allowed)}")
    if key == "solver":
        return _solver(value, where, error)
    if key in _BOOLEAN_KEYS:
        if not isinstance(value, bool):
            raise error(f"{where}: expected true or false, got {_tname(value)} {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise error(f"{where}: expected a number, got {_tname(value)} {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise error(f"{where}: must be finite, got {x}")
    if key in _INTEGER_KEYS:
        if x != int(x) or x < _INTEGER_KEYS[key]:
            raise error(f"{where}: expected an integer >= {_INTEGER_KEYS[key]}, got {value!r}")
        if x > MAX_COUNT:
            raise error(f"{where}: expected an integer at most 2**53, got {value!r}")
        return int(x)
    if x < 0 or (x == 0 and key in _POSITIVE_KEYS):
        raise error(f"{where}: must be {'>' if key in _POSITIVE_KEYS else '>='} 0, got {x:g}")
    return x


# top-level keys of the description that must be arrays of tables
_LIST_KEYS = ("bodies", "joints", "forces", "ground_markers", "constraints", "contacts", "contact_groups")


class ModelFileNotFoundError(ModelError, FileNotFoundError):
    """The model file does not exist (both a :class:`ModelError` and a :class:`FileNotFoundError`)."""


def load_model(path: str | Path) -> tuple[Model, dict]:
    """Reads a model file (``.toml`` or ``.py``) and validates it in the engine.

    Returns the :class:`mechsys.Model` and the simulation defaults (the ``[simulation]`` table or
    the Python file's ``simulation`` dict; empty if absent), checked for unknown keys and, for
    ``q0``/``u0``, against the model's joints. Any error is raised with the file name prepended,
    keeping its class (``ModelError``, ``SettingsError``, ...); the engine's key paths
    (``bodies[0].mas: unknown field ...``) are kept in the message.

    >>> model, sim = load_model("pendulum.toml")  # doctest: +SKIP
    >>> res = mechsys.simulate(model, **simulation_kwargs(sim))  # doctest: +SKIP
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".toml", ".py"):
        shown = f"'{path.suffix}'" if path.suffix else "no extension"
        raise ModelError(f"{path}: unsupported model file type ({shown}); expected a .toml or .py file")
    if not path.exists():
        raise ModelFileNotFoundError(f"{path}: no such model file")
    if path.is_dir():
        raise ModelError(f"{path}: is a directory, not a model file")
    try:
        if suffix == ".toml":
            model, sim = _load_toml(path)
        else:
            model, sim = _load_python(path)
        model.build()
        sim = _check_simulation(sim, model, allow_objects=suffix == ".py")
    except MechsysError as e:
        raise _with_path(e, path) from None
    return model, sim


def _with_path(e: MechsysError, path: Path) -> MechsysError:
    """The same exception class with the file name in front of the message."""
    msg = str(e)
    prefix = f"{path}: "
    if msg.startswith(prefix):
        return e
    try:
        return type(e)(prefix + msg)
    except Exception:  # noqa: BLE001 - an exotic subclass signature: fall back to ModelError
        return ModelError(prefix + msg)


def _load_toml(path: Path) -> tuple[Model, Any]:
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except tomllib.TOMLDecodeError as e:
        # the message ends with "(at line L, column C)"
        raise ModelError(f"invalid TOML: {e}") from None
    except UnicodeDecodeError as e:
        raise ModelError(f"not a UTF-8 text file ({e.reason} at byte {e.start})") from None
    sim = data.pop("simulation", {})
    if not isinstance(sim, dict):
        raise ModelError(f"simulation: expected a table, got {_tname(sim)}")
    for key in _LIST_KEYS:
        if key in data and not isinstance(data[key], list):
            raise ModelError(f"{key}: expected an array of tables ([[{key}]]), got {_tname(data[key])}")
    constraints = data.get("constraints", [])
    for i, c in enumerate(constraints if isinstance(constraints, list) else []):
        if isinstance(c, dict) and c.get("type") == "velocity":
            # its W, w, Wdot are Python callables, which a TOML file cannot hold
            raise ModelError(
                f"constraints[{i}] '{c.get('name', '?')}': a velocity constraint needs Python callables (W, w, Wdot); "
                "define it with mechsys.constraints.Velocity in a .py model file"
            )
    where = _callback_in(data)
    if where is not None:
        # a callback id refers to a Python callable, which a TOML file cannot hold: say so at
        # load instead of at the run ("the model refers to 1 callbacks, 0 given")
        raise ModelError(f"{where}: a callback needs a Python callable, which a TOML file cannot hold; "
                         "use a function given by values (constant, ramp, harmonic, table) or a .py model file")
    _resolve_meshes(data, path.parent)
    _resolve_elastic(data, path.parent)
    return Model.from_dict(data), sim


def _resolve_elastic(data: dict, folder: Path) -> None:
    """Elastic bodies given by a reduced-body file (``elastic = { file = "blade.npz", ... }``,
    relative to the model file; the layout of :func:`mechsys.elastic.save_reduced`) in place: the
    engine's invariants, and the body's mass, centre of mass and inertia from the file unless
    given. Options: ``rayleigh = [alpha, beta]`` or ``modal = zeta``, ``stiffening`` (default
    true), ``q0``, ``u0``. Errors name the body's key path and the file."""
    bodies = data.get("bodies", [])
    for i, b in enumerate(bodies if isinstance(bodies, list) else []):
        if not isinstance(b, dict) or not isinstance(b.get("elastic"), dict) or "file" not in b["elastic"]:
            continue
        where = f"bodies[{i}] '{b.get('name', '?')}'.elastic"
        spec = dict(b["elastic"])
        extra = set(spec) - {"file", "rayleigh", "modal", "stiffening", "q0", "u0"}
        if extra:
            raise ModelError(f"{where}: unknown key(s) {', '.join(sorted(extra))} with a file (expected file, rayleigh, "
                             "modal, stiffening, q0, u0)")
        file = spec.pop("file")
        if not isinstance(file, str):
            raise ModelError(f"{where}.file: expected a file name, got {_tname(file)}")
        from .elastic import load_reduced

        try:
            reduced = load_reduced(folder / file, name=b.get("name"))
        except ModelError as e:
            raise ModelError(f"{where}.file: {e}") from None
        scratch = Model("scratch")
        stiff = spec.get("stiffening", True)
        if not isinstance(stiff, bool):
            raise ModelError(f"{where}.stiffening: expected true or false, got {stiff!r}")
        try:
            handle = scratch.add_elastic_body(str(b.get("name", "body")), reduced, rayleigh=spec.get("rayleigh"),
                                              modal=spec.get("modal"), stiffening=stiff, q0=spec.get("q0"),
                                              u0=spec.get("u0"))
        except ModelError as e:
            raise ModelError(f"{where}: {e}") from None
        made = scratch._bodies[-1]
        b["elastic"] = made["elastic"]
        for key in ("mass", "inertia", "com"):
            b.setdefault(key, made[key])
        del handle


def _resolve_meshes(data: dict, folder: Path) -> None:
    """Mesh contours (``type = "mesh"``) in place: a ``file`` (relative to the model file) read
    through trimesh, ``scale`` and ``flip`` applied, leaving the ``vertices`` and ``triangles``
    the engine reads. Errors name the contour's key path and the file."""
    from .contours import _mesh_arrays, _read_mesh_file

    def fix(table, where: str) -> None:
        if not isinstance(table, dict) or table.get("type") != "mesh":
            return
        extra = set(table) - {"type", "file", "vertices", "triangles", "scale", "flip"}
        if extra:
            raise ModelError(f"{where}: unknown key(s) {', '.join(sorted(extra))} for a mesh "
                             "(expected file or vertices and triangles, scale, flip)")
        file = table.pop("file", None)
        if file is not None:
            if not isinstance(file, str):
                raise ModelError(f"{where}.file: expected a file name, got {_tname(file)}")
            if "vertices" in table or "triangles" in table:
                raise ModelError(f"{where}: give a mesh file or vertices and triangles, not both")
            v, t = _read_mesh_file(folder / file, f"{where}.file")
        else:
            if "vertices" not in table or "triangles" not in table:
                raise ModelError(f"{where}: a mesh needs a file or both vertices and triangles")
            v, t = table.pop("vertices"), table.pop("triangles")
        v, t = _mesh_arrays(v, t, table.pop("scale", 1.0), table.pop("flip", False), where)
        table["vertices"], table["triangles"] = v.tolist(), t.tolist()

    def label(item, key: str, i: int) -> str:
        name = item.get("name") if isinstance(item, dict) else None
        return f"{key}[{i}]" + (f" '{name}'" if isinstance(name, str) else "")

    for i, c in enumerate(data.get("contacts", []) if isinstance(data.get("contacts"), list) else []):
        if isinstance(c, dict):
            for k in ("contour1", "contour2"):
                fix(c.get(k), f"{label(c, 'contacts', i)}.{k}")
    visuals = data.get("visuals", [])
    for i, v in enumerate(visuals if isinstance(visuals, list) else []):
        if isinstance(v, dict):
            fix(v.get("shape"), f"{label(v, 'visuals', i)}.shape")
    groups = data.get("contact_groups", [])
    for i, g in enumerate(groups if isinstance(groups, list) else []):
        if isinstance(g, dict):
            for key in ("members", "against"):
                items = g.get(key, [])
                for k, m in enumerate(items if isinstance(items, list) else []):
                    if isinstance(m, dict):
                        fix(m.get("contour"), f"{label(g, 'contact_groups', i)}.{key}[{k}].contour")


def _callback_in(node, path: str = "") -> str | None:
    """Where a model description refers to a Python callback ({type = "callback"}), as
    ``forces[0] 'drive'.value``, or None."""
    if isinstance(node, dict):
        if node.get("type") == "callback":
            return path or "model"
        for k, v in node.items():
            if isinstance(v, (dict, list)):
                found = _callback_in(v, f"{path}.{k}" if path else k)
                if found:
                    return found
    elif isinstance(node, list):
        for i, v in enumerate(node):
            name = v.get("name") if isinstance(v, dict) else None
            found = _callback_in(v, f"{path}[{i}]" + (f" '{name}'" if isinstance(name, str) else ""))
            if found:
                return found
    return None


def _load_python(path: Path) -> tuple[Model, Any]:
    # like `python model.py`: modules next to the model file can be imported
    folder = str(path.resolve().parent)
    sys.path.insert(0, folder)
    try:
        namespace = runpy.run_path(str(path), run_name="__mechsys_model__")
    except SyntaxError as e:
        raise ModelError(f"line {e.lineno}: syntax error: {e.msg}" + (f": {e.text.strip()}" if e.text else "")) from None
    except MechsysError:
        raise
    except Exception as e:  # noqa: BLE001 - the model file's own errors, reported briefly
        import traceback

        frames = [f for f in traceback.extract_tb(e.__traceback__) if Path(f.filename).resolve() == path.resolve()]
        where = f"line {frames[-1].lineno}: " if frames else ""
        raise ModelError(f"{where}running the model file raised {type(e).__name__}: {e}") from None
    finally:
        try:
            sys.path.remove(folder)
        except ValueError:
            pass
    if "model" not in namespace:
        raise ModelError("defines no module-level 'model' (a mechsys.Model)")
    model = namespace["model"]
    if not isinstance(model, Model):
        raise ModelError(f"'model' must be a mechsys.Model, got {_tname(model)}")
    sim = namespace.get("simulation", {})
    if sim is None:
        sim = {}
    if not isinstance(sim, dict):
        raise ModelError(f"simulation: expected a dict, got {_tname(sim)}")
    return model, sim


def _tname(v: Any) -> str:
    names = {dict: "a table", list: "an array", str: "a string", bool: "a boolean", int: "an integer", float: "a number"}
    return names.get(type(v), type(v).__name__)


def _number(v: Any, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise ModelError(f"{where}: expected a number, got {_tname(v)} {v!r}")
    x = float(v)
    if not math.isfinite(x):
        raise ModelError(f"{where}: must be finite, got {x}")
    return x


def _check_integrator(spec: Any, allow_objects: bool) -> Any:
    """Checks ``simulation.integrator``: a name, a table or (Python files) an integrator object.

    A table comes back normalised (numbers as floats, a solver as a table); an object comes back
    as an equal object whose parameters passed the same checks as a table's."""
    where = "simulation.integrator"
    if allow_objects and isinstance(spec, tuple(_INTEGRATOR_CLASSES.values())):
        solver = getattr(spec, "solver", None)
        if isinstance(spec, MoreauJean) and not isinstance(solver, tuple(_SOLVER_CLASSES.values())):
            raise ModelError(f"{where}.solver: expected mechsys.NSGS, Newton, APGD, Lemke or Auto, got {_tname(solver)} {solver!r}")
        # the fields as given (describe() would convert them and hide, e.g., a string dt); None
        # is "not given" (Radau5's dt or rtol)
        given = {k: v for k, v in _fields(spec, _INTEGRATOR_CLASSES).items() if v is not None}
        table = _check_integrator_table(given, where)
        table.pop("type")
        if "solver" in table:
            table["solver"] = _solver(table["solver"], f"{where}.solver", ModelError)
        return type(spec)(**table)
    if allow_objects and isinstance(spec, tuple(_SOLVER_CLASSES.values())):
        raise ModelError(f"{where}: expected {_INTEGRATOR_OBJECTS}, got {type(spec).__name__} (a contact solver: "
                         f"give it to the integrator, e.g. ms.MoreauJean(dt=1e-3, solver=ms.{type(spec).__name__}()))")
    if isinstance(spec, str):
        spec = {"type": spec}
    if not isinstance(spec, dict):
        wanted = f"{_INTEGRATOR_OBJECTS}, a name or a dict like {{'type': 'rk4', 'dt': 1e-3}}" if allow_objects \
            else 'a table like { type = "rk4", dt = 1e-3 }'
        got = _tname(spec) if type(spec) in (list, str, bool, int, float) else type(spec).__name__
        raise ModelError(f"{where}: expected {wanted}, got {got}")
    return _check_integrator_table(spec, where)


def _check_integrator_table(spec: dict, where: str) -> dict:
    if "type" not in spec:
        raise ModelError(f"{where}.type: missing; expected one of {', '.join(INTEGRATOR_KEYS)}")
    kind = spec["type"]
    if not isinstance(kind, str) or kind.lower() not in INTEGRATOR_KEYS:
        raise ModelError(f"{where}.type: unknown integrator {kind!r}; expected one of {', '.join(INTEGRATOR_KEYS)}")
    kind = kind.lower()
    allowed = INTEGRATOR_KEYS[kind]
    out: dict[str, Any] = {"type": kind}
    for key, value in spec.items():
        if key == "type":
            continue
        x = _parameter(value, key, allowed, kind, f"{where}.{key}", ModelError)
        out[key] = x.describe() if key == "solver" else x
    if kind == "radau5" and "dt" in out and "rtol" in out:
        raise ModelError(f"{where}: give radau5 a step dt (fixed) or a tolerance rtol (adaptive), not both")
    return out


def _check_state(values: Any, key: str, model: Model) -> Any:
    where = f"simulation.{key}"
    joints = {j["name"]: j for j in model.joint_info()}
    count = "nq" if key == "q0" else "nu"
    if isinstance(values, dict):
        out: dict[str, Any] = {}
        for name, v in values.items():
            if name not in joints:
                raise ModelError(f"{where}.{name}: unknown joint; joints are {', '.join(joints) or '(none)'}")
            items = list(v) if isinstance(v, (list, tuple)) else [v]
            nums = [_number(x, f"{where}.{name}" + (f"[{i}]" if len(items) > 1 else "")) for i, x in enumerate(items)]
            n = joints[name][count]
            if len(nums) != n:
                what = "coordinates" if key == "q0" else "velocities"
                raise ModelError(f"{where}.{name}: a {joints[name]['type']} joint has {n} {what}, got {len(nums)}")
            out[name] = nums[0] if n == 1 and not isinstance(v, (list, tuple)) else nums
        return out
    # a full vector (allowed too, as for mechsys.simulate)
    try:
        items = list(values)
    except TypeError:
        raise ModelError(f"{where}: expected a table joint name -> value(s), got {_tname(values)}") from None
    nums = [_number(x, f"{where}[{i}]") for i, x in enumerate(items)]
    n = model.nq if key == "q0" else model.nu
    if len(nums) != n:
        raise ModelError(f"{where}: the model has {n} {'coordinates' if key == 'q0' else 'velocities'}, got {len(nums)}")
    return nums


def _check_simulation(sim: dict, model: Model, allow_objects: bool) -> dict:
    """Checks a simulation table/dict; returns a normalised copy (numbers as floats)."""
    out: dict[str, Any] = {}
    for key, value in sim.items():
        if key not in SIMULATION_KEYS:
            raise ModelError(f"simulation.{key}: unknown key; expected one of {', '.join(SIMULATION_KEYS)}")
        if value is None:
            continue
        if key in ("t_end", "t0", "output_dt"):
            x = _number(value, f"simulation.{key}")
            if key == "output_dt" and x <= 0:
                raise ModelError(f"simulation.output_dt: must be > 0, got {x:g}")
            out[key] = x
        elif key == "integrator":
            out[key] = _check_integrator(value, allow_objects)
        elif key in ("on_singular", "max_steps", "max_wall"):
            out[key] = value  # checked by simulate, naming the key
        elif key == "sensors":
            items = [value] if isinstance(value, str) else value
            if not isinstance(items, (list, tuple)) or not all(isinstance(x, str) for x in items):
                raise ModelError(f"simulation.sensors: expected a list of signal names or patterns, got {value!r}")
            out[key] = list(items)
        else:
            out[key] = _check_state(value, key, model)
    if "t_end" in out and out["t_end"] <= out.get("t0", 0.0):
        raise ModelError(f"simulation.t_end: must be > t0 = {out.get('t0', 0.0):g}, got {out['t_end']:g}")
    return out


def _fields(obj: Any, classes: dict[str, type]) -> dict | None:
    """An integrator or solver object as a table of its fields as given (``None`` if it is neither)."""
    kind = next((k for k, c in classes.items() if isinstance(obj, c)), None)
    if kind is None:
        return None
    return {"type": kind, **{f.name: getattr(obj, f.name) for f in fields(obj)}}


def _integrator_dict(spec: Any) -> dict | None:
    if spec is None:
        return None
    if isinstance(spec, dict):
        return dict(spec)
    if isinstance(spec, str):
        return {"type": spec.lower()}
    table = _fields(spec, _INTEGRATOR_CLASSES)
    if table is not None:
        return table
    raise SettingsError(f"integrator: expected a name ({', '.join(INTEGRATOR_KEYS)}), a table or {_INTEGRATOR_OBJECTS}, "
                        f"got {_tname(spec) if type(spec) in (list, bool, int, float) else type(spec).__name__}")


def simulation_kwargs(defaults: dict | None = None, **overrides: Any) -> dict:
    """Keyword arguments for :func:`mechsys.simulate` from simulation defaults plus overrides.

    ``defaults`` is the dict returned by :func:`load_model`. ``overrides`` (None values are
    ignored) may be ``t_end``, ``t0``, ``output_dt``, ``q0``, ``u0``, ``integrator`` (a name
    ``"rk4"``/``"dopri5"``/``"radau5"``/``"moreau_jean"``/``"event_driven"``, a table or an
    integrator object), the integrator parameters ``dt``, ``rtol``, ``atol`` and ``solver``
    (moreau_jean's contact solver: a name, a table or a solver object; naming the file's own
    solver keeps its settings). Changing the integrator type keeps the parameters that still
    apply (a file's ``dt`` carries over from rk4 to radau5; for radau5 a ``dt`` or ``rtol`` override
    replaces the file's other, choosing fixed or adaptive steps). Without any integrator the engine's
    default (DOPRI5) is used, or RK4 when only ``dt`` is given. Every parameter is checked, with
    the option or key in the message (``--dt: must be > 0, got -1``).

    Raises :class:`mechsys.SettingsError` when ``t_end`` is missing, a fixed-step scheme has no
    step, or a parameter does not apply to the chosen scheme.

    >>> simulation_kwargs({"t_end": 1.0, "integrator": {"type": "rk4", "dt": 1e-3}}, t_end=2.0)
    {'t_end': 2.0, 'integrator': RK4(dt=0.001)}
    """
    defaults = dict(defaults or {})
    over = {k: v for k, v in overrides.items() if v is not None}
    known = set(SIMULATION_KEYS) | {"dt", "rtol", "atol", "solver"}
    unknown = sorted(set(over) - known)
    if unknown:
        raise SettingsError(f"simulation_kwargs: unknown override {', '.join(unknown)}; expected one of {', '.join(sorted(known))}")
    unknown = sorted(set(defaults) - set(SIMULATION_KEYS))
    if unknown:
        raise SettingsError(f"simulation.{unknown[0]}: unknown key; expected one of {', '.join(SIMULATION_KEYS)}")

    kwargs: dict[str, Any] = {}
    for key in ("t_end", "t0", "output_dt", "q0", "u0", "sensors", "on_singular", "max_steps", "max_wall"):
        value = over.get(key, defaults.get(key))
        if value is not None:
            kwargs[key] = value
    if "t_end" not in kwargs:
        raise SettingsError("t_end: not given; set simulation.t_end in the model file or pass --t-end")
    for key in ("t_end", "t0", "output_dt"):
        if key in kwargs:
            try:
                kwargs[key] = float(kwargs[key])
            except (TypeError, ValueError):
                raise SettingsError(f"{key}: expected a number, got {kwargs[key]!r}") from None
            if not math.isfinite(kwargs[key]):
                raise SettingsError(f"{key}: must be finite, got {kwargs[key]}")
    if "output_dt" in kwargs and kwargs["output_dt"] <= 0:
        raise SettingsError(f"output_dt: must be > 0, got {kwargs['output_dt']:g}")

    base = _integrator_dict(defaults.get("integrator"))
    chosen = _integrator_dict(over.get("integrator"))
    params = {k: over[k] for k in ("dt", "rtol", "atol") if k in over}
    if chosen is None and base is None and not params and "solver" not in over:
        return kwargs  # the engine's default integrator
    if chosen is None:
        spec = base if base is not None else {"type": "rk4" if "dt" in params else "dopri5"}
    elif base is not None and base.get("type") == chosen.get("type"):
        spec = {**base, **chosen}
    else:
        spec = dict(chosen)
        if base is not None:
            allowed = INTEGRATOR_KEYS.get(str(spec.get("type")), ())
            # (not the Painleve choice: its default differs between the two contact schemes)
            spec = {**{k: v for k, v in base.items() if k in allowed and k != "continue_on_painleve"}, **spec}
    kind = str(spec.get("type", "")).lower()
    if kind not in INTEGRATOR_KEYS:
        raise SettingsError(f"integrator: unknown type {spec.get('type')!r}; expected one of {', '.join(INTEGRATOR_KEYS)}")
    allowed = INTEGRATOR_KEYS[kind]
    for key, value in params.items():
        if key not in allowed:
            hint = " (it is adaptive: use --rtol/--atol)" if kind in ("dopri5", "event_driven") else " (it has a fixed step: use --dt)"
            raise SettingsError(f"--{key} does not apply to integrator {kind}{hint}")
        spec[key] = value
    if kind == "radau5":
        # a step or a tolerance: the one given on the command line replaces the file's other
        if "rtol" in params and "dt" not in params:
            spec.pop("dt", None)
        if "dt" in params and "rtol" not in params:
            spec.pop("rtol", None)
        if spec.get("dt") is None and spec.get("rtol") is None:
            raise SettingsError("integrator radau5 needs a step or a tolerance: set simulation.integrator.dt or rtol, "
                                "or pass --dt (fixed steps) or --rtol (adaptive)")
        if spec.get("rtol") is None and "atol" in params:
            raise SettingsError("--atol does not apply to integrator radau5 with a fixed step (give --rtol for adaptive steps)")
    elif "dt" in allowed and spec.get("dt") is None:
        raise SettingsError(f"integrator {kind} needs a step: set simulation.integrator.dt or pass --dt")
    solver = over.get("solver")
    if solver is not None:
        if "solver" not in allowed:
            raise SettingsError(f"--solver does not apply to integrator {kind} (only moreau_jean has a contact solver)")
        previous = spec.get("solver")
        previous = _fields(previous, _SOLVER_CLASSES) or previous
        same = isinstance(solver, str) and isinstance(previous, dict) and str(previous.get("type", "")).lower() == solver.lower()
        if not same:  # naming the file's own solver again keeps its settings
            spec["solver"] = solver
    args = {}
    for key, value in spec.items():
        if key in allowed and value is not None:
            where = f"--{key}" if key in params or (key == "solver" and solver is not None) else f"integrator.{key}"
            args[key] = _parameter(value, key, allowed, kind, where, SettingsError)
    try:
        kwargs["integrator"] = _INTEGRATOR_CLASSES[kind](**args)
    except SettingsError:
        raise  # already names the setting (radau5's dt and rtol both given)
    except (TypeError, ValueError) as e:
        raise SettingsError(f"integrator {kind}: {e}") from None
    return kwargs


__all__ = ["load_model", "simulation_kwargs", "ModelFileNotFoundError", "SIMULATION_KEYS", "INTEGRATOR_KEYS"]
