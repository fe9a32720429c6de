"""The woodpecker toy: a sleeve with clearance on a vertical pole carries, on a torsion spring, a
bird that swings and hits the pole with its beak. The sleeve jams (stick, tilted against the
pole by two of its hole's corners), is freed when the swinging bird tilts it back, slides a little,
and jams again: the bird pecks its way down the pole. Impacts with friction at three contacts,
stick-slip and impact sequences, from Moreau-Jean time-stepping and, for comparison, from the
event-driven scheme (every impact, detachment, stick and slip located in time).

Data as published for the toy (Glocker & Pfeiffer; Leine, Glocker & van Campen; Leine &
Nijmeijer's book): sleeve mass m_M and inertia J_M, bird m_S and J_S, the torsion spring c_phi,
the pole and hole radii, the sleeve height, the pin and beak positions, friction 0.3 everywhere,
restitution 0.5 at contact 1 and 0 at contact 2 and at the beak. The published model keeps the
sleeve on the pole's axis (3 degrees of freedom) with one contact per tilt direction and gaps
linearized in the angles. Here the sleeve moves in the plane (x, y, tilt), the hole touches the
pole with two diagonal corners per tilt direction, and the corners, the beak (points) and the
pole's surfaces (lines) are exact contours: a model of the same toy, not a reproduction of the
published one, so its cycle differs in detail. It settles into a cycle of two pecks, a long and a
short one.
"""

from pathlib import Path

import numpy as np

import mechsys as ms

# toy data (SI)
M_M, J_M = 3.0e-4, 5.0e-9  # sleeve
M_S, J_S = 4.5e-3, 7.0e-7  # bird
R_0, R_M, H_M = 2.5e-3, 3.1e-3, 5.8e-3  # pole radius, hole radius, half the sleeve height
L_M, L_G = 1.0e-2, 1.5e-2  # sleeve axis -> pin, pin -> bird's centre of mass
L_S, H_S = 2.01e-2, 2.0e-2  # bird's centre of mass -> beak: back towards the pole, up
C_PHI = 5.6e-3  # torsion spring (N m/rad)
MU, EPS_1 = 0.3, 0.5

model = ms.Model("woodpecker", gravity=(0.0, -9.81, 0.0))
sleeve = model.add_body("sleeve", M_M, [J_M, J_M, J_M])
bird = model.add_body("bird", M_S, [J_S, J_S, J_S], com=(L_G, 0.0, 0.0))
# the sleeve moves in the plane (x, y, tilt) around the pole; its hole touches the pole with the
# corners of the hole's cross-section, diagonally: upper right with lower left when it tilts one
# way (the published contact 1, restitution 0.5), lower right with upper left the other (contact 2)
# start near the published limit-cycle state (phi_M = -0.1036, phi_S = -0.2788 rad absolute, y' =
# -0.3411 m/s, phi_M' = -7.4583, phi_S' = -0.5260 rad/s), with the sleeve angle moved to where the
# exact corner touches the pole (-0.1013 rad; -0.1036 is where the linearized gap vanishes, 16 µm
# inside the pole for the exact corner); the pin angle is phi_S - phi_M
PHI_M = float(np.arctan2(H_M, R_M) - np.arccos(R_0 / np.hypot(R_M, H_M)))
PHI_S, DY, DPHI_M, DPHI_S = -0.2788, -0.3411, -7.4583, -0.5260
model.add_joint(ms.joints.Planar("sleeve", model.ground, sleeve, q0=[0.0, 0.0, PHI_M], u0=[0.0, DY, DPHI_M]))
model.add_joint(ms.joints.Revolute("pin", sleeve, bird, axis=(0, 0, 1), parent_frame=(L_M, 0, 0), q0=PHI_S - PHI_M,
                                   u0=DPHI_S - DPHI_M, spring=ms.joints.JointSpring(k=C_PHI)))
right = model.ground.contour(ms.contours.Line(point=(R_0, 0, 0), normal=(1, 0, 0)))
left = model.ground.contour(ms.contours.Line(point=(-R_0, 0, 0), normal=(-1, 0, 0)))
friction = ms.laws.Coulomb(mu=MU)
for name, corner, side, eps in (
    ("upper_right", (R_M, H_M), right, EPS_1),
    ("lower_left", (-R_M, -H_M), left, EPS_1),
    ("lower_right", (R_M, -H_M), right, 0.0),
    ("upper_left", (-R_M, H_M), left, 0.0),
):
    model.add_contact(ms.Contact(name, sleeve.contour(ms.contours.Point((*corner, 0.0))), side,
                                 friction=friction, impact=ms.laws.Newton(eps)))
CONTACTS = ("upper_right", "lower_left", "lower_right", "upper_left", "beak")
model.add_contact(ms.Contact("beak", bird.contour(ms.contours.Point((L_G - L_S, H_S, 0))), right,
                             friction=friction, impact=ms.laws.Newton(0.0)))

simulation = dict(t_end=1.0, integrator=ms.MoreauJean(dt=1e-5), output_dt=1e-4)
event_driven = dict(simulation, integrator=ms.EventDriven(rtol=1e-8, atol=1e-10))


def pecks(res) -> np.ndarray:
    """Times at which the beak starts a burst of impacts (impacts closer than 20 ms are one burst)."""
    hit = res["contact/beak/impulse_n"] > 0
    starts = res.t[1:][np.diff(hit.astype(int)) == 1]
    return starts[np.concatenate([[True], np.diff(starts) > 0.02])] if len(starts) else starts


if __name__ == "__main__":
    import time

    t0 = time.perf_counter()
    res = ms.simulate(model, **simulation)
    wall = time.perf_counter() - t0
    y = res["joint/sleeve/q"][:, 1]
    burst = pecks(res)
    period = np.diff(burst)
    drop = -np.diff(np.interp(burst, res.t, y))
    print(f"simulated {res.t[-1]:.2f} s in {wall:.2f} s wall ({res.stats['steps']} steps of {simulation['integrator'].dt:g} s)")
    print(f"pecks at t = {', '.join(f'{t:.3f}' for t in burst)} s: period {period.mean():.3f} s "
          f"(min {period.min():.3f}, max {period.max():.3f}), the sleeve drops {1e3 * drop.mean():.1f} mm per peck")
    stuck = (res["contact/lower_right/state"] == 1) & (res["contact/upper_left/state"] == 1)
    print(f"the sleeve is jammed (both corners sticking) {100 * stuck.mean():.0f} % of the time")
    e = res["energy/total"] + res["energy/dissipated"] - res["energy/external_work"]
    print(f"energy balance drift {np.ptp(e):.1e} J; taken by impacts {1e3 * res['energy/dissipated_impact'][-1]:.3f} mJ, "
          f"by friction {1e3 * res['energy/dissipated_friction'][-1]:.3f} mJ")
    # the same toy, event-driven: every impact, lift-off, stick and slip located in time. A jam on
    # two diagonal corners is statically indeterminate (how hard the corners squeeze the pole is
    # not fixed by rigid-body mechanics); it ends when no admissible squeeze is left, which both
    # schemes find, so they settle into the same cycle
    t0 = time.perf_counter()
    ed = ms.simulate(model, **event_driven)
    wall_ed = time.perf_counter() - t0
    e_ed = ed["energy/total"] + ed["energy/dissipated"] - ed["energy/external_work"]
    kinds = {k: sum(e["event"] == k for e in ed.events) for k in ("impact", "close", "open", "stick", "slip")}
    burst_ed = pecks(ed)
    print(f"event-driven: {res.t[-1]:.2f} s in {wall_ed:.2f} s wall, {ed.stats['events']} events "
          f"({', '.join(f'{v} {k}' for k, v in kinds.items())}); pecks at t = {', '.join(f'{t:.3f}' for t in burst_ed)} s, "
          f"period {np.diff(burst_ed).mean():.3f} s; energy balance drift {np.ptp(e_ed):.1e} J; "
          f"smallest normal force on record {min(ed[f'contact/{c}/lambda_n'].min() for c in CONTACTS):.1e} N")
    Path("results").mkdir(exist_ok=True)
    ed.save("results/woodpecker_event_driven.h5")
    res.save("results/woodpecker.h5")
    ms.plot(res, ["joint/sleeve/q", "joint/pin/q", "contact/beak/lambda_n", "contact/lower_right/lambda_n",
                  "contact/lower_right/state", "energy/dissipated"], out="results/woodpecker.png")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    for r, label in ((res, "Moreau-Jean, dt = 1e-5 s"), (ed, "event-driven")):
        ax[0].plot(r.t, 1e3 * r["joint/sleeve/q"][:, 1], label=label)
        ax[1].plot(r.t, r["joint/pin/q"], label=label)
    ax[0].set_ylabel("sleeve height (mm)")
    ax[1].set_ylabel("bird angle (rad)")
    ax[1].set_xlabel("t (s)")
    ax[0].legend()
    fig.tight_layout()
    fig.savefig("results/woodpecker_schemes.png", dpi=120)
    print("wrote results/woodpecker.h5, results/woodpecker_event_driven.h5, results/woodpecker.png, "
          "results/woodpecker_schemes.png")
    # the 3D page: open results/woodpecker.html in a browser (also: mechsys view results/woodpecker.h5)
    try:
        page = ed.to_html("results/woodpecker.html", trails=["bird"],
                          signals=["joint/pin/q", "contact/beak/lambda_n", "contact/lower_right/state"])
        print(f"wrote {page} (the run in the browser: scene, timeline, contact forces, plots)")
    except ms.ResultsError as e:  # the viewer's JavaScript is built by `make build` where npm is found
        print(f"no viewer page: {e}")
