use super::bank::{cases, Known};
use super::fixtures::{dense_copy, disk_stack, random_friction_contact, sphere_pile, Rng};
use super::nsgs::local_solve;
use super::*;
use crate::Error;

// ---------- helpers ----------

fn run_lcp(p: &Lcp, method: Method) -> Result<(Vec<f64>, Report)> {
    let mut ws = Workspace::for_problem(p, &method)?;
    let mut z = vec![0.0; p.size()];
    let rep = solve(p, &method, &mut z, false, &mut ws)?;
    Ok((z, rep))
}

fn run_fc(p: &FrictionContact, method: Method) -> Result<(Vec<f64>, Report)> {
    let mut ws = Workspace::for_problem(p, &method)?;
    let mut r = vec![0.0; p.unknowns()];
    let rep = solve(p, &method, &mut r, false, &mut ws)?;
    Ok((r, rep))
}

fn nsgs(tol: f64) -> Method {
    Method::Nsgs(NsgsOptions { tol, max_iter: 100_000, ..Default::default() })
}

fn newton(tol: f64) -> Method {
    Method::Newton(NewtonOptions { tol, ..Default::default() })
}

/// z ≥ 0, w ≥ 0, z_i w_i = 0 to `tol` relative to the data's scale.
fn assert_complementary(p: &Lcp, z: &[f64], tol: f64, what: &str) {
    let mut w = vec![0.0; p.size()];
    p.w(z, &mut w).unwrap();
    let scale = 1.0 + p.q.iter().fold(0.0f64, |a, v| a.max(v.abs())) + z.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for i in 0..p.size() {
        assert!(z[i] >= -tol * scale, "{what}: z[{i}] = {}", z[i]);
        assert!(w[i] >= -tol * scale, "{what}: w[{i}] = {}", w[i]);
        assert!((z[i] * w[i]).abs() <= tol * scale * scale, "{what}: z[{i}] w[{i}] = {}", z[i] * w[i]);
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn states(p: &FrictionContact, r: &[f64]) -> Vec<ContactState> {
    (0..p.contacts()).map(|i| p.contact_state(i, r, 1e-9).unwrap()).collect()
}

// ---------- cone ----------

#[test]
fn cone_projection_hand_values_and_moreau_decomposition() {
    let mut p = [0.0; 3];
    // μ = 1, x = (0, 1): nearest boundary point (1/2, 1/2)
    project_onto_cone(1.0, &[0.0, 1.0], &mut p[..2]);
    assert!((p[0] - 0.5).abs() < 1e-15 && (p[1] - 0.5).abs() < 1e-15);
    // negative tangential side maps to the negative boundary ray
    project_onto_cone(1.0, &[0.0, -1.0], &mut p[..2]);
    assert!((p[0] - 0.5).abs() < 1e-15 && (p[1] + 0.5).abs() < 1e-15);
    // inside stays, polar cone goes to 0
    project_onto_cone(0.5, &[2.0, 0.3, -0.4], &mut p);
    assert_eq!(p, [2.0, 0.3, -0.4]);
    project_onto_cone(0.5, &[-3.0, 0.3, -0.4], &mut p);
    assert_eq!(p, [0.0; 3]);
    // μ = 0: the cone is the normal half-line
    project_onto_cone(0.0, &[2.0, 5.0, 1.0], &mut p);
    assert_eq!(p, [2.0, 0.0, 0.0]);
    project_onto_cone(0.0, &[-2.0, 0.0, 0.0], &mut p);
    assert_eq!(p, [0.0; 3]);
    // Moreau: x = P_K x + P_K° x with P_K x ⊥ P_K° x, P_K° x = −P_K*(−x), K* the cone of slope 1/μ
    let mut rng = Rng::new(7);
    for _ in 0..200 {
        let mu = rng.uniform(0.05, 2.0);
        let x = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
        let mut pk = [0.0; 3];
        project_onto_cone(mu, &x, &mut pk);
        let rest = [x[0] - pk[0], x[1] - pk[1], x[2] - pk[2]];
        // rest is in the polar cone: μ|rest_T| ≤ −rest_N
        assert!(mu * rest[1].hypot(rest[2]) <= -rest[0] + 1e-14, "mu {mu} x {x:?}");
        assert!(pk[1].hypot(pk[2]) <= mu * pk[0] + 1e-14);
        assert!((pk[0] * rest[0] + pk[1] * rest[1] + pk[2] * rest[2]).abs() < 1e-14);
    }
}

// ---------- LCP ----------

#[test]
fn lcp_bank_through_lemke() {
    for c in cases() {
        let p = Lcp::new(c.m.clone(), c.q.clone()).unwrap();
        let res = run_lcp(&p, Method::lemke());
        match &c.known {
            Known::None => {
                let err = res.expect_err(c.name);
                let Error::Solver(msg) = &err else { panic!("{}: wrong error kind {err:?}", c.name) };
                assert!(msg.contains("no solution") && msg.contains("ray termination after"), "{}: {msg}", c.name);
            }
            known => {
                let (z, rep) = res.unwrap_or_else(|e| panic!("{}: {e}", c.name));
                assert!(rep.converged, "{}", c.name);
                assert!(rep.residual < 1e-14, "{}: residual {}", c.name, rep.residual);
                assert_complementary(&p, &z, 1e-14, c.name);
                if let Known::Unique(zs) = known {
                    assert!(max_diff(&z, zs) < 1e-14, "{}: z = {z:?}, expected {zs:?}", c.name);
                }
            }
        }
    }
}

#[test]
fn lcp_bank_through_projected_gauss_seidel() {
    let method = Method::Nsgs(NsgsOptions { tol: 1e-13, ..Default::default() });
    let mut ran = 0;
    for c in cases().into_iter().filter(|c| c.pgs) {
        let p = Lcp::new(c.m.clone(), c.q.clone()).unwrap();
        let (z, rep) = run_lcp(&p, method).unwrap();
        assert!(rep.converged && rep.residual <= 1e-13, "{}: {rep:?}", c.name);
        assert_complementary(&p, &z, 1e-12, c.name);
        if let Known::Unique(zs) = &c.known {
            assert!(max_diff(&z, zs) < 1e-12, "{}: z = {z:?}", c.name);
        }
        ran += 1;
    }
    assert!(ran >= 8);
}

#[test]
fn lemke_solves_random_p_matrix_lcps() {
    let mut rng = Rng::new(11);
    for (t, &n) in [5usize, 8, 13, 20, 35, 50].iter().enumerate() {
        for rep_i in 0..3 {
            // M = S + K + 0.1 I with S = A Aᵀ/n ⪰ 0 and K skew: positive definite, hence a P-matrix
            let a: Vec<f64> = (0..n * n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let k: Vec<f64> = (0..n * n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let mut m = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    let s: f64 = (0..n).map(|l| a[i * n + l] * a[j * n + l]).sum::<f64>() / n as f64;
                    m[i * n + j] = s + 0.5 * (k[i * n + j] - k[j * n + i]) + if i == j { 0.1 } else { 0.0 };
                }
            }
            let q: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let p = Lcp::new(m, q).unwrap();
            let (z, rep) = run_lcp(&p, Method::lemke()).unwrap();
            let what = format!("n = {n}, case {t}.{rep_i}");
            assert!(rep.converged && rep.residual < 1e-10, "{what}: {rep:?}");
            assert!(rep.iterations >= 1, "{what}: q has negative entries, so at least one pivot");
            assert!(z.iter().any(|&v| v > 0.0), "{what}: a nontrivial solution");
            assert_complementary(&p, &z, 1e-10, &what);
        }
    }
}

#[test]
fn lemke_pivot_cap_is_reported_not_raised() {
    let p = Lcp::new(vec![2.0, 1.0, 0.0, 1.0, 2.0, 1.0, 0.0, 1.0, 2.0], vec![-1.0, -2.0, -1.0]).unwrap();
    let full = run_lcp(&p, Method::lemke()).unwrap().1;
    assert!(full.converged && full.iterations >= 2);
    let capped = Method::Lemke(LemkeOptions { max_pivots: Some(1), ..Default::default() });
    let (_, rep) = run_lcp(&p, capped).unwrap();
    assert!(!rep.converged);
    assert_eq!(rep.iterations, 1);
    assert!(rep.residual > 1e-3);
}

#[test]
fn lcp_residual_vanishes_only_at_the_solution() {
    let p = Lcp::new(vec![2.0, 1.0, 1.0, 2.0], vec![-1.0, 2.0]).unwrap();
    assert!(p.residual(&[0.5, 0.0]).unwrap() < 1e-16);
    // w1 = 0 but z2 negative; z1 too large (w1 > 0 with z1 > 0); sign-flipped z1
    for z in [[0.5, -0.1], [0.6, 0.0], [-0.5, 0.0]] {
        assert!(p.residual(&z).unwrap() > 0.01, "{z:?}");
    }
    // hand value at z = (0.6, 0): w = (0.2, 2.6), min(M11 z1, w1) = 0.2, min(0, 2.6) = 0
    let expect = 0.2 / (1.0 + 5f64.sqrt());
    assert!((p.residual(&[0.6, 0.0]).unwrap() - expect).abs() < 1e-15);
}

// ---------- single contacts with closed-form answers ----------

fn planar(w: [f64; 4], q: [f64; 2], mu: f64) -> FrictionContact {
    FrictionContact::new(2, Delassus::Dense(w.to_vec()), q.to_vec(), vec![mu]).unwrap()
}

fn all_methods() -> [Method; 3] {
    [Method::lemke(), nsgs(1e-12), newton(1e-12)]
}

#[test]
fn block_pushed_below_the_friction_limit_sticks() {
    // block of 2 kg: W = diag(1/2, 1/2); q_N = -1 presses, r_N = 2; limit μ r_N = 0.8
    let p = planar([0.5, 0.0, 0.0, 0.5], [-1.0, 0.3], 0.4);
    for method in all_methods() {
        let (r, rep) = run_fc(&p, method).unwrap();
        assert!(rep.converged && rep.residual <= 1e-12, "{method:?}: {rep:?}");
        // r_T = −q_T/W_TT = −0.6, opposite to the push
        assert!((r[0] - 2.0).abs() < 1e-12 && (r[1] + 0.6).abs() < 1e-12, "{method:?}: {r:?}");
        assert_eq!(p.contact_state(0, &r, 1e-9).unwrap(), ContactState::Stick);
        assert!((p.friction_reserve(0, &r).unwrap() - 0.2).abs() < 1e-12);
    }
}

#[test]
fn block_pushed_above_the_friction_limit_slips() {
    for (qt, rt) in [(0.6, -0.8), (-0.6, 0.8)] {
        let p = planar([0.5, 0.0, 0.0, 0.5], [-1.0, qt], 0.4);
        for method in all_methods() {
            let (r, rep) = run_fc(&p, method).unwrap();
            assert!(rep.converged && rep.residual <= 1e-12, "{method:?}: {rep:?}");
            // |r_T| = μ r_N = 0.8 against the push; u_T = q_T + r_T/2 keeps the push's sign
            assert!((r[0] - 2.0).abs() < 1e-12 && (r[1] - rt).abs() < 1e-12, "{method:?} q_T {qt}: {r:?}");
            let mut u = [0.0; 2];
            p.velocity(&r, &mut u).unwrap();
            assert!(u[0].abs() < 1e-12 && (u[1] - (qt + 0.5 * rt)).abs() < 1e-12);
            assert_eq!(p.contact_state(0, &r, 1e-9).unwrap(), ContactState::Slip);
            assert!(p.friction_reserve(0, &r).unwrap().abs() < 1e-12);
        }
    }
}

#[test]
fn separating_contact_stays_open() {
    let p = planar([0.5, 0.1, 0.1, 0.5], [0.5, 3.0], 0.4);
    for method in all_methods() {
        let (r, rep) = run_fc(&p, method).unwrap();
        assert!(rep.converged, "{method:?}");
        assert_eq!(r, vec![0.0, 0.0], "{method:?}");
        assert_eq!(p.contact_state(0, &r, 1e-9).unwrap(), ContactState::Open);
    }
}

#[test]
fn coupled_planar_contact_slips_with_the_coupled_normal_impulse() {
    // W_NT = 0.3 couples: slipping with u_T > 0, r_T = −μ r_N and u_N = 0 give
    // r_N = −q_N/(W_NN − μ W_NT) = 1/0.85 (a sign error would give 1/1.15)
    let p = planar([1.0, 0.3, 0.3, 2.0], [-1.0, 1.5], 0.5);
    for method in all_methods() {
        let (r, rep) = run_fc(&p, method).unwrap();
        assert!(rep.converged && rep.residual < 1e-12, "{method:?}");
        assert!((r[0] - 1.0 / 0.85).abs() < 1e-12 && (r[1] + 0.5 / 0.85).abs() < 1e-12, "{method:?}: {r:?}");
        let mut u = [0.0; 2];
        p.velocity(&r, &mut u).unwrap();
        assert!((u[1] - (0.3 / 0.85 - 2.0 * 0.5 / 0.85 + 1.5)).abs() < 1e-12 && u[1] > 0.0);
    }
    // the stick candidate −W⁻¹q, computed from the problem's own W and q, lies outside the cone
    // (|r_T| > μ r_N), so a solver must not return it: the state is slip
    let Delassus::Dense(w) = &p.w else { unreachable!() };
    let det = w[0] * w[3] - w[1] * w[2];
    let stick_n = -(w[3] * p.q[0] - w[1] * p.q[1]) / det;
    let stick_t = -(-w[2] * p.q[0] + w[0] * p.q[1]) / det;
    assert!(stick_n > 0.0 && stick_t.abs() > p.mu[0] * stick_n, "stick candidate ({stick_n}, {stick_t})");
    for method in all_methods() {
        let (r, _) = run_fc(&p, method).unwrap();
        assert_eq!(p.contact_state(0, &r, 1e-9).unwrap(), ContactState::Slip, "{method:?}");
    }
}

/// A ball (2 kg, R = 0.1 m, I = 2mR²/5) on a plane: W = diag(1/m, 1/m + R²/I, 1/m + R²/I).
fn ball(q: [f64; 3], mu: f64) -> FrictionContact {
    let (m, rr) = (2.0, 0.1);
    let i = 0.4 * m * rr * rr;
    let wt = 1.0 / m + rr * rr / i;
    let w = vec![1.0 / m, 0.0, 0.0, 0.0, wt, 0.0, 0.0, 0.0, wt];
    FrictionContact::new(3, Delassus::Dense(w), q.to_vec(), vec![mu]).unwrap()
}

#[test]
fn ball_on_plane_slips_opposite_to_its_sliding_velocity() {
    // r_N = 2, μ r_N = 0.6, sticking would need |q_T|/W_TT = 2/1.75 > 0.6
    let p = ball([-1.0, 1.2, 1.6], 0.3);
    for method in [nsgs(1e-12), newton(1e-12)] {
        let (r, rep) = run_fc(&p, method).unwrap();
        assert!(rep.converged && rep.residual < 1e-12, "{method:?}: {rep:?}");
        // r_T = −μ r_N q_T/|q_T| = −0.6 (0.6, 0.8)
        assert!(max_diff(&r, &[2.0, -0.36, -0.48]) < 1e-12, "{method:?}: {r:?}");
        let mut u = [0.0; 3];
        p.velocity(&r, &mut u).unwrap();
        // the sliding velocity keeps its direction: u_T = q_T − 1.75·0.6 (0.6, 0.8)
        assert!(max_diff(&u, &[0.0, 1.2 - 0.63, 1.6 - 0.84]) < 1e-12, "{u:?}");
        assert_eq!(p.contact_state(0, &r, 1e-9).unwrap(), ContactState::Slip);
    }
    // below the limit it rolls without slipping: r_T = −q_T/W_TT
    let p = ball([-1.0, 0.6, 0.8], 0.3);
    for method in [nsgs(1e-12), newton(1e-12)] {
        let (r, _) = run_fc(&p, method).unwrap();
        assert!(max_diff(&r, &[2.0, -0.6 / 1.75, -0.8 / 1.75]) < 1e-12, "{method:?}: {r:?}");
        assert_eq!(p.contact_state(0, &r, 1e-9).unwrap(), ContactState::Stick);
    }
}

#[test]
fn lemke_pyramid_is_exact_along_a_facet_and_converges_to_the_cone() {
    // sliding along t1: −t1 is a pyramid direction for an even number of facets
    let p = ball([-1.0, 2.0, 0.0], 0.3);
    let (r, rep) = run_fc(&p, Method::Lemke(LemkeOptions { facets: 8, ..Default::default() })).unwrap();
    assert!(rep.converged && rep.residual < 1e-14, "{rep:?}");
    assert!(max_diff(&r, &[2.0, -0.6, 0.0]) < 1e-14, "{r:?}");
    // an oblique direction: the force sits on a pyramid edge at most π/k from the exact direction,
    // so |Δr_T| ≤ 2 μ r_N sin(π/2k)
    let p = ball([-1.0, 1.2, 1.6], 0.3);
    let mut errors = Vec::new();
    for facets in [4, 8, 16, 32] {
        let (r, rep) = run_fc(&p, Method::Lemke(LemkeOptions { facets, ..Default::default() })).unwrap();
        assert!(rep.converged);
        let err = max_diff(&r, &[2.0, -0.36, -0.48]);
        assert!(err <= 1.2 * (std::f64::consts::PI / (2 * facets) as f64).sin() + 1e-12, "k = {facets}: {err}");
        errors.push(err);
    }
    assert!(errors[3] < errors[1] && errors[1] < errors[0] && errors[3] < 0.03, "{errors:?}");
}

#[test]
fn spatial_contact_with_coupled_block_slips_against_the_sliding_velocity() {
    // an anisotropic, coupled diagonal block: the slip direction is not that of q_T
    let w = [1.0, 0.2, -0.1, 0.2, 1.5, 0.4, -0.1, 0.4, 0.8];
    let mut rng = Rng::new(3);
    let mut slipped = 0;
    for _ in 0..40 {
        let q = [rng.uniform(-1.0, -0.1), rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let mu = rng.uniform(0.1, 0.8);
        let p = FrictionContact::new(3, Delassus::Dense(w.to_vec()), q.to_vec(), vec![mu]).unwrap();
        let (r1, rep1) = run_fc(&p, nsgs(1e-13)).unwrap();
        let (r2, rep2) = run_fc(&p, newton(1e-13)).unwrap();
        assert!(rep1.converged && rep2.converged, "{q:?}");
        assert!(max_diff(&r1, &r2) < 1e-10, "{q:?}: {r1:?} vs {r2:?}");
        let mut u = [0.0; 3];
        p.velocity(&r1, &mut u).unwrap();
        assert!(u[0].abs() < 1e-12, "closed contact: u_N = 0");
        if p.contact_state(0, &r1, 1e-9).unwrap() == ContactState::Slip {
            slipped += 1;
            let (rt, ut) = ([r1[1], r1[2]], [u[1], u[2]]);
            assert!((rt[0].hypot(rt[1]) - mu * r1[0]).abs() < 1e-12, "on the cone");
            // antiparallel: r_T = −μ r_N u_T/|u_T|
            let un = ut[0].hypot(ut[1]);
            assert!((rt[0] + mu * r1[0] * ut[0] / un).abs() < 1e-10 && (rt[1] + mu * r1[0] * ut[1] / un).abs() < 1e-10);
        } else {
            assert!(u[1].hypot(u[2]) < 1e-10);
        }
    }
    assert!(slipped >= 10, "the sample must exercise sliding: {slipped}");
}

#[test]
fn local_solver_covers_all_cases_exactly() {
    // 3-D local problems against the brute-force conditions, including large μ and strong coupling
    let mut rng = Rng::new(99);
    let mut counts = [0usize; 3];
    for _ in 0..2000 {
        // random SPD block
        let l = [
            rng.uniform(0.5, 1.5),
            rng.uniform(-1.0, 1.0),
            rng.uniform(0.5, 1.5),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(0.2, 1.5),
        ];
        let lm = [[l[0], 0.0, 0.0], [l[1], l[2], 0.0], [l[3], l[4], l[5]]];
        let mut a = [0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                a[i * 3 + j] = (0..3).map(|k| lm[i][k] * lm[j][k]).sum();
            }
        }
        let b = [rng.uniform(-1.0, 0.3), rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let mu = rng.uniform(0.0, 1.5);
        let mut r = [0.0; 3];
        local_solve(3, &a, mu, &b, &mut r);
        let u: Vec<f64> = (0..3).map(|i| b[i] + (0..3).map(|j| a[i * 3 + j] * r[j]).sum::<f64>()).collect();
        let res = super::problem::contact_residual_sq(3, mu, a[0], &r, &u).sqrt();
        assert!(res < 1e-11, "a {a:?} b {b:?} mu {mu}: r {r:?} residual {res}");
        let p = FrictionContact::new(3, Delassus::Dense(a.to_vec()), b.to_vec(), vec![mu]).unwrap();
        counts[p.contact_state(0, &r, 1e-9).unwrap() as usize] += 1;
        // the block prepared once solves it too, bit for bit
        assert_prepared_block_agrees(&a, mu, &b, &r);
    }
    assert!(counts.iter().all(|&c| c > 100), "open/stick/slip counts {counts:?}");
}

/// `LocalBlock3` (Cramer's cofactors and isotropy kept per solve) against `local_solve` on one
/// problem: a solution of its own (residual), and the same one bit for bit.
fn assert_prepared_block_agrees(a: &[f64; 9], mu: f64, b: &[f64; 3], r: &[f64; 3]) {
    let mut r2 = [0.0; 3]; // (the same first guess as the local_solve call)
    super::nsgs::LocalBlock3::new(a).solve(mu, b, &mut r2);
    let u: Vec<f64> = (0..3).map(|i| b[i] + (0..3).map(|j| a[i * 3 + j] * r2[j]).sum::<f64>()).collect();
    let res = super::problem::contact_residual_sq(3, mu, a[0], &r2, &u).sqrt();
    assert!(res < 1e-11, "prepared block, a {a:?} b {b:?} mu {mu}: r {r2:?} residual {res}");
    assert_eq!(r2.map(f64::to_bits), r.map(f64::to_bits), "prepared block {r2:?} against {r:?}");
}

#[test]
fn prepared_isotropic_blocks_slip_explicitly_as_the_local_solve_does() {
    // sphere-like blocks (W_NT = 0, W_TT = c I): open, stick and the explicit slip, with the
    // slip impulse opposing the sliding velocity (closed form r_T = −μ r_N b_T/|b_T|)
    let mut rng = Rng::new(7);
    let mut counts = [0usize; 3];
    for _ in 0..1000 {
        let (ann, c) = (rng.uniform(0.5, 2.0), rng.uniform(0.5, 4.0));
        let a = [ann, 0.0, 0.0, 0.0, c, 0.0, 0.0, 0.0, c];
        let b = [rng.uniform(-1.0, 0.3), rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let mu = rng.uniform(0.2, 2.0);
        let mut r = [0.0; 3];
        local_solve(3, &a, mu, &b, &mut r);
        assert_prepared_block_agrees(&a, mu, &b, &r);
        let p = FrictionContact::new(3, Delassus::Dense(a.to_vec()), b.to_vec(), vec![mu]).unwrap();
        let state = p.contact_state(0, &r, 1e-9).unwrap();
        if state == ContactState::Slip {
            let (rn, bt) = (-b[0] / ann, b[1].hypot(b[2]));
            assert!((r[0] - rn).abs() < 1e-14 * (1.0 + rn));
            assert!((r[1] + mu * rn * b[1] / bt).abs() < 1e-14 && (r[2] + mu * rn * b[2] / bt).abs() < 1e-14);
        }
        counts[state as usize] += 1;
    }
    assert!(counts.iter().all(|&c| c > 100), "open/stick/slip counts {counts:?}");
}

#[test]
fn nearly_isotropic_blocks_take_the_closed_form_within_its_tolerance_and_others_the_exact_solve() {
    // a sphere-like block perturbed by `eps` of its trace off the diagonal and between the two
    // tangential entries: at 1e-13 (the assembly's round-off) the closed form solves it, and its
    // solution has a residual of that order in the perturbed problem; at 1e-8 it is not isotropic,
    // and the exact solve meets the conditions to round-off. Frictionless and open contacts
    // included (μ = 0 gives r_T = 0, b_N ≥ 0 gives r = 0 in either path).
    let mut rng = Rng::new(23);
    let mut slips = 0;
    for k in 0..600 {
        let (ann, c) = (rng.uniform(0.5, 2.0), rng.uniform(0.5, 4.0));
        let eps = if k % 2 == 0 { 1e-13 } else { 1e-8 };
        let e = eps * (ann + 2.0 * c);
        let (x, y) = (rng.uniform(-1.0, 1.0) * e, rng.uniform(-1.0, 1.0) * e);
        let a = [ann, x, y, x, c + e, 0.5 * e, y, 0.5 * e, c];
        let b = [rng.uniform(-1.0, 0.3), rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let mu = if k % 7 == 0 { 0.0 } else { rng.uniform(0.2, 2.0) };
        let mut r = [0.0; 3];
        local_solve(3, &a, mu, &b, &mut r);
        // (a residual below 1e-11 for both: at 1e-8 the closed form would leave about 1e-8)
        assert_prepared_block_agrees(&a, mu, &b, &r);
        if b[0] >= 0.0 {
            assert_eq!(r, [0.0; 3], "open: {a:?} {b:?}");
        } else if mu == 0.0 {
            assert!(r[1].abs() <= 1e-8 * r[0] && r[2].abs() <= 1e-8 * r[0], "frictionless: {r:?}");
        }
        let p = FrictionContact::new(3, Delassus::Dense(a.to_vec()), b.to_vec(), vec![mu]).unwrap();
        if p.contact_state(0, &r, 1e-9).unwrap() == ContactState::Slip {
            slips += 1;
        }
    }
    assert!(slips > 100, "slipping contacts {slips}");
}

// ---------- coupled problems: the solvers agree ----------

#[test]
fn disk_stack_three_solvers_agree() {
    let p = disk_stack(6, 0.3, 0.6, 5).unwrap();
    let (r_lemke, rep) = run_fc(&p, Method::lemke()).unwrap();
    assert!(rep.converged && rep.residual < 1e-13, "Lemke {rep:?}");
    let (r_nsgs, rep) = run_fc(&p, nsgs(1e-13)).unwrap();
    assert!(rep.converged && rep.residual <= 1e-13, "NSGS {rep:?}");
    let (r_newton, rep) = run_fc(&p, newton(1e-13)).unwrap();
    assert!(rep.converged && rep.residual <= 1e-13, "Newton {rep:?}");
    let scale = max_abs(&r_lemke);
    assert!(scale > 0.05);
    assert!(max_diff(&r_lemke, &r_nsgs) < 1e-8 * scale, "{r_lemke:?}\n{r_nsgs:?}");
    assert!(max_diff(&r_lemke, &r_newton) < 1e-8 * scale, "{r_lemke:?}\n{r_newton:?}");
    // the case is not trivial: some contacts stick and some slip
    let s = states(&p, &r_lemke);
    assert!(s.contains(&ContactState::Stick) && s.contains(&ContactState::Slip), "{s:?}");
}

#[test]
fn random_planar_problems_three_solvers_agree() {
    let mut seen = [false; 3];
    for seed in 1..=12 {
        let p = random_friction_contact(2, 8, 0.2, seed).unwrap();
        let (r_lemke, rep) = run_fc(&p, Method::lemke()).unwrap();
        assert!(rep.converged && rep.residual < 1e-12, "seed {seed}: Lemke {rep:?}");
        let (r_nsgs, rep) = run_fc(&p, nsgs(1e-13)).unwrap();
        assert!(rep.converged && rep.residual <= 1e-13, "seed {seed}: NSGS {rep:?}");
        let (r_newton, rep) = run_fc(&p, newton(1e-13)).unwrap();
        assert!(rep.converged && rep.residual <= 1e-13, "seed {seed}: Newton {rep:?}");
        let scale = 1.0 + max_abs(&r_lemke);
        assert!(max_diff(&r_lemke, &r_nsgs) < 1e-8 * scale, "seed {seed}");
        assert!(max_diff(&r_lemke, &r_newton) < 1e-8 * scale, "seed {seed}");
        for s in states(&p, &r_lemke) {
            seen[s as usize] = true;
        }
    }
    assert_eq!(seen, [true; 3], "open, stick and slip all occur");
}

#[test]
fn random_spatial_problems_nsgs_and_newton_agree() {
    let mut seen = [false; 3];
    for seed in 1..=8 {
        let p = random_friction_contact(3, 10, 0.3, 100 + seed).unwrap();
        let (r_nsgs, rep) = run_fc(&p, nsgs(1e-13)).unwrap();
        assert!(rep.converged && rep.residual <= 1e-13, "seed {seed}: NSGS {rep:?}");
        let (r_newton, rep) = run_fc(&p, newton(1e-13)).unwrap();
        assert!(rep.converged && rep.residual <= 1e-13, "seed {seed}: Newton {rep:?}");
        assert!(max_diff(&r_nsgs, &r_newton) < 1e-8 * (1.0 + max_abs(&r_nsgs)), "seed {seed}");
        for s in states(&p, &r_nsgs) {
            seen[s as usize] = true;
        }
        // the pyramid (32 facets) is close to the cone: its inscribed facets cut the friction
        // bound by at most 1 − cos(π/32) ≈ 4.8e-3 relative; over these seeds the impulses differ
        // by at most 1.7e-3 of the scale, so 4e-3 catches a pyramid a few times coarser
        let (r_lemke, rep) = run_fc(&p, Method::Lemke(LemkeOptions { facets: 32, ..Default::default() })).unwrap();
        assert!(rep.converged);
        let diff = max_diff(&r_lemke, &r_nsgs) / (1.0 + max_abs(&r_nsgs));
        assert!(diff < 4e-3, "seed {seed}: pyramid against cone {diff:e}");
    }
    assert_eq!(seen, [true; 3], "open, stick and slip all occur");
}

#[test]
fn warm_start_reduces_nsgs_sweeps() {
    let p = random_friction_contact(3, 20, 0.3, 42).unwrap();
    let method = nsgs(1e-10);
    let mut ws = Workspace::for_problem(&p, &method).unwrap();
    let mut r = vec![0.0; p.unknowns()];
    let cold = solve(&p, &method, &mut r, false, &mut ws).unwrap();
    assert!(cold.converged && cold.iterations > 5, "{cold:?}");
    // the next step's problem differs a little
    let mut p2 = p.clone();
    for (k, v) in p2.q.iter_mut().enumerate() {
        *v *= 1.0 + 0.01 * ((k % 5) as f64 - 2.0) / 2.0;
    }
    let mut r_cold = vec![0.0; p.unknowns()];
    let cold2 = solve(&p2, &method, &mut r_cold, false, &mut ws).unwrap();
    let warm = solve(&p2, &method, &mut r, true, &mut ws).unwrap();
    assert!(cold2.converged && warm.converged);
    assert!(warm.iterations < cold2.iterations, "warm {} vs cold {}", warm.iterations, cold2.iterations);
    assert!(max_diff(&r, &r_cold) < 1e-7 * (1.0 + max_abs(&r)));
    // starting from the solution itself: one sweep confirms it
    let again = solve(&p2, &method, &mut r, true, &mut ws).unwrap();
    assert_eq!(again.iterations, 1);
}

#[test]
fn sphere_pile_is_well_posed_and_block_storage_matches_dense() {
    let p = sphere_pile(60, 0.4, 1).unwrap();
    assert_eq!(p.contacts(), 60);
    let Delassus::Blocks(bw) = &p.w else { panic!("block storage expected") };
    assert!(bw.off_diagonal_blocks() > 60, "contacts are coupled");
    let dense = dense_copy(&p);
    let Delassus::Dense(w) = &dense.w else { unreachable!() };
    let m = 3 * p.contacts();
    // symmetric and positive definite (full rank)
    for a in 0..m {
        for b in 0..m {
            assert!((w[a * m + b] - w[b * m + a]).abs() < 1e-12);
        }
    }
    let mut f = w.clone();
    let mut perm = vec![0; m];
    assert_eq!(crate::math::linalg::cholesky_semidefinite(&mut f, m, &mut perm, 1e-10), m);
    // the same answers from both storages and both iterative methods
    let (r_blk, rep) = run_fc(&p, nsgs(1e-12)).unwrap();
    assert!(rep.converged, "{rep:?}");
    let (r_den, _) = run_fc(&dense, nsgs(1e-12)).unwrap();
    assert!(max_diff(&r_blk, &r_den) < 1e-12 * (1.0 + max_abs(&r_blk)));
    let (r_newton, rep) = run_fc(&p, newton(1e-12)).unwrap();
    assert!(rep.converged, "{rep:?}");
    assert!(max_diff(&r_blk, &r_newton) < 1e-8 * (1.0 + max_abs(&r_blk)));
    // velocities agree too
    let (mut u1, mut u2) = (vec![0.0; m], vec![0.0; m]);
    p.velocity(&r_blk, &mut u1).unwrap();
    dense.velocity(&r_blk, &mut u2).unwrap();
    assert!(max_diff(&u1, &u2) < 1e-13);
    let s = states(&p, &r_blk);
    assert!(
        s.contains(&ContactState::Stick) && s.contains(&ContactState::Slip) && s.contains(&ContactState::Open),
        "{s:?}"
    );
}

#[test]
fn block_builder_sums_duplicates_and_mirrors() {
    let mut b = BlockDelassusBuilder::new(2, 3).unwrap();
    b.add(0, 0, &[1.0, 0.5, 0.5, 2.0]).unwrap();
    b.add(0, 0, &[1.0, 0.0, 0.0, 1.0]).unwrap();
    b.add(2, 0, &[0.1, 0.2, 0.3, 0.4]).unwrap(); // W_20; W_02 = W_20ᵀ
    b.add(0, 2, &[0.1, 0.3, 0.2, 0.4]).unwrap(); // the same coupling added from the other side
    b.add(1, 1, &[1.0, 0.0, 0.0, 1.0]).unwrap();
    b.add(2, 2, &[1.0, 0.0, 0.0, 1.0]).unwrap();
    let w = b.build();
    assert_eq!(w.off_diagonal_blocks(), 2);
    let d = w.to_dense();
    let at = |r: usize, c: usize| d[r * 6 + c];
    assert_eq!((at(0, 0), at(0, 1), at(1, 1)), (2.0, 0.5, 3.0));
    // W_02 = 2 W_20ᵀ: row 0 of W_02 is (0.2, 0.6)
    assert_eq!((at(0, 4), at(0, 5), at(1, 4), at(1, 5)), (0.2, 0.6, 0.4, 0.8));
    assert_eq!((at(4, 0), at(5, 0), at(4, 1)), (0.2, 0.6, 0.4));
    let mut bad = BlockDelassusBuilder::new(2, 3).unwrap();
    assert!(bad.add(0, 3, &[0.0; 4]).unwrap_err().to_string().contains("(0, 3)"));
    assert!(bad.add(0, 1, &[0.0; 3]).unwrap_err().to_string().contains("expected 4"));
    assert!(bad.add(1, 0, &[0.0, f64::NAN, 0.0, 0.0]).unwrap_err().to_string().contains("not finite"));
}

// ---------- API, states, errors ----------

#[test]
fn contact_states_and_reserve_from_a_mixed_solution() {
    // three uncoupled planar contacts: open, stick, slip
    let mut w = vec![0.0; 36];
    for k in 0..6 {
        w[k * 6 + k] = 1.0;
    }
    let p = FrictionContact::new(2, Delassus::Dense(w), vec![0.5, 1.0, -1.0, 0.2, -1.0, 2.0], vec![0.5; 3]).unwrap();
    let (r, rep) = run_fc(&p, nsgs(1e-14)).unwrap();
    assert!(rep.converged);
    assert_eq!(states(&p, &r), vec![ContactState::Open, ContactState::Stick, ContactState::Slip]);
    assert!((p.friction_reserve(1, &r).unwrap() - 0.3).abs() < 1e-14);
    assert!(p.friction_reserve(2, &r).unwrap().abs() < 1e-14);
    assert_eq!(ContactState::Slip.as_str(), "slip");
    // the residual flags a friction force pointing the wrong way
    let mut wrong = r.clone();
    wrong[5] = -wrong[5];
    assert!(p.residual(&wrong).unwrap() > 0.1);
    assert!(p.contact_state(3, &r, 1e-9).unwrap_err().to_string().contains("contact 3"));
}

#[test]
fn bad_input_is_an_error_naming_the_item() {
    let good = planar([0.5, 0.0, 0.0, 0.5], [-1.0, 0.3], 0.4);
    let msg = |e: Error| e.to_string();
    assert!(msg(FrictionContact::new(4, good.w.clone(), vec![0.0; 4], vec![0.1]).unwrap_err()).contains("dimension"));
    assert!(msg(FrictionContact::new(2, good.w.clone(), vec![0.0; 3], vec![0.1]).unwrap_err()).contains("q has 3"));
    assert!(
        msg(FrictionContact::new(2, good.w.clone(), vec![-1.0, 0.3], vec![-0.1]).unwrap_err()).contains("contact 0: μ")
    );
    assert!(msg(FrictionContact::new(2, good.w.clone(), vec![f64::NAN, 0.3], vec![0.1]).unwrap_err()).contains("q[0]"));
    let zero_n = Delassus::Dense(vec![0.0, 0.0, 0.0, 1.0]);
    assert!(msg(FrictionContact::new(2, zero_n, vec![-1.0, 0.3], vec![0.1]).unwrap_err()).contains("contact 0: W_NN"));
    assert!(msg(Lcp::new(vec![1.0; 3], vec![1.0, 2.0]).unwrap_err()).contains("M has 3 entries"));
    assert!(msg(Lcp::new(vec![1.0, f64::INFINITY, 0.0, 1.0], vec![1.0, 2.0]).unwrap_err()).contains("M[0, 1]"));
    // problems edited in place are checked at solve time
    let mut edited = good.clone();
    edited.mu[0] = f64::NAN;
    let mut ws = Workspace::for_problem(&good, &Method::nsgs()).unwrap();
    let mut r = vec![0.0; 2];
    assert!(msg(solve(&edited, &Method::nsgs(), &mut r, false, &mut ws).unwrap_err()).contains("μ"));
    // wrong solution length, non-finite warm start, bad options
    assert!(msg(solve(&good, &Method::nsgs(), &mut [0.0; 3], false, &mut ws).unwrap_err()).contains("3 entries"));
    assert!(msg(solve(&good, &Method::nsgs(), &mut [f64::NAN, 0.0], true, &mut ws).unwrap_err())
        .contains("warm start entry 0"));
    let bad = Method::Nsgs(NsgsOptions { relaxation: 2.0, ..Default::default() });
    assert!(msg(solve(&good, &bad, &mut r, false, &mut ws).unwrap_err()).contains("relaxation"));
    let bad = Method::Lemke(LemkeOptions { facets: 2, ..Default::default() });
    assert!(msg(solve(&good, &bad, &mut r, false, &mut ws).unwrap_err()).contains("facets"));
    // Newton on an LCP, PGS with a zero diagonal
    let lcp = Lcp::new(vec![0.0, 1.0, 1.0, 1.0], vec![-1.0, -1.0]).unwrap();
    assert!(msg(Workspace::for_problem(&lcp, &Method::newton()).unwrap_err()).contains("Newton"));
    assert!(msg(run_lcp(&lcp, Method::nsgs()).unwrap_err()).contains("M[0, 0] = 0"));
}

#[test]
fn workspace_must_fit_and_reserving_again_is_free() {
    let small = random_friction_contact(2, 3, 0.2, 1).unwrap();
    let big = random_friction_contact(2, 6, 0.2, 2).unwrap();
    let method = newton(1e-10);
    let mut ws = Workspace::for_problem(&small, &method).unwrap();
    let mut r = vec![0.0; big.unknowns()];
    let err = solve(&big, &method, &mut r, false, &mut ws).unwrap_err();
    assert!(err.to_string().contains("workspace is too small"));
    // sized for the big one, the small one fits without touching the buffers
    ws.reserve(&big, &method).unwrap();
    let ptr = ws.u.as_ptr();
    ws.reserve(&small, &method).unwrap();
    assert_eq!(ptr, ws.u.as_ptr());
    assert!(solve(&big, &method, &mut r, false, &mut ws).unwrap().converged);
    let mut r = vec![0.0; small.unknowns()];
    assert!(solve(&small, &method, &mut r, false, &mut ws).unwrap().converged);
    // a Lemke solve needs its own buffers
    assert!(solve(&small, &Method::lemke(), &mut r, false, &mut ws).is_err());
}

#[test]
fn method_options_round_trip_through_json() {
    let m = Method::Nsgs(NsgsOptions { tol: 1e-8, max_iter: 50, relaxation: 0.9, anderson: 0, stall: 0 });
    let s = serde_json::to_string(&m).unwrap();
    assert_eq!(serde_json::from_str::<Method>(&s).unwrap(), m);
    let m: Method = serde_json::from_str(r#"{"type": "lemke", "facets": 16}"#).unwrap();
    assert_eq!(m, Method::Lemke(LemkeOptions { facets: 16, ..Default::default() }));
}

// ---------- derivatives and formulas ----------

#[test]
fn friction_residual_hand_value() {
    // W = I, q = (−1, 0), μ = 0.5, r = (0.5, 0): u = û = (−0.5, 0), ρ = 1,
    // r − ρû = (1, 0) is in the cone, so Φ = (−0.5, 0) and the merit is 0.5/(1 + |q|) = 0.25
    let p = planar([1.0, 0.0, 0.0, 1.0], [-1.0, 0.0], 0.5);
    assert!((p.residual(&[0.5, 0.0]).unwrap() - 0.25).abs() < 1e-15);
    assert!(p.residual(&[1.0, 0.0]).unwrap() < 1e-16);
    // ρ = 1/W_NN makes it a velocity: scaling W and q by 4 scales the violation alike
    let p4 = planar([4.0, 0.0, 0.0, 4.0], [-4.0, 0.0], 0.5);
    assert!((p4.residual(&[0.5, 0.0]).unwrap() - 2.0 / 5.0).abs() < 1e-15);
}

#[test]
fn slip_equation_derivative_matches_finite_differences() {
    let mut rng = Rng::new(5);
    for _ in 0..200 {
        let a: [f64; 9] = std::array::from_fn(|_| rng.uniform(-1.0, 1.0));
        let b = [rng.uniform(-1.0, 0.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
        let (mu, th) = (rng.uniform(0.1, 1.0), rng.uniform(0.0, 6.3));
        let h = 1e-6;
        let (f, fd) = nsgs::slip_function(&a, mu, &b, th);
        let num = (nsgs::slip_function(&a, mu, &b, th + h).0 - nsgs::slip_function(&a, mu, &b, th - h).0) / (2.0 * h);
        assert!((fd - num).abs() < 1e-8 * (1.0 + fd.abs()), "{fd} vs {num}");
        // F = den · (t^⊥ · u_T) at r = (r_N, −μ r_N t), r_N = −b_N/den
        let t = [th.cos(), th.sin()];
        let den = a[0] - mu * (a[1] * t[0] + a[2] * t[1]);
        let rn = -b[0] / den;
        let r = [rn, -mu * rn * t[0], -mu * rn * t[1]];
        let u: Vec<f64> = (0..3).map(|i| b[i] + (0..3).map(|j| a[i * 3 + j] * r[j]).sum::<f64>()).collect();
        assert!(u[0].abs() < 1e-12 * (1.0 + rn.abs()), "u_N = 0 by construction");
        assert!((f - den * (-t[1] * u[1] + t[0] * u[2])).abs() < 1e-10 * (1.0 + f.abs()));
    }
}

#[test]
fn alart_curnier_jacobian_matches_finite_differences() {
    for (dim, seed) in [(2, 1), (3, 2), (3, 3)] {
        let p = random_friction_contact(dim, 4, 0.4, seed).unwrap();
        let n = p.contacts();
        let m = dim * n;
        let mut diag = vec![[0.0; 9]; n];
        nsgs::cache_diagonal(&p, &mut diag);
        let mut rng = Rng::new(seed + 10);
        let mut kinds = [0usize; 2];
        for _ in 0..20 {
            let r: Vec<f64> =
                (0..m).map(|k| if k % dim == 0 { rng.uniform(-0.2, 1.0) } else { rng.uniform(-0.5, 0.5) }).collect();
            let phi_at = |r: &[f64], dblk: Option<&mut [[f64; 9]]>| {
                let mut u = vec![0.0; m];
                p.velocity(r, &mut u).unwrap();
                let mut phi = vec![0.0; m];
                newton::evaluate(&p, &diag, r, &u, &mut phi, dblk);
                phi
            };
            let mut dblk = vec![[0.0; 9]; n];
            phi_at(&r, Some(&mut dblk));
            // count contacts by projection case so that the test covers the slip branch
            for blk in &dblk {
                kinds[usize::from(blk[0] == 1.0 && blk[dim + 1] != 1.0)] += 1;
            }
            let mut jac = vec![0.0; m * m];
            newton::assemble(&p, &diag, &dblk, 0.0, &mut jac);
            let h = 1e-7;
            for c in 0..m {
                let (mut rp, mut rm) = (r.clone(), r.clone());
                rp[c] += h;
                rm[c] -= h;
                let (fp, fm) = (phi_at(&rp, None), phi_at(&rm, None));
                for a in 0..m {
                    let num = (fp[a] - fm[a]) / (2.0 * h);
                    // a kink within h would spoil the difference; random points avoid them
                    assert!((jac[a * m + c] - num).abs() < 1e-5, "d = {dim}: J[{a},{c}] = {} vs {num}", jac[a * m + c]);
                }
            }
        }
        assert!(kinds[1] > 0 && kinds[0] > 0, "d = {dim}: both closed-slip and other cases, {kinds:?}");
    }
}

#[test]
fn fixtures_have_the_free_velocities_of_their_mechanisms() {
    // without the push the stack falls as one: only the ground contact closes (−g dt), and the
    // bottom disk's spin of 2 rad/s slides its contact point at R ω = 0.2 m/s
    let p = disk_stack(4, 0.3, 0.0, 9).unwrap();
    assert!((p.q[0] + 9.81 * 0.01).abs() < 1e-15);
    assert!((p.q[1] - 0.1 * 2.0).abs() < 1e-15);
    for k in 1..4 {
        assert!(p.q[2 * k].abs() < 1e-15, "contact {k}: u_N = {}", p.q[2 * k]);
    }
    // the spinning disk's top point moves backwards under disk 1: u_T = +R ω at contact 1 too
    assert!((p.q[3] - 0.1 * 2.0).abs() < 1e-15);
    // W_NN of the ground contact is 1/m_0 with m_0 in [1, 2]
    let Delassus::Dense(w) = &p.w else { unreachable!() };
    assert!(w[0] > 0.5 && w[0] < 1.0);
}

// ---------- redundant contacts (singular W) ----------

/// `W = J M⁻¹ Jᵀ`, `q = J v` for one rigid body with diagonal `M⁻¹` and contact rows `jac`.
fn one_body(dim: usize, jac: &[Vec<f64>], minv: &[f64], v: &[f64], mu: f64) -> FrictionContact {
    let m = jac.len();
    let w: Vec<f64> =
        (0..m * m).map(|k| (0..minv.len()).map(|c| jac[k / m][c] * minv[c] * jac[k % m][c]).sum()).collect();
    let q = jac.iter().map(|row| row.iter().zip(v).map(|(a, b)| a * b).sum()).collect();
    FrictionContact::new(dim, Delassus::Dense(w), q, vec![mu; m / dim]).unwrap()
}

#[test]
fn planar_box_on_two_corners_obeys_momentum_and_moment_balance() {
    // box 2 kg, half sizes a = 0.5, b = 0.25, landing flat with v_y = −g dt and sliding at v_x;
    // corners (∓a, −b), normal y, tangent x: rows [0, 1, c_x] and [1, 0, b]; W is 4×4 of rank 3
    let (mass, a, b, mu, gdt) = (2.0, 0.5, 0.25, 0.5, 0.0981);
    let inertia = mass * (a * a + b * b) / 3.0;
    let jac = vec![vec![0.0, 1.0, -a], vec![1.0, 0.0, b], vec![0.0, 1.0, a], vec![1.0, 0.0, b]];
    let minv = [1.0 / mass, 1.0 / mass, 1.0 / inertia];
    for vx in [0.03, 0.2] {
        let p = one_body(2, &jac, &minv, &[vx, -gdt, 0.0], mu);
        for method in all_methods() {
            let (r, rep) = run_fc(&p, method).unwrap();
            assert!(rep.converged && rep.residual < 1e-10, "v_x {vx} {method:?}: {rep:?}");
            let (sum_n, sum_t) = (r[0] + r[2], r[1] + r[3]);
            // normal momentum: the box stops falling
            assert!((sum_n - mass * gdt).abs() < 1e-9, "{method:?}: Σr_N = {sum_n}");
            // tangential: sticks (Σr_T = −m v_x) below μ m g dt = 0.0981, else slides at the limit
            let expect_t = if mass * vx < mu * mass * gdt { -mass * vx } else { -mu * mass * gdt };
            assert!((sum_t - expect_t).abs() < 1e-9, "v_x {vx} {method:?}: Σr_T = {sum_t}");
            // no rotation: a (r_N2 − r_N1) + b Σr_T = 0, the front corner carries more
            assert!((a * (r[2] - r[0]) + b * sum_t).abs() < 1e-9, "{method:?}: {r:?}");
            assert!(r[2] > r[0]);
        }
    }
}

#[test]
fn spatial_box_on_four_corners_obeys_momentum_and_moment_balance() {
    // box 3 kg, half sizes (a, c, b) = (0.4, 0.3, 0.2), diagonal inertia; corners (±a, ±c, −b);
    // rows for n = z, t1 = x, t2 = y: e·v + (p × e)·ω; W is 12×12 of rank 6
    let (mass, a, c, b, mu, gdt) = (3.0, 0.4, 0.3, 0.2, 0.4, 0.0981);
    let inertia = [mass * (c * c + b * b) / 3.0, mass * (a * a + b * b) / 3.0, mass * (a * a + c * c) / 3.0];
    let mut jac = Vec::new();
    for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        let pnt = [sx * a, sy * c, -b];
        for e in [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            let pxe = [pnt[1] * e[2] - pnt[2] * e[1], pnt[2] * e[0] - pnt[0] * e[2], pnt[0] * e[1] - pnt[1] * e[0]];
            jac.push(vec![e[0], e[1], e[2], pxe[0], pxe[1], pxe[2]]);
        }
    }
    let minv = [1.0 / mass, 1.0 / mass, 1.0 / mass, 1.0 / inertia[0], 1.0 / inertia[1], 1.0 / inertia[2]];
    for (vx, vy) in [(0.02, 0.01), (0.3, 0.1)] {
        let p = one_body(3, &jac, &minv, &[vx, vy, -gdt, 0.0, 0.0, 0.0], mu);
        for method in [nsgs(1e-11), newton(1e-11)] {
            let (r, rep) = run_fc(&p, method).unwrap();
            assert!(rep.converged, "{method:?}: {rep:?}");
            // total impulse and its moment: Jᵀ r = M Δv with Δv = (−v_x…, +g dt, 0, 0, 0) or the slip share
            let mut f = [0.0; 6];
            for (k, row) in jac.iter().enumerate() {
                for i in 0..6 {
                    f[i] += row[i] * r[k];
                }
            }
            assert!((f[2] - mass * gdt).abs() < 1e-8, "{method:?}: Σr_N = {}", f[2]);
            let speed = vx.hypot(vy);
            let (fx, fy) = if speed < mu * gdt {
                (-mass * vx, -mass * vy)
            } else {
                (-mu * mass * gdt * vx / speed, -mu * mass * gdt * vy / speed)
            };
            assert!(
                (f[0] - fx).abs() < 1e-8 && (f[1] - fy).abs() < 1e-8,
                "{method:?}: ({}, {}) vs ({fx}, {fy})",
                f[0],
                f[1]
            );
            for (i, fi) in f.iter().enumerate().skip(3) {
                assert!(fi.abs() < 1e-8, "{method:?}: moment {i} = {fi}");
            }
        }
    }
}

/// The friction-contact problem of `boxes` boxes (1 kg, 0.2 × 0.2 × 0.1 m) stacked face on face
/// on the ground, four corner contacts per interface, all falling freely for one step `h` under
/// gravity: `W = J M⁻¹ Jᵀ` is singular (12 unknowns per interface against 6 relative freedoms).
fn box_stack(boxes: usize, mu: f64, h: f64) -> FrictionContact {
    let (m, a, b, c) = (1.0, 0.1, 0.1, 0.05);
    let inertia = [m * (b * b + c * c) / 3.0, m * (a * a + c * c) / 3.0, m * (a * a + b * b) / 3.0];
    let n = 4 * boxes;
    let nu = 6 * boxes;
    // rows of J (3 per contact) over the boxes' [v, ω]
    let mut jac = vec![0.0; 3 * n * nu];
    for k in 0..boxes {
        for (corner, (sx, sy)) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)].iter().enumerate() {
            let i = 4 * k + corner;
            // the corner, relative to the upper box's centre (below it) and the lower's (above it)
            let arms = [(k, [sx * a, sy * b, -c], 1.0), (k.wrapping_sub(1), [sx * a, sy * b, c], -1.0)];
            for (body, r, sign) in arms {
                if body == usize::MAX {
                    continue;
                }
                for (row, e) in [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().enumerate() {
                    let at = (3 * i + row) * nu + 6 * body;
                    // eᵀ (v + ω × r) = eᵀ v + (r × e)ᵀ ω
                    let rxe = [r[1] * e[2] - r[2] * e[1], r[2] * e[0] - r[0] * e[2], r[0] * e[1] - r[1] * e[0]];
                    for x in 0..3 {
                        jac[at + x] += sign * e[x];
                        jac[at + 3 + x] += sign * rxe[x];
                    }
                }
            }
        }
    }
    let minv: Vec<f64> = (0..nu).map(|v| if v % 6 < 3 { 1.0 / m } else { 1.0 / inertia[v % 6 - 3] }).collect();
    let mm = 3 * n;
    let mut w = vec![0.0; mm * mm];
    for r in 0..mm {
        for s in 0..mm {
            w[r * mm + s] = (0..nu).map(|v| jac[r * nu + v] * minv[v] * jac[s * nu + v]).sum();
        }
    }
    // free velocity: every box falls at g h, so only the ground's corners approach
    let u_free: Vec<f64> = (0..nu).map(|v| if v % 6 == 2 { -9.81 * h } else { 0.0 }).collect();
    let q = (0..mm).map(|r| (0..nu).map(|v| jac[r * nu + v] * u_free[v]).sum()).collect();
    FrictionContact::new(3, Delassus::Dense(w), q, vec![mu; n]).unwrap()
}

#[test]
fn regularized_newton_converges_on_a_box_stack_and_carries_the_static_weights() {
    // the stack's W is singular; every interface must carry the impulse of the boxes above it,
    // (boxes − k) m g h, whatever the split among its four corners (statically indeterminate)
    let (boxes, h) = (6, 1e-2);
    let p = box_stack(boxes, 0.5, h);
    for method in [Method::newton(), Method::auto(), nsgs(1e-10)] {
        let mut ws = Workspace::for_problem(&p, &method).unwrap();
        let mut r = vec![0.0; p.unknowns()];
        let rep = solve(&p, &method, &mut r, false, &mut ws).unwrap();
        assert!(rep.converged && rep.residual <= 1e-10, "{method:?}: {rep:?}");
        if !matches!(method, Method::Nsgs(_)) {
            assert!(rep.iterations <= 40, "{method:?}: {rep:?}");
        }
        for k in 0..boxes {
            let carried: f64 = (0..4).map(|c| r[3 * (4 * k + c)]).sum();
            let weight = (boxes - k) as f64 * 9.81 * h;
            assert!(
                (carried - weight).abs() < 1e-9 * weight,
                "{method:?}: interface {k} carries {carried}, expected {weight}"
            );
            // the corners may pull against each other (also indeterminate), but not in sum
            for t in 1..3 {
                let net: f64 = (0..4).map(|c| r[3 * (4 * k + c) + t]).sum();
                assert!(net.abs() < 1e-8 * weight, "{method:?}: interface {k}: net friction {net}");
            }
        }
        // the local velocities are unique: all zero at rest
        let mut u = vec![0.0; p.unknowns()];
        p.velocity(&r, &mut u).unwrap();
        assert!(max_abs(&u) < 1e-9 * 9.81 * h, "{method:?}: |u| = {}", max_abs(&u));
    }
    // without the regularization the Jacobian of the sticking set is singular: Newton stalls
    let plain = Method::Newton(NewtonOptions { regularization: 0.0, max_iter: 40, ..Default::default() });
    let mut ws = Workspace::for_problem(&p, &plain).unwrap();
    let mut r = vec![0.0; p.unknowns()];
    let rep = solve(&p, &plain, &mut r, false, &mut ws).unwrap();
    assert!(!rep.converged, "plain Newton: {rep:?}");
}

#[test]
fn newton_reuses_its_factorization_on_a_resting_contact_set() {
    // the same stack solved again from a slightly perturbed warm start: the projection
    // derivatives are unchanged, so the chord direction with the old factors converges
    let p = box_stack(4, 0.5, 1e-3);
    let method = Method::newton();
    let mut ws = Workspace::for_problem(&p, &method).unwrap();
    let mut r = vec![0.0; p.unknowns()];
    let rep = solve(&p, &method, &mut r, false, &mut ws).unwrap();
    assert!(rep.converged);
    let exact = r.clone();
    for (k, v) in r.iter_mut().enumerate() {
        if k % 3 == 0 {
            *v *= 1.0 + 1e-6 * (k as f64).sin();
        }
    }
    let rep = solve(&p, &method, &mut r, true, &mut ws).unwrap();
    assert!(rep.converged && rep.iterations <= 2, "{rep:?}");
    let mut u = vec![0.0; p.unknowns()];
    p.velocity(&r, &mut u).unwrap();
    assert!(max_abs(&u) < 1e-9 * 9.81e-3);
    let total = |r: &[f64]| (0..4).map(|c| r[3 * c]).sum::<f64>();
    assert!((total(&r) - total(&exact)).abs() < 1e-12);
}

// ---------- accelerated projected gradient ----------

fn apgd(tol: f64) -> Method {
    Method::Apgd(ApgdOptions { tol, max_iter: 200_000 })
}

#[test]
fn apgd_agrees_with_lemke_on_planar_problems() {
    // exact Lemke answers (d = 2) on the random problems and the disk stack, sticking and slipping
    let mut problems: Vec<FrictionContact> = (1..=8).map(|s| random_friction_contact(2, 8, 0.2, s).unwrap()).collect();
    problems.push(disk_stack(6, 0.3, 0.6, 5).unwrap());
    let mut seen = [false; 3];
    for (k, p) in problems.iter().enumerate() {
        let (r_lemke, rep) = run_fc(p, Method::lemke()).unwrap();
        assert!(rep.converged && rep.residual < 1e-12, "problem {k}: Lemke {rep:?}");
        let (r_apgd, rep) = run_fc(p, apgd(1e-12)).unwrap();
        assert!(rep.converged && rep.residual <= 1e-12, "problem {k}: APGD {rep:?}");
        let scale = 1.0 + max_abs(&r_lemke);
        assert!(max_diff(&r_lemke, &r_apgd) < 1e-7 * scale, "problem {k}:\n{r_lemke:?}\n{r_apgd:?}");
        for s in states(p, &r_lemke) {
            seen[s as usize] = true;
        }
    }
    assert_eq!(seen, [true; 3], "open, stick and slip all occur");
}

#[test]
fn apgd_agrees_with_newton_on_spatial_problems_and_piles() {
    let mut problems: Vec<FrictionContact> =
        (1..=6).map(|s| random_friction_contact(3, 10, 0.3, 100 + s).unwrap()).collect();
    problems.push(sphere_pile(60, 0.5, 3).unwrap());
    for (k, p) in problems.iter().enumerate() {
        // the reference: Newton on the random problems, Gauss–Seidel on the pile
        let reference = if k < 6 { newton(1e-13) } else { nsgs(1e-13) };
        let (r_newton, rep) = run_fc(p, reference).unwrap();
        assert!(rep.converged, "problem {k}: reference {rep:?}");
        let (r_apgd, rep) = run_fc(p, apgd(1e-12)).unwrap();
        assert!(rep.converged && rep.residual <= 1e-12, "problem {k}: APGD {rep:?}");
        // the velocities are unique even where the impulses are not (a pile's W is singular)
        let (mut u_n, mut u_a) = (vec![0.0; p.unknowns()], vec![0.0; p.unknowns()]);
        p.velocity(&r_newton, &mut u_n).unwrap();
        p.velocity(&r_apgd, &mut u_a).unwrap();
        let scale = 1.0 + max_abs(&p.q);
        assert!(max_diff(&u_n, &u_a) < 1e-8 * scale, "problem {k}: velocities differ by {}", max_diff(&u_n, &u_a));
        if k < 6 {
            assert!(max_diff(&r_newton, &r_apgd) < 1e-7 * (1.0 + max_abs(&r_newton)), "problem {k}");
        }
    }
}

#[test]
fn apgd_carries_the_static_weights_of_a_box_stack_and_rests_warm() {
    let (boxes, h) = (6, 1e-2);
    let p = box_stack(boxes, 0.5, h);
    let method = apgd(1e-12);
    let mut ws = Workspace::for_problem(&p, &method).unwrap();
    let mut r = vec![0.0; p.unknowns()];
    let rep = solve(&p, &method, &mut r, false, &mut ws).unwrap();
    assert!(rep.converged && rep.residual <= 1e-12, "{rep:?}");
    for k in 0..boxes {
        // impulse over the step: the force each interface carries, against the weight above it
        let carried: f64 = (0..4).map(|c| r[3 * (4 * k + c)]).sum::<f64>() / h;
        let weight = (boxes - k) as f64 * 9.81;
        assert!((carried - weight).abs() < 1e-8, "interface {k} carries {carried} N, expected {weight} N");
        for t in 1..3 {
            let net: f64 = (0..4).map(|c| r[3 * (4 * k + c) + t]).sum::<f64>() / h;
            assert!(net.abs() < 1e-8, "interface {k}: net friction {net} N");
        }
    }
    // the next step at rest: the warm start is already the answer, no iteration
    let again = solve(&p, &method, &mut r, true, &mut ws).unwrap();
    assert!(again.converged && again.iterations <= 1, "{again:?}");
}

#[test]
fn apgd_options_are_checked_and_lcps_refused() {
    let p = random_friction_contact(3, 2, 0.3, 1).unwrap();
    let bad = Method::Apgd(ApgdOptions { tol: 0.0, max_iter: 10 });
    let err = run_fc(&p, bad).unwrap_err().to_string();
    assert!(err.contains("APGD: tol"), "{err}");
    let bad = Method::Apgd(ApgdOptions { tol: 1e-8, max_iter: 0 });
    assert!(run_fc(&p, bad).unwrap_err().to_string().contains("APGD: max_iter"));
    let lcp = Lcp::new(vec![2.0], vec![-1.0]).unwrap();
    assert!(run_lcp(&lcp, Method::apgd()).unwrap_err().to_string().contains("APGD solves friction-contact"));
    // a budget too small is reported, not raised, with the best iterate's residual
    let (_, rep) =
        run_fc(&sphere_pile(60, 0.5, 3).unwrap(), Method::Apgd(ApgdOptions { tol: 1e-14, max_iter: 3 })).unwrap();
    assert!(!rep.converged && rep.iterations == 3 && rep.residual.is_finite() && rep.residual > 1e-14, "{rep:?}");
    let m: Method = serde_json::from_str(r#"{"type": "apgd", "tol": 1e-6}"#).unwrap();
    assert_eq!(m, Method::Apgd(ApgdOptions { tol: 1e-6, ..Default::default() }));
}

#[test]
fn gauss_seidel_sweep_order_is_a_permutation_and_keeps_the_solution() {
    // a stack of boxes (contacts numbered bottom-up) solved with the sweeps top-down and bottom-up:
    // the same velocities and interface loads to the tolerance, the order sorted by key
    let p = box_stack(4, 0.5, 1e-2);
    let method = nsgs(1e-12);
    let mut ws = Workspace::for_problem(&p, &method).unwrap();
    let key: Vec<f64> = (0..p.contacts()).map(|i| -((i / 4) as f64)).collect();
    ws.set_order(&key);
    let mut expect: Vec<usize> = (0..p.contacts()).collect();
    expect.sort_by_key(|&i| (std::cmp::Reverse(i / 4), i));
    assert_eq!(ws.order, expect);
    let mut r_down = vec![0.0; p.unknowns()];
    let rep = solve(&p, &method, &mut r_down, false, &mut ws).unwrap();
    assert!(rep.converged, "{rep:?}");
    ws.set_order(&[]);
    assert!(ws.order.is_empty());
    let mut r_up = vec![0.0; p.unknowns()];
    assert!(solve(&p, &method, &mut r_up, false, &mut ws).unwrap().converged);
    for k in 0..4 {
        let load = |r: &[f64]| (0..4).map(|c| r[3 * (4 * k + c)]).sum::<f64>();
        assert!((load(&r_down) - load(&r_up)).abs() < 1e-10, "interface {k}");
    }
    // an order for another problem size is ignored (index order)
    ws.set_order(&[0.0; 3]);
    let mut r = vec![0.0; p.unknowns()];
    assert!(solve(&p, &method, &mut r, false, &mut ws).unwrap().converged);
    assert_eq!(r, r_up);
}

/// Newton takes one step past the first iterate under the tolerance, unless that iterate is
/// already below a thousandth of it (a time stepper's next warm start then begins well inside
/// the tolerance); the extra step lowers the residual.
#[test]
fn newton_polishes_once_past_the_tolerance() {
    let problems = [disk_stack(6, 0.3, 0.6, 5).unwrap(), random_friction_contact(3, 8, 0.5, 3).unwrap()];
    let mut polished = 0;
    for p in &problems {
        for tol in [1e-4, 1e-6, 1e-8] {
            let with = |max_iter| Method::Newton(NewtonOptions { tol, max_iter, ..Default::default() });
            let (_, full) = run_fc(p, with(200)).unwrap();
            assert!(full.converged && full.residual <= tol, "{full:?}");
            // the first iterate under the tolerance (a run capped at k iterations returns it)
            let (k0, at_k0) = (1..=full.iterations)
                .map(|k| (k, run_fc(p, with(k)).unwrap().1.residual))
                .find(|(_, r)| *r <= tol)
                .unwrap();
            if at_k0 <= 1e-3 * tol {
                assert_eq!(full.iterations, k0, "tol {tol}");
            } else {
                assert_eq!(full.iterations, k0 + 1, "tol {tol}: no polishing step");
                assert!(full.residual < at_k0, "tol {tol}: {} after {at_k0}", full.residual);
                polished += 1;
            }
        }
    }
    assert!(polished >= 1, "no case took the polishing step");
}

/// A contact whose `W_NN` is not finite (kinematics gone bad) is named as such, not as one that
/// cannot move along its normal; a zero or negative one as that.
#[test]
fn w_nn_check_names_the_contact_and_the_fault() {
    for (w, says) in
        [(f64::NAN, "not finite"), (f64::INFINITY, "not finite"), (0.0, "must be > 0"), (-1.0, "must be > 0")]
    {
        let e = check_wnn(4, w).unwrap_err().to_string();
        assert!(e.contains("contact 4") && e.contains(says), "{w}: {e}");
    }
    assert!(check_wnn(4, 1e-30).is_ok());
}

/// Auto's plan: sweeps before Newton (10 from a cold start, 4 warm, at a tenth of the
/// tolerance; more on a problem large enough that a fresh factorization costs more, until Newton
/// has factored a problem in the workspace), none before Gauss–Seidel on a large problem.
#[test]
fn auto_plan_sweeps_before_newton_only() {
    let o = AutoOptions { tol: 1e-8, newton_max_unknowns: 30, ..Default::default() };
    for held in [false, true] {
        let cold = o.plan(30, &[0.0; 30], held);
        assert!(matches!(cold.then, Method::Newton(p) if p.tol == 1e-8));
        let s = cold.sweeps.unwrap();
        assert_eq!((s.max_iter, s.tol, s.relaxation, s.anderson), (AUTO_COLD_SWEEPS, 1e-9, 1.0, 0));
        let mut warm = [0.0; 30];
        warm[7] = 0.5;
        assert_eq!(o.plan(30, &warm, held).sweeps.unwrap().max_iter, AUTO_SWEEPS);
        let big = o.plan(33, &[0.0; 33], held);
        assert!(big.sweeps.is_none() && matches!(big.then, Method::Nsgs(p) if p.tol == 1e-8));
        // a Newton plan carries the rescue sweeps (Anderson-accelerated, the full sweep budget)
        let rescue = cold.rescue.unwrap();
        assert_eq!((rescue.tol, rescue.max_iter, rescue.anderson), (1e-8, o.nsgs_max_iter, o.nsgs_anderson));
        assert!(big.rescue.is_none());
    }
    // 408 unknowns (the pyramid): 110 sweeps unless a factorization is held, accelerated from a
    // cold start; with one held (of any size) the few sweeps
    let o = AutoOptions::default();
    let mut warm = vec![0.0; 408];
    warm[3] = 1.0;
    for (x, anderson) in [(&vec![0.0; 408], AUTO_ANDERSON), (&warm, 0)] {
        let s = o.plan(408, x, false).sweeps.unwrap();
        assert_eq!((s.max_iter, s.anderson), (408 * 408 / AUTO_SWEEPS_PER_FACTOR, anderson));
        assert_eq!(s.max_iter, 110);
    }
    let s = o.plan(408, &warm, true).sweeps.unwrap();
    assert_eq!((s.max_iter, s.anderson), (AUTO_SWEEPS, 0));
}

/// Newton's stall rule on pile fixtures, where the regularized Newton often stalls near 1e-3
/// (measured: 9 of these 14 ran to the cap of 200): the solves it finishes are untouched (same
/// iterations, same impulses), the stalled ones end once the residual has not halved for
/// [`AUTO_NEWTON_STALL`] iterations (39 to 79 here) — and Auto, which sets the rule, finishes
/// every one of them with its sweeps.
#[test]
fn newton_gives_up_when_its_residual_stops_halving() {
    let (mut capped, mut ok) = (0, 0);
    for seed in 1..8 {
        for n in [60, 150] {
            let p = sphere_pile(n, 0.5, seed).unwrap();
            let (r0, plain) = run_fc(&p, newton(1e-10)).unwrap();
            let rule = Method::Newton(NewtonOptions { tol: 1e-10, stall: AUTO_NEWTON_STALL, ..Default::default() });
            let (r1, with) = run_fc(&p, rule).unwrap();
            if plain.converged {
                ok += 1;
                assert!(
                    with.converged && with.iterations == plain.iterations && r0 == r1,
                    "{n} {seed}: {plain:?} {with:?}"
                );
            } else {
                capped += 1;
                assert_eq!(plain.iterations, 200);
                assert!(!with.converged && with.iterations < 100, "{n} {seed}: {with:?}");
            }
            let auto = AutoOptions { tol: 1e-8, ..Default::default() };
            let (r, rep) = run_fc(&p, Method::Auto(auto)).unwrap();
            let again = p.residual(&r).unwrap();
            assert!(rep.converged && again <= 1e-8, "{n} {seed}: auto {rep:?}, residual {again}");
        }
    }
    assert!(capped >= 5 && ok >= 3, "both kinds are covered: {capped} capped, {ok} converged");
    assert!(matches!(AutoOptions::default().pick(30), Method::Newton(o) if o.stall == AUTO_NEWTON_STALL));
}

/// When Auto's Newton ends above the tolerance (here forced: one iteration), Gauss–Seidel from
/// its iterate finishes the solve; the report counts all three stages, and the residual
/// recomputed from the returned impulses meets the tolerance. Without the rescue the report
/// would say unconverged after 1 + the first sweeps.
#[test]
fn auto_rescues_a_stalled_newton_with_sweeps() {
    let p = sphere_pile(60, 0.5, 3).unwrap();
    for anderson in [0, 4] {
        let o = AutoOptions { tol: 1e-8, newton_max_iter: 1, nsgs_anderson: anderson, ..Default::default() };
        assert!(matches!(o.pick(p.unknowns()), Method::Newton(_)), "a Newton-sized problem");
        let (r, rep) = run_fc(&p, Method::Auto(o)).unwrap();
        assert!(rep.converged, "{anderson}: {rep:?}");
        assert!(rep.iterations > 1 + AUTO_COLD_SWEEPS, "{anderson}: the rescue ran: {rep:?}");
        let again = p.residual(&r).unwrap();
        assert!(again <= 1e-8 && (again - rep.residual).abs() <= 1e-12, "{anderson}: {again} vs {rep:?}");
        // Newton alone at this cap does not get there
        let newton = Method::Newton(NewtonOptions { tol: 1e-8, max_iter: 1, ..Default::default() });
        let mut ws = Workspace::for_problem(&p, &newton).unwrap();
        let mut x = vec![0.0; p.unknowns()];
        let sw = Method::Nsgs(NsgsOptions { tol: 1e-9, max_iter: AUTO_COLD_SWEEPS, ..Default::default() });
        solve(&p, &sw, &mut x, false, &mut Workspace::for_problem(&p, &sw).unwrap()).unwrap();
        assert!(!solve(&p, &newton, &mut x, true, &mut ws).unwrap().converged);
    }
}

/// Anderson-accelerated Gauss–Seidel solves the same problems (the returned impulses satisfy
/// the contact conditions to the tolerance, checked by an independent residual evaluation) in
/// fewer sweeps on piles, where plain sweeps crawl; a depth above the limit is refused. The
/// gain varies from pile to pile (on a few the history keeps restarting until the stall guard
/// turns it off, and the count is then near the plain one), so the test takes fifteen piles
/// and holds the median and the worst case.
#[test]
fn anderson_sweeps_converge_in_fewer_sweeps_on_piles() {
    let mut ratios = Vec::new();
    for n in [100, 150, 200] {
        for seed in 1..=5 {
            let p = sphere_pile(n, 0.5, seed).unwrap();
            let plain = Method::Nsgs(NsgsOptions { tol: 1e-8, max_iter: 100_000, ..Default::default() });
            let fast = Method::Nsgs(NsgsOptions { tol: 1e-8, max_iter: 100_000, anderson: 4, ..Default::default() });
            let (_, rp) = run_fc(&p, plain).unwrap();
            let (r, ra) = run_fc(&p, fast).unwrap();
            assert!(rp.converged && ra.converged, "{n}/{seed}: {rp:?} {ra:?}");
            // the residual recomputed from the returned impulses alone
            let again = p.residual(&r).unwrap();
            assert!(again <= 1e-8 && (again - ra.residual).abs() <= 1e-12, "{n}/{seed}: {again} vs {ra:?}");
            ratios.push(ra.iterations as f64 / rp.iterations as f64);
        }
    }
    ratios.sort_by(f64::total_cmp);
    // (measured: median 0.15, worst 0.66, plain sweeps 286–7504)
    assert!(ratios[7] < 0.3 && ratios[14] < 1.0, "sweep ratios (accelerated / plain) {ratios:?}");
    let bad = Method::Nsgs(NsgsOptions { anderson: anderson::MAX_DEPTH + 1, ..Default::default() });
    let e = run_fc(&sphere_pile(10, 0.5, 1).unwrap(), bad).unwrap_err().to_string();
    assert!(e.contains("anderson") && e.contains("0..=8"), "{e}");
}

/// Anderson's guard pauses the acceleration at a stall and then starts it again: after
/// `STALL` sweeps whose change does not beat the best one it stops extrapolating, and after
/// `RETRY` plain sweeps it extrapolates again from a fresh history (off for the rest of a solve,
/// the late steps of the 1000-sphere pour ran mostly plain; see `tests/test_anderson_retry.py`).
#[test]
fn anderson_pauses_at_a_stall_and_starts_again() {
    use super::anderson::{Anderson, RETRY, STALL};
    let n = 4;
    let mut aa = Anderson::default();
    aa.reserve(n, n);
    aa.begin(n, n, 4);
    let (mut g, mut z) = (vec![0.0; n], vec![0.0; n]);
    // sweeps whose change never falls below the first one (the same squared norm every time,
    // scattered residual terms so that the least-squares problems stay regular): a stall
    let mut seed = 12345u64;
    let mut sweep = |aa: &mut Anderson, g: &mut Vec<f64>, z: &mut Vec<f64>| {
        for i in 0..n {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let f = 0.2 + 0.1 * (seed >> 11) as f64 / (1u64 << 53) as f64;
            aa.set_residual(i, f);
            g[i] += f;
            z[i] = g[i];
        }
        aa.step(g, z, 1.0)
    };
    let mut extrapolated = Vec::new();
    for _ in 0..(STALL + RETRY + 10) {
        extrapolated.push(sweep(&mut aa, &mut g, &mut z));
    }
    // extrapolating from the second sweep on (the first has no difference yet) ...
    assert!(!extrapolated[0] && extrapolated[1..STALL - 28].iter().all(|e| *e), "{extrapolated:?}");
    // ... then paused for RETRY plain sweeps once the best change has stood for STALL sweeps ...
    let first_off = (1..extrapolated.len()).find(|&k| k > STALL - 28 && !extrapolated[k..k + RETRY].iter().any(|e| *e));
    let first_off = first_off.expect("the guard never paused the acceleration");
    assert!((STALL..=STALL + 12).contains(&first_off), "paused at sweep {first_off}");
    // ... and extrapolating again after the pause (a fresh history needs two sweeps)
    let back = first_off + RETRY;
    assert!(
        extrapolated[back..back + 4].iter().any(|e| *e),
        "not resumed after {RETRY} plain sweeps: {:?}",
        &extrapolated[back..]
    );
}

/// A tolerance that is not a finite number > 0 is refused before a solve, naming the solver: an
/// infinite one (`tol = inf` in a model file) passed the old `> 0` test and ended every solve at
/// its warm start, reported converged.
#[test]
fn a_tolerance_that_is_not_finite_and_positive_is_refused() {
    for tol in [f64::INFINITY, f64::NAN, 0.0, -1e-8] {
        let methods = [
            ("NSGS", Method::Nsgs(NsgsOptions { tol, ..Default::default() })),
            ("auto solver", Method::Auto(AutoOptions { tol, ..Default::default() })),
            ("APGD", Method::Apgd(ApgdOptions { tol, ..Default::default() })),
            ("Newton", Method::Newton(NewtonOptions { tol, ..Default::default() })),
        ];
        for (name, m) in methods {
            let e = m.validate().unwrap_err().to_string();
            assert!(e.contains(&format!("{name}: tol must be a finite number > 0, got {tol}")), "{e}");
        }
    }
    assert!(Method::Auto(AutoOptions { tol: 1e300, ..Default::default() }).validate().is_ok());
}

#[test]
fn stall_watch_passes_steady_convergence_and_catches_cycling() {
    use super::nsgs::StallWatch;
    // sweeps converging at a steady rate, however slow within reason (a factor 2.2 per window of
    // 1024 sweeps: 2000x in 10 000 sweeps, the slowest steps of the 1000-sphere pour), never stall
    let rate = (1.0f64 / 2000.0).powf(1.0 / 10_000.0);
    let mut w = StallWatch::new(1024);
    let mut change = 1.0;
    for it in 1..=50_000 {
        // (Anderson-like noise: every third sweep jumps up)
        let noisy = if it % 3 == 0 { 5.0 * change } else { change };
        assert!(!w.stalled(it, noisy), "steady convergence flagged as a stall at sweep {it}");
        change *= rate;
    }
    // a change that wanders without trend stalls at the end of the second window (2 × 1024),
    // then the windows start again from there: the next at 2048 + 2 × 1024
    let mut w = StallWatch::new(1024);
    let mut rng = Rng::new(7);
    let mut stalls = Vec::new();
    for it in 1..=10_000 {
        if w.stalled(it, rng.uniform(1e-3, 1e-2)) {
            stalls.push(it);
        }
    }
    assert_eq!(&stalls[..2], &[2048, 4096], "{stalls:?}");
    // after a stall, a change that then halves per window passes again
    let mut w = StallWatch::new(100);
    for it in 1..=200 {
        w.stalled(it, 1.0);
    }
    let mut change = 1.0;
    for it in 201..=5000 {
        change *= 0.99;
        assert!(!w.stalled(it, change), "sweep {it}");
    }
    // 0: never
    let mut w = StallWatch::new(0);
    assert!((1..=100_000).all(|it| !w.stalled(it, 1.0)));
    // the damping: 0.9 per stall, down to 0.5; over-relaxation drops to it at once
    assert_eq!(StallWatch::damped(1.0), 0.9);
    assert!((StallWatch::damped(0.9) - 0.81).abs() < 1e-15);
    assert_eq!(StallWatch::damped(0.52), 0.5);
    assert_eq!(StallWatch::damped(1.5), 0.9);
}
