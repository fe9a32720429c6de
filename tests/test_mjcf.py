"""MJCF import (mechsys.mjcf) checked against MuJoCo's own dynamics of the same file.

tests/data/mjcf_arm.xml is written for this test (see its header): turned body and inertial
frames, hinge axes off the body origin, reference positions, a slide, a ball joint and welded
bodies. MuJoCo compiles the file once for the import and once for the reference; the mass matrix
(mj_fullM) and the accelerations (mj_forward with its constraint solver switched off, so qacc is
M^-1 (tau - c)) must agree with ours to rounding.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys.mjcf import load_mjcf

mujoco = pytest.importorskip("mujoco")

ARM = Path(__file__).parent / "data" / "mjcf_arm.xml"


def mj_model(source):
    m = mujoco.MjModel.from_xml_path(str(source)) if isinstance(source, Path) else mujoco.MjModel.from_xml_string(source)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)  # no limits, no contacts: the smooth dynamics
    return m


def configurations(m, n, seed):
    """Random (qpos, qvel) of a MuJoCo model: hinge and slide values about their reference,
    unit quaternions for ball and free joints."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        q = m.qpos0.copy()
        for j in range(m.njnt):
            a, kind = int(m.jnt_qposadr[j]), int(m.jnt_type[j])
            free, ball = int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL)
            if kind == free:
                q[a:a + 3] = rng.uniform(-1, 1, 3)
                a += 3
            if kind in (free, ball):
                w = rng.normal(size=4)
                q[a:a + 4] = w / np.linalg.norm(w)
            else:
                q[a] += rng.uniform(-1.0, 1.0)
        yield q, rng.normal(size=m.nv)


def mj_state(m, q, v):
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:] = q, v
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    return d, M


@pytest.fixture(scope="module")
def arm():
    return load_mjcf(ARM)


def test_tree_is_as_written(arm):
    m = arm.model
    assert m.name == "test_arm" and load_mjcf("<mujoco><worldbody/></mujoco>").model.name == "MuJoCo Model"
    assert [b["name"] for b in m.body_info()] == ["base", "upper", "camera", "slider", "wrist", "finger"]
    kinds = {j["name"]: j["type"] for j in m.joint_info()}
    assert kinds == {"j_base": "revolute", "j_shoulder": "revolute", "camera_weld": "fixed", "j_slide": "prismatic",
                     "j_wrist": "spherical", "j_finger": "revolute"}
    assert (m.nq, m.nu) == (8, 7)
    assert arm.markers == {"tool0": "finger"}
    assert arm.limits["j_shoulder"].lower == pytest.approx(-1.8) and arm.limits["j_shoulder"].upper == pytest.approx(1.9)
    assert "j_wrist" not in arm.limits and arm.ignored == []
    np.testing.assert_allclose(m.gravity, [0.3, -0.2, -9.81])
    # the joints start at MuJoCo's qpos0 (the reference positions)
    np.testing.assert_allclose(m.q0(), mujoco.MjModel.from_xml_path(str(ARM)).qpos0, atol=0)
    kinds = {b: [type(c).__name__ for _, c in items] for b, items in arm.contours.items()}
    assert kinds == {"world": ["Plane"], "base": ["Cylinder"], "upper": ["Capsule"], "slider": ["Box"],
                     "wrist": ["Sphere", "Ellipsoid"]}  # the camera box does not collide: a visual only
    assert [v.kind for v in arm.visuals["camera"]] == ["box"]
    assert arm.contours["world"][0][0] == "ground"


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_mass_matrix_and_accelerations_match_mujoco(arm, seed):
    m = mj_model(ARM)
    for q, v in configurations(m, 2, seed):
        d, M_ref = mj_state(m, q, v)
        M = ms.dynamics.mass_matrix(arm.model, q)
        np.testing.assert_allclose(M, M_ref, rtol=0, atol=1e-12 * np.abs(M_ref).max())
        a = ms.dynamics.forward_dynamics(arm.model, q, v)
        np.testing.assert_allclose(a, d.qacc, rtol=0, atol=1e-11 * np.abs(d.qacc).max())
        assert np.abs(d.qacc).max() > 1.0  # gravity and the velocities make it a non-trivial comparison


def test_body_frames_and_sites_match_mujoco(arm):
    m = mj_model(ARM)
    q, _ = next(configurations(m, 1, seed=9))
    d, _ = mj_state(m, q, np.zeros(m.nv))
    states = ms.kinematics.body_states(arm.model, q)
    for k, name in enumerate(states["body_names"]):
        if name == "ground":
            continue
        b = m.body(name).id
        np.testing.assert_allclose(states["position"][k], d.xpos[b], atol=1e-13, err_msg=name)
        np.testing.assert_allclose(states["rotation"][k], d.xmat[b].reshape(3, 3), atol=1e-13, err_msg=name)
    tcp = next(mk for b in arm.model.to_dict()["bodies"] if b["name"] == "finger" for mk in b["markers"] if mk["name"] == "tcp")
    np.testing.assert_allclose(ms.kinematics.point_position(arm.model, q, "finger", tcp["position"]), d.site_xpos[0], atol=1e-13)


FREE = """<mujoco model="floater"><compiler angle="radian"/><option gravity="0 0 -9.81"/>
  <worldbody><body name="hull" pos="0.1 0.2 0.3" quat="0.9 0.3 -0.1 0.2">
    <freejoint name="hull_free"/>
    <inertial pos="0.05 -0.02 0.01" quat="0.7 0.1 0.6 -0.2" mass="3" diaginertia="0.05 0.08 0.06"/>
    <body name="flap" pos="0.3 0 0"><joint name="hinge" axis="0 1 0.3" pos="-0.05 0 0" damping="0.4" stiffness="2" springref="0.1"/>
      <inertial pos="0.1 0 0" mass="0.5" diaginertia="0.001 0.004 0.004"/></body>
  </body></worldbody></mujoco>"""


def test_free_joint_matches_mujoco_with_its_velocity_convention():
    """MuJoCo's free-joint velocity is (v in the world, omega in the body), ours (v, omega) in the
    body: with u = T v_mj, T = diag(R^T, E, 1), M_mj = T^T M T and qacc_mj = T^-1 (u' - T' v_mj)."""
    imp = load_mjcf(FREE)
    j = {x["name"]: x for x in imp.model.joint_info()}
    assert j["hull_free"]["type"] == "free" and j["hinge"]["type"] == "revolute"
    np.testing.assert_allclose(imp.model.q0()[:7], [0.1, 0.2, 0.3, *(np.array([0.9, 0.3, -0.1, 0.2]) / np.linalg.norm([0.9, 0.3, -0.1, 0.2]))], atol=1e-15)
    m = mj_model(FREE)
    for q, v in configurations(m, 3, seed=4):
        v[:3] = 0.0  # a body-frame linear velocity that is zero in the world too keeps T' v_mj = 0 simple
        d, M_ref = mj_state(m, q, v)
        R = ms.kinematics.quat_to_matrix(q[3:7])
        T = np.eye(m.nv)
        T[:3, :3] = R.T
        M = ms.dynamics.mass_matrix(imp.model, q)
        np.testing.assert_allclose(T.T @ M @ T, M_ref, rtol=0, atol=1e-12 * np.abs(M_ref).max())
        # with a zero linear velocity, dT/dt v_mj = 0, so u' = T qacc_mj
        a = ms.dynamics.forward_dynamics(imp.model, q, T @ v)
        np.testing.assert_allclose(a, T @ d.qacc, rtol=0, atol=1e-11 * np.abs(d.qacc).max())
        assert np.abs(d.qacc).max() > 1.0


TWO_JOINTS = """<mujoco model="two"><compiler angle="radian"/><option gravity="0.5 0 -9.81"/>
  <worldbody><body name="hip" pos="0 0 1" euler="0.2 -0.1 0.3">
    <joint name="hx" axis="1 0.2 0" pos="0.02 0 0.01" ref="0.3"/><joint name="hy" axis="0 1 0.3" pos="0.02 0 0.01" ref="-0.2"
      damping="0.3" stiffness="1.5" springref="0.1"/>
    <inertial pos="0.1 0.02 -0.2" quat="0.9 0.1 0.3 0" mass="2" diaginertia="0.04 0.03 0.02"/>
    <body name="piston" pos="0.1 0 -0.4" euler="0.4 0 0">
      <joint name="turn" axis="0 0.6 0.8" pos="0 0.01 0" ref="0.5"/><joint name="push" type="slide" axis="0 0.6 0.8" ref="0.05"/>
      <inertial pos="0.03 0 -0.05" quat="0.7 0 0.7 0.1" mass="0.7" diaginertia="0.002 0.003 0.004"/>
    </body></body></worldbody></mujoco>"""


def test_two_joints_on_a_body_as_universal_and_cylindrical():
    imp = load_mjcf(TWO_JOINTS)
    kinds = {j["name"]: j["type"] for j in imp.model.joint_info()}
    assert kinds == {"hx_hy": "universal", "turn_push": "cylindrical"}
    assert imp.compound == {"hx_hy": ["hx", "hy"], "turn_push": ["turn", "push"]}
    m = mj_model(TWO_JOINTS)
    np.testing.assert_allclose(imp.model.q0(), m.qpos0, atol=0)
    for q, v in configurations(m, 4, seed=8):
        d, M_ref = mj_state(m, q, v)
        np.testing.assert_allclose(ms.dynamics.mass_matrix(imp.model, q), M_ref, rtol=0, atol=1e-12 * np.abs(M_ref).max())
        a = ms.dynamics.forward_dynamics(imp.model, q, v)
        np.testing.assert_allclose(a, d.qacc, rtol=0, atol=1e-11 * np.abs(d.qacc).max())
    with pytest.raises(ms.ModelError, match="joint 'hx' is a coordinate of the mechsys joint 'hx_hy'"):
        load_mjcf(TWO_JOINTS.replace('ref="0.3"', 'ref="0.3" range="-1 1"'), limits="stops")
    apart = TWO_JOINTS.replace('pos="0.02 0 0.01" ref="-0.2"', 'pos="0.03 0 0.01" ref="-0.2"')
    with pytest.raises(ms.ModelError, match=r"body 'hip': 2 joints \('hx' \(hinge\), 'hy' \(hinge\)\).*two hinges through one point"):
        load_mjcf(apart)


def test_limit_stops_and_cli_round_trip(tmp_path):
    from click.testing import CliRunner

    from mechsys.cli import cli
    from mechsys.modelfile import load_model

    imp = load_mjcf(ARM, limits="stops")
    names = [c["name"] for c in imp.model.build().contacts()]
    assert names == [f"{j}_{s}" for j in ("j_base", "j_shoulder", "j_slide", "j_finger") for s in ("lower", "upper")]
    out = tmp_path / "arm.toml"
    r = CliRunner().invoke(cli, ["import", str(ARM), "-o", str(out)])
    assert r.exit_code == 0, r.output
    model, _ = load_model(out)
    arm = load_mjcf(ARM)
    m = mj_model(ARM)
    for q, _ in configurations(m, 2, seed=6):
        np.testing.assert_allclose(ms.dynamics.mass_matrix(model, q), ms.dynamics.mass_matrix(arm.model, q), rtol=0, atol=1e-15)
    r = CliRunner().invoke(cli, ["info", str(ARM)])
    assert r.exit_code == 0, r.output
    assert "j_wrist" in r.output and "spherical" in r.output


def _one_body(joints='<joint name="j1" type="hinge" axis="0 0 1"/>', inertial='<inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>', extra=""):
    return f"""<mujoco model="bad"><worldbody><body name="arm">{joints}{inertial}</body>{extra}</worldbody></mujoco>"""


def test_errors_name_the_item(tmp_path):
    with pytest.raises(ms.ModelError, match="missing.xml: no such MJCF file"):
        load_mjcf(tmp_path / "missing.xml")
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><body name='a'></worldbody></mujoco>")
    with pytest.raises(ms.ModelError, match="broken.xml: MuJoCo cannot load the model"):
        load_mjcf(broken)
    with pytest.raises(ms.ModelError, match="MJCF: MuJoCo cannot load the model .*mesh"):
        load_mjcf(_one_body(extra='<geom type="mesh" mesh="ghost"/>'))
    two = '<joint name="j1" type="hinge" axis="0 0 1"/><joint name="j2" type="slide" axis="1 0 0"/>'
    with pytest.raises(ms.ModelError, match=r"body 'arm': 2 joints \('j1' \(hinge\), 'j2' \(slide\)\)"):
        load_mjcf(_one_body(joints=two))
    massless = _one_body(inertial="", extra="").replace("<worldbody>", '<compiler inertiafromgeom="false"/><worldbody>')
    with pytest.raises(ms.ModelError, match="MuJoCo cannot load the model .*mass and inertia.*'arm'"):
        load_mjcf(massless.replace("</body>", '<body name="tip"><joint name="j2"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body>'))
    nested_free = _one_body(extra="").replace("</body>", '<body name="tip"><freejoint name="loose"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body>')
    with pytest.raises(ms.ModelError, match="MuJoCo cannot load the model .*free joint.*'tip'"):
        load_mjcf(nested_free)
    with pytest.raises(ms.ModelError, match="limits must be 'data' or 'stops'"):
        load_mjcf(_one_body(), limits="soft")
    with pytest.raises(ms.ModelError, match="contours must be 'collision', 'all' or None"):
        load_mjcf(_one_body(), contours="visual")
    with pytest.raises(ms.ModelError, match="joint 'j1': a ball joint's cone limit cannot be a gap stop"):
        load_mjcf(_one_body(joints='<joint name="j1" type="ball" range="0 0.5"/>'), limits="stops")
    with pytest.raises(ms.ModelError, match="expected a file path or the MJCF text, got int"):
        load_mjcf(3)


def test_unsupported_elements_are_named():
    text = _one_body(joints='<joint name="j1" type="hinge" axis="0 0 1" armature="0.1" frictionloss="0.2"/>') \
        .replace("</mujoco>", '<actuator><motor name="drive" joint="j1"/></actuator><sensor><jointpos name="enc" joint="j1"/></sensor></mujoco>')
    with pytest.warns(UserWarning, match="not imported: joint 'j1' armature; joint 'j1' frictionloss; actuator 'drive'; sensor 'enc'"):
        imp = load_mjcf(text)
    assert imp.ignored == ["joint 'j1' armature", "joint 'j1' frictionloss", "actuator 'drive'", "sensor 'enc'"]
    with pytest.raises(ms.ModelError, match="MJCF: not imported: joint 'j1' armature"):
        load_mjcf(text, unsupported="error")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_mjcf(text, unsupported="ignore")
    hfield = _one_body().replace("<worldbody>", '<asset><hfield name="terrain" nrow="3" ncol="3" size="1 1 0.1 0.1"/></asset><worldbody>'
                                 '<geom name="ground_field" type="hfield" hfield="terrain"/>')
    with pytest.warns(UserWarning, match=r"geom 'ground_field' \(hfield: no mechsys contour, kept as a visual\)"):
        imp = load_mjcf(hfield)
    assert [v.kind for v in imp.visuals["world"]] == ["hfield"]


def test_mesh_geom_becomes_a_placed_mesh_contour(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box(extents=(0.1, 0.2, 0.3)).export(tmp_path / "block.stl")
    (tmp_path / "m.xml").write_text(_one_body(extra="").replace(
        "<worldbody>", '<asset><mesh name="block" file="block.stl" scale="2 2 2"/></asset><worldbody>').replace(
        "</body>", '<geom name="hull" type="mesh" mesh="block" pos="0 0 1" euler="0 0 90"/></body>'))
    imp = load_mjcf(tmp_path / "m.xml")
    (body, mesh), = imp.contours["arm"]
    assert body == "arm" and isinstance(mesh, ms.contours.Mesh)
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    # scaled by 2 and turned a quarter about z (MJCF's default angle unit is degrees)
    np.testing.assert_allclose(hi - lo, [0.4, 0.2, 0.6], atol=1e-12)
    np.testing.assert_allclose(0.5 * (hi + lo), [0, 0, 1], atol=1e-12)


def test_dropped_sphere_rests_on_the_imported_floor():
    """The plane and sphere geoms as contours: a free ball falls onto the floor and rests one
    radius above it."""
    text = """<mujoco><worldbody><geom name="floor" type="plane" size="1 1 0.1"/>
      <body name="ball" pos="0 0 0.3"><freejoint/><geom name="skin" type="sphere" size="0.05" mass="0.5"/></body>
      </worldbody></mujoco>"""
    imp = load_mjcf(text)
    assert [j["name"] for j in imp.model.joint_info()] == ["ball_free"]  # an unnamed joint: after its body
    (floor,), (skin,) = imp.contours["world"], imp.contours["ball"]
    m = imp.model
    m.add_contact(ms.Contact("floor", ms.contours.OnBody(*skin), ms.contours.OnBody(*floor)))
    res = ms.simulate(m, 0.6, ms.MoreauJean(dt=1e-3))
    z = res["body/ball/position"][-1, 2]
    v_impact, dt = np.sqrt(2 * 9.81 * 0.25), 1e-3
    assert abs(z - 0.05) <= v_impact * dt


def test_geoms_are_drawn_as_visuals_at_mujocos_places():
    """Every drawable geom becomes a visual on its body (the floor plane is left out): the
    centre of each in the world at q0 is MuJoCo's geom position."""
    import mujoco

    imp = ms.load_mjcf(str(ARM))
    m = mujoco.MjModel.from_xml_path(str(ARM))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    vis = imp.model.to_dict()["visuals"]
    assert len(vis) == sum(1 for g in range(m.ngeom) if m.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE)
    states = ms.kinematics.body_states(imp.model, np.asarray(d.qpos))
    names = ["ground"] + [b["name"] for b in imp.model.build().bodies()]
    for v in vis:
        g = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, v["name"])
        shape = v["shape"]
        local = np.asarray(shape["center"]) if "center" in shape else 0.5 * (np.asarray(shape["a"]) + np.asarray(shape["b"]))
        k = names.index(v["body"])
        world = np.asarray(states["rotation"][k]) @ local + np.asarray(states["position"][k])
        np.testing.assert_allclose(world, d.geom_xpos[g], atol=1e-12)
