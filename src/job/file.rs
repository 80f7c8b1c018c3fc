//! Job files: a drawing's every setting as TOML (`pixelpie stipple
//! --save-job`, the app's presets, Python's `job=`), read back by `--job`.
//! A file names the version that wrote it; a key this version does not know
//! is refused by name, and a file from another version is read with a
//! warning, never with a silent default.

use std::path::Path;

use super::Job;
use crate::stipple::Error;

/// The key that names the version that wrote a job file.
pub const VERSION_KEY: &str = "pixelpie";

/// Every setting's key in a job file: [`Job`]'s fields under their option
/// names (the CLI's `--flag` with `_` for `-`). A test holds it to the
/// CLI's arguments.
pub const KEYS: &[&str] = &[
    "points",
    "width",
    "height",
    "crop",
    "rotate",
    "tones",
    "mapping",
    "min_radius",
    "max_radius",
    "gamma",
    "black_level",
    "white_level",
    "invert",
    "white_cutoff",
    "hdr_white",
    "dot",
    "dot_factor",
    "dot_ratio",
    "dot_radius",
    "dot_mm",
    "relax",
    "order",
    "style",
    "line_smooth",
    "scale",
    "width_mm",
    "paper",
    "margin",
    "landscape",
    "poster",
    "size_px",
    "pen_mm",
    "dot_path",
    "refill_mm",
    "layer_order",
    "spacing",
    "correction",
    "ink",
    "pens",
    "choose",
    "paper_colour",
    "policy",
    "seed",
    "subpixel_bits",
    "periodic",
    "exact",
];

/// Pairs of settings that exclude each other: given over a job file, one
/// drops the other from it ([`Job::with_overrides`]).
pub const EXCLUSIVE: [(&str, &str); 2] = [("paper", "width_mm"), ("pens", "ink")];

/// A job file read back: the job, and what the reader should be told.
#[derive(Debug)]
pub struct JobFile {
    /// The settings (the version's defaults where the file is silent).
    pub table: toml::Table,
    /// A warning to print, when the file comes from another version.
    pub warning: Option<String>,
}

impl Job {
    /// The job as a job file's text: the version, then every setting
    /// ([`KEYS`] that have a value). `source` names the picture in a
    /// comment.
    pub fn to_toml(&self, source: Option<&Path>) -> crate::Result<String> {
        let table = self.to_table()?;
        let mut text =
            String::from("# A PixelPie drawing job: pixelpie stipple IMAGE --job THIS.toml\n");
        if let Some(path) = source {
            text.push_str(&format!("# drawn from {}\n", path.display()));
        }
        text.push_str(&format!(
            "{VERSION_KEY} = \"{}\"\n",
            env!("CARGO_PKG_VERSION")
        ));
        let body = toml::to_string(&table).map_err(|e| bad(format!("job file: {e}")))?;
        text.push_str(&body);
        Ok(text)
    }

    /// The job's settings as a TOML table (the keys of [`KEYS`] that have
    /// a value).
    pub fn to_table(&self) -> crate::Result<toml::Table> {
        let mut table = toml::Table::try_from(self).map_err(|e| bad(format!("job file: {e}")))?;
        for (_, value) in table.iter_mut() {
            tidy(value);
        }
        Ok(table)
    }

    /// The job of a table of settings ([`KEYS`]), every other setting at
    /// its default, checked.
    pub fn from_table(table: toml::Table) -> crate::Result<Self> {
        let job: Self = toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| Error::Setting(setting_problem(&table, &e)))?;
        job.check()?;
        Ok(job)
    }

    /// The job of a job file's `table` with `given`'s settings of `keys`
    /// over it (the settings a user gave besides the file: the CLI's
    /// options on its command line, Python's keywords, a row the app
    /// changed). A key one of a pair that exclude each other ([`EXCLUSIVE`])
    /// drops the other from the file; a key `given` leaves unset unsets it.
    /// Checked whole. Every front end overrides a job file through it.
    pub fn with_overrides<'k>(
        table: toml::Table,
        given: &Self,
        keys: impl IntoIterator<Item = &'k str>,
    ) -> crate::Result<Self> {
        let mut table = table;
        let values = given.to_table()?;
        for key in keys {
            if !KEYS.contains(&key) {
                return Err(bad(format!("'{key}' is not a setting of a job")).into());
            }
            for (one, other) in EXCLUSIVE {
                if key == one {
                    table.remove(other);
                } else if key == other {
                    table.remove(one);
                }
            }
            match values.get(key) {
                Some(v) => table.insert(key.to_string(), v.clone()),
                None => table.remove(key),
            };
        }
        Self::from_table(table)
    }

    /// Reads the job file at `path` ([`JobFile::read`]) as a job.
    pub fn open(path: &Path) -> crate::Result<(Self, Option<String>)> {
        let file = JobFile::read(path)?;
        Ok((Self::from_table(file.table)?, file.warning))
    }
}

impl JobFile {
    /// Reads a job file: its settings, refusing a key that is not one
    /// ([`KEYS`]) by name, and a warning when another version wrote it.
    pub fn read(path: &Path) -> crate::Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Setting(format!("{}: cannot read it: {e}", path.display())))?;
        Self::parse(&text).map_err(|e| Error::Setting(format!("{}: {e}", path.display())).into())
    }

    /// [`Self::read`] of a file's text.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| format!("not a job file: {}", e.message().trim()))?;
        let ours = env!("CARGO_PKG_VERSION");
        let warning = match table.remove(VERSION_KEY) {
            Some(toml::Value::String(v)) if v == ours => None,
            Some(toml::Value::String(v)) => Some(format!(
                "the job file was written by pixelpie {v}; this is {ours}, whose defaults \
                 fill any setting it lacks"
            )),
            _ => {
                return Err(format!(
                    "not a job file: it has no `{VERSION_KEY} = \"<version>\"` line (write one \
                     with «save_job»)"
                ));
            }
        };
        let unknown: Vec<&str> = table
            .keys()
            .map(String::as_str)
            .filter(|k| !KEYS.contains(k))
            .collect();
        if !unknown.is_empty() {
            let hint = unknown
                .iter()
                .find_map(|k| nearest(k).map(|n| format!(" (did you mean `{n}`?)")))
                .unwrap_or_default();
            return Err(format!(
                "unknown setting{} {}{hint}",
                if unknown.len() == 1 { "" } else { "s" },
                unknown
                    .iter()
                    .map(|k| format!("`{k}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        Ok(Self { table, warning })
    }
}

/// A setting held as `f32` written as its shortest decimal (0.3, not
/// 0.30000001192092896): read back as `f32`, the same value.
fn tidy(value: &mut toml::Value) {
    if let toml::Value::Float(f) = value {
        let single = *f as f32;
        if f64::from(single) == *f
            && let Ok(short) = single.to_string().parse::<f64>()
        {
            *f = short;
        }
    }
}

/// The known key nearest to `key` by edit distance, when it is near.
fn nearest(key: &str) -> Option<&'static str> {
    let normal = key.replace('-', "_");
    KEYS.iter()
        .map(|k| (distance(&normal, k), *k))
        .filter(|&(d, _)| d <= 2)
        .min()
        .map(|(_, k)| k)
}

/// Levenshtein distance.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

fn bad(message: String) -> Error {
    Error::InvalidParameter(message)
}

/// What is wrong with a job file's `table`, which the job's form refused
/// with `error`: the first key that fails on its own, as "key = value:
/// what is accepted" ([`describe`]); serde's message when none does alone.
fn setting_problem(table: &toml::Table, error: &toml::de::Error) -> String {
    let alone = |key: &str, value: toml::Value| {
        let one = toml::Table::from_iter([(key.to_owned(), value)]);
        toml::Value::Table(one).try_into::<Job>().err()
    };
    table
        .iter()
        .find_map(|(key, value)| {
            let e = alone(key, value.clone())?;
            // The choices of a key that takes names, when it has them.
            let probe = alone(key, toml::Value::String("\u{1}".into()));
            let choices = probe.and_then(|p| crate::text::choices(p.message()));
            Some(describe(key, value, e.message(), choices))
        })
        .unwrap_or_else(|| format!("job file: {}", error.message().trim()))
}

/// "key = value: expected …" of serde's `message` about `value` (the
/// names accepted when `choices` has them).
fn describe(key: &str, value: &toml::Value, message: &str, choices: Option<Vec<String>>) -> String {
    let given = crate::text::single_line(&value.to_string());
    let wanted = match (choices, crate::text::expected(message)) {
        (Some(names), _) => format!("expected one of {}", names.join(", ")),
        (None, Some(expected)) => format!("expected {expected}"),
        (None, None) => crate::text::single_line(message.trim()),
    };
    format!("{key} = {given}: {wanted}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_job_survives_its_file() {
        let mut job = Job {
            points: Some(12_345),
            relax: Some(3),
            dot_ratio: 0.3,
            pens: Some("cmyk".parse().unwrap()),
            paper: Some("a4".parse().unwrap()),
            pen_mm: Some(0.3),
            ..Job::default()
        };
        job.importance.gamma = 1.1;
        job.sampler.seed = 7;
        let text = job.to_toml(None).unwrap();
        assert!(
            text.contains("dot_ratio = 0.3\n") && text.contains("gamma = 1.1\n"),
            "{text}"
        );
        let file = JobFile::parse(&text).unwrap();
        assert!(file.warning.is_none());
        assert_eq!(Job::from_table(file.table).unwrap(), job);
        // Written again, the same bytes.
        let again = Job::from_table(JobFile::parse(&text).unwrap().table).unwrap();
        assert_eq!(again.to_toml(None).unwrap(), text);
    }

    #[test]
    fn every_key_written_is_known() {
        let job = Job {
            points: Some(1),
            pens: Some("cmyk".parse().unwrap()),
            paper: Some("a4".parse().unwrap()),
            margin: Some(5.0),
            landscape: true,
            ..Job::default()
        };
        for key in job.to_table().unwrap().keys() {
            assert!(KEYS.contains(&key.as_str()), "{key} is not in KEYS");
        }
    }

    #[test]
    fn unknown_keys_and_other_versions_are_said() {
        let e = JobFile::parse("pixelpie = \"0.1.0\"\npoints = 5\nrelaxx = 3\n").unwrap_err();
        assert!(
            e.contains("`relaxx`") && e.contains("did you mean `relax`"),
            "{e}"
        );
        let e = JobFile::parse("points = 5\n").unwrap_err();
        assert!(e.contains("no `pixelpie"), "{e}");
        let old = JobFile::parse("pixelpie = \"0.0.1\"\npoints = 5\n").unwrap();
        assert!(old.warning.unwrap().contains("0.0.1"));
        let e = JobFile::parse("pixelpie = \"0.1.0\"\npoints = \"many\"\n")
            .map(|f| Job::from_table(f.table));
        assert!(matches!(e, Ok(Err(_))));
    }
}
