"""Compliant contact groups (issue 19, item 1): a contact group with a compliant normal law, its
pairs found by the broad phase at every evaluation, against the same model written with
explicit pairwise compliant contacts, the Hertz closed form and the energy balance."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

R, M = 0.05, 0.1
MAT = ms.Material(E=1e7, nu=0.3, density=M / (4 / 3 * math.pi * R**3))
# four spheres thrown into a box: they hit the floor, the walls and each other
POS = [(-0.06, -0.05, 0.08), (0.05, -0.04, 0.2), (0.0, 0.06, 0.33), (0.065, 0.055, 0.07)]
VEL = [(0.6, 0.3, 0), (-0.4, 0.2, 0), (0.1, -0.5, 0), (-0.3, -0.6, 0.5)]
H = 0.13
WALLS = [((0, 0, 0), (0, 0, 1)), ((-H, 0, 0), (1, 0, 0)), ((H, 0, 0), (-1, 0, 0)), ((0, -H, 0), (0, 1, 0)),
         ((0, H, 0), (0, -1, 0))]


def box(group: bool, law, friction=None, group_material: bool = False) -> ms.Model:
    m = ms.Model("box", gravity=(0, 0, -9.81))
    bodies = []
    for i, (p, v) in enumerate(zip(POS, VEL)):
        b = m.add_body(f"s{i}", M, ms.inertia.sphere(M, R))
        m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=[*p, 1, 0, 0, 0], u0=[*v, 0, 0, 0]))
        bodies.append(b)
    own = None if group_material else MAT

    def sph(b):
        return b.contour(ms.contours.Sphere(radius=R), material=own)

    def wall(p, n):
        return m.ground.contour(ms.contours.Plane(point=p, normal=n), material=own)

    if group:
        m.add_contact(ms.ContactGroup("pile", members=[sph(b) for b in bodies], against=[wall(*w) for w in WALLS],
                                      normal=law, friction=friction, material=MAT if group_material else None))
    else:
        for i in range(len(bodies)):
            for j in range(i + 1, len(bodies)):
                m.add_contact(ms.Contact(f"p{i}{j}", sph(bodies[i]), sph(bodies[j]), normal=law, friction=friction))
            for k, w in enumerate(WALLS):
                m.add_contact(ms.Contact(f"w{i}{k}", sph(bodies[i]), wall(*w), normal=law, friction=friction))
    return m


def run(model, t_end=0.25, rtol=1e-11, output_dt=0.01):
    return ms.simulate(model, t_end=t_end, output_dt=output_dt, integrator=ms.DOPRI5(rtol=rtol, atol=1e-14), progress=False)


def test_group_gives_the_trajectory_of_the_explicit_pairs():
    """Damped Hertz (fixed alpha) with regularized Coulomb friction: the group (pairs from the broad
    phase, onsets stepped over) and the 26 explicit contacts (onsets located) agree to the
    integrator's tolerance, and the difference falls with it."""
    law, fr = ms.laws.Hertz(alpha=0.5, v_reg=1e-3), ms.laws.Coulomb(0.3)
    diffs = []
    for rtol in (1e-9, 1e-11):
        a = run(box(True, law, fr, group_material=True), rtol=rtol)
        b = run(box(False, law, fr), rtol=rtol)
        diffs.append((np.abs(a["q"] - b["q"]).max(), np.abs(a["u"] - b["u"]).max()))
    # contacts happened: sphere-sphere and sphere-wall, up to three pairs at once
    assert a["contact/pile/touching"].max() >= 2 and a["contact/pile/touching"].sum() >= 8
    assert a["contact/pile/max_overlap"].max() > 1e-4
    assert diffs[1][0] < 2e-9 and diffs[1][1] < 5e-7
    assert diffs[1][0] < 0.05 * diffs[0][0]
    # the recorded totals are those of the explicit contacts summed
    d_exp = sum(b[k][-1] for k in b.names() if k.endswith("/energy_dissipated"))
    assert a["contact/pile/energy_dissipated"][-1] == pytest.approx(d_exp, rel=1e-6)
    i = int(np.argmax(a["contact/pile/force_n"]))
    f_exp = sum(b[k][i] for k in b.names() if k.endswith("/force_n"))
    assert a["contact/pile/force_n"][i] == pytest.approx(f_exp, rel=1e-4)


def test_group_energy_balance_closes():
    """Hunt-Crossley (restitution-tuned) with friction: kinetic + potential + stored + dissipated
    stays constant, and the group's dissipated energy is all of the run's; undamped and
    frictionless, the total energy itself is conserved."""
    res = run(box(True, ms.laws.HuntCrossley(eps=0.5, v_reg=1e-3), ms.laws.Coulomb(0.3), group_material=True), rtol=1e-10)
    e = res["energy/total"] + res["energy/dissipated"]
    assert np.abs(e - e[0]).max() < 1e-8 * abs(e[0])
    assert res["energy/dissipated"][-1] > 0.1 * abs(e[0])
    assert res["contact/pile/energy_dissipated"][-1] == pytest.approx(res["energy/dissipated"][-1], rel=1e-12)
    res = run(box(True, ms.laws.Hertz(), group_material=True), rtol=1e-10)
    e = res["energy/total"]
    # each onset stepped over leaves an energy error of the order of the tolerance (≈ 3e-9 here)
    assert np.abs(e - e[0]).max() < 1e-7 * abs(e[0])
    assert np.abs(res["energy/dissipated"]).max() < 1e-12 * abs(e[0])
    # the stored energy is seen while touching
    assert res["contact/pile/energy_elastic"].max() > 0


def test_single_sphere_in_a_group_meets_the_hertz_closed_form():
    """A steel ball at 1 m/s on a steel plane through a group of one member: delta_max =
    (5 m v^2 / 4K)^(2/5) with K = (4/3) E* sqrt(R), restitution 1 (the onset is stepped over,
    with the error control keeping the tolerance)."""
    steel = ms.Material(E=2.1e11, nu=0.3, density=7800.0)
    r = 0.01
    mass = 7800.0 * 4 / 3 * math.pi * r**3
    m = ms.Model("ball", gravity=(0, 0, 0))
    b = m.add_body("ball", mass=mass, inertia=ms.inertia.sphere(mass, r))
    m.add_joint(ms.joints.Prismatic("z", m.ground, b, axis=(0, 0, 1), q0=r + 2e-4, u0=-1.0))
    m.add_contact(ms.ContactGroup("g", members=[b.contour(ms.contours.Sphere(radius=r))],
                                  against=[m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))],
                                  normal=ms.laws.Hertz(), material=steel))
    res = ms.simulate(m, t_end=4e-4, output_dt=1e-8, integrator=ms.DOPRI5(rtol=1e-12, atol=1e-16), progress=False)
    k = 4 / 3 * (1 / (2 * (1 - 0.09) / 2.1e11)) * math.sqrt(r)
    d_ref = (1.25 * mass / k) ** 0.4
    d = res["contact/g/max_overlap"]
    j = int(np.argmax(d))
    y0, y1, y2 = d[j - 1], d[j], d[j + 1]
    assert y1 - 0.125 * (y2 - y0) ** 2 / (y0 - 2 * y1 + y2) == pytest.approx(d_ref, rel=1e-6)
    assert res["contact/g/force_n"].max() == pytest.approx(k * d_ref**1.5, rel=1e-6)
    assert res["joint/z/u"][-1] == pytest.approx(1.0, rel=1e-8)
    assert res["contact/g/touching"].max() == 1 and res["contact/g/touching"][-1] == 0


@pytest.mark.parametrize("kw, msg", [
    (dict(friction=ms.laws.LuGre(mu0=0.3, mu=0.2, v_s=1e-3, sigma0=1e5)), "LuGre"),
    (dict(impact=ms.laws.Newton(eps=0.5)), "impact"),
    (dict(group_material=None), "material"),
    (dict(normal=ms.laws.HuntCrossley()), "eps"),
])
def test_bad_compliant_groups_are_named(kw, msg):
    m = ms.Model("bad", gravity=(0, 0, -9.81))
    b = m.add_body("b", M, ms.inertia.sphere(M, R))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=[0, 0, 0.2, 1, 0, 0, 0]))
    mat = kw.pop("group_material", MAT)
    args = dict(normal=ms.laws.Hertz(), material=mat) | kw
    m.add_contact(ms.ContactGroup("heap", members=[b.contour(ms.contours.Sphere(radius=R))],
                                  against=[m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))], **args))
    with pytest.raises(ms.ModelError, match=msg) as e:
        m.build()
    assert "heap" in str(e.value)


def test_flat_faces_in_a_hertz_group_are_refused():
    m = ms.Model("boxes", gravity=(0, 0, -9.81))
    b = m.add_body("b", M, ms.inertia.box(M, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Free("f", m.ground, b, q0=[0, 0, 0.2, 1, 0, 0, 0]))
    m.add_contact(ms.ContactGroup("crate", members=[b.contour(ms.contours.Box(half_extents=(0.05, 0.05, 0.05)))],
                                  against=[m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))],
                                  normal=ms.laws.Hertz(), material=MAT))
    with pytest.raises(ms.ModelError, match="crate.*members\\[0\\].*against\\[0\\]"):
        m.build()


def test_compliant_group_in_event_driven_equals_dopri5():
    """The event-driven scheme carries a compliant group in its smooth phases: with no rigid
    contact it is a Dormand-Prince integration, and lands on DOPRI5's trajectory."""
    model = box(True, ms.laws.Hertz(alpha=0.5, v_reg=1e-3), ms.laws.Coulomb(0.3), group_material=True)
    ref = run(model, t_end=0.15, rtol=1e-11)
    ed = ms.simulate(model, t_end=0.15, output_dt=0.01, integrator=ms.EventDriven(rtol=1e-11, atol=1e-14), progress=False)
    assert np.abs(ed["q"] - ref["q"]).max() < 1e-8
    assert ed["contact/pile/energy_dissipated"][-1] == pytest.approx(ref["contact/pile/energy_dissipated"][-1], rel=1e-6)


def test_compliant_group_in_moreau_jean_next_to_dopri5():
    """A compliant group is a force element: Moreau-Jean at a small step carries it too and
    lands on the DOPRI5 trajectory to its first order."""
    model = box(True, ms.laws.Hertz(alpha=0.5, v_reg=1e-3), ms.laws.Coulomb(0.3), group_material=True)
    ref = run(model, t_end=0.15, rtol=1e-10)
    mj = ms.simulate(model, t_end=0.15, output_dt=0.01, integrator=ms.MoreauJean(dt=1e-5), progress=False)
    assert np.abs(mj["q"] - ref["q"]).max() < 2e-4
    assert ref["contact/pile/energy_dissipated"][-1] > 1e-3
    assert mj["contact/pile/energy_dissipated"][-1] == pytest.approx(ref["contact/pile/energy_dissipated"][-1], rel=0.05)


def test_model_file_compliant_group_from_the_command_line(tmp_path):
    """examples/compliant_pile.toml through `mechsys run`: the spheres settle on the floor with
    the overlap of their weight, the group's signals are written and the energy closes."""
    ex = Path(__file__).resolve().parents[1] / "examples" / "compliant_pile.toml"
    out = tmp_path / "pile.h5"
    script = Path(sys.executable).parent / "mechsys"
    r = subprocess.run([str(script), "run", str(ex), "--t-end", "0.4", "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    res = ms.load(out)
    assert res["contact/pile/touching"][-1] >= 4
    assert res.unit("contact/pile/max_overlap") == "m"
    e = res["energy/total"] + res["energy/dissipated"]
    assert np.abs(e - e[0]).max() < 1e-5 * abs(e[0])
    bad = tmp_path / "bad.toml"
    bad.write_text(ex.read_text().replace('material = { E = 1e7, nu = 0.3, density = 191.0 }\n', ""))
    r = subprocess.run([str(script), "run", str(bad), "--t-end", "0.01", "--out", str(tmp_path / "b.h5")],
                       capture_output=True, text=True)
    assert r.returncode != 0 and "'pile'" in r.stderr and "material" in r.stderr
