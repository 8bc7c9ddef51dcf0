//! triorder: triangle-order optimization for meshes.
//!
//! The pipeline (see README.md): a mesh is loaded and validated ([`mesh`]), its topology derived
//! once ([`topology`]), ordered by a method from the registry ([`order`]), measured by the vertex
//! cache simulators and the overdraw counter ([`metrics`], [`raster`]), and swept by experiment
//! specs into CSV and SVG ([`experiment`], [`figure`]).

pub mod atomic;
pub mod bench;
pub mod error;
pub mod eval;
pub mod experiment;
pub mod figure;
pub mod gpu;
pub mod mesh;

pub use error::{Error, Result};
pub mod metrics;
pub mod order;
pub mod peer;
pub mod raster;
pub mod topology;
