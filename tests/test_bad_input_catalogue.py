"""Bad input answered (issue 13, parts 5-6): each case must give a typed mechsys error whose
message names the offending item, never a raw Python exception, a panic or a silent result. Cases
found by a hostile-user review beside those already in test_model_errors.py."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import mechsys as ms


def one(name="m", **joint):
    m = ms.Model(name)
    b = m.add_body("arm", 1.0, [1, 1, 1], com=(0.1, 0, 0))
    m.add_joint(ms.joints.Revolute("hinge", m.ground, b, **joint))
    return m, b


def foreign_handle():
    a = ms.Model("a")
    arm_a = a.add_body("arm", 1.0, [1, 1, 1])
    b = ms.Model("b")
    b.add_body("arm", 2.0, [1, 1, 1])
    b.add_joint(ms.joints.Revolute("j", b.ground, arm_a))


def foreign_handle_in_force():
    a = ms.Model("a")
    arm_a = a.add_body("arm", 1.0, [1, 1, 1])
    m, _ = one("b")
    m.add_force(ms.forces.SpringDamper("spring", m.ground, arm_a, k=1.0))


def string_stiffness():
    m, b = one()
    m.add_force(ms.forces.SpringDamper("spring", m.ground, b, k="stiff"))
    m.build()


def nan_q0_dict():
    m, _ = one()
    ms.simulate(m, 1.0, q0={"hinge": float("nan")})


def inf_u0_dict():
    m, _ = one()
    ms.simulate(m, 1.0, u0={"hinge": float("inf")})


def nan_q0_joint():
    m, _ = one(q0=float("nan"))
    ms.simulate(m, 1.0)


def step_longer_than_run():
    m, _ = one()
    ms.simulate(m, 0.5, ms.RK4(dt=1.0))


def output_longer_than_run():
    m, _ = one()
    ms.simulate(m, 0.5, output_dt=2.0)


def tiny_rtol():
    m, _ = one()
    ms.simulate(m, 0.5, ms.DOPRI5(rtol=1e-30))


def huge_rtol():
    m, _ = one()
    ms.simulate(m, 0.5, ms.DOPRI5(rtol=1e6))


def bad_on_singular():
    m, _ = one()
    ms.simulate(m, 0.5, on_singular="ignore")


def point_mass_spinning_on_itself():
    m = ms.Model("pm")
    b = m.add_body("dot", 1.0, [0, 0, 0])
    m.add_joint(ms.joints.Spherical("ball", m.ground, b))
    ms.simulate(m, 0.5)


def negative_inertia():
    m = ms.Model("neg")
    b = m.add_body("arm", 1.0, [-1.0, 1.0, 1.0])
    m.add_joint(ms.joints.Revolute("hinge", m.ground, b))
    m.build()


def zero_max_steps():
    m, _ = one()
    ms.simulate(m, 0.5, max_steps=0)


def negative_max_wall():
    m, _ = one()
    ms.simulate(m, 0.5, max_wall=-3)


CASES = {
    "body handle of another model (joint)": (foreign_handle, ms.ModelError, ["joint 'j'.child", "'arm'", "model 'a'"]),
    "body handle of another model (force)": (foreign_handle_in_force, ms.ModelError, ["force 'spring'.body2", "model 'a'"]),
    "string for a stiffness": (string_stiffness, ms.ModelError, ["force 'spring'", "'stiff'"]),
    "NaN in q0": (nan_q0_dict, ms.SettingsError, ["q0", "joint 'hinge'", "not finite"]),
    "inf in u0": (inf_u0_dict, ms.SettingsError, ["u0", "joint 'hinge'", "not finite"]),
    "NaN in a joint's q0": (nan_q0_joint, ms.ModelError, ["q0", "finite"]),
    "step longer than the run": (step_longer_than_run, ms.SettingsError, ["integrator.dt", "longer than the run"]),
    "output_dt longer than the run": (output_longer_than_run, ms.SettingsError, ["output_dt", "longer than the run"]),
    "rtol 1e-30": (tiny_rtol, ms.SettingsError, ["integrator.rtol", "1e-14"]),
    "rtol 1e6": (huge_rtol, ms.SettingsError, ["integrator.rtol", "[1e-14, 1)"]),
    "unknown on_singular": (bad_on_singular, ms.SettingsError, ["on_singular", "'ignore'"]),
    "point mass turning about itself": (point_mass_spinning_on_itself, ms.ModelError, ["'ball'", "no inertia"]),
    "negative principal moment": (negative_inertia, ms.ModelError, ["'arm'", "negative principal moment"]),
    "max_steps 0": (zero_max_steps, ms.SettingsError, ["max_steps"]),
    "max_wall negative": (negative_max_wall, ms.SettingsError, ["max_wall"]),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_gets_a_clear_typed_error(case):
    fn, kind, fragments = CASES[case]
    with pytest.raises(kind) as err:
        fn()
    msg = str(err.value)
    for f in fragments:
        assert f in msg, (case, msg)


@pytest.mark.parametrize("source,fragments", [
    ('import mechsys as ms\nmodel = ms.Model("x"\n', ["line 2", "syntax error"]),
    ('import mechsys as ms\n\nraise RuntimeError("boom in the model")\n', ["line 3", "RuntimeError", "boom in the model"]),
    ("x = 1\n", ["no module-level 'model'"]),
])
def test_a_broken_python_model_file_is_one_error_line(tmp_path, source, fragments):
    path = tmp_path / "broken.py"
    path.write_text(source)
    r = subprocess.run([sys.executable, "-m", "mechsys", "info", str(path)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stderr.startswith("error: ") and all(f in r.stderr for f in fragments), r.stderr
