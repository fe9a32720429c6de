"""Elastic-body shape functions and reduced data (mechsys.elastic) against closed forms and
published values: Euler-Bernoulli roots and frequencies, FE convergence at h^4, Timoshenko,
Craig-Bampton, inertia invariants, modal effective masses, Southwell coefficients, file import."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import linalg

from mechsys import elastic as el
from mechsys.continuum import gauss_legendre, skew
from mechsys.errors import ModelError

E, NU, RHO, L = 210e9, 0.3, 7850.0, 1.0
SEC = el.BeamSection.rectangle(0.02, 0.01, E=E, nu=NU, rho=RHO)  # Iy (x-z bending) < Iz


def omega_scale(I, L=L):
    return np.sqrt(E * I / (RHO * SEC.A * L**4))


def test_characteristic_roots_match_published_values():
    # Blevins, Formulas for natural frequency and mode shape, table 8-1
    assert el.euler_bernoulli_roots("clamped-free", 5) == pytest.approx([1.87510406871196, 4.69409113297418, 7.85475743823761, 10.9955407348755, 14.1371683910465], rel=1e-12)
    assert el.euler_bernoulli_roots("free-free", 3) == pytest.approx([4.73004074486270, 7.85320462409584, 10.9956078380017], rel=1e-12)
    assert el.euler_bernoulli_roots("clamped-pinned", 2) == pytest.approx([3.92660231204792, 7.06858274562873], rel=1e-12)
    assert el.euler_bernoulli_roots("pinned-pinned", 3) == pytest.approx(np.pi * np.array([1, 2, 3]), rel=1e-15)
    with pytest.raises(ModelError, match="'fixed-free'"):
        el.euler_bernoulli_roots("fixed-free", 2)


def _quad(n_cells=40, order=12):
    xs, ws = zip(*(gauss_legendre(order, a, b) for a, b in zip(np.linspace(0, L, n_cells + 1)[:-1], np.linspace(0, L, n_cells + 1)[1:])))
    return np.concatenate(xs), np.concatenate(ws)


@pytest.mark.parametrize("bc", ["clamped-free", "free-free", "clamped-clamped", "clamped-pinned", "pinned-pinned"])
def test_analytic_modes_rayleigh_quotient_boundary_conditions_orthogonality(bc):
    x, w = _quad()
    roots = el.euler_bernoulli_roots(bc, 4)
    shapes = [el.euler_bernoulli_mode(bc, k, x, L) for k in range(1, 5)]
    for k in range(4):
        # omega^2 = int EI phi''^2 / int rho A phi^2 reproduces (beta L)^4 EI / (rho A L^4) to 1e-9
        p2 = el.euler_bernoulli_mode(bc, k + 1, x, L, derivative=2)
        w_rayleigh = np.sqrt(E * SEC.Iy * np.sum(w * p2**2) / (RHO * SEC.A * np.sum(w * shapes[k] ** 2)))
        w_closed = roots[k] ** 2 * omega_scale(SEC.Iy)
        assert w_rayleigh == pytest.approx(w_closed, rel=1e-9)
        for j in range(k):
            assert abs(np.sum(w * shapes[k] * shapes[j])) < 1e-10 * np.sqrt(np.sum(w * shapes[k] ** 2) * np.sum(w * shapes[j] ** 2))
    ends = np.array([0.0, L])
    vals = [el.euler_bernoulli_mode(bc, 3, ends, L, d) for d in range(4)]
    scale = [np.abs(v).max() for v in vals]
    zero = {"clamped": (0, 1), "pinned": (0, 2), "free": (2, 3)}
    for end, kind in enumerate(bc.split("-")):
        for d in zero[kind]:
            assert abs(vals[d][end]) < 1e-12 * max(scale)


def test_fe_cantilever_converges_at_h4_to_analytic_frequencies():
    w_an = el.euler_bernoulli_frequencies("clamped-free", 3, E, SEC.Iz, RHO, SEC.A, L)
    assert w_an[0] == pytest.approx(1.87510406871196**2 * omega_scale(SEC.Iz), rel=1e-12)
    errs = []
    for n in (2, 4, 8, 16):  # planar: bending in x-y, governed by Iz
        body = el.modal_reduction(el.beam_model(SEC, L, n, planar=True), 3, fixed={0: "clamped"}, name="c")
        errs.append(body.omega[:2] / w_an[:2] - 1)
    errs = np.array(errs)
    assert np.all(errs > 0)  # consistent mass, conforming elements: upper bounds
    rates = np.log2(errs[:-1] / errs[1:])
    assert np.all(np.abs(rates[1:, 0] - 4) < 0.15), rates  # h^4 in frequency
    assert abs(rates[-1, 1] - 4) < 0.3, rates
    assert errs[-1, 0] < 2e-7
    # spatial beam: both bending planes and torsion, the first torsional frequency (pi/2) sqrt(GJ/(rho Ip L^2))
    body = el.modal_reduction(el.beam_model(SEC, L, 40), 8, fixed={0: "clamped"}, name="c3")
    w_y = el.euler_bernoulli_frequencies("clamped-free", 2, E, SEC.Iy, RHO, SEC.A, L)
    w_t = np.pi / 2 * np.sqrt(SEC.G * SEC.J / (RHO * SEC.Ip * L**2))
    for target in (w_an[0], w_an[1], w_y[0], w_y[1]):
        assert np.min(np.abs(body.omega / target - 1)) < 1e-6
    body_t = el.modal_reduction(el.beam_model(SEC, L, 40), 20, fixed={0: "clamped"}, name="c3")
    assert np.min(np.abs(body_t.omega / w_t - 1)) < 2e-4  # linear torsion elements: h^2


def test_pinned_and_free_free_fe_beams():
    w_pp = el.euler_bernoulli_frequencies("pinned-pinned", 3, E, SEC.Iz, RHO, SEC.A, L)
    assert w_pp == pytest.approx((np.pi * np.arange(1, 4)) ** 2 * omega_scale(SEC.Iz), rel=1e-14)
    body = el.modal_reduction(el.beam_model(SEC, L, 30, planar=True), 3, fixed={0: "pinned", -1: ["ux", "uy"]}, name="pp")
    assert body.omega == pytest.approx(w_pp, rel=1e-5)
    # free-free: six rigid-body modes recognized and left out, first elastic root 4.7300...
    ff = el.modal_reduction(el.beam_model(SEC, L, 40), 2, name="ff")
    w_ff = el.euler_bernoulli_frequencies("free-free", 1, E, SEC.Iy, RHO, SEC.A, L)
    assert ff.omega[0] == pytest.approx(w_ff[0], rel=1e-6)
    assert ff.omega[0] == pytest.approx(4.73004074486270**2 * omega_scale(SEC.Iy), rel=1e-6)
    # free-free modes are orthogonal to rigid motion: no momentum coupling (mean-axis conditions)
    assert np.abs(ff.Ct).max() < 1e-8 * np.sqrt(ff.mass) and np.abs(ff.Cr).max() < 1e-8 * np.sqrt(ff.mass) * L


def test_timoshenko_closed_form_slender_limit_and_stubby_beams():
    kw = dict(E=E, G=SEC.G, kappa=SEC.kappa, rho=RHO, A=SEC.A, I=SEC.Iy)
    for length in (10.0, 0.05):
        w_det = el.timoshenko_frequencies("pinned-pinned", 3, L=length, **kw)
        w_cf = [el.timoshenko_pinned_pinned(k, L=length, **kw) for k in (1, 2, 3)]
        assert w_det == pytest.approx(w_cf, rel=1e-10)
    # slender (L/h = 1000): 1 - omega_T/omega_EB = (k pi r/L)^2 (1 + E/(kappa G)) / 2 to leading order
    r2 = SEC.Iy / SEC.A
    w_t = el.timoshenko_frequencies("pinned-pinned", 2, L=10.0, **kw)
    w_e = el.euler_bernoulli_frequencies("pinned-pinned", 2, E, SEC.Iy, RHO, SEC.A, 10.0)
    pred = 0.5 * (np.pi * np.array([1, 2]) / 10.0) ** 2 * r2 * (1 + E / (SEC.kappa * SEC.G))
    assert 1 - w_t / w_e == pytest.approx(pred, rel=2e-3)
    wc_t = el.timoshenko_frequencies("clamped-free", 3, L=10.0, **kw)
    wc_e = el.euler_bernoulli_frequencies("clamped-free", 3, E, SEC.Iy, RHO, SEC.A, 10.0)
    assert np.all(wc_t < wc_e) and np.all(wc_t / wc_e > 1 - 2e-5)
    # stubby (L/h = 5): well below Euler-Bernoulli, more so for higher modes
    ws_t = el.timoshenko_frequencies("clamped-free", 3, L=0.05, **kw)
    ws_e = el.euler_bernoulli_frequencies("clamped-free", 3, E, SEC.Iy, RHO, SEC.A, 0.05)
    ratio = ws_t / ws_e
    assert ratio[0] < 0.98 and ratio[2] < 0.75 and np.all(np.diff(ratio) < 0)


def test_craig_bampton_reproduces_the_full_models_lowest_frequencies():
    fe = el.beam_model(SEC, L, 20)
    full = el.modal_reduction(fe, 10, fixed={0: "clamped"}, name="full")
    cb = el.craig_bampton(fe, 6, interface=[-1, 10], fixed={0: "clamped"}, name="cb")
    assert cb.n_coordinates == 6 + 12 and cb.interface_nodes == (10, 20)
    assert cb.labels[6] == "n10.ux" and cb.labels[-1] == "n20.rz"
    rel = cb.frequencies()[:6] / full.frequencies()[:6] - 1
    assert np.all(rel > -1e-12)  # a Ritz basis of the full model: upper bounds
    assert np.all(rel[:3] < 1e-4) and np.all(rel < 6e-3), rel
    # more fixed-interface modes: closer
    cb12 = el.craig_bampton(fe, 12, interface=[-1, 10], fixed={0: "clamped"}, name="cb12")
    rel12 = cb12.frequencies()[:6] / full.frequencies()[:6] - 1
    assert np.all(rel12 < rel) and np.all(rel12 < 5e-4), rel12
    # the constraint modes keep the interface motion exactly: the tip static deflection
    # under a tip load equals the full model's (cantilever: P L^3 / (3 E I))
    P = 10.0
    kr = cb.K[6:, 6:]  # static condensation of the reduced model onto the interface
    f = np.zeros(12)
    f[6 + 2] = P
    u = np.linalg.solve(kr, f)
    assert u[6 + 2] == pytest.approx(P * L**3 / (3 * E * SEC.Iy), rel=1e-10)
    # the interface alone as reference of a free beam: the constraint modes are rigid motions
    with pytest.raises(ModelError, match="'floating'.*rigid-body"):
        el.craig_bampton(fe, 4, interface=[0], name="floating")
    nodes, M, K = _hand_made_two_element_cantilever()  # uz, rx, ry of nodes 1, 2 have no stiffness
    with pytest.raises(ModelError, match="'loose'.*not restrained: K_ii is singular"):
        el.craig_bampton(el.fe_model(nodes, M + np.eye(18), K), 2, interface=[0], name="loose")
    with pytest.raises(ModelError, match="rigid-body"):
        el.craig_bampton(fe, 4, interface=[0, -1], fixed={10: "pinned"}, name="half_free")


def test_inertia_invariants_of_a_beam_against_closed_forms():
    m = RHO * SEC.A * L
    body = el.modal_reduction(el.beam_model(SEC, L, 10), 6, fixed={0: "clamped"}, name="bar")
    assert body.mass == pytest.approx(m, rel=1e-13)
    assert body.first_moment == pytest.approx([m * L / 2, 0, 0], rel=1e-13, abs=1e-15)
    assert body.center_of_mass == pytest.approx([L / 2, 0, 0], abs=1e-14)
    # about the end: m L^2 / 3 transverse, rho Ip L about the axis (slender: no rotary inertia)
    assert np.diag(body.inertia) == pytest.approx([RHO * SEC.Ip * L, m * L**2 / 3, m * L**2 / 3], rel=1e-12)
    # with rotary inertia of the section: + rho I L
    bodyr = el.modal_reduction(el.beam_model(SEC, L, 10, rotary_inertia=True), 6, fixed={0: "clamped"}, name="bar_r")
    assert np.diag(bodyr.inertia) == pytest.approx([RHO * SEC.Ip * L, m * L**2 / 3 + RHO * SEC.Iy * L, m * L**2 / 3 + RHO * SEC.Iz * L], rel=1e-12)
    # the same bar placed off the origin: Steiner
    off = el.modal_reduction(el.beam_model(SEC, L, 4, start=(0.5, 0.2, 0.0)), 2, fixed={0: "clamped"}, name="off")
    c = np.array([0.5 + L / 2, 0.2, 0.0])
    I_c = np.diag([RHO * SEC.Ip * L, m * L**2 / 12, m * L**2 / 12])
    assert off.inertia == pytest.approx(I_c + m * (c @ c * np.eye(3) - np.outer(c, c)), rel=1e-12, abs=1e-12)
    # second-order invariants: I(q) = -int (r~ + u~)(r~ + u~) dm; I1_k and C_r share int x phi dm
    # (mode 1 bends in x-z: u = (0, 0, phi); I_xz(q) = -int x z dm, C_r,y = -int x phi dm)
    assert abs(body.modes[-1, 2, 0]) > 0 and abs(body.modes[-1, 1, 0]) < 1e-9
    assert body.I1[0][0, 2] == pytest.approx(body.Cr[1, 0], rel=1e-10) and abs(body.Cr[1, 0]) > 0.1 * np.sqrt(m) * L
    # I2_kk = -int u~ u~ dm = diag(int phi^2, int phi^2, 0) = diag(M_kk, M_kk, 0) without rotary inertia
    assert np.diag(body.I2[0, 0]) == pytest.approx([body.M[0, 0], body.M[0, 0], 0.0], rel=1e-10, abs=1e-14)
    assert body.M[0, 0] == pytest.approx(1.0, rel=1e-12)  # mass-normalized
    assert np.allclose(body.I2, body.I2.transpose(1, 0, 2, 3))
    # G_k = int phi_k~ Phi dm: column k is int u_k x u_k dm = 0
    assert np.abs(body.Gk[0][:, 0]).max() < 1e-14


def test_cantilever_modal_effective_masses_published():
    # effective mass fractions of a uniform cantilever's bending modes: 0.6131, 0.1883, 0.0647, 0.0331
    body = el.modal_reduction(el.beam_model(SEC, L, 40, planar=True), 4, fixed={0: "clamped"}, name="c")
    frac = body.Ct[1] ** 2 / np.diag(body.M) / body.mass
    assert frac == pytest.approx([0.6131, 0.1883, 0.0647, 0.0331], abs=6e-5)
    # analytic: m_eff / m = (int phi dx)^2 / (L int phi^2 dx) with the analytic mode shapes
    x, w = _quad()
    for k in range(4):
        phi = el.euler_bernoulli_mode("clamped-free", k + 1, x, L)
        assert frac[k] == pytest.approx(np.sum(w * phi) ** 2 / (L * np.sum(w * phi**2)), rel=2e-5)


def test_southwell_coefficient_of_a_rotating_cantilever():
    kappa = el.southwell_coefficients(SEC, L, n_elements=20, n_modes=2)
    assert kappa[0] == pytest.approx(1.193, rel=1e-2)  # Southwell, uniform cantilever, zero hub
    assert kappa[1] == pytest.approx(6.479, rel=1e-2)
    # independent: first-order perturbation with the analytic mode,
    # kappa = int (L^2 - x^2)/2 phi'^2 dx / int phi^2 dx
    x, w = _quad()
    phi = el.euler_bernoulli_mode("clamped-free", 1, x, L)
    dphi = el.euler_bernoulli_mode("clamped-free", 1, x, L, derivative=1)
    k_an = np.sum(w * 0.5 * (L**2 - x**2) * dphi**2) / np.sum(w * phi**2)
    assert kappa[0] == pytest.approx(k_an, rel=1e-5)
    # lag (in-plane) bending is softened by Omega^2: kappa - 1
    assert el.southwell_coefficients(SEC, L, n_modes=1, plane="lag")[0] == pytest.approx(kappa[0] - 1, rel=1e-9)
    # the eigenvalues at a finite speed follow omega^2 ~ omega0^2 + kappa Omega^2 closely
    w0 = el.rotating_cantilever_frequencies(SEC, L, 0.0, n_modes=1)[0]
    w = el.rotating_cantilever_frequencies(SEC, L, w0, n_modes=1)[0]
    assert (w**2 - w0**2) / w0**2 == pytest.approx(kappa[0], rel=2e-2)
    assert w > w0
    with pytest.raises(ModelError, match="plane must be"):
        el.southwell_coefficients(SEC, L, plane="pitch")


# ------------------------------------------------------------------------------------------
# Import from an external FE code
# ------------------------------------------------------------------------------------------


def _hand_made_two_element_cantilever(EI=2.0, rhoA=3.0, EA=50.0, Lb=1.2):
    """18x18 matrices of a planar (x-y) 2-element beam, written out here from the textbook element
    matrices; uz, rx, ry carry neither stiffness nor mass (they are to be fixed)."""
    h = Lb / 2
    kb = EI / h**3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h], [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
    mb = rhoA * h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h], [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])
    K = np.zeros((18, 18))
    M = np.zeros((18, 18))
    for e in range(2):
        bend = [6 * e + 1, 6 * e + 5, 6 * e + 7, 6 * e + 11]
        ax = [6 * e, 6 * e + 6]
        K[np.ix_(bend, bend)] += kb
        M[np.ix_(bend, bend)] += mb
        K[np.ix_(ax, ax)] += EA / h * np.array([[1, -1], [-1, 1]])
        M[np.ix_(ax, ax)] += rhoA * h / 6 * np.array([[2, 1], [1, 2]])
    nodes = np.array([[0, 0, 0], [h, 0, 0], [Lb, 0, 0.0]])
    return nodes, M, K


def test_fe_import_converter_from_a_hand_made_mesh(tmp_path):
    EI, rhoA, Lb = 2.0, 3.0, 1.2
    nodes, M, K = _hand_made_two_element_cantilever(EI, rhoA, 50.0, Lb)
    # the 'external code': clamp node 0, drop the out-of-plane DOFs, solve, keep 2 modes
    keep = [d for d in range(6, 18) if d % 6 in (0, 1, 5)]
    w2, V = linalg.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)])
    q = 2
    modes = np.zeros((18, q))
    modes[keep] = V[:, :q]
    node_masses = np.array([rhoA * Lb / 4, rhoA * Lb / 2, rhoA * Lb / 4])
    path = tmp_path / "beam2.npz"
    np.savez(path, nodes=nodes, M=np.eye(q), K=np.diag(w2[:q]), modes=modes.reshape(3, 6, q), interface=np.array([2]), node_masses=node_masses, units="SI")
    body = el.load_reduced(path)
    assert body.name == "beam2" and body.interface_nodes == (2,)
    assert body.omega == pytest.approx(np.sqrt(w2[:q]), rel=1e-12)
    # 2-element Hermite cantilever: lambda_1 = 3.5177 (exact 1.8751^2 = 3.5160)
    lam1 = body.omega[0] / np.sqrt(EI / (rhoA * Lb**4))
    assert lam1 == pytest.approx(3.5177, abs=1e-4)
    assert body.mass == pytest.approx(rhoA * Lb, rel=1e-14)
    assert body.inertia[2, 2] == pytest.approx(rhoA * Lb / 2 * (Lb / 2) ** 2 + rhoA * Lb / 4 * Lb**2, rel=1e-14)
    # the same mesh through fe_model + modal_reduction gives the same body
    fe = el.fe_model(nodes, M, K)
    body2 = el.modal_reduction(fe, q, fixed={0: "clamped", 1: ["uz", "rx", "ry"], 2: ["uz", "rx", "ry"]}, name="beam2")
    assert body2.omega == pytest.approx(body.omega, rel=1e-12)
    assert body2.mass == pytest.approx(rhoA * Lb, rel=1e-12)
    # round trips through both file formats keep every array
    for suffix in (".npz", ".h5"):
        p = body2.save(tmp_path / f"out{suffix}")
        back = el.load_reduced(p)
        assert back.name == "beam2" and back.labels == body2.labels
        for key in ("nodes", "M", "K", "modes", "inertia", "Ct", "Cr", "I1", "I2", "Gk"):
            assert np.array_equal(getattr(back, key), getattr(body2, key)), key


def _write(tmp_path, name="bad", **over):
    nodes, M, K = _hand_made_two_element_cantilever()
    keep = [d for d in range(6, 18) if d % 6 in (0, 1, 5)]
    w2, V = linalg.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)])
    modes = np.zeros((18, 2))
    modes[keep] = V[:, :2]
    data = dict(nodes=nodes, M=np.eye(2), K=np.diag(w2[:2]), modes=modes.reshape(3, 6, 2), node_masses=np.ones(3))
    data.update(over)
    data = {k: v for k, v in data.items() if v is not None}
    path = tmp_path / f"{name}.npz"
    np.savez(path, **data)
    return path


@pytest.mark.parametrize(
    "over, msg",
    [
        ({"M": np.array([[1.0, 0.2], [0.0, 1.0]])}, "'bad'.*M is not symmetric: entry \\(0, 1\\)"),
        ({"M": np.diag([1.0, -1.0])}, "M is not positive definite"),
        ({"K": np.diag([-5.0, 100.0])}, "K is indefinite"),
        ({"K": np.diag([0.0, 100.0])}, "rigid-body \\(zero-frequency\\) mode"),
        ({"modes": np.zeros((2, 6, 2))}, "modes must have shape \\(n_nodes, 6, n_coordinates\\) = \\(3, 6, 2\\), got \\(2, 6, 2\\)"),
        ({"modes": np.zeros((3, 6, 3))}, "got \\(3, 6, 3\\)"),
        ({"interface": np.array([0, 5])}, "interface node 5 does not exist \\(the body has 3 nodes"),
        ({"K": None}, "missing key 'K'"),
        ({"node_masses": None}, "needs the inertia invariants"),
        ({"units": "mm"}, "units must be 'SI'"),
        ({"M": np.array([[1.0, np.nan], [np.nan, 1.0]])}, "M has non-finite entries"),
    ],
)
def test_bad_reduced_files_are_named_errors(tmp_path, over, msg):
    with pytest.raises(ModelError, match=msg):
        el.load_reduced(_write(tmp_path, **over))


def test_unit_confusion_warning_and_bad_model_input(tmp_path):
    # stiffness in N/mm taken as N/m: frequencies far above any structure's
    with pytest.warns(UserWarning, match="'big'.*check the units"):
        el.load_reduced(_write(tmp_path, name="big", K=np.diag([4e15, 9e15])))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        el.load_reduced(_write(tmp_path, name="fine"))
    fe = el.beam_model(SEC, L, 4)
    with pytest.raises(ModelError, match="'tip': node 7 does not exist \\(the model has 5 nodes"):
        el.modal_reduction(fe, 2, fixed={7: "clamped"}, name="tip")
    with pytest.raises(ModelError, match="unknown DOF 'rq' at node 0"):
        el.modal_reduction(fe, 2, fixed={0: ["ux", "rq"]}, name="tip")
    with pytest.raises(ModelError, match="n_modes must be 1..12"):
        el.modal_reduction(el.beam_model(SEC, L, 2), 40, fixed={0: "clamped"}, name="tip")
    with pytest.raises(ModelError, match="fe_model: M is not symmetric"):
        M = np.eye(18)
        M[0, 1] = 1.0
        el.fe_model(np.zeros((3, 3)), M, np.eye(18))
    with pytest.raises(ModelError, match="must be 18x18"):
        el.fe_model(np.zeros((3, 3)), np.eye(12), np.eye(18))
    with pytest.raises(ModelError, match="BeamSection: Iy must be > 0"):
        el.BeamSection(E=1.0, G=1.0, rho=1.0, A=1.0, Iy=0.0, Iz=1.0, J=1.0)


def _direct_kinetic_energy(pos, masses, disp, vel, v, w):
    """½ Σ m_p |v + ω × (r_p + u_p) + u̇_p|² over mass points (eq. 2.192 with eq. 2.191)."""
    vp = v + np.cross(w, pos + disp) + vel
    return 0.5 * np.sum(masses * np.sum(vp * vp, axis=1))


def test_floating_frame_mass_matrix_reproduces_the_kinetic_energy():
    rng = np.random.default_rng(7)
    fe = el.beam_model(SEC, L, 12, planar=True)
    body = el.modal_reduction(fe, 4, fixed={0: "clamped"}, name="blade")
    pos, mp, interp = fe.mass_points
    T = body.modes.reshape(-1, body.n_coordinates)
    # the inertia of the mass points equals the one from the FE mass matrix (Gauss is exact),
    # except about the beam axis, where the FE model also has the section's polar inertia
    I_pts = -np.einsum("p,pij,pjk->ik", mp, np.array([skew(r) for r in pos]), np.array([skew(r) for r in pos]))
    assert I_pts[1:, 1:] == pytest.approx(body.inertia[1:, 1:], rel=1e-12, abs=1e-12)
    assert body.inertia[0, 0] - I_pts[0, 0] == pytest.approx(RHO * SEC.Ip * L, rel=1e-12)
    for _ in range(3):
        q = rng.normal(size=4) * 0.05
        qd = rng.normal(size=4)
        v = rng.normal(size=3)
        w = np.array([0.0, *rng.normal(size=2)])  # no spin about the beam axis (its polar inertia is not in the mass points)
        disp = np.einsum("pad,d->pa", interp, T @ q)
        vel = np.einsum("pad,d->pa", interp, T @ qd)
        t_direct = _direct_kinetic_energy(pos, mp, disp, vel, v, w)
        assert body.kinetic_energy(v, w, q, qd) == pytest.approx(t_direct, rel=1e-11)
    Mq = body.mass_matrix(q)
    assert np.allclose(Mq, Mq.T) and np.linalg.eigvalsh(Mq)[0] > 0
    with pytest.raises(ModelError, match="'blade': q must be 4 finite values"):
        body.mass_matrix([0.0, 1.0])


def test_lumped_invariants_from_a_file_give_the_exact_point_mass_energy(tmp_path):
    rng = np.random.default_rng(11)
    nodes = rng.normal(size=(5, 3))
    masses = rng.uniform(0.5, 2.0, size=5)
    q = 3
    modes = rng.normal(size=(5, 6, q))
    Mq = np.einsum("i,iak,ial->kl", masses, modes[:, :3], modes[:, :3])  # ∫ΦᵀΦ dm of the point masses
    path = tmp_path / "points.npz"
    np.savez(path, nodes=nodes, M=Mq, K=np.diag([1.0, 4.0, 9.0]) * 1e4, modes=modes, node_masses=masses)
    body = el.load_reduced(path)
    assert body.mass == pytest.approx(masses.sum(), rel=1e-14)
    assert body.first_moment == pytest.approx(masses @ nodes, rel=1e-13)
    assert body.M == pytest.approx(Mq, rel=1e-14)
    for _ in range(3):
        qq, qd, v, w = rng.normal(size=q), rng.normal(size=q), rng.normal(size=3), rng.normal(size=3)
        disp = np.einsum("iak,k->ia", modes[:, :3], qq)
        vel = np.einsum("iak,k->ia", modes[:, :3], qd)
        assert body.kinetic_energy(v, w, qq, qd) == pytest.approx(_direct_kinetic_energy(nodes, masses, disp, vel, v, w), rel=1e-12)


@pytest.mark.parametrize(
    "call, msg",
    [
        (lambda: el.beam_model(SEC, "1", 4), "beam_model: length must be a number, got '1'"),
        (lambda: el.beam_model(SEC, 1.0, 2.5), "n_elements must be a positive integer, got 2.5"),
        (lambda: el.BeamSection(E="a", G=1, rho=1, A=1, Iy=1, Iz=1, J=1), "BeamSection: E must be a number"),
        (lambda: el.modal_reduction(el.beam_model(SEC, L, 4), 3, fixed={"a": "clamped"}, name="b"), "'b': node 'a' is not an integer index"),
        (lambda: el.modal_reduction(el.beam_model(SEC, L, 4), 3, fixed={0: 5}, name="b"), "'b': node 0: give 'clamped', 'pinned' or a list"),
        (lambda: el.craig_bampton(el.beam_model(SEC, L, 4), 3, interface=None, fixed={0: "clamped"}, name="b"), "'b': interface must be a list"),
        (lambda: el.euler_bernoulli_mode("clamped-free", 1, [np.nan], L), "x has non-finite entries"),
        (lambda: el.rotating_cantilever_frequencies(SEC, L, 10.0, n_modes=0), "n_modes must be 1..40"),
        (lambda: el.timoshenko_pinned_pinned(1, E, SEC.G, SEC.kappa, RHO, SEC.A, SEC.Iy, -1.0), "timoshenko_pinned_pinned: L must be > 0"),
    ],
)
def test_bad_arguments_are_named_errors(call, msg):
    with pytest.raises(ModelError, match=msg):
        call()


def test_analytic_beam_body_against_closed_forms_and_the_fe_beam():
    m = RHO * SEC.A * L
    body = el.analytic_beam_body(SEC, L, "clamped-free", 4, plane="xz", name="analytic")
    w_cf = el.euler_bernoulli_roots("clamped-free", 4) ** 2 * omega_scale(SEC.Iy)
    assert body.omega == pytest.approx(w_cf, rel=1e-9)  # eigenvalues of the integrated K, M
    assert np.abs(body.M - np.eye(4)).max() < 1e-12
    assert body.mass == pytest.approx(m, rel=1e-13)
    assert np.diag(body.inertia) == pytest.approx([RHO * SEC.Ip * L, m * L**2 / 3, m * L**2 / 3], rel=1e-12)
    frac = body.Ct[2] ** 2 / body.mass
    assert frac == pytest.approx([0.6131, 0.1883, 0.0647, 0.0331], abs=6e-5)
    # the same invariants from 40 Hermite elements (x-z modes are FE modes 1, 3, 5, 7 here)
    fe = el.modal_reduction(el.beam_model(SEC, L, 40), 7, fixed={0: "clamped"}, name="fe")
    for ka, kf in ((0, 0), (1, 2)):
        s = np.sign(body.modes[-1, 2, ka] * fe.modes[-1, 2, kf])  # align the signs of the shapes
        assert s * fe.Ct[:, kf] == pytest.approx(body.Ct[:, ka], rel=1e-6, abs=1e-9)
        assert s * fe.Cr[:, kf] == pytest.approx(body.Cr[:, ka], rel=1e-6, abs=1e-9)
        assert s * fe.modes[-1, :, kf] == pytest.approx(body.modes[-1, :, ka], rel=1e-6, abs=1e-8)
        assert fe.I2[kf, kf] == pytest.approx(body.I2[ka, ka], rel=1e-6, abs=1e-9)
    # free-free elastic modes carry no momentum (mean-axis conditions), first root 4.7300
    ff = el.analytic_beam_body(SEC, L, "free-free", 2, name="ff")
    assert ff.omega[0] == pytest.approx(4.73004074486270**2 * omega_scale(SEC.Iz), rel=1e-9)
    assert np.abs(ff.Ct).max() < 1e-12 and np.abs(ff.Cr).max() < 1e-12
    with pytest.raises(ModelError, match="plane must be 'xy' or 'xz'"):
        el.analytic_beam_body(SEC, L, "clamped-free", 2, plane="yz")


def test_craig_bampton_constraint_modes_are_the_static_shapes():
    # a tip-only interface: unit tip deflection with the tip rotation held is 3 xi^2 - 2 xi^3,
    # unit tip rotation ry = -w' (tip deflection held) is L (xi^2 - xi^3): cubic, so Hermite
    # elements are exact and C_t = m/2 and m L/12
    m = RHO * SEC.A * L
    cb = el.craig_bampton(el.beam_model(SEC, L, 6), 3, interface=[-1], fixed={0: "clamped"}, name="cb")
    iw, ir = cb.labels.index("n6.uz"), cb.labels.index("n6.ry")
    assert cb.Ct[2, iw] == pytest.approx(m / 2, rel=1e-12)
    assert cb.Ct[2, ir] == pytest.approx(m * L / 12, rel=1e-12)
    xi = cb.nodes[:, 0] / L
    assert cb.modes[:, 2, iw] == pytest.approx(3 * xi**2 - 2 * xi**3, abs=1e-12)
    # the stiffness of the tip DOFs is the clamped-guided beam's: 12 EI/L^3 and 4 EI/L
    assert cb.K[iw, iw] == pytest.approx(12 * E * SEC.Iy / L**3, rel=1e-10)
    assert cb.K[ir, ir] == pytest.approx(4 * E * SEC.Iy / L, rel=1e-10)


@pytest.mark.parametrize("bc", ["clamped-free", "pinned-pinned", "free-free", "clamped-clamped", "clamped-pinned"])
def test_timoshenko_transfer_matrix_reduces_to_euler_bernoulli_roots(bc):
    # without shear flexibility (kappa G A -> infinity) and rotary inertia the boundary
    # determinant vanishes at the Euler-Bernoulli frequencies of every support case
    from scipy import optimize

    EI, rhoA = E * SEC.Iy, RHO * SEC.A
    for w_eb in el.euler_bernoulli_frequencies(bc, 3, E, SEC.Iy, RHO, SEC.A, L):
        f = lambda w: el._timoshenko_det(w, bc, EI, np.inf, rhoA, 0.0, L)  # noqa: E731
        root = optimize.brentq(f, 0.99 * w_eb, 1.01 * w_eb, xtol=1e-13 * w_eb)
        assert root == pytest.approx(w_eb, rel=1e-10)
