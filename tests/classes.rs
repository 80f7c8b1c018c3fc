//! Multi-class sampling (`sampler::classes`): every class a Poisson-disk set
//! of its own radii, all classes together one of the cross radii, maximal
//! over every class, and the same points for any thread count.

use std::sync::Arc;

use pixelpie::sampler::fixed::{axis_delta, inside, radius_to_fx};
use pixelpie::sampler::{ClassRadii, Params, Point, Policy, cpu};

/// Three classes over a 160×120 domain: a dense class on the left fading
/// out to the right, a uniform one, and one that only exists in a disc.
fn maps(w: u32, h: u32) -> Vec<Vec<f32>> {
    let mut a = Vec::new();
    let mut b = Vec::new();
    let mut c = Vec::new();
    for y in 0..h {
        for x in 0..w {
            a.push(if x < w * 3 / 4 {
                2.0 + 6.0 * x as f32 / w as f32
            } else {
                f32::INFINITY
            });
            b.push(5.0);
            let (dx, dy) = (x as f32 - 100.0, y as f32 - 60.0);
            c.push(if dx * dx + dy * dy < 40.0 * 40.0 {
                3.0
            } else {
                f32::INFINITY
            });
        }
    }
    vec![a, b, c]
}

fn fx(p: &Point) -> (u32, u32) {
    ((p.x * 256.0) as u32, (p.y * 256.0) as u32)
}

fn run(policy: Policy, periodic: bool) -> (ClassRadii, Vec<Point>, bool) {
    let (w, h) = (160, 120);
    let classes = ClassRadii::new(w, h, &maps(w, h)).unwrap();
    let params = Params::new(w, h)
        .with_classes(Arc::new(classes.clone()))
        .with_policy(policy)
        .with_periodic(periodic)
        .with_seed(5);
    let set = cpu::sample(&params, Default::default()).unwrap();
    (classes, set.points.clone(), set.maximal())
}

/// Whether two accepted samples keep the policy's separation of their
/// radii (their own for one class, the cross radii across classes), up to
/// the pixel rules' slack: darts are tested at pixel centres, so centres may
/// be up to √2/2 px closer than f.
fn separated(
    classes: &ClassRadii,
    policy: Policy,
    i: &Point,
    j: &Point,
    period: (u32, u32),
) -> bool {
    let radius = |p: &Point, own: bool| {
        let (x, y) = (p.x as u32, p.y as u32);
        if own {
            radius_to_fx(classes.radius_px(p.class, x, y).unwrap())
        } else {
            radius_to_fx(classes.cross_px(x, y))
        }
    };
    let own = i.class == j.class;
    let f = f64::from(policy.coverage_radius(radius(i, own), radius(j, own))) / 64.0;
    let d = |a: f32, b: f32, n: u32| {
        let d = f64::from((a - b).abs());
        if n == 0 {
            d
        } else {
            d.min(f64::from(n) / 256.0 - d)
        }
    };
    let (dx, dy) = (d(i.x, j.x, period.0), d(i.y, j.y, period.1));
    (dx * dx + dy * dy).sqrt() >= f - std::f64::consts::FRAC_1_SQRT_2 - 1e-9
}

#[test]
fn every_class_keeps_its_spacing_and_all_keep_the_cross_spacing() {
    for policy in Policy::ALL {
        for periodic in [false, true] {
            let (classes, points, maximal) = run(policy, periodic);
            assert!(maximal, "{policy:?}");
            let period = if periodic {
                (160 * 256, 120 * 256)
            } else {
                (0, 0)
            };
            let mut per_class = [0usize; 3];
            for (j, pj) in points.iter().enumerate() {
                per_class[pj.class as usize] += 1;
                // Samples only where their class has a radius.
                assert!(
                    classes
                        .radius_px(pj.class, pj.x as u32, pj.y as u32)
                        .is_some()
                );
                for pi in &points[..j] {
                    assert!(
                        separated(&classes, policy, pi, pj, period),
                        "{policy:?} periodic {periodic}: {pi:?} and {pj:?}"
                    );
                }
            }
            assert!(
                per_class.iter().all(|&n| n > 20),
                "{policy:?} {per_class:?}"
            );
        }
    }
}

#[test]
fn no_dart_of_any_class_fits_in_a_maximal_set() {
    let (w, h) = (160u32, 120u32);
    let policy = Policy::Smaller;
    let (classes, points, maximal) = run(policy, false);
    assert!(maximal);
    // Every slot with a radius is covered by some sample under the rules.
    for c in 0..3u32 {
        for y in 0..h {
            for x in 0..w {
                let Some(r) = classes.radius_px(c, x, y) else {
                    continue;
                };
                let (cx, cy) = (x * 256 + 128, y * 256 + 128);
                let covered = points.iter().any(|p| {
                    let (px, py) = fx(p);
                    let (rs, rp) = if p.class == c {
                        (classes.radius_px(c, p.x as u32, p.y as u32).unwrap(), r)
                    } else {
                        (
                            classes.cross_px(p.x as u32, p.y as u32),
                            classes.cross_px(x, y),
                        )
                    };
                    let f = policy.coverage_radius(radius_to_fx(rs), radius_to_fx(rp));
                    inside(axis_delta(px, cx, 0), axis_delta(py, cy, 0), f)
                });
                assert!(covered, "class {c} pixel ({x}, {y}) is still empty");
            }
        }
    }
}

#[test]
fn the_points_do_not_depend_on_the_thread_count() {
    let (_, want, _) = run(Policy::Smaller, false);
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (_, got, _) = pool.install(|| run(Policy::Smaller, false));
        assert_eq!(got, want, "{threads} threads");
    }
}

#[test]
fn one_class_gives_the_plain_maps_points() {
    let (w, h) = (90u32, 70u32);
    let radii: Vec<f32> = (0..w * h).map(|i| 2.0 + (i % w) as f32 / 20.0).collect();
    let map = pixelpie::sampler::RadiusMap::from_pixels(w, h, &radii).unwrap();
    let plain = Params::new(w, h)
        .with_radius_map(Arc::new(map))
        .with_seed(9);
    let one = Params::new(w, h)
        .with_classes(Arc::new(ClassRadii::new(w, h, &[radii]).unwrap()))
        .with_seed(9);
    let a = cpu::sample(&plain, Default::default()).unwrap();
    let b = cpu::sample(&one, Default::default()).unwrap();
    assert_eq!(a.points, b.points);
}

#[test]
fn bad_class_maps_are_refused() {
    assert!(ClassRadii::new(2, 1, &[]).is_err());
    assert!(ClassRadii::new(2, 1, &[vec![1.0]]).is_err());
    assert!(ClassRadii::new(2, 1, &[vec![0.5, 2.0]]).is_err());
    assert!(ClassRadii::new(2, 1, &[vec![f32::NAN, 2.0]]).is_err());
    let c = ClassRadii::new(2, 1, &[vec![2.0, 2.0]]).unwrap();
    assert!(
        Params::new(3, 1)
            .with_classes(Arc::new(c.clone()))
            .plan()
            .is_err()
    );
    assert!(
        Params::new(2, 1)
            .with_classes(Arc::new(c))
            .with_exact(true)
            .plan()
            .is_err()
    );
}
