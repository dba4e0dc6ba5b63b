#!/usr/bin/env python3
"""PROFINET recordings of a PSD4xx controller/device pair with planted violations.

Written from the PSD4xx PROFINET bus description (../shared/manuals/
psd4xx-profinet-bus-description.txt) and IEC 61158-6-10 as scapy implements it, without
any code of this project: the drive's behaviour below is what the manual describes
(3.5 process data, 3.6 status bits, 3.7 control bits, 3.8 PKW, 3.2.2 records, 4.1-4.3
runs, 4.7 referencing). Each variant is a pcapng capture and a truth file
(`<name>.truth.json`) listing every planted violation: requirement, frame (1-based, as
Wireshark counts), time (µs since 1970) and what was planted. A variant without plants
expects no finding at all; its unusual-but-conforming stretches are listed as probes.

    python3 tests/planted_psd4xx.py [OUT_DIR]      # default: corpus/planted

The output is deterministic (fixed seed, fixed time stamps): running the script again
with the same scapy version (the truth files name it) writes the same bytes.
"""

import gzip
import json
import os
import random
import struct
import sys
import uuid
from decimal import Decimal

import scapy
from scapy.config import conf
from scapy.contrib.pnio import ProfinetIO, PNIORealTimeCyclicPDU
from scapy.contrib.pnio_dcp import (
    DCPDeviceIDBlock,
    DCPIPBlock,
    DCPNameOfStationBlock,
    ProfinetDCP,
)
from scapy.contrib.pnio_rpc import (
    ARBlockReq,
    ARBlockRes,
    AlarmCRBlockReq,
    AlarmCRBlockRes,
    ExpectedSubmodule,
    ExpectedSubmoduleAPI,
    ExpectedSubmoduleBlockReq,
    ExpectedSubmoduleDataDescription,
    IOCRAPI,
    IOCRAPIObject,
    IOCRBlockReq,
    IOCRBlockRes,
    IODControlReq,
    IODControlRes,
    IODReadReq,
    IODReadRes,
    IODWriteReq,
    IODWriteRes,
    PNIOServiceReqPDU,
    PNIOServiceResPDU,
)
from scapy.layers.dcerpc import DceRpc4
from scapy.layers.inet import IP, UDP
from scapy.layers.l2 import Dot1Q, Ether
from scapy.packet import Raw
from scapy.utils import PcapNgWriter

conf.verb = 0

# ----------------------------------------------------------------------------- stations

CTRL_MAC = "00:1b:1b:4a:10:01"
DEV_MAC = "00:30:de:42:60:17"
OTHER_MAC = "00:1b:1b:4a:10:99"
CTRL_IP = "192.168.10.1"
DEV_IP = "192.168.10.26"
STATION = "psd426-axis-x"
VENDOR_ID = 0x0130
DEVICE_ID = 0x0426
T0_US = 1_767_225_600_000_000  # 2026-01-01T00:00:00Z

PNIO_PORT = 34964
CTRL_RPC_PORT = 49153
DEV_RPC_PORT = 49200

UUID_DEVICE_IF = uuid.UUID("dea00001-6c97-11d1-8271-00a02442df7d")
UUID_CONTROLLER_IF = uuid.UUID("dea00002-6c97-11d1-8271-00a02442df7d")
OBJECT_DEVICE = uuid.UUID("dea00000-6c97-11d1-8271-0001%04x%04x" % (DEVICE_ID, VENDOR_ID))
OBJECT_CONTROLLER = uuid.UUID("dea00000-6c97-11d1-8271-0001000a002a")
AR_UUID = uuid.UUID("6a1f2c3e-0b5d-4c1a-9e7f-3d2c1b0a9f8e")
ACTIVITY = [uuid.UUID("1c2d3e4f-5a6b-4c7d-8e9f-%012x" % n) for n in range(16)]

# ----------------------------------------------------------------------------- IO layout
# Bus description 3.2.1 / 3.5: a 14-byte output module and a 16-byte input module.
# The device access point (slot 0: subslot 1, interface 0x8000, ports 0x8001/0x8002)
# carries no data; slot 1 holds the output module, slot 2 the input module.
OUT_LEN = 14
IN_LEN = 16
C_SDU_LEN = 40  # both IOCRs: data, IOPS and IOCS padded to the 40-byte minimum
INPUT_FRAME_ID = 0x8000  # chosen by the controller in the Connect request
OUTPUT_FRAME_ID = 0x8001  # assigned by the device in the Connect response
SEND_CLOCK = 32  # 32 x 31.25 us = 1 ms
REDUCTION = 1
WATCHDOG = 10
DAP_SUBSLOTS = [(0, 1), (0, 0x8000), (0, 0x8001), (0, 0x8002)]
MOD_OUT = (1, 1)
MOD_IN = (2, 1)
MODULE_IDENT_OUT = 0x00000101
MODULE_IDENT_IN = 0x00000102

# Input CR (device -> controller): IOPS of the DAP subslots, the input module's data and
# IOPS, then the IOCS of the output module.
IN_DAP_IOPS = [0, 1, 2, 3]
IN_DATA = 4
IN_IOPS = IN_DATA + IN_LEN  # 20
IN_IOCS_OUT = 21
# Output CR (controller -> device): the IOCS first, then the output module.
OUT_IOCS_DAP = [0, 1, 2, 3]
OUT_IOCS_IN = 4
OUT_DATA = 5
OUT_IOPS = OUT_DATA + OUT_LEN  # 19

GOOD = 0x80

# ----------------------------------------------------------------------------- the drive
# Model PSD 426/436-14H (3.4): par 41 256,000; par 42 254,800; par 43 -254,800; par 53,
# 56 range 1..317; par 58, 59 range 1..1587. 400 increments per rotation (4.8) at the
# delivery scaling (par 38 = par 39 = 400).
INC_PER_ROT = 400

# (width in bits, signed, writable, range or None) from the table of 3.3 and 3.4.
PARAMS = {
    1: (16, False, False, None),
    2: (16, True, False, None),
    3: (32, True, True, None),
    4: (16, False, False, None),
    5: (16, False, False, None),
    6: (16, False, False, None),
    7: (16, False, False, None),
    8: (16, True, False, None),
    9: (16, False, False, None),
    10: (16, False, False, None),
    11: (16, False, False, (0, 65535)),
    12: (16, False, False, None),
    14: (32, False, False, None),
    37: (16, False, True, (0, 1)),
    38: (16, False, True, (1, 10000)),
    39: (16, False, True, (1, 10000)),
    40: (32, True, True, None),
    41: (32, True, True, None),
    42: (32, True, True, None),
    43: (32, True, True, None),
    44: (16, False, True, (1, 100)),
    45: (32, True, True, None),
    47: (16, False, True, (0, 1)),
    53: (16, False, True, (1, 317)),
    56: (16, False, True, (1, 317)),
    57: (16, False, True, (30, 90)),
    58: (16, False, True, (1, 1587)),
    59: (16, False, True, (1, 1587)),
    63: (16, False, True, (150, 720)),
    64: (16, False, True, (150, 720)),
    65: (16, False, True, (0, 630)),
    66: (16, False, True, (0, 470)),
    70: (16, False, True, (50, 500)),
    71: (16, False, True, (10, 1000)),
    72: (16, False, True, (0, 1000)),
    76: (16, False, True, (100, 1000)),
    90: (16, False, True, (180, 240)),
    91: (16, False, True, (10, 80)),
    92: (16, False, True, None),
}
DELIVERY = {
    1: 0, 2: 0, 3: 0, 4: 12, 5: 0, 6: 240, 7: 241, 8: 31, 9: 0, 10: 2547, 11: 4711,
    12: 42600, 14: 0x00010203, 37: 0, 38: 400, 39: 400, 40: 0, 41: 256_000,
    42: 254_800, 43: -254_800, 44: 2, 45: 250, 47: 0, 53: 63, 56: 22, 57: 30, 58: 150,
    59: 635, 63: 360, 64: 300, 65: 220, 66: 155, 70: 200, 71: 200, 72: 200, 76: 100,
    90: 185, 91: 80, 92: 0,
}
LIVE = {1, 2, 3, 4, 5, 6, 7, 8, 9}

# Status bits (3.6) and control bits (3.7).
S_REACHED, S_TOGGLE, S_POWER, S_ABORTED, S_RUNNING = 1 << 0, 1 << 2, 1 << 4, 1 << 5, 1 << 6
S_AGAINST_LOOP, S_OBSTRUCTION, S_MANUAL_ROT, S_BAD_TARGET = 1 << 8, 1 << 10, 1 << 11, 1 << 12
C_UP, C_DOWN, C_TRANSFER, C_RESERVED3, C_RELEASE, C_TOGGLE = 1, 2, 4, 8, 16, 1 << 13

# PKW command and response codes (3.8).
AK_NONE, AK_READ, AK_WRITE_W, AK_WRITE_D = 0, 1, 2, 3
RK_NONE, RK_WORD, RK_DWORD, RK_ERROR = 0, 1, 2, 7
ERR_PNU, ERR_READ_ONLY, ERR_LIMIT = 0, 1, 2


def pke(ak, pnu):
    return ((ak & 0xF) << 12) | (pnu & 0x7FF)


def pwe_of(pnu, value):
    """PWE bytes 4-7: a 16-bit value in the low word, the high word 0 (PROFIdrive)."""
    width = PARAMS.get(pnu, (32, True, False, None))[0]
    if width == 16:
        return value & 0xFFFF
    return value & 0xFFFFFFFF


def value_of(pnu, pwe):
    width, signed = PARAMS.get(pnu, (32, True, False, None))[:2]
    if width == 16:
        v = pwe & 0xFFFF
        return v - 0x10000 if signed and v >= 0x8000 else v
    return pwe - 0x100000000 if signed and pwe >= 0x80000000 else pwe


def output_image(pkw, control, target):
    """3.5.1: PKE, IND, PWE, control word (inverted byte order, 3.5 notice), target."""
    ak_pnu, ind, pwe = pkw
    return (
        struct.pack(">HHI", ak_pnu, ind, pwe)
        + struct.pack("<H", control)
        + struct.pack(">i", target)
    )


def input_image(pkw, status, speed, actual):
    """3.5.2: PKE, IND, PWE, status (inverted byte order), current rpm, actual position."""
    ak_pnu, ind, pwe = pkw
    return (
        struct.pack(">HHI", ak_pnu, ind, pwe)
        + struct.pack("<H", status)
        + struct.pack(">h", max(-32768, min(32767, speed)))
        + struct.pack(">i", actual)
    )


class Drive:
    """The PSD4xx as the bus description describes it, advanced 1 ms per cycle."""

    def __init__(self, start_pos=0):
        self.par = dict(DELIVERY)
        self.pos = float(start_pos)
        self.speed = 0.0  # rpm, signed
        self.target = None  # target in force
        self.seen_target = None  # target value of the last image with bit 2
        self.mode = "idle"  # idle, position, manual, stop
        self.status = S_POWER | S_AGAINST_LOOP
        self.control = 0
        self.toggle = 0
        self.cmd = (0, 0, 0)
        self.cmd_since = 0
        self.resp = (0, 0, 0)
        self.resp_due = None
        self.pkw_delay = 3
        self.overrides = {}  # (ak, pnu) -> response tuple, used once
        self.hold_reached = False
        self.cycle = 0

    # ---- PKW (3.8)
    def pkw_answer(self, cmd):
        ak, ind, pwe = cmd[0] >> 12, cmd[1], cmd[2]
        pnu = cmd[0] & 0x7FF
        key = (ak, pnu)
        if key in self.overrides:
            return self.overrides.pop(key)
        if ak == AK_NONE:
            return (pke(RK_NONE, 0), 0, 0)
        info = PARAMS.get(pnu)
        if info is None:
            return (pke(RK_ERROR, pnu), ind, ERR_PNU)
        width, signed, writable, rng = info
        word = width == 16
        if ak == AK_READ:
            v = self.read(pnu)
            return (pke(RK_WORD if word else RK_DWORD, pnu), ind, pwe_of(pnu, v))
        if ak in (AK_WRITE_W, AK_WRITE_D):
            if (ak == AK_WRITE_W) != word:
                return (pke(RK_ERROR, pnu), ind, 5)
            if not writable:
                return (pke(RK_ERROR, pnu), ind, ERR_READ_ONLY)
            v = value_of(pnu, pwe)
            if rng is not None and not rng[0] <= v <= rng[1]:
                return (pke(RK_ERROR, pnu), ind, ERR_LIMIT)
            self.write(pnu, v)
            return (pke(RK_WORD if word else RK_DWORD, pnu), ind, pwe)
        return (pke(RK_ERROR, pnu), ind, 18)

    def read(self, pnu):
        if pnu == 1:
            return self.status
        if pnu == 2:
            return int(round(self.speed))
        if pnu == 3:
            return int(round(self.pos))
        return self.par[pnu]

    def write(self, pnu, v):
        if pnu == 3:
            # 4.7: writing the actual value references it; the difference shifts the
            # referencing value, the target and the limits.
            delta = v - int(round(self.pos))
            self.pos += delta
            self.par[40] += delta
            self.par[41] += delta
            self.par[42] += delta
            self.par[43] += delta
            if self.target is not None:
                self.target += delta
            if self.seen_target is not None:
                self.seen_target += delta
            return
        self.par[pnu] = v

    # ---- one cycle: the output image received in the previous cycle, then motion
    def step(self, out):
        self.cycle += 1
        ak_pnu, ind, pwe, control, target = out
        cmd = (ak_pnu, ind, pwe)
        if cmd != self.cmd:
            self.cmd = cmd
            self.resp_due = self.cycle + (1 if (ak_pnu >> 12) == AK_NONE else self.pkw_delay)
        if self.resp_due is not None and self.cycle >= self.resp_due:
            self.resp = self.pkw_answer(self.cmd)
            self.resp_due = None
        self.control_word(control, target)
        self.move()
        # 3.6 bit 2 follows control bit 13.
        self.status = (self.status & ~S_TOGGLE) | (S_TOGGLE if control & C_TOGGLE else 0)
        return self.image()

    def image(self):
        return input_image(self.resp, self.status, self.reported_speed(), int(round(self.pos)))

    def reported_speed(self):
        if self.speed == 0:
            return 0
        s = int(round(self.speed))
        if s == 0:
            s = 1 if self.speed > 0 else -1
        return s

    def new_run(self):
        # 3.6: bits 5, 10, 11, 12 are reset for every new run command; bit 8 with loop 0.
        self.status &= ~(S_ABORTED | S_OBSTRUCTION | S_MANUAL_ROT | S_BAD_TARGET)
        if self.par[45] == 0:
            self.status &= ~S_AGAINST_LOOP

    def control_word(self, c, target):
        prev = self.control
        self.control = c
        release = c & C_RELEASE
        if c & C_TRANSFER and (not prev & C_TRANSFER or target != self.seen_target):
            self.seen_target = target
            if not self.par[43] <= target <= self.par[42]:
                self.status |= S_BAD_TARGET
                self.status &= ~S_REACHED
            else:
                self.target = target
                if abs(self.target - self.pos) > self.par[44]:
                    self.status &= ~S_REACHED
                if release:
                    self.start_position()
        if release and not prev & C_RELEASE and self.target is not None and not c & (C_UP | C_DOWN):
            if abs(self.target - self.pos) > self.par[44]:
                self.start_position()
        if release and c & (C_UP | C_DOWN) and (c & 3) != 3 and self.mode != "manual":
            self.new_run()
            self.status &= ~S_REACHED
            self.mode = "manual"
            self.manual_dir = 1 if c & C_UP else -1
        if self.mode == "manual" and not (release and c & (C_UP | C_DOWN)):
            self.mode = "stop"
        if self.mode == "position" and not release:
            # 3.7 bit 4: withdrawing the release aborts the run and sets bit 5.
            self.status |= S_ABORTED
            self.mode = "stop"

    def start_position(self):
        self.new_run()
        if abs(self.target - self.pos) > self.par[44]:
            self.status &= ~S_REACHED
            self.mode = "position"

    def move(self):
        acc = self.par[58] / 1000.0  # rpm per ms
        dec = self.par[59] / 1000.0
        rpm_to_inc = INC_PER_ROT / 60000.0  # increments per ms at 1 rpm
        if self.mode == "position":
            dist = self.target - self.pos
            direction = 1 if dist > 0 else -1
            vmax = self.par[53]
            v = abs(self.speed)
            if self.speed * direction < 0:
                v = -v
            brake = (v * v) / (2 * dec) * rpm_to_inc if v > 0 else 0
            if abs(dist) <= brake + v * rpm_to_inc:
                v = max(5.0, v - dec)
            else:
                v = min(vmax, v + acc)
            stepinc = v * rpm_to_inc
            if abs(dist) <= stepinc:
                self.pos = float(self.target)
                self.speed = 0.0
                self.mode = "idle"
                self.status |= S_REACHED
            else:
                self.pos += direction * stepinc
                self.speed = direction * v
        elif self.mode == "manual":
            v = min(self.par[56], abs(self.speed) + acc)
            self.speed = self.manual_dir * v
            self.pos += self.speed * rpm_to_inc
        elif self.mode == "stop":
            v = abs(self.speed) - dec
            if v <= 0:
                self.speed = 0.0
                self.pos = float(round(self.pos))
                self.mode = "idle"
            else:
                self.speed = v if self.speed > 0 else -v
                self.pos += self.speed * rpm_to_inc
        running = self.speed != 0
        self.status = (self.status | S_RUNNING) if running else (self.status & ~S_RUNNING)


# ----------------------------------------------------------------------------- frames


class Capture:
    """Frames with their capture times; plants are tagged on the frame they mark."""

    def __init__(self, seed):
        self.frames = []  # (time_us, order, packet, tags)
        self.rng = random.Random(seed)
        self.order = 0

    def add(self, t_us, pkt, tags=None):
        self.frames.append((t_us, self.order, pkt, tags or []))
        self.order += 1

    def write(self, path):
        self.frames.sort(key=lambda f: (f[0], f[1]))
        truth = []
        plain = path + ".part"
        w = PcapNgWriter(plain)
        w.linktype = 1  # Ethernet
        w.write_header(None)
        for n, (t, _, pkt, tags) in enumerate(self.frames, start=1):
            w.write_packet(bytes(pkt), sec=Decimal(t) / 1_000_000)
            for tag in tags:
                truth.append(dict(tag, frame=n, time_us=t))
        w.close()
        with open(plain, "rb") as f:
            data = f.read()
        os.remove(plain)
        # gzip without name or time stamp: the same capture gives the same file.
        with open(path, "wb") as f:
            with gzip.GzipFile(filename="", mode="wb", fileobj=f, mtime=0,
                               compresslevel=9) as z:
                z.write(data)
        return truth


def rt_frame(src, dst, frame_id, c_sdu, counter, data_status, vlan):
    """A cyclic RT frame built by scapy's PROFINET layers."""
    eth = Ether(src=src, dst=dst)
    if vlan:
        eth = eth / Dot1Q(prio=6, vlan=0, type=0x8892)
    else:
        eth.type = 0x8892
    return (
        eth
        / ProfinetIO(frameID=frame_id)
        / PNIORealTimeCyclicPDU(
            data=[Raw(c_sdu)],
            cycleCounter=counter & 0xFFFF,
            dataStatus=data_status,
            transferStatus=0,
        )
    )


class RtStream:
    """One cyclic stream: scapy builds its first frame; later frames reuse the header
    bytes of that frame (the C_SDU and APDU status follow the header unchanged), which
    keeps generation fast. Every frame is checked against the first one's layout."""

    def __init__(self, src, dst, frame_id, vlan):
        self.args = (src, dst, frame_id)
        self.vlan = vlan
        self.header = None

    def frame(self, c_sdu, counter, data_status):
        if self.header is None:
            full = bytes(rt_frame(*self.args, c_sdu, counter, data_status, self.vlan))
            self.header = full[: len(full) - len(c_sdu) - 4]
            fast = self.header + c_sdu + struct.pack(">HBB", counter & 0xFFFF, data_status, 0)
            assert fast == full, "the RT frame layout differs from scapy's"
            return full
        return self.header + c_sdu + struct.pack(">HBB", counter & 0xFFFF, data_status, 0)


def rpc(src_mac, dst_mac, src_ip, dst_ip, sport, dport, ptype, obj, iface, act, seq, opnum, pdu):
    return (
        Ether(src=src_mac, dst=dst_mac)
        / IP(src=src_ip, dst=dst_ip, id=seq & 0xFFFF, flags="DF", ttl=64)
        / UDP(sport=sport, dport=dport)
        / DceRpc4(
            ptype=ptype,
            flags1=0x20 if ptype == 0 else 0x0A,
            endian=1,
            object=obj,
            if_id=iface,
            act_id=act,
            server_boot=0x5F3A1000,
            seqnum=seq,
            opnum=opnum,
        )
        / pdu
    )


def connect_frames(cap, t):
    """Connect request and response (IEC 61158-6-10: ARBlockReq, IOCRBlockReq for the
    input and the output CR, AlarmCRBlockReq, ExpectedSubmoduleBlockReq)."""

    def iocr(kind, frame_id, objects, iocs):
        return IOCRBlockReq(
            IOCRType=kind,
            IOCRReference=kind,
            LT=0x8892,
            IOCRProperties_RTClass=2,
            DataLength=C_SDU_LEN,
            FrameID=frame_id,
            SendClockFactor=SEND_CLOCK,
            ReductionRatio=REDUCTION,
            Phase=1,
            Sequence=0,
            FrameSendOffset=0xFFFFFFFF,
            WatchdogFactor=WATCHDOG,
            DataHoldFactor=WATCHDOG,
            IOCRTagHeader_IOUserPriority=6,
            IOCRMulticastMACAdd="01:0e:cf:00:00:00",
            APIs=[
                IOCRAPI(
                    API=0,
                    IODataObjects=[
                        IOCRAPIObject(SlotNumber=s, SubslotNumber=ss, FrameOffset=o)
                        for (s, ss, o) in objects
                    ],
                    IOCSs=[
                        IOCRAPIObject(SlotNumber=s, SubslotNumber=ss, FrameOffset=o)
                        for (s, ss, o) in iocs
                    ],
                )
            ],
        )

    in_objects = [(s, ss, o) for (s, ss), o in zip(DAP_SUBSLOTS, IN_DAP_IOPS)]
    in_objects.append((MOD_IN[0], MOD_IN[1], IN_DATA))
    in_iocs = [(MOD_OUT[0], MOD_OUT[1], IN_IOCS_OUT)]
    out_objects = [(MOD_OUT[0], MOD_OUT[1], OUT_DATA)]
    out_iocs = [(s, ss, o) for (s, ss), o in zip(DAP_SUBSLOTS, OUT_IOCS_DAP)]
    out_iocs.append((MOD_IN[0], MOD_IN[1], OUT_IOCS_IN))

    def no_io(subslot, ident):
        return ExpectedSubmodule(
            SubslotNumber=subslot,
            SubmoduleIdentNumber=ident,
            SubmoduleProperties_Type=0,
            DataDescription=[ExpectedSubmoduleDataDescription(
                DataDescription=1, SubmoduleDataLength=0, LengthIOCS=1, LengthIOPS=1)],
        )

    expected = ExpectedSubmoduleBlockReq(
        APIs=[
            ExpectedSubmoduleAPI(
                API=0, SlotNumber=0, ModuleIdentNumber=0x00000001, ModuleProperties=0,
                Submodules=[no_io(1, 1), no_io(0x8000, 2), no_io(0x8001, 3), no_io(0x8002, 3)],
            ),
            ExpectedSubmoduleAPI(
                API=0, SlotNumber=MOD_OUT[0], ModuleIdentNumber=MODULE_IDENT_OUT,
                ModuleProperties=0,
                Submodules=[ExpectedSubmodule(
                    SubslotNumber=MOD_OUT[1], SubmoduleIdentNumber=1,
                    SubmoduleProperties_Type=2,
                    DataDescription=[ExpectedSubmoduleDataDescription(
                        DataDescription=2, SubmoduleDataLength=OUT_LEN, LengthIOCS=1,
                        LengthIOPS=1)],
                )],
            ),
            ExpectedSubmoduleAPI(
                API=0, SlotNumber=MOD_IN[0], ModuleIdentNumber=MODULE_IDENT_IN,
                ModuleProperties=0,
                Submodules=[ExpectedSubmodule(
                    SubslotNumber=MOD_IN[1], SubmoduleIdentNumber=1,
                    SubmoduleProperties_Type=1,
                    DataDescription=[ExpectedSubmoduleDataDescription(
                        DataDescription=1, SubmoduleDataLength=IN_LEN, LengthIOCS=1,
                        LengthIOPS=1)],
                )],
            ),
        ]
    )
    blocks = [
        ARBlockReq(
            ARType=1,
            ARUUID=AR_UUID,
            SessionKey=1,
            CMInitiatorMacAdd=CTRL_MAC,
            CMInitiatorObjectUUID=OBJECT_CONTROLLER,
            ARProperties_StartupMode=1,
            ARProperties_ParametrizationServer=1,
            ARProperties_State=1,
            CMInitiatorActivityTimeoutFactor=600,
            CMInitiatorUDPRTPort=0x8892,
            CMInitiatorStationName=b"plc-line-4",
        ),
        iocr(1, INPUT_FRAME_ID, in_objects, in_iocs),
        iocr(2, 0xFFFF, out_objects, out_iocs),
        AlarmCRBlockReq(AlarmCRType=1, LT=0x8892, RTATimeoutFactor=1, RTARetries=3,
                        LocalAlarmReference=1, MaxAlarmDataLength=200),
        expected,
    ]
    req = PNIOServiceReqPDU(args_max=4096, blocks=blocks)
    cap.add(t, rpc(CTRL_MAC, DEV_MAC, CTRL_IP, DEV_IP, CTRL_RPC_PORT, PNIO_PORT, 0,
                   OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], 0, 0, req))
    res_blocks = [
        ARBlockRes(ARType=1, ARUUID=AR_UUID, SessionKey=1, CMResponderMacAdd=DEV_MAC,
                   CMResponderUDPRTPort=0x8892),
        IOCRBlockRes(IOCRType=1, IOCRReference=1, FrameID=INPUT_FRAME_ID),
        IOCRBlockRes(IOCRType=2, IOCRReference=2, FrameID=OUTPUT_FRAME_ID),
        AlarmCRBlockRes(AlarmCRType=1, LocalAlarmReference=7, MaxAlarmDataLength=200),
    ]
    res = PNIOServiceResPDU(status=0, blocks=res_blocks)
    cap.add(t + 2800, rpc(DEV_MAC, CTRL_MAC, DEV_IP, CTRL_IP, PNIO_PORT, CTRL_RPC_PORT, 2,
                          OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], 0, 0, res))


def control_frames(cap, t, prm_end):
    """PrmEnd (controller -> device) or ApplicationReady (device -> controller)."""
    if prm_end:
        req = IODControlReq(block_type=0x0110, ARUUID=AR_UUID, SessionKey=1,
                            ControlCommand_PrmEnd=1)
        res = IODControlRes(block_type=0x8110, ARUUID=AR_UUID, SessionKey=1,
                            ControlCommand_Done=1)
        cap.add(t, rpc(CTRL_MAC, DEV_MAC, CTRL_IP, DEV_IP, CTRL_RPC_PORT, PNIO_PORT, 0,
                       OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], 1, 4,
                       PNIOServiceReqPDU(args_max=4096, blocks=[req])))
        cap.add(t + 900, rpc(DEV_MAC, CTRL_MAC, DEV_IP, CTRL_IP, PNIO_PORT, CTRL_RPC_PORT, 2,
                             OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], 1, 4,
                             PNIOServiceResPDU(status=0, blocks=[res])))
    else:
        req = IODControlReq(block_type=0x0112, ARUUID=AR_UUID, SessionKey=1,
                            ControlCommand_ApplicationReady=1)
        res = IODControlRes(block_type=0x8112, ARUUID=AR_UUID, SessionKey=1,
                            ControlCommand_Done=1)
        cap.add(t, rpc(DEV_MAC, CTRL_MAC, DEV_IP, CTRL_IP, DEV_RPC_PORT, PNIO_PORT, 0,
                       OBJECT_CONTROLLER, UUID_CONTROLLER_IF, ACTIVITY[1], 0, 4,
                       PNIOServiceReqPDU(args_max=4096, blocks=[req])))
        cap.add(t + 1200, rpc(CTRL_MAC, DEV_MAC, CTRL_IP, DEV_IP, PNIO_PORT, DEV_RPC_PORT, 2,
                              OBJECT_CONTROLLER, UUID_CONTROLLER_IF, ACTIVITY[1], 0, 4,
                              PNIOServiceResPDU(status=0, blocks=[res])))


def dcp_frames(cap, t):
    """DCP Identify All and the device's answer."""
    req = (
        Ether(src=CTRL_MAC, dst="01:0e:cf:00:00:00", type=0x8892)
        / ProfinetIO(frameID=0xFEFE)
        / ProfinetDCP(service_id=5, service_type=0, xid=0x00001001, reserved=1,
                      option=0xFF, sub_option=0xFF, dcp_data_length=4, dcp_block_length=0)
    )
    cap.add(t, req)
    res = (
        Ether(src=DEV_MAC, dst=CTRL_MAC, type=0x8892)
        / ProfinetIO(frameID=0xFEFF)
        / ProfinetDCP(service_id=5, service_type=1, xid=0x00001001, reserved=0,
                      dcp_blocks=[
                          DCPNameOfStationBlock(name_of_station=STATION.encode(), block_info=0),
                          DCPIPBlock(block_info=1, ip=DEV_IP, netmask="255.255.255.0",
                                     gateway="0.0.0.0"),
                          DCPDeviceIDBlock(vendor_id=VENDOR_ID, device_id=DEVICE_ID),
                      ])
    )
    cap.add(t + 640, res)


class RecordIo:
    """Acyclic Read/Write records (3.2.2) on the output module's subslot."""

    def __init__(self):
        self.seq = 2
        self.act = 2

    def read(self, cap, t, index, data, tags=None):
        self.seq += 1
        req = IODReadReq(seqNum=self.seq, ARUUID=AR_UUID, API=0, slotNumber=MOD_OUT[0],
                         subslotNumber=MOD_OUT[1], index=index, recordDataLength=4096)
        res = IODReadRes(seqNum=self.seq, ARUUID=AR_UUID, API=0, slotNumber=MOD_OUT[0],
                         subslotNumber=MOD_OUT[1], index=index, recordDataLength=len(data))
        args_req = PNIOServiceReqPDU(args_max=4096 + 64, blocks=[req])
        cap.add(t, rpc(CTRL_MAC, DEV_MAC, CTRL_IP, DEV_IP, CTRL_RPC_PORT, PNIO_PORT, 0,
                       OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], self.seq, 2, args_req))
        res_raw = bytes(res) + data
        args_res = PNIOServiceResPDU(status=0, blocks=[Raw(res_raw)])
        cap.add(t + 1500, rpc(DEV_MAC, CTRL_MAC, DEV_IP, CTRL_IP, PNIO_PORT, CTRL_RPC_PORT, 2,
                              OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], self.seq, 2,
                              args_res), tags)

    def write(self, cap, t, index, data):
        self.seq += 1
        req = IODWriteReq(seqNum=self.seq, ARUUID=AR_UUID, API=0, slotNumber=MOD_OUT[0],
                          subslotNumber=MOD_OUT[1], index=index, recordDataLength=len(data))
        res = IODWriteRes(seqNum=self.seq, ARUUID=AR_UUID, API=0, slotNumber=MOD_OUT[0],
                          subslotNumber=MOD_OUT[1], index=index, recordDataLength=len(data))
        args_req = PNIOServiceReqPDU(args_max=4096, blocks=[Raw(bytes(req) + data)])
        cap.add(t, rpc(CTRL_MAC, DEV_MAC, CTRL_IP, DEV_IP, CTRL_RPC_PORT, PNIO_PORT, 0,
                       OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], self.seq, 3, args_req))
        cap.add(t + 1800, rpc(DEV_MAC, CTRL_MAC, DEV_IP, CTRL_IP, PNIO_PORT, CTRL_RPC_PORT, 2,
                              OBJECT_DEVICE, UUID_DEVICE_IF, ACTIVITY[0], self.seq, 3,
                              PNIOServiceResPDU(status=0, blocks=[res])))


def alarm_frames(cap, t, tags):
    """A diagnosis alarm (low priority) from the output module's subslot, acknowledged."""
    hdr = struct.Struct(">HHBBHHH")
    # AlarmNotification-PDU: BlockHeader, AlarmType 1 (Diagnosis), API, slot, subslot,
    # module and submodule ident, AlarmSpecifier (sequence 1, channel diagnosis).
    body = struct.pack(">HIHHIIH", 0x0001, 0, MOD_OUT[0], MOD_OUT[1], MODULE_IDENT_OUT, 1,
                       0x0801)
    note = struct.pack(">HHBB", 0x0002, len(body) + 2, 1, 0) + body
    data = hdr.pack(1, 7, 0x11, 0x00, 0, 0xFFFF, len(note)) + note
    cap.add(t, Ether(src=DEV_MAC, dst=CTRL_MAC, type=0x8892) / ProfinetIO(frameID=0xFE01)
            / Raw(data), tags)
    ack = hdr.pack(7, 1, 0x13, 0x00, 0xFFFF, 0, 0)
    cap.add(t + 700, Ether(src=CTRL_MAC, dst=DEV_MAC, type=0x8892) / ProfinetIO(frameID=0xFE01)
            / Raw(ack))
    # AlarmAck-PDU (block 0x8002) with PNIOStatus OK.
    ack_body = struct.pack(">HIHHHI", 0x0001, 0, MOD_OUT[0], MOD_OUT[1], 0x0801, 0)
    ack_block = struct.pack(">HHBB", 0x8002, len(ack_body) + 2, 1, 0) + ack_body
    cap.add(t + 5200, Ether(src=CTRL_MAC, dst=DEV_MAC, type=0x8892)
            / ProfinetIO(frameID=0xFE01)
            / Raw(hdr.pack(7, 1, 0x11, 0x00, 0, 0, len(ack_block)) + ack_block))
    cap.add(t + 5900, Ether(src=DEV_MAC, dst=CTRL_MAC, type=0x8892) / ProfinetIO(frameID=0xFE01)
            / Raw(hdr.pack(1, 7, 0x13, 0x00, 0xFFFF, 1, 0)))


# ----------------------------------------------------------------------------- controller


class Controller:
    """Steps of the controller's program, one per cycle (see `Scenario`)."""

    def __init__(self, steps):
        self.steps = list(steps)
        self.pkw = (0, 0, 0)
        self.control = 0
        self.target = 0
        self.toggle_every = 50
        self.state = None
        self.wait_until = 0
        self.heartbeat = True

    def next_output(self, cycle, inp):
        """The output image for `cycle`, given the latest input image (decoded)."""
        if self.heartbeat and cycle % self.toggle_every == 0:
            self.control ^= C_TOGGLE
        while self.steps:
            step = self.steps[0]
            kind = step[0]
            if kind == "pkw":
                _, ak, pnu, value = step
                if self.state is None:
                    self.pkw = (pke(ak, pnu), 0, pwe_of(pnu, value) if ak != AK_READ else 0)
                    self.state = "sent"
                    break
                if self.state == "sent":
                    rk, rpnu = inp["pke"] >> 12, inp["pke"] & 0x7FF
                    if rk != RK_NONE and rpnu == pnu:
                        self.pkw = (0, 0, 0)
                        self.state = "clear"
                    break
                if self.state == "clear":
                    if inp["pke"] >> 12 == RK_NONE:
                        self.state = None
                        self.steps.pop(0)
                        continue
                    break
            elif kind == "control":
                self.control = (self.control & C_TOGGLE) | step[1]
                if len(step) > 2:
                    self.target = step[2]
                self.steps.pop(0)
                continue
            elif kind == "wait":
                if self.state is None:
                    self.wait_until = cycle + step[1]
                    self.state = "waiting"
                if cycle >= self.wait_until:
                    self.state = None
                    self.steps.pop(0)
                    continue
                break
            elif kind == "until":
                # Wait for a status condition: ("until", mask, value)
                if inp["status"] & step[1] == step[2]:
                    self.steps.pop(0)
                    continue
                break
            elif kind == "heartbeat":
                # The controller toggles control bit 13 every 50 ms while this is on.
                self.heartbeat = step[1]
                self.steps.pop(0)
                continue
            elif kind == "call":
                step[1](cycle)
                self.steps.pop(0)
                continue
            else:
                raise ValueError(kind)
        return (self.pkw[0], self.pkw[1], self.pkw[2], self.control, self.target)

    def done(self):
        return not self.steps


def decode_input(img):
    ak_pnu, ind, pwe = struct.unpack(">HHI", img[:8])
    (status,) = struct.unpack("<H", img[8:10])
    (speed,) = struct.unpack(">h", img[10:12])
    (actual,) = struct.unpack(">i", img[12:16])
    return {"pke": ak_pnu, "ind": ind, "pwe": pwe, "status": status, "speed": speed,
            "actual": actual}


# ----------------------------------------------------------------------------- scenarios


class Scenario:
    """A recording: stations talk, the controller runs `steps`, plants alter frames.

    Hooks run on every cycle with the frame being built: `out_hooks` on the controller's
    output (`pkw`, `control`, `target`), `in_hooks` on the drive's input image; a hook
    that plants a violation tags the frame with the requirement it breaks."""

    def __init__(self, name, description, seed, connect=True, tail_ms=300,
                 start_pos=12_000, startup_stop_ms=0):
        self.name = name
        self.description = description
        self.seed = seed
        self.connect = connect
        self.tail_ms = tail_ms
        self.start_pos = start_pos
        self.startup_stop_ms = startup_stop_ms
        self.steps = []
        self.probes = []
        self.out_hooks = []
        self.in_hooks = []
        self.at_cycle = {}  # cycle -> functions(cap, t, scenario) adding acyclic frames
        self.drop_in = set()
        self.counter_skew = {}  # cycle -> extra counter units in the device's counter
        self.marks = {}
        self.drive = Drive(start_pos)
        self.pkw_plants = []

    def mark(self, name):
        """A controller step that records the cycle it is reached in."""
        return ("call", lambda cycle: self.marks.__setitem__(name, cycle))

    def build(self, out_dir):
        cap = Capture(self.seed)
        rng = cap.rng
        drive = self.drive
        ctrl = Controller(self.steps)
        t = T0_US
        if self.connect:
            dcp_frames(cap, t)
            connect_frames(cap, t + 20_000)
            control_frames(cap, t + 40_000, prm_end=True)
            control_frames(cap, t + 46_000, prm_end=False)
            t_cyclic = t + 24_000
        else:
            t_cyclic = t
        out_stream = RtStream(CTRL_MAC, DEV_MAC, OUTPUT_FRAME_ID, True)
        in_stream = RtStream(DEV_MAC, CTRL_MAC, INPUT_FRAME_ID, False)
        inp = decode_input(drive.image())
        counter_in, counter_out = 0x1200, 0x5A40
        received = (0, 0, 0, 0, 0)
        cycle = 0
        skew = 0
        tail = self.tail_ms
        while True:
            cycle += 1
            base = t_cyclic + cycle * 1000
            for fn in self.at_cycle.get(cycle, []):
                fn(cap, base + 300, self)
            out = ctrl.next_output(cycle, inp)
            frame_out = {"pkw": out[:3], "control": out[3], "target": out[4], "tags": [],
                         "cycle": cycle, "stop": cycle <= self.startup_stop_ms}
            for fn in self.out_hooks:
                fn(frame_out)
            stop = frame_out["stop"]
            o_img = output_image(frame_out["pkw"], frame_out["control"], frame_out["target"])
            if stop:
                # 3.9: IOPS bad while the CPU is in STOP; the controller zeroes its outputs.
                o_img = bytes(OUT_LEN)
            c_sdu = bytearray(C_SDU_LEN)
            for o in OUT_IOCS_DAP + [OUT_IOCS_IN]:
                c_sdu[o] = GOOD
            c_sdu[OUT_DATA:OUT_DATA + OUT_LEN] = o_img
            c_sdu[OUT_IOPS] = 0x00 if stop else GOOD
            counter_out = (counter_out + SEND_CLOCK * REDUCTION) & 0xFFFF
            cap.add(base + 120 + rng.randint(0, 40),
                    out_stream.frame(bytes(c_sdu), counter_out, 0x25 if stop else 0x35),
                    frame_out["tags"])
            # The drive keeps the last valid outputs while the provider is in STOP (3.9).
            if not stop:
                received = (frame_out["pkw"][0], frame_out["pkw"][1], frame_out["pkw"][2],
                            frame_out["control"], frame_out["target"])
            frame_in = {"image": drive.step(received), "tags": [], "drive": drive,
                        "cycle": cycle}
            for fn in self.in_hooks:
                fn(frame_in)
            inp = decode_input(frame_in["image"])
            c_sdu = bytearray(C_SDU_LEN)
            for o in IN_DAP_IOPS + [IN_IOPS, IN_IOCS_OUT]:
                c_sdu[o] = GOOD
            c_sdu[IN_DATA:IN_DATA + IN_LEN] = frame_in["image"]
            skew += self.counter_skew.get(cycle, 0)
            counter_in = (counter_in + SEND_CLOCK * REDUCTION) & 0xFFFF
            if cycle not in self.drop_in:
                cap.add(base + 560 + rng.randint(0, 60),
                        in_stream.frame(bytes(c_sdu), counter_in + skew, 0x35),
                        frame_in["tags"])
            if ctrl.done() and drive.mode == "idle":
                tail -= 1
                if tail <= 0:
                    break
            if cycle > 30_000:
                raise RuntimeError(f"{self.name}: the controller's steps never finished")
        path = os.path.join(out_dir, self.name + ".pcapng.gz")
        truth = cap.write(path)
        doc = {
            "schema": "drivespec-planted/1",
            "capture": self.name + ".pcapng.gz",
            "description": self.description,
            "generator": "tests/planted_psd4xx.py",
            "scapy": scapy.__version__,
            "seed": self.seed,
            "frames": len(cap.frames),
            "connect": self.connect,
            "plants": truth,
            "probes": self.probes,
        }
        with open(os.path.join(out_dir, self.name + ".truth.json"), "w") as f:
            json.dump(doc, f, indent=1, sort_keys=True)
            f.write("\n")
        return doc


def tag(frame, requirement, what, level="must", kind="violation"):
    frame["tags"].append({"requirement": requirement, "level": level, "kind": kind,
                          "what": what})


def set_status(frame, set_bits=0, clear_bits=0):
    img = bytearray(frame["image"])
    (s,) = struct.unpack("<H", img[8:10])
    s = (s & ~clear_bits) | set_bits
    img[8:10] = struct.pack("<H", s)
    frame["image"] = bytes(img)


def set_speed(frame, rpm):
    img = bytearray(frame["image"])
    img[10:12] = struct.pack(">h", rpm)
    frame["image"] = bytes(img)


def actual_of(frame):
    return struct.unpack(">i", frame["image"][12:16])[0]


def commissioning():
    """Reads and writes a controller makes before the first run (3.3, 4.7 note 7)."""
    return [
        ("pkw", AK_READ, 12, 0),  # device model as number
        ("pkw", AK_READ, 38, 0),
        ("pkw", AK_READ, 39, 0),
        ("pkw", AK_READ, 42, 0),
        ("pkw", AK_READ, 43, 0),
        ("pkw", AK_READ, 44, 0),
        ("pkw", AK_WRITE_D, 45, 0),  # no reference loop
        ("pkw", AK_WRITE_W, 53, 300),  # positioning speed 300 rpm (PSD426: up to 317)
        ("pkw", AK_WRITE_W, 58, 1500),
        ("pkw", AK_WRITE_W, 59, 1500),
    ]


def run_to(target, wait_ms=40):
    return [
        ("control", C_TRANSFER | C_RELEASE, target),
        ("wait", 5),
        ("until", S_RUNNING | S_REACHED, S_REACHED),
        ("wait", wait_ms),
    ]


def abort_run(target, after_ms):
    return [
        ("control", C_TRANSFER | C_RELEASE, target),
        ("wait", after_ms),
        ("control", 0),  # release withdrawn during the run (3.7 bit 4)
        ("until", S_RUNNING, 0),
        ("wait", 40),
    ]


def plant_pkw_answers(s, plants):
    """Planted PKW answers: `plants` = [(ak, pnu, response, requirement, what)]. The drive
    gives the planted response to that command; the first input frame carrying it is the
    violation's frame."""
    for ak, pnu, resp, _, _ in plants:
        s.drive.overrides[(ak, pnu)] = resp
    pending = list(plants)

    def hook(frame):
        ak_pnu = struct.unpack(">H", frame["image"][:2])[0]
        cmd = frame["drive"].cmd[0]
        for p in list(pending):
            ak, pnu, _, req, what = p
            if cmd >> 12 == ak and cmd & 0x7FF == pnu and ak_pnu & 0x7FF == pnu \
                    and ak_pnu >> 12 != RK_NONE:
                tag(frame, req, what)
                pending.remove(p)
    s.in_hooks.append(hook)


def clean():
    s = Scenario(
        "psd426-clean",
        "Connect, commissioning over PKW, positioning runs, a manual run, a run aborted by "
        "withdrawing the release, re-referencing by writing par 3, record read and write, "
        "PKW writes refused with the right error codes, three lost cyclic frames, and a "
        "controller in STOP for its first 120 ms: no violation",
        seed=426001,
        startup_stop_ms=120,
    )
    s.steps = (
        [("wait", 150)]
        + commissioning()
        + [
            ("pkw", AK_WRITE_W, 44, 500),  # beyond 1..100: refused with error 2
            ("pkw", AK_READ, 200, 0),  # no such parameter: error 0
            ("pkw", AK_WRITE_W, 4, 10),  # read-only: error 1
            ("pkw", AK_READ, 8, 0),  # temperature (live)
        ]
        + run_to(14_000)
        + run_to(11_500)
        + [
            ("control", C_RELEASE | C_UP),  # manual run to larger values at par 56
            ("wait", 400),
            ("control", C_RELEASE),
            ("until", S_RUNNING, 0),
            ("wait", 30),
        ]
        + abort_run(16_000, 250)
        + [
            ("pkw", AK_WRITE_D, 3, 50_000),  # re-reference the standing drive (4.7)
            ("pkw", AK_READ, 42, 0),
        ]
        + run_to(50_600)
        + [("pkw", AK_READ, 3, 0), ("wait", 20)]
    )
    s.probes = [
        {"what": "controller ProviderState STOP with IOPS bad and zeroed outputs for its "
                 "first 120 ms (allowed: 3.9, IEC 61158-6-10)"},
        {"what": "PKW writes refused with error 2 (par 44 = 500), 0 (par 200), 1 (par 4)"},
        {"what": "par 3 written at standstill: the position jumps by the difference (4.7)"},
        {"what": "three device frames lost (the cycle counter advances by 4 cycles once)"},
        {"what": "record read of par 44 (2 bytes) and record write of par 44 with control "
                 "byte 0 (ignored, 3.2.2)"},
    ]
    rec = RecordIo()
    s.at_cycle[900] = [lambda cap, t, sc: rec.read(cap, t, 44,
                                                   struct.pack(">H", sc.drive.par[44]))]
    s.at_cycle[1000] = [lambda cap, t, sc: rec.write(cap, t, 44, struct.pack(">BH", 0, 9))]
    s.drop_in = {1500, 1501, 1502}
    return s


def planted_protocol():
    s = Scenario(
        "psd426-planted-protocol",
        "PKW answers with a wrong response code, an implausible error code and a write "
        "echo that differs; a record read answered with the wrong length; a reserved "
        "control bit; a cycle counter that jumps by half a cycle; a diagnosis alarm",
        seed=426002,
    )
    s.steps = (
        [("wait", 100)]
        + commissioning()
        + [
            ("pkw", AK_READ, 40, 0),
            ("pkw", AK_WRITE_W, 44, 50),
            ("pkw", AK_WRITE_W, 57, 40),
            ("pkw", AK_READ, 44, 0),
        ]
        + run_to(15_000)
        + [("wait", 300)]
    )
    plant_pkw_answers(s, [
        (AK_READ, 40, (pke(RK_WORD, 40), 0, 0), "PSD-PKW-012",
         "read of par 40 (32 bit) answered with response 1 (word)"),
        (AK_WRITE_W, 44, (pke(RK_ERROR, 44), 0, ERR_LIMIT), "PSD-PKW-025",
         "write of par 44 = 50 refused with error 2 (limit exceeded); 3.3: 1..100 at the "
         "delivery scaling, which the capture shows (par 38 = par 39 = 400)"),
        (AK_WRITE_W, 57, (pke(RK_WORD, 57), 0, 45), "PSD-PKW-034",
         "write of par 57 = 40 answered with PWE 45"),
    ])
    rec = RecordIo()
    s.at_cycle[700] = [lambda cap, t, sc: rec.read(
        cap, t, 44, struct.pack(">I", sc.drive.par[44]),
        [{"requirement": "PSD-REC-008", "level": "must", "kind": "violation",
          "what": "record read of par 44 (16 bit) answered with 4 bytes"}])]
    s.at_cycle[1400] = [lambda cap, t, sc: alarm_frames(
        cap, t, [{"requirement": "PN-ALARM-001", "level": "informative", "kind": "allowed",
                  "what": "diagnosis alarm of slot 1 subslot 1"}])]
    s.counter_skew[1100] = 16

    def counter(frame):
        if frame["cycle"] == 1100:
            tag(frame, "PN-RT-CC-001", "the device's cycle counter advances by 48 (1.5 "
                                       "cycles) once")

    def reserved(frame):
        if frame["cycle"] == 1250:
            frame["control"] |= C_RESERVED3
            tag(frame, "PSD-CTL-3-001", "control word with reserved bit 3")
    s.in_hooks.append(counter)
    s.out_hooks.append(reserved)
    return s


def motion_plants(s, first_target, jump_after, speed_target, prio_after, beyond, abort,
                  toggle_after):
    """Plants against the motion, placed by the marks of the controller's steps:
    - bit 0 set during the run to `first_target` while 1,934 increments away;
    - a 30,000-increment position jump at standstill, `jump_after` ms after mark `jump`;
    - a reported speed of 1450 rpm for 25 cycles in the run to `speed_target`;
    - bits 0 and 10 together `prio_after` ms after mark `prio`;
    - the target `beyond` (beyond par 42) run without bit 12;
    - the release withdrawn during the run to `abort` without bit 5;
    - the toggle bit not echoed for 30 ms after the first toggle after mark `toggle`."""
    st = {"bit0": None, "jump": None, "speed": None, "prio": None, "toggle": None,
          "echo": None}
    drive = s.drive

    def in_hook(frame):
        d = frame["drive"]
        c = d.cycle
        actual = actual_of(frame)
        if st["bit0"] is None and d.mode == "position" and d.target == first_target \
                and 1934 <= abs(d.target - actual) <= 1937:
            st["bit0"] = c
            set_status(frame, S_REACHED)
            tag(frame, "PSD-PAR-44-001",
                f"status bit 0 during the run at {actual}, target {first_target}, window 2")
        elif st["bit0"] is not None and c - st["bit0"] < 3:
            set_status(frame, S_REACHED)
        if "jump" in s.marks and st["jump"] is None and c >= s.marks["jump"] + jump_after:
            st["jump"] = c
            d.pos += 30_000
            d.status = (d.status | S_MANUAL_ROT) & ~S_REACHED
            frame["image"] = d.image()
            tag(frame, "PSD-VEL-002",
                "actual position jumps by 30,000 increments within one cycle at standstill "
                "(1000 rpm, the fastest PSD4xx, is about 7 increments per ms)")
        if st["speed"] is None and st["jump"] is not None and d.mode == "position" \
                and d.target == speed_target and abs(d.speed) >= 300:
            st["speed"] = c
            tag(frame, "PSD-VEL-002",
                "current rpm reads 1450 for 25 cycles during a positioning run (PSD4xx "
                "models reach at most 1000 rpm, 3.4 par 53)")
        if st["speed"] is not None and 0 <= c - st["speed"] < 25:
            set_speed(frame, 1450 if d.speed > 0 else -1450)
        if "prio" in s.marks and st["prio"] is None and c >= s.marks["prio"] + prio_after:
            st["prio"] = c
            set_status(frame, S_REACHED | S_OBSTRUCTION)
            tag(frame, "PSD-STS-0-PRIO", "status bits 0 and 10 set together at standstill")
        if "toggle" in s.marks and st["toggle"] is None and c > s.marks["toggle"] \
                and bool(d.control & C_TOGGLE) != st["echo"]:
            st["toggle"] = c
            tag(frame, "PSD-CTL-13-001",
                "status bit 2 keeps the old toggle value for 30 ms after control bit 13 "
                "changed")
        if st["toggle"] is not None and c - st["toggle"] < 30:
            set_status(frame, clear_bits=S_TOGGLE, set_bits=S_TOGGLE if st["echo"] else 0)
        elif st["toggle"] is None:
            st["echo"] = bool(d.control & C_TOGGLE)

    s.in_hooks.append(in_hook)

    plain = drive.control_word

    def control_word(c, target):
        # The drive accepts the target beyond the limits and runs (no bit 12), and stops
        # the run to `abort` without bit 5.
        if target == beyond and c & C_TRANSFER and drive.seen_target != target:
            drive.seen_target = target
            drive.target = target
            drive.status &= ~S_REACHED
            if c & C_RELEASE:
                drive.new_run()
                drive.mode = "position"
            drive.control = c
            return
        if drive.target == abort and drive.mode == "position" and not c & C_RELEASE:
            drive.control = c
            drive.mode = "stop"
            return
        plain(c, target)
    drive.control_word = control_word

    seen = {"beyond": False, "abort": False, "run": False}

    def out_hook(frame):
        if frame["target"] == beyond and frame["control"] & C_TRANSFER and not seen["beyond"]:
            seen["beyond"] = True
            tag(frame, "PSD-STS-12-SET-1",
                f"target {beyond} beyond par 42 transferred with 0x14; the drive runs "
                "towards it without status bit 12")
        if frame["target"] == abort:
            if frame["control"] & C_RELEASE:
                seen["run"] = True
            elif seen["run"] and not seen["abort"]:
                seen["abort"] = True
                tag(frame, "PSD-STS-5-SET-1",
                    f"release withdrawn during the run to {abort}; the drive stops without "
                    "status bit 5")
    s.out_hooks.append(out_hook)


def planted_motion():
    s = Scenario(
        "psd426-planted-motion",
        "Status bits against the motion: bit 0 during a run far from the target, bits 0 "
        "and 10 together, a target beyond par 42 run without bit 12, the release withdrawn "
        "without bit 5, the toggle bit not echoed, a 30,000-increment position jump at "
        "standstill, a reported speed above every PSD4xx model's limit",
        seed=426003,
    )
    s.steps = (
        [("wait", 100)]
        + commissioning()
        + run_to(16_000)
        + [s.mark("jump"), ("wait", 100)]
        + run_to(48_000)
        + [s.mark("prio"), ("wait", 60)]
        + abort_run(300_000, 200)
        + run_to(47_000)
        + abort_run(49_000, 300)
        + [s.mark("toggle"), ("wait", 150)]
        + run_to(46_500)
    )
    motion_plants(s, 16_000, 40, 48_000, 20, 300_000, 49_000, 0)
    return s


def idle_start():
    s = Scenario(
        "psd426-idle-start",
        "The capture starts inside a running AR (no Connect, no DCP) with 3 s of an idle "
        "drive (identical cyclic data but for one status glitch and one counter glitch) "
        "before the controller reads parameters and positions; plants in the idle stretch "
        "and after the drive starts to move",
        seed=426004,
        connect=False,
    )
    s.steps = (
        [("heartbeat", False), ("wait", 1500), s.mark("prio"), ("wait", 1500),
         ("heartbeat", True)]
        + commissioning()
        + run_to(16_000)
        + [s.mark("jump"), ("wait", 100)]
        + run_to(48_000)
        + [("wait", 60)]
        + abort_run(300_000, 200)
        + [s.mark("toggle"), ("wait", 150)]
        + run_to(47_000)
    )
    motion_plants(s, 16_000, 40, 48_000, 0, 300_000, None, 0)

    def counter(frame):
        if frame["cycle"] == 1700:
            tag(frame, "PN-RT-CC-001", "the device's cycle counter advances by 40 once, "
                                       "during the idle stretch")
    s.counter_skew[1700] = 8
    s.in_hooks.append(counter)
    s.probes = [{"what": "3 s of cyclic frames with constant data (no toggle bit, PKW 0, "
                         "control word 0) before the first PKW command"}]
    return s


def no_connect():
    s = Scenario(
        "psd426-no-connect",
        "No Connect and no DCP: the capture starts with cyclic traffic of a drive that is "
        "commissioned over PKW and positioned; PKW and motion plants",
        seed=426005,
        connect=False,
        start_pos=-20_000,
    )
    s.steps = (
        [("wait", 40)]
        + commissioning()
        + [("pkw", AK_READ, 40, 0), ("pkw", AK_WRITE_W, 57, 40)]
        + run_to(-16_000)
        + [s.mark("jump"), ("wait", 100)]
        + run_to(14_000 - 4_000)
        + [s.mark("prio"), ("wait", 60)]
        + run_to(13_000)
    )
    plant_pkw_answers(s, [
        (AK_READ, 40, (pke(RK_WORD, 40), 0, 0), "PSD-PKW-012",
         "read of par 40 (32 bit) answered with response 1 (word)"),
        (AK_WRITE_W, 57, (pke(RK_WORD, 57), 0, 45), "PSD-PKW-034",
         "write of par 57 = 40 answered with PWE 45"),
    ])
    motion_plants(s, -16_000, 40, 10_000, 20, None, None, None)
    return s


def controller_stop():
    s = Scenario(
        "psd426-controller-stop",
        "The controller goes to STOP for 60 ms during a positioning run: ProviderState "
        "STOP, IOPS bad, outputs zeroed; the drive keeps the last valid outputs (3.9), runs "
        "on and its toggle echo keeps the old value. The only finding due is the STOP "
        "after RUN, a should-level warning of IEC 61158-6-10",
        seed=426006,
    )
    s.steps = (
        [("wait", 100)]
        + commissioning()
        + [s.mark("run")]
        + run_to(18_000)
        + [("wait", 100)]
    )

    def stop(frame):
        if "run" not in s.marks:
            return
        k = frame["cycle"] - s.marks["run"]
        if 300 <= k < 360:
            frame["stop"] = True
            if k == 300:
                tag(frame, "PN-RT-DS-002", "controller ProviderState STOP after RUN, during a "
                                           "run, for 60 ms", level="should")
    s.out_hooks.append(stop)
    s.probes = [{"what": "IOPS bad and outputs zeroed while the controller is in STOP; the "
                         "drive's toggle echo keeps the last valid control word's bit 13"}]
    return s


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "corpus", "planted")
    os.makedirs(out_dir, exist_ok=True)
    for make in (clean, planted_protocol, planted_motion, idle_start, no_connect,
                 controller_stop):
        doc = make().build(out_dir)
        print(f"{doc['capture']}: {doc['frames']} frames, {len(doc['plants'])} plant(s)")


if __name__ == "__main__":
    main()
