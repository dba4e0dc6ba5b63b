//! Which requirement the bytes of a failing HPD answer break, by what differs from the
//! reference's (manual 4.1; 3.3, 3.8.1 bit tables): a response whose data differ only in bits
//! of a bit parameter breaks the rule of those bits; one whose data are the reference's in
//! reverse order breaks the byte order, unless the device showed the right order before; a
//! bit change read back without the bits it wrote breaks the rule of its mask or of its PAR.

use drivespec_hpd::{Data, FrameRules, Message};
use drivespec_spec::{Family, RuleAction};

/// The byte order a response shows against the reference's, when its data tell it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Order {
    /// The reference's multi-byte data, in the same order (least significant byte first).
    Right,
    /// The reference's multi-byte data, bytes reversed.
    Reversed,
}

/// The byte order the device's response `got` shows against the reference's `exp`: None
/// unless both are responses of the same parameter whose data have more than one byte and
/// read differently backwards (manual 4.1 cases 2 and 4, HPD-SERIAL-016).
pub(super) fn byte_order(rules: &FrameRules, exp: &[u8], got: &[u8]) -> Option<Order> {
    let (p, d) = response(rules, exp)?;
    let (q, x) = response(rules, got)?;
    if p != q || d.len() != x.len() || d.len() < 2 || d.as_slice().iter().rev().eq(d.as_slice()) {
        return None;
    }
    if x == d {
        Some(Order::Right)
    } else if x.as_slice().iter().rev().eq(d.as_slice()) {
        Some(Order::Reversed)
    } else {
        None
    }
}

/// The requirement a response of the bit parameter at `par` breaks when its data `got`
/// differ from the reference's `exp` only in bits whose set and reset rules (the bit tables
/// of 3.3, 3.6 and 3.8.1, those of operating mode `mode` for a per-mode table) all name one
/// requirement for the value the reference holds: that requirement. None when a differing
/// bit has no such rule or the rules name several.
pub(super) fn bit_requirement(
    family: &Family,
    mode: Option<u32>,
    par: u8,
    exp: &Data,
    got: &Data,
) -> Option<String> {
    let param = family.parameter_at_address(u32::from(par))?;
    if param.address != Some(u32::from(par)) || exp.len() != got.len() {
        return None;
    }
    let want = exp.unsigned();
    let differ = want ^ got.unsigned();
    if differ == 0 {
        return None;
    }
    let mut found: Option<&str> = None;
    for n in (0..32).filter(|n| differ & (1 << n) != 0) {
        let action = if want & (1 << n) != 0 {
            RuleAction::Set
        } else {
            RuleAction::Reset
        };
        let mut any = false;
        for rule in family
            .bitfields_of(&param.id)
            .filter(|b| b.modes.is_empty() || mode.is_some_and(|m| b.modes.contains(&m)))
            .filter_map(|b| b.bit(n))
            .flat_map(|b| b.rules.iter())
            .filter(|r| r.action == action)
        {
            any = true;
            match found {
                None => found = Some(&rule.requirement),
                Some(f) if f == rule.requirement => {}
                Some(_) => return None,
            }
        }
        if !any {
            return None;
        }
    }
    found.map(str::to_owned)
}

/// The rule of the CMD 6 mask and value (4.1 CMD6): D0 has 0 at the bits to change.
const MASK_RULE: &str = "HPD-FRAME-017";

/// The rule of the CMD 6 PAR (4.1 CMD6): the byte holding the bits, address + 1 for 8–15.
pub(super) const BYTE_RULE: &str = "HPD-FRAME-018";

/// The rule a bit change (CMD 6 at byte `offset` of the parameter, `mask` with 0 at the bits
/// to change, `value` with their new state) breaks, judged by the device's response `got` to
/// a read of the parameter right after it and the reference's `exp`; None when the change
/// took or the bytes do not tell. Where the reference holds the written bits and the device
/// does not: its mask and value were misread ([`MASK_RULE`]) when other bits of the byte
/// differ too, else the change went to another byte ([`BYTE_RULE`]). Where the reference
/// does not hold them (a command bit that clears itself, a drive gone silent): the device
/// took PAR for the other byte of the word ([`BYTE_RULE`]) when that byte holds the written
/// bits there and the reference's does not.
pub(super) fn bit_change_broken(
    rules: &FrameRules,
    offset: usize,
    mask: u8,
    value: u8,
    exp: &[u8],
    got: &[u8],
) -> Option<&'static str> {
    let (_, dev) = response(rules, got)?;
    let dev = dev.as_slice();
    let d = *dev.get(offset)?;
    let changed = !mask;
    let want = value & changed;
    if d & changed == want {
        return None;
    }
    let reference = response(rules, exp).map(|(_, data)| data);
    let at = |data: &[u8], k: usize| data.get(k).copied();
    let image = offset ^ 1;
    match reference.as_ref().and_then(|r| at(r.as_slice(), offset)) {
        Some(r) if r & changed == want => Some(if (d ^ r) & mask != 0 {
            MASK_RULE
        } else {
            BYTE_RULE
        }),
        _ => {
            let di = at(dev, image)?;
            let ri = reference.as_ref().and_then(|r| at(r.as_slice(), image));
            (di & changed == want && ri.is_none_or(|ri| ri & changed != want)).then_some(BYTE_RULE)
        }
    }
}

/// The address and data of the response `bytes` hold, if they are one.
fn response(rules: &FrameRules, bytes: &[u8]) -> Option<(u8, Data)> {
    match drivespec_hpd::parse(rules, bytes) {
        Ok(Message::Response { par, data, .. }) => Some((par, data)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use drivespec_spec::{FamilyId, Spec};

    fn data(b: &[u8]) -> Data {
        Data::new(b).unwrap()
    }

    #[test]
    fn a_difference_only_in_b99_3_breaks_the_zero_result_rule() {
        let spec = Spec::builtin().unwrap();
        let family = spec.family(FamilyId::Hpd);
        let pb99 = family.parameter("Pb99").unwrap().address.unwrap();
        let par = u8::try_from(pb99).unwrap();
        let got = bit_requirement(family, None, par, &data(&[0x0A, 0]), &data(&[0x02, 0]));
        assert_eq!(got.as_deref(), Some("HPD-BIT-99-3"));
        // b99.3 and b99.2 differ: their rules name two requirements.
        assert_eq!(
            bit_requirement(family, None, par, &data(&[0x0E, 0]), &data(&[0x02, 0])),
            None
        );
    }

    fn answer(rules: &FrameRules, d: &[u8]) -> Vec<u8> {
        Message::Response {
            addr: 0,
            par: 0x62,
            data: data(d),
        }
        .to_bytes(rules)
        .unwrap()
    }

    #[test]
    fn a_bit_change_read_back_without_its_bits_names_mask_or_byte() {
        let spec = Spec::builtin().unwrap();
        let rules = FrameRules::from_spec(&spec).unwrap();
        let r = |d: &[u8]| answer(&rules, d);
        // Set bit 0 of the high byte (b70.8): mask FE, value 01, byte 1.
        let set =
            |exp: &[u8], got: &[u8]| bit_change_broken(&rules, 1, 0xFE, 0x01, &r(exp), &r(got));
        assert_eq!(set(&[0x00, 0x01], &[0x00, 0x01]), None);
        assert_eq!(set(&[0x00, 0x01], &[0x01, 0x00]), Some(BYTE_RULE));
        assert_eq!(set(&[0x00, 0x01], &[0x00, 0xFF]), None);
        assert_eq!(set(&[0x00, 0x01], &[0x00, 0xFE]), Some(MASK_RULE));
        // A command bit the reference cleared at once: only the other byte tells.
        assert_eq!(set(&[0x00, 0x00], &[0x00, 0x00]), None);
        assert_eq!(set(&[0x00, 0x00], &[0x01, 0x00]), Some(BYTE_RULE));
        // The reference went silent: the device's other byte holds the bits.
        let silent = bit_change_broken(&rules, 1, 0xFE, 0x01, &[], &r(&[0x01, 0x00]));
        assert_eq!(silent, Some(BYTE_RULE));
    }

    #[test]
    fn reversed_data_show_the_byte_order() {
        let spec = Spec::builtin().unwrap();
        let rules = FrameRules::from_spec(&spec).unwrap();
        let bytes = |d: &[u8]| {
            Message::Response {
                addr: 0,
                par: 0x5C,
                data: data(d),
            }
            .to_bytes(&rules)
            .unwrap()
        };
        let exp = bytes(&[0x00, 0x42]);
        assert_eq!(byte_order(&rules, &exp, &exp), Some(Order::Right));
        assert_eq!(
            byte_order(&rules, &exp, &bytes(&[0x42, 0x00])),
            Some(Order::Reversed)
        );
        assert_eq!(byte_order(&rules, &exp, &bytes(&[0x43, 0x00])), None);
        let even = bytes(&[0x42, 0x42]);
        assert_eq!(byte_order(&rules, &even, &even), None);
    }
}
