"""SDU ur_rtde's DashboardClient against the virtual UR5e's dashboard server. Prints JSON.

Usage: python ur_rtde_dashboard.py HOST PORT
"""
import json
import sys

from dashboard_client import DashboardClient

d = DashboardClient(sys.argv[1], int(sys.argv[2]))
d.connect()
out = {
    "connected": d.isConnected(),
    "remote": d.isInRemoteControl(),
    "version": d.polyscopeVersion(),
    "robotmode": d.robotmode(),
    "safetystatus": d.safetystatus(),
}
d.powerOff()
out["after_power_off"] = d.robotmode()
d.powerOn()
out["after_power_on"] = d.robotmode()
d.brakeRelease()
out["after_brake_release"] = d.robotmode()
d.loadURP("/programs/follow.urp")  # raises unless "Loading program:"
d.play()  # raises unless "Starting program"
out["running"] = d.running()
out["program_state"] = d.programState()
d.pause()  # raises unless "Pausing program"
out["paused_state"] = d.programState()
d.stop()  # raises unless "Stopped"
out["running_after_stop"] = d.running()
d.unlockProtectiveStop()  # raises unless "Protective stop releasing"
d.closeSafetyPopup()
d.disconnect()
print(json.dumps(out))
