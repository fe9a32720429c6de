//! Timings of the friction-contact solvers on piles of spheres.
//!
//! The problem is `solver::fixtures::sphere_pile(n, μ = 0.4, seed 1)`: one Moreau–Jean step of a
//! grid of sphere columns with random velocities, `W = J M⁻¹ Jᵀ` block-sparse (contacts couple
//! through shared spheres), spatial contacts (`d = 3`). Groups:
//! - `nsgs/blocks/N`, N = 100, 1000: nonsmooth Gauss–Seidel from zero, tol 1e-8, block-sparse `W`;
//! - `nsgs/dense/100`: the same with `W` stored densely (300 × 300);
//! - `nsgs_warm/blocks/N`: warm-started from the solution of the problem with `q` scaled by 0.99,
//!   as a time-stepping scheme restarts from the previous step's impulses;
//! - `newton/blocks/100`: semismooth Newton from zero, tol 1e-8 (dense Jacobian and LU; at
//!   1000 contacts one LU of 3000 × 3000 alone takes seconds, so that size is NSGS only).
//!
//! Before timing, each case prints its report (iterations, residual) once.
//! Run with `cargo bench -p mechsys-core --bench solver` (add `-- --quick` for a short run).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

use mechsys_core::solver::fixtures::{dense_copy, sphere_pile};
use mechsys_core::solver::{solve, FrictionContact, Method, NewtonOptions, NsgsOptions, Problem, Workspace};

const MU: f64 = 0.4;
const TOL: f64 = 1e-8;

fn nsgs() -> Method {
    Method::Nsgs(NsgsOptions { tol: TOL, max_iter: 100_000, ..Default::default() })
}

fn newton() -> Method {
    Method::Newton(NewtonOptions { tol: TOL, ..Default::default() })
}

/// Times `solve` from `start` (zeros for a cold start) and prints one report first.
fn bench_case(
    c: &mut Criterion,
    group: &str,
    label: &str,
    n: usize,
    p: &FrictionContact,
    method: Method,
    start: &[f64],
) {
    let mut ws = Workspace::for_problem(p, &method).expect("workspace");
    let mut r = start.to_vec();
    let warm = start.iter().any(|&v| v != 0.0);
    let rep = solve(p, &method, &mut r, warm, &mut ws).expect("solve");
    println!("{group}/{label}/{n}: {rep:?}");
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(n as u64));
    g.bench_with_input(BenchmarkId::new(label, n), &n, |b, _| {
        b.iter(|| {
            r.copy_from_slice(start);
            let rep = solve(p, &method, &mut r, warm, &mut ws).expect("solve");
            black_box((rep, &r));
        })
    });
    g.finish();
}

fn bench_solvers(c: &mut Criterion) {
    for n in [100, 1000] {
        let p = sphere_pile(n, MU, 1).expect("fixture");
        let zeros = vec![0.0; p.unknowns()];
        bench_case(c, "nsgs", "blocks", n, &p, nsgs(), &zeros);
        if n == 100 {
            bench_case(c, "nsgs", "dense", n, &dense_copy(&p), nsgs(), &zeros);
            bench_case(c, "newton", "blocks", n, &p, newton(), &zeros);
        }
        // the previous step: same pile, slightly different free velocities
        let mut prev = p.clone();
        prev.q.iter_mut().for_each(|v| *v *= 0.99);
        let mut start = zeros.clone();
        let mut ws = Workspace::for_problem(&prev, &nsgs()).expect("workspace");
        solve(&prev, &nsgs(), &mut start, false, &mut ws).expect("solve");
        bench_case(c, "nsgs_warm", "blocks", n, &p, nsgs(), &start);
    }
}

criterion_group!(benches, bench_solvers);
criterion_main!(benches);
