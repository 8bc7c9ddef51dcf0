//! Vertex reuse as measured on real GPUs: one model per vendor, each from a published
//! measurement, for `--cache nvidia`, `amd` and `intel`.
//!
//! No current GPU keeps a FIFO of post-transform vertices across a whole draw. The GPU splits the
//! index stream into batches, shades each batch's distinct vertices once and reuses nothing
//! across batches. Kerbl, Kenzel, Ivanchenko, Schmalstieg and Steinberger, "Revisiting the Vertex
//! Cache: Understanding and Optimizing Vertex Processing on the Modern GPU" (HPG 2018, Proc. ACM
//! CGIT 1(2)), measured how each vendor forms batches, with index buffers that repeat one
//! triangle and with pipeline statistics queries, and the authors' simulator
//! (`GPUPeople/vertex_batch_optimization`, `BatchSimulationParameters.h` and `BatchSimulator.h`)
//! holds the parameters used here for NVIDIA and AMD. Their Intel model is a self-described lower
//! bound (batches of up to 1791 indices with full reuse), not a measured policy; for Intel we use
//! Kapoulkine's measurement instead ("Optimal grid rendering is not optimal", 2017): a 128-entry
//! FIFO, which reproduces every Intel number of that post (see `tests/vendor_cache.rs`).
//!
//! Counts are vertex-shader invocations, as the pipeline statistics count them, so ACMR and ATVR
//! keep their meaning: invocations per triangle and per referenced vertex.

use std::fmt;

use super::cache::CacheStats;

/// A GPU vendor's vertex-reuse model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Vendor {
    Nvidia,
    Amd,
    Intel,
}

/// NVIDIA (Kerbl et al. 2018, measured on a GeForce GTX 1080 Ti): a batch holds at most 96
/// indices (32 triangles) and at most 32 invocations; a triangle that would overflow either
/// starts the next batch whole.
const NVIDIA_BATCH_INDICES: u32 = 96;
const NVIDIA_BATCH_INVOCATIONS: u32 = 32;
/// Within a batch, a vertex is reused when it was last referenced at most this many index
/// positions earlier (the OpenGL rule of the authors' simulator; every reference refreshes it).
const NVIDIA_REUSE_WINDOW: u32 = 42;
/// AMD (Kerbl et al. 2018, measured on a Radeon R7 200 series): the index stream is cut into fixed
/// windows of 384 indices (128 triangles, the driver's recommended primitive group); the reuse
/// cache is emptied at each window and is a 15-entry LRU within it. Invocations are issued in
/// waves of 64, which do not empty the cache.
const AMD_WINDOW_TRIANGLES: usize = 128;
const AMD_LRU: usize = 15;
const AMD_WAVE: u64 = 64;
/// Intel (Kapoulkine 2017): a 128-entry FIFO across the whole draw.
const INTEL_FIFO: u32 = 128;

impl Vendor {
    pub const ALL: [Vendor; 3] = [Vendor::Nvidia, Vendor::Amd, Vendor::Intel];

    /// The name `--cache` takes.
    pub fn name(self) -> &'static str {
        match self {
            Vendor::Nvidia => "nvidia",
            Vendor::Amd => "amd",
            Vendor::Intel => "intel",
        }
    }

    pub fn parse(name: &str) -> Option<Vendor> {
        Vendor::ALL.into_iter().find(|v| v.name() == name)
    }

    /// The vertices one batch (NVIDIA), LRU (AMD) or FIFO (Intel) can hold: the `cache_size`
    /// column of results.
    pub fn size(self) -> u32 {
        match self {
            Vendor::Nvidia => NVIDIA_BATCH_INVOCATIONS,
            Vendor::Amd => AMD_LRU as u32,
            Vendor::Intel => INTEL_FIFO,
        }
    }

    /// The model's parameters and source, for `triorder methods` and `--help`.
    pub fn describe(self) -> &'static str {
        match self {
            Vendor::Nvidia => {
                "batches of at most 96 indices and 32 invocations, a triangle never split; a vertex \
                 is reused within its batch when last referenced at most 42 indices earlier. \
                 Source: Kerbl et al. 2018, Revisiting the Vertex Cache (GTX 1080 Ti), and their \
                 simulator's OpenGL rule"
            }
            Vendor::Amd => {
                "a 15-entry LRU emptied every 384 indices (128 triangles); waves of 64 invocations. \
                 Source: Kerbl et al. 2018, Revisiting the Vertex Cache (Radeon R7 200), and their \
                 simulator"
            }
            Vendor::Intel => {
                "a 128-entry FIFO over the whole draw. Source: Kapoulkine 2017, Optimal grid \
                 rendering is not optimal (Kerbl et al. 2018 give only a lower bound for Intel)"
            }
        }
    }

    /// Simulates the model over `triangles` in draw order, calling `on_miss(3·t + c)` for each
    /// corner `c` of the `t`-th triangle that is shaded. `batches` counts NVIDIA's batches and
    /// AMD's waves.
    pub(crate) fn simulate(
        self,
        triangles: &[[u32; 3]],
        vertex_count: usize,
        on_miss: impl FnMut(usize),
    ) -> CacheStats {
        let mut stats = match self {
            Vendor::Nvidia => nvidia(triangles, vertex_count, on_miss),
            Vendor::Amd => amd(triangles, vertex_count, on_miss),
            Vendor::Intel => return super::cache::fifo(INTEL_FIFO, triangles, vertex_count, on_miss),
        };
        stats.vertices = super::cache::referenced(triangles, vertex_count);
        stats
    }
}

impl fmt::Display for Vendor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// NVIDIA's batches. `last[v]` is the index position of v's last reference plus one (0: never),
/// and v is in the current batch iff that is past the batch's start, so a new batch empties the
/// cache by moving its start, not by clearing `last`.
fn nvidia(triangles: &[[u32; 3]], vertex_count: usize, mut on_miss: impl FnMut(usize)) -> CacheStats {
    let mut last = vec![0u32; vertex_count];
    let (mut start, mut indices, mut invocations) = (0u32, 0u32, 0u32);
    let (mut misses, mut batches) = (0u64, 0u64);
    // Which corners of the triangle at index position `at` miss, against a batch that began at
    // `start`: a corner repeated within the triangle hits its first use.
    let shaded = |last: &[u32], tri: &[u32; 3], at: u32, start: u32| {
        let mut miss = [false; 3];
        for (c, &v) in tri.iter().enumerate() {
            let earlier = tri[..c].iter().position(|&u| u == v);
            let seen = last[v as usize];
            miss[c] = earlier.is_none() && (seen <= start || at + c as u32 + 1 - seen > NVIDIA_REUSE_WINDOW);
        }
        miss
    };
    for (t, tri) in triangles.iter().enumerate() {
        let at = 3 * t as u32;
        let mut miss = shaded(&last, tri, at, start);
        let count = miss.iter().filter(|&&m| m).count() as u32;
        if indices + 3 > NVIDIA_BATCH_INDICES || invocations + count > NVIDIA_BATCH_INVOCATIONS {
            batches += 1;
            (start, indices, invocations) = (at, 0, 0);
            miss = shaded(&last, tri, at, start);
        }
        for (c, (&v, &m)) in tri.iter().zip(&miss).enumerate() {
            last[v as usize] = at + c as u32 + 1;
            if m {
                invocations += 1;
                misses += 1;
                on_miss(3 * t + c);
            }
        }
        indices += 3;
    }
    batches += u64::from(indices > 0);
    CacheStats { triangles: triangles.len(), vertices: 0, misses, batches }
}

/// AMD's windows: a 15-entry LRU, most recent first, emptied every 128 triangles.
fn amd(triangles: &[[u32; 3]], _vertex_count: usize, mut on_miss: impl FnMut(usize)) -> CacheStats {
    let (mut misses, mut waves) = (0u64, 0u64);
    let mut lru: Vec<u32> = Vec::with_capacity(AMD_LRU + 1);
    for (w, window) in triangles.chunks(AMD_WINDOW_TRIANGLES).enumerate() {
        lru.clear();
        let mut shaded = 0u64;
        for (i, tri) in window.iter().enumerate() {
            for (c, &v) in tri.iter().enumerate() {
                match lru.iter().position(|&u| u == v) {
                    Some(p) => lru[..=p].rotate_right(1),
                    None => {
                        lru.insert(0, v);
                        lru.truncate(AMD_LRU);
                        shaded += 1;
                        on_miss(3 * (w * AMD_WINDOW_TRIANGLES + i) + c);
                    }
                }
            }
        }
        misses += shaded;
        waves += shaded.div_ceil(AMD_WAVE);
    }
    CacheStats { triangles: triangles.len(), vertices: 0, misses, batches: waves }
}
