//! HPD line traffic from the reference drive model (`drivespec_hpd::model`), with faults
//! planted on request, and writers for every serial recording format `drivespec check`
//! reads: raw bytes, socat `-v -x` dumps, the serial text format, pcap with LINKTYPE_USER0
//! and with LINKTYPE_RTAC_SERIAL (formats in `drivespec_capture::serial`).

use super::SynthError;
use drivespec_capture::serial::{Dir, Origin, SerialChunk};
use drivespec_capture::write::PcapWriter;
use drivespec_capture::LinkType;
use drivespec_hpd::memory::ParamMap;
use drivespec_hpd::model::{Drive, DriveConfig, Output};
use drivespec_hpd::plc::PlcCodec;
use drivespec_hpd::{Data, FrameRules, Message};
use drivespec_spec::hex::{encode, Case};
use drivespec_spec::Spec;

/// 2024-01-02T10:00:00Z in µs since 1970: the start of generated recordings.
pub const EPOCH: u64 = 1_704_189_600_000_000;

/// Time between two requests of a generated session (µs).
pub const STEP_US: u64 = 20_000;

/// A fault to plant in a generated HPD session, with the violations it must give.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HpdFault {
    /// A read with a wrong checksum that a drive nevertheless answers.
    CorruptAnswered,
    /// A read after an acknowledged write that returns another value.
    WrongReadBack,
    /// A drive acknowledges a broadcast.
    AnsweredBroadcast,
    /// A request sent in two pieces further apart than the time-out (Pr26 = 8: 8 ms).
    SlowRequest,
    /// A PLC program uploaded without END.
    UploadWithoutEnd,
    /// A second drive answers a request addressed to drive 1.
    WrongDrive,
}

impl HpdFault {
    /// Every fault.
    pub const ALL: [HpdFault; 6] = [
        HpdFault::CorruptAnswered,
        HpdFault::WrongReadBack,
        HpdFault::AnsweredBroadcast,
        HpdFault::SlowRequest,
        HpdFault::UploadWithoutEnd,
        HpdFault::WrongDrive,
    ];

    /// The violations (requirement ID, count) the fault gives; `timed`: the recording has
    /// times and the checker knows the line speed.
    pub fn expected(self, timed: bool) -> &'static [(&'static str, u64)] {
        match self {
            HpdFault::CorruptAnswered => &[("HPD-FRAME-009", 1), ("HPD-SERIAL-012", 1)],
            HpdFault::WrongReadBack => &[("HPD-PAR-018", 1)],
            HpdFault::AnsweredBroadcast => &[("HPD-SERIAL-013", 1)],
            HpdFault::SlowRequest if timed => &[("HPD-FRAME-020", 1), ("HPD-FRAME-001", 1)],
            HpdFault::SlowRequest => &[],
            HpdFault::UploadWithoutEnd => &[("HPD-PLC-045", 1)],
            HpdFault::WrongDrive => &[("HPD-SERIAL-003", 1)],
        }
    }
}

/// A master talking to one model drive (address 1, Pr26 = 8) on virtual time.
struct Session<'s> {
    rules: FrameRules,
    map: ParamMap,
    drive: Drive,
    spec: &'s Spec,
    now: u64,
    chunks: Vec<SerialChunk>,
}

impl Session<'_> {
    fn chunk(&mut self, time: u64, dir: Dir, bytes: Vec<u8>) {
        let n = self.chunks.len() as u64 + 1;
        self.chunks.push(SerialChunk {
            time: Some(EPOCH + time),
            dir: Some(dir),
            bytes,
            origin: Origin::Line(n),
        });
    }

    fn bytes(&self, m: &Message) -> Result<Vec<u8>, SynthError> {
        m.to_bytes(&self.rules)
            .map_err(|e| SynthError(format!("cannot encode {m:?}: {e}")))
    }

    /// Sends `bytes` at the next step and records the drive's answers; `answer` replaces
    /// an answer's bytes.
    fn send_bytes(&mut self, bytes: Vec<u8>, answer: Option<Vec<u8>>) {
        self.now += STEP_US;
        let t = self.now;
        self.drive.handle_rx(t, &bytes);
        self.chunk(t, Dir::Tx, bytes);
        self.drive.advance(t + STEP_US / 2);
        let mut replacement = answer;
        while let Some(out) = self.drive.poll_output() {
            if let Output::Transmit { at, bytes } = out {
                let b = replacement.take().unwrap_or(bytes);
                self.chunk(at.max(t + 1000), Dir::Rx, b);
            }
        }
        if let Some(b) = replacement {
            self.chunk(t + 1000, Dir::Rx, b);
        }
    }

    fn send(&mut self, m: &Message) -> Result<(), SynthError> {
        let b = self.bytes(m)?;
        self.send_bytes(b, None);
        Ok(())
    }

    fn slot(&self, n: u8) -> Result<(u8, u8), SynthError> {
        self.map
            .slot(n)
            .map(|s| (s.addr, s.size))
            .ok_or_else(|| SynthError(format!("Pr{n} has no serial address")))
    }

    fn read(&mut self, n: u8) -> Result<(), SynthError> {
        let (par, lun) = self.slot(n)?;
        self.send(&Message::ReadParam { addr: 1, lun, par })
    }

    fn write(&mut self, n: u8, value: i64) -> Result<(), SynthError> {
        let (par, size) = self.slot(n)?;
        let data = Data::from_value(value, size)
            .ok_or_else(|| SynthError(format!("Pr{n} = {value} does not fit")))?;
        self.send(&Message::WriteParam { addr: 1, par, data })
    }

    fn bit(&mut self, n: u8, y: u8, on: bool) -> Result<(), SynthError> {
        let b = self
            .map
            .bit(n, y)
            .ok_or_else(|| SynthError(format!("b{n}.{y} has no serial address")))?;
        self.send(&Message::BitChange {
            addr: 1,
            par: b.byte,
            mask: !b.mask,
            value: if on { b.mask } else { 0 },
        })
    }

    fn upload(&mut self, listing: &str, drop_end: bool) -> Result<(), SynthError> {
        let codec = PlcCodec::from_spec(self.spec).ok_or(SynthError("no PLC table".into()))?;
        let program = codec
            .parse_listing(listing)
            .map_err(|e| SynthError(e.to_string()))?;
        let mut at = 0u8;
        let count = program.instrs.len();
        for (i, (_, instr)) in program.instrs.iter().enumerate() {
            let mut b = Vec::new();
            codec
                .encode(instr, &mut b)
                .map_err(|e| SynthError(e.to_string()))?;
            let len = u8::try_from(b.len()).map_err(|_| SynthError("instruction".into()))?;
            if drop_end && i + 1 == count {
                break;
            }
            let data = Data::new(&b).ok_or(SynthError("instruction length".into()))?;
            self.send(&Message::WritePlc {
                addr: 1,
                par: at,
                data,
            })?;
            at = at.saturating_add(len);
        }
        Ok(())
    }
}

/// A commissioned model drive at address 1 (Pr26 = 8: 57600 b/s, 8 ms time-out) and a
/// master doing reads, writes, bit changes, a broadcast and a PLC upload, every 20 ms, with
/// `faults` planted. Chunks are timed (µs since 1970) and directed (`>` master, `<` drive).
pub fn hpd_session(spec: &Spec, faults: &[HpdFault]) -> Result<Vec<SerialChunk>, SynthError> {
    let drive = Drive::new(spec, DriveConfig::commissioned(1))
        .map_err(|e| SynthError(format!("model drive: {e}")))?;
    let rules = FrameRules::from_spec(spec).map_err(|e| SynthError(e.to_string()))?;
    let mut s = Session {
        rules,
        map: ParamMap::from_spec(spec),
        drive,
        spec,
        now: 0,
        chunks: Vec::new(),
    };
    let has = |f: HpdFault| faults.contains(&f);
    s.read(7)?;
    if has(HpdFault::CorruptAnswered) {
        let (par, lun) = s.slot(7)?;
        let mut b = s.bytes(&Message::ReadParam { addr: 1, lun, par })?;
        if let Some(last) = b.last_mut() {
            *last = last.wrapping_add(1);
        }
        let data = Data::from_value(0, lun).ok_or(SynthError("data".into()))?;
        let answer = s.bytes(&Message::Response { addr: 1, par, data })?;
        s.send_bytes(b, Some(answer));
    }
    s.write(33, 253)?;
    if has(HpdFault::WrongReadBack) {
        let (par, size) = s.slot(33)?;
        let data = Data::from_value(254, size).ok_or(SynthError("data".into()))?;
        let answer = s.bytes(&Message::Response { addr: 1, par, data })?;
        let req = s.bytes(&Message::ReadParam {
            addr: 1,
            lun: size,
            par,
        })?;
        s.send_bytes(req, Some(answer));
    } else {
        s.read(33)?;
    }
    if has(HpdFault::SlowRequest) {
        let (par, lun) = s.slot(7)?;
        let b = s.bytes(&Message::ReadParam { addr: 1, lun, par })?;
        let (head, tail) = b.split_at(b.len().saturating_sub(1));
        s.now += STEP_US;
        let t = s.now;
        s.drive.handle_rx(t, head);
        s.chunk(t, Dir::Tx, head.to_vec());
        s.drive.handle_rx(t + 9_000, tail);
        s.chunk(t + 9_000, Dir::Tx, tail.to_vec());
        s.drive.advance(t + STEP_US / 2);
        while s.drive.poll_output().is_some() {}
    }
    // Stop the PLC (b99.13 = 0), upload a program, read it back, start it again.
    s.bit(99, 13, false)?;
    s.upload(
        "LD 90.1\nOUT 91.0\nADD 80,81,82\nEND",
        has(HpdFault::UploadWithoutEnd),
    )?;
    s.send(&Message::ReadPlc {
        addr: 1,
        lun: 2,
        par: 0,
    })?;
    s.bit(99, 13, true)?;
    // Broadcast Pr33 = 300 and read it back.
    let (par, size) = s.slot(33)?;
    let data = Data::from_value(300, size).ok_or(SynthError("data".into()))?;
    let ack = if has(HpdFault::AnsweredBroadcast) {
        Some(s.bytes(&Message::Ack { addr: 1 })?)
    } else {
        None
    };
    let b = s.bytes(&Message::Broadcast { par, data })?;
    s.send_bytes(b, ack);
    s.read(33)?;
    if has(HpdFault::WrongDrive) {
        let (par, lun) = s.slot(7)?;
        let data = Data::from_value(0, lun).ok_or(SynthError("data".into()))?;
        let answer = s.bytes(&Message::Response { addr: 2, par, data })?;
        let req = s.bytes(&Message::ReadParam { addr: 1, lun, par })?;
        s.send_bytes(req, Some(answer));
    }
    s.read(26)?;
    Ok(s.chunks)
}

/// The bytes of the chunks, concatenated (a raw recording, both directions interleaved).
pub fn to_raw(chunks: &[SerialChunk]) -> Vec<u8> {
    chunks
        .iter()
        .flat_map(|c| c.bytes.iter().copied())
        .collect()
}

fn dir_symbol(d: Option<Dir>) -> char {
    d.map_or('-', Dir::symbol)
}

/// The serial text format: `TIME DIR HEX` per chunk (`drivespec_capture::serial`).
pub fn to_text(chunks: &[SerialChunk]) -> String {
    let mut s = String::from("# drivespec serial text: TIME(us) DIR HEX\n");
    for c in chunks {
        let t = c.time.map_or("-".to_owned(), |t| t.to_string());
        s.push_str(&format!(
            "{t} {} {}\n",
            dir_symbol(c.dir),
            drivespec_spec::hex::to_hex(&c.bytes)
        ));
    }
    s
}

/// A socat `-v -x` dump: a header per chunk, 16 bytes per hex line, `--`.
pub fn to_socat(chunks: &[SerialChunk]) -> String {
    let mut s = String::new();
    for c in chunks {
        let t = c.time.unwrap_or(EPOCH);
        let stamp = crate::report::format_time(t);
        // 2024-01-02T10:00:00.020000Z → 2024/01/02 10:00:00.020000
        let date = stamp.get(..10).unwrap_or("2024-01-02").replace('-', "/");
        let clock = stamp.get(11..26).unwrap_or("00:00:00.000000");
        let dir = match c.dir {
            Some(Dir::Rx) => '<',
            _ => '>',
        };
        s.push_str(&format!(
            "{dir} {date} {clock}  length={} from=0 to={}\n",
            c.bytes.len(),
            c.bytes.len().saturating_sub(1)
        ));
        for line in c.bytes.chunks(16) {
            let mut l = format!(" {}", encode(line, Case::Lower, " "));
            while l.len() < 49 {
                l.push(' ');
            }
            l.push(' ');
            for b in line {
                l.push(if b.is_ascii_graphic() {
                    *b as char
                } else {
                    '.'
                });
            }
            s.push_str(&l);
            s.push('\n');
        }
        s.push_str("--\n");
    }
    s
}

/// A pcap of LINKTYPE_USER0 records, one per chunk, with the chunk times.
pub fn to_pcap_user0(chunks: &[SerialChunk]) -> Result<Vec<u8>, SynthError> {
    let mut w = PcapWriter::new(Vec::new(), LinkType::USER0, 65535).map_err(SynthError::io)?;
    for c in chunks {
        w.write_packet(c.time.unwrap_or(EPOCH), &c.bytes)
            .map_err(SynthError::io)?;
    }
    w.into_inner().map_err(SynthError::io)
}

/// A pcap of LINKTYPE_RTAC_SERIAL records: the 12-byte header (time, event 1 DATA_TX or 2
/// DATA_RX, control lines, footer) before each chunk's bytes.
pub fn to_pcap_rtac(chunks: &[SerialChunk]) -> Result<Vec<u8>, SynthError> {
    let mut w =
        PcapWriter::new(Vec::new(), LinkType::RTAC_SERIAL, 65535).map_err(SynthError::io)?;
    for c in chunks {
        let t = c.time.unwrap_or(EPOCH);
        let mut rec = Vec::with_capacity(12 + c.bytes.len());
        rec.extend_from_slice(&((t / 1_000_000) as u32).to_be_bytes());
        rec.extend_from_slice(&((t % 1_000_000) as u32).to_be_bytes());
        rec.push(if c.dir == Some(Dir::Rx) { 0x02 } else { 0x01 });
        rec.extend_from_slice(&[0, 0, 0]);
        rec.extend_from_slice(&c.bytes);
        w.write_packet(t, &rec).map_err(SynthError::io)?;
    }
    w.into_inner().map_err(SynthError::io)
}
