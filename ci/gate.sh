#!/usr/bin/env bash
# The CI gate: runs `drivespec conform` against a device under test, keeps its exit code and
# tells where the reports are. The GitHub Action (action.yml), the GitLab template
# (ci/gitlab/drivespec.gitlab-ci.yml) and the Docker image (as drivespec-gate) run this
# script; everything comes from the environment:
#
#   DRIVESPEC_FAMILY       hpd, psd4xx, psx3xx or all (required)
#   DRIVESPEC_DUT          device under test: sim[:MODEL], serial:PATH?baud=N, tcp:HOST:PORT,
#                          exec:COMMAND (default sim)
#   DRIVESPEC_EXPECT       expectations file of known failures with reasons (optional)
#   DRIVESPEC_REPORT_DIR   folder of conform.junit.xml, conform.json, conform.html
#                          (default drivespec-reports)
#   DRIVESPEC_ARGS         further conform options, e.g. `--model PSD426 --case 'hpd/frame/*'`
#                          (split like a shell command line, quotes respected, nothing expanded)
#   DRIVESPEC              the drivespec binary (default: `drivespec` on PATH, else the release
#                          build of this checkout, built when missing)
#
# Exit status is conform's: 0 pass, 1 failures, 2 bad usage or unreachable device, 130/143
# when interrupted. SIGINT and SIGTERM are passed on to conform, which writes the reports of
# the cases that ran before it stops. Under GitHub Actions the result also goes to the step
# summary and the step output `exit-code`.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

family=${DRIVESPEC_FAMILY:-}
dut=${DRIVESPEC_DUT:-sim}
expect=${DRIVESPEC_EXPECT:-}
report_dir=${DRIVESPEC_REPORT_DIR:-drivespec-reports}
if [ -z "$family" ]; then
    echo "drivespec-gate: DRIVESPEC_FAMILY is not set (hpd, psd4xx, psx3xx or all)" >&2
    exit 2
fi

bin=${DRIVESPEC:-}
if [ -z "$bin" ]; then
    if command -v drivespec >/dev/null; then
        bin=drivespec
    elif [ -f "$root/crates/cli/Cargo.toml" ]; then
        bin="$root/target/release/drivespec"
        cargo build --release --locked --manifest-path "$root/Cargo.toml" --bin drivespec || exit 2
    else
        echo "drivespec-gate: no drivespec binary: set DRIVESPEC or put drivespec on PATH" >&2
        exit 2
    fi
fi

extra=()
if [ -n "${DRIVESPEC_ARGS:-}" ]; then
    if ! words=$(printf '%s' "$DRIVESPEC_ARGS" | xargs -r -n1 printf '%s\n'); then
        echo "drivespec-gate: cannot split DRIVESPEC_ARGS: $DRIVESPEC_ARGS" >&2
        exit 2
    fi
    if [ -n "$words" ]; then mapfile -t extra <<<"$words"; fi
fi
args=(conform "$family" --dut "$dut" --report-dir "$report_dir")
if [ -n "$expect" ]; then args+=(--expect "$expect"); fi
args+=("${extra[@]}")

echo "drivespec-gate: $("$bin" --version)"
echo "drivespec-gate: $bin ${args[*]}"
# conform runs in a process group of its own (set -m) so that it hears each signal once,
# from the traps below, whether the signal was sent to this script or to its group.
set -m
"$bin" "${args[@]}" &
child=$!
set +m
trap 'kill -INT "$child" 2>/dev/null' INT
trap 'kill -TERM "$child" 2>/dev/null' TERM
status=0
wait "$child" || status=$?
# A trapped signal ends `wait` early: wait again for conform's own exit status.
while kill -0 "$child" 2>/dev/null; do
    status=0
    wait "$child" || status=$?
done
trap - INT TERM

case $status in
0) verdict="passed" ;;
1) verdict="FAILED: unexpected failures (each is in the log above and in the reports)" ;;
2) verdict="ERROR: bad usage or device not reachable (see the message above)" ;;
130 | 143) verdict="INTERRUPTED before the end" ;;
*) verdict="ERROR: drivespec ended with status $status" ;;
esac
echo "drivespec-gate: conform $family against $dut $verdict (exit $status)"
reports=()
for f in conform.junit.xml conform.json conform.html; do
    if [ -f "$report_dir/$f" ]; then reports+=("$report_dir/$f"); fi
done
if [ ${#reports[@]} -gt 0 ]; then
    echo "drivespec-gate: reports: ${reports[*]}"
else
    echo "drivespec-gate: no report written in $report_dir"
fi

if [ -n "${GITHUB_OUTPUT:-}" ]; then echo "exit-code=$status" >>"$GITHUB_OUTPUT"; fi
if [ -n "${GITHUB_STEP_SUMMARY:-}" ]; then
    {
        echo "### drivespec conform $family"
        echo
        echo "Device under test \`$dut\`: $verdict (exit $status)."
        if [ ${#reports[@]} -gt 0 ]; then echo "Reports: ${reports[*]}"; fi
    } >>"$GITHUB_STEP_SUMMARY"
fi
exit "$status"
