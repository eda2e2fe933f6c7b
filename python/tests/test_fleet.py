"""Fleet control through the control API (canfleet.Fleet): status, SDO, simulated I/O, NMT,
faults, captures, refusals and start-up errors, against real fleets."""
from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

import canfleet
from canfleet import Fleet
from helpers import BROKEN, HERE, PAIR, alive, children_of, fleet_pids, wait_until

pytestmark = pytest.mark.topology("topologies/pair.textproto")


def nmt_state(fleet: Fleet, node: str) -> str:
    return fleet.node(node).status().nmt_state


def test_a_started_fleet_is_ready_with_every_node_running(fleet: Fleet) -> None:
    status = fleet.status()
    assert status.topology == "python-pair"
    assert [b.name for b in status.buses] == ["can0"]
    assert sorted(n.name for n in status.nodes) == ["io-21", "quad-5", "quad-6"]
    for node in status.nodes:
        assert node.process == "running" and node.pid > 0 and node.booted, node
    assert fleet.state_dir is not None and fleet.log_path is not None and fleet.log_path.is_file()
    assert fleet.control.startswith("tcp://127.0.0.1:") and fleet.broker is not None
    assert fleet.broker.startswith("unix://" + str(fleet.state_dir))  # private endpoints


def test_sdo_write_read_back_and_abort_code(fleet: Fleet) -> None:
    quad5 = fleet.node("quad-5")
    quad5.sdo_write(0x1017, 0, 250, "u16")  # CiA 301 §7.5.2.30 producer heartbeat time
    assert quad5.sdo_read(0x1017, 0, "u16") == 250
    assert quad5.sdo_read(0x1017, 0) == (250).to_bytes(2, "little")
    with pytest.raises(canfleet.SdoAbortError) as e:
        quad5.sdo_read(0x5FFF, 0, "u32")
    assert e.value.code == 0x06020000  # CiA 301 §7.2.4.3.17: object does not exist
    assert "06020000" in str(e.value)


def test_sdo_ports_are_numbered_as_the_manuals_print_them(fleet: Fleet) -> None:
    quad5 = fleet.node("quad-5")
    assert quad5.sdo_read(0x1017, 0, "u16", can=1) == quad5.sdo_read(0x1017, 0, "u16")  # CAN1 by default
    with pytest.raises(canfleet.OrchestratorError, match="no CAN2"):  # a Quad has one port (manual §1)
        quad5.sdo_read(0x1017, 0, "u16", can=2)
    for wrong in (0, 3):
        with pytest.raises(ValueError, match="CAN1.*CAN2"):
            quad5.sdo_write(0x1017, 0, 100, "u16", can=wrong)


def test_io_set_on_one_node_moves_the_output_of_its_pdo_consumer(fleet: Fleet) -> None:
    # quad-5 TPDO1 (185h, AIN1 in mV) -> quad-6 RPDO1 -> POUT1 in mA (Quad manual §3.1.1, §3.5.1).
    assert fleet.node("quad-5").io_set("IN1.voltage_mV", 1800).value == "1800"
    pout = wait_until(lambda: fleet.node("quad-6").io_get("OUT1.current_mA").value == "1800")
    assert pout, fleet.node("quad-6").io_get("OUT1.current_mA")
    assert fleet.node("quad-6").io_get("OUT1.current_mA").unit == "mA"
    assert "IN1.voltage_mV" in fleet.node("quad-5").io_all()


def test_nmt_stop_and_start_are_seen_in_the_heartbeat(fleet: Fleet) -> None:
    assert wait_until(lambda: nmt_state(fleet, "quad-5") == "operational")
    fleet.node("quad-5").nmt("stop")  # CiA 301 §7.2.8.3.1
    assert wait_until(lambda: nmt_state(fleet, "quad-5") == "stopped"), nmt_state(fleet, "quad-5")
    fleet.nmt("start")  # every node
    assert wait_until(lambda: nmt_state(fleet, "quad-5") == "operational")
    with pytest.raises(ValueError):
        fleet.nmt("explode")


def test_an_injected_heartbeat_loss_makes_the_consumer_send_emcy_8130_and_clears(fleet: Fleet) -> None:
    # A consumer monitors from the first heartbeat it receives (CiA 301 §7.2.8.3.2.2): the one the
    # orchestrator sees (quad-5 operational) reached quad-6 as well.
    assert wait_until(lambda: nmt_state(fleet, "quad-5") == "operational")
    with fleet.inject("heartbeat-loss", node="quad-5", label="silent") as fault:
        assert "heartbeat-loss of quad-5" in fault.summary
        assert [f.fault_id for f in fleet.status().faults] == [fault.id]
        # Quad manual §4.1: EMCY 8130h, 1001h bit 0, from the consumer quad-6 (1016h 500 ms).
        emcy = wait_until(lambda: fleet.node("quad-6").status().last_emcy.code == 0x8130)
        assert emcy, fleet.node("quad-6").status()
    assert fault.status().state == "cleared"
    assert not fleet.status().faults
    with pytest.raises(canfleet.OrchestratorError):
        fault.clear()  # no longer active


def test_a_capture_records_the_bus(fleet: Fleet) -> None:
    capture = fleet.capture("can0", format="candump")
    assert capture.path.parent == fleet.state_dir / "captures"
    assert wait_until(lambda: capture.path.exists() and " can0 705#05" in capture.path.read_text())
    capture.stop()
    assert capture.stopped
    assert fleet.capture("can0").path.suffix == ".pcap"


def test_a_capture_outside_the_fleets_folders_is_refused(fleet: Fleet, tmp_path: Path) -> None:
    # Issue 32: anyone who may use the control API could otherwise have the orchestrator write (or
    # truncate) any file its user can.
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me")
    with pytest.raises(canfleet.OrchestratorError, match="writes captures only inside"):
        fleet.capture("can0", victim)
    with pytest.raises(canfleet.OrchestratorError, match="writes captures only inside"):
        fleet.capture("can0", "../../../elsewhere.log")
    assert victim.read_text() == "keep me"
    existing = fleet.capture("can0", "once.log", format="candump")
    existing.stop()
    with pytest.raises(canfleet.OrchestratorError, match="exists: a capture never replaces a file"):
        fleet.capture("can0", "once.log", format="candump")


def test_refusals_carry_the_orchestrators_message(fleet: Fleet) -> None:
    with pytest.raises(canfleet.OrchestratorError, match="no node called 'nobody'"):
        fleet.inject("bus-off", node="nobody")
    with pytest.raises(canfleet.OrchestratorError, match="cob"):
        fleet.inject("rpdo-timeout", node="quad-6")  # needs --cob-id (orchestrator/control/fault_kinds.cpp)
    with pytest.raises(canfleet.OrchestratorError):
        fleet.node("nobody").io_get("IN1.voltage_mV")


def test_bad_fault_arguments_raise_before_anything_is_sent(fleet: Fleet) -> None:
    with pytest.raises(ValueError, match="unknown fault kind 'meltdown'"):
        fleet.inject("meltdown", node="quad-5")
    with pytest.raises(TypeError, match="'colour'"):
        fleet.inject("drop", node="quad-5", colour="red")
    with pytest.raises(ValueError, match="SDO type"):
        fleet.node("quad-5").sdo_read(0x1017, 0, "u17")
    assert not fleet.faults(include_ended=True)


def test_attach_reaches_a_running_fleet_and_closing_it_stops_nothing(fleet: Fleet) -> None:
    with Fleet.attach(fleet.control, broker=fleet.broker) as attached:
        assert not attached.owned
        assert sorted(attached.nodes) == sorted(fleet.nodes)
        attached.node("quad-5").sdo_write(0x1017, 0, 300, "u16")
    assert fleet.node("quad-5").sdo_read(0x1017, 0, "u16") == 300
    assert fleet.returncode is None
    with pytest.raises(canfleet.NotReachableError):
        Fleet.attach("tcp://127.0.0.1:1")


def test_a_node_killed_behind_the_fleets_back_is_reported_with_its_exit_status(fleet: Fleet) -> None:
    assert fleet.dead_nodes() == []
    pid = fleet.node("io-21").status().pid
    os.kill(pid, signal.SIGKILL)
    dead = wait_until(fleet.dead_nodes)
    assert dead and dead[0].node == "io-21"
    assert "signal 9" in dead[0].detail, dead[0].detail
    with pytest.raises(canfleet.NodeDiedError, match="io-21"):
        fleet.check_nodes()
    fleet.expect_exit("io-21")  # on purpose: the plugin must not fail this test for it
    assert fleet.dead_nodes() == []


def test_a_process_fault_injected_by_the_test_is_not_a_death(fleet: Fleet) -> None:
    before = fleet.node("io-21").status().pid
    fleet.inject("restart", node="io-21")
    assert wait_until(lambda: fleet.node("io-21").status().process == "running" and
                      fleet.node("io-21").status().pid not in (0, before))
    assert fleet.dead_nodes() == []


# -- without the fixture: start-up, arguments and ending ------------------------------------------

@pytest.mark.topology("topologies/pair.textproto")  # unused: these tests start their own fleets
def test_a_topology_error_raises_with_file_line_and_column_before_anything_starts() -> None:
    before = children_of(os.getpid())
    with pytest.raises(canfleet.TopologyError) as e:
        Fleet.up(BROKEN)
    assert e.value.file is not None and e.value.file.name == "broken.textproto"
    assert (e.value.line, e.value.column) == (5, 60)
    assert 'unknown bus "can9"' in e.value.reason
    assert children_of(os.getpid()) == before


def test_bad_arguments_raise_before_anything_starts(tmp_path: Path) -> None:
    before = children_of(os.getpid())
    with pytest.raises(ValueError, match="time="):
        Fleet.up(PAIR, time="sometimes")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="seed="):
        Fleet.up(PAIR, seed=-1)
    with pytest.raises(canfleet.TopologyError, match="no such topology file"):
        Fleet.up(tmp_path / "missing.textproto")
    assert children_of(os.getpid()) == before
    assert not list(tmp_path.iterdir())


def test_a_fleet_that_is_not_ready_in_time_raises_with_the_logs_tail(tmp_path: Path) -> None:
    # Its external node never attaches (a 1 ms timeout on the pair raced a quick start: the fleet was
    # sometimes ready before the first look, and the test leaked it).
    with pytest.raises(canfleet.FleetStartError) as e:
        Fleet.up(HERE / "topologies" / "never-ready.textproto", state_dir=tmp_path / "state", ready_timeout=1)
    assert "not ready within" in str(e.value)
    assert e.value.log == tmp_path / "state" / "orchestrator.log"
    assert "control API on" in str(e.value) or "canfleet" in str(e.value)
    assert not children_of(os.getpid())


def test_a_fleet_whose_node_cannot_start_raises_naming_it(tmp_path: Path) -> None:
    # quad-6's log file (<state>/nodes/logs/quad-6.log) cannot be opened: a folder is in its place,
    # so the orchestrator cannot start that node process (orchestrator/fleet/child_process.cpp).
    (tmp_path / "state" / "nodes" / "logs" / "quad-6.log").mkdir(parents=True)
    with pytest.raises(canfleet.FleetStartError) as e:
        Fleet.up(PAIR, state_dir=tmp_path / "state", ready_timeout=60)
    assert "node quad-6 exited before the fleet was ready (could not start: cannot open" in str(e.value)
    assert "orchestrator.log" in str(e.value) and "quad-6: could not start" in str(e.value)  # the log's tail
    assert not children_of(os.getpid())


def test_close_stops_the_orchestrator_and_every_node(tmp_path: Path) -> None:
    with Fleet.up(PAIR, seed=7) as fleet:
        pids = fleet_pids(fleet)
        assert len(pids) == 4 and all(alive(p) for p in pids)
        state = fleet.state_dir
        assert state is not None
    assert fleet.closed and fleet.returncode == 0
    assert wait_until(lambda: not any(alive(p) for p in pids)), [p for p in pids if alive(p)]
    assert not state.exists()  # a temporary state folder goes with the fleet
