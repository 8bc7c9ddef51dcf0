//! Overdraw ratio statistics over a view set.
//!
//! Per view, OVR = fragments passing the depth test ÷ pixels covered (Nehab, Barczak & Sander
//! 2006 §6; 1.0 = perfect front-to-back). Over a set we report the mean of the per-view ratios,
//! the worst (max) view, and the population variance, as Nehab 2006 Fig. 8 and §6 do. Views from
//! which nothing is visible (a flat mesh seen edge-on or from behind) have no ratio; they are
//! left out of the statistics and counted in `empty_views`, never silently read as 1.0. The
//! ratio of sums (Tootle's "mean") is also given, since papers differ on which they report.

use crate::raster::ViewCounts;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverdrawSummary {
    /// Views with a ratio (covered > 0).
    pub views: usize,
    pub empty_views: usize,
    pub mean: f64,
    pub max: f64,
    pub min: f64,
    pub variance: f64,
    /// Σ passed ÷ Σ covered over all views.
    pub ratio_of_sums: f64,
}

impl OverdrawSummary {
    /// Summarises per-view counts; `None` if no view sees anything.
    pub fn of(counts: &[ViewCounts]) -> Option<OverdrawSummary> {
        let ratios: Vec<f64> = counts.iter().filter_map(ViewCounts::ovr).collect();
        if ratios.is_empty() {
            return None;
        }
        let n = ratios.len() as f64;
        let mean = ratios.iter().sum::<f64>() / n;
        let variance = ratios.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / n;
        let (passed, covered) = counts.iter().fold((0, 0), |(p, c), v| (p + v.passed, c + v.covered));
        Some(OverdrawSummary {
            views: ratios.len(),
            empty_views: counts.len() - ratios.len(),
            mean,
            max: ratios.iter().copied().fold(f64::MIN, f64::max),
            min: ratios.iter().copied().fold(f64::MAX, f64::min),
            variance,
            ratio_of_sums: passed as f64 / covered as f64,
        })
    }
}
