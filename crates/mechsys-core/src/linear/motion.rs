//! First-order linearization about a state that moves: steady motions (relative equilibria) of
//! holonomic and non-holonomic systems, in the state form `ẋ = A x + B τ`.
//!
//! The second-order form of the parent module keeps one coordinate per admissible velocity and
//! reads `u = u* + V ẏ` as the derivative of `q = q* ⊕ V y`. Both break when the state moves:
//!
//! - **non-holonomic rows** leave more configuration directions than velocity directions (a
//!   rolling wheel can reach any position and heading, yet has two admissible velocities);
//! - **constraints that turn with q** change the admissible velocities with the configuration:
//!   a perturbation δ of a moving state must carry the velocity change `−G⁺ ∂(G u*)/∂q δ` that
//!   keeps it admissible, and its accelerations a normal part `∂(G u̇* − γ)/∂x`;
//! - **rotations in the child frame** (quaternion joints, `q ⊗ exp(½ δ)`): the chart coordinate
//!   of a perturbed rotating body obeys `δ̇ = δω − ω* × δ`, not `δ̇ = δω` (and the free joint's
//!   position, moved by `A(q) v`, `δ̇_p = δv − ω* × δ_p − v* × δ_θ`).
//!
//! So the state is split as the reference text's linearization about a motion (2.204) needs it:
//! configuration perturbations `δ = V_h ξ` along the directions the holonomic rows allow
//! (`n_q,min` of them) and velocity perturbations `δu = P ξ + V η` (`n_u,min`), with `G V = 0`
//! and `P` the admissibility correction above. In the ambient chart coordinates `(δ, δu)` the
//! linearized motion is
//!
//! ```text
//! δ̇  = Ω(u*) δ + δu,             (the chart's rate; Ω = 0 for joints with q̇ = u)
//! δu̇ = ∂u̇/∂q δ + ∂u̇/∂u δu,      (the constrained forward dynamics)
//! ```
//!
//! and `A = L A_amb B` with `B = [[V_h, 0], [P, V]]` and a left inverse `L` (`L B = I`). About a
//! steady motion the admissible subspace `range B` is invariant (`A_amb B = B A`); its defect is
//! reported so a state that is not steady is seen.
//!
//! Derivatives: `∂u̇/∂x` exactly from the inverse dynamics (dual numbers, module `ad`) through
//! the linearized saddle-point system
//!
//! ```text
//! M δu̇ − Gᵀ δλ = −∂ID/∂x δx + ∂(Gᵀ λ*)/∂q δq,     G δu̇ = −∂(G u̇* − γ)/∂x δx,
//! ```
//!
//! the constraint terms by five-point differences (as `geometric`), or all of it by central
//! differences of the forward dynamics.
//!
//! Bases: `Basis::Orthonormal` takes V_h, V from the singular value decomposition (the parent
//! module's coordinates, so an equilibrium gives the same y); `Basis::Partition` picks
//! independent coordinates among the joint coordinates (pivoted elimination, the preferred ones
//! kept independent when the constraints allow), so every state entry is a named joint coordinate
//! or velocity and `L` is a selection.

use nalgebra::{DMatrix, DVector};

use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::math::Vec3;
use crate::model::{JointKind, Model};

use super::{ad, differences, null_space, DerivativeMethod, Derivatives};

/// Step of the five-point differences of the constraint terms (rad or m along the chart).
const STEP: f64 = 1e-3;

/// How the state's coordinates are chosen.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Basis {
    /// Orthonormal bases of the admissible directions (singular value decomposition).
    #[default]
    Orthonormal,
    /// Independent joint coordinates and velocities; those listed (velocity indices) are kept
    /// independent where the constraints allow.
    Partition(Vec<usize>),
}

/// The state form about (t, q, u): `x = (ξ, η)`, `δ = V_h ξ`, `δu = P ξ + V η`.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    /// Configuration coordinates ξ (n_q,min).
    pub nq: usize,
    /// Velocity coordinates η (n_u,min).
    pub nu: usize,
    /// `ẋ = A x` (nx × nx, row-major, nx = nq + nu).
    pub a: Vec<f64>,
    /// Input matrix: column k is ẋ for a unit generalized force on velocity k (nx × model.nu).
    pub b: Vec<f64>,
    /// Configuration basis V_h (model.nu × nq, row-major).
    pub vh: Vec<f64>,
    /// Admissibility correction P (model.nu × nq).
    pub p: Vec<f64>,
    /// Velocity basis V (model.nu × nu).
    pub v: Vec<f64>,
    /// Left inverse of V_h: ξ = L_h δ (nq × model.nu).
    pub lh: Vec<f64>,
    /// Left inverse of V: η = L_u δu (nu × model.nu).
    pub lu: Vec<f64>,
    /// For `Basis::Partition`: the chart coordinates (velocity indices) that are ξ.
    pub independent_q: Vec<usize>,
    /// For `Basis::Partition`: the velocities that are η.
    pub independent_u: Vec<usize>,
    /// The reference's own rates in the state coordinates: `(L_h u*, L_u u̇*)` (nx). A steady
    /// motion has `L_u u̇* = 0` and `L_h u*` along cyclic directions only.
    pub rate: Vec<f64>,
    /// `max |A_amb B − B A| / max |A_amb B|`: how far the admissible subspace is from invariant
    /// (round-off about a steady motion).
    pub defect: f64,
    /// The mass matrix at the state (model.nu × model.nu, row-major).
    pub mass: Vec<f64>,
    /// Position residuals Φ of the constraint rows at the state (nc; 0 on velocity-only rows).
    pub phi: Vec<f64>,
    /// Velocity residuals `G u* − b` of the constraint rows (nc).
    pub velocity_residual: Vec<f64>,
    /// How the derivatives were taken.
    pub method: DerivativeMethod,
}

/// The state form of `model` about (t, q, u); see the module documentation.
#[allow(clippy::too_many_arguments)]
pub fn state_space(
    model: &Model,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    how: Derivatives,
    basis: &Basis,
) -> Result<StateSpace> {
    let (nu, nc) = (model.nu, model.nc);
    let exact = super::check_point(model, q, u, how, "state_space")?;
    let (mut data, mut ws) = (Data::new(model), crate::dynamics::Workspace::new(model));
    crate::dynamics::forward_dynamics(model, &mut data, &mut ws, t, q, u, None, cb)?;
    let (a0, lambda) = (data.udot.clone(), data.lambda.clone());
    let g = data.g.clone();
    let gu = &g * DVector::from_column_slice(u);
    let velocity_residual: Vec<f64> = (0..nc).map(|r| gu[r] - data.b[r]).collect();
    let phi = data.phi.clone();
    crate::dynamics::crba::mass_matrix(model, &mut data, t, q);
    let mass = data.mass_matrix.clone();
    if let Some(i) = (0..nu).find(|&i| !(mass[(i, i)] > 0.0)) {
        return Err(Error::Model(format!(
            "linearize: the mass matrix is singular (diagonal entry {i} is {})",
            mass[(i, i)]
        )));
    }
    let chol = mass
        .clone()
        .cholesky()
        .ok_or_else(|| Error::Model("linearize: the mass matrix is not positive definite".into()))?;

    // the holonomic rows
    let mut holonomic = Vec::with_capacity(nc);
    for c in &model.constraints {
        let (rows, h) = (c.rows(), c.holonomic_rows());
        holonomic.extend((0..rows).map(|k| k < h));
    }
    let hrows: Vec<usize> = (0..nc).filter(|&r| holonomic[r]).collect();
    let gh = DMatrix::from_fn(hrows.len(), nu, |r, c| g[(hrows[r], c)]);

    // bases of the admissible configuration and velocity directions
    let (vh, lh, indep_q) = admissible(&gh, nu, basis);
    let (v, lu, indep_u) = admissible(&g, nu, basis);
    let (n1, n2) = (vh.ncols(), v.ncols());
    crate::ensure!(n2 > 0, Model, "linearize: the constraints leave no degree of freedom");

    // P: the velocity change that keeps a configuration perturbation admissible, G δu = −J δ
    // with J = ∂(G u* − b)/∂q
    let p = if nc > 0 && n1 > 0 {
        let mut data_j = Data::new(model);
        let j = differentiate_state(model, q, u, &vh, true, &mut |qp, _| {
            crate::kinematics::positions(model, &mut data_j, qp);
            crate::constraints::positions(model, &mut data_j, t, qp, cb)?;
            let mut r = &data_j.g * DVector::from_column_slice(u);
            for k in 0..nc {
                r[k] -= data_j.b[k];
            }
            Ok(r)
        })?;
        correction(&g, &j, &indep_u, basis)
    } else {
        DMatrix::zeros(nu, n1)
    };

    // the ambient Jacobians ∂u̇/∂q (chart) and ∂u̇/∂u
    let eye = DMatrix::identity(nu, nu);
    let (aq, au, method) = if exact {
        let (dq, du) = ad::inverse_dynamics_derivatives(model, t, q, u, &a0, &eye, cb)?;
        if nc == 0 {
            // M δu̇ = −∂ID δx
            (-chol.solve(&dq), -chol.solve(&du), DerivativeMethod::Exact)
        } else {
            let geo = super::geometric::constraint_load_derivative(model, t, q, &lambda, &eye, cb)?;
            let a0v = DVector::from_column_slice(&a0);
            // G u̇* − γ along q (chart) and along u
            let mut data2 = Data::new(model);
            // G and γ need only the kinematics and the constraints (as in dynamics::constrained):
            // no force is evaluated this far (STEP) from the point, where a film or a stop law
            // may be undefined
            let mut accel_rows = |qp: &[f64], up: &[f64]| -> Result<DVector<f64>> {
                crate::kinematics::forward_pass(model, &mut data2, t, qp, up);
                crate::constraints::positions(model, &mut data2, t, qp, cb)?;
                data2.a[0] = crate::spatial::Motion::ZERO;
                let zero = std::mem::take(&mut data2.zero_u);
                crate::kinematics::accelerations(model, &mut data2, &zero);
                data2.zero_u = zero;
                crate::constraints::accelerations(model, &mut data2, t, qp, up, cb)?;
                let mut r = &data2.g * &a0v;
                for k in 0..nc {
                    r[k] -= data2.gamma[k];
                }
                Ok(r)
            };
            let kq = differentiate_state(model, q, u, &eye, true, &mut accel_rows)?;
            let ku = differentiate_state(model, q, u, &eye, false, &mut accel_rows)?;
            let aq = saddle_solve(&chol, &g, &(-(dq - geo)), &(-kq));
            let au = saddle_solve(&chol, &g, &(-du), &(-ku));
            (aq, au, DerivativeMethod::ExactWithDifferencedConstraints)
        }
    } else {
        let (dq, du) = differences::acceleration_derivatives(model, &mut data, &mut ws, t, q, u, &eye, cb)?;
        (dq, du, DerivativeMethod::CentralDifferences)
    };

    // the ambient map applied to the admissible basis: A_amb B
    let omega = chart_rate(model, u);
    let nx = n1 + n2;
    let mut amb_b = DMatrix::zeros(2 * nu, nx);
    // ξ columns: (Ω V_h + P, Aq V_h + Au P); η columns: (V, Au V)
    amb_b.view_mut((0, 0), (nu, n1)).copy_from(&(&omega * &vh + &p));
    amb_b.view_mut((nu, 0), (nu, n1)).copy_from(&(&aq * &vh + &au * &p));
    amb_b.view_mut((0, n1), (nu, n2)).copy_from(&v);
    amb_b.view_mut((nu, n1), (nu, n2)).copy_from(&(&au * &v));
    let mut a = DMatrix::zeros(nx, nx);
    a.view_mut((0, 0), (n1, nx)).copy_from(&(&lh * amb_b.rows(0, nu)));
    a.view_mut((n1, 0), (n2, nx)).copy_from(&(&lu * amb_b.rows(nu, nu)));
    // invariance defect: A_amb B − B A
    let mut bm = DMatrix::zeros(2 * nu, nx);
    bm.view_mut((0, 0), (nu, n1)).copy_from(&vh);
    bm.view_mut((nu, 0), (nu, n1)).copy_from(&p);
    bm.view_mut((nu, n1), (nu, n2)).copy_from(&v);
    let scale = amb_b.amax().max(f64::MIN_POSITIVE);
    let defect = (&amb_b - &bm * &a).amax() / scale;

    // inputs: a unit generalized force on each velocity, δu̇ = M⁻¹(e_k + Gᵀ μ)
    let du_in = saddle_solve(&chol, &g, &eye, &DMatrix::zeros(nc, nu));
    let mut b = DMatrix::zeros(nx, nu);
    b.view_mut((n1, 0), (n2, nu)).copy_from(&(&lu * du_in));

    let mut rate = DVector::zeros(nx);
    rate.rows_mut(0, n1).copy_from(&(&lh * DVector::from_column_slice(u)));
    rate.rows_mut(n1, n2).copy_from(&(&lu * DVector::from_column_slice(&a0)));

    if let Some(x) = a.iter().chain(b.iter()).find(|x| !x.is_finite()) {
        return Err(Error::Solver(format!("linearize: a state-matrix entry is not finite ({x})")));
    }
    Ok(StateSpace {
        nq: n1,
        nu: n2,
        a: row_major(&a),
        b: row_major(&b),
        vh: row_major(&vh),
        p: row_major(&p),
        v: row_major(&v),
        lh: row_major(&lh),
        lu: row_major(&lu),
        independent_q: indep_q,
        independent_u: indep_u,
        rate: rate.iter().copied().collect(),
        defect,
        mass: row_major(&mass),
        phi,
        velocity_residual,
        method,
    })
}

fn row_major(a: &DMatrix<f64>) -> Vec<f64> {
    (0..a.nrows()).flat_map(|r| (0..a.ncols()).map(move |c| a[(r, c)])).collect()
}

/// `Ω(u*)`: the chart coordinates' rate beyond `δu`, `δ̇ = Ω δ + δu` (nu × nu). Zero for joints
/// with `q̇ = u`; for rotations in the child frame `−ω* ×` (and the free joint's position,
/// moved by `A(q) v`, `−ω* × δ_p − v* × δ_θ`).
pub(super) fn chart_rate(model: &Model, u: &[f64]) -> DMatrix<f64> {
    let nu = model.nu;
    let mut om = DMatrix::zeros(nu, nu);
    let put = |om: &mut DMatrix<f64>, r: usize, c: usize, w: &Vec3| {
        let m = -w.cross_matrix();
        for i in 0..3 {
            for k in 0..3 {
                om[(r + i, c + k)] += m[(i, k)];
            }
        }
    };
    for j in &model.joints {
        let i = j.iu;
        match j.kind {
            JointKind::Spherical => {
                let w = Vec3::new(u[i], u[i + 1], u[i + 2]);
                put(&mut om, i, i, &w);
            }
            JointKind::Free => {
                let v = Vec3::new(u[i], u[i + 1], u[i + 2]);
                let w = Vec3::new(u[i + 3], u[i + 4], u[i + 5]);
                put(&mut om, i, i, &w);
                put(&mut om, i, i + 3, &v);
                put(&mut om, i + 3, i + 3, &w);
            }
            _ => {}
        }
    }
    om
}

/// A basis `V` of the null space of `g` (rows: constraints) with a left inverse `L` (`L V = I`)
/// and, for a partition, the independent indices.
fn admissible(g: &DMatrix<f64>, nu: usize, basis: &Basis) -> (DMatrix<f64>, DMatrix<f64>, Vec<usize>) {
    if g.nrows() == 0 {
        return (DMatrix::identity(nu, nu), DMatrix::identity(nu, nu), (0..nu).collect());
    }
    match basis {
        Basis::Orthonormal => {
            let v = null_space(g, nu);
            let l = v.transpose();
            (v, l, Vec::new())
        }
        Basis::Partition(prefer) => {
            let dep = dependent_columns(g, prefer);
            let indep: Vec<usize> = (0..nu).filter(|c| !dep.contains(c)).collect();
            let gd = DMatrix::from_fn(g.nrows(), dep.len(), |r, c| g[(r, dep[c])]);
            let gi = DMatrix::from_fn(g.nrows(), indep.len(), |r, c| g[(r, indep[c])]);
            let x = pinv(&gd) * gi; // dependent = −x · independent
            let mut v = DMatrix::zeros(nu, indep.len());
            for (k, &i) in indep.iter().enumerate() {
                v[(i, k)] = 1.0;
            }
            for (k, &d) in dep.iter().enumerate() {
                for c in 0..indep.len() {
                    v[(d, c)] = -x[(k, c)];
                }
            }
            let mut l = DMatrix::zeros(indep.len(), nu);
            for (k, &i) in indep.iter().enumerate() {
                l[(k, i)] = 1.0;
            }
            (v, l, indep)
        }
    }
}

/// Columns of `g` to solve for (one per independent row), by pivoted Gram–Schmidt: the column
/// with the largest remaining part, among the non-preferred ones unless a preferred column is
/// ten times better conditioned.
fn dependent_columns(g: &DMatrix<f64>, prefer: &[usize]) -> Vec<usize> {
    let mut r = g.clone();
    let scale = g.amax().max(f64::MIN_POSITIVE);
    let mut dep = Vec::new();
    loop {
        let norms: Vec<f64> = (0..r.ncols()).map(|c| if dep.contains(&c) { 0.0 } else { r.column(c).norm() }).collect();
        let best = |pref: bool| {
            (0..r.ncols())
                .filter(|c| prefer.contains(c) == pref)
                .max_by(|&a, &b| norms[a].total_cmp(&norms[b]))
                .map(|c| (c, norms[c]))
                .unwrap_or((usize::MAX, 0.0))
        };
        let (cn, vn) = best(false);
        let (cp, vp) = best(true);
        let top = vn.max(vp);
        if top <= 1e-9 * scale || dep.len() == g.nrows() {
            break;
        }
        let c = if vn >= 0.1 * vp { cn } else { cp };
        dep.push(c);
        let e = r.column(c) / norms[c];
        for k in 0..r.ncols() {
            let d = e.dot(&r.column(k));
            let col = r.column(k) - &e * d;
            r.set_column(k, &col);
        }
    }
    dep.sort_unstable();
    dep
}

/// Moore–Penrose inverse by SVD (relative cut-off 1e-10).
fn pinv(a: &DMatrix<f64>) -> DMatrix<f64> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return DMatrix::zeros(a.ncols(), a.nrows());
    }
    let svd = a.clone().svd(true, true);
    let top = svd.singular_values.iter().fold(0.0f64, |m, s| m.max(*s));
    svd.pseudo_inverse(1e-10 * top.max(f64::MIN_POSITIVE)).expect("both factors computed")
}

/// `P` with `G P = −J`: minimum norm (orthonormal bases, `P ⊥ V`), or zero on the independent
/// velocities (partition, `L_u P = 0`).
fn correction(g: &DMatrix<f64>, j: &DMatrix<f64>, indep_u: &[usize], basis: &Basis) -> DMatrix<f64> {
    let nu = g.ncols();
    match basis {
        Basis::Orthonormal => -(pinv(g) * j),
        Basis::Partition(_) => {
            let dep: Vec<usize> = (0..nu).filter(|c| !indep_u.contains(c)).collect();
            let gd = DMatrix::from_fn(g.nrows(), dep.len(), |r, c| g[(r, dep[c])]);
            let x = -(pinv(&gd) * j);
            let mut p = DMatrix::zeros(nu, j.ncols());
            for (k, &d) in dep.iter().enumerate() {
                p.set_row(d, &x.row(k));
            }
            p
        }
    }
}

/// `δu̇` of the linearized saddle-point system `M δu̇ − Gᵀ μ = r1`, `G δu̇ = r2` (columns), with
/// minimum-norm multipliers for redundant rows.
fn saddle_solve(
    chol: &nalgebra::Cholesky<f64, nalgebra::Dyn>,
    g: &DMatrix<f64>,
    r1: &DMatrix<f64>,
    r2: &DMatrix<f64>,
) -> DMatrix<f64> {
    let free = chol.solve(r1);
    if g.nrows() == 0 {
        return free;
    }
    let y = chol.solve(&g.transpose()); // M⁻¹ Gᵀ
    let s = g * &y;
    let mu = pinv(&s) * (r2 - g * &free);
    free + y * mu
}

/// Five-point differences of `f(q, u)` along the columns of `dirs`, in q (chart, `config`) or in
/// u (step scaled by `max(1, |u|∞)`).
fn differentiate_state(
    model: &Model,
    q: &[f64],
    u: &[f64],
    dirs: &DMatrix<f64>,
    config: bool,
    f: &mut impl FnMut(&[f64], &[f64]) -> Result<DVector<f64>>,
) -> Result<DMatrix<f64>> {
    let (nq, nu) = (model.nq, model.nu);
    let h = if config { STEP } else { STEP * u.iter().fold(1.0f64, |a, x| a.max(x.abs())) };
    let (mut qp, mut up) = (vec![0.0; nq], vec![0.0; nu]);
    let mut out: Option<DMatrix<f64>> = None;
    for j in 0..dirs.ncols() {
        let dir: Vec<f64> = dirs.column(j).iter().copied().collect();
        let mut acc: Option<DVector<f64>> = None;
        for (s, w) in [(2.0, -1.0), (1.0, 8.0), (-1.0, -8.0), (-2.0, 1.0)] {
            if config {
                model.integrate(q, &dir, s * h, &mut qp);
                model.normalize(&mut qp);
                up.copy_from_slice(u);
            } else {
                qp.copy_from_slice(q);
                for i in 0..nu {
                    up[i] = u[i] + s * h * dir[i];
                }
            }
            let val = f(&qp, &up)? * w;
            acc = Some(match acc {
                Some(a) => a + val,
                None => val,
            });
        }
        let col = acc.expect("four points") / (12.0 * h);
        let o = out.get_or_insert_with(|| DMatrix::zeros(col.len(), dirs.ncols()));
        o.set_column(j, &col);
    }
    Ok(out.unwrap_or_else(|| DMatrix::zeros(0, dirs.ncols())))
}
