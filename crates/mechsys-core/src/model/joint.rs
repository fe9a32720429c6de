//! Joint kinematics: for each joint type, the relative placement of the child joint frame in the
//! parent joint frame as a function of the joint coordinates, the motion subspace `S` (columns of
//! the Jacobian of the relative twist, child-frame components), the bias `c_J = Ṡ u`, and the map
//! `q̇ = H*(q) u` (eq. 2.34) for joints whose velocities are not coordinate rates.
//!
//! Conventions of the generalized coordinates (q) and velocities (u) of each joint:
//!
//! | type | nq | nu | q | u |
//! |---|---|---|---|---|
//! | fixed | 0 | 0 | – | – |
//! | revolute | 1 | 1 | angle about `axis` | angle rate |
//! | prismatic | 1 | 1 | displacement along `axis` | its rate |
//! | cylindrical | 2 | 2 | angle, displacement (both about/along `axis`) | rates |
//! | universal | 2 | 2 | angle about `axis` (parent), then about `axis2` (child) | rates |
//! | spherical | 4 | 3 | unit quaternion `[w,x,y,z]` of A_PC | ω of the child, child frame |
//! | planar | 3 | 3 | x, y in the joint plane, angle about z | rates |
//! | free | 7 | 6 | position (parent frame), quaternion | velocity and ω of the child, child frame |

use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

/// The joint types, with their per-type constant data.
#[derive(Debug, Clone, PartialEq)]
pub enum JointKind {
    /// Rigid connection.
    Fixed,
    /// Rotation about a unit axis.
    Revolute {
        /// Unit axis, joint frame.
        axis: Vec3,
    },
    /// Translation along a unit axis.
    Prismatic {
        /// Unit axis, joint frame.
        axis: Vec3,
    },
    /// Rotation about and translation along one axis.
    Cylindrical {
        /// Unit axis, joint frame.
        axis: Vec3,
    },
    /// Two rotations about non-parallel axes (Cardan joint).
    Universal {
        /// First axis, fixed in the parent joint frame.
        axis1: Vec3,
        /// Second axis, fixed in the child joint frame.
        axis2: Vec3,
    },
    /// Ball joint, orientation as a unit quaternion.
    Spherical,
    /// Planar motion in the joint frame's x-y plane.
    Planar,
    /// Six degrees of freedom.
    Free,
    /// Path coordinate (section 2.2.6): the child frame's origin moves along a curve in the
    /// parent joint frame (helix, clothoid, spline), q = its arc length s; `oriented`: the child
    /// frame turns with the curve's frame [t n b] (`kinematics::path`), else it keeps the
    /// parent's axes.
    Path {
        /// The curve.
        curve: crate::kinematics::path::PathCurve,
        /// Whether the child frame follows the trihedral.
        oriented: bool,
    },
}

impl JointKind {
    /// Number of coordinates.
    pub fn nq(&self) -> usize {
        match self {
            JointKind::Fixed => 0,
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } | JointKind::Path { .. } => 1,
            JointKind::Cylindrical { .. } | JointKind::Universal { .. } => 2,
            JointKind::Spherical => 4,
            JointKind::Planar => 3,
            JointKind::Free => 7,
        }
    }
    /// Number of velocities (degrees of freedom).
    pub fn nu(&self) -> usize {
        match self {
            JointKind::Fixed => 0,
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } | JointKind::Path { .. } => 1,
            JointKind::Cylindrical { .. } | JointKind::Universal { .. } => 2,
            JointKind::Spherical | JointKind::Planar => 3,
            JointKind::Free => 6,
        }
    }
    /// Lower-case type name as used in model files.
    pub fn type_name(&self) -> &'static str {
        match self {
            JointKind::Fixed => "fixed",
            JointKind::Revolute { .. } => "revolute",
            JointKind::Prismatic { .. } => "prismatic",
            JointKind::Cylindrical { .. } => "cylindrical",
            JointKind::Universal { .. } => "universal",
            JointKind::Spherical => "spherical",
            JointKind::Planar => "planar",
            JointKind::Path { .. } => "path",
            JointKind::Free => "free",
        }
    }
    /// Whether the motion subspace depends on q (so `c_J = Ṡ u ≠ 0`).
    #[inline]
    pub fn has_bias(&self) -> bool {
        match self {
            JointKind::Universal { .. } | JointKind::Planar => true,
            // oriented: S = (Ω(s), t) in the child's own axes, constant only for the helix
            JointKind::Path { curve, oriented } => !oriented || !curve.constant_darboux(),
            _ => false,
        }
    }
    /// Whether the coordinates contain a quaternion (and so `q̇ ≠ u`).
    pub fn has_quaternion(&self) -> bool {
        matches!(self, JointKind::Spherical | JointKind::Free)
    }
    /// The neutral configuration (zero angles, identity quaternion).
    pub fn neutral(&self, q: &mut [f64]) {
        q.iter_mut().for_each(|x| *x = 0.0);
        match self {
            JointKind::Spherical => q[0] = 1.0,
            JointKind::Free => q[3] = 1.0,
            _ => {}
        }
    }

    /// Placement of the child joint frame in the parent joint frame.
    #[inline]
    pub fn placement(&self, q: &[f64]) -> Pose {
        match self {
            JointKind::Fixed => Pose::IDENTITY,
            JointKind::Revolute { axis } => Pose::new(axis_rotation(axis, q[0]), Vec3::zeros()),
            JointKind::Prismatic { axis } => Pose::new(Mat3::identity(), axis * q[0]),
            JointKind::Cylindrical { axis } => Pose::new(axis_rotation(axis, q[0]), axis * q[1]),
            JointKind::Universal { axis1, axis2 } => {
                Pose::new(axis_rotation(axis1, q[0]) * axis_rotation(axis2, q[1]), Vec3::zeros())
            }
            JointKind::Spherical => Pose::new(unit_quat_matrix(&q[0..4]), Vec3::zeros()),
            JointKind::Planar => Pose::new(axis_rotation(&Vec3::z(), q[2]), Vec3::new(q[0], q[1], 0.0)),
            JointKind::Free => Pose::new(unit_quat_matrix(&q[3..7]), Vec3::new(q[0], q[1], q[2])),
            JointKind::Path { curve, oriented } => {
                let p = curve.point(q[0]);
                Pose::new(if *oriented { p.frame } else { Mat3::identity() }, p.r)
            }
        }
    }

    /// Motion subspace columns (child joint frame components) into `s[..nu]`.
    #[inline]
    pub fn subspace(&self, q: &[f64], s: &mut [Motion; 6]) {
        let z = Vec3::zeros();
        match self {
            JointKind::Fixed => {}
            JointKind::Revolute { axis } => s[0] = Motion::new(*axis, z),
            JointKind::Prismatic { axis } => s[0] = Motion::new(z, *axis),
            JointKind::Cylindrical { axis } => {
                s[0] = Motion::new(*axis, z);
                s[1] = Motion::new(z, *axis);
            }
            JointKind::Universal { axis1, axis2 } => {
                // ω_C = Rot(a2, q2)ᵀ a1 q̇1 + a2 q̇2
                s[0] = Motion::new(axis_rotation(axis2, q[1]).transpose() * axis1, z);
                s[1] = Motion::new(*axis2, z);
            }
            JointKind::Spherical => {
                for (k, col) in s.iter_mut().take(3).enumerate() {
                    *col = Motion::new(unit(k), z);
                }
            }
            JointKind::Planar => {
                // origin velocity (ẋ, ẏ, 0) in the parent frame, seen in the rotated child frame
                let (sn, c) = q[2].sin_cos();
                s[0] = Motion::new(z, Vec3::new(c, -sn, 0.0));
                s[1] = Motion::new(z, Vec3::new(sn, c, 0.0));
                s[2] = Motion::new(Vec3::z(), z);
            }
            JointKind::Free => {
                for k in 0..3 {
                    s[k] = Motion::new(z, unit(k));
                    s[k + 3] = Motion::new(unit(k), z);
                }
            }
            JointKind::Path { curve, oriented: true } => {
                // in the trihedral's own axes: v = t ṡ, ω = Ω ṡ (the Darboux vector, (τ, 0, κ)
                // for the Frenet trihedral)
                s[0] = Motion::new(curve.point(q[0]).omega, Vec3::x());
            }
            JointKind::Path { curve, oriented: false } => {
                s[0] = Motion::new(z, curve.point(q[0]).frame.column(0).into_owned());
            }
        }
    }

    /// The bias `c_J = Ṡ(q) u` of joints whose subspace depends on q (zero otherwise).
    #[inline]
    pub fn bias(&self, q: &[f64], u: &[f64]) -> Motion {
        match self {
            JointKind::Universal { axis1, axis2 } => {
                let s1 = axis_rotation(axis2, q[1]).transpose() * axis1;
                Motion::new(-(axis2 * u[1]).cross(&(s1 * u[0])), Vec3::zeros())
            }
            JointKind::Planar => {
                let (sn, c) = q[2].sin_cos();
                let v = Vec3::new(c * u[0] + sn * u[1], -sn * u[0] + c * u[1], 0.0);
                Motion::new(Vec3::zeros(), -(Vec3::z() * u[2]).cross(&v))
            }
            JointKind::Path { curve, oriented: false } => {
                // d(t ṡ)/dt at constant ṡ: t′ ṡ² = κ n ṡ² (eq. 2.74)
                Motion::new(Vec3::zeros(), curve.point(q[0]).tangent_rate * (u[0] * u[0]))
            }
            JointKind::Path { curve, oriented: true } => {
                // S = (Ω(s), e_x) in the child's axes: Ṡ u = (Ω′ ṡ², 0)
                Motion::new(curve.point(q[0]).omega_rate * (u[0] * u[0]), Vec3::zeros())
            }
            _ => Motion::ZERO,
        }
    }

    /// Coordinate rates `q̇ = H*(q) u` (eq. 2.34).
    #[inline]
    pub fn qdot(&self, q: &[f64], u: &[f64], qd: &mut [f64]) {
        match self {
            JointKind::Spherical => quat_rate(&q[0..4], &u[0..3], &mut qd[0..4]),
            JointKind::Free => {
                let a = quat_matrix(q[3], q[4], q[5], q[6]);
                let v = a * Vec3::new(u[0], u[1], u[2]);
                qd[0] = v.x;
                qd[1] = v.y;
                qd[2] = v.z;
                quat_rate(&q[3..7], &u[3..6], &mut qd[3..7]);
            }
            _ => qd.copy_from_slice(u),
        }
    }

    /// Renormalizes the quaternion part of q (projection back onto the unit sphere after a step).
    #[inline]
    pub fn normalize(&self, q: &mut [f64]) {
        let range = match self {
            JointKind::Spherical => 0..4,
            JointKind::Free => 3..7,
            _ => return,
        };
        let n = q[range.clone()].iter().map(|x| x * x).sum::<f64>().sqrt();
        if n > 0.0 && n.is_finite() {
            q[range].iter_mut().for_each(|x| *x /= n);
        }
    }

    /// Adds the configuration increment `u·dt` to q on the joint's manifold (exact exponential map
    /// for quaternions), used by finite differences and implicit solvers.
    pub fn integrate(&self, q: &[f64], u: &[f64], dt: f64, out: &mut [f64]) {
        out.copy_from_slice(q);
        match self {
            JointKind::Spherical => quat_step(&q[0..4], &u[0..3], dt, &mut out[0..4]),
            JointKind::Free => {
                let a = quat_matrix(q[3], q[4], q[5], q[6]);
                let v = a * Vec3::new(u[0], u[1], u[2]) * dt;
                for k in 0..3 {
                    out[k] = q[k] + v[k];
                }
                quat_step(&q[3..7], &u[3..6], dt, &mut out[3..7]);
            }
            _ => out.iter_mut().zip(u).for_each(|(o, du)| *o += du * dt),
        }
    }
}

#[inline]
fn unit(k: usize) -> Vec3 {
    let mut e = Vec3::zeros();
    e[k] = 1.0;
    e
}

/// Rotation matrix about a unit axis (Rodrigues), A_PC of a rotation by `angle`.
#[inline]
pub fn axis_rotation(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = crate::math::trig::sin_cos(angle);
    // R = c E + s ã + (1 - c) a aᵀ
    let (x, y, z) = (axis.x, axis.y, axis.z);
    let k = 1.0 - c;
    Mat3::new(
        c + k * x * x,
        k * x * y - s * z,
        k * x * z + s * y,
        k * x * y + s * z,
        c + k * y * y,
        k * y * z - s * x,
        k * x * z - s * y,
        k * y * z + s * x,
        c + k * z * z,
    )
}

/// Rotation matrix of the unit quaternion `w + x i + y j + z k` (scalar first).
#[inline]
pub fn quat_matrix(w: f64, x: f64, y: f64, z: f64) -> Mat3 {
    Mat3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// Rotation matrix of a quaternion after normalization, so that a quaternion slightly off the unit
/// sphere between projections (inside a Runge–Kutta step) still gives an orthogonal matrix.
#[inline]
fn unit_quat_matrix(q: &[f64]) -> Mat3 {
    let n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    let s = if n2 > 0.0 { 1.0 / n2.sqrt() } else { 1.0 };
    quat_matrix(q[0] * s, q[1] * s, q[2] * s, q[3] * s)
}

/// q̇ = ½ q ⊗ (0, ω_C) with ω in the rotated (child) frame.
#[inline]
fn quat_rate(q: &[f64], w: &[f64], qd: &mut [f64]) {
    let (q0, q1, q2, q3) = (q[0], q[1], q[2], q[3]);
    qd[0] = 0.5 * (-q1 * w[0] - q2 * w[1] - q3 * w[2]);
    qd[1] = 0.5 * (q0 * w[0] + q2 * w[2] - q3 * w[1]);
    qd[2] = 0.5 * (q0 * w[1] + q3 * w[0] - q1 * w[2]);
    qd[3] = 0.5 * (q0 * w[2] + q1 * w[1] - q2 * w[0]);
}

/// q ⊗ exp(½ ω dt): exact rotation by a constant body-frame ω over dt.
fn quat_step(q: &[f64], w: &[f64], dt: f64, out: &mut [f64]) {
    let th = Vec3::new(w[0], w[1], w[2]) * dt;
    let ang = th.norm();
    let (s, c) = if ang < 1e-12 { (0.5, 1.0) } else { ((0.5 * ang).sin() / ang, (0.5 * ang).cos()) };
    let d = [c, th.x * s, th.y * s, th.z * s];
    out[0] = q[0] * d[0] - q[1] * d[1] - q[2] * d[2] - q[3] * d[3];
    out[1] = q[0] * d[1] + q[1] * d[0] + q[2] * d[3] - q[3] * d[2];
    out[2] = q[0] * d[2] - q[1] * d[3] + q[2] * d[0] + q[3] * d[1];
    out[3] = q[0] * d[3] + q[1] * d[2] - q[2] * d[1] + q[3] * d[0];
    let r = crate::integrator::lie_group::unit_rounding([out[0], out[1], out[2], out[3]]);
    out.copy_from_slice(&r);
}

#[cfg(test)]
mod tests {
    use super::*;

    const KINDS: [JointKind; 8] = [
        JointKind::Fixed,
        JointKind::Revolute { axis: Vec3::new(0.0, 0.6, 0.8) },
        JointKind::Prismatic { axis: Vec3::new(0.8, 0.0, 0.6) },
        JointKind::Cylindrical { axis: Vec3::new(0.0, 0.0, 1.0) },
        JointKind::Universal { axis1: Vec3::new(1.0, 0.0, 0.0), axis2: Vec3::new(0.0, 0.6, 0.8) },
        JointKind::Spherical,
        JointKind::Planar,
        JointKind::Free,
    ];

    fn sample_q(k: &JointKind) -> Vec<f64> {
        let mut q: Vec<f64> = (0..k.nq()).map(|i| 0.3 + 0.17 * i as f64).collect();
        k.normalize(&mut q);
        q
    }

    /// The relative twist S u must equal the finite-difference rate of the placement along q̇ = H* u.
    #[test]
    fn subspace_matches_placement_derivative() {
        for k in KINDS.iter() {
            let q = sample_q(k);
            let u: Vec<f64> = (0..k.nu()).map(|i| 0.7 - 0.4 * i as f64).collect();
            let mut s = [Motion::ZERO; 6];
            k.subspace(&q, &mut s);
            let mut v = Motion::ZERO;
            for i in 0..k.nu() {
                v += s[i] * u[i];
            }
            let h = 1e-6;
            let mut qp = vec![0.0; k.nq()];
            let mut qm = vec![0.0; k.nq()];
            k.integrate(&q, &u, h, &mut qp);
            k.integrate(&q, &u, -h, &mut qm);
            let (p0, pp, pm) = (k.placement(&q), k.placement(&qp), k.placement(&qm));
            // ω̃_C = A_PCᵀ Ȧ_PC (eq. 2.35), v_C = A_PCᵀ ṙ
            let adot = (pp.a - pm.a) / (2.0 * h);
            let w = crate::math::untilde(&(p0.a.transpose() * adot));
            let rdot = (pp.r - pm.r) / (2.0 * h);
            assert!((w - v.w).norm() < 1e-7, "{}: ω {w} vs {}", k.type_name(), v.w);
            assert!((p0.a.transpose() * rdot - v.v).norm() < 1e-7, "{}: v", k.type_name());
        }
    }

    /// c_J = d/dt(S) u along the motion.
    #[test]
    fn bias_matches_subspace_derivative() {
        for k in KINDS.iter() {
            let q = sample_q(k);
            let u: Vec<f64> = (0..k.nu()).map(|i| 0.9 - 0.5 * i as f64).collect();
            let h = 1e-6;
            let mut qp = vec![0.0; k.nq()];
            let mut qm = vec![0.0; k.nq()];
            k.integrate(&q, &u, h, &mut qp);
            k.integrate(&q, &u, -h, &mut qm);
            let (mut sp, mut sm) = ([Motion::ZERO; 6], [Motion::ZERO; 6]);
            k.subspace(&qp, &mut sp);
            k.subspace(&qm, &mut sm);
            let mut fd = Motion::ZERO;
            for i in 0..k.nu() {
                fd += (sp[i] - sm[i]) * (u[i] / (2.0 * h));
            }
            let c = k.bias(&q, &u);
            assert!((fd.to_vec6() - c.to_vec6()).norm() < 1e-7, "{}", k.type_name());
        }
    }

    #[test]
    fn qdot_matches_integrate() {
        for k in KINDS.iter() {
            let q = sample_q(k);
            let u: Vec<f64> = (0..k.nu()).map(|i| 0.2 + 0.3 * i as f64).collect();
            let mut qd = vec![0.0; k.nq()];
            k.qdot(&q, &u, &mut qd);
            let h = 1e-6;
            let mut qp = vec![0.0; k.nq()];
            let mut qm = vec![0.0; k.nq()];
            k.integrate(&q, &u, h, &mut qp);
            k.integrate(&q, &u, -h, &mut qm);
            for i in 0..k.nq() {
                assert!(((qp[i] - qm[i]) / (2.0 * h) - qd[i]).abs() < 1e-8, "{} q̇[{i}]", k.type_name());
            }
        }
    }

    #[test]
    fn revolute_about_z_turns_x_into_y() {
        let p = JointKind::Revolute { axis: Vec3::z() }.placement(&[std::f64::consts::FRAC_PI_2]);
        assert!((p.a * Vec3::x() - Vec3::y()).norm() < 1e-15);
        let m = quat_matrix(0.5f64.sqrt(), 0.0, 0.0, 0.5f64.sqrt());
        assert!((m * Vec3::x() - Vec3::y()).norm() < 1e-15);
    }
}
