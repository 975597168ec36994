"""The spectral path under refinement: a pulsed DBS at 40-300 m and a nacelle lidar's
50-400 m previews (Mann, IEC parameters, 600-s and 3600-s records).

    python scripts/spectral_convergence.py

For each scan: the (u, v, w) variance ratios of the default rules, their stated errors,
and the largest change under two refinements (two nodes more a panel; then a panel more
a decade): the acceptance is a change below 1e-3 (relative) and within the stated error.
"""
import time

import numpy as np

from uq.physics.lidarspectral import (PairResolution, mann_lidar_variances,
                                      probe_transfer_for)
from uq.physics.probe import PulsedProbe
from uq.physics.scangeometry import conical_scan
from uq.pipeline import records
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path
from uq.physics.spectraltensor import mann_tensor_for_intensity


def study(name, geometry, tensor, transfer):
    start = time.process_time()
    default = mann_lidar_variances(geometry, tensor, transfer)
    cost = time.process_time() - start
    worst, bounded = 0.0, True
    for resolution in (PairResolution(2, 8), PairResolution(3, 8)):
        finer = mann_lidar_variances(geometry, tensor, transfer, resolution)
        change = np.abs(finer.ratios() - default.ratios())
        worst = max(worst, float(np.max(change / np.abs(default.ratios()))))
        bounded &= bool(np.all(change <= default.ratio_errors()))
    print(f"{name}: {cost:.1f} s CPU; ratios u/v/w by gate "
          f"{np.round(default.ratios(), 4).tolist()}; stated relative errors up to "
          f"{np.max(default.ratio_errors() / np.abs(default.ratios())):.1e}; largest "
          f"relative change under refinement {worst:.1e}; within the stated error: "
          f"{bounded}", flush=True)


def main():
    tensor = mann_tensor_for_intensity(0.1, 10.0, 33.6, 3.9)
    heights = [40.0, 100.0, 200.0, 300.0]
    probe = probe_transfer_for(PulsedProbe(18.75, 24.75), heights)
    for record in (600.0, 3600.0):
        study(f"pulsed DBS, {record:g}-s records",
              conical_scan(heights, beam_duration=1.0, vertical=True, record=record,
                           speed=10.0), tensor, probe)
    settings = load_scenario(scenario_path("nacelle_fixed"), {
        "turbulence": {"intensity": 0.1}, "record": {"duration": 600},
        "sampling": {"method": "none"}, "lidar.ranges": [50.0, 100.0, 200.0, 400.0],
        "outputs": ["wind_speed"]}).settings
    geometry = records.scan_geometry(settings)
    model = records.turbulence_model(settings["turbulence"], settings["wind"]["speed"])
    study("nacelle lidar, 600-s records", geometry, model,
          probe_transfer_for(None, records.slant_ranges(settings["lidar"])))


if __name__ == "__main__":
    main()
