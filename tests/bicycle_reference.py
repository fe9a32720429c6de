"""Independent reference for the Whipple/Carvallo bicycle benchmark (no mechsys import).

J. P. Meijaard, J. M. Papadopoulos, A. Ruina, A. L. Schwab, "Linearized dynamics equations for
the balance and steer of a bicycle: a benchmark and review", Proc. R. Soc. A 463 (2007)
1955-1982. The linearized equations of upright straight running at forward speed v,

    M q'' + v C1 q' + (g K0 + v^2 K2) q = 0,    q = (phi, delta)    (lean, steer),

with M, C1, K0, K2 from the closed forms of the paper's appendix A, computed here from the
parameters of its Table 1. Conventions of the paper: x forward, y to the right, z down, the rear
contact point at the origin; lean phi positive to the right (about x), steer delta positive to the
right (about the steer axis pointing down); the steer axis tilted back by lambda from the vertical.

Also the published values (the matrix entries of the paper's eq. (A 2)-(A 4) / section 5 and the
weave and capsize speeds of its Table 2) as constants, to check the closed forms against.
"""

from __future__ import annotations

import math

import numpy as np

# ---- Table 1: the benchmark bicycle (benchmark axes: x forward, z down) ----------------------
PARAMETERS = dict(
    w=1.02,  # wheel base (m)
    c=0.08,  # trail (m)
    lam=math.pi / 10,  # steer axis tilt (rad), from the vertical
    g=9.81,  # gravity (N/kg)
    # rear wheel R
    rR=0.3, mR=2.0, IRxx=0.0603, IRyy=0.12,
    # rear body and frame B: centre of mass (xB, zB), inertia about it (tensor components)
    xB=0.3, zB=-0.9, mB=85.0, IBxx=9.2, IByy=11.0, IBzz=2.8, IBxz=2.4,
    # front handlebar and fork assembly H
    xH=0.9, zH=-0.7, mH=4.0, IHxx=0.05892, IHyy=0.06, IHzz=0.00708, IHxz=-0.00756,
    # front wheel F
    rF=0.35, mF=3.0, IFxx=0.1405, IFyy=0.28,
)

# ---- published values (the paper's section 5, to 14 digits) ----------------------------------
M_PUBLISHED = np.array([[80.81722, 2.31941332208709],
                        [2.31941332208709, 0.29784188199686]])
K0_PUBLISHED = np.array([[-80.95, -2.59951685249872],
                         [-2.59951685249872, -0.80329488458618]])
K2_PUBLISHED = np.array([[0.0, 76.59734589573222],
                         [0.0, 2.65431523794604]])
C1_PUBLISHED = np.array([[0.0, 33.86641391492494],
                         [-0.85035641456978, 1.68540397397560]])
#: weave and capsize speeds (m/s), Table 2 (the 4.292 and 6.024 quoted in the text). These and the
#: eigenvalues at v = 0 are quoted from memory of Table 2, not from the brief: the closed forms
#: below give the speeds to 3e-15 and the eigenvalues to 4e-12 of them.
WEAVE_SPEED_PUBLISHED = 4.29238253634111
CAPSIZE_SPEED_PUBLISHED = 6.02426201538837
#: eigenvalues at v = 0 (1/s), Table 2: the two static instabilities (inverted pendulums)
EIGENVALUES_V0_PUBLISHED = (3.13164324790656, 5.53094371765827)


def matrices(p: dict | None = None) -> dict:
    """M, C1, K0, K2 (2 x 2) of the benchmark's linearized equations from the parameters ``p``
    (default :data:`PARAMETERS`) by the closed forms of the paper's appendix A; also the
    intermediate quantities (total mass and centre of mass, front assembly, S_A, S_T, ...)."""
    p = dict(PARAMETERS if p is None else p)
    w, c, lam = p["w"], p["c"], p["lam"]
    rR, mR, IRxx, IRyy = p["rR"], p["mR"], p["IRxx"], p["IRyy"]
    xB, zB, mB = p["xB"], p["zB"], p["mB"]
    IBxx, IBzz, IBxz = p["IBxx"], p["IBzz"], p["IBxz"]
    xH, zH, mH = p["xH"], p["zH"], p["mH"]
    IHxx, IHzz, IHxz = p["IHxx"], p["IHzz"], p["IHxz"]
    rF, mF, IFxx, IFyy = p["rF"], p["mF"], p["IFxx"], p["IFyy"]
    sl, cl = math.sin(lam), math.cos(lam)

    # whole bicycle (A 5)-(A 10): mass, centre of mass, inertia about the rear contact point
    mT = mR + mB + mH + mF
    xT = (xB * mB + xH * mH + w * mF) / mT
    zT = (-rR * mR + zB * mB + zH * mH - rF * mF) / mT
    ITxx = IRxx + IBxx + IHxx + IFxx + mR * rR**2 + mB * zB**2 + mH * zH**2 + mF * rF**2
    ITxz = IBxz + IHxz - mB * xB * zB - mH * xH * zH + mF * w * rF
    IRzz, IFzz = IRxx, IFxx  # axisymmetric wheels
    ITzz = IRzz + IBzz + p["IHzz"] + IFzz + mB * xB**2 + mH * xH**2 + mF * w**2

    # front assembly A = H + F (A 11)-(A 17): mass, centre of mass, inertia about it
    mA = mH + mF
    xA = (xH * mH + w * mF) / mA
    zA = (zH * mH - rF * mF) / mA
    IAxx = IHxx + IFxx + mH * (zH - zA) ** 2 + mF * (rF + zA) ** 2
    IAxz = IHxz - mH * (xH - xA) * (zH - zA) + mF * (w - xA) * (rF + zA)
    IAzz = IHzz + IFzz + mH * (xH - xA) ** 2 + mF * (w - xA) ** 2
    # perpendicular distance of its centre of mass ahead of the steer axis (A 18)
    uA = (xA - w - c) * cl - zA * sl
    # its inertia about the steer axis, and products with the x and z axes through the rear
    # contact point (A 19)-(A 21)
    IAll = mA * uA**2 + IAxx * sl**2 + 2 * IAxz * sl * cl + IAzz * cl**2
    IAlx = -mA * uA * zA + IAxx * sl + IAxz * cl
    IAlz = mA * uA * xA + IAxz * sl + IAzz * cl
    # ratio of trail to wheel base (A 22), gyrostatic coefficients (A 23)-(A 25), static moment (A 26)
    mu = c / w * cl
    SR = IRyy / rR
    SF = IFyy / rF
    ST = SR + SF
    SA = mA * uA + mu * mT * xT

    M = np.array([[ITxx, IAlx + mu * ITxz],
                  [IAlx + mu * ITxz, IAll + 2 * mu * IAlz + mu**2 * ITzz]])
    K0 = np.array([[mT * zT, -SA],
                   [-SA, -SA * sl]])
    K2 = np.array([[0.0, (ST - mT * zT) / w * cl],
                   [0.0, (SA + SF * sl) / w * cl]])
    C1 = np.array([[0.0, mu * ST + SF * cl + ITxz / w * cl - mu * mT * zT],
                   [-(mu * ST + SF * cl), IAlz / w * cl + mu * (SA + ITzz / w * cl)]])
    return dict(M=M, C1=C1, K0=K0, K2=K2, g=p["g"], mT=mT, xT=xT, zT=zT, ITxx=ITxx, ITxz=ITxz,
                ITzz=ITzz, mA=mA, xA=xA, zA=zA, IAxx=IAxx, IAxz=IAxz, IAzz=IAzz, uA=uA, IAll=IAll,
                IAlx=IAlx, IAlz=IAlz, mu=mu, SR=SR, SF=SF, ST=ST, SA=SA)


_MATS = matrices()


def state_matrix(v: float, p: dict | None = None) -> np.ndarray:
    """A of x' = A x, x = (phi, delta, phi', delta')."""
    m = _MATS if p is None else matrices(p)
    minv = np.linalg.inv(m["M"])
    a = np.zeros((4, 4))
    a[:2, 2:] = np.eye(2)
    a[2:, :2] = -minv @ (m["g"] * m["K0"] + v * v * m["K2"])
    a[2:, 2:] = -minv @ (v * m["C1"])
    return a


def eigenvalues(v: float, p: dict | None = None) -> np.ndarray:
    """The 4 eigenvalues of the state form at speed v, sorted by real part, then imaginary part."""
    lam = np.linalg.eigvals(state_matrix(v, p))
    return lam[np.lexsort((lam.imag, lam.real))]


def _crossing(f, a: float, b: float, tol: float = 1e-14) -> float:
    """Root of f in [a, b] (sign change) by bisection to ``tol``."""
    fa = f(a)
    if fa * f(b) > 0:
        raise ValueError(f"no sign change in [{a}, {b}]")
    for _ in range(200):
        m = 0.5 * (a + b)
        fm = f(m)
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
        if b - a < tol:
            break
    return 0.5 * (a + b)


def _weave_real(v: float) -> float:
    """Real part of the oscillatory (complex pair) eigenvalues at v."""
    lam = eigenvalues(v)
    osc = lam[np.abs(lam.imag) > 1e-9]
    return float(osc.real.max())


def _capsize_real(v: float) -> float:
    """Real part of the real eigenvalue nearest to zero from the capsize branch at v (the largest
    real eigenvalue with zero imaginary part)."""
    lam = eigenvalues(v)
    real = lam[np.abs(lam.imag) <= 1e-9].real
    return float(real.max())


def weave_speed() -> float:
    """Speed (m/s) where the weave pair's real part crosses zero (from positive to negative)."""
    return _crossing(_weave_real, 4.0, 4.6)


def capsize_speed() -> float:
    """Speed (m/s) where the capsize eigenvalue (real) crosses zero (from negative to positive)."""
    return _crossing(_capsize_real, 5.8, 6.3)


def lean_steer_response(v: float, t, phi0: float = 0.0, delta0: float = 0.0, phidot0: float = 0.0,
                        deltadot0: float = 0.0) -> np.ndarray:
    """The linear motion (rows: t; columns phi, delta, phi', delta') from the given start, by the
    matrix exponential of the state form."""
    from scipy.linalg import expm

    a = state_matrix(v)
    x0 = np.array([phi0, delta0, phidot0, deltadot0], dtype=float)
    return np.array([expm(a * tk) @ x0 for tk in np.atleast_1d(np.asarray(t, dtype=float))])


if __name__ == "__main__":
    m = matrices()
    for k in ("M", "C1", "K0", "K2"):
        print(k, m[k].tolist())
    print("weave speed", weave_speed(), "capsize speed", capsize_speed())
    print("eigenvalues at v = 0", eigenvalues(0.0))
    print("eigenvalues at v = 5", eigenvalues(5.0))
