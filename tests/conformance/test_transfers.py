"""Segmented and block SDO transfers (CiA 301 §7.2.4.3.4-§7.2.4.3.16) with python-canopen's
client: every string/domain object of the variant's EDS both ways, and numeric objects through the
protocols a master may choose for them."""
from __future__ import annotations

import pytest

import eds_view as ev
from test_sdo import upload_raw


def block_upload(remote, index, sub) -> bytes:
    with remote.sdo.open(index, sub, mode="rb", block_transfer=True, buffering=0) as fp:
        return bytes(fp.read())


def block_download(remote, index, sub, data: bytes) -> None:
    with remote.sdo.open(index, sub, mode="wb", block_transfer=True, size=len(data)) as fp:
        fp.write(data)


def string_objects(remote):
    return [v for v in ev.variables(remote.object_dictionary) if v.data_type in ev.VARIABLE_LENGTH]


def payload(var, length: int) -> bytes:
    if var.data_type == ev.datatypes.VISIBLE_STRING:
        text = "canfleet conformance " * (length // 21 + 1)
        return text[:length].encode("ascii")
    return bytes((i * 37 + 11) & 0xFF for i in range(length))


def test_strings_and_domains_upload_segmented_and_by_block(node, variant):
    """§7.2.4.3.6/§7.2.4.3.8 segmented upload and §7.2.4.3.12-§7.2.4.3.16 block upload (with
    CRC, python-canopen asks for it) return the same bytes: the EDS default."""
    remote = node.remote
    objects = [v for v in string_objects(remote) if not ev.is_write_only(v)]
    if not objects:
        pytest.skip(f"{variant.eds.name} has no string or domain object")
    for var in objects:
        want = ev.default_bytes(var)
        size, data = upload_raw(remote, var.index, var.subindex)
        assert data == want, f"{ev.label(var)} segmented/expedited upload"
        if len(want) > 4:
            assert size == len(want), f"{ev.label(var)}: a segmented upload indicates the size"
        assert block_upload(remote, var.index, var.subindex) == want, f"{ev.label(var)} block upload"


@pytest.mark.parametrize("length", [1, 7, 8, 100, 1000])
def test_writable_strings_and_domains_round_trip(node, variant, length):
    """Downloads of 1 byte (expedited), 7/8 (one segment / two), 100 and 1000 bytes (a block
    transfer of 1000 bytes needs two blocks of at most 127 segments, §7.2.4.3.9) with both
    segmented (§7.2.4.3.4) and block download (§7.2.4.3.9-§7.2.4.3.11); each read back by
    segmented and by block upload."""
    remote = node.remote
    objects = [v for v in string_objects(remote) if v.writable and v.readable]
    if not objects:
        pytest.skip(f"{variant.eds.name} has no writable string or domain object")
    for var in objects:
        data = payload(var, length)
        remote.sdo.download(var.index, var.subindex, data, force_segment=length > 1)
        assert upload_raw(remote, var.index, var.subindex)[1] == data, f"{ev.label(var)} after segmented download"
        data = bytes(reversed(data))
        block_download(remote, var.index, var.subindex, data)
        assert block_upload(remote, var.index, var.subindex) == data, f"{ev.label(var)} after block download"
        assert upload_raw(remote, var.index, var.subindex)[1] == data


def test_numbers_through_segmented_and_block_protocols(node, variant):
    """A client may use any protocol for any size (§7.2.4.3.4: a segmented download of 2 bytes;
    §7.2.4.3.12: a block upload of a 4-byte object, python-canopen sets no protocol switch
    threshold). 1018h sub 1 (vendor-ID, ro) and 1017h (rw) exist in every CiA 301 device."""
    remote = node.remote
    vendor = remote.object_dictionary[0x1018][1]
    assert block_upload(remote, 0x1018, 1) == ev.default_bytes(vendor)
    remote.sdo.download(0x1017, 0, (500).to_bytes(2, "little"), force_segment=True)
    assert remote.sdo[0x1017].raw == 500
    block_download(remote, 0x1017, 0, (700).to_bytes(2, "little"))
    assert block_upload(remote, 0x1017, 0) == (700).to_bytes(2, "little")
    remote.sdo[0x1017].raw = 0
