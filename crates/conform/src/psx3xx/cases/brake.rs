//! Cases of the brake option (manual 5.4, 5.11–5.13): a drive with a brake turned at
//! standstill after a run, with the release and readjustment bits set, stays where it was
//! turned (PSX-ADJ-010), judged on its own input images; and which cases apply to the brake
//! option the run declares (`--brake`): the readjustment cases (5.4) only without a brake
//! that has no adjustment function, PSX-ADJ-010 only with one.

use super::{env, isdu, step, Gen, PsxCase, StepDef, Still, SETTLE};
use crate::case::Role;
use crate::cyclic::Env;

/// The prefix of the readjustment requirements (5.4).
const READJUSTMENT: &str = "PSX-ADJ-";

/// "Drives with brakes have no adjustment function" (5.4).
const NO_READJUSTMENT: &str = "PSX-ADJ-010";

/// ms a drive may take to start a readjustment after the brake's start wait: longer than the
/// start of any run (chapter 5 fixes no reaction time), so a readjustment shows within it.
const REACTION_MS: u64 = 1000;

/// Steps beyond the positioning window (ISDU 131) the shaft is turned: the window is left
/// clearly (5.4: "leaves the positioning window").
const BEYOND_WINDOW: i64 = 100;

impl Gen<'_, '_> {
    /// The brake option of the drive, when its spec record says it has no adjustment
    /// function (5.4; `[[protocol.brake]] readjustment = false`).
    fn brake_without_readjustment(&self) -> Option<&str> {
        self.brake
            .filter(|b| !b.readjustment)
            .map(|b| b.kind.as_str())
    }

    /// Why a motion case with the requirements `reqs` does not apply to the drive's brake
    /// option: a readjustment case (5.4, PSX-ADJ-001…) on a drive with a brake, which has no
    /// adjustment function; PSX-ADJ-010 on a drive without one. (An ISDU case of an entry a
    /// readjustment requirement names, ISDU 110 or 131, applies either way.)
    pub(super) fn not_applicable(&self, reqs: &[String]) -> Option<String> {
        let readjusts = reqs
            .iter()
            .any(|r| r.starts_with(READJUSTMENT) && r != NO_READJUSTMENT);
        let braked = reqs.iter().any(|r| r == NO_READJUSTMENT);
        match self.brake_without_readjustment() {
            Some(kind) if readjusts => Some(format!(
                "not applicable: the drive has a {kind} brake (--brake {kind}); drives with a brake have no adjustment function (manual 5.4, {NO_READJUSTMENT})"
            )),
            None if braked => Some(format!(
                "not applicable: no brake declared; {NO_READJUSTMENT} concerns drives with a brake (manual 5.4; declare one with --brake)"
            )),
            _ => None,
        }
    }

    /// The brake's wait before a run and time open after it (ISDU 164, 165; 5.12), each in
    /// ms with a step text naming its entry; 0 where the brake or the spec has none.
    fn brake_waits(&self) -> [(u64, String); 2] {
        let wait = |param: Option<&String>| match param {
            Some(p) => (
                u64::try_from(self.value(p)).unwrap_or(0),
                format!(" (ISDU {p})"),
            ),
            None => (0, String::new()),
        };
        let b = self.brake;
        [
            wait(b.and_then(|b| b.start_wait_param.as_ref())),
            wait(b.and_then(|b| b.end_wait_param.as_ref())),
        ]
    }

    /// PSX-ADJ-010: after a run with the release and readjustment bits set, the shaft turned
    /// out of the positioning window at standstill: against the loop, and with control bit 6
    /// (run without loop, where a drive without brake readjusts both ways) in the loop
    /// direction.
    pub(super) fn brake_cases(&mut self) {
        let window = self.value(&self.rules.protocol().motion.window_param);
        let beyond = window.saturating_add(BEYOND_WINDOW);
        let start = self.value(isdu::ACTUAL);
        let target = start.saturating_add(2000);
        let [(start_wait, start_entry), (end_wait, end_entry)] = self.brake_waits();
        let watch = start_wait.saturating_add(REACTION_MS);
        let transfer = self.control("release-and-transfer");
        let readjust = self.control_named("Readjustment");
        let no_loop = self.control_named("Run without loop");
        for (id, description, control, by, way) in [
            (
                "brake/no-readjustment-against-loop",
                "a drive with a brake, turned against the loop at standstill with control bits 4 and 10 set, stays where it was turned",
                transfer | readjust,
                beyond.saturating_neg(),
                "against the loop",
            ),
            (
                "brake/no-readjustment-without-loop",
                "a drive with a brake, turned in the loop direction at standstill with control bits 4, 6 and 10 set, stays where it was turned",
                transfer | readjust | no_loop,
                beyond,
                "in the loop direction",
            ),
        ] {
            let steps: Vec<StepDef> = vec![
                step(
                    Role::Setup,
                    format!("{control:#06x} to start+2000"),
                    self.f1(control, target),
                ),
                step(Role::Setup, "until running", Self::until(true)),
                step(Role::Setup, "until standstill", Self::until(false)),
                step(
                    Role::Setup,
                    format!("{end_wait} ms{end_entry} for the brake to close"),
                    drivespec_psx3xx::step::Step::Hold {
                        cycles: self.cycles_for(end_wait).saturating_add(SETTLE),
                    },
                ),
                step(
                    Role::Setup,
                    format!("turned {way} by {by}"),
                    env(Env::Displace(by)),
                ),
                step(
                    Role::Check,
                    format!(
                        "no adjustment run for {watch} ms (the brake's wait{start_entry} and a start)"
                    ),
                    drivespec_psx3xx::step::Step::Hold {
                        cycles: self.cycles_for(watch),
                    },
                ),
            ];
            let still = Still {
                step: steps.len().saturating_sub(1),
                requirement: NO_READJUSTMENT.to_owned(),
                what: "an adjustment run of a drive with a brake (5.4)".to_owned(),
            };
            self.push(
                format!("psx3xx/{id}"),
                &[NO_READJUSTMENT.to_owned()],
                description.to_owned(),
                PsxCase {
                    still: Some(still),
                    ..PsxCase::motion(self.idle(self.rules.default_format()), steps)
                },
            );
        }
    }
}
