//! The native half of the `pixelpie` Python package: thin bindings over the
//! lean library. `pixelpie/__init__.py` normalizes the arguments (paths,
//! arrays to float32) and documents the functions.
//!
//! * The library works on a thread of its own, in this process's thread
//!   pool, without the GIL (every call that does work: [`cancellable`]); the calling thread waits for it and checks for
//!   signals every [`POLL`], so that Ctrl-C (KeyboardInterrupt) cancels any
//!   stage in well under half a second ([`cancellable`]).
//! * The thread pool is this process's own: a child made by `fork` (which
//!   does not inherit the parent's threads) makes a new one ([`pool`]).
//! * Errors map to Python's: bad values to `ValueError`, bad types to
//!   `TypeError`, files that cannot be read or written to `OSError` with
//!   its errno and file name (so `FileNotFoundError`, `PermissionError`,
//!   ...), with the library's messages in Python's words: each setting
//!   named as its keyword argument, `points=0` ([`said`]). A panic becomes
//!   `RuntimeError`: none reaches Python as pyo3's `PanicException`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError, mpsc};
use std::time::Duration;

use numpy::{
    PyArray1, PyArrayMethods, PyReadonlyArray2, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::exceptions::{
    PyKeyboardInterrupt, PyMemoryError, PyOSError, PyRuntimeError, PyTypeError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use pixelpie::analyze::{CoverRadius, Domain};
use pixelpie::backend::{self, BackendChoice};
use pixelpie::importance::{self, ImportanceMap, Tones, budget};
use pixelpie::job::{Decoded, Format, Job, Poster, Radii, SampleJob, Stipple};
use pixelpie::sampler::{self, Control, Progress};
use pixelpie::stipple::plot::Plotter;

/// The Python exception for a library error.
fn py_err(e: &pixelpie::Error) -> PyErr {
    let raw = pixelpie::raw_line(e);
    with_raw(py_err_said(e, &said(&raw)), &raw)
}

/// The Python exception for a library error whose message, in Python's
/// words, is `text`.
fn py_err_said(e: &pixelpie::Error, text: &str) -> PyErr {
    use pixelpie::Error as E;
    let text = text.to_owned();
    if let Some(err) = os_error(e, &text) {
        return err;
    }
    match e {
        E::Sampler(sampler::Error::Cancelled) | E::Analyze(pixelpie::analyze::Error::Cancelled) => {
            PyKeyboardInterrupt::new_err(text)
        }
        E::Importance(importance::Error::TooLarge { .. } | importance::Error::Memory(_)) => {
            PyMemoryError::new_err(text)
        }
        E::Sampler(e) if e.is_backend() => PyRuntimeError::new_err(text),
        E::Importance(importance::Error::InvalidParameter(_))
        | E::Stipple(pixelpie::stipple::Error::InvalidParameter(_))
        | E::Stipple(pixelpie::stipple::Error::Setting(_))
        | E::Io(pixelpie::io::Error::Invalid(_))
        | E::Sampler(_)
        | E::Pens(_)
        | E::Analyze(_) => PyValueError::new_err(text),
        E::Importance(_) | E::Io(_) | E::Stipple(pixelpie::stipple::Error::Io(_)) => {
            PyOSError::new_err(text)
        }
        _ => PyRuntimeError::new_err(text),
    }
}

/// A file that could not be read or written, as Python's `OSError(errno,
/// message, filename)`: Python makes it the subclass of its errno
/// (`FileNotFoundError`, `PermissionError`, `IsADirectoryError`, ...).
fn os_error(e: &pixelpie::Error, text: &str) -> Option<PyErr> {
    use pixelpie::Error as E;
    let (path, io): (Option<&Path>, &std::io::Error) = match e {
        E::Importance(importance::Error::Io { path, error }) => (Some(path), error),
        E::Io(pixelpie::io::Error::Write { path, source }) => {
            (Some(path), source.downcast_ref::<std::io::Error>()?)
        }
        E::Stipple(pixelpie::stipple::Error::Io(error)) => (None, error),
        _ => return None,
    };
    let errno = io.raw_os_error()?;
    Some(match path {
        Some(path) => PyOSError::new_err((errno, text.to_owned(), path.to_path_buf())),
        None => PyOSError::new_err((errno, text.to_owned())),
    })
}

/// `err` with the message's settings still marked in its attribute
/// `_pixelpie_raw`, when it names any: for a front end built on the
/// package to spell them its own way (the vpype plugin's flags, as the
/// command line's).
fn with_raw(err: PyErr, raw: &str) -> PyErr {
    if raw.contains('\u{ab}') {
        Python::attach(|py| {
            let _ = err.value(py).setattr("_pixelpie_raw", raw);
        });
    }
    err
}

/// A library message in Python's words: each setting it names
/// ([`pixelpie::setting`], [`pixelpie::given`]) spelled as a keyword
/// argument ([`spell_python`]).
fn said(text: &str) -> String {
    pixelpie::spelled(text, spell_python)
}

/// A setting as Python names it: the keyword `pen_mm`, and with its value
/// `points=0`, `invert=True`, `paper='a4'`: the value as Python writes the
/// literal (True and False, numbers as they are, text quoted as `repr`
/// quotes it), but for a placeholder (`choose=K`).
fn spell_python(key: &str, value: Option<&str>) -> String {
    let Some(v) = value else {
        return key.to_owned();
    };
    let literal = match v {
        "true" => "True".to_owned(),
        "false" => "False".to_owned(),
        "none" | "null" => "None".to_owned(),
        // A placeholder ("add «choose=K»"), not a value.
        _ if (1..=2).contains(&v.len()) && v.chars().all(|c| c.is_ascii_uppercase()) => {
            v.to_owned()
        }
        _ if v.parse::<f64>().is_ok_and(f64::is_finite)
            && !v.trim().is_empty()
            && v.trim() == v
            && !v.starts_with('+') =>
        {
            v.to_owned()
        }
        _ => python_repr(v),
    };
    format!("{key}={literal}")
}

/// `text` as Python's `repr` of a `str` writes it: in single quotes, or in
/// double quotes when it holds a single quote and no double one.
fn python_repr(text: &str) -> String {
    let quote = if text.contains('\'') && !text.contains('"') {
        '"'
    } else {
        '\''
    };
    let mut out = String::with_capacity(text.len() + 2);
    out.push(quote);
    for c in text.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c == quote => {
                out.push('\\');
                out.push(c);
            }
            c => out.push(c),
        }
    }
    out.push(quote);
    out
}

/// A plan's JSON (`to_json`) in Python's words ([`said`]), its keys'
/// order and layout kept: each mark is spelled inside its JSON string.
fn plan_said(json: &str) -> String {
    pixelpie::spelled(json, |key, value| {
        let text = spell_python(key, value);
        let quoted = serde_json::to_string(&text).unwrap_or_default();
        quoted
            .strip_prefix('"')
            .and_then(|q| q.strip_suffix('"'))
            .unwrap_or(&text)
            .to_owned()
    })
}

fn bad(text: impl Into<String>) -> PyErr {
    PyValueError::new_err(text.into())
}

/// The value of an enum the library names in lower case (its serde and
/// command-line names), such as a policy or a backend.
fn named<T: serde::de::DeserializeOwned>(name: &str, what: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(name.to_owned()))
        .map_err(|e| bad(pixelpie::setting_error(what, &e.to_string())))
}

/// How often the waiting thread checks for signals while the library
/// works.
const POLL: Duration = Duration::from_millis(20);

/// This process's thread pool and the process it was made in.
static POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);

/// The thread pool of this process. A child made by `fork` inherits the
/// parent's pool but none of its threads (work sent there would wait
/// forever): it makes its own, and the parent's is left alone, never
/// dropped (dropping it would signal threads that do not exist here).
fn pool() -> PyResult<Arc<rayon::ThreadPool>> {
    let pid = std::process::id();
    let mut slot = POOL.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some((owner, pool)) = slot.as_ref()
        && *owner == pid
    {
        return Ok(Arc::clone(pool));
    }
    if let Some(inherited) = slot.take() {
        std::mem::forget(inherited);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .thread_name(|i| format!("pixelpie-{i}"))
        .build()
        .map(Arc::new)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start pixelpie's threads: {e}")))?;
    *slot = Some((pid, Arc::clone(&pool)));
    Ok(pool)
}

/// A panic's message.
fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".into());
    format!("pixelpie failed inside ({what}); please report it with the call that made it")
}

/// What the working thread tells the waiting one.
enum Note {
    /// An iteration is done: check for signals now, and answer.
    Iteration(mpsc::Sender<()>),
    /// The work is done.
    Done,
}

/// Runs `work` on a thread of its own in this process's pool ([`pool`]),
/// without the GIL, with a sampler control whose progress calls
/// `progress(iteration, points, empty, pixels)`. The calling thread waits,
/// checking for signals every [`POLL`] and after every sampler iteration
/// (which waits for it): a signal's exception (KeyboardInterrupt from
/// Ctrl-C) or one raised by `progress` cancels the run, which every stage
/// heeds within a few milliseconds, and is raised. A panic becomes
/// `RuntimeError`.
fn cancellable<T: Send>(
    py: Python<'_>,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(Control<'_>) -> pixelpie::Result<T> + Send,
) -> PyResult<T> {
    let pool = pool()?;
    let cancel = AtomicBool::new(false);
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let raise = |e: PyErr| {
        raised
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get_or_insert(e);
        cancel.store(true, Ordering::Relaxed);
    };
    let (notes, heard) = mpsc::channel::<Note>();
    let report = |p: Progress| {
        if let Some(f) = &progress {
            Python::attach(|py| {
                if let Err(e) = f.call1(py, (p.iteration, p.points, p.empty_pixels, p.pixels)) {
                    raise(e);
                }
            });
        }
        // The waiting thread checks for signals before the next iteration.
        let (answer, answered) = mpsc::channel();
        if notes.send(Note::Iteration(answer)).is_ok() {
            let _ = answered.recv();
        }
    };
    let outcome = py.detach(|| {
        let heard = heard;
        std::thread::scope(|s| {
            let (pool, cancel, report, done) = (&pool, &cancel, &report, notes.clone());
            let worker = s.spawn(move || {
                let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    pool.install(|| work(Control::new().with_progress(report).with_cancel(cancel)))
                }));
                let _ = done.send(Note::Done);
                result
            });
            let mut listening = true;
            loop {
                let note = heard.recv_timeout(POLL);
                if let Ok(Note::Done) | Err(mpsc::RecvTimeoutError::Disconnected) = note {
                    break;
                }
                if listening && let Err(e) = Python::attach(|py| py.check_signals()) {
                    raise(e);
                    listening = false;
                }
                if let Ok(Note::Iteration(answer)) = note {
                    let _ = answer.send(());
                }
            }
            worker.join()
        })
    });
    if let Some(e) = raised.into_inner().unwrap_or_else(PoisonError::into_inner) {
        return Err(e);
    }
    match outcome {
        Ok(Ok(result)) => result.map_err(|e| py_err(&e)),
        Ok(Err(payload)) | Err(payload) => Err(PyRuntimeError::new_err(panic_text(&*payload))),
    }
}

/// Runs `work`, which owns its data, on a thread of its own in this
/// process's pool ([`pool`]), without the GIL, as [`cancellable`] does; but
/// a signal's exception is raised at once, without waiting for the work to
/// end. The work is told to stop (its control's cancel) and ends on its own
/// at its next check, its result dropped: a step it cannot stop inside (a
/// Delaunay triangulation of millions of points, a second) does not hold
/// the interrupt back. A panic becomes `RuntimeError`.
fn detached<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce(Control<'_>) -> pixelpie::Result<T> + Send + 'static,
) -> PyResult<T> {
    let pool = pool()?;
    let cancel = Arc::new(AtomicBool::new(false));
    let (done, finished) = mpsc::channel();
    let flag = Arc::clone(&cancel);
    std::thread::Builder::new()
        .name("pixelpie-detached".into())
        .spawn(move || {
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool.install(|| work(Control::new().with_cancel(&flag)))
            }));
            let _ = done.send(result);
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start pixelpie's thread: {e}")))?;
    let outcome = py.detach(move || {
        loop {
            match finished.recv_timeout(POLL) {
                Ok(result) => return Ok(result),
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(PyRuntimeError::new_err(
                        "pixelpie's thread ended without a result",
                    ));
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        cancel.store(true, Ordering::Relaxed);
                        return Err(e);
                    }
                }
            }
        }
    })?;
    match outcome {
        Ok(result) => result.map_err(|e| py_err(&e)),
        Err(payload) => Err(PyRuntimeError::new_err(panic_text(&*payload))),
    }
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
/// `importance_values` (a grey array's values, 0 to 1, taken as they are)
/// or `importance_pixels` (a picture array or PIL image, decoded as a file
/// is: [`encoded_png`]) takes the place of a file. Returns the points, the
/// statistics (with the count `target`) and the warnings.
#[pyfunction]
#[pyo3(signature = (options, radius_map, importance_values, importance_pixels, backend_name, progress, max_memory))]
#[expect(
    clippy::too_many_arguments,
    reason = "the Python function's arguments, one by one"
)]
fn sample<'py>(
    py: Python<'py>,
    options: &str,
    radius_map: Option<PyReadonlyArray2<'py, f32>>,
    importance_values: Option<PyReadonlyArray2<'py, f32>>,
    importance_pixels: Option<PyReadonlyArrayDyn<'py, u16>>,
    backend_name: &str,
    progress: Option<Py<PyAny>>,
    max_memory: Option<u64>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Vec<String>)> {
    let mut job: SampleJob = from_options(options, "sample", &sample_options()?)?;
    let choice: BackendChoice = named(backend_name, "backend")?;
    let given_maps = [
        job.importance.is_some(),
        importance_values.is_some() || importance_pixels.is_some(),
        job.radius_map.is_some() || radius_map.is_some(),
    ];
    if given_maps.iter().filter(|&&g| g).count() > 1 {
        return Err(bad("give a radius map or an importance map, not both"));
    }
    let radii = if let Some(a) = &radius_map {
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
    } else if let Some(a) = &importance_pixels {
        let bytes = encoded_png(a, "importance")?;
        let hdr = job.importance_options.hdr_white;
        Radii::Picture(
            budget::within(max_memory, || {
                ImportanceMap::from_encoded(&bytes, Path::new("<importance>"), hdr)
            })
            .map_err(|e| py_err(&e.into()))?,
        )
    } else {
        let job = &job;
        cancellable(py, None, |_| budget::within(max_memory, || job.radii()))?
    };
    job.check(&radii).map_err(|e| py_err(&e.into()))?;
    let cap = job.max_iterations;
    let target = job.points;
    let done = cancellable(py, progress, move |ctl| {
        budget::within(max_memory, || {
            job.run(&radii, |p| {
                Ok(backend::sample(p, choice, ctl, &mut |_| {})?)
            })
        })
    })?;
    let rows = done.set.points.iter().map(|p| [p.x, p.y, p.radius]);
    let mut stats = serde_json::to_value(done.set.report())
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    if let serde_json::Value::Object(m) = &mut stats {
        m.insert("target".into(), serde_json::json!(target));
    }
    Ok((
        points_array(py, rows)?,
        to_python(py, &stats)?,
        done.warnings(cap).iter().map(|w| said(w)).collect(),
    ))
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
            let wrong_type = text.starts_with("invalid type:");
            let text = match culprit {
                // A bool where a number or a name belongs, in Python's
                // words: "points must be a whole number, at least 0, not
                // True (a bool)".
                Some((name, serde_json::Value::Bool(b))) if wrong_type => {
                    let text = pixelpie::setting_error(name, &text);
                    let word = if *b { "True" } else { "False" };
                    match text.strip_suffix(if *b { ", not true" } else { ", not false" }) {
                        Some(head) => format!("{head}, not {word} (a bool)"),
                        None => text,
                    }
                }
                Some((name, _)) => pixelpie::setting_error(name, &text),
                None => text,
            };
            // Python's words for a bool's values.
            let raw = text;
            let text = said(&raw).replace("must be true or false", "must be True or False");
            let err = if wrong_type {
                PyTypeError::new_err(text)
            } else {
                bad(text)
            };
            Err(with_raw(err, &raw))
        }
    }
}

/// The drawing job of `options` ([`from_options`]), over the job file at
/// `job_file` when given ([`Job::with_overrides`], as the CLI's `--job`
/// takes its options), checked.
fn job_from(options: &str, job_file: Option<&std::path::Path>, function: &str) -> PyResult<Job> {
    let known = job_options().map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let job: Job = from_options(options, function, &known)?;
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
#[pyo3(signature = (image, pixels, options, job_file, max_memory))]
fn plan_py(
    py: Python<'_>,
    image: Option<PathBuf>,
    pixels: Option<PyReadonlyArrayDyn<'_, u16>>,
    options: &str,
    job_file: Option<PathBuf>,
    max_memory: Option<u64>,
) -> PyResult<String> {
    let job = job_from(options, job_file.as_deref(), "plan")?;
    let encoded = pixels
        .as_ref()
        .map(|a| encoded_png(a, "image"))
        .transpose()?;
    // The call's budget holds for the picture and the plan's domain.
    cancellable(py, None, |_| {
        budget::within(max_memory, || {
            let picture = decoded(&job, image.as_deref(), encoded.as_deref())?;
            let (job, _) = job.chosen(picture.picture())?;
            job.plan(picture.picture())?.plan.to_json()
        })
    })
    .map(|json| plan_said(&json))
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
    Ok((json, file.warning.map(|w| said(&w))))
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
            ("choose", serde_json::Value::Null),
            ("paper_colour", serde_json::Value::Null),
            ("size_px", serde_json::to_value(job.size_px)?),
            ("paper", serde_json::Value::Null),
            ("margin", serde_json::Value::Null),
            ("landscape", serde_json::to_value(job.landscape)?),
            ("poster", serde_json::Value::Null),
            ("dot_path", serde_json::to_value(job.dot_path)?),
            ("crop", serde_json::Value::Null),
            ("dot_mm", serde_json::Value::Null),
            ("rotate", serde_json::Value::Null),
            ("refill_mm", serde_json::Value::Null),
            ("layer_order", serde_json::to_value(job.layer_order)?),
            ("spacing", serde_json::to_value(job.spacing)?),
            ("correction", serde_json::to_value(job.correction)?),
            ("relax", serde_json::Value::Null),
            ("style", serde_json::to_value(job.style)?),
            ("line_smooth", serde_json::to_value(job.line_smooth)?),
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
fn encoded_png(a: &PyReadonlyArrayDyn<'_, u16>, what: &str) -> PyResult<Vec<u8>> {
    use image::ImageEncoder;
    let shape = a.shape().to_vec();
    let (h, w, c) = match shape[..] {
        [h, w] => (h, w, 1),
        [h, w, c] if (1..=4).contains(&c) => (h, w, c),
        _ => {
            return Err(bad(format!(
                "{what}: a picture array must be (H, W) or (H, W, 1 to 4 channels), not {shape:?}"
            )));
        }
    };
    let (Ok(w), Ok(h)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(bad(format!(
            "{what}: a picture of shape {shape:?} is too large"
        )));
    };
    if w == 0 || h == 0 {
        return Err(bad(format!(
            "{what}: the picture array of shape {shape:?} is empty"
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
        .map_err(|e| bad(format!("{what}: {e}")))?;
    Ok(out)
}

/// The native `stipple`; see `pixelpie.stipple`. The picture is a file
/// (`image`) or an array (`pixels`). Writes `output` when given (nothing
/// when interrupted), and returns the drawing.
#[pyfunction(name = "stipple")]
#[pyo3(signature = (image, pixels, output, options, job_file, backend_name, progress, max_memory))]
#[expect(
    clippy::too_many_arguments,
    reason = "the Python function's arguments, one by one"
)]
fn stipple_py(
    py: Python<'_>,
    image: Option<PathBuf>,
    pixels: Option<PyReadonlyArrayDyn<'_, u16>>,
    output: Option<PathBuf>,
    options: &str,
    job_file: Option<PathBuf>,
    backend_name: &str,
    progress: Option<Py<PyAny>>,
    max_memory: Option<u64>,
) -> PyResult<Drawing> {
    let job = job_from(options, job_file.as_deref(), "stipple")?;
    let choice: BackendChoice = named(backend_name, "backend")?;
    let format = match &output {
        // A poster's output is a folder of sheets and poster.json.
        Some(out) if job.poster.is_some() => {
            Poster::check_folder(out).map_err(|e| py_err(&e))?;
            None
        }
        Some(out) => {
            let format = Format::from_path(out).map_err(|e| py_err(&e.into()))?;
            job.validate(format).map_err(|e| py_err(&e.into()))?;
            Some(format)
        }
        None => None,
    };
    let encoded = pixels
        .as_ref()
        .map(|a| encoded_png(a, "image"))
        .transpose()?;
    let drawing = cancellable(py, progress, |ctl| {
        let sample = |params: &pixelpie::sampler::Params| {
            Ok(backend::sample(params, choice, ctl, &mut |_| {})?)
        };
        // The call's budget holds for the picture and the drawing's domain.
        let (picture, job, drawing) = budget::within(max_memory, || -> pixelpie::Result<_> {
            let picture = decoded(&job, image.as_deref(), encoded.as_deref())?;
            // The pens of `choose`, chosen for the picture: the job drawn.
            let (job, _) = job.chosen(picture.picture())?;
            let drawing = job.draw(picture.picture(), sample, |_| ctl.check().is_ok())?;
            Ok((picture, job, drawing))
        })?;
        // A poster: the drawing made whole at the poster's size, cut into
        // its sheets; the drawing's own methods see the whole.
        let whole = job.poster_whole(picture.picture())?;
        drop(picture);
        ctl.check()?;
        let (job, poster) = match whole {
            Some(whole) => {
                let poster = job.poster(&whole, &drawing, &mut || ctl.check().is_err())?;
                (whole, Some((job, poster)))
            }
            None => (job, None),
        };
        ctl.check()?;
        // The file's bytes, written by `write_output` once the warnings
        // have been given: a warning turned into an error leaves no file
        // (a poster's folder is written then).
        let pending = match (&output, format) {
            (Some(out), Some(format)) => Some((out.clone(), Some(job.encode(&drawing, format)?))),
            (Some(out), None) => Some((out.clone(), None)),
            _ => None,
        };
        ctl.check()?;
        let mut warnings: Vec<String> = image
            .as_deref()
            .and_then(pixelpie::importance::cut_short)
            .into_iter()
            .collect();
        warnings.extend(job.warnings(&drawing, format)?);
        let warnings = warnings.iter().map(|w| said(w)).collect();
        Ok(Drawing {
            job,
            drawing,
            warnings,
            pending: Mutex::new(pending),
            poster,
        })
    })?;
    Ok(drawing)
}

/// A finished drawing and its job (`pixelpie.Drawing` wraps it): its
/// dots, its plan, its files' bytes and its pen paths.
#[pyclass(frozen, module = "pixelpie._pixelpie")]
struct Drawing {
    job: Job,
    drawing: Stipple,
    warnings: Vec<String>,
    /// The output file `stipple` was given and its bytes (none: a
    /// poster's folder), until `write_output` writes them.
    pending: Mutex<Option<(PathBuf, Option<Vec<u8>>)>>,
    /// A poster's job and sheets (`poster=(w, h)`); `job` is then the
    /// whole drawing's, at the poster's size.
    poster: Option<(Job, Poster)>,
}

impl Drawing {
    /// A drawing of its own for one of a poster's sheets.
    fn of_sheet(sheet: &pixelpie::job::Sheet) -> Self {
        Self {
            job: sheet.job.clone(),
            drawing: sheet.drawing.clone(),
            warnings: Vec::new(),
            pending: Mutex::new(None),
            poster: None,
        }
    }

    /// Writes a poster's folder: its sheets and poster.json.
    fn write_poster(&self, dir: &Path) -> pixelpie::Result<()> {
        match &self.poster {
            Some((job, poster)) => poster.write(job, dir, None),
            None => Ok(()),
        }
    }
}

#[pymethods]
impl Drawing {
    /// The dots as an (N, 3) float32 array of x, y and drawn radius in
    /// domain pixels, in drawing order; in colour (N, 4), the fourth
    /// column each dot's pen (its index in the pens).
    fn dots<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = &self.drawing;
        if d.pens.is_none() {
            return points_array(py, d.dots.iter().map(|d| [d.x, d.y, d.radius]));
        }
        let flat: Vec<f32> = d
            .dots
            .iter()
            .zip(&d.points)
            .flat_map(|(d, p)| [d.x, d.y, d.radius, p.class as f32])
            .collect();
        let n = flat.len() / 4;
        Ok(PyArray1::from_vec(py, flat).reshape([n, 4])?.into_any())
    }

    /// The domain's size in pixels, (width, height).
    #[getter]
    fn domain(&self) -> (u32, u32) {
        self.drawing.domain
    }

    /// The dot count asked for (`None` when the radii set it).
    #[getter]
    fn asked(&self) -> Option<usize> {
        self.drawing.plan.points.or(self.drawing.short_of)
    }

    /// The count reached: the dots drawn, or in a line drawing the points
    /// its line passes through.
    #[getter]
    fn reached(&self) -> usize {
        if self.drawing.strokes.is_empty() {
            self.drawing.dots.len()
        } else {
            self.drawing.strokes.iter().map(|s| s.points.len()).sum()
        }
    }

    /// What the pen draws: "dots" or "line" (the job's `style`).
    #[getter]
    fn style(&self) -> PyResult<String> {
        match serde_json::to_value(self.drawing.plan.style) {
            Ok(serde_json::Value::String(s)) => Ok(s),
            _ => Err(PyRuntimeError::new_err("the drawing's style has no name")),
        }
    }

    /// The strokes of a line drawing, one per pen in drawing order (none
    /// in a drawing of dots): (an (N, 2) float32 array of the points the
    /// pen's centre passes through, in domain pixels, in order; the line's
    /// width in domain pixels; whether it is drawn as smooth curves
    /// through them).
    fn strokes<'py>(&self, py: Python<'py>) -> PyResult<Vec<(Bound<'py, PyAny>, f32, bool)>> {
        self.drawing
            .strokes
            .iter()
            .map(|s| {
                let n = s.points.len();
                let flat: Vec<f32> = s.points.iter().flatten().copied().collect();
                Ok((
                    PyArray1::from_vec(py, flat).reshape([n, 2])?.into_any(),
                    s.width,
                    s.smooth,
                ))
            })
            .collect()
    }

    /// The plan the drawing was made by, as JSON.
    fn plan(&self) -> PyResult<String> {
        self.drawing
            .plan
            .to_json()
            .map(|json| plan_said(&json))
            .map_err(|e| py_err(&e))
    }

    /// The pens of a colour drawing, in their order: (name, "#rrggbb",
    /// width in mm or `None`); `None` for a grey drawing.
    fn pens(&self) -> Option<Vec<(String, String, Option<f64>)>> {
        self.drawing.pens.as_ref().map(|set| {
            set.pens()
                .iter()
                .map(|p| {
                    (
                        p.name.clone(),
                        pixelpie::colour::pens::hex_of(p.colour),
                        p.width_mm,
                    )
                })
                .collect()
        })
    }

    /// Seconds in each stage of the run, in order (prepare, sample, relax,
    /// order, size).
    fn stages(&self) -> Vec<(String, f64)> {
        self.drawing
            .stages
            .iter()
            .map(|(s, t)| (s.to_string(), *t))
            .collect()
    }

    /// The warnings of the run, in Python's words ([`said`]).
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The file the job writes in `format` ("svg", "png", "csv" or
    /// "json"), as bytes.
    fn encode<'py>(&self, py: Python<'py>, format: &str) -> PyResult<Bound<'py, PyBytes>> {
        let format = Format::from_path(Path::new(&format!("drawing.{format}"))).map_err(|_| {
            bad(format!(
                "format must be svg, png, csv or json, not {format:?}"
            ))
        })?;
        let bytes = cancellable(py, None, |_| self.job.encode(&self.drawing, format))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Writes the file `stipple` was asked for (its `output`), atomically;
    /// nothing when there is none or it is written. `stipple` calls it
    /// after its warnings, so that one turned into an error leaves no file.
    fn write_output(&self, py: Python<'_>) -> PyResult<()> {
        let pending = self
            .pending
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        let Some((out, bytes)) = pending else {
            return Ok(());
        };
        cancellable(py, None, |ctl| {
            // The last moment an interrupt leaves no file.
            ctl.check()?;
            match bytes {
                Some(bytes) => {
                    pixelpie::io::write_atomic(&out, |w| Ok(std::io::Write::write_all(w, &bytes)?))?
                }
                None => self.write_poster(&out)?,
            }
            Ok(())
        })
    }

    /// Writes the drawing to `path` as its extension says, atomically; a
    /// poster's to folder `path`: one SVG a sheet and poster.json.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        if self.poster.is_some() {
            return cancellable(py, None, |_| self.write_poster(&path));
        }
        cancellable(py, None, |_| self.job.write(&self.drawing, &path))
    }

    /// A poster's sheets, row by row (the order they are plotted in), each
    /// a drawing of its own on its sheet's page; empty when the drawing is
    /// no poster.
    fn sheets(&self) -> Vec<Drawing> {
        self.poster
            .iter()
            .flat_map(|(_, p)| p.sheets.iter().map(Drawing::of_sheet))
            .collect()
    }

    /// A poster's manifest (poster.json) as JSON, the plot minutes under
    /// the profile `profile` (a profile file's TOML text; `None`: an
    /// AxiDraw's) when a pen is given; `None` when the drawing is no poster.
    fn poster(&self, py: Python<'_>, profile: Option<&str>) -> PyResult<Option<String>> {
        let Some((job, poster)) = &self.poster else {
            return Ok(None);
        };
        let plotter = match profile {
            Some(text) => Plotter::from_toml(text).map_err(|e| bad(e.to_string()))?,
            None => Plotter::default(),
        };
        let manifest = cancellable(py, None, |_| poster.manifest(job, Some(&plotter)))?;
        serde_json::to_string(&manifest)
            .map(Some)
            .map_err(|e| bad(e.to_string()))
    }

    /// Domain pixels to mm on the page, (scale, x offset, y offset), and
    /// the page's size in mm (width, height), when the page has a size in
    /// mm; else `None`.
    #[expect(clippy::type_complexity, reason = "the Python tuple, as it is")]
    fn transform(&self) -> PyResult<Option<((f64, f64, f64), (f64, f64))>> {
        let domain = self.drawing.domain;
        let opts = self.job.svg_options(domain).map_err(|e| py_err(&e))?;
        let page = opts.sheet_mm.or(opts.size_mm);
        let t = self.job.page_transform(domain).map_err(|e| py_err(&e))?;
        Ok(t.zip(page)
            .map(|(t, page)| ((t.scale, t.offset.0, t.offset.1), page)))
    }

    /// The plot's statistics pen by pen, as JSON (`--plot-stats`'s
    /// table), under the plotter profile `profile` (a built-in profile's
    /// name, `axidraw` or `saxi`, or a profile file's TOML text; `None`:
    /// AxiDraw's own planner).
    fn plot_stats(&self, py: Python<'_>, profile: Option<&str>) -> PyResult<String> {
        let plotter = match profile {
            Some(text) => match Plotter::named(text) {
                Some(p) => p,
                None => Plotter::from_toml(text).map_err(|e| bad(e.to_string()))?,
            },
            None => Plotter::default(),
        };
        let plots = cancellable(py, None, |_| self.job.plot_stats(&self.drawing, &plotter))?;
        serde_json::to_string(&plots).map_err(|e| bad(e.to_string()))
    }

    /// The pen paths as the plotter draws them, layer by layer in plotting
    /// order: (name, "#rrggbb", pen width in mm, [one (K, 2) float64 array
    /// of mm per dot, or a line drawing's line (its part, with a refill)]).
    #[expect(clippy::type_complexity, reason = "the Python tuple, as it is")]
    fn paths<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Vec<(String, String, f64, Vec<Bound<'py, PyAny>>)>> {
        let layers = cancellable(py, None, |_| self.job.pen_paths(&self.drawing))?;
        layers
            .into_iter()
            .map(|l| {
                let paths = l
                    .paths
                    .into_iter()
                    .map(|p| {
                        let n = p.len();
                        let flat: Vec<f64> = p.into_iter().flatten().collect();
                        Ok(PyArray1::from_vec(py, flat).reshape([n, 2])?.into_any())
                    })
                    .collect::<PyResult<Vec<_>>>()?;
                Ok((
                    l.name,
                    pixelpie::colour::pens::hex_of(l.ink),
                    l.pen_mm,
                    paths,
                ))
            })
            .collect()
    }
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
    let report = detached(py, move |ctl| {
        let cover = match (radius, &radii) {
            (Some(r), _) => Some(CoverRadius::Uniform(r)),
            (None, Some(r)) => Some(CoverRadius::PerPoint(r)),
            (None, None) => None,
        };
        Ok(pixelpie::analyze::report_with(&xy, domain, cover, ctl)?)
    })?;
    to_python(py, &report)
}

/// A size in bytes from "4G", "512M" or a number of bytes (`max_memory=`).
#[pyfunction]
fn parse_size(text: &str) -> PyResult<u64> {
    budget::parse_size(text).map_err(|e| bad(format!("max_memory: {e}")))
}

/// The native module. NumPy's C API is loaded here, at import: loaded
/// lazily by the first array, an interrupt arriving then would become a
/// panic.
#[pymodule]
fn _pixelpie(m: &Bound<'_, PyModule>) -> PyResult<()> {
    PyArray1::<f32>::zeros(m.py(), 0, false);
    m.add_class::<Drawing>()?;
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(stipple_py, m)?)?;
    m.add_function(wrap_pyfunction!(plan_py, m)?)?;
    m.add_function(wrap_pyfunction!(stipple_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(read_job, m)?)?;
    m.add_function(wrap_pyfunction!(sample_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(analyze_py, m)?)?;
    m.add_function(wrap_pyfunction!(parse_size, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
