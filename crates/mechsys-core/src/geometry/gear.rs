//! The outline of an external involute spur gear as one closed, tangent-continuous (G1) planar
//! contour, for the parametric contact of section 2.2.7.1 ([`crate::geometry::curve::Curve::gear`]).
//!
//! **Data.** Module `m`, tooth count `z`, pressure angle `α`, profile shift `x`, backlash `j`
//! (tooth thinning on the pitch circle), addendum `h_a`, dedendum `h_f`, tip rounding radius
//! `ρ_a`, root fillet radius `ρ_f`. Radii:
//!
//! | circle | radius |
//! | --- | --- |
//! | pitch | `r = m z / 2` |
//! | base | `r_b = r cos α` |
//! | tip | `r_a = r + x m + h_a` |
//! | root | `r_f = r + x m − h_f` |
//!
//! Tooth thickness on the pitch circle `s = m (π/2 + 2 x tan α) − j`, so the tooth's half angle
//! at radius `ρ` is `ψ(ρ) = s / (2r) + inv α − inv α_ρ`, `cos α_ρ = r_b / ρ`,
//! `inv α = tan α − α`; at the base circle `ψ_b = s / (2r) + inv α`.
//!
//! **Flank.** The exact involute of the base circle, with the roll angle `φ`:
//! `r(φ) = r_b (cos φ + φ sin φ, sin φ − φ cos φ)` (turned onto the tooth; the upper flank is the
//! mirror image). Its arc length from the base circle is `σ = r_b φ² / 2` and its radius of
//! curvature `r_b φ`; the contour's parameter on it is `σ`, so `r' = (cos φ, sin φ)`,
//! `r'' = (−sin φ, cos φ) / (r_b φ)`, `r''' = −(cos φ, sin φ) / (r_b φ)² − (−sin φ, cos φ) / (r_b² φ³)`.
//!
//! **Roundings (closed form, no iteration).** With the outward normal `ν(φ) = (sin φ, −cos φ)` of
//! the involute, the centre of a circle of radius `ρ` tangent to it at `φ` on the gap side is
//! `r(φ) + ρ ν = r_b (cos φ, sin φ) + (r_b φ + ρ) ν`, at distance `√(r_b² + (r_b φ + ρ)²)` from
//! the gear centre; on the solid side replace `ρ` by `−ρ`. Hence:
//! - tip rounding, tangent to the tip circle from inside: `r_b φ_a = ρ_a + √((r_a − ρ_a)² − r_b²)`;
//! - root fillet, tangent to the root circle from outside: `r_b φ_f = √((r_f + ρ_f)² − r_b²) − ρ_f`.
//!
//! The involute is used from roll angle `φ_s = min(ρ_a, ρ_f) / r_b` up (its curvature `1/(r_b φ)`
//! is infinite on the base circle; from `φ_s` on it never exceeds the roundings' curvature). When
//! the fillet would touch the involute below `φ_s` (the root circle lies inside the base circle or
//! close to it — every gear with fewer than about 42 teeth at α = 20°), the flank continues from
//! `φ_s` inward along its tangent, a straight segment tilted by `φ_s` from the radial direction,
//! and the fillet is tangent to that segment and to the root circle (again in closed form:
//! `λ = −r_b + √((r_f + ρ_f)² − (r_b φ_s + ρ_f)²)` along the tangent from `r(φ_s)`).
//!
//! **Parameter.** The arc length along the outline: `s = 0` at the middle of the gap before tooth
//! 0, increasing counter-clockwise (solid inside, on the left). Each tooth spans the same length
//! `L`: root arc, fillet, (segment), involute, tip rounding, tip arc, and the mirror images in
//! reverse order. Tooth `k` is centred on the direction `phase + 2πk/z` at `s = (k + ½) L`. The
//! arc length makes `r'` the unit tangent, continuous across every joint (G1 is C¹ in `s`); `r''`
//! jumps there (the curvature does).

use crate::ensure;
use crate::error::Result;
use std::f64::consts::PI;

use super::curve::{Jet2, Vec2};

/// Input of [`crate::geometry::curve::Curve::gear`]; lengths in m, angles in rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearSpec {
    /// Module `m` (pitch diameter / teeth), > 0.
    pub module: f64,
    /// Number of teeth `z`, 5 to 170.
    pub teeth: usize,
    /// Pressure angle `α` on the pitch circle (0.35 rad = 20° typical).
    pub pressure_angle: f64,
    /// Profile shift coefficient `x` (the tool moved out by `x m`).
    pub shift: f64,
    /// Tooth thinning on the pitch circle (arc length), ≥ 0.
    pub backlash: f64,
    /// Tip circle above the shifted pitch circle: `r_a = r + x m + addendum`.
    pub addendum: f64,
    /// Root circle below it: `r_f = r + x m − dedendum`.
    pub dedendum: f64,
    /// Tip rounding radius; `None`: `0.05 m`, or less where that does not fit.
    pub tip_radius: Option<f64>,
    /// Root fillet radius; `None`: `0.2 m`, or less where that does not fit.
    pub root_radius: Option<f64>,
    /// Centre of the gear in the body's x-y plane.
    pub center: Vec2,
    /// Direction of tooth 0's centre line from the body's x axis.
    pub phase: f64,
}

impl GearSpec {
    /// A standard gear: α = 20°, no shift, no backlash, addendum `m`, dedendum `1.25 m`, default
    /// roundings, centred at the origin with tooth 0 on the x axis.
    pub fn new(module: f64, teeth: usize) -> GearSpec {
        GearSpec {
            module,
            teeth,
            pressure_angle: 20f64.to_radians(),
            shift: 0.0,
            backlash: 0.0,
            addendum: module,
            dedendum: 1.25 * module,
            tip_radius: None,
            root_radius: None,
            center: Vec2::zeros(),
            phase: 0.0,
        }
    }
}

/// Most teeth (so that every tooth keeps [`MIN_SAMPLES_PER_TOOTH`] samples).
pub const MAX_TEETH: usize = super::curve::MAX_SAMPLES / MIN_SAMPLES_PER_TOOTH;
/// Samples per tooth for the contact search's global start (fewer for many teeth).
pub const SAMPLES_PER_TOOTH: usize = 40;
/// Fewest samples per tooth.
pub const MIN_SAMPLES_PER_TOOTH: usize = 24;

/// `inv α = tan α − α`.
pub fn involute_function(alpha: f64) -> f64 {
    alpha.tan() - alpha
}

/// One piece of the lower half of a tooth (tooth frame: tooth centred on +x), parameterized by
/// its arc length `w` from its start.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// `c + ρ (cos a, sin a)`, `a = angle + dir w / ρ`.
    Arc { center: Vec2, radius: f64, angle: f64, dir: f64 },
    /// `start + w dir`.
    Line { start: Vec2, dir: Vec2 },
    /// The involute turned by `rot` (cos, sin), from arc length `sigma0` (from the base circle).
    Involute { rot: Vec2, base: f64, sigma0: f64 },
}

#[inline]
fn turn(rot: &Vec2, v: Vec2) -> Vec2 {
    Vec2::new(rot.x * v.x - rot.y * v.y, rot.y * v.x + rot.x * v.y)
}

impl Piece {
    #[inline]
    fn eval(&self, w: f64) -> Jet2 {
        match *self {
            Piece::Arc { center, radius, angle, dir } => {
                let (sn, cs) = (angle + dir * w / radius).sin_cos();
                let (e, t) = (Vec2::new(cs, sn), Vec2::new(-sn, cs));
                [center + e * radius, t * dir, -e / radius, t * (-dir / (radius * radius))]
            }
            Piece::Line { start, dir } => [start + dir * w, dir, Vec2::zeros(), Vec2::zeros()],
            Piece::Involute { rot, base, sigma0 } => {
                let phi = (2.0 * (sigma0 + w) / base).sqrt();
                let (sn, cs) = phi.sin_cos();
                let (t, n) = (Vec2::new(cs, sn), Vec2::new(-sn, cs));
                let rho = base * phi; // radius of curvature
                [
                    turn(&rot, Vec2::new(cs + phi * sn, sn - phi * cs) * base),
                    turn(&rot, t),
                    turn(&rot, n / rho),
                    turn(&rot, -t / (rho * rho) - n / (rho * rho * phi)),
                ]
            }
        }
    }
}

/// An involute spur gear outline (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Gear {
    spec: GearSpec,
    /// Pieces of the lower half tooth with their start parameters (increasing from 0).
    pieces: Vec<(f64, Piece)>,
    /// Parameter length of half a tooth and of a tooth.
    half: f64,
    tooth: f64,
    /// `(cos, sin)` of `phase + 2πk/z`.
    turns: Vec<Vec2>,
    pitch: f64,
    base: f64,
    tip: f64,
    root: f64,
    /// Half angle of the tooth at the base circle.
    psi_b: f64,
    /// Roll angles where the exact involute starts and ends.
    roll: (f64, f64),
    /// Tip rounding and root fillet radii used.
    rounding: (f64, f64),
    /// Whether a straight segment joins the involute to the fillet.
    segment: bool,
}

/// Tip rounding tangent to the involute (standard frame: involute from angle 0, growing to
/// positive polar angles) and to the tip circle: roll angle, centre, polar angle of the centre.
fn tip_rounding(rb: f64, ra: f64, rho: f64) -> Option<(f64, Vec2, f64)> {
    let q = (ra - rho).powi(2) - rb * rb;
    if !(q > 0.0 && rho > 0.0) {
        return None;
    }
    let phi = (rho + q.sqrt()) / rb;
    let (sn, cs) = phi.sin_cos();
    let c = Vec2::new(cs, sn) * rb + Vec2::new(sn, -cs) * (rb * phi - rho);
    Some((phi, c, c.y.atan2(c.x)))
}

/// The root fillet (standard frame): lower end of the involute (roll angle), the straight
/// segment's length below it (0: the fillet touches the involute), fillet centre and its polar
/// angle.
fn root_fillet(rb: f64, rf: f64, rho: f64, phi_s: f64) -> Option<(f64, f64, Vec2, f64)> {
    let q = (rf + rho).powi(2) - rb * rb;
    if q > 0.0 {
        let phi = (q.sqrt() - rho) / rb;
        if phi >= phi_s {
            let (sn, cs) = phi.sin_cos();
            let c = Vec2::new(cs, sn) * rb + Vec2::new(sn, -cs) * (rb * phi + rho);
            return Some((phi, 0.0, c, c.y.atan2(c.x)));
        }
    }
    // tangent to the segment from r(φ_s) inward along -t(φ_s)
    let q = (rf + rho).powi(2) - (rb * phi_s + rho).powi(2);
    if !(q >= 0.0) {
        return None;
    }
    let lambda = -rb + q.sqrt();
    let (sn, cs) = phi_s.sin_cos();
    let (t, nu) = (Vec2::new(cs, sn), Vec2::new(sn, -cs));
    let p = Vec2::new(cs + phi_s * sn, sn - phi_s * cs) * rb;
    let c = p + t * lambda + nu * rho;
    Some((phi_s, -lambda.min(0.0), c, c.y.atan2(c.x)))
}

/// Largest `ρ` in `(0, hi]` with `fits(ρ)` (bisection; `fits` true for small `ρ`).
fn largest(hi: f64, fits: impl Fn(f64) -> bool) -> f64 {
    let (mut a, mut b) = (0.0, hi);
    if fits(b) {
        return b;
    }
    for _ in 0..60 {
        let c = 0.5 * (a + b);
        if fits(c) {
            a = c;
        } else {
            b = c;
        }
    }
    a
}

impl Gear {
    /// Builds and validates the outline; `what` names the contour in errors.
    pub fn new(spec: &GearSpec, what: &str) -> Result<Gear> {
        let GearSpec {
            module: m,
            teeth: z,
            pressure_angle: alpha,
            shift: x,
            backlash: j,
            addendum: ha,
            dedendum: hf,
            ..
        } = *spec;
        ensure!(m > 0.0 && m.is_finite(), Model, "{what}: gear module must be > 0 and finite, got {m}");
        ensure!((5..=MAX_TEETH).contains(&z), Model, "{what}: a gear needs 5 to {MAX_TEETH} teeth, got {z}");
        ensure!(
            alpha > 0.0 && alpha < 60f64.to_radians(),
            Model,
            "{what}: gear pressure angle must lie between 0 and 60° (0 and 1.047 rad), got {alpha} rad"
        );
        ensure!(x.is_finite(), Model, "{what}: gear profile shift must be finite, got {x}");
        ensure!(j >= 0.0 && j.is_finite(), Model, "{what}: gear backlash must be ≥ 0, got {j}");
        ensure!(ha > 0.0 && ha.is_finite(), Model, "{what}: gear addendum must be > 0, got {ha}");
        ensure!(hf > 0.0 && hf.is_finite(), Model, "{what}: gear dedendum must be > 0, got {hf}");
        ensure!(
            spec.center.iter().all(|v| v.is_finite()) && spec.phase.is_finite(),
            Model,
            "{what}: gear center and phase must be finite"
        );
        let zf = z as f64;
        let r = 0.5 * m * zf;
        let rb = r * alpha.cos();
        let (ra, rf) = (r + x * m + ha, r + x * m - hf);
        ensure!(
            rf > 0.0,
            Model,
            "{what}: the gear's root circle has radius {rf} ≤ 0: dedendum {hf} too large for {z} teeth"
        );
        let thick = m * (0.5 * PI + 2.0 * x * alpha.tan()) - j;
        ensure!(
            thick > 0.0,
            Model,
            "{what}: the gear's tooth thickness on the pitch circle is {thick:.6e} ≤ 0 (backlash {j} too large for module {m}, shift {x})"
        );
        let psi_b = thick / (2.0 * r) + involute_function(alpha);
        // half angle of the gap at the base circle (negative when the involutes' extensions below
        // the root circle would overlap, which is harmless: the fillet must fit the real gap)
        let gap = PI / zf - psi_b;
        ensure!(
            ra > rb,
            Model,
            "{what}: the gear's tip circle (radius {ra}) lies inside its base circle (radius {rb}): no involute flank; \
             increase the addendum or the profile shift"
        );
        let alpha_a = (rb / ra).acos();
        let psi_a = psi_b - involute_function(alpha_a);
        ensure!(
            psi_a > 0.0,
            Model,
            "{what}: pointed teeth: the gear's tooth thickness at the tip circle (radius {ra}) would be {:.6e} ≤ 0; \
             reduce the addendum or the profile shift",
            2.0 * ra * psi_a
        );
        // tip rounding: its tip-circle tangency must stay on this half of the tooth
        let tip_fits = |rho: f64| tip_rounding(rb, ra, rho).is_some_and(|(_, _, g)| g <= psi_b);
        let tip_max = largest(ra - rb, tip_fits);
        let rho_a = match spec.tip_radius {
            Some(v) => {
                ensure!(
                    v > 0.0 && v.is_finite(),
                    Model,
                    "{what}: gear tip_radius must be > 0 (a sharp tip breaks the contact search), got {v}"
                );
                ensure!(
                    tip_fits(v),
                    Model,
                    "{what}: the gear's tip rounding radius {v} does not fit the tooth tip (at most {tip_max:.6e})"
                );
                v
            }
            None => (0.05 * m).min(0.9 * tip_max),
        };
        // root fillet: its root-circle tangency must stay on this half of the gap
        let fillet = |rho: f64, phi_s: f64| root_fillet(rb, rf, rho, phi_s);
        let fillet_fits = |rho: f64| {
            let phi_s = rho_a.min(rho) / rb;
            fillet(rho, phi_s)
                .is_some_and(|(lo, _, _, g)| g >= -gap && lo < tip_rounding(rb, ra, rho_a).map_or(0.0, |t| t.0))
        };
        let fillet_max = largest(2.0 * rb * gap + hf, fillet_fits);
        let rho_f = match spec.root_radius {
            Some(v) => {
                ensure!(
                    v > 0.0 && v.is_finite(),
                    Model,
                    "{what}: gear root_radius must be > 0 (a sharp root corner breaks the contact search), got {v}"
                );
                ensure!(
                    fillet_fits(v),
                    Model,
                    "{what}: the gear's root fillet radius {v} does not fit the tooth gap (at most {fillet_max:.6e})"
                );
                v
            }
            None => (0.2 * m).min(0.9 * fillet_max),
        };
        ensure!(
            rho_a > 0.0 && rho_f > 0.0,
            Model,
            "{what}: the gear's teeth leave no room for a tip rounding or root fillet (tip at most {tip_max:.3e}, root at most {fillet_max:.3e})"
        );
        let phi_s = rho_a.min(rho_f) / rb;
        let (phi_a, ca, gamma_a) = tip_rounding(rb, ra, rho_a).expect("checked by tip_fits");
        let (phi_lo, seg, cf, gamma_f) = fillet(rho_f, phi_s).expect("checked by fillet_fits");
        ensure!(
            phi_lo < phi_a,
            Model,
            "{what}: the gear's root fillet and tip rounding leave no involute flank; reduce root_radius or tip_radius"
        );
        // pieces of the lower half in the standard frame, turned by -ψ_b onto the tooth frame
        let rot = Vec2::new(psi_b.cos(), -psi_b.sin());
        let mut pieces: Vec<(f64, Piece)> = Vec::new();
        let g0 = -gap; // middle of the gap, standard frame
        pieces
            .push((rf * (gamma_f - g0), Piece::Arc { center: Vec2::zeros(), radius: rf, angle: g0 - psi_b, dir: 1.0 }));
        let span_f = gamma_f - phi_lo + 0.5 * PI;
        debug_assert!(span_f > 0.0);
        pieces.push((
            rho_f * span_f,
            Piece::Arc { center: turn(&rot, cf), radius: rho_f, angle: gamma_f + PI - psi_b, dir: -1.0 },
        ));
        let (sn, cs) = phi_s.sin_cos();
        let t_s = Vec2::new(cs, sn);
        if seg > 0.0 {
            let q = Vec2::new(cs + phi_s * sn, sn - phi_s * cs) * rb;
            pieces.push((seg, Piece::Line { start: turn(&rot, q - t_s * seg), dir: turn(&rot, t_s) }));
        }
        let sigma0 = 0.5 * rb * phi_lo * phi_lo;
        pieces.push((0.5 * rb * (phi_a * phi_a - phi_lo * phi_lo), Piece::Involute { rot, base: rb, sigma0 }));
        let span_a = gamma_a - phi_a + 0.5 * PI;
        debug_assert!(span_a > 0.0);
        pieces.push((
            rho_a * span_a,
            Piece::Arc { center: turn(&rot, ca), radius: rho_a, angle: phi_a - 0.5 * PI - psi_b, dir: 1.0 },
        ));
        pieces.push((
            ra * (psi_b - gamma_a),
            Piece::Arc { center: Vec2::zeros(), radius: ra, angle: gamma_a - psi_b, dir: 1.0 },
        ));
        // start parameters; pieces of (numerically) zero length dropped
        let scale = m * 1e-12;
        let mut start = 0.0;
        let mut list = Vec::new();
        for (len, p) in pieces.iter() {
            if *len > scale {
                list.push((start, *p));
                start += *len;
            }
        }
        let half = start;
        let turns =
            (0..z).map(|k| spec.phase + 2.0 * PI * k as f64 / zf).map(|a| Vec2::new(a.cos(), a.sin())).collect();
        Ok(Gear {
            spec: GearSpec { tip_radius: Some(rho_a), root_radius: Some(rho_f), ..*spec },
            pieces: list,
            half,
            tooth: 2.0 * half,
            turns,
            pitch: r,
            base: rb,
            tip: ra,
            root: rf,
            psi_b,
            roll: (phi_lo, phi_a),
            rounding: (rho_a, rho_f),
            segment: seg > 0.0,
        })
    }

    /// Parameter length of the whole outline (its perimeter).
    pub fn period(&self) -> f64 {
        self.tooth * self.turns.len() as f64
    }

    /// Samples the contour's global start needs.
    pub fn samples(&self) -> usize {
        let z = self.turns.len();
        z * SAMPLES_PER_TOOTH.min(super::curve::MAX_SAMPLES / z)
    }

    /// `r, r', r'', r'''` at `s` (wrapped into one period).
    #[inline]
    pub fn eval(&self, s: f64) -> Jet2 {
        let z = self.turns.len();
        // tooth index by division (no fmod); parameters outside one period wrap
        let kf = (s / self.tooth).floor();
        let u = (s - kf * self.tooth).clamp(0.0, self.tooth);
        let k = (kf.rem_euclid(z as f64) as usize).min(z - 1);
        self.tooth_eval(k, u, u > self.half)
    }

    /// The tooth (index) and flank (`true`: the upper one, facing counter-clockwise) at `s`.
    pub fn tooth_at(&self, s: f64) -> (usize, bool) {
        let z = self.turns.len();
        let kf = (s / self.tooth).floor();
        let u = s - kf * self.tooth;
        ((kf.rem_euclid(z as f64) as usize).min(z - 1), u > self.half)
    }

    /// Tooth `k` at its own parameter `u ∈ [0, L]`, from the formula of its lower (`upper =
    /// false`, `u ≤ L/2`) or upper half (both sides of a joint, for tests).
    #[inline]
    pub fn tooth_eval(&self, k: usize, u: f64, upper: bool) -> Jet2 {
        let j = if upper {
            // the upper half is the mirror image (y → -y) traversed backwards
            let l = self.lower(self.tooth - u);
            let m = |v: Vec2| Vec2::new(v.x, -v.y);
            [m(l[0]), -m(l[1]), m(l[2]), -m(l[3])]
        } else {
            self.lower(u)
        };
        let rot = &self.turns[k];
        [self.spec.center + turn(rot, j[0]), turn(rot, j[1]), turn(rot, j[2]), turn(rot, j[3])]
    }

    /// The lower half tooth (tooth frame) at `u ∈ [0, half]`.
    #[inline]
    fn lower(&self, u: f64) -> Jet2 {
        let mut i = self.pieces.len() - 1;
        while i > 0 && self.pieces[i].0 > u {
            i -= 1;
        }
        let (start, piece) = &self.pieces[i];
        piece.eval(u - start)
    }

    /// The data it was built from, with the rounding radii used.
    pub fn spec(&self) -> &GearSpec {
        &self.spec
    }

    /// Pitch radius `m z / 2`.
    pub fn pitch_radius(&self) -> f64 {
        self.pitch
    }

    /// Base radius `r cos α`.
    pub fn base_radius(&self) -> f64 {
        self.base
    }

    /// Tip radius `r + x m + h_a`.
    pub fn tip_radius(&self) -> f64 {
        self.tip
    }

    /// Root radius `r + x m − h_f`.
    pub fn root_radius(&self) -> f64 {
        self.root
    }

    /// Number of teeth.
    pub fn teeth(&self) -> usize {
        self.turns.len()
    }

    /// Parameter length of one tooth (tooth `k` spans `[kL, (k+1)L)`, its centre at `(k+½)L`).
    pub fn tooth_length(&self) -> f64 {
        self.tooth
    }

    /// Half angle of a tooth at the base circle, `ψ_b = s / (2r) + inv α`.
    pub fn base_half_angle(&self) -> f64 {
        self.psi_b
    }

    /// Roll angles `(φ_lo, φ_a)` between which the flank is the exact involute.
    pub fn roll_range(&self) -> (f64, f64) {
        self.roll
    }

    /// Tip rounding and root fillet radii used.
    pub fn roundings(&self) -> (f64, f64) {
        self.rounding
    }

    /// Whether a straight segment joins the involute to the root fillet.
    pub fn has_segment(&self) -> bool {
        self.segment
    }

    /// Tooth-local parameters where the pieces of the lower half start, and the kind of each
    /// piece (`"arc"`, `"line"`, `"involute"`); the upper half mirrors them about `L/2`.
    pub fn joints(&self) -> Vec<(f64, &'static str)> {
        self.pieces
            .iter()
            .map(|(s, p)| {
                (
                    *s,
                    match p {
                        Piece::Arc { .. } => "arc",
                        Piece::Line { .. } => "line",
                        Piece::Involute { .. } => "involute",
                    },
                )
            })
            .collect()
    }

    /// One piece of the lower half evaluated at its own arc length `w` (also beyond its end):
    /// the two sides of a joint for tests.
    pub fn piece_eval(&self, piece: usize, w: f64) -> Jet2 {
        self.pieces[piece].1.eval(w)
    }
}

#[cfg(test)]
#[path = "gear_tests.rs"]
mod tests;
