//! JUnit XML in the form GitHub and GitLab test reporters read: `<testsuites>` with
//! `<testsuite>`s, each with optional `<properties>` and one `<testcase>` per test; a test
//! passes, is skipped, fails, or passes with output.

use crate::escape;
use std::fmt::Write as _;

/// A JUnit document.
#[derive(Debug, Clone, PartialEq)]
pub struct Document {
    /// Name of the `<testsuites>` element (the tool).
    pub name: String,
    /// How much the document says about its suites.
    pub form: Form,
    /// The test suites, in order.
    pub suites: Vec<Suite>,
}

/// How much a document says: test runs are timed and counted everywhere; trace checks count
/// tests and failures per suite only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// `tests`, `failures`, `errors`, `skipped` and `time` on `<testsuites>` and on every
    /// `<testsuite>`; a test case names itself, then its class, then its time; a failure's
    /// text follows its opening tag.
    Timed,
    /// `tests`, `failures` and `errors` on every `<testsuite>`; a test case names its class,
    /// then itself; a failure's text starts on its own line, and a failure without text is
    /// an empty element.
    Counted,
}

/// One `<testsuite>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Suite {
    /// Its name.
    pub name: String,
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
    /// Wall time in milliseconds (written in seconds in the [`Form::Timed`] form).
    pub time_ms: f64,
    /// How it ended.
    pub outcome: Outcome,
}

/// How a test case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Passed.
    Passed,
    /// Passed, with text worth reading (`<system-out>`).
    PassedWithOutput(String),
    /// Not run, or not counted (`<skipped message>`).
    Skipped(String),
    /// Failed (`<failure message type>` with an optional text).
    Failed {
        /// One line.
        message: String,
        /// The `type` attribute.
        kind: String,
        /// The failure's text.
        text: Option<String>,
    },
}

impl Outcome {
    fn failed(&self) -> bool {
        matches!(self, Outcome::Failed { .. })
    }
    fn skipped(&self) -> bool {
        matches!(self, Outcome::Skipped(_))
    }
}

impl Document {
    /// The document as XML.
    pub fn to_xml(&self) -> String {
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = write!(x, "<testsuites name=\"{}\"", escape(&self.name));
        if self.form == Form::Timed {
            counts(&mut x, self.suites.iter().flat_map(|s| &s.cases), self.form);
        }
        x.push_str(">\n");
        for s in &self.suites {
            let _ = write!(x, "  <testsuite name=\"{}\"", escape(&s.name));
            counts(&mut x, &s.cases, self.form);
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
                case(&mut x, c, self.form);
            }
            x.push_str("  </testsuite>\n");
        }
        x.push_str("</testsuites>\n");
        x
    }
}

/// The count attributes of the cases `cases`.
fn counts<'c>(x: &mut String, cases: impl IntoIterator<Item = &'c Case>, form: Form) {
    let cases: Vec<&Case> = cases.into_iter().collect();
    let tests = cases.len();
    let failures = cases.iter().filter(|c| c.outcome.failed()).count();
    let skipped = cases.iter().filter(|c| c.outcome.skipped()).count();
    let ms = cases.iter().map(|c| c.time_ms).sum::<f64>();
    let _ = write!(x, " tests=\"{tests}\" failures=\"{failures}\" errors=\"0\"");
    if form == Form::Timed {
        let _ = write!(x, " skipped=\"{skipped}\" time=\"{:.3}\"", ms / 1000.0);
    }
}

fn case(x: &mut String, c: &Case, form: Form) {
    match form {
        Form::Timed => {
            let _ = write!(
                x,
                "    <testcase name=\"{}\" classname=\"{}\" time=\"{:.3}\"",
                escape(&c.name),
                escape(&c.classname),
                c.time_ms / 1000.0
            );
        }
        Form::Counted => {
            let _ = write!(
                x,
                "    <testcase classname=\"{}\" name=\"{}\"",
                escape(&c.classname),
                escape(&c.name)
            );
        }
    }
    match &c.outcome {
        Outcome::Passed => x.push_str("/>\n"),
        Outcome::PassedWithOutput(text) => {
            let _ = writeln!(
                x,
                ">\n      <system-out>{}</system-out>\n    </testcase>",
                escape(text)
            );
        }
        Outcome::Skipped(message) => {
            let _ = writeln!(
                x,
                ">\n      <skipped message=\"{}\"/>\n    </testcase>",
                escape(message)
            );
        }
        Outcome::Failed {
            message,
            kind,
            text,
        } => {
            let _ = write!(
                x,
                ">\n      <failure message=\"{}\" type=\"{}\"",
                escape(message),
                escape(kind)
            );
            match (form, text) {
                (Form::Timed, t) => {
                    let _ = write!(x, ">{}</failure>", escape(t.as_deref().unwrap_or("")));
                }
                (Form::Counted, Some(t)) => {
                    let _ = write!(x, ">\n{}      </failure>", escape(t));
                }
                (Form::Counted, None) => x.push_str("/>"),
            }
            x.push_str("\n    </testcase>\n");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(form: Form) -> Document {
        Document {
            name: "t<1>".into(),
            form,
            suites: vec![Suite {
                name: "s".into(),
                properties: vec![("seed".into(), "7".into())],
                cases: vec![
                    Case {
                        name: "a".into(),
                        classname: "c".into(),
                        time_ms: 1500.0,
                        outcome: Outcome::Passed,
                    },
                    Case {
                        name: "b".into(),
                        classname: "c".into(),
                        time_ms: 250.0,
                        outcome: Outcome::Failed {
                            message: "m&".into(),
                            kind: "mismatch".into(),
                            text: Some("x\n".into()),
                        },
                    },
                    Case {
                        name: "d".into(),
                        classname: "c".into(),
                        time_ms: 0.0,
                        outcome: Outcome::Skipped("why".into()),
                    },
                ],
            }],
        }
    }

    #[test]
    fn timed_documents_count_and_time_every_suite() {
        assert_eq!(
            doc(Form::Timed).to_xml(),
            concat!(
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n",
                "<testsuites name=\"t&lt;1&gt;\" tests=\"3\" failures=\"1\" errors=\"0\" skipped=\"1\" time=\"1.750\">\n",
                "  <testsuite name=\"s\" tests=\"3\" failures=\"1\" errors=\"0\" skipped=\"1\" time=\"1.750\">\n",
                "    <properties>\n",
                "      <property name=\"seed\" value=\"7\"/>\n",
                "    </properties>\n",
                "    <testcase name=\"a\" classname=\"c\" time=\"1.500\"/>\n",
                "    <testcase name=\"b\" classname=\"c\" time=\"0.250\">\n",
                "      <failure message=\"m&amp;\" type=\"mismatch\">x\n",
                "</failure>\n",
                "    </testcase>\n",
                "    <testcase name=\"d\" classname=\"c\" time=\"0.000\">\n",
                "      <skipped message=\"why\"/>\n",
                "    </testcase>\n",
                "  </testsuite>\n",
                "</testsuites>\n",
            )
        );
    }

    #[test]
    fn counted_documents_carry_tests_and_failures_per_suite() {
        let mut d = doc(Form::Counted);
        if let Some(s) = d.suites.first_mut() {
            s.properties.clear();
            s.cases.push(Case {
                name: "e".into(),
                classname: "c".into(),
                time_ms: 0.0,
                outcome: Outcome::Failed {
                    message: "unreadable".into(),
                    kind: "input".into(),
                    text: None,
                },
            });
        }
        assert_eq!(
            d.to_xml(),
            concat!(
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n",
                "<testsuites name=\"t&lt;1&gt;\">\n",
                "  <testsuite name=\"s\" tests=\"4\" failures=\"2\" errors=\"0\">\n",
                "    <testcase classname=\"c\" name=\"a\"/>\n",
                "    <testcase classname=\"c\" name=\"b\">\n",
                "      <failure message=\"m&amp;\" type=\"mismatch\">\n",
                "x\n",
                "      </failure>\n",
                "    </testcase>\n",
                "    <testcase classname=\"c\" name=\"d\">\n",
                "      <skipped message=\"why\"/>\n",
                "    </testcase>\n",
                "    <testcase classname=\"c\" name=\"e\">\n",
                "      <failure message=\"unreadable\" type=\"input\"/>\n",
                "    </testcase>\n",
                "  </testsuite>\n",
                "</testsuites>\n",
            )
        );
    }
}
