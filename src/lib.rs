//! triorder: triangle-order optimization for meshes.
//!
//! The pipeline (see README.md): a mesh is loaded and validated ([`mesh`]), its topology derived
//! once ([`topology`]), ordered by a method from the registry ([`order`]), measured by the vertex
//! cache simulators and the overdraw counter ([`metrics`], [`raster`]), and swept by experiment
//! specs into CSV and SVG ([`experiment`], [`figure`]).

pub mod error;
pub mod mesh;

pub use error::{Error, Result};
