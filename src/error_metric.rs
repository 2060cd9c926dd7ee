//! Error predictor e* (method.md §10).
