//! Wall-clock times in text logs (socat headers, our serial text format, IO-Link logs) as
//! microseconds since 1970-01-01T00:00:00 UTC. Times without a zone are taken as UTC.

/// Microseconds since the Unix epoch (UTC), or since any epoch a log uses.
pub type Micros = u64;

/// Days from 1970-01-01 to the given proleptic Gregorian date (H. Hinnant's
/// `days_from_civil`), `None` before 1970 or for an invalid month/day.
fn days_from_civil(year: i64, month: u32, day: u32) -> Option<i64> {
    if !(1..=12).contains(&month) || !(1..=31).contains(&day) {
        return None;
    }
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(month);
    let mp = if m > 2 { m - 3 } else { m + 9 };
    let doy = (153 * mp + 2) / 5 + i64::from(day) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    (days >= 0).then_some(days)
}

fn digits(s: &str, n: usize) -> Option<u32> {
    if s.len() != n || !s.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    s.parse().ok()
}

/// Parses `HH:MM:SS[.fraction]` (1 to 9 fraction digits) into microseconds of the day.
fn time_of_day(s: &str) -> Option<u64> {
    let (hms, frac) = match s.split_once('.') {
        Some((a, b)) => (a, Some(b)),
        None => (s, None),
    };
    let mut parts = hms.split(':');
    let h = digits(parts.next()?, 2)?;
    let m = digits(parts.next()?, 2)?;
    let sec = digits(parts.next()?, 2)?;
    if parts.next().is_some() || h > 23 || m > 59 || sec > 60 {
        return None;
    }
    let micros = match frac {
        None => 0,
        Some(f) if (1..=9).contains(&f.len()) && f.bytes().all(|b| b.is_ascii_digit()) => {
            let mut padded = String::from(f);
            while padded.len() < 6 {
                padded.push('0');
            }
            padded.get(..6)?.parse::<u64>().ok()?
        }
        Some(_) => return None,
    };
    Some((u64::from(h) * 3600 + u64::from(m) * 60 + u64::from(sec)) * 1_000_000 + micros)
}

fn date(s: &str, sep: char) -> Option<i64> {
    let mut parts = s.split(sep);
    let y = digits(parts.next()?, 4)?;
    let mo = digits(parts.next()?, 2)?;
    let d = digits(parts.next()?, 2)?;
    if parts.next().is_some() {
        return None;
    }
    days_from_civil(i64::from(y), mo, d)
}

fn combine(days: i64, tod: u64) -> Option<Micros> {
    u64::try_from(days)
        .ok()?
        .checked_mul(86_400_000_000)?
        .checked_add(tod)
}

/// Parses an ISO 8601 time `YYYY-MM-DDTHH:MM:SS[.f][Z|±HH:MM]` (a blank may replace `T`).
pub fn parse_iso(s: &str) -> Option<Micros> {
    let s = s.trim();
    let (d, rest) = s.split_at_checked(10)?;
    let days = date(d, '-')?;
    let rest = rest.strip_prefix(['T', 't', ' '])?;
    let (clock, offset_secs): (&str, i64) = if let Some(c) = rest.strip_suffix(['Z', 'z']) {
        (c, 0)
    } else if let Some(pos) = rest.rfind(['+', '-']) {
        let (c, zone) = rest.split_at(pos);
        let sign = if zone.starts_with('-') { -1 } else { 1 };
        let zone = zone.get(1..)?;
        let (zh, zm) = zone.split_once(':').or_else(|| zone.split_at_checked(2))?;
        let zh = i64::from(digits(zh, 2)?);
        let zm = i64::from(digits(zm, 2)?);
        (c, sign * (zh * 3600 + zm * 60))
    } else {
        (rest, 0)
    };
    let tod = time_of_day(clock)?;
    let utc = i128::from(combine(days, tod)?) - i128::from(offset_secs) * 1_000_000;
    u64::try_from(utc).ok()
}

/// Parses socat's `YYYY/MM/DD HH:MM:SS.ffffff` header time (taken as UTC).
pub(crate) fn parse_socat(date_part: &str, time_part: &str) -> Option<Micros> {
    combine(date(date_part, '/')?, time_of_day(time_part)?)
}

/// A time in a log: integer microseconds, or an ISO 8601 string.
pub(crate) fn parse_time_field(s: &str) -> Option<Micros> {
    let s = s.trim();
    if !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()) {
        return s.parse().ok();
    }
    parse_iso(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epoch_and_known_dates() {
        assert_eq!(parse_iso("1970-01-01T00:00:00Z"), Some(0));
        // 2024-01-02T10:00:00Z = 1704189600 s.
        assert_eq!(
            parse_iso("2024-01-02T10:00:00.123456Z"),
            Some(1_704_189_600_123_456)
        );
        assert_eq!(
            parse_iso("2024-01-02T11:00:00.5+01:00"),
            Some(1_704_189_600_500_000)
        );
        assert_eq!(
            parse_socat("2024/01/02", "10:00:00.123456789"),
            Some(1_704_189_600_123_456)
        );
        assert_eq!(parse_iso("2024-13-02T10:00:00"), None);
        assert_eq!(parse_iso("1969-12-31T23:59:59Z"), None);
        assert_eq!(parse_time_field("1500"), Some(1500));
    }
}
