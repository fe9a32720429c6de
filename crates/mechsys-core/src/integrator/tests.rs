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
    let (t, y, _) = run(IntegratorKind::Radau5 { dt: 0.05, newton_tol: 1e-12 }, 2.0, 5.0, 100);
    assert!(max_err(&t, &y, 2.0) < 1e-6, "error {}", max_err(&t, &y, 2.0));
    // stiff: ω dt = 100, an explicit scheme explodes, Radau IIA damps (L-stable) and stays bounded
    let (_, y, _) = run(IntegratorKind::Radau5 { dt: 0.1, newton_tol: 1e-10 }, 1000.0, 2.0, 20);
    assert!(y.iter().all(|v| v[0].abs() <= 1.0 + 1e-9));
    assert!(y.last().unwrap()[0].abs() < 1e-3);
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
