//! Reaction forces at the cuts (section 2.1.2): cutting the tree at a joint exposes the wrench the
//! parent body exerts on the child body. It follows from the Newton–Euler equations of the subtree
//! beyond the cut, which is what the inward pass of the RNEA sums
//! (`f_i = Σ_subtree (I a + v ×* I v − f_ext)`, gravity included through the base acceleration). Its component along the joint's
//! motion subspace is the active joint force (springs, dampers, drives); the rest is the passive
//! constraint force of the joint.

use crate::data::Data;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::math::Vec3;
use crate::model::Model;

/// The wrench the parent exerts on the child through each joint, at the child joint frame's origin,
/// in child-joint-frame components: `force[j]`, `torque[j]` (one entry per joint). `udot` must be
/// the accelerations of the state (from forward dynamics), or the result includes the generalized
/// forces that would be needed to produce them.
#[allow(clippy::too_many_arguments)]
pub fn joint_reactions(
    model: &Model,
    data: &mut Data,
    ws: &mut super::Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    udot: &[f64],
    cb: &dyn Callbacks,
    force: &mut [Vec3],
    torque: &mut [Vec3],
) -> Result<()> {
    let mut tmp = std::mem::take(&mut data.scratch_u);
    if model.nc > 0 {
        // the loop closures and drives load the bodies too: solve for λ and add Gᵀ λ
        super::constrained::forward_dynamics(model, data, ws, t, q, u, None, cb)?;
        crate::constraints::apply_forces(model, data);
        let ud = std::mem::take(&mut data.udot);
        super::rnea::rnea_prepared(model, data, &ud, &mut tmp);
        data.udot = ud;
    } else {
        super::prepare(model, data, ws, t, q, u, cb)?;
        super::rnea::rnea_prepared(model, data, udot, &mut tmp);
    }
    data.scratch_u = tmp;
    for (ji, _) in model.joints.iter().enumerate() {
        let i = ji + 1;
        let f = &data.f[i];
        let x = &data.x_joint[i];
        // world wrench about the origin → about the joint point, then joint-frame components
        let n_joint = f.n - x.r.cross(&f.f);
        force[ji] = x.a.transpose() * f.f;
        torque[ji] = x.a.transpose() * n_joint;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;
    use crate::forces::NoCallbacks;

    /// A hanging chain at rest: each joint carries the weight of everything below it, and its
    /// moment about the joint balances that weight's lever arm.
    #[test]
    fn static_chain_carries_the_weight_below_each_joint() {
        let model = fixtures::chain(3, "revolute");
        let (mut data, mut ws) = (Data::new(&model), crate::dynamics::Workspace::new(&model));
        // straight down would be q = 0 for rods along x with gravity -z: all rods horizontal; the
        // reaction must balance gravity and the moment of the rods' weight (not an equilibrium, so
        // use the actual accelerations)
        let q = vec![0.0; 3];
        let u = vec![0.0; 3];
        crate::dynamics::forward_dynamics(&model, &mut data, &mut ws, 0.0, &q, &u, None, &NoCallbacks).unwrap();
        let udot = data.udot.clone();
        let mut f = vec![Vec3::zeros(); 3];
        let mut n = vec![Vec3::zeros(); 3];
        joint_reactions(&model, &mut data, &mut ws, 0.0, &q, &u, &udot, &NoCallbacks, &mut f, &mut n).unwrap();
        // the joints are free about their axes: no moment along the axis (z, y, x in joint frames)
        let axes = [Vec3::z(), Vec3::y(), Vec3::x()];
        for j in 0..3 {
            assert!(n[j].dot(&axes[j]).abs() < 1e-12, "joint {j}: axial moment {}", n[j].dot(&axes[j]));
        }
        // Newton for the whole chain: joint 1 force = Σ m (a_c - g)
        let mut total = Vec3::zeros();
        for i in 1..model.nbodies() {
            let a_c = crate::kinematics::point_acceleration(&data, i, &model.bodies[i].com);
            total += (a_c - model.gravity) * model.bodies[i].mass;
        }
        // joint 1's frame is the ground's (identity rotation at q = 0)
        assert!((f[0] - total).norm() < 1e-12, "{} vs {}", f[0], total);
    }
}
