//! The description of unilateral contacts (section 2.5): a contour on each of two bodies, the
//! friction law and the impact law, as written in model files and emitted by the Python builder.
//!
//! Contours in space: `point`, `sphere`, `plane` (half-space below its normal), `box`, `capsule`,
//! `cylinder`, `torus`, `ellipsoid`, `bowl`, `bore`, `mesh` (triangles); in the plane (the x-y
//! plane of the body frame): `point`, `circle`, `line`
//! (half-plane behind its normal), `polygon`, and the parametric contours `ellipse`, `spline`,
//! `cam`, `gear`; the spatial parametric surfaces `revolution` (a planar profile turned about an
//! axis) and `patch` (a bicubic spline through a grid of points). Normal contact is always Signorini's law
//! (g_N ≥ 0, λ_N ≥ 0, g_N λ_N = 0); friction is none, Coulomb with a static and a sliding
//! coefficient, or a Stribeck curve; impacts follow Newton's or Poisson's law.

use serde::{Deserialize, Serialize};

use super::rotation_description::RotationDescription;

/// A contact between `contour1` on `body1` and `contour2` on `body2` (`ground` allowed).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactDescription {
    /// Unique contact name.
    pub name: String,
    /// First body.
    pub body1: String,
    /// Contour on body1, body-frame data.
    pub contour1: ContourDescription,
    /// Second body.
    pub body2: String,
    /// Contour on body2, body-frame data.
    pub contour2: ContourDescription,
    /// Normal law (Signorini's unilateral law if absent).
    #[serde(default)]
    pub normal: NormalDescription,
    /// Tangential law (frictionless if absent).
    #[serde(default)]
    pub friction: FrictionDescription,
    /// Impact law (a fully plastic Newton impact, ε = 0, if absent).
    #[serde(default)]
    pub impact: ImpactDescription,
    /// Number of contact points a pair with a parametric contour looks for (1 if absent, at
    /// most 8): the deepest local minima of the distance, e.g. both flanks of a groove.
    #[serde(default)]
    pub points: Option<usize>,
    /// Material of contour 1 (compliant laws: E* for Hertz and Johnson).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material1: Option<MaterialDescription>,
    /// Material of contour 2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material2: Option<MaterialDescription>,
}

/// An elastic material (see [`super::compliant::Material`]).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDescription {
    /// Young's modulus (Pa), > 0.
    #[serde(rename = "E")]
    pub e: f64,
    /// Poisson's ratio in (-1, 0.5).
    pub nu: f64,
    /// Density (kg/m³), > 0.
    pub density: f64,
}

/// A contour: closed-form geometry attached to a body (all data in the body frame, m).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContourDescription {
    /// A single point (in space, or in the plane against a planar contour).
    Point {
        /// The point.
        #[serde(default)]
        position: [f64; 3],
    },
    /// A sphere.
    Sphere {
        /// Centre.
        #[serde(default)]
        center: [f64; 3],
        /// Radius, > 0.
        radius: f64,
    },
    /// A plane bounding the half-space below `normal` (solid side opposite the normal).
    Plane {
        /// A point of the plane.
        #[serde(default)]
        point: [f64; 3],
        /// Outward normal (normalised when read).
        normal: [f64; 3],
        /// A moving surface (a conveyor belt): the velocity of its material over the plane, body
        /// frame (m/s), in the plane.
        #[serde(default)]
        surface_velocity: Option<[f64; 3]>,
    },
    /// A box.
    Box {
        /// Centre.
        #[serde(default)]
        center: [f64; 3],
        /// Orientation of the box axes in the body frame (identity if absent).
        #[serde(default)]
        rotation: Option<RotationDescription>,
        /// Half the edge lengths along the box axes, > 0.
        half_extents: [f64; 3],
    },
    /// A capsule: the points within `radius` of the segment `a`–`b`.
    Capsule {
        /// First end of the axis segment.
        a: [f64; 3],
        /// Second end of the axis segment.
        b: [f64; 3],
        /// Radius, > 0.
        radius: f64,
    },
    /// A finite solid cylinder.
    Cylinder {
        /// Centre.
        #[serde(default)]
        center: [f64; 3],
        /// Axis direction (normalised when read).
        axis: [f64; 3],
        /// Radius, > 0.
        radius: f64,
        /// Half the length along the axis, > 0.
        half_length: f64,
    },
    /// A torus (a wheel's rim; a thin disc with `tube = 0`).
    Torus {
        /// Centre of the rim circle.
        #[serde(default)]
        center: [f64; 3],
        /// Wheel axis (normalised when read).
        axis: [f64; 3],
        /// Radius of the rim circle, > 0.
        radius: f64,
        /// Tube radius, ≥ 0 and below the radius.
        #[serde(default)]
        tube: f64,
    },
    /// A solid ellipsoid.
    Ellipsoid {
        /// Centre.
        #[serde(default)]
        center: [f64; 3],
        /// Orientation of the ellipsoid's axes in the body frame (identity if absent).
        #[serde(default)]
        rotation: Option<RotationDescription>,
        /// Semi-axes along the ellipsoid's x, y, z axes, each > 0.
        semi_axes: [f64; 3],
    },
    /// A spherical cavity (a bowl): the solid lies outside the sphere.
    Bowl {
        /// Centre.
        #[serde(default)]
        center: [f64; 3],
        /// Radius, > 0.
        radius: f64,
    },
    /// A cylindrical cavity (a bore), infinite along `axis`: the solid lies outside the cylinder.
    Bore {
        /// A point of the axis.
        #[serde(default)]
        center: [f64; 3],
        /// Axis direction (normalised when read).
        axis: [f64; 3],
        /// Radius, > 0.
        radius: f64,
    },
    /// A triangle mesh: the solid lies behind the triangles' outward normals (vertices
    /// counter-clockwise seen from outside); a closed mesh wound inward is a cavity.
    Mesh {
        /// Vertices `[x, y, z]` (m, body frame).
        #[serde(default)]
        vertices: Vec<[f64; 3]>,
        /// Triangles as three vertex indices (from 0).
        #[serde(default)]
        triangles: Vec<[i64; 3]>,
        /// A mesh file, read by the Python loader (which replaces it by `vertices` and
        /// `triangles`); the engine itself reads no files.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        file: Option<String>,
    },
    /// A circle in the body's x-y plane.
    Circle {
        /// Centre (z ignored).
        #[serde(default)]
        center: [f64; 3],
        /// Radius, > 0.
        radius: f64,
    },
    /// A line in the body's x-y plane bounding the half-plane behind `normal`.
    Line {
        /// A point of the line (z ignored).
        #[serde(default)]
        point: [f64; 3],
        /// Outward normal in the x-y plane (normalised when read).
        normal: [f64; 3],
        /// A moving surface (a conveyor belt): the velocity of its material along the line, body
        /// frame (m/s), in the x-y plane and along the line.
        #[serde(default)]
        surface_velocity: Option<[f64; 3]>,
    },
    /// A convex polygon in the body's x-y plane, vertices counter-clockwise.
    Polygon {
        /// Vertices `[x, y]`, at least 3.
        vertices: Vec<[f64; 2]>,
    },
    /// An ellipse in the body's x-y plane (a parametric contour, section 2.2.7.1).
    Ellipse {
        /// Centre (z ignored).
        #[serde(default)]
        center: [f64; 3],
        /// Semi-axes `[a, b]` (m), along the ellipse's x and y axes, > 0.
        semi_axes: [f64; 2],
        /// Angle of the ellipse's x axis from the body's x axis (rad).
        #[serde(default)]
        angle: f64,
        /// `inside` (a solid ellipse, default) or `outside` (an elliptical hole).
        #[serde(default)]
        solid: Option<SolidSide>,
    },
    /// A C² cubic spline through points in the body's x-y plane.
    Spline {
        /// Points `[x, y]` (at least 2 open, 3 closed; a closed curve does not repeat its first).
        points: Vec<[f64; 2]>,
        /// Closed (periodic) or open (continued straight beyond its ends).
        #[serde(default)]
        closed: bool,
        /// Where the solid lies: `left`/`right` of the points' direction, or for closed curves
        /// `inside` (default) / `outside`; open curves default to `left`.
        #[serde(default)]
        solid: Option<SolidSide>,
    },
    /// A cam disc from a periodic lift table (section 2.2.7.1; see `geometry::curve::Curve::cam`).
    Cam {
        /// Cam angles (rad) from 0 to 2π, increasing.
        angles: Vec<f64>,
        /// Follower lift at those angles (m); periodic.
        lift: Vec<f64>,
        /// Radius of the base circle (m), > 0.
        base_radius: f64,
        /// `roller` (default), `knife` or `flat`.
        #[serde(default)]
        follower: Option<String>,
        /// Roller radius (m) for a roller follower.
        #[serde(default)]
        roller_radius: f64,
        /// Offset of the follower's axis from the cam centre (m).
        #[serde(default)]
        eccentricity: f64,
        /// +1: the cam turns counter-clockwise about its z axis as the angle grows; -1: clockwise.
        #[serde(default = "one")]
        direction: f64,
    },
    /// An external involute spur gear (a parametric contour, section 2.2.7.1).
    Gear(GearDescription),
    /// A surface of revolution (section 2.2.7.2): a planar `profile` (an `ellipse`, `spline` or
    /// `cam` table; its x is the radius, its y the height) turned about the z axis of the frame
    /// at `center`, turned by `rotation` in the body.
    Revolution {
        /// Centre (a point of the axis).
        #[serde(default)]
        center: [f64; 3],
        /// Orientation of the revolution frame (identity if absent: the axis is the body's z).
        #[serde(default)]
        rotation: Option<RotationDescription>,
        /// The meridian profile.
        profile: Box<ContourDescription>,
    },
    /// A bicubic spline patch `r(s1, s2)` through a grid of body-frame points, solid below its
    /// normal `r_1 × r_2` (section 2.2.7.2).
    Patch {
        /// Grid `points[i][j]` at `s1_i`, `s2_j` (at least 2 × 2, rectangular).
        points: Vec<Vec<[f64; 3]>>,
        /// Parameter range of `s1` (`[0, 1]` if absent); the knots are uniform.
        #[serde(default = "unit_range")]
        range1: [f64; 2],
        /// Parameter range of `s2`.
        #[serde(default = "unit_range")]
        range2: [f64; 2],
        /// Periodic in `s1`, `s2` (the last grid line must then repeat the first).
        #[serde(default)]
        periodic: [bool; 2],
    },
}

fn unit_range() -> [f64; 2] {
    [0.0, 1.0]
}

/// An external involute spur gear in the body's x-y plane (see `geometry::gear`); lengths in m,
/// angles in rad. Give `module` or `base_radius` (`r_b = m z cos α / 2`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearDescription {
    /// Module (pitch diameter / teeth), > 0.
    #[serde(default)]
    pub module: Option<f64>,
    /// Base-circle radius instead of the module.
    #[serde(default)]
    pub base_radius: Option<f64>,
    /// Number of teeth, 5 to 170.
    pub teeth: usize,
    /// Pressure angle on the pitch circle (rad), 20° if absent.
    #[serde(default)]
    pub pressure_angle: Option<f64>,
    /// Profile shift coefficient x (the tool moved out by x m).
    #[serde(default)]
    pub shift: f64,
    /// Tooth thinning on the pitch circle (arc length, m), ≥ 0.
    #[serde(default)]
    pub backlash: f64,
    /// Tip circle above the shifted pitch circle (m); the module if absent.
    #[serde(default)]
    pub addendum: Option<f64>,
    /// Root circle below the shifted pitch circle (m); 1.25 modules if absent.
    #[serde(default)]
    pub dedendum: Option<f64>,
    /// Tip rounding radius (m); 0.05 modules (or what fits) if absent.
    #[serde(default)]
    pub tip_radius: Option<f64>,
    /// Root fillet radius (m); 0.2 modules (or what fits) if absent.
    #[serde(default)]
    pub root_radius: Option<f64>,
    /// Centre of the gear (z ignored).
    #[serde(default)]
    pub center: [f64; 3],
    /// Direction of tooth 0's centre line from the body's x axis (rad).
    #[serde(default)]
    pub phase: f64,
}

/// Where a parametric contour's solid lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolidSide {
    /// Left of the direction of the points.
    Left,
    /// Right of it.
    Right,
    /// Inside the closed curve.
    Inside,
    /// Outside the closed curve (a hole).
    Outside,
}

fn one() -> f64 {
    1.0
}

/// A unilateral contact given by its normal distance `g_N(q, t)` (and optional tangential
/// coordinates whose rates are the sliding velocities), with the laws of any contact.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GapContactDescription {
    /// Unique contact name (shared with the contacts and groups).
    pub name: String,
    /// `g_N(q, t)` (m or the unit of the coordinates it reads): open where > 0.
    pub gap: GapTermDescription,
    /// Tangential coordinates `g_T,k(q, t)` (at most 2): the friction law acts against their rates.
    #[serde(default)]
    pub tangents: Vec<GapTermDescription>,
    /// Normal law (Signorini's if absent; bilateral: g_N = 0 held as a constraint, and with
    /// `rolling` the tangential coordinates' rates too).
    #[serde(default)]
    pub normal: NormalDescription,
    /// Tangential law (frictionless if absent; needs at least one tangent).
    #[serde(default)]
    pub friction: FrictionDescription,
    /// Impact law (a fully plastic Newton impact, ε = 0, if absent).
    #[serde(default)]
    pub impact: ImpactDescription,
}

/// One function of a gap contact: an expression of the joint coordinates (by joint name, or
/// `name[k]` for coordinate k of a multi-coordinate joint) and the time `t`, or a Python callable.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(untagged)]
pub enum GapTermDescription {
    /// A closed-form expression (`math::expr` grammar).
    Expression(String),
    /// A callable by its callback id (given by the Python builder).
    Callback {
        /// Callback id.
        callback: usize,
    },
}

/// Normal contact law.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum NormalDescription {
    /// Signorini's corner law: g_N ≥ 0, λ_N ≥ 0, g_N λ_N = 0 (a unilateral contact); with a
    /// `compliance` c > 0 (m/N) a linear compliant layer in series, `g_N + c λ_N ≥ 0`, damped by
    /// `damping` d (the time-stepping scheme's regularized Signorini law; see
    /// `integrator::moreau_jean`).
    Signorini {
        /// Compliance c = 1/k of the contact layer (m/N), ≥ 0; 0 for a rigid contact.
        #[serde(default, skip_serializing_if = "is_zero")]
        compliance: f64,
        /// Damping d of the layer (N s/m), ≥ 0 (with a compliance only): `k δ + d δ̇ = λ_N`.
        #[serde(default, skip_serializing_if = "is_zero")]
        damping: f64,
    },
    /// The contact is held closed, g_N = 0, by a bilateral constraint whose force may pull (a
    /// follower that never lifts off, a wheel held on its rail); with `rolling`, it also rolls
    /// without slipping (ġ_T = 0). No friction or impact law applies.
    Bilateral {
        /// Whether the tangential relative velocity is held at zero too.
        #[serde(default)]
        rolling: bool,
        /// Whether g_N = 0 is held (the default). `false` with `rolling`: only the tangents are
        /// held (rolling without slip) while another law of the same pair carries the normal
        /// force, e.g. a contact held on its compliant layer for a linearization.
        #[serde(default = "yes", skip_serializing_if = "is_true")]
        hold_normal: bool,
    },
    /// Compliant, Kelvin–Voigt: F = max(0, k δ + d δ̇) with δ = −g_N the overlap.
    KelvinVoigt {
        /// Stiffness (N/m), > 0.
        k: f64,
        /// Damping (N s/m), ≥ 0.
        #[serde(default)]
        d: f64,
        /// Regularization velocity of the friction law (m/s).
        #[serde(default)]
        v_reg: Option<f64>,
    },
    /// Compliant, Hertz: F = K δ^{3/2} (point) or Johnson's line law, undamped.
    Hertz(HertzDescription),
    /// Compliant, Hertz with Hunt–Crossley damping.
    HuntCrossley(HertzDescription),
    /// Compliant, Hertz with Lankarani–Nikravesh damping.
    LankaraniNikravesh(HertzDescription),
    /// Compliant, Hertz with Flores' damping.
    Flores(HertzDescription),
    /// Compliant, a user law F(δ, δ̇) (a Python callable, by its callback id).
    User {
        /// Callback id.
        callback: usize,
        /// Regularization velocity of the friction law (m/s).
        #[serde(default)]
        v_reg: Option<f64>,
    },
}

impl Default for NormalDescription {
    fn default() -> Self {
        NormalDescription::Signorini { compliance: 0.0, damping: 0.0 }
    }
}

fn yes() -> bool {
    true
}

fn is_true(v: &bool) -> bool {
    *v
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl NormalDescription {
    /// Whether this is Signorini's law, rigid or with a compliant layer (a unilateral contact of
    /// the time-stepping scheme, not a force element).
    pub fn is_signorini(&self) -> bool {
        matches!(self, NormalDescription::Signorini { .. })
    }

    /// Whether this is the default, rigid Signorini law (left out when written).
    pub fn is_rigid_signorini(&self) -> bool {
        matches!(self, NormalDescription::Signorini { compliance, damping } if *compliance == 0.0 && *damping == 0.0)
    }
}

/// The parameters of a Hertz-type compliant law.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzDescription {
    /// K (N/m^1.5) given directly instead of from the materials and curvatures.
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// Restitution the damping is tuned for, in (0, 1] (the dissipative laws).
    #[serde(default)]
    pub eps: Option<f64>,
    /// The damping coefficient α (s/m) given directly instead of from `eps`.
    #[serde(default)]
    pub alpha: Option<f64>,
    /// Contact length (m) of a line contact (planar discs; a cylinder's own length otherwise).
    #[serde(default)]
    pub length: Option<f64>,
    /// Regularization velocity of the friction law (m/s).
    #[serde(default)]
    pub v_reg: Option<f64>,
}

/// Tangential contact law.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum FrictionDescription {
    /// Frictionless.
    #[default]
    None,
    /// Coulomb's law (2.200): sliding coefficient `mu`, static coefficient `mu0` (≥ mu; = mu if absent).
    Coulomb {
        /// Sliding friction coefficient, ≥ 0.
        mu: f64,
        /// Static friction coefficient, ≥ mu.
        #[serde(default)]
        mu0: Option<f64>,
    },
    /// A Stribeck curve (2.201): µ(v) = mu + (mu0 - mu) exp(-(|v| / v_s)^exponent).
    Stribeck {
        /// Static coefficient µ(0), ≥ mu.
        mu0: f64,
        /// Coefficient at high sliding speed, ≥ 0.
        mu: f64,
        /// Stribeck velocity (m/s), > 0.
        v_s: f64,
        /// Shape exponent, > 0 (2 if absent).
        #[serde(default = "two")]
        exponent: f64,
    },
    /// µ(|v|) tabulated and interpolated linearly (constant beyond the ends).
    Table {
        /// Sliding speeds (m/s), ascending, starting at 0.
        speed: Vec<f64>,
        /// Coefficients at those speeds, ≥ 0; the first is the static coefficient.
        mu: Vec<f64>,
    },
    /// The LuGre bristle law (compliant contacts only; see [`super::compliant`]).
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
        #[serde(default)]
        sigma1: f64,
        /// Viscous friction per unit normal force (s/m).
        #[serde(default)]
        sigma2: f64,
    },
}

fn two() -> f64 {
    2.0
}

/// Impact law.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ImpactDescription {
    /// Newton's kinematic law (2.202): ġ_N⁺ = -ε ġ_N⁻ (normal direction only).
    Newton {
        /// Coefficient of restitution in [0, 1].
        eps: f64,
    },
    /// Poisson's kinetic law (2.203): expansion impulse = ε × compression impulse, in normal and
    /// (with `eps_t`) tangential direction.
    Poisson {
        /// Normal coefficient in [0, 1].
        eps: f64,
        /// Tangential coefficient in [0, 1] (0 if absent).
        #[serde(default)]
        eps_t: f64,
    },
}

impl Default for ImpactDescription {
    fn default() -> Self {
        ImpactDescription::Newton { eps: 0.0 }
    }
}

/// A contact group: every pair among `members` may touch (pairs on one body excepted), and each
/// member may touch each contour of `against` (typically the walls and floor of a container),
/// all with one friction law and one impact law. Which pairs are close enough to be checked is
/// decided at every step by a broad phase over bounding boxes, so a group of N members costs
/// about O(N) per step rather than the N(N-1)/2 explicit contacts it stands for.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactGroupDescription {
    /// Unique name (shared namespace with the contacts).
    pub name: String,
    /// Contours that may touch each other and the `against` contours.
    pub members: Vec<GroupContourDescription>,
    /// Contours that the members may touch but that are not checked against each other.
    #[serde(default)]
    pub against: Vec<GroupContourDescription>,
    /// Tangential law (frictionless if absent).
    #[serde(default)]
    pub friction: FrictionDescription,
    /// Impact law (a fully plastic Newton impact, ε = 0, if absent).
    #[serde(default)]
    pub impact: ImpactDescription,
    /// Normal law of every pair: Signorini's (rigid, Moreau–Jean) if absent, or a compliant law
    /// (Kelvin–Voigt, Hertz and its dissipative forms, a user law): the group's pairs are then
    /// force elements found by the broad phase at every evaluation, in the smooth schemes too.
    #[serde(default, skip_serializing_if = "NormalDescription::is_rigid_signorini")]
    pub normal: NormalDescription,
    /// Material of every contour that gives none of its own (compliant groups).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialDescription>,
}

/// A contour on a body, as a member of a contact group.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupContourDescription {
    /// The body carrying the contour (`ground` allowed).
    pub body: String,
    /// The contour, body-frame data.
    pub contour: ContourDescription,
    /// Its material (compliant groups; the group's `material` if absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialDescription>,
}
