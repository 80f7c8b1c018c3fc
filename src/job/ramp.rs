//! The calibration's check: a grey ramp drawn by a job, plotted with a
//! pen's dot gain ([`crate::stipple::calibrate::simulate::plotted`]), and
//! compared band by band with the ramp.

use super::Job;
use crate::colour::decode;
use crate::stipple::calibrate::simulate::plotted;

/// How a plotted grey ramp compares with the ramp.
#[derive(Clone, Debug, PartialEq)]
pub struct RampError {
    /// The largest error of a band's grey over the 5–95% bands.
    pub worst: f64,
    /// The mean absolute error over those bands.
    pub mean: f64,
    /// Each band's (target grey, plotted grey).
    pub bands: Vec<(f64, f64)>,
}

/// Stipples a ramp of display grey, black (left) to white (right), 1536 ×
/// 384 px, on a domain of the same size, with `job` (sampled on the CPU),
/// plots it with a pen of dot gain `gain` ([`plotted`]), and compares each
/// band of 1/32 of the width with the ramp: the band's grey is 1 − its
/// mean ink (a blur across the band), rendered at four times the size.
pub fn ramp_error(job: &Job, gain: f64) -> crate::Result<RampError> {
    let mut job = job.clone();
    job.width = Some(1536);
    job.height = Some(384);
    ramp_error_sized(&job, gain, (1536, 384))
}

/// [`ramp_error`] of a ramp picture of `size` px, on the job's domain (the
/// default domain for the job's count unless it sets one), rendered at
/// four times the picture's size.
pub fn ramp_error_sized(job: &Job, gain: f64, size: (u32, u32)) -> crate::Result<RampError> {
    let (w, h) = size;
    // The map holds linear light; the ramp is even in display grey.
    let values = (0..w * h)
        .map(|i| decode((f64::from(i % w) + 0.5) / f64::from(w)) as f32)
        .collect();
    let map = crate::importance::ImportanceMap::from_values(w, h, values)?;
    let drawing = job.run_map(&map, |p| Ok(p.generate()?), |_| true)?;
    let dots = plotted(&job.dots(&drawing), gain);
    // At four times the picture's size: dots a pixel or two wide are
    // measured by their true coverage.
    const K: u32 = 4;
    let scale = K as f32 * w as f32 / drawing.domain.0 as f32;
    let img = crate::stipple::raster::render_exact(&dots, drawing.domain, scale)?;
    let (iw, ih) = (img.width(), img.height());
    let bands: Vec<(f64, f64)> = (0..32)
        .map(|b| {
            let (x0, x1) = (b * w / 32, (b + 1) * w / 32);
            let target = f64::from(x0 + x1) / 2.0 / f64::from(w);
            // The band, less a margin of 1/24 of the height top and bottom.
            let (bx0, bx1) = (x0 * iw / w, x1 * iw / w);
            let grey =
                1.0 - crate::stipple::raster::mean_ink(&img, bx0, ih / 24, bx1, ih - ih / 24);
            (target, grey)
        })
        .collect();
    let errs: Vec<f64> = bands
        .iter()
        .filter(|(t, _)| (0.05..=0.95).contains(t))
        .map(|(t, g)| (g - t).abs())
        .collect();
    Ok(RampError {
        worst: errs.iter().copied().fold(0.0, f64::max),
        mean: errs.iter().sum::<f64>() / errs.len().max(1) as f64,
        bands,
    })
}
