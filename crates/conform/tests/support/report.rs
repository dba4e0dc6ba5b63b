//! A run's JSON report as the snapshot tests compare it: wall times and the tool version
//! normalised, and the coverage matrix (which lists every requirement) cut to the rows and
//! cells of the cases that ran.

/// The report `json` with wall times 0, the tool version `VERSION` and the coverage rows
/// these cases touch.
pub fn normalised(json: &str) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(json).unwrap();
    for c in v["cases"].as_array_mut().unwrap() {
        c["wall_ms"] = 0.into();
    }
    v["tool"]["version"] = "VERSION".into();
    let ran = |c: &&serde_json::Value| c["status"] != "not-run";
    let rows: Vec<serde_json::Value> = v["coverage"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["cases"].as_array().unwrap().iter().any(|c| ran(&c)))
        .map(|r| {
            let mut r = r.clone();
            let run: Vec<serde_json::Value> = r["cases"]
                .as_array()
                .unwrap()
                .iter()
                .filter(ran)
                .cloned()
                .collect();
            r["cases"] = run.into();
            r
        })
        .collect();
    v["coverage"] = rows.into();
    v
}
