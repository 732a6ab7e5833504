//! The experiment harness: named experiments pitting estimators against a reference.

pub mod plot;
