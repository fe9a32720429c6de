//! Planar models: every body moves in the world x-y plane (three degrees of freedom at most per
//! body), so a loop closure holds only its in-plane rows.
//!
//! The dynamics stay those of the spatial tree (a tree of revolute joints about z, prismatic joints
//! in the plane and planar joints has exactly the planar motions), but a spatial loop closure of a
//! planar mechanism has rows that vanish identically: a revolute loop's "z-axes stay parallel"
//! rows, the out-of-plane force. They are dependent on nothing and on everything at once, so every
//! planar loop built in 3-D is redundant (a dense pivoted solve, a warning, minimum-norm
//! multipliers for the out-of-plane reactions). Here each such constraint keeps a constant
//! combination of its spatial rows ([`Selection`]): constant because a rotation about the world
//! z-axis leaves the z-components of body-fixed vectors unchanged, so the in-plane combinations
//! found at the initial configuration stay in-plane for ever.

use crate::data::Data;
use crate::error::{Error, Result};
use crate::math::Vec3;

use super::constraint::{ConstraintKind, LoopJoint, Selection};
use super::{JointKind, Model};

/// Relative tolerance for "is in the plane" / "is along z".
const TOL: f64 = 1e-9;

fn err(msg: String) -> Error {
    Error::Model(format!("planar model: {msg}"))
}

/// Checks that `model` is planar and replaces its constraints' rows by their in-plane selections
/// (renumbering the rows). Called once by validation when the description says `planar = true`.
pub(crate) fn planarize(model: &mut Model) -> Result<()> {
    let g = model.gravity;
    if g.z.abs() > TOL * g.norm().max(1.0) {
        return Err(err(format!(
            "gravity has a z-component ({:?}); the model moves in the world x-y plane, so gravity must lie in it",
            [g.x, g.y, g.z]
        )));
    }
    let mut data = Data::new(model);
    let q0 = model.q0();
    crate::kinematics::positions(model, &mut data, &q0);
    check_joints(model, &data)?;
    let mut row = 0;
    for ci in 0..model.constraints.len() {
        let select = selection(model, &data, ci)?;
        let c = &mut model.constraints[ci];
        c.select = select;
        c.row = row;
        row += c.rows();
    }
    model.nc = row;
    Ok(())
}

/// Every joint's motion stays in the plane: world angular velocities along z, point velocities
/// without a z-component (checked on the motion subspaces at q0; a tree of such joints keeps them
/// so at every configuration).
fn check_joints(model: &Model, data: &Data) -> Result<()> {
    for (ji, j) in model.joints.iter().enumerate() {
        let what = format!("joint '{}' ({})", j.name, j.kind.type_name());
        match j.kind {
            JointKind::Fixed | JointKind::Revolute { .. } | JointKind::Prismatic { .. } | JointKind::Planar => {}
            _ => {
                return Err(err(format!(
                    "{what} moves out of the plane; a planar model has revolute joints about z, prismatic joints in the x-y plane, planar joints (x, y, angle) for free bodies, and fixed joints"
                )))
            }
        }
        for k in 0..j.nu() {
            let s = &data.s[ji + 1][k];
            let scale = s.w.norm().max(s.v.norm()).max(1e-300);
            if s.w.x.abs().max(s.w.y.abs()) > TOL * scale {
                return Err(err(format!(
                    "{what} turns about the world axis {:?} at q0, not about z (rotate its frames so that its axis is the world z-axis)",
                    rounded(&s.w)
                )));
            }
            // the velocity of the point at the world origin; ω × r adds nothing along z
            if s.v.z.abs() > TOL * scale {
                return Err(err(format!(
                    "{what} moves along the world z-axis at q0 (direction {:?}); its motion must stay in the x-y plane",
                    rounded(&s.v)
                )));
            }
        }
    }
    Ok(())
}

fn rounded(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z].map(|c| (c * 1e9).round() / 1e9)
}

/// Orthonormal combinations `a` (over `dirs`, orthonormal world directions) with no z-component:
/// the null space of the row of z-components.
fn in_plane(dirs: &[Vec3]) -> Vec<Vec<f64>> {
    let cz: Vec<f64> = dirs.iter().map(|d| d.z).collect();
    let nz = cz.iter().map(|c| c * c).sum::<f64>().sqrt();
    let k = dirs.len();
    if nz <= TOL {
        return (0..k).map(|i| (0..k).map(|j| f64::from(u8::from(i == j))).collect()).collect();
    }
    let c: Vec<f64> = cz.iter().map(|v| v / nz).collect();
    // Gram–Schmidt of the unit vectors against c (and each other)
    let mut out: Vec<Vec<f64>> = vec![];
    for i in 0..k {
        let mut a: Vec<f64> = (0..k).map(|j| f64::from(u8::from(i == j))).collect();
        for b in std::iter::once(&c).chain(out.iter()) {
            let p: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
            a.iter_mut().zip(b).for_each(|(x, y)| *x -= p * y);
        }
        let n = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        if n > 1e-6 {
            out.push(a.into_iter().map(|x| x / n).collect());
        }
        if out.len() == k - 1 {
            break;
        }
    }
    out
}

/// The in-plane selection of constraint `ci` (None: it keeps all its rows).
fn selection(model: &Model, data: &Data, ci: usize) -> Result<Option<Selection>> {
    let c = &model.constraints[ci];
    let what = format!("constraint '{}'", c.name);
    let mut sel = Selection { n: 0, s: [[0.0; 6]; 3], names: [""; 3] };
    let push = |sel: &mut Selection, coef: &[(usize, f64)], name: &'static str| {
        for &(j, v) in coef {
            sel.s[sel.n][j] = v;
        }
        sel.names[sel.n] = name;
        sel.n += 1;
    };
    let axes = [Vec3::x(), Vec3::y(), Vec3::z()];
    match &c.kind {
        ConstraintKind::Distance { .. }
        | ConstraintKind::Coupler { .. }
        | ConstraintKind::Prescribed { .. }
        | ConstraintKind::Velocity { .. }
        | ConstraintKind::Contact { .. }
        | ConstraintKind::Gap { .. }
        | ConstraintKind::KnifeEdge { .. } => return Ok(None),
        ConstraintKind::RollingDisc { .. } => {
            return Err(err(format!("{what} (rolling disc) rolls out of the plane; it has no planar form")))
        }
        ConstraintKind::PointOnPlane { body2, n, .. } => {
            let nw = data.x_abs[*body2].a * n;
            if nw.x.hypot(nw.y) <= TOL {
                return Err(err(format!(
                    "{what} (point on plane): the plane's normal is the world z-axis, so it holds nothing in the x-y plane"
                )));
            }
            // n·d: the z-part of d is constant in a planar motion, the row stays one in-plane row
            return Ok(None);
        }
        ConstraintKind::Point { .. } => {
            push(&mut sel, &[(0, 1.0)], "x");
            push(&mut sel, &[(1, 1.0)], "y");
        }
        ConstraintKind::PrescribedBody { orientation, .. } => {
            push(&mut sel, &[(0, 1.0)], "x");
            push(&mut sel, &[(1, 1.0)], "y");
            if orientation.is_some() {
                // ½ vee(Q - Qᵀ) in world axes: only the angle about z (the third Cardan angle) moves
                push(&mut sel, &[(5, 1.0)], "rz");
            }
        }
        ConstraintKind::PointOnLine { body2, n, .. } => {
            let a2 = data.x_abs[*body2].a;
            let dirs = [a2 * n[0], a2 * n[1]];
            // one in-plane normal (a line in the plane), or both when the line is along z
            for (i, a) in in_plane(&dirs).into_iter().enumerate() {
                push(&mut sel, &[(0, a[0]), (1, a[1])], ["normal", "normal2"][i]);
            }
        }
        ConstraintKind::Loop { joint, body1, f1, body2, f2 } => {
            let (x1, x2) = (data.x_abs[*body1].compose(f1), data.x_abs[*body2].compose(f2));
            let z1 = x1.a.column(2).into_owned();
            let kind = format!("loop {}", loop_name(*joint));
            let along_z = z1.x.hypot(z1.y) <= TOL;
            match joint {
                LoopJoint::Universal => {
                    return Err(err(format!("{what} ({kind}) is spatial; it has no planar form")));
                }
                LoopJoint::Revolute | LoopJoint::Cylindrical | LoopJoint::Planar if !along_z => {
                    return Err(err(format!(
                        "{what} ({kind}): its axis (frame z) is {:?} in the world at q0; in a planar model it must be the world z-axis",
                        rounded(&z1)
                    )));
                }
                _ => {}
            }
            // translation rows: world axes, or frame-2 axes for the sliding kinds
            let (dirs, offset): (Vec<Vec3>, Vec<usize>) = match joint {
                LoopJoint::Prismatic | LoopJoint::Cylindrical => {
                    (vec![x2.a.column(0).into_owned(), x2.a.column(1).into_owned()], vec![0, 1])
                }
                LoopJoint::Planar => (vec![x2.a.column(2).into_owned()], vec![0]),
                _ => (axes.to_vec(), vec![0, 1, 2]),
            };
            let sliding = matches!(joint, LoopJoint::Prismatic | LoopJoint::Cylindrical | LoopJoint::Planar);
            for (i, a) in in_plane(&dirs).into_iter().enumerate() {
                let coef: Vec<(usize, f64)> = offset.iter().map(|&j| (j, a[j])).collect();
                // world axes give x and y exactly; the sliding kinds hold the in-plane normal(s)
                let name = if sliding { ["normal", "normal2"][i] } else { ["x", "y"][i] };
                push(&mut sel, &coef, name);
            }
            if matches!(joint, LoopJoint::Fixed | LoopJoint::Prismatic) {
                // Φ_rot = ½ vee(R - Rᵀ) in frame-2 axes: the rotation about the world z-axis is
                // its component along ez expressed in frame 2 (constant)
                let cz = x2.a.transpose() * Vec3::z();
                let k0 = dirs.len();
                push(&mut sel, &[(k0, cz.x), (k0 + 1, cz.y), (k0 + 2, cz.z)], "rz");
            }
            if sel.n == 0 {
                return Err(err(format!("{what} ({kind}) holds nothing in the x-y plane")));
            }
        }
    }
    Ok(Some(sel))
}

fn loop_name(j: LoopJoint) -> &'static str {
    match j {
        LoopJoint::Spherical => "spherical",
        LoopJoint::Revolute => "revolute",
        LoopJoint::Fixed => "fixed",
        LoopJoint::Prismatic => "prismatic",
        LoopJoint::Cylindrical => "cylindrical",
        LoopJoint::Universal => "universal",
        LoopJoint::Planar => "planar",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_plane_combinations_have_no_z_component_and_are_orthonormal() {
        let dirs = [Vec3::x(), Vec3::y(), Vec3::z()];
        assert_eq!(in_plane(&dirs), vec![vec![1.0, 0.0, 0.0], vec![0.0, 1.0, 0.0]]);
        // two unit normals of a sliding axis in the plane: one combination stays in the plane
        let t = 0.4f64;
        let n1 = Vec3::new(0.0, 0.0, 1.0);
        let n2 = Vec3::new(-t.sin(), t.cos(), 0.0);
        let tilted = [(n1 * 0.6 + n2 * 0.8), (n2 * 0.6 - n1 * 0.8)];
        let a = in_plane(&tilted);
        assert_eq!(a.len(), 1);
        let v = tilted[0] * a[0][0] + tilted[1] * a[0][1];
        assert!(v.z.abs() < 1e-15 && (v.norm() - 1.0).abs() < 1e-15);
        assert!((v - n2).norm() < 1e-15 || (v + n2).norm() < 1e-15);
        // a single direction along z leaves nothing
        assert!(in_plane(&[Vec3::z()]).is_empty());
    }
}
