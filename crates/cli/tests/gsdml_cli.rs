//! `drivespec spec gsdml psd4xx`: the GSDML follows the rules of `drivespec_spec::gsdml`
//! (well-formed, unique IDs, every text defined once, every module reference resolved, IO data
//! as long as the modules of bus description 3.5, records of 3.2.2 lengths with defaults in
//! their allowed values). The PI schema is not published under a licence that lets us fetch
//! it here; where `DRIVESPEC_GSDML_XSD` names a copy (GSDML-DeviceProfile-V2.35.xsd with its
//! includes beside it), the document is also validated against it with `xmllint --schema`.
#![allow(
    clippy::expect_used,
    clippy::unwrap_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drivespec_spec::{FamilyId, Spec};
use drivespec_testkit::{run, temp_dir};
use roxmltree::{Document, Node};
use std::collections::HashMap;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

const NS: &str = "http://www.profibus.com/GSDML/2003/11/DeviceProfile";

fn gsdml(args: &[&str]) -> String {
    let mut argv = vec!["spec", "gsdml", "psd4xx"];
    argv.extend_from_slice(args);
    let (code, out, err) = run(BIN, &argv);
    assert_eq!(code, 0, "{err}");
    out
}

/// Size in bytes of a GSDML simple data type.
fn size(data_type: &str) -> Option<usize> {
    Some(match data_type {
        "Unsigned8" | "Integer8" => 1,
        "Unsigned16" | "Integer16" => 2,
        "Unsigned32" | "Integer32" => 4,
        _ => return None,
    })
}

fn allows(allowed: &str, v: i64) -> bool {
    allowed
        .split_whitespace()
        .any(|part| match part.split_once("..") {
            Some((lo, hi)) => lo.parse::<i64>().unwrap() <= v && v <= hi.parse::<i64>().unwrap(),
            None => part.parse::<i64>().unwrap() == v,
        })
}

fn elements<'a, 'i>(doc: &'a Document<'i>, tag: &'a str) -> impl Iterator<Item = Node<'a, 'i>> {
    doc.descendants()
        .filter(move |n| n.is_element() && n.tag_name().name() == tag)
}

/// Every broken rule of the module doc of `drivespec_spec::gsdml`, one line each.
fn problems(xml: &str, spec: &Spec) -> Vec<String> {
    let mut out = Vec::new();
    let doc = match Document::parse(xml) {
        Ok(d) => d,
        Err(e) => return vec![format!("not well-formed: {e}")],
    };
    let root = doc.root_element();
    if root.tag_name().name() != "ISO15745Profile" || root.tag_name().namespace() != Some(NS) {
        out.push(format!("root {:?}", root.tag_name()));
    }
    for required in [
        "ProfileHeader",
        "DeviceIdentity",
        "DeviceAccessPointItem",
        "ModuleList",
        "ExternalTextList",
    ] {
        if elements(&doc, required).next().is_none() {
            out.push(format!("no {required}"));
        }
    }
    let mut ids = HashMap::new();
    for n in doc.descendants().filter(|n| n.is_element()) {
        if let Some(id) = n.attribute("ID") {
            if ids.insert(id, ()).is_some() {
                out.push(format!("ID {id} twice"));
            }
        }
    }
    let mut texts: HashMap<&str, usize> = HashMap::new();
    for t in elements(&doc, "Text") {
        *texts
            .entry(t.attribute("TextId").unwrap_or(""))
            .or_default() += 1;
    }
    for (id, n) in &texts {
        if *n > 1 {
            out.push(format!("text {id} defined {n} times"));
        }
    }
    for n in doc
        .descendants()
        .filter(|n| n.is_element() && n.tag_name().name() != "Text")
    {
        if let Some(id) = n.attribute("TextId") {
            if !texts.contains_key(id) {
                out.push(format!("text {id} used but not defined"));
            }
        }
    }
    for r in elements(&doc, "ModuleItemRef") {
        let target = r.attribute("ModuleItemTarget").unwrap_or("");
        if !elements(&doc, "ModuleItem").any(|m| m.attribute("ID") == Some(target)) {
            out.push(format!("ModuleItemTarget {target} names no ModuleItem"));
        }
    }
    let proto = spec.family(FamilyId::Psd4xx).psd4xx().unwrap();
    for (tag, module) in [
        ("Output", &proto.process_data.output),
        ("Input", &proto.process_data.input),
    ] {
        let lists: Vec<_> = elements(&doc, tag).collect();
        if lists.len() != 1 {
            out.push(format!("{} {tag} lists", lists.len()));
            continue;
        }
        let items: Vec<_> = lists[0]
            .children()
            .filter(|n| n.is_element() && n.tag_name().name() == "DataItem")
            .collect();
        let mut offset = 0;
        for (item, field) in items.iter().zip(&module.fields) {
            let Some(len) = size(item.attribute("DataType").unwrap_or("")) else {
                out.push(format!("{tag} {}: data type", field.name));
                continue;
            };
            if offset != field.offset || len != field.length {
                out.push(format!(
                    "{tag} {}: bytes {offset}+{len}, 3.5 says {}+{}",
                    field.name, field.offset, field.length
                ));
            }
            let bits: Vec<u32> = item
                .children()
                .filter(|n| n.is_element())
                .map(|b| b.attribute("BitOffset").unwrap().parse().unwrap())
                .collect();
            let as_bits = item.attribute("UseAsBits") == Some("true");
            if as_bits != field.inverted || (as_bits && bits.is_empty()) {
                out.push(format!("{tag} {}: UseAsBits {as_bits}", field.name));
            }
            if bits.iter().any(|b| *b as usize >= 8 * len) {
                out.push(format!("{tag} {}: bit offset past the item", field.name));
            }
            offset += len;
        }
        if items.len() != module.fields.len() || offset != module.length {
            out.push(format!(
                "{tag}: {} items, {offset} bytes; 3.5 says {} fields, {} bytes",
                items.len(),
                module.fields.len(),
                module.length
            ));
        }
    }
    let family = spec.family(FamilyId::Psd4xx);
    for rec in elements(&doc, "ParameterRecordDataItem") {
        let index: u32 = rec.attribute("Index").unwrap().parse().unwrap();
        let length: usize = rec.attribute("Length").unwrap().parse().unwrap();
        let Some(p) = family.parameters.iter().find(|p| p.number == index) else {
            out.push(format!("record {index}: no such parameter"));
            continue;
        };
        if !p.access.writable() {
            out.push(format!("record {index}: parameter is read-only"));
        }
        let refs: Vec<_> = rec
            .children()
            .filter(|n| n.is_element() && n.tag_name().name() == "Ref")
            .collect();
        let mut end = 0;
        for r in &refs {
            let at: usize = r.attribute("ByteOffset").unwrap().parse().unwrap();
            let len = size(r.attribute("DataType").unwrap()).unwrap_or(0);
            end = end.max(at + len);
            let default: i64 = r.attribute("DefaultValue").unwrap().parse().unwrap();
            if !allows(r.attribute("AllowedValues").unwrap_or(""), default) {
                out.push(format!("record {index}: default {default} not allowed"));
            }
        }
        let want = proto
            .record
            .length_for(p.data_type.width().unwrap() * 8)
            .map(|l| l.write);
        if refs.len() != 2 || end != length || Some(length) != want {
            out.push(format!(
                "record {index}: {} refs over {end} of {length} bytes; 3.2.2 says {want:?}",
                refs.len()
            ));
        }
    }
    out
}

#[test]
fn psd4xx_gsdml_follows_the_rules() {
    let spec = Spec::builtin().unwrap();
    let xml = gsdml(&[]);
    assert_eq!(problems(&xml, &spec), Vec::<String>::new());
    assert!(
        xml.contains("ParameterRecordDataItem Index=\"38\""),
        "{xml}"
    );
    assert!(xml.contains("VendorID=\"0x0130\""), "{xml}");
    // 3.5 notice: the bit-wise words name their byte order.
    assert_eq!(
        xml.matches("bits 0-7 in the first byte").count(),
        2,
        "{xml}"
    );
}

#[test]
fn the_rules_catch_a_broken_document() {
    let spec = Spec::builtin().unwrap();
    let xml = gsdml(&[]);
    let cases = [
        ("ID=\"DAP_0001\"", "ID=\"DAP\"", "ID DAP twice"),
        (
            "DataType=\"Integer32\"",
            "DataType=\"Integer16\"",
            "3.5 says",
        ),
        ("Length=\"5\"", "Length=\"4\"", "3.2.2 says"),
        ("DefaultValue=\"400\"", "DefaultValue=\"0\"", "not allowed"),
        (
            "<Text TextId=\"IDT_INFO_DAP\"",
            "<Text TextId=\"IDT_X\"",
            "not defined",
        ),
        (
            "ModuleItemTarget=\"MOD_",
            "ModuleItemTarget=\"X_",
            "names no ModuleItem",
        ),
        ("</ModuleList>", "", "not well-formed"),
    ];
    for (from, to, want) in cases {
        let broken = xml.replacen(from, to, 1);
        assert_ne!(broken, xml, "{from}");
        let found = problems(&broken, &spec);
        assert!(found.iter().any(|p| p.contains(want)), "{from}: {found:?}");
    }
}

#[test]
fn model_ranges_and_the_output_file() {
    let dir = temp_dir("gsdml", "out");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("psd4xx.xml");
    let path = file.display().to_string();
    let (code, out, err) = run(
        BIN,
        &[
            "spec",
            "gsdml",
            "psd4xx",
            "--model",
            "PSD480-5V",
            "--out",
            &path,
        ],
    );
    assert_eq!((code, out.as_str()), (0, ""), "{err}");
    let xml = std::fs::read_to_string(&file).unwrap();
    assert!(xml.contains("model PSD480-5V"), "{xml}");
    assert_eq!(
        problems(&xml, &Spec::builtin().unwrap()),
        Vec::<String>::new()
    );
    let (code, _, err) = run(BIN, &["spec", "gsdml", "psd4xx", "--model", "nope"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("known models"), "{err}");
    let (code, _, err) = run(BIN, &["spec", "gsdml", "hpd"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not a PROFINET device"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn validates_against_the_pi_schema_where_one_is_given() {
    let Some(xsd) = std::env::var_os("DRIVESPEC_GSDML_XSD") else {
        println!("skipping: DRIVESPEC_GSDML_XSD names no GSDML schema");
        return;
    };
    let dir = temp_dir("gsdml", "xsd");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("psd4xx.xml");
    std::fs::write(&file, gsdml(&[])).unwrap();
    let out = std::process::Command::new("xmllint")
        .arg("--noout")
        .arg("--schema")
        .arg(&xsd)
        .arg(&file)
        .output()
        .expect("run xmllint");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// profinet-py's GSDML reader (an independent IO controller, installed by `.ci/run`) takes
/// from the document the identity and the slots of `[protocol.profinet]`: the DAP with its
/// submodules in slot 0, the 14-byte output module and the 16-byte input module of 3.5.
#[test]
fn profinet_py_reads_the_identity_and_slots() {
    let dir = temp_dir("gsdml", "profinet-py");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("psd4xx.xml");
    std::fs::write(&file, gsdml(&[])).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/gsdml_profinet_py.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(&file)
        .output();
    std::fs::remove_dir_all(&dir).unwrap();
    let out = match out {
        Ok(o) if o.status.code() != Some(3) => o,
        _ => {
            let msg = "profinet-py is not installed (python3 -m pip install profinet-py)";
            assert!(
                std::env::var_os("DRIVESPEC_REQUIRE_PROFINET_PY").is_none(),
                "{msg}"
            );
            println!("skipping: {msg}");
            return;
        }
    };
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let spec = Spec::builtin().unwrap();
    let proto = spec.family(FamilyId::Psd4xx).psd4xx().unwrap();
    let pn = &proto.profinet;
    let mut want: Vec<serde_json::Value> = pn
        .dap
        .submodule
        .iter()
        .map(|s| serde_json::json!([pn.dap.slot, s.subslot, 0, 0, pn.dap.module_ident, s.ident]))
        .collect();
    let (o, i) = (&pn.output, &pn.input);
    let (olen, ilen) = (
        proto.process_data.output.length,
        proto.process_data.input.length,
    );
    want.push(serde_json::json!([
        o.slot,
        o.subslot,
        0,
        olen,
        o.module_ident,
        o.submodule_ident
    ]));
    want.push(serde_json::json!([
        i.slot,
        i.subslot,
        ilen,
        0,
        i.module_ident,
        i.submodule_ident
    ]));
    assert_eq!(got["vendor_id"], pn.vendor_id);
    assert_eq!(got["device_id"], pn.device_id);
    assert_eq!(got["slots"], serde_json::Value::Array(want));
}
