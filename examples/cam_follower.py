"""A cam-follower valve train (parametric contours, section 2.2.7.1): a cam disc driven at constant
speed lifts a roller follower against a preloaded spring. The cam's profile is built from its lift
table, h = H (1 - cos theta) / 2, as the pitch curve offset inward by the roller radius, and the
contact between roller and cam is found on the cam's parameter at every evaluation.

While the roller stays on the cam, the follower's vertical force balance gives the contact force
m omega^2 h''(theta) + k (h + preload deflection) + m g, which is least at full lift (theta = pi,
h'' = -H / 2): the roller lifts off above the critical speed

    omega_c = sqrt(2 (k H + F0 + m g) / (m H)).

The model runs below and above omega_c (event-driven: lift-off is located where the normal force
reaches zero); printed are the lift against the table, the contact force against the closed form
and whether and where the roller left the cam.

    python examples/cam_follower.py
    mechsys run examples/cam_follower.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

BASE, ROLLER, LIFT = 0.03, 0.01, 0.008  # base circle, roller radius, total lift (m)
MASS, K, PRELOAD, G = 0.2, 2000.0, 20.0, 9.81  # follower mass (kg), spring (N/m), preload at base (N)
ANCHOR = 0.1  # the spring pulls the follower towards a point this far below the cam centre (m)
OMEGA_C = np.sqrt(2 * (K * LIFT + PRELOAD + MASS * G) / (MASS * LIFT))


def lift(theta):
    return 0.5 * LIFT * (1 - np.cos(theta))


def build(omega: float) -> ms.Model:
    m = ms.Model("cam-follower", gravity=(0.0, -G, 0.0), planar=True)
    cam = m.add_body("cam", 1.0, ms.inertia.cylinder(1.0, BASE, 0.01, axis="z"))
    follower = m.add_body("follower", MASS, ms.inertia.box(MASS, (0.01, 0.02, 0.01)))
    m.add_joint(ms.joints.Revolute("shaft", m.ground, cam, axis=(0, 0, 1)))
    y0 = BASE + ROLLER  # roller centre on the base circle
    m.add_joint(ms.joints.Prismatic("guide", m.ground, follower, axis=(0, 1, 0), q0=y0))
    m.add_constraint(ms.constraints.Prescribed("motor", "shaft", ms.functions.Ramp(slope=omega)))
    # a spring from below the cam: its tension at the base circle is the preload
    l_base = y0 + ANCHOR
    m.add_force(ms.forces.SpringDamper("spring", m.ground, follower, point1=(0, -ANCHOR, 0), k=K, l0=l_base - PRELOAD / K))
    profile = ms.contours.Cam(lift=lift, base_radius=BASE, follower="roller", roller_radius=ROLLER, samples=360)
    m.add_contact(ms.Contact("cam", follower.contour(ms.contours.Circle(radius=ROLLER)), cam.contour(profile),
                             impact=ms.laws.Newton(eps=0.0)))
    return m


model = build(0.9 * OMEGA_C)
simulation = dict(t_end=2 * 2 * np.pi / (0.9 * OMEGA_C), integrator=ms.EventDriven(), output_dt=1e-5)


def contact_force_closed_form(res) -> np.ndarray:
    """Vertical contact force while the roller follows the cam: m omega^2 h'' + k h + F0 + m g."""
    omega = np.gradient(res["joint/shaft/q"], res.t)
    theta = res["joint/shaft/q"]
    hdd = 0.5 * LIFT * np.cos(theta) * omega**2
    return MASS * hdd + K * lift(theta) + PRELOAD + MASS * G


def contact_force_closed_form_min(omega: float) -> float:
    """Least contact force, at full lift: -m omega^2 H / 2 + k H + F0 + m g."""
    return -MASS * omega**2 * LIFT / 2 + K * LIFT + PRELOAD + MASS * G


def report(res, omega: float) -> dict:
    theta = res["joint/shaft/q"]
    y = res["joint/guide/q"] - (BASE + ROLLER)
    gap = res["contact/cam/g_n"]
    lam = res["contact/cam/lambda_n"]
    n = res["contact/cam/normal"]
    closed = gap < 1e-7
    follow_err = np.abs(y - lift(theta))[closed].max()
    f_y = lam * np.abs(n[:, 1])
    f_err = np.abs(f_y - contact_force_closed_form(res))[closed][5:-5].max()
    out = dict(omega=omega, follow_error=follow_err, force_error=f_err, max_gap=gap.max(), min_force=f_y[closed].min())
    opens = [e["t"] for e in res.events if e["contact"] == "cam" and e["event"] == "open" and e["t"] > 0]
    if opens:
        # the roller leaves where the normal force has fallen to zero (event-driven: located exactly)
        out["lift_off_angle"] = float(np.mod(omega * opens[0], 2 * np.pi))
    return out


def lift_off_angle(omega: float) -> float:
    """Where m omega^2 h'' + k h + F0 + m g first vanishes: cos(theta) = -(k H / 2 + F0 + m g) / (H / 2 (m omega^2 - k))."""
    c = -(0.5 * K * LIFT + PRELOAD + MASS * G) / (0.5 * LIFT * (MASS * omega**2 - K))
    return float(np.arccos(c)) if abs(c) <= 1 else float("nan")


if __name__ == "__main__":
    print(f"critical speed {OMEGA_C:.2f} rad/s ({OMEGA_C * 30 / np.pi:.0f} rpm)")
    Path("results").mkdir(exist_ok=True)
    for factor in (0.9, 1.15):
        omega = factor * OMEGA_C
        res = ms.simulate(build(omega), t_end=2 * 2 * np.pi / omega, integrator=ms.EventDriven(), output_dt=1e-5)
        r = report(res, omega)
        if "lift_off_angle" in r:
            print(f"omega = {factor:.2f} omega_c: the roller lifts off at cam angle {np.degrees(r['lift_off_angle']):.5f} deg "
                  f"(closed form {np.degrees(lift_off_angle(omega)):.5f} deg), largest gap {r['max_gap'] * 1e3:.3f} mm")
        else:
            print(f"omega = {factor:.2f} omega_c: stays on the cam: lift vs table {r['follow_error']:.1e} m, contact force "
                  f"vs closed form {r['force_error']:.1e} N, least force {r['min_force']:.2f} N "
                  f"(closed form {contact_force_closed_form_min(omega):.2f} N)")
        tag = f"{factor:.2f}".replace(".", "_")
        res.save(f"results/cam_follower_{tag}.h5")
        ms.plot(res, ["joint/guide/q", "contact/cam/g_n", "contact/cam/lambda_n", "contact/cam/point"],
                out=f"results/cam_follower_{tag}.png")
    print("wrote results/cam_follower_*.h5, results/cam_follower_*.png")
