//! The Guiding Light Tree's light choice on a GPU: a WGSL compute kernel
//! (`sample.wgsl`) over the plain-data arrays of a
//! [`guiding::snapshot::Snapshot`], run through `wgpu`.
//!
//! The kernel is `guiding`'s `src/snapshot/sampling.rs` and
//! `importance.rs` line for line, so its answers can be checked against
//! the CPU's: `tests/city.rs` samples a million queries on a trained city
//! on whatever adapter `wgpu` finds (Mesa's lavapipe where there is no
//! GPU) and compares choices and pmfs; `examples/throughput.rs` measures
//! samples per second on both.
//!
//! ```no_run
//! # fn demo(snapshot: &guiding::snapshot::Snapshot) {
//! use guiding_gpu::{GpuSampler, Query};
//! let Some(gpu) = guiding_gpu::Gpu::new() else { return };
//! let sampler = GpuSampler::new(&gpu, snapshot);
//! let q = Query::new([0.0, 1.0, 0.0], Some([0.0, 1.0, 0.0]), 0.5);
//! let answers = sampler.sample(&[q]);
//! println!("{:?}", answers[0].light());
//! # }
//! ```

mod device;
mod pack;
mod query;
mod sampler;

pub use device::Gpu;
pub use pack::{Packed, pack};
pub use query::{Answer, Query};
pub use sampler::GpuSampler;
