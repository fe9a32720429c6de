//! Evaluating the dynamics of a model with a compliant contact group (broad phase, narrow phase
//! of the pairs it keeps, Hertz forces with damping and regularized friction) allocates nothing
//! once every pair has been met (a counting global allocator, per thread).

use mechsys_core::contact::group::sphere_pile;
use mechsys_core::data::Data;
use mechsys_core::dynamics::{forward_dynamics, Workspace};
use mechsys_core::forces::NoCallbacks;
use mechsys_core::model::{Model, ModelDescription};

mod common;
use common::allocations;

#[global_allocator]
static A: common::Counting = common::Counting;

#[test]
fn compliant_group_evaluations_do_not_allocate_after_the_pairs_are_met() {
    // the rigid pile fixture, its group made compliant (Hertz with damping, soft material)
    let rigid = sphere_pile(27, 0.05, 0.1, 0.17, 0.3, 0.0, 3);
    let impact = format!("\"impact\": {{\"type\": \"newton\", \"eps\": {}}}", 0.0f64);
    assert!(rigid.contains(&impact));
    let json = rigid.replace(
        &impact,
        "\"normal\": {\"type\": \"hertz\", \"alpha\": 0.5, \"v_reg\": 0.001}, \"material\": {\"E\": 1e7, \"nu\": 0.3, \"density\": 191}",
    );
    let model = Model::from_description(ModelDescription::from_json(&json).unwrap()).unwrap();
    assert!(model.contact_groups.is_empty() && model.n_compliant_points == 1);
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    let (q0, u) = (model.q0(), model.u0());
    let mut q = q0.clone();
    // the spheres pressed down and towards one wall, deeper at every evaluation: more pairs touch
    let mut pass = |data: &mut Data, ws: &mut Workspace| -> (usize, f64) {
        let before = allocations();
        let mut force = 0.0;
        for k in 0..60 {
            for i in 0..27 {
                q[7 * i] = q0[7 * i] - 1e-3 * k as f64;
                q[7 * i + 2] = q0[7 * i + 2] * (1.0 - 0.01 * k as f64);
            }
            forward_dynamics(&model, data, ws, 0.0, &q, &u, None, &NoCallbacks).unwrap();
            // the group's recorded total normal force
            force += data.element_force[0];
        }
        (allocations() - before, force)
    };
    let (first, force) = pass(&mut data, &mut ws);
    assert!(first > 0, "the first pass meets the pairs");
    assert!(force > 0.0, "the spheres touch");
    let (second, force2) = pass(&mut data, &mut ws);
    assert_eq!(force2, force, "the same evaluations");
    assert_eq!(second, 0, "{second} allocations in 60 evaluations after the pairs were met");
}
