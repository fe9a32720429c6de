//! Integrators against closed-form solutions.

use super::*;

/// ẍ = -ω² x as a first-order system.
struct Oscillator {
    omega: f64,
    evals: usize,
}

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        self.evals += 1;
        dy[0] = y[1];
        dy[1] = -self.omega * self.omega * y[0];
        Ok(())
    }
}

fn run(kind: IntegratorKind, omega: f64, t_end: f64, n_out: usize) -> (Vec<f64>, Vec<[f64; 2]>, Stats) {
    let mut sys = Oscillator { omega, evals: 0 };
    let t_out: Vec<f64> = (0..=n_out).map(|k| t_end * k as f64 / n_out as f64).collect();
    let mut ts = vec![];
    let mut ys = vec![];
    let mut obs = |_s: &mut Oscillator, t: f64, y: &[f64], _f: bool| -> Result<()> {
        ts.push(t);
        ys.push([y[0], y[1]]);
        Ok(())
    };
    let st = integrate(&kind, &mut sys, 0.0, &[1.0, 0.0], &t_out, &mut obs).unwrap();
    (ts, ys, st)
}

fn radau_fixed(dt: f64, newton_tol: f64) -> IntegratorKind {
    IntegratorKind::Radau5 { dt, newton_tol, rtol: 0.0, atol: 1e-10, max_step: 0.0, first_step: 0.0 }
}

fn radau_adaptive(rtol: f64, atol: f64) -> IntegratorKind {
    IntegratorKind::Radau5 { dt: 0.0, newton_tol: 1e-10, rtol, atol, max_step: 0.0, first_step: 0.0 }
}

fn max_err(ts: &[f64], ys: &[[f64; 2]], omega: f64) -> f64 {
    ts.iter().zip(ys).map(|(t, y)| (y[0] - (omega * t).cos()).abs()).fold(0.0, f64::max)
}

#[test]
fn rk4_is_fourth_order() {
    let (t1, y1, _) = run(IntegratorKind::Rk4 { dt: 0.01 }, 2.0, 5.0, 50);
    let (t2, y2, _) = run(IntegratorKind::Rk4 { dt: 0.005 }, 2.0, 5.0, 50);
    let (e1, e2) = (max_err(&t1, &y1, 2.0), max_err(&t2, &y2, 2.0));
    assert_eq!(t1.len(), 51);
    assert!((t1[50] - 5.0).abs() < 1e-12);
    let order = (e1 / e2).log2();
    assert!((order - 4.0).abs() < 0.2, "observed order {order}");
    assert!(e1 < 1e-6);
}

#[test]
fn dopri5_meets_tolerance_with_dense_output() {
    let kind = IntegratorKind::Dopri5 { rtol: 1e-10, atol: 1e-12, max_step: 0.0, first_step: 0.0 };
    // outputs far denser than steps: exercised through the continuous extension
    let (t, y, st) = run(kind, 3.0, 10.0, 1000);
    assert!(max_err(&t, &y, 3.0) < 1e-8, "error {}", max_err(&t, &y, 3.0));
    // the output grid must not change the steps taken
    let (_, _, coarse) = run(kind, 3.0, 10.0, 10);
    assert_eq!(st.steps, coarse.steps);
}

#[test]
fn radau5_is_stable_on_a_stiff_oscillator_and_accurate_on_a_smooth_one() {
    // smooth: order 5 at a moderate step
    let (t, y, _) = run(radau_fixed(0.05, 1e-12), 2.0, 5.0, 100);
    assert!(max_err(&t, &y, 2.0) < 1e-6, "error {}", max_err(&t, &y, 2.0));
    // stiff: ω dt = 100, an explicit scheme explodes, Radau IIA damps (L-stable) and stays bounded
    let (_, y, _) = run(radau_fixed(0.1, 1e-10), 1000.0, 2.0, 20);
    assert!(y.iter().all(|v| v[0].abs() <= 1.0 + 1e-9));
    // each step is the stability function R(Z) = (I + 2Z/5 + Z²/20)(I − 3Z/5 + 3Z²/20 − Z³/60)⁻¹
    // of Z = h A, A = [[0, 1], [−ω², 0]]: |R(100 i)| ≈ 0.030, so 20 steps leave ≈ 3.5e-31
    let z = nalgebra::Matrix2::<f64>::new(0.0, 1.0, -1e6, 0.0) * 0.1;
    let i = nalgebra::Matrix2::identity();
    let num = i + z * 0.4 + z * z / 20.0;
    let den = i - z * 0.6 + z * z * 0.15 - z * z * z / 60.0;
    let r = num * den.try_inverse().unwrap();
    let mut exact = nalgebra::Vector2::<f64>::new(1.0, 0.0);
    for (k, yk) in y.iter().enumerate().skip(1) {
        exact = r * exact;
        // (x and v/ω to round-off of the first step's size, 1e-13, and relative 1e-9 after)
        let tol = 1e-13 * 0.031f64.powi(k as i32 - 1) + 1e-9 * exact[0].abs();
        assert!((yk[0] - exact[0]).abs() <= tol, "step {k}: x {} vs R^k x0 = {}", yk[0], exact[0]);
        assert!((yk[1] - exact[1]).abs() <= 1e3 * tol, "step {k}: v {} vs {}", yk[1], exact[1]);
    }
    assert!(y.last().unwrap()[0].abs() < 1e-25, "{}", y.last().unwrap()[0]);
}

#[test]
fn rejects_bad_settings() {
    let mut sys = Oscillator { omega: 1.0, evals: 0 };
    let mut obs = |_s: &mut Oscillator, _t: f64, _y: &[f64], _f: bool| -> Result<()> { Ok(()) };
    let e = integrate(&IntegratorKind::Rk4 { dt: -1.0 }, &mut sys, 0.0, &[1.0, 0.0], &[0.0, 1.0], &mut obs);
    assert!(format!("{}", e.unwrap_err()).contains("dt"));
    let e = integrate(
        &IntegratorKind::Dopri5 { rtol: 0.0, atol: 1e-9, max_step: 0.0, first_step: 0.0 },
        &mut sys,
        0.0,
        &[1.0, 0.0],
        &[0.0, 1.0],
        &mut obs,
    );
    assert!(format!("{}", e.unwrap_err()).contains("rtol"));
}

#[test]
fn dopri5_dense_output_is_exact_for_linear_growth() {
    // y' = 1: the continuous extension must reproduce y = t exactly (its weights sum to zero)
    struct Ramp;
    impl OdeSystem for Ramp {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, _y: &[f64], dy: &mut [f64]) -> Result<()> {
            dy[0] = 1.0;
            Ok(())
        }
    }
    let t_out: Vec<f64> = (0..=37).map(|k| k as f64 * 0.27).collect();
    let mut worst: f64 = 0.0;
    let mut obs = |_s: &mut Ramp, t: f64, y: &[f64], _f: bool| -> Result<()> {
        worst = worst.max((y[0] - t).abs());
        Ok(())
    };
    let kind = IntegratorKind::Dopri5 { rtol: 1e-6, atol: 1e-6, max_step: 3.0, first_step: 0.0 };
    integrate(&kind, &mut Ramp, 0.0, &[0.0], &t_out, &mut obs).unwrap();
    assert!(worst < 1e-12, "{worst}");
}

// ---- adaptive Radau IIA ---------------------------------------------------------------------------

/// Runs `sys` from (0, y0) with outputs at `t_out`; the outputs and the stats.
fn run_sys<S: OdeSystem>(kind: IntegratorKind, sys: &mut S, y0: &[f64], t_out: &[f64]) -> (Vec<Vec<f64>>, Stats) {
    let mut ys = vec![];
    let mut obs = |_s: &mut S, _t: f64, y: &[f64], _f: bool| -> Result<()> {
        ys.push(y.to_vec());
        Ok(())
    };
    let st = integrate(&kind, sys, 0.0, y0, t_out, &mut obs).unwrap();
    (ys, st)
}

#[test]
fn radau5_constants_match_hairer_wanner() {
    let tab = radau5::Tableau::new();
    let (a, _) = radau5::coefficients();
    // eigenvalues of A⁻¹ (HW IV.8, the constants of RADAU5)
    assert!((tab.gamma - 3.637834252744496).abs() < 1e-13, "{}", tab.gamma);
    assert!((tab.alpha - 2.681082873627752).abs() < 1e-13, "{}", tab.alpha);
    assert!((tab.beta - 3.050430199247411).abs() < 1e-13, "{}", tab.beta);
    // T⁻¹ A⁻¹ T = Λ = [γ 0 0; 0 α −β; 0 β α], via A T Λ = T
    let lam = [[tab.gamma, 0.0, 0.0], [0.0, tab.alpha, -tab.beta], [0.0, tab.beta, tab.alpha]];
    for i in 0..3 {
        for j in 0..3 {
            let atl: f64 = (0..3).map(|k| a[i][k] * (0..3).map(|l| tab.t[k][l] * lam[l][j]).sum::<f64>()).sum();
            assert!((atl - tab.t[i][j]).abs() < 1e-12, "({i}, {j})");
            let tti: f64 = (0..3).map(|k| tab.ti[i][k] * tab.t[k][j]).sum();
            assert!((tti - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
        }
    }
    // error-estimate weights: −(13 + 7√6)/3, (−13 + 7√6)/3, −1/3
    let s6 = 6f64.sqrt();
    let dd = [-(13.0 + 7.0 * s6) / 3.0, (-13.0 + 7.0 * s6) / 3.0, -1.0 / 3.0];
    for j in 0..3 {
        assert!((tab.dd[j] - dd[j]).abs() < 1e-12, "dd[{j}] = {} vs {}", tab.dd[j], dd[j]);
    }
    // the collocation weights interpolate: w_i(c_j) = δ_ij, w(0) = 0
    for j in 0..3 {
        let w = tab.collocation_weights(tab.c[j]);
        for i in 0..3 {
            assert!((w[i] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
        }
    }
    assert!(tab.collocation_weights(0.0).iter().all(|w| w.abs() < 1e-15));
}

/// Prothero–Robinson: y' = λ (y − sin t) + cos t, exact y = sin t from y(0) = 0.
struct ProtheroRobinson {
    lambda: f64,
}

impl OdeSystem for ProtheroRobinson {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        dy[0] = self.lambda * (y[0] - t.sin()) + t.cos();
        Ok(())
    }
}

/// y' = M y with M = S diag(−1, −1e5) S⁻¹, S = [1 1; 1 −1]: a slow and a fast mode, coupled.
struct StiffLinear;

impl StiffLinear {
    const L: [f64; 2] = [-1.0, -1e5];
    fn exact(t: f64, y0: &[f64; 2]) -> [f64; 2] {
        // modal coordinates m = S⁻¹ y0 = ((y1 + y2)/2, (y1 − y2)/2)
        let m = [0.5 * (y0[0] + y0[1]) * (Self::L[0] * t).exp(), 0.5 * (y0[0] - y0[1]) * (Self::L[1] * t).exp()];
        [m[0] + m[1], m[0] - m[1]]
    }
}

impl OdeSystem for StiffLinear {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        let (a, b) = (0.5 * (Self::L[0] + Self::L[1]), 0.5 * (Self::L[0] - Self::L[1]));
        dy[0] = a * y[0] + b * y[1];
        dy[1] = b * y[0] + a * y[1];
        Ok(())
    }
}

#[test]
fn radau5_adaptive_error_falls_with_rtol_on_stiff_linear_problems() {
    let mut last = [f64::INFINITY; 2];
    for rtol in [1e-4, 1e-6, 1e-8] {
        // Prothero–Robinson with λ = −1e6 over 10 s: an explicit scheme needs h < 3e-6, 3e6 steps
        let (ys, st) =
            run_sys(radau_adaptive(rtol, rtol), &mut ProtheroRobinson { lambda: -1e6 }, &[0.0], &[0.0, 10.0]);
        let e_pr = (ys[1][0] - 10f64.sin()).abs();
        assert!(st.steps < 2000, "rtol {rtol}: {st:?}");
        // the coupled stiff pair over 5 s (explicit: h < 2.8e-5, 2e5 steps)
        let y0 = [1.0, 3.0];
        let (ys, st2) = run_sys(radau_adaptive(rtol, rtol), &mut StiffLinear, &y0, &[0.0, 5.0]);
        let ex = StiffLinear::exact(5.0, &y0);
        let e_lin = (ys[1][0] - ex[0]).abs().max((ys[1][1] - ex[1]).abs()) / ex[0].abs();
        assert!(st2.steps < 1000, "rtol {rtol}: {st2:?}");
        eprintln!("rtol {rtol:e}: Prothero-Robinson error {e_pr:.3e} ({st:?}); stiff pair relative error {e_lin:.3e} ({st2:?})");
        assert!(e_pr < rtol && e_lin < rtol, "rtol {rtol}: {e_pr:e}, {e_lin:e}");
        assert!(e_pr < 0.1 * last[0] && e_lin < 0.1 * last[1], "rtol {rtol}: {e_pr:e}, {e_lin:e} after {last:?}");
        last = [e_pr, e_lin];
    }
}

/// Van der Pol in the scaled form of the Hairer test set: y1' = y2, y2' = ((1 − y1²) y2 − y1)/ε.
struct VanDerPol {
    eps: f64,
}

impl OdeSystem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        dy[0] = y[1];
        dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / self.eps;
        Ok(())
    }
}

#[test]
fn radau5_adaptive_solves_van_der_pol_with_eps_1e6_to_its_tolerance() {
    // reference at t = 2 of the Test Set for IVP Solvers (Bari), problem VDPOL: ε = 1e-6,
    // y(0) = (2, 0), computed there by RADAU in quadruple precision
    let reference = [1.706167732170483, -0.8928097010247975];
    let mut last = f64::INFINITY;
    for rtol in [1e-6, 1e-8, 1e-10] {
        let (ys, st) = run_sys(radau_adaptive(rtol, rtol), &mut VanDerPol { eps: 1e-6 }, &[2.0, 0.0], &[0.0, 2.0]);
        let e = (ys[1][0] - reference[0]).abs().max((ys[1][1] - reference[1]).abs());
        eprintln!("van der Pol rtol {rtol:e}: error {e:.3e}, {st:?}");
        assert!(e < 0.1 * rtol && e < 0.1 * last, "rtol {rtol}: error {e:e}");
        // an explicit scheme needs h < ~1e-6 on the slow branches: 2e6 steps
        assert!(st.steps < 10_000, "{st:?}");
        assert!(st.jacobians < st.steps / 2, "the Jacobian is reused: {st:?}");
        last = e;
    }
}

#[test]
fn radau5_dense_output_meets_the_tolerance_between_steps() {
    // the stiff pair: outputs far denser than the steps, through the collocation polynomial
    let rtol = 1e-7;
    let y0 = [1.0, 3.0];
    let t_out: Vec<f64> = (0..=1000).map(|k| 5.0 * k as f64 / 1000.0).collect();
    let (ys, st) = run_sys(radau_adaptive(rtol, rtol), &mut StiffLinear, &y0, &t_out);
    assert!(st.steps < 200, "{st:?}");
    let worst = t_out
        .iter()
        .zip(&ys)
        .skip(1) // (the fast mode's layer, 1e-5 s, is inside the first step)
        .map(|(&t, y)| {
            let ex = StiffLinear::exact(t, &y0);
            ((y[0] - ex[0]).abs() / (rtol * ex[0].abs() + rtol)).max((y[1] - ex[1]).abs() / (rtol * ex[1].abs() + rtol))
        })
        .fold(0.0, f64::max);
    assert!(worst < 1.0, "dense output error {worst} × the tolerance");
    // the output grid does not change the steps
    let (_, coarse) = run_sys(radau_adaptive(rtol, rtol), &mut StiffLinear, &y0, &[0.0, 5.0]);
    assert_eq!(st.steps, coarse.steps);
    // a smooth oscillator through its interpolant
    let (t, y, st) = run(radau_adaptive(1e-9, 1e-12), 3.0, 10.0, 1000);
    assert!(max_err(&t, &y, 3.0) < 1e-8, "error {} ({st:?})", max_err(&t, &y, 3.0));
}

#[test]
fn radau5_adaptive_runs_long_spans_without_a_span_relative_step_floor() {
    // a fast transient at the start, then nothing: steps from ~1e-5 s (the transient followed to
    // rtol until it is below atol) to ~1e11 s; a step floor of 1e-14 × span = 1e-2 s would fail
    struct Decay;
    impl OdeSystem for Decay {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
            dy[0] = -1e3 * y[0];
            dy[1] = 1.0;
            Ok(())
        }
    }
    let (ys, st) = run_sys(radau_adaptive(1e-10, 1e-12), &mut Decay, &[1.0, 0.0], &[0.0, 1e-3, 1e12]);
    assert!(((ys[1][0] - (-1.0f64).exp()) / (-1.0f64).exp()).abs() < 1e-8, "{:?}", ys[1]);
    assert!(ys[2][0].abs() < 1e-12 && (ys[2][1] - 1e12).abs() < 1e-3, "{:?}", ys[2]);
    assert!(st.steps < 1500, "{st:?}");
}

#[test]
fn radau5_adaptive_reports_underflow_at_a_blow_up() {
    // y' = y², y(0) = 1: y = 1/(1 − t) leaves every bound at t = 1
    struct BlowUp;
    impl OdeSystem for BlowUp {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
            dy[0] = y[0] * y[0];
            Ok(())
        }
    }
    let mut obs = |_s: &mut BlowUp, _t: f64, _y: &[f64], _f: bool| -> Result<()> { Ok(()) };
    let e = integrate(&radau_adaptive(1e-6, 1e-9), &mut BlowUp, 0.0, &[1.0], &[0.0, 2.0], &mut obs).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("step size underflow at t = "), "{msg}");
    let t: f64 = msg["step size underflow at t = ".len()..].split(' ').next().unwrap().parse().unwrap();
    assert!((t - 1.0).abs() < 1e-3, "{msg}");
}

#[test]
fn radau5_rejects_bad_settings_naming_them() {
    let mut sys = Oscillator { omega: 1.0, evals: 0 };
    let mut obs = |_s: &mut Oscillator, _t: f64, _y: &[f64], _f: bool| -> Result<()> { Ok(()) };
    let radau = |dt: f64, rtol: f64, atol: f64| IntegratorKind::Radau5 {
        dt,
        newton_tol: 1e-10,
        rtol,
        atol,
        max_step: 0.0,
        first_step: 0.0,
    };
    for (kind, words) in [
        (radau(1e-3, 1e-6, 1e-9), &["dt", "rtol", "not both"][..]),
        (radau(0.0, 0.0, 1e-9), &["dt", "rtol", "one of"][..]),
        (radau(0.0, 1e-30, 1e-9), &["integrator.rtol", "[1e-14, 1)", "1e-30"][..]),
        (radau(0.0, -1e-6, 1e-9), &["integrator.rtol"][..]),
        (radau(0.0, 1e-6, -1.0), &["integrator.atol", "> 0"][..]),
        (radau(-1e-3, 0.0, 1e-9), &["integrator.dt", "> 0"][..]),
    ] {
        let e = integrate(&kind, &mut sys, 0.0, &[1.0, 0.0], &[0.0, 1.0], &mut obs).unwrap_err();
        assert!(matches!(e, crate::Error::Settings(_)), "{e}");
        for w in words {
            assert!(e.to_string().contains(w), "{e} lacks {w}");
        }
    }
}

#[test]
fn radau5_settings_read_from_json_keep_fixed_and_adaptive_apart() {
    let fixed: IntegratorKind = serde_json::from_str(r#"{"type": "radau5", "dt": 0.01}"#).unwrap();
    assert_eq!(fixed, radau_fixed(0.01, 1e-10));
    assert_eq!(fixed.fixed_step(), Some(0.01));
    let adaptive: IntegratorKind = serde_json::from_str(r#"{"type": "radau5", "rtol": 1e-6}"#).unwrap();
    assert_eq!(adaptive, radau_adaptive(1e-6, 1e-10));
    assert_eq!(adaptive.fixed_step(), None);
}

/// A kink at y0 = 0.3: ẏ0 = 1, ẏ1 = (y0 − 0.3)₊, whose solution y1 = (t − 0.3)²/2 after t = 0.3 is a
/// polynomial each scheme integrates exactly on either side: only a step across the kink errs.
struct Kink;

impl OdeSystem for Kink {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        dy[0] = 1.0;
        dy[1] = (y[0] - 0.3).max(0.0);
        Ok(())
    }
    fn switches(&self) -> usize {
        1
    }
    fn switching(&mut self, _t: f64, y: &[f64], out: &mut [f64]) -> Result<()> {
        out[0] = 0.3 - y[0];
        Ok(())
    }
}

#[test]
fn steps_end_at_switches() {
    let exact = 0.5 * 0.7f64 * 0.7;
    for kind in [
        IntegratorKind::Rk4 { dt: 0.25 },
        IntegratorKind::Dopri5 { rtol: 1e-6, atol: 1e-9, max_step: 0.0, first_step: 0.0 },
        IntegratorKind::Radau5 { dt: 0.0, newton_tol: 1e-10, rtol: 1e-6, atol: 1e-9, max_step: 0.0, first_step: 0.0 },
    ] {
        let mut end = [0.0; 2];
        let mut obs = |_s: &mut Kink, _t: f64, y: &[f64], _f: bool| -> Result<()> {
            end = [y[0], y[1]];
            Ok(())
        };
        integrate(&kind, &mut Kink, 0.0, &[0.0, 0.0], &[0.0, 1.0], &mut obs).unwrap();
        // the retaken step ends 1e-7 of a step past the kink: the last stage of that step sees
        // the sliver, an error of h² 1e-7 at most (a step across the kink errs by about h² / 10)
        assert!((end[1] - exact).abs() < 1e-9, "{kind:?}: {} against {exact}", end[1]);
    }
}
