//! Prints the PSD4xx checker's report of a generated capture (development aid):
//! `cargo run -p drivespec-check --example psd_trace [FAULT…]`.
use drivespec_capture::profinet::Events;
use drivespec_capture::CaptureReader;
use drivespec_check::profinet::{check, PnOptions};
use drivespec_check::synth::profinet::{psd_capture, PsdFault, PsdScenario};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spec = drivespec_spec::Spec::builtin().map_err(|e| format!("{e:?}"))?;
    let faults: Vec<PsdFault> = std::env::args()
        .skip(1)
        .filter_map(|a| PsdFault::ALL.into_iter().find(|f| format!("{f:?}") == a))
        .collect();
    let t = std::time::Instant::now();
    let bytes = psd_capture(
        &spec,
        &PsdScenario {
            faults,
            ..PsdScenario::default()
        },
    )?;
    eprintln!("{} bytes in {:?}", bytes.len(), t.elapsed());
    let r = check(
        &spec,
        PnOptions::default(),
        Events::new(CaptureReader::new(&bytes[..])?),
    )?;
    print!("{}", drivespec_check::render::text(&[r]));
    Ok(())
}
