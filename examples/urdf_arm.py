"""A three-link arm described in URDF, imported with ``ms.load_urdf`` and released from the
horizontal to swing under gravity. The URDF is written here (and saved next to the results, so it
can also go through ``mechsys import results/urdf_arm.urdf -o arm.toml``). Without dampers the
energy T + V stays constant; its drift is the check.

Run it:            .venv/bin/python examples/urdf_arm.py
or as a model:     mechsys run examples/urdf_arm.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import mechsys as ms


def rod(name: str, mass: float, length: float, radius: float = 0.03) -> str:
    """A link: a rod along its x axis, the inertia of a solid cylinder about its centre, given in
    an inertial frame turned so the cylinder's axis is z (as CAD exports often do)."""
    axial = 0.5 * mass * radius**2
    across = mass * (3 * radius**2 + length**2) / 12
    return f"""
  <link name="{name}">
    <inertial>
      <origin xyz="{length / 2} 0 0" rpy="0 1.5707963267948966 0"/>
      <mass value="{mass}"/>
      <inertia ixx="{across}" iyy="{across}" izz="{axial}" ixy="0" ixz="0" iyz="0"/>
    </inertial>
    <collision>
      <origin xyz="{length / 2} 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><cylinder radius="{radius}" length="{length}"/></geometry>
    </collision>
  </link>"""


URDF = f"""<?xml version="1.0"?>
<robot name="urdf_arm">
  <link name="base"/>
  {rod("upper", 2.0, 0.5)}
  {rod("fore", 1.2, 0.4)}
  {rod("hand", 0.4, 0.15, 0.02)}
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 1.0" rpy="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-3.1" upper="3.1" effort="50" velocity="4"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="0.5 0 0" rpy="0.4 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.6" upper="2.6" effort="30" velocity="4"/>
  </joint>
  <joint name="wrist" type="continuous">
    <parent link="fore"/><child link="hand"/>
    <origin xyz="0.4 0 0" rpy="0 0 -0.5"/><axis xyz="0 0 1"/>
  </joint>
</robot>
"""

arm = ms.load_urdf(URDF)
model = arm.model  # gravity -z, URDF's convention

# q = 0: every link straight out along x (horizontal); released from rest, a spin on the wrist
simulation = dict(
    t_end=5.0,
    integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12),
    output_dt=0.005,
    u0={"wrist": 3.0},
)

if __name__ == "__main__":
    Path("results").mkdir(exist_ok=True)
    Path("results/urdf_arm.urdf").write_text(URDF)
    print(f"imported {len(model.body_info())} bodies, {len(model.joint_info())} joints; limits: "
          + ", ".join(f"{n} [{lim.lower:g}, {lim.upper:g}]" for n, lim in arm.limits.items()))
    res = ms.simulate(model, **simulation)
    e = res["energy/total"]
    drift = np.max(np.abs(e - e[0]))
    print(f"{len(res.t)} samples over {res.t[-1]:.0f} s, {res.stats['steps']} steps")
    print(f"energy: {e[0]:.6f} J at the start, largest drift {drift:.2e} J "
          f"({drift / np.max(res['energy/kinetic']):.1e} of the largest kinetic energy)")
    print(f"shoulder swings {np.degrees(res['joint/shoulder/q'].min()):.0f}..{np.degrees(res['joint/shoulder/q'].max()):.0f} deg")
    res.save("results/urdf_arm.h5")
    ms.plot(res, ["joint/shoulder/q", "joint/elbow/q", "joint/wrist/u", "energy/total"], out="results/urdf_arm.png")
    print("wrote results/urdf_arm.urdf, results/urdf_arm.h5 and results/urdf_arm.png")
