//! The position/speed/status plot of a positioning case (PSD4xx and PSx3xx): the samples
//! travel in the evidence (a cleanup record with action [`ACTION`], at most [`MAX_POINTS`]
//! samples as text in its note) and the HTML report draws them as a small inline SVG with
//! [`svg`].

use crate::svg::polyline;
use std::fmt::Write as _;

/// Action of the evidence record that carries the plot data.
pub const ACTION: &str = "plot: position, speed, status (reference vs device)";

/// Most samples kept per plot.
pub const MAX_POINTS: usize = 80;

/// One cycle: time, and (position, speed, status) of the reference and of the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    /// Time (ms).
    pub t_ms: u64,
    /// Reference: position, speed, status word.
    pub reference: (i64, i64, u16),
    /// Device: position, speed, status word; None when it gave no image.
    pub dut: Option<(i64, i64, u16)>,
}

/// The samples as text, thinned to at most [`MAX_POINTS`] (always keeping the last).
pub fn encode(samples: &[Sample]) -> String {
    let step = samples.len().div_ceil(MAX_POINTS).max(1);
    let mut out = String::new();
    let last = samples.len().saturating_sub(1);
    for (i, s) in samples.iter().enumerate() {
        if i % step != 0 && i != last {
            continue;
        }
        if !out.is_empty() {
            out.push(';');
        }
        let (rp, rs, rst) = s.reference;
        let _ = write!(out, "{},{rp},{rs},{rst}", s.t_ms);
        match s.dut {
            Some((dp, ds, dst)) => {
                let _ = write!(out, ",{dp},{ds},{dst}");
            }
            None => out.push_str(",-,-,-"),
        }
    }
    out
}

/// Parses [`encode`]'s text; None when it is not plot data.
pub fn decode(text: &str) -> Option<Vec<Sample>> {
    text.split(';')
        .map(|p| {
            let f: Vec<&str> = p.split(',').collect();
            let num = |i: usize| f.get(i).and_then(|x| x.parse::<i64>().ok());
            let st = |i: usize| f.get(i).and_then(|x| x.parse::<u16>().ok());
            let reference = (num(1)?, num(2)?, st(3)?);
            let dut = match (num(4), num(5), st(6)) {
                (Some(a), Some(b), Some(c)) => Some((a, b, c)),
                _ => None,
            };
            Some(Sample {
                t_ms: f.first()?.parse().ok()?,
                reference,
                dut,
            })
        })
        .collect()
}

/// An inline SVG (about 2 KB) of the plot data in `note`; None when `note` is not plot data.
pub fn svg(note: &str) -> Option<String> {
    let samples = decode(note)?;
    let (first, last) = (samples.first()?, samples.last()?);
    let (w, ph) = (420.0_f64, 60.0_f64);
    let t0 = first.t_ms as f64;
    let span = ((last.t_ms as f64) - t0).max(1.0);
    let x = |t: u64| 40.0 + (t as f64 - t0) / span * (w - 50.0);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{}\" font-size=\"9\">",
        ph * 2.0 + 40.0
    );
    for (panel, name) in [(0usize, "position"), (1, "speed")] {
        let pick = |v: (i64, i64, u16)| if panel == 0 { v.0 } else { v.1 } as f64;
        let values = samples
            .iter()
            .flat_map(|s| std::iter::once(pick(s.reference)).chain(s.dut.map(pick)));
        let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        let range = (hi - lo).max(1.0);
        let top = 5.0 + panel as f64 * (ph + 10.0);
        let y = |v: f64| top + ph - (v - lo) / range * ph;
        let _ = write!(
            out,
            "<text x=\"0\" y=\"{:.0}\">{name}</text><text x=\"0\" y=\"{:.0}\" fill=\"#777\">{hi:.0}</text><text x=\"0\" y=\"{:.0}\" fill=\"#777\">{lo:.0}</text>",
            top + ph / 2.0,
            top + 8.0,
            top + ph
        );
        let r: Vec<(f64, f64)> = samples
            .iter()
            .map(|s| (x(s.t_ms), y(pick(s.reference))))
            .collect();
        let d: Vec<(f64, f64)> = samples
            .iter()
            .filter_map(|s| s.dut.map(|v| (x(s.t_ms), y(pick(v)))))
            .collect();
        out.push_str(&polyline(&r, "stroke=\"#0057b3\" stroke-width=\"2\""));
        out.push_str(&polyline(
            &d,
            "stroke=\"#e07000\" stroke-width=\"1\" stroke-dasharray=\"3 2\"",
        ));
    }
    // Status strip: green where the words agree, red where they differ.
    let top = 5.0 + 2.0 * (ph + 10.0);
    let _ = write!(out, "<text x=\"0\" y=\"{:.0}\">status</text>", top + 8.0);
    let bw = ((w - 50.0) / samples.len() as f64).max(1.0);
    for s in &samples {
        let same = s.dut.map(|d| d.2) == Some(s.reference.2);
        let _ = write!(
            out,
            "<rect x=\"{:.1}\" y=\"{top:.0}\" width=\"{bw:.1}\" height=\"10\" fill=\"{}\"><title>{} ms: reference {:#06x}, device {}</title></rect>",
            x(s.t_ms),
            if same { "#9c9" } else { "#e66" },
            s.t_ms,
            s.reference.2,
            s.dut.map_or("none".to_owned(), |d| format!("{:#06x}", d.2))
        );
    }
    let _ = write!(
        out,
        "<text x=\"40\" y=\"{:.0}\" fill=\"#0057b3\">reference</text><text x=\"110\" y=\"{:.0}\" fill=\"#e07000\">device</text><text x=\"170\" y=\"{:.0}\" fill=\"#777\">{t0:.0}–{:.0} ms</text></svg>",
        top + 24.0,
        top + 24.0,
        top + 24.0,
        last.t_ms
    );
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodes_thins_and_draws() {
        let samples: Vec<Sample> = (0..500)
            .map(|i| Sample {
                t_ms: i * 10,
                reference: (i as i64 * 8, 30, 0x40),
                dut: (i % 7 != 0).then_some((i as i64 * 8, 30, 0x40)),
            })
            .collect();
        let text = encode(&samples);
        let back = decode(&text).unwrap();
        assert!(back.len() <= MAX_POINTS + 1);
        assert_eq!(back.last().unwrap().t_ms, 4990);
        let svg = svg(&text).unwrap();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.len() < 16_000, "{}", svg.len());
        assert!(decode("hello").is_none());
    }
}
