//! Importance maps: every format decodes to the right linear luminance, HDR
//! normalization follows its documented rule, bad files fail with the file
//! named, and the adjustments and mappings keep their promises.

mod fixtures;

use std::path::Path;

use fixtures::{decode_srgb, exr_rgba, exr_y, file, gray16, halves_gray8, rgb8, rgba8};
use image::{DynamicImage, ImageBuffer, Rgb};
use pixelpie::importance::{
    Adjust, Error, ImportanceMap, Mapping, RadiusRange, Range, fit_size, ink, load,
};

const LUMA: [f64; 3] = [0.2126, 0.7152, 0.0722];

fn open(path: &Path) -> ImportanceMap {
    ImportanceMap::open(path, None).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn assert_close(got: f32, want: f64, tol: f64, what: &str) {
    assert!(
        (f64::from(got) - want).abs() <= tol,
        "{what}: got {got}, want {want} ± {tol}"
    );
}

#[test]
fn each_integer_format_decodes_to_linear_luminance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let c = |v: u8| decode_srgb(f64::from(v) / 255.0);

    halves_gray8(8, 4, 128, 255)
        .save(file(d, "g8.png"))
        .unwrap();
    let m = open(&file(d, "g8.png"));
    assert_eq!((m.width(), m.height()), (8, 4));
    assert_close(m.value(0, 0), c(128), 1e-5, "8-bit grey PNG, left");
    assert_close(m.value(7, 3), 1.0, 1e-6, "8-bit grey PNG, right");

    gray16(5, 3, 40_000).save(file(d, "g16.png")).unwrap();
    assert_close(
        open(&file(d, "g16.png")).value(4, 2),
        decode_srgb(40_000.0 / 65535.0),
        1e-5,
        "16-bit grey PNG",
    );

    rgb8(4, 4, [0, 255, 0]).save(file(d, "green.png")).unwrap();
    assert_close(
        open(&file(d, "green.png")).value(1, 1),
        LUMA[1],
        1e-5,
        "RGB PNG, pure green",
    );

    // Alpha composites over white paper.
    rgba8(4, 4, [0, 0, 0, 0])
        .save(file(d, "clear.png"))
        .unwrap();
    assert_close(
        open(&file(d, "clear.png")).value(0, 0),
        1.0,
        1e-6,
        "transparent RGBA",
    );
    rgba8(4, 4, [0, 0, 0, 102])
        .save(file(d, "veil.png"))
        .unwrap();
    assert_close(
        open(&file(d, "veil.png")).value(0, 0),
        1.0 - 102.0 / 255.0,
        1e-4,
        "40% black RGBA",
    );

    halves_gray8(16, 16, 128, 128)
        .save(file(d, "g.jpg"))
        .unwrap();
    assert_close(
        open(&file(d, "g.jpg")).value(8, 8),
        c(128),
        0.01,
        "grey JPEG",
    );

    let bmp = [200u8, 100, 50];
    rgb8(6, 2, bmp).save(file(d, "c.bmp")).unwrap();
    let want = LUMA[0] * c(bmp[0]) + LUMA[1] * c(bmp[1]) + LUMA[2] * c(bmp[2]);
    assert_close(open(&file(d, "c.bmp")).value(5, 1), want, 1e-5, "RGB BMP");

    rgb8(6, 2, [10, 20, 30]).save(file(d, "c.webp")).unwrap();
    let want = LUMA[0] * c(10) + LUMA[1] * c(20) + LUMA[2] * c(30);
    assert_close(
        open(&file(d, "c.webp")).value(0, 0),
        want,
        1e-5,
        "lossless WebP",
    );

    let tiff: ImageBuffer<Rgb<u16>, Vec<u16>> =
        ImageBuffer::from_pixel(3, 3, Rgb([30_000, 30_000, 30_000]));
    tiff.save(file(d, "c16.tiff")).unwrap();
    assert_close(
        open(&file(d, "c16.tiff")).value(2, 2),
        decode_srgb(30_000.0 / 65535.0),
        1e-4,
        "16-bit RGB TIFF",
    );
}

#[test]
fn format_is_recognized_by_content_not_extension() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(dir.path(), "actually-a-png.jpg");
    halves_gray8(4, 4, 0, 0)
        .save_with_format(&path, image::ImageFormat::Png)
        .unwrap();
    assert_close(open(&path).value(0, 0), 0.0, 1e-6, "PNG named .jpg");
}

#[test]
fn exr_half_float_scanline_tiled_y_and_rgba_load() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Y ramp 0..2 across 64 columns, in each storage variant.
    let ramp = |x: usize, _: usize| 2.0 * x as f32 / 63.0;
    for (half, tiled) in [(true, false), (false, false), (true, true), (false, true)] {
        let path = file(d, &format!("y-{half}-{tiled}.exr"));
        exr_y(&path, 64, 8, half, tiled, ramp);
        let lum = load(&path).unwrap();
        assert_eq!(lum.range, Range::Float);
        assert_eq!((lum.width, lum.height), (64, 8));
        assert_close(lum.values[32], 2.0 * 32.0 / 63.0, 2e-3, "EXR Y sample");
        // With an explicit white point of 2 the ramp maps to 0..1.
        let m = ImportanceMap::open(&path, Some(2.0)).unwrap();
        assert_close(m.value(63, 0), 1.0, 1e-3, "EXR ramp end");
        assert_close(m.value(21, 7), 21.0 / 63.0, 2e-3, "EXR ramp middle");
    }
    // RGBA: luminance of linear RGB; alpha is premultiplied, over white.
    let path = file(d, "rgba.exr");
    exr_rgba(&path, 4, 4, [0.25, 0.25, 0.25, 0.5]);
    let m = ImportanceMap::open(&path, Some(1.0)).unwrap();
    assert_close(
        m.value(0, 0),
        0.25 + 0.5,
        1e-4,
        "premultiplied RGBA over white",
    );
    exr_rgba(&path, 4, 4, [1.0, 0.0, 0.0, 1.0]);
    let m = ImportanceMap::open(&path, Some(1.0)).unwrap();
    assert_close(m.value(3, 3), LUMA[0], 1e-4, "red EXR luminance");
}

#[test]
fn hdr_white_point_is_the_99_5th_percentile() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(dir.path(), "hdr.exr");
    // 1000 pixels: a ramp i/1000 and four highlights of 1000 (0.4%).
    exr_y(&path, 100, 10, false, false, |x, y| {
        let i = y * 100 + x;
        if i >= 996 { 1000.0 } else { i as f32 / 1000.0 }
    });
    let lum = load(&path).unwrap();
    // Sorted, index ceil(0.995 * 1000) - 1 = 994 is the ramp's 0.994.
    assert_close(lum.white_point(), 0.994, 1e-6, "white point");
    let m = lum.normalized(None).unwrap();
    assert_close(m.value(97, 4), 497.0 / 994.0, 1e-5, "mid ramp");
    assert_eq!(m.value(99, 9), 1.0, "highlights clip to white");
    assert_eq!(m.value(95, 9), 1.0, "the ramp above the white point clips");
    // Integer images are not stretched: a dark PNG stays dark.
    let png = file(dir.path(), "dark.png");
    halves_gray8(4, 4, 60, 60).save(&png).unwrap();
    assert_close(
        open(&png).value(0, 0),
        decode_srgb(60.0 / 255.0),
        1e-5,
        "dark PNG",
    );
    // A float TIFF is HDR too.
    let tif = file(dir.path(), "f.tiff");
    let img: ImageBuffer<Rgb<f32>, Vec<f32>> =
        ImageBuffer::from_fn(20, 10, |x, _| Rgb([x as f32 * 0.5; 3]));
    DynamicImage::ImageRgb32F(img).save(&tif).unwrap();
    let lum = load(&tif).unwrap();
    assert_eq!(lum.range, Range::Float);
    assert_close(lum.white_point(), 9.5, 1e-4, "float TIFF white point");
}

#[test]
fn nan_and_infinite_pixels_are_refused_with_file_channel_and_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(dir.path(), "bad-pixel.exr");
    exr_y(&path, 8, 4, false, false, |x, y| {
        if (x, y) == (3, 1) { f32::NAN } else { 0.5 }
    });
    let err = ImportanceMap::open(&path, None).unwrap_err();
    assert!(
        matches!(err, Error::NonFinite { x: 3, y: 1, .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    for part in ["bad-pixel.exr", "NaN", "'Y'", "(3, 1)"] {
        assert!(msg.contains(part), "'{msg}' lacks {part}");
    }
    exr_y(&path, 8, 4, false, false, |x, y| {
        if (x, y) == (7, 3) { f32::INFINITY } else { 0.5 }
    });
    let msg = ImportanceMap::open(&path, None).unwrap_err().to_string();
    assert!(msg.contains("inf") && msg.contains("(7, 3)"), "{msg}");
}

#[test]
fn corrupt_truncated_and_empty_files_fail_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let noise = ImageBuffer::from_fn(64, 64, |x, y| {
        image::Luma([((x * 31 + y * 17) % 251) as u8])
    });
    noise.save(file(d, "full.png")).unwrap();
    let bytes = std::fs::read(file(d, "full.png")).unwrap();
    std::fs::write(file(d, "truncated.png"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(file(d, "empty.png"), b"").unwrap();
    std::fs::write(
        file(d, "garbage.jpg"),
        b"\xff\xd8\xff\xe0 this is not a JPEG at all",
    )
    .unwrap();
    std::fs::write(file(d, "text.bmp"), b"hello").unwrap();
    exr_y(&file(d, "full.exr"), 64, 64, false, false, |x, _| x as f32);
    let exr = std::fs::read(file(d, "full.exr")).unwrap();
    std::fs::write(file(d, "truncated.exr"), &exr[..exr.len() * 3 / 5]).unwrap();
    std::fs::write(file(d, "empty.exr"), b"").unwrap();
    for name in [
        "truncated.png",
        "empty.png",
        "garbage.jpg",
        "text.bmp",
        "truncated.exr",
        "empty.exr",
        "missing.png",
    ] {
        let err = ImportanceMap::open(&file(d, name), None)
            .err()
            .unwrap_or_else(|| panic!("{name} loaded"));
        let msg = err.to_string();
        assert!(msg.contains(name), "{name}: '{msg}'");
        assert!(!msg.contains('\n'), "{name}: one line, got '{msg}'");
    }
    // A directory is not an image either.
    assert!(ImportanceMap::open(d, None).is_err());
}

#[test]
fn adjustments_apply_levels_then_gamma_then_invert() {
    let m = ImportanceMap::from_values(5, 1, vec![0.0, 0.1, 0.4, 0.7, 1.0]).unwrap();
    let a = Adjust {
        black: 0.1,
        white: 0.7,
        gamma: 2.0,
        invert: false,
    };
    let got = m.adjusted(&a).unwrap();
    let want = [0.0, 0.0, 0.25, 1.0, 1.0];
    for (g, w) in got.values().iter().zip(want) {
        assert_close(*g, w, 1e-6, "levels + gamma");
    }
    let inv = m.adjusted(&Adjust { invert: true, ..a }).unwrap();
    for (g, w) in inv.values().iter().zip(want) {
        assert_close(*g, 1.0 - w, 1e-6, "inverted");
    }
    assert!(m.adjusted(&Adjust { gamma: 0.0, ..a }).is_err());
    assert!(m.adjusted(&Adjust { black: 0.8, ..a }).is_err());
    assert!(ImportanceMap::from_values(2, 1, vec![0.5, 1.5]).is_err());
}

#[test]
fn mappings_are_monotone_and_exact_at_both_ends() {
    let range = RadiusRange::new(2.5, 17.0).unwrap();
    for mapping in [Mapping::Linear, Mapping::Tone, Mapping::ToneSized(0.4)] {
        assert_eq!(mapping.radius(0.0, range), 2.5);
        assert_eq!(mapping.radius(1.0, range), 17.0);
        let mut last = 0.0;
        for i in 0..=1000 {
            let r = mapping.radius(i as f32 / 1000.0, range);
            assert!(
                r >= last && (2.5..=17.0).contains(&r),
                "{mapping:?} at {i}: {r}"
            );
            last = r;
        }
    }
    // Tone: the black dots put down ink 1 − v on the disks of v, by the
    // measured curve, wherever r stays inside the range.
    for mapping in [Mapping::Tone, Mapping::ToneSized(0.4)] {
        for v in [0.1f32, 0.3, 0.5, 0.7] {
            let (r, rho) = (mapping.radius(v, range), mapping.dot_radius(v, range));
            let k = ink::ink(f64::from(rho / r), f64::from(r));
            assert!(
                (k - f64::from(1.0 - v)).abs() < 2e-3,
                "{mapping:?} v {v}: ink {k}"
            );
        }
    }
    // Linear is the paper's ramp.
    assert_close(
        Mapping::Linear.radius(0.5, range),
        9.75,
        1e-6,
        "linear midpoint",
    );
}

#[test]
fn resizing_keeps_the_mean_and_the_aspect() {
    let values: Vec<f32> = (0..300 * 200)
        .map(|i| ((i % 300) as f32 / 299.0).powi(2))
        .collect();
    let m = ImportanceMap::from_values(300, 200, values).unwrap();
    let mean = |m: &ImportanceMap| {
        m.values().iter().map(|&v| f64::from(v)).sum::<f64>() / m.values().len() as f64
    };
    for (w, h) in [(150, 100), (600, 400), (97, 61)] {
        let r = m.resized(w, h).unwrap();
        assert_eq!((r.width(), r.height()), (w, h));
        assert!(
            (mean(&r) - mean(&m)).abs() < 0.01,
            "{w}x{h}: {} vs {}",
            mean(&r),
            mean(&m)
        );
    }
    assert_eq!(fit_size((300, 200), Some(600), None), (600, 400));
    assert_eq!(fit_size((300, 200), None, Some(50)), (75, 50));
}

#[test]
fn white_cutoff_keeps_only_dots_at_or_below_the_level() {
    let m = ImportanceMap::from_values(2, 1, vec![0.3, 0.9]).unwrap();
    assert!(m.keeps(0.5, 0.5, Some(0.5)));
    assert!(!m.keeps(1.5, 0.5, Some(0.5)));
    assert!(m.keeps(1.5, 0.5, None));
    let radii = [2.0, 2.0];
    let all = m.expected_points(&radii, None);
    assert!((m.expected_points(&radii, Some(0.5)) - all / 2.0).abs() < 1e-9);
}

#[test]
fn bundled_assets_load() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !["png", "jpg", "exr"].contains(&ext) {
            continue;
        }
        let m = open(&path);
        assert!(m.values().iter().all(|v| (0.0..=1.0).contains(v)));
        n += 1;
    }
    assert!(n >= 4, "expected at least 4 assets, found {n}");
    let default = open(&dir.join("default.png"));
    assert!(default.width().max(default.height()) <= 512);
    // The EXR asset is HDR: its highlight is clipped by the percentile rule.
    let lum = load(&dir.join("gradient.exr")).unwrap();
    assert_eq!(lum.range, Range::Float);
    assert!(lum.values.iter().copied().fold(0.0, f32::max) > 50.0);
    assert!(lum.white_point() < 5.0);
}

/// A 60×40 RGB PNG, black on its left third, white elsewhere, whose EXIF
/// says "rotate 90° clockwise to view" (orientation 6), as phones write.
fn sideways_png(path: &Path) {
    use image::ImageEncoder;
    let img = image::RgbImage::from_fn(60, 40, |x, _| {
        if x < 20 {
            Rgb([0, 0, 0])
        } else {
            Rgb([255, 255, 255])
        }
    });
    // TIFF header (big-endian), one IFD entry: tag 0x0112, SHORT, 1, value 6.
    let exif: Vec<u8> = [
        &b"MM\0\x2a"[..],
        &8u32.to_be_bytes(),
        &1u16.to_be_bytes(),
        &0x0112u16.to_be_bytes(),
        &3u16.to_be_bytes(),
        &1u32.to_be_bytes(),
        &6u16.to_be_bytes(),
        &0u16.to_be_bytes(),
        &0u32.to_be_bytes(),
    ]
    .concat();
    let file = std::fs::File::create(path).unwrap();
    let mut enc = image::codecs::png::PngEncoder::new(std::io::BufWriter::new(file));
    enc.set_exif_metadata(exif).unwrap();
    enc.write_image(img.as_raw(), 60, 40, image::ExtendedColorType::Rgb8)
        .unwrap();
}

#[test]
fn photos_are_turned_upright_by_their_exif_orientation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sideways.png");
    sideways_png(&path);
    // Turned a quarter clockwise: 40 wide, 60 tall, the black third on top.
    let grey = open(&path);
    assert_eq!((grey.width(), grey.height()), (40, 60));
    assert!(grey.value(20, 5) < 0.01 && grey.value(20, 55) > 0.99);
    let colour = pixelpie::importance::ColourMap::open(&path, None).unwrap();
    assert_eq!((colour.width(), colour.height()), (40, 60));
    assert!(colour.rgb()[5 * 40 + 20][0] < 0.01);
    let bytes = std::fs::read(&path).unwrap();
    let from_bytes = ImportanceMap::from_encoded(&bytes, &path, None).unwrap();
    assert_eq!(from_bytes, grey);
    let decoded = pixelpie::importance::decode_file(&path).unwrap();
    assert_eq!((decoded.width(), decoded.height()), (40, 60));
}
