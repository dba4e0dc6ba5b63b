#!/usr/bin/env python3
"""A faulty HPD device for the fuzzer's `exec:` tests (tests/fuzz_exec.rs).

It relays the line bytes between stdin/stdout and the reference drive the test serves on
TCP (127.0.0.1, port in argv[1]), so it answers exactly as the reference does, except:

- a broadcast (CMD 7 in the byte after STX, manual 4.1) makes it exit with status 3 and
  "boom" on stderr: a crash;
- a PLC read (CMD 2) makes it stop reading and answering for good: a hang.

A byte after $7E that is not the stuffing byte $00 is taken as CMD+ADDR.
"""

import os
import select
import socket
import sys
import time

STX, STUFF = 0x7E, 0x00
DIE_CMD, HANG_CMD = 7, 2

conn = socket.create_connection(("127.0.0.1", int(sys.argv[1])))
conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
prev = None
while True:
    ready, _, _ = select.select([0, conn], [], [])
    if 0 in ready:
        data = os.read(0, 256)
        if not data:
            break
        for b in data:
            if prev == STX and b != STUFF:
                cmd = b >> 5
                if cmd == DIE_CMD:
                    sys.stderr.write("boom\n")
                    sys.stderr.flush()
                    sys.exit(3)
                if cmd == HANG_CMD:
                    while True:
                        time.sleep(1)
            prev = b
        conn.sendall(data)
    if conn in ready:
        data = conn.recv(256)
        if not data:
            break
        os.write(1, data)
