//! A sans-IO PROFINET IO stack for the PSD4xx (manual "PSD4xx PROFINET bus description",
//! IEC 61158-6-10): the reference drive as an IO device, and an IO controller.
//!
//! - Encoders, one protocol layer each: [`eth`] (Ethernet II, 802.1Q), [`udp`] (IPv4/UDP),
//!   [`rpc`] (DCE/RPC connectionless), [`cm`] (PNIO-CM blocks), [`dcp`] (DCP), [`rt`]
//!   (cyclic and alarm frames), [`arp`] (ARP replies). Decoding is `drivespec_capture`'s: every frame built here
//!   reads back through its decoders.
//! - [`status`]: the PNIOStatus values sent and recognised; [`identity`]: vendor and device
//!   ID, slots, idents and I&M0 from the spec.
//! - [`device::Device`]: the PSD4xx reference model (`drivespec_psd4xx::model::Drive`) behind
//!   DCP, PNIO-CM and RT class 1 cyclic data.
//! - [`controller::Controller`]: DCP identify by name, Connect, parameterisation, PrmEnd,
//!   ApplicationReady, cyclic exchange, records, Release.
//!
//! Sans-IO after quinn-proto and str0m: nothing here reads a clock or touches a socket.
//! Callers pass raw Ethernet frames in (`handle_frame(now, bytes)`), drain frames to send
//! (`poll_transmit(now)`), and wake at `poll_timeout()` to call `handle_timeout(now)`; `now`
//! is a [`std::time::Duration`] since any fixed origin. The same inputs give the same
//! outputs, so a virtual clock drives whole sessions in memory.
//!
//! Guarantees: no `unsafe`; no panic on any input frame; memory bounded by the limits each
//! module names (queues, caches); every wait of the controller has a deadline.
#![forbid(unsafe_code)]

pub mod arp;
mod buf;
pub mod cm;
pub mod controller;
pub mod dcp;
pub mod device;
pub mod eth;
pub mod identity;
pub mod rpc;
pub mod rt;
mod station;
pub mod status;
pub mod udp;

pub use controller::{
    Controller, ControllerConfig, ControllerError, ControllerEvent, InputData, RecordId,
};
pub use device::{ArEnd, Device, DeviceConfig, DeviceError, DeviceEvent};

use std::time::Duration;

/// A sans-IO station: frames and time in, frames out (module docs above). Lets one socket
/// loop or virtual wire serve the reference device and any wrapper of it.
pub trait SansIo {
    /// A frame received at `now`.
    fn handle_frame(&mut self, now: Duration, frame: &[u8]);
    /// Runs the deadlines up to `now`.
    fn handle_timeout(&mut self, now: Duration);
    /// The next frame to send at `now`.
    fn poll_transmit(&mut self, now: Duration) -> Option<Vec<u8>>;
    /// When the station has work next.
    fn poll_timeout(&self) -> Option<Duration>;
}
pub use identity::{Identity, IdentityError};
