//! The shared codec pieces against the real spec tables (PSD4xx 3.5–3.8, PSx3xx 3.3).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_positioner::{decode_bits, ByteOrder, CodeEntry, CodeTable, Field, FieldError};
use drivespec_spec::{FamilyId, Spec};
use proptest::prelude::*;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

drivespec_positioner::open_enum! {
    /// PSD4xx PKW error code (3.8).
    pub struct ErrorCode(u16);
    /// Error codes by spec name.
    pub struct ErrorCodes {
        /// error 2
        out_of_range = "out-of-range",
        /// error 17
        operating_state = "operating-state",
    }
}

#[test]
fn control_word_bits_from_the_spec() {
    let spec = spec();
    let family = spec.family(FamilyId::Psd4xx);
    let control = family.bitfield("control").unwrap();
    let d = decode_bits(control, 0x14);
    assert_eq!(
        d.set.iter().map(|b| b.bit).collect::<Vec<_>>(),
        vec![2, 4],
        "3.7: bits 2 and 4"
    );
    assert!(d.is_clean());
    assert_eq!(d.value.as_ref().unwrap().name, "release-and-transfer");
    assert_eq!(
        d.to_string(),
        "0x0014: bit 2 Transfer target value, bit 4 Release (release-and-transfer)"
    );
    let bad = decode_bits(control, 0x0808 | 1 << 20);
    assert_eq!(bad.must_be_zero, vec![3, 11]);
    assert_eq!(bad.undefined, vec![20]);
    assert!(!bad.is_clean());
    assert_eq!(
        bad.to_string(),
        "0x100808: bit 3 Reserved, bit 11 Reserved; must be 0: bit 3, 11; undefined: bit 20"
    );
    let json = serde_json::to_value(&bad).unwrap();
    assert_eq!(json["must_be_zero"], serde_json::json!([3, 11]));
    assert_eq!(json["set"][0]["reserved"], serde_json::json!(true));
    let status = family.bitfield("status").unwrap();
    let s = decode_bits(status, 0x4454);
    assert_eq!(
        s.set.iter().map(|b| b.bit).collect::<Vec<_>>(),
        vec![2, 4, 6, 10, 14]
    );
    assert!(s.must_be_zero.is_empty(), "status has no must-be-zero bits");
    assert_eq!(decode_bits(status, 0).to_string(), "0x0000: no bit set");
}

#[test]
fn error_codes_from_the_spec_table() {
    let spec = spec();
    let pkw = &spec.family(FamilyId::Psd4xx).psd4xx().unwrap().pkw;
    let table = CodeTable::new(
        "error",
        pkw.errors
            .iter()
            .map(|e| CodeEntry::new(ErrorCode(e.code), &e.name, &e.meaning, &e.source)),
    )
    .unwrap();
    let known = ErrorCodes::from_table(&table).unwrap();
    assert_eq!(known.out_of_range, ErrorCode(2));
    assert_eq!(known.operating_state, ErrorCode(17));
    assert_eq!(table.named(ErrorCode(2)).to_string(), "out-of-range");
    assert_eq!(
        table.named(ErrorCode(2)).label(),
        Some("lower or upper limit value exceeded")
    );
    assert_eq!(table.named(ErrorCode(99)).to_string(), "0x0063");
}

#[test]
fn spec_orders_convert() {
    let spec = spec();
    let psd = spec.family(FamilyId::Psd4xx).psd4xx().unwrap();
    assert_eq!(ByteOrder::from(psd.byte_order), ByteOrder::BigEndian);
    let psx = spec.family(FamilyId::Psx3xx).psx3xx().unwrap();
    assert_eq!(ByteOrder::from(psx.byte_order.wire), ByteOrder::BigEndian);
}

fn field() -> impl Strategy<Value = Field> {
    (0usize..8, 1usize..=8, prop::bool::ANY).prop_map(|(offset, len, be)| {
        let order = if be {
            ByteOrder::BigEndian
        } else {
            ByteOrder::LittleEndian
        };
        Field::new(offset, len, order).unwrap()
    })
}

proptest! {
    #[test]
    fn unsigned_round_trip(f in field(), v in any::<u64>()) {
        let v = v & f.max_unsigned();
        let mut buf = [0u8; 16];
        f.write_unsigned(&mut buf, v).unwrap();
        prop_assert_eq!(f.read_unsigned(&buf).unwrap(), v);
        // Only the field's bytes change.
        for (i, b) in buf.iter().enumerate() {
            if !f.span().contains(&i) {
                prop_assert_eq!(*b, 0);
            }
        }
    }

    #[test]
    fn signed_round_trip(f in field(), v in any::<i64>()) {
        let (min, max) = f.signed_range();
        let v = v.clamp(min, max);
        let mut buf = [0u8; 16];
        f.write_signed(&mut buf, v).unwrap();
        prop_assert_eq!(f.read_signed(&buf).unwrap(), v);
    }

    #[test]
    fn orders_mirror(f in field(), bytes in prop::collection::vec(any::<u8>(), 16)) {
        let be = f.with_order(ByteOrder::BigEndian).read_unsigned(&bytes).unwrap();
        let mut rev = bytes.clone();
        rev[f.span()].reverse();
        let le = f.with_order(ByteOrder::LittleEndian).read_unsigned(&rev).unwrap();
        prop_assert_eq!(be, le);
    }

    #[test]
    fn short_buffers_are_truncated(f in field(), len in 0usize..16) {
        let buf = vec![0u8; len];
        let r = f.read_unsigned(&buf);
        if len < f.end() {
            prop_assert_eq!(r, Err(FieldError::Truncated { offset: f.offset(), need: f.end(), have: len }));
        } else {
            prop_assert_eq!(r, Ok(0));
        }
    }

    #[test]
    fn any_word_decodes(word in any::<u64>()) {
        for b in &spec().family(FamilyId::Psd4xx).bitfields {
            let d = decode_bits(b, word);
            prop_assert_eq!(d.set.len() + d.undefined.len(), word.count_ones() as usize);
            let _ = d.to_string();
        }
    }
}
