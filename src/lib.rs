//! triorder: triangle-order optimization for meshes.
//!
//! The pipeline (see README.md): a mesh source is opened into frames of one connectivity
//! ([`mesh`]), ordered by a method from the registry ([`order`]), measured by the vertex-cache
//! simulators and the fragment counters ([`measure`], over [`raster`] and [`gpu`]), and swept by
//! experiment specs into CSV and SVG ([`experiment`], [`figure`]).

pub mod atomic;
pub mod error;
pub mod experiment;
pub mod figure;
pub mod gpu;
pub mod measure;
pub mod mesh;
pub mod order;
pub mod raster;
pub mod reproduce;
pub mod results;

pub use error::{Error, Result};
