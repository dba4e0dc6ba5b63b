#!/usr/bin/env python3
"""A hostile HPD device for `hostile_cli.rs`: it relays bytes between its stdin/stdout and
the command given as arguments (the built-in simulator, `drivespec sim hpd --stdio`) until it
has relayed five requests, then floods its stdout with random bytes without end."""

import os
import subprocess
import sys
import threading


def main():
    child = subprocess.Popen(sys.argv[1:], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    out = sys.stdout.buffer
    lock = threading.Lock()
    flooding = threading.Event()

    def answers():
        while not flooding.is_set():
            data = os.read(child.stdout.fileno(), 4096)
            if not data:
                return
            with lock:
                if not flooding.is_set():
                    out.write(data)
                    out.flush()

    threading.Thread(target=answers, daemon=True).start()
    requests = 0
    while requests < 5:
        data = os.read(sys.stdin.fileno(), 4096)
        if not data:
            return
        child.stdin.write(data)
        child.stdin.flush()
        requests += data.count(0x7E)
    flooding.set()
    with lock:
        try:
            while True:
                out.write(os.urandom(65536))
                out.flush()
        except (BrokenPipeError, OSError):
            child.kill()


if __name__ == "__main__":
    main()
