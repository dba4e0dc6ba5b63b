#!/usr/bin/env python3
"""A noisy HPD line for `flaky_cli.rs`: it relays bytes between its stdin/stdout and the
command given as arguments (the built-in simulator, `drivespec sim hpd --stdio`), but loses
the first answer the device gives, once."""

import os
import subprocess
import sys
import threading


def main():
    child = subprocess.Popen(sys.argv[1:], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    out = sys.stdout.buffer

    def answers():
        lost = False
        while True:
            data = os.read(child.stdout.fileno(), 4096)
            if not data:
                return
            if not lost:
                lost = True
                continue
            out.write(data)
            out.flush()

    threading.Thread(target=answers, daemon=True).start()
    while True:
        data = os.read(sys.stdin.fileno(), 4096)
        if not data:
            child.kill()
            return
        child.stdin.write(data)
        child.stdin.flush()


if __name__ == "__main__":
    main()
