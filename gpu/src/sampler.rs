//! [`GpuSampler`]: a snapshot uploaded once, its kernels run over batches
//! of queries.

use crate::device::Gpu;
use crate::pack::pack;
use crate::query::{Answer, Query};
use guiding::snapshot::Snapshot;
use std::time::{Duration, Instant};
use wgpu::util::DeviceExt;

/// Invocations per workgroup (the kernel's `@workgroup_size`).
const GROUP: u32 = 64;
/// The most workgroups along one dispatch dimension.
const MAX_GROUPS: u32 = 65_535;

/// A snapshot on the GPU with the sampling and pmf kernels ready.
#[derive(Debug)]
pub struct GpuSampler<'g> {
    gpu: &'g Gpu,
    snapshot: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    sample: wgpu::ComputePipeline,
    pmf: wgpu::ComputePipeline,
    /// Bytes of the snapshot buffer.
    bytes: usize,
}

/// Which kernel a batch runs.
#[derive(Clone, Copy, Debug)]
enum Kernel {
    Sample,
    Pmf,
}

/// A batch's buffers, uploaded and bound.
struct Batch {
    bind: wgpu::BindGroup,
    answers: wgpu::Buffer,
    count: u32,
}

impl<'g> GpuSampler<'g> {
    /// Uploads `snapshot` (packed into one word buffer, see
    /// [`crate::Packed`]) and compiles the kernels.
    pub fn new(gpu: &'g Gpu, snapshot: &Snapshot) -> Self {
        let device = &gpu.device;
        let words = pack(snapshot).words;
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("snapshot"),
            contents: bytemuck::cast_slice(&words),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sample.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("sample.wgsl").into()),
        });
        let entry = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("snapshot, queries, answers"),
            entries: &[entry(0, true), entry(1, true), entry(2, false)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry_point| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Self {
            gpu,
            snapshot: buffer,
            sample: pipeline("sample_main"),
            pmf: pipeline("pmf_main"),
            layout,
            bytes: words.len() * 4,
        }
    }

    /// Bytes of the snapshot on the GPU.
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// Samples a light for each query (its point, normal and number).
    pub fn sample(&self, queries: &[Query]) -> Vec<Answer> {
        self.run(Kernel::Sample, queries, 1).0
    }

    /// The pmf of each query's light at its point.
    pub fn pmf(&self, queries: &[Query]) -> Vec<Answer> {
        self.run(Kernel::Pmf, queries, 1).0
    }

    /// Samples as [`GpuSampler::sample`], running the kernel `repeats`
    /// times over the uploaded queries; also the median time of one run
    /// (submission to completion, uploads and read-back excluded).
    pub fn sample_timed(&self, queries: &[Query], repeats: usize) -> (Vec<Answer>, Duration) {
        self.run(Kernel::Sample, queries, repeats.max(1))
    }

    fn run(&self, kernel: Kernel, queries: &[Query], repeats: usize) -> (Vec<Answer>, Duration) {
        if queries.is_empty() {
            return (Vec::new(), Duration::ZERO);
        }
        let batch = self.upload(queries);
        self.wait();
        let mut times: Vec<Duration> = (0..repeats)
            .map(|_| {
                let t = Instant::now();
                self.dispatch(kernel, &batch);
                self.wait();
                t.elapsed()
            })
            .collect();
        times.sort();
        (self.read(&batch), times[times.len() / 2])
    }

    fn upload(&self, queries: &[Query]) -> Batch {
        let device = &self.gpu.device;
        let queries_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("queries"),
            contents: bytemuck::cast_slice(queries),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let answers = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("answers"),
            size: std::mem::size_of_val(queries) as u64 / 2,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.snapshot.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: queries_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: answers.as_entire_binding(),
                },
            ],
        });
        Batch {
            bind,
            answers,
            count: queries.len() as u32,
        }
    }

    fn dispatch(&self, kernel: Kernel, batch: &Batch) {
        let groups = batch.count.div_ceil(GROUP);
        let (x, y) = if groups <= MAX_GROUPS {
            (groups, 1)
        } else {
            (MAX_GROUPS, groups.div_ceil(MAX_GROUPS))
        };
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(match kernel {
                Kernel::Sample => &self.sample,
                Kernel::Pmf => &self.pmf,
            });
            pass.set_bind_group(0, &batch.bind, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
        self.gpu.queue.submit([encoder.finish()]);
    }

    fn read(&self, batch: &Batch) -> Vec<Answer> {
        let device = &self.gpu.device;
        let size = batch.answers.size();
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&batch.answers, 0, &staging, 0, size);
        self.gpu.queue.submit([encoder.finish()]);
        staging
            .slice(..)
            .map_async(wgpu::MapMode::Read, |r| r.expect("map"));
        self.wait();
        let answers = {
            let view = staging.slice(..).get_mapped_range().expect("mapped");
            bytemuck::cast_slice(&view).to_vec()
        };
        staging.unmap();
        answers
    }

    fn wait(&self) {
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the device answers");
    }
}
