"""mechsys models of the steady motions of ``steady_refs``, started exactly in the steady motion.

Every builder takes the same physical parameters as the matching reference in ``steady_refs``
(which supplies the spin rates and the other steady-state data), returns the ``ms.Model`` with
q0/u0 set on its joints, and attaches ``model.steady_info`` (a dict) with

- ``reference``: the :class:`steady_refs.SteadyReference` of the same parameters,
- ``cyclic``: the joint coordinates that grow linearly in the steady motion (positions on the
  plane, heading, wheel/spin angles, precession angle) as ``(joint, index)`` pairs,
- ``constant``: the joint coordinates that stay constant, as ``(joint, index)`` pairs,
- ``spurious_zeros``: extra zero eigenvalues the model has over the reference's minimal state
  (neutral degrees of freedom of massless carriers). 0 for every builder here: the free disc
  carrier, which could otherwise turn about the axle, is levelled by a constraint.

Eigenvalues to expect from a linearization of these models: the reference's ``eigenvalues``
(non-trivial), zeros, and for the turning disc, whose chain measures the centre in the heading
frame (joints xi, eta), also the reference's ``group_eigenvalues`` +-i Omega (a shifted circle,
seen from the turning heading frame). With the free carrier the same pair appears if position
deviations are taken in body axes, zeros if in world axes.

Modelling rule for the linearization about steady motions: the joint velocities are CONSTANT in
the steady motion. Free and Spherical joints have body-frame velocities u = [v_B, omega_B], so a
spinning symmetric body gets its spin from a Revolute joint on a non-spinning carrier. Carrier
bodies get ``CARRIER_MASS`` and an isotropic ``CARRIER_INERTIA``; where they sit and why their
effect on the eigenvalues is below 1e-6 relative is said per builder.

``PARAMS`` holds the parameter sets the tests use (one dict per builder, valid for the reference
of the same name as well).
"""

from __future__ import annotations

import numpy as np

import mechsys as ms

import steady_refs as refs

CARRIER_MASS = 1e-9  # kg
CARRIER_INERTIA = 1e-12  # kg m^2, isotropic
#: isotropic inertia (about the disc centre) of the free disc carrier, INCLUDED in the reference
#: (``carrier_inertia`` of steady_refs.upright_disc / circular_disc): a tiny value would leave the
#: unconstrained mass matrix nearly singular about the axle (the level constraint removes that
#: direction only from the constrained motion) and the simulation noisy at the 1e-8 level
FREE_CARRIER_INERTIA = 2e-3  # kg m^2

G = 9.81

#: parameter sets used by the tests (keyword arguments of builder and reference alike)
PARAMS = {
    "upright_disc": dict(m=1.5, R=0.3, v=3.0),
    "circular_disc": dict(m=1.5, R=0.2, theta=0.3, Omega=2.0),
    "chaplygin_sleigh": dict(m=2.0, I=0.05, a=-0.2, v=1.0),  # blade behind the CM: stable
    "chaplygin_sleigh_unstable": dict(m=2.0, I=0.05, a=0.2, v=1.0),
    "heavy_top": dict(m=0.5, l=0.05, I1=1.65e-3, I3=6e-4, theta=0.5, precession=2.0),
    "conical_pendulum": dict(m=1.0, l=0.5, I_t=0.02, I_a=0.001, alpha=0.6),
}


def _carrier(model: ms.Model, name: str, inertia: float = CARRIER_INERTIA):
    return model.add_body(name, CARRIER_MASS, [inertia] * 3)


def _disc_body(model: ms.Model, m: float, R: float):
    # thin uniform disc, axle = body y: m R^2/2 about y, m R^2/4 about x and z
    return model.add_body("disc", m, ms.inertia.disc(m, R, axis="y"))


def _chain_tail(model, bodies, disc, R, theta, spin_rate):
    J = ms.joints
    model.add_joint(J.Revolute("lean", bodies[-2], bodies[-1], axis=(1, 0, 0), q0=theta, u0=0.0))
    model.add_joint(J.Revolute("spin", bodies[-1], disc, axis=(0, 1, 0), q0=0.0, u0=spin_rate))
    model.add_constraint(ms.constraints.RollingDisc("roll", disc, radius=R, axis=(0, 1, 0)))
    return model


def _disc_chain_world(name, m, R, g, v, spin_rate) -> ms.Model:
    """ground -x, y, z (Prism along the world axes)- -heading (Rev z)- -lean (Rev x)- -spin (Rev y)-
    disc: x and y are cyclic (the dynamics do not depend on them), so straight running at
    constant heading has constant joint velocities."""
    model = ms.Model(name, gravity=(0.0, 0.0, -g))
    bodies = [_carrier(model, n) for n in ("c_x", "c_y", "c_z", "c_heading", "c_lean")]
    disc = _disc_body(model, m, R)
    J = ms.joints
    model.add_joint(J.Prismatic("x", model.ground, bodies[0], axis=(1, 0, 0), q0=0.0, u0=v))
    model.add_joint(J.Prismatic("y", bodies[0], bodies[1], axis=(0, 1, 0), q0=0.0, u0=0.0))
    model.add_joint(J.Prismatic("z", bodies[1], bodies[2], axis=(0, 0, 1), q0=R, u0=0.0))
    model.add_joint(J.Revolute("heading", bodies[2], bodies[3], axis=(0, 0, 1), q0=0.0, u0=0.0))
    return _chain_tail(model, bodies[3:], disc, R, 0.0, spin_rate)


def _disc_chain_turning(name, m, R, g, heading_rate, eta, theta, spin_rate) -> ms.Model:
    """ground -heading (Rev z at the origin)- -xi (Prism x)- -eta (Prism y)- -height (Prism z)-
    -lean (Rev x)- -spin (Rev y)- disc. The centre (xi, eta) is measured in the heading frame
    (x = direction of travel t, y = l = e_z x t): the dynamics do not depend on the heading, and
    a steady circle about the world z axis has constant xi, eta. (Not for straight running: xi
    would grow, and the dynamics depend on xi.)"""
    model = ms.Model(name, gravity=(0.0, 0.0, -g))
    bodies = [_carrier(model, n) for n in ("c_heading", "c_xi", "c_eta", "c_height", "c_lean")]
    disc = _disc_body(model, m, R)
    J = ms.joints
    model.add_joint(J.Revolute("heading", model.ground, bodies[0], axis=(0, 0, 1), q0=0.0, u0=heading_rate))
    model.add_joint(J.Prismatic("xi", bodies[0], bodies[1], axis=(1, 0, 0), q0=0.0, u0=0.0))
    model.add_joint(J.Prismatic("eta", bodies[1], bodies[2], axis=(0, 1, 0), q0=eta, u0=0.0))
    model.add_joint(J.Prismatic("height", bodies[2], bodies[3], axis=(0, 0, 1), q0=R * np.cos(theta), u0=0.0))
    return _chain_tail(model, bodies[3:], disc, R, theta, spin_rate)


def _disc_free(name, m, R, g, Omega, contact, theta, spin_rate) -> ms.Model:
    """Carrier on a Free joint with its origin at the contact point and body axes (t, l', k) =
    (travel direction, axle, contact -> centre); the disc on a Revolute about the carrier's y
    through the centre (0, 0, R). A ``PointOnPlane`` "level" keeps the carrier's point (1, 0, 0)
    on the ground plane, i.e. t horizontal: without it the carrier could turn about the axle
    (a neutral degree of freedom of a massless body). Steady: the carrier frame moves with the
    contact point, v_B = (R phi', 0, 0), omega_B = Omega (0, sin th, cos th), both constant.
    The carrier (centre of mass at the disc centre) has the isotropic inertia
    FREE_CARRIER_INERTIA, which the reference includes."""
    model = ms.Model(name, gravity=(0.0, 0.0, -g))
    carrier = model.add_body("carrier", CARRIER_MASS, [FREE_CARRIER_INERTIA] * 3, com=(0.0, 0.0, R))
    disc = _disc_body(model, m, R)
    rot = ms.kinematics.rot_x(theta)  # heading 0: t = e_x, l = e_y
    u_carrier = [R * spin_rate, 0.0, 0.0, 0.0, Omega * np.sin(theta), Omega * np.cos(theta)]
    model.add_joint(ms.joints.Free("float", model.ground, carrier,
                                   q0=[*contact, *ms.kinematics.matrix_to_quat(rot)], u0=u_carrier))
    model.add_joint(ms.joints.Revolute("spin", carrier, disc, axis=(0, 1, 0), parent_frame=(0.0, 0.0, R),
                                       q0=0.0, u0=spin_rate))
    model.add_constraint(ms.constraints.PointOnPlane("level", carrier, model.ground, normal=(0, 0, 1),
                                                     point1=(1.0, 0.0, 0.0)))
    model.add_constraint(ms.constraints.RollingDisc("roll", disc, radius=R, axis=(0, 1, 0)))
    return model


def upright_disc_model(m: float, R: float, v: float, g: float = G, carrier: str = "chain") -> ms.Model:
    """Thin uniform disc (mass m, radius R; inertia m R^2/2 about the axle = disc body y, m R^2/4
    about diameters) rolling upright and straight along +x at speed v (steady spin v/R about the
    axle +y, from ``steady_refs.upright_disc``), gravity -g e_z, ``RollingDisc`` constraint
    (disc body y is the axle, centre at the body origin).

    ``carrier="chain"`` (default): joints x, y, z (Prism along the world axes, the centre),
    heading (Rev z), lean (Rev x), spin (Rev y); u0: x' = v, spin' = v / R, the rest 0.
    Cyclic: x (grows as v t), spin (v t / R); constant: y, z (= R), heading, lean.
    Five carrier bodies (1e-9 kg, 1e-12 kg m^2) at the centre: relative effect ~1e-9.

    ``carrier="free"``: a carrier body on the Free joint "float" with its origin at the contact
    point and axes (travel direction, axle, contact -> centre), u0 = [v, 0, 0, 0, 0, 0]; the
    disc on Revolute "spin" about the carrier's y through (0, 0, R); a ``PointOnPlane``
    constraint "level" holds the carrier's point (1, 0, 0) on the ground (travel direction
    horizontal; otherwise the carrier could turn freely about the axle -- a neutral degree of
    freedom, numerically drifting when the carrier is light). The carrier has the isotropic inertia
    ``FREE_CARRIER_INERTIA`` (2e-3 kg m^2) about the disc centre, and the reference
    (``model.steady_info["reference"]``) includes it (``carrier_inertia``), so the eigenvalues
    differ from the bare disc's. Cyclic: the x position and spin; constant: y, z, orientation."""
    if carrier not in ("chain", "free"):
        raise ValueError(f"carrier: 'chain' or 'free', got {carrier!r}")
    ref = refs.upright_disc(m, R, v, g, carrier_inertia=FREE_CARRIER_INERTIA if carrier == "free" else 0.0)
    spin = ref.steady["spin_rate"]
    if carrier == "chain":
        model = _disc_chain_world("upright-disc", m, R, g, v, spin)
        cyclic = [("x", 0), ("spin", 0)]
        constant = [("y", 0), ("z", 0), ("heading", 0), ("lean", 0)]
    else:
        model = _disc_free("upright-disc-free", m, R, g, 0.0, (0.0, 0.0, 0.0), 0.0, spin)
        cyclic = [("float", 0), ("spin", 0)]
        constant = [("float", k) for k in range(1, 7)]
    model.steady_info = dict(reference=ref, cyclic=cyclic, constant=constant, spurious_zeros=0)
    return model


def circular_disc_model(m: float, R: float, theta: float, Omega: float, g: float = G,
                        carrier: str = "chain") -> ms.Model:
    """The thin disc of :func:`upright_disc_model` in steady circular rolling at lean ``theta``
    and heading rate ``Omega`` (conventions and spin from ``steady_refs.circular_disc``); the
    centre's circle is centred on the world z axis, the heading starts at 0 (t = +x; the centre
    moves at R n t, i.e. along -x when n < 0, as for the parameters in ``PARAMS``).

    ``carrier="chain"``: joints heading (Rev z at the origin), xi, eta, height (Prism x, y, z in
    the heading frame), lean (Rev x), spin (Rev y); heading' = Omega, xi = 0,
    eta = -radius = -R n / Omega (the centre in the heading frame), height = R cos(theta),
    lean = theta, spin' = phi'; all joint velocities constant. Cyclic: heading, spin;
    constant: xi, eta, height, lean. Carrier effect ~1e-9.
    A linearization in these coordinates has, besides the reference's non-trivial pair, the
    group pair +-i Omega (the circle's centre, seen in the heading frame) and 4 zeros.

    ``carrier="free"``: Free joint "float" (carrier at the contact point, axes t, l', k, as in
    :func:`upright_disc_model`), u0 = [R phi', 0, 0, 0, Omega sin(theta), Omega cos(theta)]
    (the contact point moves at R phi' along t), disc on Revolute "spin" at phi'; the carrier's
    inertia is included in the reference (it leaves the steady spin unchanged -- an isotropic
    body turning steadily needs no moment -- but changes the eigenvalues). Cyclic: the
    carrier pose (it runs round the circle); constant: its height z = 0 (and u). A
    linearization with body-frame velocities again shows the group pair +-i Omega."""
    if carrier not in ("chain", "free"):
        raise ValueError(f"carrier: 'chain' or 'free', got {carrier!r}")
    ref = refs.circular_disc(m, R, theta, Omega, g,
                             carrier_inertia=FREE_CARRIER_INERTIA if carrier == "free" else 0.0)
    st = ref.steady
    radius = st["radius"]
    if carrier == "chain":
        model = _disc_chain_turning("circular-disc", m, R, g, Omega, -radius, theta, st["spin_rate"])
        cyclic = [("heading", 0), ("spin", 0)]
        constant = [("xi", 0), ("eta", 0), ("height", 0), ("lean", 0)]
    else:
        contact = (0.0, -radius + R * np.sin(theta), 0.0)
        model = _disc_free("circular-disc-free", m, R, g, Omega, contact, theta, st["spin_rate"])
        cyclic = [("float", k) for k in (0, 1, 3, 4, 5, 6)] + [("spin", 0)]
        constant = [("float", 2)]
    model.steady_info = dict(reference=ref, cyclic=cyclic, constant=constant, spurious_zeros=0)
    return model


def sleigh_model(m: float, I: float, a: float, v: float, joint: str = "planar") -> ms.Model:
    """Chaplygin sleigh: body (mass m, inertia I about the vertical through its centre of mass,
    [I/2, I/2, I] in body axes; centre of mass at the body origin), ``KnifeEdge`` at body point
    (a, 0, 0) with direction body y, moving straight along +x at speed v. Gravity -g e_z (taken
    by the plane).

    ``joint="planar"``: ``Planar`` joint "plane" (x, y, heading; world-frame rates), q0 = 0,
    u0 = [v, 0, 0]. Cyclic: x; constant: y, heading.
    ``joint="free"``: ``Free`` joint "float" with u0 = [v, 0, 0, 0, 0, 0] and a ``LoopPlanar``
    keeping the body frame's x-y plane on the ground's. Cyclic: x; constant: the rest."""
    ref = refs.chaplygin_sleigh(m, I, a, v)
    model = ms.Model("sleigh", gravity=(0.0, 0.0, -G))
    body = model.add_body("sleigh", m, [I / 2, I / 2, I])
    if joint == "planar":
        model.add_joint(ms.joints.Planar("plane", model.ground, body, q0=[0.0, 0.0, 0.0], u0=[v, 0.0, 0.0]))
        cyclic, constant = [("plane", 0)], [("plane", 1), ("plane", 2)]
    elif joint == "free":
        model.add_joint(ms.joints.Free("float", model.ground, body, q0=[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
                                       u0=[v, 0.0, 0.0, 0.0, 0.0, 0.0]))
        model.add_constraint(ms.constraints.LoopPlanar("plane", body, model.ground))
        cyclic, constant = [("float", 0)], [("float", k) for k in range(1, 7)]
    else:
        raise ValueError(f"joint: 'planar' or 'free', got {joint!r}")
    model.add_constraint(ms.constraints.KnifeEdge("blade", body, direction=(0, 1, 0), point=(a, 0, 0)))
    model.steady_info = dict(reference=ref, cyclic=cyclic, constant=constant, spurious_zeros=0)
    return model


def heavy_top_model(m: float, l: float, I1: float, I3: float, theta: float, precession: float,
                    g: float = G) -> ms.Model:
    """Heavy symmetric top, Euler angles z-x-z as three Revolute joints: "precession" (Rev z,
    ground -> carrier), "nutation" (Rev x, carrier -> carrier), "spin" (Rev z, carrier -> top).
    The top: centre of mass (0, 0, l), inertia about it diag(I1 - m l^2, I1 - m l^2, I3) (``I1``
    is about the fixed point, as in ``steady_refs.heavy_top``). q0 = (0, theta, 0),
    u0 = (precession, 0, phi') with phi' from the steady condition. Cyclic: precession, spin;
    constant: nutation. Both carriers sit at the fixed point (1e-12 kg m^2 vs I1: ~1e-9)."""
    ref = refs.heavy_top(m, l, I1, I3, theta, precession, g)
    model = ms.Model("heavy-top-euler", gravity=(0.0, 0.0, -g))
    c1, c2 = _carrier(model, "c_precession"), _carrier(model, "c_nutation")
    i1c = I1 - m * l * l
    top = model.add_body("top", m, [i1c, i1c, I3], com=(0.0, 0.0, l))
    J = ms.joints
    model.add_joint(J.Revolute("precession", model.ground, c1, axis=(0, 0, 1), q0=0.0, u0=precession))
    model.add_joint(J.Revolute("nutation", c1, c2, axis=(1, 0, 0), q0=theta, u0=0.0))
    model.add_joint(J.Revolute("spin", c2, top, axis=(0, 0, 1), q0=0.0, u0=ref.steady["spin_rate"]))
    model.steady_info = dict(reference=ref, cyclic=[("precession", 0), ("spin", 0)], constant=[("nutation", 0)],
                             spurious_zeros=0)
    return model


def conical_pendulum_model(m: float, l: float, I_t: float, I_a: float, alpha: float, g: float = G,
                           joint: str = "spherical", direction: float = 1.0) -> ms.Model:
    """Conical pendulum: a body hanging from a pivot at the world origin, centre of mass at
    distance l along its axis (body -z), inertia about the centre of mass diag(I_t, I_t, I_a),
    turning about the vertical at the steady rate Omega (``steady_refs.conical_pendulum``) with
    its axis at cone angle alpha from the downward vertical; started tilted about world x
    (centre of mass at l (0, sin alpha, -cos alpha)), omega_B = Omega (0, sin alpha, cos alpha).

    ``joint="spherical"``: ``Spherical`` joint "pivot" at the origin, body origin at the pivot,
    centre of mass (0, 0, -l). u0 = omega_B (constant); the quaternion turns (cyclic: the
    rotation about the vertical), the axis' height -cos(alpha) stays constant.
    ``joint="free"``: ``Free`` joint "float", body origin at the centre of mass, q0 = [centre of
    mass, quaternion], u0 = [omega_B x (0, 0, -l), omega_B], and a ``Point`` constraint "pin"
    holding body point (0, 0, l) at the world origin. Cyclic: the pose turns about the vertical;
    constant: u and the centre of mass height."""
    ref = refs.conical_pendulum(m, l, I_t, I_a, alpha, g, direction=direction)
    w_b = ref.steady["omega_body"]
    quat = [np.cos(alpha / 2), np.sin(alpha / 2), 0.0, 0.0]
    model = ms.Model(f"conical-pendulum-{joint}", gravity=(0.0, 0.0, -g))
    inertia = [I_t, I_t, I_a]
    if joint == "spherical":
        body = model.add_body("bob", m, inertia, com=(0.0, 0.0, -l))
        model.add_joint(ms.joints.Spherical("pivot", model.ground, body, q0=quat, u0=w_b))
        cyclic, constant = [("pivot", k) for k in range(4)], []
    elif joint == "free":
        body = model.add_body("bob", m, inertia)
        com = l * np.array([0.0, np.sin(alpha), -np.cos(alpha)])
        v_b = np.cross(w_b, [0.0, 0.0, -l])
        model.add_joint(ms.joints.Free("float", model.ground, body, q0=[*com, *quat], u0=[*v_b, *w_b]))
        model.add_constraint(ms.constraints.Point("pin", body, model.ground, point1=(0.0, 0.0, l)))
        cyclic, constant = [("float", k) for k in (0, 1, 3, 4, 5, 6)], [("float", 2)]
    else:
        raise ValueError(f"joint: 'spherical' or 'free', got {joint!r}")
    model.steady_info = dict(reference=ref, cyclic=cyclic, constant=constant, spurious_zeros=0)
    return model


BUILDERS = {
    "upright_disc": upright_disc_model,
    "circular_disc": circular_disc_model,
    "chaplygin_sleigh": sleigh_model,
    "heavy_top": heavy_top_model,
    "conical_pendulum": conical_pendulum_model,
}
