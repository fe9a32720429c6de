//! Contact geometry and relative contact kinematics (section 2.2.7, notation of section 2.5).
//!
//! - [`contour`]: the contours a body carries ([`Contour`]), in the body frame, with validation
//!   and world bounding boxes (a triangle mesh, [`Contour::Mesh`], has its own hierarchy of boxes
//!   over its triangles, [`crate::geometry::mesh`]).
//! - [`broad`]: sweep and prune over bounding boxes ([`SweepAndPrune`]).
//! - [`narrow`]: a [`ContactPair`] of two contours, prepared once, and [`evaluate`], which gives
//!   a fixed number of candidate [`ContactPoint`]s per pair (gap, normal, points, tangents).
//! - [`group`]: contact groups at run time: broad phase, a cache of prepared pairs, narrow phase
//!   on the pairs that may touch ([`GroupPhase`]).
//! - [`kinematics`]: [`contact_kinematics`], the relative velocities `ġ_N`, `ġ_T` and the
//!   velocity-product terms `w̄_N`, `w̄_T` of the relative accelerations; its velocity level
//!   [`contact_velocities_warm`] without them, for time stepping.
//!
//! # Conventions
//!
//! Body 1 carries contour 1, body 2 contour 2; placements, twists and accelerations are world
//! quantities about the world origin (body 0, the ground, is the identity at rest).
//!
//! - `g_N > 0` open, `< 0` penetrating.
//! - `n` is the unit normal pointing from contour 2 towards contour 1: `g_N` grows when body 1
//!   moves along `n` relative to body 2, `ġ_N = n·(v_1(P1) - v_2(P2))`, and a force `λ_N n`
//!   (`λ_N ≥ 0`) acts on body 1 at `P1`, `-λ_N n` on body 2 at `P2`.
//! - `P1` lies on contour 1's surface, `P2` on contour 2's, and `P1 - P2 = g_N n`.
//! - `(t1, t2, n)` is right-handed orthonormal; `ġ_T = (t1, t2)·(v_1(P1) - v_2(P2))`. Planar
//!   pairs have one tangent `t1 = e_z × n` (body 2's z axis).
//! - W-part: `g̈_N = w_Nᵀ u̇ + w̄_N` with `w_N = J_P1ᵀ n - J_P2ᵀ n` from the translational point
//!   Jacobians at `P1`, `P2`; see [`kinematics`] for the exact definition of `w̄`.
//!
//! Per-step functions ([`evaluate`], [`contact_kinematics`], [`SweepAndPrune::update`] once
//! sized) do not allocate.

pub mod broad;
pub mod contour;
pub mod gap;
pub mod group;
pub mod kinematics;
pub mod narrow;

#[cfg(test)]
pub(crate) mod test_util;

#[cfg(test)]
mod bench;

pub use broad::{Aabb, SweepAndPrune};
pub use contour::{Contour, ContourKind, Vec2};
pub use group::GroupPhase;
pub use kinematics::{
    at_contact, contact_kinematics, contact_kinematics_warm, contact_point_kinematics, contact_point_velocities,
    contact_velocities_warm, gap_with_accelerations, BodyMotion, ContactKinematics,
};
pub use narrow::warm::SearchHint;
pub use narrow::{candidates, evaluate, ContactPair, ContactPoint};
