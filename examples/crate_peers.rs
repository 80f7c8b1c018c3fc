//! Measures well-kept crates against PixelPie's own code, for the choice
//! between them (docs/benchmarks.md, "Crates against our own code"):
//! `pixelpie::analyze::csv::parse` (the csv crate inside) against the csv
//! crate's raw reader, fast_image_resize against image's resize (Triangle,
//! f32, what `ImportanceMap::resized` uses), and kiddo's nearest-neighbour
//! queries against a median k-d tree of the shape of relax's site tree.
//!
//! `cargo run --release --example crate_peers`

use std::time::Instant;

use fast_image_resize as fr;

/// The fastest of `reps` runs of `f`, in seconds, and its result.
fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..reps {
        let t = Instant::now();
        let o = f();
        best = best.min(t.elapsed().as_secs_f64());
        out = Some(o);
    }
    (best, out.expect("at least one run"))
}

/// The csv crate's reader alone: byte records, fields parsed as `f64`.
fn csv_raw(text: &str) -> Vec<[f64; 2]> {
    let mut rd = csv::ReaderBuilder::new()
        .has_headers(true)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let mut pts = Vec::new();
    let mut rec = csv::ByteRecord::new();
    let f = |b: &[u8]| -> f64 {
        std::str::from_utf8(b)
            .expect("UTF-8")
            .trim()
            .parse()
            .expect("a number")
    };
    while rd.read_byte_record(&mut rec).expect("a record") {
        pts.push([f(&rec[0]), f(&rec[1])]);
    }
    pts
}

/// `vals` (`w`×`h`) resized to `tw`×`th` by image (Triangle) and by
/// fast_image_resize (bilinear convolution): seconds and values of each.
fn resize_both(
    vals: &[f32],
    (w, h): (u32, u32),
    (tw, th): (u32, u32),
    reps: usize,
) -> ((f64, Vec<f32>), (f64, Vec<f32>)) {
    let image = best(reps, || {
        let buf = image::ImageBuffer::<image::Luma<f32>, Vec<f32>>::from_raw(w, h, vals.to_vec())
            .expect("sized buffer");
        image::imageops::resize(&buf, tw, th, image::imageops::FilterType::Triangle).into_raw()
    });
    let fir = best(reps, || {
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let src = fr::images::Image::from_vec_u8(w, h, bytes, fr::PixelType::F32).expect("src");
        let mut dst = fr::images::Image::new(tw, th, fr::PixelType::F32);
        let alg = fr::ResizeAlg::Convolution(fr::FilterType::Bilinear);
        fr::Resizer::new()
            .resize(&src, &mut dst, &fr::ResizeOptions::new().resize_alg(alg))
            .expect("resize");
        dst.into_vec()
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    });
    (image, fir)
}

fn main() {
    // 1. 1M rows of x,y,radius as `pixelpie sample` writes them.
    let n = 1_000_000;
    let mut text = String::from("x,y,radius\n");
    let mut s = 12345u64;
    for _ in 0..n {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let x = (s >> 40) as f32 / 16777216.0 * 4096.0;
        let y = ((s >> 16) & 0xff_ffff) as f32 / 16777216.0 * 4096.0;
        text.push_str(&format!("{x},{y},4.25\n"));
    }
    let (ours, table) = best(5, || pixelpie::analyze::csv::parse(&text).expect("parses"));
    let (raw, pts) = best(5, || csv_raw(&text));
    assert_eq!(table.points, pts);
    println!(
        "csv, 1M rows: analyze::csv::parse {ours:.3} s, the csv crate's raw reader {raw:.3} s \
         (parse/raw {:.2})",
        ours / raw
    );

    // 2. The 1M-dot enlargement (600×400 to 10000×6667) and the default
    // stipple's (512² to 1024²).
    for ((w, h), (tw, th), reps) in [
        ((600, 400), (10000, 6667), 3),
        ((512, 512), (1024, 1024), 5),
    ] {
        let vals: Vec<f32> = (0..w * h)
            .map(|i| ((i * 7919) % 1000) as f32 / 1000.0)
            .collect();
        let ((t_image, a), (t_fir, b)) = resize_both(&vals, (w, h), (tw, th), reps);
        let same = a.iter().zip(&b).filter(|(x, y)| x.to_bits() == y.to_bits());
        let same = 100.0 * same.count() as f64 / a.len() as f64;
        let diff = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0f32, f32::max);
        println!(
            "resize {w}x{h} -> {tw}x{th} f32: image {t_image:.4} s, fast_image_resize \
             {t_fir:.4} s (fir/image {:.2}); equal bits {same:.1}%, max |diff| {diff:.2e}",
            t_fir / t_image
        );
    }

    // 3. Nearest site of 200K queries among 200K sites.
    let m = 200_000usize;
    let sites = &table.points[..m];
    let queries = &table.points[m..2 * m];
    let (t_kiddo, sum_kiddo) = best(3, || {
        let mut tree: kiddo::KdTree<f64, 2> = kiddo::KdTree::with_capacity(m);
        for (i, p) in sites.iter().enumerate() {
            tree.add(p, i as u64);
        }
        queries
            .iter()
            .map(|q| tree.nearest_one::<kiddo::SquaredEuclidean>(q).item)
            .sum::<u64>()
    });
    let (t_median, sum_median) = best(3, || {
        let tree = Median::new(sites);
        queries.iter().map(|q| tree.nearest(*q) as u64).sum::<u64>()
    });
    assert_eq!(sum_kiddo, sum_median);
    println!(
        "nearest, 200K queries among 200K sites (build + queries): kiddo {t_kiddo:.3} s, \
         median k-d tree {t_median:.3} s (kiddo/median {:.2})",
        t_kiddo / t_median
    );
}

/// A node of [`Median`]: bounding box, range of sites, children.
struct Node {
    bbox: [f64; 4],
    start: usize,
    end: usize,
    children: Option<[usize; 2]>,
}

/// A median-split k-d tree with leaves of at most 8 sites, split along the
/// longer side: the shape of relax's site tree.
struct Median {
    pos: Vec<[f64; 2]>,
    ids: Vec<usize>,
    nodes: Vec<Node>,
}

fn box_dist2(b: &[f64; 4], q: [f64; 2]) -> f64 {
    let dx = (b[0] - q[0]).max(q[0] - b[2]).max(0.0);
    let dy = (b[1] - q[1]).max(q[1] - b[3]).max(0.0);
    dx * dx + dy * dy
}

fn build(s: &mut [(usize, [f64; 2])], start: usize, nodes: &mut Vec<Node>) -> usize {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for (_, q) in s.iter() {
        b = [
            b[0].min(q[0]),
            b[1].min(q[1]),
            b[2].max(q[0]),
            b[3].max(q[1]),
        ];
    }
    let id = nodes.len();
    nodes.push(Node {
        bbox: b,
        start,
        end: start + s.len(),
        children: None,
    });
    if s.len() > 8 {
        let axis = usize::from(b[3] - b[1] > b[2] - b[0]);
        let mid = s.len() / 2;
        s.select_nth_unstable_by(mid, |a, c| a.1[axis].total_cmp(&c.1[axis]));
        let (l, r) = s.split_at_mut(mid);
        let a = build(l, start, nodes);
        let c = build(r, start + mid, nodes);
        nodes[id].children = Some([a, c]);
    }
    id
}

impl Median {
    fn new(p: &[[f64; 2]]) -> Self {
        let mut s: Vec<(usize, [f64; 2])> = p.iter().copied().enumerate().collect();
        let mut nodes = Vec::new();
        build(&mut s, 0, &mut nodes);
        let (ids, pos) = s.into_iter().unzip();
        Self { pos, ids, nodes }
    }

    /// The nearest site to `q`, nearer children first.
    fn nearest(&self, q: [f64; 2]) -> usize {
        let mut best = (f64::INFINITY, 0usize);
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if box_dist2(&node.bbox, q) >= best.0 {
                continue;
            }
            match node.children {
                None => {
                    for (p, &id) in self.pos[node.start..node.end]
                        .iter()
                        .zip(&self.ids[node.start..node.end])
                    {
                        let d = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
                        if d < best.0 {
                            best = (d, id);
                        }
                    }
                }
                Some([a, c]) => {
                    let (da, dc) = (
                        box_dist2(&self.nodes[a].bbox, q),
                        box_dist2(&self.nodes[c].bbox, q),
                    );
                    let (near, far) = if da <= dc { (a, c) } else { (c, a) };
                    stack.push(far);
                    stack.push(near);
                }
            }
        }
        best.1
    }
}
