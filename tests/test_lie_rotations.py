"""Free and spherical joints integrated on the rotation group: the orientation of a torque-free
asymmetric body and of the heavy symmetric top against their closed forms, with the error falling
at each scheme's order, and the quaternion norm staying 1 to round-off without renormalization.

References (written here, independent of the engine):
- torque-free body, I1 < I2 < I3, L^2 > 2 T I2: omega(t) by Jacobi's elliptic functions
  (Landau & Lifshitz, Mechanics, section 37); the orientation from L fixed in space, with the body
  components L_B = (sin th sin psi, sin th cos psi, cos th) |L| and the precession rate
  phi' = |L| (I1 w1^2 + I2 w2^2) / (I1^2 w1^2 + I2^2 w2^2) (Euler z-x-z angles phi, th, psi);
- heavy symmetric top released at rest in precession: u = cos(th) swings between the roots u2 = u0
  and u1 of the energy/momentum cubic, u(t) = u1 + (u2 - u1) cd^2(tau, k); the precession
  phi' = (b - a u) / (1 - u^2) and the spin psi' = w3 - phi' u are integrated by quadrature.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import ellipj, ellipk

import mechsys as ms


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def quat_matrix(q):
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def cumulative_quad(f, ts):
    """∫_0^t f for each t in ts (increasing), piece by piece."""
    out, acc, last = [], 0.0, 0.0
    for t in ts:
        acc += quad(f, last, t, epsabs=1e-14, epsrel=1e-13, limit=200)[0]
        out.append(acc)
        last = t
    return np.array(out)


# ---- torque-free asymmetric body (free joint) ----------------------------------------------

I_BODY = np.array([0.02, 0.035, 0.05])
W0 = np.array([2.0, 0.0, 3.0])  # rad/s, body frame; omega_2 = 0 at t = 0 fixes the elliptic phase
V0 = np.array([0.3, -0.1, 0.2])  # m/s, body frame
T_FREE = 2.0


def free_body_model():
    m = ms.Model("tumbling")
    b = m.add_body("box", mass=1.5, inertia=np.diag(I_BODY))
    m.add_joint(ms.joints.Free("free", parent=m.ground, child=b))
    return m


def free_body_exact(ts):
    i1, i2, i3 = I_BODY
    two_t = float(I_BODY @ W0**2)
    l2 = float(I_BODY**2 @ W0**2)
    assert l2 > two_t * i2  # rotation about the I3 axis: omega_3 keeps its sign
    tau_rate = np.sqrt((i3 - i2) * (l2 - two_t * i1) / (i1 * i2 * i3))
    m = (i2 - i1) * (two_t * i3 - l2) / ((i3 - i2) * (l2 - two_t * i1))
    a1 = np.sqrt((two_t * i3 - l2) / (i1 * (i3 - i1)))
    a2 = np.sqrt((two_t * i3 - l2) / (i2 * (i3 - i2)))
    a3 = np.sqrt((l2 - two_t * i1) / (i3 * (i3 - i1)))
    assert np.isclose(a1, W0[0]) and np.isclose(a3, W0[2])

    def omega(t):
        sn, cn, dn, _ = ellipj(tau_rate * np.asarray(t), m)
        return np.stack([a1 * cn, a2 * sn, a3 * dn], axis=-1)

    big_l = np.sqrt(l2)

    def phi_rate(t):
        w = omega(t)
        return big_l * (i1 * w[0] ** 2 + i2 * w[1] ** 2) / (i1**2 * w[0] ** 2 + i2**2 * w[1] ** 2)

    def angles(w):
        lb = I_BODY * w / big_l
        return np.arccos(lb[2]), np.arctan2(lb[0], lb[1])

    th0, psi0 = angles(W0)
    r_l = (rot_x(th0) @ rot_z(psi0)).T  # A(0) = identity
    phis = cumulative_quad(phi_rate, ts)
    a_ref, w_ref = [], []
    for t, phi in zip(ts, phis):
        w = omega(t)
        th, psi = angles(w)
        a_ref.append(r_l @ rot_z(phi) @ rot_x(th) @ rot_z(psi))
        w_ref.append(w)
    # the centre moves uniformly: r(t) = A(0) v0 t
    r_ref = np.outer(ts, V0)
    return np.array(a_ref), np.array(w_ref), r_ref


@pytest.fixture(scope="module")
def free_reference():
    ts = np.linspace(0.0, T_FREE, 11)
    return ts, free_body_exact(ts)


def free_body_error(integrator, reference):
    ts, (a_ref, w_ref, r_ref) = reference
    res = ms.simulate(free_body_model(), t_end=T_FREE, integrator=integrator, output_dt=0.2,
                      q0={"free": [0, 0, 0, 1, 0, 0, 0]}, u0={"free": [*V0, *W0]})
    assert np.allclose(res.t, ts)
    q = res["joint/free/q"]
    err_a = max(np.linalg.norm(quat_matrix(qk[3:]) - a) for qk, a in zip(q, a_ref))
    err_w = np.max(np.abs(res["joint/free/u"][:, 3:] - w_ref))
    err_r = np.max(np.abs(q[:, :3] - r_ref))
    return max(err_a, err_w, err_r), res


def observed_orders(errors, steps):
    e, h = np.array(errors), np.array(steps)
    return np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])


def test_free_body_closed_form_is_met_tightly(free_reference):
    err, res = free_body_error(ms.DOPRI5(rtol=1e-12, atol=1e-14), free_reference)
    assert err < 1e-9, err
    # the energy and |L| of the closed form hold along the run too
    e = res["energy/kinetic"]
    assert np.ptp(e) / e[0] < 1e-10


@pytest.mark.parametrize("name, make, steps, order, tol", [
    ("rk4", lambda h: ms.RK4(h), [0.02, 0.01, 0.005], 4.0, 0.3),
    # DOPRI5 at a fixed step: first_step = max_step = h under tolerances it always meets
    ("dopri5", lambda h: ms.DOPRI5(rtol=0.5, atol=1e3, first_step=h, max_step=h), [0.05, 0.025, 0.0125], 5.0, 0.4),
    ("radau5", lambda h: ms.Radau5(h, newton_tol=1e-14), [0.05, 0.025, 0.0125], 5.0, 0.5),
    # Moreau-Jean is of order 1 where impacts happen; on smooth motion its steps are the midpoint
    # rule (positions at the half step, velocity-dependent forces at the mean velocity): order 2
    ("moreau_jean", lambda h: ms.MoreauJean(dt=h), [0.004, 0.002, 0.001], 2.0, 0.2),
])
def test_free_body_error_falls_at_the_scheme_order(free_reference, name, make, steps, order, tol):
    errors = [free_body_error(make(h), free_reference)[0] for h in steps]
    p = observed_orders(errors, steps)
    assert np.all(np.abs(p - order) < tol), f"{name}: errors {errors}, observed orders {p}"


def test_dopri5_error_follows_the_tolerance_at_order_five(free_reference):
    """Tolerance sweep: the error falls with rtol, and against the number of steps at about the
    5th power."""
    import json

    errs, steps = [], []
    for rtol in (1e-6, 1e-8, 1e-10):
        e, res = free_body_error(ms.DOPRI5(rtol=rtol, atol=rtol * 1e-2), free_reference)
        errs.append(e)
        steps.append(json.loads(res.attrs["stats"])["steps"])
    assert errs[0] > 20 * errs[1] > 400 * errs[2], errs
    slope = -np.polyfit(np.log(steps), np.log(errs), 1)[0]
    assert 4.0 < slope < 6.5, (steps, errs, slope)


def test_quaternion_norm_stays_one_over_long_runs():
    """2 * 10^5 RK4 steps and 10^5 Moreau-Jean steps: no renormalization, |Q| - 1 at round-off."""
    m = free_body_model()
    for integ, t_end in ((ms.RK4(1e-3), 200.0), (ms.MoreauJean(dt=1e-3), 100.0)):
        res = ms.simulate(m, t_end=t_end, integrator=integ, output_dt=0.5,
                          q0={"free": [0, 0, 0, 1, 0, 0, 0]}, u0={"free": [*V0, *W0]})
        n = np.linalg.norm(res["joint/free/q"][:, 3:], axis=1)
        assert np.max(np.abs(n - 1.0)) < 1e-14, (integ, np.max(np.abs(n - 1.0)))


# ---- heavy symmetric top (spherical joint) --------------------------------------------------

G, MASS, RADIUS, HEIGHT = 9.81, 0.3, 0.04, 0.04
SPIN, TILT, T_TOP = 40.0, np.radians(30.0), 1.0


def top_model():
    m = ms.Model("heavy-top", gravity=(0.0, 0.0, -G))
    top = m.add_body("top", mass=MASS, inertia=ms.inertia.disc(MASS, RADIUS, axis="z"), com=(0.0, 0.0, HEIGHT))
    m.add_joint(ms.joints.Spherical("pivot", parent=m.ground, child=top))
    return m


def top_exact(ts):
    c_ax = 0.5 * MASS * RADIUS**2
    a_tip = 0.25 * MASS * RADIUS**2 + MASS * HEIGHT**2
    a = c_ax * SPIN / a_tip
    beta = 2 * MASS * G * HEIGHT / a_tip
    u0 = np.cos(TILT)
    b = a * u0  # released without precession
    # f(u) = (u0 - u) [beta (1 - u^2) - a^2 (u0 - u)]: roots u0 and those of the bracket
    disc = np.sqrt(a**4 - 4 * beta * (a**2 * u0 - beta))
    u1, u3 = (a**2 - disc) / (2 * beta), (a**2 + disc) / (2 * beta)
    u2 = u0
    assert -1 < u1 < u2 < 1 < u3
    m = (u2 - u1) / (u3 - u1)
    rate = np.sqrt(beta * (u3 - u1)) / 2
    big_k = ellipk(m)

    def u_of(t):
        sn, cn, dn, _ = ellipj(rate * np.asarray(t) + big_k, m)  # sn(tau + K) = cd(tau): u(0) = u2
        return u1 + (u2 - u1) * sn**2

    phi_rate = lambda t: (b - a * u_of(t)) / (1 - u_of(t) ** 2)  # noqa: E731
    phis = cumulative_quad(phi_rate, ts)
    psis = SPIN * ts - cumulative_quad(lambda t: phi_rate(t) * u_of(t), ts)
    frames = np.array([rot_z(p) @ rot_x(np.arccos(u_of(t))) @ rot_z(s) for t, p, s in zip(ts, phis, psis)])
    return frames, (u1, u2, big_k / rate)


@pytest.fixture(scope="module")
def top_reference():
    ts = np.linspace(0.0, T_TOP, 11)
    return ts, top_exact(ts)


def top_error(integrator, reference):
    ts, (a_ref, _) = reference
    res = ms.simulate(top_model(), t_end=T_TOP, integrator=integrator, output_dt=0.1,
                      q0={"pivot": [np.cos(0.5 * TILT), np.sin(0.5 * TILT), 0.0, 0.0]},
                      u0={"pivot": [0.0, 0.0, SPIN]})
    q = res["joint/pivot/q"]
    return max(np.linalg.norm(quat_matrix(qk) - a) for qk, a in zip(q, a_ref)), res


def test_heavy_top_nutation_bounds_and_orientation(top_reference):
    err, _ = top_error(ms.DOPRI5(rtol=1e-12, atol=1e-14), top_reference)
    assert err < 1e-8, err
    # the nutation bounds of the energy and momentum integrals: cos(th) never leaves [u1, u2] and
    # reaches u1 after half a nutation period, K / rate
    _, (_, (u1, u2, t_low)) = top_reference
    res = ms.simulate(top_model(), t_end=t_low, integrator=ms.DOPRI5(rtol=1e-11, atol=1e-13), output_dt=t_low / 200,
                      q0={"pivot": [np.cos(0.5 * TILT), np.sin(0.5 * TILT), 0.0, 0.0]},
                      u0={"pivot": [0.0, 0.0, SPIN]})
    w, x, y, _z = res["joint/pivot/q"].T
    cos_th = 1 - 2 * (x * x + y * y)
    assert cos_th.max() <= u2 + 1e-12 and cos_th.min() >= u1 - 1e-9, (cos_th.min(), u1, cos_th.max(), u2)
    assert abs(cos_th[-1] - u1) < 1e-9, (cos_th[-1], u1)


@pytest.mark.parametrize("name, make, steps, order, tol", [
    ("rk4", lambda h: ms.RK4(h), [0.002, 0.001, 0.0005], 4.0, 0.3),
    ("dopri5", lambda h: ms.DOPRI5(rtol=0.5, atol=1e3, first_step=h, max_step=h), [0.01, 0.005, 0.0025], 5.0, 0.5),
    ("radau5", lambda h: ms.Radau5(h, newton_tol=1e-14), [0.01, 0.005, 0.0025], 5.0, 0.6),
    ("moreau_jean", lambda h: ms.MoreauJean(dt=h), [0.001, 0.0005, 0.00025], 2.0, 0.2),
])
def test_heavy_top_error_falls_at_the_scheme_order(top_reference, name, make, steps, order, tol):
    errors = [top_error(make(h), top_reference)[0] for h in steps]
    p = observed_orders(errors, steps)
    assert np.all(np.abs(p - order) < tol), f"{name}: errors {errors}, observed orders {p}"
