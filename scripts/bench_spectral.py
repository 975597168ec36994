"""CPU time of the spectral path (issue 24, "seconds, not minutes"): one scene is a fixed
DBS (5 beams, 1-s beams, pulsed probe 18.75 / 24.75 m) with several gates, and a CW VAD
(50 lines of sight per 1-s revolution) with one gate, in an IEC Mann field; reports CPU
seconds per scene (``time.process_time``, so a loaded machine reads the same) and the
ratio of the DBS's time to that of the point variance alone (the tensor's cost).

Run: ``python scripts/bench_spectral.py``."""
import time

from uq.physics.lidarspectral import mann_lidar_variances, probe_transfer_for
from uq.physics.probe import ContinuousWaveProbe, PulsedProbe
from uq.physics.scangeometry import conical_scan
from uq.physics.spectraltensor import mann_tensor_for_intensity, point_variances


def conical(n_beams, heights, vertical, beam_duration):
    """The scan (:func:`uq.physics.scangeometry.conical_scan`, shared with the tests)."""
    return conical_scan(heights, n_beams=n_beams, vertical=vertical,
                        beam_duration=beam_duration)


def cpu(function):
    start = time.process_time()
    function()
    return time.process_time() - start


def main():
    tensor = mann_tensor_for_intensity(0.1, 10.0, 33.6, 3.9)
    base = cpu(lambda: point_variances(tensor))
    print(f"point variances alone (the tensor on the grid): {base:.3f} s CPU")
    for heights in ([100.0], [40.0, 100.0, 160.0], [40.0, 60.0, 80.0, 100.0, 120.0, 140.0]):
        g = conical(4, heights, True, 1.0)
        t = cpu(lambda: mann_lidar_variances(g, tensor, probe_transfer_for(
            PulsedProbe(18.75, 24.75), heights)))
        print(f"5-beam pulsed DBS, {len(heights)} gate(s): {t:.3f} s CPU "
              f"({t / base:.1f} x the point variances)")
    g = conical(50, [100.0], False, 0.02)
    probe = ContinuousWaveProbe(1.565e-6, 0.028, 0.02)
    t = cpu(lambda: mann_lidar_variances(g, tensor, probe_transfer_for(probe, [115.5])))
    print(f"CW VAD, 50 lines of sight, 1 gate: {t:.3f} s CPU ({t / base:.1f} x)")


if __name__ == "__main__":
    main()
