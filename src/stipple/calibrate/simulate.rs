//! Synthetic plots and scans, to try and test the calibration loop without
//! a plotter: the chart as a pen with a known dot gain and ink would plot
//! it on off-white paper, then scanned with blur, noise, a small rotation
//! and a perspective warp.
//!
//! The plot model: a pen touch inks a disk `gain` × the pen's width across;
//! a filled shape (a spiral-filled mark, a hatched square) grows by
//! (gain − 1) × half the pen's width on every side; inks multiply in linear
//! light on the paper, but one lighter than the paper covers what is below
//! (an opaque gel pen on dark paper).

use image::RgbImage;

use super::chart::{BIT_MM, Chart, MARK_RADIUS_MM, PATCH_MM};
use super::homography::Homography;
use crate::colour::{decode, linear_to_srgb};
use crate::stipple::{Error, Result};

/// Supersampling per axis of each pen's coverage.
const SS: usize = 3;

/// How the synthetic plot and scan are made.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanOptions {
    /// The scan's resolution on the sheet, px per mm.
    pub px_per_mm: f64,
    /// Each pen's dot gain (the last repeats for further pens).
    pub gains: Vec<f64>,
    /// Each pen's real ink, sRGB on white (the chart's colour when absent).
    pub inks: Vec<[u8; 3]>,
    /// The paper's colour, linear RGB.
    pub paper: [f64; 3],
    /// The background around the sheet, linear RGB.
    pub background: [f64; 3],
    /// Gaussian blur, px.
    pub blur_px: f64,
    /// Gaussian noise on the 8-bit values, as a fraction of full scale.
    pub noise: f64,
    /// Rotation, degrees.
    pub rotate_deg: f64,
    /// Perspective: each corner moves by up to this fraction of the sheet.
    pub perspective: f64,
    /// The noise's and the warp's seed.
    pub seed: u64,
}

impl Default for ScanOptions {
    fn default() -> Self {
        Self {
            px_per_mm: 8.0,
            gains: vec![1.0],
            inks: Vec::new(),
            paper: [0.90, 0.89, 0.85],
            background: [0.18, 0.17, 0.16],
            blur_px: 1.0,
            noise: 0.02,
            rotate_deg: 2.0,
            perspective: 0.03,
            seed: 1,
        }
    }
}

impl ScanOptions {
    fn check(&self, pens: usize) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if !(self.px_per_mm.is_finite() && (2.0..=40.0).contains(&self.px_per_mm)) {
            return bad(format!(
                "scan resolution {} px/mm must be in [2, 40]",
                self.px_per_mm
            ));
        }
        if self.gains.is_empty()
            || self
                .gains
                .iter()
                .any(|g| !(g.is_finite() && (0.25..=4.0).contains(g)))
        {
            return bad(format!(
                "dot gains {:?} must be numbers in [0.25, 4]",
                self.gains
            ));
        }
        if self.inks.len() > pens || self.gains.len() > pens {
            return bad(format!("the chart has {pens} pens"));
        }
        let finite = [
            self.blur_px,
            self.noise,
            self.rotate_deg.abs(),
            self.perspective,
        ]
        .iter()
        .all(|v| v.is_finite() && *v >= 0.0);
        if !finite || self.blur_px > 20.0 || self.perspective > 0.2 || self.rotate_deg.abs() > 30.0
        {
            return bad(
                "blur, noise, rotation and perspective must be small numbers, at least 0".into(),
            );
        }
        Ok(())
    }
}

/// A splitmix64 stream: seeded noise without a dependency's API.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A standard normal (Box–Muller).
    fn normal(&mut self) -> f64 {
        let u = self.next().max(1e-300);
        let v = self.next();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A plotted sheet: linear RGB, `px_per_mm` px per mm, row-major.
struct Sheet {
    width: usize,
    height: usize,
    rgb: Vec<[f32; 3]>,
}

/// The chart as plotted (before scanning): linear RGB at `px_per_mm`.
fn plot(chart: &Chart, o: &ScanOptions) -> Sheet {
    let ppm = o.px_per_mm;
    let (w, h) = (
        (chart.spec.sheet_mm.0 * ppm).round() as usize,
        (chart.spec.sheet_mm.1 * ppm).round() as usize,
    );
    let mut rgb = vec![[o.paper[0] as f32, o.paper[1] as f32, o.paper[2] as f32]; w * h];
    let (sw, sh) = (w * SS, h * SS);
    let s = ppm * SS as f64;
    let mark_pen = chart.mark_pen();
    // Inks cover or multiply as on the chart's own paper (white when it
    // names none, whatever the simulated paper's tint).
    let paper8 = chart.spec.paper_rgb();
    for (i, pen) in chart.spec.pens.iter().enumerate() {
        let gain = o.gains[i.min(o.gains.len() - 1)];
        let nominal = crate::colour::pens::parse_hex(&pen.colour).unwrap_or([0, 0, 0]);
        let ink8 = o.inks.get(i).copied().unwrap_or(nominal);
        // An ink lighter than the paper covers it, a darker one multiplies.
        let opaque = crate::colour::pens::default_opacity(ink8, paper8) >= 1.0;
        let ink = ink8.map(|c| decode(f64::from(c) / 255.0));
        let grow = (gain - 1.0) * pen.width_mm / 2.0;
        let mut mask = vec![false; sw * sh];
        let mut disc = |(cx, cy): (f64, f64), r: f64| {
            let (cx, cy, r) = (cx * s, cy * s, r * s);
            let y0 = (cy - r).floor().max(0.0) as usize;
            let y1 = ((cy + r).ceil().max(0.0) as usize).min(sh);
            let x0 = (cx - r).floor().max(0.0) as usize;
            let x1 = ((cx + r).ceil().max(0.0) as usize).min(sw);
            for y in y0..y1 {
                let dy = y as f64 + 0.5 - cy;
                for x in x0..x1 {
                    let dx = x as f64 + 0.5 - cx;
                    if dx * dx + dy * dy <= r * r {
                        mask[y * sw + x] = true;
                    }
                }
            }
        };
        let mut squares = Vec::new();
        for p in chart.pen_patches(i) {
            for &d in &p.dots {
                disc(d, gain * pen.width_mm / 2.0);
            }
            if p.fraction >= 1.0 {
                squares.push((p.origin_mm, PATCH_MM));
            }
        }
        if i == mark_pen {
            for &m in &chart.marks {
                disc(m, MARK_RADIUS_MM + grow);
            }
            for ((x, y), on) in chart.bits() {
                if on {
                    squares.push(((x - BIT_MM / 2.0, y - BIT_MM / 2.0), BIT_MM));
                }
            }
        }
        for ((x, y), side) in squares {
            let (x0, y0) = (((x - grow) * s).max(0.0), ((y - grow) * s).max(0.0));
            let (x1, y1) = (
                ((x + side + grow) * s).min(sw as f64),
                ((y + side + grow) * s).min(sh as f64),
            );
            for yy in y0.round() as usize..y1.round() as usize {
                for xx in x0.round() as usize..x1.round() as usize {
                    mask[yy * sw + xx] = true;
                }
            }
        }
        for y in 0..h {
            for x in 0..w {
                let mut n = 0;
                for dy in 0..SS {
                    let row = (y * SS + dy) * sw + x * SS;
                    n += mask[row..row + SS].iter().filter(|&&m| m).count();
                }
                if n > 0 {
                    let cov = n as f64 / (SS * SS) as f64;
                    let px = &mut rgb[y * w + x];
                    for c in 0..3 {
                        px[c] = if opaque {
                            (f64::from(px[c]) * (1.0 - cov) + ink[c] * cov) as f32
                        } else {
                            px[c] * (1.0 - cov * (1.0 - ink[c])) as f32
                        };
                    }
                }
            }
        }
    }
    Sheet {
        width: w,
        height: h,
        rgb,
    }
}

/// A separable Gaussian blur of `sigma` px.
fn blur(sheet: &mut Sheet, sigma: f64) {
    if sigma <= 0.0 {
        return;
    }
    let r = (3.0 * sigma).ceil() as isize;
    let k: Vec<f32> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp() as f32)
        .collect();
    let sum: f32 = k.iter().sum();
    let k: Vec<f32> = k.iter().map(|v| v / sum).collect();
    let (w, h) = (sheet.width as isize, sheet.height as isize);
    for pass in 0..2 {
        let src = sheet.rgb.clone();
        for y in 0..h {
            for x in 0..w {
                let mut acc = [0.0f32; 3];
                for (j, kv) in k.iter().enumerate() {
                    let d = j as isize - r;
                    let (sx, sy) = if pass == 0 {
                        ((x + d).clamp(0, w - 1), y)
                    } else {
                        (x, (y + d).clamp(0, h - 1))
                    };
                    let p = src[(sy * w + sx) as usize];
                    for c in 0..3 {
                        acc[c] += kv * p[c];
                    }
                }
                sheet.rgb[(y * w + x) as usize] = acc;
            }
        }
    }
}

/// A synthetic scan of `chart` plotted as `o` says: the sheet rotated,
/// warped in perspective, on a background, blurred, with noise, as an
/// 8-bit sRGB image.
pub fn scan(chart: &Chart, o: &ScanOptions) -> Result<RgbImage> {
    o.check(chart.spec.pens.len())?;
    let mut sheet = plot(chart, o);
    blur(&mut sheet, o.blur_px);
    let (w, h) = (sheet.width as f64, sheet.height as f64);
    let (ow, oh) = ((w * 1.2).round(), (h * 1.2).round());
    let mut rng = Rng(o.seed);
    let (c, s) = (
        o.rotate_deg.to_radians().cos(),
        o.rotate_deg.to_radians().sin(),
    );
    let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)];
    let jitter = o.perspective * w.min(h);
    let to: Vec<(f64, f64)> = corners
        .iter()
        .map(|&(x, y)| {
            let (dx, dy) = (x - w / 2.0, y - h / 2.0);
            (
                ow / 2.0 + c * dx - s * dy + jitter * (2.0 * rng.next() - 1.0),
                oh / 2.0 + s * dx + c * dy + jitter * (2.0 * rng.next() - 1.0),
            )
        })
        .collect();
    let forward = Homography::from_points(&corners, &[to[0], to[1], to[2], to[3]])
        .ok_or_else(|| Error::InvalidParameter("degenerate warp".into()))?;
    let back = forward
        .inverse()
        .ok_or_else(|| Error::InvalidParameter("degenerate warp".into()))?;
    let (ow, oh) = (ow as u32, oh as u32);
    let mut out = RgbImage::new(ow, oh);
    let bg = o.background.map(|v| v as f32);
    for (u, v, px) in out.enumerate_pixels_mut() {
        let (x, y) = back.apply((f64::from(u) + 0.5, f64::from(v) + 0.5));
        let lin = bilinear(&sheet, x - 0.5, y - 0.5).unwrap_or(bg);
        for (out, l) in px.0.iter_mut().zip(lin) {
            let e = f64::from(linear_to_srgb(l.clamp(0.0, 1.0))) + o.noise * rng.normal();
            *out = (e.clamp(0.0, 1.0) * 255.0).round() as u8;
        }
    }
    Ok(out)
}

/// The sheet's colour at (x, y) px, bilinear; None outside it.
fn bilinear(sheet: &Sheet, x: f64, y: f64) -> Option<[f32; 3]> {
    let (w, h) = (sheet.width as f64, sheet.height as f64);
    if !(x >= -0.5 && y >= -0.5 && x <= w - 0.5 && y <= h - 0.5) {
        return None;
    }
    let (x, y) = (x.clamp(0.0, w - 1.0), y.clamp(0.0, h - 1.0));
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = (
        (x0 + 1).min(sheet.width - 1),
        (y0 + 1).min(sheet.height - 1),
    );
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let at = |xx: usize, yy: usize| sheet.rgb[yy * sheet.width + xx];
    let (a, b, c, d) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
    Some(std::array::from_fn(|k| {
        (a[k] * (1.0 - fx) + b[k] * fx) * (1.0 - fy) + (c[k] * (1.0 - fx) + d[k] * fx) * fy
    }))
}

/// `dots` as a pen with dot gain `gain` plots them: each `gain` × wider.
#[must_use]
pub fn plotted(dots: &[crate::stipple::Dot], gain: f64) -> Vec<crate::stipple::Dot> {
    dots.iter()
        .map(|d| crate::stipple::Dot {
            radius: d.radius * gain as f32,
            ..*d
        })
        .collect()
}
