//! A drawing's plot statistics as the job writes its pen SVG
//! ([`crate::stipple::plot`]: the plotter's model of paths, lifts and time).

use super::{Job, Stipple};
use crate::stipple::plot::{PenPlot, PlotSpeeds, plot_paths};
use crate::stipple::{Error, svg};

impl Job {
    /// The plot of `drawing` as this job writes its pen SVG, pen by pen
    /// (needs `width_mm` and `pen_mm`).
    pub fn plot_stats(&self, drawing: &Stipple, speeds: PlotSpeeds) -> crate::Result<Vec<PenPlot>> {
        speeds.check()?;
        let (Some(scale), Some(pen_mm)) = (self.mm_per_px(drawing.domain)?, self.pen_width())
        else {
            return Err(Error::InvalidParameter(
                "plot statistics need --pen-mm and --width-mm or --paper: a plotter draws pen paths"
                    .into(),
            )
            .into());
        };
        // On paper, home is the sheet's corner.
        let origin = self
            .placement(drawing.domain)?
            .map_or((0.0, 0.0), |p| p.origin_mm);
        // Pen by pen, in plotting order.
        let layers = self.layers_split(drawing, None)?;
        Ok(layers
            .iter()
            .map(|layer| {
                let pen = layer.pen_mm.unwrap_or(pen_mm);
                let paths: Vec<Vec<(f64, f64)>> = layer
                    .dots
                    .iter()
                    .map(|d| {
                        svg::pen_path(
                            origin.0 + f64::from(d.x) * scale,
                            origin.1 + f64::from(d.y) * scale,
                            f64::from(d.radius) * scale,
                            pen,
                            self.dot_path,
                        )
                    })
                    .collect();
                plot_paths(&layer.name, layer.dots.len(), &paths, speeds)
            })
            .collect())
    }
}
