//! The GPU backend's errors: a device that cannot run the sampler, or a GPU
//! operation that failed. They reach the contract's callers inside
//! [`crate::sampler::Error::Backend`], so that the contract knows no device.

/// What can go wrong on the GPU.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GpuError {
    /// The device cannot run this job (its limits, a radius too large for
    /// the GPU path, a poisoned state).
    #[error("GPU: {0}")]
    Unusable(String),
    /// A GPU operation failed; the source is wgpu's error.
    #[error("GPU: {what}")]
    Failed {
        /// What failed.
        what: String,
        /// wgpu's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

impl From<GpuError> for crate::sampler::Error {
    fn from(e: GpuError) -> Self {
        Self::backend(e)
    }
}

/// The sampler error of a device that cannot run the job.
pub(crate) fn unusable(why: impl Into<String>) -> crate::sampler::Error {
    GpuError::Unusable(why.into()).into()
}

/// The sampler error of a GPU operation `what` that failed with `source`.
pub(crate) fn failed(
    what: impl Into<String>,
    source: impl std::error::Error + Send + Sync + 'static,
) -> crate::sampler::Error {
    GpuError::Failed {
        what: what.into(),
        source: Box::new(source),
    }
    .into()
}
