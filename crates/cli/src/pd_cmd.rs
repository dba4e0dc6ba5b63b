//! `drivespec decode|encode psd4xx|psx3xx …`: process images field by field.

use crate::{input, json, Context, Format, Outcome};
use anyhow::{anyhow, Result};
use clap::Args;
use drivespec_positioner::ByteOrder;
use drivespec_spec::hex::{parse_hex, parse_int, to_hex};
use drivespec_spec::FamilyId;
use std::path::PathBuf;

/// Which image: `--out` (controller → drive) or `--in` (drive → controller).
#[derive(Args)]
#[group(required = true, multiple = false)]
pub struct Dir {
    /// An output image (controller → drive).
    #[arg(long)]
    out: bool,
    /// An input image (drive → controller).
    #[arg(long = "in")]
    input: bool,
}

/// Arguments of `drivespec decode psd4xx`.
#[derive(Args)]
pub struct Psd4xxDecode {
    #[command(flatten)]
    dir: Dir,
    /// Byte order of the image (default: the manual's).
    #[arg(long)]
    byte_order: Option<ByteOrder>,
    /// The image in hex (14 bytes out, 16 bytes in).
    hex: Vec<String>,
}

/// Arguments of `drivespec encode psd4xx`.
#[derive(Args)]
pub struct Psd4xxEncode {
    #[command(flatten)]
    dir: Dir,
    /// Byte order of the image (default: the manual's).
    #[arg(long)]
    byte_order: Option<ByteOrder>,
    /// Control word (output).
    #[arg(long, value_parser = number)]
    control: Option<i64>,
    /// Target value (output).
    #[arg(long, value_parser = number, allow_hyphen_values = true)]
    target: Option<i64>,
    /// Status word (input).
    #[arg(long, value_parser = number)]
    status: Option<i64>,
    /// Current speed in rpm (input).
    #[arg(long, value_parser = number, allow_hyphen_values = true)]
    speed: Option<i64>,
    /// Actual position (input).
    #[arg(long, value_parser = number, allow_hyphen_values = true)]
    actual: Option<i64>,
    /// PKW request (`read:44`, `write:44=5`, `read:13[2]`) or reply (`value:44=5`, `error:44=2`).
    #[arg(long)]
    pkw: Option<String>,
    /// Any other field as `NAME=VALUE`.
    fields: Vec<String>,
}

/// A number in decimal or 0x hex.
fn number(s: &str) -> std::result::Result<i64, String> {
    parse_int(s).map_err(|_| format!("{s:?} is not a number"))
}

fn psd_rules(
    spec: &drivespec_spec::Spec,
    order: Option<ByteOrder>,
) -> Result<drivespec_psd4xx::Rules> {
    let mut options = drivespec_psd4xx::Options::from_protocol(
        spec.family(FamilyId::Psd4xx)
            .psd4xx()
            .ok_or_else(|| anyhow!("the spec has no PSD4xx protocol table"))?,
    );
    if let Some(o) = order {
        options.byte_order = o;
    }
    Ok(drivespec_psd4xx::Rules::with_options(spec, options)?)
}

fn psd_direction(dir: &Dir) -> drivespec_psd4xx::Direction {
    if dir.out {
        drivespec_psd4xx::Direction::Out
    } else {
        drivespec_psd4xx::Direction::In
    }
}

/// Runs `drivespec decode psd4xx`.
pub fn decode_psd4xx(args: Psd4xxDecode, ctx: &Context) -> Result<Outcome> {
    let bytes = parse_hex(&args.hex.join(" ")).map_err(|e| anyhow!("bad hex: {e}"))?;
    let spec = ctx.spec()?;
    let rules = psd_rules(&spec, args.byte_order)?;
    let e = drivespec_psd4xx::explain(&rules, psd_direction(&args.dir), &bytes)?;
    report(ctx, &e, e.notes.is_empty())
}

/// Runs `drivespec encode psd4xx`.
pub fn encode_psd4xx(args: Psd4xxEncode, ctx: &Context) -> Result<Outcome> {
    let spec = ctx.spec()?;
    let rules = psd_rules(&spec, args.byte_order)?;
    let mut b = drivespec_psd4xx::ImageBuilder::new(&rules, psd_direction(&args.dir));
    let named = [
        ("control", args.control),
        ("target", args.target),
        ("status", args.status),
        ("speed", args.speed),
        ("actual", args.actual),
    ];
    for (name, value) in named {
        if let Some(v) = value {
            b.set(name, v)?;
        }
    }
    for item in &args.fields {
        let (name, value) = item
            .split_once('=')
            .ok_or_else(|| anyhow!("expected NAME=VALUE, found {item:?}"))?;
        b.set(name.trim(), number(value).map_err(|e| anyhow!(e))?)?;
    }
    if let Some(text) = &args.pkw {
        b.pkw(text)?;
    }
    let bytes = b.into_bytes();
    print_image(ctx, &bytes, || {
        Ok(drivespec_psd4xx::explain(
            &rules,
            psd_direction(&args.dir),
            &bytes,
        )?)
    })
}

/// Prints built bytes: hex, or with `--format json` the bytes and their explanation.
fn print_image<E: serde::Serialize>(
    ctx: &Context,
    bytes: &[u8],
    explain: impl FnOnce() -> Result<E>,
) -> Result<Outcome> {
    match ctx.format {
        Format::Text => say!("{}", to_hex(bytes))?,
        Format::Json => {
            #[derive(serde::Serialize)]
            struct Out<E> {
                bytes: String,
                image: E,
            }
            say!(
                "{}",
                json(&Out {
                    bytes: to_hex(bytes),
                    image: explain()?
                })
            )?;
        }
    }
    Ok(Outcome::Pass)
}

/// Arguments of `drivespec decode psx3xx`.
#[derive(Args)]
pub struct Psx3xxDecode {
    #[command(flatten)]
    dir: Dir,
    /// Process-data format of an output image (ISDU 116: 0 time stamp, 1 six bytes, 2 eight bytes).
    #[arg(long, default_value_t = 1)]
    pd_format: u8,
    /// Byte order (default: the IO-Link order of the spec).
    #[arg(long)]
    byte_order: Option<ByteOrder>,
    /// Device model, for model-dependent ranges.
    #[arg(long)]
    model: Option<String>,
    /// Input images, one per line in FILE, to detect the byte order from (the manual's bit-4 trick and other evidence).
    #[arg(long, value_name = "FILE", conflicts_with = "hex")]
    detect_order: Option<PathBuf>,
    /// The image in hex.
    hex: Vec<String>,
}

/// Arguments of `drivespec encode psx3xx`.
#[derive(Args)]
pub struct Psx3xxEncode {
    #[command(flatten)]
    dir: Dir,
    /// Process-data format of an output image (ISDU 116: 0 time stamp, 1 six bytes, 2 eight bytes).
    #[arg(long, default_value_t = 1)]
    pd_format: u8,
    /// Byte order (default: the IO-Link order of the spec).
    #[arg(long)]
    byte_order: Option<ByteOrder>,
    /// Fields as `NAME=VALUE` (`control_word=0x14 target=12000`, `stamp=2000`).
    #[arg(allow_hyphen_values = true)]
    fields: Vec<String>,
}

/// Runs `drivespec decode psx3xx`.
pub fn decode_psx3xx(args: Psx3xxDecode, ctx: &Context) -> Result<Outcome> {
    let spec = ctx.spec()?;
    let family = spec.family(FamilyId::Psx3xx);
    let rules = drivespec_psx3xx::Rules::from_spec(&spec)?;
    let model = match &args.model {
        Some(q) => Some(family.model(q).ok_or_else(|| {
            let known: Vec<&str> = family.models.iter().map(|m| m.id.as_str()).collect();
            anyhow!(
                "unknown psx3xx model {q:?}; known models: {}",
                known.join(", ")
            )
        })?),
        None => None,
    };
    if let Some(path) = &args.detect_order {
        let text = input::read_text(path, input::MAX_TEXT)?;
        let mut images = Vec::new();
        for (i, line) in text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
        {
            images.push(
                parse_hex(line)
                    .map_err(|e| anyhow!("{} line {}: bad hex: {e}", path.display(), i + 1))?,
            );
        }
        let d = drivespec_psx3xx::detect_order(&rules, &images);
        match ctx.format {
            Format::Json => say!("{}", json(&d))?,
            Format::Text => say!("{d}")?,
        }
        return Ok(Outcome::Pass);
    }
    let bytes = parse_hex(&args.hex.join(" ")).map_err(|e| anyhow!("bad hex: {e}"))?;
    let order = args.byte_order.unwrap_or(rules.wire_order());
    let e = if args.dir.out {
        drivespec_psx3xx::explain_output(&rules, args.pd_format, order, model, &bytes)?
    } else {
        drivespec_psx3xx::explain_input(&rules, order, model, &bytes)?
    };
    report(ctx, &e, e.warnings.is_empty())
}

/// Runs `drivespec encode psx3xx`.
pub fn encode_psx3xx(args: Psx3xxEncode, ctx: &Context) -> Result<Outcome> {
    let spec = ctx.spec()?;
    let rules = drivespec_psx3xx::Rules::from_spec(&spec)?;
    let order = args.byte_order.unwrap_or(rules.wire_order());
    if args.dir.out {
        let layout = &rules
            .output(args.pd_format)
            .ok_or_else(|| anyhow!("no process-data format {}", args.pd_format))?
            .layout;
        let fields = drivespec_psx3xx::parse_assignments(&rules, layout, &args.fields)?;
        let image = drivespec_psx3xx::Output::from_fields(&rules, args.pd_format, &fields)?;
        let bytes = image.to_bytes(&rules, order)?;
        print_image(ctx, &bytes, || {
            Ok(drivespec_psx3xx::explain_output(
                &rules,
                args.pd_format,
                order,
                None,
                &bytes,
            )?)
        })
    } else {
        let fields = drivespec_psx3xx::parse_assignments(&rules, rules.input(), &args.fields)?;
        let image = drivespec_psx3xx::Input::from_fields(&rules, &fields)?;
        let bytes = image.to_bytes(&rules, order)?;
        print_image(ctx, &bytes, || {
            Ok(drivespec_psx3xx::explain_input(
                &rules, order, None, &bytes,
            )?)
        })
    }
}

/// Prints an explanation (text ending in one newline, or JSON); fails when it is not `clean`.
fn report<E: std::fmt::Display + serde::Serialize>(
    ctx: &Context,
    e: &E,
    clean: bool,
) -> Result<Outcome> {
    match ctx.format {
        Format::Json => say!("{}", json(e))?,
        Format::Text => say!("{}", e.to_string().trim_end())?,
    }
    Ok(if clean { Outcome::Pass } else { Outcome::Fail })
}
