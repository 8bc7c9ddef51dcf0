//! The measurements: vertex-cache simulation ([`cache`]), overdraw statistics over view sets
//! ([`overdraw`]) and linear-arrangement costs of an order ([`arrangement`]).

pub mod arrangement;
pub mod cache;
pub mod overdraw;

pub use cache::{CacheModel, CacheStats, Corner};
pub use overdraw::OverdrawSummary;
