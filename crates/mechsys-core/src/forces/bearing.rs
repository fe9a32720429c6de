//! Hydrodynamic journal bearings: the film forces of the short-bearing (Ocvirk) and long-bearing
//! (Sommerfeld) solutions of the Reynolds equation over a π-film, the friction torque of eq. 2.212,
//! the static operating point under a constant load, and the eight stiffness and damping
//! coefficients.
//!
//! # Geometry and conventions
//!
//! The shell frame S has its origin at the bearing centre and z along the bearing axis; the journal
//! frame's origin is on the journal axis. `e` is the journal centre's offset from the shell centre
//! in the S x-y plane, `ė` its rate seen in S, `ε = |e|/c` (c the radial clearance), `φ` the angle
//! of `e` from the S x axis, `ω_rel` the journal's spin relative to the shell about S z. The polar
//! axes of the offset are `e_r = e/|e|` and `e_t = z × e_r` (towards growing φ). The film
//! thickness is `h = c(1 + ε cos θ)` with θ measured from the widest gap (the direction −e_r),
//! positive along φ. Forces are those of the film on the journal; the shell carries the opposite
//! force and torque, applied at the same point (the journal centre), so momentum is conserved.
//!
//! # Film forces
//!
//! With the journal moving, the Reynolds equation (x = Rθ) reads
//! `∂x(h³ ∂x p) + ∂z(h³ ∂z p) = 6 η ω R ∂x h + 12 η ∂t h`, and `∂t h = c ε̇ cos θ + c ε φ̇ sin θ`
//! folds the whirl into the effective speed `ω* = ω_rel − 2 φ̇`:
//! the right-hand side is `6 η c (2 ε̇ cos θ − ω* ε sin θ)` per unit `h³`. Over the π-film
//! θ ∈ [0, π] (ambient pressure elsewhere: the half-Sommerfeld cut, fixed to the line of centres)
//! the forces are `F_r = R ∫ P cos θ dθ`, `F_t = R ∫ P sin θ dθ` with P the pressure integrated
//! over the length, and with `q = 1 − ε²`:
//!
//! - short bearing (`∂x` flow neglected, p = 0 at z = ±L/2):
//!   `P(θ) = η L³/(2c²) · (ω* ε sin θ − 2 ε̇ cos θ)/(1 + ε cos θ)³`,
//!   `F_r = −η R L³/c² · [ω* ε²/q² + π ε̇ (1 + 2ε²)/(2 q^{5/2})]`,
//!   `F_t = η R L³/c² · [π ω* ε/(4 q^{3/2}) + 2 ε ε̇/q²]`;
//! - long bearing (`∂z` flow neglected, p = 0 at both ends θ = 0, π of the film):
//!   `p'(θ) = 6 η R²/c² · (ε ω* cos θ + 2 ε̇ sin θ + K)/(1 + ε cos θ)³` with
//!   `K = 3 ε² ω*/(2 + ε²) − 8 ε̇ √q/(π (2 + ε²))`, which integrates to
//!   `F_r = −6 η R³ L/c² · [2 ε² ω*/((2 + ε²) q) + ε̇ (π − 16/(π (2 + ε²)))/q^{3/2}]`,
//!   `F_t = 6 η R³ L/c² · [π ε ω*/((2 + ε²) √q) + 4 ε ε̇/((2 + ε²) q)]`
//!   (steady part: Sommerfeld's half-film result).
//!
//! Both hold for a spin ω_rel ≥ 0. A negative spin is the mirror image (the converging half of the
//! gap is then the other one): with `s = sgn ω_rel`, `F_r` has `s ω*` in place of ω* and the
//! squeeze term of `F_t` takes the factor s. The film's half is fixed by the spin, not by the sign
//! of ω*: in a half-frequency whirl ω* passes through zero and the formulas continue linearly, so
//! the force stays smooth along the orbit (a half chosen by the sign of ω* would jump there, and
//! an adaptive integrator would chatter on the jump). F_t points along the rotation and F_r towards
//! the shell centre for a steady journal.
//!
//! The viscous friction torque on the journal is eq. 2.212 with the wall speed `R ω_rel`:
//! `M = −2(1 + 2ε²)/(√q (1 + ε²/2)) · π R³ L η/c · ω_rel` (Petroff's law at ε = 0).
//!
//! # Steady operation
//!
//! At constant speed ω and load W the journal sits where the film force balances the load:
//! `W(ε) = |F(ε, 0, ω)|`, short `W = η ω R L³/(4c²) · ε √(16ε² + π² q)/q²`, long
//! `W = 6 η ω R³ L/c² · ε √(4ε² + π² q)/((2 + ε²) q)`, at the attitude angle ψ between the load
//! line and the line of centres, `tan ψ = −F_t/F_r` (short: `π √q/(4ε)`). The eight coefficients
//! `K_ij = −∂F_i/∂x_j`, `C_ij = −∂F_i/∂ẋ_j` there are exact derivatives (dual numbers) of the same
//! force law the simulation uses.

use num_dual::{Dual64, DualNum};

use crate::error::{Error, Result};
use crate::model::bearing::{BearingLaw, BearingTheory};

/// Film forces along the polar axes of the offset and the friction torque, all on the journal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmLoad<T> {
    /// Radial force F_r along e_r (N); negative pushes the journal back to the centre.
    pub f_r: T,
    /// Tangential force F_t along e_t (N); along the rotation for a steady journal.
    pub f_t: T,
    /// Friction torque about the shell axis (N m), opposing ω_rel.
    pub torque: T,
}

/// The film's forces on the journal in shell-frame components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellLoad<T> {
    /// Force on the journal, shell x and y (N).
    pub force: [T; 2],
    /// Friction torque on the journal about the shell z axis (N m).
    pub torque: T,
    /// Relative eccentricity ε.
    pub eps: T,
    /// Radial film force F_r (N).
    pub f_r: T,
    /// Tangential film force F_t (N).
    pub f_t: T,
}

/// The shape factors of a theory at ε: `F_r = −k (rr s ω* ε² + rs ε̇)`,
/// `F_t = k (tt ω* ε + ts s ε ε̇)`, `s = sgn ω_rel`.
struct Shape<T> {
    rr: T,
    rs: T,
    tt: T,
    ts: T,
}

impl BearingLaw {
    /// The force scale k (N s): `η R L³/c²` (short) or `6 η R³ L/c²` (long).
    pub fn force_scale(&self) -> f64 {
        let (r, l, c, eta) = (self.radius, self.length, self.clearance, self.viscosity);
        match self.theory {
            BearingTheory::Short => eta * r * l.powi(3) / (c * c),
            BearingTheory::Long => 6.0 * eta * r.powi(3) * l / (c * c),
        }
    }

    fn shape<T: DualNum<f64> + Copy>(&self, eps: T) -> Shape<T> {
        let pi = std::f64::consts::PI;
        let e2 = eps * eps;
        let q = -e2 + 1.0;
        let sq = q.sqrt();
        match self.theory {
            BearingTheory::Short => {
                let q2 = (q * q).recip();
                Shape {
                    rr: q2,
                    rs: (e2 * 2.0 + 1.0) * q2 / sq * (pi / 2.0),
                    tt: (q * sq).recip() * (pi / 4.0),
                    ts: q2 * 2.0,
                }
            }
            BearingTheory::Long => {
                let a = (e2 + 2.0).recip();
                Shape {
                    rr: a * q.recip() * 2.0,
                    rs: (-a * (16.0 / pi) + pi) / (q * sq),
                    tt: a / sq * pi,
                    ts: a * q.recip() * 4.0,
                }
            }
        }
    }

    /// Petroff's torque per relative speed with eccentricity (eq. 2.212), N m s/rad.
    fn petroff<T: DualNum<f64> + Copy>(&self, eps: T) -> T {
        let e2 = eps * eps;
        let shape = (e2 * 2.0 + 1.0) * 2.0 / ((-e2 + 1.0).sqrt() * (e2 * 0.5 + 1.0));
        let (r, l, c, eta) = (self.radius, self.length, self.clearance, self.viscosity);
        shape * (std::f64::consts::PI * r.powi(3) * l * eta / c)
    }

    /// The film forces and the friction torque on the journal at eccentricity ε < 1, its rate ε̇,
    /// the effective speed ω* = ω_rel − 2φ̇ and the relative spin ω_rel (module docs), generic over
    /// the scalar so that the exact linearization differentiates the same law.
    pub fn film<T: DualNum<f64> + Copy>(&self, eps: T, eps_dot: T, omega_star: T, omega_rel: T) -> FilmLoad<T> {
        debug_assert!(eps.re() >= 0.0 && eps.re() < 1.0);
        let k = self.force_scale();
        let s = if omega_rel.re() >= 0.0 { 1.0 } else { -1.0 };
        let sh = self.shape(eps);
        FilmLoad {
            f_r: -(sh.rr * omega_star * s * eps * eps + sh.rs * eps_dot) * k,
            f_t: (sh.tt * omega_star * eps + sh.ts * eps * eps_dot * s) * k,
            torque: -self.petroff(eps) * omega_rel,
        }
    }

    /// The film's load on the journal from the offset `e` and its rate `e_dot` (shell x, y) and
    /// the relative spin; `Err(ε)` once the journal touches the shell (ε ≥ 1).
    ///
    /// Assembled in Cartesian form, `F = −k [rr s ω* ε e/c + rs ε̇ e_r] + k [tt (ω_rel ẑ × e/c −
    /// 2 (e_t·ė/c) e_t) + ts s ε ε̇ e_t]` (s = sgn ω_rel), which is [`BearingLaw::film`]'s `F_r e_r + F_t e_t`
    /// for ε > 0 and stays differentiable in `e` at the centre (where e_r is taken along x).
    pub fn shell_load<T: DualNum<f64> + Copy>(
        &self,
        e: [T; 2],
        e_dot: [T; 2],
        omega_rel: T,
    ) -> std::result::Result<ShellLoad<T>, f64> {
        let c = self.clearance;
        let u = [e[0] / c, e[1] / c];
        let v = [e_dot[0] / c, e_dot[1] / c];
        let e2 = u[0] * u[0] + u[1] * u[1];
        if !(e2.re() < 1.0) {
            return Err(e2.re().sqrt());
        }
        // at the exact centre the offset has no direction: take x (ε then carries no derivative)
        let (eps, er) = if e2.re() > 0.0 {
            let eps = e2.sqrt();
            (eps, [u[0] / eps, u[1] / eps])
        } else {
            (T::from(0.0), [T::from(1.0), T::from(0.0)])
        };
        let et = [-er[1], er[0]];
        let eps_dot = er[0] * v[0] + er[1] * v[1];
        // ε φ̇ and ω* ε: finite at the centre, unlike φ̇
        let eps_phidot = et[0] * v[0] + et[1] * v[1];
        let w_eps = omega_rel * eps - eps_phidot * 2.0;
        // the converging half of the gap follows the spin
        let s = if omega_rel.re() >= 0.0 { 1.0 } else { -1.0 };
        let k = self.force_scale();
        let sh = self.shape(eps);
        let zu = [-u[1], u[0]];
        let radial = sh.rs * eps_dot;
        let spin = sh.rr * w_eps * s;
        let tangential = sh.ts * eps * eps_dot * s - sh.tt * eps_phidot * 2.0;
        let mut force = [T::from(0.0); 2];
        for i in 0..2 {
            force[i] = (-(spin * u[i] + radial * er[i]) + sh.tt * omega_rel * zu[i] + tangential * et[i]) * k;
        }
        let f_r = -(sh.rr * w_eps * s * eps + radial) * k;
        let f_t = (sh.tt * w_eps + sh.ts * eps * eps_dot * s) * k;
        Ok(ShellLoad { force, torque: -self.petroff(eps) * omega_rel, eps, f_r, f_t })
    }

    /// Load capacity W(ε) = |F| of a steady journal at ε ∈ [0, 1) and speed ω (N).
    pub fn load_capacity(&self, eps: f64, speed: f64) -> f64 {
        let f = self.film(eps, 0.0, speed, speed);
        f.f_r.hypot(f.f_t)
    }

    /// Attitude angle ψ (rad) of a steady journal at ε: the angle from the load line to the line
    /// of centres, along the rotation; `tan ψ = −F_t/F_r`, π/2 at ε = 0.
    pub fn attitude_angle(&self, eps: f64) -> f64 {
        let sh = self.shape(eps);
        // F_t/(−F_r) = tt/(rr ε) at ε̇ = 0 and ω* > 0
        sh.tt.atan2(sh.rr * eps)
    }

    /// The steady operating point at speed ω ≠ 0 (rad/s, the journal's spin relative to the shell)
    /// under a load W > 0 (N) acting on the journal along −y.
    pub fn operating_point(&self, speed: f64, load: f64) -> Result<OperatingPoint> {
        crate::ensure!(
            speed.is_finite() && speed != 0.0,
            Settings,
            "bearing operating point: speed must be finite and nonzero, got {speed} rad/s"
        );
        crate::ensure!(
            load.is_finite() && load > 0.0,
            Settings,
            "bearing operating point: load must be > 0, got {load} N"
        );
        let eps = self.eccentricity_for_load(speed, load)?;
        let f = self.film(eps, 0.0, speed, speed);
        // the film force on the journal points up (+y): φ + angle(F in the polar axes) = π/2
        let phi = std::f64::consts::FRAC_PI_2 - f.f_t.atan2(f.f_r);
        let c = self.clearance;
        let e = [c * eps * phi.cos(), c * eps * phi.sin()];
        let (stiffness, damping) = self.coefficients(e, speed).ok_or_else(|| {
            Error::Solver(format!("bearing operating point: the journal touches the shell at ε = {eps}"))
        })?;
        let n = speed.abs() / (2.0 * std::f64::consts::PI);
        let d = 2.0 * self.radius;
        Ok(OperatingPoint {
            eps,
            attitude: self.attitude_angle(eps),
            position_angle: phi,
            offset: e,
            sommerfeld: self.viscosity * n * self.length * d / load * (self.radius / c).powi(2),
            h_min: c * (1.0 - eps),
            torque: self.petroff(eps) * speed.abs(),
            stiffness,
            damping,
        })
    }

    /// Solves `W(ε) = load` by bisection (W grows monotonically from 0 to ∞ on [0, 1)).
    fn eccentricity_for_load(&self, speed: f64, load: f64) -> Result<f64> {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.load_capacity(mid, speed) < load {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let eps = 0.5 * (lo + hi);
        crate::ensure!(
            eps < 1.0 - 1e-12,
            Settings,
            "bearing operating point: the load {load} N is beyond the film's capacity at {speed} rad/s (ε → 1)"
        );
        Ok(eps)
    }

    /// `K = −∂F/∂e` and `C = −∂F/∂ė` (shell x, y; N/m and N s/m) at the offset `e` of a journal
    /// at rest in the shell frame spinning at `speed`, exact (dual numbers); None if the offset
    /// is not inside the clearance.
    pub fn coefficients(&self, e: [f64; 2], speed: f64) -> Option<([[f64; 2]; 2], [[f64; 2]; 2])> {
        let (mut k, mut d) = ([[0.0; 2]; 2], [[0.0; 2]; 2]);
        for j in 0..4 {
            let seed = |i: usize, x: f64| if i == j { Dual64::new(x, 1.0) } else { Dual64::from(x) };
            let pos = [seed(0, e[0]), seed(1, e[1])];
            let vel = [seed(2, 0.0), seed(3, 0.0)];
            let l = self.shell_load(pos, vel, Dual64::from(speed)).ok()?;
            for i in 0..2 {
                let g = -l.force[i].eps;
                if j < 2 {
                    k[i][j] = g;
                } else {
                    d[i][j - 2] = g;
                }
            }
        }
        Some((k, d))
    }
}

/// A bearing's steady operating point under a load along −y (shell frame), spinning at ω.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OperatingPoint {
    /// Relative eccentricity ε.
    pub eps: f64,
    /// Attitude angle ψ (rad) from the load line to the line of centres, along the rotation.
    pub attitude: f64,
    /// Angle φ (rad) of the journal centre from the shell x axis.
    pub position_angle: f64,
    /// The journal centre's offset, shell x and y (m).
    pub offset: [f64; 2],
    /// Sommerfeld number `S = η N L D/W · (R/c)²`, N in rev/s.
    pub sommerfeld: f64,
    /// Minimum film thickness c (1 − ε) (m).
    pub h_min: f64,
    /// Friction torque on the journal (N m, magnitude; it opposes the spin).
    pub torque: f64,
    /// Stiffness coefficients K_ij = −∂F_i/∂x_j (N/m), shell x, y.
    pub stiffness: [[f64; 2]; 2],
    /// Damping coefficients C_ij = −∂F_i/∂ẋ_j (N s/m), shell x, y.
    pub damping: [[f64; 2]; 2],
}

/// The error of a journal touching its shell (or of an offset that is not finite), naming the
/// element and the time.
pub fn touch_error(name: &str, eps: f64, t: f64) -> Error {
    if !eps.is_finite() {
        return Error::Solver(format!(
            "hydrodynamic bearing '{name}': the journal's offset is not finite at t = {t} s"
        ));
    }
    Error::Solver(format!(
        "hydrodynamic bearing '{name}': the journal touches the shell at t = {t} s (eccentricity ε = {eps:.6} ≥ 1), \
         where the film theory ends; check the initial offset, the load against the film's capacity at the speed, \
         or shorten a fixed step that overshoots the squeeze film"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn law(theory: BearingTheory) -> BearingLaw {
        BearingLaw { theory, radius: 0.05, length: 0.04, clearance: 1e-4, viscosity: 0.03 }
    }

    /// ∫₀^π f by composite Gauss–Legendre (5 points on each of n panels).
    fn gauss(f: impl Fn(f64) -> f64, n: usize) -> f64 {
        let x = [0.0, -0.538_469_310_105_683, 0.538_469_310_105_683, -0.906_179_845_938_664, 0.906_179_845_938_664];
        let w = [
            0.568_888_888_888_889,
            0.478_628_670_499_366,
            0.478_628_670_499_366,
            0.236_926_885_056_189,
            0.236_926_885_056_189,
        ];
        let h = PI / n as f64;
        (0..n)
            .map(|k| {
                let m = (k as f64 + 0.5) * h;
                (0..5).map(|i| w[i] * f(m + 0.5 * h * x[i])).sum::<f64>() * 0.5 * h
            })
            .sum()
    }

    const CASES: [(f64, f64, f64); 6] =
        [(0.3, 0.0, 100.0), (0.7, 0.0, 50.0), (0.5, 3.0, 0.0), (0.8, -2.0, 80.0), (0.05, 1.0, 10.0), (0.9, 0.4, 300.0)];

    #[test]
    fn short_bearing_forces_are_the_integrated_ocvirk_pressure() {
        let b = law(BearingTheory::Short);
        let (r, l, c, eta) = (b.radius, b.length, b.clearance, b.viscosity);
        for (eps, ed, ws) in CASES {
            let p = |t: f64| {
                eta * l.powi(3) / (2.0 * c * c) * (ws * eps * t.sin() - 2.0 * ed * t.cos())
                    / (1.0 + eps * t.cos()).powi(3)
            };
            let fr = r * gauss(|t| p(t) * t.cos(), 400);
            let ft = r * gauss(|t| p(t) * t.sin(), 400);
            let f = b.film(eps, ed, ws, ws);
            let scale = fr.abs().max(ft.abs());
            assert!(
                (f.f_r - fr).abs() < 1e-10 * scale && (f.f_t - ft).abs() < 1e-10 * scale,
                "{eps} {ed} {ws}: {f:?} vs {fr} {ft}"
            );
        }
    }

    #[test]
    fn long_bearing_forces_are_the_integrated_sommerfeld_pressure() {
        // p' of the module docs with K chosen so that p(π) = 0, integrated by the trapezoid rule on a
        // fine grid, then F_r = R L ∫ p cos θ, F_t = R L ∫ p sin θ
        let b = law(BearingTheory::Long);
        let (r, l, c, eta) = (b.radius, b.length, b.clearance, b.viscosity);
        let n = 200_000;
        let h = PI / n as f64;
        for (eps, ed, ws) in CASES {
            let g = |t: f64, k: f64| (eps * ws * t.cos() + 2.0 * ed * t.sin() + k) / (1.0 + eps * t.cos()).powi(3);
            // K from p(π) = 0 (Gauss, independent of the closed form)
            let k = -gauss(|t| g(t, 0.0), 400) / gauss(|t| (1.0 + eps * t.cos()).powi(-3), 400);
            let (mut p, mut fr, mut ft) = (0.0, 0.0, 0.0);
            let mut gp = g(0.0, k);
            for i in 1..=n {
                let t = i as f64 * h;
                let gi = g(t, k);
                let p_new = p + 0.5 * h * (gp + gi) * 6.0 * eta * r * r / (c * c);
                let t0 = t - h;
                fr += 0.5 * h * (p * t0.cos() + p_new * t.cos());
                ft += 0.5 * h * (p * t0.sin() + p_new * t.sin());
                p = p_new;
                gp = gi;
            }
            let f = b.film(eps, ed, ws, ws);
            let (fr, ft) = (r * l * fr, r * l * ft);
            let scale = fr.abs().max(ft.abs());
            assert!(p.abs() < 1e-6 * scale / (r * l), "p(π) = {p}");
            assert!(
                (f.f_r - fr).abs() < 1e-7 * scale && (f.f_t - ft).abs() < 1e-7 * scale,
                "{eps} {ed} {ws}: {f:?} vs {fr} {ft}"
            );
        }
    }

    #[test]
    fn closed_form_load_capacity_and_attitude() {
        let (s, lg) = (law(BearingTheory::Short), law(BearingTheory::Long));
        let (r, l, c, eta) = (s.radius, s.length, s.clearance, s.viscosity);
        let w = 120.0;
        for eps in [0.01, 0.2, 0.5, 0.8, 0.95] {
            let q = 1.0 - eps * eps;
            let ws = eta * w * r * l.powi(3) / (4.0 * c * c) * eps / (q * q) * (16.0 * eps * eps + PI * PI * q).sqrt();
            assert!((s.load_capacity(eps, w) / ws - 1.0).abs() < 1e-13);
            assert!((s.attitude_angle(eps) - (PI * q.sqrt() / (4.0 * eps)).atan()).abs() < 1e-13);
            let wl = 6.0 * eta * w * r.powi(3) * l / (c * c) * eps * (4.0 * eps * eps + PI * PI * q).sqrt()
                / ((2.0 + eps * eps) * q);
            assert!((lg.load_capacity(eps, w) / wl - 1.0).abs() < 1e-13);
            assert!((lg.attitude_angle(eps) - (PI * q.sqrt() / (2.0 * eps)).atan()).abs() < 1e-13);
        }
        // ε → 0: the load vanishes linearly and the journal sits at right angles to the load
        assert_eq!(s.load_capacity(0.0, w), 0.0);
        assert!((s.attitude_angle(0.0) - PI / 2.0).abs() < 1e-15);
    }

    #[test]
    fn cartesian_load_is_the_polar_law_and_mirrors_with_the_rotation() {
        for theory in [BearingTheory::Short, BearingTheory::Long] {
            let b = law(theory);
            let c = b.clearance;
            for (phi, eps, ed, phid, w) in
                [(0.3, 0.4, 0.2, 3.0, 90.0), (-2.0, 0.85, -1.0, -20.0, 150.0), (1.0, 0.2, 0.0, 10.0, -60.0)]
            {
                let (er, et) = ([f64::cos(phi), f64::sin(phi)], [-f64::sin(phi), f64::cos(phi)]);
                let e = [c * eps * er[0], c * eps * er[1]];
                let ed_v = [c * (ed * er[0] + eps * phid * et[0]), c * (ed * er[1] + eps * phid * et[1])];
                let l = b.shell_load(e, ed_v, w).unwrap();
                let f = b.film(eps, ed, w - 2.0 * phid, w);
                for i in 0..2 {
                    let want = f.f_r * er[i] + f.f_t * et[i];
                    assert!(
                        (l.force[i] - want).abs() < 1e-11 * f.f_r.hypot(f.f_t),
                        "{theory:?}: {:?} vs {f:?}",
                        l.force
                    );
                }
                assert!(
                    (l.f_r - f.f_r).abs() < 1e-11 * f.f_r.abs() && (l.f_t - f.f_t).abs() < 1e-11 * f.f_t.abs().max(1.0)
                );
                assert!((l.torque - f.torque).abs() < 1e-14 * f.torque.abs());
                // the mirror image of the motion (y → −y, spins reversed) gives the mirrored force
                let m = b.shell_load([e[0], -e[1]], [ed_v[0], -ed_v[1]], -w).unwrap();
                assert!((m.force[0] - l.force[0]).abs() < 1e-11 * l.f_r.hypot(l.f_t));
                assert!((m.force[1] + l.force[1]).abs() < 1e-11 * l.f_r.hypot(l.f_t));
                assert!((m.torque + l.torque).abs() < 1e-14 * l.torque.abs());
            }
        }
    }

    #[test]
    fn a_journal_below_the_centre_is_pushed_up_and_along_the_rotation() {
        // spin +z (counter-clockwise seen from +z): the bottom of the journal moves along +x
        for theory in [BearingTheory::Short, BearingTheory::Long] {
            let b = law(theory);
            let l = b.shell_load([0.0, -0.5 * b.clearance], [0.0, 0.0], 100.0).unwrap();
            assert!(l.force[1] > 0.0 && l.force[0] > 0.0, "{theory:?}: {:?}", l.force);
            assert!(l.f_r < 0.0 && l.f_t > 0.0 && l.torque < 0.0);
        }
    }

    #[test]
    fn the_centre_is_the_small_offset_limit() {
        for theory in [BearingTheory::Short, BearingTheory::Long] {
            let b = law(theory);
            let (c, w) = (b.clearance, 200.0);
            let at0 = b.shell_load([0.0, 0.0], [0.0, 0.0], w).unwrap();
            assert_eq!(at0.force, [0.0, 0.0]);
            // the torque is Petroff's
            let petroff = 2.0 * PI * b.radius.powi(3) * b.length * b.viscosity / c * w;
            assert!((at0.torque + petroff).abs() < 1e-12 * petroff);
            // the stiffness at the centre (exact, through the e-linear terms) is the slope of F_t
            let (k, _) = b.coefficients([0.0, 0.0], w).unwrap();
            let d = 1e-9 * c;
            let f = b.shell_load([d, 0.0], [0.0, 0.0], w).unwrap();
            assert!((k[1][0] + f.force[1] / d).abs() < 1e-6 * k[1][0].abs(), "{k:?}");
            assert!((k[0][1] - f.force[1] / d).abs() < 1e-6 * k[1][0].abs(), "{k:?}");
            assert!(k[0][0].abs() < 1e-6 * k[1][0].abs() && k[1][1].abs() < 1e-6 * k[1][0].abs());
        }
    }

    #[test]
    fn friction_torque_is_eq_2_212() {
        for theory in [BearingTheory::Short, BearingTheory::Long] {
            let b = law(theory);
            for eps in [0.0, 0.3, 0.6, 0.9] {
                let c = crate::forces::damping::journal_bearing_coefficient(
                    b.radius,
                    b.length,
                    b.clearance,
                    b.viscosity,
                    eps,
                );
                let f = b.film(eps, 0.0, 70.0, -40.0);
                assert!((f.torque - 40.0 * c).abs() < 1e-13 * 40.0 * c, "{eps}: {} vs {}", f.torque, 40.0 * c);
            }
        }
    }

    #[test]
    fn touching_the_shell_is_refused() {
        let b = law(BearingTheory::Short);
        assert_eq!(b.shell_load([b.clearance, 0.0], [0.0, 0.0], 10.0).unwrap_err(), 1.0);
        assert!(b.shell_load([0.0, -1.2 * b.clearance], [0.0, 0.0], 10.0).is_err());
        let msg = touch_error("brg", 1.01, 0.25).to_string();
        assert!(msg.contains("'brg'") && msg.contains("t = 0.25") && msg.contains("touches the shell"));
        assert!(touch_error("brg", f64::NAN, 0.5).to_string().contains("not finite at t = 0.5 s"));
        assert!(b.coefficients([0.0, 1.5 * b.clearance], 10.0).is_none());
    }

    #[test]
    fn coefficients_are_the_derivatives_of_the_force() {
        for theory in [BearingTheory::Short, BearingTheory::Long] {
            let b = law(theory);
            let w = 150.0;
            let op = b.operating_point(w, 800.0).unwrap();
            // balance: the film carries the load along +y
            let l = b.shell_load(op.offset, [0.0, 0.0], w).unwrap();
            assert!(l.force[0].abs() < 1e-9 * 800.0 && (l.force[1] - 800.0).abs() < 1e-9 * 800.0, "{:?}", l.force);
            assert!((op.eps - l.eps).abs() < 1e-15);
            let x0 = [op.offset[0], op.offset[1], 0.0, 0.0];
            let force = |x: [f64; 4]| b.shell_load([x[0], x[1]], [x[2], x[3]], w).unwrap().force;
            for j in 0..4 {
                let h = if j < 2 { 1e-6 * b.clearance } else { 1e-4 * b.clearance * w };
                let (mut xp, mut xm) = (x0, x0);
                xp[j] += h;
                xm[j] -= h;
                let (fp, fm) = (force(xp), force(xm));
                for i in 0..2 {
                    let fd = -(fp[i] - fm[i]) / (2.0 * h);
                    let exact = if j < 2 { op.stiffness[i][j] } else { op.damping[i][j - 2] };
                    let scale = if j < 2 { op.stiffness[0][0].abs() } else { op.damping[0][0].abs() };
                    assert!((fd - exact).abs() < 1e-7 * scale, "{theory:?} ({i},{j}): fd {fd} exact {exact}");
                }
            }
        }
    }

    #[test]
    fn operating_point_inputs_are_checked() {
        let b = law(BearingTheory::Short);
        assert!(b.operating_point(0.0, 10.0).is_err());
        assert!(b.operating_point(10.0, -1.0).is_err());
        assert!(b.operating_point(f64::NAN, 1.0).is_err());
        // the ε of a light load is small, of a heavy one close to 1
        assert!(b.operating_point(500.0, 1e-3).unwrap().eps < 1e-4);
        assert!(b.operating_point(5.0, 1e5).unwrap().eps > 0.9);
    }
}
