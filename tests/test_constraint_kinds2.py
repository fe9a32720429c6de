"""Constraint kinds of issue 3 (third part): the prismatic, cylindrical, universal and planar
loop-closing joints, prescribed body motion, and user-given velocity constraints, each checked
against closed-form mechanics, plus their bad-input errors."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms
from mechsys.modelfile import load_model

from test_constraint_kinds import matrix_of, quat_of

G = 9.81
TIGHT = ms.DOPRI5(rtol=1e-12, atol=1e-13)

# a full inertia tensor (not principal in the body frame): spinning about body z needs a moment
INERTIA = np.array([[0.05, 0.004, -0.006], [0.004, 0.04, 0.003], [-0.006, 0.003, 0.03]])


def rot_y(b):
    c, s = np.cos(b), np.sin(b)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(g):
    c, s = np.cos(g), np.sin(g)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def spin_moment(omega, angle):
    """Moment (frame-2 components) that keeps a body with ``INERTIA`` spinning at constant
    ``omega`` about its z-axis when its x-axis is turned by ``angle`` from frame 2's: in body axes
    dH/dt = omega x (I omega) = omega^2 e_z x (I e_z) = omega^2 (-I_yz, I_xz, 0)."""
    m_body = omega**2 * np.array([-INERTIA[1, 2], INERTIA[0, 2], 0.0])
    return np.einsum("nij,j->ni", np.stack([rot_z(a) for a in np.atleast_1d(angle)]), m_body)


# ---- loop-closing prismatic, cylindrical, planar joints on an incline ---------------------------

ALPHA, MASS = 0.35, 1.7
# frame 2 on the ground: z2 up the incline at ALPHA from horizontal, y2 horizontal
A2 = rot_y(np.pi / 2 - ALPHA)
ORIGIN = np.array([0.2, -0.1, 0.4])


def body_on_incline(constraint_type, v0, spin=0.0):
    """A free body whose frame starts at ``ORIGIN`` with frame 2's orientation, moving up the
    incline at ``v0`` and spinning about z2 at ``spin``; held to the ground by the loop joint."""
    m = ms.Model("incline", gravity=(0.0, 0.0, -G))
    b = m.add_body("b", MASS, INERTIA)
    u0 = [0.0, 0.0, v0, 0.0, 0.0, spin]  # body axes: the body's z-axis is z2
    m.add_joint(ms.joints.Free("float", m.ground, b, q0=[*ORIGIN, *quat_of(A2)], u0=u0))
    m.add_constraint(constraint_type("slide", b, m.ground, frame2=ms.Frame(position=ORIGIN, rotation=A2)))
    return m


def test_loop_prismatic_slides_down_the_incline_with_g_sin_alpha():
    v0 = 2.0
    res = ms.simulate(body_on_incline(ms.constraints.LoopPrismatic, v0), 1.5, TIGHT, output_dt=0.01)
    t = res.t
    s = v0 * t - 0.5 * G * np.sin(ALPHA) * t**2
    expected = ORIGIN + s[:, None] * A2[:, 2]
    np.testing.assert_allclose(res["body/b/position"], expected, rtol=0, atol=1e-9)
    # no rotation at all
    np.testing.assert_allclose(matrix_of(res["body/b/orientation"]), np.broadcast_to(A2, (len(t), 3, 3)), atol=1e-10)
    lam = res["constraint/slide/lambda"]
    assert lam.shape == (len(t), 5)
    # the force on the body along x2 = (sin a, 0, -cos a) cancels gravity's normal part: -m g cos a
    np.testing.assert_allclose(lam[:, 0], -MASS * G * np.cos(ALPHA), rtol=1e-9)
    np.testing.assert_allclose(lam[:, 1:], 0.0, atol=1e-9)
    assert np.abs(res["constraint/slide/violation"]).max() < 1e-10
    assert res.unit("constraint/slide/lambda") == "N, N m"


def test_loop_cylindrical_slides_and_spins_with_the_gyroscopic_moment():
    v0, spin = 1.0, 3.0
    res = ms.simulate(body_on_incline(ms.constraints.LoopCylindrical, v0, spin), 2.0, TIGHT, output_dt=0.01)
    t = res.t
    s = v0 * t - 0.5 * G * np.sin(ALPHA) * t**2
    np.testing.assert_allclose(res["body/b/position"], ORIGIN + s[:, None] * A2[:, 2], rtol=0, atol=1e-9)
    # free rotation about the axis at the constant rate
    a = matrix_of(res["body/b/orientation"])
    rel = np.einsum("ji,njk->nik", A2, a)  # body in frame-2 axes: Rz(spin t)
    np.testing.assert_allclose(rel, np.stack([rot_z(spin * tk) for tk in t]), atol=1e-8)
    lam = res["constraint/slide/lambda"]
    np.testing.assert_allclose(lam[:, 0], -MASS * G * np.cos(ALPHA), rtol=1e-9)
    np.testing.assert_allclose(lam[:, 1], 0.0, atol=1e-9)
    # moment rows about z1 x x2 = y2 and z1 x y2 = -x2 hold the spinning body's tilt
    m = spin_moment(spin, spin * t)
    np.testing.assert_allclose(lam[:, 2], m[:, 1], rtol=0, atol=1e-8)
    np.testing.assert_allclose(lam[:, 3], -m[:, 0], rtol=0, atol=1e-8)


def test_loop_planar_puck_on_the_incline():
    """Planar joint whose plane is the incline (normal z2 = frame 2's z): the body slides in the
    plane with g sin(alpha) down the slope direction, spins freely about the normal, and the normal
    force carries m g cos(alpha)."""
    v0, spin = 0.8, -2.0
    m = ms.Model("puck", gravity=(0.0, 0.0, -G))
    b = m.add_body("b", MASS, INERTIA)
    a2 = rot_y(ALPHA)  # z2 is the incline's normal, x2 points down the slope, y2 horizontal
    m.add_joint(ms.joints.Free("float", m.ground, b, q0=[*ORIGIN, *quat_of(a2)], u0=[0.0, v0, 0.0, 0.0, 0.0, spin]))
    m.add_constraint(ms.constraints.LoopPlanar("plane", b, m.ground, frame2=ms.Frame(position=ORIGIN, rotation=a2)))
    res = ms.simulate(m, 2.0, TIGHT, output_dt=0.01)
    t = res.t
    expected = ORIGIN + (v0 * t)[:, None] * a2[:, 1] + (0.5 * G * np.sin(ALPHA) * t**2)[:, None] * a2[:, 0]
    np.testing.assert_allclose(res["body/b/position"], expected, rtol=0, atol=1e-9)
    rel = np.einsum("ji,njk->nik", a2, matrix_of(res["body/b/orientation"]))
    np.testing.assert_allclose(rel, np.stack([rot_z(spin * tk) for tk in t]), atol=1e-8)
    lam = res["constraint/plane/lambda"]
    assert lam.shape == (len(t), 3)
    np.testing.assert_allclose(lam[:, 0], MASS * G * np.cos(ALPHA), rtol=1e-9)
    mom = spin_moment(spin, spin * t)
    np.testing.assert_allclose(lam[:, 1], mom[:, 1], rtol=0, atol=1e-8)
    np.testing.assert_allclose(lam[:, 2], -mom[:, 0], rtol=0, atol=1e-8)
    assert np.abs(res["constraint/plane/violation"]).max() < 1e-10


def test_loop_universal_closes_a_cardan_shaft():
    """Input shaft turned at constant rate w1 about world z; output shaft on a bearing whose axis
    is tilted by beta in the x-z plane; a Hooke joint at the origin with pins x (input) and y
    (output). Closed form: tan(phi2) = tan(phi1) / cos(beta), and the drive torque is the output
    shaft's power J2 w2 dw2/dt divided by w1, with w2 = w1 cos(beta) / (1 - sin^2(beta) cos^2(phi1))."""
    beta, w1, j2 = 0.5, 2.0, 0.07
    m = ms.Model("cardan", gravity=(0.0, 0.0, 0.0))
    shaft_in = m.add_body("in", 0.5, [0.02, 0.02, 0.01])
    shaft_out = m.add_body("out", 0.4, [0.05, 0.06, j2])
    m.add_joint(ms.joints.Revolute("j_in", m.ground, shaft_in, axis=(0, 0, 1)))
    m.add_joint(ms.joints.Revolute("j_out", m.ground, shaft_out, parent_frame=ms.Frame(cardan=(0.0, beta, 0.0)), axis=(0, 0, 1)))
    m.add_constraint(ms.constraints.Prescribed("motor", "j_in", ms.functions.Ramp(w1)))
    m.add_constraint(ms.constraints.LoopUniversal("hooke", shaft_in, shaft_out))
    # the bearings already hold the joint centre: the universal joint's 3 force rows are redundant
    with pytest.warns(UserWarning, match="redundant"):
        res = ms.simulate(m, 4.0, TIGHT, output_dt=0.01)
    t = res.t
    phi1 = w1 * t
    phi2 = np.unwrap(np.arctan2(np.sin(phi1), np.cos(phi1) * np.cos(beta)))
    np.testing.assert_allclose(res["joint/j_in/q"], phi1, atol=1e-10)
    np.testing.assert_allclose(res["joint/j_out/q"], phi2, rtol=0, atol=1e-9)
    d = 1 - np.sin(beta) ** 2 * np.cos(phi1) ** 2
    w2 = w1 * np.cos(beta) / d
    w2dot = -(w1**2) * np.cos(beta) * np.sin(beta) ** 2 * np.sin(2 * phi1) / d**2
    np.testing.assert_allclose(res["joint/j_out/u"], w2, rtol=1e-9)
    np.testing.assert_allclose(res["constraint/motor/lambda"], j2 * w2 * w2dot / w1, rtol=0, atol=1e-8)
    assert np.abs(res["constraint/hooke/violation"]).max() < 1e-10


@pytest.mark.parametrize("cls", ["LoopPrismatic", "LoopCylindrical", "LoopUniversal", "LoopPlanar"])
def test_new_loop_joints_report_type_rows_and_bad_input(cls):
    kind = getattr(ms.constraints, cls)
    m = ms.Model("m")
    b = m.add_body("b", 1.0, [0.1, 0.1, 0.1])
    m.add_joint(ms.joints.Free("j", m.ground, b))
    m.add_constraint(kind("k", b, m.ground))
    (c,) = m.build().constraints()
    snake = {"LoopPrismatic": "loop_prismatic", "LoopCylindrical": "loop_cylindrical", "LoopUniversal": "loop_universal", "LoopPlanar": "loop_planar"}
    rows = {"LoopPrismatic": 5, "LoopCylindrical": 4, "LoopUniversal": 4, "LoopPlanar": 3}
    assert (c["type"], c["rows"], c["unit"]) == (snake[cls], rows[cls], "N, N m")
    for bad, fragments in [
        (kind("k", "nobody", m.ground), ["'k'", "body1", "nobody"]),
        (kind("k", b, b), ["'k'", "same body"]),
        (kind("k", b, "ground", frame1=ms.Frame(rotation=[[1, 0, 0], [0, 1, 0], [0, 0, 2]])), ["'k'", "frame1", "rotation"]),
        ({"type": snake[cls], "name": "k", "body1": "b", "body2": "ground", "frame2": {"positon": [0, 0, 0]}}, ["constraint 'k'.frame2", "positon"]),
    ]:
        m._constraints = [bad]
        m._invalidate()
        with pytest.raises(ms.ModelError) as e:
            m.build()
        for f in fragments:
            assert f in str(e.value), (f, str(e.value))


# ---- prescribed body motion ----------------------------------------------------------------------

R_CIRCLE, OMEGA, HEIGHT, M_BODY = 0.8, 2.5, 0.3, 1.3


def circle_model(position=None, spin=True):
    m = ms.Model("circle", gravity=(0.0, 0.0, -G))
    b = m.add_body("b", M_BODY, INERTIA)
    m.add_joint(
        ms.joints.Free("float", m.ground, b, q0=[R_CIRCLE, 0.0, HEIGHT, 1.0, 0.0, 0.0, 0.0], u0=[0.0, R_CIRCLE * OMEGA, 0.0, 0.0, 0.0, OMEGA if spin else 0.0])
    )
    if position is None:
        position = (ms.functions.Harmonic(R_CIRCLE, OMEGA, phase=np.pi / 2), ms.functions.Harmonic(R_CIRCLE, OMEGA), HEIGHT)
    orientation = (0.0, 0.0, ms.functions.Ramp(OMEGA)) if spin else None
    m.add_constraint(ms.constraints.PrescribedBody("drive", b, position=position, orientation=orientation))
    return m


def test_prescribed_body_on_a_circle_needs_the_centripetal_force_and_the_gyroscopic_moment():
    """The body frame (at the centre of mass) is driven on a horizontal circle at constant speed
    and turned with it: the drive supplies F = m (a - g) with a the centripetal acceleration, and the
    moment omega x (I omega) that turns the non-principal inertia."""
    res = ms.simulate(circle_model(), 3.0, TIGHT, output_dt=0.01)
    t = res.t
    ph = OMEGA * t
    circle = np.stack([R_CIRCLE * np.cos(ph), R_CIRCLE * np.sin(ph), np.full_like(t, HEIGHT)], -1)
    np.testing.assert_allclose(res["body/b/position"], circle, rtol=0, atol=1e-10)
    lam = res["constraint/drive/lambda"]
    assert lam.shape == (len(t), 6)
    force = M_BODY * np.stack([-(OMEGA**2) * circle[:, 0], -(OMEGA**2) * circle[:, 1], np.full_like(t, G)], -1)
    np.testing.assert_allclose(lam[:, :3], force, rtol=0, atol=1e-8)
    np.testing.assert_allclose(lam[:, 3:], spin_moment(OMEGA, ph), rtol=0, atol=1e-8)
    assert np.abs(res["constraint/drive/violation"]).max() < 1e-10
    assert res.unit("constraint/drive/lambda") == "N, N m"
    # the drive does the work: lambda . b enters the external work (here: the kinetic energy stays
    # constant and the potential too, so the drive's net work vanishes)
    assert np.abs(res["energy/external_work"]).max() < 1e-9


def test_prescribed_point_only_leaves_the_orientation_free():
    """Only the origin driven (3 equations): the body keeps spinning freely at its initial rate
    about the vertical (torque-free about the centre of mass, but not a principal axis: it tumbles),
    while the force is the same."""
    res = ms.simulate(circle_model(spin=False), 1.0, TIGHT, output_dt=0.01)
    lam = res["constraint/drive/lambda"]
    assert lam.shape == (len(res.t), 3)
    ph = OMEGA * res.t
    force = M_BODY * np.stack([-(OMEGA**2) * R_CIRCLE * np.cos(ph), -(OMEGA**2) * R_CIRCLE * np.sin(ph), np.full_like(ph, G)], -1)
    np.testing.assert_allclose(lam, force, rtol=0, atol=1e-8)
    assert res.unit("constraint/drive/lambda") == "N"


def cardan(a, b, c):
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    return rx, ry, rz


def test_prescribed_orientation_by_cardan_angles_newton_euler():
    """All three Cardan angles harmonic, the frame off the centre of mass and fixed in place: the
    recorded orientation is Rx Ry Rz of the angles, and the drive's force and moment equal the
    Newton-Euler loads m (a_C - g) and dH_C/dt + rho x F (rho from the frame origin to the centre of
    mass), with omega and its rate from A-dot A^T and its derivative (product rule, generators)."""
    amp = np.array([0.4, -0.3, 0.6])
    om = np.array([1.3, 2.1, 0.7])
    ph = np.array([0.2, 0.5, -0.4])
    com, p_f = np.array([0.0, 0.05, -0.03]), np.array([0.1, -0.05, 0.2])
    p0 = np.array([0.3, 0.2, 1.0])
    m = ms.Model("wobble", gravity=(0.0, 0.0, -G))
    b = m.add_body("b", M_BODY, INERTIA, com=com)
    m.add_joint(ms.joints.Free("float", m.ground, b))
    angles = [ms.functions.Harmonic(amp[k], om[k], phase=ph[k]) for k in range(3)]
    m.add_constraint(ms.constraints.PrescribedBody("drive", b, position=tuple(p0), orientation=angles, frame=tuple(p_f)))
    res = ms.simulate(m, 2.0, TIGHT, output_dt=0.01)
    # generators: d/dθ R(θ) = R(θ) tilde(axis); np.cross(E, e) has rows e_i x e = tilde(e)
    gens = [np.cross(np.eye(3), e) for e in np.eye(3)]
    for k, tk in enumerate(res.t):
        th = amp * np.sin(om * tk + ph)
        thd = amp * om * np.cos(om * tk + ph)
        thdd = -amp * om**2 * np.sin(om * tk + ph)
        rs = cardan(*th)
        d1 = [r @ g * v for r, g, v in zip(rs, gens, thd)]
        d2 = [r @ g @ g * v**2 + r @ g * a for r, g, v, a in zip(rs, gens, thd, thdd)]
        a_m = rs[0] @ rs[1] @ rs[2]
        a_d = d1[0] @ rs[1] @ rs[2] + rs[0] @ d1[1] @ rs[2] + rs[0] @ rs[1] @ d1[2]
        a_dd = (
            d2[0] @ rs[1] @ rs[2] + rs[0] @ d2[1] @ rs[2] + rs[0] @ rs[1] @ d2[2]
            + 2 * (d1[0] @ d1[1] @ rs[2] + d1[0] @ rs[1] @ d1[2] + rs[0] @ d1[1] @ d1[2])
        )
        wt = a_d @ a_m.T
        wdt = a_dd @ a_m.T + a_d @ a_d.T
        w = np.array([wt[2, 1], wt[0, 2], wt[1, 0]])
        wd = np.array([wdt[2, 1], wdt[0, 2], wdt[1, 0]])
        rho = a_m @ (com - p_f)
        acc = np.cross(wd, rho) + np.cross(w, np.cross(w, rho))
        force = M_BODY * (acc - np.array([0.0, 0.0, -G]))
        i_w = a_m @ INERTIA @ a_m.T
        moment = i_w @ wd + np.cross(w, i_w @ w) + np.cross(rho, force)
        np.testing.assert_allclose(matrix_of(res["body/b/orientation"][k]), a_m, atol=1e-10)
        np.testing.assert_allclose(res["constraint/drive/lambda"][k, :3], force, rtol=0, atol=1e-8)
        np.testing.assert_allclose(res["constraint/drive/lambda"][k, 3:], moment, rtol=0, atol=1e-8)
        np.testing.assert_allclose(res["body/b/angular_velocity"][k], w, rtol=0, atol=1e-8)


def test_prescribed_body_with_python_callables():
    """Time functions as Python callables (derivatives by central differences): the same circle."""
    pos = (lambda t: R_CIRCLE * np.cos(OMEGA * t), lambda t: R_CIRCLE * np.sin(OMEGA * t), HEIGHT)
    res = ms.simulate(circle_model(position=pos), 0.5, TIGHT, output_dt=0.05)
    ph = OMEGA * res.t
    np.testing.assert_allclose(res["constraint/drive/lambda"][:, 0], -M_BODY * OMEGA**2 * R_CIRCLE * np.cos(ph), rtol=0, atol=1e-5)


@pytest.mark.parametrize(
    "make, fragments",
    [
        (lambda b: ms.constraints.PrescribedBody("d", "nobody", position=(0, 0, 0)), ["'d'", "body", "nobody"]),
        (lambda b: ms.constraints.PrescribedBody("d", "ground", position=(0, 0, 0)), ["'d'", "body", "ground"]),
        (lambda b: ms.constraints.PrescribedBody("d", b, position=(0, 0)), ["'d'", "position", "expected 3 time functions", "got 2"]),
        (lambda b: ms.constraints.PrescribedBody("d", b, position=(0, 0, 0), orientation=(0, 0, 0, 0)), ["'d'", "orientation", "got 4"]),
        (lambda b: ms.constraints.PrescribedBody("d", b, position=ms.functions.Ramp(1.0)), ["'d'", "position", "sequence of 3"]),
        (lambda b: ms.constraints.PrescribedBody("d", b, position=(0, 0, "z")), ["'d'", "position[2]"]),
        (lambda b: ms.constraints.PrescribedBody("d", b, position=(0, 0, 0), frame="origin"), ["'d'", "frame"]),
        (lambda b: {"type": "prescribed_body", "name": "d", "body": "b", "position": [{"type": "constant", "value": 0}] * 3, "orientaton": []}, ["constraint 'd'", "orientaton"]),
        (lambda b: {"type": "prescribed_body", "name": "d", "body": "b", "position": [{"type": "harmonic", "amplitude": 1.0}] * 3}, ["constraint 'd'", "omega"]),
    ],
)
def test_bad_prescribed_body_names_the_constraint_and_key(make, fragments):
    m = ms.Model("m")
    b = m.add_body("b", 1.0, [0.1, 0.1, 0.1])
    m.add_joint(ms.joints.Free("j", m.ground, b))
    with pytest.raises(ms.ModelError) as e:
        m.add_constraint(make(b))
        m.build()
    for f in fragments:
        assert f in str(e.value), (f, str(e.value))


def test_prescribed_body_callback_returning_nan_names_the_constraint():
    m = circle_model(position=(lambda t: np.nan if t > 0.1 else R_CIRCLE, 0.0, HEIGHT))
    with pytest.raises(ms.CallbackError, match=r"constraint 'drive'\.position\[0\]"):
        ms.simulate(m, 0.3, ms.RK4(0.01))


# ---- user-given velocity constraints W(q, t)^T u + w(q, t) = 0 ---------------------------------


V_SLED, W_SLED, M_SLED = 1.5, 0.8, 2.0


def lateral_row(t, q):
    """The knife edge of the sledge as W^T: blade along body x through the origin, blocked body y."""
    return np.array([-np.sin(q[2]), np.cos(q[2]), 0.0])


def lateral_row_rate(t, q, u):
    return np.array([-np.cos(q[2]) * u[2] * u[0] - np.sin(q[2]) * u[2] * u[1]])


def sledge(constraint):
    m = ms.Model("sledge", gravity=(0.0, 0.0, 0.0))
    s = m.add_body("sledge", M_SLED, ms.inertia.box(M_SLED, (0.6, 0.2, 0.1)))
    m.add_joint(ms.joints.Planar("plane", m.ground, s, q0=[0.0, 0.0, 0.0], u0=[V_SLED, 0.0, W_SLED]))
    m.add_constraint(constraint)
    return m


@pytest.mark.parametrize("rate, lambda_tol", [(lateral_row_rate, 1e-10), (None, 1e-9)])
def test_user_knife_edge_reproduces_the_built_in_one(rate, lambda_tol):
    """The knife edge written as W reproduces the built-in KnifeEdge run to 1e-10 (the multiplier
    to 1e-9 with the central-difference rate, about 3e-10 off), and both run on the circle of
    radius v/omega."""
    ref = ms.simulate(sledge(ms.constraints.KnifeEdge("blade", "sledge", direction=(0.0, 1.0, 0.0))), 10.0, TIGHT, output_dt=0.01)
    res = ms.simulate(sledge(ms.constraints.Velocity("blade", rows=1, W=lateral_row, Wdot=rate)), 10.0, TIGHT, output_dt=0.01)
    np.testing.assert_allclose(res["joint/plane/q"], ref["joint/plane/q"], rtol=0, atol=1e-10)
    np.testing.assert_allclose(res["constraint/blade/lambda"], ref["constraint/blade/lambda"], rtol=0, atol=lambda_tol)
    t, q, rho = res.t, res["joint/plane/q"], V_SLED / W_SLED
    np.testing.assert_allclose(q[:, 0], rho * np.sin(W_SLED * t), rtol=0, atol=1e-8)
    np.testing.assert_allclose(q[:, 1], rho * (1 - np.cos(W_SLED * t)), rtol=0, atol=1e-8)
    np.testing.assert_allclose(res["constraint/blade/lambda"], M_SLED * V_SLED * W_SLED, rtol=1e-8)
    assert res.unit("constraint/blade/lambda") == ""


@pytest.mark.parametrize("rate", [True, False])
def test_user_velocity_constraint_with_offset_skids_at_the_given_rate(rate):
    """w = -c: the blade skids sideways at speed c. The lateral force through the centre of mass
    leaves the turn rate omega constant, the forward speed grows as v_f = v0 + omega c t (the
    constraint does work), and the multiplier is m omega v_f. Integrating the velocity:
    x = v0 sin(wt)/w + c t sin(wt) + 2c (cos(wt) - 1)/w, y = v0 (1 - cos(wt))/w - c t cos(wt) + 2c sin(wt)/w."""
    c = 0.3
    con = ms.constraints.Velocity(
        "skid", rows=1, W=lateral_row, w=lambda t, q: np.array([-c]), Wdot=lateral_row_rate if rate else None
    )
    m = sledge(con)
    res = ms.simulate(m, 5.0, TIGHT, output_dt=0.01, u0=[V_SLED, c, W_SLED])
    t, q = res.t, res["joint/plane/q"]
    w, v0 = W_SLED, V_SLED
    x = v0 * np.sin(w * t) / w + c * t * np.sin(w * t) + 2 * c * (np.cos(w * t) - 1) / w
    y = v0 * (1 - np.cos(w * t)) / w - c * t * np.cos(w * t) + 2 * c * np.sin(w * t) / w
    np.testing.assert_allclose(q[:, 2], w * t, rtol=0, atol=1e-9)
    np.testing.assert_allclose(q[:, 0], x, rtol=0, atol=1e-8)
    np.testing.assert_allclose(q[:, 1], y, rtol=0, atol=1e-8)
    np.testing.assert_allclose(res["constraint/skid/lambda"], M_SLED * w * (v0 + w * c * t), rtol=1e-8)


def test_user_velocity_rows_in_single_evaluations():
    """G = W^T, b = -w from constraint_jacobian; gamma = -Wdot from constraint_gamma, or by central
    differences to about 1e-9."""
    c = 0.3
    q, u = np.array([0.2, -0.1, 0.7]), np.array([0.5, 0.4, -0.9])
    for rate in (lateral_row_rate, None):
        m = sledge(ms.constraints.Velocity("skid", rows=1, W=lateral_row, w=lambda t, q: [-c * t], Wdot=rate))
        core, cbs = m.engine()
        phi, g, b = ms._core.constraint_jacobian(core, q, 0.4, cbs)
        np.testing.assert_array_equal(phi, [0.0])
        np.testing.assert_allclose(g, [lateral_row(0.4, q)], rtol=0, atol=1e-16)
        np.testing.assert_allclose(b, [c * 0.4], rtol=1e-15)
        gamma = ms._core.constraint_gamma(core, q, u, 0.4, cbs)
        # d/dt (W^T u + w) = lateral_row_rate + dw/dt, with dw/dt = -c (only with the callback
        # absent is w differentiated; Wdot given must include it, here it does not: -Wdot only)
        expected = -lateral_row_rate(0.4, q, u)[0] + (c if rate is None else 0.0)
        assert abs(gamma[0] - expected) < (1e-15 if rate else 1e-9), (gamma, expected)
    assert m.build().constraints()[0]["type"] == "velocity"


def _eval_user_rows(W, w=None, Wdot=None, rows=1):
    m = sledge(ms.constraints.Velocity("skate", rows=rows, W=W, w=w, Wdot=Wdot))
    core, cbs = m.engine()
    q, u = np.array([0.2, -0.1, 0.7]), np.array([0.5, 0.4, -0.9])
    ms._core.constraint_jacobian(core, q, 0.0, cbs)
    return ms._core.constraint_gamma(core, q, u, 0.0, cbs)


@pytest.mark.parametrize(
    "kwargs, fragments",
    [
        (dict(W=lambda t, q: np.zeros((2, 5))), ["constraint 'skate'", "W returned shape (2, 5), expected (1, 3) or (3,)"]),
        (dict(W=lambda t, q: np.zeros((2, 5)), rows=2), ["constraint 'skate'", "W returned shape (2, 5), expected (2, 3)"]),
        (dict(W=lambda t, q: [0.0, np.nan, 1.0]), ["constraint 'skate'", "W returned NaN at [0, 1]"]),
        (dict(W=lambda t, q: [0.0, np.inf, 1.0]), ["constraint 'skate'", "W returned inf at [0, 1]"]),
        (dict(W=lambda t, q: None), ["constraint 'skate'", "W returned None"]),
        (dict(W=lambda t, q: "abc"), ["constraint 'skate'", "W returned a str", "not an array of numbers"]),
        (dict(W=lambda t, q: 1 / 0), ["constraint 'skate'", "W raised", "ZeroDivisionError"]),
        (dict(W=lateral_row, w=lambda t, q: [1.0, 2.0]), ["constraint 'skate'", "w returned shape (2,), expected (1,) or a number"]),
        (dict(W=lateral_row, w=lambda t, q: [np.nan]), ["constraint 'skate'", "w returned NaN at [0]"]),
        (dict(W=lateral_row, Wdot=lambda t, q, u: np.zeros(3)), ["constraint 'skate'", "Wdot returned shape (3,)"]),
        (dict(W=lateral_row, Wdot=lambda t, q: 0.0), ["constraint 'skate'", "Wdot raised", "TypeError"]),
    ],
)
def test_bad_user_velocity_callbacks_name_the_constraint(kwargs, fragments):
    with pytest.raises(ms.CallbackError) as e:
        _eval_user_rows(**kwargs)
    for f in fragments:
        assert f in str(e.value), (f, str(e.value))


@pytest.mark.parametrize(
    "make, fragments",
    [
        (lambda: ms.constraints.Velocity("skate", rows=0, W=lateral_row), ["constraint 'skate'.rows", ">= 1"]),
        (lambda: ms.constraints.Velocity("skate", rows=1.5, W=lateral_row), ["constraint 'skate'.rows", "integer"]),
        (lambda: ms.constraints.Velocity("skate", rows=1, W=[0.0, 1.0, 0.0]), ["constraint 'skate'.W", "callable W(t, q)"]),
        (lambda: ms.constraints.Velocity("skate", rows=1, W=lateral_row, Wdot=3.0), ["constraint 'skate'.Wdot", "callable"]),
        (lambda: {"type": "velocity", "name": "skate", "rows": 0, "W": 0}, ["constraint", "'skate'", "rows", ">= 1"]),
        (lambda: {"type": "velocity", "name": "skate", "rows": 1}, ["constraint 'skate'", "W"]),
    ],
)
def test_bad_user_velocity_constraints_fail_the_build(make, fragments):
    m = ms.Model("m")
    b = m.add_body("b", 1.0, [0.1, 0.1, 0.1])
    m.add_joint(ms.joints.Planar("p", m.ground, b))
    with pytest.raises(ms.ModelError) as e:
        m.add_constraint(make())
        m.build()
    for f in fragments:
        assert f in str(e.value), (f, str(e.value))


def test_velocity_constraints_need_a_python_model_file(tmp_path):
    toml = tmp_path / "sledge.toml"
    toml.write_text(
        'name = "s"\n[[bodies]]\nname = "b"\nmass = 1.0\ninertia = [0.1, 0.1, 0.1]\n'
        '[[joints]]\nname = "p"\ntype = "planar"\nparent = "ground"\nchild = "b"\n'
        '[[constraints]]\ntype = "velocity"\nname = "skate"\nrows = 1\nW = 0\n'
    )
    with pytest.raises(ms.ModelError, match=r"constraints\[0\] 'skate': a velocity constraint needs Python callables"):
        load_model(toml)
    py = tmp_path / "sledge.py"
    py.write_text(
        "import numpy as np\nimport mechsys as ms\n"
        "model = ms.Model('s')\nb = model.add_body('b', 1.0, [0.1, 0.1, 0.1])\n"
        "model.add_joint(ms.joints.Planar('p', model.ground, b))\n"
        "model.add_constraint(ms.constraints.Velocity('skate', rows=1, W=lambda t, q: [-np.sin(q[2]), np.cos(q[2]), 0.0]))\n"
    )
    model, _ = load_model(py)
    core, cbs = model.engine()
    _, g, _ = ms._core.constraint_jacobian(core, np.zeros(3), 0.0, cbs)
    np.testing.assert_array_equal(g, [[0.0, 1.0, 0.0]])
