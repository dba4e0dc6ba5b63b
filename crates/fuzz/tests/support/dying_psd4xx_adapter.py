#!/usr/bin/env python3
"""A faulty PSD4xx device for the fuzzer's `exec:` test (tests/fuzz_psd4xx.rs).

It is the example adapter tests/psd4xx_adapter.py, except:

- a record write (a `WRITE` request) makes it exit with status 3 and "boom" on stderr: a
  crash;
- time passing without a bus cycle (an `ADVANCE` request) makes it stop answering: a hang
  (the runner kills it after the protocol's time-out).
"""

import os
import sys
import time

sys.path.insert(
    0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "..", "tests")
)
import psd4xx_adapter  # noqa: E402


def requests(lines):
    for line in lines:
        if line.startswith("WRITE "):
            sys.stderr.write("boom\n")
            sys.stderr.flush()
            sys.exit(3)
        if line.startswith("ADVANCE "):
            while True:
                time.sleep(60)
        yield line


sys.stdin = requests(sys.stdin)
psd4xx_adapter.main()
