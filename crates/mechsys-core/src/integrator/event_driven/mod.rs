//! Event-driven integration of contact models (section 2.5): the motion is smooth between events,
//! and every change of the contact structure is an event located in time.
//!
//! - **Smooth phases.** Each candidate point is open, sticking or slipping. With the set fixed the
//!   equations are smooth: a closed point adds `g̈_N = w_Nᵀ u̇ + w̄_N = 0`, a sticking one also
//!   `g̈_T = W_Tᵀ u̇ + w̄_T = 0`, a slipping one the force `λ_T = −µ(|ġ_T|) λ_N ŝ` along its sliding
//!   direction ŝ (eqs. 2.110–2.132, 2.200, 2.201). The forces solve a small linear system; the
//!   state (with the energy dissipated by sliding and the time integrals of the contact forces) is
//!   integrated by Dormand–Prince with error control.
//! - **Events** (roots located on the continuous extension of the step, Illinois' regula falsi):
//!   an open point's gap `g_N` reaches zero; a closed point's normal force `λ_N` reaches zero,
//!   or its `ġ_N` jumps below `−10 velocity_tol` (a contour whose normal jumps, a mesh's concave
//!   edge: the point starts to approach its new face, an impact at the event);
//!   a sticking point's friction reserve `µ0 λ_N − |λ_T|` reaches zero; a slipping point's
//!   sliding velocity `ġ_T` reaches zero.
//! - **At an event**, with positions frozen:
//!   1. points that touch (`g_N ≤ gap_tol`) while approaching faster than `velocity_tol` impact:
//!      one impulse problem over every touching point, with Newton's law (2.202) or Poisson's
//!      (2.203): compression to `ġ_N ≥ 0` with impulse `Λ_C`, then expansion with
//!      `Λ_E ≥ ε Λ_C` (normal) and `ε_t Λ_TC` released tangentially; Coulomb's cone bounds the
//!      tangential impulse;
//!   2. the transition problem decides which touching points stay closed and which of those
//!      stick: an LCP at acceleration level, `g̈_N ≥ 0 ⊥ λ_N ≥ 0` and Coulomb's law in `g̈_T`
//!      with µ0 (a pyramid of `K` directions, exact for planar contacts, `K = 8` in space),
//!      solved by Lemke's method. No solution (a Painlevé situation) is a `SolverError` naming
//!      the contacts, unless asked to continue, which resolves it by an impulsive stop (an impact
//!      without collision).
//!
//! An accumulation of impacts (a ball coming to rest) passes in finitely many events: an approach
//! slower than `velocity_tol` closes the contact without impact.
//!
//! Compliant contacts ([`crate::forces::compliant`]) are smooth forces of the phases (so the
//! transition and impact problems see them like any applied force); their onsets, releases and
//! force cut-offs are kinks, not events: a step across one is retaken up to just past it (located
//! by [`crate::integrator::switching`] on the step's continuous extension) and the phase goes on
//! without a transition. Their dissipated energy and bristle states follow the contact forces'
//! integrals in the state.

mod impact;
mod matrices;
mod phase;
mod transition;

pub use matrices::ContactMatrices;

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::dopri5::{self, Step};
use super::{OdeSystem, Stats};
use crate::contact::ContactKinematics;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::integrator::events::EventLog;
use crate::integrator::moreau_jean::OPEN;
use crate::model::Model;
use crate::solver::{FrictionContact, Lcp, Workspace};

/// Settings of the event-driven scheme.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// Relative tolerance of the smooth phases.
    pub rtol: f64,
    /// Absolute tolerance of the smooth phases.
    pub atol: f64,
    /// Largest step (s); 0 means unlimited.
    pub max_step: f64,
    /// A point with a gap up to this (m) touches at an event.
    pub gap_tol: f64,
    /// Relative velocities up to this (m/s) count as zero: an approach that slow closes the
    /// contact without impact, a sliding speed that slow may stick.
    pub velocity_tol: f64,
    /// Stop with an error after this many events.
    pub max_events: usize,
    /// On a Painlevé situation, stop the sliding points by an impulse and go on (with a warning)
    /// instead of raising.
    pub continue_on_painleve: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: 1e-10,
            atol: 1e-12,
            max_step: 0.0,
            gap_tol: 1e-10,
            velocity_tol: 1e-8,
            max_events: 100_000,
            continue_on_painleve: false,
        }
    }
}

impl Options {
    /// Checks the settings.
    pub fn validate(&self) -> Result<()> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        crate::ensure!(
            ok(self.rtol) && ok(self.atol),
            Settings,
            "integrator: rtol and atol must be > 0, got rtol={}, atol={}",
            self.rtol,
            self.atol
        );
        crate::ensure!(self.max_step >= 0.0, Settings, "integrator.max_step: must be >= 0, got {}", self.max_step);
        crate::ensure!(
            self.gap_tol.is_finite() && self.gap_tol >= 0.0,
            Settings,
            "integrator.gap_tol: must be >= 0, got {}",
            self.gap_tol
        );
        crate::ensure!(
            ok(self.velocity_tol),
            Settings,
            "integrator.velocity_tol: must be > 0, got {}",
            self.velocity_tol
        );
        crate::ensure!(self.max_events > 0, Settings, "integrator.max_events: must be > 0");
        Ok(())
    }
}

/// A sliding point whose normal acceleration per unit normal force has fallen to this fraction
/// of its value at the phase's start is taken to have reached the Painlevé boundary (dynamic
/// jamming: its normal force grows as the inverse of that coefficient).
const JAM: f64 = 1e-3;

/// Friction directions of the pyramid in the transition problem for spatial contacts.
const PYRAMID: usize = 8;

/// The model with a fixed contact structure as an [`OdeSystem`], and the event machinery.
///
/// The state is `y = [q, u, E_diss, W_ext, E_friction, ∫λ_N dt (np), ∫λ_T dt (2 np)]`.
pub struct Phase<'a> {
    model: &'a Model,
    cb: &'a dyn Callbacks,
    opts: Options,
    /// The workspace of the last evaluation.
    pub data: Data,
    /// The dynamics stage's own workspace (the factors of M and of the bilateral constraints).
    pub dynamics: crate::dynamics::Workspace,
    /// 2 if every contact is planar, else 3 (normal and tangents per point).
    d: usize,
    /// Per point: [`OPEN`], [`STICK`] or [`SLIP`].
    pub status: Vec<f64>,
    /// Sliding direction (t1, t2 components) of slipping points, for speeds below `velocity_tol`.
    dir: Vec<[f64; 2]>,
    /// Per point: the normal acceleration per unit normal force of a sliding point under its
    /// sliding friction (1/kg; 1 for other points), whose zero is a Painlevé situation reached.
    slip_margin: Vec<f64>,
    /// That coefficient at the start of the phase: the event fires when it has fallen to
    /// [`JAM`] of it (the normal force grows as its inverse, so the phase cannot reach zero).
    slip_margin_start: Vec<f64>,
    /// Added to an open point's gap in its event function: a point that left its contact at an
    /// event (gap zero to round-off) must see a return to zero, not start on it (m).
    gap_offset: Vec<f64>,
    /// Contact kinematics of the last evaluation (`w̄` with the velocity-product accelerations).
    pub kin: Vec<ContactKinematics>,
    /// Per candidate point: the contact search's state between evaluations. Trial states come
    /// out of time order (rejected steps, root finding); a warm start compares the placement with
    /// the one of the last cold search, whatever came between, so any order is safe.
    search: Vec<crate::contact::SearchHint>,
    /// Warm-start the contact searches of planar parametric contours (the same roots as cold
    /// searches; off: every evaluation searches cold).
    pub warm_search: bool,
    /// Normal forces of the last evaluation (N).
    pub lam_n: Vec<f64>,
    /// Tangential forces, t1 and t2 components (N).
    pub lam_t: Vec<[f64; 2]>,
    friction_power: f64,
    /// Unknown forces of the smooth phase: (point, 0 normal / k tangent k).
    unk: Vec<(usize, usize)>,
    /// Row directions (one per unknown or LCP row), nu columns each.
    rows: DMatrix<f64>,
    /// Force directions.
    cols: DMatrix<f64>,
    /// `M̃⁻¹` times each force direction, nu per column.
    x: Vec<f64>,
    mat: Vec<f64>,
    rhs: Vec<f64>,
    aat: Vec<f64>,
    piv_r: Vec<usize>,
    piv_c_work: Vec<f64>,
    /// The force distribution that moves nothing, when there is one (see `redistribute`).
    null: Vec<f64>,
    a_free: Vec<f64>,
    tmp: Vec<f64>,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
    /// Every contact event, in time order.
    pub log: EventLog,
    /// Compliant contact points that closed or opened, as (t, point slot, closed).
    pub compliant_changes: Vec<(f64, usize, bool)>,
    lcp: Lcp,
    fc: FrictionContact,
    ws: Workspace,
    z: Vec<f64>,
    ev: EventWork,
    /// Offsets of the unit quaternions in the state (stepped on the rotation group).
    quats: Vec<usize>,
}

/// Scratch of the event handling (impacts, transitions), sized once.
#[derive(Default)]
struct EventWork {
    before: Vec<f64>,
    lam: Vec<f64>,
    total: Vec<f64>,
    after_c: Vec<f64>,
    stored: Vec<f64>,
    extra: Vec<f64>,
    unresolved: Vec<bool>,
    stick: Vec<usize>,
    touching: Vec<usize>,
    closing: Vec<usize>,
    old: Vec<f64>,
    old_dir: Vec<[f64; 2]>,
    /// Per point: its normal force reached zero at this event (it leaves unless held).
    leaving: Vec<bool>,
    /// Per point: its friction reserve reached zero at this event (it slides unless held).
    breaking: Vec<bool>,
    /// Per point: the tangential force before the event (t1, t2), the direction a break-away
    /// slides against.
    lam_t_before: Vec<[f64; 2]>,
    /// Per point: kinetic energy taken by the last impact (J).
    point_energy: Vec<f64>,
    /// Impulses per point (3 each) before the last impact, and the points it hit.
    imp_before: Vec<f64>,
    hit: Vec<usize>,
    /// Generalized velocities before the last impact.
    u_before: Vec<f64>,
    /// Sliding points of the last transition problem whose normal acceleration per unit normal
    /// force is not positive: (point, that coefficient, µ, critical µ, free normal acceleration).
    painleve: Vec<(usize, f64, f64, f64, f64)>,
    /// Per point: a sliding point reached the Painlevé boundary at this event.
    jam: Vec<bool>,
    /// Full-acceleration kinematics of one contact's points (the apex cap).
    apex: Vec<ContactKinematics>,
}

/// What one event did, for the records.
#[derive(Debug, Default, Clone, Copy)]
pub struct Dissipation {
    /// Kinetic energy taken by normal impulses (J).
    pub impact: f64,
    /// Kinetic energy taken by tangential impulses (J).
    pub friction: f64,
    /// Work done on the system through the impulses by what drives the contacts' rheonomic terms
    /// (a conveyor belt, a time-dependent gap): `-Λᵀ w̃` (J).
    pub external: f64,
}

/// Observer of the driver: called at each output time with the phase freshly evaluated at
/// (t, y), and the impulses of the impacts since the previous output.
pub type Sample<'s, 'a> = dyn FnMut(&mut Phase<'a>, f64, &[f64], &[f64], Dissipation) -> Result<()> + 's;

/// Runs the scheme from (t0, y0) (`y0` of [`Phase::state_len`]) through every output time.
pub fn integrate<'a>(
    phase: &mut Phase<'a>,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    warnings: &mut Vec<String>,
    sample: &mut Sample<'_, 'a>,
) -> Result<Stats> {
    let opts = phase.opts;
    let n = phase.state_len();
    let np = phase.status.len();
    let t_end = *t_out.last().unwrap_or(&t0);
    let hmax = if opts.max_step > 0.0 { opts.max_step } else { (t_end - t0).abs().max(f64::MIN_POSITIVE) };
    let mut stats = Stats::default();
    let mut y = y0.to_vec();
    // the quaternions are stepped on the rotation group (RKMK, crate::integrator::lie_group)
    let mut st = Step::on_group(crate::integrator::lie_group::Chart::new(n, phase.quaternions()), n);
    let mut yout = vec![0.0; n];
    let mut scratch = vec![0.0; n];
    let mut imp = vec![0.0; 3 * np];
    let mut diss = Dissipation::default();
    let (mut e_start, mut e_end, mut e_try) = (vec![0.0; 3 * np], vec![0.0; 3 * np], vec![0.0; 3 * np]);
    // θ of each event function's root in the step (infinite where it has none), and which of
    // them ended the phase
    let mut roots = vec![f64::INFINITY; 3 * np];
    let mut triggered = vec![false; 3 * np];
    let mut t = t0;
    let mut next = 0usize;
    let mut events = 0usize;
    let (mut last_event, mut same_instant) = (f64::NEG_INFINITY, 0usize);
    // the compliant contacts' switches (none without compliant contacts)
    let mut locator = crate::integrator::switching::Locator::new(phase);

    phase.project(t, &mut y)?;
    let d = timed_transition(phase, t, &mut y, (&mut imp, warnings), &triggered, &mut stats)?;
    diss.impact += d.impact;
    diss.friction += d.friction;
    diss.external += d.external;
    st.first_rate(phase, t, &y)?;
    phase.event_values(&mut e_start);
    let mut cap = phase.after_step()?;
    while next < t_out.len() && t_out[next] <= t {
        sample(phase, t, &y, &imp, diss)?;
        imp.fill(0.0);
        diss = Dissipation::default();
        next += 1;
    }
    let mut h = st.starting_step(phase, t, &y, opts.rtol, opts.atol, hmax)?;
    let mut err_old: f64 = 1e-4;
    let mut reject = false;
    // after a step retaken to end at a switch or an event: the first rate and event values at the
    // new start, the phase's step cap, and the samples up to t (which see the state after it)
    macro_rules! restart {
        () => {
            st.first_rate(phase, t, &y)?;
            stats.evaluations += 1;
            phase.event_values(&mut e_start);
            cap = phase.after_step()?;
            while next < t_out.len() && t_out[next] <= t {
                sample(phase, t_out[next], &y, &imp, diss)?;
                imp.fill(0.0);
                diss = Dissipation::default();
                next += 1;
            }
            reject = false;
        };
    }
    while next < t_out.len() {
        if t_end - t <= 1e-13 * t.abs().max(1.0) {
            while next < t_out.len() {
                phase.rhs(t_out[next], &y, &mut scratch)?;
                sample(phase, t_out[next], &y, &imp, diss)?;
                imp.fill(0.0);
                diss = Dissipation::default();
                next += 1;
            }
            break;
        }
        h = h.min(hmax).min(t_end - t);
        if cap.is_finite() {
            h = h.min(cap.max(1e-14 * t.abs().max(1.0)));
        }
        if h < crate::integrator::step_floor(t, t0, t_end) {
            return Err(Error::Solver(format!("step size underflow at t = {t:.9} s (h = {h:.3e})")));
        }
        let err = st.attempt(phase, t, &y, h, opts.rtol, opts.atol)?;
        stats.evaluations += 6;
        if !err.is_finite() || err > 1.0 {
            stats.rejected += 1;
            h *= if err.is_finite() { (0.9 * err.powf(-0.2)).max(0.2) } else { 0.1 };
            reject = true;
            continue;
        }
        // the phase was last evaluated at the step's end
        phase.event_values(&mut e_end);
        let cap_end = phase.after_step()?;
        st.prepare_dense(&y, h);
        // the earliest event in the step
        let mut theta = f64::INFINITY;
        for i in 0..3 * np {
            roots[i] = f64::INFINITY;
            if e_start[i] > 0.0 && e_end[i] <= 0.0 {
                let th = locate(phase, &st, (t, h), (i, e_start[i], e_end[i]), &mut yout, &mut e_try, &mut scratch)?;
                stats.evaluations += 1;
                roots[i] = th;
                theta = theta.min(th);
            }
        }
        // every indicator whose root falls on the event (to the location's resolution) ends the
        // phase there: the transition switches it even where its value is zero to round-off
        let resolution = 1e-12 * t.abs().max(1.0) / h;
        for i in 0..3 * np {
            triggered[i] = roots[i] <= theta + resolution;
        }
        // a compliant contact's onset, release or cut-off before the first rigid event: the step
        // ends just past it (a kink of the smooth phase's forces, no transition)
        let mut switch = None;
        if locator.active() {
            let ynew = &st.ynew;
            let found = locator.locate(phase, t, h, &y, ynew, |th, out| st.dense(th, out))?;
            if let Some(th) = found.filter(|th| *th < theta) {
                switch = Some(th);
            }
        }
        let t_new = match switch {
            Some(th) => t + th * h,
            None if theta.is_finite() => t + theta * h,
            None => t + h,
        };
        // outputs inside the step (up to and including an event's time)
        while next < t_out.len() && t_out[next] <= t_new + 1e-12 * t_new.abs().max(1.0) {
            let to = t_out[next].min(t_new);
            st.dense(((to - t) / h).clamp(0.0, 1.0), &mut yout);
            phase.project(to, &mut yout)?;
            phase.rhs(to, &yout, &mut scratch)?;
            sample(phase, t_out[next], &yout, &imp, diss)?;
            imp.fill(0.0);
            diss = Dissipation::default();
            next += 1;
        }
        stats.steps += 1;
        if let Some(th) = switch {
            // the step again, ending just past the switch; the phase goes on without a transition
            st.attempt(phase, t, &y, th * h, opts.rtol, opts.atol)?;
            y.copy_from_slice(&st.ynew);
            t = t_new;
            phase.project(t, &mut y)?;
            crate::integrator::check_finite(t, &y)?;
            phase.accepted(t, &mut y)?;
            restart!();
            continue;
        }
        if theta.is_finite() {
            // the step again, ending at the event, then the event itself
            let hs = theta * h;
            if hs > 0.0 {
                // k[0] still holds f(t, y)
                st.attempt(phase, t, &y, hs, opts.rtol, opts.atol)?;
                y.copy_from_slice(&st.ynew);
            }
            t = t_new;
            phase.project(t, &mut y)?;
            phase.accepted(t, &mut y)?;
            events += 1;
            if (t - last_event).abs() <= 1e-12 * t.abs().max(1.0) {
                same_instant += 1;
            } else {
                same_instant = 0;
            }
            last_event = t;
            if events > opts.max_events || same_instant > 100 {
                let what: Vec<usize> =
                    (0..np).filter(|&pt| phase.status[pt] != OPEN || phase.kin[pt].point.g_n <= opts.gap_tol).collect();
                return Err(Error::Solver(format!(
                    "{} events by t = {t:.9} s (contacts {:?}): an accumulation the event-driven scheme cannot pass; raise velocity_tol or use MoreauJean",
                    events,
                    phase.names(&what)
                )));
            }
            let d = timed_transition(phase, t, &mut y, (&mut imp, warnings), &triggered, &mut stats)?;
            diss.impact += d.impact;
            diss.friction += d.friction;
            diss.external += d.external;
            // samples at exactly the event time see the state after it
            restart!();
            continue;
        }
        phase.project(t_new, &mut st.ynew)?;
        crate::integrator::check_finite(t_new, &st.ynew)?;
        phase.accepted(t_new, &mut st.ynew)?;
        t = t_new;
        std::mem::swap(&mut y, &mut st.ynew);
        st.fsal();
        std::mem::swap(&mut e_start, &mut e_end);
        cap = cap_end;
        h *= dopri5::next_factor(err, err_old, reject);
        err_old = err.max(1e-4);
        reject = false;
    }
    stats.evaluations = phase.evaluations;
    stats.events = events;
    Ok(stats)
}

/// [`Phase::transition`], counted and timed in `stats` (the cost per transition).
fn timed_transition(
    phase: &mut Phase,
    t: f64,
    y: &mut [f64],
    (imp, warnings): (&mut [f64], &mut Vec<String>),
    triggered: &[bool],
    stats: &mut Stats,
) -> Result<Dissipation> {
    let clock = std::time::Instant::now();
    let d = phase.transition(t, y, imp, warnings, triggered)?;
    stats.transitions += 1;
    stats.transition_seconds += clock.elapsed().as_secs_f64();
    Ok(d)
}

/// The root of event function `i` in the step `[t, t + h]` by Illinois' regula falsi on the
/// continuous extension; returns θ at or just after the root (where the event has happened).
fn locate(
    phase: &mut Phase,
    st: &Step,
    (t, h): (f64, f64),
    (i, fa, fb): (usize, f64, f64),
    y: &mut [f64],
    e: &mut [f64],
    scratch: &mut [f64],
) -> Result<f64> {
    let (mut a, mut b, mut fa, mut fb) = (0.0f64, 1.0f64, fa, fb);
    let mut side = 0i8;
    let tol = 1e-15 * t.abs().max(1.0) / h;
    for _ in 0..200 {
        if b - a <= tol {
            break;
        }
        let mut c = b - fb * (b - a) / (fb - fa);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        st.dense(c, y);
        phase.rhs(t + c * h, y, scratch)?;
        phase.event_values(e);
        let fc = e[i];
        if fc <= 0.0 {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if fc == 0.0 {
            break;
        }
    }
    Ok(b)
}

#[cfg(test)]
mod tests {
    use super::Options;
    use crate::forces::NoCallbacks;
    use crate::integrator::IntegratorKind;
    use crate::model::{Model, ModelDescription};
    use crate::simulate::{simulate, Settings};

    /// A point mass over the floor z = 0 dropped from `h0` with restitution `eps`, sliding along x
    /// at `vx` on a floor with friction `mu`.
    fn drop(h0: f64, eps: f64, vx: f64, mu: f64) -> Model {
        let json = format!(
            r#"{{"name": "drop", "gravity": [0, 0, -9.81],
            "bodies": [{{"name": "b", "mass": 2.0, "inertia": [0.01, 0.01, 0.01]}}],
            "joints": [{{"name": "f", "type": "free", "parent": "ground", "child": "b",
                         "q0": [0, 0, {h0}, 1, 0, 0, 0], "u0": [{vx}, 0, 0, 0, 0, 0]}}],
            "contacts": [{{"name": "floor", "body1": "b", "contour1": {{"type": "point"}}, "body2": "ground",
                           "contour2": {{"type": "plane", "normal": [0, 0, 1]}},
                           "friction": {{"type": "coulomb", "mu": {mu}}}, "impact": {{"type": "newton", "eps": {eps}}}}}]}}"#
        );
        Model::from_description(ModelDescription::from_json(&json).unwrap()).unwrap()
    }

    fn settings(t_end: f64, opts: Options) -> Settings {
        let json = format!(r#"{{"t_end": {t_end}, "output_dt": 0.01, "integrator": {{"type": "event_driven"}}}}"#);
        let mut s: Settings = serde_json::from_str(&json).unwrap();
        assert_eq!(s.integrator, IntegratorKind::EventDriven(Options::default()));
        s.integrator = IntegratorKind::EventDriven(opts);
        s
    }

    #[test]
    fn accumulation_time_and_rest() {
        // impacts accumulate at t0 (1 + eps) / (1 - eps), t0 = sqrt(2 h0 / g); then the mass rests
        let (h0, eps) = (0.5, 0.6);
        let m = drop(h0, eps, 0.0, 0.0);
        let opts = Options { velocity_tol: 1e-10, ..Options::default() };
        let rec = simulate(&m, &settings(2.0, opts), &NoCallbacks, None).unwrap();
        let t_inf = (2.0 * h0 / 9.81f64).sqrt() * (1.0 + eps) / (1.0 - eps);
        let closes: Vec<f64> = rec.events.iter().filter(|e| e.kind == "close").map(|e| e.t).collect();
        assert_eq!(closes.len(), 1);
        assert!((closes[0] - t_inf).abs() < 1e-9 * t_inf, "{} vs {t_inf}", closes[0]);
        // resting: λ_N = m g at the last sample, state stick (frictionless, not sliding)
        let last = rec.contact_lambda_n.last().unwrap();
        assert!((last - 2.0 * 9.81).abs() < 1e-10, "{last}");
        assert_eq!(*rec.contact_state.last().unwrap(), crate::integrator::moreau_jean::STICK);
    }

    #[test]
    fn sliding_stops_at_the_closed_form_time() {
        // landing flat (h0 = 0) at vx = 1 m/s with mu = 0.5: it stops at v / (mu g), after
        // sliding v² / (2 mu g), and the friction took m v² / 2
        let m = drop(0.0, 0.0, 1.0, 0.5);
        let rec = simulate(&m, &settings(0.5, Options::default()), &NoCallbacks, None).unwrap();
        let stick: Vec<f64> = rec.events.iter().filter(|e| e.kind == "stick").map(|e| e.t).collect();
        assert_eq!(stick.len(), 1);
        assert!((stick[0] - 1.0 / (0.5 * 9.81)).abs() < 1e-9, "{stick:?}");
        let nb = rec.n_bodies;
        let x_end = rec.body_position[(rec.n_out - 1) * nb * 3];
        assert!((x_end - 1.0 / (2.0 * 0.5 * 9.81)).abs() < 1e-9, "{x_end}");
        assert!((rec.dissipated_friction.last().unwrap() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn bad_options_name_the_key() {
        for (o, key) in [
            (Options { velocity_tol: -1.0, ..Options::default() }, "velocity_tol"),
            (Options { gap_tol: f64::NAN, ..Options::default() }, "gap_tol"),
            (Options { atol: 0.0, ..Options::default() }, "atol"),
            (Options { max_step: -1.0, ..Options::default() }, "max_step"),
        ] {
            let e = o.validate().unwrap_err().to_string();
            assert!(e.contains(key), "{e}");
        }
    }
}
