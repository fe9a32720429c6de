"""Independent reference results for linearizations about STEADY MOTIONS (relative equilibria).

Nothing here imports mechsys: every case is derived below with SymPy from first principles
(Newton-Euler or Lagrange, in coordinates chosen here), linearized symbolically, and evaluated
with numpy. The symbolic work is cached (``functools.lru_cache``), so after the first call each
reference costs a few microseconds.

Every reference function returns a :class:`SteadyReference`:

- ``eigenvalues``: the NON-TRIVIAL eigenvalues of the linearized motion (those of the reduced
  dynamics that do not vanish identically), sorted by imaginary part.
- ``group_eigenvalues``: eigenvalues contributed by the symmetry directions when positions are
  measured in a frame moving with the steady motion (heading frame / body frame). They are
  +-i Omega for the translations of a body turning at rate Omega in the plane (circular rolling),
  and absent otherwise (cyclic coordinates give zeros).
- ``n_zero``: the number of zero eigenvalues of the linearization in a MINIMAL state
  (independent coordinates + independent velocities; cyclic coordinates included).
- ``all_eigenvalues``: ``eigenvalues``, ``group_eigenvalues`` and ``n_zero`` zeros together,
  i.e. the full spectrum of the minimal linearization (length 2 x DOF of the configuration for
  holonomic systems; configuration dimension + independent velocities for non-holonomic ones).
- ``steady``: the data needed to start the steady motion (spin rates, speeds, radii, ...).

Linearizations of the same motion in other (time-invariant, or co-moving) coordinates give the
same non-zero eigenvalues; a model with extra neutral degrees of freedom (e.g. a massless
carrier free to turn about an axle) has extra zeros.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

__all__ = [
    "SteadyReference",
    "upright_disc",
    "upright_disc_critical_speed",
    "circular_disc",
    "disc_steady_spin",
    "chaplygin_sleigh",
    "heavy_top",
    "heavy_top_spin",
    "conical_pendulum",
    "conical_pendulum_rate",
    "nontrivial",
]


@dataclass(frozen=True)
class SteadyReference:
    """Eigenvalues of a linearized steady motion and the data that set the motion up."""

    eigenvalues: np.ndarray
    n_zero: int
    group_eigenvalues: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    steady: dict = field(default_factory=dict)

    @property
    def all_eigenvalues(self) -> np.ndarray:
        ev = np.concatenate([self.eigenvalues, self.group_eigenvalues, np.zeros(self.n_zero, complex)])
        return _sorted(ev)

    def __array__(self, dtype=None, copy=None):  # np.asarray(ref) -> the non-trivial eigenvalues
        return np.asarray(self.eigenvalues, dtype=dtype)


def _sorted(ev) -> np.ndarray:
    ev = np.asarray(ev, dtype=complex)
    return ev[np.lexsort((ev.real, ev.imag))]


def _nonzero_pair(jac: np.ndarray, n_zero: int) -> np.ndarray:
    """The two eigenvalues of ``jac`` that are not identically zero, for a matrix whose
    characteristic polynomial is lambda^(n - 2) (lambda^2 - c1 lambda + c2) (n_zero = n - 2).

    c1 = trace, c2 = second elementary symmetric function of the eigenvalues (sum of the principal
    2x2 minors) -- no thresholding of small eigenvalues is needed. The remaining coefficients are
    checked to vanish (to round-off)."""
    n = jac.shape[0]
    assert n_zero == n - 2
    c1 = np.trace(jac)
    c2 = 0.5 * (c1**2 - np.trace(jac @ jac))
    coeffs = np.poly(jac)  # 1, -c1, c2, -c3, ...
    scale = np.max(np.abs(jac)) + 1e-300
    for k in range(3, n + 1):
        if abs(coeffs[k]) > 1e-8 * scale**k:
            raise AssertionError(f"characteristic coefficient {k} = {coeffs[k]:.3e} is not zero")
    disc = np.sqrt(complex(c1 * c1 - 4 * c2))
    return _sorted([(c1 + disc) / 2, (c1 - disc) / 2])


def nontrivial(ev, rel: float = 1e-7) -> np.ndarray:
    """Helper for comparisons: the eigenvalues of ``ev`` whose modulus exceeds ``rel`` times the
    largest modulus, sorted by imaginary part."""
    ev = np.asarray(ev, dtype=complex)
    big = np.abs(ev).max() if ev.size else 0.0
    return _sorted(ev[np.abs(ev) > rel * big])


# =============================================================================================
# (a), (b) rolling disc: Kane's method in the non-spinning disc frame
# =============================================================================================
#
# Coordinates: heading psi about the vertical e_z, lean theta about the horizontal forward
# direction t = (cos psi, sin psi, 0), spin phi about the axle. Frames:
#   l  = e_z x t                    horizontal, to the left of t
#   l' = cos th l + sin th e_z      the axle (disc normal)              (t, l, e_z) turned by th
#   k  = cos th e_z - sin th l      contact point -> centre, unit        about t
# The carrier frame (t, l', k) turns with omega_c = psi' e_z + th' t; the disc with
# omega = omega_c + phi' l'. In carrier components e_z = (0, sin th, cos th) and
#   omega = (th', psi' sin th + phi', psi' cos th).
# Rolling without slipping: the disc's material point at the contact P = C - R k is at rest,
#   v_C = omega x (R k).
# Kane's equations (d'Alembert along the independent speeds u = th', psi', phi'; the contact
# force does no work since the contact material point is at rest):
#   sum over bodies of  (m a_C + m g e_z) . dv_C/du + dH_C/dt . domega/du = 0,
#   H_C = diag(I_d, I_a, I_d) omega  (about the centre),
# plus, optionally, a non-spinning carrier of isotropic inertia J_c turning with omega_c
# (term J_c omega_c' . domega_c/du; the reactions keeping its travel axis horizontal do no work).
# For J_c = 0 this is the same as Newton-Euler about the centre with the contact force
# eliminated: dH_C/dt + R k x m (a_C + g e_z) = 0. Time derivatives of carrier components by
# d/dt v = dv/dt|_carrier + omega_c x v.
# Everything is invariant under psi and phi (symmetry), so the reduced state is
# x = (th, th', psi', phi'), with 2 integrals (a 2-parameter family of steady motions: lean and
# precession rate), i.e. 2 zero eigenvalues of the reduced Jacobian; x, y (contact position),
# psi and phi add 4 more dimensions to the minimal state (5 coordinates + 3 velocities = 8).
#
# Spin component along the axle: n = omega . l' = psi' sin th + phi'. Centre velocity
# v_C = R n t (+ R th' ...); at a steady motion the centre runs on a circle of radius |R n/Omega|
# about the point C + (R n / Omega) l.


@functools.lru_cache(maxsize=None)
def _disc_system():
    t = sp.Symbol("t")
    th, ps, ph = (sp.Function(name)(t) for name in ("theta", "psi", "phi"))
    m, R, g, Ia, Id = sp.symbols("m R g I_a I_d", positive=True)
    Jc = sp.Symbol("J_c", nonnegative=True)
    thd, psd, phd = (f.diff(t) for f in (th, ps, ph))
    wc = sp.Matrix([thd, psd * sp.sin(th), psd * sp.cos(th)])
    w = wc + sp.Matrix([0, phd, 0])
    k = sp.Matrix([0, 0, 1])
    ez = sp.Matrix([0, sp.sin(th), sp.cos(th)])

    def ddt(v):
        return v.diff(t) + wc.cross(v)

    v_c = w.cross(R * k)
    a_c = ddt(v_c)
    h_c = sp.diag(Id, Ia, Id) * w
    # Kane: generalized inertia + active forces along the independent speeds (th', psi', phi');
    # the contact force does no work (the contact material point is at rest) and neither do the
    # reactions that hold a carrier's travel direction horizontal
    speeds = (thd, psd, phd)
    eqs = []
    for u in speeds:
        dv = v_c.diff(u)
        dw = w.diff(u)
        dwc = wc.diff(u)
        eqs.append((m * (a_c + g * ez)).dot(dv) + ddt(h_c).dot(dw) + (Jc * ddt(wc)).dot(dwc))
    eqs = sp.Matrix(eqs)

    # plain symbols for the state and the accelerations
    x_th, x_thd, x_psd, x_phd = sp.symbols("th thd psd phd")
    a_th, a_ps, a_ph = sp.symbols("thdd psdd phdd")
    subs = {
        th.diff(t, 2): a_th, ps.diff(t, 2): a_ps, ph.diff(t, 2): a_ph,
    }
    eqs = eqs.subs(subs)
    eqs = eqs.subs({thd: x_thd, psd: x_psd, phd: x_phd}).subs(th, x_th)
    A, b = sp.linear_eq_to_matrix(list(eqs), [a_th, a_ps, a_ph])
    acc = sp.simplify(A.LUsolve(b))
    state = sp.Matrix([x_th, x_thd, x_psd, x_phd])
    f = sp.Matrix([x_thd, acc[0], acc[1], acc[2]])
    jac = f.jacobian(state)
    params = (m, R, g, Ia, Id, Jc)
    # steady condition: th'' = 0 at th' = 0, psi' = Omega -> phi' (linear in phi')
    Om = sp.Symbol("Omega")
    cond = sp.simplify(acc[0].subs({x_thd: 0, x_psd: Om}))
    spin = sp.solve(sp.Eq(cond, 0), x_phd)
    assert len(spin) == 1, spin
    spin = sp.simplify(spin[0])
    # the other two accelerations must vanish there too
    for other in (acc[1], acc[2]):
        assert sp.simplify(other.subs({x_thd: 0, x_psd: Om, x_phd: spin})) == 0
    # upright straight rolling: reduced Jacobian at (0, 0, 0, v/R); its characteristic polynomial is
    # lambda^2 (lambda^2 - c(v)): the lean mode is stable where c < 0
    v = sp.Symbol("v", positive=True)
    j_up = jac.subs({x_th: 0, x_thd: 0, x_psd: 0, x_phd: v / R, Jc: 0})
    lam = sp.Symbol("lambda")
    char_up = sp.factor(sp.simplify((lam * sp.eye(4) - j_up).det()))
    return {
        "f": sp.lambdify((state, params), f, "numpy"),
        "jac": sp.lambdify((state, params), jac, "numpy"),
        "spin": sp.lambdify((x_th, Om, params), spin, "numpy"),
        "spin_expr": spin,
        "char_upright": char_up,
        "symbols": dict(theta=x_th, Omega=Om, v=v, lam=lam, m=m, R=R, g=g, I_a=Ia, I_d=Id, J_c=Jc),
    }


def _disc_inertia(m, R, I_a, I_d):
    return (0.5 * m * R * R if I_a is None else I_a, 0.25 * m * R * R if I_d is None else I_d)


def upright_disc(m: float, R: float, v: float, g: float = 9.81, I_a: float | None = None,
                 I_d: float | None = None, carrier_inertia: float = 0.0) -> SteadyReference:
    """Disc of mass ``m``, radius ``R`` rolling without slipping, upright and straight at speed
    ``v`` on the horizontal plane (gravity ``g`` down). Inertia about the centre: ``I_a`` about
    the axle, ``I_d`` about a diameter (default the thin uniform disc, m R^2/2 and m R^2/4).
    ``carrier_inertia`` J_c: an optional non-spinning carrier rigidly following the disc's
    frame (t, l', k) -- angular velocity psi' e_z + theta' t -- with isotropic inertia J_c about
    the centre (its mass is counted in m); 0 for the bare disc.

    Steady motion: lean 0, heading rate 0, spin rate phi' = v / R (about the axle l' = e_z x t,
    t the direction of travel), centre at height R.

    Returns the NON-ZERO eigenvalue pair of the lean/heading dynamics, +-sqrt(c) with
    c = (m g R - (I_a + m R^2) I_a (v/R)^2 / I_d) / (I_d + m R^2) (an oscillation +-i w above the
    critical speed, a real pair -- capsize -- below it). ``n_zero = 6``: the minimal state
    (x, y, heading, lean, spin angle; lean rate, heading rate, spin rate) has 8 dimensions; the
    zeros are x, y, heading, spin angle, the speed (neighbouring straight motions) and the
    heading/lean combination of neighbouring large-radius circles. No group eigenvalues (no turn).
    With a carrier, I_d becomes I_d + J_c in the closed form (the carrier turns with the lean and
    heading rates, not with the spin).
    ``steady``: ``spin_rate`` (rad/s, phi'), ``speed``, ``center_height``."""
    I_a, I_d = _disc_inertia(m, R, I_a, I_d)
    s = _disc_system()
    p = (m, R, g, I_a, I_d, carrier_inertia)
    x0 = np.array([0.0, 0.0, 0.0, v / R])
    assert np.allclose(np.asarray(s["f"](x0, p), float).ravel(), 0.0, atol=1e-12)
    jac = np.asarray(s["jac"](x0, p), float)
    ev = _nonzero_pair(jac, 2)
    return SteadyReference(
        eigenvalues=ev,
        n_zero=6,
        steady=dict(spin_rate=v / R, speed=v, center_height=R, lean=0.0, precession=0.0),
    )


def upright_disc_critical_speed(R: float, g: float = 9.81, m: float = 1.0, I_a: float | None = None,
                                I_d: float | None = None) -> float:
    """Speed (m/s) above which upright straight rolling is stable, from the characteristic
    polynomial lambda^2 (lambda^2 - c(v)) of the derivation (root of c(v) = 0). For the thin disc
    this is v^2 = g R / 3 (independent of m)."""
    I_a, I_d = _disc_inertia(m, R, I_a, I_d)
    s = _disc_system()
    sy = s["symbols"]
    lam, v = sy["lam"], sy["v"]
    poly = sp.Poly(sp.expand(s["char_upright"]), lam)
    # lambda^4 - c lambda^2: c = -coefficient of lambda^2 (leading coefficient normalised)
    coeffs = dict(zip(poly.monoms(), poly.coeffs()))
    lead = coeffs[(4,)]
    c = -coeffs.get((2,), 0) / lead
    assert all(coeffs.get((k,), 0) == 0 for k in (3, 1, 0))
    c = c.subs({sy["m"]: m, sy["R"]: R, sy["g"]: g, sy["I_a"]: I_a, sy["I_d"]: I_d})
    roots = [r for r in sp.solve(sp.Eq(c, 0), v) if r.is_positive]
    assert len(roots) == 1, roots
    return float(roots[0])


def disc_steady_spin(theta: float, Omega: float, R: float, g: float = 9.81, m: float = 1.0,
                     I_a: float | None = None, I_d: float | None = None, carrier_inertia: float = 0.0) -> float:
    """Spin rate phi' (about the axle, relative to the non-spinning carrier frame (t, l', k)) of
    steady rolling at lean ``theta`` and heading rate ``Omega``, from the derivation. For the thin
    disc it satisfies  Omega cos th (6 n - Omega sin th) + 4 g sin th / R = 0  with
    n = phi' + Omega sin th  (the spin component along the axle), i.e.
    n = (Omega sin th - 4 g tan th / (R Omega)) / 6."""
    I_a, I_d = _disc_inertia(m, R, I_a, I_d)
    return float(_disc_system()["spin"](theta, Omega, (m, R, g, I_a, I_d, carrier_inertia)))


def circular_disc(m: float, R: float, theta: float, Omega: float, g: float = 9.81,
                  I_a: float | None = None, I_d: float | None = None, carrier_inertia: float = 0.0) -> SteadyReference:
    """The disc of :func:`upright_disc` (``carrier_inertia`` as there) in steady circular
    rolling: lean ``theta`` (rad, from the
    vertical, the centre displaced towards -l = t x e_z, i.e. to the right of the direction of
    travel t for theta > 0), heading (precession) rate ``Omega`` (rad/s, about +e_z), spin rate
    phi' from :func:`disc_steady_spin`.

    Conventions (as examples/rolling_disc.py with its e1 = l, t = -e2): axle a = l' =
    cos th l + sin th e_z, contact -> centre k = cos th e_z - sin th l, spin component
    n = omega . a = phi' + Omega sin th, centre velocity R n t, centre circle of radius
    |R n / Omega| about the point C + (R n / Omega) l.

    Returns the NON-TRIVIAL eigenvalue pair of the reduced dynamics (lean, lean rate, heading
    rate, spin rate): +-i w (nutation of the lean, stable) or a real pair (unstable).
    ``group_eigenvalues = +-i Omega``: the translation of the whole circle, seen in the heading
    frame (a chain heading -> position in the heading frame, or a free carrier's body-frame
    velocities) turns at -Omega; measured in world axes these are zeros instead.
    ``n_zero = 4``: heading, spin angle and the 2-parameter family of steady motions (lean,
    precession rate). ``steady``: ``spin_rate`` phi', ``n``, ``speed`` |R n| of the centre,
    ``radius`` R n / Omega (signed: the circle centre lies at C + radius l), ``center_height``."""
    I_a, I_d = _disc_inertia(m, R, I_a, I_d)
    s = _disc_system()
    p = (m, R, g, I_a, I_d, carrier_inertia)
    spin = float(s["spin"](theta, Omega, p))
    x0 = np.array([theta, 0.0, Omega, spin])
    assert np.allclose(np.asarray(s["f"](x0, p), float).ravel(), 0.0, atol=1e-9 * (1 + Omega**2 + spin**2))
    jac = np.asarray(s["jac"](x0, p), float)
    ev = _nonzero_pair(jac, 2)
    n = spin + Omega * np.sin(theta)
    return SteadyReference(
        eigenvalues=ev,
        n_zero=4,
        group_eigenvalues=_sorted([1j * Omega, -1j * Omega]),
        steady=dict(spin_rate=spin, n=n, speed=abs(R * n), radius=R * n / Omega,
                    center_height=R * np.cos(theta), lean=theta, precession=Omega),
    )


# =============================================================================================
# (c) Chaplygin sleigh: Lagrange with a multiplier
# =============================================================================================
#
# Coordinates x, y (centre of mass), psi (body axis e1 = (cos psi, sin psi)). The blade point
# P = CM + a e1 has no velocity along e2 = (-sin psi, cos psi):
#   -sin psi x' + cos psi y' + a psi' = 0.
# Lagrange: m x'' = -lam sin psi, m y'' = lam cos psi, I psi'' = a lam, with the constraint
# differentiated once. State (x, y, psi, x', y', psi'); straight motion psi = 0, x' = v.


@functools.lru_cache(maxsize=None)
def _sleigh_system():
    m, I, a = sp.symbols("m I a", positive=True)
    ps, xd, yd, psd = sp.symbols("psi xd yd psd")
    xdd, ydd, psdd, lam = sp.symbols("xdd ydd psdd lam")
    eqs = [
        m * xdd + lam * sp.sin(ps),
        m * ydd - lam * sp.cos(ps),
        I * psdd - a * lam,
        # d/dt of the constraint
        -sp.sin(ps) * xdd - sp.cos(ps) * psd * xd + sp.cos(ps) * ydd - sp.sin(ps) * psd * yd + a * psdd,
    ]
    sol = sp.solve(eqs, [xdd, ydd, psdd, lam], dict=True)[0]
    x, y = sp.symbols("x y")
    state = sp.Matrix([x, y, ps, xd, yd, psd])
    f = sp.Matrix([xd, yd, psd, sol[xdd], sol[ydd], sol[psdd]])
    jac = f.jacobian(state)
    v = sp.Symbol("v")
    j0 = jac.subs({ps: 0, xd: v, yd: 0, psd: 0})
    lam_sym = sp.simplify(j0.trace())  # the only non-zero eigenvalue (the rest: see below)
    return {"jac": sp.lambdify((v, m, I, a), j0, "numpy"), "lam": lam_sym, "symbols": (m, I, a, v)}


def chaplygin_sleigh(m: float, I: float, a: float, v: float) -> SteadyReference:
    """Planar rigid body (mass ``m``, moment of inertia ``I`` about its centre of mass) with a
    knife edge at distance ``a`` along the body axis e1 from the centre of mass (blade point
    CM + a e1, no velocity along e2), sliding straight along e1 at speed ``v`` (v > 0: towards +e1).

    Returns the single non-trivial eigenvalue  lambda = m a v / (I + m a^2):  the heading rate
    decays (stable) when a v < 0 -- the blade trails behind the centre of mass -- and grows when
    a v > 0 (the blade leads). ``n_zero = 4`` in the minimal state (x, y, psi, forward speed,
    heading rate); the derivation's 6-state (x, y, psi, x', y', psi') Jacobian has one extra zero
    for the constraint direction. ``steady``: ``speed`` v, heading rate 0."""
    s = _sleigh_system()
    jac = np.asarray(s["jac"](v, m, I, a), float)
    ev = np.linalg.eigvals(jac)
    lam = float(np.trace(jac))
    # all but one eigenvalue vanish (nilpotent rest)
    rest = np.sort(np.abs(ev))[:-1] if abs(lam) > 0 else np.abs(ev)
    assert np.all(rest < 1e-6 * (abs(lam) + 1e-300)), ev
    return SteadyReference(eigenvalues=np.array([lam + 0j]), n_zero=4,
                           steady=dict(speed=v, heading_rate=0.0))


# =============================================================================================
# (d) heavy symmetric top: Lagrange in Euler angles z-x-z
# =============================================================================================
#
# psi precession about e_z, theta nutation (axis from the upward vertical), phi spin.
#   L = 1/2 A (theta'^2 + psi'^2 sin^2 theta) + 1/2 C (phi' + psi' cos theta)^2 - m g l cos theta,
# A transverse moment ABOUT THE FIXED POINT, C axial, l distance fixed point -> centre of mass
# along the axis (l < 0: centre of mass below the fixed point). psi and phi are cyclic: reduced
# state (theta, theta', psi', phi') with two conserved momenta.


@functools.lru_cache(maxsize=None)
def _top_system():
    t = sp.Symbol("t")
    th, ps, ph = (sp.Function(name)(t) for name in ("theta", "psi", "phi"))
    m, g, l, A, C = sp.symbols("m g l A C")
    L = (A * (th.diff(t) ** 2 + ps.diff(t) ** 2 * sp.sin(th) ** 2) / 2
         + C * (ph.diff(t) + ps.diff(t) * sp.cos(th)) ** 2 / 2 - m * g * l * sp.cos(th))
    coords = (th, ps, ph)
    eqs = [sp.diff(L.diff(q.diff(t)), t) - L.diff(q) for q in coords]
    x_th, x_thd, x_psd, x_phd = sp.symbols("th thd psd phd")
    accs = sp.symbols("thdd psdd phdd")
    rep = {q.diff(t, 2): a for q, a in zip(coords, accs)}
    eqs = [e.subs(rep).subs({th.diff(t): x_thd, ps.diff(t): x_psd, ph.diff(t): x_phd}).subs(th, x_th) for e in eqs]
    Am, b = sp.linear_eq_to_matrix(eqs, accs)
    acc = sp.simplify(Am.LUsolve(b))
    state = sp.Matrix([x_th, x_thd, x_psd, x_phd])
    f = sp.Matrix([x_thd, *acc])
    jac = f.jacobian(state)
    Om = sp.Symbol("Omega")
    cond = sp.simplify(acc[0].subs({x_thd: 0, x_psd: Om}))
    spin = sp.solve(sp.Eq(cond, 0), x_phd)
    assert len(spin) == 1
    params = (m, g, l, A, C)
    return {
        "f": sp.lambdify((state, params), f, "numpy"),
        "jac": sp.lambdify((state, params), jac, "numpy"),
        "spin": sp.lambdify((x_th, Om, params), spin[0], "numpy"),
        "spin_expr": sp.simplify(spin[0]),
    }


def heavy_top_spin(m: float, l: float, I1: float, I3: float, theta: float, precession: float,
                   g: float = 9.81) -> tuple[float, float]:
    """(spin rate phi', axial angular velocity omega3) of steady precession, from the derivation:
    m g l = Omega (I3 omega3 - I1 Omega cos theta)  =>  omega3 = (m g l + I1 Omega^2 cos theta) /
    (I3 Omega),  phi' = omega3 - Omega cos theta  (I1 about the fixed point)."""
    spin = float(_top_system()["spin"](theta, precession, (m, g, l, I1, I3)))
    return spin, spin + precession * np.cos(theta)


def heavy_top(m: float, l: float, I1: float, I3: float, theta: float, precession: float,
              g: float = 9.81) -> SteadyReference:
    """Heavy symmetric top on a fixed point: mass ``m``, centre of mass at distance ``l`` from the
    fixed point on the symmetry axis, ``I1`` the transverse moment of inertia ABOUT THE FIXED
    POINT (= I1_cm + m l^2), ``I3`` the axial one; gravity ``g`` down. Steady precession at
    nutation angle ``theta`` (axis from the upward vertical) with precession rate
    ``precession`` = psi' (rad/s, about +e_z); the spin follows from the steady condition
    (:func:`heavy_top_spin`): omega3 = (m g l + I1 Omega^2 cos theta) / (I3 Omega),
    phi' = omega3 - Omega cos theta.

    Returns the nutation pair +-i w (or a real pair when unstable); the classical closed form
    (also derived by the Routh reduction) is  w^2 = a^2 - 4 a Omega cos theta + Omega^2 (1 + 3
    cos^2 theta),  a = I3 omega3 / I1. ``n_zero = 4`` (psi, phi and their conserved momenta).
    ``steady``: ``spin_rate`` phi', ``omega3``, ``precession``, ``theta``."""
    s = _top_system()
    p = (m, g, l, I1, I3)
    spin = float(s["spin"](theta, precession, p))
    x0 = np.array([theta, 0.0, precession, spin])
    assert np.allclose(np.asarray(s["f"](x0, p), float).ravel(), 0.0, atol=1e-9 * (1 + spin**2))
    jac = np.asarray(s["jac"](x0, p), float)
    ev = _nonzero_pair(jac, 2)
    return SteadyReference(eigenvalues=ev, n_zero=4,
                           steady=dict(spin_rate=spin, omega3=spin + precession * np.cos(theta),
                                       precession=precession, theta=theta))


# =============================================================================================
# (e) conical pendulum: Newton-Euler (Euler-Poisson equations) in the body frame
# =============================================================================================
#
# Body about the pivot: centre of mass at r = (0, 0, -l) (body frame, hanging along -z_B),
# inertia about the pivot I_P = diag(I_t + m l^2, I_t + m l^2, I_a). gamma = body components of
# the upward vertical e_z. Euler about the fixed pivot and Poisson:
#   I_P omega' = (I_P omega) x omega + r x (-m g gamma),   gamma' = gamma x omega.
# Steady conical motion at cone angle alpha (axis from the DOWNWARD vertical), no spin relative to
# the turning frame: gamma0 = (0, sin alpha, cos alpha), omega0 = Omega gamma0. Condition:
#   Omega^2 = m g l / ((I_t + m l^2 - I_a) cos alpha).
# The (omega, gamma) linearization (6 x 6) has 4 zeros (|gamma|, the vertical angular momentum,
# omega . e3 and the family parameter) and the nutation pair.


@functools.lru_cache(maxsize=None)
def _cone_system():
    m, g, l, It, Ia = sp.symbols("m g l I_t I_a", positive=True)
    w = sp.Matrix(sp.symbols("w1:4"))
    gam = sp.Matrix(sp.symbols("g1:4"))
    IP = sp.diag(It + m * l**2, It + m * l**2, Ia)
    r = sp.Matrix([0, 0, -l])
    wd = IP.inv() * ((IP * w).cross(w) + r.cross(-m * g * gam))
    gd = gam.cross(w)
    state = sp.Matrix([*w, *gam])
    f = sp.Matrix([*wd, *gd])
    jac = f.jacobian(state)
    al, Om = sp.symbols("alpha Omega")
    g0 = sp.Matrix([0, sp.sin(al), sp.cos(al)])
    at0 = dict(zip(state, [*(Om * g0), *g0]))
    cond = sp.simplify(f.subs(at0))
    # the only non-trivial row is omega_1' ~ (m g l - Omega^2 cos(alpha)(I_t + m l^2 - I_a)) sin(alpha)
    Om2 = sp.solve(sp.Eq(cond[0], 0), Om**2) if cond[0] != 0 else None
    params = (m, g, l, It, Ia)
    return {
        "f": sp.lambdify((state, params), f, "numpy"),
        "jac": sp.lambdify((state, params), jac, "numpy"),
        "cond": cond,
        "Omega2": Om2,
    }


def conical_pendulum_rate(m: float, l: float, I_t: float, I_a: float, alpha: float, g: float = 9.81) -> float:
    """Steady turning rate Omega > 0 of the conical motion at cone angle ``alpha``:
    Omega^2 = m g l / ((I_t + m l^2 - I_a) cos alpha)  (needs I_t + m l^2 > I_a, alpha < pi/2).
    Point mass (I_t = I_a = 0): Omega^2 = g / (l cos alpha)."""
    den = (I_t + m * l * l - I_a) * np.cos(alpha)
    if not den > 0:
        raise ValueError("no steady conical motion: need (I_t + m l^2 - I_a) cos(alpha) > 0")
    return float(np.sqrt(m * g * l / den))


def conical_pendulum(m: float, l: float, I_t: float, I_a: float, alpha: float, g: float = 9.81,
                     direction: float = 1.0) -> SteadyReference:
    """Rigid body on a spherical joint (pivot), centre of mass at distance ``l`` below the pivot
    on the body's symmetry axis, inertia about the centre of mass ``I_t`` transverse and ``I_a``
    axial (point mass on a massless rod: I_t = I_a = 0; for the derivation I_a may be tiny but
    must be > 0), gravity ``g`` down. Steady conical motion: the axis at cone angle ``alpha``
    from the downward vertical turns about the vertical at rate Omega = direction *
    :func:`conical_pendulum_rate`, the body not spinning relative to the turning vertical plane
    (omega = Omega e_z).

    Returns the nutation pair +-i w. Closed form (from the heavy-top result with I1 = I_t + m l^2,
    I3 = I_a, theta = pi - alpha, omega3 = -Omega cos alpha):
    w^2 = Omega^2 (cos^2 alpha (2 - I_a / I1)^2 + sin^2 alpha); the point mass gives the classical
    w^2 = Omega^2 (1 + 3 cos^2 alpha). ``n_zero = 4`` (minimal state of the 3-DOF body: 6).
    ``steady``: ``Omega`` (signed), ``omega_body`` = Omega (0, sin alpha, cos alpha) (body frame
    with the axis along -z_B, tilted about x), ``alpha``."""
    s = _cone_system()
    Om = direction * conical_pendulum_rate(m, l, I_t, I_a, alpha, g)
    g0 = np.array([0.0, np.sin(alpha), np.cos(alpha)])
    x0 = np.concatenate([Om * g0, g0])
    p = (m, g, l, I_t, I_a)
    res = np.asarray(s["f"](x0, p), float).ravel()
    assert np.allclose(res, 0.0, atol=1e-9 * (1 + Om * Om)), res
    jac = np.asarray(s["jac"](x0, p), float)
    ev = _nonzero_pair(jac, 4)
    return SteadyReference(eigenvalues=ev, n_zero=4,
                           steady=dict(Omega=Om, omega_body=Om * g0, alpha=alpha))
