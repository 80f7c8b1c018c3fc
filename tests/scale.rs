//! Drawings at scale: the count fit predicts the scale, so that one sampler
//! run lands within ±3% of the asked count, and a million dots stay on a
//! domain of at most 4096² pixels.

use std::path::Path;

use pixelpie::importance::ImportanceMap;
use pixelpie::job::{Job, MAX_DOMAIN_PIXELS};

fn asset(name: &str) -> ImportanceMap {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name);
    ImportanceMap::open(&path, None).unwrap()
}

#[test]
fn one_run_hits_the_count_within_three_per_cent() {
    for name in ["rocket.jpg", "astronaut.jpg", "default.png"] {
        let map = asset(name);
        for n in [30_000usize, 200_000] {
            let mut job = Job::default();
            job.points = Some(n);
            let mut runs = 0;
            let drawing = job
                .run_map(
                    &map,
                    |p| {
                        runs += 1;
                        Ok(p.generate()?)
                    },
                    |_| true,
                )
                .unwrap();
            let got = drawing.points.len() as f64;
            let off = (got - n as f64) / n as f64;
            eprintln!(
                "{name} {n}: {got} dots ({:+.2}%), {runs} run(s)",
                100.0 * off
            );
            assert_eq!(runs, 1, "{name} {n}: {runs} runs");
            assert_eq!(drawing.runs, 1);
            assert!(off.abs() <= 0.03, "{name} {n}: {got}");
        }
    }
}

#[test]
fn a_million_dots_stay_within_the_pixel_budget() {
    let map = asset("rocket.jpg");
    let mut job = Job::default();
    job.points = Some(1_000_000);
    let drawing = job.run_map(&map, |p| Ok(p.generate()?), |_| true).unwrap();
    let (w, h) = drawing.domain;
    assert!(u64::from(w) * u64::from(h) <= MAX_DOMAIN_PIXELS + u64::from(w));
    let aspect = f64::from(w) / f64::from(h);
    let photo = f64::from(map.width()) / f64::from(map.height());
    assert!((aspect - photo).abs() / photo < 0.01);
    let got = drawing.points.len() as f64;
    assert!((got - 1e6).abs() <= 3e4, "{got}");
    // The dots keep their calibrated sizes: the smallest sample radius is
    // still above the sampler's 1 px floor, with room.
    assert!(drawing.range.min > 2.0, "{:?}", drawing.range);
}
