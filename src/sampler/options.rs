//! The sampler options that every front end shares: `pixelpie sample`,
//! `pixelpie stipple` (with the `cli` feature these are their arguments),
//! the Python package and library users. The policy is not among them: a
//! job states it beside them (its default is [`super::DEFAULT_POLICY`]).

use serde::Serialize;

use super::{DEFAULT_SUBPIXEL_BITS, Params};

/// Seed, sub-pixel darts, periodic domain and exact mode.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[non_exhaustive]
pub struct SamplerOptions {
    /// Seed of the dart hash.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 0))]
    pub seed: u64,
    /// Sub-pixel bits per axis of dart positions (0 = pixel centres, at most 7).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = DEFAULT_SUBPIXEL_BITS))]
    pub subpixel_bits: u32,
    /// Wrap distances and disks around the domain: tileable output, whose
    /// copies keep the spacing across their seams.
    #[cfg_attr(feature = "cli", arg(long))]
    pub periodic: bool,
    /// Exact mode: the disk condition between the samples themselves with no
    /// sub-pixel slack, maximal in the continuous domain, at the RSA density
    /// (on the GPU backend all but the finest level runs there).
    #[cfg_attr(feature = "cli", arg(long))]
    pub exact: bool,
}

impl Default for SamplerOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            subpixel_bits: DEFAULT_SUBPIXEL_BITS,
            periodic: false,
            exact: false,
        }
    }
}

impl SamplerOptions {
    /// `params` with these options.
    #[must_use]
    pub fn apply(&self, params: Params) -> Params {
        params
            .with_seed(self.seed)
            .with_subpixel_bits(self.subpixel_bits)
            .with_periodic(self.periodic)
            .with_exact(self.exact)
    }
}
