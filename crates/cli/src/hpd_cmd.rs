//! `drivespec decode|encode|plc hpd …`: the HPD serial protocol and pico-PLC from the command line.

use crate::{input, json, Context, Format, Outcome};
use anyhow::{anyhow, bail, Result};
use clap::{Args, Subcommand, ValueEnum};
use drivespec_hpd::explain::{explain, Explained};
use drivespec_hpd::params::Target;
use drivespec_hpd::plc::{PlcCodec, Program};
use drivespec_hpd::{Data, Exchange, FrameRules, LineDecoder, LineEvent, Message, Pairer};
use drivespec_spec::hex::{parse_hex, parse_int, to_hex};
use drivespec_spec::{Family, FamilyId, Spec};
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `drivespec decode hpd`.
#[derive(Args)]
pub struct DecodeArgs {
    /// Bytes in hex: `7E 80 01 54 D5`, `7E800154D5` or `[$7E][$80][$01][$54][$D5]`.
    hex: Vec<String>,
    /// Decode a whole line capture from FILE (`-` for standard input) instead.
    #[arg(long, value_name = "FILE", conflicts_with = "hex")]
    stream: Option<PathBuf>,
    /// How the capture is written: raw bytes or hex text (auto: hex when it reads as hex).
    #[arg(long, value_enum, default_value_t = StreamFormat::Auto)]
    input_format: StreamFormat,
}

/// How a `--stream` file holds its bytes.
#[derive(Clone, Copy, ValueEnum)]
enum StreamFormat {
    /// Hex text if the whole file reads as hex, else raw bytes.
    Auto,
    /// Raw bytes as on the line.
    Raw,
    /// Hex text.
    Hex,
}

/// Everything found on the line, in order.
#[derive(Serialize)]
struct Decoded {
    frames: Vec<FrameOut>,
    discarded: Vec<DiscardOut>,
    exchanges: Vec<ExchangeOut>,
}

#[derive(Serialize)]
struct FrameOut {
    offset: u64,
    bytes: String,
    #[serde(flatten)]
    message: Explained,
}

#[derive(Serialize)]
struct DiscardOut {
    offset: u64,
    bytes: String,
    reason: String,
}

#[derive(Serialize)]
struct ExchangeOut {
    request: u64,
    answer: Option<u64>,
    verdict: String,
}

/// Runs `drivespec decode hpd`.
pub fn decode(args: DecodeArgs, ctx: &Context) -> Result<Outcome> {
    let bytes = match &args.stream {
        Some(path) => read_stream(path, args.input_format)?,
        None if args.hex.is_empty() => bail!("give the bytes in hex, or --stream FILE"),
        None => parse_hex(&args.hex.join(" ")).map_err(|e| anyhow!("bad hex: {e}"))?,
    };
    let spec = ctx.spec()?;
    let family = spec.family(FamilyId::Hpd);
    let rules = FrameRules::from_spec(&spec)?;
    let plc = PlcCodec::from_spec(&spec);
    let mut pairer = Pairer::from_spec(&spec)?;
    let mut out = Decoded {
        frames: Vec::new(),
        discarded: Vec::new(),
        exchanges: Vec::new(),
    };
    let mut events = Vec::new();
    let mut decoder = LineDecoder::new(rules.clone());
    decoder.feed(&bytes, None, &mut |e| events.push(e));
    decoder.finish(&mut |e| events.push(e));
    let slice = |offset: u64, len: usize| {
        let start = usize::try_from(offset).unwrap_or(usize::MAX);
        to_hex(bytes.get(start..start.saturating_add(len)).unwrap_or(&[]))
    };
    let mut request = None;
    for event in events {
        match event {
            LineEvent::Frame(f) => {
                pairer.push(f, &mut |x| out.exchanges.push(exchange_out(&x)));
                let message = explain(family, &rules, plc.as_ref(), &f.message, request.as_ref());
                if f.message.is_request() {
                    request = Some(f.message);
                }
                out.frames.push(FrameOut {
                    offset: f.offset,
                    bytes: slice(f.offset, f.len),
                    message,
                });
            }
            LineEvent::Discarded(d) => {
                out.discarded.push(DiscardOut {
                    offset: d.offset,
                    bytes: slice(d.offset, d.len),
                    reason: d.reason.to_string(),
                });
            }
        }
    }
    pairer.flush(&mut |x| out.exchanges.push(exchange_out(&x)));
    match ctx.format {
        Format::Json => say!("{}", json(&out))?,
        Format::Text => say_raw!("{}", decoded_text(&out, args.stream.is_some()))?,
    }
    let breaches = out.frames.iter().any(|f| f.message.breaks.is_some());
    Ok(if out.discarded.is_empty() && !breaches {
        Outcome::Pass
    } else {
        Outcome::Fail
    })
}

fn exchange_out(x: &Exchange) -> ExchangeOut {
    match x {
        Exchange::Answered { request, answer } => ExchangeOut {
            request: request.offset,
            answer: Some(answer.offset),
            verdict: "answered".into(),
        },
        Exchange::Unanswered { request } => ExchangeOut {
            request: request.offset,
            answer: None,
            verdict: "unanswered".into(),
        },
        Exchange::Broadcast { request } => ExchangeOut {
            request: request.offset,
            answer: None,
            verdict: "broadcast, no answer expected".into(),
        },
        Exchange::Unexpected {
            answer,
            request,
            reason,
        } => ExchangeOut {
            request: request.map_or(answer.offset, |r| r.offset),
            answer: Some(answer.offset),
            verdict: format!("unexpected answer: {reason:?}"),
        },
    }
}

fn decoded_text(out: &Decoded, stream: bool) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let mut items: Vec<(u64, String)> = Vec::new();
    for f in &out.frames {
        let m = &f.message;
        let mut fields = format!("cmd {} {}, addr {}", m.cmd, m.kind, m.addr);
        if let Some(lun) = m.lun {
            let _ = write!(fields, ", lun {lun}");
        }
        if let Some(par) = m.par {
            let _ = write!(fields, ", par {par:#04x}");
        }
        if let Some(d) = &m.data {
            let _ = write!(fields, ", data {d}");
        }
        if m.lun.is_some() {
            fields.push_str(", checksum ok");
        }
        let breach = m.breaks.as_ref().map_or(String::new(), |b| {
            format!("    breaks {}: {}\n", b.requirement, b.text)
        });
        items.push((
            f.offset,
            format!(
                "@{}  {}\n    {}\n    {}\n{breach}",
                f.offset, f.bytes, m.summary, fields
            ),
        ));
    }
    for d in &out.discarded {
        items.push((
            d.offset,
            format!("@{}  {}\n    discarded: {}\n", d.offset, d.bytes, d.reason),
        ));
    }
    items.sort_by_key(|(o, _)| *o);
    for (_, text) in items {
        s.push_str(&text);
    }
    if stream {
        let count = |v: &str| {
            out.exchanges
                .iter()
                .filter(|x| x.verdict.starts_with(v))
                .count()
        };
        let _ = writeln!(
            s,
            "{} frames, {} discarded; {} answered, {} unanswered, {} broadcasts, {} unexpected answers",
            out.frames.len(),
            out.discarded.len(),
            count("answered"),
            count("unanswered"),
            count("broadcast"),
            count("unexpected")
        );
    }
    s
}

fn read_stream(path: &std::path::Path, format: StreamFormat) -> Result<Vec<u8>> {
    let raw = input::read_bytes(path, input::MAX_STREAM)?;
    let as_hex = || {
        std::str::from_utf8(&raw)
            .ok()
            .and_then(|t| parse_hex(t).ok())
    };
    Ok(match format {
        StreamFormat::Raw => raw,
        StreamFormat::Hex => {
            let text = std::str::from_utf8(&raw)
                .map_err(|_| anyhow!("{} is not hex text", path.display()))?;
            parse_hex(text).map_err(|e| anyhow!("{}: bad hex: {e}", path.display()))?
        }
        StreamFormat::Auto => match as_hex() {
            Some(bytes) => bytes,
            None => raw,
        },
    })
}

/// Arguments of `drivespec encode hpd`.
#[derive(Args)]
pub struct EncodeArgs {
    #[command(subcommand)]
    what: EncodeWhat,
}

#[derive(Subcommand)]
enum EncodeWhat {
    /// Read a parameter: `read --addr 1 Pr7` (`Pr64:65` for a double word).
    Read {
        /// Drive address (Pr27).
        #[arg(long, default_value_t = 0)]
        addr: u8,
        /// Parameter.
        param: String,
    },
    /// Write a parameter with the value as the keypad shows it: `write --addr 3 Pr33=25.3`.
    Write {
        /// Drive address (Pr27).
        #[arg(long, default_value_t = 0)]
        addr: u8,
        /// `PARAM=VALUE`.
        assignment: String,
    },
    /// Change one bit: `bit --addr 0 b99.14=1`.
    Bit {
        /// Drive address (Pr27).
        #[arg(long, default_value_t = 0)]
        addr: u8,
        /// `bNN.Y=0|1`.
        assignment: String,
    },
    /// Read PLC program bytes: `plc-read --addr 0 --at 0 --lun 4`.
    PlcRead {
        /// Drive address (Pr27).
        #[arg(long, default_value_t = 0)]
        addr: u8,
        /// PLC byte address.
        #[arg(long, default_value = "0", value_parser = parse_u8)]
        at: u8,
        /// Bytes to read (1…4).
        #[arg(long, default_value_t = 4)]
        lun: u8,
    },
    /// Write PLC instructions: `plc-write --addr 0 --at 0 'LD 90.4'`.
    PlcWrite {
        /// Drive address (Pr27).
        #[arg(long, default_value_t = 0)]
        addr: u8,
        /// PLC byte address.
        #[arg(long, default_value = "0", value_parser = parse_u8)]
        at: u8,
        /// Listing lines (at most 4 bytes in all).
        listing: Vec<String>,
    },
    /// Write a parameter on every drive: `broadcast Pr5=100`.
    Broadcast {
        /// `PARAM=VALUE`.
        assignment: String,
    },
}

fn parse_u8(s: &str) -> std::result::Result<u8, String> {
    parse_int(s).map_err(|_| format!("{s:?} is not a byte (0…255 or 0x00…0xFF)"))
}

/// Runs `drivespec encode hpd`.
pub fn encode(args: EncodeArgs, ctx: &Context) -> Result<Outcome> {
    let spec = ctx.spec()?;
    let family = spec.family(FamilyId::Hpd);
    let rules = FrameRules::from_spec(&spec)?;
    let msg = build(&spec, family, args.what)?;
    let bytes = msg.to_bytes(&rules)?;
    match ctx.format {
        Format::Text => say!("{}", to_hex(&bytes))?,
        Format::Json => {
            #[derive(Serialize)]
            struct Out {
                bytes: String,
                message: Explained,
            }
            let message = explain(
                family,
                &rules,
                PlcCodec::from_spec(&spec).as_ref(),
                &msg,
                None,
            );
            say!(
                "{}",
                json(&Out {
                    bytes: to_hex(&bytes),
                    message
                })
            )?;
        }
    }
    Ok(Outcome::Pass)
}

fn split_assignment(text: &str) -> Result<(&str, &str)> {
    text.split_once('=')
        .ok_or_else(|| anyhow!("expected PARAM=VALUE, found {text:?}"))
}

fn build(spec: &Spec, family: &Family, what: EncodeWhat) -> Result<Message> {
    Ok(match what {
        EncodeWhat::Read { addr, param } => Target::parse(family, &param)?.read(addr)?,
        EncodeWhat::Write { addr, assignment } | EncodeWhat::Bit { addr, assignment } => {
            let (name, value) = split_assignment(&assignment)?;
            Target::parse(family, name)?.write(family, addr, value)?
        }
        EncodeWhat::Broadcast { assignment } => {
            let (name, value) = split_assignment(&assignment)?;
            match Target::parse(family, name)?.write(family, 0, value)? {
                Message::WriteParam { par, data, .. } => Message::Broadcast { par, data },
                _ => bail!("a broadcast writes a whole parameter, not a bit"),
            }
        }
        EncodeWhat::PlcRead { addr, at, lun } => {
            let codec =
                PlcCodec::from_spec(spec).ok_or_else(|| anyhow!("the spec has no PLC table"))?;
            in_plc_area(&codec, at, usize::from(lun))?;
            Message::ReadPlc { addr, lun, par: at }
        }
        EncodeWhat::PlcWrite { addr, at, listing } => {
            let codec =
                PlcCodec::from_spec(spec).ok_or_else(|| anyhow!("the spec has no PLC table"))?;
            let program = codec.parse_listing(&listing.join("\n"))?;
            let bytes = codec.encode_program(&program)?;
            let data = Data::new(&bytes).ok_or_else(|| {
                anyhow!(
                    "a PLC write carries 1 to 4 bytes, the listing makes {}",
                    bytes.len()
                )
            })?;
            in_plc_area(&codec, at, bytes.len())?;
            Message::WritePlc {
                addr,
                par: at,
                data,
            }
        }
    })
}

/// Refuses PLC bytes `at`…`at + len − 1` outside the PLC area (3.8.1: 0x00–0x7F).
fn in_plc_area(codec: &PlcCodec, at: u8, len: usize) -> Result<()> {
    match codec.outside_area(at, len) {
        Some(outside) => bail!("{outside} (3.8.1)"),
        None => Ok(()),
    }
}

/// Arguments of `drivespec plc hpd`.
#[derive(Args)]
pub struct PlcArgs {
    #[command(subcommand)]
    what: PlcWhat,
}

#[derive(Subcommand)]
enum PlcWhat {
    /// Assemble a listing file (`-` for standard input) into program bytes.
    Asm {
        /// Listing, one instruction per line; `;` starts a comment.
        file: PathBuf,
    },
    /// Disassemble program bytes given in hex.
    Disasm {
        /// Program bytes in hex.
        hex: Vec<String>,
    },
    /// The default program (appendix G) with what it reads and drives.
    Default,
}

#[derive(Serialize)]
struct ProgramOut {
    bytes: String,
    instructions: Vec<InstrOut>,
    issues: Vec<String>,
    reads: Vec<Named>,
    writes: Vec<Named>,
}

/// A bit or word with its name from the spec.
#[derive(Serialize)]
struct Named {
    id: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    name: Option<String>,
}

#[derive(Serialize)]
struct InstrOut {
    address: usize,
    listing: String,
    bytes: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    comment: Option<String>,
}

/// Runs `drivespec plc hpd`.
pub fn plc(args: PlcArgs, ctx: &Context) -> Result<Outcome> {
    let spec = ctx.spec()?;
    let codec = PlcCodec::from_spec(&spec).ok_or_else(|| anyhow!("the spec has no PLC table"))?;
    let is_default = matches!(args.what, PlcWhat::Default);
    let (program, bytes) = match args.what {
        PlcWhat::Asm { file } => {
            let text = input::read_text(&file, input::MAX_TEXT)?;
            let program = codec.parse_listing(&text)?;
            let bytes = codec.encode_program(&program)?;
            (program, bytes)
        }
        PlcWhat::Disasm { hex } => {
            let bytes = parse_hex(&hex.join(" ")).map_err(|e| anyhow!("bad hex: {e}"))?;
            (codec.decode_program(&bytes)?, bytes)
        }
        PlcWhat::Default => {
            let g = &spec
                .family(FamilyId::Hpd)
                .hpd()
                .ok_or_else(|| anyhow!("the spec has no HPD protocol table"))?
                .default_program;
            let listing: String = g.iter().map(|l| format!("{}\n", l.listing)).collect();
            let program = codec.parse_listing(&listing)?;
            let bytes = codec.encode_program(&program)?;
            (program, bytes)
        }
    };
    let comments = match spec.family(FamilyId::Hpd).hpd() {
        Some(p) if is_default => p
            .default_program
            .iter()
            .map(|l| (usize::from(l.address), l.comment.clone()))
            .collect(),
        _ => Vec::new(),
    };
    let mut out = program_out(&codec, &program, &bytes, spec.family(FamilyId::Hpd));
    for i in &mut out.instructions {
        i.comment = comments
            .iter()
            .find(|(a, _)| *a == i.address)
            .and_then(|(_, c)| c.clone());
    }
    match ctx.format {
        Format::Json => say!("{}", json(&out))?,
        Format::Text => {
            for i in &out.instructions {
                match &i.comment {
                    Some(c) => say!(
                        "{:02X}: {:<14} ; {:<11} ; {c}",
                        i.address,
                        i.listing,
                        i.bytes
                    )?,
                    None => say!("{:02X}: {:<14} ; {}", i.address, i.listing, i.bytes)?,
                }
            }
            say!("{} bytes: {}", bytes.len(), out.bytes)?;
            let names = |list: &[Named]| -> String {
                list.iter()
                    .map(|n| match &n.name {
                        Some(name) => format!("{} ({name})", n.id),
                        None => n.id.clone(),
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            say!("reads:  {}", names(&out.reads))?;
            say!("drives: {}", names(&out.writes))?;
            for issue in &out.issues {
                say!("warning: {issue}")?;
            }
        }
    }
    Ok(if out.issues.is_empty() {
        Outcome::Pass
    } else {
        Outcome::Fail
    })
}

fn program_out(codec: &PlcCodec, program: &Program, bytes: &[u8], family: &Family) -> ProgramOut {
    let instructions = program
        .instrs
        .iter()
        .map(|(address, instr)| {
            let len = codec.length(instr.code).unwrap_or(2);
            InstrOut {
                address: *address,
                listing: codec.format(instr),
                bytes: to_hex(bytes.get(*address..address + len).unwrap_or(&[])),
                comment: None,
            }
        })
        .collect();
    let issues = codec
        .check(program)
        .iter()
        .map(ToString::to_string)
        .collect();
    let fx = codec.effects(program);
    let named = |ids: Vec<String>| {
        ids.into_iter()
            .map(|id| Named {
                name: name_of(family, &id),
                id,
            })
            .collect()
    };
    ProgramOut {
        bytes: to_hex(bytes),
        instructions,
        issues,
        reads: named(fx.reads),
        writes: named(fx.writes),
    }
}

/// The spec's name of `b40.4` (the bit's name) or `Pr5` (the parameter's name).
fn name_of(family: &Family, id: &str) -> Option<String> {
    match id.strip_prefix('b').and_then(|r| r.split_once('.')) {
        Some((n, y)) => {
            let p = family.parameter(n)?;
            let bit: u32 = y.parse().ok()?;
            family
                .bitfields_of(&p.id)
                .find_map(|b| b.bit(bit))
                .map(|b| b.name.clone())
        }
        None => family.parameter(id).map(|p| p.name.clone()),
    }
}
