#!/usr/bin/env python3
"""A pass-through HPD device for `exec:` runs: it starts the command in argv[1:] (e.g.
`drivespec sim hpd --stdio`) and relays the line bytes between its own stdin/stdout and the
command's, unchanged, as soon as they come. What the suite sees is the command's behaviour
plus the relay's scheduling delays, as with a real adapter between master and drive."""

import os
import select
import subprocess
import sys

child = subprocess.Popen(sys.argv[1:], stdin=subprocess.PIPE, stdout=subprocess.PIPE, bufsize=0)
out = child.stdout.fileno()
into = child.stdin.fileno()
while True:
    ready, _, _ = select.select([0, out], [], [])
    if 0 in ready:
        data = os.read(0, 256)
        if not data:
            break
        os.write(into, data)
    if out in ready:
        data = os.read(out, 256)
        if not data:
            break
        os.write(1, data)
child.stdin.close()
child.wait()
