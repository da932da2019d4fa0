"""ROBOTIS dynamixel-sdk against the virtual MX-106 bus: ping, torque on, write and read Goal
Position, then poll Present Position while the twin's motor moves. Prints JSON.

Usage: python dynamixel_sdk_client.py PTY GOAL_TICKS
"""
import json
import sys
import time

from dynamixel_sdk import COMM_RX_TIMEOUT, COMM_SUCCESS, PacketHandler, PortHandler

port = PortHandler(sys.argv[1])
goal = int(sys.argv[2])
assert port.openPort(), "cannot open port"
assert port.setBaudRate(57600), "cannot set baud rate"
ph = PacketHandler(2.0)


def retry(call, *args):
    """`call(*args)`, again if no status came: on a loaded machine the virtual bus can miss the
    SDK's 34 ms reply window now and then, as a real bus can drop a packet."""
    for _ in range(5):
        result = call(*args)
        if result[-2] != COMM_RX_TIMEOUT:
            return result
    return result


def ok(res, err, what):
    if res != COMM_SUCCESS or err != 0:
        raise SystemExit(f"{what}: {ph.getTxRxResult(res)} {ph.getRxPacketError(err)}")


model, res, err = retry(ph.ping, port, 1)
ok(res, err, "ping")
present0, res, err = retry(ph.read4ByteTxRx, port, 1, 132)
ok(res, err, "read present")
res, err = retry(ph.write1ByteTxRx, port, 1, 64, 1)
ok(res, err, "torque on")
res, err = retry(ph.write4ByteTxRx, port, 1, 116, goal & 0xFFFFFFFF)
ok(res, err, "write goal")
goal_read, res, err = retry(ph.read4ByteTxRx, port, 1, 116)
ok(res, err, "read goal")
present = present0
deadline = time.time() + 5.0
while time.time() < deadline:
    present, res, err = retry(ph.read4ByteTxRx, port, 1, 132)
    ok(res, err, "read present")
    if abs(present - goal) <= 20:
        break
    time.sleep(0.02)
port.closePort()
print(json.dumps({"model": model, "goal": goal_read, "present0": present0, "present": present}))
