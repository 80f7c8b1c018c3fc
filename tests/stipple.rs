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
    let dots = DotSize::Proportional(0.5).dots(&points);
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

/// Points per pixel inside [x0, x1) × [y0, y1).
fn density(points: &[Point], x0: f32, x1: f32, y0: f32, y1: f32) -> f64 {
    let n = points
        .iter()
        .filter(|p| (x0..x1).contains(&p.x) && (y0..y1).contains(&p.y))
        .count();
    n as f64 / f64::from((x1 - x0) * (y1 - y0))
}

#[test]
fn tone_mapping_makes_darker_regions_denser_by_the_promised_ratio() {
    // Left half v = 0.2 (darkness 0.8), right half v = 0.6 (darkness 0.4).
    let (w, h) = (512u32, 256u32);
    let values = (0..w * h)
        .map(|i| if i % w < w / 2 { 0.2 } else { 0.6 })
        .collect();
    let map = ImportanceMap::from_values(w, h, values).unwrap();
    let range = RadiusRange::new(4.0, 32.0).unwrap();
    let radii = map.radii(Mapping::Tone, range);
    let params = Params::new(w, h)
        .with_radius_map(Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap()))
        .with_policy(Policy::Smaller);
    let set = cpu::sample(&params, Default::default()).unwrap();
    // Density goes as 1/r²; the tone mapping makes 1/r² affine in darkness:
    // (floor + 0.8 a) / (floor + 0.4 a), floor = 1/32², a = 1/4² − floor.
    let (floor, a) = (1.0 / 1024.0, 1.0 / 16.0 - 1.0 / 1024.0);
    let promised = (floor + 0.8 * a) / (floor + 0.4 * a);
    let dark = density(&set.points, 32.0, 224.0, 32.0, 224.0);
    let light = density(&set.points, 288.0, 480.0, 32.0, 224.0);
    let ratio = dark / light;
    assert!(
        (ratio / promised - 1.0).abs() < 0.08,
        "density ratio {ratio:.3}, promised {promised:.3}"
    );
    // The linear mapping would give a very different ratio: the test can fail.
    let linear = (Mapping::Linear.radius(0.6, range) / Mapping::Linear.radius(0.2, range)).powi(2);
    assert!((f64::from(linear) / promised - 1.0).abs() > 0.3);
    // Drawn with equal dots, the dark half carries more ink, by about the
    // darkness ratio until dots start to overlap.
    let dots = DotSize::Fixed(0.5 * range.min).dots(&set.points);
    let img = raster::render(&dots, (w, h), 1.0).unwrap();
    let ink_dark = raster::mean_ink(&img, 32, 32, 224, 224);
    let ink_light = raster::mean_ink(&img, 288, 32, 480, 224);
    assert!(
        (ink_dark / ink_light / promised - 1.0).abs() < 0.12,
        "ink {ink_dark:.3} vs {ink_light:.3}"
    );
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
        tour.length < 0.93 * tour.nearest_neighbour_length,
        "2-opt {} vs nearest neighbour {}",
        tour.length,
        tour.nearest_neighbour_length
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

#[test]
fn tone_mapping_with_default_dots_reproduces_a_ramp() {
    // A linear ramp from black (left) to white (right), stippled as `stipple`
    // does by default: tone mapping, r_max = 8 r_min, fixed dots of
    // FIXED_DOT_FACTOR × r_min. The ink (in linear light) follows the darkness.
    let (w, h) = (1024u32, 256u32);
    let values = (0..w * h)
        .map(|i| (i % w) as f32 / (w - 1) as f32)
        .collect();
    let map = ImportanceMap::from_values(w, h, values).unwrap();
    let range = RadiusRange::new(5.0, 40.0).unwrap();
    let radii = map.radii(Mapping::Tone, range);
    let params = Params::new(w, h)
        .with_radius_map(Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap()))
        .with_policy(Policy::Smaller);
    let set = cpu::sample(&params, Default::default()).unwrap();
    let dots = DotSize::Fixed(pixelpie::stipple::FIXED_DOT_FACTOR * range.min).dots(&set.points);
    let img = raster::render(&dots, (w, h), 1.0).unwrap();
    for band in 1..9u32 {
        let (x0, x1) = (band * 102 + 10, band * 102 + 92);
        let darkness = 1.0 - f64::from(x0 + x1) / 2.0 / f64::from(w - 1);
        let ink = raster::mean_ink(&img, x0, 20, x1, h - 20);
        assert!(
            (ink - darkness).abs() < 0.08,
            "darkness {darkness:.2}: ink {ink:.3}"
        );
    }
}
