//! The native half of the `pixelpie` Python package: thin bindings over the
//! lean library. `pixelpie/__init__.py` normalizes the arguments (paths,
//! arrays to float32) and documents the functions.
//!
//! * The GIL is released while the library works; progress callbacks and
//!   signal checks take it back between iterations, so Ctrl-C
//!   (KeyboardInterrupt) cancels a run before its next iteration.
//! * Errors map to Python's: bad arguments to `ValueError`, files that
//!   cannot be read or written to `OSError`, with the CLI's messages.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use numpy::{
    PyArray1, PyArrayMethods, PyReadonlyArray2, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use pixelpie::analyze::{CoverRadius, Domain};
use pixelpie::backend::{self, BackendChoice};
use pixelpie::importance::{self, ImportanceMap, Tones};
use pixelpie::job::{Decoded, Format, Job, Radii, SampleJob};
use pixelpie::sampler::{self, Control, Progress};

/// The Python exception for a library error.
fn py_err(e: &pixelpie::Error) -> PyErr {
    use pixelpie::Error as E;
    let text = pixelpie::one_line(e);
    match e {
        E::Sampler(sampler::Error::Cancelled) => PyKeyboardInterrupt::new_err(text),
        E::Sampler(e) if e.is_backend() => PyRuntimeError::new_err(text),
        E::Importance(importance::Error::InvalidParameter(_))
        | E::Stipple(pixelpie::stipple::Error::InvalidParameter(_))
        | E::Io(pixelpie::io::Error::Invalid(_))
        | E::Sampler(_)
        | E::Analyze(_) => PyValueError::new_err(text),
        E::Importance(_) | E::Io(_) | E::Stipple(pixelpie::stipple::Error::Io(_)) => {
            PyOSError::new_err(text)
        }
        _ => PyRuntimeError::new_err(text),
    }
}

fn bad(text: impl Into<String>) -> PyErr {
    PyValueError::new_err(text.into())
}

/// The value of an enum the library names in lower case (its serde and
/// command-line names), such as a policy or a backend.
fn named<T: serde::de::DeserializeOwned>(name: &str, what: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(name.to_owned()))
        .map_err(|e| bad(format!("{what}: {e}")))
}

/// Runs `work` without the GIL, with a sampler control whose progress
/// calls `progress(iteration, points, empty, pixels)` and checks for
/// signals between iterations; an exception there (KeyboardInterrupt from
/// Ctrl-C among them) cancels the run and is raised.
fn cancellable<T: Send>(
    py: Python<'_>,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(Control<'_>) -> pixelpie::Result<T> + Send,
) -> PyResult<T> {
    let cancel = AtomicBool::new(false);
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let report = |p: Progress| {
        Python::attach(|py| {
            let result = match &progress {
                Some(f) => f
                    .call1(py, (p.iteration, p.points, p.empty_pixels, p.pixels))
                    .map(drop),
                None => Ok(()),
            }
            .and_then(|()| py.check_signals());
            if let Err(e) = result {
                if let Ok(mut slot) = raised.lock() {
                    slot.get_or_insert(e);
                }
                cancel.store(true, Ordering::Relaxed);
            }
        });
    };
    let result = py.detach(|| work(Control::new().with_progress(&report).with_cancel(&cancel)));
    if let Some(e) = raised.into_inner().ok().flatten() {
        return Err(e);
    }
    result.map_err(|e| py_err(&e))
}

/// Points as an (N, 3) float32 array of x, y and radius.
fn points_array<'py>(
    py: Python<'py>,
    rows: impl Iterator<Item = [f32; 3]>,
) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = rows.flatten().collect();
    let n = flat.len() / 3;
    Ok(PyArray1::from_vec(py, flat).reshape([n, 3])?.into_any())
}

/// A serializable value as a Python object (through JSON).
fn to_python<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// An (H, W) array's values, row-major, with its size as (width, height).
fn grid(a: &PyReadonlyArray2<'_, f32>, what: &str) -> PyResult<(u32, u32, Vec<f32>)> {
    let shape = a.shape();
    let (h, w) = (shape[0], shape[1]);
    let (Ok(w32), Ok(h32)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(bad(format!("{what} of shape ({h}, {w}) is too large")));
    };
    let values = a.as_array().iter().copied().collect();
    Ok((w32, h32, values))
}

/// The native `sample`; see `pixelpie.sample`. `options` is a JSON object
/// of [`SampleJob`]'s options; an array in `radius_map` or
/// `importance_values` takes the place of a file.
#[pyfunction]
#[pyo3(signature = (options, radius_map, importance_values, backend_name, progress))]
fn sample<'py>(
    py: Python<'py>,
    options: &str,
    radius_map: Option<PyReadonlyArray2<'py, f32>>,
    importance_values: Option<PyReadonlyArray2<'py, f32>>,
    backend_name: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mut job: SampleJob = from_options(options, "sample", &sample_options()?)?;
    let choice: BackendChoice = named(backend_name, "backend")?;
    let radii = if let Some(a) = &radius_map {
        if job.importance.is_some() || importance_values.is_some() {
            return Err(bad("give a radius map or an importance map, not both"));
        }
        let (width, height, radii) = grid(a, "radius_map")?;
        Radii::Map {
            width,
            height,
            radii,
        }
    } else if let Some(a) = &importance_values {
        // An array is the grey to reproduce, as it is: linear unless the
        // options say otherwise.
        let given: serde_json::Value =
            serde_json::from_str(options).map_err(|e| bad(format!("options: {e}")))?;
        if given.get("tones").is_none() {
            job.importance_options.tones = Tones::Linear;
        }
        let (w, h, values) = grid(a, "importance")?;
        Radii::Picture(ImportanceMap::from_values(w, h, values).map_err(|e| py_err(&e.into()))?)
    } else {
        job.radii().map_err(|e| py_err(&e))?
    };
    job.check(&radii).map_err(|e| py_err(&e.into()))?;
    let set = cancellable(py, progress, move |ctl| {
        Ok(job
            .run(&radii, |p| {
                Ok(backend::sample(p, choice, ctl, &mut |_| {})?)
            })?
            .set)
    })?;
    let rows = set.points.iter().map(|p| [p.x, p.y, p.radius]);
    Ok((points_array(py, rows)?, to_python(py, &set.report())?))
}

/// The point-set job's options and their defaults, as JSON (the names
/// `sample` takes).
#[pyfunction]
fn sample_defaults() -> PyResult<String> {
    serde_json::to_string(&sample_options()?).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// Every option of [`SampleJob`] with its default, `null` where the job
/// picks.
fn sample_options() -> PyResult<serde_json::Value> {
    let mut v =
        shortest(&SampleJob::default()).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    if let serde_json::Value::Object(m) = &mut v {
        for name in ["radius_map", "importance"] {
            m.entry(name).or_insert(serde_json::Value::Null);
        }
    }
    Ok(v)
}

/// `value` as JSON, its `f32` numbers written as the shortest decimals that
/// read back as them (0.3, not 0.30000001192092896).
fn shortest(value: &impl serde::Serialize) -> serde_json::Result<serde_json::Value> {
    serde_json::from_str(&serde_json::to_string(value)?)
}

/// A job of type `T` from `options`, a JSON object of keyword arguments
/// under the library's own names (`known`: every option with its default);
/// a name that is not an option, or a value of the wrong type or range, is
/// refused with the option's name (`ValueError`).
fn from_options<T: serde::de::DeserializeOwned>(
    options: &str,
    function: &str,
    known: &serde_json::Value,
) -> PyResult<T> {
    let given: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(options).map_err(|e| bad(format!("options: {e}")))?;
    let serde_json::Value::Object(known) = known else {
        return Err(PyRuntimeError::new_err(
            "the job's options are not an object",
        ));
    };
    if let Some(name) = given.keys().find(|k| !known.contains_key(k.as_str())) {
        let mut names: Vec<&str> = known.keys().map(String::as_str).collect();
        names.sort_unstable();
        return Err(bad(format!(
            "{function}() got an unexpected option '{name}'; the options are: {}",
            names.join(", ")
        )));
    }
    match serde_json::from_value(serde_json::Value::Object(given.clone())) {
        Ok(job) => Ok(job),
        Err(e) => {
            // Name the option at fault: the first that fails on its own.
            let culprit = given.iter().find(|(k, v)| {
                let one = serde_json::Map::from_iter([((*k).clone(), (*v).clone())]);
                serde_json::from_value::<T>(serde_json::Value::Object(one)).is_err()
            });
            let text = e.to_string();
            Err(bad(match culprit {
                Some((name, _)) if !text.starts_with(&format!("{name}:")) => {
                    format!("{name}: {text}")
                }
                _ => text,
            }))
        }
    }
}

/// The drawing job of `options` ([`from_options`]), over the job file at
/// `job_file` when given ([`Job::with_overrides`], as the CLI's `--job`
/// takes its options), checked.
fn job_from(options: &str, job_file: Option<&std::path::Path>) -> PyResult<Job> {
    let known = job_options().map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let job: Job = from_options(options, "stipple", &known)?;
    let job = match job_file {
        None => job,
        Some(path) => {
            let given: serde_json::Map<String, serde_json::Value> =
                serde_json::from_str(options).map_err(|e| bad(format!("options: {e}")))?;
            let file = pixelpie::job::file::JobFile::read(path).map_err(|e| py_err(&e))?;
            Job::with_overrides(file.table, &job, given.keys().map(String::as_str))
                .map_err(|e| py_err(&e))?
        }
    };
    job.check().map_err(|e| py_err(&e.into()))?;
    Ok(job)
}

/// The picture of `image` (a path) or `encoded` (an array's PNG bytes,
/// [`encoded_png`]), decoded as `job` draws it ([`Decoded`]).
fn decoded(
    job: &Job,
    image: Option<&std::path::Path>,
    encoded: Option<&[u8]>,
) -> pixelpie::Result<Decoded> {
    match (encoded, image) {
        (Some(bytes), _) => Decoded::decode(job, bytes, std::path::Path::new("<array>")),
        (None, Some(path)) => Decoded::open(job, path),
        (None, None) => Err(pixelpie::stipple::Error::InvalidParameter(
            "give a picture: a path, an array or a PIL image".into(),
        )
        .into()),
    }
}

/// The native `plan`; see `pixelpie.plan`: the drawing's plan as JSON.
#[pyfunction(name = "plan")]
#[pyo3(signature = (image, pixels, options, job_file))]
fn plan_py(
    py: Python<'_>,
    image: Option<PathBuf>,
    pixels: Option<PyReadonlyArrayDyn<'_, u16>>,
    options: &str,
    job_file: Option<PathBuf>,
) -> PyResult<String> {
    let job = job_from(options, job_file.as_deref())?;
    let encoded = pixels.as_ref().map(encoded_png).transpose()?;
    py.detach(|| {
        let picture = decoded(&job, image.as_deref(), encoded.as_deref())?;
        job.plan(picture.picture())?.plan.to_json()
    })
    .map_err(|e| py_err(&e))
}

/// The settings of the job file at `path` (`pixelpie stipple
/// --save-job`, the app's presets) as JSON, and the warning to give when
/// another version wrote it; a file that is not a job, or holds an unknown
/// setting, raises `ValueError`.
#[pyfunction]
fn read_job(path: PathBuf) -> PyResult<(String, Option<String>)> {
    let file = pixelpie::job::file::JobFile::read(&path).map_err(|e| py_err(&e))?;
    // Checked whole, as the CLI's --job checks it.
    Job::from_table(file.table.clone()).map_err(|e| py_err(&e))?;
    let json =
        serde_json::to_string(&file.table).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok((json, file.warning))
}

/// The drawing job's options and their defaults, as JSON (the names
/// `stipple` takes).
#[pyfunction]
fn stipple_defaults() -> PyResult<String> {
    let options = job_options().map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    serde_json::to_string(&options).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// Every option of the job with its default, `null` where the job picks
/// (the pens and the paper included, which the job's JSON leaves out while
/// they hold their defaults).
fn job_options() -> serde_json::Result<serde_json::Value> {
    let job = Job::default();
    let mut v = shortest(&job)?;
    if let serde_json::Value::Object(m) = &mut v {
        for (name, default) in [
            ("pens", serde_json::Value::Null),
            ("paper", serde_json::Value::Null),
            ("margin", serde_json::Value::Null),
            ("landscape", serde_json::to_value(job.landscape)?),
            ("dot_path", serde_json::to_value(job.dot_path)?),
            ("crop", serde_json::Value::Null),
            ("dot_mm", serde_json::Value::Null),
            ("rotate", serde_json::Value::Null),
            ("refill_mm", serde_json::Value::Null),
            ("layer_order", serde_json::to_value(job.layer_order)?),
            ("spacing", serde_json::to_value(job.spacing)?),
            ("correction", serde_json::to_value(job.correction)?),
            ("relax", serde_json::Value::Null),
        ] {
            m.entry(name).or_insert(default);
        }
    }
    Ok(v)
}

/// A picture array as the bytes of a 16-bit PNG, so that it takes the
/// file loader's one path (sRGB decoding, alpha over white): (H, W) grey,
/// (H, W, 2) grey and alpha, (H, W, 3) RGB or (H, W, 4) RGBA, sRGB-encoded
/// 16-bit values.
fn encoded_png(a: &PyReadonlyArrayDyn<'_, u16>) -> PyResult<Vec<u8>> {
    use image::ImageEncoder;
    let shape = a.shape().to_vec();
    let (h, w, c) = match shape[..] {
        [h, w] => (h, w, 1),
        [h, w, c] if (1..=4).contains(&c) => (h, w, c),
        _ => {
            return Err(bad(format!(
                "a picture array must be (H, W) or (H, W, 1 to 4 channels), not {shape:?}"
            )));
        }
    };
    let (Ok(w), Ok(h)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(bad(format!("a picture of shape {shape:?} is too large")));
    };
    if w == 0 || h == 0 {
        return Err(bad(format!(
            "the picture array of shape {shape:?} is empty"
        )));
    }
    let values: Vec<u8> = a.as_array().iter().flat_map(|v| v.to_ne_bytes()).collect();
    let colour = match c {
        1 => image::ExtendedColorType::L16,
        2 => image::ExtendedColorType::La16,
        3 => image::ExtendedColorType::Rgb16,
        _ => image::ExtendedColorType::Rgba16,
    };
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&values, w, h, colour)
        .map_err(|e| bad(format!("picture array: {e}")))?;
    Ok(out)
}

/// The native `stipple`; see `pixelpie.stipple`. The picture is a file
/// (`image`) or an array (`pixels`); with `want_svg` the SVG comes back as
/// text instead of the dots.
#[pyfunction(name = "stipple")]
#[pyo3(signature = (image, pixels, output, options, job_file, backend_name, want_svg, progress))]
#[expect(
    clippy::too_many_arguments,
    reason = "the Python function's arguments, one by one"
)]
fn stipple_py<'py>(
    py: Python<'py>,
    image: Option<PathBuf>,
    pixels: Option<PyReadonlyArrayDyn<'py, u16>>,
    output: Option<PathBuf>,
    options: &str,
    job_file: Option<PathBuf>,
    backend_name: &str,
    want_svg: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let job = job_from(options, job_file.as_deref())?;
    let choice: BackendChoice = named(backend_name, "backend")?;
    if let Some(out) = &output {
        let format = Format::from_path(out).map_err(|e| py_err(&e.into()))?;
        job.validate(format).map_err(|e| py_err(&e.into()))?;
    }
    let encoded = pixels.as_ref().map(encoded_png).transpose()?;
    let (drawing, svg) = cancellable(py, progress, |ctl| {
        let sample = |params: &pixelpie::sampler::Params| {
            Ok(backend::sample(params, choice, ctl, &mut |_| {})?)
        };
        let picture = decoded(&job, image.as_deref(), encoded.as_deref())?;
        let drawing = job.draw(picture.picture(), sample, |_| ctl.check().is_ok())?;
        ctl.check()?;
        if let Some(out) = &output {
            job.write(&drawing, out)?;
        }
        let svg = if want_svg {
            Some(job.svg(&drawing)?)
        } else {
            None
        };
        Ok((drawing, svg))
    })?;
    if let Some(svg) = svg {
        let text = String::from_utf8(svg).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        return Ok(pyo3::types::PyString::new(py, &text).into_any());
    }
    if drawing.pens.is_none() {
        return points_array(py, drawing.dots.iter().map(|d| [d.x, d.y, d.radius]));
    }
    // Colour: a fourth column, the pen's index.
    let flat: Vec<f32> = drawing
        .dots
        .iter()
        .zip(&drawing.points)
        .flat_map(|(d, p)| [d.x, d.y, d.radius, p.class as f32])
        .collect();
    let n = flat.len() / 4;
    Ok(PyArray1::from_vec(py, flat).reshape([n, 4])?.into_any())
}

/// The native `analyze`; see `pixelpie.analyze`.
#[pyfunction(name = "analyze")]
#[pyo3(signature = (points, width, height, periodic, radius))]
fn analyze_py<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    width: f64,
    height: f64,
    periodic: bool,
    radius: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let shape = points.shape();
    if shape[1] < 2 {
        return Err(bad(format!(
            "points of shape ({}, {}) need at least two columns, x and y",
            shape[0], shape[1]
        )));
    }
    let a = points.as_array();
    let xy: Vec<[f64; 2]> = a.rows().into_iter().map(|r| [r[0], r[1]]).collect();
    let radii: Option<Vec<f64>> = (shape[1] >= 3).then(|| a.column(2).to_vec());
    // The CLI's rules: every coordinate a finite number, every radius a
    // positive one, and a domain of positive size.
    if let Some(i) = xy
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(bad(format!(
            "point {i} ({}, {}) is not a finite position",
            xy[i][0], xy[i][1]
        )));
    }
    if let Some(r) = &radii
        && let Some(i) = r.iter().position(|r| !(r.is_finite() && *r > 0.0))
    {
        return Err(bad(format!(
            "point {i}'s radius {} must be a positive number",
            r[i]
        )));
    }
    if !(width.is_finite() && height.is_finite() && width > 0.0 && height > 0.0) {
        return Err(bad(format!(
            "the domain {width}x{height} must have a positive size"
        )));
    }
    if let Some(r) = radius
        && !(r.is_finite() && r > 0.0)
    {
        return Err(bad(format!("radius {r} must be a positive number")));
    }
    let domain = Domain {
        width,
        height,
        periodic,
    };
    let report = py.detach(|| {
        let cover = match (radius, &radii) {
            (Some(r), _) => Some(CoverRadius::Uniform(r)),
            (None, Some(r)) => Some(CoverRadius::PerPoint(r)),
            (None, None) => None,
        };
        pixelpie::analyze::report(&xy, domain, cover)
    });
    let report = report.map_err(|e| py_err(&e.into()))?;
    to_python(py, &report)
}

/// The native module.
#[pymodule]
fn _pixelpie(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(stipple_py, m)?)?;
    m.add_function(wrap_pyfunction!(plan_py, m)?)?;
    m.add_function(wrap_pyfunction!(stipple_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(read_job, m)?)?;
    m.add_function(wrap_pyfunction!(sample_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(analyze_py, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
