//! Timings and accuracy of the linearization (issue 5): exact derivatives (forward-mode dual
//! numbers through a generic RNEA, `Derivatives::Exact`) against central differences of the
//! forward dynamics (`Derivatives::CentralDifferences`), on the spatial revolute chain of
//! `fixtures::chain(N, "revolute")` (uniform rods, 1 kg, 0.5 m; axes alternating z, y, x; gravity
//! −z) in its initial configuration, moving, so every matrix is populated. N = 10 and 200 DOF.
//!
//! Before timing, the accuracy is printed: the largest difference of each of K, D (+G) between
//! the two methods relative to that matrix's largest entry; the exact path's own error is at
//! round-off, so this is the error of the differences.
//!
//! Run with `cargo bench -p mechsys-core --bench linear` (or `-- --quick` for a short run).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

use mechsys_core::fixtures::chain;
use mechsys_core::forces::NoCallbacks;
use mechsys_core::linear::{linearize_with, Derivatives, Linearization};
use mechsys_core::model::Model;

/// Degrees of freedom of the chains.
const SIZES: [usize; 2] = [10, 200];

fn state(model: &Model) -> (Vec<f64>, Vec<f64>) {
    let q = model.q0();
    let u = (0..model.nu).map(|k| 0.3 - 0.01 * (k % 17) as f64).collect();
    (q, u)
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / max_abs(b)
}

fn report(n: usize, ex: &Linearization, fd: &Linearization) {
    let c_ex: Vec<f64> = ex.d.iter().zip(&ex.g).map(|(d, g)| d + g).collect();
    let c_fd: Vec<f64> = fd.d.iter().zip(&fd.g).map(|(d, g)| d + g).collect();
    let s_ex: Vec<f64> = ex.k.iter().zip(&ex.n_mat).map(|(k, n)| k + n).collect();
    let s_fd: Vec<f64> = fd.k.iter().zip(&fd.n_mat).map(|(k, n)| k + n).collect();
    println!(
        "linearize chain {n} DOF: exact vs central differences, max relative difference K {:.2e}, K + N {:.2e}, D + G {:.2e}",
        rel_diff(&fd.k, &ex.k),
        rel_diff(&s_fd, &s_ex),
        rel_diff(&c_fd, &c_ex)
    );
}

fn bench_linearize(c: &mut Criterion) {
    let cb = NoCallbacks;
    let mut g = c.benchmark_group("linearize");
    g.sample_size(10).measurement_time(Duration::from_secs(5)).warm_up_time(Duration::from_secs(1));
    for &n in &SIZES {
        let model = chain(n, "revolute");
        let (q, u) = state(&model);
        let ex = linearize_with(&model, 0.0, &q, &u, &cb, Derivatives::Exact).expect("exact linearization");
        let fd = linearize_with(&model, 0.0, &q, &u, &cb, Derivatives::CentralDifferences).expect("fd linearization");
        report(n, &ex, &fd);
        for (name, how) in [("exact", Derivatives::Exact), ("fd", Derivatives::CentralDifferences)] {
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| black_box(linearize_with(&model, 0.0, black_box(&q), &u, &cb, how).expect("linearization")))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench_linearize);
criterion_main!(benches);
