//! Iteration schedule of guided rendering and the inverse-variance combination of its last iterations.
