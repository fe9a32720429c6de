"""mechsys against its peers, timed in the same run on the same model.

The model is the engine's fixture chain (``mechsys_core::fixtures::chain(n, "revolute")``): n
uniform rods (1 kg, 0.5 m long, radius 0.02 m) along x, joint i at the tip of rod i-1, revolute
axes alternating z, y, x, gravity -z, initial angles q_i = 0.1 + 0.05 i, at rest. It is built
identically in each package:

- mechsys: the Python model builder (``mechsys.Model``, ``joints.Revolute``);
- Pinocchio (``pin``): ``JointModelRZ/RY/RX`` with placements [0.5, 0, 0] and ``Inertia(m, c, I_c)``;
- MuJoCo (``mujoco``): an MJCF string of nested bodies with hinges, explicit ``<inertial>``, no
  geoms (hence no contacts), no limits, damping or armature, ``integrator="RK4"``, dt = 1e-3;
- Exudyn (``exudyn``): one ``ObjectKinematicTree`` (minimal coordinates) solved with ``RK44``.

Measured:

(a) per call from Python: ``mechsys.dynamics.forward_dynamics`` (kinematics + ABA) and
    ``mechsys.dynamics.mass_matrix`` (positions + CRBA) against ``pinocchio.aba`` and
    ``pinocchio.crba``, N = 1, 4, 16, 64, 256, after checking that both give the same
    accelerations and mass matrix (relative 1e-9); MuJoCo's ``qacc`` from ``mj_forward`` is checked too;
(b) whole simulations, 1 s at dt = 1e-3 with RK4, from a Python call until the results are in
    hand: ``mechsys.simulate`` (records every step: 1001 samples of every signal) against
    ``mujoco.rollout.rollout`` (MuJoCo's own C loop, 1000 states) and Exudyn's
    ``SolveDynamic(RK44)`` (1000 steps, no solution file, no sensors). Final states are compared.

Timings use ``time.perf_counter`` with the garbage collector off: per-call timings are batches
calibrated to >= 20 ms (each call its own count), one batch of each call per round
(mechsys's and Pinocchio's taking turns, ``benchdoc.interleaved``); whole simulations are single
calls, repeated. Each cell shows
min (median); ratios use the minimum, the least disturbed by other load on the machine.

Reproduce (after ``make build``)::

    .venv/bin/python -m pip install pin mujoco exudyn
    .venv/bin/python benches/peers.py --out docs/benchmarks.md     # or: make bench

``--quick`` for a smoke run; ``--sizes``/``--sim-sizes`` to choose N; ``--skip exudyn`` to leave a peer out.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import gc
import json
import math
import os
import platform
import re
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from benchdoc import fmt_time, interleaved, machine, ratio, revision, write_doc  # noqa: E402  (shared report helpers)

ROOT = Path(__file__).resolve().parent.parent

# ---- the chain (same numbers as crates/mechsys-core/src/fixtures.rs) --------------------------------
MASS, LENGTH, RADIUS = 1.0, 0.5, 0.02
I_AXIAL = 0.5 * MASS * RADIUS**2
I_TRANSVERSE = MASS * (3.0 * RADIUS**2 + LENGTH**2) / 12.0
AXES = ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))
GRAVITY = (0.0, 0.0, -9.81)
T_END, DT = 1.0, 1e-3
N_STEPS = 1000
REL_TOL = 1e-9


def q_init(n: int) -> np.ndarray:
    return np.array([0.1 + 0.05 * i for i in range(n)])


def u_test(n: int) -> np.ndarray:
    """The velocity of the per-call checks (the same pattern as the Rust benchmark)."""
    return np.array([0.3 - 0.01 * (k % 17) for k in range(n)])


# ---- models -----------------------------------------------------------------------------------------
def mechsys_chain(n: int):
    import mechsys as ms
    from mechsys import joints

    m = ms.Model(f"chain-{n}-revolute", gravity=GRAVITY)
    parent = m.ground
    for i in range(n):
        body = m.add_body(f"link{i + 1}", mass=MASS, inertia=[I_AXIAL, I_TRANSVERSE, I_TRANSVERSE], com=(0.5 * LENGTH, 0, 0))
        m.add_joint(
            joints.Revolute(
                f"j{i + 1}",
                parent,
                body,
                parent_frame=(0.0 if i == 0 else LENGTH, 0.0, 0.0),
                axis=AXES[i % 3],
                q0=0.1 + 0.05 * i,
            )
        )
        parent = body
    m.build()
    return m


def pinocchio_chain(n: int):
    import pinocchio as pin

    model = pin.Model()
    model.gravity = pin.Motion(np.array(GRAVITY), np.zeros(3))
    kinds = (pin.JointModelRZ, pin.JointModelRY, pin.JointModelRX)
    parent = 0
    inertia = pin.Inertia(MASS, np.array([0.5 * LENGTH, 0.0, 0.0]), np.diag([I_AXIAL, I_TRANSVERSE, I_TRANSVERSE]))
    for i in range(n):
        placement = pin.SE3(np.eye(3), np.array([0.0 if i == 0 else LENGTH, 0.0, 0.0]))
        jid = model.addJoint(parent, kinds[i % 3](), placement, f"j{i + 1}")
        model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        parent = jid
    return model, model.createData()


def mjcf_chain(n: int) -> str:
    """MJCF of the chain: nested bodies, explicit inertials, no geoms, no contacts."""
    body = ""
    for i in reversed(range(n)):
        pos = "0 0 0" if i == 0 else f"{LENGTH} 0 0"
        axis = " ".join(str(a) for a in AXES[i % 3])
        body = (
            f'<body name="link{i + 1}" pos="{pos}">'
            f'<joint name="j{i + 1}" type="hinge" axis="{axis}" pos="0 0 0" limited="false" damping="0" armature="0" frictionloss="0"/>'
            f'<inertial pos="{0.5 * LENGTH} 0 0" mass="{MASS}" diaginertia="{I_AXIAL!r} {I_TRANSVERSE!r} {I_TRANSVERSE!r}"/>'
            f"{body}</body>"
        )
    g = " ".join(str(x) for x in GRAVITY)
    return (
        f'<mujoco model="chain-{n}"><compiler angle="radian" inertiafromgeom="false"/>'
        f'<option timestep="{DT}" integrator="RK4" gravity="{g}"><flag contact="disable"/></option>'
        f"<worldbody>{body}</worldbody></mujoco>"
    )


def _set_first(obj, paths, names, value) -> None:
    """Sets the first existing ``path.name`` of ``obj`` (settings renamed across Exudyn versions)."""
    names = (names,) * len(paths) if isinstance(names, str) else names
    for path, name in zip(paths, names):
        o = obj
        try:
            for part in path.split("."):
                o = getattr(o, part)
            if hasattr(o, name):
                setattr(o, name, value)
                return
        except AttributeError:
            continue
    raise AttributeError(f"Exudyn settings: none of {paths} has {names}")


def exudyn_chain(n: int):
    import exudyn as exu
    from exudyn.itemInterface import NodeGenericODE2, ObjectKinematicTree

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    transforms, offsets = exu.Matrix3DList(), exu.Vector3DList()
    coms, inertias = exu.Vector3DList(), exu.Matrix3DList()
    kinds = (exu.JointType.RevoluteZ, exu.JointType.RevoluteY, exu.JointType.RevoluteX)
    for i in range(n):
        transforms.Append(np.eye(3))
        offsets.Append([0.0 if i == 0 else LENGTH, 0.0, 0.0])
        coms.Append([0.5 * LENGTH, 0.0, 0.0])
        inertias.Append(np.diag([I_AXIAL, I_TRANSVERSE, I_TRANSVERSE]))
    node = mbs.AddNode(
        NodeGenericODE2(
            referenceCoordinates=[0.0] * n,
            initialCoordinates=list(q_init(n)),
            initialCoordinates_t=[0.0] * n,
            numberOfODE2Coordinates=n,
        )
    )
    mbs.AddObject(
        ObjectKinematicTree(
            nodeNumber=node,
            jointTypes=[kinds[i % 3] for i in range(n)],
            linkParents=list(range(-1, n - 1)),
            jointTransformations=transforms,
            jointOffsets=offsets,
            linkInertiasCOM=inertias,
            linkCOMs=coms,
            linkMasses=[MASS] * n,
            baseOffset=[0.0, 0.0, 0.0],
            gravity=list(GRAVITY),
        )
    )
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.timeIntegration.numberOfSteps = N_STEPS
    s.timeIntegration.endTime = T_END
    s.timeIntegration.startTime = 0.0
    s.timeIntegration.verboseMode = 0
    s.timeIntegration.automaticStepSize = False
    # 4 right-hand sides per step, as mechsys and MuJoCo (the default adds a 5th for output);
    # no solution file, no sensor storage (newer Exudyn renamed these settings)
    _set_first(s, ("timeIntegration.explicit", "timeIntegration.explicitIntegration"), "computeEndOfStepAccelerations", False)
    _set_first(s, ("solution.file", "solutionSettings"), ("write", "writeSolutionToFile"), False)
    _set_first(s, ("solution.sensors", "solutionSettings"), ("active", "sensorsStoreAndWriteFiles"), False)
    return sc, mbs, node, s


# ---- timing -----------------------------------------------------------------------------------------
def _timed(fn, number: int) -> float:
    gc_was = gc.isenabled()
    gc.disable()
    try:
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        return time.perf_counter() - t0
    finally:
        if gc_was:
            gc.enable()


def per_call_turns(fns: dict, repeat: int, batch_time: float = 0.02) -> dict:
    """``{name: (min, median)}`` seconds per call of several calls timed taking turns: each in
    batches of >= ``batch_time`` (its own count of calls per batch), one batch of each per round
    (``benchdoc.interleaved``), so that a slow spell of the machine weighs on every side of a ratio
    alike instead of on whichever ran in it."""
    counts = {}
    for name, fn in fns.items():
        fn()
        number = 1
        while True:
            t = _timed(fn, number)
            if t >= batch_time:
                break
            number = max(number * 2, int(number * batch_time / max(t, 1e-9) * 1.2))
        counts[name] = number
    batches = {name: (lambda f=fn, k=counts[name]: _timed(f, k)) for name, fn in fns.items()}
    out = interleaved(batches, repeat)
    return {name: (out[name][0] / counts[name], out[name][1] / counts[name]) for name in fns}


def whole_run(fn, repeat: int, budget: float) -> tuple[float, float, int, object]:
    """(min, median, runs, last result) of single calls; fewer runs when one is slow."""
    gc.collect()
    t0 = time.perf_counter()
    out = fn()  # warm-up; also gives the result for the state comparison
    first = time.perf_counter() - t0
    if first > budget:  # one run is already too long: it is the measurement
        return first, first, 1, out
    runs = max(2, min(repeat, int(budget / max(first, 1e-9))))
    times = []
    for _ in range(runs):
        gc.collect()
        gc.disable()
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        gc.enable()
    return min(times), statistics.median(times), runs, out




def cell(t: tuple[float, float] | None) -> str:
    if t is None:
        return "–"
    return f"{fmt_time(t[0])} ({fmt_time(t[1])})"


def sim_cell(row: dict, key: str) -> str:
    """A whole-simulation cell; a single run (longer than the budget) is marked."""
    if key not in row:
        return "–"
    return fmt_time(row[key][0]) + " (1 run)" if row.get(f"runs_{key}") == 1 else cell(row[key])




def rel_err(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


# ---- the measurements ---------------------------------------------------------------------------------
def measure_calls(sizes, repeat, peers, log) -> list[dict]:
    import mechsys as ms

    rows = []
    for n in sizes:
        row: dict = {"n": n}
        m = mechsys_chain(n)
        q, u = q_init(n), u_test(n)
        a_ms = ms.dynamics.forward_dynamics(m, q, u)
        mm_ms = ms.dynamics.mass_matrix(m, q)
        # like Pinocchio (which returns its data.ddq), write into a kept array: no allocation per call
        out = np.empty(m.nu)
        calls = {"mechsys_aba": lambda: ms.dynamics.forward_dynamics(m, q, u, out=out),
                 "mechsys_crba": lambda: ms.dynamics.mass_matrix(m, q)}
        if "pinocchio" in peers:
            import pinocchio as pin

            pm, pd = pinocchio_chain(n)
            tau = np.zeros(n)
            a_pin = np.array(pin.aba(pm, pd, q, u, tau))
            mm_pin = np.array(pin.crba(pm, pd, q))
            mm_pin = np.triu(mm_pin) + np.triu(mm_pin, 1).T  # Pinocchio fills the upper triangle
            row["check_aba_pin"] = rel_err(a_ms, a_pin)
            row["check_crba_pin"] = rel_err(mm_ms, mm_pin)
            if row["check_aba_pin"] > REL_TOL or row["check_crba_pin"] > REL_TOL:
                row["mismatch"] = True
                log(f"  MISMATCH N={n}: aba rel {row['check_aba_pin']:.2e}, crba rel {row['check_crba_pin']:.2e}")
            calls["pin_aba"] = lambda: pin.aba(pm, pd, q, u, tau)
            calls["pin_crba"] = lambda: pin.crba(pm, pd, q)
        # every call's batches taken in turns with the others' (one batch of each per round)
        row.update(per_call_turns(calls, repeat))
        if "mujoco" in peers:
            import mujoco

            mm = mujoco.MjModel.from_xml_string(mjcf_chain(n))
            md = mujoco.MjData(mm)
            md.qpos[:] = q
            md.qvel[:] = u
            mujoco.mj_forward(mm, md)
            row["check_aba_mujoco"] = rel_err(a_ms, np.array(md.qacc))
            # MuJoCo solves M q̈ = f by factorizing M, whose round-off grows with cond(M) (≈ 6e9 at
            # N = 256), while both ABAs are O(n) recursions: hold it to eps·cond(M), not 1e-9
            row["cond_M"] = float(np.linalg.cond(mm_ms))
            tol = max(REL_TOL, np.finfo(float).eps * row["cond_M"])
            if row["check_aba_mujoco"] > tol:
                row["mismatch"] = True
                log(f"  MISMATCH N={n}: MuJoCo qacc rel {row['check_aba_mujoco']:.2e} > {tol:.1e}")
        log(
            f"  N={n:4d}  mechsys aba {cell(row['mechsys_aba'])}  crba {cell(row['mechsys_crba'])}"
            + (f"  | pin aba {cell(row['pin_aba'])}  crba {cell(row['pin_crba'])}" if "pin_aba" in row else "")
            + "".join(f"  {k}={v:.1e}" for k, v in row.items() if k.startswith("check_"))
        )
        rows.append(row)
    return rows


def measure_sims(sizes, repeat, budget, peers, log, exudyn_max_n=1 << 30) -> tuple[list[dict], dict]:
    import mechsys as ms

    notes: dict = {}
    rows = []
    for n in sizes:
        row: dict = {"n": n}
        m = mechsys_chain(n)
        integ = ms.RK4(DT)
        tmin, tmed, runs, res = whole_run(lambda: ms.simulate(m, T_END, integrator=integ), repeat, budget)
        assert res["t"].shape[0] == N_STEPS + 1 and abs(res["t"][-1] - T_END) < 1e-12
        q_ms, u_ms = np.array(res["q"][-1]), np.array(res["u"][-1])
        row["mechsys"] = (tmin, tmed)
        row["runs_mechsys"] = runs
        if "mujoco" in peers:
            import mujoco

            mm = mujoco.MjModel.from_xml_string(mjcf_chain(n))
            md = mujoco.MjData(mm)
            md.qpos[:] = q_init(n)
            md.qvel[:] = 0.0
            mujoco.mj_forward(mm, md)
            spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
            x0 = np.empty(mujoco.mj_stateSize(mm, spec))
            mujoco.mj_getState(mm, md, x0, spec)
            try:
                from mujoco import rollout as _rollout

                def run_mj():
                    state, _ = _rollout.rollout(mm, md, x0, nstep=N_STEPS)
                    return state

                notes["mujoco_loop"] = "`mujoco.rollout.rollout` (C++ loop, single thread)"
            except ImportError:  # older MuJoCo: a Python loop of mj_step

                def run_mj():
                    mujoco.mj_setState(mm, md, x0, spec)
                    out = np.empty((1, N_STEPS, x0.size))
                    for k in range(N_STEPS):
                        mujoco.mj_step(mm, md)
                        mujoco.mj_getState(mm, md, out[0, k], spec)
                    return out

                notes["mujoco_loop"] = "Python loop of `mj_step` (mujoco.rollout unavailable)"
            tmin, tmed, runs, state = whole_run(run_mj, repeat, budget)
            row["mujoco"] = (tmin, tmed)
            row["runs_mujoco"] = runs
            if runs >= repeat and row["runs_mechsys"] >= repeat:
                # both fit the budget: timed again taking turns (benchdoc.interleaved), so that a
                # drift of the machine's speed weighs on both sides of the ratio alike
                paired = interleaved({"mechsys": lambda: ms.simulate(m, T_END, integrator=integ), "mujoco": run_mj},
                                     repeat, budget=min(budget, 3.0))
                row["mechsys"], row["mujoco"] = paired["mechsys"][:2], paired["mujoco"][:2]
                state = paired["mujoco"][2]
                notes["interleaved"] = True
            md2 = mujoco.MjData(mm)
            mujoco.mj_setState(mm, md2, np.asarray(state)[0, -1], spec)
            assert abs(md2.time - T_END) < 1e-9, md2.time
            row["dq_mujoco"] = float(np.max(np.abs(md2.qpos - q_ms)))
            row["du_mujoco"] = float(np.max(np.abs(md2.qvel - u_ms)))
        if "exudyn" in peers and n <= exudyn_max_n:
            import exudyn as exu

            try:
                sc, mbs, node, s = exudyn_chain(n)

                def run_exu():
                    ok = mbs.SolveDynamic(s, solverType=exu.DynamicSolverType.RK44)
                    if not ok:
                        raise RuntimeError("Exudyn SolveDynamic failed")
                    return np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates)), np.array(
                        mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates_t)
                    )

                tmin, tmed, runs, (q_ex, u_ex) = whole_run(run_exu, repeat, budget)
                row["exudyn"] = (tmin, tmed)
                row["runs_exudyn"] = runs
                row["dq_exudyn"] = float(np.max(np.abs(q_ex - q_ms)))
                row["du_exudyn"] = float(np.max(np.abs(u_ex - u_ms)))
            except Exception as e:  # noqa: BLE001 - report and go on
                notes.setdefault("exudyn_errors", []).append(f"N={n}: {type(e).__name__}: {e}")
                log(f"  Exudyn failed at N={n}: {e}")
        log(
            f"  N={n:4d}  mechsys {cell(row['mechsys'])}"
            + (f"  mujoco {cell(row['mujoco'])} |dq|={row['dq_mujoco']:.1e}" if "mujoco" in row else "")
            + (f"  exudyn {cell(row['exudyn'])} |dq|={row['dq_exudyn']:.1e}" if "exudyn" in row else "")
        )
        rows.append(row)
    return rows, notes


def rust_core_times() -> dict:
    """Medians of the last `cargo bench -p mechsys-core --bench dynamics` (criterion's JSON), if any."""
    out: dict = {}
    base = ROOT / "target" / "criterion"
    for group in ("aba", "crba", "rnea", "step_rk4", "simulate_1s"):
        d = base / group
        if not d.is_dir():
            continue
        for sub in d.iterdir():
            f = sub / "new" / "estimates.json"
            if sub.name.isdigit() and f.is_file():
                est = json.loads(f.read_text())
                out[(group, int(sub.name))] = (est["median"]["point_estimate"] * 1e-9, f.stat().st_mtime)
    return out


# ---- report -------------------------------------------------------------------------------------------


def versions(peers: dict) -> dict:
    import numpy
    import mechsys

    v = {"mechsys": mechsys.__version__, "numpy": numpy.__version__}
    # which sources: the commit, and whether the working tree had changes (the results file aside)
    v["mechsys"] += f" (git {revision(ROOT, ROOT / 'docs' / 'benchmarks.md')})"
    # the timed extension must be built from the sources the Rust benchmark compiled
    so = Path(mechsys._core.__file__)
    newer = [f for f in (ROOT / "crates").rglob("src/**/*.rs") if f.stat().st_mtime > so.stat().st_mtime]
    if newer:
        v["mechsys"] += f", **extension older than {len(newer)} source file(s): run `make build` first**"
    for name, mod in peers.items():
        v[name] = getattr(mod, "__version__", "?")
    return v


def report(calls, sims, notes, peers, missing, mach, vers, rust, argv) -> str:
    L: list[str] = []
    now = _dt.datetime.now().strftime("%Y-%m-%d %H:%M")
    L.append(f"Measured {now} on {mach['nproc']} × {mach['cpu']} ({mach['os']}), Python {mach['python']}; "
             f"load average at start {mach['load'][0]:.2f} / {mach['load'][1]:.2f} / {mach['load'][2]:.2f}.")
    L.append("")
    L.append("Versions: " + ", ".join(f"{k} {v}" for k, v in vers.items()) + ".")
    for name, why in missing.items():
        L.append(f"Not measured: **{name}** ({why}).")
    L.append("")
    L.append("Command: `.venv/bin/python benches/peers.py " + " ".join(argv) + "`")
    L.append("")
    L.append("Cells: min (median) over the repeats; ratios use the minimum. Per-call timings: batches of "
             ">= 20 ms, one batch of each call per round, mechsys's and Pinocchio's taking turns.")
    L.append("")

    if calls:
        L.append("### Per call from Python: forward dynamics (ABA) and mass matrix (CRBA)")
        L.append("")
        has_pin = "pinocchio" in peers
        has_rust = any(k[0] == "aba" for k in rust)
        hdr = ["N", "mechsys ABA"]
        if has_rust:
            hdr.append("(Rust core)")
        if has_pin:
            hdr += ["Pinocchio aba", "mechsys vs Pinocchio"]
        hdr.append("mechsys CRBA")
        if has_rust:
            hdr.append("(Rust core)")
        if has_pin:
            hdr += ["Pinocchio crba", "mechsys vs Pinocchio"]
        hdr.append("check (rel. diff of q̈ / M)")
        L.append("| " + " | ".join(hdr) + " |")
        L.append("|" + "|".join("---:" for _ in hdr) + "|")
        for r in calls:
            n = r["n"]
            c = [str(n), cell(r["mechsys_aba"])]
            if has_rust:
                c.append(fmt_time(rust.get(("aba", n), (None,))[0]))
            if has_pin:
                c += [cell(r["pin_aba"]), ratio(r["mechsys_aba"][0], r["pin_aba"][0])]
            c.append(cell(r["mechsys_crba"]))
            if has_rust:
                c.append(fmt_time(rust.get(("crba", n), (None,))[0]))
            if has_pin:
                c += [cell(r["pin_crba"]), ratio(r["mechsys_crba"][0], r["pin_crba"][0])]
            checks = []
            if "check_aba_pin" in r:
                checks.append(f"pin {r['check_aba_pin']:.0e} / {r['check_crba_pin']:.0e}")
            if "check_aba_mujoco" in r:
                checks.append(f"MuJoCo q̈ {r['check_aba_mujoco']:.0e} (cond M {r['cond_M']:.0e})")
            c.append(("**MISMATCH** " if r.get("mismatch") else "") + ", ".join(checks))
            L.append("| " + " | ".join(c) + " |")
        L.append("")
        if has_rust:
            stamp = max(v[1] for v in rust.values())
            L.append("“Rust core”: criterion median of the same call inside Rust, from the last "
                     "`cargo bench -p mechsys-core --bench dynamics` "
                     f"({_dt.datetime.fromtimestamp(stamp).strftime('%Y-%m-%d %H:%M')}); the difference is the binding overhead.")
            L.append("")

    if sims:
        L.append("### Whole simulation: 1 s of the chain, RK4, dt = 1e-3, from Python until the results are in hand")
        L.append("")
        hdr = ["N", "mechsys `simulate`"]
        has_rust = any(k[0] == "simulate_1s" for k in rust)
        if has_rust:
            hdr.append("(Rust core)")
        if "mujoco" in peers:
            hdr += ["MuJoCo rollout", "mechsys vs MuJoCo", "Δq, Δu at 1 s (max abs)"]
        if "exudyn" in peers:
            hdr += ["Exudyn RK44", "mechsys vs Exudyn", "Δq, Δu at 1 s (max abs)"]
        L.append("| " + " | ".join(hdr) + " |")
        L.append("|" + "|".join("---:" for _ in hdr) + "|")
        for r in sims:
            n = r["n"]
            c = [str(n), sim_cell(r, "mechsys")]
            if has_rust:
                c.append(fmt_time(rust.get(("simulate_1s", n), (None,))[0]))
            if "mujoco" in peers:
                c += [sim_cell(r, "mujoco"), ratio(r["mechsys"][0], r.get("mujoco", (None,))[0]),
                      f"{r['dq_mujoco']:.0e}, {r['du_mujoco']:.0e}" if "dq_mujoco" in r else "–"]
            if "exudyn" in peers:
                c += [sim_cell(r, "exudyn"), ratio(r["mechsys"][0], r.get("exudyn", (None,))[0]),
                      f"{r['dq_exudyn']:.0e}, {r['du_exudyn']:.0e}" if "dq_exudyn" in r else "–"]
            L.append("| " + " | ".join(c) + " |")
        L.append("")
        L.append("mechsys records every step (1001 samples of q, u, u̇, body poses, velocities, accelerations, "
                 "energies, momenta; the `Results` name and unit them on first use, after the timing); MuJoCo returns its full physics state at each of the 1000 steps "
                 f"(loop: {notes.get('mujoco_loop', '–')}); Exudyn keeps only the final state "
                 "(no solution file, no sensors, no end-of-step accelerations)."
                 + (" Where both fit the budget, mechsys and MuJoCo were timed taking turns, one run of each per "
                    "round (`benchdoc.interleaved`): on a shared VM whose speed jumps between modes, a drift then "
                    "weighs on both sides of the ratio alike." if notes.get("interleaved") else ""))
        for e in notes.get("exudyn_errors", []):
            L.append(f"Exudyn error: {e}.")
        L.append("")

    if rust:
        groups = [g for g in ("crba", "rnea", "aba", "step_rk4", "simulate_1s") if any(k[0] == g for k in rust)]
        ns = sorted({k[1] for k in rust})
        stamp = max(v[1] for v in rust.values())
        L.append("### Rust core (criterion medians of the last `cargo bench -p mechsys-core --bench dynamics`, "
                 f"{_dt.datetime.fromtimestamp(stamp).strftime('%Y-%m-%d %H:%M')})")
        L.append("")
        L.append("| N | " + " | ".join(f"`{g}`" for g in groups) + " |")
        L.append("|---:|" + "|".join("---:" for _ in groups) + "|")
        for n in ns:
            L.append(f"| {n} | " + " | ".join(fmt_time(rust.get((g, n), (None,))[0]) for g in groups) + " |")
        L.append("")

    # targets
    L.append("### Against the targets")
    L.append("")
    if calls and "pinocchio" in peers:
        worst = max(calls, key=lambda r: r["mechsys_aba"][0] / r["pin_aba"][0])
        miss = [r for r in calls if r["mechsys_aba"][0] > r["pin_aba"][0]]
        if miss:
            L.append("- ABA per call from Python no slower than Pinocchio's at every N: **missed** at N = "
                     + ", ".join(f"{r['n']} ({r['mechsys_aba'][0] / r['pin_aba'][0]:.2f}× slower)" for r in miss) + ".")
        else:
            L.append(f"- ABA per call from Python no slower than Pinocchio's at every N: **met** "
                     f"(closest: N = {worst['n']}, {worst['pin_aba'][0] / worst['mechsys_aba'][0]:.2f}× faster).")
    if sims and "mujoco" in peers:
        with_mj = [r for r in sims if "mujoco" in r]
        miss = [r for r in with_mj if r["mujoco"][0] / r["mechsys"][0] < 2.0]
        if miss:
            L.append("- Whole simulation at least 2× faster than MuJoCo's RK4 rollout at every N: **missed** at N = "
                     + ", ".join(f"{r['n']} ({ratio(r['mechsys'][0], r['mujoco'][0]).strip('*')})" for r in miss) + ".")
        else:
            L.append("- Whole simulation at least 2× faster than MuJoCo's RK4 rollout at every N: **met** (min. "
                     f"{min(r['mujoco'][0] / r['mechsys'][0] for r in with_mj):.2f}×).")
    L.append("")
    return "\n".join(L)


BEGIN, END = "<!-- peers.py:begin (generated by benches/peers.py) -->", "<!-- peers.py:end -->"




def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sizes", default="1,4,16,64,256", help="chain sizes of the per-call timings")
    p.add_argument("--sim-sizes", default="1,4,16,64,256", help="chain sizes of the whole simulations")
    p.add_argument("--repeat", type=int, default=7, help="repeats of each timing (default 7)")
    p.add_argument("--budget", type=float, default=10.0, help="seconds per whole-simulation cell before reducing repeats")
    p.add_argument("--exudyn-max-n", type=int, default=256,
                   help="largest chain for Exudyn (its N = 256 run takes minutes; default 256)")
    p.add_argument("--skip", default="", help="comma-separated peers to leave out: pinocchio,mujoco,exudyn")
    p.add_argument("--no-calls", action="store_true", help="skip the per-call timings")
    p.add_argument("--no-sims", action="store_true", help="skip the whole simulations")
    p.add_argument("--quick", action="store_true", help="smoke run: 3 repeats, small budget")
    p.add_argument("--out", type=Path, help="write/update the generated section of this markdown file")
    a = p.parse_args(argv)
    if a.quick:
        a.repeat, a.budget = 3, 2.0

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    skip = {s.strip().lower() for s in a.skip.split(",") if s.strip()}
    peers: dict = {}
    missing: dict = {}
    for name, mod in (("pinocchio", "pinocchio"), ("mujoco", "mujoco"), ("exudyn", "exudyn")):
        if name in skip:
            continue
        try:
            peers[name] = __import__(mod)
            if name == "mujoco":
                __import__("mujoco.rollout")
        except ImportError as e:
            if name == "mujoco" and "mujoco" in sys.modules:
                peers[name] = sys.modules["mujoco"]
            else:
                missing[name] = f"not importable: {e}; install with `.venv/bin/python -m pip install pin mujoco exudyn`"
                log(f"{name}: {missing[name]}")

    mach = machine()
    vers = versions(peers)
    log(f"{mach['nproc']} × {mach['cpu']}, load {mach['load'][0]:.2f}; " + ", ".join(f"{k} {v}" for k, v in vers.items()))
    calls = sims = None
    notes: dict = {}
    if not a.no_calls:
        log("per call from Python:")
        calls = measure_calls([int(x) for x in a.sizes.split(",")], a.repeat, peers, log)
    if not a.no_sims:
        log("whole simulations (1 s, RK4, dt = 1e-3):")
        sims, notes = measure_sims([int(x) for x in a.sim_sizes.split(",")], a.repeat, a.budget, peers, log, a.exudyn_max_n)
    text = report(calls, sims, notes, peers, missing, mach, vers, rust_core_times(), argv)
    print(text)
    if a.out:
        write_doc(a.out if a.out.is_absolute() else Path.cwd() / a.out, text, BEGIN, END, "## Peers (Python)")
        log(f"updated {a.out}")
    return 1 if calls and any(r.get("mismatch") for r in calls) else 0


if __name__ == "__main__":
    sys.exit(main())
