"""An independent PROFINET IO controller: profinet-py (PyPI, GPL-3.0; an external test tool,
never vendored or linked) runs a plan against a device and prints what it saw, as JSON.

    python3 profinet_py_controller.py IFACE NAME GSDML PLAN_JSON

It knows nothing of the PSD4xx: the plan gives the bytes. In order it
1. finds every station by DCP Identify All and then NAME by DCP Identify by name;
2. reads the plan's "implicit" records without an AR (Read Implicit);
3. connects an IO AR with the slots of the GSDML (send clock factor 32, reduction ratio 32:
   a 32 ms cycle; data hold factor 30: the device ends the AR after 0.96 s without output
   frames, which a Python controller on a loaded machine stays within), PrmEnd, answers
   ApplicationReady;
4. runs the plan's "actions" in that AR: {"read": [slot, subslot, index]},
   {"write": [slot, subslot, index, hex]}, and {"output": hex, "until": [mask, want]}:
   the output image of the plan's output submodule is set, then the input image of its input
   submodule is read every cycle until (input & mask) == want, or 5 s pass;
5. releases the AR.

Output: {"scan": [...], "found": {...}, "implicit": [...], "actions": [...]}; a refused
record gives {"error": text}, an action that timed out "met": false with the last input.

Exit 3 when profinet-py is not installed; 4 when the whole run takes more than 40 s."""

import json
import signal
import sys
import time

try:
    from profinet import IOCRSetup, ProfinetDevice, scan
    from profinet.exceptions import PNIOError, RPCError
    from profinet.gsdml import load_gsdml
except ImportError:
    sys.exit(3)

# Longest wait for one "until" condition, and for the whole run.
UNTIL_S = 5.0
RUN_S = 40


def give_up(_signum, _frame):
    print("profinet-py controller: no result within %d s" % RUN_S, file=sys.stderr)
    sys.exit(4)


def record(call):
    try:
        return {"data": call().hex()}
    except (PNIOError, RPCError) as e:
        return {"error": str(e)}


def main():
    iface, name, gsdml, plan = sys.argv[1], sys.argv[2], sys.argv[3], json.loads(sys.argv[4])
    signal.signal(signal.SIGALRM, give_up)
    signal.alarm(RUN_S)
    out = {"scan": [], "implicit": [], "actions": []}
    for d in scan(iface, timeout=1.0):
        out["scan"].append(
            {"name": d.name, "vendor_id": d._info.vendor_id, "device_id": d._info.device_id}
        )
    dev = ProfinetDevice.discover(name, iface, timeout=2.0)
    out["found"] = {"name": dev.name, "ip": dev.ip, "mac": dev.mac}
    # ProfinetDevice.connect() opens a Device Access AR (ARType IOSAR, ARProperties
    # DeviceAccess). IEC 61158-6-10 makes that AR optional (GSDML DeviceAccessSupported,
    # default false) and the generated GSDML does not claim it, so the device refuses that
    # Connect (ErrorCode1 ARBlockReq, ErrorCode2 4: ARType). Records are read here without an
    # AR and read and written inside the IO AR below.
    for slot, subslot, index in plan["implicit"]:
        out["implicit"].append(record(lambda: dev.read_implicit(slot, subslot, index)))
    (oslot, osub), (islot, isub) = plan["output"], plan["input"]
    slots = load_gsdml(gsdml).build_io_slots()
    setup = IOCRSetup(
        slots=slots,
        send_clock_factor=32,
        reduction_ratio=32,
        watchdog_factor=30,
        data_hold_factor=30,
    )
    cyclic = dev.start_cyclic(setup)
    try:
        for a in plan["actions"]:
            if "read" in a:
                slot, subslot, index = a["read"]
                out["actions"].append(record(lambda: dev.read(slot, subslot, index)))
            elif "write" in a:
                slot, subslot, index, data = a["write"]
                out["actions"].append(
                    record(lambda: dev.write(slot, subslot, index, bytes.fromhex(data)) or b"")
                )
            else:
                cyclic.set_output_data(oslot, osub, bytes.fromhex(a["output"]))
                mask, want = (bytes.fromhex(x) for x in a["until"])
                end = time.monotonic() + UNTIL_S
                got, met = None, False
                while not met and time.monotonic() < end:
                    time.sleep(0.01)
                    got = cyclic.get_input_data(islot, isub, allow_bad=True)
                    met = got is not None and bytes(g & m for g, m in zip(got, mask)) == want
                out["actions"].append(
                    {
                        "input": got.hex() if got is not None else None,
                        "iops_good": cyclic.is_input_good(islot, isub),
                        "met": met,
                    }
                )
    finally:
        cyclic.stop()
        dev.close()
    print(json.dumps(out))


main()
