"""Batch simulation: 1000 rollouts of a 7-DOF arm on all cores, mechsys (`ms.simulate_batch`)
against MuJoCo's `mujoco.rollout.rollout` with the same number of threads, in the same run.

Model, identical in both engines: the arm of examples/arm7.py without its shoulder drive -- seven
solid cylinders (radius 0.05 m) on revolute joints about z, y, z, y, z, y, z, each link along its
body z axis, viscous joint dampers, gravity -9.81 m/s^2 along z. MuJoCo: nested bodies with hinge
joints, explicit `<inertial>`, joint `damping`, no geoms (no contacts), RK4 at dt = 1e-3.
mechsys: `ms.RK4(1e-3)`.

Each rollout runs 1 s (1000 steps) from its own initial state: joint angles uniform in
[-1, 1] rad, rates uniform in [-1, 1] rad/s (seeded). Timed from the Python call until the stacked
states are in hand: mechsys records q, u and the energies at every step (`sensors=["joint/*/q"]`
skips the per-body signals), MuJoCo returns its full physics state at every step. Both engines'
final states are compared (they integrate the same equations with the same scheme and step).
min (median) over repeats.

Usage: ``.venv/bin/python benches/batch.py [--out docs/benchmarks.md] [--n 1000] [--threads K] [--repeat 3] [--quick]``.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchdoc import fmt_time, machine, ratio, timed, write_doc  # noqa: E402

import mechsys as ms  # noqa: E402

LENGTHS = [0.30, 0.20, 0.20, 0.20, 0.20, 0.15, 0.08]
MASSES = [4.0, 3.5, 3.0, 2.5, 1.8, 1.2, 0.4]
RADIUS = 0.05
DAMPINGS = [3.0, 3.0, 2.0, 2.0, 1.0, 0.5, 0.05]
AXES = [(0, 0, 1), (0, 1, 0)] * 3 + [(0, 0, 1)]
DT, T_END, G = 1e-3, 1.0, 9.81
BEGIN, END = "<!-- batch:begin -->", "<!-- batch:end -->"


def arm():
    model = ms.Model("arm7-limp", gravity=(0.0, 0.0, -G))
    parent, offset = model.ground, 0.0
    for i, (length, mass, axis, d) in enumerate(zip(LENGTHS, MASSES, AXES, DAMPINGS), start=1):
        link = model.add_body(f"link{i}", mass=mass, inertia=ms.inertia.cylinder(mass, RADIUS, length, axis="z"),
                              com=(0.0, 0.0, 0.5 * length))
        model.add_joint(ms.joints.Revolute(f"j{i}", parent=parent, child=link, parent_frame=(0.0, 0.0, offset), axis=axis,
                                           damper=ms.forces.RotaryDamper(d=d)))
        parent, offset = link, length
    return model


def arm_mjcf() -> str:
    body = ""
    offsets = [0.0] + LENGTHS[:-1]
    for i in reversed(range(7)):
        m, length = MASSES[i], LENGTHS[i]
        ixx = m * (3 * RADIUS**2 + length**2) / 12
        izz = 0.5 * m * RADIUS**2
        axis = " ".join(str(a) for a in AXES[i])
        body = (f'<body name="link{i + 1}" pos="0 0 {offsets[i]!r}">'
                f'<joint name="j{i + 1}" type="hinge" axis="{axis}" damping="{DAMPINGS[i]!r}" armature="0" frictionloss="0" limited="false"/>'
                f'<inertial pos="0 0 {0.5 * length!r}" mass="{m!r}" diaginertia="{ixx!r} {ixx!r} {izz!r}"/>'
                f"{body}</body>")
    return (f'<mujoco model="arm7"><compiler angle="radian" inertiafromgeom="false"/>'
            f'<option timestep="{DT}" integrator="RK4" gravity="0 0 {-G}"><flag contact="disable"/></option>'
            f"<worldbody>{body}</worldbody></mujoco>")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args(argv)
    if a.quick:
        a.repeat, a.n = 1, min(a.n, 100)
    mach = machine()
    rng = np.random.default_rng(1)
    x0 = np.hstack([rng.uniform(-1, 1, (a.n, 7)), rng.uniform(-1, 1, (a.n, 7))])
    n_steps = int(round(T_END / DT))

    model = arm()
    integ = ms.RK4(DT)

    def run_ms():
        return ms.simulate_batch(model, T_END, integ, initial_states=x0, threads=a.threads, sensors=["joint/*/q"])

    t_ms, med_ms, batch = timed(run_ms, a.repeat)
    assert batch.q.shape == (a.n, n_steps + 1, 7)
    # one case alone, for the serial cost and the bit-for-bit check
    single = ms.simulate(model, T_END, integ, q0=x0[0, :7], u0=x0[0, 7:])
    assert np.array_equal(single["q"], batch.q[0])
    t_one, _, _ = timed(lambda: ms.simulate(model, T_END, integ, q0=x0[0, :7], u0=x0[0, 7:], sensors=["joint/*/q"]),
                        a.repeat)

    row = {"ms": (t_ms, med_ms)}
    try:
        import mujoco
        from mujoco import rollout

        mm = mujoco.MjModel.from_xml_string(arm_mjcf())
        datas = [mujoco.MjData(mm) for _ in range(a.threads)]
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        nstate = mujoco.mj_stateSize(mm, spec)
        init = np.zeros((a.n, nstate))
        d = datas[0]
        for i in range(a.n):
            mujoco.mj_resetData(mm, d)
            d.qpos[:] = x0[i, :7]
            d.qvel[:] = x0[i, 7:]
            mujoco.mj_getState(mm, d, init[i], spec)

        def run_mj():
            state, _ = rollout.rollout(mm, datas, init, nstep=n_steps, persistent_pool=True)
            return state

        t_mj, med_mj, state = timed(run_mj, a.repeat)
        row["mj"] = (t_mj, med_mj)
        # state layout (FULLPHYSICS): time, qpos, qvel, act, ...
        q_mj, u_mj = state[:, -1, 1:8], state[:, -1, 8:15]
        row["dq"] = float(np.max(np.abs(q_mj - batch.q[:, -1])))
        row["du"] = float(np.max(np.abs(u_mj - batch.u[:, -1])))
        rollout.shutdown_persistent_pool() if hasattr(rollout, "shutdown_persistent_pool") else None
        mj_version = mujoco.__version__
    except ImportError:
        mj_version = None

    lines = [
        f"{a.n}-rollout batch of the 7-DOF arm (the limp arm of examples/arm7.py: dampers and gravity, no drive), "
        f"{a.n} rollouts of {T_END:g} s at dt = {DT:g} (RK4 in both), {a.threads} threads; "
        f"machine: {mach['nproc']} × {mach['cpu']}, load average at start {mach['load'][0]:.2f}; "
        f"MuJoCo {mj_version or 'not installed'}. Reproduce: `.venv/bin/python benches/batch.py --out docs/benchmarks.md`.",
        "",
        "| | mechsys `simulate_batch` | MuJoCo `rollout` | mechsys vs MuJoCo | max Δq, Δu at 1 s |",
        "|---|---|---|---|---|",
    ]
    mj = row.get("mj")
    cell = lambda c: f"{fmt_time(c[0])} ({fmt_time(c[1])})" if c else "–"  # noqa: E731
    lines.append(f"| {a.n} rollouts, {a.threads} threads | {cell(row['ms'])} | {cell(mj)} | "
                 f"{ratio(row['ms'][0], mj[0]) if mj else '–'} | "
                 f"{row.get('dq', float('nan')):.1e}, {row.get('du', float('nan')):.1e} |")
    lines += ["", f"One rollout alone with `ms.simulate`: {fmt_time(t_one)}; the batch runs "
              f"{a.n * t_one / t_ms:.2f}× as fast as {a.n} such calls one after another. Every batch case equals the "
              "single run bit for bit (checked for case 0)."]
    text = "\n".join(lines)
    print(text)
    if a.out:
        write_doc(a.out, text, BEGIN, END, heading="## Batch simulation (7-DOF arm rollouts)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
