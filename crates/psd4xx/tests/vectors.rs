//! Every `pkw`, `process-image` and `record` vector of `spec/psd4xx/vectors` decodes and
//! encodes byte-exact, and agrees with the PKW rules of manual 3.8 and the record rules of
//! 3.2.2. (`sequence` vectors belong to the reference model.)
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psd4xx::{
    explain_pkw, ClientConfig, Direction, ImageBuilder, Input, Outcome, Output, PkwClient,
    PkwRequest, PkwResponse, RecordRead, RecordValue, RecordWrite, Reply, Request, Rules, Verdict,
};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{FamilyId, IntOrText, Spec, Vector, VectorKind};
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> Rules {
    Rules::from_spec(spec()).unwrap()
}

fn vectors(kind: VectorKind) -> Vec<&'static Vector> {
    spec()
        .family(FamilyId::Psd4xx)
        .vectors
        .iter()
        .filter(|v| v.kind == kind)
        .collect()
}

fn bytes(hex: &Option<String>) -> Option<Vec<u8>> {
    hex.as_deref().map(|h| parse_hex(h).unwrap())
}

/// A PKW block's AK, PNU, IND and PWE as a vector gives them.
type Fields = [Option<i64>; 4];

fn check_fields<C>(id: &str, side: &str, pkw: &drivespec_psd4xx::Pkw<C>, want: Fields)
where
    C: Copy + Into<u8>,
{
    let [ak, pnu, ind, pwe] = want;
    assert_eq!(Some(i64::from(pkw.ak.into())), ak, "{id} {side}: ak");
    assert_eq!(Some(i64::from(pkw.pnu)), pnu, "{id} {side}: pnu");
    assert_eq!(Some(i64::from(pkw.ind)), ind, "{id} {side}: ind");
    assert_eq!(Some(i64::from(pkw.pwe)), pwe, "{id} {side}: pwe");
}

#[test]
fn pkw_vectors() {
    let rules = rules();
    let pkw = rules.pkw();
    let list = vectors(VectorKind::Pkw);
    assert!(list.len() >= 30, "found {} pkw vectors", list.len());
    for v in list {
        let id = v.id.as_str();
        let b = v.pkw().unwrap();
        let (i, e) = (&b.input, &b.expect);
        let req_bytes = bytes(&i.bytes).unwrap();
        let req = PkwRequest::parse(pkw, &req_bytes).unwrap_or_else(|e| panic!("{id}: {e}"));
        check_fields(id, "input", &req, [Some(i.ak), Some(i.pnu), i.ind, i.pwe]);
        assert_eq!(
            req.to_bytes(pkw).unwrap(),
            req_bytes,
            "{id}: request re-encoding"
        );
        let resp_bytes = bytes(&e.bytes).unwrap();
        let resp = PkwResponse::parse(pkw, &resp_bytes).unwrap_or_else(|e| panic!("{id}: {e}"));
        check_fields(id, "expect", &resp, [e.ak, e.pnu, e.ind, e.pwe]);
        assert_eq!(
            resp.to_bytes(pkw).unwrap(),
            resp_bytes,
            "{id}: response re-encoding"
        );

        // The typed meaning round-trips for canonical blocks.
        let request = pkw
            .request(&req)
            .unwrap_or_else(|| panic!("{id}: known command"));
        let reply = pkw
            .reply(&resp)
            .unwrap_or_else(|| panic!("{id}: known response"));
        assert_eq!(
            pkw.encode_reply(&reply).unwrap(),
            resp,
            "{id}: canonical response"
        );
        let canonical = pkw.encode_request(&request).unwrap() == req;
        let notes = explain_pkw(&rules, Direction::Out, &req_bytes)
            .unwrap()
            .notes;
        assert!(
            canonical || !notes.is_empty(),
            "{id}: a non-canonical block is noted"
        );
        assert!(
            canonical || id == "pkw-no-command-after-read",
            "{id}: request not canonical"
        );

        // 3.8: the response is one the command allows.
        let verdict = pkw.verdict(req.ak, resp.ak);
        assert!(
            matches!(verdict, Verdict::Positive | Verdict::Negative),
            "{id}: {verdict:?}"
        );
        if verdict == Verdict::Positive {
            assert_eq!(
                pkw.expected_response(&req),
                Some(resp.ak),
                "{id}: word or double word by the parameter's width"
            );
            assert_ne!(pkw.echo_holds(&req, &resp), Some(false), "{id}: echo");
        } else {
            let Reply::Error { error, .. } = reply else {
                panic!("{id}: negative is an error reply");
            };
            assert!(
                pkw.errors().contains(error),
                "{id}: error {error:?} in the table"
            );
        }
        if let Some(value) = e.value {
            let Reply::Value { value: got, .. } = reply else {
                panic!("{id}: a value reply");
            };
            assert_eq!(got, value, "{id}: signed value");
        }
        if let Some(text) = e.text.as_deref() {
            assert_eq!(
                pkw.segment_text(resp.pnu, resp.pwe).as_deref(),
                Some(text),
                "{id}"
            );
        }

        // The mini-syntax names the request.
        let text = pkw.format_request(&request);
        assert_eq!(pkw.parse_request(&text).unwrap(), request, "{id}: {text}");

        // The client completes the request against a drive giving this response.
        if request == Request::None {
            continue;
        }
        let mut client = PkwClient::new(pkw.clone(), ClientConfig::default());
        let sent = client.submit(req).unwrap();
        let none = pkw.reply_from_text("none").unwrap();
        assert_eq!(client.poll(&none), req, "{id}: command sent at once");
        client.poll(&resp);
        let done = client.next_completion().unwrap();
        assert_eq!(done.id, sent);
        match (verdict, done.outcome) {
            (Verdict::Positive, Outcome::Done { response }) => assert_eq!(response, resp),
            (Verdict::Negative, Outcome::Refused { error, .. }) => {
                assert_eq!(error.0, resp.pwe, "{id}")
            }
            other => panic!("{id}: {other:?}"),
        }
    }
}

#[test]
fn process_image_vectors() {
    let rules = rules();
    let list = vectors(VectorKind::ProcessImage);
    assert!(list.len() >= 8, "found {}", list.len());
    for v in list {
        let id = v.id.as_str();
        let body = v.process_image().unwrap();
        let direction = match body.input.direction.as_str() {
            "out" => Direction::Out,
            "in" => Direction::In,
            other => panic!("{id}: direction {other:?}"),
        };
        let (input, expect) = v.body.tables();
        let (image, named) = match (bytes(&body.input.bytes), bytes(&body.expect.bytes)) {
            (Some(b), None) => (b, expect),
            (None, Some(b)) => {
                // Build from the named fields.
                let mut builder = ImageBuilder::new(&rules, direction);
                for (k, val) in &input {
                    if k != "direction" {
                        builder.set(k, val.as_integer().unwrap()).unwrap();
                    }
                }
                assert_eq!(builder.bytes(), b.as_slice(), "{id}: built image");
                (b, input)
            }
            _ => panic!("{id}: bytes on one side"),
        };
        let fields: Vec<(&str, i64)> = match direction {
            Direction::Out => {
                let out = Output::parse(&rules, &image).unwrap();
                assert_eq!(out.to_bytes(&rules).unwrap(), image, "{id}: re-encoding");
                vec![
                    ("pke", i64::from(out.pkw.pke(rules.pkw()).unwrap())),
                    ("ind", i64::from(out.pkw.ind)),
                    ("pwe", i64::from(out.pkw.pwe)),
                    ("control", i64::from(out.control)),
                    ("target", i64::from(out.target)),
                ]
            }
            Direction::In => {
                let inp = Input::parse(&rules, &image).unwrap();
                assert_eq!(inp.to_bytes(&rules).unwrap(), image, "{id}: re-encoding");
                vec![
                    ("pke", i64::from(inp.pkw.pke(rules.pkw()).unwrap())),
                    ("ind", i64::from(inp.pkw.ind)),
                    ("pwe", i64::from(inp.pkw.pwe)),
                    ("status", i64::from(inp.status)),
                    ("speed", i64::from(inp.speed)),
                    ("actual", i64::from(inp.actual)),
                ]
            }
        };
        for (k, val) in &named {
            if k == "direction" {
                continue;
            }
            let got = fields.iter().find(|(n, _)| n == k).map(|(_, v)| *v);
            assert_eq!(got, val.as_integer(), "{id}: field {k}");
        }
        let e = drivespec_psd4xx::explain(&rules, direction, &image).unwrap();
        assert_eq!(e.fields.len(), fields.len(), "{id}: every field explained");
    }
}

#[test]
fn record_vectors() {
    let rules = rules();
    let rec = rules.record();
    let list = vectors(VectorKind::Record);
    assert!(list.len() >= 9, "found {}", list.len());
    for v in list {
        let id = v.id.as_str();
        let b = v.record().unwrap();
        let index = u16::try_from(b.input.index).unwrap();
        let before = b
            .input
            .state
            .as_ref()
            .and_then(|s| s.get(&index.to_string()));
        let after = b
            .expect
            .state
            .as_ref()
            .and_then(|s| s.get(&index.to_string()));
        match b.input.op.as_str() {
            "write" => {
                let data = bytes(&b.input.data).unwrap();
                let w =
                    RecordWrite::parse(rec, index, &data).unwrap_or_else(|e| panic!("{id}: {e}"));
                assert_eq!(w.to_bytes(rec).unwrap(), data, "{id}: re-encoding");
                assert_eq!(data.len(), rec.write_len(w.width), "{id}: 3 or 5 bytes");
                if w.executes(rec) {
                    assert_eq!(after.copied(), Some(w.value), "{id}");
                } else {
                    assert_eq!(
                        after.map(|a| IntOrText::Int(*a)).as_ref(),
                        before,
                        "{id}: an ignored write changes nothing"
                    );
                }
            }
            "read" => {
                if let Some(data) = bytes(&b.expect.data) {
                    let r = RecordRead::parse(rec, index, &data).unwrap();
                    let RecordValue::Number { width, value } = r.value else {
                        panic!("{id}: a number");
                    };
                    assert_eq!(Some(&IntOrText::Int(value)), before, "{id}");
                    assert_eq!(data.len(), rec.read_len(width), "{id}: 2 or 4 bytes");
                    assert_eq!(r.to_bytes(rec).unwrap(), data, "{id}: re-encoding");
                } else {
                    let text = b.expect.text.as_deref().unwrap();
                    let r = RecordRead {
                        index,
                        value: RecordValue::Text(text.as_bytes().to_vec()),
                    };
                    let data = r.to_bytes(rec).unwrap();
                    assert_eq!(data.last(), Some(&0), "{id}: null-terminated");
                    assert_eq!(RecordRead::parse(rec, index, &data).unwrap(), r, "{id}");
                }
            }
            other => panic!("{id}: op {other:?}"),
        }
    }
}
