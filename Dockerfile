# syntax=docker/dockerfile:1
# drivespec in a container: the binary, its completions and man pages, the CI gate
# (drivespec-gate) and python3 for exec: adapters written in Python.
#
#   docker build -t drivespec .
#   docker run --rm -v "$PWD:/work" drivespec conform all --report-dir reports
#
# The build stage runs ci/package.sh, the script CI runs, and installs what its archive holds.

FROM rust:1-bookworm AS build
WORKDIR /src
COPY . .
# The commit --version names comes from .git; where the context has none (a source archive,
# a git worktree), pass it: --build-arg DRIVESPEC_COMMIT=abc1234 --build-arg DRIVESPEC_COMMIT_DATE=2026-11-27
ARG DRIVESPEC_COMMIT=""
ARG DRIVESPEC_COMMIT_DATE=""
RUN --mount=type=cache,target=/usr/local/cargo/registry \
    --mount=type=cache,target=/src/target \
    ci/package.sh && \
    mkdir /install && \
    tar -xzf dist/drivespec-*.tar.gz -C /install --strip-components=1

FROM debian:bookworm-slim
RUN apt-get update && \
    apt-get install -y --no-install-recommends python3 && \
    rm -rf /var/lib/apt/lists/*
COPY --from=build /install/drivespec /install/drivespec-gate /usr/local/bin/
COPY --from=build /install/completions/drivespec.bash /usr/share/bash-completion/completions/drivespec
COPY --from=build /install/man/man1/ /usr/local/share/man/man1/
COPY --from=build /install/README.md /install/NOTICE /usr/local/share/doc/drivespec/
WORKDIR /work
ENTRYPOINT ["drivespec"]
CMD ["--help"]
