//! `drivespec fuzz`: stateful, spec-aware black-box fuzzing of a device under test, judged by
//! the same differential oracle as `drivespec conform` (`crates/fuzz/README.md`).
//!
//! - [`run`] (or [`run_on`] with a link of the caller's) generates sequences from the spec
//!   (valid, boundary and malformed requests, commands, PLC programs, environment changes),
//!   runs each against the device and the reference model, and minimises every new finding
//!   (delta debugging over the steps, then over the bytes of each message) into a replay file
//!   ([`Replay`], format `drivespec-fuzz-replay/1`).
//! - [`replay`] reproduces a replay file; [`minimize`] minimises one.
//! - Reports: the conform report model (JSON with a `fuzz` section, JUnit, HTML) under
//!   `Options::out_dir`.
//!
//! The same seed sends the same sequences; on `sim` (virtual time) the whole run, its findings
//! and their replays are the same. Every wait is bounded by the transports' deadlines; a
//! device that dies or hangs is a finding, and the run goes on after restarting it. Nothing
//! here panics on any device behaviour or replay file.
//!
//! HPD ([`hpd`], serial frames), PSD4xx ([`psd4xx`]) and PSx3xx ([`psx3xx`]), the last two
//! over the cyclic-exchange protocol; each implements the crate-internal `Target`
//! (`engine.rs`) with its generator and the family's conformance session of
//! `drivespec-conform`.
#![forbid(unsafe_code)]

mod cyclic_target;
mod ddmin;
mod engine;
mod hpd;
mod output;
pub mod profinet;
mod psd4xx;
mod psx3xx;
mod replay;
mod stats;

pub use output::{json as report_json, Finding};
pub use replay::{
    Action, FindingClass, FindingInfo, Layer, Observed, Replay, ReplayError, Start, Step,
    REPLAY_FORMAT,
};
pub use stats::{FindingSummary, Stats, STATS_SCHEMA};

use drivespec_conform::bar::Bar;
use drivespec_conform::case::CaseRun;
use drivespec_conform::cyclic::{LinkPeer, Peer};
use drivespec_conform::dut::{shell_quote, Dut};
use drivespec_conform::hpd::HpdSuite;
use drivespec_conform::link::Link;
use drivespec_conform::psd4xx::Psd4xxSuite;
use drivespec_conform::psx3xx::Psx3xxSuite;
use drivespec_conform::report::{self, Report};
use drivespec_conform::runner::Progress;
use drivespec_conform::suite::{Settings, SetupError};
use drivespec_spec::{FamilyId, Spec};
use engine::{Event, Found, Limits, Target};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Sequences run when neither `iterations` nor `duration` is given.
pub const DEFAULT_ITERATIONS: u64 = 1000;

/// Everything `drivespec fuzz` takes.
#[derive(Debug, Clone)]
pub struct Options {
    /// The family (HPD, PSD4xx or PSx3xx).
    pub family: FamilyId,
    /// The layer the inputs act at (`--layer`; `profinet` for a PSD4xx on the network).
    pub layer: Layer,
    /// The device under test.
    pub dut: Dut,
    /// Address, seed, model, slack, bit rate.
    pub settings: Settings,
    /// Sequences to run (`--iterations`).
    pub iterations: Option<u64>,
    /// Wall-clock budget (`--duration`).
    pub duration: Option<Duration>,
    /// Folder of the reports and replay files (`--out`, default `reports/fuzz`).
    pub out_dir: PathBuf,
    /// Write no files.
    pub no_reports: bool,
    /// How progress is shown.
    pub progress: Progress,
    /// Distinct findings minimised and kept; later ones are counted.
    pub max_findings: usize,
    /// Runs one minimisation may take.
    pub minimize_runs: u64,
    /// The command, for replay lines (`drivespec fuzz`).
    pub command: String,
    /// Set by the caller to stop after the current sequence; the report is marked
    /// interrupted.
    pub stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            family: FamilyId::Hpd,
            layer: Layer::Application,
            dut: Dut::default(),
            settings: Settings::default(),
            iterations: None,
            duration: None,
            out_dir: PathBuf::from("reports/fuzz"),
            no_reports: false,
            progress: Progress::Auto,
            max_findings: 20,
            minimize_runs: 400,
            command: "drivespec fuzz".to_owned(),
            stop: std::sync::Arc::default(),
        }
    }
}

/// Why fuzzing could not happen (exit 2).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FuzzError {
    /// The suite, the reference or the transport could not be set up.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// A replay file is unusable.
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// The replay file is for another family.
    #[error("the replay is for {found}, not {wanted}")]
    Family {
        /// Family of the run.
        wanted: FamilyId,
        /// Family of the file.
        found: FamilyId,
    },
    /// A report could not be written.
    #[error("cannot write {file}: {why}")]
    Write {
        /// The file.
        file: String,
        /// Why.
        why: String,
    },
}

/// What a campaign gives back.
#[derive(Debug, Clone)]
pub struct Summary {
    /// The report (also written to the files).
    pub report: Report,
    /// The statistics (the report's `fuzz` section).
    pub stats: Stats,
    /// The findings, minimised.
    pub findings: Vec<Finding>,
    /// Files written.
    pub written: Vec<PathBuf>,
}

impl Summary {
    /// 0 no findings, 1 findings.
    pub fn exit_code(&self) -> u8 {
        u8::from(!self.findings.is_empty())
    }
}

/// What replaying a file gave.
#[derive(Debug, Clone)]
pub struct ReplayOutcome {
    /// The evidence of the run.
    pub run: CaseRun,
    /// The finding it showed, if any: class, signature, failing step.
    pub fault: Option<(FindingClass, String, usize)>,
    /// What each step gave.
    pub exchanges: Vec<Observed>,
    /// The exchanges equal the file's, byte for byte (sent, reference, device, verdict).
    pub same_as_recorded: bool,
    /// The finding equals the file's (same signature, or none in both).
    pub same_finding: bool,
    /// How the device was at the start.
    pub start: Start,
}

impl ReplayOutcome {
    /// 0 passes now, 1 still fails.
    pub fn exit_code(&self) -> u8 {
        u8::from(self.fault.is_some())
    }
}

/// Settings of a run: `--dut sim:MODEL` and `serial:…?baud=` fill in the model and bit rate.
fn effective(opts: &Options) -> Settings {
    let mut settings = opts.settings.clone();
    match &opts.dut {
        Dut::Sim { model: Some(m) } if settings.model.is_none() => settings.model = Some(m.clone()),
        Dut::Serial { baud: Some(b), .. } if settings.bit_rate.is_none() => {
            settings.bit_rate = Some(*b)
        }
        _ => {}
    }
    settings
}

/// A device under test of the caller's, instead of the transport `Options::dut` names.
pub enum Device {
    /// A byte link: HPD frames, or `drivespec-cyclic/1` lines for PSD4xx and PSx3xx.
    Link(Box<dyn Link>),
    /// A cyclic-exchange peer (PSD4xx, PSx3xx): e.g. a [`drivespec_conform::cyclic::LocalPeer`] on a test
    /// device.
    Peer(Box<dyn Peer>),
    /// A PSD4xx PROFINET IO device on a wire (`--layer profinet`): a raw socket loop of the
    /// caller's, or a [`profinet::MemoryWire`].
    Profinet(Box<dyn profinet::PnWire>),
}

/// How long a device on a link may take for one cyclic reply (a process may take a while to
/// start): the protocol's time-out, as `drivespec conform` uses it.
const CYCLIC_TIMEOUT_US: u64 = 2_000_000;

/// Builds the family's target on `device` (or the transport `opts.dut` names) and calls `f`.
fn with_target<R>(
    spec: &Spec,
    opts: &Options,
    settings: &Settings,
    device: Option<Device>,
    f: impl FnOnce(&mut dyn Target) -> Result<R, FuzzError>,
) -> Result<R, FuzzError> {
    if opts.layer == Layer::Profinet {
        return with_profinet_target(spec, opts, settings, device, f);
    }
    if let Some(Device::Profinet(_)) = device {
        return Err(FuzzError::Setup(SetupError::Usage(
            "a PROFINET wire needs --layer profinet".to_owned(),
        )));
    }
    match opts.family {
        FamilyId::Hpd => {
            let suite = HpdSuite::new(spec, settings)?;
            let link = match device {
                Some(Device::Link(l)) => l,
                Some(Device::Peer(_) | Device::Profinet(_)) => {
                    return Err(FuzzError::Setup(SetupError::Usage(
                        "hpd needs a byte link, not a cyclic-exchange peer".to_owned(),
                    )))
                }
                None => suite.link(&opts.dut)?,
            };
            let mut target = crate::hpd::HpdTarget::new(&suite, link)?;
            f(&mut target)
        }
        FamilyId::Psd4xx => {
            let suite = Psd4xxSuite::new(spec, settings)?;
            let peer: Box<dyn Peer> = match device {
                Some(Device::Peer(p)) => p,
                Some(Device::Link(l)) => Box::new(LinkPeer::new(l, CYCLIC_TIMEOUT_US)),
                Some(Device::Profinet(_)) | None => suite.peer(&opts.dut)?,
            };
            let mut target = crate::psd4xx::target(&suite, peer)?;
            f(&mut target)
        }
        FamilyId::Psx3xx => {
            let suite = Psx3xxSuite::new(spec, settings)?;
            let peer: Box<dyn Peer + '_> = match device {
                Some(Device::Peer(p)) => p,
                Some(Device::Link(l)) => Box::new(LinkPeer::new(l, CYCLIC_TIMEOUT_US)),
                Some(Device::Profinet(_)) | None => suite.peer(&opts.dut)?,
            };
            let mut target = crate::psx3xx::target(&suite, peer)?;
            f(&mut target)
        }
    }
}

/// NameOfStation of the simulated device of `--layer profinet --dut sim`.
const SIM_STATION: &str = "psd4xx-sim";
/// MAC and IP of the simulated device and of the fuzzer on its virtual wire
/// (locally administered addresses, a private subnet).
const SIM_DEVICE: ([u8; 6], [u8; 4]) = ([0x02, 0x00, 0x00, 0x00, 0x04, 0x01], [10, 4, 0, 2]);
/// The fuzzer's side of the virtual wire.
const SIM_CONTROLLER: ([u8; 6], [u8; 4]) = ([0x02, 0x00, 0x00, 0x00, 0x04, 0x02], [10, 4, 0, 1]);

/// The PROFINET-layer target on `device` (a wire of the caller's) or, for `--dut sim`, on
/// the reference device in memory; the device must pass the liveness probe first (else
/// a setup error: no such station, Connect refused).
fn with_profinet_target<R>(
    spec: &Spec,
    opts: &Options,
    settings: &Settings,
    device: Option<Device>,
    f: impl FnOnce(&mut dyn Target) -> Result<R, FuzzError>,
) -> Result<R, FuzzError> {
    if opts.family != FamilyId::Psd4xx {
        return Err(FuzzError::Setup(SetupError::Usage(format!(
            "--layer profinet is for psd4xx, not {}",
            opts.family
        ))));
    }
    let setup = |e: String| FuzzError::Setup(SetupError::Spec(e));
    let identity =
        drivespec_profinet::Identity::from_spec(spec).map_err(|e| setup(e.to_string()))?;
    let wire: Box<dyn profinet::PnWire> = match (device, &opts.dut) {
        (Some(Device::Profinet(w)), _) => w,
        (None, Dut::Sim { .. }) => {
            let model = settings
                .model
                .clone()
                .unwrap_or_else(|| drivespec_sim::reference::PSD4XX_DEFAULT_MODEL.to_owned());
            let mut config =
                drivespec_profinet::DeviceConfig::new(spec, &model, SIM_DEVICE.0, SIM_STATION)
                    .map_err(|e| setup(e.to_string()))?;
            config.ip = SIM_DEVICE.1;
            config.netmask = [255, 255, 255, 0];
            let fresh =
                drivespec_profinet::Device::new(spec, config).map_err(|e| setup(e.to_string()))?;
            Box::new(profinet::MemoryWire::new(
                Box::new(move || fresh.clone()),
                SIM_CONTROLLER,
                SIM_STATION,
                &format!("sim:{model} (PROFINET IO device in memory)"),
            ))
        }
        _ => {
            return Err(FuzzError::Setup(SetupError::Usage(format!(
                "--layer profinet needs --dut sim or a PROFINET wire, not {}",
                opts.dut
            ))))
        }
    };
    let what = wire.describe();
    let mut target = profinet::ProfinetTarget::new(spec, wire, identity);
    if let Some(why) = target.check_alive() {
        return Err(FuzzError::Setup(SetupError::Link(
            drivespec_conform::link::LinkError::Open { what, reason: why },
        )));
    }
    f(&mut target)
}

/// Runs a fuzzing campaign against `opts.dut` and writes the reports.
pub fn run(spec: &Spec, opts: &Options, progress: &mut dyn Write) -> Result<Summary, FuzzError> {
    let settings = effective(opts);
    with_target(spec, opts, &settings, None, |t| {
        campaign(t, opts, &settings, progress)
    })
}

/// [`run`] on a link of the caller's (a mutant on `sim`, a custom transport); `opts.dut`
/// only names it in the reports.
pub fn run_on(
    spec: &Spec,
    opts: &Options,
    link: Box<dyn Link>,
    progress: &mut dyn Write,
) -> Result<Summary, FuzzError> {
    run_on_device(spec, opts, Device::Link(link), progress)
}

/// [`run`] on a device of the caller's: a link, or a cyclic-exchange peer (PSD4xx and PSx3xx
/// mutants, embedding tools); `opts.dut` only names it in the reports.
pub fn run_on_device(
    spec: &Spec,
    opts: &Options,
    device: Device,
    progress: &mut dyn Write,
) -> Result<Summary, FuzzError> {
    let settings = effective(opts);
    with_target(spec, opts, &settings, Some(device), |t| {
        campaign(t, opts, &settings, progress)
    })
}

/// The replay of a finding, as saved.
fn replay_of(
    found: &Found,
    family: FamilyId,
    layer: Layer,
    dut: &str,
    settings: &Settings,
) -> Replay {
    let t0 = found.trial.run.evidence.first().map_or(0, |r| r.at_us);
    Replay {
        family,
        layer,
        dut: dut.to_owned(),
        address: settings.address,
        model: settings.model.clone(),
        bit_rate: settings.bit_rate,
        seed: settings.seed,
        start: found.start,
        finding: Some(FindingInfo {
            class: found.fault.class,
            signature: found.fault.signature.clone(),
            message: found.fault.failure.message.clone(),
            step: found.fault.step.min(found.steps.len().saturating_sub(1)),
            requirements: found
                .fault
                .failure
                .requirements
                .iter()
                .map(|r| r.id.clone())
                .collect(),
            sequence: found.sequence,
            original_steps: found.original_steps,
            minimisation_runs: found.runs,
            reproduced: found.reproduced,
        }),
        steps: found.steps.clone(),
        exchanges: found
            .trial
            .run
            .evidence
            .iter()
            .map(|r| Observed::of(r, t0))
            .collect(),
    }
}

fn replay_line(opts: &Options, file: &Path) -> String {
    let layer = match opts.layer {
        Layer::Application => String::new(),
        l => format!(" --layer {l}"),
    };
    format!(
        "{} {}{layer} --dut {} --replay {}",
        opts.command,
        opts.family,
        shell_quote(&opts.dut.to_string()),
        shell_quote(&file.display().to_string())
    )
}

fn campaign(
    target: &mut dyn Target,
    opts: &Options,
    settings: &Settings,
    progress: &mut dyn Write,
) -> Result<Summary, FuzzError> {
    if !opts.no_reports {
        let names = ["fuzz.junit.xml", "fuzz.json", "fuzz.html"];
        let paths: Vec<PathBuf> = names.iter().map(|n| opts.out_dir.join(n)).collect();
        drivespec_report::check_writable(&paths).map_err(|e| FuzzError::Write {
            file: e.path.display().to_string(),
            why: e.why.to_string(),
        })?;
    }
    let family = target.family();
    let mode = opts.progress.resolve();
    let (started, clock) = (std::time::SystemTime::now(), std::time::Instant::now());
    let mut stats = Stats::new(family, settings.seed);
    let iterations = match (opts.iterations, opts.duration) {
        (None, None) => Some(DEFAULT_ITERATIONS),
        (i, _) => i,
    };
    let limits = Limits {
        iterations,
        duration: opts.duration,
        max_findings: opts.max_findings,
        minimize_runs: opts.minimize_runs,
        stop: opts.stop.clone(),
    };
    let dut = opts.dut.to_string();
    let mut findings: Vec<Finding> = Vec::new();
    let mut errors: Vec<FuzzError> = Vec::new();
    let every = iterations.map_or(200, |n| (n / 10).max(1));
    // A count of sequences, or the time spent of the --duration budget.
    let bar = (mode == Progress::Bar).then(|| match (iterations, opts.duration) {
        (None, Some(d)) => Bar::time(d),
        (n, _) => Bar::count(n.unwrap_or(0), "sequences"),
    });
    let found = {
        let mut on_event = |ev: Event<'_>| match ev {
            Event::Sequence { n, findings: k } => match mode {
                Progress::Plain if n % every == 0 => {
                    let total = iterations.map_or_else(|| "?".to_owned(), |t| t.to_string());
                    let _ = writeln!(
                        progress,
                        "fuzz {family}: {n}/{total} sequences, {k} finding(s)"
                    );
                }
                Progress::Bar => {
                    if let Some(b) = &bar {
                        if iterations.is_some() {
                            b.set(n, format!("{k} finding(s)"));
                        } else {
                            let spent = clock.elapsed();
                            let rate = n as f64 / spent.as_secs_f64().max(1e-3);
                            b.set(
                                u64::try_from(spent.as_millis()).unwrap_or(u64::MAX),
                                format!("{n} sequences, {rate:.0}/s, {k} finding(s)"),
                            );
                        }
                    }
                }
                _ => {}
            },
            Event::Finding(f) => {
                let id = format!("{family}/fuzz/finding-{}", findings.len() + 1);
                let replay = replay_of(f, family, opts.layer, &dut, settings);
                let mut finding = Finding::new(id.clone(), f, replay);
                if !opts.no_reports {
                    let path = opts
                        .out_dir
                        .join(format!("finding-{}.json", findings.len() + 1));
                    match finding.replay.save(&path) {
                        Ok(()) => finding.file = Some(path),
                        Err(e) => errors.push(e.into()),
                    }
                }
                let say = |progress: &mut dyn Write| {
                    let _ = writeln!(
                        progress,
                        "{id}: {} in {} step(s) (from {}){}",
                        f.fault.signature,
                        f.steps.len(),
                        f.original_steps,
                        match (f.reproduced, f.cut_short) {
                            (_, true) => ", minimisation stopped at the --duration limit",
                            (true, false) => "",
                            (false, false) => ", did not reproduce from the start state",
                        }
                    );
                    if let Some(file) = &finding.file {
                        let _ = writeln!(progress, "  replay: {}", replay_line(opts, file));
                    }
                    let _ = progress.flush();
                };
                match (&bar, mode) {
                    (_, Progress::Quiet) => {}
                    (Some(b), _) => b.suspend(|| say(&mut *progress)),
                    (None, _) => say(&mut *progress),
                }
                findings.push(finding);
            }
            Event::Improved(i, f) => {
                let Some(old) = findings.get_mut(i) else {
                    return;
                };
                let replay = replay_of(f, family, opts.layer, &dut, settings);
                let mut finding = Finding::new(old.id.clone(), f, replay);
                if let Some(path) = old.file.take() {
                    match finding.replay.save(&path) {
                        Ok(()) => finding.file = Some(path),
                        Err(e) => errors.push(e.into()),
                    }
                }
                if mode == Progress::Plain {
                    let _ = writeln!(
                        progress,
                        "{}: replaced by a shorter replay, {} step(s)",
                        finding.id,
                        f.steps.len()
                    );
                }
                *old = finding;
            }
        };
        engine::campaign(target, settings.seed, limits, &mut stats, &mut on_event)
    };
    if let Some(b) = &bar {
        // A time bar ends at the time spent: full when the budget ran out.
        if iterations.is_none() {
            b.reach(u64::try_from(clock.elapsed().as_millis()).unwrap_or(u64::MAX));
        }
        b.finish();
    }
    if let Some(e) = errors.into_iter().next() {
        return Err(e);
    }
    // Occurrence counts are final only now.
    for (f, x) in findings.iter_mut().zip(&found) {
        f.occurrences = x.occurrences;
    }
    let touched: Vec<String> = stats.requirements_touched.keys().cloned().collect();
    let all = target.requirement_ids();
    stats.requirements_not_touched = all
        .iter()
        .filter(|(id, _)| !touched.contains(id))
        .map(|(id, _)| id.clone())
        .collect();
    stats.findings = findings
        .iter()
        .zip(&found)
        .map(|(f, x)| FindingSummary {
            id: f.id.clone(),
            class: x.fault.class,
            signature: x.fault.signature.clone(),
            first_sequence: x.sequence,
            occurrences: x.occurrences,
            steps: x.steps.len(),
            exchanges: x.steps.iter().filter(|s| engine::is_exchange(s)).count(),
            original_steps: x.original_steps,
            reproduced: x.reproduced,
            file: f.file.as_ref().map(|p| p.display().to_string()),
            requirements: x
                .fault
                .failure
                .requirements
                .iter()
                .map(|r| r.id.clone())
                .collect(),
        })
        .collect();
    let replay_cmd = |f: &Finding| f.file.as_ref().map(|p| replay_line(opts, p));
    let desc = output::RunDesc {
        family,
        dut: dut.clone(),
        transport: target.describe(),
        seed: settings.seed,
        address: settings.address,
        model: settings.model.clone(),
        replay_cmd: &replay_cmd,
    };
    let mut report = output::build(&desc, &findings, &stats, &|id| target.requirement(id), &all);
    report.summary.interrupted = stats.stopped_by == "interrupted";
    report.timing = Some(report::Timing {
        started,
        wall_ms: clock.elapsed().as_secs_f64() * 1000.0,
    });
    let mut written = Vec::new();
    if !opts.no_reports {
        let dir = &opts.out_dir;
        let files = [
            (
                dir.join("fuzz.junit.xml"),
                report::junit_with(&report, "drivespec fuzz", &output::junit_properties(&stats)),
            ),
            (dir.join("fuzz.json"), output::json(&report, &stats)),
            (
                dir.join("fuzz.html"),
                report::html_with(&report, "drivespec fuzz", &output::html_section(&stats)),
            ),
        ];
        drivespec_report::write_set(&files).map_err(|e| FuzzError::Write {
            file: e.path.display().to_string(),
            why: e.why.to_string(),
        })?;
        written.extend(files.into_iter().map(|(p, _)| p));
        written.extend(findings.iter().filter_map(|f| f.file.clone()));
    }
    Ok(Summary {
        report,
        stats,
        findings,
        written,
    })
}

/// Settings of a replay: the address, model and bit rate it was recorded with.
fn replay_settings(opts: &Options, r: &Replay) -> Settings {
    let mut s = effective(opts);
    s.address = r.address;
    if r.model.is_some() {
        s.model = r.model.clone();
    }
    if r.bit_rate.is_some() {
        s.bit_rate = r.bit_rate;
    }
    s.seed = r.seed;
    s
}

fn check_family(opts: &Options, r: &Replay) -> Result<(), FuzzError> {
    if r.family != opts.family {
        return Err(FuzzError::Family {
            wanted: opts.family,
            found: r.family,
        });
    }
    if r.layer != opts.layer {
        return Err(FuzzError::Setup(SetupError::Usage(format!(
            "the replay is at layer {}, the run at layer {} (--layer {})",
            r.layer, opts.layer, r.layer
        ))));
    }
    Ok(())
}

fn replay_with(target: &mut dyn Target, r: &Replay) -> ReplayOutcome {
    let (trial, start) = engine::replay_once(target, &r.steps);
    let t0 = trial.run.evidence.first().map_or(0, |x| x.at_us);
    let exchanges: Vec<Observed> = trial
        .run
        .evidence
        .iter()
        .map(|x| Observed::of(x, t0))
        .collect();
    let same_as_recorded = exchanges.len() == r.exchanges.len()
        && exchanges
            .iter()
            .zip(&r.exchanges)
            .all(|(a, b)| a.same_exchange(b));
    let fault = trial
        .fault
        .as_ref()
        .map(|f| (f.class, f.signature.clone(), f.step));
    let same_finding = match (&fault, &r.finding) {
        (Some((_, sig, _)), Some(fi)) => *sig == fi.signature,
        (None, None) => true,
        _ => false,
    };
    ReplayOutcome {
        run: trial.run,
        fault,
        exchanges,
        same_as_recorded,
        same_finding,
        start,
    }
}

/// Replays `r` against `opts.dut` from the start state (where the transport allows).
pub fn replay(spec: &Spec, opts: &Options, r: &Replay) -> Result<ReplayOutcome, FuzzError> {
    check_family(opts, r)?;
    let settings = replay_settings(opts, r);
    with_target(spec, opts, &settings, None, |t| Ok(replay_with(t, r)))
}

/// [`replay`] on a link of the caller's.
pub fn replay_on(
    spec: &Spec,
    opts: &Options,
    r: &Replay,
    link: Box<dyn Link>,
) -> Result<ReplayOutcome, FuzzError> {
    replay_on_device(spec, opts, r, Device::Link(link))
}

/// [`replay`] on a device of the caller's (a link or a cyclic-exchange peer).
pub fn replay_on_device(
    spec: &Spec,
    opts: &Options,
    r: &Replay,
    device: Device,
) -> Result<ReplayOutcome, FuzzError> {
    check_family(opts, r)?;
    let settings = replay_settings(opts, r);
    with_target(spec, opts, &settings, Some(device), |t| {
        Ok(replay_with(t, r))
    })
}

fn minimize_with(
    target: &mut dyn Target,
    opts: &Options,
    settings: &Settings,
    r: &Replay,
) -> Option<Replay> {
    let family = target.family();
    let (trial, _) = engine::replay_once(target, &r.steps);
    let fault = trial.fault.clone()?;
    let cut: Vec<Step> = r.steps.iter().take(fault.step + 1).cloned().collect();
    let sequence = r.finding.as_ref().map_or(0, |f| f.sequence);
    let found = engine::minimise(
        target,
        cut,
        &[],
        &fault,
        opts.minimize_runs,
        sequence,
        &trial,
        opts.duration.map(|d| std::time::Instant::now() + d),
    );
    let mut out = replay_of(&found, family, opts.layer, &opts.dut.to_string(), settings);
    if let (Some(new), Some(old)) = (out.finding.as_mut(), r.finding.as_ref()) {
        new.original_steps = old.original_steps.max(new.original_steps);
    }
    Some(out)
}

/// Minimises the sequence of `r` against `opts.dut`: None when it does not fail any more.
pub fn minimize(spec: &Spec, opts: &Options, r: &Replay) -> Result<Option<Replay>, FuzzError> {
    check_family(opts, r)?;
    let settings = replay_settings(opts, r);
    with_target(spec, opts, &settings, None, |t| {
        Ok(minimize_with(t, opts, &settings, r))
    })
}

/// [`minimize`] on a link of the caller's.
pub fn minimize_on(
    spec: &Spec,
    opts: &Options,
    r: &Replay,
    link: Box<dyn Link>,
) -> Result<Option<Replay>, FuzzError> {
    minimize_on_device(spec, opts, r, Device::Link(link))
}

/// [`minimize`] on a device of the caller's (a link, a cyclic-exchange peer, a PROFINET
/// wire).
pub fn minimize_on_device(
    spec: &Spec,
    opts: &Options,
    r: &Replay,
    device: Device,
) -> Result<Option<Replay>, FuzzError> {
    check_family(opts, r)?;
    let settings = replay_settings(opts, r);
    with_target(spec, opts, &settings, Some(device), |t| {
        Ok(minimize_with(t, opts, &settings, r))
    })
}
