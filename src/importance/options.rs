//! The options that turn an image into a radius map, shared by `sample
//! --importance`, `stipple`, the Python package and library users. With the
//! `cli` feature they are also the command line's arguments.

use std::path::Path;

use serde::Serialize;

use super::{Adjust, Error, ImportanceMap, Mapping, Prepared, RadiusRange, Result, Tones};

/// r_max / r_min when only one end (or neither) is given.
pub const DEFAULT_RADIUS_RATIO: f32 = 8.0;

/// How importance becomes radius, by name (the sized-dot mapping follows
/// from the dot mode instead).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum MappingKind {
    /// r = r_min + (r_max − r_min)·v (paper §3.4).
    #[default]
    Linear,
    /// Calibrated: the stipple's ink equals the darkness (reproduces tones),
    /// for the dots drawn (sized dots keep their sizes).
    Tone,
}

impl From<MappingKind> for Mapping {
    fn from(m: MappingKind) -> Self {
        match m {
            MappingKind::Linear => Self::Linear,
            MappingKind::Tone => Self::Tone,
        }
    }
}

/// Options that turn an image into a radius map.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default)]
#[non_exhaustive]
pub struct ImportanceOptions {
    /// The grey the drawing reproduces (levels and gamma apply to it).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Tones::Display, requires = "importance"))]
    pub tones: Tones,
    /// Importance-to-radius mapping [default: tone for stipple, linear for sample].
    #[cfg_attr(feature = "cli", arg(long, value_enum, requires = "importance"))]
    pub mapping: Option<MappingKind>,
    /// Radius in px of black (most important) pixels; scaled with --points.
    #[cfg_attr(feature = "cli", arg(long, requires = "importance"))]
    pub min_radius: Option<f32>,
    /// Radius in px of white pixels [default: 8 × the minimum].
    #[cfg_attr(feature = "cli", arg(long, requires = "importance"))]
    pub max_radius: Option<f32>,
    /// Gamma applied after the levels: above 1 darkens mid-tones.
    #[cfg_attr(
        feature = "cli",
        arg(long, default_value_t = 1.0, requires = "importance")
    )]
    pub gamma: f32,
    /// Black level: values at or below it count as black (0..1).
    #[cfg_attr(
        feature = "cli",
        arg(long, default_value_t = 0.0, requires = "importance")
    )]
    pub black_level: f32,
    /// White level: values at or above it count as white (0..1).
    #[cfg_attr(
        feature = "cli",
        arg(long, default_value_t = 1.0, requires = "importance")
    )]
    pub white_level: f32,
    /// Invert the image: light parts become the important ones.
    #[cfg_attr(feature = "cli", arg(long, requires = "importance"))]
    pub invert: bool,
    /// Drop dots whose (adjusted) importance is above this level (0..1).
    #[cfg_attr(feature = "cli", arg(long, requires = "importance"))]
    pub white_cutoff: Option<f32>,
    /// White point of float images (EXR, float TIFF) [default: their 99.5th percentile].
    #[cfg_attr(feature = "cli", arg(long, requires = "importance"))]
    pub hdr_white: Option<f32>,
}

impl Default for ImportanceOptions {
    fn default() -> Self {
        Self {
            tones: Tones::Display,
            mapping: None,
            min_radius: None,
            max_radius: None,
            gamma: 1.0,
            black_level: 0.0,
            white_level: 1.0,
            invert: false,
            white_cutoff: None,
            hdr_white: None,
        }
    }
}

impl ImportanceOptions {
    /// Loads `path`, applies the adjustments and reads it at `size` (given
    /// the image's own size: resized when smaller, read bilinearly when
    /// larger, [`Self::prepare_map_on`]). `radii_scaled`: a point count will scale
    /// the radii, so a missing radius range may default.
    pub fn prepare(
        &self,
        path: &Path,
        size: impl FnOnce(u32, u32) -> (u32, u32),
        default_mapping: Mapping,
        radii_scaled: bool,
    ) -> Result<Prepared> {
        self.prepare_map(
            &ImportanceMap::open(path, self.hdr_white)?,
            size,
            default_mapping,
            radii_scaled,
        )
    }

    /// The radius range at scale 1: the given ends, the other at
    /// [`DEFAULT_RADIUS_RATIO`] from it; with a count target (a point count
    /// will scale the radii) a missing range defaults to 1..8 px.
    pub fn radius_range(&self, radii_scaled: bool) -> Result<RadiusRange> {
        let ratio = DEFAULT_RADIUS_RATIO;
        match (self.min_radius, self.max_radius) {
            (Some(lo), Some(hi)) => RadiusRange::new(lo, hi),
            (Some(lo), None) => RadiusRange::new(lo, lo * ratio),
            (None, Some(hi)) if radii_scaled => RadiusRange::new(hi / ratio, hi),
            (None, _) if radii_scaled => RadiusRange::new(1.0, ratio),
            (None, _) => Err(Error::InvalidParameter(
                "give «points» or «min_radius» with an importance map".into(),
            )),
        }
    }

    /// Checks the radii, the tone adjustments and the white cutoff, which
    /// grey and colour pictures and the point-set job share.
    pub fn check(&self) -> Result<()> {
        self.adjust().validate()?;
        let bad = |m: String| Err(Error::InvalidParameter(m));
        for (key, r) in [
            ("min_radius", self.min_radius),
            ("max_radius", self.max_radius),
        ] {
            if let Some(r) = r
                && !(r.is_finite() && r > 0.0)
            {
                return bad(format!(
                    "{} must be a positive number of px",
                    crate::text::given(key, r)
                ));
            }
        }
        if let (Some(lo), Some(hi)) = (self.min_radius, self.max_radius)
            && lo > hi
        {
            return bad(format!(
                "{} is larger than {}",
                crate::text::given("min_radius", lo),
                crate::text::given("max_radius", hi)
            ));
        }
        if let Some(c) = self.white_cutoff
            && !(0.0..=1.0).contains(&c)
        {
            return Err(Error::InvalidParameter(format!(
                "«white_cutoff={c}» must be between 0 and 1"
            )));
        }
        Ok(())
    }

    /// The tone adjustments: levels, gamma, invert.
    #[must_use]
    pub fn adjust(&self) -> Adjust {
        Adjust {
            black: self.black_level,
            white: self.white_level,
            gamma: self.gamma,
            invert: self.invert,
        }
    }

    /// [`Self::prepare`] for a map already in memory (borrowed: the
    /// prepared map is a toned copy anyway).
    pub fn prepare_map(
        &self,
        map: &ImportanceMap,
        size: impl FnOnce(u32, u32) -> (u32, u32),
        default_mapping: Mapping,
        radii_scaled: bool,
    ) -> Result<Prepared> {
        self.prepare_map_on(map, size, default_mapping, radii_scaled, None)
    }

    /// [`Self::prepare_map`] for an ink on a paper that is not white:
    /// `paper` = (P, Q), the paper's grey and the ink's grey on it; after
    /// the adjustments each grey v becomes 1 − (P − v)/(P − Q), clamped,
    /// so that the ink's coverage follows the picture (a light ink on dark
    /// paper draws its light parts).
    pub fn prepare_map_on(
        &self,
        map: &ImportanceMap,
        size: impl FnOnce(u32, u32) -> (u32, u32),
        default_mapping: Mapping,
        radii_scaled: bool,
        paper: Option<(f32, f32)>,
    ) -> Result<Prepared> {
        self.check()?;
        let adjust = self.adjust();
        let (w, h) = size(map.width(), map.height());
        // Toned and adjusted as it is resized, in one pass. A picture
        // enlarged to its domain is toned at its own size and read
        // bilinearly at the domain's pixels ([`Prepared::stretched`]): it is
        // enlarged in display grey, as a viewer enlarges it, and no map of
        // the domain's size is made (100K dots on a 512² photo: 0.92× the
        // time; at LBG's count on five photos the mean of 4 seeds 0.15 to
        // 2.8 dB closer, though single seeds vary by 1–2 dB;
        // docs/benchmarks.md). One made smaller is resized to the domain,
        // averaged in linear light. Point sets (`sample` with a map) are
        // prepared alike.
        let tones = self.tones;
        let own = (map.width(), map.height());
        let enlarged = (w, h) != own && w >= own.0 && h >= own.1;
        let (tw, th) = if enlarged { own } else { (w, h) };
        let map = match paper {
            None => map.resized_with(tw, th, |v| adjust.apply(tones.tone(v)))?,
            Some((p, q)) => {
                // The picture the ink draws, in light (as if it were black
                // on white), then resized as any picture is.
                let inked = map.resized_with(own.0, own.1, |v| {
                    let a = (p - adjust.apply(tones.tone(v))) / (p - q);
                    tones.untone((1.0 - a).clamp(0.0, 1.0))
                })?;
                inked.resized_with(tw, th, |v| tones.tone(v))?
            }
        };
        let range = self.radius_range(radii_scaled)?;
        let mapping = match (self.mapping, default_mapping) {
            (Some(MappingKind::Linear), _) => Mapping::Linear,
            // Calibrated for the drawing's dots: a job's own tone mapping
            // (sized dots stay sized), else equal dots.
            (Some(MappingKind::Tone), Mapping::Linear) => Mapping::Tone,
            (Some(MappingKind::Tone) | None, m) => m,
        };
        Ok(Prepared::new(map, mapping, range, self.white_cutoff).stretched((w, h)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A picture enlarged to its domain is toned and levelled at its own
    /// size and read bilinearly there; one made smaller is resized; the
    /// white cutoff reads the domain's pixels either way.
    #[test]
    fn an_enlarged_picture_is_toned_at_its_own_size() {
        let values: Vec<f32> = (0..12).map(|i| i as f32 / 11.0).collect();
        let map = ImportanceMap::from_values(4, 3, values).unwrap();
        let opts = ImportanceOptions {
            gamma: 2.0,
            white_cutoff: Some(0.5),
            ..ImportanceOptions::default()
        };
        let big = opts
            .prepare_map(&map, |_, _| (40, 30), Mapping::Tone, true)
            .unwrap();
        assert_eq!(big.domain(), (40, 30));
        assert_eq!((big.map().width(), big.map().height()), (4, 3));
        let toned = map
            .resized_with(4, 3, |v| opts.adjust().apply(opts.tones.tone(v)))
            .unwrap();
        let expected =
            Prepared::new(toned, Mapping::Tone, big.range, Some(0.5)).stretched((40, 30));
        for (x, y) in [(0, 0), (13, 7), (39, 29), (21, 15)] {
            assert_eq!(big.value(x, y), expected.value(x, y), "({x}, {y})");
        }
        // The cutoff drops the points whose domain pixel is past it.
        let points: Vec<crate::sampler::Point> = (0..40)
            .map(|i| crate::sampler::Point {
                x: i as f32 + 0.5,
                y: 15.5,
                radius: 1.0,
                class: 0,
            })
            .collect();
        let kept = big.cut(&points);
        assert!(!kept.is_empty() && kept.len() < points.len());
        for p in &points {
            assert_eq!(kept.contains(p), big.value_at(p.x, p.y) <= 0.5, "{p:?}");
        }
        // Made smaller, it is resized to the domain.
        let small = opts
            .prepare_map(&map, |_, _| (2, 2), Mapping::Tone, true)
            .unwrap();
        assert_eq!((small.map().width(), small.map().height()), (2, 2));
    }

    #[test]
    fn tone_means_calibrated_for_the_dots_drawn() {
        let map = || ImportanceMap::from_values(4, 4, vec![0.5; 16]).unwrap();
        let prepare = |mapping, default| {
            let opts = ImportanceOptions {
                mapping,
                ..ImportanceOptions::default()
            };
            opts.prepare_map(&map(), |w, h| (w, h), default, true)
                .unwrap()
                .mapping
        };
        let sized = Mapping::ToneSized(0.3);
        assert_eq!(prepare(Some(MappingKind::Tone), sized), sized);
        assert_eq!(prepare(None, sized), sized);
        assert_eq!(prepare(Some(MappingKind::Linear), sized), Mapping::Linear);
        // Point sets default to the paper's ramp; tone calibrates equal dots.
        assert_eq!(prepare(None, Mapping::Linear), Mapping::Linear);
        assert_eq!(
            prepare(Some(MappingKind::Tone), Mapping::Linear),
            Mapping::Tone
        );
    }
}
