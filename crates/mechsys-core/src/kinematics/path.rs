//! Path coordinates (section 2.2.6): a body's point moving along a space curve, parameterized by
//! its arc length s, with the moving trihedral of the curve (Frenet: tangent t, principal normal
//! n, binormal b), curvature κ and torsion τ (dt/ds = κ n, dn/ds = -κ t + τ b, db/ds = -τ n).
//!
//! The curve here is the circular helix r(φ) = (R cos φ, R sin φ, c φ) about the z-axis of the
//! joint frame (c = pitch / 2π; c = 0: a circle). With L = √(R² + c²), φ = s / L and
//! t = (-R sin φ, R cos φ, c) / L, n = (-cos φ, -sin φ, 0), b = (c sin φ, -c cos φ, R) / L,
//! κ = R / L², τ = c / L², both constant. The functions are generic over the scalar so that the
//! exact linearization (dual numbers) uses the same formulas.

use nalgebra::{Matrix3, Vector3};
use num_dual::DualNum;

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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trihedral_is_orthonormal_and_obeys_frenet_serret_by_differences() {
        let h = Helix { radius: 0.3, lead: 0.05 };
        let (s, e) = (0.7, 1e-5);
        let (r0, f0) = h.frame(s);
        let (rp, fp) = h.frame(s + e);
        let (rm, fm) = h.frame(s - e);
        assert!((f0.transpose() * f0 - Matrix3::identity()).norm() < 1e-14);
        assert!((f0.determinant() - 1.0).abs() < 1e-14);
        let (t, n, b) = (f0.column(0), f0.column(1), f0.column(2));
        // dr/ds = t (unit speed: s is the arc length), dt/ds = κ n, dn/ds = -κ t + τ b, db/ds = -τ n
        assert!(((rp - rm) / (2.0 * e) - t).norm() < 1e-9);
        let d = (fp - fm) / (2.0 * e);
        let (k, tau) = (h.curvature(), h.torsion());
        assert!((d.column(0) - n * k).norm() < 1e-9);
        assert!((d.column(1) - (-t * k + b * tau)).norm() < 1e-9);
        assert!((d.column(2) + n * tau).norm() < 1e-9);
        // closed forms for R = 0.3, c = 0.05
        assert!((k - 0.3 / (0.09 + 0.0025)).abs() < 1e-15 && (tau - 0.05 / 0.0925).abs() < 1e-15);
        assert!(r0.x.hypot(r0.y) - 0.3 < 1e-15);
    }
}
