//! A checked cursor over a byte slice (the shape of rustls `msgs/codec.rs` `Reader`): every
//! read either returns the bytes or says how many were missing, and never panics.

/// The bytes end before a field does, in any layer (our doc: module `bytes`, after rustls
/// `InvalidMessage` and etherparse `LenError`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("truncated at byte {offset}: need {need} byte(s), have {have}")]
pub struct Truncated {
    /// Offset of the field that does not fit, from the start of the parsed unit.
    pub offset: usize,
    /// Bytes the field needs.
    pub need: usize,
    /// Bytes that were left.
    pub have: usize,
}

/// Byte order of multi-byte integers (DCE/RPC data representation, pcap/pcapng sections).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Endian {
    /// Most significant byte first (network order).
    Big,
    /// Least significant byte first.
    Little,
}

/// A cursor over `bytes`.
#[derive(Debug, Clone)]
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Reader<'a> {
        Reader { bytes, pos: 0 }
    }

    /// Offset of the next byte.
    pub(crate) fn pos(&self) -> usize {
        self.pos
    }

    /// Bytes not yet read.
    pub(crate) fn rest(&self) -> &'a [u8] {
        self.bytes.get(self.pos..).unwrap_or(&[])
    }

    pub(crate) fn remaining(&self) -> usize {
        self.rest().len()
    }

    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8], Truncated> {
        let rest = self.rest();
        match rest.split_at_checked(n) {
            Some((head, _)) => {
                self.pos += n;
                Ok(head)
            }
            None => Err(Truncated {
                offset: self.pos,
                need: n,
                have: rest.len(),
            }),
        }
    }

    pub(crate) fn skip(&mut self, n: usize) -> Result<(), Truncated> {
        self.take(n).map(|_| ())
    }

    pub(crate) fn array<const N: usize>(&mut self) -> Result<[u8; N], Truncated> {
        let at = self.pos;
        let have = self.remaining();
        let bytes = self.take(N)?;
        <[u8; N]>::try_from(bytes).map_err(|_| Truncated {
            offset: at,
            need: N,
            have,
        })
    }

    pub(crate) fn u8(&mut self) -> Result<u8, Truncated> {
        self.array::<1>().map(|[b]| b)
    }

    pub(crate) fn u16(&mut self, order: Endian) -> Result<u16, Truncated> {
        let b = self.array::<2>()?;
        Ok(match order {
            Endian::Big => u16::from_be_bytes(b),
            Endian::Little => u16::from_le_bytes(b),
        })
    }

    pub(crate) fn u32(&mut self, order: Endian) -> Result<u32, Truncated> {
        let b = self.array::<4>()?;
        Ok(match order {
            Endian::Big => u32::from_be_bytes(b),
            Endian::Little => u32::from_le_bytes(b),
        })
    }

    pub(crate) fn be16(&mut self) -> Result<u16, Truncated> {
        self.u16(Endian::Big)
    }

    pub(crate) fn be32(&mut self) -> Result<u32, Truncated> {
        self.u32(Endian::Big)
    }
}

/// Reads a big-endian u16 at `at`, if present.
pub(crate) fn be16_at(bytes: &[u8], at: usize) -> Option<u16> {
    let b = bytes.get(at..at.checked_add(2)?)?;
    Some(u16::from_be_bytes(<[u8; 2]>::try_from(b).ok()?))
}
