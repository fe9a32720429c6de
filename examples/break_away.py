"""Contact transitions driven slowly by forces (reference text 2.5.2): a 1 kg block rests on a
rough floor (static coefficient 0.6, sliding 0.4). A horizontal push rising as F_x = t N holds it
in stick until the friction reserve mu0 m g - |lambda_T| is used up at t = mu0 m g / 1 N/s =
5.886 s; it then slides, with the sliding coefficient. From t = 6 s a vertical pull rising as
2 (t - 6) N unloads the floor: the normal force reaches zero and the block lifts off at
t = 6 + g / 2 = 10.905 s.

Both contact schemes are run: the event-driven one locates each transition by its indicator (the
reserve, then the normal force) and records the events; Moreau-Jean time-stepping finds them
within a step. Printed: each scheme's event log beside the closed-form times, and the sliding
distance at lift-off against the closed form. Run it with `python examples/break_away.py` or
`mechsys run examples/break_away.py`.
"""

from pathlib import Path

import numpy as np
from scipy.integrate import quad

import mechsys as ms

G, MU0, MU, PUSH, PULL, T_PULL = 9.81, 0.6, 0.4, 1.0, 2.0, 6.0
T_BREAK = MU0 * G / PUSH
T_LIFT = T_PULL + G / PULL

model = ms.Model("break-away", gravity=(0.0, -G, 0.0))
block = model.add_body("block", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
model.add_joint(ms.joints.Planar("slide", model.ground, block))
model.add_contact(ms.Contact("floor", block.contour(ms.contours.Point()),
                             model.ground.contour(ms.contours.Line(normal=(0, 1, 0))),
                             friction=ms.laws.Coulomb(mu=MU, mu0=MU0)))
model.add_force(ms.forces.JointForce("push", "slide", value=[PUSH, 0.0, 0.0], function=ms.functions.Ramp(1.0)))
model.add_force(ms.forces.JointForce("pull", "slide", value=[0.0, PULL, 0.0], function=ms.functions.Ramp(1.0, t0=T_PULL)))

simulation = dict(t_end=11.5, integrator=ms.EventDriven(), output_dt=1e-3)


def slide_at_lift_off() -> float:
    """x(T_LIFT) in closed form: a = F_x - mu (m g - F_y) from the break-away, integrated twice."""
    acc = lambda t: PUSH * t - MU * (G - PULL * max(t - T_PULL, 0.0))  # noqa: E731
    vel = lambda t: quad(acc, T_BREAK, t, points=[T_PULL])[0]  # noqa: E731
    return quad(vel, T_BREAK, T_LIFT, points=[T_PULL], epsabs=1e-13)[0]


if __name__ == "__main__":
    x_lift = slide_at_lift_off()
    print(f"closed form: slip at {T_BREAK:.6f} s, lift-off at {T_LIFT:.6f} s after sliding {x_lift:.6f} m")
    out = Path("results")
    out.mkdir(exist_ok=True)
    for name, integrator in (("event-driven", ms.EventDriven()), ("Moreau-Jean, dt = 1e-4", ms.MoreauJean(dt=1e-4))):
        res = ms.simulate(model, **dict(simulation, integrator=integrator))
        events = [e for e in res.events if e["t"] > 0.0]
        print(f"{name}:")
        for e in events:
            print(f"  {e['t']:.6f} s  {e['contact']}  {e['event']}")
        x = float(np.interp(T_LIFT, res.t, res["joint/slide/q"][:, 0]))
        print(f"  slid {x:.6f} m by the closed-form lift-off (error {x - x_lift:+.1e} m); smallest normal force on record "
              f"{res['contact/floor/lambda_n'].min():.2e} N, smallest friction reserve while sticking "
              f"{res['contact/floor/friction_reserve'][res['contact/floor/state'] == 1].min():.2e} N")
        if integrator == simulation["integrator"]:
            res.save(out / "break_away.h5")
            ms.plot(res, ["joint/slide/q", "contact/floor/lambda_n", "contact/floor/lambda_t", "contact/floor/friction_reserve"],
                    out=out / "break_away.png")
    print(f"wrote {out / 'break_away.h5'}, {out / 'break_away.png'}")
