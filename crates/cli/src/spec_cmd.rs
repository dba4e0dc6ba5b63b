//! `drivespec spec …`: browse and check the machine-readable spec.

use crate::{json, spec_build, Context, Format, Outcome};
use anyhow::{anyhow, bail, Result};
use clap::{Args, Subcommand};
use drivespec_spec::{DeviceModel, Family, FamilyId, Level, Parameter, Ranges, Spec};
use serde::Serialize;
use std::fmt::Write as _;
use std::sync::Arc;

/// Arguments of `drivespec spec`.
#[derive(Args)]
pub struct SpecArgs {
    #[command(subcommand)]
    command: SpecCommand,
}

#[derive(Subcommand)]
enum SpecCommand {
    /// List the parameters of a device family.
    List {
        /// hpd, psd4xx or psx3xx.
        device: String,
        /// Resolve ranges and defaults for this device model.
        #[arg(long)]
        model: Option<String>,
    },
    /// Show one parameter with its ranges, bits and requirements.
    Show {
        /// hpd, psd4xx or psx3xx.
        device: String,
        /// Parameter id, number or name (`63`, `193`, `Pr64`, `Pb99`).
        param: String,
        /// Resolve range and default for this device model.
        #[arg(long)]
        model: Option<String>,
    },
    /// List the device models of a family.
    Models {
        /// hpd, psd4xx or psx3xx.
        device: String,
    },
    /// List the requirements of a family.
    Requirements {
        /// hpd, psd4xx or psx3xx.
        device: String,
        /// Only requirements of this level.
        #[arg(long, value_parser = ["must", "should", "informative"])]
        level: Option<String>,
    },
    /// List the manual's worked examples (golden vectors).
    Examples {
        /// hpd, psd4xx or psx3xx.
        device: String,
    },
    /// List the manual's contradictions and the readings adopted.
    Errata {
        /// hpd, psd4xx or psx3xx.
        device: String,
    },
    /// Write the GSDML device description (XML) of a PROFINET family to stdout or a file.
    Gsdml {
        /// psd4xx (the PROFINET family).
        device: String,
        /// Parameter ranges and defaults of this device model (default: the simulator's).
        #[arg(long)]
        model: Option<String>,
        /// Write to this file instead of stdout.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
    /// Validate the spec and build every suite's cases and every simulator from it; one line
    /// per problem, exit 1 when there is any.
    Check,
}

/// Runs `drivespec spec …`.
pub fn run(args: SpecArgs, ctx: &Context) -> Result<Outcome> {
    let format = ctx.format;
    if let SpecCommand::Check = args.command {
        let loaded = match &ctx.spec_dir {
            Some(dir) if !dir.is_dir() => {
                bail!("cannot read spec folder {}: not a directory", dir.display())
            }
            Some(dir) => Spec::load_dir(dir),
            None => Spec::builtin(),
        };
        return check(loaded, format);
    }
    let spec = ctx.spec()?;
    let out = match &args.command {
        SpecCommand::List { device, model } => {
            let family = family(&spec, device)?;
            let model = model_arg(family, model.as_deref())?;
            list(family, model, format)
        }
        SpecCommand::Show {
            device,
            param,
            model,
        } => {
            let family = family(&spec, device)?;
            let model = model_arg(family, model.as_deref())?;
            let p = family.parameter(param).ok_or_else(|| {
                anyhow!(
                    "{} has no parameter {param:?} (see `drivespec spec list {}`)",
                    family.id(),
                    family.id()
                )
            })?;
            show(family, p, model, format)
        }
        SpecCommand::Models { device } => models(family(&spec, device)?, format),
        SpecCommand::Requirements { device, level } => {
            requirements(family(&spec, device)?, level.as_deref(), format)
        }
        SpecCommand::Examples { device } => examples(family(&spec, device)?, format),
        SpecCommand::Errata { device } => errata(family(&spec, device)?, format),
        SpecCommand::Gsdml { device, model, out } => {
            let family = family(&spec, device)?;
            if family.psd4xx().is_none() {
                bail!(drivespec_spec::gsdml::GsdmlError::NotProfinet(
                    family.id().as_str().to_owned()
                ));
            }
            let query = model
                .as_deref()
                .unwrap_or(drivespec_sim::reference::PSD4XX_DEFAULT_MODEL);
            let model = model_arg(family, Some(query))?
                .ok_or_else(|| anyhow!("unknown {} model {query:?}", family.id()))?;
            let xml = drivespec_spec::gsdml::psd4xx(family, model)?;
            match out {
                Some(path) => {
                    std::fs::write(path, &xml)
                        .map_err(|e| anyhow!("cannot write {}: {e}", path.display()))?;
                    Ok(String::new())
                }
                None => Ok(xml),
            }
        }
        SpecCommand::Check => unreachable_check(),
    }?;
    say_raw!("{out}")?;
    Ok(Outcome::Pass)
}

fn unreachable_check() -> Result<String> {
    bail!("spec check is handled before loading")
}

fn check(loaded: Result<Spec, drivespec_spec::SpecErrors>, format: Format) -> Result<Outcome> {
    #[derive(Serialize)]
    struct Report {
        ok: bool,
        problems: Vec<ProblemJson>,
    }
    #[derive(Serialize)]
    struct ProblemJson {
        file: String,
        record: Option<String>,
        message: String,
    }
    let loaded = loaded.map(Arc::new);
    let (problems, built) = match &loaded {
        Ok(spec) => {
            let steps: Vec<_> = drivespec_psd4xx::step::check_steps(spec)
                .into_iter()
                .chain(drivespec_psx3xx::step::check_steps(spec))
                .chain(drivespec_psx3xx::scenario::check_scenarios(spec))
                .chain(drivespec_conform::psd4xx::check_scenarios(spec))
                .collect();
            // Suites and simulators are built from a spec whose steps read.
            let built = if steps.is_empty() {
                spec_build::problems(spec)
            } else {
                Vec::new()
            };
            (steps, built)
        }
        Err(e) => (e.0.clone(), Vec::new()),
    };
    let ok = problems.is_empty() && built.is_empty();
    match format {
        Format::Json => {
            let report = Report {
                ok,
                problems: problems
                    .iter()
                    .map(|p| ProblemJson {
                        file: p.file.clone(),
                        record: p.record.clone(),
                        message: p.kind.to_string(),
                    })
                    .chain(built.iter().map(|p| ProblemJson {
                        file: p.file().to_owned(),
                        record: Some(p.record()),
                        message: p.message(),
                    }))
                    .collect(),
            };
            say!("{}", json(&report))?;
        }
        Format::Text => {
            for p in &problems {
                say!("{p}")?;
            }
            for p in &built {
                say!("{p}")?;
            }
            if let (Ok(spec), true) = (&loaded, ok) {
                for f in spec.families() {
                    say!(
                        "{}: {} parameters, {} models, {} bitfields, {} requirements, {} errata, {} vectors",
                        f.id(),
                        f.parameters.len(),
                        f.models.len(),
                        f.bitfields.len(),
                        f.requirements.len(),
                        f.errata.len(),
                        f.vectors.len()
                    )?;
                }
                say!("spec ok")?;
            }
        }
    }
    Ok(if ok { Outcome::Pass } else { Outcome::Fail })
}

fn family<'s>(spec: &'s Spec, device: &str) -> Result<&'s Family> {
    let id = FamilyId::parse(device).ok_or_else(|| {
        anyhow!("unknown device {device:?}; expected one of: hpd, psd4xx, psx3xx")
    })?;
    Ok(spec.family(id))
}

fn model_arg<'f>(family: &'f Family, model: Option<&str>) -> Result<Option<&'f DeviceModel>> {
    let Some(query) = model else { return Ok(None) };
    match family.model(query) {
        Some(m) => Ok(Some(m)),
        None => {
            let known: Vec<&str> = family.models.iter().map(|m| m.id.as_str()).collect();
            bail!(
                "unknown {} model {query:?}; known models: {}",
                family.id(),
                known.join(", ")
            )
        }
    }
}

/// One row of `spec list`, with range and default resolved for the model.
#[derive(Serialize)]
struct ParamRow<'a> {
    id: &'a str,
    number: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    subindex: Option<u32>,
    name: &'a str,
    #[serde(rename = "type")]
    data_type: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    unit: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    scale: Option<f64>,
    range: Option<Ranges>,
    default: Option<i64>,
    model_dependent: bool,
    access: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    saved: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    address: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    size: Option<u32>,
    source: &'a str,
}

fn row<'a>(family: &Family, p: &'a Parameter, model: Option<&DeviceModel>) -> ParamRow<'a> {
    let dependent = p.range_model || p.default_model;
    let r = family.resolve(p, model);
    let (range, default) = if dependent && model.is_none() {
        (
            if p.range_model { None } else { r.range },
            if p.default_model { None } else { r.default },
        )
    } else {
        (r.range, r.default)
    };
    ParamRow {
        id: &p.id,
        number: p.number,
        subindex: p.subindex,
        name: &p.name,
        data_type: p.data_type.as_str(),
        unit: p.unit.as_deref(),
        scale: p.scale,
        range,
        default,
        model_dependent: dependent,
        access: p.access.as_str(),
        saved: p.saved,
        address: p.address,
        size: p.size,
        source: &p.source,
    }
}

/// A raw value with its unit and scale applied: `253` → `25.3 %`.
fn shown(p: &Parameter, raw: i64) -> String {
    let mut s = match p.scale {
        Some(scale) if scale != 1.0 => {
            let decimals = (-scale.log10()).ceil().max(0.0) as usize;
            format!("{raw} (= {:.*})", decimals, p.display_value(raw))
        }
        _ => raw.to_string(),
    };
    if let Some(u) = &p.unit {
        let _ = write!(s, " {u}");
    }
    s
}

fn range_text(p: &Parameter, range: &Ranges) -> String {
    let mut s = range.to_string();
    if let Some(u) = &p.unit {
        let _ = write!(s, " {u}");
    }
    if let Some(scale) = p.scale.filter(|s| *s != 1.0) {
        let _ = write!(s, " (× {scale})");
    }
    s
}

fn list(family: &Family, model: Option<&DeviceModel>, format: Format) -> Result<String> {
    let rows: Vec<ParamRow> = family
        .parameters
        .iter()
        .map(|p| row(family, p, model))
        .collect();
    if let Format::Json = format {
        #[derive(Serialize)]
        struct Out<'a> {
            family: FamilyId,
            model: Option<&'a str>,
            parameters: Vec<ParamRow<'a>>,
        }
        let out = Out {
            family: family.id(),
            model: model.map(|m| m.id.as_str()),
            parameters: rows,
        };
        return Ok(json(&out) + "\n");
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} parameters{}",
        family.id(),
        model
            .map(|m| format!(" for model {}", m.id))
            .unwrap_or_default()
    );
    for (p, r) in family.parameters.iter().zip(&rows) {
        let range = match &r.range {
            Some(range) => range_text(p, range),
            None if p.range_model => "per model".to_owned(),
            None => "-".to_owned(),
        };
        let default = match r.default {
            Some(d) => d.to_string(),
            None if p.default_model => "per model".to_owned(),
            None => p.default_text.clone().unwrap_or_else(|| "-".to_owned()),
        };
        let addr = match (p.address, p.size) {
            (Some(a), Some(n)) => format!("  @{a:#05x}/{n}"),
            _ => String::new(),
        };
        let _ = writeln!(
            s,
            "{:<6} {:<44} {:<6} {:<2}  range {}  default {}{}",
            p.id,
            truncate(&p.name, 44),
            p.data_type.as_str(),
            p.access.as_str(),
            range,
            default,
            addr
        );
    }
    Ok(s)
}

fn truncate(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_owned()
    } else {
        let mut t: String = s.chars().take(n.saturating_sub(1)).collect();
        t.push('…');
        t
    }
}

fn show(
    family: &Family,
    p: &Parameter,
    model: Option<&DeviceModel>,
    format: Format,
) -> Result<String> {
    let requirements: Vec<&str> = family
        .requirements
        .iter()
        .filter(|r| {
            r.params
                .iter()
                .any(|id| family.parameter(id).is_some_and(|q| q.id == p.id))
        })
        .map(|r| r.id.as_str())
        .collect();
    let bitfields: Vec<_> = family.bitfields_of(&p.id).collect();
    let per_model: Vec<PerModel> = if p.range_model
        || p.default_model
        || family
            .models
            .iter()
            .any(|m| m.params.iter().any(|mp| mp.id == p.id))
    {
        family
            .models
            .iter()
            .map(|m| {
                let r = family.resolve(p, Some(m));
                PerModel {
                    model: &m.id,
                    range: r.range,
                    default: r.default,
                }
            })
            .collect()
    } else {
        Vec::new()
    };
    let resolved = row(family, p, model);
    if let Format::Json = format {
        #[derive(Serialize)]
        struct Out<'a> {
            family: FamilyId,
            model: Option<&'a str>,
            parameter: &'a Parameter,
            resolved: ParamRow<'a>,
            per_model: Vec<PerModel<'a>>,
            bitfields: Vec<&'a drivespec_spec::Bitfield>,
            requirements: Vec<&'a str>,
        }
        let out = Out {
            family: family.id(),
            model: model.map(|m| m.id.as_str()),
            parameter: p,
            resolved,
            per_model,
            bitfields,
            requirements,
        };
        return Ok(json(&out) + "\n");
    }
    let mut s = String::new();
    let _ = writeln!(s, "{} parameter {}: {}", family.id(), p.id, p.name);
    let mut field = |k: &str, v: String| {
        let _ = writeln!(s, "  {k:<12}{v}");
    };
    if let Some(sub) = p.subindex {
        field("index", format!("{} sub-index {sub}", p.number));
    }
    if let Some(g) = &p.group {
        field("group", g.clone());
    }
    let mut ty = p.data_type.as_str().to_owned();
    if let Some(len) = p.length {
        let _ = write!(ty, ", at most {len} bytes");
    }
    if let Some(n) = p.array {
        let _ = write!(ty, ", array of {n}");
    }
    field("type", ty);
    if let Some(u) = &p.unit {
        field("unit", u.clone());
    }
    if let Some(scale) = p.scale {
        field("scale", format!("shown value = raw × {scale}"));
    }
    let mut access = p.access.as_str().to_owned();
    match p.saved {
        Some(true) => access.push_str(", saved"),
        Some(false) => access.push_str(", not saved"),
        None => {}
    }
    if p.live {
        access.push_str(", live value");
    }
    field("access", access);
    if let (Some(a), Some(n)) = (p.address, p.size) {
        field(
            "serial",
            format!(
                "address {a:#05x}, {n} byte{}",
                if n == 1 { "" } else { "s" }
            ),
        );
    }
    let which = model
        .map(|m| format!(" (model {})", m.id))
        .unwrap_or_default();
    match (&resolved.range, p.range_model && model.is_none()) {
        (_, true) => field("range", "per model, see below".into()),
        (Some(r), _) => field("range", format!("{}{which}", range_text(p, r))),
        (None, _) => {}
    }
    match (resolved.default, p.default_model && model.is_none()) {
        (_, true) => field("default", "per model, see below".into()),
        (Some(d), _) => field("default", format!("{}{which}", shown(p, d))),
        (None, _) => {
            if let Some(t) = &p.default_text {
                field("default", format!("{t:?}"));
            }
        }
    }
    if let Some(n) = &p.range_note {
        field("range note", n.clone());
    }
    if !p.conditions.is_empty() {
        field("conditions", p.conditions.join(", "));
    }
    if let Some(d) = &p.description {
        field("meaning", d.clone());
    }
    field("source", p.source.clone());
    if !p.values.is_empty() {
        let _ = writeln!(s, "  values:");
        for v in &p.values {
            let _ = writeln!(s, "    {:>6}  {}: {}", v.value, v.name, v.meaning);
        }
    }
    if !p.modes.is_empty() {
        let _ = writeln!(s, "  in operating modes:");
        for m in &p.modes {
            let modes: Vec<String> = m.modes.iter().map(u32::to_string).collect();
            let mut line = format!("    mode {}: {}", modes.join(", "), m.name);
            if let Some(u) = &m.unit {
                let _ = write!(line, " [{u}]");
            }
            if let Some(r) = &m.range {
                let _ = write!(line, ", range {r}");
            }
            if let Some(d) = m.default {
                let _ = write!(line, ", default {d}");
            }
            let _ = writeln!(s, "{line}");
        }
    }
    if model.is_none() && !per_model.is_empty() {
        let _ = writeln!(s, "  per model:");
        for pm in &per_model {
            let range = pm
                .range
                .as_ref()
                .map(|r| r.to_string())
                .unwrap_or_else(|| "-".into());
            let default = pm
                .default
                .map(|d| d.to_string())
                .unwrap_or_else(|| "-".into());
            let _ = writeln!(
                s,
                "    {:<22} range {:<16} default {}",
                pm.model, range, default
            );
        }
    }
    for b in &bitfields {
        let modes = if b.modes.is_empty() {
            String::new()
        } else {
            format!(
                " (modes {})",
                b.modes
                    .iter()
                    .map(u32::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        let _ = writeln!(s, "  bits of {}{modes}:", b.name);
        for bit in &b.bits {
            let mut flags = Vec::new();
            if bit.reserved {
                flags.push("reserved".to_owned());
            }
            if bit.must_be_zero {
                flags.push("must be 0".to_owned());
            }
            if let Some(a) = bit.access {
                flags.push(a.as_str().to_owned());
            }
            if let Some(d) = bit.default {
                flags.push(format!("default {d}"));
            }
            let flags = if flags.is_empty() {
                String::new()
            } else {
                format!(" [{}]", flags.join(", "))
            };
            let _ = writeln!(s, "    {:>2}  {}{flags}", bit.bit, bit.name);
            for rule in &bit.rules {
                let verb = match rule.action {
                    drivespec_spec::RuleAction::Set => "set",
                    drivespec_spec::RuleAction::Reset => "reset",
                };
                let _ = writeln!(
                    s,
                    "          {verb:<5} {} ({})",
                    rule.text, rule.requirement
                );
            }
        }
        for v in &b.values {
            let _ = writeln!(s, "    value {:#06x}  {}: {}", v.value, v.name, v.meaning);
        }
    }
    if !requirements.is_empty() {
        let _ = writeln!(s, "  requirements: {}", requirements.join(", "));
    }
    Ok(s)
}

#[derive(Serialize)]
struct PerModel<'a> {
    model: &'a str,
    range: Option<Ranges>,
    default: Option<i64>,
}

fn models(family: &Family, format: Format) -> Result<String> {
    if let Format::Json = format {
        #[derive(Serialize)]
        struct Out<'a> {
            family: FamilyId,
            models: &'a [DeviceModel],
        }
        return Ok(json(&Out {
            family: family.id(),
            models: &family.models,
        }) + "\n");
    }
    let mut s = String::new();
    let _ = writeln!(s, "{} models", family.id());
    for m in &family.models {
        let _ = writeln!(s, "{:<20} {}", m.id, m.name);
        if !m.aliases.is_empty() {
            let _ = writeln!(s, "{:<20}   also: {}", "", m.aliases.join(", "));
        }
        if !m.attributes.is_empty() {
            let attrs: Vec<String> = m
                .attributes
                .iter()
                .map(|(k, v)| format!("{k} = {v}"))
                .collect();
            let _ = writeln!(s, "{:<20}   {}", "", attrs.join(", "));
        }
    }
    Ok(s)
}

fn requirements(family: &Family, level: Option<&str>, format: Format) -> Result<String> {
    let keep = |l: Level| level.is_none_or(|want| l.as_str() == want);
    let reqs: Vec<_> = family
        .requirements
        .iter()
        .filter(|r| keep(r.level))
        .collect();
    if let Format::Json = format {
        #[derive(Serialize)]
        struct Out<'a> {
            family: FamilyId,
            requirements: Vec<&'a drivespec_spec::Requirement>,
        }
        return Ok(json(&Out {
            family: family.id(),
            requirements: reqs,
        }) + "\n");
    }
    let mut s = String::new();
    for r in reqs {
        let _ = writeln!(
            s,
            "{:<24} {:<11} {}  [{}]",
            r.id,
            r.level.as_str(),
            r.text,
            r.source
        );
    }
    Ok(s)
}

fn examples(family: &Family, format: Format) -> Result<String> {
    if let Format::Json = format {
        #[derive(Serialize)]
        struct Out<'a> {
            family: FamilyId,
            examples: &'a [drivespec_spec::Vector],
        }
        return Ok(json(&Out {
            family: family.id(),
            examples: &family.vectors,
        }) + "\n");
    }
    let mut s = String::new();
    for v in &family.vectors {
        let _ = writeln!(
            s,
            "{} ({}, {}): {}",
            v.id,
            v.kind.as_str(),
            v.source,
            v.description
        );
        let (input, expect) = v.body.tables();
        for (k, val) in &input {
            let _ = writeln!(s, "    in   {k} = {}", inline(val));
        }
        for (k, val) in &expect {
            let _ = writeln!(s, "    out  {k} = {}", inline(val));
        }
    }
    Ok(s)
}

/// A TOML value on one line.
fn inline(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => format!("{s:?}"),
        other => other.to_string(),
    }
}

fn errata(family: &Family, format: Format) -> Result<String> {
    if let Format::Json = format {
        #[derive(Serialize)]
        struct Out<'a> {
            family: FamilyId,
            errata: &'a [drivespec_spec::Erratum],
        }
        return Ok(json(&Out {
            family: family.id(),
            errata: &family.errata,
        }) + "\n");
    }
    let mut s = String::new();
    for e in &family.errata {
        let _ = writeln!(s, "{}: {} [{}]", e.id, e.title, e.source);
        for r in &e.readings {
            let mark = if r.id == e.adopted { "*" } else { " " };
            let _ = writeln!(s, "  {mark} {}: {}", r.id, r.text);
        }
        let _ = writeln!(s, "    adopted {}: {}", e.adopted, e.reason);
        if let Some(o) = &e.option {
            let _ = writeln!(s, "    selectable with option {o:?}");
        }
    }
    Ok(s)
}
