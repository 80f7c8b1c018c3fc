//! The wgpu backend against the CPU reference: identical points, bit for bit.
//!
//! With `PIXELPIE_EXPECT_GPU=1` (set by `.ci/run`), a missing adapter fails
//! these tests instead of skipping them.

mod common;

use std::sync::{Arc, Mutex, OnceLock};

use common::{smooth_radii, step_radii};
use pixelpie::gpu::{GpuContext, GpuSampler};
use pixelpie::sampler::{BackendKind, Control, Params, Policy, RadiusMap, SampleSet, cpu};

struct Gpu {
    ctx: GpuContext,
    sampler: Mutex<GpuSampler>,
}

fn gpu() -> Option<&'static Gpu> {
    static GPU: OnceLock<Option<Gpu>> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new() {
        Ok(ctx) => {
            let sampler = GpuSampler::new(&ctx.device, ctx.info.name.clone()).expect("pipelines");
            Some(Gpu {
                sampler: Mutex::new(sampler),
                ctx,
            })
        }
        Err(e) => {
            assert!(
                std::env::var("PIXELPIE_EXPECT_GPU").as_deref() != Ok("1"),
                "a GPU adapter is expected but none was found: {e}"
            );
            eprintln!("skipping GPU test: {e}");
            None
        }
    })
    .as_ref()
}

fn both(params: &Params) -> Option<(SampleSet, SampleSet)> {
    let g = gpu()?;
    let on_gpu = g
        .sampler
        .lock()
        .unwrap()
        .sample(&g.ctx.device, &g.ctx.queue, params, Control::default())
        .expect("GPU sampling");
    let on_cpu = cpu::sample(params, Control::default()).expect("CPU sampling");
    Some((on_gpu, on_cpu))
}

fn assert_identical(params: &Params, what: &str) {
    let Some((g, c)) = both(params) else { return };
    assert!(c.points.len() >= 10, "{what}: too few points to compare");
    assert_eq!(g.iterations(), c.iterations(), "{what}: iterations");
    assert_eq!(g.maximal(), c.maximal(), "{what}: maximality");
    assert_eq!(g.points.len(), c.points.len(), "{what}: point count");
    for (i, (a, b)) in g.points.iter().zip(&c.points).enumerate() {
        assert!(
            a.x.to_bits() == b.x.to_bits()
                && a.y.to_bits() == b.y.to_bits()
                && a.radius.to_bits() == b.radius.to_bits(),
            "{what}: point {i} differs: gpu {a:?} cpu {b:?}"
        );
    }
}

#[test]
fn uniform_sampling_matches_reference_implementation() {
    for bits in [0, 3] {
        for periodic in [false, true] {
            for policy in Policy::ALL {
                let params = Params::new(300, 200)
                    .with_radius(6.5)
                    .with_subpixel_bits(bits)
                    .with_periodic(periodic)
                    .with_policy(policy)
                    .with_seed(42);
                assert_identical(
                    &params,
                    &format!("uniform {policy:?} bits {bits} periodic {periodic}"),
                );
            }
        }
    }
}

#[test]
fn radius_map_sampling_matches_reference_implementation() {
    let (w, h) = (240, 180);
    for (name, radii) in [("step", step_radii(w, h)), ("smooth", smooth_radii(w, h))] {
        let map = Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap());
        for policy in Policy::ALL {
            for (bits, periodic) in [(0, false), (3, false), (3, true), (0, true)] {
                let params = Params::new(w, h)
                    .with_radius_map(map.clone())
                    .with_policy(policy)
                    .with_subpixel_bits(bits)
                    .with_periodic(periodic)
                    .with_seed(7);
                assert_identical(
                    &params,
                    &format!("{name} map {policy:?} bits {bits} periodic {periodic}"),
                );
            }
        }
    }
}

#[test]
fn a_larger_domain_and_capped_runs_match_reference_implementation() {
    assert_identical(
        &Params::new(1024, 768).with_radius(8.5).with_seed(3),
        "1024x768",
    );
    assert_identical(
        &Params::new(512, 512)
            .with_radius(3.0)
            .with_max_iterations(2)
            .with_seed(1),
        "capped",
    );
    // Big disks: rows of hundreds of pixels (llvmpipe caps a shader loop at
    // 65535 iterations, so each GPU thread covers one row).
    assert_identical(
        &Params::new(600, 600).with_radius(150.0).with_seed(2),
        "r = 150 px",
    );
    // Radii above 1024 px take the 32-bit radius texture.
    let radii: Vec<f32> = (0..1200 * 48)
        .map(|i| if i % 1200 > 1150 { 1030.0 } else { 3.0 })
        .collect();
    let map = Arc::new(RadiusMap::from_pixels(1200, 48, &radii).unwrap());
    assert_identical(
        &Params::new(1200, 48).with_radius_map(map).with_seed(2),
        "32-bit radii",
    );
    assert_identical(
        &Params::new(257, 131)
            .with_radius(4.0)
            .with_batch(37)
            .with_seed(5),
        "odd sizes, small batch",
    );
    // A batch above the pixel count: the GPU's room for accepted samples
    // (at most the pixel count) holds less than two batches, so every
    // iteration's survivors are read back apart, from where the gather put
    // them.
    assert_identical(
        &Params::new(96, 80)
            .with_radius(2.0)
            .with_batch(1 << 20)
            .with_seed(4),
        "batch above the pixel count",
    );
    // Room for 2.5 batches (a sixteenth of the pixels) and about eight
    // batches of samples: held on the GPU and read back several times in
    // the run.
    assert_identical(
        &Params::new(1200, 1000)
            .with_radius(2.0)
            .with_batch(30_000)
            .with_seed(6),
        "held samples read back mid-run",
    );
}

/// A 200×150 domain with a stepped radius map, for every policy, periodic
/// off and on.
fn step_map_cases(seed: u64) -> impl Iterator<Item = (Policy, bool, Params)> {
    let (w, h) = (200, 150);
    let map = Arc::new(RadiusMap::from_pixels(w, h, &step_radii(w, h)).unwrap());
    Policy::ALL.into_iter().flat_map(move |policy| {
        let map = map.clone();
        [false, true].into_iter().map(move |periodic| {
            let params = Params::new(w, h)
                .with_radius_map(map.clone())
                .with_policy(policy)
                .with_periodic(periodic)
                .with_seed(seed);
            (policy, periodic, params)
        })
    })
}

#[test]
fn every_s1_path_matches_reference_implementation() {
    use pixelpie::gpu::S1Path;
    let Some(g) = gpu() else { return };
    for path in S1Path::ALL {
        for (policy, periodic, params) in step_map_cases(13) {
            let mut s = g.sampler.lock().unwrap();
            s.set_path(Some(path));
            let on_gpu = s
                .sample(&g.ctx.device, &g.ctx.queue, &params, Control::default())
                .expect("GPU");
            s.set_path(None);
            drop(s);
            let on_cpu = cpu::sample(&params, Control::default()).unwrap();
            assert_eq!(
                on_gpu.points, on_cpu.points,
                "{path:?} {policy:?} periodic {periodic}"
            );
            assert_eq!(
                on_gpu.stats.backend,
                match path {
                    S1Path::Raster => BackendKind::GpuRaster,
                    S1Path::Compute => BackendKind::GpuCompute,
                    S1Path::Coalesced => BackendKind::GpuCoalesced,
                }
            );
        }
    }
}

#[test]
fn a_chunked_key_buffer_matches_reference_implementation() {
    use pixelpie::gpu::S1Path;
    let Some(g) = gpu() else { return };
    let mut s = g.sampler.lock().unwrap();
    for path in [S1Path::Compute, S1Path::Coalesced] {
        s.set_path(Some(path));
        let mut run = |params: &Params, cap: Option<u32>| {
            s.set_strip_cap(cap);
            s.sample(&g.ctx.device, &g.ctx.queue, params, Control::default())
                .expect("GPU")
        };
        // Strips of 1 row, of 7 (the last one partial) and of 64 rows.
        let uniform = Params::new(200, 150).with_radius(3.5).with_seed(5);
        let whole = run(&uniform, None);
        let reference = cpu::sample(&uniform, Control::default()).unwrap();
        assert_eq!(
            whole.points, reference.points,
            "{path:?} uniform, whole key buffer"
        );
        for cap in [1, 7, 64] {
            let chunked = run(&uniform, Some(cap));
            assert_eq!(
                chunked.points, whole.points,
                "{path:?} uniform, strips of {cap} rows"
            );
            // The key buffer, 4 B/px when whole, shrinks to one strip;
            // nothing else changes.
            let saved = whole.stats.bytes_per_pixel - chunked.stats.bytes_per_pixel;
            let want = 4.0 * f64::from(150 - cap) / 150.0;
            assert!(
                (saved - want).abs() < 1e-9,
                "{path:?} strips of {cap} rows save {saved} B/px, not {want}"
            );
        }
        for (policy, periodic, params) in step_map_cases(21) {
            let on_gpu = run(&params, Some(7));
            let on_cpu = cpu::sample(&params, Control::default()).unwrap();
            assert_eq!(
                on_gpu.points, on_cpu.points,
                "{path:?} strips of 7 rows, {policy:?} periodic {periodic}"
            );
        }
    }
    s.set_strip_cap(None);
    s.set_path(None);
}

/// Exact mode: the GPU's pixel pass, then the CPU's refinement, gives the
/// CPU's points bit for bit.
fn assert_exact_identical(params: &Params, what: &str) {
    assert_identical(&params.clone().with_exact(true), what);
    if let Some((g, c)) = both(&params.clone().with_exact(true)) {
        assert_eq!(g.stats.backend, BackendKind::GpuExact, "{what}");
        assert!(
            g.stats.exact && g.stats.repaired == c.stats.repaired,
            "{what}"
        );
    }
}

#[test]
fn exact_mode_matches_reference_implementation() {
    for periodic in [false, true] {
        assert_exact_identical(
            &Params::new(300, 200)
                .with_radius(6.5)
                .with_periodic(periodic)
                .with_seed(42),
            &format!("exact uniform periodic {periodic}"),
        );
    }
    let (w, h) = (160, 120);
    for (name, radii) in [("step", step_radii(w, h)), ("smooth", smooth_radii(w, h))] {
        let map = Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap());
        for policy in Policy::ALL {
            for periodic in [false, true] {
                let params = Params::new(w, h)
                    .with_radius_map(map.clone())
                    .with_policy(policy)
                    .with_periodic(periodic)
                    .with_seed(7);
                assert_exact_identical(
                    &params,
                    &format!("exact {name} map {policy:?} periodic {periodic}"),
                );
            }
        }
    }
}

#[test]
fn exact_mode_with_repairs_small_batches_and_caps_matches_reference_implementation() {
    // This seed leaves a void that the CPU's repair fills (tests/exact.rs).
    let repaired = Params::new(512, 512)
        .with_radius(2.0)
        .with_periodic(true)
        .with_seed(1);
    assert_exact_identical(&repaired, "exact 512² r = 2 seed 1");
    if let Some((g, _)) = both(&repaired.clone().with_exact(true)) {
        assert!(g.stats.repaired > 0, "the void is repaired");
    }
    // Many GPU iterations before the handover, a narrow domain, and a run
    // cut short on the GPU (not maximal).
    assert_exact_identical(
        &Params::new(257, 131)
            .with_radius(4.0)
            .with_batch(37)
            .with_seed(5),
        "exact odd sizes, small batch",
    );
    assert_exact_identical(
        &Params::new(1000, 7).with_radius(3.0).with_seed(9),
        "exact 1000x7",
    );
    // A batch far above the pixel count: every iteration throws one dart
    // per active pixel or cell (the GPU's buffers are sized for the batch,
    // since below the pixel the cells may outnumber the pixels).
    assert_exact_identical(
        &Params::new(64, 48)
            .with_radius(6.0)
            .with_batch(1 << 20)
            .with_seed(2),
        "exact, batch above the pixel count",
    );
    // Radii beyond the GPU pass's reach are refused with a GPU error (which
    // `auto` answers with the CPU).
    if let Some(g) = gpu() {
        let big = Params::new(600, 600).with_radius(120.0).with_exact(true);
        let err = g
            .sampler
            .lock()
            .unwrap()
            .sample(&g.ctx.device, &g.ctx.queue, &big, Control::default())
            .unwrap_err();
        assert!(
            err.is_backend() && err.to_string().contains("100 px"),
            "{err}"
        );
    }
    let capped = Params::new(256, 256)
        .with_radius(3.0)
        .with_max_iterations(2)
        .with_seed(4);
    assert_exact_identical(&capped, "exact capped");
    if let Some((g, _)) = both(&capped.with_exact(true)) {
        assert!(!g.maximal() && g.iterations() == 2);
    }
}

/// Three classes: a dense one fading out to the right, a uniform one, and
/// one that only exists in a disc (the others are holes: slots that start
/// covered).
fn class_maps(w: u32, h: u32) -> pixelpie::sampler::ClassRadii {
    let mut maps = vec![Vec::new(), Vec::new(), Vec::new()];
    for y in 0..h {
        for x in 0..w {
            maps[0].push(if x < w * 3 / 4 {
                2.0 + 6.0 * x as f32 / w as f32
            } else {
                f32::INFINITY
            });
            maps[1].push(5.0);
            let (dx, dy) = (x as f32 - w as f32 * 0.6, y as f32 - h as f32 / 2.0);
            maps[2].push(if dx * dx + dy * dy < 1600.0 {
                3.0
            } else {
                f32::INFINITY
            });
        }
    }
    pixelpie::sampler::ClassRadii::new(w, h, &maps).unwrap()
}

/// Multi-class sampling (the pens of a colour drawing): the GPU's key and
/// coverage layers give the CPU's points and classes, bit for bit, under
/// every policy, periodic or not, whole or in strips of the key buffer.
#[test]
fn classes_match_reference_implementation() {
    use pixelpie::gpu::S1Path;
    let Some(g) = gpu() else { return };
    let classes = Arc::new(class_maps(160, 120));
    for policy in Policy::ALL {
        for periodic in [false, true] {
            let params = Params::new(160, 120)
                .with_classes(classes.clone())
                .with_policy(policy)
                .with_periodic(periodic)
                .with_seed(8);
            let what = format!("classes, {policy:?} periodic {periodic}");
            assert_identical(&params, &what);
            let (on_gpu, on_cpu) = both(&params).unwrap();
            let class = |s: &SampleSet| s.points.iter().map(|p| p.class).collect::<Vec<_>>();
            assert_eq!(class(&on_gpu), class(&on_cpu), "{what}: classes");
            assert!(on_cpu.maximal(), "{what}");
            assert!(
                (0..3).all(|c| class(&on_cpu).contains(&c)),
                "{what}: a class is missing"
            );
            assert!(
                matches!(
                    on_gpu.stats.backend,
                    BackendKind::GpuCompute | BackendKind::GpuCoalesced
                ),
                "{what}: classes take a compute path, not {}",
                on_gpu.stats.backend
            );
        }
    }
    // The key buffer in strips of 5 stacked rows (a strip may span two
    // classes' layers), and small batches, on both compute paths; a raster
    // path asked for takes the compute path with classes.
    let params = Params::new(160, 120)
        .with_classes(classes)
        .with_batch(37)
        .with_seed(3);
    let reference = cpu::sample(&params, Control::default()).unwrap();
    for (path, kind) in [
        (S1Path::Compute, BackendKind::GpuCompute),
        (S1Path::Coalesced, BackendKind::GpuCoalesced),
        (S1Path::Raster, BackendKind::GpuCompute),
    ] {
        let mut s = g.sampler.lock().unwrap();
        s.set_strip_cap(Some(5));
        s.set_path(Some(path));
        let chunked = s
            .sample(&g.ctx.device, &g.ctx.queue, &params, Control::default())
            .expect("GPU");
        s.set_strip_cap(None);
        s.set_path(None);
        drop(s);
        assert_eq!(
            chunked.points, reference.points,
            "{path:?}: classes in strips of 5 rows"
        );
        assert_eq!(chunked.stats.backend, kind, "{path:?}");
    }
}
