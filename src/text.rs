//! Text for people: error text on one line, for front ends and for the
//! modules' own error messages, and counts with their thousands apart. A
//! leaf: it imports nothing of the crate.

/// `e`'s message followed by its sources, `: `-separated, on one line, its
/// settings spelled as a job file and a Rust caller name them
/// ([`spell_rust`]). A front end spells them its own way: [`spelled`].
#[must_use]
pub fn one_line(e: &dyn std::error::Error) -> String {
    spelled(&raw_line(e), spell_rust)
}

/// `e`'s one line with its settings left marked ([`setting`], [`given`]),
/// for a front end to [`spelled`] them.
#[must_use]
pub fn raw_line(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    single_line(&text)
}

/// Opens a setting named in a message ([`setting`], [`given`]).
pub const SETTING_OPEN: char = '\u{ab}';
/// Closes a setting named in a message.
pub const SETTING_CLOSE: char = '\u{bb}';

/// A setting named in a message or a warning, by its job-file key
/// ([`crate::job::file::KEYS`]: `pen_mm`), for each front end to spell in
/// its own words ([`spelled`]): the CLI's `--pen-mm`, Python's `pen_mm`,
/// the app's control label.
#[must_use]
pub fn setting(key: &str) -> String {
    format!("{SETTING_OPEN}{key}{SETTING_CLOSE}")
}

/// A setting with the value given ([`setting`]): the CLI spells it
/// `--points 0`, Python `points=0`, the app `Points 0`.
#[must_use]
pub fn given(key: &str, value: impl std::fmt::Display) -> String {
    format!("{SETTING_OPEN}{key}={value}{SETTING_CLOSE}")
}

/// `text` with each marked setting ([`setting`], [`given`]) spelled by
/// `name(key, value)`. Unmarked text comes back as it is.
#[must_use]
pub fn spelled(text: &str, name: impl Fn(&str, Option<&str>) -> String) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find(SETTING_OPEN) {
        let after = &rest[start + SETTING_OPEN.len_utf8()..];
        let Some(end) = after.find(SETTING_CLOSE) else {
            break;
        };
        out.push_str(&rest[..start]);
        let mark = &after[..end];
        out.push_str(&match mark.split_once('=') {
            Some((key, value)) => name(key, Some(value)),
            None => name(mark, None),
        });
        rest = &after[end + SETTING_CLOSE.len_utf8()..];
    }
    out.push_str(rest);
    out
}

/// A setting as a job file and the Rust API name it: `pen_mm`, `points = 0`.
#[must_use]
pub fn spell_rust(key: &str, value: Option<&str>) -> String {
    match value {
        Some(v) => format!("{key} = {v}"),
        None => key.to_owned(),
    }
}

/// A setting as the command line names it: `--pen-mm`, `--points 0`, and a
/// switch given (`true`) as the bare flag.
#[must_use]
pub fn spell_cli(key: &str, value: Option<&str>) -> String {
    let flag = format!("--{}", key.replace('_', "-"));
    match value {
        Some("true") | None => flag,
        Some(v) => format!("{flag} {v}"),
    }
}

/// `text` on one line: each run of whitespace, line breaks included, becomes
/// one space (wgpu's and some decoders' messages span lines).
#[must_use]
pub fn single_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A count with its thousands apart: 20 012.
#[must_use]
pub fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// serde's "invalid type: FOUND, expected EXPECTED" (or "invalid value")
/// for the setting `name`, in a user's words: "relax must be a whole
/// number, at least 0, not the text \"tsp\"". Other messages come back as
/// they are, after `name: `.
#[must_use]
pub fn setting_error(name: &str, message: &str) -> String {
    let message = message.trim();
    if let Some(rest) = message.strip_prefix("unknown variant `")
        && let Some((given, _)) = rest.split_once("`, expected ")
        && let Some(names) = choices(message)
    {
        return format!(
            "{name} must be one of {}, not \"{given}\"",
            names.join(", ")
        );
    }
    let (Some(found), Some(expected)) = (found(message), expected(message)) else {
        return if message.starts_with(&format!("{name}:")) {
            message.to_owned()
        } else {
            format!("{name}: {message}")
        };
    };
    format!("{name} must be {expected}, not {found}")
}

/// The names serde's "unknown variant `x`, expected `a` or `b`" (or "one
/// of `a`, `b`, …") accepts.
#[must_use]
pub fn choices(message: &str) -> Option<Vec<String>> {
    let rest = message.trim().strip_prefix("unknown variant `")?;
    let (_, expected) = rest.split_once("`, expected ")?;
    let expected = expected.split(" at line ").next().unwrap_or(expected);
    let names: Vec<String> = expected
        .trim_start_matches("one of ")
        .split([',', ' '])
        .filter(|w| w.starts_with('`'))
        .map(|w| w.trim_matches('`').to_owned())
        .collect();
    (!names.is_empty()).then_some(names)
}

/// What serde's "invalid type: …, expected X" (or "invalid value") says
/// is accepted, in a user's words.
#[must_use]
pub fn expected(message: &str) -> Option<String> {
    let (_, expected) = type_parts(message)?;
    Some(
        match expected {
            "u8" | "u16" | "u32" | "u64" | "usize" => "a whole number, at least 0",
            "i8" | "i16" | "i32" | "i64" | "isize" | "integer" => "a whole number",
            "f32" | "f64" => "a number",
            "a boolean" | "bool" => "true or false",
            "a string" | "a borrowed string" | "char" => "text",
            "a sequence" => "a list",
            "string or map" | "string only" => "text: one of its names",
            other => other,
        }
        .to_owned(),
    )
}

/// What serde's "invalid type: FOUND, expected …" says was given, in a
/// user's words.
fn found(message: &str) -> Option<String> {
    let (found, _) = type_parts(message)?;
    let tick = |s: &str| s.trim_matches('`').to_owned();
    Some(if let Some(v) = found.strip_prefix("string ") {
        format!("the text {v}")
    } else if let Some(v) = found
        .strip_prefix("floating point ")
        .or_else(|| found.strip_prefix("integer "))
        .or_else(|| found.strip_prefix("boolean "))
    {
        tick(v)
    } else {
        match found {
            "unit value" | "unit variant" | "null" => "nothing".into(),
            "sequence" => "a list".into(),
            "map" => "a table".into(),
            other => other.into(),
        }
    })
}

/// serde's "invalid type: FOUND, expected EXPECTED" (or "invalid value"),
/// split; serde's " at line L column C" left out.
fn type_parts(message: &str) -> Option<(&str, &str)> {
    let message = message.trim();
    let (found, expected) = ["invalid type: ", "invalid value: "]
        .iter()
        .find_map(|p| message.strip_prefix(p))?
        .split_once(", expected ")?;
    let expected = expected
        .split(" at line ")
        .next()
        .unwrap_or(expected)
        .trim_end_matches('.');
    Some((found, expected))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_front_end_spells_a_setting() {
        let text = format!(
            "{} needs {} or {}; {}",
            given("pen_mm", 0),
            setting("width_mm"),
            setting("paper"),
            given("invert", true)
        );
        assert_eq!(
            spelled(&text, spell_cli),
            "--pen-mm 0 needs --width-mm or --paper; --invert"
        );
        assert_eq!(
            spelled(&text, spell_rust),
            "pen_mm = 0 needs width_mm or paper; invert = true"
        );
        assert_eq!(spelled("no marks «open", spell_cli), "no marks «open");
    }

    #[test]
    fn serde_speaks_as_a_user() {
        assert_eq!(
            setting_error("relax", r#"invalid type: string "tsp", expected u32"#),
            r#"relax must be a whole number, at least 0, not the text "tsp""#
        );
        assert_eq!(
            setting_error("gamma", "invalid type: boolean `true`, expected f32"),
            "gamma must be a number, not true"
        );
        assert_eq!(
            setting_error("points", "invalid value: integer `-3`, expected usize"),
            "points must be a whole number, at least 0, not -3"
        );
        assert_eq!(
            setting_error("order", "unknown variant `x`, expected `none` or `tsp`"),
            r#"order must be one of none, tsp, not "x""#
        );
        assert_eq!(
            setting_error(
                "dot",
                "unknown variant `big`, expected one of `sized`, `fixed`"
            ),
            r#"dot must be one of sized, fixed, not "big""#
        );
        assert_eq!(
            setting_error("gamma", "gamma: must be positive"),
            "gamma: must be positive"
        );
    }
}
