"""A produce item pinched between two upright plates under gravity: how fast MuJoCo lets it slide.

Takes the item's flex (its `<flexcomp>`, with the contact its Hertz calibration gave) from a scene
exported by `tendril scene`, and squeezes it between two plates of the finger's friction: the left
plate fixed, the right one pushed by a constant force N, so that the plates' friction carries
`margin` times the item's weight (2 mu N = margin m g). The analytic answer is that the item does
not move at any margin above 1. MuJoCo's friction is a soft constraint, so it creeps; this prints
the item's sliding speed (its vertices' mean height, from 2 s to 4 s) at MuJoCo's default-like
impedance ratio 3 (the cell's `physics.impratio`) and at 30, for the flex and for a rigid ball of
the same size and mass on the cell's 5 ms contacts.

    tendril scene scenarios/cherry-tomato.toml --out /tmp/trilinear.xml
    tendril scene scenarios/cherry-tomato.toml --set 'produce.dof="quadratic"' --out /tmp/quadratic.xml
    vendor/venv/bin/python docs/produce/pinch_creep.py /tmp/trilinear.xml /tmp/quadratic.xml
"""
import re
import sys

import mujoco
import numpy as np

MU = 0.5  # the skin's friction against the finger's TPU (the cherry tomato's `produce_friction`)
MASS_KG = 0.012  # the cherry tomato
RADIUS_M = 0.0148  # its flex's half extent: 6 intervals of 4.93 mm
STEP_S = 0.0025  # the cell's default step
PLATE = 'type="box" size="0.005 0.03 0.03" contype="2" conaffinity="0" friction="0.5 0.005 0.0001"'


def scene(body, impratio, integrator):
    gap = RADIUS_M + 0.0005 + 0.005
    return f"""<mujoco>
  <option timestep="{STEP_S}" integrator="{integrator}" cone="elliptic" impratio="{impratio}" solver="Newton"/>
  <default><geom solref="0.005 1" solimp="0.95 0.99 0.001 0.5 2"/></default>
  <worldbody>
    <body pos="{-gap} 0 0"><geom {PLATE}/></body>
    <body pos="{gap} 0 0"><joint name="slide" type="slide" axis="1 0 0" damping="2"/>
      <geom {PLATE} mass="0.05"/></body>
    <body name="item">{body}</body>
  </worldbody>
  <actuator><motor joint="slide" gear="1"/></actuator>
</mujoco>"""


def slide_mm_s(xml, margin):
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.ctrl[0] = -margin * MASS_KG * 9.81 / (2 * MU)
    heights = []
    while d.time < 4.0:
        mujoco.mj_step(m, d)
        z = d.flexvert_xpos[:, 2].mean() if m.nflex else d.xpos[-1, 2]
        heights.append((d.time, z))
    h = np.array([p for p in heights if p[0] >= 2.0])
    return (h[-1, 1] - h[0, 1]) / (h[-1, 0] - h[0, 0]) * 1e3


rigid = f'<freejoint/><geom type="sphere" size="{RADIUS_M}" mass="{MASS_KG}" contype="0" conaffinity="2" friction="0.5 0.005 0.0001"/>'
items = [("rigid ball, 5 ms contacts", rigid, "implicitfast")]
for path in sys.argv[1:]:
    text = open(path).read()
    flex = re.search(r"<flexcomp.*?</flexcomp>", text, re.S).group(0)
    dof = re.search(r'dof="(\w+)"', flex).group(1)
    items.append((f"flex, {dof}", flex, "discrete"))
print("item | impratio | sliding speed at a friction margin of 2, 5, 10, 20 [mm/s]")
for name, body, integrator in items:
    for impratio in (3.0, 30.0):
        speeds = [slide_mm_s(scene(body, impratio, integrator), k) for k in (2, 5, 10, 20)]
        print(f"{name} | {impratio:g} | " + ", ".join(f"{-v:.3f}" for v in speeds), flush=True)
