"""SDO access against the variant's EDS, with python-canopen's RemoteNode as the client.

CiA 301 §7.2.4 (SDO), §7.2.4.3.17 table 22 (abort codes); CiA 306 §4.6.3 (object descriptions,
DefaultValue, AccessType). The node runs with its measured inputs at the values that make every
object read its EDS default (variants.Variant.default_io) and is never configured beforehand.
"""
from __future__ import annotations

import pytest
from canopen.sdo import SdoAbortedError

import eds_view as ev

ABORT_WRITE_ONLY = 0x06010001      # attempt to read a write-only object
ABORT_READ_ONLY = 0x06010002       # attempt to write a read-only object
ABORT_NO_OBJECT = 0x06020000       # object does not exist in the object dictionary
ABORT_NO_SUB = 0x06090011          # sub-index does not exist
ABORT_NO_DATA = 0x08000024         # no data available


def upload_raw(remote, index, sub):
    """(indicated size or None, bytes) as the server sent them: python-canopen's upload() cuts
    the data to the EDS size, which would hide a server sending too many bytes."""
    with remote.sdo.open(index, sub, buffering=0) as fp:
        size = fp.size
        data = fp.read()
    return size, bytes(data)


def test_every_readable_object_reads_its_eds_default(node, variant):
    """CiA 306 §4.6.3.2: a device fresh from power-on holds each DefaultValue; CiA 301 §7.2.4.3:
    an upload returns the object's value with its size (expedited, or segmented for more than
    4 bytes). Write-only objects abort 06010001h; empty 1003h entries abort 08000024h."""
    remote = node.remote
    all_vars = list(ev.variables(remote.object_dictionary))
    # Not vacuous: python-canopen saw every sub-object the file describes.
    assert len(all_vars) == ev.count_sections(variant.eds), "python-canopen dropped objects of the EDS"
    mismatches, compared = [], 0
    for var in all_vars:
        where = ev.label(var)
        if ev.is_write_only(var):
            with pytest.raises(SdoAbortedError) as err:
                upload_raw(remote, var.index, var.subindex)
            if err.value.code != ABORT_WRITE_ONLY:
                mismatches.append(f"{where}: write-only, read aborted {err.value.code:08X}h, want 06010001h")
            continue
        if variant.no_data(var.index, var.subindex):
            try:
                size, data = upload_raw(remote, var.index, var.subindex)
                mismatches.append(f"{where}: empty entry read {data.hex()} (want abort 08000024h)")
            except SdoAbortedError as e:
                if e.code != ABORT_NO_DATA:
                    mismatches.append(f"{where}: aborted {e.code:08X}h, want 08000024h")
            continue
        try:
            size, data = upload_raw(remote, var.index, var.subindex)
        except SdoAbortedError as e:
            mismatches.append(f"{where}: aborted {e.code:08X}h")
            continue
        want = ev.default_bytes(var)
        if variant.measured(var.index, var.subindex):
            # A measurement no input can hold at its default without a fault: only its size.
            if len(data) != len(want) or (size is not None and size != len(want)):
                mismatches.append(f"{where}: measured value of {len(data)} bytes (size {size}), want {len(want)}")
            continue
        compared += 1
        if data != want:
            mismatches.append(f"{where}: read {data.hex(' ') or '(empty)'}, EDS default "
                              f"{var.default_raw!r} = {want.hex(' ') or '(empty)'}")
        elif size is not None and size != len(want):
            mismatches.append(f"{where}: value right but indicated size {size}, want {len(want)}")
        else:
            # python-canopen's decoding of the same bytes (what Variable.raw returns) agrees too.
            value = var.decode_raw(data)
            if value != ev.normalised_default(var):
                mismatches.append(f"{where}: python-canopen decoded {value!r}, want {ev.normalised_default(var)!r}")
    assert compared > 0
    assert not mismatches, f"{len(mismatches)} of {len(all_vars)} sub-objects of {variant.eds.name} differ:\n" + \
        "\n".join(mismatches)


def test_writes_to_read_only_objects_abort_and_change_nothing(node, variant):
    """CiA 301 §7.2.4.3.17: a download to a read-only or constant object aborts 06010002h, and
    the object keeps its value (checked by reading it back)."""
    remote = node.remote
    wrong = []
    targets = [v for v in ev.variables(remote.object_dictionary) if ev.is_read_only(v)]
    assert targets, "the EDS has no read-only object"
    # A measured object keeps the value it had before the write (the input does not change).
    measured_before = {(v.index, v.subindex): upload_raw(remote, v.index, v.subindex)[1]
                       for v in targets if variant.measured(v.index, v.subindex)}
    for var in targets:
        size = ev.size_of(var)
        # A value of the right size that differs from the default.
        data = bytes([0x5A]) * (size or 5)
        try:
            remote.sdo.download(var.index, var.subindex, data)
            wrong.append(f"{ev.label(var)}: write accepted")
        except SdoAbortedError as e:
            if e.code != ABORT_READ_ONLY:
                wrong.append(f"{ev.label(var)}: aborted {e.code:08X}h, want 06010002h")
        if variant.no_data(var.index, var.subindex):
            continue
        before = ev.default_bytes(var)
        if variant.measured(var.index, var.subindex):
            before = measured_before[(var.index, var.subindex)]
        _, after = upload_raw(remote, var.index, var.subindex)
        if after != before:
            wrong.append(f"{ev.label(var)}: changed to {after.hex(' ')}")
    assert not wrong, f"{len(wrong)} of {len(targets)} read-only sub-objects:\n" + "\n".join(wrong)


def test_missing_objects_and_sub_indexes_abort(node, variant):
    """CiA 301 §7.2.4.3.17: 06020000h for an object the dictionary lacks, 06090011h for a missing
    sub-index of an existing object; both for reads and writes."""
    remote = node.remote
    od = remote.object_dictionary
    missing = next(i for i in range(0x2FFF, 0x2000, -1) if i not in od)
    record = next(od[i] for i in sorted(od.indices) if i >= 0x1000 and hasattr(od[i], "subindices"))
    missing_sub = max(record.subindices) + 1
    for index, sub, want in ((missing, 0, ABORT_NO_OBJECT), (record.index, missing_sub, ABORT_NO_SUB)):
        with pytest.raises(SdoAbortedError) as err:
            upload_raw(remote, index, sub)
        assert err.value.code == want, f"read {index:04X}h.{sub}: {err.value.code:08X}h, want {want:08X}h"
        with pytest.raises(SdoAbortedError) as err:
            remote.sdo.download(index, sub, b"\x00\x00\x00\x00")
        assert err.value.code == want, f"write {index:04X}h.{sub}: {err.value.code:08X}h, want {want:08X}h"


def test_writable_objects_keep_what_python_canopen_writes(node, variant):
    """CiA 301 §7.2.4.3.3/§7.2.4.3.5: an expedited download of a rw object is confirmed and the
    value read back; python-canopen's Variable.raw encodes from the EDS type. 1017h is mandatory
    when heartbeats are used (CiA 301 §7.5.2.30) and rw in every variant's EDS."""
    remote = node.remote
    remote.sdo[0x1017].raw = 1234
    assert remote.sdo[0x1017].raw == 1234
    assert upload_raw(remote, 0x1017, 0) == (2, (1234).to_bytes(2, "little"))
    remote.sdo[0x1017].raw = 0
