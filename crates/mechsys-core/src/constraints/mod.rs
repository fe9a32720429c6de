//! Bilateral constraints on the tree (sections 2.1.3, 2.2.5): loop closures and driving
//! constraints that the kinematic tree itself does not express.
//!
//! Each constraint contributes rows to `Φ(q, t) = 0`, to its velocity form `G u = b(t)` with
//! `G = Wᵀ` (eq. 2.70) and to its acceleration form `G u̇ = γ`, where `γ = -(Ġ u) + ḃ` is
//! computed from the velocity-product accelerations of the tree (the accelerations at `u̇ = 0`),
//! so no derivative of `G` is ever formed explicitly. The dynamics become
//! `M u̇ = h + τ + Gᵀ λ` (Lagrange multipliers λ), solved in `dynamics::constrained`.
//!
//! Kinds: coincidence of two body points (a spherical loop closure, 3 rows), a fixed distance
//! between two body points (1 row), a coupler `q_a = r q_b + c` between joint coordinates (1 row),
//! and a prescribed joint coordinate `q = f(t)` (1 row, rheonomic).

use nalgebra::DMatrix;

use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::kinematics::{point_acceleration, point_position, point_velocity};
use crate::math::Vec3;
use crate::model::{Model, TimeFunction};
use crate::spatial::Motion;

/// What a constraint holds.
#[derive(Debug, Clone, PartialEq)]
pub enum ConstraintKind {
    /// Point `p1` on `body1` coincides with point `p2` on `body2` (3 rows, force on body1 in I).
    Point {
        /// First body.
        body1: usize,
        /// Point on body1, body frame.
        p1: Vec3,
        /// Second body.
        body2: usize,
        /// Point on body2, body frame.
        p2: Vec3,
    },
    /// |r_P1 - r_P2| = length (1 row; λ is the tension pulling the points together).
    Distance {
        /// First body.
        body1: usize,
        /// Point on body1, body frame.
        p1: Vec3,
        /// Second body.
        body2: usize,
        /// Point on body2, body frame.
        p2: Vec3,
        /// Distance (m), > 0.
        length: f64,
    },
    /// q[iq_a] = ratio · q[iq_b] + offset between single coordinates (velocities iu_a, iu_b).
    Coupler {
        /// Coordinate index of the driven coordinate.
        iq_a: usize,
        /// Velocity index of the driven coordinate.
        iu_a: usize,
        /// Coordinate index of the driving coordinate.
        iq_b: usize,
        /// Velocity index of the driving coordinate.
        iu_b: usize,
        /// Ratio.
        ratio: f64,
        /// Offset.
        offset: f64,
    },
    /// q[iq] = f(t) (1 row): a driven joint; λ is the driving force or torque.
    Prescribed {
        /// Coordinate index.
        iq: usize,
        /// Velocity index.
        iu: usize,
        /// The motion.
        function: TimeFunction,
    },
}

/// A named constraint with its row offset in the stacked constraint vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Constraint {
    /// Unique name.
    pub name: String,
    /// What it holds.
    pub kind: ConstraintKind,
    /// Offset of its rows.
    pub row: usize,
}

impl ConstraintKind {
    /// Number of scalar equations.
    pub fn rows(&self) -> usize {
        match self {
            ConstraintKind::Point { .. } => 3,
            _ => 1,
        }
    }
}

/// Adds `sign · dirᵀ J_T(point)` (or all three rows of `sign · J_T` when `dir` is None) of the
/// world point `p` attached to `body` into the rows of `g` starting at `row`.
#[allow(clippy::too_many_arguments)]
fn add_point_rows(model: &Model, s_all: &[[Motion; 6]], body: usize, p: &Vec3, sign: f64, dir: Option<&Vec3>, g: &mut DMatrix<f64>, row: usize) {
    let mut b = body;
    while b != 0 {
        let j = &model.joints[b - 1];
        for k in 0..j.nu() {
            let s = &s_all[b][k];
            let v = (s.v + s.w.cross(p)) * sign;
            match dir {
                Some(d) => g[(row, j.iu + k)] += d.dot(&v),
                None => {
                    for r in 0..3 {
                        g[(row + r, j.iu + k)] += v[r];
                    }
                }
            }
        }
        b = j.parent;
    }
}

/// Value and first two time derivatives of a time function (callbacks by central differences).
pub fn function_derivatives(f: &TimeFunction, t: f64, cb: &dyn Callbacks) -> Result<(f64, f64, f64)> {
    Ok(match f {
        TimeFunction::Constant(v) => (*v, 0.0, 0.0),
        TimeFunction::Ramp { slope, t0, .. } => {
            let v = f.eval(t, cb)?;
            let rising = t >= *t0 && (v - slope * (t - t0)).abs() < 1e-300f64.max(1e-12 * v.abs());
            (v, if rising { *slope } else { 0.0 }, 0.0)
        }
        TimeFunction::Harmonic { amplitude, omega, phase, offset } => {
            let (s, c) = (omega * t + phase).sin_cos();
            (offset + amplitude * s, amplitude * omega * c, -amplitude * omega * omega * s)
        }
        TimeFunction::Table { t: ts, values } => {
            let v = f.eval(t, cb)?;
            let n = ts.len();
            let slope = if n < 2 || t <= ts[0] || t >= ts[n - 1] {
                0.0
            } else {
                let k = ts.partition_point(|x| *x <= t).clamp(1, n - 1);
                (values[k] - values[k - 1]) / (ts[k] - ts[k - 1])
            };
            (v, slope, 0.0)
        }
        TimeFunction::Callback(_) => {
            let h = 1e-4 * t.abs().max(1.0);
            let (fm, f0, fp) = (f.eval(t - h, cb)?, f.eval(t, cb)?, f.eval(t + h, cb)?);
            (f0, (fp - fm) / (2.0 * h), (fp - 2.0 * f0 + fm) / (h * h))
        }
    })
}

/// Position stage of the constraints: `phi` (m) and `G` (m × nu) at the last
/// [`crate::kinematics::positions`]; `b` (m) receives the velocity right-hand side `G u = b`.
pub fn positions(model: &Model, data: &mut Data, t: f64, q: &[f64], cb: &dyn Callbacks) -> Result<()> {
    data.g.fill(0.0);
    for c in &model.constraints {
        let r = c.row;
        match &c.kind {
            ConstraintKind::Point { body1, p1, body2, p2 } => {
                let (w1, w2) = (point_position(data, *body1, p1), point_position(data, *body2, p2));
                let d = w1 - w2;
                for k in 0..3 {
                    data.phi[r + k] = d[k];
                    data.b[r + k] = 0.0;
                }
                add_point_rows(model, &data.s, *body1, &w1, 1.0, None, &mut data.g, r);
                add_point_rows(model, &data.s, *body2, &w2, -1.0, None, &mut data.g, r);
            }
            ConstraintKind::Distance { body1, p1, body2, p2, length } => {
                let (w1, w2) = (point_position(data, *body1, p1), point_position(data, *body2, p2));
                let d = w1 - w2;
                let l = d.norm();
                if l < 1e-12 * length.max(1.0) {
                    return Err(Error::Solver(format!(
                        "constraint '{}': its two points coincide at t = {t} s, the distance direction is undefined",
                        c.name
                    )));
                }
                let e = d / l;
                data.phi[r] = l - length;
                data.b[r] = 0.0;
                add_point_rows(model, &data.s, *body1, &w1, 1.0, Some(&e), &mut data.g, r);
                add_point_rows(model, &data.s, *body2, &w2, -1.0, Some(&e), &mut data.g, r);
            }
            ConstraintKind::Coupler { iq_a, iu_a, iq_b, iu_b, ratio, offset } => {
                data.phi[r] = q[*iq_a] - ratio * q[*iq_b] - offset;
                data.b[r] = 0.0;
                data.g[(r, *iu_a)] += 1.0;
                data.g[(r, *iu_b)] -= ratio;
            }
            ConstraintKind::Prescribed { iq, iu, function } => {
                let (f, fd, _) = function_derivatives(function, t, cb)?;
                data.phi[r] = q[*iq] - f;
                data.b[r] = fd;
                data.g[(r, *iu)] += 1.0;
            }
        }
    }
    Ok(())
}

/// Acceleration right-hand side `γ` of `G u̇ = γ` (m). Requires the velocities of the state and
/// `data.a` holding the velocity-product accelerations (accelerations at u̇ = 0, no gravity).
pub fn accelerations(model: &Model, data: &mut Data, t: f64, cb: &dyn Callbacks) -> Result<()> {
    for c in &model.constraints {
        let r = c.row;
        match &c.kind {
            ConstraintKind::Point { body1, p1, body2, p2 } => {
                let a = point_acceleration(data, *body1, p1) - point_acceleration(data, *body2, p2);
                for k in 0..3 {
                    data.gamma[r + k] = -a[k];
                }
            }
            ConstraintKind::Distance { body1, p1, body2, p2, .. } => {
                let d = point_position(data, *body1, p1) - point_position(data, *body2, p2);
                let l = d.norm();
                let e = d / l;
                let v = point_velocity(data, *body1, p1) - point_velocity(data, *body2, p2);
                let a = point_acceleration(data, *body1, p1) - point_acceleration(data, *body2, p2);
                // d²|d|/dt² = e·a + (|v|² - (e·v)²)/|d|
                data.gamma[r] = -(e.dot(&a) + (v.norm_squared() - e.dot(&v).powi(2)) / l);
            }
            ConstraintKind::Coupler { .. } => data.gamma[r] = 0.0,
            ConstraintKind::Prescribed { function, .. } => {
                data.gamma[r] = function_derivatives(function, t, cb)?.2;
            }
        }
    }
    Ok(())
}

/// Adds the constraint forces `Gᵀ λ` of the last solve to the loads: point forces on the bodies
/// (`data.f_ext`) and generalized forces on joint coordinates (`data.tau_applied`), so that the
/// reaction forces at the joints include them.
pub fn apply_forces(model: &Model, data: &mut Data) {
    for c in &model.constraints {
        let r = c.row;
        match &c.kind {
            ConstraintKind::Point { body1, p1, body2, p2 } => {
                let l = Vec3::new(data.lambda[r], data.lambda[r + 1], data.lambda[r + 2]);
                add_point_force(data, *body1, p1, &l);
                add_point_force(data, *body2, p2, &(-l));
            }
            ConstraintKind::Distance { body1, p1, body2, p2, .. } => {
                let d = point_position(data, *body1, p1) - point_position(data, *body2, p2);
                let f = d / d.norm() * data.lambda[r];
                add_point_force(data, *body1, p1, &f);
                add_point_force(data, *body2, p2, &(-f));
            }
            ConstraintKind::Coupler { iu_a, iu_b, ratio, .. } => {
                data.tau_applied[*iu_a] += data.lambda[r];
                data.tau_applied[*iu_b] -= ratio * data.lambda[r];
            }
            ConstraintKind::Prescribed { iu, .. } => data.tau_applied[*iu] += data.lambda[r],
        }
    }
}

fn add_point_force(data: &mut Data, body: usize, p_b: &Vec3, f: &Vec3) {
    if body != 0 {
        let p = point_position(data, body, p_b);
        data.f_ext[body] += crate::spatial::Force::new(p.cross(f), *f);
    }
}

#[cfg(test)]
mod tests;
