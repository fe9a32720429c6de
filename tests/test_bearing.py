"""Hydrodynamic journal bearings (ms.forces.HydrodynamicBearing, ms.bearings) against references
that do not come from the engine: the closed-form load capacity and attitude angle, an independent
finite-difference solution of the 2-D Reynolds equation, finite differences of the film force, the
published short-bearing coefficients (Friswell et al., Dynamics of Rotating Machines, 2010, sec.
5.5: the closed forms and example 5.5.1), a rotor that settles where the static analysis says, the
linearization of that rotor, and the oil-whirl threshold by Lund's criterion against the
eigenvalues of the linearized multibody model and against the growth of the whirl in a simulation.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spl
from scipy.integrate import quad

import mechsys as ms

B = ms.bearings
PI = np.pi
TIGHT = ms.DOPRI5(rtol=1e-10, atol=1e-14)

# the rotor of the dynamic tests: L/D = 0.3 (short theory), 50 kg on one bearing
R, L, C, ETA, MASS, G = 0.05, 0.03, 1e-4, 0.02, 50.0, 9.81
GEOM = ("short", R, L, C, ETA)


# ---- the law in closed form ----------------------------------------------------------------------


def test_short_bearing_load_capacity_and_attitude_are_the_closed_forms():
    w = 300.0
    eps = np.array([0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.97])
    q = 1 - eps**2
    want = ETA * w * R * L**3 / (4 * C**2) * eps / q**2 * np.sqrt(16 * eps**2 + PI**2 * q)
    np.testing.assert_allclose(B.load_capacity(eps, *GEOM, w), want, rtol=1e-13)
    np.testing.assert_allclose(B.attitude_angle(eps), np.arctan(PI * np.sqrt(q) / (4 * eps)), rtol=1e-13)
    # long bearing (Sommerfeld, half film): W = 6 eta w R^3 L/c^2 eps sqrt(4 eps^2 + pi^2 q)/((2 + eps^2) q)
    want = 6 * ETA * w * R**3 * L / C**2 * eps * np.sqrt(4 * eps**2 + PI**2 * q) / ((2 + eps**2) * q)
    np.testing.assert_allclose(B.load_capacity(eps, "long", R, L, C, ETA, w), want, rtol=1e-13)
    np.testing.assert_allclose(B.attitude_angle(eps, "long"), np.arctan(PI * np.sqrt(q) / (2 * eps)), rtol=1e-13)
    # the steady point solves W(eps) = load, the journal below the centre and ahead by psi
    op = B.static(*GEOM, w, 400.0)
    assert B.load_capacity(op.eps, *GEOM, w) == pytest.approx(400.0, rel=1e-12)
    assert op.position_angle == pytest.approx(-PI / 2 + op.attitude, abs=1e-12)
    np.testing.assert_allclose(op.offset, C * op.eps * np.array([np.sin(op.attitude), -np.cos(op.attitude)]), rtol=1e-12)
    assert op.h_min == pytest.approx(C * (1 - op.eps), rel=1e-14)
    assert op.sommerfeld == pytest.approx(ETA * (w / (2 * PI)) * L * 2 * R / 400.0 * (R / C) ** 2, rel=1e-14)
    # friction torque: eq. 2.212 at the operating eccentricity
    assert op.torque == pytest.approx(ms.forces.journal_bearing_coefficient(R, L, C, ETA, op.eps) * w, rel=1e-12)


@pytest.mark.parametrize("theory", ["short", "long"])
def test_film_forces_are_the_integrated_pressure(theory):
    # independent quadrature: the short-bearing pressure P(theta) integrated over the pi-film; the
    # long bearing's p' (p = 0 at both film ends) integrated twice. The film's half follows the
    # spin: a negative spin mirrors it (s = -1), a whirl faster than half the spin makes omega* < 0
    # with the same half (the wedge term then pushes outwards)
    for eps, ed, ws, spin in [(0.4, 0.0, 150.0, 150.0), (0.6, 20.0, -40.0, -40.0), (0.85, -5.0, 300.0, 300.0),
                              (0.5, 8.0, -60.0, 100.0)]:
        s = 1.0 if spin >= 0 else -1.0
        fr, ft, m = B.film_forces(theory, R, L, C, ETA, eps, ed, ws, spin)
        if theory == "short":
            P = lambda t: ETA * L**3 / (2 * C**2) * (s * ws * eps * np.sin(t) - 2 * ed * np.cos(t)) / (1 + eps * np.cos(t)) ** 3
            gr = R * quad(lambda t: P(t) * np.cos(t), 0, PI, epsabs=0, epsrel=1e-12)[0]
            gt = s * R * quad(lambda t: P(t) * np.sin(t), 0, PI, epsabs=0, epsrel=1e-12)[0]
        else:
            g = lambda t, k: (eps * s * ws * np.cos(t) + 2 * ed * np.sin(t) + k) / (1 + eps * np.cos(t)) ** 3
            k = -quad(lambda t: g(t, 0), 0, PI, epsrel=1e-13)[0] / quad(lambda t: (1 + eps * np.cos(t)) ** -3, 0, PI, epsrel=1e-13)[0]
            p = lambda t: 6 * ETA * R**2 / C**2 * quad(lambda u: g(u, k), 0, t, epsrel=1e-13)[0]
            gr = R * L * quad(lambda t: p(t) * np.cos(t), 0, PI, epsrel=1e-11)[0]
            gt = s * R * L * quad(lambda t: p(t) * np.sin(t), 0, PI, epsrel=1e-11)[0]
        scale = max(abs(gr), abs(gt))
        assert abs(fr - gr) < 1e-9 * scale and abs(ft - gt) < 1e-9 * scale, (theory, eps, ed, ws, spin)
        # Petroff with eccentricity, opposing the spin
        assert m == pytest.approx(-ms.forces.journal_bearing_coefficient(R, L, C, ETA, eps) * spin, rel=1e-12)


# ---- an independent solution of the 2-D Reynolds equation ---------------------------------------


def reynolds(radius, length, eps, omega, eps_dot=0.0, nt=240, nz=41, film="cut"):
    """Finite differences of (1/R^2) d/dth (h^3 dp/dth) + d/dz (h^3 dp/dz) = -6 eta w c eps sin th +
    12 eta c eps' cos th, h = c (1 + eps cos th), p = 0 at z = +-L/2. ``film``: "cut" periodic in
    th, negative pressures set to 0 after solving (half-Sommerfeld); "full" periodic, no cut; "pi"
    th in [0, pi] with p = 0 at both ends. Returns F_r, F_t (conservative 5-point stencil, h^3 at
    the half nodes) and the mid-plane pressure's forces (times L)."""
    periodic = film != "pi"
    if periodic:
        dth = 2 * PI / nt
        th = dth * np.arange(nt)
    else:
        dth = PI / (nt + 1)
        th = dth * np.arange(1, nt + 1)
    dz = length / (nz + 1)
    h3 = lambda t: (C * (1 + eps * np.cos(t))) ** 3
    hp, hm = h3(th + dth / 2) / (radius * dth) ** 2, h3(th - dth / 2) / (radius * dth) ** 2
    T = sp.lil_matrix((nt, nt))
    T.setdiag(-(hp + hm))
    for i in range(nt):
        if i + 1 < nt or periodic:
            T[i, (i + 1) % nt] = hp[i]
        if i > 0 or periodic:
            T[i, i - 1] = hm[i]
    Z = sp.diags([np.ones(nz - 1), -2 * np.ones(nz), np.ones(nz - 1)], [-1, 0, 1]) / dz**2
    A = sp.kron(T.tocsr(), sp.identity(nz)) + sp.kron(sp.diags(h3(th)), Z)
    f = -6 * ETA * omega * C * eps * np.sin(th) + 12 * ETA * C * eps_dot * np.cos(th)
    p = spl.spsolve(A.tocsc(), np.repeat(f, nz)).reshape(nt, nz)
    if film == "cut":
        p = np.maximum(p, 0.0)
    P = p.sum(axis=1) * dz  # trapezoid in z with p = 0 at the ends
    forces = radius * dth * np.array([np.sum(P * np.cos(th)), np.sum(P * np.sin(th))])
    mid = p[:, nz // 2] * length
    return forces, radius * dth * np.array([np.sum(mid * np.cos(th)), np.sum(mid * np.sin(th))])


# measured deviations of the short theory from the 2-D film at L/D = 1/8 (grid 240 x 41; halving
# the steps moves them by < 0.06 percentage points): load 0.85 %, 2.0 %, 6.8 % at eps 0.2, 0.5, 0.8
SHORT_VS_FD = {0.2: 0.012, 0.5: 0.025, 0.8: 0.075}


@pytest.mark.parametrize("eps", sorted(SHORT_VS_FD))
def test_short_theory_against_the_reynolds_equation_at_l_over_d_one_eighth(eps):
    length, w = 2 * R / 8, 200.0
    (fr, ft), _ = reynolds(R, length, eps, w)
    gr, gt, _ = B.film_forces("short", R, length, C, ETA, eps, 0.0, w)
    # the short theory neglects the circumferential flow: it overestimates the load, more so at large eps
    dw = np.hypot(fr, ft) / np.hypot(gr, gt) - 1
    assert -SHORT_VS_FD[eps] < dw < 0, dw
    assert abs(np.arctan2(ft, -fr) - np.arctan2(gt, -gr)) < 0.02


@pytest.mark.parametrize("eps", [0.2, 0.5, 0.8])
def test_long_theory_against_the_reynolds_equation_at_l_over_d_eight(eps):
    length, w = 16 * R, 200.0
    (fr, ft), (mr, mt) = reynolds(R, length, eps, w, nz=164)
    gr, gt, _ = B.film_forces("long", R, length, C, ETA, eps, 0.0, w)
    # away from the ends the film is Sommerfeld's (mid-plane: measured 3e-4 .. 5e-4)
    assert mr / gr == pytest.approx(1, abs=2e-3) and mt / gt == pytest.approx(1, abs=2e-3)
    # the ends leak over about a radius each: the whole bearing carries 7 % (eps 0.8) to 12 %
    # (eps 0.2) less than the infinitely long one
    dw = np.hypot(fr, ft) / np.hypot(gr, gt) - 1
    assert -0.13 < dw < -0.06, dw


def test_squeeze_terms_against_the_reynolds_equation():
    # long bearing over the pi-film (p = 0 at th = 0 and pi, as the theory's film), at mid-plane:
    # pure squeeze and squeeze with rotation (measured: within 2e-4)
    length = 16 * R
    for eps, ed, w in [(0.5, 50.0, 0.0), (0.6, -30.0, 200.0)]:
        _, (mr, mt) = reynolds(R, length, eps, w, eps_dot=ed, nz=164, film="pi")
        gr, gt, _ = B.film_forces("long", R, length, C, ETA, eps, ed, w)
        assert mr / gr == pytest.approx(1, abs=1e-3) and mt / gt == pytest.approx(1, abs=1e-3), (eps, ed, w)
    # short bearing: its squeeze pressure does not vanish at the film's ends, so compare the full
    # (uncut) film, whose pure-squeeze load is twice the pi-film's by symmetry (measured 1.0 %, 2.1 %)
    length = 2 * R / 8
    for eps, tol in [(0.3, 0.015), (0.6, 0.03)]:
        (fr, ft), _ = reynolds(R, length, eps, 0.0, eps_dot=40.0, film="full")
        gr, _, _ = B.film_forces("short", R, length, C, ETA, eps, 40.0, 0.0)
        assert fr / (2 * gr) == pytest.approx(1, abs=tol) and abs(ft) < 1e-9 * abs(fr)


# ---- the eight coefficients -----------------------------------------------------------------------


@pytest.mark.parametrize("theory", ["short", "long"])
def test_coefficients_are_the_finite_differences_of_the_film_force(theory):
    w, load = 400.0, 300.0
    op = B.static(theory, R, L, C, ETA, w, load)
    f0, _ = B.film_load(theory, R, L, C, ETA, op.offset, (0, 0), w)
    np.testing.assert_allclose(f0, [0.0, load], atol=1e-9 * load)  # the film carries the load
    x0 = np.r_[op.offset, 0.0, 0.0]
    for j in range(4):
        h = 1e-6 * C if j < 2 else 1e-4 * C * w
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        fp, _ = B.film_load(theory, R, L, C, ETA, xp[:2], xp[2:], w)
        fm, _ = B.film_load(theory, R, L, C, ETA, xm[:2], xm[2:], w)
        fd = -(fp - fm) / (2 * h)
        exact = op.K[:, j] if j < 2 else op.C[:, j - 2]
        scale = np.abs(op.K).max() if j < 2 else np.abs(op.C).max()
        np.testing.assert_allclose(fd, exact, atol=1e-7 * scale)


def friswell_short(eps):
    """Dimensionless short-bearing coefficients K c/W and C c w/W (Friswell et al. 2010, sec. 5.5;
    x horizontal, y up, load along -y, rotation counter-clockwise), written out from the book."""
    q = 1 - eps**2
    h0 = 1 / (PI**2 * q + 16 * eps**2) ** 1.5
    k = h0 * np.array([
        [4 * (PI**2 * (2 - eps**2) + 16 * eps**2), PI * (PI**2 * q**2 - 16 * eps**4) / (eps * np.sqrt(q))],
        [-PI * (PI**2 * q * (1 + 2 * eps**2) + 32 * eps**2 * (1 + eps**2)) / (eps * np.sqrt(q)),
         4 * (PI**2 * (1 + 2 * eps**2) + 32 * eps**2 * (1 + eps**2) / q)],
    ])
    cxy = -8 * (PI**2 * (1 + 2 * eps**2) - 16 * eps**2)
    c = h0 * np.array([
        [2 * PI * np.sqrt(q) * (PI**2 * (1 + 2 * eps**2) - 16 * eps**2) / eps, cxy],
        [cxy, 2 * PI * (PI**2 * q**2 + 48 * eps**2) / (eps * np.sqrt(q))],
    ])
    return k, c


@pytest.mark.parametrize("load", [20.0, 200.0, 800.0, 3000.0, 2e4])
def test_short_coefficients_are_the_published_closed_forms(load):
    op = B.static(*GEOM, 300.0, load)
    k, c = friswell_short(op.eps)
    np.testing.assert_allclose(op.K_bar, k, rtol=1e-10)
    np.testing.assert_allclose(op.C_bar, c, rtol=1e-10)


def test_friswell_example_5_5_1():
    # D = 100 mm, L = 30 mm, c = 0.1 mm, eta = 0.1 Pa s, 1500 rpm, 525 N: the book's K (MN/m) and C (kN s/m)
    op = B.static("short", 0.05, 0.03, 1e-4, 0.1, 1500 * 2 * PI / 60, 525.0)
    np.testing.assert_allclose(op.K / 1e6, [[12.81, 16.39], [-25.06, 8.815]], rtol=5e-4)
    np.testing.assert_allclose(op.C / 1e3, [[232.9, -81.92], [-81.92, 294.9]], rtol=5e-4)


# ---- the element in a rotor -----------------------------------------------------------------------


def rotor(speed, offset=None, drive="prescribed", polar=0.5, eta=ETA):
    """A rigid rotor (the cylindrical whirl of a symmetric rotor on two bearings, carried here by
    one) on a planar joint in a short bearing on the ground, gravity along -y. The spin is held at
    ``speed`` by a prescribed-motion constraint, or (``drive="motor"``) driven by a constant torque
    equal to the friction torque at the static point, the spin then free."""
    op = B.static("short", R, L, C, eta, speed, MASS * G)
    m = ms.Model("rotor", gravity=(0, -G, 0))
    body = m.add_body("rotor", MASS, [0.4, 0.4, polar])
    xy = op.offset if offset is None else offset
    m.add_joint(ms.joints.Planar("float", m.ground, body, q0=[xy[0], xy[1], 0.0], u0=[0.0, 0.0, speed]))
    m.add_force(ms.forces.HydrodynamicBearing("brg", body, m.ground, radius=R, length=L, clearance=C, viscosity=eta))
    if drive == "prescribed":
        m.add_constraint(ms.constraints.Prescribed("spin", "float", ms.functions.Ramp(speed), index=2))
    else:
        m.add_force(ms.forces.JointForce("motor", "float", [0.0, 0.0, op.torque]))
    return m


def test_rotor_settles_at_the_static_eccentricity_and_attitude():
    speed = 400.0
    op = B.static(*GEOM, speed, MASS * G)
    # released from the centre, the journal sinks, swings out and settles
    res = ms.simulate(rotor(speed, offset=(0.0, 0.0)), t_end=1.0, output_dt=1e-3, integrator=TIGHT)
    eps, att = res["force/brg/eccentricity"], res["force/brg/attitude_angle"]
    assert eps[-1] == pytest.approx(op.eps, abs=1e-6)
    assert att[-1] == pytest.approx(op.attitude, abs=1e-6)
    assert res["force/brg/position_angle"][-1] == pytest.approx(op.position_angle, abs=1e-6)
    np.testing.assert_allclose(res["joint/float/q"][-1, :2], op.offset, atol=1e-6 * C)
    # the film carries the weight and brakes the spin with eq. 2.212 (held by the constraint)
    np.testing.assert_allclose(res["force/brg/force"][-1], [0.0, MASS * G], atol=1e-6 * MASS * G)
    assert res["force/brg/torque"][-1] == pytest.approx(-op.torque, rel=1e-6)
    assert res.unit("force/brg/force") == "N" and res.columns("force/brg/force") == ["x", "y"]
    assert res.unit("force/brg/torque") == "N m" and res.unit("force/brg/eccentricity") == "1"
    assert res.unit("force/brg/attitude_angle") == "rad" and res.unit("force/brg/position_angle") == "rad"
    # power balance: what the film takes out plus the kinetic and potential energy is the work of
    # the spin drive
    balance = res["energy/total"] + res["energy/dissipated"] - res["energy/external_work"]
    assert np.ptp(balance) < 1e-6 * np.abs(res["energy/external_work"]).max()


def test_linearized_rotor_has_the_bearing_coefficients():
    speed = 400.0
    op = B.static(*GEOM, speed, MASS * G)
    lin = ms.linear.linearize(rotor(speed), operating_point=True)
    assert lin.method == "exact+fd-constraints" and lin.M.shape == (2, 2)
    np.testing.assert_allclose(lin.M, MASS * np.eye(2), rtol=1e-12)
    np.testing.assert_allclose(lin.K + lin.N, op.K, rtol=1e-9, atol=1e-9 * np.abs(op.K).max())
    np.testing.assert_allclose(lin.D + lin.G, op.C, rtol=1e-9, atol=1e-9 * np.abs(op.C).max())
    # the free spin adds its own row and column; the x-y block is the same (exact derivatives)
    lin = ms.linear.linearize(rotor(speed, drive="motor"), operating_point=True)
    assert lin.method == "exact"
    np.testing.assert_allclose((lin.K + lin.N)[:2, :2], op.K, rtol=1e-9, atol=1e-9 * np.abs(op.K).max())
    np.testing.assert_allclose((lin.D + lin.G)[:2, :2], op.C, rtol=1e-9, atol=1e-9 * np.abs(op.C).max())


def whirl_rate(speed, **kw) -> float:
    """Largest real part of the oscillating eigenvalues of the linearized rotor (1/s)."""
    lin = ms.linear.linearize(rotor(speed, **kw), operating_point=True)
    n = lin.M.shape[0]
    minv = np.linalg.inv(lin.M)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ (lin.K + lin.N), -minv @ (lin.D + lin.G)]])
    ev = np.linalg.eigvals(a)
    return float(ev[np.abs(ev.imag) > 1e-6].real.max())


def eigenvalue_threshold(**kw) -> float:
    th = B.threshold(*GEOM, mass=MASS).speed
    lo, hi = 0.8 * th, 1.25 * th
    assert whirl_rate(lo, **kw) < 0 < whirl_rate(hi, **kw)
    while hi - lo > 1e-9 * th:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if whirl_rate(mid, **kw) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def test_whirl_threshold_of_the_linearized_rotor_is_lunds():
    th = B.threshold(*GEOM, mass=MASS)
    # oil whirl at about half the speed, at a moderate eccentricity
    assert 0.2 < th.point.eps < 0.3 and 0.5 < th.whirl_ratio < 0.53
    # the spin held: the multibody model is Lund's 2-DOF rotor, the crossing is his threshold
    # (measured 2e-13)
    assert eigenvalue_threshold() == pytest.approx(th.speed, rel=1e-8)
    # the spin free under a constant motor torque: the friction torque's dependence on the offset
    # couples the spin in (measured +2.6e-6 for a polar inertia of 0.5 kg m^2)
    assert eigenvalue_threshold(drive="motor") == pytest.approx(th.speed, rel=1e-4)
    # at the threshold the whirl frequency is Lund's
    lin = ms.linear.linearize(rotor(th.speed), operating_point=True)
    minv = np.linalg.inv(lin.M)
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-minv @ (lin.K + lin.N), -minv @ (lin.D + lin.G)]])
    ev = np.linalg.eigvals(a)
    crossing = ev[np.argmax(ev.real)]
    assert abs(crossing.real) < 1e-5 * abs(crossing.imag)
    assert abs(crossing.imag) == pytest.approx(th.whirl_ratio * th.speed, rel=1e-6)


@pytest.mark.parametrize("factor", [0.9, 1.1])
def test_whirl_grows_in_a_simulation_as_the_linearization_says(factor):
    speed = factor * B.threshold(*GEOM, mass=MASS).speed
    op = B.static(*GEOM, speed, MASS * G)
    sigma = whirl_rate(speed)
    # a small push off the static point; the orbit's size follows exp(sigma t)
    start = op.offset + np.array([1e-3, 0.0]) * C
    t_end = 4.0 / abs(sigma)
    res = ms.simulate(rotor(speed, offset=start), t_end=t_end, output_dt=t_end / 4000, integrator=TIGHT)
    r = np.linalg.norm(res["joint/float/q"][:, :2] - op.offset, axis=1)
    t = res.t
    peaks = [k for k in range(1, len(r) - 1) if r[k - 1] < r[k] >= r[k + 1] and t[k] > 0.25 * t_end]
    rate = np.polyfit(t[peaks], np.log(r[peaks]), 1)[0]
    # measured: within 6e-5 (0.9 x) and 2e-4 (1.1 x) of the eigenvalue's real part
    assert rate == pytest.approx(sigma, rel=2e-3), (rate, sigma)
    assert np.sign(rate) == np.sign(factor - 1)


# ---- input errors --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(clearance=0.06), ["'brg'", "clearance", "smaller than the radius"]),
        (dict(viscosity=-1.0), ["'brg'", "viscosity", "> 0"]),
        (dict(length=float("nan")), ["brg", "length"]),
        (dict(theory="medium"), ["'brg'", "theory", "short", "long"]),
        (dict(shell="nowhere"), ["'brg'", "shell", "unknown body 'nowhere'"]),
        (dict(shell="rotor"), ["'brg'", "journal and shell are the same body"]),
    ],
)
def test_bad_element_input_names_the_element_and_key(kw, words):
    m = ms.Model("bad")
    body = m.add_body("rotor", 1.0, [1, 1, 1])
    m.add_joint(ms.joints.Planar("float", m.ground, body))
    args = dict(name="brg", journal="rotor", shell="ground", radius=R, length=L, clearance=C, viscosity=ETA)
    args.update(kw)
    m.add_force(ms.forces.HydrodynamicBearing(**args))
    with pytest.raises(ms.ModelError) as e:
        ms.simulate(m, t_end=0.01)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_journal_touching_the_shell_stops_the_run_with_the_element_and_time():
    # under a steady load the squeeze film never lets the journal reach the shell (the approach
    # slows down as (1 - eps^2)^(5/2)); it touches when it starts outside the clearance, or when a
    # fixed step too long for the film overshoots
    with pytest.raises(ms.SolverError) as e:
        ms.simulate(rotor(400.0, offset=(0.0, -1.2 * C)), t_end=0.1)
    msg = str(e.value)
    assert "hydrodynamic bearing 'brg'" in msg and "touches the shell at t = 0 s" in msg, msg
    m = rotor(400.0, offset=(0.0, -0.5 * C))
    m.add_force(ms.forces.BodyForce("push", "rotor", force=(0.0, -2e5, 0.0)))
    with pytest.raises(ms.SolverError) as e:
        ms.simulate(m, t_end=0.1, integrator=ms.RK4(dt=1e-3))
    msg = str(e.value)
    assert "hydrodynamic bearing 'brg'" in msg and "touches the shell at t = 0.00" in msg, msg


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: B.static(*GEOM, 100.0, 0.0), ["load", "> 0"]),
        (lambda: B.static(*GEOM, 0.0, 10.0), ["speed", "nonzero"]),
        (lambda: B.static("medium", R, L, C, ETA, 100.0, 10.0), ["theory", "'short' or 'long'"]),
        (lambda: B.static("short", R, L, 0.1, ETA, 100.0, 10.0), ["clearance", "smaller than the radius"]),
        (lambda: B.load_capacity(1.0, *GEOM, 100.0), ["eccentricity ratio", "[0, 1)"]),
        (lambda: B.load_capacity(-0.1, *GEOM, 100.0), ["eccentricity ratio", "[0, 1)"]),
        (lambda: B.attitude_angle(float("nan")), ["eps", "finite"]),
        (lambda: B.film_forces(*GEOM, 0.5, 0.0, float("inf")), ["omega_star", "finite"]),
        (lambda: B.threshold(*GEOM, mass=-1.0), ["mass", "> 0"]),
    ],
)
def test_bad_analysis_input_is_a_settings_error(call, words):
    with pytest.raises(ms.SettingsError) as e:
        call()
    for w in words:
        assert w in str(e.value), str(e.value)


def test_film_load_touching_the_shell_is_a_solver_error():
    with pytest.raises(ms.SolverError, match="touches the shell"):
        B.film_load(*GEOM, (0.0, -1.01 * C), (0.0, 0.0), 100.0)
