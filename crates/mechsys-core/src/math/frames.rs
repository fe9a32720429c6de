//! Relative kinematics of moving frames.
//!
//! A point `P` is located from the origin `Q` of a moving frame `B` by `r = r_QP`, given in
//! B-components `r_b`, so that `r_OP,i = r_OQ,i + A_IB r_b` (eq. 2.27). Differentiating in the
//! inertial frame, with `Ȧ_IB = ω̃_I A_IB` (eq. 2.35), gives the velocity and acceleration of `P`
//! in inertial (eqs. 2.28, 2.41) or body components (eqs. 2.38, 2.42):
//!
//! ```text
//! v_P = v_Q + ω × r + ṙ                               (2.28, 2.38)
//! a_P = a_Q + ω̇ × r + ω × (ω × r) + 2 ω × ṙ + r̈        (2.41, 2.42)
//! ```
//!
//! where `ṙ`, `r̈` are the rates of the B-components of `r` (the motion relative to `B`) and `ω̇`
//! the rate of `ω_B`. The terms are, in order, the motion of the reference point, the angular
//! (Euler), centripetal, Coriolis and relative accelerations.
//!
//! Cylindrical coordinates `(r, φ, z)` with `(x, y, z) = (r cos φ, r sin φ, z)` are a special
//! moving frame: the trihedral of radial, circumferential and axial unit vectors,
//! `A_IB = Rz(φ)` (eqs. 2.43, 2.44). Successive frames compose by matrix products (eqs. 2.10,
//! 2.11), see [`chain`].

use super::{rotation::rot_z, Mat3, Vec3};

/// Product `A_12 A_23 ⋯ A_(n−1)n` of a chain of transformations, giving `A_1n` (eqs. 2.10, 2.11);
/// the identity for an empty chain.
///
/// # Example
/// ```
/// use mechsys_core::math::{frames::chain, rotation::{euler_zxz_to_matrix, rot_x, rot_z}};
/// // A_IB = A_I,ψ A_nodal,ϑ A_B,φ (eq. 2.15)
/// let a = chain(&[rot_z(0.1), rot_x(0.2), rot_z(0.3)]);
/// assert!((a - euler_zxz_to_matrix([0.1, 0.2, 0.3])).norm() < 1e-15);
/// ```
pub fn chain(transforms: &[Mat3]) -> Mat3 {
    // eq. 2.11
    transforms.iter().fold(Mat3::identity(), |acc, a| acc * a)
}

/// Absolute velocity of `P` in I-components (eq. 2.28 with `Ȧ_IB = ω̃_I A_IB`, eq. 2.35).
///
/// - `v_q_i`: absolute velocity of the frame origin `Q`, I-components;
/// - `a_ib`: orientation of `B`, mapping B- to I-components;
/// - `omega_i`: angular velocity of `B` relative to `I`, I-components;
/// - `r_b`: position of `P` relative to `Q`, B-components;
/// - `rdot_b`: time derivative of `r_b` (velocity of `P` relative to `B`), B-components.
#[inline]
pub fn point_velocity_inertial(v_q_i: &Vec3, a_ib: &Mat3, omega_i: &Vec3, r_b: &Vec3, rdot_b: &Vec3) -> Vec3 {
    // eq. 2.28: v_Q + Ȧ_IB r_B + A_IB ṙ_B, with Ȧ_IB r_B = ω̃_I (A_IB r_B)
    v_q_i + omega_i.cross(&(a_ib * r_b)) + a_ib * rdot_b
}

/// Absolute velocity of `P` in B-components (eq. 2.38).
///
/// - `v_q_b`: absolute velocity of the frame origin `Q`, B-components (`A_BI v_Q,I`);
/// - `omega_b`: angular velocity of `B` relative to `I`, B-components;
/// - `r_b`: position of `P` relative to `Q`, B-components;
/// - `rdot_b`: time derivative of `r_b`, B-components.
#[inline]
pub fn point_velocity_body(v_q_b: &Vec3, omega_b: &Vec3, r_b: &Vec3, rdot_b: &Vec3) -> Vec3 {
    // eq. 2.38: v_Q + ω̃_B r + ṙ
    v_q_b + omega_b.cross(r_b) + rdot_b
}

/// Absolute acceleration of `P` in I-components (eq. 2.41).
///
/// - `a_q_i`: absolute acceleration of the frame origin `Q`, I-components;
/// - `a_ib`: orientation of `B`, mapping B- to I-components;
/// - `omega_b`: angular velocity of `B` relative to `I`, B-components;
/// - `omegadot_b`: time derivative of `omega_b` (equal to `A_BI ω̇_I`), B-components;
/// - `r_b`: position of `P` relative to `Q`, B-components;
/// - `rdot_b`, `rddot_b`: first and second time derivatives of `r_b`, B-components.
#[inline]
pub fn point_acceleration_inertial(
    a_q_i: &Vec3,
    a_ib: &Mat3,
    omega_b: &Vec3,
    omegadot_b: &Vec3,
    r_b: &Vec3,
    rdot_b: &Vec3,
    rddot_b: &Vec3,
) -> Vec3 {
    // eq. 2.41: a_Q + A_IB (ω̇̃ r + ω̃ ω̃ r) + A_IB (2 ω̃ ṙ + r̈)
    a_q_i + a_ib * relative_acceleration_terms(omega_b, omegadot_b, r_b, rdot_b, rddot_b)
}

/// Absolute acceleration of `P` in B-components (eq. 2.42).
///
/// - `a_q_b`: absolute acceleration of the frame origin `Q`, B-components (`A_BI a_Q,I`);
/// - `omega_b`: angular velocity of `B` relative to `I`, B-components;
/// - `omegadot_b`: time derivative of `omega_b`, B-components;
/// - `r_b`: position of `P` relative to `Q`, B-components;
/// - `rdot_b`, `rddot_b`: first and second time derivatives of `r_b`, B-components.
#[inline]
pub fn point_acceleration_body(
    a_q_b: &Vec3,
    omega_b: &Vec3,
    omegadot_b: &Vec3,
    r_b: &Vec3,
    rdot_b: &Vec3,
    rddot_b: &Vec3,
) -> Vec3 {
    // eq. 2.42
    a_q_b + relative_acceleration_terms(omega_b, omegadot_b, r_b, rdot_b, rddot_b)
}

/// Angular, centripetal, Coriolis and relative terms of eqs. 2.41/2.42, B-components.
#[inline]
fn relative_acceleration_terms(omega_b: &Vec3, omegadot_b: &Vec3, r_b: &Vec3, rdot_b: &Vec3, rddot_b: &Vec3) -> Vec3 {
    omegadot_b.cross(r_b) + omega_b.cross(&omega_b.cross(r_b)) + 2.0 * omega_b.cross(rdot_b) + rddot_b
}

/// Position `(r cos φ, r sin φ, z)` of cylindrical coordinates, I-components.
#[inline]
pub fn cylindrical_position(r: f64, phi: f64, z: f64) -> Vec3 {
    let (s, c) = phi.sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// Velocity of a point given in cylindrical coordinates, I-components (eq. 2.43, first part).
///
/// `r`, `phi`: radius and azimuth; `rdot`, `phidot`, `zdot`: their rates and that of the height.
#[inline]
pub fn cylindrical_velocity(r: f64, phi: f64, rdot: f64, phidot: f64, zdot: f64) -> Vec3 {
    let (s, c) = phi.sin_cos();
    // eq. 2.43
    Vec3::new(rdot * c - r * phidot * s, rdot * s + r * phidot * c, zdot)
}

/// Acceleration of a point given in cylindrical coordinates, I-components (eq. 2.43).
///
/// `r`, `phi`, `z`: coordinates; `rdot`, `phidot`, `zdot`: first and `rddot`, `phiddot`,
/// `zddot`: second time derivatives. The height enters only through `zddot`; `z` and `zdot` are
/// accepted so that the arguments are the full state and do not change the result.
#[allow(clippy::too_many_arguments)] // the nine scalars of (q, q̇, q̈) read clearer than three arrays
#[inline]
pub fn cylindrical_acceleration(
    r: f64,
    phi: f64,
    z: f64,
    rdot: f64,
    phidot: f64,
    zdot: f64,
    rddot: f64,
    phiddot: f64,
    zddot: f64,
) -> Vec3 {
    let _ = (z, zdot);
    let (s, c) = phi.sin_cos();
    let w2 = phidot * phidot;
    // eq. 2.43
    Vec3::new(
        rddot * c - 2.0 * rdot * phidot * s - r * phiddot * s - r * w2 * c,
        rddot * s + 2.0 * rdot * phidot * c + r * phiddot * c - r * w2 * s,
        zddot,
    )
}

/// Orientation `A_IB = Rz(φ)` of the cylindrical trihedral (radial, circumferential, axial unit
/// vectors as columns); its transpose is the `A_BI` of eq. 2.44.
#[inline]
pub fn cylindrical_a_ib(phi: f64) -> Mat3 {
    rot_z(phi)
}

/// Velocity of a point in cylindrical coordinates, in the components of the cylindrical
/// trihedral: `(ṙ, r φ̇, ż)` (`A_BI` times eq. 2.43).
#[inline]
pub fn cylindrical_velocity_trihedral(r: f64, rdot: f64, phidot: f64, zdot: f64) -> Vec3 {
    Vec3::new(rdot, r * phidot, zdot)
}

/// Acceleration of a point in cylindrical coordinates, in the components of the cylindrical
/// trihedral: `(r̈ − r φ̇², 2 ṙ φ̇ + r φ̈, z̈)` (eq. 2.44).
#[inline]
pub fn cylindrical_acceleration_trihedral(
    r: f64,
    rdot: f64,
    phidot: f64,
    rddot: f64,
    phiddot: f64,
    zddot: f64,
) -> Vec3 {
    // eq. 2.44
    Vec3::new(rddot - r * phidot * phidot, 2.0 * rdot * phidot + r * phiddot, zddot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rotation::tests::{d1, d2, Rng};
    use crate::math::rotation::{
        cardan_h_body, cardan_h_inertial, cardan_xyz_to_matrix, euler_zxz_to_matrix, rot_x, rot_y,
    };
    use std::f64::consts::PI;

    /// Cardan angles of the moving frame: polynomials in t.
    fn angles(t: f64) -> [f64; 3] {
        [0.3 + 1.1 * t - 0.7 * t * t, -0.4 + 0.8 * t + 0.5 * t * t * t, 1.2 - 2.0 * t + 0.9 * t * t]
    }

    fn angle_rates(t: f64) -> Vec3 {
        Vec3::new(1.1 - 1.4 * t, 0.8 + 1.5 * t * t, -2.0 + 1.8 * t)
    }

    fn a_ib(t: f64) -> Mat3 {
        cardan_xyz_to_matrix(angles(t))
    }

    fn omega_b(t: f64) -> Vec3 {
        cardan_h_body(angles(t)) * angle_rates(t)
    }

    fn omega_i(t: f64) -> Vec3 {
        cardan_h_inertial(angles(t)) * angle_rates(t)
    }

    /// Origin of the moving frame, I-components, with its derivatives.
    fn r_q(t: f64) -> (Vec3, Vec3, Vec3) {
        (
            Vec3::new(1.0 + 0.5 * t * t, -2.0 * t, 0.3 * t * t * t),
            Vec3::new(t, -2.0, 0.9 * t * t),
            Vec3::new(1.0, 0.0, 1.8 * t),
        )
    }

    /// The point relative to the origin, B-components, with its derivatives.
    fn r_b(t: f64) -> (Vec3, Vec3, Vec3) {
        (
            Vec3::new(0.4 - 0.3 * t, 0.2 + t * t, -0.5 + 0.6 * t - 0.2 * t * t * t),
            Vec3::new(-0.3, 2.0 * t, 0.6 - 0.6 * t * t),
            Vec3::new(0.0, 2.0, -1.2 * t),
        )
    }

    /// Position of P in I-components (eq. 2.27).
    fn r_p(t: f64) -> Vec3 {
        r_q(t).0 + a_ib(t) * r_b(t).0
    }

    #[test]
    fn chain_composes_frames() {
        assert_eq!(chain(&[]), Mat3::identity());
        let (a, b, c) = (rot_x(0.4), rot_y(-1.1), rot_z(2.2));
        assert!((chain(&[a, b, c]) - a * b * c).amax() < 1e-15);
        // order matters: A_IB = A_IR A_RB, not A_RB A_IR
        assert!((chain(&[a, b]) - b * a).amax() > 0.1);
        assert!((chain(&[rot_z(0.1), rot_x(0.2), rot_z(0.3)]) - euler_zxz_to_matrix([0.1, 0.2, 0.3])).amax() < 1e-15);
        assert!((chain(&[rot_x(0.1), rot_y(0.2), rot_z(0.3)]) - cardan_xyz_to_matrix([0.1, 0.2, 0.3])).amax() < 1e-15);
    }

    #[test]
    fn point_velocity_matches_finite_differences() {
        for t in [0.0, 0.35, 0.9] {
            let v_fd = d1(r_p, t, 1e-3);
            let (_, v_q, _) = r_q(t);
            let (r, rd, _) = r_b(t);
            let a = a_ib(t);
            let v_i = point_velocity_inertial(&v_q, &a, &omega_i(t), &r, &rd);
            assert!((v_i - v_fd).norm() < 1e-9, "{v_i} {v_fd}");
            let v_b = point_velocity_body(&(a.transpose() * v_q), &omega_b(t), &r, &rd);
            assert!((a * v_b - v_fd).norm() < 1e-9, "{v_b}");
            // the rotational term matters here: dropping it misses by far more than the tolerance
            assert!((v_q + a * rd - v_fd).norm() > 0.1);
        }
    }

    #[test]
    fn point_acceleration_matches_finite_differences() {
        for t in [0.0, 0.35, 0.9] {
            let acc_fd = d2(r_p, t, 1e-3);
            let (_, _, a_q) = r_q(t);
            let (r, rd, rdd) = r_b(t);
            let a = a_ib(t);
            let w = omega_b(t);
            let wd = d1(omega_b, t, 1e-3);
            let acc_i = point_acceleration_inertial(&a_q, &a, &w, &wd, &r, &rd, &rdd);
            assert!((acc_i - acc_fd).norm() < 1e-6, "{acc_i} {acc_fd}");
            let acc_b = point_acceleration_body(&(a.transpose() * a_q), &w, &wd, &r, &rd, &rdd);
            assert!((acc_b - a.transpose() * acc_fd).norm() < 1e-6, "{acc_b}");
            // ω̇_B = A_BI ω̇_I
            assert!((wd - a.transpose() * d1(omega_i, t, 1e-3)).norm() < 1e-8);
            // each of the Coriolis and centripetal terms is needed
            let no_coriolis = acc_b - 2.0 * w.cross(&rd);
            let no_centripetal = acc_b - w.cross(&w.cross(&r));
            assert!((no_coriolis - a.transpose() * acc_fd).norm() > 0.1);
            assert!((no_centripetal - a.transpose() * acc_fd).norm() > 0.1);
        }
    }

    #[test]
    fn random_moving_frames() {
        // frames spinning at constant rates about random axes with points fixed in them:
        // the relative terms vanish and a_P = a_Q + ω × (ω × r) in closed form
        let mut rng = Rng::new(21);
        for _ in 0..20 {
            let w_b = rng.vec3(3.0);
            let a0 = cardan_xyz_to_matrix([rng.uniform(-PI, PI), rng.uniform(-1.5, 1.5), rng.uniform(-PI, PI)]);
            let r = rng.vec3(1.0);
            let w_i = a0 * w_b;
            let v = point_velocity_inertial(&Vec3::zeros(), &a0, &w_i, &r, &Vec3::zeros());
            assert!((v - w_i.cross(&(a0 * r))).norm() < 1e-14);
            let acc = point_acceleration_inertial(
                &Vec3::zeros(),
                &a0,
                &w_b,
                &Vec3::zeros(),
                &r,
                &Vec3::zeros(),
                &Vec3::zeros(),
            );
            // centripetal: pointing towards the axis, magnitude |ω|² times the distance from it
            let r_i = a0 * r;
            let axis = w_i.normalize();
            let radial = r_i - axis * axis.dot(&r_i);
            assert!((acc + radial * w_i.norm_squared()).norm() < 1e-12);
        }
    }

    fn cyl(t: f64) -> (f64, f64, f64, f64, f64, f64, f64, f64, f64) {
        let r = 1.5 + 0.4 * t - 0.3 * t * t;
        let phi = 0.2 + 2.5 * t + 0.7 * t * t;
        let z = -0.3 + t - 0.5 * t * t * t;
        (r, phi, z, 0.4 - 0.6 * t, 2.5 + 1.4 * t, 1.0 - 1.5 * t * t, -0.6, 1.4, -3.0 * t)
    }

    #[test]
    fn cylindrical_coordinates_match_finite_differences() {
        let pos = |t: f64| {
            let c = cyl(t);
            cylindrical_position(c.0, c.1, c.2)
        };
        for t in [0.0, 0.4, 1.1] {
            let (r, phi, z, rd, pd, zd, rdd, pdd, zdd) = cyl(t);
            let v = cylindrical_velocity(r, phi, rd, pd, zd);
            assert!((v - d1(pos, t, 1e-3)).norm() < 1e-9, "{v}");
            let a = cylindrical_acceleration(r, phi, z, rd, pd, zd, rdd, pdd, zdd);
            assert!((a - d2(pos, t, 1e-3)).norm() < 1e-6, "{a}");
            // eq. 2.44: the same vectors in the trihedral
            let a_bi = cylindrical_a_ib(phi).transpose();
            assert!((cylindrical_acceleration_trihedral(r, rd, pd, rdd, pdd, zdd) - a_bi * a).norm() < 1e-13);
            assert!((cylindrical_velocity_trihedral(r, rd, pd, zd) - a_bi * v).norm() < 1e-13);
            // the trihedral is a moving frame with ω = φ̇ e_z: eq. 2.42 with r_b = (r, 0, 0)
            let w = Vec3::new(0.0, 0.0, pd);
            let wd = Vec3::new(0.0, 0.0, pdd);
            let a_b = point_acceleration_body(
                &Vec3::new(0.0, 0.0, zdd),
                &w,
                &wd,
                &Vec3::new(r, 0.0, 0.0),
                &Vec3::new(rd, 0.0, 0.0),
                &Vec3::new(rdd, 0.0, 0.0),
            );
            assert!((a_b - a_bi * a).norm() < 1e-13);
        }
        // uniform circular motion: centripetal acceleration r φ̇² towards the axis
        let a = cylindrical_acceleration(2.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0);
        assert!((a - Vec3::new(-18.0, 0.0, 0.0)).norm() < 1e-14);
        let v = cylindrical_velocity(2.0, PI / 2.0, 0.0, 3.0, 0.5);
        assert!((v - Vec3::new(-6.0, 0.0, 0.5)).norm() < 1e-14);
        // z and ż do not enter the acceleration
        assert_eq!(
            cylindrical_acceleration(1.0, 0.3, 5.0, 0.2, 0.7, -4.0, 0.1, 0.2, 0.3),
            cylindrical_acceleration(1.0, 0.3, -1.0, 0.2, 0.7, 9.0, 0.1, 0.2, 0.3)
        );
    }
}
