//! Position projection of closed contacts after a Moreau–Jean step.
//!
//! The scheme holds closed contacts at velocity level only (`ġ_N⁺ ≥ 0` at the step's midpoint).
//! On a curved contour a contact that rolls or slides along it therefore drifts into it by
//! O(h²) per step — the midpoint's normal turns within the step — and the drift adds up: a ball
//! rolling in a curved track sinks steadily. After the step, every explicit contact point that
//! was in its contact problem and now penetrates is moved back onto its contour by Newton steps on
//! `g_N(q) = 0` with the smallest correction in the kinetic metric,
//! `Δu = M̃⁻¹ W μ`, `Wᵀ M̃⁻¹ W μ = -g` (M̃⁻¹ restricted to the bilateral constraints' tangent
//! space, as in the step), and `q ← q ⊕ Δu` — the direct projection of the closed contacts onto
//! their admissible set. Velocities are not changed. Points whose multiplier comes out negative
//! (the others' correction lifts them off) are left to the next iteration. Box–box pairs are
//! left out: flat on flat, they do not drift, and their clipped manifold points slide over both
//! faces.

use nalgebra::DMatrix;

use crate::contact::{contact_point_kinematics, ContactKinematics};
use crate::data::Data;
use crate::error::Result;
use crate::forces::Callbacks;
use crate::math::linalg::solve_min_norm;
use crate::model::Model;

/// Penetration (m) above which a closed point is projected: below the scheme's activation
/// margin, so a projected point stays in the next step's problem.
pub(super) const TOLERANCE: f64 = 1e-10;

/// Newton iterations at most (one or two suffice: the correction is O(h²)).
const ITERATIONS: usize = 4;

/// Buffers of the projection, sized for the model's explicit contact points.
pub(super) struct Projection {
    kin: Vec<ContactKinematics>,
    /// Penetrating closed points of an iteration.
    points: Vec<usize>,
    rows: DMatrix<f64>,
    cols: Vec<f64>,
    a: Vec<f64>,
    aat: Vec<f64>,
    piv: Vec<usize>,
    work: Vec<f64>,
    mu: Vec<f64>,
    du: Vec<f64>,
    q_tmp: Vec<f64>,
    /// Projections done (steps in which some point moved).
    pub(super) count: usize,
}

impl Projection {
    pub(super) fn new(model: &Model) -> Projection {
        let (np, nu) = (model.n_contact_points, model.nu);
        Projection {
            kin: vec![ContactKinematics::default(); np],
            points: Vec::with_capacity(np),
            rows: DMatrix::zeros(np, nu),
            cols: vec![0.0; np * nu],
            a: vec![0.0; np * np],
            aat: vec![0.0; np * np],
            piv: vec![0; np],
            work: vec![0.0; np],
            mu: vec![0.0; np],
            du: vec![0.0; nu],
            q_tmp: vec![0.0; model.nq],
            count: 0,
        }
    }

    /// Projects `q` (at time `t`, velocities `u` only for the gap functions' evaluation) so that
    /// no point with `closed(pt)` (in the step's problem) penetrates by more than [`TOLERANCE`]. `ws` holds the step's
    /// factor of M (and of the bilateral constraints' Schur complement when `model.nc > 0`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn project(
        &mut self,
        model: &Model,
        data: &mut Data,
        ws: &mut crate::dynamics::Workspace,
        t: f64,
        q: &mut [f64],
        u: &[f64],
        cb: &dyn Callbacks,
        closed: impl Fn(usize) -> bool,
    ) -> Result<()> {
        let (nu, nc) = (model.nu, model.nc);
        let mut moved = false;
        for _ in 0..ITERATIONS {
            crate::kinematics::positions(model, data, q);
            self.points.clear();
            for con in &model.contacts {
                let range = con.first..con.first + con.points();
                // a box–box manifold rests on flat faces (no drift to undo), and its clipped
                // points are no material points a correction could be computed for
                if !range.clone().any(&closed) || con.pair().is_some_and(|p| p.is_clipped_manifold()) {
                    continue;
                }
                // (the rates come from stale velocities and are not used: only g, n and points)
                contact_point_kinematics(con, data, t, q, u, cb, &mut self.kin[range.clone()], None)
                    .map_err(|e| crate::contact::at_contact(e, &con.name, t))?;
                for pt in range {
                    if closed(pt) && self.kin[pt].point.g_n < -TOLERANCE {
                        self.points.push(pt);
                    }
                }
            }
            let m = self.points.len();
            if m == 0 {
                break;
            }
            moved = true;
            // W_N of the penetrating points, X = M̃⁻¹ W_N column by column, A = W_Nᵀ X
            for (r, &pt) in self.points.iter().enumerate() {
                for i in 0..nu {
                    self.rows[(r, i)] = 0.0;
                }
                let con = model.contact_of_point(pt);
                match con.gap() {
                    Some((_, slot)) => {
                        for i in 0..nu {
                            self.rows[(r, i)] = data.gap.rows[3 * slot * nu + i];
                        }
                    }
                    None => {
                        let k = &self.kin[pt].point;
                        crate::constraints::add_relative_rows(
                            model,
                            &data.s,
                            (&data.x_abs, &data.elastic, &data.body_elastic),
                            (con.body1, &k.p1),
                            (con.body2, &k.p2),
                            Some(&k.n),
                            &mut self.rows,
                            r,
                        );
                    }
                }
                let x = &mut self.cols[r * nu..(r + 1) * nu];
                for i in 0..nu {
                    x[i] = self.rows[(r, i)];
                }
                crate::dynamics::constrained::tangent_inverse_mass(data, &mut ws.saddle, nc, x, None);
            }
            for i in 0..m {
                for j in 0..m {
                    self.a[i * m + j] = (0..nu).map(|c| self.rows[(i, c)] * self.cols[j * nu + c]).sum();
                }
                self.mu[i] = -self.kin[self.points[i]].point.g_n;
            }
            // points that cannot move independently (a box's four corners on a face) make A
            // singular: the minimum-norm multipliers share the correction evenly (and keep a
            // symmetric configuration symmetric)
            solve_min_norm(
                &self.a[..m * m],
                m,
                &mut self.mu[..m],
                &mut self.aat[..m * m],
                &mut self.piv[..m],
                &mut self.work[..m],
                1e-12,
            );
            self.du.fill(0.0);
            for j in 0..m {
                // a negative multiplier would pull a contact shut: left to the next iteration
                let l = self.mu[j].max(0.0);
                for i in 0..nu {
                    self.du[i] += self.cols[j * nu + i] * l;
                }
            }
            self.q_tmp.copy_from_slice(q);
            model.integrate(&self.q_tmp, &self.du, 1.0, q);
            model.normalize(q);
        }
        if moved {
            self.count += 1;
        }
        Ok(())
    }
}
