"""Identities of the equations of motion M(q) u' = h(q, u, t) + tau on a branched mixed-joint tree.

References that do not come from the algorithms under test:
- T = 1/2 u^T M u (eq. 2.183 summed over the bodies), so M is the Hessian of T in u, symmetric and
  positive definite; central second differences of the engine's *kinetic energy* (which sums
  1/2 m v_C^2 + 1/2 omega^T I omega per body, no mass matrix involved) are exact for a quadratic.
- ABA, CRBA and RNEA must agree with each other: u' = M^-1 (h + tau), tau = M u' - h.
- Jourdain's principle: projecting each body's Newton-Euler equations (eqs. 2.150-2.152 and the
  moment-of-momentum balance) with the Jacobians of its centre of mass and of its angular velocity
  (eqs. 2.63-2.69) gives M = sum(J_T^T m J_T + J_R^T I J_R) and
  h = sum(J_T^T (m g - m j_T) - J_R^T (I j_R + omega x I omega)), where j = J' u (the velocity
  terms of the accelerations) is taken here by central differences of J along q' = H*(q) u.
  The Jacobians themselves are checked against finite differences of positions and rotations.
- The energy balance of a damped, driven model: T + V + E_dissipated - W_external = const, with the
  dissipated energy and the external work checked against their own definitions.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.spatial.transform import Rotation

import mechsys as ms
from mechsys import dynamics as dyn

try:  # the public wrappers, where the package has them
    from mechsys import kinematics as kin

    point_jacobian, point_position, body_states = kin.point_jacobian, kin.point_position, kin.body_states
except (ImportError, AttributeError):  # pragma: no cover - older package: the bindings directly
    from mechsys import _core

    def point_jacobian(model, q, body, point=(0.0, 0.0, 0.0)):
        return _core.point_jacobian(model.build(), np.ascontiguousarray(q, dtype=float), body, [float(x) for x in point])

    def point_position(model, q, body, point=(0.0, 0.0, 0.0)):
        return _core.point_position(model.build(), np.ascontiguousarray(q, dtype=float), body, [float(x) for x in point])

    def body_states(model, q, u=None):
        core = model.build()
        out = dict(_core.body_states(core, np.ascontiguousarray(q, dtype=float), None if u is None else np.ascontiguousarray(u, dtype=float)))
        out["body_names"] = list(core.body_names)
        return out

GRAVITY = np.array([0.7, -9.81, 0.4])

# body name, parent body, joint name, joint constructor, extra joint arguments
TREE = [
    ("base", "ground", "float", ms.joints.Free, {}),
    ("arm", "base", "hinge", ms.joints.Revolute, {"axis": (0.3, -0.5, 0.8)}),
    ("slider", "arm", "slide", ms.joints.Prismatic, {"axis": (1.0, 0.2, -0.1)}),
    ("wrist", "slider", "cardan", ms.joints.Universal, {"axis": (1.0, 0.0, 0.0), "axis2": (0.0, 0.6, 0.8)}),
    ("ball", "arm", "ball", ms.joints.Spherical, {}),  # second branch on 'arm'
    ("plate", "ball", "plane", ms.joints.Planar, {}),
    ("sleeve", "ground", "screw", ms.joints.Cylindrical, {"axis": (0.0, 0.0, 1.0)}),  # second tree from the ground
]


def random_bodies(rng):
    """Mass, com and a physically valid inertia tensor (a box with turned principal axes) per body."""
    bodies = {}
    for name, *_ in TREE:
        m = rng.uniform(0.5, 3.0)
        size = rng.uniform(0.05, 0.6, size=3)
        a = Rotation.random(random_state=rng).as_matrix()
        bodies[name] = dict(mass=m, com=rng.uniform(-0.3, 0.3, size=3), inertia=a @ ms.inertia.box(m, size) @ a.T)
    return bodies


def build_tree(rng, gravity=GRAVITY):
    bodies = random_bodies(rng)
    model = ms.Model("mixed-tree", gravity=gravity)
    for name, *_ in TREE:
        model.add_body(name, **bodies[name])
    for name, parent, joint, kind, extra in TREE:
        frames = {
            "parent_frame": ms.Frame(position=rng.uniform(-0.5, 0.5, 3), rotvec=rng.uniform(-1, 1, 3)),
            "child_frame": ms.Frame(position=rng.uniform(-0.2, 0.2, 3), rotvec=rng.uniform(-1, 1, 3)),
        }
        model.add_joint(kind(joint, parent=parent, child=name, **frames, **extra))
    return model, bodies


def random_state(model, rng):
    q = np.zeros(model.nq)
    for j in model.joint_info():
        s = slice(j["iq"], j["iq"] + j["nq"])
        if j["type"] == "spherical":
            q[s] = Rotation.random(random_state=rng).as_quat(scalar_first=True)
        elif j["type"] == "free":
            q[s] = np.r_[rng.uniform(-1, 1, 3), Rotation.random(random_state=rng).as_quat(scalar_first=True)]
        else:
            q[s] = rng.uniform(-np.pi, np.pi, j["nq"])
    return q, rng.uniform(-2.0, 2.0, model.nu)


def quat_product(p, r):
    w1, v1, w2, v2 = p[0], p[1:], r[0], r[1:]
    return np.r_[w1 * w2 - v1 @ v2, w1 * v2 + w2 * v1 + np.cross(v1, v2)]


def quat_matrix(quat):
    return Rotation.from_quat(quat, scalar_first=True).as_matrix()


def coordinate_rates(model, q, u):
    """q' = H*(q) u (eq. 2.34) from the joint conventions in python/mechsys/joints.py."""
    qd = np.zeros_like(q)
    for j in model.joint_info():
        iq, iu = j["iq"], j["iu"]
        if j["type"] == "spherical":
            qd[iq : iq + 4] = 0.5 * quat_product(q[iq : iq + 4], np.r_[0.0, u[iu : iu + 3]])
        elif j["type"] == "free":
            quat = q[iq + 3 : iq + 7]
            qd[iq : iq + 3] = quat_matrix(quat / np.linalg.norm(quat)) @ u[iu : iu + 3]
            qd[iq + 3 : iq + 7] = 0.5 * quat_product(quat, np.r_[0.0, u[iu + 3 : iu + 6]])
        else:
            qd[iq : iq + j["nq"]] = u[iu : iu + j["nu"]]
    return qd


SEEDS = [0, 1, 2, 3]


@pytest.fixture(params=SEEDS, ids=[f"seed{s}" for s in SEEDS])
def case(request):
    rng = np.random.default_rng(request.param)
    model, bodies = build_tree(rng)
    q, u = random_state(model, rng)
    return model, bodies, q, u, rng


def test_tree_has_every_joint_type(case):
    model, *_ = case
    types = {j["type"] for j in model.joint_info()}
    assert types == {"free", "revolute", "prismatic", "universal", "spherical", "planar", "cylindrical"}
    assert model.nq == 7 + 1 + 1 + 2 + 4 + 3 + 2 and model.nu == 6 + 1 + 1 + 2 + 3 + 3 + 2


def test_mass_matrix_symmetric_positive_definite(case):
    model, _, q, _, _ = case
    m = dyn.mass_matrix(model, q)
    assert m.shape == (model.nu, model.nu)
    np.testing.assert_allclose(m, m.T, rtol=0, atol=1e-14 * np.abs(m).max())
    assert np.linalg.eigvalsh(m).min() > 0.0
    np.linalg.cholesky(m)


def test_kinetic_energy_is_half_u_m_u(case):
    model, _, q, u, _ = case
    m = dyn.mass_matrix(model, q)
    e = dyn.energies(model, q, u)
    assert e["kinetic"] == pytest.approx(0.5 * u @ m @ u, rel=1e-12)
    assert np.sum(e["kinetic_per_body"]) == pytest.approx(e["kinetic"], rel=1e-13)


def test_mass_matrix_is_hessian_of_kinetic_energy(case):
    model, _, q, u, _ = case
    n = model.nu

    def kin(v):
        return dyn.energies(model, q, v)["kinetic"]

    hess = np.zeros((n, n))
    h = 1.0  # T is exactly quadratic in u: the central second difference has no truncation error
    eye = np.eye(n)
    for i in range(n):
        for k in range(i, n):
            d = (kin(u + h * eye[i] + h * eye[k]) - kin(u + h * eye[i] - h * eye[k])
                 - kin(u - h * eye[i] + h * eye[k]) + kin(u - h * eye[i] - h * eye[k])) / (4.0 * h * h)
            hess[i, k] = hess[k, i] = d
    m = dyn.mass_matrix(model, q)
    np.testing.assert_allclose(hess, m, rtol=0, atol=1e-10 * np.abs(m).max())


def test_forward_dynamics_equals_mass_matrix_solve(case):
    model, _, q, u, rng = case
    tau = rng.uniform(-5.0, 5.0, model.nu)
    m = dyn.mass_matrix(model, q)
    h = dyn.nonlinear_effects(model, q, u)
    for t in (None, tau):
        rhs = h if t is None else h + t
        ref = np.linalg.solve(m, rhs)
        udot = dyn.forward_dynamics(model, q, u, t)
        assert np.linalg.norm(udot - ref) <= 1e-12 * np.linalg.norm(ref)  # cond(M) ~ 1e4 here
        # residual of the equations of motion, the solver-independent form of the same statement
        assert np.linalg.norm(m @ udot - rhs) <= 1e-12 * (np.abs(m).max() * np.linalg.norm(udot) + np.linalg.norm(rhs))


def test_inverse_dynamics_inverts_forward_dynamics(case):
    model, _, q, u, rng = case
    tau = rng.uniform(-5.0, 5.0, model.nu)
    udot = dyn.forward_dynamics(model, q, u, tau)
    back = dyn.inverse_dynamics(model, q, u, udot)
    scale = np.linalg.norm(tau) + np.linalg.norm(dyn.nonlinear_effects(model, q, u))
    assert np.linalg.norm(back - tau) < 1e-10 * scale
    # and the other way round, from an arbitrary acceleration
    udot = rng.uniform(-3.0, 3.0, model.nu)
    tau = dyn.inverse_dynamics(model, q, u, udot)
    assert np.linalg.norm(dyn.forward_dynamics(model, q, u, tau) - udot) < 1e-10 * np.linalg.norm(udot)


def test_nonlinear_effects_with_gravity_and_velocity(case):
    model, _, q, u, _ = case
    m = dyn.mass_matrix(model, q)
    h = dyn.nonlinear_effects(model, q, u)
    # tau = M u' - h for any u'; at u' = 0 inverse dynamics is -h
    np.testing.assert_allclose(dyn.inverse_dynamics(model, q, u, np.zeros(model.nu)), -h, rtol=0, atol=1e-12 * np.abs(h).max())
    # with no velocity-dependent force elements, h(q, u) - h(q, 0) is quadratic in u
    h0 = dyn.nonlinear_effects(model, q, np.zeros(model.nu))
    h3 = dyn.nonlinear_effects(model, q, 3.0 * u)
    np.testing.assert_allclose(h3 - h0, 9.0 * (h - h0), rtol=0, atol=1e-11 * np.abs(h3 - h0).max())
    # gravity alone: h(q, 0) = J_C^T sum m g, the generalized weight (checked body by body below);
    # without gravity h(q, 0) vanishes
    flat, _ = build_tree(np.random.default_rng(99), gravity=(0.0, 0.0, 0.0))
    assert np.abs(dyn.nonlinear_effects(flat, q, np.zeros(model.nu))).max() == 0.0


def jacobians(model, q, name, point):
    jt, jr = point_jacobian(model, q, name, point)
    return np.asarray(jt), np.asarray(jr)


def test_point_jacobians_match_finite_differences(case):
    model, bodies, q, u, _ = case
    qd = coordinate_rates(model, q, u)
    eps = 1e-6
    states = body_states(model, q, u)
    names = list(states["body_names"])
    qp, qm = q + eps * qd, q - eps * qd
    rot_p = body_states(model, qp)["rotation"]
    rot_m = body_states(model, qm)["rotation"]
    for name, b in bodies.items():
        k = names.index(name)
        jt, jr = jacobians(model, q, name, b["com"])
        # velocity of the centre of mass: d/dt of its position along q' = H* u
        fd_v = (point_position(model, qp, name, b["com"]) - point_position(model, qm, name, b["com"])) / (2 * eps)
        np.testing.assert_allclose(jt @ u, fd_v, rtol=0, atol=1e-7 * max(1.0, np.linalg.norm(fd_v)))
        # angular velocity: omega~_I = A' A^T (eq. 2.35)
        a = states["rotation"][k]
        w_tilde = (rot_p[k] - rot_m[k]) / (2 * eps) @ a.T
        fd_w = np.array([w_tilde[2, 1], w_tilde[0, 2], w_tilde[1, 0]])
        np.testing.assert_allclose(jr @ u, fd_w, rtol=0, atol=1e-7 * max(1.0, np.linalg.norm(fd_w)))
        np.testing.assert_allclose(states["angular_velocity"][k], jr @ u, rtol=0, atol=1e-12 * max(1.0, np.linalg.norm(fd_w)))
        # the body-origin velocity reported by body_states is J_T(origin) u
        jt0, _ = jacobians(model, q, name, np.zeros(3))
        np.testing.assert_allclose(states["velocity"][k], jt0 @ u, rtol=0, atol=1e-12 * max(1.0, np.linalg.norm(jt0 @ u)))


def test_jourdain_projection_of_newton_euler_equations(case):
    """M and h assembled body by body from Newton-Euler about the centre of mass."""
    model, bodies, q, u, _ = case
    states = body_states(model, q, u)
    names, rotations = list(states["body_names"]), states["rotation"]
    qd = coordinate_rates(model, q, u)
    eps = 1e-6
    n = model.nu
    m_ref, h_ref = np.zeros((n, n)), np.zeros(n)
    for name, b in bodies.items():
        a = rotations[names.index(name)]
        inertia_i = a @ b["inertia"] @ a.T
        jt, jr = jacobians(model, q, name, b["com"])
        jt_p, jr_p = jacobians(model, q + eps * qd, name, b["com"])
        jt_m, jr_m = jacobians(model, q - eps * qd, name, b["com"])
        jbar_t = (jt_p - jt_m) @ u / (2 * eps)  # velocity terms of the com acceleration
        jbar_r = (jr_p - jr_m) @ u / (2 * eps)  # velocity terms of the angular acceleration
        omega = jr @ u
        m_ref += b["mass"] * jt.T @ jt + jr.T @ inertia_i @ jr
        h_ref += jt.T @ (b["mass"] * GRAVITY - b["mass"] * jbar_t) - jr.T @ (inertia_i @ jbar_r + np.cross(omega, inertia_i @ omega))
    m = dyn.mass_matrix(model, q)
    h = dyn.nonlinear_effects(model, q, u)
    np.testing.assert_allclose(m, m_ref, rtol=0, atol=1e-12 * np.abs(m).max())
    np.testing.assert_allclose(h, h_ref, rtol=0, atol=1e-7 * np.abs(h).max())


# ---- energy balance with force elements ---------------------------------------------------------


def damped_driven_model():
    """A chain with joint springs and dampers, a point-to-point spring-damper, a harmonic body force
    and a constant joint torque under gravity."""
    model = ms.Model("damped-driven", gravity=(0.0, -9.81, 0.0))
    arm = model.add_body("arm", mass=1.5, inertia=ms.inertia.cylinder(1.5, 0.03, 0.6), com=(0.3, 0.0, 0.0))
    slider = model.add_body("slider", mass=0.8, inertia=ms.inertia.box(0.8, (0.1, 0.1, 0.1)), com=(0.0, 0.05, 0.0))
    bob = model.add_body("bob", mass=0.5, inertia=ms.inertia.box(0.5, (0.2, 0.05, 0.1)), com=(0.1, 0.0, 0.02))
    model.add_joint(ms.joints.Revolute("hinge", parent=model.ground, child=arm, axis=(0, 0, 1),
                                       spring=ms.forces.RotarySpring(k=4.0, q_free=-1.2), damper=ms.forces.RotaryDamper(d=0.3)))
    model.add_joint(ms.joints.Prismatic("slide", parent=arm, child=slider, parent_frame=(0.6, 0.0, 0.0), axis=(1, 0, 0),
                                        spring=ms.forces.LinearSpring(k=50.0, q_free=0.1), damper=ms.forces.LinearDamper(d=2.0)))
    model.add_joint(ms.joints.Spherical("ball", parent=slider, child=bob, parent_frame=(0.0, 0.1, 0.0),
                                        damper=ms.forces.RotaryDamper(d=[0.01, 0.02, 0.015])))
    model.add_force(ms.forces.SpringDamper("strut", body1=model.ground, point1=(0.0, 0.5, 0.2), body2=bob, point2=(0.2, 0.0, 0.0),
                                           k=30.0, d=0.8, l0=0.4, k3=100.0))
    model.add_force(ms.forces.BodyForce("push", body=bob, force=(0.0, 0.0, 25.0), torque=(0.5, 0.0, 0.0), point=(0.1, 0.0, 0.0),
                                        function=ms.functions.Harmonic(amplitude=1.0, omega=7.0)))
    model.add_force(ms.forces.JointForce("motor", joint="hinge", value=6.0))
    return model


def test_energy_balance_with_dampers_springs_and_loads():
    model = damped_driven_model()
    res = ms.simulate(model, 3.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.005, q0={"hinge": -0.9, "slide": 0.2},
                      u0={"ball": [1.0, -2.0, 0.5]})
    total, diss, work = res["energy/total"], res["energy/dissipated"], res["energy/external_work"]
    scale = max(np.abs(total).max(), np.abs(diss).max(), np.abs(work).max())
    assert diss[-1] > 0.05 * scale and np.abs(work).max() > 0.05 * scale  # both terms really matter
    assert np.all(np.diff(diss) >= -1e-12 * scale)  # dissipation never gives energy back
    balance = total + diss - work
    assert np.max(np.abs(balance - balance[0])) < 1e-8 * scale


def test_dissipated_energy_and_external_work_match_their_definitions():
    """Only joint dampers and a constant joint torque: E_diss = int sum d u^2 dt, W = tau0 (q - q0)."""
    model = ms.Model("damped-pendulum", gravity=(0.0, -9.81, 0.0))
    rod = model.add_body("rod", mass=1.0, inertia=ms.inertia.rod(1.0, 1.0), com=(0.5, 0.0, 0.0))
    tip = model.add_body("tip", mass=0.3, inertia=ms.inertia.sphere(0.3, 0.05))
    model.add_joint(ms.joints.Revolute("hinge", parent=model.ground, child=rod, axis=(0, 0, 1), damper=ms.forces.RotaryDamper(d=0.2)))
    model.add_joint(ms.joints.Prismatic("slide", parent=rod, child=tip, parent_frame=(1.0, 0.0, 0.0), axis=(1, 0, 0),
                                        spring=ms.forces.LinearSpring(k=40.0), damper=ms.forces.LinearDamper(d=1.5)))
    tau0 = 0.7
    model.add_force(ms.forces.JointForce("motor", joint="hinge", value=tau0))
    res = ms.simulate(model, 2.0, ms.DOPRI5(rtol=1e-12, atol=1e-12), output_dt=1e-3, q0={"hinge": 0.3, "slide": 0.1})
    u_h, u_s = res["joint/hinge/u"], res["joint/slide/u"]
    power = 0.2 * u_h**2 + 1.5 * u_s**2
    diss = np.r_[0.0, [simpson(power[: k + 1], x=res.t[: k + 1]) for k in range(1, len(res.t))]]
    sel = slice(200, None, 200)  # Simpson with an even number of intervals
    np.testing.assert_allclose(res["energy/dissipated"][sel], diss[sel], rtol=1e-6)
    np.testing.assert_allclose(res["energy/external_work"], tau0 * (res["joint/hinge/q"] - 0.3), rtol=0, atol=1e-9)
