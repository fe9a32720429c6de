"""Contact groups (mechsys.ContactGroup): one declaration for every pair among many contours and
each of them against a container; a broad phase picks the pairs that may touch at every step."""

import numpy as np
import pytest

import mechsys as ms

G = 9.81
R = 0.05
MASS = 0.1


def pile(n, half=0.17, mu=0.3, eps=0.0, seed=0, walls=True, group=True, spacing=2.2, height=0.01):
    """n spheres on a jittered lattice in a box, falling onto its floor; as one group or as the
    equivalent explicit pairwise contacts (declared member by member, then the walls)."""
    rng = np.random.default_rng(seed)
    m = ms.Model("pile", gravity=(0, 0, -G))
    per = max(1, int(2 * half / (spacing * R)))
    members = []
    for i in range(n):
        ix, iy, iz = i % per, (i // per) % per, i // (per * per)
        x = -half + spacing / 2 * R + spacing * R * ix + rng.uniform(-0.05, 0.05) * R
        y = -half + spacing / 2 * R + spacing * R * iy + rng.uniform(-0.05, 0.05) * R
        z = R + height + spacing * R * iz
        b = m.add_body(f"s{i}", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
        m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=[x, y, z, 1, 0, 0, 0]))
        members.append(b.contour(ms.contours.Sphere(radius=R)))
    against = [m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))]
    if walls:
        for ax in range(2):
            for sgn in (1, -1):
                nrm, pt = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
                nrm[ax], pt[ax] = sgn, -sgn * half
                against.append(m.ground.contour(ms.contours.Plane(point=pt, normal=nrm)))
    friction, impact = ms.laws.Coulomb(mu=mu), ms.laws.Newton(eps=eps)
    if group:
        m.add_contact(ms.ContactGroup("pile", members=members, against=against, friction=friction, impact=impact))
    else:
        for i in range(n):
            for j in range(i + 1, n):
                m.add_contact(ms.Contact(f"c{i}_{j}", members[i], members[j], friction=friction, impact=impact))
            for k, a in enumerate(against):
                m.add_contact(ms.Contact(f"c{i}_w{k}", members[i], a, friction=friction, impact=impact))
    return m


def tight(dt=1e-3):
    return ms.MoreauJean(dt, solver=ms.NSGS(tol=1e-11, max_iter=100_000))


def test_group_equals_the_explicit_pairwise_contacts():
    """12 spheres in two layers: the group and the 12·11/2 + 12·5 explicit contacts it stands for
    give the same motion and the same energy taken, to round-off."""
    kw = dict(n=12, half=0.12, mu=0.3, eps=0.3, seed=4)
    rg = ms.simulate(pile(**kw), 0.4, tight(), output_dt=1e-2)
    rc = ms.simulate(pile(group=False, **kw), 0.4, tight(), output_dt=1e-2)
    np.testing.assert_allclose(rg["q"], rc["q"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(rg["u"], rc["u"], rtol=0, atol=1e-10)
    for k in ("energy/dissipated_impact", "energy/dissipated_friction"):
        np.testing.assert_allclose(rg[k], rc[k], rtol=1e-10, atol=1e-14)
    # the group's totals are those of the pairs
    names = [n for n in rc.names() if n.startswith("contact/c") and n.endswith("/impulse_n")]
    total = sum(rc[n] for n in names)
    np.testing.assert_allclose(rg["contact/pile/impulse_n"], total, rtol=1e-9, atol=1e-14)
    assert rg["contact/pile/closed"].max() >= 12, "the spheres should touch each other and the floor"
    # the broad phase keeps a small part of the 66 + 60 pairs
    assert 0 < rg["contact/pile/pairs"][-1] < 66


def square_pyramid(gap=1e-3, mu=0.5, base=3, at=(0.0,)):
    """14 spheres stacked 3×3, 2×2, 1 (``base`` = 3; else ``base``², ..., 1) in a box that holds
    the base layer exactly, each layer dropped from `gap` above its resting height; one such
    pyramid and box at each x of `at` (one contact group each, ``pile``, ``pile1``, ...)."""
    m = ms.Model("pyramid", gravity=(0, 0, -G))
    k = 0
    for p, x0 in enumerate(at):
        members = []
        for layer, size in enumerate(range(base, 0, -1)):
            z = R + layer * np.sqrt(2) * R + gap * (layer + 1)
            for i in range(size):
                for j in range(size):
                    x, y = x0 + (2 * i - (size - 1)) * R, (2 * j - (size - 1)) * R
                    b = m.add_body(f"s{k}", mass=MASS, inertia=ms.inertia.sphere(MASS, R))
                    m.add_joint(ms.joints.Free(f"f{k}", m.ground, b, q0=[x, y, z, 1, 0, 0, 0]))
                    members.append(b.contour(ms.contours.Sphere(radius=R)))
                    k += 1
        against = [m.ground.contour(ms.contours.Plane(point=(x0, 0, 0), normal=(0, 0, 1)))]
        for ax in range(2):
            for sgn in (1, -1):
                nrm, pt = [0.0, 0.0, 0.0], [x0, 0.0, 0.0]
                nrm[ax], pt[ax] = sgn, pt[ax] - sgn * base * R
                against.append(m.ground.contour(ms.contours.Plane(point=pt, normal=nrm)))
        m.add_contact(ms.ContactGroup("pile" if p == 0 else f"pile{p}", members=members, against=against,
                                      friction=ms.laws.Coulomb(mu=mu)))
    return m, k


def test_pile_at_rest_carries_its_weight_on_the_container():
    """14 spheres stacked in a box settle; then the container's impulse on them over each sample
    interval is their weight, N m g (momentum balance), to the solver's tolerance."""
    m, n = square_pyramid()
    # the resting pyramid is statically indeterminate (many contact forces carry the same loads):
    # Gauss–Seidel converges slowly there; the auto solver's regularized Newton method does not
    res = ms.simulate(m, 0.5, ms.MoreauJean(1e-3, solver=ms.Auto(tol=1e-9)), output_dt=2e-2)
    # every step converged (the signals cover every step since the previous sample)
    assert res["solver/converged"][1:].all() and res["solver/residual"].max() <= 1e-9
    f = res["contact/pile/force_against"]
    late = res.t > 0.3
    np.testing.assert_allclose(f[late, 2], n * MASS * G, rtol=1e-6)
    np.testing.assert_allclose(f[late, :2], 0.0, atol=1e-6 * n * MASS * G)
    # at rest: no velocity left, every sphere on its neighbours (3·3 on the floor, 4·4 + 4 between
    # the layers, 12 base contacts with the walls... at least one contact per sphere)
    assert np.abs(res["u"][-1]).max() < 1e-8
    assert res["contact/pile/closed"][-1] >= n
    # no sphere deeper in another or the box than one step of the fastest fall (the midpoint
    # scheme lets a point close at most that far within a step)
    v_max = np.sqrt(2 * G * 3e-3)
    pen = res["contact/pile/max_penetration"]
    assert pen.max() < v_max * 1e-3, pen.max()
    # the resting pile takes no energy: T + V + E_diss stays constant, and the energy taken is
    # the potential energy lost
    e = res["energy/total"] + res["energy/dissipated"]
    assert np.ptp(e) < 1e-9 * res["energy/dissipated"][-1]
    drop = res["energy/potential"][0] - res["energy/potential"][-1]
    np.testing.assert_allclose(res["energy/dissipated"][-1], drop, rtol=1e-9)
    assert drop > n * MASS * G * 1e-3


def test_frictionless_spheres_on_a_floor_keep_their_horizontal_momentum():
    """Without walls and friction, the floor and the spheres' mutual impacts act only vertically
    and in pairs: the horizontal momentum of 8 colliding spheres is conserved to round-off, and
    elastic impacts (eps = 1) keep the energy."""
    m = pile(8, half=0.11, mu=0.0, eps=1.0, seed=2, walls=False, spacing=2.02, height=0.0)
    rng = np.random.default_rng(5)
    u0 = {f"f{i}": np.r_[rng.uniform(-0.5, 0.5, 2), 0.0, 0.0, 0.0, 0.0] for i in range(8)}
    res = ms.simulate(m, 0.5, tight(1e-4), output_dt=1e-3, u0=u0)
    p = res["momentum/linear"]
    np.testing.assert_allclose(p[:, :2] - p[0, :2], 0.0, rtol=0, atol=1e-12)
    assert res["contact/pile/impulse_n"].sum() > 0.1, "the spheres should collide"
    e = res["energy/total"]
    assert np.ptp(e) < 1e-9 * e[0]


def test_group_signals_and_info(tmp_path):
    from click.testing import CliRunner

    from mechsys.cli import cli

    m = pile(2, half=0.12)
    path = tmp_path / "pile.toml"
    path.write_text("""
name = "pile"
gravity = [0.0, 0.0, -9.81]
[[bodies]]
name = "s0"
mass = 0.1
inertia = [1e-4, 1e-4, 1e-4]
[[bodies]]
name = "s1"
mass = 0.1
inertia = [1e-4, 1e-4, 1e-4]
[[joints]]
name = "f0"
type = "free"
parent = "ground"
child = "s0"
q0 = [0.0, 0.0, 0.06, 1.0, 0.0, 0.0, 0.0]
[[joints]]
name = "f1"
type = "free"
parent = "ground"
child = "s1"
q0 = [0.02, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0]
[[contact_groups]]
name = "pile"
members = [{ body = "s0", contour = { type = "sphere", radius = 0.05 } },
           { body = "s1", contour = { type = "sphere", radius = 0.05 } }]
against = [{ body = "ground", contour = { type = "plane", normal = [0.0, 0.0, 1.0] } }]
friction = { type = "coulomb", mu = 0.3 }
impact = { type = "newton", eps = 0.5 }
""")
    from mechsys.modelfile import load_model

    model, _ = load_model(path)
    m = ms.Model("pile", gravity=(0, 0, -G))
    mem = []
    for i, q0 in enumerate([[0.0, 0.0, 0.06, 1, 0, 0, 0], [0.02, 0.0, 0.2, 1, 0, 0, 0]]):
        b = m.add_body(f"s{i}", mass=0.1, inertia=[1e-4, 1e-4, 1e-4])
        m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=q0))
        mem.append(b.contour(ms.contours.Sphere(radius=0.05)))
    m.add_contact(ms.ContactGroup("pile", members=mem, against=[m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))],
                                  friction=ms.laws.Coulomb(mu=0.3), impact=ms.laws.Newton(eps=0.5)))
    r1 = ms.simulate(m, 0.3, tight(), output_dt=1e-2)
    r2 = ms.simulate(model, 0.3, tight(), output_dt=1e-2)
    np.testing.assert_array_equal(r1["q"], r2["q"])
    assert r1["contact/pile/closed"].max() == 2 and r1["contact/pile/impulse_n"].sum() > 0
    for k, unit in [("closed", "1"), ("max_penetration", "m"), ("impulse_n", "N s"), ("lambda_n", "N"),
                    ("pairs", "1"), ("force_against", "N")]:
        assert r1.unit(f"contact/pile/{k}") == unit
    out = CliRunner().invoke(cli, ["info", str(path)])
    assert out.exit_code == 0 and "contact groups (1" in out.output and "pile" in out.output, out.output
    assert "sphere" in out.output and "plane" in out.output


def test_smooth_integrators_refuse_groups():
    with pytest.raises(ms.SettingsError, match="contact groups \\('pile'\\).*MoreauJean"):
        ms.simulate(pile(2), 0.1, ms.RK4(1e-3))


@pytest.mark.parametrize(
    "change, fragments",
    [
        (lambda g: g["members"][1].update(body="nobody"), ["contact_groups[0] 'pile'", "members[1].body", "nobody"]),
        (lambda g: g["against"][0]["contour"].update(normal=[0, 0, 0]), ["contact_groups[0] 'pile'", "against[0]"]),
        (lambda g: g["members"][2]["contour"].update(radius=-1.0), ["'pile'", "members[2]", "radius"]),
        (lambda g: g["members"].append({"body": "s0", "contour": {"type": "cylinder", "axis": [0, 0, 1], "radius": 0.1, "half_length": 0.1}}),
         ["'pile'", "members[0] (sphere)", "members[3] (cylinder)", "cannot touch"]),
        (lambda g: g.update(members=[]), ["'pile'", "members", "at least one"]),
        (lambda g: g.update(friction={"type": "coulomb", "mu": -1.0}), ["'pile'", "friction.mu"]),
        (lambda g: g.update(impact={"type": "newton", "eps": 2.0}), ["'pile'", "impact.eps"]),
        (lambda g: g.update(memberz=[]), ["contact_groups[0]", "memberz"]),
        (lambda g: g["members"].append({"body": "s1", "contour": {"type": "circle", "radius": 0.1}}), ["'pile'", "planar"]),
    ],
)
def test_bad_groups_name_the_group_and_the_member(change, fragments):
    d = pile(3).to_dict()
    change(d["contact_groups"][0])
    with pytest.raises(ms.MechsysError) as e:
        ms.Model.from_dict(d).build()
    for f in fragments:
        assert f in str(e.value), (f, str(e.value))


def test_bad_group_objects_in_python():
    m = pile(2)
    with pytest.raises(ms.ModelError, match="contact group 'g'.members\\[1\\]: expected a contour on a body"):
        m.add_contact(ms.ContactGroup("g", members=[m.ground.contour(ms.contours.Sphere(radius=0.1)), "s1"]))
        m.build()
    m = pile(2)
    with pytest.raises(ms.ModelError, match="contact group 'g'.against: expected a list"):
        m.add_contact(ms.ContactGroup("g", members=[], against=m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))))
        m.build()
    m = pile(2)
    m.add_contact(ms.ContactGroup("pile", members=[m.ground.contour(ms.contours.Sphere(radius=0.1))]))
    with pytest.raises(ms.ModelError, match="contact_groups\\[1\\] 'pile': duplicate name"):
        m.build()


def test_group_with_a_bilateral_constraint_takes_the_dense_path():
    """A pendulum bob on a massless rod (a distance constraint: the dense assembly through the
    constrained inverse) swings into two resting spheres of the same group: the rod's length
    holds and the group equals its explicit pairs there too."""

    def build(group):
        m = ms.Model("bob", gravity=(0, 0, -G))
        s, bodies = [], []
        for i, q0 in enumerate([[0.3, 0.0, 0.35, 1, 0, 0, 0], [0.0, 0.0, R, 1, 0, 0, 0], [-0.1, 0.0, R, 1, 0, 0, 0]]):
            b = m.add_body(f"s{i}", MASS, ms.inertia.sphere(MASS, R))
            m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=q0))
            s.append(b.contour(ms.contours.Sphere(radius=R)))
            bodies.append(b)
        m.add_constraint(ms.constraints.Distance("rod", body1=bodies[0], body2=m.ground,
                                                 point2=(0.0, 0.0, 0.35), length=0.3))
        floor = m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))
        law = dict(friction=ms.laws.Coulomb(mu=0.2), impact=ms.laws.Newton(eps=0.5))
        if group:
            m.add_contact(ms.ContactGroup("pile", members=s, against=[floor], **law))
        else:
            for i in range(3):
                for j in range(i + 1, 3):
                    m.add_contact(ms.Contact(f"c{i}{j}", s[i], s[j], **law))
                m.add_contact(ms.Contact(f"c{i}f", s[i], floor, **law))
        return m

    rg = ms.simulate(build(True), 0.6, tight(), output_dt=1e-2)
    rc = ms.simulate(build(False), 0.6, tight(), output_dt=1e-2)
    np.testing.assert_allclose(rg["q"], rc["q"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(rg["constraint/rod/violation"], 0.0, atol=1e-12)
    assert rg["contact/pile/impulse_n"].sum() > 0.05, "the bob should hit the spheres"
    for k in ("energy/dissipated_impact", "energy/dissipated_friction"):
        np.testing.assert_allclose(rg[k], rc[k], rtol=1e-10, atol=1e-14)
    assert rg["energy/dissipated_impact"][-1] > 1e-3


def test_group_points_are_the_closed_explicit_contacts():
    """The group's recorded points (contact/<g>/points, point_forces, point_states) are those of
    the equivalent explicit contacts closed in the same step: the same places, the same forces
    (normal and friction together), the same states."""
    kw = dict(n=12, half=0.12, mu=0.3, eps=0.3, seed=4)
    # a sample every step: the explicit contacts' forces (impulses since the last sample over the
    # interval) are then the last step's, as the group records them
    rg = ms.simulate(pile(**kw), 0.4, tight(), output_dt=1e-3)
    rc = ms.simulate(pile(group=False, **kw), 0.4, tight(), output_dt=1e-3)
    assert rg.unit("contact/pile/points") == "m" and rg.unit("contact/pile/point_forces") == "N"
    contacts = sorted({n.split("/")[1] for n in rc.names() if n.startswith("contact/c")})
    checked = 0
    for i in range(50, len(rg.t), 25):
        want = []
        for c in contacts:
            ln = rc[f"contact/{c}/lambda_n"][i]
            if ln > 0:
                f = rc[f"contact/{c}/normal"][i] * ln + rc[f"contact/{c}/friction_force"][i]
                want.append([*rc[f"contact/{c}/point"][i], *f, rc[f"contact/{c}/state"][i]])
        pts, frc = rg["contact/pile/points"][i], rg["contact/pile/point_forces"][i]
        keep = rg["contact/pile/point_states"][i] != 0
        assert np.all(pts[~keep] == 0.0) and keep.sum() == rg["contact/pile/closed"][i]
        got = np.column_stack([pts[keep], frc[keep], rg["contact/pile/point_states"][i][keep]])
        assert len(got) == len(want) == rg["contact/pile/closed"][i]
        if not want:
            continue
        order = lambda a: a[np.lexsort(np.round(a[:, 2::-1].T, 3))]  # noqa: E731
        got, want = order(got), order(np.array(want))
        # the group's geometry is that of the step's midpoint, the explicit contacts' that of the
        # sample: points apart by at most half a step's travel, the same impulses (so the same
        # force magnitudes) along tangents turned as little
        np.testing.assert_allclose(got[:, :3], want[:, :3], atol=1e-4)
        np.testing.assert_allclose(np.linalg.norm(got[:, 3:6], axis=1), np.linalg.norm(want[:, 3:6], axis=1), rtol=1e-8)
        np.testing.assert_allclose(got[:, 3:6], want[:, 3:6], atol=2e-3 * np.abs(want[:, 3:6]).max())
        np.testing.assert_array_equal(got[:, 6], want[:, 6])
        checked += len(got)
    assert checked > 50
