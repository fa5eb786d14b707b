"""flex from a script or notebook: two readings of the thesis's spring preload.

Run it as a script (``.venv/bin/python docs/example.py``) or cell by cell in an editor that
understands ``# %%`` cells. ``tests/test_docs_example.py`` runs it and checks its numbers.
"""

# %% [markdown]
# The thesis never states the spring preload: its ABAQUS study presses the spring 22 mm,
# while the slider travel it reports fits 11 mm (docs/thesis.md). The bundled scene
# `cavezza2012` takes 22 mm; derive the 11 mm reading from it and simulate both with rigid
# links over the first 0.03 s of the deployment.

# %%
import tempfile
from pathlib import Path

import numpy as np

from flex import derive_scene, load_scene, open_result, run_study, simulate

scene = load_scene()  # the bundled cavezza2012 scene, validated
scene = derive_scene(scene, {"simulation.end_time_s": 0.03})  # [s]
soft = derive_scene(scene, {"drive.spring_preload_m": 0.011})  # [m]
print("preloads [m]:", scene["drive"]["spring_preload_m"], soft["drive"]["spring_preload_m"])

# %%
peaks = {}
for label, each in (("22 mm", scene), ("11 mm", soft)):
    case = simulate(each, name=label)  # rigid links: a fraction of a second
    time_s = case.datasets["time"].data
    speed = case.datasets["crank/angular_velocity"]
    i = int(np.argmax(speed.data))
    peaks[label] = float(speed.data[i])
    print(f"preload {label}: peak crank speed {speed.data[i]:.2f} {speed.units} "
          f"at t = {time_s[i]:.5f} s")

# %% [markdown]
# The same run as a result file, as `flex run simulate --set drive.spring_preload_m=0.011`
# writes it, opened as an xarray Dataset (units on every variable).

# %%
folder = Path(tempfile.mkdtemp(prefix="flex-example-"))
run_study("simulate", overrides={"drive.spring_preload_m": 0.011,
                                 "simulation.end_time_s": 0.03},
          out=folder / "soft.h5", figures=False, quiet=True)
ds = open_result(folder / "soft.h5")  # one case: no case name needed
print(f"result file {folder / 'soft.h5'}")
angle = ds["crank/angle"]
print(f"crank angle maximum {float(angle.max()):.3f} {angle.attrs['units']} "
      f"at t = {float(angle.idxmax('time')):.4f} s")
