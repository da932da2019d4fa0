"""SDU ur_rtde's RTDEReceiveInterface against the virtual UR5e: prints actual_q and the timestamp as JSON.

Usage: python ur_rtde_receive.py HOST   (ur_rtde always uses port 30004)
"""
import json
import sys
import time

import rtde_receive

r = rtde_receive.RTDEReceiveInterface(sys.argv[1], 500.0, ["timestamp", "actual_q", "robot_mode"])
time.sleep(0.3)
out = {"q": r.getActualQ(), "t": r.getTimestamp(), "robot_mode": r.getRobotMode(), "connected": r.isConnected()}
r.disconnect()
print(json.dumps(out))
