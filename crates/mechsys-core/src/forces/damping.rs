//! Damping laws of section 2.6: the squeeze-film slide way (eq. 2.211), the journal bearing's
//! Reynolds–Sommerfeld friction torque (eq. 2.212), the progressive law of elastomer mounts, and
//! the rotation measure of the six-component bushing.

use crate::math::{tilde, Mat3, Vec3};

/// Largest relative eccentricity accepted for eq. 2.212: the torque grows like (1 − ε²)^(−1/2)
/// and the shaft touches the shell at ε = 1, where the film theory no longer holds.
pub const MAX_ECCENTRICITY: f64 = 0.95;

/// Largest relative rotation of a bushing (rad): its rotation vector is ambiguous at π.
pub const MAX_BUSHING_ROTATION: f64 = 0.99 * std::f64::consts::PI;

/// `12 η A l²` of eq. 2.211 (N s m²): the squeeze-film force is this over h³ times ḣ.
pub fn squeeze_film_coefficient(eta: f64, length: f64, area: f64) -> f64 {
    12.0 * eta * area * length * length
}

/// Torque per shaft speed of a journal bearing (eq. 2.212 with the wall speed u_w = r0 Ω):
/// `c = 2(1 + 2ε²) / (√(1 − ε²)(1 + ε²/2)) · π r0² b η / a · r0` (N m s/rad). At ε = 0 this is
/// Petroff's `2π r0³ b η / a`.
pub fn journal_bearing_coefficient(radius: f64, length: f64, clearance: f64, eta: f64, eps: f64) -> f64 {
    let e2 = eps * eps;
    let shape = 2.0 * (1.0 + 2.0 * e2) / ((1.0 - e2).sqrt() * (1.0 + 0.5 * e2));
    shape * std::f64::consts::PI * radius * radius * length * eta / clearance * radius
}

/// Squeeze-film force (eq. 2.211) for gap h and gap rate ḣ: `F = 12 η A l² / h³ · ḣ`, given
/// `coeff = 12 η A l²`; positive while the gap opens (the film then pulls the surfaces together).
#[inline]
pub fn squeeze_film_force(coeff: f64, h: f64, hdot: f64) -> f64 {
    coeff / (h * h * h) * hdot
}

/// Progressive (elastomer-mount) factor `1 / (1 − (δ/s)²)` by which a stop travel s stiffens
/// and damps the linear law; `None` once |δ| reaches s (the mount is on its stop).
#[inline]
pub fn progressive_factor(delta: f64, travel: f64) -> Option<f64> {
    let r = delta / travel;
    let den = 1.0 - r * r;
    (den > 0.0).then(|| 1.0 / den)
}

/// Potential of the progressive spring `F = k δ / (1 − (δ/s)²)`: `−(k s²/2) ln(1 − (δ/s)²)`.
#[inline]
pub fn progressive_energy(k: f64, delta: f64, travel: f64) -> f64 {
    let r = delta / travel;
    -0.5 * k * travel * travel * (-(r * r)).ln_1p()
}

/// `J⁻ᵀ(θ)` of the rotation vector θ, with `J` the Jacobian of `ω = J(θ) θ̇` for the rotation
/// `exp(θ̃)` whose angular velocity ω is taken in the frame the rotation is measured from. A
/// torque `n = −J⁻ᵀ ∂V/∂θ` derives from the potential V(θ), so the bushing is conservative for
/// any rotational stiffness, not only for small angles.
pub fn rotvec_jacobian_inv_t(theta: &Vec3) -> Mat3 {
    let a = theta.norm();
    // J⁻¹ = E − θ̃/2 + c θ̃², c = 1/a² − (1 + cos a)/(2 a sin a); its series near 0 is 1/12 + a²/720
    let c = if a < 1e-4 { 1.0 / 12.0 + a * a / 720.0 } else { 1.0 / (a * a) - (1.0 + a.cos()) / (2.0 * a * a.sin()) };
    let t = tilde(theta);
    Mat3::identity() + 0.5 * t + c * t * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rotation::rotvec_to_matrix;

    #[test]
    fn journal_bearing_reduces_to_petroff_and_grows_with_eccentricity() {
        let (r, b, a, eta): (f64, f64, f64, f64) = (0.05, 0.08, 5e-5, 0.02);
        let petroff = 2.0 * std::f64::consts::PI * r.powi(3) * b * eta / a;
        assert!((journal_bearing_coefficient(r, b, a, eta, 0.0) / petroff - 1.0).abs() < 1e-14);
        // ε = 0.6: 2(1.72)/(0.8 · 1.18) times π r² b η / a · r
        let c = journal_bearing_coefficient(r, b, a, eta, 0.6);
        let expect = 2.0 * 1.72 / (0.8 * 1.18) * std::f64::consts::PI * r * r * b * eta / a * r;
        assert!((c / expect - 1.0).abs() < 1e-14);
        assert!(c > petroff);
    }

    #[test]
    fn progressive_law_integrates_to_its_energy() {
        let (k, s) = (2.0e4, 0.01);
        for d in [-0.008, -0.003, 0.0005, 0.006, 0.0095] {
            let h = 1e-7;
            let f = (progressive_energy(k, d + h, s) - progressive_energy(k, d - h, s)) / (2.0 * h);
            let law = k * d * progressive_factor(d, s).unwrap();
            assert!((f - law).abs() < 1e-6 * law.abs().max(1.0), "δ = {d}: {f} vs {law}");
        }
        assert!(progressive_factor(0.01, s).is_none());
        // small deflections: the linear spring
        assert!((progressive_factor(1e-6, s).unwrap() - 1.0).abs() < 1e-7);
    }

    #[test]
    fn rotation_vector_jacobian_maps_rates_to_angular_velocity() {
        // ω̃ = Ȧ Aᵀ by finite differences against J θ̇ with J from the inverse transpose
        let th = Vec3::new(0.7, -1.1, 0.4);
        let thd = Vec3::new(0.3, 0.2, -0.5);
        let h = 1e-6;
        let ap = rotvec_to_matrix(&(th + thd * h));
        let am = rotvec_to_matrix(&(th - thd * h));
        let w = crate::math::untilde(&((ap - am) / (2.0 * h) * rotvec_to_matrix(&th).transpose()));
        let j = rotvec_jacobian_inv_t(&th).transpose().try_inverse().unwrap();
        assert!((j * thd - w).norm() < 1e-8, "{} vs {}", j * thd, w);
        // small angles
        let th = Vec3::new(1e-6, 0.0, -2e-6);
        assert!((rotvec_jacobian_inv_t(&th) - Mat3::identity()).norm() < 1e-5);
    }
}
