"""Opens a scene exported by `tendril scene` with MuJoCo's own Python package, resets it to its
`start` keyframe and steps it for a second with nothing driving it: the object must stand still on
the table. Prints one JSON line with what it measured.

usage: scene_at_rest.py SCENE.xml
"""
import json
import sys

import mujoco
import numpy as np

model = mujoco.MjModel.from_xml_path(sys.argv[1])
data = mujoco.MjData(model)
key = model.key("start").id
mujoco.mj_resetDataKeyframe(model, data, key)
mujoco.mj_forward(model, data)
obj = model.body("object").id
hand = model.body("hand").id
obj0, hand0 = data.xpos[obj].copy(), data.xpos[hand].copy()
keyframe_matches = bool(np.allclose(data.qpos, model.key_qpos[key]))
steps = int(round(1.0 / model.opt.timestep))
for _ in range(steps):
    mujoco.mj_step(model, data)
print(json.dumps({
    "nkey": int(model.nkey),
    "keyframe_matches": keyframe_matches,
    "steps": steps,
    "object_moved_m": float(np.linalg.norm(data.xpos[obj] - obj0)),
    "hand_moved_m": float(np.linalg.norm(data.xpos[hand] - hand0)),
    "object_z_m": float(data.xpos[obj][2]),
    "finite": bool(np.all(np.isfinite(data.qpos))),
}))
