//! Hydrodynamic journal bearings as model elements: the validated geometry, oil and theory of the
//! film, and where the journal and the shell sit on their bodies. The force stage
//! ([`crate::forces::bearing`], whose documentation has the derivation) evaluates them.

use crate::spatial::Pose;

/// Which closed-form solution of the Reynolds equation gives the film forces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BearingTheory {
    /// Short bearing (Ocvirk, L/D ≲ 1/2): the circumferential pressure flow is neglected.
    Short,
    /// Long bearing (Sommerfeld, L/D ≳ 2): the axial pressure flow is neglected.
    Long,
}

impl BearingTheory {
    /// The names [`BearingTheory::from_name`] accepts.
    pub const NAMES: [&'static str; 2] = ["short", "long"];

    /// From `"short"` or `"long"`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "short" => Some(BearingTheory::Short),
            "long" => Some(BearingTheory::Long),
            _ => None,
        }
    }

    /// `"short"` or `"long"`.
    pub fn as_str(self) -> &'static str {
        match self {
            BearingTheory::Short => "short",
            BearingTheory::Long => "long",
        }
    }
}

/// The film law of a plain journal bearing: geometry, oil and theory (all checked > 0 and finite,
/// clearance < radius, by whoever builds it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingLaw {
    /// Short or long bearing theory.
    pub theory: BearingTheory,
    /// Journal radius R (m).
    pub radius: f64,
    /// Bearing length L (m).
    pub length: f64,
    /// Radial clearance c (m).
    pub clearance: f64,
    /// Dynamic viscosity η (Pa s).
    pub viscosity: f64,
}

/// A hydrodynamic journal bearing between a journal (frame origin on its axis) and a shell (frame
/// origin at the bearing centre, z along the bearing axis).
#[derive(Debug, Clone, PartialEq)]
pub struct HydrodynamicBearing {
    /// Name.
    pub name: String,
    /// Body carrying the journal.
    pub journal: usize,
    /// Journal frame on that body: origin on the journal axis in the bearing's mid-plane.
    pub journal_frame: Pose,
    /// Body carrying the shell (0: the ground).
    pub shell: usize,
    /// Shell frame on that body: origin at the bearing centre, z along its axis.
    pub shell_frame: Pose,
    /// The film law.
    pub law: BearingLaw,
}
