//! The guiding field of the paper: one spatial tree whose cells hold a directional quadtree and a guiding cut.
