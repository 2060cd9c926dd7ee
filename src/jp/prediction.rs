//! Prediction of the boundary conditions (method.md §7): placeholder until the AFT lands.
