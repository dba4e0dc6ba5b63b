//! Inline SVG primitives shared by the plots of the HTML reports.

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

#[cfg(test)]
mod tests {
    use super::polyline;

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
}
