//! Complementarity problems of contact mechanics (section 2.5): linear complementarity problems
//! and friction-contact problems, with the solvers that time-stepping and event-driven schemes share.
//!
//! # Problems
//!
//! - [`Lcp`]: find `z ≥ 0` with `w = M z + q ≥ 0` and `zᵀw = 0`. Event-driven schemes pose their
//!   normal-contact transition problems this way (`λ_N ≥ 0 ⊥ g̈_N ≥ 0`, Signorini's corner law of
//!   fig. 2.33 on acceleration level).
//! - [`FrictionContact`]: `n` contacts in dimension `d = 2` (normal, tangent) or `d = 3` (normal, two
//!   tangents) with local velocities `u = W r + q`, `W` the Delassus matrix (symmetric positive
//!   semidefinite), `r = [r_N, r_T]` per contact (impulses for Moreau–Jean, forces on acceleration
//!   level) and a friction coefficient `μ` per contact. A solution has `r` in the Coulomb cone
//!   `K_μ = {|r_T| ≤ μ r_N}` and, per contact, one of
//!   - open: `r = 0`, `u_N ≥ 0` (Signorini, fig. 2.33);
//!   - stick: `u_N = 0`, `|r_T| ≤ μ r_N`, `u_T = 0` (eq. 2.200, first line);
//!   - slip: `u_N = 0`, `r_T = -μ r_N u_T/|u_T|` (eq. 2.200, sliding lines; in 3-D the friction force
//!     opposes the sliding velocity).
//!
//!   Equivalently (De Saxcé) `K_μ ∋ r ⊥ û ∈ K_μ*` with the modified velocity
//!   `û = u + μ |u_T| e_N`. The text's friction reserve `μ λ_N − |λ_T|` is
//!   [`FrictionContact::friction_reserve`]; the open/stick/slip classification is
//!   [`FrictionContact::contact_state`]. Which `μ` a caller puts in (the static `μ0` of a sticking
//!   contact or the sliding `μ`, eq. 2.201) is the caller's decision; the solver sees one coefficient.
//!
//! # Solvers
//!
//! One call, [`solve`]`(problem, method, x, warm_start, workspace)`, with the method chosen by
//! [`Method`]:
//!
//! | method | [`Lcp`] | [`FrictionContact`] |
//! | --- | --- | --- |
//! | [`Method::Lemke`] | complementary pivoting ([`lemke`]), exact | `d = 2`: exact through the LCP of [`friction_lcp`]; `d = 3`: pyramid with `facets` sides |
//! | [`Method::Nsgs`] | projected Gauss–Seidel | nonsmooth Gauss–Seidel with exact local solves ([`nsgs`]) |
//! | [`Method::Newton`] | — | semismooth Newton on the Alart–Curnier function with a regularized Delassus matrix ([`newton`]) |
//! | [`Method::Apgd`] | — | accelerated projected gradient with adaptive restart on the De Saxcé velocity ([`apgd`]) |
//! | [`Method::Auto`] | Lemke | Newton up to [`AutoOptions::newton_max_unknowns`] unknowns (sweeps finish where it stalls), NSGS above |
//!
//! Every solve returns a [`Report`]; its residual is recomputed from the returned solution with
//! the merit described at [`Report::residual`], whatever the method. Failing to reach the
//! tolerance is reported (`converged: false`), not raised; what raises is bad input and Lemke's
//! ray termination (no solution).
//!
//! All scratch lives in a [`Workspace`], sized once with [`Workspace::reserve`] for the largest
//! problem and method a caller will use; a solve allocates nothing.
//!
//! # Example
//!
//! ```
//! use mechsys_core::solver::{solve, Delassus, FrictionContact, Method, Workspace, ContactState};
//! // one planar contact: a block of 1 kg pushed sideways (u_T = 2 m/s) while pressed down
//! let problem = FrictionContact::new(2, Delassus::Dense(vec![1.0, 0.0, 0.0, 1.0]), vec![-1.0, 2.0], vec![0.5])?;
//! let method = Method::nsgs();
//! let mut ws = Workspace::for_problem(&problem, &method)?;
//! let mut r = vec![0.0; 2];
//! let report = solve(&problem, &method, &mut r, false, &mut ws)?;
//! assert!(report.converged);
//! assert!((r[0] - 1.0).abs() < 1e-12 && (r[1] + 0.5).abs() < 1e-12); // slips: r_T = -μ r_N
//! assert_eq!(problem.contact_state(0, &r, 1e-9)?, ContactState::Slip);
//! # Ok::<(), mechsys_core::Error>(())
//! ```
//!
//! Literature (for the methods, not the code): Cottle, Pang & Stone, *The Linear Complementarity
//! Problem* (Lemke's method, lexicographic degeneracy resolution); Stewart & Trinkle (1996) and
//! Anitescu & Potra (1997) for the friction LCP; Moreau (1988) and Jean (1999) for nonsmooth
//! Gauss–Seidel; Alart & Curnier (1991) for the augmented-Lagrangian Newton; De Saxcé & Feng (1991)
//! for the modified velocity; Acary & Brogliato, *Numerical Methods for Nonsmooth Dynamical Systems*
//! (2008), for the merit function.

pub(crate) mod anderson;
pub mod apgd;
pub mod fixtures;
pub mod friction_lcp;
pub mod lemke;
pub mod newton;
pub mod nsgs;
mod problem;
mod workspace;

pub(crate) use problem::{check_local, check_wnn, classify, contact_residual_sq};
pub use problem::{
    project_onto_cone, BlockDelassus, BlockDelassusBuilder, ContactState, Delassus, FrictionContact, Lcp,
};
pub use workspace::Workspace;

use workspace::Needs;

use serde::{Deserialize, Serialize};

use crate::ensure;
use crate::error::Result;

/// Outcome of a solve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Pivots (Lemke), sweeps (Gauss–Seidel) or Newton iterations.
    pub iterations: usize,
    /// Scale-aware merit of the returned solution, recomputed after solving.
    ///
    /// For an LCP, `‖min(M_ii z_i, w_i)‖₂ / (1 + ‖q‖₂)` (the natural map in `w` units; `M_ii` is
    /// replaced by 1 where it is not positive). For a friction-contact problem,
    /// `‖(r_i − proj_{K_μi}(r_i − ρ_i û_i)) / ρ_i‖₂ / (1 + ‖q‖₂)` with `ρ_i = 1/W_NN,i` and the
    /// modified velocity `û`, i.e. the violation of the Signorini–Coulomb conditions in velocity
    /// units relative to the free velocity. Zero exactly at a solution.
    pub residual: f64,
    /// Whether the method's stopping test was met. Gauss–Seidel and Newton: `residual ≤ tol`.
    /// Lemke: the pivoting ended in a complementary basis (for `d = 3` this solves the pyramid
    /// approximation exactly; `residual` then measures the facet error against the round cone).
    pub converged: bool,
}

impl Report {
    /// This report of a method that went on from `first`'s solution, counting both's iterations.
    pub fn after(self, first: &Report) -> Report {
        Report { iterations: first.iterations + self.iterations, ..self }
    }
}

/// Lemke's method ([`lemke`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LemkeOptions {
    /// Pivot-column entries `≤ pivot_tol · max(1, max|M_ij|)` count as zero.
    pub pivot_tol: f64,
    /// Cap on pivots; `None` means `50 (n + 1)` for an LCP of size `n`.
    pub max_pivots: Option<usize>,
    /// Sides of the friction pyramid that replaces the cone for `d = 3` (3 to
    /// [`friction_lcp::MAX_FACETS`]).
    pub facets: usize,
}

impl Default for LemkeOptions {
    fn default() -> Self {
        Self { pivot_tol: 1e-12, max_pivots: None, facets: 8 }
    }
}

/// (Nonsmooth) projected Gauss–Seidel ([`nsgs`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NsgsOptions {
    /// Stop when the residual of [`Report::residual`] is at most this.
    pub tol: f64,
    /// Cap on sweeps.
    pub max_iter: usize,
    /// Relaxation `ω ∈ (0, 2)`: `r_i ← ω r_i,local + (1 − ω) r_i`; under 1 it damps, over 1 it
    /// extrapolates (projected onto the cone, and back to 1 for the rest of the solve when a
    /// sweep changes the impulses more than the one before).
    pub relaxation: f64,
    /// Anderson acceleration of the sweeps (friction contact, `ω = 1`): the number of past
    /// sweeps combined, `0` (off) to 8. Each sweep's result is replaced by
    /// the combination of the last ones whose changes cancel best, restarting whenever a sweep
    /// changes the impulses more than the one before, and pausing for 32 plain sweeps when the
    /// change stalls (`anderson::RETRY`). On the pour of 100 spheres (tol 1e-4) the sweeps per step
    /// fell from 107 to 37–45 (mean over the run; the pour is chaotic).
    pub anderson: usize,
    /// Stall test (friction contact): the length of its first window of sweeps, 0 for none.
    /// When the smallest change of a sweep stops halving from one window to the next (windows of
    /// `stall`, `stall`, `2 stall`, `4 stall`, … sweeps; `nsgs::StallWatch`), the sweeps are
    /// cycling rather than converging, and from then on they are under-relaxed: `ω ← 0.9 ω` at
    /// each stall, down to 0.5, without Anderson acceleration. Set by [`Method::Auto`]
    /// ([`AUTO_SWEEP_STALL`]).
    pub stall: usize,
}

impl Default for NsgsOptions {
    fn default() -> Self {
        Self { tol: 1e-10, max_iter: 10_000, relaxation: 1.0, anderson: 0, stall: 0 }
    }
}

/// Semismooth Newton on the Alart–Curnier function ([`newton`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NewtonOptions {
    /// Stop when the residual of [`Report::residual`] is at most this.
    pub tol: f64,
    /// Cap on Newton iterations (a fallback Gauss–Seidel sweep counts as one).
    pub max_iter: usize,
    /// Relative regularization `ε_i / W_NN,i` of the Delassus matrix in the Newton direction
    /// (see [`newton`]); 0 for the plain Jacobian.
    pub regularization: f64,
    /// Reuse the last solve's factorization while the projection derivatives are unchanged
    /// (successive steps of a resting contact set), as a chord direction checked by the line
    /// search.
    pub reuse: bool,
    /// Give up (unconverged) once this many iterations have passed without halving the residual;
    /// 0: never. Set by [`Method::Auto`] ([`AUTO_NEWTON_STALL`]), whose sweeps then go on.
    #[serde(skip)]
    pub stall: usize,
    /// A Moreau–Jean problem of more unknowns than this whose contacts are all on free bodies
    /// and the ground (a pile) takes its Newton direction in body space: one sparse
    /// factorization in the bodies' velocities, 6 per body, instead of a dense one of the
    /// contact Jacobian (see `integrator::moreau_jean::sparse::body_newton`). The iterates are
    /// the same up to round-off.
    pub body_space_above: usize,
}

/// [`NewtonOptions::body_space_above`]'s default: the size up to which [`Method::Auto`] takes
/// Newton's dense factorization.
pub const BODY_SPACE_ABOVE: usize = 480;

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            max_iter: 200,
            regularization: 1e-4,
            reuse: true,
            stall: 0,
            body_space_above: BODY_SPACE_ABOVE,
        }
    }
}

/// Iterations without halving the residual after which [`Method::Auto`]'s Newton gives up and
/// its sweeps go on ([`AutoPlan::rescue`]). On a pour of 36 spheres (tol 1e-6) the Newton solves
/// that converged took 2 iterations on average and at most 78, the longest of them stalling for
/// up to 30 before converging; the 42 that never converged had stalled by their 20th and then
/// ran to the cap of 200, each with fresh factorizations.
pub const AUTO_NEWTON_STALL: usize = 30;

/// The first window of [`Method::Auto`]'s stall test on its Gauss–Seidel sweeps (problems above
/// Newton's size, and the rescue of a Newton solve): see [`NsgsOptions::stall`]. Over eight starts
/// of the 100-sphere pour, 256 and 1024 both left no step unconverged (one before), but 256 also
/// damped slowly converging steps of the 1000-sphere pour and slowed them; 1024 passes any steady
/// rate of at least 2000× in 10 000 sweeps.
pub const AUTO_SWEEP_STALL: usize = 1024;

/// The relative regularization `R_i / W_NN,i` (compliant Signorini layers, on every contact of a
/// problem) from which [`Method::Auto`] takes Gauss–Seidel on problems of any size instead of
/// Newton: regularized by a hundredth of its diagonal the problem is well conditioned and its
/// sweeps converge in tens (the 100-sphere pour on layers of 1e6 N/m, 5-10 %: Newton on its small
/// islands made the run three times as long).
pub const AUTO_SOFT: f64 = 1e-2;

/// Accelerated projected gradient ([`apgd`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ApgdOptions {
    /// Stop when the residual of [`Report::residual`] is at most this.
    pub tol: f64,
    /// Cap on iterations (each one product with `W`, more while the step size is searched).
    pub max_iter: usize,
}

impl Default for ApgdOptions {
    fn default() -> Self {
        Self { tol: 1e-10, max_iter: 10_000 }
    }
}

/// Gauss–Seidel sweeps [`Method::Auto`] takes before it turns to Newton. Four: a warm
/// step that needs one or two still finishes in them, and a step that does not is handed to
/// Newton before more sweeps are wasted (instruction counts on the box stack at dt 1e-3 and
/// 1e-2 were lowest at 4 of 1, 4 and 10).
pub const AUTO_SWEEPS: usize = 4;

/// Gauss–Seidel sweeps [`Method::Auto`] takes from a cold start (all impulses zero) before it
/// turns to Newton: nearer the solution, Newton needs fewer fresh factorizations (the first step
/// of the box stack and of the pyramid cost 2.9 and 1.3 times fewer instructions than with 4).
pub const AUTO_COLD_SWEEPS: usize = 10;

/// Sweeps worth one fresh Newton factorization are about `m² / AUTO_SWEEPS_PER_FACTOR` for `m`
/// unknowns (the profile LU of the 408-unknown pyramid problem costs 12.7 M instructions, one
/// sweep about 70 k: 180 sweeps). Without a factorization to reuse [`Method::Auto`] sweeps up to
/// that many before Newton until Newton has factored a problem in the workspace (Anderson-accelerated
/// from a cold start).
pub const AUTO_SWEEPS_PER_FACTOR: usize = 1500;

/// [`AUTO_COLD_SWEEPS`] if the warm start `x` is all zeros, else [`AUTO_SWEEPS`].
pub fn auto_sweeps(x: &[f64]) -> usize {
    if x.iter().all(|v| *v == 0.0) {
        AUTO_COLD_SWEEPS
    } else {
        AUTO_SWEEPS
    }
}

/// The sweeps of [`Method::Auto`] stop early only below this fraction of the tolerance; between
/// it and the tolerance Newton polishes (a resting box stack at dt 1e-3: 1.19 G instructions
/// over 2 s against 2.29 G when the sweeps stopped at the tolerance itself).
pub const AUTO_SWEEP_MARGIN: f64 = 0.1;

/// The automatic choice ([`Method::Auto`]): the method by the problem's shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AutoOptions {
    /// Stop when the residual of [`Report::residual`] is at most this.
    pub tol: f64,
    /// Friction-contact problems with at most this many unknowns (`d n`) go to the regularized
    /// semismooth Newton method (a dense factorization, `O((d n)³)` but reused while the contact
    /// set rests: converges on stacks and other statically indeterminate supports in a few
    /// iterations); larger ones to nonsmooth Gauss–Seidel (`O(d n)` per sweep).
    pub newton_max_unknowns: usize,
    /// Cap on Newton iterations.
    pub newton_max_iter: usize,
    /// Cap on Gauss–Seidel sweeps.
    pub nsgs_max_iter: usize,
    /// Anderson acceleration of Gauss–Seidel on problems above `newton_max_unknowns`
    /// ([`NsgsOptions::anderson`]).
    pub nsgs_anderson: usize,
}

/// Anderson depth of [`Method::Auto`]'s Gauss–Seidel on large problems (on the settling pile of
/// 100 spheres at tol 1e-4, plain NSGS with depths 2 to 8 all took about 58 sweeps a step against
/// 127 without; depth 2 left more solves stalling than 3 or 4).
pub const AUTO_ANDERSON: usize = 4;

impl Default for AutoOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            newton_max_unknowns: 480,
            newton_max_iter: 200,
            nsgs_max_iter: 10_000,
            nsgs_anderson: AUTO_ANDERSON,
        }
    }
}

/// What [`Method::Auto`] does with one friction-contact problem ([`AutoOptions::plan`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoPlan {
    /// Gauss–Seidel sweeps first (before Newton), stopping early only at
    /// [`AUTO_SWEEP_MARGIN`] times the tolerance; their report stands if they converge.
    pub sweeps: Option<NsgsOptions>,
    /// The method for the rest ([`AutoOptions::pick`]).
    pub then: Method,
    /// Where `then` is Newton and it ends above the tolerance: Gauss–Seidel (Anderson-accelerated,
    /// up to [`AutoOptions::nsgs_max_iter`] sweeps) from Newton's last iterate. On piles, whose
    /// contact problems are far more indeterminate than a stack's, the regularized Newton can
    /// stall at its iteration cap (36 spheres poured at tol 1e-6: 9 % of the steps, residuals up
    /// to 7e-3), where sweeps, slow but steady, finish.
    pub rescue: Option<NsgsOptions>,
}

/// One stage of an [`AutoPlan`]: Gauss–Seidel sweeps, or another method.
#[derive(Debug, Clone, Copy)]
pub enum Stage<'a> {
    /// Gauss–Seidel with these settings.
    Sweeps(&'a NsgsOptions),
    /// This method (Newton, for Auto).
    Solve(&'a Method),
}

impl AutoPlan {
    /// Runs the plan through `stage` (the caller's solver for each kind of stage: blocks, or the
    /// factored operator for sweeps): the sweeps, then `then` unless they converged, then the
    /// rescue unless that converged; the report counts every stage's iterations.
    pub fn run<E>(
        &self,
        mut stage: impl FnMut(Stage<'_>) -> std::result::Result<Report, E>,
    ) -> std::result::Result<Report, E> {
        let Some(sweeps) = &self.sweeps else {
            return match &self.then {
                Method::Nsgs(o) => stage(Stage::Sweeps(o)),
                m => stage(Stage::Solve(m)),
            };
        };
        let first = stage(Stage::Sweeps(sweeps))?;
        if first.converged {
            return Ok(first);
        }
        let second = stage(Stage::Solve(&self.then))?.after(&first);
        match &self.rescue {
            Some(rescue) if !second.converged => Ok(stage(Stage::Sweeps(rescue))?.after(&second)),
            _ => Ok(second),
        }
    }
}

impl AutoOptions {
    /// The plan for a friction-contact problem of `unknowns` unknowns warm-started from `x`.
    ///
    /// Before Newton a few Gauss–Seidel sweeps ([`auto_sweeps`]): they finish a warm-started
    /// step that needs little and bring a cold start near enough for Newton's few steps. They
    /// must get well below the tolerance: a step left just under it passes its error on to the
    /// next step's free velocity, which then starts above the tolerance (on a resting stack every
    /// other step went to Newton).
    pub fn plan(&self, unknowns: usize, x: &[f64], held: bool) -> AutoPlan {
        let then = self.pick(unknowns);
        let newton = matches!(then, Method::Newton(_));
        let sweeps = newton.then(|| {
            let few = auto_sweeps(x);
            // until Newton has factored a problem in this workspace (`held`), its first step would
            // pay a fresh factorization: sweeps up to about its cost come first. From a cold
            // start they are Anderson-accelerated; from a warm one plain, so that where they fail
            // Newton starts from a Gauss–Seidel iterate (from an accelerated one, on a pyramid of
            // spheres in a box at tol 1e-9, it stalled and the rescue ended at 1.02e-9). Once a
            // factorization is held the few sweeps as before: a workspace whose problems reach
            // Newton and change size (the islands of a pile) lost more to the extra sweeps than
            // it saved (1000-sphere pour: 230 -> 333 s/s, unconverged steps 2.7 -> 5.7 %)
            let budget = if held { few } else { few.max(unknowns * unknowns / AUTO_SWEEPS_PER_FACTOR) };
            let cold = few == AUTO_COLD_SWEEPS;
            let anderson = if budget > few && cold { self.nsgs_anderson } else { 0 };
            NsgsOptions { tol: AUTO_SWEEP_MARGIN * self.tol, max_iter: budget, anderson, ..Default::default() }
        });
        let rescue = newton.then(|| self.sweeps());
        AutoPlan { sweeps, then, rescue }
    }

    /// Its Gauss–Seidel settings (problems above Newton's size, and the rescue of a Newton solve;
    /// all of a problem regularized by at least [`AUTO_SOFT`], whose sweeps converge fast).
    pub fn sweeps(&self) -> NsgsOptions {
        let (tol, max_iter, anderson) = (self.tol, self.nsgs_max_iter, self.nsgs_anderson);
        NsgsOptions { tol, max_iter, anderson, stall: AUTO_SWEEP_STALL, ..Default::default() }
    }

    /// The method it takes for a friction-contact problem of `unknowns` unknowns.
    pub fn pick(&self, unknowns: usize) -> Method {
        if unknowns <= self.newton_max_unknowns {
            Method::Newton(NewtonOptions {
                tol: self.tol,
                max_iter: self.newton_max_iter,
                stall: AUTO_NEWTON_STALL,
                ..Default::default()
            })
        } else {
            Method::Nsgs(self.sweeps())
        }
    }
}

/// The solver and its settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Method {
    /// Lemke's complementary pivoting (LCPs; planar friction exactly, spatial with a pyramid).
    Lemke(LemkeOptions),
    /// Projected Gauss–Seidel (LCP) or nonsmooth Gauss–Seidel (friction contact).
    Nsgs(NsgsOptions),
    /// Semismooth Newton (friction contact only).
    Newton(NewtonOptions),
    /// Accelerated projected gradient (friction contact only).
    Apgd(ApgdOptions),
    /// Newton for small friction-contact problems (after up to [`AUTO_SWEEPS`] Gauss–Seidel
    /// sweeps, [`AUTO_COLD_SWEEPS`] from a cold start, more until Newton has factored a problem
    /// in the workspace ([`AUTO_SWEEPS_PER_FACTOR`]), and followed by sweeps if it stalls: see
    /// [`AutoPlan`]; the report counts every stage), Gauss–Seidel for large ones, Lemke for LCPs
    /// ([`AutoOptions::pick`]).
    Auto(AutoOptions),
}

impl Method {
    /// Lemke with default options.
    pub fn lemke() -> Self {
        Method::Lemke(LemkeOptions::default())
    }
    /// Gauss–Seidel with default options.
    pub fn nsgs() -> Self {
        Method::Nsgs(NsgsOptions::default())
    }
    /// Newton with default options.
    pub fn newton() -> Self {
        Method::Newton(NewtonOptions::default())
    }
    /// APGD with default options.
    pub fn apgd() -> Self {
        Method::Apgd(ApgdOptions::default())
    }
    /// The automatic choice with default options.
    pub fn auto() -> Self {
        Method::Auto(AutoOptions::default())
    }

    pub(crate) fn validate(&self) -> Result<()> {
        // (an infinite tolerance, `tol = inf` in a model file, would pass `> 0` and stop every
        // solve at once with its warm start)
        let tol_ok = |tol: f64| tol > 0.0 && tol.is_finite();
        match self {
            Method::Lemke(o) => {
                ensure!(
                    o.pivot_tol >= 0.0 && o.pivot_tol < 1.0,
                    Settings,
                    "Lemke: pivot_tol must be in [0, 1), got {}",
                    o.pivot_tol
                );
                ensure!(o.max_pivots != Some(0), Settings, "Lemke: max_pivots must be > 0");
                ensure!(
                    (3..=friction_lcp::MAX_FACETS).contains(&o.facets),
                    Settings,
                    "Lemke: facets must be in 3..={}, got {}",
                    friction_lcp::MAX_FACETS,
                    o.facets
                );
            }
            Method::Nsgs(o) => {
                ensure!(tol_ok(o.tol), Settings, "NSGS: tol must be a finite number > 0, got {}", o.tol);
                ensure!(o.max_iter > 0, Settings, "NSGS: max_iter must be > 0");
                ensure!(
                    o.relaxation > 0.0 && o.relaxation < 2.0,
                    Settings,
                    "NSGS: relaxation must be in (0, 2), got {}",
                    o.relaxation
                );
                ensure!(
                    o.anderson <= anderson::MAX_DEPTH,
                    Settings,
                    "NSGS: anderson (sweeps combined) must be in 0..={}, got {}",
                    anderson::MAX_DEPTH,
                    o.anderson
                );
            }
            Method::Auto(o) => {
                ensure!(tol_ok(o.tol), Settings, "auto solver: tol must be a finite number > 0, got {}", o.tol);
                ensure!(
                    o.newton_max_iter > 0 && o.nsgs_max_iter > 0,
                    Settings,
                    "auto solver: newton_max_iter and nsgs_max_iter must be > 0"
                );
                ensure!(
                    o.nsgs_anderson <= anderson::MAX_DEPTH,
                    Settings,
                    "auto solver: nsgs_anderson (sweeps combined) must be in 0..={}, got {}",
                    anderson::MAX_DEPTH,
                    o.nsgs_anderson
                );
            }
            Method::Apgd(o) => {
                ensure!(tol_ok(o.tol), Settings, "APGD: tol must be a finite number > 0, got {}", o.tol);
                ensure!(o.max_iter > 0, Settings, "APGD: max_iter must be > 0");
            }
            Method::Newton(o) => {
                ensure!(tol_ok(o.tol), Settings, "Newton: tol must be a finite number > 0, got {}", o.tol);
                ensure!(o.max_iter > 0, Settings, "Newton: max_iter must be > 0");
                ensure!(
                    o.regularization >= 0.0 && o.regularization < 1.0,
                    Settings,
                    "Newton: regularization must be in [0, 1), got {}",
                    o.regularization
                );
            }
        }
        Ok(())
    }
}

/// A problem [`solve`] accepts: [`Lcp`] or [`FrictionContact`].
pub trait Problem: sealed::Sealed {
    /// Number of unknowns (`n` for an LCP, `d·n` for a friction-contact problem).
    fn unknowns(&self) -> usize;
    /// Checks sizes and values; the message names the offending entry.
    fn validate(&self) -> Result<()>;
}

mod sealed {
    /// Dispatch to the problem's solvers; outside the public API so that only this module's
    /// problems implement [`super::Problem`].
    pub trait Sealed {
        fn needs(&self, method: &super::Method) -> crate::error::Result<super::Needs>;
        fn run(
            &self,
            method: &super::Method,
            x: &mut [f64],
            ws: &mut super::Workspace,
        ) -> crate::error::Result<super::Report>;
    }
}

impl Problem for Lcp {
    fn unknowns(&self) -> usize {
        self.size()
    }
    fn validate(&self) -> Result<()> {
        self.check()
    }
}

impl sealed::Sealed for Lcp {
    fn needs(&self, method: &Method) -> Result<Needs> {
        let n = self.size();
        match method {
            Method::Lemke(_) => Ok(Needs { u: n, lemke: n, ..Needs::default() }),
            Method::Nsgs(_) => Ok(Needs { u: n, ..Needs::default() }),
            Method::Newton(_) | Method::Apgd(_) => Err(not_for_lcps(method)),
            Method::Auto(_) => self.needs(&Method::lemke()),
        }
    }
    fn run(&self, method: &Method, x: &mut [f64], ws: &mut Workspace) -> Result<Report> {
        match method {
            Method::Auto(_) => lemke::solve_lcp(self, &LemkeOptions::default(), x, ws),
            Method::Lemke(o) => lemke::solve_lcp(self, o, x, ws),
            Method::Nsgs(o) => nsgs::solve_lcp(self, o, x, ws),
            Method::Newton(_) | Method::Apgd(_) => Err(not_for_lcps(method)),
        }
    }
}

impl Problem for FrictionContact {
    fn unknowns(&self) -> usize {
        self.dim * self.contacts()
    }
    fn validate(&self) -> Result<()> {
        self.check()
    }
}

impl sealed::Sealed for FrictionContact {
    fn needs(&self, method: &Method) -> Result<Needs> {
        let n = self.contacts();
        let m = self.dim * n;
        Ok(match method {
            Method::Lemke(o) => {
                let nl = (friction_lcp::directions(self.dim, o) + 2) * n;
                let dense = if matches!(self.w, Delassus::Blocks(_)) { m } else { 0 };
                Needs { u: m, diag: n, lemke: nl, lcp: nl, dense, newton: 0, apgd: 0, anderson: 0 }
            }
            Method::Nsgs(o) => {
                Needs { u: m, diag: n, anderson: if o.anderson > 0 { m } else { 0 }, ..Needs::default() }
            }
            Method::Newton(_) => Needs { u: m, diag: n, newton: m, ..Needs::default() },
            Method::Apgd(_) => Needs { u: m, diag: n, apgd: m, ..Needs::default() },
            Method::Auto(o) => {
                // (Newton's needs and room for the rescue's acceleration)
                let mut needs = self.needs(&o.pick(m))?;
                if o.nsgs_anderson > 0 {
                    needs.anderson = m;
                }
                return Ok(needs);
            }
        })
    }
    fn run(&self, method: &Method, x: &mut [f64], ws: &mut Workspace) -> Result<Report> {
        match method {
            Method::Auto(o) => o.plan(self.unknowns(), x, ws.newton.holds_factorization()).run(|stage| match stage {
                Stage::Sweeps(s) => nsgs::solve_fc(self, s, x, ws),
                Stage::Solve(m) => self.run(m, x, ws),
            }),
            Method::Lemke(o) => friction_lcp::solve(self, o, x, ws),
            Method::Nsgs(o) => nsgs::solve_fc(self, o, x, ws),
            Method::Newton(o) => newton::solve(self, o, x, ws),
            Method::Apgd(o) => apgd::solve(self, o, x, ws),
        }
    }
}

fn not_for_lcps(method: &Method) -> crate::Error {
    let name = if matches!(method, Method::Apgd(_)) { "APGD" } else { "Newton" };
    crate::Error::Settings(format!("solver: {name} solves friction-contact problems; solve an LCP with Lemke or Nsgs"))
}

/// Solves `problem` with `method` into `x`.
///
/// `x` has [`Problem::unknowns`] entries; with `warm_start` it holds the initial guess (e.g. the
/// previous step's impulses; Lemke ignores it), otherwise it is zeroed first. `workspace` must have
/// been sized for this problem size and method ([`Workspace::reserve`]); no allocation happens here.
///
/// Errors: invalid input (sizes, non-finite values, `μ < 0`, `W_NN ≤ 0`, a method that does not
/// apply to the problem, a workspace too small) and Lemke's ray termination. Not reaching the
/// tolerance is not an error: see [`Report::converged`].
pub fn solve<P: Problem + ?Sized>(
    problem: &P,
    method: &Method,
    x: &mut [f64],
    warm_start: bool,
    workspace: &mut Workspace,
) -> Result<Report> {
    method.validate()?;
    problem.validate()?;
    let n = problem.unknowns();
    ensure!(
        x.len() == n,
        Settings,
        "solver: the solution vector has {} entries, the problem has {n} unknowns",
        x.len()
    );
    if warm_start {
        if let Some(k) = x.iter().position(|v| !v.is_finite()) {
            return Err(crate::Error::Settings(format!("solver: warm start entry {k} is not finite ({})", x[k])));
        }
    } else {
        x.fill(0.0);
    }
    workspace.check(&problem.needs(method)?)?;
    problem.run(method, x, workspace)
}

#[cfg(test)]
mod bank;
#[cfg(test)]
mod tests;
