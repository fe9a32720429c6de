//! Parametric contact geometry (section 2.2.7): planar contours `r(s)` with their moving
//! trihedral and curvature ([`curve`]), built on C² cubic splines ([`spline`]) or on involute gear
//! outlines ([`gear`]); spatial surfaces of revolution ([`revolution`]) and bicubic spline
//! patches ([`surface`]); triangle meshes with a bounding-volume hierarchy for closest points
//! ([`mesh`]).

pub mod curve;
pub mod gear;
pub mod mesh;
pub mod revolution;
pub mod spline;
pub mod surface;
