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
use crate::model::{ForceElement, Jenkins, Model};
use crate::solver::{self, Lcp, LemkeOptions, Method, Workspace};

/// The solver scratch of one chain (preallocated: the step loop does not allocate). The force
/// stage keeps one per chain in [`crate::forces::Workspace`], in the order of the model's
/// force elements ([`chains`]).
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

/// The scratch of every chain of `model` (the elements with a shaft), in the order of its force
/// elements.
pub fn chains(model: &Model) -> Vec<ChainWork> {
    model
        .forces
        .iter()
        .filter_map(|f| match f {
            ForceElement::Jenkins(j) if j.shaft.is_some() => Some(ChainWork::new(j)),
            _ => None,
        })
        .collect()
}

/// The force the element carries along x (Σ λ_i) at the last evaluation, resisting a positive
/// deflection.
pub fn force(j: &Jenkins, data: &Data) -> f64 {
    data.slider_force[j.slot..j.slot + j.len()].iter().sum()
}

/// Elastic energy stored at the last evaluation: the Jenkins springs and the shaft segments.
pub fn energy(j: &Jenkins, data: &Data, q: &[f64]) -> f64 {
    let s = j.slot..j.slot + j.len();
    let (z, lam) = (&data.slider_trial[s.clone()], &data.slider_force[s]);
    let mut e: f64 = lam.iter().map(|l| 0.5 * l * l / j.k).sum();
    if let Some(ks) = j.shaft {
        let x = q[j.iq] - j.offset;
        let node = |i: usize| z[i] + lam[i] / j.k;
        let mut prev = x;
        for i in 0..j.len() {
            let d = prev - node(i);
            e += 0.5 * ks * d * d;
            prev = node(i);
        }
    }
    e
}

/// Solves the incremental problem of element `j` at coordinate `q` against the committed slider
/// positions: writes `data.slider_trial` (z) and `data.slider_force` (λ) and returns Σλ. A chain
/// (an element with a shaft) is the `chain`-th of the model and solves in `chains[chain]`; the
/// parallel elements need no scratch.
pub fn evaluate(
    j: &Jenkins,
    chain: usize,
    data: &mut Data,
    chains: &mut [ChainWork],
    q: &[f64],
    t: f64,
) -> Result<f64> {
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
        let work = &mut chains[chain];
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
/// reference. Returns the work the sliders dissipated over the step (≥ 0). `chains` is the force
/// stage's scratch ([`crate::forces::Workspace::jenkins`]).
pub fn commit(model: &Model, data: &mut Data, chains: &mut [ChainWork], q: &[f64], t: f64) -> Result<f64> {
    let mut work = 0.0;
    let mut chain = 0;
    for f in &model.forces {
        if let ForceElement::Jenkins(j) = f {
            evaluate(j, chain, data, chains, q, t)?;
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
