#!/usr/bin/env python3
"""Frames per second between two python-can processes: a comparison point for the transport table.

    python_can_bench.py udp_multicast [--frames N]
    python_can_bench.py socketcand HOST PORT [--frames N]   (a canfleet socketcand endpoint)

A receiver process and a sender process each open one python-can Bus. The sender sends N 8-byte
frames as fast as bus.send() returns; the receiver counts them. Printed: frames received, the
sender's rate (N / time spent in send) and the receiver's rate (frames received / time from the
first to the last one). udp_multicast may lose frames (UDP, no flow control); socketcand runs over
TCP and the broker's session applies backpressure, so nothing is lost there.

Needs python-can 4.6.1 (the version scripts/python-env.sh pins) and, for udp_multicast, msgpack,
which the project's venv does not carry: see bench/transport/README.md for a throwaway venv.
"""

import argparse
import multiprocessing as mp
import time

import can

GROUP = "239.74.163.2"  # python-can's default IPv4 group for udp_multicast


def open_bus(args):
    if args.interface == "udp_multicast":
        return can.Bus(interface="udp_multicast", channel=GROUP)
    return can.Bus(interface="socketcand", host=args.host, port=args.port, channel="can0")


def receiver(args, ready, result):
    bus = open_bus(args)
    ready.set()
    count = 0
    first = last = None
    idle_deadline = time.monotonic() + 30  # waiting for the first frame
    while count < args.frames:
        msg = bus.recv(timeout=0.5)
        now = time.monotonic()
        if msg is None:
            if now > idle_deadline:
                break
            continue
        if first is None:
            first = now
        last = now
        count += 1
        idle_deadline = now + 2.0  # the sender is done when nothing came for 2 s
    bus.shutdown()
    result.put((count, first, last))


def sender(args, start, result):
    bus = open_bus(args)
    start.wait()
    time.sleep(0.5)  # let the receiver's subscription settle
    data = bytes([0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88])
    t0 = time.monotonic()
    for i in range(args.frames):
        bus.send(can.Message(arbitration_id=0x100 + (i & 0x7F), data=data, is_extended_id=False))
    t1 = time.monotonic()
    time.sleep(0.5)  # socketcand: let the last writes leave before the socket closes
    bus.shutdown()
    result.put(t1 - t0)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("interface", choices=["udp_multicast", "socketcand"])
    parser.add_argument("host", nargs="?", default="127.0.0.1")
    parser.add_argument("port", nargs="?", type=int, default=29536)
    parser.add_argument("--frames", type=int, default=100_000)
    args = parser.parse_args()

    ctx = mp.get_context("spawn")  # two fresh interpreters, as two separate programs would be
    ready, rx_result, tx_result = ctx.Event(), ctx.Queue(), ctx.Queue()
    rx = ctx.Process(target=receiver, args=(args, ready, rx_result))
    tx = ctx.Process(target=sender, args=(args, ready, tx_result))
    rx.start()
    tx.start()
    send_time = tx_result.get()
    count, first, last = rx_result.get()
    tx.join()
    rx.join()
    rx_rate = (count - 1) / (last - first) if count > 1 and last > first else 0.0
    print(f"{args.interface}: sent {args.frames} in {send_time:.2f} s ({args.frames / send_time:.0f} frames/s), "
          f"received {count} ({100.0 * count / args.frames:.1f} %) at {rx_rate:.0f} frames/s")


if __name__ == "__main__":
    main()
