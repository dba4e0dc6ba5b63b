//! Generated recordings for tests, fuzz seeds and benchmarks: HPD line traffic from the
//! reference drive model in every serial format ([`serial`]), PROFINET captures with a
//! Connect, cyclic PSD4xx images and records ([`profinet`]), and IO-Link master logs
//! ([`iolink`]). Everything is written through `drivespec_capture::write` or as the text
//! formats the capture crate documents, so it reads back through the same readers as real
//! recordings. Nothing here panics; errors are [`SynthError`].

pub mod iolink;
pub mod profinet;
pub mod serial;

/// A recording could not be generated (a spec table is missing or a writer failed).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot generate the recording: {0}")]
pub struct SynthError(pub String);

impl SynthError {
    /// An I/O error of a writer.
    pub fn io(e: std::io::Error) -> SynthError {
        SynthError(e.to_string())
    }
}
