//! Running a batch: sequential below [`PARALLEL_FROM`] points, on rayon's
//! pool above it; either way the results come back in the points' order
//! and equal bit for bit (each point's query is independent of the others).

use guiding::ShadingContext;
use guiding::glam::Vec3;
use rayon::prelude::*;

/// The batch length from which a call runs in parallel: below it the
/// pool's start-up costs more than the work (a GLT sample is about a
/// microsecond).
pub const PARALLEL_FROM: usize = 4096;

/// Points per task on the pool.
const CHUNK: usize = 1024;

/// `f(i)` for every `i < n`, in order.
pub fn map<T: Send, F: Fn(usize) -> T + Sync + Send>(n: usize, f: F) -> Vec<T> {
    if n < PARALLEL_FROM {
        (0..n).map(f).collect()
    } else {
        (0..n).into_par_iter().with_min_len(CHUNK).map(f).collect()
    }
}

/// The shading points of a batch: positions, and normals where given.
pub struct Points {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
}

impl Points {
    /// How many points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Point `i`'s context: on a surface when a normal is given (a zero
    /// normal means none: a point in a medium, or a two-sided surface).
    pub fn context(&self, i: usize) -> ShadingContext {
        let p = Vec3::from(self.positions[i]);
        match &self.normals {
            Some(n) if Vec3::from(n[i]) != Vec3::ZERO => {
                ShadingContext::on_surface(p, Vec3::from(n[i]))
            }
            _ => ShadingContext::at(p),
        }
    }
}
