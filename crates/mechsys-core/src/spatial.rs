//! Spatial (6-D) vectors for the recursive algorithms: twists, wrenches, rigid transforms and body
//! inertias, all as pairs of fixed-size 3-vectors so that nothing allocates.
//!
//! Conventions: a motion vector `(ω, v)` holds a body's angular velocity and the velocity of the
//! frame's origin, both in that frame's components (the text's `Bω`, `Bv`, eq. 2.38); a force vector
//! `(n, f)` holds the moment about the frame origin and the force. A [`Pose`] of frame B relative
//! to frame P holds `a = A_PB` (B components → P components) and `r`, B's origin in P components.

use std::ops::{Add, AddAssign, Mul, Neg, Sub};

use nalgebra::{Matrix6, Vector6};

use crate::math::{tilde, Mat3, Vec3};

/// A spatial motion vector: angular velocity `w` and origin velocity `v`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Motion {
    /// Angular part.
    pub w: Vec3,
    /// Linear part (velocity of the frame origin).
    pub v: Vec3,
}

/// A spatial force vector: moment `n` about the frame origin and force `f`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Force {
    /// Moment about the origin.
    pub n: Vec3,
    /// Force.
    pub f: Vec3,
}

impl Motion {
    /// Zero motion.
    pub const ZERO: Motion = Motion { w: Vec3::new(0.0, 0.0, 0.0), v: Vec3::new(0.0, 0.0, 0.0) };
    /// Builds from parts.
    #[inline]
    pub fn new(w: Vec3, v: Vec3) -> Self {
        Motion { w, v }
    }
    /// Motion cross product `self ×m m` (derivative of a motion vector in a moving frame).
    #[inline]
    pub fn cross_motion(&self, m: &Motion) -> Motion {
        Motion { w: self.w.cross(&m.w), v: self.w.cross(&m.v) + self.v.cross(&m.w) }
    }
    /// Force cross product `self ×f f` (the gyroscopic term of the Newton–Euler equations).
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force { n: self.w.cross(&f.n) + self.v.cross(&f.f), f: self.w.cross(&f.f) }
    }
    /// Power pairing with a force.
    #[inline]
    pub fn dot(&self, f: &Force) -> f64 {
        self.w.dot(&f.n) + self.v.dot(&f.f)
    }
    /// As a 6-vector `[w; v]`.
    #[inline]
    pub fn to_vec6(&self) -> Vector6<f64> {
        Vector6::new(self.w.x, self.w.y, self.w.z, self.v.x, self.v.y, self.v.z)
    }
}

impl Force {
    /// Zero force.
    pub const ZERO: Force = Force { n: Vec3::new(0.0, 0.0, 0.0), f: Vec3::new(0.0, 0.0, 0.0) };
    /// Builds from parts.
    #[inline]
    pub fn new(n: Vec3, f: Vec3) -> Self {
        Force { n, f }
    }
    /// As a 6-vector `[n; f]`.
    #[inline]
    pub fn to_vec6(&self) -> Vector6<f64> {
        Vector6::new(self.n.x, self.n.y, self.n.z, self.f.x, self.f.y, self.f.z)
    }
}

macro_rules! spatial_ops {
    ($t:ident, $a:ident, $b:ident) => {
        impl Add for $t {
            type Output = $t;
            #[inline]
            fn add(self, o: $t) -> $t {
                $t { $a: self.$a + o.$a, $b: self.$b + o.$b }
            }
        }
        impl Sub for $t {
            type Output = $t;
            #[inline]
            fn sub(self, o: $t) -> $t {
                $t { $a: self.$a - o.$a, $b: self.$b - o.$b }
            }
        }
        impl AddAssign for $t {
            #[inline]
            fn add_assign(&mut self, o: $t) {
                self.$a += o.$a;
                self.$b += o.$b;
            }
        }
        impl Neg for $t {
            type Output = $t;
            #[inline]
            fn neg(self) -> $t {
                $t { $a: -self.$a, $b: -self.$b }
            }
        }
        impl Mul<f64> for $t {
            type Output = $t;
            #[inline]
            fn mul(self, s: f64) -> $t {
                $t { $a: self.$a * s, $b: self.$b * s }
            }
        }
    };
}
spatial_ops!(Motion, w, v);
spatial_ops!(Force, n, f);

/// Placement of a frame B relative to a frame P: `a = A_PB`, `r` = origin of B in P components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation matrix A_PB.
    pub a: Mat3,
    /// Position of B's origin, P components.
    pub r: Vec3,
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

impl Pose {
    /// The identity placement.
    pub const IDENTITY: Pose =
        Pose { a: Mat3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0), r: Vec3::new(0.0, 0.0, 0.0) };
    /// Builds from parts.
    #[inline]
    pub fn new(a: Mat3, r: Vec3) -> Self {
        Pose { a, r }
    }
    /// Composition: `self` = P→B, `other` = B→C gives P→C (eq. 2.46, 2.51).
    #[inline]
    pub fn compose(&self, other: &Pose) -> Pose {
        Pose { a: self.a * other.a, r: self.r + self.a * other.r }
    }
    /// Composition with a pure translation `p` (B components): `self ∘ (E, p)`.
    #[inline]
    pub fn translate(&self, p: &Vec3) -> Pose {
        Pose { a: self.a, r: self.r + self.a * p }
    }
    /// Whether the rotation is exactly the identity (fast paths for the common joint frames).
    #[inline]
    pub fn rotation_is_identity(&self) -> bool {
        self.a == Mat3::identity()
    }
    /// Inverse placement (P relative to B).
    #[inline]
    pub fn inverse(&self) -> Pose {
        let at = self.a.transpose();
        Pose { a: at, r: -(at * self.r) }
    }
    /// A point given in B components, expressed in P components.
    #[inline]
    pub fn point_to_parent(&self, p_b: &Vec3) -> Vec3 {
        self.r + self.a * p_b
    }
    /// Motion of P (P components) seen as the motion of the rigidly attached frame B (B components).
    #[inline]
    pub fn motion_to_child(&self, m: &Motion) -> Motion {
        let at = self.a.transpose();
        Motion { w: at * m.w, v: at * (m.v + m.w.cross(&self.r)) }
    }
    /// Motion of B (B components) seen as the motion of the rigidly attached frame P (P components).
    #[inline]
    pub fn motion_to_parent(&self, m: &Motion) -> Motion {
        let w = self.a * m.w;
        Motion { w, v: self.a * m.v - w.cross(&self.r) }
    }
    /// A force acting at B's origin (B components) moved to P's origin (P components).
    #[inline]
    pub fn force_to_parent(&self, f: &Force) -> Force {
        let ff = self.a * f.f;
        Force { n: self.a * f.n + self.r.cross(&ff), f: ff }
    }
    /// A force at P's origin (P components) moved to B's origin (B components).
    #[inline]
    pub fn force_to_child(&self, f: &Force) -> Force {
        let at = self.a.transpose();
        Force { n: at * (f.n - self.r.cross(&f.f)), f: at * f.f }
    }
    /// The 6×6 motion transform P→B, `[E 0; -E r̃ E]` with `E = A_PBᵀ`.
    pub fn motion_matrix_to_child(&self) -> Matrix6<f64> {
        let e = self.a.transpose();
        let mut x = Matrix6::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&e);
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&e);
        x.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-e * tilde(&self.r)));
        x
    }
}

/// Rigid-body inertia about a frame origin: mass `m`, first moment `h = m c` and rotational inertia
/// `i_o` about the origin (`I_c - m c̃ c̃`, Steiner's theorem), all in that frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RigidInertia {
    /// Mass.
    pub m: f64,
    /// First moment of mass, `m c`.
    pub h: Vec3,
    /// Inertia tensor about the origin.
    pub i_o: Mat3,
}

impl RigidInertia {
    /// From mass, centre of mass and inertia about the centre of mass (eq. 2.174-style Steiner shift).
    pub fn from_com(m: f64, c: &Vec3, i_c: &Mat3) -> Self {
        // Steiner: I_O = I_C + m (|c|² E - c cᵀ) = I_C - m c̃ c̃
        let (x, y, z) = (c.x, c.y, c.z);
        let (xx, yy, zz) = (m * x * x, m * y * y, m * z * z);
        let (xy, xz, yz) = (m * x * y, m * x * z, m * y * z);
        let shift = Mat3::new(yy + zz, -xy, -xz, -xy, xx + zz, -yz, -xz, -yz, xx + yy);
        RigidInertia { m, h: c * m, i_o: i_c + shift }
    }
    /// Momentum (moment about origin, linear momentum) of the body moving with `v`.
    #[inline]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force { n: self.i_o * v.w + self.h.cross(&v.v), f: v.v * self.m - self.h.cross(&v.w) }
    }
    /// Kinetic energy ½ vᵀ I v.
    #[inline]
    pub fn kinetic_energy(&self, v: &Motion) -> f64 {
        0.5 * v.dot(&self.mul_motion(v))
    }
    /// Dense 6×6 form `[i_o h̃; -h̃ m E]` in the (angular, linear) ordering.
    pub fn to_matrix(&self) -> Matrix6<f64> {
        let mut x = Matrix6::zeros();
        let ht = tilde(&self.h);
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.i_o);
        x.fixed_view_mut::<3, 3>(0, 3).copy_from(&ht);
        x.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-ht));
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&(Mat3::identity() * self.m));
        x
    }
    /// The same inertia expressed about the origin of P (P components), `self` given in B where
    /// `pose` places B in P.
    pub fn to_parent(&self, pose: &Pose) -> RigidInertia {
        let a = &pose.a;
        let r = &pose.r;
        let h_p = a * self.h;
        let i_rot = a * self.i_o * a.transpose();
        // shift from B's origin to P's origin: I_P = I_B' - m r̃ r̃ - (r̃ h̃' + h̃' r̃)
        let rt = tilde(r);
        let ht = tilde(&h_p);
        let i_o = i_rot - rt * rt * self.m - (rt * ht + ht * rt);
        RigidInertia { m: self.m, h: h_p + r * self.m, i_o }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose() -> Pose {
        let a = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
        Pose::new(a, Vec3::new(0.4, -0.2, 0.9))
    }

    #[test]
    fn motion_transforms_match_dense_matrix() {
        let p = pose();
        let m = Motion::new(Vec3::new(0.1, 0.2, -0.3), Vec3::new(1.0, -2.0, 0.5));
        let dense = p.motion_matrix_to_child() * m.to_vec6();
        let fast = p.motion_to_child(&m).to_vec6();
        assert!((dense - fast).norm() < 1e-14);
        let back = p.motion_to_parent(&p.motion_to_child(&m));
        assert!((back.to_vec6() - m.to_vec6()).norm() < 1e-14);
    }

    #[test]
    fn point_velocity_of_attached_frame() {
        // The frame B attached at r in P: its origin moves with v_P + ω × r (eq. 2.28 with ṙ = 0).
        let p = pose();
        let m = Motion::new(Vec3::new(0.0, 0.0, 2.0), Vec3::new(1.0, 0.0, 0.0));
        let c = p.motion_to_child(&m);
        let v_expected = m.v + m.w.cross(&p.r);
        assert!((p.a * c.v - v_expected).norm() < 1e-14);
    }

    #[test]
    fn force_transform_is_dual_of_motion_transform() {
        // power is invariant: m_P · f_P = m_B · f_B
        let p = pose();
        let m = Motion::new(Vec3::new(0.3, -0.1, 0.2), Vec3::new(-1.0, 0.5, 2.0));
        let f = Force::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-0.5, 0.25, 4.0));
        let p1 = m.dot(&p.force_to_parent(&f));
        let p2 = p.motion_to_child(&m).dot(&f);
        assert!((p1 - p2).abs() < 1e-13);
        let back = p.force_to_child(&p.force_to_parent(&f));
        assert!((back.to_vec6() - f.to_vec6()).norm() < 1e-13);
    }

    #[test]
    fn inertia_shift_and_congruence_agree() {
        let p = pose();
        let i_c = Mat3::new(2.0, 0.1, -0.2, 0.1, 3.0, 0.3, -0.2, 0.3, 4.0);
        let ri = RigidInertia::from_com(1.5, &Vec3::new(0.2, -0.1, 0.3), &i_c);
        let x = p.motion_matrix_to_child();
        let dense = x.transpose() * ri.to_matrix() * x;
        assert!((ri.to_parent(&p).to_matrix() - dense).norm() < 1e-12);
        // kinetic energy of a pure translation is ½ m v²
        let v = Motion::new(Vec3::zeros(), Vec3::new(3.0, 0.0, 4.0));
        assert!((ri.kinetic_energy(&v) - 0.5 * 1.5 * 25.0).abs() < 1e-12);
    }
}

/// A 6-vector as a plain array (the inner loops of the ABA work on these; LLVM unrolls them).
pub type V6 = [f64; 6];

/// Symmetric 6×6 matrix in block form `[A B; Bᵀ C]` (articulated-body inertias): `A` and `C`
/// symmetric, stored as their upper triangles `[xx, xy, xz, yy, yz, zz]`; 21 numbers instead of 36,
/// which is what the ABA's inner loops read and write.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct M6 {
    /// Upper triangle of the angular block.
    pub a: [f64; 6],
    /// Coupling block, row-major.
    pub b: [[f64; 3]; 3],
    /// Upper triangle of the linear block.
    pub c: [f64; 6],
}

impl Motion {
    /// As a plain array `[w; v]`.
    #[inline]
    pub fn v6(&self) -> V6 {
        [self.w.x, self.w.y, self.w.z, self.v.x, self.v.y, self.v.z]
    }
    /// Pairing with a force given as a plain array `[n; f]`.
    #[inline]
    pub fn dot6(&self, f: &V6) -> f64 {
        // a balanced sum (see [`M6::mul`])
        (self.w.x * f[0] + self.w.y * f[1]) + (self.w.z * f[2] + self.v.x * f[3]) + (self.v.y * f[4] + self.v.z * f[5])
    }
}

impl Force {
    /// As a plain array `[n; f]`.
    #[inline]
    pub fn v6(&self) -> V6 {
        [self.n.x, self.n.y, self.n.z, self.f.x, self.f.y, self.f.z]
    }
    /// From a plain array `[n; f]`.
    #[inline]
    pub fn from_v6(x: &V6) -> Self {
        Force { n: Vec3::new(x[0], x[1], x[2]), f: Vec3::new(x[3], x[4], x[5]) }
    }
}

impl M6 {
    /// Overwrites with the 6×6 form of a rigid-body inertia, `[i_o h̃; -h̃ m E]`.
    #[inline]
    pub fn set_rigid(&mut self, r: &RigidInertia) {
        let (h, i) = (&r.h, &r.i_o);
        self.a = [i[(0, 0)], i[(0, 1)], i[(0, 2)], i[(1, 1)], i[(1, 2)], i[(2, 2)]];
        self.b = [[0.0, -h.z, h.y], [h.z, 0.0, -h.x], [-h.y, h.x, 0.0]];
        self.c = [r.m, 0.0, 0.0, r.m, 0.0, r.m];
    }
    /// Entry (r, c) of the full matrix.
    #[inline]
    pub fn get(&self, r: usize, c: usize) -> f64 {
        const TRI: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];
        match (r < 3, c < 3) {
            (true, true) => self.a[TRI[r][c]],
            (true, false) => self.b[r][c - 3],
            (false, true) => self.b[c][r - 3],
            (false, false) => self.c[TRI[r - 3][c - 3]],
        }
    }
    /// Product with a plain 6-vector. Each row is summed as a balanced tree (three additions deep
    /// instead of five in a row): the ABA's inward pass is a serial chain through these products,
    /// and its latency, not the operation count, bounds a chain.
    #[inline(always)]
    pub fn mul(&self, x: &V6) -> V6 {
        let (a, b, c) = (&self.a, &self.b, &self.c);
        [
            (a[0] * x[0] + a[1] * x[1]) + (a[2] * x[2] + b[0][0] * x[3]) + (b[0][1] * x[4] + b[0][2] * x[5]),
            (a[1] * x[0] + a[3] * x[1]) + (a[4] * x[2] + b[1][0] * x[3]) + (b[1][1] * x[4] + b[1][2] * x[5]),
            (a[2] * x[0] + a[4] * x[1]) + (a[5] * x[2] + b[2][0] * x[3]) + (b[2][1] * x[4] + b[2][2] * x[5]),
            (b[0][0] * x[0] + b[1][0] * x[1]) + (b[2][0] * x[2] + c[0] * x[3]) + (c[1] * x[4] + c[2] * x[5]),
            (b[0][1] * x[0] + b[1][1] * x[1]) + (b[2][1] * x[2] + c[1] * x[3]) + (c[3] * x[4] + c[4] * x[5]),
            (b[0][2] * x[0] + b[1][2] * x[1]) + (b[2][2] * x[2] + c[2] * x[3]) + (c[4] * x[4] + c[5] * x[5]),
        ]
    }
    /// Product with a motion vector; the result is a force vector.
    #[inline(always)]
    pub fn mul_motion(&self, m: &Motion) -> V6 {
        self.mul(&m.v6())
    }
    /// `self += o - s · u uᵀ` (adding a child's articulated inertia with its joint's motion removed).
    #[inline(always)]
    pub fn add_minus_outer(&mut self, o: &M6, s: f64, u: &V6) {
        const TRI: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
        for (k, &(r, c)) in TRI.iter().enumerate() {
            self.a[k] += o.a[k] - s * u[r] * u[c];
            self.c[k] += o.c[k] - s * u[r + 3] * u[c + 3];
        }
        for r in 0..3 {
            for c in 0..3 {
                self.b[r][c] += o.b[r][c] - s * u[r] * u[c + 3];
            }
        }
    }
    /// `self -= x yᵀ` on the stored entries only; used to subtract `U D⁻¹ Uᵀ = Σ_r w_r u_rᵀ`
    /// term by term, whose sum is symmetric even though each term is not.
    #[inline]
    pub fn sub_product(&mut self, x: &V6, y: &V6) {
        const TRI: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
        for (k, &(r, c)) in TRI.iter().enumerate() {
            self.a[k] -= x[r] * y[c];
            self.c[k] -= x[r + 3] * y[c + 3];
        }
        for r in 0..3 {
            for c in 0..3 {
                self.b[r][c] -= x[r] * y[c + 3];
            }
        }
    }
    /// `self += o`.
    #[inline(always)]
    pub fn add(&mut self, o: &M6) {
        for k in 0..6 {
            self.a[k] += o.a[k];
            self.c[k] += o.c[k];
        }
        for r in 0..3 {
            for c in 0..3 {
                self.b[r][c] += o.b[r][c];
            }
        }
    }
}
