//! Elastic bodies in the floating frame of reference (sections 2.2.8, 2.4.2, 2.4.3).
//!
//! A body point at `r0` (body frame B, undeformed) moves to `s = r0 + Φ(r0) q_e`: the Ritz
//! ansatz with shape functions Φ (3 × n_e) and elastic coordinates `q_e`; in the inertial frame
//! `x = r_IB + A_IB s` (the vector chain of eq. 2.133, linear in the deformation). Its velocity is
//! the rigid velocity of the reference frame at `x` plus `A Φ q̇_e` (eq. 2.191 to first order),
//! and the kinetic energy (eq. 2.192) splits into time functions and integrals over the body that
//! are evaluated once, beforehand (the Ritz separation of 2.4.2). With
//!
//! - `S_t,k = ∫ Φ_k dm` (the first-order coupling with translation),
//! - `P1_k = ∫ r0 Φ_kᵀ dm` and `P2_kl = ∫ Φ_k Φ_lᵀ dm` (3 × 3 each),
//!
//! everything follows exactly for the Ritz field, second-order terms in `q_e` included:
//! `∫ s Φ_kᵀ dm = Q_k = P1_k + Σ_l q_l P2_lk`, the deformed first moment `m c0 + Σ q_k S_t,k`,
//! the deformed inertia from `∫ s sᵀ dm`, the elastic mass matrix `(M_ee)_kl = tr P2_kl`.
//!
//! In world spatial components about the origin (the engine's convention) the body contributes
//!
//! - the deformed rigid inertia `I(q_e)` of the reference twist `V = (ω, v_O)`,
//! - the coupling `C_k = (∫ x × AΦ_k dm + A S_r,k, A S_t,k)`: `T = ½VᵀIV + Vᵀ C q̇_e + ½ q̇_eᵀ M_ee q̇_e`,
//!   where `S_r,k = ∫ J ψ_k` and `M_ee`'s part `∫ ψ_kᵀ J ψ_l` come from the mass elements' own rotary
//!   inertia J turning by the small rotations ψ (a shaft's torsion: optional, given by the body),
//! - the Newton–Euler force `f = I a + V ×* I V + F_c + C q̈_e` with the Coriolis force of the
//!   elastic velocities `F_c = ∫ (x × 2ω×AΦq̇, 2ω×AΦq̇) dm + (ω × A S_r q̇, 0)`,
//! - the elastic equations `Cᵀ (a - g) + M_ee q̈_e + b_e + K q_e + D q̇_e + K_g q_e = Q_e`, where
//!   `b_e,k = (A S_t,k)·(ω × v_B) + tr(ω̃_B² Q_k) + 2 Σ_l q̇_l ω_B · ∫ Φ_l × Φ_k dm` collects
//!   the centrifugal and Coriolis terms of the reference motion, `v_B` the velocity of B's origin.
//!
//! `K_g` is the geometric (stress) stiffness of the reference motion's body forces: the engine
//! is given the geometric stiffness of 12 unit fields of body force per unit mass (3 uniform,
//! `e_a`, and 9 linear, `e_a s_b`) and combines them with the field of gravity and of the
//! reference motion's velocity terms, `A_IBᵀ(g - ω × v_B) - ω̃_B² s`, at every evaluation:
//! centrifugal stiffening of a spinning beam, softening under axial compression by its weight.
//! The parts of the stress state from the reference accelerations (α, a_B) are left out: they
//! would make the mass matrix depend on `q_e` through `K_g`, for a term of second order.

use nalgebra::DMatrix;

use crate::data::Data;
use crate::error::Result;
use crate::math::{Mat3, Vec3};
use crate::model::description::ElasticDescription;
use crate::spatial::{Force, Motion, RigidInertia};

/// A node (or point) of an elastic body: where markers attach, with its translation and small
/// rotation per elastic coordinate (eq. 2.134).
#[derive(Debug, Clone, PartialEq)]
pub struct ElasticNode {
    /// Node name.
    pub name: String,
    /// Undeformed position, body frame (m).
    pub position: Vec3,
    /// Translation per unit elastic coordinate, body frame (n_e columns).
    pub translation: Vec<Vec3>,
    /// Small rotation per unit elastic coordinate, body frame (n_e columns; empty if not given).
    pub rotation: Vec<Vec3>,
}

/// The validated elastic part of a body: its coordinates and the Ritz invariants.
#[derive(Debug, Clone, PartialEq)]
pub struct ElasticBody {
    /// The body it makes elastic.
    pub body: usize,
    /// First coordinate and velocity index of `q_e` (coordinates and velocities coincide).
    pub iq: usize,
    /// First velocity index.
    pub iu: usize,
    /// Number of elastic coordinates.
    pub ne: usize,
    /// `∫ r0 r0ᵀ dm` about the body origin, body frame.
    pub r0r0: Mat3,
    /// `S_t,k = ∫ Φ_k dm`.
    pub s_t: Vec<Vec3>,
    /// `∫ J ψ_k`: the rotary inertia's coupling of mode k with the reference rotation (body frame).
    pub s_r: Vec<Vec3>,
    /// `P1_k = ∫ r0 Φ_kᵀ dm`.
    pub p1: Vec<Mat3>,
    /// `P2_kl = ∫ Φ_k Φ_lᵀ dm`, at `k * ne + l`.
    pub p2: Vec<Mat3>,
    /// `∫ Φ_l × Φ_k dm` (the axial vector of `P2_lk`), at `l * ne + k`.
    pub cross: Vec<Vec3>,
    /// Elastic mass matrix `tr P2_kl` (plus the rotary mass `∫ ψ_kᵀ J ψ_l`).
    pub m_ee: DMatrix<f64>,
    /// Stiffness.
    pub k: DMatrix<f64>,
    /// Damping.
    pub d: DMatrix<f64>,
    /// Geometric stiffness of the 12 unit body-force fields (empty: none given).
    pub geometric: Vec<DMatrix<f64>>,
    /// Nodes.
    pub nodes: Vec<ElasticNode>,
    /// Initial elastic coordinates and velocities.
    pub q0: Vec<f64>,
    /// Initial elastic velocities.
    pub u0: Vec<f64>,
}

/// The per-evaluation quantities of one elastic body (in [`Data::elastic`]).
#[derive(Debug, Clone, Default)]
pub struct ElasticWork {
    /// Elastic coordinates of this evaluation.
    pub q: Vec<f64>,
    /// Their rates.
    pub qd: Vec<f64>,
    /// Their accelerations (of the last acceleration stage).
    pub qdd: Vec<f64>,
    /// `Q_k = ∫ s Φ_kᵀ dm`, body frame.
    pub qk: Vec<Mat3>,
    /// Couplings `C_k`, world spatial forces about the origin.
    pub c: Vec<Force>,
    /// Scratch of length n_e.
    pub tmp: Vec<f64>,
    /// First elastic velocity index (for the generalized forces of loads at nodes).
    pub iu: usize,
    /// Undeformed node positions (body frame).
    pub nodes: Vec<Vec3>,
    /// Node translations per elastic coordinate, node-major: `phi[n * n_e + k]`.
    pub phi: Vec<Vec3>,
    /// Node small rotations per elastic coordinate (eq. 2.134), node-major (zero where not given).
    pub psi: Vec<Vec3>,
}

impl ElasticWork {
    /// The node at the body-frame point `p_b` (a point given at a node's position moves with it).
    #[inline]
    pub fn node_at(&self, p_b: &Vec3) -> Option<usize> {
        let tol = 1e-12 * (1.0 + p_b.norm());
        self.nodes.iter().position(|n| (n - p_b).amax() <= tol)
    }
    /// `Σ_k x_k φ_nk` for the coordinates (or rates, accelerations) `x`: the node's deflection.
    #[inline]
    pub fn node_field(&self, n: usize, x: &[f64]) -> Vec3 {
        let ne = x.len();
        let mut d = Vec3::zeros();
        for (k, xk) in x.iter().enumerate() {
            d += self.phi[n * ne + k] * *xk;
        }
        d
    }
    /// `Σ_k x_k ψ_nk`: the node's small rotation (eq. 2.134) of the coordinates `x`, body frame.
    #[inline]
    pub fn node_rotation(&self, n: usize, x: &[f64]) -> Vec3 {
        let ne = x.len();
        let mut d = Vec3::zeros();
        for (k, xk) in x.iter().enumerate() {
            d += self.psi[n * ne + k] * *xk;
        }
        d
    }
}

impl ElasticWork {
    /// Sized for `e` (the node tables copied: point kinematics read them from the data alone).
    pub fn new(e: &ElasticBody) -> Self {
        ElasticWork {
            q: e.q0.clone(),
            qd: e.u0.clone(),
            qdd: vec![0.0; e.ne],
            qk: vec![Mat3::zeros(); e.ne],
            c: vec![Force::ZERO; e.ne],
            tmp: vec![0.0; e.ne],
            iu: e.iu,
            nodes: e.nodes.iter().map(|n| n.position).collect(),
            phi: e.nodes.iter().flat_map(|n| n.translation.iter().copied()).collect(),
            psi: e
                .nodes
                .iter()
                .flat_map(|n| (0..e.ne).map(move |k| n.rotation.get(k).copied().unwrap_or_else(Vec3::zeros)))
                .collect(),
        }
    }
}

/// The axial vector of the antisymmetric part: `∫ s × φ dm` from `∫ s φᵀ dm`.
#[inline]
fn axial(m: &Mat3) -> Vec3 {
    Vec3::new(m[(1, 2)] - m[(2, 1)], m[(2, 0)] - m[(0, 2)], m[(0, 1)] - m[(1, 0)])
}

fn mat3(v: &[f64; 9]) -> Mat3 {
    Mat3::new(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8])
}

fn square(rows: &[Vec<f64>], n: usize, what: &str) -> Result<DMatrix<f64>> {
    crate::ensure!(
        rows.len() == n,
        Model,
        "{what}: expected {n} rows (one per elastic coordinate), got {}",
        rows.len()
    );
    let mut m = DMatrix::zeros(n, n);
    for (r, row) in rows.iter().enumerate() {
        crate::ensure!(row.len() == n, Model, "{what}[{r}]: expected {n} numbers, got {}", row.len());
        for (c, v) in row.iter().enumerate() {
            crate::ensure!(v.is_finite(), Model, "{what}[{r}][{c}]: must be finite, got {v}");
            m[(r, c)] = *v;
        }
    }
    Ok(m)
}

fn symmetric(m: &DMatrix<f64>, what: &str) -> Result<()> {
    let scale = m.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
    for r in 0..m.nrows() {
        for c in 0..r {
            crate::ensure!(
                (m[(r, c)] - m[(c, r)]).abs() <= 1e-9 * scale,
                Model,
                "{what}: not symmetric, entry [{r}][{c}] = {} but [{c}][{r}] = {}",
                m[(r, c)],
                m[(c, r)]
            );
        }
    }
    Ok(())
}

/// Smallest eigenvalue of a symmetric matrix.
fn smallest_eigenvalue(m: &DMatrix<f64>) -> f64 {
    m.clone().symmetric_eigen().eigenvalues.iter().fold(f64::INFINITY, |a, v| a.min(*v))
}

/// Validates the elastic part of body `body` (mass `mass`, centre of mass `com`, inertia about
/// it `i_c`, all undeformed) with its coordinates from `iq`, `iu`. Errors name `what`.
#[allow(clippy::too_many_arguments)]
pub fn validate(
    d: &ElasticDescription,
    body: usize,
    mass: f64,
    com: &Vec3,
    i_c: &Mat3,
    iq: usize,
    iu: usize,
    what: &str,
) -> Result<ElasticBody> {
    let what = format!("{what}.elastic");
    let ne = d.modes;
    crate::ensure!(ne >= 1, Model, "{what}.modes: an elastic body needs at least one elastic coordinate, got 0");
    crate::ensure!(ne <= 200, Model, "{what}.modes: at most 200 elastic coordinates per body, got {ne}");
    let finite = |v: &[f64], w: String| -> Result<()> {
        match v.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(crate::error::Error::Model(format!("{w}[{i}]: must be finite, got {}", v[i]))),
            None => Ok(()),
        }
    };
    crate::ensure!(d.s_t.len() == ne, Model, "{what}.s_t: expected {ne} vectors (one per mode), got {}", d.s_t.len());
    crate::ensure!(d.p1.len() == ne, Model, "{what}.p1: expected {ne} 3x3 matrices (one per mode), got {}", d.p1.len());
    crate::ensure!(
        d.p2.len() == ne * ne,
        Model,
        "{what}.p2: expected {} 3x3 matrices (one per pair of modes), got {}",
        ne * ne,
        d.p2.len()
    );
    for (k, v) in d.s_t.iter().enumerate() {
        finite(v, format!("{what}.s_t[{k}]"))?;
    }
    for (k, v) in d.p1.iter().enumerate() {
        finite(v, format!("{what}.p1[{k}]"))?;
    }
    for (k, v) in d.p2.iter().enumerate() {
        finite(v, format!("{what}.p2[{k}]"))?;
    }
    let p2: Vec<Mat3> = d.p2.iter().map(mat3).collect();
    // P2_kl = P2_lkᵀ by its definition
    let scale = p2.iter().fold(0.0f64, |a, m| a.max(m.amax())).max(f64::MIN_POSITIVE);
    for k in 0..ne {
        for l in 0..ne {
            let diff = (p2[k * ne + l] - p2[l * ne + k].transpose()).amax();
            crate::ensure!(
                diff <= 1e-9 * scale,
                Model,
                "{what}.p2: the entries of modes ({k}, {l}) and ({l}, {k}) must be each other's transpose (∫ Φ_k Φ_lᵀ dm)"
            );
        }
    }
    let mut m_ee = DMatrix::zeros(ne, ne);
    for k in 0..ne {
        for l in 0..ne {
            m_ee[(k, l)] = p2[k * ne + l].trace();
        }
    }
    // the mass elements' own rotary inertia (a twist of a shaft's axis carries no translation)
    let s_r = match &d.s_r {
        Some(v) => {
            crate::ensure!(v.len() == ne, Model, "{what}.s_r: expected {ne} vectors (one per mode), got {}", v.len());
            for (k, x) in v.iter().enumerate() {
                finite(x, format!("{what}.s_r[{k}]"))?;
            }
            v.iter().map(|x| Vec3::from(*x)).collect()
        }
        None => vec![Vec3::zeros(); ne],
    };
    if let Some(rows) = &d.m_rr {
        let m_rr = square(rows, ne, &format!("{what}.m_rr"))?;
        symmetric(&m_rr, &format!("{what}.m_rr"))?;
        let rmin = smallest_eigenvalue(&m_rr);
        crate::ensure!(
            rmin >= -1e-9 * m_rr.amax().max(m_ee.amax()),
            Model,
            "{what}.m_rr: the rotary mass must be positive semi-definite (smallest eigenvalue {rmin:.3e})"
        );
        m_ee += m_rr;
    }
    let m_min = smallest_eigenvalue(&m_ee);
    crate::ensure!(
        m_min > 1e-12 * m_ee.amax().max(f64::MIN_POSITIVE),
        Model,
        "{what}: the elastic mass matrix (traces of p2, plus m_rr) is not positive definite (smallest eigenvalue \
         {m_min:.3e}): the shape functions are linearly dependent or zero, or a mode moves only mass without \
         translation (a twist about an axis of mass points) and its rotary mass m_rr is not given"
    );
    let k = square(&d.stiffness, ne, &format!("{what}.stiffness"))?;
    symmetric(&k, &format!("{what}.stiffness"))?;
    // generalized eigenvalues of (K, M_ee): ω² > 0 for every mode, else a rigid-body mode (or a
    // mode without stiffness) is left in the elastic basis
    let not_pd = || {
        crate::error::Error::Model(format!(
            "{what}: the elastic mass matrix (traces of p2) is too ill-conditioned to factor"
        ))
    };
    let l = m_ee.clone().cholesky().ok_or_else(not_pd)?.l();
    let li = l.clone().try_inverse().ok_or_else(not_pd)?;
    let kk = &li * &k * li.transpose();
    let w2 = kk.symmetric_eigen().eigenvalues;
    let (w2min, w2max) = w2.iter().fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(*v), b.max(*v)));
    crate::ensure!(
        w2min > 1e-10 * w2max.max(f64::MIN_POSITIVE),
        Model,
        "{what}.stiffness: a mode without stiffness (ω² = {w2min:.3e} 1/s²): a rigid-body mode is left in the elastic \
         basis (the reference frame already carries the rigid motion) or the stiffness is not positive definite"
    );
    let dm = match &d.damping {
        Some(rows) => {
            let dm = square(rows, ne, &format!("{what}.damping"))?;
            symmetric(&dm, &format!("{what}.damping"))?;
            let dmin = smallest_eigenvalue(&dm);
            crate::ensure!(
                dmin >= -1e-12 * dm.amax(),
                Model,
                "{what}.damping: must be positive semi-definite (smallest eigenvalue {dmin:.3e})"
            );
            dm
        }
        None => DMatrix::zeros(ne, ne),
    };
    let geometric = match &d.geometric {
        Some(g) => {
            crate::ensure!(
                g.len() == 12,
                Model,
                "{what}.geometric: expected 12 matrices (3 uniform, then 9 linear unit body-force fields), got {}",
                g.len()
            );
            let mut out = Vec::with_capacity(12);
            for (f, rows) in g.iter().enumerate() {
                let m = square(rows, ne, &format!("{what}.geometric[{f}]"))?;
                symmetric(&m, &format!("{what}.geometric[{f}]"))?;
                out.push(m);
            }
            out
        }
        None => Vec::new(),
    };
    let mut nodes = Vec::with_capacity(d.nodes.len());
    let mut names = std::collections::HashSet::new();
    for (n, nd) in d.nodes.iter().enumerate() {
        let w = format!("{what}.nodes[{n}] '{}'", nd.name);
        crate::ensure!(names.insert(nd.name.clone()), Model, "{w}: duplicate node name");
        finite(&nd.position, format!("{w}.position"))?;
        crate::ensure!(
            nd.translation.len() == ne,
            Model,
            "{w}.translation: expected {ne} vectors (one per mode), got {}",
            nd.translation.len()
        );
        crate::ensure!(
            nd.rotation.is_empty() || nd.rotation.len() == ne,
            Model,
            "{w}.rotation: expected {ne} vectors (one per mode) or none, got {}",
            nd.rotation.len()
        );
        for (k, v) in nd.translation.iter().chain(&nd.rotation).enumerate() {
            finite(v, format!("{w}.translation/rotation[{k}]"))?;
        }
        nodes.push(ElasticNode {
            name: nd.name.clone(),
            position: Vec3::from(nd.position),
            translation: nd.translation.iter().map(|v| Vec3::from(*v)).collect(),
            rotation: nd.rotation.iter().map(|v| Vec3::from(*v)).collect(),
        });
    }
    let vec_or_zero = |v: &Option<Vec<f64>>, key: &str| -> Result<Vec<f64>> {
        match v {
            None => Ok(vec![0.0; ne]),
            Some(v) => {
                crate::ensure!(v.len() == ne, Model, "{what}.{key}: expected {ne} numbers, got {}", v.len());
                finite(v, format!("{what}.{key}"))?;
                Ok(v.clone())
            }
        }
    };
    // ∫ r0 r0ᵀ dm from the undeformed mass properties: ∫ ρρᵀ dm = ½ tr(I_c) E - I_c about the centre
    let r0r0 = Mat3::identity() * (0.5 * i_c.trace()) - i_c + com * com.transpose() * mass;
    let mut cross = vec![Vec3::zeros(); ne * ne];
    for l in 0..ne {
        for k in 0..ne {
            cross[l * ne + k] = axial(&p2[l * ne + k]);
        }
    }
    Ok(ElasticBody {
        body,
        iq,
        iu,
        ne,
        r0r0,
        s_t: d.s_t.iter().map(|v| Vec3::from(*v)).collect(),
        s_r,
        p1: d.p1.iter().map(mat3).collect(),
        p2,
        cross,
        m_ee,
        k,
        d: dm,
        geometric,
        nodes,
        q0: vec_or_zero(&d.q0, "q0")?,
        u0: vec_or_zero(&d.u0, "u0")?,
    })
}

/// The deformed inertia (world, about the origin) of elastic body `e` at the stored `q_e`, and its
/// couplings `C_k`; `mass`, `com` are the body's (undeformed centre of mass, body frame).
pub fn deform(e: &ElasticBody, data: &mut Data, k_e: usize, mass: f64, com: &Vec3) {
    let i = e.body;
    let x = data.x_abs[i];
    let w = &mut data.elastic[k_e];
    let ne = e.ne;
    // Q_k = P1_k + Σ_l q_l P2_lk, and ∫ s sᵀ dm = ∫ r0 r0ᵀ + Σ_k q_k (P1_k + P1_kᵀ) + Σ_kl q_k q_l P2_kl
    let mut ss = e.r0r0;
    let mut h_b = com * mass;
    for k in 0..ne {
        let mut qk = e.p1[k];
        for l in 0..ne {
            qk += e.p2[l * ne + k] * w.q[l];
        }
        w.qk[k] = qk;
        // Σ_k q_k (P1_k + P1_kᵀ + Σ_l q_l P2_kl) = Σ_k q_k (P1_k + Q_kᵀ), as P2_lkᵀ = P2_kl
        ss += (e.p1[k] + qk.transpose()) * w.q[k];
        h_b += e.s_t[k] * w.q[k];
    }
    let j_b = Mat3::identity() * ss.trace() - ss;
    let inertia_b = RigidInertia { m: mass, h: h_b, i_o: j_b };
    data.inertia[i] = inertia_b.to_parent(&x);
    // C_k = (r × A S_t,k + A ∫ s × Φ_k dm, A S_t,k)
    for k in 0..ne {
        let lin = x.a * e.s_t[k];
        w.c[k] = Force::new(x.r.cross(&lin) + x.a * (axial(&w.qk[k]) + e.s_r[k]), lin);
    }
}

/// The body's Newton–Euler force beyond the rigid terms, the Coriolis force of the elastic
/// velocities `F_c` (world, about the origin), from the body's twist `v`.
pub fn coriolis_force(e: &ElasticBody, w: &ElasticWork, x: &crate::spatial::Pose, v: &Motion) -> Force {
    let om = v.w;
    let om_b = x.a.transpose() * om;
    // Σ_l q̇_l (r × (ω × A S_t,l) + A (ω_B tr Q_l - Q_lᵀ ω_B)) and Σ_l q̇_l ω × A S_t,l, doubled
    let mut st_qd = Vec3::zeros();
    let mut ang_b = Vec3::zeros();
    let mut sr_qd = Vec3::zeros();
    for l in 0..e.ne {
        let qd = w.qd[l];
        if qd == 0.0 {
            continue;
        }
        st_qd += e.s_t[l] * qd;
        sr_qd += e.s_r[l] * qd;
        ang_b += (om_b * w.qk[l].trace() - w.qk[l].transpose() * om_b) * qd;
    }
    let lin = om.cross(&(x.a * st_qd));
    // the rotary inertia's angular momentum A ∫ J ψ q̇ turns with the body: ω × (A S_r q̇), once
    Force::new((x.r.cross(&lin) + x.a * ang_b) * 2.0 + om.cross(&(x.a * sr_qd)), lin * 2.0)
}

/// The velocity-dependent terms of the elastic equations, `b_e`, into `out` (length n_e).
pub fn elastic_bias(e: &ElasticBody, w: &ElasticWork, x: &crate::spatial::Pose, v: &Motion, out: &mut [f64]) {
    let om = v.w;
    let om_b = x.a.transpose() * om;
    // velocity of B's origin: v_O + ω × r
    let v_b = v.v + om.cross(&x.r);
    let om_v = x.a.transpose() * om.cross(&v_b);
    let wt = crate::math::tilde(&om_b);
    let w2 = wt * wt;
    let ne = e.ne;
    for k in 0..ne {
        let mut b = e.s_t[k].dot(&om_v) + (w2 * w.qk[k]).trace();
        for l in 0..ne {
            b += 2.0 * w.qd[l] * om_b.dot(&e.cross[l * ne + k]);
        }
        out[k] = b;
    }
}

/// The elastic body's kinetic energy beyond `½ Vᵀ I(q_e) V`: `Vᵀ C q̇_e + ½ q̇_eᵀ M_ee q̇_e`.
pub fn kinetic_energy_extra(e: &ElasticBody, w: &ElasticWork, v: &Motion) -> f64 {
    let mut t = 0.0;
    for k in 0..e.ne {
        t += v.dot(&w.c[k]) * w.qd[k];
        for l in 0..e.ne {
            t += 0.5 * w.qd[k] * e.m_ee[(k, l)] * w.qd[l];
        }
    }
    t
}

/// Strain energy `½ q_eᵀ K q_e` (eq. 2.199 after the Ritz separation).
pub fn strain_energy(e: &ElasticBody, q: &[f64]) -> f64 {
    let mut u = 0.0;
    for k in 0..e.ne {
        for l in 0..e.ne {
            u += 0.5 * q[k] * e.k[(k, l)] * q[l];
        }
    }
    u
}

/// Adds the geometric stiffness force `-K_g(field) q_e` to `out`, the body-force field per unit
/// mass of the reference motion being `b(s) = c + L s` (body frame) with `c = A_IBᵀ(g - a_B)` and
/// `L = -(α̃_B + ω̃_B²)`.
pub fn add_geometric_force(e: &ElasticBody, q: &[f64], c: &Vec3, l: &Mat3, out: &mut [f64]) {
    if e.geometric.is_empty() {
        return;
    }
    let ne = e.ne;
    for (f, kg) in e.geometric.iter().enumerate() {
        let s = if f < 3 { c[f] } else { l[((f - 3) / 3, (f - 3) % 3)] };
        if s == 0.0 {
            continue;
        }
        for r in 0..ne {
            let mut acc = 0.0;
            for cc in 0..ne {
                acc += kg[(r, cc)] * q[cc];
            }
            out[r] -= s * acc;
        }
    }
}

/// Newton–Euler terms of the elastic bodies for the inward pass: adds `F_c + C q̈_e` to each
/// elastic body's force `f` and writes the elastic rows `out[iu..iu + n_e]` =
/// `Cᵀ (a - g) + M_ee q̈ + b_e + K q + D q̇ - (geometric force) - τ_applied` (the residual of the
/// elastic equations; `-h_e` at zero acceleration).
pub fn rnea_terms(model: &crate::model::Model, data: &mut Data, out: &mut [f64]) {
    let g = Motion::new(Vec3::zeros(), model.gravity);
    for (k_e, e) in model.elastic.iter().enumerate() {
        let i = e.body;
        let x = data.x_abs[i];
        let v = data.v[i];
        let a_rel = data.a[i] - g;
        let w = &mut data.elastic[k_e];
        let mut f = coriolis_force(e, w, &x, &v);
        for k in 0..e.ne {
            f += w.c[k] * w.qdd[k];
        }
        data.f[i] += f;
        let mut tmp = std::mem::take(&mut w.tmp);
        elastic_bias(e, w, &x, &v, &mut tmp);
        for k in 0..e.ne {
            let mut r = a_rel.dot(&w.c[k]) + tmp[k];
            for l in 0..e.ne {
                r += e.m_ee[(k, l)] * w.qdd[l] + e.k[(k, l)] * w.q[l] + e.d[(k, l)] * w.qd[l];
            }
            out[e.iu + k] = r - data.tau_applied[e.iu + k];
        }
        if !e.geometric.is_empty() {
            // the reference motion's body-force field: c + L s, c = Aᵀ(g - ω × v_B), L = -ω̃_B²
            let om = v.w;
            let v_b = v.v + om.cross(&x.r);
            let c = x.a.transpose() * (model.gravity - om.cross(&v_b));
            let wt = crate::math::tilde(&(x.a.transpose() * om));
            let l = -(wt * wt);
            tmp.iter_mut().for_each(|t| *t = 0.0);
            add_geometric_force(e, &w.q, &c, &l, &mut tmp);
            for k in 0..e.ne {
                out[e.iu + k] -= tmp[k];
            }
        }
        w.tmp = tmp;
    }
}

/// Why the mass matrix may have failed to factor with elastic bodies in the model: the body whose
/// elastic coordinates have grown past the small-deformation range (or are not finite), named,
/// for the error message; empty when they look sane.
pub fn runaway(model: &crate::model::Model, data: &Data) -> String {
    for (e, w) in model.elastic.iter().zip(&data.elastic) {
        let big = w.q.iter().fold(0.0f64, |a, v| if v.is_finite() { a.max(v.abs()) } else { f64::INFINITY });
        // the deflection of the largest node against the body's size
        let size = e.nodes.iter().map(|n| n.position.norm()).fold(0.0f64, f64::max).max(1e-300);
        let defl = e
            .nodes
            .iter()
            .map(|n| n.translation.iter().zip(&w.q).fold(Vec3::zeros(), |acc, (t, q)| acc + t * *q).norm())
            .fold(0.0f64, f64::max);
        if !big.is_finite() || (!e.nodes.is_empty() && defl > 10.0 * size) {
            return format!(
                "; the elastic coordinates of body '{}' have run away (largest {big:.3e}, node deflection {defl:.3e} m \
                 on a body {size:.3e} m long): the deformation is no longer small, the model diverged (a missing \
                 geometric stiffness, an instability)",
                model.bodies[e.body].name
            );
        }
    }
    String::new()
}
