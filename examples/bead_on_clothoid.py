"""A roller-coaster car entering a clothoid loop (path coordinates, section 2.2.6): the track in a
vertical plane is an Euler spiral, its curvature growing linearly from zero, kappa = s / A^2, and
the arc length s along it is the generalized coordinate. The car (a point mass, turning with the
track's frame [t n b]) comes off the straight at speed v0 and climbs into the loop. Because the
curvature starts at zero the track's push on the car rises smoothly from m g; a circular loop of
the same radius at the top would add m v0^2 / R at once at its entry. The push is the
Frenet-frame equation m (kappa v^2 - g . n) along n and nothing along t (no friction); both are
printed against the run, with the energy drift.

    python examples/bead_on_clothoid.py
    mechsys run examples/bead_on_clothoid.py
"""

from pathlib import Path

import numpy as np

import mechsys as ms

A, MASS, G, V0 = 2.0, 500.0, 9.81, 8.0  # clothoid parameter (m), car (kg), gravity, entry speed (m/s)

model = ms.Model("clothoid-loop", gravity=(0.0, -G, 0.0))
car = model.add_body("car", MASS, np.zeros((3, 3)))
track = model.add_joint(ms.joints.Path.clothoid("track", model.ground, car, A=A, oriented=True, u0=V0))

simulation = dict(t_end=1.2, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=2e-3)

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    s, v, a = res["joint/track/q"], res["joint/track/u"], res["joint/track/udot"]
    geo = track.geometry(s)
    kappa, t_hat, n_hat = geo["curvature"], geo["frame"][:, :, 0], geo["frame"][:, :, 1]
    g = np.array([0.0, -G, 0.0])
    # the track's force on the car, in the track's axes [t n b] (the child frame turns with them)
    f = res["joint/track/reaction_force"]
    f_n = MASS * (kappa * v**2 - n_hat @ g)  # eq. 2.74 along n: m kappa s'^2 = F_n + m g . n
    print(f"top of the loop (tangent angle pi) at s = {np.sqrt(2 * np.pi) * A:.3f} m, radius there "
          f"{1 / (np.sqrt(2 * np.pi) / A):.3f} m; the car reaches s = {s[-1]:.3f} m")
    print(f"tangential acceleration against g . t: max error {np.abs(a - t_hat @ g).max():.2e} m/s^2")
    print(f"normal force against m (kappa v^2 - g . n): max error {np.abs(f[:, 1] - f_n).max():.2e} N; "
          f"along t and b at most {np.abs(f[:, [0, 2]]).max():.2e} N")
    print(f"normal force: {f[0, 1] / (MASS * G):.3f} g at the entry, at most {f[:, 1].max() / (MASS * G):.2f} g; "
          f"largest jump between samples {np.abs(np.diff(f[:, 1])).max() / (MASS * G):.3f} g "
          f"(a circular loop of the top's radius: {V0**2 * np.sqrt(2 * np.pi) / A / G:.2f} g at once)")
    print(f"energy drift {np.ptp(res['energy/total']) / res['energy/total'][0]:.1e} (relative)")
    Path("results").mkdir(exist_ok=True)
    res.save("results/bead_on_clothoid.h5")
    ms.plot(res, ["joint/track/q", "joint/track/u", "joint/track/reaction_force", "joint/track/normal_acceleration",
                  "body/car/position", "energy/total"], out="results/bead_on_clothoid.png")
    print("wrote results/bead_on_clothoid.h5, results/bead_on_clothoid.png")
