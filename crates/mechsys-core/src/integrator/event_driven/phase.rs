//! The smooth phase: the motion with a fixed contact structure, its forces and its event functions.

use nalgebra::DMatrix;

use super::{EventWork, Options, Phase, JAM, PYRAMID};
use crate::contact::{
    at_contact, contact_kinematics_warm, contact_point_kinematics, gap_with_accelerations, BodyMotion,
    ContactKinematics,
};
use crate::data::Data;
use crate::dynamics::sparse::Saddle;
use crate::error::{Error, Result};
use crate::forces::{Callbacks, Powers};
use crate::integrator::events::EventLog;
use crate::integrator::moreau_jean::{OPEN, SLIP, STICK};
use crate::integrator::OdeSystem;
use crate::math::linalg::{cholesky_semidefinite, solve_min_norm};
use crate::math::Vec3;
use crate::model::contact::FrictionLaw;
use crate::model::Model;
use crate::solver::{Delassus, FrictionContact, Lcp, Workspace};
use crate::spatial::Motion;

impl<'a> Phase<'a> {
    /// A phase for `model` with every point open.
    pub fn new(model: &'a Model, cb: &'a dyn Callbacks, opts: Options) -> Result<Self> {
        opts.validate()?;
        let (nu, np) = (model.nu, model.n_contact_points);
        let d = if model.contacts.iter().all(|c| c.is_planar()) { 2 } else { 3 };
        // the LCP has at most np (1 + K + 1) unknowns
        let k = if d == 2 { 2 } else { PYRAMID };
        let rmax = (np * (k + 1)).max(d * np).max(1);
        Ok(Phase {
            model,
            cb,
            opts,
            data: Data::new(model),
            dynamics: crate::dynamics::Workspace::new(model),
            quats: crate::simulate::quaternion_offsets(model),
            d,
            status: vec![OPEN; np],
            dir: vec![[0.0; 2]; np],
            gap_offset: vec![0.0; np],
            slip_margin: vec![1.0; np],
            slip_margin_start: vec![1.0; np],
            kin: vec![ContactKinematics::default(); np],
            search: vec![crate::contact::SearchHint::default(); np],
            warm_search: true,
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
            null: vec![0.0; rmax + np],
            a_free: vec![0.0; nu],
            tmp: vec![0.0; nu],
            evaluations: 0,
            log: EventLog::default(),
            compliant_changes: Vec::new(),
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
                leaving: vec![false; np],
                breaking: vec![false; np],
                lam_t_before: vec![[0.0; 2]; np],
                point_energy: vec![0.0; np],
                imp_before: vec![0.0; 3 * np],
                hit: Vec::with_capacity(np),
                u_before: vec![0.0; model.nu],
                painleve: Vec::with_capacity(np),
                jam: vec![false; np],
                apex: vec![ContactKinematics::default(); model.contacts.iter().map(|c| c.points()).max().unwrap_or(0)],
            },
        })
    }

    /// Length of the integrated state: q, u, the three energy integrals, the contact forces'
    /// time integrals, then the compliant contacts' extra states.
    pub fn state_len(&self) -> usize {
        self.compliant_offset() + crate::model::compliant::STATES_PER_POINT * self.model.n_compliant_points
    }

    /// Where the compliant contacts' extra states (dissipated energy, bristles) start in the state.
    pub fn compliant_offset(&self) -> usize {
        self.model.nq + self.model.nu + 3 + 3 * self.model.n_contact_points
    }

    /// The compliant contacts at the state `y` of time `t`: the approach speeds of those closed
    /// (their histories), without an event. Called once before the first step.
    pub fn commit_compliant(&mut self, t: f64, y: &mut [f64]) -> Result<()> {
        if self.model.n_compliant_points == 0 {
            return Ok(());
        }
        let (nq, nu) = (self.model.nq, self.model.nu);
        let (head, aux) = y.split_at_mut(self.compliant_offset());
        crate::kinematics::forward_pass(self.model, &mut self.data, t, &head[..nq], &head[nq..nq + nu]);
        let w = &mut self.dynamics.forces.compliant;
        crate::forces::compliant::commit(self.model, &self.data, w, t, aux)?;
        for &(slot, closed) in &w.changed {
            self.compliant_changes.push((t, slot, closed));
        }
        Ok(())
    }

    /// The motion without contact forces: kinematics, smooth forces, the mass matrix factored,
    /// the accelerations `a_free` under the bilateral constraints, and every point's kinematics
    /// with `w̄` (velocity-product accelerations in `data.a`).
    pub(super) fn free_motion(&mut self, t: f64, q: &[f64], u: &[f64]) -> Result<Powers> {
        let (model, nc) = (self.model, self.model.nc);
        let (data, ws) = (&mut self.data, &mut self.dynamics);
        let mut p = crate::dynamics::prepare(model, data, ws, t, q, u, self.cb)?;
        let sp = &mut ws.saddle;
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
            let Data { inertia, s, ic, elastic, .. } = &mut *data;
            crate::dynamics::crba::composite_inertias(model, inertia, s, ic, elastic, |r, col, v| {
                sp.put_mass(r, col, v)
            });
        }
        if !sp.factor_mass() {
            self.a_free = c;
            return Err(Error::Solver(format!(
                "the mass matrix is singular at t = {t:.6} s{}",
                crate::elastic::runaway(model, data)
            )));
        }
        sp.solve_mass(&mut c);
        if nc > 0 {
            sp.gather_g(&data.g);
            sp.assemble_schur(true);
            if !sp.factor_schur(1e-12) {
                self.a_free = c;
                return Err(Error::Settings(format!(
                    "integrator: the event-driven scheme needs independent bilateral constraints; they are redundant at t = {t:.6} s (use MoreauJean)"
                )));
            }
            sp.g_times(&c, &mut data.lambda);
            for r in 0..nc {
                data.lambda[r] = data.gamma[r] - data.lambda[r];
            }
            sp.solve_schur(&mut data.lambda);
            sp.add_constraint_accelerations(&data.lambda, &mut c);
            for k in 0..nc {
                p.external += data.lambda[k] * data.b[k];
            }
        }
        self.a_free = c;
        for con in &model.contacts {
            let pts = con.first..con.first + con.points();
            let s = self.warm_search.then(|| &mut self.search[pts.clone()]);
            contact_point_kinematics(con, data, t, q, u, self.cb, &mut self.kin[pts], s)
                .map_err(|e| at_contact(e, &con.name, t))?;
        }
        Ok(p)
    }

    /// `x ← M̃⁻¹ x`: the accelerations a generalized force `x` causes under the bilateral
    /// constraints; `lambda`, if given, receives the multipliers it adds.
    pub(super) fn inverse_mass(data: &mut Data, sp: &mut Saddle, nc: usize, x: &mut [f64], lambda: Option<&mut [f64]>) {
        crate::dynamics::constrained::tangent_inverse_mass(data, sp, nc, x, lambda);
    }

    /// Generalized direction of a force `dir` at point `pt` (body 1 pushed along `dir`, body 2
    /// back) into row `r` of `m`.
    pub(super) fn put_row(
        model: &Model,
        data: &Data,
        kin: &[ContactKinematics],
        pt: usize,
        dir: &Vec3,
        m: &mut DMatrix<f64>,
        r: usize,
    ) {
        for i in 0..model.nu {
            m[(r, i)] = 0.0;
        }
        let con = model.contact_of_point(pt);
        if let Some((_, slot)) = con.gap() {
            // a gap function's rows, combined along the direction's parts in its fixed frame
            let nu = model.nu;
            let rows = &data.gap.rows[3 * slot * nu..3 * (slot + 1) * nu];
            for (k, c) in [dir.z, dir.x, dir.y].into_iter().enumerate() {
                for i in 0..nu {
                    m[(r, i)] += c * rows[k * nu + i];
                }
            }
            return;
        }
        let k = &kin[pt].point;
        crate::constraints::add_relative_rows(
            model,
            &data.s,
            (&data.x_abs, &data.elastic, &data.body_elastic),
            (con.body1, &k.p1),
            (con.body2, &k.p2),
            Some(dir),
            m,
            r,
        );
    }

    /// World tangent direction of (t1, t2) components `c` at point `pt`.
    pub(super) fn tangent(&self, pt: usize, c: [f64; 2]) -> Vec3 {
        let k = &self.kin[pt].point;
        k.t1 * c[0] + if self.d == 3 { k.t2 * c[1] } else { Vec3::zeros() }
    }

    /// Sliding velocity (t1, t2 components; t2 = 0 for planar pairs) and speed of point `pt`.
    pub(super) fn sliding(&self, pt: usize) -> ([f64; 2], f64) {
        let g = self.kin[pt].gd_t;
        let g = if self.d == 3 { g } else { [g[0], 0.0] };
        (g, (g[0] * g[0] + g[1] * g[1]).sqrt())
    }

    /// Unit sliding direction of a slipping point: the current one above `velocity_tol`, else the
    /// one the last transition found (sliding starts from rest along the relative acceleration).
    pub(super) fn slip_direction(&self, pt: usize) -> [f64; 2] {
        let (g, s) = self.sliding(pt);
        if s > self.opts.velocity_tol {
            [g[0] / s, g[1] / s]
        } else {
            self.dir[pt]
        }
    }

    pub(super) fn mu_sliding(&self, pt: usize) -> f64 {
        let (_, s) = self.sliding(pt);
        match &self.model.contact_of_point(pt).friction {
            FrictionLaw::None => 0.0,
            law => law.mu(s.max(f64::MIN_POSITIVE)),
        }
    }

    /// `M̃⁻¹` times the first `n` rows of `cols` into `x`.
    pub(super) fn solve_columns(&mut self, n: usize) {
        let nu = self.model.nu;
        for j in 0..n {
            let x = &mut self.x[j * nu..(j + 1) * nu];
            for i in 0..nu {
                x[i] = self.cols[(j, i)];
            }
            Self::inverse_mass(&mut self.data, &mut self.dynamics.saddle, self.model.nc, x, None);
        }
    }

    /// `rows_i · x_j`.
    pub(super) fn coupling(&self, i: usize, j: usize) -> f64 {
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
            self.slip_margin[pt] = 1.0;
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
            solve_min_norm(
                &self.mat[..n * n],
                n,
                &mut self.rhs[..n],
                &mut self.aat,
                &mut self.piv_r,
                &mut self.piv_c_work,
                1e-13,
            );
            for (j, &(pt, k)) in self.unk.iter().enumerate() {
                if k == 0 && self.status[pt] == SLIP {
                    self.slip_margin[pt] = self.mat[j * n + j];
                }
            }
            if self.unk.iter().any(|&(_, k)| k > 0) {
                self.redistribute(n);
            }
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
                Self::inverse_mass(&mut self.data, &mut self.dynamics.saddle, model.nc, &mut f, Some(&mut lam));
                self.data.lambda = lam;
                self.tmp = f;
            }
        }
        self.data.a[0] = Motion::ZERO;
        crate::kinematics::accelerations(model, &mut self.data, &udot);
        self.data.udot = udot;
        Ok(p)
    }

    /// Sticking points can be statically indeterminate (two corners of a sleeve jammed on a
    /// pole): the forces in `rhs[..n]` are then fixed only up to a distribution that moves
    /// nothing. The minimum-norm one is kept while every friction reserve and normal force it
    /// gives is positive; once it is not, and one free distribution remains (`M̃⁻¹` times the
    /// force directions has a null space of dimension one), the one that maximizes the smallest
    /// of them is taken, so that the phase ends (a reserve or a normal force reaches zero) only
    /// when no admissible distribution is left. Larger null spaces keep the minimum norm.
    fn redistribute(&mut self, n: usize) {
        let nu = self.model.nu;
        // (checked first: this runs at every evaluation of a sticking phase, and the minimum-norm
        // forces are admissible in all but the jammed ones)
        if self.smallest_margin(n, 0.0) > 0.0 {
            return;
        }
        // Gram matrix of the accelerations each force direction causes
        for i in 0..n {
            for j in 0..=i {
                let v: f64 = (0..nu).map(|c| self.x[i * nu + c] * self.x[j * nu + c]).sum();
                self.aat[i * n + j] = v;
                self.aat[j * n + i] = v;
            }
        }
        let rank = cholesky_semidefinite(&mut self.aat[..n * n], n, &mut self.piv_r, 1e-10);
        if rank + 1 != n {
            return;
        }
        // null vector: in pivoted order [x; 1] with L11ᵀ x = -l21
        let a = &self.aat;
        let w = &mut self.piv_c_work;
        for r in 0..rank {
            w[r] = -a[(n - 1) * n + r];
        }
        for r in (0..rank).rev() {
            let mut s = w[r];
            for c in r + 1..rank {
                s -= a[c * n + r] * w[c];
            }
            w[r] = s / a[r * n + r];
        }
        w[rank] = 1.0;
        let norm = w[..n].iter().map(|v| v * v).sum::<f64>().sqrt();
        for i in 0..n {
            self.null[self.piv_r[i]] = w[i] / norm;
        }
        // the smallest margin is concave in the amount s of the null distribution: golden section
        let scale = 1.0 + self.rhs[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (mut lo, mut hi) = (-1e3 * scale, 1e3 * scale);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        let (mut f1, mut f2) = (self.smallest_margin(n, x1), self.smallest_margin(n, x2));
        for _ in 0..200 {
            if hi - lo <= 1e-15 * scale {
                break;
            }
            if f1 < f2 {
                lo = x1;
                x1 = x2;
                f1 = f2;
                x2 = lo + g * (hi - lo);
                f2 = self.smallest_margin(n, x2);
            } else {
                hi = x2;
                x2 = x1;
                f2 = f1;
                x1 = hi - g * (hi - lo);
                f1 = self.smallest_margin(n, x1);
            }
        }
        let s = 0.5 * (lo + hi);
        if s.abs() > 0.999e3 * scale {
            // unbounded (an internal squeeze that only adds reserve): keep the minimum norm
            return;
        }
        for j in 0..n {
            self.rhs[j] += s * self.null[j];
        }
    }

    /// The smallest normal force and friction reserve of the forces `rhs + s · null`.
    fn smallest_margin(&self, n: usize, s: f64) -> f64 {
        let mut m = f64::INFINITY;
        let mut j = 0;
        while j < n {
            let (pt, _) = self.unk[j];
            let lam_n = self.rhs[j] + s * self.null[j];
            m = m.min(lam_n);
            if self.status[pt] == STICK {
                let mut t2 = 0.0;
                for k in 1..self.d {
                    let v = self.rhs[j + k] + s * self.null[j + k];
                    t2 += v * v;
                }
                m = m.min(self.model.contact_of_point(pt).friction.mu0() * lam_n - t2.sqrt());
                j += self.d;
            } else {
                j += 1;
            }
        }
        m
    }

    /// Event functions of the last evaluation, three per point (the gap or the normal force; the
    /// friction reserve or the sliding velocity; a sliding point's normal acceleration per unit
    /// normal force, whose zero is a Painlevé situation); an event is a sign change from positive
    /// to non-positive.
    pub fn event_values(&self, out: &mut [f64]) {
        for pt in 0..self.status.len() {
            out[3 * pt + 2] = if self.status[pt] == SLIP && self.slip_margin_start[pt] > 0.0 {
                self.slip_margin[pt] - JAM * self.slip_margin_start[pt]
            } else {
                1.0
            };
            let (e0, e1) = if self.status[pt] == OPEN {
                (self.kin[pt].point.g_n + self.gap_offset[pt], 1.0)
            } else if self.status[pt] == STICK {
                let lt = (self.lam_t[pt][0].powi(2) + self.lam_t[pt][1].powi(2)).sqrt();
                (self.lam_n[pt], self.model.contact_of_point(pt).friction.mu0() * self.lam_n[pt] - lt)
            } else if self.mu_sliding(pt) > 0.0 {
                let (g, _) = self.sliding(pt);
                (self.lam_n[pt], g[0] * self.dir[pt][0] + g[1] * self.dir[pt][1])
            } else {
                (self.lam_n[pt], 1.0)
            };
            // a closed point whose normal jumps (a mesh's concave edge, where the nearest face
            // changes) starts to approach: an event, which the impact step resolves like any
            // touching approach; a closed point otherwise keeps ġ_N ≈ 0 (its g̈_N = 0)
            let e0 = if self.status[pt] == OPEN {
                e0
            } else {
                e0.min(self.kin[pt].gd_n + APPROACH * self.opts.velocity_tol)
            };
            out[3 * pt] = e0;
            out[3 * pt + 1] = e1;
        }
    }

    /// After an accepted step: slipping points remember their current direction, and the step
    /// is capped so that no open point changes its gap unseen: one moving apart cannot come back
    /// within the step (the time to its apex, from `g̈_N` at the step's end), and one approaching
    /// cannot pass through a closed contour (a ball through a sphere, whose gap is positive again
    /// on the far side) — the step ends before the gap, predicted from `g`, `ġ_N` and `g̈_N`,
    /// would reach `-g`, so the crossing is a sign change the event search sees. Uses the last
    /// evaluation.
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
            if !pts.clone().any(|pt| self.status[pt] == OPEN) {
                continue;
            }
            // (every contact's points, not a fixed-size buffer: none may be skipped)
            let k = &mut self.ev.apex;
            let n = con.points();
            if con.gap().is_some() {
                // the last evaluation's velocity-product part and rows, with its accelerations
                k[0] = self.kin[con.first];
                gap_with_accelerations(con, &self.data, &self.data.udot, &mut k[0]);
            } else {
                let (b1, b2) =
                    (BodyMotion::from_data(&self.data, con.body1), BodyMotion::from_data(&self.data, con.body2));
                let s = self.warm_search.then(|| &mut self.search[pts.clone()]);
                contact_kinematics_warm(con.pair().expect("a contour contact"), &b1, &b2, &mut k[..n], s)?;
            }
            for (j, kk) in k[..n].iter().enumerate() {
                let pt = con.first + j;
                if self.status[pt] != OPEN {
                    continue;
                }
                let (g, v, a) = (kk.point.g_n, kk.gd_n, kk.wbar_n);
                if v > 0.0 && a < 0.0 {
                    cap = cap.min(v / -a);
                }
                if g > 0.0 {
                    cap = cap.min(time_to_gap(g, v, a, -g));
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

    pub(super) fn names(&self, pts: &[usize]) -> Vec<String> {
        let mut v: Vec<String> = pts.iter().map(|&pt| self.model.contact_of_point(pt).name.clone()).collect();
        v.dedup();
        v
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
        let aux = self.compliant_offset();
        if self.model.n_compliant_points > 0 {
            self.dynamics.forces.compliant.states.copy_from_slice(&y[aux..]);
        }
        let p = self.evaluate(t, q, u)?;
        self.model.qdot(q, u, &mut dy[..nq]);
        dy[nq..nq + nu].copy_from_slice(&self.data.udot);
        let e = nq + nu;
        dy[e] = p.dissipated;
        // a moving surface (conveyor) or a time-dependent gap works on the system through the
        // contact forces: -λᵀ w̃
        let belt: f64 = (0..np)
            .map(|pt| {
                let w = self.kin[pt].w_tilde;
                -(self.lam_n[pt] * w[0] + self.lam_t[pt][0] * w[1] + self.lam_t[pt][1] * w[2])
            })
            .sum();
        dy[e + 1] = p.external + belt;
        dy[e + 2] = self.friction_power;
        for pt in 0..np {
            dy[e + 3 + pt] = self.lam_n[pt];
            dy[e + 3 + np + 2 * pt] = self.lam_t[pt][0];
            dy[e + 3 + np + 2 * pt + 1] = self.lam_t[pt][1];
        }
        if self.model.n_compliant_points > 0 {
            dy[aux..].copy_from_slice(&self.dynamics.forces.compliant.rates);
        }
        Ok(())
    }
    fn switches(&self) -> usize {
        crate::forces::compliant::switches(self.model)
    }
    fn switching(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<()> {
        // the compliant contacts' gaps and forces before the cut-off (located like the smooth
        // schemes do, [`crate::integrator::switching`]); the rigid points have event_values
        let (nq, nu) = (self.model.nq, self.model.nu);
        crate::kinematics::forward_pass(self.model, &mut self.data, t, &y[..nq], &y[nq..nq + nu]);
        crate::forces::compliant::switching(
            self.model,
            &self.data,
            &mut self.dynamics.forces.compliant,
            t,
            self.cb,
            out,
        )
    }
    fn accepted(&mut self, t: f64, y: &mut [f64]) -> Result<()> {
        let (nq, nu) = (self.model.nq, self.model.nu);
        if self.model.n_sliders > 0 {
            let chains = &mut self.dynamics.forces.jenkins;
            y[nq + nu] += crate::forces::jenkins::commit(self.model, &mut self.data, chains, &y[..nq], t)?;
        }
        self.commit_compliant(t, y)
    }
    fn quaternions(&self) -> &[usize] {
        &self.quats
    }
    fn project(&mut self, t: f64, y: &mut [f64]) -> Result<()> {
        // (no renormalization: the quaternions are stepped on the rotation group)
        let (nq, nu) = (self.model.nq, self.model.nu);
        if self.model.nc > 0 {
            let (q, rest) = y.split_at_mut(nq);
            crate::dynamics::constrained::project(
                self.model,
                &mut self.data,
                &mut self.dynamics,
                t,
                q,
                &mut rest[..nu],
                self.cb,
            )?;
        }
        Ok(())
    }
}

/// A closed point approaching faster than this many `velocity_tol` is an event (above the
/// approach that closes a contact without impact, so the event's impact step takes it).
const APPROACH: f64 = 10.0;

/// The first time `t > 0` at which `g + v t + a t²/2` reaches `target` (< g), or infinity if it
/// never does.
fn time_to_gap(g: f64, v: f64, a: f64, target: f64) -> f64 {
    // ½ a t² + v t + (g - target) = 0 with g - target > 0
    let c = g - target;
    if a.abs() <= 1e-300 {
        return if v < 0.0 { c / -v } else { f64::INFINITY };
    }
    let disc = v * v - 2.0 * a * c;
    if disc < 0.0 {
        return f64::INFINITY;
    }
    let sq = disc.sqrt();
    // the roots (-v ± sq) / a; the smallest positive one, computed without cancellation
    let q = -0.5 * (v + v.signum() * sq) * 2.0;
    let mut best = f64::INFINITY;
    for t in [q / a, if q != 0.0 { 2.0 * c / q } else { f64::INFINITY }] {
        if t > 0.0 && t < best {
            best = t;
        }
    }
    best
}

#[cfg(test)]
mod gap_time_tests {
    use super::time_to_gap;

    #[test]
    fn time_to_gap_solves_the_quadratic() {
        // falling from rest: 0.25 - 4.905 t² = -0.25
        let t = time_to_gap(0.25, 0.0, -9.81, -0.25);
        assert!((t - (0.5f64 / 4.905).sqrt()).abs() < 1e-14);
        // constant approach speed
        assert!((time_to_gap(0.1, -2.0, 0.0, -0.1) - 0.1).abs() < 1e-15);
        // moving apart and decelerating, comes back
        let t = time_to_gap(0.1, 1.0, -2.0, -0.1);
        assert!((0.1 + t - t * t - (-0.1)).abs() < 1e-14, "{t}");
        // moving apart, accelerating away: never
        assert!(time_to_gap(0.1, 1.0, 2.0, -0.1).is_infinite());
    }
}
