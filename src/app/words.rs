//! The app's words for the library's messages: a setting that an error or a
//! warning names ([`crate::setting`], [`crate::given`]) is spelled as the
//! control that sets it is labelled ("Pen mm", "Points 0"), never as a
//! command-line flag or a job file's key.

/// The label of the control that sets the job's `key` (a job file's key,
/// the `Job` field's name), or the words for a setting the app has no
/// control of.
#[must_use]
pub fn label(key: &str) -> &str {
    match key {
        "points" => "Points",
        "width" => "Domain width",
        "height" => "Domain height",
        "crop" => "Crop",
        "rotate" => "Turn",
        "tones" => "Tones",
        "mapping" => "Mapping",
        "min_radius" => "Radius min",
        "max_radius" => "Radius max",
        "gamma" => "Gamma",
        "black_level" => "Black level",
        "white_level" => "White level",
        "invert" => "Invert",
        "white_cutoff" => "White cutoff",
        "hdr_white" => "HDR white",
        "dot" => "Dots",
        "dot_factor" => "Dot size",
        "dot_ratio" => "Lightest / darkest dot",
        "dot_radius" => "Dot radius",
        "dot_mm" => "Dot mm",
        "relax" => "Relax (Lloyd steps)",
        "order" => "Order",
        "style" => "Style",
        "line_smooth" => "Smooth line",
        "scale" => "PNG ×",
        "width_mm" => "Width mm",
        "paper" => "Paper",
        "margin" => "Margin",
        "landscape" => "Landscape",
        "poster" => "Poster",
        "size_px" => "SVG size in px",
        "pen_mm" => "Pen mm",
        "dot_path" => "Dot path",
        "refill_mm" => "Refill mm",
        "layer_order" => "Layer order",
        "spacing" => "Size for local spacing",
        "correction" => "Correct tones by rendering",
        "ink" => "Dot colour",
        "pens" => "Pens",
        "choose" => "Choose",
        "paper_colour" => "Paper colour",
        "policy" => "Policy",
        "seed" => "Seed",
        "subpixel_bits" => "Sub-pixel bits",
        "periodic" => "Periodic (tileable)",
        "exact" => "Exact spacing",
        other => other,
    }
}

/// A setting named in a message, as the app spells it: the control's label
/// ([`label`]), with the value given after it ("Points 0", "PNG ×0.1",
/// "Turn 45°"); a switch given as on is its label alone.
#[must_use]
pub fn spell_app(key: &str, value: Option<&str>) -> String {
    let name = label(key);
    match (key, value) {
        (_, None | Some("true")) => name.to_owned(),
        ("scale", Some(v)) => format!("{name}{v}"),
        ("rotate", Some(v)) => format!("{name} {v}°"),
        (_, Some(v)) => format!("{name} {v}"),
    }
}

/// A library message (an error's text, a warning, a plan's line) in the
/// app's words ([`spell_app`]).
#[must_use]
pub fn app_text(text: &str) -> String {
    crate::spelled(text, spell_app)
}

/// An error on one line, its sources after it, in the app's words.
#[must_use]
pub fn app_line(e: &dyn std::error::Error) -> String {
    app_text(&crate::raw_line(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_are_named_by_their_controls() {
        let text = format!(
            "{} must be at least 1; {} needs {} or {}; at {}",
            crate::given("points", 0),
            crate::setting("pen_mm"),
            crate::setting("width_mm"),
            crate::setting("paper"),
            crate::given("scale", 0.1)
        );
        assert_eq!(
            app_text(&text),
            "Points 0 must be at least 1; Pen mm needs Width mm or Paper; at PNG ×0.1"
        );
        // Every job file key has words of its own, none a flag.
        for key in crate::job::file::KEYS {
            let words = spell_app(key, Some("1"));
            assert!(
                !words.contains("--") && !words.contains('_'),
                "{key}: {words}"
            );
        }
    }
}
