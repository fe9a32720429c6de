"""The viewer's data (no browser; tests/test_viewer_browser.py drives the page): shapes against
their closed forms, decimation, poses at the kept frames, mode animations, visuals, the
friction-force signal the arrows show, and the errors of `mechsys view`.
"""

from __future__ import annotations

import base64
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys import viewer
from mechsys.viewer import shapes

G = 9.81
MU, MU0 = 0.4, 0.6
PUSH = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0)), 0.0])
ROOT = Path(__file__).resolve().parents[1]


def arr(d: dict) -> np.ndarray:
    return np.frombuffer(base64.b64decode(d["b64"]), dtype=d["dtype"]).reshape(d["shape"])


def pushed_block(planar: bool = False) -> ms.Model:
    """A 1 kg block on a floor with Coulomb friction, pushed by kdot t (1 N/s) 30 degrees off x
    (along x in the plane): it sticks until kdot t = mu0 m g, then slides."""
    if planar:
        m = ms.Model("pushed", gravity=(0, -G, 0))
        b = m.add_body("block", 1.0, ms.inertia.sphere(1.0, 0.1))
        m.add_joint(ms.joints.Planar("pl", m.ground, b))
        m.add_contact(ms.Contact("floor", b.contour(ms.contours.Point()), m.ground.contour(ms.contours.Line(normal=(0, 1, 0))),
                                 friction=ms.laws.Coulomb(mu=MU, mu0=MU0)))
        m.add_force(ms.forces.JointForce("push", "pl", value=[1.0, 0.0, 0.0], function=ms.functions.Ramp(1.0)))
        return m
    m = ms.Model("pushed", gravity=(0, 0, -G))
    b = m.add_body("block", 1.0, ms.inertia.sphere(1.0, 0.1))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, 0, 1, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Point()), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(mu=MU, mu0=MU0)))
    m.add_force(ms.forces.BodyForce("push", b, force=PUSH, function=ms.functions.Ramp(1.0)))
    return m


# ---- the friction force signal (what the arrows draw) ------------------------------------------
@pytest.mark.parametrize("planar", [False, True])
def test_friction_force_holds_the_push_while_sticking_and_is_mu_m_g_against_it_while_sliding(planar):
    res = ms.simulate(pushed_block(planar), t_end=8.0, integrator=ms.EventDriven(), output_dt=0.05)
    f = res["contact/floor/friction_force"]
    assert res.unit("contact/floor/friction_force") == "N"
    assert res.columns("contact/floor/friction_force") == ["x", "y", "z"]
    direction = np.array([1.0, 0.0, 0.0]) if planar else PUSH
    t_break = MU0 * G  # kdot = 1 N/s
    stick = (res.t > 0.1) & (res.t < t_break - 0.1)
    slide = res.t > t_break + 0.1
    # sticking: the floor holds the push exactly, f = -kdot t e
    np.testing.assert_allclose(f[stick], -res.t[stick, None] * direction, atol=1e-9)
    # sliding: mu m g against the motion (along the push)
    np.testing.assert_allclose(f[slide], np.broadcast_to(-MU * G * direction, f[slide].shape), atol=1e-9)


def test_friction_force_of_moreau_jean_is_its_impulse_over_the_step():
    res = ms.simulate(pushed_block(), t_end=8.0, integrator=ms.MoreauJean(dt=1e-3), output_dt=0.05)
    f = res["contact/floor/friction_force"]
    slide = res.t > MU0 * G + 0.2
    np.testing.assert_allclose(f[slide], np.broadcast_to(-MU * G * PUSH, f[slide].shape), atol=1e-6)
    # the same force in the contact's own components: |lambda_t| = |f|
    np.testing.assert_allclose(np.linalg.norm(res["contact/floor/lambda_t"], axis=1), np.linalg.norm(f, axis=1), rtol=1e-12)


# ---- shapes against their closed forms ----------------------------------------------------------
def test_sphere_ellipsoid_cylinder_and_box_vertices_lie_on_their_surfaces():
    c = np.array([0.1, -0.2, 0.3])
    (sph,) = shapes.contour_parts(ms.contours.Sphere(radius=0.5, center=c).describe("s"), 10.0, 0.01)
    np.testing.assert_allclose(np.linalg.norm(sph["v"] - c, axis=1), 0.5, rtol=1e-6)
    (ell,) = shapes.contour_parts(ms.contours.Ellipsoid(semi_axes=(0.3, 0.2, 0.1), center=c, cardan=(0.3, 0.2, 0.1)).describe("e"), 10.0, 0.01)
    a = ms.kinematics.cardan_xyz_to_matrix([0.3, 0.2, 0.1])
    local = (ell["v"] - c) @ a  # back into the ellipsoid's axes
    np.testing.assert_allclose(np.sum((local / [0.3, 0.2, 0.1]) ** 2, axis=1), 1.0, rtol=1e-5)
    (cyl,) = shapes.contour_parts(ms.contours.Cylinder(radius=0.2, length=1.0, axis=(0, 1, 0)).describe("c"), 10.0, 0.01)
    radial = np.hypot(cyl["v"][:, 0], cyl["v"][:, 2])
    on_side = np.abs(radial - 0.2) < 1e-6
    assert on_side.sum() > 0 and np.all(np.abs(cyl["v"][on_side, 1]) <= 0.5 + 1e-6)
    assert np.all(radial <= 0.2 + 1e-6) and np.isclose(np.abs(cyl["v"][:, 1]).max(), 0.5, rtol=1e-6)
    (box,) = shapes.contour_parts(ms.contours.Box(half_extents=(1, 2, 3), center=(1, 0, 0)).describe("b"), 10.0, 0.01)
    np.testing.assert_allclose(np.sort(np.unique(box["v"][:, 0])), [0.0, 2.0])
    np.testing.assert_allclose(np.sort(np.unique(box["v"][:, 2])), [-3.0, 3.0])
    assert len(box["f"]) == 12


def test_capsule_and_torus_vertices_keep_their_distance_from_the_core():
    a, b = np.array([0.0, 0.0, 0.0]), np.array([1.0, 1.0, 0.0])
    (cap,) = shapes.contour_parts(ms.contours.Capsule(a=a, b=b, radius=0.1).describe("c"), 10.0, 0.01)
    d = b - a
    s = np.clip((cap["v"] - a) @ d / (d @ d), 0, 1)
    dist = np.linalg.norm(cap["v"] - (a + s[:, None] * d), axis=1)
    np.testing.assert_allclose(dist[dist > 1e-9], 0.1, rtol=1e-5)
    (tor,) = shapes.contour_parts(ms.contours.Torus(radius=0.5, tube=0.1, axis=(0, 0, 1)).describe("t"), 10.0, 0.01)
    ring = np.hypot(tor["v"][:, 0], tor["v"][:, 1]) - 0.5
    np.testing.assert_allclose(np.hypot(ring, tor["v"][:, 2]), 0.1, rtol=1e-5)


def test_planar_curves_are_drawn_from_the_engine_outline():
    e = ms.contours.Ellipse(a=0.3, b=0.1, center=(0.1, 0.2, 0), angle=0.4)
    mesh, line = shapes.contour_parts(e.describe("e"), 10.0, 0.01)
    p = line["v"][:, :2] - [0.1, 0.2]
    rot = np.array([[np.cos(0.4), np.sin(0.4)], [-np.sin(0.4), np.cos(0.4)]])
    local = p @ rot.T
    np.testing.assert_allclose((local[:, 0] / 0.3) ** 2 + (local[:, 1] / 0.1) ** 2, 1.0, rtol=1e-5)
    # a cam with no lift is its base circle (roller follower: the profile, not the pitch curve)
    cam = ms.contours.Cam(lift=(np.linspace(0, 2 * np.pi, 13).tolist(), [0.0] * 13), base_radius=0.04, roller_radius=0.01)
    _, outline = shapes.contour_parts(cam.describe("cam"), 10.0, 0.01)
    np.testing.assert_allclose(np.hypot(outline["v"][:, 0], outline["v"][:, 1]), 0.04, rtol=1e-6)
    with pytest.raises(ms.ModelError, match="expected a curve"):
        ms._core.curve_outline(json.dumps({"type": "sphere", "radius": 1.0}), "contour 'x'", 10)


def test_a_ground_plane_covers_the_motion_and_nothing_more_than_a_margin():
    d = ms.contours.Plane(normal=(0, 0, 1)).describe("p")
    (part,) = shapes.contour_parts(d, 3.0, 0.01, bounds=([-1.0, -2.0, 0.0], [3.0, 1.0, 5.0]))
    v = part["v"]
    np.testing.assert_allclose(v[:, 2], 0.0)
    pad = 0.25
    np.testing.assert_allclose([v[:, 0].min(), v[:, 0].max(), v[:, 1].min(), v[:, 1].max()],
                               [-1 - pad, 3 + pad, -2 - pad, 1 + pad], atol=1e-6)


# ---- page data ----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def bouncing():
    """A ball bouncing on a floor (Newton, e = 0.8): impacts at known times."""
    m = ms.Model("bounce", gravity=(0, 0, -G))
    b = m.add_body("ball", 0.1, ms.inertia.sphere(0.1, 0.05))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, 0.5, 1, 0, 0, 0], u0=[0.3, 0, 0, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=0.05)), m.ground.contour(ms.contours.Plane()),
                             impact=ms.laws.Newton(0.8)))
    m.add_visual(b, ms.contours.Box(half_extents=(0.01, 0.01, 0.06)), name="stripe", color=(1, 0, 0))
    return ms.simulate(m, t_end=1.5, integrator=ms.EventDriven(), output_dt=1e-4)


def test_frames_are_decimated_and_keep_every_event_sample(bouncing):
    data = viewer.page_data(bouncing, max_frames=200)
    t = arr(data["t"])
    impacts = [e["t"] for e in bouncing.events if e["event"] == "impact"]
    assert len(impacts) >= 3
    assert 200 <= len(t) <= 200 + len(bouncing.events)
    for ti in impacts:
        # the first sample at or after the impact is a kept frame
        k = np.searchsorted(bouncing.t, ti)
        assert np.min(np.abs(t - bouncing.t[k])) == 0.0


def test_poses_at_the_kept_frames_are_the_recorded_ones(bouncing):
    data = viewer.page_data(bouncing, max_frames=300)
    t, pose = arr(data["t"]), arr(data["pose"])
    assert pose.shape == (len(t), 1, 7)
    idx = np.searchsorted(bouncing.t, t)
    np.testing.assert_allclose(pose[:, 0, :3], bouncing["body/ball/position"][idx], atol=1e-6)
    np.testing.assert_allclose(pose[:, 0, 3:], bouncing["body/ball/orientation"][idx], atol=1e-6)


def test_contact_arrows_scale_with_the_forces_and_share_one_scale():
    res = ms.simulate(pushed_block(), t_end=8.0, integrator=ms.EventDriven(), output_dt=0.05)
    data = viewer.page_data(res)
    (c,) = data["contacts"]
    normal, friction, state = arr(c["normal"]), arr(c["friction"]), arr(c["state"])
    scale = 0.2 * data["scene"] / G  # the largest force: the normal force m g
    np.testing.assert_allclose(normal[5:], np.broadcast_to([0, 0, G * scale], normal[5:].shape), rtol=1e-5)
    idx = np.searchsorted(res.t, arr(data["t"]))
    np.testing.assert_allclose(friction, res["contact/floor/friction_force"][idx] * scale, rtol=1e-5, atol=1e-7)
    assert set(np.unique(state[5:])) == {1, 2}  # stick, then slip


def test_visuals_are_drawn_on_their_body(bouncing):
    data = viewer.page_data(bouncing)
    (ball,) = data["bodies"]
    names = [p["name"] for p in ball["parts"]]
    assert "stripe" in names and "floor.contour1" in names
    stripe = next(p for p in ball["parts"] if p["name"] == "stripe")
    assert stripe["color"] == [1.0, 0.0, 0.0]
    np.testing.assert_allclose(np.abs(arr(stripe["v"])).max(axis=0), [0.01, 0.01, 0.06], rtol=1e-6)


def test_plots_keep_a_short_peak_through_decimation():
    t = np.linspace(0.0, 1.0, 100001)
    y = np.zeros_like(t)
    y[31415] = 7.0
    td, yd = viewer._decimate_minmax(t, y[:, None], 2000)
    assert len(td) <= 2100 and yd.max() == 7.0 and td[np.argmax(yd)] == t[31415]


def test_a_trail_is_the_body_point_carried_by_the_pose(bouncing):
    data = viewer.page_data(bouncing, trails=["ball:0,0,0.05"], max_frames=100)
    path = arr(data["trails"][0]["path"])
    t = arr(data["t"])
    idx = np.searchsorted(bouncing.t, t)
    a = np.array([ms.kinematics.quat_to_matrix(q) for q in bouncing["body/ball/orientation"][idx]])
    expect = bouncing["body/ball/position"][idx] + a @ np.array([0, 0, 0.05])
    np.testing.assert_allclose(path, expect, atol=1e-6)


def two_rods():
    m = ms.Model("double", gravity=(0, -G, 0))
    a = m.add_body("upper", 1.0, [1e-4, 1 / 12, 1 / 12], com=(0.5, 0, 0))
    b = m.add_body("lower", 1.0, [1e-4, 1 / 12, 1 / 12], com=(0.5, 0, 0))
    m.add_joint(ms.joints.Revolute("shoulder", m.ground, a, axis=(0, 0, 1), q0=[-np.pi / 2]))
    m.add_joint(ms.joints.Revolute("elbow", a, b, axis=(0, 0, 1), parent_frame=ms.Frame(position=(1, 0, 0))))
    return m


def test_a_mode_animation_swings_the_shape_at_its_frequency():
    lin = ms.linear.linearize(two_rods())
    modes = lin.modes()
    anim = viewer.mode_results(lin, 1, amplitude=0.1, cycles=2.0, frames_per_cycle=40)
    f = modes.natural_frequency[1]
    np.testing.assert_allclose(anim.t[-1], 2.0 / f, rtol=1e-12)
    q = anim.results["q"]
    shape = np.real(modes.shapes_u[:, 1])
    np.testing.assert_allclose(q[0], lin.q + 0.1 * shape, atol=1e-12)
    np.testing.assert_allclose(q[20], lin.q - 0.1 * shape, atol=1e-12)  # half a period later
    # the second mode of two equal hanging rods: the joints swing in opposite senses
    assert shape[0] * shape[1] < 0
    # the poses follow the coordinates: the lower rod's origin is the upper rod's tip
    tip = np.array([np.cos(q[:, 0]), np.sin(q[:, 0]), np.zeros(len(q))]).T
    np.testing.assert_allclose(anim.position[:, 1, :], tip, atol=1e-12)
    data = viewer.page_data(anim)
    assert "mode 2" in data["title"] and data["plots"][0]["columns"] == ["shoulder", "elbow"]


def test_bad_options_name_the_item(bouncing):
    with pytest.raises(ms.SettingsError, match="trail: no body 'nobody'"):
        viewer.page_data(bouncing, trails=["nobody"])
    with pytest.raises(ms.SettingsError, match="signal 'nope' is not in the results"):
        viewer.page_data(bouncing, signals=["nope"])
    with pytest.raises(ms.SettingsError, match="follow: no body 'x'"):
        viewer.page_data(bouncing, follow="x")
    with pytest.raises(ms.SettingsError, match="max_frames"):
        viewer.page_data(bouncing, max_frames=1)
    with pytest.raises(ms.SettingsError, match="must end in .html"):
        viewer.to_html(bouncing, "/tmp/page.txt")
    with pytest.raises(ms.SettingsError, match="mode must be"):
        viewer.mode_results(ms.linear.linearize(two_rods()), 7)


def test_a_missing_bundle_is_a_clear_error(bouncing, monkeypatch, tmp_path):
    monkeypatch.setattr(viewer, "_BUNDLE", tmp_path / "nowhere")
    with pytest.raises(ms.ResultsError, match="make viewer"):
        viewer.to_html(bouncing, tmp_path / "p.html")


def test_visual_errors_name_the_visual():
    m = ms.Model("v")
    b = m.add_body("b", 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Free("f", m.ground, b))
    m.add_visual("nobody", ms.contours.Sphere(radius=1), name="head")
    with pytest.raises(ms.ModelError, match=r"visuals\[0\] 'head'.body.*nobody"):
        m.build()
    m = ms.Model("v")
    b = m.add_body("b", 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Free("f", m.ground, b))
    m.add_visual(b, ms.contours.Sphere(radius=1), color=(2, 0, 0))
    with pytest.raises(ms.ModelError, match=r"visuals\[0\].color"):
        m.build()
    with pytest.raises(ms.ModelError, match="no such mesh file"):
        m.add_visual(b, "/nonexistent/part.stl")
    with pytest.raises(ms.ModelError, match=r"visual 'x'.shape"):
        m.add_visual(b, 42, name="x")


def test_a_toml_visual_reads_its_mesh_file(tmp_path):
    import trimesh

    trimesh.creation.box(extents=(2.0, 2.0, 2.0)).export(tmp_path / "cube.stl")
    (tmp_path / "m.toml").write_text("""
name = "vis"
gravity = [0, 0, -9.81]
[[bodies]]
name = "b"
mass = 1.0
inertia = [1, 1, 1]
[[joints]]
name = "f"
type = "free"
parent = "ground"
child = "b"
[[visuals]]
name = "cube"
body = "b"
shape = { type = "mesh", file = "cube.stl", scale = 0.5 }
color = [0.2, 0.4, 0.6]
[simulation]
t_end = 0.01
""")
    from mechsys.modelfile import load_model

    model, _ = load_model(tmp_path / "m.toml")
    (vis,) = model.to_dict()["visuals"]
    np.testing.assert_allclose(np.abs(np.asarray(vis["shape"]["vertices"])).max(), 0.5)
    res = ms.simulate(model, t_end=0.01)
    assert res.model["visuals"][0]["name"] == "cube"


# ---- the command line ---------------------------------------------------------------------------
def mechsys(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "mechsys", *args], capture_output=True, text=True, cwd=cwd, timeout=120)


def test_mechsys_view_writes_a_self_contained_page(bouncing, tmp_path):
    src = bouncing.save(tmp_path / "bounce.h5")
    r = mechsys("view", str(src), "--trail", "ball", "--signals", "contact/floor/lambda_n,energy/total")
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "bounce.html").read_text()
    assert "<script" in page and "http://" not in page.split("mechsys-data")[0].lower().replace("http://www.w3.org", "")
    data = json.loads(page.split('id="mechsys-data">')[1].split("</script>")[0].replace("<\\/", "</"))
    assert [p["name"] for p in data["plots"]] == ["contact/floor/lambda_n", "energy/total"]
    assert data["trails"][0]["body"] == "ball"


def test_mechsys_view_refuses_a_truncated_file_and_a_model_without_mode(bouncing, tmp_path):
    src = bouncing.save(tmp_path / "bounce.h5")
    cut = tmp_path / "cut.h5"
    cut.write_bytes(src.read_bytes()[: src.stat().st_size // 3])
    r = mechsys("view", str(cut))
    assert r.returncode == 2 and "cut.h5" in r.stderr and "Traceback" not in r.stderr
    r = mechsys("view", str(ROOT / "examples" / "pendulum.toml"))
    assert r.returncode == 2 and "--mode" in r.stderr
    r = mechsys("view", str(src), "--out", str(src))
    assert r.returncode == 2 and "--out" in r.stderr


def test_mechsys_view_mode_of_a_model_file(tmp_path):
    r = mechsys("view", str(ROOT / "examples" / "pendulum.toml"), "--mode", "1", "--at", "equilibrium", "-o", str(tmp_path / "m.html"))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "m.html").stat().st_size > 100_000
    r = mechsys("view", str(ROOT / "examples" / "pendulum.toml"), "--mode", "9", "-o", str(tmp_path / "m.html"))
    assert r.returncode == 2 and "modes 1 to" in r.stderr


def test_solids_are_wound_outward():
    """Front faces outward (three.js culls back faces): each triangle's normal points away from
    the solid's centre."""
    for d in (ms.contours.Sphere(radius=0.5).describe("s"), ms.contours.Cylinder(radius=0.2, length=1.0).describe("c"),
              ms.contours.Box(half_extents=(1, 2, 3)).describe("b"), ms.contours.Ellipsoid(semi_axes=(1, 2, 3)).describe("e"),
              ms.contours.Capsule(a=(0, 0, -1), b=(0, 0, 1), radius=0.3).describe("k")):
        (part,) = shapes.contour_parts(d, 10.0, 0.01)
        v, f = part["v"].astype(float), part["f"]
        n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
        centroid = v[f].mean(axis=1)
        area = np.linalg.norm(n, axis=1)
        keep = area > 1e-12 * area.max()
        assert np.all(np.einsum("ij,ij->i", n[keep], centroid[keep]) > 0), d["type"]


def test_view_writes_a_page_and_in_a_notebook_returns_an_inline_frame(bouncing, monkeypatch, tmp_path):
    page = ms.view(bouncing, tmp_path / "v.html", open_browser=False)
    assert Path(page).read_text().count('id="mechsys-data"') == 1
    monkeypatch.setattr(viewer, "_in_notebook", lambda: True)
    shown = ms.view(bouncing)
    html_text = shown._repr_html_()
    assert html_text.startswith("<iframe srcdoc=") and "mechsys-data" in html_text


def test_a_run_recorded_without_body_poses_is_drawn_from_its_coordinates():
    m = two_rods()
    full = ms.simulate(m, t_end=0.5, integrator=ms.RK4(dt=1e-3), output_dt=0.01)
    sparse = ms.simulate(m, t_end=0.5, integrator=ms.RK4(dt=1e-3), output_dt=0.01, sensors=["joint/*/q"])
    assert "body/lower/position" not in sparse
    a, b = viewer.page_data(full), viewer.page_data(sparse)
    np.testing.assert_allclose(arr(b["pose"]), arr(a["pose"]), atol=1e-6)


def test_an_elastic_body_is_drawn_by_its_deflected_nodes():
    """The slider-crank's elastic rod: its node line's displacement at every kept frame is the
    nodes' translation fields times the recorded elastic coordinates, magnified by a power of ten."""
    import runpy

    ns = runpy.run_path(str(ROOT / "examples" / "flexible_slider_crank.py"), run_name="x")
    res = ms.simulate(ns["model"], **dict(ns["simulation"], t_end=0.02, output_dt=1e-3))
    data = viewer.page_data(res)
    (e,) = data["elastic"]
    assert data["bodies"][e["body"]]["name"] == "rod"
    body = ns["ROD_BODY"]
    np.testing.assert_allclose(arr(e["nodes"]), body.nodes, atol=1e-7)
    idx = np.searchsorted(res.t, arr(data["t"]))
    expect = np.einsum("fk,nck->fnc", res["body/rod/elastic_q"][idx], body.modes[:, :3, :])
    np.testing.assert_allclose(arr(e["disp"]), expect, atol=1e-9 + 1e-6 * np.abs(expect).max())
    assert e["scale"] in (1.0, 10.0, 100.0, 1000.0) and e["scale"] * e["largest"] <= 0.05 * data["scene"] + 1e-12
    # drawn by its node line, not by rods from its centre of mass
    assert not data["bodies"][e["body"]]["stick"]
