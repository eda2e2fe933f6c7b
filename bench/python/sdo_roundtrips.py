#!/usr/bin/env python3
"""SDO expedited round trips per second from Python (python-canopen 2.4.1 on python-can 4.6.1): in
real time over the fleet's socketcand endpoint and over the "canfleet" python-can interface (the
node wire protocol), and in virtual time over the interface (a fleet driven by this process: per
wall-clock second, and the simulated time each round trip takes on the bus). One fleet, one Quad
controller, SDO upload of 1017h (2 bytes, expedited, CiA 301 §7.2.4.3.6) in a loop. Figures:
bench/python/README.md.

Usage: .venv/bin/python bench/python/sdo_roundtrips.py [--count N] [--bitrate B] [--bin-dir DIR]
"""
from __future__ import annotations

import argparse
import socket
import statistics
import tempfile
import time
from pathlib import Path
from typing import Dict, List

import canopen

from canfleet import Fleet


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def measure(network: canopen.Network, count: int, fleet: Fleet) -> Dict[str, float]:
    node = canopen.RemoteNode(5, canopen.ObjectDictionary())
    node.sdo.RESPONSE_TIMEOUT = 5.0
    network.add_node(node)
    for _ in range(50):  # warm-up: connections, caches, the node's first answers
        node.sdo.upload(0x1017, 0)
    latencies: List[float] = []
    start = time.perf_counter()
    for _ in range(count):
        t = time.perf_counter()
        node.sdo.upload(0x1017, 0)
        latencies.append(time.perf_counter() - t)
    elapsed = time.perf_counter() - start
    latencies.sort()
    result = {"per_s": count / elapsed, "median_ms": statistics.median(latencies) * 1e3,
              "p99_ms": latencies[int(len(latencies) * 0.99) - 1] * 1e3}
    if fleet.clock is not None:
        sim_start = fleet.now
        for _ in range(count):
            node.sdo.upload(0x1017, 0)
        result["sim_us"] = (fleet.now - sim_start) / count * 1e6
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=2000, help="round trips per transport (default 2000)")
    parser.add_argument("--bitrate", type=int, default=500_000, help="bus bit rate (default 500000)")
    parser.add_argument("--rounds", type=int, default=3, help="alternating rounds per transport (default 3)")
    parser.add_argument("--bin-dir", default=None, help="folder of canfleet and canfleet-node")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory(prefix="canfleet-bench-") as work:
        port = free_port()
        topology = Path(work) / "bench.textproto"
        topology.write_text(
            'name: "sdo-bench"\n'
            f'bus {{ name: "can0" bitrate: {args.bitrate} socketcand_port: {port} }}\n'
            'node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" }\n')
        with Fleet.up(topology, bin_dir=args.bin_dir) as fleet:
            results: Dict[str, List[Dict[str, float]]] = {"socketcand": [], "canfleet": []}
            for _ in range(args.rounds):
                for transport in results:
                    network = canopen.Network()
                    if transport == "socketcand":
                        network.connect(interface="socketcand", host="127.0.0.1", port=port, channel="can0")
                    else:
                        network.connect(interface="canfleet", channel="can0", fleet=fleet)
                    try:
                        results[transport].append(measure(network, args.count, fleet))
                    finally:
                        network.disconnect()
        virtual_topology = Path(work) / "bench-virtual.textproto"
        virtual_topology.write_text(
            'name: "sdo-bench-virtual"\n'
            f'bus {{ name: "can0" bitrate: {args.bitrate} }}\n'
            'node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" }\n')
        virtual: List[Dict[str, float]] = []
        with Fleet.up(virtual_topology, time="virtual", bin_dir=args.bin_dir) as fleet:
            for _ in range(args.rounds):
                network = canopen.Network()
                network.connect(interface="canfleet", channel="can0", fleet=fleet)
                try:
                    virtual.append(measure(network, args.count, fleet))
                finally:
                    network.disconnect()
    print(f"SDO expedited upload 1017h, {args.count} round trips x {args.rounds} rounds, "
          f"bus at {args.bitrate} bit/s, real time")
    print(f"{'transport':<12} {'round trips/s':>14} {'median ms':>10} {'p99 ms':>8}")
    for transport, runs in results.items():
        best = max(runs, key=lambda r: r["per_s"])
        print(f"{transport:<12} {statistics.median(r['per_s'] for r in runs):>14.0f} "
              f"{statistics.median(r['median_ms'] for r in runs):>10.3f} {best['p99_ms']:>8.3f}")
    best = max(virtual, key=lambda r: r["per_s"])
    print(f"{'virtual':<12} {statistics.median(r['per_s'] for r in virtual):>14.0f} "
          f"{statistics.median(r['median_ms'] for r in virtual):>10.3f} {best['p99_ms']:>8.3f}   "
          f"(canfleet interface, driven virtual time: wall-clock figures; each round trip takes "
          f"{statistics.median(r['sim_us'] for r in virtual):.0f} us of simulated bus time)")


if __name__ == "__main__":
    main()
