"""MAVSDK (a second ground-station library, its own C++ MAVLink) against the real vehicle.

``fdm-awe fly --mavlink`` flies the stored reference as a subprocess paced at real time; MAVSDK's
native binding (the ``mavsdk`` package of the dev extras, asyncio API) listens on UDP 127.0.0.1 and
reads and commands it as it would ArduPilot: the flight mode, ``in_air``, a whole-number parameter,
the mission round trip, and the actions hold, start/pause mission and return to launch. Each
MAVSDK call is bounded by a timeout; the flight is stopped with Ctrl-C (SIGINT) at the end.
"""

from __future__ import annotations

import asyncio
import importlib.util
import signal
import subprocess
import time

import pytest

from mavlink_helpers import free_udp_port, launch_fly, stop_process

START_S = 60.0  # the flight's start (imports, JSBSim, the kernels' compilation) at most


def _mavsdk_usable() -> str | None:
    """Why MAVSDK cannot run here (None: it can): the package or its native library."""
    if importlib.util.find_spec("mavsdk") is None:
        return "mavsdk not installed (pip install 'fdm-awe[dev]')"
    try:
        from mavsdk.asyncio import Mavsdk  # noqa: F401 - loads the native library
    except Exception as e:  # noqa: BLE001 - the reason of the skip
        return f"mavsdk's native library cannot run here: {type(e).__name__}: {e}"
    return None


pytestmark = pytest.mark.skipif(_mavsdk_usable() is not None, reason=str(_mavsdk_usable()))



async def _first(agen, pred, timeout: float):
    """The first value of the async generator ``agen`` for which ``pred`` holds, within ``timeout`` s."""
    async def run():
        async for v in agen:
            if pred(v):
                return v
    try:
        return await asyncio.wait_for(run(), timeout)
    finally:
        await agen.aclose()


async def _ground_station(port: int, fly: subprocess.Popen) -> dict:
    from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
    from mavsdk.asyncio.plugins.action import ActionAsync
    from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
    from mavsdk.asyncio.plugins.param import ParamAsync
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
    from mavsdk.plugins.telemetry import FlightMode

    seen: dict = {}
    async with Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION)) as sdk:
        t0 = time.monotonic()
        await sdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        system = await sdk.first_autopilot(timeout_s=START_S)
        assert system is not None, "no autopilot seen"
        seen["autopilot_s"] = time.monotonic() - t0
        tel, act = TelemetryAsync(system), ActionAsync(system)
        mission, param = MissionRawAsync(system), ParamAsync(system)
        texts: list[str] = []

        async def collect():
            async for st in tel.subscribe_status_text():
                texts.append(st.text)
        collector = asyncio.ensure_future(collect())

        async def mode_is(mode, timeout: float = 10.0):
            return await _first(tel.subscribe_flight_mode(), lambda m: m == mode, timeout)

        # the vehicle flies its cycle in AUTO: MAVSDK's MISSION
        seen["auto"] = await mode_is(FlightMode.MISSION, START_S)
        seen["flying_s"] = time.monotonic() - t0
        seen["in_air"] = await _first(tel.subscribe_in_air(), lambda v: True, 10.0)
        seen["armable"] = (await _first(tel.subscribe_health(), lambda h: True, 10.0)).is_armable
        seen["battery"] = await _first(tel.subscribe_battery(), lambda b: b.voltage_v == b.voltage_v, 10.0)
        seen["rec_land"] = await asyncio.wait_for(param.get_param_int("REC_LAND"), 15.0)
        # the mission round trip: download, then upload what came down
        items = await asyncio.wait_for(mission.download_mission(), 30.0)
        seen["items"] = len(items)
        seen["current"] = [it.seq for it in items if it.current]
        await asyncio.wait_for(mission.upload_mission(items), 30.0)
        # the actions, each read back as the mode the vehicle flies
        await asyncio.wait_for(act.hold(), 10.0)
        seen["hold"] = await mode_is(FlightMode.HOLD)
        await asyncio.wait_for(mission.start_mission(), 10.0)
        seen["start"] = await mode_is(FlightMode.MISSION)
        await asyncio.wait_for(mission.pause_mission(), 10.0)
        seen["pause"] = await mode_is(FlightMode.HOLD)
        await asyncio.wait_for(act.return_to_launch(), 10.0)
        seen["rtl"] = await mode_is(FlightMode.RETURN_TO_LAUNCH)
        # a refused write: the reason arrives once (MAVSDK retries, then reports a failure)
        t1 = time.monotonic()
        try:
            await asyncio.wait_for(param.set_param_int("REC_LAND", 5), 20.0)
            seen["refused_write"] = "accepted"
        except Exception as e:  # noqa: BLE001 - the failure MAVSDK reports
            seen["refused_write"] = type(e).__name__ + ": " + str(e)
        seen["refused_write_s"] = time.monotonic() - t1
        await asyncio.sleep(1.0)
        collector.cancel()
        seen["texts"] = list(texts)
    return seen


def test_mavsdk_reads_and_commands_the_real_vehicle(tmp_path):
    port = free_udp_port()
    fly = launch_fly(port, "--cycles", "2", "--realtime", "1", "--params", str(tmp_path / "params.json"))
    try:
        seen = asyncio.run(asyncio.wait_for(_ground_station(port, fly), 150.0))
    finally:
        stop_process(fly, signal.SIGINT)
        stop_process(fly, signal.SIGKILL, 5.0)
    print(fly.stdout.read())
    print({k: v for k, v in seen.items() if k not in ("texts", "battery")})
    print(seen["texts"])
    assert seen["autopilot_s"] < 5.0          # the heartbeat while the flight loads
    assert seen["in_air"] is True
    assert seen["armable"] is True            # the pre-arm bit of SYS_STATUS
    bat = seen["battery"]
    assert 5.0 < bat.voltage_v < 60.0 and bat.voltage_v != 12.6   # the motor's supply, from its engine file
    assert bat.current_battery_a >= 0.0
    assert seen["rec_land"] in (0, 1)         # an INT32 parameter (REC_LAND, on/off)
    assert seen["items"] == 60 and len(seen["current"]) == 1
    assert "mission is the vehicle's own path: cycle kept" in seen["texts"]
    for step, text in (("hold", "mode AUTO -> LOITER"), ("start", "mode LOITER -> AUTO"),
                       ("pause", "mode AUTO -> LOITER"), ("rtl", "mode LOITER -> RECOVER")):
        assert seen[step] is not None, step
        assert text in seen["texts"], text
    assert seen["refused_write"] != "accepted"
    assert sum("REC_LAND" in t for t in seen["texts"]) == 1, seen["texts"]
