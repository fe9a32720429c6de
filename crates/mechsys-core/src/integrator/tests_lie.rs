//! The schemes on the rotation group against the torque-free symmetric rigid body, whose motion
//! is known in closed form: with `I₁ = I₂`, `A(t) = Rot(L_I, |L| t / I₁) A₀ Rot(e₃, μ t)`,
//! `μ = (1/I₃ − 1/I₁) L₃` (regular precession about the fixed angular momentum).

use super::*;
use crate::math::rotation::{quat_to_matrix, rot_axis, rot_z};
use crate::math::{Mat3, Vec3};

/// Euler's equations `I ω̇ = −ω × I ω` with the quaternion `Q̇ = ½ Q ⊗ (0, ω)`; y = [Q, ω].
struct FreeBody {
    inertia: Vec3,
}

impl OdeSystem for FreeBody {
    fn dim(&self) -> usize {
        7
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        let q = [y[0], y[1], y[2], y[3]];
        let w = Vec3::new(y[4], y[5], y[6]);
        let qd = crate::math::rotation::quat_derivative(q, &w);
        dy[..4].copy_from_slice(&qd);
        let iw = w.component_mul(&self.inertia);
        let wd = -w.cross(&iw).component_div(&self.inertia);
        dy[4..7].copy_from_slice(wd.as_slice());
        Ok(())
    }
    fn quaternions(&self) -> &[usize] {
        &[0]
    }
}

const I1: f64 = 0.4;
const I3: f64 = 0.9;

fn y0() -> Vec<f64> {
    // a tilted start, spinning fast about the symmetry axis and tumbling
    let q = crate::math::rotation::rotvec_to_quat(&Vec3::new(0.3, -0.5, 0.2));
    vec![q[0], q[1], q[2], q[3], 1.5, -0.8, 6.0]
}

fn exact(t: f64) -> Mat3 {
    let y = y0();
    let a0 = quat_to_matrix([y[0], y[1], y[2], y[3]]);
    let w0 = Vec3::new(y[4], y[5], y[6]);
    let l_b = Vec3::new(I1 * w0.x, I1 * w0.y, I3 * w0.z);
    let l_i = a0 * l_b;
    let mu = (1.0 / I3 - 1.0 / I1) * l_b.z;
    rot_axis(&l_i.normalize(), l_i.norm() * t / I1) * a0 * rot_z(mu * t)
}

/// Largest orientation error (Frobenius norm of A − A_exact) and largest |1 − |Q|| over the samples.
fn run(kind: IntegratorKind, t_end: f64, n_out: usize) -> (f64, f64) {
    let mut sys = FreeBody { inertia: Vec3::new(I1, I1, I3) };
    let t_out: Vec<f64> = (0..=n_out).map(|k| t_end * k as f64 / n_out as f64).collect();
    let (mut err, mut drift) = (0.0f64, 0.0f64);
    let mut obs = |_s: &mut FreeBody, t: f64, y: &[f64], _f: bool| -> Result<()> {
        let q = [y[0], y[1], y[2], y[3]];
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        drift = drift.max((n - 1.0).abs());
        err = err.max((quat_to_matrix(q) - exact(t)).norm());
        Ok(())
    };
    integrate(&kind, &mut sys, 0.0, &y0(), &t_out, &mut obs).unwrap();
    (err, drift)
}

fn order(kind: fn(f64) -> IntegratorKind, dts: &[f64]) -> Vec<f64> {
    let errs: Vec<f64> = dts.iter().map(|&dt| run(kind(dt), 2.0, 20).0).collect();
    errs.windows(2).zip(dts.windows(2)).map(|(e, d)| (e[0] / e[1]).ln() / (d[0] / d[1]).ln()).collect()
}

#[test]
fn rk4_on_the_group_is_fourth_order() {
    let p = order(|dt| IntegratorKind::Rk4 { dt }, &[0.02, 0.01, 0.005]);
    assert!(p.iter().all(|&p| (p - 4.0).abs() < 0.25), "observed orders {p:?}");
    let (e, _) = run(IntegratorKind::Rk4 { dt: 0.005 }, 2.0, 20);
    assert!(e < 1e-6, "error {e}");
}

#[test]
fn radau5_fixed_on_the_group_is_fifth_order() {
    let kind =
        |dt| IntegratorKind::Radau5 { dt, newton_tol: 1e-14, rtol: 0.0, atol: 1e-10, max_step: 0.0, first_step: 0.0 };
    let p = order(kind, &[0.05, 0.025, 0.0125]);
    assert!(p.iter().all(|&p| (p - 5.0).abs() < 0.5), "observed orders {p:?}");
}

/// Adaptive schemes: the error follows the tolerance (a decade of rtol, about a decade of error).
#[test]
fn adaptive_schemes_on_the_group_follow_the_tolerance() {
    for (name, kind) in [
        (
            "dopri5",
            (|rtol| IntegratorKind::Dopri5 { rtol, atol: rtol * 1e-2, max_step: 0.0, first_step: 0.0 })
                as fn(f64) -> IntegratorKind,
        ),
        ("radau5", |rtol| IntegratorKind::Radau5 {
            dt: 0.0,
            newton_tol: 1e-10,
            rtol,
            atol: rtol * 1e-2,
            max_step: 0.0,
            first_step: 0.0,
        }),
    ] {
        let errs: Vec<f64> = [1e-6, 1e-8, 1e-10].iter().map(|&r| run(kind(r), 2.0, 20).0).collect();
        for (k, w) in errs.windows(2).enumerate() {
            let ratio = w[0] / w[1];
            assert!((5.0..2000.0).contains(&ratio), "{name}: error ratio {ratio} at step {k} of {errs:?}");
        }
        assert!(errs[2] < 1e-7, "{name}: {errs:?}");
    }
}

/// No renormalization anywhere: |Q| stays 1 to round-off over 10⁵ steps.
#[test]
fn the_quaternion_norm_stays_one_over_long_runs() {
    let (_, drift) = run(IntegratorKind::Rk4 { dt: 1e-3 }, 100.0, 100);
    assert!(drift < 1e-14, "RK4: |Q| − 1 = {drift:e}");
    let (_, drift) =
        run(IntegratorKind::Dopri5 { rtol: 1e-9, atol: 1e-12, max_step: 0.0, first_step: 0.0 }, 100.0, 1000);
    assert!(drift < 1e-14, "DOPRI5 (dense output too): |Q| − 1 = {drift:e}");
}
