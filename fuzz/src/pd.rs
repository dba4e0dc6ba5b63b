//! Fuzz harnesses of the PSD4xx (bus description 3.5, 3.8, 3.2.2) and PSx3xx (instruction
//! manual 3.1, 3.3) codecs.

use drivespec_positioner::ByteOrder;
use drivespec_psd4xx::{CommandCode, Direction, Pkw, RecordRead, RecordWrite, ResponseCode};
use drivespec_spec::Spec;
use std::sync::OnceLock;

// The `expect`s below cannot fail on any input: the built-in spec and the rules built from it
// are checked by `drivespec spec check` in CI. The re-encoding ones are the harness's
// invariants: a panic there is the finding (see the crate doc).

/// The built-in spec, loaded once.
pub(crate) fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().expect("the built-in spec loads"))
}

/// The PSD4xx codec rules of the built-in spec.
pub(crate) fn psd() -> &'static drivespec_psd4xx::Rules {
    static RULES: OnceLock<drivespec_psd4xx::Rules> = OnceLock::new();
    RULES.get_or_init(|| drivespec_psd4xx::Rules::from_spec(spec()).expect("PSD4xx rules"))
}

/// The PSx3xx codec rules of the built-in spec.
pub(crate) fn psx() -> &'static drivespec_psx3xx::Rules<'static> {
    static RULES: OnceLock<drivespec_psx3xx::Rules<'static>> = OnceLock::new();
    RULES.get_or_init(|| drivespec_psx3xx::Rules::from_spec(spec()).expect("PSx3xx rules"))
}

/// PSD4xx process images: any bytes parse or fail cleanly; a parsed image re-encodes exactly.
pub fn psd4xx_image(data: &[u8]) {
    let rules = psd();
    if let Ok(out) = drivespec_psd4xx::Output::parse(rules, data) {
        assert_eq!(
            out.to_bytes(rules).expect("a decoded value re-encodes"),
            data
        );
    }
    if let Ok(input) = drivespec_psd4xx::Input::parse(rules, data) {
        assert_eq!(
            input.to_bytes(rules).expect("a decoded value re-encodes"),
            data
        );
    }
    for direction in [Direction::Out, Direction::In] {
        if let Ok(e) = drivespec_psd4xx::explain(rules, direction, data) {
            let _ = e.to_string();
        }
    }
}

/// PSD4xx PKW blocks: unknown codes decode and re-encode unchanged.
pub fn psd4xx_pkw(data: &[u8]) {
    let rules = psd().pkw();
    if let Ok(p) = Pkw::<CommandCode>::parse(rules, data) {
        assert_eq!(p.to_bytes(rules).expect("a decoded value re-encodes"), data);
    }
    if let Ok(p) = Pkw::<ResponseCode>::parse(rules, data) {
        assert_eq!(p.to_bytes(rules).expect("a decoded value re-encodes"), data);
    }
}

/// PSD4xx records: the first two bytes pick the index; a parsed record re-encodes exactly.
pub fn psd4xx_record(data: &[u8]) {
    let Some((index, body)) = data.split_first_chunk::<2>() else {
        return;
    };
    let index = u16::from_be_bytes(*index) % 128;
    let rules = psd().record();
    if let Ok(w) = RecordWrite::parse(rules, index, body) {
        assert_eq!(w.to_bytes(rules).expect("a decoded value re-encodes"), body);
    }
    if let Ok(r) = RecordRead::parse(rules, index, body) {
        let _ = r.to_bytes(rules);
    }
}

/// PSx3xx process images of every format and both byte orders; parsed images re-encode exactly.
pub fn psx3xx_image(data: &[u8]) {
    let Some((&sel, bytes)) = data.split_first() else {
        return;
    };
    let rules = psx();
    let order = if sel & 0x80 == 0 {
        rules.wire_order()
    } else {
        rules.wire_order().flipped()
    };
    let format = sel % 4;
    if let Ok(out) = drivespec_psx3xx::Output::parse(rules, format, order, bytes) {
        assert_eq!(
            out.to_bytes(rules, order)
                .expect("a decoded image re-encodes"),
            bytes
        );
    }
    if let Ok(input) = drivespec_psx3xx::Input::parse(rules, order, bytes) {
        assert_eq!(
            input
                .to_bytes(rules, order)
                .expect("a decoded image re-encodes"),
            bytes
        );
    }
    if let Ok(e) = drivespec_psx3xx::explain_output(rules, format, order, None, bytes) {
        let _ = e.to_string();
    }
    if let Ok(e) = drivespec_psx3xx::explain_input(rules, ByteOrder::LittleEndian, None, bytes) {
        let _ = e.to_string();
    }
}

/// PSx3xx ISDU values: bytes 0–2 pick index and sub-index; a decoded value encodes and
/// decodes to itself; requests are checked without panicking.
pub fn psx3xx_isdu(data: &[u8]) {
    let Some((head, body)) = data.split_first_chunk::<3>() else {
        return;
    };
    let rules = psx();
    let index = u16::from_be_bytes([head[0], head[1]]);
    let subindex = head[2];
    let _ = rules.check_read(index, subindex);
    let Ok(target) = rules.isdu_target(index, subindex) else {
        return;
    };
    if let Ok(value) = rules.decode_value(&target, body) {
        if let Ok(bytes) = rules.encode_value(&target, &value) {
            assert_eq!(rules.decode_value(&target, &bytes).ok(), Some(value));
        }
    }
    let _ = drivespec_psx3xx::ErrorType::parse(body);
}

/// PSx3xx Direct Parameter page 1: any bytes at any start address decode or fail cleanly.
pub fn psx3xx_direct(data: &[u8]) {
    let Some((&first, bytes)) = data.split_first() else {
        return;
    };
    let _ = psx().decode_direct(first % 32, bytes);
}
