"""The paper's Figure 1 from Python: the nonholonomic particle's energy along
the DLA (alpha = 1/2), RK4 and the reference solution at h = 0.2, drawn with
matplotlib (plots/energy.gp draws the same figure from `nhi run`'s files).

    python3 examples/python/fig1.py [SCENE.json [OUT.png]]

SCENE defaults to experiments/scenes/particle_fig12.json, OUT to
fig1_particle_energy.png.  Needs the module nhi on the path (PYTHONPATH).
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import nhi  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
scene_file = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "../../experiments/scenes/particle_fig12.json")
out = sys.argv[2] if len(sys.argv) > 2 else "fig1_particle_energy.png"

with open(scene_file) as f:
    scene = json.load(f)
runs = {label: nhi.run({**scene, "method": method})
        for label, method in [("DLA, α = 1/2", "dla"), ("RK4", "rk4"), ("benchmark (CVODE, tol 1e-12)", "benchmark")]}

fig, (whole, start) = plt.subplots(2, 1, figsize=(8, 7), constrained_layout=True)
fig.suptitle(f"Figure 1: nonholonomic particle, energy (h = {scene['h']})")
for label, r in runs.items():
    whole.plot(r["t"], r["energy"], lw=0.8, label=label)
    first = r["t"] <= 40
    start.plot(r["t"][first], r["energy"][first], lw=0.8, label=label)
    print(f"{label:30s} max |E - E0| = {r['summary']['max_abs_energy_error']:.3e}")
start.set_title("first 40 time units")
for ax in (whole, start):
    ax.set_xlabel("t")
    ax.set_ylabel("E")
whole.legend(loc="lower left")  # the same colours below
fig.savefig(out, dpi=100)
print(f"wrote {out}")
