"""TAV scene tooling: the 75 bpm pressure waveform, the parametric size-23 valve mesh,
the ISO 5840-3 tube description and the kinematic metrics of a run (issue 4).

Run the command-line tools from `scripts/` (or with PYTHONPATH=scripts):
    /usr/bin/python3 -m valve_scene.waveform --textproto cases/waveforms/wiggers-75bpm.textproto
    /usr/bin/python3 -m valve_scene.generate --variant full --resolution medium --out valve.mesh.h5
    /usr/bin/python3 -m valve_scene.tube --png tube.png
See docs/valve-scene.md for the models and their sources.
"""

MMHG_TO_PA = 133.322387415  # 1 mmHg = 101325/760 Pa
