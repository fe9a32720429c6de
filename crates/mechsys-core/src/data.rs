//! The workspace: every quantity derived from a model during one evaluation, allocated once.
//!
//! Each field says which stage fills it and its shape. `Data::new(&model)` sizes everything; the
//! algorithms then run without allocating. `Data` holds the quantities the stages share, as plain
//! arrays; a stage's private working memory whose form only that stage knows (the factorization of
//! the constrained solve, the Jenkins chains' slider problems) is the stage's own workspace
//! ([`crate::dynamics::Workspace`], [`crate::forces::Workspace`]), kept next to the `Data`.

use nalgebra::{DMatrix, DVector};

use crate::model::{constraint, Model};
use crate::spatial::{Force, Motion, Pose, RigidInertia, M6, V6};

/// The state of a simulation: time, coordinates, velocities (`q̇ = H*(q) u`, eq. 2.34).
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Time (s).
    pub t: f64,
    /// Generalized coordinates (nq).
    pub q: Vec<f64>,
    /// Generalized velocities (nu).
    pub u: Vec<f64>,
}

/// Workspace of the recursive algorithms, one entry per body (index 0 = ground) or per joint.
#[derive(Debug, Clone)]
pub struct Data {
    /// kinematics: placement of body i in the inertial frame, `a = A_IB`, `r = r_IB` (nbody).
    pub x_abs: Vec<Pose>,
    /// kinematics: placement of the child joint frame of the joint moving body i, in I (nbody).
    pub x_joint: Vec<Pose>,
    /// kinematics: `(sin q, cos q)` of the revolute joint moving body i about a coordinate axis,
    /// computed for all such joints before the placements (nbody; others unused).
    pub sin_cos: Vec<(f64, f64)>,
    /// kinematics: motion subspace of the joint moving body i, world twists (nbody × 6, nu used).
    pub s: Vec<[Motion; 6]>,
    /// kinematics: twist of body i, world components about the origin (nbody).
    pub v: Vec<Motion>,
    /// kinematics: velocity-product acceleration `v_i × v_J + c_J` of body i, world (nbody).
    pub c: Vec<Motion>,
    /// dynamics: spatial acceleration of body i, world, without the gravity offset (nbody).
    pub a: Vec<Motion>,
    /// kinematics: body inertia at the current time, world components about the origin (nbody).
    pub inertia: Vec<RigidInertia>,
    /// forces: external wrench on body i, world components about the origin (nbody).
    pub f_ext: Vec<Force>,
    /// forces: applied generalized forces from joint springs, dampers and joint forces (nu).
    pub tau_applied: Vec<f64>,
    /// forces: the external loads' share of `f_ext` (body forces, thrust), world components
    /// about the origin (nbody): with `tau_load`, what [`crate::forces::Powers::external`] is the
    /// power of, for a scheme that needs their work at other velocities than the forces' own.
    pub f_load: Vec<Force>,
    /// forces: the external loads' share of `tau_applied` (joint forces, servos, callbacks and the
    /// elastic coordinates' share of loads at nodes) (nu).
    pub tau_load: Vec<f64>,
    /// forces: whether the force stage fills `f_load` and `tau_load` (set by the scheme that reads
    /// them; off, they are left as they are).
    pub record_loads: bool,
    /// dynamics: spatial force transmitted by the joint into body i, body frame (nbody).
    pub f: Vec<Force>,
    /// crba: composite rigid-body inertias (nbody).
    pub ic: Vec<RigidInertia>,
    /// crba: mass matrix M(q) (nu × nu).
    pub mass_matrix: DMatrix<f64>,
    /// rnea: generalized forces h(q, u, t) with M u̇ = h + τ (nu).
    pub h: DVector<f64>,
    /// aba: generalized accelerations (nu).
    pub udot: Vec<f64>,
    /// aba: articulated-body inertias (nbody).
    pub ia: Vec<M6>,
    /// aba: articulated bias forces (nbody).
    pub pa: Vec<Force>,
    /// aba: `U = I^A S` per body (nbody × 6, nu used).
    pub u_mat: Vec<[V6; 6]>,
    /// aba: `D⁻¹ = (Sᵀ U)⁻¹` per body (nbody, nu × nu block used).
    pub d_inv: Vec<[[f64; 6]; 6]>,
    /// aba: `τ - Sᵀ p^A` per body (nbody × 6, nu used).
    pub u_bias: Vec<[f64; 6]>,
    /// scratch (nu).
    pub scratch_u: Vec<f64>,
    /// zeros (nu), for h = -rnea(u̇ = 0).
    pub zero_u: Vec<f64>,
    /// constraints: violation Φ (nc).
    pub phi: Vec<f64>,
    /// constraints: G = Wᵀ, rows of the velocity form G u = b (nc × nu).
    pub g: DMatrix<f64>,
    /// constraints: pattern of G, row pointers: row r may be nonzero only at the velocities
    /// `g_row_idx[g_row_ptr[r]..g_row_ptr[r + 1]]`, planned once from each constraint's reach
    /// ([`constraint::row_pattern`]) (nc + 1).
    pub g_row_ptr: Vec<usize>,
    /// constraints: pattern of G, velocity indices of each row, ascending (entries of the pattern).
    pub g_row_idx: Vec<usize>,
    /// constraints: velocity right-hand side b (nc).
    pub b: Vec<f64>,
    /// constraints: acceleration right-hand side γ of G u̇ = γ (nc).
    pub gamma: Vec<f64>,
    /// constraints: Lagrange multipliers λ (nc).
    pub lambda: Vec<f64>,
    /// constrained solve: Cholesky factor of M, row-major (nu × nu).
    pub m_factor: Vec<f64>,
    /// constrained solve: M⁻¹ Gᵀ, column k contiguous (nc × nu).
    pub minv_gt: Vec<f64>,
    /// constrained solve: Schur complement G M⁻¹ Gᵀ or G Gᵀ, row-major (nc × nc).
    pub schur: Vec<f64>,
    /// constrained solve: pivot orders (nu) and (nc).
    pub perm_u: Vec<usize>,
    /// constrained solve: pivot order (nc).
    pub perm_c: Vec<usize>,
    /// constrained solve: scratch (max(nu, nc)) × 2.
    pub work: Vec<f64>,
    /// constrained solve: scratch (max(nu, nc)).
    pub work2: Vec<f64>,
    /// constrained solve: scratch configuration (nq).
    pub q_tmp: Vec<f64>,
    /// constraints: numerical rank of the last dense pivoted factorization (redundant rows only).
    pub constraint_rank: usize,
    /// constraints: Baumgarte feedback (α, β) when that drift control is chosen.
    pub baumgarte: Option<(f64, f64)>,
    /// minimum-norm multipliers: null-space basis of S, column-major (nc × nc at most).
    pub null_basis: Vec<f64>,
    /// minimum-norm multipliers: NᵀN (nc × nc at most).
    pub null_gram: Vec<f64>,
    /// minimum-norm multipliers: pivot order (nc).
    pub perm_null: Vec<usize>,
    /// minimum-norm multipliers: scratch (nc).
    pub null_scratch: Vec<f64>,
    /// constraints: rows found dependent at the last solve (nc).
    pub dependent: Vec<bool>,
    /// constraints: rows the projections leave out (nc): near a singular configuration their
    /// Jacobian row nearly vanishes, and a correction through it would amplify round-off (set by
    /// the smooth integrators' system, `simulate::MultibodySystem`).
    pub skip_rows: Vec<bool>,
    /// forces: committed positions of the Jenkins sliders, the history of the dry friction (n_sliders).
    pub slider: Vec<f64>,
    /// forces: slider positions solved at the last force evaluation (n_sliders).
    pub slider_trial: Vec<f64>,
    /// forces: slider forces λ at the last force evaluation (n_sliders).
    pub slider_force: Vec<f64>,
    /// Force stage: the elastic energy stored in the compliant contacts (their overlaps and
    /// bristles) at the last evaluation (J).
    pub contact_energy: f64,
    /// forces: each element's force at the last evaluation, resisting its deflection (n_force_outputs).
    pub element_force: Vec<f64>,
    /// forces: each element's deflection at the last evaluation (n_force_outputs).
    pub element_deflection: Vec<f64>,
    /// contacts: the user gap functions' scratch and their rows at the last evaluation.
    pub gap: crate::contact::gap::GapWork,
    /// kinematics: each elastic body's coordinates, deformed invariants and couplings.
    pub elastic: Vec<crate::elastic::ElasticWork>,
    /// kinematics: the index into `elastic` of each body that is elastic (nbody).
    pub body_elastic: Vec<Option<usize>>,
}

impl Data {
    /// Allocates a workspace for `model`.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbodies();
        let nu = model.nu;
        let (g_row_ptr, g_row_idx) = constraint::row_pattern(model);
        Data {
            x_abs: vec![Pose::IDENTITY; nb],
            x_joint: vec![Pose::IDENTITY; nb],
            sin_cos: vec![(0.0, 1.0); nb],
            s: vec![[Motion::ZERO; 6]; nb],
            v: vec![Motion::ZERO; nb],
            c: vec![Motion::ZERO; nb],
            a: vec![Motion::ZERO; nb],
            inertia: vec![RigidInertia::default(); nb],
            f_ext: vec![Force::ZERO; nb],
            tau_applied: vec![0.0; nu],
            f_load: vec![Force::ZERO; nb],
            tau_load: vec![0.0; nu],
            record_loads: false,
            f: vec![Force::ZERO; nb],
            ic: vec![RigidInertia::default(); nb],
            mass_matrix: DMatrix::zeros(nu, nu),
            h: DVector::zeros(nu),
            udot: vec![0.0; nu],
            ia: vec![M6::default(); nb],
            pa: vec![Force::ZERO; nb],
            u_mat: vec![[[0.0; 6]; 6]; nb],
            d_inv: vec![[[0.0; 6]; 6]; nb],
            u_bias: vec![[0.0; 6]; nb],
            scratch_u: vec![0.0; nu],
            zero_u: vec![0.0; nu],
            phi: vec![0.0; model.nc],
            g: DMatrix::zeros(model.nc, nu),
            g_row_ptr,
            g_row_idx,
            b: vec![0.0; model.nc],
            gamma: vec![0.0; model.nc],
            lambda: vec![0.0; model.nc],
            m_factor: vec![0.0; if model.nc > 0 { nu * nu } else { 0 }],
            minv_gt: vec![0.0; model.nc * nu],
            schur: vec![0.0; model.nc * model.nc],
            perm_u: vec![0; nu],
            perm_c: vec![0; model.nc],
            work: vec![0.0; nu.max(model.nc)],
            work2: vec![0.0; nu.max(model.nc)],
            q_tmp: vec![0.0; model.nq],
            constraint_rank: 0,
            baumgarte: None,
            null_basis: vec![0.0; model.nc * model.nc],
            null_gram: vec![0.0; model.nc * model.nc],
            perm_null: vec![0; model.nc],
            null_scratch: vec![0.0; model.nc],
            dependent: vec![false; model.nc],
            skip_rows: vec![false; model.nc],
            slider: vec![0.0; model.n_sliders],
            slider_trial: vec![0.0; model.n_sliders],
            slider_force: vec![0.0; model.n_sliders],
            contact_energy: 0.0,
            element_force: vec![0.0; model.n_force_outputs],
            element_deflection: vec![0.0; model.n_force_outputs],
            elastic: model.elastic.iter().map(crate::elastic::ElasticWork::new).collect(),
            body_elastic: model.bodies.iter().map(|b| b.elastic).collect(),
            gap: {
                // the gap functions of contacts and of contacts held closed, by slot
                let mut f: Vec<(usize, &crate::contact::gap::GapFunction)> =
                    model.contacts.iter().filter_map(|c| c.gap().map(|(g, s)| (s, g))).collect();
                f.extend(model.constraints.iter().filter_map(|c| match &c.kind {
                    constraint::ConstraintKind::Gap { function, slot, .. } => Some((*slot, &**function)),
                    _ => None,
                }));
                let slots = f.iter().map(|(s, _)| s + 1).max().unwrap_or(0);
                let functions: Vec<_> = f.iter().map(|(_, g)| *g).collect();
                crate::contact::gap::GapWork::new(slots, model.nq, model.nu, &functions)
            },
        }
    }
}
