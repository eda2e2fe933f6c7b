#!/usr/bin/env python3
"""python-can's socketcand client on a canfleet socketcand endpoint (driven by python_test.cpp).

Connects with can.Bus(interface="socketcand"), prints READY, sends --send frames, then receives
--receive frames and prints each as "RX <id hex> <extended 0/1> <dlc> <data hex or -> <timestamp>",
then DONE. Frame i of either side is frame(i) below; the C++ test builds the same frames.
"""
import argparse
import sys
import time

import can


def frame(i: int) -> can.Message:
    extended = i % 3 == 2
    if i % 7 == 5:
        arbitration_id = 0x123  # a 29-bit id with a small value when extended
    elif extended:
        arbitration_id = 0x1ABC0000 + i
    else:
        arbitration_id = 0x100 + i % 0x600
    dlc = i % 9
    data = bytes((i + k * 17) & 0xFF for k in range(dlc))
    return can.Message(arbitration_id=arbitration_id, is_extended_id=extended, data=data, dlc=dlc)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, required=True)
    parser.add_argument("--channel", default="can0")
    parser.add_argument("--send", type=int, default=0)
    parser.add_argument("--receive", type=int, default=0)
    parser.add_argument("--first", type=int, default=0, help="index of the first frame received")
    parser.add_argument("--timeout", type=float, default=20.0)
    args = parser.parse_args()

    print(f"VERSION {can.__version__}", flush=True)
    with can.Bus(interface="socketcand", host=args.host, port=args.port, channel=args.channel) as bus:
        print("READY", flush=True)
        for i in range(args.send):
            bus.send(frame(i))
        print("SENT", flush=True)
        received = 0
        deadline = time.monotonic() + args.timeout
        while received < args.receive and time.monotonic() < deadline:
            msg = bus.recv(timeout=0.5)
            if msg is None:
                continue
            print(
                f"RX {msg.arbitration_id:X} {int(msg.is_extended_id)} {msg.dlc} "
                f"{bytes(msg.data).hex().upper() or '-'} {msg.timestamp:.6f}",
                flush=True,
            )
            received += 1
    print(f"DONE {received}", flush=True)
    return 0 if received == args.receive else 1


if __name__ == "__main__":
    sys.exit(main())
