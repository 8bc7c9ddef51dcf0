//! The GPU raster backend: the same per-view counts as [`super::cpu::CpuRaster`], drawn by a real
//! Vulkan device through wgpu and counted by occlusion queries and a fragment-shader counter.
//!
//! Per view, in one render pass over an R×R `Depth32Float` buffer cleared to 1.0, two draws:
//! 1. The mesh in draw order, back faces culled (counter-clockwise is front, NDC y up, as on the
//!    CPU), depth test LESS with writes. An occlusion query counts the samples that pass:
//!    **passed**. The fragment shader adds one to an atomic counter for the view: because it
//!    writes to memory, Vulkan runs it before the depth test, for every rasterized fragment, so
//!    the counter is **fragments** (GPU.md: exact on lavapipe and on an H100). The counter is
//!    spread over [`LANES`] words, a 64-byte line per 64×64-pixel tile (16 lines, by tile) and a
//!    word per column within it, so fragments do not all contend for one address, threads
//!    drawing different tiles rarely share a line, and no word can overflow.
//! 2. A full-screen triangle at depth 1.0 tested GREATER without writes, which passes exactly
//!    where some fragment left a depth below 1.0: **covered**, by a second query.
//!
//! One mesh draw per view, not two: drawing is what costs (lavapipe spends it in vertex
//! processing and triangle setup, which it runs on one thread).
//!
//! The rules the CPU reference spells out (pixel centres, top-left rule, LESS, clear to 1.0) are
//! Vulkan's own; the CPU snaps to 8 sub-pixel bits as Vulkan devices do. What can still differ is below the rules:
//! how a device rounds to its sub-pixel grid and interpolates depth. A fragment whose depth ties
//! with, or lies within a rounding error of, an earlier one may pass on one backend and not the
//! other. tests/gpu_raster.rs measures that difference and holds it under 0.1% of fragments.
//!
//! Vulkan only promises that an occlusion query is zero or not, and wgpu does not ask for precise
//! counts; every driver we met (lavapipe, NVIDIA) counts exactly anyway. [`GpuRaster::new`] draws a
//! calibration scene whose counts are known and refuses a driver that does not.
//!
//! Views go in batches of [`BATCH`]: one submission, one uniform buffer of matrices addressed by
//! dynamic offset, one query resolve and one readback per batch.

use glam::{Mat4, Vec3};

use super::cpu::{self, MAX_RESOLUTION};
use super::views::Camera;
use super::{RasterBackend, ViewCounts};
use crate::error::{Error, Result};
use crate::gpu::{self, Gpu};

/// Views per submission: two occlusion queries each, under wgpu's 4,096 per query set.
const BATCH: usize = 1024;
const QUERIES_PER_VIEW: usize = 2;
/// Counter words per view for the fragment count (see the module comment).
const LANES: usize = 256;
/// Bytes per view in the uniform buffer: the matrix, then the view's first counter word.
const VIEW_BYTES: u64 = 80;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

const SHADER: &str = r#"
struct View {
    view_proj: mat4x4<f32>,
    first_counter: u32,
}
@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<storage, read_write> fragments: array<atomic<u32>>;

@vertex
fn mesh(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view.view_proj * vec4<f32>(position, 1.0);
}

// Runs for every rasterized fragment: a shader that writes memory gets late depth testing.
@fragment
fn count(@builtin(position) pixel: vec4<f32>) {
    let x = u32(pixel.x);
    let y = u32(pixel.y);
    let lane = ((x / 64u + 8u * (y / 64u)) % 16u) * 16u + x % 16u;
    atomicAdd(&fragments[view.first_counter + lane], 1u);
}

// One triangle covering the whole image, at the far plane.
@vertex
fn fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return vec4<f32>(select(-1.0, 3.0, i == 1u), select(-1.0, 3.0, i == 2u), 1.0, 1.0);
}
"#;

/// Overdraw counts from the GPU.
pub struct GpuRaster {
    gpu: &'static Gpu,
    layout: wgpu::BindGroupLayout,
    passed: wgpu::RenderPipeline,
    covered: wgpu::RenderPipeline,
}

impl GpuRaster {
    /// Opens the GPU, builds the three pipelines and checks on a calibration scene that the
    /// driver's occlusion queries count every sample.
    pub fn new() -> Result<GpuRaster> {
        let gpu = gpu::shared()?;
        let raster = gpu.checked("building the raster pipelines", || Ok(GpuRaster::build(gpu)))?;
        raster.calibrate()?;
        Ok(raster)
    }

    fn build(gpu: &'static Gpu) -> GpuRaster {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("overdraw"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(VIEW_BYTES),
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("overdraw"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let positions = wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        };
        let pipeline = |entry: &str, mesh: bool, compare: wgpu::CompareFunction, write: bool| {
            let buffers = [Some(positions.clone())];
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
                // No colour target: the mesh's fragment shader only counts.
                fragment: mesh.then(|| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("count"),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        GpuRaster {
            gpu,
            passed: pipeline("mesh", true, wgpu::CompareFunction::Less, true),
            covered: pipeline("fullscreen", false, wgpu::CompareFunction::Greater, false),
            layout,
        }
    }

    /// The device's name and driver, for provenance.
    pub fn device(&self) -> String {
        self.gpu.describe()
    }

    /// Draws a square filling the image twice at the same depth: the second copy fails LESS, so
    /// exact queries give passed = covered = R², fragments = 2R². A driver answering "some" (1)
    /// instead of a count is refused here, before it can produce a wrong figure.
    fn calibrate(&self) -> Result<()> {
        let res = 64;
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let positions: Vec<Vec3> = corners.iter().map(|&(x, y)| Vec3::new(x, y, 0.5)).collect();
        let quad = [[0, 1, 2], [0, 2, 3]];
        let camera = Camera { view_proj: Mat4::IDENTITY, eye: Vec3::Z, forward: Vec3::NEG_Z, perspective: false };
        let counts = self.count(&positions, &[quad, quad].concat(), &[camera], res)?;
        let area = u64::from(res * res);
        let expected = ViewCounts { covered: area, fragments: 2 * area, passed: area };
        if counts[0] != expected {
            return Err(Error::Gpu(format!(
                "{}: occlusion queries are not exact on this driver (calibration counted {:?}, expected {expected:?})",
                self.device(),
                counts[0]
            )));
        }
        Ok(())
    }

    fn draw_batch(&self, mesh: &Mesh, cameras: &[Camera]) -> Result<Vec<ViewCounts>> {
        let device = &self.gpu.device;
        let stride = VIEW_BYTES.next_multiple_of(u64::from(device.limits().min_uniform_buffer_offset_alignment));
        let mut uniforms = vec![0u8; stride as usize * cameras.len()];
        for (v, (slot, camera)) in uniforms.chunks_exact_mut(stride as usize).zip(cameras).enumerate() {
            slot[..64].copy_from_slice(bytemuck::cast_slice(&camera.view_proj.to_cols_array()));
            slot[64..68].copy_from_slice(&((v * LANES) as u32).to_le_bytes());
        }
        let uniforms = self.gpu.buffer_init("views", &uniforms, wgpu::BufferUsages::UNIFORM)?;
        let counters = self.gpu.buffer_init(
            "fragment counters",
            &vec![0u8; cameras.len() * LANES * 4],
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        )?;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("view"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &uniforms,
                        offset: 0,
                        size: wgpu::BufferSize::new(VIEW_BYTES),
                    }),
                },
                wgpu::BindGroupEntry { binding: 1, resource: counters.as_entire_binding() },
            ],
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
        let [queries, fragments]: [Vec<u8>; 2] = self
            .gpu
            .read_back(encoder, &[&resolved, &counters])?
            .try_into()
            .map_err(|_| Error::Gpu("readback returned the wrong number of buffers".into()))?;
        let queries: Vec<u64> = bytemuck::pod_collect_to_vec(&queries);
        let fragments: Vec<u32> = bytemuck::pod_collect_to_vec(&fragments);
        Ok(queries
            .chunks_exact(QUERIES_PER_VIEW)
            .zip(fragments.chunks_exact(LANES))
            .map(|(q, lanes)| ViewCounts {
                passed: q[0],
                covered: q[1],
                fragments: lanes.iter().map(|&n| u64::from(n)).sum(),
            })
            .collect())
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

    fn count(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>> {
        let limit = self.gpu.device.limits().max_texture_dimension_2d.min(MAX_RESOLUTION);
        if !(1..=limit).contains(&res) {
            return Err(Error::usage(format!("resolution {res} is outside 1..={limit} ({})", self.device())));
        }
        check_projection(positions, cameras, res)?;
        if cameras.is_empty() {
            return Ok(Vec::new());
        }
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
}

/// The CPU reference refuses a view that would need clipping or that projects far off screen; the
/// GPU would silently clip instead. Same input, same answer: a bounding sphere that every camera
/// frames settles it in O(vertices + views); only a camera that fails the sphere test pays the
/// CPU's exact per-vertex check, which then names the vertex.
fn check_projection(positions: &[Vec3], cameras: &[Camera], res: u32) -> Result<()> {
    let framing = super::Framing::of(positions);
    for (i, camera) in cameras.iter().enumerate() {
        if !camera.frames_sphere(framing.center, framing.radius) {
            cpu::check_projection(positions, camera, res).map_err(|why| Error::usage(format!("view {i}: {why}")))?;
        }
    }
    Ok(())
}
