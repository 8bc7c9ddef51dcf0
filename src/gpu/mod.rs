//! The GPU, through wgpu (Vulkan): one device per process, opened on first use, shared by the
//! raster backend ([`crate::gpu::raster`]) and the hardware measurements (vertex-shader invocations,
//! render time). On a software adapter the raster backend also draws on a [`pool`] of devices.
//!
//! Every failure a user can meet here becomes an [`Error::Gpu`] that says what to do: no Vulkan
//! adapter (install Mesa's lavapipe, or point `VK_DRIVER_FILES` at a driver), a lost device, a
//! validation or out-of-memory error, a submission that does not finish within [`WAIT`].
//! Nothing here panics on a driver's answer.

pub mod raster;
pub mod render_time;
pub mod vertex_reuse;

use std::sync::{Arc, Mutex, OnceLock};

use std::time::Duration;

use crate::error::{Error, Result};

/// How long one submission may take before we give up rather than hang.
pub const WAIT: Duration = Duration::from_secs(300);

/// An open device and what it is.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Why the device was lost, once it has been.
    lost: Arc<Mutex<Option<String>>>,
}

/// The optional features we use when the adapter has them: pipeline statistics for vertex-shader
/// invocations, timestamps for render time. Overdraw counting needs none.
const OPTIONAL: wgpu::Features = wgpu::Features::PIPELINE_STATISTICS_QUERY.union(wgpu::Features::TIMESTAMP_QUERY);

/// The process's GPU, opened once; the error, if opening failed, is returned on every call.
pub fn shared() -> Result<&'static Gpu> {
    static GPU: OnceLock<std::result::Result<Gpu, String>> = OnceLock::new();
    once(&GPU, Gpu::open)
}

/// The vertex layout of [`Gpu::mesh_buffers`] given bare positions: three floats at location 0.
pub const POSITIONS: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &wgpu::vertex_attr_array![0 => Float32x3],
};

/// At most this many devices in a software [`pool`]: each brings its own rasterizer threads.
const MAX_SOFTWARE_DEVICES: usize = 8;

/// The devices to split independent draws over: the shared one and, on a software adapter, one
/// more per core (at most [`MAX_SOFTWARE_DEVICES`] in all). Mesa's lavapipe fetches, shades, clips
/// and sets up every triangle of a device's queue on one thread, so one device keeps the other
/// cores waiting for vertex work (docs/performance.md has the timings). Each extra device comes
/// from its own instance, because lavapipe's devices on one instance share one set of rasterizer
/// threads and take turns on it.
/// A hardware GPU gets its one device: it parallelises itself.
pub fn pool() -> Result<Vec<&'static Gpu>> {
    static MORE: OnceLock<std::result::Result<Vec<Gpu>, String>> = OnceLock::new();
    let first = shared()?;
    let more = once(&MORE, || {
        let software = first.info.device_type == wgpu::DeviceType::Cpu;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let wanted = if software { cores.min(MAX_SOFTWARE_DEVICES) } else { 1 };
        (1..wanted).map(|_| Gpu::open()).collect()
    })?;
    Ok(std::iter::once(first).chain(more).collect())
}

/// The object in `cell`, built by `build` on first use. Pipelines are built once per process;
/// a failure is kept and returned, as the same error, on every later call.
pub fn once<T>(
    cell: &'static OnceLock<std::result::Result<T, String>>,
    build: impl FnOnce() -> Result<T>,
) -> Result<&'static T> {
    cell.get_or_init(|| {
        build().map_err(|e| match e {
            Error::Gpu(message) => message,
            other => other.to_string(),
        })
    })
    .as_ref()
    .map_err(|e| Error::Gpu(e.clone()))
}

impl Gpu {
    fn open() -> Result<Gpu> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        };
        let adapter = pollster::block_on(instance.request_adapter(&options)).map_err(|e| {
            Error::Gpu(format!(
                "no GPU adapter found through Vulkan ({e}). Install a Vulkan driver: on Debian or Ubuntu \
                 `apt-get install mesa-vulkan-drivers libvulkan1` gives Mesa's software rasterizer (lavapipe); \
                 for a hardware GPU, point VK_DRIVER_FILES at its ICD json"
            ))
        })?;
        let info = adapter.get_info();
        let descriptor = wgpu::DeviceDescriptor {
            label: Some("triorder"),
            required_features: adapter.features() & OPTIONAL,
            // The adapter's own limits: large meshes need more than WebGPU's defaults.
            required_limits: adapter.limits(),
            ..Default::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))
            .map_err(|e| Error::Gpu(format!("{}: cannot open the device: {e}", info.name)))?;
        let lost = Arc::new(Mutex::new(None));
        let record = Arc::clone(&lost);
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut slot) = record.lock() {
                *slot = Some(format!("{reason:?}: {message}"));
            }
        });
        Ok(Gpu { device, queue, info, lost })
    }

    /// "NAME (DRIVER DRIVER_INFO)", as written into every CSV row measured on this device.
    pub fn describe(&self) -> String {
        format!("{} ({} {})", self.info.name, self.info.driver, self.info.driver_info)
    }

    /// True for a software rasterizer (Mesa's lavapipe): exact counts, but CPU times.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// True when the adapter offers `features` (pipeline statistics, timestamps).
    pub fn has(&self, features: wgpu::Features) -> bool {
        self.device.features().contains(features)
    }

    /// Runs `f`, which records and submits GPU work, and turns any validation or out-of-memory
    /// error it raised, or a lost device, into an error naming `what`.
    pub fn checked<T>(&self, what: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        let memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let result = f();
        let invalid = pollster::block_on(validation.pop());
        let out_of_memory = pollster::block_on(memory.pop());
        self.check_lost()?;
        if let Some(e) = out_of_memory.or(invalid) {
            return Err(Error::Gpu(format!("{} ({what}): {e}", self.info.name)));
        }
        result
    }

    fn check_lost(&self) -> Result<()> {
        match self.lost.lock().ok().and_then(|slot| slot.clone()) {
            Some(why) => Err(Error::Gpu(format!("{}: device lost ({why})", self.info.name))),
            None => Ok(()),
        }
    }

    /// Waits for `submission`, at most [`WAIT`].
    pub fn wait(&self, submission: wgpu::SubmissionIndex) -> Result<()> {
        let poll = wgpu::PollType::Wait { submission_index: Some(submission), timeout: Some(WAIT) };
        self.device.poll(poll).map_err(|e| Error::Gpu(format!("{}: waiting for the GPU: {e}", self.info.name)))?;
        self.check_lost()
    }

    /// Submits `encoder` after copying each of `sources` (whole buffers, `COPY_SRC`) back, waits,
    /// and returns their bytes in order.
    pub fn read_back(&self, mut encoder: wgpu::CommandEncoder, sources: &[&wgpu::Buffer]) -> Result<Vec<Vec<u8>>> {
        let size: u64 = sources.iter().map(|b| b.size()).sum();
        let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut offset = 0;
        for source in sources {
            encoder.copy_buffer_to_buffer(source, 0, &readback, offset, source.size());
            offset += source.size();
        }
        let submission = self.queue.submit([encoder.finish()]);
        let slice = readback.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            // The receiver outlives every poll that can deliver this.
            let _ = sender.send(r);
        });
        self.wait(submission)?;
        // Whichever thread polls runs the callback: if another thread's poll found our work done,
        // the callback may land a moment after our own wait returns, so keep polling until it does.
        let deadline = std::time::Instant::now() + WAIT;
        let mapped = loop {
            match receiver.recv_timeout(Duration::from_millis(5)) {
                Ok(r) => break r,
                Err(_) if std::time::Instant::now() < deadline => {
                    self.device.poll(wgpu::PollType::Poll).map_err(|e| Error::Gpu(format!("polling the GPU: {e}")))?;
                }
                Err(_) => return Err(Error::Gpu(format!("{}: results never came back", self.info.name))),
            }
        };
        mapped.map_err(|e| Error::Gpu(format!("{}: reading results back: {e}", self.info.name)))?;
        let bytes = slice.get_mapped_range().map_err(|e| Error::Gpu(format!("reading results back: {e}")))?;
        let mut out = Vec::with_capacity(sources.len());
        let mut start = 0;
        for source in sources {
            let end = start + source.size() as usize;
            out.push(bytes[start..end].to_vec());
            start = end;
        }
        drop(bytes);
        readback.unmap();
        Ok(out)
    }

    /// The WGSL module `source`.
    pub fn shader(&self, label: &str, source: &str) -> wgpu::ShaderModule {
        self.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        })
    }

    /// The layouts of a pipeline whose only binding is one uniform buffer of `bytes` at group 0,
    /// binding 0, seen by `visibility`; `dynamic` when each draw picks its slot by offset.
    pub fn uniform_layouts(
        &self,
        label: &str,
        visibility: wgpu::ShaderStages,
        bytes: u64,
        dynamic: bool,
    ) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
        let group = self.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: dynamic,
                    min_binding_size: wgpu::BufferSize::new(bytes),
                },
                count: None,
            }],
        });
        let pipeline = self.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&group)],
            immediate_size: 0,
        });
        (group, pipeline)
    }

    /// The vertex buffer of `vertices` (floats, interleaved as the pipeline reads them) and the
    /// index buffer of `triangles`, with the index count.
    pub fn mesh_buffers(&self, vertices: &[f32], triangles: &[[u32; 3]]) -> Result<(wgpu::Buffer, wgpu::Buffer, u32)> {
        let indices: &[u32] = bytemuck::cast_slice(triangles);
        let vertex = self.buffer_init("vertex buffer", bytemuck::cast_slice(vertices), wgpu::BufferUsages::VERTEX)?;
        let index = self.buffer_init("index buffer", bytemuck::cast_slice(indices), wgpu::BufferUsages::INDEX)?;
        let count = u32::try_from(indices.len())
            .map_err(|_| Error::Gpu(format!("{}: {} indices do not fit one draw", self.info.name, indices.len())))?;
        Ok((vertex, index, count))
    }

    /// A buffer of `bytes` for `usage`, or an error if it exceeds the device's buffer limit
    /// (a mesh too large for this GPU in one piece).
    pub fn buffer_init(&self, what: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> Result<wgpu::Buffer> {
        use wgpu::util::DeviceExt;
        let limit = self.device.limits().max_buffer_size;
        if bytes.len() as u64 > limit {
            return Err(Error::Gpu(format!(
                "{}: the {what} needs {} bytes, over the device's buffer limit of {limit}; split the mesh",
                self.info.name,
                bytes.len()
            )));
        }
        Ok(self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(what),
            contents: bytes,
            usage,
        }))
    }
}
