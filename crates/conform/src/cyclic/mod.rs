//! The cyclic-exchange protocol `drivespec-cyclic/1` (the crate `drivespec-cyclic`) as the
//! PSD4xx and PSx3xx suites use it, and the device under test as their sessions hold it
//! (`device`).

pub use drivespec_cyclic::*;

pub(crate) mod device;
