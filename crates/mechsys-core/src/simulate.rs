//! The simulation loop: the model's equations of motion as a first-order system, one integrator,
//! and the record stage, which samples every signal at the output times into preallocated arrays.
//!
//! The integrated state is `y = [q, u, E_diss, W_ext]`: besides coordinates and velocities it
//! carries the energy dissipated by dampers and the work of external loads, so that the energy
//! balance `T + V + E_diss - W_ext = const` can be checked on any result.

mod events_json;

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

pub use events_json::events_json;

use serde::{Deserialize, Serialize};

use crate::data::Data;
use crate::dynamics::sparse::Saddle;
use crate::dynamics::{self, energy};
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::integrator::{self, IntegratorKind, OdeSystem, Stats};
use crate::kinematics::{point_acceleration, point_velocity};
use crate::model::{ForceElement, Model};

/// Settings of one simulation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// Start time (s).
    #[serde(default)]
    pub t0: f64,
    /// End time (s).
    pub t_end: f64,
    /// Interval between recorded samples (s).
    pub output_dt: f64,
    /// The integration scheme.
    pub integrator: IntegratorKind,
    /// Initial coordinates (nq); the model's q0 if absent.
    #[serde(default)]
    pub q0: Option<Vec<f64>>,
    /// Initial velocities (nu); the model's u0 if absent.
    #[serde(default)]
    pub u0: Option<Vec<f64>>,
    /// Drift control of the constraints.
    #[serde(default)]
    pub stabilization: Stabilization,
    /// What a singular configuration (the constraint rows lose rank) does to the run.
    #[serde(default)]
    pub on_singular: OnSingular,
    /// Most accepted steps of a smooth scheme (RK4, DOPRI5, Radau5) before the run stops.
    #[serde(default)]
    pub max_steps: Option<u64>,
    /// Most wall-clock seconds before the run stops (checked at every sample and every 256 steps).
    #[serde(default)]
    pub max_wall: Option<f64>,
    /// What is recorded beyond the state, energies and momenta (default: everything).
    #[serde(default)]
    pub record: RecordSelection,
    /// Warm-start the contact searches of planar parametric contours (default; the same roots as
    /// cold searches, see [`crate::contact::SearchHint`]); `false`: every evaluation searches cold.
    #[serde(default = "warm_search_default")]
    pub warm_search: bool,
}

fn warm_search_default() -> bool {
    true
}

/// Which groups of signals a run records. The state (t, q, u), energies, momenta and contact
/// signals are always recorded; a large model asked for a few signals skips the rest (a body's
/// states are 23 values per sample).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSelection {
    /// Bodies whose states (position, orientation, velocities, accelerations, mass, kinetic
    /// energy) are recorded, by name; None: all.
    #[serde(default)]
    pub bodies: Option<Vec<String>>,
    /// Generalized and body accelerations.
    #[serde(default = "yes")]
    pub accelerations: bool,
    /// Constraint multipliers and violations.
    #[serde(default = "yes")]
    pub constraints: bool,
    /// Force elements' forces and deflections.
    #[serde(default = "yes")]
    pub forces: bool,
    /// The contact points' signals (gap, point, normal, rates, forces, impulses, state, reserve):
    /// without them Moreau–Jean also skips the contact kinematics at each sample (a narrow phase
    /// per pair). The solver's signals and the contact energies are recorded either way.
    #[serde(default = "yes")]
    pub contacts: bool,
}

fn yes() -> bool {
    true
}

impl Default for RecordSelection {
    fn default() -> Self {
        RecordSelection { bodies: None, accelerations: true, constraints: true, forces: true, contacts: true }
    }
}

/// The run's budgets ([`Settings::max_steps`], [`Settings::max_wall`]) and the clock.
#[derive(Debug, Clone)]
pub struct Budget {
    start: std::time::Instant,
    max_steps: Option<u64>,
    max_wall: Option<f64>,
    steps: u64,
}

impl Budget {
    /// Starts the clock.
    pub fn new(settings: &Settings) -> Self {
        Budget {
            start: std::time::Instant::now(),
            max_steps: settings.max_steps,
            max_wall: settings.max_wall,
            steps: 0,
        }
    }

    /// An error once the wall-time budget is spent.
    pub fn wall(&self, t: f64) -> Result<()> {
        if let Some(w) = self.max_wall {
            let used = self.start.elapsed().as_secs_f64();
            if used > w {
                return Err(Error::Solver(format!(
                    "wall-time budget of {w} s spent at t = {t:.6} s ({used:.3} s): raise max_wall, or shorten the run"
                )));
            }
        }
        Ok(())
    }

    /// Counts an accepted step; an error once the step budget is spent.
    pub fn step(&mut self, t: f64) -> Result<()> {
        self.steps += 1;
        if let Some(n) = self.max_steps {
            if self.steps > n {
                return Err(Error::Solver(format!(
                    "step budget of {n} accepted steps spent at t = {t:.6} s: raise max_steps, or look for what makes the \
                     steps small (a stiff element, a near-singular configuration, a tolerance too tight)"
                )));
            }
        }
        if self.steps % 256 == 0 {
            self.wall(t)?;
        }
        Ok(())
    }
}

/// What a run does where the constraint equations lose rank (a dead point, a change point of a
/// mechanism such as a parallelogram four-bar passing its flat position).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OnSingular {
    /// Go on with minimum-norm multipliers and note the passage as a warning (time and rows).
    #[default]
    Continue,
    /// Stop with a `SolverError` naming the constraint.
    Stop,
}

/// How the constraint drift of a simulation is controlled.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Stabilization {
    /// Project q and u onto the constraint manifolds after every step (exact to round-off).
    #[default]
    Projection,
    /// Baumgarte: enforce `Φ̈ + 2α Φ̇ + β² Φ = 0` instead of `Φ̈ = 0`; cruder (the violation decays
    /// but never vanishes, and large α, β stiffen the equations), kept for comparison with codes
    /// that use it.
    Baumgarte {
        /// Velocity feedback (1/s).
        alpha: f64,
        /// Position feedback (1/s).
        beta: f64,
    },
    /// No drift control: the violation grows with the integration error.
    None,
}

/// Recorded signals, sample-major flat arrays (`n_out` samples).
#[derive(Debug, Clone, Default)]
pub struct Recording {
    /// Number of samples.
    pub n_out: usize,
    /// Number of bodies recorded (the model's bodies without the ground, or the selected ones).
    pub n_bodies: usize,
    /// Model indices of the recorded bodies (1-based: 0 is the ground), in recording order.
    pub body_index: Vec<usize>,
    /// What was recorded.
    pub selection: RecordSelection,
    /// Sample times (n_out), s.
    pub t: Vec<f64>,
    /// Coordinates (n_out × nq).
    pub q: Vec<f64>,
    /// Velocities (n_out × nu).
    pub u: Vec<f64>,
    /// Accelerations (n_out × nu).
    pub udot: Vec<f64>,
    /// Body-frame origin positions, I components (n_out × n_bodies × 3), m.
    pub body_position: Vec<f64>,
    /// Body orientations as unit quaternions [w, x, y, z] of A_IB (n_out × n_bodies × 4).
    pub body_orientation: Vec<f64>,
    /// Velocities of body-frame origins, I components (n_out × n_bodies × 3), m/s.
    pub body_velocity: Vec<f64>,
    /// Angular velocities, I components (n_out × n_bodies × 3), rad/s.
    pub body_angular_velocity: Vec<f64>,
    /// Accelerations of body-frame origins, I components (n_out × n_bodies × 3), m/s².
    pub body_acceleration: Vec<f64>,
    /// Angular accelerations, I components (n_out × n_bodies × 3), rad/s².
    pub body_angular_acceleration: Vec<f64>,
    /// Body masses (n_out × n_bodies), kg.
    pub body_mass: Vec<f64>,
    /// Kinetic energy (n_out), J.
    pub kinetic: Vec<f64>,
    /// Kinetic energy per body (n_out × n_bodies), J.
    pub body_kinetic: Vec<f64>,
    /// Potential energy of gravity and springs (n_out), J.
    pub potential: Vec<f64>,
    /// Energy dissipated by dampers since t0 (n_out), J.
    pub dissipated: Vec<f64>,
    /// Work of external loads since t0 (n_out), J.
    pub external_work: Vec<f64>,
    /// Linear momentum, I components (n_out × 3), N s.
    pub momentum_linear: Vec<f64>,
    /// Moment of momentum about the inertial origin, I components (n_out × 3), N m s.
    pub momentum_angular: Vec<f64>,
    /// Constraint multipliers λ (n_out × nc).
    pub constraint_lambda: Vec<f64>,
    /// Constraint violations Φ (n_out × nc).
    pub constraint_violation: Vec<f64>,
    /// Velocity-level constraint residuals `G u - b` (n_out × nc).
    pub constraint_velocity_violation: Vec<f64>,
    /// Force of each force element along its deflection, resisting it (n_out × n_force_outputs).
    pub force_value: Vec<f64>,
    /// Deflection of each force element (n_out × n_force_outputs).
    pub force_deflection: Vec<f64>,
    /// Set when the run was cancelled from outside: the message; the samples before it are kept.
    pub cancelled: Option<String>,
    /// Notes on the run that did not stop it (near-singular configurations), in time order.
    pub warnings: Vec<String>,
    /// Contact gaps g_N per candidate point (n_out × n_points), m.
    pub contact_gap: Vec<f64>,
    /// Contact points on contour 1's surface, I components (n_out × points × 3), m.
    pub contact_point: Vec<f64>,
    /// Contact normals from contour 2 towards contour 1, I components (n_out × points × 3).
    pub contact_normal: Vec<f64>,
    /// Friction forces on contour 1's body, λ_T1 t1 + λ_T2 t2, I components (n_out × points × 3), N.
    pub contact_friction: Vec<f64>,
    /// Relative normal velocities ġ_N (n_out × n_points), m/s.
    pub contact_gd_n: Vec<f64>,
    /// Relative tangential velocities ġ_T (n_out × n_points × 2), m/s.
    pub contact_gd_t: Vec<f64>,
    /// Relative angular velocities in the contact frame, [spin about n, rolling about t1, t2]
    /// (n_out × n_points × 3), rad/s.
    pub contact_omega: Vec<f64>,
    /// Normal contact force λ_N: the impulse since the previous sample over that interval
    /// (n_out × n_points), N.
    pub contact_lambda_n: Vec<f64>,
    /// Tangential contact forces λ_T (n_out × n_points × 2), N.
    pub contact_lambda_t: Vec<f64>,
    /// Normal impulses Λ_N summed since the previous sample (n_out × n_points), N s.
    pub contact_impulse_n: Vec<f64>,
    /// Tangential impulses Λ_T summed since the previous sample (n_out × n_points × 2), N s.
    pub contact_impulse_t: Vec<f64>,
    /// Contact state (0 open, 1 stick, 2 slip) (n_out × n_points).
    pub contact_state: Vec<f64>,
    /// Friction reserve µ0 λ_N − |λ_T| (n_out × n_points), N.
    pub contact_reserve: Vec<f64>,
    /// Energy dissipated by normal impulses since t0 (n_out), J.
    pub dissipated_impact: Vec<f64>,
    /// Energy dissipated by friction since t0 (n_out), J.
    pub dissipated_friction: Vec<f64>,
    /// Elastic energy held by compliant Signorini layers (n_out), J (Moreau–Jean; 0 otherwise).
    pub contact_elastic: Vec<f64>,
    /// Energy the steps' geometry took from the compliant layers between steps since t0
    /// (n_out), J ([`crate::integrator::moreau_jean::MoreauJean::contact_drift`]; 0 otherwise).
    pub contact_drift: Vec<f64>,
    /// Moreau–Jean's contact solver over the steps since the previous sample (n_out × 5): the
    /// worst residual (of [`crate::solver::Report::residual`], 1), the most iterations of a step,
    /// 1 if every step converged (else 0), the unknowns' contacts of the last step and its
    /// independent islands.
    pub solver: Vec<f64>,
    /// Contact groups: candidate points closed (positive normal impulse) in the last step before
    /// each sample (n_out × n_groups).
    pub group_closed: Vec<f64>,
    /// Contact groups: largest penetration at the step midpoints since the previous sample
    /// (n_out × n_groups), m.
    pub group_max_penetration: Vec<f64>,
    /// Contact groups: normal impulses summed over the group and since the previous sample
    /// (n_out × n_groups), N s.
    pub group_impulse_n: Vec<f64>,
    /// Contact groups: pairs kept by the broad phase in the last step (n_out × n_groups).
    pub group_pairs: Vec<f64>,
    /// Contact groups: impulse of the `against` contours on the members summed since the
    /// previous sample, world components (n_out × n_groups × 3), N s.
    pub group_impulse_against: Vec<f64>,
    /// Contact groups: the number of points closed in the last step before each sample
    /// (n_out × n_groups) and those points, in sample then group order, `[x, y, z, fx, fy, fz,
    /// state]` each (point on the first contour, force on its body in N, world components).
    pub group_point_count: Vec<usize>,
    /// See [`Recording::group_point_count`].
    pub group_points: Vec<[f64; 7]>,
    /// Contact events of either contact scheme, in time order.
    pub events: Vec<EventRecord>,
    /// Integrator counters.
    pub stats: Stats,
}

/// One contact event of a run ([`crate::integrator::events`]), with its contact named.
#[derive(Debug, Clone, PartialEq)]
pub struct EventRecord {
    /// Time (s).
    pub t: f64,
    /// The contact's name.
    pub contact: String,
    /// The point of the contact (0 for single-point contours).
    pub point: usize,
    /// impact, close, open, stick, slip or painleve.
    pub kind: &'static str,
    /// Normal and tangential impulses of the event at the point (N s).
    pub impulse: [f64; 3],
    /// Kinetic energy its impulses took (J).
    pub energy: f64,
    /// Generalized velocities before and after (impacts; empty otherwise).
    pub u_before: Vec<f64>,
    /// See `u_before`.
    pub u_after: Vec<f64>,
    /// Painlevé situations (see [`PainleveRecord`]).
    pub painleve: Option<PainleveRecord>,
    /// Consecutive time steps merged into the event (1 for the event-driven scheme).
    pub steps: usize,
}

/// What a Painlevé event recorded, with points named ("contact[k]").
#[derive(Debug, Clone, PartialEq)]
pub struct PainleveRecord {
    /// The sliding coefficient in use.
    pub mu: f64,
    /// The coefficient at which the normal acceleration per unit normal force vanishes.
    pub mu_critical: f64,
    /// True: two solutions; false: none (inconsistent).
    pub non_unique: bool,
    /// The points closed in each solution of a non-unique state.
    pub solutions: [Vec<String>; 2],
    /// The sliding was stopped by an impulse.
    pub resolved_by_impulse: bool,
}

impl Recording {
    /// Room for `samples` samples of the contact signals of `np` points (and the solver's): the
    /// time-stepping loop then records without reallocating (each growth copied the signals so
    /// far: 2 % of a box stack's run recorded at every step).
    fn reserve_contacts(&mut self, samples: usize, np: usize) {
        for (v, width) in [
            (&mut self.contact_gap, 1),
            (&mut self.contact_point, 3),
            (&mut self.contact_normal, 3),
            (&mut self.contact_friction, 3),
            (&mut self.contact_gd_n, 1),
            (&mut self.contact_gd_t, 2),
            (&mut self.contact_omega, 3),
            (&mut self.contact_lambda_n, 1),
            (&mut self.contact_lambda_t, 2),
            (&mut self.contact_impulse_n, 1),
            (&mut self.contact_impulse_t, 2),
            (&mut self.contact_state, 1),
            (&mut self.contact_reserve, 1),
        ] {
            v.reserve(samples * np * width);
        }
        self.dissipated_impact.reserve(samples);
        self.dissipated_friction.reserve(samples);
        self.contact_elastic.reserve(samples);
        self.contact_drift.reserve(samples);
        self.solver.reserve(5 * samples);
    }

    /// One sample of one contact point: its kinematics `kk`, the impulses since the last sample
    /// (normal, tangential), the forces, the friction force (world), its state code and reserve.
    fn push_contact_point(
        &mut self,
        kk: &crate::contact::ContactKinematics,
        impulse: (f64, [f64; 2]),
        lambda: (f64, [f64; 2]),
        friction: crate::math::Vec3,
        state: f64,
        reserve: f64,
    ) {
        self.contact_gap.push(kk.point.g_n);
        self.contact_point.extend_from_slice(kk.point.p1.as_slice());
        self.contact_normal.extend_from_slice(kk.point.n.as_slice());
        self.contact_gd_n.push(kk.gd_n);
        self.contact_gd_t.extend_from_slice(&kk.gd_t);
        self.contact_omega.extend_from_slice(&kk.omega_rel);
        self.contact_impulse_n.push(impulse.0);
        self.contact_impulse_t.extend_from_slice(&impulse.1);
        self.contact_lambda_n.push(lambda.0);
        self.contact_lambda_t.extend_from_slice(&lambda.1);
        self.contact_friction.extend_from_slice(friction.as_slice());
        self.contact_state.push(state);
        self.contact_reserve.push(reserve);
    }
}

impl EventRecord {
    fn from_log(model: &Model, log: &crate::integrator::events::EventLog) -> Vec<EventRecord> {
        let name = |pt: usize| {
            let c = model.contact_of_point(pt);
            format!("{}[{}]", c.name, pt - c.first)
        };
        log.events
            .iter()
            .map(|e| {
                let c = model.contact_of_point(e.point);
                let (u_before, u_after) = match e.velocities {
                    Some(at) => {
                        let (b, a) = log.velocities_at(at, model.nu);
                        (b.to_vec(), a.to_vec())
                    }
                    None => (Vec::new(), Vec::new()),
                };
                EventRecord {
                    t: e.t,
                    contact: c.name.clone(),
                    point: e.point - c.first,
                    kind: e.kind.as_str(),
                    impulse: e.impulse,
                    energy: e.energy,
                    u_before,
                    u_after,
                    painleve: e.painleve.as_ref().map(|p| {
                        let names = |v: &Vec<usize>| v.iter().map(|&pt| name(pt)).collect::<Vec<_>>();
                        PainleveRecord {
                            mu: p.mu,
                            mu_critical: p.mu_critical,
                            non_unique: p.non_unique,
                            solutions: [names(&p.solutions[0]), names(&p.solutions[1])],
                            resolved_by_impulse: p.resolved_by_impulse,
                        }
                    }),
                    steps: e.steps,
                }
            })
            .collect()
    }
}

/// Progress and cancellation shared with another thread (the Python progress bar).
#[derive(Debug, Default)]
pub struct Progress {
    /// Samples recorded so far.
    pub samples: AtomicU64,
    /// Set to stop the run early with an error.
    pub cancel: AtomicBool,
}

/// The equations of motion of a model as a first-order system.
pub struct MultibodySystem<'a> {
    model: &'a Model,
    /// The workspace (public so that observers can read the last evaluation).
    pub data: Data,
    /// The dynamics stage's own workspace (the factorization of the constrained solve).
    pub ws: dynamics::Workspace,
    cb: &'a dyn Callbacks,
    stabilization: Stabilization,
    /// Dependent rows and pivots of the constraint factorization at the first evaluation (a rank
    /// drop or a pivot that collapses later marks a singular configuration).
    start: Option<(Vec<bool>, Vec<f64>)>,
    /// Whether the last evaluation was near a singular configuration (one warning per passage).
    near_singular: bool,
    /// Whether the last evaluation had lost rank (one warning per passage).
    rank_lost: bool,
    /// Stop at a rank drop instead of going on.
    stop_at_singular: bool,
    /// The unit of the grid of time shifts to the neighbours in [`Self::passage`] (s), fixed at
    /// the first passage, and the grid steps last found on either side.
    passage_tau: f64,
    passage_k: [i32; 2],
    /// Workspace of the neighbouring states in [`Self::passage`] (made at the first passage).
    neighbour: Option<Neighbours>,
    /// Each constraint row's squared Jacobian norm at the last evaluation relative to the start.
    ratio: Vec<f64>,
    /// Squared norms of the constraint Jacobian's rows at the first evaluation.
    row0: Vec<f64>,
    /// The same at the last evaluation (a buffer).
    norms: Vec<f64>,
    /// The evaluated state projected onto the constraints near a singular configuration (buffers).
    staged: (Vec<f64>, Vec<f64>),
    /// Step and wall-time budgets.
    pub budget: Option<Budget>,
    /// The velocities of the last evaluation (models with Jenkins sliders), for `switched`.
    last_u: Vec<f64>,
    /// Per Jenkins slider: whether it slipped at an evaluation since the last `switched` call.
    slipped: Vec<bool>,
    /// Near-singular passages met so far.
    pub warnings: Vec<String>,
    /// Offsets of the unit quaternions in y (spherical and free joints), stepped on the group.
    quats: Vec<usize>,
    /// The onsets and releases of compliant contacts, at the ends of accepted steps.
    pub events: Vec<EventRecord>,
}

impl<'a> MultibodySystem<'a> {
    /// Wraps a model with a fresh workspace.
    pub fn new(model: &'a Model, cb: &'a dyn Callbacks) -> Self {
        MultibodySystem {
            model,
            data: Data::new(model),
            ws: dynamics::Workspace::new(model),
            cb,
            stabilization: Stabilization::Projection,
            start: None,
            near_singular: false,
            rank_lost: false,
            stop_at_singular: false,
            passage_tau: 0.0,
            passage_k: [20, 20],
            neighbour: None,
            ratio: Vec::new(),
            row0: Vec::new(),
            staged: (Vec::new(), Vec::new()),
            norms: Vec::with_capacity(model.nc),
            budget: None,
            last_u: Vec::with_capacity(model.nu),
            slipped: vec![false; model.n_sliders],
            warnings: Vec::new(),
            quats: quaternion_offsets(model),
            events: Vec::new(),
        }
    }

    /// Stops the run at a rank drop of the constraints instead of going on.
    pub fn with_on_singular(mut self, policy: OnSingular) -> Self {
        self.stop_at_singular = policy == OnSingular::Stop;
        self
    }

    /// Chooses the constraint drift control.
    pub fn with_stabilization(mut self, s: Stabilization) -> Self {
        self.stabilization = s;
        self.data.baumgarte = match s {
            Stabilization::Baumgarte { alpha, beta } => Some((alpha, beta)),
            _ => None,
        };
        self
    }
}

/// A pivot of the constraint factorization that fell below this fraction of its value at the
/// start marks a near-singular configuration (its row vanishes or turns dependent, and its
/// multiplier may grow without bound): a warning, since the motion passes it.
const NEAR_SINGULAR: f64 = 1e-6;

/// Below this fraction of its start value (squared norms) a constraint row is near a singular
/// configuration (its Jacobian row below about 3 % of its start size near a change point such as
/// a parallelogram four-bar's flat position): the projections leave it out, and the dynamics take its multiplier
/// from states on the constraint manifold on either side ([`MultibodySystem::passage`]) instead
/// of from the ill-conditioned quotient at the (slightly off-manifold) state being evaluated,
/// which would turn the state's distance from the manifold, amplified by the inverse cube of the
/// distance to the singular point, into a motion along the other branch.
const SINGULAR_WINDOW: f64 = 1e-3;

/// How far outside the window the nodes of [`MultibodySystem::passage`] lie (factor on the
/// squared row norms).
const NODE_MARGIN: f64 = 16.0;

/// Interpolation nodes on each side of a singular configuration in [`MultibodySystem::passage`].
const PASSAGE_NODES: usize = 5;

/// Below this fraction of its start value (squared norms) a row is near enough to a singular
/// configuration for the evaluated states to be projected onto the constraints first (see
/// [`OdeSystem::rhs`] of [`MultibodySystem`]).
const SINGULAR_CARE: f64 = 1e-1;

impl MultibodySystem<'_> {
    /// Notes (or, with [`OnSingular::Stop`], stops at) a rank drop of the constraint equations
    /// since the start (a dead point or a change point of the mechanism) and passages near such
    /// a configuration; marks the rows the projections leave out there.
    fn check_singular(&mut self, t: f64) -> Result<()> {
        let dep = &self.data.dependent;
        let (pivots, rows) = self.ws.saddle.pivots();
        let Some((d0, p0)) = &self.start else {
            self.start = Some((dep.clone(), pivots.to_vec()));
            return Ok(());
        };
        let name_of = |row: usize| {
            let c = self.model.constraints.iter().rev().find(|c| c.row <= row);
            (c.map_or("?", |c| c.name.as_str()), c.map_or(0, |c| row - c.row))
        };
        // which rows of a redundant set count as the dependent ones may change: only a rank drop counts
        let (r0, r1) = (d0.iter().filter(|d| !**d).count(), dep.iter().filter(|d| !**d).count());
        let lost = r1 < r0;
        if lost {
            let row = (0..dep.len()).find(|&r| dep[r] && !d0[r]).unwrap_or(0);
            let (name, k) = name_of(row);
            if self.stop_at_singular {
                return Err(Error::Solver(format!(
                    "singular configuration at t = {t:.6} s: constraint '{name}' (row {k}) became dependent on the others (rank {r0} → {r1})"
                )));
            }
            if !self.rank_lost {
                self.warnings.push(format!(
                    "singular configuration at t = {t:.6} s: constraint '{name}' (row {k}) became dependent on the others (rank {r0} → {r1}); continued with minimum-norm multipliers"
                ));
            }
        }
        self.rank_lost = lost;
        let mut weakest = (f64::INFINITY, 0);
        for j in 0..pivots.len() {
            if p0[j] > 0.0 && pivots[j] / p0[j] < weakest.0 {
                weakest = (pivots[j] / p0[j], rows[j]);
            }
        }
        // a row whose Jacobian shrank to a fraction of its start size (squared norms): the row of
        // a loop that vanishes at a change point
        // (into a buffer sized once: this runs at every evaluation of a constrained model)
        let mut norms = std::mem::take(&mut self.norms);
        row_norms(&self.data, &mut norms);
        if self.row0.is_empty() {
            self.row0 = norms.clone();
        }
        let skip = &mut self.data.skip_rows;
        skip.fill(false);
        self.ratio.resize(dep.len(), 1.0);
        for r in 0..dep.len() {
            self.ratio[r] = if self.row0[r] > 0.0 { norms[r] / self.row0[r] } else { 1.0 };
            if self.ratio[r] < SINGULAR_WINDOW {
                skip[r] = true;
            }
        }
        for r in 0..dep.len() {
            if dep[r] && !d0[r] {
                skip[r] = true;
                self.ratio[r] = 0.0;
            }
        }
        let near = weakest.0 < NEAR_SINGULAR;
        if near && !self.near_singular && !lost {
            let (name, k) = name_of(weakest.1);
            self.warnings.push(format!(
                "near-singular configuration at t = {t:.6} s: constraint '{name}' (row {k}) nearly vanishes or depends on the others (its pivot fell to {:.1e} of its start value); its multipliers may be large",
                weakest.0
            ));
        }
        self.near_singular = near || lost;
        self.norms = norms;
        Ok(())
    }
}

impl MultibodySystem<'_> {
    /// The accelerations near a singular configuration. There the multiplier of a row whose
    /// Jacobian row nearly vanished is the quotient of two vanishing numbers (λ = r / S with r,
    /// S of order s² at a distance s from the singular point), and the state's distance from the
    /// constraint manifold, divided by S, pushes the motion onto the other branch (a
    /// parallelogram four-bar flipping to its crossed form). The accelerations along the motion
    /// are smooth through the point, so they are interpolated from neighbouring states
    /// `q ⊕ σ u` (projected onto the constraints) just outside the window of every such row:
    /// three on each side, the nearest ones where the row leaves the window, and the Lagrange
    /// polynomial through the six evaluated at σ = 0 (error of the order of the sixth power of
    /// the window's width along the motion, whatever the state's place inside it). The rows'
    /// multipliers are interpolated the same way (of a redundant set near the point only their
    /// forces are determined). Falls back to the direct solve when no neighbour within reach is
    /// well conditioned on one side (the motion stops at the singular point: a dead point).
    fn passage(&mut self, t: f64, q: &[f64], u: &[f64]) -> Result<crate::forces::Powers> {
        let model = self.model;
        let (nu, nc) = (model.nu, model.nc);
        let speed = u.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let p = dynamics::forward_dynamics(model, &mut self.data, &mut self.ws, t, q, u, None, self.cb)?;
        if speed == 0.0 {
            return Ok(p);
        }
        // the workspace, made at the first passage and reused (nothing allocated per evaluation)
        let mut w = self.neighbour.take().unwrap_or_else(|| Neighbours::new(model));
        w.rows.clear();
        w.rows.extend((0..nc).filter(|&r| self.data.skip_rows[r]));
        // the nearest shift on each side whose state lies outside the window, on the grid
        // σ_k = σ₀ 2^k fixed at the first passage (the smallest such k, searched from the last
        // one found: the result depends on the state only)
        if self.passage_tau == 0.0 {
            self.passage_tau = 1e-9 / speed;
        }
        let base = self.passage_tau;
        let mut edge = [0.0f64; 2];
        let mut n = 0; // nodes filled
        for (side, sign) in [(0, 1.0), (1, -1.0)] {
            let mut k = self.passage_k[side];
            let mut best = None;
            let mut rising = false;
            for _ in 0..64 {
                let sigma = base * 2f64.powi(k);
                if sigma * speed > 1.0 {
                    break;
                }
                // node slot n holds the trial: kept when it is the last one outside
                if self.neighbour_state(&mut w, n, t, q, u, sign * sigma)? {
                    best = Some(k);
                    if rising || k == 0 {
                        break; // the one below was inside
                    }
                    w.save(n); // a smaller one may do as well
                    k -= 1;
                } else if best.is_some() {
                    w.restore(n);
                    break;
                } else {
                    rising = true;
                    k += 1;
                }
            }
            let Some(k) = best else {
                self.neighbour = Some(w);
                return Ok(p);
            };
            self.passage_k[side] = k;
            edge[side] = base * 2f64.powi(k);
            w.sigma[n] = sign * edge[side];
            n += 1;
        }
        // more on each side, spaced by a quarter of the gap across the window
        let d = 0.25 * (edge[0] + edge[1]);
        for (side, sign) in [(0, 1.0), (1, -1.0)] {
            for k in 1..PASSAGE_NODES {
                let sigma = sign * (edge[side] + k as f64 * d);
                if !self.neighbour_state(&mut w, n, t, q, u, sigma)? {
                    self.neighbour = Some(w);
                    return Ok(p);
                }
                w.sigma[n] = sigma;
                n += 1;
            }
        }
        // the Lagrange polynomial through the nodes at σ = 0
        self.data.udot.fill(0.0);
        for &r in &w.rows {
            self.data.lambda[r] = 0.0;
        }
        for k in 0..n {
            let sk = w.sigma[k];
            let weight: f64 = (0..n).filter(|&j| j != k).map(|j| (0.0 - w.sigma[j]) / (sk - w.sigma[j])).product();
            for i in 0..nu {
                self.data.udot[i] += weight * w.udot[k * nu + i];
            }
            for &r in &w.rows {
                self.data.lambda[r] += weight * w.lambda[k * nc + r];
            }
        }
        self.neighbour = Some(w);
        // body accelerations of these accelerations (without gravity), for records and reactions
        self.data.a[0] = crate::spatial::Motion::ZERO;
        let ud = std::mem::take(&mut self.data.udot);
        crate::kinematics::accelerations(model, &mut self.data, &ud);
        self.data.udot = ud;
        Ok(p)
    }

    /// Evaluates the state `q ⊕ σ u` at time `t + σ` (along the motion, also for driven
    /// constraints) projected onto the constraints into node slot `slot` of `w` (accelerations
    /// and multipliers); false when it lies inside the window of one of `w.rows` (or does not
    /// project).
    #[allow(clippy::too_many_arguments)]
    fn neighbour_state(
        &mut self,
        w: &mut Neighbours,
        slot: usize,
        t: f64,
        q: &[f64],
        u: &[f64],
        sigma: f64,
    ) -> Result<bool> {
        let model = self.model;
        let (nu, nc) = (model.nu, model.nc);
        let ts = t + sigma;
        model.integrate(q, u, sigma, &mut w.qs);
        model.normalize(&mut w.qs);
        w.us.copy_from_slice(u);
        let data = &mut w.data;
        data.skip_rows.fill(false);
        // twice: the second call finds the positions converged and projects the velocities with
        // G factored at the projected configuration itself (the first may reuse a factor from
        // one Newton step before, whose error near the singular point is not small)
        for _ in 0..2 {
            if dynamics::constrained::project(model, data, &mut self.ws, ts, &mut w.qs, &mut w.us, self.cb).is_err() {
                return Ok(false);
            }
        }
        dynamics::forward_dynamics(model, data, &mut self.ws, ts, &w.qs, &w.us, None, self.cb)?;
        row_norms(data, &mut self.norms);
        if w.rows.iter().any(|&r| self.norms[r] < NODE_MARGIN * SINGULAR_WINDOW * self.row0[r]) {
            return Ok(false);
        }
        w.udot[slot * nu..(slot + 1) * nu].copy_from_slice(&data.udot);
        w.lambda[slot * nc..(slot + 1) * nc].copy_from_slice(&data.lambda);
        Ok(true)
    }
}

/// The workspace of [`MultibodySystem::passage`]: a model workspace for the neighbouring states,
/// their coordinates, and the accelerations and multipliers of the interpolation nodes.
struct Neighbours {
    data: Data,
    rows: Vec<usize>,
    qs: Vec<f64>,
    us: Vec<f64>,
    sigma: Vec<f64>,
    /// Per node, nu accelerations (node-major).
    udot: Vec<f64>,
    /// Per node, nc multipliers (node-major).
    lambda: Vec<f64>,
    /// One node kept aside while the search tries a smaller shift.
    kept: (Vec<f64>, Vec<f64>),
}

impl Neighbours {
    fn new(model: &Model) -> Self {
        let (nu, nc, nodes) = (model.nu, model.nc, 2 * PASSAGE_NODES);
        Neighbours {
            data: Data::new(model),
            rows: Vec::with_capacity(nc),
            qs: vec![0.0; model.nq],
            us: vec![0.0; nu],
            sigma: vec![0.0; nodes],
            udot: vec![0.0; nodes * nu],
            lambda: vec![0.0; nodes * nc],
            kept: (vec![0.0; nu], vec![0.0; nc]),
        }
    }
    /// Keeps node `slot` aside.
    fn save(&mut self, slot: usize) {
        let (nu, nc) = (self.kept.0.len(), self.kept.1.len());
        self.kept.0.copy_from_slice(&self.udot[slot * nu..(slot + 1) * nu]);
        self.kept.1.copy_from_slice(&self.lambda[slot * nc..(slot + 1) * nc]);
    }
    /// Puts the node kept aside back into `slot`.
    fn restore(&mut self, slot: usize) {
        let (nu, nc) = (self.kept.0.len(), self.kept.1.len());
        self.udot[slot * nu..(slot + 1) * nu].copy_from_slice(&self.kept.0);
        self.lambda[slot * nc..(slot + 1) * nc].copy_from_slice(&self.kept.1);
    }
}

/// Squared norms of the rows of the constraint Jacobian in `data.g`.
fn row_norms(data: &Data, out: &mut Vec<f64>) {
    // over each row's planned pattern only (the rest of G is zero)
    out.clear();
    out.extend((0..data.g.nrows()).map(|r| {
        (data.g_row_ptr[r]..data.g_row_ptr[r + 1]).map(|p| data.g[(r, data.g_row_idx[p])].powi(2)).sum::<f64>()
    }));
}

impl OdeSystem for MultibodySystem<'_> {
    fn dim(&self) -> usize {
        self.model.nq + self.model.nu + 2 + compliant_states(self.model)
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        let (nq, nu) = (self.model.nq, self.model.nu);
        let (q, rest) = y.split_at(nq);
        let u = &rest[..nu];
        let aux = nq + nu + 2;
        if self.model.n_compliant_points > 0 {
            self.ws.forces.compliant.states.copy_from_slice(&y[aux..]);
        }
        let mut p = dynamics::forward_dynamics(self.model, &mut self.data, &mut self.ws, t, q, u, None, self.cb)?;
        let (mut qs, mut us) = std::mem::take(&mut self.staged);
        let mut staged = false;
        if self.model.nc > 0 {
            self.check_singular(t)?;
            // near a singular configuration the accelerations of a state off the constraint
            // manifold (a Runge–Kutta stage) carry its distance from it, amplified by inverse
            // powers of the distance to the singular point, into the other branch's direction:
            // such a state is evaluated at its projection (a smooth map that changes nothing on
            // the manifold, so the scheme keeps its order there); decided on the state's own
            // row norms, so that the motion does not depend on the evaluations before it
            if self.ratio.iter().any(|&r| r < SINGULAR_CARE) {
                qs.clear();
                qs.extend_from_slice(q);
                us.clear();
                us.extend_from_slice(u);
                if dynamics::constrained::project(
                    self.model,
                    &mut self.data,
                    &mut self.ws,
                    t,
                    &mut qs,
                    &mut us,
                    self.cb,
                )
                .is_ok()
                {
                    staged = true;
                    p = dynamics::forward_dynamics(
                        self.model,
                        &mut self.data,
                        &mut self.ws,
                        t,
                        &qs,
                        &us,
                        None,
                        self.cb,
                    )?;
                    self.check_singular(t)?;
                }
            }
        }
        let (q, u) = if staged { (&qs[..], &us[..]) } else { (q, u) };
        if self.data.skip_rows.iter().any(|s| *s) {
            p = self.passage(t, q, u)?;
        }
        if self.model.n_sliders > 0 {
            // the velocities of the last evaluation and which sliders slipped, for `switched`
            self.last_u.clear();
            self.last_u.extend_from_slice(u);
            for i in 0..self.slipped.len() {
                self.slipped[i] |= self.data.slider_trial[i] != self.data.slider[i];
            }
        }
        self.model.qdot(q, u, &mut dy[..nq]);
        dy[nq..nq + nu].copy_from_slice(&self.data.udot);
        dy[nq + nu] = p.dissipated;
        dy[nq + nu + 1] = p.external;
        if self.model.n_compliant_points > 0 {
            dy[aux..].copy_from_slice(&self.ws.forces.compliant.rates);
        }
        self.staged = (qs, us);
        Ok(())
    }
    fn switches(&self) -> usize {
        crate::forces::compliant::switches(self.model)
    }
    fn switching(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<()> {
        let (nq, nu) = (self.model.nq, self.model.nu);
        crate::kinematics::forward_pass(self.model, &mut self.data, t, &y[..nq], &y[nq..nq + nu]);
        crate::forces::compliant::switching(self.model, &self.data, &mut self.ws.forces.compliant, t, self.cb, out)
    }
    fn switched(&mut self) -> bool {
        // a slider that slipped since its commit while its joint now moves back (the deflection
        // rate against the slip) reversed inside the step: the return mapping from the commit
        // misses how far it went before it stuck
        let mut reversed = false;
        for f in &self.model.forces {
            if let ForceElement::Jenkins(j) = f {
                let v = self.last_u.get(j.iu).copied().unwrap_or(0.0);
                for i in j.slot..j.slot + j.len() {
                    let d = self.data.slider_trial[i] - self.data.slider[i];
                    // still slipping but moving back, or slipped at an earlier stage and stuck now
                    reversed |= d * v < 0.0 || (self.slipped[i] && d == 0.0);
                }
            }
        }
        self.slipped.fill(false);
        reversed
    }
    fn accepted(&mut self, t: f64, y: &mut [f64]) -> Result<()> {
        if let Some(b) = self.budget.as_mut() {
            b.step(t)?;
        }
        let (nq, nu) = (self.model.nq, self.model.nu);
        if self.model.n_sliders > 0 {
            let chains = &mut self.ws.forces.jenkins;
            y[nq + nu] += crate::forces::jenkins::commit(self.model, &mut self.data, chains, &y[..nq], t)?;
        }
        if self.model.n_compliant_points > 0 {
            let (head, aux) = y.split_at_mut(nq + nu + 2);
            crate::kinematics::forward_pass(self.model, &mut self.data, t, &head[..nq], &head[nq..nq + nu]);
            let w = &mut self.ws.forces.compliant;
            crate::forces::compliant::commit(self.model, &self.data, w, t, aux)?;
            compliant_events(self.model, w, t, &mut self.events);
        }
        Ok(())
    }
    fn quaternions(&self) -> &[usize] {
        &self.quats
    }
    fn project(&mut self, t: f64, y: &mut [f64]) -> Result<()> {
        // (no renormalization: the schemes step the quaternions on the rotation group)
        let (nq, nu) = (self.model.nq, self.model.nu);
        if self.model.nc > 0 && self.stabilization == Stabilization::Projection {
            let (q, rest) = y.split_at_mut(nq);
            crate::dynamics::constrained::project(
                self.model,
                &mut self.data,
                &mut self.ws,
                t,
                q,
                &mut rest[..nu],
                self.cb,
            )?;
        }
        Ok(())
    }
}

/// Offsets in q (and so in y = [q, u, ...]) of the quaternions of the spherical and free joints.
pub fn quaternion_offsets(model: &Model) -> Vec<usize> {
    let mut v = Vec::new();
    for j in &model.joints {
        match j.kind {
            crate::model::JointKind::Spherical => v.push(j.iq),
            crate::model::JointKind::Free => v.push(j.iq + 3),
            _ => {}
        }
    }
    v.sort_unstable();
    v
}

/// Extra states of the compliant contacts (dissipated energy, bristles) after the energy entries.
fn compliant_states(model: &Model) -> usize {
    crate::model::compliant::STATES_PER_POINT * model.n_compliant_points
}

/// Event records of the compliant contact points that closed (`close`) or opened (`open`) at
/// the last commit.
fn compliant_events(model: &Model, w: &crate::forces::compliant::Work, t: f64, out: &mut Vec<EventRecord>) {
    for &(slot, closed) in &w.changed {
        if let Some((name, point)) = crate::forces::compliant::point_of(model, slot) {
            out.push(EventRecord {
                t,
                contact: name.to_string(),
                point,
                kind: if closed { "close" } else { "open" },
                impulse: [0.0; 3],
                energy: 0.0,
                u_before: Vec::new(),
                u_after: Vec::new(),
                painleve: None,
                steps: 1,
            });
        }
    }
}

/// Quaternion [w, x, y, z] of a rotation matrix (Shepperd's method, robust for all rotations).
pub fn matrix_to_quaternion(a: &crate::math::Mat3) -> [f64; 4] {
    let tr = a[(0, 0)] + a[(1, 1)] + a[(2, 2)];
    let q = if tr > a[(0, 0)].max(a[(1, 1)]).max(a[(2, 2)]) {
        let s = 2.0 * (1.0 + tr).sqrt();
        [0.25 * s, (a[(2, 1)] - a[(1, 2)]) / s, (a[(0, 2)] - a[(2, 0)]) / s, (a[(1, 0)] - a[(0, 1)]) / s]
    } else if a[(0, 0)] >= a[(1, 1)] && a[(0, 0)] >= a[(2, 2)] {
        let s = 2.0 * (1.0 + a[(0, 0)] - a[(1, 1)] - a[(2, 2)]).sqrt();
        [(a[(2, 1)] - a[(1, 2)]) / s, 0.25 * s, (a[(0, 1)] + a[(1, 0)]) / s, (a[(0, 2)] + a[(2, 0)]) / s]
    } else if a[(1, 1)] >= a[(2, 2)] {
        let s = 2.0 * (1.0 + a[(1, 1)] - a[(0, 0)] - a[(2, 2)]).sqrt();
        [(a[(0, 2)] - a[(2, 0)]) / s, (a[(0, 1)] + a[(1, 0)]) / s, 0.25 * s, (a[(1, 2)] + a[(2, 1)]) / s]
    } else {
        let s = 2.0 * (1.0 + a[(2, 2)] - a[(0, 0)] - a[(1, 1)]).sqrt();
        [(a[(1, 0)] - a[(0, 1)]) / s, (a[(0, 2)] + a[(2, 0)]) / s, (a[(1, 2)] + a[(2, 1)]) / s, 0.25 * s]
    };
    // keep w ≥ 0 so recorded orientations are continuous for rotations below π
    if q[0] < 0.0 {
        [-q[0], -q[1], -q[2], -q[3]]
    } else {
        q
    }
}

/// A `ModelError` naming the joint coordinates that move no inertia at the start (bodies of zero
/// inertia are allowed: a point mass turning about its own centre is not): the equations of
/// motion have no solution for their accelerations.
pub fn check_inertia(model: &Model, t: f64, q: &[f64]) -> Result<()> {
    let nu = model.nu;
    if nu == 0 || model.bodies.iter().skip(1).all(|b| b.principal_axes && b.inertia.diagonal().min() > 0.0) {
        return Ok(());
    }
    let mut data = Data::new(model);
    crate::kinematics::positions(model, &mut data, q);
    crate::dynamics::crba::mass_matrix(model, &mut data, t, q);
    let m = &data.mass_matrix;
    let big = (0..nu).map(|i| m[(i, i)].abs()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let name = |i: usize| {
        let j = model.joints.iter().find(|j| j.iu <= i && i < j.iu + j.nu()).expect("every velocity has a joint");
        if j.nu() == 1 {
            format!("'{}'", j.name)
        } else {
            format!("'{}' (velocity {})", j.name, i - j.iu)
        }
    };
    let light: Vec<String> = (0..nu).filter(|&i| !(m[(i, i)] > 1e-12 * big)).map(name).collect();
    let singular = !light.is_empty() || m.clone().cholesky().is_none();
    crate::ensure!(
        !singular,
        Model,
        "the joint coordinate(s) {} move no inertia at t = {t} s (a body of zero inertia turning about its own centre, \
         or massless bodies alone on a joint): their accelerations are undetermined; give those bodies inertia, \
         offset the centre of mass from the joint, or remove the coordinate",
        if light.is_empty() { "of a combination".to_string() } else { light.join(", ") }
    );
    Ok(())
}

/// Checks settings and returns the output times and the initial state.
pub fn prepare(model: &Model, s: &Settings) -> Result<(Vec<f64>, Vec<f64>)> {
    crate::ensure!(s.t0.is_finite(), Settings, "t0: must be finite, got {}", s.t0);
    crate::ensure!(
        s.t_end.is_finite() && s.t_end > s.t0,
        Settings,
        "t_end: must be finite and > t0 = {}, got {}",
        s.t0,
        s.t_end
    );
    crate::ensure!(
        s.output_dt.is_finite() && s.output_dt > 0.0,
        Settings,
        "output_dt: must be > 0, got {}",
        s.output_dt
    );
    let span = s.t_end - s.t0;
    if matches!(s.integrator, IntegratorKind::Radau5 { .. }) {
        crate::integrator::radau5::check(&s.integrator)?;
    }
    if let Some(dt) = s.integrator.fixed_step() {
        crate::ensure!(
            !(dt > span * (1.0 + 1e-12)),
            Settings,
            "integrator.dt: the step ({dt} s) is longer than the run ({span} s from t0 to t_end)"
        );
    }
    crate::ensure!(
        s.output_dt <= span * (1.0 + 1e-12),
        Settings,
        "output_dt: {} s is longer than the run ({span} s from t0 to t_end): the results would hold the start only",
        s.output_dt
    );
    if let IntegratorKind::Dopri5 { rtol, atol, .. } = s.integrator {
        // below ~100 ε the error estimate is round-off: the step size collapses instead of converging
        crate::ensure!(
            rtol.is_finite() && (1e-14..1.0).contains(&rtol),
            Settings,
            "integrator.rtol: must be in [1e-14, 1) (below 1e-14 double precision cannot meet it; 1 and above \
             control nothing), got {rtol:e}"
        );
        crate::ensure!(atol.is_finite() && atol >= 0.0, Settings, "integrator.atol: must be >= 0, got {atol}");
    }
    // the samples' memory, estimated before anything is allocated (in f64: a huge span must not
    // wrap the count to zero)
    let (samples, width) = sample_size(model, s);
    let bytes = samples * width * 8.0;
    let budget = crate::resources::memory_budget();
    crate::ensure!(
        bytes.is_finite() && bytes < budget,
        Settings,
        "output_dt: {:e} s over {:e} s gives {samples:.3e} samples of {width} values, about {:.3e} bytes of results, more than \
         the {:.3e} bytes this run may use (half the memory available); choose a larger output_dt, a shorter run or \
         sensors= to record less",
        s.output_dt,
        span,
        bytes,
        budget
    );
    if let Some(dt) = s.integrator.fixed_step() {
        crate::ensure!(dt.is_finite() && dt > 0.0, Settings, "integrator.dt: must be > 0, got {dt}");
        // a step count that could never be run (or counted) is refused, not started
        let steps = span / dt;
        crate::ensure!(
            steps < 1e12,
            Settings,
            "integrator.dt: {dt:e} s over {span:e} s is {steps:.3e} steps, more than 1e12 (years of computing); choose a \
             larger step or a shorter run"
        );
        let ratio = s.output_dt / dt;
        crate::ensure!(
            (ratio - ratio.round()).abs() < 1e-9 * ratio.max(1.0) && ratio.round() >= 1.0,
            Settings,
            "output_dt: must be a whole multiple of the fixed step dt = {dt} s, got {}",
            s.output_dt
        );
    }
    let n_out = samples as usize;
    let t_out: Vec<f64> = (0..n_out).map(|k| (s.t0 + k as f64 * s.output_dt).min(s.t_end)).collect();

    let mut y = vec![0.0; model.nq + model.nu + 2];
    match &s.q0 {
        Some(q) => {
            crate::ensure!(
                q.len() == model.nq,
                Settings,
                "q0: the model has {} coordinates, got {}",
                model.nq,
                q.len()
            );
            model.check_q(q, "q0")?;
            y[..model.nq].copy_from_slice(q);
            model.normalize(&mut y[..model.nq]);
        }
        None => y[..model.nq].copy_from_slice(&model.q0()),
    }
    match &s.u0 {
        Some(u) => {
            crate::ensure!(u.len() == model.nu, Settings, "u0: the model has {} velocities, got {}", model.nu, u.len());
            for (i, v) in u.iter().enumerate() {
                crate::ensure!(v.is_finite(), Settings, "u0[{i}]: must be finite, got {v}");
            }
            y[model.nq..model.nq + model.nu].copy_from_slice(u);
        }
        None => y[model.nq..model.nq + model.nu].copy_from_slice(&model.u0()),
    }
    Ok((t_out, y))
}

/// The number of samples a run records and the values per sample (an estimate of its results'
/// size, made before anything is allocated; in f64 so that a huge span cannot wrap the count).
pub fn sample_size(model: &Model, s: &Settings) -> (f64, f64) {
    let samples = (((s.t_end - s.t0) / s.output_dt) * (1.0 + 1e-12) + 1e-9).floor() + 1.0;
    let bodies = s.record.bodies.as_ref().map_or(model.nbodies() - 1, |b| b.len()) as f64;
    let width = 1.0
        + 2.0 * model.nq as f64
        + 3.0 * model.nu as f64
        + 23.0 * bodies
        + 3.0 * model.nc as f64
        + 2.0 * model.n_force_outputs as f64
        + 17.0 * model.n_contact_points as f64
        + 10.0;
    (samples, width)
}

/// Runs a simulation and records all signals.
pub fn simulate(
    model: &Model,
    settings: &Settings,
    cb: &dyn Callbacks,
    progress: Option<&Progress>,
) -> Result<Recording> {
    let (t_out, y0) = prepare(model, settings)?;
    check_inertia(model, settings.t0, &y0[..model.nq])?;
    let n_out = t_out.len();
    let body_index = recorded_bodies(model, &settings.record)?;
    let nb = body_index.len();
    let sel = settings.record.clone();
    let (na, nc, nf) = (
        if sel.accelerations { 1 } else { 0 },
        if sel.constraints { model.nc } else { 0 },
        if sel.forces { model.n_force_outputs } else { 0 },
    );
    let (nq, nu) = (model.nq, model.nu);
    let mut rec = Recording {
        n_out,
        n_bodies: nb,
        body_index,
        selection: sel,
        t: Vec::with_capacity(n_out),
        q: Vec::with_capacity(n_out * nq),
        u: Vec::with_capacity(n_out * nu),
        udot: Vec::with_capacity(n_out * nu * na),
        body_position: Vec::with_capacity(n_out * nb * 3),
        body_orientation: Vec::with_capacity(n_out * nb * 4),
        body_velocity: Vec::with_capacity(n_out * nb * 3),
        body_angular_velocity: Vec::with_capacity(n_out * nb * 3),
        body_acceleration: Vec::with_capacity(n_out * nb * 3 * na),
        body_angular_acceleration: Vec::with_capacity(n_out * nb * 3 * na),
        body_mass: Vec::with_capacity(n_out * nb),
        kinetic: Vec::with_capacity(n_out),
        body_kinetic: Vec::with_capacity(n_out * nb),
        potential: Vec::with_capacity(n_out),
        dissipated: Vec::with_capacity(n_out),
        external_work: Vec::with_capacity(n_out),
        momentum_linear: Vec::with_capacity(n_out * 3),
        momentum_angular: Vec::with_capacity(n_out * 3),
        constraint_lambda: Vec::with_capacity(n_out * nc),
        constraint_violation: Vec::with_capacity(n_out * nc),
        constraint_velocity_violation: Vec::with_capacity(n_out * nc),
        force_value: Vec::with_capacity(n_out * nf),
        force_deflection: Vec::with_capacity(n_out * nf),
        warnings: Vec::new(),
        stats: Stats::default(),
        ..Default::default()
    };
    match settings.stabilization {
        Stabilization::Baumgarte { alpha, beta } => crate::ensure!(
            alpha.is_finite() && beta.is_finite() && alpha >= 0.0 && beta >= 0.0,
            Settings,
            "stabilization: Baumgarte alpha and beta must be >= 0, got {alpha}, {beta}"
        ),
        _ => {}
    }
    let contacts = !model.contacts.is_empty();
    if let IntegratorKind::MoreauJean { dt, solver, continue_on_painleve, project, parallel } = settings.integrator {
        // Poisson's law (2.203) relates the impulses of an impact's compression and expansion
        // phases; a time step's impulse mixes the impact with the step's smooth forces, so the
        // scheme cannot apply it: refused rather than replaced by Newton's law unseen
        let poisson =
            |law: &crate::model::contact::ImpactLaw| matches!(law, crate::model::contact::ImpactLaw::Poisson { .. });
        if let Some(c) = model.contacts.iter().find(|c| poisson(&c.impact)) {
            return Err(Error::Settings(format!(
                "contact '{}': Poisson's impact law needs the event-driven scheme (integrator EventDriven); MoreauJean applies restitution at velocity level, as Newton's law: give this contact laws.Newton(eps) (impact = {{ type = \"newton\", eps = ... }} in a model file) to use it",
                c.name
            )));
        }
        if let Some(g) = model.contact_groups.iter().find(|g| poisson(&g.impact)) {
            return Err(Error::Settings(format!(
                "contact group '{}': Poisson's impact law needs the event-driven scheme, which does not take contact groups; give the group laws.Newton(eps)",
                g.name
            )));
        }
        return time_stepping(
            model,
            settings,
            cb,
            progress,
            &t_out,
            y0,
            (dt, solver, continue_on_painleve, project, parallel),
            rec,
        );
    }
    crate::ensure!(
        model.contact_groups.is_empty() || matches!(settings.integrator, IntegratorKind::MoreauJean { .. }),
        Settings,
        "integrator: the model has contact groups ('{}'); use MoreauJean (time-stepping)",
        model.contact_groups.first().map_or("", |g| g.name.as_str())
    );
    if let IntegratorKind::EventDriven(opts) = settings.integrator {
        // its contacts close and open at located events, rigidly: a compliant layer's overlap
        // is the time-stepping scheme's regularized law
        if let Some(c) = model.contacts.iter().find(|c| c.compliance > 0.0) {
            return Err(Error::Settings(format!(
                "integrator: contact '{}' has a compliant Signorini law (normal.compliance = {} m/N), which the \
                 event-driven scheme does not take; use MoreauJean (time-stepping), or a compliant force law \
                 (laws.KelvinVoigt, laws.Hertz) in any scheme",
                c.name, c.compliance
            )));
        }
        return event_driven(model, settings, cb, progress, &t_out, y0, opts, rec);
    }
    crate::ensure!(
        !contacts,
        Settings,
        "integrator: the model has unilateral contacts ('{}'); use MoreauJean (time-stepping) or EventDriven",
        model.contacts[0].name
    );
    let mut sys = MultibodySystem::new(model, cb)
        .with_stabilization(settings.stabilization)
        .with_on_singular(settings.on_singular);
    // a consistent initial state: on the constraint manifolds (assembly from the given q0, u0)
    // (always by projection, whatever the drift control during the run)
    let mut y0 = y0;
    y0.resize(sys.dim(), 0.0);
    if model.n_compliant_points > 0 {
        // the points closed at the start (their onset speeds, no event)
        let (head, aux) = y0.split_at_mut(model.nq + model.nu + 2);
        crate::kinematics::forward_pass(
            model,
            &mut sys.data,
            settings.t0,
            &head[..model.nq],
            &head[model.nq..model.nq + model.nu],
        );
        crate::forces::compliant::commit(model, &sys.data, &mut sys.ws.forces.compliant, settings.t0, aux)?;
    }
    model.normalize(&mut y0[..model.nq]);
    if model.nc > 0 {
        let (q, rest) = y0.split_at_mut(model.nq);
        crate::dynamics::constrained::project(
            model,
            &mut sys.data,
            &mut sys.ws,
            settings.t0,
            q,
            &mut rest[..model.nu],
            cb,
        )?;
    }
    let mut scratch = vec![0.0; sys.dim()];
    // an explicit fixed step above its stability limit grows the energy geometrically: watched
    // for RK4 (the adaptive and implicit schemes control or damp it); variable-mass bodies carry
    // energy away with the ejected mass, so their balance is not checked
    let guard =
        matches!(settings.integrator, IntegratorKind::Rk4 { .. }) && model.bodies.iter().all(|b| b.mass_rate == 0.0);
    let mut divergence =
        Divergence { floor: 1e-6 * model.bodies.iter().skip(1).map(|b| b.mass).sum::<f64>(), ..Default::default() };
    sys.budget = Some(Budget::new(settings));
    let mut observer = |sys: &mut MultibodySystem, t: f64, y: &[f64], fresh: bool| -> Result<()> {
        if !fresh {
            sys.rhs(t, y, &mut scratch)?;
        }
        record(model, &sys.data, &sys.ws.saddle, t, y, &mut rec);
        if model.n_sliders > 0 {
            // the Jenkins sliders book their work when a step is committed; a sample inside or at
            // the end of a step (before the commit) adds the work they did since the last one
            let d = &sys.data;
            let pending: f64 =
                (0..model.n_sliders).map(|i| d.slider_force[i] * (d.slider_trial[i] - d.slider[i])).sum();
            if let Some(last) = rec.dissipated.last_mut() {
                *last += pending;
            }
        }
        if guard {
            if let Some(msg) = divergence.check(&rec, t) {
                return Err(divergence_error(model, settings, &mut sys.data, t, y, msg));
            }
        }
        if let Some(b) = &sys.budget {
            b.wall(t)?;
        }
        report_progress(progress, rec.t.len(), t)
    };
    let outcome = integrator::integrate(&settings.integrator, &mut sys, settings.t0, &y0, &t_out, &mut observer);
    match outcome {
        Ok(stats) => rec.stats = stats,
        // cancelled (Ctrl-C): the samples recorded so far are kept, each one complete
        Err(Error::Solver(msg)) if msg.starts_with(CANCELLED) => {
            rec.n_out = rec.t.len();
            rec.cancelled = Some(msg);
        }
        Err(e) => return Err(e),
    }
    rec.warnings = std::mem::take(&mut sys.warnings);
    rec.events = std::mem::take(&mut sys.events);
    Ok(rec)
}

/// The start of the message of a run cancelled from outside ([`Progress::cancel`]).
pub const CANCELLED: &str = "simulation cancelled";

/// Watches the energy balance of a fixed-step explicit run: the kinetic plus potential energy
/// minus the external work plus the dissipated energy is constant for a stable run (to the
/// integration error); above the step's stability limit it grows geometrically.
#[derive(Debug, Default)]
struct Divergence {
    /// |T| + |V| + |W| + |D| of the first sample.
    start: f64,
    /// The energy balance T + V − W + D of the first sample.
    balance0: f64,
    /// Round-off floor of the energies: a millijoule per tonne of the model's mass.
    floor: f64,
}

impl Divergence {
    /// What grew when the energy balance grew beyond half of all the energies present and to a
    /// thousand times the energies at the start (and well above round-off: a millijoule per
    /// tonne), else None.
    fn check(&mut self, rec: &Recording, t: f64) -> Option<String> {
        let k = rec.t.len() - 1;
        let (tk, v, w, d) = (rec.kinetic[k], rec.potential[k], rec.external_work[k], rec.dissipated[k]);
        let balance = tk + v - w + d;
        let size = tk.abs() + v.abs() + w.abs() + d.abs();
        if k == 0 {
            (self.start, self.balance0) = (size, balance);
            return None;
        }
        let grown = (balance - self.balance0).abs();
        if grown > 0.5 * size && size > 1e3 * self.start.max(self.floor) {
            Some(format!(
                "the run diverged at t = {t:.6} s: the energy grew from {:.4e} J to {balance:.4e} J with nothing doing that work",
                self.balance0
            ))
        } else {
            None
        }
    }
}

/// The divergence error: the step, the stiffest spring (point-to-point `k (1/m1 + 1/m2)`, or a
/// joint spring's `k / M_ii` with the mass matrix at the state) and the step that would be stable.
fn divergence_error(model: &Model, settings: &Settings, data: &mut Data, t: f64, y: &[f64], msg: String) -> Error {
    let IntegratorKind::Rk4 { dt } = settings.integrator else { return Error::Solver(msg) };
    let mut msg = msg + &format!("; the fixed step dt = {dt} s is above the scheme's stability limit");
    let inv_mass = |b: usize| if b == 0 { 0.0 } else { 1.0 / model.bodies[b].mass };
    let mut stiffest: Option<(String, f64)> = None;
    let mut consider = |name: String, w2: f64| {
        if w2.is_finite() && w2 > 0.0 && stiffest.as_ref().is_none_or(|s| w2.sqrt() > s.1) {
            stiffest = Some((name, w2.sqrt()));
        }
    };
    for f in &model.forces {
        if let ForceElement::SpringDamper { name, body1, body2, k, .. } = f {
            consider(format!("force element '{name}'"), k.abs() * (inv_mass(*body1) + inv_mass(*body2)));
        }
    }
    let q = &y[..model.nq];
    if q.iter().all(|v| v.is_finite()) && model.joints.iter().any(|j| j.spring.is_some()) {
        crate::dynamics::crba::mass_matrix(model, data, t, q);
        for j in &model.joints {
            if let Some(sp) = &j.spring {
                for (i, k) in sp.k.iter().enumerate() {
                    let m = data.mass_matrix[(j.iu + i, j.iu + i)];
                    consider(format!("the spring of joint '{}'", j.name), k.abs() / m);
                }
            }
        }
    }
    if let Some((name, omega)) = stiffest {
        msg += &format!(
            " ({name}, the stiffest spring, oscillates at about {omega:.4e} rad/s: RK4 is stable for dt < 2.8 / omega = {:.3e} s)",
            2.8 / omega
        );
    }
    Error::Solver(msg + "; reduce dt, or use DOPRI5 (adaptive) or Radau5 (implicit, for stiff models)")
}

/// The Moreau–Jean run: steps of `dt`, a sample after every `output_dt / dt` steps.
#[allow(clippy::too_many_arguments)]
fn time_stepping(
    model: &Model,
    settings: &Settings,
    cb: &dyn Callbacks,
    progress: Option<&Progress>,
    t_out: &[f64],
    y0: Vec<f64>,
    (dt, solver, continue_on_painleve, project, parallel): (f64, crate::solver::Method, bool, bool, bool),
    mut rec: Recording,
) -> Result<Recording> {
    let budget = Budget::new(settings);
    use crate::integrator::moreau_jean::MoreauJean;
    let (nq, nu, np) = (model.nq, model.nu, model.n_contact_points);
    // (prepare() checked that output_dt is a whole multiple of dt)
    let every = (settings.output_dt / dt).round() as u64;
    let mut stepper = MoreauJean::new(model, dt, solver)?;
    stepper.project = project;
    stepper.parallel = parallel;
    stepper.warm_search = settings.warm_search;
    let mut group_stats = vec![crate::integrator::moreau_jean::GroupStats::default(); model.contact_groups.len()];
    let (mut data, mut ws) = (Data::new(model), dynamics::Workspace::new(model));
    let mut y = y0;
    model.normalize(&mut y[..nq]);
    if model.nc > 0 {
        let (q, rest) = y.split_at_mut(nq);
        crate::dynamics::constrained::project(model, &mut data, &mut ws, settings.t0, q, &mut rest[..nu], cb)?;
    }
    let contact_signals = rec.selection.contacts;
    rec.reserve_contacts(t_out.len(), if contact_signals { np } else { 0 });
    let mut udot = vec![0.0; nu];
    let mut u_start = vec![0.0; nu];
    // impulses summed over each sample interval (so that impacts between samples are not lost)
    let mut acc_n = vec![0.0; np];
    let mut acc_t = vec![[0.0; 2]; np];
    let mut step = 0u64;
    let mut stats = crate::integrator::Stats::default();
    let mut log = crate::integrator::events::EventLog::default();
    let mut states = vec![OPEN_STATE; np];
    // per point: the index of its last event and the step it was last extended at
    let mut last_event: Vec<Option<(usize, u64)>> = vec![None; np];
    let mut last_painleve: Vec<Option<(usize, u64)>> = vec![None; np];
    let mut compliant_log = Vec::new();
    if model.n_compliant_points > 0 {
        let (q, rest) = y.split_at(nq);
        crate::kinematics::forward_pass(model, &mut data, settings.t0, q, &rest[..nu]);
        let w = &mut ws.forces.compliant;
        let mut st = std::mem::take(&mut w.states);
        crate::forces::compliant::commit(model, &data, w, settings.t0, &mut st)?;
        w.states = st;
    }
    // the solver's worst residual, most iterations and convergence since the last sample
    let mut solver_acc = (0.0f64, 0usize, true);
    for (k, &t_rec) in t_out.iter().enumerate() {
        if k > 0 {
            for _ in 0..every {
                let t = settings.t0 + step as f64 * dt;
                let (q, rest) = y.split_at_mut(nq);
                let (u, energy) = rest.split_at_mut(nu);
                u_start.copy_from_slice(u);
                let (work, diss) = stepper.step(model, &mut data, &mut ws, t, q, u, cb)?;
                if let Some(r) = &stepper.report {
                    solver_acc.0 = solver_acc.0.max(r.residual);
                    solver_acc.1 = solver_acc.1.max(r.iterations);
                    solver_acc.2 &= r.converged;
                }
                for (pt, r) in stepper.results.iter().enumerate() {
                    acc_n[pt] += r.impulse_n;
                    acc_t[pt][0] += r.impulse_t[0];
                    acc_t[pt][1] += r.impulse_t[1];
                }
                energy[0] += diss;
                energy[1] += work;
                if model.n_sliders > 0 {
                    energy[0] += crate::forces::jenkins::commit(model, &mut data, &mut ws.forces.jenkins, q, t + dt)?;
                }
                if model.n_compliant_points > 0 {
                    // the compliant contacts' extra states with their rates at the step's midpoint
                    let w = &mut ws.forces.compliant;
                    for (x, r) in w.states.iter_mut().zip(&w.rates) {
                        *x += dt * r;
                    }
                    crate::kinematics::forward_pass(model, &mut data, t + dt, q, u);
                    let mut st = std::mem::take(&mut w.states);
                    crate::forces::compliant::commit(model, &data, w, t + dt, &mut st)?;
                    w.states = st;
                    compliant_events(model, w, t + dt, &mut compliant_log);
                }
                for i in 0..nu {
                    udot[i] = (u[i] - u_start[i]) / dt;
                }
                let t_end = t + dt;
                log_step(model, &stepper, step, t_end, (&u_start, u), &mut states, &mut last_event, &mut log);
                for &(pt, mu, crit, non_unique) in &stepper.painleve {
                    if !non_unique && !continue_on_painleve {
                        let c = model.contact_of_point(pt);
                        return Err(Error::Painleve(format!(
                            "Painlevé situation at t = {t:.9} s: contact '{}' (point {}) slides with µ = {mu} above the critical µ = {crit:.6}; pressed into its contact, the contact problem has no solution at acceleration level (Moreau-Jean would stop the sliding by an impulse: set continue_on_painleve to go on)",
                            c.name,
                            pt - c.first
                        )));
                    }
                    let fresh =
                        painleve_event(&stepper, pt, (mu, crit, non_unique), step, t_end, &mut last_painleve, &mut log);
                    if fresh {
                        let c = model.contact_of_point(pt);
                        rec.warnings.push(if non_unique {
                            format!("Painlevé situation at t = {t:.9} s: contact '{}' (point {}) slides with µ = {mu} above the critical µ = {crit:.6}; the contact problem has two solutions (open, or closed pressing itself on): the time-stepping took one", c.name, pt - c.first)
                        } else {
                            format!("Painlevé situation at t = {t:.9} s: contact '{}' (point {}) slides with µ = {mu} above the critical µ = {crit:.6}; the sliding was stopped by an impulse (an impact without collision)", c.name, pt - c.first)
                        });
                    }
                }
                crate::integrator::check_finite(t + dt, &y)?;
                step += 1;
                stats.steps += 1;
            }
        }
        // the sample: kinematics and forces at the state, averaged accelerations of the last step
        let (q, rest) = y.split_at(nq);
        let u = &rest[..nu];
        crate::dynamics::prepare(model, &mut data, &mut ws, t_rec, q, u, cb)?;
        if model.nc > 0 {
            crate::constraints::positions(model, &mut data, t_rec, q, cb)?;
            ws.saddle.gather_g(&data.g);
            for (l, mu) in data.lambda.iter_mut().zip(&stepper.bilateral_impulse) {
                *l = mu / dt;
            }
        }
        data.udot.copy_from_slice(&udot);
        data.a[0] = crate::spatial::Motion::ZERO;
        let ud = std::mem::take(&mut data.udot);
        crate::kinematics::accelerations(model, &mut data, &ud);
        data.udot = ud;
        record(model, &data, &ws.saddle, t_rec, &y, &mut rec);
        // the contact points at the sample (skipped when no contact signal is recorded)
        if contact_signals {
            stepper.measure(model, &mut data, t_rec, q, u, cb)?;
            // the points' contact (as `Model::contact_of_point`, walked along: points ascend) and
            // its static coefficient, once per contact
            let mut ci = 0;
            let mut mu0 = model.contacts.first().map_or(0.0, |c| c.friction.mu0());
            for (pt, kk) in stepper.kinematics().iter().enumerate() {
                while ci + 1 < model.contacts.len() && model.contacts[ci + 1].first <= pt {
                    ci += 1;
                    mu0 = model.contacts[ci].friction.mu0();
                }
                let r = &stepper.results[pt];
                // over the interval since the last sample (one step at the first sample)
                let span = if k == 0 { dt } else { settings.output_dt };
                let (in_, it) = (acc_n[pt], acc_t[pt]);
                let f_t = (kk.point.t1 * it[0] + kk.point.t2 * it[1]) / span;
                // the reserve of the last step (forces of that step)
                let lt = (r.impulse_t[0].powi(2) + r.impulse_t[1].powi(2)).sqrt();
                let reserve = (mu0 * r.impulse_n - lt) / dt;
                let lambda = (in_ / span, [it[0] / span, it[1] / span]);
                rec.push_contact_point(kk, (in_, it), lambda, f_t, r.state, reserve);
            }
        }
        acc_n.fill(0.0);
        acc_t.fill([0.0; 2]);
        rec.dissipated_impact.push(stepper.dissipated_impact);
        rec.dissipated_friction.push(stepper.dissipated_friction);
        rec.contact_elastic.push(stepper.contact_elastic);
        rec.contact_drift.push(stepper.contact_drift);
        let (contacts, islands) = stepper.problem_shape();
        rec.solver.extend_from_slice(&[
            solver_acc.0,
            solver_acc.1 as f64,
            if solver_acc.2 { 1.0 } else { 0.0 },
            contacts as f64,
            islands as f64,
        ]);
        solver_acc = (0.0, 0, true);
        // the work of moving surfaces (conveyors) is external work done through the contacts
        if let Some(w) = rec.external_work.last_mut() {
            *w += stepper.surface_work;
        }
        // contact groups: what happened since the previous sample
        stepper.take_group_stats(&mut group_stats);
        for g in &group_stats {
            rec.group_closed.push(g.closed as f64);
            rec.group_max_penetration.push(g.max_penetration.max(0.0));
            rec.group_impulse_n.push(g.impulse_n);
            rec.group_pairs.push(g.pairs as f64);
            rec.group_impulse_against.extend_from_slice(&g.impulse_against);
        }
        for g in 0..group_stats.len() {
            let pts = stepper.group_points(g);
            rec.group_point_count.push(pts.len());
            rec.group_points.extend_from_slice(pts);
        }
        budget.wall(t_rec)?;
        match report_progress(progress, rec.t.len(), t_rec) {
            Ok(()) => {}
            // cancelled (Ctrl-C): the samples recorded so far are kept, each one complete
            Err(Error::Solver(msg)) if msg.starts_with(CANCELLED) => {
                rec.n_out = rec.t.len();
                rec.cancelled = Some(msg);
                break;
            }
            Err(e) => return Err(e),
        }
    }
    rec.events = EventRecord::from_log(model, &log);
    if !compliant_log.is_empty() {
        rec.events.extend(compliant_log);
        rec.events.sort_by(|a, b| a.t.total_cmp(&b.t));
    }
    if stepper.unconverged.0 > 0 {
        let (t1, names) = stepper.first_unconverged.clone().unwrap_or_default();
        rec.warnings.push(format!(
            "the contact solver did not reach its tolerance in {} of {} steps (worst residual {:.1e}; first at t = {t1:.6} s, contacts {names:?}); tighten the solver, raise max_iter or shorten dt",
            stepper.unconverged.0, stats.steps, stepper.unconverged.1
        ));
    }
    stats.evaluations = stats.steps;
    rec.stats = stats;
    Ok(rec)
}

/// The event-driven run ([`crate::integrator::event_driven`]): samples on the continuous
/// extension of the smooth phases; contact forces are the exact ones at the sample, impulses the
/// integrals of the forces plus the impacts since the previous sample.
#[allow(clippy::too_many_arguments)]
fn event_driven(
    model: &Model,
    settings: &Settings,
    cb: &dyn Callbacks,
    progress: Option<&Progress>,
    t_out: &[f64],
    y0: Vec<f64>,
    opts: crate::integrator::event_driven::Options,
    mut rec: Recording,
) -> Result<Recording> {
    let budget = Budget::new(settings);
    use crate::integrator::event_driven::{self, Phase};
    let (nq, nu, np) = (model.nq, model.nu, model.n_contact_points);
    let mut phase = Phase::new(model, cb, opts)?;
    phase.warm_search = settings.warm_search;
    let mut y = vec![0.0; phase.state_len()];
    y[..nq + nu + 2].copy_from_slice(&y0);
    // compliant contacts closed at the start: their onset speeds, no event
    phase.commit_compliant(settings.t0, &mut y)?;
    phase.compliant_changes.clear();
    let e = nq + nu;
    // integrals of the forces at the previous sample, and the energy taken by impacts so far
    let mut prev = vec![0.0; 3 * np];
    let contact_signals = rec.selection.contacts;
    rec.reserve_contacts(rec.n_out, if contact_signals { np } else { 0 });
    let (mut e_impact, mut e_impulsive_friction, mut w_impulsive) = (0.0, 0.0, 0.0);
    let mut warnings = Vec::new();
    let mut sample = |ph: &mut Phase, t: f64, y: &[f64], imp: &[f64], d: event_driven::Dissipation| -> Result<()> {
        record(model, &ph.data, &ph.dynamics.saddle, t, y, &mut rec);
        e_impact += d.impact;
        e_impulsive_friction += d.friction;
        // a moving surface or time-dependent gap works through the impulses too
        w_impulsive += d.external;
        if let Some(w) = rec.external_work.last_mut() {
            *w += w_impulsive;
        }
        for pt in 0..np {
            let kk = &ph.kin[pt];
            let now_n = y[e + 3 + pt];
            let now_t = [y[e + 3 + np + 2 * pt], y[e + 3 + np + 2 * pt + 1]];
            let i_n = now_n - prev[3 * pt] + imp[3 * pt];
            let i_t = [now_t[0] - prev[3 * pt + 1] + imp[3 * pt + 1], now_t[1] - prev[3 * pt + 2] + imp[3 * pt + 2]];
            prev[3 * pt] = now_n;
            prev[3 * pt + 1] = now_t[0];
            prev[3 * pt + 2] = now_t[1];
            // (the impulse integrals above run either way; the points' signals only if recorded)
            if !contact_signals {
                continue;
            }
            let f_t = kk.point.t1 * ph.lam_t[pt][0] + kk.point.t2 * ph.lam_t[pt][1];
            let con = model.contact_of_point(pt);
            let lt = (ph.lam_t[pt][0].powi(2) + ph.lam_t[pt][1].powi(2)).sqrt();
            let reserve = con.friction.mu0() * ph.lam_n[pt] - lt;
            let lambda = (ph.lam_n[pt], ph.lam_t[pt]);
            rec.push_contact_point(kk, (i_n, i_t), lambda, f_t, ph.state_code(pt), reserve);
        }
        rec.dissipated_impact.push(e_impact);
        rec.dissipated_friction.push(y[e + 2] + e_impulsive_friction);
        rec.contact_elastic.push(0.0);
        rec.contact_drift.push(0.0);
        budget.wall(t)?;
        report_progress(progress, rec.t.len(), t)
    };
    match event_driven::integrate(&mut phase, settings.t0, &y, t_out, &mut warnings, &mut sample) {
        Ok(stats) => rec.stats = stats,
        // cancelled (Ctrl-C): the samples recorded so far are kept, each one complete
        Err(Error::Solver(msg)) if msg.starts_with(CANCELLED) => {
            rec.n_out = rec.t.len();
            rec.cancelled = Some(msg);
        }
        Err(e) => return Err(e),
    }
    rec.warnings.extend(warnings);
    rec.events = EventRecord::from_log(model, &phase.log);
    if !phase.compliant_changes.is_empty() {
        // the compliant points' closings and openings among the rigid events, in time order
        let mut w = crate::forces::compliant::Work::default();
        for &(t, slot, closed) in &phase.compliant_changes {
            w.changed.clear();
            w.changed.push((slot, closed));
            compliant_events(model, &w, t, &mut rec.events);
        }
        rec.events.sort_by(|a, b| a.t.total_cmp(&b.t));
    }
    Ok(rec)
}

const OPEN_STATE: f64 = crate::integrator::moreau_jean::OPEN;

/// Moreau–Jean's events of one step ending at `t`: every change of a point's state (an impact
/// where a point closes approaching faster than 1e-8 m/s), with the step's impulses and the
/// energy they took; an impact spread over consecutive steps is one event.
#[allow(clippy::too_many_arguments)]
fn log_step(
    model: &Model,
    stepper: &crate::integrator::moreau_jean::MoreauJean,
    step: u64,
    t: f64,
    (u_before, u_after): (&[f64], &[f64]),
    states: &mut [f64],
    last_event: &mut [Option<(usize, u64)>],
    log: &mut crate::integrator::events::EventLog,
) {
    use crate::integrator::events::EventKind;
    use crate::integrator::moreau_jean::{OPEN, SLIP, STICK};
    let _ = model;
    for (pt, r) in stepper.results.iter().enumerate() {
        let (was, now) = (states[pt], r.state);
        states[pt] = now;
        let impact = now != OPEN && r.gd_n_before < -1e-8 && r.impulse_n > 0.0;
        // an impact that goes on from the previous step joins its event
        if impact {
            if let Some((k, s)) = last_event[pt] {
                let e = &mut log.events[k];
                if e.kind == EventKind::Impact && s + 1 == step {
                    e.impulse[0] += r.impulse_n;
                    e.impulse[1] += r.impulse_t[0];
                    e.impulse[2] += r.impulse_t[1];
                    e.energy += r.energy;
                    e.steps += 1;
                    if let Some(at) = e.velocities {
                        let nu = u_after.len();
                        log.velocities[at + nu..at + 2 * nu].copy_from_slice(u_after);
                    }
                    last_event[pt] = Some((k, step));
                    continue;
                }
            }
        }
        let kind = if impact && was == OPEN {
            EventKind::Impact
        } else if was == now {
            continue;
        } else if now == OPEN {
            EventKind::Open
        } else if was == OPEN {
            EventKind::Close
        } else if now == STICK {
            EventKind::Stick
        } else if now == SLIP {
            EventKind::Slip
        } else {
            continue;
        };
        let at = (kind == EventKind::Impact).then(|| log.store_velocities(u_before, u_after));
        let e = log.push(t, pt, kind);
        e.impulse = [r.impulse_n, r.impulse_t[0], r.impulse_t[1]];
        e.energy = r.energy;
        e.velocities = at;
        last_event[pt] = Some((log.events.len() - 1, step));
    }
}

/// A Painlevé situation found in the step ending at `t`: a new event, or the point's last one
/// extended if it was found in the previous step too. Returns true for a new one.
fn painleve_event(
    stepper: &crate::integrator::moreau_jean::MoreauJean,
    pt: usize,
    (mu, mu_critical, non_unique): (f64, f64, bool),
    step: u64,
    t: f64,
    last_painleve: &mut [Option<(usize, u64)>],
    log: &mut crate::integrator::events::EventLog,
) -> bool {
    use crate::integrator::events::{EventKind, Painleve};
    if let Some((k, s)) = last_painleve[pt] {
        if s + 1 == step {
            log.events[k].steps += 1;
            last_painleve[pt] = Some((k, step));
            return false;
        }
    }
    let r = &stepper.results[pt];
    let e = log.push(t, pt, EventKind::Painleve);
    e.impulse = [r.impulse_n, r.impulse_t[0], r.impulse_t[1]];
    e.energy = r.energy;
    let closed = if r.state != crate::integrator::moreau_jean::OPEN { vec![pt] } else { Vec::new() };
    let other = if closed.is_empty() { vec![pt] } else { Vec::new() };
    e.painleve = Some(Painleve {
        mu,
        mu_critical,
        non_unique,
        solutions: if non_unique { [closed, other] } else { [Vec::new(), Vec::new()] },
        resolved_by_impulse: !non_unique,
    });
    last_painleve[pt] = Some((log.events.len() - 1, step));
    true
}

/// Tells the progress watcher how many samples are recorded; an error if it asked to cancel.
fn report_progress(progress: Option<&Progress>, samples: usize, t: f64) -> Result<()> {
    if let Some(p) = progress {
        p.samples.store(samples as u64, Ordering::Relaxed);
        if p.cancel.load(Ordering::Relaxed) {
            return Err(Error::Solver(format!("{CANCELLED} at t = {t:.6} s")));
        }
    }
    Ok(())
}

/// Model indices of the bodies a run records (ascending), from the selection's names.
fn recorded_bodies(model: &Model, sel: &RecordSelection) -> Result<Vec<usize>> {
    let Some(names) = &sel.bodies else {
        return Ok((1..model.nbodies()).collect());
    };
    let mut out = Vec::with_capacity(names.len());
    for n in names {
        match model.body_id(n) {
            Some(0) => return Err(Error::Settings(format!("record.bodies: 'ground' has no recorded states"))),
            Some(i) => out.push(i),
            None => return Err(Error::Settings(format!("record.bodies: unknown body '{n}'"))),
        }
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// The record stage: appends one sample of every signal from an evaluated workspace (`saddle`:
/// the constrained solve's factorization, holding G as last gathered, for `G u - b`).
fn record(model: &Model, data: &Data, saddle: &Saddle, t: f64, y: &[f64], rec: &mut Recording) {
    let (nq, nu) = (model.nq, model.nu);
    let nb_rec = rec.n_bodies;
    let sel = &rec.selection;
    let (acc, cons, forces) = (sel.accelerations, sel.constraints, sel.forces);
    rec.t.push(t);
    rec.q.extend_from_slice(&y[..nq]);
    rec.u.extend_from_slice(&y[nq..nq + nu]);
    if acc {
        rec.udot.extend_from_slice(&data.udot);
    }
    for bi in 0..nb_rec {
        let i = rec.body_index[bi];
        let x = &data.x_abs[i];
        rec.body_position.extend_from_slice(x.r.as_slice());
        let mut qb = matrix_to_quaternion(&x.a);
        // q and -q are the same rotation: keep the sign closest to the previous sample so that
        // recorded orientations stay continuous through rotations past π
        let k = rec.body_orientation.len();
        if k >= 4 * nb_rec {
            let prev = &rec.body_orientation[k - 4 * nb_rec..k - 4 * nb_rec + 4];
            if prev.iter().zip(&qb).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
                qb = [-qb[0], -qb[1], -qb[2], -qb[3]];
            }
        }
        rec.body_orientation.extend_from_slice(&qb);
        let (v, a) = (&data.v[i], &data.a[i]);
        if data.body_elastic.get(i).copied().flatten().is_none() {
            // a rigid body's origin (the common case, without the elastic node search):
            // v_O = v + ω × r, a_O = a + ω̇ × r + ω × v_O (world convention, eq. 2.41)
            let vo = v.v + v.w.cross(&x.r);
            rec.body_velocity.extend_from_slice(vo.as_slice());
            rec.body_angular_velocity.extend_from_slice(v.w.as_slice());
            if acc {
                let ao = a.v + a.w.cross(&x.r) + v.w.cross(&vo);
                rec.body_acceleration.extend_from_slice(ao.as_slice());
                rec.body_angular_acceleration.extend_from_slice(a.w.as_slice());
            }
        } else {
            let origin = crate::math::Vec3::zeros();
            rec.body_velocity.extend_from_slice(point_velocity(data, i, &origin).as_slice());
            rec.body_angular_velocity.extend_from_slice(v.w.as_slice());
            if acc {
                rec.body_acceleration.extend_from_slice(point_acceleration(data, i, &origin).as_slice());
                rec.body_angular_acceleration.extend_from_slice(a.w.as_slice());
            }
        }
        rec.body_mass.push(data.inertia[i].m);
    }
    // one product I v per body gives its kinetic energy and both momenta (world convention)
    let (mut t_sum, mut p, mut l) = (0.0, crate::math::Vec3::zeros(), crate::math::Vec3::zeros());
    let all = nb_rec == model.nbodies() - 1;
    let mut next = 0;
    for i in 1..model.nbodies() {
        let (h, e) = energy::body_momentum(model, data, i);
        if all || (next < nb_rec && rec.body_index[next] == i) {
            rec.body_kinetic.push(e);
            next += 1;
        }
        t_sum += e;
        p += h.f;
        l += h.n;
    }
    rec.kinetic.push(t_sum);
    rec.potential.push(energy::potential_energy(model, data, &y[..nq]));
    rec.dissipated.push(y[nq + nu]);
    rec.external_work.push(y[nq + nu + 1]);
    rec.momentum_linear.extend_from_slice(p.as_slice());
    rec.momentum_angular.extend_from_slice(l.as_slice());
    if forces {
        rec.force_value.extend_from_slice(&data.element_force);
        rec.force_deflection.extend_from_slice(&data.element_deflection);
    }
    if !cons {
        return;
    }
    rec.constraint_lambda.extend_from_slice(&data.lambda);
    rec.constraint_violation.extend_from_slice(&data.phi);
    let k = rec.constraint_velocity_violation.len();
    rec.constraint_velocity_violation.resize(k + model.nc, 0.0);
    if model.nc > 0 {
        let out = &mut rec.constraint_velocity_violation[k..];
        saddle.g_times(&y[nq..nq + nu], out);
        for (o, b) in out.iter_mut().zip(&data.b) {
            *o -= b;
        }
    }
}
