"""Linear vibration analysis (issue 5): cost of linearization, eigen-analysis, frequency responses
and Campbell diagrams, with the accuracy each reaches on a closed form.

1. A chain of N = 200 masses (1 kg) on prismatic joints along x, tied to each other and to the
   walls at both ends by spring-dampers (k = 1e4 N/m, d = 2 N s/m): ``linearize`` (each method
   it offers), ``modes()`` (eigenvalues of the 2N x 2N state matrix); the natural frequencies
   2 sqrt(k/m) sin(j pi / (2 (N + 1))) / 2 pi against the modes' |lambda| / 2 pi (equal: the
   damping D = (d/k) K is proportional).
2. H(j w) at 1000 frequencies for one input and one output (the first and the last mass): the
   modal form (one diagonalization, K Phi = M Phi W^2 for this proportionally damped chain, then
   O(N) per frequency), the state-space modal form (the same chain with one extra damper
   between masses 0 and 1, which makes the damping non-proportional: one eigen-decomposition of
   the 2N x 2N state matrix) and the direct one (an N x N complex solve per frequency): wall time
   and the largest difference to the direct solve.
3. A Campbell diagram of the gyroscopic rotor of examples/rotor_campbell.py at 100 speeds (100
   re-linearizations, eigen-analyses and the MAC tracking).

Times: from Python with the model built beforehand, min (median) over repeats, with BLAS on one
thread (OPENBLAS_NUM_THREADS=1 etc., unless set): on the shared two-core machine OpenBLAS' threads
wait on each other and one 200 x 200 complex solve took 128 ms instead of 0.7 ms.
Usage: ``.venv/bin/python benches/linear.py [--out docs/benchmarks.md] [--quick]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import inspect
import os
import sys
import time
import warnings
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # before numpy loads its BLAS

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchdoc import fmt_time, machine, timed, write_doc  # noqa: E402

import mechsys as ms  # noqa: E402

N, K, D, MASS = 200, 1e4, 2.0, 1.0


def chain(n: int = N) -> ms.Model:
    m = ms.Model(f"chain{n}", gravity=(0.0, 0.0, 0.0))
    bodies = [m.add_body(f"m{i}", MASS, [1e-3] * 3) for i in range(n)]
    for i, b in enumerate(bodies):
        m.add_joint(ms.joints.Prismatic(f"x{i}", m.ground, b, axis=(1, 0, 0), parent_frame=(i + 1.0, 0, 0)))
    ends = [(m.ground, (0, 0, 0), bodies[0])] + [(bodies[i], (0, 0, 0), bodies[i + 1]) for i in range(n - 1)]
    for k, (b1, p1, b2) in enumerate(ends):
        m.add_force(ms.forces.SpringDamper(f"s{k}", b1, b2, point1=p1, k=K, d=D, l0=1.0))
    m.add_force(ms.forces.SpringDamper(f"s{n}", bodies[-1], m.ground, point2=(n + 1.0, 0, 0), k=K, d=D, l0=1.0))
    return m


def exact_frequencies(n: int = N) -> np.ndarray:
    j = np.arange(1, n + 1)
    return 2 * np.sqrt(K / MASS) * np.sin(j * np.pi / (2 * (n + 1))) / (2 * np.pi)


def rotor_example():
    spec = importlib.util.spec_from_file_location("rotor_campbell", Path(__file__).resolve().parent.parent / "examples" / "rotor_campbell.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, help="write the results section into this markdown file")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    repeat = 1 if a.quick else a.repeat
    warnings.simplefilter("ignore")
    mach = machine()
    model = chain()
    model.build()

    # 1. linearization (each method linearize offers) and eigen-analysis
    methods = [None]
    if "method" in inspect.signature(ms.linear.linearize).parameters:
        methods = ["exact", "fd"]
    rows_lin, lins = [], {}
    for meth in methods:
        kw = {} if meth is None else {"method": meth}
        tmin, tmed, lin = timed(lambda: ms.linear.linearize(model, **kw), repeat)
        lins[meth] = lin
        rows_lin.append((meth or "(single method)", tmin, tmed))
        print(f"linearize {meth or '':6s} N = {N}: {fmt_time(tmin)} ({fmt_time(tmed)})")
    lin = lins[methods[0]]
    k_diff = None
    if len(methods) == 2:
        ka, kb = lins["exact"].K, lins["fd"].K
        k_diff = float(np.abs(ka - kb).max() / np.abs(ka).max())
        print(f"max |K_exact - K_fd| / max |K_exact| = {k_diff:.2e}")
    tmin_m, tmed_m, modes = timed(lin.modes, repeat)
    f_err = float(np.abs(modes.natural_frequency / exact_frequencies() - 1).max())
    zeta_max = float(modes.damping_ratio.max())
    print(f"modes N = {N}: {fmt_time(tmin_m)} ({fmt_time(tmed_m)}), max relative frequency error {f_err:.1e} (zeta up to {zeta_max:.1e})")

    # 2. FRF at 1000 frequencies, one input, one output
    f = np.linspace(0.5, 1.05 * exact_frequencies()[-1], 1000)
    extra = np.zeros((N, N))
    extra[:2, :2] = [[5.0, -5.0], [-5.0, 5.0]]
    nonprop = lin.with_damping(lin.D + extra)
    rows_frf = []
    cases = (("modal, real modes (proportional damping)", lin, "modal"), ("direct (proportional damping)", lin, "direct"),
             ("modal, state space (non-proportional damping)", nonprop, "modal"), ("direct (non-proportional damping)", nonprop, "direct"))
    direct = {id(lin): lin.frf(f[:1], inputs=[0], outputs=[N - 1], method="direct")}
    for name, lm, meth in cases:
        tmin, tmed, h = timed(lambda: lm.frf(f, inputs=[0], outputs=[N - 1], method=meth), repeat if meth == "modal" else max(1, repeat // 3))
        if meth == "direct":
            direct[id(lm)] = h
        rows_frf.append([name, tmin, tmed, h, lm])
        print(f"frf {name:48s} 1000 frequencies: {fmt_time(tmin)} ({fmt_time(tmed)})")
    for row in rows_frf:
        ref = direct[id(row[4])]
        row[3] = float(np.abs(row[3] - ref).max() / np.abs(ref).max())
        print(f"frf {row[0]:48s} against the direct solve: largest difference {row[3]:.1e} of max |H|")

    # 3. Campbell diagram at 100 speeds
    rot = rotor_example()
    rlin = ms.linear.linearize(rot.model)
    speeds = np.linspace(0.0, 600.0, 100)
    tmin_c, tmed_c, camp = timed(lambda: rlin.campbell(speeds, joint="spin", whirl=("alpha", "beta")), repeat)
    c_err = 0.0
    for k, w in enumerate(speeds[1:], start=1):
        ff, fb = rot.whirl_frequencies(w)
        by = dict(zip(camp.whirl[k], camp.frequencies[k]))
        c_err = max(c_err, abs(by["forward"] / ff - 1), abs(by["backward"] / fb - 1))
    print(f"campbell 100 speeds: {fmt_time(tmin_c)} ({fmt_time(tmed_c)}), whirl frequencies vs undamped formula {c_err:.1e}")

    if a.out:
        L = ["## Linear vibration analysis (issue 5)", ""]
        L.append(f"Generated by `benches/linear.py` (this section only). {time.strftime('%Y-%m-%d %H:%M')} on "
                 f"{mach['nproc']} × {mach['cpu']}, load average at start {mach['load'][0]:.2f}. Problems are in the "
                 f"script's docstring; times from Python with the model built beforehand, BLAS on one thread, min (median) over {repeat} run(s).")
        L += ["", f"### Chain of {N} masses on prismatic joints ({N} DOF)", "", "| step | wall time | accuracy |", "|---|---:|---|"]
        for name, tmin, tmed in rows_lin:
            acc = f"max relative difference of K to the exact method {k_diff:.1e}" if (k_diff is not None and name == "fd") else ""
            L.append(f"| `linearize` {name} | {fmt_time(tmin)} ({fmt_time(tmed)}) | {acc} |")
        if k_diff is None:
            L.append("| `linearize` method=\"fd\" | – | TODO: `linearize` has no `method=` yet; rerun this script once it has |")
        L.append(f"| `modes()` (eigenvalues of the {2 * N} × {2 * N} state matrix) | {fmt_time(tmin_m)} ({fmt_time(tmed_m)}) | "
                 f"natural frequencies against the closed form: largest relative difference {f_err:.1e} (damping ratios up to {zeta_max:.1e}) |")
        for name, tmin, tmed, diff, _ in rows_frf:
            acc = f"largest difference to the direct solve {diff:.1e} of max \\|H\\|" if name.startswith("modal") else ""
            L.append(f"| `frf` at 1000 frequencies, 1 input, 1 output, {name} | {fmt_time(tmin)} ({fmt_time(tmed)}) | {acc} |")
        L += ["", "### Campbell diagram of the gyroscopic rotor (examples/rotor_campbell.py), 100 speeds", "",
              "| step | wall time | accuracy |", "|---|---:|---|",
              f"| `campbell` (100 linearizations, eigen-analyses, MAC tracking, whirl directions) | {fmt_time(tmin_c)} ({fmt_time(tmed_c)}) | "
              f"whirl frequencies against the undamped formula: largest relative difference {c_err:.1e} (the example's damping, zeta = 0.0025) |"]
        write_doc(a.out, "\n".join(L), "<!-- linear.py:begin -->", "<!-- linear.py:end -->")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
