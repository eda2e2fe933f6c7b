"""The device variants the suite runs against: one entry each. A new variant joins by adding one
`Variant(...)` to VARIANTS (its EDS, how canfleet-node starts it, the inputs that make its measured
objects read their EDS defaults, and what its RPDO and device-specific fault look like).

The variant list of canfleet-node is node/devices/registry.cpp (`canfleet-node --list-devices`):
today `quad-controller`, plus the generic node (`--eds FILE` without `--device`), which runs any
EDS on the plain CiA 301 stack; it is checked with two EDSs.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Optional, Tuple

REPO = Path(__file__).resolve().parents[2]


@dataclass
class DeviceFault:
    """A real fault of the device, and the EMCY (CiA 301 §7.2.7) it must cause."""

    what: str                      # for messages, with the clause / manual section
    inject: Callable               # (fleet, node) -> None
    clear: Callable                # (fleet, node) -> None
    code: int                      # EMCY error code
    register: int                  # 1001h in the EMCY frame
    data: bytes                    # manufacturer-specific bytes 3-7
    history: int                   # the 1003h sub 1 entry


@dataclass
class Variant:
    id: str                        # pytest id
    name: str                      # node name in the fleet's topology (for canfleet io/fault)
    eds: Path                      # the EDS the user loads into their master
    node_id: int
    device: Optional[str] = None   # canfleet-node --device; None = the generic node (--eds)
    # Simulated inputs that make measured objects read their EDS default (the EDS gives a measured
    # object no default beyond 0).
    default_io: List[str] = field(default_factory=list)
    # PDO test: inputs to set, and the values the TPDOs must then carry (index, sub) -> value.
    pdo_io: List[Tuple[str, str]] = field(default_factory=list)
    tpdo_expected: Dict[Tuple[int, int], int] = field(default_factory=dict)
    # RPDO test: values for the objects RPDO1 maps; optional simulated outputs that must follow.
    rpdo_values: Dict[Tuple[int, int], int] = field(default_factory=dict)
    rpdo_outputs: Dict[str, str] = field(default_factory=dict)
    # Heartbeat-consumer EMCY (CiA 301 §7.2.8.3.2.2, 8130h): error register and manufacturer bytes
    # for a lost heartbeat of node `hb_node`, and the 1003h entry.
    hb_register: int = 0x11
    hb_data: Callable[[int], bytes] = lambda node: bytes([node, 0, 0, 0, 0])
    hb_history: Callable[[int], int] = lambda node: (node << 16) | 0x8130
    device_faults: List[DeviceFault] = field(default_factory=list)
    # Objects a master may read but that have no data to give (read aborts that are correct).
    no_data: Callable[[int, int], bool] = lambda index, sub: index == 0x1003 and sub > 0

    def node_args(self) -> List[str]:
        if self.device:
            return ["--device", self.device]
        return ["--eds", str(self.eds)]


def _io_set(signal: str, value: str):
    def run(fleet, node):
        fleet.cli("io", "set", node.variant.name, signal, value)
    return run


def _fault_inject(*args: str):
    def run(fleet, node):
        fleet.cli("fault", "inject", *args, "--node", node.variant.name, "--label", "conformance")
    return run


def _fault_clear(fleet, node):
    fleet.cli("fault", "clear", "--label", "conformance")


# Quad (AX020506 manual V2.02, §4.1): the channel byte then the description byte follow the code;
# 1003h holds (description << 8 | channel) << 16 | code.
QUAD = Variant(
    id="quad-controller",
    name="quad-5",
    device="quad-controller",
    eds=REPO / "node/devices/quad_controller/quad-controller.eds",
    node_id=5,
    default_io=["AIN1.voltage_mV=0", "AIN2.voltage_mV=0", "AIN3.voltage_mV=0", "AIN4.voltage_mV=0",
                "FIN1.duty_pct=0", "FIN2.duty_pct=0"],
    # Manual §3.1.1 default TPDO1: 7100h sub 1-4, the AI field values, in mV at the default 0-5 V
    # sensor type (§3.3.1); 6000h sub 1 in TPDO3 has bit n-1 set for a high DINn (§3.2.1).
    pdo_io=[("AIN1.voltage_mV", "1200"), ("AIN2.voltage_mV", "800"), ("AIN3.voltage_mV", "400"),
            ("AIN4.voltage_mV", "1600")],
    tpdo_expected={(0x7100, 1): 1200, (0x7100, 2): 800, (0x7100, 3): 400, (0x7100, 4): 1600},
    # Manual §3.1.1 default RPDO1: 7330h sub 1-4, the POUT current commands (mA) with 3010h = 0
    # (control by CAN, §3.5.1); the measured current 30C0h follows (§3.5.22).
    rpdo_values={(0x7330, 1): 500, (0x7330, 2): 600, (0x7330, 3): 700, (0x7330, 4): 800},
    rpdo_outputs={"POUT1.current_mA": "500", "POUT4.current_mA": "800"},
    # Manual §4.1/§4.2: a lost heartbeat is 8130h with description 08h and the node-ID as channel;
    # only the generic bit of 1001h is used (§3.1.3, canfleet's README choice 1).
    hb_register=0x01,
    hb_data=lambda node: bytes([node, 0x08, 0, 0, 0]),
    hb_history=lambda node: (((0x08 << 8) | node) << 16) | 0x8130,
    device_faults=[
        DeviceFault(
            what="short circuit at POUT1 (manual §4.1: 2320h, description 04h, channel 01h)",
            inject=_io_set("POUT1.load", "short"), clear=_io_set("POUT1.load", "nominal"),
            code=0x2320, register=0x01, data=bytes([0x01, 0x04, 0, 0, 0]), history=0x04012320),
        DeviceFault(
            what="open circuit at POUT2 (manual §4.1: 3300h, description 04h, channel 02h)",
            inject=_io_set("POUT2.load", "open"), clear=_io_set("POUT2.load", "nominal"),
            code=0x3300, register=0x01, data=bytes([0x02, 0x04, 0, 0, 0]), history=0x04023300),
    ],
)

# The generic node with the demo's hand-written CiA 401 module (topologies/eds/canfleet-dio16.eds).
DIO16 = Variant(
    id="generic-dio16",
    name="dio-20",
    eds=REPO / "topologies/eds/canfleet-dio16.eds",
    node_id=20,
    tpdo_expected={(0x6000, 1): 0},
    rpdo_values={(0x6200, 1): 0xA5, (0x6200, 2): 0x5A},
    device_faults=[
        DeviceFault(
            what="CAN controller error passive (CiA 301 §7.2.7.1 table 21: 8120h, communication bit 4)",
            inject=_fault_inject("error-passive"), clear=_fault_clear,
            code=0x8120, register=0x11, data=bytes(5), history=0x8120),
    ],
)

# The generic node with the suite's own EDS: strings and a domain to write, signed and 64-bit
# defaults, LSS support (tests/conformance/eds/conformance-io.eds).
CONFORMANCE_IO = Variant(
    id="generic-conformance-io",
    name="io-21",
    eds=REPO / "tests/conformance/eds/conformance-io.eds",
    node_id=21,
    tpdo_expected={(0x6000, 1): 0, (0x6401, 1): -1234, (0x2100, 1): -100000},
    rpdo_values={(0x6200, 1): 0xC3, (0x6411, 1): -20000, (0x2100, 3): -7},
    device_faults=DIO16.device_faults,
)

VARIANTS = [QUAD, DIO16, CONFORMANCE_IO]
