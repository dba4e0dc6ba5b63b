//! The device under test as a conformance session holds it: a [`Peer`] greeted with `HELLO`
//! for one family and model, restarted after a transport failure, with the first failure of a
//! case run kept for the fuzzer (crates/cyclic/README.md).

use super::{Env, Peer, PeerError, Reply, Request, VERSION};
use drivespec_spec::FamilyId;

/// A greeted peer and the first transport failure since [`Device::clear_error`].
pub(crate) struct Device<'a> {
    peer: Box<dyn Peer + 'a>,
    family: FamilyId,
    model: String,
    error: Option<PeerError>,
}

impl<'a> Device<'a> {
    /// The device behind `peer`, to be greeted as `family` `model`.
    pub(crate) fn new(peer: Box<dyn Peer + 'a>, family: FamilyId, model: &str) -> Device<'a> {
        Device {
            peer,
            family,
            model: model.to_owned(),
            error: None,
        }
    }

    /// When the input image of the last `CYCLE` was taken ([`Peer::taken_at`]).
    pub(crate) fn taken_at(&self) -> Option<u64> {
        self.peer.taken_at()
    }

    /// What the peer is, one line.
    pub(crate) fn describe(&self) -> String {
        self.peer.describe()
    }

    /// Sends one request and returns the reply (bounded in time).
    pub(crate) fn call(&mut self, req: &Request) -> Result<Reply, PeerError> {
        self.peer.call(req)
    }

    /// Exchanges `HELLO`; an error names what the device side said.
    pub(crate) fn hello(&mut self) -> Result<String, String> {
        let req = Request::Hello {
            version: VERSION,
            family: self.family.as_str().to_owned(),
            model: self.model.clone(),
        };
        match self.peer.call(&req) {
            Ok(Reply::Hello { version, name }) if version == VERSION => Ok(name),
            Ok(other) => Err(format!(
                "{}: HELLO answered with {other:?} (expected HELLO drivespec-cyclic {VERSION} …)",
                self.peer.describe()
            )),
            Err(e) => Err(format!("{}: {e}", self.peer.describe())),
        }
    }

    /// Whether the device takes the injection `env` (`ENV` answered `OK`; the injections are
    /// optional). The device is reset after it; a transport failure counts as no (and the
    /// device is restarted).
    pub(crate) fn takes(&mut self, env: Env) -> bool {
        let ok = match self.peer.call(&Request::Env { t: 0, env }) {
            Ok(r) => r == Reply::Ok,
            Err(_) => {
                self.restart();
                return false;
            }
        };
        if self.peer.call(&Request::Reset).is_err() {
            self.restart();
        }
        ok
    }

    /// Notes a transport failure, then reconnects or restarts the peer and greets it again.
    pub(crate) fn failed(&mut self, e: &PeerError) {
        if self.error.is_none() {
            self.error = Some(e.clone());
        }
        self.restart();
    }

    /// After a transport error: reconnect or restart the peer and greet it again.
    pub(crate) fn restart(&mut self) {
        if self.peer.recover().is_ok() {
            let _ = self.hello();
        }
    }

    /// Forgets the failure noted so far (a case run begins).
    pub(crate) fn clear_error(&mut self) {
        self.error = None;
    }

    /// The first transport failure since [`Device::clear_error`], if any (taken).
    pub(crate) fn take_error(&mut self) -> Option<PeerError> {
        self.error.take()
    }
}
