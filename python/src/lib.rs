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

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use pixelpie::analyze::{CoverRadius, Domain};
use pixelpie::backend::{self, BackendChoice};
use pixelpie::importance::{self, ImportanceMap, ImportanceOptions, Tones};
use pixelpie::job::{Format, Job, Radii, SampleJob};
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

/// The native `sample`; see `pixelpie.sample`.
#[pyfunction]
#[pyo3(signature = (width, height, radius, points, radius_map, importance_path, importance_values, policy_name, seed, subpixel_bits, periodic, exact, backend_name, max_iterations, progress))]
#[expect(
    clippy::too_many_arguments,
    reason = "Python's keyword arguments, one by one"
)]
fn sample<'py>(
    py: Python<'py>,
    width: u32,
    height: u32,
    radius: Option<f32>,
    points: Option<usize>,
    radius_map: Option<PyReadonlyArray2<'py, f32>>,
    importance_path: Option<PathBuf>,
    importance_values: Option<PyReadonlyArray2<'py, f32>>,
    policy_name: &str,
    seed: u64,
    subpixel_bits: u32,
    periodic: bool,
    exact: bool,
    backend_name: &str,
    max_iterations: Option<u32>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let choice: BackendChoice = named(backend_name, "backend")?;
    if usize::from(radius_map.is_some())
        + usize::from(importance_path.is_some())
        + usize::from(importance_values.is_some())
        > 1
    {
        return Err(bad("give at most one of radius_map and importance"));
    }
    // Python's idiom: `radius` is the black pixels' radius with an
    // importance map; an array is the grey to reproduce, as it is.
    let mut importance = ImportanceOptions::default();
    let radii = if let Some(a) = &radius_map {
        if radius.is_some() {
            return Err(bad(
                "radius and radius_map exclude each other (points scales the map)",
            ));
        }
        let (w, h, radii) = grid(a, "radius_map")?;
        if (w, h) != (width, height) {
            return Err(bad(format!(
                "radius_map has shape ({h}, {w}); the {width}x{height} domain needs ({height}, {width})"
            )));
        }
        Radii::Map {
            width: w,
            height: h,
            radii,
        }
    } else if let Some(path) = &importance_path {
        importance.min_radius = radius;
        Radii::Picture(ImportanceMap::open(path, None).map_err(|e| py_err(&e.into()))?)
    } else if let Some(a) = &importance_values {
        importance.min_radius = radius;
        importance.tones = Tones::Linear;
        let (w, h, values) = grid(a, "importance")?;
        Radii::Picture(ImportanceMap::from_values(w, h, values).map_err(|e| py_err(&e.into()))?)
    } else {
        Radii::Uniform(radius)
    };
    if matches!(radii, Radii::Picture(_)) && radius.is_none() && points.is_none() {
        return Err(bad(
            "give points or radius (the black pixels' radius) with an importance map",
        ));
    }
    let mut job = SampleJob::new(radii);
    job.width = Some(width);
    job.height = Some(height);
    job.points = points;
    job.importance = importance;
    job.policy = named(policy_name, "policy")?;
    job.sampler.seed = seed;
    job.sampler.subpixel_bits = subpixel_bits;
    job.sampler.periodic = periodic;
    job.sampler.exact = exact;
    if let Some(m) = max_iterations {
        job.max_iterations = m;
    }
    job.check().map_err(|e| py_err(&e.into()))?;
    let set = cancellable(py, progress, move |ctl| {
        Ok(job
            .run(|p| Ok(backend::sample(p, choice, ctl, &mut |_| {})?))?
            .set)
    })?;
    let rows = set.points.iter().map(|p| [p.x, p.y, p.radius]);
    Ok((points_array(py, rows)?, to_python(py, &set.report())?))
}

/// The job of `options`, a JSON object of keyword arguments under the
/// library's own names ([`Job`]'s fields, as `pixelpie stipple` spells them
/// with underscores); a name that is not an option is refused.
fn job_from(options: &str) -> PyResult<Job> {
    let given: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(options).map_err(|e| bad(format!("options: {e}")))?;
    let known = match job_options() {
        Ok(serde_json::Value::Object(m)) => m,
        _ => {
            return Err(PyRuntimeError::new_err(
                "the job's options are not an object",
            ));
        }
    };
    if let Some(name) = given.keys().find(|k| !known.contains_key(k.as_str())) {
        let mut names: Vec<&str> = known.keys().map(String::as_str).collect();
        names.sort_unstable();
        return Err(bad(format!(
            "stipple() got an unexpected option '{name}'; the options are: {}",
            names.join(", ")
        )));
    }
    let job: Job = match serde_json::from_value(serde_json::Value::Object(given.clone())) {
        Ok(job) => job,
        Err(e) => {
            // Name the option at fault: the first that fails on its own.
            let culprit = given.iter().find(|(k, v)| {
                let one = serde_json::Map::from_iter([((*k).clone(), (*v).clone())]);
                serde_json::from_value::<Job>(serde_json::Value::Object(one)).is_err()
            });
            return Err(bad(match culprit {
                Some((name, _)) => format!("{name}: {e}"),
                None => e.to_string(),
            }));
        }
    };
    job.check().map_err(|e| py_err(&e.into()))?;
    Ok(job)
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
    let mut v = serde_json::to_value(&job)?;
    if let serde_json::Value::Object(m) = &mut v {
        for (name, default) in [
            ("pens", serde_json::Value::Null),
            ("paper", serde_json::Value::Null),
            ("margin", serde_json::Value::Null),
            ("landscape", serde_json::to_value(job.landscape)?),
            ("dot_path", serde_json::to_value(job.dot_path)?),
        ] {
            m.entry(name).or_insert(default);
        }
    }
    Ok(v)
}

/// The native `stipple`; see `pixelpie.stipple`.
#[pyfunction(name = "stipple")]
#[pyo3(signature = (image, output, options, backend_name, progress))]
fn stipple_py<'py>(
    py: Python<'py>,
    image: PathBuf,
    output: Option<PathBuf>,
    options: &str,
    backend_name: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let job = job_from(options)?;
    let choice: BackendChoice = named(backend_name, "backend")?;
    if let Some(out) = &output {
        let format = Format::from_path(out).map_err(|e| py_err(&e.into()))?;
        job.validate(format).map_err(|e| py_err(&e.into()))?;
    }
    let drawing = cancellable(py, progress, |ctl| {
        let drawing = job.run_on(&image, choice, ctl, &mut |_| {})?;
        ctl.check()?;
        if let Some(out) = &output {
            job.write(&drawing, out)?;
        }
        Ok(drawing)
    })?;
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
    m.add_function(wrap_pyfunction!(stipple_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(analyze_py, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
