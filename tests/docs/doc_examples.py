#!/usr/bin/env python3
"""Runs the command examples of the project's READMEs and compares their output with what the READMEs
show, so that the docs cannot drift from the code (issue 29, point 7).

Every fenced code block of a checked file whose lines start with `$ ` (a shell prompt) is an
example: each `$ ` line is a command, the lines after it up to the next `$ ` line are its output. A
block without prompts whose info string is `sh` (`scripts/demo.sh`) is a list of commands. The
HTML comment right above a block says how to run it (invisible when the README is rendered):

    <!-- doc-test: fleet=demo at=44 mask=numbers -->

    fleet=NAME     the fleet the commands drive: topologies/NAME.textproto, started once per NAME
                   by this runner in virtual time, paced (--speed), on private endpoints and a DDS
                   domain of its own; CANFLEET_CONTROL and CANFLEET_DDS_DOMAIN point the commands at
                   it. NAME:LABEL starts another fleet of the same topology (for `canfleet down`).
                   fleet=none: no orchestrator runs.
    at=SECONDS     run once the fleet's simulated time has reached SECONDS (blocks of one fleet run
                   in the order of their `at`, across files)
    mask=numbers   compare with every decimal number masked (live tables: counters, loads, ages)
    mask=numbers,events  also `canfleet top`'s recent events: each line under "recent events"
                   stands for any event (simultaneous events reach the view in either order, and
                   which of them are the newest five is decided by microseconds)
    order=any      compare the lines in any order (a real-time run decides simultaneous things in
                   either order)
    output=any     run the commands and check their exit codes only
    skip=REASON    not run here, and why (another test runs it, or it needs what CI lacks)
    demo=SECONDS   scripts/demo.sh: run it for SECONDS of real time, then Ctrl-C; it must have
                   shown the live view and stopped every process it started

A block with prompts and no comment is an error: a new example is tested or says why not. Outputs
are compared after masking what changes from run to run (wall-clock times, timings with decimals,
temporary paths, process ids; see `normalise`); a line `...` in the README stands for any number of
lines. Commands run in a scratch folder holding tests/docs/files/ (the files examples name, e.g.
broken.textproto), with bash; a command must exit 0 unless the block goes on with `$ echo $?`.

  doc_examples.py --build-dir build FILE.md...            check (exit 1 on a difference)
  doc_examples.py --build-dir build --update FILE.md...    write the actual outputs into the files
                                                           (scripts/readme-captures.sh)
"""
from __future__ import annotations

import argparse
import difflib
import json
import os
import re
import select
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Set

REPO = Path(__file__).resolve().parents[2]
FILES = Path(__file__).resolve().parent / "files"
# Simulated seconds per real second of the fleets this runner starts: the demo's faults (40, 60,
# 80 s) come within 40 s, and a command (about a second of real time) lands within two simulated
# seconds of the time its block asks for, before the next thing the scenario does.
SPEED = 2
FLEET_START_TIMEOUT = 120.0
COMMAND_TIMEOUT = 120.0
DDS_DOMAIN_BASE = 150  # domains 150.. belong to this test


@dataclass
class Command:
    line: str  # without the "$ "
    expected: List[str] = field(default_factory=list)
    actual: List[str] = field(default_factory=list)
    status: int = 0


@dataclass
class Block:
    path: Path
    first_line: int  # 1-based line of the opening fence
    options: Dict[str, str]
    commands: List[Command]
    prompted: bool  # `$ ` lines (else a `sh` list of commands)
    body_range: tuple  # (start, end) line indexes of the block's body in the file, 0-based, end exclusive

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(REPO)}:{self.first_line}"


ANNOTATION = re.compile(r"^<!--\s*doc-test:(.*?)-->\s*$")


def parse_options(text: str, where: str) -> Dict[str, str]:
    options: Dict[str, str] = {}
    # key=value pairs; a value runs to the next " key=" (skip reasons contain spaces).
    for match in re.finditer(r"(\w+)=(.*?)(?=\s+\w+=|$)", text.strip()):
        options[match.group(1)] = match.group(2).strip()
    known = {"fleet", "at", "mask", "output", "skip", "demo", "order"}
    unknown = set(options) - known
    if unknown:
        raise SystemExit(f"{where}: unknown doc-test option(s) {sorted(unknown)} (known: {sorted(known)})")
    return options


def parse_file(path: Path) -> List[Block]:
    lines = path.read_text().splitlines()
    blocks: List[Block] = []
    i = 0
    while i < len(lines):
        fence = re.match(r"^```(\S*)\s*$", lines[i])
        if not fence:
            i += 1
            continue
        info = fence.group(1)
        start = i
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        body = lines[start + 1:j]
        where = f"{path.relative_to(REPO)}:{start + 1}"
        annotation = None
        k = start - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        if k >= 0:
            m = ANNOTATION.match(lines[k])
            if m:
                annotation = parse_options(m.group(1), where)
        prompted = any(line.startswith("$ ") for line in body)
        if prompted or (info == "sh" and annotation is not None) or (info == "sh" and body):
            commands: List[Command] = []
            if prompted:
                for line in body:
                    if line.startswith("$ "):
                        commands.append(Command(line[2:]))
                    elif commands:
                        commands[-1].expected.append(line)
                    elif line.strip():
                        raise SystemExit(f"{where}: output before the first `$ ` line")
            else:
                commands = [Command(re.sub(r"\s+#.*$", "", line)) for line in body if line.strip()]
            if annotation is None:
                raise SystemExit(f"{where}: a command example without a `<!-- doc-test: ... -->` line above it "
                                 "(say how to run it, or skip=REASON)")
            blocks.append(Block(path, start + 1, annotation, commands, prompted, (start + 1, j)))
        i = j + 1
    return blocks


# --- comparing -----------------------------------------------------------------------------------

MASKS = [
    (re.compile(r"\d{4}-\d\d-\d\d[T ]\d\d:\d\d:\d\d(\.\d+)?Z?"), "<TIME>"),
    (re.compile(r"\(\d{9,}\.\d+\)"), "(<TIME>)"),  # candump times
    (re.compile(r"\b\d+\.\d+ ?(s|ms|x)\b"), r"<N>\1"),  # measured timings and speed factors
    (re.compile(r"\b\d\d:\d\d:\d\d\.\d{3}\b"), "<CLOCK>"),  # top's and watch's event times
    (re.compile(r"\b\d+:\d\d:\d\d\b"), "<UPTIME>"),
    (re.compile(r"\bpid \d+"), "pid <PID>"),
    (re.compile(r"canfleet-(test|doc)-\w+"), r"canfleet-\1-<ID>"),  # mkdtemp's folders
    (re.compile(r"(/[\w.+<>-]+)+/(?=[\w.+<>-]+)"), "<DIR>/"),  # absolute folders (keep the file's name)
    # A fault table's HITS (`canfleet fault list`, `status`): frames a fault touched so far, which
    # depends on the instant the command lands (FAULT STATE STARTED ENDED HITS LABEL SUMMARY).
    (re.compile(r"^(\s*\d+\s+[a-z]+\s+\S+\s+\S+\s+)\d+(?=\s)"), r"\1<HITS>"),
]
# A number alone, with a unit of time ("16s", "250ms": ages and periods) or as a factor ("2.0x real
# time": achieved, so a loaded machine shows 1.9x).
NUMBER = re.compile(r"(?<![\w.#-])\d+(\.\d+)?(?:(?=m?s\b|x\b)|(?![\w.]))")
# A candump record's identifier and payload ("185#B0042003"), a JSON frame's base64 payload.
PAYLOAD = re.compile(r"\b[0-9A-F]{3}(?:[0-9A-F]{5})?#[0-9A-FR]*|(\"data\":\")[0-9A-Za-z+/=]+")


def normalise(line: str, mask_numbers: bool) -> str:
    for pattern, replacement in MASKS:
        line = pattern.sub(replacement, line)
    if mask_numbers:
        line = PAYLOAD.sub(lambda m: (m.group(1) + "<DATA>") if m.group(1) else "<ID>#<DATA>", line)
        line = NUMBER.sub("<N>", line)
    return re.sub(r"\s+", " ", line).strip()


def block_masks(block: "Block") -> Set[str]:
    masks = set(filter(None, block.options.get("mask", "").split(",")))
    unknown = masks - {"numbers", "events"}
    if unknown:
        raise SystemExit(f"{block.where}: unknown mask(s) {sorted(unknown)} (known: numbers, events)")
    return masks


def normalised(lines: List[str], masks: Set[str]) -> List[str]:
    out = [normalise(x, "numbers" in masks) if x.strip() != "..." else "..." for x in lines]
    if "events" in masks:
        in_events = False
        for i, line in enumerate(out):
            if line == "recent events":
                in_events = True
            elif in_events and line.startswith("q quit"):
                in_events = False
            elif in_events:
                out[i] = "<EVENT>"
    while out and out[-1] == "":
        out.pop()
    return out


def matches(expected: List[str], actual: List[str], masks: Set[str], any_order: bool = False) -> bool:
    """`expected` (with `...` lines standing for any number of lines) against `actual`."""
    exp = normalised(expected, masks)
    act = normalised(actual, masks)
    if any_order:
        return sorted(exp) == sorted(act)

    def match(e: int, a: int) -> bool:
        if e == len(exp):
            return a == len(act)
        if exp[e] == "...":
            return any(match(e + 1, k) for k in range(a, len(act) + 1))
        return a < len(act) and exp[e] == act[a] and match(e + 1, a + 1)

    return match(0, 0)


def updated_output(expected: List[str], actual: List[str]) -> List[str]:
    """The actual lines, with the README's `...` elisions kept where the lines around them still match."""
    if "..." not in [x.strip() for x in expected]:
        return actual
    head = []
    for x in expected:
        if x.strip() == "...":
            break
        head.append(x)
    tail = []
    for x in reversed(expected):
        if x.strip() == "...":
            break
        tail.insert(0, x)
    if len(head) + len(tail) <= len(actual):
        return actual[:len(head)] + ["..."] + (actual[len(actual) - len(tail):] if tail else [])
    return actual


# --- fleets --------------------------------------------------------------------------------------


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Fleet:
    def __init__(self, name: str, bin_dir: Path, work: Path, domain: int):
        topology_name = name.split(":")[0]
        self.name = name
        self.bin_dir = bin_dir
        if not (REPO / "topologies" / f"{topology_name}.textproto").exists():
            raise SystemExit(f"doc-test: fleet={name}: no topologies/{topology_name}.textproto")
        self.state = work / f"fleet-{name.replace(':', '-')}"
        # A copy of topologies/ (its files name EDS files beside them): the fleet's stored parameters
        # go to the copy's .canfleet/, not to the repository's, and no two fleets share them.
        shutil.copytree(REPO / "topologies", self.state / "topologies", ignore=shutil.ignore_patterns(".canfleet"))
        # Named relative to the fleet's folder, its working folder: what the fleet prints (verdicts
        # name their file) reads as a user's `canfleet up topologies/demo.textproto` does.
        self.topology = Path("topologies") / f"{topology_name}.textproto"
        self.control = f"tcp://127.0.0.1:{free_port()}"
        self.domain = domain
        self.log = self.state / "orchestrator.log"
        ready = self.state / "ready"
        env = dict(os.environ, CANFLEET_DDS_DOMAIN=str(domain))
        self.proc = subprocess.Popen(
            [str(bin_dir / "canfleet"), "up", str(self.topology), "--time", "virtual", "--speed", str(SPEED),
             "--control", self.control, "--listen", "tcp://127.0.0.1:0", "--ready-file", str(ready)],
            stdout=open(self.log, "w"), stderr=subprocess.STDOUT, cwd=self.state, env=env,
            start_new_session=True)
        deadline = time.monotonic() + FLEET_START_TIMEOUT
        while "state ready" not in (ready.read_text() if ready.exists() else ""):
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise SystemExit(f"doc-test: fleet {name} did not start:\n{self.log.read_text()[-3000:]}")
            time.sleep(0.1)

    def env(self) -> Dict[str, str]:
        return {"CANFLEET_CONTROL": self.control, "CANFLEET_DDS_DOMAIN": str(self.domain)}

    def simulated_s(self) -> float:
        out = subprocess.run([str(self.bin_dir / "canfleet"), "--control", self.control, "status", "--json"],
                             capture_output=True, text=True, timeout=60)
        if out.returncode != 0:
            raise SystemExit(f"doc-test: fleet {self.name}: status failed: {out.stderr}")
        return float(json.loads(out.stdout)["uptime_s"])

    def wait_until(self, seconds: float) -> None:
        while True:
            now = self.simulated_s()
            if now >= seconds:
                return
            if self.proc.poll() is not None:
                raise SystemExit(f"doc-test: fleet {self.name} exited:\n{self.log.read_text()[-3000:]}")
            time.sleep(min(1.0, max(0.05, (seconds - now) / SPEED / 2)))

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()


# --- running -------------------------------------------------------------------------------------

MARK = "<<<doc-test status"


def run_block(block: Block, work: Path, env: Dict[str, str]) -> None:
    """Runs the block's commands in one bash (so `echo $?` sees the previous command's status)."""
    script = ["set +e", "exec 2>&1"]  # stderr in its place among the output, as a terminal shows it
    for command in block.commands:
        script.append(command.line)
        script.append(f'__s=$?; printf "\\n{MARK} %d>>>\\n" "$__s"; (exit $__s)')
    out = subprocess.run(["bash", "-c", "\n".join(script)], cwd=work, env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, errors="replace",
                         timeout=COMMAND_TIMEOUT * max(1, len(block.commands)))
    text = out.stdout
    parts = re.split(rf"\n?{re.escape(MARK)} (\d+)>>>\n", text)
    for index, command in enumerate(block.commands):
        chunk = parts[2 * index] if 2 * index < len(parts) else ""
        command.actual = chunk.splitlines()
        command.status = int(parts[2 * index + 1]) if 2 * index + 1 < len(parts) else -1


def session_processes(sid: int) -> List[str]:
    """The live processes of session `sid` ("PID COMMAND"), zombies left out."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
        except OSError:
            continue  # gone meanwhile
        fields = stat.rsplit(")", 1)[1].split()  # after "pid (comm)": state ppid pgrp session ...
        if int(fields[3]) == sid and fields[0] != "Z":
            found.append(f"{entry.name} {cmdline}")
    return found


def run_demo(block: Block, seconds: float, env: Dict[str, str]) -> List[str]:
    """scripts/demo.sh for `seconds`, then Ctrl-C: what went wrong, or nothing."""
    problems: List[str] = []
    proc = subprocess.Popen(["bash", str(REPO / "scripts" / "demo.sh")], cwd=REPO, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
    assert proc.stdout is not None
    fd = proc.stdout.fileno()
    output: List[bytes] = []

    def drain(until: float) -> None:
        # Raw reads of the pipe (no text layer: a non-blocking TextIOWrapper fails on an empty read).
        while time.monotonic() < until:
            ready, _, _ = select.select([fd], [], [], max(0.0, min(0.2, until - time.monotonic())))
            if ready:
                chunk = os.read(fd, 65536)
                if not chunk:
                    return  # every writer closed the pipe
                output.append(chunk)
            elif proc.poll() is not None:
                return

    drain(time.monotonic() + seconds)
    os.killpg(proc.pid, signal.SIGINT)
    drain(time.monotonic() + 60)
    try:
        proc.wait(timeout=5)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        problems.append("scripts/demo.sh did not stop within 60 s of Ctrl-C")
    text = b"".join(output).decode(errors="replace")
    for needed in ("live view", "canfleet top", "demo stopped"):
        if needed not in text:
            problems.append(f"scripts/demo.sh never printed {needed!r}")
    # The demo's processes are those of its session (start_new_session; the fleet's children get
    # process groups of their own, never sessions): other tests' canfleet processes do not count.
    left = session_processes(proc.pid)
    if left:
        problems.append(f"processes left after Ctrl-C: {left}")
    if problems:
        problems.append("its output (end):\n" + text[-3000:])
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build-dir", default=str(REPO / "build"))
    parser.add_argument("--update", action="store_true", help="write the actual outputs into the files")
    parser.add_argument("--no-demo", action="store_true", help="leave out scripts/demo.sh (demo=)")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    bin_dir = Path(args.build_dir).resolve() / "bin"
    for tool in ("canfleet", "canfleet-node"):
        if not (bin_dir / tool).exists():
            print(f"doc-test: {bin_dir / tool} is missing (build first)", file=sys.stderr)
            return 2

    blocks: List[Block] = []
    for name in args.files:
        blocks += parse_file((REPO / name).resolve())

    work = Path(tempfile.mkdtemp(prefix="canfleet-doc-"))
    shutil.copytree(FILES, work, dirs_exist_ok=True)
    # The READMEs' commands run from the repository's top folder: `canfleet check topologies/...`.
    (work / "topologies").symlink_to(REPO / "topologies")
    base_env = dict(os.environ)
    base_env["PATH"] = f"{bin_dir}:{base_env['PATH']}"
    for variable in ("CANFLEET_CONTROL", "CANFLEET_DDS_CONFIG", "CYCLONEDDS_URI"):
        base_env.pop(variable, None)
    base_env["CANFLEET_DDS_DOMAIN"] = str(DDS_DOMAIN_BASE)

    failures: List[str] = []
    skipped = 0
    ran = 0
    fleets: Dict[str, Fleet] = {}
    # Fleet by fleet, each fleet's blocks in the order of their time.
    order = sorted(blocks, key=lambda b: (b.options.get("fleet", "none"), float(b.options.get("at", 0))))
    try:
        for block in order:
            # A fleet whose blocks are done stops before the next fleet starts (two cores).
            for name in [n for n in fleets if n != block.options.get("fleet")]:
                fleets.pop(name).stop()
            if "skip" in block.options:
                if not block.options["skip"]:
                    failures.append(f"{block.where}: skip= needs a reason")
                skipped += 1
                continue
            if "demo" in block.options:
                # scripts/demo.sh builds and runs build/: only a test of that folder may start it.
                if args.no_demo or Path(args.build_dir).resolve() != REPO / "build":
                    print(f"doc-test: {block.where}: scripts/demo.sh not run (it builds and runs build/, "
                          f"this run tests {args.build_dir})")
                    skipped += 1
                    continue
                problems = run_demo(block, float(block.options["demo"]), base_env)
                failures += [f"{block.where}: {p}" for p in problems]
                ran += 1
                continue
            fleet_name = block.options.get("fleet")
            if fleet_name is None:
                failures.append(f"{block.where}: say fleet=NAME (or fleet=none)")
                continue
            env = dict(base_env)
            if fleet_name != "none":
                if fleet_name not in fleets:
                    fleets[fleet_name] = Fleet(fleet_name, bin_dir, work, DDS_DOMAIN_BASE + 1 + len(fleets))
                fleet = fleets[fleet_name]
                fleet.wait_until(float(block.options.get("at", 0)))
                env.update(fleet.env())
            run_block(block, work, env)
            ran += 1
            mask = block_masks(block)
            for index, command in enumerate(block.commands):
                # A command may fail where the README shows it failing: its status is shown next, or
                # its output is the tool's error line.
                next_is_status = index + 1 < len(block.commands) and block.commands[index + 1].line == "echo $?"
                shows_error = bool(command.expected) and re.match(r"^[\w.-]+:", command.expected[0]) is not None
                if command.status != 0 and not (next_is_status or shows_error):
                    failures.append(f"{block.where}: `{command.line}` exited {command.status}:\n  " +
                                    "\n  ".join(command.actual[-20:]))
                    continue
                if block.options.get("output") == "any" or not block.prompted:
                    continue
                any_order = block.options.get("order") == "any"
                if not matches(command.expected, command.actual, mask, any_order):
                    # The lines as compared (masked), so that the difference that counts stands out.
                    diff = difflib.unified_diff(normalised(command.expected, mask), normalised(command.actual, mask),
                                                "README (masked)", "actual (masked)", lineterm="")
                    failures.append(f"{block.where}: `{command.line}` printed something else:\n  " +
                                    "\n  ".join(diff))
    finally:
        for fleet in fleets.values():
            fleet.stop()

    if args.update:
        write_updates([b for b in blocks if b.prompted and "skip" not in b.options and "demo" not in b.options
                       and b.options.get("output") != "any"])
        print(f"doc-test: outputs written into {len(args.files)} file(s); review with git diff")
    print(f"doc-test: {ran} examples run, {skipped} skipped (with reasons), {len(failures)} problems")
    for failure in failures:
        print(f"FAIL {failure}")
    if failures and not args.update:
        print(f"state and logs: {work}")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    return 0


def write_updates(blocks: List[Block]) -> None:
    by_file: Dict[Path, List[Block]] = {}
    for block in blocks:
        by_file.setdefault(block.path, []).append(block)
    for path, file_blocks in by_file.items():
        lines = path.read_text().splitlines()
        for block in sorted(file_blocks, key=lambda b: b.body_range[0], reverse=True):
            body: List[str] = []
            for command in block.commands:
                body.append("$ " + command.line)
                body += [line.rstrip() for line in updated_output(command.expected, command.actual)]
            start, end = block.body_range
            lines[start:end] = body
        path.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
