//! LBG stippling (Deussen, Spicker & Zheng, "Weighted Linde-Buzo-Gray
//! Stippling", SIGGRAPH Asia 2017) as a peer, written from the paper and
//! the authors' public code's defaults, kept out of the library.
//!
//! From a single point, each iteration computes the Voronoi cells of the
//! points on the pixel grid and each cell's mass (the sum of the density,
//! 1 − the display grey, over its pixels). A cell whose mass exceeds
//! (1 + h/2) × the dot's area splits its point in two along its principal
//! axis; one under (1 − h/2) × the area loses its point; any other moves
//! its point to the cell's centroid. The hysteresis h rises by Δh each
//! iteration (0.6 and 0.01, the authors' defaults), and the loop stops when
//! nothing splits or merges (or after 50 iterations). The dots are all the
//! dot's area, which sets the count: the area is the picture's mass over
//! the count asked.
//!
//! ```sh
//! cargo run --release --example lbg -- assets/astronaut.jpg 10000 lbg.svg
//! pixelpie fidelity assets/astronaut.jpg lbg.svg
//! # LBG started from a PixelPie set instead of one point:
//! pixelpie stipple assets/astronaut.jpg --points 10000 -o start.csv
//! cargo run --release --example lbg -- assets/astronaut.jpg 10000 seeded.svg start.csv
//! ```

use std::path::Path;

use pixelpie::importance::{ImportanceMap, linear_to_srgb};
use pixelpie::stipple::{Dot, raster, svg};
use rayon::prelude::*;

/// The hysteresis at the start (the authors' default).
const HYSTERESIS: f64 = 0.6;
/// The hysteresis's rise per iteration (the authors' default).
const HYSTERESIS_STEP: f64 = 0.01;
/// The most iterations.
const MAX_ITERATIONS: usize = 50;

/// A density on a pixel grid (1 is black ink).
struct Density {
    width: usize,
    height: usize,
    values: Vec<f32>,
}

/// A Voronoi cell's density moments.
#[derive(Clone, Copy, Default, Debug)]
struct Cell {
    mass: f64,
    x: f64,
    y: f64,
    xx: f64,
    xy: f64,
    yy: f64,
}

/// What one iteration did.
#[derive(Debug, PartialEq, Eq)]
struct Step {
    splits: usize,
    merges: usize,
}

/// What a cell of mass `mass` does to its point under hysteresis `h` for
/// dots of area `area`.
#[derive(Debug, PartialEq, Eq)]
enum Fate {
    Split,
    Merge,
    Move,
}

fn fate(mass: f64, area: f64, h: f64) -> Fate {
    if mass < (1.0 - h / 2.0) * area {
        Fate::Merge
    } else if mass > (1.0 + h / 2.0) * area {
        Fate::Split
    } else {
        Fate::Move
    }
}

/// Points bucketed on a grid, for the nearest point to a pixel.
struct Grid {
    side: f64,
    cols: usize,
    rows: usize,
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(points: &[[f64; 2]], width: usize, height: usize) -> Self {
        let side = ((width * height) as f64 / points.len().max(1) as f64)
            .sqrt()
            .max(1.0);
        let cols = (width as f64 / side).ceil() as usize;
        let rows = (height as f64 / side).ceil() as usize;
        let mut cells = vec![Vec::new(); cols * rows];
        for (i, p) in points.iter().enumerate() {
            let c = ((p[0] / side) as usize).min(cols - 1);
            let r = ((p[1] / side) as usize).min(rows - 1);
            cells[r * cols + c].push(i as u32);
        }
        Self {
            side,
            cols,
            rows,
            cells,
        }
    }

    /// The nearest point to (x, y): rings of grid cells outward until no
    /// nearer point can lie beyond.
    fn nearest(&self, points: &[[f64; 2]], x: f64, y: f64) -> usize {
        let (c0, r0) = (
            ((x / self.side) as isize).min(self.cols as isize - 1),
            ((y / self.side) as isize).min(self.rows as isize - 1),
        );
        let (mut best, mut best_d) = (0usize, f64::INFINITY);
        for ring in 0.. {
            let ring = ring as isize;
            for r in r0 - ring..=r0 + ring {
                for c in c0 - ring..=c0 + ring {
                    let on_ring = (r - r0).abs() == ring || (c - c0).abs() == ring;
                    if !on_ring
                        || r < 0
                        || c < 0
                        || r >= self.rows as isize
                        || c >= self.cols as isize
                    {
                        continue;
                    }
                    for &i in &self.cells[r as usize * self.cols + c as usize] {
                        let p = points[i as usize];
                        let d = (p[0] - x).powi(2) + (p[1] - y).powi(2);
                        if d < best_d {
                            (best, best_d) = (i as usize, d);
                        }
                    }
                }
            }
            // Every point beyond this ring is farther than ring × side.
            let reach = ring as f64 * self.side;
            if best_d.is_finite() && best_d <= reach * reach {
                break;
            }
            if ring as usize > self.cols + self.rows {
                break;
            }
        }
        best
    }
}

/// Each point's Voronoi cell's moments over `density`.
fn cells(points: &[[f64; 2]], density: &Density) -> Vec<Cell> {
    let grid = Grid::new(points, density.width, density.height);
    (0..density.height)
        .into_par_iter()
        .fold(
            || vec![Cell::default(); points.len()],
            |mut acc, y| {
                for x in 0..density.width {
                    let rho = f64::from(density.values[y * density.width + x]);
                    if rho <= 0.0 {
                        continue;
                    }
                    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                    let c = &mut acc[grid.nearest(points, px, py)];
                    c.mass += rho;
                    c.x += rho * px;
                    c.y += rho * py;
                    c.xx += rho * px * px;
                    c.xy += rho * px * py;
                    c.yy += rho * py * py;
                }
                acc
            },
        )
        .reduce(
            || vec![Cell::default(); points.len()],
            |mut a, b| {
                for (p, q) in a.iter_mut().zip(&b) {
                    p.mass += q.mass;
                    p.x += q.x;
                    p.y += q.y;
                    p.xx += q.xx;
                    p.xy += q.xy;
                    p.yy += q.yy;
                }
                a
            },
        )
}

/// One LBG iteration under hysteresis `h`: the new points and what split
/// and merged.
fn iterate(points: &[[f64; 2]], density: &Density, area: f64, h: f64) -> (Vec<[f64; 2]>, Step) {
    let mut next = Vec::with_capacity(points.len() * 2);
    let mut step = Step {
        splits: 0,
        merges: 0,
    };
    for (p, c) in points.iter().zip(cells(points, density)) {
        match fate(c.mass, area, h) {
            Fate::Merge => step.merges += 1,
            Fate::Move => next.push([c.x / c.mass, c.y / c.mass]),
            Fate::Split => {
                step.splits += 1;
                let (cx, cy) = (c.x / c.mass, c.y / c.mass);
                // The principal axis of the cell's density.
                let (vxx, vxy, vyy) = (
                    c.xx / c.mass - cx * cx,
                    c.xy / c.mass - cx * cy,
                    c.yy / c.mass - cy * cy,
                );
                let half = (vxx - vyy) / 2.0;
                let lambda = (vxx + vyy) / 2.0 + (half * half + vxy * vxy).sqrt();
                let (ex, ey) = if vxy.abs() > 1e-12 {
                    (lambda - vyy, vxy)
                } else if vxx >= vyy {
                    (1.0, 0.0)
                } else {
                    (0.0, 1.0)
                };
                let norm = ex.hypot(ey).max(1e-12);
                let s = 0.5 * lambda.max(0.25).sqrt();
                let (dx, dy) = (ex / norm * s, ey / norm * s);
                let _ = p;
                next.push([cx - dx, cy - dy]);
                next.push([cx + dx, cy + dy]);
            }
        }
    }
    (next, step)
}

/// LBG stippling of `density` toward `n` dots: the points, the dots'
/// radius, and the iterations run.
fn lbg(density: &Density, n: usize) -> (Vec<[f64; 2]>, f64, usize) {
    let centre = vec![[density.width as f64 / 2.0, density.height as f64 / 2.0]];
    lbg_from(density, n, centre)
}

/// [`lbg`] from the points `start` (LBG's own start is one point; a
/// PixelPie set starts it near its end).
fn lbg_from(density: &Density, n: usize, start: Vec<[f64; 2]>) -> (Vec<[f64; 2]>, f64, usize) {
    let mass: f64 = density.values.iter().map(|&v| f64::from(v)).sum();
    let area = mass / n.max(1) as f64;
    let mut points = start;
    let mut h = HYSTERESIS;
    let mut iterations = 0;
    while iterations < MAX_ITERATIONS {
        let (next, step) = iterate(&points, density, area, h);
        points = next;
        iterations += 1;
        h += HYSTERESIS_STEP;
        if step.splits == 0 && step.merges == 0 {
            break;
        }
    }
    (points, (area / std::f64::consts::PI).sqrt(), iterations)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (photo, n, out, seed) = match args.as_slice() {
        [photo, n, out] => (photo, n, out, None),
        [photo, n, out, seed] => (photo, n, out, Some(seed)),
        _ => return Err("usage: lbg PHOTO DOTS OUT.svg|OUT.png [START.csv]".into()),
    };
    let n: usize = n.parse()?;
    let t0 = std::time::Instant::now();
    let map = ImportanceMap::open(Path::new(photo), None)?;
    let (w, h) = pixelpie::job::default_domain(map.width(), map.height(), n);
    let map = map.resized(w, h)?;
    // Ink where the display grey is dark, as PixelPie's default tones.
    let density = Density {
        width: w as usize,
        height: h as usize,
        values: map
            .values()
            .iter()
            .map(|&v| 1.0 - linear_to_srgb(v))
            .collect(),
    };
    // A start: the x,y columns of a point set on the same domain (e.g.
    // `pixelpie stipple PHOTO --points N -o start.csv`).
    let (points, radius, iterations) = match seed {
        None => lbg(&density, n),
        Some(csv) => {
            let start: Vec<[f64; 2]> = std::fs::read_to_string(csv)?
                .lines()
                .skip(1)
                .filter_map(|l| {
                    let mut f = l.split(',');
                    Some([f.next()?.parse().ok()?, f.next()?.parse().ok()?])
                })
                .collect();
            lbg_from(&density, n, start)
        }
    };
    let dots: Vec<Dot> = points
        .iter()
        .map(|p| Dot {
            x: p[0] as f32,
            y: p[1] as f32,
            radius: radius as f32,
        })
        .collect();
    let mut file = std::io::BufWriter::new(std::fs::File::create(out)?);
    if out.ends_with(".png") {
        // The drawing as `pixelpie stipple` draws a PNG.
        let img = raster::render(&dots, (w, h), 1.0)?;
        raster::write_png(&mut file, &img, dots.len())?;
    } else {
        svg::write(&mut file, &dots, &svg::SvgOptions::new((w, h)))?;
    }
    eprintln!(
        "lbg: {} dots of radius {radius:.2} px on {w}x{h} in {iterations} iterations, {:.2} s",
        dots.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(w: usize, h: usize, v: f32) -> Density {
        Density {
            width: w,
            height: h,
            values: vec![v; w * h],
        }
    }

    #[test]
    fn a_cell_splits_above_and_merges_below_its_hysteresis_band() {
        // Dots of area 100 under h = 0.6: the band is 70..130.
        assert_eq!(fate(131.0, 100.0, 0.6), Fate::Split);
        assert_eq!(fate(129.0, 100.0, 0.6), Fate::Move);
        assert_eq!(fate(71.0, 100.0, 0.6), Fate::Move);
        assert_eq!(fate(69.0, 100.0, 0.6), Fate::Merge);
        // A wider band (the hysteresis risen) keeps more.
        assert_eq!(fate(131.0, 100.0, 0.7), Fate::Move);
        assert_eq!(fate(66.0, 100.0, 0.7), Fate::Move);
    }

    #[test]
    fn one_point_on_a_heavy_cell_splits_along_its_long_axis() {
        // A 40×10 strip: the split points lie apart along x.
        let d = uniform(40, 10, 1.0);
        let (next, step) = iterate(&[[20.0, 5.0]], &d, 100.0, 0.6);
        assert_eq!(
            step,
            Step {
                splits: 1,
                merges: 0
            }
        );
        assert_eq!(next.len(), 2);
        assert!((next[0][0] - next[1][0]).abs() > 5.0 * (next[0][1] - next[1][1]).abs());
        // A cell lighter than the band loses its point.
        let (next, step) = iterate(&[[20.0, 5.0]], &uniform(40, 10, 0.1), 100.0, 0.6);
        assert_eq!((next.len(), step.merges), (0, 1));
    }

    #[test]
    fn the_loop_stops_when_nothing_splits_or_merges_near_the_count() {
        let d = uniform(200, 200, 0.5);
        let (points, _, iterations) = lbg(&d, 400);
        assert!(iterations < MAX_ITERATIONS, "{iterations} iterations");
        // The last iteration split and merged nothing: every cell's mass was
        // in its band, so the count is the mass over the dot's area within
        // the band. (From one point, by doubling on a flat picture: 512.)
        let (mass, area) = (200.0 * 200.0 * 0.5, 200.0 * 200.0 * 0.5 / 400.0);
        let h = HYSTERESIS + HYSTERESIS_STEP * (iterations - 1) as f64;
        let n = points.len() as f64;
        assert!(
            n * (1.0 - h / 2.0) * area <= mass && mass <= n * (1.0 + h / 2.0) * area,
            "{n} points, h {h}"
        );
        // Without the hysteresis's rise it would not have stopped as soon.
        let mut p = vec![[100.0, 100.0]];
        let mut still = 0;
        for _ in 0..iterations {
            let (next, step) = iterate(&p, &d, area, HYSTERESIS / 4.0);
            p = next;
            still = step.splits + step.merges;
        }
        assert!(still > 0, "a narrow band keeps splitting and merging");
    }
}
