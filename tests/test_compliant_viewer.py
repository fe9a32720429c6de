"""Compliant contacts in the viewer and the plots (issue 19, item 5): the recorded contact point,
normal and friction force of a compliant contact, drawn like a rigid contact's dot and arrows."""

from __future__ import annotations

import base64
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys import viewer

R, M = 0.05, 0.2
SOFT = ms.Material(E=1e7, nu=0.3, density=1000.0)


def arr(d):
    return np.frombuffer(base64.b64decode(d["b64"]), dtype=d["dtype"]).reshape(d["shape"])


@pytest.fixture(scope="module")
def rolling():
    """A soft ball thrown sideways onto the floor: it bounces, then slides and rolls (friction)."""
    m = ms.Model("soft-ball", gravity=(0, 0, -9.81))
    b = m.add_body("ball", M, ms.inertia.sphere(M, R))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, 0.12, 1, 0, 0, 0], u0=[0.8, 0, 0, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Sphere(radius=R), material=SOFT),
                             m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)), material=SOFT),
                             normal=ms.laws.HuntCrossley(eps=0.5, v_reg=1e-3), friction=ms.laws.Coulomb(mu=0.4)))
    return ms.simulate(m, t_end=0.6, output_dt=1e-3, integrator=ms.DOPRI5(rtol=1e-9, atol=1e-12), progress=False)


def test_point_normal_and_friction_are_recorded(rolling):
    """The point on the ball is its lowest point (centre minus R along z), the normal is +z, and the
    friction force is F_T1 t1 + F_T2 t2 against the slip."""
    p = rolling["contact/floor/point"]
    c = rolling["body/ball/position"]
    np.testing.assert_allclose(p[:, :2], c[:, :2], atol=1e-12)
    np.testing.assert_allclose(p[:, 2], c[:, 2] - R, atol=1e-12)
    np.testing.assert_allclose(rolling["contact/floor/normal"], np.broadcast_to([0, 0, 1], p.shape), atol=1e-12)
    ft = rolling["contact/floor/friction_force"]
    assert np.allclose(np.linalg.norm(ft, axis=1), np.linalg.norm(rolling["contact/floor/force_t"], axis=1), rtol=1e-9, atol=1e-12)
    # against the slip: F_T · v_slip <= 0 where it slides
    touching = rolling["contact/floor/overlap"] > 0
    assert touching.any() and (~touching).any()
    work = np.einsum("ij,ij->i", rolling["contact/floor/force_t"], rolling["contact/floor/slip_velocity"])
    assert np.all(work[touching] <= 1e-15) and work[touching].min() < 0
    assert rolling.unit("contact/floor/point") == "m" and rolling.unit("contact/floor/friction_force") == "N"


def test_viewer_draws_the_compliant_contact_where_it_overlaps(rolling):
    data = viewer.page_data(rolling, max_frames=600)
    (c,) = data["contacts"]
    assert c["contact"] == "floor"
    idx = np.searchsorted(rolling.t, arr(data["t"]))
    state, normal, point = arr(c["state"]), arr(c["normal"]), arr(c["point"])
    over = rolling["contact/floor/overlap"][idx] > 0
    np.testing.assert_array_equal(state > 0, over)
    # both kinds seen: sliding after the landing, then rolling without slip (under 1 µm/s)
    assert {1, 2} <= set(np.unique(state[over]).tolist())
    # the normal arrow is the normal force along +z, on the scale shared with the friction arrow
    f = rolling["contact/floor/force_n"][idx]
    scale = 0.2 * data["scene"] / max(f.max(), np.linalg.norm(rolling["contact/floor/friction_force"][idx], axis=1).max())
    np.testing.assert_allclose(normal[:, 2], f * scale, rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(point, rolling["contact/floor/point"][idx], atol=1e-6)
    # the default plots show its normal force
    assert "contact/floor/force_n" in [p["name"] for p in data["plots"]]


def test_view_and_plot_from_the_command_line(rolling, tmp_path):
    h5 = tmp_path / "ball.h5"
    rolling.save(h5)
    script = Path(sys.executable).parent / "mechsys"
    r = subprocess.run([str(script), "view", str(h5), "-o", str(tmp_path / "ball.html")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "ball.html").read_text()
    assert '"contact":"floor"' in page
    r = subprocess.run([str(script), "plot", str(h5), "contact/floor/force_n", "contact/floor/point", "contact/floor/overlap",
                        "-o", str(tmp_path / "ball.png")], capture_output=True, text=True, env={"MPLBACKEND": "Agg", **__import__("os").environ})
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "ball.png").stat().st_size > 1000


def test_viewer_draws_a_compliant_groups_touching_points(tmp_path):
    """examples/compliant_pile.toml: the group records its first touching points (two per member at
    most) with the force on their first contour; the viewer draws them as a rigid group's."""
    from mechsys.modelfile import load_model

    model, sim = load_model(Path(__file__).resolve().parents[1] / "examples" / "compliant_pile.toml")
    res = ms.simulate(model, t_end=0.5, output_dt=1e-2, integrator=ms.DOPRI5(rtol=1e-7, atol=1e-10), progress=False)
    n_pts = res["contact/pile/touching_points"]
    pts, forces, states = res["contact/pile/points"], res["contact/pile/point_forces"], res["contact/pile/point_states"]
    assert pts.shape[1] == 12 and n_pts.max() >= 6
    np.testing.assert_array_equal(states.sum(axis=1), np.minimum(n_pts, 12))
    # the drawn points lie within the box and carry forces (zero only where a separating contact's
    # damped force is cut off); undrawn slots are zero
    drawn = states > 0
    norms = np.linalg.norm(forces[drawn], axis=1)
    assert np.all(norms >= 0) and np.mean(norms > 0) > 0.9
    assert np.all(np.abs(forces[~drawn]) == 0)
    assert np.all(np.abs(pts[drawn][:, :2]) <= 0.12 + 1e-3) and np.all(pts[drawn][:, 2] >= -1e-3)  # (the overlap)
    # a point on the floor (z near 0) is pushed up
    on_floor = drawn & (pts[:, :, 2] < 1e-3)
    assert on_floor.any() and np.all(forces[on_floor][:, 2] >= 0)
    data = viewer.page_data(res)
    group = [c for c in data["contacts"] if c["contact"] == "pile"]
    assert len(group) == 12
    idx = np.searchsorted(res.t, arr(data["t"]))
    st = np.stack([arr(c["state"]) for c in group], axis=1)
    np.testing.assert_array_equal(st > 0, drawn[idx])
