"""Contact benchmarks of issue 4 (first part): mechsys (Moreau-Jean time-stepping) against MuJoCo and
PyBullet in the same run, on problems with closed-form answers.

1. Bouncing ball: a sphere (r = 0.1 m, 1 kg) dropped from 1 m onto a plane with restitution 0.8;
   error of the first three apex heights against h0 eps^(2k), largest penetration, wall time for
   3 s. MuJoCo has no restitution coefficient: its contact is a damped spring set by solref;
   the time constant and damping ratio that give eps = 0.8 for a linear spring-damper are used
   (zeta = -ln(eps) / sqrt(pi^2 + ln(eps)^2), with a 2 ms time constant). PyBullet: restitution 0.8
   on the ball and 1 on the plane (Bullet multiplies the two; likewise friction below).
2. Block that must stick: a box (0.2 x 0.1 x 0.1 m, 2 kg) on an incline of 0.3 rad with static
   friction 0.4 > tan(0.3) = 0.309, released at rest; creep (displacement) after 2 s, wall time.
   Gravity is tilted instead of the plane, the same in every engine.

Penetration: mechsys' is read from its gap signal at the 1 ms samples (penetration inside a
step is not seen there); the peers' at every step. Steps: the ball at dt = 1e-4 (mechsys also at 1e-3), except PyBullet at 1e-3: at 1e-4 its
restitution does not act at all (the ball stays on the floor after the first impact); the block at
dt = 1e-3 everywhere. Times: the whole simulation from Python with the model built
beforehand, min (median) over repeats.

Not yet here (issue 4): 100 and 1000 spheres poured into a box and a stack of boxes (mechsys needs
contact groups from its broad phase and box-box contours first).

Usage: ``.venv/bin/python benches/contacts.py [--out docs/benchmarks.md] [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchdoc import fmt_time, machine, ratio, write_doc  # noqa: E402

G, R, H0, EPS = 9.81, 0.1, 1.0, 0.8
ALPHA, MU0, MU = 0.3, 0.4, 0.3
HALF = (0.1, 0.05, 0.05)


def timed(fn, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), statistics.median(times), out


def apexes(t, z, n=3):
    k = [i for i in range(1, len(z) - 1) if z[i] > z[i - 1] and z[i] >= z[i + 1] and z[i] > 1e-3]
    return np.array([z[i] for i in k[:n]])


# ---- mechsys ------------------------------------------------------------------------------------------
def ms_ball():
    import mechsys as ms

    m = ms.Model("ball", gravity=(0, 0, -G))
    b = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, R))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, H0 + R, 1, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=R)), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             impact=ms.laws.Newton(EPS)))
    m.build()
    return m


def ms_block():
    import mechsys as ms

    m = ms.Model("block", gravity=(G * math.sin(ALPHA), 0, -G * math.cos(ALPHA)))
    b = m.add_body("block", 2.0, ms.inertia.box(2.0, tuple(2 * h for h in HALF)))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, HALF[2], 1, 0, 0, 0]))
    m.add_contact(ms.Contact("base", b.contour(ms.contours.Box(half_extents=HALF)), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(MU, MU0)))
    m.build()
    return m


def run_ms_ball(model, dt):
    import mechsys as ms

    res = ms.simulate(model, 3.0, ms.MoreauJean(dt), output_dt=1e-3)
    z = res["body/ball/position"][:, 2] - R
    return res.t, z, max(0.0, -res["contact/floor/g_n"].min())


def run_ms_block(model, dt):
    import mechsys as ms

    res = ms.simulate(model, 2.0, ms.MoreauJean(dt), output_dt=1e-2)
    x = res["body/block/position"]
    return float(np.linalg.norm(x[-1, :2] - x[0, :2]))


# ---- MuJoCo -------------------------------------------------------------------------------------------
def mj_solref(eps, tc=0.002):
    zeta = -math.log(eps) / math.sqrt(math.pi**2 + math.log(eps) ** 2)
    return f"{tc} {zeta}"


def run_mj_ball(dt):
    import mujoco

    xml = f"""<mujoco><option timestep="{dt}" gravity="0 0 {-G}" integrator="implicitfast"/>
    <worldbody><geom type="plane" size="5 5 0.1" solref="{mj_solref(EPS)}"/>
    <body pos="0 0 {H0 + R}"><freejoint/><geom type="sphere" size="{R}" mass="1" solref="{mj_solref(EPS)}"/></body></worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    n = int(round(3.0 / dt))
    every = max(1, int(round(1e-3 / dt)))
    z, t, pen = [], [], 0.0
    for k in range(n):
        mujoco.mj_step(m, d)
        if k % every == 0:
            z.append(d.qpos[2] - R)
            t.append(d.time)
        pen = max(pen, R - d.qpos[2])
    return np.array(t), np.array(z), pen


def run_mj_block(dt):
    import mujoco

    g = (G * math.sin(ALPHA), 0, -G * math.cos(ALPHA))
    xml = f"""<mujoco><option timestep="{dt}" gravity="{g[0]} {g[1]} {g[2]}" cone="elliptic" impratio="10"/>
    <worldbody><geom type="plane" size="5 5 0.1" friction="{MU0} 0.005 0.0001"/>
    <body pos="0 0 {HALF[2]}"><freejoint/><geom type="box" size="{HALF[0]} {HALF[1]} {HALF[2]}" mass="2" friction="{MU0} 0.005 0.0001"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    x0 = None
    for k in range(int(round(2.0 / dt))):
        mujoco.mj_step(m, d)
        if k == 0:
            x0 = d.qpos[:2].copy()
    return float(np.linalg.norm(d.qpos[:2] - x0))


# ---- PyBullet -----------------------------------------------------------------------------------------
def _pb():
    import pybullet as p

    cid = p.connect(p.DIRECT)
    return p, cid


def run_pb_ball(dt):
    p, cid = _pb()
    try:
        p.setGravity(0, 0, -G, physicsClientId=cid)
        p.setTimeStep(dt, physicsClientId=cid)
        plane = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=cid), physicsClientId=cid)
        ball = p.createMultiBody(1.0, p.createCollisionShape(p.GEOM_SPHERE, radius=R, physicsClientId=cid),
                                 basePosition=[0, 0, H0 + R], physicsClientId=cid)
        # Bullet multiplies the two bodies' coefficients: the plane gets 1
        p.changeDynamics(plane, -1, restitution=1.0, lateralFriction=0.0, physicsClientId=cid)
        p.changeDynamics(ball, -1, restitution=EPS, lateralFriction=0.0, linearDamping=0.0, angularDamping=0.0, physicsClientId=cid)
        n = int(round(3.0 / dt))
        every = max(1, int(round(1e-3 / dt)))
        z, t, pen = [], [], 0.0
        for k in range(n):
            p.stepSimulation(physicsClientId=cid)
            zk = p.getBasePositionAndOrientation(ball, physicsClientId=cid)[0][2]
            if k % every == 0:
                z.append(zk - R)
                t.append((k + 1) * dt)
            pen = max(pen, R - zk)
        return np.array(t), np.array(z), pen
    finally:
        p.disconnect(physicsClientId=cid)


def run_pb_block(dt):
    p, cid = _pb()
    try:
        p.setGravity(G * math.sin(ALPHA), 0, -G * math.cos(ALPHA), physicsClientId=cid)
        p.setTimeStep(dt, physicsClientId=cid)
        plane = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=cid), physicsClientId=cid)
        box = p.createMultiBody(2.0, p.createCollisionShape(p.GEOM_BOX, halfExtents=HALF, physicsClientId=cid),
                                basePosition=[0, 0, HALF[2]], physicsClientId=cid)
        p.changeDynamics(plane, -1, lateralFriction=1.0, restitution=0.0, physicsClientId=cid)  # multiplied, as above
        p.changeDynamics(box, -1, lateralFriction=MU0, restitution=0.0, linearDamping=0.0, angularDamping=0.0, physicsClientId=cid)
        x0 = None
        for k in range(int(round(2.0 / dt))):
            p.stepSimulation(physicsClientId=cid)
            if k == 0:
                x0 = np.array(p.getBasePositionAndOrientation(box, physicsClientId=cid)[0][:2])
        x = np.array(p.getBasePositionAndOrientation(box, physicsClientId=cid)[0][:2])
        return float(np.linalg.norm(x - x0))
    finally:
        p.disconnect(physicsClientId=cid)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, help="write the results section into this markdown file")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    repeat = 1 if a.quick else a.repeat
    warnings.simplefilter("ignore")
    mach = machine()
    expected = H0 * EPS ** (2 * np.arange(1, 4))
    rows_ball, rows_block = [], []
    ball, blk = ms_ball(), ms_block()
    for engine, fn in (("mechsys MoreauJean, dt = 1e-4", lambda: run_ms_ball(ball, 1e-4)),
                       ("mechsys MoreauJean, dt = 1e-3", lambda: run_ms_ball(ball, 1e-3)),
                       ("MuJoCo, dt = 1e-4", lambda: run_mj_ball(1e-4)),
                       ("PyBullet, dt = 1e-3", lambda: run_pb_ball(1e-3))):
        try:
            tmin, tmed, (t, z, pen) = timed(fn, repeat)
        except Exception as e:  # noqa: BLE001 - a missing peer is reported, not fatal
            print(f"{engine}: {e}")
            continue
        ap_ = apexes(t, z)
        err = np.abs(ap_ - expected[: len(ap_)]).max() if len(ap_) == 3 else float("nan")
        rows_ball.append((engine, tmin, tmed, ap_, err, pen))
        print(f"ball  {engine:20s} {fmt_time(tmin)}  apexes {np.round(ap_, 4)}  max error {err:.2e} m  penetration {pen:.2e} m")
    for engine, fn in (("mechsys MoreauJean", lambda: run_ms_block(blk, 1e-3)), ("MuJoCo", lambda: run_mj_block(1e-3)),
                       ("PyBullet", lambda: run_pb_block(1e-3))):
        try:
            tmin, tmed, creep = timed(fn, repeat)
        except Exception as e:  # noqa: BLE001
            print(f"{engine}: {e}")
            continue
        rows_block.append((engine, tmin, tmed, creep))
        print(f"block {engine:20s} {fmt_time(tmin)}  creep after 2 s {creep:.2e} m")
    if a.out:
        ms_ball_t = next((r[1] for r in rows_ball if r[0].startswith("mechsys") and "1e-4" in r[0]), None)
        ms_block_t = next((r[1] for r in rows_block if r[0].startswith("mechsys")), None)
        L = ["## Contacts (issue 4): mechsys against MuJoCo and PyBullet", ""]
        L.append(f"Generated by `benches/contacts.py` (this section only). {time.strftime('%Y-%m-%d %H:%M')} on "
                 f"{mach['nproc']} × {mach['cpu']}, load average at start {mach['load'][0]:.2f}. Problems, settings and "
                 "fairness notes are in the script's docstring; times from Python with the model built beforehand, "
                 f"min (median) over {repeat} run(s).")
        L += ["", "### Bouncing ball, eps = 0.8, 3 s", "",
              "| engine | wall time | mechsys vs it | apexes (m), expected " + ", ".join(f"{e:.4f}" for e in expected) + " | largest apex error | largest penetration |",
              "|---|---:|---:|---|---:|---:|"]
        def ms_at(engine):
            # mechsys at the peer's step
            step = engine.split("dt = ")[-1]
            return next((r[1] for r in rows_ball if r[0].startswith("mechsys") and r[0].endswith(step)), ms_ball_t)

        for engine, tmin, tmed, ap_, err, pen in rows_ball:
            err_s = f"{err:.1e} m" if math.isfinite(err) else f"– ({len(ap_)} bounces above 1 mm)"
            L.append(f"| {engine} | {fmt_time(tmin)} ({fmt_time(tmed)}) | {ratio(ms_at(engine), tmin) if not engine.startswith('mechsys') else '–'} | "
                     f"{', '.join(f'{x:.4f}' for x in ap_)} | {err_s} | {pen:.1e} m |")
        L += ["", "“mechsys vs it”: against mechsys at the same step."]
        L += ["", "### Block that must stick (static friction 0.4, tan α = 0.309), 2 s at dt = 1e-3", "",
              "| engine | wall time | mechsys vs it | creep after 2 s |", "|---|---:|---:|---:|"]
        for engine, tmin, tmed, creep in rows_block:
            L.append(f"| {engine} | {fmt_time(tmin)} ({fmt_time(tmed)}) | {ratio(ms_block_t, tmin) if not engine.startswith('mechsys') else '–'} | {creep:.1e} m |")
        L += ["", "Still missing from issue 4's list: spheres poured into a box (100, 1000) and a stack of 10 boxes."]
        write_doc(a.out, "\n".join(L), "<!-- contacts.py:begin -->", "<!-- contacts.py:end -->")
        print(f"updated {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
