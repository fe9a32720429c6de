"""A three-link arm written in MuJoCo's MJCF, imported with ``ms.load_mjcf`` (MuJoCo's own
compiler reads the file) and released from the horizontal to swing under gravity, its hand on a
ball joint. Run as a script it also integrates the same file in MuJoCo (RK4, small steps, no
constraints) and prints how far the two trajectories are apart, and the energy drift of ours.

Run it:            .venv/bin/python examples/mjcf_arm.py       (needs: pip install mujoco)
or as a model:     mechsys run examples/mjcf_arm.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mechsys as ms

MJCF = """
<mujoco model="mjcf_arm">
  <compiler angle="degree" autolimits="true"/>
  <option gravity="0 0 -9.81" integrator="RK4" timestep="0.0005"/>
  <default><joint damping="0" armature="0"/><geom contype="0" conaffinity="0" density="2700"/></default>
  <worldbody>
    <body name="upper" pos="0 0 1">
      <joint name="shoulder" type="hinge" axis="0 1 0" range="-170 170"/>
      <geom name="upper_rod" type="capsule" fromto="0 0 0 0.5 0 0" size="0.03"/>
      <body name="fore" pos="0.5 0 0" euler="20 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0" ref="10"/>
        <geom name="fore_rod" type="cylinder" fromto="0 0 0 0.4 0 0" size="0.025"/>
        <body name="hand" pos="0.4 0 0">
          <joint name="wrist" type="ball"/>
          <geom name="palm" type="box" pos="0.06 0 0" size="0.06 0.03 0.01"/>
          <site name="tcp" pos="0.12 0 0"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

arm = ms.load_mjcf(MJCF)
model = arm.model

# q0 is MuJoCo's qpos0 (the elbow at its reference angle); the hand starts spinning about x
simulation = dict(
    t_end=2.0,
    integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12),
    output_dt=0.005,
    u0={"wrist": [4.0, 0.0, 0.0]},
)

if __name__ == "__main__":
    import mujoco

    Path("results").mkdir(exist_ok=True)
    Path("results/mjcf_arm.xml").write_text(MJCF)
    print(f"imported {len(model.body_info())} bodies, {len(model.joint_info())} joints, nq = {model.nq}, nu = {model.nu}")
    res = ms.simulate(model, **simulation)
    e = res["energy/total"]
    print(f"energy: largest drift {np.max(np.abs(e - e[0])):.2e} J of {np.max(res['energy/kinetic']):.3f} J kinetic")

    m = mujoco.MjModel.from_xml_string(MJCF)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    d = mujoco.MjData(m)
    d.qvel[m.jnt_dofadr[m.joint("wrist").id]] = 4.0
    while d.time < simulation["t_end"] - 1e-12:
        mujoco.mj_step(m, d)
    q_ours = model.state_vector({j["name"]: res[f"joint/{j['name']}/q"][-1] for j in model.joint_info()}, "q")
    print(f"after {simulation['t_end']:g} s: shoulder {q_ours[0]:+.6f} rad here, {d.qpos[0]:+.6f} rad in MuJoCo; "
          f"largest |q - q_mujoco| {np.max(np.abs(q_ours - d.qpos)):.1e}")
    res.save("results/mjcf_arm.h5")
    ms.plot(res, ["joint/shoulder/q", "joint/elbow/q", "energy/total"], out="results/mjcf_arm.png")
    print("wrote results/mjcf_arm.xml, results/mjcf_arm.h5 and results/mjcf_arm.png")
