//! The position/speed/status plot of a positioning case (PSD4xx and PSx3xx): the samples
//! travel in the evidence (a cleanup record with action [`ACTION`], as text in its note,
//! thinned by [`encode`] to min/max envelopes, never dropping the failing cycle) and the
//! HTML report draws them as an inline SVG with [`svg`]: time axis in ms, position and speed
//! panels in the family's units with ticks, the status words compared, a legend, and the
//! failing cycle marked.

use crate::escape;
use crate::svg::{legend, polyline, Frame, Key};
use std::fmt::Write as _;

/// Action of the evidence record that carries the plot data.
pub const ACTION: &str = "plot: position, speed, status (reference vs device)";

/// Runs of up to this many samples are kept whole; longer ones are thinned.
pub const MAX_POINTS: usize = 400;

/// Time slices of a thinned run: each keeps its first sample, the samples with the lowest
/// and highest position and speed of either side, and its first status changes.
const BUCKETS: usize = 200;

/// Status changes kept per time slice of a thinned run.
const CHANGES_PER_BUCKET: usize = 4;

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

/// Plot data read back by [`decode`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plot {
    /// The samples kept, in time order.
    pub samples: Vec<Sample>,
    /// Time (ms) of the cycle where the case failed, when it did.
    pub failed_ms: Option<u64>,
}

/// Units of the plotted quantities, as the family's spec names them (parameter `unit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Units<'a> {
    /// Unit of the position (`increments`, `1/100 mm`).
    pub position: &'a str,
    /// Unit of the speed (`rpm`).
    pub speed: &'a str,
}

/// The samples as text: `t,position,speed,status` of the reference then of the device (`-`
/// where it gave no image) per cycle, `;` between cycles, then `;!t` with the time of
/// sample `failed` when given. Runs longer than [`MAX_POINTS`] are thinned to min/max
/// envelopes per time slice, keeping status changes, the last sample and sample `failed`.
pub fn encode(samples: &[Sample], failed: Option<usize>) -> String {
    let mut out = String::new();
    for i in kept(samples, failed) {
        let Some(s) = samples.get(i) else { continue };
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
    if let Some(s) = failed.and_then(|i| samples.get(i)) {
        let _ = write!(out, ";!{}", s.t_ms);
    }
    out
}

/// The indices of `samples` that [`encode`] writes, in order.
fn kept(samples: &[Sample], failed: Option<usize>) -> Vec<usize> {
    let n = samples.len();
    if n <= MAX_POINTS {
        return (0..n).collect();
    }
    let per = n.div_ceil(BUCKETS);
    let mut keep: Vec<usize> = Vec::new();
    let quantities: [fn(&Sample) -> Option<i64>; 4] = [
        |s| Some(s.reference.0),
        |s| Some(s.reference.1),
        |s| s.dut.map(|d| d.0),
        |s| s.dut.map(|d| d.1),
    ];
    let status = |s: &Sample| (s.reference.2, s.dut.map(|d| d.2));
    for start in (0..n).step_by(per) {
        let slice = samples.get(start..(start + per).min(n)).unwrap_or(&[]);
        keep.push(start);
        for q in quantities {
            let values = slice
                .iter()
                .enumerate()
                .filter_map(|(i, s)| q(s).map(|v| (i, v)));
            if let Some((i, _)) = values.clone().min_by_key(|(_, v)| *v) {
                keep.push(start + i);
            }
            if let Some((i, _)) = values.max_by_key(|(_, v)| *v) {
                keep.push(start + i);
            }
        }
        let changes = (start.max(1)..start + slice.len())
            .filter(|i| {
                let pair = (samples.get(i - 1), samples.get(*i));
                matches!(pair, (Some(a), Some(b)) if status(a) != status(b))
            })
            .take(CHANGES_PER_BUCKET);
        keep.extend(changes);
    }
    keep.push(n - 1);
    keep.extend(failed.filter(|i| *i < n));
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// Parses [`encode`]'s text; None when it is not plot data.
pub fn decode(text: &str) -> Option<Plot> {
    let mut failed_ms = None;
    let mut samples = Vec::new();
    for p in text.split(';') {
        if let Some(t) = p.strip_prefix('!') {
            failed_ms = Some(t.parse().ok()?);
            continue;
        }
        let f: Vec<&str> = p.split(',').collect();
        let num = |i: usize| f.get(i).and_then(|x| x.parse::<i64>().ok());
        let st = |i: usize| f.get(i).and_then(|x| x.parse::<u16>().ok());
        let reference = (num(1)?, num(2)?, st(3)?);
        let dut = match (num(4), num(5), st(6)) {
            (Some(a), Some(b), Some(c)) => Some((a, b, c)),
            _ => None,
        };
        samples.push(Sample {
            t_ms: f.first()?.parse().ok()?,
            reference,
            dut,
        });
    }
    Some(Plot { samples, failed_ms })
}

/// Colour and style of the reference's lines.
const REFERENCE: &str = "stroke=\"#0057b3\" stroke-width=\"2\"";
/// Colour and style of the device's lines.
const DEVICE: &str = "stroke=\"#e07000\" stroke-width=\"1.5\" stroke-dasharray=\"4 2\"";
/// Colour and style of the failure marker.
const FAILURE: &str = "stroke=\"#d00000\" stroke-width=\"1.5\"";
/// Status strip colours: the words agree, they differ.
const SAME: &str = "#9c9";
const DIFFERENT: &str = "#e66";

/// Page width of a plot (px).
const WIDTH: f64 = 760.0;
/// Left edge of the panels (px): room for tick labels and the turned axis title.
const LEFT: f64 = 90.0;

/// An inline SVG (`<svg class="plot">`) of the plot data in `note` with the quantities in
/// `units`: a legend (reference, device, the failure marker, the status strip's colours), a
/// position and a speed panel over time (ms) with ticks and titled axes, a strip where the
/// status words agree or differ, and a vertical marker with the failing cycle's time; None
/// when `note` is not plot data.
pub fn svg(note: &str, units: Units<'_>) -> Option<String> {
    let plot = decode(note)?;
    let samples = &plot.samples;
    let (first, last) = (samples.first()?, samples.last()?);
    // Time runs from the case's start (0 ms).
    let t0 = 0.0_f64.min(first.t_ms as f64);
    let t1 = (last.t_ms as f64).max(t0 + 1.0);
    let width = WIDTH - LEFT - 15.0;
    let (pos_top, pos_h, speed_top, speed_h) = (30.0, 130.0, 190.0, 100.0);
    let strip_top = speed_top + speed_h + 44.0;
    let height = strip_top + 22.0;
    let mut out = format!(
        "<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{height}\" viewBox=\"0 0 {WIDTH} {height}\" font-family=\"sans-serif\" font-size=\"11\">"
    );
    let mut keys = vec![
        (Key::Line(REFERENCE), "reference"),
        (Key::Line(DEVICE), "device"),
    ];
    let failure_label = plot.failed_ms.map(|t| format!("failure at {t} ms"));
    if let Some(l) = &failure_label {
        keys.push((Key::Line(FAILURE), l.as_str()));
    }
    keys.push((Key::Fill(SAME), "status same"));
    keys.push((Key::Fill(DIFFERENT), "status differs"));
    out.push_str(&legend(LEFT, 14.0, &keys));
    let panels = [
        (
            pos_top,
            pos_h,
            format!("position ({})", units.position),
            0usize,
        ),
        (speed_top, speed_h, format!("speed ({})", units.speed), 1),
    ];
    for (top, h, title, which) in &panels {
        let pick = |v: (i64, i64, u16)| if *which == 0 { v.0 } else { v.1 } as f64;
        let values = samples
            .iter()
            .flat_map(|s| std::iter::once(pick(s.reference)).chain(s.dut.map(pick)));
        let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        // A flat line sits mid-panel with whole-number ticks.
        let pad = ((hi - lo) * 0.05).max(2.0);
        let frame = Frame {
            left: LEFT,
            top: *top,
            width,
            height: *h,
            x: (t0, t1),
            y: (lo - pad, hi + pad),
        };
        let x_title = (*which == 1).then_some("time (ms)");
        out.push_str(&frame.axes(x_title, title));
        let r: Vec<(f64, f64)> = samples
            .iter()
            .map(|s| (frame.x(s.t_ms as f64), frame.y(pick(s.reference))))
            .collect();
        out.push_str(&polyline(&r, REFERENCE));
        // The device's line breaks where it gave no image.
        for run in samples.split(|s| s.dut.is_none()) {
            let d: Vec<(f64, f64)> = run
                .iter()
                .filter_map(|s| s.dut.map(|v| (frame.x(s.t_ms as f64), frame.y(pick(v)))))
                .collect();
            if !d.is_empty() {
                out.push_str(&polyline(&d, DEVICE));
            }
        }
        if let Some(s) = plot
            .failed_ms
            .and_then(|t| samples.iter().find(|s| s.t_ms == t))
        {
            if let Some(v) = s.dut {
                let _ = write!(
                    out,
                    "<circle class=\"failure-point\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"none\" {FAILURE}/>",
                    frame.x(s.t_ms as f64),
                    frame.y(pick(v))
                );
            }
        }
    }
    // Status strip: green where the words agree, red where they differ; a rectangle per run
    // of cycles with the same two words, until the next sample.
    let strip = Frame {
        left: LEFT,
        top: strip_top,
        width,
        height: 12.0,
        x: (t0, t1),
        y: (0.0, 1.0),
    };
    let _ = write!(
        out,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">status word</text>",
        LEFT - 6.0,
        strip_top + 10.0
    );
    let words = |s: &Sample| (s.reference.2, s.dut.map(|d| d.2));
    let mut i = 0;
    while let Some(s) = samples.get(i) {
        let run = samples
            .get(i..)
            .unwrap_or(&[])
            .iter()
            .take_while(|n| words(n) == words(s))
            .count()
            .max(1);
        i += run;
        let end = samples.get(i).map_or(t1, |n| n.t_ms as f64);
        let same = s.dut.map(|d| d.2) == Some(s.reference.2);
        let x = strip.x(s.t_ms as f64);
        let _ = write!(
            out,
            "<rect x=\"{x:.1}\" y=\"{strip_top:.0}\" width=\"{:.1}\" height=\"12\" fill=\"{}\" shape-rendering=\"crispEdges\"><title>from {} ms: reference {:#06x}, device {}</title></rect>",
            (strip.x(end) - x).max(0.5),
            if same { SAME } else { DIFFERENT },
            s.t_ms,
            s.reference.2,
            s.dut.map_or("none".to_owned(), |d| format!("{:#06x}", d.2))
        );
    }
    if let (Some(t), Some(l)) = (plot.failed_ms, &failure_label) {
        let x = strip.x((t as f64).clamp(t0, t1));
        let anchor = if x > LEFT + width / 2.0 {
            "end"
        } else {
            "start"
        };
        let nudge = if anchor == "end" { -4.0 } else { 4.0 };
        let _ = write!(
            out,
            "<g class=\"failure-marker\"><line x1=\"{x:.1}\" y1=\"{pos_top:.0}\" x2=\"{x:.1}\" y2=\"{:.0}\" {FAILURE} stroke-dasharray=\"6 3\" stroke-opacity=\"0.7\"/><text x=\"{:.1}\" y=\"{:.0}\" fill=\"#d00000\" text-anchor=\"{anchor}\">{}</text><title>{}</title></g>",
            strip_top + 12.0,
            x + nudge,
            pos_top + 12.0,
            escape(l),
            escape(l)
        );
    }
    out.push_str("</svg>");
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const UNITS: Units<'static> = Units {
        position: "increments",
        speed: "rpm",
    };

    fn run(n: u64) -> Vec<Sample> {
        (0..n)
            .map(|i| Sample {
                t_ms: i * 10,
                reference: (i as i64 * 8, 30, 0x40),
                dut: (i % 7 != 0).then_some((i as i64 * 8, 30, 0x40)),
            })
            .collect()
    }

    #[test]
    fn short_runs_are_kept_whole() {
        let samples = run(50);
        let text = encode(&samples, None);
        assert_eq!(decode(&text).unwrap().samples, samples);
        assert!(decode("hello").is_none());
    }

    #[test]
    fn long_runs_keep_the_envelope_the_changes_and_the_failing_cycle() {
        let mut samples = run(5000);
        // A one-cycle glitch, a status change and the failure all inside thinned slices.
        samples[1011].dut = Some((8088, 16_584, 0x40));
        samples[2503].reference.2 = 0x41;
        let text = encode(&samples, Some(3007));
        let back = decode(&text).unwrap();
        assert!(back.samples.len() < 5000 / 4, "{}", back.samples.len());
        assert_eq!(back.samples.last().unwrap().t_ms, 49_990);
        assert!(back
            .samples
            .iter()
            .any(|s| s.dut.is_some_and(|d| d.1 == 16_584)));
        assert!(back.samples.iter().any(|s| s.t_ms == 25_030));
        assert!(back.samples.iter().any(|s| s.t_ms == 25_040));
        assert!(back.samples.iter().any(|s| s.t_ms == 30_070));
        assert_eq!(back.failed_ms, Some(30_070));
    }

    #[test]
    fn the_plot_has_axes_units_a_legend_and_the_failure_marker() {
        let mut samples = run(300);
        samples[101].dut = Some((808, 16_584, 0x40));
        let svg = svg(&encode(&samples, Some(101)), UNITS).unwrap();
        assert!(svg.starts_with("<svg class=\"plot\"") && svg.ends_with("</svg>"));
        assert_eq!(svg.matches("<g class=\"axis x\"").count(), 2);
        assert_eq!(svg.matches("<g class=\"axis y\"").count(), 2);
        for title in [
            "time (ms)",
            "position (increments)",
            "speed (rpm)",
            "status word",
        ] {
            assert!(svg.contains(&format!(">{title}</text>")), "{title}");
        }
        // Time ticks over 0…2990 ms, speed ticks up to the glitch.
        assert!(svg.contains(">1000</text>") && svg.contains(">2500</text>"));
        assert!(svg.contains(">15000</text>"));
        let legend = svg.split("<g class=\"legend\">").nth(1).unwrap();
        let legend = legend.split("</g>").next().unwrap();
        for key in [
            "reference",
            "device",
            "failure at 1010 ms",
            "status differs",
        ] {
            assert!(legend.contains(&format!(">{key}</text>")), "{key}");
        }
        assert!(svg.contains("<g class=\"failure-marker\">"));
        assert_eq!(svg.matches("class=\"failure-point\"").count(), 2);
        // The device's line breaks at each cycle without an image: 43 runs per panel.
        assert_eq!(svg.matches(DEVICE).count(), 2 * 43 + 1);
    }

    #[test]
    fn a_passing_plot_has_no_failure_marker() {
        let svg = svg(&encode(&run(20), None), UNITS).unwrap();
        assert!(!svg.contains("failure"));
        assert!(svg.contains(">reference</text>"));
    }
}
