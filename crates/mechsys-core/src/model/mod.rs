//! The validated, immutable model: bodies, joints forming a kinematic tree, force elements.
//!
//! A [`Model`] is built once from a [`ModelDescription`] by [`Model::from_description`], which checks
//! everything a user can get wrong and names the offending item. Bodies are stored in topological
//! order (index 0 is the ground, each body's parent has a smaller index) and body `i > 0` is moved
//! by joint `i - 1`, so the recursive algorithms are plain loops.
//!
//! Every model element is defined here (joints, bilateral constraints in [`constraint`], Jenkins
//! elements in [`jenkins`], hydrodynamic bearings in [`bearing`], contacts in [`contact`]); the
//! stages that evaluate them import the model, never the other way round.

pub mod bearing;
pub mod compliant;
pub mod constraint;
pub mod contact;
pub mod contact_description;
pub mod description;
pub mod jenkins;
pub mod joint;
mod planar;
pub mod rotation_description;
pub mod validate;

use std::collections::HashMap;

pub use bearing::{BearingLaw, BearingTheory, HydrodynamicBearing};
pub use constraint::{Constraint, ConstraintKind, LoopJoint, Reach};
pub use description::ModelDescription;
pub use jenkins::Jenkins;
pub use joint::JointKind;

use crate::math::{Mat3, Vec3};
use crate::spatial::Pose;

/// A named body-fixed frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Name, unique on its body.
    pub name: String,
    /// Placement in the body frame.
    pub pose: Pose,
}

/// A rigid body; for variable mass (section 2.1.1) the inertia scales with m(t)/m(0).
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Unique name (`ground` for index 0).
    pub name: String,
    /// Mass at t = 0 (kg).
    pub mass: f64,
    /// Centre of mass, body frame (m).
    pub com: Vec3,
    /// Inertia tensor about the centre of mass, body frame (kg m²).
    pub inertia: Mat3,
    /// Named frames.
    pub markers: Vec<Marker>,
    /// Mass rate ṁ (kg/s), 0 for constant mass.
    pub mass_rate: f64,
    /// Relative velocity of the ejected mass, body frame (m/s).
    pub ejection_velocity: Vec3,
    /// Point where the thrust acts, body frame.
    pub ejection_point: Vec3,
    /// Mass at which the flow stops.
    pub mass_final: f64,
    /// Whether the inertia tensor is diagonal in the body frame (fast path in the kinematics).
    pub principal_axes: bool,
    /// Index into [`Model::elastic`] for an elastic body.
    pub elastic: Option<usize>,
}

impl Body {
    /// Mass at time t: m(0) + ṁ t until `mass_final` is reached (eq. of section 2.1.1, m > 0 always).
    #[inline]
    pub fn mass_at(&self, t: f64) -> f64 {
        if self.mass_rate == 0.0 {
            return self.mass;
        }
        let m = self.mass + self.mass_rate * t;
        if self.mass_rate < 0.0 {
            m.max(self.mass_final)
        } else {
            m.min(self.mass_final)
        }
    }
    /// The mass rate at time t (zero once the flow has stopped).
    #[inline]
    pub fn mass_rate_at(&self, t: f64) -> f64 {
        if self.mass_rate == 0.0 {
            return 0.0;
        }
        let m = self.mass + self.mass_rate * t;
        let flowing = if self.mass_rate < 0.0 { m > self.mass_final } else { m < self.mass_final };
        if flowing {
            self.mass_rate
        } else {
            0.0
        }
    }
}

/// A joint linear spring: τ = -k (q - q_free) per coordinate (1-DOF-per-coordinate joints only).
#[derive(Debug, Clone, PartialEq)]
pub struct JointSpring {
    /// Stiffness per velocity index.
    pub k: Vec<f64>,
    /// Unloaded coordinates.
    pub q_free: Vec<f64>,
}

/// A joint, moving its child body relative to its parent.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Unique name.
    pub name: String,
    /// Type and its constants.
    pub kind: JointKind,
    /// Parent body index.
    pub parent: usize,
    /// Child body index (= joint index + 1).
    pub child: usize,
    /// Joint frame on the parent body.
    pub parent_frame: Pose,
    /// Joint frame on the child body.
    pub child_frame: Pose,
    /// `child_frame.inverse()`, kept because every evaluation needs it.
    pub child_frame_inv: Pose,
    /// Offset of this joint's coordinates in q.
    pub iq: usize,
    /// Offset of this joint's velocities in u.
    pub iu: usize,
    /// Whether the parent and child joint frames have identity rotations (pure offsets).
    pub frames_plain: (bool, bool),
    /// For a revolute joint about a coordinate axis of its joint frame: that axis (0, 1, 2).
    pub coordinate_axis: Option<usize>,
    /// Initial coordinates.
    pub q0: Vec<f64>,
    /// Initial velocities.
    pub u0: Vec<f64>,
    /// Optional spring.
    pub spring: Option<JointSpring>,
    /// Damping coefficients per velocity (empty if none).
    pub damper: Vec<f64>,
}

impl Joint {
    /// Number of coordinates.
    pub fn nq(&self) -> usize {
        self.kind.nq()
    }
    /// Number of velocities.
    pub fn nu(&self) -> usize {
        self.kind.nu()
    }
}

/// A scalar function of time.
#[derive(Debug, Clone, PartialEq)]
pub enum TimeFunction {
    /// Constant.
    Constant(f64),
    /// Ramp from t0 with a slope, optionally saturating.
    Ramp {
        /// Slope.
        slope: f64,
        /// Start time.
        t0: f64,
        /// Saturation value.
        final_value: Option<f64>,
    },
    /// offset + amplitude sin(ω t + phase).
    Harmonic {
        /// Amplitude.
        amplitude: f64,
        /// Circular frequency.
        omega: f64,
        /// Phase.
        phase: f64,
        /// Offset.
        offset: f64,
    },
    /// Piecewise-linear table.
    Table {
        /// Times, increasing.
        t: Vec<f64>,
        /// Values.
        values: Vec<f64>,
    },
    /// User callback by index.
    Callback(usize),
}

/// The frame in which a body force is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ForceFrame {
    /// Inertial components.
    Inertial,
    /// Body components.
    Body,
}

/// A force element.
#[derive(Debug, Clone, PartialEq)]
pub enum ForceElement {
    /// Point-to-point spring–damper.
    SpringDamper {
        /// Name.
        name: String,
        /// First body index.
        body1: usize,
        /// Point on body1, body frame.
        point1: Vec3,
        /// Second body index.
        body2: usize,
        /// Point on body2, body frame.
        point2: Vec3,
        /// Linear stiffness.
        k: f64,
        /// Cubic stiffness.
        k3: f64,
        /// Damping.
        d: f64,
        /// Unstretched length.
        l0: f64,
        /// Tabulated force–deflection curve (deflections, forces), possibly empty.
        table: (Vec<f64>, Vec<f64>),
        /// Stop travel of the progressive law (0: linear).
        travel: f64,
    },
    /// Six-component bushing (see [`description::ForceDescription::Bushing`]).
    Bushing {
        /// Name.
        name: String,
        /// First body index.
        body1: usize,
        /// Frame on body1.
        frame1: Pose,
        /// Second body index.
        body2: usize,
        /// Frame on body2.
        frame2: Pose,
        /// Stiffness (6 × 6, symmetric), on `[Δr; θ]` in frame-1 components.
        k: nalgebra::Matrix6<f64>,
        /// Damping (6 × 6, symmetric), on the relative velocity `[Δṙ; ω_rel]` in frame-1 components.
        d: nalgebra::Matrix6<f64>,
        /// Stop travel per component of the progressive law (diagonal k, d), or none.
        travel: Option<[f64; 6]>,
    },
    /// Squeeze-film slide way (eq. 2.211).
    SqueezeFilm {
        /// Name.
        name: String,
        /// Body of the guide surface.
        body1: usize,
        /// Point of the surface, body1 frame.
        point1: Vec3,
        /// Unit normal towards body2, body1 frame.
        normal: Vec3,
        /// Body of the slider.
        body2: usize,
        /// Slider point, body2 frame.
        point2: Vec3,
        /// `12 η A l²` (N s m²): the force is this over h³ times ḣ.
        coeff: f64,
        /// Gap h0 at zero offset (m).
        gap: f64,
        /// Largest gap of the thin-film law, l/10 (m).
        gap_max: f64,
    },
    /// Journal-bearing friction torque (eq. 2.212) on a revolute joint.
    JournalBearing {
        /// Name.
        name: String,
        /// Joint index.
        joint: usize,
        /// Torque per shaft speed (N m s/rad).
        c: f64,
    },
    /// Jenkins elements on one joint velocity (evaluated by [`crate::forces::jenkins`]).
    Jenkins(Jenkins),
    /// Hydrodynamic journal bearing between a journal and a shell (evaluated by
    /// [`crate::forces::bearing`]).
    HydrodynamicBearing(HydrodynamicBearing),
    /// Force and torque on a body.
    BodyForce {
        /// Name.
        name: String,
        /// Body index.
        body: usize,
        /// Point of application, body frame.
        point: Vec3,
        /// Force.
        force: Vec3,
        /// Torque.
        torque: Vec3,
        /// Frame of force and torque.
        frame: ForceFrame,
        /// Time scaling.
        function: TimeFunction,
    },
    /// A position or velocity servo on one joint velocity (see `ForceDescription::Servo`).
    Servo {
        /// Name.
        name: String,
        /// Joint index.
        joint: usize,
        /// Velocity index within the joint.
        index: usize,
        /// Position (true) or velocity servo.
        position: bool,
        /// Gains (motor side).
        kp: f64,
        /// Derivative or velocity gain (motor side).
        kd: f64,
        /// Reference of time.
        reference: TimeFunction,
        /// Motor torque limit (infinite: none).
        max_torque: f64,
        /// Gear ratio.
        gear: f64,
    },
    /// Generalized force on a joint.
    JointForce {
        /// Name.
        name: String,
        /// Joint index.
        joint: usize,
        /// Values per joint velocity.
        value: Vec<f64>,
        /// Time scaling.
        function: TimeFunction,
    },
    /// Generalized forces from a user callback.
    Callback {
        /// Name.
        name: String,
        /// Callback index.
        id: usize,
    },
    /// A compliant contact (evaluated by [`crate::forces::compliant`]).
    Contact(Box<compliant::CompliantContact>),
    /// A compliant contact group (evaluated by [`crate::forces::compliant_group`]).
    ContactGroup(Box<compliant::CompliantGroup>),
}

impl ForceElement {
    /// The element's name.
    pub fn name(&self) -> &str {
        match self {
            ForceElement::SpringDamper { name, .. }
            | ForceElement::BodyForce { name, .. }
            | ForceElement::JointForce { name, .. }
            | ForceElement::Servo { name, .. }
            | ForceElement::Bushing { name, .. }
            | ForceElement::SqueezeFilm { name, .. }
            | ForceElement::JournalBearing { name, .. }
            | ForceElement::Callback { name, .. } => name,
            ForceElement::Jenkins(j) => &j.name,
            ForceElement::HydrodynamicBearing(b) => &b.name,
            ForceElement::Contact(c) => &c.name,
            ForceElement::ContactGroup(g) => &g.geometry.name,
        }
    }

    /// How many values the element records as its force (and as its deflection): 6 for a
    /// bushing, 1 for the elements acting along one coordinate; the loads record what they apply
    /// (a body force its force and torque, 6; a joint force one value per joint velocity; a Python
    /// force its generalized forces, `nu` of a model of `nu` velocities) and no deflection. A
    /// hydrodynamic bearing records 3: as force its film force (shell x, y) and friction torque,
    /// as deflection its eccentricity ε, the position angle φ and the attitude angle ψ.
    pub fn outputs(&self, nu: usize) -> usize {
        match self {
            ForceElement::HydrodynamicBearing(_) => 3,
            ForceElement::Bushing { .. } | ForceElement::BodyForce { .. } => 6,
            ForceElement::SpringDamper { .. }
            | ForceElement::SqueezeFilm { .. }
            | ForceElement::JournalBearing { .. }
            | ForceElement::Servo { .. }
            | ForceElement::Jenkins(_) => 1,
            ForceElement::JointForce { value, .. } => value.len(),
            ForceElement::Callback { .. } => nu,
            ForceElement::Contact(c) => compliant::OUTPUTS_PER_POINT * c.points(),
            ForceElement::ContactGroup(g) => g.outputs(),
        }
    }
}

/// The validated model.
#[derive(Debug, Clone)]
pub struct Model {
    /// Model name.
    pub name: String,
    /// Gravity, inertial frame.
    pub gravity: Vec3,
    /// Bodies; index 0 is the ground.
    pub bodies: Vec<Body>,
    /// Joints; joint `i` moves body `i + 1`.
    pub joints: Vec<Joint>,
    /// Force elements.
    pub forces: Vec<ForceElement>,
    /// Bilateral constraints beyond the tree.
    pub constraints: Vec<Constraint>,
    /// Unilateral contacts.
    pub contacts: Vec<contact::Contact>,
    /// Contact groups (pairs found by a broad phase at every step).
    pub contact_groups: Vec<contact::ContactGroup>,
    /// Elastic bodies (floating frame of reference); their coordinates follow every joint's.
    pub elastic: Vec<crate::elastic::ElasticBody>,
    /// Number of candidate contact points over all contacts.
    pub n_contact_points: usize,
    /// Total number of constraint equations.
    pub nc: usize,
    /// A planar model (see [`planar`]): constraints keep their in-plane rows.
    pub planar: bool,
    /// Total number of coordinates.
    pub nq: usize,
    /// Total number of velocities (degrees of freedom).
    pub nu: usize,
    /// Whether any body has variable mass.
    pub variable_mass: bool,
    /// Whether q̇ = u holds for every coordinate (no quaternion joints), decided once here.
    pub qdot_is_u: bool,
    /// Number of user callbacks the model refers to.
    pub n_callbacks: usize,
    /// Number of Coulomb sliders over all Jenkins elements (history variables of the forces).
    pub n_sliders: usize,
    /// Number of recorded force and deflection values over all force elements.
    pub n_force_outputs: usize,
    /// Number of candidate points over all compliant contacts (their history and extra states),
    /// plus one per compliant group (its dissipated energy state).
    pub n_compliant_points: usize,
    /// The description it was built from (stored with results).
    pub description: ModelDescription,
    body_index: HashMap<String, usize>,
    joint_index: HashMap<String, usize>,
}

impl Model {
    /// Number of bodies including the ground.
    pub fn nbodies(&self) -> usize {
        self.bodies.len()
    }
    /// Index of a body by name.
    pub fn body_id(&self, name: &str) -> Option<usize> {
        self.body_index.get(name).copied()
    }
    /// Index of a joint by name.
    pub fn joint_id(&self, name: &str) -> Option<usize> {
        self.joint_index.get(name).copied()
    }
    /// The contact that owns candidate point `pt` (points are numbered contact after contact).
    pub fn contact_of_point(&self, pt: usize) -> &contact::Contact {
        let k = self.contacts.partition_point(|c| c.first <= pt);
        &self.contacts[k.saturating_sub(1)]
    }

    /// The initial coordinates given in the model (neutral where none were given).
    pub fn q0(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.nq];
        for j in &self.joints {
            q[j.iq..j.iq + j.nq()].copy_from_slice(&j.q0);
        }
        for e in &self.elastic {
            q[e.iq..e.iq + e.ne].copy_from_slice(&e.q0);
        }
        q
    }
    /// The initial velocities given in the model (zero where none were given).
    pub fn u0(&self) -> Vec<f64> {
        let mut u = vec![0.0; self.nu];
        for j in &self.joints {
            u[j.iu..j.iu + j.nu()].copy_from_slice(&j.u0);
        }
        for e in &self.elastic {
            u[e.iu..e.iu + e.ne].copy_from_slice(&e.u0);
        }
        u
    }
    /// The neutral configuration.
    pub fn neutral(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.nq];
        for j in &self.joints {
            j.kind.neutral(&mut q[j.iq..j.iq + j.nq()]);
        }
        q
    }
    /// Checks that q has the model's length, is finite, and that no quaternion is zero (a zero
    /// quaternion is no rotation at all; any other norm is normalized where it is used).
    pub fn check_q(&self, q: &[f64], what: &str) -> crate::error::Result<()> {
        crate::ensure!(q.len() == self.nq, Settings, "{what}: the model has {} coordinates, got {}", self.nq, q.len());
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(crate::error::Error::Settings(format!("{what}[{i}]: must be finite, got {}", q[i])));
        }
        for j in &self.joints {
            let r = match j.kind {
                JointKind::Spherical => j.iq..j.iq + 4,
                JointKind::Free => j.iq + 3..j.iq + 7,
                _ => continue,
            };
            let n: f64 = q[r].iter().map(|x| x * x).sum();
            crate::ensure!(n > 1e-24, Settings, "{what}: the quaternion of joint '{}' must not be zero", j.name);
        }
        Ok(())
    }
    /// Normalizes all quaternions in q.
    pub fn normalize(&self, q: &mut [f64]) {
        for j in &self.joints {
            j.kind.normalize(&mut q[j.iq..j.iq + j.nq()]);
        }
    }
    /// q̇ = H*(q) u for the whole model (eq. 2.34).
    pub fn qdot(&self, q: &[f64], u: &[f64], qd: &mut [f64]) {
        if self.qdot_is_u {
            // no quaternions: every coordinate rate is its velocity
            qd.copy_from_slice(u);
            return;
        }
        for j in &self.joints {
            j.kind.qdot(&q[j.iq..j.iq + j.nq()], &u[j.iu..j.iu + j.nu()], &mut qd[j.iq..j.iq + j.nq()]);
        }
        for e in &self.elastic {
            qd[e.iq..e.iq + e.ne].copy_from_slice(&u[e.iu..e.iu + e.ne]);
        }
    }
    /// The velocity tree: within a joint each velocity hangs on the previous one, a joint's first
    /// velocity on the last velocity of the nearest ancestor joint that has any. Returns the parent
    /// velocity of each velocity (nu), `usize::MAX` for a root.
    pub fn velocity_parents(&self) -> Vec<usize> {
        let mut parent = vec![usize::MAX; self.nu];
        let mut last = vec![usize::MAX; self.nbodies()];
        for (ji, j) in self.joints.iter().enumerate() {
            let mut p = last[j.parent];
            for k in 0..j.nu() {
                parent[j.iu + k] = p;
                p = j.iu + k;
            }
            last[ji + 1] = p;
        }
        // elastic coordinates hang on their body's last velocity, one after another (they couple
        // with the reference motion and each other)
        for e in &self.elastic {
            let mut p = last[e.body];
            for k in 0..e.ne {
                parent[e.iu + k] = p;
                p = e.iu + k;
            }
        }
        parent
    }
    /// q ⊕ u·dt on the configuration manifold.
    pub fn integrate(&self, q: &[f64], u: &[f64], dt: f64, out: &mut [f64]) {
        for j in &self.joints {
            let (rq, ru) = (j.iq..j.iq + j.nq(), j.iu..j.iu + j.nu());
            j.kind.integrate(&q[rq.clone()], &u[ru], dt, &mut out[rq]);
        }
        for e in &self.elastic {
            for k in 0..e.ne {
                out[e.iq + k] = q[e.iq + k] + u[e.iu + k] * dt;
            }
        }
    }
}
