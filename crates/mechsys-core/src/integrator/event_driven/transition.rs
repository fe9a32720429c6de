//! The transition problem at acceleration level (section 2.5.2): which touching points stay closed and which stick.

use super::{Dissipation, Phase, PYRAMID};
use crate::contact::{contact_kinematics, gap_with_accelerations, BodyMotion};
use crate::error::{Error, Result};
use crate::integrator::events::{EventKind, Painleve};
use crate::integrator::moreau_jean::{OPEN, SLIP, STICK};
use crate::model::contact::FrictionLaw;
use crate::solver::{self, Method};

impl Phase<'_> {
    /// The transition problem at acceleration level over the touching points `pts` with zero
    /// normal velocity: sets every point's status. Returns false when it has no solution.
    pub(super) fn transition_lcp(&mut self, pts: &[usize]) -> Result<bool> {
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
        stick.extend(pts.iter().copied().filter(|&pt| {
            !matches!(model.contact_of_point(pt).friction, FrictionLaw::None) && self.sliding(pt).1 <= vtol
        }));
        let ok = self.transition_lcp_with(pts, &stick);
        self.ev.stick = stick;
        ok
    }

    pub(super) fn transition_lcp_with(&mut self, pts: &[usize], stick: &[usize]) -> Result<bool> {
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
        // Painlevé test of the sliding points: the normal acceleration per unit normal force with
        // the sliding friction, c = w_Nᵀ M̃⁻¹ (w_N − µ W_T ŝ); c ≤ 0 is a Painlevé situation, and
        // the critical µ is where it vanishes, µ W_NN / (W_NN − c)
        self.ev.painleve.clear();
        for (a, &pt) in pts.iter().enumerate() {
            if stick.contains(&pt) {
                continue;
            }
            let c = self.lcp.m[a * n + a];
            let kp = self.kin[pt].point;
            let spare = nb;
            Self::put_row(model, &self.data, &self.kin, pt, &kp.n, &mut self.cols, spare);
            let x = &mut self.x[spare * nu..(spare + 1) * nu];
            for i in 0..nu {
                x[i] = self.cols[(spare, i)];
            }
            Self::inverse_mass(&mut self.data, &mut self.dynamics.saddle, model.nc, x, None);
            let w_nn: f64 = (0..nu).map(|i| self.rows[(a, i)] * self.x[spare * nu + i]).sum();
            if c <= 1e-12 * w_nn.abs() || self.ev.jam[pt] {
                let mu = self.mu_sliding(pt);
                let crit = if w_nn - c > 0.0 { mu * w_nn / (w_nn - c) } else { f64::INFINITY };
                self.ev.painleve.push((pt, c, mu, crit, self.lcp.q[a]));
            }
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
            // (a point whose force reached zero at this event leaves unless it must push)
            if self.z[a] <= scale && (acc > qscale || (self.ev.leaving[pt] && acc >= -qscale)) {
                continue;
            }
            match stick.iter().position(|&p| p == pt) {
                Some(b) => {
                    let gamma = self.z[nb + b];
                    let gscale = 1e-12 * (1.0 + self.lcp.q.iter().fold(0.0f64, |a, v| a.max(v.abs())));
                    // (a point whose friction reserve reached zero at this event slides: at the
                    // root the sliding acceleration is zero to round-off)
                    if gamma <= gscale && !self.ev.breaking[pt] {
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
                        let [l1, l2] = self.ev.lam_t_before[pt];
                        let lt = (l1 * l1 + l2 * l2).sqrt();
                        self.dir[pt] = if s > 0.0 {
                            [-f[0] / s, -f[1] / s]
                        } else if lt > 0.0 {
                            [-l1 / lt, -l2 / lt]
                        } else {
                            [1.0, 0.0]
                        };
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

    /// Everything that happens at an event at (t, y): impacts, then the new contact structure.
    /// Impulses are added to `imp`; warnings (a Painlevé situation passed) to `warnings`.
    pub fn transition(
        &mut self,
        t: f64,
        y: &mut [f64],
        imp: &mut [f64],
        warnings: &mut Vec<String>,
        triggered: &[bool],
    ) -> Result<Dissipation> {
        let mut ev = std::mem::take(&mut self.ev);
        let (mut touching, mut closing) = (std::mem::take(&mut ev.touching), std::mem::take(&mut ev.closing));
        let (mut old, mut old_dir) = (std::mem::take(&mut ev.old), std::mem::take(&mut ev.old_dir));
        self.ev = ev;
        let r =
            self.transition_with(t, y, imp, warnings, triggered, (&mut touching, &mut closing, &mut old, &mut old_dir));
        self.ev.touching = touching;
        self.ev.closing = closing;
        self.ev.old = old;
        self.ev.old_dir = old_dir;
        r
    }

    #[allow(clippy::type_complexity)]
    pub(super) fn transition_with(
        &mut self,
        t: f64,
        y: &mut [f64],
        imp: &mut [f64],
        warnings: &mut Vec<String>,
        triggered: &[bool],
        (touching, closing, old, old_dir): (&mut Vec<usize>, &mut Vec<usize>, &mut Vec<f64>, &mut Vec<[f64; 2]>),
    ) -> Result<Dissipation> {
        let (nq, nu, np) = (self.model.nq, self.model.nu, self.model.n_contact_points);
        let vtol = self.opts.velocity_tol;
        let (q, rest) = y.split_at_mut(nq);
        let u = &mut rest[..nu];
        // the forces of the ending phase: a closed point whose normal force reached zero leaves,
        // a sticking one whose friction reserve reached zero breaks away (section 2.5.2); at the
        // located root both are zero to round-off, so the transition problem alone cannot tell
        self.evaluate(t, q, u)?;
        for pt in 0..np {
            let closed = self.status[pt] != OPEN;
            let stick = self.status[pt] == STICK;
            let [l1, l2] = self.lam_t[pt];
            let reserve = self.model.contact_of_point(pt).friction.mu0() * self.lam_n[pt] - (l1 * l1 + l2 * l2).sqrt();
            self.ev.leaving[pt] = closed && (triggered[3 * pt] || self.lam_n[pt] <= 0.0);
            self.ev.breaking[pt] = stick && (triggered[3 * pt + 1] || reserve <= 0.0);
            self.ev.jam[pt] = self.status[pt] == SLIP && triggered[3 * pt + 2];
            self.ev.lam_t_before[pt] = self.lam_t[pt];
        }
        touching.clear();
        touching.extend((0..np).filter(|&pt| self.kin[pt].point.g_n <= self.opts.gap_tol));
        old.clear();
        old.extend_from_slice(&self.status);
        old_dir.clear();
        old_dir.extend_from_slice(&self.dir);
        let mut diss = Dissipation::default();
        if touching.iter().any(|&pt| self.kin[pt].gd_n < -vtol) {
            let mut hit = std::mem::take(&mut self.ev.hit);
            hit.clear();
            hit.extend(touching.iter().copied().filter(|&pt| self.kin[pt].gd_n < -vtol));
            let r = self.impact_logged(t, u, touching, false, imp, &hit, EventKind::Impact);
            self.ev.hit = hit;
            let d = r?;
            diss.impact += d.impact;
            diss.friction += d.friction;
            diss.external += d.external;
            self.free_motion(t, q, u)?;
            // after an impulse the forces are new: nothing is decided by the old ones
            self.ev.leaving.fill(false);
            self.ev.breaking.fill(false);
        }
        closing.clear();
        closing.extend(touching.iter().copied().filter(|&pt| self.kin[pt].gd_n.abs() <= vtol));
        // a slide that reached the Painlevé boundary (jam) while pressed on has no continuation
        let solved = self.transition_lcp(closing)?;
        let jammed = self.ev.painleve.iter().any(|p| self.ev.jam[p.0] && p.4 <= 0.0);
        if !solved || jammed {
            // no solution: the sliding points pressed into their contacts with a non-positive
            // normal acceleration per unit normal force are the cause (all sliding ones if none is)
            let mut culprits = std::mem::take(&mut self.ev.hit);
            culprits.clear();
            culprits.extend(self.ev.painleve.iter().filter(|p| p.4 <= 0.0).map(|p| p.0));
            if culprits.is_empty() {
                culprits.extend(closing.iter().copied().filter(|&pt| self.sliding(pt).1 > vtol));
            }
            let what = self.painleve_text(&culprits);
            if !self.opts.continue_on_painleve {
                self.ev.hit = culprits;
                return Err(Error::Painleve(format!(
                    "Painlevé situation at t = {t:.9} s: {what}; pressed into its contact, the contact problem has no solution at acceleration level. Set continue_on_painleve to stop the sliding by an impulse (an impact without collision) and go on"
                )));
            }
            warnings.push(format!(
                "Painlevé situation at t = {t:.9} s: {what}; the sliding was stopped by an impulse (an impact without collision)"
            ));
            // the impulsive stop: every touching point's relative velocity brought to zero (the
            // impact without collision ends in stick: with µ above the critical value no slide
            // can go on), then the transition problem from rest
            self.ev.u_before.copy_from_slice(u);
            for &pt in culprits.iter() {
                self.ev.imp_before[3 * pt..3 * pt + 3].copy_from_slice(&imp[3 * pt..3 * pt + 3]);
            }
            for &pt in closing.iter() {
                self.status[pt] = STICK;
            }
            let d = self.settle(u, imp);
            let at = self.log.store_velocities(&self.ev.u_before, u);
            for &pt in culprits.iter() {
                let e = self.log.push(t, pt, EventKind::Painleve);
                for k in 0..3 {
                    e.impulse[k] = imp[3 * pt + k] - self.ev.imp_before[3 * pt + k];
                }
                e.energy = self.ev.point_energy[pt];
                e.velocities = Some(at);
            }
            let first = self.log.events.len() - culprits.len();
            for k in first..self.log.events.len() {
                let (mu, mu_critical) = self.painleve_mu(self.log.events[k].point);
                self.log.events[k].painleve = Some(Painleve {
                    mu,
                    mu_critical,
                    non_unique: false,
                    solutions: [Vec::new(), Vec::new()],
                    resolved_by_impulse: true,
                });
            }
            self.ev.hit = culprits;
            diss.impact += d.impact;
            diss.friction += d.friction;
            diss.external += d.external;
            self.free_motion(t, q, u)?;
            closing.retain(|&pt| self.kin[pt].gd_n.abs() <= vtol);
            if !self.transition_lcp(closing)? {
                let names = self.names(closing);
                return Err(Error::Painleve(format!(
                    "Painlevé situation at t = {t:.9} s: the contact problem of {names:?} has no solution even after an impulsive stop"
                )));
            }
        } else {
            // several solutions: a sliding point with a non-positive coefficient and a separating
            // free acceleration may open (the solution taken) or stay closed pressing itself on
            for i in 0..self.ev.painleve.len() {
                let (pt, c, mu, mu_critical, acc) = self.ev.painleve[i];
                if acc <= 0.0 {
                    continue;
                }
                let taken: Vec<usize> = closing.iter().copied().filter(|&p| self.status[p] != OPEN).collect();
                let mut other: Vec<usize> = taken.iter().copied().filter(|&p| p != pt).collect();
                if !taken.contains(&pt) && -acc / c >= 0.0 {
                    other.push(pt);
                    other.sort_unstable();
                }
                let what = self.painleve_text(&[pt]);
                warnings.push(format!(
                    "Painlevé situation at t = {t:.9} s: {what}; the contact problem has two solutions (points closed: {:?} or {:?}), the first was taken",
                    self.point_names(&taken),
                    self.point_names(&other)
                ));
                self.log.push(t, pt, EventKind::Painleve).painleve = Some(Painleve {
                    mu,
                    mu_critical,
                    non_unique: true,
                    solutions: [taken, other],
                    resolved_by_impulse: false,
                });
            }
        }
        let d = self.settle(u, imp);
        diss.impact += d.impact;
        diss.friction += d.friction;
        diss.external += d.external;
        self.check_switches(t, q, u, old)?;
        // the sliding points' starting coefficients, for the jam indicator
        self.evaluate(t, q, u)?;
        self.slip_margin_start.copy_from_slice(&self.slip_margin);
        // a point left open on its contact (gap zero to round-off, not moving apart) must see its
        // gap return to zero: its event function starts just above zero
        for pt in 0..np {
            let k = &self.kin[pt];
            self.gap_offset[pt] = if self.status[pt] == OPEN && k.point.g_n <= self.opts.gap_tol && k.gd_n <= vtol {
                let scale = 1.0 + k.point.p1.amax().max(k.point.p2.amax());
                (-k.point.g_n).max(0.0) + 4.0 * f64::EPSILON * scale
            } else {
                0.0
            };
        }
        for pt in 0..np {
            let (was, now) = (old[pt], self.status[pt]);
            let (a, b) = (old_dir[pt], self.dir[pt]);
            let reversed = was == SLIP && now == SLIP && a[0] * b[0] + a[1] * b[1] < 0.0;
            if was != now || reversed {
                let kind = if now == OPEN {
                    EventKind::Open
                } else if was == OPEN {
                    EventKind::Close
                } else if now == STICK {
                    EventKind::Stick
                } else {
                    EventKind::Slip
                };
                self.log.push(t, pt, kind);
            }
        }
        Ok(diss)
    }

    /// The switches an event's indicators forced (a point left open because its normal force
    /// reached zero, a sticking one set sliding because its reserve did) must agree with the
    /// motion they start: an opened point may not accelerate into its contact, a sliding one not
    /// against its sliding direction; one that does is switched back. In space a break-away
    /// slides along the direction ŝ in which its sliding acceleration points under the friction
    /// force −µ λ_N ŝ (the cone's direction, not the pyramid's): the angle of ŝ is found by the
    /// secant method (the plain fixed-point iteration diverges once µ > (µ0 − µ)).
    pub(super) fn check_switches(&mut self, t: f64, q: &[f64], u: &[f64], old: &[f64]) -> Result<()> {
        let np = self.status.len();
        let forced = |s: &Self, pt: usize| {
            (s.ev.leaving[pt] && old[pt] != OPEN && s.status[pt] == OPEN) || (s.ev.breaking[pt] && s.status[pt] == SLIP)
        };
        if !(0..np).any(|pt| forced(self, pt)) {
            return Ok(());
        }
        if self.d == 3 {
            for pt in 0..np {
                if self.ev.breaking[pt] && self.status[pt] == SLIP {
                    self.cone_direction(t, q, u, pt)?;
                }
            }
        }
        for _ in 0..np + 1 {
            self.evaluate(t, q, u)?;
            let tol = 1e-8 * (1.0 + self.a_free.iter().fold(0.0f64, |a, v| a.max(v.abs())));
            let mut reverted = false;
            for pt in 0..np {
                if !forced(self, pt) {
                    continue;
                }
                let (gn, gt) = self.relative_acceleration(t, pt)?;
                if self.status[pt] == OPEN {
                    if gn < -tol {
                        self.status[pt] = old[pt];
                        reverted = true;
                    }
                } else if gt[0] * self.dir[pt][0] + gt[1] * self.dir[pt][1] < -tol {
                    self.status[pt] = STICK;
                    reverted = true;
                }
            }
            if !reverted {
                break;
            }
        }
        Ok(())
    }

    /// Relative normal and tangential accelerations (g̈_N, g̈_T) of point `pt` from the last
    /// evaluation (its full accelerations are in `data.a`, so w̄ holds them).
    fn relative_acceleration(&mut self, t: f64, pt: usize) -> Result<(f64, [f64; 2])> {
        let con = self.model.contact_of_point(pt);
        let n = con.points();
        if con.gap().is_some() {
            self.ev.apex[0] = self.kin[con.first];
            gap_with_accelerations(con, &self.data, &self.data.udot, &mut self.ev.apex[0]);
        } else {
            let (b1, b2) = (BodyMotion::from_data(&self.data, con.body1), BodyMotion::from_data(&self.data, con.body2));
            contact_kinematics(con.pair().expect("a contour contact"), &b1, &b2, &mut self.ev.apex[..n])
                .map_err(|e| Error::Solver(format!("contact '{}' at t = {t:.9} s: {e}", con.name)))?;
        }
        let k = &self.ev.apex[pt - con.first];
        Ok((k.wbar_n, if self.d == 3 { k.wbar_t } else { [k.wbar_t[0], 0.0] }))
    }

    /// The sliding direction of a break-away in space: the angle φ of ŝ with
    /// f(φ) = angle from ŝ to g̈_T(ŝ) = 0, by the secant method from the transition's guess.
    fn cone_direction(&mut self, t: f64, q: &[f64], u: &[f64], pt: usize) -> Result<()> {
        let f = |s: &mut Self, phi: f64| -> Result<f64> {
            s.dir[pt] = [phi.cos(), phi.sin()];
            s.evaluate(t, q, u)?;
            let (_, g) = s.relative_acceleration(t, pt)?;
            let d = s.dir[pt];
            Ok((d[0] * g[1] - d[1] * g[0]).atan2(d[0] * g[0] + d[1] * g[1]))
        };
        let start = self.dir[pt];
        let mut p0 = start[1].atan2(start[0]);
        let mut f0 = f(self, p0)?;
        // a small first step along the error, then secants
        let mut p1 = p0 + 0.25 * f0;
        let mut f1 = f(self, p1)?;
        for _ in 0..60 {
            if f1.abs() < 1e-14 || f1 == f0 {
                break;
            }
            let p2 = p1 - f1 * (p1 - p0) / (f1 - f0);
            (p0, f0) = (p1, f1);
            p1 = p2;
            f1 = f(self, p1)?;
        }
        if !(f1.abs() < 1e-9) {
            // no direction along which the slide can start found: keep the transition's guess
            self.dir[pt] = start;
        } else {
            self.dir[pt] = [p1.cos(), p1.sin()];
        }
        Ok(())
    }

    /// [`Self::impact`] with its events on record: one of `kind` per point of `hit`, with the
    /// point's impulses and the energy its impulses took, and the generalized velocities around
    /// the impact.
    #[allow(clippy::too_many_arguments)]
    fn impact_logged(
        &mut self,
        t: f64,
        u: &mut [f64],
        pts: &[usize],
        plastic: bool,
        imp: &mut [f64],
        hit: &[usize],
        kind: EventKind,
    ) -> Result<Dissipation> {
        self.ev.u_before.copy_from_slice(u);
        for &pt in hit {
            self.ev.imp_before[3 * pt..3 * pt + 3].copy_from_slice(&imp[3 * pt..3 * pt + 3]);
        }
        let d = self.impact(t, u, pts, plastic, imp)?;
        let at = self.log.store_velocities(&self.ev.u_before, u);
        for &pt in hit {
            let e = self.log.push(t, pt, kind);
            for r in 0..3 {
                e.impulse[r] = imp[3 * pt + r] - self.ev.imp_before[3 * pt + r];
            }
            e.energy = self.ev.point_energy[pt];
            e.velocities = Some(at);
        }
        Ok(d)
    }

    /// µ and the critical µ of point `pt` from the last transition problem (NaN if it was not
    /// found there).
    fn painleve_mu(&self, pt: usize) -> (f64, f64) {
        match self.ev.painleve.iter().find(|p| p.0 == pt) {
            Some(p) => (p.2, p.3),
            None => (self.mu_sliding(pt), f64::NAN),
        }
    }

    /// "contact 'tip' (point 0) slides with µ = 3 above the critical µ = 2.502" for each point.
    fn painleve_text(&self, pts: &[usize]) -> String {
        let parts: Vec<String> = pts
            .iter()
            .map(|&pt| {
                let con = self.model.contact_of_point(pt);
                let (mu, crit) = self.painleve_mu(pt);
                let crit = if !crit.is_finite() {
                    String::new()
                } else if mu >= crit {
                    format!(" above the critical µ = {crit:.6}")
                } else {
                    format!(" at the critical µ = {crit:.6} (its normal force grows without bound: jamming)")
                };
                format!("contact '{}' (point {}) slides with µ = {mu}{crit}", con.name, pt - con.first)
            })
            .collect();
        if parts.is_empty() {
            "the sliding contacts".to_string()
        } else {
            parts.join(", ")
        }
    }

    /// "tip[0]" names of points.
    fn point_names(&self, pts: &[usize]) -> Vec<String> {
        pts.iter()
            .map(|&pt| {
                let con = self.model.contact_of_point(pt);
                format!("{}[{}]", con.name, pt - con.first)
            })
            .collect()
    }
}
