#!/usr/bin/env python3
"""A hostile `drivespec-cyclic/1` device for `hostile_cli.rs`: it relays lines to the command
given as arguments (the built-in simulator, `drivespec sim psd4xx --stdio`) and its replies
back for three requests, then answers with a line that never ends."""

import subprocess
import sys


def main():
    child = subprocess.Popen(
        sys.argv[1:], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1
    )
    for n, line in enumerate(sys.stdin):
        if n >= 3:
            break
        child.stdin.write(line)
        child.stdin.flush()
        sys.stdout.write(child.stdout.readline())
        sys.stdout.flush()
    child.kill()
    chunk = "x" * 65536
    try:
        while True:
            sys.stdout.write(chunk)
            sys.stdout.flush()
    except (BrokenPipeError, OSError):
        pass


if __name__ == "__main__":
    main()
