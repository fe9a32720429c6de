"""A gyroscopic rotor and its Campbell diagram (linear analysis, section 2.6.2).

A disc (polar inertia I_p, diametral I_d) spins about its axis z at the end of a shaft that tilts
elastically: the tilts alpha about x and beta about y are Cardan joints with rotary springs k_t
(the shaft's bending stiffness at the disc) and light rotary dampers; the spin joint is free.
At a spin speed W the disc's gyroscopic moments couple the two tilts (the skew matrix G of eq.
2.204), and the tilt mode splits into a forward whirl (the disc axis orbits with the spin) and a
backward whirl (against it):

    w_f,b = (+- W I_p + sqrt(W^2 I_p^2 + 4 I_d k_t)) / (2 I_d).

With I_p < I_d (a long rotor) both branches cross the 1x line: the backward whirl at
W = sqrt(k_t / (I_d + I_p)), the forward one at W = sqrt(k_t / (I_d - I_p)).

Runs on its own (prints the modes at standstill and at 300 rad/s, checks the whirl frequencies
against the formula and writes results/rotor_campbell.png) and as a model file:

    mechsys linear examples/rotor_campbell.py --campbell spin:0:600:61 --whirl alpha,beta
    mechsys run examples/rotor_campbell.py     # the whirl of the spinning rotor after a tilt
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mechsys as ms

IP, ID = 0.02, 0.05  # disc inertia about its axis and about a diameter (kg m^2)
KT, DT = 2000.0, 0.05  # tilt stiffness (N m/rad) and damping (N m s/rad) of the shaft at the disc


def build(spin: float = 0.0) -> ms.Model:
    m = ms.Model("rotor", gravity=(0.0, 0.0, 0.0))
    # the gimbal bodies only carry the tilt axes: their inertia (1e-9 kg m^2) is negligible
    g1 = m.add_body("gimbal_x", 1e-3, [1e-9] * 3)
    g2 = m.add_body("gimbal_y", 1e-3, [1e-9] * 3)
    disc = m.add_body("disc", 8.0, [ID, ID, IP])
    tilt = dict(spring=ms.joints.JointSpring(KT), damper=ms.joints.JointDamper(DT))
    m.add_joint(ms.joints.Revolute("alpha", m.ground, g1, axis=(1, 0, 0), **tilt))
    m.add_joint(ms.joints.Revolute("beta", g1, g2, axis=(0, 1, 0), **tilt))
    m.add_joint(ms.joints.Revolute("spin", g2, disc, axis=(0, 0, 1), u0=spin))
    return m


def whirl_frequencies(speed: float) -> tuple[float, float]:
    """Forward and backward whirl frequencies (Hz) of the undamped rotor."""
    root = np.sqrt((speed * IP) ** 2 + 4 * ID * KT)
    return (abs(speed) * IP + root) / (2 * ID) / (2 * np.pi), (root - abs(speed) * IP) / (2 * ID) / (2 * np.pi)


model = build()
# `mechsys run examples/rotor_campbell.py`: released tilted by 10 mrad about x while spinning at
# 300 rad/s, the disc axis whirls (forward and backward whirl superposed) and the dampers take it out
simulation = dict(t_end=1.0, integrator=ms.DOPRI5(rtol=1e-9, atol=1e-12), output_dt=1e-3,
                  q0={"alpha": 0.01}, u0={"spin": 300.0})

if __name__ == "__main__":
    lin = ms.linear.linearize(model)
    print("standstill (the spin's rigid-body mode has zero frequency):")
    print(lin.modes().table())
    spinning = ms.linear.linearize(build(spin=300.0))
    print("\nat 300 rad/s: G =\n", np.array2string(spinning.G, precision=4))
    print(spinning.modes().table())

    speeds = np.linspace(0.0, 600.0, 61)
    camp = lin.campbell(speeds, joint="spin", whirl=("alpha", "beta"))
    worst = 0.0
    for k, w in enumerate(speeds):
        ff, fb = whirl_frequencies(w)
        got = dict(zip(camp.whirl[k], camp.frequencies[k])) if w else {"forward": max(camp.frequencies[k]), "backward": min(camp.frequencies[k])}
        worst = max(worst, abs(got["forward"] / ff - 1), abs(got["backward"] / fb - 1))
    print(f"\nwhirl frequencies against the undamped formula: largest relative difference {worst:.1e} (damping zeta ~ 0.002)")
    for cs in camp.critical_speeds():
        exact = np.sqrt(KT / (ID + IP)) if cs["whirl"] == "backward" else np.sqrt(KT / (ID - IP))
        print(f"critical speed, {cs['whirl']:8s} whirl: {cs['speed']:8.2f} rad/s (formula {exact:8.2f} rad/s)")
    out = Path("results") / "rotor_campbell.png"
    camp.plot(out=out, orders=(1, 2), title="Gyroscopic rotor: Campbell diagram")
    print(f"Campbell diagram: {out}")
