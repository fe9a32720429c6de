"""A pile of spheres on compliant Signorini layers against the same pile on rigid contacts.

The pour of `examples/sphere_pile.py` (N spheres of radius 5 cm and 0.1 kg, friction 0.5, no
restitution, poured into a box) with every contact a Signorini law with a layer of stiffness
k = 1e6 N/m in series (``laws.Signorini(compliance=1e-6)``), solved to tol 1e-4 by ``Auto``, and
the same pour on rigid contacts. On rigid contacts the settling pile's force distribution is not
unique and Gauss-Seidel needs thousands of sweeps in some steps; on the layers the problem is
regularized by c/h^2 on each normal diagonal, its solution unique, and every step converges in
tens. The price is an overlap of c times each contact's force (micrometres here), which the layer
holds at rest instead of letting it drift like the rigid scheme's penetration.

Printed for both pours: sweeps per step (mean, largest), unconverged steps, wall time, the vertical
force of the box on the spheres (N m g once the pile rests) and the largest penetration at the
end; for the layers also the energy they hold (``energy/contact_elastic``), the energy balance
with it, the summed normal force of the group's points, what the impacts took and what points
that joined a step already overlapped gave (``energy/dissipated_drift``).

``python examples/compliant_layer_pile.py [N]`` (default 100 spheres, 1 s; a few seconds);
``mechsys run examples/compliant_layer_pile.py`` runs the compliant pour alone.
"""

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import mechsys as ms

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sphere_pile import MASS, G, build as rigid_build  # noqa: E402

COMPLIANCE = 1e-6  # m/N: k = 1e6 N/m


def build(n: int = 100, compliance: float = COMPLIANCE) -> ms.Model:
    """The pile of `n` spheres of examples/sphere_pile.py, its group on compliant layers."""
    return rigid_build(n, compliance=compliance)


N = int(sys.argv[1]) if len(sys.argv) > 1 and __name__ == "__main__" else 100
model = build(N)
simulation = dict(t_end=1.0, integrator=ms.MoreauJean(dt=1e-3, solver=ms.Auto(tol=1e-4)), output_dt=1e-3)


def pour(m: ms.Model):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an unconverged rigid step warns; the signals say it
        t0 = time.perf_counter()
        res = ms.simulate(m, **simulation)
        return res, time.perf_counter() - t0


if __name__ == "__main__":
    weight = N * MASS * G
    runs = {"rigid": pour(rigid_build(N)), "compliant layers": pour(model)}
    for name, (res, wall) in runs.items():
        it = res["solver/iterations"][1:]
        unconverged = int((res["solver/converged"][1:] == 0).sum())
        f = res["contact/pile/force_against"]
        print(f"{name:17s}: {wall:6.2f} s wall for {res.t[-1]:.2f} s; sweeps per step mean {it.mean():7.1f}, largest "
              f"{it.max():6.0f}; {unconverged} steps unconverged; box on spheres {f[-1, 2]:.4f} N (N m g = {weight:.4f} N); "
              f"largest penetration at the end {1e3 * res['contact/pile/max_penetration'][-1]:.4f} mm")
    res, _ = runs["compliant layers"]
    e = (res["energy/kinetic"] + res["energy/potential"] + res["energy/contact_elastic"] + res["energy/dissipated"]
         - res["energy/external_work"])
    lam = res["contact/pile/lambda_n"][-1]
    print(f"compliant layers: energy held {res['energy/contact_elastic'][-1]:.3e} J; balance drift {np.ptp(e):.1e} J; "
          f"summed normal force {lam:.3f} N; taken by impacts {res['energy/dissipated_impact'][-1]:.3f} J, "
          f"given by points joining overlapped {-res['energy/dissipated_drift'][-1]:.3e} J")
    Path("results").mkdir(exist_ok=True)
    res.save("results/compliant_layer_pile.h5")
    ms.plot(res, ["solver/iterations", "contact/pile/max_penetration", "energy/contact_elastic", "energy/kinetic",
                  "energy/dissipated", "energy/dissipated_drift"], out="results/compliant_layer_pile.png")
    print("wrote results/compliant_layer_pile.h5, results/compliant_layer_pile.png")
