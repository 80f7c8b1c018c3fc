//! Golden outputs: the exact points (and, for drawings, the dots and the
//! SVG bytes) of a fixed set of cases, pinned by hash. Any change that moves
//! a single point, or a single dot's radius, fails here, even when every
//! sampling property still holds.
//!
//! When a change is meant to move the output, run
//! `PIXELPIE_GOLDEN_PRINT=1 cargo test --release --test golden -- --nocapture`,
//! paste the printed table over [`GOLDEN`], and say in the commit why the
//! points moved.
//!
//! The sampler cases run on the CPU and, where an adapter exists, on the GPU
//! on both S1 paths, against the same table (the backends agree bit for
//! bit). With `PIXELPIE_EXPECT_GPU=1` (set by `.ci/run`) a missing adapter
//! fails the GPU test instead of skipping it.

mod common;

use std::path::Path;
use std::sync::Arc;

use common::smooth_radii;
use pixelpie::colour::PenSet;
use pixelpie::job::{Correction, Job, Order, Stipple};
use pixelpie::sampler::{ClassRadii, Control, Params, Point, Policy, RadiusMap, SampleSet, cpu};

/// (case, points, hash): the pinned outputs. Update as the module doc says.
#[rustfmt::skip]
const GOLDEN: &[(&str, usize, u64)] = &[
    ("grey stipple", 2996, 0x701690f6c8fecaf5),
    ("grey stipple, SVG", 2996, 0x8a15770507bf13e9),
    ("grey stipple, spacing radius, relax 0, correction off", 2996, 0xf8c488c2c4957557),
    ("grey stipple, spacing radius, relax 0, correction off, SVG", 2996, 0x71ddae12be9ae11a),
    ("grey stipple, relax 3, correction off", 2996, 0xa2be90fe14536dd4),
    ("grey stipple, relax 3, correction off, SVG", 2996, 0x3b401120eb2a0e5c),
    ("grey stipple, TSP", 2996, 0xbcc3a1dc23427560),
    ("grey stipple, TSP, SVG", 2996, 0xb4e7c298451e1963),
    ("grey stipple, periodic", 3051, 0x98b9739a888b56a6),
    ("grey stipple, periodic, SVG", 3051, 0x2d5b136e7f4cce69),
    ("CMYK stipple", 3076, 0xe58e77225c7ad29a),
    ("CMYK stipple, SVG", 3076, 0xc155ec93a7c13d4a),
    ("CMYK stipple, relax 0", 3076, 0xd33b8f05dac124bf),
    ("CMYK stipple, relax 0, SVG", 3076, 0x7c32950c26b59772),
    ("uniform", 1897, 0xdbb96cf27fff9ec9),
    ("uniform, periodic", 1849, 0x7704e67eaecaa3f4),
    ("uniform, no sub-pixel bits", 1847, 0x8c3e8515ae42bd94),
    ("uniform, exact", 2038, 0xc7c88e682c325565),
    ("map, exact", 9079, 0xdb1b100853f7bc46),
    ("map, Prior", 7764, 0x9bc2c6e2f759760c),
    ("map, Current", 7744, 0x845b66f3b99e6b48),
    ("map, Bigger", 7779, 0x0ad93a8d43de70dd),
    ("map, Smaller", 7903, 0x69d2b71f5f4d36bd),
    ("3 classes, Smaller", 4984, 0x220a28cee1d78bc2),
];

/// FNV-1a, 64 bits: stable across platforms and Rust versions.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn point(&mut self, p: &Point) {
        for v in [p.x.to_bits(), p.y.to_bits(), p.radius.to_bits(), p.class] {
            self.bytes(&v.to_le_bytes());
        }
    }
}

fn hash_points(points: &[Point]) -> u64 {
    let mut h = Fnv::new();
    for p in points {
        h.point(p);
    }
    h.0
}

/// The points of a drawing, in drawing order, with each dot's drawn radius.
fn hash_drawing(job: &Job, drawing: &Stipple) -> u64 {
    let mut h = Fnv::new();
    for (p, d) in drawing.points.iter().zip(job.dots(drawing)) {
        h.point(p);
        for v in [d.x, d.y, d.radius] {
            h.bytes(&v.to_bits().to_le_bytes());
        }
    }
    h.0
}

/// The sampler's cases: uniform, periodic, exact, each policy on a radius
/// map, and several classes together.
fn sampler_cases() -> Vec<(String, Params)> {
    let (w, h) = (400, 300);
    let base = Params::new(w, h).with_seed(11);
    let map = Arc::new(RadiusMap::from_pixels(w, h, &smooth_radii(w, h)).expect("radius map"));
    let mut cases = vec![
        ("uniform".to_owned(), base.clone().with_radius(6.5)),
        (
            "uniform, periodic".to_owned(),
            base.clone().with_radius(6.5).with_periodic(true),
        ),
        (
            "uniform, no sub-pixel bits".to_owned(),
            base.clone().with_radius(6.5).with_subpixel_bits(0),
        ),
        (
            "uniform, exact".to_owned(),
            base.clone().with_radius(6.5).with_exact(true),
        ),
        (
            "map, exact".to_owned(),
            base.clone()
                .with_radius_map(map.clone())
                .with_policy(Policy::Smaller)
                .with_exact(true),
        ),
    ];
    for policy in Policy::ALL {
        cases.push((
            format!("map, {policy:?}"),
            base.clone()
                .with_radius_map(map.clone())
                .with_policy(policy),
        ));
    }
    let classes: Vec<Vec<f32>> = (0..3)
        .map(|k| {
            (0..w * h)
                .map(|i| 4.0 + (k as f32) + 3.0 * ((i % w) as f32 / w as f32))
                .collect()
        })
        .collect();
    let classes = ClassRadii::new(w, h, &classes).expect("classes");
    cases.push((
        "3 classes, Smaller".to_owned(),
        base.with_classes(Arc::new(classes)),
    ));
    cases
}

/// The drawings' cases: grey, grey as earlier versions drew it, grey
/// relaxed without the correction, grey in TSP order, grey periodic, CMYK,
/// CMYK not relaxed.
fn drawing_cases() -> Vec<(String, &'static str, Job)> {
    let job = |f: &dyn Fn(&mut Job)| {
        let mut j = Job::default();
        j.points = Some(3000);
        f(&mut j);
        j
    };
    let grey = job(&|_| {});
    // The drawings of earlier versions: sized for the sample radius, not
    // relaxed, not corrected by rendering (their hashes are the grey
    // stipple's of before: the points unchanged, the sizes as then).
    let old = job(&|j| {
        j.spacing = pixelpie::job::Spacing::Radius;
        j.relax = Some(0);
        j.correction = Correction::Off;
    });
    let relaxed = job(&|j| {
        j.relax = Some(3);
        j.correction = Correction::Off;
    });
    let tsp = job(&|j| j.order = Order::Tsp);
    // Periodic drawings relax on pixel cells, whose ties go by the dots'
    // order: pinned, so that a change of that order shows.
    let periodic = job(&|j| j.sampler.periodic = true);
    let cmyk = job(&|j| j.pens = Some(PenSet::cmyk()));
    // Colour is relaxed pen by pen by default: the unrelaxed colour path
    // (the pens spread apart only) pinned on its own.
    let cmyk_plain = job(&|j| {
        j.pens = Some(PenSet::cmyk());
        j.relax = Some(0);
    });
    vec![
        ("grey stipple".into(), "assets/default.png", grey),
        (
            "grey stipple, spacing radius, relax 0, correction off".into(),
            "assets/default.png",
            old,
        ),
        (
            "grey stipple, relax 3, correction off".into(),
            "assets/default.png",
            relaxed,
        ),
        ("grey stipple, TSP".into(), "assets/default.png", tsp),
        (
            "grey stipple, periodic".into(),
            "assets/default.png",
            periodic,
        ),
        ("CMYK stipple".into(), "assets/astronaut.jpg", cmyk),
        (
            "CMYK stipple, relax 0".into(),
            "assets/astronaut.jpg",
            cmyk_plain,
        ),
    ]
}

/// Checks `got` against the table; with `PIXELPIE_GOLDEN_PRINT=1`, prints
/// the table's line instead of failing.
fn check(results: &[(String, usize, u64)]) {
    let print = std::env::var("PIXELPIE_GOLDEN_PRINT").as_deref() == Ok("1");
    let mut wrong = Vec::new();
    for (case, n, hash) in results {
        if print {
            println!("    ({case:?}, {n}, {hash:#018x}),");
            continue;
        }
        match GOLDEN.iter().find(|(c, _, _)| c == case) {
            Some(&(_, gn, gh)) if (gn, gh) == (*n, *hash) => {}
            Some(&(_, gn, gh)) => wrong.push(format!(
                "{case}: {n} points, hash {hash:#018x}; the table has {gn} points, {gh:#018x}"
            )),
            None => wrong.push(format!(
                "{case}: not in the table ({n} points, {hash:#018x})"
            )),
        }
    }
    assert!(
        wrong.is_empty(),
        "golden outputs changed:\n  {}\nIf the change is meant, run \
         `PIXELPIE_GOLDEN_PRINT=1 cargo test --release --test golden -- --nocapture`, \
         paste its lines over GOLDEN in tests/golden.rs and say why in the commit.",
        wrong.join("\n  ")
    );
}

fn sampled(set: &SampleSet) -> (usize, u64) {
    (set.points.len(), hash_points(&set.points))
}

#[test]
fn the_sampler_gives_the_pinned_points_on_the_cpu() {
    let results: Vec<_> = sampler_cases()
        .into_iter()
        .map(|(case, params)| {
            let set = cpu::sample(&params, Control::default()).expect("CPU sampling");
            assert!(set.points.len() > 100, "{case}: too few points");
            let (n, h) = sampled(&set);
            (case, n, h)
        })
        .collect();
    check(&results);
}

#[test]
fn drawings_give_the_pinned_dots_and_files() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut results = Vec::new();
    for (case, image, job) in drawing_cases() {
        let drawing = job
            .run(
                Path::new(image),
                |p| Ok(cpu::sample(p, Control::default())?),
                |_| true,
            )
            .expect("drawing");
        let n = drawing.points.len();
        assert!(n > 2000, "{case}: {n} dots");
        results.push((case.clone(), n, hash_drawing(&job, &drawing)));
        let svg = dir.path().join("d.svg");
        job.write(&drawing, &svg).expect("SVG");
        let mut h = Fnv::new();
        h.bytes(&std::fs::read(&svg).expect("read SVG"));
        results.push((format!("{case}, SVG"), n, h.0));
    }
    check(&results);
}

#[cfg(feature = "gpu")]
#[test]
fn the_gpu_gives_the_pinned_points_on_both_s1_paths() {
    use pixelpie::backend::SharedGpu;
    use pixelpie::gpu::S1Path;
    let gpu = match SharedGpu::get() {
        Ok(g) => g,
        Err(e) => {
            assert!(
                std::env::var("PIXELPIE_EXPECT_GPU").as_deref() != Ok("1"),
                "a GPU adapter is expected but none was found: {e}"
            );
            eprintln!("skipping GPU golden test: {e}");
            return;
        }
    };
    for path in S1Path::ALL {
        let results: Vec<_> = sampler_cases()
            .into_iter()
            .map(|(case, params)| {
                let set = gpu
                    .sample_on(&params, Some(path), Control::default())
                    .expect("GPU sampling");
                let (n, h) = sampled(&set);
                (case, n, h)
            })
            .collect();
        check(&results);
    }
}

/// Every row of the table is some case's: a row that no case produces
/// (a case renamed or removed) would pin nothing.
#[test]
fn every_golden_row_is_a_case() {
    let mut names: Vec<String> = sampler_cases().into_iter().map(|(n, _)| n).collect();
    for (n, _, _) in drawing_cases() {
        names.push(format!("{n}, SVG"));
        names.push(n);
    }
    let orphans: Vec<&str> = GOLDEN
        .iter()
        .map(|(c, _, _)| *c)
        .filter(|c| !names.iter().any(|n| n == c))
        .collect();
    assert!(orphans.is_empty(), "rows no case produces: {orphans:?}");
}
