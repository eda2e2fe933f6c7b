#!/usr/bin/env python3
"""canfleet web with a 500-node fleet (issue 31): four canfleet-fake-fleet processes publish 125
nodes each (NodeStatus, IoSnapshot, EMCYs, BusStats) on a DDS domain of their own; `canfleet web`
serves them at 5 Hz to a headless chromium showing the page. Over a measured window it prints the
server's CPU and memory, the bytes per second it sends the browser, the updates the page applied,
and the browser's own CPU. Figures: bench/web/README.md.

Usage: .venv/bin/python bench/web/web_bench.py [--nodes 500] [--seconds 30] [--update-ms 200] [--bin-dir DIR]
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "system" / "web"))
from browser import Browser, find_chromium  # noqa: E402


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--nodes", type=int, default=500)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--update-ms", type=int, default=200)
    parser.add_argument("--bin-dir", default=str(REPO / "build" / "bin"))
    args = parser.parse_args()
    chromium = find_chromium()
    if chromium is None:
        raise SystemExit("no chromium (apt-get install chromium)")
    bin_dir = Path(args.bin_dir)
    env = dict(os.environ, CANFLEET_DDS_DOMAIN="97")
    work = Path(tempfile.mkdtemp(prefix="canfleet-web-bench-"))
    procs = []
    try:
        per_bus = 125
        for b in range((args.nodes + per_bus - 1) // per_bus):
            n = min(per_bus, args.nodes - b * per_bus)
            procs.append(subprocess.Popen(
                [str(bin_dir / "canfleet-fake-fleet"), "--bus", f"can{b}", "--nodes", str(n), "--names", "node",
                 "--io", "--emcy-every", "10", "--update", "0.1"] + (["--orchestrator"] if b == 0 else []),
                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL))
        ready = work / "web.ready"
        web = subprocess.Popen([str(bin_dir / "canfleet"), "web", "--listen", "127.0.0.1:0", "--read-only",
                                "--update-ms", str(args.update_ms), "--ready-file", str(ready)],
                               env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        procs.append(web)
        while not ready.exists():
            time.sleep(0.1)
        url = ready.read_text().split()[1]
        browser = Browser(chromium, 1400, 1500)
        try:
            browser.open(url)
            browser.wait_for(f"document.querySelectorAll('#overview tbody tr').length >= {args.nodes}", 120)
            time.sleep(5)  # settle: discovery and the first full snapshot are not the steady state
            c0, b0 = cpu_seconds(web.pid), browser.cpu_seconds()
            m0 = browser.js("[window.canfleet.messages, window.canfleet.bytes]")
            t0 = time.monotonic()
            time.sleep(args.seconds)
            dt = time.monotonic() - t0
            c1, b1 = cpu_seconds(web.pid), browser.cpu_seconds()
            m1 = browser.js("[window.canfleet.messages, window.canfleet.bytes]")
            rows = browser.js("document.querySelectorAll('#overview tbody tr').length")
            points = browser.js("Object.values(window.canfleet.series).reduce((n, s) => n + s.length, 0)")
        finally:
            browser.close()
        print(f"canfleet web, {rows} nodes on {len(procs) - 1} buses, updates every {args.update_ms} ms, "
              f"{dt:.0f} s measured")
        print(f"  server CPU          {100 * (c1 - c0) / dt:6.1f} % of one core")
        print(f"  server memory       {rss_mib(web.pid):6.1f} MiB RSS (retention 600 s)")
        print(f"  to the browser      {(m1[1] - m0[1]) / dt / 1024:6.1f} KiB/s, "
              f"{(m1[0] - m0[0]) / dt:.1f} updates/s applied by the page")
        print(f"  browser CPU         {100 * (b1 - b0) / dt:6.1f} % of one core (every chromium process)")
        print(f"  page's series       {points} points kept")
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()


if __name__ == "__main__":
    main()
