"""Campbell diagram of an elastic overhung rotor.

A steel shaft (0.4 m, 20 mm diameter) clamped in a rigid spindle carries a disc (5 kg, 0.2 m
diameter) at its free end. The shaft is an elastic body in the floating frame of reference, built
from the beam FE model with the disc as a rigid mass (`add_rigid_mass`: its gyroscopic coupling
and the tilt stiffening of a spinning disc enter the invariants and the geometric stiffness) and
reduced to its 6 lowest modes. The spindle turns at a prescribed speed; `ms.linear.linearize`
gives the modes about each steady spin.

The elastic coordinates turn with the shaft: an axisymmetric rotor's whirl at ω in the inertial
frame appears at |ω - Ω| (forward) or ω + Ω (backward) in them. The script plots the modes against
the spin with the analytic disc on a massless shaft seen the same way, and reports the forward
critical speed (forward whirl at 1x spin: it stands still in the rotating frame). As a model file it is the rotor spinning at 300 rad/s, released with its disc
displaced by 0.1 mm:

    mechsys run examples/elastic_rotor_campbell.py --plot results/rotor_q.png
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

import mechsys as ms
from mechsys import elastic as el

LENGTH, D_SHAFT = 0.4, 0.02
M_DISC, R_DISC = 5.0, 0.1
J_P, J_D = 0.5 * M_DISC * R_DISC**2, 0.25 * M_DISC * R_DISC**2
SHAFT = el.BeamSection.circle(D_SHAFT / 2, E=210e9, nu=0.3, rho=7850.0)
FE = el.add_rigid_mass(el.beam_model(SHAFT, LENGTH, 8), -1, M_DISC, (J_P, J_D, J_D))
ROTOR = el.modal_reduction(FE, 6, fixed={0: "clamped"}, name="rotor")


def build(spin: float) -> ms.Model:
    m = ms.Model("elastic_rotor")
    rotor = m.add_elastic_body("rotor", ROTOR, modal=0.002)
    m.add_joint(ms.joints.Revolute("spindle", m.ground, rotor, axis=(1, 0, 0), u0=[spin]))
    m.add_constraint(ms.constraints.Prescribed("drive", "spindle", ms.functions.Ramp(spin)))
    return m


# as a model file: released with the disc 0.1 mm off the axis (in its first bending mode)
_tip = ROTOR.modes[-1, 1, :]
_q0 = np.zeros(ROTOR.n_coordinates)
_q0[int(np.argmax(np.abs(_tip)))] = 1e-4 / _tip[int(np.argmax(np.abs(_tip)))]
model = build(300.0)
model._bodies[0]["elastic"]["q0"] = _q0.tolist()
simulation = dict(t_end=0.2, integrator=ms.DOPRI5(rtol=1e-9, atol=1e-12), output_dt=2e-4)


def analytic(spin: float) -> np.ndarray:
    """Inertial whirl frequencies (rad/s, backward then forward of each pair) of the rigid disc on a
    massless cantilever shaft: M x'' + spin G x' + K x = 0, x = (v, θ_z, w, θ_y)."""
    ei, l = SHAFT.E * SHAFT.Iz, LENGTH
    k = ei / l**3 * np.array([[12, -6 * l], [-6 * l, 4 * l**2]])
    stiff = np.zeros((4, 4))
    stiff[:2, :2] = k
    stiff[2:, 2:] = k * np.array([[1, -1], [-1, 1]])
    mass = np.diag([M_DISC, J_D, M_DISC, J_D])
    gyro = np.zeros((4, 4))
    gyro[1, 3], gyro[3, 1] = J_P * spin, -J_P * spin
    a = np.block([[np.zeros((4, 4)), np.eye(4)], [-np.linalg.solve(mass, stiff), -np.linalg.solve(mass, gyro)]])
    lam = np.linalg.eigvals(a)
    return np.sort(lam.imag[lam.imag > 0])


def campbell(spins):
    """Rotating-frame frequencies of the bending modes (Hz) at each spin, lowest four."""
    torsion = np.sqrt(SHAFT.G * SHAFT.Ip / LENGTH / J_P) / (2 * np.pi)
    out = []
    for s in spins:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f = np.sort(ms.linear.linearize(build(s)).modes().natural_frequency)
        out.append(f[np.abs(f - torsion) > 1e-3 * torsion][:4])
    return np.array(out)


if __name__ == "__main__":
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    spins = np.linspace(0.0, 1200.0, 25)
    rot = campbell(spins)
    ref = np.array([analytic(s) for s in spins]) / (2 * np.pi)
    # the analytic whirl seen from the shaft: backward b at b + Ω, forward f at |f - Ω|
    fig, ax = plt.subplots(figsize=(7, 5))
    hz = spins / (2 * np.pi)
    seen = np.column_stack([ref[:, 0] + hz, np.abs(ref[:, 1] - hz), ref[:, 2] + hz, np.abs(ref[:, 3] - hz)])
    for k, label in ((0, "backward 1"), (1, "forward 1"), (2, "backward 2"), (3, "forward 2")):
        ax.plot(hz, seen[:, k], "k--" if k % 2 == 0 else "k-", lw=0.8, label=f"disc on a massless shaft, {label}")
    for k in range(4):
        ax.plot(hz, rot[:, k], "C0o", ms=3, label="mechsys elastic rotor" if k == 0 else None)
    ax.set_xlabel("spin (Hz)")
    ax.set_ylabel("frequency in the rotating frame (Hz)")
    ax.set_ylim(0, 450)
    ax.legend(fontsize=7)
    fig.tight_layout()
    Path("results").mkdir(exist_ok=True)
    fig.savefig("results/elastic_rotor_campbell.png", dpi=120)
    # forward critical speed: where the forward whirl equals the spin, i.e. stands still in the
    # rotating frame (its rotating-frame frequency passes through zero)
    from scipy.optimize import brentq, minimize_scalar

    crit_ref = brentq(lambda s: analytic(s)[1] - s, 1.0, 5000.0)
    crit = minimize_scalar(lambda s: float(np.min(campbell([s])[0])), bounds=(0.8 * crit_ref, 1.2 * crit_ref),
                           method="bounded", options={"xatol": 1e-3}).x
    shaft_mass = SHAFT.rho * SHAFT.A * LENGTH
    print(f"first bending frequency at rest {ROTOR.frequencies()[0]:.3f} Hz (disc on a massless shaft: "
          f"{analytic(0.0)[0] / (2 * np.pi):.3f} Hz; the shaft itself weighs {shaft_mass:.3f} kg)")
    print(f"forward critical speed {crit:.2f} rad/s ({crit * 60 / (2 * np.pi):.0f} rpm); disc on a massless shaft "
          f"{crit_ref:.2f} rad/s")
    res = ms.simulate(model, **simulation)
    res.save("results/elastic_rotor.h5")
    print("wrote results/elastic_rotor_campbell.png, results/elastic_rotor.h5")
