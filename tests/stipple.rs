//! Stipple drawings: the SVG is well-formed XML with one circle per dot, the
//! PNG covers the right area, the tone mapping's density ratio is the one it
//! promises, and the plotter order is a permutation that shortens the path.

mod fixtures;

use std::collections::HashMap;
use std::sync::Arc;

use pixelpie::importance::{ImportanceMap, Mapping, RadiusRange};
use pixelpie::sampler::{Params, Point, Policy, RadiusMap, cpu};
use pixelpie::stipple::{Dot, DotSize, raster, svg, tsp};
use quick_xml::events::Event;

fn uniform_set(side: u32, r: f32) -> Vec<Point> {
    cpu::sample(&Params::new(side, side).with_radius(r), Default::default())
        .unwrap()
        .points
}

/// Every element of an SVG document with its attributes, in order; panics
/// if the document is not well-formed.
fn parse_svg(text: &str) -> Vec<(String, HashMap<String, String>)> {
    let mut reader = quick_xml::Reader::from_str(text);
    let mut out = Vec::new();
    let mut depth = 0i32;
    loop {
        match reader.read_event().expect("well-formed XML") {
            Event::Start(e) | Event::Empty(e) => {
                let attrs = e
                    .attributes()
                    .map(|a| {
                        let a = a.expect("attribute");
                        (
                            String::from_utf8(a.key.as_ref().to_vec()).unwrap(),
                            String::from_utf8(a.value.to_vec()).unwrap(),
                        )
                    })
                    .collect();
                out.push((
                    String::from_utf8(e.name().as_ref().to_vec()).unwrap(),
                    attrs,
                ));
                depth += 1;
            }
            Event::End(_) => depth -= 1,
            Event::Eof => break,
            _ => {}
        }
    }
    // Empty elements count as opened and never closed; the rest must balance.
    let empties = out.iter().filter(|(n, _)| n == "circle").count() as i32;
    assert_eq!(depth, empties, "unbalanced elements");
    out
}

#[test]
fn svg_parses_as_xml_with_one_circle_per_dot() {
    let points = uniform_set(256, 5.0);
    let dots: Vec<Dot> = points
        .iter()
        .map(|p| Dot {
            x: p.x,
            y: p.y,
            radius: DotSize::Proportional(0.5).radius(p.radius, 0.0, 1.0),
        })
        .collect();
    let mut out = Vec::new();
    let opts = svg::SvgOptions::with_width_mm((256, 128), 200.0).unwrap();
    svg::write(&mut out, &dots, &opts).unwrap();
    let elements = parse_svg(&String::from_utf8(out).unwrap());
    let (root, attrs) = &elements[0];
    assert_eq!(root, "svg");
    assert_eq!(attrs["viewBox"], "0 0 256 128");
    assert_eq!(attrs["width"], "200mm");
    assert_eq!(attrs["height"], "100mm");
    let circles: Vec<&HashMap<String, String>> = elements
        .iter()
        .filter(|(n, _)| n == "circle")
        .map(|(_, a)| a)
        .collect();
    assert_eq!(circles.len(), dots.len());
    for (c, d) in circles.iter().zip(&dots) {
        let get = |k: &str| c[k].parse::<f32>().unwrap();
        assert!((get("cx") - d.x).abs() <= 1e-3);
        assert!((get("cy") - d.y).abs() <= 1e-3);
        assert!((get("r") - d.radius).abs() <= 1e-3);
    }
}

#[test]
fn png_dots_cover_their_area() {
    let dots = [
        Dot {
            x: 20.0,
            y: 20.0,
            radius: 6.0,
        },
        Dot {
            x: 60.0,
            y: 30.0,
            radius: 3.5,
        },
    ];
    for scale in [1.0f32, 2.0] {
        let img = raster::render(&dots, (100, 50), scale).unwrap();
        assert_eq!(
            img.dimensions(),
            ((100.0 * scale) as u32, (50.0 * scale) as u32)
        );
        // Ink summed in linear light is the dots' area, in output pixels.
        let ink = raster::mean_ink(&img, 0, 0, img.width(), img.height())
            * f64::from(img.width() * img.height());
        let area: f64 = dots
            .iter()
            .map(|d| std::f64::consts::PI * f64::from(d.radius * scale).powi(2))
            .sum();
        assert!(
            (ink / area - 1.0).abs() < 0.03,
            "scale {scale}: ink {ink} vs area {area}"
        );
    }
    assert!(raster::render(&dots, (100, 50), 0.0).is_err());
    assert!(raster::render(&dots, (100_000, 100_000), 1.0).is_err());
}

#[test]
fn tsp_order_is_a_permutation_and_shortens_the_path() {
    let points = uniform_set(512, 3.0);
    let xy: Vec<[f64; 2]> = points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    let n = xy.len();
    assert!(n > 15_000, "{n} points");
    let tour = tsp::plan(&xy, tsp::TspOptions::default());
    let mut seen = tour.order.clone();
    seen.sort_unstable();
    assert!(seen.iter().copied().eq(0..n), "not a permutation");
    let length = tsp::path_length(&xy, &tour.order);
    assert!((length - tour.length).abs() < 1e-6 * length);
    assert!(tour.moves > 0);
    assert!(
        tour.length < 0.95 * tour.start_length,
        "2-opt {} vs the Hilbert curve {}",
        tour.length,
        tour.start_length
    );
    // Far shorter than the sampler's order, which jumps across the domain.
    let identity: Vec<usize> = (0..n).collect();
    assert!(tour.length < 0.1 * tsp::path_length(&xy, &identity));
    // A maximal set of radius 3 has neighbours 3..6 px apart: the path's
    // mean step must be of that order.
    let step = tour.length / (n - 1) as f64;
    assert!((3.0..4.5).contains(&step), "mean step {step}");
}

#[test]
fn tsp_handles_tiny_and_degenerate_inputs() {
    for n in 0..6 {
        let xy: Vec<[f64; 2]> = (0..n).map(|i| [i as f64, (i * i) as f64]).collect();
        let tour = tsp::plan(&xy, tsp::TspOptions::default());
        let mut o = tour.order.clone();
        o.sort_unstable();
        assert!(o.iter().copied().eq(0..n));
    }
    // Duplicates and collinear points.
    let xy = vec![[1.0, 1.0]; 50];
    assert_eq!(tsp::plan(&xy, tsp::TspOptions::default()).length, 0.0);
    let xy: Vec<[f64; 2]> = (0..200).map(|i| [((i * 73) % 200) as f64, 5.0]).collect();
    let tour = tsp::plan(&xy, tsp::TspOptions::default());
    assert!((tour.length - 199.0).abs() < 1e-9, "{}", tour.length);
}

/// Stipples a ramp of display grey from black (left) to white (right) as
/// `stipple` does (Smaller policy, r_max = 8 r_min, calibrated dots) and
/// returns, per band of 32 columns, the target grey and the drawing's grey
/// (1 − mean ink: the band's mean is a blur across the band).
fn ramp_greys(mapping: Mapping, r_min: f32) -> Vec<(f64, f64)> {
    let (w, h) = (2048u32, 384u32);
    let values = (0..w * h)
        .map(|i| (f64::from(i % w) + 0.5) as f32 / w as f32)
        .collect();
    let map = ImportanceMap::from_values(w, h, values).unwrap();
    let range = RadiusRange::new(r_min, 8.0 * r_min).unwrap();
    let radii = map.radii(mapping, range);
    let params = Params::new(w, h)
        .with_radius_map(Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap()))
        .with_policy(Policy::Smaller);
    let set = cpu::sample(&params, Default::default()).unwrap();
    let dots: Vec<Dot> = set
        .points
        .iter()
        .map(|p| Dot {
            x: p.x,
            y: p.y,
            radius: DotSize::Calibrated(1.0).radius(
                p.radius,
                mapping.dot_radius(map.value_at(p.x, p.y), range),
                1.0,
            ),
        })
        .collect();
    let img = raster::render(&dots, (w, h), 1.0).unwrap();
    (0..w / 32)
        .map(|band| {
            let (x0, x1) = (band * 32, band * 32 + 32);
            let target = f64::from(x0 + x1) / 2.0 / f64::from(w);
            let grey = 1.0 - raster::mean_ink(&img, x0, 24, x1, h - 24);
            (target, grey)
        })
        .collect()
}

#[test]
fn calibrated_dots_reproduce_a_ramp_within_four_percent() {
    for (mapping, r_min) in [
        (Mapping::Tone, 4.0),
        (Mapping::Tone, 2.0),
        (Mapping::ToneSized(0.4), 4.0),
    ] {
        let greys = ramp_greys(mapping, r_min);
        let mut worst = 0.0f64;
        for &(target, grey) in greys.iter().filter(|(t, _)| (0.05..=0.95).contains(t)) {
            worst = worst.max((grey - target).abs());
        }
        eprintln!("{mapping:?}, r_min {r_min}: worst error {worst:.3}");
        assert!(
            worst < 0.04,
            "{mapping:?}, r_min {r_min}: worst error {worst:.3}: {greys:.2?}"
        );
        // Black is black: the darkest bands reach 95% ink.
        assert!(
            greys[0].1 < 0.05,
            "{mapping:?}: black band grey {:.3}",
            greys[0].1
        );
    }
}

#[test]
fn the_paper_ramp_does_not_reproduce_tones() {
    // The same ramp through the linear mapping misses by far: the ramp test
    // can fail.
    let greys = ramp_greys(Mapping::Linear, 4.0);
    let worst = greys
        .iter()
        .filter(|(t, _)| (0.05..=0.95).contains(t))
        .map(|(t, g)| (g - t).abs())
        .fold(0.0, f64::max);
    assert!(worst > 0.1, "worst error {worst:.3}");
}
