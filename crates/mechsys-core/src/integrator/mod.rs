//! Time integrators behind one interface, one file per scheme.
//!
//! An [`OdeSystem`] gives `ẏ = f(t, y)`, the unit quaternions in y (which the smooth schemes
//! step on the rotation group, [`lie_group`]) and a projection back onto the constraint
//! manifold; a scheme advances it and calls an observer at each requested output time.
//! - [`rk4`]: classical fixed-step Runge–Kutta of order 4;
//! - [`dopri5`]: Dormand–Prince 5(4) with step-size control and dense output;
//! - [`radau5`]: the 3-stage Radau IIA method (order 5, L-stable) for stiff systems, at a fixed
//!   step or adaptive with error control and dense output;
//! - [`moreau_jean`]: time-stepping at velocity/impulse level for models with unilateral contacts
//!   (not an [`OdeSystem`] scheme: [`crate::simulate`] runs it directly);
//! - [`event_driven`]: smooth phases between located contact events, impacts and transition
//!   problems at each event (its own driver around a Dormand–Prince step).

pub mod dopri5;
pub mod event_driven;
pub mod events;
pub mod lie_group;
pub mod moreau_jean;
pub mod radau5;
pub mod rk4;
pub(crate) mod switching;

use serde::{Deserialize, Serialize};

use crate::error::Result;

/// A first-order system `ẏ = f(t, y)`.
pub trait OdeSystem {
    /// Dimension of y.
    fn dim(&self) -> usize;
    /// Evaluates `dy = f(t, y)`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()>;
    /// Offsets in y of the unit quaternions with `Q̇ = ½ Q ⊗ (0, ω_B)` (increasing). The smooth
    /// schemes step them on the rotation group ([`lie_group`]) so that they stay unit quaternions
    /// without renormalization; none by default (y is a vector space).
    fn quaternions(&self) -> &[usize] {
        &[]
    }
    /// Projects y at time t back onto its manifolds after a step (closed-loop constraints).
    fn project(&mut self, _t: f64, _y: &mut [f64]) -> Result<()> {
        Ok(())
    }
    /// Called once per accepted step at its end (t, y), after the outputs inside the step: the
    /// place to commit history variables (the sliders of dry-friction elements). It may add to y's
    /// bookkeeping entries but must not move the state.
    fn accepted(&mut self, _t: f64, _y: &mut [f64]) -> Result<()> {
        Ok(())
    }
    /// Whether a force law switched in a way the step's error estimate cannot see since the last
    /// call (a dry-friction slider that slipped and then stuck again: its history within the step
    /// is lost); resets. An adaptive scheme shrinks such a step until it is below its tolerance.
    fn switched(&mut self) -> bool {
        false
    }
    /// Number of switching functions: functions of (t, y) whose sign changes mark kinks of the
    /// right-hand side (a compliant contact's onset); the schemes end their steps there
    /// ([`switching`]).
    fn switches(&self) -> usize {
        0
    }
    /// The switching functions at (t, y) into `out` (`switches()` values).
    fn switching(&mut self, _t: f64, _y: &[f64], _out: &mut [f64]) -> Result<()> {
        Ok(())
    }
}

/// Called at each output time with the system and the state; `fresh` says the system's last `rhs`
/// call was at exactly this (t, y), so its workspace can be read without another evaluation.
pub type Observer<'a, S> = dyn FnMut(&mut S, f64, &[f64], bool) -> Result<()> + 'a;

/// Which scheme, with its settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum IntegratorKind {
    /// Fixed-step RK4.
    Rk4 {
        /// Step size (s).
        dt: f64,
    },
    /// Adaptive Dormand–Prince 5(4).
    Dopri5 {
        /// Relative tolerance.
        #[serde(default = "default_rtol")]
        rtol: f64,
        /// Absolute tolerance.
        #[serde(default = "default_atol")]
        atol: f64,
        /// Largest step (s); 0 means unlimited.
        #[serde(default)]
        max_step: f64,
        /// Initial step (s); 0 means automatic.
        #[serde(default)]
        first_step: f64,
    },
    /// Radau IIA (3 stages, order 5), implicit, for stiff systems: a fixed step `dt`, or
    /// adaptive steps under the tolerances `rtol`, `atol` (exactly one of `dt`, `rtol` is > 0).
    Radau5 {
        /// Fixed step size (s); 0 with an `rtol` (adaptive).
        #[serde(default)]
        dt: f64,
        /// Newton tolerance on the stage increments (relative) of the fixed-step mode; the
        /// adaptive mode derives its own from `rtol`.
        #[serde(default = "default_newton_tol")]
        newton_tol: f64,
        /// Relative tolerance of the adaptive mode; 0 means fixed steps.
        #[serde(default)]
        rtol: f64,
        /// Absolute tolerance of the adaptive mode.
        #[serde(default = "default_atol")]
        atol: f64,
        /// Largest adaptive step (s); 0 means unlimited.
        #[serde(default)]
        max_step: f64,
        /// Initial adaptive step (s); 0 means automatic.
        #[serde(default)]
        first_step: f64,
    },
    /// Moreau–Jean time-stepping for unilateral contacts, impacts and friction ([`moreau_jean`]).
    MoreauJean {
        /// Step size (s).
        dt: f64,
        /// The contact solver.
        #[serde(default = "crate::solver::Method::nsgs")]
        solver: crate::solver::Method,
        /// On a Painlevé situation (a sliding point whose contact problem has no solution), go on
        /// with the impulse the step's problem gives (an impact without collision, on record as
        /// a `painleve` event and a warning) instead of raising.
        #[serde(default = "default_true")]
        continue_on_painleve: bool,
        /// Project the contacts that stay closed back onto their contours after each step
        /// ([`moreau_jean`]'s position projection): stops the O(h) sinking of contacts rolling
        /// or sliding along curved contours; it moves positions without a force, so the energy
        /// balance then carries the projection's (small) work.
        #[serde(default)]
        project: bool,
        /// Solve independent contact islands on several threads (the impulses are the same
        /// either way).
        #[serde(default = "default_true")]
        parallel: bool,
    },
    /// Event-driven integration of contact models ([`event_driven`]).
    EventDriven(event_driven::Options),
}

impl IntegratorKind {
    /// The step of a fixed-step scheme (RK4, Moreau–Jean, Radau5 without `rtol`), else None.
    pub fn fixed_step(&self) -> Option<f64> {
        match *self {
            IntegratorKind::Rk4 { dt } | IntegratorKind::MoreauJean { dt, .. } => Some(dt),
            IntegratorKind::Radau5 { dt, rtol: 0.0, .. } => Some(dt),
            _ => None,
        }
    }
}

fn default_true() -> bool {
    true
}

fn default_rtol() -> f64 {
    1e-8
}
fn default_atol() -> f64 {
    1e-10
}
fn default_newton_tol() -> f64 {
    1e-10
}

/// Counters of a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (adaptive schemes).
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
    /// Jacobian evaluations (implicit schemes).
    pub jacobians: usize,
    /// Contact events (event-driven scheme).
    #[serde(default)]
    pub events: usize,
    /// Transitions solved (event-driven scheme: impacts, transition problems, checks of the
    /// switches) and the wall time they took (s), for the cost per transition.
    #[serde(default)]
    pub transitions: usize,
    /// See `transitions`.
    #[serde(default)]
    pub transition_seconds: f64,
}

/// Runs the chosen scheme from (t0, y0) through all `t_out` (increasing, ≥ t0).
pub fn integrate<S: OdeSystem>(
    kind: &IntegratorKind,
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    obs: &mut Observer<'_, S>,
) -> Result<Stats> {
    match kind {
        IntegratorKind::Rk4 { dt } => rk4::integrate(sys, t0, y0, *dt, t_out, obs),
        IntegratorKind::Dopri5 { rtol, atol, max_step, first_step } => {
            dopri5::integrate(sys, t0, y0, t_out, *rtol, *atol, *max_step, *first_step, obs)
        }
        IntegratorKind::Radau5 { .. } => radau5::integrate(kind, sys, t0, y0, t_out, obs),
        IntegratorKind::MoreauJean { .. } | IntegratorKind::EventDriven(_) => Err(crate::error::Error::Settings(
            "integrator: Moreau–Jean and the event-driven scheme are for contact models; simulate() runs them".into(),
        )),
    }
}

/// The smallest step an adaptive scheme may take at time `t` of a run over `[t0, t_end]`: a few
/// units of round-off of t (a step below it no longer advances the time). Not relative to the
/// span: a floor of 1e-14 (t_end − t0) stopped long runs of fast systems (a 1000 s run at
/// t = 1.9 s); near t = 0 a millionth of the span keeps it above zero.
pub(crate) fn step_floor(t: f64, t0: f64, t_end: f64) -> f64 {
    10.0 * f64::EPSILON * t.abs().max(1e-6 * (t_end - t0).abs()).max(f64::MIN_POSITIVE)
}

/// Calls the observer at every output time of an accepted step `[t, t + h]` that has not been
/// served yet (from index `next`): at the step's end with its end state `y_new`, before it with
/// the scheme's continuous extension `dense(θ, out)` (θ ∈ [0, 1)) projected onto the manifolds.
/// Returns the next output index. One place for the adaptive schemes' outputs.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step_outputs<S: OdeSystem>(
    sys: &mut S,
    obs: &mut Observer<'_, S>,
    t_out: &[f64],
    mut next: usize,
    t: f64,
    h: f64,
    y_new: &[f64],
    yout: &mut [f64],
    mut dense: impl FnMut(f64, &mut [f64]),
) -> Result<usize> {
    let t_new = t + h;
    while next < t_out.len() && t_out[next] <= t_new + 1e-12 * t_new.abs().max(1.0) {
        let to = t_out[next];
        if to >= t_new {
            obs(sys, to, y_new, false)?;
        } else {
            dense((to - t) / h, yout);
            sys.project(to, yout)?;
            obs(sys, to, yout, false)?;
        }
        next += 1;
    }
    Ok(next)
}

/// Fails with a solver error if y holds a NaN or inf, naming the time.
pub(crate) fn check_finite(t: f64, y: &[f64]) -> Result<()> {
    if y.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(crate::Error::Solver(format!(
            "the solution diverged (non-finite state) at t = {t:.6} s; reduce the step size or check the model"
        )))
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_lie;
