//! The path space module: what every estimator shares about building and weighting paths
//! (DESIGN.md §2). So far: multiple-importance-sampling weights, and the joining of a light
//! subpath's vertex to the camera (light tracing's strategies).

pub mod camera_connection;
pub mod mis;
