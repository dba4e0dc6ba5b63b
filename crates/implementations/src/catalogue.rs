//! Every implementation by family and name: the legal variants and the violation mutants.

use crate::{hpd_mutants, hpd_variants, psd4xx_mutants, psd4xx_variants};
use crate::{psx3xx_mutants, psx3xx_variants};
use drivespec_cyclic::CyclicDevice;
use drivespec_sim::SimDevice;
use drivespec_spec::FamilyId;

/// Which side of the manual an implementation is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Differs from the reference only where the manual allows: must pass.
    Variant,
    /// Breaks the manual in one planted way: must fail.
    Mutant,
}

/// An implementation ready to run: an HPD drive on the serial line or a cyclic-exchange one.
pub enum Device {
    /// An HPD drive (serial line, manual 4.1).
    Hpd(Box<dyn SimDevice>),
    /// A PSD4xx or PSx3xx drive (`drivespec-cyclic/1`).
    Cyclic(Box<dyn CyclicDevice<'static>>),
}

/// The names of the implementations of `family` on `side`, in their order.
pub fn names(family: FamilyId, side: Side) -> Vec<String> {
    match (family, side) {
        (FamilyId::Hpd, Side::Variant) => hpd_variants::variants()
            .into_iter()
            .map(|(n, _)| n)
            .collect(),
        (FamilyId::Hpd, Side::Mutant) => hpd_mutants::mutants()
            .into_iter()
            .map(|c| c.name.to_owned())
            .collect(),
        (FamilyId::Psd4xx, Side::Variant) => psd4xx_variants::variants()
            .into_iter()
            .map(|(n, _)| n.to_owned())
            .collect(),
        (FamilyId::Psd4xx, Side::Mutant) => psd4xx_mutants::mutants()
            .into_iter()
            .map(|c| c.name.to_owned())
            .collect(),
        (FamilyId::Psx3xx, Side::Variant) => psx3xx_variants::variants()
            .into_iter()
            .map(|(n, _)| n.to_owned())
            .collect(),
        (FamilyId::Psx3xx, Side::Mutant) => psx3xx_mutants::mutants()
            .into_iter()
            .map(|c| c.name.to_owned())
            .collect(),
    }
}

/// The implementation of `family` called `name` (a variant's or a mutant's), if any.
pub fn device(family: FamilyId, name: &str) -> Option<Device> {
    match family {
        FamilyId::Hpd => {
            if let Some((_, k)) = hpd_variants::variants()
                .into_iter()
                .find(|(n, _)| n == name)
            {
                return Some(Device::Hpd(Box::new(hpd_variants::Variant::new(k))));
            }
            let c = hpd_mutants::mutants()
                .into_iter()
                .find(|c| c.name == name)?;
            Some(Device::Hpd(Box::new(hpd_mutants::Mutant::new(c.kind))))
        }
        FamilyId::Psd4xx => {
            if let Some((_, k)) = psd4xx_variants::variants()
                .into_iter()
                .find(|(n, _)| *n == name)
            {
                return Some(Device::Cyclic(Box::new(psd4xx_variants::Variant::new(k))));
            }
            let c = psd4xx_mutants::mutants()
                .into_iter()
                .find(|c| c.name == name)?;
            Some(Device::Cyclic(Box::new(psd4xx_mutants::Mutant::new(
                c.kind,
            ))))
        }
        FamilyId::Psx3xx => {
            if let Some((_, k)) = psx3xx_variants::variants()
                .into_iter()
                .find(|(n, _)| *n == name)
            {
                return Some(Device::Cyclic(Box::new(psx3xx_variants::Variant::new(k))));
            }
            let c = psx3xx_mutants::mutants()
                .into_iter()
                .find(|c| c.name == name)?;
            Some(Device::Cyclic(Box::new(psx3xx_mutants::Mutant::new(
                c.kind,
            ))))
        }
    }
}
