//! The pen layers of a drawing as its SVG holds them: in plotting order
//! (`--layer-order`: the lightest ink first by default), each pen's layer
//! split into sub-layers for refills (`--refill-mm`).

use super::{Job, LayerOrder, Stipple};
use crate::colour::luminance;
use crate::stipple::{Dot, Stroke, svg};

/// One layer of the SVG: a pen's dots, or a part of them.
#[derive(Clone, Debug, PartialEq)]
pub struct PenLayer {
    /// The label: the pen's name; a part's is "L name k/n", L its layer's
    /// position in the file (vpype and plotter tools number layers by the
    /// label's first digits: each part gets its own, in plotting order).
    pub name: String,
    /// The pen's ink.
    pub ink: [u8; 3],
    /// The pen's own width in mm, when it has one.
    pub pen_mm: Option<f64>,
    /// How much the ink covers what lies below it, on the job's paper
    /// ([`crate::colour::Pen::opacity_on`]; one ink's, [`Job::ink_opacity`]).
    pub opacity: f64,
    /// The dots, in drawing order.
    pub dots: Vec<Dot>,
    /// The strokes, in drawing order (a line drawing's line, or its part).
    pub strokes: Vec<Stroke>,
    /// The pen-down length in mm of these dots' and strokes' paths (with a
    /// pen).
    pub pen_down_mm: f64,
}

impl Job {
    /// The pens of inks `inks` in plotting order ([`LayerOrder`]): the
    /// lightest first, or as given.
    #[must_use]
    pub fn plot_order(&self, inks: &[[u8; 3]]) -> Vec<usize> {
        let mut order: Vec<usize> = (0..inks.len()).collect();
        if self.layer_order == LayerOrder::LightFirst {
            // Stable: pens of equal lightness keep their order.
            order.sort_by(|&a, &b| luminance(inks[b]).total_cmp(&luminance(inks[a])));
        }
        order
    }

    /// The render model of `pens` for this job: its tone convention, its
    /// paper and its plotting order.
    #[must_use]
    pub fn model_of(&self, pens: &crate::colour::PenSet) -> crate::colour::RenderModel {
        let linear = self.importance.tones == crate::importance::Tones::Linear;
        let inks: Vec<[u8; 3]> = pens.pens().iter().map(|p| p.colour).collect();
        crate::colour::RenderModel::on_paper(
            pens,
            linear,
            self.paper_rgb(),
            &self.plot_order(&inks),
        )
    }

    /// The drawing's pen layers as the SVG writes them: one per pen (one
    /// for a grey drawing), in [`LayerOrder`], each split into parts of at
    /// most `refill_mm` of pen-down length.
    pub fn layers(&self, drawing: &Stipple) -> crate::Result<Vec<PenLayer>> {
        self.layers_split(drawing, self.refill_mm)
    }

    /// [`Self::layers`], each pen's split at `refill_mm`, or whole.
    pub(crate) fn layers_split(
        &self,
        drawing: &Stipple,
        refill_mm: Option<f64>,
    ) -> crate::Result<Vec<PenLayer>> {
        let dots = self.pen_dots(drawing);
        let paper = self.paper_rgb();
        let pens: Vec<(String, [u8; 3], Option<f64>, f64)> = match &drawing.pens {
            Some(set) => set
                .pens()
                .iter()
                .map(|p| (p.name.clone(), p.colour, p.width_mm, p.opacity_on(paper)))
                .collect(),
            None => vec![(
                self.one_pen().map_or_else(
                    || crate::colour::pens::name_of(self.ink_rgb()),
                    |p| p.name.clone(),
                ),
                self.ink_rgb(),
                None,
                self.ink_opacity(),
            )],
        };
        let inks: Vec<[u8; 3]> = pens.iter().map(|p| p.1).collect();
        let order = self.plot_order(&inks);
        let scale = self.mm_per_px(drawing.domain)?;
        let mut layers = Vec::new();
        for k in order {
            let (name, ink, own, opacity) = &pens[k];
            let pen = own.or(self.pen_width());
            let length = |d: &Dot| match (scale, pen) {
                (Some(mm), Some(pen)) => path_length(&svg::pen_path(
                    0.0,
                    0.0,
                    f64::from(d.radius) * mm,
                    pen,
                    self.dot_path,
                )),
                _ => 0.0,
            };
            let parts: Vec<(Vec<Dot>, Vec<Stroke>, f64)> = match drawing.strokes.get(k) {
                Some(stroke) if drawing.pens.is_some() || k == 0 => {
                    split_stroke(stroke, refill_mm.zip(scale).map(|(l, mm)| l / mm))
                        .into_iter()
                        .map(|(s, px)| (Vec::new(), vec![s], px * scale.unwrap_or(0.0)))
                        .collect()
                }
                _ => split(&dots[k], refill_mm, length)
                    .into_iter()
                    .map(|(d, l)| (d, Vec::new(), l))
                    .collect(),
            };
            let n = parts.len();
            for (i, (part, strokes, pen_down_mm)) in parts.into_iter().enumerate() {
                layers.push(PenLayer {
                    name: if n > 1 {
                        format!("{} {name} {}/{n}", layers.len() + 1, i + 1)
                    } else {
                        name.clone()
                    },
                    ink: *ink,
                    pen_mm: *own,
                    opacity: *opacity,
                    dots: part,
                    strokes,
                    pen_down_mm,
                });
            }
        }
        Ok(layers)
    }

    /// Where `drawing`'s dots lie on its page, when the page has a size in
    /// mm (`width_mm` or `paper`): x mm = `offset.0 + scale × x px`, and
    /// the same for y (the SVG's own frame).
    pub fn page_transform(&self, domain: (u32, u32)) -> crate::Result<Option<PageTransform>> {
        Ok(self
            .svg_options(domain)?
            .mm_frame()
            .map(|(scale, offset)| PageTransform { scale, offset }))
    }

    /// The pen paths of `drawing` as the plotter draws them, layer by
    /// layer in plotting order ([`Self::layers`]): each dot's polyline in
    /// mm on the page. Err without a pen and a page size in mm.
    pub fn pen_paths(&self, drawing: &Stipple) -> crate::Result<Vec<LayerPaths>> {
        let opts = self.svg_options(drawing.domain)?;
        let (Some(default_pen), Some(page)) =
            (self.pen_width(), self.page_transform(drawing.domain)?)
        else {
            return Err(crate::stipple::Error::InvalidParameter(
                "pen paths need a pen and a page: give pen_mm, and paper or width_mm".into(),
            )
            .into());
        };
        Ok(self
            .layers(drawing)?
            .into_iter()
            .map(|l| {
                let pen = l.pen_mm.unwrap_or(default_pen);
                let strokes = l.strokes.iter().map(|s| {
                    // Curves within a hundredth of a mm, as the file holds
                    // them.
                    s.path(0.01 / page.scale)
                        .into_iter()
                        .map(|[x, y]| page.mm([x as f32, y as f32]))
                        .collect()
                });
                let paths = l
                    .dots
                    .iter()
                    .map(|d| {
                        let [x, y] = page.mm([d.x, d.y]);
                        svg::pen_path(x, y, f64::from(d.radius) * page.scale, pen, opts.dot_path)
                            .into_iter()
                            .map(|(x, y)| [x, y])
                            .collect()
                    })
                    .chain(strokes)
                    .collect();
                LayerPaths {
                    name: l.name,
                    ink: l.ink,
                    pen_mm: pen,
                    paths,
                }
            })
            .collect())
    }
}

/// Domain pixels to mm on the page ([`Job::page_transform`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PageTransform {
    /// mm per domain pixel.
    pub scale: f64,
    /// Where the domain's origin lies on the page, in mm.
    pub offset: (f64, f64),
}

impl PageTransform {
    /// A point of the domain (px) on the page (mm).
    #[must_use]
    pub fn mm(&self, [x, y]: [f32; 2]) -> [f64; 2] {
        [
            self.offset.0 + f64::from(x) * self.scale,
            self.offset.1 + f64::from(y) * self.scale,
        ]
    }
}

/// One layer's pen paths ([`Job::pen_paths`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LayerPaths {
    /// The layer's label, as the SVG's.
    pub name: String,
    /// The pen's ink.
    pub ink: [u8; 3],
    /// The pen's width in mm.
    pub pen_mm: f64,
    /// One polyline per dot, in drawing order, in mm on the page.
    pub paths: Vec<Vec<[f64; 2]>>,
}

/// The length of a polyline.
fn path_length(points: &[(f64, f64)]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum()
}

/// `stroke` cut into consecutive parts of at most `limit` px of length
/// each (a segment longer than the limit alone in its part), each part
/// starting where the one before ended; one part without a limit. Each
/// part with its length in px.
fn split_stroke(stroke: &Stroke, limit: Option<f64>) -> Vec<(Stroke, f64)> {
    let mut parts: Vec<(Stroke, f64)> = Vec::new();
    let mut now = Stroke {
        points: Vec::new(),
        ..stroke.clone()
    };
    let mut length = 0.0;
    for p in &stroke.points {
        let step = now.points.last().map_or(0.0, |q: &[f32; 2]| {
            f64::from(p[0] - q[0]).hypot(f64::from(p[1] - q[1]))
        });
        if let (Some(limit), Some(&last)) = (limit, now.points.last())
            && now.points.len() > 1
            && length + step > limit
        {
            let done = std::mem::replace(
                &mut now,
                Stroke {
                    points: vec![last],
                    ..stroke.clone()
                },
            );
            parts.push((done, length));
            length = 0.0;
        }
        now.points.push(*p);
        length += step;
    }
    parts.push((now, length));
    parts
}

/// `dots` in consecutive parts of at most `limit` of `length` each (a dot
/// longer than the limit alone in its part); one part without a limit.
fn split(dots: &[Dot], limit: Option<f64>, length: impl Fn(&Dot) -> f64) -> Vec<(Vec<Dot>, f64)> {
    let mut parts = vec![(Vec::new(), 0.0)];
    for d in dots {
        let l = length(d);
        let last = parts.last_mut().expect("one part at least");
        if let Some(limit) = limit
            && !last.0.is_empty()
            && last.1 + l > limit
        {
            parts.push((vec![*d], l));
        } else {
            last.0.push(*d);
            last.1 += l;
        }
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stroke cut for refills: parts within the limit, each starting
    /// where the last ended, together the whole stroke.
    #[test]
    fn a_stroke_is_cut_into_parts_that_join() {
        let stroke = Stroke {
            points: (0..21).map(|i| [i as f32, 0.0]).collect(),
            width: 1.0,
            smooth: false,
        };
        let parts = split_stroke(&stroke, Some(6.5));
        assert_eq!(
            parts.iter().map(|p| p.1).collect::<Vec<_>>(),
            [6.0, 6.0, 6.0, 2.0]
        );
        for w in parts.windows(2) {
            assert_eq!(w[0].0.points.last(), w[1].0.points.first());
        }
        let joined: usize = parts.iter().map(|p| p.0.points.len()).sum();
        assert_eq!(joined - (parts.len() - 1), stroke.points.len());
        assert_eq!(split_stroke(&stroke, None).len(), 1);
    }

    #[test]
    fn lighter_inks_sort_first_and_parts_keep_under_the_limit() {
        let [y, c, m, k] = [[255, 255, 0], [0, 255, 255], [255, 0, 255], [0, 0, 0]].map(luminance);
        assert!(y > c && c > m && m > k);
        let dots: Vec<Dot> = (0..10)
            .map(|i| Dot {
                x: i as f32,
                y: 0.0,
                radius: 1.0,
            })
            .collect();
        let parts = split(&dots, Some(3.5), |_| 1.0);
        assert_eq!(
            parts.iter().map(|p| p.0.len()).collect::<Vec<_>>(),
            [3, 3, 3, 1]
        );
        assert!(parts.iter().all(|p| p.1 <= 3.5));
        let joined: Vec<Dot> = parts.into_iter().flat_map(|p| p.0).collect();
        assert_eq!(joined, dots);
        assert_eq!(split(&dots, None, |_| 1.0).len(), 1);
        // A dot longer than the limit is a part of its own.
        assert_eq!(split(&dots[..2], Some(0.5), |_| 1.0).len(), 2);
    }
}
