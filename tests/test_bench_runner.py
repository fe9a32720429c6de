"""The one-run benchmark driver (benches/run_all.py): it runs the scripts it is given, records
each one's status in its summary section, and reports a failing script with exit status 1."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RUN_ALL = ROOT / "benches" / "run_all.py"


def run(*args, cwd=ROOT):
    return subprocess.run([sys.executable, str(RUN_ALL), *args], cwd=cwd, capture_output=True, text=True, timeout=600)


def test_unknown_script_is_named():
    r = run("--only", "peerz")
    assert r.returncode == 2
    assert "unknown benchmark script 'peerz.py'" in r.stderr


def test_summary_section_lists_each_script(tmp_path):
    out = tmp_path / "bench.md"
    out.write_text("# Benchmarks\n\n<!-- run_all:begin -->\nold\n<!-- run_all:end -->\n\ntail kept\n")
    r = run("--only", "planar", "--quick", "--out", str(out))
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert "old" not in text and "tail kept" in text
    assert "| `planar.py` |" in text and "| ok |" in text
    assert "1 of the 19 benchmark scripts" in text
    # the script's own section was written into the same file
    assert "<!-- planar.py:begin" in text


def test_failing_script_gives_exit_1(tmp_path):
    out = tmp_path / "bench.md"
    # a directory where the output file should be: the script cannot write its section and fails
    out.mkdir()
    r = run("--only", "planar", "--quick", "--out", str(out))
    assert r.returncode == 1
    assert "failed: planar.py" in r.stderr


def test_revision_ignores_the_results_file_being_written(tmp_path):
    """The scripts of one run write their sections into the results file one after another, so
    the later ones found the tree changed and marked the figures "dirty" (a280e3f-dirty in the
    constraints section of a clean run); only other changes count."""
    sys.path.insert(0, str(ROOT / "benches"))
    from benchdoc import revision

    git = lambda *a: subprocess.run(["git", *a], cwd=tmp_path, check=True, capture_output=True)  # noqa: E731
    git("init", "-q")
    (tmp_path / "docs").mkdir()
    results, source = tmp_path / "docs" / "benchmarks.md", tmp_path / "model.py"
    results.write_text("# Benchmarks\n")
    source.write_text("x = 1\n")
    git("add", ".")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "start")
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=tmp_path, capture_output=True, text=True).stdout.strip()
    results.write_text("# Benchmarks\nnew figures\n")
    assert revision(tmp_path, results) == head
    assert revision(tmp_path) == f"{head} (with local changes)"
    source.write_text("x = 2\n")
    assert revision(tmp_path, results) == f"{head} (with local changes)"
    assert revision(tmp_path / "nowhere") == "unknown"


def test_interleaved_timing_takes_turns_and_times_every_call():
    """benchdoc.interleaved: one warm-up each, then rounds in which every call runs once, the
    order turned by one each round; min <= median per call, and the last results returned."""
    sys.path.insert(0, str(ROOT / "benches"))
    import time

    from benchdoc import interleaved

    order = []

    def make(name, pause):
        def fn():
            order.append(name)
            time.sleep(pause)
            return len(order)
        return fn

    out = interleaved({"a": make("a", 0.002), "b": make("b", 0.0), "c": make("c", 0.0)}, rounds=3)
    # warm-ups a b c, then rounds a b c / b c a / c a b
    assert order == list("abc" + "abc" + "bca" + "cab")
    assert (out["a"][2], out["b"][2], out["c"][2]) == (11, 12, 10)  # each one's last call
    for name, (tmin, tmed, _) in out.items():
        assert 0 < tmin <= tmed, name
    assert out["a"][0] >= 0.002 > out["b"][1]
