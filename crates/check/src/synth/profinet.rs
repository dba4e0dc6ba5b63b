//! PROFINET captures for tests and benchmarks: Ethernet and IPv4/UDP framing, RT cyclic
//! frames with the APDU status, DCE/RPC PNIO-CM calls (Connect with AR, IOCR and expected
//! submodule blocks, record Read/Write, Control), written field by field after IEC 61158-6-10
//! and C706 (the layouts `drivespec_capture` reads), and a controller scenario driving the
//! PSD4xx reference model (`drivespec_psd4xx::model`) with faults planted on request.

use super::SynthError;
use drivespec_capture::write::PcapWriter;
use drivespec_capture::LinkType;
use drivespec_psd4xx::model::{Drive, DriveConfig, RecordAnswer, RecordRequest};
use drivespec_psd4xx::{Input, Output, PkwRequest, RecordRead, RecordWrite, Rules, Width};
use drivespec_spec::Spec;
use std::io::Write;

/// MAC of the IO controller (PLC).
pub const CONTROLLER_MAC: [u8; 6] = [0x00, 0x0e, 0xcf, 0x01, 0x02, 0x03];
/// MAC of the IO device (the PSD4xx).
pub const DEVICE_MAC: [u8; 6] = [0x00, 0x1b, 0x1b, 0x0a, 0x0b, 0x0c];
/// IPv4 address of the controller.
pub const CONTROLLER_IP: [u8; 4] = [192, 168, 0, 1];
/// IPv4 address of the device.
pub const DEVICE_IP: [u8; 4] = [192, 168, 0, 10];
/// FrameID of the input CR (device → controller).
pub const IN_FRAME: u16 = 0x8000;
/// FrameID of the output CR (controller → device).
pub const OUT_FRAME: u16 = 0x8001;
/// C_SDU length of both IOCRs (the RT_CLASS_1 minimum of 40 bytes).
pub const DATA_LENGTH: u16 = 40;
/// The AR UUID of the generated Connect.
pub const AR_UUID: [u8; 16] = [
    0xa0, 0xa1, 0xa2, 0xa3, 0xa4, 0xa5, 0xa6, 0xa7, 0xa8, 0xa9, 0xaa, 0xab, 0xac, 0xad, 0xae, 0xaf,
];
const PNIO_DEVICE: [u8; 16] = [
    0xDE, 0xA0, 0x00, 0x01, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF, 0x7D,
];
const ACTIVITY: [u8; 16] = [
    0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88, 0x99, 0xaa, 0xbb, 0xcc, 0xdd, 0xee, 0xff, 0x01,
];

/// Ethernet II frame (no tag) padded to 60 bytes (without FCS).
pub fn ethernet(dst: [u8; 6], src: [u8; 6], ethertype: u16, payload: &[u8]) -> Vec<u8> {
    let mut f = Vec::with_capacity(14 + payload.len().max(46));
    f.extend_from_slice(&dst);
    f.extend_from_slice(&src);
    f.extend_from_slice(&ethertype.to_be_bytes());
    f.extend_from_slice(payload);
    while f.len() < 60 {
        f.push(0);
    }
    f
}

/// An RT cyclic frame payload: FrameID, C_SDU padded to `data_length`, APDU status.
pub fn rt_cyclic(
    frame_id: u16,
    c_sdu: &[u8],
    data_length: usize,
    cycle: u16,
    data_status: u8,
) -> Vec<u8> {
    let mut p = Vec::with_capacity(6 + data_length.max(c_sdu.len()));
    p.extend_from_slice(&frame_id.to_be_bytes());
    p.extend_from_slice(c_sdu);
    while p.len() < 2 + data_length {
        p.push(0);
    }
    p.extend_from_slice(&cycle.to_be_bytes());
    p.push(data_status);
    p.push(0);
    p
}

/// IPv4 + UDP around `payload` (no options, checksums zero).
pub fn ipv4_udp(src: [u8; 4], dst: [u8; 4], sport: u16, dport: u16, payload: &[u8]) -> Vec<u8> {
    let total = (20 + 8 + payload.len()) as u16;
    let mut p = vec![0x45, 0];
    p.extend_from_slice(&total.to_be_bytes());
    p.extend_from_slice(&[0x12, 0x34, 0x00, 0x00, 64, 17, 0, 0]);
    p.extend_from_slice(&src);
    p.extend_from_slice(&dst);
    p.extend_from_slice(&sport.to_be_bytes());
    p.extend_from_slice(&dport.to_be_bytes());
    p.extend_from_slice(&((8 + payload.len()) as u16).to_be_bytes());
    p.extend_from_slice(&[0, 0]);
    p.extend_from_slice(payload);
    p
}

fn uuid_le(canonical: [u8; 16]) -> Vec<u8> {
    let mut b = canonical.to_vec();
    if let Some(f) = b.get_mut(0..4) {
        f.reverse();
    }
    if let Some(f) = b.get_mut(4..6) {
        f.reverse();
    }
    if let Some(f) = b.get_mut(6..8) {
        f.reverse();
    }
    b
}

/// A connectionless DCE/RPC PDU (little-endian data representation, C706 12.5.1) to the PNIO
/// device interface: request (`response` false) or response.
pub fn rpc(response: bool, opnum: u16, sequence: u32, body: &[u8]) -> Vec<u8> {
    let mut p = vec![4, if response { 2 } else { 0 }, 0x20, 0, 0x10, 0, 0, 0];
    p.extend(uuid_le([0xde; 16]));
    p.extend(uuid_le(PNIO_DEVICE));
    p.extend(uuid_le(ACTIVITY));
    p.extend_from_slice(&0u32.to_le_bytes());
    p.extend_from_slice(&1u32.to_le_bytes());
    p.extend_from_slice(&sequence.to_le_bytes());
    p.extend_from_slice(&opnum.to_le_bytes());
    p.extend_from_slice(&0xffffu16.to_le_bytes());
    p.extend_from_slice(&0xffffu16.to_le_bytes());
    p.extend_from_slice(&(body.len() as u16).to_le_bytes());
    p.extend_from_slice(&0u16.to_le_bytes());
    p.push(0);
    p.push(0);
    p.extend_from_slice(body);
    p
}

/// The NDR header of a request (ArgsMaximum …) or response (PNIOStatus …) and the blocks.
pub fn ndr(response: bool, status: u32, blocks: &[u8]) -> Vec<u8> {
    let n = blocks.len() as u32;
    let first = if response { status } else { 4096 };
    let mut b = Vec::with_capacity(20 + blocks.len());
    for v in [first, n, 4096, 0, n] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(blocks);
    b
}

/// A PNIO-CM block: BlockType, BlockLength, version 1.0, body.
pub fn block(block_type: u16, body: &[u8]) -> Vec<u8> {
    let mut b = block_type.to_be_bytes().to_vec();
    b.extend_from_slice(&((body.len() + 2) as u16).to_be_bytes());
    b.extend_from_slice(&[1, 0]);
    b.extend_from_slice(body);
    b
}

/// Big-endian field writer for block bodies.
#[derive(Default)]
struct Be(Vec<u8>);

impl Be {
    fn u8(mut self, v: u8) -> Be {
        self.0.push(v);
        self
    }
    fn u16(mut self, v: u16) -> Be {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    fn u32(mut self, v: u32) -> Be {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    fn bytes(mut self, v: &[u8]) -> Be {
        self.0.extend_from_slice(v);
        self
    }
}

/// The blocks of a Connect request for one PSD4xx in slot 1, subslot 1 (output 14, input 16
/// bytes at offset 0 of their CRs), 1 ms cycle.
pub fn connect_request_blocks(out_len: u16, in_len: u16) -> Vec<u8> {
    let name = b"plc-1";
    let ar = block(
        0x0101,
        &Be::default()
            .u16(1)
            .bytes(&AR_UUID)
            .u16(1)
            .bytes(&CONTROLLER_MAC)
            .bytes(&PNIO_DEVICE)
            .u32(0x11)
            .u16(600)
            .u16(0x8892)
            .u16(name.len() as u16)
            .bytes(name)
            .0,
    );
    // Input CR: data 16 @0, IOPS @16; IOCS of the output submodule @17.
    // Output CR: data 14 @0, IOPS @14; IOCS of the input submodule @15.
    let iocr = |t: u16, frame: u16, len: u16| {
        block(
            0x0102,
            &Be::default()
                .u16(t)
                .u16(t)
                .u16(0x8892)
                .u32(1)
                .u16(DATA_LENGTH)
                .u16(frame)
                .u16(32)
                .u16(1)
                .u16(1)
                .u16(0)
                .u32(0)
                .u16(10)
                .u16(10)
                .u16(0xc000)
                .bytes(&[0; 6])
                .u16(1)
                .u32(0)
                .u16(1)
                .u16(1)
                .u16(1)
                .u16(0)
                .u16(1)
                .u16(1)
                .u16(1)
                .u16(len + 1)
                .0,
        )
    };
    let expected = block(
        0x0104,
        &Be::default()
            .u16(1)
            .u32(0)
            .u16(1)
            .u32(0x0000_0400)
            .u16(0)
            .u16(1)
            .u16(1)
            .u32(0x0000_0401)
            .u16(3)
            .u16(1)
            .u16(in_len)
            .u8(1)
            .u8(1)
            .u16(2)
            .u16(out_len)
            .u8(1)
            .u8(1)
            .0,
    );
    [
        ar,
        iocr(1, IN_FRAME, in_len),
        iocr(2, OUT_FRAME, out_len),
        expected,
    ]
    .concat()
}

/// The blocks of the Connect response (ARBlockRes, IOCRBlockRes for both CRs).
pub fn connect_response_blocks() -> Vec<u8> {
    let ar = block(
        0x8101,
        &Be::default()
            .u16(1)
            .bytes(&AR_UUID)
            .u16(1)
            .bytes(&DEVICE_MAC)
            .u16(0x8892)
            .0,
    );
    let res = |t: u16, frame: u16| block(0x8102, &Be::default().u16(t).u16(t).u16(frame).0);
    [ar, res(1, IN_FRAME), res(2, OUT_FRAME)].concat()
}

/// A record header block (IODReadReqHeader 0x0009, IODWriteReqHeader 0x0008, their
/// responses 0x8009, 0x8008) for slot 1, subslot 1.
pub fn record_header(block_type: u16, sequence: u16, index: u16, len: u32, status: u32) -> Vec<u8> {
    let mut body = Be::default()
        .u16(sequence)
        .bytes(&AR_UUID)
        .u32(0)
        .u16(1)
        .u16(1)
        .u16(0)
        .u16(index)
        .u32(len);
    if block_type & 0x8000 != 0 {
        body = body.u16(0).u16(0);
        if block_type == 0x8008 {
            body = body.u32(status);
        }
    }
    let mut body = body.0;
    while body.len() < 58 {
        body.push(0);
    }
    block(block_type, &body)
}

/// A control block (IODControlReq PrmEnd 0x0110 and its response 0x8110 …).
pub fn control_block(block_type: u16, command: u16) -> Vec<u8> {
    block(
        block_type,
        &Be::default()
            .u16(0)
            .bytes(&AR_UUID)
            .u16(1)
            .u16(0)
            .u16(command)
            .u16(0)
            .0,
    )
}

/// A fault to plant in a generated PSD4xx capture, with the violations it must give.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PsdFault {
    /// Status bit 2 keeps its value for 100 cycles after control bit 13 changed.
    ToggleNotEchoed,
    /// Status bits 0 and 10 set together in one input image.
    TargetAndOverload,
    /// Control bit 3 (reserved) set for a few cycles.
    ReservedControlBit,
    /// The answer to a PKW write carries another value than the command.
    WriteEchoWrong,
    /// A PKW read of a 32-bit parameter answered with the 16-bit response code.
    WrongResponseCode,
    /// A record write of a 16-bit parameter 4 bytes long, refused by the drive.
    RecordWriteLength,
    /// A record read of a 16-bit parameter answered with 3 bytes.
    RecordReadLength,
    /// One output frame's cycle counter is off by one.
    CycleCounterOff,
    /// DataValid cleared in one input frame.
    DataInvalid,
    /// Status bit 0 while the position is outside the positioning window.
    ReachedOutsideWindow,
    /// The release is withdrawn during a run and status bit 5 never comes.
    AbortNotSignalled,
}

impl PsdFault {
    /// Every fault.
    pub const ALL: [PsdFault; 11] = [
        PsdFault::ToggleNotEchoed,
        PsdFault::TargetAndOverload,
        PsdFault::ReservedControlBit,
        PsdFault::WriteEchoWrong,
        PsdFault::WrongResponseCode,
        PsdFault::RecordWriteLength,
        PsdFault::RecordReadLength,
        PsdFault::CycleCounterOff,
        PsdFault::DataInvalid,
        PsdFault::ReachedOutsideWindow,
        PsdFault::AbortNotSignalled,
    ];

    /// The violations (requirement ID, count) the fault gives.
    pub fn expected(self) -> &'static [(&'static str, u64)] {
        match self {
            PsdFault::ToggleNotEchoed => &[("PSD-CTL-13-001", 1)],
            PsdFault::TargetAndOverload => &[("PSD-STS-0-PRIO", 1)],
            PsdFault::ReservedControlBit => &[("PSD-CTL-3-001", 1)],
            PsdFault::WriteEchoWrong => &[("PSD-PKW-034", 1)],
            PsdFault::WrongResponseCode => &[("PSD-PKW-012", 1)],
            PsdFault::RecordWriteLength => &[("PN-CM-002", 1), ("PSD-REC-006", 1)],
            PsdFault::RecordReadLength => &[("PSD-REC-008", 1)],
            PsdFault::CycleCounterOff => &[("PN-RT-CC-001", 2)],
            PsdFault::DataInvalid => &[("PN-RT-DS-001", 1)],
            PsdFault::ReachedOutsideWindow => &[("PSD-PAR-44-001", 1)],
            PsdFault::AbortNotSignalled => &[("PSD-STS-5-SET-1", 1)],
        }
    }
}

/// How a generated PSD4xx capture looks.
#[derive(Debug, Clone)]
pub struct PsdScenario {
    /// Faults to plant.
    pub faults: Vec<PsdFault>,
    /// Include the Connect (else the drive must be found by options or the search).
    pub connect: bool,
    /// Device model of the reference drive.
    pub model: String,
    /// Cycles (1 ms) the controller leaves the drive idle before the first command.
    pub idle_start: u32,
    /// Cycles from the first frame in which the controller is in STOP (start-up: provider
    /// STOP, IOPS bad, outputs 0).
    pub startup_stop: u32,
    /// The controller goes to STOP for 50 cycles during the first positioning run (provider
    /// STOP, IOPS bad, outputs 0); the drive keeps the last valid outputs (3.9).
    pub stop_during_run: bool,
    /// The controller goes to STOP for the last 20 cycles and then releases the AR (a
    /// controller shutting down).
    pub stop_before_release: bool,
}

impl Default for PsdScenario {
    fn default() -> PsdScenario {
        PsdScenario {
            faults: Vec::new(),
            connect: true,
            model: "PSD426".into(),
            idle_start: 0,
            startup_stop: 0,
            stop_during_run: false,
            stop_before_release: false,
        }
    }
}

/// Start time of generated captures (2024-01-02T10:00:00Z, µs).
pub const START: u64 = 1_704_189_600_000_000;
/// Cycle of the generated IOCRs (µs).
pub const CYCLE_US: u64 = 1000;

/// What the controller does in a phase of the scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    Pkw(PkwRequest),
    PkwIdle,
    ToggleOn,
    ToggleOff,
    Run(i32),
    RunThenAbort(i32),
    Record,
    Idle(u32),
}

/// The capture being written: pcap records and the state of the two streams.
struct Writer {
    pcap: PcapWriter<Vec<u8>>,
    now: u64,
    out_counter: u16,
    in_counter: u16,
    seq: u32,
}

impl Writer {
    fn frame(&mut self, time: u64, data: &[u8]) -> Result<(), SynthError> {
        self.pcap.write_packet(time, data).map_err(SynthError::io)
    }

    fn rpc_pair(&mut self, opnum: u16, req: &[u8], res: &[u8]) -> Result<(), SynthError> {
        self.seq += 1;
        let t = self.now;
        let q = rpc(false, opnum, self.seq, &ndr(false, 0, req));
        let r = rpc(true, opnum, self.seq, &ndr(true, 0, res));
        let qf = ethernet(
            DEVICE_MAC,
            CONTROLLER_MAC,
            0x0800,
            &ipv4_udp(CONTROLLER_IP, DEVICE_IP, 49152, 34964, &q),
        );
        let rf = ethernet(
            CONTROLLER_MAC,
            DEVICE_MAC,
            0x0800,
            &ipv4_udp(DEVICE_IP, CONTROLLER_IP, 34964, 49152, &r),
        );
        self.frame(t + 100, &qf)?;
        self.frame(t + 400, &rf)
    }
}

/// A capture of a controller driving the PSD4xx reference model over PROFINET for a few
/// seconds: (optionally) the Connect and PrmEnd, then 1 ms cycles with PKW reads and writes,
/// toggle-bit handshakes, positioning runs, a run aborted by withdrawing the release, and
/// record writes and reads; `faults` are planted on the way. Returns the pcap bytes.
pub fn psd_capture(spec: &Spec, scenario: &PsdScenario) -> Result<Vec<u8>, SynthError> {
    let rules = Rules::from_spec(spec).map_err(|e| SynthError(e.to_string()))?;
    let mut drive = Drive::new(spec, DriveConfig::new(&scenario.model))
        .map_err(|e| SynthError(format!("model drive: {e}")))?;
    let pkw = rules.pkw().clone();
    let has = |f: PsdFault| scenario.faults.contains(&f);
    let pcap = PcapWriter::new(Vec::new(), LinkType::ETHERNET, 65535).map_err(SynthError::io)?;
    let mut w = Writer {
        pcap,
        now: START,
        out_counter: 0,
        in_counter: 0,
        seq: 0,
    };
    let olen = Output::buffer_len(&rules) as u16;
    let ilen = Input::buffer_len(&rules) as u16;
    if scenario.connect {
        w.rpc_pair(
            0,
            &connect_request_blocks(olen, ilen),
            &connect_response_blocks(),
        )?;
        w.now += 2000;
        w.rpc_pair(4, &control_block(0x0110, 1), &control_block(0x8110, 8))?;
        w.now += 2000;
    }
    let read = |pnu: u16| -> Result<PkwRequest, SynthError> {
        pkw.encode_request(&drivespec_psd4xx::Request::Read { pnu, index: None })
            .map_err(|e| SynthError(e.to_string()))
    };
    let write = |pnu: u16, value: i64| -> Result<PkwRequest, SynthError> {
        let width = pkw.width(pnu).unwrap_or(Width::Word);
        pkw.encode_request(&drivespec_psd4xx::Request::Write {
            pnu,
            index: None,
            width,
            value,
        })
        .map_err(|e| SynthError(e.to_string()))
    };
    let steps = vec![
        Step::Idle(20 + scenario.idle_start),
        Step::Pkw(read(44)?),
        Step::PkwIdle,
        Step::Pkw(write(44, 5)?),
        Step::PkwIdle,
        Step::Pkw(read(42)?),
        Step::PkwIdle,
        Step::Pkw(read(43)?),
        Step::PkwIdle,
        Step::ToggleOn,
        Step::Run(2000),
        Step::ToggleOff,
        Step::Idle(50),
        Step::Record,
        Step::Idle(20),
        Step::Pkw(read(44)?),
        Step::PkwIdle,
        Step::RunThenAbort(-6000),
        Step::Idle(100),
    ];
    let mut control: u16 = 0;
    let mut target: i32 = 0;
    let mut out_pkw = PkwRequest {
        ak: pkw.command_codes().no_command,
        ..PkwRequest::default()
    };
    let mut last_in = drive.input();
    let mut last_valid = Output::default()
        .to_bytes(&rules)
        .map_err(|e| SynthError(e.to_string()))?;
    let mut forced_toggle: Option<u32> = None;
    let mut abort_masked = false;
    let mut cycle: u64 = 0;
    let mut planted_counter = false;
    let mut planted_invalid = false;
    let mut planted_both = false;
    let mut planted_window: Option<u32> = None;
    let mut reserved_cycles = 0u32;
    let echo_fault = has(PsdFault::WriteEchoWrong);
    let code_fault = has(PsdFault::WrongResponseCode);
    for step in steps {
        let mut budget: u32 = 30_000;
        let mut abort_at: Option<u32> = None;
        let mut step_cycles = 0u32;
        loop {
            // The controller decides the next output from the last input it saw.
            let status = last_in.status;
            let done = match step {
                Step::Idle(n) => step_cycles >= n,
                Step::Pkw(r) => {
                    out_pkw = r;
                    pkw.answers(&r, &last_in.pkw) && step_cycles > 0
                }
                Step::PkwIdle => {
                    out_pkw = PkwRequest {
                        ak: pkw.command_codes().no_command,
                        ..PkwRequest::default()
                    };
                    last_in.pkw.ak == pkw.response_codes().no_response && step_cycles > 0
                }
                Step::ToggleOn => {
                    control |= 1 << 13;
                    status & (1 << 2) != 0 && step_cycles > 0
                }
                Step::ToggleOff => {
                    control &= !(1 << 13);
                    if has(PsdFault::ToggleNotEchoed) && forced_toggle.is_none() {
                        forced_toggle = Some(100);
                    }
                    (status & (1 << 2) == 0 || forced_toggle.is_some()) && step_cycles > 0
                }
                Step::Run(delta) | Step::RunThenAbort(delta) => {
                    if step_cycles == 0 {
                        target = last_in.actual.saturating_add(delta);
                        control = (control & (1 << 13)) | 0x14;
                    }
                    if matches!(step, Step::RunThenAbort(_)) && step_cycles == 300 {
                        control &= 1 << 13;
                        abort_at = Some(step_cycles);
                        if has(PsdFault::AbortNotSignalled) {
                            abort_masked = true;
                        }
                    }
                    let reached = status & 1 != 0 && status & (1 << 6) == 0 && step_cycles > 50;
                    let aborted =
                        abort_at.is_some_and(|a| step_cycles > a + 50) && status & (1 << 6) == 0;
                    reached || aborted
                }
                Step::Record => {
                    record_exchange(&mut w, &mut drive, &rules, &scenario.faults)?;
                    true
                }
            };
            if done || budget == 0 {
                break;
            }
            budget -= 1;
            step_cycles += 1;
            cycle += 1;
            let t = w.now;
            // Output frame.
            let mut out_control = control;
            if has(PsdFault::ReservedControlBit)
                && matches!(step, Step::Idle(100))
                && reserved_cycles < 5
                && step_cycles > 10
            {
                out_control |= 1 << 3;
                reserved_cycles += 1;
            }
            let out = Output {
                pkw: out_pkw,
                control: out_control,
                target,
            };
            let out_bytes = out
                .to_bytes(&rules)
                .map_err(|e| SynthError(e.to_string()))?;
            let stopped = cycle <= u64::from(scenario.startup_stop)
                || (scenario.stop_during_run
                    && matches!(step, Step::Run(_))
                    && (10..60).contains(&step_cycles))
                || (scenario.stop_before_release
                    && matches!(step, Step::Idle(100))
                    && step_cycles > 80);
            // With the controller in STOP the drive keeps the last valid outputs (3.9).
            if !stopped {
                last_valid.clone_from(&out_bytes);
            }
            // The model runs on its own clock from power-up; the capture on wall-clock time.
            let mt = t - START;
            drive
                .handle_image(mt, &last_valid)
                .map_err(|e| SynthError(e.to_string()))?;
            drive.advance(mt + 500);
            while drive.poll_input().is_some() {}
            while drive.poll_event().is_some() {}
            let mut c_sdu = if stopped {
                vec![0; out_bytes.len()]
            } else {
                out_bytes.clone()
            };
            c_sdu.extend_from_slice(&[if stopped { 0 } else { 0x80 }, 0x80]);
            w.out_counter = w.out_counter.wrapping_add(32);
            let mut counter = w.out_counter;
            if has(PsdFault::CycleCounterOff) && !planted_counter && cycle == 400 {
                counter = counter.wrapping_add(1);
                planted_counter = true;
            }
            let f = ethernet(
                DEVICE_MAC,
                CONTROLLER_MAC,
                0x8892,
                &rt_cyclic(
                    OUT_FRAME,
                    &c_sdu,
                    usize::from(DATA_LENGTH),
                    counter,
                    if stopped { 0x25 } else { 0x35 },
                ),
            );
            w.frame(t, &f)?;
            // Input frame.
            let mut inp = drive.input();
            let real = inp;
            if let Some(n) = forced_toggle.as_mut() {
                if *n > 0 {
                    inp.status |= 1 << 2;
                    *n -= 1;
                }
            }
            if abort_masked {
                inp.status &= !(1 << 5);
            }
            if echo_fault
                && inp.pkw.pnu == 44
                && inp.pkw.ak == pkw.response_codes().value_word
                && out_pkw.ak == pkw.command_codes().write_word
            {
                inp.pkw.pwe = inp.pkw.pwe.wrapping_add(1);
            }
            if code_fault && inp.pkw.pnu == 42 && inp.pkw.ak == pkw.response_codes().value_dword {
                inp.pkw.ak = pkw.response_codes().value_word;
            }
            if matches!(step, Step::Idle(50))
                && step_cycles == 5
                && has(PsdFault::TargetAndOverload)
                && !planted_both
            {
                inp.status |= 1 | 1 << 10;
                planted_both = true;
            }
            if has(PsdFault::ReachedOutsideWindow)
                && matches!(step, Step::Idle(50))
                && status & 1 != 0
            {
                let n = planted_window.get_or_insert(0);
                if *n < 10 && step_cycles > 20 {
                    inp.actual = inp.actual.saturating_add(500);
                    *n += 1;
                }
            }
            let in_bytes = inp
                .to_bytes(&rules)
                .map_err(|e| SynthError(e.to_string()))?;
            let mut c_sdu = in_bytes;
            c_sdu.extend_from_slice(&[0x80, 0x80]);
            w.in_counter = w.in_counter.wrapping_add(32);
            let mut ds = 0x35;
            if has(PsdFault::DataInvalid) && !planted_invalid && cycle == 500 {
                ds &= !0x04;
                planted_invalid = true;
            }
            let f = ethernet(
                CONTROLLER_MAC,
                DEVICE_MAC,
                0x8892,
                &rt_cyclic(IN_FRAME, &c_sdu, usize::from(DATA_LENGTH), w.in_counter, ds),
            );
            w.frame(t + 300, &f)?;
            last_in = if abort_masked || forced_toggle.is_some() {
                inp
            } else {
                real
            };
            if forced_toggle == Some(0) {
                forced_toggle = None;
                last_in = real;
            }
            w.now += CYCLE_US;
        }
    }
    if scenario.stop_before_release {
        // Release (IEC 61158-6-10 ReleaseBlockReq 0x0114, ControlCommand Release) and its
        // answer (Done).
        w.rpc_pair(1, &control_block(0x0114, 4), &control_block(0x8114, 8))?;
    }
    w.pcap.into_inner().map_err(SynthError::io)
}

/// A record write of par 44 = 4 with control byte 1, then a record read of par 44, through
/// the model (bus description 3.2.2), with the record faults planted.
fn record_exchange(
    w: &mut Writer,
    drive: &mut Drive,
    rules: &Rules,
    faults: &[PsdFault],
) -> Result<(), SynthError> {
    let rr = rules.record();
    let mut data = RecordWrite {
        index: 44,
        control: 1,
        width: Width::Word,
        value: 4,
    }
    .to_bytes(rr)
    .map_err(|e| SynthError(e.to_string()))?;
    if faults.contains(&PsdFault::RecordWriteLength) {
        data.push(0);
    }
    let t = w.now - START;
    drive.handle_record(
        t,
        RecordRequest::Write {
            index: 44,
            data: data.clone(),
        },
    );
    let ok = matches!(
        drive.poll_record().map(|r| r.result),
        Some(Ok(RecordAnswer::Written | RecordAnswer::Ignored))
    );
    let seq = (w.seq + 1) as u16;
    let mut req = record_header(0x0008, seq, 44, data.len() as u32, 0);
    req.extend_from_slice(&data);
    let status = if ok { 0 } else { 0xDF80_B600 };
    let res = record_header(0x8008, seq, 44, data.len() as u32, status);
    w.rpc_pair(3, &req, &res)?;
    w.now += 2000;
    let t = w.now - START;
    drive.handle_record(t, RecordRequest::Read { index: 44 });
    let mut bytes = match drive.poll_record().map(|r| r.result) {
        Some(Ok(RecordAnswer::Data { bytes })) => bytes,
        _ => RecordRead {
            index: 44,
            value: drivespec_psd4xx::RecordValue::Number {
                width: Width::Word,
                value: 4,
            },
        }
        .to_bytes(rr)
        .map_err(|e| SynthError(e.to_string()))?,
    };
    if faults.contains(&PsdFault::RecordReadLength) {
        bytes.push(0);
    }
    let seq = (w.seq + 1) as u16;
    let req = record_header(0x0009, seq, 44, 64, 0);
    let mut res = record_header(0x8009, seq, 44, bytes.len() as u32, 0);
    res.extend_from_slice(&bytes);
    w.rpc_pair(2, &req, &res)?;
    w.now += 2000;
    Ok(())
}

/// Writes a synthetic PROFINET capture of at least `bytes` bytes to `out` for benchmarks:
/// `drives` PSD4xx pairs of 1 ms streams (each frame one output or input image, PKW and
/// counters moving), in classic pcap. Returns the frames written.
pub fn bulk_capture<W: Write>(out: W, bytes: u64, drives: u16) -> std::io::Result<u64> {
    let mut pcap = PcapWriter::new(out, LinkType::ETHERNET, 65535)?;
    let drives = drives.max(1);
    let mut written = 16u64;
    let mut frames = 0u64;
    let mut t = START;
    let mut counter: u16 = 0;
    while written < bytes {
        counter = counter.wrapping_add(32);
        for d in 0..drives {
            let moving = (u32::from(counter)).to_be_bytes();
            // Output: PKW read of par 44, control 0x14, target moving; IOPS, IOCS good.
            let mut out = vec![0x10, 44, 0, 0, 0, 0, 0, 0, 0x14, 0];
            out.extend_from_slice(&moving);
            out.extend_from_slice(&[0x80, 0x80]);
            let f = ethernet(
                DEVICE_MAC,
                CONTROLLER_MAC,
                0x8892,
                &rt_cyclic(
                    OUT_FRAME + 2 * d,
                    &out,
                    usize::from(DATA_LENGTH),
                    counter,
                    0x35,
                ),
            );
            pcap.write_packet(t, &f)?;
            // Input: the answer to the read, status 0, speed 0, actual moving.
            let mut inp = vec![0x10, 44, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0];
            inp.extend_from_slice(&moving);
            inp.extend_from_slice(&[0x80, 0x80]);
            let f = ethernet(
                CONTROLLER_MAC,
                DEVICE_MAC,
                0x8892,
                &rt_cyclic(
                    IN_FRAME + 2 * d,
                    &inp,
                    usize::from(DATA_LENGTH),
                    counter,
                    0x35,
                ),
            );
            pcap.write_packet(t + 300, &f)?;
            written += 2 * (16 + f.len() as u64);
            frames += 2;
        }
        t += CYCLE_US;
    }
    pcap.into_inner()?;
    Ok(frames)
}
