//! The model description: the plain-data form of a model shared by model files (TOML), the Python
//! builder (which emits the same structure as JSON) and the engine. Parsing reports the key path of
//! any error (`bodies[2].inertia`); unknown keys are rejected so that a misspelt key never passes
//! silently. [`super::Model::from_description`] turns it into a validated [`super::Model`].

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

use super::contact_description::{ContactDescription, ContactGroupDescription, GapContactDescription};
pub use super::rotation_description::{AnglesDescription, RotationDescription};

/// A whole model as written in a model file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDescription {
    /// Model name.
    #[serde(default = "default_name")]
    pub name: String,
    /// Gravitational acceleration in the inertial frame (m/s²).
    #[serde(default)]
    pub gravity: [f64; 3],
    /// Rigid bodies (the ground is implicit and named `ground`).
    #[serde(default)]
    pub bodies: Vec<BodyDescription>,
    /// Joints; they must form a tree rooted at the ground.
    #[serde(default)]
    pub joints: Vec<JointDescription>,
    /// Force elements.
    #[serde(default)]
    pub forces: Vec<ForceDescription>,
    /// Markers (named frames) on the ground.
    #[serde(default)]
    pub ground_markers: Vec<MarkerDescription>,
    /// Bilateral constraints beyond the tree (loop closures, couplers, driven coordinates).
    #[serde(default)]
    pub constraints: Vec<ConstraintDescription>,
    /// Unilateral contacts between contours on bodies.
    #[serde(default)]
    pub contacts: Vec<ContactDescription>,
    /// Contact groups: every pair among a set of contours, and each of them against a set of
    /// other contours, with one friction and one impact law (pairs found by a broad phase).
    #[serde(default)]
    pub contact_groups: Vec<ContactGroupDescription>,
    /// Unilateral contacts given by user gap functions of the coordinates and time.
    #[serde(default)]
    pub gap_contacts: Vec<GapContactDescription>,
    /// A planar model: every body moves in the world x-y plane (revolute joints about z,
    /// prismatic and planar joints in the plane), loop closures keep only their in-plane rows.
    #[serde(default)]
    pub planar: bool,
    /// Shapes drawn by the viewer only (no contact): a contour's geometry or a triangle mesh on a
    /// body, with an optional colour.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub visuals: Vec<VisualDescription>,
}

/// A shape drawn on a body by the viewer; the engine only checks it.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VisualDescription {
    /// Visual name (optional; for the viewer's legend).
    #[serde(default)]
    pub name: String,
    /// The body carrying it (`ground` allowed).
    pub body: String,
    /// Its geometry, written as a contact contour (body frame).
    pub shape: super::contact_description::ContourDescription,
    /// RGB colour, each in [0, 1].
    #[serde(default)]
    pub color: Option<[f64; 3]>,
    /// Opacity in (0, 1].
    #[serde(default)]
    pub opacity: Option<f64>,
}

/// A bilateral constraint. Read through a JSON value so that a malformed entry's error names the
/// constraint and the key inside it (`constraint 'k'.frame1: unknown field ...`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(remote = "Self", tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ConstraintDescription {
    /// Point `point1` on `body1` coincides with point `point2` on `body2` (a spherical loop closure).
    Point {
        /// Constraint name.
        name: String,
        /// First body.
        body1: String,
        /// Point on body1, body frame.
        #[serde(default)]
        point1: [f64; 3],
        /// Second body (`ground` allowed).
        body2: String,
        /// Point on body2, body frame.
        #[serde(default)]
        point2: [f64; 3],
    },
    /// Fixed distance between two body points (a massless rod with ball joints at both ends).
    Distance {
        /// Constraint name.
        name: String,
        /// First body.
        body1: String,
        /// Point on body1, body frame.
        #[serde(default)]
        point1: [f64; 3],
        /// Second body (`ground` allowed).
        body2: String,
        /// Point on body2, body frame.
        #[serde(default)]
        point2: [f64; 3],
        /// Distance (m), > 0.
        length: f64,
    },
    /// Coupler (gear) between single-coordinate joints: q(joint1) = ratio · q(joint2) + offset.
    Coupler {
        /// Constraint name.
        name: String,
        /// Driven joint.
        joint1: String,
        /// Driving joint.
        joint2: String,
        /// Ratio.
        ratio: f64,
        /// Offset.
        #[serde(default)]
        offset: f64,
    },
    /// Prescribed motion of one joint coordinate: q(joint)[index] = f(t).
    Prescribed {
        /// Constraint name.
        name: String,
        /// Driven joint.
        joint: String,
        /// Coordinate of the joint (default 0).
        #[serde(default)]
        index: usize,
        /// The motion q(t).
        function: TimeFunctionDescription,
    },
    /// Point `point1` on `body1` stays on the line through `point2` of `body2` along `direction`
    /// (body2 frame): 2 rows.
    PointOnLine {
        /// Constraint name.
        name: String,
        /// First body.
        body1: String,
        /// Point on body1, body frame.
        #[serde(default)]
        point1: [f64; 3],
        /// Second body (`ground` allowed).
        body2: String,
        /// A point of the line, body2 frame.
        #[serde(default)]
        point2: [f64; 3],
        /// Line direction, body2 frame (normalized).
        direction: [f64; 3],
    },
    /// Point `point1` on `body1` stays in the plane through `point2` of `body2` with `normal`
    /// (body2 frame): 1 row.
    PointOnPlane {
        /// Constraint name.
        name: String,
        /// First body.
        body1: String,
        /// Point on body1, body frame.
        #[serde(default)]
        point1: [f64; 3],
        /// Second body (`ground` allowed).
        body2: String,
        /// A point of the plane, body2 frame.
        #[serde(default)]
        point2: [f64; 3],
        /// Plane normal, body2 frame (normalized).
        normal: [f64; 3],
    },
    /// Loop-closing spherical joint: the origins of `frame1` (on body1) and `frame2` (on body2)
    /// coincide (3 rows).
    LoopSpherical(LoopFrames),
    /// Loop-closing revolute joint about the common z-axis of `frame1` and `frame2` (5 rows).
    LoopRevolute(LoopFrames),
    /// Loop-closing fixed joint: `frame1` and `frame2` coincide (6 rows).
    LoopFixed(LoopFrames),
    /// Loop-closing prismatic joint along the z-axis of `frame2`: the origin of `frame1` stays on
    /// that axis and the orientations coincide (5 rows).
    LoopPrismatic(LoopFrames),
    /// Loop-closing cylindrical joint: the origin of `frame1` stays on the z-axis of `frame2` and
    /// the z-axes stay parallel (4 rows).
    LoopCylindrical(LoopFrames),
    /// Loop-closing universal (Hooke) joint: the origins coincide and the x-axis of `frame1`
    /// stays perpendicular to the y-axis of `frame2` (4 rows).
    LoopUniversal(LoopFrames),
    /// Loop-closing planar joint: the z-axes stay parallel and the origin of `frame1` stays in the
    /// x-y plane of `frame2` (3 rows).
    LoopPlanar(LoopFrames),
    /// Prescribed motion of a frame on a body (a driving constraint): its origin follows three
    /// time functions (world x, y, z) and, if given, its orientation three time functions of the
    /// Cardan angles x-y-z (3 or 6 rows).
    PrescribedBody {
        /// Constraint name.
        name: String,
        /// The driven body.
        body: String,
        /// The driven frame on the body (default: the body frame).
        #[serde(default)]
        frame: FrameDescription,
        /// World x, y, z of the frame origin: exactly 3 time functions.
        position: Vec<TimeFunctionDescription>,
        /// Cardan angles x-y-z of the frame's orientation: 3 time functions, or absent.
        #[serde(default)]
        orientation: Option<Vec<TimeFunctionDescription>>,
    },
    /// A user-given non-holonomic constraint `W(q, t)ᵀ u + w(q, t) = 0` (eq. 2.70) from Python
    /// callables (`rows` velocity rows). The arrays are callback indices (see
    /// `mechsys.constraints.Velocity`); a TOML model file cannot define the callables.
    Velocity {
        /// Constraint name.
        name: String,
        /// Number of rows, ≥ 1.
        rows: usize,
        /// Callback index of `W(t, q) -> (rows, nu)` (the transposed W of eq. 2.70).
        #[serde(rename = "W")]
        w_matrix: usize,
        /// Callback index of `w(t, q) -> (rows,)`; zero if absent.
        #[serde(rename = "w", default)]
        w_offset: Option<usize>,
        /// Callback index of `Wdot(t, q, u) -> (rows,)` = `d(Wᵀ)/dt u + ẇ`; central differences
        /// if absent.
        #[serde(rename = "Wdot", default)]
        w_rate: Option<usize>,
    },
    /// Knife edge (sledge, skate): the velocity of `point` of `body` along the body-fixed
    /// `direction` is zero (1 non-holonomic row).
    KnifeEdge {
        /// Constraint name.
        name: String,
        /// The body.
        body: String,
        /// Contact point, body frame.
        #[serde(default)]
        point: [f64; 3],
        /// Blocked direction, body frame (normalized).
        direction: [f64; 3],
    },
    /// A disc of `radius` about the body-fixed `axis` through `center` rolls without slipping on
    /// the ground plane z = 0 (1 holonomic + 2 non-holonomic rows).
    RollingDisc {
        /// Constraint name.
        name: String,
        /// The disc body.
        body: String,
        /// Disc centre, body frame.
        #[serde(default)]
        center: [f64; 3],
        /// Disc axis, body frame (normalized).
        axis: [f64; 3],
        /// Radius (m), > 0.
        radius: f64,
    },
}

/// The two frames of a loop-closing joint (every `loop_*` constraint type).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoopFrames {
    /// Constraint name.
    pub name: String,
    /// First body.
    pub body1: String,
    /// Frame on body1.
    #[serde(default)]
    pub frame1: FrameDescription,
    /// Second body (`ground` allowed).
    pub body2: String,
    /// Frame on body2.
    #[serde(default)]
    pub frame2: FrameDescription,
}

impl Serialize for ConstraintDescription {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        ConstraintDescription::serialize(self, s)
    }
}

impl<'de> Deserialize<'de> for ConstraintDescription {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Derived(ConstraintDescription);
        impl<'de> Deserialize<'de> for Derived {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
                ConstraintDescription::deserialize(d).map(Derived)
            }
        }
        let v = serde_json::Value::deserialize(d)?;
        serde_path_to_error::deserialize::<_, Derived>(&v).map(|x| x.0).map_err(|e| {
            let who = match v.get("name").and_then(|n| n.as_str()) {
                Some(n) => format!("constraint '{n}'"),
                None => "constraint".to_string(),
            };
            let mut path = e.path().to_string();
            let msg = e.inner().to_string();
            // an internally tagged enum buffers its content, so the path stops at the variant:
            // locate a misspelt key inside a nested table (frame1, frame2) by its name
            if let Some(key) = msg.strip_prefix("unknown field `").and_then(|r| r.split('`').next()) {
                if let Some(obj) = v.as_object().filter(|o| !o.contains_key(key)) {
                    if let Some((outer, _)) =
                        obj.iter().find(|(_, x)| x.as_object().is_some_and(|o| o.contains_key(key)))
                    {
                        path = outer.clone();
                    }
                }
            }
            let at = if path == "." || path.is_empty() { who } else { format!("{who}.{path}") };
            <D::Error as serde::de::Error>::custom(format!("{at}: {msg}"))
        })
    }
}

impl ConstraintDescription {
    /// The constraint's name.
    pub fn name(&self) -> &str {
        match self {
            ConstraintDescription::Point { name, .. }
            | ConstraintDescription::Distance { name, .. }
            | ConstraintDescription::Coupler { name, .. }
            | ConstraintDescription::Prescribed { name, .. }
            | ConstraintDescription::PointOnLine { name, .. }
            | ConstraintDescription::PointOnPlane { name, .. }
            | ConstraintDescription::LoopSpherical(LoopFrames { name, .. })
            | ConstraintDescription::LoopRevolute(LoopFrames { name, .. })
            | ConstraintDescription::LoopFixed(LoopFrames { name, .. })
            | ConstraintDescription::LoopPrismatic(LoopFrames { name, .. })
            | ConstraintDescription::LoopCylindrical(LoopFrames { name, .. })
            | ConstraintDescription::LoopUniversal(LoopFrames { name, .. })
            | ConstraintDescription::LoopPlanar(LoopFrames { name, .. })
            | ConstraintDescription::PrescribedBody { name, .. }
            | ConstraintDescription::Velocity { name, .. }
            | ConstraintDescription::KnifeEdge { name, .. }
            | ConstraintDescription::RollingDisc { name, .. } => name,
        }
    }
}

fn default_name() -> String {
    "model".to_string()
}

/// An inertia tensor as a full 3×3 matrix, its diagonal `[Ixx, Iyy, Izz]`, or the six independent
/// entries `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]` (products of inertia as matrix entries, i.e. `Ixy = -∫xy dm`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(untagged)]
pub enum InertiaDescription {
    /// Full matrix, rows.
    Matrix([[f64; 3]; 3]),
    /// Diagonal or six entries.
    List(Vec<f64>),
}

/// A frame placed on a body: position of its origin and orientation, both in the body frame.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameDescription {
    /// Origin in the body frame (m).
    #[serde(default)]
    pub position: [f64; 3],
    /// Orientation relative to the body frame (identity if absent).
    #[serde(default)]
    pub rotation: Option<RotationDescription>,
}

/// A named body-fixed frame.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerDescription {
    /// Marker name, unique on its body.
    pub name: String,
    /// Origin in the body frame (m).
    #[serde(default)]
    pub position: [f64; 3],
    /// Orientation relative to the body frame.
    #[serde(default)]
    pub rotation: Option<RotationDescription>,
}

/// A rigid body.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyDescription {
    /// Unique body name.
    pub name: String,
    /// Mass (kg), > 0. For a variable-mass body, the mass at t = 0.
    pub mass: f64,
    /// Inertia tensor about the centre of mass, body-frame components (kg m²).
    pub inertia: InertiaDescription,
    /// Centre of mass in the body frame (m).
    #[serde(default)]
    pub com: [f64; 3],
    /// Named body-fixed frames.
    #[serde(default)]
    pub markers: Vec<MarkerDescription>,
    /// Variable mass (section 2.1.1): mass rate ṁ (kg/s), negative when mass is ejected.
    #[serde(default)]
    pub mass_rate: f64,
    /// Velocity of the ejected (or accreted) mass relative to the body, body frame (m/s).
    #[serde(default)]
    pub ejection_velocity: [f64; 3],
    /// Point (body frame) where the thrust acts; defaults to the centre of mass.
    #[serde(default)]
    pub ejection_point: Option<[f64; 3]>,
    /// Mass at which the mass flow stops (burn-out), > 0; required when `mass_rate < 0`.
    #[serde(default)]
    pub mass_final: Option<f64>,
    /// Makes the body elastic (floating frame of reference, [`crate::elastic`]); its mass, centre
    /// of mass and inertia are then those of the undeformed body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic: Option<ElasticDescription>,
}

/// The elastic part of a body: Ritz invariants (body frame, SI), stiffness, damping, nodes.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticDescription {
    /// Number of elastic coordinates n_e.
    pub modes: usize,
    /// `∫ Φ_k dm` per mode (n_e vectors).
    pub s_t: Vec<[f64; 3]>,
    /// `∫ r0 Φ_kᵀ dm` per mode, 3 × 3 row-major (n_e).
    pub p1: Vec<[f64; 9]>,
    /// `∫ Φ_k Φ_lᵀ dm` per pair, 3 × 3 row-major, at `k n_e + l` (n_e²).
    pub p2: Vec<[f64; 9]>,
    /// Rotary inertia of the mass elements themselves (section torsion, rotary inertia), which
    /// the translations of `p1`, `p2` do not carry: `∫ J ψ_k` per mode (n_e vectors, the coupling
    /// with the reference rotation); none by default.
    #[serde(default)]
    pub s_r: Option<Vec<[f64; 3]>>,
    /// Their elastic mass `∫ ψ_kᵀ J ψ_l` (n_e × n_e, added to the traces of `p2`); none by default.
    #[serde(default)]
    pub m_rr: Option<Vec<Vec<f64>>>,
    /// Stiffness matrix (n_e × n_e).
    pub stiffness: Vec<Vec<f64>>,
    /// Damping matrix (n_e × n_e); none by default.
    #[serde(default)]
    pub damping: Option<Vec<Vec<f64>>>,
    /// Geometric stiffness of 12 unit body-force fields per unit mass: `e_x, e_y, e_z`, then
    /// `e_a s_b` for a, b in x, y, z (a-major); none by default.
    #[serde(default)]
    pub geometric: Option<Vec<Vec<Vec<f64>>>>,
    /// Nodes where markers attach.
    #[serde(default)]
    pub nodes: Vec<ElasticNodeDescription>,
    /// Initial elastic coordinates (default zero).
    #[serde(default)]
    pub q0: Option<Vec<f64>>,
    /// Initial elastic velocities (default zero).
    #[serde(default)]
    pub u0: Option<Vec<f64>>,
}

/// A node of an elastic body.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticNodeDescription {
    /// Node name.
    pub name: String,
    /// Undeformed position, body frame (m).
    pub position: [f64; 3],
    /// Translation per unit elastic coordinate (n_e vectors).
    pub translation: Vec<[f64; 3]>,
    /// Small rotation per unit elastic coordinate (n_e vectors, or none).
    #[serde(default)]
    pub rotation: Vec<[f64; 3]>,
}

/// A linear spring on a joint coordinate: τ = -k (q - q_free).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpringDescription {
    /// Stiffness (N/m or N m/rad), one per joint coordinate or one for all.
    pub k: Vec<f64>,
    /// Unloaded position, one per joint coordinate (default 0).
    #[serde(default)]
    pub q_free: Option<Vec<f64>>,
}

/// A linear damper on a joint velocity: τ = -d u.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDamperDescription {
    /// Damping coefficient (N s/m or N m s/rad), one per joint velocity or one for all.
    pub d: Vec<f64>,
}

/// A joint between a parent and a child body.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDescription {
    /// Unique joint name.
    pub name: String,
    /// Joint type: fixed, revolute, prismatic, cylindrical, universal, spherical, planar, free, path.
    #[serde(rename = "type")]
    pub kind: String,
    /// Parent body name (`ground` for the inertial frame).
    pub parent: String,
    /// Child body name.
    pub child: String,
    /// Joint axis in the joint frame (revolute, prismatic, cylindrical; default z).
    #[serde(default)]
    pub axis: Option<[f64; 3]>,
    /// Second axis of a universal joint, in the child joint frame (default y; first axis default x).
    #[serde(default)]
    pub axis2: Option<[f64; 3]>,
    /// Path joint: radius of the helix about the joint frame's z-axis (m), > 0.
    #[serde(default)]
    pub radius: Option<f64>,
    /// Path joint: rise of the helix per turn (m; 0, the default, is a circle).
    #[serde(default)]
    pub pitch: Option<f64>,
    /// Path joint: whether the child frame turns with the curve's trihedral (default true).
    #[serde(default)]
    pub oriented: Option<bool>,
    /// Path joint: the curve, `helix` (default), `clothoid`, `spline` (through `points`) or
    /// `hermite` (through samples with derivatives, as `joints.Path.function` writes them).
    #[serde(default)]
    pub curve: Option<String>,
    /// Clothoid: the parameter A (m, > 0), κ(s) = κ₀ + s/A².
    #[serde(default, rename = "A")]
    pub clothoid_a: Option<f64>,
    /// Clothoid: the curvature at s = 0 (1/m, default 0).
    #[serde(default)]
    pub kappa0: Option<f64>,
    /// Spline: the points it passes through (m, joint frame); hermite: the sampled positions.
    #[serde(default)]
    pub points: Option<Vec<[f64; 3]>>,
    /// Spline or hermite: whether the curve closes on itself (default false).
    #[serde(default)]
    pub closed: Option<bool>,
    /// Spline or hermite: the reference direction of the child frame's binormal (see
    /// `kinematics::path`); default the plane's normal, or the direction the path runs along least.
    #[serde(default)]
    pub up: Option<[f64; 3]>,
    /// Hermite: the sample parameter values (increasing).
    #[serde(default)]
    pub parameters: Option<Vec<f64>>,
    /// Hermite: dr/dp at the samples.
    #[serde(default)]
    pub tangents: Option<Vec<[f64; 3]>>,
    /// Hermite: d²r/dp² at the samples.
    #[serde(default)]
    pub second_derivatives: Option<Vec<[f64; 3]>>,
    /// Joint frame on the parent body.
    #[serde(default)]
    pub parent_frame: FrameDescription,
    /// Joint frame on the child body.
    #[serde(default)]
    pub child_frame: FrameDescription,
    /// Initial joint coordinates (length nq of the joint; a plain number for a 1-DOF joint).
    #[serde(default, deserialize_with = "one_or_many_opt")]
    pub q0: Option<Vec<f64>>,
    /// Initial joint velocities (length nu of the joint; a plain number for a 1-DOF joint).
    #[serde(default, deserialize_with = "one_or_many_opt")]
    pub u0: Option<Vec<f64>>,
    /// Joint spring.
    #[serde(default)]
    pub spring: Option<JointSpringDescription>,
    /// Joint damper.
    #[serde(default)]
    pub damper: Option<JointDamperDescription>,
}

impl JointDescription {
    /// A joint of type `kind` from `parent` to `child` with every optional key at its default
    /// (for building descriptions in code: `JointDescription { axis, ..JointDescription::new(..) }`).
    pub fn new(name: &str, kind: &str, parent: &str, child: &str) -> Self {
        JointDescription {
            name: name.into(),
            kind: kind.into(),
            parent: parent.into(),
            child: child.into(),
            axis: None,
            axis2: None,
            radius: None,
            pitch: None,
            oriented: None,
            curve: None,
            clothoid_a: None,
            kappa0: None,
            points: None,
            closed: None,
            up: None,
            parameters: None,
            tangents: None,
            second_derivatives: None,
            parent_frame: FrameDescription::default(),
            child_frame: FrameDescription::default(),
            q0: None,
            u0: None,
            spring: None,
            damper: None,
        }
    }
}

/// A scalar function of time.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeFunctionDescription {
    /// f(t) = value.
    Constant {
        /// The value.
        value: f64,
    },
    /// f(t) = 0 before `t0`, slope·(t - t0) after, held at `final_value` once reached (if given).
    Ramp {
        /// Slope (1/s).
        slope: f64,
        /// Start time (s).
        #[serde(default)]
        t0: f64,
        /// Value at which the ramp stops rising.
        #[serde(default)]
        final_value: Option<f64>,
    },
    /// f(t) = offset + amplitude·sin(omega·t + phase).
    Harmonic {
        /// Amplitude.
        amplitude: f64,
        /// Circular frequency (rad/s).
        omega: f64,
        /// Phase (rad).
        #[serde(default)]
        phase: f64,
        /// Offset.
        #[serde(default)]
        offset: f64,
    },
    /// Piecewise-linear interpolation of a table, held constant outside it.
    Table {
        /// Strictly increasing times (s).
        t: Vec<f64>,
        /// Values at those times.
        values: Vec<f64>,
    },
    /// A user callback registered under an index (Python callables; slow).
    Callback {
        /// Index into the callback table given with the model.
        id: usize,
    },
}

/// A force element.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ForceDescription {
    /// Point-to-point spring–damper between two body points:
    /// F = k (l - l0) + k3 (l - l0)³ + d l̇ (+ a tabulated force of l - l0), pulling the points together when positive.
    SpringDamper {
        /// Element name.
        name: String,
        /// First body.
        body1: String,
        /// Attachment point on body1, body frame.
        #[serde(default)]
        point1: [f64; 3],
        /// Second body.
        body2: String,
        /// Attachment point on body2, body frame.
        #[serde(default)]
        point2: [f64; 3],
        /// Linear stiffness (N/m).
        #[serde(default)]
        k: f64,
        /// Cubic stiffness (N/m³).
        #[serde(default)]
        k3: f64,
        /// Damping (N s/m).
        #[serde(default)]
        d: f64,
        /// Unstretched length (m).
        #[serde(default)]
        l0: f64,
        /// Optional tabulated force–deflection curve: deflections (m), increasing.
        #[serde(default)]
        table_deflection: Option<Vec<f64>>,
        /// Forces (N) at `table_deflection`.
        #[serde(default)]
        table_force: Option<Vec<f64>>,
        /// Stop travel s (m) of a progressive (elastomer-mount) law: the linear spring and damper
        /// terms are divided by `1 − (δ/s)²`, so the force grows without bound as |δ| → s.
        #[serde(default)]
        travel: Option<f64>,
    },
    /// Six-component bushing between `frame1` on body1 and `frame2` on body2: the deflection
    /// `x = [Δr; θ]` of frame 2 relative to frame 1 (translation and rotation vector, frame-1
    /// components) and its rate give the wrench `−K x − D ẋ` on frame 2 (equal and opposite on body1).
    Bushing {
        /// Element name.
        name: String,
        /// First body.
        body1: String,
        /// Frame on body1.
        #[serde(default)]
        frame1: FrameDescription,
        /// Second body.
        body2: String,
        /// Frame on body2.
        #[serde(default)]
        frame2: FrameDescription,
        /// Stiffness: 6 diagonal values [kx, ky, kz, kα, kβ, kγ] (N/m, N m/rad) or a symmetric 6×6 matrix (36 values, row-major).
        #[serde(default)]
        k: Vec<f64>,
        /// Damping: 6 diagonal values (N s/m, N m s/rad) or a symmetric 6×6 matrix (36 values).
        #[serde(default)]
        d: Vec<f64>,
        /// Stop travel per component (m, rad) of a progressive elastomer law (diagonal k, d only).
        #[serde(default)]
        travel: Option<[f64; 6]>,
    },
    /// Squeeze-film slide way (eq. 2.211): an oil film of gap h between a surface of body1
    /// (through `point1`, normal `normal`, body1 frame) and `point2` on body2, pushing back with
    /// `F = 12 η A l² / h³ · ḣ` against the change of the gap.
    SqueezeFilm {
        /// Element name.
        name: String,
        /// Body carrying the guide surface.
        body1: String,
        /// A point of the surface, body1 frame.
        #[serde(default)]
        point1: [f64; 3],
        /// Surface normal towards body2, body1 frame.
        normal: [f64; 3],
        /// Body carrying the slider.
        body2: String,
        /// The slider point, body2 frame.
        #[serde(default)]
        point2: [f64; 3],
        /// Dynamic viscosity η (Pa s).
        eta: f64,
        /// Half-length l of the slide way (m).
        length: f64,
        /// Cross-section area A of the gap flow (m²).
        area: f64,
        /// Gap h0 (m) when `point2` lies on the surface's offset by zero: h = h0 + n·(p2 − p1).
        gap: f64,
    },
    /// Journal-bearing friction torque by Reynolds–Sommerfeld (eq. 2.212) on a revolute joint:
    /// `M = 2(1 + 2ε²) / (√(1 − ε²)(1 + ε²/2)) · π r0² b η / a · r0 Ω`, opposing the joint speed Ω.
    JournalBearing {
        /// Element name.
        name: String,
        /// The revolute joint between shaft and bearing.
        joint: String,
        /// Shaft radius r0 (m).
        radius: f64,
        /// Bearing length b (m).
        length: f64,
        /// Radial clearance a (m), a ≪ r0.
        clearance: f64,
        /// Dynamic viscosity η (Pa s).
        eta: f64,
        /// Relative eccentricity ε = e/a, 0 ≤ ε ≤ 0.95.
        #[serde(default)]
        eccentricity: f64,
    },
    /// Hydrodynamic journal bearing (short- or long-bearing theory over a π-film, see
    /// `forces::bearing`): the oil film between a journal (the origin of `journal_frame` on its
    /// axis) and a shell (the origin of `shell_frame` at the bearing centre, its z along the
    /// bearing axis) pushes the journal with the film force of its offset, offset rate and relative
    /// spin, and brakes the spin with the friction torque of eq. 2.212; the shell gets the opposite.
    HydrodynamicBearing {
        /// Element name.
        name: String,
        /// Body carrying the journal.
        journal: String,
        /// Journal frame on that body (its origin on the journal axis, mid-length).
        #[serde(default)]
        journal_frame: FrameDescription,
        /// Body carrying the shell (`ground` allowed).
        shell: String,
        /// Shell frame on that body (origin at the bearing centre, z along the bearing axis).
        #[serde(default)]
        shell_frame: FrameDescription,
        /// Journal radius R (m).
        radius: f64,
        /// Bearing length L (m).
        length: f64,
        /// Radial clearance c (m), 0 < c < R.
        clearance: f64,
        /// Dynamic viscosity η (Pa s).
        viscosity: f64,
        /// "short" (Ocvirk) or "long" (Sommerfeld).
        #[serde(default = "default_bearing_theory")]
        theory: String,
    },
    /// Jenkins elements (a spring in series with a Coulomb slider, eq. 2.215) on one velocity of a
    /// joint: one element, several in parallel, or a press fit (Fig. 2.39): a chain of massless
    /// shaft segments of stiffness `shaft_stiffness`, each held to the hub by a Jenkins element.
    Jenkins {
        /// Element name.
        name: String,
        /// The joint whose coordinate is the relative displacement (shaft against hub).
        joint: String,
        /// Which velocity of the joint (0 for one-degree-of-freedom joints).
        #[serde(default)]
        index: usize,
        /// Stiffness of each Jenkins spring (N/m or N m/rad).
        k: f64,
        /// Slip force (or torque) of each slider, one per element (> 0).
        slip: Vec<f64>,
        /// Stiffness of each shaft segment between the elements; absent: a rigid shaft (elements in parallel).
        #[serde(default)]
        shaft_stiffness: Option<f64>,
        /// Joint coordinate at which the springs are relaxed with the sliders at rest.
        #[serde(default)]
        offset: f64,
    },
    /// A force and torque on a body, scaled by a time function.
    BodyForce {
        /// Element name.
        name: String,
        /// Body acted upon.
        body: String,
        /// Point of application, body frame.
        #[serde(default)]
        point: [f64; 3],
        /// Force vector (N).
        #[serde(default)]
        force: [f64; 3],
        /// Torque vector (N m).
        #[serde(default)]
        torque: [f64; 3],
        /// Frame of `force` and `torque`: "inertial" or "body".
        #[serde(default = "default_frame")]
        frame: String,
        /// Scalar time function multiplying force and torque (constant 1 if absent).
        #[serde(default)]
        function: Option<TimeFunctionDescription>,
    },
    /// Generalized forces on a joint's velocities, scaled by a time function.
    JointForce {
        /// Element name.
        name: String,
        /// Joint acted upon.
        joint: String,
        /// One value per joint velocity (N or N m; a plain number for a 1-DOF joint).
        #[serde(deserialize_with = "one_or_many_value")]
        value: Vec<f64>,
        /// Scalar time function multiplying `value` (constant 1 if absent).
        #[serde(default)]
        function: Option<TimeFunctionDescription>,
    },
    /// A servo actuator on one joint velocity: a position servo `τ_m = kp n (r − q) + kd n (ṙ − q̇)`
    /// or a velocity servo `τ_m = kd n (r − q̇)` on the motor side of a gear of ratio n (motor
    /// angle n q), the motor torque clamped to ±`max_torque`, `n τ_m` on the joint.
    Servo {
        /// Element name.
        name: String,
        /// Joint acted upon.
        joint: String,
        /// Which of the joint's velocities (0 for 1-DOF joints).
        #[serde(default)]
        index: usize,
        /// "position" or "velocity".
        #[serde(default = "default_servo_mode")]
        mode: String,
        /// Proportional gain (N m/rad or N/m, motor side).
        #[serde(default)]
        kp: f64,
        /// Derivative (position servo) or velocity (velocity servo) gain (N m s/rad or N s/m).
        #[serde(default)]
        kd: f64,
        /// The reference r(t): joint coordinate (position servo) or joint velocity (velocity servo).
        reference: TimeFunctionDescription,
        /// Motor torque limit (absent: none).
        #[serde(default)]
        max_torque: Option<f64>,
        /// Gear ratio n (motor turns per joint turn).
        #[serde(default = "default_gear")]
        gear: f64,
    },
    /// A user callback computing generalized forces from (t, q, u): slow, it calls back into Python.
    Callback {
        /// Element name.
        name: String,
        /// Index into the callback table given with the model.
        id: usize,
    },
}

fn default_frame() -> String {
    "inertial".to_string()
}

/// A list of numbers, or one number standing for a list of one (the 1-DOF case in model files).
#[derive(Deserialize)]
#[serde(untagged)]
enum OneOrMany {
    One(f64),
    Many(Vec<f64>),
}

fn one_or_many<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Vec<f64>, D::Error> {
    let v = OneOrMany::deserialize(d)
        .map_err(|_| serde::de::Error::custom("expected a finite number or a list of finite numbers"))?;
    Ok(match v {
        OneOrMany::One(x) => vec![x],
        OneOrMany::Many(v) => v,
    })
}

/// As [`one_or_many`] for a force's `value` (an internally tagged enum's errors carry no key path).
fn one_or_many_value<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Vec<f64>, D::Error> {
    one_or_many(d).map_err(|_| serde::de::Error::custom("value: expected a finite number or a list of finite numbers"))
}

fn one_or_many_opt<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Option<Vec<f64>>, D::Error> {
    // null (how an absent value is written back out) reads as absent, so a written
    // description reads back
    let v = Option::<OneOrMany>::deserialize(d)
        .map_err(|_| serde::de::Error::custom("expected a finite number or a list of finite numbers"))?;
    Ok(v.map(|v| match v {
        OneOrMany::One(x) => vec![x],
        OneOrMany::Many(v) => v,
    }))
}

fn default_bearing_theory() -> String {
    "short".to_string()
}

fn default_servo_mode() -> String {
    "position".to_string()
}

fn default_gear() -> f64 {
    1.0
}

impl ModelDescription {
    /// Parses a JSON description, reporting the key path of the first error.
    pub fn from_json(text: &str) -> Result<Self> {
        let de = &mut serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize(de).map_err(|e| Error::Description {
            path: display_path(&e.path().to_string()),
            message: clean_message(&e.inner().to_string()),
        })
    }

    /// Serializes to JSON (the form stored as an HDF5 attribute).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }
}

/// serde_path_to_error prints the root as "."; make it read as a key path.
fn display_path(p: &str) -> String {
    if p == "." || p.is_empty() {
        "model".to_string()
    } else {
        p.to_string()
    }
}

/// Drop serde_json's " at line X column Y" (meaningless for a TOML file or a Python dict) and
/// say in plain words what the few opaque serde messages mean.
fn clean_message(m: &str) -> String {
    let m = match m.find(" at line ") {
        Some(i) => &m[..i],
        None => m,
    };
    if m.contains("invalid number") || m == "expected value" {
        // NaN and infinities reach the parser as non-JSON tokens
        "must be a finite number (NaN and infinity are not allowed)".to_string()
    } else if m.contains("untagged enum InertiaDescription") {
        "expected a 3x3 matrix, 3 diagonal values or 6 values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]".to_string()
    } else if m.contains("untagged enum RotationDescription") {
        "expected a 3x3 rotation matrix, a quaternion [w, x, y, z] or a table with one of cardan, euler, rotvec"
            .to_string()
    } else {
        m.to_string()
    }
}
