//! The Monte Carlo lecture's quantitative claims as code that measures them (the
//! `mc-basics`, `sampling-rates` and `sampling-spectra` experiments).

pub mod mc_basics;
