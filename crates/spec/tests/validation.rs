//! One broken spec per validation rule: each must give exactly its one clear error.
#![allow(
    clippy::indexing_slicing,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic
)]

use drivespec_spec::{FamilyId, Protocol, Spec, SpecFiles};

/// The built-in family and protocol files, with no records but the requirements the
/// PSD4xx protocol tables name (PKW answers and errors, the echo, record read lengths).
fn skeleton() -> SpecFiles {
    let builtin = SpecFiles::builtin();
    let mut files = SpecFiles::from_pairs(
        builtin
            .iter()
            .filter(|(p, _)| p.ends_with("/family.toml") || p.ends_with("/protocol.toml"))
            .map(|(p, c)| (p.to_owned(), c.to_owned())),
    );
    files.set("psd4xx/requirements-access.toml", &access_requirements());
    files
}

/// A requirement record for each ID the built-in PSD4xx protocol tables name.
fn access_requirements() -> String {
    let spec = Spec::builtin().unwrap();
    let family = spec.family(FamilyId::Psd4xx);
    let Protocol::Psd4xx(p) = &family.protocol else {
        panic!("the PSD4xx family has the PSD4xx protocol");
    };
    let ids = p
        .pkw
        .commands
        .iter()
        .map(|c| &c.requirement)
        .chain(p.pkw.errors.iter().map(|e| &e.requirement))
        .chain(std::iter::once(&p.pkw.echo.requirement))
        .chain(p.record.lengths.iter().map(|l| &l.read_requirement));
    ids.map(|id| {
        format!("[[requirement]]\nid = {id:?}\nlevel = \"must\"\ntext = \"named by the PKW and record tables\"\nsource = \"3.8\"\n\n")
    })
    .collect()
}

const PARAM: &str = r#"
[[parameter]]
id = "44"
number = 44
name = "Positioning window"
type = "u16"
range = [[1, 100]]
default = 2
access = "rw"
source = "3.3"
"#;

const REQ: &str = r#"
[[requirement]]
id = "PSD-PAR-044"
level = "must"
text = "the positioning window is 1 to 100"
source = "3.3"
"#;

/// Loads the skeleton plus `psd4xx/test.toml` and returns the problems as lines.
fn problems_with(file: &str, contents: &str) -> Vec<String> {
    let mut files = skeleton();
    files.set(file, contents);
    match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    }
}

fn one_problem(contents: &str) -> String {
    let problems = problems_with("psd4xx/test.toml", contents);
    assert_eq!(
        problems.len(),
        1,
        "expected exactly one problem, got {problems:#?}"
    );
    problems.into_iter().next().unwrap_or_default()
}

#[test]
fn skeleton_and_sample_records_are_valid() {
    assert_eq!(
        problems_with("psd4xx/test.toml", &format!("{PARAM}{REQ}")),
        Vec::<String>::new()
    );
}

#[test]
fn unknown_key_is_rejected() {
    let p = one_problem(&PARAM.replace("range =", "rnage ="));
    assert!(
        p.starts_with(r#"psd4xx/test.toml: parameter "44": unknown field `rnage`"#),
        "{p}"
    );
}

#[test]
fn unknown_top_level_key_is_rejected() {
    let p = one_problem("[[parametr]]\nid = \"1\"\n");
    assert_eq!(p, "psd4xx/test.toml: unknown top-level key `parametr`, expected one of: parameter, model, param_set, bitfield, requirement, erratum");
}

#[test]
fn syntax_error_names_line_and_column() {
    let p = one_problem("[[parameter]]\nid = \"1\nnumber = 1\n");
    assert!(
        p.starts_with("psd4xx/test.toml: invalid TOML at line 2, column"),
        "{p}"
    );
}

#[test]
fn missing_required_key_is_rejected() {
    let p = one_problem(&PARAM.replace("source = \"3.3\"\n", ""));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "44": missing field `source`"#
    );
}

#[test]
fn duplicate_parameter_id_is_rejected() {
    let p = one_problem(&format!(
        "{PARAM}{}",
        PARAM.replace("number = 44", "number = 45")
    ));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "44": duplicate parameter id "44" (first in psd4xx/test.toml)"#
    );
}

#[test]
fn duplicate_parameter_number_is_rejected() {
    let p = one_problem(&format!(
        "{PARAM}{}",
        PARAM.replace("id = \"44\"", "id = \"x44\"")
    ));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "x44": duplicate parameter number "44" (first in psd4xx/test.toml)"#
    );
}

#[test]
fn default_outside_range_is_rejected() {
    let p = one_problem(&PARAM.replace("default = 2", "default = 0"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "44": default 0 outside range 1..100"#
    );
}

#[test]
fn range_beyond_data_type_is_rejected() {
    let p = one_problem(&PARAM.replace("[[1, 100]]", "[[1, 70000]]"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "44": range 1..70000 exceeds the data type"#
    );
}

#[test]
fn inverted_range_is_rejected() {
    let p = one_problem(&PARAM.replace("[[1, 100]]", "[[1, 100], [9, 3]]"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "44": range 9..3 has min > max"#
    );
}

#[test]
fn enumerated_value_outside_range_is_rejected() {
    let extra = "[[parameter.value]]\nvalue = 200\nname = \"big\"\nmeaning = \"too big\"\n";
    let p = one_problem(&format!("{PARAM}{extra}"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "44": enumerated value 200 outside range 1..100"#
    );
}

const MODEL: &str = r#"
[[model]]
id = "PSD426-14H"
name = "PSD 426/436-14H"
aliases = ["PSD426"]
source = "3.4"
"#;

#[test]
fn model_default_outside_its_range_is_rejected() {
    let m = format!("{MODEL}[[model.param]]\nid = \"44\"\nrange = [[1, 50]]\ndefault = 60\n");
    let p = one_problem(&format!("{PARAM}{m}"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: parameter "44": default 60 outside range 1..50 for model PSD426-14H"#
    );
}

#[test]
fn model_dependent_value_must_come_from_every_model() {
    let param = PARAM.replace("default = 2", "default_model = true");
    let p = one_problem(&format!("{param}{MODEL}"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: model "PSD426-14H": model "PSD426-14H" gives no default for parameter "44""#
    );
}

#[test]
fn model_param_must_exist() {
    let m = format!("{MODEL}[[model.param]]\nid = \"99\"\ndefault = 1\n");
    let p = one_problem(&m);
    assert_eq!(
        p,
        r#"psd4xx/test.toml: model "PSD426-14H": parameter "99" does not exist"#
    );
}

#[test]
fn model_names_must_be_unique_after_folding() {
    let other = MODEL
        .replace("PSD426-14H", "PSD426-8V")
        .replace("PSD 426/436-14H", "PSD 426-8V")
        .replace("[\"PSD426\"]", "[\"psd-426\"]");
    let p = one_problem(&format!("{MODEL}{other}"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: model "PSD426-8V": duplicate model name "psd426" (first in psd4xx/test.toml)"#
    );
}

#[test]
fn serial_addresses_must_not_overlap() {
    let a = "[[parameter]]\nid = \"Pr7\"\nnumber = 7\nname = \"a\"\ntype = \"i16\"\naccess = \"rw\"\naddress = 0x42\nsize = 2\nsource = \"4.2\"\n";
    let b = "[[parameter]]\nid = \"Pr8\"\nnumber = 8\nname = \"b\"\ntype = \"u8\"\naccess = \"rw\"\naddress = 0x43\nsize = 1\nsource = \"4.2\"\n";
    let problems = problems_with("hpd/test.toml", &format!("{a}{b}"));
    assert_eq!(
        problems,
        vec![
            r#"hpd/test.toml: parameter "Pr8": address 0x043..0x044 overlaps parameter "Pr7""#
                .to_owned()
        ]
    );
}

#[test]
fn serial_size_must_be_1_2_or_4() {
    let a = "[[parameter]]\nid = \"Pr7\"\nnumber = 7\nname = \"a\"\ntype = \"i16\"\naccess = \"rw\"\naddress = 0x42\nsize = 3\nsource = \"4.2\"\n";
    let problems = problems_with("hpd/test.toml", a);
    assert_eq!(
        problems,
        vec![r#"hpd/test.toml: parameter "Pr7": size 3, expected 1, 2 or 4"#.to_owned()]
    );
}

const BITS: &str = r#"
[[bitfield]]
id = "status"
param = "44"
name = "Status word"
width = 16
source = "3.6"

[[bitfield.bit]]
bit = 0
name = "Target position reached"

[[bitfield.bit.rule]]
action = "set"
trigger = "target-reached"
requirement = "PSD-PAR-044"
level = "must"
text = "a target has been reached"
"#;

#[test]
fn bitfield_sample_is_valid() {
    assert_eq!(
        problems_with("psd4xx/test.toml", &format!("{PARAM}{BITS}")),
        Vec::<String>::new()
    );
}

#[test]
fn bitfield_parameter_must_exist() {
    let p = one_problem(BITS);
    assert_eq!(
        p,
        r#"psd4xx/test.toml: bitfield "status": parameter "44" does not exist"#
    );
}

#[test]
fn bit_must_lie_inside_the_width() {
    let p = one_problem(&format!("{PARAM}{}", BITS.replace("bit = 0", "bit = 16")));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: bitfield "status" bit 16: bit 16 outside width 16"#
    );
}

#[test]
fn bit_rule_creates_its_requirement() {
    let mut files = skeleton();
    files.set("psd4xx/test.toml", &format!("{PARAM}{BITS}"));
    let spec = Spec::from_files(&files).unwrap();
    let r = spec
        .family(drivespec_spec::FamilyId::Psd4xx)
        .requirement("PSD-PAR-044")
        .unwrap();
    assert_eq!(
        (r.level, r.text.as_str(), r.source.as_str(), r.file.as_str()),
        (
            drivespec_spec::Level::Must,
            "status bit 0 is set: a target has been reached",
            "3.6 bit 0",
            "psd4xx/test.toml"
        )
    );
}

#[test]
fn bit_rule_needs_a_level() {
    let p = one_problem(&format!(
        "{PARAM}{}",
        BITS.replace("level = \"must\"\n", "")
    ));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: bitfield "status": missing field `level`"#
    );
}

#[test]
fn requirement_record_repeating_a_bit_rule_is_a_duplicate() {
    let mut files = skeleton();
    files.set("psd4xx/bits.toml", &format!("{PARAM}{BITS}"));
    files.set("psd4xx/requirements-params.toml", REQ);
    let problems: Vec<String> = match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    };
    assert_eq!(problems, vec![r#"psd4xx/requirements-params.toml: requirement "PSD-PAR-044": duplicate requirement id "PSD-PAR-044" (first in psd4xx/bits.toml)"#.to_owned()]);
}

#[test]
fn later_rule_of_a_requirement_must_not_restate_it() {
    let second = "\n[[bitfield.bit.rule]]\naction = \"reset\"\ntrigger = \"target-left\"\nrequirement = \"PSD-PAR-044\"\nlevel = \"should\"\ntext = \"the target is left\"\n";
    let p = one_problem(&format!("{PARAM}{BITS}{second}"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: bitfield "status" bit 0: level should for requirement "PSD-PAR-044", which an earlier rule gives level must"#
    );
    let p = one_problem(&format!(
        "{PARAM}{BITS}{}",
        second.replace("should", "must") + "note = \"again\"\n"
    ));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: bitfield "status" bit 0: `note` for requirement "PSD-PAR-044", which an earlier rule already states"#
    );
}

#[test]
fn bit_rule_trigger_must_be_a_token() {
    let p = one_problem(&format!(
        "{PARAM}{}",
        BITS.replace("target-reached", "Target reached")
    ));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: bitfield "status" bit 0: identifier "Target reached" does not match a kebab-case token"#
    );
}

#[test]
fn bit_priority_must_name_an_existing_bit() {
    let bits = BITS.replace(
        "trigger = \"target-reached\"",
        "trigger = \"target-reached\"\npriority_over = [10]",
    );
    let p = one_problem(&format!("{PARAM}{bits}"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: bitfield "status" bit 0: bit "10" does not exist"#
    );
}

#[test]
fn requirement_id_must_carry_the_family_prefix() {
    let p = one_problem(&REQ.replace("PSD-PAR-044", "PSX-PAR-044"));
    assert!(p.starts_with(r#"psd4xx/test.toml: requirement "PSX-PAR-044": identifier "PSX-PAR-044" does not match"#), "{p}");
}

#[test]
fn requirement_level_is_checked() {
    let p = one_problem(&REQ.replace("level = \"must\"", "level = \"may\""));
    assert!(
        p.starts_with(r#"psd4xx/test.toml: requirement "PSD-PAR-044": unknown variant `may`"#),
        "{p}"
    );
}

#[test]
fn unobservable_requirement_with_its_reason_is_valid() {
    let req =
        format!("{REQ}observable = false\nreason = \"the motor's heating is not on the bus\"\n");
    assert_eq!(
        problems_with("psd4xx/test.toml", &req),
        Vec::<String>::new()
    );
}

#[test]
fn unobservable_requirement_needs_a_reason() {
    let p = one_problem(&format!("{REQ}observable = false\n"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: requirement "PSD-PAR-044": `observable = false` needs a `reason` saying why no check can see it"#
    );
    let p = one_problem(&format!("{REQ}observable = false\nreason = \" \"\n"));
    assert!(
        p.ends_with("needs a `reason` saying why no check can see it"),
        "{p}"
    );
}

#[test]
fn reason_on_an_observable_requirement_is_rejected() {
    let p = one_problem(&format!("{REQ}reason = \"seen on the bus\"\n"));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: requirement "PSD-PAR-044": a `reason` is given only with `observable = false`"#
    );
}

#[test]
fn duplicate_requirement_across_files_names_the_first_file() {
    let mut files = skeleton();
    files.set("psd4xx/a.toml", REQ);
    files.set("psd4xx/b.toml", REQ);
    let problems: Vec<String> = match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    };
    assert_eq!(problems, vec![r#"psd4xx/b.toml: requirement "PSD-PAR-044": duplicate requirement id "PSD-PAR-044" (first in psd4xx/a.toml)"#.to_owned()]);
}

const ERRATUM: &str = r#"
[[erratum]]
id = "PSD-ERRATUM-001"
source = "3.3 par 96"
title = "-1 listed twice"
adopted = "save"
reason = "1 saves"

[[erratum.reading]]
id = "save"
text = "-1 sets the delivery state"

[[erratum.reading]]
id = "other"
text = "-1 saves"
"#;

#[test]
fn erratum_must_adopt_one_of_its_readings() {
    let p = one_problem(&ERRATUM.replace("adopted = \"save\"", "adopted = \"third\""));
    assert_eq!(
        p,
        r#"psd4xx/test.toml: erratum "PSD-ERRATUM-001": reading "third" does not exist"#
    );
}

#[test]
fn erratum_needs_two_readings() {
    let one = ERRATUM
        .split("[[erratum.reading]]\nid = \"other\"")
        .next()
        .unwrap_or_default();
    let p = one_problem(one);
    assert_eq!(
        p,
        r#"psd4xx/test.toml: erratum "PSD-ERRATUM-001": 1 reading(s), expected at least 2"#
    );
}

const VECTOR: &str = r#"
[[vector]]
id = "pkw-read-44"
kind = "pkw"
source = "3.8"
description = "read par 44"
requirements = ["PSD-PAR-044"]
[vector.input]
ak = 1
pnu = 44
[vector.expect]
ak = 1
pwe = 2
"#;

#[test]
fn vector_requirements_must_exist() {
    let problems = problems_with("psd4xx/vectors/test.toml", VECTOR);
    assert_eq!(problems, vec![r#"psd4xx/vectors/test.toml: vector "pkw-read-44": requirement "PSD-PAR-044" does not exist"#.to_owned()]);
}

#[test]
fn vector_kind_must_be_known() {
    let mut files = skeleton();
    files.set("psd4xx/test.toml", REQ);
    files.set(
        "psd4xx/vectors/test.toml",
        &VECTOR.replace("kind = \"pkw\"", "kind = \"pkx\""),
    );
    let problems: Vec<String> = match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    };
    assert_eq!(problems.len(), 1, "{problems:#?}");
    assert!(
        problems[0].starts_with(
            r#"psd4xx/vectors/test.toml: vector "pkw-read-44": unknown variant `pkx`"#
        ),
        "{problems:#?}"
    );
}

#[test]
fn vectors_folder_holds_only_vectors() {
    let problems = problems_with("psd4xx/vectors/test.toml", REQ);
    assert_eq!(problems, vec!["psd4xx/vectors/test.toml: unknown top-level key `requirement`, expected one of: vector".to_owned()]);
}

#[test]
fn family_folder_and_id_must_agree() {
    let mut files = skeleton();
    let hpd = files
        .get("hpd/family.toml")
        .unwrap_or_default()
        .replace("id = \"hpd\"", "id = \"psd4xx\"");
    files.set("hpd/family.toml", &hpd);
    let problems: Vec<String> = match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    };
    assert_eq!(
        problems,
        vec![r#"hpd/family.toml: family id "psd4xx" in folder "hpd""#.to_owned()]
    );
}

#[test]
fn missing_family_file_is_reported() {
    let files = SpecFiles::from_pairs(
        skeleton()
            .iter()
            .filter(|(p, _)| *p != "psx3xx/family.toml")
            .map(|(p, c)| (p.to_owned(), c.to_owned())),
    );
    let problems: Vec<String> = match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    };
    assert_eq!(
        problems,
        vec!["psx3xx/family.toml: missing file".to_owned()]
    );
}

#[test]
fn string_parameter_takes_default_text() {
    let s = "[[parameter]]\nid = \"13\"\nnumber = 13\nname = \"Device model\"\ntype = \"string\"\nlength = 20\ndefault = 1\naccess = \"r\"\nsource = \"3.3\"\n";
    assert_eq!(
        one_problem(s),
        r#"psd4xx/test.toml: parameter "13": a string parameter takes default_text, not default"#
    );
}

#[test]
fn every_problem_is_reported_not_just_the_first() {
    let bad = format!(
        "{}{}",
        PARAM.replace("default = 2", "default = 0"),
        REQ.replace("PSD-PAR-044", "PSD-X")
    );
    assert_eq!(problems_with("psd4xx/test.toml", &bad).len(), 2);
}

/// Loads the skeleton with `REQ` and `vector` as `psd4xx/vectors/test.toml`.
fn vector_problems(vector: &str) -> Vec<String> {
    let mut files = skeleton();
    files.set("psd4xx/test.toml", REQ);
    files.set("psd4xx/vectors/test.toml", vector);
    match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    }
}

#[test]
fn vector_needs_its_kinds_input_keys() {
    let problems = vector_problems(&VECTOR.replace(
        "ak = 1\npnu = 44\n[vector.expect]",
        "pnu = 44\n[vector.expect]",
    ));
    assert_eq!(
        problems,
        vec![
            r#"psd4xx/vectors/test.toml: vector "pkw-read-44": input: missing field `ak`"#
                .to_owned()
        ]
    );
}

#[test]
fn vector_key_must_be_known_to_its_kind() {
    let problems = vector_problems(&VECTOR.replace("pwe = 2", "pwe_value = 2"));
    assert_eq!(problems.len(), 1, "{problems:#?}");
    assert!(
        problems[0].starts_with(
            r#"psd4xx/vectors/test.toml: vector "pkw-read-44": expect: unknown field `pwe_value`, expected one of"#
        ),
        "{problems:#?}"
    );
}

#[test]
fn vector_value_must_have_its_keys_type() {
    let problems = vector_problems(&VECTOR.replace("pnu = 44", "pnu = \"44\""));
    assert_eq!(problems.len(), 1, "{problems:#?}");
    assert!(
        problems[0]
            .starts_with(r#"psd4xx/vectors/test.toml: vector "pkw-read-44": input: invalid type"#),
        "{problems:#?}"
    );
}

#[test]
fn vector_parameters_must_exist() {
    let mut files = skeleton();
    files.set("psd4xx/test.toml", &format!("{PARAM}{REQ}"));
    let v = VECTOR
        .replace("pnu = 44\n", "pnu = 44\nstate = { \"45\" = 1 }\n")
        .replace("pwe = 2\n", "pwe = 2\nstate = { \"44\" = 2, \"46\" = 1 }\n");
    files.set("psd4xx/vectors/test.toml", &v);
    let problems: Vec<String> = match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    };
    assert_eq!(
        problems,
        vec![
            r#"psd4xx/vectors/test.toml: vector "pkw-read-44": parameter "45" does not exist"#
                .to_owned(),
            r#"psd4xx/vectors/test.toml: vector "pkw-read-44": parameter "46" does not exist"#
                .to_owned(),
        ]
    );
}

/// The problems of the built-in spec with one file edited (`from` must occur in it).
fn builtin_problems_with(file: &str, from: &str, to: &str) -> Vec<String> {
    let mut files = SpecFiles::builtin();
    let text = files.get(file).unwrap_or_default();
    assert!(text.contains(from), "{file} has no {from:?}");
    files.set(file, &text.replacen(from, to, 1));
    match Spec::from_files(&files) {
        Ok(_) => Vec::new(),
        Err(e) => e.0.iter().map(ToString::to_string).collect(),
    }
}

#[test]
fn model_maximum_contradicting_its_attribute_is_reported() {
    let problems = builtin_problems_with(
        "psx3xx/models.toml",
        r#"{ id = "142", min = 15 },"#,
        r#"{ id = "142", range = [[15, 999]] },"#,
    );
    // Every model of the set is named, each with its own attribute.
    assert_eq!(problems.len(), 12, "{problems:#?}");
    assert_eq!(
        problems[0],
        r#"psx3xx/models.toml: model "PSE301-8": range of parameter "142" written out (maximum 999); its maximum is the attribute max_speed_rpm = 230: give `min` only"#
    );
}

#[test]
fn model_default_repeating_its_attribute_is_reported() {
    let problems = builtin_problems_with(
        "psx3xx/models.toml",
        r#"{ id = "143", min = 15 },"#,
        r#"{ id = "143", min = 15, default = 230 },"#,
    );
    let written: Vec<&String> = problems
        .iter()
        .filter(|p| p.contains("written out"))
        .collect();
    assert_eq!(written.len(), 12, "{problems:#?}");
    assert_eq!(
        problems[0],
        r#"psx3xx/models.toml: model "PSE301-8": default 230 of parameter "143" written out; it is the same as max (230): leave it out"#
    );
    assert!(
        problems[8].contains("contradicted by max (180)"),
        "{problems:#?}"
    );
}

#[test]
fn parameter_range_where_the_models_give_it_is_reported() {
    let problems = builtin_problems_with(
        "psx3xx/parameters.toml",
        "range_model = true\nmodel_max = \"max_speed_rpm\"\n",
        "range = [[15, 999]]\nrange_model = true\nmodel_max = \"max_speed_rpm\"\n",
    );
    assert_eq!(
        problems,
        vec![
            r#"psx3xx/parameters.toml: parameter "142": a range here and range_model: the models give the range"#
                .to_owned()
        ]
    );
}

#[test]
fn model_needs_the_attribute_its_values_follow_from() {
    let problems = builtin_problems_with("psx3xx/models.toml", "rated_torque_cnm = 100.0, ", "");
    assert_eq!(
        problems,
        vec![
            r#"psx3xx/models.toml: model "PSE301-8": the model has no attribute rated_torque_cnm, which parameter "153" takes its maximum from"#
                .to_owned(),
            r#"psx3xx/models.toml: model "PSE301-8": model "PSE301-8" gives no range for parameter "153""#
                .to_owned(),
            r#"psx3xx/models.toml: model "PSE301-8": model "PSE301-8" gives no default for parameter "153""#
                .to_owned(),
        ]
    );
}

#[test]
fn model_param_set_must_exist() {
    let problems = builtin_problems_with(
        "psx3xx/models.toml",
        "param_set = \"3418\"",
        "param_set = \"3419\"",
    );
    assert!(
        problems.contains(
            &r#"psx3xx/models.toml: model "PSE3418-14": param_set "3419" does not exist"#
                .to_owned()
        ),
        "{problems:#?}"
    );
}
