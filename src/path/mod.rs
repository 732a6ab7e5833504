//! The path space module: what every estimator shares about building and weighting paths
//! (docs/DESIGN.md §2): path vertices with their densities, the random walk that makes
//! subpaths and the starts of camera and light subpaths, the joining of a light subpath's
//! vertex to the camera (light tracing's strategies), the bidirectional strategies, and
//! multiple-importance-sampling weights.

pub mod camera_connection;
pub mod connection;
pub mod mis;
pub mod mis_sums;
pub mod next_event;
pub mod random_walk;
pub mod settings;
pub mod subpath;
pub mod vertex;
