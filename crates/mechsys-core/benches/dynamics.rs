//! Timings of the dynamics algorithms and of whole simulations on the fixture chains.
//!
//! Groups, each over the spatial revolute chain of `fixtures::chain(n, "revolute")` (uniform rods,
//! 1 kg, 0.5 m; axes alternating z, y, x; gravity -z), in the chain's initial state `q0` with
//! nonzero velocities so that the velocity-product terms are exercised:
//! - `crba/N`: `M(q)` (positions + inertias + CRBA), N = 1, 4, 16, 64, 256;
//! - `rnea/N`: `τ = M u̇ - h` (kinematics + forces + RNEA);
//! - `aba/N`: `u̇ = M⁻¹ h` (kinematics + forces + ABA), what every integrator stage calls;
//! - `step_rk4/N`: one classical RK4 step of the `MultibodySystem` (4 right-hand sides, the
//!   update and the projection), N = 1, 16, 64;
//! - `simulate_1s/N`: `simulate::simulate` for 1 s at dt = 1e-3 with RK4 and a sample recorded at
//!   every step (1001 samples), as `mechsys.simulate(model, 1.0, integrator=RK4(1e-3))` does.
//!
//! Run with `cargo bench -p mechsys-core --bench dynamics` (a few minutes); filter with e.g.
//! `cargo bench -p mechsys-core --bench dynamics -- aba/`. The Python-level comparison with
//! Pinocchio, MuJoCo and Exudyn is `benches/peers.py` (see `docs/benchmarks.md`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

use mechsys_core::data::Data;
use mechsys_core::dynamics::{aba, crba::mass_matrix, rnea, Workspace};
use mechsys_core::fixtures::chain;
use mechsys_core::forces::NoCallbacks;
use mechsys_core::integrator::{IntegratorKind, OdeSystem};
use mechsys_core::model::Model;
use mechsys_core::simulate::{simulate, MultibodySystem, Settings};

/// Chain sizes of the per-call algorithms.
const SIZES: [usize; 5] = [1, 4, 16, 64, 256];
/// Chain sizes of the stepping benchmarks.
const STEP_SIZES: [usize; 3] = [1, 16, 64];

/// A state of the chain: its initial coordinates and a fixed, nonzero velocity pattern.
fn state(model: &Model) -> (Vec<f64>, Vec<f64>) {
    let q = model.q0();
    let u = (0..model.nu).map(|k| 0.3 - 0.01 * (k % 17) as f64).collect();
    (q, u)
}

fn bench_algorithms(c: &mut Criterion) {
    let cb = NoCallbacks;

    let mut g = c.benchmark_group("crba");
    for &n in &SIZES {
        let model = chain(n, "revolute");
        let mut data = Data::new(&model);
        let (q, _) = state(&model);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                mass_matrix(&model, &mut data, 0.0, black_box(&q));
                black_box(&data.mass_matrix);
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("rnea");
    for &n in &SIZES {
        let model = chain(n, "revolute");
        let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
        let (q, u) = state(&model);
        let udot: Vec<f64> = (0..model.nu).map(|k| 1.0 - 0.1 * (k % 7) as f64).collect();
        let mut tau = vec![0.0; model.nu];
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                rnea(&model, &mut data, &mut ws, 0.0, black_box(&q), black_box(&u), black_box(&udot), &cb, &mut tau)
                    .expect("rnea");
                black_box(&tau);
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("aba");
    for &n in &SIZES {
        let model = chain(n, "revolute");
        let (mut data, mut ws) = (Data::new(&model), Workspace::new(&model));
        let (q, u) = state(&model);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                aba(&model, &mut data, &mut ws, 0.0, black_box(&q), black_box(&u), None, &cb).expect("aba");
                black_box(&data.udot);
            })
        });
    }
    g.finish();
}

/// One classical RK4 step of `sys` from (t, y) with step h, as `integrator::rk4` takes it:
/// four right-hand sides, the weighted update and the projection onto the manifold.
#[allow(clippy::too_many_arguments)]
fn rk4_step<S: OdeSystem>(sys: &mut S, t: f64, h: f64, y: &mut [f64], k: &mut [Vec<f64>; 4], tmp: &mut [f64]) {
    let n = y.len();
    let [k1, k2, k3, k4] = k;
    sys.rhs(t, y, k1).expect("rhs");
    for i in 0..n {
        tmp[i] = y[i] + 0.5 * h * k1[i];
    }
    sys.rhs(t + 0.5 * h, tmp, k2).expect("rhs");
    for i in 0..n {
        tmp[i] = y[i] + 0.5 * h * k2[i];
    }
    sys.rhs(t + 0.5 * h, tmp, k3).expect("rhs");
    for i in 0..n {
        tmp[i] = y[i] + h * k3[i];
    }
    sys.rhs(t + h, tmp, k4).expect("rhs");
    for i in 0..n {
        y[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
    }
    sys.project(t + h, y).expect("project");
}

fn bench_stepping(c: &mut Criterion) {
    let cb = NoCallbacks;
    let dt = 1e-3;

    let mut g = c.benchmark_group("step_rk4");
    for &n in &STEP_SIZES {
        let model = chain(n, "revolute");
        let mut sys = MultibodySystem::new(&model, &cb);
        let dim = sys.dim();
        let mut y0 = vec![0.0; dim];
        y0[..model.nq].copy_from_slice(&model.q0());
        let mut k = [vec![0.0; dim], vec![0.0; dim], vec![0.0; dim], vec![0.0; dim]];
        let mut tmp = vec![0.0; dim];
        let mut y = y0.clone();
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                // always step from the same state, so every iteration does identical work
                y.copy_from_slice(&y0);
                rk4_step(&mut sys, 0.0, dt, black_box(&mut y), &mut k, &mut tmp);
                black_box(&y);
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("simulate_1s");
    // each iteration is milliseconds to a second: fewer samples, longer window
    g.sample_size(10).measurement_time(Duration::from_secs(8)).warm_up_time(Duration::from_secs(1));
    for &n in &STEP_SIZES {
        let model = chain(n, "revolute");
        let settings = Settings {
            t0: 0.0,
            t_end: 1.0,
            output_dt: dt,
            integrator: IntegratorKind::Rk4 { dt },
            q0: None,
            u0: None,
            stabilization: Default::default(),
            on_singular: Default::default(),
            max_steps: None,
            max_wall: None,
            record: Default::default(),
            warm_search: true,
        };
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                let rec = simulate(&model, black_box(&settings), &cb, None).expect("simulate");
                assert_eq!(rec.n_out, 1001);
                black_box(rec)
            })
        });
    }
    g.finish();
}

fn config() -> Criterion {
    // small samples: the whole file runs in a few minutes on a shared 2-core machine
    Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .noise_threshold(0.05)
}

criterion_group! {
    name = benches;
    config = config();
    targets = bench_algorithms, bench_stepping
}
criterion_main!(benches);
