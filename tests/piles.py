"""Spheres in an open box (a floor and four walls), the piles of the solver tests."""

import mechsys as ms

R, M, MU = 0.05, 0.1, 0.5


def box_pile(centres, half, name=None, compliance=0.0):
    """Spheres of radius R and mass M at `centres` (n × 3) in a box of half-width `half`, one contact
    group "pile" with Coulomb friction MU and no rebound (on compliant Signorini layers of
    `compliance` m/N if given)."""
    m = ms.Model(name or f"pile-{len(centres)}", gravity=(0, 0, -9.81))
    members = []
    for i, x in enumerate(centres):
        b = m.add_body(f"s{i}", M, ms.inertia.sphere(M, R))
        m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=[*x, 1, 0, 0, 0]))
        members.append(b.contour(ms.contours.Sphere(radius=R)))
    walls = [((0, 0, 0), (0, 0, 1))] + [(tuple(-s * half * (k == ax) for k in range(3)), tuple(s * (k == ax) * 1.0 for k in range(3)))
                                        for ax in range(2) for s in (1, -1)]
    against = [m.ground.contour(ms.contours.Plane(point=p, normal=nrm)) for p, nrm in walls]
    m.add_contact(ms.ContactGroup("pile", members=members, against=against, friction=ms.laws.Coulomb(MU),
                                  impact=ms.laws.Newton(0.0), normal=ms.laws.Signorini(compliance=compliance)))
    m.build()
    return m
