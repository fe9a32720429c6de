"""Model files (TOML and Python): loading, validation messages with key paths, simulation defaults."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import ModelError, SettingsError
from mechsys.modelfile import load_model, simulation_kwargs

PENDULUM_TOML = """\
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
t_end = 1.0
integrator = { type = "rk4", dt = 1e-3 }
q0 = { hinge = 0.5 }
"""

PENDULUM_PY = """\
import mechsys as ms

model = ms.Model("pendulum", gravity=(0.0, -9.81, 0.0))
rod = model.add_body("rod", mass=1.0, inertia=[1e-4, 0.0833, 0.0833], com=(0.5, 0.0, 0.0))
model.add_joint(ms.joints.Revolute("hinge", parent=model.ground, child=rod, axis=(0.0, 0.0, 1.0)))
simulation = {"t_end": 1.0, "integrator": ms.RK4(dt=1e-3), "q0": {"hinge": 0.5}}

if __name__ == "__main__":
    raise RuntimeError("the __main__ block of a model file must not run when it is loaded")
"""


def write(tmp_path: Path, text: str, name: str = "pendulum.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def python_pendulum() -> ms.Model:
    m = ms.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", mass=1.0, inertia=[1e-4, 0.0833, 0.0833], com=(0.5, 0.0, 0.0))
    m.add_joint(ms.joints.Revolute("hinge", parent=m.ground, child=rod, axis=(0.0, 0.0, 1.0)))
    return m


# ---- TOML ----------------------------------------------------------------------------------------


def test_toml_loads_model_and_defaults(tmp_path):
    model, sim = load_model(write(tmp_path, PENDULUM_TOML))
    assert isinstance(model, ms.Model)
    assert model.name == "pendulum"
    assert (model.nq, model.nu) == (1, 1)
    assert [j["name"] for j in model.joint_info()] == ["hinge"]
    assert model.gravity == [0.0, -9.81, 0.0]
    assert sim == {"t_end": 1.0, "integrator": {"type": "rk4", "dt": 1e-3}, "q0": {"hinge": 0.5}}


def test_toml_without_simulation_table(tmp_path):
    text = PENDULUM_TOML.split("[simulation]")[0]
    model, sim = load_model(write(tmp_path, text))
    assert sim == {}
    assert model.nu == 1


def test_toml_and_python_model_give_identical_results(tmp_path):
    model, sim = load_model(write(tmp_path, PENDULUM_TOML))
    res_file = ms.simulate(model, **simulation_kwargs(sim))
    res_py = ms.simulate(python_pendulum(), t_end=1.0, integrator=ms.RK4(dt=1e-3), q0={"hinge": 0.5})
    assert res_file.names() == res_py.names()
    for name in res_py.names():
        np.testing.assert_allclose(res_file[name], res_py[name], rtol=0, atol=1e-12, err_msg=name)
        assert res_file.unit(name) == res_py.unit(name)
    # and the physics is right: a conservative pendulum keeps its energy, starting from
    # E = m g y_com = 1 * 9.81 * 0.5 sin(0.5) (kinetic energy zero)
    e = res_file["energy/total"]
    assert e[0] == pytest.approx(9.81 * 0.5 * math.sin(0.5), rel=1e-9)
    assert np.max(np.abs(e - e[0])) < 1e-8


def test_misspelt_key_names_path_and_key(tmp_path):
    p = write(tmp_path, PENDULUM_TOML.replace("mass = 1.0", "mas = 1.0"))
    with pytest.raises(ModelError) as e:
        load_model(p)
    msg = str(e.value)
    assert msg.startswith(f"{p}: ")
    assert "bodies[0].mas" in msg
    assert "unknown field" in msg


def test_misspelt_top_level_key(tmp_path):
    p = write(tmp_path, 'nmae = "x"\n' + PENDULUM_TOML)
    with pytest.raises(ModelError, match=r"nmae: unknown field"):
        load_model(p)


def test_negative_mass_names_body(tmp_path):
    p = write(tmp_path, PENDULUM_TOML.replace("mass = 1.0", "mass = -1.0"))
    with pytest.raises(ModelError) as e:
        load_model(p)
    msg = str(e.value)
    assert str(p) in msg and "'rod'" in msg and "mass" in msg and "-1" in msg


def test_unknown_simulation_key(tmp_path):
    p = write(tmp_path, PENDULUM_TOML.replace("t_end = 1.0", "t_ned = 1.0"))
    with pytest.raises(ModelError) as e:
        load_model(p)
    assert str(e.value) == (
        f"{p}: simulation.t_ned: unknown key; expected one of t_end, t0, output_dt, integrator, q0, u0, sensors, on_singular, max_steps, max_wall"
    )


@pytest.mark.parametrize(
    "old, new, expected",
    [
        ('type = "rk4"', 'type = "euler"', r"simulation\.integrator\.type: unknown integrator 'euler'"),
        ("dt = 1e-3", "dt = 1e-3, rtol = 1e-6", r"simulation\.integrator\.rtol: unknown key for rk4"),
        ("dt = 1e-3", "dt = -1e-3", r"simulation\.integrator\.dt: must be > 0"),
        ("hinge = 0.5", "hing = 0.5", r"simulation\.q0\.hing: unknown joint; joints are hinge"),
        ("hinge = 0.5", "hinge = [0.5, 1.0]", r"simulation\.q0\.hinge: a revolute joint has 1 coordinates, got 2"),
        ("hinge = 0.5", 'hinge = "up"', r"simulation\.q0\.hinge: expected a number, got a string"),
        ("t_end = 1.0", 't_end = "long"', r"simulation\.t_end: expected a number"),
        ("t_end = 1.0", "t_end = 1.0\nt0 = 2.0", r"simulation\.t_end: must be > t0"),
    ],
)
def test_bad_simulation_values(tmp_path, old, new, expected):
    p = write(tmp_path, PENDULUM_TOML.replace(old, new))
    with pytest.raises(ModelError, match=expected):
        load_model(p)


def test_bodies_as_table_instead_of_array(tmp_path):
    p = write(tmp_path, PENDULUM_TOML.replace("[[bodies]]", "[bodies]"))
    with pytest.raises(ModelError, match=r"bodies: expected an array of tables \(\[\[bodies\]\]\)"):
        load_model(p)


def test_toml_syntax_error_has_file_and_line(tmp_path):
    p = write(tmp_path, PENDULUM_TOML.replace('name = "rod"', "name = rod"))
    with pytest.raises(ModelError) as e:
        load_model(p)
    msg = str(e.value)
    assert msg.startswith(f"{p}: invalid TOML")
    assert "line 5" in msg


def test_missing_file(tmp_path):
    p = tmp_path / "nothere.toml"
    with pytest.raises(ModelError, match="no such model file") as e:
        load_model(p)
    assert str(p) in str(e.value)
    assert isinstance(e.value, FileNotFoundError)


def test_unsupported_extension(tmp_path):
    p = write(tmp_path, "{}", "model.json")
    with pytest.raises(ModelError, match=r"unsupported model file type \('\.json'\)"):
        load_model(p)


# ---- Python model files --------------------------------------------------------------------------


def test_python_model_file(tmp_path):
    model, sim = load_model(write(tmp_path, PENDULUM_PY, "pendulum.py"))
    assert model.name == "pendulum" and model.nu == 1
    assert sim["integrator"] == ms.RK4(dt=1e-3)
    kwargs = simulation_kwargs(sim)
    assert kwargs["integrator"] == ms.RK4(dt=1e-3)
    res = ms.simulate(model, **kwargs)
    ref = ms.simulate(python_pendulum(), t_end=1.0, integrator=ms.RK4(dt=1e-3), q0={"hinge": 0.5})
    np.testing.assert_array_equal(res["joint/hinge/q"], ref["joint/hinge/q"])


def test_python_file_imports_sibling_module(tmp_path):
    (tmp_path / "pend_params.py").write_text("MASS = 2.5\n")
    text = "from pend_params import MASS\n" + PENDULUM_PY.replace("mass=1.0", "mass=MASS")
    model, _ = load_model(write(tmp_path, text, "withparams.py"))
    assert model.body_info()[0]["mass"] == 2.5


def test_python_file_without_model(tmp_path):
    p = write(tmp_path, "import mechsys as ms\nm = ms.Model('x')\n", "nomodel.py")
    with pytest.raises(ModelError, match=r"nomodel\.py: defines no module-level 'model'"):
        load_model(p)


def test_python_file_with_wrong_model_type(tmp_path):
    p = write(tmp_path, "model = 3\n", "wrong.py")
    with pytest.raises(ModelError, match=r"'model' must be a mechsys.Model, got an integer"):
        load_model(p)


def test_python_file_invalid_model_reports_file(tmp_path):
    text = PENDULUM_PY.replace("mass=1.0", "mass=-2.0")
    p = write(tmp_path, text, "neg.py")
    with pytest.raises(ModelError, match=r"neg\.py: bodies\[0\] 'rod'\.mass: must be > 0"):
        load_model(p)


def test_python_file_bad_simulation_key(tmp_path):
    p = write(tmp_path, PENDULUM_PY.replace('"t_end"', '"tend"'), "sim.py")
    with pytest.raises(ModelError, match=r"sim\.py: simulation\.tend: unknown key"):
        load_model(p)


# ---- simulation_kwargs ---------------------------------------------------------------------------


def test_simulation_kwargs_builds_integrators():
    kw = simulation_kwargs({"t_end": 2, "integrator": {"type": "dopri5", "rtol": 1e-6, "atol": 1e-9}})
    assert kw == {"t_end": 2.0, "integrator": ms.DOPRI5(rtol=1e-6, atol=1e-9)}
    kw = simulation_kwargs({"t_end": 1, "integrator": {"type": "radau5", "dt": 1e-2}, "q0": {"hinge": 0.1}})
    assert kw["integrator"] == ms.Radau5(dt=1e-2)
    assert kw["q0"] == {"hinge": 0.1}


def test_simulation_kwargs_overrides():
    defaults = {"t_end": 1.0, "output_dt": 0.01, "integrator": {"type": "rk4", "dt": 1e-3}}
    kw = simulation_kwargs(defaults, t_end=3.0, dt=2e-3, output_dt=None)
    assert kw == {"t_end": 3.0, "output_dt": 0.01, "integrator": ms.RK4(dt=2e-3)}
    # switching scheme keeps the parameters that still apply
    assert simulation_kwargs(defaults, integrator="radau5")["integrator"] == ms.Radau5(dt=1e-3)
    assert simulation_kwargs(defaults, integrator="dopri5", rtol=1e-5)["integrator"] == ms.DOPRI5(rtol=1e-5)
    # an integrator object as a default (Python model files)
    kw = simulation_kwargs({"t_end": 1.0, "integrator": ms.DOPRI5(rtol=1e-7)}, atol=1e-12)
    assert kw["integrator"] == ms.DOPRI5(rtol=1e-7, atol=1e-12)


def test_simulation_kwargs_defaults_and_errors():
    assert simulation_kwargs({"t_end": 1.0}) == {"t_end": 1.0}  # engine default integrator
    assert simulation_kwargs({}, t_end=1.0, dt=1e-3)["integrator"] == ms.RK4(dt=1e-3)
    with pytest.raises(SettingsError, match="t_end: not given"):
        simulation_kwargs({})
    with pytest.raises(SettingsError, match="integrator rk4 needs a step"):
        simulation_kwargs({"t_end": 1.0}, integrator="rk4")
    with pytest.raises(SettingsError, match="--dt does not apply to integrator dopri5"):
        simulation_kwargs({"t_end": 1.0}, integrator="dopri5", dt=1e-3)
    with pytest.raises(SettingsError, match="--rtol does not apply to integrator rk4"):
        simulation_kwargs({"t_end": 1.0}, dt=1e-3, rtol=1e-3)
    with pytest.raises(SettingsError, match="output_dt: must be > 0, got 0"):
        simulation_kwargs({"t_end": 1.0}, output_dt=0.0)
    with pytest.raises(SettingsError, match="t_end: must be finite"):
        simulation_kwargs({"t_end": float("nan")})
    with pytest.raises(SettingsError, match="unknown override"):
        simulation_kwargs({"t_end": 1.0}, t_final=2.0)


# ---- integrator objects and tables for contact models ---------------------------------------------


@pytest.mark.parametrize(
    "source, integrator",
    [
        ("ms.MoreauJean(dt=1e-3)", ms.MoreauJean(dt=1e-3)),
        ("ms.MoreauJean(1e-3, solver=ms.Lemke(facets=4))", ms.MoreauJean(1e-3, solver=ms.Lemke(facets=4))),
        ("ms.MoreauJean(1e-3, ms.Newton(tol=1e-9, max_iter=50))", ms.MoreauJean(1e-3, solver=ms.Newton(tol=1e-9, max_iter=50))),
        ("ms.EventDriven(rtol=1e-8, atol=1e-10, max_events=10, continue_on_painleve=True)",
         ms.EventDriven(rtol=1e-8, atol=1e-10, max_events=10, continue_on_painleve=True)),
        ("ms.Radau5(dt=1e-3)", ms.Radau5(dt=1e-3)),
        ("ms.DOPRI5(rtol=1e-6)", ms.DOPRI5(rtol=1e-6)),
        ("{'type': 'moreau_jean', 'dt': 1e-3, 'solver': ms.Newton()}", ms.MoreauJean(1e-3, solver=ms.Newton())),
    ],
    ids=lambda x: x if isinstance(x, str) else "",
)
def test_python_file_accepts_every_integrator_object(tmp_path, source, integrator):
    _, sim = load_model(write(tmp_path, PENDULUM_PY.replace("ms.RK4(dt=1e-3)", source), "objects.py"))
    assert simulation_kwargs(sim)["integrator"] == integrator


@pytest.mark.parametrize(
    "value, expected",
    [
        ("ms.MoreauJean(dt=-1e-3)", r"simulation\.integrator\.dt: must be > 0, got -0\.001"),
        ("ms.MoreauJean(dt='small')", r"simulation\.integrator\.dt: expected a number, got a string 'small'"),
        ("ms.MoreauJean(1e-3, solver=3)", r"simulation\.integrator\.solver: expected mechsys\.NSGS, Newton, APGD, Lemke or Auto"),
        ("ms.MoreauJean(1e-3, solver=ms.NSGS(tol=0.0))", r"simulation\.integrator\.solver\.tol: must be > 0"),
        ("ms.MoreauJean(1e-3, solver=ms.Lemke(facets=2))", r"simulation\.integrator\.solver\.facets: expected an integer >= 3"),
        ("ms.EventDriven(max_events=0)", r"simulation\.integrator\.max_events: expected an integer >= 1, got 0"),
        ("ms.EventDriven(continue_on_painleve='yes')", r"simulation\.integrator\.continue_on_painleve: expected true or false"),
        ("ms.EventDriven(rtol=float('nan'))", r"simulation\.integrator\.rtol: must be finite"),
        ("ms.NSGS()", r"simulation\.integrator: expected mechsys\.RK4, DOPRI5, Radau5, MoreauJean or EventDriven, got NSGS"),
        ("3", r"simulation\.integrator: expected mechsys\.RK4, .* got an integer"),
        ("{'type': 'moreau_jean', 'dt': 1e-3, 'solver': {'type': 'nsgs', 'tole': 1}}",
         r"simulation\.integrator\.solver\.tole: unknown key for nsgs; expected one of type, tol, max_iter, relaxation"),
        ("{'type': 'moreau_jean', 'dt': 1e-3, 'solver': 'gauss'}", r"simulation\.integrator\.solver\.type: expected nsgs, newton, apgd, lemke or auto"),
    ],
)
def test_python_file_bad_integrator_names_the_key(tmp_path, value, expected):
    p = write(tmp_path, PENDULUM_PY.replace("ms.RK4(dt=1e-3)", value), "bad_integrator.py")
    with pytest.raises(ModelError, match=expected) as e:
        load_model(p)
    assert str(e.value).startswith(f"{p}: ")


def test_toml_contact_integrator_tables(tmp_path):
    text = PENDULUM_TOML.replace('{ type = "rk4", dt = 1e-3 }',
                                 '{ type = "moreau_jean", dt = 1e-3, solver = { type = "nsgs", tol = 1e-8, max_iter = 50 } }')
    _, sim = load_model(write(tmp_path, text))
    assert sim["integrator"] == {"type": "moreau_jean", "dt": 1e-3,
                                 "solver": {"type": "nsgs", "tol": 1e-8, "max_iter": 50, "relaxation": 1.0, "anderson": 0,
                                            "stall": 0}}
    assert simulation_kwargs(sim)["integrator"] == ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-8, max_iter=50))
    text = PENDULUM_TOML.replace('{ type = "rk4", dt = 1e-3 }',
                                 '{ type = "moreau_jean", dt = 1e-3, solver = { type = "nsgs", tol = 1e-6, anderson = 4 } }')
    _, sim = load_model(write(tmp_path, text))
    assert simulation_kwargs(sim)["integrator"] == ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-6, anderson=4))
    text = PENDULUM_TOML.replace('{ type = "rk4", dt = 1e-3 }',
                                 '{ type = "moreau_jean", dt = 1e-3, solver = { type = "nsgs", tol = 1e-6, stall = 1024 } }')
    _, sim = load_model(write(tmp_path, text))
    assert simulation_kwargs(sim)["integrator"] == ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-6, stall=1024))
    for table, key in (('{ type = "nsgs", anderson = -1 }', "anderson"), ('{ type = "auto", nsgs_anderson = 2.5 }', "nsgs_anderson"),
                       ('{ type = "nsgs", stall = -1 }', "stall")):
        text = PENDULUM_TOML.replace('{ type = "rk4", dt = 1e-3 }', f'{{ type = "moreau_jean", dt = 1e-3, solver = {table} }}')
        with pytest.raises(ModelError, match=rf"simulation\.integrator\.solver\.{key}: expected an integer >= 0"):
            load_model(write(tmp_path, text))
    text = PENDULUM_TOML.replace('{ type = "rk4", dt = 1e-3 }', '{ type = "event_driven", max_events = 10, continue_on_painleve = true }')
    _, sim = load_model(write(tmp_path, text))
    assert simulation_kwargs(sim)["integrator"] == ms.EventDriven(max_events=10, continue_on_painleve=True)
    text = PENDULUM_TOML.replace('{ type = "rk4", dt = 1e-3 }', '{ type = "event_driven", max_events = 1.5 }')
    with pytest.raises(ModelError, match=r"simulation\.integrator\.max_events: expected an integer >= 1, got 1\.5"):
        load_model(write(tmp_path, text))
    # a count beyond what the engine's unsigned integers take, named (it had reached the engine)
    text = PENDULUM_TOML.replace('{ type = "rk4", dt = 1e-3 }',
                                 '{ type = "moreau_jean", dt = 1e-3, solver = { type = "nsgs", stall = 1e30 } }')
    with pytest.raises(ModelError, match=r"simulation\.integrator\.solver\.stall: expected an integer at most 2\*\*53"):
        load_model(write(tmp_path, text))


def test_simulation_kwargs_overrides_an_integrator_object():
    defaults = {"t_end": 1.0, "integrator": ms.MoreauJean(1e-5, solver=ms.NSGS(tol=1e-6, max_iter=100))}
    assert simulation_kwargs(defaults, dt=1e-4)["integrator"] == ms.MoreauJean(1e-4, solver=ms.NSGS(tol=1e-6, max_iter=100))
    # naming the file's own solver keeps its settings; another solver replaces it
    assert simulation_kwargs(defaults, solver="nsgs")["integrator"] == defaults["integrator"]
    assert simulation_kwargs(defaults, solver="lemke")["integrator"] == ms.MoreauJean(1e-5, solver=ms.Lemke())
    assert simulation_kwargs(defaults, integrator="event_driven", rtol=1e-6)["integrator"] == ms.EventDriven(rtol=1e-6)
    assert simulation_kwargs(defaults, integrator="radau5")["integrator"] == ms.Radau5(dt=1e-5)  # the step carries over
    ed = {"t_end": 1.0, "integrator": ms.EventDriven(rtol=1e-8, max_events=7, continue_on_painleve=True)}
    assert simulation_kwargs(ed, atol=1e-9)["integrator"] == ms.EventDriven(rtol=1e-8, atol=1e-9, max_events=7,
                                                                            continue_on_painleve=True)
    with pytest.raises(SettingsError, match=r"--solver does not apply to integrator event_driven"):
        simulation_kwargs(ed, solver="nsgs")
    with pytest.raises(SettingsError, match=r"--solver does not apply to integrator dopri5"):
        simulation_kwargs({"t_end": 1.0}, solver="nsgs")
    with pytest.raises(SettingsError, match=r"--dt: must be > 0, got -1"):
        simulation_kwargs(defaults, dt=-1.0)
    with pytest.raises(SettingsError, match=r"--solver\.type: expected nsgs, newton, apgd, lemke or auto, got 'gauss'"):
        simulation_kwargs(defaults, solver="gauss")


def test_scalars_for_one_dof_values_in_toml(tmp_path):
    # q0, u0 of a 1-DOF joint and a joint force's value may be plain numbers (newcomer finding 18)
    text = """
name = "pend"
gravity = [0, 0, -9.81]
[[bodies]]
name = "bob"
mass = 1.0
inertia = [0.01, 0.01, 0.01]
com = [0, 0, -0.5]
[[joints]]
name = "hinge"
type = "revolute"
parent = "ground"
child = "bob"
axis = [1, 0, 0]
q0 = 0.3
u0 = -0.2
[[forces]]
type = "joint_force"
name = "push"
joint = "hinge"
value = 2.0
"""
    path = tmp_path / "pend.toml"
    path.write_text(text)
    from mechsys.modelfile import load_model

    model, _ = load_model(path)
    assert model.q0()[0] == 0.3 and model.state_vector(None, "u")[0] == -0.2
    res = ms.simulate(model, 0.01, ms.RK4(dt=1e-3))
    np.testing.assert_allclose(res["force/push/force"], 2.0)
    path.write_text(text.replace("value = 2.0", 'value = "lots"'))
    with pytest.raises(ms.ModelError, match=r"forces\[0\].*value: expected a finite number or a list of finite numbers"):
        load_model(path)
    path.write_text(text.replace("q0 = 0.3", 'q0 = "up"'))
    with pytest.raises(ms.ModelError, match=r"joints\[0\]\.q0: expected a finite number or a list of finite numbers"):
        load_model(path)


def test_run_guards_and_sensors_in_the_simulation_table(tmp_path):
    p = write(tmp_path, PENDULUM_TOML.replace("t_end = 1.0", "t_end = 1.0\nmax_steps = 10\nsensors = [\"joint/*/q\"]"))
    model, defaults = load_model(p)
    assert defaults["max_steps"] == 10 and defaults["sensors"] == ["joint/*/q"]
    with pytest.raises(ms.SolverError, match="step budget"):
        ms.simulate(model, **simulation_kwargs(defaults))
    p = write(tmp_path, PENDULUM_TOML.replace("t_end = 1.0", "t_end = 1.0\non_singular = \"sometimes\""))
    model, defaults = load_model(p)
    with pytest.raises(ms.SettingsError, match="on_singular: must be 'continue' or 'stop'"):
        ms.simulate(model, **simulation_kwargs(defaults))


@pytest.mark.parametrize("key", ["constraints", "contacts", "contact_groups"])
def test_a_single_table_where_an_array_of_tables_belongs_is_named(tmp_path, key):
    p = write(tmp_path, PENDULUM_TOML + f"\n[{key}]\nname = \"x\"\n")
    with pytest.raises(ModelError, match=rf"{key}: expected an array of tables \(\[\[{key}\]\]\)"):
        load_model(p)


@pytest.mark.parametrize("extra, where", [
    ('[[forces]]\ntype = "callback"\nname = "law"\nid = 0\n', "forces[0] 'law'"),
    ('[[forces]]\ntype = "joint_force"\nname = "drive"\njoint = "hinge"\nvalue = { type = "callback", id = 0 }\n',
     "forces[0] 'drive'.value"),
])
def test_a_callback_in_a_toml_file_is_refused_at_load_naming_the_element(tmp_path, extra, where):
    text = PENDULUM_TOML.replace("[simulation]", extra + "\n[simulation]")
    with pytest.raises(ModelError, match=re.escape(f"{where}: a callback needs a Python callable")):
        load_model(write(tmp_path, text))


def test_the_description_an_engine_writes_reads_back_for_every_example():
    """A results file stores the engine's description (absent values written as null): it must
    build the same model again (the viewer and parameter studies rebuild models from it)."""
    import glob
    import json
    import warnings

    from mechsys.modelfile import load_model

    root = Path(__file__).resolve().parents[1]
    files = sorted(glob.glob(str(root / "examples" / "*.py"))) + sorted(glob.glob(str(root / "examples" / "*.toml")))
    assert len(files) > 20
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for f in files:
            m, _ = load_model(f)
            d = json.loads(m.build().description_json())
            again = ms.Model.from_dict(d, m.callbacks)
            assert json.loads(again.build().description_json()) == d, f


def test_solver_names_and_auto_tables():
    """solver="auto" in Python and a TOML-style table with the auto keys; a bad name in the
    Python object names the parameter."""
    assert ms.MoreauJean(1e-3, solver="auto").solver == ms.Auto()
    assert ms.MoreauJean(1e-3, solver="newton").solver == ms.Newton()
    sim = simulation_kwargs({"t_end": 1.0, "integrator": {"type": "moreau_jean", "dt": 1e-3, "parallel": False,
                                                          "solver": {"type": "auto", "tol": 1e-8, "newton_max_unknowns": 90}}})
    assert sim["integrator"] == ms.MoreauJean(1e-3, solver=ms.Auto(tol=1e-8, newton_max_unknowns=90), parallel=False)
    with pytest.raises(SettingsError, match=r"MoreauJean\.solver\.type: expected nsgs, newton, apgd, lemke or auto, got 'fast'"):
        ms.MoreauJean(1e-3, solver="fast")
