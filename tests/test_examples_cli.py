"""Every file in examples/ runs from the command line, as the README says (`mechsys run X`).

Each example is run in a subprocess through the installed console script with a short end time;
the run must succeed and the HDF5 file it writes must hold finite samples at the file's own
sampling interval. The files are found by glob, so a new example is covered without editing this.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import mechsys as ms
from mechsys.modelfile import load_model

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FILES = sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".py", ".toml"))

#: Shortest simulated span (s); an example sampled more coarsely runs for SAMPLES output intervals.
T_SHORT = 0.05
SAMPLES = 10
#: Slower examples run for less (per file name); none is needed today.
T_END: dict[str, float] = {}


def mechsys_command() -> list[str]:
    script = Path(sys.executable).parent / "mechsys"
    return [str(script)] if script.exists() else [sys.executable, "-m", "mechsys"]


def run_example(path: Path, t_end: float, out: Path, cwd: Path, *extra: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "MPLBACKEND": "Agg"}
    cmd = mechsys_command() + ["run", str(path), "--t-end", repr(t_end), "--out", str(out), *extra]
    return subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd, timeout=120)


def sample_count(t0: float, t_end: float, output_dt: float) -> int:
    """Samples t0, t0 + output_dt, ... up to t_end (as mechsys.simulate counts them)."""
    return int(math.floor((t_end - t0) / output_dt * (1 + 1e-12) + 1e-9)) + 1


def short_end(path: Path, sim: dict) -> float:
    if path.name in T_END:
        return T_END[path.name]
    output_dt = sim.get("output_dt")
    return max(T_SHORT, SAMPLES * output_dt) if output_dt else T_SHORT


def test_examples_are_found():
    names = {p.name for p in FILES}
    assert {"woodpecker.py", "press_fit.py", "pendulum.toml", "box_stack.py"} <= names


@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_example_runs_from_the_command_line(path, tmp_path):
    _, sim = load_model(path)  # the file's own simulation defaults: its sampling interval
    t_end = short_end(path, sim)
    out = tmp_path / f"{path.stem}.h5"
    proc = run_example(path, t_end, out, tmp_path)
    assert proc.returncode == 0, f"exit {proc.returncode}\nstdout:\n{proc.stdout}\nstderr:\n{proc.stderr}"
    assert "Traceback" not in proc.stderr, proc.stderr
    assert str(out) in proc.stdout

    assert out.exists() and h5py.is_hdf5(out)
    res = ms.load(out)
    t = res.t
    t0 = sim.get("t0", 0.0)
    assert len(t) >= 2 and t[0] == pytest.approx(t0) and t[-1] <= t_end * (1 + 1e-12)
    if "output_dt" in sim:
        assert len(t) == sample_count(t0, t_end, sim["output_dt"])
        np.testing.assert_allclose(np.diff(t), sim["output_dt"], rtol=1e-9)
    sampled = [n for n in res.names() if np.asarray(res[n]).ndim >= 1 and len(res[n]) == len(t)]
    assert sampled, f"no signal with {len(t)} samples in {out}"
    not_finite = [n for n in sampled if not np.all(np.isfinite(np.asarray(res[n], dtype=float)))]
    assert not not_finite, f"non-finite values in {not_finite}"


def test_woodpecker_samples_and_contacts_from_the_command_line(tmp_path):
    """The showcase with its own Moreau-Jean object: 0.05 s sampled every 1e-4 s is 501 samples."""
    path = EXAMPLES / "woodpecker.py"
    out = tmp_path / "wp.h5"
    proc = run_example(path, 0.05, out, tmp_path, "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == ""
    res = ms.load(out)
    assert res.settings["integrator"]["type"] == "moreau_jean"
    assert res.settings["integrator"]["dt"] == 1e-5
    assert res.settings["output_dt"] == 1e-4
    assert len(res.t) == 501  # 0.05 / 1e-4 + 1
    assert res.t[-1] == pytest.approx(0.05, abs=1e-12)
    for name in ("contact/beak/impulse_n", "joint/sleeve/q", "joint/pin/q", "energy/total"):
        assert name in res and np.all(np.isfinite(res[name])), name
    # the sleeve slides down the pole
    assert res["joint/sleeve/q"][-1, 1] < res["joint/sleeve/q"][0, 1]


def test_command_line_options_override_an_integrator_object(tmp_path):
    """--integrator / --dt / --solver override the MoreauJean object in the file's simulation dict."""
    path = EXAMPLES / "striking_pendulum.py"
    out = tmp_path / "sp.h5"
    proc = run_example(path, 0.02, out, tmp_path, "--dt", "2e-4", "--solver", "lemke", "--output-dt", "1e-3")
    assert proc.returncode == 0, proc.stderr
    settings = ms.load(out).settings
    assert settings["integrator"]["type"] == "moreau_jean"
    assert settings["integrator"]["dt"] == 2e-4
    assert settings["integrator"]["solver"]["type"] == "lemke"
    assert len(ms.load(out).t) == 21
    proc = run_example(path, 0.02, out, tmp_path, "--integrator", "event_driven", "--rtol", "1e-8")
    assert proc.returncode == 0, proc.stderr
    settings = ms.load(out).settings
    assert settings["integrator"]["type"] == "event_driven" and settings["integrator"]["rtol"] == 1e-8
    # an option that does not fit the file's scheme is an input error, not a traceback
    proc = run_example(path, 0.02, out, tmp_path, "--rtol", "1e-8")
    assert proc.returncode == 2
    assert proc.stderr.strip() == "error: --rtol does not apply to integrator moreau_jean (it has a fixed step: use --dt)"


def test_the_readme_model_is_the_model_of_its_toml_file(tmp_path, monkeypatch):
    """The README's first Python model and examples/double_pendulum.toml are one model: run both
    and compare (the README code as written, results written under a temporary directory)."""
    readme = (EXAMPLES.parent / "README.md").read_text()
    code = readme.split("## A first model", 1)[1].split("```python", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    exec(compile(code, "README.md", "exec"), ns)  # noqa: S102 - the project's own README
    model, defaults = load_model(EXAMPLES / "double_pendulum.toml")
    from mechsys.modelfile import simulation_kwargs

    toml_res = ms.simulate(model, **simulation_kwargs(defaults))
    py_res = ns["res"]
    assert len(py_res.t) == len(toml_res.t)
    for name in ("joint/shoulder/q", "joint/elbow/q", "energy/total"):
        assert np.abs(py_res[name] - toml_res[name]).max() < 1e-12, name
