"""A stack of 10 boxes and a pyramid of 20 at rest (issues 4, 17): mechsys (Moreau-Jean with NSGS
and with the automatic solver choice) against MuJoCo and PyBullet (stack only) in the same run.

Model, identical in every engine: ten equal boxes (0.2 x 0.2 x 0.1 m, 1 kg, inertia of the solid
box) stacked face on face on a plane, exactly touching at t = 0 and at rest, gravity 9.81 m/s^2,
Coulomb friction 0.5 everywhere (PyBullet multiplies the two bodies' coefficients: the floor gets
1), no restitution. Each engine runs T simulated seconds (default 2) at dt = 1e-3 and 1e-2.

Measured per run:
- wall time per simulated second, from the Python call until the run is done, model built
  beforehand; min (median) over repeats. mechsys auto (both recordings) and MuJoCo take turns
  (`benchdoc.interleaved`: one run of each per round, for at least 3 s), so that a drift of the
  machine's speed weighs on both sides alike. mechsys: one `ms.simulate` call (it records its signals
  every 10 ms: all of them, and in a second run with `solver="auto"` only the bodies' states and
  the solver's signals, what the rollout returns); MuJoCo: `mujoco.rollout.rollout` (its C loop) from the initial state; PyBullet: a
  Python loop of `stepSimulation` (it has no batch call; the loop costs < 1 us per step);
- largest penetration over the run: mechsys from its gap signals at every step (a separate run
  recording every step, not timed), MuJoCo from `-min(contact.dist)` after every step, PyBullet
  from `-min(contactDistance)` of `getContactPoints` after every step (separate, untimed runs);
- drift of the top box: |r_top(T) - r_top(0)| (includes the initial settling of compliant
  contacts) and |r_top(T) - r_top(T - 1 s)| (creep of the settled stack).

Settings: mechsys `MoreauJean(dt)` with the default `NSGS()` (tol 1e-10, 10^4 sweeps), a tight
`NSGS(tol=1e-12, max_iter=10^5)` (stack only) and `Auto()` (`solver="auto"`: regularized semismooth
Newton on problems up to 480 unknowns, tol 1e-10) and `APGD()` (accelerated projected gradient, tol 1e-10); box-box contacts are the separating-axis manifold (up to 8 points
per pair, 4 closed for a face-on-face stack). MuJoCo 3.x/4.x defaults (soft contacts, solref 0.02 1,
pyramidal cone, Newton solver, Euler integrator), box-box collision by its own routine. PyBullet
defaults (sequential impulses, 50 iterations, split impulse / ERP position correction).

Usage: ``.venv/bin/python benches/stack.py [--out docs/benchmarks.md] [--t-end 2] [--repeat 3] [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchdoc import fmt_time, interleaved, machine, ratio, timed, write_doc  # noqa: E402

G, N, MASS, MU = 9.81, 10, 1.0, 0.5
HALF = (0.1, 0.1, 0.05)
#: the pyramid's rows, bottom first (20 boxes), and the gap between neighbours in a row (m)
PYRAMID_ROWS, PYRAMID_GAP = (6, 5, 4, 3, 2), 0.01


def z0(k: int) -> float:
    return HALF[2] * (2 * k + 1)


def scene(kind: str):
    """Box centres and the contacts (upper box, lower box or None for the floor) of a scene:
    ``stack`` (ten boxes face on face) or ``pyramid`` (rows of 6, 5, 4, 3, 2 boxes, each upper box
    straddling the two below it, half on each)."""
    if kind == "stack":
        return [(0.0, 0.0, z0(k)) for k in range(N)], [(0, None)] + [(k, k - 1) for k in range(1, N)]
    centres, contacts, rows = [], [], []
    pitch = 2 * HALF[0] + PYRAMID_GAP
    for r, count in enumerate(PYRAMID_ROWS):
        row = []
        for i in range(count):
            row.append(len(centres))
            centres.append(((i - (count - 1) / 2) * pitch, 0.0, z0(r)))
            if r == 0:
                contacts.append((row[-1], None))
            else:
                contacts += [(row[-1], rows[-1][i]), (row[-1], rows[-1][i + 1])]
        rows.append(row)
    return centres, contacts




def drifts(top: np.ndarray, t: np.ndarray, t_end: float) -> tuple[float, float]:
    """|r(T) - r(0)| and |r(T) - r(T - 1)| of the top box (positions sampled at times t)."""
    k1 = int(np.argmin(np.abs(t - (t_end - 1.0))))
    return float(np.linalg.norm(top[-1] - top[0])), float(np.linalg.norm(top[-1] - top[k1]))


# ---- mechsys ------------------------------------------------------------------------------------------
def ms_model(kind="stack"):
    import mechsys as ms

    centres, pairs = scene(kind)
    m = ms.Model(f"{kind}{len(centres)}", gravity=(0.0, 0.0, -G))
    boxes = []
    for k, c in enumerate(centres):
        b = m.add_body(f"box{k}", MASS, ms.inertia.box(MASS, tuple(2 * h for h in HALF)))
        m.add_joint(ms.joints.Free(f"free{k}", m.ground, b, q0=[*c, 1, 0, 0, 0]))
        boxes.append(b)
    shape = ms.contours.Box(half_extents=HALF)
    floor = m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))
    for up, low in pairs:
        name = f"floor{up}" if low is None else f"on{up}_{low}"
        m.add_contact(ms.Contact(name, boxes[up].contour(shape), floor if low is None else boxes[low].contour(shape),
                                 friction=ms.laws.Coulomb(MU)))
    m.build()
    return m


#: mechsys solver settings of the table: label -> solver
def ms_solvers():
    import mechsys as ms

    return {"NSGS default": ms.NSGS(), "NSGS tol 1e-12, 10^5 sweeps": ms.NSGS(tol=1e-12, max_iter=100_000),
            "auto (tol 1e-10)": ms.Auto(), "APGD (tol 1e-10)": ms.APGD()}


#: what MuJoCo's rollout returns, as mechsys signals: the bodies' states (and the solver's report)
STATES = ["body/*/position", "body/*/orientation", "body/*/velocity", "body/*/angular_velocity", "solver/*"]


def run_ms(model, dt, t_end, solver, output_dt=1e-2, sensors=None):
    import mechsys as ms

    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        res = ms.simulate(model, t_end, ms.MoreauJean(dt, solver=solver), output_dt=output_dt, sensors=sensors)
    note = next((str(x.message) for x in w if "tolerance" in str(x.message)), "")
    return res, note


def ms_measure(model, dt, t_end, solver, kind):
    res, note = run_ms(model, dt, t_end, solver, output_dt=dt)
    names = [c for c in res.names() if c.startswith("contact/") and c.endswith("/g_n")]
    gmin = min(float(res[c].min()) for c in names)
    top = res[f"body/box{len(scene(kind)[0]) - 1}/position"]
    floor = sum(float(res[c][-1].sum()) for c in res.names() if c.startswith("contact/floor") and c.endswith("/lambda_n"))
    floor /= len(scene(kind)[0]) * MASS * G
    conv = res["solver/converged"][1:]
    unconverged = f"{int((conv == 0).sum())} of {conv.size} steps"
    worst = float(res["solver/residual"].max())
    return max(0.0, -gmin), drifts(top, res.t, t_end), floor, unconverged, worst


# ---- MuJoCo -------------------------------------------------------------------------------------------
def mj_xml(dt, kind="stack"):
    centres, _ = scene(kind)
    bodies = "".join(
        f'<body pos="{c[0]} {c[1]} {c[2]}"><freejoint/><geom type="box" size="{HALF[0]} {HALF[1]} {HALF[2]}" mass="{MASS}" '
        f'friction="{MU} 0.005 0.0001"/></body>' for c in centres)
    return (f'<mujoco><option timestep="{dt}" gravity="0 0 {-G}"/><worldbody>'
            f'<geom type="plane" size="5 5 0.1" friction="{MU} 0.005 0.0001"/>{bodies}</worldbody></mujoco>')


def mj_setup(dt, kind="stack"):
    import mujoco

    m = mujoco.MjModel.from_xml_string(mj_xml(dt, kind))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    x0 = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, x0, spec)
    return m, d, x0, spec


def run_mj(setup, dt, t_end):
    from mujoco import rollout

    m, d, x0, _ = setup
    state, _ = rollout.rollout(m, d, x0, nstep=int(round(t_end / dt)))
    return state


def mj_measure(setup, dt, t_end):
    import mujoco

    m, _, x0, spec = setup
    top_k = m.nbody - 2
    d = mujoco.MjData(m)
    mujoco.mj_setState(m, d, x0, spec)
    mujoco.mj_forward(m, d)
    n = int(round(t_end / dt))
    top = np.empty((n + 1, 3))
    top[0] = d.qpos[7 * top_k: 7 * top_k + 3]
    pen = 0.0
    for k in range(n):
        mujoco.mj_step(m, d)
        if d.ncon:
            pen = max(pen, -float(d.contact.dist[: d.ncon].min()))
        top[k + 1] = d.qpos[7 * top_k: 7 * top_k + 3]
    return pen, drifts(top, np.arange(n + 1) * dt, t_end)


# ---- PyBullet -----------------------------------------------------------------------------------------
def pb_world(dt):
    import pybullet as p

    cid = p.connect(p.DIRECT)
    p.setGravity(0, 0, -G, physicsClientId=cid)
    p.setTimeStep(dt, physicsClientId=cid)
    plane = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=cid), physicsClientId=cid)
    p.changeDynamics(plane, -1, lateralFriction=1.0, restitution=0.0, physicsClientId=cid)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=HALF, physicsClientId=cid)
    boxes = []
    for k in range(N):
        b = p.createMultiBody(MASS, shape, basePosition=[0, 0, z0(k)], physicsClientId=cid)
        p.changeDynamics(b, -1, lateralFriction=math.sqrt(MU), restitution=0.0, linearDamping=0.0, angularDamping=0.0,
                         physicsClientId=cid)
        boxes.append(b)
    return p, cid, boxes


def run_pb(dt, t_end, measure=False):
    p, cid, boxes = pb_world(dt)
    try:
        n = int(round(t_end / dt))
        top = np.empty((n + 1, 3))
        top[0] = p.getBasePositionAndOrientation(boxes[-1], physicsClientId=cid)[0]
        pen = 0.0
        for k in range(n):
            p.stepSimulation(physicsClientId=cid)
            if measure:
                pts = p.getContactPoints(physicsClientId=cid)
                if pts:
                    pen = max(pen, -min(c[8] for c in pts))
                top[k + 1] = p.getBasePositionAndOrientation(boxes[-1], physicsClientId=cid)[0]
        if not measure:
            top[-1] = p.getBasePositionAndOrientation(boxes[-1], physicsClientId=cid)[0]
        return pen, drifts(top, np.arange(n + 1) * dt, t_end)
    finally:
        p.disconnect(physicsClientId=cid)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, help="write the results section into this markdown file")
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one repeat, 1e-3 only")
    a = ap.parse_args(argv)
    repeat = 1 if a.quick else a.repeat
    T = a.t_end
    warnings.simplefilter("ignore")
    mach = machine()
    t_start = time.perf_counter()
    rows = []  # (scene, dt, engine, tmin, tmed, pen, (drift_all, drift_last), extra)
    for kind in ("stack", "pyramid"):
        model = ms_model(kind)
        nb = len(scene(kind)[0])
        for dt in ([1e-3] if a.quick else [1e-3, 1e-2]):
            # the headline comparison, side by side: mechsys auto (every signal, and the bodies'
            # states only) and MuJoCo's rollout take turns (see benchdoc.interleaved)
            auto = ms_solvers()["auto (tol 1e-10)"]
            side = {"auto": lambda: run_ms(model, dt, T, auto),
                    "states": lambda: run_ms(model, dt, T, auto, sensors=STATES)}
            try:
                setup = mj_setup(dt, kind)
                side["mujoco"] = lambda: run_mj(setup, dt, T)
            except Exception as e:  # noqa: BLE001 - a missing peer is reported, not fatal
                setup = None
                print(f"MuJoCo: {e}")
            paired = interleaved(side, repeat, budget=0.0 if a.quick else 3.0)
            for label, solver in ms_solvers().items():
                if kind == "pyramid" and label.startswith("NSGS tol"):
                    continue  # 10^5 sweeps per step on the pyramid's 136 points: minutes per run
                if label.startswith("auto"):
                    tmin, tmed, _ = paired["auto"]
                else:
                    tmin, tmed, _ = timed(lambda: run_ms(model, dt, T, solver), repeat)
                pen, dr, floor, unconv, worst = ms_measure(model, dt, T, solver, kind)
                extra = (f"worst residual {worst:.1e}, unconverged {unconv}; the floor carries {floor:.10f} × {nb} m g")
                rows.append((kind, dt, f"mechsys MoreauJean, {label}", tmin, tmed, pen, dr, extra))
                print(f"{kind} dt {dt:g} {label:32s} {fmt_time(tmin / T)}/s  pen {pen:.1e}  drift {dr[0]:.1e} / {dr[1]:.1e}  {extra}")
                if label.startswith("auto"):
                    # the same run recording what the rollout returns: no contact-point signals, so
                    # no contact kinematics at the samples (the motion is the same bit for bit)
                    tmin, tmed, _ = paired["states"]
                    rows.append((kind, dt, "mechsys MoreauJean, auto, states only", tmin, tmed, pen, dr,
                                 "`sensors=` the bodies' states and `solver/*` (what MuJoCo's rollout returns); "
                                 "the same motion as the row above"))
                    print(f"{kind} dt {dt:g} {'auto, states only':32s} {fmt_time(tmin / T)}/s")
            if setup is not None:
                tmin, tmed, _ = paired["mujoco"]
                pen, dr = mj_measure(setup, dt, T)
                rows.append((kind, dt, "MuJoCo (defaults, rollout)", tmin, tmed, pen, dr, ""))
                print(f"{kind} dt {dt:g} {'MuJoCo':32s} {fmt_time(tmin / T)}/s  pen {pen:.1e}  drift {dr[0]:.1e} / {dr[1]:.1e}")
            if kind == "stack":
                try:
                    tmin, tmed, _ = timed(lambda: run_pb(dt, T), repeat)
                    pen, dr = run_pb(dt, T, measure=True)
                    rows.append((kind, dt, "PyBullet (defaults)", tmin, tmed, pen, dr, ""))
                    print(f"{kind} dt {dt:g} {'PyBullet':32s} {fmt_time(tmin / T)}/s  pen {pen:.1e}  drift {dr[0]:.1e} / {dr[1]:.1e}")
                except Exception as e:  # noqa: BLE001
                    print(f"PyBullet: {e}")
    whole = time.perf_counter() - t_start
    load_end = machine()["load"]
    if a.out:
        try:
            import mechsys
            import mujoco

            versions = f"mechsys {getattr(mechsys, '__version__', '?')}, MuJoCo {mujoco.__version__}"
        except Exception:  # noqa: BLE001
            versions = "–"
        L = ["## Stack of 10 boxes and pyramid of 20 at rest (issues 4, 17): mechsys against MuJoCo and PyBullet", ""]
        L.append(f"Generated by `benches/stack.py` (this section only). {time.strftime('%Y-%m-%d %H:%M')} on "
                 f"{mach['nproc']} × {mach['cpu']}; load average {mach['load'][0]:.2f} at the start, "
                 f"{load_end[0]:.2f} at the end (a shared 2-core machine: above ≈ 1 the times are preliminary); "
                 f"whole run {whole:.0f} s. {versions}.")
        L += ["", f"Boxes 0.2 × 0.2 × 0.1 m, 1 kg, face on face, touching and at rest at t = 0, friction 0.5, {T:g} s "
              "simulated. *stack*: ten boxes in a column; *pyramid*: rows of 6, 5, 4, 3, 2 boxes 1 cm apart, each upper "
              "box straddling the two below it (34 box-box or box-floor pairs, 136 closed points). Settings and fairness "
              f"notes in the script's docstring. Wall time per simulated second: min (median) over {repeat} run(s); the "
              "three rows of the headline comparison (auto, auto states only, MuJoCo) taken in turns, one run of each "
              f"per round, {repeat} rounds and more for 3 s (a shared VM's speed jumps between modes); "
              "“mechsys auto vs it”: mechsys with `solver=\"auto\"` against that row at the same step (recording "
              "every signal, and in the MuJoCo rows also recording only the bodies' states, as the rollout does).", "",
              f"Command: `.venv/bin/python benches/stack.py {' '.join(sys.argv[1:] if argv is None else argv)}`", "",
              "| scene | dt | engine | wall time per simulated second | mechsys auto vs it | largest penetration | top box drift, 0 → T | top box drift over the last 1 s | notes |",
              "|---|---:|---|---:|---:|---:|---:|---:|---|"]
        for kind, dt, engine, tmin, tmed, pen, dr, extra in rows:
            ref = next((r[3] for r in rows if r[0] == kind and r[1] == dt and "auto" in r[2]), None)
            cell = ratio(ref / T, tmin / T) if ref is not None and "auto" not in engine else "–"
            if "MuJoCo" in engine:
                # and the run recording what the rollout returns, against it
                lean = next((r[3] for r in rows if r[0] == kind and r[1] == dt and "states only" in r[2]), None)
                if lean is not None:
                    cell += f"; states only: {ratio(lean / T, tmin / T)}"
            L.append(f"| {kind} | {dt:g} | {engine} | {fmt_time(tmin / T)} ({fmt_time(tmed / T)}) | {cell} | "
                     f"{pen:.1e} m | {dr[0]:.1e} m | {dr[1]:.1e} m | {extra} |")
        L += ["", "Reading the table:", "",
              "- *Drift 0 → T* includes the settling at the start: compliant contacts (MuJoCo's soft constraints, "
              "PyBullet's position correction) sink in under the load until they carry it; mechsys' contacts are rigid "
              "(Signorini at velocity level), so any drift is solver error. *Drift over the last 1 s* is the creep of "
              "the settled stack. The worst residual is `solver/residual` over every step.",
              "- The stack's and the pyramid's friction-contact problems are singular (four points per interface, "
              "statically indeterminate), and ten bodies in series make Gauss-Seidel slow from a cold start: NSGS misses "
              "its tolerance in the first steps. `solver=\"auto\"` takes the semismooth Newton method on these sizes, "
              "with the Delassus matrix regularized in the direction (ε = 1e-4 W_NN, three refinement passes against "
              "the exact Jacobian): the cold first step takes tens of iterations, the resting steps 0 or 1, each a "
              "solve with the factorization of the last step (it is reused while the projection derivatives, i.e. "
              "the stick/slip/open pattern, do not change).",
              "- Where the time goes (callgrind instruction counts, stack at dt = 1e-2, auto, recorded at every step, "
              "about 490 k instructions a step; 40 active points, 120 unknowns): the contact solve 22 % (the warm "
              "steps finish in one or two sweeps; the cold first step and a few others take Newton with its "
              "factorization: 7 % of the run, the first step 5 %), contact kinematics with the box-box manifold "
              "19 % (at the step's midpoint, and again at each sample for the records: 10 %, skipped by `sensors=` "
              "without contact signals), the sparse Delassus rows and their reduction (`SparseRows::add_contact`, "
              "straight-line arithmetic of the free bodies' 6 × 6 blocks) 10 %, the diagonal blocks and couplings "
              "4 %, the tree kinematics, mass-matrix factor and solves ≈ 12 %, the records ≈ 13 %. The profile LU "
              "of the Newton steps searches pivots, exchanges rows and eliminates only within the band of rows "
              "that reach each column (1.49 M → 1.17 M instructions for the cold step's three factorizations); "
              "the records take each contact's static friction coefficient once per sample (was twice per point: "
              "1 % of the run). On the "
              "pyramid (408 unknowns) the first step alone took 31 % of the run while Auto solved it by Newton "
              "(seven profile LU factorizations); it now takes 86 Anderson-accelerated sweeps (see docs/usage.md).",
              "- APGD (`solver=\"apgd\"`) needs hundreds of gradient steps from a cold start and 0 or 1 at rest "
              "(the warm start from the last step's impulses per contact point already meets the tolerance)."]
        write_doc(a.out, "\n".join(L), "<!-- stack.py:begin -->", "<!-- stack.py:end -->")
        print(f"updated {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
