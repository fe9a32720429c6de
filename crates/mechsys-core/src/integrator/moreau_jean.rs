//! Moreau–Jean time-stepping (section 2.5): velocities and impulses instead of accelerations and
//! forces, so impacts, stick–slip transitions and accumulations of impacts need no event
//! detection.
//!
//! One step of size h from (q_k, u_k), the midpoint rule of Moreau:
//! 1. `q_m = q_k + h/2 · q̇(u_k)`; at (t_k + h/2, q_m, u_k) the mass matrix, the smooth forces and
//!    the contact geometry are evaluated once;
//! 2. free velocity `u_free = u_k + h M⁻¹ (τ - c)`, made to satisfy the bilateral constraints at
//!    velocity level (`G u_free = b`) by an impulse;
//! 3. the contact points with `g_N(q_m) ≤` [`CONTACT_MARGIN`] are active (a positive gap lets the
//!    point approach by at most that gap within the step); with `W = [w_N, W_T]` at q_m and the
//!    inverse mass `M̃⁻¹` restricted by the bilateral constraints, the local velocities after the
//!    step are `ġ⁺ = Wᵀ u_free + (Wᵀ M̃⁻¹ W) Λ`;
//! 4. the friction-contact problem in the impulses Λ: Signorini–Coulomb between `Λ` and the
//!    Newton-restituted velocity `ġ_N⁺ + ε min(ġ_N⁻, 0)` (eq. 2.202 at velocity level), Coulomb's
//!    cone with µ0 for a contact that was sticking and µ(|ġ_T⁻|) for one that was sliding
//!    (eqs. 2.200, 2.201), solved by one of [`crate::solver`]'s methods, warm-started;
//! 5. `u_{k+1} = u_free + M̃⁻¹ W Λ`, `q_{k+1} = q_m + h/2 · q̇(u_{k+1})`, then the bilateral
//!    constraints are projected as in the smooth schemes.
//!
//! Energy: with M frozen over the step, the kinetic energy changes by `h fᵀ ū + Λᵀ Wᵀ ū`
//! (ū = (u_k + u_{k+1})/2), so `-Λᵀ ½(ġ⁻ + ġ⁺)` is what the contacts dissipate in the step; the
//! friction share is `-Λ_Tᵀ ġ_T⁺` (never negative under Coulomb's law), the impacts' the rest. Poisson's law is applied with its
//! normal coefficient as Newton's (they agree for a single frictionless impact); its tangential
//! coefficient needs the event-driven scheme.
//!
//! Assembly ([`Assembly`]): without bilateral constraints the rows of `W` are kept on their
//! bodies' root paths and the Delassus matrix is built as per-contact blocks from the tree
//! factor of M ([`sparse`]); with bilateral constraints `M̃⁻¹` couples every velocity and the
//! dense path (`M̃⁻¹ W` column by column) is taken. Both give the same impulses to round-off.
//!
//! Contact groups ([`crate::model::contact::ContactGroup`]): at the midpoint each group's broad
//! phase ([`GroupPhase`]) lists the pairs that may touch; their candidates join the explicit
//! contacts' in the same problem, warm-started from the pair's impulses of the previous step.

use nalgebra::DMatrix;

use crate::contact::{at_contact, ContactKinematics, ContactPoint, GroupPhase, SearchHint};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::model::contact::FrictionLaw;
use crate::model::joint::quat_matrix;
use crate::model::JointKind;
use crate::model::Model;
use crate::solver::{self, BlockDelassus, ContactState, Delassus, FrictionContact, Method, Workspace};
use crate::spatial::{Force, Motion};

mod islands;
mod projection;
mod sparse;
#[cfg(test)]
mod tests;

use sparse::SparseRows;

/// Candidate points with a midpoint gap up to this (m) join the step's contact problem, so that
/// resting contacts whose gap is a rounding error above zero (a box on four corners) are not
/// dropped and picked up in turn.
pub const CONTACT_MARGIN: f64 = 1e-9;

/// A point closed in the last step stays in the problem up to this gap (m): a pressed contact
/// whose gap creeps by rounding and the midpoint rule (a stuck tip of a turning rod) would
/// otherwise drop out for a step and come back with an impact. With its gap allowance such a
/// point takes an impulse only where it would otherwise end the step inside its contact.
pub const HOLD_MARGIN: f64 = 1e-7;

/// The share `τ/(h + τ)` of a compliant layer's deflection that is left after a step of `h`
/// without force (implicit Euler of `k δ + d δ̇ = 0`, `τ = c d`): 0 undamped, 1 infinitely damped.
#[inline]
fn relaxed(h: f64, tau: f64) -> f64 {
    if tau.is_finite() {
        tau / (h + tau)
    } else {
        1.0
    }
}

/// How far (m) beyond the activation margin a compliant point is taken into the step's problem
/// while it approaches at `gd_n` (twice the step's approach at the start velocity): its gap
/// allowance lets it close, not pass. A compliant layer must not be entered by a whole step's
/// motion the way a rigid point is (its velocity-level penetration stays as drift): the gap term
/// would then push that penetration out within a step, an elastic pop at any stiffness.
fn speculative(h: f64, gd_n: f64) -> f64 {
    2.0 * h * (-gd_n).max(0.0)
}

/// The activation margin of a point by its state in the last step (the run's first step holds
/// every point that touches at the start, so that a state given as closed is treated as closed).
fn margin(last_state: f64, first_step: bool) -> f64 {
    if last_state == OPEN && !first_step {
        CONTACT_MARGIN
    } else {
        HOLD_MARGIN
    }
}

/// Islands are solved on several threads, and a large problem's two domains swept on two, from
/// this many active contact points on; the impulses are the same either way. Below, handing work
/// to a second thread costs more than it saves: on the pour of 100 spheres (up to about 250
/// contact points) one thread was 10–20 % faster than two over eight starts; four such pours
/// side by side (800 points in several islands, solved island by island) ran 1.35 times faster
/// on two.
pub const PARALLEL_MIN_CONTACTS: usize = 400;

/// Contact state code in the recorded signal `contact/<c>/state`.
pub const OPEN: f64 = 0.0;
/// Sticking (closed, no sliding).
pub const STICK: f64 = 1.0;
/// Slipping (closed, sliding on the cone).
pub const SLIP: f64 = 2.0;

/// Per contact point results of the last step.
#[derive(Debug, Clone, Copy, Default)]
pub struct PointResult {
    /// Normal impulse Λ_N over the step (N s).
    pub impulse_n: f64,
    /// Tangential impulses (N s).
    pub impulse_t: [f64; 2],
    /// State code ([`OPEN`], [`STICK`], [`SLIP`]).
    pub state: f64,
    /// Normal relative velocity at the start of the step (m/s).
    pub gd_n_before: f64,
    /// Kinetic energy the point's impulses took in the step (J).
    pub energy: f64,
    /// Deflection δ of its compliant Signorini layer at the step's end (m): the layer's state,
    /// carried into the next step while the point stays in the problem. `None` for a rigid
    /// point or one not in the step (a layer left is taken as relaxed).
    pub layer: Option<f64>,
}

/// How the local contact problem is assembled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Assembly {
    /// Sparse for models without bilateral constraints, dense otherwise.
    #[default]
    Auto,
    /// Dense rows `W` (dim·m × nu), `M̃⁻¹ W` column by column, dense Delassus matrix; the only
    /// choice with bilateral constraints (`M̃⁻¹` couples everything).
    Dense,
    /// Rows on their bodies' root paths, per-contact Delassus blocks from the tree factor
    /// (see [`sparse`]); for models without bilateral constraints.
    Sparse,
}

/// Where an active contact point comes from.
#[derive(Debug, Clone, Copy)]
enum Source {
    /// Candidate point `pt` of the explicit contacts.
    Point(usize),
    /// Candidate `k` of slot `slot` of contact group `group`.
    Group { group: usize, slot: usize, k: usize },
}

/// A candidate point taking part in this step's contact problem.
#[derive(Debug, Clone, Copy)]
struct Active {
    b1: usize,
    b2: usize,
    /// The explicit contact of a [`Source::Point`] (index into `model.contacts`; 0 for a group's).
    contact: usize,
    point: ContactPoint,
    source: Source,
}

/// Closed points a contact group keeps for the record, per contour of the group (members and
/// `against`): a sphere in a pile touches its neighbours and the floor at a few points.
pub const GROUP_POINTS_PER_CONTOUR: usize = 8;

/// What a contact group did since the last [`MoreauJean::take_group_stats`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroupStats {
    /// Candidate points with a positive normal impulse in the last step.
    pub closed: usize,
    /// Largest penetration `max(0, -g_N)` over the candidates of the pairs the broad phase kept,
    /// at the midpoints of the steps (m).
    pub max_penetration: f64,
    /// Sum of the normal impulses over the steps (N s).
    pub impulse_n: f64,
    /// Pairs the broad phase kept in the last step.
    pub pairs: usize,
    /// Sum over the steps of the impulses the `against` contours exert on the members,
    /// `Λ_N n + Λ_T1 t1 + Λ_T2 t2`, world components (N s): with a container at rest this is
    /// the weight its contents put on it (times the interval).
    pub impulse_against: [f64; 3],
}

/// The workspace of the scheme, sized for the model.
pub struct MoreauJean {
    /// Step size (s).
    pub h: f64,
    method: Method,
    /// Contact dimension of the local problem (2 if every contact is planar, else 3).
    dim: usize,
    kin: Vec<ContactKinematics>,
    /// Per candidate point: the contact search's state between evaluations (warm starts).
    search: Vec<SearchHint>,
    /// Warm-start the contact searches of planar parametric contours (the same roots as cold
    /// searches; off: every evaluation searches cold).
    pub warm_search: bool,
    /// Local rows of every candidate (dim × nu per point), world-Jacobian projections.
    w_rows: DMatrix<f64>,
    x_cols: Vec<f64>,
    problem: FrictionContact,
    ws: Workspace,
    r: Vec<f64>,
    /// Last impulses per candidate, for warm starts and records.
    pub results: Vec<PointResult>,
    u_free: Vec<f64>,
    u_prev: Vec<f64>,
    /// The external loads' generalized forces at the midpoint (nu): their work over the step is
    /// `h Q_extᵀ (u_k + u_{k+1})/2`, the velocities the impulses leave included.
    q_ext: Vec<f64>,
    /// Scratch for `q_ext`: the loads' wrenches summed up the tree (nbody).
    load_acc: Vec<Force>,
    q_mid: Vec<f64>,
    q_pred: Vec<f64>,
    /// Joints whose velocities are components in their moving child frame (free: v and ω,
    /// spherical: ω): (coordinate offset of the quaternion, velocity offset, number of 3-blocks).
    rotating: Vec<(usize, usize, usize)>,
    tmp_u: Vec<f64>,
    gd_before: Vec<f64>,
    /// Per active point: it took the static coefficient µ0 (it was not sliding) while its law
    /// slides with less; a break-away in the step is solved again with the sliding coefficient.
    static_mu: Vec<bool>,
    /// Each active point's normal regularization `c/(h (h + τ))` (compliant Signorini laws,
    /// `τ = c d`); emptied after assembly where every point is rigid.
    reg: Vec<f64>,
    /// Each active point's compliance c, time constant τ = c d and layer deflection δ at the
    /// step's start (with `reg`; for the layer's law, state and energy).
    layer_c: Vec<[f64; 3]>,
    /// Painlevé situations of the last step: (point, µ, critical µ, non-unique) for each
    /// explicit point that slid into the step with a non-positive normal velocity change per
    /// unit normal impulse under its sliding friction; non-unique if its free motion separates
    /// it, else (pressed on) the step's problem stops the sliding impulsively.
    pub painleve: Vec<(usize, f64, f64, bool)>,
    /// Energy dissipated so far by normal impulses (J).
    pub dissipated_impact: f64,
    /// Energy dissipated so far by tangential impulses (J).
    pub dissipated_friction: f64,
    /// Elastic energy held by the compliant Signorini layers at the end of the last step,
    /// `Σ ½ k δ²` (J; `½ c λ_N²` undamped); the impact share of the contacts' work leaves its
    /// changes out.
    pub contact_elastic: f64,
    /// Energy the steps' geometry has given the compliant Signorini layers, as a negative
    /// dissipation (J, never positive): the held energy `½ k g_N²` of each point that joined a
    /// step already overlapped (the velocity-level step let it in within a step, so no work
    /// deflected its layer), which the layer then gives back. Zero for rigid contacts; part of the
    /// dissipated energy, so the balance is unchanged.
    pub contact_drift: f64,
    /// Work done on the system by moving surfaces (conveyor belts) through friction (J).
    pub surface_work: f64,
    /// Bilateral constraint impulse of the last step (nc), N s.
    pub bilateral_impulse: Vec<f64>,
    /// Steps whose contact problem did not reach the solver tolerance, and the worst residual.
    pub unconverged: (usize, f64),
    /// The first step that ended unconverged: its midpoint time (s) and the contacts of its
    /// problem (for the run's warning).
    pub first_unconverged: Option<(f64, Vec<String>)>,
    /// The solver's report of the last step (`None`: no contact was active).
    pub report: Option<solver::Report>,
    /// Broad and narrow phase of each contact group.
    pub groups: Vec<GroupPhase>,
    group_stats: Vec<GroupStats>,
    /// Per group: the points closed in the last step, `[p (3), force on the first contour's body
    /// (3), state]`, at most the capacity reserved up front (no allocation while stepping).
    group_points: Vec<Vec<[f64; 7]>>,
    act: Vec<Active>,
    sparse: Option<SparseRows>,
    /// The step's independent contact islands.
    islands: islands::Islands,
    /// Height of each active point along gravity (m), Gauss–Seidel's visiting order.
    height: Vec<f64>,
    /// Solve the islands on rayon's threads (the impulses do not depend on it).
    pub parallel: bool,
    /// Steps taken (for the validity of the groups' warm starts).
    steps: u64,
    /// Whether the contacts that stay closed are projected onto their contours after each step.
    pub project: bool,
    /// The closed contacts' position projection after each step.
    projection: projection::Projection,
    /// Per explicit point: it was in the last step's contact problem and closed before it.
    in_step: Vec<bool>,
    /// Per explicit point: closed (stick or slip) at the start of the step.
    closed_before: Vec<bool>,
    /// The sparse assembly's off-diagonal blocks are in `problem.w` for this step (they are
    /// built only when a solve needs them: not for Gauss–Seidel on the factored operator).
    blocks_ready: bool,
    /// This step's problem goes whole to the body-space Newton method (see `sparse::body_newton`).
    body_space: bool,
    /// `W r + q` of the step's solution when the factored solve found it (else empty).
    local_u: Vec<f64>,
}

impl MoreauJean {
    /// A stepper for `model` with step `h` and contact solver `method`.
    pub fn new(model: &Model, h: f64, method: Method) -> Result<Self> {
        Self::with_assembly(model, h, method, Assembly::Auto)
    }

    /// A stepper with a chosen assembly of the contact problem (an error for [`Assembly::Sparse`]
    /// on a model with bilateral constraints).
    pub fn with_assembly(model: &Model, h: f64, method: Method, assembly: Assembly) -> Result<Self> {
        crate::ensure!(h.is_finite() && h > 0.0, Settings, "integrator.dt: must be > 0, got {h}");
        // bad solver settings stop the run before its first step, not at its first contact
        method.validate()?;
        let (nu, np) = (model.nu, model.n_contact_points);
        let planar = model.contacts.iter().all(|c| c.is_planar()) && model.contact_groups.iter().all(|g| g.planar);
        let dim = if planar { 2 } else { 3 };
        crate::ensure!(
            !(assembly == Assembly::Sparse && model.nc > 0),
            Settings,
            "integrator: the sparse contact assembly needs a model without bilateral constraints (this one has {})",
            model.nc
        );
        let gaps = model.contacts.iter().any(|c| c.gap().is_some());
        crate::ensure!(
            !(assembly == Assembly::Sparse && gaps),
            Settings,
            "integrator: the sparse contact assembly works on contours; this model has gap contacts (use the dense one)"
        );
        // the sparse path builds rows from body points; a gap function brings its own
        let use_sparse = model.nc == 0 && !gaps && assembly != Assembly::Dense;
        let problem = FrictionContact {
            dim,
            w: if use_sparse {
                Delassus::Blocks(BlockDelassus::default())
            } else {
                Delassus::Dense(Vec::with_capacity(dim * dim * np * np))
            },
            q: Vec::with_capacity(dim * np),
            mu: Vec::with_capacity(np),
        };
        Ok(MoreauJean {
            h,
            method,
            dim,
            kin: vec![ContactKinematics::default(); np],
            search: vec![SearchHint::default(); np],
            warm_search: true,
            w_rows: DMatrix::zeros(if use_sparse { 0 } else { dim * np.max(1) }, nu),
            x_cols: if use_sparse { Vec::new() } else { vec![0.0; dim * np * nu] },
            problem,
            ws: Workspace::new(),
            r: Vec::with_capacity(dim * np),
            results: vec![PointResult::default(); np],
            u_free: vec![0.0; nu],
            u_prev: vec![0.0; nu],
            q_ext: vec![0.0; nu],
            load_acc: vec![Force::ZERO; model.nbodies()],
            q_mid: vec![0.0; model.nq],
            q_pred: vec![0.0; model.nq],
            rotating: model
                .joints
                .iter()
                .filter_map(|j| match j.kind {
                    JointKind::Free => Some((j.iq + 3, j.iu, 2)),
                    JointKind::Spherical => Some((j.iq, j.iu, 1)),
                    _ => None,
                })
                .collect(),
            tmp_u: vec![0.0; nu],
            gd_before: vec![0.0; dim * np],
            static_mu: Vec::with_capacity(np),
            reg: Vec::with_capacity(np),
            layer_c: Vec::with_capacity(np),
            painleve: Vec::with_capacity(np),
            dissipated_impact: 0.0,
            dissipated_friction: 0.0,
            contact_elastic: 0.0,
            contact_drift: 0.0,
            surface_work: 0.0,
            bilateral_impulse: vec![0.0; model.nc],
            unconverged: (0, 0.0),
            first_unconverged: None,
            report: None,
            groups: model.contact_groups.iter().map(GroupPhase::new).collect(),
            group_stats: vec![GroupStats::default(); model.contact_groups.len()],
            group_points: model
                .contact_groups
                .iter()
                .map(|g| Vec::with_capacity(GROUP_POINTS_PER_CONTOUR * (g.members.len() + g.against.len()).max(8)))
                .collect(),
            act: Vec::with_capacity(np),
            sparse: use_sparse.then(|| {
                let mut sp = SparseRows::new(model, dim);
                let accelerated = match method {
                    Method::Nsgs(o) => o.anderson > 0,
                    Method::Auto(o) => o.nsgs_anderson > 0,
                    _ => false,
                };
                if accelerated {
                    sp.reserve_acceleration(dim * np);
                }
                sp
            }),
            islands: islands::Islands::default(),
            height: Vec::new(),
            parallel: true,
            steps: 0,
            project: false,
            projection: projection::Projection::new(model),
            in_step: vec![false; np],
            closed_before: vec![false; np],
            blocks_ready: false,
            body_space: false,
            local_u: Vec::with_capacity(dim * np),
        })
    }

    /// The last step's contact problem: active contact points and independent islands (contacts
    /// that share no moving body solve apart).
    pub fn problem_shape(&self) -> (usize, usize) {
        (self.act.len(), self.islands.count())
    }

    /// Whether the contact problem is assembled sparsely.
    pub fn is_sparse(&self) -> bool {
        self.sparse.is_some()
    }

    /// Each group's points closed in the last step: `[x, y, z, fx, fy, fz, state]`, the contact
    /// point on the first contour and the contact force on its body (impulse over the step, world
    /// components). At most [`GROUP_POINTS_PER_CONTOUR`] per contour of the group are kept.
    pub fn group_points(&self, group: usize) -> &[[f64; 7]] {
        &self.group_points[group]
    }

    /// The statistics of each contact group since the last call, then reset (the count of closed
    /// points is that of the last step and is kept).
    pub fn take_group_stats(&mut self, out: &mut [GroupStats]) {
        for (o, s) in out.iter_mut().zip(self.group_stats.iter_mut()) {
            *o = *s;
            s.max_penetration = 0.0;
            s.impulse_n = 0.0;
            s.impulse_against = [0.0; 3];
        }
    }

    /// Advances (q, u) from t by one step; returns the work of the smooth external loads and the
    /// energy dissipated by the smooth dampers over the step (J). `ws` is the dynamics stage's
    /// workspace of `model` (its tree factor of M and the bilateral constraints' factorization).
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        model: &Model,
        data: &mut Data,
        ws: &mut crate::dynamics::Workspace,
        t: f64,
        q: &mut [f64],
        u: &mut [f64],
        cb: &dyn Callbacks,
    ) -> Result<(f64, f64)> {
        let (nu, nc, h) = (model.nu, model.nc, self.h);
        let tm = t + 0.5 * h;
        for (c, r) in self.closed_before.iter_mut().zip(&self.results) {
            *c = r.state != OPEN;
        }
        // (the exponential map keeps quaternions unit: no renormalization)
        model.integrate(q, u, 0.5 * h, &mut self.q_mid);
        // ---- smooth part at the midpoint: u_free = u + h M⁻¹ (τ - c(ū)), with the velocity-
        // dependent forces at ū = (u + u_free)/2 (one predictor pass at u): explicit Euler on them
        // would inflate rotating velocity components by (ω h)²/2 per step, e.g. a body-frame
        // velocity turning with the body of a rolling ball
        let mut p = crate::forces::Powers::default();
        for pass in 0..2 {
            if pass == 1 {
                for i in 0..nu {
                    self.u_free[i] = 0.5 * (u[i] + self.u_free[i]);
                }
            }
            p = if pass == 0 {
                crate::dynamics::prepare(model, data, ws, tm, &self.q_mid, u, cb)?
            } else {
                // (the same midpoint positions: only the velocities and forces are redone)
                data.record_loads = true;
                let p = crate::dynamics::prepare_rates(model, data, ws, tm, &self.q_mid, &self.u_free, cb);
                data.record_loads = false;
                let p = p?;
                self.external_loads(model, data);
                p
            };
            data.a[0] = Motion::ZERO;
            let zero = std::mem::take(&mut data.zero_u);
            crate::kinematics::accelerations(model, data, &zero);
            data.zero_u = zero;
            let mut c = std::mem::take(&mut self.tmp_u);
            crate::dynamics::rnea::rnea_inward(model, data, &mut c);
            if pass == 0 {
                let Data { inertia, s, ic, elastic, .. } = &mut *data;
                let saddle = &mut ws.saddle;
                crate::dynamics::crba::composite_inertias(model, inertia, s, ic, elastic, |r, col, v| {
                    saddle.put_mass(r, col, v);
                });
                if !ws.saddle.factor_mass() {
                    return Err(Error::Solver(format!(
                        "the mass matrix is singular at t = {tm:.6} s{}",
                        crate::elastic::runaway(model, data)
                    )));
                }
                if let Some(sp) = self.sparse.as_mut() {
                    sp.factor.copy_from(&ws.saddle);
                }
            }
            for v in c.iter_mut() {
                *v = -*v * h;
            }
            ws.saddle.solve_mass(&mut c);
            for i in 0..nu {
                self.u_free[i] = u[i] + c[i];
            }
            self.tmp_u = c;
        }
        // everything from here on is written in the joint frames of the midpoint: u_free (meant
        // for the end of the step) and u_k (for ġ⁻) are carried there
        let (q_mid, mut q_pred) = (std::mem::take(&mut self.q_mid), std::mem::take(&mut self.q_pred));
        model.integrate(&q_mid, &self.u_free, 0.5 * h, &mut q_pred);
        let mut uf = std::mem::take(&mut self.u_free);
        self.reframe(&q_pred, &q_mid, &mut uf);
        self.u_free = uf;
        self.u_prev.copy_from_slice(u);
        let mut up = std::mem::take(&mut self.u_prev);
        self.reframe(q, &q_mid, &mut up);
        self.u_prev = up;
        self.q_mid = q_mid;
        self.q_pred = q_pred;
        if nc > 0 {
            // bilateral rows at velocity level: G u_free = b(t + h), by the impulse μ
            crate::constraints::positions(model, data, t + h, &self.q_mid, cb)?;
            ws.saddle.gather_g(&data.g);
            ws.saddle.assemble_schur(true);
            ws.saddle.factor_schur(1e-12);
            let mut mu = std::mem::take(&mut self.bilateral_impulse);
            ws.saddle.g_times(&self.u_free, &mut mu);
            for k in 0..nc {
                mu[k] = data.b[k] - mu[k];
            }
            ws.saddle.solve_schur(&mut mu);
            ws.saddle.add_constraint_accelerations(&mu, &mut self.u_free);
            self.bilateral_impulse = mu;
        }
        // ---- contacts at the midpoint: the explicit pairs, then the groups' pairs
        let (d, np) = (self.dim, model.n_contact_points);
        self.act.clear();
        for (ci, con) in model.contacts.iter().enumerate() {
            let k = &mut self.kin[con.first..con.first + con.points()];
            let s = self.warm_search.then(|| &mut self.search[con.first..con.first + con.points()]);
            // a gap function reads the step's start velocities (its w̃ does not depend on them);
            // the step works at velocity level, so the w̄ terms are not formed
            crate::contact::contact_point_velocities(con, data, tm, &self.q_mid, u, cb, k, s)
                .map_err(|e| at_contact(e, &con.name, tm))?;
            for (j, kk) in k.iter().enumerate() {
                let pt = con.first + j;
                let reach = if con.compliance > 0.0 { speculative(h, kk.gd_n) } else { 0.0 };
                if kk.point.g_n <= margin(self.results[pt].state, self.steps == 0) + reach {
                    self.act.push(Active {
                        b1: con.body1,
                        b2: con.body2,
                        contact: ci,
                        point: kk.point,
                        source: Source::Point(pt),
                    });
                }
            }
        }
        for (gi, group) in model.contact_groups.iter().enumerate() {
            let ph = &mut self.groups[gi];
            ph.update(group, data, h, CONTACT_MARGIN).map_err(|e| Error::Solver(format!("at t = {tm:.6} s: {e}")))?;
            let mut pen = self.group_stats[gi].max_penetration;
            for &slot in &ph.live {
                let sl = &ph.slots[slot];
                let fresh = sl.stamp == self.steps.wrapping_sub(1);
                for (k, kk) in sl.kin.iter().enumerate() {
                    pen = pen.max(-kk.point.g_n);
                    let reach = if group.compliance > 0.0 { speculative(h, kk.gd_n) } else { 0.0 };
                    if kk.point.g_n <= margin(if fresh { sl.last[k].1 } else { OPEN }, self.steps == 0) + reach {
                        let source = Source::Group { group: gi, slot, k };
                        self.act.push(Active { b1: sl.body1, b2: sl.body2, contact: 0, point: kk.point, source });
                    }
                }
            }
            self.group_stats[gi].max_penetration = pen;
            self.group_stats[gi].pairs = ph.live.len();
        }
        let m = self.act.len();
        // the layers' energy at the step's end (stored), at the start of the points that carry
        // their layer's state from the last step (kept) and of those that join overlapped (new)
        let (mut dw_n, mut dw_t, mut stored, mut kept, mut new) = (0.0, 0.0, 0.0, 0.0, 0.0);
        if m > 0 {
            let dm = d * m;
            // local velocities before (u_k) and without (u_free) the impulses: ġ⁻, ġ_free
            self.gd_before.clear();
            self.gd_before.resize(dm, 0.0);
            self.problem.q.clear();
            self.problem.q.resize(dm, 0.0);
            if let Some(sp) = self.sparse.as_mut() {
                sp.clear();
                for a in &self.act {
                    let k = &a.point;
                    sp.add_contact(
                        model,
                        &data.s,
                        (&data.x_abs, &data.elastic, &data.body_elastic),
                        a.b1,
                        &k.p1,
                        a.b2,
                        &k.p2,
                        &[k.n, k.t1, k.t2],
                    );
                }
                // the diagonal blocks and the couplings now, the pairs' blocks when a solve needs them
                sp.couplings();
                self.blocks_ready = false;
                let (mut g, mut g0) = ([0.0; 3], [0.0; 3]);
                for ai in 0..m {
                    sp.local_velocity2(ai, &self.u_free, &self.u_prev, &mut g, &mut g0);
                    // (element-wise: a slice copy of d values is a library call)
                    for r in 0..d {
                        self.problem.q[ai * d + r] = g[r];
                        self.gd_before[ai * d + r] = g0[r];
                    }
                }
            } else {
                self.assemble_rows(model, data);
                // X = M̃⁻¹ W, column by column (restricted to the bilateral constraints' tangent space)
                if self.x_cols.len() < dm * nu {
                    self.x_cols.resize(dm * nu, 0.0);
                }
                for col in 0..dm {
                    let x = &mut self.x_cols[col * nu..(col + 1) * nu];
                    for i in 0..nu {
                        x[i] = self.w_rows[(col, i)];
                    }
                    crate::dynamics::constrained::tangent_inverse_mass(data, &mut ws.saddle, nc, x, None);
                }
                let Delassus::Dense(w) = &mut self.problem.w else { unreachable!("dense Delassus") };
                w.clear();
                w.resize(dm * dm, 0.0);
                for a in 0..dm {
                    for b in 0..dm {
                        let mut s = 0.0;
                        for i in 0..nu {
                            s += self.w_rows[(a, i)] * self.x_cols[b * nu + i];
                        }
                        w[a * dm + b] = s;
                    }
                }
                // a tangent along which nothing can move (the out-of-plane tangent of a planar
                // mechanism) has a zero row: give it a positive diagonal so that its impulse is zero
                // instead of taking up the friction cone
                for a in 0..dm {
                    if a % d != 0 && (0..nu).all(|i| self.w_rows[(a, i)] == 0.0) {
                        let n = a - a % d;
                        w[a * dm + a] = w[n * dm + n].max(f64::MIN_POSITIVE);
                    }
                }
                for a in 0..dm {
                    let (mut s, mut s0) = (0.0, 0.0);
                    for i in 0..nu {
                        s += self.w_rows[(a, i)] * self.u_free[i];
                        s0 += self.w_rows[(a, i)] * self.u_prev[i];
                    }
                    self.problem.q[a] = s;
                    self.gd_before[a] = s0;
                }
            }
            // rheonomic terms: ġ = Wᵀ u + w̃ (eq. 2.112), a belt's speed or a user gap's ∂g/∂t at
            // the midpoint
            for (ai, a) in self.act.iter().enumerate() {
                if let Source::Point(pt) = a.source {
                    let s = self.kin[pt].w_tilde;
                    for k in 0..d {
                        self.problem.q[ai * d + k] += s[k];
                        self.gd_before[ai * d + k] += s[k];
                    }
                }
            }
            // the local problem: restitution, gap allowance, friction coefficients, warm start
            self.problem.dim = d;
            self.problem.mu.clear();
            self.static_mu.clear();
            self.reg.clear();
            self.layer_c.clear();
            self.painleve.clear();
            self.r.clear();
            for (ai, a) in self.act.iter().enumerate() {
                let (friction, impact, compliance, gd_t, prev, prev_state, prev_layer) = match a.source {
                    Source::Point(pt) => {
                        let con = &model.contacts[a.contact];
                        let r = &self.results[pt];
                        let prev = [r.impulse_n, r.impulse_t[0], r.impulse_t[1]];
                        (
                            &con.friction,
                            &con.impact,
                            (con.compliance, con.damping),
                            self.kin[pt].gd_t,
                            prev,
                            r.state,
                            r.layer,
                        )
                    }
                    Source::Group { group, slot, k } => {
                        let g = &model.contact_groups[group];
                        let sl = &self.groups[group].slots[slot];
                        let fresh = sl.stamp == self.steps.wrapping_sub(1);
                        let (prev, st) = if fresh { sl.last[k] } else { ([0.0; 3], OPEN) };
                        let (delta, written) = sl.layer[k];
                        let layer = (g.compliance > 0.0 && written == self.steps.wrapping_sub(1)).then_some(delta);
                        (&g.friction, &g.impact, (g.compliance, g.damping), sl.kin[k].gd_t, prev, st, layer)
                    }
                };
                // a point slides into the step if it slid in the last one, or if it took no
                // impulse in the last one (the run's first step, a closing) and touches without
                // approaching while sliding clearly (1e-6 m/s: above the creep a solver's
                // tolerance leaves at a point of a statically indeterminate stick)
                let slip_speed = (gd_t[0].powi(2) + if d == 3 { gd_t[1].powi(2) } else { 0.0 }).sqrt();
                // (gd_t is the midpoint's free-motion rate; the rate at the step's start is ġ⁻)
                let speed_before = self.gd_before[ai * d + 1..(ai + 1) * d].iter().map(|v| v * v).sum::<f64>().sqrt();
                let sliding_in = prev_state == SLIP
                    || (prev_state == OPEN && speed_before > 1e-6 && self.gd_before[ai * d] >= -1e-9);
                // Painlevé test of a point sliding into the step (see crate::integrator::events)
                if let (Source::Point(pt), true) = (a.source, sliding_in) {
                    let gt = &self.gd_before[ai * d + 1..(ai + 1) * d];
                    let speed = gt.iter().map(|v| v * v).sum::<f64>().sqrt();
                    if speed > 0.0 && !matches!(friction, FrictionLaw::None) {
                        let mut s = [0.0; 2];
                        for (k, v) in gt.iter().enumerate() {
                            s[k] = v / speed;
                        }
                        let mu = friction.mu(speed);
                        let mut blk = [0.0; 9];
                        match self.sparse.as_ref() {
                            Some(sp) => sp.diag_block(ai, &mut blk),
                            None => self.problem.w.diag_block(d, ai, &mut blk),
                        }
                        let (c, crit) = crate::integrator::events::painleve_margin(&blk[..d * d], d, mu, s);
                        if c <= 1e-12 * blk[0].abs() {
                            // the free normal acceleration times h: at the midpoint ġ⁻ holds
                            // half a step of w̄ and ġ_free adds the step's forces, so
                            // h (w̄ + w_Nᵀ M⁻¹ f) = ġ_free + ġ⁻ for a point closed at the start
                            let free = self.problem.q[ai * d] + self.gd_before[ai * d];
                            self.painleve.push((pt, mu, crit, free > 0.0));
                        }
                    }
                }
                // a point still open by less than the margin may close within the step, not
                // beyond. A compliant point's layer (k = 1/c, d, τ = c d) is deflected by δ₀ at the
                // step's start: its state from the last step, or the overlap −g_N of a point that
                // joins overlapped. Pressed, it ends the step at the body, δ = −(g_N + h ġ_N⁺), with
                // F = Λ_N/h = k δ + d (δ − δ₀)/h, i.e. ġ_N⁺ + (g_N + τ δ₀/(h + τ))/h
                // + c/(h (h + τ)) Λ_N ≥ 0: the regularization of W_NN (added below) and a gap
                // term, an implicit Euler step of the layer. Without force the layer relaxes to
                // τ δ₀/(h + τ) on its own, and the body cannot pass its surface there (a layer
                // let go while still deflected is not pressed again at the body's overlap)
                let (c, damping) = compliance;
                let g = a.point.g_n;
                let tau = c * damping;
                let d0 = if c > 0.0 { prev_layer.unwrap_or((-g).max(0.0)) } else { 0.0 };
                if c > 0.0 {
                    match prev_layer {
                        Some(_) => kept += 0.5 * d0 * d0 / c,
                        None => new += 0.5 * d0 * d0 / c,
                    }
                }
                let gap_allowance = if c > 0.0 { (g + relaxed(h, tau) * d0) / h } else { g.max(0.0) / h };
                self.reg.push(c / (h * (h + tau)));
                self.layer_c.push([c, tau, d0]);
                self.problem.q[ai * d] += impact.eps() * self.gd_before[ai * d].min(0.0) + gap_allowance;
                let mu = match friction {
                    FrictionLaw::None => 0.0,
                    law if sliding_in => law.mu(slip_speed.max(f64::MIN_POSITIVE)),
                    law => law.mu0(),
                };
                let sliding_less =
                    !matches!(friction, FrictionLaw::None) && !sliding_in && friction.mu(f64::MIN_POSITIVE) < mu;
                self.static_mu.push(sliding_less);
                self.problem.mu.push(mu);
                if d == 3 {
                    // (a fixed-size copy: a slice of d values is a library call)
                    self.r.extend_from_slice(&prev);
                } else {
                    self.r.extend_from_slice(&prev[..d]);
                }
            }
            // the compliant layers' regularization on the normal diagonal (all solvers see W + R)
            if self.reg.iter().any(|v| *v > 0.0) {
                match self.sparse.as_mut() {
                    Some(sp) => {
                        for (ai, reg) in self.reg.iter().enumerate() {
                            sp.diag[ai * d * d] += reg;
                        }
                        sp.reg.clear();
                        sp.reg.extend_from_slice(&self.reg);
                    }
                    None => {
                        let Delassus::Dense(w) = &mut self.problem.w else { unreachable!("dense Delassus") };
                        for (ai, reg) in self.reg.iter().enumerate() {
                            w[(ai * d) * (d * m) + ai * d] += reg;
                        }
                    }
                }
            } else {
                self.reg.clear();
                self.layer_c.clear();
            }
            // `auto` sweeps a problem regularized well on every contact, at any size (its sweeps
            // converge fast; Newton's factorizations cost more than they save there)
            let chosen = self.method;
            if let Method::Auto(o) = chosen {
                if !self.reg.is_empty() && self.well_regularized(d) {
                    self.method = Method::Nsgs(o.sweeps());
                }
            }
            // sweeps from the bottom up along gravity: each contact then sees the newest support
            // below it, and a warm-started pile settles in fewer sweeps than in pair order
            self.height.clear();
            let g = model.gravity;
            if g.norm() > 0.0 {
                let down = g / g.norm();
                self.height.extend(self.act.iter().map(|a| -down.dot(&(0.5 * (a.point.p1 + a.point.p2)))));
            }
            self.ws.set_order(&self.height);
            // independent islands (sparse assembly only: the dense one couples through M̃⁻¹)
            let mut sweep_whole = false;
            match self.sparse.as_ref() {
                Some(sp) => {
                    self.islands.partition(m, &sp.links);
                    // `Auto` sweeps an island above its Newton size in any case; where such
                    // islands hold most contacts, and every contact is on free bodies with one
                    // coefficient, the whole problem takes the factored sweeps, the small islands
                    // swept along: no Delassus blocks are formed and no block sweeps run (four
                    // pours side by side ran 20 % faster whole than island by island, the
                    // islands' sweeps on the blocks costing about twice the factored ones)
                    // Plain NSGS sweeps every island; where one holds most contacts (a pile with
                    // a few strays of its own), sweeping the rest along costs less than the
                    // blocks: the 1000-sphere pour under NSGS(tol=1e-4, max_iter=20) spent 28 %
                    // of its time on the block form for the sake of a sphere or two. (Islands of
                    // similar size keep their own stopping tests and threads.)
                    let whole = match &self.method {
                        Method::Auto(o) => 4 * self.islands.in_islands_above(o.newton_max_unknowns / d) >= 3 * m,
                        Method::Nsgs(_) => 4 * self.islands.largest() >= 3 * m,
                        _ => false,
                    };
                    sweep_whole = whole && sp.all_free() && !self.static_mu.iter().any(|s| *s);
                    if self.islands.count() > 1 && !sweep_whole {
                        self.ensure_blocks();
                        let sp = self.sparse.as_ref().expect("sparse assembly");
                        self.islands.fill(&self.problem, &sp.diag, &sp.upper, &sp.upper_val, &self.r, &self.height);
                    }
                }
                None => self.islands.single(m),
            }
            // Newton on a large problem of free bodies: solved whole, its direction in body space
            self.body_space = match (&self.method, self.sparse.as_ref()) {
                (Method::Newton(o), Some(sp)) => {
                    // (its direction in body space carries no regularization)
                    m * d > o.body_space_above
                        && !self.static_mu.iter().any(|s| *s)
                        && sp.all_free()
                        && self.reg.is_empty()
                }
                _ => false,
            };
            let split = self.sparse.is_some() && self.islands.count() > 1 && !self.body_space && !sweep_whole;
            self.local_u.clear();
            let factored = !split && !self.static_mu.iter().any(|s| *s);
            let solved = self.solve_contacts(split, false, factored);
            if solved.is_err() {
                // (the integrator's own method back before the error leaves the step)
                self.method = chosen;
            }
            let report = solved.map_err(|e| {
                let names = self.active_names(model);
                Error::Solver(format!("contacts {names:?} at t = {tm:.6} s: {e}"))
            })?;
            // µ0 decides whether a contact that was not sliding sticks; where it breaks away in
            // this step the slide takes the sliding coefficient at its new speed (a step of µ0
            // would lag the motion by h (µ0 - µ) λ_N / m for good)
            let mut report = report;
            if self.static_mu.iter().any(|s| *s) {
                let r_scale = 1.0 + self.r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                let q_scale = 1.0 + self.problem.q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                let mut again = false;
                for ai in 0..m {
                    if !self.static_mu[ai] {
                        continue;
                    }
                    // on the cone's boundary and moving: the static friction is used up (a slide
                    // that starts from rest is slower than the state tolerance within its first
                    // steps, but faster than the solver's noise; a point of a statically
                    // indeterminate stick may sit on its cone without moving)
                    let tol = 1e-9 * (1.0 + self.r[ai * d].abs());
                    let v = self.problem.local_velocity(ai, &self.r)?;
                    let speed = (v[1] * v[1] + v[2] * v[2]).sqrt();
                    let noise = (100.0 * report.residual).max(1e-14 * q_scale);
                    let saturated = self.r[ai * d] > 0.0
                        && speed > noise
                        && self.problem.friction_reserve(ai, &self.r)? <= 1e-9 * self.problem.mu[ai] * self.r[ai * d];
                    if saturated
                        || self.problem.contact_state_scaled(ai, &self.r, tol, r_scale, q_scale)? == ContactState::Slip
                    {
                        let law = match self.act[ai].source {
                            Source::Point(_) => &model.contacts[self.act[ai].contact].friction,
                            Source::Group { group, .. } => &model.contact_groups[group].friction,
                        };
                        self.problem.mu[ai] = law.mu(speed.max(f64::MIN_POSITIVE));
                        again = true;
                    }
                }
                if again {
                    let solved = self.solve_contacts(split, true, false);
                    if solved.is_err() {
                        self.method = chosen;
                    }
                    report = solved.map_err(|e| {
                        let names = self.active_names(model);
                        Error::Solver(format!("contacts {names:?} at t = {tm:.6} s: {e}"))
                    })?;
                }
            }
            self.method = chosen;
            if !report.converged {
                self.unconverged.0 += 1;
                self.unconverged.1 = self.unconverged.1.max(report.residual);
                if self.first_unconverged.is_none() {
                    // once per run: the names for the warning
                    self.first_unconverged = Some((tm, self.active_names(model)));
                }
            }
            self.report = Some(report);
            // u⁺ = u_free + M̃⁻¹ W Λ
            u.copy_from_slice(&self.u_free);
            if let Some(sp) = self.sparse.as_mut() {
                sp.apply(&self.r, u);
            } else {
                for (col, lam) in self.r.iter().enumerate() {
                    if *lam != 0.0 {
                        for i in 0..nu {
                            u[i] += self.x_cols[col * nu + i] * lam;
                        }
                    }
                }
            }
            for s in self.group_stats.iter_mut() {
                s.closed = 0;
            }
            self.group_points.iter_mut().for_each(Vec::clear);
            let mut after = [0.0; 3];
            let r_scale = 1.0 + self.r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let q_scale = 1.0 + self.problem.q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for ai in 0..m {
                let tol = 1e-9 * (1.0 + self.r[ai * d].abs());
                let state = if self.local_u.is_empty() {
                    self.problem.contact_state_unchecked(ai, &self.r, tol, r_scale, q_scale)
                } else {
                    // the factored solve's W r + q (no blocks were built)
                    let (mut ri, mut ui) = ([0.0; 3], [0.0; 3]);
                    ri[..d].copy_from_slice(&self.r[ai * d..(ai + 1) * d]);
                    ui[..d].copy_from_slice(&self.local_u[ai * d..(ai + 1) * d]);
                    solver::classify(&ri, &ui, tol, r_scale, q_scale)
                };
                let code = match state {
                    ContactState::Open => OPEN,
                    ContactState::Stick => STICK,
                    ContactState::Slip => SLIP,
                };
                let mut imp = [0.0; 3];
                for (r, v) in imp.iter_mut().enumerate().take(d) {
                    *v = self.r[ai * d + r];
                }
                match self.act[ai].source {
                    Source::Point(pt) => {
                        self.results[pt] = PointResult {
                            impulse_n: imp[0],
                            impulse_t: [imp[1], imp[2]],
                            state: code,
                            gd_n_before: self.gd_before[ai * d],
                            energy: 0.0,
                            layer: None,
                        };
                    }
                    Source::Group { group, slot, k } => {
                        let sl = &mut self.groups[group].slots[slot];
                        sl.last[k] = (imp, code);
                        sl.stamp = self.steps;
                        let against = sl.key.1 as usize >= model.contact_groups[group].members.len();
                        let st = &mut self.group_stats[group];
                        st.impulse_n += imp[0];
                        if against {
                            let p = &self.act[ai].point;
                            let f = p.n * imp[0] + p.t1 * imp[1] + p.t2 * imp[2];
                            for c in 0..3 {
                                st.impulse_against[c] += f[c];
                            }
                        }
                        if imp[0] > 0.0 {
                            st.closed += 1;
                            let pts = &mut self.group_points[group];
                            if pts.len() < pts.capacity() {
                                let p = &self.act[ai].point;
                                let f = (p.n * imp[0] + p.t1 * imp[1] + p.t2 * imp[2]) / h;
                                pts.push([p.p1.x, p.p1.y, p.p1.z, f.x, f.y, f.z, code]);
                            }
                        }
                    }
                }
                // the kinetic energy the impulses take is -Λᵀ(ġ⁻ + ġ⁺)/2 in total; friction's share
                // is -Λ_Tᵀ ġ_T⁺ (≥ 0 by Coulomb's law, zero while sticking), the rest is the impact's
                if let Some(sp) = self.sparse.as_ref() {
                    sp.local_velocity(ai, u, &mut after);
                } else {
                    for (row, af) in after.iter_mut().enumerate().take(d) {
                        let a = ai * d + row;
                        *af = (0..nu).map(|i| self.w_rows[(a, i)] * u[i]).sum();
                    }
                }
                // a moving surface or a time-dependent gap: ġ⁺ includes w̃, and the motion that
                // drives it works on the system by -Λᵀ w̃
                if let Source::Point(pt) = self.act[ai].source {
                    let w = self.kin[pt].w_tilde;
                    for row in 0..d {
                        after[row] += w[row];
                        self.surface_work -= self.r[ai * d + row] * w[row];
                    }
                }
                let mut e_point = 0.0;
                for row in 0..d {
                    let a = ai * d + row;
                    let e = -self.r[a] * 0.5 * (after[row] + self.gd_before[a]);
                    e_point += e;
                    dw_n += e;
                    if row > 0 {
                        dw_t += -self.r[a] * after[row];
                    }
                }
                if let Some(&[c, tau, d0]) = self.layer_c.get(ai) {
                    // the layer's state at the step's end: pressed, at the body (by the step's law
                    // δ = (h c λ_N + τ δ₀)/(h + τ) = −(g_N + h ġ_N⁺)); without force, relaxed on its
                    // own to τ δ₀/(h + τ). It holds ½ k δ²; from δ₀ the layer takes in
                    // λ_N (δ − δ₀) and stores ½ k (δ² − δ₀²), the rest (½ k + d/h) (δ − δ₀)² is its
                    // damper's and the step's dissipation: never negative
                    if c > 0.0 {
                        let f = self.r[ai * d] / h;
                        let w = relaxed(h, tau);
                        let delta = if f > 0.0 { (1.0 - w) * c * f + w * d0 } else { w * d0 };
                        stored += 0.5 * delta * delta / c;
                        match self.act[ai].source {
                            Source::Point(pt) => self.results[pt].layer = Some(delta),
                            Source::Group { group, slot, k } => {
                                self.groups[group].slots[slot].layer[k] = (delta, self.steps)
                            }
                        }
                    }
                }
                if let Source::Point(pt) = self.act[ai].source {
                    self.results[pt].energy = e_point;
                }
            }
        } else {
            self.report = None;
            self.islands.partition(0, &[]);
            u.copy_from_slice(&self.u_free);
            for s in self.group_stats.iter_mut() {
                s.closed = 0;
            }
            self.group_points.iter_mut().for_each(Vec::clear);
        }
        // explicit points that are not active carry no impulse and are open
        let mut next = 0;
        for pt in 0..np {
            let hit = self.act[next..].first().is_some_and(|a| matches!(a.source, Source::Point(p) if p == pt));
            // held: in this step's problem and closed before it (an impact's penetration is the
            // scheme's own and stays)
            self.in_step[pt] = hit && self.closed_before[pt];
            if hit {
                next += 1;
            } else {
                self.results[pt] = PointResult::default();
            }
        }
        self.steps += 1;
        // (what a compliant layer takes in within the step, it holds, from the deflection it
        // starts from; a layer whose point left the step relaxes, its damper dissipating what it
        // held (the last step's store less what the points kept carry on); a point that joins
        // overlapped brings a deflection no work made: the step's geometry put that energy in)
        self.dissipated_impact += dw_n - dw_t - (stored - kept - new) + (self.contact_elastic - kept);
        self.contact_drift -= new;
        self.contact_elastic = stored;
        self.dissipated_friction += dw_t;
        // the external loads' work over the step at the velocities the step gives them, u_k and
        // u_{k+1} (both in the midpoint's joint frames here): at the force stage's own (u_k +
        // u_free)/2 it missed the impulses' share, e.g. counted work on a body pressed at rest
        let external =
            h * self.q_ext.iter().zip(&self.u_prev).zip(u.iter()).map(|((f, a), b)| f * 0.5 * (a + b)).sum::<f64>();
        // ---- positions at the end of the step, and u in the end's joint frames
        model.integrate(&self.q_mid, u, 0.5 * h, q);
        self.reframe(&self.q_mid, q, u);
        // contacts that the velocity-level step let sink into a curved contour: every point of
        // the step's problem that was closed before it (a redundant twin of a closed point
        // too, so a symmetric resting configuration stays symmetric)
        if self.project {
            let (proj, in_step) = (&mut self.projection, &self.in_step);
            // (a compliant point's overlap is its layer's deflection, held on purpose)
            proj.project(model, data, ws, t + h, q, u, cb, |pt| {
                in_step[pt] && model.contact_of_point(pt).compliance == 0.0
            })?;
        }
        if nc > 0 {
            crate::dynamics::constrained::project(model, data, ws, t + h, q, u, cb)?;
        }
        Ok((external, p.dissipated * h))
    }

    /// `q_ext`: the generalized forces of the external loads of the force stage just evaluated
    /// (`Data::f_load`, `Data::tau_load`), the wrenches summed from the leaves (world components,
    /// so a parent adds its children's as they are) and projected on each joint's motion.
    fn external_loads(&mut self, model: &Model, data: &Data) {
        self.q_ext.copy_from_slice(&data.tau_load);
        self.load_acc.copy_from_slice(&data.f_load);
        for (ji, j) in model.joints.iter().enumerate().rev() {
            let i = ji + 1;
            let f = self.load_acc[i];
            for k in 0..j.nu() {
                self.q_ext[j.iu + k] += data.s[i][k].dot(&f);
            }
            if j.parent != 0 {
                self.load_acc[j.parent] += f;
            }
        }
    }

    /// Solves the step's friction-contact problem into `self.r` (warm-started from it): whole,
    /// or island by island when `split` (after [`islands::Islands::fill`]); `again` marks the
    /// re-solve after a break-away changed friction coefficients.
    ///
    /// With `factored` (one island of the sparse assembly) Gauss–Seidel runs on the factored
    /// operator ([`SparseRows::gauss_seidel`]) without the off-diagonal blocks: all of an NSGS
    /// solve, or [`Method::Auto`]'s first sweeps, the blocks being built only if Newton follows.
    fn solve_contacts(&mut self, split: bool, again: bool, factored: bool) -> Result<solver::Report> {
        if factored && self.sparse.is_some() {
            let m = self.r.len();
            // Gauss–Seidel on the factored operator, then (Auto's Newton) on the blocks
            let plan = match &self.method {
                Method::Nsgs(o) => Some(solver::AutoPlan { sweeps: None, then: Method::Nsgs(*o), rescue: None }),
                Method::Newton(o) if self.body_space => {
                    Some(solver::AutoPlan { sweeps: None, then: Method::Newton(*o), rescue: None })
                }
                Method::Auto(o) => Some(o.plan(m, &self.r, self.ws.newton.holds_factorization()))
                    .filter(|p| p.sweeps.is_some() || matches!(p.then, Method::Nsgs(_))),
                _ => None,
            };
            if let Some(plan) = plan {
                // the block solver's checks of its input (W_NN from the diagonal blocks)
                let d = self.problem.dim;
                solver::check_local(d, &self.problem.q, &self.problem.mu)?;
                let sp = self.sparse.as_ref().expect("sparse assembly");
                for i in 0..m / d {
                    solver::check_wnn(i, sp.diag[i * d * d])?;
                }
                if let Some(k) = self.r.iter().position(|v| !v.is_finite()) {
                    return Err(Error::Settings(format!("solver: warm start entry {k} is not finite ({})", self.r[k])));
                }
                return plan.run(|stage| match stage {
                    solver::Stage::Sweeps(o) => {
                        // (capacity for every contact point since construction: no allocation)
                        self.local_u.resize(m, 0.0);
                        let sp = self.sparse.as_mut().expect("sparse assembly");
                        // (a solve is split, and its halves go to threads, only from
                        // PARALLEL_MIN_CONTACTS points: `domains::SPLIT_MIN_CONTACTS`)
                        sp.parallel = self.parallel;
                        let problem = (&self.problem.q[..], &self.problem.mu[..]);
                        Ok(sp.gauss_seidel(problem, &self.ws.order, &mut self.r, o, &mut self.local_u))
                    }
                    solver::Stage::Solve(Method::Newton(o)) if self.body_space => {
                        self.local_u.resize(m, 0.0);
                        let sp = self.sparse.as_mut().expect("sparse assembly");
                        let problem = (&self.problem.q[..], &self.problem.mu[..]);
                        // (`body_space` was set only where every contact is on free bodies)
                        sp.body_newton(problem, &self.ws.order, &mut self.r, o, &mut self.local_u).ok_or_else(|| {
                            Error::Solver("Newton in body space: a contact is not on free bodies and the ground".into())
                        })
                    }
                    solver::Stage::Solve(method) => {
                        // on the blocks (an empty `local_u` tells the contact states to come
                        // from the problem)
                        self.local_u.clear();
                        self.ensure_blocks();
                        self.ws.reserve(&self.problem, method)?;
                        solver::solve(&self.problem, method, &mut self.r, true, &mut self.ws)
                    }
                });
            }
        }
        self.ensure_blocks();
        if split {
            if again {
                self.islands.refresh(&self.problem, &self.r);
            }
            // threads pay off only on problems of some size; the result does not depend on it
            let parallel = self.parallel && self.act.len() >= PARALLEL_MIN_CONTACTS;
            return self.islands.solve(&self.method, parallel, &mut self.r);
        }
        self.ws.reserve(&self.problem, &self.method)?;
        let warm = again || self.r.iter().any(|v| *v != 0.0);
        solver::solve(&self.problem, &self.method, &mut self.r, warm, &mut self.ws)
    }

    /// Whether every active point's normal regularization is at least [`solver::AUTO_SOFT`] of
    /// its rigid `W_NN` (after the regularization was added to the diagonal).
    fn well_regularized(&self, d: usize) -> bool {
        let m = self.reg.len();
        (0..m).all(|ai| {
            let wnn = match (self.sparse.as_ref(), &self.problem.w) {
                (Some(sp), _) => sp.diag[ai * d * d],
                (None, Delassus::Dense(w)) => w[(ai * d) * (d * m) + ai * d],
                (None, _) => return false,
            };
            let reg = self.reg[ai];
            reg >= solver::AUTO_SOFT * (wnn - reg)
        })
    }

    /// Puts the sparse assembly's Delassus blocks into the step's problem (once per step).
    fn ensure_blocks(&mut self) {
        if let (Some(sp), false) = (self.sparse.as_mut(), self.blocks_ready) {
            sp.pairs();
            let d = self.problem.dim;
            let Delassus::Blocks(bw) = &mut self.problem.w else { unreachable!("block Delassus") };
            bw.refill(d, sp.len(), &sp.diag, &sp.upper, &sp.upper_val);
            self.blocks_ready = true;
        }
    }

    /// Factorizations of the body-space Newton method so far (see
    /// [`crate::solver::NewtonOptions::body_space_above`]).
    pub fn body_space_factorizations(&self) -> usize {
        self.sparse.as_ref().map_or(0, |sp| sp.newton.factorizations())
    }

    /// Steps in which the position projection moved a contact back onto its contour.
    pub fn projections(&self) -> usize {
        self.projection.count
    }

    /// Re-expresses the child-frame velocity blocks of `u`, given in the joint frames of `q_from`,
    /// in those of `q_to`: `u ← A(q_to)ᵀ A(q_from) u` per block. The contact rows are built at
    /// the midpoint, so velocities meant for other configurations are carried there first (without
    /// it a body rotating at ω gains a spurious slip of order ω h per step).
    fn reframe(&self, q_from: &[f64], q_to: &[f64], u: &mut [f64]) {
        for &(iq, iu, blocks) in &self.rotating {
            let a = |q: &[f64]| quat_matrix(q[iq], q[iq + 1], q[iq + 2], q[iq + 3]);
            let d = a(q_to).transpose() * a(q_from);
            for b in 0..blocks {
                let k = iu + 3 * b;
                let v = d * crate::math::Vec3::new(u[k], u[k + 1], u[k + 2]);
                u[k..k + 3].copy_from_slice(v.as_slice());
            }
        }
    }

    /// Rows `n`, `t1` (, `t2`) of every active point into `w_rows` (the generalized directions of
    /// the contact forces: `w_N = J_P1ᵀ n - J_P2ᵀ n`, eq. 2.110 ff.).
    fn assemble_rows(&mut self, model: &Model, data: &Data) {
        let d = self.dim;
        let rows = d * self.act.len();
        if self.w_rows.nrows() < rows {
            self.w_rows = DMatrix::zeros(rows, model.nu);
        }
        for r in 0..rows {
            for i in 0..model.nu {
                self.w_rows[(r, i)] = 0.0;
            }
        }
        for (ai, a) in self.act.iter().enumerate() {
            let k = &a.point;
            let gap = match a.source {
                Source::Point(pt) => model.contact_of_point(pt).gap().map(|g| g.1),
                Source::Group { .. } => None,
            };
            if let Some(slot) = gap {
                // a gap function's own rows W_N, W_T1, W_T2
                let nu = model.nu;
                for row in 0..d {
                    let w = &data.gap.rows[(3 * slot + row) * nu..(3 * slot + row + 1) * nu];
                    for (i, v) in w.iter().enumerate() {
                        self.w_rows[(ai * d + row, i)] = *v;
                    }
                }
                continue;
            }
            let dirs = [k.n, k.t1, k.t2];
            for (row, dir) in dirs.iter().enumerate().take(d) {
                let r = ai * d + row;
                crate::constraints::add_relative_rows(
                    model,
                    &data.s,
                    (&data.x_abs, &data.elastic, &data.body_elastic),
                    (a.b1, &k.p1),
                    (a.b2, &k.p2),
                    Some(dir),
                    &mut self.w_rows,
                    r,
                );
            }
        }
    }

    /// Names of the contacts (and groups) in this step's problem, for messages.
    fn active_names(&self, model: &Model) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for a in &self.act {
            let n = match a.source {
                Source::Point(pt) => model.contact_of_point(pt).name.clone(),
                Source::Group { group, .. } => format!("group {}", model.contact_groups[group].name),
            };
            if out.last() != Some(&n) {
                out.push(n);
            }
        }
        out
    }

    /// Contact geometry and relative velocities of every candidate at the state in `data`
    /// (after a kinematics pass), for the records.
    pub fn measure(
        &mut self,
        model: &Model,
        data: &mut Data,
        t: f64,
        q: &[f64],
        u: &[f64],
        cb: &dyn Callbacks,
    ) -> Result<()> {
        for con in &model.contacts {
            let pts = con.first..con.first + con.points();
            let s = self.warm_search.then(|| &mut self.search[pts.clone()]);
            // velocity level: the records hold no w̄
            crate::contact::contact_point_velocities(con, data, t, q, u, cb, &mut self.kin[pts], s)
                .map_err(|e| at_contact(e, &con.name, t))?;
        }
        Ok(())
    }

    /// The candidates' kinematics of the last [`MoreauJean::measure`] (or step midpoint).
    pub fn kinematics(&self) -> &[ContactKinematics] {
        &self.kin
    }
}
