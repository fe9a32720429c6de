"""Rigid and compliant contacts in one event-driven run: a soft ball on a spring bounces on the
floor through a damped Hertz contact (its force acts in the smooth phases; each onset and release
is located like in DOPRI5, without a transition), while beside it a hard ball falls 0.25 m onto
the floor with Newton's impact law (e = 0.5; impacts, transitions and the accumulation of its
bounces handled by the event-driven scheme). Printed: the hard ball's impact times against
t1 (1 + 2e + ... + 2e^(k-1)), the soft ball's contact events, and the energy balance.

    python examples/mixed_contacts.py
    mechsys run examples/mixed_contacts.py --plot mixed.png --signals joint/za/q,joint/zb/q,contact/soft_floor/force_n
"""

import math

import numpy as np

import mechsys as ms

R, M, G = 0.05, 0.2, 9.81
SOFT = ms.Material(E=1e7, nu=0.3, density=1000.0)
EPS, H0 = 0.5, 0.25


def build() -> ms.Model:
    m = ms.Model("mixed-contacts", gravity=(0, 0, -G))
    a = m.add_body("soft", M, ms.inertia.sphere(M, R))
    m.add_joint(ms.joints.Prismatic("za", m.ground, a, axis=(0, 0, 1), q0=0.15, spring=ms.joints.JointSpring(k=40.0)))
    b = m.add_body("hard", M, ms.inertia.sphere(M, R))
    m.add_joint(ms.joints.Prismatic("zb", m.ground, b, axis=(0, 0, 1), q0=R + H0))
    m.add_contact(ms.Contact("soft_floor", a.contour(ms.contours.Sphere(radius=R), material=SOFT),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=SOFT),
                             normal=ms.laws.Hertz(alpha=0.4)))
    m.add_contact(ms.Contact("hard_floor", b.contour(ms.contours.Sphere(radius=R)),
                             m.ground.contour(ms.contours.Plane(point=(1, 0, 0), normal=(0, 0, 1))),
                             impact=ms.laws.Newton(eps=EPS)))
    return m


model = build()
simulation = dict(t_end=1.0, output_dt=1e-3, integrator=ms.EventDriven(rtol=1e-10, atol=1e-13))

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    t1 = math.sqrt(2 * H0 / G)
    hits = [e["t"] for e in res.events if e["contact"] == "hard_floor" and e["event"] == "impact"][:4]
    for k, t in enumerate(hits):
        ref = t1 * (1 + sum(2 * EPS**j for j in range(1, k + 1)))
        print(f"hard ball impact {k + 1}: t = {t:.9f} s (closed form {ref:.9f} s)")
    soft = [(e["t"], e["event"]) for e in res.events if e["contact"] == "soft_floor"]
    print(f"soft ball: {len(soft)} contact events, the first {soft[:2]}")
    e = res["energy/total"] + res["energy/dissipated"]
    print(f"energy balance: |E + D - E0| / E0 = {np.abs(e - e[0]).max() / abs(e[0]):.1e}")
    ms.plot(res, ["joint/za/q", "joint/zb/q", "contact/soft_floor/force_n"])
