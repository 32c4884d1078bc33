//! The adapter and device the kernels run on.

/// A `wgpu` device and its queue, with what the adapter says it is.
#[derive(Debug)]
pub struct Gpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter (name, backend, device type: `Cpu` for lavapipe).
    pub info: wgpu::AdapterInfo,
}

impl Gpu {
    /// The default adapter's device with the adapter's own limits (large
    /// storage buffers), `None` when there is no adapter at all (no GPU
    /// and no software Vulkan such as Mesa's lavapipe).
    pub fn new() -> Option<Self> {
        pollster::block_on(async {
            let instance = wgpu::Instance::default();
            let adapter = instance
                .request_adapter(&wgpu::RequestAdapterOptions::default())
                .await
                .ok()?;
            let (device, queue) = adapter
                .request_device(&wgpu::DeviceDescriptor {
                    label: Some("guiding-gpu"),
                    required_limits: adapter.limits(),
                    ..Default::default()
                })
                .await
                .ok()?;
            Some(Self {
                device,
                queue,
                info: adapter.get_info(),
            })
        })
    }
}
