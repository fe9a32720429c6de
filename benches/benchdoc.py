"""Shared helpers of the benchmark scripts: formatting of times and ratios, the machine
description, and replacing a script's marked section of docs/benchmarks.md."""

from __future__ import annotations

import contextlib
import math
import os
import platform
import re
import statistics
import time
from pathlib import Path


def bench_args(doc: str, argv=None, repeat: int = 5):
    """The common options of a benchmark script (``--out``, ``--repeat``, ``--quick``: one run):
    the parsed arguments, with ``repeat`` already lowered by ``--quick``."""
    import argparse

    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--repeat", type=int, default=repeat)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    if a.quick:
        a.repeat = 1
    return a


def timed(fn, repeat: int):
    """Runs ``fn`` ``repeat`` times: (min, median) wall time and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), statistics.median(times), out


def interleaved(fns: dict, rounds: int, budget: float = 0.0) -> dict:
    """Times several calls side by side: one warm-up each, then rounds in which every call runs
    once (the order turned by one each round, the garbage collector off during a call), so that
    a machine whose speed drifts or jumps between modes (a shared VM) slows them alike instead of
    whichever happened to run in its slow spell. At least ``rounds`` rounds, more while the
    rounds so far took less than ``budget`` seconds. ``{name: (min, median, last result)}``."""
    import gc

    names = list(fns)
    out = {n: fns[n]() for n in names}
    times: dict = {n: [] for n in names}
    t_start = time.perf_counter()
    k = 0
    while k < rounds or (time.perf_counter() - t_start < budget and k < 50 * max(rounds, 1)):
        for i in range(len(names)):
            n = names[(i + k) % len(names)]
            gc.collect()
            gc.disable()
            t0 = time.perf_counter()
            out[n] = fns[n]()
            times[n].append(time.perf_counter() - t0)
            gc.enable()
        k += 1
    return {n: (min(times[n]), statistics.median(times[n]), out[n]) for n in names}


def fmt_time(s: float | None) -> str:
    """A duration in µs, ms or s with three significant digits ("–" for none)."""
    if s is None or not math.isfinite(s):
        return "–"
    if s < 1e-3:
        return f"{s * 1e6:.3g} µs"
    if s < 1.0:
        return f"{s * 1e3:.3g} ms"
    return f"{s:.3g} s"


def ratio(ours: float | None, peer: float | None) -> str:
    """mechsys against a peer, from the minimum times."""
    if ours is None or peer is None:
        return "–"
    return f"**{peer / ours:.2f}× faster**" if ours <= peer else f"{ours / peer:.2f}× slower"


def machine() -> dict:
    """Cores, CPU model, OS, Python version and the load average now."""
    cpu = platform.processor() or "unknown"
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return {"nproc": os.cpu_count(), "cpu": cpu, "os": platform.platform(), "python": platform.python_version(), "load": load}


def revision(root: Path, output: Path | None = None) -> str:
    """The checked-out commit, "(with local changes)" if tracked files differ from it — not
    counting ``output``, the results file the benchmarks themselves are writing — or "unknown"."""
    import subprocess

    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True, check=True, timeout=10)
        spec = ["--", "."] + ([f":(exclude){Path(output).resolve().relative_to(Path(root).resolve())}"] if output else [])
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", *spec], cwd=root,
                               capture_output=True, text=True, timeout=10)
        return out.stdout.strip() + (" (with local changes)" if dirty.stdout.strip() else "")
    except (OSError, ValueError, subprocess.SubprocessError):
        return "unknown"


def write_doc(path: Path, section: str, begin: str, end: str, heading: str | None = None) -> None:
    """Replaces the text between a script's markers in ``path``, or appends the marked section
    (under ``heading`` if given); the rest of the file is kept."""
    block = f"{begin}\n{section}\n{end}"
    head = f"{heading}\n\n" if heading else ""
    if path.exists():
        text = path.read_text()
        if begin in text and end in text:
            text = re.sub(re.escape(begin) + r".*?" + re.escape(end), lambda _: block, text, count=1, flags=re.S)
        else:
            text = text.rstrip("\n") + "\n\n" + head + block + "\n"
    else:
        text = f"# Benchmarks\n\n{head}{block}\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
