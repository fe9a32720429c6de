//! Parametric contact geometry (section 2.2.7): planar contours `r(s)` with their moving
//! trihedral and curvature ([`curve`]), built on C² cubic splines ([`spline`]).

pub mod curve;
pub mod spline;
