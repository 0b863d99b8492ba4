//! Ray/primitive intersection and the surface points it yields.

pub mod surface;
pub mod surface_lanes;
pub mod triangle;
