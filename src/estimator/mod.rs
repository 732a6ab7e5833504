//! Estimators: interchangeable ways of estimating the pixel integrals (DESIGN.md §3).
