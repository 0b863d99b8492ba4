//! Ray/primitive intersection.

pub mod triangle;
