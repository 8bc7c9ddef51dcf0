//! Vertex reuse counted on the GPU: vertex-shader invocations of each buffer's indexed draw
//! (`--cache gpu`, a spec's `caches = ["gpu"]`), reported as `acmr` and `atvr` with cache `gpu`
//! beside the simulated models, over the draws as they are.

use super::cache::{CacheStats, acmr_atvr_columns, over_draws};
use super::{CacheColumn, Draws, GPU_CACHE, MeasureOptions, Metric, Name, Value};
use crate::error::Result;
use crate::gpu::vertex_reuse;

pub struct Counted;

pub static METRIC: Counted = Counted;

static NAMES: &[Name] = &[
    Name { name: "acmr", label: "ACMR (vertex-cache misses per triangle)", needs: "`caches = [\"gpu\"]`", optimum: None },
    Name { name: "atvr", label: "ATVR (misses per referenced vertex)", needs: "`caches = [\"gpu\"]`", optimum: Some(1.0) },
];

impl Metric for Counted {
    fn names(&self) -> &'static [Name] {
        NAMES
    }

    fn reported(&self, options: &MeasureOptions) -> Vec<&'static str> {
        if options.gpu_vertices { vec!["acmr", "atvr"] } else { Vec::new() }
    }

    fn needs_gpu(&self) -> bool {
        true
    }

    fn measure(&self, draws: &Draws) -> Result<Vec<Value>> {
        let counter = vertex_reuse::shared()?;
        let mesh = &draws.scene.mesh;
        let mut counted = Vec::new();
        for (b, n) in draws.used() {
            let triangles = draws.triangles(b);
            let stats = CacheStats {
                triangles: triangles.len(),
                vertices: super::cache::referenced(&triangles, mesh.vertex_count()),
                misses: counter.count(&mesh.positions, &triangles)?,
                batches: 0,
            };
            counted.push((n, stats));
        }
        let (acmr, atvr) = over_draws(counted);
        // Counted, not simulated: the cache is the device, named in `device`.
        let cache = Some(CacheColumn { name: GPU_CACHE.into(), kind: GPU_CACHE, size: None });
        let device = Some(counter.device());
        Ok(vec![
            Value { cache: cache.clone(), device: device.clone(), ..Value::new("acmr", acmr) },
            Value { cache, device, ..Value::new("atvr", atvr) },
        ])
    }

    fn columns(&self, values: &[&Value]) -> Vec<(String, String)> {
        acmr_atvr_columns(values, |_| "ACMR/ATVR counted by the Vulkan device".into())
    }
}
