//! Running an estimator for a number of passes or a time budget.
