//! `drivespec-impl FAMILY NAME`: serves one legal variant or violation mutant on stdin/stdout
//! (an `exec:` device under test); `drivespec-impl FAMILY` lists the names, variants first.
//! `drivespec-impl profinet-fault IFACE STATION [NAME]` serves a PSD4xx PROFINET IO device
//! with a planted fault on a network interface (default: the first of
//! `profinet_faults::NAMES`).

use drivespec_implementations::catalogue::{names, Side};
use drivespec_implementations::profinet_faults;
use drivespec_implementations::serve::serve_stdio;
use drivespec_spec::FamilyId;
use std::process::ExitCode;
use std::time::Duration;

/// A served implementation stops by itself after this long (a runner that died leaves none).
const TIME_LIMIT: Duration = Duration::from_secs(900);

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("profinet-fault") {
        let (Some(iface), Some(station)) = (args.get(1), args.get(2)) else {
            eprintln!("usage: drivespec-impl profinet-fault IFACE STATION [NAME]");
            return ExitCode::from(2);
        };
        let name = args
            .get(3)
            .map_or(profinet_faults::NAMES[0], String::as_str);
        if !profinet_faults::NAMES.contains(&name) {
            eprintln!(
                "drivespec-impl: no PROFINET fault named {name:?}; known: {}",
                profinet_faults::NAMES.join(", ")
            );
            return ExitCode::from(2);
        }
        return match profinet_faults::serve_profinet(iface, station, name, TIME_LIMIT) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("drivespec-impl: {e}");
                ExitCode::from(2)
            }
        };
    }
    let family = args.first().and_then(|f| FamilyId::parse(f));
    match (family, args.get(1)) {
        (Some(family), None) => {
            for side in [Side::Variant, Side::Mutant] {
                for n in names(family, side) {
                    println!(
                        "{}\t{n}",
                        if side == Side::Variant {
                            "variant"
                        } else {
                            "mutant"
                        }
                    );
                }
            }
            ExitCode::SUCCESS
        }
        (Some(family), Some(name)) => match serve_stdio(family, name, TIME_LIMIT) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("drivespec-impl: {e}");
                ExitCode::from(2)
            }
        },
        (None, _) => {
            eprintln!("usage: drivespec-impl hpd|psd4xx|psx3xx [NAME]");
            ExitCode::from(2)
        }
    }
}
