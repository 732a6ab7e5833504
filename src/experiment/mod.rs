//! The pure computation behind experiments: error metrics (DESIGN.md §5) and the statistics
//! reported over runs and checkpoints (confidence intervals, convergence slopes, bias/variance).

pub mod metrics;
pub mod statistics;
