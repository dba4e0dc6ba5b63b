//! Running a suite against a legal variant: every case, and what each failure says.

use drivespec_conform::case::{CaseInfo, Failure, Outcome};
use drivespec_conform::suite::Session;

/// The failures of every case of `cases` on `session`, with the case id.
pub fn failures(cases: &[CaseInfo], session: &mut dyn Session) -> Vec<(String, Failure)> {
    cases
        .iter()
        .enumerate()
        .filter_map(|(i, info)| match session.run(i).outcome {
            Outcome::Fail(f) => Some((info.id.clone(), f)),
            _ => None,
        })
        .collect()
}

/// One line per failure: case, message, what the reference allowed and what came.
pub fn describe(variant: &str, failures: &[(String, Failure)]) -> Vec<String> {
    failures
        .iter()
        .map(|(id, f)| {
            format!(
                "{variant}: {id} failed: {}\n  expected {}\n  got      {}",
                f.message, f.expected, f.got
            )
        })
        .collect()
}
