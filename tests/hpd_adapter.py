#!/usr/bin/env python3
"""A minimal HPD drive on stdin/stdout, for `drivespec conform hpd --dut exec:...`.

The example adapter of the runner contract (crates/conform/README.md): it reads the bytes a
master sends on stdin and writes the drive's answers to stdout, exactly as on the RS-485 line
(manual 4.1). It implements the frame (STX $7E, stuffing $00 after $7E, checksum = sum of the
fields mod 256), the 8 ms message time-out of Pr26 = 8, address 0, and only a few parameters:
Pr31, Pr33 and Pr80 with their serial addresses, sizes, ranges and delivery values. Everything
else reads as 0 and ignores writes, so a run needs an expectations file for the rest
(tests/hpd_adapter_expect.toml).
"""

import os
import select
import sys
import time

STX, STUFF = 0x7E, 0x00
ADDRESS = 0
TIMEOUT_S = 0.008  # Pr26 = 8: a message must be complete within 8 ms of its STX

# serial address -> (size, signed, lo, hi); delivery values below
PARAMS = {
    0x54: (1, False, 0, 12),  # Pr31 operating mode (the gap 3..7 is not checked here)
    0xC6: (2, False, 100, 500),  # Pr33 continuous current, 0.1 %
    0xCE: (2, True, -32768, 32767),  # Pr80 free user word
}
memory = bytearray(256)
memory[0xC6:0xC8] = (500).to_bytes(2, "little")


def frame(fields):
    """The fields with their checksum, stuffed, behind STX."""
    out = [STX]
    for b in list(fields) + [sum(fields) & 0xFF]:
        out.append(b)
        if b == STX:
            out.append(STUFF)
    return bytes(out)


def write(par, data):
    spec = PARAMS.get(par)
    if spec is None or spec[0] != len(data):
        return  # not a whole parameter this adapter knows: ignored
    size, signed, lo, hi = spec
    value = int.from_bytes(bytes(data), "little", signed=signed)
    if lo <= value <= hi:
        memory[par : par + size] = bytes(data)


def handle(fields):
    """Acts on one message (unstuffed fields after STX, checksum checked)."""
    cmd, addr = fields[0] >> 5, fields[0] & 0x1F
    lun, par = fields[1], fields[2]
    data = fields[3:]
    if cmd == 7 and addr == 0:  # broadcast: executed, never answered
        write(par, data)
        return None
    if addr != ADDRESS:
        return None
    if cmd == 4:  # read parameter
        return frame([0x20 | ADDRESS, lun, par] + list(memory[par : par + lun].ljust(lun, b"\0")))
    if cmd == 5:  # write parameter
        write(par, data)
        return bytes([STX, 0x20 | ADDRESS])
    if cmd in (3, 6):  # PLC write, bit change: acknowledged, not implemented
        return bytes([STX, 0x20 | ADDRESS])
    return None  # CMD 2 (PLC read) is not implemented


def expected_length(fields):
    """Fields a message needs after STX, checksum included; None while unknown."""
    if len(fields) < 2:
        return None
    cmd = fields[0] >> 5
    return 4 if cmd in (2, 4) else 4 + fields[1]


def valid_start(fields):
    if not fields:
        return True
    cmd = fields[0] >> 5
    if fields[0] == 0 or cmd in (0, 1) or (cmd == 7 and fields[0] & 0x1F):
        return False
    if len(fields) >= 2 and not 1 <= fields[1] <= 4:
        return False
    if len(fields) >= 2 and cmd == 6 and fields[1] != 2:
        return False
    return True


def main():
    fd = sys.stdin.fileno()
    out = sys.stdout.buffer
    fields, in_msg, pending, started = [], False, False, 0.0
    while True:
        wait = max(0.0, started + TIMEOUT_S - time.monotonic()) if in_msg else None
        ready, _, _ = select.select([fd], [], [], wait)
        now = time.monotonic()
        if in_msg and now - started > TIMEOUT_S:
            in_msg, fields, pending = False, [], False  # time-out: drop, wait for STX
        if not ready:
            continue
        chunk = os.read(fd, 256)
        if not chunk:
            return
        for b in chunk:
            if not in_msg:
                if b == STX:
                    in_msg, fields, pending, started = True, [], False, now
                continue
            if pending:
                pending = False
                if b == STUFF:
                    fields.append(STX)
                else:  # the $7E was not stuffed: it started a new message
                    fields, started = [], now
                    if b == STX:
                        pending = True
                        continue
                    fields.append(b)
            elif b == STX:
                pending = True
                continue
            else:
                fields.append(b)
            if not valid_start(fields):
                in_msg, fields = False, []
                continue
            need = expected_length(fields)
            if need is not None and len(fields) >= need:
                body, chk = fields[:-1], fields[-1]
                in_msg, fields = False, []
                if sum(body) & 0xFF == chk:
                    answer = handle(body)
                    if answer:
                        out.write(answer)
                        out.flush()


if __name__ == "__main__":
    try:
        main()
    except (BrokenPipeError, KeyboardInterrupt):
        pass
