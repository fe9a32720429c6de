"""mechsys.kinematics: rotation parametrizations, H matrices, moving frames and model-level points.

References that do not come from our code: SciPy's ``Rotation`` (intrinsic "ZXZ" is Euler z-x-z,
intrinsic "XYZ" is Cardan x-y-z, quaternions scalar last), rotation matrices and the tilde matrix
written out in numpy here, ``scipy.linalg.expm`` for the exponential map, closed-form values, and
fourth-order central finite differences (error ~h^4, h = 1e-3) of positions and matrices.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

import mechsys as ms
from mechsys import kinematics as kin

PI = np.pi
N_RANDOM = 200


# ---- references written out here -----------------------------------------------------------------
def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def skew(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def unskew(m):
    return 0.5 * np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])


def d1(f, t, h=1e-3):
    """First derivative, fourth-order central difference."""
    return (f(t - 2 * h) - 8 * f(t - h) + 8 * f(t + h) - f(t + 2 * h)) / (12 * h)


def d2(f, t, h=1e-3):
    """Second derivative, fourth-order central difference."""
    return (-f(t - 2 * h) + 16 * f(t - h) - 30 * f(t) + 16 * f(t + h) - f(t + 2 * h)) / (12 * h * h)


def angle_dist(a, b):
    """Distance of two angles on the circle."""
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


def quat_scipy(q):
    """Our [w, x, y, z] as a SciPy rotation ([x, y, z, w])."""
    return Rotation.from_quat([q[1], q[2], q[3], q[0]])


@pytest.fixture
def rng():
    return np.random.default_rng(20240611)


def euler_samples(rng, n=N_RANDOM, margin=0.05):
    return np.column_stack(
        [rng.uniform(-PI, PI, n), rng.uniform(margin, PI - margin, n), rng.uniform(-PI, PI, n)]
    )


def cardan_samples(rng, n=N_RANDOM, margin=0.05):
    return np.column_stack(
        [rng.uniform(-PI, PI, n), rng.uniform(-PI / 2 + margin, PI / 2 - margin, n), rng.uniform(-PI, PI, n)]
    )


def random_quats(rng, n=N_RANDOM):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


# ---- elementary rotations, tilde, chain -----------------------------------------------------------
def test_elementary_rotations_match_written_out_matrices(rng):
    for a in rng.uniform(-2 * PI, 2 * PI, 50):
        np.testing.assert_allclose(kin.rot_x(a), rx(a), atol=1e-15)
        np.testing.assert_allclose(kin.rot_y(a), ry(a), atol=1e-15)
        np.testing.assert_allclose(kin.rot_z(a), rz(a), atol=1e-15)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        np.testing.assert_allclose(kin.rot_axis(axis, a), expm(skew(axis) * a), atol=1e-14)
    # rot_axis about the coordinate axes is the elementary rotation
    np.testing.assert_allclose(kin.rot_axis([0, 1, 0], 0.7), ry(0.7), atol=1e-15)
    assert isinstance(kin.rot_x(0.1), np.ndarray) and kin.rot_x(0.1).shape == (3, 3)


def test_known_rotations():
    ey, ez = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    # Cardan (pi/2, 0, 0) is a quarter turn about x: y -> z, z -> -y
    a = kin.cardan_xyz_to_matrix([PI / 2, 0.0, 0.0])
    np.testing.assert_allclose(a @ ey, ez, atol=1e-15)
    np.testing.assert_allclose(a @ ez, -ey, atol=1e-15)
    # Cardan (0, pi/2, 0): z -> x; Euler (pi/2, 0, 0): x -> y; Euler (0, pi/2, 0) = Rx(pi/2)
    np.testing.assert_allclose(kin.cardan_xyz_to_matrix([0.0, PI / 2, 0.0]) @ ez, [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(kin.euler_zxz_to_matrix([PI / 2, 0.0, 0.0]) @ [1.0, 0.0, 0.0], ey, atol=1e-15)
    np.testing.assert_allclose(kin.euler_zxz_to_matrix([0.0, PI / 2, 0.0]), rx(PI / 2), atol=1e-15)
    # a quarter turn about z as quaternion and rotation vector
    s = np.sqrt(0.5)
    np.testing.assert_allclose(kin.quat_from_axis_angle([0, 0, 1], PI / 2), [s, 0.0, 0.0, s], atol=1e-15)
    np.testing.assert_allclose(kin.matrix_to_quat(rz(PI / 2)), [s, 0.0, 0.0, s], atol=1e-15)
    np.testing.assert_allclose(kin.rotvec_to_matrix([0.0, 0.0, PI / 2]), rz(PI / 2), atol=1e-15)
    np.testing.assert_allclose(kin.matrix_to_rotvec(rx(-0.3)), [-0.3, 0.0, 0.0], atol=1e-15)
    # a 270 degree turn comes back as the shorter opposite turn
    np.testing.assert_allclose(kin.matrix_to_rotvec(rz(1.5 * PI)), [0.0, 0.0, -PI / 2], atol=1e-14)
    # half turn about x as Euler angles: theta = pi
    np.testing.assert_allclose(kin.matrix_to_euler_zxz(rx(PI)), [0.0, PI, 0.0], atol=1e-15)
    assert kin.wrap_angle(1.5 * PI) == pytest.approx(-PI / 2, abs=1e-15)
    assert kin.wrap_angle(PI) == PI
    assert kin.wrap_angle(-PI) == pytest.approx(PI, abs=1e-15)


def test_angle_sets_match_scipy_and_elementary_products(rng):
    for e in euler_samples(rng, 50):
        a = kin.euler_zxz_to_matrix(e)
        np.testing.assert_allclose(a, rz(e[0]) @ rx(e[1]) @ rz(e[2]), atol=1e-14)  # eq. 2.15
        np.testing.assert_allclose(a, Rotation.from_euler("ZXZ", e).as_matrix(), atol=1e-14)
    for c in cardan_samples(rng, 50):
        a = kin.cardan_xyz_to_matrix(c)
        np.testing.assert_allclose(a, rx(c[0]) @ ry(c[1]) @ rz(c[2]), atol=1e-14)  # eq. 2.19
        np.testing.assert_allclose(a, Rotation.from_euler("XYZ", c).as_matrix(), atol=1e-14)
    for q in random_quats(rng, 50):
        np.testing.assert_allclose(kin.quat_to_matrix(q), quat_scipy(q).as_matrix(), atol=1e-14)
        rv = quat_scipy(q).as_rotvec()
        np.testing.assert_allclose(kin.rotvec_to_matrix(rv), quat_scipy(q).as_matrix(), atol=1e-14)


def test_tilde_is_the_cross_product(rng):
    a, b = rng.normal(size=3), rng.normal(size=3)
    t = kin.tilde(a)
    np.testing.assert_allclose(t @ b, np.cross(a, b), atol=1e-15)  # eq. 2.36
    np.testing.assert_allclose(t.T, -t, atol=0)  # eq. 2.37
    np.testing.assert_allclose(kin.untilde(t), a, atol=1e-15)
    np.testing.assert_array_equal(kin.tilde([1.0, 0.0, 0.0]) @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])


def test_chain_composes_in_order(rng):
    a, b, c = rx(0.4), ry(-1.1), rz(2.2)
    np.testing.assert_allclose(kin.chain([a, b, c]), a @ b @ c, atol=1e-15)  # eq. 2.11
    np.testing.assert_allclose(kin.chain(np.stack([a, b, c])), a @ b @ c, atol=1e-15)
    np.testing.assert_array_equal(kin.chain([]), np.eye(3))
    assert np.abs(kin.chain([a, b]) - b @ a).max() > 0.1
    e = [0.1, 0.2, 0.3]
    euler = kin.chain([kin.rot_z(0.1), kin.rot_x(0.2), kin.rot_z(0.3)])
    np.testing.assert_allclose(euler, kin.euler_zxz_to_matrix(e), atol=1e-15)


# ---- round trips -------------------------------------------------------------------------------------
def test_euler_round_trips(rng):
    for e in euler_samples(rng):
        a = kin.euler_zxz_to_matrix(e)
        for back in (kin.matrix_to_euler_zxz(a), kin.quat_to_euler_zxz(kin.euler_zxz_to_quat(e)),
                     kin.rotvec_to_euler_zxz(kin.euler_zxz_to_rotvec(e))):
            assert angle_dist(back, e).max() < 1e-12, (e, back)
            assert 0.0 <= back[1] <= PI and -PI < back[0] <= PI and -PI < back[2] <= PI
        c = kin.euler_zxz_to_cardan_xyz(e)
        np.testing.assert_allclose(kin.cardan_xyz_to_matrix(c), a, atol=1e-13)
        if abs(np.cos(c[1])) > 0.05:  # away from the Cardan singularity the pair is unique
            assert angle_dist(kin.cardan_xyz_to_euler_zxz(c), e).max() < 1e-11


def test_cardan_round_trips(rng):
    for c in cardan_samples(rng):
        a = kin.cardan_xyz_to_matrix(c)
        for back in (kin.matrix_to_cardan_xyz(a), kin.quat_to_cardan_xyz(kin.cardan_xyz_to_quat(c)),
                     kin.rotvec_to_cardan_xyz(kin.cardan_xyz_to_rotvec(c))):
            assert angle_dist(back, c).max() < 1e-12, (c, back)
            assert -PI / 2 <= back[1] <= PI / 2
        e = kin.cardan_xyz_to_euler_zxz(c)
        np.testing.assert_allclose(kin.euler_zxz_to_matrix(e), a, atol=1e-13)


def test_quaternion_and_rotvec_round_trips(rng):
    for q in random_quats(rng):
        a = kin.quat_to_matrix(q)
        qb = kin.matrix_to_quat(a)
        assert qb[0] >= 0.0
        assert min(np.abs(qb - q).max(), np.abs(qb + q).max()) < 1e-13  # q and -q are one rotation
        rv = kin.quat_to_rotvec(q)
        assert np.linalg.norm(rv) <= PI * (1 + 1e-15)
        np.testing.assert_allclose(kin.rotvec_to_matrix(rv), a, atol=1e-13)
        np.testing.assert_allclose(kin.matrix_to_rotvec(a), rv, atol=1e-12)
        np.testing.assert_allclose(kin.quat_to_matrix(kin.rotvec_to_quat(rv)), a, atol=1e-13)
        np.testing.assert_allclose(kin.quat_to_rotvec(-q), rv, atol=1e-12)
        # the angle sets reproduce the matrix from any quaternion
        np.testing.assert_allclose(kin.euler_zxz_to_matrix(kin.quat_to_euler_zxz(q)), a, atol=1e-13)
        np.testing.assert_allclose(kin.cardan_xyz_to_matrix(kin.quat_to_cardan_xyz(q)), a, atol=1e-13)
        np.testing.assert_allclose(kin.euler_zxz_to_matrix(kin.matrix_to_euler_zxz(a)), a, atol=1e-13)
        np.testing.assert_allclose(kin.cardan_xyz_to_matrix(kin.matrix_to_cardan_xyz(a)), a, atol=1e-13)
    # tiny rotation vectors keep their relative accuracy
    rv = np.array([1e-9, -2e-9, 3e-10])
    np.testing.assert_allclose(kin.quat_to_rotvec(kin.rotvec_to_quat(rv)), rv, rtol=1e-12)


def test_singular_angles_still_reproduce_the_matrix():
    # at theta = 0 only psi + phi is determined, at beta = pi/2 only alpha + gamma: phi = 0, gamma = 0
    e = kin.matrix_to_euler_zxz(kin.euler_zxz_to_matrix([0.5, 0.0, 0.7]))
    np.testing.assert_allclose(e, [1.2, 0.0, 0.0], atol=1e-14)
    c = kin.matrix_to_cardan_xyz(kin.cardan_xyz_to_matrix([0.5, PI / 2, 0.7]))
    np.testing.assert_allclose(c, [1.2, PI / 2, 0.0], atol=1e-14)
    np.testing.assert_allclose(kin.cardan_xyz_to_matrix(c), kin.cardan_xyz_to_matrix([0.5, PI / 2, 0.7]), atol=1e-14)


def test_quaternion_algebra(rng):
    p, q = random_quats(rng, 2)
    a_p, a_q = kin.quat_to_matrix(p), kin.quat_to_matrix(q)
    np.testing.assert_allclose(kin.quat_to_matrix(kin.quat_mul(p, q)), a_p @ a_q, atol=1e-14)
    np.testing.assert_allclose(kin.quat_to_matrix(kin.quat_conj(q)), kin.quat_to_matrix(q).T, atol=1e-14)
    np.testing.assert_allclose(kin.quat_mul(q, kin.quat_conj(q)), [1.0, 0.0, 0.0, 0.0], atol=1e-15)
    v = rng.normal(size=3)
    np.testing.assert_allclose(kin.quat_rotate(q, v), quat_scipy(q).apply(v), atol=1e-14)
    np.testing.assert_allclose(kin.quat_normalize(3.0 * q), q, atol=1e-15)
    np.testing.assert_allclose(kin.quat_normalize([0.0, 0.0, 2.0, 0.0]), [0.0, 0.0, 1.0, 0.0], atol=0)
    with pytest.raises(ms.ModelError, match="q: .*cannot be normalized"):
        kin.quat_normalize([0.0, 0.0, 0.0, 0.0])
    # the non-normalizing conversions accept any nonzero scale
    np.testing.assert_allclose(kin.quat_to_cardan_xyz(5.0 * q), kin.quat_to_cardan_xyz(q), atol=1e-14)


# ---- H matrices (eqs. 2.30-2.34) ---------------------------------------------------------------------
H_CASES = [
    ("euler_zxz", kin.euler_zxz_to_matrix, kin.euler_h_inertial, kin.euler_h_body, kin.euler_h_inertial_inv,
     kin.euler_h_body_inv, kin.euler_rates_from_omega_inertial, kin.euler_rates_from_omega_body),
    ("cardan_xyz", kin.cardan_xyz_to_matrix, kin.cardan_h_inertial, kin.cardan_h_body, kin.cardan_h_inertial_inv,
     kin.cardan_h_body_inv, kin.cardan_rates_from_omega_inertial, kin.cardan_rates_from_omega_body),
]


def samples(name, rng, n=N_RANDOM):
    return euler_samples(rng, n) if name == "euler_zxz" else cardan_samples(rng, n)


@pytest.mark.parametrize("case", H_CASES, ids=[c[0] for c in H_CASES])
def test_h_times_h_star_is_identity(case, rng):
    name, _, h_i, h_b, h_i_inv, h_b_inv, _, _ = case
    for p in samples(name, rng):
        for h, hs in ((h_i(p), h_i_inv(p)), (h_b(p), h_b_inv(p))):
            np.testing.assert_allclose(h @ hs, np.eye(3), atol=1e-12)  # eq. 2.34
            np.testing.assert_allclose(hs @ h, np.eye(3), atol=1e-12)


@pytest.mark.parametrize("case", H_CASES, ids=[c[0] for c in H_CASES])
def test_h_matches_finite_difference_of_the_rotation_matrix(case, rng):
    """omega_I~ = A_dot A^T and omega_B~ = A^T A_dot (eq. 2.35) along p + p_dot t, A from the engine."""
    name, to_matrix, h_i, h_b, _, _, _, _ = case
    for p in samples(name, rng, 60):
        pd = rng.uniform(-2.0, 2.0, 3)
        a = to_matrix(p)
        a_dot = d1(lambda t: to_matrix(p + pd * t), 0.0)
        w_i_tilde = a_dot @ a.T
        w_b_tilde = a.T @ a_dot
        assert np.abs(w_i_tilde + w_i_tilde.T).max() < 1e-9  # skew-symmetric (eq. 2.29)
        np.testing.assert_allclose(h_i(p) @ pd, unskew(w_i_tilde), atol=1e-9)
        np.testing.assert_allclose(h_b(p) @ pd, unskew(w_b_tilde), atol=1e-9)
        # and the two are related by A_IB
        np.testing.assert_allclose(h_i(p), a @ h_b(p), atol=1e-14)


@pytest.mark.parametrize("case", H_CASES, ids=[c[0] for c in H_CASES])
def test_rates_from_omega_invert_h(case, rng):
    name, _, h_i, h_b, _, _, rates_i, rates_b = case
    for p in samples(name, rng):
        pd = rng.uniform(-3.0, 3.0, 3)
        np.testing.assert_allclose(rates_i(p, h_i(p) @ pd), pd, atol=1e-10)
        np.testing.assert_allclose(rates_b(p, h_b(p) @ pd), pd, atol=1e-10)


@pytest.mark.parametrize(
    "name, angles",
    [
        ("euler_zxz", [0.3, 0.0, -0.4]),
        ("euler_zxz", [0.3, PI, -0.4]),
        ("euler_zxz", [0.3, 1e-10, -0.4]),
        ("cardan_xyz", [0.3, PI / 2, -0.4]),
        ("cardan_xyz", [0.3, -PI / 2, -0.4]),
        ("cardan_xyz", [0.3, PI / 2 - 1e-10, 0.0]),
    ],
)
def test_singularity_is_detected(name, angles):
    _, _, h_i, h_b, h_i_inv, h_b_inv, rates_i, rates_b = next(c for c in H_CASES if c[0] == name)
    assert kin.is_near_singular(name, angles)
    assert kin.singularity_margin(name, angles) < kin.SINGULAR_TOL
    calls = [lambda: h_i_inv(angles), lambda: h_b_inv(angles), lambda: rates_i(angles, [0.1, 0.2, 0.3]),
             lambda: rates_b(angles, [0.1, 0.2, 0.3])]
    for call in calls:
        with pytest.raises(ms.SingularityError, match="singular") as info:
            call()
        assert isinstance(info.value, ValueError) and isinstance(info.value, ms.MechsysError)
        assert ("Euler" if name == "euler_zxz" else "Cardan") in str(info.value)
    # the forward H is fine there
    assert np.all(np.isfinite(h_i(angles))) and np.all(np.isfinite(h_b(angles)))


def test_just_outside_the_singularity_h_star_is_finite():
    p = [0.3, 1e-8, -0.4]
    assert not kin.is_near_singular("euler_zxz", p)
    assert kin.is_near_singular("euler_zxz", p, tol=1e-6)
    hs = kin.euler_h_body_inv(p)
    assert np.all(np.isfinite(hs)) and np.abs(hs).max() > 1e7
    assert kin.singularity_margin("cardan_xyz", [0.0, 1.0, 0.0]) == pytest.approx(np.cos(1.0), abs=1e-16)


# ---- quaternion kinematics ---------------------------------------------------------------------------
def cardan_path(t):
    return np.array([0.3 + 1.1 * t - 0.7 * t**2, -0.4 + 0.8 * t + 0.5 * t**3, 1.2 - 2.0 * t + 0.9 * t**2])


def cardan_path_rate(t):
    return np.array([1.1 - 1.4 * t, 0.8 + 1.5 * t**2, -2.0 + 1.8 * t])


def test_quaternion_derivative_matches_finite_differences():
    for t in (0.0, 0.3, 0.8):
        p, pd = cardan_path(t), cardan_path_rate(t)
        q = kin.cardan_xyz_to_quat(p)
        w_b, w_i = kin.cardan_h_body(p) @ pd, kin.cardan_h_inertial(p) @ pd
        qd_fd = d1(lambda s: kin.cardan_xyz_to_quat(cardan_path(s)), t)
        np.testing.assert_allclose(kin.quat_derivative(q, w_b), qd_fd, atol=1e-9)
        np.testing.assert_allclose(kin.quat_derivative_inertial(q, w_i), qd_fd, atol=1e-9)
        g = kin.quat_derivative_matrix(q)
        assert g.shape == (4, 3)
        np.testing.assert_allclose(g @ w_b, qd_fd, atol=1e-9)
        np.testing.assert_allclose(4.0 * g.T @ g, np.eye(3), atol=1e-15)
        np.testing.assert_allclose(kin.quat_omega_body(q, qd_fd), w_b, atol=1e-9)
        np.testing.assert_allclose(kin.quat_omega_inertial(q, qd_fd), w_i, atol=1e-9)


def test_quat_integrate_is_the_exponential_map(rng):
    q0 = kin.euler_zxz_to_quat([0.4, 1.1, -2.0])
    a0 = kin.quat_to_matrix(q0)
    for w, dt in [(rng.normal(size=3), 0.7), (np.array([0.0, 0.0, 5.0]), 0.1), (np.zeros(3), 1.0)]:
        turn = expm(skew(w) * dt)
        np.testing.assert_allclose(kin.quat_to_matrix(kin.quat_integrate(q0, w, dt)), a0 @ turn, atol=1e-13)
        np.testing.assert_allclose(kin.quat_to_matrix(kin.quat_integrate_inertial(q0, w, dt)), turn @ a0, atol=1e-13)


# ---- moving frames (eqs. 2.28, 2.38, 2.41, 2.42) ------------------------------------------------------
# A frame B turning along Cardan angles polynomial in t, its origin Q and a point P moving in it.
def frame_a(t):
    return Rotation.from_euler("XYZ", cardan_path(t)).as_matrix()  # independent of our code


def r_q(t):
    return np.array([1.0 + 0.5 * t**2, -2.0 * t, 0.3 * t**3])


def r_b(t):
    return np.array([0.4 - 0.3 * t, 0.2 + t**2, -0.5 + 0.6 * t - 0.2 * t**3])


def r_p(t):
    return r_q(t) + frame_a(t) @ r_b(t)  # eq. 2.27


def omega_i(t):
    return unskew(d1(frame_a, t) @ frame_a(t).T)


def omega_b(t):
    return unskew(frame_a(t).T @ d1(frame_a, t))


@pytest.mark.parametrize("t", [0.0, 0.35, 0.9])
def test_point_velocity_matches_finite_differences(t):
    a = frame_a(t)
    v_fd = d1(r_p, t)
    v_q, rb, rbd = d1(r_q, t), r_b(t), d1(r_b, t)
    v_i = kin.point_velocity_inertial(v_q, a, omega_i(t), rb, rbd)  # eq. 2.28
    np.testing.assert_allclose(v_i, v_fd, atol=1e-8)
    v_b = kin.point_velocity_body(a.T @ v_q, omega_b(t), rb, rbd)  # eq. 2.38
    np.testing.assert_allclose(a @ v_b, v_fd, atol=1e-8)
    # the rotational term is not negligible here
    assert np.linalg.norm(v_q + a @ rbd - v_fd) > 0.1


@pytest.mark.parametrize("t", [0.0, 0.35, 0.9])
def test_point_acceleration_matches_finite_differences(t):
    a = frame_a(t)
    acc_fd = d2(r_p, t)
    a_q, rb, rbd, rbdd = d2(r_q, t), r_b(t), d1(r_b, t), d2(r_b, t)
    w, wd = omega_b(t), d1(omega_b, t)
    acc_i = kin.point_acceleration_inertial(a_q, a, w, wd, rb, rbd, rbdd)  # eq. 2.41
    np.testing.assert_allclose(acc_i, acc_fd, atol=1e-6)
    acc_b = kin.point_acceleration_body(a.T @ a_q, w, wd, rb, rbd, rbdd)  # eq. 2.42
    np.testing.assert_allclose(acc_b, a.T @ acc_fd, atol=1e-6)
    # Coriolis and centripetal terms both matter
    assert np.linalg.norm(acc_b - 2.0 * np.cross(w, rbd) - a.T @ acc_fd) > 0.1
    assert np.linalg.norm(acc_b - np.cross(w, np.cross(w, rb)) - a.T @ acc_fd) > 0.1


def test_point_in_a_spinning_frame_has_centripetal_acceleration(rng):
    for _ in range(20):
        w_b = rng.uniform(-3.0, 3.0, 3)
        a0 = Rotation.random(random_state=rng).as_matrix()
        r = rng.normal(size=3)
        w_i = a0 @ w_b
        z = np.zeros(3)
        np.testing.assert_allclose(kin.point_velocity_inertial(z, a0, w_i, r, z), np.cross(w_i, a0 @ r), atol=1e-14)
        acc = kin.point_acceleration_inertial(z, a0, w_b, z, r, z, z)
        axis = w_i / np.linalg.norm(w_i)
        radial = a0 @ r - axis * (axis @ (a0 @ r))
        np.testing.assert_allclose(acc, -radial * (w_i @ w_i), atol=1e-12)


def cyl(t):
    """(r, phi, z) polynomial in t with first and second rates."""
    q = np.array([1.5 + 0.4 * t - 0.3 * t**2, 0.2 + 2.5 * t + 0.7 * t**2, -0.3 + t - 0.5 * t**3])
    qd = np.array([0.4 - 0.6 * t, 2.5 + 1.4 * t, 1.0 - 1.5 * t**2])
    qdd = np.array([-0.6, 1.4, -3.0 * t])
    return q, qd, qdd


@pytest.mark.parametrize("t", [0.0, 0.4, 1.1])
def test_cylindrical_coordinates_match_finite_differences(t):
    def pos(s):
        r, phi, z = cyl(s)[0]
        return np.array([r * np.cos(phi), r * np.sin(phi), z])

    (r, phi, z), (rd, pd, zd), (rdd, pdd, zdd) = cyl(t)
    np.testing.assert_allclose(kin.cylindrical_position(r, phi, z), pos(t), atol=1e-15)
    v = kin.cylindrical_velocity(r, phi, rd, pd, zd)  # eq. 2.43
    np.testing.assert_allclose(v, d1(pos, t), atol=1e-8)
    acc = kin.cylindrical_acceleration(r, phi, z, rd, pd, zd, rdd, pdd, zdd)  # eq. 2.43
    np.testing.assert_allclose(acc, d2(pos, t), atol=1e-6)
    a_bi = kin.cylindrical_a_ib(phi).T
    np.testing.assert_allclose(kin.cylindrical_a_ib(phi), rz(phi), atol=1e-15)
    np.testing.assert_allclose(kin.cylindrical_velocity_trihedral(r, rd, pd, zd), a_bi @ v, atol=1e-13)
    acc_trihedral = kin.cylindrical_acceleration_trihedral(r, rd, pd, rdd, pdd, zdd)  # eq. 2.44
    np.testing.assert_allclose(acc_trihedral, a_bi @ acc, atol=1e-13)


def test_uniform_circular_motion():
    # r = 2, phi_dot = 3: centripetal r phi_dot^2 = 18 towards the axis
    acc = kin.cylindrical_acceleration(2.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0)
    np.testing.assert_allclose(acc, [-18.0, 0.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(kin.cylindrical_velocity(2.0, PI / 2, 0.0, 3.0, 0.5), [-6.0, 0.0, 0.5], atol=1e-14)


# ---- argument checking ------------------------------------------------------------------------------
A_OK = np.eye(3)
V_OK = [0.1, 0.2, 0.3]
BAD_ARGUMENTS = [
    (kin.euler_zxz_to_matrix, ([1.0, 2.0],), "angles"),
    (kin.cardan_xyz_to_matrix, (np.zeros((3, 1)),), "angles"),
    (kin.cardan_xyz_to_matrix, ([np.nan, 0.0, 0.0],), "angles[0]"),
    (kin.euler_h_body_inv, ([0.0, np.inf, 0.0],), "angles[1]"),
    (kin.matrix_to_quat, (np.eye(2),), "a_ib"),
    (kin.matrix_to_euler_zxz, (np.ones(9),), "a_ib"),
    (kin.matrix_to_cardan_xyz, ([[1, 0, 0], [0, 1, 0], [0, 0, np.nan]],), "a_ib[2, 2]"),
    (kin.quat_to_matrix, ([1.0, 0.0, 0.0],), "q"),
    (kin.quat_to_matrix, ([2.0, 0.0, 0.0, 0.0],), "q: must be a unit quaternion"),
    (kin.quat_to_rotvec, ([0.0, 0.0, 0.0, 0.0],), "q: the zero quaternion"),
    (kin.quat_mul, ([1.0, 0.0, 0.0, 0.0], "abc"), "q"),
    (kin.quat_rotate, ([1.0, 0.0, 0.0, 0.0], [1.0, 2.0, 3.0, 4.0]), "v"),
    (kin.rot_x, ("abc",), "angle"),
    (kin.rot_y, (np.nan,), "angle"),
    (kin.rot_axis, ([1.0, 1.0, 0.0], 0.3), "axis: must be a unit vector"),
    (kin.quat_from_axis_angle, ([0.0, 0.0, 0.0], 0.3), "axis"),
    (kin.quat_integrate, ([1.0, 0.0, 0.0, 0.0], V_OK, None), "dt"),
    (kin.tilde, ([1.0, 2.0],), "a"),
    (kin.chain, (np.zeros((2, 3)),), "transforms"),
    (kin.chain, ([np.eye(3), [[np.nan] * 3] * 3],), "transforms[1][0, 0]"),
    (kin.is_near_singular, ("xyz", V_OK), "angle_set"),
    (kin.point_velocity_inertial, (V_OK, A_OK, V_OK, [1.0, 2.0], V_OK), "r_b"),
    (kin.point_velocity_inertial, (V_OK, np.eye(4), V_OK, V_OK, V_OK), "a_ib"),
    (kin.point_velocity_body, (V_OK, V_OK, V_OK, None), "rdot_b"),
    (kin.point_acceleration_body, (V_OK, V_OK, [[1.0, 2.0, 3.0]], V_OK, V_OK, V_OK), "omegadot_b"),
    (kin.point_acceleration_inertial, (V_OK, A_OK, V_OK, V_OK, V_OK, V_OK, [0, 0, np.inf]), "rddot_b[2]"),
    (kin.cylindrical_velocity, (1.0, 0.0, 0.0, [1.0, 2.0], 0.0), "phidot"),
]


@pytest.mark.parametrize("func, args, named", BAD_ARGUMENTS, ids=[f"{f.__name__}-{n}" for f, _, n in BAD_ARGUMENTS])
def test_bad_arguments_raise_value_error_naming_the_argument(func, args, named):
    with pytest.raises(ValueError) as info:
        func(*args)
    assert isinstance(info.value, ms.SettingsError), type(info.value)
    assert str(info.value).startswith(named), str(info.value)


def test_non_rotations_are_rejected_naming_the_argument():
    bad = rx(0.3)
    bad[0, 1] += 1e-3
    reflection = np.diag([1.0, 1.0, -1.0])
    for m, what in ((bad, "not orthogonal"), (reflection, "reflection")):
        for f in (kin.matrix_to_quat, kin.matrix_to_euler_zxz, kin.matrix_to_cardan_xyz, kin.matrix_to_rotvec,
                  kin.check_rotation_matrix):
            with pytest.raises(ms.ModelError, match=f"^a_ib: .*{what}"):
                f(m)
        with pytest.raises(ms.ModelError, match="^a_ib: "):
            kin.point_velocity_inertial(V_OK, m, V_OK, V_OK, V_OK)
    with pytest.raises(ms.ModelError, match="non-finite"):
        kin.check_rotation_matrix(np.full((3, 3), np.nan))
    kin.check_rotation_matrix(rx(0.3))
    kin.check_rotation_matrix(bad, tol=1e-2)
    # a slightly drifted rotation is accepted
    drift = rx(0.3)
    drift[1, 1] *= 1 + 1e-8
    np.testing.assert_allclose(kin.matrix_to_rotvec(drift), [0.3, 0.0, 0.0], atol=1e-8)


def test_inputs_may_be_lists_tuples_or_other_dtypes():
    e = (0.1, 0.2, 0.3)
    ref = kin.euler_zxz_to_matrix(np.array(e))
    np.testing.assert_array_equal(kin.euler_zxz_to_matrix(list(e)), ref)
    np.testing.assert_array_equal(kin.euler_zxz_to_matrix(e), ref)
    e32 = np.array(e, dtype=np.float32)
    np.testing.assert_array_equal(kin.euler_zxz_to_matrix(e32), kin.euler_zxz_to_matrix(e32.astype(np.float64)))
    np.testing.assert_array_equal(kin.rot_z(np.float64(0.2)), kin.rot_z(0.2))
    np.testing.assert_array_equal(kin.rot_z(1), rz(1.0))
    np.testing.assert_array_equal(kin.matrix_to_quat(np.eye(3, dtype=int)), [1.0, 0.0, 0.0, 0.0])
    # non-contiguous views
    big = np.zeros((3, 6))
    big[:, ::2] = rx(0.4)
    np.testing.assert_allclose(kin.matrix_to_rotvec(big[:, ::2]), [0.4, 0.0, 0.0], atol=1e-15)


# ---- model level: a double pendulum -----------------------------------------------------------------
L1, L2 = 0.9, 0.6


def double_pendulum(axis2=(0.0, 0.0, 1.0)):
    model = ms.Model("double-pendulum", gravity=(0.0, -9.81, 0.0))
    link1 = model.add_body("link1", mass=1.2, inertia=[0.001, 0.08, 0.08], com=(L1 / 2, 0.0, 0.0))
    link2 = model.add_body("link2", mass=0.7, inertia=[0.001, 0.02, 0.02], com=(L2 / 2, 0.0, 0.0))
    model.add_joint(ms.joints.Revolute("shoulder", parent=model.ground, child=link1, axis=(0, 0, 1)))
    model.add_joint(ms.joints.Revolute("elbow", parent=link1, child=link2, parent_frame=(L1, 0.0, 0.0), axis=axis2))
    return model, link2


def test_double_pendulum_tip_position(rng):
    model, link2 = double_pendulum()
    for q1, q2 in rng.uniform(-PI, PI, (20, 2)):
        tip = kin.point_position(model, [q1, q2], "link2", [L2, 0.0, 0.0])
        hand = L1 * np.array([np.cos(q1), np.sin(q1), 0.0]) + L2 * np.array([np.cos(q1 + q2), np.sin(q1 + q2), 0.0])
        np.testing.assert_allclose(tip, hand, atol=1e-14)
        # the body handle works as well as its name; the elbow is the origin of link 2
        elbow = kin.point_position(model, np.array([q1, q2]), link2)
        np.testing.assert_allclose(elbow, L1 * np.array([np.cos(q1), np.sin(q1), 0.0]), atol=1e-14)


def test_double_pendulum_jacobian_is_the_derivative_of_the_position(rng):
    model, _ = double_pendulum()
    for q in rng.uniform(-PI, PI, (10, 2)):
        jt, jr = kin.point_jacobian(model, q, "link2", (L2, 0.0, 0.0))
        assert jt.shape == (3, 2) and jr.shape == (3, 2)
        for k in range(2):
            dq = np.eye(2)[k]
            fd = d1(lambda s: kin.point_position(model, q + s * dq, "link2", (L2, 0.0, 0.0)), 0.0)
            np.testing.assert_allclose(jt[:, k], fd, atol=1e-10)
        q1, q2 = q
        hand = np.array([[-L1 * np.sin(q1) - L2 * np.sin(q1 + q2), -L2 * np.sin(q1 + q2)],
                         [L1 * np.cos(q1) + L2 * np.cos(q1 + q2), L2 * np.cos(q1 + q2)], [0.0, 0.0]])
        np.testing.assert_allclose(jt, hand, atol=1e-14)
        np.testing.assert_allclose(jr, [[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]], atol=1e-15)


def test_body_states_of_a_spatial_double_pendulum(rng):
    """Elbow about the link's y axis, so link 2 leaves the plane: velocities and angular velocities
    against finite differences of the positions and rotation matrices (omega_I~ = A_dot A^T)."""
    model, _ = double_pendulum(axis2=(0.0, 1.0, 0.0))
    for _ in range(5):
        q, u = rng.uniform(-PI, PI, 2), rng.uniform(-2.0, 2.0, 2)
        s = kin.body_states(model, q, u)
        assert s["body_names"] == ["ground", "link1", "link2"]
        assert s["position"].shape == (3, 3) and s["rotation"].shape == (3, 3, 3)
        np.testing.assert_allclose(s["rotation"][1], rz(q[0]), atol=1e-15)
        np.testing.assert_allclose(s["rotation"][2], rz(q[0]) @ ry(q[1]), atol=1e-15)
        np.testing.assert_allclose(s["position"][2], kin.point_position(model, q, "link2"), atol=1e-15)
        pos = lambda t: kin.body_states(model, q + t * u)["position"]  # noqa: E731
        rot = lambda t: kin.body_states(model, q + t * u)["rotation"]  # noqa: E731
        np.testing.assert_allclose(s["velocity"], d1(pos, 0.0), atol=1e-10)
        a_dot = d1(rot, 0.0)
        for i in (1, 2):
            np.testing.assert_allclose(s["angular_velocity"][i], unskew(a_dot[i] @ s["rotation"][i].T), atol=1e-10)
            jt, jr = kin.point_jacobian(model, q, s["body_names"][i])
            np.testing.assert_allclose(jt @ u, s["velocity"][i], atol=1e-14)
            np.testing.assert_allclose(jr @ u, s["angular_velocity"][i], atol=1e-14)
        # without u the body is at rest
        np.testing.assert_array_equal(kin.body_states(model, q)["velocity"], np.zeros((3, 3)))


def test_model_helpers_check_their_arguments():
    model, _ = double_pendulum()
    with pytest.raises(ms.SettingsError, match="^point"):
        kin.point_position(model, [0.1, 0.2], "link2", [1.0, 2.0])
    with pytest.raises(ms.SettingsError, match="^point"):
        kin.point_jacobian(model, [0.1, 0.2], "link2", [np.nan, 0.0, 0.0])
    with pytest.raises(ms.SettingsError, match="^q: expected length 2"):
        kin.point_position(model, [0.1], "link2")
    with pytest.raises(ms.SettingsError, match="^q"):
        kin.body_states(model, "ab")
    with pytest.raises(ms.SettingsError, match="^u"):
        kin.body_states(model, [0.1, 0.2], [1.0, np.nan])
    with pytest.raises(ms.SettingsError, match="unknown body 'link3'"):
        kin.point_jacobian(model, [0.1, 0.2], "link3")
