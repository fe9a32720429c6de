"""Constraint kinds of issue 3 (second part): point on line / plane, loop-closing joints, and the
non-holonomic knife edge and rolling disc, checked against closed-form mechanics."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms

G = 9.81
TIGHT = ms.DOPRI5(rtol=1e-12, atol=1e-13)


def quat_of(a):
    """Unit quaternion [w, x, y, z] of a rotation matrix (Shepperd)."""
    a = np.asarray(a, dtype=float)
    t = np.trace(a)
    k = int(np.argmax([t, a[0, 0], a[1, 1], a[2, 2]]))
    if k == 0:
        w = 0.5 * np.sqrt(1 + t)
        q = [w, (a[2, 1] - a[1, 2]) / (4 * w), (a[0, 2] - a[2, 0]) / (4 * w), (a[1, 0] - a[0, 1]) / (4 * w)]
    else:
        i, j, l = k - 1, k % 3, (k + 1) % 3
        s = 0.5 * np.sqrt(1 + a[i, i] - a[j, j] - a[l, l])
        q = [0.0] * 4
        q[0] = (a[l, j] - a[j, l]) / (4 * s)
        q[1 + i] = s
        q[1 + j] = (a[j, i] + a[i, j]) / (4 * s)
        q[1 + l] = (a[l, i] + a[i, l]) / (4 * s)
    return np.array(q) * np.sign(q[0] or 1.0)


def matrix_of(q):
    """Rotation matrices of quaternions [..., 4] ([w, x, y, z])."""
    w, x, y, z = (q[..., k] for k in range(4))
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


# ---- (i) pendulum closed by a loop-revolute joint ---------------------------------------------

MASS, L, THETA0 = 1.3, 0.7, 1.1
INERTIA = np.array([[0.02, 0.001, -0.002], [0.001, 0.03, 0.0015], [-0.002, 0.0015, 0.025]])


def pendulum_by_revolute():
    m = ms.Model("revolute-pendulum", gravity=(0.0, -G, 0.0))
    bob = m.add_body("bob", MASS, INERTIA, com=(0.0, -L, 0.0))
    m.add_joint(ms.joints.Revolute("pin", m.ground, bob, axis=(0, 0, 1), q0=THETA0))
    return m


def pendulum_by_loop(hinge=(0.3, 0.2, 0.0)):
    """The same body on a free joint, hinged to the ground by a loop-revolute constraint about the
    world z-axis through ``hinge`` (the body frame origin sits on the hinge)."""
    m = ms.Model("loop-pendulum", gravity=(0.0, -G, 0.0))
    bob = m.add_body("bob", MASS, INERTIA, com=(0.0, -L, 0.0))
    c, s = np.cos(THETA0 / 2), np.sin(THETA0 / 2)
    m.add_joint(ms.joints.Free("float", m.ground, bob, q0=[*hinge, c, 0.0, 0.0, s]))
    # frames: z-axes along world z; frame 2 on the ground is turned, only its z-axis matters
    m.add_constraint(
        ms.constraints.LoopRevolute("hinge", bob, m.ground, frame2=ms.Frame(position=hinge, cardan=(0.0, 0.0, 0.4)))
    )
    return m


def pendulum_period(theta0):
    """Exact period 4 sqrt(I_O / (m g L)) K(sin(theta0/2)), K by the arithmetic-geometric mean."""
    i_o = INERTIA[2, 2] + MASS * L**2
    a, b = 1.0, np.cos(theta0 / 2)
    for _ in range(30):
        a, b = (a + b) / 2, np.sqrt(a * b)
    return 4 * np.sqrt(i_o / (MASS * G * L)) * np.pi / (2 * a)


def upward_zero_crossings(t, x):
    k = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    return t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])


def test_loop_revolute_pendulum_matches_the_revolute_joint_pendulum():
    ref = ms.simulate(pendulum_by_revolute(), 10.0, TIGHT, output_dt=0.01)
    res = ms.simulate(pendulum_by_loop(), 10.0, TIGHT, output_dt=0.01)
    q = res["body/bob/orientation"]
    angle = 2 * np.arctan2(q[:, 3], q[:, 0])
    # the body's x- and y-axes stay in the x-y plane: the hinge holds the orientation
    np.testing.assert_allclose(q[:, 1:3], 0.0, atol=1e-10)
    np.testing.assert_allclose(angle, ref["joint/pin/q"], rtol=0, atol=1e-8)
    np.testing.assert_allclose(res["body/bob/position"], np.broadcast_to([0.3, 0.2, 0.0], (len(res.t), 3)), atol=1e-10)
    assert np.abs(res["constraint/hinge/violation"]).max() < 1e-10
    # same period, equal to the closed form
    t_ref = np.diff(upward_zero_crossings(ref.t, ref["joint/pin/q"]))
    t_loop = np.diff(upward_zero_crossings(res.t, angle))
    assert len(t_loop) >= 2
    np.testing.assert_allclose(t_loop, t_ref, rtol=0, atol=1e-7)
    np.testing.assert_allclose(t_loop, pendulum_period(THETA0), rtol=1e-6)
    # the hinge moments hold the body's tilting inertia forces; the force carries the weight
    assert res.unit("constraint/hinge/lambda") == "N, N m"
    e = res["energy/total"]
    assert np.ptp(e) < 1e-9 * np.abs(e).max()


def test_loop_spherical_and_fixed_and_point_on_line_plane_hold():
    """A double pendulum closed by every holonomic kind at once (redundantly): the free body is
    welded to the link tip, so it must move exactly with the link; the extra point-on-line,
    point-on-plane and spherical rows repeat what the weld already says (dependent rows)."""
    m = ms.Model("weld", gravity=(0.0, -G, 0.0))
    link = m.add_body("link", 1.0, ms.inertia.rod(1.0, 0.5), com=(0.25, 0, 0))
    box = m.add_body("box", 0.7, ms.inertia.box(0.7, (0.1, 0.2, 0.3)), com=(0.05, 0.0, 0.0))
    m.add_joint(ms.joints.Revolute("pin", m.ground, link, axis=(0, 0, 1), q0=-0.4))
    m.add_joint(ms.joints.Free("float", m.ground, box, q0=[0.4, -0.1, 0.0, 1.0, 0.0, 0.0, 0.0]))
    tip = ms.Frame(position=(0.5, 0.0, 0.0), cardan=(0.0, 0.0, 0.3))
    m.add_constraint(ms.constraints.LoopFixed("weld", box, link, frame2=tip))
    m.add_constraint(ms.constraints.LoopSpherical("ball", box, link, frame1=(0.1, 0.0, 0.0), frame2=ms.Frame(position=(0.5 + 0.1 * np.cos(0.3), 0.1 * np.sin(0.3), 0.0))))
    m.add_constraint(ms.constraints.PointOnLine("rail", box, link, direction=(1.0, 0.0, 0.0), point1=(0.0, 0.0, 0.0), point2=(0.5, 0.0, 0.0)))
    m.add_constraint(ms.constraints.PointOnPlane("slide", box, m.ground, normal=(0.0, 0.0, 1.0), point1=(0.0, 0.1, 0.0)))
    with pytest.warns(UserWarning, match="redundant"):
        res = ms.simulate(m, 2.0, TIGHT, output_dt=0.01)
    th = res["joint/pin/q"]
    tip_pos = 0.5 * np.stack([np.cos(th), np.sin(th), 0 * th], -1)
    np.testing.assert_allclose(res["body/box/position"], tip_pos, atol=1e-9)
    q = res["body/box/orientation"]
    np.testing.assert_allclose(2 * np.arctan2(q[:, 3], q[:, 0]), th + 0.3, atol=1e-9)
    for name in ("weld", "ball", "rail", "slide"):
        assert np.abs(res[f"constraint/{name}/violation"]).max() < 1e-10, name
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * np.abs(e).max()


# ---- (ii) knife edge --------------------------------------------------------------------------


def test_knife_edge_sledge_runs_on_a_circle():
    """A sledge on a planar joint (x, y, yaw) with its blade along the body x-axis through the
    centre of mass, no gravity: the lateral blade force passes through the centre of mass, so the
    yaw rate and the speed along the blade stay constant and the sledge runs on a circle of radius
    v / omega: x = (v/omega) sin(omega t), y = (v/omega)(1 - cos(omega t)), yaw = omega t."""
    v, omega = 1.5, 0.8
    m = ms.Model("sledge", gravity=(0.0, 0.0, 0.0))
    sledge = m.add_body("sledge", 2.0, ms.inertia.box(2.0, (0.6, 0.2, 0.1)))
    m.add_joint(ms.joints.Planar("plane", m.ground, sledge, q0=[0.0, 0.0, 0.0], u0=[v, 0.0, omega]))
    m.add_constraint(ms.constraints.KnifeEdge("blade", sledge, direction=(0.0, 1.0, 0.0)))
    res = ms.simulate(m, 10.0, TIGHT, output_dt=0.01)
    t = res.t
    q = res["joint/plane/q"]
    rho = v / omega
    np.testing.assert_allclose(q[:, 2], omega * t, rtol=0, atol=1e-8)
    np.testing.assert_allclose(q[:, 0], rho * np.sin(omega * t), rtol=0, atol=1e-8)
    np.testing.assert_allclose(q[:, 1], rho * (1 - np.cos(omega * t)), rtol=0, atol=1e-8)
    # lateral force = mass * centripetal acceleration, towards the centre (+y body axis)
    np.testing.assert_allclose(res["constraint/blade/lambda"], 2.0 * v * omega, rtol=1e-8)
    # non-holonomic: no position violation is defined
    assert np.all(res["constraint/blade/violation"] == 0.0)
    ke = res["energy/kinetic"]
    assert np.ptp(ke) < 1e-9 * ke.max()


def test_knife_edge_is_not_integrable_the_sledge_reaches_a_sideways_point():
    """Parallel parking: turning out and back while it drives forward, the sledge ends displaced
    sideways (along its blocked direction) with its original heading: a holonomic constraint could
    not allow that. Driven by prescribed yaw psi = 0.5 sin^2(pi t / 2) and a forward push sin(pi t / 2)
    (unit mass): the blade takes no forward force, so the forward speed is
    v = (2 / pi)(1 - cos(pi t / 2)) and the end point is the quadrature of v (cos psi, sin psi)."""
    from scipy.integrate import quad

    m = ms.Model("parking", gravity=(0.0, 0.0, 0.0))
    sledge = m.add_body("sledge", 1.0, ms.inertia.box(1.0, (0.4, 0.2, 0.1)))
    m.add_joint(ms.joints.Planar("plane", m.ground, sledge))
    m.add_constraint(ms.constraints.KnifeEdge("blade", sledge, direction=(0.0, 1.0, 0.0)))
    # yaw goes 0 -> 0.5 -> 0 while the sledge drives forward at first and back later
    m.add_constraint(ms.constraints.Prescribed("steer", "plane", lambda t: 0.5 * np.sin(np.pi * t / 2) ** 2, index=2))
    m.add_force(ms.forces.BodyForce("push", sledge, force=(1.0, 0.0, 0.0), frame="body", function=ms.functions.Harmonic(1.0, np.pi / 2)))
    res = ms.simulate(m, 4.0, ms.RK4(1e-3), output_dt=0.01)
    q = res["joint/plane/q"]
    assert abs(q[-1, 2]) < 1e-6
    lateral = -np.sin(q[:, 2]) * res["joint/plane/u"][:, 0] + np.cos(q[:, 2]) * res["joint/plane/u"][:, 1]
    np.testing.assert_allclose(lateral, 0.0, atol=1e-9)
    speed = lambda t: 2 / np.pi * (1 - np.cos(np.pi * t / 2))  # noqa: E731
    psi = lambda t: 0.5 * np.sin(np.pi * t / 2) ** 2  # noqa: E731
    forward = np.cos(q[:, 2]) * res["joint/plane/u"][:, 0] + np.sin(q[:, 2]) * res["joint/plane/u"][:, 1]
    np.testing.assert_allclose(forward, speed(res.t), rtol=0, atol=1e-9)
    end = [quad(lambda t: speed(t) * f(psi(t)), 0.0, 4.0, epsabs=1e-13)[0] for f in (np.cos, np.sin)]
    # (RK4 at dt = 1e-3: 7e-12 m measured)
    np.testing.assert_allclose(q[-1, :2], end, rtol=0, atol=1e-9)
    assert end[1] > 0.6  # sideways by 0.62 m


# ---- (iii) rolling disc -----------------------------------------------------------------------


def steady_rolling_disc(theta, Omega, R=0.2, mass=1.5, spin_factor=1.0):
    """Initial state of a thin disc (I3 = m R^2/2 about its axis, I1 = m R^2/4 about diameters)
    in steady rolling on the plane z = 0, tilted by ``theta`` from the vertical and precessing at
    ``Omega`` about the vertical.

    Derivation. Horizontal unit vectors e1, e2, vertical ez. Let h = cos(theta) ez - sin(theta) e1
    point from the contact P to the centre C (C - P = R h), the disc axis a = sin(theta) ez +
    cos(theta) e1, the rolling direction e2. In steady motion (a, h) turn about ez at Omega and
    omega = Omega ez + s a; let n = omega . a = Omega sin(theta) + s. Rolling (v_P = 0):
    v_C = omega x (R h) = -R n e2 =: V e2, so C runs on a circle of radius rho = V / Omega about
    a vertical axis on the -e1 side (the disc leans inwards), a_C = -Omega V e1.
    Newton: contact force F = m g ez - m Omega V e1. Angular momentum about C:
    H = I1 Omega ez + (I3 n - I1 Omega sin(theta)) a, and in steady motion dH/dt = Omega ez x H =
    Omega cos(theta) (I3 n - I1 Omega sin(theta)) e2. The moment of F about C is
    (-R h) x F = R m (Omega V cos(theta) - g sin(theta)) e2. Equating with V = -R n:
        Omega cos(theta) ((I3 + m R^2) n - I1 Omega sin(theta)) + m g R sin(theta) = 0,
    i.e. for the thin disc  Omega cos(theta) (6 n - Omega sin(theta)) + 4 g sin(theta) / R = 0.
    (Large circles, Omega -> 0: tan(theta) = 3 V^2 / (2 g rho), the classical coin result.)

    Returns (model, n, V): the disc body's frame has z along a, x along h, centre at the origin.
    ``spin_factor`` scales n away from the steady value (a rolling but not steady start).
    """
    n = spin_factor * (Omega * np.sin(theta) - 4 * G * np.tan(theta) / (R * Omega)) / 6
    s = n - Omega * np.sin(theta)
    V = -R * n
    e1, e2, ez = np.eye(3)
    h = np.cos(theta) * ez - np.sin(theta) * e1
    a = np.sin(theta) * ez + np.cos(theta) * e1
    A = np.column_stack([h, np.cross(a, h), a])
    center = R * h  # contact at the origin
    w = Omega * ez + s * a
    m = ms.Model("rolling-disc", gravity=(0.0, 0.0, -G))
    disc = m.add_body("disc", mass, ms.inertia.disc(mass, R))
    # free joint: u = [v_B, omega_B] in body axes
    m.add_joint(ms.joints.Free("float", m.ground, disc, q0=[*center, *quat_of(A)], u0=[*(A.T @ (V * e2)), *(A.T @ w)]))
    m.add_constraint(ms.constraints.RollingDisc("roll", disc, radius=R, axis=(0, 0, 1)))
    return m, n, V


def test_rolling_disc_in_steady_circular_motion():
    theta, Omega, R = 0.3, 2.0, 0.2
    model, n, V = steady_rolling_disc(theta, Omega, R)
    t_end = 3 * 2 * np.pi / Omega  # three precession revolutions
    res = ms.simulate(model, t_end, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01)
    A = matrix_of(res["body/disc/orientation"])
    a = A[:, :, 2]
    tilt = np.arcsin(a[:, 2])
    assert np.abs(tilt - theta).max() < 1e-6
    psi = np.unwrap(np.arctan2(a[:, 1], a[:, 0]))
    assert np.abs(psi - psi[0] - Omega * res.t).max() < 1e-6
    # the centre runs on its circle at constant speed |V|
    speed = np.linalg.norm(res["body/disc/velocity"], axis=1)
    assert np.abs(speed - abs(V)).max() < 1e-6
    # rolling without slipping does no work: energy conserved
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * np.abs(e).max()
    # the contact force carries the weight and the centripetal force
    lam = res["constraint/roll/lambda"]
    np.testing.assert_allclose(lam[:, 0], 1.5 * G, rtol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(lam[:, 1:], axis=1), 1.5 * abs(Omega * V), rtol=1e-6)
    assert np.abs(res["constraint/roll/violation"]).max() < 1e-10


def test_rolling_disc_off_steady_state_nutates_and_conserves_energy():
    """The steady condition is not trivially satisfied: starting with 10 % more spin than the
    steady value the tilt oscillates visibly, while energy is still conserved and the contact stays
    on the ground."""
    model, _, _ = steady_rolling_disc(0.3, 2.0, 0.2, spin_factor=1.1)
    res = ms.simulate(model, 3.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01)
    a = matrix_of(res["body/disc/orientation"])[:, :, 2]
    assert np.ptp(np.arcsin(a[:, 2])) > 1e-3  # (a mismatched pair of Omega and n is not steady)
    e = res["energy/total"]
    assert np.ptp(e) < 1e-8 * np.abs(e).max()
    assert np.abs(res["constraint/roll/violation"]).max() < 1e-10


# ---- (iv) bad input ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "constraint, fragments",
    [
        (lambda: ms.constraints.PointOnLine("l", "nobody", "ground", direction=(1, 0, 0)), ["'l'", "body1", "nobody"]),
        (lambda: ms.constraints.PointOnLine("l", "b", "ground", direction=(0, 0, 0)), ["'l'", "direction", "zero"]),
        (lambda: ms.constraints.PointOnPlane("p", "b", "nobody", normal=(0, 0, 1)), ["'p'", "body2", "nobody"]),
        (lambda: ms.constraints.PointOnPlane("p", "b", "ground", normal=(0, 0, 0)), ["'p'", "normal", "zero"]),
        (lambda: ms.constraints.LoopRevolute("h", "nobody", "ground"), ["'h'", "body1", "nobody"]),
        (lambda: ms.constraints.LoopFixed("w", "b", "b"), ["'w'", "same body"]),
        (
            lambda: ms.constraints.LoopSpherical("s", "b", "ground", frame2=ms.Frame(rotation=[[1, 0, 0], [0, 1, 0], [0, 0, 2]])),
            ["'s'", "frame2", "rotation"],
        ),
        (lambda: ms.constraints.KnifeEdge("k", "nobody", direction=(0, 1, 0)), ["'k'", "body", "nobody"]),
        (lambda: ms.constraints.KnifeEdge("k", "b", direction=(0, 0, 0)), ["'k'", "direction", "zero"]),
        (lambda: ms.constraints.RollingDisc("r", "b", radius=0.0), ["'r'", "radius", "> 0"]),
        (lambda: ms.constraints.RollingDisc("r", "b", radius=-1.0), ["'r'", "radius"]),
        (lambda: ms.constraints.RollingDisc("r", "b", radius=0.1, axis=(0, 0, 0)), ["'r'", "axis", "zero"]),
        (lambda: ms.constraints.RollingDisc("r", "ground", radius=0.1), ["'r'", "body", "ground"]),
        (lambda: {"type": "knife_edge", "name": "k", "body": "b", "directoin": [0, 1, 0]}, ["constraints[0]", "constraint 'k'", "directoin"]),
        (lambda: {"type": "rolling_disc", "name": "r", "body": "b", "axis": [0, 0, 1]}, ["constraints[0]", "constraint 'r'", "radius"]),
        (
            lambda: {"type": "loop_fixed", "name": "w", "body1": "b", "body2": "ground", "frame1": {"positon": [0, 0, 0]}},
            ["constraints[0]", "constraint 'w'.frame1", "positon"],
        ),
    ],
)
def test_bad_constraint_kinds_name_the_item_and_key(constraint, fragments):
    m = ms.Model("m")
    b = m.add_body("b", 1.0, [0.1, 0.1, 0.1])
    m.add_joint(ms.joints.Free("j", m.ground, b))
    m.add_constraint(constraint())
    with pytest.raises(ms.ModelError) as e:
        m.build()
    for f in fragments:
        assert f in str(e.value), (f, str(e.value))


def test_constraint_kinds_report_type_and_units():
    m, _, _ = steady_rolling_disc(0.3, 2.0)
    cs = {c["name"]: c for c in m.build().constraints()}
    assert cs["roll"]["type"] == "rolling_disc" and cs["roll"]["rows"] == 3
    assert pendulum_by_loop().build().constraints()[0]["type"] == "loop_revolute"
