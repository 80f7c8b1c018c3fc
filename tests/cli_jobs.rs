//! `pixelpie stipple`'s saved jobs (`--save-job`, `--job`) and batches
//! (several pictures, `-o DIR/`), through the binary.

mod fixtures;

use std::path::Path;

use fixtures::{asset, ok, pixelpie, s};

#[test]
fn a_saved_job_replays_byte_for_byte_and_flags_override_it() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a.svg"),
        dir.path().join("b.svg"),
        dir.path().join("c.svg"),
    );
    let job = dir.path().join("job.toml");
    let photo = asset("astronaut.jpg");
    ok(&[
        "stipple",
        &photo,
        "--points",
        "1500",
        "--relax",
        "2",
        "--gamma",
        "1.2",
        "--pens",
        "cmyk",
        "--order",
        "tsp",
        "--seed",
        "5",
        "-q",
        "-o",
        s(&a),
        "--save-job",
        s(&job),
    ]);
    let text = std::fs::read_to_string(&job).unwrap();
    assert!(
        text.contains("points = 1500") && text.contains("[[pens]]"),
        "{text}"
    );
    ok(&["stipple", &photo, "--job", s(&job), "-q", "-o", s(&b)]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // A flag given with the job overrides its setting, and only that one.
    let again = dir.path().join("again.toml");
    ok(&[
        "stipple",
        &photo,
        "--job",
        s(&job),
        "--seed",
        "6",
        "-q",
        "-o",
        s(&c),
        "--save-job",
        s(&again),
    ]);
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap());
    let changed: Vec<_> = text
        .lines()
        .zip(std::fs::read_to_string(&again).unwrap().lines())
        .filter(|(x, y)| x != y)
        .map(|(_, y)| y.to_string())
        .collect();
    assert_eq!(changed, vec!["seed = 6".to_string()]);
}

#[test]
fn a_job_file_with_an_unknown_key_or_version_is_said() {
    let dir = tempfile::tempdir().unwrap();
    let photo = asset("astronaut.jpg");
    let out = dir.path().join("x.svg");
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "pixelpie = \"0.1.0\"\npoints = 900\ndot_ration = 0.5\n",
    )
    .unwrap();
    let r = pixelpie(&["stipple", &photo, "--job", s(&bad), "-o", s(&out)]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("`dot_ration`") && err.contains("dot_ratio"),
        "{err}"
    );
    assert!(!out.exists());
    let old = dir.path().join("old.toml");
    std::fs::write(&old, "pixelpie = \"0.0.9\"\npoints = 900\n").unwrap();
    let r = ok(&["stipple", &photo, "--job", s(&old), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("warning:") && err.contains("0.0.9"), "{err}");
}

#[test]
fn a_batch_draws_every_good_picture_and_says_which_failed() {
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.png");
    std::fs::write(&broken, b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let folder = dir.path().join("out");
    let slash = format!("{}/", folder.display());
    let r = pixelpie(&[
        "stipple",
        &asset("astronaut.jpg"),
        s(&broken),
        &asset("rocket.jpg"),
        "--points",
        "800",
        "-o",
        &slash,
    ]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("broken.png") && err.contains("1 of 3"),
        "{err}"
    );
    assert!(folder.join("astronaut.svg").is_file() && folder.join("rocket.svg").is_file());
    assert!(!folder.join("broken.svg").exists());
    // The same drawing as a single run's.
    let one = dir.path().join("one.svg");
    ok(&[
        "stipple",
        &asset("rocket.jpg"),
        "--points",
        "800",
        "-q",
        "-o",
        s(&one),
    ]);
    assert_eq!(
        std::fs::read(&one).unwrap(),
        std::fs::read(folder.join("rocket.svg")).unwrap()
    );
    // --format picks the batch's format.
    let pngs = dir.path().join("pngs");
    ok(&[
        "stipple",
        &asset("astronaut.jpg"),
        &asset("rocket.jpg"),
        "--points",
        "500",
        "--format",
        "png",
        "-q",
        "-o",
        s(&pngs),
    ]);
    for name in ["astronaut.png", "rocket.png"] {
        assert!(image::open(pngs.join(name)).is_ok(), "{name}");
    }
}

#[test]
fn a_cut_short_jpeg_is_drawn_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(asset("astronaut.jpg")).unwrap();
    let cut = dir.path().join("cut.jpg");
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    let out = dir.path().join("cut.svg");
    let r = pixelpie(&["stipple", s(&cut), "--points", "500", "-o", s(&out)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("warning:") && err.contains("ends early"),
        "{err}"
    );
}

/// The mean grey (0 black, 1 white) of a PNG.
fn mean_grey(path: &Path) -> f64 {
    let img = image::open(path).unwrap().to_luma8();
    img.pixels().map(|p| f64::from(p.0[0]) / 255.0).sum::<f64>()
        / f64::from(img.width() * img.height())
}

#[test]
fn the_preview_shows_the_pen_and_a_pen_too_wide_warns_with_a_count() {
    let dir = tempfile::tempdir().unwrap();
    let photo = asset("astronaut.jpg");
    let mut greys = Vec::new();
    let mut warnings = Vec::new();
    for pen in ["0.3", "2.0"] {
        let preview = dir.path().join(format!("p{pen}.png"));
        let out = dir.path().join(format!("p{pen}.svg"));
        let r = ok(&[
            "stipple",
            &photo,
            "--points",
            "300000",
            "--pens",
            "cmyk",
            "--paper",
            "a4",
            "--pen-mm",
            pen,
            "--dot",
            "sized",
            "-o",
            s(&out),
            "--preview",
            s(&preview),
        ]);
        let img = image::open(&preview).unwrap();
        // The sheet: A4 portrait.
        let aspect = f64::from(img.height()) / f64::from(img.width());
        assert!((aspect - 297.0 / 210.0).abs() < 0.01, "{aspect}");
        greys.push(mean_grey(&preview));
        warnings.push(String::from_utf8_lossy(&r.stderr).to_string());
    }
    assert!(greys[1] < greys[0] - 0.05, "{greys:?}");
    for w in &warnings {
        assert!(
            w.contains("warning:") && w.contains("darker") && w.contains("--points"),
            "{w}"
        );
    }
    // The count it names draws the tones true: no warning.
    let count: String = warnings[0]
        .rsplit("--points ")
        .next()
        .unwrap()
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    let out = dir.path().join("true.svg");
    let r = ok(&[
        "stipple",
        &photo,
        "--points",
        &count,
        "--pens",
        "cmyk",
        "--paper",
        "a4",
        "--pen-mm",
        "0.3",
        "--dot",
        "sized",
        "-o",
        s(&out),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!err.contains("darker"), "{count} dots: {err}");
    // Without a pen the preview is the drawing's own PNG.
    let (png, preview) = (dir.path().join("d.png"), dir.path().join("dp.png"));
    ok(&[
        "stipple",
        &photo,
        "--points",
        "2000",
        "-o",
        s(&png),
        "--preview",
        s(&preview),
    ]);
    assert!((mean_grey(&png) - mean_grey(&preview)).abs() < 0.005);
}

#[test]
fn crop_and_rotate_frame_the_picture_and_are_saved_in_the_job() {
    let dir = tempfile::tempdir().unwrap();
    let photo = asset("rocket.jpg"); // 480×320
    let (a, job) = (dir.path().join("a.png"), dir.path().join("j.toml"));
    ok(&[
        "stipple",
        &photo,
        "--points",
        "1000",
        "--crop",
        "40,20,200,300",
        "--rotate",
        "90",
        "-q",
        "-o",
        s(&a),
        "--save-job",
        s(&job),
    ]);
    // 200×300 turned a quarter: 300 wide, 200 high, scaled to 1024 wide.
    let img = image::open(&a).unwrap();
    assert_eq!((img.width(), img.height()), (1024, 683));
    let text = std::fs::read_to_string(&job).unwrap();
    assert!(
        text.contains("crop = \"40,20,200,300\"") && text.contains("rotate = 90"),
        "{text}"
    );
    let b = dir.path().join("b.png");
    ok(&["stipple", &photo, "--job", s(&job), "-q", "-o", s(&b)]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    for (flag, value) in [
        ("--crop", "300,0,200,10"),
        ("--rotate", "45"),
        ("--crop", "1,2"),
    ] {
        let r = pixelpie(&[
            "stipple",
            &photo,
            flag,
            value,
            "-o",
            s(&dir.path().join("x.png")),
        ]);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(
            !r.status.success() && err.lines().count() == 1,
            "{flag} {value}: {err}"
        );
    }
}

#[test]
fn dots_sized_in_mm_are_that_size_on_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mm.svg");
    ok(&[
        "stipple",
        &asset("astronaut.jpg"),
        "--paper",
        "a5",
        "--dot-mm",
        "1.2",
        "-q",
        "-o",
        s(&out),
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    let largest = text
        .split(" r=\"")
        .skip(1)
        .map(|t| t[..t.find('"').unwrap()].parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    // The darkest dots: 1.2 mm across (the SVG's unit is the mm on paper).
    assert!((largest - 0.6).abs() < 0.01, "{largest}");
    let r = pixelpie(&[
        "stipple",
        &asset("astronaut.jpg"),
        "--dot-mm",
        "1",
        "-o",
        s(&out),
    ]);
    assert!(String::from_utf8_lossy(&r.stderr).contains("needs --width-mm or --paper"));
}

#[test]
fn a_png_of_dots_under_a_pixel_warns_with_a_count() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("small.png");
    let r = ok(&[
        "stipple",
        &asset("astronaut.jpg"),
        "--points",
        "20000",
        "--scale",
        "0.05",
        "-o",
        s(&out),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("warning: the PNG's dots are") && err.contains("dots, or a larger --scale"),
        "{err}"
    );
    let r = ok(&[
        "stipple",
        &asset("astronaut.jpg"),
        "--points",
        "20000",
        "-o",
        s(&out),
    ]);
    assert!(!String::from_utf8_lossy(&r.stderr).contains("warning"));
}

#[test]
fn every_key_given_a_wrong_type_is_named_with_its_value_and_what_it_takes() {
    use pixelpie::job::Job;
    use pixelpie::job::file::KEYS;
    // For each key, the first of these values its form refuses.
    let wrong = [
        toml::Value::String("zz".into()),
        toml::Value::Float(1.5),
        toml::Value::Boolean(true),
        toml::Value::Array(vec![toml::Value::Integer(1)]),
        toml::Value::Integer(-7),
    ];
    let mut named = 0;
    for &key in KEYS {
        let refused = wrong.iter().find_map(|v| {
            let table = toml::Table::from_iter([(key.to_owned(), v.clone())]);
            Job::from_table(table).err().map(|e| (v, e.to_string()))
        });
        let Some((value, message)) = refused else {
            continue;
        };
        let given = value.to_string();
        assert!(
            message.starts_with(&format!("{key} = {given}: ")),
            "{key} = {given}: {message}"
        );
        assert!(
            !message.contains("invalid type") && !message.contains("variant"),
            "{message}"
        );
        named += 1;
    }
    assert!(named >= 30, "only {named} keys refused a wrong type");
    // Through the command line: one line, the file first, then the key.
    let dir = tempfile::tempdir().unwrap();
    let job = dir.path().join("j.toml");
    std::fs::write(&job, "pixelpie = \"0.1.0\"\nrelax = \"tsp\"\n").unwrap();
    let out = dir.path().join("x.svg");
    let r = pixelpie(&[
        "stipple",
        &asset("default.png"),
        "--job",
        s(&job),
        "-o",
        s(&out),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success() && !out.exists());
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: relax = \"tsp\": expected a whole number, at least 0",
            job.display()
        )
    );
}

#[test]
fn a_pen_files_wrong_value_is_named_with_its_pen_and_key() {
    use pixelpie::colour::PenSet;
    let text = "[[pen]]\nname = \"a\"\ncolour = \"#000000\"\n\n[[pen]]\nname = \"b\"\ncolour = \"#ff0000\"\n";
    for (line, want) in [
        (
            "width_mm = \"x\"",
            "pens: pen 2: width_mm = \"x\": expected a number",
        ),
        (
            "dot_gain = true",
            "pens: pen 2: dot_gain = true: expected a number",
        ),
    ] {
        let e = PenSet::from_toml(&format!("{text}{line}\n")).unwrap_err();
        assert_eq!(e.to_string(), want);
    }
    // Through the command line, as a job file's: the file, then the pen.
    let dir = tempfile::tempdir().unwrap();
    let pens = dir.path().join("pens.toml");
    std::fs::write(&pens, format!("{text}width_mm = \"x\"\n")).unwrap();
    let out = dir.path().join("x.svg");
    let r = pixelpie(&[
        "stipple",
        &asset("default.png"),
        "--pens",
        s(&pens),
        "-o",
        s(&out),
    ]);
    assert!(!r.status.success() && !out.exists());
    assert_eq!(
        String::from_utf8_lossy(&r.stderr).trim(),
        format!(
            "error: {}: pen 2: width_mm = \"x\": expected a number",
            pens.display()
        )
    );
}
