//! The Moreau–Jean step on a contact group allocates nothing once every pair has been met and
//! every buffer has grown to the largest problem (a counting global allocator, per thread).

use mechsys_core::contact::group::sphere_pile;
use mechsys_core::data::Data;
use mechsys_core::dynamics::Workspace;
use mechsys_core::forces::NoCallbacks;
use mechsys_core::integrator::moreau_jean::MoreauJean;
use mechsys_core::model::{Model, ModelDescription};
use mechsys_core::solver::{ApgdOptions, AutoOptions, Method, NewtonOptions, NsgsOptions};

mod common;
use common::allocations;

#[global_allocator]
static A: common::Counting = common::Counting;

/// 27 spheres poured into a box: a first pass meets every pair and sizes every buffer; the same
/// run repeated from the start (same stepper) then allocates nothing, in about 11 000 contact
/// solves.
#[test]
fn group_steps_do_not_allocate_after_warm_up() {
    pile_steps_do_not_allocate_after_warm_up(Method::Nsgs(NsgsOptions {
        tol: 1e-8,
        max_iter: 500,
        relaxation: 1.0,
        anderson: 0,
        stall: 0,
    }));
}

/// The same with Anderson-accelerated sweeps (NSGS with a history of 4, and the auto solver's
/// Gauss–Seidel above its Newton size).
#[test]
fn group_steps_with_anderson_do_not_allocate_after_warm_up() {
    let nsgs = NsgsOptions { tol: 1e-8, max_iter: 500, relaxation: 1.0, anderson: 4, stall: 0 };
    pile_steps_do_not_allocate_after_warm_up(Method::Nsgs(nsgs));
    let auto = AutoOptions { tol: 1e-8, newton_max_unknowns: 0, nsgs_max_iter: 500, ..Default::default() };
    pile_steps_do_not_allocate_after_warm_up(Method::Auto(auto));
}

/// The same with Newton's direction in body space (its ordering, fill pattern and factors grown
/// to the largest contact graph of the run).
#[test]
fn group_steps_with_body_space_newton_do_not_allocate_after_warm_up() {
    let newton = NewtonOptions { tol: 1e-8, body_space_above: 0, ..Default::default() };
    pile_steps_do_not_allocate_after_warm_up(Method::Newton(newton));
}

/// The same with the accelerated projected gradient (its scratch sized once in the workspace).
#[test]
fn group_steps_with_apgd_do_not_allocate_after_warm_up() {
    pile_steps_do_not_allocate_after_warm_up(Method::Apgd(ApgdOptions { tol: 1e-8, max_iter: 500 }));
}

fn pile_steps_do_not_allocate_after_warm_up(method: Method) {
    let model =
        Model::from_description(ModelDescription::from_json(&sphere_pile(27, 0.05, 0.1, 0.17, 0.3, 0.2, 3)).unwrap())
            .unwrap();
    let h = 1e-3;
    let mut st = MoreauJean::new(&model, h, method).unwrap();
    assert!(st.is_sparse());
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    let mut stats = vec![Default::default(); 1];
    let mut run = |st: &mut MoreauJean, data: &mut Data, ws: &mut Workspace| -> (usize, usize) {
        let (mut q, mut u) = (model.q0(), model.u0());
        let mut contacts = 0;
        let before = allocations();
        for k in 0..400 {
            st.step(&model, data, ws, k as f64 * h, &mut q, &mut u, &NoCallbacks).unwrap();
            st.take_group_stats(&mut stats);
            contacts += stats[0].closed;
        }
        (allocations() - before, contacts)
    };
    let (first, contacts) = run(&mut st, &mut data, &mut ws);
    assert!(first > 0, "the first pass creates the pairs");
    assert!(contacts > 5000, "only {contacts} closed contact points over the run");
    let (second, contacts2) = run(&mut st, &mut data, &mut ws);
    assert_eq!(contacts2, contacts, "the repeated run is the same run");
    assert_eq!(second, 0, "{second} allocations in 400 steps after warm-up");
}

/// A ball rolling in a spherical bowl (an explicit curved contact, dense assembly) with the
/// position projection on: every step projects, and none allocates after the first.
#[test]
fn projected_steps_do_not_allocate() {
    let json = r#"{
        "name": "bowl",
        "gravity": [0.0, 0.0, -9.81],
        "bodies": [{"name": "ball", "mass": 1.0, "inertia": [0.004, 0.004, 0.004]}],
        "joints": [{"name": "free", "type": "free", "parent": "ground", "child": "ball",
                    "q0": [0.05, 0.0, -0.39686269665968863, 1.0, 0.0, 0.0, 0.0]}],
        "contacts": [{"name": "bowl", "body1": "ball", "contour1": {"type": "sphere", "radius": 0.1},
                      "body2": "ground", "contour2": {"type": "bowl", "radius": 0.5},
                      "friction": {"type": "coulomb", "mu": 0.8}}]
    }"#;
    let model = Model::from_description(ModelDescription::from_json(json).unwrap()).unwrap();
    let h = 1e-3;
    let method = Method::Nsgs(NsgsOptions { tol: 1e-10, max_iter: 500, relaxation: 1.0, anderson: 0, stall: 0 });
    let mut st = MoreauJean::new(&model, h, method).unwrap();
    st.project = true;
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    let (mut q, mut u) = (model.q0(), model.u0());
    for k in 0..50 {
        st.step(&model, &mut data, &mut ws, k as f64 * h, &mut q, &mut u, &NoCallbacks).unwrap();
    }
    let before = allocations();
    for k in 50..400 {
        st.step(&model, &mut data, &mut ws, k as f64 * h, &mut q, &mut u, &NoCallbacks).unwrap();
    }
    let n = allocations() - before;
    assert!(st.projections() > 300, "only {} projected steps", st.projections());
    assert_eq!(n, 0, "{n} allocations in 350 projected steps");
}

/// A roller pressed by gravity on a spinning elliptical cam (a planar curve pair whose contact
/// search warm-starts between steps): after a first run, the same run allocates nothing, warm
/// starts and cold searches alike.
#[test]
fn curve_contact_steps_do_not_allocate_after_warm_up() {
    let model = mechsys_core::fixtures::ellipse_cam(20.0, 0.061);
    let h = 1e-4;
    let method = Method::Nsgs(NsgsOptions { tol: 1e-10, max_iter: 500, relaxation: 1.0, anderson: 0, stall: 0 });
    let mut st = MoreauJean::new(&model, h, method).unwrap();
    assert!(st.warm_search);
    let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
    let run = |st: &mut MoreauJean, data: &mut Data, ws: &mut Workspace| -> (usize, f64) {
        let (mut q, mut u) = (model.q0(), model.u0());
        let before = allocations();
        for k in 0..2000 {
            st.step(&model, data, ws, k as f64 * h, &mut q, &mut u, &NoCallbacks).unwrap();
        }
        (allocations() - before, q[1])
    };
    let (_, y1) = run(&mut st, &mut data, &mut ws);
    let (second, y2) = run(&mut st, &mut data, &mut ws);
    assert_eq!(second, 0, "{second} allocations in 2000 steps after warm-up");
    assert!((y1 - y2).abs() < 1e-12, "the repeated run is the same run: {y1} vs {y2}");
}
