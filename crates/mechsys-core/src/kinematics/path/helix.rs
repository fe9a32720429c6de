//! The circular helix `r(φ) = (R cos φ, R sin φ, c φ)` about the z-axis of the joint frame
//! (c = pitch / 2π; c = 0: a circle). With `L = √(R² + c²)`, `φ = s / L` and
//! `t = (−R sin φ, R cos φ, c) / L`, `n = (−cos φ, −sin φ, 0)`, `b = (c sin φ, −c cos φ, R) / L`,
//! `κ = R / L²`, `τ = c / L²`, both constant. The closed forms are generic over the scalar, so
//! they are exact for dual numbers of any order.

use nalgebra::{Matrix3, Vector3};
use num_dual::DualNum;

use super::{PathLocal, PathPoint};
use crate::math::Vec3;

/// A circular helix about z (a circle when `lead` is zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Helix {
    /// Radius R (m), > 0.
    pub radius: f64,
    /// Rise per radian c = pitch / 2π (m/rad); negative for a left-handed helix.
    pub lead: f64,
}

impl Helix {
    /// Arc length per radian, L = √(R² + c²).
    #[inline]
    pub fn length_per_radian(&self) -> f64 {
        self.radius.hypot(self.lead)
    }
    /// Curvature κ = R / L² (1/m).
    #[inline]
    pub fn curvature(&self) -> f64 {
        self.radius / self.length_per_radian().powi(2)
    }
    /// Torsion τ = c / L² (1/m).
    #[inline]
    pub fn torsion(&self) -> f64 {
        self.lead / self.length_per_radian().powi(2)
    }
    /// Position r(s) and the trihedral [t n b] (columns) at arc length s.
    pub fn frame<T: DualNum<f64> + Copy + nalgebra::Scalar>(&self, s: T) -> (Vector3<T>, Matrix3<T>) {
        let (r, c, l) = (self.radius, self.lead, self.length_per_radian());
        let phi = s / l;
        let (sn, cs) = (phi.sin(), phi.cos());
        let z = T::from(0.0);
        let pos = Vector3::new(cs * r, sn * r, phi * c);
        let t = Vector3::new(-sn * (r / l), cs * (r / l), T::from(c / l));
        let n = Vector3::new(-cs, -sn, z);
        let b = Vector3::new(sn * (c / l), -cs * (c / l), T::from(r / l));
        (pos, Matrix3::from_columns(&[t, n, b]))
    }
    /// Everything at s (real).
    pub(super) fn point(&self, s: f64) -> PathPoint {
        let (r, frame) = self.frame(s);
        let (k, tau) = (self.curvature(), self.torsion());
        PathPoint {
            r,
            frame,
            tangent_rate: frame.column(1) * k,
            omega: Vec3::new(tau, 0.0, k),
            omega_rate: Vec3::zeros(),
            curvature: k,
            torsion: tau,
        }
    }
    /// Everything at s (any scalar).
    pub(super) fn local<T: DualNum<f64> + Copy + nalgebra::Scalar>(&self, s: T) -> PathLocal<T> {
        let (r, frame) = self.frame(s);
        let (k, tau) = (self.curvature(), self.torsion());
        let z = T::from(0.0);
        PathLocal {
            r,
            frame,
            tangent_rate: frame.column(1) * T::from(k),
            omega: Vector3::new(T::from(tau), z, T::from(k)),
            omega_rate: Vector3::new(z, z, z),
        }
    }
}
