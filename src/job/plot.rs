//! A drawing's plot statistics as the job writes its pen SVG
//! ([`crate::stipple::plot`]: the plotter's motion model of paths, lifts
//! and time).

use super::{Job, Stipple};
use crate::stipple::plot::{PenPlot, Plotter, plot_paths_of};
use crate::stipple::{Error, svg};

impl Job {
    /// The plot of `drawing` as this job writes its pen SVG, pen by pen
    /// (needs `width_mm` and `pen_mm`), timed by `plotter`'s motion model.
    pub fn plot_stats(&self, drawing: &Stipple, plotter: &Plotter) -> crate::Result<Vec<PenPlot>> {
        plotter.check()?;
        let (Some(scale), Some(pen_mm)) = (self.mm_per_px(drawing.domain)?, self.pen_width())
        else {
            return Err(Error::InvalidParameter(
                "plot statistics need «pen_mm» and «width_mm» or «paper»: a plotter draws pen paths"
                    .into(),
            )
            .into());
        };
        // On paper, home is the sheet's corner.
        let origin = self
            .placement(drawing.domain)?
            .map_or((0.0, 0.0), |p| p.origin_mm);
        // The sheet, where the plotter's home is.
        let opts = self.svg_options(drawing.domain)?;
        let sheet_mm = opts.sheet_mm.or(opts.size_mm);
        // Pen by pen, in plotting order.
        let layers = self.layers_split(drawing, None)?;
        Ok(layers
            .iter()
            .map(|layer| {
                let pen = layer.pen_mm.unwrap_or(pen_mm);
                // The strokes as the file holds them: curves within a
                // hundredth of a mm, on the plotter's grid.
                let strokes: Vec<Vec<(f64, f64)>> = layer
                    .strokes
                    .iter()
                    .map(|s| {
                        let mut buf: Vec<(f64, f64)> = s
                            .path(0.01 / scale)
                            .into_iter()
                            .map(|[x, y]| (origin.0 + x * scale, origin.1 + y * scale))
                            .collect();
                        svg::on_grid(&mut buf);
                        buf
                    })
                    .collect();
                let n = layer.dots.len();
                let path = |i: usize, buf: &mut Vec<(f64, f64)>| {
                    if let Some(s) = i.checked_sub(n).and_then(|k| strokes.get(k)) {
                        buf.extend_from_slice(s);
                        return;
                    }
                    let d = &layer.dots[i];
                    svg::pen_path_into(
                        buf,
                        origin.0 + f64::from(d.x) * scale,
                        origin.1 + f64::from(d.y) * scale,
                        f64::from(d.radius) * scale,
                        pen,
                        self.dot_path,
                    );
                    // As the file holds it, on the plotter's grid.
                    svg::on_grid(buf);
                };
                plot_paths_of(&layer.name, n, n + strokes.len(), &path, plotter, sheet_mm)
            })
            .collect())
    }
}
