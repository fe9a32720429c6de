//! Small-matrix mathematics of rigid-body kinematics: the tilde operator (eqs. 2.36, 2.37),
//! rotation parametrizations and their angular-velocity matrices (eqs. 2.12–2.19, 2.30–2.34),
//! and relative kinematics of moving frames (eqs. 2.28, 2.38, 2.41–2.44).

use nalgebra::{Matrix3, Vector3};

pub mod block_sparse;
pub mod expr;
pub mod frames;
pub mod fresnel;
pub mod linalg;
pub mod quadrature;
pub mod rotation;
pub mod trig;

/// 3-vector of `f64`.
pub type Vec3 = Vector3<f64>;
/// 3×3 matrix of `f64`.
pub type Mat3 = Matrix3<f64>;

/// The skew-symmetric matrix `ã` with `ã b = a × b` (eq. 2.36).
#[inline]
pub fn tilde(a: &Vec3) -> Mat3 {
    Mat3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// The vector `a` of a skew-symmetric matrix `ã` (inverse of [`tilde`]); the symmetric part is ignored.
#[inline]
pub fn untilde(m: &Mat3) -> Vec3 {
    Vec3::new(0.5 * (m[(2, 1)] - m[(1, 2)]), 0.5 * (m[(0, 2)] - m[(2, 0)]), 0.5 * (m[(1, 0)] - m[(0, 1)]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tilde_is_cross_product_and_skew() {
        let a = Vec3::new(0.3, -1.2, 2.5);
        let b = Vec3::new(-0.7, 0.4, 1.1);
        assert!((tilde(&a) * b - a.cross(&b)).norm() < 1e-15);
        // eq. 2.37: ã^T = -ã and ã b = -b̃ a
        assert!((tilde(&a).transpose() + tilde(&a)).norm() < 1e-15);
        assert!((tilde(&a) * b + tilde(&b) * a).norm() < 1e-15);
        assert!((untilde(&tilde(&a)) - a).norm() < 1e-15);
        // a concrete component: (x̂ × ŷ) = ẑ, a sign error would flip it
        let z = tilde(&Vec3::x()) * Vec3::y();
        assert_eq!(z, Vec3::z());
    }
}
