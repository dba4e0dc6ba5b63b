//! Checking files: detecting the format and the device, opening the right reader, feeding the
//! right checker, reporting progress. This is the only part of the crate that does I/O; the
//! checkers it drives are pure.
//!
//! Detection (reported in [`Report::detection`]): the format from the first bytes
//! (`drivespec_capture::detect`); a pcap or pcapng whose first record has a serial link type
//! (LINKTYPE_USER0 147, LINKTYPE_RTAC_SERIAL 250) is an HPD line, any other capture is
//! PROFINET (PSD4xx); raw bytes, socat dumps and the serial text format are HPD lines; JSON
//! lines and CSV are IO-Link logs (PSx3xx). `--input-format` and `--device` override it, and
//! a combination that cannot work is an error.

use crate::error::SetupError;
use crate::hpd::{HpdChecker, HpdOptions};
use crate::iolink::{IoLinkChecker, PsxOptions};
use crate::profinet::{PnChecker, PnOptions};
use crate::report::{Catalog, Policy, Report};
use drivespec_capture::detect::Format;
use drivespec_capture::input::Input;
use drivespec_capture::iolink::{CsvReader, IoLinkReader, JsonLinesReader};
use drivespec_capture::pcap::CaptureReader;
use drivespec_capture::profinet::{Counts, Decoder};
use drivespec_capture::serial::{PcapSerial, RawChunks, SerialReader, SocatReader, TextReader};
use drivespec_capture::LinkType;
use drivespec_spec::Spec;
use std::cell::Cell;
use std::fs::File;
use std::io::{self, BufReader, Read};
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A device family to check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Device {
    /// Parker HPD on a serial line (manual chapter 4).
    Hpd,
    /// PSD4xx on PROFINET (bus description chapter 3).
    Psd4xx,
    /// PSx3xx on IO-Link (instruction manual chapter 3).
    Psx3xx,
}

impl Device {
    /// The family id.
    pub fn as_str(self) -> &'static str {
        match self {
            Device::Hpd => "hpd",
            Device::Psd4xx => "psd4xx",
            Device::Psx3xx => "psx3xx",
        }
    }
}

/// The recording format (`--input-format`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputFormat {
    /// Detected from the first bytes.
    #[default]
    Auto,
    /// Classic pcap.
    Pcap,
    /// pcapng.
    Pcapng,
    /// Raw serial bytes.
    Raw,
    /// socat `-v -x` dump.
    Socat,
    /// Serial text format.
    Text,
    /// IO-Link JSON lines.
    Jsonl,
    /// IO-Link CSV.
    Csv,
}

/// Options of a file check.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// The device, when not detected.
    pub device: Option<Device>,
    /// The format, when not detected.
    pub format: InputFormat,
    /// HPD options.
    pub hpd: HpdOptions,
    /// PROFINET options.
    pub pn: PnOptions,
    /// IO-Link options.
    pub psx: PsxOptions,
    /// How the verdict is reached (`--strict`, `--require`).
    pub policy: Policy,
    /// Set by the caller to stop reading; the report covers what was read and is marked
    /// interrupted.
    pub stop: Arc<AtomicBool>,
}

/// Progress of a check: bytes read so far of the file's size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Bytes read (of the file as stored: compressed for gzip input).
    pub bytes: u64,
    /// The file's size, when known.
    pub total: Option<u64>,
}

/// Why a file cannot be checked at all (a file that breaks off is still checked: see
/// [`Report::error`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The file cannot be opened or read.
    #[error("{path}: {source}")]
    Open {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: io::Error,
    },
    /// The checker cannot be set up (spec tables, options).
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The file is not in a format the device's checker reads, or its start is unreadable.
    #[error("{path}: {reason}")]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

/// A reader that counts the bytes it delivers.
struct Counting<R> {
    inner: R,
    count: Rc<Cell<u64>>,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.set(self.count.get() + n as u64);
        Ok(n)
    }
}

/// Events between two progress calls.
const PROGRESS_EVERY: u64 = 16_384;

/// Bytes of the input's start that detection looks at; the check reads them again, followed
/// by the rest, so the input is opened and read once (a pipe or FIFO works like a file).
const PEEK: u64 = 1 << 16;

/// An opened input: the rest after its start, its size when known, and its first bytes.
type Opened = (Box<dyn Read>, Option<u64>, Vec<u8>);

/// The input named `path` (`-`: standard input), opened once.
fn open(path: &Path) -> Result<Opened, RunError> {
    let failed = |source| RunError::Open {
        path: path.to_owned(),
        source,
    };
    let (mut input, len): (Box<dyn Read>, Option<u64>) = if path == Path::new("-") {
        (Box::new(io::stdin()), None)
    } else {
        let f = File::open(path).map_err(failed)?;
        let meta = f.metadata().map_err(failed)?;
        if meta.is_dir() {
            return Err(unreadable(path, "a folder, not a recording"));
        }
        (Box::new(f), meta.is_file().then_some(meta.len()))
    };
    let mut start = Vec::new();
    input
        .by_ref()
        .take(PEEK)
        .read_to_end(&mut start)
        .map_err(failed)?;
    Ok((input, len, start))
}

fn unreadable(path: &Path, reason: impl Into<String>) -> RunError {
    RunError::Unreadable {
        path: path.to_owned(),
        reason: reason.into(),
    }
}

/// What a file holds, decided from its start and the options.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Plan {
    Profinet,
    SerialCapture,
    SerialAuto,
    Raw,
    Socat,
    Text,
    Jsonl,
    Csv,
}

fn plan(
    path: &Path,
    start: &[u8],
    options: &RunOptions,
    notes: &mut Vec<String>,
) -> Result<Plan, RunError> {
    let input = Input::open(start).map_err(|e| unreadable(path, e.to_string()))?;
    let detection = input.detection().clone();
    drop(input);
    let detected = detection.format;
    notes.push(format!("format: {detection}"));
    let mut capture = |forced: bool| -> Result<Plan, RunError> {
        if forced && !matches!(detected, Format::Pcap { .. } | Format::PcapNg { .. }) {
            return Err(unreadable(
                path,
                format!("not a pcap or pcapng capture: detected {detection}"),
            ));
        }
        let mut r = CaptureReader::new(start).map_err(|e| unreadable(path, e.to_string()))?;
        let link = match r.next_record() {
            Ok(Some(rec)) => Some(rec.link_type),
            _ => None,
        };
        Ok(match link {
            Some(LinkType::USER0) | Some(LinkType::RTAC_SERIAL) => {
                notes.push(format!(
                    "device: hpd (first record has the serial link type {})",
                    link.map_or(0, |l| l.0)
                ));
                Plan::SerialCapture
            }
            Some(l) => {
                notes.push(format!(
                    "device: PROFINET capture, PSD4xx checks (first record has link type {})",
                    l.0
                ));
                Plan::Profinet
            }
            None => {
                notes.push("device: PROFINET capture (no records)".into());
                Plan::Profinet
            }
        })
    };
    let p = match options.format {
        InputFormat::Pcap | InputFormat::Pcapng => capture(true)?,
        InputFormat::Raw => Plan::Raw,
        InputFormat::Socat => Plan::Socat,
        InputFormat::Text => Plan::Text,
        InputFormat::Jsonl => Plan::Jsonl,
        InputFormat::Csv => Plan::Csv,
        InputFormat::Auto => match detected {
            Format::Pcap { .. } | Format::PcapNg { .. } => capture(false)?,
            Format::UnknownText => {
                return Err(unreadable(
                    path,
                    format!(
                        "cannot tell what this recording is: {}; give --format",
                        detection.reason
                    ),
                ))
            }
            Format::Socat | Format::SerialText | Format::Raw => {
                notes.push("device: hpd (serial recording)".into());
                Plan::SerialAuto
            }
            Format::JsonLines => {
                notes.push("device: psx3xx (IO-Link master log)".into());
                Plan::Jsonl
            }
            Format::Csv => {
                notes.push("device: psx3xx (IO-Link master log)".into());
                Plan::Csv
            }
            _ => Plan::SerialAuto,
        },
    };
    let family = match p {
        Plan::Profinet => Device::Psd4xx,
        Plan::Jsonl | Plan::Csv => Device::Psx3xx,
        _ => Device::Hpd,
    };
    if let Some(d) = options.device {
        if d != family {
            return Err(unreadable(
                path,
                format!(
                    "--device {} does not fit the recording: detected {} ({})",
                    d.as_str(),
                    family.as_str(),
                    notes.join("; ")
                ),
            ));
        }
    }
    Ok(p)
}

/// Reads the capture at `path` again from its start for the drives found late (a file
/// only: memory stays bounded, nothing of the first pass is kept but the drives' places).
fn second_pass(path: &Path, c: &mut PnChecker<'_>) -> Result<(), RunError> {
    let file = File::open(path).map_err(|source| RunError::Open {
        path: path.to_owned(),
        source,
    })?;
    let mut reader = CaptureReader::new(BufReader::with_capacity(1 << 16, file))
        .map_err(|e| unreadable(path, e.to_string()))?;
    c.begin_second_pass();
    let mut decoder = Decoder::default();
    // A read error was reported by the first pass; the second stops there too.
    while let Ok(Some(rec)) = reader.next_record() {
        let pdu = decoder.decode(rec.link_type, rec.data);
        c.replay_pdu(rec.number, rec.time, &pdu);
    }
    Ok(())
}

/// One Ethernet frame received from a live interface.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiveFrame {
    /// Microseconds since 1970 (UTC) when it was received.
    pub time: u64,
    /// The frame from its destination address on, without FCS.
    pub data: Vec<u8>,
}

/// Runs the PROFINET checks on the Ethernet frames of `frames` as they arrive (`source`
/// names the interface in the report), until it ends or `options.stop` is set; the report is
/// the one a recording of the same frames gets. No second pass: a drive found late is
/// checked from the frames kept since it appeared.
pub fn check_frames(
    spec: &Spec,
    source: &str,
    frames: impl IntoIterator<Item = LiveFrame>,
    options: &RunOptions,
) -> Result<Report, RunError> {
    let (started, clock) = (std::time::SystemTime::now(), std::time::Instant::now());
    if options.device.is_some_and(|d| d != Device::Psd4xx) {
        return Err(unreadable(
            Path::new(source),
            "a live interface carries PROFINET: only --device psd4xx fits",
        ));
    }
    let catalog = Arc::new(Catalog::new(spec).map_err(SetupError::from)?);
    let mut pn = options.pn.clone();
    pn.rescan = false;
    let mut c = PnChecker::with_catalog(spec, pn, catalog)?;
    let mut decoder = Decoder::default();
    let mut counts = Counts::default();
    let mut interrupted = false;
    for (n, frame) in (1u64..).zip(frames) {
        let pdu = decoder.decode(LinkType::ETHERNET, &frame.data);
        counts.add(&pdu);
        c.push_pdu(n, Some(frame.time), &pdu);
        if options.stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
    }
    interrupted |= options.stop.load(Ordering::Relaxed);
    c.end_of_input();
    let mut report = c.finish(Some(counts));
    report.file = Some(source.to_owned());
    report.interrupted = interrupted;
    report.timing = Some((started, clock.elapsed().as_secs_f64() * 1000.0));
    report
        .detection
        .insert(0, format!("live capture on {source}, PSD4xx checks"));
    report.judge(options.policy.clone());
    Ok(report)
}

/// Checks one file (see the module docs); `progress` is called now and then.
pub fn check_path(
    spec: &Spec,
    path: &Path,
    options: &RunOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Report, RunError> {
    let (started, clock) = (std::time::SystemTime::now(), std::time::Instant::now());
    let catalog = Arc::new(Catalog::new(spec).map_err(SetupError::from)?);
    let mut notes = Vec::new();
    let (rest, total, start) = open(path)?;
    if start.is_empty() {
        return Err(unreadable(path, "empty: nothing to check"));
    }
    let plan = plan(path, &start, options, &mut notes)?;
    let count = Rc::new(Cell::new(0u64));
    let reader = BufReader::with_capacity(
        1 << 16,
        Counting {
            inner: io::Cursor::new(start).chain(rest),
            count: count.clone(),
        },
    );
    let mut interrupted = false;
    // Progress now and then; false when the caller asks to stop.
    let mut tick = |n: u64| {
        if n % PROGRESS_EVERY == 0 {
            progress(Progress {
                bytes: count.get(),
                total,
            });
        }
        if options.stop.load(Ordering::Relaxed) {
            interrupted = true;
            return false;
        }
        true
    };
    let mut report = match plan {
        Plan::Profinet => {
            let mut pn = options.pn.clone();
            pn.rescan = total.is_some() && path != Path::new("-");
            let mut c = PnChecker::with_catalog(spec, pn, catalog)?;
            let mut reader =
                CaptureReader::new(reader).map_err(|e| unreadable(path, e.to_string()))?;
            // Records are lent out of the read buffer and decoded in place: no copy per frame.
            let mut decoder = Decoder::default();
            let mut counts = Counts::default();
            let mut n = 0u64;
            loop {
                match reader.next_record() {
                    Ok(Some(rec)) => {
                        let pdu = decoder.decode(rec.link_type, rec.data);
                        counts.add(&pdu);
                        c.push_pdu(rec.number, rec.time, &pdu);
                    }
                    Ok(None) => break,
                    Err(e) => {
                        c.fail(&e);
                        break;
                    }
                }
                n += 1;
                if !tick(n) {
                    break;
                }
            }
            c.end_of_input();
            if c.wants_second_pass() {
                second_pass(path, &mut c)?;
            }
            c.finish(Some(counts))
        }
        Plan::Jsonl | Plan::Csv => {
            let mut c = IoLinkChecker::with_catalog(spec, options.psx.clone(), catalog)?;
            let forced = |r| Input::open(r).map_err(|e| unreadable(path, e.to_string()));
            let lines: Box<dyn Iterator<Item = _>> = match (plan, options.format) {
                (Plan::Jsonl, InputFormat::Jsonl) => {
                    Box::new(JsonLinesReader::new(forced(reader)?))
                }
                (Plan::Csv, InputFormat::Csv) => Box::new(CsvReader::new(forced(reader)?)),
                _ => Box::new(
                    IoLinkReader::open(reader).map_err(|e| unreadable(path, e.to_string()))?,
                ),
            };
            let mut n = 0u64;
            for item in lines {
                match item {
                    Ok(ev) => c.push(&ev),
                    Err(e) if crate::iolink::continues(&e) => c.skipped(&e),
                    Err(e) => {
                        c.fail(&e);
                        break;
                    }
                }
                n += 1;
                if !tick(n) {
                    break;
                }
            }
            c.finish()
        }
        _ => {
            let mut c = HpdChecker::with_catalog(spec, &options.hpd, catalog)?;
            let chunks: Box<dyn Iterator<Item = _>> = match plan {
                Plan::SerialCapture => Box::new(PcapSerial::new(
                    CaptureReader::new(reader).map_err(|e| unreadable(path, e.to_string()))?,
                )),
                Plan::Raw => Box::new(RawChunks::new(
                    Input::open(reader).map_err(|e| unreadable(path, e.to_string()))?,
                )),
                Plan::Socat => Box::new(SocatReader::new(
                    Input::open(reader).map_err(|e| unreadable(path, e.to_string()))?,
                )),
                Plan::Text => Box::new(TextReader::new(
                    Input::open(reader).map_err(|e| unreadable(path, e.to_string()))?,
                )),
                _ => Box::new(
                    SerialReader::open(reader).map_err(|e| unreadable(path, e.to_string()))?,
                ),
            };
            let mut n = 0u64;
            for item in chunks {
                match item {
                    Ok(chunk) => c.push(&chunk),
                    Err(e) if crate::hpd::continues(&e) => c.skipped(&e),
                    Err(e) => {
                        c.fail(&e);
                        break;
                    }
                }
                n += 1;
                if !tick(n) {
                    break;
                }
            }
            c.finish()
        }
    };
    progress(Progress {
        bytes: count.get(),
        total,
    });
    report.file = Some(path.display().to_string());
    report.interrupted = interrupted;
    report.timing = Some((started, clock.elapsed().as_secs_f64() * 1000.0));
    let mut detection = notes;
    detection.append(&mut report.detection);
    report.detection = detection;
    report.judge(options.policy.clone());
    Ok(report)
}
