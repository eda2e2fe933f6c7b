"""The fleet in a real browser (issue 31): Debian's chromium, headless, against a running fleet and
`canfleet web`. The page lists the nodes; a plot of a signal the test moves changes; a fault injected
from the page's own form shows its EMCY on the timeline and the node's error register in the
overview. Screenshots (PNG) are kept in $CANFLEET_WEB_SHOTS (default: the test's folder)."""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Dict, Generator, List

import pytest

from browser import Browser, find_chromium
from canfleet import Fleet
from conftest import PAIR, REPO, start_web, up_with_web


@pytest.fixture
def browser() -> Generator[Browser, None, None]:
    chromium = find_chromium()
    if chromium is None:
        pytest.skip("no chromium on this machine (apt-get install chromium; scripts/install-deps.sh does)")
    b = Browser(chromium, 1400, 1500)
    yield b
    b.close()


def shots(tmp_path: Path) -> Path:
    return Path(os.environ.get("CANFLEET_WEB_SHOTS", tmp_path))


def test_the_page_shows_the_fleet_plots_a_signal_and_injects_a_fault(
        fleet: Fleet, webs: List[Dict[str, object]], browser: Browser, tmp_path: Path) -> None:
    web = start_web("--listen", "127.0.0.1:0", "--broker", str(fleet.broker), control=fleet.control,
                    folder=tmp_path)
    webs.append(web)
    browser.open(str(web["url"]))
    # Overview: every node of the topology, by name, with its NMT state from its heartbeat.
    browser.wait_for("document.querySelectorAll('#overview tbody tr').length === 3")
    names = browser.js("[...document.querySelectorAll('#overview tbody tr')].map(r => r.dataset.name)")
    assert sorted(names) == ["io-21", "quad-5", "quad-6"]
    browser.wait_for("[...document.querySelectorAll('#overview td[data-field=nmt]')]"
                     ".every(td => td.textContent === 'operational')")
    browser.wait_for("document.querySelector('#buses .bus polyline') !== null")  # bus load over time
    # CANopen-Diag statistics from the bus (the monitor): quad-5's heartbeat period (100 ms,
    # pair.textproto) and the orchestrator's SDO answered by quad-5.
    browser.wait_for("(window.canfleet.diag['can0:5'] || {}).hb_min_ms > 0")
    diag = browser.js("window.canfleet.diag['can0:5']")
    # Real time: the figures are the bus's (tests/unit/web checks the arithmetic), not asserted here.
    assert 0 < diag["hb_min_ms"] <= diag["hb_max_ms"] and diag["heartbeats"] >= 2, diag
    assert fleet.node("quad-5").sdo_read(0x1017, 0, "u16") == 100
    browser.wait_for("(window.canfleet.diag['can0:5'] || {}).sdo_responses >= 1")
    browser.wait_for("document.querySelector('#overview tr[data-name=quad-5] td[data-field=sdo-time]')"
                     ".textContent.includes('ms')")

    # A plot of quad-5's IN1 (Quad manual §3.1.1), chosen with the page's own picker, follows it.
    series = "io:can0:5/IN1.voltage_mV"
    browser.wait_for(f"[...document.querySelectorAll('#series-pick option')].some(o => o.value === '{series}')")
    browser.js(f"document.getElementById('series-pick').value = '{series}'; "
               "document.getElementById('plot-add').click(); true")
    browser.wait_for(f"(window.canfleet.series['{series}'] || []).some(p => p[1] === 1200)")
    fleet.node("quad-5").io_set("IN1.voltage_mV", 2500)
    browser.wait_for(f"(window.canfleet.series['{series}'] || []).some(p => p[1] === 2500)")
    browser.wait_for(f"document.querySelector('#plot polyline[data-series=\"{series}\"]') !== null")
    # An object, polled by SDO from the page: quad-5's heartbeat time (1017h, CiA 301 §7.5.2.31).
    browser.js("document.getElementById('object-pick').value = 'quad-5 1017 0 u16';"
               "document.getElementById('object-add').click(); true")
    browser.wait_for("(window.canfleet.series['sdo:quad-5/1017h.0'] || []).some(p => p[1] === 100)")
    fleet.node("quad-5").sdo_write(0x1017, 0, 250, "u16")
    browser.wait_for("(window.canfleet.series['sdo:quad-5/1017h.0'] || []).some(p => p[1] === 250)")
    fleet.node("quad-5").sdo_write(0x1017, 0, 100, "u16")
    csv_rows = browser.js("window.canfleetActions.plotCsv()")
    assert csv_rows >= 2
    browser.screenshot(shots(tmp_path) / "web-plot.png")

    # A fault from the page's form: quad-6 stops hearing quad-5's heartbeat, reports EMCY 8130h
    # (Quad manual §4.1) and sets 1001h bit 0 (CiA 301 §7.5.2.2).
    browser.js("document.getElementById('fault-kind').value = 'HEARTBEAT_LOSS';"
               "document.getElementById('fault-node').value = 'quad-5';"
               "document.getElementById('fault-options').value = '{\"receivers\": [\"quad-6\"]}';"
               "document.getElementById('fault-inject').click(); true")
    browser.wait_for("window.canfleet.lastResult && window.canfleet.lastResult.ok")
    browser.wait_for("window.canfleet.events.some(e => e.type === 'fault' && e.kind === 'heartbeat-loss')")
    browser.wait_for("window.canfleet.events.some(e => e.type === 'emcy' && e.name === 'quad-6' && e.code === 33072)")
    browser.wait_for("document.querySelector('#timeline circle[data-type=emcy]') !== null")
    browser.wait_for("document.querySelector('#overview tr[data-name=quad-6] td[data-field=error-register]')"
                     ".textContent !== '00h'")
    browser.js("document.querySelector('#overview tr[data-name=quad-6]').click(); true")
    browser.wait_for("document.getElementById('detail').textContent.includes('8130h')")
    # Its 1003h (CiA 301 §7.5.2.5), read by SDO from the page: the Quad's entry for a lost
    # heartbeat of node 5 (Quad manual §4.1: (description 08h << 8 | channel 05h) << 16 | 8130h).
    browser.wait_for("document.querySelector('#detail [data-field=\"1003h\"]').textContent.includes('0x08058130')")
    browser.wait_for("document.querySelectorAll('#faults li').length === 1")
    # quad-6's controller state over time is a series too (plotted on demand): error-active, 0.
    browser.js("window.canfleetActions.addPlot('node:can0:6/controller'); true")
    browser.wait_for("(window.canfleet.series['node:can0:6/controller'] || []).some(p => p[1] === 0)")
    browser.screenshot(shots(tmp_path) / "web-fault.png")

    # A refusal comes back with the orchestrator's own message, as the CLI prints it.
    browser.js("document.getElementById('fault-kind').value = 'PARTITION';"
               "document.getElementById('fault-node').value = '';"
               "document.getElementById('fault-options').value = '';"
               "document.getElementById('fault-inject').click(); true")
    browser.wait_for("window.canfleet.lastResult && !window.canfleet.lastResult.ok")
    message = browser.js("document.getElementById('fault-result').textContent")
    assert message.startswith("partition needs at least 2 groups"), message  # as `canfleet fault inject` says
    # Clearing from the page ends it.
    browser.js("document.querySelector('#faults li button').click(); true")
    browser.wait_for("document.querySelectorAll('#faults li').length === 0")


def test_the_page_of_a_read_only_server_refuses_actions(
        fleet: Fleet, webs: List[Dict[str, object]], browser: Browser, tmp_path: Path) -> None:
    web = start_web("--listen", "127.0.0.1:0", "--read-only", control=fleet.control, folder=tmp_path)
    webs.append(web)
    browser.open(str(web["url"]))
    browser.wait_for("document.querySelectorAll('#overview tbody tr').length === 3")
    result = browser.js("window.canfleetActions.action({fault_clear: {}})")
    assert result == {"ok": False, "error": "read-only: actions are off (--read-only)"}
    assert json.loads(browser.js("fetch('/api/info').then(r => r.text())"))["read_only"] is True


def test_in_virtual_time_the_page_counts_simulated_seconds(browser: Browser, tmp_path: Path) -> None:
    # `canfleet up --time virtual --speed 4 --web`: a fleet in virtual time, paced for a person.
    with up_with_web(PAIR, tmp_path, "--time", "virtual", "--speed", "4") as url:
        browser.open(url)
        browser.wait_for("document.querySelectorAll('#overview tbody tr').length === 3")
        browser.wait_for("document.getElementById('clock').textContent.startsWith('virtual time')")
        browser.wait_for("window.canfleet.clockPairs.length >= 2")
        browser.wait_for("document.querySelector('#buses text[data-axis]').textContent.endsWith('s simulated')")
        browser.wait_for("[...document.querySelectorAll('#events li')].some(li => li.textContent.startsWith('t='))")
        browser.screenshot(shots(tmp_path) / "web-virtual.png")


def test_the_scenario_panel_shows_each_expectations_verdict(browser: Browser, tmp_path: Path) -> None:
    # The heartbeat-loss example's scenario in virtual time (as fast as it goes): its expectations'
    # verdicts, from the Verdict topic, one row each with what was seen.
    with up_with_web(REPO / "topologies" / "examples" / "heartbeat-loss.textproto", tmp_path,
                     "--time", "virtual") as url:
        browser.open(url)
        browser.wait_for("document.querySelector('#verdicts tr[data-verdict=steady][data-result=pass]') !== null")
        browser.wait_for("document.querySelector('#verdicts tr[data-verdict=emcy][data-result=pass]') !== null")
        text = browser.js("document.querySelector('#verdicts tr[data-verdict=emcy]').textContent")
        assert "8130h" in text, text
        browser.screenshot(shots(tmp_path) / "web-scenario.png")
