"""URDF import (mechsys.urdf) checked against Pinocchio's own URDF parser and dynamics.

The arm below is written for this test: joint origins turned by rpy angles, inertial frames
offset and turned in their links, a prismatic joint, a fixed link with mass, a massless tool frame
and a mimic joint. Pinocchio reads the same text, so any mistake in our frames, in the rotation of
the inertia tensors or in the joint axes shows up in M(q) and in the gravity torques.
"""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms
from mechsys.modelfile import load_model
from mechsys.urdf import load_urdf

pin = pytest.importorskip("pinocchio")


def inertial(mass, xyz, rpy, ixx, iyy, izz, ixy=0.0, ixz=0.0, iyz=0.0):
    return (f'<inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="{ixy}" ixz="{ixz}" iyz="{iyz}"/></inertial>')


ARM = f"""<?xml version="1.0"?>
<robot name="test_arm">
  <link name="base">{inertial(5.0, "0 0 0.05", "0 0 0", 0.02, 0.02, 0.03)}
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="shoulder">{inertial(2.0, "0.01 0.02 0.1", "0.3 -0.2 0.5", 0.011, 0.013, 0.007, 0.001, -0.0005, 0.0002)}
    <collision><origin xyz="0 0 0.1" rpy="0.2 0 0"/><geometry><cylinder radius="0.04" length="0.2"/></geometry></collision>
    <visual><geometry><sphere radius="0.05"/></geometry></visual>
  </link>
  <link name="upper_arm">{inertial(1.5, "0.15 0 0.01", "0 0.4 -0.3", 0.004, 0.021, 0.02, 0.0003, 0.0001, -0.0002)}
    <collision><origin xyz="0.15 0 0" rpy="0 1.5707963 0"/><geometry><cylinder radius="0.03" length="0.3"/></geometry></collision>
  </link>
  <link name="slider">{inertial(0.8, "0.05 0.01 0", "-0.7 0.1 0.2", 0.002, 0.003, 0.0025)}</link>
  <link name="camera">{inertial(0.3, "0.02 0 0.01", "0 0 0.9", 0.0004, 0.0005, 0.0003)}</link>
  <link name="wrist">{inertial(0.5, "0 0.03 0.02", "0.5 0.5 0.5", 0.0011, 0.0009, 0.0008, 0.0001)}
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="finger">{inertial(0.1, "0.02 0 0", "0 0 0", 0.00005, 0.00006, 0.00004)}</link>
  <link name="tool0"/>
  <joint name="j_shoulder" type="revolute">
    <parent link="base"/><child link="shoulder"/>
    <origin xyz="0.01 -0.02 0.1" rpy="0.1 0.2 -0.3"/><axis xyz="0 0 1"/>
    <limit lower="-2.5" upper="2.5" effort="80" velocity="3"/>
  </joint>
  <joint name="j_elbow" type="revolute">
    <parent link="shoulder"/><child link="upper_arm"/>
    <origin xyz="0.02 0.05 0.2" rpy="-1.2 0.3 0.7"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-1.8" upper="1.9" effort="40" velocity="3"/>
  </joint>
  <joint name="j_slide" type="prismatic">
    <parent link="upper_arm"/><child link="slider"/>
    <origin xyz="0.3 0.01 -0.02" rpy="0.4 -0.1 0.25"/><axis xyz="1 0 0"/>
    <limit lower="-0.05" upper="0.12" effort="100" velocity="0.5"/>
  </joint>
  <joint name="j_camera" type="fixed">
    <parent link="upper_arm"/><child link="camera"/>
    <origin xyz="0.1 0.04 0.03" rpy="0 -0.6 1.1"/>
  </joint>
  <joint name="j_wrist" type="continuous">
    <parent link="slider"/><child link="wrist"/>
    <origin xyz="0.08 0 0.01" rpy="0.9 0.1 -0.4"/><axis xyz="1 1 0"/>
  </joint>
  <joint name="j_finger" type="revolute">
    <parent link="wrist"/><child link="finger"/>
    <origin xyz="0.03 0.01 0" rpy="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.5" effort="5" velocity="2"/>
    <mimic joint="j_wrist" multiplier="0.5" offset="0.1"/>
  </joint>
  <joint name="j_tool" type="fixed">
    <parent link="wrist"/><child link="tool0"/>
    <origin xyz="0 0 0.05" rpy="3.14159 0 0"/>
  </joint>
</robot>
"""

GRAVITY = np.array([0.0, 0.0, -9.81])


def pin_model():
    model = pin.buildModelFromXML(ARM)
    model.gravity.linear = GRAVITY
    return model


def pin_configuration(pmodel, values: dict) -> np.ndarray:
    """A pinocchio q from {joint name: value}: Pinocchio orders joints its own way, so map by name."""
    q = pin.neutral(pmodel)
    for name, v in values.items():
        jid = pmodel.getJointId(name)
        assert jid < pmodel.njoints, name
        j = pmodel.joints[jid]
        if j.nq == 2:  # a continuous joint: Pinocchio's coordinates are (cos q, sin q)
            q[j.idx_q : j.idx_q + 2] = np.cos(v), np.sin(v)
        else:
            q[j.idx_q] = v
    return q


def pin_to_ours(pmodel, ours: ms.Model):
    """Index map: our velocity index k has Pinocchio's index perm[k] (by joint name)."""
    perm = []
    for j in ours.joint_info():
        if j["nu"] == 0:
            continue
        assert j["nu"] == 1
        perm.append(pmodel.joints[pmodel.getJointId(j["name"])].idx_v)
    return np.array(perm)


def random_configurations(n, seed=3):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        yield {"j_shoulder": rng.uniform(-2.5, 2.5), "j_elbow": rng.uniform(-1.8, 1.9), "j_slide": rng.uniform(-0.05, 0.12),
               "j_wrist": rng.uniform(-np.pi, np.pi), "j_finger": rng.uniform(-0.5, 0.5)}


@pytest.fixture(scope="module")
def arm():
    return load_urdf(ARM)


def test_tree_is_as_written(arm):
    m = arm.model
    names = [b["name"] for b in m.body_info()]
    assert set(names) == {"shoulder", "upper_arm", "slider", "camera", "wrist", "finger"}
    assert arm.markers == {"tool0": "wrist"}
    kinds = {j["name"]: j["type"] for j in m.joint_info()}
    assert kinds == {"j_shoulder": "revolute", "j_elbow": "revolute", "j_slide": "prismatic", "j_camera": "fixed",
                     "j_wrist": "revolute", "j_finger": "revolute"}
    assert m.nu == 5
    assert arm.limits["j_elbow"].lower == pytest.approx(-1.8) and arm.limits["j_elbow"].upper == pytest.approx(1.9)
    assert arm.limits["j_slide"].effort == pytest.approx(100.0)
    assert arm.mimics == {"j_finger": ("j_wrist", 0.5, 0.1)}
    assert [c["type"] for c in m.build().constraints()] == ["coupler"]
    assert set(arm.contours) == {"base", "shoulder", "upper_arm", "wrist"}
    assert arm.contours["base"][0][0] == "ground"
    assert arm.visuals["shoulder"][0].kind == "sphere"


@pytest.mark.parametrize("values", list(random_configurations(6)))
def test_mass_matrix_matches_pinocchio(arm, values):
    pmodel = pin_model()
    pdata = pmodel.createData()
    qp = pin_configuration(pmodel, values)
    Mp = pin.crba(pmodel, pdata, qp)
    Mp = np.triu(Mp) + np.triu(Mp, 1).T
    perm = pin_to_ours(pmodel, arm.model)
    q = arm.model.state_vector(values, "q")
    M = ms.dynamics.mass_matrix(arm.model, q)
    np.testing.assert_allclose(M, Mp[np.ix_(perm, perm)], rtol=0, atol=1e-12)


@pytest.mark.parametrize("values", list(random_configurations(4, seed=11)))
def test_gravity_torques_match_pinocchio(arm, values):
    pmodel = pin_model()
    pdata = pmodel.createData()
    qp = pin_configuration(pmodel, values)
    # Pinocchio's g(q) is the torque that holds the robot (M a + g = tau); our h = -g (M u' = h + tau)
    g = pin.computeGeneralizedGravity(pmodel, pdata, qp)
    perm = pin_to_ours(pmodel, arm.model)
    q = arm.model.state_vector(values, "q")
    h = ms.dynamics.nonlinear_effects(arm.model, q, np.zeros(arm.model.nu))
    np.testing.assert_allclose(h, -g[perm], rtol=0, atol=1e-11)
    assert np.max(np.abs(g)) > 1.0  # the comparison is not a trivial one of zeros


def test_link_placements_match_pinocchio(arm):
    """Every body frame and the tool marker where Pinocchio puts the same link frames."""
    pmodel = pin_model()
    pdata = pmodel.createData()
    values = {"j_shoulder": 0.4, "j_elbow": -0.7, "j_slide": 0.03, "j_wrist": 1.2, "j_finger": 0.0}
    pin.framesForwardKinematics(pmodel, pdata, pin_configuration(pmodel, values))
    q = arm.model.state_vector(values, "q")
    states = ms.kinematics.body_states(arm.model, q)
    for k, name in enumerate(states["body_names"]):
        if name == "ground":
            continue
        ref = pdata.oMf[pmodel.getFrameId(name)]
        np.testing.assert_allclose(states["position"][k], ref.translation, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(states["rotation"][k], ref.rotation, atol=1e-12, err_msg=name)
    marker = next(m for b in arm.model.to_dict()["bodies"] if b["name"] == "wrist" for m in b["markers"])
    ref = pdata.oMf[pmodel.getFrameId("tool0")]
    np.testing.assert_allclose(ms.kinematics.point_position(arm.model, q, "wrist", marker["position"]), ref.translation, atol=1e-12)


def test_round_trip_through_toml(arm, tmp_path):
    from mechsys.cli import cli
    from click.testing import CliRunner

    src = tmp_path / "arm.urdf"
    src.write_text(ARM)
    out = tmp_path / "arm.toml"
    r = CliRunner().invoke(cli, ["import", str(src), "-o", str(out)])
    assert r.exit_code == 0, r.output
    model, _ = load_model(out)
    for values in random_configurations(3, seed=5):
        q = arm.model.state_vector(values, "q")
        np.testing.assert_allclose(ms.dynamics.mass_matrix(model, q), ms.dynamics.mass_matrix(arm.model, q), rtol=0, atol=1e-15)
        np.testing.assert_allclose(ms.dynamics.nonlinear_effects(model, q, np.zeros(5)),
                                   ms.dynamics.nonlinear_effects(arm.model, q, np.zeros(5)), rtol=0, atol=1e-13)
    r = CliRunner().invoke(cli, ["info", str(src)])
    assert r.exit_code == 0, r.output
    assert "j_elbow" in r.output and "coupler" in r.output


def test_limit_stops_hold_the_joint(tmp_path):
    text = f"""<robot name="one"><link name="base"/>
      <link name="arm">{inertial(1.0, "0.5 0 0", "0 0 0", 0.001, 0.08, 0.08)}</link>
      <joint name="swing" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
        <limit lower="-0.3" upper="0.3" effort="1" velocity="1"/></joint></robot>"""
    imp = load_urdf(text, limits="stops")
    assert [c["name"] for c in imp.model.build().contacts()] == ["swing_lower", "swing_upper"]
    # released level, gravity -z pulls the arm down: about +y that is a positive angle
    res = ms.simulate(imp.model, t_end=1.0, integrator=ms.MoreauJean(dt=1e-3))
    q = res["joint/swing/q"]
    assert np.max(q) <= 0.3 + 1e-3 and np.max(q) > 0.29


def test_free_base_root():
    imp = load_urdf(ARM, root="free")
    m = imp.model
    assert m.nq == 7 + 5 and m.nu == 6 + 5
    assert "base" in [b["name"] for b in m.body_info()]
    # Pinocchio's free flyer has q = (x, y, z, qx, qy, qz, qw) and v = (linear, angular) in the base
    # frame; with the base unturned these are our Free joint's coordinates and velocities too
    pmodel = pin.buildModelFromXML(ARM, pin.JointModelFreeFlyer())
    pdata = pmodel.createData()
    for values in random_configurations(3, seed=7):
        qp = pin_configuration(pmodel, values)
        qp[:3] = (0.3, -0.2, 0.5)
        q = m.state_vector({**values, "base_free": [0.3, -0.2, 0.5, 1.0, 0.0, 0.0, 0.0]}, "q")
        order = [0, 1, 2, 3, 4, 5] + [pmodel.joints[pmodel.getJointId(j["name"])].idx_v
                                      for j in m.joint_info() if j["nu"] == 1]
        Mp = pin.crba(pmodel, pdata, qp)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(ms.dynamics.mass_matrix(m, q), Mp[np.ix_(order, order)], rtol=0, atol=1e-12)


# ---- errors ------------------------------------------------------------------------------------

def _one_joint(kind="revolute", child_inertial=None, extra="", child_geometry=""):
    child_inertial = inertial(1.0, "0 0 0", "0 0 0", 0.01, 0.01, 0.01) if child_inertial is None else child_inertial
    return f"""<robot name="bad"><link name="base"/>
      <link name="arm">{child_inertial}{child_geometry}</link>
      <joint name="j1" type="{kind}"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>{extra}</robot>"""


def test_errors_name_the_item(tmp_path):
    with pytest.raises(ms.ModelError, match="no such URDF file"):
        load_urdf(str(tmp_path / "missing.urdf"))
    with pytest.raises(ms.ModelError, match="joint 'j1': unknown joint type 'screw'"):
        load_urdf(_one_joint("screw"))
    with pytest.raises(ms.ModelError, match="link 'arm': a moving link needs a mass > 0, got mass 0"):
        load_urdf(_one_joint(child_inertial=inertial(0.0, "0 0 0", "0 0 0", 0.01, 0.01, 0.01)))
    with pytest.raises(ms.ModelError, match="link 'arm': a moving link needs a mass > 0, got mass -2"):
        load_urdf(_one_joint(child_inertial=inertial(-2.0, "0 0 0", "0 0 0", 0.01, 0.01, 0.01)))
    with pytest.raises(ms.ModelError, match="link 'arm': a moving link needs a mass > 0, got no <inertial>"):
        load_urdf(_one_joint(child_inertial=""))
    with pytest.raises(ms.ModelError, match="link 'arm': the inertia is not positive definite"):
        load_urdf(_one_joint(child_inertial=inertial(1.0, "0 0 0", "0 0 0", 0.01, 0.01, -0.01)))
    with pytest.raises(ms.ModelError, match=r"link 'arm'.collision\[0\]: mesh file 'meshes/arm.stl' not found"):
        load_urdf(_one_joint(child_geometry='<collision><geometry><mesh filename="meshes/arm.stl"/></geometry></collision>'))
    f = tmp_path / "bad.urdf"
    f.write_text(_one_joint(child_geometry='<visual><geometry><mesh filename="package://arm_pkg/arm.stl"/></geometry></visual>'))
    with pytest.raises(ms.ModelError, match=r"bad.urdf: link 'arm'.visual\[0\]: mesh file 'package://arm_pkg/arm.stl' not found"):
        load_urdf(f, package_dirs=[tmp_path])
    cyclic = _one_joint(extra='<link name="c"/><link name="d"/>'
                              '<joint name="jc" type="fixed"><parent link="d"/><child link="c"/></joint>'
                              '<joint name="jd" type="fixed"><parent link="c"/><child link="d"/></joint>')
    with pytest.raises(ms.ModelError, match="link\\(s\\) 'c', 'd' are not reachable from the root 'base'"):
        load_urdf(cyclic)
    two_parents = _one_joint(extra='<joint name="j2" type="fixed"><parent link="base"/><child link="arm"/></joint>')
    with pytest.raises(ms.ModelError, match="joint 'j2': link 'arm' already has the parent joint 'j1'"):
        load_urdf(two_parents)
    disconnected = _one_joint(extra='<link name="lonely"/>')
    with pytest.raises(ms.ModelError, match="not one tree: 2 links have no parent joint \\('base', 'lonely'\\)"):
        load_urdf(disconnected)
    with pytest.raises(ms.ModelError, match="joint 'j1': child link 'nowhere' is not defined"):
        load_urdf(_one_joint().replace('<child link="arm"/>', '<child link="nowhere"/>'))
    with pytest.raises(ms.ModelError, match="cannot read the URDF"):
        load_urdf("<robot name='x'><link name='a'>")
    with pytest.raises(ms.ModelError, match="root must be 'ground' or 'free'"):
        load_urdf(_one_joint(), root="wall")


def test_mesh_collision_is_read_and_placed(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box(extents=(0.1, 0.2, 0.3)).export(tmp_path / "block.stl")
    (tmp_path / "robot.urdf").write_text(_one_joint(
        child_geometry='<collision><origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/>'
                       '<geometry><mesh filename="block.stl" scale="2 2 2"/></geometry></collision>'))
    imp = load_urdf(tmp_path / "robot.urdf")
    body, mesh = imp.contours["arm"][0]
    assert body == "arm" and isinstance(mesh, ms.contours.Mesh)
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    # scaled by 2 and turned a quarter about z: x and y extents swap
    np.testing.assert_allclose(hi - lo, [0.4, 0.2, 0.6], atol=1e-12)
    np.testing.assert_allclose(0.5 * (hi + lo), [0, 0, 1], atol=1e-12)


def test_planar_and_floating_joints():
    """A planar joint moves its link in the plane normal to the URDF axis; a floating joint is a
    Free joint whose mass matrix equals Pinocchio's free flyer at an unturned placement."""
    text = f"""<robot name="pf"><link name="base"/>
      <link name="puck">{inertial(2.0, "0.1 0 0", "0.3 0.2 0.1", 0.01, 0.02, 0.015)}</link>
      <link name="drone">{inertial(1.5, "0 0.05 0", "0 0.4 0", 0.03, 0.02, 0.04, 0.001)}</link>
      <joint name="slide_plane" type="planar"><parent link="base"/><child link="puck"/>
        <origin xyz="0 0 0.2" rpy="0.3 0 0"/><axis xyz="0 1 1"/></joint>
      <joint name="fly" type="floating"><parent link="base"/><child link="drone"/>
        <origin xyz="1 0 0" rpy="0 0 0"/></joint></robot>"""
    imp = load_urdf(text)
    m = imp.model
    q = m.state_vector({"slide_plane": [0.3, -0.2, 0.7]}, "q")
    # every motion of the puck's centre of mass is across the plane normal (the axis in the world)
    normal = ms.kinematics.rot_x(0.3) @ (np.array([0.0, 1.0, 1.0]) / np.sqrt(2.0))
    jv, _ = ms.kinematics.point_jacobian(m, q, "puck", (0.1, 0.0, 0.0))
    np.testing.assert_allclose(normal @ jv[:, :3], 0.0, atol=1e-14)
    assert np.linalg.matrix_rank(jv[:, :3]) == 2
    # and the link keeps its orientation in the plane: the origin sits where the joint put it
    p0 = ms.kinematics.point_position(m, m.q0(), "puck")
    np.testing.assert_allclose(p0, [0.0, 0.0, 0.2], atol=1e-15)

    pmodel = pin.buildModelFromXML(text.replace("""<joint name="slide_plane" type="planar"><parent link="base"/><child link="puck"/>
        <origin xyz="0 0 0.2" rpy="0.3 0 0"/><axis xyz="0 1 1"/></joint>""", "").replace(
        f"""<link name="puck">{inertial(2.0, "0.1 0 0", "0.3 0.2 0.1", 0.01, 0.02, 0.015)}</link>""", ""))
    pdata = pmodel.createData()
    fly = next(j for j in m.joint_info() if j["name"] == "fly")
    qp = pin.neutral(pmodel)
    qp[:3] = (0.2, 0.1, -0.3)
    q = m.state_vector({"fly": [0.2, 0.1, -0.3, 1.0, 0.0, 0.0, 0.0]}, "q")
    Mp = pin.crba(pmodel, pdata, qp)
    Mp = np.triu(Mp) + np.triu(Mp, 1).T
    sl = slice(fly["iu"], fly["iu"] + 6)
    np.testing.assert_allclose(ms.dynamics.mass_matrix(m, q)[sl, sl], Mp, rtol=0, atol=1e-12)


def test_more_errors(monkeypatch):
    bad_mimic = _one_joint().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="ghost"/>')
    with pytest.raises(ms.ModelError, match="joint 'j1'.mimic: mimicked joint 'ghost' is not defined"):
        load_urdf(bad_mimic)
    with pytest.raises(ms.ModelError, match="limits must be 'data' or 'stops'"):
        load_urdf(_one_joint(), limits="soft")
    with pytest.raises(ms.ModelError, match="joint 'j-1': a limit stop's gap expression needs a joint name"):
        load_urdf(_one_joint().replace('name="j1"', 'name="j-1"'), limits="stops")
    with pytest.raises(ms.ModelError, match="joint 'j1': the axis must be a non-zero vector"):
        load_urdf(_one_joint().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'))
    with pytest.raises(ms.ModelError, match="the top element is <model>, expected <robot>"):
        load_urdf("<model name='x'/>")
    monkeypatch.setitem(__import__("sys").modules, "yourdfpy", None)
    with pytest.raises(ms.ModelError, match="needs the 'yourdfpy' package"):
        load_urdf(_one_joint())


def test_bad_files_are_errors_naming_the_item(tmp_path):
    """The bad-input catalogue of URDF files: every case a ModelError naming the file, link or
    joint, and none of them slow (a cycle must not send the tree walk round and round)."""
    import time

    arm_inertial = inertial(1.0, "0 0 0", "0 0 0", 0.01, 0.01, 0.01)
    two = f"""<robot name="loop"><link name="a">{arm_inertial}</link><link name="b">{arm_inertial}</link>
      <joint name="ab" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
      <joint name="ba" type="revolute"><parent link="b"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>"""
    mimic_loop = _one_joint(extra=f'<link name="tip">{arm_inertial}</link><joint name="j2" type="revolute"><parent link="arm"/>'
                                  '<child link="tip"/><axis xyz="0 0 1"/><mimic joint="j1"/></joint>') \
        .replace('<axis xyz="0 0 1"/>\n', '<axis xyz="0 0 1"/><mimic joint="j2"/>\n', 1)
    (tmp_path / "junk.stl").write_bytes(b"\x00\x01 not a mesh" * 8)
    (tmp_path / "junk.urdf").write_text(_one_joint(child_geometry='<collision><geometry><mesh filename="junk.stl"/></geometry></collision>'))
    (tmp_path / "empty.urdf").write_text("")
    cases = [
        (two, "no root link: the joints form a cycle through every link"),
        (_one_joint(extra='<joint name="self" type="fixed"><parent link="arm"/><child link="arm"/></joint>'),
         "joint 'self': link 'arm' already has the parent joint 'j1'"),
        (mimic_loop, r"joint 'j1'.mimic: the mimic joints form a cycle \(j1 -> j2 -> j1\)"),
        (_one_joint().replace('<axis xyz="0 0 1"/>', '<origin xyz="nan 0 0"/><axis xyz="0 0 1"/>'), "joint 'j1': the origin is not a finite transform"),
        (tmp_path / "junk.urdf", r"junk.urdf: link 'arm'.collision\[0\]: mesh file 'junk.stl'"),
        (tmp_path / "empty.urdf", "empty.urdf: cannot read the URDF"),
    ]
    for source, message in cases:
        start = time.perf_counter()
        with pytest.raises(ms.ModelError, match=message):
            load_urdf(source)
        assert time.perf_counter() - start < 5.0, message


def test_toml_writer_round_trips_awkward_values():
    import tomllib

    from mechsys.tomlwrite import dumps

    desc = {"name": 'arm "7" — ünïcode\\path', "gravity": [0.0, -9.81, 1e-300], "flag": True,
            "bodies": [{"name": "a b", "inertia": [[1.0, 0.1], [0.1, 2.0]], "frame": {"position": [0.1, 0.2, 0.3]},
                        "limit": float("inf")}]}
    back = tomllib.loads(dumps(desc, "a header\nover two lines"))
    assert back == desc


def test_primitive_contours_are_placed_in_the_body():
    text = _one_joint(child_geometry='<collision><origin xyz="0.1 0.2 0.3" rpy="0.3 -0.4 1.1"/>'
                                     '<geometry><box size="0.2 0.4 0.6"/></geometry></collision>'
                                     '<collision><origin xyz="0 0 0.5" rpy="1.5707963267948966 0 0"/>'
                                     '<geometry><cylinder radius="0.05" length="0.3"/></geometry></collision>')
    (_, box), (_, cyl) = load_urdf(text).contours["arm"]
    d = box.describe("box")
    # URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll), fixed axes
    k = ms.kinematics
    R = k.rot_z(1.1) @ k.rot_y(-0.4) @ k.rot_x(0.3)
    np.testing.assert_allclose(k.cardan_xyz_to_matrix(d["rotation"]["cardan"]), R, atol=1e-14)
    np.testing.assert_allclose(d["half_extents"], [0.1, 0.2, 0.3])
    np.testing.assert_allclose(d["center"], [0.1, 0.2, 0.3])
    # a cylinder along the link's z turned a quarter about x lies along -y
    np.testing.assert_allclose(cyl.axis, [0.0, -1.0, 0.0], atol=1e-15)
    assert cyl.length == pytest.approx(0.3) and cyl.center == pytest.approx((0.0, 0.0, 0.5))


def test_collision_contours_attach_to_contacts():
    """A free-floating link with a sphere collision off its origin, dropped on the floor through
    the imported contour: it comes to rest with the sphere's centre one radius above the floor."""
    text = f"""<robot name="ball"><link name="ball">{inertial(0.5, "0 0 0.1", "0 0 0", 0.002, 0.002, 0.002)}
      <collision><origin xyz="0 0 0.1"/><geometry><sphere radius="0.05"/></geometry></collision></link></robot>"""
    imp = load_urdf(text, root="free")
    m = imp.model
    (on_body,) = imp.contour_list()
    assert on_body.body == "ball"
    m.add_contact(ms.Contact("floor", on_body, m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))))
    res = ms.simulate(m, 1.0, ms.MoreauJean(dt=1e-3), q0={"ball_free": [0, 0, 0.2, 1, 0, 0, 0]})
    z = res["body/ball/position"][-1, 2]
    # Moreau-Jean closes the gap at velocity level: the step of impact may sink by up to v dt
    v_impact, dt = np.sqrt(2 * 9.81 * 0.25), 1e-3
    assert abs(z - (0.05 - 0.1)) <= v_impact * dt
    assert np.abs(res["body/ball/velocity"][-1]).max() < 1e-9


def test_visual_elements_become_model_visuals_the_viewer_draws(tmp_path):
    """Each <visual> is drawn on the body its link ended up on: primitives as their contours
    placed by the origin, meshes read from their file with the scale, the material's colour kept."""
    import trimesh

    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(tmp_path / "cube.stl")
    urdf = _one_joint(child_geometry=(
        '<visual><origin xyz="0.1 0 0" rpy="0 0 0"/><geometry><box size="0.2 0.4 0.6"/></geometry>'
        '<material name="red"><color rgba="0.9 0.1 0.1 1"/></material></visual>'
        '<visual><origin xyz="0 0 0.5" rpy="0 0 0"/><geometry><mesh filename="cube.stl" scale="0.1 0.2 0.3"/></geometry></visual>'))
    f = tmp_path / "arm.urdf"
    f.write_text(urdf)
    imp = load_urdf(f)
    vis = [v for v in imp.model.to_dict()["visuals"] if v["body"] == "arm"]
    assert len(vis) == 2
    box, mesh = vis
    assert box["shape"]["type"] == "box" and box["color"] == pytest.approx([0.9, 0.1, 0.1])
    np.testing.assert_allclose(box["shape"]["half_extents"], [0.1, 0.2, 0.3])
    np.testing.assert_allclose(box["shape"]["center"], [0.1, 0.0, 0.0], atol=1e-15)
    v = np.asarray(mesh["shape"]["vertices"])
    np.testing.assert_allclose(v.min(axis=0), [-0.05, -0.1, 0.35], atol=1e-12)
    np.testing.assert_allclose(v.max(axis=0), [0.05, 0.1, 0.65], atol=1e-12)
    # the engine accepts them and the viewer draws them on the body
    from mechsys import viewer

    res = ms.simulate(imp.model, t_end=0.01)
    names = [p["name"] for b in viewer.page_data(res)["bodies"] for p in b["parts"]]
    assert "arm.visual[0]" in names and "arm.visual[1]" in names
