"""PDOs through python-canopen's PDO API (CiA 301 §7.2.2): the TPDO configuration read by SDO
(1800h-1803h, 1A00h-1A03h) equals the EDS's, the TPDOs python-canopen receives decode to the
values SDO reads, and an RPDO python-canopen sends changes the objects it maps."""
from __future__ import annotations

from harness import observe_absence, wait_until
from test_nmt import wait_heartbeat_state

PDO_NOT_VALID = 1 << 31


def eds_pdo(od, com_index, map_index):
    """(cob_id, valid, transmission type, event timer or None, [(index, sub, bits)]) from the EDS."""
    com, mp = od[com_index], od[map_index]
    cob = com[1].default
    timer = com[5].default if 5 in com.subindices else None
    entries = []
    for sub in range(1, (mp[0].default or 0) + 1):
        value = mp[sub].default
        # An entry of 0 maps nothing (0 bits), as python-canopen's PdoMap.read() reads it: the power
        # supply's manual counts such entries in sub 0 ("4: 60110120h, 60120120h, 0, 0", UMAX080311
        # §2.2.15, its README-dictionary choice 5).
        if value:
            entries.append((value >> 16, (value >> 8) & 0xFF, value & 0xFF))
    return cob & 0x1FFFFFFF, not cob & PDO_NOT_VALID, com[2].default, timer, entries


def test_tpdo_configuration_reads_as_the_eds_says(node, variant):
    """§7.5.2.35/§7.5.2.37: python-canopen's TPDO read() (SDO uploads of 18xxh/1Axxh) gives the COB-ID
    (§7.2.2.2: 180h/280h/380h/480h + node-ID by default), validity, transmission type, event timer
    and mapping of the EDS."""
    remote = node.remote
    remote.tpdo.read()
    assert len(remote.tpdo) > 0
    for n, pdo in remote.tpdo.items():
        cob, valid, ttype, timer, entries = eds_pdo(remote.object_dictionary, 0x1800 + n - 1, 0x1A00 + n - 1)
        assert pdo.cob_id == cob, f"TPDO{n} COB-ID"
        assert pdo.enabled == valid, f"TPDO{n} valid bit"
        assert pdo.trans_type == ttype, f"TPDO{n} transmission type"
        if timer is not None and ttype >= 254:
            assert pdo.event_timer == timer, f"TPDO{n} event timer"
        assert [(v.index, v.subindex, v.length) for v in pdo.map] == entries, f"TPDO{n} mapping"


def test_tpdos_decode_after_nmt_start(node, variant, fleet):
    """§7.3.2.2.2: no PDO before operational; after NMT start every valid TPDO with an event timer
    (§7.2.2.3.2 transmission types FEh/FFh) arrives and python-canopen's decoded variables equal
    what SDO reads from the same objects, and the inputs the variant sets."""
    remote = node.remote
    for signal, value in variant.pdo_io:
        fleet.io_set(variant.name, signal, value)
    remote.tpdo.read()
    periodic = {n: p for n, p in remote.tpdo.items() if p.enabled and p.event_timer}
    assert periodic, "no valid TPDO with an event timer"
    cob_ids = {p.cob_id for p in periodic.values()}
    # Pre-operational: none of them on the bus.
    mark = node.frames.mark()
    longest = max(p.event_timer for p in periodic.values()) / 1000.0
    early = observe_absence(lambda: [m for m in node.frames.since(mark) if m.arbitration_id in cob_ids],
                            max(1.0, 2 * longest),
                            "two event-timer periods of the slowest of these TPDOs (at least 1 s): "
                            "each would have been sent at least once")
    assert early == []

    received = {}
    for n, pdo in periodic.items():
        pdo.add_callback(lambda p, n=n: received.setdefault(n, bytes(p.data)))
    remote.nmt.state = "OPERATIONAL"
    got = wait_until(lambda: len(received) == len(periodic) and received)
    missing = sorted(set(periodic) - set(received))
    assert got, f"TPDOs {missing} not received after NMT start"
    remote.nmt.state = "PRE-OPERATIONAL"  # values stay put while SDO reads them
    seen = {}
    for n, pdo in periodic.items():
        data = received[n]
        assert len(data) * 8 >= sum(v.length for v in pdo.map), f"TPDO{n} shorter than its mapping"
        pdo.data = data
        for var in pdo.map:
            decoded = var.raw
            seen[(var.index, var.subindex)] = decoded
            by_sdo = var.od.decode_raw(remote.sdo.upload(var.index, var.subindex))
            assert decoded == by_sdo, f"TPDO{n} {var.index:04X}h.{var.subindex}: PDO {decoded}, SDO {by_sdo}"
    for key, value in variant.tpdo_expected.items():
        assert seen.get(key) == value, f"{key[0]:04X}h.{key[1]} in a TPDO: {seen.get(key)}, want {value}"


def test_rpdo_changes_the_mapped_objects(node, variant, fleet):
    """§7.2.2: an RPDO received in operational writes its mapped objects (python-canopen's RPDO
    read() gives the mapping from 16xxh, transmit() sends the frame on the COB-ID of 14xxh)."""
    remote = node.remote
    remote.rpdo.read()
    rpdo = remote.rpdo[1]
    assert rpdo.enabled and rpdo.cob_id == 0x200 + node.node_id  # §7.2.2.2 default RPDO1
    keys = [(v.index, v.subindex) for v in rpdo.map]
    assert set(keys) == set(variant.rpdo_values), f"RPDO1 maps {keys}"
    for var in rpdo.map:
        var.raw = variant.rpdo_values[(var.index, var.subindex)]
    remote.sdo[0x1017].raw = 50
    remote.nmt.state = "OPERATIONAL"
    assert wait_heartbeat_state(node, "OPERATIONAL")
    rpdo.transmit()

    def applied():
        return all(remote.sdo[i][s].raw == v for (i, s), v in variant.rpdo_values.items())

    assert wait_until(applied, timeout=10), {k: remote.sdo[k[0]][k[1]].raw for k in variant.rpdo_values}
    for signal, value in variant.rpdo_outputs.items():
        assert wait_until(lambda: fleet.io_get(variant.name, signal) == value), \
            f"{signal} = {fleet.io_get(variant.name, signal)}, want {value}"
