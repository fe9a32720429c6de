"""Hydrodynamic journal bearing: what the element costs in a run and what its analysis costs.

The rotor of examples/rotor_bearing.py (50 kg on a planar joint in a short bearing, D = 100 mm,
L/D = 0.3, c = 0.1 mm, 0.02 Pa s; whirl threshold 830 rad/s). Measured:

1. one evaluation of the element inside the step loop: RK4 (dt = 1e-5 s, 2 s, 4 evaluations per
   step, two samples recorded) on the rotor with its spin held at 600 rad/s by a prescribed motion,
   once with the bearing split into 21 bearings of a 21st of the viscosity each (the same film
   force, so the same motion) and once with the one bearing: the difference over 20 x the number of
   right-hand-side evaluations (a single element's cost is below the run-to-run noise);
2. wall time per simulated second with the adaptive DOPRI5 (rtol 1e-9, atol 1e-13, a sample per
   ms): steady running at 600 rad/s after a push of 0.05 c; the example's run-up through the
   threshold into oil whip (2.5 s); 0.1 s of the whip's limit cycle (eps ~ 0.98, from the state at
   2.5 s: the squeeze film is stiff there, its damping grows as (1 - eps^2)^(-5/2));
3. the analysis: ``ms.bearings.static`` (operating point and the eight coefficients, through the
   bindings), ``ms.bearings.threshold`` (Lund's criterion, ~100 operating points and a
   bisection) and the exact linearization of the rotor (``ms.linear.linearize``).

Times: from Python with the model built beforehand, min (median) over repeats.
Usage: ``.venv/bin/python benches/bearing.py [--out docs/benchmarks.md] [--quick]``.
"""

from __future__ import annotations

import importlib.util
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from benchdoc import bench_args, fmt_time, machine, timed, write_doc  # noqa: E402

import mechsys as ms  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("rotor_bearing", ROOT / "examples" / "rotor_bearing.py")
ex = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ex)

SPEED, DT, T_RK4 = 600.0, 1e-5, 2.0
ADAPTIVE = ms.DOPRI5(rtol=1e-9, atol=1e-13)


def held(speed: float, split: int = 1, push: float = 0.0) -> ms.Model:
    """The example's rotor with its spin held at ``speed``, its bearing split into ``split``
    bearings of a ``split``-th of the viscosity, started ``push`` clearances off the static point."""
    op = ms.bearings.static(*ex.BEARING, speed, ex.MASS * ex.G)
    m = ms.Model("rotor", gravity=(0.0, -ex.G, 0.0))
    rotor = m.add_body("rotor", ex.MASS, [0.4, 0.4, 0.5])
    q0 = [op.offset[0] + push * ex.C, op.offset[1], 0.0]
    m.add_joint(ms.joints.Planar("float", m.ground, rotor, q0=q0, u0=[0.0, 0.0, speed]))
    for k in range(split):
        m.add_force(ms.forces.HydrodynamicBearing("brg" if k == 0 else f"brg{k}", rotor, m.ground, radius=ex.R,
                                                  length=ex.L, clearance=ex.C, viscosity=ex.ETA / split))
    m.add_constraint(ms.constraints.Prescribed("spin", "float", ms.functions.Ramp(speed), index=2))
    return m


def main(argv=None) -> int:
    a = bench_args(__doc__, argv)
    repeat = a.repeat
    warnings.simplefilter("ignore")
    mach = machine()
    rows = []

    # 1. the element's share of a right-hand-side evaluation
    steps, extra = int(round(T_RK4 / DT)), 20
    one, many = held(SPEED), held(SPEED, split=extra + 1)
    one.build()
    many.build()
    o_min, o_med, res = timed(lambda: ms.simulate(one, T_RK4, ms.RK4(dt=DT), output_dt=T_RK4), repeat)
    m_min, m_med, res_m = timed(lambda: ms.simulate(many, T_RK4, ms.RK4(dt=DT), output_dt=T_RK4), repeat)
    evals = res.stats["evaluations"]
    per_eval = (m_min - o_min) / (extra * evals)
    same = abs(res_m["force/brg/eccentricity"][-1] - res["force/brg/eccentricity"][-1])
    print(f"RK4 {steps} steps: 1 bearing {fmt_time(o_min)}, {extra + 1} bearings {fmt_time(m_min)}: "
          f"{per_eval * 1e9:.3g} ns per evaluation of one element ({evals} evaluations; eps differs by {same:.1e})")
    rows.append((f"one evaluation of the element (RK4, {steps} steps, {evals} evaluations; {extra + 1} bearings "
                 f"{fmt_time(m_min)}, one bearing {fmt_time(o_min)})", f"{per_eval * 1e9:.3g} ns",
                 f"{o_min / evals * 1e9:.3g} ns per evaluation of the whole rotor model with one bearing (kinematics, "
                 "bearing, constraint, dynamics)"))

    # 2. per simulated second, adaptive
    steady = held(SPEED, push=0.05)
    steady.build()
    s_min, s_med, sres = timed(lambda: ms.simulate(steady, 1.0, ADAPTIVE, output_dt=1e-3), repeat)
    eps_end = sres["force/brg/eccentricity"][-1]
    eps_static = ms.bearings.static(*ex.BEARING, SPEED, ex.MASS * ex.G).eps
    print(f"steady running, 1 s: {fmt_time(s_min)}, {sres.stats['steps']} steps; eps {eps_end:.9f} "
          f"vs static {eps_static:.9f}")
    rows.append((f"steady running at {SPEED:.0f} rad/s after a push of 0.05 c, DOPRI5, 1 s simulated",
                 f"{fmt_time(s_min)} ({fmt_time(s_med)})",
                 f"{sres.stats['steps']} steps; the eccentricity settles at the static one to "
                 f"{abs(eps_end - eps_static):.1e}"))
    run = ex.build()
    run.build()
    t_run = ex.simulation["t_end"]
    r_min, r_med, rres = timed(lambda: ms.simulate(run, t_run, ADAPTIVE, output_dt=1e-3), repeat)
    print(f"run-up {t_run} s: {fmt_time(r_min)}, {rres.stats['steps']} steps")
    rows.append((f"run-up of examples/rotor_bearing.py, 400 → {ex.W1:.0f} rad/s and into oil whip, {t_run} s "
                 "simulated", f"{fmt_time(r_min)} ({fmt_time(r_med)})",
                 f"{rres.stats['steps']} steps, {rres.stats['rejected']} rejected"))
    # oil whip: from the state at the end of the run-up, 0.1 s of the limit cycle
    t_whip, span = t_run, 0.1
    q1, u1 = rres["q"][-1], rres["u"][-1]
    eps_whip = rres["force/brg/eccentricity"][-1]
    ww_min, ww_med, whip = timed(lambda: ms.simulate(run, t_whip + span, ADAPTIVE, output_dt=1e-3, t0=t_whip,
                                                     q0=q1, u0=u1), repeat)
    eps_max = whip["force/brg/eccentricity"].max()
    print(f"oil whip {span} s from eps {eps_whip:.3f}: {fmt_time(ww_min)}, {whip.stats['steps']} steps, "
          f"{whip.stats['rejected']} rejected, eps up to {eps_max:.4f}")
    rows.append((f"oil whip, {span} s of the limit cycle (eps up to {eps_max:.3f})", f"{fmt_time(ww_min)} ({fmt_time(ww_med)})",
                 f"{whip.stats['steps']} steps, {whip.stats['rejected']} rejected: {fmt_time(ww_min / span)} per "
                 "simulated second (the explicit steps are held to the film's stability limit)"))

    # 3. the analysis
    st_min, st_med, _ = timed(lambda: ms.bearings.static(*ex.BEARING, SPEED, ex.MASS * ex.G), 20 * repeat)
    rows.append(("`ms.bearings.static` (operating point, eight exact coefficients)", f"{fmt_time(st_min)} ({fmt_time(st_med)})", ""))
    th_min, th_med, th = timed(lambda: ms.bearings.threshold(*ex.BEARING, mass=ex.MASS), repeat)
    rows.append(("`ms.bearings.threshold` (Lund's criterion)", f"{fmt_time(th_min)} ({fmt_time(th_med)})",
                 f"{th.speed:.2f} rad/s at eps = {th.point.eps:.4f}"))
    lin_model = held(th.speed)
    lin_model.build()
    li_min, li_med, lin = timed(lambda: ms.linear.linearize(lin_model, operating_point=True), 5 * repeat)
    rows.append((f"`ms.linear.linearize` of the rotor at the threshold ({lin.method})", f"{fmt_time(li_min)} ({fmt_time(li_med)})",
                 "K, C equal the bearing's coefficients (tests/test_bearing.py)"))
    for r in rows[-3:]:
        print(f"{r[0]}: {r[1]} {r[2]}")

    if a.out:
        L = ["## Hydrodynamic journal bearing", ""]
        L.append(f"Generated by `benches/bearing.py` (this section only). {time.strftime('%Y-%m-%d %H:%M')} on "
                 f"{mach['nproc']} × {mach['cpu']}, load average at start {mach['load'][0]:.2f}. Problems are in the "
                 f"script's docstring; release build, times from Python, min (median) over {repeat} run(s).")
        L.append("")
        L.append("| what | time | note |")
        L.append("|---|---|---|")
        for what, t, note in rows:
            L.append(f"| {what} | {t} | {note} |")
        write_doc(a.out, "\n".join(L), "<!-- bearing.py:begin -->", "<!-- bearing.py:end -->")
        print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
