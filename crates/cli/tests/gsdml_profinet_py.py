"""Reads a GSDML file with profinet-py (PyPI, GPL-3.0; an external test tool, never
vendored or linked) and prints what an IO controller built from it would connect: the
identity and one line per slot/subslot with its IO lengths and idents, as JSON.

Exit 3 when profinet-py is not installed."""

import json
import sys

try:
    from profinet.gsdml import load_gsdml
except ImportError:
    sys.exit(3)

device = load_gsdml(sys.argv[1])
print(
    json.dumps(
        {
            "vendor_id": device.vendor_id,
            "device_id": device.device_id,
            "slots": [
                [s.slot, s.subslot, s.input_length, s.output_length, s.module_ident, s.submodule_ident]
                for s in device.build_io_slots()
            ],
        }
    )
)
