//! The SD-tree of Practical Path Guiding: a spatial binary tree whose cells hold directional quadtrees.
