//! Text for people: error text on one line, for front ends and for the
//! modules' own error messages, and counts with their thousands apart. A
//! leaf: it imports nothing of the crate.

/// `e`'s message followed by its sources, `: `-separated: the one line the
/// CLI prints (as anyhow's `{:#}`), for front ends without anyhow.
#[must_use]
pub fn one_line(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    single_line(&text)
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
