#!/bin/bash -eu
# Builds every cargo-fuzz target of fuzz/ into $OUT, each with its seed corpus
# $OUT/<target>_seed_corpus.zip (the files of corpus/<target>/ but its README).
#
#   .clusterfuzzlite/build.sh                        ClusterFuzzLite: $OUT and $SANITIZER set
#   OUT=DIR .clusterfuzzlite/build.sh                any machine with cargo (nightly flags
#                                                    through RUSTC_BOOTSTRAP=1 on stable;
#                                                    installs cargo-fuzz when missing)
#   OUT=DIR .clusterfuzzlite/build.sh --corpus-only  no build: checks that every [[bin]] of
#                                                    fuzz/Cargo.toml has its source and seeds
#                                                    and that no source is left out, then
#                                                    writes the seed zips
#
# Targets are built with `cargo fuzz build -O --debug-assertions` (release code with debug
# assertions and overflow checks) and the sanitizer in $SANITIZER (default address;
# `coverage` is handled by the builder image's cargo; one Rust cannot build, such as
# `undefined`, builds without one).
set -euo pipefail

mode=build
case ${1:-} in
--corpus-only) mode=corpus ;;
"") ;;
*)
    echo "usage: OUT=DIR $0 [--corpus-only]" >&2
    exit 2
    ;;
esac
out=${OUT:?set OUT to the folder the targets go to}
# In the ClusterFuzzLite image this script is $SRC/build.sh, run from the repository; here it
# is .clusterfuzzlite/build.sh.
here=$(cd "$(dirname "$0")" && pwd)
if [ -f "$here/../fuzz/Cargo.toml" ]; then root=$(cd "$here/.." && pwd); else root=$PWD; fi
if [ ! -f "$root/fuzz/Cargo.toml" ]; then
    echo "build.sh: no fuzz/Cargo.toml in $root" >&2
    exit 2
fi
cd "$root"
mkdir -p "$out"

# The targets: the [[bin]] names of fuzz/Cargo.toml.
mapfile -t targets < <(awk '
    /^\[/ { bin = ($0 == "[[bin]]") }
    bin && /^name *= *"/ { sub(/^name *= *"/, ""); sub(/".*/, ""); print }
' fuzz/Cargo.toml)
problems=()
[ ${#targets[@]} -gt 0 ] || problems+=("fuzz/Cargo.toml names no [[bin]] target")
for t in "${targets[@]}"; do
    [ -f "fuzz/fuzz_targets/$t.rs" ] || problems+=("target $t: no fuzz/fuzz_targets/$t.rs")
    if [ -z "$(find "corpus/$t" -maxdepth 1 -type f ! -name 'README*' -print -quit 2>/dev/null)" ]; then
        problems+=("target $t: no seed in corpus/$t/")
    fi
done
for src in fuzz/fuzz_targets/*.rs; do
    t=$(basename "$src" .rs)
    printf '%s\n' "${targets[@]}" | grep -qx "$t" || problems+=("$src is no [[bin]] of fuzz/Cargo.toml")
done
if [ ${#problems[@]} -gt 0 ]; then
    printf 'build.sh: %s\n' "${problems[@]}" >&2
    exit 1
fi

if [ "$mode" = build ]; then
    export RUSTC_BOOTSTRAP=${RUSTC_BOOTSTRAP:-1}
    command -v cargo-fuzz >/dev/null || cargo install --locked cargo-fuzz
    case ${SANITIZER:-address} in
    address | memory | thread | leak) sanitizer=${SANITIZER:-address} ;;
    *) sanitizer=none ;;
    esac
    listed=$(cargo fuzz list | sort)
    if [ "$listed" != "$(printf '%s\n' "${targets[@]}" | sort)" ]; then
        echo "build.sh: cargo fuzz list differs from the [[bin]] names of fuzz/Cargo.toml" >&2
        exit 1
    fi
    cargo fuzz build -O --debug-assertions -s "$sanitizer"
    bins="${CARGO_TARGET_DIR:-$root/target}/$(rustc -vV | sed -n 's/^host: //p')/release"
    for t in "${targets[@]}"; do cp "$bins/$t" "$out/"; done
fi

# One zip per target, the seed files at its top level.
zip_seeds() {
    local dir=$1 archive=$2
    rm -f "$archive"
    if command -v zip >/dev/null; then
        (cd "$dir" && find . -maxdepth 1 -type f ! -name 'README*' -printf '%P\n' | sort | zip -q -X -@ "$archive")
    else
        python3 - "$dir" "$archive" <<'PY'
import os, sys, zipfile
src, dst = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as z:
    for name in sorted(os.listdir(src)):
        path = os.path.join(src, name)
        if os.path.isfile(path) and not name.startswith("README"):
            z.write(path, name)
PY
    fi
}
for t in "${targets[@]}"; do
    zip_seeds "$root/corpus/$t" "$(cd "$out" && pwd)/${t}_seed_corpus.zip"
done

printf '%-16s %8s %10s %s\n' target seeds zip binary
for t in "${targets[@]}"; do
    seeds=$(find "corpus/$t" -maxdepth 1 -type f ! -name 'README*' | wc -l)
    zip_size=$(stat -c %s "$out/${t}_seed_corpus.zip")
    if [ -x "$out/$t" ]; then binary=$(stat -c %s "$out/$t"); else binary=-; fi
    printf '%-16s %8s %10s %s\n' "$t" "$seeds" "$zip_size" "$binary"
done
echo "build.sh: ${#targets[@]} targets in $out ($mode)"
