//! Render time on the GPU (issue 6 §4): does a lower overdraw ratio or ACMR buy time on real
//! hardware? One draw order is rendered many times from one camera with one of two shaders, each
//! frame timed by timestamp queries at the start and end of its render pass.
//!
//! - [`Shading::Pixel`], pixel-bound: a procedural texture and per-pixel lighting, the load Nehab,
//!   Barczak & Sander 2006 (§6) time, so every shaded fragment costs and early-Z rejection saves.
//! - [`Shading::Vertex`], vertex-bound: a long per-vertex computation (the lighting loop of
//!   Bogomjakov & Gotsman 2002's Table 2 in spirit) and a trivial fragment shader, so every
//!   vertex-cache miss costs.
//!
//! Frames are rendered back to back in one submission after [`WARMUP`] untimed ones; the result
//! is the median frame time with the 10th and 90th percentiles. On lavapipe timestamps measure the
//! CPU that emulates the GPU: the numbers are real but say nothing about hardware.

use glam::Vec3;

use super::Gpu;
use crate::error::{Error, Result};
use crate::raster::Camera;

/// Frames rendered before timing starts (caches, clocks, lazy driver work).
pub const WARMUP: usize = 5;
/// Most timed frames per call: two timestamps each, under wgpu's 4,096 per query set.
pub const MAX_FRAMES: usize = 2000;

/// Which stage the shader loads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Shading {
    Pixel,
    Vertex,
}

impl Shading {
    pub fn name(self) -> &'static str {
        match self {
            Shading::Pixel => "pixel",
            Shading::Vertex => "vertex",
        }
    }

    pub fn parse(text: &str) -> Result<Shading> {
        match text {
            "pixel" => Ok(Shading::Pixel),
            "vertex" => Ok(Shading::Vertex),
            other => Err(Error::usage(format!("unknown shading `{other}` (pixel or vertex)"))),
        }
    }
}

/// Frame times of one draw order from one camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    pub median_ms: f64,
    pub p10_ms: f64,
    pub p90_ms: f64,
}

const SHADER: &str = r#"
struct View {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
}
@group(0) @binding(0) var<uniform> view: View;

struct Varying {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) shade: f32,
}

@vertex
fn plain(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> Varying {
    return Varying(view.view_proj * vec4<f32>(p, 1.0), p, n, 1.0);
}

// 256 rounds of a rotation and a transcendental per vertex, feeding the colour so none is dead.
@vertex
fn heavy(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> Varying {
    var a = n;
    for (var i = 0u; i < 256u; i = i + 1u) {
        a = normalize(vec3<f32>(a.y + 0.37 * sin(a.z * 3.1), a.z - 0.21 * cos(a.x * 2.3), a.x + 0.11));
    }
    return Varying(view.view_proj * vec4<f32>(p, 1.0), p, n, 0.5 + 0.5 * a.x);
}

@fragment
fn flat(v: Varying) -> @location(0) vec4<f32> {
    return vec4<f32>(v.shade, v.shade, v.shade, 1.0);
}

// Procedural marble: 48 octaves of sines over world position, then Blinn-Phong lighting.
@fragment
fn textured(v: Varying) -> @location(0) vec4<f32> {
    var q = v.world * 8.0;
    var t = 0.0;
    var amplitude = 1.0;
    for (var i = 0u; i < 48u; i = i + 1u) {
        t = t + amplitude * sin(q.x + 1.7 * sin(q.y) + 2.3 * sin(q.z));
        q = q.yzx * 1.93 + vec3<f32>(0.31, 0.17, 0.53);
        amplitude = amplitude * 0.71;
    }
    let albedo = mix(vec3<f32>(0.9, 0.85, 0.8), vec3<f32>(0.3, 0.25, 0.35), 0.5 + 0.5 * sin(t));
    let n = normalize(v.normal);
    let l = normalize(vec3<f32>(0.4, 0.8, 0.45));
    let h = normalize(l + normalize(view.eye.xyz - v.world));
    let light = 0.15 + 0.85 * max(dot(n, l), 0.0) + 0.4 * pow(max(dot(n, h), 0.0), 32.0);
    return vec4<f32>(albedo * light, 1.0);
}
"#;

/// Times draws on the shared GPU.
pub struct RenderTimer {
    gpu: &'static Gpu,
    layout: wgpu::BindGroupLayout,
    pixel: wgpu::RenderPipeline,
    vertex: wgpu::RenderPipeline,
}

/// Bytes of the shader's `View`: the matrix, then the eye.
const VIEW_BYTES: u64 = 80;
const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The process's timer, built once; the error, if building failed, is returned on every call.
pub fn shared() -> Result<&'static RenderTimer> {
    static TIMER: std::sync::OnceLock<std::result::Result<RenderTimer, String>> = std::sync::OnceLock::new();
    super::once(&TIMER, RenderTimer::new)
}

impl RenderTimer {
    /// Opens the GPU; fails when it has no timestamp queries.
    pub fn new() -> Result<RenderTimer> {
        let gpu = super::shared()?;
        if !gpu.has(wgpu::Features::TIMESTAMP_QUERY) {
            return Err(Error::Gpu(format!(
                "{}: no timestamp queries, so render time cannot be measured",
                gpu.describe()
            )));
        }
        gpu.checked("building the timing pipelines", || Ok(RenderTimer::build(gpu)))
    }

    fn build(gpu: &'static Gpu) -> RenderTimer {
        let device = &gpu.device;
        let module = gpu.shader("render time", SHADER);
        let stages = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let (layout, pipeline_layout) = gpu.uniform_layouts("render time", stages, VIEW_BYTES, false);
        let pipeline = |vertex: &str, fragment: &str| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(fragment),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vertex),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: 24,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                    })],
                },
                primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fragment),
                    compilation_options: Default::default(),
                    targets: &[Some(COLOR.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        RenderTimer { gpu, pixel: pipeline("plain", "textured"), vertex: pipeline("heavy", "flat"), layout }
    }

    /// The device, as written into results.
    pub fn device(&self) -> String {
        self.gpu.describe()
    }

    /// Renders `triangles` (in draw order) from `camera` at `res`² with `shading`, [`WARMUP`]
    /// frames and then `frames` timed ones.
    pub fn time(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        camera: &Camera,
        res: u32,
        shading: Shading,
        frames: usize,
    ) -> Result<Timing> {
        if !(1..=MAX_FRAMES).contains(&frames) {
            return Err(Error::usage(format!("frames = {frames} is outside 1..={MAX_FRAMES}")));
        }
        let limit = self.gpu.device.limits().max_texture_dimension_2d;
        if !(1..=limit).contains(&res) {
            return Err(Error::usage(format!("resolution {res} is outside 1..={limit} ({})", self.device())));
        }
        // The model in the camera's unit frame, as the overdraw counts see it: at any scale or
        // place it covers the same pixels, and the marble has the same number of veins.
        let positions = &camera.framing.unit_positions(positions);
        let normals = vertex_normals(positions, triangles)?;
        self.gpu.checked("timing a draw", || {
            let device = &self.gpu.device;
            let interleaved: Vec<f32> =
                positions.iter().zip(&normals).flat_map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z]).collect();
            let (vertices, index, index_count) = self.gpu.mesh_buffers(&interleaved, triangles)?;
            let mut uniform = camera.view_proj.to_cols_array().to_vec();
            uniform.extend(camera.unit_eye().extend(1.0).to_array());
            let uniform = self.gpu.buffer_init("view", bytemuck::cast_slice(&uniform), wgpu::BufferUsages::UNIFORM)?;
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("view"),
                layout: &self.layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }],
            });
            let target = |format: wgpu::TextureFormat| {
                device
                    .create_texture(&wgpu::TextureDescriptor {
                        label: Some("render time target"),
                        size: wgpu::Extent3d { width: res, height: res, depth_or_array_layers: 1 },
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D2,
                        format,
                        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                        view_formats: &[],
                    })
                    .create_view(&Default::default())
            };
            let (color, depth) = (target(COLOR), target(DEPTH));
            let total = WARMUP + frames;
            let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame times"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * frames as u32,
            });
            let pipeline = match shading {
                Shading::Pixel => &self.pixel,
                Shading::Vertex => &self.vertex,
            };
            let mut encoder = device.create_command_encoder(&Default::default());
            for frame in 0..total {
                let timed = frame.checked_sub(WARMUP).map(|i| wgpu::RenderPassTimestampWrites {
                    query_set: &queries,
                    beginning_of_pass_write_index: Some(2 * i as u32),
                    end_of_pass_write_index: Some(2 * i as u32 + 1),
                });
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("frame"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &color,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &depth,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Discard,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: timed,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.set_vertex_buffer(0, vertices.slice(..));
                pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..index_count, 0, 0..1);
            }
            let resolved = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame times"),
                size: 16 * frames as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            encoder.resolve_query_set(&queries, 0..2 * frames as u32, &resolved, 0);
            let bytes = self.gpu.read_back(encoder, &[&resolved])?;
            let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes[0]);
            let period_ns = f64::from(self.gpu.queue.get_timestamp_period());
            let mut ms: Vec<f64> =
                ticks.chunks_exact(2).map(|t| t[1].saturating_sub(t[0]) as f64 * period_ns * 1e-6).collect();
            ms.sort_by(f64::total_cmp);
            let at = |q: f64| ms[((ms.len() - 1) as f64 * q).round() as usize];
            Ok(Timing { median_ms: at(0.5), p10_ms: at(0.1), p90_ms: at(0.9) })
        })
    }
}

/// Area-weighted vertex normals (unit, or zero for a vertex whose triangles have no area).
fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<Vec<Vec3>> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| positions.get(v as usize).copied());
        let (Some(a), Some(b), Some(c)) = (a, b, c) else {
            return Err(Error::usage(format!("triangle {t:?} indexes past {} vertices", positions.len())));
        };
        let n = (b - a).cross(c - a);
        for v in t {
            normals[*v as usize] += n;
        }
    }
    Ok(normals.into_iter().map(|n| n.normalize_or_zero()).collect())
}
