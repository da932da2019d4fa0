"""SDU ur_rtde's RTDEReceiveInterface against the virtual UR5e: prints actual_q, actual_qd,
actual_TCP_pose, the safety mode and the timestamp as JSON.

Usage: python ur_rtde_receive.py HOST   (ur_rtde always uses port 30004)
"""
import json
import sys
import time

import rtde_receive

names = ["timestamp", "actual_q", "actual_qd", "actual_TCP_pose", "robot_mode", "safety_mode"]
r = rtde_receive.RTDEReceiveInterface(sys.argv[1], 500.0, names)
time.sleep(0.3)
out = {
    "q": r.getActualQ(),
    "qd": r.getActualQd(),
    "pose": r.getActualTCPPose(),
    "t": r.getTimestamp(),
    "robot_mode": r.getRobotMode(),
    "safety_mode": r.getSafetyMode(),
    "connected": r.isConnected(),
}
r.disconnect()
print(json.dumps(out))
