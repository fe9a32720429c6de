"""Gear rattle (involute gear contours, section 2.2.7.1): a spur gear pair with backlash whose
driving pinion turns at a fluctuating speed, omega1(t) = Omega + A sin(nu t), while the driven
wheel carries only a light resisting torque. When the pinion slows down faster than the load can
brake the wheel (z1/z2 A nu > T / J2), the wheel runs ahead, crosses the backlash and hammers on
the coast flanks; when the pinion speeds up again it catches the wheel on the drive flanks.

Both gears are exact involute contours (`ms.contours.Gear`) with thinned teeth; the contact keeps
two candidates (`points=2`): the closest tooth pair on the drive side and on the coast side, which
is every pair in mesh on that side (involute action: one line of action, one gap). The
event-driven scheme locates every impact; printed are the impacts per second on each side, the
dynamic transmission error (the wheel's lag behind the rigid ratio, along the line of action)
against the backlash band, and the contact forces and wheel speed are plotted.

The pinion's angle Omega t + (A/nu)(1 - cos nu t) is prescribed by two drives in series (a ramp
on a carrier, a harmonic of the pinion on the carrier), both with exact derivatives.

    python examples/gear_rattle.py
    mechsys run examples/gear_rattle.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

M, Z1, Z2 = 0.002, 17, 31  # module (m), teeth of pinion and wheel
ALPHA = np.radians(20.0)  # pressure angle
THIN = 0.05 * M  # each gear's teeth thinned by this on the pitch circle (backlash)
WIDTH, RHO = 0.01, 7850.0  # face width (m), steel (kg/m^3)
OMEGA, A, NU = 20.0, 2.0, 2 * np.pi * 25  # pinion speed (rad/s): mean, fluctuation, its frequency (rad/s)
LOAD = 0.005  # resisting torque on the wheel (N m)
EPS = 0.5  # Newton's restitution of a tooth impact

PINION = ms.contours.Gear(M, Z1, backlash=THIN)
WHEEL = ms.contours.Gear(M, Z2, backlash=THIN)
CENTER = ms.contours.gear_center_distance(Z1, Z2, M, ALPHA)  # standard: m (z1 + z2) / 2
MESH = ms.contours.gear_mesh(PINION, WHEEL, CENTER)
GEO1, GEO2 = PINION.geometry(), WHEEL.geometry()


def disc(z):
    """Mass and polar inertia of a steel disc of the gear's pitch diameter."""
    r = 0.5 * M * z
    mass = RHO * np.pi * r**2 * WIDTH
    return mass, ms.inertia.cylinder(mass, r, WIDTH, axis="z")


def wheel_angle_touching(theta1: float, gap: float = 0.0) -> float:
    """The wheel's angle with the drive flanks `gap` apart along the line of action when the pinion
    is at `theta1` (the flanks' roll angles on the line of action add up to a sin(alpha_w))."""
    aw = MESH.working_pressure_angle
    phi1 = GEO1.base_half_angle + aw + theta1
    phi2 = (CENTER * np.sin(aw) - gap - GEO1.base_radius * phi1) / GEO2.base_radius
    return np.pi - aw + phi2 - GEO2.base_half_angle


def build(load: float = LOAD, amplitude: float = A) -> ms.Model:
    m = ms.Model("gear-rattle", gravity=(0.0, 0.0, 0.0), planar=True)
    carrier = m.add_body("carrier", 1e-3, ms.inertia.cylinder(1e-3, 0.005, 0.005, axis="z"))
    pinion = m.add_body("pinion", *disc(Z1))
    wheel = m.add_body("wheel", *disc(Z2))
    m.add_joint(ms.joints.Revolute("motor_shaft", m.ground, carrier, axis=(0, 0, 1)))
    m.add_joint(ms.joints.Revolute("pinion_shaft", carrier, pinion, axis=(0, 0, 1)))
    # start on the drive flanks at the mean speed ratio
    m.add_joint(ms.joints.Revolute("wheel_shaft", m.ground, wheel, parent_frame=(CENTER, 0, 0), axis=(0, 0, 1),
                                   q0=[wheel_angle_touching(0.0)], u0=[-OMEGA * Z1 / Z2]))
    m.add_constraint(ms.constraints.Prescribed("motor", "motor_shaft", ms.functions.Ramp(slope=OMEGA)))
    # (A/nu)(1 - cos nu t) = A/nu + (A/nu) sin(nu t - pi/2): the pinion's speed relative to the carrier is A sin(nu t)
    m.add_constraint(ms.constraints.Prescribed("flutter", "pinion_shaft", ms.functions.Harmonic(
        amplitude=amplitude / NU, omega=NU, phase=-np.pi / 2, offset=amplitude / NU)))
    m.add_force(ms.forces.JointForce("load", "wheel_shaft", value=load))
    m.add_contact(ms.Contact("mesh", pinion.contour(PINION), wheel.contour(WHEEL), points=2,
                             impact=ms.laws.Newton(eps=EPS)))
    return m


model = build()
simulation = dict(t_end=0.4, integrator=ms.EventDriven(velocity_tol=1e-6), output_dt=1e-4)


def transmission_error(res) -> np.ndarray:
    """Dynamic transmission error along the line of action (m): how far the wheel runs ahead of the
    rigid ratio, -(r_b1 theta1 + r_b2 theta2) from its value with the drive flanks touching (the
    gap of the drive flanks): 0 on the drive flanks, the normal backlash on the coast flanks."""
    theta1 = res["joint/motor_shaft/q"] + res["joint/pinion_shaft/q"]
    theta2 = res["joint/wheel_shaft/q"]
    return -(GEO1.base_radius * theta1 + GEO2.base_radius * (theta2 - wheel_angle_touching(0.0)))


def impacts(res) -> dict:
    """Impacts from the event log per flank side (the contact's candidate 1: the pinion's upper,
    driving flanks; candidate 0: its lower, coast flanks), and the strokes: impacts on the side
    opposite to the previous one (the wheel crossing the backlash; the rest are the bounces of an
    accumulation that settles on a flank)."""
    hits = [e for e in res.events if e["contact"] == "mesh" and e["event"] == "impact"]
    out = {"drive": 0, "coast": 0, "strokes": 0}
    last = 1  # starts on the drive flanks
    for e in hits:
        out["drive" if e["point"] == 1 else "coast"] += 1
        out["strokes"] += e["point"] != last
        last = e["point"]
    return out


if __name__ == "__main__":
    print(f"pinion z1 = {Z1}, wheel z2 = {Z2}, m = {M * 1e3:.1f} mm, centre distance {CENTER * 1e3:.3f} mm, "
          f"contact ratio {MESH.contact_ratio:.3f}, normal backlash {MESH.normal_backlash * 1e6:.1f} um")
    j2 = disc(Z2)[1][2][2]
    print(f"the wheel separates when z1/z2 A nu = {Z1 / Z2 * A * NU:.0f} rad/s^2 exceeds T/J2 = {LOAD / j2:.0f} rad/s^2")
    res = ms.simulate(model, **simulation)
    n = impacts(res)
    span = res.t[-1] - res.t[0]
    print(f"impacts: {n['drive'] / span:.0f} per second on the drive flanks, {n['coast'] / span:.0f} on the coast flanks "
          f"({n['drive'] + n['coast']} in {span:.2f} s); {n['strokes'] / span:.0f} strokes per second across the backlash "
          f"(speed fluctuation {NU / (2 * np.pi):.0f} Hz)")
    dte = transmission_error(res)
    print(f"dynamic transmission error {dte.min() * 1e6:.2f} to {dte.max() * 1e6:.2f} um "
          f"(backlash band 0 to {MESH.normal_backlash * 1e6:.2f} um)")
    Path("results").mkdir(exist_ok=True)
    res.save("results/gear_rattle.h5")
    ms.plot(res, ["contact/mesh/lambda_n", "joint/wheel_shaft/u", "contact/mesh/g_n"], out="results/gear_rattle.png")
    print("wrote results/gear_rattle.h5, results/gear_rattle.png")
