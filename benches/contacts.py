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

3. Sphere piles: N = 100 and 1000 spheres (r = 5 cm, 0.1 kg, friction 0.5, no restitution) on a
   lattice of spacing 2.2 r (jittered by ±1 % of r, the same in every engine) filling a square box
   (inner half-width 0.275 m: 5 × 5 per layer; 0.55 m: 10 × 10) layer by layer from 1 cm above
   its floor, poured in by gravity: the lower layers land first, the upper ones (up to 1.05 m high
   for N = 1000) onto them. mechsys: one `ContactGroup` (every pair of spheres, and each sphere
   against the floor and the four walls; pairs from its sweep-and-prune broad phase), Moreau-Jean
   with nonsmooth Gauss-Seidel, two budgets: `NSGS(tol=1e-6, max_iter=100)` and the faster
   `NSGS(tol=1e-4, max_iter=20)`, and `Auto(tol=1e-4)` (issue 17: islands solved apart, Newton
   on the small ones, Gauss-Seidel to convergence on the large ones) and, on the 100-sphere pile,
   `APGD(tol=1e-4)` (accelerated projected gradient, up to 10^4 iterations) and `Newton(tol=1e-4)`
   (semismooth Newton, its direction solved in body space: a sparse factorization in the spheres'
   velocities; up to 200 iterations), and `Auto(tol=1e-4)` on compliant Signorini layers
   (`laws.Signorini(compliance=1e-6)`: a contact stiffness of 1e6 N/m in series with the rigid
   contact, undamped; the pile's weight presses the lowest layers by tens of micrometres; the
   contact problem is regularized by c/h^2 on its normal diagonal and its solution unique, so
   converged steps take tens of sweeps: the counterpart of MuJoCo's soft contacts, far stiffer)
   (sweeps stop at the tolerance or the budget, whichever first;
   the table says in how many steps the budget came first: the impulses of those steps are
   Gauss-Seidel iterates, not solutions).
   MuJoCo: sphere geoms, plane floor and walls, its default settings (Newton solver, pyramidal
   cones, soft contacts with solref 0.02 s / damping ratio 1) and its CG solver; the table says in
   how many steps its solver used all of its iterations (100 by default), i.e. stopped before its
   own tolerance (1e-8, on its regularized problem, where soft contacts make the cost strictly
   convex; mechsys' contacts are rigid and its problems singular on piles); PyBullet: sphere
   shapes, plane floor and walls (static), default solver settings, restitution 0. Reported: wall
   time per simulated second, the largest penetration (mechsys: the group's signal, largest
   overlap at the midpoint of every step; MuJoCo: the deepest contact of every step; PyBullet: the
   deepest contact point every 10th step, to keep the Python query out of the timing), and the
   mean height of the sphere centres at the end (the same pile in every engine?).

Usage: ``.venv/bin/python benches/contacts.py [--out docs/benchmarks.md] [--quick] [--piles 100,1000]
[--pile-time 1.0]``.
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
from benchdoc import fmt_time, machine, ratio, timed, write_doc  # noqa: E402

G, R, H0, EPS = 9.81, 0.1, 1.0, 0.8
ALPHA, MU0, MU = 0.3, 0.4, 0.3
HALF = (0.1, 0.05, 0.05)




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


# ---- sphere piles -------------------------------------------------------------------------------------
PILE_R, PILE_M, PILE_MU = 0.05, 0.1, 0.5
MISSED: dict = {}  # (model, dt, tol, max_iter) -> share of mechsys steps that stopped at the sweep budget
MJ_CAPPED: dict = {}  # (n, dt, solver) -> (share of MuJoCo steps whose solver used all its iterations, the cap)


def pile_layout(n):
    """Half-width of the box and the sphere centres (n × 3) of the pile of `n` spheres."""
    half = 0.275 if n <= 100 else 0.55
    per = int(round(2 * half / (2.2 * PILE_R)))
    rng = np.random.default_rng(0)
    pos = []
    for i in range(n):
        ix, iy, iz = i % per, (i // per) % per, i // (per * per)
        pos.append((-half + 1.1 * PILE_R + 2.2 * PILE_R * ix + rng.uniform(-0.01, 0.01) * PILE_R,
                    -half + 1.1 * PILE_R + 2.2 * PILE_R * iy + rng.uniform(-0.01, 0.01) * PILE_R,
                    PILE_R + 0.01 + 2.2 * PILE_R * iz))
    return half, np.array(pos)


def _walls(half):
    """(point, outward normal) of the floor and the four walls."""
    out = [((0, 0, 0), (0, 0, 1))]
    for ax in range(2):
        for sgn in (1, -1):
            n, p = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
            n[ax], p[ax] = sgn, -sgn * half
            out.append((tuple(p), tuple(n)))
    return out


def ms_pile(n, compliance=0.0):
    """The pile of `n` spheres; with `compliance` (m/N) its contacts are compliant Signorini ones."""
    import mechsys as ms

    half, pos = pile_layout(n)
    m = ms.Model(f"pile-{n}", gravity=(0, 0, -G))
    members = []
    for i, x in enumerate(pos):
        b = m.add_body(f"s{i}", PILE_M, ms.inertia.sphere(PILE_M, PILE_R))
        m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=[*x, 1, 0, 0, 0]))
        members.append(b.contour(ms.contours.Sphere(radius=PILE_R)))
    against = [m.ground.contour(ms.contours.Plane(point=p, normal=nrm)) for p, nrm in _walls(half)]
    m.add_contact(ms.ContactGroup("pile", members=members, against=against, friction=ms.laws.Coulomb(PILE_MU),
                                  impact=ms.laws.Newton(0.0), normal=ms.laws.Signorini(compliance=compliance)))
    m.build()
    return m


def run_ms_pile(model, n, dt, t_end, tol, max_iter, auto=False):
    import mechsys as ms

    import re

    solver = (ms.APGD(tol=tol, max_iter=10_000) if auto == "apgd" else ms.Newton(tol=tol) if auto == "newton"
              else ms.Auto(tol=tol) if auto else ms.NSGS(tol=tol, max_iter=max_iter))
    with warnings.catch_warnings(record=True) as notes:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        res = ms.simulate(model, t_end, ms.MoreauJean(dt, solver=solver), output_dt=0.05, progress=False)
        el = time.perf_counter() - t0
    # steps whose contact problem stopped at the sweep budget before the tolerance
    missed = [re.search(r"in (\d+) of (\d+) steps", str(w.message)) for w in notes]
    missed = [m for m in missed if m]
    MISSED[(id(model), dt, tol, auto if auto in ("apgd", "newton") else "auto" if auto else max_iter)] = (int(missed[0].group(1)) / int(missed[0].group(2))
                                                                  if missed else 0.0)
    z = res["q"][-1].reshape(n, 7)[:, 2]
    return el, float(res["contact/pile/max_penetration"].max()), float(z.mean()), int(res["contact/pile/closed"][-1]), t_end


def run_mj_pile(n, dt, t_end, solver, cap=None):
    import mujoco

    half, pos = pile_layout(n)
    walls = "".join(f'<geom type="plane" pos="{p[0]} {p[1]} {p[2]}" zaxis="{nrm[0]} {nrm[1]} {nrm[2]}" size="2 2 0.1" friction="{PILE_MU} 0.005 0.0001"/>'
                    for p, nrm in _walls(half))
    bodies = "".join(f'<body pos="{x[0]} {x[1]} {x[2]}"><freejoint/><geom type="sphere" size="{PILE_R}" mass="{PILE_M}" '
                     f'friction="{PILE_MU} 0.005 0.0001"/></body>' for x in pos)
    opt = f'timestep="{dt}" gravity="0 0 {-G}"' + ("" if solver == "Newton" else f' solver="{solver}"')
    xml = f"<mujoco><option {opt}/><size memory=\"{64 if n > 100 else 16}M\"/><worldbody>{walls}{bodies}</worldbody></mujoco>"
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    pen = 0.0
    # MuJoCo's own convergence: a step whose solver (any island's) used all of its iterations
    # stopped before its tolerance, the counterpart of mechsys' sweep budget
    niter, cap_it, capped = d.solver_niter, m.opt.iterations, 0

    # only mj_step is timed: the penetration and convergence reads after it are this script's
    # bookkeeping (a numpy call or two per step), not MuJoCo's work
    t0, el = time.perf_counter(), 0.0
    steps = int(round(t_end / dt))
    for k in range(steps):
        ts = time.perf_counter()
        mujoco.mj_step(m, d)
        el += time.perf_counter() - ts
        if d.ncon:
            pen = max(pen, -float(d.contact.dist[: d.ncon].min()))
        capped += int(niter[: max(d.nisland, 1)].max() >= cap_it)
        if cap is not None and k % 50 == 49 and time.perf_counter() - t0 > cap:
            steps = k + 1
            break
    z = d.qpos.reshape(n, 7)[:, 2]
    MJ_CAPPED[(n, dt, solver)] = (capped / steps, cap_it)
    return el, pen, float(z.mean()), int(d.ncon), steps * dt


def run_pb_pile(n, dt, t_end, cap=None):
    p, cid = _pb()
    try:
        half, pos = pile_layout(n)
        p.setGravity(0, 0, -G, physicsClientId=cid)
        p.setTimeStep(dt, physicsClientId=cid)
        plane = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=cid)
        for pt, nrm in _walls(half):
            # the plane shape's normal is +z: turn it onto nrm
            ax = np.cross((0, 0, 1), nrm)
            ang = math.acos(max(-1.0, min(1.0, nrm[2])))
            q = (0, 0, 0, 1) if np.linalg.norm(ax) < 1e-12 else tuple(np.r_[ax / np.linalg.norm(ax) * math.sin(ang / 2), math.cos(ang / 2)])
            w = p.createMultiBody(0, plane, basePosition=pt, baseOrientation=q, physicsClientId=cid)
            p.changeDynamics(w, -1, lateralFriction=1.0, restitution=0.0, physicsClientId=cid)
        shape = p.createCollisionShape(p.GEOM_SPHERE, radius=PILE_R, physicsClientId=cid)
        ids = []
        for x in pos:
            b = p.createMultiBody(PILE_M, shape, basePosition=list(x), physicsClientId=cid)
            p.changeDynamics(b, -1, lateralFriction=PILE_MU, restitution=0.0, linearDamping=0.0, angularDamping=0.0,
                             physicsClientId=cid)
            ids.append(b)
        pen = 0.0
        t0 = time.perf_counter()
        steps = int(round(t_end / dt))
        for k in range(steps):
            p.stepSimulation(physicsClientId=cid)
            if k % 10 == 9:
                cps = p.getContactPoints(physicsClientId=cid)
                if cps:
                    pen = max(pen, -min(c[8] for c in cps))
                if cap is not None and time.perf_counter() - t0 > cap:
                    steps = k + 1
                    break
        el = time.perf_counter() - t0
        z = np.array([p.getBasePositionAndOrientation(b, physicsClientId=cid)[0][2] for b in ids])
        return el, pen, float(z.mean()), len(p.getContactPoints(physicsClientId=cid)), steps * dt
    finally:
        p.disconnect(physicsClientId=cid)


# the compliant layers of the pile rows (m/N): k = 1e6 N/m
PILE_COMPLIANCE = 1e-6
COMPLIANT = "compliant layers k = 1e6 N/m"


def MISSED_SHARE(label: str) -> float:
    """The share of steps that stopped at the budget, read back from a mechsys row's label."""
    import re

    m = re.search(r"in (\d+) % of steps", label)
    return int(m.group(1)) / 100 if m else 0.0


def pile_rows(n, t_end, repeat, cap):
    """(engine, dt, min and median wall s per simulated s, penetration, mean z, contacts, simulated time
    reached) per setting for the pile of n; each run times the stepping only (models built beforehand).
    A peer's run that takes longer than `cap` wall seconds stops there: its rate is then that of the
    part it simulated (the first, cheaper part of the pour, so it errs in the peer's favour)."""
    model = ms_pile(n)
    soft = ms_pile(n, compliance=PILE_COMPLIANCE)
    settings = [
        ("mechsys NSGS(tol=1e-6, max_iter=100)", 1e-3, lambda dt: run_ms_pile(model, n, dt, t_end, 1e-6, 100)),
        ("mechsys NSGS(tol=1e-4, max_iter=20)", 1e-3, lambda dt: run_ms_pile(model, n, dt, t_end, 1e-4, 20)),
        ("mechsys Auto(tol=1e-4)", 1e-3, lambda dt: run_ms_pile(model, n, dt, t_end, 1e-4, 0, auto=True)),
        (f"mechsys Auto(tol=1e-4), {COMPLIANT}", 1e-3, lambda dt: run_ms_pile(soft, n, dt, t_end, 1e-4, 0, auto=True)),
        *([(f"mechsys Auto(tol=1e-4), {COMPLIANT}", 2e-3, lambda dt: run_ms_pile(soft, n, dt, t_end, 1e-4, 0, auto=True))]
          if n > 100 else []),
        # accelerated projected gradient (issue 17): on the small pile only (one W product per iteration,
        # thousands of iterations per step on a settling pile)
        *([("mechsys APGD(tol=1e-4)", 1e-3, lambda dt: run_ms_pile(model, n, dt, t_end, 1e-4, 0, auto="apgd"))]
          if n <= 100 else []),
        # semismooth Newton with its direction in body space (the problems exceed 480 unknowns), on
        # the small pile only (it stalls on settling piles, whose steps then end at its cap)
        *([("mechsys Newton(tol=1e-4)", 1e-3, lambda dt: run_ms_pile(model, n, dt, t_end, 1e-4, 0, auto="newton"))]
          if n <= 100 else []),
        ("MuJoCo default (Newton)", 1e-3, lambda dt: run_mj_pile(n, dt, t_end, "Newton", cap)),
        ("MuJoCo CG", 1e-3, lambda dt: run_mj_pile(n, dt, t_end, "CG", cap)),
        ("PyBullet", 1e-3, lambda dt: run_pb_pile(n, dt, t_end, cap)),
        ("mechsys NSGS(tol=1e-4, max_iter=20)", 2e-3, lambda dt: run_ms_pile(model, n, dt, t_end, 1e-4, 20)),
        ("MuJoCo CG", 2e-3, lambda dt: run_mj_pile(n, dt, t_end, "CG", cap)),
    ]
    rows = []
    # repeats interleaved (every setting once, then again) so that a change of the machine's load
    # falls on all settings alike
    runs = {k: [] for k in range(len(settings))}
    for _ in range(repeat):
        for k, (engine, dt, fn) in enumerate(settings):
            if runs[k] is None:
                continue
            try:
                runs[k].append(fn(dt))
            except Exception as e:  # noqa: BLE001 - a missing peer is reported, not fatal
                print(f"pile {n} {engine} dt = {dt:g}: {e}")
                runs[k] = None
    for k, (engine, dt, fn) in enumerate(settings):
        outs = runs[k]
        if not outs:
            continue
        # rates: wall time over the simulated time reached (a run stopped at the cap reached less)
        rates = [o[0] / o[4] for o in outs]
        tmin, tmed, (_, pen, zm, ncon, reached) = min(rates), statistics.median(rates), outs[-1]
        if engine.startswith("mechsys"):
            tol, it = (1e-6, 100) if "1e-6" in engine else (1e-4, "auto" if "Auto" in engine else "apgd" if "APGD" in engine
                                                             else "newton" if "Newton(tol" in engine else 20)
            share = MISSED.get((id(soft if COMPLIANT in engine else model), dt, tol, it))
            if share is not None:
                engine = f"{engine}; budget reached before tol in {100 * share:.0f} % of steps"
        elif engine.startswith("MuJoCo"):
            capped = MJ_CAPPED.get((n, dt, "CG" if "CG" in engine else "Newton"))
            if capped is not None:
                engine = f"{engine}; its {capped[1]} iterations used up in {100 * capped[0]:.0f} % of steps"
        rows.append((engine, dt, tmin, tmed, pen, zm, ncon, reached))
        print(f"pile {n:5d} {engine:40s} dt = {dt:g}: {tmin:7.3f} s per simulated s (median {tmed:.3f}), "
              f"penetration {pen:.2e} m, mean z {zm:.4f} m, contacts at the end {ncon}, simulated {reached:g} s", flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, help="write the results section into this markdown file")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--piles", default="100,1000", help="pile sizes, comma separated ('' for none)")
    ap.add_argument("--pile-time", type=float, default=1.0, help="simulated seconds of each pile run")
    ap.add_argument("--pile-repeat", type=int, default=3, help="repeats of each pile run up to 100 spheres")
    ap.add_argument("--pile-repeat-large", type=int, default=1, help="repeats of each pile run above 100 spheres")
    ap.add_argument("--pile-cap", type=float, default=120.0, help="wall seconds after which a peer's pile run stops")
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
    load_before = mach["load"][0]
    piles = {}
    for n in [int(x) for x in a.piles.split(",") if x.strip()]:
        # the 1000-sphere runs take minutes each with some peers: one run unless asked otherwise
        piles[n] = pile_rows(n, a.pile_time, a.pile_repeat if n <= 100 else a.pile_repeat_large, a.pile_cap)
    import os

    load_after = os.getloadavg()[0]
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
        T = a.pile_time
        for n, rows in piles.items():
            L += ["", f"### {n} spheres poured into a box, {T:g} s", "",
                  "| engine / settings | dt | wall s per simulated s | mechsys (fastest rigid setting at this dt) vs it | "
                  "largest penetration | mean height at the end | contacts at the end |",
                  "|---|---:|---:|---:|---:|---:|---:|"]
            best = {}
            for engine, dt, tmin, *_ in rows:
                # (rigid settings: the compliant rows' ratios are in their own target lines)
                if engine.startswith("mechsys") and COMPLIANT not in engine:
                    best[dt] = min(best.get(dt, float("inf")), tmin)
            for engine, dt, tmin, tmed, pen, zm, ncon, reached in rows:
                vs = "–" if engine.startswith("mechsys") else ratio(best.get(dt), tmin)
                part = "" if reached >= T - 1e-9 else f" (stopped at the cap after {reached:.2g} s simulated)"
                L.append(f"| {engine} | {dt:g} | {tmin:.3g} ({tmed:.3g}){part} | {vs} | {pen * 1e3:.2f} mm | {zm:.4f} m | {ncon} |")
        if piles:
            L += ["", f"Wall s per simulated s: min (median) over {a.pile_repeat} run(s) up to 100 spheres, "
                  f"{a.pile_repeat_large} above. mechsys' contacts are candidate points with a "
                  "positive normal impulse in the last step; MuJoCo's its active contacts (`ncon`); PyBullet's its contact "
                  "points. Penetration: see the script's docstring for where each engine's is taken. A peer's run "
                  f"stops after {a.pile_cap:g} s of wall time; its rate is then that of the part it simulated (the first, "
                  "cheaper part of the pour: this errs in the peer's favour) and its penetration and mean height are "
                  "those of that part. Threads: mechsys solves independent contact islands, and the two halves of "
                  "a large problem on free bodies, on up to two threads (`MoreauJean(parallel=True)`, the default; "
                  "from 400 contact points, so the 100-sphere pile runs on one; the impulses are the same bit for "
                  "bit on one); MuJoCo and PyBullet step on one. Load average "
                  f"{load_before:.2f} before the run, {load_after:.2f} after the piles (2 cores shared with other work: "
                  "times above ≈ 1 per core are slowed)."]
            L += ["", "Targets (issue 4): the 100-sphere pile at least 4× faster than MuJoCo's default at the same step; "
                  "1000 spheres at least as fast as MuJoCo's fastest setting."]
            for n, rows in piles.items():
                ms_rows = [r for r in rows if r[0].startswith("mechsys") and COMPLIANT not in r[0]]
                mj = [r for r in rows if r[0].startswith("MuJoCo")]
                if not ms_rows or not mj:
                    continue
                if n <= 100:
                    base = next((r for r in mj if "default" in r[0] and r[1] == 1e-3), None)
                    ours = min((r for r in ms_rows if r[1] == 1e-3), key=lambda r: r[2], default=None)
                    if base and ours:
                        f = base[2] / ours[2]
                        how = f"{f:.2f}× faster" if f >= 1 else f"{1 / f:.2f}× slower"
                        L.append(f"- {n} spheres, {ours[0]} at dt = 1e-3 against MuJoCo default at dt = 1e-3: "
                                 f"**{'met' if f >= 4 else 'missed'}** ({how}; penetration "
                                 f"{ours[4] * 1e3:.2f} mm against {base[4] * 1e3:.2f} mm).")
                else:
                    fastest = min(mj, key=lambda r: r[2])
                    ours = min(ms_rows, key=lambda r: r[2])
                    f = fastest[2] / ours[2]
                    L.append(f"- {n} spheres, mechsys' fastest ({ours[0]}, dt = {ours[1]:g}) against MuJoCo's fastest "
                             f"({fastest[0]}, dt = {fastest[1]:g}): **{'met' if f >= 1 else 'missed'}** "
                             f"({f'{f:.2f}× faster' if f >= 1 else f'{1 / f:.2f}× slower'}; penetration {ours[4] * 1e3:.2f} mm against "
                             f"{fastest[4] * 1e3:.2f} mm).")
            # issue 17: the same targets with converged contact problems (no budget reached first)
            L += ["", "Targets (issue 17): the same with converged contact forces (at least 99 % of the steps at the "
                  "tolerance): the rows without a sweep budget, `Auto`, `APGD` and `Newton`."]
            for n, rows in piles.items():
                conv = [r for r in rows if r[0].startswith("mechsys") and ("Auto" in r[0] or "APGD" in r[0] or "Newton(tol" in r[0])
                        and MISSED_SHARE(r[0]) <= 0.01 and COMPLIANT not in r[0]]
                mj = [r for r in rows if r[0].startswith("MuJoCo")]
                if not mj:
                    continue
                base = (next((r for r in mj if "default" in r[0] and r[1] == 1e-3), None) if n <= 100
                        else min(mj, key=lambda r: r[2]))
                goal = 4.0 if n <= 100 else 1.0
                if not conv:
                    L.append(f"- {n} spheres: **missed** (no converged setting: the unbudgeted solvers miss the tolerance in more "
                             "than 1 % of the steps).")
                    continue
                ours = min(conv, key=lambda r: r[2])
                f = base[2] / ours[2]
                L.append(f"- {n} spheres, {ours[0]} against {base[0]} (dt = {base[1]:g}): "
                         f"**{'met' if f >= goal else 'missed'}** ({f'{f:.2f}× faster' if f >= 1 else f'{1 / f:.2f}× slower'}, "
                         f"goal {goal:g}× faster).")
            # the converged rows on compliant layers: the counterpart of MuJoCo's soft contacts
            L += ["", f"The same converged targets on compliant Signorini layers ({COMPLIANT}: the contact problem "
                  "regularized and its solution unique, as MuJoCo's soft contacts make its own; far stiffer than "
                  "MuJoCo's defaults, whose spheres sink by millimetres):"]
            for n, rows in piles.items():
                conv = [r for r in rows if COMPLIANT in r[0] and MISSED_SHARE(r[0]) <= 0.01]
                mj = [r for r in rows if r[0].startswith("MuJoCo")]
                if not mj or not conv:
                    continue
                base = (next((r for r in mj if "default" in r[0] and r[1] == 1e-3), None) if n <= 100
                        else min(mj, key=lambda r: r[2]))
                goal = 4.0 if n <= 100 else 1.0
                ours = min((r for r in conv if n > 100 or r[1] == base[1]), key=lambda r: r[2], default=None)
                if ours is None:
                    continue
                f = base[2] / ours[2]
                L.append(f"- {n} spheres, {ours[0]} (dt = {ours[1]:g}) against {base[0]} (dt = {base[1]:g}): "
                         f"**{'met' if f >= goal else 'missed'}** ({f'{f:.2f}× faster' if f >= 1 else f'{1 / f:.2f}× slower'}, "
                         f"goal {goal:g}× faster; penetration {ours[4] * 1e3:.2f} mm against {base[4] * 1e3:.2f} mm).")
        write_doc(a.out, "\n".join(L), "<!-- contacts.py:begin -->", "<!-- contacts.py:end -->")
        print(f"updated {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
