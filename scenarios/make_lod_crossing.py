#!/usr/bin/env python3
"""Writes scenarios/lod-crossing.json: a 481 x 481-tuft meadow (120 m) with a painted football
field, a mower and a football, and a scripted camera that crosses it diagonally in 15 s while
the level-of-detail window (121 x 121 particles, 30 m) follows it.
    python3 scenarios/make_lod_crossing.py"""
import json
import os

TICKS = 900            # 15 s at 1/60 s
START, END = -45, 45   # camera x = z from START to END (m)
KEY_EVERY = 4          # camera keys every 4 ticks (0.6 m apart)

camera = []
for t in range(0, TICKS + 1, KEY_EVERY):
    c = START + (END - START) * t / TICKS
    camera.append({"tick": t, "position": [round(c, 4), 2, round(c, 4)]})

script = [
    {"tick": 10, "body": "football", "command": "addVelocity", "value": [6, 0, 6]},
    {"tick": 30, "body": "mower", "command": "addVelocity", "value": [1.5, 0, 0]},
]
# The mower's damping eats its speed: a small push every 10 ticks keeps it at about 1.5 m/s.
script += [{"tick": t, "body": "mower", "command": "addVelocity", "value": [0.033, 0, 0]}
           for t in range(40, TICKS, 10)]

mower = {
    "name": "mower", "mass": 30, "position": [-42, 0.45, -40], "friction": 0.02, "restitution": 0,
    "linearDamping": 1, "angularDamping": 0.2, "mower": True,
    "shape": {"type": "compound", "parts": [
        {"type": "box", "halfExtents": [0.5, 0.25, 0.4], "offset": [0, 0, 0]},
        {"type": "sphere", "radius": 0.15, "offset": [0.4, -0.3, 0.35]},
        {"type": "sphere", "radius": 0.15, "offset": [0.4, -0.3, -0.35]},
        {"type": "sphere", "radius": 0.15, "offset": [-0.4, -0.3, 0.35]},
        {"type": "sphere", "radius": 0.15, "offset": [-0.4, -0.3, -0.35]}]}}
football = {"name": "football", "mass": 0.45, "position": [-44, 0.4, -44], "friction": 0.3,
            "restitution": 0.5, "shape": {"type": "sphere", "radius": 0.35}}

scenario = {
    "format": "simgrass-scenario/1",
    "name": "lod-crossing",
    "description": "Level of detail: a 120 m meadow with a painted football field; the camera crosses it "
                   "diagonally in 15 s and the 30 m simulation window, its edge-grass ring and the ground "
                   "follow it, while a mower cuts a lane and a football rolls along. Made by make_lod_crossing.py.",
    "seed": 7,
    "scalar": "fx32",
    "timeStep": "1/60",
    "field": {"patchesX": 481, "patchesZ": 481, "spacing": 0.25, "jitter": 0.3, "center": [0, 0],
              "scaleY": 0.6, "scaleXZ": 0.5},
    "particles": {"interpolation": 1, "constraintLength": 0.5, "tiltDrop": [0.1, 0.15, 0.2]},
    "terrain": {"type": "flat", "height": 0},
    "markings": {"center": [0, 0], "length": 30, "width": 20, "lineWidth": 0.5, "centerCircleRadius": 3},
    "lod": {"mode": "window", "window": [121, 121], "center": [START, START], "edgeSpacing": 4, "edgeRows": 20},
    "bodies": {"mowerCutHeight": 0.25,
               "list": [mower, football]},
    "script": script,
    "camera": camera,
}
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "lod-crossing.json")
with open(path, "w") as f:
    json.dump(scenario, f, indent=1)
    f.write("\n")
print(path)
