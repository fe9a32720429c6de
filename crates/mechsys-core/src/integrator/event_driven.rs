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
//!   an open point's gap `g_N` reaches zero; a closed point's normal force `λ_N` reaches zero;
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

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::dopri5::{self, Step};
use super::{OdeSystem, Stats};
use crate::contact::{contact_kinematics, BodyMotion, ContactKinematics};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::{Callbacks, Powers};
use crate::integrator::moreau_jean::{OPEN, SLIP, STICK};
use crate::math::linalg::solve_min_norm;
use crate::math::Vec3;
use crate::model::contact::{FrictionLaw, ImpactLaw};
use crate::model::Model;
use crate::solver::{self, Delassus, FrictionContact, Lcp, Method, Workspace};
use crate::spatial::Motion;

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
        crate::ensure!(ok(self.velocity_tol), Settings, "integrator.velocity_tol: must be > 0, got {}", self.velocity_tol);
        crate::ensure!(self.max_events > 0, Settings, "integrator.max_events: must be > 0");
        Ok(())
    }
}

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
    /// 2 if every contact is planar, else 3 (normal and tangents per point).
    d: usize,
    /// Per point: [`OPEN`], [`STICK`] or [`SLIP`].
    pub status: Vec<f64>,
    /// Sliding direction (t1, t2 components) of slipping points, for speeds below `velocity_tol`.
    dir: Vec<[f64; 2]>,
    /// Contact kinematics of the last evaluation (`w̄` with the velocity-product accelerations).
    pub kin: Vec<ContactKinematics>,
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
    a_free: Vec<f64>,
    tmp: Vec<f64>,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
    /// Every contact event: (time, point, what happened: impact, close, open, stick, slip).
    pub log: Vec<(f64, usize, &'static str)>,
    lcp: Lcp,
    fc: FrictionContact,
    ws: Workspace,
    z: Vec<f64>,
    ev: EventWork,
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
}

impl<'a> Phase<'a> {
    /// A phase for `model` with every point open.
    pub fn new(model: &'a Model, cb: &'a dyn Callbacks, opts: Options) -> Result<Self> {
        opts.validate()?;
        let (nu, np) = (model.nu, model.n_contact_points);
        let d = if model.contacts.iter().all(|c| c.pair.is_planar()) { 2 } else { 3 };
        // the LCP has at most np (1 + K + 1) unknowns
        let k = if d == 2 { 2 } else { PYRAMID };
        let rmax = (np * (k + 1)).max(d * np).max(1);
        Ok(Phase {
            model,
            cb,
            opts,
            data: Data::new(model),
            d,
            status: vec![OPEN; np],
            dir: vec![[0.0; 2]; np],
            kin: vec![ContactKinematics::default(); np],
            lam_n: vec![0.0; np],
            lam_t: vec![[0.0; 2]; np],
            friction_power: 0.0,
            unk: Vec::with_capacity(d * np),
            rows: DMatrix::zeros(rmax, nu),
            cols: DMatrix::zeros(rmax, nu),
            x: vec![0.0; rmax * nu],
            mat: vec![0.0; (rmax + np) * (rmax + np)],
            rhs: vec![0.0; rmax + np],
            aat: vec![0.0; (rmax + np) * (rmax + np)],
            piv_r: vec![0; rmax + np],
            piv_c_work: vec![0.0; rmax + np],
            a_free: vec![0.0; nu],
            tmp: vec![0.0; nu],
            evaluations: 0,
            log: Vec::new(),
            lcp: Lcp { m: Vec::with_capacity((np * (k + 2)).pow(2)), q: Vec::with_capacity(np * (k + 2)) },
            fc: FrictionContact {
                dim: d,
                w: Delassus::Dense(Vec::with_capacity(d * d * np * np)),
                q: Vec::with_capacity(d * np),
                mu: Vec::with_capacity(np),
            },
            ws: Workspace::new(),
            z: Vec::with_capacity(np * (k + 2)),
            ev: EventWork {
                before: Vec::with_capacity(d * np),
                lam: Vec::with_capacity(d * np),
                total: Vec::with_capacity(d * np),
                after_c: Vec::with_capacity(d * np),
                stored: Vec::with_capacity(d * np),
                extra: Vec::with_capacity(d * np),
                unresolved: Vec::with_capacity(np),
                stick: Vec::with_capacity(np),
                touching: Vec::with_capacity(np),
                closing: Vec::with_capacity(np),
                old: Vec::with_capacity(np),
                old_dir: Vec::with_capacity(np),
                apex: vec![ContactKinematics::default(); model.contacts.iter().map(|c| c.points()).max().unwrap_or(0)],
            },
        })
    }

    /// Length of the integrated state.
    pub fn state_len(&self) -> usize {
        self.model.nq + self.model.nu + 3 + 3 * self.model.n_contact_points
    }

    /// The motion without contact forces: kinematics, smooth forces, the mass matrix factored,
    /// the accelerations `a_free` under the bilateral constraints, and every point's kinematics
    /// with `w̄` (velocity-product accelerations in `data.a`).
    fn free_motion(&mut self, t: f64, q: &[f64], u: &[f64]) -> Result<Powers> {
        let (model, nc) = (self.model, self.model.nc);
        let data = &mut self.data;
        let mut p = crate::dynamics::prepare(model, data, t, q, u, self.cb)?;
        if nc > 0 {
            crate::constraints::positions(model, data, t, q, self.cb)?;
        }
        data.a[0] = Motion::ZERO;
        let zero = std::mem::take(&mut data.zero_u);
        crate::kinematics::accelerations(model, data, &zero);
        data.zero_u = zero;
        if nc > 0 {
            crate::constraints::accelerations(model, data, t, q, u, self.cb)?;
        }
        let mut c = std::mem::take(&mut self.a_free);
        crate::dynamics::rnea::rnea_inward(model, data, &mut c);
        for v in c.iter_mut() {
            *v = -*v;
        }
        {
            let Data { inertia, s, ic, saddle, .. } = &mut *data;
            crate::dynamics::crba::composite_inertias(model, inertia, s, ic, |r, col, v| saddle.put_mass(r, col, v));
        }
        if !data.saddle.factor_mass() {
            self.a_free = c;
            return Err(Error::Solver(format!("the mass matrix is singular at t = {t:.6} s")));
        }
        data.saddle.solve_mass(&mut c);
        if nc > 0 {
            data.saddle.gather_g(&data.g);
            data.saddle.assemble_schur(true);
            if !data.saddle.factor_schur(1e-12) {
                self.a_free = c;
                return Err(Error::Settings(format!(
                    "integrator: the event-driven scheme needs independent bilateral constraints; they are redundant at t = {t:.6} s (use MoreauJean)"
                )));
            }
            data.saddle.g_times(&c, &mut data.lambda);
            for r in 0..nc {
                data.lambda[r] = data.gamma[r] - data.lambda[r];
            }
            data.saddle.solve_schur(&mut data.lambda);
            data.saddle.add_constraint_accelerations(&data.lambda, &mut c);
            for k in 0..nc {
                p.external += data.lambda[k] * data.b[k];
            }
        }
        self.a_free = c;
        for con in &model.contacts {
            let (b1, b2) = (BodyMotion::from_data(data, con.body1), BodyMotion::from_data(data, con.body2));
            contact_kinematics(&con.pair, &b1, &b2, &mut self.kin[con.first..con.first + con.points()])
                .map_err(|e| Error::Solver(format!("contact '{}' at t = {t:.6} s: {e}", con.name)))?;
        }
        Ok(p)
    }

    /// `x ← M̃⁻¹ x`: the accelerations a generalized force `x` causes under the bilateral
    /// constraints; `lambda`, if given, receives the multipliers it adds.
    fn inverse_mass(data: &mut Data, nc: usize, x: &mut [f64], lambda: Option<&mut [f64]>) {
        data.saddle.solve_mass(x);
        if nc > 0 {
            let mut y = std::mem::take(&mut data.work2);
            y.resize(nc.max(y.len()), 0.0);
            data.saddle.g_times(x, &mut y[..nc]);
            for v in y[..nc].iter_mut() {
                *v = -*v;
            }
            data.saddle.solve_schur(&mut y[..nc]);
            data.saddle.add_constraint_accelerations(&y[..nc], x);
            if let Some(l) = lambda {
                for k in 0..nc {
                    l[k] += y[k];
                }
            }
            data.work2 = y;
        }
    }

    /// Generalized direction of a force `dir` at point `pt` (body 1 pushed along `dir`, body 2
    /// back) into row `r` of `m`.
    fn put_row(model: &Model, data: &Data, kin: &[ContactKinematics], pt: usize, dir: &Vec3, m: &mut DMatrix<f64>, r: usize) {
        for i in 0..model.nu {
            m[(r, i)] = 0.0;
        }
        let con = model.contact_of_point(pt);
        let k = &kin[pt].point;
        crate::constraints::add_point_rows(model, &data.s, con.body1, &k.p1, 1.0, Some(dir), m, r);
        crate::constraints::add_point_rows(model, &data.s, con.body2, &k.p2, -1.0, Some(dir), m, r);
    }

    /// World tangent direction of (t1, t2) components `c` at point `pt`.
    fn tangent(&self, pt: usize, c: [f64; 2]) -> Vec3 {
        let k = &self.kin[pt].point;
        k.t1 * c[0] + if self.d == 3 { k.t2 * c[1] } else { Vec3::zeros() }
    }

    /// Sliding velocity (t1, t2 components; t2 = 0 for planar pairs) and speed of point `pt`.
    fn sliding(&self, pt: usize) -> ([f64; 2], f64) {
        let g = self.kin[pt].gd_t;
        let g = if self.d == 3 { g } else { [g[0], 0.0] };
        (g, (g[0] * g[0] + g[1] * g[1]).sqrt())
    }

    /// Unit sliding direction of a slipping point: the current one above `velocity_tol`, else the
    /// one the last transition found (sliding starts from rest along the relative acceleration).
    fn slip_direction(&self, pt: usize) -> [f64; 2] {
        let (g, s) = self.sliding(pt);
        if s > self.opts.velocity_tol {
            [g[0] / s, g[1] / s]
        } else {
            self.dir[pt]
        }
    }

    fn mu_sliding(&self, pt: usize) -> f64 {
        let (_, s) = self.sliding(pt);
        match &self.model.contact_of_point(pt).friction {
            FrictionLaw::None => 0.0,
            law => law.mu(s.max(f64::MIN_POSITIVE)),
        }
    }

    /// `M̃⁻¹` times the first `n` rows of `cols` into `x`.
    fn solve_columns(&mut self, n: usize) {
        let nu = self.model.nu;
        for j in 0..n {
            let x = &mut self.x[j * nu..(j + 1) * nu];
            for i in 0..nu {
                x[i] = self.cols[(j, i)];
            }
            Self::inverse_mass(&mut self.data, self.model.nc, x, None);
        }
    }

    /// `rows_i · x_j`.
    fn coupling(&self, i: usize, j: usize) -> f64 {
        let nu = self.model.nu;
        let x = &self.x[j * nu..(j + 1) * nu];
        (0..nu).map(|k| self.rows[(i, k)] * x[k]).sum()
    }

    /// One evaluation with the current contact structure: forces and `u̇` (into `data.udot`,
    /// body accelerations into `data.a`). Returns the smooth power balance.
    pub fn evaluate(&mut self, t: f64, q: &[f64], u: &[f64]) -> Result<Powers> {
        self.evaluations += 1;
        let p = self.free_motion(t, q, u)?;
        let (model, nu, np) = (self.model, self.model.nu, self.model.n_contact_points);
        self.unk.clear();
        for pt in 0..np {
            self.lam_n[pt] = 0.0;
            self.lam_t[pt] = [0.0; 2];
            if self.status[pt] == OPEN {
                continue;
            }
            self.unk.push((pt, 0));
            if self.status[pt] == STICK {
                for k in 1..self.d {
                    self.unk.push((pt, k));
                }
            }
        }
        let n = self.unk.len();
        self.friction_power = 0.0;
        let mut udot = std::mem::take(&mut self.data.udot);
        udot.copy_from_slice(&self.a_free);
        if n > 0 {
            // rows: the constrained directions; columns: the force directions
            for j in 0..n {
                let (pt, k) = self.unk[j];
                let kp = &self.kin[pt].point;
                let row_dir = match k {
                    0 => kp.n,
                    1 => kp.t1,
                    _ => kp.t2,
                };
                Self::put_row(model, &self.data, &self.kin, pt, &row_dir, &mut self.rows, j);
                let col_dir = if k == 0 && self.status[pt] == SLIP {
                    let s = self.slip_direction(pt);
                    kp.n - self.tangent(pt, s) * self.mu_sliding(pt)
                } else {
                    row_dir
                };
                Self::put_row(model, &self.data, &self.kin, pt, &col_dir, &mut self.cols, j);
            }
            self.solve_columns(n);
            for i in 0..n {
                for j in 0..n {
                    self.mat[i * n + j] = self.coupling(i, j);
                }
                let (pt, k) = self.unk[i];
                let wbar = match k {
                    0 => self.kin[pt].wbar_n,
                    k => self.kin[pt].wbar_t[k - 1],
                };
                let ra: f64 = (0..nu).map(|c| self.rows[(i, c)] * self.a_free[c]).sum();
                self.rhs[i] = -(ra + wbar);
            }
            solve_min_norm(&self.mat[..n * n], n, &mut self.rhs[..n], &mut self.aat, &mut self.piv_r, &mut self.piv_c_work, 1e-13);
            for j in 0..n {
                let l = self.rhs[j];
                let x = &self.x[j * nu..(j + 1) * nu];
                for i in 0..nu {
                    udot[i] += x[i] * l;
                }
                let (pt, k) = self.unk[j];
                if k == 0 {
                    self.lam_n[pt] = l;
                } else {
                    self.lam_t[pt][k - 1] = l;
                }
            }
            for pt in 0..np {
                if self.status[pt] == SLIP {
                    let (s, mu) = (self.slip_direction(pt), self.mu_sliding(pt));
                    self.lam_t[pt] = [-mu * self.lam_n[pt] * s[0], -mu * self.lam_n[pt] * s[1]];
                    self.friction_power += mu * self.lam_n[pt] * self.sliding(pt).1;
                }
            }
            if model.nc > 0 {
                // the multipliers of the bilateral constraints gain what the contact forces add
                let mut f = std::mem::take(&mut self.tmp);
                f.fill(0.0);
                for j in 0..n {
                    for i in 0..nu {
                        f[i] += self.cols[(j, i)] * self.rhs[j];
                    }
                }
                let mut lam = std::mem::take(&mut self.data.lambda);
                Self::inverse_mass(&mut self.data, model.nc, &mut f, Some(&mut lam));
                self.data.lambda = lam;
                self.tmp = f;
            }
        }
        self.data.a[0] = Motion::ZERO;
        crate::kinematics::accelerations(model, &mut self.data, &udot);
        self.data.udot = udot;
        Ok(p)
    }

    /// Event functions of the last evaluation, two per point; an event is a sign change from
    /// positive to non-positive.
    pub fn event_values(&self, out: &mut [f64]) {
        for pt in 0..self.status.len() {
            let (e0, e1) = if self.status[pt] == OPEN {
                (self.kin[pt].point.g_n, 1.0)
            } else if self.status[pt] == STICK {
                let lt = (self.lam_t[pt][0].powi(2) + self.lam_t[pt][1].powi(2)).sqrt();
                (self.lam_n[pt], self.model.contact_of_point(pt).friction.mu0() * self.lam_n[pt] - lt)
            } else if self.mu_sliding(pt) > 0.0 {
                let (g, _) = self.sliding(pt);
                (self.lam_n[pt], g[0] * self.dir[pt][0] + g[1] * self.dir[pt][1])
            } else {
                (self.lam_n[pt], 1.0)
            };
            out[2 * pt] = e0;
            out[2 * pt + 1] = e1;
        }
    }

    /// After an accepted step: slipping points remember their current direction, and the step
    /// is capped so that an open point moving apart cannot come back within one step unseen
    /// (the time to its apex, from `g̈_N` at the step's end). Uses the last evaluation.
    pub fn after_step(&mut self) -> Result<f64> {
        let np = self.status.len();
        let mut cap = f64::INFINITY;
        for pt in 0..np {
            if self.status[pt] == SLIP {
                let (g, s) = self.sliding(pt);
                if s > self.opts.velocity_tol {
                    self.dir[pt] = [g[0] / s, g[1] / s];
                }
            }
        }
        // full accelerations are in data.a: contact_kinematics then gives g̈_N in wbar_n
        for con in &self.model.contacts {
            let pts = con.first..con.first + con.points();
            if !pts.clone().any(|pt| self.status[pt] == OPEN && self.kin[pt].gd_n > 0.0) {
                continue;
            }
            // (every contact's points, not a fixed-size buffer: none may be skipped)
            let k = &mut self.ev.apex;
            let (b1, b2) = (BodyMotion::from_data(&self.data, con.body1), BodyMotion::from_data(&self.data, con.body2));
            let n = con.points();
            contact_kinematics(&con.pair, &b1, &b2, &mut k[..n])?;
            for (j, kk) in k[..n].iter().enumerate() {
                let pt = con.first + j;
                if self.status[pt] == OPEN && kk.gd_n > 0.0 && kk.wbar_n < 0.0 {
                    cap = cap.min(kk.gd_n / -kk.wbar_n);
                }
            }
        }
        Ok(cap)
    }

    /// The recorded state of point `pt`: a closed frictionless point that does not slide reads as
    /// sticking, as in the time-stepping scheme.
    pub fn state_code(&self, pt: usize) -> f64 {
        if self.status[pt] == SLIP && self.mu_sliding(pt) == 0.0 && self.sliding(pt).1 <= self.opts.velocity_tol {
            STICK
        } else {
            self.status[pt]
        }
    }

    fn names(&self, pts: &[usize]) -> Vec<String> {
        let mut v: Vec<String> = pts.iter().map(|&pt| self.model.contact_of_point(pt).name.clone()).collect();
        v.dedup();
        v
    }

    /// The impact at an event: one impulse problem over the touching points `pts` (Newton's or
    /// Poisson's law per contact), `u` updated. Impulses are added to `imp` (3 per point).
    fn impact(&mut self, t: f64, u: &mut [f64], pts: &[usize], plastic: bool, imp: &mut [f64]) -> Result<Dissipation> {
        let (model, nu, d) = (self.model, self.model.nu, self.d);
        let m = pts.len();
        let dm = d * m;
        for (a, &pt) in pts.iter().enumerate() {
            let kp = self.kin[pt].point;
            for (row, dir) in [kp.n, kp.t1, kp.t2].iter().enumerate().take(d) {
                Self::put_row(model, &self.data, &self.kin, pt, dir, &mut self.rows, a * d + row);
                Self::put_row(model, &self.data, &self.kin, pt, dir, &mut self.cols, a * d + row);
            }
        }
        self.solve_columns(dm);
        let mut w = match std::mem::replace(&mut self.fc.w, Delassus::Dense(Vec::new())) {
            Delassus::Dense(w) => w,
            Delassus::Blocks(_) => Vec::new(),
        };
        w.clear();
        for i in 0..dm {
            for j in 0..dm {
                w.push(self.coupling(i, j));
            }
        }
        // a tangent that can take no velocity (planar motion, spatial contour) or no force (no
        // friction) takes no impulse: decoupled, with a positive diagonal
        for a in 0..dm {
            let frictionless = matches!(model.contact_of_point(pts[a / d]).friction, FrictionLaw::None);
            if a % d != 0 && (frictionless || (0..nu).all(|i| self.rows[(a, i)] == 0.0)) {
                let nrow = a - a % d;
                for b in 0..dm {
                    w[a * dm + b] = 0.0;
                    w[b * dm + a] = 0.0;
                }
                w[a * dm + a] = w[nrow * dm + nrow].max(f64::MIN_POSITIVE);
            }
        }
        self.fc.w = Delassus::Dense(w);
        self.fc.dim = d;
        // local velocities before
        let mut ev = std::mem::take(&mut self.ev);
        let before = &mut ev.before;
        before.clear();
        before.resize(dm, 0.0);
        for (a, b) in before.iter_mut().enumerate() {
            *b = (0..nu).map(|i| self.rows[(a, i)] * u[i]).sum();
        }
        self.fc.mu.clear();
        for &pt in pts {
            let (_, s) = self.sliding(pt);
            let law = &model.contact_of_point(pt).friction;
            self.fc.mu.push(if s <= self.opts.velocity_tol { law.mu0() } else { law.mu(s) });
        }
        let method = if d == 2 {
            Method::lemke()
        } else {
            Method::Newton(solver::NewtonOptions { tol: 1e-13, max_iter: 500 })
        };
        let poisson = pts.iter().any(|&pt| matches!(model.contact_of_point(pt).impact, ImpactLaw::Poisson { .. }));
        // a rebound too low to be resolved in floating point (its apex within a few ulps of the
        // contact point's coordinates) would only chatter: such a point's impact is plastic
        let unresolved = &mut ev.unresolved;
        unresolved.clear();
        unresolved.resize(m, false);
        for (a, &pt) in pts.iter().enumerate() {
            let eps = model.contact_of_point(pt).impact.eps();
            let v = eps * before[a * d].min(0.0);
            let acc: f64 = (0..nu).map(|i| self.rows[(a * d, i)] * self.a_free[i]).sum::<f64>() + self.kin[pt].wbar_n;
            let con = model.contact_of_point(pt);
            let kp = &self.kin[pt].point;
            let scale = [kp.p1.amax(), kp.p2.amax(), self.data.x_abs[con.body1].r.amax(), self.data.x_abs[con.body2].r.amax()]
                .iter()
                .fold(1e-300f64, |a, b| a.max(*b));
            unresolved[a] = acc < 0.0 && v * v / (-2.0 * acc) < 64.0 * f64::EPSILON * scale;
        }
        let eps_of = |a: usize, e: f64| if unresolved[a] { 0.0 } else { e };
        // phase 1: Newton's law in one problem, or Poisson's compression (ġ_N ≥ 0, plastic)
        self.fc.q.clear();
        for (a, &pt) in pts.iter().enumerate() {
            let eps = match model.contact_of_point(pt).impact {
                ImpactLaw::Newton { eps } if !plastic && !poisson => eps_of(a, eps),
                _ => 0.0,
            };
            self.fc.q.push(before[a * d] + eps * before[a * d].min(0.0));
            for r in 1..d {
                self.fc.q.push(before[a * d + r]);
            }
        }
        let (lam, total) = (&mut ev.lam, &mut ev.total);
        lam.clear();
        lam.resize(dm, 0.0);
        if let Err(e) = self.solve_fc(t, pts, &method, lam) {
            self.ev = ev;
            return Err(e);
        }
        total.clear();
        total.extend_from_slice(lam);
        if poisson && !plastic {
            // expansion: the stored impulses ε Λ_C (normal), ε_t Λ_TC (tangential) come back; the
            // extra impulse x keeps ġ_N ≥ 0 (a contact may not close further), bounded by the cone
            let (gc, stored) = (&mut ev.after_c, &mut ev.stored);
            gc.clear();
            gc.resize(dm, 0.0);
            stored.clear();
            stored.resize(dm, 0.0);
            for (a, &pt) in pts.iter().enumerate() {
                let (en, et) = match model.contact_of_point(pt).impact {
                    ImpactLaw::Poisson { eps, eps_t } => (eps_of(a, eps), eps_t),
                    ImpactLaw::Newton { eps } => (eps_of(a, eps), 0.0),
                };
                stored[a * d] = en * lam[a * d];
                for r in 1..d {
                    stored[a * d + r] = et * lam[a * d + r];
                }
            }
            let Delassus::Dense(w) = &self.fc.w else { unreachable!() };
            for i in 0..dm {
                let wl: f64 = (0..dm).map(|j| w[i * dm + j] * (lam[j] + stored[j])).sum();
                gc[i] = before[i] + wl;
            }
            self.fc.q.clear();
            self.fc.q.extend_from_slice(gc);
            let x = &mut ev.extra;
            x.clear();
            x.resize(dm, 0.0);
            if let Err(e) = self.solve_fc(t, pts, &method, x) {
                self.ev = ev;
                return Err(e);
            }
            for i in 0..dm {
                total[i] += stored[i] + x[i];
            }
        }
        // u⁺ = u⁻ + M̃⁻¹ W Λ; the energy taken is −Λᵀ(ġ⁻ + ġ⁺)/2 (friction's share −Λ_Tᵀ ġ_T⁺)
        for (j, l) in total.iter().enumerate() {
            if *l != 0.0 {
                let x = &self.x[j * nu..(j + 1) * nu];
                for i in 0..nu {
                    u[i] += x[i] * l;
                }
            }
        }
        let mut diss = Dissipation::default();
        for a in 0..dm {
            let after: f64 = (0..nu).map(|i| self.rows[(a, i)] * u[i]).sum();
            let e = -total[a] * 0.5 * (after + before[a]);
            if a % d == 0 {
                diss.impact += e;
            } else {
                let f = -total[a] * after;
                diss.friction += f;
                diss.impact += e - f;
            }
        }
        for (a, &pt) in pts.iter().enumerate() {
            imp[3 * pt] += total[a * d];
            for r in 1..d {
                imp[3 * pt + r] += total[a * d + r];
            }
        }
        self.ev = ev;
        Ok(diss)
    }

    fn solve_fc(&mut self, t: f64, pts: &[usize], method: &Method, x: &mut [f64]) -> Result<()> {
        self.ws.reserve(&self.fc, method)?;
        let report = solver::solve(&self.fc, method, x, false, &mut self.ws)
            .map_err(|e| Error::Solver(format!("impact of contacts {:?} at t = {t:.9} s: {e}", self.names(pts))))?;
        crate::ensure!(
            report.converged || report.residual < 1e-9,
            Solver,
            "impact of contacts {:?} at t = {t:.9} s: the impulse problem did not converge (residual {:.1e})",
            self.names(pts),
            report.residual
        );
        Ok(())
    }

    /// The transition problem at acceleration level over the touching points `pts` with zero
    /// normal velocity: sets every point's status. Returns false when it has no solution.
    fn transition_lcp(&mut self, pts: &[usize]) -> Result<bool> {
        let (model, np) = (self.model, self.model.n_contact_points);
        let vtol = self.opts.velocity_tol;
        for pt in 0..np {
            self.status[pt] = OPEN;
        }
        if pts.is_empty() {
            return Ok(true);
        }
        // stick candidates: friction and no sliding
        let mut stick = std::mem::take(&mut self.ev.stick);
        stick.clear();
        stick.extend(
            pts.iter()
                .copied()
                .filter(|&pt| !matches!(model.contact_of_point(pt).friction, FrictionLaw::None) && self.sliding(pt).1 <= vtol),
        );
        let ok = self.transition_lcp_with(pts, &stick);
        self.ev.stick = stick;
        ok
    }

    fn transition_lcp_with(&mut self, pts: &[usize], stick: &[usize]) -> Result<bool> {
        let (model, nu, d) = (self.model, self.model.nu, self.d);
        let kdirs = if d == 2 { 2 } else { PYRAMID };
        let (nc, ns) = (pts.len(), stick.len());
        let nb = nc + ns * kdirs; // rows/columns with a force direction
        let n = nb + ns;
        let pyramid = |k: usize| -> [f64; 2] {
            if d == 2 {
                [if k == 0 { 1.0 } else { -1.0 }, 0.0]
            } else {
                let a = 2.0 * std::f64::consts::PI * k as f64 / kdirs as f64;
                [a.cos(), a.sin()]
            }
        };
        for (a, &pt) in pts.iter().enumerate() {
            let kp = self.kin[pt].point;
            Self::put_row(model, &self.data, &self.kin, pt, &kp.n, &mut self.rows, a);
            let col = if stick.contains(&pt) {
                kp.n
            } else {
                let (g, s) = self.sliding(pt);
                let mu = self.mu_sliding(pt);
                if s > 0.0 {
                    kp.n - self.tangent(pt, [g[0] / s, g[1] / s]) * mu
                } else {
                    kp.n
                }
            };
            Self::put_row(model, &self.data, &self.kin, pt, &col, &mut self.cols, a);
        }
        for (b, &pt) in stick.iter().enumerate() {
            for k in 0..kdirs {
                let dir = self.tangent(pt, pyramid(k));
                let r = nc + b * kdirs + k;
                Self::put_row(model, &self.data, &self.kin, pt, &dir, &mut self.rows, r);
                Self::put_row(model, &self.data, &self.kin, pt, &dir, &mut self.cols, r);
            }
        }
        self.solve_columns(nb);
        let m = &mut self.lcp.m;
        m.clear();
        m.resize(n * n, 0.0);
        self.lcp.q.clear();
        self.lcp.q.resize(n, 0.0);
        for i in 0..nb {
            for j in 0..nb {
                let v: f64 = {
                    let x = &self.x[j * nu..(j + 1) * nu];
                    (0..nu).map(|c| self.rows[(i, c)] * x[c]).sum()
                };
                self.lcp.m[i * n + j] = v;
            }
            let ra: f64 = (0..nu).map(|c| self.rows[(i, c)] * self.a_free[c]).sum();
            let wbar = if i < nc {
                self.kin[pts[i]].wbar_n
            } else {
                let (b, k) = ((i - nc) / kdirs, (i - nc) % kdirs);
                let pd = pyramid(k);
                let w = self.kin[stick[b]].wbar_t;
                pd[0] * w[0] + pd[1] * w[1]
            };
            self.lcp.q[i] = ra + wbar;
        }
        for (b, &pt) in stick.iter().enumerate() {
            let g = nb + b;
            let a = pts.iter().position(|&p| p == pt).unwrap_or(0);
            for k in 0..kdirs {
                let r = nc + b * kdirs + k;
                self.lcp.m[r * n + g] = 1.0; // γ: the sliding acceleration
                self.lcp.m[g * n + r] = -1.0;
            }
            self.lcp.m[g * n + a] = model.contact_of_point(pt).friction.mu0();
        }
        if self.lcp.q.iter().chain(self.lcp.m.iter()).any(|v| !v.is_finite()) {
            return Err(Error::Solver("the transition problem has non-finite entries".into()));
        }
        let method = Method::lemke();
        self.ws.reserve(&self.lcp, &method)?;
        self.z.clear();
        self.z.resize(n, 0.0);
        let ok = match solver::solve(&self.lcp, &method, &mut self.z, false, &mut self.ws) {
            Ok(r) => r.converged,
            Err(Error::Solver(_)) => false,
            Err(e) => return Err(e),
        };
        if !ok {
            return Ok(false);
        }
        let scale = 1e-12 * (1.0 + self.z[..nc].iter().fold(0.0f64, |a, v| a.max(v.abs())));
        let qscale = 1e-9 * (1.0 + self.lcp.q.iter().fold(0.0f64, |a, v| a.max(v.abs())));
        for (a, &pt) in pts.iter().enumerate() {
            // opens: no normal force and a separating acceleration; a point with neither (one of
            // redundant supports that Lemke's basic solution left unloaded) stays closed and
            // shares the load in the smooth phase's minimum-norm forces
            let acc: f64 = (0..n).map(|j| self.lcp.m[a * n + j] * self.z[j]).sum::<f64>() + self.lcp.q[a];
            if self.z[a] <= scale && acc > qscale {
                continue;
            }
            match stick.iter().position(|&p| p == pt) {
                Some(b) => {
                    let gamma = self.z[nb + b];
                    let gscale = 1e-12 * (1.0 + self.lcp.q.iter().fold(0.0f64, |a, v| a.max(v.abs())));
                    if gamma <= gscale {
                        self.status[pt] = STICK;
                    } else {
                        // sliding starts against the friction force the pyramid found
                        let mut f = [0.0; 2];
                        for k in 0..kdirs {
                            let pd = pyramid(k);
                            let beta = self.z[nc + b * kdirs + k];
                            f[0] += beta * pd[0];
                            f[1] += beta * pd[1];
                        }
                        let s = (f[0] * f[0] + f[1] * f[1]).sqrt();
                        self.status[pt] = SLIP;
                        self.dir[pt] = if s > 0.0 { [-f[0] / s, -f[1] / s] } else { [1.0, 0.0] };
                    }
                }
                None => {
                    let (g, s) = self.sliding(pt);
                    self.status[pt] = SLIP;
                    self.dir[pt] = if s > 0.0 { [g[0] / s, g[1] / s] } else { [1.0, 0.0] };
                }
            }
        }
        Ok(true)
    }

    /// Closed points keep the relative velocities the transition took as zero (up to
    /// `velocity_tol`): a small impulse makes them exactly zero (normal, and tangential for
    /// sticking points), so that a resting contact does not creep apart or slide.
    fn settle(&mut self, u: &mut [f64], imp: &mut [f64]) -> Dissipation {
        let (model, nu, np) = (self.model, self.model.nu, self.status.len());
        self.unk.clear();
        for pt in 0..np {
            if self.status[pt] != OPEN {
                self.unk.push((pt, 0));
                if self.status[pt] == STICK {
                    for k in 1..self.d {
                        self.unk.push((pt, k));
                    }
                }
            }
        }
        let n = self.unk.len();
        let mut diss = Dissipation::default();
        if n == 0 {
            return diss;
        }
        for j in 0..n {
            let (pt, k) = self.unk[j];
            let kp = self.kin[pt].point;
            let dir = [kp.n, kp.t1, kp.t2][k];
            Self::put_row(model, &self.data, &self.kin, pt, &dir, &mut self.rows, j);
            Self::put_row(model, &self.data, &self.kin, pt, &dir, &mut self.cols, j);
        }
        self.solve_columns(n);
        for i in 0..n {
            for j in 0..n {
                self.mat[i * n + j] = self.coupling(i, j);
            }
            self.rhs[i] = -(0..nu).map(|c| self.rows[(i, c)] * u[c]).sum::<f64>();
        }
        let mut before = std::mem::take(&mut self.ev.before);
        before.clear();
        before.extend(self.rhs[..n].iter().map(|v| -v));
        solve_min_norm(&self.mat[..n * n], n, &mut self.rhs[..n], &mut self.aat, &mut self.piv_r, &mut self.piv_c_work, 1e-13);
        for j in 0..n {
            let l = self.rhs[j];
            let x = &self.x[j * nu..(j + 1) * nu];
            for i in 0..nu {
                u[i] += x[i] * l;
            }
            let (pt, k) = self.unk[j];
            imp[3 * pt + k] += l;
            let after: f64 = (0..nu).map(|c| self.rows[(j, c)] * u[c]).sum();
            let e = -l * 0.5 * (before[j] + after);
            if k == 0 {
                diss.impact += e;
            } else {
                diss.friction += e;
            }
        }
        self.ev.before = before;
        diss
    }

    /// Everything that happens at an event at (t, y): impacts, then the new contact structure.
    /// Impulses are added to `imp`; warnings (a Painlevé situation passed) to `warnings`.
    pub fn transition(&mut self, t: f64, y: &mut [f64], imp: &mut [f64], warnings: &mut Vec<String>) -> Result<Dissipation> {
        let mut ev = std::mem::take(&mut self.ev);
        let (mut touching, mut closing) = (std::mem::take(&mut ev.touching), std::mem::take(&mut ev.closing));
        let (mut old, mut old_dir) = (std::mem::take(&mut ev.old), std::mem::take(&mut ev.old_dir));
        self.ev = ev;
        let r = self.transition_with(t, y, imp, warnings, (&mut touching, &mut closing, &mut old, &mut old_dir));
        self.ev.touching = touching;
        self.ev.closing = closing;
        self.ev.old = old;
        self.ev.old_dir = old_dir;
        r
    }

    #[allow(clippy::type_complexity)]
    fn transition_with(
        &mut self,
        t: f64,
        y: &mut [f64],
        imp: &mut [f64],
        warnings: &mut Vec<String>,
        (touching, closing, old, old_dir): (&mut Vec<usize>, &mut Vec<usize>, &mut Vec<f64>, &mut Vec<[f64; 2]>),
    ) -> Result<Dissipation> {
        let (nq, nu, np) = (self.model.nq, self.model.nu, self.model.n_contact_points);
        let vtol = self.opts.velocity_tol;
        let (q, rest) = y.split_at_mut(nq);
        let u = &mut rest[..nu];
        self.free_motion(t, q, u)?;
        touching.clear();
        touching.extend((0..np).filter(|&pt| self.kin[pt].point.g_n <= self.opts.gap_tol));
        old.clear();
        old.extend_from_slice(&self.status);
        old_dir.clear();
        old_dir.extend_from_slice(&self.dir);
        let mut diss = Dissipation::default();
        if touching.iter().any(|&pt| self.kin[pt].gd_n < -vtol) {
            for &pt in touching.iter() {
                if self.kin[pt].gd_n < -vtol {
                    self.log.push((t, pt, "impact"));
                }
            }
            let d = self.impact(t, u, touching, false, imp)?;
            diss.impact += d.impact;
            diss.friction += d.friction;
            self.free_motion(t, q, u)?;
        }
        closing.clear();
        closing.extend(touching.iter().copied().filter(|&pt| self.kin[pt].gd_n.abs() <= vtol));
        if !self.transition_lcp(closing)? {
            let names = self.names(closing);
            if !self.opts.continue_on_painleve {
                return Err(Error::Solver(format!(
                    "Painlevé situation at t = {t:.9} s: the contact problem of {names:?} has no solution at acceleration level (sliding friction too large for the geometry); set continue_on_painleve to stop the sliding by an impulse and go on"
                )));
            }
            warnings.push(format!(
                "Painlevé situation at t = {t:.9} s in contacts {names:?}: the sliding was stopped by an impulse (an impact without collision)"
            ));
            let d = self.impact(t, u, closing, true, imp)?;
            diss.impact += d.impact;
            diss.friction += d.friction;
            self.free_motion(t, q, u)?;
            closing.retain(|&pt| self.kin[pt].gd_n.abs() <= vtol);
            if !self.transition_lcp(closing)? {
                return Err(Error::Solver(format!(
                    "Painlevé situation at t = {t:.9} s: the contact problem of {names:?} has no solution even after an impulsive stop"
                )));
            }
        }
        let d = self.settle(u, imp);
        diss.impact += d.impact;
        diss.friction += d.friction;
        for pt in 0..np {
            let (was, now) = (old[pt], self.status[pt]);
            let (a, b) = (old_dir[pt], self.dir[pt]);
            let reversed = was == SLIP && now == SLIP && a[0] * b[0] + a[1] * b[1] < 0.0;
            if was != now || reversed {
                let what = if now == OPEN {
                    "open"
                } else if was == OPEN {
                    "close"
                } else if now == STICK {
                    "stick"
                } else {
                    "slip"
                };
                self.log.push((t, pt, what));
            }
        }
        Ok(diss)
    }
}

impl OdeSystem for Phase<'_> {
    fn dim(&self) -> usize {
        self.state_len()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        let (nq, nu, np) = (self.model.nq, self.model.nu, self.model.n_contact_points);
        let (q, rest) = y.split_at(nq);
        let u = &rest[..nu];
        let p = self.evaluate(t, q, u)?;
        self.model.qdot(q, u, &mut dy[..nq]);
        dy[nq..nq + nu].copy_from_slice(&self.data.udot);
        let e = nq + nu;
        dy[e] = p.dissipated;
        dy[e + 1] = p.external;
        dy[e + 2] = self.friction_power;
        for pt in 0..np {
            dy[e + 3 + pt] = self.lam_n[pt];
            dy[e + 3 + np + 2 * pt] = self.lam_t[pt][0];
            dy[e + 3 + np + 2 * pt + 1] = self.lam_t[pt][1];
        }
        Ok(())
    }
    fn accepted(&mut self, t: f64, y: &mut [f64]) -> Result<()> {
        let (nq, nu) = (self.model.nq, self.model.nu);
        if self.model.n_sliders > 0 {
            y[nq + nu] += crate::forces::jenkins::commit(self.model, &mut self.data, &y[..nq], t)?;
        }
        Ok(())
    }
    fn project(&mut self, t: f64, y: &mut [f64]) -> Result<()> {
        let (nq, nu) = (self.model.nq, self.model.nu);
        self.model.normalize(&mut y[..nq]);
        if self.model.nc > 0 {
            let (q, rest) = y.split_at_mut(nq);
            crate::dynamics::constrained::project(self.model, &mut self.data, t, q, &mut rest[..nu], self.cb)?;
        }
        Ok(())
    }
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
    let mut st = Step::new(n);
    let mut yout = vec![0.0; n];
    let mut scratch = vec![0.0; n];
    let mut imp = vec![0.0; 3 * np];
    let mut diss = Dissipation::default();
    let (mut e_start, mut e_end, mut e_try) = (vec![0.0; 2 * np], vec![0.0; 2 * np], vec![0.0; 2 * np]);
    let mut t = t0;
    let mut next = 0usize;
    let mut events = 0usize;
    let (mut last_event, mut same_instant) = (f64::NEG_INFINITY, 0usize);

    phase.project(t, &mut y)?;
    let d = phase.transition(t, &mut y, &mut imp, warnings)?;
    diss.impact += d.impact;
    diss.friction += d.friction;
    phase.rhs(t, &y, &mut st.k[0])?;
    phase.event_values(&mut e_start);
    let mut cap = phase.after_step()?;
    while next < t_out.len() && t_out[next] <= t {
        sample(phase, t, &y, &imp, diss)?;
        imp.fill(0.0);
        diss = Dissipation::default();
        next += 1;
    }
    let mut h = {
        let (k0, rest) = st.k.split_at_mut(1);
        dopri5::starting_step(phase, t, &y, &k0[0], opts.rtol, opts.atol, hmax, (&mut scratch, &mut rest[0]))?
    };
    let mut err_old: f64 = 1e-4;
    let mut reject = false;
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
        if h < 1e-15 * t.abs().max(t_end - t0) {
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
        for i in 0..2 * np {
            if e_start[i] > 0.0 && e_end[i] <= 0.0 {
                let th = locate(phase, &st, (t, h), (i, e_start[i], e_end[i]), &mut yout, &mut e_try, &mut scratch)?;
                stats.evaluations += 1;
                theta = theta.min(th);
            }
        }
        let t_new = if theta.is_finite() { t + theta * h } else { t + h };
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
                let what: Vec<usize> = (0..np).filter(|&pt| phase.status[pt] != OPEN || phase.kin[pt].point.g_n <= opts.gap_tol).collect();
                return Err(Error::Solver(format!(
                    "{} events by t = {t:.9} s (contacts {:?}): an accumulation the event-driven scheme cannot pass; raise velocity_tol or use MoreauJean",
                    events,
                    phase.names(&what)
                )));
            }
            let d = phase.transition(t, &mut y, &mut imp, warnings)?;
            diss.impact += d.impact;
            diss.friction += d.friction;
            phase.rhs(t, &y, &mut st.k[0])?;
            stats.evaluations += 1;
            phase.event_values(&mut e_start);
            cap = phase.after_step()?;
            // samples at exactly the event time see the state after it
            while next < t_out.len() && t_out[next] <= t {
                sample(phase, t_out[next], &y, &imp, diss)?;
                imp.fill(0.0);
                diss = Dissipation::default();
                next += 1;
            }
            reject = false;
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
        let closes: Vec<f64> = rec.events.iter().filter(|e| e.3 == "close").map(|e| e.0).collect();
        assert_eq!(closes.len(), 1);
        assert!((closes[0] - t_inf).abs() < 1e-9 * t_inf, "{} vs {t_inf}", closes[0]);
        // resting: λ_N = m g at the last sample, state stick (frictionless, not sliding)
        let last = rec.contact_lambda_n.last().unwrap();
        assert!((last - 2.0 * 9.81).abs() < 1e-10, "{last}");
        assert_eq!(*rec.contact_state.last().unwrap(), super::STICK);
    }

    #[test]
    fn sliding_stops_at_the_closed_form_time() {
        // landing flat (h0 = 0) at vx = 1 m/s with mu = 0.5: it stops at v / (mu g), after
        // sliding v² / (2 mu g), and the friction took m v² / 2
        let m = drop(0.0, 0.0, 1.0, 0.5);
        let rec = simulate(&m, &settings(0.5, Options::default()), &NoCallbacks, None).unwrap();
        let stick: Vec<f64> = rec.events.iter().filter(|e| e.3 == "stick").map(|e| e.0).collect();
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
