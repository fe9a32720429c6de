"""A stack of 10 boxes at rest (issue 4): mechsys (Moreau-Jean, NSGS) against MuJoCo and PyBullet
in the same run.

Model, identical in every engine: ten equal boxes (0.2 x 0.2 x 0.1 m, 1 kg, inertia of the solid
box) stacked face on face on a plane, exactly touching at t = 0 and at rest, gravity 9.81 m/s^2,
Coulomb friction 0.5 everywhere (PyBullet multiplies the two bodies' coefficients: the floor gets
1), no restitution. Each engine runs T simulated seconds (default 2) at dt = 1e-3 and 1e-2.

Measured per run:
- wall time per simulated second, from the Python call until the run is done, model built
  beforehand; min (median) over repeats. mechsys: one `ms.simulate` call (it records its signals
  every 10 ms); MuJoCo: `mujoco.rollout.rollout` (its C loop) from the initial state; PyBullet: a
  Python loop of `stepSimulation` (it has no batch call; the loop costs < 1 us per step);
- largest penetration over the run: mechsys from its gap signals at every step (a separate run
  recording every step, not timed), MuJoCo from `-min(contact.dist)` after every step, PyBullet
  from `-min(contactDistance)` of `getContactPoints` after every step (separate, untimed runs);
- drift of the top box: |r_top(T) - r_top(0)| (includes the initial settling of compliant
  contacts) and |r_top(T) - r_top(T - 1 s)| (creep of the settled stack).

Settings: mechsys `MoreauJean(dt)` with the default `NSGS()` (tol 1e-10, 10^4 sweeps) and a tight
`NSGS(tol=1e-12, max_iter=10^5)`; box-box contacts are the separating-axis manifold (up to 8 points
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
from benchdoc import fmt_time, machine, ratio, timed, write_doc  # noqa: E402

G, N, MASS, MU = 9.81, 10, 1.0, 0.5
HALF = (0.1, 0.1, 0.05)


def z0(k: int) -> float:
    return HALF[2] * (2 * k + 1)




def drifts(top: np.ndarray, t: np.ndarray, t_end: float) -> tuple[float, float]:
    """|r(T) - r(0)| and |r(T) - r(T - 1)| of the top box (positions sampled at times t)."""
    k1 = int(np.argmin(np.abs(t - (t_end - 1.0))))
    return float(np.linalg.norm(top[-1] - top[0])), float(np.linalg.norm(top[-1] - top[k1]))


# ---- mechsys ------------------------------------------------------------------------------------------
def ms_model():
    import mechsys as ms

    m = ms.Model("stack10", gravity=(0.0, 0.0, -G))
    boxes = []
    for k in range(N):
        b = m.add_body(f"box{k}", MASS, ms.inertia.box(MASS, tuple(2 * h for h in HALF)))
        m.add_joint(ms.joints.Free(f"free{k}", m.ground, b, q0=[0, 0, z0(k), 1, 0, 0, 0]))
        boxes.append(b)
    shape = ms.contours.Box(half_extents=HALF)
    m.add_contact(ms.Contact("floor", boxes[0].contour(shape), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(MU)))
    for k in range(1, N):
        m.add_contact(ms.Contact(f"on{k}", boxes[k].contour(shape), boxes[k - 1].contour(shape), friction=ms.laws.Coulomb(MU)))
    m.build()
    return m


def ms_solver(tight: bool):
    import mechsys as ms

    return ms.NSGS(tol=1e-12, max_iter=100_000) if tight else ms.NSGS()


def run_ms(model, dt, t_end, tight, output_dt=1e-2):
    import mechsys as ms

    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        res = ms.simulate(model, t_end, ms.MoreauJean(dt, solver=ms_solver(tight)), output_dt=output_dt)
    note = next((str(x.message) for x in w if "tolerance" in str(x.message)), "")
    return res, note


def ms_measure(model, dt, t_end, tight):
    res, note = run_ms(model, dt, t_end, tight, output_dt=dt)
    names = ["floor"] + [f"on{k}" for k in range(1, N)]
    gmin = min(float(res[f"contact/{c}/g_n"].min()) for c in names)
    top = res[f"body/box{N - 1}/position"]
    floor = float(res["contact/floor/lambda_n"][-1].sum()) / (N * MASS * G)
    unconverged = note.split("tolerance in ")[1].split(" steps")[0] + " steps" if note else "0"
    return max(0.0, -gmin), drifts(top, res.t, t_end), floor, unconverged


# ---- MuJoCo -------------------------------------------------------------------------------------------
def mj_xml(dt):
    bodies = "".join(
        f'<body pos="0 0 {z0(k)}"><freejoint/><geom type="box" size="{HALF[0]} {HALF[1]} {HALF[2]}" mass="{MASS}" '
        f'friction="{MU} 0.005 0.0001"/></body>' for k in range(N))
    return (f'<mujoco><option timestep="{dt}" gravity="0 0 {-G}"/><worldbody>'
            f'<geom type="plane" size="5 5 0.1" friction="{MU} 0.005 0.0001"/>{bodies}</worldbody></mujoco>')


def mj_setup(dt):
    import mujoco

    m = mujoco.MjModel.from_xml_string(mj_xml(dt))
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
    d = mujoco.MjData(m)
    mujoco.mj_setState(m, d, x0, spec)
    mujoco.mj_forward(m, d)
    n = int(round(t_end / dt))
    top = np.empty((n + 1, 3))
    top[0] = d.qpos[7 * (N - 1): 7 * (N - 1) + 3]
    pen = 0.0
    for k in range(n):
        mujoco.mj_step(m, d)
        if d.ncon:
            pen = max(pen, -float(d.contact.dist[: d.ncon].min()))
        top[k + 1] = d.qpos[7 * (N - 1): 7 * (N - 1) + 3]
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
    model = ms_model()
    rows = []  # (dt, engine, tmin, tmed, pen, (drift_all, drift_last), extra)
    for dt in ([1e-3] if a.quick else [1e-3, 1e-2]):
        for tight in (False, True):
            label = "mechsys MoreauJean, NSGS tol 1e-12, 10^5 sweeps" if tight else "mechsys MoreauJean, NSGS default"
            tmin, tmed, _ = timed(lambda: run_ms(model, dt, T, tight), repeat)
            pen, dr, floor, unconv = ms_measure(model, dt, T, tight)
            rows.append((dt, label, tmin, tmed, pen, dr, f"floor carries {floor:.10f} × 10 m g; solver missed its tolerance in {unconv}"))
            print(f"dt {dt:g} {label:50s} {fmt_time(tmin / T)}/s  pen {pen:.1e}  drift {dr[0]:.1e} / {dr[1]:.1e}  {rows[-1][-1]}")
        try:
            setup = mj_setup(dt)
            tmin, tmed, _ = timed(lambda: run_mj(setup, dt, T), repeat)
            pen, dr = mj_measure(setup, dt, T)
            rows.append((dt, "MuJoCo (defaults, rollout)", tmin, tmed, pen, dr, ""))
            print(f"dt {dt:g} {'MuJoCo':50s} {fmt_time(tmin / T)}/s  pen {pen:.1e}  drift {dr[0]:.1e} / {dr[1]:.1e}")
        except Exception as e:  # noqa: BLE001 - a missing peer is reported, not fatal
            print(f"MuJoCo: {e}")
        try:
            tmin, tmed, _ = timed(lambda: run_pb(dt, T), repeat)
            pen, dr = run_pb(dt, T, measure=True)
            rows.append((dt, "PyBullet (defaults)", tmin, tmed, pen, dr, ""))
            print(f"dt {dt:g} {'PyBullet':50s} {fmt_time(tmin / T)}/s  pen {pen:.1e}  drift {dr[0]:.1e} / {dr[1]:.1e}")
        except Exception as e:  # noqa: BLE001
            print(f"PyBullet: {e}")
    whole = time.perf_counter() - t_start
    load_end = machine()["load"]
    if a.out:
        try:
            import mechsys
            import mujoco
            import pybullet  # noqa: F401

            versions = f"mechsys {getattr(mechsys, '__version__', '?')}, MuJoCo {mujoco.__version__}, PyBullet (API {pybullet.getAPIVersion()})"
        except Exception:  # noqa: BLE001
            versions = "–"
        L = ["## Stack of 10 boxes at rest (issue 4): mechsys against MuJoCo and PyBullet", ""]
        L.append(f"Generated by `benches/stack.py` (this section only). {time.strftime('%Y-%m-%d %H:%M')} on "
                 f"{mach['nproc']} × {mach['cpu']}; load average {mach['load'][0]:.2f} at the start, "
                 f"{load_end[0]:.2f} at the end (a shared 2-core machine: above ≈ 1 the times are preliminary); "
                 f"whole run {whole:.0f} s. {versions}.")
        L += ["", f"Ten boxes 0.2 × 0.2 × 0.1 m, 1 kg, face on face on the floor, touching and at rest at t = 0, "
              f"friction 0.5, {T:g} s simulated. Settings and fairness notes in the script's docstring. Wall time "
              f"per simulated second: min (median) over {repeat} run(s); “mechsys vs it”: against mechsys with that "
              "solver setting at the same step.", "",
              f"Command: `.venv/bin/python benches/stack.py {' '.join(sys.argv[1:] if argv is None else argv)}`", "",
              "| dt | engine | wall time per simulated second | mechsys (default NSGS) vs it | mechsys (tight NSGS) vs it | largest penetration | top box drift, 0 → T | top box drift over the last 1 s | notes |",
              "|---:|---|---:|---:|---:|---:|---:|---:|---|"]
        for dt, engine, tmin, tmed, pen, dr, extra in rows:
            cells = []
            for suffix in ("NSGS default", "10^5 sweeps"):
                ref = next((r[2] for r in rows if r[0] == dt and r[1].endswith(suffix)), None)
                cells.append(ratio(ref / T, tmin / T) if ref is not None and not engine.startswith("mechsys") else "–")
            L.append(f"| {dt:g} | {engine} | {fmt_time(tmin / T)} ({fmt_time(tmed / T)}) | {cells[0]} | {cells[1]} | "
                     f"{pen:.1e} m | {dr[0]:.1e} m | {dr[1]:.1e} m | {extra} |")
        L += ["", "Reading the table:", "",
              "- *Drift 0 → T* includes the settling at the start: compliant contacts (MuJoCo's soft constraints, "
              "PyBullet's position correction) sink in under the load until they carry it; mechsys' contacts are rigid "
              "(Signorini at velocity level), so any drift is solver error. *Drift over the last 1 s* is the creep of "
              "the settled stack.",
              "- mechsys' default NSGS (tol 1e-10, at most 10^4 sweeps) misses its tolerance in a few of the first "
              "steps, started cold: the stack's friction-contact problem (four points per interface, ten bodies in "
              "series) converges slowly; what it leaves in the velocities stays in the positions (no position "
              "correction in Moreau-Jean). With tol 1e-12 and up to 10^5 sweeps every step converges and the stack "
              "holds to rounding, and the warm-started steps are then cheaper, so the whole run is not slower.",
              "- Where mechsys' time goes (`perf` on the tight run at dt = 1e-3, 2026-11-22): ≈ 70 % of the engine's "
              "samples in the contact problem (Delassus products and NSGS sweeps over the 44 closed points, 132 rows), "
              "≈ 15 % in the box-box narrow phase, which then rebuilt the separating-axis manifold for each of a pair's 8 "
              "candidates (≈ 8 µs per pair and step). Since issue 12 one manifold serves all 8: `contact_kinematics` "
              "0.80-0.86 µs per pair (4.7-5.2 before), `evaluate` 0.49-0.53 µs (criterion, 100 tilted moving pairs: "
              "`cargo bench -p mechsys-core --bench contact -- box_box`)."]
        write_doc(a.out, "\n".join(L), "<!-- stack.py:begin -->", "<!-- stack.py:end -->")
        print(f"updated {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
