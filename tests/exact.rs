//! Exact mode: the disk condition between the samples themselves, checked in
//! integers over every pair; maximality in the continuous domain, checked by
//! probes inside every pixel, by the union test, and by the largest empty
//! circle (Delaunay); the RSA density band; determinism across thread counts.

mod common;

use std::sync::Arc;

use pixelpie::analyze::{CoverRadius, Domain, gaps};
use pixelpie::sampler::exact::{frac_bits, union};
use pixelpie::sampler::{Control, Params, Point, Policy, RadiusMap, SampleSet, cpu};

use common::separation;

/// The points' positions in `f64`.
fn xy(set: &SampleSet) -> Vec<[f64; 2]> {
    set.points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect()
}

fn run(p: &Params) -> SampleSet {
    cpu::sample(p, Control::default()).unwrap()
}

/// A position or radius in the exact mode's units (1/2^F px), asserting that
/// the `f32` holds it exactly.
fn fine(v: f32, frac: u32) -> i64 {
    let s = f64::from(v) * f64::from(1u32 << frac);
    assert_eq!(s.fract(), 0.0, "{v} is not on the 2^-{frac} px grid");
    s as i64
}

/// Every pair (earlier i, later j) is at least f(r_i, r_j) apart, in
/// integers: |c_i − c_j|² >= f².
fn assert_disk_condition(set: &SampleSet, policy: Policy, periodic: bool) {
    let frac = frac_bits(set.width, set.height);
    let (pw, ph) = (i64::from(set.width) << frac, i64::from(set.height) << frac);
    let pts: Vec<(i64, i64, i64)> = set
        .points
        .iter()
        .map(|p| (fine(p.x, frac), fine(p.y, frac), fine(p.radius, frac)))
        .collect();
    let wrap = |d: i64, period: i64| {
        let d = d.abs();
        if periodic { d.min(period - d) } else { d }
    };
    for (j, b) in pts.iter().enumerate() {
        for a in &pts[..j] {
            let f = match policy {
                Policy::Prior => a.2,
                Policy::Current => b.2,
                Policy::Bigger => a.2.max(b.2),
                Policy::Smaller => a.2.min(b.2),
            };
            let (dx, dy) = (wrap(a.0 - b.0, pw), wrap(a.1 - b.1, ph));
            assert!(
                dx * dx + dy * dy >= f * f,
                "{policy:?}: pair {a:?} {b:?} closer than {f}"
            );
        }
    }
}

/// Probes a 5×5 grid of points in every pixel, corners and edges included:
/// each lies strictly within f(r_i, r(x)) of some sample, r(x) the radius of
/// the pixel it lies in.
fn assert_probes_covered(
    set: &SampleSet,
    policy: Policy,
    periodic: bool,
    radius_at: &dyn Fn(u32, u32) -> f64,
) {
    let (w, h) = (f64::from(set.width), f64::from(set.height));
    let delta = |a: f64, b: f64, p: f64| {
        let d = (a - b).abs();
        if periodic { d.min(p - d) } else { d }
    };
    for py in 0..set.height {
        for px in 0..set.width {
            for k in 0..25 {
                let (x, y) = (
                    f64::from(px) + f64::from(k % 5) / 4.0,
                    f64::from(py) + f64::from(k / 5) / 4.0,
                );
                if x > w || y > h {
                    continue;
                }
                let (cx, cy) = (
                    (x as u32).min(set.width - 1),
                    (y as u32).min(set.height - 1),
                );
                if x.fract() == 0.0 && x > 0.0 && (x as u32) < set.width && cx != x as u32 {
                    continue;
                }
                let r_x = radius_at(cx, cy);
                let covered = set.points.iter().any(|p| {
                    let d = delta(f64::from(p.x), x, w).hypot(delta(f64::from(p.y), y, h));
                    d < separation(policy, f64::from(p.radius), r_x)
                });
                assert!(
                    covered,
                    "{policy:?}: ({x}, {y}) in pixel ({cx}, {cy}) is uncovered"
                );
            }
        }
    }
}

/// Each pixel, as a closed cell, is covered by the union of the disks
/// f(r_i, r_pixel) (the `f64` union test, which errs towards "not covered").
fn assert_cells_covered(
    set: &SampleSet,
    policy: Policy,
    periodic: bool,
    radius_at: &dyn Fn(u32, u32) -> f64,
) {
    let (w, h) = (f64::from(set.width), f64::from(set.height));
    for py in 0..set.height {
        for px in 0..set.width {
            let r_p = radius_at(px, py);
            let (mx, my) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
            let disks: Vec<union::Disk> = set
                .points
                .iter()
                .map(|p| {
                    let (mut x, mut y) = (f64::from(p.x), f64::from(p.y));
                    if periodic {
                        x -= w * ((x - mx) / w).round();
                        y -= h * ((y - my) / h).round();
                    }
                    union::Disk {
                        x,
                        y,
                        r: separation(policy, f64::from(p.radius), r_p),
                    }
                })
                .filter(|d| (d.x - mx).hypot(d.y - my) < d.r + 1.0)
                .collect();
            let cell = (
                f64::from(px),
                f64::from(py),
                f64::from(px) + 1.0,
                f64::from(py) + 1.0,
            );
            assert!(
                union::covers(&disks, cell),
                "{policy:?}: pixel ({px}, {py}) not covered"
            );
        }
    }
}

fn uniform_any(w: u32, h: u32, r: f32, periodic: bool, seed: u64) -> SampleSet {
    run(&Params::new(w, h)
        .with_radius(r)
        .with_periodic(periodic)
        .with_seed(seed)
        .with_exact(true))
}

fn uniform(w: u32, h: u32, r: f32, periodic: bool, seed: u64) -> SampleSet {
    let set = uniform_any(w, h, r, periodic, seed);
    assert!(
        set.maximal() && set.stats.exact,
        "{w}x{h} r {r}: reported not maximal"
    );
    set
}

#[test]
fn uniform_sets_meet_the_disk_condition_and_leave_no_gap() {
    for (w, h, r, periodic) in [
        (160, 120, 8.5, false),
        (160, 120, 8.5, true),
        (90, 70, 2.0, false),
        (96, 96, 2.0, true),
        (101, 77, 3.3, false),
    ] {
        let set = uniform(w, h, r, periodic, 7);
        // The radius as the contract quantizes it (1/64 px).
        let r = set.points[0].radius;
        assert!((r - 3.3).abs() > 1e-3 || r == 211.0 / 64.0);
        assert_disk_condition(&set, Policy::Prior, periodic);
        assert_probes_covered(&set, Policy::Prior, periodic, &|_, _| f64::from(r));
        assert_cells_covered(&set, Policy::Prior, periodic, &|_, _| f64::from(r));
        // The largest empty circle (Delaunay, boundary mirrored or wrapped)
        // is smaller than r, and the closest pair at least r.
        let pts = xy(&set);
        let d = Domain {
            width: f64::from(w),
            height: f64::from(h),
            periodic,
        };
        let gap = gaps::largest_gap(&pts, d).unwrap();
        assert!(gap.radius < f64::from(r), "{w}x{h} r {r}: gap {gap:?}");
        let closest = pixelpie::analyze::metrics::min_distance(&pts, d).unwrap();
        assert!(closest >= f64::from(r), "closest pair {closest}");
        assert_eq!(
            gaps::uncovered_cells(&pts, CoverRadius::Uniform(f64::from(r)), d).unwrap(),
            0
        );
    }
}

#[test]
fn the_pixel_mode_fails_the_same_checks() {
    // The checks can fail: the pixel mode's sets break the disk condition
    // by up to √2/2 px and leave gaps larger than r.
    let set = run(&Params::new(160, 120).with_radius(8.5).with_seed(7));
    let pts = xy(&set);
    let d = Domain {
        width: 160.0,
        height: 120.0,
        periodic: false,
    };
    assert!(gaps::largest_gap(&pts, d).unwrap().radius > 8.5);
    assert!(pixelpie::analyze::metrics::min_distance(&pts, d).unwrap() < 8.5);
    assert!(gaps::uncovered_cells(&pts, CoverRadius::Uniform(8.5), d).unwrap() > 0);
}

fn maps(w: u32, h: u32) -> Vec<(&'static str, Vec<f32>)> {
    let step = (0..w * h)
        .map(|i| if i % w < w / 2 { 2.5 } else { 6.0 })
        .collect();
    let ramp = (0..w * h)
        .map(|i| 2.0 + 6.0 * ((i % w) as f32 / w as f32) + ((i / w) % 3) as f32 * 0.25)
        .collect();
    vec![("step", step), ("ramp", ramp)]
}

#[test]
fn radius_maps_under_every_policy_are_exact_and_maximal() {
    let (w, h) = (72u32, 56u32);
    for (name, radii) in maps(w, h) {
        let map = Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap());
        let radius_at = |x: u32, y: u32| f64::from(map.radius_px(x, y));
        for policy in Policy::ALL {
            for periodic in [false, true] {
                let p = Params::new(w, h)
                    .with_radius_map(map.clone())
                    .with_policy(policy)
                    .with_periodic(periodic)
                    .with_seed(3)
                    .with_exact(true);
                let set = run(&p);
                assert!(
                    set.maximal(),
                    "{name} {policy:?} periodic {periodic}: not maximal"
                );
                // Each point carries its own pixel's radius.
                for pt in &set.points {
                    assert_eq!(pt.radius, map.radius_px(pt.x as u32, pt.y as u32));
                }
                assert_disk_condition(&set, policy, periodic);
                assert_probes_covered(&set, policy, periodic, &radius_at);
                assert_cells_covered(&set, policy, periodic, &radius_at);
            }
        }
    }
}

fn density(points: &[Point], w: u32, h: u32) -> f64 {
    points
        .iter()
        .map(|p| std::f64::consts::PI * (f64::from(p.radius) / 2.0).powi(2))
        .sum::<f64>()
        / f64::from(w * h)
}

#[test]
fn uniform_periodic_sets_land_at_the_rsa_jamming_density() {
    // Zhang & Torquato 2013: 0.547070; the band is the issue's ±0.004, for
    // the mean over seeds of sets of 20K to 45K points. (A void finer than
    // the position grid, which a set may keep, changes no density.)
    for (side, r) in [(512u32, 2.0f32), (640, 3.3), (1536, 8.5)] {
        let mean = (1..=3)
            .map(|seed| density(&uniform_any(side, side, r, true, seed).points, side, side))
            .sum::<f64>()
            / 3.0;
        assert!((mean - 0.5471).abs() <= 0.004, "r {r}: density {mean}");
    }
}

#[test]
fn same_points_on_one_thread_and_two() {
    let p = Params::new(300, 200)
        .with_radius_map(Arc::new(
            RadiusMap::from_pixels(300, 200, &maps(300, 200)[1].1).unwrap(),
        ))
        .with_policy(Policy::Smaller)
        .with_seed(11)
        .with_exact(true);
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| run(&p).points)
    };
    let one = on(1);
    assert!(one.len() > 500);
    assert_eq!(one, on(2));
    assert_eq!(one, run(&p).points);
    // The seed matters.
    assert_ne!(one, run(&p.clone().with_seed(12)).points);
}

#[test]
fn a_run_cut_short_is_reported_not_maximal() {
    let set = run(&Params::new(200, 200)
        .with_radius(3.0)
        .with_exact(true)
        .with_max_iterations(3));
    assert!(!set.maximal() && !set.stats.maximal && set.stats.empty_left > 0);
    assert_eq!(set.iterations(), 3);
}

#[test]
fn exact_mode_without_a_gpu_fails_on_gpu_and_falls_back_on_auto() {
    use pixelpie::backend::{BackendChoice, Notice, sample_with};
    let p = Params::new(64, 64).with_radius(4.0).with_exact(true);
    let err = sample_with(
        &p,
        BackendChoice::Gpu,
        Err("no adapter here".into()),
        Control::default(),
        &mut |_| {},
    )
    .unwrap_err();
    assert!(
        err.is_backend() && err.to_string().contains("no adapter here"),
        "{err}"
    );
    let mut notices = Vec::new();
    let set = sample_with(
        &p,
        BackendChoice::Auto,
        Err("no adapter here".into()),
        Control::default(),
        &mut |n| notices.push(n),
    )
    .unwrap();
    assert_eq!(set.points, run(&p).points);
    assert!(set.stats.exact && set.stats.backend == pixelpie::sampler::BackendKind::Cpu);
    assert!(matches!(&notices[..], [Notice::Fallback(_)]), "{notices:?}");
}

#[test]
fn a_void_finer_than_the_position_grid_is_repaired() {
    // r = 2 px on a 512² torus: positions are 2^-15 px apart, and seed 1
    // once left a void narrower than that. The repair takes back the
    // sample that closed it and fills the area again: the set is then
    // maximal by every independent check, and still meets the disk
    // condition.
    let set = uniform(512, 512, 2.0, true, 1);
    assert!(set.stats.repaired > 0, "this seed needs a repair");
    assert_eq!(set.stats.empty_left, 0);
    assert_disk_condition(&set, Policy::Smaller, true);
    let pts = xy(&set);
    let d = Domain {
        width: 512.0,
        height: 512.0,
        periodic: true,
    };
    assert_eq!(
        gaps::uncovered_cells(&pts, CoverRadius::Uniform(2.0), d).unwrap(),
        0
    );
    let gap = gaps::largest_gap(&pts, d).unwrap().radius;
    assert!(gap < 2.0, "gap {gap}");
    // Deterministic, repair included.
    assert_eq!(set.points, uniform(512, 512, 2.0, true, 1).points);
}

#[test]
fn a_cancel_flag_already_set_stops_before_the_first_iteration() {
    use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
    let cancel = AtomicBool::new(true);
    let calls = AtomicU32::new(0);
    let progress = |_| {
        calls.fetch_add(1, Ordering::Relaxed);
    };
    for exact in [false, true] {
        let ctl = Control::new().with_progress(&progress).with_cancel(&cancel);
        let r = cpu::sample(&Params::new(64, 64).with_radius(3.0).with_exact(exact), ctl);
        assert!(matches!(r, Err(pixelpie::sampler::Error::Cancelled)));
    }
    assert_eq!(calls.load(Ordering::Relaxed), 0, "no iteration ran");
}

#[test]
fn progress_comes_after_every_iteration_and_a_cancel_stops_the_next() {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, Ordering};
    for exact in [false, true] {
        let p = Params::new(300, 200).with_radius(2.5).with_exact(exact);
        // Uncancelled: one report per iteration, counts growing, the last
        // one the set itself.
        let seen = Mutex::new(Vec::new());
        let progress = |q: pixelpie::sampler::Progress| seen.lock().unwrap().push(q);
        let set = cpu::sample(&p, Control::new().with_progress(&progress)).unwrap();
        let seen = seen.into_inner().unwrap();
        assert_eq!(seen.len() as u32, set.iterations());
        assert!(
            seen.windows(2)
                .all(|w| w[0].iteration + 1 == w[1].iteration && w[0].points <= w[1].points)
        );
        let last = seen.last().unwrap();
        assert_eq!((last.points, last.empty_pixels), (set.points.len(), 0));
        assert!(set.iterations() > 3);
        // Cancelled from the second report on: exactly two iterations ran.
        let cancel = AtomicBool::new(false);
        let calls = Mutex::new(0u32);
        let progress = |_| {
            let mut n = calls.lock().unwrap();
            *n += 1;
            if *n == 2 {
                cancel.store(true, Ordering::Relaxed);
            }
        };
        let r = cpu::sample(
            &p,
            Control::new().with_progress(&progress).with_cancel(&cancel),
        );
        assert!(matches!(r, Err(pixelpie::sampler::Error::Cancelled)));
        assert_eq!(*calls.lock().unwrap(), 2, "exact {exact}");
    }
}
