//! Which received frames are passed on: by EtherType (looking through 802.1Q tags) and by
//! source address.

use drivespec_capture::link::{ethertype, parse_ethernet};

/// A receive filter; the default passes every frame.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Filter {
    ether_types: Option<Vec<u16>>,
    skip_from: Option<[u8; 6]>,
}

impl Filter {
    /// Passes every frame.
    pub fn all() -> Self {
        Self::default()
    }

    /// Passes only frames whose EtherType, outside or inside their VLAN tags, is one of
    /// `types` (e.g. [`ethertype::PROFINET`]); listing [`ethertype::VLAN`] passes every
    /// tagged frame.
    pub fn ether_types(types: &[u16]) -> Self {
        Self {
            ether_types: Some(types.to_vec()),
            skip_from: None,
        }
    }

    /// Passes PROFINET frames (0x8892, tagged or not) only.
    pub fn profinet() -> Self {
        Self::ether_types(&[ethertype::PROFINET])
    }

    /// Also drops frames sent from `mac` (an AF_PACKET socket sees its own transmissions).
    pub fn skipping_source(mut self, mac: [u8; 6]) -> Self {
        self.skip_from = Some(mac);
        self
    }

    /// Whether `frame` passes; a frame too short for its Ethernet header never does.
    pub fn passes(&self, frame: &[u8]) -> bool {
        let Ok(link) = parse_ethernet(frame) else {
            return false;
        };
        if self.skip_from.is_some() && link.src == self.skip_from {
            return false;
        }
        match &self.ether_types {
            None => true,
            Some(types) => {
                types.contains(&link.ethertype)
                    || (!link.tags.as_slice().is_empty() && types.contains(&ethertype::VLAN))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DST: [u8; 6] = [0x01, 0x0e, 0xcf, 0, 0, 0];
    const SRC: [u8; 6] = [0x02, 0, 0, 0, 0, 1];

    fn frame(tag: Option<u16>, ty: u16) -> Vec<u8> {
        let mut f = [DST, SRC].concat();
        if let Some(vid) = tag {
            f.extend_from_slice(&ethertype::VLAN.to_be_bytes());
            f.extend_from_slice(&vid.to_be_bytes());
        }
        f.extend_from_slice(&ty.to_be_bytes());
        f.extend_from_slice(&[0xfe, 0xfe, 0x05, 0x00]);
        f
    }

    #[test]
    fn profinet_filter_passes_plain_and_tagged_profinet_only() {
        let f = Filter::profinet();
        assert!(f.passes(&frame(None, ethertype::PROFINET)));
        assert!(f.passes(&frame(Some(0), ethertype::PROFINET)));
        assert!(!f.passes(&frame(None, ethertype::IPV4)));
        assert!(!f.passes(&frame(Some(5), ethertype::IPV4)));
    }

    #[test]
    fn vlan_in_the_list_passes_every_tagged_frame() {
        let f = Filter::ether_types(&[ethertype::VLAN]);
        assert!(f.passes(&frame(Some(5), ethertype::IPV4)));
        assert!(!f.passes(&frame(None, ethertype::IPV4)));
    }

    #[test]
    fn own_frames_and_runts_are_dropped() {
        let f = Filter::all().skipping_source(SRC);
        assert!(!f.passes(&frame(None, ethertype::PROFINET)));
        assert!(Filter::all().passes(&frame(None, ethertype::PROFINET)));
        assert!(!Filter::all().passes(&[0u8; 13]));
    }
}
