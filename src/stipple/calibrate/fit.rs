//! The fit: from a scan or photograph of a plotted chart to each pen's dot
//! gain and ink colour.
//!
//! 1. The four round marks are found: the dark connected components (Otsu
//!    threshold on each pixel's darkest channel; light ones, on one less
//!    its lightest, where the chart's mark pen is lighter than its paper)
//!    that are round (no pixel
//!    farther from the centroid than 1.2 × the radius of a disk of the
//!    same area: a square has 1.25) and large, away from the image's edge;
//!    the four largest, of similar size, ordered by corner.
//! 2. Their centroids give the homography from the chart's millimetres to
//!    the scan's pixels; the 16-bit code is read through it and must be the
//!    chart's.
//! 3. Each patch's mean colour is measured inside a 1.5 mm inset (linear
//!    light, bilinear samples through the homography); the paper white is
//!    the 0% patches' mean, each pen's ink the solid patch's over the paper
//!    (an ink lighter than the paper covers it: its own colour, opacity 1).
//! 4. A patch's ink cover is its colour's distance from the paper toward
//!    the solid ink. The model's cover at gain g is the fraction of the
//!    inset within g × half the pen's width of a dot; the gain is the one
//!    that minimizes the squared error over the 10–90% patches, searched in
//!    steps of 0.001.

use image::RgbImage;

use super::chart::{Chart, FRACTIONS, MARK_RADIUS_MM, PATCH_MM};
use super::homography::Homography;
use crate::colour::pens::{MAX_GAIN, MIN_GAIN};
use crate::colour::{Pen, PenSet, linear_to_srgb, srgb_to_linear};
use crate::stipple::{Error, Result};

/// The inset of a patch's measured area, mm.
const INSET_MM: f64 = 1.5;
/// The model's resolution, samples per mm.
const MODEL_PER_MM: f64 = 25.0;
/// The largest RMS cover error a fit may leave.
const MAX_RMS: f64 = 0.08;

/// One pen, fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct PenFit {
    /// The pen's name.
    pub name: String,
    /// Its width, mm.
    pub width_mm: f64,
    /// The plotted dot's diameter over the drawn one.
    pub dot_gain: f64,
    /// The ink as scanned, on white paper (sRGB); an opaque ink's own
    /// colour.
    pub colour: [u8; 3],
    /// 1 for an ink lighter than the paper, which covers it (a gel pen on
    /// dark paper); none for one that darkens it, which multiplies.
    pub opacity: Option<f64>,
    /// The RMS error of the patches' cover at the fitted gain.
    pub rms: f64,
    /// Each stippled patch's (nominal, measured, fitted) cover.
    pub patches: Vec<(f64, f64, f64)>,
}

/// The fit of a chart's scan.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The chart's code, as read.
    pub code: u16,
    /// The pens, in the chart's order.
    pub pens: Vec<PenFit>,
    /// The paper's colour, linear RGB.
    pub paper: [f64; 3],
}

impl Fit {
    /// The fitted pens as a pen set (`--pens` reads its TOML).
    pub fn pen_set(&self) -> Result<PenSet> {
        let pens = self
            .pens
            .iter()
            .map(|p| Pen {
                name: p.name.clone(),
                colour: p.colour,
                width_mm: Some(p.width_mm),
                dot_gain: Some((p.dot_gain * 1000.0).round() / 1000.0),
                opacity: p.opacity,
            })
            .collect();
        PenSet::new(pens).map_err(|e| Error::InvalidParameter(e.to_string()))
    }
}

/// A scan in linear light.
struct Scan {
    width: usize,
    height: usize,
    rgb: Vec<[f32; 3]>,
}

impl Scan {
    fn new(img: &RgbImage) -> Self {
        let lut: Vec<f32> = (0..=255u8)
            .map(|v| srgb_to_linear(f32::from(v) / 255.0))
            .collect();
        Self {
            width: img.width() as usize,
            height: img.height() as usize,
            rgb: img
                .pixels()
                .map(|p| p.0.map(|c| lut[usize::from(c)]))
                .collect(),
        }
    }

    /// The colour at (x, y) px (pixel centres at +0.5), bilinear, clamped
    /// to the image.
    fn at(&self, x: f64, y: f64) -> [f64; 3] {
        let (w, h) = (self.width as f64, self.height as f64);
        let (x, y) = ((x - 0.5).clamp(0.0, w - 1.0), (y - 0.5).clamp(0.0, h - 1.0));
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let p = |xx: usize, yy: usize| self.rgb[yy * self.width + xx];
        let (a, b, c, d) = (p(x0, y0), p(x1, y0), p(x0, y1), p(x1, y1));
        std::array::from_fn(|k| {
            (f64::from(a[k]) * (1.0 - fx) + f64::from(b[k]) * fx) * (1.0 - fy)
                + (f64::from(c[k]) * (1.0 - fx) + f64::from(d[k]) * fx) * fy
        })
    }

    /// The mean colour over the chart's rectangle (x0, y0)–(x1, y1) in mm,
    /// `n` × `n` samples through `h`.
    fn mean(&self, h: &Homography, (x0, y0, x1, y1): (f64, f64, f64, f64), n: usize) -> [f64; 3] {
        let mut acc = [0.0; 3];
        for i in 0..n {
            for j in 0..n {
                let x = x0 + (x1 - x0) * (i as f64 + 0.5) / n as f64;
                let y = y0 + (y1 - y0) * (j as f64 + 0.5) / n as f64;
                let c = self.at_mm(h, (x, y));
                for k in 0..3 {
                    acc[k] += c[k];
                }
            }
        }
        acc.map(|v| v / (n * n) as f64)
    }

    fn at_mm(&self, h: &Homography, p: (f64, f64)) -> [f64; 3] {
        let (u, v) = h.apply(p);
        self.at(u, v)
    }
}

/// How much a colour looks like the marks, low where it does: its
/// darkest channel, or for light marks on dark paper one less its
/// lightest.
fn tone(c: [f64; 3], light: bool) -> f64 {
    if light {
        1.0 - c[0].max(c[1]).max(c[2])
    } else {
        c[0].min(c[1]).min(c[2])
    }
}

/// Otsu's threshold of `values` in [0, 1].
fn otsu(values: impl Iterator<Item = f32>) -> f32 {
    let mut hist = [0u64; 256];
    let mut n = 0u64;
    for v in values {
        hist[((v.clamp(0.0, 1.0) * 255.0) as usize).min(255)] += 1;
        n += 1;
    }
    let total: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * c as f64)
        .sum();
    let (mut w0, mut sum0, mut best, mut at) = (0.0, 0.0, -1.0, 128usize);
    for (i, &c) in hist.iter().enumerate() {
        w0 += c as f64;
        sum0 += i as f64 * c as f64;
        let w1 = n as f64 - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let (m0, m1) = (sum0 / w0, (total - sum0) / w1);
        let between = w0 * w1 * (m0 - m1) * (m0 - m1);
        if between > best {
            best = between;
            at = i;
        }
    }
    (at as f32 + 1.0) / 255.0
}

/// The centroids of the four fiducial marks, ordered top left, top right,
/// bottom left, bottom right (in the scan's pixels).
fn find_marks(scan: &Scan, light: bool) -> Result<[(f64, f64); 4]> {
    let lum: Vec<f32> = scan
        .rgb
        .iter()
        .map(|c| tone(c.map(f64::from), light) as f32)
        .collect();
    // Otsu's threshold, and where a light ink (white on grey paper) takes
    // the paper to the marks' side of it, Otsu's again below it.
    let t = otsu(lum.iter().copied());
    marks_at(scan, &lum, t).or_else(|e| {
        let below = otsu(lum.iter().copied().filter(|&v| v < t));
        marks_at(scan, &lum, below).map_err(|_| e)
    })
}

/// [`find_marks`] at the threshold `t` of `lum`.
fn marks_at(scan: &Scan, lum: &[f32], t: f32) -> Result<[(f64, f64); 4]> {
    let (w, h) = (scan.width, scan.height);
    let mut label = vec![u32::MAX; w * h];
    struct Comp {
        area: f64,
        sx: f64,
        sy: f64,
        edge: bool,
    }
    let mut comps: Vec<Comp> = Vec::new();
    let mut stack = Vec::new();
    for start in 0..w * h {
        if lum[start] >= t || label[start] != u32::MAX {
            continue;
        }
        let id = comps.len() as u32;
        let mut c = Comp {
            area: 0.0,
            sx: 0.0,
            sy: 0.0,
            edge: false,
        };
        label[start] = id;
        stack.push(start);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            c.area += 1.0;
            c.sx += x as f64 + 0.5;
            c.sy += y as f64 + 0.5;
            c.edge |= x == 0 || y == 0 || x == w - 1 || y == h - 1;
            for (dx, dy) in [
                (-1i64, 0i64),
                (1, 0),
                (0, -1),
                (0, 1),
                (-1, -1),
                (1, 1),
                (-1, 1),
                (1, -1),
            ] {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if lum[j] < t && label[j] == u32::MAX {
                    label[j] = id;
                    stack.push(j);
                }
            }
        }
        comps.push(c);
    }
    let min_area = (w * h) as f64 * 1e-4;
    let mut far = vec![0.0f64; comps.len()];
    for (i, &l) in label.iter().enumerate() {
        if l == u32::MAX {
            continue;
        }
        let c = &comps[l as usize];
        if c.area < min_area || c.edge {
            continue;
        }
        let (cx, cy) = (c.sx / c.area, c.sy / c.area);
        let d = ((i % w) as f64 + 0.5 - cx).hypot((i / w) as f64 + 0.5 - cy);
        far[l as usize] = far[l as usize].max(d);
    }
    let mut round: Vec<(f64, (f64, f64))> = comps
        .iter()
        .zip(&far)
        .filter(|&(c, &d)| {
            c.area >= min_area && !c.edge && d <= 1.2 * (c.area / std::f64::consts::PI).sqrt()
        })
        .map(|(c, _)| (c.area, (c.sx / c.area, c.sy / c.area)))
        .collect();
    round.sort_by(|a, b| b.0.total_cmp(&a.0));
    let none = |found: usize| {
        Error::InvalidParameter(format!(
            "found {found} of the chart's 4 round marks in the scan: scan the whole sheet, \
             flat and lit evenly, marks in view"
        ))
    };
    if round.len() < 4 {
        return Err(none(round.len()));
    }
    let four = &round[..4];
    if four[3].0 < four[0].0 / 2.5 {
        return Err(none(3));
    }
    let pts: Vec<(f64, f64)> = four.iter().map(|c| c.1).collect();
    let pick = |key: &dyn Fn(&(f64, f64)) -> f64, max: bool| -> (f64, f64) {
        let mut best = pts[0];
        for p in &pts {
            if (max && key(p) > key(&best)) || (!max && key(p) < key(&best)) {
                best = *p;
            }
        }
        best
    };
    let tl = pick(&|p| p.0 + p.1, false);
    let br = pick(&|p| p.0 + p.1, true);
    let tr = pick(&|p| p.0 - p.1, true);
    let bl = pick(&|p| p.0 - p.1, false);
    let corners = [tl, tr, bl, br];
    for (i, a) in corners.iter().enumerate() {
        if corners[..i].contains(a) {
            return Err(none(3));
        }
    }
    Ok(corners)
}

/// Each sample point of a patch's inset: its distance to the nearest dot,
/// sorted (capped at `cap`).
fn dot_distances(dots: &[(f64, f64)], inset: (f64, f64, f64, f64), cap: f64) -> Vec<f64> {
    let (x0, y0, x1, y1) = inset;
    let cell = cap.max(0.05);
    let gx0 = x0 - cap;
    let gy0 = y0 - cap;
    let nx = ((x1 - x0 + 2.0 * cap) / cell).ceil() as usize + 1;
    let ny = ((y1 - y0 + 2.0 * cap) / cell).ceil() as usize + 1;
    let mut grid: Vec<Vec<(f64, f64)>> = vec![Vec::new(); nx * ny];
    for &(x, y) in dots {
        let (i, j) = ((x - gx0) / cell, (y - gy0) / cell);
        if i >= 0.0 && j >= 0.0 && (i as usize) < nx && (j as usize) < ny {
            grid[j as usize * nx + i as usize].push((x, y));
        }
    }
    let n = ((x1 - x0) * MODEL_PER_MM).round() as usize;
    let m = ((y1 - y0) * MODEL_PER_MM).round() as usize;
    let mut out = Vec::with_capacity(n * m);
    for a in 0..n {
        for b in 0..m {
            let x = x0 + (x1 - x0) * (a as f64 + 0.5) / n as f64;
            let y = y0 + (y1 - y0) * (b as f64 + 0.5) / m as f64;
            let (ci, cj) = (((x - gx0) / cell) as usize, ((y - gy0) / cell) as usize);
            let mut best = cap;
            for j in cj.saturating_sub(1)..(cj + 2).min(ny) {
                for i in ci.saturating_sub(1)..(ci + 2).min(nx) {
                    for &(dx, dy) in &grid[j * nx + i] {
                        best = best.min((dx - x).hypot(dy - y));
                    }
                }
            }
            out.push(best);
        }
    }
    out.sort_by(f64::total_cmp);
    out
}

/// The fraction of `sorted` distances within `r`.
fn cover(sorted: &[f64], r: f64) -> f64 {
    sorted.partition_point(|&d| d <= r) as f64 / sorted.len().max(1) as f64
}

/// Fits `chart`'s pens to `img`, a scan or photograph of it plotted.
pub fn fit(chart: &Chart, img: &RgbImage) -> Result<Fit> {
    if img.width() < 64 || img.height() < 64 {
        return Err(Error::InvalidParameter(format!(
            "the scan is {} × {} px: too small to hold a chart",
            img.width(),
            img.height()
        )));
    }
    let scan = Scan::new(img);
    let light = chart.light_marks();
    let found = find_marks(&scan, light)?;
    let h = Homography::from_points(&chart.marks, &found).ok_or_else(|| {
        Error::InvalidParameter("the scan's marks do not make a quadrilateral".into())
    })?;
    // The code, read against the marks' tone and the paper's.
    let r = MARK_RADIUS_MM / 2.0;
    let mark_dark = chart
        .marks
        .iter()
        .map(|&(x, y)| tone(scan.mean(&h, (x - r, y - r, x + r, y + r), 6), light))
        .sum::<f64>()
        / 4.0;
    let inset = |p: &super::chart::Patch, d: f64| {
        (
            p.origin_mm.0 + d,
            p.origin_mm.1 + d,
            p.origin_mm.0 + PATCH_MM - d,
            p.origin_mm.1 + PATCH_MM - d,
        )
    };
    let blanks: Vec<[f64; 3]> = chart
        .patches
        .iter()
        .filter(|p| p.fraction <= 0.0)
        .map(|p| scan.mean(&h, inset(p, INSET_MM), 24))
        .collect();
    let paper: [f64; 3] =
        std::array::from_fn(|k| blanks.iter().map(|c| c[k]).sum::<f64>() / blanks.len() as f64);
    let t = (tone(paper, light) + mark_dark) / 2.0;
    let code = chart.bits().iter().fold(0u16, |acc, &((x, y), _)| {
        let d = tone(
            scan.mean(&h, (x - 0.8, y - 0.8, x + 0.8, y + 0.8), 5),
            light,
        );
        acc << 1 | u16::from(d < t)
    });
    if code != chart.code || tone(paper, light) - mark_dark < 0.15 {
        return Err(Error::InvalidParameter(format!(
            "the scan is not of this chart: its code reads {code:04x}, the chart's is {:04x}",
            chart.code
        )));
    }
    let mut pens = Vec::new();
    for (i, pen) in chart.spec.pens.iter().enumerate() {
        let solid = chart
            .pen_patches(i)
            .find(|p| p.fraction >= 1.0)
            .map(|p| scan.mean(&h, inset(p, 2.0), 24))
            .unwrap_or(paper);
        let axis: [f64; 3] = std::array::from_fn(|k| paper[k] - solid[k]);
        let norm2: f64 = axis.iter().map(|a| a * a).sum();
        if norm2 < 1e-4 {
            return Err(Error::InvalidParameter(format!(
                "pen '{}': its solid patch is as light as the paper; was it plotted?",
                pen.name
            )));
        }
        let rho = pen.width_mm / 2.0;
        let mut rows = Vec::new();
        for p in chart
            .pen_patches(i)
            .filter(|p| p.fraction > 0.0 && p.fraction < 1.0)
        {
            let m = scan.mean(&h, inset(p, INSET_MM), 48);
            let measured = (0..3).map(|k| (paper[k] - m[k]) * axis[k]).sum::<f64>() / norm2;
            let d = dot_distances(&p.dots, inset(p, INSET_MM), MAX_GAIN * rho);
            rows.push((p.fraction, measured, d));
        }
        let err = |g: f64| {
            rows.iter()
                .map(|(_, m, d)| (cover(d, g * rho) - m).powi(2))
                .sum::<f64>()
        };
        let steps = ((MAX_GAIN - MIN_GAIN) / 0.001).round() as usize;
        let gain = (0..=steps)
            .map(|s| MIN_GAIN + s as f64 * 0.001)
            .min_by(|&a, &b| err(a).total_cmp(&err(b)))
            .unwrap_or(1.0);
        let rms = (err(gain) / rows.len().max(1) as f64).sqrt();
        if rms > MAX_RMS || gain <= MIN_GAIN + 0.01 || gain >= MAX_GAIN - 0.01 {
            return Err(Error::InvalidParameter(format!(
                "pen '{}': the patches do not follow the chart's dots (gain {gain:.2}, RMS \
                 error {rms:.3}): rescan flat and lit evenly",
                pen.name
            )));
        }
        // An ink lighter than the paper covers it: its colour is the solid
        // patch's own; a darker one multiplies: its colour on white is the
        // solid patch's over the paper's.
        // Only on a chart made for coloured paper: on white, a bright ink
        // (yellow, fluorescent) lighter than the scanned paper still
        // multiplies.
        let luminance = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        let opaque = chart.spec.paper.is_some() && luminance(solid) > luminance(paper);
        let ink: [f64; 3] = std::array::from_fn(|k| {
            if opaque {
                solid[k].clamp(0.0, 1.0)
            } else {
                (solid[k] / paper[k].max(1e-6)).clamp(0.0, 1.0)
            }
        });
        pens.push(PenFit {
            name: pen.name.clone(),
            width_mm: pen.width_mm,
            dot_gain: gain,
            opacity: opaque.then_some(1.0),
            colour: ink.map(|v| (linear_to_srgb(v as f32) * 255.0).round() as u8),
            rms,
            patches: rows
                .iter()
                .map(|(f, m, d)| (*f, *m, cover(d, gain * rho)))
                .collect(),
        });
    }
    debug_assert_eq!(FRACTIONS.len(), 11);
    Ok(Fit { code, pens, paper })
}
