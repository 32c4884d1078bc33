//! The directional quadtree of Practical Path Guiding over the equal-area sphere map.
