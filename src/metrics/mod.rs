//! The measurements: vertex-cache simulation ([`cache`]) and overdraw statistics over view sets
//! ([`overdraw`]).

pub mod cache;
pub mod overdraw;

pub use cache::{CacheModel, CacheStats, Corner};
pub use overdraw::OverdrawSummary;
