"""ROBOTIS dynamixel-sdk against the virtual MX-106 pair (IDs 1 and 2): the status errors of the
e-manual, then sync write, sync read and bulk read while the twin's motors move. Prints JSON.

Usage: python dynamixel_sdk_bus.py PTY
"""
import json
import sys
import time

from dynamixel_sdk import (
    COMM_RX_TIMEOUT,
    COMM_SUCCESS,
    GroupBulkRead,
    GroupSyncRead,
    GroupSyncWrite,
    PacketHandler,
    PortHandler,
)

port = PortHandler(sys.argv[1])
assert port.openPort(), "cannot open port"
assert port.setBaudRate(57600), "cannot set baud rate"
ph = PacketHandler(2.0)
out = {}


def retry(call, *args):
    """`call(*args)`, again if no status came: on a loaded machine the virtual bus can miss the
    SDK's 34 ms reply window now and then, as a real bus can drop a packet."""
    started = time.time()
    for attempt in range(5):
        result = call(*args)
        res = result if isinstance(result, int) else result[-2]
        if res != COMM_RX_TIMEOUT:
            return result
        print(f"retry {attempt + 1} of {getattr(call, '__name__', call)}{args[1:]}: {res} after {time.time() - started:.3f} s", file=sys.stderr)
    return result


def ok(res, err, what):
    if res != COMM_SUCCESS or err != 0:
        raise SystemExit(f"{what}: {ph.getTxRxResult(res)} {ph.getRxPacketError(err)}")


def error_of(res, err, what):
    """The status error number of a reply that must have come (communication succeeded)."""
    if res != COMM_SUCCESS:
        raise SystemExit(f"{what}: no status: {ph.getTxRxResult(res)}")
    return err & 0x7F


def s32(v):
    return v - (1 << 32) if v & 0x80000000 else v


def s16(v):
    return v - (1 << 16) if v & 0x8000 else v


# --- Status errors (torque off, factory defaults: position mode) ---
out["velocity_limit"], res, err = retry(ph.read4ByteTxRx, port, 1, 44)
ok(res, err, "read velocity limit")
out["goal_before_errors"], res, err = retry(ph.read4ByteTxRx, port, 1, 116)
ok(res, err, "read goal")
out["data_length"] = error_of(*retry(ph.write2ByteTxRx, port, 1, 116, 512), "2-byte goal")
out["range_goal"] = error_of(*retry(ph.write4ByteTxRx, port, 1, 116, 5000), "goal 5000")
out["range_mode"] = error_of(*retry(ph.write1ByteTxRx, port, 1, 11, 9), "mode 9")
out["access_read_only"] = error_of(*retry(ph.write4ByteTxRx, port, 1, 132, 0), "write present position")
out["access_undefined"] = error_of(*retry(ph.read1ByteTxRx, port, 1, 200)[1:], "read address 200")

# A Write of 512 to Goal Position (the e-manual's example) with its CRC corrupted, sent raw.
bad = bytes([0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0x00, 0x02, 0x00, 0x00, 0xCA, 0x88])
port.clearPort()
port.writePort(list(bad))
port.setPacketTimeout(11)
port.is_using = True
rx, res = ph.rxPacket(port, False)
port.is_using = False
if res != COMM_SUCCESS:
    raise SystemExit(f"no CRC error status: {ph.getTxRxResult(res)}")
out["crc"] = rx[8] & 0x7F
goal, res, err = retry(ph.read4ByteTxRx, port, 1, 116)
ok(res, err, "read goal")
out["goal_after_errors"] = goal

# --- Both motors: extended position mode, torque on, sync write goals ---
start = {}
for dxl_id in (1, 2):
    ok(*retry(ph.write1ByteTxRx, port, dxl_id, 11, 4), f"mode 4 on {dxl_id}")
    start[dxl_id], res, err = retry(ph.read4ByteTxRx, port, dxl_id, 132)
    ok(res, err, f"read present {dxl_id}")
    start[dxl_id] = s32(start[dxl_id])
    ok(*retry(ph.write1ByteTxRx, port, dxl_id, 64, 1), f"torque on {dxl_id}")
goals = {1: start[1] + 300, 2: start[2] + 600}
sync_write = GroupSyncWrite(port, ph, 116, 4)
for dxl_id, g in goals.items():
    assert sync_write.addParam(dxl_id, list((g & 0xFFFFFFFF).to_bytes(4, "little")))
res = sync_write.txPacket()
if res != COMM_SUCCESS:
    raise SystemExit(f"sync write: {ph.getTxRxResult(res)}")

# Bulk read while they move: ID 1 velocity and position, ID 2 current, velocity and position.
bulk = GroupBulkRead(port, ph)
assert bulk.addParam(1, 128, 8)
assert bulk.addParam(2, 126, 10)
sync_read = GroupSyncRead(port, ph, 132, 4)
for dxl_id in (1, 2):
    assert sync_read.addParam(dxl_id)
max_velocity = {1: 0, 2: 0}
moving_seen = False
still_since = None
present = dict(start)
deadline = time.time() + 10.0
while time.time() < deadline:
    res = retry(bulk.txRxPacket)
    if res != COMM_SUCCESS:
        raise SystemExit(f"bulk read: {ph.getTxRxResult(res)}")
    v1 = s32(bulk.getData(1, 128, 4))
    v2 = s32(bulk.getData(2, 128, 4))
    current = s16(bulk.getData(2, 126, 2))
    max_velocity[1] = max(max_velocity[1], v1)
    max_velocity[2] = max(max_velocity[2], v2)
    moving, res, err = retry(ph.read1ByteTxRx, port, 2, 122)
    ok(res, err, "read moving")
    moving_seen = moving_seen or moving == 1
    res = retry(sync_read.txRxPacket)
    if res != COMM_SUCCESS:
        raise SystemExit(f"sync read: {ph.getTxRxResult(res)}")
    present = {i: s32(sync_read.getData(i, 132, 4)) for i in (1, 2)}
    # Done once both have moved and then stood still for 300 ms of the device's own time
    # (Realtime Tick: a twin held up by a loaded machine does not count); a loaded motor may stall
    # short of its goal, as a real one does.
    tick, res, err = retry(ph.read2ByteTxRx, port, 2, 120)
    ok(res, err, "read realtime tick")
    if (v1, v2) == (0, 0) and min(max_velocity.values()) > 0:
        still_since = tick if still_since is None else still_since
        if (tick - still_since) % 32768 >= 300:
            break
    else:
        still_since = None
    time.sleep(0.01)
port.closePort()
out.update(
    {
        "start": start,
        "goals": goals,
        "present": present,
        "max_velocity": max_velocity,
        "moving_seen": moving_seen,
        "final_velocity": [v1, v2],
        "twine_current": current,
    }
)
print(json.dumps(out))
