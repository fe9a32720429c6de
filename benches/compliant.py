"""Compliant contact (issue 19): the Hertz impact with DOPRI5 and Radau5, a heavily damped stiff
contact, and a pile of compliant spheres against MuJoCo's soft contacts and mechsys' rigid pile.

1. Hertz impact: a steel ball (R = 10 mm) at 1 m/s on a steel plane, gravity off, one contact
   event (onset to release, about 70 µs). Per integrator and tolerance: accepted and rejected
   steps, right-hand-side evaluations and the wall time of the whole run (which holds one contact
   event), and the error of delta_max against the closed form (5 m v^2 / 4K)^(2/5).
2. Heavily damped stiff contact: the same ball resting on its plane through a Kelvin-Voigt
   contact with k = 1e9 N/m and d = 1e4 N s/m (time constants d/k = 10 µs and m/d = 3 µs), 0.1 s
   from twice its static overlap: the stiff case is Radau5's (its steps follow the motion);
   DOPRI5's are held at its stability limit.
3. Pile of N compliant spheres (r = 5 cm, 0.1 kg, E = 1e7 Pa, nu = 0.3, Hunt-Crossley eps = 0.3,
   friction 0.5 regularized at 1e-3 m/s) in a box, the lattice of benches/contacts.py, 0.3 s
   simulated (the layers fall in and land; ``--pile-time``): one compliant contact group (broad phase at
   every evaluation), DOPRI5 at rtol 1e-6, and at N = ``--explicit`` (20) the same pile both as a group
   and as explicit pairs (N(N-1)/2 plus 5 N contacts, onsets located); against MuJoCo (soft contacts,
   defaults, dt 1e-3) and mechsys' rigid pile (one contact group, Moreau-Jean dt 1e-3, NSGS tol 1e-6).
   Columns: wall time, largest penetration (compliant: the largest overlap sampled every 5 ms;
   rigid: the group's max_penetration; MuJoCo: -min dist after every step), and the energy drift
   |E(T) + D(T) - E(0)| / E(0) where the engine reports what its contacts dissipate (mechsys).

Usage: ``.venv/bin/python benches/compliant.py [--out docs/benchmarks.md] [--quick] [--pile 100]``.
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
from benchdoc import fmt_time, machine, timed, write_doc  # noqa: E402
from contacts import PILE_M, PILE_MU, PILE_R, _walls, ms_pile, pile_layout, run_mj_pile, run_ms_pile  # noqa: E402

import mechsys as ms  # noqa: E402

R, RHO, G = 0.01, 7800.0, 9.81
MASS = RHO * 4 / 3 * math.pi * R**3
STEEL = ms.Material(E=2.1e11, nu=0.3, density=RHO)
E_STAR = 1 / (2 * (1 - 0.09) / 2.1e11)


def ball(law, q0, u0, gravity):
    m = ms.Model("ball", gravity=(0, 0, -gravity))
    b = m.add_body("ball", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=q0, u0=u0))
    m.add_contact(ms.Contact("c", b.contour(ms.contours.Sphere(radius=R), material=STEEL),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=STEEL), normal=law))
    return m


def impact_rows(repeat):
    model = ball(ms.laws.Hertz(), R + 2e-4, -1.0, 0.0)
    k = 4 / 3 * E_STAR * math.sqrt(R)
    d_ref = (1.25 * MASS / k) ** 0.4
    rows = []
    for name, integ in (("DOPRI5 rtol 1e-8", ms.DOPRI5(rtol=1e-8, atol=1e-14)),
                        ("DOPRI5 rtol 1e-12", ms.DOPRI5(rtol=1e-12, atol=1e-16)),
                        ("Radau5 rtol 1e-8", ms.Radau5(rtol=1e-8, atol=1e-14)),
                        ("Radau5 rtol 1e-11", ms.Radau5(rtol=1e-11, atol=1e-16))):
        # timed with few samples (the recording would dominate), measured on a finely sampled run
        tmin, tmed, res = timed(lambda: ms.simulate(model, t_end=4e-4, output_dt=4e-5, integrator=integ, progress=False), repeat)
        d = ms.simulate(model, t_end=4e-4, output_dt=2e-8, integrator=integ, progress=False)["contact/c/overlap"]
        j = int(np.argmax(d))
        y0, y1, y2 = d[j - 1], d[j], d[j + 1]
        dmax = y1 - 0.125 * (y2 - y0) ** 2 / (y0 - 2 * y1 + y2)
        s = res.stats
        rows.append((name, s["steps"], s["rejected"], s["evaluations"], tmin, tmed, abs(dmax / d_ref - 1)))
        print(f"impact {name:20s} steps {s['steps']:5d} rejected {s['rejected']:4d} evals {s['evaluations']:6d} "
              f"{fmt_time(tmin)}  delta_max error {rows[-1][-1]:.1e}")
    return rows


def damped_rows(repeat):
    # pressed to twice its static overlap and let go: it creeps back to m g / k without lifting off
    model = ball(ms.laws.KelvinVoigt(k=1e9, d=1e4), R - 2 * MASS * G / 1e9, 0.0, G)
    rows = []
    for name, integ in (("DOPRI5 rtol 1e-6", ms.DOPRI5(rtol=1e-6, atol=1e-12)),
                        ("Radau5 rtol 1e-6", ms.Radau5(rtol=1e-6, atol=1e-12))):
        tmin, tmed, res = timed(lambda: ms.simulate(model, t_end=0.1, output_dt=1e-3, integrator=integ, progress=False), repeat)
        s = res.stats
        rest = res["contact/c/overlap"][-1]
        rows.append((name, s["steps"], s["rejected"], s["evaluations"], tmin, tmed, rest))
        print(f"damped {name:20s} steps {s['steps']:7d} rejected {s['rejected']:5d} evals {s['evaluations']:8d} {fmt_time(tmin)}  "
              f"rest overlap {rest:.4e} m (m g / k = {MASS * G / 1e9:.4e})")
    return rows


def compliant_pile(n, group=True):
    """The pile with compliant contacts: one compliant contact group (broad phase), or (group=False)
    every pair an explicit contact."""
    half, pos = pile_layout(n)
    mat = ms.Material(E=1e7, nu=0.3, density=PILE_M / (4 / 3 * math.pi * PILE_R**3))
    m = ms.Model(f"compliant-pile-{n}", gravity=(0, 0, -G))
    bodies = []
    for i, x in enumerate(pos):
        b = m.add_body(f"s{i}", PILE_M, ms.inertia.sphere(PILE_M, PILE_R))
        m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=[*x, 1, 0, 0, 0]))
        bodies.append(b)
    law = ms.laws.HuntCrossley(eps=0.3, v_reg=1e-3)
    fr = ms.laws.Coulomb(PILE_MU)
    if group:
        m.add_contact(ms.ContactGroup("pile", members=[b.contour(ms.contours.Sphere(radius=PILE_R)) for b in bodies],
                                      against=[m.ground.contour(ms.contours.Plane(point=p, normal=nrm)) for p, nrm in _walls(half)],
                                      normal=law, friction=fr, material=mat))
        m.build()
        return m
    for i in range(n):
        for j in range(i + 1, n):
            m.add_contact(ms.Contact(f"p{i}_{j}", bodies[i].contour(ms.contours.Sphere(radius=PILE_R), material=mat),
                                     bodies[j].contour(ms.contours.Sphere(radius=PILE_R), material=mat), normal=law, friction=fr))
        for k, (p, nrm) in enumerate(_walls(half)):
            m.add_contact(ms.Contact(f"w{i}_{k}", bodies[i].contour(ms.contours.Sphere(radius=PILE_R), material=mat),
                                     m.ground.contour(ms.contours.Plane(point=p, normal=nrm), material=mat), normal=law, friction=fr))
    m.build()
    return m


def compliant_row(n, t_end, group):
    model = compliant_pile(n, group)
    t0 = time.perf_counter()
    res = ms.simulate(model, t_end=t_end, output_dt=5e-3, integrator=ms.DOPRI5(rtol=1e-6, atol=1e-9), progress=False)
    el = time.perf_counter() - t0
    if group:
        pen = float(np.max(res["contact/pile/max_overlap"]))
        what = f"mechsys compliant group (Hunt-Crossley, DOPRI5 rtol 1e-6), N = {n}"
        note = f"{int(res['contact/pile/touching'][-1])} pairs touching at the end"
    else:
        pen = max(float(np.max(res[k])) for k in res.names() if k.endswith("/overlap"))
        what = f"mechsys compliant, explicit pairs (DOPRI5 rtol 1e-6), N = {n}, {len(model._contacts)} contacts"
        note = "onsets located"
    e = res["energy/total"] + res["energy/dissipated"]
    drift = abs(e[-1] - e[0]) / abs(e[0])
    z = res["q"][-1].reshape(n, 7)[:, 2]
    row = (what, el, pen, f"{drift:.1e}", float(z.mean()), f"{res.stats['steps']} steps, {res.stats['rejected']} rejected, {note}")
    print(f"pile {row}")
    return row


def pile_rows(n, t_end, explicit):
    rows = [compliant_row(n, t_end, True)]
    if explicit:
        # the same pile with every pair an explicit contact (N^2 cost), at a size that runs quickly,
        # next to the group at that size
        rows.append(compliant_row(explicit, t_end, True))
        rows.append(compliant_row(explicit, t_end, False))
    rigid = ms_pile(n)
    el, pen, zm, closed, _ = run_ms_pile(rigid, n, 1e-3, t_end, 1e-6, 100)
    rows.append((f"mechsys rigid (contact group, Moreau-Jean dt 1e-3, NSGS 1e-6), N = {n}", el, pen, "–", zm, f"{closed} points closed at the end"))
    print(f"pile {rows[-1]}")
    try:
        el, pen, zm, ncon, _ = run_mj_pile(n, 1e-3, t_end, "Newton")
        rows.append((f"MuJoCo (soft contacts, defaults, dt 1e-3), N = {n}", el, pen, "–", zm, f"{ncon} contacts at the end"))
        print(f"pile {rows[-1]}")
    except Exception as ex:  # noqa: BLE001 - a missing peer is reported, not fatal
        print(f"MuJoCo: {ex}")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--pile", type=int, default=100)
    ap.add_argument("--pile-time", type=float, default=0.3)
    ap.add_argument("--explicit", type=int, default=20, help="also run a pile of this size as explicit pairs (0: no)")
    a = ap.parse_args(argv)
    repeat = 1 if a.quick else a.repeat
    warnings.simplefilter("ignore")
    mach = machine()
    t_start = time.perf_counter()
    imp = impact_rows(repeat)
    damp = damped_rows(repeat)
    pile = pile_rows(a.pile, a.pile_time, a.explicit)
    whole = time.perf_counter() - t_start
    if a.out:
        try:
            import mujoco

            versions = f"mechsys {ms.__version__}, MuJoCo {mujoco.__version__}"
        except Exception:  # noqa: BLE001
            versions = f"mechsys {ms.__version__}"
        L = ["## Compliant contact (issue 19): Hertz impact, stiff damped contact, compliant pile", ""]
        L.append(f"Generated by `benches/compliant.py` (this section only). {time.strftime('%Y-%m-%d %H:%M')} on "
                 f"{mach['nproc']} × {mach['cpu']}; load average {mach['load'][0]:.2f} at the start "
                 f"(a shared 2-core machine: above ≈ 1 the times are preliminary); whole run {whole:.0f} s. {versions}.")
        L += ["", f"Command: `.venv/bin/python benches/compliant.py {' '.join(sys.argv[1:] if argv is None else argv)}`", "",
              "**Hertz impact** (steel ball R = 10 mm at 1 m/s on steel, one contact event of ≈ 70 µs; the run is "
              f"0.4 ms and holds that one event; min (median) of {repeat}):", "",
              "| integrator | steps | rejected | evaluations | wall time per contact event | δ_max error |",
              "|---|---:|---:|---:|---:|---:|"]
        for name, st, rj, ev, tmin, tmed, err in imp:
            L.append(f"| {name} | {st} | {rj} | {ev} | {fmt_time(tmin)} ({fmt_time(tmed)}) | {err:.1e} |")
        L += ["", "**Heavily damped stiff contact** (Kelvin–Voigt k = 1e9 N/m, d = 1e4 N s/m, the ball settling "
              "back from twice its static overlap for 0.1 s):", "",
              "| integrator | steps | rejected | evaluations | wall time | overlap at rest |", "|---|---:|---:|---:|---:|---:|"]
        for name, st, rj, ev, tmin, tmed, rest in damp:
            L.append(f"| {name} | {st} | {rj} | {ev} | {fmt_time(tmin)} ({fmt_time(tmed)}) | {rest:.4e} m |")
        L += ["", f"**Pile of {a.pile} spheres** (and of {a.explicit} for the explicit pairs), {a.pile_time:g} s simulated (one run each):", "",
              "| engine | wall time | largest penetration | energy drift (E + D − E0)/E0 | mean height at the end | notes |",
              "|---|---:|---:|---:|---:|---|"]
        for name, el, pen, drift, zm, note in pile:
            L.append(f"| {name} | {fmt_time(el)} | {pen:.2e} m | {drift} | {zm:.4f} m | {note} |")
        L += ["", "Reading the tables:", "",
              "- The impact's δ_max is within the tolerance's reach of the closed form because no step straddles "
              "the onset or the release (located switches); the damped case is stiff, and Radau5 needs a small "
              "fraction of DOPRI5's steps.",
              "- The compliant pile is one compliant contact group: at every right-hand side the broad phase "
              "(sweep and prune over the contours' boxes) keeps the pairs whose boxes overlap, and only those get "
              "the narrow phase and the Hertz–Hunt–Crossley force, so an evaluation costs O(N) instead of the "
              "N(N−1)/2 + 5N explicit pairs (5450 for N = 100, 1080 s before groups took compliant laws). Onsets "
              "in a group are stepped over under error control (Hertz forces are continuous at δ = 0), not "
              "located. Its penetration is the physical overlap of the soft material (E = 1e7 Pa), set by the "
              "material, not by a solver tolerance; MuJoCo's soft contacts penetrate by their solref time "
              "constant; mechsys' rigid pile by the Moreau–Jean step's drift. The steps follow the contacts' "
              "≈ 5 ms vibrations (DOPRI5 is explicit), which is what keeps it behind the time-stepping engines; "
              "per evaluation (≈ 95 µs for N = 100) `perf` puts the tree dynamics (ABA, forward kinematics) at "
              "about 45 % and the group's broad and narrow phases at about 12 %. "
              "Its energy balance (kinetic + potential + stored − work + dissipated) closes to the integrator's "
              "tolerance."]
        write_doc(a.out, "\n".join(L), "<!-- compliant.py:begin -->", "<!-- compliant.py:end -->")
        print(f"updated {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
