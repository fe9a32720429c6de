//! The description of a rotation, shared by the model description ([`super::description`]) and
//! the contact description ([`super::contact_description`]).

use serde::{Deserialize, Serialize};

/// A rotation: a unit quaternion `[w, x, y, z]`, a 3×3 matrix (rows of A_PB), or named angles.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RotationDescription {
    /// Rotation matrix rows.
    Matrix([[f64; 3]; 3]),
    /// Quaternion `[w, x, y, z]` (normalised when read).
    Quaternion([f64; 4]),
    /// Angles by name.
    Angles(AnglesDescription),
}

/// Named rotation angles.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnglesDescription {
    /// Cardan angles x-y-z (α, β, γ), eq. 2.19.
    #[serde(default)]
    pub cardan: Option<[f64; 3]>,
    /// Euler angles z-x-z (ψ, ϑ, φ), eq. 2.15.
    #[serde(default)]
    pub euler: Option<[f64; 3]>,
    /// Rotation vector (axis × angle).
    #[serde(default)]
    pub rotvec: Option<[f64; 3]>,
}
