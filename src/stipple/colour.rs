//! Colour drawings (`--pens`): the photo separated into the pens' inks
//! under the render model ([`crate::colour::separation`]), one importance
//! map per pen, all pens sampled together in one multi-class run
//! ([`crate::sampler::classes`]) so that they interleave, each pen's dots
//! calibrated to its own ink, and the outputs: one Inkscape layer per pen,
//! the composite PNG, a `pen` column in CSV and JSON.

use std::path::Path;

use super::job::{Format, Job, Order, Stipple};
use super::{Dot, svg, tsp};
use crate::colour::{RenderModel, Separation};
use crate::importance::ink::{self, K_MAX};
use crate::importance::{Classes, ColourMap, Prepared, RadiusRange, Tones};
use crate::sampler::{Params, Point, SampleSet};

impl Job {
    /// The render model of this job's pens, under its tone convention.
    #[must_use]
    pub fn render_model(&self) -> Option<RenderModel> {
        let linear = self.importance.tones == Tones::Linear;
        self.pens.as_ref().map(|p| RenderModel::new(p, linear))
    }

    /// Draws a colour `picture` with the job's pens ([`Job::colour`]), with
    /// `sample` running the sampler.
    pub fn run_colour(
        &self,
        picture: &ColourMap,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
    ) -> crate::Result<Stipple> {
        let t0 = std::time::Instant::now();
        self.check()?;
        let (Some(pens), Some(model)) = (self.pens.clone(), self.render_model()) else {
            return Err(
                super::Error::InvalidParameter("a colour drawing needs --pens".into()).into(),
            );
        };
        let (points, count_target) = self.count();
        let (width, height) = self.domain_for((picture.width(), picture.height()), points);
        let picture = picture.resized(width, height)?;
        let separation = Separation::new(model, K_MAX);
        let mapping = self.dot_mode().mapping(self.dot_ratio);
        let range = self.importance.radius_range(count_target)?;
        let range = self.dot_range(range, width)?;
        let prepared: Vec<Prepared> = picture
            .separate(&separation)
            .into_iter()
            .map(|map| Prepared {
                map,
                mapping,
                range,
                cutoff: None,
            })
            .collect();
        let t_load = t0.elapsed().as_secs_f64();
        let base = self
            .sampler
            .apply(Params::new(width, height).with_policy(self.policy));
        let fitted = Classes { maps: &prepared }.sample(&base, points, sample)?;
        let (set, range) = (fitted.set, fitted.range);
        let t_sample = t0.elapsed().as_secs_f64() - t_load;
        // Pen by pen, in the pens' order; each pen's own tour with --order tsp.
        let mut by_pen: Vec<Vec<Point>> = vec![Vec::new(); pens.len()];
        for p in &set.points {
            by_pen[p.class as usize].push(*p);
        }
        let mut tour: Option<tsp::Tour> = None;
        let mut ordered = Vec::with_capacity(set.points.len());
        for pen_points in by_pen {
            if self.order == Order::Tsp {
                let xy: Vec<[f64; 2]> = pen_points
                    .iter()
                    .map(|p| [f64::from(p.x), f64::from(p.y)])
                    .collect();
                let t = tsp::plan(&xy, tsp::TspOptions::default());
                let base = ordered.len();
                ordered.extend(t.order.iter().map(|&i| pen_points[i]));
                let all = tour.get_or_insert_with(|| tsp::Tour {
                    order: Vec::new(),
                    nearest_neighbour_length: 0.0,
                    length: 0.0,
                    moves: 0,
                });
                all.order.extend(t.order.iter().map(|&i| base + i));
                all.nearest_neighbour_length += t.nearest_neighbour_length;
                all.length += t.length;
                all.moves += t.moves;
            } else {
                ordered.extend(pen_points);
            }
        }
        let density = Density::new(&ordered, &prepared, range, (width, height));
        let calibrated = ordered
            .iter()
            .map(|p| {
                let map = &prepared[p.class as usize];
                let ink = f64::from(1.0 - map.map.value_at(p.x, p.y));
                map.dot_radius(p, range) * density.dot_factor(p, ink)
            })
            .collect();
        let mut drawing = Stipple {
            dots: Vec::new(),
            points: ordered,
            calibrated,
            set,
            domain: (width, height),
            range,
            runs: fitted.runs,
            short_of: fitted.short_of,
            tour,
            seconds: (t_load, t_sample, 0.0),
            pens: Some(pens),
        };
        drawing.dots = self.dots(&drawing);
        Ok(drawing)
    }

    /// Writes a colour drawing (its `pens` set) in `format` to `path`: one
    /// layer per pen in SVG, the composite in PNG, a pen column in CSV and
    /// JSON.
    pub(crate) fn write_colour(
        &self,
        drawing: &Stipple,
        format: Format,
        path: &Path,
    ) -> crate::Result<()> {
        let Some(pens) = &drawing.pens else {
            return Err(super::Error::InvalidParameter("not a colour drawing".into()).into());
        };
        let dots = self.dots(drawing);
        let layers: Vec<Vec<Dot>> = (0..pens.len() as u32)
            .map(|k| {
                drawing
                    .points
                    .iter()
                    .zip(&dots)
                    .filter(|(p, _)| p.class == k)
                    .map(|(_, d)| *d)
                    .collect()
            })
            .collect();
        match format {
            Format::Svg => {
                let domain = drawing.domain;
                let mut opts = match self.width_mm {
                    Some(mm) => svg::SvgOptions::with_width_mm(domain, mm)?,
                    None => svg::SvgOptions::new(domain),
                };
                if let Some(pen) = self.pen_mm {
                    opts = opts.with_pen_mm(pen)?;
                }
                let svg_layers: Vec<svg::Layer<'_>> = pens
                    .pens()
                    .iter()
                    .zip(&layers)
                    .map(|(p, d)| svg::Layer {
                        name: &p.name,
                        ink: p.colour,
                        pen_mm: p.width_mm,
                        dots: d,
                    })
                    .collect();
                crate::io::write_atomic(path, |w| Ok(svg::write_layers(w, &svg_layers, &opts)?))?;
            }
            Format::Png => {
                let papers = layers
                    .iter()
                    .map(|d| super::raster::render(d, drawing.domain, self.scale))
                    .collect::<Result<Vec<_>, _>>()?;
                let model = RenderModel::new(pens, false);
                let img = super::raster::composite(&papers, &model)?;
                crate::io::write_atomic(path, |w| {
                    Ok(super::raster::write_png_rgb(w, &img, dots.len())?)
                })?;
            }
            Format::Csv | Format::Json => {
                let set = drawing.set.clone().with_points(drawing.points.clone());
                crate::io::write_points_pens(path, &set, self, pens)?;
            }
        }
        Ok(())
    }
}

/// Each pen's dots as sampled against the count a maximal set of that pen
/// alone would have: the other pens' cross spacing thins every pen out, so
/// its dots are enlarged until they put down the ink they were calibrated
/// for ([`crate::importance::ink`]), at the spacing they actually have.
///
/// Counts are taken in a square window of half-side [`WINDOW`] × the dot's
/// sample radius (about a hundred neighbours), from summed-area tables of
/// the pens' points and of their RSA densities at the sampled radii.
struct Density {
    width: usize,
    height: usize,
    /// Per pen: summed-area table of point counts, (w+1)×(h+1).
    counts: Vec<Vec<u32>>,
    /// Per pen: summed-area table of the expected point density.
    expected: Vec<Vec<f64>>,
}

/// The counting window's half-side in sample radii.
const WINDOW: f32 = 3.0;

impl Density {
    fn new(points: &[Point], maps: &[Prepared], range: RadiusRange, (w, h): (u32, u32)) -> Self {
        let (w, h) = (w as usize, h as usize);
        let sat = |f: &dyn Fn(usize) -> f64| -> Vec<f64> {
            let mut t = vec![0f64; (w + 1) * (h + 1)];
            for y in 0..h {
                let mut row = 0.0;
                for x in 0..w {
                    row += f(y * w + x);
                    t[(y + 1) * (w + 1) + x + 1] = t[y * (w + 1) + x + 1] + row;
                }
            }
            t
        };
        let expected = maps
            .iter()
            .map(|m| {
                let radii = m.map.radii(m.mapping, range);
                sat(&|i| {
                    let r = f64::from(radii[i]);
                    crate::sampler::RSA_DENSITY / (std::f64::consts::PI * r * r / 4.0)
                })
            })
            .collect();
        let counts = (0..maps.len() as u32)
            .map(|c| {
                let mut n = vec![0u32; w * h];
                for p in points.iter().filter(|p| p.class == c) {
                    let (x, y) = ((p.x as usize).min(w - 1), (p.y as usize).min(h - 1));
                    n[y * w + x] += 1;
                }
                let mut t = vec![0u32; (w + 1) * (h + 1)];
                for y in 0..h {
                    let mut row = 0;
                    for x in 0..w {
                        row += n[y * w + x];
                        t[(y + 1) * (w + 1) + x + 1] = t[y * (w + 1) + x + 1] + row;
                    }
                }
                t
            })
            .collect();
        Self {
            width: w,
            height: h,
            counts,
            expected,
        }
    }

    /// The factor on the calibrated dot radius of point `p` whose pen puts
    /// down `ink` there.
    fn dot_factor(&self, p: &Point, ink: f64) -> f32 {
        let half = WINDOW * p.radius;
        let x0 = (p.x - half).max(0.0) as usize;
        let y0 = (p.y - half).max(0.0) as usize;
        let x1 = ((p.x + half).max(0.0) as usize + 1).min(self.width);
        let y1 = ((p.y + half).max(0.0) as usize + 1).min(self.height);
        let stride = self.width + 1;
        let c = p.class as usize;
        let n = self.counts[c][y1 * stride + x1] + self.counts[c][y0 * stride + x0]
            - self.counts[c][y0 * stride + x1]
            - self.counts[c][y1 * stride + x0];
        let e = self.expected[c][y1 * stride + x1] + self.expected[c][y0 * stride + x0]
            - self.expected[c][y0 * stride + x1]
            - self.expected[c][y1 * stride + x0];
        if n == 0 || e <= 0.0 {
            return 1.0;
        }
        let q = (f64::from(n) / e).clamp(0.1, 4.0);
        let r = f64::from(p.radius);
        let r_eff = r / q.sqrt();
        let k = ink.clamp(0.0, K_MAX);
        let want = ink::dot_ratio(k, r_eff) * r_eff;
        let had = ink::dot_ratio(k, r) * r;
        if had > 0.0 { (want / had) as f32 } else { 1.0 }
    }
}
