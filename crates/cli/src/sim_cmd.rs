//! `drivespec sim`: argument parsing and printing around `drivespec_sim`.

use crate::{Context, Outcome};
use anyhow::{bail, Context as _, Result};
use drivespec_cyclic::Server;
use drivespec_sim::{DeviceOptions, Faults, Options, ServedDevice, Stats, Stop};
use drivespec_spec::FamilyId;
use std::io::Write;
use std::net::TcpListener;
use std::sync::Arc;
use std::time::Duration;

/// Serve a reference model to masters and PLC drivers on TCP, a pseudo-terminal, stdio or
/// (psd4xx) as a PROFINET IO device on a network interface.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("transport").required(true).args(["listen", "pty", "stdio", "profinet"])))]
pub struct SimArgs {
    /// Device family: hpd (serial protocol), psd4xx or psx3xx (cyclic-exchange protocol).
    device: String,
    /// Device model, matched forgivingly.
    #[arg(long)]
    model: Option<String>,
    /// psx3xx: the drive's brake option, snap or holding (manual 5.11–5.13); the model must be
    /// one the spec offers it for.
    #[arg(long, value_name = "KIND")]
    brake: Option<String>,
    /// Serial address of the drive (HPD Pr27).
    #[arg(long, default_value_t = 0, visible_alias = "address")]
    addr: u8,
    /// Baud-rate code (HPD Pr26); default: the delivery value.
    #[arg(long, value_name = "C")]
    baud_code: Option<u8>,
    /// Listen on tcp:HOST:PORT, one client at a time (port 0: any free port; printed).
    #[arg(long, value_name = "tcp:HOST:PORT")]
    listen: Option<String>,
    /// Create a pseudo-terminal and print its path, for serial clients.
    #[arg(long)]
    pty: bool,
    /// Requests on stdin, answers on stdout (an `exec:` device under test).
    #[arg(long)]
    stdio: bool,
    /// psd4xx: a PROFINET IO device (DCP, PNIO-CM, RT class 1) on this network interface;
    /// needs root or cap_net_raw,cap_net_admin.
    #[arg(long, value_name = "IFACE")]
    profinet: Option<String>,
    /// NameOfStation of the PROFINET IO device (--profinet).
    #[arg(
        long,
        value_name = "NAME",
        default_value = "drivespec-sim",
        requires = "profinet"
    )]
    name: String,
    /// Probability (0–1) that an answer is not sent.
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    drop_answers: f64,
    /// Probability (0–1) that an answer with a checksum is sent with a wrong one (hpd).
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    corrupt_checksums: f64,
    /// Probability (0–1) that an input image is sent with one bit flipped (psd4xx, psx3xx).
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    corrupt_images: f64,
    /// Extra delay of every answer, in ms.
    #[arg(long, value_name = "D", default_value_t = 0.0)]
    delay_ms: f64,
    /// Seed of the fault decisions.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Log every byte received and sent, with the time and the message in words (stderr).
    #[arg(long)]
    log: bool,
    /// Take bytes whatever bit rate the client set on the pseudo-terminal.
    #[arg(long)]
    any_bit_rate: bool,
    /// Stop after this many seconds.
    #[arg(long, value_name = "S")]
    time_limit: Option<f64>,
}

/// Runs `drivespec sim`.
pub fn run(args: SimArgs, ctx: &Context) -> Result<Outcome> {
    let Some(family) = FamilyId::parse(&args.device) else {
        bail!("unknown device {:?}: hpd, psd4xx or psx3xx", args.device);
    };
    if !(args.delay_ms.is_finite() && args.delay_ms >= 0.0) {
        bail!("--delay-ms {}: a time in ms, 0 or more", args.delay_ms);
    }
    let time_limit = match args.time_limit {
        Some(s) => match Duration::try_from_secs_f64(s) {
            Ok(d) if !d.is_zero() => Some(d),
            _ => bail!("--time-limit {s}: a time in seconds, more than 0"),
        },
        None => None,
    };
    let faults = Faults {
        drop_answers: args.drop_answers,
        corrupt_checksums: args.corrupt_checksums,
        corrupt_images: args.corrupt_images,
        delay_us: (args.delay_ms * 1000.0).round() as u64,
        seed: args.seed,
    };
    faults.check()?;
    if let (Some(text), false) = (&args.brake, family == FamilyId::Psx3xx) {
        bail!("--brake {text}: the brake is an option of the psx3xx drives, not of {family}");
    }
    if let Some(iface) = &args.profinet {
        return run_profinet(&args, ctx, family, iface, faults, time_limit);
    }
    if family != FamilyId::Hpd {
        return run_cyclic(&args, ctx, family, faults, time_limit);
    }
    if args.corrupt_images > 0.0 {
        bail!("--corrupt-images is for the cyclic-exchange families (psd4xx, psx3xx); hpd takes --corrupt-checksums");
    }
    let spec = Arc::new(ctx.spec()?);
    let device = drivespec_sim::device(
        spec,
        family,
        &DeviceOptions {
            model: args.model,
            address: args.addr,
            baud_code: args.baud_code,
        },
    )?;
    let opts = Options {
        faults,
        log: args.log,
        time_limit,
        max_clients: None,
        check_bit_rate: !args.any_bit_rate,
    };
    let stop = Stop::new();
    let stderr = std::io::stderr();
    let mut log = stderr.lock();
    let banner = |log: &mut dyn Write, device: &dyn ServedDevice, on: &str| {
        let _ = writeln!(
            log,
            "drivespec sim: {} on {on}; {}",
            device.describe(),
            faults.describe()
        );
    };
    let stats = if let Some(listen) = &args.listen {
        let Some(addr) = listen.strip_prefix("tcp:") else {
            bail!("--listen {listen:?}: expected tcp:HOST:PORT (e.g. tcp:127.0.0.1:4000)");
        };
        let listener =
            TcpListener::bind(addr).with_context(|| format!("cannot listen on tcp:{addr}"))?;
        let local = listener
            .local_addr()
            .with_context(|| format!("cannot listen on tcp:{addr}"))?;
        // The one line on stdout: what a client connects to.
        print_line(&local.to_string());
        banner(&mut log, device.as_ref(), &format!("tcp:{local}"));
        let _ = writeln!(
            log,
            "drivespec sim: test it with: drivespec conform {family} --dut tcp:{local}"
        );
        drivespec_sim::serve_tcp(listener, device, &opts, &stop, &mut log)?
    } else if args.pty {
        serve_pty(device, &opts, &stop, &mut log, family, banner)?
    } else {
        banner(&mut log, device.as_ref(), "stdin/stdout");
        drivespec_sim::serve_stdio(device, &opts, &stop, &mut log)?
    };
    print_stats(&mut log, &stats);
    Ok(Outcome::Pass)
}

/// `drivespec sim psd4xx --profinet IFACE`.
fn run_profinet(
    args: &SimArgs,
    ctx: &Context,
    family: FamilyId,
    iface: &str,
    faults: Faults,
    time_limit: Option<Duration>,
) -> Result<Outcome> {
    if family != FamilyId::Psd4xx {
        bail!(
            "--profinet is for psd4xx (a PROFINET IO device); {family} has no PROFINET interface"
        );
    }
    let Faults {
        drop_answers,
        corrupt_checksums,
        corrupt_images,
        delay_us,
        ..
    } = faults;
    if drop_answers > 0.0 || corrupt_checksums > 0.0 || corrupt_images > 0.0 || delay_us > 0 {
        bail!("--drop-answers, --corrupt-* and --delay-ms are for the drivespec-cyclic/1 transports, not --profinet");
    }
    if args.baud_code.is_some() || args.addr != 0 || args.any_bit_rate {
        bail!("--baud-code, --addr and --any-bit-rate are for hpd (serial line)");
    }
    let spec = ctx.spec()?;
    crate::sim_profinet::run(
        &spec,
        &crate::sim_profinet::ProfinetSim {
            iface,
            name: &args.name,
            model: args.model.as_deref(),
            log: args.log,
            time_limit,
        },
    )
}

/// `drivespec sim psd4xx|psx3xx`: the family's cyclic server on tcp, a pty or stdio.
fn run_cyclic(
    args: &SimArgs,
    ctx: &Context,
    family: FamilyId,
    faults: Faults,
    time_limit: Option<Duration>,
) -> Result<Outcome> {
    if args.corrupt_checksums > 0.0 {
        bail!("--corrupt-checksums is for hpd; the cyclic-exchange protocol has no checksums (use --corrupt-images)");
    }
    if args.baud_code.is_some() || args.addr != 0 || args.any_bit_rate {
        bail!("--baud-code, --addr and --any-bit-rate are for hpd (serial line)");
    }
    let spec = ctx.spec()?;
    let brake = match &args.brake {
        Some(text) => Some(crate::conform_cmd::brake_kind(&spec, text)?),
        None => None,
    };
    let opts = Options {
        faults,
        log: args.log,
        time_limit,
        max_clients: None,
        check_bit_rate: false,
    };
    drivespec_sim::with_cyclic_server(
        &spec,
        family,
        args.model.as_deref(),
        brake,
        |server, name| serve_cyclic(args, family, server, name, &opts),
    )?
}

/// Serves `server` on the transport `args` names until stopped.
fn serve_cyclic(
    args: &SimArgs,
    family: FamilyId,
    server: &mut Server<'_>,
    name: &str,
    opts: &Options,
) -> Result<Outcome> {
    let faults = opts.faults;
    let stop = Stop::new();
    let stderr = std::io::stderr();
    let mut log = stderr.lock();
    let banner = |log: &mut dyn Write, on: &str| {
        let _ = writeln!(
            log,
            "drivespec sim: {name} on {on} (drivespec-cyclic/1); {}",
            faults.describe()
        );
    };
    let stats = if let Some(listen) = &args.listen {
        let Some(addr) = listen.strip_prefix("tcp:") else {
            bail!("--listen {listen:?}: expected tcp:HOST:PORT (e.g. tcp:127.0.0.1:4000)");
        };
        let listener =
            TcpListener::bind(addr).with_context(|| format!("cannot listen on tcp:{addr}"))?;
        let local = listener
            .local_addr()
            .with_context(|| format!("cannot listen on tcp:{addr}"))?;
        print_line(&local.to_string());
        banner(&mut log, &format!("tcp:{local}"));
        let _ = writeln!(
            log,
            "drivespec sim: test it with: drivespec conform {family} --dut tcp:{local}{}",
            options_of(args)
        );
        drivespec_sim::serve_cyclic_tcp(listener, server, opts, &stop, &mut log)?
    } else if args.pty {
        serve_cyclic_pty(
            server,
            opts,
            &stop,
            &mut log,
            family,
            &options_of(args),
            banner,
        )?
    } else {
        banner(&mut log, "stdin/stdout");
        drivespec_sim::serve_cyclic_stdio(server, opts, &stop, &mut log)?
    };
    let _ = writeln!(
        log,
        "drivespec sim: served {:.1} s{}: {} byte(s) received, {} reply line(s) sent, {} dropped, {} image(s) corrupted, {} lost",
        stats.wall_us as f64 / 1e6,
        if stats.clients > 0 {
            format!(", {} client(s)", stats.clients)
        } else {
            String::new()
        },
        stats.received,
        stats.sent,
        stats.dropped,
        stats.corrupted,
        stats.lost
    );
    Ok(Outcome::Pass)
}

/// The `--model` and `--brake` a conformance run against the served drive needs (a brake
/// is declared, not read from the device: PSx3xx manual 5.11–5.13).
fn options_of(args: &SimArgs) -> String {
    match (&args.brake, &args.model) {
        (Some(b), Some(m)) => format!(" --model {m} --brake {b}"),
        (Some(b), None) => format!(" --brake {b}"),
        _ => String::new(),
    }
}

#[cfg(unix)]
fn serve_cyclic_pty(
    server: &mut Server<'_>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
    family: FamilyId,
    options: &str,
    banner: impl Fn(&mut dyn Write, &str),
) -> Result<Stats> {
    let pty = drivespec_sim::Pty::open(None)?;
    print_line(pty.path());
    banner(log, pty.path());
    let _ = writeln!(
        log,
        "drivespec sim: test it with: drivespec conform {family} --dut serial:{}{options}",
        pty.path()
    );
    Ok(drivespec_sim::serve_cyclic_pty(
        &pty, server, opts, stop, log,
    )?)
}

#[cfg(not(unix))]
fn serve_cyclic_pty(
    _server: &mut Server<'_>,
    _opts: &Options,
    _stop: &Stop,
    _log: &mut dyn Write,
    _family: FamilyId,
    _options: &str,
    _banner: impl Fn(&mut dyn Write, &str),
) -> Result<Stats> {
    bail!("--pty needs a Unix system (pseudo-terminals); use --listen or --stdio")
}

#[cfg(unix)]
fn serve_pty(
    device: Box<dyn ServedDevice>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
    family: FamilyId,
    banner: impl Fn(&mut dyn Write, &dyn ServedDevice, &str),
) -> Result<Stats> {
    let pty = drivespec_sim::Pty::open(device.bit_rate())?;
    // The one line on stdout: the path a serial client opens.
    print_line(pty.path());
    banner(log, device.as_ref(), pty.path());
    let _ = writeln!(
        log,
        "drivespec sim: test it with: drivespec conform {family} --dut serial:{}",
        pty.path()
    );
    Ok(drivespec_sim::serve_pty(&pty, device, opts, stop, log)?)
}

#[cfg(not(unix))]
fn serve_pty(
    _device: Box<dyn ServedDevice>,
    _opts: &Options,
    _stop: &Stop,
    _log: &mut dyn Write,
    _family: FamilyId,
    _banner: impl Fn(&mut dyn Write, &dyn ServedDevice, &str),
) -> Result<Stats> {
    bail!("--pty needs a Unix system (pseudo-terminals); use --listen or --stdio")
}

/// One line on stdout, flushed; a closed stdout (`| head -1`) is not an error.
fn print_line(text: &str) {
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{text}");
    let _ = out.flush();
}

fn print_stats(log: &mut dyn Write, s: &Stats) {
    let _ = writeln!(
        log,
        "drivespec sim: served {:.1} s{}: {} byte(s) received ({} refused at a wrong bit rate), {} message(s) sent, {} dropped, {} corrupted, {} lost",
        s.wall_us as f64 / 1e6,
        if s.clients > 0 {
            format!(", {} client(s)", s.clients)
        } else {
            String::new()
        },
        s.received,
        s.refused,
        s.sent,
        s.dropped,
        s.corrupted,
        s.lost
    );
}
