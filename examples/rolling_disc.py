"""A coin rolling without slipping (non-holonomic constraint): started in the steady state of a
lean theta and precession rate Omega it runs on a circle; the relation between spin, precession
and lean is the closed form below. A second run with 10 % more spin nods (nutation) about the
steady lean. Rolling does no work, so the energy is conserved in both.

Steady rolling of a thin disc (I_axis = m R^2/2, I_diameter = m R^2/4), spin n = omega . axis:
    Omega cos(theta) (6 n - Omega sin(theta)) + 4 g sin(theta) / R = 0.
"""

from pathlib import Path

import numpy as np

import mechsys as ms

G, R, MASS = 9.81, 0.2, 1.5
THETA, OMEGA = 0.3, 2.0  # lean from the vertical (rad), precession rate (rad/s)


def coin(spin_factor: float = 1.0) -> ms.Model:
    n = spin_factor * (OMEGA * np.sin(THETA) - 4 * G * np.tan(THETA) / (R * OMEGA)) / 6
    e1, e2, ez = np.eye(3)
    h = np.cos(THETA) * ez - np.sin(THETA) * e1  # contact point -> centre
    a = np.sin(THETA) * ez + np.cos(THETA) * e1  # disc axis
    rot = np.column_stack([h, np.cross(a, h), a])  # body axes x = h, z = a
    omega = OMEGA * ez + (n - OMEGA * np.sin(THETA)) * a
    v_centre = -R * n * e2
    m = ms.Model("rolling-coin", gravity=(0.0, 0.0, -G))
    disc = m.add_body("coin", MASS, ms.inertia.disc(MASS, R))
    quat = ms.kinematics.matrix_to_quat(rot)
    m.add_joint(ms.joints.Free("float", m.ground, disc, q0=[*(R * h), *quat], u0=[*(rot.T @ v_centre), *(rot.T @ omega)]))
    m.add_constraint(ms.constraints.RollingDisc("roll", disc, radius=R, axis=(0, 0, 1)))
    return m


model = coin()
simulation = dict(t_end=3 * 2 * np.pi / OMEGA, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01)

if __name__ == "__main__":
    for label, m in (("steady", model), ("10 % more spin", coin(1.1))):
        res = ms.simulate(m, **simulation)
        axis = np.array([ms.kinematics.quat_to_matrix(q)[:, 2] for q in res["body/coin/orientation"]])
        lean = np.arcsin(axis[:, 2])
        e = res["energy/total"]
        print(f"{label:15s} lean {np.degrees(lean.min()):7.3f}° .. {np.degrees(lean.max()):7.3f}° "
              f"(steady {np.degrees(THETA):.3f}°); energy drift {np.ptp(e) / np.abs(e).max():.1e}; "
              f"contact height max {np.abs(res['constraint/roll/violation']).max():.1e} m")
    res = ms.simulate(model, **simulation)
    Path("results").mkdir(exist_ok=True)
    res.save("results/rolling_disc.h5")
    ms.plot(res, ["body/coin/position", "constraint/roll/lambda", "energy/total"], out="results/rolling_disc.png")
    print("wrote results/rolling_disc.h5, results/rolling_disc.png")
