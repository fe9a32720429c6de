//! Validated unilateral contacts: the pair of contours (prepared once for the narrow phase), the
//! friction law (eqs. 2.200, 2.201) and the impact law (eqs. 2.202, 2.203).

use crate::contact::gap::{GapFunction, GapTerm};
use crate::contact::{ContactPair, Contour, Vec2};
use crate::error::{Error, Result};
use crate::math::expr::Expr;
use crate::math::Vec3;

use super::contact_description::{
    ContactDescription, ContactGroupDescription, ContourDescription, FrictionDescription, GapContactDescription,
    GapTermDescription, GearDescription, ImpactDescription, SolidSide,
};
use crate::geometry::curve::{Curve, Follower, Solid};
use crate::geometry::gear::GearSpec;
use crate::geometry::revolution::Revolution;
use crate::geometry::surface::Patch;

/// Tangential law with its coefficients.
#[derive(Debug, Clone, PartialEq)]
pub enum FrictionLaw {
    /// No friction.
    None,
    /// Coulomb: sliding `mu`, static `mu0` (≥ mu).
    Coulomb {
        /// Sliding coefficient.
        mu: f64,
        /// Static coefficient.
        mu0: f64,
    },
    /// µ(v) = mu + (mu0 - mu) exp(-(|v| / v_s)^exponent).
    Stribeck {
        /// Static coefficient.
        mu0: f64,
        /// High-speed coefficient.
        mu: f64,
        /// Stribeck velocity (m/s).
        v_s: f64,
        /// Shape exponent.
        exponent: f64,
    },
    /// µ(|v|) piecewise linear, constant beyond the ends.
    Table {
        /// Speeds (m/s), ascending from 0.
        speed: Vec<f64>,
        /// Coefficients.
        mu: Vec<f64>,
    },
}

impl FrictionLaw {
    /// Sliding coefficient at relative speed `v` (m/s), eq. 2.201; `mu(0)` is the static one.
    pub fn mu(&self, v: f64) -> f64 {
        let v = v.abs();
        match self {
            FrictionLaw::None => 0.0,
            FrictionLaw::Coulomb { mu, mu0 } => {
                if v == 0.0 {
                    *mu0
                } else {
                    *mu
                }
            }
            FrictionLaw::Stribeck { mu0, mu, v_s, exponent } => mu + (mu0 - mu) * (-(v / v_s).powf(*exponent)).exp(),
            FrictionLaw::Table { speed, mu } => {
                let k = speed.partition_point(|s| *s <= v);
                if k == 0 {
                    mu[0]
                } else if k >= speed.len() {
                    mu[mu.len() - 1]
                } else {
                    let w = (v - speed[k - 1]) / (speed[k] - speed[k - 1]);
                    mu[k - 1] + w * (mu[k] - mu[k - 1])
                }
            }
        }
    }

    /// Static coefficient µ0 (the limit of µ at zero sliding speed, eq. 2.201). Given below the
    /// sliding coefficient (accepted with a warning), a contact still sticks up to the sliding
    /// one: a slide against more friction than held it could not start.
    pub fn mu0(&self) -> f64 {
        self.mu(0.0).max(self.mu(f64::MIN_POSITIVE))
    }
}

/// Impact law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ImpactLaw {
    /// Newton (2.202): ġ_N⁺ = -ε ġ_N⁻.
    Newton {
        /// Restitution.
        eps: f64,
    },
    /// Poisson (2.203): expansion impulse = ε × compression impulse, normal and tangential.
    Poisson {
        /// Normal coefficient.
        eps: f64,
        /// Tangential coefficient.
        eps_t: f64,
    },
}

impl ImpactLaw {
    /// The normal coefficient.
    pub fn eps(&self) -> f64 {
        match self {
            ImpactLaw::Newton { eps } | ImpactLaw::Poisson { eps, .. } => *eps,
        }
    }
}

/// A validated contact between two bodies.
#[derive(Debug, Clone)]
pub struct Contact {
    /// Unique name.
    pub name: String,
    /// Body carrying contour 1 (0, the ground, for a gap function).
    pub body1: usize,
    /// Body carrying contour 2 (0 for a gap function).
    pub body2: usize,
    /// What the contact's kinematics come from.
    pub geometry: ContactGeometry,
    /// Friction law.
    pub friction: FrictionLaw,
    /// Impact law.
    pub impact: ImpactLaw,
    /// Compliance of its Signorini law (m/N): 0 rigid; else `g_N + c λ_N ≥ 0` in the
    /// time-stepping scheme.
    pub compliance: f64,
    /// Damping of the compliant layer (N s/m; 0 where rigid).
    pub damping: f64,
    /// Index of its first candidate point among all contact points of the model.
    pub first: usize,
}

/// A contour on a body, a member (or an `against` contour) of a [`ContactGroup`].
#[derive(Debug, Clone, PartialEq)]
pub struct GroupContour {
    /// Body carrying it.
    pub body: usize,
    /// The contour, body-frame data (validated, normalized directions).
    pub contour: Contour,
}

/// A validated contact group: every pair of `members` on different bodies, and every member
/// against every `against` contour on another body, is a potential contact with the group's
/// laws; the pairs that may touch are found at every step by a broad phase
/// ([`crate::contact::group`]).
#[derive(Debug, Clone)]
pub struct ContactGroup {
    /// Unique name (shared namespace with the contacts).
    pub name: String,
    /// Contours checked against each other and against `against`.
    pub members: Vec<GroupContour>,
    /// Contours checked against the members only.
    pub against: Vec<GroupContour>,
    /// Friction law of every pair.
    pub friction: FrictionLaw,
    /// Impact law of every pair.
    pub impact: ImpactLaw,
    /// Compliance of every pair's Signorini law (m/N), as [`Contact::compliance`].
    pub compliance: f64,
    /// Damping of their compliant layers (N s/m), as [`Contact::damping`].
    pub damping: f64,
    /// Whether the group is planar (every contour in the x-y planes of its bodies).
    pub planar: bool,
}

/// Where a contact's kinematics come from.
#[derive(Debug, Clone)]
pub enum ContactGeometry {
    /// A contour on each body, searched by the narrow phase.
    Contours {
        /// The prepared pair of contours.
        pair: ContactPair,
        /// The two contours (body-frame data, normalized), for queries and reports.
        contours: [Contour; 2],
    },
    /// A user gap function of the coordinates and time ([`crate::contact::gap`]).
    Gap {
        /// The function.
        function: GapFunction,
        /// Its index among the model's gap contacts (its rows in `GapWork::rows`).
        slot: usize,
    },
}

impl Contact {
    /// Number of candidate points.
    pub fn points(&self) -> usize {
        match &self.geometry {
            ContactGeometry::Contours { pair, .. } => pair.candidates(),
            ContactGeometry::Gap { .. } => 1,
        }
    }

    /// The pair of contours (None for a gap function).
    pub fn pair(&self) -> Option<&ContactPair> {
        match &self.geometry {
            ContactGeometry::Contours { pair, .. } => Some(pair),
            ContactGeometry::Gap { .. } => None,
        }
    }

    /// The two contours (None for a gap function).
    pub fn contours(&self) -> Option<&[Contour; 2]> {
        match &self.geometry {
            ContactGeometry::Contours { contours, .. } => Some(contours),
            ContactGeometry::Gap { .. } => None,
        }
    }

    /// Friction directions per point: 1 for planar pairs, 2 in space; a gap function's number
    /// of tangential coordinates (at least 1, so a frictionless one fits a planar model).
    pub fn tangent_dim(&self) -> usize {
        match &self.geometry {
            ContactGeometry::Contours { pair, .. } => pair.tangent_dim(),
            ContactGeometry::Gap { function, .. } => function.tangents().max(1),
        }
    }

    /// Whether the contact has one friction direction (it fits a planar contact problem).
    pub fn is_planar(&self) -> bool {
        self.tangent_dim() == 1
    }

    /// The gap function and its slot (None for contours).
    pub fn gap(&self) -> Option<(&GapFunction, usize)> {
        match &self.geometry {
            ContactGeometry::Gap { function, slot } => Some((function, *slot)),
            ContactGeometry::Contours { .. } => None,
        }
    }
}

fn finite(x: f64, what: &str) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(Error::Model(format!("{what}: must be finite, got {x}")))
    }
}

fn vec3(v: &[f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

fn planar(c: &ContourDescription) -> bool {
    matches!(
        c,
        ContourDescription::Circle { .. }
            | ContourDescription::Line { .. }
            | ContourDescription::Polygon { .. }
            | ContourDescription::Ellipse { .. }
            | ContourDescription::Spline { .. }
            | ContourDescription::Cam { .. }
            | ContourDescription::Gear(_)
    )
}

/// The surface velocity of a moving plane or line (a conveyor belt).
fn surface_velocity(c: &ContourDescription) -> Option<[f64; 3]> {
    match c {
        ContourDescription::Plane { surface_velocity, .. } | ContourDescription::Line { surface_velocity, .. } => {
            *surface_velocity
        }
        _ => None,
    }
}

/// The gear of a description: `module` or `base_radius` (exactly one), defaults filled in;
/// `what` names the contour in errors.
pub fn gear_spec(g: &GearDescription, what: &str) -> Result<GearSpec> {
    let alpha = g.pressure_angle.unwrap_or(20f64.to_radians());
    crate::ensure!(
        alpha.is_finite() && alpha > 0.0 && alpha < 60f64.to_radians(),
        Model,
        "{what}.pressure_angle: must lie between 0 and 60° (1.047 rad), got {alpha} rad"
    );
    let m = match (g.module, g.base_radius) {
        (Some(m), None) => m,
        (None, Some(rb)) => {
            crate::ensure!(rb.is_finite() && rb > 0.0, Model, "{what}.base_radius: must be > 0, got {rb}");
            crate::ensure!(g.teeth > 0, Model, "{what}.teeth: must be ≥ 5, got {}", g.teeth);
            2.0 * rb / (g.teeth as f64 * alpha.cos())
        }
        (Some(_), Some(_)) => {
            return Err(Error::Model(format!("{what}: give the gear's module or its base_radius, not both")))
        }
        (None, None) => return Err(Error::Model(format!("{what}: a gear needs its module (or base_radius)"))),
    };
    for (k, v) in
        [("shift", Some(g.shift)), ("backlash", Some(g.backlash)), ("addendum", g.addendum), ("dedendum", g.dedendum)]
    {
        if let Some(v) = v {
            finite(v, &format!("{what}.{k}"))?;
        }
    }
    Ok(GearSpec {
        module: m,
        teeth: g.teeth,
        pressure_angle: alpha,
        shift: g.shift,
        backlash: g.backlash,
        addendum: g.addendum.unwrap_or(m),
        dedendum: g.dedendum.unwrap_or(1.25 * m),
        tip_radius: g.tip_radius,
        root_radius: g.root_radius,
        center: Vec2::new(g.center[0], g.center[1]),
        phase: g.phase,
    })
}

/// The engine contour of a description; a `point` is planar when its partner is.
fn contour(
    c: &ContourDescription,
    partner_planar: bool,
    what: &str,
    rotation: impl Fn(&Option<super::description::RotationDescription>, &str) -> Result<crate::math::Mat3>,
) -> Result<Contour> {
    Ok(match c {
        ContourDescription::Point { position } if partner_planar => {
            Contour::Point2 { p: Vec2::new(position[0], position[1]) }
        }
        ContourDescription::Point { position } => Contour::Point { p: vec3(position) },
        ContourDescription::Sphere { center, radius } => Contour::Sphere { center: vec3(center), radius: *radius },
        ContourDescription::Plane { point, normal, .. } => Contour::Plane { point: vec3(point), normal: vec3(normal) },
        ContourDescription::Box { center, rotation: r, half_extents } => Contour::Box {
            center: vec3(center),
            rotation: rotation(r, &format!("{what}.rotation"))?,
            half_extents: vec3(half_extents),
        },
        ContourDescription::Capsule { a, b, radius } => Contour::Capsule { a: vec3(a), b: vec3(b), radius: *radius },
        ContourDescription::Cylinder { center, axis, radius, half_length } => {
            Contour::Cylinder { center: vec3(center), axis: vec3(axis), radius: *radius, half_length: *half_length }
        }
        ContourDescription::Torus { center, axis, radius, tube } => {
            Contour::Torus { center: vec3(center), axis: vec3(axis), radius: *radius, tube: *tube }
        }
        ContourDescription::Ellipsoid { center, rotation: r, semi_axes } => Contour::Ellipsoid {
            center: vec3(center),
            rotation: rotation(r, &format!("{what}.rotation"))?,
            semi_axes: vec3(semi_axes),
        },
        ContourDescription::Bowl { center, radius } => Contour::Bowl { center: vec3(center), radius: *radius },
        ContourDescription::Bore { center, axis, radius } => {
            Contour::Bore { center: vec3(center), axis: vec3(axis), radius: *radius }
        }
        ContourDescription::Mesh { vertices, triangles, file } => {
            crate::ensure!(
                file.is_none(),
                Model,
                "{what}.file: mesh files are read by the Python model loader (mechsys.load_model, `mechsys run`); \
                 give vertices and triangles here"
            );
            let mut tris = Vec::with_capacity(triangles.len());
            for (t, tri) in triangles.iter().enumerate() {
                let mut out = [0usize; 3];
                for (j, &i) in tri.iter().enumerate() {
                    crate::ensure!(i >= 0, Model, "{what}.triangles[{t}][{j}]: vertex index must be ≥ 0, got {i}");
                    out[j] = i as usize;
                }
                tris.push(out);
            }
            let v: Vec<Vec3> = vertices.iter().map(vec3).collect();
            Contour::Mesh(std::sync::Arc::new(crate::geometry::mesh::TriMesh::new(&v, &tris, what)?))
        }
        ContourDescription::Circle { center, radius } => {
            Contour::Circle { center: Vec2::new(center[0], center[1]), radius: *radius }
        }
        ContourDescription::Line { point, normal, .. } => {
            Contour::Line { point: Vec2::new(point[0], point[1]), normal: Vec2::new(normal[0], normal[1]) }
        }
        ContourDescription::Polygon { vertices } => {
            Contour::Polygon { vertices: vertices.iter().map(|v| Vec2::new(v[0], v[1])).collect() }
        }
        ContourDescription::Ellipse { center, semi_axes, angle, solid } => {
            let e = Curve::ellipse(Vec2::new(center[0], center[1]), semi_axes[0], semi_axes[1], *angle, what)?;
            match solid {
                None | Some(SolidSide::Inside) => Contour::Curve(Box::new(e)),
                Some(SolidSide::Outside) => Contour::Curve(Box::new(e.flipped())),
                Some(s) => {
                    return Err(Error::Model(format!(
                        "{what}: an ellipse's solid is 'inside' or 'outside', got '{}'",
                        format!("{s:?}").to_lowercase()
                    )))
                }
            }
        }
        ContourDescription::Spline { points, closed, solid } => {
            let side = match solid {
                Some(SolidSide::Left) => Solid::Left,
                Some(SolidSide::Right) => Solid::Right,
                Some(SolidSide::Inside) => Solid::Inside,
                Some(SolidSide::Outside) => Solid::Outside,
                None if *closed => Solid::Inside,
                None => Solid::Left,
            };
            let pts: Vec<Vec2> = points.iter().map(|p| Vec2::new(p[0], p[1])).collect();
            Contour::Curve(Box::new(Curve::spline(&pts, *closed, side, what)?))
        }
        ContourDescription::Cam { angles, lift, base_radius, follower, roller_radius, eccentricity, direction } => {
            let f = match follower.as_deref().unwrap_or("roller") {
                "roller" => Follower::Roller { radius: *roller_radius, eccentricity: *eccentricity },
                "knife" => Follower::Roller { radius: 0.0, eccentricity: *eccentricity },
                "flat" => Follower::Flat,
                other => {
                    return Err(Error::Model(format!(
                        "{what}.follower: expected 'roller', 'knife' or 'flat', got '{other}'"
                    )))
                }
            };
            Contour::Curve(Box::new(Curve::cam(angles, lift, *base_radius, f, *direction, what)?))
        }
        ContourDescription::Gear(g) => Contour::Curve(Box::new(Curve::gear(&gear_spec(g, what)?, what)?)),
        ContourDescription::Revolution { center, rotation: r, profile } => {
            let w = format!("{what}.profile");
            let Contour::Curve(c) = contour(profile, true, &w, no_rotation)? else {
                return Err(Error::Model(format!(
                    "{w}: a revolution profile is an ellipse, spline or cam, got {}",
                    Contour::kind(&contour(profile, true, &w, no_rotation)?)
                )));
            };
            let frame = rotation(r, &format!("{what}.rotation"))?;
            Contour::Revolution(Box::new(Revolution::new(vec3(center), frame, *c, what)?))
        }
        ContourDescription::Patch { points, range1, range2, periodic } => {
            let grid: Vec<Vec<Vec3>> = points.iter().map(|row| row.iter().map(vec3).collect()).collect();
            Contour::Patch(Box::new(Patch::new(
                &grid,
                (range1[0], range1[1]),
                (range2[0], range2[1]),
                *periodic,
                what,
            )?))
        }
    })
}

/// A profile (in its own plane) has no rotation of its own.
fn no_rotation(r: &Option<super::description::RotationDescription>, what: &str) -> Result<crate::math::Mat3> {
    match r {
        None => Ok(crate::math::Mat3::identity()),
        Some(_) => Err(Error::Model(format!("{what}: a revolution profile takes no rotation"))),
    }
}

/// The validated friction law of a description; `what` names the owner in messages.
fn friction_law(friction: &FrictionDescription, what: &str) -> Result<FrictionLaw> {
    Ok(match friction {
        FrictionDescription::None => FrictionLaw::None,
        FrictionDescription::Coulomb { mu, mu0 } => {
            let mu = finite(*mu, &format!("{what}.friction.mu"))?;
            let mu0 = finite(mu0.unwrap_or(mu), &format!("{what}.friction.mu0"))?;
            crate::ensure!(mu >= 0.0, Model, "{what}.friction.mu: must be >= 0, got {mu}");
            // (µ0 < µ is accepted; the Python layer warns, and mu0() holds up to µ)
            crate::ensure!(mu0 >= 0.0, Model, "{what}.friction.mu0: must be >= 0, got {mu0}");
            FrictionLaw::Coulomb { mu, mu0 }
        }
        FrictionDescription::Stribeck { mu0, mu, v_s, exponent } => {
            let w = format!("{what}.friction");
            let (mu0, mu) = (finite(*mu0, &format!("{w}.mu0"))?, finite(*mu, &format!("{w}.mu"))?);
            crate::ensure!(mu >= 0.0, Model, "{w}.mu: must be >= 0, got {mu}");
            crate::ensure!(mu0 >= 0.0, Model, "{w}.mu0: must be >= 0, got {mu0}");
            crate::ensure!(v_s.is_finite() && *v_s > 0.0, Model, "{w}.v_s: must be > 0, got {v_s}");
            crate::ensure!(exponent.is_finite() && *exponent > 0.0, Model, "{w}.exponent: must be > 0, got {exponent}");
            FrictionLaw::Stribeck { mu0, mu, v_s: *v_s, exponent: *exponent }
        }
        FrictionDescription::Table { speed, mu } => {
            let w = format!("{what}.friction");
            crate::ensure!(
                !speed.is_empty() && speed.len() == mu.len(),
                Model,
                "{w}: speed and mu need the same nonzero length, got {} and {}",
                speed.len(),
                mu.len()
            );
            crate::ensure!(speed[0] == 0.0, Model, "{w}.speed[0]: the table starts at speed 0, got {}", speed[0]);
            for k in 1..speed.len() {
                crate::ensure!(
                    speed[k].is_finite() && speed[k] > speed[k - 1],
                    Model,
                    "{w}.speed[{k}]: must be finite and ascending, got {}",
                    speed[k]
                );
            }
            for (k, m) in mu.iter().enumerate() {
                crate::ensure!(m.is_finite() && *m >= 0.0, Model, "{w}.mu[{k}]: must be finite and >= 0, got {m}");
            }
            FrictionLaw::Table { speed: speed.clone(), mu: mu.clone() }
        }
        FrictionDescription::LuGre { .. } => {
            return Err(Error::Model(format!(
                "{what}.friction: the LuGre bristle law acts on compliant contacts (a normal law such as laws.Hertz or laws.KelvinVoigt); a rigid contact takes Coulomb, Stribeck or a table"
            )))
        }
    })
}

/// The parts of a compliant law that do not depend on the pair of contours: the elastic law
/// (resolved per pair by [`super::compliant::ElasticSpec::resolve`]), the damping and the
/// tangential law. `what` names the contact or group in errors.
pub(super) fn compliant_law(
    normal: &super::contact_description::NormalDescription,
    friction: &FrictionDescription,
    what: &str,
    n_callbacks: &mut usize,
) -> Result<(super::compliant::ElasticSpec, super::compliant::Dissipation, super::compliant::Tangential)> {
    use super::compliant::{Dissipation, Elastic, ElasticSpec, RestitutionMap, Tangential};
    use super::contact_description::NormalDescription as N;
    let positive = |v: f64, key: &str| -> Result<f64> {
        crate::ensure!(v.is_finite() && v > 0.0, Model, "{what}.normal.{key}: must be > 0, got {v}");
        Ok(v)
    };
    let (elastic, dissipation, v_reg) = match normal {
        N::KelvinVoigt { k, d: damping, v_reg } => {
            positive(*k, "k")?;
            crate::ensure!(
                damping.is_finite() && *damping >= 0.0,
                Model,
                "{what}.normal.d: must be >= 0, got {damping}"
            );
            (ElasticSpec::Given(Elastic::KelvinVoigt { k: *k, d: *damping }), Dissipation::None, *v_reg)
        }
        N::User { callback, v_reg } => {
            crate::ensure!(*callback < 1 << 32, Model, "{what}.normal.callback: index {callback} is out of range");
            *n_callbacks = (*n_callbacks).max(callback + 1);
            (ElasticSpec::Given(Elastic::User { callback: *callback }), Dissipation::None, *v_reg)
        }
        N::Hertz(h) | N::HuntCrossley(h) | N::LankaraniNikravesh(h) | N::Flores(h) => {
            let map = match normal {
                N::HuntCrossley(_) => Some(RestitutionMap::HuntCrossley),
                N::LankaraniNikravesh(_) => Some(RestitutionMap::LankaraniNikravesh),
                N::Flores(_) => Some(RestitutionMap::Flores),
                _ => None,
            };
            if let Some(k) = h.stiffness {
                positive(k, "stiffness")?;
            }
            let dissipation = match (map, h.eps, h.alpha) {
                (_, Some(_), Some(_)) => {
                    return Err(Error::Model(format!("{what}.normal: give eps or alpha, not both")))
                }
                (_, None, Some(a)) => {
                    crate::ensure!(a.is_finite() && a >= 0.0, Model, "{what}.normal.alpha: the damping coefficient must be >= 0, got {a}");
                    if a == 0.0 { Dissipation::None } else { Dissipation::Alpha(a) }
                }
                (None, Some(_), None) => {
                    return Err(Error::Model(format!(
                        "{what}.normal.eps: the undamped Hertz law has restitution 1; use HuntCrossley, LankaraniNikravesh or Flores for a restitution"
                    )))
                }
                (Some(map), Some(e), None) => {
                    crate::ensure!(e.is_finite() && e > 0.0 && e <= 1.0, Model, "{what}.normal.eps: must be in (0, 1], got {e}");
                    if e == 1.0 { Dissipation::None } else { Dissipation::Restitution { map, eps: e } }
                }
                (Some(map), None, None) => {
                    return Err(Error::Model(format!("{what}.normal: the {} law needs eps (restitution) or alpha (s/m)", map.name())))
                }
                (None, None, None) => Dissipation::None,
            };
            (ElasticSpec::Hertz { stiffness: h.stiffness, length: h.length }, dissipation, h.v_reg)
        }
        N::Signorini { .. } | N::Bilateral { .. } => {
            return Err(Error::Model(format!("{what}.normal: not a compliant law")))
        }
    };
    let tangential = match friction {
        FrictionDescription::None => Tangential::None,
        FrictionDescription::LuGre { mu0, mu, v_s, sigma0, sigma1, sigma2 } => {
            let w = format!("{what}.friction");
            for (k, v) in [("mu0", mu0), ("mu", mu), ("sigma1", sigma1), ("sigma2", sigma2)] {
                crate::ensure!(v.is_finite() && *v >= 0.0, Model, "{w}.{k}: must be >= 0, got {v}");
            }
            crate::ensure!(v_s.is_finite() && *v_s > 0.0, Model, "{w}.v_s: must be > 0, got {v_s}");
            crate::ensure!(sigma0.is_finite() && *sigma0 > 0.0, Model, "{w}.sigma0: must be > 0, got {sigma0}");
            crate::ensure!(*mu0 > 0.0 || *mu > 0.0, Model, "{w}: mu0 and mu are both zero");
            Tangential::LuGre { mu0: *mu0, mu: *mu, v_s: *v_s, sigma0: *sigma0, sigma1: *sigma1, sigma2: *sigma2 }
        }
        f => {
            let law = friction_law(f, what)?;
            let v_reg = v_reg.unwrap_or(1e-4);
            crate::ensure!(v_reg.is_finite() && v_reg > 0.0, Model, "{what}.normal.v_reg: must be > 0, got {v_reg}");
            Tangential::Regularized { law, v_reg }
        }
    };
    Ok((elastic, dissipation, tangential))
}

/// Validates a contact whose normal law is compliant (`index` among the contacts, `slot` its
/// first point among the compliant contact points): the pair as for a rigid contact, then the
/// materials, the law and the tangential law. `callbacks` counts a user law's callback.
pub(super) fn validate_compliant(
    d: &ContactDescription,
    index: usize,
    slot: usize,
    body: impl Fn(&str, &str) -> Result<usize>,
    rotation: impl Fn(&Option<super::description::RotationDescription>, &str) -> Result<crate::math::Mat3> + Copy,
    n_callbacks: &mut usize,
) -> Result<super::compliant::CompliantContact> {
    use super::compliant as cc;
    let what = format!("contacts[{index}] '{}'", d.name);
    let mut rigid = d.clone();
    rigid.friction = FrictionDescription::None;
    let c = validate(&rigid, index, 0, &body, rotation)?;
    let ContactGeometry::Contours { pair, contours } = c.geometry else {
        return Err(Error::Model(format!("{what}: a compliant contact needs two contours")));
    };
    crate::ensure!(
        pair.surface_velocity().iter().all(|v| v.norm() == 0.0),
        Model,
        "{what}: a compliant contact on a moving surface is not supported"
    );
    let material =
        |m: &Option<super::contact_description::MaterialDescription>, k: usize| -> Result<Option<cc::Material>> {
            m.map(|m| cc::Material::new(m.e, m.nu, m.density, &format!("{what}.material{k}"))).transpose()
        };
    let (m1, m2) = (material(&d.material1, 1)?, material(&d.material2, 2)?);
    let materials = match (m1, m2) {
        (Some(a), Some(b)) => Some([a, b]),
        (None, None) => None,
        _ => {
            return Err(Error::Model(format!(
                "{what}: give both contours a material (one has none: E* combines the two sides)"
            )))
        }
    };
    let e_star = materials.map(|[a, b]| cc::effective_modulus(&a, &b));
    let (spec, dissipation, tangential) = compliant_law(&d.normal, &d.friction, &what, n_callbacks)?;
    let elastic = spec.resolve(&contours, e_star, &what)?;
    Ok(cc::CompliantContact {
        name: d.name.clone(),
        body1: c.body1,
        body2: c.body2,
        pair,
        contours,
        law: cc::CompliantLaw { elastic, dissipation, tangential },
        materials,
        slot,
    })
}

/// The validated impact law of a description.
fn impact_law(impact: &ImpactDescription, what: &str) -> Result<ImpactLaw> {
    let impact = match *impact {
        ImpactDescription::Newton { eps } => ImpactLaw::Newton { eps },
        ImpactDescription::Poisson { eps, eps_t } => ImpactLaw::Poisson { eps, eps_t },
    };
    let (eps, eps_t) = match impact {
        ImpactLaw::Newton { eps } => (eps, 0.0),
        ImpactLaw::Poisson { eps, eps_t } => (eps, eps_t),
    };
    for (k, e) in [("eps", eps), ("eps_t", eps_t)] {
        crate::ensure!(
            e.is_finite() && (0.0..=1.0).contains(&e),
            Model,
            "{what}.impact.{k}: must be in [0, 1], got {e}"
        );
    }
    Ok(impact)
}

/// The compliance and damping of a Signorini law (0 for a bilateral one), checked: finite and
/// `≥ 0`, damping only with a compliance.
fn compliance(normal: &super::contact_description::NormalDescription, what: &str) -> Result<(f64, f64)> {
    let (c, d) = match normal {
        super::contact_description::NormalDescription::Signorini { compliance, damping } => (*compliance, *damping),
        _ => (0.0, 0.0),
    };
    crate::ensure!(
        c.is_finite() && c >= 0.0,
        Model,
        "{what}.normal.compliance: must be a finite number >= 0 (m/N; 0 for a rigid contact), got {c}"
    );
    crate::ensure!(
        d.is_finite() && d >= 0.0,
        Model,
        "{what}.normal.damping: must be a finite number >= 0 (N s/m), got {d}"
    );
    crate::ensure!(
        d == 0.0 || c > 0.0,
        Model,
        "{what}.normal.damping: damps a compliant layer; give a compliance > 0 too (a rigid contact's impacts take an impact law)"
    );
    Ok((c, d))
}

/// A compliant layer's rebound comes from its stiffness and damping: a restitution on top of it
/// is refused (a plastic Newton law, ε = 0, the default, is accepted).
fn layer_takes_no_restitution(impact: &ImpactLaw, compliance: f64, what: &str) -> Result<()> {
    crate::ensure!(
        compliance == 0.0 || (matches!(impact, ImpactLaw::Newton { .. }) && impact.eps() == 0.0),
        Model,
        "{what}.impact: a compliant Signorini layer rebounds by its own stiffness and damping (normal.compliance, \
         normal.damping); give no impact law or Newton(eps=0)"
    );
    Ok(())
}

/// Validates one contact description (body indices resolved by `body`).
pub(super) fn validate(
    d: &ContactDescription,
    index: usize,
    first: usize,
    body: impl Fn(&str, &str) -> Result<usize>,
    rotation: impl Fn(&Option<super::description::RotationDescription>, &str) -> Result<crate::math::Mat3> + Copy,
) -> Result<Contact> {
    let what = format!("contacts[{index}] '{}'", d.name);
    super::validate::check_name(&d.name, &format!("contacts[{index}]"))?;
    let b1 = body(&d.body1, &format!("{what}.body1"))?;
    let b2 = body(&d.body2, &format!("{what}.body2"))?;
    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{}'", d.body1);
    let c1 = contour(&d.contour1, planar(&d.contour2), &format!("{what}.contour1"), rotation)?;
    let c2 = contour(&d.contour2, planar(&d.contour1), &format!("{what}.contour2"), rotation)?;
    let contours = [c1.normalized(), c2.normalized()];
    let pair = ContactPair::new(&d.name, c1, c2)?;
    let mut pair = pair;
    for (which, c) in [(1, &d.contour1), (2, &d.contour2)] {
        if let Some(v) = surface_velocity(c) {
            pair = pair.with_surface_velocity(which, vec3(&v)).map_err(|e| match e {
                Error::Model(m) => Error::Model(format!("{what}.contour{which}.surface_velocity: {m}")),
                other => other,
            })?;
        }
    }
    let pair = match d.points {
        None => pair,
        Some(p) => pair.with_points(p).map_err(|e| match e {
            Error::Model(m) => Error::Model(format!("{what}.points: {m}")),
            other => other,
        })?,
    };
    let friction = friction_law(&d.friction, &what)?;
    let impact = impact_law(&d.impact, &what)?;
    let geometry = ContactGeometry::Contours { pair, contours };
    let (compliance, damping) = compliance(&d.normal, &what)?;
    layer_takes_no_restitution(&impact, compliance, &what)?;
    Ok(Contact { name: d.name.clone(), body1: b1, body2: b2, geometry, friction, impact, compliance, damping, first })
}

/// Validates one gap contact (`index` among the gap contacts, `first` its point index): its
/// functions parsed against the joints' coordinates, callbacks counted into `n_callbacks`.
pub(super) fn validate_gap(
    d: &GapContactDescription,
    index: usize,
    first: usize,
    joints: &[super::Joint],
    n_callbacks: &mut usize,
) -> Result<Contact> {
    let what = format!("gap_contacts[{index}] '{}'", d.name);
    super::validate::check_name(&d.name, &format!("gap_contacts[{index}]"))?;
    crate::ensure!(
        d.tangents.len() <= 2,
        Model,
        "{what}.tangents: at most 2 tangential coordinates, got {}",
        d.tangents.len()
    );
    crate::ensure!(
        !d.tangents.is_empty() || matches!(d.friction, FrictionDescription::None),
        Model,
        "{what}.friction: a friction law needs a tangential coordinate to act along (give tangents)"
    );
    let mut coordinates: Vec<(usize, usize)> = Vec::new();
    let mut terms = Vec::with_capacity(1 + d.tangents.len());
    for (k, term) in std::iter::once(&d.gap).chain(&d.tangents).enumerate() {
        let key = if k == 0 { "gap".to_string() } else { format!("tangents[{}]", k - 1) };
        match term {
            GapTermDescription::Expression(text) => {
                let resolve = |name: &str, index: Option<usize>| -> std::result::Result<usize, String> {
                    let j = joints.iter().find(|j| j.name == name).ok_or_else(|| {
                        let known: Vec<&str> = joints.iter().filter(|j| j.nq() > 0).map(|j| j.name.as_str()).collect();
                        format!("unknown name '{name}' (joint coordinates: {}; and t)", known.join(", "))
                    })?;
                    if j.kind.has_quaternion() {
                        return Err(format!(
                            "joint '{name}' turns by a quaternion; a gap function reads coordinates whose rates are                              velocities (revolute, prismatic, cylindrical, universal, planar, path joints)"
                        ));
                    }
                    let k = match (index, j.nq()) {
                        (None, 1) => 0,
                        (None, n) => {
                            return Err(format!(
                                "joint '{name}' has {n} coordinates; write {name}[0] .. {name}[{}]",
                                n.max(1) - 1
                            ))
                        }
                        (Some(k), n) if k < n => k,
                        (Some(k), n) => {
                            return Err(format!("joint '{name}' has {n} coordinate(s), [{k}] is out of range"))
                        }
                    };
                    let c = (j.iq + k, j.iu + k);
                    Ok(coordinates.iter().position(|x| *x == c).unwrap_or_else(|| {
                        coordinates.push(c);
                        coordinates.len() - 1
                    }))
                };
                let e =
                    Expr::parse(text, resolve).map_err(|m| Error::Model(format!("{what}.{key}: {m} in \"{text}\"")))?;
                // a function of time alone has no row: nothing the contact force could act on
                crate::ensure!(
                    !e.slots().is_empty(),
                    Model,
                    "{what}.{key}: \"{text}\" reads no joint coordinate; a contact function must depend on the motion"
                );
                terms.push(GapTerm::Expr(e));
            }
            GapTermDescription::Callback { callback } => {
                crate::ensure!(*callback < 1 << 32, Model, "{what}.{key}: callback index {callback} is out of range");
                if let Some(j) = joints.iter().find(|j| j.kind.has_quaternion()) {
                    return Err(Error::Model(format!(
                        "{what}.{key}: a Python gap function needs every coordinate's rate to be its velocity, but joint \
                         '{}' turns by a quaternion; write the gap as an expression of the other joints' coordinates",
                        j.name
                    )));
                }
                *n_callbacks = (*n_callbacks).max(callback + 1);
                terms.push(GapTerm::Callback(*callback));
            }
        }
    }
    let friction = friction_law(&d.friction, &what)?;
    let impact = impact_law(&d.impact, &what)?;
    let geometry = ContactGeometry::Gap { function: GapFunction::new(terms, coordinates), slot: index };
    let (compliance, damping) = compliance(&d.normal, &what)?;
    layer_takes_no_restitution(&impact, compliance, &what)?;
    Ok(Contact { name: d.name.clone(), body1: 0, body2: 0, geometry, friction, impact, compliance, damping, first })
}

/// Validates one contact group (body indices resolved by `body`): names, contours, that every
/// kind of pair the group can form has a contact geometry, and the laws.
/// The planar curve (ellipse, spline, cam, gear) of a contour description, as the engine builds
/// it, for drawing its outline; other contours are refused by name.
pub fn planar_curve(c: &ContourDescription, what: &str) -> Result<Curve> {
    match contour(c, true, what, no_rotation)? {
        Contour::Curve(curve) => Ok(*curve),
        other => {
            Err(Error::Model(format!("{what}: expected a curve (ellipse, spline, cam or gear), got {}", other.kind())))
        }
    }
}

/// Checks a visual: its body exists, its shape is a valid contour, its colour and opacity in range.
pub(super) fn validate_visual(
    d: &super::description::VisualDescription,
    i: usize,
    body: impl Fn(&str, &str) -> Result<usize>,
    rotation: impl Fn(&Option<super::description::RotationDescription>, &str) -> Result<crate::math::Mat3>,
) -> Result<()> {
    let what = if d.name.is_empty() { format!("visuals[{i}]") } else { format!("visuals[{i}] '{}'", d.name) };
    body(&d.body, &format!("{what}.body"))?;
    if let ContourDescription::Mesh { vertices, triangles, .. } = &d.shape {
        // a drawn mesh need not be closed or consistently wound (CAD exports often are not):
        // only finite vertices and indices in range
        for (k, v) in vertices.iter().enumerate() {
            crate::ensure!(
                v.iter().all(|x| x.is_finite()),
                Model,
                "{what}.shape.vertices[{k}]: must be finite, got {v:?}"
            );
        }
        for (t, tri) in triangles.iter().enumerate() {
            for (j, &i) in tri.iter().enumerate() {
                crate::ensure!(
                    i >= 0 && (i as usize) < vertices.len(),
                    Model,
                    "{what}.shape.triangles[{t}][{j}]: vertex index {i} out of range (the mesh has {} vertices)",
                    vertices.len()
                );
            }
        }
    } else {
        let c = contour(&d.shape, planar(&d.shape), &format!("{what}.shape"), rotation)?;
        c.validate(&format!("{what}.shape ({})", c.kind()))?;
    }
    if let Some(rgb) = d.color {
        crate::ensure!(
            rgb.iter().all(|v| (0.0..=1.0).contains(v)),
            Model,
            "{what}.color: expected three numbers in [0, 1], got {rgb:?}"
        );
    }
    if let Some(a) = d.opacity {
        crate::ensure!(a > 0.0 && a <= 1.0, Model, "{what}.opacity: expected a number in (0, 1], got {a}");
    }
    Ok(())
}

pub(super) fn validate_group(
    d: &ContactGroupDescription,
    index: usize,
    body: impl Fn(&str, &str) -> Result<usize>,
    rotation: impl Fn(&Option<super::description::RotationDescription>, &str) -> Result<crate::math::Mat3> + Copy,
) -> Result<ContactGroup> {
    let what = format!("contact_groups[{index}] '{}'", d.name);
    super::validate::check_name(&d.name, &format!("contact_groups[{index}]"))?;
    crate::ensure!(!d.members.is_empty(), Model, "{what}.members: a group needs at least one member");
    let any_planar = d.members.iter().chain(&d.against).any(|m| planar(&m.contour));
    let any_spatial = d
        .members
        .iter()
        .chain(&d.against)
        .any(|m| !planar(&m.contour) && !matches!(m.contour, ContourDescription::Point { .. }));
    crate::ensure!(
        !(any_planar && any_spatial),
        Model,
        "{what}: mixes planar contours (circle, line, polygon) with spatial ones; a group is either planar or spatial"
    );
    let side = |list: &[super::contact_description::GroupContourDescription], key: &str| -> Result<Vec<GroupContour>> {
        list.iter()
            .enumerate()
            .map(|(k, m)| {
                let w = format!("{what}.{key}[{k}]");
                let b = body(&m.body, &format!("{w}.body"))?;
                crate::ensure!(
                    surface_velocity(&m.contour).is_none(),
                    Model,
                    "{w}.contour.surface_velocity: moving surfaces are supported on explicit contacts, not in groups"
                );
                let c = contour(&m.contour, any_planar, &format!("{w}.contour"), rotation)?;
                c.validate(&format!("{w}.contour ({})", c.kind()))?;
                Ok(GroupContour { body: b, contour: c.normalized() })
            })
            .collect()
    };
    let members = side(&d.members, "members")?;
    let against = side(&d.against, "against")?;
    // one check per kind of pair: (first, second) member of each contour kind
    let kinds_of = |list: &[GroupContour]| {
        let mut seen: Vec<(crate::contact::ContourKind, usize, Option<usize>)> = Vec::new();
        for (k, m) in list.iter().enumerate() {
            match seen.iter_mut().find(|(kind, _, _)| *kind == m.contour.kind()) {
                Some(e) if e.2.is_none() => e.2 = Some(k),
                Some(_) => {}
                None => seen.push((m.contour.kind(), k, None)),
            }
        }
        seen
    };
    let (mk, ak) = (kinds_of(&members), kinds_of(&against));
    let check = |c1: &GroupContour, c2: &GroupContour, l1: String, l2: String| -> Result<()> {
        crate::contact::candidates(&c1.contour, &c2.contour).map(|_| ()).map_err(|e| {
            Error::Model(format!(
                "{what}: {l1} ({}) and {l2} ({}) cannot touch: {e}",
                c1.contour.kind(),
                c2.contour.kind()
            ))
        })
    };
    for (x, &(_, i, second)) in mk.iter().enumerate() {
        if let Some(j) = second {
            check(&members[i], &members[j], format!("members[{i}]"), format!("members[{j}]"))?;
        }
        for &(_, j, _) in &mk[x + 1..] {
            check(&members[i], &members[j], format!("members[{i}]"), format!("members[{j}]"))?;
        }
        for &(_, k, _) in &ak {
            check(&members[i], &against[k], format!("members[{i}]"), format!("against[{k}]"))?;
        }
    }
    let friction = friction_law(&d.friction, &what)?;
    let impact = impact_law(&d.impact, &what)?;
    let (compliance, damping) = compliance(&d.normal, &what)?;
    layer_takes_no_restitution(&impact, compliance, &what)?;
    Ok(ContactGroup {
        name: d.name.clone(),
        members,
        against,
        friction,
        impact,
        compliance,
        damping,
        planar: any_planar,
    })
}

/// Validates a contact group whose normal law is compliant (`slot` its place among the compliant
/// points, `index` among the compliant groups): the contours as for a rigid group, the
/// materials, and the law of every kind of pair the group can form (so that no pair met during
/// the run fails). The bristle law (LuGre) is refused: a group's pairs come and go, and their
/// bristle states would have to follow them through the integrator's extra states.
pub(super) fn validate_compliant_group(
    d: &ContactGroupDescription,
    index: usize,
    slot: usize,
    group_index: usize,
    body: impl Fn(&str, &str) -> Result<usize>,
    rotation: impl Fn(&Option<super::description::RotationDescription>, &str) -> Result<crate::math::Mat3> + Copy,
    n_callbacks: &mut usize,
) -> Result<super::compliant::CompliantGroup> {
    use super::compliant as cc;
    let what = format!("contact_groups[{index}] '{}'", d.name);
    crate::ensure!(
        matches!(d.impact, ImpactDescription::Newton { eps } if eps == 0.0),
        Model,
        "{what}.impact: a compliant group takes no impact law (its restitution comes from its normal law: HuntCrossley(eps=...), LankaraniNikravesh, Flores, or KelvinVoigt's damping)"
    );
    if matches!(d.friction, FrictionDescription::LuGre { .. }) {
        return Err(Error::Model(format!(
            "{what}.friction: the LuGre bristle law needs a bristle state per contact point, which a group's pairs (found anew at every evaluation) do not carry; give the group a regularized law (Coulomb, Stribeck, table) or declare the contacts that need bristles explicitly"
        )));
    }
    let mut rigid = d.clone();
    rigid.friction = FrictionDescription::None;
    rigid.normal = super::contact_description::NormalDescription::default();
    let geometry = validate_group(&rigid, index, body, rotation)?;
    let (elastic, dissipation, tangential) = compliant_law(&d.normal, &d.friction, &what, n_callbacks)?;
    let mut materials = Vec::with_capacity(d.members.len() + d.against.len());
    for (key, list) in [("members", &d.members), ("against", &d.against)] {
        for (k, m) in list.iter().enumerate() {
            let desc = m.material.or(d.material);
            let w =
                if m.material.is_some() { format!("{what}.{key}[{k}].material") } else { format!("{what}.material") };
            materials.push(desc.map(|x| cc::Material::new(x.e, x.nu, x.density, &w)).transpose()?);
        }
    }
    let group = cc::CompliantGroup { geometry, materials, elastic, dissipation, tangential, slot, index: group_index };
    if let cc::ElasticSpec::Hertz { stiffness: None, .. } = group.elastic {
        if let Some(k) = group.materials.iter().position(|m| m.is_none()) {
            return Err(Error::Model(format!(
                "{what}.{}: a Hertz-type law needs the material of every contour (the group's material = ms.Material(E, nu, density), or body.contour(..., material=...)) or a given stiffness",
                group.label(k)
            )));
        }
    }
    // one pair per kind of contour pair (and per material, where they differ)
    let n = group.materials.len();
    let members = d.members.len();
    let mut reps: Vec<usize> = Vec::new();
    for k in 0..n {
        let c = group.contour(k);
        let same = |r: &usize| {
            let o = group.contour(*r);
            (*r < members) == (k < members)
                && o.contour.kind() == c.contour.kind()
                && group.materials[*r] == group.materials[k]
        };
        // a kind seen twice among the members keeps its second member too (member–member pairs)
        let seen = reps.iter().filter(|r| same(r)).count();
        if seen == 0 || (k < members && seen == 1) {
            reps.push(k);
        }
    }
    for (x, &i) in reps.iter().enumerate() {
        if i >= members {
            continue;
        }
        for &j in &reps[x + 1..] {
            group.law(i, j)?;
        }
    }
    Ok(group)
}
