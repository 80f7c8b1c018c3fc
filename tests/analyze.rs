//! The analysis measures: brute-force checks of d_min and coverage, CSV
//! reading, and a separation of a jittered grid from a Poisson-disk set
//! that would fail if the measures did not see the difference.

mod fixtures;

use fixtures::{jittered_grid, uniform_points};
use pixelpie::analyze::{self, CoverRadius, Domain, angles, csv, metrics, spectrum};
use pixelpie::sampler::{Params, cpu};

fn square(side: f64) -> Domain {
    Domain {
        width: side,
        height: side,
        periodic: false,
    }
}

fn brute_min_distance(points: &[[f64; 2]], domain: Domain) -> f64 {
    let mut best = f64::INFINITY;
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            best = best.min(metrics::distance(*a, *b, domain));
        }
    }
    best
}

#[test]
fn min_distance_matches_brute_force() {
    for (n, seed) in [(2, 1), (50, 2), (700, 3), (3000, 4)] {
        let pts = uniform_points(n, 300.0, 170.0, seed);
        for periodic in [false, true] {
            let d = Domain {
                width: 300.0,
                height: 170.0,
                periodic,
            };
            let got = metrics::min_distance(&pts, d).unwrap();
            assert_eq!(
                got,
                brute_min_distance(&pts, d),
                "n {n} periodic {periodic}"
            );
        }
    }
    // Clustered points: the grid's bounding box is tiny, the answer exact.
    let mut pts = uniform_points(500, 1.0, 1.0, 9);
    pts.push([1000.0, 1000.0]);
    assert_eq!(
        metrics::min_distance(&pts, square(2000.0)),
        Some(brute_min_distance(&pts, square(2000.0)))
    );
    assert_eq!(metrics::min_distance(&pts[..1], square(10.0)), None);
}

#[test]
fn uncovered_pixels_match_brute_force() {
    let pts = uniform_points(40, 64.0, 48.0, 5);
    let radii: Vec<f64> = (0..40).map(|i| 2.0 + (i % 7) as f64).collect();
    for periodic in [false, true] {
        let d = Domain {
            width: 64.0,
            height: 48.0,
            periodic,
        };
        let mut want = 0;
        for y in 0..48 {
            for x in 0..64 {
                let c = [x as f64 + 0.5, y as f64 + 0.5];
                if !pts
                    .iter()
                    .zip(&radii)
                    .any(|(p, r)| metrics::distance(*p, c, d) < *r)
                {
                    want += 1;
                }
            }
        }
        assert!(want > 0);
        assert_eq!(
            metrics::uncovered_pixels(&pts, CoverRadius::PerPoint(&radii), d).unwrap(),
            want
        );
    }
}

#[test]
fn csv_reader_detects_headers_and_delimiters() {
    let t = csv::parse("x,y,radius\n1,2,3\n4.5,5e1,6\n").unwrap();
    assert_eq!(t.points, vec![[1.0, 2.0], [4.5, 50.0]]);
    assert_eq!(t.radii, Some(vec![3.0, 6.0]));
    let t = csv::parse("# from another sampler\n\"Y\";\"X\"\n1;2\n").unwrap();
    assert_eq!(t.points, vec![[2.0, 1.0]]);
    let t = csv::parse("0.25 0.5\n0.75\t1\n").unwrap();
    assert_eq!(t.points, vec![[0.25, 0.5], [0.75, 1.0]]);
    assert!(t.radii.is_none());
    for bad in ["", "a,b\n1,2\n", "x,y\n1,nan\n", "x,y\n1\n", "x,y\n", "5\n"] {
        assert!(csv::parse(bad).is_err(), "{bad:?} parsed");
    }
    let err = csv::parse("x,y\n1,2\n3,oops\n").unwrap_err().to_string();
    assert!(err.contains("line 3") && err.contains("oops"), "{err}");
}

#[test]
fn angle_histogram_counts_both_directions_of_each_edge() {
    // A square lattice: Delaunay edges along the axes and one diagonal per cell.
    let pts: Vec<[f64; 2]> = (0..100)
        .map(|i| [(i % 10) as f64, (i / 10) as f64])
        .collect();
    let a = angles::delaunay_angles(&pts);
    let h = angles::histogram(&a, 360);
    assert_eq!(a.len(), 2 * (2 * 9 * 10 + 81));
    assert_eq!(h[0], h[180]);
    assert_eq!(h[90], h[270]);
    assert_eq!(h[0] + h[90], 2 * 90);
    assert_eq!(h.iter().sum::<u64>() as usize, a.len());
}

struct Measures {
    rho: f64,
    angle_std: f64,
    peak_power: f64,
    low_power: f64,
    max_anisotropy_db: f64,
}

fn measure(points: &[[f64; 2]], side: f64) -> Measures {
    let r = analyze::report(points, square(side), None).unwrap();
    let p = spectrum::periodogram(
        points,
        (side, side),
        spectrum::default_max_frequency(points.len()),
    );
    let radial = spectrum::radial(&p);
    let s = spectrum::summary(&radial);
    // Mean power over rings below 60% of the hexagonal spacing's frequency.
    let f_hex = (3f64.sqrt() * points.len() as f64 / 2.0).sqrt();
    let low: Vec<f64> = radial
        .frequency
        .iter()
        .zip(&radial.power)
        .filter(|(f, _)| **f >= 2.0 && **f < 0.6 * f_hex)
        .map(|(_, p)| *p)
        .collect();
    // Anisotropy above a tenth of that frequency (the lowest rings are a
    // handful of samples, dominated by the domain's edges).
    let max_aniso = radial
        .frequency
        .iter()
        .zip(&radial.anisotropy_db)
        .filter(|(f, a)| **f >= 0.1 * f_hex && a.is_finite())
        .map(|(_, a)| *a)
        .fold(f64::NEG_INFINITY, f64::max);
    Measures {
        rho: r.rho.unwrap(),
        angle_std: r.angle_std.unwrap(),
        peak_power: s.peak_power,
        low_power: low.iter().sum::<f64>() / low.len() as f64,
        max_anisotropy_db: max_aniso,
    }
}

fn show(name: &str, n: usize, m: &Measures) {
    eprintln!(
        "{name} ({n} pts): rho {:.3}, angle std {:.1}, peak power {:.2}, low power {:.3}, max anisotropy {:.1} dB",
        m.rho, m.angle_std, m.peak_power, m.low_power, m.max_anisotropy_db
    );
}

#[test]
fn analysis_separates_jittered_grids_from_a_poisson_disk_set() {
    let side = 512u32;
    let pd: Vec<[f64; 2]> = cpu::sample(
        &Params::new(side, side).with_radius(9.0),
        Default::default(),
    )
    .unwrap()
    .points
    .iter()
    .map(|p| [f64::from(p.x), f64::from(p.y)])
    .collect();
    let n = (pd.len() as f64).sqrt().round() as usize;
    let stratified = jittered_grid(n, f64::from(side), 1.0, 11);
    let half = jittered_grid(n, f64::from(side), 0.5, 12);
    let a = measure(&pd, f64::from(side));
    let b = measure(&stratified, f64::from(side));
    let c = measure(&half, f64::from(side));
    show("Poisson disk", pd.len(), &a);
    show("jittered grid, full cell", stratified.len(), &b);
    show("jittered grid, half cell", half.len(), &c);
    // ρ: a maximal set keeps its points apart, a stratified grid does not.
    assert!(a.rho > 0.65 && b.rho < 0.3, "rho {} vs {}", a.rho, b.rho);
    // Spectrum: blue noise has a peak above white noise and little power
    // below it; the stratified grid has no peak and more low-frequency power.
    assert!(a.peak_power > 1.4 && b.peak_power < 1.25);
    assert!(a.low_power < 0.5 * b.low_power);
    // A half-jittered grid keeps the lattice: spikes in the spectrum (high
    // anisotropy) and neighbours along the axes (high angle std).
    assert!(c.max_anisotropy_db > a.max_anisotropy_db + 6.0);
    assert!(
        c.angle_std > 2.0 * a.angle_std,
        "angle std {} vs {}",
        c.angle_std,
        a.angle_std
    );
    // Poisson-disk angles are close to Poisson counts: std ≈ sqrt(mean).
    let mean = 2.0
        * analyze::report(&pd, square(f64::from(side)), None)
            .unwrap()
            .angle_edges as f64
        / 360.0;
    assert!(
        a.angle_std < 1.5 * mean.sqrt(),
        "{} vs {}",
        a.angle_std,
        mean.sqrt()
    );
}

#[test]
fn pixelpie_sets_are_maximal_and_measured_as_such() {
    let set = cpu::sample(&Params::new(200, 150).with_radius(6.0), Default::default()).unwrap();
    let pts: Vec<[f64; 2]> = set
        .points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    let d = Domain {
        width: 200.0,
        height: 150.0,
        periodic: false,
    };
    let r = analyze::report(&pts, d, Some(CoverRadius::Uniform(6.0))).unwrap();
    assert_eq!(r.uncovered_pixels, Some(0));
    // Darts test conflicts at their pixel's centre: half a diagonal of slack.
    assert!(r.min_distance.unwrap() >= 6.0 - std::f64::consts::FRAC_1_SQRT_2);
    // RSA saturation density is 0.547; a maximal set on a finite domain is near it.
    let density = r.density.unwrap();
    assert!((0.45..0.6).contains(&density), "density {density}");
    // Half the radius leaves holes.
    let r = analyze::report(&pts, d, Some(CoverRadius::Uniform(3.0))).unwrap();
    assert!(r.uncovered_pixels.unwrap() > 1000);
}
