#!/usr/bin/env python3
"""A faulty PSx3xx device for the fuzzer's `exec:` test (fuzz_psx3xx_cli.rs).

It relays every `drivespec-cyclic/1` line to the command given as arguments (the built-in
simulator, `drivespec sim psx3xx --stdio`) and its reply back, except:

- an ISDU write to index 2 (a standard command) makes it exit with status 3 and "boom" on
  stderr: a crash;
- time passing without a bus cycle (an `ADVANCE` request) makes it stop answering: a hang
  (the runner kills it after the protocol's time-out).
"""

import subprocess
import sys
import time


def main():
    child = subprocess.Popen(
        sys.argv[1:], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1
    )
    for line in sys.stdin:
        words = line.split()
        if words[:1] == ["ISDU-WRITE"] and words[2:3] == ["2"]:
            sys.stderr.write("boom\n")
            sys.stderr.flush()
            child.kill()
            sys.exit(3)
        if words[:1] == ["ADVANCE"]:
            while True:
                time.sleep(60)
        child.stdin.write(line)
        child.stdin.flush()
        reply = child.stdout.readline()
        if not reply:
            sys.exit(4)
        sys.stdout.write(reply)
        sys.stdout.flush()


main()
