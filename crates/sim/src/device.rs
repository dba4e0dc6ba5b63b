//! What `drivespec sim` serves: a sans-IO device model on virtual time, behind one trait so the
//! PSD4xx and PSx3xx models can join once their cyclic-exchange protocol exists.

use super::ServeError;
use drivespec_hpd::explain::explain;
use drivespec_hpd::model::{Drive, DriveConfig, ModelError, Output};
use drivespec_hpd::plc::PlcCodec;
use drivespec_hpd::{FrameRules, LineDecoder, LineEvent, Message};
use drivespec_link::Micros;
use drivespec_spec::{FamilyId, Spec};
use std::sync::Arc;

/// Something the served device did, at a time on its clock (µs since serving started).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Emitted {
    /// Bytes for the line: an answer, or a broadcast the device sends by itself.
    Line {
        /// When the first byte is due.
        at: Micros,
        /// The bytes, exactly as on the line.
        bytes: Vec<u8>,
    },
    /// A change worth logging that is not on the line (HPD digital outputs).
    Note {
        /// When it happened.
        at: Micros,
        /// What happened, in words.
        text: String,
    },
}

/// A sans-IO device model served on a byte stream in real time.
pub trait ServedDevice: Send {
    /// The device and its line settings, one line (for the banner and the log).
    fn describe(&self) -> String;
    /// Line bytes received at `now`.
    fn handle_rx(&mut self, now: Micros, bytes: &[u8]);
    /// Lets time pass until `now`.
    fn advance(&mut self, now: Micros);
    /// The next thing the device did, in order.
    fn poll_output(&mut self) -> Option<Emitted>;
    /// When the device next needs [`ServedDevice::advance`], if ever.
    fn poll_timeout(&self) -> Option<Micros>;
    /// The bit rate the device listens at now, when it has a serial line.
    fn bit_rate(&self) -> Option<u32>;
    /// `bytes` (one message the device sends) with a wrong checksum; None when it has none.
    fn corrupt(&self, bytes: &[u8]) -> Option<Vec<u8>>;
    /// The messages in `bytes` (received at `now`, or sent) in words, for the log.
    fn explain(&mut self, now: Micros, bytes: &[u8], from_device: bool) -> String;
}

/// How the served device is set up (`--model`, `--addr`, `--baud-code`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DeviceOptions {
    /// Device model, matched forgivingly; None: any.
    pub model: Option<String>,
    /// Bus address (HPD Pr27).
    pub address: u8,
    /// HPD Pr26 code; None: the delivery value.
    pub baud_code: Option<u8>,
}

/// The reference model of `family`, commissioned as `opts` says.
pub fn device(
    spec: Arc<Spec>,
    family: FamilyId,
    opts: &DeviceOptions,
) -> Result<Box<dyn ServedDevice>, ServeError> {
    match family {
        FamilyId::Hpd => Ok(Box::new(HpdDevice::new(spec, opts)?)),
        other => Err(ServeError::NotAvailable { family: other }),
    }
}

/// The HPD reference drive (manual chapter 4), commissioned for the serial line (4.1).
pub struct HpdDevice {
    spec: Arc<Spec>,
    drive: Drive,
    rules: FrameRules,
    codec: Option<PlcCodec>,
    model: Option<String>,
    /// Decodes received bytes for the log, across chunks, with the drive's time-out.
    log_decoder: LineDecoder,
    /// The time-out `log_decoder` applies (µs).
    log_timeout: Option<Micros>,
    /// The last request seen, which tells how to read an answer's PAR.
    last_request: Option<Message>,
}

impl HpdDevice {
    /// A drive commissioned at `opts.address` with Pr26 = `opts.baud_code` (manual 4.1).
    pub fn new(spec: Arc<Spec>, opts: &DeviceOptions) -> Result<HpdDevice, ServeError> {
        let family = spec.family(FamilyId::Hpd);
        let model = match &opts.model {
            Some(m) => Some(
                family
                    .model(m)
                    .ok_or_else(|| {
                        let known: Vec<&str> =
                            family.models.iter().map(|m| m.id.as_str()).collect();
                        ServeError::Usage(format!(
                            "unknown HPD model {m:?}; known: {}",
                            known.join(", ")
                        ))
                    })?
                    .id
                    .clone(),
            ),
            None => None,
        };
        let config = match opts.baud_code {
            Some(code) => DriveConfig::commissioned_at(code, opts.address),
            None => DriveConfig::commissioned(opts.address),
        };
        let drive = Drive::new(&spec, config).map_err(|e| match e {
            ModelError::BaudCode { code } => {
                let codes: Vec<String> = family
                    .hpd()
                    .map(|p| p.baud_rates.iter().map(|b| b.code.to_string()).collect())
                    .unwrap_or_default();
                ServeError::Usage(format!(
                    "Pr26 code {code} is not in the baud-rate table (codes: {})",
                    codes.join(", ")
                ))
            }
            ModelError::Address { addr, max } => {
                ServeError::Usage(format!("address {addr} outside 0..={max} (Pr27)"))
            }
            other => ServeError::Model(other.to_string()),
        })?;
        let rules = FrameRules::from_spec(&spec).map_err(|e| ServeError::Model(e.to_string()))?;
        let codec = PlcCodec::from_spec(&spec);
        Ok(HpdDevice {
            log_decoder: LineDecoder::new(rules.clone()),
            log_timeout: None,
            spec,
            drive,
            rules,
            codec,
            model,
            last_request: None,
        })
    }

    /// The drive, for inspection.
    pub fn drive(&self) -> &Drive {
        &self.drive
    }
}

impl ServedDevice for HpdDevice {
    fn describe(&self) -> String {
        let model = self
            .model
            .as_ref()
            .map(|m| format!(" {m}"))
            .unwrap_or_default();
        match self.drive.line() {
            Some(l) => format!(
                "HPD{model} drive at address {}, Pr26 = {} ({} b/s, 8E1, message time-out {} ms{})",
                l.address,
                l.baud_code,
                l.bps,
                l.timeout_us / 1000,
                if l.answer_delay_us > 0 {
                    format!(", answers delayed {} ms", l.answer_delay_us / 1000)
                } else {
                    String::new()
                }
            ),
            None => format!("HPD{model} drive with an unusable Pr26 or Pr27 (silent)"),
        }
    }

    fn handle_rx(&mut self, now: Micros, bytes: &[u8]) {
        self.drive.handle_rx(now, bytes);
    }

    fn advance(&mut self, now: Micros) {
        self.drive.advance(now);
    }

    fn poll_output(&mut self) -> Option<Emitted> {
        self.drive.poll_output().map(|o| match o {
            Output::Transmit { at, bytes } => Emitted::Line { at, bytes },
            Output::DigitalOutputs { at, value } => Emitted::Note {
                at,
                text: format!("digital outputs {value:#06b}"),
            },
        })
    }

    fn poll_timeout(&self) -> Option<Micros> {
        self.drive.poll_timeout()
    }

    fn bit_rate(&self) -> Option<u32> {
        self.drive.line().map(|l| l.bps)
    }

    fn corrupt(&self, bytes: &[u8]) -> Option<Vec<u8>> {
        match drivespec_hpd::parse(&self.rules, bytes) {
            // The short acknowledge has no checksum (manual 4.1).
            Ok(Message::Ack { .. }) | Err(_) => None,
            Ok(_) => corrupt_checksum(&self.rules, bytes),
        }
    }

    fn explain(&mut self, now: Micros, bytes: &[u8], from_device: bool) -> String {
        let family = self.spec.family(FamilyId::Hpd);
        let mut parts = Vec::new();
        let mut frames = Vec::new();
        let mut sink = |e: LineEvent| match e {
            LineEvent::Frame(f) => frames.push(f.message),
            LineEvent::Discarded(d) => parts.push(format!(
                "{} byte(s) that are not a message ({})",
                d.len, d.reason
            )),
        };
        if from_device {
            let mut dec = LineDecoder::new(self.rules.clone());
            dec.feed(bytes, None, &mut sink);
            dec.finish(&mut sink);
        } else {
            // The drive's own time-out (Pr26), so a message it drops is logged as dropped.
            let timeout = self.drive.line().map(|l| l.timeout_us);
            if timeout != self.log_timeout {
                self.log_timeout = timeout;
                let fresh = LineDecoder::new(self.rules.clone());
                self.log_decoder = match timeout {
                    Some(t) => fresh.with_timeout(t),
                    None => fresh,
                };
            }
            self.log_decoder.feed(bytes, Some(now), &mut sink);
        }
        for m in frames {
            let request = if from_device {
                self.last_request.as_ref()
            } else {
                None
            };
            parts.push(explain(family, &self.rules, self.codec.as_ref(), &m, request).summary);
            if !from_device {
                self.last_request = Some(m);
            }
        }
        if parts.is_empty() {
            "(no complete message yet)".to_owned()
        } else {
            parts.join("; ")
        }
    }
}

/// `bytes` with its checksum (the last field, manual 4.1) changed to a value needing no stuffing.
fn corrupt_checksum(rules: &FrameRules, bytes: &[u8]) -> Option<Vec<u8>> {
    let (first, _) = bytes.split_first()?;
    if *first != rules.stx {
        return None;
    }
    // Walk the fields after STX; a field equal to STX is followed by the stuffing byte.
    let mut last = None;
    let mut i = 1;
    while let Some(b) = bytes.get(i) {
        last = Some(i);
        i += if *b == rules.stx { 2 } else { 1 };
    }
    let at = last?;
    let old = *bytes.get(at)?;
    let mut new = old.wrapping_add(1);
    if new == rules.stx {
        new = new.wrapping_add(1);
    }
    let mut out = bytes.get(..at)?.to_vec();
    out.push(new);
    Some(out)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use drivespec_hpd::Data;
    use drivespec_hpd::FrameError;

    fn hpd() -> HpdDevice {
        HpdDevice::new(
            Arc::new(Spec::builtin().unwrap()),
            &DeviceOptions::default(),
        )
        .unwrap()
    }

    #[test]
    fn corrupted_answers_fail_only_their_checksum() {
        let d = hpd();
        // Every data value, so checksums equal to STX (stuffed) are covered too.
        for v in 0..=u16::MAX {
            let m = Message::Response {
                addr: 1,
                par: 0x42,
                data: Data::from_value(i64::from(v), 2).unwrap(),
            };
            let bytes = m.to_bytes(&d.rules).unwrap();
            let bad = d.corrupt(&bytes).unwrap();
            assert_ne!(bad, bytes);
            match drivespec_hpd::parse(&d.rules, &bad) {
                Err(FrameError::Checksum { .. }) => {}
                other => panic!("{v}: {other:?} for {bad:02X?}"),
            }
        }
        let ack = Message::Ack { addr: 1 }.to_bytes(&d.rules).unwrap();
        assert_eq!(d.corrupt(&ack), None);
        assert_eq!(d.corrupt(&[0x01, 0x02]), None);
    }

    #[test]
    fn unknown_options_are_usage_errors() {
        let spec = Arc::new(Spec::builtin().unwrap());
        let bad = |o: DeviceOptions| match HpdDevice::new(spec.clone(), &o) {
            Err(ServeError::Usage(m)) => m,
            other => panic!("{:?}", other.map(|d| d.describe())),
        };
        assert!(bad(DeviceOptions {
            baud_code: Some(42),
            ..DeviceOptions::default()
        })
        .contains("Pr26 code 42"));
        assert!(bad(DeviceOptions {
            address: 200,
            ..DeviceOptions::default()
        })
        .contains("address 200"));
        assert!(bad(DeviceOptions {
            model: Some("nope".into()),
            ..DeviceOptions::default()
        })
        .contains("unknown HPD model"));
        assert!(matches!(
            device(spec, FamilyId::Psd4xx, &DeviceOptions::default()),
            Err(ServeError::NotAvailable { .. })
        ));
    }
}
