"""A part hopping on a shaker table (a user gap function, section 2.2.7): the table moves up and
down as A sin(omega t) and is not a body of the model at all — the contact is written directly as
the gap between the part's height and the table's,

    g_N = lift - A sin(omega t),

an expression of the part's coordinate and time that the engine evaluates with exact derivatives.
The part rides on the table while the table pushes it, m (g - A omega^2 sin(omega t)) > 0, and
lifts off where the table falls faster than gravity, at sin(omega t*) = g / (A omega^2); then it
flies, lands (Newton's impact law, eps = 0.3) and hops again, the table's motion doing work on it.

Printed: the first lift-off against the closed form, the hops per second, the energy balance.
Plotted: the part's and the table's heights and the contact force.

    python examples/shaker_table.py
    mechsys run examples/shaker_table.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

AMPLITUDE, OMEGA, MASS, G = 0.002, 2 * np.pi * 15.0, 0.05, 9.81  # 2 mm at 15 Hz: A omega^2 = 1.8 g
EPS = 0.3

model = ms.Model("shaker-table", gravity=(0.0, -G, 0.0), planar=True)
part = model.add_body("part", MASS, ms.inertia.box(MASS, (0.02, 0.01, 0.02)))
# riding on the table at t = 0: at its height and with its speed
model.add_joint(ms.joints.Prismatic("lift", model.ground, part, axis=(0, 1, 0), q0=0.0, u0=AMPLITUDE * OMEGA))
model.add_contact(ms.GapContact("table", gap=f"lift - {AMPLITUDE} * sin({OMEGA} * t)", impact=ms.laws.Newton(eps=EPS)))

simulation = dict(t_end=0.5, integrator=ms.EventDriven(rtol=1e-9, atol=1e-12), output_dt=1e-4)

T_OFF = np.arcsin(G / (AMPLITUDE * OMEGA**2)) / OMEGA  # first lift-off


if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    opens = [e["t"] for e in res.events if e["event"] == "open"]
    impacts = [e for e in res.events if e["event"] == "impact"]
    print(f"first lift-off at t = {opens[0]:.9f} s (closed form {T_OFF:.9f} s)")
    print(f"{len(impacts)} landings in {simulation['t_end']} s; largest flight "
          f"{res['contact/table/g_n'].max() * 1e3:.3f} mm above the table")
    balance = res["energy/total"] + res["energy/dissipated"] - res["energy/external_work"]
    print(f"energy: the table's work {res['energy/external_work'][-1]:.4e} J, lost in impacts "
          f"{res['energy/dissipated'][-1]:.4e} J; balance drift {np.abs(balance - balance[0]).max():.2e} J")
    out = Path("results")
    out.mkdir(exist_ok=True)
    res.save(out / "shaker_table.h5")
    ms.plot(res, signals=["joint/lift/q", "contact/table/g_n", "contact/table/lambda_n"], out=out / "shaker_table.png")
