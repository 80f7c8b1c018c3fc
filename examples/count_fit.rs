//! How far the count estimates are from the sampler's count, per run of
//! `stipple`'s count fit: the plain RSA estimate, and the one corrected by
//! the pixel-mode density ([`pixelpie::importance::ink::density`]) that the
//! fit uses (its ratio is what `COUNT_BIAS` in src/importance/fit.rs
//! absorbs). One line per sampler run, so a second run shows as a second
//! line.
//!
//! `cargo run --release --example count_fit -- PHOTOS`
use pixelpie::importance::{ImportanceMap, ink};
use pixelpie::job::Job;
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    for img in &args {
        let map = ImportanceMap::open(std::path::Path::new(img), None).unwrap();
        for n in [10_000usize, 100_000, 1_000_000] {
            let mut job = Job::default();
            job.points = Some(n);
            let mut runs = Vec::new();
            let t = std::time::Instant::now();
            let d = job
                .run_map(
                    &map,
                    |p| {
                        let set = p.generate()?;
                        // expected RSA and corrected, from the params' radius map
                        let pixelpie::sampler::Radius::Map(rm) = &p.radius else {
                            return Ok(set);
                        };
                        let (mut e, mut ec) = (0.0, 0.0);
                        for &fx in rm.radii_fx() {
                            let r = fx as f64 / 64.0;
                            let x = 0.547 / (std::f64::consts::PI * r * r / 4.0);
                            e += x;
                            ec += x * ink::density(r);
                        }
                        runs.push((set.points.len(), e, ec));
                        Ok(set)
                    },
                    |_| true,
                )
                .unwrap();
            let _ = d;
            for (got, e, ec) in &runs {
                println!(
                    "{img} n={n}: got {got} rsa {:.3} corr {:.3}",
                    *got as f64 / e,
                    *got as f64 / ec
                );
            }
            println!("  {:.2}s", t.elapsed().as_secs_f64());
        }
    }
}
