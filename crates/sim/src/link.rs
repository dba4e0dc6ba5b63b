//! `sim`: a device model on virtual time as the device under test.

use drivespec_hpd::model::{Drive, Output};
use drivespec_link::{Caps, Chunk, Link, LinkError, Micros, Recovered};

/// A sans-IO device model the simulator link drives (the HPD reference [`Drive`], or a
/// wrapper around it with a planted deviation, for mutation tests).
pub trait SimDevice: Send {
    /// Line bytes received at `now`.
    fn handle_rx(&mut self, now: Micros, bytes: &[u8]);
    /// Lets virtual time pass until `now`.
    fn advance(&mut self, now: Micros);
    /// The next output.
    fn poll_output(&mut self) -> Option<Output>;
    /// Off and on again at `now`.
    fn power_cycle(&mut self, now: Micros);
    /// A copy in the same state.
    fn clone_box(&self) -> Box<dyn SimDevice>;
    /// The digital inputs change at `now` (manual 3.8.1 b90); false when the device has none.
    fn set_inputs(&mut self, now: Micros, inputs: u16) -> bool {
        let _ = (now, inputs);
        false
    }
}

impl SimDevice for Drive {
    fn handle_rx(&mut self, now: Micros, bytes: &[u8]) {
        Drive::handle_rx(self, now, bytes);
    }
    fn advance(&mut self, now: Micros) {
        Drive::advance(self, now);
    }
    fn poll_output(&mut self) -> Option<Output> {
        Drive::poll_output(self)
    }
    fn power_cycle(&mut self, now: Micros) {
        Drive::power_cycle(self, now);
    }
    fn clone_box(&self) -> Box<dyn SimDevice> {
        Box::new(self.clone())
    }
    fn set_inputs(&mut self, now: Micros, inputs: u16) -> bool {
        Drive::set_inputs(self, now, inputs);
        true
    }
}

/// The simulator link: a [`SimDevice`] on a virtual clock. `reset` restores the device it
/// was opened with, at the current time.
pub struct SimLink {
    name: String,
    start: Box<dyn SimDevice>,
    device: Box<dyn SimDevice>,
    /// Virtual time of the link.
    clock: Micros,
    /// The device's clock starts at 0 at every reset; `offset` maps link time to it.
    offset: Micros,
}

impl SimLink {
    /// A link to `device`, described as `name` in reports.
    pub fn new(name: impl Into<String>, device: Box<dyn SimDevice>) -> SimLink {
        SimLink {
            name: name.into(),
            start: device.clone_box(),
            device,
            clock: 0,
            offset: 0,
        }
    }

    fn local(&self, t: Micros) -> Micros {
        t.saturating_sub(self.offset)
    }
}

impl Link for SimLink {
    fn describe(&self) -> String {
        self.name.clone()
    }

    fn caps(&self) -> Caps {
        Caps {
            reset: true,
            power_cycle: true,
            virtual_time: true,
            inputs: true,
        }
    }

    fn now(&mut self) -> Micros {
        self.clock
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let t = self.local(self.clock);
        self.device.handle_rx(t, bytes);
        Ok(())
    }

    fn recv(
        &mut self,
        deadline: Micros,
        _enough: &mut dyn FnMut(&[u8]) -> bool,
    ) -> Result<Vec<Chunk>, LinkError> {
        // Virtual time: waiting is free, so always listen until the deadline.
        let deadline = deadline.max(self.clock);
        self.device.advance(self.local(deadline));
        let mut chunks = Vec::new();
        while let Some(out) = self.device.poll_output() {
            if let Output::Transmit { at, bytes } = out {
                let at = at.saturating_add(self.offset).max(self.clock);
                chunks.push(Chunk { at, bytes });
            }
        }
        self.clock = deadline;
        Ok(chunks)
    }

    fn reset(&mut self) -> Result<bool, LinkError> {
        self.device = self.start.clone_box();
        self.offset = self.clock;
        Ok(true)
    }

    fn power_cycle(&mut self) -> Result<bool, LinkError> {
        let t = self.local(self.clock);
        self.device.power_cycle(t);
        // Outputs of the power-up (digital outputs) are not line bytes.
        while self.device.poll_output().is_some() {}
        Ok(true)
    }

    fn set_inputs(&mut self, inputs: u16) -> Result<bool, LinkError> {
        let t = self.local(self.clock);
        Ok(self.device.set_inputs(t, inputs))
    }

    fn recover(&mut self) -> Result<Recovered, LinkError> {
        self.reset()?;
        Ok(Recovered::Fresh)
    }
}
