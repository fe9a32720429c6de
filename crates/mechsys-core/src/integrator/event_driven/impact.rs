//! Impacts at an event (Newton's and Poisson's laws, eqs. 2.202, 2.203) and the settling impulse of closed points.

use super::{Dissipation, Phase};
use crate::error::{Error, Result};
use crate::integrator::moreau_jean::{OPEN, STICK};
use crate::math::linalg::solve_min_norm;
use crate::model::contact::{FrictionLaw, ImpactLaw};
use crate::solver::{self, Delassus, Method};

impl Phase<'_> {
    /// The impact at an event: one impulse problem over the touching points `pts` (Newton's or
    /// Poisson's law per contact), `u` updated. Impulses are added to `imp` (3 per point).
    pub(super) fn impact(
        &mut self,
        t: f64,
        u: &mut [f64],
        pts: &[usize],
        plastic: bool,
        imp: &mut [f64],
    ) -> Result<Dissipation> {
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
            // ġ = Wᵀu + w̃ (a moving surface's speed in the tangential rows)
            *b = (0..nu).map(|i| self.rows[(a, i)] * u[i]).sum::<f64>() + self.surface_rate(pts[a / d], a % d);
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
            Method::Newton(solver::NewtonOptions { tol: 1e-13, max_iter: 500, ..Default::default() })
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
            // (the contact points' coordinates set the round-off of a contour pair's gap; a gap
            // function's points are its fixed frame's origin, its gap a function of the
            // coordinates: a round-off of about ε)
            let scale = if con.gap().is_some() {
                1.0
            } else {
                [kp.p1.amax(), kp.p2.amax(), self.data.x_abs[con.body1].r.amax(), self.data.x_abs[con.body2].r.amax()]
                    .iter()
                    .fold(1e-300f64, |a, b| a.max(*b))
            };
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
        for &pt in pts {
            ev.point_energy[pt] = 0.0;
        }
        for a in 0..dm {
            // ġ⁺ with the rheonomic part, as ġ⁻; what drives that part works by -Λ w̃
            let w = self.surface_rate(pts[a / d], a % d);
            let after: f64 = (0..nu).map(|i| self.rows[(a, i)] * u[i]).sum::<f64>() + w;
            diss.external -= total[a] * w;
            let e = -total[a] * 0.5 * (after + before[a]);
            ev.point_energy[pts[a / d]] += e;
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

    pub(super) fn solve_fc(&mut self, t: f64, pts: &[usize], method: &Method, x: &mut [f64]) -> Result<()> {
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

    /// The rheonomic part `w̃` of relative velocity `k` (0 normal, 1–2 tangential) of point `pt`:
    /// a moving surface's speed or a user gap's `∂g/∂t` (eq. 2.112); zero otherwise.
    #[inline]
    fn surface_rate(&self, pt: usize, k: usize) -> f64 {
        self.kin[pt].w_tilde[k]
    }

    /// Closed points keep the relative velocities the transition took as zero (up to
    /// `velocity_tol`): a small impulse makes them exactly zero (normal, and tangential for
    /// sticking points), so that a resting contact does not creep apart or slide.
    pub(super) fn settle(&mut self, u: &mut [f64], imp: &mut [f64]) -> Dissipation {
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
        for &(pt, _) in &self.unk {
            self.ev.point_energy[pt] = 0.0;
        }
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
            let (pt, k) = self.unk[i];
            self.rhs[i] = -(0..nu).map(|c| self.rows[(i, c)] * u[c]).sum::<f64>() - self.surface_rate(pt, k);
        }
        let mut before = std::mem::take(&mut self.ev.before);
        before.clear();
        before.extend(self.rhs[..n].iter().map(|v| -v));
        solve_min_norm(
            &self.mat[..n * n],
            n,
            &mut self.rhs[..n],
            &mut self.aat,
            &mut self.piv_r,
            &mut self.piv_c_work,
            1e-13,
        );
        for j in 0..n {
            let l = self.rhs[j];
            let x = &self.x[j * nu..(j + 1) * nu];
            for i in 0..nu {
                u[i] += x[i] * l;
            }
        }
        // the energy taken, -Λᵀ(ġ⁻ + ġ⁺)/2, with ġ⁺ after all the impulses
        for j in 0..n {
            let l = self.rhs[j];
            let (pt, k) = self.unk[j];
            imp[3 * pt + k] += l;
            let w = self.surface_rate(pt, k);
            let after: f64 = (0..nu).map(|c| self.rows[(j, c)] * u[c]).sum::<f64>() + w;
            diss.external -= l * w;
            let e = -l * 0.5 * (before[j] + after);
            self.ev.point_energy[pt] += e;
            if k == 0 {
                diss.impact += e;
            } else {
                diss.friction += e;
            }
        }
        self.ev.before = before;
        diss
    }
}
