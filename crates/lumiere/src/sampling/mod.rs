//! Sampling building blocks: pure warps from uniform numbers, discrete distributions, and the
//! chi-square harness that tests them.

pub mod chi2;
pub mod distrib;
pub mod mis;
pub mod warp;
