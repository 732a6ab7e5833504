//! The path space module: what every estimator shares about building and weighting paths
//! (DESIGN.md §2). So far: multiple-importance-sampling weights.

pub mod mis;
