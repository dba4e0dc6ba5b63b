//! Seeded fault injection (`--drop-answers`, `--corrupt-checksums`, `--corrupt-images`,
//! `--delay-ms`, `--seed`): the same seed and the same traffic always give the same faults.

use super::ServeError;
use crate::rng::Rng;
use drivespec_link::Micros;

/// Faults applied to what the device sends.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Faults {
    /// Probability (0–1) that a message the device sends is not sent.
    pub drop_answers: f64,
    /// Probability (0–1) that a message with a checksum is sent with a wrong one.
    pub corrupt_checksums: f64,
    /// Probability (0–1) that an input image (`IN` reply of `drivespec-cyclic/1`) is sent
    /// with one bit flipped.
    pub corrupt_images: f64,
    /// Extra delay of every message the device sends (µs).
    pub delay_us: Micros,
    /// Seed of the fault decisions.
    pub seed: u64,
}

impl Faults {
    /// Checks that both probabilities lie in 0–1.
    pub fn check(&self) -> Result<(), ServeError> {
        for (name, p) in [
            ("--drop-answers", self.drop_answers),
            ("--corrupt-checksums", self.corrupt_checksums),
            ("--corrupt-images", self.corrupt_images),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return Err(ServeError::Usage(format!(
                    "{name} {p}: a probability from 0 to 1"
                )));
            }
        }
        Ok(())
    }

    /// No fault at all.
    pub fn none(&self) -> bool {
        self.drop_answers == 0.0
            && self.corrupt_checksums == 0.0
            && self.corrupt_images == 0.0
            && self.delay_us == 0
    }

    /// The flags, as `drivespec sim` takes them (for the banner).
    pub fn describe(&self) -> String {
        if self.none() {
            return "no faults".to_owned();
        }
        let mut parts = Vec::new();
        if self.drop_answers > 0.0 {
            parts.push(format!("--drop-answers {}", self.drop_answers));
        }
        if self.corrupt_checksums > 0.0 {
            parts.push(format!("--corrupt-checksums {}", self.corrupt_checksums));
        }
        if self.corrupt_images > 0.0 {
            parts.push(format!("--corrupt-images {}", self.corrupt_images));
        }
        if self.delay_us > 0 {
            parts.push(format!("--delay-ms {}", self.delay_us as f64 / 1000.0));
        }
        parts.push(format!("--seed {}", self.seed));
        parts.join(" ")
    }
}

/// The fault decisions, in the order the device sends its messages.
#[derive(Debug, Clone)]
pub(crate) struct Dice {
    faults: Faults,
    rng: Rng,
}

impl Dice {
    pub(crate) fn new(faults: Faults) -> Dice {
        Dice {
            rng: Rng::new(faults.seed),
            faults,
        }
    }

    /// True with probability `p` (never for 0, always for 1).
    fn chance(&mut self, p: f64) -> bool {
        if p <= 0.0 {
            return false;
        }
        // 53 random bits as a fraction in [0, 1).
        let x = (self.rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        x < p
    }

    /// Whether the next message is dropped.
    pub(crate) fn drop(&mut self) -> bool {
        self.chance(self.faults.drop_answers)
    }

    /// Whether checksums are corrupted at all (so the caller need not look for one).
    pub(crate) fn corrupting(&self) -> bool {
        self.faults.corrupt_checksums > 0.0
    }

    /// Whether the next message with a checksum gets a wrong one.
    pub(crate) fn corrupt(&mut self) -> bool {
        self.chance(self.faults.corrupt_checksums)
    }

    /// Extra delay of every message (µs).
    pub(crate) fn delay(&self) -> Micros {
        self.faults.delay_us
    }

    /// Whether the next input image gets a bit flipped.
    pub(crate) fn corrupt_image(&mut self) -> bool {
        self.chance(self.faults.corrupt_images)
    }

    /// A position in `0..n` (0 when `n` is 0): which bit to flip.
    pub(crate) fn pick(&mut self, n: usize) -> usize {
        let n = u64::try_from(n).unwrap_or(u64::MAX).max(1);
        usize::try_from(self.rng.next_u64() % n).unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_honoured_and_seeded() {
        let f = Faults {
            drop_answers: 0.25,
            corrupt_checksums: 0.5,
            corrupt_images: 0.0,
            delay_us: 0,
            seed: 9,
        };
        let mut a = Dice::new(f);
        let mut b = Dice::new(f);
        let rolls: Vec<(bool, bool)> = (0..4000).map(|_| (a.drop(), a.corrupt())).collect();
        assert!(rolls.iter().all(|x| *x == (b.drop(), b.corrupt())));
        let drops = rolls.iter().filter(|x| x.0).count();
        let corrupt = rolls.iter().filter(|x| x.1).count();
        assert!((800..1200).contains(&drops), "{drops}");
        assert!((1800..2200).contains(&corrupt), "{corrupt}");
        let mut all = Dice::new(Faults {
            drop_answers: 1.0,
            corrupt_checksums: 1.0,
            ..Faults::default()
        });
        assert!((0..100).all(|_| all.drop() && all.corrupt()));
        let mut none = Dice::new(Faults::default());
        assert!((0..100).all(|_| !none.drop() && !none.corrupt() && !none.corrupting()));
        for bad in [-0.1, 1.5, f64::NAN] {
            let f = Faults {
                corrupt_checksums: bad,
                ..Faults::default()
            };
            assert!(f.check().is_err());
        }
    }
}
