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
use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use pixelpie::analyze::{CoverRadius, Domain};
use pixelpie::backend::{self, BackendChoice};
use pixelpie::importance::{self, ImportanceMap, ImportanceOptions, Mapping, Tones, fit_size};
use pixelpie::sampler::{self, Control, Params, Policy, Progress, RadiusMap, SampleSet};
use pixelpie::stipple::{DotMode, Order, StippleOptions};

/// The Python exception for a library error.
fn py_err(e: &pixelpie::Error) -> PyErr {
    use pixelpie::Error as E;
    let text = pixelpie::one_line(e);
    match e {
        E::Sampler(sampler::Error::Cancelled) => PyKeyboardInterrupt::new_err(text),
        E::Sampler(e) if e.is_gpu() => PyRuntimeError::new_err(text),
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

fn policy(name: &str) -> PyResult<Policy> {
    Policy::ALL
        .into_iter()
        .find(|p| p.name() == name)
        .ok_or_else(|| {
            bad(format!(
                "policy '{name}' is not one of prior, current, bigger, smaller"
            ))
        })
}

fn backend_choice(name: &str) -> PyResult<BackendChoice> {
    match name {
        "auto" => Ok(BackendChoice::Auto),
        "cpu" => Ok(BackendChoice::Cpu),
        "gpu" => Ok(BackendChoice::Gpu),
        _ => Err(bad(format!(
            "backend '{name}' is not one of auto, cpu, gpu"
        ))),
    }
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

/// What `sample` draws its radii from.
enum Radii {
    Uniform(Option<f32>),
    Map(u32, u32, Vec<f32>),
    ImageFile(PathBuf),
    ImageValues(u32, u32, Vec<f32>),
}

fn run_sample(
    (width, height): (u32, u32),
    radii: Radii,
    radius: Option<f32>,
    points: Option<usize>,
    base: Params,
    choice: BackendChoice,
    ctl: Control<'_>,
) -> pixelpie::Result<SampleSet> {
    let mut run = |p: &Params| -> pixelpie::Result<SampleSet> {
        Ok(backend::sample(p, choice, ctl, &mut |_| {})?)
    };
    let image = match radii {
        Radii::Uniform(r) => {
            let make =
                |s: f64| -> pixelpie::Result<Params> { Ok(base.clone().with_radius(s as f32)) };
            let start = f64::from(r.unwrap_or(1.0));
            return Ok(pixelpie::count::sample_scaled(start, points, make, &mut run)?.0);
        }
        Radii::Map(w, h, values) => {
            let make = |s: f64| -> pixelpie::Result<Params> {
                let map = RadiusMap::from_pixels_scaled(w, h, &values, s)?;
                Ok(base.clone().with_radius_map(Arc::new(map)))
            };
            return Ok(pixelpie::count::sample_scaled(1.0, points, make, &mut run)?.0);
        }
        Radii::ImageFile(path) => (ImportanceMap::open(&path, None)?, Tones::Display),
        // An array is the grey to reproduce, as it is.
        Radii::ImageValues(w, h, values) => {
            (ImportanceMap::from_values(w, h, values)?, Tones::Linear)
        }
    };
    let (map, tones) = image;
    let mut opts = ImportanceOptions::default();
    opts.tones = tones;
    opts.min_radius = radius;
    let prepared = opts.prepare_map(
        map,
        |w, h| fit_size((w, h), Some(width), Some(height)),
        Mapping::Linear,
        points.is_some(),
    )?;
    Ok(prepared.sample(&base, points, run)?.set)
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
    let choice = backend_choice(backend_name)?;
    let mut base = Params::new(width, height)
        .with_policy(policy(policy_name)?)
        .with_seed(seed)
        .with_subpixel_bits(subpixel_bits)
        .with_periodic(periodic)
        .with_exact(exact);
    if let Some(m) = max_iterations {
        base = base.with_max_iterations(m);
    }
    let importance = importance_path.is_some() || importance_values.is_some();
    if usize::from(radius_map.is_some())
        + usize::from(importance_path.is_some())
        + usize::from(importance_values.is_some())
        > 1
    {
        return Err(bad("give at most one of radius_map and importance"));
    }
    let radii = if let Some(a) = &radius_map {
        if radius.is_some() {
            return Err(bad(
                "radius and radius_map exclude each other (points scales the map)",
            ));
        }
        let (w, h, values) = grid(a, "radius_map")?;
        if (w, h) != (width, height) {
            return Err(bad(format!(
                "radius_map has shape ({h}, {w}); the {width}x{height} domain needs ({height}, {width})"
            )));
        }
        Radii::Map(w, h, values)
    } else if let Some(path) = importance_path {
        Radii::ImageFile(path)
    } else if let Some(a) = &importance_values {
        let (w, h, values) = grid(a, "importance")?;
        Radii::ImageValues(w, h, values)
    } else {
        match (radius, points) {
            (Some(_), Some(_)) => {
                return Err(bad("give radius or points, not both"));
            }
            (None, None) => {
                return Err(bad("give radius, points, radius_map or importance"));
            }
            _ => Radii::Uniform(radius),
        }
    };
    if importance && radius.is_none() && points.is_none() {
        return Err(bad(
            "give points or radius (the black pixels' radius) with an importance map",
        ));
    }
    let set = cancellable(py, progress, move |ctl| {
        run_sample((width, height), radii, radius, points, base, choice, ctl)
    })?;
    let rows = set.points.iter().map(|p| [p.x, p.y, p.radius]);
    Ok((points_array(py, rows)?, to_python(py, &set.report())?))
}

/// The native `stipple`; see `pixelpie.stipple`.
#[pyfunction(name = "stipple")]
#[pyo3(signature = (image, output, points, width, height, dot, dot_factor, dot_ratio, dot_radius, relax, order, scale, width_mm, pen_mm, policy_name, seed, subpixel_bits, periodic, exact, tones, mapping, min_radius, max_radius, gamma, black_level, white_level, invert, white_cutoff, hdr_white, backend_name, progress))]
#[expect(
    clippy::too_many_arguments,
    reason = "Python's keyword arguments, one by one"
)]
fn stipple_py<'py>(
    py: Python<'py>,
    image: PathBuf,
    output: Option<PathBuf>,
    points: Option<usize>,
    width: Option<u32>,
    height: Option<u32>,
    dot: Option<&str>,
    dot_factor: Option<f32>,
    dot_ratio: f32,
    dot_radius: Option<f32>,
    relax: u32,
    order: &str,
    scale: f32,
    width_mm: Option<f64>,
    pen_mm: Option<f64>,
    policy_name: &str,
    seed: u64,
    subpixel_bits: u32,
    periodic: bool,
    exact: bool,
    tones: &str,
    mapping: Option<&str>,
    min_radius: Option<f32>,
    max_radius: Option<f32>,
    gamma: f32,
    black_level: f32,
    white_level: f32,
    invert: bool,
    white_cutoff: Option<f32>,
    hdr_white: Option<f32>,
    backend_name: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut o = StippleOptions::default();
    o.points = points;
    o.width = width;
    o.height = height;
    o.dot = match dot {
        None => None,
        Some("fixed") => Some(DotMode::Fixed),
        Some("sized") => Some(DotMode::Sized),
        Some("proportional") => Some(DotMode::Proportional),
        Some(d) => {
            return Err(bad(format!(
                "dot '{d}' is not one of fixed, sized, proportional"
            )));
        }
    };
    o.dot_factor = dot_factor;
    o.dot_ratio = dot_ratio;
    o.dot_radius = dot_radius;
    o.relax = relax;
    o.order = match order {
        "none" => Order::None,
        "tsp" => Order::Tsp,
        _ => return Err(bad(format!("order '{order}' is not one of none, tsp"))),
    };
    o.scale = scale;
    o.width_mm = width_mm;
    o.pen_mm = pen_mm;
    o.policy = policy(policy_name)?;
    o.sampler.seed = seed;
    o.sampler.subpixel_bits = subpixel_bits;
    o.sampler.periodic = periodic;
    o.sampler.exact = exact;
    let imp = &mut o.importance;
    imp.tones = match tones {
        "display" => Tones::Display,
        "linear" => Tones::Linear,
        _ => {
            return Err(bad(format!(
                "tones '{tones}' is not one of display, linear"
            )));
        }
    };
    imp.mapping = match mapping {
        None => None,
        Some("linear") => Some(importance::MappingKind::Linear),
        Some("tone") => Some(importance::MappingKind::Tone),
        Some(m) => return Err(bad(format!("mapping '{m}' is not one of linear, tone"))),
    };
    imp.min_radius = min_radius;
    imp.max_radius = max_radius;
    imp.gamma = gamma;
    imp.black_level = black_level;
    imp.white_level = white_level;
    imp.invert = invert;
    imp.white_cutoff = white_cutoff;
    imp.hdr_white = hdr_white;
    if dot_radius.is_some() && (points.is_some() || min_radius.is_some()) {
        return Err(bad("dot_radius excludes points and min_radius"));
    }
    let choice = backend_choice(backend_name)?;
    if let Some(out) = &output {
        let format = pixelpie::stipple::Format::from_path(out).map_err(|e| py_err(&e.into()))?;
        o.validate(format).map_err(|e| py_err(&e.into()))?;
    }
    let drawing = cancellable(py, progress, |ctl| {
        let drawing = o.run(
            &image,
            |p| Ok(backend::sample(p, choice, ctl, &mut |_| {})?),
            |_| ctl.check().is_ok(),
        )?;
        ctl.check()?;
        if let Some(out) = &output {
            o.write(&drawing, out)?;
        }
        Ok(drawing)
    })?;
    points_array(py, drawing.dots.iter().map(|d| [d.x, d.y, d.radius]))
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
    m.add_function(wrap_pyfunction!(analyze_py, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
