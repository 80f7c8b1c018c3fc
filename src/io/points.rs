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
    let format = PointFormat::from_path(path)?;
    super::write_atomic(path, |w| match format {
        PointFormat::Csv => write_csv(w, set),
        PointFormat::Json => write_json(w, set, parameters),
    })
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
    let format = PointFormat::from_path(path)?;
    super::write_atomic(path, |w| match format {
        PointFormat::Csv => {
            writeln!(w, "x,y,radius,pen")?;
            for p in &set.points {
                writeln!(w, "{},{},{},{}", p.x, p.y, p.radius, p.class)?;
            }
            Ok(())
        }
        PointFormat::Json => {
            #[derive(Serialize)]
            struct PenPoint {
                x: f32,
                y: f32,
                radius: f32,
                pen: u32,
            }
            #[derive(Serialize)]
            struct Doc<'a, P> {
                parameters: &'a P,
                width: u32,
                height: u32,
                maximal: bool,
                iterations: u32,
                pens: &'a crate::colour::PenSet,
                points: Vec<PenPoint>,
            }
            let points = set
                .points
                .iter()
                .map(|p| PenPoint {
                    x: p.x,
                    y: p.y,
                    radius: p.radius,
                    pen: p.class,
                })
                .collect();
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
    })
}

fn write_csv(w: &mut dyn Write, set: &SampleSet) -> Result<(), BoxError> {
    writeln!(w, "x,y,radius")?;
    for p in &set.points {
        // `f32`'s Display prints the shortest decimal that reads back exactly.
        writeln!(w, "{},{},{}", p.x, p.y, p.radius)?;
    }
    Ok(())
}

fn write_json(
    w: &mut dyn Write,
    set: &SampleSet,
    parameters: &impl Serialize,
) -> Result<(), BoxError> {
    #[derive(Serialize)]
    struct Doc<'a, P> {
        parameters: &'a P,
        width: u32,
        height: u32,
        maximal: bool,
        iterations: u32,
        points: &'a [crate::sampler::Point],
    }
    serde_json::to_writer(
        &mut *w,
        &Doc {
            parameters,
            width: set.width,
            height: set.height,
            maximal: set.maximal(),
            iterations: set.iterations(),
            points: &set.points,
        },
    )?;
    writeln!(w)?;
    Ok(())
}
