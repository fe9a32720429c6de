//! Jenkins elements: a linear spring in series with a Coulomb slider (eq. 2.215), the building
//! block of dry-friction damping in screws and press fits (section 2.6.3, Fig. 2.39).
//!
//! The element acts on one joint coordinate x (relative displacement, shaft against hub). Its n
//! sliders sit at z_i on the hub; slider i carries the force λ_i = k (w_i − z_i) of its spring,
//! where w_i is the node it holds, and the set-valued law is
//!
//! ```text
//! |λ_i| ≤ F_s,i,   ż_i = 0 if |λ_i| < F_s,i,   ż_i λ_i ≥ 0 (the slider moves with its force).
//! ```
//!
//! Without a shaft stiffness all nodes are the load point (w_i = x): n elements in parallel (a
//! single Jenkins element for n = 1; a Masing/Iwan model for several slip forces). With a shaft
//! stiffness k_s the nodes are massless segments of a press-fitted shaft, joined to the load point
//! and to each other by k_s, each held to the hub by its Jenkins element; slip then spreads from
//! the loaded end inwards (microslip), so the hysteresis loop widens and its secant stiffness
//! falls with the amplitude, as in Fig. 2.40.
//!
//! The sliders are history variables. Over a step from the committed positions z⁰ the increment
//! Δz solves the incremental problem (the catching-up scheme of the sweeping process, exact while
//! x moves monotonically within the step). Node equilibrium `A w = b x + k z` with
//! `A = K_shaft + k E` gives the trial forces `λ* = k (A⁻¹(b x + k z⁰) − z⁰)` and
//! `λ = λ* − W Δz` with the symmetric positive definite `W = k (E − k A⁻¹)`; the slider law
//! then is the linear complementarity problem in `Δz = Δz⁺ − Δz⁻ ≥ 0`:
//!
//! ```text
//! [F_s − λ; F_s + λ] = [W −W; −W W] [Δz⁺; Δz⁻] + [F_s − λ*; F_s + λ*] ≥ 0  ⊥  [Δz⁺; Δz⁻] ≥ 0,
//! ```
//!
//! solved by Lemke's method (the contact solvers' own, [`crate::solver`]). In parallel (W = k E)
//! it decouples into the projection `λ_i = clamp(λ*_i, ±F_s,i)`. Each force evaluation solves it
//! against z⁰; [`commit`] makes the solution the new z⁰ after every accepted step and returns the
//! work `Σ λ_i Δz_i = Σ F_s,i |Δz_i|` the sliders dissipated.

use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::{ForceElement, Model};
use crate::solver::{self, Lcp, LemkeOptions, Method, Workspace};

/// A set of Jenkins elements on one joint velocity (validated; see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Jenkins {
    /// Name.
    pub name: String,
    /// Joint index.
    pub joint: usize,
    /// Index of the coordinate in q.
    pub iq: usize,
    /// Index of the velocity in u.
    pub iu: usize,
    /// Stiffness of each Jenkins spring.
    pub k: f64,
    /// Slip force of each slider (n).
    pub slip: Vec<f64>,
    /// Shaft segment stiffness (none: elements in parallel).
    pub shaft: Option<f64>,
    /// Joint coordinate at which everything is relaxed.
    pub offset: f64,
    /// First slider of this element in `Data::slider`.
    pub slot: usize,
    /// Chain only: `A⁻¹ b` (n).
    ainv_b: Vec<f64>,
    /// Chain only: `k A⁻¹` (n × n, row-major).
    k_ainv: Vec<f64>,
    /// Chain only: `W = k (E − k A⁻¹)` (n × n, row-major).
    w: Vec<f64>,
}

impl Jenkins {
    /// Builds the element and, for a chain, its constant matrices. Inputs are checked by the caller.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: String,
        joint: usize,
        iq: usize,
        iu: usize,
        k: f64,
        slip: Vec<f64>,
        shaft: Option<f64>,
        offset: f64,
        slot: usize,
    ) -> Result<Self> {
        let n = slip.len();
        let (mut ainv_b, mut k_ainv, mut w) = (vec![], vec![], vec![]);
        if let Some(ks) = shaft {
            // A = K_shaft + k E: the load point joins node 0, node i joins node i + 1 (tridiagonal)
            let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
            for i in 0..n {
                a[(i, i)] = k + ks + if i + 1 < n { ks } else { 0.0 };
                if i + 1 < n {
                    a[(i, i + 1)] = -ks;
                    a[(i + 1, i)] = -ks;
                }
            }
            // A is symmetric positive definite when k, ks > 0 (strictly diagonally dominant)
            let ainv = a.cholesky().map(|c| c.inverse()).ok_or_else(|| {
                Error::Model(format!("Jenkins element '{name}': k and shaft_stiffness must be > 0 (got {k}, {ks})"))
            })?;
            ainv_b = (0..n).map(|i| ainv[(i, 0)] * ks).collect();
            k_ainv = (0..n * n).map(|m| k * ainv[(m / n, m % n)]).collect();
            w = (0..n * n).map(|m| k * (if m / n == m % n { 1.0 } else { 0.0 } - k * ainv[(m / n, m % n)])).collect();
        }
        Ok(Jenkins { name, joint, iq, iu, k, slip, shaft, offset, slot, ainv_b, k_ainv, w })
    }

    /// Number of sliders.
    pub fn len(&self) -> usize {
        self.slip.len()
    }

    /// Whether the element has no slider (never, once validated).
    pub fn is_empty(&self) -> bool {
        self.slip.is_empty()
    }

    /// The force the element carries along x (Σ λ_i), resisting a positive deflection.
    pub fn force(&self, data: &Data) -> f64 {
        data.slider_force[self.slot..self.slot + self.len()].iter().sum()
    }

    /// Elastic energy stored at the last evaluation: the Jenkins springs and the shaft segments.
    pub fn energy(&self, data: &Data, q: &[f64]) -> f64 {
        let s = self.slot..self.slot + self.len();
        let (z, lam) = (&data.slider_trial[s.clone()], &data.slider_force[s]);
        let mut e: f64 = lam.iter().map(|l| 0.5 * l * l / self.k).sum();
        if let Some(ks) = self.shaft {
            let x = q[self.iq] - self.offset;
            let node = |i: usize| z[i] + lam[i] / self.k;
            let mut prev = x;
            for i in 0..self.len() {
                let d = prev - node(i);
                e += 0.5 * ks * d * d;
                prev = node(i);
            }
        }
        e
    }
}

/// The solver scratch of one chain (preallocated: the step loop does not allocate).
#[derive(Debug, Clone)]
pub struct ChainWork {
    lcp: Lcp,
    x: Vec<f64>,
    ws: Workspace,
}

impl ChainWork {
    /// Scratch for element `j` (a chain), with the constant LCP matrix filled in.
    pub fn new(j: &Jenkins) -> Self {
        let n = j.len();
        let m2 = 2 * n;
        let mut m = vec![0.0; m2 * m2];
        for r in 0..n {
            for c in 0..n {
                let v = j.w[r * n + c];
                m[r * m2 + c] = v;
                m[r * m2 + n + c] = -v;
                m[(n + r) * m2 + c] = -v;
                m[(n + r) * m2 + n + c] = v;
            }
        }
        let lcp = Lcp { m, q: vec![0.0; m2] };
        // the LCP is valid by construction (finite, square), so reserving cannot fail
        let ws = Workspace::for_problem(&lcp, &Method::lemke()).unwrap_or_default();
        ChainWork { lcp, x: vec![0.0; m2], ws }
    }
}

/// Solves the incremental problem of element `j` at coordinate `q` against the committed slider
/// positions: writes `data.slider_trial` (z) and `data.slider_force` (λ) and returns Σλ.
pub fn evaluate(j: &Jenkins, chain: usize, data: &mut Data, q: &[f64], t: f64) -> Result<f64> {
    let n = j.len();
    let x = q[j.iq] - j.offset;
    let s = j.slot;
    if j.shaft.is_none() {
        // parallel elements: each slider is the projection of its trial force
        for i in 0..n {
            let z0 = data.slider[s + i];
            let lam = (j.k * (x - z0)).clamp(-j.slip[i], j.slip[i]);
            data.slider_force[s + i] = lam;
            data.slider_trial[s + i] = x - lam / j.k;
        }
    } else {
        let work = &mut data.jenkins_work[chain];
        // trial forces with the sliders held: λ* = k (A⁻¹ b x + k A⁻¹ z⁰ − z⁰)
        for r in 0..n {
            let mut wr = j.ainv_b[r] * x;
            for c in 0..n {
                wr += j.k_ainv[r * n + c] * data.slider[s + c];
            }
            let lam_star = j.k * (wr - data.slider[s + r]);
            work.lcp.q[r] = j.slip[r] - lam_star;
            work.lcp.q[n + r] = j.slip[r] + lam_star;
            // λ* is kept in the output slot until Δz is known
            data.slider_force[s + r] = lam_star;
        }
        // M was checked when the scratch was built and q is finite with x: Lemke directly,
        // without the per-call validation of the generic `solver::solve`
        let rep = solver::lemke::solve_lcp(&work.lcp, &LemkeOptions::default(), &mut work.x, &mut work.ws)
            .map_err(|e| Error::Solver(format!("Jenkins element '{}' at t = {t} s: {e}", j.name)))?;
        if !rep.converged {
            return Err(Error::Solver(format!(
                "Jenkins element '{}' at t = {t} s: the slider problem was not solved (residual {:.1e})",
                j.name, rep.residual
            )));
        }
        for r in 0..n {
            let dz_r = work.x[r] - work.x[n + r];
            data.slider_trial[s + r] = data.slider[s + r] + dz_r;
        }
        for r in 0..n {
            let mut wdz = 0.0;
            for c in 0..n {
                wdz += j.w[r * n + c] * (work.x[c] - work.x[n + c]);
            }
            // clamp the round-off of the pivoting onto the admissible interval
            data.slider_force[s + r] = (data.slider_force[s + r] - wdz).clamp(-j.slip[r], j.slip[r]);
        }
    }
    Ok(data.slider_force[s..s + n].iter().sum())
}

/// After an accepted step at configuration `q`: the sliders' positions there become the new
/// reference. Returns the work the sliders dissipated over the step (≥ 0).
pub fn commit(model: &Model, data: &mut Data, q: &[f64], t: f64) -> Result<f64> {
    let mut work = 0.0;
    let mut chain = 0;
    for f in &model.forces {
        if let ForceElement::Jenkins(j) = f {
            evaluate(j, chain, data, q, t)?;
            if j.shaft.is_some() {
                chain += 1;
            }
            for i in j.slot..j.slot + j.len() {
                work += data.slider_force[i] * (data.slider_trial[i] - data.slider[i]);
                data.slider[i] = data.slider_trial[i];
            }
        }
    }
    // each λ_i Δz_i ≥ 0 by the slider law (up to round-off): no clamp, a sign error must show
    Ok(work)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn element(slip: Vec<f64>, shaft: Option<f64>) -> Jenkins {
        Jenkins::new("press".into(), 0, 0, 0, 100.0, slip, shaft, 0.0, 0).unwrap()
    }

    #[test]
    fn w_is_symmetric_positive_definite_and_matches_series_springs() {
        // one node: the shaft spring and the Jenkins spring in series, W = k ks / (k + ks)
        let j = element(vec![1.0], Some(300.0));
        assert!((j.w[0] - 100.0 * 300.0 / 400.0).abs() < 1e-12);
        let j = element(vec![1.0; 5], Some(50.0));
        let w = nalgebra::DMatrix::from_row_slice(5, 5, &j.w);
        assert!((&w - w.transpose()).norm() < 1e-12);
        assert!(w.symmetric_eigen().eigenvalues.min() > 0.0);
        // a non-positive stiffness is an error naming the element, not a made-up matrix
        let e = Jenkins::new("press".into(), 0, 0, 0, -100.0, vec![1.0; 3], Some(50.0), 0.0, 0).unwrap_err();
        assert!(e.to_string().contains("'press'"), "{e}");
    }
}
