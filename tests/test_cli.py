"""The ``mechsys`` command line: run, info, plot, signals; errors as one line with exit status 2."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import mechsys as ms
from mechsys.cli import cli, main

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

[[forces]]
type = "joint_force"
name = "drive"
joint = "hinge"
value = [0.0]

[simulation]
t_end = 0.5
integrator = { type = "rk4", dt = 1e-3 }
q0 = { hinge = 0.5 }
"""

DOUBLE_TOML = """\
name = "double"
gravity = [0.0, -9.81, 0.0]

[[bodies]]
name = "upper"
mass = 1.0
inertia = [1e-4, 0.0833, 0.0833]
com = [0.5, 0.0, 0.0]

[[bodies]]
name = "lower"
mass = 0.5
inertia = [1e-4, 0.04, 0.04]
com = [0.5, 0.0, 0.0]

[[joints]]
name = "shoulder"
type = "revolute"
parent = "ground"
child = "upper"

[[joints]]
name = "elbow"
type = "revolute"
parent = "upper"
child = "lower"
parent_frame = { position = [1.0, 0.0, 0.0] }
"""


@pytest.fixture(scope="module", autouse=True)
def _matplotlib_loaded():
    """Import matplotlib once per module so that its start-up cost is not charged to one test."""
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner()


@pytest.fixture
def model_file(tmp_path: Path) -> Path:
    p = tmp_path / "pendulum.toml"
    p.write_text(PENDULUM_TOML)
    return p


def reference_results() -> ms.Results:
    m = ms.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", mass=1.0, inertia=[1e-4, 0.0833, 0.0833], com=(0.5, 0.0, 0.0))
    m.add_joint(ms.joints.Revolute("hinge", parent=m.ground, child=rod, axis=(0.0, 0.0, 1.0)))
    m.add_force(ms.forces.JointForce("drive", joint="hinge", value=0.0))
    return ms.simulate(m, t_end=0.5, integrator=ms.RK4(dt=1e-3), q0={"hinge": 0.5})


def assert_input_error(result, *fragments: str) -> str:
    """Exit status 2 and one line 'error: ...' on stderr containing every fragment."""
    assert result.exit_code == 2, (result.exit_code, result.output, result.exception)
    err = result.stderr.strip()
    assert err.startswith("error: "), err
    assert "\n" not in err, err
    assert "Traceback" not in result.output
    for f in fragments:
        assert f in err, (f, err)
    return err


# ---- run -----------------------------------------------------------------------------------------


def test_run_saves_results_identical_to_python(runner, model_file, tmp_path):
    out = tmp_path / "out" / "res.h5"
    result = runner.invoke(cli, ["run", str(model_file), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "501 samples" in result.stdout
    assert "500 steps" in result.stdout
    assert str(out) in result.stdout
    assert "wall time" in result.stdout
    loaded = ms.load(out)
    ref = reference_results()
    assert sorted(loaded.names()) == sorted(ref.names())
    for name in ref.names():
        np.testing.assert_array_equal(loaded[name], ref[name], err_msg=name)
        assert loaded.unit(name) == ref.unit(name)
    assert loaded.unit("joint/hinge/q") == "rad"
    assert loaded.settings["integrator"] == {"type": "rk4", "dt": 1e-3}


def test_run_default_output_path_and_quiet(runner, model_file, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(cli, ["run", str(model_file), "--quiet"])
    assert result.exit_code == 0, result.output
    assert result.output == ""
    res = ms.load(tmp_path / "results" / "pendulum.h5")
    assert len(res.t) == 501


def test_run_overrides(runner, model_file, tmp_path):
    out = tmp_path / "r.h5"
    args = ["run", str(model_file), "--out", str(out), "--t-end", "0.2", "--integrator", "dopri5", "--rtol", "1e-6"]
    result = runner.invoke(cli, args + ["--output-dt", "0.01", "-q"])
    assert result.exit_code == 0, result.output
    res = ms.load(out)
    np.testing.assert_allclose(res.t, np.linspace(0.0, 0.2, 21), atol=1e-12)
    assert res.settings["integrator"]["type"] == "dopri5"
    assert res.settings["integrator"]["rtol"] == 1e-6


def test_run_plot_and_csv(runner, model_file, tmp_path):
    png, csv = tmp_path / "p.png", tmp_path / "p.csv"
    args = ["run", str(model_file), "--out", str(tmp_path / "r.h5"), "--plot", str(png), "--csv", str(csv)]
    result = runner.invoke(cli, args + ["--signals", "joint/hinge/q,energy/kinetic", "--signals", "body/rod/position"])
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = csv.read_text().splitlines()
    assert lines[0] == (
        "t [s],joint/hinge/q [rad],energy/kinetic [J],"
        "body/rod/position[0] [m],body/rod/position[1] [m],body/rod/position[2] [m]"
    )
    assert len(lines) == 1 + 501


def test_run_default_plot(runner, model_file, tmp_path):
    svg = tmp_path / "p.svg"
    result = runner.invoke(cli, ["run", str(model_file), "--out", str(tmp_path / "r.h5"), "--plot", str(svg), "-q"])
    assert result.exit_code == 0, result.output
    text = svg.read_text()
    assert "<svg" in text and "joint/hinge/q" in text and "energy/total" in text


def test_run_unknown_signal(runner, model_file, tmp_path):
    out = tmp_path / "r.h5"
    result = runner.invoke(cli, ["run", str(model_file), "--out", str(out), "--plot", str(tmp_path / "p.png"), "--signals", "joint/hing/q"])
    assert_input_error(result, "unknown signal 'joint/hing/q'", str(out))
    assert out.exists()  # the simulation is not lost


def test_run_misspelt_key(runner, model_file):
    model_file.write_text(PENDULUM_TOML.replace("mass = 1.0", "mas = 1.0"))
    result = runner.invoke(cli, ["run", str(model_file)])
    assert_input_error(result, str(model_file), "bodies[0]", "mas", "unknown field")


def test_run_negative_mass(runner, model_file):
    model_file.write_text(PENDULUM_TOML.replace("mass = 1.0", "mass = -1.0"))
    result = runner.invoke(cli, ["run", str(model_file)])
    assert_input_error(result, "'rod'", "mass", "> 0")


def test_run_settings_errors(runner, model_file, tmp_path):
    result = runner.invoke(cli, ["run", str(model_file), "--integrator", "dopri5", "--dt", "1e-3"])
    assert_input_error(result, "--dt does not apply to integrator dopri5")
    result = runner.invoke(cli, ["run", str(model_file), "--output-dt", "0"])
    assert_input_error(result, "output_dt: must be > 0")
    result = runner.invoke(cli, ["run", str(model_file), "--t-end", "-1"])
    assert_input_error(result, "t_end", "> t0")
    no_sim = tmp_path / "nosim.toml"
    no_sim.write_text(PENDULUM_TOML.split("[simulation]")[0])
    result = runner.invoke(cli, ["run", str(no_sim)])
    assert_input_error(result, "t_end: not given")


def test_run_missing_and_unsupported_files(runner, tmp_path):
    result = runner.invoke(cli, ["run", str(tmp_path / "nothere.toml")])
    assert_input_error(result, "nothere.toml", "no such model file")
    (tmp_path / "m.yaml").write_text("x: 1\n")
    result = runner.invoke(cli, ["run", str(tmp_path / "m.yaml")])
    assert_input_error(result, "'.yaml'")


def test_run_python_model_file(runner, tmp_path):
    p = tmp_path / "pend.py"
    p.write_text(
        "import mechsys as ms\n"
        "model = ms.Model('pypend', gravity=(0, -9.81, 0))\n"
        "rod = model.add_body('rod', mass=1.0, inertia=[1e-4, 0.0833, 0.0833], com=(0.5, 0, 0))\n"
        "model.add_joint(ms.joints.Revolute('hinge', parent=model.ground, child=rod))\n"
        "simulation = {'t_end': 0.1, 'integrator': ms.RK4(dt=1e-3)}\n"
    )
    out = tmp_path / "py.h5"
    result = runner.invoke(cli, ["run", str(p), "--out", str(out), "--integrator", "radau5"])
    assert result.exit_code == 0, result.output
    assert ms.load(out).settings["integrator"]["type"] == "radau5"


def test_console_script_runs(model_file, tmp_path):
    """The installed entry point (and python -m mechsys) work outside the test process."""
    script = Path(sys.executable).parent / "mechsys"
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "mechsys"]
    out = tmp_path / "sub.h5"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run(cmd + ["run", str(model_file), "--out", str(out)], capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "501 samples" in proc.stdout
    np.testing.assert_array_equal(ms.load(out)["joint/hinge/q"], reference_results()["joint/hinge/q"])

    bad = tmp_path / "bad.toml"
    bad.write_text(PENDULUM_TOML.replace("mass = 1.0", "mas = 1.0"))
    proc = subprocess.run(cmd + ["run", str(bad)], capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.startswith("error: ") and "bodies[0].mas" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_python_dash_m(model_file):
    proc = subprocess.run([sys.executable, "-m", "mechsys", "--version"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"mechsys {ms.__version__}"


def test_main_returns_exit_status(model_file, capsys):
    assert main(["--version"]) == 0
    assert main(["info", str(model_file.with_name("nothere.toml"))]) == 2
    assert capsys.readouterr().err.startswith("error: ")


# ---- info ----------------------------------------------------------------------------------------


def test_info(runner, model_file):
    result = runner.invoke(cli, ["info", str(model_file)])
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "pendulum" in out
    assert "DOF      1 (nu), nq = 1" in out
    assert "hinge" in out and "revolute" in out and "ground -> rod" in out
    assert "drive" in out and "joint_force" in out
    assert "(0, -9.81, 0)" in out
    assert "t_end = 0.5" in out


def test_info_two_joints(runner, tmp_path):
    p = tmp_path / "double.toml"
    p.write_text(DOUBLE_TOML)
    result = runner.invoke(cli, ["info", str(p)])
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "DOF      2 (nu), nq = 2" in out
    for name in ("shoulder", "elbow", "upper", "lower", "upper -> lower"):
        assert name in out
    assert "force elements (0)" in out


def test_info_misspelt_key(runner, tmp_path):
    p = tmp_path / "double.toml"
    p.write_text(DOUBLE_TOML.replace('name = "elbow"', 'nme = "elbow"'))
    result = runner.invoke(cli, ["info", str(p)])
    assert_input_error(result, "joints[1]", "nme")


# ---- plot and signals ----------------------------------------------------------------------------


@pytest.fixture
def results_file(model_file, tmp_path) -> Path:
    out = tmp_path / "res.h5"
    reference_results().save(out)
    return out


def test_plot_command(runner, results_file, tmp_path):
    result = runner.invoke(cli, ["plot", str(results_file), "joint/hinge/q", "body/rod/orientation"])
    assert result.exit_code == 0, result.output
    png = results_file.with_suffix(".png")
    assert png.stat().st_size > 1000
    svg = tmp_path / "q.svg"
    result = runner.invoke(cli, ["plot", str(results_file), "energy/total", "--out", str(svg)])
    assert result.exit_code == 0, result.output
    assert "<svg" in svg.read_text()


def test_plot_unknown_signal(runner, results_file):
    result = runner.invoke(cli, ["plot", str(results_file), "joint/hinge/q", "energy/totl"])
    assert_input_error(result, "unknown signal 'energy/totl'", "energy/total")


def test_plot_bad_extension(runner, results_file, tmp_path):
    result = runner.invoke(cli, ["plot", str(results_file), "energy/total", "--out", str(tmp_path / "x.bmp")])
    assert_input_error(result, "'.bmp'", ".png")


def test_signals_command(runner, results_file):
    result = runner.invoke(cli, ["signals", str(results_file)])
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    rows = {line.split()[0]: line.split()[1:] for line in lines[2:]}
    assert rows["t"] == ["s", "(501,)"]
    assert rows["joint/hinge/q"] == ["rad", "(501,)"]
    assert rows["body/rod/position"] == ["m", "(501,", "3)"]
    assert rows["energy/total"] == ["J", "(501,)"]


def test_non_hdf5_results_file(runner, tmp_path):
    p = tmp_path / "results.h5"
    p.write_text("this is not HDF5\n")
    for args in (["signals", str(p)], ["plot", str(p), "energy/total"]):
        result = runner.invoke(cli, args)
        assert_input_error(result, str(p), "not an HDF5 results file")
    result = runner.invoke(cli, ["signals", str(tmp_path / "missing.h5")])
    assert_input_error(result, "missing.h5", "does not exist")


# ---- help and version ----------------------------------------------------------------------------


@pytest.mark.parametrize("command", [[], ["run"], ["plot"], ["info"], ["signals"]])
def test_help(runner, command):
    result = runner.invoke(cli, command + ["--help"])
    assert result.exit_code == 0
    assert "Usage: " in result.output
    if command == ["run"]:
        for opt in ("--t-end", "--dt", "--integrator", "--rtol", "--atol", "--output-dt", "--out", "--plot", "--signals", "--csv", "--quiet"):
            assert opt in result.output


def test_version(runner):
    result = runner.invoke(cli, ["--version"])
    assert result.exit_code == 0
    assert result.output.strip() == f"mechsys {ms.__version__}"


def test_usage_error_exit_code(runner):
    result = runner.invoke(cli, ["run"])
    assert result.exit_code == 2
    assert "Missing argument 'MODEL'" in result.output


def test_run_prints_warnings_as_warning_lines_and_plots_without_offset(tmp_path):
    """A run's warnings reach the terminal as `warning: ...` lines, without Python's source line
    (review newcomer.md, 16); plotted axes carry absolute tick labels, not an offset (13)."""
    ex = Path(__file__).resolve().parents[1] / "examples" / "slider_crank.py"
    script = Path(sys.executable).parent / "mechsys"
    r = subprocess.run([str(script), "run", str(ex), "--t-end", "0.01", "--out", str(tmp_path / "sc.h5")],
                       capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 0, r.stderr
    assert "warning: model 'slider-crank': 1 redundant constraint equation(s)" in r.stderr
    assert "UserWarning" not in r.stderr and "cli.py" not in r.stderr
    res = ms.load(tmp_path / "sc.h5")
    fig = ms.plot(res, ["energy/total"], out=tmp_path / "e.png")
    assert all(not ax.yaxis.get_major_formatter().get_useOffset() for ax in fig.axes)
