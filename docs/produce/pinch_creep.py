"""A produce item pinched between two upright plates under gravity: how fast MuJoCo lets it slide.

Takes the item's flex (its `<flexcomp>`, with the contact its Hertz calibration gave) from a scene
exported by `tendril scene`, and squeezes it between two plates of the finger's friction: the left
plate fixed, the right one pushed by a constant force N, so that the plates' friction carries
`margin` times the item's weight (2 mu N = margin m g). The analytic answer is that the item does
not move at any margin above 1. MuJoCo's friction is a soft constraint, so it creeps; this prints
the item's sliding speed (its vertices' mean height, from 2 s to 4 s) at the cell's impedance
ratio 3 (`physics.impratio`; MuJoCo's own default is 1) and at 30, for the flex and for a rigid
ball of the first item's size and mass on the cell's 5 ms contacts. The item's mass, size and
friction are read from its flexcomp.

    tendril scene scenarios/cherry-tomato.toml --out /tmp/trilinear.xml
    tendril scene scenarios/cherry-tomato.toml --set 'produce.dof="quadratic"' --out /tmp/quadratic.xml
    vendor/venv/bin/python docs/produce/pinch_creep.py /tmp/trilinear.xml /tmp/quadratic.xml
"""
import re
import sys

import mujoco

STEP_S = 0.0025  # the cell's default step


def attribute(xml, name):
    return re.search(rf'\b{name}="([^"]*)"', xml).group(1)


def scene(body, item, impratio, integrator):
    plate = f'type="box" size="0.005 0.03 0.03" contype="2" conaffinity="0" friction="{item["mu"]} 0.005 0.0001"'
    gap = item["radius_m"] + 0.0005 + 0.005
    return f"""<mujoco>
  <option timestep="{STEP_S}" integrator="{integrator}" cone="elliptic" impratio="{impratio}" solver="Newton"/>
  <default><geom solref="0.005 1" solimp="0.95 0.99 0.001 0.5 2"/></default>
  <worldbody>
    <body pos="{-gap} 0 0"><geom {plate}/></body>
    <body pos="{gap} 0 0"><joint name="slide" type="slide" axis="1 0 0" damping="2"/>
      <geom {plate} mass="0.05"/></body>
    <body name="item">{body}</body>
  </worldbody>
  <actuator><motor joint="slide" gear="1"/></actuator>
</mujoco>"""


def height(m, d):
    return d.flexvert_xpos[:, 2].mean() if m.nflex else d.xpos[-1, 2]


def slide_mm_s(xml, item, margin):
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.ctrl[0] = -margin * item["mass_kg"] * 9.81 / (2 * item["mu"])
    while d.time < 2.0:
        mujoco.mj_step(m, d)
    t0, z0 = d.time, height(m, d)
    while d.time < 4.0:
        mujoco.mj_step(m, d)
    return (height(m, d) - z0) / (d.time - t0) * 1e3


items = []
for path in sys.argv[1:]:
    flex = re.search(r"<flexcomp.*?</flexcomp>", open(path).read(), re.S).group(0)
    count = float(attribute(flex, "count").split()[0])
    spacing = float(attribute(flex, "spacing").split()[0])
    item = {
        "mass_kg": float(attribute(flex, "mass")),
        "radius_m": (count - 1) * spacing / 2,  # the flex's half extent across the plates
        "mu": float(re.search(r'<contact[^>]*\bfriction="([^" ]*)', flex).group(1)),  # the skin's
    }
    items.append((f"flex, {attribute(flex, 'dof')}", flex, "discrete", item))
# The rigid ball: the first item's size, mass and friction on the cell's 5 ms contacts.
item = items[0][3]
rigid = (
    f'<freejoint/><geom type="sphere" size="{item["radius_m"]}" mass="{item["mass_kg"]}" contype="0" '
    f'conaffinity="2" friction="{item["mu"]} 0.005 0.0001"/>'
)
items.insert(0, ("rigid ball, 5 ms contacts", rigid, "implicitfast", item))
print("item | impratio | sliding speed at a friction margin of 2, 5, 10, 20 [mm/s]")
for name, body, integrator, item in items:
    for impratio in (3.0, 30.0):
        speeds = [slide_mm_s(scene(body, item, impratio, integrator), item, k) for k in (2, 5, 10, 20)]
        print(f"{name} | {impratio:g} | " + ", ".join(f"{-v:.3f}" for v in speeds), flush=True)
