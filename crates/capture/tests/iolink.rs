//! IO-Link master logs (IOLINK-LOG.md): the documented examples, errors with line numbers,
//! and no panic on any input.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::iolink::{
    Access, CsvReader, IoLinkError, IoLinkEvent, IoLinkKind, IoLinkReader, IsduResult,
};
use proptest::prelude::*;

/// The examples of IOLINK-LOG.md, taken from the file itself.
fn example(lang: &str) -> String {
    let doc = include_str!("../IOLINK-LOG.md");
    let start = doc.find(&format!("```{lang}\n")).unwrap() + lang.len() + 4;
    let len = doc[start..].find("```").unwrap();
    doc[start..start + len].to_string()
}

fn read(text: &str) -> (Vec<IoLinkEvent>, Vec<String>) {
    let mut events = Vec::new();
    let mut errors = Vec::new();
    for item in IoLinkReader::open(text.as_bytes()).unwrap() {
        match item {
            Ok(e) => events.push(e),
            Err(e) => errors.push(e.to_string()),
        }
    }
    (events, errors)
}

#[test]
fn the_documented_json_example() {
    let (events, errors) = read(&example("json"));
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(events.len(), 6);
    assert_eq!(events[0].line, 1);
    assert_eq!((events[0].time, events[0].port), (Some(0), Some(1)));
    assert_eq!(
        events[0].kind,
        IoLinkKind::ProcessData {
            out: Some(vec![0, 1]),
            input: Some(vec![0, 0, 0x0a, 0x2b, 0x10])
        }
    );
    assert_eq!(
        events[1].kind,
        IoLinkKind::IsduRequest {
            access: Access::Write,
            index: 193,
            subindex: 0,
            data: vec![0xfb]
        }
    );
    assert_eq!(
        events[2].kind,
        IoLinkKind::IsduResponse {
            index: Some(193),
            subindex: None,
            result: IsduResult::Data(vec![])
        }
    );
    assert!(matches!(
        events[3].kind,
        IoLinkKind::IsduRequest { access: Access::Read, index: 16, ref data, .. } if data.is_empty()
    ));
    assert_eq!(
        events[4].kind,
        IoLinkKind::IsduResponse {
            index: Some(16),
            subindex: None,
            result: IsduResult::Error(0x8011)
        }
    );
    assert_eq!(events[5].time, Some(1_704_189_600_500_000));
    assert_eq!(
        events[5].kind,
        IoLinkKind::PortEvent {
            code: 0x1800,
            qualifier: Some(0xe4),
            text: Some("temperature fault".into())
        }
    );
}

#[test]
fn the_documented_csv_example_matches_the_json_one() {
    let (csv, errors) = read(&example("csv"));
    assert!(errors.is_empty(), "{errors:?}");
    let (json, _) = read(&example("json"));
    assert_eq!(csv.len(), 5);
    assert_eq!(csv[0].line, 2, "line numbers count the header");
    for (c, j) in csv.iter().zip(json.iter().filter(|e| e.line != 4)).take(4) {
        assert_eq!((c.time, c.port, &c.kind), (j.time, j.port, &j.kind));
    }
    assert!(matches!(
        &csv[4].kind,
        IoLinkKind::PortEvent { text: Some(t), .. } if t == "temperature fault, port 1"
    ));
}

#[test]
fn errors_name_the_line_and_reading_goes_on() {
    let text = r#"{"kind":"pd","out":"01"}
{"kind":"pd"}
{"kind":"isdu_req","rw":"read","index":1,"data":"00"}
{"kind":"isdu_req","rw":"write","index":70000,"data":"00"}
{"kind":"pd","out":"0g"}
{"kind":"pd","out":"01","colour":"red"}
{"kind":"isdu_res","data":"01","error":1}
{"kind":"event"}
{"kind":"nope"}
not json
{"kind":"pd","in":"02","time":"yesterday"}
{"kind":"event","code":1,"index":2}
{"kind":"pd","in":"03"}
"#;
    let (events, errors) = read(text);
    assert_eq!(events.len(), 2);
    assert_eq!(events[1].line, 13);
    let expected = [
        "line 2: field `out`: a `pd` line needs `out` or `in`",
        "line 3: field `data`: a read request carries no data",
        "line 4: field `index`: 70000 is more than 65535",
        "line 5: field `out`: `0g` is not hex bytes",
        "line 6: unknown field `colour`",
        "line 7: field `error`: a response has data or an error, not both",
        "line 8: field `code`: missing",
        "line 9: field `kind`: `nope` is not pd, isdu_req, isdu_res or event",
        "line 10: expected ident",
        "line 11: field `time`: `yesterday` is neither microseconds nor ISO 8601",
        "line 12: field `index`: not allowed for kind `event`",
    ];
    assert_eq!(errors.len(), expected.len(), "{errors:#?}");
    for (got, want) in errors.iter().zip(expected) {
        assert!(got.starts_with(want), "{got} vs {want}");
    }
}

#[test]
fn csv_header_and_row_errors() {
    // An unknown column: not detected as an IO-Link log; read as CSV anyway, a header error.
    assert!(matches!(
        IoLinkReader::open(&b"time,kind,colour\n"[..]),
        Err(IoLinkError::NotIoLink(_))
    ));
    let errors: Vec<String> = CsvReader::new(&b"time,kind,colour\ntime,out\n"[..])
        .map(|e| e.unwrap_err().to_string())
        .collect();
    assert_eq!(
        errors,
        vec![
            "line 1: CSV header: unknown column `colour`",
            "line 2: CSV header: no `kind` column"
        ]
    );
    let (events, errors) = read("kind,out\npd,01\npd\npd,01,02\n\"pd,01\n");
    assert_eq!(events.len(), 1);
    assert_eq!(
        errors,
        vec![
            "line 3: 1 cell(s) where the header has 2",
            "line 4: 3 cell(s) where the header has 2",
            "line 5: 0 cell(s) where the header has 2",
        ]
    );
}

proptest! {
    #[test]
    fn any_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        for prefix in [&b""[..], b"{", b"kind,out,in,index,data,error,code,text\n"] {
            let mut input = prefix.to_vec();
            input.extend_from_slice(&bytes);
            if let Ok(reader) = IoLinkReader::open(&input[..]) {
                for _ in reader {}
            }
        }
    }

    #[test]
    fn any_field_values_never_panic(
        kind in "(pd|isdu_req|isdu_res|event|x)",
        values in proptest::collection::vec("[0-9a-fx:\\- ]{0,12}", 6),
    ) {
        let line = format!(
            "{{\"kind\":\"{kind}\",\"out\":\"{}\",\"index\":\"{}\",\"rw\":\"{}\",\"data\":\"{}\",\"error\":\"{}\",\"time\":\"{}\"}}\n",
            values[0], values[1], values[2], values[3], values[4], values[5]
        );
        if let Ok(reader) = IoLinkReader::open(line.as_bytes()) {
            for _ in reader {}
        }
        let csv = format!("kind,out,index,rw,data,error,time\n{kind},{}\n", values.join(","));
        if let Ok(reader) = IoLinkReader::open(csv.as_bytes()) {
            for _ in reader {}
        }
    }
}
