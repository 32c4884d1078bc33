//! The Guiding Light Tree: learned adaptive cuts through the light tree, per spatial cell.
