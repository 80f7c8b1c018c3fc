//! Posters: a drawing bigger than the plotter's sheet (`--poster WxH`),
//! plotted sheet by sheet. The drawing is made once, whole, at the
//! poster's size ([`Job::poster_whole`]: the job of `--width-mm` the
//! picture's frame on the poster); then [`Job::poster`] lays a grid of
//! `--paper` sheets over it ([`SheetGrid`]), gives each dot, whole, to the
//! one sheet that holds it inside its margin, and orders each sheet for
//! its own plot. A sheet's job ([`Sheet::job`]) writes it as any job
//! writes a drawing, on the sheet's own page: the dots where they lie on
//! the poster, moved by the sheet's corner.
//!
//! Neighbouring sheets' printable areas overlap by
//! [`SheetGrid::overlap_mm`]: the seam runs down the middle of the
//! overlap, and a dot belongs to the sheet on its side, so that it never
//! crosses its sheet's margin. Registration crosses lie on the seams,
//! where the sheets' corners meet, and each is drawn by every sheet that
//! holds it: on a light table the crosses of two sheets cover each other.
//! Those on the grid's edge lie outside the picture.

use std::path::Path;

use serde::Serialize;

use super::{Job, Order, Picture, Stipple, Style};
use crate::sampler::{Point, SampleSet};
use crate::stipple::paper::Placement;
use crate::stipple::plot::Plotter;
use crate::stipple::{Dot, Error, Stroke, tsp};

/// A registration cross's arms, end to end, mm.
pub const MARK_MM: f64 = 5.0;
/// The least room between the picture and a cross on the grid's edge, mm.
pub const MARK_GAP_MM: f64 = 2.0;
/// The least overlap of neighbouring sheets' printable areas, mm: a cross
/// and half a millimetre either side of it.
pub const MIN_OVERLAP_MM: f64 = MARK_MM + 1.0;
/// The most sheets a poster is cut into.
pub const MAX_SHEETS: usize = 400;
/// The label of a sheet's layer of crosses: plotted first (AxiDraw's
/// layer 0), in vpype's layer 1 with the first pen.
pub const REGISTRATION_LAYER: &str = "0 registration";
/// A cross's line width without a pen, mm.
const MARK_LINE_MM: f64 = 0.3;

/// The page of one sheet of a poster: where the drawing lies on it, and
/// its registration crosses' centres in the sheet's mm.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SheetPage {
    pub(crate) placement: Placement,
    pub(crate) marks: Vec<[f64; 2]>,
}

/// The grid of sheets over a poster, in the poster's mm (x right, y down,
/// from the poster's top-left corner).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct SheetGrid {
    /// The poster, mm.
    pub poster_mm: [f64; 2],
    /// The picture's frame on the poster: x, y, width, height.
    pub frame_mm: [f64; 4],
    /// A sheet, oriented, mm.
    pub sheet_mm: [f64; 2],
    /// The margin on every sheet, mm.
    pub margin_mm: f64,
    /// How far neighbouring sheets' printable areas overlap, mm.
    pub overlap_mm: f64,
    /// Rows of sheets.
    pub rows: usize,
    /// Columns of sheets.
    pub cols: usize,
    /// The top-left corner of the first sheet's printable area on the poster.
    pub origin_mm: [f64; 2],
    /// How far the dots reach from their centres (radius and half the
    /// pen), mm: the plan's estimate, or the drawing's own.
    pub reach_mm: f64,
}

/// The number of sheets of printable length `p` overlapping by `o` that
/// cover `need`.
fn sheets_for(need: f64, p: f64, o: f64) -> usize {
    if need <= p {
        1
    } else {
        ((need - o) / (p - o) - 1e-9).ceil().max(1.0) as usize
    }
}

impl SheetGrid {
    /// The grid of `sheet_mm` sheets with `margin_mm` margins over a
    /// picture framed at `frame_mm` on a `poster_mm` poster, whose dots
    /// reach at most `reach_mm` from their centres (radius and half the
    /// pen): the fewest sheets whose printable areas, overlapping by at
    /// least [`MIN_OVERLAP_MM`] and by the widest dot, cover every dot and,
    /// with more than one sheet, leave room for the crosses outside the
    /// picture. Err when a sheet's printable area cannot hold the
    /// overlap, or more than [`MAX_SHEETS`] sheets would be needed.
    pub fn new(
        poster_mm: [f64; 2],
        frame_mm: [f64; 4],
        sheet_mm: [f64; 2],
        margin_mm: f64,
        reach_mm: f64,
    ) -> crate::Result<Self> {
        let overlap = MIN_OVERLAP_MM.max((2.0 * reach_mm + 1.0).ceil());
        let p = [sheet_mm[0] - 2.0 * margin_mm, sheet_mm[1] - 2.0 * margin_mm];
        if p[0] <= overlap || p[1] <= overlap {
            return Err(Error::InvalidParameter(format!(
                "a {} × {} mm sheet with «margin={margin_mm}» mm leaves no room for the poster's {overlap} mm overlap: use a smaller margin or a bigger paper",
                sheet_mm[0], sheet_mm[1]
            ))
            .into());
        }
        let [_, _, fw, fh] = frame_mm;
        let cover = |extra: f64| {
            (
                sheets_for(fw + 2.0 * extra, p[0], overlap),
                sheets_for(fh + 2.0 * extra, p[1], overlap),
            )
        };
        let (mut cols, mut rows) = cover(reach_mm);
        if cols * rows > 1 {
            // Room for the crosses on the grid's edge, outside the picture.
            let marks = overlap / 2.0 + MARK_MM / 2.0 + MARK_GAP_MM;
            (cols, rows) = cover(reach_mm.max(marks));
        }
        if cols * rows > MAX_SHEETS {
            return Err(Error::InvalidParameter(format!(
                "a {} × {} mm poster takes {cols} × {rows} sheets of {} × {} mm, more than {MAX_SHEETS}: use a bigger paper or a smaller poster",
                poster_mm[0], poster_mm[1], sheet_mm[0], sheet_mm[1]
            ))
            .into());
        }
        let span = |n: usize, p: f64| n as f64 * p - (n as f64 - 1.0) * overlap;
        let origin_mm = [
            frame_mm[0] + fw / 2.0 - span(cols, p[0]) / 2.0,
            frame_mm[1] + fh / 2.0 - span(rows, p[1]) / 2.0,
        ];
        Ok(Self {
            poster_mm,
            frame_mm,
            sheet_mm,
            margin_mm,
            overlap_mm: overlap,
            rows,
            cols,
            origin_mm,
            reach_mm,
        })
    }

    /// A sheet's printable width and height, mm.
    fn printable(&self) -> [f64; 2] {
        [
            self.sheet_mm[0] - 2.0 * self.margin_mm,
            self.sheet_mm[1] - 2.0 * self.margin_mm,
        ]
    }

    /// The printable area of sheet (`row`, `col`) on the poster: x0, y0,
    /// x1, y1.
    #[must_use]
    pub fn printable_mm(&self, row: usize, col: usize) -> [f64; 4] {
        let p = self.printable();
        let x = self.origin_mm[0] + col as f64 * (p[0] - self.overlap_mm);
        let y = self.origin_mm[1] + row as f64 * (p[1] - self.overlap_mm);
        [x, y, x + p[0], y + p[1]]
    }

    /// Sheet (`row`, `col`)'s top-left corner on the poster.
    #[must_use]
    pub fn sheet_origin(&self, row: usize, col: usize) -> [f64; 2] {
        let [x, y, ..] = self.printable_mm(row, col);
        [x - self.margin_mm, y - self.margin_mm]
    }

    /// The seam between column `c` and `c + 1` (x) or row `c` and `c + 1`
    /// (y): the middle of their overlap.
    fn seam(&self, axis: usize, c: usize) -> f64 {
        let p = self.printable()[axis];
        self.origin_mm[axis] + (c as f64 + 1.0) * (p - self.overlap_mm) + self.overlap_mm / 2.0
    }

    /// The sheet (row, col) whose side of the seams holds poster point
    /// (`x`, `y`).
    #[must_use]
    pub fn cell(&self, x: f64, y: f64) -> (usize, usize) {
        let side =
            |v: f64, axis: usize, n: usize| (0..n - 1).filter(|&c| v >= self.seam(axis, c)).count();
        (side(y, 1, self.rows), side(x, 0, self.cols))
    }

    /// Every registration cross's centre on the poster: where the seams
    /// cross, and where they meet the grid's edge (outside the picture).
    #[must_use]
    pub fn marks(&self) -> Vec<[f64; 2]> {
        let o = self.overlap_mm;
        let ends = |axis: usize, n: usize| {
            let [a0, b0, ..] = self.printable_mm(0, 0);
            let [.., a1, b1] = self.printable_mm(self.rows - 1, self.cols - 1);
            let (lo, hi) = if axis == 0 { (a0, a1) } else { (b0, b1) };
            let mut at = vec![lo + o / 2.0];
            at.extend((0..n - 1).map(|c| self.seam(axis, c)));
            at.push(hi - o / 2.0);
            at
        };
        let (xs, ys) = (ends(0, self.cols), ends(1, self.rows));
        let mut marks = Vec::new();
        for (j, &y) in ys.iter().enumerate() {
            for (i, &x) in xs.iter().enumerate() {
                // On a seam: an inner x or an inner y.
                let on_x = i > 0 && i + 1 < xs.len();
                let on_y = j > 0 && j + 1 < ys.len();
                if on_x || on_y {
                    marks.push([x, y]);
                }
            }
        }
        marks
    }

    /// The crosses sheet (`row`, `col`) draws: those whole inside its
    /// printable area.
    #[must_use]
    pub fn sheet_marks(&self, row: usize, col: usize) -> Vec<[f64; 2]> {
        let [x0, y0, x1, y1] = self.printable_mm(row, col);
        let h = MARK_MM / 2.0 + 1e-6;
        self.marks()
            .into_iter()
            .filter(|&[x, y]| x - h >= x0 && x + h <= x1 && y - h >= y0 && y + h <= y1)
            .collect()
    }
}

/// What a poster's plan says: the grid, and the dots each sheet is
/// expected to hold (the picture's predicted share).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct PosterPlan {
    /// The grid.
    #[serde(flatten)]
    pub grid: SheetGrid,
    /// Sheets, row by row.
    pub sheets: usize,
    /// The dots (or a line's points) each sheet is expected to hold, row
    /// by row: the picture's predicted count in each sheet's side of the
    /// seams, scaled to the plan's count.
    pub sheet_dots: Vec<usize>,
}

/// One sheet of a poster: its place on the poster, the job that writes
/// it and its part of the drawing.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Sheet {
    /// Its row, from the top, from 0.
    pub row: usize,
    /// Its column, from the left, from 0.
    pub col: usize,
    /// Its top-left corner on the poster, mm: a point (u, v) on the sheet
    /// lies at (x + u, y + v) on the poster.
    pub origin_mm: [f64; 2],
    /// The job that writes this sheet (its page, margin and crosses).
    pub job: Job,
    /// Its dots (or lines), ordered for its own plot.
    pub drawing: Stipple,
    /// Its registration crosses' centres on the poster, mm.
    pub marks: Vec<[f64; 2]>,
}

impl Sheet {
    /// The sheet's file name in the poster's folder: plotting order, row
    /// and column, from 1 (`03-r1-c3.svg`).
    #[must_use]
    pub fn file_name(&self, index: usize) -> String {
        format!("{:02}-r{}-c{}.svg", index + 1, self.row + 1, self.col + 1)
    }

    /// The dots (or line points) on this sheet.
    #[must_use]
    pub fn dots(&self) -> usize {
        self.drawing.points.len()
    }
}

/// A drawing cut into sheets.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Poster {
    /// The grid.
    pub grid: SheetGrid,
    /// The sheets, row by row: the order they are plotted in.
    pub sheets: Vec<Sheet>,
}

impl Job {
    /// The job that draws a poster whole: this job's drawing at the
    /// picture's frame on the poster (`--width-mm` its width; no paper,
    /// no order: each sheet is ordered apart). `None` without `poster`.
    pub fn poster_whole(&self, picture: Picture<'_>) -> crate::Result<Option<Self>> {
        let Some(poster) = &self.poster else {
            return Ok(None);
        };
        let (w, h) = picture.size();
        let (w, h) = match self.crop {
            Some(c) => (
                c.width.min(w.saturating_sub(c.x)).max(1),
                c.height.min(h.saturating_sub(c.y)).max(1),
            ),
            None => (w, h),
        };
        let (w, h) = match self.rotate {
            Some(90 | 270) => (h, w),
            _ => (w, h),
        };
        let (pw, ph) = (poster.width_mm, poster.height_mm);
        let (w, h) = (f64::from(w.max(1)), f64::from(h.max(1)));
        // To a nanometre: the frame's corners read as written.
        let width_mm = ((pw / w).min(ph / h) * w * 1e6).round() / 1e6;
        Ok(Some(Self {
            width_mm: Some(width_mm),
            paper: None,
            margin: None,
            landscape: false,
            poster: None,
            sheet: None,
            order: Order::None,
            ..self.clone()
        }))
    }

    /// The poster's frame and grid for a drawing of `domain` px drawn by
    /// `whole` ([`Self::poster_whole`]), whose dots reach `reach_mm` from
    /// their centres.
    fn sheet_grid(
        &self,
        whole: &Self,
        domain: (u32, u32),
        reach_mm: f64,
    ) -> crate::Result<SheetGrid> {
        let (Some(poster), Some(paper), Some(fw)) = (&self.poster, &self.paper, whole.width_mm)
        else {
            return Err(
                Error::InvalidParameter("a poster needs «poster» and «paper»".into()).into(),
            );
        };
        let fh = fw * f64::from(domain.1.max(1)) / f64::from(domain.0.max(1));
        let (pw, ph) = (poster.width_mm, poster.height_mm);
        let frame = [(pw - fw) / 2.0, (ph - fh) / 2.0, fw, fh];
        let (sw, sh) = paper.oriented(self.landscape);
        SheetGrid::new([pw, ph], frame, [sw, sh], self.margin(), reach_mm)
    }

    /// The poster's plan for a drawing of `domain` px by `whole`
    /// ([`Self::poster_whole`]) whose largest dots have radius `radius`
    /// px (the plan's prediction).
    pub(crate) fn poster_plan(
        &self,
        whole: &Self,
        planned: &super::Planned,
    ) -> crate::Result<Option<PosterPlan>> {
        let plan = &planned.plan;
        let domain = plan.domain;
        let mm = whole.width_mm.unwrap_or(0.0) / f64::from(domain.0.max(1));
        let grid = self.sheet_grid(whole, domain, self.reach_mm(f64::from(plan.radius.0) * mm))?;
        let sheets = grid.rows * grid.cols;
        // Each sheet's share of the predicted count, at the count's scale.
        let [fx, fy, ..] = grid.frame_mm;
        let mut parts = vec![0.0; sheets];
        for map in planned.maps.all() {
            let scale = match plan.points {
                Some(n) if n > 0 => (map.predicted_points(1.0) / n as f64).sqrt().max(1e-9),
                _ => 1.0,
            };
            let cell = |x: f64, y: f64| {
                let (r, c) = grid.cell(fx + x * mm, fy + y * mm);
                r * grid.cols + c
            };
            for (p, q) in parts.iter_mut().zip(map.predicted_in(scale, sheets, cell)) {
                *p += q;
            }
        }
        let total: f64 = parts.iter().sum();
        let sheet_dots = parts
            .iter()
            .map(|p| {
                if total > 0.0 {
                    (p / total * plan.dots as f64).round() as usize
                } else {
                    0
                }
            })
            .collect();
        Ok(Some(PosterPlan {
            sheets,
            grid,
            sheet_dots,
        }))
    }

    /// How far a dot of radius `r_mm` reaches from its centre as drawn:
    /// its radius, and half the pen around its outline.
    fn reach_mm(&self, r_mm: f64) -> f64 {
        r_mm + self.pen_width().unwrap_or(0.0) / 2.0
    }

    /// The grid `drawing` (made by `whole`) is cut along, as
    /// [`Self::poster`] cuts it: the plan's, unless a dot reaches further
    /// than it planned. The app draws it over the view.
    ///
    /// # Errors
    /// Without poster or paper, or when the sheets cannot hold the dots.
    pub fn poster_grid(&self, whole: &Self, drawing: &Stipple) -> crate::Result<SheetGrid> {
        Ok(self.grid_of(whole, drawing, &whole.dots(drawing))?.0)
    }

    /// [`Self::poster_grid`] for the drawing's `dots` as drawn, and how
    /// far the widest reaches from its centre, mm.
    fn grid_of(
        &self,
        whole: &Self,
        drawing: &Stipple,
        dots: &[Dot],
    ) -> crate::Result<(SheetGrid, f64)> {
        let mm = whole.width_mm.unwrap_or(0.0) / f64::from(drawing.domain.0.max(1));
        let line_width = drawing
            .strokes
            .iter()
            .map(|s| s.width)
            .fold(0.0f32, f32::max);
        let reach_px = dots
            .iter()
            .map(|d| d.radius)
            .fold(line_width / 2.0, f32::max);
        let reach = if drawing.strokes.is_empty() {
            self.reach_mm(f64::from(reach_px) * mm)
        } else {
            f64::from(reach_px) * mm
        };
        // The plan's reach, unless a dot reaches further than it planned:
        // the plan's grid for the settings as they are now.
        let planned = drawing
            .plan
            .poster
            .as_ref()
            .map_or(0.0, |p| p.grid.reach_mm);
        let grid = self.sheet_grid(whole, drawing.domain, reach.max(planned))?;
        Ok((grid, reach))
    }

    /// `drawing`, made by `whole` ([`Self::poster_whole`]), cut into this
    /// job's poster sheets: each dot (or line point) on the sheet whose
    /// side of the seams holds it, each sheet ordered for its own plot
    /// (`--order tsp`: a tour per pen; a line: one line per pen per
    /// sheet), with the crosses it shares. `stop` is asked during the
    /// tours whether to end them early.
    pub fn poster(
        &self,
        whole: &Self,
        drawing: &Stipple,
        stop: &mut dyn FnMut() -> bool,
    ) -> crate::Result<Poster> {
        let mm = whole.width_mm.unwrap_or(0.0) / f64::from(drawing.domain.0.max(1));
        let dots = whole.dots(drawing);
        let (grid, reach) = self.grid_of(whole, drawing, &dots)?;
        let [fx, fy, ..] = grid.frame_mm;
        let on_poster = |p: &Point| [fx + f64::from(p.x) * mm, fy + f64::from(p.y) * mm];
        // Each point's sheet, its points in the drawing's order.
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); grid.rows * grid.cols];
        for (i, p) in drawing.points.iter().enumerate() {
            let [x, y] = on_poster(p);
            let (r, c) = grid.cell(x, y);
            members[r * grid.cols + c].push(i);
        }
        let pens = drawing.pens.as_ref().map_or(1, crate::colour::PenSet::len);
        let mut sheets = Vec::with_capacity(members.len());
        for (k, idx) in members.into_iter().enumerate() {
            let (row, col) = (k / grid.cols, k % grid.cols);
            let [x0, y0, x1, y1] = grid.printable_mm(row, col);
            for &i in &idx {
                let [x, y] = on_poster(&drawing.points[i]);
                let r = dots
                    .get(i)
                    .map_or(reach, |d| self.reach_mm(f64::from(d.radius) * mm));
                let r = if drawing.strokes.is_empty() { r } else { reach };
                if x - r < x0 - 1e-6 || x + r > x1 + 1e-6 || y - r < y0 - 1e-6 || y + r > y1 + 1e-6
                {
                    return Err(Error::InvalidParameter(format!(
                        "a dot at ({x:.2}, {y:.2}) mm leaves sheet {} × {} of the poster's grid",
                        row + 1,
                        col + 1
                    ))
                    .into());
                }
            }
            let ordered = self.sheet_order(drawing, idx, pens, stop);
            let origin = grid.sheet_origin(row, col);
            let marks = grid.sheet_marks(row, col);
            let part = sub_drawing(
                drawing,
                &dots,
                &ordered,
                pens,
                self.style == Style::Line,
                stop,
            );
            let page = SheetPage {
                placement: Placement {
                    sheet_mm: (grid.sheet_mm[0], grid.sheet_mm[1]),
                    origin_mm: (fx - origin[0], fy - origin[1]),
                    size_mm: (grid.frame_mm[2], grid.frame_mm[3]),
                    margin_mm: grid.margin_mm,
                },
                marks: marks
                    .iter()
                    .map(|&[x, y]| [x - origin[0], y - origin[1]])
                    .collect(),
            };
            sheets.push(Sheet {
                row,
                col,
                origin_mm: origin,
                job: Self {
                    sheet: Some(page),
                    order: self.order,
                    ..whole.clone()
                },
                drawing: part,
                marks,
            });
        }
        Ok(Poster { grid, sheets })
    }

    /// A sheet's points `idx` (in the drawing's order) pen by pen in the
    /// pens' order, each pen's along its own tour with `--order tsp` (a
    /// line is toured by [`sub_drawing`]).
    fn sheet_order(
        &self,
        drawing: &Stipple,
        idx: Vec<usize>,
        pens: usize,
        stop: &mut dyn FnMut() -> bool,
    ) -> Vec<usize> {
        let mut by_pen: Vec<Vec<usize>> = vec![Vec::new(); pens.max(1)];
        for i in idx {
            if let Some(pen) = by_pen.get_mut(drawing.points[i].class as usize) {
                pen.push(i);
            }
        }
        if self.order != Order::Tsp || self.style == Style::Line {
            return by_pen.concat();
        }
        let mut out = Vec::new();
        for pen in by_pen {
            let xy: Vec<[f64; 2]> = pen
                .iter()
                .map(|&i| {
                    [
                        f64::from(drawing.points[i].x),
                        f64::from(drawing.points[i].y),
                    ]
                })
                .collect();
            let t = tsp::plan_until(&xy, tsp::TspOptions::default(), stop);
            out.extend(t.order.iter().map(|&k| pen[k]));
        }
        out
    }
}

/// The part of `drawing` of its points `order`, in that order: their dots,
/// or, for a line, one line per pen through them (toured anew).
fn sub_drawing(
    drawing: &Stipple,
    dots: &[Dot],
    order: &[usize],
    pens: usize,
    line: bool,
    stop: &mut dyn FnMut() -> bool,
) -> Stipple {
    let mut points: Vec<Point> = order.iter().map(|&i| drawing.points[i]).collect();
    let mut calibrated: Vec<f32> = order.iter().map(|&i| drawing.calibrated[i]).collect();
    let mut strokes = Vec::new();
    if line {
        let (mut toured, mut cal) = (Vec::with_capacity(points.len()), Vec::new());
        for pen in 0..pens.max(1) {
            let mine: Vec<usize> = (0..points.len())
                .filter(|&i| points[i].class as usize == pen)
                .collect();
            let xy: Vec<[f64; 2]> = mine
                .iter()
                .map(|&i| [f64::from(points[i].x), f64::from(points[i].y)])
                .collect();
            let mut t = tsp::plan_until(&xy, tsp::TspOptions::line(), stop);
            tsp::uncross(&xy, &mut t.order);
            let width = drawing.strokes.get(pen).map_or(1.0, |s| s.width);
            let smooth = drawing.strokes.get(pen).is_some_and(|s| s.smooth);
            strokes.push(Stroke {
                points: t
                    .order
                    .iter()
                    .map(|&k| [points[mine[k]].x, points[mine[k]].y])
                    .collect(),
                width,
                smooth,
            });
            toured.extend(t.order.iter().map(|&k| points[mine[k]]));
            cal.extend(t.order.iter().map(|&k| calibrated[mine[k]]));
        }
        points = toured;
        calibrated = cal;
    }
    let sheet_dots = if dots.is_empty() || line {
        Vec::new()
    } else {
        order.iter().map(|&i| dots[i]).collect()
    };
    Stipple {
        dots: sheet_dots,
        strokes,
        set: SampleSet {
            width: drawing.set.width,
            height: drawing.set.height,
            points: Vec::new(),
            stats: drawing.set.stats.clone(),
        },
        points,
        calibrated,
        domain: drawing.domain,
        range: drawing.range,
        runs: drawing.runs,
        short_of: None,
        tour: None,
        stages: Vec::new(),
        plan: drawing.plan.clone(),
        pens: drawing.pens.clone(),
    }
}

/// `poster.json`: where each sheet lies on the poster. A point (u, v)
/// on a sheet's SVG (its own mm) lies at (x_mm + u, y_mm + v) on the
/// poster.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Manifest {
    /// The poster, mm.
    pub poster_mm: [f64; 2],
    /// The picture's frame on the poster: x, y, width, height, mm.
    pub frame_mm: [f64; 4],
    /// The sheets' paper (as `--paper` names it).
    pub paper: String,
    /// The margin on every sheet, mm.
    pub margin_mm: f64,
    /// How far neighbouring sheets' printable areas overlap, mm.
    pub overlap_mm: f64,
    /// Rows of sheets.
    pub rows: usize,
    /// Columns of sheets.
    pub cols: usize,
    /// How the registration crosses plot.
    pub registration: String,
    /// The sheets in plotting order.
    pub sheets: Vec<ManifestSheet>,
}

/// One sheet of [`Manifest`].
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ManifestSheet {
    /// Its SVG, in the poster's folder.
    pub file: String,
    /// Its row, from 1 at the top.
    pub row: usize,
    /// Its column, from 1 at the left.
    pub col: usize,
    /// Its top-left corner on the poster, mm.
    pub x_mm: f64,
    /// Its top-left corner on the poster, mm.
    pub y_mm: f64,
    /// Its width, mm.
    pub width_mm: f64,
    /// Its height, mm.
    pub height_mm: f64,
    /// Its dots (a line's points).
    pub dots: usize,
    /// Its registration crosses.
    pub marks: usize,
    /// Its estimated plotting time, with a pen.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plot_minutes: Option<f64>,
}

impl Poster {
    /// The manifest, each sheet's plotting time by `plotter` when the job
    /// has a pen.
    pub fn manifest(&self, job: &Job, plotter: Option<&Plotter>) -> crate::Result<Manifest> {
        let g = &self.grid;
        let mut sheets = Vec::with_capacity(self.sheets.len());
        for (i, s) in self.sheets.iter().enumerate() {
            let plot_minutes = match plotter {
                Some(p) if s.job.pen_mm.is_some() => Some(
                    s.job
                        .plot_stats(&s.drawing, p)?
                        .iter()
                        .map(|r| r.seconds)
                        .sum::<f64>()
                        / 60.0,
                ),
                _ => None,
            };
            sheets.push(ManifestSheet {
                file: s.file_name(i),
                row: s.row + 1,
                col: s.col + 1,
                x_mm: s.origin_mm[0],
                y_mm: s.origin_mm[1],
                width_mm: g.sheet_mm[0],
                height_mm: g.sheet_mm[1],
                dots: s.dots(),
                marks: s.marks.len(),
                plot_minutes,
            });
        }
        Ok(Manifest {
            poster_mm: g.poster_mm,
            frame_mm: g.frame_mm,
            paper: job
                .paper
                .as_ref()
                .map_or_else(String::new, ToString::to_string),
            margin_mm: g.margin_mm,
            overlap_mm: g.overlap_mm,
            rows: g.rows,
            cols: g.cols,
            registration: format!(
                "crosses {MARK_MM} mm across on the seams, on the layer '{REGISTRATION_LAYER}' of each sheet: plotted first, with the first pen"
            ),
            sheets,
        })
    }

    /// Refuses a poster's output `dir` when it is a file: a poster is a
    /// folder of sheets (checked before the drawing is made, and by
    /// [`Self::write`]).
    pub fn check_folder(dir: &Path) -> crate::Result<()> {
        if dir.is_file() {
            return Err(Error::InvalidParameter(format!(
                "a poster is a folder of sheets, and '{}' is a file: name a folder (e.g. poster/)",
                dir.display()
            ))
            .into());
        }
        Ok(())
    }

    /// Writes the poster to folder `dir` (made if missing): one SVG a
    /// sheet ([`Sheet::file_name`]) and `poster.json`, each atomically.
    /// Sheets of an earlier poster in the folder that this one has not
    /// are removed, so that the folder holds this poster only.
    pub fn write(&self, job: &Job, dir: &Path, plotter: Option<&Plotter>) -> crate::Result<()> {
        Self::check_folder(dir)?;
        let manifest = self.manifest(job, plotter)?;
        std::fs::create_dir_all(dir).map_err(|e| crate::io::Error::Write {
            path: dir.to_path_buf(),
            source: e.into(),
        })?;
        for (s, m) in self.sheets.iter().zip(&manifest.sheets) {
            let bytes = s.job.svg(&s.drawing)?;
            crate::io::write_atomic(&dir.join(&m.file), |w| Ok(w.write_all(&bytes)?))?;
        }
        let text = serde_json::to_string_pretty(&manifest)
            .map_err(|e| crate::io::Error::Invalid(e.to_string()))?;
        crate::io::write_atomic(&dir.join("poster.json"), |w| {
            Ok(w.write_all(format!("{text}\n").as_bytes())?)
        })?;
        let ours: Vec<&str> = manifest.sheets.iter().map(|m| m.file.as_str()).collect();
        if let Ok(entries) = std::fs::read_dir(dir) {
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                if is_sheet_name(&name) && !ours.contains(&name.as_str()) {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        Ok(())
    }

    /// The assembled poster as the pens plot it ([`Job::preview`] of the
    /// whole drawing), on the area the sheets cover, with each sheet's
    /// edge (blue), the seams (red) and the crosses drawn over it.
    pub fn preview(&self, whole: &Job, drawing: &Stipple) -> crate::Result<image::RgbImage> {
        let g = &self.grid;
        // The area of the poster and every sheet.
        let (mut x0, mut y0, mut x1, mut y1) = (0.0f64, 0.0f64, g.poster_mm[0], g.poster_mm[1]);
        for s in &self.sheets {
            let [x, y] = s.origin_mm;
            (x0, y0) = (x0.min(x), y0.min(y));
            (x1, y1) = (x1.max(x + g.sheet_mm[0]), y1.max(y + g.sheet_mm[1]));
        }
        let page = Job {
            sheet: Some(SheetPage {
                placement: Placement {
                    sheet_mm: (x1 - x0, y1 - y0),
                    origin_mm: (g.frame_mm[0] - x0, g.frame_mm[1] - y0),
                    size_mm: (g.frame_mm[2], g.frame_mm[3]),
                    margin_mm: 0.0,
                },
                marks: Vec::new(),
            }),
            ..whole.clone()
        };
        let mut img = page.preview(drawing)?;
        let mm = g.frame_mm[2] / f64::from(drawing.domain.0.max(1));
        let at = |v: f64, o: f64| ((v - o) / mm).round() as i64;
        if !drawing.strokes.is_empty() {
            // Each sheet's own lines, the darker ink where sheets overlap.
            img = image::RgbImage::from_pixel(
                img.width(),
                img.height(),
                image::Rgb(whole.paper_rgb()),
            );
            for s in &self.sheets {
                let sheet = s.job.preview(&s.drawing)?;
                let (ox, oy) = (at(s.origin_mm[0], x0), at(s.origin_mm[1], y0));
                for (x, y, p) in sheet.enumerate_pixels() {
                    let (cx, cy) = (i64::from(x) + ox, i64::from(y) + oy);
                    if cx >= 0
                        && cy >= 0
                        && cx < i64::from(img.width())
                        && cy < i64::from(img.height())
                    {
                        let q = img.get_pixel_mut(cx as u32, cy as u32);
                        for c in 0..3 {
                            q.0[c] = q.0[c].min(p.0[c]);
                        }
                    }
                }
            }
        }
        let (w, h) = (i64::from(img.width()), i64::from(img.height()));
        let put = |img: &mut image::RgbImage, x: i64, y: i64, c: [u8; 3]| {
            if (0..w).contains(&x) && (0..h).contains(&y) {
                img.put_pixel(x as u32, y as u32, image::Rgb(c));
            }
        };
        let thick = ((0.5 / mm).round() as i64).max(1);
        let rect =
            |img: &mut image::RgbImage, [ax, ay, bx, by]: [f64; 4], c: [u8; 3], dash: bool| {
                let (ax, ay, bx, by) = (at(ax, x0), at(ay, y0), at(bx, x0), at(by, y0));
                let on = |t: i64| !dash || (t / (4 * thick)) % 2 == 0;
                for t in 0..thick {
                    for x in ax..=bx {
                        if on(x) {
                            put(img, x, ay + t, c);
                            put(img, x, by - t, c);
                        }
                    }
                    for y in ay..=by {
                        if on(y) {
                            put(img, ax + t, y, c);
                            put(img, bx - t, y, c);
                        }
                    }
                }
            };
        for s in &self.sheets {
            let [x, y] = s.origin_mm;
            rect(
                &mut img,
                [x, y, x + g.sheet_mm[0], y + g.sheet_mm[1]],
                [40, 110, 220],
                false,
            );
        }
        for c in 0..g.cols.saturating_sub(1) {
            let x = g.seam(0, c);
            rect(&mut img, [x, y0, x, y1], [220, 40, 40], true);
        }
        for r in 0..g.rows.saturating_sub(1) {
            let y = g.seam(1, r);
            rect(&mut img, [x0, y, x1, y], [220, 40, 40], true);
        }
        let ink = whole.ink_rgb();
        let hm = MARK_MM / 2.0;
        for [x, y] in g.marks() {
            rect(&mut img, [x - hm, y, x + hm, y], ink, false);
            rect(&mut img, [x, y - hm, x, y + hm], ink, false);
        }
        Ok(img)
    }
}

/// Whether `name` is a sheet's file name ([`Sheet::file_name`]).
fn is_sheet_name(name: &str) -> bool {
    let Some(stem) = name.strip_suffix(".svg") else {
        return false;
    };
    let parts: Vec<&str> = stem.split('-').collect();
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    matches!(parts.as_slice(), [n, r, c] if digits(n)
        && r.strip_prefix('r').is_some_and(digits)
        && c.strip_prefix('c').is_some_and(digits))
}

impl Job {
    /// A poster sheet's registration crosses as strokes in domain px (two
    /// arms each, the pen's width): none off a poster.
    pub(crate) fn registration(&self, domain: (u32, u32)) -> crate::Result<Vec<Stroke>> {
        let Some(page) = &self.sheet else {
            return Ok(Vec::new());
        };
        let p = page.placement;
        let mm = p.mm_per_px(domain.0);
        let width = (self.pen_width().unwrap_or(MARK_LINE_MM) / mm) as f32;
        let px = |u: f64, v: f64| {
            [
                ((u - p.origin_mm.0) / mm) as f32,
                ((v - p.origin_mm.1) / mm) as f32,
            ]
        };
        let h = MARK_MM / 2.0;
        Ok(page
            .marks
            .iter()
            .flat_map(|&[u, v]| [[px(u - h, v), px(u + h, v)], [px(u, v - h), px(u, v + h)]])
            .map(|arm| Stroke {
                points: arm.to_vec(),
                width,
                smooth: false,
            })
            .collect())
    }
}

impl Picture<'_> {
    /// The picture's size in pixels, before any crop or turn.
    pub(crate) fn size(&self) -> (u32, u32) {
        match self {
            Self::Grey(m) | Self::Both(m, _) => (m.width(), m.height()),
            Self::Colour(c) => (c.width(), c.height()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn a4_grid(frame: [f64; 4]) -> SheetGrid {
        SheetGrid::new([600.0, 420.0], frame, [210.0, 297.0], 10.0, 0.5).unwrap()
    }

    #[test]
    fn the_grid_covers_the_frame_and_its_seams_lie_in_the_overlaps() {
        let g = a4_grid([0.0, 0.0, 600.0, 420.0]);
        // 190 mm printable, 6 mm overlap: 4 columns cover 600 + 2·(3 + 2.5 + 2).
        assert_eq!((g.cols, g.rows, g.overlap_mm), (4, 2, 6.0));
        let [x0, y0, ..] = g.printable_mm(0, 0);
        let [.., x1, y1] = g.printable_mm(g.rows - 1, g.cols - 1);
        assert!(
            x0 <= -7.5 && x1 >= 607.5 && y0 <= -7.5 && y1 >= 427.5,
            "{g:?}"
        );
        for c in 0..g.cols - 1 {
            let s = g.seam(0, c);
            assert!((g.printable_mm(0, c)[2] - s - 3.0).abs() < 1e-9);
            assert!((s - g.printable_mm(0, c + 1)[0] - 3.0).abs() < 1e-9);
            assert_eq!(g.cell(s - 1e-6, 10.0).1, c);
            assert_eq!(g.cell(s, 10.0).1, c + 1);
        }
    }

    #[test]
    fn every_sheet_shares_its_crosses_with_a_neighbour() {
        let g = a4_grid([0.0, 30.0, 600.0, 360.0]);
        let marks = g.marks();
        assert!(!marks.is_empty());
        for r in 0..g.rows {
            for c in 0..g.cols {
                let mine = g.sheet_marks(r, c);
                assert!(!mine.is_empty(), "sheet {r},{c}");
                let shared = mine.iter().any(|m| {
                    [
                        (r.wrapping_sub(1), c),
                        (r + 1, c),
                        (r, c.wrapping_sub(1)),
                        (r, c + 1),
                    ]
                    .iter()
                    .filter(|(rr, cc)| *rr < g.rows && *cc < g.cols)
                    .any(|&(rr, cc)| g.sheet_marks(rr, cc).contains(m))
                });
                assert!(shared, "sheet {r},{c} shares no cross");
            }
        }
        // The crosses on the grid's edge lie outside the picture.
        let [fx, fy, fw, fh] = g.frame_mm;
        for [x, y] in marks {
            let inside_x = x > fx - MARK_GAP_MM && x < fx + fw + MARK_GAP_MM;
            let inside_y = y > fy - MARK_GAP_MM && y < fy + fh + MARK_GAP_MM;
            let inner = (0..g.cols - 1).any(|c| (g.seam(0, c) - x).abs() < 1e-9)
                && (0..g.rows - 1).any(|r| (g.seam(1, r) - y).abs() < 1e-9);
            assert!(
                inner || !(inside_x && inside_y),
                "({x}, {y}) in the picture"
            );
        }
    }

    #[test]
    fn one_sheet_needs_no_crosses_and_bad_sheets_are_refused() {
        let g = a4_grid([10.0, 10.0, 150.0, 100.0]);
        assert_eq!((g.rows, g.cols), (1, 1));
        assert!(g.marks().is_empty());
        assert!(
            SheetGrid::new(
                [600.0, 420.0],
                [0.0, 0.0, 600.0, 420.0],
                [20.0, 20.0],
                8.0,
                0.5
            )
            .is_err()
        );
        assert!(
            SheetGrid::new(
                [9000.0, 9000.0],
                [0.0, 0.0, 9000.0, 9000.0],
                [105.0, 148.0],
                10.0,
                0.5
            )
            .is_err()
        );
    }
}
