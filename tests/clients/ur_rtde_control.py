"""SDU ur_rtde's RTDEControlInterface, RTDEReceiveInterface and RTDEIOInterface against the
virtual UR5e: the control interface uploads its own control script (run by the virtual
controller's URScript interpreter) and drives the arm with moveJ, moveL, servoJ, speedJ; the IO
interface sets outputs. Prints what it commanded and what it read back as JSON.

Usage: python ur_rtde_control.py HOST   (ur_rtde always uses ports 30004, 30003 and 29999)
"""
import json
import math
import sys
import time

import rtde_control
import rtde_io
import rtde_receive

host = sys.argv[1]
c = rtde_control.RTDEControlInterface(host)
r = rtde_receive.RTDEReceiveInterface(host)
out = {"program_running": c.isProgramRunning()}


def settle():
    # moveJ/moveL return once the program's move is over; give the receive stream a few
    # packages to carry the arm's state after the last physics step.
    time.sleep(0.05)


q0 = r.getActualQ()
q1 = list(q0)
q1[0] += 0.2
q1[5] -= 0.1
t = time.time()
out["movej_ok"] = c.moveJ(q1, 1.0, 2.0)
out["movej_s"] = time.time() - t
settle()
out["q0"], out["q1"], out["after_movej"] = q0, q1, r.getActualQ()
out["movej_back_ok"] = c.moveJ(q0, 1.0, 2.0)
settle()
out["after_movej_back"] = r.getActualQ()

p0 = r.getActualTCPPose()
p1 = list(p0)
p1[0] += 0.03
p1[2] -= 0.05
out["movel_ok"] = c.moveL(p1, 0.25, 1.2)
settle()
out["p0"], out["p1"], out["after_movel"] = p0, p1, r.getActualTCPPose()

# servoJ at 500 Hz for 1 s: the base joint along a 0.2 rad sine arc.
q = r.getActualQ()
follow = []
last = q
for k in range(500):
    start = c.initPeriod()
    last = list(q)
    last[0] += 0.2 * math.sin(2.0 * k * 0.002)
    c.servoJ(last, 0.5, 0.5, 0.002, 0.1, 300)
    if k % 50 == 49:
        follow.append([last[0], r.getActualQ()[0]])
    c.waitPeriod(start)
settle()
out["servo_start"], out["servo_last"], out["servo_follow"] = q, last, follow
out["servo_stop_ok"] = c.servoStop()
settle()
out["after_servo_stop"] = r.getActualQ()

# speedJ: base joint towards 0.3 rad/s at 0.5 rad/s²; speed sampled at 0.9-1.4 s (at speed after 0.6 s).
out["speedj_ok"] = c.speedJ([0.3, 0, 0, 0, 0, 0], 0.5, 0.002)
time.sleep(0.9)
qa, ta = r.getActualQ()[0], r.getTimestamp()
time.sleep(0.5)
qb, tb = r.getActualQ()[0], r.getTimestamp()
out["speed_mean"] = (qb - qa) / (tb - ta)
out["speed_stop_ok"] = c.speedStop(2.0)
time.sleep(0.4)
out["after_speed_stop_qd"] = r.getActualQd()
qs = r.getActualQ()[0]
time.sleep(0.2)
out["drift_after_speed_stop"] = r.getActualQ()[0] - qs

# stopJ ends an asynchronous moveJ half way: 0.6 rad on the last joint at 0.3 rad/s.
qs = r.getActualQ()
target = list(qs)
target[5] -= 0.6
out["movej_async_ok"] = c.moveJ(target, 0.3, 1.0, True)
time.sleep(0.8)
out["moving_before_stopj"] = r.getActualQd()
c.stopJ(2.0)
time.sleep(0.4)
out["after_stopj_qd"] = r.getActualQd()
out["stopj_start"], out["stopj_target"], out["after_stopj"] = qs, target, r.getActualQ()

io = rtde_io.RTDEIOInterface(host)
out["io_ok"] = [
    io.setStandardDigitalOut(3, True),
    io.setToolDigitalOut(1, True),
    io.setSpeedSlider(0.4),
    io.setAnalogOutputVoltage(1, 0.3),
]
time.sleep(0.1)
out["digital_bits"] = r.getActualDigitalOutputBits()
out["speed_fraction"] = r.getTargetSpeedFraction()
out["analog1"] = r.getStandardAnalogOutput1()
io.setStandardDigitalOut(3, False)
time.sleep(0.1)
out["digital_bits_after_clear"] = r.getActualDigitalOutputBits()

c.stopScript()
time.sleep(0.1)
out["running_after_stop_script"] = c.isProgramRunning()
c.disconnect()
r.disconnect()
print(json.dumps(out))
