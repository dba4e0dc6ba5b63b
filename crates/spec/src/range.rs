//! Inclusive integer intervals: the allowed raw values of a parameter.

use serde::{Deserialize, Serialize};
use std::fmt;

/// A union of inclusive raw intervals, e.g. `[[-6, -1], [1, 1]]` for PSD par 96.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "Vec<[i64; 2]>", into = "Vec<[i64; 2]>")]
pub struct Ranges(pub Vec<[i64; 2]>);

impl TryFrom<Vec<[i64; 2]>> for Ranges {
    type Error = &'static str;

    fn try_from(v: Vec<[i64; 2]>) -> Result<Ranges, &'static str> {
        if v.is_empty() {
            return Err("a range needs at least one [min, max] interval");
        }
        Ok(Ranges(v))
    }
}

impl From<Ranges> for Vec<[i64; 2]> {
    fn from(r: Ranges) -> Vec<[i64; 2]> {
        r.0
    }
}

impl Ranges {
    /// One interval.
    pub fn new(min: i64, max: i64) -> Ranges {
        Ranges(vec![[min, max]])
    }

    /// Whether `v` lies in one of the intervals.
    pub fn contains(&self, v: i64) -> bool {
        self.0.iter().any(|[lo, hi]| (*lo..=*hi).contains(&v))
    }

    /// The smallest allowed value.
    pub fn min(&self) -> Option<i64> {
        self.0.iter().map(|[lo, _]| *lo).min()
    }

    /// The largest allowed value.
    pub fn max(&self) -> Option<i64> {
        self.0.iter().map(|[_, hi]| *hi).max()
    }

    /// The intervals.
    pub fn intervals(&self) -> &[[i64; 2]] {
        &self.0
    }
}

impl fmt::Display for Ranges {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, [lo, hi]) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(" or ")?;
            }
            if lo == hi {
                write!(f, "{lo}")?;
            } else {
                write!(f, "{lo}..{hi}")?;
            }
        }
        Ok(())
    }
}
