//! The GPU raster backend: the same per-view counts as [`super::cpu::CpuRaster`], drawn by a real
//! Vulkan device through wgpu and counted by occlusion queries.
//!
//! Per view, in one render pass over an R×R `Depth32Float` buffer cleared to 1.0, two draws
//! without a fragment shader (depth only, the cheapest path on every device):
//! 1. The mesh in draw order, back faces culled (counter-clockwise is front, NDC y up, as on the
//!    CPU), depth test LESS with writes. An occlusion query counts the samples that pass:
//!    **passed**.
//! 2. A full-screen triangle at depth 1.0 tested GREATER without writes, which passes exactly
//!    where some fragment left a depth below 1.0: **covered**, by a second query.
//!
//! The positions are uploaded in the cameras' unit frame ([`crate::mesh::Framing::to_unit`], the
//! same f32 values the CPU reference projects), so the counts depend on the shape alone, not on
//! the model's scale or place, on both backends alike.
//!
//! The rules the CPU reference spells out (pixel centres, top-left rule, LESS, clear to 1.0) are
//! Vulkan's own; the CPU snaps to 8 sub-pixel bits as Vulkan devices do. What can still differ is below the rules:
//! how a device rounds to its sub-pixel grid and interpolates depth. A fragment whose depth ties
//! with, or lies within a rounding error of, an earlier one may pass on one backend and not the
//! other. tests/gpu_raster.rs measures that difference and holds it under 0.1% of fragments.
//!
//! Vulkan only promises that an occlusion query is zero or not, and wgpu does not ask for precise
//! counts; every driver we met (lavapipe, NVIDIA) counts exactly anyway. [`GpuRaster::new`] draws a
//! calibration scene whose counts are known on every device and refuses a driver that does not.
//!
//! Views go in batches of [`BATCH`]: one submission, one uniform buffer of matrices addressed by
//! dynamic offset, one query resolve and one readback per batch. The views are split over the
//! devices of [`gpu::pool`], a thread each: one device on a hardware GPU, one per core on a
//! software one, whose drawing is single-threaded per device.

use glam::{Mat4, Vec3};

use crate::error::{Error, Result};
use crate::gpu::{self, Gpu};
use crate::mesh::Framing;
use crate::raster::cpu::{self, MAX_RESOLUTION};
use crate::raster::{Camera, RasterBackend, ViewCounts};

/// Views per submission: two occlusion queries each, within wgpu's 4,096 per query set.
const BATCH: usize = 4096 / QUERIES_PER_VIEW;
const QUERIES_PER_VIEW: usize = 2;
/// Bytes per view in the uniform buffer: its matrix.
const VIEW_BYTES: u64 = 64;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

const SHADER: &str = r#"
@group(0) @binding(0) var<uniform> view_proj: mat4x4<f32>;

@vertex
fn mesh(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view_proj * vec4<f32>(position, 1.0);
}

// One triangle covering the whole image, at the far plane.
@vertex
fn fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return vec4<f32>(select(-1.0, 3.0, i == 1u), select(-1.0, 3.0, i == 2u), 1.0, 1.0);
}
"#;

/// Overdraw counts from the GPU.
pub struct GpuRaster {
    /// One per device of [`gpu::pool`], each checked by calibration.
    devices: Vec<DeviceRaster>,
}

/// The pipelines on one device.
struct DeviceRaster {
    gpu: &'static Gpu,
    layout: wgpu::BindGroupLayout,
    passed: wgpu::RenderPipeline,
    covered: wgpu::RenderPipeline,
}

impl GpuRaster {
    /// Opens the GPU's devices, builds the pipelines on each and checks on a calibration scene
    /// that the driver's occlusion queries count every sample.
    pub fn new() -> Result<GpuRaster> {
        let devices = gpu::pool()?
            .into_iter()
            .map(|gpu| {
                let raster = gpu.checked("building the raster pipelines", || Ok(DeviceRaster::build(gpu)))?;
                raster.calibrate()?;
                Ok(raster)
            })
            .collect::<Result<_>>()?;
        Ok(GpuRaster { devices })
    }

    /// The device's name and driver, for provenance.
    pub fn device(&self) -> String {
        self.devices[0].gpu.describe()
    }
}

impl DeviceRaster {
    fn build(gpu: &'static Gpu) -> DeviceRaster {
        let device = &gpu.device;
        let module = gpu.shader("overdraw", SHADER);
        let (layout, pipeline_layout) = gpu.uniform_layouts("view", wgpu::ShaderStages::VERTEX, VIEW_BYTES, true);
        let pipeline = |entry: &str, mesh: bool, compare: wgpu::CompareFunction, write: bool| {
            let buffers = [Some(gpu::POSITIONS)];
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    buffers: if mesh { &buffers } else { &[] },
                },
                primitive: wgpu::PrimitiveState {
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: mesh.then_some(wgpu::Face::Back),
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH,
                    depth_write_enabled: Some(write),
                    depth_compare: Some(compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                // Depth only: the queries count what passes the depth test.
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        };
        DeviceRaster {
            gpu,
            passed: pipeline("mesh", true, wgpu::CompareFunction::Less, true),
            covered: pipeline("fullscreen", false, wgpu::CompareFunction::Greater, false),
            layout,
        }
    }

    /// Draws a square filling the image twice at the same depth: the second copy fails LESS, so
    /// exact queries give passed = covered = R². A driver answering "some" (1) instead of a
    /// count is refused here, before it can produce a wrong figure.
    fn calibrate(&self) -> Result<()> {
        let res = 64;
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let positions: Vec<Vec3> = corners.iter().map(|&(x, y)| Vec3::new(x, y, 0.5)).collect();
        let quad = [[0, 1, 2], [0, 2, 3]];
        let camera = Camera {
            view_proj: Mat4::IDENTITY,
            framing: Framing::UNIT,
            eye: Vec3::Z,
            forward: Vec3::NEG_Z,
            perspective: false,
        };
        let counts = self.count(&positions, &[quad, quad].concat(), &[camera], res)?;
        let area = u64::from(res * res);
        let expected = ViewCounts { covered: area, passed: area };
        if counts[0] != expected {
            return Err(Error::Gpu(format!(
                "{}: occlusion queries are not exact on this driver (calibration counted {:?}, expected {expected:?})",
                self.gpu.describe(),
                counts[0]
            )));
        }
        Ok(())
    }

    /// Uploads the mesh, in the unit frame of each run of cameras with one framing (all of them,
    /// from a view set), and counts `cameras` on this device, a batch per submission.
    fn count(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>> {
        let mut counts = Vec::with_capacity(cameras.len());
        for run in cameras.chunk_by(|a, b| a.framing == b.framing) {
            let unit = run[0].framing.unit_positions(positions);
            counts.extend(self.count_unit(&unit, triangles, run, res)?);
        }
        Ok(counts)
    }

    /// Counts `cameras` on positions already in their unit frame.
    fn count_unit(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>> {
        self.gpu.checked("counting fragments", || {
            let (vertices, index, index_count) = self.gpu.mesh_buffers(bytemuck::cast_slice(positions), triangles)?;
            let depth = self.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("depth"),
                size: wgpu::Extent3d { width: res, height: res, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: DEPTH,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            });
            let depth = depth.create_view(&Default::default());
            let mesh = Mesh { vertices: &vertices, index: &index, index_count, depth: &depth };
            let mut counts = Vec::with_capacity(cameras.len());
            for batch in cameras.chunks(BATCH) {
                counts.extend(self.draw_batch(&mesh, batch)?);
            }
            Ok(counts)
        })
    }

    fn draw_batch(&self, mesh: &Mesh, cameras: &[Camera]) -> Result<Vec<ViewCounts>> {
        let device = &self.gpu.device;
        let stride = VIEW_BYTES.next_multiple_of(u64::from(device.limits().min_uniform_buffer_offset_alignment));
        let mut uniforms = vec![0u8; stride as usize * cameras.len()];
        for (slot, camera) in uniforms.chunks_exact_mut(stride as usize).zip(cameras) {
            slot[..64].copy_from_slice(bytemuck::cast_slice(&camera.view_proj.to_cols_array()));
        }
        let uniforms = self.gpu.buffer_init("views", &uniforms, wgpu::BufferUsages::UNIFORM)?;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("view"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &uniforms,
                    offset: 0,
                    size: wgpu::BufferSize::new(VIEW_BYTES),
                }),
            }],
        });
        let queries = (cameras.len() * QUERIES_PER_VIEW) as u32;
        let query_set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("overdraw"),
            ty: wgpu::QueryType::Occlusion,
            count: queries,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        for v in 0..cameras.len() {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("view"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: mesh.depth,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: Some(&query_set),
                multiview_mask: None,
            });
            pass.set_bind_group(0, &bind_group, &[(v as u64 * stride) as u32]);
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.index.slice(..), wgpu::IndexFormat::Uint32);
            let first = (v * QUERIES_PER_VIEW) as u32;
            pass.set_pipeline(&self.passed);
            pass.begin_occlusion_query(first);
            pass.draw_indexed(0..mesh.index_count, 0, 0..1);
            pass.end_occlusion_query();
            pass.set_pipeline(&self.covered);
            pass.begin_occlusion_query(first + 1);
            pass.draw(0..3, 0..1);
            pass.end_occlusion_query();
        }
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occlusion results"),
            size: u64::from(queries) * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        encoder.resolve_query_set(&query_set, 0..queries, &resolved, 0);
        let [queries]: [Vec<u8>; 1] = self
            .gpu
            .read_back(encoder, &[&resolved])?
            .try_into()
            .map_err(|_| Error::Gpu("readback returned the wrong number of buffers".into()))?;
        let queries: Vec<u64> = bytemuck::pod_collect_to_vec(&queries);
        Ok(queries.chunks_exact(QUERIES_PER_VIEW).map(|q| ViewCounts { passed: q[0], covered: q[1] }).collect())
    }
}

/// What one call draws, uploaded once for all its batches.
struct Mesh<'a> {
    vertices: &'a wgpu::Buffer,
    index: &'a wgpu::Buffer,
    index_count: u32,
    depth: &'a wgpu::TextureView,
}

impl RasterBackend for GpuRaster {
    fn name(&self) -> &'static str {
        "gpu"
    }

    fn describe(&self) -> String {
        format!("gpu: {}", self.device())
    }

    /// Splits the views into one contiguous share per device, drawn in parallel, concatenated
    /// back in order.
    fn count(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>> {
        let first = &self.devices[0];
        let limit = first.gpu.device.limits().max_texture_dimension_2d.min(MAX_RESOLUTION);
        if !(1..=limit).contains(&res) {
            return Err(Error::usage(format!("resolution {res} is outside 1..={limit} ({})", self.device())));
        }
        check_projection(positions, cameras, res)?;
        let share = cameras.len().div_ceil(self.devices.len()).max(1);
        if share == cameras.len() {
            return first.count(positions, triangles, cameras, res);
        }
        std::thread::scope(|scope| {
            let parts: Vec<_> = (self.devices.iter().zip(cameras.chunks(share)))
                .map(|(device, views)| scope.spawn(move || device.count(positions, triangles, views, res)))
                .collect();
            let mut counts = Vec::with_capacity(cameras.len());
            for part in parts {
                counts.extend(part.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))?);
            }
            Ok(counts)
        })
    }
}

/// The CPU reference refuses a view that would need clipping or that projects far off screen; the
/// GPU would silently clip instead. Same input, same answer: a bounding sphere that every camera
/// frames settles it in O(vertices + views); only a camera that fails the sphere test pays the
/// CPU's exact per-vertex check, which then names the vertex.
fn check_projection(positions: &[Vec3], cameras: &[Camera], res: u32) -> Result<()> {
    let framing = Framing::of(positions);
    for (i, camera) in cameras.iter().enumerate() {
        if !camera.frames_sphere(framing) {
            cpu::check_projection(positions, camera, res).map_err(|why| Error::usage(format!("view {i}: {why}")))?;
        }
    }
    Ok(())
}
