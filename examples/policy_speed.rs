//! Samples per second of the four disk policies on one radius map, CPU
//! backend, with the per-stage split (issue 22, part 2), on the radius map of
//! `pixelpie sample --importance IMAGE --min-radius MIN --max-radius MAX` at
//! SIDE².
//!
//! `cargo run --release --example policy_speed -- [IMAGE] [SIDE] [MIN] [MAX] [REPS] [POLICIES…]`
use pixelpie::importance::ImportanceMap;
use pixelpie::job::{Radii, SampleJob};
use pixelpie::sampler::{Control, Policy, cpu};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let img = args.first().map_or("assets/astronaut.jpg", String::as_str);
    let side: u32 = args.get(1).map_or(4096, |s| s.parse().unwrap());
    let r0: f32 = args.get(2).map_or(2.0, |s| s.parse().unwrap());
    let r1: f32 = args.get(3).map_or(16.0, |s| s.parse().unwrap());
    let reps: u32 = args.get(4).map_or(3, |s| s.parse().unwrap());
    // The radius map that `pixelpie sample --importance IMG --width SIDE
    // --height SIDE --min-radius MIN --max-radius MAX` samples.
    let radii = Radii::Picture(ImportanceMap::open(std::path::Path::new(img), None).unwrap());
    let mut job = SampleJob::default();
    (job.width, job.height) = (Some(side), Some(side));
    job.importance_options.min_radius = Some(r0);
    job.importance_options.max_radius = Some(r1);
    let mut base = None;
    job.run(&radii, |p| {
        base = Some(p.clone());
        Ok(cpu::sample(p, Control::default())?)
    })
    .unwrap();
    let base = base.unwrap();
    println!("{img} at {side}², radii {r0}..{r1} px, best of {reps}");
    println!(
        "| policy | points | iterations | darts | s | M samples/s | ÷ Prior | ns/dart | throw ms | cull+cover ms | compact ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut prior = 0.0;
    for policy in [
        Policy::Prior,
        Policy::Current,
        Policy::Bigger,
        Policy::Smaller,
    ] {
        if args.len() > 5
            && !args[5..].iter().any(|a| a == policy.name())
            && policy != Policy::Prior
        {
            continue;
        }
        let params = base.clone().with_policy(policy);
        let plan = params.plan().unwrap();
        let mut best: Option<pixelpie::sampler::SampleSet> = None;
        let mut darts = 0u64;
        for _ in 0..reps {
            // The darts of each iteration: the batch, capped by the pixels
            // empty before it (no pixel of these maps starts covered).
            let empties = std::sync::Mutex::new(vec![u64::from(side) * u64::from(side)]);
            let log = |p: pixelpie::sampler::Progress| empties.lock().unwrap().push(p.empty_pixels);
            let s = cpu::sample(&params, Control::default().with_progress(&log)).unwrap();
            let empties = empties.into_inner().unwrap();
            darts = empties[..empties.len() - 1]
                .iter()
                .map(|&e| u64::from(plan.darts_for(u32::try_from(e).unwrap())))
                .sum();
            if best
                .as_ref()
                .is_none_or(|b| s.stats.seconds < b.stats.seconds)
            {
                best = Some(s);
            }
        }
        let s = best.unwrap();
        let rate = s.points.len() as f64 / s.stats.seconds / 1e6;
        if policy == Policy::Prior {
            prior = rate;
        }
        let st = &s.stats.stages;
        println!(
            "| {} | {} | {} | {darts} | {:.3} | {:.2} | {:.2} | {:.0} | {:.0} | {:.0} | {:.0} |",
            policy.name(),
            s.points.len(),
            s.stats.iterations,
            s.stats.seconds,
            rate,
            rate / prior,
            s.stats.seconds * 1e9 / darts as f64,
            st.get("throw") * 1e3,
            st.get("cull") * 1e3,
            st.get("compact") * 1e3
        );
    }
}
