"""Turbulence-intensity KPIs of a verification campaign, and the TI that ``uq`` predicts.

Per reference-wind-speed bin, with TI in percent as the files give it (``100 sigma / U``
of each 10-min record) and only records where both instruments have a TI:

* mean bias error ``MBE = mean(TI_unit - TI_ref)`` [percentage points];
* relative error ``MBE / mean(TI_ref)`` [1];
* root-mean-square error ``sqrt(mean((TI_unit - TI_ref)^2))`` [percentage points];
* representative TI ``TI_rep = mean + 1.28 sd`` (IEC 61400-1:2005 Sec. 6.3.1, the 90 %
  quantile of a normal TI distribution; sd with ``ddof = 1``) of each instrument and their
  difference ``TI_rep,unit - TI_rep,ref`` [percentage points].

These are the error metrics of the Carbon Trust OWA roadmap's TI assessment (version 3.0,
2023, the "+" designation; IEC 61400-12-1 Annex L compares a remote sensor's TI in the
same way). No numeric acceptance band for them was found in the public material at hand
(the 2018 roadmap has no TI KPI; DNV-RP-0661 gives none), so by default they are
**informational**; ``golden.kpi.turbulence.bands`` sets ``[best, minimum]`` bounds on the
absolute value of each, and a bin is then ``best practice``, ``minimum`` or ``fail``.

Prediction. A lidar does not see the point TI: its probe volume, the separation of its
beams and the scan's timing filter the turbulence (Sathe et al. 2011). Where the unit's
instrument names its ``uq`` scenario (``golden.instruments.NAME.scenario``), the apparent
TI is predicted by the spectral path (:mod:`uq.physics.lidarspectral`) for that lidar,
fixed and level (motion is left out), in an IEC 61400-1 Mann field at each height (L = 0.8
Lambda_1, Gamma = 3.9), a 600-s record at the mid speed of the required range:
``TI_predicted = TI_ref sqrt(var_lidar / var_true)`` per bin; where the reference is a
lidar with a scenario too, the ratio is the unit's over the reference's.

References
----------
Carbon Trust (2023). Offshore Wind Accelerator roadmap for the commercial acceptance of
floating LiDAR technology, version 3.0. IEC 61400-1:2005, Sec. 6.3.1 and Annex B.
Sathe, A., Mann, J., Gottschall, J. and Courtney, M. S. (2011). J. Atmos. Oceanic Technol.
28, 853-868.
"""
import numpy as np

from uq.constants import GOLDEN_RECORD_SECONDS, REPRESENTATIVE_TI_QUANTILE
from uq.physics.lidarspectral import mann_lidar_variances, probe_transfer_for
from uq.physics.scangeometry import ScanGeometry, earth_to_wind_frame
from uq.physics.spectraltensor import iec_mann_parameters, mann_tensor_for_intensity
from . import binning
from .kpi import BEST, FAIL, MINIMUM, NO_DATA

INFORMATIONAL = "informational"
#: KPI names (Dataset variables ``ti_<name>``) and their units.
TI_KPIS = {"mean_bias": "percent", "relative_error": "1", "rmse": "percent",
           "representative_error": "percent"}
#: Speed [m s-1] and TI [1] at which the prediction's variance ratio is computed (the
#: ratio does not depend on the TI; on the speed only through the scan's timing).
PREDICTION_INTENSITY = 0.1


#: The statistics of the unit's own TI (NaN where its TI is a copy of the reference's).
UNIT_STATISTICS = ("unit_mean", "mean_bias", "relative_error", "rmse", "unit_representative",
                   "representative_error")


def copies(reference_ti, unit_ti):
    """Is the unit's TI the reference's, record for record (every record where both have
    one, and at least one)? A synthetic campaign whose lidars carry the mast's TI, say:
    then there is no TI error to measure, and an error of exactly zero would read as one."""
    ref, unit = np.asarray(reference_ti, float), np.asarray(unit_ti, float)
    both = np.isfinite(ref) & np.isfinite(unit)
    return bool(both.any() and np.array_equal(ref[both], unit[both]))


def ti_bin_kpis(reference_ti, unit_ti, reference_speed, centres, width):
    """Per-bin TI statistics and KPIs (module docstring); arrays of shape (n_bins,)."""
    ref, unit = np.asarray(reference_ti, float), np.asarray(unit_ti, float)
    both = np.isfinite(ref) & np.isfinite(unit)
    index = binning.bin_index(np.where(both, reference_speed, np.nan), width)
    keys = np.rint(np.asarray(centres) / width).astype(int)
    rows = [_bin(ref[index == k], unit[index == k]) for k in keys]
    return {name: np.array([r[name] for r in rows]) for name in rows[0]}


def _bin(ref, unit):
    n = len(ref)
    if n == 0:
        nan = np.nan
        return dict(n_records=0, reference_mean=nan, unit_mean=nan, mean_bias=nan,
                    relative_error=nan, rmse=nan, reference_representative=nan,
                    unit_representative=nan, representative_error=nan)
    difference = unit - ref
    rep_ref, rep_unit = representative_ti(ref), representative_ti(unit)
    return dict(n_records=n, reference_mean=ref.mean(), unit_mean=unit.mean(),
                mean_bias=difference.mean(), relative_error=difference.mean() / ref.mean(),
                rmse=np.sqrt(np.mean(difference ** 2)), reference_representative=rep_ref,
                unit_representative=rep_unit, representative_error=rep_unit - rep_ref)


def representative_ti(values):
    """``mean + 1.28 sd`` (sd with ddof 1; NaN for fewer than 2 values)."""
    values = np.asarray(values, float)
    if len(values) < 2:
        return np.nan
    return values.mean() + REPRESENTATIVE_TI_QUANTILE * values.std(ddof=1)


def band_verdicts(values, band):
    """Verdict per bin of ``|value|`` against ``(best, minimum)``; ``informational``
    without a band, ``no data`` where a value is NaN."""
    out = []
    for v in np.asarray(values, float):
        if not np.isfinite(v):
            out.append(NO_DATA)
        elif band is None:
            out.append(INFORMATIONAL)
        else:
            out.append(BEST if abs(v) <= band[0] else MINIMUM if abs(v) <= band[1] else FAIL)
    return np.array(out, dtype=object)


def scenario_geometry(settings, height, speed, record=GOLDEN_RECORD_SECONDS):
    """The :class:`ScanGeometry` of a ``uq run`` scenario's lidar, fixed and level, with its
    gate at `height` [m] as the reference point, and the slant distance of that gate [m].

    The scenario's ``lidar.ranges`` are heights above the lidar; beams at ``half_cone``
    from the vertical, azimuths clockwise from the heading (``ship.heading``), one after
    another every ``lidar.scan.beam_duration`` (1 s by default); the reconstruction is
    the least-squares inverse of the beam directions."""
    lidar, wind = settings["lidar"], settings["wind"]
    heading = float(settings.get("ship", {}).get("heading", 0.0))
    phi = np.radians(float(lidar["half_cone"]))
    azimuth = np.radians(heading + np.asarray(lidar["azimuths"], float))
    earth = np.stack([np.sin(phi) * np.cos(azimuth), np.sin(phi) * np.sin(azimuth),
                      np.full(len(azimuth), np.cos(phi))], axis=-1)
    if lidar.get("vertical_beam"):
        earth = np.vstack([earth, [0.0, 0.0, 1.0]])
    directions = earth_to_wind_frame(earth, float(wind["direction"]))
    above = height - float(lidar.get("height", 0.0))
    slant = above / directions[:, 2]
    centres = (slant[:, None] * directions - [0.0, 0.0, above])[:, None, :]
    duration = float(lidar.get("scan", {}).get("beam_duration", 1.0))
    n = len(directions)
    return ScanGeometry(directions, centres, (np.arange(n) + 0.5) * duration, duration,
                        n * duration, np.zeros(1), np.ones((1, 1)),
                        np.linalg.pinv(directions)[None], speed, record), float(slant[0])


def predicted_variance_ratio(settings, height, speed):
    """``var_lidar / var_true`` of u [1] for a scenario's lidar at `height` [m] and
    `speed` [m s-1] in the IEC Mann field (module docstring)."""
    from uq.pipeline import probesection
    geometry, slant = scenario_geometry(settings, height, speed)
    length, anisotropy = iec_mann_parameters(height)
    tensor = mann_tensor_for_intensity(PREDICTION_INTENSITY, speed, length, anisotropy)
    probe = probesection.make_probe(settings["lidar"].get("probe"))
    result = mann_lidar_variances(geometry, tensor, probe_transfer_for(probe, [slant]))
    return float(result.ratio()[0])
