//! Runge–Kutta on the rotation group: the chart that lets a scheme step unit quaternions by the
//! exponential map instead of adding increments to them (Munthe-Kaas' RKMK; Hairer, Lubich,
//! Wanner, *Geometric Numerical Integration*, IV.8).
//!
//! A state `y` that holds unit quaternions `Q` with `Q̇ = ½ Q ⊗ (0, ω_B)` (spherical and free
//! joints) is advanced over a step from `y₀` in local coordinates `z`: every quaternion is
//! `Q₀ ⊗ exp(θ)` with a rotation vector `θ` (3 numbers in place of 4), every other component is
//! `y₀ + z`. In these coordinates the equations are an ODE on a vector space,
//! `θ̇ = J_r⁻¹(θ) ω_B` ([`crate::math::rotation::rotvec_rate_body`]), so any Runge–Kutta scheme
//! applied to them keeps its order, and the stages and the step's end are mapped back by the
//! exponential, which keeps |Q| = 1 to round-off: no renormalization, no drift off the sphere
//! ([`unit_rounding`] keeps the round-off of the products from adding up).
//! The chart is re-centred at every step (z = 0 at its start).

use crate::math::rotation::{quat_mul, rotvec_rate_body, rotvec_to_quat};
use crate::math::Vec3;

/// One piece of the state: `len` vector-space components, or one quaternion.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// Components `y[at..at + len]` ↔ `z[local..local + len]`.
    Flat { at: usize, local: usize, len: usize },
    /// Quaternion `y[at..at + 4]` ↔ rotation vector `z[local..local + 3]`.
    Rotation { at: usize, local: usize },
}

/// The layout of a state's local coordinates; flat (the identity) when it holds no quaternion.
#[derive(Debug, Clone, Default)]
pub struct Chart {
    n: usize,
    nl: usize,
    pieces: Vec<Piece>,
    /// Per local coordinate, the state component that scales its error (usize::MAX: a rotation,
    /// measured in radians against 1).
    scale_of: Vec<usize>,
}

impl Chart {
    /// The chart of a state of `n` components with unit quaternions at the offsets `quats`
    /// (increasing, non-overlapping).
    pub fn new(n: usize, quats: &[usize]) -> Self {
        let mut pieces = Vec::with_capacity(2 * quats.len() + 1);
        let mut scale_of = Vec::with_capacity(n);
        let (mut at, mut local) = (0, 0);
        for &p in quats {
            debug_assert!(p >= at && p + 4 <= n, "quaternion offsets must increase and fit the state");
            if p > at {
                pieces.push(Piece::Flat { at, local, len: p - at });
                scale_of.extend(at..p);
                local += p - at;
            }
            pieces.push(Piece::Rotation { at: p, local });
            scale_of.extend([usize::MAX; 3]);
            at = p + 4;
            local += 3;
        }
        if n > at {
            pieces.push(Piece::Flat { at, local, len: n - at });
            scale_of.extend(at..n);
            local += n - at;
        }
        Chart { n, nl: local, pieces, scale_of }
    }

    /// Whether the state holds no quaternion (local coordinates are the state itself).
    #[inline]
    pub fn is_flat(&self) -> bool {
        self.nl == self.n
    }

    /// Number of local coordinates (the state's size less one per quaternion).
    #[inline]
    pub fn local_dim(&self) -> usize {
        self.nl
    }

    /// `y = y₀ ⊕ z`: quaternions turned by `exp(θ)` in their own frame, the rest added.
    pub fn retract(&self, y0: &[f64], z: &[f64], y: &mut [f64]) {
        for p in &self.pieces {
            match *p {
                Piece::Flat { at, local, len } => {
                    for i in 0..len {
                        y[at + i] = y0[at + i] + z[local + i];
                    }
                }
                Piece::Rotation { at, local } => {
                    let e = rotvec_to_quat(&Vec3::new(z[local], z[local + 1], z[local + 2]));
                    let q = quat_mul([y0[at], y0[at + 1], y0[at + 2], y0[at + 3]], e);
                    y[at..at + 4].copy_from_slice(&unit_rounding(q));
                }
            }
        }
    }

    /// The local rates `k = ż` at `y = y₀ ⊕ z` from the state's rates `dy = ẏ` there: the
    /// body angular velocity `ω = 2 vec(Q* ⊗ Q̇)` of each quaternion through `J_r⁻¹(θ)`, the
    /// rest copied.
    pub fn tangent(&self, y: &[f64], z: &[f64], dy: &[f64], k: &mut [f64]) {
        for p in &self.pieces {
            match *p {
                Piece::Flat { at, local, len } => k[local..local + len].copy_from_slice(&dy[at..at + len]),
                Piece::Rotation { at, local } => {
                    let w = body_rate(&y[at..at + 4], &dy[at..at + 4]);
                    let th = Vec3::new(z[local], z[local + 1], z[local + 2]);
                    let r = rotvec_rate_body(&th, &w);
                    k[local..local + 3].copy_from_slice(r.as_slice());
                }
            }
        }
    }

    /// [`Chart::tangent`] at the chart's centre (z = 0, where `J_r⁻¹ = E`).
    pub fn tangent0(&self, y: &[f64], dy: &[f64], k: &mut [f64]) {
        for p in &self.pieces {
            match *p {
                Piece::Flat { at, local, len } => k[local..local + len].copy_from_slice(&dy[at..at + len]),
                Piece::Rotation { at, local } => {
                    let w = body_rate(&y[at..at + 4], &dy[at..at + 4]);
                    k[local..local + 3].copy_from_slice(w.as_slice());
                }
            }
        }
    }

    /// The magnitude that scales local coordinate `i` in error norms: `max(|y_j|, |ŷ_j|)` of its
    /// state component, 1 for a rotation vector (the quaternion's norm).
    #[inline]
    pub fn magnitude(&self, i: usize, y: &[f64], ynew: &[f64]) -> f64 {
        match self.scale_of[i] {
            usize::MAX => 1.0,
            j => y[j].abs().max(ynew[j].abs()),
        }
    }

    /// [`Chart::magnitude`] over a step by the local increment `dz` of coordinate `i`:
    /// `max(|y_j|, |y_j + dz|)`, 1 for a rotation vector.
    #[inline]
    pub fn magnitude_step(&self, i: usize, y: &[f64], dz: f64) -> f64 {
        match self.scale_of[i] {
            usize::MAX => 1.0,
            j => y[j].abs().max((y[j] + dz).abs()),
        }
    }
}

/// Removes the rounding of a product of unit quaternions, `Q (3 − |Q|²)/2` (one Newton step
/// towards |Q| = 1): a change of O(ε) per step that would otherwise add up, one way, over long
/// runs (4e-12 after 10⁵ steps). Unlike the renormalization of an additive scheme it does not
/// move the state by the scheme's error.
/// A quaternion farther off the unit sphere than round-off (a user's unnormalized input) is
/// left alone.
#[inline]
pub fn unit_rounding(q: [f64; 4]) -> [f64; 4] {
    let n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (n2 - 1.0).abs() > 1e-10 {
        return q;
    }
    let k = 0.5 * (3.0 - n2);
    [q[0] * k, q[1] * k, q[2] * k, q[3] * k]
}

/// `ω_B = 2 vec(Q* ⊗ Q̇)` of a unit quaternion.
#[inline]
fn body_rate(q: &[f64], qd: &[f64]) -> Vec3 {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    let (dw, dx, dy, dz) = (qd[0], qd[1], qd[2], qd[3]);
    // vector part of (w, −x, −y, −z) ⊗ (dw, dx, dy, dz)
    Vec3::new(
        2.0 * (w * dx - x * dw - y * dz + z * dy),
        2.0 * (w * dy + x * dz - y * dw - z * dx),
        2.0 * (w * dz - x * dy + y * dx - z * dw),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rotation::quat_derivative;

    #[test]
    fn layout_maps_quaternions_to_rotation_vectors() {
        // [x, y, z, Q(4), a, Q(4), b, c]
        let c = Chart::new(14, &[3, 8]);
        assert_eq!(c.local_dim(), 12);
        assert!(!c.is_flat());
        assert!(Chart::new(5, &[]).is_flat());
        let mut y0 = vec![0.0; 14];
        y0[3] = 1.0;
        y0[8] = 0.6;
        y0[9] = 0.8;
        let z: Vec<f64> = (0..12).map(|i| 0.1 * i as f64).collect();
        let mut y = vec![0.0; 14];
        c.retract(&y0, &z, &mut y);
        assert_eq!(&y[0..3], &z[0..3]);
        assert_eq!(y[7], z[6]);
        assert_eq!(&y[12..14], &z[10..12]);
        for at in [3, 8] {
            let n: f64 = y[at..at + 4].iter().map(|v| v * v).sum();
            assert!((n - 1.0).abs() < 1e-15);
        }
    }

    /// The local rates are the derivative of z ↦ y₀ ⊕ z pulled back: y₀ ⊕ (z + k dt) = y(t + dt).
    #[test]
    fn tangent_inverts_the_retraction_rate() {
        let c = Chart::new(7, &[0]);
        let y0 = [0.5, 0.5, -0.5, 0.5, 1.0, 2.0, 3.0];
        let z = [0.3, -0.7, 0.2, 0.1, 0.2, 0.3];
        let mut y = [0.0; 7];
        c.retract(&y0, &z, &mut y);
        let w = Vec3::new(1.3, -0.4, 0.9);
        let qd = quat_derivative([y[0], y[1], y[2], y[3]], &w);
        let dy = [qd[0], qd[1], qd[2], qd[3], 4.0, 5.0, 6.0];
        let mut k = [0.0; 6];
        c.tangent(&y, &z, &dy, &mut k);
        let h = 1e-6;
        let (mut zp, mut zm) = (z, z);
        for i in 0..6 {
            zp[i] += h * k[i];
            zm[i] -= h * k[i];
        }
        let (mut yp, mut ym) = ([0.0; 7], [0.0; 7]);
        c.retract(&y0, &zp, &mut yp);
        c.retract(&y0, &zm, &mut ym);
        for i in 0..7 {
            assert!(((yp[i] - ym[i]) / (2.0 * h) - dy[i]).abs() < 1e-8, "ẏ[{i}]");
        }
    }
}
