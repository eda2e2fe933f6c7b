#!/usr/bin/env python3
"""CPU per idle node (issue 20 §1): N canfleet-node processes of one variant on one canfleet-broker
bus, nothing changing, and what each costs.

Every node runs the variant's own EDS with the heartbeat producer 1017h = 500 ms and a consumer of
its neighbour's heartbeat (1016h sub 1 = 1500 ms), as in the issue; --operational also sets 5555h
(the Quad's "start in operational") so the default TPDOs (event timer 100 ms) run. After --settle
seconds the script reads every node's CPU time twice, --window seconds apart, and prints per node:
  - CPU % of one core from /proc/PID/stat utime+stime (10 ms clock ticks; all threads, live or
    ended), and from /proc/PID/task/*/schedstat (nanoseconds, live threads): the same figure, finer;
  - wake-ups per second: voluntary context switches of all live threads (/proc/PID/task/*/status).
  - resident memory (VmRSS) at the end of the window.
The broker's own CPU is printed for reference. With --monitor a canfleet-bus-client listens on the
bus (bus times in ns) and the script adds the fleet's figures: the start time (first node launched
→ a boot-up or heartbeat of every node seen on the bus), the heartbeat period of every node during
the window (deviation from 500 ms: min/p50/p99/max) and the EMCY 8130h frames (heartbeat lost)
of the whole run: false faults, since nothing is injected. It is a benchmark, not a test: it prints
figures.

A bus has at most 127 node-IDs: --buses K spreads the nodes over K buses of the one broker
(can0, can1, ...; node-IDs 1.. on each, each consuming its neighbour's heartbeat on its own bus),
so 500 nodes run as --nodes 500 --buses 4. A variant with two CAN ports (the data logger) needs
--ports 2: every node then has port 1 on can0 and port 2 on can1, and runs at its factory settings
(the compiled-in EDS, no --eds: the heartbeat and consumer above are not set).

  bench/idle/idle_bench.py --bin build/ [--nodes 10] [--buses 1] [--window 30] [--settle 5]
                           [--operational] [--no-telemetry] [--monitor] [--device quad-controller]
                           [--eds BASE.eds]
"""

import argparse
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time

CLK_TCK = os.sysconf("SC_CLK_TCK")


def find_binary(bin_dir, name):
    for sub in ("bin", "", "node/process", "orchestrator"):
        path = os.path.join(bin_dir, sub, name)
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    sys.exit(f"{name} not found under {bin_dir}")


def base_eds(node, device, given):
    if given:
        with open(given, encoding="utf-8") as f:
            return f.read()
    out = subprocess.run([node, "--device", device, "--write-eds", "-"], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"{node} cannot write the {device} EDS (older build? give --eds): {out.stderr.strip()}")
    return out.stdout


def set_default(eds, section, value):
    """Sets DefaultValue of [section]; the section must exist."""
    pattern = re.compile(r"(^\[" + re.escape(section) + r"\]\s*$.*?^DefaultValue=)[^\r\n]*", re.M | re.S | re.I)
    new, count = pattern.subn(lambda m: m.group(1) + value, eds, count=1)
    if count != 1:
        sys.exit(f"the EDS has no [{section}] DefaultValue")
    return new


def cpu_ticks(pid):
    with open(f"/proc/{pid}/stat", encoding="ascii") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])  # utime, stime (fields 14, 15 of proc(5))


def threads(pid):
    try:
        return os.listdir(f"/proc/{pid}/task")
    except FileNotFoundError:
        return []


def sched_ns_and_switches(pid):
    ns = 0
    switches = 0
    for tid in threads(pid):
        try:
            with open(f"/proc/{pid}/task/{tid}/schedstat", encoding="ascii") as f:
                ns += int(f.read().split()[0])
            with open(f"/proc/{pid}/task/{tid}/status", encoding="ascii") as f:
                for line in f:
                    if line.startswith("voluntary_ctxt_switches:"):
                        switches += int(line.split()[1])
        except (FileNotFoundError, ProcessLookupError):
            pass  # a thread ended between listing and reading
    return ns, switches


def sample(pid):
    ns, switches = sched_ns_and_switches(pid)
    return cpu_ticks(pid), ns, switches


def rss_kib(pid):
    with open(f"/proc/{pid}/status", encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


class Monitor:
    """Reads canfleet-bus-client --monitor: "rx BUS_TIME_NS ID#DATA" lines. Nodes are keyed
    (bus, node-ID)."""

    def __init__(self, cmd, bus):
        self.bus = bus
        self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1)
        self.lock = threading.Lock()
        self.first_seen = {}  # node-ID -> monotonic time of its first boot-up or heartbeat
        self.heartbeats = {}  # node-ID -> [bus time ns]
        self.heartbeat_losses = 0
        self.connected = threading.Event()
        self.thread = threading.Thread(target=self.read, daemon=True)
        self.thread.start()

    def read(self):
        for line in self.proc.stdout:
            parts = line.split()
            if parts and parts[0] == "connected":
                self.connected.set()
            if len(parts) != 3 or parts[0] != "rx" or "#" not in parts[2]:
                continue
            ident, data = parts[2].split("#", 1)
            can_id, t = int(ident, 16), int(parts[1])
            with self.lock:
                if 0x701 <= can_id <= 0x77F and len(data) == 2:
                    node = (self.bus, can_id - 0x700)
                    self.first_seen.setdefault(node, time.monotonic())
                    if data != "00":  # 00 is the boot-up
                        self.heartbeats.setdefault(node, []).append(t)
                elif 0x81 <= can_id <= 0xFF and data.upper().startswith("3081"):
                    self.heartbeat_losses += 1  # EMCY 8130h, little-endian

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def percentile(values, q):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def summary(values):
    return (f"mean {statistics.mean(values):8.4f}  median {statistics.median(values):8.4f}  "
            f"min {min(values):8.4f}  max {max(values):8.4f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True, help="build folder with canfleet-node and canfleet-broker")
    ap.add_argument("--nodes", type=int, default=10)
    ap.add_argument("--buses", type=int, default=1, help="spread the nodes over this many buses")
    ap.add_argument("--ports", type=int, choices=(1, 2), default=1,
                    help="2: two-port nodes on can0 and can1, at factory settings")
    ap.add_argument("--window", type=float, default=30.0, help="measurement window, seconds")
    ap.add_argument("--settle", type=float, default=5.0, help="seconds between start and measurement")
    ap.add_argument("--bitrate", default="250k")
    ap.add_argument("--device", default="quad-controller")
    ap.add_argument("--eds", help="the variant's EDS (default: canfleet-node --write-eds)")
    ap.add_argument("--operational", action="store_true", help="5555h = 1: boot operational (TPDOs run)")
    ap.add_argument("--no-telemetry", action="store_true", help="start the nodes with --no-telemetry")
    ap.add_argument("--monitor", action="store_true",
                    help="listen on the bus: start time, heartbeat periods, EMCY 8130h")
    args = ap.parse_args()
    if args.ports == 2:
        if args.buses != 1 or args.operational or args.eds or args.monitor:
            sys.exit("--ports 2 runs every node on can0 and can1 at factory settings: "
                     "no --buses, --operational, --eds, --monitor")
        args.buses = 2
    if args.buses < 1 or not 1 <= args.nodes <= 127 * args.buses:
        sys.exit("--nodes: 1..127 per bus (--buses)")
    per_bus = -(-args.nodes // args.buses)  # ceiling
    bus_names = [f"can{b}" for b in range(args.buses)]
    # Node k (0-based) is on bus k // per_bus with node-ID k % per_bus + 1.
    placement = [(k // per_bus, k % per_bus + 1) for k in range(args.nodes)]
    if args.ports == 2:  # every node on both buses; the placement names its node-ID
        per_bus = args.nodes
        placement = [(0, k + 1) for k in range(args.nodes)]
    on_bus = [sum(1 for b, _ in placement if b == bus) for bus in range(args.buses)]

    node_bin = find_binary(args.bin, "canfleet-node")
    broker_bin = find_binary(args.bin, "canfleet-broker")
    if args.ports == 2:
        eds = None
    else:
        eds = set_default(base_eds(node_bin, args.device, args.eds), "1017", "500")
        if args.operational:
            eds = set_default(eds, "5555", "1")

    work = tempfile.mkdtemp(prefix="canfleet-idle-")
    procs = []
    monitors = []
    try:
        sock = os.path.join(work, "broker.sock")
        ready = os.path.join(work, "ready")
        bus_args = [a for name in bus_names for a in ("--bus", f"{name}:{args.bitrate}")]
        broker = subprocess.Popen([broker_bin, *bus_args, "--listen", f"unix://{sock}",
                                   "--ready-file", ready, "--no-telemetry", "--log-level", "warn"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        procs.append(broker)
        deadline = time.monotonic() + 10
        while not os.path.exists(ready):
            if time.monotonic() > deadline or broker.poll() is not None:
                sys.exit("the broker did not start")
            time.sleep(0.05)
        if args.monitor:
            for b, name in enumerate(bus_names):
                monitors.append(Monitor([find_binary(args.bin, "canfleet-bus-client"), "--connect", f"unix://{sock}",
                                         "--bus", name, "--monitor", "--name", f"idle-bench-monitor-{name}",
                                         "--log-level", "warn"], b))
            for m in monitors:
                if not m.connected.wait(10):
                    sys.exit(f"the monitor of {bus_names[m.bus]} did not connect")
        nodes = []
        launched = time.monotonic()
        for k, (b, i) in enumerate(placement):
            if args.ports == 2:
                cmd = [node_bin, "--device", args.device, "--node-id", str(i), "--node-id", str(i),
                       "--bus", f"can0@unix://{sock}", "--bus", f"can1@unix://{sock}", "--log-level", "warn"]
                if args.no_telemetry:
                    cmd.append("--no-telemetry")
                nodes.append(subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                              stderr=subprocess.DEVNULL))
                procs.append(nodes[-1])
                continue
            neighbour = i % on_bus[b] + 1
            node_eds = eds
            if on_bus[b] > 1:
                node_eds = set_default(node_eds, "1016sub1", f"0x{(neighbour << 16) | 1500:08X}")
            path = os.path.join(work, f"node{k + 1}.eds")
            with open(path, "w", encoding="utf-8") as f:
                f.write(node_eds)
            cmd = [node_bin, "--device", args.device, "--eds", path, "--node-id", str(i),
                   "--bus", f"{bus_names[b]}@unix://{sock}", "--log-level", "warn"]
            if args.no_telemetry:
                cmd.append("--no-telemetry")
            p = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            procs.append(p)
            nodes.append(p)
        time.sleep(args.settle)
        dead = [p.args for p in nodes if p.poll() is not None]
        if dead:
            sys.exit(f"{len(dead)} node(s) ended early, e.g. {' '.join(dead[0])}")

        load_start = os.getloadavg()[0]
        before = {p.pid: sample(p.pid) for p in nodes + [broker]}
        t0 = time.monotonic()
        hb_mark = {}
        losses_before_window = 0
        for m in monitors:
            with m.lock:
                hb_mark.update({n: len(v) for n, v in m.heartbeats.items()})
                losses_before_window += m.heartbeat_losses
        time.sleep(args.window)
        after = {p.pid: sample(p.pid) for p in nodes + [broker]}
        elapsed = time.monotonic() - t0
        rss = [rss_kib(p.pid) / 1024.0 for p in nodes]

        def rates(pid):
            (t_a, ns_a, sw_a), (t_b, ns_b, sw_b) = before[pid], after[pid]
            return (100.0 * (t_b - t_a) / CLK_TCK / elapsed, 100.0 * (ns_b - ns_a) / 1e9 / elapsed,
                    (sw_b - sw_a) / elapsed)

        per_node = [rates(p.pid) for p in nodes]
        where = f"{args.buses} buses at {args.bitrate} ({per_bus} nodes each at most)" if args.buses > 1 \
            else f"can0:{args.bitrate}"
        print(f"{args.nodes} x {args.device} on {where}, "
              f"{'operational (TPDOs every 100 ms)' if args.operational else 'pre-operational'}, "
              f"{'two ports (can0, can1), factory settings' if args.ports == 2 else 'heartbeat 500 ms + consumer 1500 ms'}, "
              f"telemetry {'off' if args.no_telemetry else 'on'}, "
              f"window {elapsed:.1f} s, load average {load_start:.2f} at its start, {os.getloadavg()[0]:.2f} at its end")
        print(f"  node CPU % of a core (stat):      {summary([r[0] for r in per_node])}")
        print(f"  node CPU % of a core (schedstat): {summary([r[1] for r in per_node])}")
        print(f"  node wake-ups per second:         {summary([r[2] for r in per_node])}")
        print(f"  node RSS MiB:                     {summary(rss)}")
        b = rates(broker.pid)
        total = sum(r[1] for r in per_node) + b[1]
        print(f"  broker CPU % (schedstat) {b[1]:.3f}, wake-ups/s {b[2]:.1f}; nodes + broker {total:.2f} % of a core")
        if monitors:
            time.sleep(0.5)  # the last frames of the window reach the monitors
            seen = {}
            deviations = []
            losses = 0
            for m in monitors:
                with m.lock:
                    seen.update(m.first_seen)
                    for n, times in m.heartbeats.items():
                        window = times[max(hb_mark.get(n, 0) - 1, 0):]
                        deviations += [(b2 - a2) / 1e6 - 500.0 for a2, b2 in zip(window, window[1:])]
                    losses += m.heartbeat_losses
            ready = (f"{max(seen.values()) - launched:.1f} s" if len(seen) == args.nodes
                     else f"not all seen ({len(seen)} of {args.nodes})")
            print(f"  fleet start (launch -> every node seen on the bus): {ready}")
            if deviations:
                print(f"  heartbeat period - 500 ms, ms: min {min(deviations):.2f}  p50 {percentile(deviations, 0.5):.2f}  "
                      f"p99 {percentile(deviations, 0.99):.2f}  max {max(deviations):.2f}  ({len(deviations)} periods)")
            print(f"  EMCY 8130h (heartbeat lost): {losses - losses_before_window} in the window, "
                  f"{losses} in the whole run")
    finally:
        for m in monitors:
            m.stop()
        for p in reversed(procs):
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        for p in reversed(procs):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
