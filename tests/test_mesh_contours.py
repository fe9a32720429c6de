"""Triangle meshes as contact contours (issue 14, part 5): ms.contours.Mesh from arrays, STL/OBJ
files and model files, against closed forms (a ball rolling in a bowl, a bouncing ball, a box at
rest) and against the equivalent explicit contacts of a contact group."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

import mechsys as ms

G = 9.81


def cap(R: float, rc: float, n: int):
    """The bottom of a spherical cavity of radius R about the origin, within rc of its axis: an
    n × n grid over [-rc, rc]² lifted onto z = -√(R² - x² - y²); triangles counter-clockwise seen
    from above (normals up, into the cavity: the solid lies below)."""
    xs = np.linspace(-rc, rc, n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    Z = -np.sqrt(np.maximum(R**2 - X**2 - Y**2, 0.0))  # (corners beyond the rim are not used)
    v = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    inside = X**2 + Y**2 <= rc**2
    tris = []
    for j in range(n):
        for i in range(n):
            if inside[j, i] and inside[j, i + 1] and inside[j + 1, i] and inside[j + 1, i + 1]:
                a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i
                tris += [[a, b, c], [a, c, d]]
    return v, np.array(tris)


def floor(half: float = 1.0, n: int = 4, z: float = 0.0):
    """A square floor of 2 n² triangles at height z, normals up."""
    xs = np.linspace(-half, half, n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    v = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, z)])
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i
            tris += [[a, b, c], [a, c, d]] if (i + j) % 2 == 0 else [[a, b, d], [b, c, d]]
    return v, np.array(tris)


def crossings(t, x):
    k = np.where((x[:-1] > 0) & (x[1:] <= 0))[0]
    return t[k] + (t[k + 1] - t[k]) * x[k] / (x[k] - x[k + 1])


def ball_in_bowl(mesh, R, r, phi0):
    m = ms.Model("bowl", gravity=(0.0, 0.0, -G))
    ball = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, r))
    x0, z0 = (R - r) * math.sin(phi0), -(R - r) * math.cos(phi0)
    m.add_joint(ms.joints.Free("free", m.ground, ball, q0=[x0, 0.0, z0, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("bowl", ball.contour(ms.contours.Sphere(radius=r)), m.ground.contour(mesh),
                             friction=ms.laws.Coulomb(mu=1.0)))
    return m


@pytest.mark.parametrize("integrator", [ms.MoreauJean(1e-3), ms.EventDriven()], ids=["MoreauJean", "EventDriven"])
def test_a_ball_rolling_in_a_mesh_bowl_has_the_period_of_the_spherical_cavity(integrator):
    # T = 2 pi sqrt(7 (R - r) / (5 g)) for a solid ball rolling in a sphere; the tessellated bowl
    # approaches it as the grid is refined (a 0.1 rad swing adds phi0²/16 = 0.06 % to the period).
    # Rolling over a concave edge the normal turns by the edges' angle: a small impact (the
    # event-driven scheme's event of a closed point starting to approach), energy lost ∝ h
    R, r, phi0 = 0.5, 0.05, 0.1
    expected = 2 * math.pi * math.sqrt(7 * (R - r) / (5 * G))
    errors, lost = [], []
    for n in (24, 48, 96):
        v, t = cap(R, 0.12, n)
        res = ms.simulate(ball_in_bowl(ms.contours.Mesh(v, t), R, r, phi0), t_end=3.3, integrator=integrator, output_dt=1e-3)
        tc = crossings(res.t, res["joint/free/q"][:, 0])
        assert len(tc) >= 2
        errors.append(abs(np.diff(tc).mean() / expected - 1))
        lost.append(-np.diff(res["energy/total"][[0, -1]])[0])
        # it stays in the bowl, touching (gap within the step's penetration), rolling
        assert np.abs(res["contact/bowl/g_n"]).max() < 1e-3
        assert res["contact/bowl/lambda_n"].max() > 0
    assert errors[2] < 5e-3, errors
    assert errors[2] < errors[1] < errors[0], errors
    if isinstance(integrator, ms.EventDriven):
        # the energy lost at the edges falls with the edge angle (≈ h / R), from a swing's 0.022 J
        assert 0 < lost[2] < lost[1] < lost[0] < 1e-3, lost


def test_a_ball_bounces_on_a_mesh_floor_as_on_a_plane_in_both_integrators():
    # dropped from h onto a tessellated floor with Newton's law: first impact at sqrt(2 h / g),
    # rebound to eps² h; the same as on the analytic plane
    h, r, eps = 0.3, 0.05, 0.8
    v, t = floor(1.0, 4, z=0.0)
    for integrator in (ms.EventDriven(), ms.MoreauJean(1e-4)):
        m = ms.Model("drop", gravity=(0.0, 0.0, -G))
        ball = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, r))
        # above a vertex shared by six triangles, 0.13 off it: the contact is on a face
        m.add_joint(ms.joints.Free("free", m.ground, ball, q0=[0.13, 0.02, h + r, 1.0, 0.0, 0.0, 0.0]))
        m.add_contact(ms.Contact("floor", ball.contour(ms.contours.Sphere(radius=r)), m.ground.contour(ms.contours.Mesh(v, t)),
                                 impact=ms.laws.Newton(eps=eps)))
        res = ms.simulate(m, t_end=0.9, integrator=integrator, output_dt=1e-4)
        z = res["joint/free/q"][:, 2] - r
        t_hit = math.sqrt(2 * h / G)
        first = res.t[np.argmax(z < 1e-3)]
        assert first == pytest.approx(t_hit, abs=2e-3)
        apex = z[(res.t > t_hit) & (res.t < 3 * t_hit)].max()
        assert apex == pytest.approx(eps**2 * h, rel=2e-3), type(integrator).__name__
        if isinstance(integrator, ms.EventDriven):
            hits = [e["t"] for e in res.events if e["event"] == "impact"]
            assert hits[0] == pytest.approx(t_hit, rel=1e-9)


@pytest.mark.parametrize("integrator", [ms.EventDriven(), ms.MoreauJean(1e-3)], ids=["EventDriven", "MoreauJean"])
def test_a_box_resting_on_a_mesh_floor_carries_its_weight_on_four_corners(integrator):
    mass = 2.0
    v, t = floor(1.0, 5, z=0.0)
    m = ms.Model("box", gravity=(0.0, 0.0, -G))
    box = m.add_body("box", mass, ms.inertia.box(mass, (0.3, 0.2, 0.1)))
    # turned about z: its corners land inside triangles and on edges of the grid
    qz = 0.35
    m.add_joint(ms.joints.Free("free", m.ground, box, q0=[0.05, -0.02, 0.05 + 1e-4, math.cos(qz / 2), 0.0, 0.0, math.sin(qz / 2)]))
    m.add_contact(ms.Contact("floor", box.contour(ms.contours.Box(half_extents=(0.15, 0.1, 0.05))),
                             m.ground.contour(ms.contours.Mesh(v, t)), friction=ms.laws.Coulomb(mu=0.5)))
    res = ms.simulate(m, t_end=0.5, integrator=integrator, output_dt=1e-2)
    lam = res["contact/floor/lambda_n"][-1]
    assert lam.shape == (8,)
    assert lam.sum() == pytest.approx(mass * G, rel=1e-6)
    g = res["contact/floor/g_n"][-1]
    # the four lower corners touch and carry it, the upper four are a box height above (Moreau–
    # Jean keeps the penetration of its first, plastic impact step: v dt)
    tol = 1e-9 if isinstance(integrator, ms.EventDriven) else 1e-4
    assert np.sort(g)[:4] == pytest.approx(0.0, abs=tol) and np.sort(g)[4:] == pytest.approx(0.1, abs=tol)
    assert np.all(lam[g > 0.05] == 0) and np.all(lam[g < 0.05] > 0)
    assert res["joint/free/q"][-1, 2] == pytest.approx(0.05, abs=tol)


def test_a_capsule_lying_on_a_mesh_floor_rests_on_its_end_spheres():
    # a rod of length L and radius r across the grid: each end sphere carries half its weight
    mass, L, r = 1.5, 0.4, 0.03
    v, t = floor(1.0, 7, z=0.0)
    m = ms.Model("rod", gravity=(0.0, 0.0, -G))
    rod = m.add_body("rod", mass, ms.inertia.cylinder(mass, r, L, axis="x"))
    qz = 0.6
    m.add_joint(ms.joints.Free("free", m.ground, rod, q0=[0.1, 0.05, r + 1e-4, math.cos(qz / 2), 0.0, 0.0, math.sin(qz / 2)]))
    m.add_contact(ms.Contact("floor", rod.contour(ms.contours.Capsule(a=(-L / 2, 0, 0), b=(L / 2, 0, 0), radius=r)),
                             m.ground.contour(ms.contours.Mesh(v, t)), friction=ms.laws.Coulomb(mu=0.5)))
    res = ms.simulate(m, t_end=0.5, integrator=ms.EventDriven(), output_dt=1e-2)
    lam = res["contact/floor/lambda_n"][-1]
    assert lam == pytest.approx([mass * G / 2] * 2, rel=1e-6)
    assert res["contact/floor/g_n"][-1] == pytest.approx([0.0, 0.0], abs=1e-9)
    assert res["joint/free/q"][-1, 2] == pytest.approx(r, abs=1e-9)


def test_a_ball_beside_an_open_bowl_falls_freely():
    # beyond an open mesh's boundary there is no material: a ball beside the bowl's rim, below it,
    # falls as in free space (g_N > 0 throughout, no force)
    v, t = cap(0.5, 0.12, 24)
    m = ms.Model("outside", gravity=(0.0, 0.0, -G))
    ball = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, 0.05))
    m.add_joint(ms.joints.Free("free", m.ground, ball, q0=[0.25, 0.0, -0.5, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("bowl", ball.contour(ms.contours.Sphere(radius=0.05)), m.ground.contour(ms.contours.Mesh(v, t))))
    for integrator in (ms.MoreauJean(1e-3), ms.EventDriven()):
        res = ms.simulate(m, t_end=0.3, integrator=integrator, output_dt=1e-2)
        assert res["contact/bowl/g_n"].min() > 0.05
        assert np.all(res["contact/bowl/lambda_n"] == 0)
        assert res["joint/free/q"][:, 2] == pytest.approx(-0.5 - 0.5 * G * res.t**2, abs=1e-9)


def test_spheres_in_a_mesh_container_as_a_group_equal_the_explicit_contacts():
    # the group's pairs go through the same narrow phase: the same motion as the declared pairs
    def model(group: bool):
        m = ms.Model("cup", gravity=(0.0, 0.0, -G))
        v, t = cap(0.4, 0.3, 24)
        bowl = m.ground.contour(ms.contours.Mesh(v, t))
        members = []
        for i, (x, y) in enumerate([(0.0, 0.0), (0.09, 0.02), (-0.05, 0.08)]):
            b = m.add_body(f"b{i}", 0.1, ms.inertia.sphere(0.1, 0.04))
            m.add_joint(ms.joints.Free(f"f{i}", m.ground, b, q0=[x, y, -0.3 + 0.02 * i, 1.0, 0.0, 0.0, 0.0]))
            members.append(b.contour(ms.contours.Sphere(radius=0.04)))
        law = dict(friction=ms.laws.Coulomb(mu=0.3), impact=ms.laws.Newton(eps=0.2))
        if group:
            m.add_contact(ms.ContactGroup("cup", members=members, against=[bowl], **law))
        else:
            for i in range(3):
                for j in range(i + 1, 3):
                    m.add_contact(ms.Contact(f"c{i}{j}", members[i], members[j], **law))
                m.add_contact(ms.Contact(f"c{i}w", members[i], bowl, **law))
        return m

    integ = ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-11, max_iter=100_000))
    rg = ms.simulate(model(True), 0.5, integ, output_dt=1e-2)
    rc = ms.simulate(model(False), 0.5, integ, output_dt=1e-2)
    np.testing.assert_allclose(rg["q"], rc["q"], rtol=0, atol=1e-10)
    # they came to rest on the bowl's floor, below its rim
    assert np.all(rg["q"][-1, [2, 9, 16]] < -0.3)


STL = """solid tri
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 1 1 0
 endloop
endfacet
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 1 1 0
  vertex 0 1 0
 endloop
endfacet
endsolid tri
"""

OBJ = """# a unit square, two triangles, normals up
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
f 1 2 3
f 1 3 4
"""


def _drop_on(contour) -> ms.Model:
    m = ms.Model("drop", gravity=(0.0, 0.0, -G))
    b = m.add_body("ball", 1.0, ms.inertia.sphere(1.0, 0.05))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0.6, 0.3, 0.1, 1.0, 0.0, 0.0, 0.0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=0.05)), m.ground.contour(contour)))
    return m


def test_mesh_files_read_through_trimesh(tmp_path):
    (tmp_path / "sq.stl").write_text(STL)
    (tmp_path / "sq.obj").write_text(OBJ)
    stl = ms.contours.Mesh.from_file(tmp_path / "sq.stl", scale=2.0)
    obj = ms.contours.Mesh.from_file(tmp_path / "sq.obj", scale=2.0)
    # the STL's six vertices merge into four; both are the same surface
    assert len(stl.vertices) == 4 and len(obj.vertices) == 4 and len(stl.triangles) == 2
    for mesh in (stl, obj):
        assert mesh.vertices.max() == 2.0
        n = np.cross(*(mesh.vertices[mesh.triangles[:, k]] - mesh.vertices[mesh.triangles[:, 0]] for k in (1, 2)))
        assert np.all(n[:, 2] > 0)
        geo = ms.dynamics.contact_geometry(_drop_on(mesh), [0.6, 0.3, 0.1, 1.0, 0.0, 0.0, 0.0])
        assert geo["gap"][0] == pytest.approx(0.05, abs=1e-14)
        assert np.allclose(geo["normal"][0], [0.0, 0.0, 1.0])
    # flipped: the solid is above, the ball's centre inside it
    flipped = ms.contours.Mesh.from_file(tmp_path / "sq.obj", scale=2.0, flip=True)
    geo = ms.dynamics.contact_geometry(_drop_on(flipped), [0.6, 0.3, 0.1, 1.0, 0.0, 0.0, 0.0])
    assert geo["gap"][0] == pytest.approx(-0.15, abs=1e-14)


def test_mesh_input_errors_name_the_contour_and_the_file(tmp_path, monkeypatch):
    with pytest.raises(ms.ModelError, match=r"Mesh: vertex 1 must be finite"):
        ms.contours.Mesh([[0, 0, 0], [1, float("nan"), 0], [0, 1, 0]], [[0, 1, 2]])
    with pytest.raises(ms.ModelError, match=r"Mesh: triangle 0 vertex 2 is index 3, out of range"):
        ms.contours.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])
    with pytest.raises(ms.ModelError, match=r"Mesh.triangles: expected an \(m, 3\) array of whole vertex indices"):
        ms.contours.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 1.5]])
    with pytest.raises(ms.ModelError, match=r"Mesh: the mesh has no triangles"):
        ms.contours.Mesh(np.zeros((3, 3)), np.zeros((0, 3), dtype=int))
    with pytest.raises(ms.ModelError, match=r"no such mesh file '.*nothing.stl'"):
        ms.contours.Mesh.from_file(tmp_path / "nothing.stl")
    (tmp_path / "empty.obj").write_text("# nothing here\n")
    with pytest.raises(ms.ModelError, match=r"empty.obj' contains no triangles"):
        ms.contours.Mesh.from_file(tmp_path / "empty.obj")
    # the engine's checks name the contact: a degenerate triangle, opposite windings
    deg = ms.contours.Mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(ms.ModelError, match=r"contacts\[0\] 'floor'.contour2: triangle 0 \(vertices 0, 1, 2\) is degenerate"):
        _drop_on(deg).build()
    wound = ms.contours.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 3, 2]])
    with pytest.raises(ms.ModelError, match=r"contacts\[0\] 'floor'.contour2: triangles 0 and 1 are wound in opposite senses"):
        _drop_on(wound).build()
    # an unsupported partner
    m = ms.Model("can")
    can = m.add_body("can", 1.0, ms.inertia.sphere(1.0, 0.1))
    m.add_joint(ms.joints.Free("free", m.ground, can))
    square = ms.contours.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    m.add_contact(ms.Contact("floor", can.contour(ms.contours.Cylinder(radius=0.1, length=0.2)), m.ground.contour(square)))
    with pytest.raises(ms.ModelError, match=r"cylinder–mesh"):
        m.build()
    # without trimesh: a clear message instead of an ImportError
    (tmp_path / "sq.stl").write_text(STL)
    monkeypatch.setitem(sys.modules, "trimesh", None)
    with pytest.raises(ms.ModelError, match=r"needs the 'trimesh' package"):
        ms.contours.Mesh.from_file(tmp_path / "sq.stl")


BALL = """
name = "marble"
gravity = [0, 0, -9.81]

[[bodies]]
name = "ball"
mass = 1.0
inertia = [0.001, 0.001, 0.001]

[[joints]]
name = "free"
type = "free"
parent = "ground"
child = "ball"
q0 = [0.6, 0.3, 0.1, 1, 0, 0, 0]
"""

MODEL = BALL + """
[[contacts]]
name = "floor"
body1 = "ball"
contour1 = { type = "sphere", radius = 0.05 }
body2 = "ground"
contour2 = CONTOUR
"""


def _write_model(tmp_path, contour: str):
    path = tmp_path / "model.toml"
    path.write_text(MODEL.replace("CONTOUR", contour))
    return path


def test_model_files_take_a_mesh_file_or_inline_triangles(tmp_path):
    from mechsys.modelfile import load_model

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "sq.obj").write_text(OBJ)
    state = [0.6, 0.3, 0.1, 1.0, 0.0, 0.0, 0.0]
    for contour in ('{ type = "mesh", file = "meshes/sq.obj", scale = 2.0 }',
                    '{ type = "mesh", vertices = [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], triangles = [[0, 1, 2], [0, 2, 3]] }'):
        model, _ = load_model(_write_model(tmp_path, contour))
        geo = ms.dynamics.contact_geometry(model, state)
        assert geo["gap"][0] == pytest.approx(0.05, abs=1e-14)
    # relative to the model file, not to the working directory
    model, _ = load_model(_write_model(tmp_path, '{ type = "mesh", file = "meshes/sq.obj", flip = true }'))
    assert ms.dynamics.contact_geometry(model, state)["gap"][0] == pytest.approx(-0.15, abs=1e-14)
    bad = {
        '{ type = "mesh", file = "meshes/none.stl" }': r"contacts\[0\] 'floor'.contour2.file: no such mesh file",
        '{ type = "mesh", file = "model.toml" }': r"contacts\[0\] 'floor'.contour2.file: .*model.toml",
        '{ type = "mesh", vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles = [[0, 1, 7]] }':
            r"contacts\[0\] 'floor'.contour2: triangle 0 vertex 2 is index 7, out of range",
        '{ type = "mesh", vertices = [[0, 0, 0]], triangles = [] }': r"contacts\[0\] 'floor'.contour2: the mesh has no triangles",
        '{ type = "mesh", vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles = [[0, 1, 2]], scale = -1 }':
            r"contour2.scale: must be > 0",
        '{ type = "mesh", file = "meshes/sq.obj", colour = "red" }': r"contour2: unknown key\(s\) colour",
        '{ type = "mesh" }': r"contour2: a mesh needs a file or both vertices and triangles",
    }
    for contour, message in bad.items():
        with pytest.raises(ms.ModelError, match=message):
            load_model(_write_model(tmp_path, contour))
    # a description that reaches the engine with a file (not through the loader) is refused clearly
    import tomllib

    desc = tomllib.loads(MODEL.replace("CONTOUR", '{ type = "mesh", file = "meshes/sq.obj" }'))
    with pytest.raises(ms.ModelError, match=r"contour2.file: mesh files are read by the Python model loader"):
        ms.Model.from_dict(desc).build()


GROUP_MODEL = BALL.replace('"marble"', '"group"') + """
[[contact_groups]]
name = "balls"
members = [{ body = "ball", contour = { type = "sphere", radius = 0.05 } }]
against = [{ body = "ground", contour = { type = "mesh", file = "sq.obj", scale = 2.0 } }]
"""


def test_a_contact_group_in_a_model_file_takes_a_mesh_file(tmp_path):
    from mechsys.modelfile import load_model

    (tmp_path / "sq.obj").write_text(OBJ)
    (tmp_path / "group.toml").write_text(GROUP_MODEL)
    model, _ = load_model(tmp_path / "group.toml")
    res = ms.simulate(model, t_end=0.5, integrator=ms.MoreauJean(1e-3), output_dt=1e-2)
    # dropped 5 cm onto the floor, at rest on it (within the plastic impact step's v dt)
    assert res["joint/free/q"][-1, 2] == pytest.approx(0.05, abs=1e-3)
    assert np.abs(res["u"][-1]).max() < 1e-9
    (tmp_path / "group.toml").write_text(GROUP_MODEL.replace('file = "sq.obj"', 'file = "missing.obj"'))
    with pytest.raises(ms.ModelError, match=r"contact_groups\[0\] 'balls'.against\[0\].contour.file: no such mesh file"):
        load_model(tmp_path / "group.toml")
