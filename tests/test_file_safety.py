"""Outputs never destroy what was there (issue 13's bad inputs; ../shared/reviews/file-safety.md):
every writer goes through a temporary file renamed over its target, so a save that fails or is
interrupted part-way leaves the previous file intact and no debris; the command line refuses, before
it simulates, an output that is its own input or another output, or that cannot be written."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys.files import check_outputs, write_atomically

ROOT = Path(__file__).resolve().parents[1]
PENDULUM = ROOT / "examples" / "pendulum.toml"


def mechsys(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "mechsys", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT)


@pytest.fixture
def model(tmp_path):
    p = tmp_path / "pendulum.toml"
    p.write_bytes(PENDULUM.read_bytes())
    return p


@pytest.mark.parametrize("option", ["--out", "--csv", "--plot"])
def test_an_output_naming_the_model_file_is_refused_and_the_model_survives(model, tmp_path, option):
    before = model.read_bytes()
    extra = [] if option == "--out" else ["--out", tmp_path / "r.h5"]
    p = mechsys("run", model, option, model, *extra, "--t-end", "0.1")
    assert p.returncode != 0
    assert f"{option} {model}: that is the model file" in p.stderr and "Traceback" not in p.stderr
    assert model.read_bytes() == before
    assert not (tmp_path / "r.h5").exists()  # refused before the run: nothing written


def test_two_outputs_naming_one_file_and_unwritable_places_are_refused_before_the_run(model, tmp_path):
    p = mechsys("run", model, "--out", tmp_path / "r.png", "--plot", tmp_path / "r.png", "--t-end", "0.1")
    assert p.returncode != 0 and "--out and --plot name the same file" in p.stderr
    assert not (tmp_path / "r.png").exists()
    p = mechsys("run", model, "--out", tmp_path, "--t-end", "0.1")
    assert p.returncode != 0 and "is a directory" in p.stderr
    if os.geteuid() != 0:  # root writes anywhere
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        try:
            p = mechsys("run", model, "--out", ro / "r.h5", "--t-end", "0.1")
            assert p.returncode != 0 and "cannot write in" in p.stderr
        finally:
            ro.chmod(0o755)


def test_plot_refuses_to_overwrite_its_results_file(model, tmp_path):
    res_path = tmp_path / "res.h5"
    assert mechsys("run", model, "--out", res_path, "--t-end", "0.1", "-q").returncode == 0
    before = res_path.read_bytes()
    p = mechsys("plot", res_path, "joint/hinge/q", "--out", res_path)
    assert p.returncode != 0 and "that is the results file" in p.stderr
    assert res_path.read_bytes() == before
    assert ms.Results.load(res_path)["joint/hinge/q"].shape == (11,)


def test_a_save_that_fails_part_way_keeps_the_previous_results_and_leaves_no_debris(model, tmp_path, monkeypatch):
    from mechsys.modelfile import load_model

    m, sim = load_model(model)
    res = ms.simulate(m, 0.1, ms.RK4(dt=1e-3))
    path = tmp_path / "r.h5"
    res.save(path)
    before = path.read_bytes()
    import h5py

    real = h5py.Group.create_dataset
    calls = {"n": 0}

    def failing(self, name, *a, **k):
        calls["n"] += 1
        if calls["n"] > 3:
            raise OSError(28, "No space left on device")
        return real(self, name, *a, **k)

    monkeypatch.setattr(h5py.Group, "create_dataset", failing)
    with pytest.raises(OSError, match="No space left"):
        res.save(path)
    monkeypatch.setattr(h5py.Group, "create_dataset", real)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pendulum.toml", "r.h5"]
    # an interrupt during a write: the same
    csv = tmp_path / "r.csv"
    res.to_csv(csv, ["joint/hinge/q"])
    good = csv.read_text()

    def interrupted(tmp):
        Path(tmp).write_text("half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_atomically(csv, interrupted)
    assert csv.read_text() == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pendulum.toml", "r.csv", "r.h5"]


def test_check_outputs_names_each_problem(tmp_path):
    a = tmp_path / "a.h5"
    a.write_text("x")
    with pytest.raises(ms.SettingsError, match=r"--out .*a.h5: that is the model file"):
        check_outputs({"model file": a}, {"--out": a})
    # the same file through a different spelling of its path
    with pytest.raises(ms.SettingsError, match="--out and --csv name the same file"):
        check_outputs({}, {"--out": tmp_path / "b.h5", "--csv": tmp_path / "sub" / ".." / "b.h5"})
    check_outputs({"model file": a}, {"--out": tmp_path / "new" / "deeper" / "r.h5", "--plot": None})


@pytest.mark.parametrize("name, fragment", [
    ("a/position", "must not contain '/'"),
    ("a\x00b", "control character"),
    ("line\nbreak", "control character"),
    ("..", "is not a usable name"),
    ("x" * 201, "too long"),
])
def test_names_that_would_break_signal_names_or_the_results_file_are_refused(name, fragment):
    m = ms.Model("names")
    b = m.add_body(name, 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Revolute("j", m.ground, b))
    with pytest.raises(ms.ModelError, match=r"bodies\[0\]"):
        m.build()
    with pytest.raises(ms.ModelError, match=fragment):
        m.build()
    m2 = ms.Model("names")
    b2 = m2.add_body("b", 1.0, [1, 1, 1])
    m2.add_joint(ms.joints.Revolute(name, m2.ground, b2))
    with pytest.raises(ms.ModelError, match=r"joints\[0\]"):
        m2.build()


def test_an_output_that_is_a_symlink_is_refused_unless_followed(model, tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious data")
    link = tmp_path / "link.h5"
    link.symlink_to(victim)
    p = mechsys("run", model, "--out", link, "--t-end", "0.1")
    assert p.returncode != 0 and "is a symbolic link" in p.stderr
    assert victim.read_text() == "precious data"
    for opt, name in (("--csv", "link.csv"), ("--plot", "link.png")):
        other = tmp_path / name
        other.symlink_to(victim)
        p = mechsys("run", model, "--out", tmp_path / "r.h5", opt, other, "--t-end", "0.1")
        assert p.returncode != 0 and f"{opt} {other}: is a symbolic link" in p.stderr
        assert victim.read_text() == "precious data"
    # asked for: the link's target is written (and the link stays a link)
    target = tmp_path / "target.h5"
    link2 = tmp_path / "link2.h5"
    link2.symlink_to(target)
    p = mechsys("run", model, "--out", link2, "--t-end", "0.1", "--follow-symlinks", "-q")
    assert p.returncode == 0, p.stderr
    assert link2.is_symlink() and ms.Results.load(target)["joint/hinge/q"].shape == (11,)


@pytest.mark.parametrize("args, fragment", [
    (["--t-end", "1e300"], "gives 1.000e302 samples"),
    (["--dt", "1e-300", "--t-end", "1"], "is 1.000e300 steps, more than 1e12"),
    (["--t-end", "1e6", "--output-dt", "1e-6"], "bytes of results, more than the"),
])
def test_runs_that_could_never_finish_or_fit_are_refused_before_they_start(model, tmp_path, args, fragment):
    """--t-end 1e300 returned 0 samples with exit 0 (the sample count wrapped to zero), --dt 1e-300
    hung; now each is an error with the estimate, before any allocation."""
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(model), "--out", str(tmp_path / "r.h5"), *args],
                       capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert p.returncode != 0 and fragment in p.stderr and "Traceback" not in p.stderr, p.stderr
    assert not (tmp_path / "r.h5").exists()


def test_a_model_too_big_for_memory_is_refused_with_the_estimate():
    from mechsys.errors import ModelError

    m = ms.Model("big")
    for i in range(40_000):
        b = m.add_body(f"b{i}", 1.0, [1, 1, 1])
        m.add_joint(ms.joints.Free(f"j{i}", m.ground, b))
    with pytest.raises(ModelError, match=r"40000 bodies, 240000 velocities .* need about 4.6\d\de11 bytes of workspace"):
        m.build()


SAVER = r"""
import signal
import sys
# a shell that starts jobs in the background leaves SIGINT ignored in them: Python's own handler
signal.signal(signal.SIGINT, signal.default_int_handler)
import mechsys as ms
m = ms.Model("chain", gravity=(0, -9.81, 0))
parent = m.ground
for i in range(20):
    b = m.add_body(f"b{i}", 1.0, ms.inertia.rod(1.0, 0.1), com=(0.05, 0, 0))
    m.add_joint(ms.joints.Revolute(f"j{i}", parent, b, parent_frame=(0.1, 0, 0) if i else None, q0=0.1))
    parent = b
res = ms.simulate(m, 0.5, ms.RK4(dt=1e-4), output_dt=1e-4)
print("ready", flush=True)
while True:
    res.save(sys.argv[1])
    print("saved", flush=True)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_killing_a_save_at_random_moments_never_damages_the_results_file(tmp_path):
    """SIGKILL and SIGINT during saves, 20 times at random moments: the file is always a complete,
    verified results file (the previous one or the new one)."""
    import random
    import signal
    import time

    path = tmp_path / "r.h5"
    rng = random.Random(7)
    for k in range(20):
        p = subprocess.Popen([sys.executable, "-u", "-c", SAVER, str(path)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
        try:
            assert p.stdout.readline().strip() == "ready"
            if k == 0:
                # one whole save first, so that the file exists (and is checked) after every kill
                # however slow the machine is (under load, all 20 random kills once came before
                # the first save had finished)
                assert p.stdout.readline().strip() == "saved"
            time.sleep(rng.uniform(0.0, 0.6))
            p.send_signal(signal.SIGKILL if k % 2 == 0 else signal.SIGINT)
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                # an interrupt raised inside a finalizer is swallowed by Python ("Exception
                # ignored"), and this saver loops for ever: what counts here is the file
                p.kill()
                p.wait()
        finally:
            if p.poll() is None:
                p.kill()
                p.wait()
        if path.exists():
            res = ms.Results.load(path)  # complete marker and every checksum verified
            assert res["joint/j19/q"].shape == (5001,)
    assert path.exists()


def test_two_runs_writing_one_output_at_once_leave_one_complete_file(model, tmp_path):
    out = tmp_path / "r.h5"
    runs = [subprocess.Popen([sys.executable, "-m", "mechsys", "run", str(model), "--out", str(out), "--t-end", t, "-q"],
                             cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE) for t in ("2.0", "3.0")]
    for p in runs:
        p.wait(timeout=120)
    assert all(p.returncode == 0 for p in runs)
    res = ms.Results.load(out)
    assert res.t[-1] in (2.0, 3.0) and len(res.t) in (201, 301)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pendulum.toml", "r.h5"]


def test_default_results_names_of_different_models_do_not_collide():
    from mechsys.cli import _safe_name

    names = ["a\\b", "a\nb", "a b", " a ", "a", ".", "..", "/", "x" * 300]
    stems = [_safe_name(n) for n in names]
    assert len(set(stems)) == len(stems), stems
    assert _safe_name("pendulum") == "pendulum" and all(len(s) <= 110 for s in stems)


def test_an_output_below_a_file_names_that_file(model, tmp_path):
    blocker = tmp_path / "victim.txt"
    blocker.write_text("data")
    p = mechsys("run", model, "--out", blocker / "x.h5", "--t-end", "0.1")
    assert p.returncode != 0 and f"{blocker} is not a directory" in p.stderr
    assert blocker.read_text() == "data"


@pytest.mark.skipif(not Path("/proc/self/limits").exists(), reason="Linux resource limits")
def test_a_run_over_an_address_space_limit_is_refused_not_aborted(model, tmp_path):
    """Review F12: under `ulimit -v 4000000` a 2.5e7-sample run (6.6 GB estimated) aborted with
    SIGABRT; the memory budget now includes the process's address-space limit."""
    script = (
        "import resource, sys\n"
        "resource.setrlimit(resource.RLIMIT_AS, (4_000_000_000, 4_000_000_000))\n"
        "from mechsys.cli import main\n"
        "sys.argv = ['mechsys', 'run', sys.argv[1], '--dt', '2e-7', '--output-dt', '2e-7', '--t-end', '5', '--out', sys.argv[2], '-q']\n"
        "sys.exit(main())\n"
    )
    p = subprocess.run([sys.executable, "-c", script, str(model), str(tmp_path / "r.h5")], capture_output=True, text=True,
                       cwd=ROOT, timeout=120)
    assert p.returncode == 2, (p.returncode, p.stderr[-500:])
    assert "bytes of results, more than the" in p.stderr and "Traceback" not in p.stderr


COLL_TOML = """
name = "coll"
[[bodies]]
name = "a"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
[[bodies]]
name = "a/position"
mass = 1.0
inertia = [1.0, 1.0, 1.0]
[[joints]]
type = "revolute"
name = "j1"
parent = "ground"
child = "a"
[[joints]]
type = "revolute"
name = "j2"
parent = "a"
child = "a/position"
[simulation]
t_end = 0.1
integrator = { type = "rk4", dt = 1e-3 }
"""


def test_review_f3_colliding_names_leave_the_previous_results_intact(model, tmp_path):
    prev = tmp_path / "prev.h5"
    assert mechsys("run", model, "--out", prev, "--t-end", "0.1", "-q").returncode == 0
    before = prev.read_bytes()
    coll = tmp_path / "coll.toml"
    coll.write_text(COLL_TOML)
    p = mechsys("run", coll, "--out", prev, "-q")
    assert p.returncode == 2 and "must not contain '/'" in p.stderr and "Traceback" not in p.stderr
    assert prev.read_bytes() == before
    assert mechsys("signals", prev).returncode == 0


def test_review_f14_a_huge_model_file_is_an_error_line_not_an_abort(tmp_path):
    n = 40_000
    lines = []
    for i in range(n):
        lines.append(f'[[bodies]]\nname = "b{i}"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n')
        parent = "ground" if i == 0 else f"b{i - 1}"
        lines.append(f'[[joints]]\ntype = "free"\nname = "j{i}"\nparent = "{parent}"\nchild = "b{i}"\n')
    big = tmp_path / "big.toml"
    big.write_text('name = "big"\n' + "".join(lines))
    p = mechsys("info", big)
    assert p.returncode == 2, (p.returncode, p.stderr[-300:])
    assert "need about" in p.stderr and "bytes of workspace" in p.stderr and "Traceback" not in p.stderr


@pytest.mark.parametrize("command", ["run", "info", "linear"])
def test_review_f15_the_help_of_every_command_loading_a_model_says_py_files_run(command):
    p = mechsys(command, "--help")
    assert p.returncode == 0 and "executed as Python code" in " ".join(p.stdout.split())


def test_an_unwritable_output_directory_is_named_even_for_root(tmp_path, monkeypatch):
    """The subprocess check above is skipped as root (root writes anywhere): the decision itself,
    with the permission check answering no."""
    ro = tmp_path / "ro"
    ro.mkdir()
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, mode, *a, **k: False if Path(p) == ro else real(p, mode, *a, **k))
    with pytest.raises(ms.SettingsError, match=r"--out .*r.h5: cannot write in .*ro \(permission denied\)"):
        check_outputs({}, {"--out": ro / "sub" / "r.h5"})
