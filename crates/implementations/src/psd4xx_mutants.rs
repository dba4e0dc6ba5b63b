//! The PSD4xx mutants: the reference drive with one planted deviation (a wrapper around
//! `psd4xx::model::Drive`, served over the cyclic protocol in-process), shared by the mutation
//! test (`psd4xx_mutants.rs`) and the fuzzer test (`crates/fuzz/tests/fuzz_psd4xx.rs`).

use crate::{psd4xx_bit, spec};
use drivespec_cyclic::{CyclicDevice, Env};
use drivespec_positioner::Micros;
use drivespec_psd4xx::model::{Drive, RecordAnswer, RecordFailure, RecordRequest};
use drivespec_psd4xx::{Input, Output, PkwRequest, Request};
use drivespec_spec::FamilyId;

/// The planted deviations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A repeated PKW command is executed again every cycle (answers before "no command").
    PkwRefresh,
    /// Error 1 (read-only) is reported as error 2.
    ReadOnlyAsRange,
    /// Status bit 10 is set together with bit 0.
    Bits0And10,
    /// The loop bit (control bit 6) is taken inverted: loop on the wrong runs.
    LoopInverted,
    /// A positive write answer does not echo PWE.
    EchoMissing,
    /// Control bit 13 is not copied into the status word.
    ToggleNotEchoed,
    /// Out-of-range writes are answered as accepted.
    RangeIgnored,
    /// A record write with control byte 0 is executed.
    RecordControl0Executed,
    /// Clearing the release during a run does not abort it.
    ReleaseWithdrawalIgnored,
    /// Command 0 is answered with the previous response instead of response 0.
    NoResponseMissing,
    /// Par 96 = -1 (delivery state) restores the user's values instead.
    Par96DeliveryWrong,
    /// The speed in the input image has the wrong sign.
    SpeedSignInverted,
    /// A new target during a run is ignored until standstill.
    NewTargetIgnored,
    /// Record reads of 16-bit values return 4 bytes.
    RecordReadWide,
    /// Status bit 10 (obstruction) is never set.
    ObstructionBitMissing,
    /// A write of a standstill-only parameter during a run is answered as accepted.
    StandstillWritesAccepted,
    /// Status bit 0 is set at a standstill within ten positioning windows of the target.
    ReachedOutsideWindow,
    /// Status bits 14 (positive limit) and 15 (negative limit) are swapped.
    LimitBitsSwapped,
    /// A run that ends outside the positioning window is not repeated: one attempt only.
    NoSecondPositioning,
    /// Par 44 is not kept in EEPROM: after a power cycle it has its delivery value again.
    WindowNotBackedUp,
    /// Status bit 7 is reset as soon as the temperature is no longer above par 91 (no 5 °C
    /// hysteresis).
    TemperatureWithoutHysteresis,
    /// Status bit 9 is reset by the next change of the control word instead of a reset only.
    ErrorResetByCommand,
    /// Status bit 15 (negative range limit) is never set.
    LowerLimitBitMissing,
    /// The speed jumps to 50 rpm when a run starts and from there to 0 when it stops (no
    /// ramp below 50 rpm).
    SpeedJumps,
    /// After a run aborted by clearing the release, a shaft turned at standstill (release set,
    /// par 47 = 1) is run back to the last target although no run has completed since: the
    /// release is withdrawn for one cycle and set again, which starts the run (4.1).
    ReadjustAfterAbort,
}

/// The built-in spec with one positioning attempt instead of two (4.2.1), as a drive that
/// leaves out the second positioning is built.
fn one_attempt() -> &'static drivespec_spec::Spec {
    static SPEC: std::sync::OnceLock<drivespec_spec::Spec> = std::sync::OnceLock::new();
    SPEC.get_or_init(|| {
        let mut files = drivespec_spec::SpecFiles::builtin();
        let path = "psd4xx/protocol.toml";
        let text = files
            .get(path)
            .expect("a file of the built-in spec")
            .replace("attempts = 2", "attempts = 1");
        files.set(path, &text);
        drivespec_spec::Spec::from_files(&files).expect("the built-in spec with one attempt loads")
    })
}

#[derive(Clone)]
pub struct Mutant {
    kind: Kind,
    drive: Drive,
    last_pkw: Option<PkwRequest>,
    last_response: Option<drivespec_psd4xx::PkwResponse>,
    running: bool,
    target_in_force: i32,
    /// The target last transferred (control bit 2), if any.
    transferred: Option<i32>,
    /// The device temperature last injected (°C).
    temperature: Option<i16>,
    /// Whether the control word changed since the last position fault.
    error_cleared: bool,
    /// The control word last received.
    last_control: u16,
    /// Whether a run was aborted by clearing the release and none has completed since.
    aborted: bool,
    /// Cycles left of the release withdrawn and set again that start the adjustment.
    adjusting: u8,
}

impl Mutant {
    /// The reference PSD 401 with the deviation `kind`.
    pub fn new(kind: Kind) -> Mutant {
        let spec = if kind == Kind::NoSecondPositioning {
            one_attempt()
        } else {
            spec()
        };
        let drive = Drive::new(spec, drivespec_psd4xx::model::DriveConfig::new("PSD401-5V"))
            .expect("the built-in spec builds the reference drive");
        Mutant {
            kind,
            drive,
            last_pkw: None,
            last_response: None,
            running: false,
            target_in_force: 0,
            transferred: None,
            temperature: None,
            error_cleared: false,
            last_control: 0,
            aborted: false,
            adjusting: 0,
        }
    }
}

impl CyclicDevice<'static> for Mutant {
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String> {
        let rules = self.drive.rules().clone();
        let pkw = rules.pkw();
        let mut out = Output::parse(&rules, image).map_err(|e| e.to_string())?;
        let original = out;
        let release = psd4xx_bit("control", "Release");
        let transfer = psd4xx_bit("control", "Transfer target value");
        match self.kind {
            Kind::PkwRefresh if self.last_pkw == Some(out.pkw) => {
                let mut idle = out;
                idle.pkw = PkwRequest::default();
                let b = idle
                    .to_bytes(&rules)
                    .expect("an image of the spec's layout encodes");
                self.drive.cycle(now, &b)?;
            }
            Kind::LoopInverted => {
                out.control ^= psd4xx_bit("control", "Run without reference loop")
            }
            Kind::ReadjustAfterAbort => {
                if self.running && self.last_control & release != 0 && out.control & release == 0 {
                    self.aborted = true;
                }
                if self.adjusting == 2 {
                    out.control &= !release;
                }
                self.adjusting = self.adjusting.saturating_sub(1);
            }
            Kind::ReleaseWithdrawalIgnored if self.running => out.control |= release,
            Kind::NewTargetIgnored => {
                if self.running && out.control & transfer != 0 {
                    out.target = self.target_in_force;
                } else if out.control & transfer != 0 {
                    self.target_in_force = out.target;
                }
            }
            Kind::Par96DeliveryWrong => {
                let minus1 = pkw
                    .encode_request(&Request::Write {
                        pnu: 96,
                        index: None,
                        width: drivespec_psd4xx::Width::Word,
                        value: -1,
                    })
                    .expect("par 96 is a writable word of the built-in table");
                if out.pkw == minus1 {
                    out.pkw = pkw
                        .encode_request(&Request::Write {
                            pnu: 96,
                            index: None,
                            width: drivespec_psd4xx::Width::Word,
                            value: -2,
                        })
                        .expect("par 96 is a writable word of the built-in table");
                }
            }
            _ => {}
        }
        let bytes = self.drive.cycle(
            now,
            &out.to_bytes(&rules)
                .expect("an image of the spec's layout encodes"),
        )?;
        let mut input = Input::parse(&rules, &bytes).map_err(|e| e.to_string())?;
        let codes = pkw.error_codes();
        let cannot = pkw.response_codes().cannot_execute;
        match self.kind {
            Kind::ReadOnlyAsRange
                if input.pkw.ak == cannot && input.pkw.pwe == codes.read_only.0 =>
            {
                input.pkw.pwe = codes.out_of_range.0;
            }
            Kind::Bits0And10
                if input.status & psd4xx_bit("status", "Target position reached") != 0 =>
            {
                input.status |= psd4xx_bit("status", "Positioning error (obstruction)");
            }
            Kind::EchoMissing => {
                let write = pkw
                    .command_info(original.pkw.ak)
                    .is_some_and(|c| c.op == drivespec_spec::psd4xx::PkwOp::Write);
                if write
                    && input.pkw.ak != cannot
                    && input.pkw.ak != pkw.response_codes().no_response
                {
                    input.pkw.pwe = 0;
                }
            }
            Kind::ToggleNotEchoed => {
                input.status &= !psd4xx_bit("status", "Toggle bit");
            }
            Kind::RangeIgnored
                if input.pkw.ak == cannot && input.pkw.pwe == codes.out_of_range.0 =>
            {
                input.pkw.ak = pkw.expected_response(&original.pkw).unwrap_or(input.pkw.ak);
                input.pkw.pwe = original.pkw.pwe;
            }
            Kind::NoResponseMissing if original.pkw == PkwRequest::default() => {
                if let Some(r) = self.last_response {
                    input.pkw = r;
                }
            }
            Kind::Par96DeliveryWrong => {
                input.pkw.pwe = if input.pkw.pnu == 96 && input.pkw.ak != cannot {
                    original.pkw.pwe
                } else {
                    input.pkw.pwe
                }
            }
            Kind::SpeedSignInverted => input.speed = input.speed.wrapping_neg(),
            Kind::ObstructionBitMissing => {
                input.status &= !psd4xx_bit("status", "Positioning error (obstruction)")
            }
            Kind::StandstillWritesAccepted
                if input.pkw.ak == cannot && input.pkw.pwe == codes.operating_state.0 =>
            {
                input.pkw.ak = pkw.expected_response(&original.pkw).unwrap_or(input.pkw.ak);
                input.pkw.pwe = original.pkw.pwe;
            }
            Kind::ReachedOutsideWindow => {
                if original.control & transfer != 0 {
                    self.transferred = Some(original.target);
                }
                let window = self.drive.parameter(44).unwrap_or(0);
                let still = input.status & psd4xx_bit("status", "Drive is running") == 0;
                if let Some(t) = self.transferred.filter(|_| still) {
                    if (i64::from(input.actual) - i64::from(t)).abs() <= 10 * window {
                        input.status |= psd4xx_bit("status", "Target position reached");
                    }
                }
            }
            Kind::TemperatureWithoutHysteresis => {
                let limit = self.drive.parameter(91).unwrap_or(80);
                if self.temperature.is_some_and(|c| i64::from(c) <= limit) {
                    input.status &= !psd4xx_bit("status", "Temperature too high");
                }
            }
            Kind::ErrorResetByCommand => {
                if original.control != self.last_control {
                    self.error_cleared = true;
                }
                if self.error_cleared {
                    input.status &= !psd4xx_bit("status", "Error");
                }
            }
            Kind::LowerLimitBitMissing => {
                input.status &= !psd4xx_bit("status", "Negative range limit")
            }
            Kind::SpeedJumps
                if input.status & psd4xx_bit("status", "Drive is running") != 0
                    && input.speed != 0 =>
            {
                input.speed = input.speed.signum() * input.speed.abs().max(50);
            }
            Kind::ReadjustAfterAbort
                if input.status & psd4xx_bit("status", "Target position reached") != 0 =>
            {
                self.aborted = false;
            }
            Kind::LimitBitsSwapped => {
                let (up, down) = (
                    psd4xx_bit("status", "Positive range limit"),
                    psd4xx_bit("status", "Negative range limit"),
                );
                let (u, d) = (input.status & up != 0, input.status & down != 0);
                input.status &= !(up | down);
                input.status |= if u { down } else { 0 } | if d { up } else { 0 };
            }
            _ => {}
        }
        self.running = input.status & psd4xx_bit("status", "Drive is running") != 0;
        self.last_control = original.control;
        self.last_pkw = Some(original.pkw);
        if original.pkw != PkwRequest::default() {
            self.last_response = Some(input.pkw);
        }
        Ok(input
            .to_bytes(&rules)
            .expect("an image of the spec's layout encodes"))
    }

    fn advance(&mut self, now: Micros) {
        CyclicDevice::advance(&mut self.drive, now);
    }

    fn record(
        &mut self,
        now: Micros,
        req: RecordRequest,
    ) -> Option<Result<RecordAnswer, RecordFailure>> {
        let req = match (self.kind, req) {
            (Kind::RecordControl0Executed, RecordRequest::Write { index, mut data }) => {
                if data.first() == Some(&0) {
                    data[0] = 1;
                }
                RecordRequest::Write { index, data }
            }
            (_, r) => r,
        };
        let r = self.drive.record(now, req);
        match (self.kind, r) {
            (Kind::RecordReadWide, Some(Ok(RecordAnswer::Data { bytes }))) if bytes.len() == 2 => {
                let mut wide = vec![0, 0];
                wide.extend(bytes);
                Some(Ok(RecordAnswer::Data { bytes: wide }))
            }
            (_, r) => r,
        }
    }

    fn env(&mut self, now: Micros, env: Env) -> bool {
        match env {
            Env::Temperature(c) => self.temperature = Some(c),
            Env::PositionFault => self.error_cleared = false,
            Env::Displace(_)
                if self.kind == Kind::ReadjustAfterAbort
                    && self.aborted
                    && !self.running
                    && self.last_control & psd4xx_bit("control", "Release") != 0
                    && self.drive.parameter(47) == Ok(1) =>
            {
                self.adjusting = 2;
            }
            _ => {}
        }
        let ok = self.drive.env(now, env);
        if self.kind == Kind::WindowNotBackedUp && env == Env::PowerCycle {
            let delivery = spec()
                .family(FamilyId::Psd4xx)
                .parameter("44")
                .and_then(|p| p.default)
                .expect("par 44 has a delivery value in the built-in table");
            // Out of range after a rescaling (par 38/39): the value stays.
            let _ = self.drive.write_parameter(now, 44, delivery);
        }
        ok
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice<'static>> {
        Box::new(self.clone())
    }
}

/// A mutant, its name, the conformance cases that must fail against it, and the requirement
/// IDs (glob patterns) its deviation breaks.
pub struct Case {
    pub kind: Kind,
    pub name: &'static str,
    pub must_fail: &'static [&'static str],
    pub breaks: &'static [&'static str],
}

/// Every PSD4xx mutant.
pub fn mutants() -> Vec<Case> {
    use Kind::*;
    vec![
        Case {
            kind: PkwRefresh,
            name: "pkw-answers-before-no-command",
            must_fail: &[
                "psd4xx/pkw/held-while-running",
                "psd4xx/pkw/reread-after-no-command",
            ],
            breaks: &[
                "PSD-PKW-005",
                "PSD-PKW-003",
                "PSD-PKW-004",
                "PSD-PKW-006",
                "PSD-PKW-007",
            ],
        },
        Case {
            kind: ReadOnlyAsRange,
            name: "wrong-error-code",
            must_fail: &[
                "psd4xx/pkw/write/1/read-only",
                "psd4xx/pkw/write/14/read-only",
            ],
            breaks: &["PSD-PKW-024"],
        },
        Case {
            kind: Bits0And10,
            name: "status-bits-0-and-10-together",
            must_fail: &[
                "psd4xx/position/loop/up",
                "psd4xx/sequence/seq-position-0x14",
            ],
            breaks: &["PSD-STS-0-*", "PSD-STS-10-*"],
        },
        Case {
            kind: LoopInverted,
            name: "loop-on-the-wrong-side",
            must_fail: &["psd4xx/position/loop/down", "psd4xx/position/no-loop/down"],
            // Par 45's sign sets the side of the loop (PSD-PAR-45-002).
            breaks: &[
                "PSD-POS-*",
                "PSD-STS-*",
                "PSD-RUN-*",
                "PSD-PAR-3-001",
                "PSD-PAR-32-*",
                "PSD-PAR-45-*",
                "PSD-PKW-004",
            ],
        },
        Case {
            kind: EchoMissing,
            name: "write-echo-missing",
            must_fail: &["psd4xx/pkw/write/44/max", "psd4xx/pkw/write/3/min"],
            breaks: &[
                "PSD-PKW-034",
                "PSD-PKW-003",
                "PSD-PKW-004",
                "PSD-PKW-006",
                "PSD-PKW-007",
            ],
        },
        Case {
            kind: ToggleNotEchoed,
            name: "toggle-bit-not-echoed",
            must_fail: &["psd4xx/status/toggle"],
            breaks: &["PSD-CTL-13-001", "PSD-STS-2-*"],
        },
        Case {
            kind: RangeIgnored,
            name: "range-ignored",
            must_fail: &[
                "psd4xx/pkw/write/44/above-max",
                "psd4xx/pkw/write/45/below-min",
                "psd4xx/pkw/write/45/gap-1",
            ],
            breaks: &[
                "PSD-PAR-RANGE-001",
                "PSD-PKW-025",
                "PSD-PKW-003",
                "PSD-PKW-004",
                "PSD-PKW-006",
                "PSD-PKW-007",
            ],
        },
        Case {
            kind: RecordControl0Executed,
            name: "record-control-byte-0-executed",
            must_fail: &["psd4xx/record/write/44/control-0"],
            breaks: &["PSD-REC-*"],
        },
        Case {
            kind: ReleaseWithdrawalIgnored,
            name: "release-withdrawal-not-aborting",
            must_fail: &[
                "psd4xx/position/release-withdrawn",
                "psd4xx/sequence/seq-abort-release-withdrawn",
            ],
            breaks: &["PSD-ABORT-*", "PSD-STS-5-*", "PSD-RUN-001"],
        },
        Case {
            kind: NoResponseMissing,
            name: "no-response-missing",
            must_fail: &["psd4xx/pkw/read/44"],
            breaks: &["PSD-PKW-006", "PSD-PKW-003"],
        },
        Case {
            kind: Par96DeliveryWrong,
            name: "par96-delivery-restores-user-values",
            must_fail: &["psd4xx/par96/minus-1"],
            breaks: &["PSD-PAR-96-*"],
        },
        Case {
            kind: SpeedSignInverted,
            name: "speed-sign-inverted",
            must_fail: &["psd4xx/position/manual/up"],
            breaks: &["PSD-PAR-2-001", "PSD-PKW-004"],
        },
        Case {
            kind: NewTargetIgnored,
            name: "new-target-during-run-ignored",
            must_fail: &["psd4xx/position/new-target/same-direction"],
            // Standing at the old target it reports "in position" for a target no longer in
            // force (bit 0, 3.6).
            breaks: &["PSD-POS-002", "PSD-POS-003", "PSD-STS-0-*"],
        },
        Case {
            kind: RecordReadWide,
            name: "record-read-16-bit-as-4-bytes",
            must_fail: &["psd4xx/record/read/44"],
            breaks: &["PSD-REC-*"],
        },
        Case {
            kind: StandstillWritesAccepted,
            name: "standstill-writes-accepted-while-running",
            must_fail: &[
                "psd4xx/pkw/error/operating-state/3",
                "psd4xx/pkw/error/operating-state/37",
                "psd4xx/pkw/error/operating-state/41",
            ],
            breaks: &[
                "PSD-PKW-030",
                "PSD-PAR-3-003",
                "PSD-PAR-37-003",
                "PSD-PAR-38-002",
                "PSD-PAR-40-002",
                "PSD-PAR-41-002",
            ],
        },
        Case {
            kind: ReachedOutsideWindow,
            name: "bit-0-outside-the-window",
            must_fail: &["psd4xx/sequence/seq-second-positioning"],
            breaks: &["PSD-STS-0-*", "PSD-POS-013", "PSD-POS-014", "PSD-STS-10-*"],
        },
        Case {
            kind: LimitBitsSwapped,
            name: "limit-bits-swapped",
            must_fail: &["psd4xx/sequence/seq-manual-run-to-upper-limit"],
            breaks: &["PSD-STS-14-*", "PSD-STS-15-*"],
        },
        Case {
            kind: NoSecondPositioning,
            name: "no-second-positioning",
            must_fail: &["psd4xx/sequence/seq-second-positioning"],
            breaks: &["PSD-POS-013", "PSD-POS-014", "PSD-STS-10-*", "PSD-STS-0-*"],
        },
        Case {
            kind: WindowNotBackedUp,
            name: "window-not-backed-up",
            must_fail: &["psd4xx/pkw/backup/44", "psd4xx/par96/1"],
            breaks: &["PSD-PAR-SAVE-001", "PSD-PAR-96-*", "PSD-PAR-44-002"],
        },
        Case {
            kind: TemperatureWithoutHysteresis,
            name: "temperature-bit-without-hysteresis",
            must_fail: &["psd4xx/status/temperature"],
            breaks: &["PSD-STS-7-*"],
        },
        Case {
            kind: ErrorResetByCommand,
            name: "error-bit-reset-by-a-command",
            must_fail: &["psd4xx/status/position-fault"],
            breaks: &["PSD-STS-9-*"],
        },
        Case {
            kind: LowerLimitBitMissing,
            name: "lower-limit-bit-missing",
            must_fail: &[
                "psd4xx/limits/lower/manual-run",
                "psd4xx/limits/lower/changed",
                "psd4xx/limits/lower/external-force",
            ],
            breaks: &["PSD-STS-15-*"],
        },
        Case {
            kind: SpeedJumps,
            name: "speed-jumps-without-ramp",
            must_fail: &["psd4xx/position/loop/up", "psd4xx/speed/changed-during-run"],
            breaks: &["PSD-VEL-003", "PSD-VEL-004", "PSD-PAR-2-001"],
        },
        Case {
            kind: ReadjustAfterAbort,
            name: "readjustment-after-an-aborted-run",
            must_fail: &["psd4xx/position/readjust-after-abort"],
            breaks: &["PSD-ADJ-009"],
        },
        Case {
            kind: ObstructionBitMissing,
            name: "obstruction-bit-missing",
            must_fail: &["psd4xx/status/obstruction"],
            breaks: &["PSD-STS-10-*", "PSD-OBST-*"],
        },
    ]
}
