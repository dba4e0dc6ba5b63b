//! Inline SVG primitives shared by the plots of the HTML reports: polylines, round axis
//! ticks, a plot frame with labelled axes and a legend.

use crate::escape;
use std::fmt::Write as _;

/// A `<polyline fill="none" {style} points="x,y x,y …"/>` through `points` (one decimal).
pub fn polyline(points: &[(f64, f64)], style: &str) -> String {
    let mut s = format!("<polyline fill=\"none\" {style} points=\"");
    for (i, (x, y)) in points.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{x:.1},{y:.1}");
    }
    s.push_str("\"/>");
    s
}

/// Round tick values within `lo..=hi`: multiples of 1, 2 or 5 × 10^k, at most `max` + 1 of
/// them (at least 2 when the range is not empty); none for a range that is empty or not
/// finite.
pub fn ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) || max == 0 {
        return Vec::new();
    }
    let rough = span / max as f64;
    let magnitude = 10f64.powf(rough.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= rough)
        .unwrap_or(10.0 * magnitude);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .take(max + 1)
        .map(|i| i as f64 * step)
        .collect()
}

/// `v` as a tick label: as many decimals as the tick step needs.
fn label(v: f64, step: f64) -> String {
    let decimals = if step >= 1.0 || step <= 0.0 {
        0
    } else {
        (-step.log10()).ceil() as usize
    };
    let text = format!("{v:.decimals$}");
    // "-0" reads oddly on an axis.
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        text.trim_start_matches('-').to_owned()
    } else {
        text
    }
}

/// A rectangle of the page (px) and the data ranges it shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Left edge (px).
    pub left: f64,
    /// Top edge (px).
    pub top: f64,
    /// Width (px).
    pub width: f64,
    /// Height (px).
    pub height: f64,
    /// Data range shown left to right.
    pub x: (f64, f64),
    /// Data range shown bottom to top.
    pub y: (f64, f64),
}

impl Frame {
    /// The page x (px) of data value `v`.
    pub fn x(&self, v: f64) -> f64 {
        let (lo, hi) = self.x;
        self.left + (v - lo) / (hi - lo).max(f64::MIN_POSITIVE) * self.width
    }

    /// The page y (px) of data value `v`.
    pub fn y(&self, v: f64) -> f64 {
        let (lo, hi) = self.y;
        self.top + self.height - (v - lo) / (hi - lo).max(f64::MIN_POSITIVE) * self.height
    }

    /// The frame, grid lines, ticks and tick labels of both axes (`<g class="axis x">`,
    /// `<g class="axis y">`), the y axis title `y_title` turned along the axis and, when
    /// given, the x axis title `x_title` under the tick labels.
    pub fn axes(&self, x_title: Option<&str>, y_title: &str) -> String {
        let (right, bottom) = (self.left + self.width, self.top + self.height);
        let mut o = format!(
            "<rect class=\"frame\" x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"#999\"/>",
            self.left, self.top, self.width, self.height
        );
        let xs = ticks(self.x.0, self.x.1, (self.width / 70.0).max(2.0) as usize);
        let x_step = step_of(&xs);
        o.push_str("<g class=\"axis x\" text-anchor=\"middle\">");
        for v in &xs {
            let px = self.x(*v);
            let _ = write!(
                o,
                "<line x1=\"{px:.1}\" y1=\"{:.1}\" x2=\"{px:.1}\" y2=\"{bottom:.1}\" stroke=\"#eee\"/><line x1=\"{px:.1}\" y1=\"{bottom:.1}\" x2=\"{px:.1}\" y2=\"{:.1}\" stroke=\"#999\"/><text x=\"{px:.1}\" y=\"{:.1}\">{}</text>",
                self.top,
                bottom + 4.0,
                bottom + 14.0,
                label(*v, x_step)
            );
        }
        if let Some(t) = x_title {
            let _ = write!(
                o,
                "<text class=\"title\" x=\"{:.1}\" y=\"{:.1}\">{}</text>",
                self.left + self.width / 2.0,
                bottom + 28.0,
                escape(t)
            );
        }
        o.push_str("</g><g class=\"axis y\" text-anchor=\"end\">");
        let ys = ticks(self.y.0, self.y.1, (self.height / 25.0).max(2.0) as usize);
        let y_step = step_of(&ys);
        for v in &ys {
            let py = self.y(*v);
            let _ = write!(
                o,
                "<line x1=\"{:.1}\" y1=\"{py:.1}\" x2=\"{right:.1}\" y2=\"{py:.1}\" stroke=\"#eee\"/><line x1=\"{:.1}\" y1=\"{py:.1}\" x2=\"{:.1}\" y2=\"{py:.1}\" stroke=\"#999\"/><text x=\"{:.1}\" y=\"{:.1}\">{}</text>",
                self.left,
                self.left - 4.0,
                self.left,
                self.left - 6.0,
                py + 3.5,
                label(*v, y_step)
            );
        }
        // The title stands clear of the widest tick label (about 6 px a character).
        let widest = ys
            .iter()
            .map(|v| label(*v, y_step).len())
            .max()
            .unwrap_or(1);
        let (tx, ty) = (
            self.left - 14.0 - 6.0 * widest as f64,
            self.top + self.height / 2.0,
        );
        let _ = write!(
            o,
            "<text class=\"title\" x=\"{tx:.1}\" y=\"{ty:.1}\" text-anchor=\"middle\" transform=\"rotate(-90 {tx:.1} {ty:.1})\">{}</text></g>",
            escape(y_title)
        );
        o
    }
}

/// The step between the first two of `ticks` (1 when there are fewer).
fn step_of(ticks: &[f64]) -> f64 {
    match ticks {
        [a, b, ..] => b - a,
        _ => 1.0,
    }
}

/// How a legend entry is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key<'a> {
    /// A line with this SVG style (`stroke="…" …`).
    Line(&'a str),
    /// A filled box of this colour.
    Fill(&'a str),
}

/// A legend row (`<g class="legend">`) starting at (`x`, `y`): each entry's key, then its
/// label.
pub fn legend(x: f64, y: f64, entries: &[(Key<'_>, &str)]) -> String {
    let mut o = String::from("<g class=\"legend\">");
    let mut at = x;
    for (key, text) in entries {
        match key {
            Key::Line(style) => {
                let _ = write!(
                    o,
                    "<line x1=\"{at:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" {style}/>",
                    y - 4.0,
                    at + 22.0,
                    y - 4.0
                );
            }
            Key::Fill(colour) => {
                let _ = write!(
                    o,
                    "<rect x=\"{at:.1}\" y=\"{:.1}\" width=\"22\" height=\"9\" fill=\"{colour}\"/>",
                    y - 9.0
                );
            }
        }
        let _ = write!(
            o,
            "<text x=\"{:.1}\" y=\"{y:.1}\">{}</text>",
            at + 27.0,
            escape(text)
        );
        // About 6 px a character at the plots' font size.
        at += 40.0 + 6.0 * text.chars().count() as f64;
    }
    o.push_str("</g>");
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polylines_join_points_with_spaces() {
        assert_eq!(
            polyline(&[(1.0, 2.0), (3.0, 4.0)], "stroke=\"red\""),
            "<polyline fill=\"none\" stroke=\"red\" points=\"1.0,2.0 3.0,4.0\"/>"
        );
        assert_eq!(
            polyline(&[], "stroke=\"red\""),
            "<polyline fill=\"none\" stroke=\"red\" points=\"\"/>"
        );
    }

    #[test]
    fn ticks_are_round_and_inside_the_range() {
        assert_eq!(
            ticks(0.0, 1000.0, 5),
            vec![0.0, 200.0, 400.0, 600.0, 800.0, 1000.0]
        );
        assert_eq!(ticks(-3.0, 17.0, 4), vec![0.0, 5.0, 10.0, 15.0]);
        assert_eq!(
            ticks(0.1, 0.45, 4),
            vec![0.1, 0.2, 0.30000000000000004, 0.4]
        );
        assert!(ticks(5.0, 5.0, 4).is_empty());
        assert!(ticks(0.0, f64::INFINITY, 4).is_empty());
        assert!(ticks(0.0, 1e9, 8).len() <= 9);
    }

    #[test]
    fn labels_have_the_decimals_the_step_needs() {
        assert_eq!(label(1500.0, 500.0), "1500");
        assert_eq!(label(0.25, 0.05), "0.25");
        assert_eq!(label(-0.0, 1.0), "0");
    }

    #[test]
    fn axes_have_ticks_labels_and_titles() {
        let f = Frame {
            left: 60.0,
            top: 10.0,
            width: 400.0,
            height: 100.0,
            x: (0.0, 2000.0),
            y: (-50.0, 50.0),
        };
        assert!((f.x(1000.0) - 260.0).abs() < 1e-9);
        assert!((f.y(50.0) - 10.0).abs() < 1e-9);
        let a = f.axes(Some("time (ms)"), "speed (rpm)");
        assert!(a.contains("<g class=\"axis x\""));
        assert!(a.contains("<g class=\"axis y\""));
        assert!(a.contains(">time (ms)</text>") && a.contains(">speed (rpm)</text>"));
        assert!(a.contains(">1000</text>") && a.contains(">-50</text>"));
        let l = legend(
            0.0,
            10.0,
            &[
                (Key::Line("stroke=\"red\""), "device"),
                (Key::Fill("#9c9"), "same"),
            ],
        );
        assert!(l.starts_with("<g class=\"legend\">") && l.contains(">device</text>"));
    }
}
