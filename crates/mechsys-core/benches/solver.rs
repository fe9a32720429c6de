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
//! - `block_lu/grid3d/N`, N = 125, 1000: [`BlockLu`] on the `k × k × k` grid graph of 6 × 6
//!   blocks (each block row coupled to its up to six neighbours, like the bodies of a settled pile
//!   of spheres): `analyze` (minimum-degree ordering and fill), `factor` and `solve`.
//!
//! Before timing, each case prints its report (iterations, residual) once.
//! Run with `cargo bench -p mechsys-core --bench solver` (add `-- --quick` for a short run).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

use mechsys_core::math::block_sparse::BlockLu;
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

/// The pairs of the `k × k × k` grid graph.
fn grid3d(k: usize) -> Vec<(usize, usize)> {
    let id = |x: usize, y: usize, z: usize| (x * k + y) * k + z;
    let mut pairs = vec![];
    for x in 0..k {
        for y in 0..k {
            for z in 0..k {
                if x + 1 < k {
                    pairs.push((id(x, y, z), id(x + 1, y, z)));
                }
                if y + 1 < k {
                    pairs.push((id(x, y, z), id(x, y + 1, z)));
                }
                if z + 1 < k {
                    pairs.push((id(x, y, z), id(x, y, z + 1)));
                }
            }
        }
    }
    pairs
}

fn bench_block_lu(c: &mut Criterion) {
    let mut g = c.benchmark_group("block_lu");
    for k in [5usize, 10] {
        let (n, pairs) = (k * k * k, grid3d(k));
        let mut lu = BlockLu::<6>::default();
        let load = |lu: &mut BlockLu<6>| {
            lu.zero();
            let mut d = [0.0; 36];
            for r in 0..6 {
                d[r * 7] = 10.0;
            }
            for i in 0..n {
                lu.add(i, i, &d);
            }
            for &(i, j) in &pairs {
                lu.add(i, j, &[0.1; 36]);
                lu.add(j, i, &[-0.1; 36]);
            }
        };
        lu.analyze(n, &pairs);
        println!(
            "block_lu/grid3d/{n}: {} filled blocks, {:.2e} multiply-adds per factorization",
            lu.filled(),
            lu.factor_cost() as f64
        );
        g.bench_with_input(BenchmarkId::new("analyze", n), &n, |b, _| b.iter(|| lu.analyze(n, black_box(&pairs))));
        g.bench_with_input(BenchmarkId::new("factor", n), &n, |b, _| {
            b.iter(|| {
                load(&mut lu);
                lu.factor().expect("nonsingular")
            })
        });
        load(&mut lu);
        lu.factor().expect("nonsingular");
        let (mut x, mut w) = (vec![1.0; 6 * n], vec![0.0; 6 * n]);
        g.bench_with_input(BenchmarkId::new("solve", n), &n, |b, _| b.iter(|| lu.solve(black_box(&mut x), &mut w)));
    }
    g.finish();
}

criterion_group!(benches, bench_solvers, bench_block_lu);
criterion_main!(benches);
