#!/usr/bin/env python3
"""Renders a canfleet fleet for Docker swarm from a shard file (topologies/swarm.shards).

One shard per bus: an orchestrator service (`canfleet up` with a topology of that bus alone: its
broker, control API, socketcand endpoint) and a node service whose tasks take their node-ID and
name from the swarm task slot, so `docker service scale <stack>_<bus>-nodes=N` adds or removes
nodes. A `node` line makes one service for one node instead. Writes into OUT:

  stack.yaml               the stack file (docker stack deploy -c OUT/stack.yaml STACK)
  <bus>.textproto          each shard's topology (a swarm config mounted into its orchestrator)
  cyclonedds-swarm.xml     the DDS configuration every container uses (unicast, no multicast)
  monitor-uri.txt          the same as one line, for CYCLONEDDS_URI of an ad-hoc monitor
  shards.json              what scripts/docker-swarm.sh needs to know afterwards (ports, slots)

Python 3 standard library only. Called by scripts/docker-swarm.sh; run it with --help for options.
"""

import argparse
import hashlib
import ipaddress
import json
import os
import re
import shlex
import sys

EDS_DIR = "/usr/local/share/canfleet/topologies"  # where the image keeps topologies/ (and eds/)
CONTAINER_BROKER, CONTAINER_CONTROL, CONTAINER_SOCKETCAND = 29600, 29700, 29536
NAME_RE = re.compile(r"^[a-z][a-z0-9-]{0,30}$")  # a bus or node name: part of service and DNS names


class ShardError(Exception):
    pass


def parse_shards(path):
    """The shard file: `bus NAME key=value...` and `node NAME key=value...` lines, # comments."""
    buses, nodes = [], []
    with open(path, encoding="utf-8") as f:
        for lineno, raw in enumerate(f, 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            where = f"{path}:{lineno}"
            try:
                words = shlex.split(line)
            except ValueError as e:
                raise ShardError(f"{where}: {e}")
            kind, name, rest = words[0], (words[1] if len(words) > 1 else ""), words[2:]
            if kind not in ("bus", "node"):
                raise ShardError(f"{where}: a line starts with 'bus' or 'node', not '{kind}'")
            if not NAME_RE.match(name):
                raise ShardError(f"{where}: '{name}' is not a valid name (lower case, digits, '-', at most 31)")
            entry = {"name": name, "where": where, "constraint": [], "io": []}
            for word in rest:
                if "=" not in word:
                    raise ShardError(f"{where}: '{word}' is not key=value")
                key, value = word.split("=", 1)
                if key in ("constraint", "io"):
                    entry[key].append(value)
                elif key in entry:
                    raise ShardError(f"{where}: {key} given twice")
                else:
                    entry[key] = value
            (buses if kind == "bus" else nodes).append(entry)
    if not buses:
        raise ShardError(f"{path}: no 'bus' line")
    return buses, nodes


def as_int(entry, key, default, lo, hi):
    value = entry.get(key, default)
    try:
        number = int(str(value), 0)
    except ValueError:
        raise ShardError(f"{entry['where']}: {key}={value} is not a number")
    if not lo <= number <= hi:
        raise ShardError(f"{entry['where']}: {key}={number} is outside {lo}..{hi}")
    return number


def check_keys(entry, allowed):
    unknown = sorted(set(entry) - allowed - {"name", "where", "constraint", "io"})
    if unknown:
        raise ShardError(f"{entry['where']}: unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(allowed))})")


def device_of(entry):
    """(device, eds) as the topology and canfleet-node take them; default the Quad controller."""
    if "device" in entry and "eds" in entry:
        raise ShardError(f"{entry['where']}: give device= or eds=, not both")
    eds = entry.get("eds", "")
    if eds and not eds.startswith("/"):
        eds = f"{EDS_DIR}/{eds}"  # relative to the image's topologies folder, like topologies' own paths
    return ("" if eds else entry.get("device", "quad-controller")), eds


def quote(s):
    return json.dumps(s)  # a protobuf text-format string and a YAML double-quoted scalar alike


# ---- the topology of one shard -------------------------------------------------------------------

def topology(stack, bus, slot_nodes, single_nodes):
    """`canfleet up` input for one bus: every node external (its own task), configured after boot-up."""
    out = [
        "# proto-file: orchestrator/topology/canfleet_topology.proto",
        "# proto-message: canfleet.topology.Topology",
        f"# Rendered by docker/swarm/render.py for stack {stack}, shard {bus['name']}: do not edit; edit the",
        "# shard file and deploy again. Every node is external: a task of this shard's node service",
        "# (node-ID = task slot) or a service of its own; the orchestrator configures it after each boot-up.",
        "",
        f"name: {quote(stack + '-' + bus['name'])}",
        "orchestrator {",
        f"  control: \"tcp://0.0.0.0:{CONTAINER_CONTROL}\"",
        f"  listen: \"tcp://0.0.0.0:{CONTAINER_BROKER}\"",
        "  state_root: \"/var/lib/canfleet/state\"",
        "}",
        f"bus {{ name: {quote(bus['name'])} bitrate: {bus['bitrate']} socketcand_port: {CONTAINER_SOCKETCAND} }}",
        "",
    ]
    everyone = [(n["node_id"], n) for n in slot_nodes] + [(n["node_id"], n) for n in single_nodes]
    ids = {node_id for node_id, _ in everyone}
    for node_id, node in sorted(everyone, key=lambda x: x[0]):
        lines = ["node {", f"  name: {quote(node['node_name'])}"]
        if node["device"]:
            lines.append(f"  device: {quote(node['device'])}")
        if node["eds"]:
            lines.append(f"  eds: {quote(node['eds'])}")
        lines += [f"  node_id: {node_id}", f"  bus: {quote(bus['name'])}", "  external: true"]
        for sdo in node.get("sdo", []):
            lines.append(f"  sdo {{ {sdo} }}")
        hb = [f"producer_ms: {node['heartbeat_ms']}"]
        # Each node watches its predecessor (the first one its successor): killing any node makes
        # one consumer report the loss (CiA 301 §7.2.8.3.2.2). A consumer of a node-ID that never
        # sent a heartbeat does not report anything (monitoring starts with the first heartbeat).
        watched = node.get("watch")
        if watched is None:
            watched = node_id - 1 if node_id - 1 in ids else node_id + 1
        if watched and watched in ids and watched != node_id and node["consumer_ms"] > 0:
            hb.append(f"consumer {{ node_id: {watched} timeout_ms: {node['consumer_ms']} }}")
        lines.append(f"  heartbeat {{ {' '.join(hb)} }}")
        lines.append("}")
        out += lines
    return "\n".join(out) + "\n"


# ---- DDS -----------------------------------------------------------------------------------------

def monitor_addresses(subnet, count):
    """The fixed addresses of the monitor slots: the top of the subnet, outside the range from which
    swarm gives tasks their addresses (the network's --ip-range is the lower half)."""
    hosts = subnet.broadcast_address
    return [str(hosts - 1 - i) for i in range(count)]


def cyclone_config(subnet, slots, domain):
    """Unicast discovery on the overlay. Writers (nodes, orchestrators) append their announce-only
    settings (telemetry/dds.hpp: no multicast, no participant index, SPDP every second): they send
    their announcement to the monitor slots listed here, one port each, and meet nobody else.
    Monitors (canfleet top/watch) run at a slot address, alone in their container, so they take
    participant index 0, the port named here; they answer every writer that announces itself."""
    port = 7400 + 250 * domain + 10  # DDSI unicast discovery port of participant index 0 (PB + DG*d + d1)
    peers = "".join(f'<Peer address="{a}:{port}"/>' for a in slots)
    network = str(subnet.network_address)
    return (
        '<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">'
        # The overlay interface (matched by its network; a task also has eth1 on docker_gwbridge).
        f'<General><Interfaces><NetworkInterface address="{network}"/></Interfaces>'
        "<AllowMulticast>false</AllowMulticast></General>"
        "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>9</MaxAutoParticipantIndex>"
        f"<Peers>{peers}</Peers></Discovery>"
        "</Domain></CycloneDDS>"
    )


# ---- YAML (block style; every scalar JSON-quoted, which YAML reads as a double-quoted string) -----

def to_yaml(value, indent=0):
    pad = "  " * indent
    if isinstance(value, dict):
        if not value:
            return " {}"
        out = []
        for key, item in value.items():
            if isinstance(item, (dict, list)) and item:
                out.append(f"{pad}{key}:\n{to_yaml(item, indent + 1)}")
            else:
                out.append(f"{pad}{key}:{to_yaml(item, indent + 1) if isinstance(item, (dict, list)) else ' ' + scalar(item)}")
        return "\n".join(out)
    if isinstance(value, list):
        if not value:
            return " []"
        out = []
        for item in value:
            if isinstance(item, dict) and item:
                body = to_yaml(item, indent + 1).lstrip()
                out.append(f"{pad}- {body}")
            else:
                out.append(f"{pad}- {scalar(item)}")
        return "\n".join(out)
    return scalar(value)


def scalar(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    return json.dumps(str(value))


# ---- the stack -----------------------------------------------------------------------------------

def render(args):
    buses, singles = parse_shards(args.shards)
    subnet = ipaddress.ip_network(args.subnet)
    if subnet.version != 4 or subnet.prefixlen > 24:
        raise ShardError(f"--subnet {args.subnet}: an IPv4 network of /24 or larger")
    slots = monitor_addresses(subnet, args.monitors)
    names = set()
    shards = []
    for index, bus in enumerate(buses):
        check_keys(bus, {"bitrate", "nodes", "max", "device", "eds", "heartbeat_ms", "consumer_ms",
                         "broker_port", "control_port", "socketcand_port"})
        if bus["name"] in names:
            raise ShardError(f"{bus['where']}: bus {bus['name']} named twice")
        names.add(bus["name"])
        bus["bitrate"] = as_int(bus, "bitrate", 500000, 10000, 1000000)
        device, eds = device_of(bus)
        shard = {
            "bus": bus["name"],
            "index": index,
            "bitrate": bus["bitrate"],
            "nodes": as_int(bus, "nodes", 0, 0, 127),
            "max": as_int(bus, "max", 127, 0, 127),
            "device": device,
            "eds": eds,
            "io": bus["io"],
            "heartbeat_ms": as_int(bus, "heartbeat_ms", 500, 0, 65535),
            "consumer_ms": as_int(bus, "consumer_ms", 1500, 0, 65535),
            "constraint": bus["constraint"],
            "ports": {
                "broker": as_int(bus, "broker_port", args.broker_base + index, 1, 65535),
                "control": as_int(bus, "control_port", args.control_base + index, 1, 65535),
                "socketcand": as_int(bus, "socketcand_port", args.socketcand_base + index, 1, 65535),
            },
            "singles": [],
        }
        if shard["nodes"] > shard["max"]:
            raise ShardError(f"{bus['where']}: nodes={shard['nodes']} is more than max={shard['max']}")
        shards.append(shard)
    by_bus = {s["bus"]: s for s in shards}
    for node in singles:
        check_keys(node, {"bus", "id", "device", "eds", "serial", "heartbeat_ms", "consumer_ms", "watch"})
        shard = by_bus.get(node.get("bus", ""))
        if shard is None:
            raise ShardError(f"{node['where']}: bus={node.get('bus', '')} is not a bus of this file")
        node_id = as_int(node, "id", None, 1, 127) if "id" in node else None
        if node_id is None:
            raise ShardError(f"{node['where']}: id= (the node-ID) is required")
        if node_id <= shard["max"]:
            raise ShardError(f"{node['where']}: id={node_id} is one of {shard['bus']}'s slots 1..{shard['max']}: "
                             f"give the bus a smaller max= or the node a higher id")
        if node["name"] in names or any(n["name"] == node["name"] for n in shard["singles"]):
            raise ShardError(f"{node['where']}: name {node['name']} used twice")
        names.add(node["name"])
        device, eds = device_of(node)
        shard["singles"].append({
            "node_name": node["name"], "node_id": node_id, "device": device, "eds": eds,
            "serial": node.get("serial"), "io": node["io"],
            "heartbeat_ms": as_int(node, "heartbeat_ms", 500, 0, 65535),
            "consumer_ms": as_int(node, "consumer_ms", 1500, 0, 65535),
            "watch": as_int(node, "watch", 0, 0, 127) if "watch" in node else None,
        })
        if any(n["node_id"] == node_id for n in shard["singles"][:-1]):
            raise ShardError(f"{node['where']}: node-ID {node_id} used twice on {shard['bus']}")
    used = {}
    for s in shards:
        for kind, port in s["ports"].items():
            if port in used:
                raise ShardError(f"host port {port} ({s['bus']} {kind}) is also {used[port]}: "
                                 "set the bases (--*-base) or the shard's *_port")
            used[port] = f"{s['bus']} {kind}"

    os.makedirs(args.out, exist_ok=True)
    dds = cyclone_config(subnet, slots, args.domain)
    files = {"cyclonedds-swarm.xml": dds + "\n", "monitor-uri.txt": dds + "\n"}
    for s in shards:
        slot_nodes = [{
            "node_name": f"{s['bus']}-node-{i}", "node_id": i, "device": s["device"], "eds": s["eds"],
            "heartbeat_ms": s["heartbeat_ms"], "consumer_ms": s["consumer_ms"],
        } for i in range(1, s["max"] + 1)]
        files[f"{s['bus']}.textproto"] = topology(args.stack, {"name": s["bus"], "bitrate": s["bitrate"]},
                                                  slot_nodes, s["singles"])

    def digest(name):
        return hashlib.sha256(files[name].encode()).hexdigest()[:10]

    # Configs are immutable in swarm: name them by content, so deploying a changed shard file again
    # creates new ones (the stack's old ones go with `docker stack rm`, or `docker config prune`).
    configs = {"dds": {"name": f"{args.stack}_dds-{digest('cyclonedds-swarm.xml')}", "file": "./cyclonedds-swarm.xml"}}
    # The fleet's token: the control APIs and brokers listen on every address, so every client
    # must send it (bus/wire/auth_token.hpp). A Docker secret made from the host's token file at
    # deploy time (in swarm's encrypted store, never in an image layer or on a command line),
    # named by content like the configs (secrets are immutable too).
    with open(args.token_file, "rb") as f:
        token_digest = hashlib.sha256(f.read()).hexdigest()[:10]
    secrets = {"canfleet_token": {"name": f"{args.stack}_token-{token_digest}",
                                  "file": os.path.abspath(args.token_file)}}
    token_mount = [{"source": "canfleet_token", "target": "canfleet_token", "mode": 0o444}]
    common_env = {
        "CANFLEET_DDS_DOMAIN": str(args.domain),
        "CANFLEET_DDS_CONFIG": "/etc/canfleet/cyclonedds-swarm.xml",
        "CANFLEET_TOKEN_FILE": "/run/secrets/canfleet_token",
    }
    dds_mount = {"source": "dds", "target": "/etc/canfleet/cyclonedds-swarm.xml"}
    services = {}
    for s in shards:
        bus = s["bus"]
        topo = f"topology-{bus}"
        configs[topo] = {"name": f"{args.stack}_{topo}-{digest(bus + '.textproto')}", "file": f"./{bus}.textproto"}
        labels = {"canfleet.bus": bus, "canfleet.shard-index": str(s["index"])}
        placement = {"constraints": s["constraint"]} if s["constraint"] else None
        orchestrator = {
            "image": args.image,
            "hostname": f"{bus}-orchestrator",
            "command": ["canfleet", "up", f"/etc/canfleet/swarm/{bus}.textproto",
                        "--listen", f"tcp://0.0.0.0:{CONTAINER_BROKER}",
                        "--control", f"tcp://0.0.0.0:{CONTAINER_CONTROL}",
                        "--socketcand-bind", "0.0.0.0",
                        "--ready-file", "/tmp/canfleet-ready",
                        "--log-level", args.log_level],
            "environment": dict(common_env),
            "configs": [dict(dds_mount), {"source": topo, "target": f"/etc/canfleet/swarm/{bus}.textproto"}],
            "secrets": list(token_mount),
            "networks": ["fleet"],
            # Host mode: the ingress routing mesh needs IPVS (absent on some kernels, this project's VM
            # included); these listen on every interface of the orchestrator's host. The control API and
            # the broker let in only clients with the fleet's token; socketcand has no authentication
            # in its protocol: firewall it.
            "ports": [
                {"target": CONTAINER_CONTROL, "published": s["ports"]["control"], "protocol": "tcp", "mode": "host"},
                {"target": CONTAINER_BROKER, "published": s["ports"]["broker"], "protocol": "tcp", "mode": "host"},
                {"target": CONTAINER_SOCKETCAND, "published": s["ports"]["socketcand"], "protocol": "tcp", "mode": "host"},
            ],
            "healthcheck": {"test": ["CMD", "test", "-s", "/tmp/canfleet-ready"], "interval": "2s",
                            "timeout": "2s", "retries": 30},
            "stop_grace_period": "20s",
            "deploy": {
                "replicas": 1,
                # The name resolves to the task's address, not to a virtual IP (which needs IPVS).
                "endpoint_mode": "dnsrr",
                "restart_policy": {"condition": "any", "delay": "2s"},
                "labels": dict(labels, **{
                    "canfleet.role": "orchestrator",
                    "canfleet.control-port": str(s["ports"]["control"]),
                    "canfleet.broker-port": str(s["ports"]["broker"]),
                    "canfleet.socketcand-port": str(s["ports"]["socketcand"]),
                }),
            },
        }
        if placement:
            orchestrator["deploy"]["placement"] = placement
        services[f"{bus}-orchestrator"] = orchestrator

        node_args = ["--bus", f"{bus}@tcp://{bus}-orchestrator:{CONTAINER_BROKER}", "--state-dir", "/var/lib/canfleet"]
        what = ["--device", s["device"]] if s["device"] else ["--eds", s["eds"]]
        slot_io = [a for io in s["io"] for a in ("--io", io)]
        # The task slot is the node-ID (swarm templates only env, hostname and mounts, so a shell
        # puts it on the command line). exec: canfleet-node is PID 1 and gets docker's SIGTERM.
        script = (
            'slot="$${CANFLEET_SLOT:?}"; '
            'if [ "$$slot" -gt "$${CANFLEET_MAX_SLOT:?}" ]; then '
            f'echo "canfleet: task slot $$slot is above {bus}\'s max=$$CANFLEET_MAX_SLOT (the node-IDs its topology names);'
            f' scale {args.stack}_{bus}-nodes to at most $$CANFLEET_MAX_SLOT or deploy with a higher max=" >&2; exit 2; fi; '
            f'exec canfleet-node --name "{bus}-node-$$slot" --node-id "$$slot" '
            + " ".join(shlex.quote(a).replace("$", "$$") for a in what + node_args + slot_io)
        )
        services[f"{bus}-nodes"] = {
            "image": args.image,
            "hostname": f"{bus}-node-{{{{.Task.Slot}}}}",
            "command": ["sh", "-c", script],
            "environment": dict(common_env, CANFLEET_SLOT="{{.Task.Slot}}", CANFLEET_MAX_SLOT=str(s["max"])),
            "configs": [dict(dds_mount)],
            "secrets": list(token_mount),
            "networks": ["fleet"],
            "stop_grace_period": "5s",
            "deploy": {
                "replicas": s["nodes"],
                "endpoint_mode": "dnsrr",
                # A node whose task ends (killed, crashed, its host gone) is replaced; the new task has
                # the same slot, so the same node-ID and name, and its orchestrator configures it again.
                "restart_policy": {"condition": "any", "delay": "2s"},
                "update_config": {"parallelism": 0},
                "labels": dict(labels, **{"canfleet.role": "nodes", "canfleet.max-slot": str(s["max"])}),
            },
        }
        if placement:
            services[f"{bus}-nodes"]["deploy"]["placement"] = placement
        for n in s["singles"]:
            what = ["--device", n["device"]] if n["device"] else ["--eds", n["eds"]]
            command = ["canfleet-node", "--name", n["node_name"], "--node-id", str(n["node_id"])] + what + node_args
            if n["serial"]:
                command += ["--serial", str(n["serial"])]
            for io in n["io"]:
                command += ["--io", io]
            service = {
                "image": args.image,
                "hostname": n["node_name"],
                "command": [a.replace("$", "$$") for a in command],
                "environment": dict(common_env),
                "configs": [dict(dds_mount)],
                "secrets": list(token_mount),
                "networks": ["fleet"],
                "stop_grace_period": "5s",
                "deploy": {
                    "replicas": 1,
                    "endpoint_mode": "dnsrr",
                    "restart_policy": {"condition": "any", "delay": "2s"},
                    "labels": dict(labels, **{"canfleet.role": "node", "canfleet.node-id": str(n["node_id"])}),
                },
            }
            if placement:
                service["deploy"]["placement"] = placement
            services[n["node_name"]] = service

    stack = {
        "version": "3.8",
        "services": services,
        # Created by scripts/docker-swarm.sh before the deploy (a stack file cannot give an overlay
        # network the --ip-range that keeps the monitor slots free) and removed after `stack rm`.
        "networks": {"fleet": {"external": True, "name": args.network}},
        "configs": configs,
        "secrets": secrets,
    }
    header = (
        f"# Rendered by docker/swarm/render.py from {args.shards} for stack {args.stack}: do not edit.\n"
        "# scripts/docker-swarm.sh up creates the network and deploys this; see docker/README.md.\n"
    )
    files["stack.yaml"] = header + to_yaml(stack) + "\n"
    files["shards.json"] = json.dumps({
        "stack": args.stack, "network": args.network, "subnet": str(subnet),
        "ip_range": str(list(subnet.subnets(prefixlen_diff=1))[0]), "monitor_slots": slots,
        "domain": args.domain, "image": args.image,
        "shards": [{k: s[k] for k in ("bus", "bitrate", "nodes", "max", "device", "eds", "ports")}
                   | {"singles": [n["node_name"] for n in s["singles"]]} for s in shards],
    }, indent=2) + "\n"
    for name, text in files.items():
        with open(os.path.join(args.out, name), "w", encoding="utf-8") as f:
            f.write(text)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("shards", help="the shard file (topologies/swarm.shards)")
    p.add_argument("--out", required=True, help="folder for the rendered files")
    p.add_argument("--stack", default="canfleet")
    p.add_argument("--network", help="overlay network name (default STACK_fleet)")
    p.add_argument("--subnet", default="10.213.0.0/16")
    p.add_argument("--monitors", type=int, default=4, help="monitor slots (fixed addresses at the top of the subnet)")
    p.add_argument("--domain", type=int, default=0, help="DDS domain id")
    p.add_argument("--image", default="canfleet:dev")
    p.add_argument("--log-level", default="info")
    p.add_argument("--token-file", required=True, help="the fleet's token (made by scripts/docker-swarm.sh)")
    p.add_argument("--broker-base", type=int, default=29600, help="host port of the first bus's broker")
    p.add_argument("--control-base", type=int, default=29700, help="host port of the first bus's control API")
    p.add_argument("--socketcand-base", type=int, default=29800, help="host port of the first bus's socketcand")
    args = p.parse_args()
    args.network = args.network or f"{args.stack}_fleet"
    if not 1 <= args.monitors <= 16:
        p.error("--monitors: 1..16")
    try:
        render(args)
    except (ShardError, OSError, ValueError) as e:
        print(f"render: {e}", file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    main()
