"""The benchmark bicycle (the Whipple/Carvallo model) of Meijaard, Papadopoulos, Ruina and Schwab,
Proc. R. Soc. A 463 (2007) 1955-1982, with the parameters of its Table 1: a rear frame with rider
on a free joint, the rear wheel, the front frame (handlebar and fork) on the tilted steer axis and
the front wheel on revolute joints, both wheels knife-edge discs rolling without slipping on the
ground (two RollingDisc constraints: contact height zero, no slip). No rider control, no friction.

Axes. The paper's are x forward, y to the right, z down, with the rear contact point at the origin;
mechsys's world is z up. Every body frame here is the paper's frame turned by pi about x
(x forward, y to the LEFT, z UP): positions (x, y, z) -> (x, -y, -z), inertia products I_xz ->
-I_xz. A rotation about x is the same in both, so

* lean phi (positive: leaning to the right, as in the paper) is the rotation of the rear frame
  about the forward axis; with the yaw-lean-pitch angles of the paper (A_IB = Rz(psi) Rx(phi)
  Ry(theta)) sin(phi) = A_IB[2, 1], see :func:`lean`. Near upright it is the x component (index 0)
  of the rear frame's rotation vector, and its rate is u[3] (omega_B x of the free joint);
* steer delta is the coordinate of the revolute joint ``steer``, whose axis points DOWN along the
  steer axis, (sin(lambda), 0, -cos(lambda)) in the rear frame, so positive steer turns the front
  wheel to the right, as in the paper;
* the wheels turn about (0, -1, 0) (the paper's y axis), so forward rolling at speed v has the
  paper's spin rates -v/r_R and -v/r_F.

The benchmark is self-stable between its weave speed (4.292 m/s) and capsize speed (6.024 m/s):
at 5 m/s a push in lean dies out (weave oscillation, then the slow capsize mode). The linear
analysis about straight running (``ms.linear.linearize`` in lean and steer, ``ms.linear.sweep``
over the speed) reproduces the benchmark's matrices and eigenvalues:

    python examples/bicycle.py
    mechsys linear examples/bicycle.py --coordinates "free[3],steer" --check --sweep "rear_hub':0:-33.3:51"
    mechsys run examples/bicycle.py      # the push in lean rate dying out at 5 m/s
"""

from pathlib import Path

import numpy as np

import mechsys as ms

# ---- Table 1 (the paper's axes: x forward, z down) ---------------------------------------------
W, C, LAMBDA, G = 1.02, 0.08, np.pi / 10, 9.81  # wheel base, trail (m), steer axis tilt (rad)
R_R, M_R, I_R = 0.3, 2.0, (0.0603, 0.12)  # rear wheel: radius, mass, (I_xx = I_zz, I_yy)
X_B, Z_B, M_B = 0.3, -0.9, 85.0  # rear body and frame: centre of mass, mass
I_B = [[9.2, 0.0, 2.4], [0.0, 11.0, 0.0], [2.4, 0.0, 2.8]]
X_H, Z_H, M_H = 0.9, -0.7, 4.0  # front handlebar and fork
I_H = [[0.05892, 0.0, -0.00756], [0.0, 0.06, 0.0], [-0.00756, 0.0, 0.00708]]
R_F, M_F, I_F = 0.35, 3.0, (0.1405, 0.28)  # front wheel

#: the paper's axes -> the z-up body axes used here (a rotation by pi about x)
FLIP = np.diag([1.0, -1.0, -1.0])

#: names in the model
REAR, REAR_WHEEL, FORK, FRONT_WHEEL = "rear_frame", "rear_wheel", "front_frame", "front_wheel"
FREE, REAR_HUB, STEER, FRONT_HUB = "free", "rear_hub", "steer", "front_hub"
#: steer axis (down, positive steer to the right), a point on it (its ground point at upright)
STEER_AXIS = np.array([np.sin(LAMBDA), 0.0, -np.cos(LAMBDA)])
STEER_POINT = np.array([W + C, 0.0, 0.0])
#: front wheel centre in the front frame's axes (origin at STEER_POINT)
FRONT_HUB_POINT = np.array([W, 0.0, R_F]) - STEER_POINT
#: wheel axles (the paper's y axis, pointing right)
AXLE = np.array([0.0, -1.0, 0.0])
#: indices into q and u (joints in the order added: free 7/6, rear hub, steer, front hub)
Q_STEER, U_LEAN_RATE, U_STEER = 8, 3, 7


def _flip_point(x, z):
    return FLIP @ np.array([x, 0.0, z])


def _flip_inertia(i):
    return FLIP @ np.asarray(i, dtype=float) @ FLIP.T


def _wheel_inertia(ixx, iyy):
    return np.diag([ixx, iyy, ixx])


def _model(q0, u0, name: str) -> ms.Model:
    m = ms.Model(name, gravity=(0.0, 0.0, -G))
    # rear frame: body frame at the rear contact point of the upright bicycle (the paper's origin)
    rear = m.add_body(REAR, M_B, _flip_inertia(I_B), com=_flip_point(X_B, Z_B))
    rear_wheel = m.add_body(REAR_WHEEL, M_R, _wheel_inertia(*I_R))
    fork = m.add_body(FORK, M_H, _flip_inertia(I_H), com=_flip_point(X_H, Z_H) - STEER_POINT)
    front_wheel = m.add_body(FRONT_WHEEL, M_F, _wheel_inertia(*I_F))
    m.add_joint(ms.joints.Free(FREE, m.ground, rear, q0=q0[0:7], u0=u0[0:6]))
    m.add_joint(ms.joints.Revolute(REAR_HUB, rear, rear_wheel, axis=AXLE, parent_frame=(0.0, 0.0, R_R),
                                   q0=q0[7], u0=u0[6]))
    m.add_joint(ms.joints.Revolute(STEER, rear, fork, axis=STEER_AXIS, parent_frame=STEER_POINT,
                                   q0=q0[8], u0=u0[7]))
    m.add_joint(ms.joints.Revolute(FRONT_HUB, fork, front_wheel, axis=AXLE, parent_frame=FRONT_HUB_POINT,
                                   q0=q0[9], u0=u0[8]))
    m.add_constraint(ms.constraints.RollingDisc("rear_contact", rear_wheel, radius=R_R, axis=AXLE))
    m.add_constraint(ms.constraints.RollingDisc("front_contact", front_wheel, radius=R_F, axis=AXLE))
    return m


def _front_height(lean_: float, pitch: float, steer_: float) -> float:
    """Height of the front wheel's lowest point above the ground, rear frame at yaw 0, lean, pitch
    (A_IB = Rx(lean) Ry(pitch)) with the rear wheel touching the ground at the origin."""
    a = ms.kinematics.rot_x(lean_) @ ms.kinematics.rot_y(pitch)
    origin = R_R * (ms.kinematics.rot_x(lean_)[:, 2] - a[:, 2])  # rear centre above the rear contact
    rs = ms.kinematics.rot_axis(STEER_AXIS, steer_)
    centre = origin + a @ (STEER_POINT + rs @ FRONT_HUB_POINT)
    axle = a @ rs @ AXLE
    return float(centre[2] - R_F * np.sqrt(max(0.0, 1.0 - axle[2] ** 2)))


def configuration(lean: float = 0.0, steer: float = 0.0) -> tuple[np.ndarray, float]:
    """q of the bicycle standing at ``lean`` and ``steer`` (rad) with yaw 0, rear contact at the
    origin, both wheels on the ground: the rear frame's pitch solves the front contact's height
    (Newton, to round-off). Returns (q, pitch)."""
    pitch = 0.0
    for _ in range(50):
        h = _front_height(lean, pitch, steer)
        dh = (_front_height(lean, pitch + 1e-7, steer) - _front_height(lean, pitch - 1e-7, steer)) / 2e-7
        step = h / dh
        pitch -= step
        if abs(step) < 1e-16:
            break
    a = ms.kinematics.rot_x(lean) @ ms.kinematics.rot_y(pitch)
    origin = R_R * (ms.kinematics.rot_x(lean)[:, 2] - a[:, 2])
    q = np.zeros(10)
    q[0:3] = origin
    q[3:7] = ms.kinematics.matrix_to_quat(a)
    q[Q_STEER] = steer
    return q, pitch


def contact_point(model: ms.Model, q, wheel: str, radius: float) -> np.ndarray:
    """The wheel's material point at its ground contact, in the wheel's body axes."""
    st = ms.kinematics.body_states(model, q)
    k = st["body_names"].index(wheel)
    a, centre = st["rotation"][k], st["position"][k]
    axle = a @ AXLE
    up = np.array([0.0, 0.0, 1.0]) - axle[2] * axle
    return a.T @ (-radius * up / np.linalg.norm(up))


def velocities(model: ms.Model, q, v: float, lean_rate: float = 0.0, steer_rate: float = 0.0) -> np.ndarray:
    """u consistent with rolling at q (yaw 0): rear wheel spin -v/r_R, lean rate (the rear frame's
    angular velocity about the world x axis, = phi' at yaw 0) and steer rate given; the rest from
    the contact points' zero velocity (3 rows per wheel)."""
    rows, rhs = [], []
    for wheel, r in ((REAR_WHEEL, R_R), (FRONT_WHEEL, R_F)):
        jt, _ = ms.kinematics.point_jacobian(model, q, wheel, contact_point(model, q, wheel, r))
        rows.append(jt)
        rhs += [0.0, 0.0, 0.0]
    _, jr = ms.kinematics.point_jacobian(model, q, REAR)
    e = np.eye(model.nu)
    rows += [jr[0:1], e[6:7], e[U_STEER:U_STEER + 1]]
    rhs += [lean_rate, -v / R_R, steer_rate]
    return np.linalg.solve(np.vstack(rows), np.array(rhs))


def build(v: float = 5.0, lean: float = 0.0, steer: float = 0.0, lean_rate: float = 0.0, steer_rate: float = 0.0,
          name: str = "bicycle") -> ms.Model:
    """The benchmark bicycle started at forward speed ``v`` (m/s; rear wheel spin -v/r_R) in
    upright straight running, or, with the optional perturbations, at ``lean``, ``steer`` (rad)
    and ``lean_rate``, ``steer_rate`` (rad/s). Positions satisfy both contacts to round-off (the
    rear frame's pitch solved for; 0 at upright), velocities the rolling constraints."""
    q, _ = configuration(lean, steer)
    upright = np.zeros(9)
    upright[0], upright[6], upright[8] = v, -v / R_R, -v / R_F
    u = upright
    if lean or steer or lean_rate or steer_rate:
        u = velocities(_model(q, upright, name), q, v, lean_rate, steer_rate)
    return _model(q, u, name)


def lean(res) -> np.ndarray:
    """Lean phi (rad, positive to the right) from the rear frame's orientation in results:
    A_IB = Rz(psi) Rx(phi) Ry(theta), so sin(phi) = A_IB[2, 1] = 2 (q_y q_z + q_w q_x)."""
    qw, qx, qy, qz = np.asarray(res[f"body/{REAR}/orientation"]).T
    return np.arcsin(np.clip(2.0 * (qy * qz + qw * qx), -1.0, 1.0))


def steer(res) -> np.ndarray:
    """Steer delta (rad, positive to the right)."""
    return np.asarray(res[f"joint/{STEER}/q"]).reshape(-1)


def linear_analysis(v: float = 5.0):
    """The linearization about straight running at ``v`` in lean (the rear frame's rotation-vector
    x component, ``free[3]``) and steer: M, D + G, K + N against the benchmark's M, v C1,
    g K0 + v^2 K2, the eigenvalues, and the check against the nonlinear model."""
    lin = ms.linear.linearize(build(v=v), coordinates=["free[3]", STEER])
    return lin, lin.modes(), ms.linear.check(lin)


def eigenvalue_sweep(speeds=np.linspace(0.0, 10.0, 101)):
    """Eigenvalues against the forward speed, the self-stable range shaded."""
    return ms.linear.sweep(lambda v: build(v=v), speeds, parameter="forward speed v [m/s]")


# steady running at 5 m/s; `mechsys run` starts it with a push in lean rate of 0.5 rad/s
model = build(v=5.0)
_pushed = build(v=5.0, lean_rate=0.5)
simulation = dict(t_end=10.0, integrator=ms.DOPRI5(rtol=1e-10, atol=1e-12), output_dt=0.01,
                  q0=_pushed.q0(), u0=_pushed.state_vector(None, "u"))

if __name__ == "__main__":
    res = ms.simulate(model, **simulation)
    phi, delta = lean(res), steer(res)
    print("benchmark bicycle at 5 m/s (self-stable between 4.292 and 6.024 m/s), lean rate 0.5 rad/s at t = 0")
    print("   t (s)   lean (deg)  steer (deg)  |lean| max since (deg)")
    for tk in np.arange(0.0, simulation["t_end"] + 1e-9, 1.0):
        k = int(round(tk / simulation["output_dt"]))
        print(f"{tk:8.1f}  {np.degrees(phi[k]):11.5f}  {np.degrees(delta[k]):11.5f}  "
              f"{np.degrees(np.abs(phi[k:]).max()):11.5f}")
    speed = np.linalg.norm(res[f"body/{REAR_WHEEL}/velocity"], axis=1)  # of the rear wheel's centre
    viol = max(np.abs(res[f"constraint/{c}/violation"]).max() for c in ("rear_contact", "front_contact"))
    e = res["energy/total"]
    print(f"rear hub speed {speed[0]:.6f} -> {speed[-1]:.6f} m/s (the push's energy); "
          f"contact heights max {viol:.1e} m; "
          f"energy drift {np.ptp(e) / np.abs(e).max():.1e}")
    lin, modes, check = linear_analysis(5.0)
    print("\nlinearized at 5 m/s in (lean, steer): M =", np.array2string(lin.M, precision=6),
          "\n  K + N =", np.array2string(lin.K + lin.N, precision=4), "\n  D + G =", np.array2string(lin.D + lin.G, precision=4))
    print(f"  cyclic: {', '.join(lin.cyclic)}")
    print(modes.table())
    print("check against the nonlinear model:\n" + check.table())
    sw = eigenvalue_sweep()
    Path("results").mkdir(exist_ok=True)
    sw.plot(out="results/bicycle_eigenvalues.png", title="benchmark bicycle: eigenvalues against speed")
    print("self-stable " + ", ".join(f"{a:.4f} .. {b:.4f} m/s" for a, b in sw.stable_ranges()) +
          " (benchmark 4.2924 .. 6.0243); wrote results/bicycle_eigenvalues.png")
    res.save("results/bicycle.h5")
    ms.plot(res, [f"joint/{STEER}/q", f"body/{REAR}/angular_velocity", "energy/total"], out="results/bicycle.png")
    print("wrote results/bicycle.h5, results/bicycle.png")
