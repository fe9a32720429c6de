//! Many simulations at once: copies of one model from different initial states, or variants of
//! a model (parameter sets), run side by side on a pool of threads, the way a Monte Carlo study
//! or a policy rollout needs them.
//!
//! Each case is an ordinary [`simulate`] run (its workspace made once at its start, none in its
//! step loop), so a case's result is bit for bit that of the same run made alone, whatever the
//! number of threads or the order the pool picks the cases in. The cases are independent; a
//! failing case gives its own error and leaves the others alone.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::forces::NoCallbacks;
use crate::model::Model;
use crate::simulate::{simulate, Progress, Recording, Settings};

/// The number of threads a batch uses when none is given: the machine's cores.
pub fn default_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Runs every case `(model, settings)` on `threads` threads (0: all cores); the results come back
/// in the cases' order, each its own `Ok(recording)` or `Err` (whose message names the case).
/// The models must need no user callbacks (those run in the Python interpreter, one at a time).
/// `progress`, shared by all cases, cancels them: each stops at its next sample with the samples
/// so far (its recording marked cancelled), the cases not yet begun at their first.
pub fn simulate_batch(
    cases: &[(&Model, Settings)],
    threads: usize,
    progress: Option<&Progress>,
) -> Result<Vec<Result<Recording>>> {
    let threads = if threads == 0 { default_threads() } else { threads };
    // every case's results are held at once: their sum against the memory budget (each run
    // checks only its own; a case with settings that give no count fails on its own)
    let bytes: f64 = cases
        .iter()
        .map(|(m, s)| crate::simulate::sample_size(m, s))
        .map(|(n, w)| 8.0 * n * w)
        .filter(|b| b.is_finite() && *b > 0.0)
        .sum();
    let budget = crate::resources::memory_budget();
    crate::ensure!(
        bytes < budget,
        Settings,
        "simulate_batch: {} cases would record about {bytes:.3e} bytes of results, more than the {budget:.3e} bytes \
         this batch may use (half the memory available); run fewer cases at once, a larger output_dt, or sensors= \
         to record less",
        cases.len()
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("mechsys-batch-{i}"))
        .build()
        .map_err(|e| Error::Settings(format!("threads: cannot start {threads} threads ({e})")))?;
    let run = |(i, (model, settings)): (usize, &(&Model, Settings))| {
        simulate(model, settings, &NoCallbacks, progress).map_err(|e| name_case(i, e))
    };
    // one case per task: cases differ in cost (stiff or contact-rich ones), so the pool balances
    Ok(pool.install(|| cases.par_iter().enumerate().with_max_len(1).map(run).collect()))
}

/// The error of case `i`, its message prefixed by the case.
fn name_case(i: usize, e: Error) -> Error {
    let prefix = |m: String| format!("case {i}: {m}");
    match e {
        Error::Model(m) => Error::Model(prefix(m)),
        Error::Description { path, message } => Error::Description { path: prefix(path), message },
        Error::Settings(m) => Error::Settings(prefix(m)),
        Error::Singular(m) => Error::Singular(prefix(m)),
        Error::Solver(m) => Error::Solver(prefix(m)),
        Error::Painleve(m) => Error::Painleve(prefix(m)),
        Error::Callback(m) => Error::Callback(prefix(m)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::IntegratorKind;

    fn settings(q: f64) -> Settings {
        let mut s: Settings =
            serde_json::from_str(r#"{"t_end": 0.5, "output_dt": 0.01, "integrator": {"type": "rk4", "dt": 0.001}}"#)
                .unwrap();
        let model = crate::fixtures::chain(4, "revolute");
        let mut q0 = model.q0();
        q0[0] = q;
        s.q0 = Some(q0);
        s
    }

    #[test]
    fn batch_equals_serial_runs_bit_for_bit_at_any_thread_count() {
        let model = crate::fixtures::chain(4, "revolute");
        let cases: Vec<(&Model, Settings)> = (0..12).map(|k| (&model, settings(0.1 * k as f64))).collect();
        let serial: Vec<Recording> = cases.iter().map(|(m, s)| simulate(m, s, &NoCallbacks, None).unwrap()).collect();
        for threads in [1, 2, 3] {
            let batch = simulate_batch(&cases, threads, None).unwrap();
            for (k, (b, s)) in batch.iter().zip(&serial).enumerate() {
                let b = b.as_ref().unwrap();
                assert_eq!(b.q, s.q, "case {k}, {threads} threads: q");
                assert_eq!(b.u, s.u, "case {k}, {threads} threads: u");
                assert_eq!(b.kinetic, s.kinetic, "case {k}, {threads} threads");
            }
        }
        // and the cases differ (the test would pass on identical cases otherwise)
        assert_ne!(serial[1].q, serial[2].q);
    }

    #[test]
    fn a_batch_too_large_for_memory_is_refused_before_it_runs() {
        let model = crate::fixtures::chain(2, "revolute");
        let mut s = settings(0.0);
        s.q0 = None;
        // each case alone fits (0.4 of the budget), four together do not
        let (_, width) = crate::simulate::sample_size(&model, &s);
        s.output_dt = 1e-3;
        s.t_end = 0.4 * crate::resources::memory_budget() / (8.0 * width) * s.output_dt;
        s.integrator = IntegratorKind::Rk4 { dt: 1e-3 };
        let cases: Vec<(&Model, Settings)> = (0..4).map(|_| (&model, s.clone())).collect();
        let err = simulate_batch(&cases, 1, None).unwrap_err().to_string();
        assert!(err.contains("4 cases") && err.contains("bytes"), "{err}");
    }

    #[test]
    fn a_cancelled_batch_returns_what_each_case_had() {
        let model = crate::fixtures::chain(4, "revolute");
        let cases: Vec<(&Model, Settings)> = (0..3).map(|k| (&model, settings(0.1 * k as f64))).collect();
        let p = Progress::default();
        p.cancel.store(true, std::sync::atomic::Ordering::Relaxed);
        for r in simulate_batch(&cases, 2, Some(&p)).unwrap() {
            let r = r.unwrap();
            assert!(r.cancelled.is_some() && r.t.len() <= 1, "{:?}", r.cancelled);
        }
    }

    #[test]
    fn a_failing_case_names_itself_and_leaves_the_others() {
        let model = crate::fixtures::chain(2, "revolute");
        let mut bad = settings(0.0);
        bad.q0 = Some(vec![0.0; 2]);
        bad.integrator = IntegratorKind::Rk4 { dt: -1.0 };
        let good = {
            let mut s = settings(0.0);
            s.q0 = None;
            s
        };
        let cases = vec![(&model, good.clone()), (&model, bad), (&model, good)];
        let out = simulate_batch(&cases, 2, None).unwrap();
        assert!(out[0].is_ok() && out[2].is_ok());
        let msg = out[1].as_ref().unwrap_err().to_string();
        assert!(msg.contains("case 1") && msg.contains("dt"), "{msg}");
    }
}
