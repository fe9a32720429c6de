"""Continuum utilities (mechsys.continuum) against closed forms: polar decomposition of stretch +
rotation and of simple shear, strain measures, small-rotation split, Hooke's law and the strain
energy of a stretched and of a bent bar."""

from __future__ import annotations

import numpy as np
import pytest

from mechsys import continuum as cm
from mechsys.errors import ModelError


def rot(axis, theta):
    """Rodrigues' formula, written independently of the module."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K


def test_stretch_then_rotation_recovered_exactly():
    lam, theta = 1.3, 0.7
    R0 = rot([1.0, 2.0, -0.5], theta)
    U0 = np.diag([lam, 1.0, 1.0])
    F = R0 @ U0
    R, U, V = cm.polar_decomposition(F)
    assert np.allclose(R, R0, atol=1e-13, rtol=0)
    assert np.allclose(U, U0, atol=1e-13, rtol=0)
    assert np.allclose(V, R0 @ U0 @ R0.T, atol=1e-13, rtol=0)
    assert np.allclose(R @ U, F, atol=1e-14) and np.allclose(V @ R, F, atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)
    # Green-Lagrange: only G_xx = (lam^2 - 1)/2 (reference frame, rotation drops out)
    G = cm.green_lagrange(F)
    assert np.allclose(G, np.diag([(lam**2 - 1) / 2, 0, 0]), atol=1e-14)
    # Euler-Almansi: (1 - 1/lam^2)/2 along the rotated stretch direction
    e = cm.euler_almansi(F)
    n = R0[:, 0]
    assert np.allclose(e, 0.5 * (1 - lam**-2) * np.outer(n, n), atol=1e-14)


def test_simple_shear_polar_closed_form():
    g = 0.8
    F = np.array([[1.0, g, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    R, U, V = cm.polar_decomposition(F)
    s = np.sqrt(4 + g * g)
    # closed form: rotation about -z by atan(g/2); U = [[2, g], [g, 2 + g^2]] / sqrt(4 + g^2)
    R_ref = np.array([[2 / s, g / s, 0], [-g / s, 2 / s, 0], [0, 0, 1]])
    U_ref = np.array([[2 / s, g / s, 0], [g / s, (2 + g * g) / s, 0], [0, 0, 1]])
    V_ref = np.array([[(2 + g * g) / s, g / s, 0], [g / s, 2 / s, 0], [0, 0, 1]])
    assert np.allclose(R, R_ref, atol=1e-14)
    assert np.allclose(U, U_ref, atol=1e-14)
    assert np.allclose(V, V_ref, atol=1e-14)
    G = cm.green_lagrange(F)
    assert np.allclose(G, [[0, g / 2, 0], [g / 2, g * g / 2, 0], [0, 0, 0]], atol=1e-15)
    # linear strain misses the quadratic term g^2/2 in G_yy (eq. 2.141 without brackets)
    eps, omega = cm.small_strain(F - np.eye(3))
    assert np.allclose(eps, [[0, g / 2, 0], [g / 2, 0, 0], [0, 0, 0]], atol=1e-15)
    assert np.allclose(cm.rotation_vector(F - np.eye(3)), [0, 0, -g / 2], atol=1e-15)
    assert np.allclose(omega, cm.skew([0, 0, -g / 2]), atol=1e-15)


def test_pure_rotation_no_green_strain_but_linear_strain_of_order_theta_squared():
    axis = np.array([0.0, 0.0, 1.0])
    for theta in (1e-1, 1e-2, 1e-3):
        F = rot(axis, theta)
        assert np.abs(cm.green_lagrange(F)).max() < 1e-15
        eps, omega = cm.small_strain(F - np.eye(3))
        # eps = (cos(theta) - 1) in the plane of rotation: -theta^2/2 to leading order
        assert eps[0, 0] == pytest.approx(np.cos(theta) - 1, rel=1e-9, abs=1e-17)
        assert eps[0, 0] / theta**2 == pytest.approx(-0.5, rel=theta**2)
        assert abs(eps[2, 2]) < 1e-16
        # the small-rotation vector (eq. 2.145) is sin(theta) about the axis -> theta for small theta
        phi = cm.rotation_vector(F - np.eye(3))
        assert np.allclose(phi, np.sin(theta) * axis, atol=1e-16)


def test_deformation_gradient_by_differences_and_exact():
    A = np.array([[0.1, -0.2, 0.05], [0.03, 0.02, 0.1], [-0.07, 0.0, 0.04]])

    def u(X):
        x, y, z = X
        return A @ X + np.array([0.01 * x * x * y, 0.02 * y * z, 0.005 * x**3])

    def grad(X):
        x, y, z = X
        return A + np.array([[0.02 * x * y, 0.01 * x * x, 0], [0, 0.02 * z, 0.02 * y], [0.015 * x * x, 0, 0]])

    X = np.array([0.4, -1.2, 2.0])
    F_exact = cm.deformation_gradient(u, X, grad=grad)
    F_fd = cm.deformation_gradient(u, X)
    assert np.allclose(F_fd, F_exact, atol=1e-11, rtol=0)
    assert np.allclose(F_exact, np.eye(3) + grad(X), atol=0)


def test_linear_elements_reproduce_homogeneous_deformation():
    A = np.array([[0.1, -0.2, 0.05], [0.03, 0.02, 0.1], [-0.07, 0.0, 0.04]])
    b = np.array([0.3, -0.1, 0.2])
    Xt = np.array([[0, 0, 0], [1.0, 0.1, 0], [0.2, 0.9, 0.1], [0.1, 0.2, 1.1]])
    assert np.allclose(cm.tet4_deformation_gradient(Xt, Xt @ A.T + b), np.eye(3) + A, atol=1e-14)
    # a distorted hexahedron under the same homogeneous field, at a few points
    Xh = cm._HEX * np.array([0.5, 0.4, 0.3]) + np.array([1, 2, 3]) + 0.03 * np.sin(np.arange(24)).reshape(8, 3)
    for xi in ([0, 0, 0], [0.5, -0.3, 0.9], [-1, 1, -1]):
        assert np.allclose(cm.hex8_deformation_gradient(Xh, Xh @ A.T + b, xi), np.eye(3) + A, atol=1e-13)
    with pytest.raises(ModelError, match="degenerate tetrahedron"):
        cm.tet4_deformation_gradient(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0.0]]), np.zeros((4, 3)))
    with pytest.raises(ModelError, match="det\\(dX/dxi\\)"):
        cm.hex8_deformation_gradient(Xh[[1, 0, 3, 2, 5, 4, 7, 6]], np.zeros((8, 3)))


def test_invalid_deformation_gradients_are_named_errors():
    with pytest.raises(ModelError, match="polar_decomposition: det F = -1"):
        cm.polar_decomposition(np.diag([1.0, 1.0, -1.0]))  # a reflection
    with pytest.raises(ModelError, match="green_lagrange: det F = 0"):
        cm.green_lagrange(np.diag([1.0, 0.0, 1.0]))
    with pytest.raises(ModelError, match="non-finite"):
        cm.euler_almansi(np.array([[1.0, np.nan, 0], [0, 1, 0], [0, 0, 1]]))
    with pytest.raises(ModelError, match="3x3"):
        cm.small_strain(np.eye(2))
    with pytest.raises(ModelError, match="u\\("):
        cm.deformation_gradient(lambda X: np.array([np.nan, 0, 0]), [0, 0, 0])


def test_material_constants_conversions_and_validation():
    E, nu = 210e9, 0.3
    m = cm.isotropic(E=E, nu=nu)
    assert m.G == pytest.approx(E / 2.6, rel=1e-14)
    assert m.lam == pytest.approx(E * 0.3 / (1.3 * 0.4), rel=1e-14)
    assert m.K == pytest.approx(E / (3 * (1 - 2 * nu)), rel=1e-13)
    for kw in ({"E": E, "G": m.G}, {"lam": m.lam, "mu": m.G}, {"nu": nu, "G": m.G}, {"nu": nu, "lam": m.lam}, {"E": E, "lam": m.lam}, {"E": E, "nu": nu, "G": m.G, "lam": m.lam}):
        m2 = cm.isotropic(**kw)
        assert (m2.E, m2.nu, m2.G, m2.lam) == pytest.approx((E, nu, m.G, m.lam), rel=1e-12)
    # auxetic material: lam < 0 is valid
    assert cm.isotropic(E=1.0, nu=-0.5).lam < 0
    for kw, msg in (
        ({"E": E, "nu": 0.5}, "nu must lie in \\(-1, 0.5\\), got 0.5"),
        ({"E": E, "nu": -1.0}, "nu must lie"),
        ({"E": -1.0, "nu": 0.3}, "E must be > 0"),
        ({"G": 0.0, "nu": 0.3}, "G must be > 0"),
        ({"E": E, "G": 0.3 * E}, "nu = 0.666"),
        ({"E": E, "nu": nu, "G": 80e9}, "G = 80000000000.0 is inconsistent with E"),
        ({"G": 1e9, "mu": 2e9}, "G = 1000000000.0 and mu"),
        ({"E": E}, "got only \\['E'\\]"),
        ({"E": float("nan"), "nu": 0.3}, "E must be finite"),
        ({"E": "210e9", "nu": 0.3}, "E must be a number, got .210e9."),
        ({"E": E, "G": "x"}, "G must be a number"),
    ):
        with pytest.raises(ModelError, match=msg):
            cm.isotropic(**kw)


def test_hooke_law_and_energy_density_forms_agree():
    m = cm.isotropic(E=70e9, nu=0.33)
    rng = np.random.default_rng(3)
    A = rng.normal(size=(3, 3)) * 1e-3
    eps = 0.5 * (A + A.T)
    sig = m.stress(eps)
    assert np.allclose(m.strain(sig), eps, atol=1e-18, rtol=1e-12)
    # eq. 2.195 written out for the xx component
    assert eps[0, 0] == pytest.approx((sig[0, 0] - m.nu * (sig[1, 1] + sig[2, 2])) / m.E, rel=1e-12)
    assert eps[0, 1] == pytest.approx(sig[0, 1] / (2 * m.G), rel=1e-12)  # eq. 2.196
    W1 = m.energy_density(eps)
    W2 = m.energy_density_from_stress(sig)
    W3 = (sig[0, 0] ** 2 + sig[1, 1] ** 2 + sig[2, 2] ** 2) / (2 * m.E) - m.nu / m.E * (
        sig[0, 0] * sig[1, 1] + sig[1, 1] * sig[2, 2] + sig[2, 2] * sig[0, 0]
    ) + (sig[0, 1] ** 2 + sig[1, 2] ** 2 + sig[2, 0] ** 2) / (2 * m.G)  # eq. 2.198
    assert W1 == pytest.approx(W2, rel=1e-12) and W1 == pytest.approx(W3, rel=1e-12)
    with pytest.raises(ModelError, match="strain must be symmetric"):
        m.stress(A)


def test_energy_of_stretched_and_bent_bar():
    E, nu = 200e9, 0.28
    m = cm.isotropic(E=E, nu=nu)
    L, b, h, e0 = 2.0, 0.03, 0.05, 1e-3
    uniax = np.diag([e0, -nu * e0, -nu * e0])  # uniaxial stress state
    V = cm.strain_energy_beam(lambda X: uniax, m, L, ("rect", b, h))
    assert V == pytest.approx(0.5 * E * b * h * L * e0**2, rel=1e-13)
    r = 0.02
    Vc = cm.strain_energy_beam(lambda X: uniax, m, L, ("circle", r))
    assert Vc == pytest.approx(0.5 * E * np.pi * r * r * L * e0**2, rel=1e-13)
    # pure bending, curvature k about z: eps_xx = -k y, lateral -nu eps_xx -> V = E I k^2 L / 2
    k = 0.01

    def bend(X):
        exx = -k * X[1]
        return np.diag([exx, -nu * exx, -nu * exx])

    assert cm.strain_energy_beam(bend, m, L, ("rect", b, h)) == pytest.approx(0.5 * E * h * b**3 / 12 * k * k * L, rel=1e-12)
    assert cm.strain_energy_beam(bend, m, L, ("circle", r)) == pytest.approx(0.5 * E * np.pi * r**4 / 4 * k * k * L, rel=1e-12)
    # the same bar as a box, and a bad section
    assert cm.strain_energy_box(lambda X: uniax, m, ((0, L), (0, b), (0, h))) == pytest.approx(V, rel=1e-13)
    with pytest.raises(ModelError, match="section must be"):
        cm.strain_energy_beam(lambda X: uniax, m, L, ("rect", b, -h))
    with pytest.raises(ModelError, match="bounds must be"):
        cm.strain_energy_box(lambda X: uniax, m, ((0, L), (1, 0), (0, h)))


def test_finite_differences_then_polar_decomposition_of_a_general_field():
    R0 = rot([0.3, -1.0, 0.4], 1.1)
    Q = rot([1.0, 1.0, 0.0], 0.4)
    U0 = Q @ np.diag([1.2, 0.9, 1.05]) @ Q.T  # stretch with principal axes off the coordinates
    F0 = R0 @ U0
    F = cm.deformation_gradient(lambda X: (F0 - np.eye(3)) @ X + np.array([1.0, 2.0, 3.0]), [0.5, -0.2, 0.1])
    assert np.allclose(F, F0, atol=1e-12)
    R, U, V = cm.polar_decomposition(F)
    assert np.allclose(R, R0, atol=1e-11) and np.allclose(U, U0, atol=1e-11)
    assert np.allclose(V, R0 @ U0 @ R0.T, atol=1e-11)
    # U and V share the principal stretches; e = F^-T G F^-1 (push-forward of the Green strain)
    assert np.allclose(np.linalg.eigvalsh(U), [0.9, 1.05, 1.2], atol=1e-11)
    assert np.allclose(np.linalg.eigvalsh(V), [0.9, 1.05, 1.2], atol=1e-11)
    Fi = np.linalg.inv(F)
    assert np.allclose(cm.euler_almansi(F), Fi.T @ cm.green_lagrange(F) @ Fi, atol=1e-14)
    assert np.allclose(cm.green_lagrange(F), 0.5 * (U0 @ U0 - np.eye(3)), atol=1e-11)
