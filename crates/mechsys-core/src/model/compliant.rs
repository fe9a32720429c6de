//! Compliant contacts (section 2.5.4, the first way of modelling impacts: a contact zone that
//! deforms, with forces over a finite duration): a contact whose normal force is a function of
//! the overlap `δ = −g_N` and its rate `δ̇ = −ġ_N`, evaluated on the same contour geometry as a
//! rigid contact and applied as a force element (`Jᵀ F`), so it runs in every scheme.
//!
//! Normal laws (all with the non-adhesive cut-off `F = max(0, ·)`):
//!
//! - Kelvin–Voigt: `F = k δ + d δ̇`;
//! - Hertz point contact: `F = K δ^{3/2}`, `K = (4/3) E* √R` for a circular contact
//!   (`1/R = κ₁ + κ₂`), and in general from the relative principal curvatures `A ≤ B` through the
//!   eccentricity `e` of the contact ellipse (Hertz's elliptic-integral solution):
//!   `B/A = (E(e)/(1−e²) − K(e)) / (K(e) − E(e))`, `K = (2π E*/(3 K(e))) √((K(e) − E(e)) / (A e² K(e)))`;
//! - Johnson's line contact (a cylinder of radius R and length L on a plane, or two parallel
//!   cylinders with `R = R₁R₂/(R₁+R₂)`): `δ = (F/(π L E*)) (ln(4π L E* R / F) − 1)`, solved for F;
//! - dissipative Hertz-type laws `F = F_el(δ) (1 + α δ̇)`, α either given (s/m) or from a
//!   restitution ε and the approach speed `v⁻` at the contact's onset:
//!   Hunt–Crossley `α = 3(1−ε)/(2v⁻)`, Lankarani–Nikravesh `α = 3(1−ε²)/(4v⁻)`, Flores
//!   `α = 8(1−ε)/(5ε v⁻)`. Each is derived under its own approximation, so the restitution a law
//!   achieves differs from ε; for a Hertz point contact (measured in `tests/test_compliant.py`
//!   against SciPy) ε = 0.2, 0.5, 0.8 give 0.547, 0.663, 0.833 (Hunt–Crossley), 0.672, 0.725,
//!   0.847 (Lankarani–Nikravesh, derived for small dissipation) and 0.156, 0.470, 0.789 (Flores,
//!   the closest);
//! - a user law `F(δ, δ̇)` (a Python callable, slow).
//!
//! `E* = 1 / ((1−ν₁²)/E₁ + (1−ν₂²)/E₂)` from the two contours' materials.
//!
//! Tangential forces: the contact's friction law (Coulomb, Stribeck, table) regularized with a
//! velocity `v_reg`, `F_T = −µ(|v|) F_N tanh(|v|/v_reg) v/|v|` (a contact under a tangential load
//! below µ F_N creeps at `v = v_reg atanh(F_T/(µ F_N))`), or the LuGre bristle law
//! `ż = v − σ₀ |v| z / g(v)`, `F_T = −(σ₀ z + σ₁ ż + σ₂ v)` with `g(v) = F_N (µ + (µ₀−µ) e^{−(v/v_s)²})`,
//! which holds a sticking contact at a bristle deflection instead of creeping.

use crate::contact::Contour;
use crate::error::{Error, Result};

/// Elastic material of a contour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus (Pa).
    pub e: f64,
    /// Poisson's ratio.
    pub nu: f64,
    /// Density (kg/m³), for reports (wave speeds, masses of the parts).
    pub density: f64,
}

impl Material {
    /// Checks the values; `what` names the owner in errors.
    pub fn new(e: f64, nu: f64, density: f64, what: &str) -> Result<Material> {
        crate::ensure!(e.is_finite() && e > 0.0, Model, "{what}.E: Young's modulus must be > 0, got {e}");
        crate::ensure!(
            nu.is_finite() && nu > -1.0 && nu < 0.5,
            Model,
            "{what}.nu: Poisson's ratio must lie in (-1, 0.5), got {nu}"
        );
        crate::ensure!(density.is_finite() && density > 0.0, Model, "{what}.density: must be > 0, got {density}");
        Ok(Material { e, nu, density })
    }

    /// `(1 − ν²)/E`, this side's share of `1/E*`.
    pub fn compliance(&self) -> f64 {
        (1.0 - self.nu * self.nu) / self.e
    }
}

/// The effective modulus `E*` of two materials.
pub fn effective_modulus(m1: &Material, m2: &Material) -> f64 {
    1.0 / (m1.compliance() + m2.compliance())
}

/// How a Hertz-type law's damping coefficient α follows from a restitution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RestitutionMap {
    /// Hunt–Crossley: α = 3(1−ε)/(2v⁻).
    HuntCrossley,
    /// Lankarani–Nikravesh: α = 3(1−ε²)/(4v⁻).
    LankaraniNikravesh,
    /// Flores et al.: α = 8(1−ε)/(5ε v⁻).
    Flores,
}

impl RestitutionMap {
    /// α (s/m) for restitution `eps` at approach speed `v` (m/s, > 0).
    pub fn alpha(self, eps: f64, v: f64) -> f64 {
        let c = match self {
            RestitutionMap::HuntCrossley => 1.5 * (1.0 - eps),
            RestitutionMap::LankaraniNikravesh => 0.75 * (1.0 - eps * eps),
            RestitutionMap::Flores => 1.6 * (1.0 - eps) / eps,
        };
        c / v
    }

    /// The law's name in messages and model files.
    pub fn name(self) -> &'static str {
        match self {
            RestitutionMap::HuntCrossley => "hunt_crossley",
            RestitutionMap::LankaraniNikravesh => "lankarani_nikravesh",
            RestitutionMap::Flores => "flores",
        }
    }
}

/// The damping factor `(1 + α δ̇)` of a Hertz-type law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Dissipation {
    /// Undamped (elastic): restitution 1.
    None,
    /// A fixed α (s/m).
    Alpha(f64),
    /// α from a restitution and the approach speed at onset.
    Restitution {
        /// The mapping.
        map: RestitutionMap,
        /// Restitution in (0, 1].
        eps: f64,
    },
}

/// Where the elastic force comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Elastic {
    /// `k δ + d δ̇` (N/m, N s/m).
    KelvinVoigt {
        /// Stiffness.
        k: f64,
        /// Damping.
        d: f64,
    },
    /// `K δ^{3/2}` with a constant K (N/m^{3/2}): given, or from the materials and constant
    /// curvatures (spheres, planes, bowls).
    Hertz {
        /// K.
        k: f64,
    },
    /// `K δ^{3/2}` with K from the curvatures at the contact point at every evaluation (an
    /// ellipsoid, a torus or a capsule against a sphere, plane or bowl, or two of them: the
    /// relative curvature tensor's eigenvalues give A and B).
    HertzCurved {
        /// E*.
        e_star: f64,
    },
    /// Johnson's line contact per candidate point: `R`, the length each point carries, E*.
    Line {
        /// Radius of relative curvature across the line (m).
        radius: f64,
        /// Contact length carried by each candidate point (m).
        length: f64,
        /// E*.
        e_star: f64,
    },
    /// `F(δ, δ̇)` from a Python callable (its callback id).
    User {
        /// Callback id.
        callback: usize,
    },
}

/// The tangential law of a compliant contact.
#[derive(Debug, Clone, PartialEq)]
pub enum Tangential {
    /// No tangential force.
    None,
    /// The friction law µ(|v|) regularized by `tanh(|v| / v_reg)`.
    Regularized {
        /// The friction law.
        law: super::contact::FrictionLaw,
        /// Regularization velocity (m/s).
        v_reg: f64,
    },
    /// LuGre bristles.
    LuGre {
        /// Static coefficient.
        mu0: f64,
        /// Sliding coefficient.
        mu: f64,
        /// Stribeck velocity (m/s).
        v_s: f64,
        /// Bristle stiffness per unit normal force (1/m).
        sigma0: f64,
        /// Bristle damping per unit normal force (s/m).
        sigma1: f64,
        /// Viscous coefficient per unit normal force (s/m).
        sigma2: f64,
    },
}

/// The validated law of a compliant contact.
#[derive(Debug, Clone, PartialEq)]
pub struct CompliantLaw {
    /// Elastic part.
    pub elastic: Elastic,
    /// Damping factor (Hertz-type and line laws; Kelvin–Voigt carries its own d).
    pub dissipation: Dissipation,
    /// Tangential law.
    pub tangential: Tangential,
}

/// A compliant contact: a pair of contours with a force law (evaluated by
/// [`crate::forces::compliant`]).
#[derive(Debug, Clone)]
pub struct CompliantContact {
    /// Name.
    pub name: String,
    /// Body carrying contour 1.
    pub body1: usize,
    /// Body carrying contour 2.
    pub body2: usize,
    /// The prepared pair.
    pub pair: crate::contact::ContactPair,
    /// The two contours (normalized), for curvatures.
    pub contours: [Contour; 2],
    /// The law.
    pub law: CompliantLaw,
    /// The materials (for reports and post-processing).
    pub materials: Option<[Material; 2]>,
    /// Its first slot among the compliant contact points of the model (history and extra states).
    pub slot: usize,
}

impl PartialEq for CompliantContact {
    /// Same name, bodies, contours, law and slot (the prepared pair follows from the contours).
    fn eq(&self, o: &Self) -> bool {
        self.name == o.name
            && self.body1 == o.body1
            && self.body2 == o.body2
            && self.contours == o.contours
            && self.law == o.law
            && self.materials == o.materials
            && self.slot == o.slot
    }
}

impl CompliantContact {
    /// Candidate points.
    pub fn points(&self) -> usize {
        self.pair.candidates()
    }
}

/// A compliant law's elastic part before the pair of contours is known (a contact group's
/// pairs differ in kind and material).
#[derive(Debug, Clone, PartialEq)]
pub enum ElasticSpec {
    /// Independent of the contours (Kelvin–Voigt, a user law).
    Given(Elastic),
    /// A Hertz-type law: K (or Johnson's line law) from the pair's curvatures and E*, or given.
    Hertz {
        /// K given directly (N/m^{3/2}).
        stiffness: Option<f64>,
        /// Contact length of a planar line contact (m).
        length: Option<f64>,
    },
}

impl ElasticSpec {
    /// The elastic law on contours `c` with effective modulus `e_star` (if both have materials).
    pub fn resolve(&self, c: &[Contour; 2], e_star: Option<f64>, what: &str) -> Result<Elastic> {
        match self {
            ElasticSpec::Given(e) => Ok(e.clone()),
            ElasticSpec::Hertz { stiffness, length } => hertz_elastic(c, e_star, *stiffness, *length, what),
        }
    }
}

/// A compliant contact group: the pairs of a contact group's contours (found by its broad phase,
/// [`crate::contact::group::GroupPhase`], at every evaluation) each carry a compliant law,
/// resolved per pair from the pair's contours and materials when it first comes close
/// ([`CompliantGroup::law`]). Its forces are evaluated by [`crate::forces::compliant_group`].
#[derive(Debug, Clone)]
pub struct CompliantGroup {
    /// The contours (name, members, `against`; its rigid laws are unused).
    pub geometry: super::contact::ContactGroup,
    /// Material of each contour: the members, then the `against` contours.
    pub materials: Vec<Option<Material>>,
    /// The elastic law before the pair is known.
    pub elastic: ElasticSpec,
    /// Damping factor.
    pub dissipation: Dissipation,
    /// Tangential law (regularized only: bristle states per pair are not kept in groups).
    pub tangential: Tangential,
    /// Its slot among the compliant contact points (its dissipated energy is that slot's state).
    pub slot: usize,
    /// Its index among the model's compliant groups (its working memory).
    pub index: usize,
}

impl PartialEq for CompliantGroup {
    /// Same contours, materials, law and slots.
    fn eq(&self, o: &Self) -> bool {
        self.geometry.name == o.geometry.name
            && self.geometry.members == o.geometry.members
            && self.geometry.against == o.geometry.against
            && self.materials == o.materials
            && self.elastic == o.elastic
            && self.dissipation == o.dissipation
            && self.tangential == o.tangential
            && self.slot == o.slot
            && self.index == o.index
    }
}

impl CompliantGroup {
    /// The contour with index `k` (members first, then `against`).
    pub fn contour(&self, k: usize) -> &super::contact::GroupContour {
        let m = self.geometry.members.len();
        if k < m {
            &self.geometry.members[k]
        } else {
            &self.geometry.against[k - m]
        }
    }

    /// The compliant law of the pair of contours `i`, `j`.
    pub fn law(&self, i: usize, j: usize) -> Result<CompliantLaw> {
        let e_star = match (self.materials[i], self.materials[j]) {
            (Some(a), Some(b)) => Some(effective_modulus(&a, &b)),
            _ => None,
        };
        let what = format!("contact group '{}': {}–{}", self.geometry.name, self.label(i), self.label(j));
        let c = [self.contour(i).contour.clone(), self.contour(j).contour.clone()];
        Ok(CompliantLaw {
            elastic: self.elastic.resolve(&c, e_star, &what)?,
            dissipation: self.dissipation,
            tangential: self.tangential.clone(),
        })
    }

    /// Contact points recorded per sample for drawing (two per member, at most 256): the first
    /// touching points in pair order.
    pub fn drawn(&self) -> usize {
        (2 * self.geometry.members.len()).min(256)
    }

    /// Values recorded per sample: [`GROUP_OUTPUTS`] totals, then per drawn point its position
    /// (m) and the force on the first contour (N), world axes.
    pub fn outputs(&self) -> usize {
        GROUP_OUTPUTS + 6 * self.drawn()
    }

    /// `members[k]` or `against[k − members]`.
    pub fn label(&self, k: usize) -> String {
        let m = self.geometry.members.len();
        if k < m {
            format!("members[{k}]")
        } else {
            format!("against[{}]", k - m)
        }
    }
}

/// Totals a compliant group records (force columns: total normal force, stored energy,
/// dissipated energy, touching pairs; deflection columns: largest overlap, largest approach
/// rate, pairs kept by the broad phase, touching points), before its drawn points
/// ([`CompliantGroup::outputs`]).
pub const GROUP_OUTPUTS: usize = 4;

/// Values each compliant contact point records (force columns: F_N, F_T1, F_T2, stored energy,
/// dissipated energy, the contact point on contour 1 (world, m), the friction force (world, N);
/// deflection columns: δ, δ̇, ġ_T1, ġ_T2, α in use, the normal (world), three zeros).
pub const OUTPUTS_PER_POINT: usize = 11;

/// Extra ODE states per compliant contact point: dissipated energy, bristle deflections z1, z2.
pub const STATES_PER_POINT: usize = 3;

/// Complete elliptic integrals of the first and second kind, `K(m)` and `E(m)`, parameter
/// `m = e²` in [0, 1), by the arithmetic–geometric mean (Abramowitz & Stegun 17.6).
pub fn elliptic_ke(m: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    let mut c2 = m;
    let mut sum = 0.5 * c2;
    let mut p = 0.5;
    for _ in 0..40 {
        let an = 0.5 * (a + b);
        let cn = 0.5 * (a - b);
        b = (a * b).sqrt();
        a = an;
        p *= 2.0;
        c2 = cn * cn;
        sum += p * c2;
        if c2 <= 1e-34 * a * a {
            break;
        }
    }
    let k = std::f64::consts::PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// The contact ellipse of two bodies with relative principal curvatures `a_curv ≤ b_curv`
/// (A, B of Hertz's theory, each half the sum of the two surfaces' curvatures in that direction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzEllipse {
    /// `m = e² = 1 − (b/a)²` of the contact ellipse (0 for a circle).
    pub m: f64,
    /// K(m).
    pub k: f64,
    /// E(m).
    pub e: f64,
    /// `(K − E)/(m K)` (its limit 1/2 for a circle).
    pub ratio: f64,
}

impl HertzEllipse {
    /// Solves `B/A = (E/(1−m) − K)/(K − E)` for the shape of the ellipse.
    pub fn new(a_curv: f64, b_curv: f64) -> HertzEllipse {
        let r = b_curv / a_curv;
        if !(r > 1.0 + 1e-9) {
            let (k, e) = elliptic_ke(0.0);
            // (K − E)/m → π/4 as m → 0
            return HertzEllipse { m: 0.0, k, e, ratio: std::f64::consts::FRAC_PI_4 / k };
        }
        // bisection on k' = b/a ∈ (0, 1): the curvature ratio falls monotonically with k'
        let ratio_of = |kp: f64| {
            let m = 1.0 - kp * kp;
            let (k, e) = elliptic_ke(m);
            (e / (1.0 - m) - k) / (k - e)
        };
        let (mut lo, mut hi) = (1e-12f64, 1.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if ratio_of(mid) > r {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-16 * hi {
                break;
            }
        }
        let kp = 0.5 * (lo + hi);
        let m = 1.0 - kp * kp;
        let (k, e) = elliptic_ke(m);
        HertzEllipse { m, k, e, ratio: (k - e) / (m * k) }
    }

    /// Hertz's stiffness `K` in `F = K δ^{3/2}` for curvature `a_curv` (the smaller) and `E*`.
    pub fn stiffness(&self, a_curv: f64, e_star: f64) -> f64 {
        2.0 * std::f64::consts::PI * e_star / (3.0 * self.k) * (self.ratio / a_curv).sqrt()
    }

    /// Semi-axes `(a, b)` (a along the direction of the smaller curvature) and the peak pressure
    /// p0 at approach `delta` under force `force`.
    pub fn contact(&self, a_curv: f64, delta: f64, force: f64) -> (f64, f64, f64) {
        let a = (delta * self.ratio / a_curv).sqrt();
        let b = a * (1.0 - self.m).sqrt();
        let p0 = if a > 0.0 { 1.5 * force / (std::f64::consts::PI * a * b) } else { 0.0 };
        (a, b, p0)
    }
}

/// Johnson's line contact: the force per unit length over `π E*`, `x`, at approach δ for radius
/// R: solves `δ = x (ln(4R/x) − 1)`; None beyond the law's range (δ > 4R/e², where the
/// approach stops growing with the force).
pub fn johnson_x(delta: f64, radius: f64) -> Option<f64> {
    if delta <= 0.0 {
        return Some(0.0);
    }
    let x_max = 4.0 * radius * (-2.0f64).exp();
    let g = |x: f64| x * ((4.0 * radius / x).ln() - 1.0) - delta;
    if g(x_max) < 0.0 {
        return None;
    }
    // g rises on (0, x_max]: safeguarded Newton
    let (mut lo, mut hi) = (0.0f64, x_max);
    let mut x = (delta / (4.0 * radius / delta).ln().max(1.0)).min(0.5 * x_max);
    for _ in 0..100 {
        let gx = g(x);
        if gx > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let dg = (4.0 * radius / x).ln() - 2.0;
        let mut xn = x - gx / dg;
        if !(xn > lo && xn < hi) {
            xn = 0.5 * (lo + hi);
        }
        if (xn - x).abs() <= 1e-15 * x {
            return Some(xn);
        }
        x = xn;
    }
    Some(x)
}

/// Energy stored in Johnson's line contact at `x` (force per length over π E*):
/// `π L E* x² (½ ln(4R/x) − ¾)` = ∫ F dδ.
pub fn johnson_energy(x: f64, radius: f64, length: f64, e_star: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    std::f64::consts::PI * length * e_star * x * x * (0.5 * (4.0 * radius / x).ln() - 0.75)
}

/// What kind of contour a Hertz law sees: a constant curvature in every direction (κ, a sphere,
/// bowl or plane), two principal curvatures that vary (an ellipsoid, a torus, a capsule: a
/// cylinder's side with spherical ends), a cylinder's
/// side or a planar disc (line contact), or nothing to work with (flat faces, edges, vertices).
enum Shape {
    Isotropic(f64),
    Curved,
    Line { radius: f64, length: Option<f64> },
    None,
}

fn shape(c: &Contour) -> Shape {
    match c {
        Contour::Sphere { radius, .. } => Shape::Isotropic(1.0 / radius),
        Contour::Bowl { radius, .. } => Shape::Isotropic(-1.0 / radius),
        Contour::Plane { .. } | Contour::Line { .. } => Shape::Isotropic(0.0),
        Contour::Ellipsoid { .. } | Contour::Capsule { .. } => Shape::Curved,
        Contour::Torus { tube, .. } if *tube > 0.0 => Shape::Curved,
        Contour::Cylinder { radius, half_length, .. } => {
            Shape::Line { radius: *radius, length: Some(2.0 * half_length) }
        }
        Contour::Circle { radius, .. } => Shape::Line { radius: *radius, length: None },
        _ => Shape::None,
    }
}

/// The elastic part of a Hertz-type law on contours `c` (with materials giving `e_star`, or a
/// given stiffness `k`), and the line `length` where the law asks for one. `what` names the
/// contact.
pub fn hertz_elastic(
    c: &[Contour; 2],
    e_star: Option<f64>,
    k: Option<f64>,
    length: Option<f64>,
    what: &str,
) -> Result<Elastic> {
    let planar = c.iter().any(|x| {
        matches!(
            x,
            Contour::Circle { .. }
                | Contour::Line { .. }
                | Contour::Point2 { .. }
                | Contour::Polygon { .. }
                | Contour::Curve(_)
        )
    });
    let (s1, s2) = (shape(&c[0]), shape(&c[1]));
    let need_e = || {
        e_star.ok_or_else(|| {
            Error::Model(format!(
                "{what}: a Hertz-type law needs the materials of both contours (body.contour(..., material=ms.Material(E, nu, density))) or a given stiffness"
            ))
        })
    };
    let flat = |s: &Shape| matches!(s, Shape::Isotropic(k) if *k == 0.0);
    match (&s1, &s2) {
        (Shape::None, _) | (_, Shape::None) => Err(Error::Model(format!(
            "{what}: a Hertz law needs curved contours at the contact ({} against {}: a flat face, an edge or a vertex has no Hertz contact); use laws.KelvinVoigt",
            c[0].kind(),
            c[1].kind()
        ))),
        (Shape::Isotropic(k1), Shape::Isotropic(k2)) => {
            let kappa = k1 + k2;
            crate::ensure!(
                kappa > 0.0 && kappa.is_finite(),
                Model,
                "{what}: a Hertz law needs curved contours (the relative curvature of {} and {} is {kappa} 1/m: flat–flat or conforming face contact); use laws.KelvinVoigt",
                c[0].kind(),
                c[1].kind()
            );
            if planar {
                return Err(Error::Model(format!("{what}: planar contours touch along a line: internal error")));
            }
            Ok(Elastic::Hertz { k: match k { Some(k) => k, None => 4.0 / 3.0 * need_e()? * (1.0 / kappa).sqrt() } })
        }
        // doubly curved on one or both sides: K from the relative curvature tensor at the contact
        // point at every evaluation (principal directions crossing at any angle)
        (Shape::Curved, Shape::Isotropic(_)) | (Shape::Isotropic(_), Shape::Curved) | (Shape::Curved, Shape::Curved) => {
            match k {
                Some(k) => Ok(Elastic::Hertz { k }),
                None => Ok(Elastic::HertzCurved { e_star: need_e()? }),
            }
        }
        (Shape::Line { radius, length: l }, other) | (other, Shape::Line { radius, length: l }) => {
            let r = match other {
                Shape::Isotropic(k) if flat(other) && *k == 0.0 => *radius,
                Shape::Line { radius: r2, .. } if planar => radius * r2 / (radius + r2),
                _ => {
                    return Err(Error::Model(format!(
                        "{what}: a line contact (Johnson) is a cylinder or disc on a plane or line, or two discs in the plane; got {} against {}",
                        c[0].kind(),
                        c[1].kind()
                    )))
                }
            };
            let total = match (length, l) {
                (Some(v), _) => v,
                (None, Some(v)) => *v,
                (None, None) => {
                    return Err(Error::Model(format!(
                        "{what}.normal.length: a planar line contact needs the contact length (m) along the discs' axes"
                    )))
                }
            };
            crate::ensure!(total.is_finite() && total > 0.0, Model, "{what}.normal.length: must be > 0, got {total}");
            // a spatial cylinder on a plane touches at its two rim circles: each carries half
            let per_point = if planar { total } else { 0.5 * total };
            Ok(Elastic::Line { radius: r, length: per_point, e_star: need_e()? })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elliptic_integrals_match_tabulated_values() {
        // K(0.5) = 1.8540746773013719, E(0.5) = 1.3506438810476755 (A&S table 17.1)
        let (k, e) = elliptic_ke(0.5);
        assert!((k - 1.854_074_677_301_371_9).abs() < 1e-14);
        assert!((e - 1.350_643_881_047_675_5).abs() < 1e-14);
        let (k, e) = elliptic_ke(0.0);
        assert!((k - std::f64::consts::FRAC_PI_2).abs() < 1e-15 && (e - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn circular_limit_is_the_sphere_formula() {
        let el = HertzEllipse::new(2.0, 2.0);
        // A = B = 1/(2R): R = 0.25, K = 4/3 E* √R
        let k = el.stiffness(2.0, 1e9);
        assert!((k / (4.0 / 3.0 * 1e9 * 0.5) - 1.0).abs() < 1e-14);
        let near = HertzEllipse::new(2.0, 2.0 * (1.0 + 1e-7));
        assert!((near.stiffness(2.0, 1e9) / k - 1.0).abs() < 1e-6);
    }

    #[test]
    fn johnson_inverts() {
        let x = johnson_x(1e-5, 0.01).unwrap();
        assert!((x * ((0.04 / x).ln() - 1.0) - 1e-5).abs() < 1e-19);
        assert!(johnson_x(0.01, 0.01).is_none());
    }
}
