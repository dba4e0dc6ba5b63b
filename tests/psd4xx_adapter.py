#!/usr/bin/env python3
"""A minimal PSD4xx for `drivespec conform psd4xx --dut exec:...` (protocol drivespec-cyclic/1,
crates/cyclic/README.md).

It implements the PKW handshake for four parameters (1 status, 3 actual position read-only
here, 44 positioning window, 45 loop length), records for the same, the toggle bit and a
trivial position loop (constant speed, no reference loop, no ramps). Everything else is listed
with a reason in tests/psd4xx_adapter_expect.toml.

Images (PSD-ERRATUM-050 adopted reading): output = PKE IND PWE (big-endian), control word
(little-endian), target (big-endian i32); input = PKE IND PWE, status word (little-endian),
speed (big-endian i16), actual position (big-endian i32).
"""
import struct
import sys

# pnu: (bits, signed, allowed (min, max) intervals or None, default, writable)
PARAMS = {
    1: (16, False, None, 0, False),
    3: (32, True, None, 0, False),
    44: (16, False, [(1, 100)], 2, True),
    45: (32, True, [(-4000, -10), (0, 0), (10, 4000)], 250, True),
}
READ, WRITE_WORD, WRITE_DWORD = 1, 2, 3
ERR_UNKNOWN, ERR_READ_ONLY, ERR_RANGE, ERR_TYPE, ERR_OTHER = 0, 1, 2, 5, 18
STEP = 40  # increments per 10 ms cycle


class Drive:
    def __init__(self):
        self.values = {p: d for p, (_, _, _, d, _) in PARAMS.items()}
        self.last_pkw = None
        self.response = (0, 0, 0, 0)  # ak, pnu, ind, pwe
        self.target = 0
        self.running = False
        self.reached = False
        self.toggle = 0

    def status(self):
        s = 0x0110  # motor supply available, run in opposite direction to loop (after power-on)
        if self.running:
            s |= 1 << 6
        if self.reached:
            s = (s | 1) & ~0x0100
        if self.toggle:
            s |= 1 << 2
        return s

    def pkw(self, ak, pnu, ind, pwe):
        if ak == 0:
            return (0, 0, 0, 0)
        error = lambda code: (7, pnu, ind, code)
        if pnu not in PARAMS:
            return error(ERR_UNKNOWN)
        bits, signed, rng, _, writable = PARAMS[pnu]
        if pnu == 1:
            self.values[1] = self.status()
        if pnu == 3:
            self.values[3] = self.values.get(3, 0)
        if ak == READ:
            value = self.values[pnu] & 0xFFFFFFFF if bits == 32 else self.values[pnu] & 0xFFFF
            return (1 if bits == 16 else 2, pnu, ind, value)
        if ak in (WRITE_WORD, WRITE_DWORD):
            if not writable:
                return error(ERR_READ_ONLY)
            if (ak == WRITE_WORD) != (bits == 16):
                return error(ERR_TYPE)
            value = pwe & 0xFFFF if bits == 16 else pwe
            if signed and value >= 1 << (bits - 1):
                value -= 1 << bits
            if rng and not any(lo <= value <= hi for lo, hi in rng):
                return error(ERR_RANGE)
            self.values[pnu] = value
            return (1 if bits == 16 else 2, pnu, ind, pwe)
        return error(ERR_OTHER)

    def cycle(self, image):
        pke, ind, pwe = struct.unpack(">HHI", image[0:8])
        control = struct.unpack("<H", image[8:10])[0]
        target = struct.unpack(">i", image[10:14])[0]
        request = (pke >> 12, pke & 0x7FF, ind, pwe)
        if request != self.last_pkw:  # one command at a time, answer held until a new one
            self.last_pkw = request
            self.response = self.pkw(*request)
        self.toggle = control & 0x2000
        if control & 0x14 == 0x14 and (target != self.target or not self.reached):
            self.target, self.running, self.reached = target, True, False
        if not control & 0x10:
            self.running = False
        speed = 0
        actual = self.values[3]
        if self.running:
            delta = max(-STEP, min(STEP, self.target - actual))
            self.values[3] = actual + delta
            speed = 6 if delta > 0 else -6
            if self.values[3] == self.target:
                self.running, self.reached = False, True
        ak, pnu, ind, pwe = self.response
        return struct.pack(">HHI", (ak << 12) | pnu, ind, pwe) + struct.pack(
            "<H", self.status()) + struct.pack(">hi", speed, self.values[3])

    def record(self, op, index, data=b""):
        if index not in PARAMS:
            return "REFUSED 0"
        bits, signed, rng, _, writable = PARAMS[index]
        n = bits // 8
        if op == "READ":
            value = self.status() if index == 1 else self.values[index]
            return "DATA " + (value & ((1 << bits) - 1)).to_bytes(n, "big").hex().upper()
        if not writable:
            return "REFUSED 1"
        if len(data) != 1 + n:
            return "MALFORMED"
        value = int.from_bytes(data[1:], "big", signed=signed)
        if data[0] == 0:
            return "IGNORED"
        if rng and not any(lo <= value <= hi for lo, hi in rng):
            return "REFUSED 2"
        self.values[index] = value
        return "WRITTEN"


def main():
    drive = Drive()
    for line in sys.stdin:
        words = line.split()
        verb = words[0] if words else ""
        try:
            if verb == "HELLO":
                reply = "HELLO drivespec-cyclic 1 psd4xx_adapter.py (example)"
            elif verb == "RESET":
                drive, reply = Drive(), "OK"
            elif verb == "CYCLE":
                reply = "IN " + drive.cycle(bytes.fromhex(words[2])).hex().upper()
            elif verb == "ADVANCE":
                reply = "OK"
            elif verb == "READ":
                reply = drive.record("READ", int(words[2]))
            elif verb == "WRITE":
                reply = drive.record("WRITE", int(words[2]), bytes.fromhex(words[3]))
            elif verb == "ENV":
                reply = "UNSUPPORTED"
            else:
                reply = "ERR unknown request"
        except (IndexError, ValueError, struct.error) as e:
            reply = "ERR " + str(e)
        sys.stdout.write(reply + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
