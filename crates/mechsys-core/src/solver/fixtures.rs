//! Problem generators shared by the solver tests and benchmarks: Delassus matrices of real
//! mechanisms (`W = J M⁻¹ Jᵀ`) rather than arbitrary matrices, so that the problems have the
//! structure and conditioning the integrators will produce.
//!
//! - [`random_friction_contact`]: dense `J` with random entries and a random SPD mass matrix;
//! - [`disk_stack`]: a planar stack of disks resting on the ground, pushed sideways;
//! - [`sphere_pile`]: a pile of spheres on a square grid (columns, plus contacts between
//!   neighbours in every other layer), block-sparse `W`.

use super::problem::{BlockDelassusBuilder, Delassus, FrictionContact};
use crate::error::Result;

/// Small deterministic generator (SplitMix64), so that fixtures need no extra dependency.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// `W = J M⁻¹ Jᵀ` for `n` contacts of dimension `dim` with a random dense `J` (`d n × ndof`,
/// `ndof = 2 d n`) and `M = L Lᵀ` (random lower-triangular `L` with diagonal in [1, 2]); `q` has
/// normal components in [−1, 0.5] and tangential ones in [−1, 1]; `μ` is the same for all.
pub fn random_friction_contact(dim: usize, n: usize, mu: f64, seed: u64) -> Result<FrictionContact> {
    let mut rng = Rng::new(seed);
    let m = dim * n;
    let ndof = 2 * m;
    let mut l = vec![0.0; ndof * ndof];
    for i in 0..ndof {
        for j in 0..i {
            l[i * ndof + j] = rng.uniform(-0.3, 0.3);
        }
        l[i * ndof + i] = rng.uniform(1.0, 2.0);
    }
    // G = L⁻¹ Jᵀ column by column (forward substitution), then W = Gᵀ G
    let mut g = vec![0.0; ndof * m];
    for c in 0..m {
        let jrow: Vec<f64> = (0..ndof).map(|_| rng.uniform(-1.0, 1.0)).collect();
        for i in 0..ndof {
            let s: f64 = (0..i).map(|k| l[i * ndof + k] * g[k * m + c]).sum();
            g[i * m + c] = (jrow[i] - s) / l[i * ndof + i];
        }
    }
    let mut w = vec![0.0; m * m];
    for a in 0..m {
        for b in 0..m {
            w[a * m + b] = (0..ndof).map(|k| g[k * m + a] * g[k * m + b]).sum();
        }
    }
    let q = (0..m).map(|k| if k % dim == 0 { rng.uniform(-1.0, 0.5) } else { rng.uniform(-1.0, 1.0) }).collect();
    FrictionContact::new(dim, Delassus::Dense(w), q, vec![mu; n])
}

/// A planar stack of `n` disks (radius 0.1 m, masses 1–2 kg, `I = m R²/2`) on the ground, each
/// resting on the one below with its contact normal tilted by up to ±0.3 rad; one Moreau–Jean
/// step of 10 ms under gravity with a sideways push on the top disk of `push` m/s and a spin of
/// the bottom one. Contacts: ground–disk 0, then disk k–disk k+1; `d = 2`, dense `W`.
pub fn disk_stack(n: usize, mu: f64, push: f64, seed: u64) -> Result<FrictionContact> {
    let mut rng = Rng::new(seed);
    let radius = 0.1;
    let mass: Vec<f64> = (0..n).map(|_| rng.uniform(1.0, 2.0)).collect();
    let inertia: Vec<f64> = mass.iter().map(|m| 0.5 * m * radius * radius).collect();
    // centers, going up along the tilted normals
    let mut normal = vec![[0.0, 1.0]; n];
    let mut center = vec![[0.0, radius]; n];
    for k in 1..n {
        let phi: f64 = rng.uniform(-0.3, 0.3);
        normal[k] = [phi.sin(), phi.cos()];
        center[k] = [center[k - 1][0] + 2.0 * radius * normal[k][0], center[k - 1][1] + 2.0 * radius * normal[k][1]];
    }
    // free velocities: gravity impulse on all, push on the top, spin on the bottom
    let dt = 0.01;
    let mut v = vec![[0.0, -9.81 * dt, 0.0]; n];
    v[n - 1][0] += push;
    v[0][2] += 2.0;
    let ndof = 3 * n;
    let m = 2 * n;
    let mut jac = vec![0.0; m * ndof];
    for k in 0..n {
        // contact k: between body k−1 (or ground) below and body k above, normal[k] upward
        let nv = normal[k];
        let t = [nv[1], -nv[0]];
        let point = [center[k][0] - radius * nv[0], center[k][1] - radius * nv[1]];
        for (a, e) in [nv, t].into_iter().enumerate() {
            let row = (2 * k + a) * ndof;
            let cross = |c: [f64; 2]| (point[0] - c[0]) * e[1] - (point[1] - c[1]) * e[0];
            jac[row + 3 * k] = e[0];
            jac[row + 3 * k + 1] = e[1];
            jac[row + 3 * k + 2] = cross(center[k]);
            if k > 0 {
                jac[row + 3 * (k - 1)] = -e[0];
                jac[row + 3 * (k - 1) + 1] = -e[1];
                jac[row + 3 * (k - 1) + 2] = -cross(center[k - 1]);
            }
        }
    }
    let minv: Vec<f64> = (0..ndof).map(|c| if c % 3 == 2 { 1.0 / inertia[c / 3] } else { 1.0 / mass[c / 3] }).collect();
    let mut w = vec![0.0; m * m];
    for a in 0..m {
        for b in 0..m {
            w[a * m + b] = (0..ndof).map(|c| jac[a * ndof + c] * minv[c] * jac[b * ndof + c]).sum();
        }
    }
    let q = (0..m).map(|a| (0..ndof).map(|c| jac[a * ndof + c] * v[c / 3][c % 3]).sum()).collect();
    FrictionContact::new(2, Delassus::Dense(w), q, vec![mu; n])
}

/// A pile of spheres (radius 0.05 m, masses 0.5–1.5 kg, `I = 2 m R²/5`) with about
/// `n_contacts` contacts: a `g × g` grid of columns (`g ≈ √n / 2`) built layer by layer, each
/// sphere resting on the one below (or the ground), and in even layers touching its left
/// neighbour; contact normals tilted randomly by up to 0.15 rad. One 10 ms step under gravity
/// with random velocities up to 0.2 m/s and 2 rad/s. The list is cut at exactly `n_contacts`.
/// `d = 3`, block-sparse `W`: contacts couple when they share a sphere.
pub fn sphere_pile(n_contacts: usize, mu: f64, seed: u64) -> Result<FrictionContact> {
    let mut rng = Rng::new(seed);
    let radius = 0.05;
    let g = ((n_contacts as f64).sqrt() / 2.0).ceil().max(2.0) as usize;
    // contacts as (body below/left or None for ground, body above/right, normal)
    let mut contacts: Vec<(Option<usize>, usize, [f64; 3])> = Vec::with_capacity(n_contacts);
    let tilted = |rng: &mut Rng, axis: usize| {
        let mut nv = [rng.uniform(-0.15, 0.15), rng.uniform(-0.15, 0.15), rng.uniform(-0.15, 0.15)];
        nv[axis] = 1.0;
        let l = (nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]).sqrt();
        [nv[0] / l, nv[1] / l, nv[2] / l]
    };
    let mut bodies = 0;
    'fill: for layer in 0.. {
        for _ in 0..g {
            for col in 0..g {
                let s = bodies;
                bodies += 1;
                let below = if layer == 0 { None } else { Some(s - g * g) };
                contacts.push((below, s, tilted(&mut rng, 2)));
                if contacts.len() == n_contacts {
                    break 'fill;
                }
                if layer % 2 == 0 && col > 0 {
                    contacts.push((Some(s - 1), s, tilted(&mut rng, 0)));
                    if contacts.len() == n_contacts {
                        break 'fill;
                    }
                }
            }
        }
    }
    let mass: Vec<f64> = (0..bodies).map(|_| rng.uniform(0.5, 1.5)).collect();
    let vel: Vec<[f64; 6]> = (0..bodies)
        .map(|_| {
            let mut v = [0.0; 6];
            for (k, x) in v.iter_mut().enumerate() {
                *x = if k < 3 { rng.uniform(-0.2, 0.2) } else { rng.uniform(-2.0, 2.0) };
            }
            v[2] -= 9.81 * 0.01;
            v
        })
        .collect();
    // per contact and body: 3×6 Jacobian block (rows n, t1, t2), see the module docs
    let mut at_body: Vec<Vec<(usize, [f64; 18])>> = vec![Vec::new(); bodies];
    let mut q = vec![0.0; 3 * contacts.len()];
    for (i, &(lower, upper, nv)) in contacts.iter().enumerate() {
        let helper = if nv[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let t1 = unit(cross(nv, helper));
        let t2 = cross(nv, t1);
        // u_e = e·(v_B − v_A) − R ω_B·(n × e) − R ω_A·(n × e): contact point at ±R n from the centers
        for (body, sign) in [(Some(upper), 1.0), (lower, -1.0)] {
            let Some(b) = body else { continue };
            let mut blk = [0.0; 18];
            for (a, e) in [nv, t1, t2].into_iter().enumerate() {
                let ne = cross(nv, e);
                for k in 0..3 {
                    blk[a * 6 + k] = sign * e[k];
                    blk[a * 6 + 3 + k] = -radius * ne[k];
                }
                q[3 * i + a] += (0..6).map(|k| blk[a * 6 + k] * vel[b][k]).sum::<f64>();
            }
            at_body[b].push((i, blk));
        }
    }
    let mut builder = BlockDelassusBuilder::new(3, contacts.len())?;
    for (b, list) in at_body.iter().enumerate() {
        let inertia = 0.4 * mass[b] * radius * radius;
        let minv = [1.0 / mass[b], 1.0 / mass[b], 1.0 / mass[b], 1.0 / inertia, 1.0 / inertia, 1.0 / inertia];
        for (x, &(i, ji)) in list.iter().enumerate() {
            for &(j, jj) in &list[x..] {
                let mut blk = [0.0; 9];
                for a in 0..3 {
                    for c in 0..3 {
                        blk[a * 3 + c] = (0..6).map(|k| ji[a * 6 + k] * minv[k] * jj[c * 6 + k]).sum();
                    }
                }
                builder.add(i, j, &blk)?;
            }
        }
    }
    FrictionContact::new(3, Delassus::Blocks(builder.build()), q, vec![mu; contacts.len()])
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

/// The same problem with `W` stored densely.
pub fn dense_copy(p: &FrictionContact) -> FrictionContact {
    let w = match &p.w {
        Delassus::Dense(w) => w.clone(),
        Delassus::Blocks(b) => b.to_dense(),
    };
    FrictionContact { dim: p.dim, w: Delassus::Dense(w), q: p.q.clone(), mu: p.mu.clone() }
}
