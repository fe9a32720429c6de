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
