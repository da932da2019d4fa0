"""Quasi-static wrap: where the finger presses the object, at a fixed tendon stroke.

Loads a scene exported by `tendril scene` (MuJoCo's Python package, as in the test venv), holds
the arm at its start pose, grows the strip to 14 cm at 5 cm/s, winds `stroke_mm` of tendon at
4.2 mm/s (the guarded close's 15 deg/s on the 16 mm spool), holds 3 s, and prints the normal
force of every contact on the object's grip by finger geom. No controller, no sensor: the force
distribution the discretisation alone produces.

    for n in 8 16 32 64 128; do
      tendril scene scenarios/crimper.toml --set finger.segments=$n --out /tmp/c$n.xml
      vendor/venv/bin/python docs/convergence/wrap_quasistatic.py /tmp/c$n.xml 30
    done
"""
import sys

import mujoco
import numpy as np

path, stroke_mm = sys.argv[1], float(sys.argv[2])
m = mujoco.MjModel.from_xml_path(path)
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, m.key("start").id)
arm = [m.joint(n) for n in ["shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"]]
q0 = d.qpos.copy()
grow, twine = m.actuator("growth").id, m.actuator("twine").id
grip = m.geom("object_grip").id
grow_s = 0.14 / 0.05
end_s = grow_s + stroke_mm / 4.2 + 3.0
while d.time < end_s:
    t = d.time
    d.ctrl[grow] = min(0.14, 0.05 * t)
    d.ctrl[twine] = 0.0 if t < grow_s else min(stroke_mm / 1000.0, 0.0042 * (t - grow_s))
    for j in arm:  # the arm holds its pose (the twin's kinematic arm)
        d.qpos[j.qposadr[0]] = q0[j.qposadr[0]]
        d.qvel[j.dofadr[0]] = 0.0
    mujoco.mj_step(m, d)

force = np.zeros(6)
by_geom = {}
for i in range(d.ncon):
    c = d.contact[i]
    if grip not in (c.geom1, c.geom2):
        continue
    other = c.geom2 if c.geom1 == grip else c.geom1
    mujoco.mj_contactForce(m, d, i, force)
    name = m.geom(other).name
    by_geom[name] = by_geom.get(name, 0.0) + force[0]
total = sum(by_geom.values())
pad = by_geom.get("pad_bump", 0.0) + by_geom.get("pad_casing", 0.0)
print(f"{path}: grip {total:.2f} N, pad {pad:.3f} N ({100 * pad / max(total, 1e-9):.0f} %), "
      f"palm {by_geom.get('palm', 0.0):.2f} N, {len(by_geom)} geoms in contact")
print("  " + " ".join(f"{k}:{v:.2f}" for k, v in sorted(by_geom.items())))
