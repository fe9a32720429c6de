"""A ball rocking in a spherical bowl on a compliant contact layer: linearized sliding and rolling,
then simulated (section 2.6 with a compliant Signorini contact, section 2.5.5).

A steel-like ball (radius r = 5 cm, 1 kg) rests at the bottom of a bowl of radius R = 0.5 m. The
contact is a Signorini law with a layer of k = 1e7 N/m in series (``laws.Signorini(compliance=1e-7)``)
and Coulomb friction 0.8. Linearized at rest with the contact held:

- ``contacts="hold"``: the layer is its spring along the normal and the ball slides without
  friction: it rocks at omega^2 = g / (R - r), and bounces on the layer at omega^2 = k / m;
- ``contacts="roll"``: the layer carries the normal force and a tangents-only bilateral contact
  (``bowl_rolling``) holds the ball from slipping: it rocks at omega^2 = 5 g / (7 (R - r)), the
  rolling ball's (its rotational inertia 2/5 m r^2 adds 2/5 to its mass), and bounces as before.

Then the model runs as it is (the contact unilateral, Moreau-Jean), released 2 cm to the side:
the ball rolls to and fro at the rolling frequency.

    python examples/bowl_layer_modes.py
    mechsys run examples/bowl_layer_modes.py
    mechsys linear examples/bowl_layer_modes.py --contacts roll
"""

from pathlib import Path

import numpy as np

import mechsys as ms

G, MASS, R_BALL, R_BOWL, COMPLIANCE, MU = 9.81, 1.0, 0.05, 0.5, 1e-7, 0.8
SIDE = 0.02  # initial sideways offset of the simulation (m)
ROCK_SLIDE = np.sqrt(G / (R_BOWL - R_BALL))
ROCK_ROLL = np.sqrt(5 * G / (7 * (R_BOWL - R_BALL)))
BOUNCE = np.sqrt(1.0 / (COMPLIANCE * MASS))


def placed(side: float = 0.0) -> list[float]:
    """The ball's free-joint coordinates resting on its layer (overlap c m g), `side` along x."""
    rho = R_BOWL - R_BALL + COMPLIANCE * MASS * G  # the centre's distance from the bowl's centre
    angle = side / rho
    return [rho * np.sin(angle), 0.0, -rho * np.cos(angle), 1.0, 0.0, 0.0, 0.0]


def build() -> ms.Model:
    """The ball in the bowl, at rest at its bottom on the layer."""
    m = ms.Model("bowl-layer", gravity=(0.0, 0.0, -G))
    ball = m.add_body("ball", MASS, ms.inertia.sphere(MASS, R_BALL))
    m.add_joint(ms.joints.Free("free", m.ground, ball, q0=placed(0.0)))
    m.add_contact(ms.Contact("bowl", ball.contour(ms.contours.Sphere(radius=R_BALL)),
                             m.ground.contour(ms.contours.Bowl(radius=R_BOWL)),
                             normal=ms.laws.Signorini(compliance=COMPLIANCE), friction=ms.laws.Coulomb(MU)))
    return m


# at rest (what `mechsys linear` linearizes about); the run starts SIDE aside
model = build()
simulation = dict(t_end=2 * 2 * np.pi / ROCK_ROLL, integrator=ms.MoreauJean(1e-4), output_dt=1e-3,
                  q0={"free": placed(SIDE)})


if __name__ == "__main__":
    rest = build()
    for mode, rock in (("hold", ROCK_SLIDE), ("roll", ROCK_ROLL)):
        lin = ms.linear.linearize(rest, contacts=mode)
        f = np.sort(lin.modes().natural_frequency)
        print(f"linearized, contact {mode!r}: rocking {f[-2]:.6f} Hz (closed form {rock / (2 * np.pi):.6f}), "
              f"bounce {f[-1]:.3f} Hz (closed form {BOUNCE / (2 * np.pi):.3f}); held: "
              f"{[c['name'] for c in lin.model.engine()[0].constraints()] or 'the layer only'}")
    res = ms.simulate(model, **simulation)
    x = res["body/ball/position"][:, 0]
    f_sim = 1.0 / ms.analysis.period(res.t, x)
    slip = np.abs(res["contact/bowl/gd_t"]).max()
    print(f"simulated from {SIDE} m aside: rocks at {f_sim:.4f} Hz (rolling {ROCK_ROLL / (2 * np.pi):.4f} Hz, sliding "
          f"{ROCK_SLIDE / (2 * np.pi):.4f} Hz); largest slip speed {slip:.2e} m/s; overlap at the bottom "
          f"{-res['contact/bowl/g_n'].min():.3e} m (c m g = {COMPLIANCE * MASS * G:.3e} m)")
    out = Path("results")
    out.mkdir(exist_ok=True)
    res.save(out / "bowl_layer_modes.h5")
    ms.plot(res, signals=["body/ball/position", "contact/bowl/lambda_n", "contact/bowl/gd_t"], out=out / "bowl_layer_modes.png")
    print("wrote results/bowl_layer_modes.h5, results/bowl_layer_modes.png")
