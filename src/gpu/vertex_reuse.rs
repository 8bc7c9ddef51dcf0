//! Vertex reuse as the GPU does it: vertex-shader invocations of one indexed draw, read from a
//! pipeline-statistics query (issue 6; Kerbl et al. 2018 measure GPUs the same way).
//!
//! Invocations ÷ triangles is a hardware ACMR and invocations ÷ referenced vertices a hardware
//! ATVR, directly comparable with the simulated cache models of [`crate::measure::cache`]. A
//! device reports what its vertex front end really shaded: on an NVIDIA H100 that is its batch
//! reuse; on Mesa's lavapipe it is reuse within the draw module's small batches only
//! (../shared/GPU.md), so lavapipe checks the plumbing, not the hardware.
//!
//! The draw uses a real vertex shader (a matrix transform) and a 1×1 target with every triangle
//! culled after the vertex stage, so nothing but vertex work is done.

use glam::Vec3;

use super::Gpu;
use crate::error::{Error, Result};

const SHADER: &str = r#"
@vertex
fn main(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    // Every vertex lands behind the far plane: clipped, never rasterized.
    return vec4<f32>(position.xy, 2.0 + position.z * 0.0, 1.0);
}
"#;

/// The process's counter, built once; the error, if building failed, is returned on every call.
pub fn shared() -> Result<&'static VertexCounter> {
    static COUNTER: std::sync::OnceLock<std::result::Result<VertexCounter, String>> = std::sync::OnceLock::new();
    super::once(&COUNTER, VertexCounter::new)
}

/// Counts vertex-shader invocations on the shared GPU.
pub struct VertexCounter {
    gpu: &'static Gpu,
    pipeline: wgpu::RenderPipeline,
    target: wgpu::TextureView,
}

impl VertexCounter {
    /// Opens the GPU; fails when it has no pipeline-statistics queries.
    pub fn new() -> Result<VertexCounter> {
        let gpu = super::shared()?;
        if !gpu.has(wgpu::Features::PIPELINE_STATISTICS_QUERY) {
            return Err(Error::Gpu(format!(
                "{}: no pipeline-statistics queries, so vertex-shader invocations cannot be counted",
                gpu.describe()
            )));
        }
        gpu.checked("building the vertex-count pipeline", || Ok(VertexCounter::build(gpu)))
    }

    fn build(gpu: &'static Gpu) -> VertexCounter {
        let device = &gpu.device;
        let module = gpu.shader("vertex count", SHADER);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("vertex count"),
            bind_group_layouts: &[],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("vertex count"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                buffers: &[Some(super::POSITIONS)],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let target = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("vertex count"),
                size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Depth32Float,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default());
        VertexCounter { gpu, pipeline, target }
    }

    /// The device, as written into results.
    pub fn device(&self) -> String {
        self.gpu.describe()
    }

    /// Vertex-shader invocations when `triangles` are drawn in order, once, as one indexed
    /// triangle list over `positions`: the GPU's cache misses.
    pub fn count(&self, positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<u64> {
        if let Some(&v) = triangles.iter().flatten().find(|&&v| v as usize >= positions.len()) {
            return Err(Error::usage(format!("vertex index {v} is out of range for {} vertices", positions.len())));
        }
        let invocations = self.gpu.checked("counting vertex-shader invocations", || {
            let device = &self.gpu.device;
            let (vertices, index, index_count) = self.gpu.mesh_buffers(bytemuck::cast_slice(positions), triangles)?;
            let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("vertex invocations"),
                ty: wgpu::QueryType::PipelineStatistics(wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS),
                count: 1,
            });
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("vertex count"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &self.target,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Discard,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_vertex_buffer(0, vertices.slice(..));
                pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
                pass.begin_pipeline_statistics_query(&queries, 0);
                pass.draw_indexed(0..index_count, 0, 0..1);
                pass.end_pipeline_statistics_query();
            }
            let resolved = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("vertex invocations"),
                size: 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            encoder.resolve_query_set(&queries, 0..1, &resolved, 0);
            let bytes = self.gpu.read_back(encoder, &[&resolved])?;
            Ok(bytemuck::pod_read_unaligned::<u64>(&bytes[0][..8]))
        })?;
        Ok(invocations)
    }
}
