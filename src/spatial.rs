//! Spatial subdivision: the trait and Practical Path Guiding's binary tree, generic over what a cell holds.
