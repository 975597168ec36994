"""The model's terms of each record and height, by the fast path (the campaign's
tables, :mod:`uq.campaign.surrogate`) or the direct path (the spectral path and the
measurement model run for the record itself, :mod:`uq.campaign.adapter`).

Terms (arrays (n,)): ``filtering`` F and ``spread`` of the record variance
(:mod:`uq.campaign.spectra`), ``motion_variance`` V_m [m2 s-2] (the record's high-pass
applied), ``motion_u`` [m s-1] (the motion's u of one scan, no high-pass: the clause-8
flag reads its tolerance), ``motion_cross`` [m2 s-2] (``sum_k V_k q(f_k)``: the motion's
share of the spread of s^2 with the turbulence, :mod:`uq.campaign.spectra`),
``motion_phase`` [m4 s-4] (the spread of the motion's own sample variance, its phases
unknown; 0 for an IMU log's),
``motion_bias`` b [m s-1] and ``noise_variance`` sigma^2 [m2 s-2]. They are evaluated at the record's measured mean speed (the motion's bias,
~1 % of it, moves them by its second order). With ``filtering`` ``none`` F is 1 (the
records keep the lidar's own filtering: only the motion is removed); the spread is the
lidar's still.
"""
import numpy as np

from uq.campaign import adapter, motion, spectra, surrogate

#: Components per call of the measurement model in the direct path (its trials hold
#: every component: memory and time ~ n^2).
DIRECT_CHUNK = 96
TERMS = ("filtering", "spread", "motion_variance", "motion_u", "motion_cross", "motion_phase",
         "motion_bias", "noise_variance")


def fast_terms(tables, height_index, speed, direction, motions, filtering=True):
    """The terms of records (height index, speed [m s-1], direction [deg], each (n,);
    their :class:`uq.campaign.motion.MotionSet`) from the tables."""
    speed = np.asarray(speed, float)
    f, spread, _ = surrogate.spectral_at(tables, height_index, speed, direction)
    out = {"filtering": f if filtering else np.ones_like(f), "spread": spread,
           "noise_variance": surrogate.noise_at(tables, height_index, speed, direction)}
    if motions.frequency.shape[1] == 0:
        zero = np.zeros_like(speed)
        return {**out, "motion_variance": zero, "motion_u": zero, "motion_cross": zero,
                "motion_phase": zero, "motion_bias": zero}
    y = surrogate.response_at(tables, height_index, speed, direction, motions.frequency,
                              motions.shape)
    g = surrogate.curvature_at(tables, height_index, speed, direction, motions.frequency,
                               motions.shape)
    q = surrogate.cross_at(tables, height_index, speed, direction, motions.frequency)
    return {**out, **motion_terms(y, g, q, motions.power, motions.frequency,
                                  tables.scan_period, tables.record_duration,
                                  motions.random_phases)}


def motion_terms(y, g, q, power, frequency, scan_period, record_duration, random_phases):
    """The motion's terms from each component's response y, curvature g, cross response
    q, power P and frequency [Hz] (arrays (..., K)); `random_phases` as
    :class:`uq.campaign.motion.MotionSet`'s."""
    high_pass = adapter.record_high_pass(frequency, scan_period, record_duration)
    one_scan = motion.motion_variance(y, power, 1.0)
    n_scans = int(np.floor(record_duration / scan_period + 1e-9))
    phase = spectra.phase_variance(power * np.abs(y) ** 2, frequency, scan_period, n_scans) \
        if random_phases else np.zeros(np.shape(one_scan))
    return {"motion_variance": motion.motion_variance(y, power, high_pass),
            "motion_u": np.sqrt(np.maximum(one_scan, 0.0)),
            "motion_cross": motion.motion_variance(y, power, q),
            "motion_phase": phase,
            "motion_bias": motion.motion_bias(g, power)}


def direct_terms(lidar, height, scale, turbulence, record_duration, speed, direction,
                 motions, filtering=True):
    """The terms of one record at one height (floats) by the direct path: the spectral
    path of the gate in the record's wind, the measurement model's derivatives at the
    record's own components (`motions`: a set of one record)."""
    settings = adapter.gate_settings(lidar, [height], {**turbulence, "length_scale": scale},
                                     record_duration, speed, direction)
    terms = adapter.spectral_terms(settings).gate(0)
    n_scans = adapter.scans_per_record(settings)
    covariance = spectra.scan_covariance(terms, n_scans)
    out = {"filtering": spectra.filtering_factor(terms) if filtering else 1.0,
           "spread": spectra.toeplitz_spread(covariance),
           "noise_variance": adapter.scan_noise_variance(settings)}
    frequency, power = motions.frequency[0], motions.power[0]
    keep = power != 0
    if not np.any(keep):
        return {**out, "motion_variance": 0.0, "motion_u": 0.0, "motion_cross": 0.0,
                "motion_phase": 0.0, "motion_bias": 0.0}
    frequency, power = frequency[keep], power[keep]
    shape = motions.shapes[motions.shape[0][keep]]
    y = np.concatenate([adapter.motion_jacobian(settings, frequency[i:i + DIRECT_CHUNK],
                                                shape[i:i + DIRECT_CHUNK])
                        for i in range(0, frequency.size, DIRECT_CHUNK)])
    q = np.concatenate([adapter.motion_shift(settings, frequency[i:i + DIRECT_CHUNK],
                                             shape[i:i + DIRECT_CHUNK])
                        for i in range(0, frequency.size, DIRECT_CHUNK)])
    q_cross = spectra.cross_response(covariance, terms.scan_period,
                                     spectra.folded(frequency, terms.scan_period))
    found = motion_terms(y, 2.0 * q, q_cross, power, frequency, terms.scan_period,
                         record_duration, motions.random_phases)
    return {**out, **{name: float(value) for name, value in found.items()}}
