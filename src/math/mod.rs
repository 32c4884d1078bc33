//! Math shared by every layer: scalar shims, boxes, cones, the equal-area
//! sphere map, the exact one-number descent and sums that many threads can
//! add to.

mod aabb;
mod cone;
mod counter;
mod descent;
mod luminance;
mod random;
pub(crate) mod scalar;
mod sphere_map;
mod sum;

pub use aabb::Aabb;
pub use cone::LightCone;
pub(crate) use cone::angle_between as cone_angle_between;
pub(crate) use counter::Counter;
pub(crate) use descent::Descent;
pub use descent::Side;
pub(crate) use descent::pmf_to_f32;
pub use luminance::luminance;
pub use random::{unit_f32, unit_f64};
pub(crate) use sphere_map::SPHERE_MAP_JACOBIAN;
pub(crate) use sphere_map::unit_direction;
pub use sphere_map::{canonical_to_dir, dir_to_canonical};
pub(crate) use sum::ACCUMULATION;
pub use sum::Accumulation;
pub(crate) use sum::SumBuffer;
