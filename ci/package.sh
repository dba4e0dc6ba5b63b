#!/usr/bin/env bash
# Builds the release binary and packs it for installation:
#
#   ci/package.sh            -> dist/drivespec-<version>-<target>.tar.gz (and .sha256)
#
# The archive holds one folder drivespec-<version>-<target>/ with
#   drivespec                      the binary (release profile: no debug info, stripped)
#   drivespec-gate                 ci/gate.sh, the CI gate the GitHub Action and GitLab template run
#   completions/drivespec.bash     bash   (-> /usr/share/bash-completion/completions/drivespec)
#   completions/_drivespec         zsh    (-> a folder on $fpath)
#   completions/drivespec.fish     fish   (-> ~/.config/fish/completions/)
#   man/man1/drivespec*.1          man pages, one per subcommand
#   README.md, NOTICE              the README; the licence and the crates compiled in
#
# The Dockerfile runs this same script. `cargo build` is a no-op when the release binary is
# already up to date (.ci/run builds it first), so nothing is built twice.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --locked --bin drivespec
bin=target/release/drivespec
version=$("$bin" --version | cut -d' ' -f2)
target=$(rustc -vV | sed -n 's/^host: //p')
name="drivespec-$version-$target"
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
dir="$stage/$name"
mkdir -p "$dir/completions" "$dir/man/man1"

cp "$bin" "$dir/drivespec"
cp ci/gate.sh "$dir/drivespec-gate"
"$bin" completions bash >"$dir/completions/drivespec.bash"
"$bin" completions zsh >"$dir/completions/_drivespec"
"$bin" completions fish >"$dir/completions/drivespec.fish"
"$bin" man --out "$dir/man/man1" >/dev/null
cp README.md "$dir/README.md"
license=$(sed -n 's/^license = "\(.*\)"$/\1/p' Cargo.toml)
{
    echo "drivespec $("$bin" --version | cut -d' ' -f2-), built for $target."
    echo "Licensed under $license."
    echo
    echo "The binary contains these crates, each under its own licence:"
    echo
    cargo tree --locked -p drivespec-cli -e normal,no-proc-macro --prefix none --format '{p} {l}' |
        sed 's/ (\*)$//; s/ (\/[^)]*)//' | sort -u
} >"$dir/NOTICE"

# Reproducible archive: fixed order, owner and time (the commit's, else the epoch).
mtime=$(git log -1 --format=%ct 2>/dev/null || echo 0)
mkdir -p dist
archive="dist/$name.tar.gz"
tar --sort=name --owner=0 --group=0 --numeric-owner --mtime="@$mtime" -C "$stage" -cf - "$name" |
    gzip -n -9 >"$archive"
(cd dist && sha256sum "$name.tar.gz" >"$name.tar.gz.sha256")
echo "$archive: $(du -h "$archive" | cut -f1) ($(tar -tzf "$archive" | grep -c -v '/$') files; binary $(stat -c %s "$bin") bytes)"
