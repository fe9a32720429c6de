//! Planar parametric contours (section 2.2.7.1, eqs. 2.89–2.90): a curve `r(s)` in a body's x-y
//! plane with its tangent, outward normal, signed curvature and the curvature's derivative.
//!
//! Conventions (chosen so that every contour of the contact module reads the same way):
//! - The parameter `s` need not be the arc length: an ellipse uses its angle parameter, a spline
//!   the chord length of its data, a cam the cam angle. Every formula below works with `r'(s)` of
//!   any length; per-arc-length quantities divide by `|r'|`.
//! - The solid lies to the left of the direction of increasing `s` (a closed curve runs
//!   counter-clockwise around its solid), unless the curve was built with the solid on the right
//!   (a hole, a bore, a groove seen from inside). The outward normal is
//!   `ν = σ (r'_y, -r'_x) / |r'|` with `σ = +1` (solid on the left) or `-1`.
//! - The signed curvature `κ = σ (r' × r'') / |r'|³` is positive where the contour bulges
//!   outward (convex), negative where it is hollow (concave). With the text's inward normal
//!   `n = -ν` this is eq. 2.89: `t' = κ n`, `n' = -κ t` (per arc length).
//! - A contour may be offset from its base curve by a signed distance `o` along `ν` (a cam's
//!   profile is its pitch curve offset by minus the roller radius): the contour point is
//!   `r + o ν`, its curvature `κ / (1 + o κ)`, and its normal the base curve's.
//! - Open curves continue along their end tangents beyond their ends (straight extensions, `κ = 0`
//!   there), so the contact search never falls off the end.
//!
//! Shapes: [`Curve::ellipse`], [`Curve::spline`] (cubic, C², natural or periodic, through points),
//! [`Curve::cam`] (a cam disc from a periodic lift table for a roller, knife-edge or flat-faced
//! translating follower), [`Curve::gear`] (an involute spur gear outline, see
//! [`crate::geometry::gear`]). Constructors validate the data and name the contour in errors; they
//! also precompute the samples and the bounding-circle hierarchy of the contact search.

use crate::ensure;
use crate::error::Result;
use crate::geometry::gear::{Gear, GearSpec};
use crate::geometry::spline::{wrap, Quintic1, Spline1};

/// 2-vector of `f64`.
pub type Vec2 = nalgebra::Vector2<f64>;

/// `r, r', r'', r'''` at a parameter.
pub type Jet2 = [Vec2; 4];

/// 2-D cross product `a × b` (the z-component).
#[inline]
pub fn cross(a: &Vec2, b: &Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Whether a contour bulges out, is hollow, or both (from its sampled curvature).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Convexity {
    /// `κ ≥ 0` everywhere.
    Convex,
    /// `κ ≤ 0` everywhere.
    Concave,
    /// Both signs occur.
    Mixed,
}

impl Convexity {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Convexity::Convex => "convex",
            Convexity::Concave => "concave",
            Convexity::Mixed => "mixed",
        }
    }
}

/// Where a spline contour's solid lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solid {
    /// Left of the direction of increasing parameter.
    Left,
    /// Right of it.
    Right,
    /// Inside a closed curve (either orientation of the points).
    Inside,
    /// Outside a closed curve: a hole.
    Outside,
}

/// How a cam's follower touches it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Follower {
    /// A roller of `radius` (0: a knife edge) on a translating follower whose axis passes the cam
    /// centre at distance `eccentricity`.
    Roller {
        /// Roller radius (m), ≥ 0.
        radius: f64,
        /// Offset of the follower axis from the cam centre (m).
        eccentricity: f64,
    },
    /// A flat face perpendicular to the follower's axis.
    Flat,
}

#[derive(Debug, Clone, PartialEq)]
enum Shape {
    /// `c + R(φ) (a cos s, b sin s)`; `rot = (cos φ, sin φ)`.
    Ellipse { center: Vec2, a: f64, b: f64, rot: Vec2 },
    /// `(x(s), y(s))` with chord-length parameter.
    Spline { x: Spline1, y: Spline1 },
    /// A cam disc: the follower axis is the +y axis of the frame the cam turns in; at cam angle
    /// `s` the cam has turned by `dir · s`; `w = base + h(s)` is the follower's position along its
    /// axis (the roller centre, or the flat face).
    Cam { lift: Lift, base: f64, eccentricity: f64, dir: f64, flat: bool },
    /// An involute spur gear outline, arc-length parameter.
    Gear(Box<Gear>),
}

/// A cam's lift table as a periodic spline: quintic (C⁴) on equally spaced angles, else cubic.
#[derive(Debug, Clone, PartialEq)]
enum Lift {
    Cubic(Spline1),
    Quintic(Quintic1),
}

impl Lift {
    /// `[h, h', h'', h''', h'''']`.
    #[inline]
    fn eval(&self, s: f64) -> [f64; 5] {
        match self {
            Lift::Cubic(c) => {
                let j = c.eval(s);
                [j[0], j[1], j[2], j[3], 0.0]
            }
            Lift::Quintic(q) => q.eval(s),
        }
    }
}

/// One sample of the base curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Parameter.
    pub s: f64,
    /// Point of the base curve.
    pub r: Vec2,
    /// Outward normal of the base curve.
    pub nu: Vec2,
}

/// Consecutive samples `first..first + count` (and the piece of curve up to the next sample)
/// lie within `radius` of `center`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chunk {
    /// Centre of the bounding circle.
    pub center: Vec2,
    /// Radius of the bounding circle.
    pub radius: f64,
    /// First sample.
    pub first: usize,
    /// Number of samples.
    pub count: usize,
}

/// Samples per chunk of the bounding hierarchy.
pub const CHUNK: usize = 8;
/// Newton iterations of a contact-parameter search from one seed.
pub const NEWTON_ITERATIONS: usize = 40;
/// Newton stops when its step is below this fraction of the sample spacing (the quadratic
/// convergence leaves an error of about its square).
pub const CONVERGED: f64 = 1e-10;

/// A sign change of a function that increases through the wanted root (the derivative of a
/// distance at its minimum): negative at `lo`, positive at `hi`. A Newton step that leaves it is
/// replaced by bisection: where the curvature jumps (the joints of a gear's pieces, the corner
/// of a tip rounding seen from a flank) a damped Newton iteration can cycle about the root.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bracket {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
}

impl Bracket {
    pub(crate) fn new() -> Self {
        Bracket { lo: f64::NEG_INFINITY, hi: f64::INFINITY }
    }
    /// Records the sign of `f` at `x` (ignored if it contradicts the bracket: a maximum between).
    #[inline]
    pub(crate) fn update(&mut self, x: f64, f: f64) {
        if x > self.lo && x < self.hi {
            if f < 0.0 {
                self.lo = x;
            } else if f > 0.0 {
                self.hi = x;
            }
        }
    }
    /// `x + dx`, or the middle of the bracket if that leaves it (or lands on one of its ends:
    /// a step capped at exactly the distance back to an earlier iterate would cycle); steps
    /// below `tiny` (converged) are taken as they are.
    #[inline]
    pub(crate) fn step(&self, x: f64, dx: f64, tiny: f64) -> f64 {
        let y = x + dx;
        if dx.abs() > tiny && self.lo.is_finite() && self.hi.is_finite() && !(y > self.lo && y < self.hi) {
            0.5 * (self.lo + self.hi)
        } else {
            y
        }
    }
}

/// Upper bound on the samples of one curve (the search's stack buffers are this long).
pub const MAX_SAMPLES: usize = 4096;

/// A planar parametric contour in a body frame (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    shape: Shape,
    offset: f64,
    sigma: f64,
    lo: f64,
    hi: f64,
    closed: bool,
    samples: Vec<Sample>,
    chunks: Vec<Chunk>,
    /// Largest parameter step between samples.
    step: f64,
    /// Bounding circle of the contour (offset included).
    bound: (Vec2, f64),
    convexity: Convexity,
    /// Smallest and largest signed curvature of the contour (sampled).
    kappa_range: (f64, f64),
}

impl Curve {
    /// An ellipse with semi-axes `a` (along the rotated x axis) and `b`, centre `center`, turned
    /// by `angle` (rad) about z; parameter `s ∈ [0, 2π)`: `r = c + R(angle) (a cos s, b sin s)`.
    ///
    /// # Example
    /// ```
    /// use mechsys_core::geometry::curve::{Curve, Vec2};
    /// let e = Curve::ellipse(Vec2::zeros(), 2.0, 1.0, 0.0, "contour 'egg'")?;
    /// // curvature a/b² at the end of the major axis
    /// assert!((e.curvature(0.0) - 2.0).abs() < 1e-14);
    /// assert!(Curve::ellipse(Vec2::zeros(), 0.0, 1.0, 0.0, "contour 'egg'").is_err());
    /// # Ok::<(), mechsys_core::Error>(())
    /// ```
    pub fn ellipse(center: Vec2, a: f64, b: f64, angle: f64, what: &str) -> Result<Curve> {
        ensure!(center.iter().all(|v| v.is_finite()), Model, "{what}: ellipse center must be finite");
        for (k, v) in [("semi-axis a", a), ("semi-axis b", b)] {
            ensure!(v > 0.0 && v.is_finite(), Model, "{what}: ellipse {k} must be > 0 and finite, got {v}");
        }
        ensure!(angle.is_finite(), Model, "{what}: ellipse angle must be finite, got {angle}");
        let shape = Shape::Ellipse { center, a, b, rot: Vec2::new(angle.cos(), angle.sin()) };
        Curve::build(shape, 0.0, 1.0, 0.0, std::f64::consts::TAU, true, 64, what)
    }

    /// A C² cubic spline through `points` with chord-length parameter: `closed` makes it periodic
    /// (do not repeat the first point; a repeated last point is dropped), else natural and
    /// continued along its end tangents. `solid` says where the body's material is: left or
    /// right of the points' direction, or (closed curves) inside or outside (a hole, a bore, a
    /// groove seen from within). Refused: fewer than 2 (open) or 3 (closed)
    /// points, coincident consecutive points, data that turns back on itself (a corner the
    /// spline would overshoot), a self-intersecting curve, non-finite values.
    pub fn spline(points: &[Vec2], closed: bool, solid: Solid, what: &str) -> Result<Curve> {
        let mut p: Vec<Vec2> = points.to_vec();
        for (i, v) in p.iter().enumerate() {
            ensure!(
                v.iter().all(|x| x.is_finite()),
                Model,
                "{what}: spline point {i} is not finite ({}, {})",
                v.x,
                v.y
            );
        }
        let scale = p.iter().map(|v| v.norm()).fold(0.0, f64::max).max(1e-300);
        if closed && p.len() > 1 && (p[p.len() - 1] - p[0]).norm() <= 1e-12 * scale {
            p.pop();
        }
        let min = if closed { 3 } else { 2 };
        ensure!(
            p.len() >= min,
            Model,
            "{what}: a {} spline needs at least {min} points, got {}",
            if closed { "closed" } else { "open" },
            p.len()
        );
        let n = p.len();
        let segs = if closed { n } else { n - 1 };
        for i in 0..segs {
            let j = (i + 1) % n;
            ensure!(
                (p[j] - p[i]).norm() > 1e-9 * scale,
                Model,
                "{what}: spline points {i} and {j} coincide ({}, {}); a zero-length segment has no tangent",
                p[i].x,
                p[i].y
            );
        }
        // data that doubles back (a corner of more than 120°) makes the interpolant loop
        for i in 0..n {
            if !closed && (i == 0 || i == n - 1) {
                continue;
            }
            let (a, b, c) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
            let (e1, e2) = ((b - a).normalize(), (c - b).normalize());
            let turn = cross(&e1, &e2).atan2(e1.dot(&e2)).abs();
            ensure!(
                turn < 2.0 * std::f64::consts::FRAC_PI_3,
                Model,
                "{what}: the spline data turns by {:.0}° at point {i} ({}, {}): a corner that sharp is not smooth; \
                 round it with more points",
                turn.to_degrees(),
                b.x,
                b.y
            );
        }
        let mut t = vec![0.0];
        for i in 0..segs {
            let j = (i + 1) % n;
            t.push(t[i] + (p[j] - p[i]).norm());
        }
        let xs: Vec<f64> = (0..=segs).map(|i| p[i % n].x).collect();
        let ys: Vec<f64> = (0..=segs).map(|i| p[i % n].y).collect();
        let (x, y) = if closed {
            (Spline1::periodic(&t, &xs, what)?, Spline1::periodic(&t, &ys, what)?)
        } else {
            (Spline1::natural(&t, &xs, what)?, Spline1::natural(&t, &ys, what)?)
        };
        let per = (8 * segs).clamp(32, MAX_SAMPLES);
        let sigma = match (solid, closed) {
            (Solid::Left, _) => 1.0,
            (Solid::Right, _) => -1.0,
            (Solid::Inside | Solid::Outside, false) => {
                return Err(crate::Error::Model(format!(
                "{what}: an open curve has no inside; put its solid on the left or the right of the points' direction"
            )))
            }
            (Solid::Inside | Solid::Outside, true) => {
                // the shoelace area is positive for counter-clockwise points, whose inside is on the left
                let area: f64 = (0..n).map(|i| cross(&p[i], &p[(i + 1) % n])).sum();
                let ccw = if area > 0.0 { 1.0 } else { -1.0 };
                if solid == Solid::Inside {
                    ccw
                } else {
                    -ccw
                }
            }
        };
        let curve = Curve::build(Shape::Spline { x, y }, 0.0, sigma, 0.0, t[segs], closed, per, what)?;
        curve.check_simple(what)?;
        Ok(curve)
    }

    /// A cam disc from a periodic lift table: `angles` (rad, increasing, from 0 to 2π inclusive)
    /// and `lift` (m) with `lift[last] = lift[0]` (a table ending before 2π is closed with the
    /// first value), interpolated by a periodic quintic spline (C⁴) when the angles are equally
    /// spaced, else by a periodic cubic spline (C²). `base_radius` is the radius of the cam's base circle (its profile where the
    /// lift is 0). The cam turns about its body's z axis by `direction · angle` (`direction` ±1);
    /// the follower translates along the +y axis of the frame it turns in (the cam body at
    /// angle 0), so at cam angle θ the follower is at `base_radius (+ roller radius) + h(θ)`.
    /// A roller or knife edge: the profile is the pitch curve offset inward by the roller
    /// radius (refused where the roller would undercut it); flat-faced: the envelope of the
    /// face (refused where `R_b + h + h'' ≤ 0`, which would need a concave profile).
    pub fn cam(
        angles: &[f64],
        lift: &[f64],
        base_radius: f64,
        follower: Follower,
        direction: f64,
        what: &str,
    ) -> Result<Curve> {
        ensure!(
            base_radius > 0.0 && base_radius.is_finite(),
            Model,
            "{what}: cam base_radius must be > 0, got {base_radius}"
        );
        ensure!(
            direction == 1.0 || direction == -1.0,
            Model,
            "{what}: cam direction must be +1 or -1, got {direction}"
        );
        ensure!(
            angles.len() == lift.len(),
            Model,
            "{what}: cam lift table has {} angles but {} lifts",
            angles.len(),
            lift.len()
        );
        ensure!(angles.len() >= 3, Model, "{what}: cam lift table needs at least 3 rows, got {}", angles.len());
        let tau = std::f64::consts::TAU;
        let (mut t, mut h) = (angles.to_vec(), lift.to_vec());
        ensure!(t[0].abs() < 1e-12, Model, "{what}: cam lift table must start at angle 0, got {}", t[0]);
        t[0] = 0.0;
        let last = t[t.len() - 1];
        let hmax = h.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if (last - tau).abs() < 1e-9 {
            let n = t.len() - 1;
            t[n] = tau;
            ensure!(
                (h[n] - h[0]).abs() <= 1e-9 * (base_radius + hmax),
                Model,
                "{what}: the cam lift table is not periodic: lift {} at 2π but {} at 0",
                h[n],
                h[0]
            );
            h[n] = h[0];
        } else {
            ensure!(last < tau, Model, "{what}: cam lift angles must lie in [0, 2π], the last is {last}");
            t.push(tau);
            h.push(h[0]);
        }
        // equally spaced angles (a sampled lift function, most tables): a C⁴ quintic spline, so
        // the follower's jerk stays continuous; otherwise a C² cubic
        let spline = match Quintic1::periodic(&t, &h, what)? {
            Some(q) => Lift::Quintic(q),
            None => Lift::Cubic(Spline1::periodic(&t, &h, what)?),
        };
        let (eccentricity, radius, flat) = match follower {
            Follower::Roller { radius, eccentricity } => {
                ensure!(
                    radius >= 0.0 && radius.is_finite(),
                    Model,
                    "{what}: cam roller radius must be ≥ 0, got {radius}"
                );
                ensure!(
                    eccentricity.abs() < base_radius + radius,
                    Model,
                    "{what}: the follower's eccentricity {eccentricity} must be smaller than base_radius + roller radius"
                );
                (eccentricity, radius, false)
            }
            Follower::Flat => (0.0, 0.0, true),
        };
        let base = if flat { base_radius } else { ((base_radius + radius).powi(2) - eccentricity.powi(2)).sqrt() };
        let per = (4 * t.len()).clamp(360, MAX_SAMPLES);
        let shape = Shape::Cam { lift: spline, base, eccentricity, dir: direction, flat };
        // the roller profile is the pitch curve offset inward by the roller radius; turning the
        // cam forward moves the follower's point backward around it, so the solid is on the
        // right of increasing cam angle when the cam turns counter-clockwise
        let curve = Curve::build(shape, -radius, -direction, 0.0, tau, true, per, what)?;
        for smp in &curve.samples {
            let j = curve.eval(smp.s);
            let k = curve.curvature_of(&j);
            if flat {
                ensure!(
                    base_radius + curve.lift(smp.s)[0] + curve.lift(smp.s)[2] > 0.0,
                    Model,
                    "{what}: a flat-faced follower needs R_b + h + h'' > 0, but it is {:.4e} at cam angle {:.2}°; \
                     enlarge the base circle or smooth the lift",
                    base_radius + curve.lift(smp.s)[0] + curve.lift(smp.s)[2],
                    smp.s.to_degrees()
                );
            } else {
                ensure!(
                    base + curve.lift(smp.s)[0] > 0.0,
                    Model,
                    "{what}: the cam lift {} at cam angle {:.2}° goes below the cam centre",
                    curve.lift(smp.s)[0],
                    smp.s.to_degrees()
                );
                ensure!(
                    1.0 - radius * k > 0.0,
                    Model,
                    "{what}: the roller (radius {radius}) undercuts the cam at cam angle {:.2}°: the pitch curve's radius \
                     of curvature there is {:.4e}; use a smaller roller or a larger base circle",
                    smp.s.to_degrees(),
                    1.0 / k
                );
            }
        }
        curve.check_simple(what)?;
        Ok(curve)
    }

    /// An external involute spur gear outline (see [`crate::geometry::gear`] for the geometry):
    /// one closed G1 contour, solid inside, parameterized by its arc length from the middle of the
    /// gap before tooth 0, counter-clockwise. Refused, naming the contour: fewer than 5 teeth,
    /// a non-positive module, a pressure angle outside (0°, 60°), teeth that fill the pitch,
    /// pointed teeth, a tip inside the base circle, roundings that do not fit.
    ///
    /// # Example
    /// ```
    /// use mechsys_core::geometry::curve::Curve;
    /// use mechsys_core::geometry::gear::GearSpec;
    /// let c = Curve::gear(&GearSpec::new(0.002, 17), "contour 'pinion'")?;
    /// let g = c.as_gear().unwrap();
    /// assert!((g.base_radius() - 0.017 * 20f64.to_radians().cos()).abs() < 1e-15);
    /// assert!(Curve::gear(&GearSpec::new(0.002, 3), "contour 'pinion'").is_err());
    /// # Ok::<(), mechsys_core::Error>(())
    /// ```
    pub fn gear(spec: &GearSpec, what: &str) -> Result<Curve> {
        let gear = Gear::new(spec, what)?;
        let (period, per) = (gear.period(), gear.samples());
        // the curvature's range in closed form (the samples may step over the small roundings):
        // the fillet's -1/ρ_f, the tip rounding's 1/ρ_a or the involute's 1/(r_b φ) at its start
        let (rho_a, rho_f) = gear.roundings();
        let kmax = (1.0 / rho_a).max(1.0 / (gear.base_radius() * gear.roll_range().0));
        let mut c = Curve::build(Shape::Gear(Box::new(gear)), 0.0, 1.0, 0.0, period, true, per, what)?;
        c.kappa_range = (-1.0 / rho_f, kmax);
        c.convexity = Convexity::Mixed;
        Ok(c)
    }

    /// The gear's geometry (radii, roll angles, pieces) if this contour is a gear.
    pub fn as_gear(&self) -> Option<&Gear> {
        match &self.shape {
            Shape::Gear(g) => Some(g),
            _ => None,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn build(
        shape: Shape,
        offset: f64,
        sigma: f64,
        lo: f64,
        hi: f64,
        closed: bool,
        per: usize,
        what: &str,
    ) -> Result<Curve> {
        let mut c = Curve {
            shape,
            offset,
            sigma,
            lo,
            hi,
            closed,
            samples: Vec::new(),
            chunks: Vec::new(),
            step: (hi - lo) / per as f64,
            bound: (Vec2::zeros(), 0.0),
            convexity: Convexity::Convex,
            kappa_range: (0.0, 0.0),
        };
        let count = if closed { per } else { per + 1 };
        let (mut kmin, mut kmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..count {
            let s = lo + (hi - lo) * i as f64 / per as f64;
            let j = c.eval(s);
            let speed = j[1].norm();
            ensure!(
                speed > 0.0 && speed.is_finite() && j[0].iter().all(|v| v.is_finite()),
                Model,
                "{what}: the curve is degenerate at parameter {s:.6} (zero or undefined tangent)"
            );
            let k = c.curvature_of(&j);
            kmin = kmin.min(k);
            kmax = kmax.max(k);
            c.samples.push(Sample { s, r: j[0], nu: c.outward(&j[1]) });
        }
        let tiny = 1e-9 * (kmax.abs().max(kmin.abs()));
        c.convexity = if kmin >= -tiny {
            Convexity::Convex
        } else if kmax <= tiny {
            Convexity::Concave
        } else {
            Convexity::Mixed
        };
        c.kappa_range = (kmin, kmax);
        // chunks: samples first..first+count and the curve up to the following sample
        let n = c.samples.len();
        let mut first = 0;
        let mut lo_b = Vec2::repeat(f64::INFINITY);
        let mut hi_b = Vec2::repeat(f64::NEG_INFINITY);
        while first < n {
            let count = CHUNK.min(n - first);
            let last = if closed { (first + count) % n } else { (first + count).min(n - 1) };
            let pts = (first..first + count).map(|i| c.samples[i].r).chain(std::iter::once(c.samples[last].r));
            let (mut a, mut b) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
            let mut chord: f64 = 0.0;
            let mut prev: Option<Vec2> = None;
            for p in pts {
                a = a.inf(&p);
                b = b.sup(&p);
                if let Some(q) = prev {
                    chord = chord.max((p - q).norm());
                }
                prev = Some(p);
            }
            let center = (a + b) * 0.5;
            let far = (first..first + count)
                .map(|i| c.samples[i].r)
                .chain(std::iter::once(c.samples[last].r))
                .map(|p| (p - center).norm())
                .fold(0.0, f64::max);
            // a piece between samples bulges at most half its chord beyond them (well-sampled)
            c.chunks.push(Chunk { center, radius: far + 0.5 * chord, first, count });
            lo_b = lo_b.inf(&a);
            hi_b = hi_b.sup(&b);
            first += count;
        }
        let center = (lo_b + hi_b) * 0.5;
        let r = c.chunks.iter().map(|k| (k.center - center).norm() + k.radius).fold(0.0, f64::max);
        c.bound = (center, r + offset.max(0.0));
        Ok(c)
    }

    /// Refuses a self-intersecting base curve (pairs of sample chords that cross).
    fn check_simple(&self, what: &str) -> Result<()> {
        let n = self.samples.len();
        let segs = if self.closed { n } else { n - 1 };
        let seg = |i: usize| (self.samples[i].r, self.samples[(i + 1) % n].r);
        for i in 0..segs {
            let (a, b) = seg(i);
            for j in i + 2..segs {
                if self.closed && i == 0 && j == segs - 1 {
                    continue;
                }
                let (c, d) = seg(j);
                let (d1, d2) = (b - a, d - c);
                let den = cross(&d1, &d2);
                if den.abs() < 1e-300 {
                    continue;
                }
                let u = cross(&(c - a), &d2) / den;
                let v = cross(&(c - a), &d1) / den;
                // half-open: two chords through one sample point cross there too
                ensure!(
                    !((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v)),
                    Model,
                    "{what}: the curve intersects itself near ({:.4}, {:.4}) (parameters {:.4} and {:.4})",
                    a.x + u * d1.x,
                    a.y + u * d1.y,
                    self.samples[i].s,
                    self.samples[j].s
                );
            }
        }
        Ok(())
    }

    /// The same curve with the solid on its other side: an ellipse's or a closed spline's
    /// complement (an elliptical hole, a bore), an open track's other side.
    pub fn flipped(mut self) -> Curve {
        self.sigma = -self.sigma;
        for smp in &mut self.samples {
            smp.nu = -smp.nu;
        }
        self.offset = -self.offset;
        self.kappa_range = (-self.kappa_range.1, -self.kappa_range.0);
        self.convexity = match self.convexity {
            Convexity::Convex => Convexity::Concave,
            Convexity::Concave => Convexity::Convex,
            Convexity::Mixed => Convexity::Mixed,
        };
        let (center, r) = self.bound;
        self.bound = (center, r + self.offset.abs());
        self
    }

    /// Lift `[h, h', h'', h''', h'''']` of a cam at cam angle `s` (zeros for other shapes).
    fn lift(&self, s: f64) -> [f64; 5] {
        match &self.shape {
            Shape::Cam { lift, .. } => lift.eval(s),
            _ => [0.0; 5],
        }
    }

    /// `r, r', r'', r'''` of the base curve at `s` (closed curves wrap; open curves continue
    /// straight beyond their ends). No allocation.
    #[inline]
    pub fn eval(&self, s: f64) -> Jet2 {
        match &self.shape {
            Shape::Ellipse { center, a, b, rot } => {
                let (sn, cs) = s.sin_cos();
                let turn = |v: Vec2| Vec2::new(rot.x * v.x - rot.y * v.y, rot.y * v.x + rot.x * v.y);
                [
                    center + turn(Vec2::new(a * cs, b * sn)),
                    turn(Vec2::new(-a * sn, b * cs)),
                    turn(Vec2::new(-a * cs, -b * sn)),
                    turn(Vec2::new(a * sn, -b * cs)),
                ]
            }
            Shape::Spline { x, y } => {
                let (jx, jy) = (x.eval(s), y.eval(s));
                [Vec2::new(jx[0], jy[0]), Vec2::new(jx[1], jy[1]), Vec2::new(jx[2], jy[2]), Vec2::new(jx[3], jy[3])]
            }
            Shape::Cam { lift, base, eccentricity, dir, flat } => {
                let h = lift.eval(s);
                let (sn, cs) = s.sin_cos();
                let d = *dir;
                // a: the cam-frame image of the follower frame's x axis, u: of its y axis
                // (the cam has turned by d·s); a' = -d u, u' = d a
                let a = Vec2::new(cs, -d * sn);
                let u = Vec2::new(d * sn, cs);
                if *flat {
                    // envelope of the face lines u·x = ρ: x = ρ u + d ρ' a
                    let (r0, r1, r2, r3, r4) = (base + h[0], h[1], h[2], h[3], h[4]);
                    [
                        u * r0 + a * (d * r1),
                        a * (d * (r0 + r2)),
                        a * (d * (r1 + r3)) - u * (r0 + r2),
                        a * (d * (r4 - r0)) - u * (2.0 * (r1 + r3)),
                    ]
                } else {
                    // pitch curve p = e a + w u, w = base + h
                    let (w0, w1, w2, w3) = (base + h[0], h[1], h[2], h[3]);
                    let e = *eccentricity;
                    [
                        a * e + u * w0,
                        u * (w1 - d * e) + a * (d * w0),
                        u * (w2 - w0) + a * (2.0 * d * w1 - e),
                        u * (w3 - 3.0 * w1 + d * e) + a * (d * (3.0 * w2 - w0)),
                    ]
                }
            }
            Shape::Gear(g) => g.eval(s),
        }
    }

    /// Outward unit normal of the base curve for the tangent vector `r1`.
    #[inline]
    pub fn outward(&self, r1: &Vec2) -> Vec2 {
        Vec2::new(r1.y, -r1.x) * (self.sigma / r1.norm())
    }

    /// Signed curvature of the base curve from its jet (convex > 0).
    #[inline]
    pub fn curvature_of(&self, j: &Jet2) -> f64 {
        self.sigma * cross(&j[1], &j[2]) / j[1].norm().powi(3)
    }

    /// Signed curvature of the contour (offset included) at `s`: `κ / (1 + o κ)`.
    pub fn curvature(&self, s: f64) -> f64 {
        let k = self.curvature_of(&self.eval(s));
        k / (1.0 + self.offset * k)
    }

    /// The contour's geometry at `s`: point, unit tangent (direction of increasing `s`), outward
    /// normal, signed curvature κ and its derivative per arc length dκ/dσ (offset included).
    pub fn frame(&self, s: f64) -> CurveFrame {
        let j = self.eval(s);
        let l = j[1].norm();
        let x = cross(&j[1], &j[2]);
        let xd = cross(&j[1], &j[3]);
        let ld = j[1].dot(&j[2]) / l;
        let k = self.sigma * x / l.powi(3);
        // dκ/ds of the base curve, then per arc length of the base curve
        let kd = self.sigma * (xd / l.powi(3) - 3.0 * x * ld / l.powi(4)) / l;
        let o = self.offset;
        let den = 1.0 + o * k;
        let nu = self.outward(&j[1]);
        // the offset curve's arc length grows by the factor (1 + o κ)
        CurveFrame {
            point: j[0] + nu * o,
            tangent: j[1] / l,
            normal: nu,
            curvature: k / den,
            curvature_rate: kd / (den * den * den),
        }
    }

    /// The foot point of `y` (body frame) on the base curve by Newton on `F(s) = (y - r)·r'` from
    /// `s`, steps limited to two sample spacings and kept within the sign change of `F` once one
    /// is known ([`Bracket`]); `None` unless it converges to a distance minimum (a maximum — the
    /// far side of a hollow arc — is refused), else the foot point's parameter and the jet there.
    /// No allocation.
    pub fn foot(&self, y: &Vec2, mut s: f64) -> Option<(f64, Jet2)> {
        let cap = 2.0 * self.step;
        let mut bracket = Bracket::new();
        for _ in 0..NEWTON_ITERATIONS {
            let j = self.eval(s);
            let d = y - j[0];
            let f = d.dot(&j[1]);
            let fs = -j[1].norm_squared() + d.dot(&j[2]);
            // -F is the derivative of half the squared distance
            bracket.update(s, -f);
            if !(fs < 0.0) {
                // not a minimum direction here: step along the gradient of the squared distance
                let ds = (f / j[1].norm_squared()).clamp(-cap, cap);
                s = bracket.step(s, ds, 0.0);
                continue;
            }
            let next = bracket.step(s, (-f / fs).clamp(-cap, cap), CONVERGED * self.step);
            let ds = next - s;
            s = next;
            if ds.abs() <= CONVERGED * self.step {
                let j = self.eval(s);
                let fs = -j[1].norm_squared() + (y - j[0]).dot(&j[2]);
                return (fs < 0.0).then_some((s, j));
            }
        }
        None
    }

    /// The parameter of the contour point nearest to `y` (body frame): the nearest sample,
    /// refined by [`Self::foot`] (the sample itself if that does not converge). For queries,
    /// not the step loop.
    pub fn closest_parameter(&self, y: &Vec2) -> f64 {
        let best = self
            .samples
            .iter()
            .min_by(|a, b| (y - a.r).norm_squared().total_cmp(&(y - b.r).norm_squared()))
            .map(|smp| smp.s)
            .unwrap_or(self.lo);
        self.foot(y, best).map(|(s, _)| self.wrap(s)).unwrap_or(best)
    }

    /// Parameter range `[lo, hi]` (the period for closed curves).
    pub fn range(&self) -> (f64, f64) {
        (self.lo, self.hi)
    }

    /// Whether the curve is closed (periodic).
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Offset of the contour from its base curve along the outward normal.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// Convex, concave or mixed.
    pub fn convexity(&self) -> Convexity {
        self.convexity
    }

    /// Smallest and largest sampled curvature of the contour (offset included).
    pub fn curvature_range(&self) -> (f64, f64) {
        let o = self.offset;
        let f = |k: f64| k / (1.0 + o * k);
        (f(self.kappa_range.0), f(self.kappa_range.1))
    }

    /// Samples of the base curve.
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// Bounding-circle hierarchy over the samples.
    pub fn chunks(&self) -> &[Chunk] {
        &self.chunks
    }

    /// Largest parameter step between samples.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// How far beyond the closest point a search for several contact points looks, where the
    /// contour knows the scale of its features: a gear's module (the flanks in mesh, drive and
    /// coast, lie within the backlash of each other, a fraction of it). `None`: the search uses a
    /// tenth of the bounding radius.
    pub fn reach(&self) -> Option<f64> {
        self.as_gear().map(|g| g.spec().module)
    }

    /// Bounding circle of the contour (centre, radius), offset included.
    pub fn bound(&self) -> (Vec2, f64) {
        self.bound
    }

    /// Name of the shape for messages ("ellipse", "spline", "cam", "gear").
    pub fn shape_name(&self) -> &'static str {
        match self.shape {
            Shape::Ellipse { .. } => "ellipse",
            Shape::Spline { .. } => "spline",
            Shape::Cam { .. } => "cam",
            Shape::Gear(_) => "gear",
        }
    }

    /// `s` brought into the parameter range of a closed curve (unchanged for open ones).
    #[inline]
    pub fn wrap(&self, s: f64) -> f64 {
        if self.closed {
            wrap(s, self.lo, self.hi)
        } else {
            s
        }
    }
}

/// The moving trihedral of a planar contour at one parameter (eqs. 2.89–2.90; the binormal is
/// the body's z axis for a contour whose solid is on the left).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveFrame {
    /// Contour point (offset included).
    pub point: Vec2,
    /// Unit tangent, direction of increasing parameter.
    pub tangent: Vec2,
    /// Outward unit normal.
    pub normal: Vec2,
    /// Signed curvature (1/m), convex > 0.
    pub curvature: f64,
    /// Derivative of the curvature per arc length of the contour (1/m²).
    pub curvature_rate: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    fn fd_check(c: &Curve, s: f64) {
        let h = 1e-5;
        let (jm, j0, jp) = (c.eval(s - h), c.eval(s), c.eval(s + h));
        for k in 0..3 {
            let fd = (jp[k] - jm[k]) / (2.0 * h);
            assert!(
                (fd - j0[k + 1]).norm() < 1e-6 * (1.0 + j0[k + 1].norm()),
                "{} derivative {k} at {s}: {fd} vs {}",
                c.shape_name(),
                j0[k + 1]
            );
        }
        // curvature rate per arc length of the contour against differences
        let (fm, f0, fp) = (c.frame(s - h), c.frame(s), c.frame(s + h));
        let dsigma = (fp.point - fm.point).norm();
        let fd = (fp.curvature - fm.curvature) / dsigma;
        assert!(
            (fd - f0.curvature_rate).abs() < 1e-5 * (1.0 + f0.curvature_rate.abs()),
            "{} (offset {}) at {s}: κ' {fd} vs {}",
            c.shape_name(),
            c.offset(),
            f0.curvature_rate
        );
        // outward normal ⟂ tangent, eq. 2.89: t' = -κ ν per arc length (ν outward = -n)
        let tfd = (fp.tangent - fm.tangent) / dsigma;
        assert!((tfd + f0.normal * f0.curvature).norm() < 1e-5 * (1.0 + f0.curvature.abs()));
    }

    #[test]
    fn ellipse_curvature_matches_closed_form() {
        let (a, b) = (0.3, 0.1);
        let e = Curve::ellipse(Vec2::new(0.1, -0.2), a, b, 0.4, "e").unwrap();
        for s in [0.0, 0.3, 1.0, PI / 2.0, 2.5, 4.0] {
            // κ = ab / (a² sin² + b² cos²)^{3/2}
            let k = a * b / (a * a * s.sin().powi(2) + b * b * s.cos().powi(2)).powf(1.5);
            assert!((e.curvature(s) - k).abs() < 1e-12 * k, "{s}");
            fd_check(&e, s);
        }
        assert_eq!(e.convexity(), Convexity::Convex);
        // outward normal points away from the centre
        let f = e.frame(0.0);
        assert!((f.point - Vec2::new(0.1, -0.2)).dot(&f.normal) > 0.0);
    }

    #[test]
    fn spline_through_circle_points_approaches_the_circle_and_knows_its_side() {
        let pts: Vec<Vec2> =
            (0..48).map(|i| TAU * i as f64 / 48.0).map(|t| Vec2::new(t.cos(), t.sin()) * 0.5).collect();
        let c = Curve::spline(&pts, true, Solid::Inside, "ring").unwrap();
        // between knots (r''' jumps at the knots)
        for s in [0.013, 0.37, 1.21, 2.9] {
            let f = c.frame(s);
            assert!((f.point.norm() - 0.5).abs() < 2e-6, "{}", f.point.norm());
            // chord-length splines approximate the curvature at second order in the spacing (0.065)
            assert!((f.curvature - 2.0).abs() < 5e-3, "{}", f.curvature);
            fd_check(&c, s);
        }
        // the points reversed: still the disc (inside), or its complement (a bore)
        let rev: Vec<Vec2> = pts.iter().rev().cloned().collect();
        let disc = Curve::spline(&rev, true, Solid::Inside, "disc").unwrap();
        assert_eq!(disc.convexity(), Convexity::Convex);
        assert!((disc.curvature(0.3) - 2.0).abs() < 5e-3);
        let hole = Curve::spline(&rev, true, Solid::Outside, "bore").unwrap();
        assert_eq!(hole.convexity(), Convexity::Concave);
        assert!(hole.frame(0.3).normal.dot(&hole.frame(0.3).point) < 0.0);
        assert!((hole.curvature(0.3) + 2.0).abs() < 5e-3);
        // left/right follow the direction of the points
        assert_eq!(Curve::spline(&pts, true, Solid::Right, "x").unwrap().convexity(), Convexity::Concave);
        let e = Curve::spline(&pts[..5], false, Solid::Inside, "contour 'x'").unwrap_err();
        assert!(e.to_string().contains("open curve has no inside"), "{e}");
    }

    #[test]
    fn bad_spline_data_is_named() {
        let err = |p: &[(f64, f64)], closed: bool| {
            let pts: Vec<Vec2> = p.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
            Curve::spline(&pts, closed, Solid::Left, "contour 'track'").unwrap_err().to_string()
        };
        assert!(err(&[(0.0, 0.0)], false).contains("at least 2 points"));
        assert!(err(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (2.0, 1.0)], false).contains("points 1 and 2 coincide"));
        assert!(err(&[(0.0, 0.0), (1.0, 0.0), (0.0, 0.1)], false).contains("turns by"));
        let bow = [(0.0, 0.0), (1.0, 1.0), (2.0, 0.0), (2.0, 1.0), (1.0, 0.0), (0.0, 1.0)];
        let e = err(&bow, true);
        assert!(e.contains("intersects itself") || e.contains("turns by"), "{e}");
        let e = err(&[(0.0, 0.0), (f64::NAN, 0.0), (1.0, 1.0)], false);
        assert!(e.contains("contour 'track'") && e.contains("point 1 is not finite"), "{e}");
    }

    #[test]
    fn cam_pitch_curve_follows_the_lift_and_derivatives_match() {
        // a harmonic lift h = H (1 - cos θ) / 2
        let n = 72;
        let ang: Vec<f64> = (0..=n).map(|i| TAU * i as f64 / n as f64).collect();
        let lift: Vec<f64> = ang.iter().map(|t| 0.004 * (1.0 - t.cos())).collect();
        for (follower, dir) in [
            (Follower::Roller { radius: 0.01, eccentricity: 0.0 }, 1.0),
            (Follower::Roller { radius: 0.008, eccentricity: 0.005 }, -1.0),
            (Follower::Flat, 1.0),
        ] {
            let c = Curve::cam(&ang, &lift, 0.03, follower, dir, "cam").unwrap();
            for s in [0.1, 1.0, 2.0, 3.3, 5.9] {
                fd_check(&c, s);
                // the follower frame at cam angle s: the cam point seen from there
                let (sn, cs) = (dir * s).sin_cos();
                let to_follower = |v: Vec2| Vec2::new(cs * v.x - sn * v.y, sn * v.x + cs * v.y);
                let h = c.lift(s)[0];
                match follower {
                    Follower::Roller { radius, eccentricity } => {
                        let p = to_follower(c.eval(s)[0]);
                        let base = ((0.03 + radius).powi(2) - eccentricity * eccentricity).sqrt();
                        assert!((p.x - eccentricity).abs() < 1e-14 && (p.y - base - h).abs() < 1e-14);
                    }
                    Follower::Flat => {
                        // the envelope point lies on the face line y = R_b + h, and the face is tangent there
                        let f = c.frame(s);
                        assert!((to_follower(f.point).y - 0.03 - h).abs() < 1e-14);
                        assert!((to_follower(f.normal) - Vec2::y()).norm() < 1e-12);
                    }
                }
            }
            assert_eq!(c.convexity(), Convexity::Convex);
        }
    }

    #[test]
    fn bad_cam_data_is_named() {
        let ang = [0.0, 2.0, 4.0, TAU];
        let e = Curve::cam(&ang, &[0.0, 0.01, 0.0, 0.002], 0.03, Follower::Flat, 1.0, "contour 'cam'").unwrap_err();
        assert!(e.to_string().contains("not periodic"), "{e}");
        // a sharp lift needs R_b + h + h'' > 0 for a flat face
        let n = 36;
        let a: Vec<f64> = (0..=n).map(|i| TAU * i as f64 / n as f64).collect();
        let h: Vec<f64> = a.iter().map(|t| 0.02 * (1.0 - (3.0 * t).cos())).collect();
        let e = Curve::cam(&a, &h, 0.01, Follower::Flat, 1.0, "contour 'cam'").unwrap_err();
        assert!(e.to_string().contains("R_b + h + h''"), "{e}");
        let e = Curve::cam(&a, &h, 0.01, Follower::Roller { radius: 0.05, eccentricity: 0.0 }, 1.0, "contour 'cam'")
            .unwrap_err();
        assert!(e.to_string().contains("undercuts"), "{e}");
        assert!(Curve::cam(&[0.0, 1.0], &[0.0, 0.0], 0.01, Follower::Flat, 1.0, "c").is_err());
    }
}
