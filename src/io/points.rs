//! Point-set writers: CSV (`x,y,radius`, shortest round-trip decimals) and
//! JSON (the parameters and the points).

use std::io::Write;
use std::path::Path;

use super::{BoxError, Error, Result};
use serde::Serialize;

use crate::sampler::SampleSet;

/// A point-set format, picked by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointFormat {
    /// `x,y,radius` rows.
    Csv,
    /// `{"parameters": …, "points": [{x, y, radius}, …]}`.
    Json,
}

impl PointFormat {
    /// The format of `path`'s extension.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("csv") => Ok(Self::Csv),
            Some("json") => Ok(Self::Json),
            _ => Err(Error::Invalid(format!(
                "unknown output extension of '{}': use .csv or .json",
                path.display()
            ))),
        }
    }
}

/// Writes the points of `set` to `path` atomically; `parameters` goes into
/// the JSON form.
pub fn write_points(path: &Path, set: &SampleSet, parameters: &impl Serialize) -> Result<()> {
    write_points_with(path, set, parameters, None)
}

/// [`write_points`] for a colour drawing: each point's class is its pen.
/// CSV gets a `pen` column (the pen's index), JSON a `pens` list (name
/// and colour) and a `pen` per point.
pub fn write_points_pens(
    path: &Path,
    set: &SampleSet,
    parameters: &impl Serialize,
    pens: &crate::colour::PenSet,
) -> Result<()> {
    write_points_with(path, set, parameters, Some(pens))
}

/// The one writer of point files: CSV or JSON, with the pens when given.
fn write_points_with(
    path: &Path,
    set: &SampleSet,
    parameters: &impl Serialize,
    pens: Option<&crate::colour::PenSet>,
) -> Result<()> {
    let format = PointFormat::from_path(path)?;
    super::write_atomic(path, |w| points_to(w, format, set, parameters, pens))
}

/// The points of `set` in `format` to `w` (what [`write_points`] and
/// [`write_points_pens`] write into their file): `parameters` go into the
/// JSON form, and with `pens` each point's pen.
pub fn points_to(
    w: &mut dyn Write,
    format: PointFormat,
    set: &SampleSet,
    parameters: &impl Serialize,
    pens: Option<&crate::colour::PenSet>,
) -> Result<(), BoxError> {
    match (format, pens) {
        (PointFormat::Csv, _) => write_csv(w, set, pens.is_some()),
        (PointFormat::Json, None) => write_json(w, set, parameters, None, &set.points),
        (PointFormat::Json, Some(pens)) => {
            #[derive(Serialize)]
            struct PenPoint {
                x: f32,
                y: f32,
                radius: f32,
                pen: u32,
            }
            let points: Vec<PenPoint> = set
                .points
                .iter()
                .map(|p| PenPoint {
                    x: p.x,
                    y: p.y,
                    radius: p.radius,
                    pen: p.class,
                })
                .collect();
            write_json(w, set, parameters, Some(pens), &points)
        }
    }
}

/// The points as CSV: x, y, radius, and with `pens` each point's pen.
fn write_csv(w: &mut dyn Write, set: &SampleSet, pens: bool) -> Result<(), BoxError> {
    writeln!(w, "x,y,radius{}", if pens { ",pen" } else { "" })?;
    for p in &set.points {
        // `f32`'s Display prints the shortest decimal that reads back exactly.
        if pens {
            writeln!(w, "{},{},{},{}", p.x, p.y, p.radius, p.class)?;
        } else {
            writeln!(w, "{},{},{}", p.x, p.y, p.radius)?;
        }
    }
    Ok(())
}

/// The points as one JSON document: the parameters, the domain, whether
/// the set is maximal, the sampler's iterations, the pens and `points`.
fn write_json(
    w: &mut dyn Write,
    set: &SampleSet,
    parameters: &impl Serialize,
    pens: Option<&crate::colour::PenSet>,
    points: &impl Serialize,
) -> Result<(), BoxError> {
    #[derive(Serialize)]
    struct Doc<'a, P, Q> {
        parameters: &'a P,
        width: u32,
        height: u32,
        maximal: bool,
        iterations: u32,
        #[serde(skip_serializing_if = "Option::is_none")]
        pens: Option<&'a crate::colour::PenSet>,
        points: &'a Q,
    }
    serde_json::to_writer(
        &mut *w,
        &Doc {
            parameters,
            width: set.width,
            height: set.height,
            maximal: set.maximal(),
            iterations: set.iterations(),
            pens,
            points,
        },
    )?;
    writeln!(w)?;
    Ok(())
}
