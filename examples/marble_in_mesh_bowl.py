"""A marble rolling in a bowl given as a triangle mesh (ms.contours.Mesh): the bowl is the bottom
of a spherical cavity of radius R, tessellated on a 64 × 64 grid, written to an OBJ file and read
back through trimesh, as a bowl from a CAD program would be. The marble (radius r, solid) rolls
without slipping (Coulomb friction, mu = 1); small swings have the period of a ball rolling in a
sphere,

    T = 2 pi sqrt(7 (R - r) / (5 g)),

which the tessellated bowl approaches as its grid is refined. Rolling over an edge between two
triangles, the contact normal turns by the edges' small angle: each crossing is a tiny impact
(event-driven scheme), so the marble loses a little energy that the smooth bowl would keep.

Printed: the period against the closed form, the edge impacts and the energy they took.
Plotted: the contact force and the marble's position.

    python examples/marble_in_mesh_bowl.py
    mechsys run examples/marble_in_mesh_bowl.py
"""

import math
import tempfile
from pathlib import Path

import numpy as np

import mechsys as ms

R, RADIUS, MASS, G, MU = 0.5, 0.05, 0.1, 9.81, 1.0
PHI0 = 0.1  # start, at rest, this far from the bottom (rad, about the bowl's centre)
RIM, CELLS = 0.12, 64  # the tessellated part: within RIM of the axis, CELLS × CELLS grid


def bowl_obj(path: Path) -> None:
    """Writes the bowl: the grid over [-RIM, RIM]² lifted onto z = -√(R² - x² - y²), the cells
    within RIM of the axis, two triangles each, counter-clockwise seen from above (normals into
    the cavity, the solid below)."""
    xs = np.linspace(-RIM, RIM, CELLS + 1)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    Z = -np.sqrt(R**2 - X**2 - Y**2)
    inside = X**2 + Y**2 <= RIM**2
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in zip(X.ravel(), Y.ravel(), Z.ravel())]
    for j in range(CELLS):
        for i in range(CELLS):
            if inside[j, i] and inside[j, i + 1] and inside[j + 1, i] and inside[j + 1, i + 1]:
                a, b = j * (CELLS + 1) + i + 1, j * (CELLS + 1) + i + 2  # OBJ counts from 1
                c, d = b + CELLS + 1, a + CELLS + 1
                lines += [f"f {a} {b} {c}", f"f {a} {c} {d}"]
    path.write_text("\n".join(lines) + "\n")


with tempfile.TemporaryDirectory() as folder:
    obj = Path(folder) / "bowl.obj"
    bowl_obj(obj)
    bowl = ms.contours.Mesh.from_file(obj)

model = ms.Model("marble-in-mesh-bowl", gravity=(0.0, 0.0, -G))
marble = model.add_body("marble", MASS, ms.inertia.sphere(MASS, RADIUS))
x0, z0 = (R - RADIUS) * math.sin(PHI0), -(R - RADIUS) * math.cos(PHI0)
model.add_joint(ms.joints.Free("free", model.ground, marble, q0=[x0, 0.0, z0, 1.0, 0.0, 0.0, 0.0]))
model.add_contact(ms.Contact("bowl", marble.contour(ms.contours.Sphere(radius=RADIUS)), model.ground.contour(bowl),
                             friction=ms.laws.Coulomb(mu=MU)))

simulation = dict(t_end=4.0, integrator=ms.EventDriven(), output_dt=1e-3)


def period(res) -> float:
    return ms.analysis.period(res.t, res["joint/free/q"][:, 0])


if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    expected = 2 * math.pi * math.sqrt(7 * (R - RADIUS) / (5 * G))
    e = res["energy/total"]
    impacts = [ev for ev in res.events if ev["event"] == "impact"]
    swing = MASS * G * (R - RADIUS) * (1 - math.cos(PHI0))
    print(f"bowl: {len(bowl.triangles)} triangles; period {period(res):.4f} s against {expected:.4f} s "
          f"for the smooth bowl ({period(res) / expected - 1:+.2%})")
    print(f"{len(impacts)} edge impacts took {e[0] - e[-1]:.2e} J of the swing's {swing:.2e} J; "
          f"contact state {sorted(set(res['contact/bowl/state'].tolist()))} (1 = stick)")
    Path("results").mkdir(exist_ok=True)
    res.save("results/marble_in_mesh_bowl.h5")
    ms.plot(res, ["joint/free/q", "contact/bowl/lambda_n", "contact/bowl/g_n", "energy/total"],
            out="results/marble_in_mesh_bowl.png")
    print("wrote results/marble_in_mesh_bowl.h5, results/marble_in_mesh_bowl.png")
