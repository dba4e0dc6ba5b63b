//! JUnit XML valid against the Jenkins xUnit schema (`junit-10.xsd`) and in the form GitHub
//! and GitLab test reporters read: `<testsuites>` with counts and time, `<testsuite>`s with
//! counts, time, `timestamp` and `hostname`, optional `<properties>`, and one `<testcase name
//! classname time>` per test that passes, is skipped, fails (`<failure>`: the device or the
//! recording broke a rule) or errs (`<error>`: the test could not run, such as an unreadable
//! input), with an optional `<system-out>`.

use crate::escape;
use std::fmt::Write as _;
use std::time::{SystemTime, UNIX_EPOCH};

/// A JUnit document.
#[derive(Debug, Clone, PartialEq)]
pub struct Document {
    /// Name of the `<testsuites>` element (the tool).
    pub name: String,
    /// When the run started, as [`timestamp`] writes it (on every `<testsuite>`).
    pub timestamp: Option<String>,
    /// The machine that ran it (on every `<testsuite>`).
    pub hostname: Option<String>,
    /// The test suites, in order.
    pub suites: Vec<Suite>,
}

/// One `<testsuite>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Suite {
    /// Its name.
    pub name: String,
    /// Its wall time in milliseconds (None: the sum of its cases' times).
    pub time_ms: Option<f64>,
    /// `<property name value>` pairs, in order (none: no `<properties>` element).
    pub properties: Vec<(String, String)>,
    /// Its test cases, in order.
    pub cases: Vec<Case>,
}

/// One `<testcase>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// `name`.
    pub name: String,
    /// `classname`.
    pub classname: String,
    /// Wall time in milliseconds (written in seconds).
    pub time_ms: f64,
    /// How it ended.
    pub outcome: Outcome,
    /// Text worth reading beside the outcome (`<system-out>`): an exchange log, findings.
    pub output: Option<String>,
}

/// How a test case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Passed.
    Passed,
    /// Not run, or not counted (`<skipped message>`).
    Skipped(String),
    /// The thing under test broke a rule (`<failure message type>` with its text).
    Failed(Problem),
    /// The test could not run: unreadable input, unreachable device (`<error message type>`
    /// with its text).
    Errored(Problem),
    /// Passed when run again after failing (`<rerunFailure message type>` with the failure
    /// of the first run, as Maven Surefire writes flaky tests).
    Flaky(Problem),
}

/// What a failure or an error says.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// One line (`message`).
    pub message: String,
    /// The `type` attribute.
    pub kind: String,
    /// The element's text (none: an empty element).
    pub text: Option<String>,
}

impl Document {
    /// The document as XML.
    pub fn to_xml(&self) -> String {
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = write!(x, "<testsuites name=\"{}\"", escape(&self.name));
        let all: Vec<&Case> = self.suites.iter().flat_map(|s| &s.cases).collect();
        let ms = self.suites.iter().map(Suite::wall_ms).sum::<f64>();
        counts(&mut x, &all);
        let _ = write!(x, " time=\"{}\"", seconds(ms));
        x.push_str(">\n");
        for s in &self.suites {
            let _ = write!(x, "  <testsuite name=\"{}\"", escape(&s.name));
            let cases: Vec<&Case> = s.cases.iter().collect();
            counts(&mut x, &cases);
            let skipped = cases
                .iter()
                .filter(|c| matches!(c.outcome, Outcome::Skipped(_)))
                .count();
            let _ = write!(
                x,
                " skipped=\"{skipped}\" time=\"{}\"",
                seconds(s.wall_ms())
            );
            if let Some(t) = &self.timestamp {
                let _ = write!(x, " timestamp=\"{}\"", escape(t));
            }
            if let Some(h) = &self.hostname {
                let _ = write!(x, " hostname=\"{}\"", escape(h));
            }
            x.push_str(">\n");
            if !s.properties.is_empty() {
                x.push_str("    <properties>\n");
                for (k, v) in &s.properties {
                    let _ = writeln!(
                        x,
                        "      <property name=\"{}\" value=\"{}\"/>",
                        escape(k),
                        escape(v)
                    );
                }
                x.push_str("    </properties>\n");
            }
            for c in &s.cases {
                case(&mut x, c);
            }
            x.push_str("  </testsuite>\n");
        }
        x.push_str("</testsuites>\n");
        x
    }
}

impl Suite {
    fn wall_ms(&self) -> f64 {
        self.time_ms.unwrap_or_else(|| {
            self.cases
                .iter()
                .map(|c| c.time_ms)
                .filter(|ms| ms.is_finite() && *ms > 0.0)
                .sum()
        })
    }
}

/// Milliseconds as seconds with three decimals (never negative or not a number).
fn seconds(ms: f64) -> String {
    let s = if ms.is_finite() && ms > 0.0 {
        ms / 1000.0
    } else {
        0.0
    };
    format!("{s:.3}")
}

/// The `tests`, `failures` and `errors` attributes of `cases`.
fn counts(x: &mut String, cases: &[&Case]) {
    let failures = cases
        .iter()
        .filter(|c| matches!(c.outcome, Outcome::Failed(_)))
        .count();
    let errors = cases
        .iter()
        .filter(|c| matches!(c.outcome, Outcome::Errored(_)))
        .count();
    let _ = write!(
        x,
        " tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\"",
        cases.len()
    );
}

fn case(x: &mut String, c: &Case) {
    let _ = write!(
        x,
        "    <testcase name=\"{}\" classname=\"{}\" time=\"{}\"",
        escape(&c.name),
        escape(&c.classname),
        seconds(c.time_ms)
    );
    if c.outcome == Outcome::Passed && c.output.is_none() {
        x.push_str("/>\n");
        return;
    }
    x.push_str(">\n");
    match &c.outcome {
        Outcome::Passed => {}
        Outcome::Skipped(message) => {
            let _ = writeln!(x, "      <skipped message=\"{}\"/>", escape(message));
        }
        Outcome::Failed(p) => problem(x, "failure", p),
        Outcome::Errored(p) => problem(x, "error", p),
        Outcome::Flaky(p) => problem(x, "rerunFailure", p),
    }
    if let Some(out) = &c.output {
        let _ = writeln!(x, "      <system-out>{}</system-out>", escape(out));
    }
    x.push_str("    </testcase>\n");
}

fn problem(x: &mut String, element: &str, p: &Problem) {
    let _ = write!(
        x,
        "      <{element} message=\"{}\" type=\"{}\"",
        escape(&p.message),
        escape(&p.kind)
    );
    match &p.text {
        Some(t) => {
            let _ = writeln!(x, ">{}</{element}>", escape(t));
        }
        None => x.push_str("/>\n"),
    }
}

/// `time` as a JUnit timestamp: UTC, ISO 8601 without a zone (`2026-01-02T10:00:00`), the
/// form Ant, Maven Surefire and the xUnit schemas use.
pub fn timestamp(time: SystemTime) -> String {
    let secs = time.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let days = i64::try_from(secs / 86_400).unwrap_or(0);
    let rest = secs % 86_400;
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}",
        rest / 3600,
        rest % 3600 / 60,
        rest % 60
    )
}

/// The name of this machine: the kernel's host name, else `$HOSTNAME` or `$COMPUTERNAME`,
/// else `localhost`.
pub fn hostname() -> String {
    let from_file = ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .find_map(|f| std::fs::read_to_string(f).ok());
    let from_env = || {
        ["HOSTNAME", "COMPUTERNAME"]
            .iter()
            .find_map(|v| std::env::var(v).ok())
    };
    from_file
        .or_else(from_env)
        .map(|h| h.trim().to_owned())
        .filter(|h| !h.is_empty() && h.len() <= 255)
        .unwrap_or_else(|| "localhost".to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Document {
        Document {
            name: "t<1>".into(),
            timestamp: Some("2026-01-02T10:00:00".into()),
            hostname: Some("ci-1".into()),
            suites: vec![Suite {
                name: "s".into(),
                time_ms: None,
                properties: vec![("seed".into(), "7".into())],
                cases: vec![
                    Case {
                        name: "a".into(),
                        classname: "c".into(),
                        time_ms: 1500.0,
                        outcome: Outcome::Passed,
                        output: None,
                    },
                    Case {
                        name: "b".into(),
                        classname: "c".into(),
                        time_ms: 250.0,
                        outcome: Outcome::Failed(Problem {
                            message: "m&".into(),
                            kind: "mismatch".into(),
                            text: Some("x\n".into()),
                        }),
                        output: Some("sent 7E\n".into()),
                    },
                    Case {
                        name: "d".into(),
                        classname: "c".into(),
                        time_ms: 0.0,
                        outcome: Outcome::Skipped("why".into()),
                        output: None,
                    },
                    Case {
                        name: "e".into(),
                        classname: "c".into(),
                        time_ms: f64::NAN,
                        outcome: Outcome::Errored(Problem {
                            message: "unreadable".into(),
                            kind: "input".into(),
                            text: None,
                        }),
                        output: None,
                    },
                ],
            }],
        }
    }

    #[test]
    fn documents_count_and_time_every_suite_and_stamp_it() {
        assert_eq!(
            doc().to_xml(),
            concat!(
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n",
                "<testsuites name=\"t&lt;1&gt;\" tests=\"4\" failures=\"1\" errors=\"1\" time=\"1.750\">\n",
                "  <testsuite name=\"s\" tests=\"4\" failures=\"1\" errors=\"1\" skipped=\"1\" time=\"1.750\" timestamp=\"2026-01-02T10:00:00\" hostname=\"ci-1\">\n",
                "    <properties>\n",
                "      <property name=\"seed\" value=\"7\"/>\n",
                "    </properties>\n",
                "    <testcase name=\"a\" classname=\"c\" time=\"1.500\"/>\n",
                "    <testcase name=\"b\" classname=\"c\" time=\"0.250\">\n",
                "      <failure message=\"m&amp;\" type=\"mismatch\">x\n",
                "</failure>\n",
                "      <system-out>sent 7E\n",
                "</system-out>\n",
                "    </testcase>\n",
                "    <testcase name=\"d\" classname=\"c\" time=\"0.000\">\n",
                "      <skipped message=\"why\"/>\n",
                "    </testcase>\n",
                "    <testcase name=\"e\" classname=\"c\" time=\"0.000\">\n",
                "      <error message=\"unreadable\" type=\"input\"/>\n",
                "    </testcase>\n",
                "  </testsuite>\n",
                "</testsuites>\n",
            )
        );
    }

    #[test]
    fn a_suite_time_given_overrides_the_sum_of_its_cases() {
        let mut d = doc();
        if let Some(s) = d.suites.first_mut() {
            s.time_ms = Some(20_000.0);
        }
        let x = d.to_xml();
        assert!(x.contains("errors=\"1\" time=\"20.000\">"), "{x}");
        assert!(x.contains("skipped=\"1\" time=\"20.000\" timestamp"), "{x}");
    }

    #[test]
    fn timestamps_are_utc_civil_dates() {
        let at = |s: u64| timestamp(UNIX_EPOCH + std::time::Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00");
        assert_eq!(at(951_782_400), "2000-02-29T00:00:00");
        assert_eq!(at(1_767_348_000), "2026-01-02T10:00:00");
        assert_eq!(at(4_107_542_399), "2100-02-28T23:59:59");
    }

    #[test]
    fn the_host_name_is_never_empty() {
        assert!(!hostname().is_empty());
    }
}
